// SPDX-License-Identifier: MIT
// End-to-end test of the viewer as a participant's debugger (docs/recording.md, viewer/README.md),
// in headless Chromium:
//
//   node viewer/tests/exercise_e2e.mjs LLSFSIM [ARTIFACT_DIR]
//
//   1. live: `llsfsim exercise 04 --skill tests/app/exercises/rescue.lua --speed 30 --serve`
//      (a reference solution, 300 s of game in 10 s): #/live draws the robot's flashlight cone
//      and at least one camera sighting, the skill's state shows in the panel, and when the game
//      is over the verdict banner says PASS with the score;
//   2. replay: exercise 01 played with a skill that prints (printf in a state's init, print in
//      another) and `--record --trace`, opened with `llsfsim serve` at #/file/NAME: the printed
//      lines are markers on the timeline (hovering shows the text, clicking seeks to the line's
//      time), the skill's state changes (with what made each: --trace) and lines are in the
//      panel, the grid and the mouse's field coordinates show, and at the end the verdict banner
//      says PASS;
//   3. replay: the same skill sent to a goal inside M1: the navigator's refusal is a marker on
//      the timeline and a line in the panel, and the banner says FAIL and why.
// Screenshots go to ARTIFACT_DIR. Exit code 0, or 1 with a message.
import {execFileSync} from "node:child_process";
import {mkdirSync, mkdtempSync, rmSync, writeFileSync} from "node:fs";
import {tmpdir} from "node:os";
import {join} from "node:path";

import {check, launch, prerequisites, sourceDir, startLlsfsimServer, viewerDir} from "./e2e_lib.mjs";

const kName = "viewer_exercise_e2e";
const {llsfsim, artifacts, chromium} = await prerequisites(kName, "exercise_e2e.mjs", ["index.html", "viewer.js"]);

const exercises = join(sourceDir, "exercises");
const reference = join(sourceDir, "tests", "app", "exercises");
// Exercise 01's reference solution with two log lines.
const kPrinted = "hello from DRIVE: going to";
const printingSkill = `-- SPDX-License-Identifier: MIT
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
depends_interfaces = {
   {v = "pose", type = "Position3DInterface"},
}
documentation      = [==[Drives the robot to a point of the field, saying where.]==]

fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="CHECK", fail_to="FAILED"},
   {"CHECK", JumpState},
}

fsm:add_transitions{
   {"CHECK", "FINAL", cond=function(self, vars) return pose:distance_to(vars.x, vars.y) < 0.1 end},
   {"CHECK", "DRIVE", timeout=0.5},
}

function DRIVE:init()
   local x, y = pose:get()
   printf("${kPrinted} %.2f %.2f", self.fsm.vars.x, self.fsm.vars.y)
   self.args["drive_to"] = {x = self.fsm.vars.x, y = self.fsm.vars.y,
                            ori = math.atan(self.fsm.vars.y - y, self.fsm.vars.x - x)}
end

function CHECK:init()
   print("checking the distance")
end
`;

const env = {...process.env, LLSF_VIEWER_DIR: join(viewerDir, "dist"), LLSF_EXERCISES_DIR: exercises};
const children = [];
const startServer = (args, cwd) => startLlsfsimServer(llsfsim, args, {cwd, env, children});

