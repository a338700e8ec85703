// SPDX-License-Identifier: MIT
// Draws the field to scale on a 2D canvas: walls, the 16 devices with name, type and lamps,
// pucks coloured by state, robots with heading, name, held puck, skill and status, the believed
// pose as a ghost, lock holders, radio drops and planned paths. Worlds with extra obstacles get
// them as dark boxes; the hackathon variant (docs/hackathon.md) its safe area and coloured pucks,
// each robot's flashlight cone and what its camera reported (fading with age); a finer grid with
// coordinates on request.
import {kSightingMemory, type Header, type State} from "./recording";

export const kRobotColors = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b", "#e377c2"];

export const kPuckColors: Record<string, string> = {
  S0: "#f4f4f4",
  S1: "#f2c94c",
  S2: "#f2994a",
  P1: "#56ccf2",
  P2: "#2f80ed",
  P3: "#9b51e0",
  CONSUMED: "#666666",
  FINISHED: "#27ae60",
};

const kLampColors = ["#e53935", "#fbc02d", "#43a047"];
const kLampOff = ["#4a2323", "#4a4123", "#234a26"];

/// CSS colours of the hackathon's colour names; other names are tried as CSS colours, then
/// given one of kFallbackColours by a hash of the name.
const kNamedColours: Record<string, string> = {
  red: "#e53935",
  green: "#43a047",
  blue: "#1e88e5",
  yellow: "#fdd835",
  orange: "#fb8c00",
  purple: "#8e24aa",
  violet: "#8e24aa",
  magenta: "#d81b60",
  pink: "#f06292",
  cyan: "#00acc1",
  white: "#fafafa",
  black: "#212121",
  grey: "#9e9e9e",
  gray: "#9e9e9e",
  brown: "#6d4c41",
};
const kFallbackColours = ["#00897b", "#5e35b1", "#c0ca33", "#6d4c41", "#546e7a", "#f4511e"];
const colourCache = new Map<string, string>();

/// The CSS colour to draw pucks of the hackathon colour `name` with.
export function colourCss(name: string): string {
  const known = colourCache.get(name);
  if (known) return known;
  const key = name.trim().toLowerCase();
  let css = kNamedColours[key];
  if (!css) {
    // A CSS colour name the browser knows ("teal", "#abc") is taken as it is.
    const probe = document.createElement("canvas").getContext("2d");
    if (probe) {
      probe.fillStyle = "#010203";
      probe.fillStyle = key;
      if (probe.fillStyle !== "#010203") css = probe.fillStyle;
    }
  }
  if (!css) {
    let h = 0;
    for (const ch of key) h = (h * 31 + ch.charCodeAt(0)) >>> 0;
    css = kFallbackColours[h % kFallbackColours.length];
  }
  colourCache.set(name, css);
  return css;
}

/// Black or white, whichever reads better on `css` (a #rrggbb colour; others get black).
function textOn(css: string): string {
  const m = /^#([0-9a-f]{2})([0-9a-f]{2})([0-9a-f]{2})$/i.exec(css);
  if (!m) return "#000";
  const [r, g, b] = [m[1], m[2], m[3]].map((x) => parseInt(x, 16));
  return 0.299 * r + 0.587 * g + 0.114 * b < 140 ? "#fff" : "#000";
}

export interface DrawStats {
  devices: number;
  robots: number;
  pucks: number;
  obstacles: number;
  /// Flashlight cones drawn (hackathon recordings with the camera in the header).
  cones: number;
  /// Camera sightings drawn (every frame still within kSightingMemory s).
  sightings: number;
  /// Of them, from each robot's latest frame (age below one camera frame, 0.15 s).
  freshSightings: number;
  /// Each robot drawn with a held puck: where its labels and the puck are (canvas CSS pixels,
  /// y down), for the check that the labels keep clear of the puck (viewer_e2e).
  heldLabels: HeldLabel[];
}

/// A robot holding a puck as drawn: its heading (rad), the bottom of its name label, the top of
/// its skill label (null: none drawn) and the puck's top and bottom.
export interface HeldLabel {
  robot: string;
  th: number;
  nameBottom: number;
  skillTop: number | null;
  puckTop: number;
  puckBottom: number;
}

