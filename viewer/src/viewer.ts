// SPDX-License-Identifier: MIT
// The browser viewer served by `llsfsim serve` (index.html + this bundle). Hash routes:
//   #/            the batches of the statistics store
//   #/batch/ID    the batch's report (box plots, tables) and its runs
//   #/run/ID      replay of a run's recording (/api/runs/ID/recording)
//   #/file/PATH   replay of /api/recordings/PATH
//   #/live        the live game (WebSocket /api/live)
// Test hook: window.llsfViewer (see Replay.hook); #app carries data-page and data-ready.
import {AgentPanel, fmtTime, type AgentView} from "./agent_panel";
import {colourCss, drawField, fieldScale, HeldLabel, kPuckColors, kRobotColors} from "./field";
import {Cursor, kSightingMemory, Recording, type State} from "./recording";
import {skillSection, verdictBanner, type SkillView} from "./skill_panel";
import {el, renderReport, table, type Child, type ReportData} from "./report_view";

interface BatchInfo {
  id: number;
  kind: string;
  scenario_name: string;
  scenario_file: string;
  variants: number;
  runs_per_variant: number;
  finished: boolean;
}

interface RunInfo {
  id: number;
  variant: string;
  seed: number;
  points: number;
  passed: boolean;
  result_hash: string;
  recording: boolean;
}

interface ViewerHook {
  page: string;
  ready: boolean;
  error: string | null;
  time(): number;
  endTime(): number;
  robots(): {name: string; x: number; y: number}[];
  seek(t: number): void;
  play(on: boolean): void;
  devicesDrawn(): number;
  /// Field renders so far (frames per second = its growth over wall time; bench/viewer_replay.mjs).
  framesDrawn(): number;
  /// Replay speed (0.25 .. 64 in the page's selector; any positive factor here).
  setSpeed(x: number): void;
  robotsDrawn(): number;
  pucksDrawn(): number;
  obstaclesDrawn(): number;
  /// The hackathon score at the shown time (null outside the variant).
  rescue(): {points: number; rescued: number; decoys: number; pucks: number[]} | null;
  /// Opens the agent browser on `robot` (null closes it); the panel is drawn at once.
  selectRobot(robot: string | null): void;
  /// The agent browser's robot and facts at the shown time (all, and those the filters show);
  /// null while it is closed.
  agent(): AgentView | null;
  /// The debugger's view at the shown time: cones and camera sightings drawn (all, and of the
  /// latest frames), each robot's skill section, the verdict banner, the timeline's markers
  /// (x in CSS pixels of the timeline canvas), the grid and the mouse readout.
  debug(): DebugView;
  /// Shows or hides the finer grid with coordinates.
  setGrid(on: boolean): void;
}

interface DebugView {
  cones: number;
  sightings: number;
  freshSightings: number;
  /// The most sightings drawn in one render so far (a live game moves on between polls).
  maxSightings: number;
  skills: SkillView[];
  verdict: {result: string; score: string; shown: boolean} | null;
  markers: {t: number; kind: string; label: string; x: number}[];
  grid: boolean;
  mouse: string;
  /// The robots drawn with a held puck: their labels' and the puck's extent (field.ts).
  heldLabels: HeldLabel[];
}

declare global {
  interface Window {
    llsfViewer?: ViewerHook;
  }
}

const app = document.getElementById("app") as HTMLElement;
let teardown: (() => void) | null = null;

async function fetchJson<T>(url: string, signal: AbortSignal): Promise<T> {
  const res = await fetch(url, {signal});
  if (!res.ok) throw new Error(await errorText(res));
  return (await res.json()) as T;
}

async function errorText(res: Response): Promise<string> {
  let msg = `${res.status} ${res.statusText}`;
  try {
    const j = (await res.json()) as {error?: string};
    if (j.error) msg = `${j.error} (${res.status})`;
  } catch {
    // not JSON: keep the status
  }
  return `${res.url}: ${msg}`;
}

function showError(target: HTMLElement, e: unknown): void {
  if (e instanceof DOMException && e.name === "AbortError") return;
  const msg = e instanceof Error ? e.message : String(e);
  target.append(el("p", {class: "error"}, msg));
  app.setAttribute("data-error", msg);
}

// ---------------------------------------------------------------------------------------------
// #/ and #/batch/ID

function batchesPage(signal: AbortSignal): void {
  const root = el("div", {class: "page"}, el("h1", {}, "Batches"));
  app.replaceChildren(root);
  fetchJson<BatchInfo[]>("/api/batches", signal)
    .then((batches) => {
      const rows: Child[][] = batches.map((b) => [
        el("a", {href: `#/batch/${b.id}`}, `batch ${b.id}`),
        b.kind,
        b.scenario_name,
        b.scenario_file,
        b.variants,
        b.runs_per_variant,
        // The single games of `llsfsim run` are never finished, nor running (docs/statistics.md).
        b.kind === "run" ? "single games" : b.finished ? "yes" : "running",
      ]);
      root.append(
        batches.length === 0
          ? el("p", {class: "note"}, "The statistics store holds no batch yet.")
          : table(
              ["batch", "kind", "scenario", "file", "variants", "runs/variant", "finished"],
              rows,
              {"data-table": "batches"},
            ),
        el("p", {class: "note"}, el("a", {href: "#/live"}, "Live game"), " (when one is served)"),
      );
      app.setAttribute("data-ready", "true");
    })
    .catch((e) => showError(root, e));
}

