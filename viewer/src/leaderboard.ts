// SPDX-License-Identifier: MIT
// The hackathon leaderboard's page (leaderboard.html, served by `llsfsim hackathon serve`): one
// board per exercise (#NAME in the address), the recent submissions, a submit form; refreshed
// every few seconds. The server's API: docs/hackathon-server.md.

interface Exercise {
  name: string;
  title: string;
  goal: string;
  better: "lower" | "higher";
}

interface ExerciseList {
  exercises: Exercise[];
  seeds: number;
  max_skill_bytes: number;
  max_per_minute: number;
}

interface SubmissionView {
  id: number;
  team: string;
  exercise: string;
  file_name: string;
  received: string;
  status: "queued" | "running" | "done" | "failed" | "timeout";
  passed?: number;
  total?: number;
  value?: number | null;
  verdict?: string;
  reason?: string;
  error?: string;
  rank?: number;
  submissions?: number;
}

interface Board {
  exercise: string;
  title: string;
  goal: string;
  better: "lower" | "higher";
  seeds: number;
  entries: SubmissionView[];
  recent: SubmissionView[];
  queue: {queued: number; running: number};
}

const kRefreshMs = 3000;
const kTeamKey = "llsf-hackathon-team";

let list: ExerciseList | null = null;
let current = "";
let refreshTimer: number | undefined;

function el<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  text?: string,
  cls?: string,
): HTMLElementTagNameMap[K] {
  const e = document.createElement(tag);
  if (text !== undefined) e.textContent = text;
  if (cls) e.className = cls;
  return e;
}

function byId<T extends HTMLElement>(id: string): T {
  const e = document.getElementById(id);
  if (!e) throw new Error(`#${id} is missing from the page`);
  return e as T;
}

async function getJson<T>(path: string): Promise<T> {
  const r = await fetch(path, {cache: "no-store"});
  const body = await r.json().catch(() => ({error: `HTTP ${r.status}`}));
  if (!r.ok) throw new Error((body as {error?: string}).error ?? `HTTP ${r.status}`);
  return body as T;
}

/// The value with its unit: a distance in m or points.
function formatValue(goal: string, v: number | null | undefined): string {
  if (v === null || v === undefined) return "–";
  return goal === "points" ? `${v.toFixed(1)} points` : `${v.toFixed(2)} m`;
}

function formatTime(iso: string): string {
  const d = new Date(iso);
  return Number.isNaN(d.getTime()) ? iso : d.toLocaleTimeString();
}

function renderTabs(): void {
  const tabs = byId<HTMLElement>("tabs");
  tabs.replaceChildren();
  for (const ex of list?.exercises ?? []) {
    const a = el("a", `${ex.name.slice(0, 2)} ${ex.title}`);
    a.href = `#${ex.name}`;
    a.dataset.exercise = ex.name;
    if (ex.name === current) a.className = "current";
    tabs.append(a);
  }
  const select = byId<HTMLSelectElement>("exercise");
  if (select.options.length === 0) {
    for (const ex of list?.exercises ?? []) {
      const o = el("option", `${ex.name} (${ex.title})`);
      o.value = ex.name;
      select.append(o);
    }
  }
  select.value = current;
}

function renderBoard(b: Board): void {
  byId("board-title").textContent = `${b.exercise}: ${b.title}`;
  byId("board-rule").textContent =
    `${b.seeds} hidden seeds; ranked by seeds passed, then ` +
    (b.better === "lower" ? "the mean distance (lower is better)" : "the mean points (higher is better)") +
    `, then the earlier submission. Queue: ${b.queue.queued} waiting, ${b.queue.running} playing.`;
  byId("value-head").textContent = b.goal === "points" ? "mean points" : "mean distance";
  const body = byId<HTMLTableElement>("board").tBodies[0];
  body.replaceChildren();
  if (b.entries.length === 0) {
    const tr = el("tr");
    const td = el("td", "no results yet: be the first to submit", "empty");
    td.colSpan = 6;
    tr.append(td);
    body.append(tr);
  }
  for (const e of b.entries) {
    const tr = el("tr");
    tr.className = `rank-${e.rank ?? 0}`;
    tr.dataset.team = e.team;
    tr.dataset.rank = String(e.rank ?? 0);
    tr.append(el("td", String(e.rank ?? ""), "rank"));
    tr.append(el("td", e.team));
    tr.append(el("td", `${e.passed ?? 0} / ${e.total ?? 0}`, e.verdict === "PASS" ? "pass" : "fail"));
    tr.append(el("td", formatValue(b.goal, e.value)));
    tr.append(el("td", formatTime(e.received)));
    tr.append(el("td", String(e.submissions ?? 1)));
    body.append(tr);
  }
  const recent = byId<HTMLTableElement>("recent").tBodies[0];
  recent.replaceChildren();
  for (const s of b.recent) {
    const tr = el("tr");
    tr.dataset.id = String(s.id);
    tr.dataset.status = s.status;
    tr.append(el("td", String(s.id)));
    tr.append(el("td", s.team));
    const status = el("td", s.status, `status-${s.status}`);
    if (s.status === "done" && s.verdict) status.textContent = `done: ${s.verdict}`;
    tr.append(status);
    tr.append(el("td", s.status === "done" ? `${s.passed} / ${s.total}` : "–"));
    tr.append(el("td", formatTime(s.received)));
    recent.append(tr);
    // Why it failed: the worker's error, or the first run a played submission did not pass.
    const why = s.status === "done" ? s.verdict !== "PASS" ? s.reason : undefined : s.error;
    if (why) {
      const er = el("tr");
      const td = el("td", why, "error");
      td.colSpan = 5;
      er.append(td);
      recent.append(er);
    }
  }
}

