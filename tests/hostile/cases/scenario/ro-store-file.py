# SPDX-License-Identifier: MIT
# run --db on a read-only store file: refused before the game (no recording is written).
import os
import sys

import readonly_lib as lib

db = os.path.join(lib.TMP, "ro.db")
lib.make_store(db)
os.chmod(db, 0o444)
rec = os.path.join(lib.TMP, "r.jsonl.gz")
code = lib.run_unprivileged(["run", os.path.join(lib.TMP, "s.yaml"), "--db", db, "--record", rec])
if os.path.exists(rec):
    sys.stderr.write("the game was played: the recording exists\n")
    code = 99
sys.exit(code)
