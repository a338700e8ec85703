#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The hostile-input suite (docs/security.md, "The hostile-input suite").

Runs every case file tests/hostile/cases/<area>/<name>.case under a memory cap (prlimit --as)
and a time limit, and checks its exit code and messages. A case file is `key: value` lines
(`#` starts a comment line; a value may continue on following lines indented by two spaces):

  args:      llsfsim's arguments (shell words), e.g.  check {here}/bad-dup-keys.yaml
  script:    instead of args: a Python script (path relative to the case file) run with
             python3; it gets LLSFSIM, LLSF_COMM_HUB, CASE_DIR and CASE_TMP in its environment
  setup:     a shell command run in {tmp} before (e.g. mkfifo pipe.yaml); optional
  stdin:     a file (relative to the case file) fed to standard input; default: nothing
  exit:      the expected exit code (1 or 2 for refused input; 0 only for inputs that must work)
  stderr:    a Python regular expression that must match somewhere in standard error; optional
  stdout:    the same for standard output; optional
  timeout_s: the time limit (default 10)
  mem_mb:    the address-space cap (default 512)

{here} is the case file's folder, {tmp} a fresh empty folder per case (the working directory),
{src} the source tree. Usage: run_suite.py LLSFSIM LLSF_COMM_HUB CASES_DIR [-k SUBSTRING] [-v]
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

KEYS = {"args", "script", "setup", "stdin", "exit", "stderr", "stdout", "timeout_s", "mem_mb"}


def parse_case(path):
    case, key = {}, None
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            if line.startswith("  ") and key is not None:
                case[key] += "\n" + line[2:]
                continue
            if ":" not in line:
                raise ValueError(f"{path}:{n}: expected 'key: value', got {line!r}")
            key, value = line.split(":", 1)
            key = key.strip()
            if key not in KEYS:
                raise ValueError(f"{path}:{n}: unknown key {key!r} (known: {', '.join(sorted(KEYS))})")
            if key in case:
                raise ValueError(f"{path}:{n}: key {key!r} given twice")
            case[key] = value.strip()
    if ("args" in case) == ("script" in case):
        raise ValueError(f"{path}: give exactly one of 'args' and 'script'")
    if "exit" not in case:
        raise ValueError(f"{path}: 'exit' is missing")
    return case


def run_case(path, llsfsim, hub, src, verbose):
    case = parse_case(path)
    here = os.path.dirname(os.path.abspath(path))
    tmp = tempfile.mkdtemp(prefix="llsf-hostile-")
    try:
        def subst(s):
            return s.replace("{here}", here).replace("{tmp}", tmp).replace("{src}", src)

        env = dict(os.environ, LLSFSIM=llsfsim, LLSF_COMM_HUB=hub, CASE_DIR=here, CASE_TMP=tmp,
                   LLSF_SOURCE_DIR=src)
        if "setup" in case:
            subprocess.run(subst(case["setup"]), shell=True, cwd=tmp, check=True, env=env,
                           timeout=60)
        mem = int(case.get("mem_mb", "512")) * 1024 * 1024
        timeout = float(case.get("timeout_s", "10"))
        if "args" in case:
            cmd = [llsfsim] + [subst(a) for a in shlex.split(case["args"])]
        else:
            cmd = [sys.executable, os.path.join(here, case["script"])]
        cmd = ["prlimit", f"--as={mem}", "--core=0", "--"] + cmd
        stdin = open(os.path.join(here, case["stdin"]), "rb") if "stdin" in case else subprocess.DEVNULL
        t0 = time.monotonic()
        try:
            p = subprocess.run(cmd, cwd=tmp, env=env, stdin=stdin, capture_output=True,
                               timeout=timeout)
        except subprocess.TimeoutExpired as e:
            return False, f"no end within {timeout:g} s", (e.stdout or b""), (e.stderr or b"")
        finally:
            if stdin is not subprocess.DEVNULL:
                stdin.close()
        took = time.monotonic() - t0
        out = p.stdout.decode("utf-8", "replace")
        err = p.stderr.decode("utf-8", "replace")
        problems = []
        if p.returncode != int(case["exit"]):
            problems.append(f"exit {p.returncode}, expected {case['exit']}")
        for stream, text in (("stderr", err), ("stdout", out)):
            if stream in case and not re.search(subst(case[stream]), text, re.S):
                problems.append(f"{stream} does not match /{case[stream]}/")
        return (not problems), "; ".join(problems) or f"{took:.2f} s", p.stdout, p.stderr
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def main(argv):
    if len(argv) < 4:
        print(__doc__, file=sys.stderr)
        return 2
    llsfsim, hub, cases_dir = (os.path.abspath(a) for a in argv[1:4])
    rest = argv[4:]
    verbose = "-v" in rest
    pattern = rest[rest.index("-k") + 1] if "-k" in rest else ""
    src = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
    files = sorted(os.path.join(d, f) for d, _, fs in os.walk(cases_dir) for f in fs
                   if f.endswith(".case"))
    files = [f for f in files if pattern in os.path.relpath(f, cases_dir)]
    if not files:
        print(f"run_suite: no .case files under {cases_dir}", file=sys.stderr)
        return 2
    failed = 0
    for f in files:
        name = os.path.relpath(f, cases_dir)
        try:
            ok, what, out, err = run_case(f, llsfsim, hub, src, verbose)
        except (ValueError, OSError, subprocess.SubprocessError) as e:
            ok, what, out, err = False, f"bad case: {e}", b"", b""
        print(f"{'ok  ' if ok else 'FAIL'} {name}: {what}")
        if not ok or verbose:
            for label, text in (("stdout", out), ("stderr", err)):
                text = text.decode("utf-8", "replace")
                if text.strip():
                    print(f"  --- {label} (last 2,000 characters)\n  " +
                          text[-2000:].replace("\n", "\n  "))
        failed += not ok
    print(f"hostile-input suite: {len(files) - failed} of {len(files)} cases pass")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
