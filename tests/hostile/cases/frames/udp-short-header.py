#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""3-byte datagrams to a peer's port are counted as short_header and dropped; the hub goes on forwarding."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub()
robot, refbox = udp_socket(), udp_socket()
for _ in range(200):
    robot.sendto(b"\x01\x02\x03", (LOOPBACK, hub.ports["robot1"]))
refbox.sendto(lock_frame(1), (LOOPBACK, hub.ports["refbox"]))  # the refbox is learnt
time.sleep(0.1)
robot.sendto(lock_frame(2), (LOOPBACK, hub.ports["robot1"]))
got = udp_receive_all(refbox, 0.5)
check(hub.alive(), "the hub died")
counters, _, _ = hub.finish()
short = counters["peers"][0]["malformed"]["short_header"]
check(len(got) == 1 and got[0] == lock_frame(2), f"the valid frame did not come through: {got}")
print(f"short_header {short}, valid frame forwarded")
