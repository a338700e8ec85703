#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""20,000 random and mutated datagrams from several ports: the hub survives, stays small, and a valid frame still flows afterwards."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import random
import time
rng = random.Random(21)
hub = Hub()
robot, refbox = udp_socket(), udp_socket()
refbox.sendto(lock_frame(0), (LOOPBACK, hub.ports["refbox"]))
robot.sendto(lock_frame(0), (LOOPBACK, hub.ports["robot1"]))
time.sleep(0.1)
udp_receive_all(robot, 0.1)
udp_receive_all(refbox, 0.1)
senders = [udp_socket() for _ in range(4)]
base = lock_frame(7)
for i in range(20000):
    if i % 2:
        d = bytes(rng.getrandbits(8) for _ in range(rng.randrange(0, 64)))
    else:
        d = bytearray(base)
        for _ in range(rng.randrange(1, 4)):
            d[rng.randrange(len(d))] = rng.getrandbits(8)
        d = bytes(d[: rng.randrange(len(d) + 1)])
    port = hub.ports["robot1"]  # a valid mutant moves robot1's learnt address, as it may
    try:
        senders[i % 4].sendto(d, (LOOPBACK, port))
    except OSError:
        pass
    if i % 1000 == 0:
        time.sleep(0.005)
time.sleep(0.3)
udp_receive_all(robot, 0.1)
udp_receive_all(refbox, 0.2)
robot.sendto(lock_frame(9), (LOOPBACK, hub.ports["robot1"]))
got = udp_receive_all(refbox, 0.5)
check(hub.alive(), "the hub died")
rss = hub.status("VmHWM")
hub.finish()
check(lock_frame(9) in got, "a valid frame no longer reaches the refbox")
check(rss < 100_000, f"peak RSS {rss} kB")
print(f"survived 20000 datagrams, peak RSS {rss} kB")
