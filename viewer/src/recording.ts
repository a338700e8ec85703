// SPDX-License-Identifier: MIT
// A recording (docs/recording.md) in memory, indexed for replay: lines are appended as they arrive
// (a download in chunks, or a live game's WebSocket), frames are indexed by time for binary
// search, and the derived state of the game (pucks, lamps, skills, locks, orders, points, ...) is
// rebuilt incrementally with snapshots every few seconds, so seeking anywhere costs at most one
// snapshot's copy plus a few seconds of lines. The agents' trace (`facts`, `fact`, `rules` lines)
// is kept apart, per robot, in an AgentTrace (agent_trace.ts): no game state depends on it.
import {AgentTrace} from "./agent_trace";
import {countAtOrBefore, upperBound} from "./search";

export interface DeviceInfo {
  name: string;
  x: number;
  y: number;
  ori: number;
  box: [number, number, number, number, number];  // cx, cy, depth, width, theta
}

/// An extra static box of the world (`obstacles` in the header).
export interface ObstacleInfo {
  name: string;
  box: [number, number, number, number, number];  // cx, cy, size_x, size_y, theta
}

/// The hackathon variant's task (`hackathon` in the header, docs/hackathon.md).
export interface HackathonInfo {
  safe_area: [number, number, number, number];  // x_min, y_min, x_max, y_max
  safe_place: string;
  colours: {name: string; decoy: boolean}[];
  pucks: Record<string, string>;  // puck id -> colour name
  points_per_puck: number;
  decoy_penalty: number;
  /// The flashlight camera's cone (recordings before it was added have none: no cone is drawn).
  camera?: {range_m: number; fov_deg: number};
}

export interface Header {
  format: string;
  version: number;
  scenario: string;
  variant: string;
  seed: number;
  llsfsim: string;
  pose_hz: number;
  field: {width: number; height: number};
  devices: DeviceInfo[];
  robots: string[];
  /// Jersey numbers, in the order of `robots` (recordings before they were added have none).
  jerseys?: number[];
  robot_radius: number;
  puck_radius: number;
  obstacles?: ObstacleInfo[];
  hackathon?: HackathonInfo;
}

/// One line after the header: a frame (`f`) or an event (`e`), always with `t`.
// eslint-disable-next-line @typescript-eslint/no-explicit-any
export type Line = {t: number; f?: number; e?: string; [key: string]: any};

export interface PuckState {
  x: number;
  y: number;
  on: boolean;  // on the field (false after `pr`)
  state: string;
}

export interface RobotState {
  skill: string;
  status: string;
  skillInfo: string;  // result or error of the last skill
  agent: string;
  agentLevel: string;
  agentT: number;
  role: string;
  locks: Record<string, string>;  // resource -> lock state (NONE entries removed)
  drops: number;
  dropT: number;  // time of the last drop attributed to this robot
  path: [number, number][] | null;
  held: number;
  /// The colour camera's recent frames with pucks (field frame), oldest first, kept for
  /// kSightingMemory s (an empty frame adds none: the older ones fade on).
  sightings: SightingFrame[];
  /// The time of the camera's last `sightings` line (with pucks or empty), -1 before one.
  sightingT: number;
  /// The state of the skill string's first skill (`skill_state` lines), "" when none.
  skillName: string;
  skillState: string;
  skillStateT: number;
}

/// One frame of a robot's colour camera: when, and each puck seen: [x, y, colour].
export interface SightingFrame {
  t: number;
  pucks: [number, number, string][];
}

/// How long sightings stay drawn (fading) after the frame that reported them, in simulated s.
export const kSightingMemory = 2;

/// Lines of a robot's skill on the timeline: its log lines, state changes, the navigator's
/// refusals and failures (kept apart from the State: they are listed up to the shown time).
export interface SkillLog {
  t: number;
  robot: string;
  kind: "log" | "state" | "nav";
  level: string;  // log: debug, info, warn, error; state: ""; nav: refused, failed
  text: string;
  /// nav: the goal [x, y, theta], when known.
  goal?: [number, number, number];
}