function batchPage(id: string, signal: AbortSignal): void {
  const report = el("div", {id: "llsf-batch-report"});
  const runs = el("div", {}, el("h2", {}, "Runs"));
  const root = el("div", {class: "page"}, el("p", {}, el("a", {href: "#/"}, "← batches")), report, runs);
  app.replaceChildren(root);
  const enc = encodeURIComponent(id);
  Promise.all([
    fetchJson<ReportData>(`/api/batches/${enc}/report`, signal),
    fetchJson<RunInfo[]>(`/api/batches/${enc}/runs`, signal),
  ])
    .then(([data, list]) => {
      renderReport(report, data);
      const rows: Child[][] = list.map((r) => [
        r.recording ? el("a", {href: `#/run/${r.id}`}, `run ${r.id}`) : `run ${r.id}`,
        r.variant || "(no matrix)",
        r.seed,
        r.points,
        r.passed ? "yes" : el("span", {class: "failed"}, "no"),
        el("code", {}, r.result_hash),
        r.recording ? el("a", {href: `#/run/${r.id}`}, "replay") : "–",
      ]);
      runs.append(
        table(["run", "variant", "seed", "points", "passed", "result hash", "recording"], rows, {
          "data-table": "runs",
        }),
      );
      app.setAttribute("data-ready", "true");
    })
    .catch((e) => showError(root, e));
}

// ---------------------------------------------------------------------------------------------
// The replay: field, side panel, controls and timeline.

const kSpeeds = [0.25, 0.5, 1, 2, 4, 8, 16, 32, 64];

class Replay {
  readonly rec = new Recording();
  private readonly cursor: Cursor = this.rec.cursor();
  private time = 0;
  private playing = false;
  private speed = 1;
  follow = false;
  private raf = 0;
  private lastWall = 0;
  private lastPanel = -1;
  private panelVersion = -1;
  private lastStats = {
    devices: 0,
    robots: 0,
    pucks: 0,
    obstacles: 0,
    cones: 0,
    sightings: 0,
    freshSightings: 0,
    heldLabels: [] as HeldLabel[],
  };
  private maxSightings = 0;
  private skillViews: SkillView[] = [];
  private grid = false;
  private mouse: [number, number] | null = null;
  private readonly mouseLabel = el("span", {class: "mouse", "data-mouse": ""}, "");
  private readonly gridBox = el("input", {type: "checkbox", "data-control": "grid"});
  private readonly banner = el("div", {class: "banner", "data-banner": ""});
  private framesDrawn = 0;
  private timelineCache: HTMLCanvasElement | null = null;
  private timelineKey = "";
  private fpsFrames = 0;
  private fpsT0 = 0;
  fps = 0;
  ready = false;
  error: string | null = null;

  readonly root: HTMLElement;
  private readonly title = el("span", {class: "title"});
  private readonly status = el("span", {class: "status"});
  private readonly canvas = el("canvas", {class: "field", "data-field": ""});
  private readonly panel = el("div", {class: "panel", "data-panel": ""});
  private readonly timeline = el("canvas", {class: "timeline", "data-timeline": ""});
  private readonly tip = el("div", {class: "tip"});
  private readonly playBtn = el("button", {title: "play/pause (space)", "data-control": "play"}, "play");
  private readonly speedSel = el("select", {title: "speed", "data-control": "speed"});
  private readonly timeLabel = el("span", {class: "time", "data-time": "0"});
  private readonly followBox = el("input", {type: "checkbox", "data-control": "follow"});
  private readonly agentBtn = el(
    "button",
    {title: "the agent browser: a robot's facts, rule firings, skill and log", "data-control": "agent"},
    "agent",
  );
  private readonly agentPanel: AgentPanel;
  private agentOpen = false;

