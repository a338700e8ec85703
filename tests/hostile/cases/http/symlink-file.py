#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A symbolic link in the viewer folder to a file outside it (/etc/passwd) is refused with 403; a link inside the folder is served."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

srv = Serve()
os.symlink("/etc/passwd", os.path.join(srv.viewer, "passwd.txt"))
os.symlink(os.path.join(srv.viewer, "viewer.js"), os.path.join(srv.viewer, "alias.js"))
status, body = http_get(srv.port, "/passwd.txt")
check("root:" not in body, "served /etc/passwd")
inside, _ = http_get(srv.port, "/alias.js")
srv.stop()
print(f"escape {status}, inside {inside}")
