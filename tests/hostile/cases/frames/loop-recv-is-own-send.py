#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A peer whose recv_port is its own send_port (the hub would send every frame to itself) is refused at load with file:line."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import subprocess
p = subprocess.run([os.environ["LLSF_COMM_HUB"], "--sockets",
                    os.path.join(os.environ["CASE_DIR"], "loop-recv-is-own-send.yaml"),
                    "--seconds", "1"], capture_output=True, text=True, timeout=5)
check(p.returncode == 2, f"exit {p.returncode}, expected 2: {p.stderr}")
print("refused: " + p.stderr.strip())