  constructor(private readonly live: boolean) {
    for (const s of kSpeeds) {
      const o = el("option", {value: String(s)}, `${s}×`);
      if (s === 1) o.selected = true;
      this.speedSel.append(o);
    }
    const back = el("button", {title: "one frame back (←)", "data-control": "back"}, "‹ frame");
    const fwd = el("button", {title: "one frame forward (→)", "data-control": "forward"}, "frame ›");
    back.onclick = () => this.step(-1);
    fwd.onclick = () => this.step(1);
    this.playBtn.onclick = () => this.setPlaying(!this.playing);
    this.speedSel.onchange = () => (this.speed = Number(this.speedSel.value));
    const followLabel = el("label", {class: "follow"}, this.followBox, " follow live");
    this.followBox.onchange = () => (this.follow = this.followBox.checked);
    if (!live) followLabel.style.display = "none";
    this.agentPanel = new AgentPanel(this.rec, () => this.showAgent(null), () => this.redraw());
    this.agentPanel.root.style.display = "none";
    this.agentBtn.onclick = () => this.showAgent(this.agentOpen ? null : this.agentPanel.robot);
    this.canvas.addEventListener("click", (ev) => this.clickField(ev));
    this.canvas.addEventListener("mousemove", (ev) => this.moveMouse(ev));
    this.canvas.addEventListener("mouseleave", () => {
      this.mouse = null;
      this.mouseLabel.textContent = "";
      this.mouseLabel.setAttribute("data-mouse", "");
    });
    this.gridBox.onchange = () => this.setGrid(this.gridBox.checked);
    const gridLabel = el(
      "label",
      {title: "a 0.25 m grid with the metres along the edges, and a cross hair"},
      this.gridBox,
      " grid",
    );
    const controls = el(
      "div",
      {class: "controls"},
      back,
      this.playBtn,
      fwd,
      this.speedSel,
      this.timeLabel,
      followLabel,
      this.agentBtn,
      gridLabel,
      this.mouseLabel,
      this.status,
    );
    this.root = el(
      "div",
      {class: "replay"},
      el("div", {class: "bar"}, el("a", {href: "#/"}, "batches"), " · ", this.title),
      el(
        "div",
        {class: "main"},
        el("div", {class: "fieldbox"}, this.canvas, this.banner),
        this.panel,
        this.agentPanel.root,
      ),
      controls,
      el("div", {class: "timelinebox"}, this.timeline, this.tip),
    );
    this.setupTimeline();
  }

  setTitle(text: string): void {
    this.title.textContent = text;
  }

  setStatus(text: string): void {
    this.status.textContent = text;
  }

  fail(e: unknown): void {
    if (e instanceof DOMException && e.name === "AbortError") return;
    this.error = e instanceof Error ? e.message : String(e);
    this.setStatus("");
    this.root.append(el("p", {class: "error"}, this.error));
    app.setAttribute("data-error", this.error);
  }

  /// Opens the agent browser on `robot` ("" = the one selected before), or closes it (null).
  showAgent(robot: string | null): void {
    this.agentOpen = robot !== null;
    if (robot) this.agentPanel.select(robot);
    this.agentPanel.root.style.display = this.agentOpen ? "" : "none";
    this.agentBtn.classList.toggle("on", this.agentOpen);
    this.redraw();
  }

  /// Draws everything now (after a change of the selection or a seek by the test hook).
  private redraw(): void {
    this.render(performance.now(), true);
  }

  /// The field coordinates under a mouse event (null off the field's drawing).
  private fieldAt(ev: MouseEvent): [number, number] | null {
    const h = this.rec.header;
    if (!h) return null;
    const {s, ox, oy} = fieldScale(this.canvas.clientWidth, this.canvas.clientHeight, h);
    return [(ev.offsetX - ox) / s, h.field.height - (ev.offsetY - oy) / s];
  }

  /// The readout of the field coordinates under the mouse (metres, the field frame).
  private moveMouse(ev: MouseEvent): void {
    const p = this.fieldAt(ev);
    const h = this.rec.header;
    if (!p || !h) return;
    const on = p[0] >= 0 && p[1] >= 0 && p[0] <= h.field.width && p[1] <= h.field.height;
    this.mouse = on ? p : null;
    let text = on ? `x ${p[0].toFixed(2)}  y ${p[1].toFixed(2)} m` : "";
    // A camera sighting under the mouse: its colour, robot and age.
    const st = on ? this.cursor.at(this.time) : null;
    let best = 0.08;
    let near = "";
    for (const [name, r] of Object.entries(st?.robots ?? {})) {
      for (const f of r.sightings ?? []) {
        const age = this.time - f.t;
        if (age < 0 || age > kSightingMemory) continue;
        for (const [x, y, colour] of f.pucks) {
          const d = Math.hypot(x - p[0], y - p[1]);
          if (d < best) {
            best = d;
            near = ` · ${colour} seen by ${name} ${age.toFixed(1)} s ago at (${x.toFixed(2)}, ${y.toFixed(2)})`;
          }
        }
      }
    }
    text += near;
    this.mouseLabel.textContent = text;
    this.mouseLabel.setAttribute("data-mouse", text);
    if (this.grid && !this.playing) this.redraw();
  }

  /// The navigator's refused or failed goals of the last 3 s before the shown time.
  private navGoals(): {x: number; y: number; age: number; refused: boolean}[] {
    const out: {x: number; y: number; age: number; refused: boolean}[] = [];
    const log = this.rec.skillLog;
    for (let i = this.rec.skillLogUpTo(this.time) - 1; i >= 0; i--) {
      const e = log[i];
      const age = this.time - e.t;
      if (age > 3) break;
      if (e.kind === "nav" && e.goal) {
        out.push({x: e.goal[0], y: e.goal[1], age, refused: e.level === "refused"});
      }
    }
    return out;
  }

  setGrid(on: boolean): void {
    this.grid = on;
    this.gridBox.checked = on;
    this.redraw();
  }

