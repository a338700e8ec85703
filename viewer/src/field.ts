// SPDX-License-Identifier: MIT
// Draws the field to scale on a 2D canvas: walls, the 16 devices with name, type and lamps,
// pucks coloured by state, robots with heading, name, held puck, skill and status, the believed
// pose as a ghost, lock holders, radio drops and planned paths.
import type {Header, State} from "./recording";

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

export interface DrawStats {
  devices: number;
  robots: number;
  pucks: number;
}

/// Whether a lamp in mode m (0 off, 1 on, 2 blinking at 2 Hz) is lit at simulated time t.
function lit(m: number, t: number): boolean {
  return m === 1 || (m === 2 && Math.floor(t * 4) % 2 === 0);
}

export function drawField(
  canvas: HTMLCanvasElement,
  header: Header,
  state: State,
  poses: number[][],
  time: number,
): DrawStats {
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
  const margin = 14;
  const s = Math.max(1, Math.min((cssW - 2 * margin) / fw, (cssH - 2 * margin) / fh));
  const ox = (cssW - fw * s) / 2;
  const oy = (cssH - fh * s) / 2;
  const X = (x: number) => ox + x * s;
  const Y = (y: number) => oy + (fh - y) * s;
  const stats: DrawStats = {devices: 0, robots: 0, pucks: 0};

  // The floor, a 1 m grid and the walls.
  ctx.fillStyle = "#fafaf7";
  ctx.fillRect(X(0), Y(fh), fw * s, fh * s);
  ctx.strokeStyle = "#e6e6e0";
  ctx.lineWidth = 1;
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
  ctx.strokeStyle = "#333";
  ctx.lineWidth = 3;
  ctx.strokeRect(X(0), Y(fh), fw * s, fh * s);

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
  const fontPx = Math.max(9, Math.min(13, s * 0.09));
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
  const pr = Math.max(2.5, header.puck_radius * s);
  for (const [idText, q] of Object.entries(state.pucks)) {
    const id = Number(idText);
    if (!q.on || held.has(id)) continue;
    drawPuck(ctx, X(q.x), Y(q.y), pr, q.state, id, fontPx);
    stats.pucks++;
  }

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
    if (heldId > 0) {
      const hx = X(x) + Math.cos(th) * (rr + pr * 0.6);
      const hy = Y(y) - Math.sin(th) * (rr + pr * 0.6);
      drawPuck(ctx, hx, hy, pr, state.pucks[heldId]?.state ?? "", heldId, fontPx);
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
    ctx.fillText(name, X(x), Y(y) - rr - 2);
    if (rs && rs.skill) {
      const short = rs.skill.length > 34 ? rs.skill.slice(0, 33) + "…" : rs.skill;
      ctx.font = `${fontPx - 1}px sans-serif`;
      ctx.textBaseline = "top";
      ctx.fillStyle =
        rs.status === "FAILED" ? "#c0392b" : rs.status === "FINAL" ? "#2e7d32" : "#333";
      ctx.fillText(`${short} ${rs.status}`, X(x), Y(y) + rr + 2);
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
  return stats;
}

function drawPuck(
  ctx: CanvasRenderingContext2D,
  x: number,
  y: number,
  r: number,
  state: string,
  id: number,
  fontPx: number,
): void {
  ctx.beginPath();
  ctx.arc(x, y, r, 0, 2 * Math.PI);
  ctx.fillStyle = kPuckColors[state] ?? "#bbbbbb";
  ctx.fill();
  ctx.strokeStyle = "#333";
  ctx.lineWidth = 1;
  ctx.stroke();
  if (r >= 5) {
    ctx.font = `${Math.max(7, fontPx - 3)}px sans-serif`;
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    ctx.fillStyle = state === "CONSUMED" || state === "P2" || state === "P3" ? "#fff" : "#000";
    ctx.fillText(String(id), x, y + 0.5);
  }
}

function angleDiff(a: number, b: number): number {
  let d = a - b;
  while (d > Math.PI) d -= 2 * Math.PI;
  while (d < -Math.PI) d += 2 * Math.PI;
  return d;
}
