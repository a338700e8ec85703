// SPDX-License-Identifier: MIT
// End-to-end test of `llsfsim report --html` in headless Chromium (CTest: viewer_report_e2e).
//
//   node viewer/tests/report_e2e.mjs LLSFSIM [ARTIFACT_DIR]
//
// Plays a small batch (2 matrix variants x 3 seeds of a short game) into a fresh store, writes the
// report page, opens it from file:// in Chromium (/usr/bin/chromium, driven by playwright-core; no
// browser is downloaded) and checks: no script error, one box per variant in the points plot,
// two per variant in the per-phase plot, the tables. Saves a screenshot (and the page) to
// ARTIFACT_DIR (default: the current directory). Exit code 0, or 1 with a message.
import {execFileSync} from "node:child_process";
import {copyFileSync, mkdirSync, mkdtempSync, rmSync, writeFileSync} from "node:fs";
import {tmpdir} from "node:os";
import {join} from "node:path";
import {pathToFileURL} from "node:url";

import {check, launch, prerequisites, sourceDir, viewerDir} from "./e2e_lib.mjs";

const kName = "viewer_report_e2e";
const {llsfsim, artifacts, chromium} = await prerequisites(kName, "report_e2e.mjs", ["report.js"]);

// A short game: 60 s exploration + 240 s production, two robots with the 2013 team agent.
const agents = join(sourceDir, "clips", "agents");
const scenario = `name: viewer-e2e
seeds: {first: 1, count: 3}
refbox: {exploration_s: 60, production_s: 240}
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
const variants = ["P1P2-P3", "P3-P3"];  // name order, labels without "config="

const tmp = mkdtempSync(join(tmpdir(), "llsf-viewer-e2e-"));
let browser;
let ok = false;
try {
  writeFileSync(join(tmp, "e2e.yaml"), scenario);
  const run = (args) =>
    execFileSync(llsfsim, args, {
      cwd: tmp,
      encoding: "utf8",
      stdio: ["ignore", "pipe", "pipe"],
      env: {...process.env, LLSF_VIEWER_DIR: join(viewerDir, "dist")},
      timeout: 300_000,
    });
  run(["batch", "e2e.yaml", "--runs", "3", "--db", "tmp.db", "--jobs", "2", "--quiet"]);
  const text = run(["report", "--db", "tmp.db", "--html", join(tmp, "report.html")]);
  check(text.includes("config=P3-P3"), `the text report lacks the variants:\n${text}`);
  mkdirSync(artifacts, {recursive: true});
  copyFileSync(join(tmp, "report.html"), join(artifacts, "report.html"));

  // The page in Chromium: nothing but file:// is loaded.
  browser = await launch(chromium);
  const page = await browser.newPage({viewport: {width: 1100, height: 900}});
  const errors = [];
  page.on("pageerror", (e) => errors.push(`page error: ${e.message}`));
  page.on("console", (m) => {
    if (m.type() === "error") errors.push(`console error: ${m.text()}`);
  });
  page.on("request", (r) => {
    if (!r.url().startsWith("file:") && !r.url().startsWith("data:")) {
      errors.push(`the page requested ${r.url()} (it must be self-contained)`);
    }
  });
  await page.goto(pathToFileURL(join(tmp, "report.html")).href);
  await page.waitForSelector("#llsf-report[data-ready], #llsf-report[data-error]", {
    timeout: 30_000,
  });
  const pageError = await page.getAttribute("#llsf-report", "data-error");
  check(pageError === null, `the page reports: ${pageError}`);

  const count = (selector) => page.locator(selector).count();
  const pointsBoxes = await count('svg[data-plot="points"] g[aria-label="bar"] rect');
  check(pointsBoxes === variants.length,
        `the points plot has ${pointsBoxes} box(es), expected one per variant (${variants.length})`);
  const runDots = await count('svg[data-plot="points"] g[aria-label="dot"] circle');
  check(runDots >= 6, `the points plot has ${runDots} dot(s), expected one per run (6)`);
  check(await count('svg[data-plot="phases"]') === 1, "the per-phase plot is missing");
  const phaseBoxes = await count('svg[data-plot="phases"] g[aria-label="bar"] rect');
  check(phaseBoxes === 2 * variants.length,
        `the per-phase plot has ${phaseBoxes} box(es), expected 2 per variant`);
  const axisText = await page.locator('svg[data-plot="points"]').textContent();
  for (const v of variants) check(axisText.includes(v), `the points plot does not name ${v}`);
  check(axisText.includes("points"), "the points plot's y axis is not labelled");
  const variantRows = await count('table[data-table="variants"] tbody tr');
  check(variantRows === variants.length, `the variants table has ${variantRows} row(s)`);
  const differenceRows = await count('table[data-table="differences"] tbody tr');
  check(differenceRows >= 1, "the differences table is empty");
  check(errors.length === 0, errors.join("\n"));

  await page.screenshot({path: join(artifacts, "report.png"), fullPage: true});
  ok = true;
  console.log(
    `${kName}: ok: ${pointsBoxes} boxes in the points plot, ${phaseBoxes} in the per-phase plot; ` +
      `screenshot ${join(artifacts, "report.png")}`,
  );
} catch (e) {
  const output = e.stderr ? `\n${e.stderr}` : "";
  console.error(`${kName}: FAIL: ${e.message ?? e}${output}`);
} finally {
  if (browser) await browser.close();
  rmSync(tmp, {recursive: true, force: true});
}
process.exit(ok ? 0 : 1);