  /// A click on a robot of the field opens the agent browser on it.
  private clickField(ev: MouseEvent): void {
    const h = this.rec.header;
    if (!h) return;
    const {s, ox, oy} = fieldScale(this.canvas.clientWidth, this.canvas.clientHeight, h);
    const x = (ev.offsetX - ox) / s;
    const y = h.field.height - (ev.offsetY - oy) / s;
    let best = -1;
    let bestD = h.robot_radius * 1.5;
    this.rec.posesAt(this.time).forEach((p, i) => {
      const d = Math.hypot(p[0] - x, p[1] - y);
      if (d < bestD) {
        bestD = d;
        best = i;
      }
    });
    if (best >= 0 && h.robots[best]) this.showAgent(h.robots[best]);
  }

  setFollow(on: boolean): void {
    this.follow = on;
    this.followBox.checked = on;
  }

  setPlaying(on: boolean): void {
    this.playing = on;
    this.playBtn.textContent = on ? "pause" : "play";
    if (on && this.time >= this.rec.endTime && !this.live) this.time = 0;
  }

  seek(t: number): void {
    this.time = Math.max(0, Math.min(this.rec.endTime, t));
    if (this.live) this.setFollow(this.time >= this.rec.endTime - 0.001);
  }

  step(dir: number): void {
    this.setPlaying(false);
    const rec = this.rec;
    if (rec.frameT.length === 0) return;
    let i = rec.frameAt(this.time);
    if (dir > 0) i = Math.min(rec.frameT.length - 1, i + 1);
    else if (i > 0 && rec.frameT[i] >= this.time - 1e-9) i -= 1;
    this.seek(rec.frameT[Math.max(0, i)]);
  }

  start(): void {
    const loop = (now: number) => {
      this.raf = requestAnimationFrame(loop);
      this.tick(now);
    };
    this.lastWall = performance.now();
    this.raf = requestAnimationFrame(loop);
    window.addEventListener("keydown", this.onKey);
    const hook: ViewerHook = {
      page: this.live ? "live" : "replay",
      get ready() {
        return replay.ready;
      },
      get error() {
        return replay.error;
      },
      time: () => this.time,
      endTime: () => this.rec.endTime,
      robots: () => {
        const h = this.rec.header;
        if (!h) return [];
        return this.rec.posesAt(this.time).map((p, i) => ({name: h.robots[i], x: p[0], y: p[1]}));
      },
      seek: (t: number) => {
        this.seek(t);
        this.render(performance.now(), true);
      },
      play: (on: boolean) => this.setPlaying(on),
      devicesDrawn: () => this.lastStats.devices,
      framesDrawn: () => this.framesDrawn,
      setSpeed: (x: number) => {
        this.speed = x;
      },
      robotsDrawn: () => this.lastStats.robots,
      pucksDrawn: () => this.lastStats.pucks,
      obstaclesDrawn: () => this.lastStats.obstacles,
      rescue: () => {
        if (!this.rec.header?.hackathon) return null;
        const st = this.cursor.at(this.time);
        return st ? {...st.rescue, pucks: [...st.rescue.pucks]} : null;
      },
      selectRobot: (robot: string | null) => this.showAgent(robot),
      agent: () => {
        if (!this.agentOpen) return null;
        const v = this.agentPanel.view();
        return v ? {...v, facts: [...v.facts], shown: [...v.shown]} : null;
      },
      debug: () => {
        const v = this.rec.verdict;
        return {
          cones: this.lastStats.cones,
          sightings: this.lastStats.sightings,
          freshSightings: this.lastStats.freshSightings,
          maxSightings: this.maxSightings,
          skills: this.skillViews.map((k) => ({...k, lines: [...k.lines]})),
          verdict: v
            ? {result: v.result, score: v.score, shown: this.banner.childElementCount > 0}
            : null,
          markers: this.rec.markers.map((m) => ({
            t: m.t,
            kind: m.kind,
            label: m.label,
            x: this.timelineX(m.t),
          })),
          grid: this.grid,
          mouse: this.mouseLabel.textContent ?? "",
          heldLabels: this.lastStats.heldLabels.map((h) => ({...h})),
        };
      },
      setGrid: (on: boolean) => this.setGrid(on),
    };
    // eslint-disable-next-line @typescript-eslint/no-this-alias
    const replay = this;
    window.llsfViewer = hook;
  }

  stop(): void {
    cancelAnimationFrame(this.raf);
    window.removeEventListener("keydown", this.onKey);
    delete window.llsfViewer;
  }

  private onKey = (ev: KeyboardEvent) => {
    if (ev.target instanceof HTMLInputElement || ev.target instanceof HTMLSelectElement) return;
    if (ev.key === " ") {
      this.setPlaying(!this.playing);
      ev.preventDefault();
    } else if (ev.key === "ArrowRight") {
      this.step(1);
    } else if (ev.key === "ArrowLeft") {
      this.step(-1);
    }
  };

  private tick(now: number): void {
    const dt = Math.min(0.25, (now - this.lastWall) / 1000);
    this.lastWall = now;
    const end = this.rec.endTime;
    if (this.live && this.follow) {
      this.time = end;
    } else if (this.playing) {
      this.time = Math.min(end, this.time + dt * this.speed);
      if (this.time >= end && !this.live) this.setPlaying(false);
    }
    this.render(now, false);
    this.fpsFrames++;
    if (now - this.fpsT0 > 1000) {
      this.fps = (this.fpsFrames * 1000) / (now - this.fpsT0);
      this.fpsFrames = 0;
      this.fpsT0 = now;
      this.root.setAttribute("data-fps", this.fps.toFixed(0));
    }
  }

