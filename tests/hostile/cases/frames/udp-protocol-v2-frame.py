#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Frames of the later refbox protocol (version byte 2, cipher byte, then the size; component and type inside the payload) and bad cipher/version bytes read as 2013 headers of unknown types: refused as unknown_type (forward_unregistered: false), never relayed."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import struct
import time
hub = Hub(hub_yaml="forward_unregistered: false\n")
robot, refbox = udp_socket(), udp_socket()
refbox.sendto(lock_frame(1), (LOOPBACK, hub.ports["refbox"]))
time.sleep(0.1)
body = lock_frame(1)[8:]
for version, cipher in ((2, 0), (2, 1), (255, 255), (1, 7)):
    inner = struct.pack(">HH", 2100, 1) + body
    frame = struct.pack(">BBBBI", version, cipher, 0, 0, len(inner)) + inner
    robot.sendto(frame, (LOOPBACK, hub.ports["robot1"]))
got = udp_receive_all(refbox, 0.4)
counters, _, _ = hub.finish()
print(f"unknown_type {counters['peers'][0]['malformed']['unknown_type']}, forwarded {len(got)}")
