// SPDX-License-Identifier: MIT
// End-to-end test of the viewer's agent browser (issue #16 item 3), in headless Chromium.
//
//   node viewer/tests/agent_e2e.mjs LLSFSIM [ARTIFACT_DIR]
//
// Records a short two-robot game with `llsfsim run --record`, serves it with `llsfsim serve
// --recordings DIR`, and opens #/file/NAME:
//   1. clicks a robot on the field: the agent browser opens on it;
//   2. drags the timeline to about 60 % of the game and compares the listed facts (index and
//      text) with the facts reconstructed here from the .jsonl.gz itself (docs/recording.md: the
//      last `facts` snapshot of the robot at or before t, then its `fact` deltas up to t); an
//      expected fact (one asserted by a delta after that snapshot where there is one) is listed,
//      the last delta's facts are marked, and (recorded trace) every device has a machine fact;
//   3. the template filter narrows the list to that template's facts, the text filter to the
//      expected fact; the rule firings (rule and fact indices) are the recording's last 40 up to t,
//      the newest output line is its last one;
//      a click on a fact index in a firing filters the list to that fact;
//   4. the same game without the agents' lines shows "no agent facts recorded";
//   5. a live game (`llsfsim run --serve`): the agent browser lists the selected robot's facts;
//   6. a one-robot game whose agent makes a runtime error: the timeline marks it (an `agent`
//      marker naming the rule and its file:line; hovering shows it).
// When the recording has no `facts` lines (an llsfsim before the agents' trace), the test writes
// them itself in that format (synthetic: facts derived from the game's skill and agent lines) and
// skips step 5; it says which in its last line. Screenshots go to ARTIFACT_DIR (agent-*.png).
import {execFileSync} from "node:child_process";
import {mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync} from "node:fs";
import {tmpdir} from "node:os";
import {join} from "node:path";
import {gunzipSync, gzipSync} from "node:zlib";

import {check, launch, prerequisites, sourceDir, startLlsfsimServer, viewerDir} from "./e2e_lib.mjs";

const kName = "agent_e2e";
const {llsfsim, artifacts, chromium} =
  await prerequisites(kName, "agent_e2e.mjs", ["index.html", "viewer.js"]);

// A short game: 30 s exploration + 60 s production, two robots with the 2013 team agent.
const agents = join(sourceDir, "clips", "agents");
const scenario = `name: agent-e2e
refbox: {exploration_s: 30, production_s: 60}
robots:
  count: 2
  agent: [${JSON.stringify(join(agents, "common"))}, ${JSON.stringify(join(agents, "llsf2013"))}]
  config: {roles: [P1P2, P3], recycle: never}
`;
const liveScenario = scenario
  .replace("refbox: {exploration_s: 30, production_s: 60}", "refbox: {exploration_s: 60, production_s: 240}")
  .replace("name: agent-e2e", "name: agent-e2e-live");

const env = {...process.env, LLSF_VIEWER_DIR: join(viewerDir, "dist")};
const children = [];

/// Starts `llsfsim ARGS` in `cwd` and resolves with its URL (e2e_lib.mjs, startLlsfsimServer).
const startServer = (args, cwd) => startLlsfsimServer(llsfsim, args, {cwd, env, children});

// ---------------------------------------------------------------------------------------------
// The recording, read here independently of the viewer's code.

const readLines = (file) =>
  gunzipSync(readFileSync(file))
    .toString("utf8")
    .split("\n")
    .filter((l) => l.trim() !== "")
    .map((l) => JSON.parse(l));
const writeLines = (file, lines) =>
  writeFileSync(file, gzipSync(lines.map((l) => JSON.stringify(l)).join("\n") + "\n"));