  render(now: number, force: boolean): void {
    const h = this.rec.header;
    if (!h) return;
    const state = this.cursor.at(this.time);
    if (!state) return;
    const poses = this.rec.posesAt(this.time);
    this.lastStats = drawField(this.canvas, h, state, poses, this.time, {
      selected: this.agentOpen ? this.agentPanel.robot : "",
      grid: this.grid,
      mouse: this.mouse,
      navGoals: this.navGoals(),
    });
    this.maxSightings = Math.max(this.maxSightings, this.lastStats.sightings);
    ++this.framesDrawn;
    this.canvas.setAttribute("data-cones", String(this.lastStats.cones));
    this.canvas.setAttribute("data-sightings", String(this.lastStats.sightings));
    // The verdict banner (an exercise's recording), from the verdict's time on.
    const banner = verdictBanner(this.rec.verdict, this.time);
    const bannerKey = banner ? banner.textContent ?? "" : "";
    if (bannerKey !== (this.banner.getAttribute("data-banner") ?? "")) {
      this.banner.replaceChildren(...(banner ? [banner] : []));
      this.banner.setAttribute("data-banner", bannerKey);
    }
    this.canvas.setAttribute("data-devices", String(this.lastStats.devices));
    this.canvas.setAttribute("data-robots", String(this.lastStats.robots));
    this.canvas.setAttribute("data-obstacles", String(this.lastStats.obstacles));
    this.timeLabel.textContent = `${fmtTime(this.time)} / ${fmtTime(this.rec.endTime)}`;
    this.timeLabel.setAttribute("data-time", this.time.toFixed(2));
    // The panel at most 8 times a second (DOM work), at once when forced or paused on a change.
    const key = this.time * 1000 + this.rec.version;
    if (force || (now - this.lastPanel > 120 && key !== this.panelVersion)) {
      this.lastPanel = now;
      this.panelVersion = key;
      this.renderPanel(state);
      if (this.agentOpen) this.agentPanel.render(this.time, state);
    }
    this.drawTimeline();
  }

  // --- side panel ---

