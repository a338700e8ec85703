// SPDX-License-Identifier: MIT
// The agent browser of the replay and live pages: for the selected robot at the shown time its
// facts (index and text, filterable by template and by text), its last rule firings (time, rule,
// matched fact indices), its skill string and status, and its last output lines. Everything comes
// from the recording's AgentTrace (agent_trace.ts) and the derived State; the DOM is rebuilt
// only for the parts whose inputs changed, so playing a game with the panel open stays smooth.
import {templateOf, type Fact} from "./agent_trace";
import {kRobotColors} from "./field";
import type {Recording, State} from "./recording";
import {el} from "./report_view";

/// m:ss.s of a game time in seconds.
export function fmtTime(t: number): string {
  const m = Math.floor(t / 60);
  const s = t - m * 60;
  return `${m}:${s.toFixed(1).padStart(4, "0")}`;
}

const kMaxFacts = 400;  // fact rows drawn at most (the count says how many match)
const kFirings = 40;  // rule firings shown
const kLogLines = 30;  // output lines shown

/// What the list shows: the facts at the time and those the filters let through.
export interface AgentView {
  robot: string;
  time: number;
  recorded: boolean;
  facts: Fact[];
  shown: Fact[];
}

export class AgentPanel {
  readonly root = el("div", {class: "agentpanel", "data-agent-panel": ""});
  /// The selected robot ("" before the header is known).
  robot = "";
  private readonly robotSel = el("select", {"data-agent": "robot", title: "robot"});
  private readonly skill = el("div", {class: "askill", "data-agent": "skill"});
  private readonly count = el("span", {class: "acount", "data-agent": "count"});
  private readonly templateSel = el("select", {"data-agent": "template", title: "template"});
  private readonly filter = el("input", {
    type: "search",
    placeholder: "filter text",
    "data-agent": "filter",
    title: "show the facts that contain this text (case-insensitive; f-12 followed by a space: fact 12)",
  });
  private readonly factList = el("div", {class: "alist facts", "data-agent": "facts"});
  private readonly rules = el("div", {class: "alist rules", "data-agent": "rules"});
  private readonly log = el("div", {class: "alist log", "data-agent": "log"});
  private readonly debugBox = el("input", {type: "checkbox", "data-agent": "debug"});
  private robotsKey = "";
  private templatesKey = "";
  private factsKey = "";
  private rulesKey = "";
  private rulesCount = 0;
  private logKey = "";
  private logCount = 0;
  /// The rows of the facts shown, by index (reused while the fact is shown with the same text).
  private readonly factRows = new Map<number, {text: string; row: HTMLElement}>();
  private skillKey = "";
  private last: AgentView | null = null;

  constructor(
    private readonly rec: Recording,
    onClose: () => void,
    /// Called when the selection or a filter changed (the owner draws the panel again).
    private readonly onChange: () => void,
  ) {
    const close = el(
      "button",
      {class: "aclose", title: "close the agent browser", "data-agent": "close"},
      "×",
    );
    close.onclick = onClose;
    this.robotSel.onchange = () => this.select(this.robotSel.value);
    this.templateSel.onchange = () => this.invalidate();
    this.filter.oninput = () => this.invalidate();
    this.debugBox.onchange = () => this.invalidate();
    this.root.append(
      el("div", {class: "ahead"}, el("b", {}, "agent "), this.robotSel, close),
      this.skill,
      el("div", {class: "asec"}, el("b", {}, "facts "), this.count),
      el("div", {class: "afilter"}, this.templateSel, this.filter),
      this.factList,
      el("div", {class: "asec"}, el("b", {}, "rules fired"), ` (last ${kFirings})`),
      this.rules,
      el(
        "div",
        {class: "asec"},
        el("b", {}, "log"),
        ` (last ${kLogLines}) `,
        el("label", {title: "with the debug lines (e.g. CLIPS' watch output)"}, this.debugBox, " debug"),
      ),
      this.log,
    );
  }

  /// Selects `robot` (its facts, rules and log show at the next render).
  select(robot: string): void {
    if (robot === this.robot) return;
    this.robot = robot;
    this.robotSel.value = robot;
    this.root.setAttribute("data-robot", robot);
    this.invalidate();
  }