/// Options of drawField.
export interface DrawOptions {
  /// A robot's name that gets a ring (the agent browser's robot).
  selected?: string;
  /// A 0.25 m grid with the metres written along the field's edges (else the 1 m grid alone).
  grid?: boolean;
  /// A point to mark (the mouse), in field coordinates.
  mouse?: [number, number] | null;
  /// Goals the navigator refused or gave up on lately: a purple cross there, fading with age (s).
  navGoals?: {x: number; y: number; age: number; refused: boolean}[];
}

/// How a puck is drawn: fill, label colour, and the hackathon's marks.
interface PuckLook {
  fill: string;
  text: string;
  decoy: boolean;  // hackathon: a colour that costs points (an 'x' over it)
  counted: boolean;  // hackathon: in the safe area and scored (a ring around it)
}

/// Whether a lamp in mode m (0 off, 1 on, 2 blinking at 2 Hz) is lit at simulated time t.
function lit(m: number, t: number): boolean {
  return m === 1 || (m === 2 && Math.floor(t * 4) % 2 === 0);
}

/// Where the field is drawn on a canvas of cssW x cssH CSS pixels: pixels per metre `s` and the
/// offset of the field's corner; the field point (x, y) is at (ox + x s, oy + (height - y) s).
export function fieldScale(cssW: number, cssH: number, header: Header): {s: number; ox: number; oy: number} {
  const fw = header.field.width;
  const fh = header.field.height;
  const margin = 14;
  const s = Math.max(1, Math.min((cssW - 2 * margin) / fw, (cssH - 2 * margin) / fh));
  return {s, ox: (cssW - fw * s) / 2, oy: (cssH - fh * s) / 2};
}

