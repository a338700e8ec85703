// SPDX-License-Identifier: MIT
// End-to-end test of the hackathon leaderboard (`llsfsim hackathon serve`) in headless Chromium
// (CTest: viewer_leaderboard_e2e).
//
//   node viewer/tests/leaderboard_e2e.mjs LLSFSIM [ARTIFACT_DIR]
//
// Starts the server on a free port with a fresh store, opens its page, submits two skill files of
// exercise 01 through the page's form -- first the unchanged skeleton (exercises/01-*/skill.lua,
// it fails), then a reference solution (tests/app/exercises/01-drive-to-point.lua) -- waits until
// both are played, and checks that the board ranks the reference first (5/5 seeds) and the
// skeleton second, that the skeleton's FAIL shows its reason on the page, that a bad submission
// (no team) is refused with the server's message on the page, and that no seed number reaches the
// page. Then restarts the server on the same store: the board is still there. Saves a screenshot
// to ARTIFACT_DIR. Exit code 0, or 1 with a message.
import {spawn} from "node:child_process";
import {mkdirSync, mkdtempSync, rmSync} from "node:fs";
import {tmpdir} from "node:os";
import {join} from "node:path";

import {check, launch, prerequisites, sourceDir, viewerDir} from "./e2e_lib.mjs";

const kName = "viewer_leaderboard_e2e";
const {llsfsim, artifacts, chromium} = await prerequisites(kName, "leaderboard_e2e.mjs", [
  "leaderboard.js",
  "leaderboard.html",
]);
const kSeeds = "7771-7773";  // hidden: must never show on the page

/// Starts `llsfsim hackathon serve` and resolves with {child, url} once it prints its URL.
function startServer(tmp, children) {
  const args = ["hackathon", "serve", "--port", "0", "--db", join(tmp, "board.db"), "--seeds",
    kSeeds, "--workers", "2", "--exercises", join(sourceDir, "exercises")];
  return new Promise((resolvePromise, reject) => {
    const child = spawn(llsfsim, args, {
      cwd: tmp,
      env: {...process.env, LLSF_VIEWER_DIR: join(viewerDir, "dist")},
      stdio: ["ignore", "pipe", "pipe"],
    });
    children.push(child);
    let out = "";
    let err = "";
    const timer = setTimeout(() => reject(new Error(`no URL within 30 s\n${out}${err}`)), 30_000);
    child.stdout.setEncoding("utf8");
    child.stderr.setEncoding("utf8");
    child.stdout.on("data", (d) => {
      out += d;
      const m = /llsfsim hackathon: (http:\/\/\S+)/.exec(out);
      if (m) {
        clearTimeout(timer);
        resolvePromise({child, url: m[1]});
      }
    });
    child.stderr.on("data", (d) => (err += d));
    child.on("exit", (code) => {
      clearTimeout(timer);
      reject(new Error(`llsfsim ${args.join(" ")} exited (${code}) before serving\n${out}${err}`));
    });
  });
}

function stop(child) {
  return new Promise((res) => {
    if (child.exitCode !== null) return res();
    child.on("exit", () => res());
    child.kill("SIGTERM");
  });
}

