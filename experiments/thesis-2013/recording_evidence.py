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

Standard library only; no llsfsim code. The numbers are what the recordings hold, nothing is
modelled here.
"""
import collections
import gzip
import json
import math
import os
import sys

CLOSE_M = 0.6
STILL_MPS = 0.02


def recordings(paths):
    for p in paths:
        if os.path.isdir(p):
            for root, _dirs, files in os.walk(p):
                for f in sorted(files):
                    if f.endswith(".jsonl.gz") or f.endswith(".jsonl"):
                        yield os.path.join(root, f)
        else:
            yield p


def open_text(path):
    return gzip.open(path, "rt") if path.endswith(".gz") else open(path, "rt")


def analyse(path):
    m = collections.Counter()
    requested = {}
    navigating = set()
    jammed = set()
    prev = None
    prev_t = None
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
                    for i, p in enumerate(poses):
                        speed = math.dist(p, prev[i]) / dt
                        if close[i] and speed < STILL_MPS and i < len(robots) and \
                                robots[i] in navigating:
                            m["stalled_close_s"] += dt
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
    m["jammed_at_end"] = len(jammed)
    return header.get("variant", ""), m


COLUMNS = [
    ("lock wait M", "wait_M"), ("lock wait INS", "wait_INS"), ("lock wait DEL", "wait_DEL"),
    ("refusals", "refusals"), ("close s", "close_s"), ("stalled close s", "stalled_close_s"),
    ("r-r contacts", "rr_contacts"), ("nav fail", "nav_fail"),
    ("blocked by robot", "blocked_by_robot"), ("jams", "jams"),
    ("jammed at end", "jammed_at_end"), ("no S0 seen", "no_s0_seen"),
]


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) >= 2 else 2
    by_variant = collections.defaultdict(list)
    for path in recordings(argv[1:]):
        try:
            variant, m = analyse(path)
        except (OSError, ValueError, KeyError, EOFError) as err:
            print(f"recording_evidence: {path}: {err}", file=sys.stderr)
            return 2
        by_variant[variant].append(m)
    if not by_variant:
        print("recording_evidence: no recordings found", file=sys.stderr)
        return 2
    print("| variant | games | " + " | ".join(c for c, _ in COLUMNS) + " |")
    print("|---|---:|" + "---:|" * len(COLUMNS))
    for variant in sorted(by_variant):
        games = by_variant[variant]
        cells = [f"{sum(g[k] for g in games) / len(games):.1f}" for _, k in COLUMNS]
        print(f"| {variant} | {len(games)} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