/// Draws the field at `time`; `selected` (a robot's name) gets a ring (the agent browser's robot).
export function drawField(
  canvas: HTMLCanvasElement,
  header: Header,
  state: State,
  poses: number[][],
  time: number,
  options: DrawOptions = {},
): DrawStats {
  const selected = options.selected ?? "";
  const dpr = window.devicePixelRatio || 1;
  const cssW = canvas.clientWidth;
  const cssH = canvas.clientHeight;
  if (canvas.width !== Math.round(cssW * dpr) || canvas.height !== Math.round(cssH * dpr)) {
    canvas.width = Math.round(cssW * dpr);
    canvas.height = Math.round(cssH * dpr);
  }
  const ctx = canvas.getContext("2d")!;
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, cssW, cssH);
  const fw = header.field.width;
  const fh = header.field.height;
  const {s, ox, oy} = fieldScale(cssW, cssH, header);
  const X = (x: number) => ox + x * s;
  const Y = (y: number) => oy + (fh - y) * s;
  const stats: DrawStats = {
    devices: 0,
    robots: 0,
    pucks: 0,
    obstacles: 0,
    cones: 0,
    sightings: 0,
    freshSightings: 0,
    heldLabels: [],
  };
  const hack = header.hackathon;

  // The floor, a 1 m grid and the walls.
  ctx.fillStyle = "#fafaf7";
  ctx.fillRect(X(0), Y(fh), fw * s, fh * s);
  // The metre lines in `colour`.
  const metreLines = (colour: string) => {
    ctx.strokeStyle = colour;
    ctx.beginPath();
    for (let x = 1; x < fw; x++) {
      ctx.moveTo(X(x), Y(0));
      ctx.lineTo(X(x), Y(fh));
    }
    for (let y = 1; y < fh; y++) {
      ctx.moveTo(X(0), Y(y));
      ctx.lineTo(X(fw), Y(y));
    }
    ctx.stroke();
  };
  ctx.lineWidth = 1;
  metreLines("#e6e6e0");
  if (options.grid) {
    // The finer grid (0.25 m) and the metres along the bottom and left edges.
    ctx.strokeStyle = "#eeeee8";
    ctx.beginPath();
    for (let k = 1; k < fw * 4; k++) {
      if (k % 4 === 0) continue;
      ctx.moveTo(X(k / 4), Y(0));
      ctx.lineTo(X(k / 4), Y(fh));
    }
    for (let k = 1; k < fh * 4; k++) {
      if (k % 4 === 0) continue;
      ctx.moveTo(X(0), Y(k / 4));
      ctx.lineTo(X(fw), Y(k / 4));
    }
    ctx.stroke();
    metreLines("#cfcfc6");
    ctx.fillStyle = "#777";
    ctx.font = "10px sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "bottom";
    for (let x = 0; x <= fw + 1e-9; x++) ctx.fillText(String(x), X(x), Y(0) - 2);
    ctx.textAlign = "left";
    ctx.textBaseline = "middle";
    for (let y = 1; y <= fh + 1e-9; y++) ctx.fillText(String(y), X(0) + 3, Y(y));
  }

  // Hackathon: the safe area, tinted and hatched, labelled with its planner place.
  const fontPx = Math.max(9, Math.min(13, s * 0.09));
  if (hack && Array.isArray(hack.safe_area) && hack.safe_area.length === 4) {
    const [x0, y0, x1, y1] = hack.safe_area;
    const rx = X(x0);
    const ry = Y(y1);
    const rw = (x1 - x0) * s;
    const rh = (y1 - y0) * s;
    ctx.save();
    ctx.fillStyle = "rgba(46, 160, 67, 0.16)";
    ctx.fillRect(rx, ry, rw, rh);
    ctx.beginPath();
    ctx.rect(rx, ry, rw, rh);
    ctx.clip();
    ctx.strokeStyle = "rgba(46, 125, 50, 0.35)";
    ctx.lineWidth = 1;
    ctx.beginPath();
    for (let d = -rh; d < rw; d += 9) {
      ctx.moveTo(rx + d, ry + rh);
      ctx.lineTo(rx + d + rh, ry);
    }
    ctx.stroke();
    ctx.restore();
    ctx.strokeStyle = "#2e7d32";
    ctx.lineWidth = 2;
    ctx.setLineDash([6, 3]);
    ctx.strokeRect(rx, ry, rw, rh);
    ctx.setLineDash([]);
    const label = hack.safe_place || "SAFE";
    ctx.font = `bold ${fontPx}px sans-serif`;
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    const tw = ctx.measureText(label).width;
    ctx.fillStyle = "rgba(250,250,247,0.85)";
    ctx.fillRect(rx + rw / 2 - tw / 2 - 2, ry + 4, tw + 4, fontPx + 2);
    ctx.fillStyle = "#1b5e20";
    ctx.fillText(label, rx + rw / 2, ry + 5);
  }

  ctx.strokeStyle = "#333";
  ctx.lineWidth = 3;
  ctx.strokeRect(X(0), Y(fh), fw * s, fh * s);

  // Extra static obstacles: dark boxes.
  for (const o of header.obstacles ?? []) {
    if (!Array.isArray(o.box) || o.box.length < 4) continue;
    const [cx, cy, sx, sy, theta = 0] = o.box;
    ctx.save();
    ctx.translate(X(cx), Y(cy));
    ctx.rotate(-theta);
    ctx.fillStyle = "#37474f";
    ctx.strokeStyle = "#111";
    ctx.lineWidth = 1.2;
    ctx.fillRect((-sx / 2) * s, (-sy / 2) * s, sx * s, sy * s);
    ctx.strokeRect((-sx / 2) * s, (-sy / 2) * s, sx * s, sy * s);
    ctx.restore();
    if (o.name && sx * s >= 24) {
      ctx.font = `${Math.max(8, fontPx - 3)}px sans-serif`;
      ctx.textAlign = "center";
      ctx.textBaseline = "middle";
      ctx.fillStyle = "#eceff1";
      ctx.fillText(o.name, X(cx), Y(cy));
    }
    stats.obstacles++;
  }

  const robotColor = new Map<string, string>();
  header.robots.forEach((r, i) => robotColor.set(r, kRobotColors[i % kRobotColors.length]));

  // Lock holders per resource (ACCEPTED until another state).
  const holders = new Map<string, string[]>();
  for (const [name, r] of Object.entries(state.robots)) {
    for (const [res, st] of Object.entries(r.locks)) {
      if (st === "ACCEPTED") holders.set(res, [...(holders.get(res) ?? []), name]);
    }
  }

  // Planned paths, under everything else.
  header.robots.forEach((name) => {
    const path = state.robots[name]?.path;
    if (!path || path.length < 2) return;
    ctx.save();
    ctx.strokeStyle = robotColor.get(name)!;
    ctx.globalAlpha = 0.55;
    ctx.lineWidth = 2;
    ctx.setLineDash([6, 4]);
    ctx.beginPath();
    path.forEach(([x, y], i) => (i === 0 ? ctx.moveTo(X(x), Y(y)) : ctx.lineTo(X(x), Y(y))));
    ctx.stroke();
    ctx.restore();
  });

  // Devices: footprint, lamps, name and type, lock holders.
  for (const d of header.devices) {
    const [cx, cy, depth, width, theta] = d.box;
    ctx.save();
    ctx.translate(X(cx), Y(cy));
    ctx.rotate(-theta);
    const holder = holders.get(d.name);
    ctx.fillStyle = d.name.startsWith("D") ? "#d8e8d8" : d.name.startsWith("M") ? "#dcdcdc" : "#e8e0d0";
    ctx.strokeStyle = holder ? robotColor.get(holder[0]) ?? "#000" : "#555";
    ctx.lineWidth = holder ? 3 : 1.2;
    ctx.fillRect((-depth / 2) * s, (-width / 2) * s, depth * s, width * s);
    ctx.strokeRect((-depth / 2) * s, (-width / 2) * s, depth * s, width * s);
    // The facing side (where robots work).
    ctx.strokeStyle = "#222";
    ctx.lineWidth = 2.5;
    ctx.beginPath();
    ctx.moveTo((depth / 2) * s, (-width / 2) * s);
    ctx.lineTo((depth / 2) * s, (width / 2) * s);
    ctx.stroke();
    ctx.restore();

    // The signal column: red, yellow, green from top to bottom, upright on screen.
    const lamps = state.lights[d.name] ?? [0, 0, 0];
    const lr = Math.max(2.5, Math.min(6, s * 0.03));
    const lx = X(d.x);
    const ly = Y(d.y) - lr * 2.2;
    for (let k = 0; k < 3; k++) {
      ctx.beginPath();
      ctx.arc(lx, ly + k * lr * 2.2, lr, 0, 2 * Math.PI);
      ctx.fillStyle = lit(lamps[k] ?? 0, time) ? kLampColors[k] : kLampOff[k];
      ctx.fill();
      if (lamps[k] === 2) {
        ctx.strokeStyle = kLampColors[k];
        ctx.lineWidth = 1;
        ctx.stroke();
      }
    }
    // Label: name and type (the plan's, with a check mark once an agent explored it).
    const planned = state.planTypes[d.name];
    const explored = state.exploredTypes[d.name];
    let label = d.name;
    if (planned || explored) label += ` ${explored ?? planned}${explored ? " ✓" : ""}`;
    ctx.font = `${fontPx}px sans-serif`;
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    const ty = Y(d.y) + Math.max(width, depth) * s * 0.5 + 2;
    ctx.fillStyle = "rgba(250,250,247,0.8)";
    const tw = ctx.measureText(label).width;
    ctx.fillRect(lx - tw / 2 - 2, ty - 1, tw + 4, fontPx + 2);
    ctx.fillStyle = "#222";
    ctx.fillText(label, lx, ty);
    if (holder) {
      ctx.fillStyle = robotColor.get(holder[0]) ?? "#000";
      ctx.font = `bold ${fontPx - 1}px sans-serif`;
      ctx.fillText(`lock: ${holder.join(",")}`, lx, ty + fontPx + 2);
    }
    stats.devices++;
  }

  // Pucks on the field (held ones are drawn with their robot).
  const held = new Set(poses.map((p) => p[6]).filter((id) => id > 0));
  // Hackathon pucks are drawn a little larger so that their colour shows.
  const pr = Math.max(hack ? 5.5 : 2.5, header.puck_radius * s);
  const decoyColours = new Set((hack?.colours ?? []).filter((c) => c.decoy).map((c) => c.name));
  const counted = new Set(state.rescue.pucks);
  const look = (id: number): PuckLook => {
    const colour = hack?.pucks?.[String(id)];
    if (colour !== undefined) {
      const fill = colourCss(colour);
      return {fill, text: textOn(fill), decoy: decoyColours.has(colour), counted: counted.has(id)};
    }
    const st = state.pucks[id]?.state ?? "";
    return {
      fill: kPuckColors[st] ?? "#bbbbbb",
      text: st === "CONSUMED" || st === "P2" || st === "P3" ? "#fff" : "#000",
      decoy: false,
      counted: false,
    };
  };
  for (const [idText, q] of Object.entries(state.pucks)) {
    const id = Number(idText);
    if (!q.on || held.has(id)) continue;
    drawPuck(ctx, X(q.x), Y(q.y), pr, look(id), id, fontPx);
    stats.pucks++;
  }

  // Hackathon: each robot's flashlight cone (from its centre, range and opening of the header's
  // camera), then what its camera reported: a ring in the reported colour at the reported field
  // position, fading over kSightingMemory s (the latest frame drawn solid).
  const cam = hack?.camera;
  if (cam && cam.range_m > 0 && cam.fov_deg > 0) {
    const half = (cam.fov_deg * Math.PI) / 360;
    poses.forEach((p, i) => {
      const color = robotColor.get(header.robots[i] ?? "") ?? "#000";
      const [x, y, th] = p;
      ctx.save();
      ctx.fillStyle = "rgba(255, 236, 130, 0.28)";
      ctx.strokeStyle = color;
      ctx.globalAlpha = 0.9;
      ctx.lineWidth = 1;
      ctx.setLineDash([3, 3]);
      ctx.beginPath();
      ctx.moveTo(X(x), Y(y));
      // Canvas angles run clockwise (y down): the field's heading th is -th on screen.
      ctx.arc(X(x), Y(y), cam.range_m * s, -th - half, -th + half);
      ctx.closePath();
      ctx.fill();
      ctx.stroke();
      ctx.restore();
      stats.cones++;
    });
  }
  header.robots.forEach((name) => {
    const frames = state.robots[name]?.sightings;
    if (!frames) return;
    // The camera's latest frame (its last line, with pucks or empty) is drawn solid while it is
    // new (under 0.15 s, a 10 Hz camera's next frame comes after 0.1 s).
    const latest = state.robots[name]?.sightingT ?? -1;
    for (const f of frames) {
      const age = time - f.t;
      if (age < 0 || age > kSightingMemory) continue;
      const fresh = f.t === latest && age < 0.15;
      ctx.save();
      ctx.globalAlpha = fresh ? 1 : Math.max(0.08, 0.6 * (1 - age / kSightingMemory));
      for (const [px, py, colour] of f.pucks) {
        const r = Math.max(4, header.puck_radius * s) + 3;
        ctx.beginPath();
        ctx.arc(X(px), Y(py), r, 0, 2 * Math.PI);
        ctx.strokeStyle = colourCss(colour);
        ctx.lineWidth = fresh ? 2.5 : 1.5;
        ctx.stroke();
        if (fresh) {
          // A cross at the reported centre: where the skill believes the puck is.
          ctx.beginPath();
          ctx.moveTo(X(px) - 3, Y(py));
          ctx.lineTo(X(px) + 3, Y(py));
          ctx.moveTo(X(px), Y(py) - 3);
          ctx.lineTo(X(px), Y(py) + 3);
          ctx.strokeStyle = "#111";
          ctx.lineWidth = 1;
          ctx.stroke();
          stats.freshSightings++;
        }
        stats.sightings++;
      }
      ctx.restore();
    }
  });

  // Robots: believed pose as a ghost, body, heading, held puck, name, skill and status.
  const rr = header.robot_radius * s;
  poses.forEach((p, i) => {
    const name = header.robots[i] ?? `robot${i + 1}`;
    const color = robotColor.get(name) ?? "#000";
    const rs = state.robots[name];
    const [x, y, th, bx, by, bth, heldId] = p;
    const ghost = Math.hypot(bx - x, by - y) > 0.02 || Math.abs(angleDiff(bth, th)) > 0.05;
    if (ghost) {
      ctx.save();
      ctx.globalAlpha = 0.5;
      ctx.setLineDash([4, 3]);
      ctx.strokeStyle = color;
      ctx.lineWidth = 1.5;
      ctx.beginPath();
      ctx.arc(X(bx), Y(by), rr, 0, 2 * Math.PI);
      ctx.moveTo(X(bx), Y(by));
      ctx.lineTo(X(bx) + Math.cos(bth) * rr, Y(by) - Math.sin(bth) * rr);
      ctx.stroke();
      ctx.restore();
    }
    if (name === selected) {
      ctx.save();
      ctx.globalAlpha = 0.35;
      ctx.strokeStyle = color;
      ctx.lineWidth = 5;
      ctx.beginPath();
      ctx.arc(X(x), Y(y), rr + 6, 0, 2 * Math.PI);
      ctx.stroke();
      ctx.restore();
    }
    ctx.beginPath();
    ctx.arc(X(x), Y(y), rr, 0, 2 * Math.PI);
    ctx.fillStyle = color + "33";
    ctx.fill();
    ctx.strokeStyle = color;
    ctx.lineWidth = 2;
    ctx.stroke();
    ctx.beginPath();
    ctx.moveTo(X(x), Y(y));
    ctx.lineTo(X(x) + Math.cos(th) * rr, Y(y) - Math.sin(th) * rr);
    ctx.stroke();
    // The labels go above (name) and below (skill) the robot, clear of a held puck that sticks
    // out there (it used to be drawn over the skill label when the robot faced down).
    let nameY = Y(y) - rr - 2;
    let skillY = Y(y) + rr + 2;
    let held: HeldLabel | null = null;
    if (heldId > 0) {
      const hx = X(x) + Math.cos(th) * (rr + pr * 0.6);
      const hy = Y(y) - Math.sin(th) * (rr + pr * 0.6);
      drawPuck(ctx, hx, hy, pr, look(heldId), heldId, fontPx);
      nameY = Math.min(nameY, hy - pr - 2);
      skillY = Math.max(skillY, hy + pr + 2);
      held = {robot: name, th, nameBottom: nameY, skillTop: null, puckTop: hy - pr,
              puckBottom: hy + pr};
      stats.heldLabels.push(held);
    }
    // A radio drop from this robot in the last second: a red flash on its rim.
    if (rs && time - rs.dropT >= 0 && time - rs.dropT < 1) {
      ctx.strokeStyle = "#e53935";
      ctx.lineWidth = 3;
      ctx.beginPath();
      ctx.arc(X(x), Y(y), rr + 4, -0.6, 0.6);
      ctx.stroke();
      ctx.fillStyle = "#e53935";
      ctx.font = `bold ${fontPx}px sans-serif`;
      ctx.textAlign = "left";
      ctx.textBaseline = "middle";
      ctx.fillText("× drop", X(x) + rr + 6, Y(y));
    }
    ctx.font = `bold ${fontPx}px sans-serif`;
    ctx.textAlign = "center";
    ctx.textBaseline = "bottom";
    ctx.fillStyle = color;
    const jersey = header.jerseys?.[i];
    ctx.fillText(jersey !== undefined ? `${name} #${jersey}` : name, X(x), nameY);
    if (rs && rs.skill) {
      const short = rs.skill.length > 34 ? rs.skill.slice(0, 33) + "…" : rs.skill;
      ctx.font = `${fontPx - 1}px sans-serif`;
      ctx.textBaseline = "top";
      ctx.fillStyle =
        rs.status === "FAILED" ? "#c0392b" : rs.status === "FINAL" ? "#2e7d32" : "#333";
      const st = rs.skillState && rs.status === "RUNNING" ? ` · ${rs.skillState}` : "";
      ctx.fillText(`${short} ${rs.status}${st}`, X(x), skillY);
      if (held) held.skillTop = skillY;
    }
    stats.robots++;
  });

  // Radio drops without a sender: a flash in the corner.
  if (time - state.dropT >= 0 && time - state.dropT < 1) {
    ctx.fillStyle = "#e53935";
    ctx.font = `bold ${fontPx}px sans-serif`;
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    ctx.fillText(`radio drop (${state.drops} total)`, X(fw / 2), Y(fh) + 4);
  }

  // Goals the navigator refused (or failed to reach) in the last seconds: a purple cross.
  for (const g of options.navGoals ?? []) {
    ctx.save();
    ctx.globalAlpha = Math.max(0.15, 1 - g.age / 3);
    ctx.strokeStyle = "#8e24aa";
    ctx.lineWidth = 3;
    const k = 7;
    ctx.beginPath();
    ctx.moveTo(X(g.x) - k, Y(g.y) - k);
    ctx.lineTo(X(g.x) + k, Y(g.y) + k);
    ctx.moveTo(X(g.x) - k, Y(g.y) + k);
    ctx.lineTo(X(g.x) + k, Y(g.y) - k);
    ctx.stroke();
    ctx.fillStyle = "#8e24aa";
    ctx.font = `bold ${fontPx - 1}px sans-serif`;
    ctx.textAlign = "left";
    ctx.textBaseline = "bottom";
    ctx.fillText(g.refused ? "refused" : "failed", X(g.x) + k + 2, Y(g.y) - 2);
    ctx.restore();
  }

  // The mouse, with the grid on: a cross hair through the field.
  if (options.grid && options.mouse) {
    const [mx, my] = options.mouse;
    if (mx >= 0 && my >= 0 && mx <= fw && my <= fh) {
      ctx.save();
      ctx.strokeStyle = "rgba(43, 93, 154, 0.45)";
      ctx.lineWidth = 1;
      ctx.beginPath();
      ctx.moveTo(X(mx), Y(0));
      ctx.lineTo(X(mx), Y(fh));
      ctx.moveTo(X(0), Y(my));
      ctx.lineTo(X(fw), Y(my));
      ctx.stroke();
      ctx.restore();
    }
  }
  return stats;
}

