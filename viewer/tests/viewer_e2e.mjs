// SPDX-License-Identifier: MIT
// End-to-end test of the browser viewer served by `llsfsim serve`, in headless Chromium.
//
//   node viewer/tests/viewer_e2e.mjs LLSFSIM [ARTIFACT_DIR]
//
// Plays a small batch (2 matrix variants x 2 seeds of a short game) into a fresh store (its
// recordings beside it), starts `llsfsim serve --port 0 --db DB` and reads its URL from the first
// stdout line, then in Chromium (/usr/bin/chromium via playwright-core; no browser is downloaded):
//   1. #/run/ID: the field shows 16 devices and every robot; seeking the timeline to two times
//      moves the robots;
//      every robot holding a puck has its name and skill labels clear of the puck (sampled every
//      0.5 s; at least one sample faces up or down);
//   2. #/: a single game of `llsfsim run` in the same store is listed as "single games" (neither
//      finished nor running); #/batch/ID: one box per variant in the points plot, a row per run
//      in the runs table;
//   3. #/live: a 300 s game played with `llsfsim run --speed 20 --serve --serve-exit --port 0`;
//      the shown game time advances.
// Screenshots go to ARTIFACT_DIR (default: the current directory). Exit code 0, or 1 with a
// message. LLSF_CHROMIUM names another Chromium binary.
import {execFileSync} from "node:child_process";
import {mkdirSync, mkdtempSync, rmSync, writeFileSync} from "node:fs";
import {tmpdir} from "node:os";
import {join} from "node:path";

import {check, launch, prerequisites, sourceDir, startLlsfsimServer, viewerDir} from "./e2e_lib.mjs";

const kName = "viewer_e2e";
const {llsfsim, artifacts, chromium} = await prerequisites(kName, "viewer_e2e.mjs", ["index.html", "viewer.js"]);

// A short game: 30 s exploration + 60 s production, two robots with the 2013 team agent.
const agents = join(sourceDir, "clips", "agents");
const scenario = `name: viewer-e2e
seeds: {first: 1, count: 2}
refbox: {exploration_s: 30, production_s: 60}
robots:
  count: 2
  agent: [${JSON.stringify(join(agents, "common"))}, ${JSON.stringify(join(agents, "llsf2013"))}]
  config: {roles: [P1P2, P3], recycle: never}
matrix:
  config:
    P3-P3: {robots.config.roles: [P3, P3]}
    P1P2-P3: {}
tests:
  - no_agent_errors: true
`;
// The live game is longer (300 s, 15 s of wall time at --speed 20): `--serve-exit` ends the
// server with the game, and the page must load and watch the time advance before that.
const liveScenario = scenario
  .replace("refbox: {exploration_s: 30, production_s: 60}",
           "refbox: {exploration_s: 60, production_s: 240}")
  .replace("name: viewer-e2e", "name: viewer-e2e-live");
const kVariants = 2;
const kRuns = 2;

const env = {...process.env, LLSF_VIEWER_DIR: join(viewerDir, "dist")};
const children = [];

/// Starts `llsfsim ARGS` in `cwd` and resolves with its URL (e2e_lib.mjs, startLlsfsimServer).
const startServer = (args, cwd) => startLlsfsimServer(llsfsim, args, {cwd, env, children});

async function getJson(url) {
  const res = await fetch(url);
  const text = await res.text();
  check(res.ok, `GET ${url}: ${res.status} ${text}`);
  return JSON.parse(text);
}