const tmp = mkdtempSync(join(tmpdir(), "llsf-exercise-e2e-"));
let browser;
let ok = false;
try {
  mkdirSync(artifacts, {recursive: true});
  browser = await launch(chromium);
  const page = await browser.newPage({viewport: {width: 1280, height: 860}});
  const errors = [];
  page.on("pageerror", (e) => errors.push(`page error: ${e.message}`));
  page.on("console", (m) => {
    if (m.type() === "error") errors.push(`console error: ${m.text()}`);
  });
  const ready = async (what) => {
    await page.waitForFunction(
      () => window.llsfViewer?.ready || document.getElementById("app")?.hasAttribute("data-error"),
      null,
      {timeout: 30_000},
    );
    const error = await page.getAttribute("#app", "data-error");
    check(error === null, `${what}: the page reports: ${error}`);
  };
  const debug = () => page.evaluate(() => window.llsfViewer.debug());

  // 1. Live: exercise 04 with the reference rescue skill, 30 times real time.
  const live = await startServer(
    ["exercise", "04", "--skill", join(reference, "rescue.lua"), "--speed", "30", "--serve",
     "--port", "0"],
    tmp,
  );
  await page.goto(`${live.url}#/live`);
  await ready("#/live");
  await page.waitForFunction(() => {
    const d = window.llsfViewer.debug();
    return d.cones >= 1 && d.maxSightings >= 1;
  }, null, {timeout: 20_000, polling: 50});
  const seen = await debug();
  await page.screenshot({path: join(artifacts, "exercise-live.png")});
  check(seen.cones === 1, `${seen.cones} cone(s) drawn for one robot`);
  // The canvas says the same as the hook.
  check(Number(await page.getAttribute("canvas[data-field]", "data-cones")) === 1,
        "the field canvas's data-cones is not 1");
  // The game goes on to its end (300 s at 30x): the verdict banner.
  await page.waitForSelector("[data-verdict]", {timeout: 30_000});
  const liveVerdict = await page.textContent("[data-verdict]");
  check(/^PASS\b.*points/.test(liveVerdict), `the live verdict banner says "${liveVerdict}"`);
  const liveEnd = await debug();
  check(liveEnd.skills.length === 1 && liveEnd.skills[0].skill === "rescue",
        `the skill panel: ${JSON.stringify(liveEnd.skills)}`);
  check(liveEnd.skills[0].lines.some((l) => /^rescue: \S+ → \S+/.test(l)),
        `no state change in the skill panel: ${JSON.stringify(liveEnd.skills[0].lines)}`);
  await page.screenshot({path: join(artifacts, "exercise-live-end.png")});
  await page.goto("about:blank");  // the live page polls its server: leave it first
  live.child.kill("SIGTERM");

  // 2. Replay of a recording of exercise 01 with a skill that prints.
  writeFileSync(join(tmp, "printing.lua"), printingSkill);
  mkdirSync(join(tmp, "rec"));
  let stdout = "";
  try {
    stdout = execFileSync(
      llsfsim,
      ["exercise", "01", "--skill", "printing.lua", "--trace", "--record", join("rec", "ex01.jsonl.gz")],
      {cwd: tmp, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], env, timeout: 60_000},
    );
  } catch (e) {
    throw new Error(`llsfsim exercise 01 failed: ${e.stdout ?? ""}${e.stderr ?? ""}`);
  }
  check(/result\s+PASS/.test(stdout), `exercise 01 did not pass:\n${stdout}`);
  const served = await startServer(
    ["serve", "--port", "0", "--db", "e2e.db", "--recordings", "rec"], tmp);
  await page.goto(`${served.url}#/file/ex01.jsonl.gz`);
  await ready("#/file/ex01.jsonl.gz");
  const rep = await debug();
  const logs = rep.markers.filter((m) => m.kind === "log");
  const printed = logs.find((m) => m.label.includes(kPrinted));
  check(printed, `no timeline marker for the printed line: ${JSON.stringify(rep.markers)}`);
  check(logs.some((m) => m.label.includes("checking the distance")),
        `no timeline marker for the print line: ${JSON.stringify(logs)}`);
  // Hovering the marker shows its text; clicking it seeks to its time.
  const box = await page.locator("canvas[data-timeline]").boundingBox();
  check(box, "the timeline is missing");
  await page.evaluate(() => window.llsfViewer.seek(window.llsfViewer.endTime()));
  await page.mouse.move(box.x + printed.x, box.y + box.height * 0.2);
  const tip = await page.textContent(".tip");
  check(tip.includes(kPrinted), `hovering the marker shows "${tip}"`);
  await page.mouse.click(box.x + printed.x, box.y + box.height * 0.2);
  await page.mouse.move(box.x + box.width / 2, box.y - 40);  // off the timeline: no drag
  const t = await page.evaluate(() => window.llsfViewer.time());
  check(Math.abs(t - printed.t) < 1e-6, `clicking the marker at ${printed.t} s seeked to ${t} s`);
  await page.evaluate(() => window.llsfViewer.seek(window.llsfViewer.time()));
  const atLine = await debug();
  check(atLine.skills[0].lines.some((l) => l.includes(kPrinted)),
        `the skill panel at ${t} s: ${JSON.stringify(atLine.skills)}`);
  check(atLine.verdict && atLine.verdict.result === "PASS" && !atLine.verdict.shown,
        `the verdict before the end: ${JSON.stringify(atLine.verdict)}`);
  // The grid and the mouse's coordinates.
  await page.evaluate(() => window.llsfViewer.setGrid(true));
  const field = await page.locator("canvas[data-field]").boundingBox();
  await page.mouse.move(field.x + field.width / 2, field.y + field.height / 2);
  const mouse = await page.getAttribute("[data-mouse]", "data-mouse");
  const m = /^x (\d+\.\d\d)\s+y (\d+\.\d\d) m$/.exec(mouse ?? "");
  check(m && Math.abs(Number(m[1]) - 2.8) < 0.1 && Math.abs(Number(m[2]) - 2.8) < 0.1,
        `the mouse readout at the field's centre says "${mouse}"`);
  await page.screenshot({path: join(artifacts, "exercise-replay-line.png")});
  // At the end: the verdict banner with the score.
  await page.evaluate(() => window.llsfViewer.seek(window.llsfViewer.endTime()));
  const end = await debug();
  check(end.verdict && end.verdict.shown, `no verdict banner at the end: ${JSON.stringify(end.verdict)}`);
  const banner = await page.textContent("[data-verdict]");
  check(/^PASS\b.*m from the target/.test(banner), `the verdict banner says "${banner}"`);
  check(end.skills[0].state === "FINAL", `the skill's state at the end: ${end.skills[0].state}`);
  // Recorded with --trace: each state change says what made it (the transition and its line).
  check(end.skills[0].lines.some((l) => /^drive_to_point: CHECK → FINAL  \(\{"CHECK", "FINAL", cond=<function>\} at .*printing\.lua:\d+\)$/.test(l)),
        `no state change with what made it in the panel: ${JSON.stringify(end.skills[0].lines)}`);
  await page.screenshot({path: join(artifacts, "exercise-replay-end.png")});

  // 3. The same skill sent into M1: the navigator's refusal on the timeline and in the panel,
  // and a FAIL banner saying why.
  writeFileSync(join(tmp, "into_m1.lua"),
                printingSkill.replace("x = self.fsm.vars.x, y = self.fsm.vars.y,", "x = 3.92, y = 1.68,"));
  let failed = "";
  try {
    execFileSync(llsfsim,
                 ["exercise", "01", "--skill", "into_m1.lua", "--record", join("rec", "nav.jsonl.gz")],
                 {cwd: tmp, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], env, timeout: 60_000});
  } catch (e) {
    failed = e.stdout ?? "";
  }
  check(/result\s+FAIL/.test(failed), `exercise 01 into M1 did not fail:\n${failed}`);
  await page.goto(`${served.url}#/file/nav.jsonl.gz`);
  await ready("#/file/nav.jsonl.gz");
  const nav = await debug();
  const refusal = nav.markers.find((m) => m.kind === "nav");
  check(refusal && /refused \(3\.92, 1\.68\): INVALID_GOAL .*inside M1/.test(refusal.label),
        `no navigator refusal on the timeline: ${JSON.stringify(nav.markers)}`);
  await page.evaluate((t) => window.llsfViewer.seek(t), refusal.t);
  const atRefusal = await debug();
  check(atRefusal.skills[0].lines.some((l) => l.startsWith("navigator refused")),
        `the panel at the refusal: ${JSON.stringify(atRefusal.skills)}`);
  await page.screenshot({path: join(artifacts, "exercise-replay-nav.png")});
  await page.evaluate(() => window.llsfViewer.seek(window.llsfViewer.endTime()));
  const failBanner = await page.textContent("[data-verdict]");
  check(/^FAIL\b.*inside M1/.test(failBanner), `the FAIL banner says "${failBanner}"`);

  check(errors.length === 0, errors.join("\n"));
  ok = true;
  console.log(
    `${kName}: ok: live cone + ${seen.maxSightings} sighting(s), verdict "${liveVerdict}"; ` +
      `replay: "${printed.label}" at ${printed.t} s, banner "${banner}"; screenshots in ${artifacts}`,
  );
} catch (e) {
  console.error(`${kName}: FAIL: ${e.message ?? e}`);
} finally {
  if (browser) await browser.close();
  for (const c of children) if (c.exitCode === null) c.kill("SIGTERM");
  rmSync(tmp, {recursive: true, force: true});
}
process.exit(ok ? 0 : 1);
