#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A symbolic link to a folder outside the viewer folder (/etc) is refused for every file below it."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

srv = Serve()
os.symlink("/etc", os.path.join(srv.viewer, "etc"))
a, body_a = http_get(srv.port, "/etc/passwd")
b, _ = http_get(srv.port, "/etc/hostname")
check("root:" not in body_a, "served /etc/passwd")
srv.stop()
print(f"{a} {b}")
