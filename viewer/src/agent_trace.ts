// SPDX-License-Identifier: MIT
// The agents' trace of a recording (docs/recording.md: `facts`, `fact`, `rules`, `agent` lines),
// per robot and indexed for seeking: the facts of a robot at time t are its last `facts`
// snapshot at or before t with every later `fact` delta up to t applied. Besides the recorded
// snapshots, one is kept every kSnapshotEvery deltas, so a seek costs one snapshot's copy plus at
// most that many deltas, whatever the recording's snapshot period; moving forward a little (playback)
// applies only the deltas in between. Recordings without these lines have an empty trace.
import {countAtOrBefore, upperBound} from "./search";

/// A fact: its index in the agent's fact base and its text, `(state IDLE)`.
export type Fact = [number, string];

/// One rule firing of an agent cycle.
export interface Firing {
  t: number;
  rule: string;
  facts: number[];
}

/// One line of an agent's output (`agent` lines).
export interface LogLine {
  t: number;
  level: string;
  text: string;
}

/// The facts of a robot at a time (sorted by index) and what they were computed from.
export interface FactsAt {
  /// The facts, sorted by index; empty when `recorded` is false.
  facts: Fact[];
  /// Whether any fact of this robot at or before the time is recorded.
  recorded: boolean;
  /// The number of the robot's fact entries (snapshots and deltas) up to the time: a key that
  /// changes whenever the facts may have.
  version: number;
  /// The robot's last delta at or before the time: its time, the indices it asserted, the number
  /// it retracted.
  latest: {t: number; added: number[]; removed: number};
}

