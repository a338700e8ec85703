// SPDX-License-Identifier: MIT
// Benchmark: how smoothly the browser viewer replays a full game.
//
//   node bench/viewer_replay.mjs LLSFSIM
//
// Records scenarios/default.yaml (seed 1, 1080 s, 3 robots) with LLSFSIM, serves it with
// `llsfsim serve --port 0 --recordings DIR`, opens #/file/NAME in headless Chromium
// (/usr/bin/chromium via playwright-core, 1280x860), and plays it at 64x (the fastest speed of
// the page) for 5 s of wall time, three times from different starting points. Prints, like
// llsf-bench, one JSON object per result line:
//   {"bench": "viewer_replay", "metric": "fps", ...}        median frames drawn per second
//   {"bench": "viewer_replay", "metric": "fps_agent", ...}  the same with the agent browser open
//                                                           on robot1 (its facts, firings, log)
//   {"bench": "viewer_replay", "metric": "load_s", ...}     page load until the recording is ready
// The bar (issue: viewer) is >= 30 frames per second.
import {execFileSync, spawn} from "node:child_process";
import {mkdirSync, mkdtempSync, rmSync} from "node:fs";
import {tmpdir} from "node:os";
import {dirname, join, resolve} from "node:path";
import {fileURLToPath} from "node:url";

const sourceDir = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const viewerDir = join(sourceDir, "viewer");
const llsfsim = resolve(process.argv[2] ?? join(sourceDir, "build", "release", "llsfsim"));
const {chromium} = await import(join(viewerDir, "node_modules", "playwright-core", "index.mjs"));
const {launch} = await import(join(viewerDir, "tests", "e2e_lib.mjs"));

function report(metric, value, unit) {
  console.log(JSON.stringify({bench: "viewer_replay", metric, value: Number(value.toPrecision(6)), unit}));
}
const median = (v) => {
  const s = [...v].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};

const tmp = mkdtempSync(join(tmpdir(), "llsf-viewer-bench-"));
const recordings = join(tmp, "recordings");
mkdirSync(recordings);
let server;
let browser;
try {
  execFileSync(llsfsim, ["run", join(sourceDir, "scenarios", "default.yaml"), "--no-db", "-q",
                         "--record", join(recordings, "default-seed1.jsonl.gz")],
               {stdio: ["ignore", "ignore", "inherit"]});
  server = spawn(llsfsim, ["serve", "--port", "0", "--db", join(tmp, "none.db"), "--recordings",
                           recordings, "--viewer", join(viewerDir, "dist")],
                 {stdio: ["ignore", "pipe", "inherit"]});
  const url = await new Promise((ok, fail) => {
    let out = "";
    server.stdout.setEncoding("utf8");
    server.stdout.on("data", (d) => {
      out += d;
      const m = /llsfsim serve: (http:\/\/\S+)/.exec(out);
      if (m) ok(m[1].endsWith("/") ? m[1] : `${m[1]}/`);
    });
    server.on("exit", (code) => fail(new Error(`llsfsim serve exited (${code})`)));
  });
  browser = await launch(chromium);
  const page = await browser.newPage({viewport: {width: 1280, height: 860}});
  const t0 = Date.now();
  await page.goto(`${url}#/file/default-seed1.jsonl.gz`);
  await page.waitForFunction(() => window.llsfViewer?.ready === true, null, {timeout: 60_000});
  report("load_s", (Date.now() - t0) / 1000, "s");
  const measure = async () => {
    const fps = [];
    for (const start of [0, 300, 700]) {
      const f = await page.evaluate(async (start) => {
        const v = window.llsfViewer;
        v.seek(start);
        v.setSpeed(64);
        const f0 = v.framesDrawn();
        const w0 = performance.now();
        v.play(true);
        await new Promise((r) => setTimeout(r, 5000));
        v.play(false);
        return ((v.framesDrawn() - f0) * 1000) / (performance.now() - w0);
      }, start);
      fps.push(f);
    }
    return median(fps);
  };
  report("fps", await measure(), "frames/s");
  await page.evaluate(() => window.llsfViewer.selectRobot("robot1"));
  report("fps_agent", await measure(), "frames/s");
} finally {
  if (browser) await browser.close();
  if (server) server.kill("SIGTERM");
  rmSync(tmp, {recursive: true, force: true});
}