function drawPuck(
  ctx: CanvasRenderingContext2D,
  x: number,
  y: number,
  r: number,
  look: PuckLook,
  id: number,
  fontPx: number,
): void {
  if (look.counted) {
    // In the safe area and scored: a ring, green (counts) or red (a decoy, costs points).
    ctx.beginPath();
    ctx.arc(x, y, r + 3, 0, 2 * Math.PI);
    ctx.strokeStyle = look.decoy ? "#c62828" : "#2e7d32";
    ctx.lineWidth = 2;
    ctx.stroke();
  }
  ctx.beginPath();
  ctx.arc(x, y, r, 0, 2 * Math.PI);
  ctx.fillStyle = look.fill;
  ctx.fill();
  ctx.strokeStyle = "#333";
  ctx.lineWidth = 1;
  ctx.stroke();
  if (look.decoy) {
    // A decoy: an 'x' across it, reaching past its rim.
    const k = r * 1.25;
    ctx.strokeStyle = "#111";
    ctx.lineWidth = 1.6;
    ctx.beginPath();
    ctx.moveTo(x - k, y - k);
    ctx.lineTo(x + k, y + k);
    ctx.moveTo(x - k, y + k);
    ctx.lineTo(x + k, y - k);
    ctx.stroke();
  } else if (r >= 5) {
    ctx.font = `${Math.max(7, fontPx - 3)}px sans-serif`;
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    ctx.fillStyle = look.text;
    ctx.fillText(String(id), x, y + 0.5);
  }
}

function angleDiff(a: number, b: number): number {
  let d = a - b;
  while (d > Math.PI) d -= 2 * Math.PI;
  while (d < -Math.PI) d += 2 * Math.PI;
  return d;
}