const tmp = mkdtempSync(join(tmpdir(), "llsf-viewer-e2e-"));
let browser;
let ok = false;
try {
  writeFileSync(join(tmp, "e2e.yaml"), scenario);
  writeFileSync(join(tmp, "live.yaml"), liveScenario);
  execFileSync(
    llsfsim,
    ["batch", "e2e.yaml", "--runs", String(kRuns), "--db", "tmp.db", "--jobs", "2", "--quiet"],
    {cwd: tmp, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], env, timeout: 300_000},
  );
  // A single game of `llsfsim run` in the same store: the batches page calls it that, neither
  // finished nor running.
  execFileSync(llsfsim, ["run", "e2e.yaml", "--db", "tmp.db", "--no-record", "-q"],
               {cwd: tmp, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], env, timeout: 300_000});
  mkdirSync(artifacts, {recursive: true});
  const {url} = await startServer(["serve", "--port", "0", "--db", "tmp.db"], tmp);

  // The API, as far as the pages need it.
  const batches = await getJson(`${url}api/batches`);
  check(batches.length >= 2, "GET /api/batches: not the batch and the single run");
  const batch = batches.find((b) => b.kind !== "run");
  check(batch, `GET /api/batches: no batch but single runs: ${JSON.stringify(batches)}`);
  const runs = await getJson(`${url}api/batches/${batch.id}/runs`);
  check(runs.length === kVariants * kRuns, `batch ${batch.id} has ${runs.length} run(s)`);
  const run = runs.find((r) => r.recording);
  check(run, `no run of batch ${batch.id} has a recording`);

  browser = await launch(chromium);
  const page = await browser.newPage({viewport: {width: 1280, height: 860}});
  const errors = [];
  page.on("pageerror", (e) => errors.push(`page error: ${e.message}`));
  page.on("console", (m) => {
    if (m.type() === "error") errors.push(`console error: ${m.text()}`);
  });
  // Only the servers' own URLs (http and ws) may be requested.
  const allowedHosts = new Set([new URL(url).host]);
  page.on("request", (r) => {
    if (r.url().startsWith("data:")) return;
    if (!allowedHosts.has(new URL(r.url()).host)) {
      errors.push(`the page requested ${r.url()} (only the server's own URLs are allowed)`);
    }
  });
  const readyOrError = async (what) => {
    await page.waitForFunction(
      () => window.llsfViewer?.ready || document.getElementById("app")?.hasAttribute("data-error"),
      null,
      {timeout: 30_000},
    );
    const error = await page.getAttribute("#app", "data-error");
    check(error === null, `${what}: the page reports: ${error}`);
  };

  // 1. A run's replay.
  await page.goto(`${url}#/run/${run.id}`);
  await readyOrError(`#/run/${run.id}`);
  const end = await page.evaluate(() => window.llsfViewer.endTime());
  check(end > 30, `#/run/${run.id}: the recording ends at ${end} s`);
  // Seek by clicking the timeline at 20 % and 80 % of its width.
  const box = await page.locator("canvas[data-timeline]").boundingBox();
  check(box, "the timeline is missing");
  const seekClick = async (frac) => {
    await page.mouse.click(box.x + 8 + (box.width - 16) * frac, box.y + 4);
    await page.waitForTimeout(300);
    return page.evaluate(() => ({
      time: window.llsfViewer.time(),
      robots: window.llsfViewer.robots(),
      devices: window.llsfViewer.devicesDrawn(),
      drawn: window.llsfViewer.robotsDrawn(),
    }));
  };
  const a = await seekClick(0.2);
  await page.screenshot({path: join(artifacts, "viewer-run-a.png")});
  const b = await seekClick(0.8);
  await page.screenshot({path: join(artifacts, "viewer-run-b.png")});
  check(Math.abs(b.time - a.time) > 0.3 * end,
        `clicking the timeline did not seek: ${a.time} s, then ${b.time} s`);
  for (const s of [a, b]) {
    check(s.devices === 16, `${s.devices} device(s) drawn at ${s.time} s, expected 16`);
    check(s.drawn === 2 && s.robots.length === 2,
          `${s.drawn} robot(s) drawn at ${s.time} s, expected 2`);
  }
  // The labels keep clear of a held puck: every 0.5 s of the game, each robot holding one has
  // its name label above the puck and its skill label below it, whichever way it faces.
  const held = [];
  for (let t = 0; t <= end; t += 0.5) {
    held.push(...(await page.evaluate((at) => {
      window.llsfViewer.seek(at);
      return window.llsfViewer.debug().heldLabels.map((h) => ({...h, t: at}));
    }, t)));
  }
  check(held.some((h) => Math.abs(Math.sin(h.th)) > 0.7),
        `no robot held a puck facing up or down in ${held.length} sample(s): the check checks nothing`);
  const clash = held.filter((h) => h.nameBottom > h.puckTop + 1e-6 ||
                                   (h.skillTop !== null && h.skillTop < h.puckBottom - 1e-6));
  check(clash.length === 0, `a label drawn over the held puck: ${JSON.stringify(clash.slice(0, 3))}`);
  const moved = a.robots.some((r, i) => Math.hypot(r.x - b.robots[i].x, r.y - b.robots[i].y) > 0.05);
  check(moved, `the robots did not move between ${a.time} s and ${b.time} s: ` +
        JSON.stringify([a.robots, b.robots]));

  // 2. The batches: the single game of `run` is neither finished nor running.
  await page.goto(`${url}#/`);
  await page.waitForSelector("#app[data-ready], #app[data-error]", {timeout: 30_000});
  const rowsText = await page.locator('table[data-table="batches"] tbody tr').allInnerTexts();
  check(rowsText.some((r) => r.includes("single games")),
        `the batches table shows no single games row: ${JSON.stringify(rowsText)}`);
  check(!rowsText.some((r) => r.includes("single games") && r.includes("running")),
        `a single games row says running: ${JSON.stringify(rowsText)}`);

  // The batch: one box per variant in the points plot, a row per run.
  await page.goto(`${url}#/batch/${batch.id}`);
  await page.waitForSelector("#app[data-ready], #app[data-error]", {timeout: 30_000});
  const batchError = await page.getAttribute("#app", "data-error");
  check(batchError === null, `#/batch/${batch.id}: the page reports: ${batchError}`);
  const boxes = await page.locator('svg[data-plot="points"] g[aria-label="bar"] rect').count();
  check(boxes === kVariants, `the points plot has ${boxes} box(es), expected ${kVariants}`);
  const runRows = await page.locator('table[data-table="runs"] tbody tr').count();
  check(runRows === kVariants * kRuns, `the runs table has ${runRows} row(s)`);
  check(await page.locator(`table[data-table="runs"] a[href="#/run/${run.id}"]`).count() >= 1,
        `the runs table does not link #/run/${run.id}`);
  await page.screenshot({path: join(artifacts, "viewer-batch.png"), fullPage: true});

  // 3. A live game.
  const live = await startServer(
    ["run", "live.yaml", "--no-db", "--no-record", "--speed", "20", "--serve", "--serve-exit",
     "--port", "0"],
    tmp,
  );
  const liveUrl = live.url;
  allowedHosts.add(new URL(liveUrl).host);
  const status = await getJson(`${liveUrl}api/live/status`);
  check(status.live === true, `GET /api/live/status: ${JSON.stringify(status)}`);
  await page.goto(`${liveUrl}#/live`);
  await page.waitForFunction(
    () => window.llsfViewer?.ready || document.getElementById("app")?.hasAttribute("data-error"),
    null,
    {timeout: 30_000},
  );
  const liveError = await page.getAttribute("#app", "data-error");
  check(liveError === null, `#/live: the page reports: ${liveError}`);
  const t0 = await page.evaluate(() => window.llsfViewer.time());
  await page.waitForTimeout(1500);
  const t1 = await page.evaluate(() => window.llsfViewer.time());
  await page.screenshot({path: join(artifacts, "viewer-live.png")});
  check(t1 > t0, `the live game time did not advance: ${t0} s, then ${t1} s`);
  check(await page.evaluate(() => window.llsfViewer.devicesDrawn()) === 16,
        "the live field does not show 16 devices");

  check(errors.length === 0, errors.join("\n"));
  ok = true;
  console.log(
    `${kName}: ok: run ${run.id} seeks ${a.time.toFixed(1)} s -> ${b.time.toFixed(1)} s, ` +
      `${held.length} held-puck samples with clear labels, ${boxes} boxes, live ${t0.toFixed(1)} s -> ${t1.toFixed(1)} s; screenshots in ${artifacts}`,
  );
} catch (e) {
  const output = e.stderr ? `\n${e.stderr}` : "";
  console.error(`${kName}: FAIL: ${e.message ?? e}${output}`);
} finally {
  if (browser) await browser.close();
  for (const c of children) if (c.exitCode === null) c.kill("SIGTERM");
  rmSync(tmp, {recursive: true, force: true});
}
process.exit(ok ? 0 : 1);