const tmp = mkdtempSync(join(tmpdir(), "llsf-leaderboard-e2e-"));
const children = [];
let browser;
let ok = false;
try {
  let {child, url} = await startServer(tmp, children);
  browser = await launch(chromium);
  const page = await browser.newPage({viewport: {width: 1200, height: 900}});
  const errors = [];
  page.on("pageerror", (e) => errors.push(`page error: ${e.message}`));
  await page.goto(`${url}#01`);
  await page.waitForSelector('#tabs a[data-exercise="01-drive-to-point"].current', {timeout: 20_000});

  // A refused submission: the server's message on the page.
  await page.setInputFiles("#file", join(sourceDir, "exercises", "01-drive-to-point", "skill.lua"));
  await page.fill("#team", "   ");
  await page.click("#submit-button");
  await page.waitForSelector("#submit-message.bad", {timeout: 10_000});
  const refused = await page.textContent("#submit-message");
  check(/team/.test(refused), `a submission without a team: "${refused}"`);

  // The weaker skill first (the skeleton), then the reference solution.
  const submitAs = async (team, file) => {
    await page.fill("#team", team);
    await page.selectOption("#exercise", "01-drive-to-point");
    await page.setInputFiles("#file", file);
    await page.click("#submit-button");
    await page.waitForFunction(
      (t) => document.querySelector("#submit-message.ok")?.textContent?.includes("queued") &&
        [...document.querySelectorAll("#recent tbody tr")].some((r) => r.textContent.includes(t)),
      team, {timeout: 10_000});
  };
  await submitAs("slow snails", join(sourceDir, "exercises", "01-drive-to-point", "skill.lua"));
  await submitAs("rapid robots", join(sourceDir, "tests", "app", "exercises", "01-drive-to-point.lua"));

  // Both played: the board (auto-refreshed) ranks them.
  await page.waitForFunction(() => document.querySelectorAll("#board tbody tr[data-team]").length === 2,
    null, {timeout: 120_000});
  const rows = await page.$$eval("#board tbody tr[data-team]", (trs) =>
    trs.map((tr) => ({team: tr.dataset.team, rank: tr.dataset.rank, text: tr.textContent})));
  check(rows[0].team === "rapid robots" && rows[0].rank === "1",
    `the reference solution is not first: ${JSON.stringify(rows)}`);
  check(rows[1].team === "slow snails" && rows[1].rank === "2",
    `the skeleton is not second: ${JSON.stringify(rows)}`);
  check(rows[0].text.includes("3 / 3"), `the reference passed 3 of 3 seeds: ${rows[0].text}`);
  check(rows[1].text.includes("0 / 3"), `the skeleton passed 0 of 3 seeds: ${rows[1].text}`);
  const html = await page.content();
  for (const seed of ["7771", "7772", "7773"]) {
    check(!html.includes(seed), `a hidden seed (${seed}) is on the page`);
  }
  // The skeleton's FAIL says why on the page: its first run not passed (no seed named).
  const reasonShown = () => [...document.querySelectorAll("#recent tbody td.error")]
    .some((td) => td.textContent.includes("not solved yet"));
  await page.waitForFunction(reasonShown, null, {timeout: 30_000}).catch(() => {});
  const reasons = await page.$$eval("#recent tbody td.error", (tds) => tds.map((td) => td.textContent));
  check(reasons.some((r) => r.startsWith("run 1 of 3: ") && r.includes("not solved yet")),
    `the failed submission shows no reason on the page: ${JSON.stringify(reasons)}`);
  const api = await (await fetch(`${url}api/hackathon/submissions/2`)).text();
  check(!/777[123]/.test(api), `a hidden seed is in the API's answer: ${api}`);
  mkdirSync(artifacts, {recursive: true});
  await page.screenshot({path: join(artifacts, "leaderboard.png"), fullPage: true});

  // A restart keeps the board.
  await stop(child);
  ({child, url} = await startServer(tmp, children));
  const board = await (await fetch(`${url}api/hackathon/board/01`)).json();
  check(board.entries.length === 2 && board.entries[0].team === "rapid robots",
    `the board after a restart: ${JSON.stringify(board.entries)}`);
  check(errors.length === 0, errors.join("\n"));
  ok = true;
  console.log(`${kName}: ok (ranked: ${rows.map((r) => r.team).join(", ")})`);
} catch (e) {
  console.error(`${kName}: FAIL: ${e.stack ?? e}`);
} finally {
  if (browser) await browser.close();
  for (const c of children) await stop(c);
  rmSync(tmp, {recursive: true, force: true});
}
process.exit(ok ? 0 : 1);