  /// Filters the list to fact `index` (a click on it in a rule firing).
  private showFact(index: number): void {
    this.templateSel.value = "";
    this.filter.value = `f-${index} `;
    this.invalidate();
  }

  /// The last rendered view (for the test hook).
  view(): AgentView | null {
    return this.last;
  }

  private invalidate(): void {
    this.templatesKey = this.factsKey = this.rulesKey = this.logKey = this.skillKey = "";
    this.onChange();
  }

  /// Shows the selected robot at `time` (`state`: the derived game state at that time).
  render(time: number, state: State): void {
    const h = this.rec.header;
    if (!h) return;
    const robotsKey = h.robots.join(" ");
    if (robotsKey !== this.robotsKey) {
      this.robotsKey = robotsKey;
      this.robotSel.replaceChildren(
        ...h.robots.map((r, i) =>
          el("option", {value: r, style: `color:${kRobotColors[i % kRobotColors.length]}`}, r),
        ),
      );
      if (!h.robots.includes(this.robot)) this.robot = h.robots[0] ?? "";
      this.robotSel.value = this.robot;
      this.root.setAttribute("data-robot", this.robot);
    }
    const name = this.robot;
    const trace = this.rec.trace;

    // Skill string and status, with the last result or error.
    const rs = state.robots[name];
    const skillKey = `${name}\n${rs?.skill}\n${rs?.status}\n${rs?.skillInfo}`;
    if (skillKey !== this.skillKey) {
      this.skillKey = skillKey;
      const cls = rs?.status === "FAILED" ? "failed" : rs?.status === "FINAL" ? "final" : "";
      this.skill.replaceChildren(
        rs?.skill
          ? el("span", {class: `sk ${cls}`}, `${rs.skill} `, el("b", {"data-status": rs.status}, rs.status))
          : el("span", {class: "info"}, "no skill yet"),
        rs?.skillInfo ? el("div", {class: "info"}, rs.skillInfo) : "",
      );
    }

    // Facts: the templates present, then the list through the filters.
    const at = trace.factsAt(name, time);
    const template = this.templateSel.value;
    const text = this.filter.value.trim().toLowerCase();
    const factsKey = `${name}\n${at.version}\n${template}\n${text}`;
    if (factsKey !== this.factsKey) {
      this.factsKey = factsKey;
      const counts = new Map<string, number>();
      for (const [, f] of at.facts) {
        const tpl = templateOf(f);
        counts.set(tpl, (counts.get(tpl) ?? 0) + 1);
      }
      const names = [...counts.keys()].sort();
      if (template !== "" && !counts.has(template)) names.push(template);
      const templatesKey = names.map((n) => `${n}:${counts.get(n) ?? 0}`).join(" ");
      if (templatesKey !== this.templatesKey) {
        this.templatesKey = templatesKey;
        this.templateSel.replaceChildren(
          el("option", {value: ""}, `all templates (${counts.size})`),
          ...names.map((n) => el("option", {value: n}, `${n} (${counts.get(n) ?? 0})`)),
        );
        this.templateSel.value = template;
      }
      const shown = at.facts.filter(
        ([i, f]) =>
          (template === "" || templateOf(f) === template) &&
          (text === "" || `f-${i} ${f.toLowerCase()}`.includes(text)),
      );
      this.last = {robot: name, time, recorded: at.recorded, facts: at.facts, shown};
      const last = at.latest.added.length + at.latest.removed > 0
        ? ` · last change ${fmtTime(at.latest.t)}: +${at.latest.added.length} −${at.latest.removed}`
        : "";
      const total = at.facts.length;
      const n = shown.length === total ? `${total}` : `${shown.length} of ${total}`;
      this.count.textContent = at.recorded ? n + last : "";
      this.factList.setAttribute("data-shown", String(shown.length));
      this.factList.setAttribute("data-total", String(at.facts.length));
      if (!at.recorded) {
        this.factRows.clear();
        this.factList.replaceChildren(
          el(
            "div",
            {class: "info", "data-agent": "nofacts"},
            trace.hasFacts ? `no facts of ${name} recorded yet` : "no agent facts recorded",
          ),
          ...(trace.hasFacts
            ? []
            : [
                el(
                  "div",
                  {class: "info"},
                  "(`llsfsim run` records them unless --no-record-agents; `batch` with --record-agents)",
                ),
              ]),
        );
      } else {
        this.showFacts(
          shown.slice(0, kMaxFacts),
          new Set(at.latest.added),
          shown.length > kMaxFacts
            ? el("div", {class: "info"}, `… ${shown.length - kMaxFacts} more: narrow the filter`)
            : shown.length === 0
              ? el("div", {class: "info"}, "no fact matches the filter")
              : null,
        );
      }
    } else if (this.last) {
      this.last.time = time;
    }

    // The last rule firings up to the time.
    const nFired = trace.firingCount(name, time);
    const rulesKey = `${name}`;
    if (rulesKey !== this.rulesKey || nFired !== this.rulesCount) {
      let facts: Map<number, string> | null = null;
      newestFirst(
        this.rules,
        rulesKey === this.rulesKey ? this.rulesCount : -1,
        nFired,
        kFirings,
        (n) => trace.firingsAt(name, time, n),
        (f) => {
          facts ??= new Map(at.facts);
          return el(
            "div",
            {class: "firing", "data-rule": f.rule},
            el("span", {class: "at"}, fmtTime(f.t)),
            ` ${f.rule} `,
            ...f.facts.map((i) => {
              const e = el("span", {class: "fi", title: facts!.get(i) ?? "(retracted since)"}, `f-${i} `);
              e.onclick = () => this.showFact(i);
              return e;
            }),
          );
        },
        trace.hasRules ? "no rule fired yet" : "no rule firings recorded",
      );
      this.rulesKey = rulesKey;
      this.rulesCount = nFired;
    }

    // The last output lines up to the time.
    const debug = this.debugBox.checked;
    const nLog = trace.logCount(name, time, debug);
    const logKey = `${name}\n${debug}`;
    if (logKey !== this.logKey || nLog !== this.logCount) {
      newestFirst(
        this.log,
        logKey === this.logKey ? this.logCount : -1,
        nLog,
        kLogLines,
        (n) => trace.logAt(name, time, n, debug),
        (l) =>
          el("div", {class: `logline ${l.level}`}, el("span", {class: "at"}, fmtTime(l.t)), ` ${l.text}`),
        "no output yet",
      );
      this.logKey = logKey;
      this.logCount = nLog;
    }
  }