/// An exercise's judged outcome (the `verdict` line).
export interface Verdict {
  t: number;
  result: string;
  score: string;
  why: string;
}

export interface OrderState {
  id: number;
  product: string;
  requested: number;
  delivered: number;
  window: [number, number];
}

/// The game at one moment, as far as lines up to that moment tell.
export interface State {
  t: number;
  phase: string;
  gameState: string;
  points: number;
  phasePoints: Record<string, number>;
  planTypes: Record<string, string>;
  exploredTypes: Record<string, string>;
  lights: Record<string, number[]>;
  pucks: Record<number, PuckState>;
  robots: Record<string, RobotState>;
  orders: Record<number, OrderState>;
  drops: number;
  dropT: number;
  collisions: number;
  skillFailures: number;
  /// The hackathon score as of the last `rescue` event (zero before the first one).
  rescue: RescueState;
}

export interface RescueState {
  points: number;
  rescued: number;
  decoys: number;
  pucks: number[];  // ids in the safe area that count
}

export interface Marker {
  t: number;
  kind: "award" | "failure" | "collision" | "rescue" | "log" | "nav" | "agent";
  label: string;
}

function emptyRobot(): RobotState {
  return {
    skill: "",
    status: "",
    skillInfo: "",
    agent: "",
    agentLevel: "",
    agentT: -1,
    role: "",
    locks: {},
    drops: 0,
    dropT: -1e9,
    path: null,
    held: 0,
    sightings: [],
    sightingT: -1,
    skillName: "",
    skillState: "",
    skillStateT: -1,
  };
}

function emptyState(header: Header): State {
  const robots: Record<string, RobotState> = {};
  for (const r of header.robots) robots[r] = emptyRobot();
  return {
    t: 0,
    phase: "",
    gameState: "",
    points: 0,
    phasePoints: {},
    planTypes: {},
    exploredTypes: {},
    lights: {},
    pucks: {},
    robots,
    orders: {},
    drops: 0,
    dropT: -1e9,
    collisions: 0,
    skillFailures: 0,
    rescue: {points: 0, rescued: 0, decoys: 0, pucks: []},
  };
}

function robotOf(s: State, name: unknown): RobotState | null {
  if (typeof name !== "string") return null;
  return (s.robots[name] ??= emptyRobot());
}