async function refresh(): Promise<void> {
  window.clearTimeout(refreshTimer);
  try {
    if (!list) {
      list = await getJson<ExerciseList>("api/hackathon/exercises");
    }
    const wanted = decodeURIComponent(location.hash.replace(/^#/, ""));
    const names = list.exercises.map((e) => e.name);
    current = names.includes(wanted) ? wanted : (names.find((n) => n.startsWith(wanted)) ?? names[0] ?? "");
    renderTabs();
    if (current) renderBoard(await getJson<Board>(`api/hackathon/board/${encodeURIComponent(current)}`));
    byId("meta").textContent = `updated ${new Date().toLocaleTimeString()} (every ${kRefreshMs / 1000} s)`;
  } catch (e) {
    byId("meta").textContent = `cannot reach the leaderboard: ${(e as Error).message}`;
  }
  refreshTimer = window.setTimeout(() => void refresh(), kRefreshMs);
}

function say(text: string, ok: boolean): void {
  const m = byId("submit-message");
  m.textContent = text;
  m.className = ok ? "ok" : "bad";
}

async function submit(ev: Event): Promise<void> {
  ev.preventDefault();
  const team = byId<HTMLInputElement>("team").value.trim();
  const exercise = byId<HTMLSelectElement>("exercise").value;
  const file = byId<HTMLInputElement>("file").files?.[0];
  if (!team) return say("give your team's name", false);
  if (!file) return say("choose your skill file (.lua)", false);
  const max = list?.max_skill_bytes ?? 256 * 1024;
  if (file.size > max) return say(`${file.name} is ${file.size} bytes; at most ${max} bytes`, false);
  let text: string;
  try {
    text = new TextDecoder("utf-8", {fatal: true}).decode(await file.arrayBuffer());
  } catch {
    return say(`${file.name} is not UTF-8 text: save it as UTF-8`, false);
  }
  localStorage.setItem(kTeamKey, team);
  const button = byId<HTMLButtonElement>("submit-button");
  button.disabled = true;
  try {
    const r = await fetch("api/hackathon/submit", {
      method: "POST",
      headers: {"Content-Type": "application/json"},
      body: JSON.stringify({team, exercise, file_name: file.name, skill: text}),
    });
    const body = (await r.json().catch(() => ({}))) as {id?: number; error?: string; exercise?: string};
    if (r.status !== 202) {
      say(`refused: ${body.error ?? `HTTP ${r.status}`}`, false);
    } else {
      say(`submission ${body.id} queued for ${body.exercise}: it shows below when played`, true);
      if (body.exercise && body.exercise !== current) location.hash = body.exercise;
      void refresh();
    }
  } catch (e) {
    say(`cannot reach the leaderboard: ${(e as Error).message}`, false);
  } finally {
    button.disabled = false;
  }
}

function main(): void {
  byId<HTMLInputElement>("team").value = localStorage.getItem(kTeamKey) ?? "";
  byId("cli-hint").textContent =
    `llsfsim exercise NN --skill FILE --submit ${location.origin}/ --team NAME`;
  byId<HTMLFormElement>("submit-form").addEventListener("submit", (ev) => void submit(ev));
  byId<HTMLSelectElement>("exercise").addEventListener("change", (ev) => {
    location.hash = (ev.target as HTMLSelectElement).value;
  });
  window.addEventListener("hashchange", () => void refresh());
  void refresh();
}

main();