  private renderPanel(s: State): void {
    const h = this.rec.header!;
    const gate = ["D1", "D2", "D3"].find((d) => {
      const l = s.lights[d];
      return l && (l[2] === 1 || l[2] === 2);
    });
    const phases = Object.entries(s.phasePoints)
      .map(([p, n]) => `${p.toLowerCase()} ${n}`)
      .join(", ");
    const orders = Object.values(s.orders).sort((a, b) => a.id - b.id);
    const skillViews: SkillView[] = [];
    const robotRows = h.robots.map((name, i) => {
      const r = s.robots[name];
      const color = kRobotColors[i % kRobotColors.length];
      const locks = r
        ? Object.entries(r.locks)
            .map(([res, st]) => (st === "ACCEPTED" ? res : `${res}:${st.toLowerCase()}`))
            .join(" ")
        : "";
      const skill = skillSection(this.rec, name, r, this.time, (t) => {
        this.setPlaying(false);
        this.seek(t);
        this.redraw();
      });
      skillViews.push(skill.view);
      const agentLine = r?.agent || !h.hackathon;
      return el(
        "div",
        {class: "robot", "data-robot": name},
        this.robotName(name, color, r?.role ?? ""),
        el("div", {class: "skill"}, r?.skill ? `${r.skill} ${r.status}` : "–"),
        r?.skillInfo ? el("div", {class: "info"}, r.skillInfo) : "",
        // The skill's section where skills log or report states (or in the hackathon).
        h.hackathon || this.rec.skillLog.length > 0 ? skill.node : "",
        agentLine
          ? el(
              "div",
              {class: `agent ${r?.agentLevel ?? ""}`},
              r?.agent ? `[${fmtTime(r.agentT)}] ${r.agent}` : "no agent decision yet",
            )
          : "",
        locks ? el("div", {class: "locks"}, `locks: ${locks}`) : "",
        r && r.drops > 0 ? el("div", {class: "info"}, `radio drops: ${r.drops}`) : "",
      );
    });
    this.skillViews = skillViews;
    // The hackathon (docs/hackathon.md): the rescue score leads; the refbox's parts (phase,
    // points, delivery gate, orders) show only when the refbox plays (it stays in PRE_GAME by
    // default, lamps and all).
    const hack = h.hackathon;
    const refbox = !hack || (s.phase !== "" && s.phase !== "PRE_GAME") || orders.length > 0;
    const game: Child[] = [];
    if (hack) {
      const r = s.rescue;
      const colourOf = hack.pucks ?? {};
      const decoyNames = new Set((hack.colours ?? []).filter((c) => c.decoy).map((c) => c.name));
      const countable = Object.values(colourOf).filter((c) => !decoyNames.has(c)).length;
      game.push(
        el(
          "div",
          {
            class: "big",
            "data-points": String(r.points),
            "data-rescue": `${r.points}/${r.rescued}/${r.decoys}`,
          },
          `${r.points} points`,
        ),
        el(
          "div",
          {class: "rescue"},
          `rescued ${r.rescued} of ${countable}`,
          r.decoys > 0 ? el("span", {class: "failed"}, ` · decoys ${r.decoys}`) : " · decoys 0",
          " in the safe area",
        ),
        el(
          "div",
          {class: "info"},
          `${hack.points_per_puck} per puck, −${hack.decoy_penalty} per decoy · ` +
            `safe place ${hack.safe_place || "SAFE"}`,
        ),
      );
      if (refbox) {
        game.push(el("div", {}, `refbox ${s.points} points · ${s.phase || "–"} · ${s.gameState || "–"}`));
      }
    } else {
      game.push(
        el("div", {class: "big", "data-points": String(s.points)}, `${s.points} points`),
        el("div", {}, `${s.phase || "–"} · ${s.gameState || "–"}`),
      );
    }
    game.push(el("div", {}, `game time ${fmtTime(this.time)}`));
    if (phases) game.push(el("div", {class: "info"}, phases));
    if (refbox) game.push(el("div", {}, `delivery gate: ${gate ?? "–"}`));
    game.push(
      el(
        "div",
        {class: "info"},
        `radio drops ${s.drops} · collisions ${s.collisions} · skill failures ${s.skillFailures}`,
      ),
    );
    let legend: HTMLElement;
    if (hack) {
      // The colours: swatch (decoys crossed), name, pucks in the safe area (released there, as the
      // last rescue event says) of all of that colour.
      const inSafe = new Map<string, number>();
      const total = new Map<string, number>();
      for (const c of Object.values(hack.pucks ?? {})) {
        total.set(c, (total.get(c) ?? 0) + 1);
      }
      for (const id of s.rescue.pucks) {
        const c = hack.pucks?.[String(id)];
        if (c !== undefined) inSafe.set(c, (inSafe.get(c) ?? 0) + 1);
      }
      legend = el(
        "div",
        {class: "legend colours", "data-legend": "colours"},
        ...(hack.colours ?? []).map((c) =>
          el(
            "span",
            {"data-colour": c.name, title: c.decoy ? "decoy: costs points in the safe area" : "counts"},
            el("i", {class: c.decoy ? "decoy" : "", style: `background-color:${colourCss(c.name)}`}),
            c.decoy ? `${c.name} (decoy)` : c.name,
            ` ${inSafe.get(c.name) ?? 0}/${total.get(c.name) ?? 0} safe`,
          ),
        ),
      );
    } else {
      legend = el(
        "div",
        {class: "legend"},
        ...Object.entries(kPuckColors).map(([st, c]) =>
          el("span", {}, el("i", {style: `background:${c}`}), st),
        ),
      );
    }
    this.panel.replaceChildren(
      el("div", {class: "game"}, ...game),
      orders.length > 0
        ? table(
            ["order", "product", "delivered", "window (production)"],
            orders.map((o) => [
              o.id,
              o.product,
              `${o.delivered}/${o.requested}`,
              `${fmtTime(o.window[0])}–${fmtTime(o.window[1])}`,
            ]),
            {"data-table": "orders", class: "small"},
          )
        : hack
          ? ""
          : el("div", {class: "info"}, "no orders yet"),
      ...robotRows,
      legend,
    );
  }

  /// A robot's name in the panel: a click opens the agent browser on it.
  private robotName(name: string, color: string, role: string): HTMLElement {
    const e = el(
      "div",
      {class: "rname", style: `color:${color}`, title: `${name}'s agent: facts, rule firings, log`},
      name,
      role ? ` · ${role}` : "",
    );
    e.onclick = () => this.showAgent(name);
    return e;
  }

  // --- timeline ---

  private timelineX(t: number): number {
    const w = this.timeline.clientWidth;
    const end = Math.max(1, this.rec.endTime);
    return 8 + (t / end) * (w - 16);
  }

  private timelineT(x: number): number {
    const w = this.timeline.clientWidth;
    const end = Math.max(1, this.rec.endTime);
    return Math.max(0, Math.min(end, ((x - 8) / (w - 16)) * end));
  }

  private markerNear(x: number): {t: number; label: string} | null {
    let best: {t: number; label: string} | null = null;
    let bestD = 5;
    for (const m of this.rec.markers) {
      const d = Math.abs(this.timelineX(m.t) - x);
      if (d < bestD) {
        bestD = d;
        best = m;
      }
    }
    return best;
  }

  private setupTimeline(): void {
    let dragging = false;
    const seekAt = (ev: PointerEvent, snap: boolean) => {
      const x = ev.offsetX;
      const m = snap ? this.markerNear(x) : null;
      this.seek(m ? m.t : this.timelineT(x));
    };
    this.timeline.addEventListener("pointerdown", (ev) => {
      dragging = true;
      this.timeline.setPointerCapture(ev.pointerId);
      seekAt(ev, true);
    });
    this.timeline.addEventListener("pointermove", (ev) => {
      if (dragging) seekAt(ev, false);
      const m = this.markerNear(ev.offsetX);
      this.tip.textContent = m ? `${fmtTime(m.t)} ${m.label}` : fmtTime(this.timelineT(ev.offsetX));
      this.tip.style.left = `${Math.min(ev.offsetX, this.timeline.clientWidth - 260)}px`;
      this.tip.style.display = "block";
    });
    this.timeline.addEventListener("pointerup", () => (dragging = false));
    this.timeline.addEventListener("pointerleave", () => (this.tip.style.display = "none"));
  }