/// Applies one line to the state (lines must come in file order).
function apply(s: State, header: Header, line: Line): void {
  s.t = line.t;
  if (line.f) {
    const p = line.p as [number, number, number][] | undefined;
    if (p) {
      for (const [id, x, y] of p) {
        const q = (s.pucks[id] ??= {x, y, on: true, state: ""});
        q.x = x;
        q.y = y;
        q.on = true;
      }
    }
    const pr = line.pr as number[] | undefined;
    if (pr) for (const id of pr) if (s.pucks[id]) s.pucks[id].on = false;
    const r = line.r as number[][] | undefined;
    if (r) {
      r.forEach((pose, i) => {
        const robot = robotOf(s, header.robots[i]);
        if (robot) robot.held = pose[6] ?? 0;
      });
    }
    // `drops`: a number (radio copies dropped since the last frame), or per robot (an array in
    // the header's robot order, or an object by robot name). `drops_from` names the senders of
    // the number's copies (robots with drops only); the rest has no known sender.
    const drops = line.drops as unknown;
    const addRobot = (name: unknown, n: unknown): number => {
      const robot = robotOf(s, name);
      if (!robot || typeof n !== "number" || n <= 0) return 0;
      robot.drops += n;
      robot.dropT = line.t;
      return n;
    };
    if (typeof drops === "number" && drops > 0) {
      s.drops += drops;
      let named = 0;
      const from = line.drops_from as unknown;
      if (from && typeof from === "object" && !Array.isArray(from)) {
        for (const [name, n] of Object.entries(from as Record<string, unknown>)) {
          named += addRobot(name, n);
        }
      }
      if (drops > named) s.dropT = line.t;
    } else if (Array.isArray(drops)) {
      drops.forEach((n, i) => (s.drops += addRobot(header.robots[i], n)));
    } else if (drops && typeof drops === "object") {
      for (const [name, n] of Object.entries(drops as Record<string, unknown>)) {
        s.drops += addRobot(name, n);
      }
    }
    return;
  }
  switch (line.e) {
    case "game":
      s.phase = line.phase ?? s.phase;
      s.gameState = line.state ?? s.gameState;
      if (typeof line.points === "number") s.points = line.points;
      break;
    case "plan":
      Object.assign(s.planTypes, line.types ?? {});
      break;
    case "award": {
      const phase = s.phase || "?";
      s.phasePoints[phase] = (s.phasePoints[phase] ?? 0) + (line.points ?? 0);
      if (typeof line.total === "number") s.points = line.total;
      break;
    }
    case "lights":
      s.lights[line.d] = line.l;
      break;
    case "collision":
      s.collisions++;
      break;
    case "skill": {
      const robot = robotOf(s, line.robot);
      if (!robot) break;
      robot.skill = line.string ?? robot.skill;
      robot.status = line.status ?? "";
      robot.skillInfo = line.error ?? line.result ?? "";
      if (line.status === "FAILED") s.skillFailures++;
      break;
    }
    case "puck": {
      const q = (s.pucks[line.id] ??= {x: 0, y: 0, on: false, state: ""});
      q.state = line.state;
      break;
    }
    case "order":
      s.orders[line.id] = {
        id: line.id,
        product: line.product,
        requested: line.requested,
        delivered: line.delivered,
        window: line.window,
      };
      break;
    case "agent": {
      const robot = robotOf(s, line.robot);
      // Debug lines (CLIPS' watch output, recorded with the agents' trace) are for the agent
      // browser's log; the panel keeps the last decision.
      if (!robot || line.level === "debug") break;
      const text = String(line.text ?? "");
      robot.agent = text;
      robot.agentLevel = line.level ?? "";
      robot.agentT = line.t;
      let m = /^production: role (.+)$/.exec(text);
      if (m) robot.role = m[1];
      m = /^won (\S+)/.exec(text);
      if (m) robot.role = m[1];
      m = /^explore: (\S+) is an? (\S+)/.exec(text);
      if (m) s.exploredTypes[m[1]] = m[2];
      break;
    }
    case "lock": {
      const robot = robotOf(s, line.robot);
      if (!robot) break;
      if (line.to === "NONE") delete robot.locks[line.resource];
      else robot.locks[line.resource] = line.to;
      break;
    }
    case "rescue":
      s.rescue = {
        points: typeof line.points === "number" ? line.points : s.rescue.points,
        rescued: typeof line.rescued === "number" ? line.rescued : s.rescue.rescued,
        decoys: typeof line.decoys === "number" ? line.decoys : s.rescue.decoys,
        pucks: Array.isArray(line.pucks) ? (line.pucks as number[]) : [],
      };
      break;
    case "sightings": {
      const robot = robotOf(s, line.robot);
      if (!robot) break;
      const pucks = Array.isArray(line.pucks)
        ? (line.pucks as unknown[]).filter(
            (p): p is [number, number, string] =>
              Array.isArray(p) && typeof p[0] === "number" && typeof p[1] === "number",
          )
        : [];
      // Robots of recordings before sightings existed have no list (snapshots made then).
      const frames = (robot.sightings ??= []);
      robot.sightingT = line.t;
      if (pucks.length > 0) {
        frames.push({t: line.t, pucks: pucks.map((p) => [p[0], p[1], String(p[2] ?? "")])});
      }
      while (frames.length > 0 && frames[0].t < line.t - kSightingMemory) frames.shift();
      break;
    }
    case "skill_state": {
      const robot = robotOf(s, line.robot);
      if (!robot) break;
      robot.skillName = String(line.skill ?? "");
      robot.skillState = String(line.to ?? "");
      robot.skillStateT = line.t;
      break;
    }
    case "path": {
      const robot = robotOf(s, line.robot);
      if (!robot) break;
      const pts = line.points as [number, number][] | undefined;
      robot.path = pts && pts.length > 0 ? pts : null;
      break;
    }
    default:
      break;
  }
}

