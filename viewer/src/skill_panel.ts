// SPDX-License-Identifier: MIT
// A robot's skill as a participant debugs it (the side panel, one section per robot): the skill's
// current state and since when, and its recent history up to the shown time -- state changes
// (transitions), the lines it logged (print, printf, print_warn, ...) and the navigator's refusals
// and failures -- each line a link that seeks the replay to its time. Also the verdict banner of an
// exercise's recording.
import {fmtTime} from "./agent_panel";
import type {Recording, RobotState, SkillLog, Verdict} from "./recording";
import {el} from "./report_view";

/// Lines of a robot's history shown in its section (the newest).
export const kSkillLogShown = 10;

/// What the section of one robot shows (the test hook reports it).
export interface SkillView {
  robot: string;
  skill: string;
  state: string;
  /// The shown history lines' texts, oldest first.
  lines: string[];
}

/// Navigator refusals and failures listed apart (the newest), so that log lines do not push
/// them out.
export const kNavShown = 5;

/// The newest `max` entries of `robot` with t <= time (of the kinds `kinds`), oldest first.
export function recentSkillLog(
  rec: Recording,
  robot: string,
  time: number,
  max: number,
  kinds: readonly SkillLog["kind"][] = ["log", "state", "nav"],
): SkillLog[] {
  const out: SkillLog[] = [];
  for (let i = rec.skillLogUpTo(time) - 1; i >= 0 && out.length < max; i--) {
    const e = rec.skillLog[i];
    if (e.robot === robot && kinds.includes(e.kind)) out.push(e);
  }
  return out.reverse();
}

function lineRow(e: SkillLog, seek: (t: number) => void): HTMLElement {
  const row = el(
    "div",
    {class: `sline ${e.kind} ${e.level}`, title: `${fmtTime(e.t)}: click to go there`},
    el("span", {class: "at"}, fmtTime(e.t)),
    " ",
    e.kind === "log" && e.level !== "info" ? `${e.level}: ${e.text}` : e.text,
  );
  row.onclick = () => seek(e.t);
  return row;
}

/// The section of robot `name` at `time`; `seek` is called with a line's time when it is clicked.
export function skillSection(
  rec: Recording,
  name: string,
  r: RobotState | undefined,
  time: number,
  seek: (t: number) => void,
): {node: HTMLElement; view: SkillView} {
  const lines = recentSkillLog(rec, name, time, kSkillLogShown, ["log", "state"]);
  const navs = recentSkillLog(rec, name, time, kNavShown, ["nav"]);
  const state = r?.skillState ?? "";
  const head = el(
    "div",
    {class: "sstate", "data-skill-state": state},
    "state ",
    el("b", {}, state || "–"),
    state && r && r.skillStateT >= 0 ? ` since ${fmtTime(r.skillStateT)}` : "",
  );
  const list = el("div", {class: "slog", "data-skill-log": name}, ...lines.map((e) => lineRow(e, seek)));
  const navList = el("div", {class: "slog", "data-nav-log": name}, ...navs.map((e) => lineRow(e, seek)));
  const node = el(
    "div",
    {class: "skillbox"},
    head,
    lines.length > 0 ? list : el("div", {class: "info"}, "no skill lines yet"),
    navs.length > 0 ? el("div", {class: "sstate"}, "navigator refused or failed:") : "",
    navs.length > 0 ? navList : "",
  );
  return {
    node,
    view: {
      robot: name,
      skill: r?.skillName ?? "",
      state,
      lines: [...lines, ...navs].sort((a, b) => a.t - b.t).map((e) => e.text),
    },
  };
}

/// The verdict banner's content (PASS/FAIL and the score), or null to hide it. Shown from the
/// verdict's time on (the end of the recording).
export function verdictBanner(v: Verdict | null, time: number): HTMLElement | null {
  if (!v || time < v.t - 1e-6) return null;
  const pass = v.result === "PASS";
  return el(
    "div",
    {class: `verdict ${pass ? "pass" : "fail"}`, "data-verdict": v.result},
    el("b", {}, v.result),
    ` ${v.score}`,
    v.why ? el("div", {class: "why"}, v.why) : "",
  );
}