const kTraceEvents = new Set(["facts", "fact", "rules"]);
const templateOf = (text) => /^\s*\(\s*([^\s()]+)/.exec(text)?.[1] ?? text.trim();

/// The facts of `robot` at `time` as docs/recording.md defines them: the last `facts` snapshot of
/// the robot with t <= time, then every later `fact` delta of the robot up to time.
/// Returns {facts: Map index -> text, snapshotT, deltaAdds: Map index -> t of the asserting delta}.
function factsAt(lines, robot, time) {
  let facts = null;
  let snapshotT = null;
  let deltaAdds = new Map();
  for (const l of lines.slice(1)) {
    if (l.t > time) break;
    if (l.robot !== robot) continue;
    if (l.e === "facts") {
      facts = new Map(l.facts.map(([i, text]) => [i, text]));
      snapshotT = l.t;
      deltaAdds = new Map();
    } else if (l.e === "fact") {
      facts ??= new Map();
      for (const i of l.r ?? []) {
        facts.delete(i);
        deltaAdds.delete(i);
      }
      for (const [i, text] of l.a ?? []) {
        facts.set(i, text);
        deltaAdds.set(i, l.t);
      }
    }
  }
  return {facts, snapshotT, deltaAdds};
}

/// The rule firings ([t, rule, indices]) and agent lines ([t, text], without the debug ones) of
/// `robot` up to `time`.
function historyAt(lines, robot, time) {
  const firings = [];
  const log = [];
  for (const l of lines.slice(1)) {
    if (l.t > time) break;
    if (l.robot !== robot) continue;
    if (l.e === "rules") for (const [rule, idx] of l.fired ?? []) firings.push([l.t, rule, idx]);
    if (l.e === "agent" && l.level !== "debug") log.push([l.t, l.text]);
  }
  return {firings, log};
}

/// Adds `facts`, `fact` and `rules` lines in the recorded format to a recording without them:
/// per robot a few static facts (the devices), `(time S US)` renewed every second, `(state S)`
/// and `(skill ...)` from its skill lines, `(decision "...")` from its agent lines; a snapshot at
/// the first cycle and every 20 s; a `rules` line per delta.
function synthesize(lines) {
  const [header, ...rest] = lines;
  const added = [];
  for (const robot of header.robots) {
    let next = 1;
    const facts = new Map();
    const byKey = new Map();  // "time", "state", "skill" -> index
    for (const d of header.devices) facts.set(next++, `(machine (name ${d.name}) (mtype UNKNOWN))`);
    const events = rest.filter((l) => l.robot === robot && (l.e === "skill" || l.e === "agent"));
    const end = rest[rest.length - 1].t;
    let lastSnapshot = -1e9;
    let ei = 0;
    for (let t = 0; t <= end; t = Math.round((t + 1) * 100) / 100) {
      const a = [];
      const r = [];
      const fired = [];
      const put = (key, text, rule) => {
        if (byKey.has(key)) {
          r.push(byKey.get(key));
          facts.delete(byKey.get(key));
        }
        const i = next++;
        facts.set(i, text);
        byKey.set(key, i);
        a.push([i, text]);
        fired.push([rule, byKey.get("time") !== undefined && key !== "time" ? [byKey.get("time"), i] : [i]]);
      };
      put("time", `(time ${Math.floor(t)} 0)`, "time-retract");
      for (; ei < events.length && events[ei].t <= t; ei++) {
        const e = events[ei];
        if (e.e === "skill") {
          put("state", `(state ${e.status === "RUNNING" ? "SKILL-EXECUTION" : "IDLE"})`, "skill-state");
          const name = JSON.stringify(e.string ?? "");
          put("skill", `(skill (name ${name}) (status ${e.status}))`, "skill-update");
        } else {
          const i = next++;
          const text = `(decision ${JSON.stringify(e.text ?? "")})`;
          facts.set(i, text);
          a.push([i, text]);
          fired.push(["decide", [i]]);
        }
      }
      if (t - lastSnapshot >= 20) {
        lastSnapshot = t;
        added.push({t, e: "facts", robot, facts: [...facts.entries()]});
      }
      const delta = {t, e: "fact", robot};
      if (a.length > 0) delta.a = a;
      if (r.length > 0) delta.r = r;
      added.push(delta);
      added.push({t, e: "rules", robot, fired});
    }
  }
  // Merged in time order, the game's own lines first at equal times.
  const merged = [...rest.map((l, k) => [l, 0, k]), ...added.map((l, k) => [l, 1, k])];
  merged.sort((x, y) => x[0].t - y[0].t || x[1] - y[1] || x[2] - y[2]);
  return [header, ...merged.map((m) => m[0])];
}

// ---------------------------------------------------------------------------------------------

const tmp = mkdtempSync(join(tmpdir(), "llsf-agent-e2e-"));
const recordings = join(tmp, "recordings");
mkdirSync(recordings);
let browser;
let ok = false;
try {
  writeFileSync(join(tmp, "agent.yaml"), scenario);
  writeFileSync(join(tmp, "live.yaml"), liveScenario);
  const recorded = join(recordings, "game.jsonl.gz");
  execFileSync(llsfsim, ["run", "agent.yaml", "--no-db", "-q", "--record", recorded],
               {cwd: tmp, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], env, timeout: 300_000});
  let lines = readLines(recorded);
  const real = lines.some((l) => l.e === "facts");
  if (!real) {
    lines = synthesize(lines);
    writeLines(recorded, lines);
  }
  // A game whose agent makes a runtime error at 2 s (step 6).
  writeFileSync(join(tmp, "broken.clp"),
                '(defrule broken (time ?s ?) (test (>= ?s 2)) (not (broke)) => (assert (broke))\n' +
                '  (eval "(no-such-fn)"))\n');
  writeFileSync(join(tmp, "broken.yaml"),
                "name: broken\nduration_s: 5\nstart: production\nrobots: {count: 1, agent: [broken.clp]}\n");
  execFileSync(llsfsim, ["run", "broken.yaml", "--no-db", "-q", "--record", join(recordings, "broken.jsonl.gz")],
               {cwd: tmp, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], env, timeout: 300_000});
  // The same game without the agents' trace, as recorded before it existed.
  writeLines(join(recordings, "old.jsonl.gz"), lines.filter((l) => !kTraceEvents.has(l.e)));

  mkdirSync(artifacts, {recursive: true});
  const {url} = await startServer(
    ["serve", "--port", "0", "--db", join(tmp, "none.db"), "--recordings", recordings], tmp);
  browser = await launch(chromium);
  const page = await browser.newPage({viewport: {width: 1500, height: 900}});
  const errors = [];
  page.on("pageerror", (e) => errors.push(`page error: ${e.message}`));
  page.on("console", (m) => {
    if (m.type() === "error") errors.push(`console error: ${m.text()}`);
  });
  const readyOrError = async (what) => {
    await page.waitForFunction(
      () => window.llsfViewer?.ready || document.getElementById("app")?.hasAttribute("data-error"),
      null,
      {timeout: 60_000},
    );
    const error = await page.getAttribute("#app", "data-error");
    check(error === null, `${what}: the page reports: ${error}`);
  };

  await page.goto(`${url}#/file/game.jsonl.gz`);
  await readyOrError("#/file/game.jsonl.gz");
  const header = lines[0];
  const robot = header.robots[1];
  const end = await page.evaluate(() => window.llsfViewer.endTime());
  check(end > 60, `the recording ends at ${end} s`);

  // 1. Click the robot on the field (at 10 % of the game: the robots have left their start).
  await page.evaluate((t) => window.llsfViewer.seek(t), end * 0.1);
  const field = await page.locator("canvas[data-field]").boundingBox();
  const pos = (await page.evaluate(() => window.llsfViewer.robots())).find((r) => r.name === robot);
  check(pos, `no ${robot} on the field`);
  {
    const margin = 14;
    const s = Math.max(1, Math.min((field.width - 2 * margin) / header.field.width,
                                   (field.height - 2 * margin) / header.field.height));
    const ox = (field.width - header.field.width * s) / 2;
    const oy = (field.height - header.field.height * s) / 2;
    await page.mouse.click(field.x + ox + pos.x * s, field.y + oy + (header.field.height - pos.y) * s);
  }
  await page.waitForSelector(`[data-agent-panel][data-robot="${robot}"]`, {state: "visible", timeout: 5000});
  check(await page.inputValue('select[data-agent="robot"]') === robot,
        `clicking ${robot} on the field did not select it in the agent browser`);

  // 2. Scrub: drag the timeline from 20 % to 60 % of its width.
  const tl = await page.locator("canvas[data-timeline]").boundingBox();
  const xAt = (frac) => tl.x + 8 + (tl.width - 16) * frac;
  await page.mouse.move(xAt(0.2), tl.y + 20);
  await page.mouse.down();
  for (const f of [0.3, 0.4, 0.5, 0.6]) await page.mouse.move(xAt(f), tl.y + 20);
  await page.mouse.up();
  await page.waitForTimeout(400);
  const time = await page.evaluate(() => window.llsfViewer.time());
  // (The panels follow at most 8 times a second; drawn now at the time reached, whatever the load.)
  await page.evaluate((t) => window.llsfViewer.seek(t), time);
  check(Math.abs(time - 0.6 * end) < 0.05 * end, `dragging the timeline to 60 % shows ${time} s of ${end} s`);
  const want = factsAt(lines, robot, time);
  check(want.facts && want.facts.size > 0, `the recording holds no facts of ${robot} at ${time} s`);
  const listed = async () =>
    page.$$eval('[data-agent="facts"] .fact', (rows) =>
      rows.map((r) => [Number(r.getAttribute("data-index")), r.textContent.replace(/^f-\d+/, "")]));
  await page.waitForFunction(
    (n) => document.querySelector('[data-agent="facts"]')?.getAttribute("data-total") === String(n),
    want.facts.size, {timeout: 5000}).catch(() => {});
  const rows = await listed();
  const wantRows = [...want.facts.entries()].sort((a, b) => a[0] - b[0]);
  check(JSON.stringify(rows) === JSON.stringify(wantRows.slice(0, 400)),
        `the facts of ${robot} at ${time} s differ from the recording's:\n` +
          `listed ${rows.length}: ${JSON.stringify(rows.slice(0, 8))}...\n` +
          `recording ${wantRows.length}: ${JSON.stringify(wantRows.slice(0, 8))}...`);
  // The expected fact: one asserted by a delta after the snapshot (the newest), else any.
  const byDelta = [...want.deltaAdds.entries()].sort((a, b) => b[1] - a[1] || b[0] - a[0]);
  const expectIndex = byDelta.length > 0 ? byDelta[0][0] : wantRows[wantRows.length - 1][0];
  const expectText = want.facts.get(expectIndex);
  check(rows.some(([i, text]) => i === expectIndex && text === expectText),
        `the agent browser does not list f-${expectIndex} ${expectText} at ${time} s`);
  // The facts of the last delta up to the time are marked.
  const lastDelta = lines.slice(1).filter((l) => l.e === "fact" && l.robot === robot && l.t <= time).pop();
  const marked = await page.$$eval('[data-agent="facts"] .fact.new',
                                   (r) => r.map((x) => Number(x.getAttribute("data-index"))));
  const wantMarked =
    (lastDelta?.a ?? []).map(([i]) => i).filter((i) => want.facts.has(i)).sort((x, y) => x - y);
  check(JSON.stringify(marked) === JSON.stringify(wantMarked),
        `marked as the last change: ${JSON.stringify(marked)}, ` +
          `the recording's last delta: ${JSON.stringify(wantMarked)}`);
  // The 2013 agent knows every device as a machine fact.
  const machines = rows.filter(([, text]) => templateOf(text) === "machine").length;
  check(!real || machines === header.devices.length,
        `${machines} machine facts listed, the field has ${header.devices.length} devices`);
  await page.screenshot({path: join(artifacts, "agent-facts.png")});

  // 3. The template filter: only that template's facts; the text filter: the expected fact.
  const template = templateOf(expectText);
  const options = await page.$$eval('select[data-agent="template"] option', (os) => os.map((o) => o.value));
  const templates = new Set(wantRows.map(([, text]) => templateOf(text)));
  check(JSON.stringify(options.filter((o) => o !== "")) === JSON.stringify([...templates].sort()),
        `the template choices ${JSON.stringify(options)} are not the templates present ` +
          JSON.stringify([...templates]));
  await page.selectOption('select[data-agent="template"]', template);
  await page.waitForTimeout(300);
  const narrowed = await listed();
  const wantNarrowed = wantRows.filter(([, text]) => templateOf(text) === template);
  check(narrowed.length < rows.length, `the template filter ${template} did not narrow the list`);
  check(JSON.stringify(narrowed) === JSON.stringify(wantNarrowed.slice(0, 400)),
        `with template ${template}: listed ${JSON.stringify(narrowed.slice(0, 5))}, ` +
          `expected ${JSON.stringify(wantNarrowed.slice(0, 5))}`);
  await page.screenshot({path: join(artifacts, "agent-template.png")});
  await page.selectOption('select[data-agent="template"]', "");
  await page.fill('input[data-agent="filter"]', expectText);
  await page.waitForTimeout(300);
  const found = await listed();
  check(found.some(([i]) => i === expectIndex) &&
          found.every(([, text]) => text.toLowerCase().includes(expectText.toLowerCase())),
        `the text filter ${expectText} lists ${JSON.stringify(found)}`);
  await page.fill('input[data-agent="filter"]', "");
  // The rule firings and output lines: the newest shown first, the recording's last up to t.
  const hist = historyAt(lines, robot, time);
  const shownFirings = await page.$$eval('[data-agent="rules"] .firing', (r) =>
    r.map((x) => [x.getAttribute("data-rule"),
                  [...x.querySelectorAll(".fi")].map((f) => Number(f.textContent.slice(2)))]));
  const wantFirings = hist.firings.slice(-40).reverse().map(([, rule, idx]) => [rule, idx]);
  check(wantFirings.length > 0 && JSON.stringify(shownFirings) === JSON.stringify(wantFirings),
        `the rule firings shown (newest first) ${JSON.stringify(shownFirings.slice(0, 3))}... are not ` +
          `the recording's last ones up to ${time} s ${JSON.stringify(wantFirings.slice(0, 3))}...`);
  if (hist.log.length > 0) {
    const firstLog = await page.$eval('[data-agent="log"]', (e) => e.firstElementChild?.textContent ?? "");
    const lastLog = hist.log[hist.log.length - 1][1];
    check(firstLog.endsWith(lastLog),
          `the newest log line shown is "${firstLog}", the recording's "${lastLog}"`);
  }
  // A click on a matched fact's index in a firing filters the list to that fact.
  const clickable = await page.$$eval('[data-agent="rules"] .firing .fi',
                                      (r) => r.map((x) => Number(x.textContent.slice(2))));
  const k = clickable.findIndex((i) => want.facts.has(i));
  if (k >= 0) {
    await page.locator('[data-agent="rules"] .firing .fi').nth(k).click();
    await page.waitForTimeout(300);
    const one = await listed();
    check(JSON.stringify(one) === JSON.stringify([[clickable[k], want.facts.get(clickable[k])]]),
          `a click on f-${clickable[k]} in a firing lists ${JSON.stringify(one)}`);
    await page.fill('input[data-agent="filter"]', "");
  }
  const skill = await page.textContent('[data-agent="skill"]');
  check(skill && skill.length > 0, "the agent browser shows no skill");

  // 4. A recording without the agents' trace.
  await page.goto(`${url}#/file/old.jsonl.gz`);
  await readyOrError("#/file/old.jsonl.gz");
  await page.evaluate((r) => window.llsfViewer.selectRobot(r), robot);
  await page.evaluate((t) => window.llsfViewer.seek(t), time);
  const none = await page.textContent('[data-agent="nofacts"]');
  check(none === "no agent facts recorded", `an old recording shows "${none}"`);

  // 5. Live: the selected robot's facts arrive with the game (only with the real trace).
  let liveFacts = -1;
  if (real) {
    const live = await startServer(
      ["run", "live.yaml", "--no-db", "--no-record", "--speed", "20", "--serve", "--serve-exit",
       "--port", "0"],
      tmp);
    await page.goto(`${live.url}#/live`);
    await readyOrError("#/live");
    await page.evaluate((r) => window.llsfViewer.selectRobot(r), robot);
    await page.waitForFunction(() => (window.llsfViewer.agent()?.facts.length ?? 0) > 0, null,
                               {timeout: 15_000});
    await page.waitForTimeout(500);
    liveFacts = await page.locator('[data-agent="facts"] .fact').count();
    await page.screenshot({path: join(artifacts, "agent-live.png")});
    check(liveFacts > 0, "the live agent browser lists no facts");
  }

  // 6. An agent's runtime error is a marker on the timeline.
  await page.goto(`${url}#/file/broken.jsonl.gz`);
  await readyOrError("#/file/broken.jsonl.gz");
  const marks = (await page.evaluate(() => window.llsfViewer.debug())).markers;
  const agentError = marks.find((m) => m.kind === "agent");
  check(agentError && /robot1 runtime-error rule broken \(.*broken\.clp:1\): .*no-such-fn/.test(agentError.label) &&
        Math.abs(agentError.t - 2) < 0.2,
        `no timeline marker for the agent's runtime error: ${JSON.stringify(marks)}`);
  const timelineBox = await page.locator("canvas[data-timeline]").boundingBox();
  await page.mouse.move(timelineBox.x + agentError.x, timelineBox.y + timelineBox.height * 0.2);
  const agentTip = await page.textContent(".tip");
  check(agentTip.includes("runtime-error rule broken"), `hovering the agent error shows "${agentTip}"`);
  await page.screenshot({path: join(artifacts, "agent-error-marker.png")});

  check(errors.length === 0, errors.join("\n"));
  ok = true;
  console.log(
    `${kName}: ok: ${real ? "recorded" : "synthetic"} agent trace; ${robot} at ${time.toFixed(2)} s: ` +
      `${rows.length} facts as in the recording (snapshot at ${want.snapshotT} s), f-${expectIndex} ` +
      `${expectText}; template ${template}: ${narrowed.length}; ` +
      (real ? `live: ${liveFacts} facts` : "live: skipped (no trace recorded)") +
      "; the agent's runtime error marked on the timeline" +
      `; screenshots in ${artifacts}`,
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