/// Lines of `text` that hold JSON objects; a line that is not one is an error with its number.
export function parseLine(text: string, number: number): Line | Header {
  let v: unknown;
  try {
    v = JSON.parse(text);
  } catch {
    throw new Error(`line ${number}: not JSON`);
  }
  if (!v || typeof v !== "object" || Array.isArray(v)) {
    throw new Error(`line ${number}: not a JSON object`);
  }
  return v as Line | Header;
}

const kSnapshotEvery = 5;  // simulated seconds between snapshots

export class Recording {
  header: Header | null = null;
  readonly lines: Line[] = [];
  readonly lineT: number[] = [];
  readonly frameT: number[] = [];
  readonly frameR: number[][][] = [];
  readonly markers: Marker[] = [];
  readonly phaseStarts: {t: number; phase: string}[] = [];
  /// The hackathon score after each `rescue` event (for the timeline).
  readonly rescueSteps: {t: number; points: number}[] = [];
  /// The agents' facts, rule firings and output lines, per robot.
  readonly trace = new AgentTrace();
  /// The skills' log lines, state changes and navigation failures, in time order.
  readonly skillLog: SkillLog[] = [];
  readonly skillLogT: number[] = [];
  /// The exercise's verdict (the last `verdict` line), null before it.
  verdict: Verdict | null = null;
  /// Incremented whenever lines were appended (the views redraw what depends on them).
  version = 0;
  private builder: State | null = null;
  private snapshots: {index: number; state: State}[] = [];
  private lastPhase = "";
  private lineCount = 0;

  /// The number of lines read, the header included.
  get lineTotal(): number {
    return this.lineCount;
  }

  get endTime(): number {
    return this.lineT.length > 0 ? this.lineT[this.lineT.length - 1] : 0;
  }

  /// Appends one text line (empty lines are skipped). Throws on a bad line.
  appendText(text: string): void {
    const trimmed = text.trim();
    if (trimmed === "") return;
    this.lineCount++;
    const v = parseLine(trimmed, this.lineCount);
    if (!this.header) {
      const h = v as Header;
      if (h.format !== "llsfsim-recording") {
        throw new Error(`line 1: not an llsfsim recording (format ${String(h.format)})`);
      }
      if (h.version !== 1) {
        throw new Error(`line 1: recording version ${h.version} (this viewer reads version 1)`);
      }
      this.header = h;
      this.builder = emptyState(h);
      this.snapshots.push({index: 0, state: structuredClone(this.builder)});
      this.version++;
      return;
    }
    const line = v as Line;
    if (typeof line.t !== "number") throw new Error(`line ${this.lineCount}: no "t"`);
    this.append(line);
  }

