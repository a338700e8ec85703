# SPDX-License-Identifier: MIT
# run --db on a writable store in a folder that is not (SQLite's journal goes there): refused
# before the game.
import os
import sys

import readonly_lib as lib

folder = os.path.join(lib.TMP, "ro")
os.mkdir(folder)
db = os.path.join(folder, "x.db")
lib.make_store(db)
os.chmod(db, 0o666)
os.chmod(folder, 0o555)
rec = os.path.join(lib.TMP, "r.jsonl.gz")
code = lib.run_unprivileged(["run", os.path.join(lib.TMP, "s.yaml"), "--db", db, "--record", rec])
if os.path.exists(rec):
    sys.stderr.write("the game was played: the recording exists\n")
    code = 99
os.chmod(folder, 0o755)
sys.exit(code)
