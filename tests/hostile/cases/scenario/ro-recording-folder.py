# SPDX-License-Identifier: MIT
# run --record into a folder that cannot be written: refused before the game.
import os
import sys

import readonly_lib as lib

folder = os.path.join(lib.TMP, "ro")
os.mkdir(folder)
os.chmod(folder, 0o555)
s = lib.scenario()
code = lib.run_unprivileged(["run", s, "--no-db", "--record", os.path.join(folder, "r.jsonl.gz")])
os.chmod(folder, 0o755)
sys.exit(code)