  private append(line: Line): void {
    const header = this.header!;
    const builder = this.builder!;
    // The agents' trace goes to the trace only (`agent` lines to both).
    if (this.trace.take(line)) {
      this.version++;
      return;
    }
    const index = this.lines.length;
    // A snapshot of the state before this line, every few seconds.
    const last = this.snapshots[this.snapshots.length - 1];
    const lastT = last.index === 0 ? 0 : this.lineT[last.index - 1];
    if (line.t >= lastT + kSnapshotEvery && index > last.index) {
      this.snapshots.push({index, state: structuredClone(builder)});
    }
    this.lines.push(line);
    this.lineT.push(line.t);
    if (line.f) {
      this.frameT.push(line.t);
      this.frameR.push(line.r ?? []);
    } else if (line.e === "award") {
      this.markers.push({
        t: line.t,
        kind: "award",
        label: `${line.points >= 0 ? "+" : ""}${line.points} ${line.reason ?? ""}` +
          (line.device ? ` ${line.device}` : ""),
      });
    } else if (line.e === "skill" && line.status === "FAILED") {
      this.markers.push({
        t: line.t,
        kind: "failure",
        label: `${line.robot}: ${line.string ?? ""} failed: ${line.error ?? ""}`,
      });
    } else if (line.e === "issue" && line.kind !== "skill-failure") {
      // An agent's mistake (docs/recording.md: a runtime error, a rule loop, a halted agent, an
      // unknown skill, a lock held too long); skill failures have their own markers. A lock held
      // too long is noticed at the end: its marker stands where it happened (time_s).
      const where = line.rule ? ` rule ${line.rule}${line.place ? ` (${line.place})` : ""}` : "";
      this.markers.push({
        t: typeof line.time_s === "number" ? line.time_s : line.t,
        kind: "agent",
        // An unknown skill: its skill string (`skill`) before the engine's error.
        label: `${line.robot ?? ""} ${line.kind ?? "issue"}${where}: ` +
          `${line.skill ? `${line.skill}: ` : ""}${line.text ?? ""}`,
      });
    } else if (line.e === "jam" && line.jammed) {
      // Robot profiles: a robot jammed at a device (docs/profiles.md).
      this.markers.push({t: line.t, kind: "failure", label: `${line.robot} jammed at ${line.d}`});
    } else if (line.e === "collision") {
      this.markers.push({
        t: line.t,
        kind: "collision",
        label: `${line.kind}: ${line.robot}${line.other ? ` with ${line.other}` : ""}`,
      });
    } else if (line.e === "rescue") {
      const prev = this.rescueSteps.length > 0 ? this.rescueSteps[this.rescueSteps.length - 1].points : 0;
      const points = typeof line.points === "number" ? line.points : prev;
      const d = points - prev;
      this.rescueSteps.push({t: line.t, points});
      this.markers.push({
        t: line.t,
        kind: "rescue",
        label: `${d >= 0 ? "+" : ""}${d} rescue: ${points} points, ${line.rescued ?? 0} rescued, ` +
          `${line.decoys ?? 0} decoys`,
      });
    } else if (line.e === "log" || line.e === "skill_state" || line.e === "nav") {
      this.addSkillLog(line);
    } else if (line.e === "verdict") {
      this.verdict = {
        t: line.t,
        result: String(line.result ?? ""),
        score: String(line.score ?? ""),
        why: String(line.why ?? ""),
      };
    } else if (line.e === "game" && line.phase && line.phase !== this.lastPhase) {
      this.lastPhase = line.phase;
      this.phaseStarts.push({t: line.t, phase: line.phase});
    }
    apply(builder, header, line);
    this.version++;
  }

