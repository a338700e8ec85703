// SPDX-License-Identifier: MIT
// What the browser tests (report_e2e.mjs, viewer_e2e.mjs, agent_e2e.mjs) and bench/viewer_replay.mjs share:
// the paths, the prerequisites with the command that provides each, Chromium's launch and starting an
// `llsfsim serve` (or `run --serve`) child.
import {spawn} from "node:child_process";
import {existsSync} from "node:fs";
import {dirname, join, resolve} from "node:path";
import {fileURLToPath} from "node:url";

export const viewerDir = resolve(dirname(fileURLToPath(import.meta.url)), "..");
export const sourceDir = resolve(viewerDir, "..");
/// Debian's chromium (scripts/install-deps); LLSF_CHROMIUM names another binary.
export const chromiumPath = process.env.LLSF_CHROMIUM ?? "/usr/bin/chromium";
/// Headless, and nothing that reaches for the network (this machine's network is closed).
export const chromiumArgs = [
  "--headless",
  "--no-sandbox",
  "--disable-gpu",
  "--disable-quic",
  "--no-first-run",
  "--disable-background-networking",
  "--disable-component-update",
  "--disable-sync",
];

/// fail(message): prints "NAME: FAIL: message" and exits 1.
export function failer(name) {
  return (message) => {
    console.error(`${name}: FAIL: ${message}`);
    process.exit(1);
  };
}

export function check(condition, message) {
  if (!condition) throw new Error(message);
}

/// Checks the arguments (LLSFSIM [ARTIFACT_DIR]) and that the built viewer files `dist`,
/// playwright-core and Chromium are there; returns {llsfsim, artifacts, chromium} (chromium:
/// playwright-core's browser type). Fails with the command to run otherwise.
export async function prerequisites(name, script, dist) {
  const fail = failer(name);
  const [llsfsimArg, artifactArg] = process.argv.slice(2);
  if (!llsfsimArg) fail(`usage: node ${script} LLSFSIM [ARTIFACT_DIR]`);
  const llsfsim = resolve(llsfsimArg);
  const artifacts = resolve(artifactArg ?? ".");
  if (!existsSync(llsfsim)) fail(`no llsfsim binary at ${llsfsim}`);
  if (!existsSync(join(viewerDir, "node_modules", "playwright-core"))) {
    fail("viewer/node_modules is missing: run `make viewer` (scripts/build-viewer)");
  }
  for (const f of dist) {
    if (!existsSync(join(viewerDir, "dist", f))) {
      fail(`viewer/dist/${f} is missing: run \`make viewer\` (scripts/build-viewer)`);
    }
  }
  if (!existsSync(chromiumPath)) {
    fail(`no Chromium at ${chromiumPath}: run scripts/install-deps (Debian package chromium)`);
  }
  const {chromium} = await import(join(viewerDir, "node_modules", "playwright-core", "index.mjs"));
  return {llsfsim, artifacts, chromium};
}

/// Headless Chromium (playwright-core's `chromium` browser type).
export function launch(chromium) {
  return chromium.launch({
    executablePath: chromiumPath,
    headless: true,
    args: chromiumArgs,
    timeout: 60_000,
  });
}

/// Starts `llsfsim ARGS` in `cwd` with `env` and resolves with {child, url} once its stdout names
/// the URL ("llsfsim serve: http://127.0.0.1:PORT/"); rejects if it exits first or prints none
/// within 30 s. The child is added to `children` (the caller ends them).
export function startLlsfsimServer(llsfsim, args, {cwd, env, children}) {
  return new Promise((resolvePromise, reject) => {
    const child = spawn(llsfsim, args, {cwd, env, stdio: ["ignore", "pipe", "pipe"]});
    children.push(child);
    let out = "";
    let err = "";
    let done = false;
    const timer = setTimeout(() => {
      if (done) return;
      done = true;
      reject(new Error(`llsfsim ${args.join(" ")}: no URL on stdout within 30 s\n${out}${err}`));
    }, 30_000);
    child.stdout.setEncoding("utf8");
    child.stderr.setEncoding("utf8");
    child.stdout.on("data", (d) => {
      out += d;
      const m = /llsfsim serve: (http:\/\/\S+)/.exec(out);
      if (m && !done) {
        done = true;
        clearTimeout(timer);
        resolvePromise({child, url: m[1].endsWith("/") ? m[1] : `${m[1]}/`});
      }
    });
    child.stderr.on("data", (d) => (err += d));
    child.on("exit", (code) => {
      if (done) return;
      done = true;
      clearTimeout(timer);
      reject(new Error(`llsfsim ${args.join(" ")} exited (${code}) before serving\n${out}${err}`));
    });
  });
}
