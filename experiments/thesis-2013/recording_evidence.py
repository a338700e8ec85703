#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Where the time goes, from recordings: the mechanisms the thesis names for its findings.

    experiments/thesis-2013/recording_evidence.py RECORDING_OR_DIR...

Reads llsfsim recordings (docs/recording.md; a directory is searched for *.jsonl.gz) and prints
one markdown table row per variant, with means per game of:

  lock wait M / INS / DEL   seconds robots waited for a lock (from the first request until it
                            was granted or given up, across refusals and repeated requests) on
                            machines and recyclers, the insertion area, the delivery zone
  refusals                  lock requests refused
  close s                   seconds in which two robots were closer than CLOSE_M (centre to centre)
  stalled close s           robot-seconds a robot stood still (under STILL_MPS) with another robot
                            closer than CLOSE_M while it was driving somewhere (a navigator path
                            was active): robots held up by each other, the thesis' Fig. 6.4d
  r-r contacts              robot-robot collisions
  nav fail                  skill failures from the navigator (STUCK, BLOCKED, ...)
  blocked by robot          of them, BLOCKED by another robot
  jams / jammed at end      device jams (robot profiles) and robots still jammed at the end
  no S0 seen                get_s0 failures with an empty insertion area
  encounters                episodes in which two robots stayed closer than CLOSE_M while at
                            least one of them was driving somewhere (each pair on its own), per
                            game; "median enc s" and "longest enc s" are the
                            median and the longest of them over all the variant's games
  recovery s / aborted s    robot-seconds move_base ran a recovery behaviour / stood aborted
                            waiting for the navigation graph to send its goal again (only at
                            the move_base-2013 level, docs/recording.md)
  stuck for good            robots that had a navigation goal at the end of the game and moved
                            less than STUCK_M in its last STUCK_S seconds; a second table lists
                            each with its seed, position and since when it stood there
  recycling fail            failures of the recycling steps: get_consumed, recycle and
                            finish_puck_at at R1/R2; a third table lists them by cause (the
                            skill's error with numbers and device names generalised), per game

Standard library only; no llsfsim code. The numbers are what the recordings hold, nothing is
modelled here.
"""
import collections
import gzip
import json
import math
import os
import re
import sys

CLOSE_M = 0.6
STILL_MPS = 0.02
STUCK_M = 0.3
STUCK_S = 120.0


def recordings(paths):
    for p in paths:
        if os.path.isdir(p):
            for root, _dirs, files in os.walk(p):
                for f in sorted(files):
                    if f.endswith(".jsonl.gz") or f.endswith(".jsonl"):
                        yield os.path.join(root, f)
        else:
            yield p


RECYCLING = re.compile(r'^(get_consumed|recycle)\{|^finish_puck_at\{place="R[12]"')


def cause(error):
    """A skill error with its numbers and device names generalised: the cause."""
    error = re.sub(r"\b(M10|M[1-9]|R[12]|D[123]|TST)\b", "<device>", error)
    error = re.sub(r"-?\d+(\.\d+)?", "N", error)
    return error.strip()


def open_text(path):
    return gzip.open(path, "rt") if path.endswith(".gz") else open(path, "rt")


def analyse(path):
    m = collections.Counter()
    requested = {}
    navigating = set()
    jammed = set()
    prev = None
    prev_t = None
    encounter_start = {}  # (i, j) -> time the pair came closer than CLOSE_M
    encounters = []
    nav_state = {}  # robot -> (move_base state, since)
    trail = collections.defaultdict(list)  # robot index -> [(t, x, y)]
    recycling = collections.Counter()  # cause -> failures
    with open_text(path) as f:
        header = json.loads(f.readline())
        if header.get("format") != "llsfsim-recording":
            raise ValueError(f"{path}:1: not an llsfsim recording")
        robots = header.get("robots", [])
        for n, line in enumerate(f, start=2):
            try:
                o = json.loads(line)
            except json.JSONDecodeError as err:
                raise ValueError(f"{path}:{n}: {err}") from err
            t = o.get("t", 0.0)
            if o.get("f") == 1:
                poses = [(r[0], r[1]) for r in o["r"]]
                if prev is not None and t > prev_t:
                    dt = t - prev_t
                    close = [False] * len(poses)
                    for i in range(len(poses)):
                        for j in range(i + 1, len(poses)):
                            if math.dist(poses[i], poses[j]) < CLOSE_M:
                                close[i] = close[j] = True
                    if any(close):
                        m["close_s"] += dt
                    for i in range(len(poses)):
                        for j in range(i + 1, len(poses)):
                            busy = [k < len(robots) and (robots[k] in navigating or
                                                         nav_state.get(robots[k], ("idle",))[0]
                                                         != "idle") for k in (i, j)]
                            near = math.dist(poses[i], poses[j]) < CLOSE_M and any(busy)
                            if near and (i, j) not in encounter_start:
                                encounter_start[(i, j)] = t
                            elif not near and (i, j) in encounter_start:
                                encounters.append(t - encounter_start.pop((i, j)))
                    for i, p in enumerate(poses):
                        speed = math.dist(p, prev[i]) / dt
                        if close[i] and speed < STILL_MPS and i < len(robots) and \
                                robots[i] in navigating:
                            m["stalled_close_s"] += dt
                for i, p in enumerate(poses):
                    trail[i].append((t, p[0], p[1]))
                prev, prev_t = poses, t
                continue
            e = o.get("e")
            if e == "lock":
                # A wait: from the first request until the lock is granted or the robot
                # gives up (back to NONE), across refusals and repeated requests.
                key = (o["robot"], o["resource"])
                if o["to"] == "REQUESTED":
                    requested.setdefault(key, t)
                elif o["to"] == "REFUSED":
                    m["refusals"] += 1
                elif o["to"] in ("ACCEPTED", "NONE") and key in requested:
                    res = o["resource"]
                    cls = "INS" if res == "INS" else "DEL" if res == "DELIVERY" else "M"
                    m["wait_" + cls] += t - requested.pop(key)
            elif e == "path":
                if o.get("points"):
                    navigating.add(o["robot"])
                else:
                    navigating.discard(o["robot"])
            elif e == "move_base":
                r = o["robot"]
                if r in nav_state:
                    state, since = nav_state[r]
                    if state == "clearing":
                        m["recovery_s"] += t - since
                    elif state == "aborted":
                        m["aborted_s"] += t - since
                nav_state[r] = (o["state"], t)
            elif e == "collision" and o.get("kind") == "robot-robot":
                m["rr_contacts"] += 1
            elif e == "jam":
                if o.get("jammed"):
                    m["jams"] += 1
                    jammed.add(o["robot"])
                else:
                    jammed.discard(o["robot"])
            elif e == "skill" and o.get("status") == "FAILED":
                err = o.get("error", "")
                if "navigator " in err:
                    m["nav_fail"] += 1
                    if "BLOCKED: by robot" in err:
                        m["blocked_by_robot"] += 1
                if "no puck seen" in err:
                    m["no_s0_seen"] += 1
                if RECYCLING.match(o.get("string", "")):
                    m["recycling_fail"] += 1
                    recycling[cause(err)] += 1
    m["jammed_at_end"] = len(jammed)
    end = prev_t if prev_t is not None else 0.0
    for (i, j), start in encounter_start.items():
        encounters.append(end - start)
    m["encounters"] = len(encounters)
    for r, (state, since) in nav_state.items():
        if state == "clearing":
            m["recovery_s"] += end - since
        elif state == "aborted":
            m["aborted_s"] += end - since
    stuck = []
    for i, tr in trail.items():
        name = robots[i] if i < len(robots) else str(i)
        if not tr or tr[0][0] > end - STUCK_S:
            continue
        busy = name in navigating or nav_state.get(name, ("idle", 0))[0] != "idle"
        last = (tr[-1][1], tr[-1][2])
        # Since when it stood within STUCK_M of where it ended.
        since = tr[0][0]
        for t_k, x, y in reversed(tr):
            if math.dist((x, y), last) >= STUCK_M:
                break
            since = t_k
        if busy and since <= end - STUCK_S:
            stuck.append((name, last[0], last[1], since))
    m["stuck_for_good"] = len(stuck)
    return header.get("variant", ""), header.get("seed", ""), m, encounters, stuck, recycling


COLUMNS = [
    ("lock wait M", "wait_M"), ("lock wait INS", "wait_INS"), ("lock wait DEL", "wait_DEL"),
    ("refusals", "refusals"), ("close s", "close_s"), ("stalled close s", "stalled_close_s"),
    ("r-r contacts", "rr_contacts"), ("nav fail", "nav_fail"),
    ("blocked by robot", "blocked_by_robot"), ("jams", "jams"),
    ("jammed at end", "jammed_at_end"), ("no S0 seen", "no_s0_seen"),
    ("encounters", "encounters"), ("recovery s", "recovery_s"), ("aborted s", "aborted_s"),
    ("stuck for good", "stuck_for_good"), ("recycling fail", "recycling_fail"),
]


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) >= 2 else 2
    by_variant = collections.defaultdict(list)
    encounters = collections.defaultdict(list)
    stuck_rows = []
    causes = collections.defaultdict(collections.Counter)
    for path in recordings(argv[1:]):
        try:
            variant, seed, m, enc, stuck, recycling = analyse(path)
        except (OSError, ValueError, KeyError, EOFError) as err:
            print(f"recording_evidence: {path}: {err}", file=sys.stderr)
            return 2
        by_variant[variant].append(m)
        encounters[variant].extend(enc)
        stuck_rows.extend((variant, seed, *row) for row in stuck)
        causes[variant].update(recycling)
    if not by_variant:
        print("recording_evidence: no recordings found", file=sys.stderr)
        return 2
    print("| variant | games | " + " | ".join(c for c, _ in COLUMNS) +
          " | median enc s | longest enc s |")
    print("|---|---:|" + "---:|" * (len(COLUMNS) + 2))
    for variant in sorted(by_variant):
        games = by_variant[variant]
        cells = [f"{sum(g[k] for g in games) / len(games):.1f}" for _, k in COLUMNS]
        enc = sorted(encounters[variant])
        median = enc[len(enc) // 2] if enc else 0.0
        longest = enc[-1] if enc else 0.0
        print(f"| {variant} | {len(games)} | " + " | ".join(cells) +
              f" | {median:.1f} | {longest:.1f} |")
    if stuck_rows:
        print()
        print("| variant | seed | robot stuck for good | x | y | standing there since s |")
        print("|---|---:|---|---:|---:|---:|")
        for variant, seed, name, x, y, since in sorted(stuck_rows, key=str):
            print(f"| {variant} | {seed} | {name} | {x:.2f} | {y:.2f} | {since:.1f} |")
    if any(causes.values()):
        print()
        print("| variant | recycling failure cause | failures | per game |")
        print("|---|---|---:|---:|")
        for variant in sorted(causes):
            games = len(by_variant[variant])
            for c, k in sorted(causes[variant].items(), key=lambda kv: (-kv[1], kv[0])):
                print(f"| {variant} | {c} | {k} | {k / games:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