  private addSkillLog(line: Line): void {
    const robot = String(line.robot ?? "");
    let entry: SkillLog;
    if (line.e === "log") {
      entry = {t: line.t, robot, kind: "log", level: String(line.level ?? "info"), text: String(line.text ?? "")};
      this.markers.push({t: line.t, kind: "log", label: `${robot} ${entry.level}: ${entry.text}`});
    } else if (line.e === "skill_state") {
      const from = String(line.from ?? "") || "–";
      const to = String(line.to ?? "") || "–";
      // `via` (exercise --trace): what took it there, the transition and its file:line.
      const via = line.via ? `  (${String(line.via)})` : "";
      entry = {t: line.t, robot, kind: "state", level: "", text: `${String(line.skill ?? "")}: ${from} → ${to}${via}`};
    } else {
      const where = line.place
        ? String(line.place)
        : Array.isArray(line.goal)
          ? `(${Number(line.goal[0]).toFixed(2)}, ${Number(line.goal[1]).toFixed(2)})`
          : "?";
      const kind = line.kind === "refused" ? "refused" : "failed";
      entry = {
        t: line.t,
        robot,
        kind: "nav",
        level: kind,
        text: `navigator ${kind} ${where}: ${String(line.outcome ?? "")} ${String(line.message ?? "")}`.trim(),
      };
      if (Array.isArray(line.goal) && line.goal.length >= 2) {
        entry.goal = [Number(line.goal[0]), Number(line.goal[1]), Number(line.goal[2] ?? 0)];
      }
      this.markers.push({t: line.t, kind: "nav", label: `${robot} ${entry.text}`});
    }
    this.skillLog.push(entry);
    this.skillLogT.push(line.t);
  }

  /// The skill log entries with t <= time (their count: a prefix of skillLog).
  skillLogUpTo(time: number): number {
    return upperBound(this.skillLogT, time);
  }

  /// The number of lines with t <= time.
  upperBound(time: number): number {
    return upperBound(this.lineT, time);
  }

  /// The index of the last frame with t <= time (-1 when none).
  frameAt(time: number): number {
    let lo = 0;
    let hi = this.frameT.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if (this.frameT[mid] <= time) lo = mid + 1;
      else hi = mid;
    }
    return lo - 1;
  }

  /// Robot poses at `time`: [x, y, theta, bx, by, btheta, held] per robot, interpolated
  /// linearly between the frames around it (held puck from the earlier frame).
  posesAt(time: number): number[][] {
    const i = this.frameAt(time);
    if (i < 0) return this.frameR.length > 0 ? this.frameR[0] : [];
    const a = this.frameR[i];
    if (i + 1 >= this.frameR.length) return a;
    const b = this.frameR[i + 1];
    const t0 = this.frameT[i];
    const t1 = this.frameT[i + 1];
    const u = t1 > t0 ? Math.min(1, Math.max(0, (time - t0) / (t1 - t0))) : 0;
    if (u === 0) return a;
    return a.map((pa, k) => {
      const pb = b[k] ?? pa;
      const lerp = (j: number) => pa[j] + (pb[j] - pa[j]) * u;
      const angle = (j: number) => {
        let d = pb[j] - pa[j];
        while (d > Math.PI) d -= 2 * Math.PI;
        while (d < -Math.PI) d += 2 * Math.PI;
        return pa[j] + d * u;
      };
      return [lerp(0), lerp(1), angle(2), lerp(3), lerp(4), angle(5), pa[6]];
    });
  }

  /// A cursor over the derived state.
  cursor(): Cursor {
    return new Cursor(this);
  }

  /** @internal */ snapshotBefore(index: number): {index: number; state: State} {
    const lo = countAtOrBefore(this.snapshots, (s) => s.index, index);
    return this.snapshots[Math.max(0, lo - 1)];
  }

  /** @internal */ applyLine(state: State, index: number): void {
    apply(state, this.header!, this.lines[index]);
  }
}

/// The derived state at a chosen time: moving forward applies the lines in between; moving back
/// (or far forward) restarts from the nearest snapshot.
export class Cursor {
  private state: State | null = null;
  private index = 0;  // lines applied

  constructor(private readonly rec: Recording) {}

  at(time: number): State | null {
    const rec = this.rec;
    if (!rec.header) return null;
    const target = rec.upperBound(time);
    if (!this.state || target < this.index || target - this.index > 2000) {
      const snap = rec.snapshotBefore(target);
      if (!this.state || snap.index > this.index || target < this.index) {
        this.state = structuredClone(snap.state);
        this.index = snap.index;
      }
    }
    while (this.index < target) rec.applyLine(this.state, this.index++);
    this.state.t = time;
    return this.state;
  }
}
