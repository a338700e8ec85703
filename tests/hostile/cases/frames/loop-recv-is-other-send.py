#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A socket config where the refbox's recv_port is where the hub listens for robot1 (one frame would circulate for ever) is refused at load with file:line; nothing is bound."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import subprocess
p = subprocess.run([os.environ["LLSF_COMM_HUB"], "--sockets",
                    os.path.join(os.environ["CASE_DIR"], "loop-recv-is-other-send.yaml"),
                    "--seconds", "1"], capture_output=True, text=True, timeout=5)
check(p.returncode == 2, f"exit {p.returncode}, expected 2: {p.stderr}")
print("refused: " + p.stderr.strip())