  private drawTimeline(): void {
    const c = this.timeline;
    const dpr = window.devicePixelRatio || 1;
    const w = c.clientWidth;
    const hgt = c.clientHeight;
    if (w === 0) return;
    const key = `${w}x${hgt}@${dpr}/${this.rec.markers.length}/${this.rec.endTime}`;
    if (key !== this.timelineKey || !this.timelineCache) {
      this.timelineKey = key;
      const cache = this.timelineCache ?? document.createElement("canvas");
      cache.width = Math.round(w * dpr);
      cache.height = Math.round(hgt * dpr);
      const g = cache.getContext("2d")!;
      g.setTransform(dpr, 0, 0, dpr, 0, 0);
      g.fillStyle = "#f3f3f3";
      g.fillRect(0, 0, w, hgt);
      // Phases as bands.
      const starts = this.rec.phaseStarts;
      starts.forEach((p, i) => {
        const x0 = this.timelineX(p.t);
        const x1 = this.timelineX(i + 1 < starts.length ? starts[i + 1].t : this.rec.endTime);
        g.fillStyle = p.phase === "EXPLORATION" ? "#fbecd2" : p.phase === "PRODUCTION" ? "#dde7f3" : "#eee";
        g.fillRect(x0, 0, x1 - x0, hgt);
        g.fillStyle = "#777";
        g.font = "10px sans-serif";
        g.textBaseline = "top";
        g.textAlign = "left";
        g.fillText(p.phase.toLowerCase(), x0 + 3, 2);
      });
      // The hackathon score as a step line (scaled to its range, 0 included).
      const steps = this.rec.rescueSteps;
      if (steps.length > 0) {
        const lo = Math.min(0, ...steps.map((p) => p.points));
        const hi = Math.max(1, ...steps.map((p) => p.points));
        const yOf = (v: number) => hgt - 4 - ((v - lo) / (hi - lo)) * (hgt - 16);
        g.strokeStyle = "rgba(0, 137, 123, 0.6)";
        g.lineWidth = 1.5;
        g.beginPath();
        g.moveTo(this.timelineX(0), yOf(0));
        let last = 0;
        for (const p of steps) {
          g.lineTo(this.timelineX(p.t), yOf(last));
          g.lineTo(this.timelineX(p.t), yOf(p.points));
          last = p.points;
        }
        g.lineTo(this.timelineX(this.rec.endTime), yOf(last));
        g.stroke();
        g.fillStyle = "#00695c";
        g.font = "10px sans-serif";
        g.textAlign = "right";
        g.textBaseline = "top";
        g.fillText(`rescue ${last} points`, w - 10, 2);
      }
      // Rows: the skills' log lines and the agents' errors at the top, awards and rescues,
      // failures and the navigator's refusals, collisions at the bottom.
      const rows = {log: 0.2, agent: 0.2, award: 0.45, failure: 0.68, nav: 0.68, collision: 0.88, rescue: 0.45};
      const colors = {
        award: "#2e7d32",
        failure: "#c0392b",
        collision: "#ef6c00",
        rescue: "#00897b",
        log: "#1f5fa8",
        nav: "#8e24aa",
        agent: "#d81b60",
      };
      for (const m of this.rec.markers) {
        const x = this.timelineX(m.t);
        g.strokeStyle = colors[m.kind];
        g.lineWidth = 2;
        g.beginPath();
        g.moveTo(x, hgt * rows[m.kind] - 6);
        g.lineTo(x, hgt * rows[m.kind] + 5);
        g.stroke();
      }
      this.timelineCache = cache;
    }
    if (c.width !== Math.round(w * dpr) || c.height !== Math.round(hgt * dpr)) {
      c.width = Math.round(w * dpr);
      c.height = Math.round(hgt * dpr);
    }
    const ctx = c.getContext("2d")!;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.drawImage(this.timelineCache!, 0, 0);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    const x = this.timelineX(this.time);
    ctx.strokeStyle = "#000";
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(x, 0);
    ctx.lineTo(x, hgt);
    ctx.stroke();
  }
}

/// Reads a response body as lines into the recording, chunk by chunk (the page shows the game
/// while the rest loads).
async function loadInto(replay: Replay, url: string, signal: AbortSignal): Promise<void> {
  replay.setStatus("loading…");
  const res = await fetch(url, {signal});
  if (!res.ok) throw new Error(await errorText(res));
  const reader = res.body!.getReader();
  const decoder = new TextDecoder();
  let rest = "";
  let started = false;
  for (;;) {
    const {done, value} = await reader.read();
    if (done) break;
    rest += decoder.decode(value, {stream: true});
    const lines = rest.split("\n");
    rest = lines.pop() ?? "";
    for (const l of lines) replay.rec.appendText(l);
    if (!started && replay.rec.header) {
      started = true;
      replay.start();
    }
  }
  rest += decoder.decode();
  if (rest.trim()) replay.rec.appendText(rest);
  if (!replay.rec.header) throw new Error(`${url}: the recording is empty`);
  if (!started) replay.start();
  const h = replay.rec.header;
  replay.setStatus(
    `${replay.rec.lineTotal} lines · ${h.robots.length} robots · seed ${h.seed}`,
  );
  replay.ready = true;
  app.setAttribute("data-ready", "true");
}