/// The template of a fact: the first symbol after "(" (`machine` for `(machine (name M1))`).
export function templateOf(text: string): string {
  const m = /^\s*\(\s*([^\s()]+)/.exec(text);
  return m ? m[1] : text.trim();
}

const noFacts = (): FactsAt => ({
  facts: [],
  recorded: false,
  version: 0,
  latest: {t: 0, added: [], removed: 0},
});

const kSnapshotEvery = 200;  // fact entries between the trace's own snapshots


/// A robot's trace: fact entries in file order, snapshots of the fact base, rule firings, log.
class RobotTrace {
  /// Fact entries: a recorded snapshot (`full`) or a delta (`add`, `del`).
  readonly entryT: number[] = [];
  private readonly entries: {full?: Fact[]; add?: Fact[]; del?: number[]}[] = [];
  /// Snapshots of the fact base after entry `index` (recorded, or kept every kSnapshotEvery).
  private readonly snapshots: {index: number; facts: Fact[]}[] = [];
  /// The fact base after the last entry (the builder of the snapshots).
  private readonly current = new Map<number, string>();
  /// The `rules` lines: their times, their `fired` lists as read (checked when shown), and the
  /// number of firings before each (the firings are made objects only when shown: a game has
  /// tens of thousands).
  readonly rulesT: number[] = [];
  readonly rulesFired: unknown[][] = [];
  readonly firingsBefore: number[] = [];
  firings = 0;
  readonly logT: number[] = [];
  readonly log: LogLine[] = [];
  /// The lines above debug level.
  readonly infoT: number[] = [];
  readonly info: LogLine[] = [];
  // The seek cursor: the fact base after `cursorIndex` entries.
  private cursorFacts: Map<number, string> | null = null;
  private cursorIndex = 0;
  private cursorSorted: Fact[] | null = null;

  addSnapshot(t: number, facts: Fact[]): void {
    this.current.clear();
    for (const [i, text] of facts) this.current.set(i, text);
    this.entryT.push(t);
    this.entries.push({full: facts});
    this.snapshots.push({index: this.entries.length, facts: sortedFacts(this.current)});
  }

  addDelta(t: number, add: Fact[] | undefined, del: number[] | undefined): void {
    applyDelta(this.current, add, del);
    this.entryT.push(t);
    this.entries.push({add, del});
    const last = this.snapshots.length > 0 ? this.snapshots[this.snapshots.length - 1].index : 0;
    if (this.entries.length - last >= kSnapshotEvery) {
      this.snapshots.push({index: this.entries.length, facts: sortedFacts(this.current)});
    }
  }

  /// The facts after the entries with t <= time.
  factsAt(time: number): FactsAt {
    const target = upperBound(this.entryT, time);
    if (target === 0) return noFacts();
    // Forward by a few entries from the cursor, else from the last snapshot at or before target.
    if (!this.cursorFacts || target < this.cursorIndex || target - this.cursorIndex > kSnapshotEvery) {
      const snap = this.snapshotAtOrBefore(target);
      if (!this.cursorFacts || target < this.cursorIndex || snap.index > this.cursorIndex) {
        this.cursorFacts = new Map(snap.facts);
        this.cursorIndex = snap.index;
        this.cursorSorted = null;
      }
    }
    while (this.cursorIndex < target) {
      const e = this.entries[this.cursorIndex++];
      if (e.full) {
        this.cursorFacts.clear();
        for (const [i, text] of e.full) this.cursorFacts.set(i, text);
      } else {
        applyDelta(this.cursorFacts, e.add, e.del);
      }
      this.cursorSorted = null;
    }
    this.cursorSorted ??= sortedFacts(this.cursorFacts);
    // The last delta (a snapshot of the same cycle may follow it).
    let latest = {t: 0, added: [] as number[], removed: 0};
    for (let k = target - 1; k >= 0; k--) {
      const e = this.entries[k];
      if (!e.full) {
        latest = {t: this.entryT[k], added: (e.add ?? []).map((f) => f[0]), removed: e.del?.length ?? 0};
        break;
      }
      if (k === 0 || this.entryT[k - 1] !== this.entryT[k]) break;
    }
    return {facts: this.cursorSorted, recorded: true, version: target, latest};
  }

  private snapshotAtOrBefore(index: number): {index: number; facts: Fact[]} {
    const lo = countAtOrBefore(this.snapshots, (s) => s.index, index);
    return lo > 0 ? this.snapshots[lo - 1] : {index: 0, facts: []};
  }
}

function applyDelta(facts: Map<number, string>, add: Fact[] | undefined, del: number[] | undefined): void {
  if (del) for (const i of del) facts.delete(i);
  if (add) for (const [i, text] of add) facts.set(i, text);
}

function sortedFacts(facts: Map<number, string>): Fact[] {
  return [...facts.entries()].sort((a, b) => a[0] - b[0]);
}

/// A fact list ([[index, text], ...]) as read, when its entries are well-formed (checked on the
/// first: the writer writes them all alike); otherwise the well-formed entries.
function factList(v: unknown): Fact[] | undefined {
  if (!Array.isArray(v)) return undefined;
  const ok = (f: unknown) => Array.isArray(f) && typeof f[0] === "number" && typeof f[1] === "string";
  if (v.length === 0 || (ok(v[0]) && ok(v[v.length - 1]))) return v as Fact[];
  return v.filter(ok) as Fact[];
}

function indexList(v: unknown): number[] | undefined {
  if (!Array.isArray(v)) return undefined;
  const isIndex = (x: unknown): x is number => typeof x === "number";
  return v.every(isIndex) ? (v as number[]) : v.filter(isIndex);
}

/// The trace of every robot of a recording.
export class AgentTrace {
  private readonly robots = new Map<string, RobotTrace>();
  /// Whether any `facts` or `fact` line was read (a recording with agents' facts).
  hasFacts = false;
  /// Whether any `rules` line was read.
  hasRules = false;

  private robot(name: string): RobotTrace {
    let r = this.robots.get(name);
    if (!r) {
      r = new RobotTrace();
      this.robots.set(name, r);
    }
    return r;
  }

  /// Takes a line if it belongs to the trace (`facts`, `fact`, `rules`; `agent` and `note` are
  /// read too but left to the caller as well). Returns true when the line is the trace's only (no game state
  /// depends on it).
  // eslint-disable-next-line @typescript-eslint/no-explicit-any
  take(line: {t: number; e?: string; [key: string]: any}): boolean {
    const e = line.e;
    if (e !== "facts" && e !== "fact" && e !== "rules" && e !== "agent" && e !== "note") return false;
    if (typeof line.robot !== "string") return e !== "agent" && e !== "note";
    const r = this.robot(line.robot);
    switch (e) {
      case "facts":
        this.hasFacts = true;
        r.addSnapshot(line.t, factList(line.facts) ?? []);
        return true;
      case "fact":
        this.hasFacts = true;
        r.addDelta(line.t, factList(line.a), indexList(line.r));
        return true;
      case "rules":
        this.hasRules = true;
        if (Array.isArray(line.fired) && line.fired.length > 0) {
          r.rulesT.push(line.t);
          r.rulesFired.push(line.fired);
          r.firingsBefore.push(r.firings);
          r.firings += line.fired.length;
        }
        return true;
      default: {
        // `agent` lines, and `note` lines about the robot (e.g. its agent reloaded in a paced run).
        const level = e === "note" ? "note" : String(line.level ?? "");
        const l = {t: line.t, level, text: String(line.text ?? "")};
        r.logT.push(line.t);
        r.log.push(l);
        if (l.level !== "debug") {
          r.infoT.push(line.t);
          r.info.push(l);
        }
        return false;
      }
    }
  }

  /// The facts of `robot` at `time` (empty, `recorded` false, when none are recorded up to then).
  factsAt(robot: string, time: number): FactsAt {
    const r = this.robots.get(robot);
    return r ? r.factsAt(time) : noFacts();
  }

  /// The last `n` rule firings of `robot` at or before `time`, oldest first.
  firingsAt(robot: string, time: number, n: number): Firing[] {
    const r = this.robots.get(robot);
    if (!r) return [];
    const out: Firing[] = [];
    for (let k = upperBound(r.rulesT, time) - 1; k >= 0 && out.length < n; k--) {
      const fired = r.rulesFired[k];
      for (let j = fired.length - 1; j >= 0 && out.length < n; j--) {
        const f = fired[j];
        if (!Array.isArray(f)) continue;
        out.push({t: r.rulesT[k], rule: String(f[0] ?? ""), facts: indexList(f[1]) ?? []});
      }
    }
    return out.reverse();
  }

  /// The number of rule firings of `robot` at or before `time`.
  firingCount(robot: string, time: number): number {
    const r = this.robots.get(robot);
    if (!r) return 0;
    const k = upperBound(r.rulesT, time);
    return k === 0 ? 0 : r.firingsBefore[k - 1] + r.rulesFired[k - 1].length;
  }

  /// The last `n` agent lines of `robot` at or before `time`, oldest first (`debug`: with the
  /// debug lines).
  logAt(robot: string, time: number, n: number, debug: boolean): LogLine[] {
    const r = this.robots.get(robot);
    if (!r) return [];
    const [ts, lines] = debug ? [r.logT, r.log] : [r.infoT, r.info];
    const end = upperBound(ts, time);
    return lines.slice(Math.max(0, end - n), end);
  }

  /// The number of agent lines of `robot` at or before `time` (`debug`: with the debug lines).
  logCount(robot: string, time: number, debug: boolean): number {
    const r = this.robots.get(robot);
    return r ? upperBound(debug ? r.logT : r.infoT, time) : 0;
  }
}