  /// Shows `facts` (sorted by index) and `tail` after them, keeping the rows of facts that are
  /// still shown (a step of the game changes a few facts of a few hundred).
  /// `latest`: the indices asserted by the last delta (marked).
  private showFacts(facts: Fact[], latest: Set<number>, tail: HTMLElement | null): void {
    const keep = new Set<Node>();
    const rows = facts.map(([i, f]) => {
      let c = this.factRows.get(i);
      if (!c || c.text !== f) {
        const index = el("span", {class: "fi"}, `f-${i}`);
        const row = el("div", {class: "fact", "data-index": String(i)}, index, f);
        c = {text: f, row};
        this.factRows.set(i, c);
      }
      c.row.classList.toggle("new", latest.has(i));
      keep.add(c.row);
      return c.row;
    });
    for (const child of [...this.factList.children]) if (!keep.has(child)) child.remove();
    for (const [i, c] of this.factRows) if (!keep.has(c.row)) this.factRows.delete(i);
    let at = this.factList.firstChild;
    for (const r of rows) {
      if (at === r) at = at.nextSibling;
      else this.factList.insertBefore(r, at);
    }
    if (tail) this.factList.append(tail);
  }
}

/// Shows the last `max` of `count` items in `list`, newest first. When the list showed the first
/// `before` of the same items (-1: other items) and a few more came, only those are added on top.
function newestFirst<T>(
  list: HTMLElement,
  before: number,
  count: number,
  max: number,
  last: (n: number) => T[],
  row: (item: T) => HTMLElement,
  empty: string,
): void {
  const added = count - before;
  if (before > 0 && added > 0 && added < max) {
    for (const item of last(added)) list.prepend(row(item));
    while (list.children.length > max) list.lastElementChild!.remove();
    return;
  }
  const items = last(max);
  list.replaceChildren(
    ...(items.length === 0 ? [el("div", {class: "info"}, empty)] : items.reverse().map(row)),
  );
}
