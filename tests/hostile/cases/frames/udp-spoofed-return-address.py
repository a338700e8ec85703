#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Malformed datagrams from another local port must not move a peer's learnt return address (traffic hijack): the robot keeps getting the refbox's frames, the attacker none."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub()
robot, refbox, attacker = udp_socket(), udp_socket(), udp_socket()
robot.sendto(lock_frame(1), (LOOPBACK, hub.ports["robot1"]))
refbox.sendto(lock_frame(2), (LOOPBACK, hub.ports["refbox"]))
time.sleep(0.2)
udp_receive_all(robot, 0.1)
for bad in (b"\x00\x01\x02", header(2100, 1, 500), header(2100, 1, 3) + b"abc", lock_frame(3)[:-2]):
    attacker.sendto(bad, (LOOPBACK, hub.ports["robot1"]))
time.sleep(0.1)
for n in range(3):
    refbox.sendto(lock_frame(10 + n), (LOOPBACK, hub.ports["refbox"]))
at_robot = udp_receive_all(robot, 0.4)
at_attacker = udp_receive_all(attacker, 0.1)
hub.finish()
print(f"robot got {len(at_robot)}, attacker got {len(at_attacker)}")
