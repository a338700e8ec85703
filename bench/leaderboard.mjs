// SPDX-License-Identifier: MIT
// bench/leaderboard.mjs LLSFSIM: the hackathon leaderboard under load (bench/run leaderboard;
// docs/benchmarks.md "leaderboard"). Starts `llsfsim hackathon serve` (a fresh store, --workers 2,
// 5 hidden seeds), sends 40 submissions of a reference skill (default: exercise 04 with
// tests/app/exercises/rescue.lua; LEADERBOARD_EXERCISE and LEADERBOARD_SKILL override) from 8 teams
// and times until the last is played, while a client fetches the page and the board every 100 ms
// and records each answer's latency. One JSON line per figure on stdout.
import {spawn} from "node:child_process";
import {mkdtempSync, readFileSync, rmSync} from "node:fs";
import {tmpdir} from "node:os";
import {dirname, join, resolve} from "node:path";
import {fileURLToPath} from "node:url";

const source = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const llsfsim = resolve(process.argv[2] ?? join(source, "build", "release", "llsfsim"));
const exercise = process.env.LEADERBOARD_EXERCISE ?? "04-rescue-5-minutes";
const skillFile = process.env.LEADERBOARD_SKILL ?? join(source, "tests", "app", "exercises", "rescue.lua");
const kSubmissions = 40;
const kTeams = 8;
const kWorkers = 2;
const kSeeds = "1001-1005";

const tmp = mkdtempSync(join(tmpdir(), "llsf-bench-leaderboard-"));
const server = spawn(llsfsim, ["hackathon", "serve", "--port", "0", "--db", join(tmp, "b.db"),
  "--workers", String(kWorkers), "--seeds", kSeeds, "--max-per-minute", "1000",
  "--exercises", join(source, "exercises")], {
  cwd: tmp,
  env: {...process.env, LLSF_VIEWER_DIR: join(source, "viewer", "dist")},
  stdio: ["ignore", "pipe", "pipe"],
});
let serverErr = "";
server.stderr.on("data", (d) => (serverErr += d));
const url = await new Promise((res, rej) => {
  let out = "";
  server.stdout.on("data", (d) => {
    out += d;
    const m = /llsfsim hackathon: (http:\/\/\S+)/.exec(out);
    if (m) res(m[1]);
  });
  server.on("exit", (c) => rej(new Error(`the server exited (${c}): ${serverErr}`)));
});

function line(metric, value, unit) {
  console.log(JSON.stringify({bench: "leaderboard", metric, value, unit}));
}

try {
  const skill = readFileSync(skillFile, "utf8");
  // The page client: the page and the board, one after the other, every 100 ms.
  const latencies = [];
  let clientRunning = true;
  const client = (async () => {
    while (clientRunning) {
      for (const path of ["", `api/hackathon/board/${exercise}`]) {
        const t = performance.now();
        const r = await fetch(url + path);
        await r.text();
        if (!r.ok) throw new Error(`GET /${path}: HTTP ${r.status}`);
        latencies.push(performance.now() - t);
      }
      await new Promise((r) => setTimeout(r, 100));
    }
  })();

  const t0 = performance.now();
  const ids = [];
  for (let i = 0; i < kSubmissions; ++i) {
    const r = await fetch(`${url}api/hackathon/submit`, {
      method: "POST",
      headers: {"Content-Type": "application/json"},
      body: JSON.stringify({team: `team-${i % kTeams}`, exercise, file_name: "rescue.lua", skill}),
    });
    const body = await r.json();
    if (r.status !== 202) throw new Error(`submission ${i}: HTTP ${r.status}: ${body.error}`);
    ids.push(body.id);
  }
  // Until every submission is played.
  let statuses = [];
  for (;;) {
    const list = await (await fetch(`${url}api/hackathon/submissions?limit=1000`)).json();
    statuses = list.map((s) => s.status);
    if (statuses.length === kSubmissions && statuses.every((s) => s !== "queued" && s !== "running")) break;
    await new Promise((r) => setTimeout(r, 200));
  }
  const wall = (performance.now() - t0) / 1000;
  clientRunning = false;
  await client;
  const done = statuses.filter((s) => s === "done").length;
  const board = await (await fetch(`${url}api/hackathon/board/${exercise}`)).json();
  const passed = board.entries.every((e) => e.passed === 5);
  latencies.sort((a, b) => a - b);
  const median = latencies[Math.floor(latencies.length / 2)];
  line("wall_s", Number(wall.toFixed(1)), "s");
  line("submissions_done", done, "submissions");
  line("games_per_s", Number(((done * 5) / wall).toFixed(2)), "games/s");
  line("all_seeds_passed", passed ? 1 : 0, "bool");
  line("page_requests", latencies.length, "requests");
  line("page_median_ms", Number(median.toFixed(2)), "ms");
  line("page_max_ms", Number(latencies[latencies.length - 1].toFixed(2)), "ms");
} finally {
  server.kill("SIGTERM");
  await new Promise((r) => server.on("exit", r));
  rmSync(tmp, {recursive: true, force: true});
}
