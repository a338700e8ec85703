# SPDX-License-Identifier: MIT
"""Shared by the read-only store and recording cases: a store or folder that cannot be written,
and llsfsim run on it as a user without privileges (root may write read-only files, so the
command drops to nobody with setpriv when the suite runs as root). Relays llsfsim's output and
exit code."""
import os
import subprocess
import sys

LLSFSIM = os.environ["LLSFSIM"]
TMP = os.environ["CASE_TMP"]


def scenario():
    """A 600 s game of one robot: seconds of CPU, so that playing it first would show."""
    os.chmod(TMP, 0o777)
    path = os.path.join(TMP, "s.yaml")
    with open(path, "w", encoding="utf-8") as f:
        f.write("name: s\nduration_s: 600\nrobots: {count: 1}\n")
    return path


def make_store(path):
    """A store with the schema, written as the suite's user."""
    short = os.path.join(TMP, "short.yaml")
    with open(short, "w", encoding="utf-8") as f:
        f.write("name: short\nduration_s: 1\nrobots: {count: 1}\n")
    subprocess.run([LLSFSIM, "run", short, "--db", path, "--no-record", "-q"], check=True,
                   timeout=60, stdout=subprocess.DEVNULL)
    scenario()


def run_unprivileged(args):
    cmd = [LLSFSIM] + args
    if os.geteuid() == 0:
        cmd = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", "--"] + cmd
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=30)
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    return r.returncode
