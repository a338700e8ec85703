#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Frames of unknown component ids and message types are refused as unknown_type when forward_unregistered is false, and nothing reaches the other peer."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub(hub_yaml="forward_unregistered: false\n")
robot, refbox = udp_socket(), udp_socket()
refbox.sendto(lock_frame(1), (LOOPBACK, hub.ports["refbox"]))
time.sleep(0.1)
for comp, t in ((0, 0), (65535, 65535), (2100, 99), (2000, 1), (1, 2100)):
    robot.sendto(header(comp, t, 4) + b"\x08\x01\x10\x02", (LOOPBACK, hub.ports["robot1"]))
got = udp_receive_all(refbox, 0.4)
counters, _, _ = hub.finish()
print(f"unknown_type {counters['peers'][0]['malformed']['unknown_type']}, forwarded {len(got)}")