function replayPage(url: string, title: string, signal: AbortSignal): () => void {
  const replay = new Replay(false);
  replay.setTitle(title);
  app.replaceChildren(replay.root);
  loadInto(replay, url, signal)
    .then(() => {
      const h = replay.rec.header!;
      replay.setTitle(
        `${title} · ${h.scenario}${h.variant ? ` (${h.variant})` : ""} · seed ${h.seed}`,
      );
    })
    .catch((e) => replay.fail(e));
  return () => replay.stop();
}

function livePage(signal: AbortSignal): () => void {
  const replay = new Replay(true);
  replay.setTitle("live game");
  app.replaceChildren(replay.root);
  replay.setFollow(true);
  let ws: WebSocket | null = null;
  let retry = 0;
  let closed = false;
  const connect = async () => {
    if (closed) return;
    try {
      const st = await fetchJson<{live: boolean}>("/api/live/status", signal);
      if (!st.live) {
        replay.setStatus("no live game is served; waiting…");
        retry = window.setTimeout(connect, 2000);
        return;
      }
    } catch (e) {
      if (closed) return;
      replay.setStatus(`live status: ${e instanceof Error ? e.message : String(e)}; retrying…`);
      retry = window.setTimeout(connect, 2000);
      return;
    }
    const proto = location.protocol === "https:" ? "wss:" : "ws:";
    ws = new WebSocket(`${proto}//${location.host}/api/live`);
    let started = false;
    let rest = "";
    replay.setStatus("connecting…");
    ws.onmessage = (ev) => {
      if (typeof ev.data !== "string") return;
      // Messages hold whole lines; a trailing partial line is kept for the next one.
      const lines = (rest + ev.data).split("\n");
      rest = lines.pop() ?? "";
      try {
        if (rest.trim() !== "") {
          // A message ending without "\n" whose last line parses is complete.
          try {
            JSON.parse(rest);
            lines.push(rest);
            rest = "";
          } catch {
            // incomplete: wait for the rest
          }
        }
        for (const l of lines) replay.rec.appendText(l);
      } catch (e) {
        replay.fail(e);
        ws?.close();
        return;
      }
      if (!started && replay.rec.header) {
        started = true;
        replay.start();
        replay.ready = true;
        app.setAttribute("data-ready", "true");
      }
      replay.setStatus(`live${over ? " · game over" : ""} · ${replay.rec.lineTotal} lines`);
    };
    // The server keeps the socket open after the game; its status says when the game is over.
    let over = false;
    const poll = async () => {
      if (closed || over) return;
      try {
        const st = await fetchJson<{live: boolean; running?: boolean}>("/api/live/status", signal);
        if (st.running === false) {
          over = true;
          replay.setStatus(`live · game over · ${replay.rec.lineTotal} lines`);
          return;
        }
      } catch {
        // the server may be gone (--serve-exit): stop polling
        return;
      }
      retry = window.setTimeout(poll, 2000);
    };
    retry = window.setTimeout(poll, 2000);
    ws.onclose = () => {
      if (!closed) replay.setStatus(`live game ended · ${replay.rec.lineTotal} lines`);
    };
    ws.onerror = () => {
      if (!closed) replay.setStatus("live connection failed");
    };
  };
  void connect();
  return () => {
    closed = true;
    window.clearTimeout(retry);
    ws?.close();
    replay.stop();
  };
}

// ---------------------------------------------------------------------------------------------
// The router.

function route(): void {
  teardown?.();
  teardown = null;
  const controller = new AbortController();
  const signal = controller.signal;
  app.removeAttribute("data-ready");
  app.removeAttribute("data-error");
  const hash = location.hash.replace(/^#/, "") || "/";
  let m: RegExpExecArray | null;
  let stop: (() => void) | null = null;
  if ((m = /^\/batch\/([^/]+)$/.exec(hash))) {
    app.setAttribute("data-page", "batch");
    batchPage(decodeURIComponent(m[1]), signal);
  } else if ((m = /^\/run\/([^/]+)$/.exec(hash))) {
    app.setAttribute("data-page", "run");
    stop = replayPage(`/api/runs/${m[1]}/recording`, `run ${decodeURIComponent(m[1])}`, signal);
  } else if ((m = /^\/file\/(.+)$/.exec(hash))) {
    app.setAttribute("data-page", "file");
    const path = decodeURIComponent(m[1]);
    const url = `/api/recordings/${path.split("/").map(encodeURIComponent).join("/")}`;
    stop = replayPage(url, path, signal);
  } else if (hash === "/live") {
    app.setAttribute("data-page", "live");
    stop = livePage(signal);
  } else {
    app.setAttribute("data-page", "batches");
    batchesPage(signal);
  }
  teardown = () => {
    controller.abort();
    stop?.();
  };
}

window.addEventListener("hashchange", route);
route();
