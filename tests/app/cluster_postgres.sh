# SPDX-License-Identifier: MIT
# shellcheck shell=bash
# Sourced by cluster_test.sh with the Slurm cluster up, in $T, after the local 40-game batch
# ($T/local.db, `$S --runs 20`): `batch --slurm` into a real PostgreSQL 15 server
# (scripts/test-postgres in $T/pg, stopped by cluster_test.sh's cleanup):
#  (f) the same 40-game batch through Slurm into PostgreSQL: the same result hash per (variant,
#      seed) as the local SQLite batch, every run whole, the same `report` table, absolute
#      recording paths; `batch status` on the URL; a resubmission submits nothing;
#  (g) an array task cancelled mid-slice (scancel) and the server restarted while another task
#      is writing: after the resubmission every run present exactly once and whole;
#  (h) two batches submitted at once into a new (empty) database, one more played locally into it
#      meanwhile: all three complete, every run once;
#  (i) an unreachable server: exit 2 before anything is submitted.
# Uses L, SRC, T, S, fail, has, wait_batch from cluster_test.sh.

# The server; $T must let the postgres user through to $T/pg.
chmod 711 "$T"
eval "$("$SRC/scripts/test-postgres" start "$T/pg")"
PG=${LLSF_PG_URL%/*}  # postgresql://llsf@127.0.0.1:PORT
pq() { psql "$1" -X -q -At -F'|' -v ON_ERROR_STOP=1 -c "$2"; }
newdb() { pq "$PG/postgres" "CREATE DATABASE $1" && echo "$PG/$1"; }
# Every run of the first batch with its hash and how many rows each child table holds for it:
# equal between two stores = the same runs, each whole. Sorted bytewise (collations differ).
RUN_ROWS="SELECT r.variant, r.seed, r.result_hash,
  (SELECT count(*) FROM statistics x WHERE x.run_id = r.id),
  (SELECT count(*) FROM orders x WHERE x.run_id = r.id),
  (SELECT count(*) FROM tests x WHERE x.run_id = r.id),
  (SELECT count(*) FROM awards x WHERE x.run_id = r.id),
  (SELECT count(*) FROM events x WHERE x.run_id = r.id)
  FROM runs r WHERE r.batch_id = (SELECT min(id) FROM batches)"
local_rows=$(sqlite3 "$T/local.db" "$RUN_ROWS" | LC_ALL=C sort)
[ "$(wc -l <<<"$local_rows")" -eq 40 ] || fail "local.db: not 40 runs"
[ -z "$(awk -F'|' '$4 == 0 || $6 == 0' <<<"$local_rows")" ] || fail "local.db: a run without statistics or tests"
pg_rows() { pq "$1" "$RUN_ROWS" | LC_ALL=C sort; }
once() {  # url, runs expected: every (variant, seed) of each batch exactly once
  [ "$(pq "$1" "SELECT count(*), count(DISTINCT (batch_id, variant, seed)) FROM runs")" = "$2|$2" ] ||
    fail "$1: not $2 runs exactly once: $(pq "$1" "SELECT count(*), count(DISTINCT (batch_id, variant, seed)) FROM runs")"
}

# (f) 40 games through Slurm into PostgreSQL.
U=$(newdb forty)
out=$("$L" batch "$S" --runs 20 --db "$U" --slurm --games-per-task 6)
has "$out" "40 of 40 runs missing, 6 games per task"
has "$out" "(array 0-6)"
has "$out" "follow     llsfsim batch status tiny.yaml --runs 20 --db $U --wait"
[[ "$out" != *"batch merge"* ]] || fail "a merge suggested for a database server: $out"
wait_batch "$U" --runs 20
out=$("$L" batch status "$S" --runs 20 --db "$U")
has "$out" "40 of 40 runs stored in $U;"
once "$U" 40
[ "$(pg_rows "$U")" = "$local_rows" ] || fail "PostgreSQL: other hashes or incomplete runs than the local batch:
$(diff <(echo "$local_rows") <(pg_rows "$U"))"
"$L" report --db "$U" > "$T/report-pg.txt"
# The same text, the heading (batch id, scenario file) included.
diff "$T/report-local.txt" "$T/report-pg.txt" || fail "the reports differ (SQLite vs PostgreSQL)"
# Recordings: <database>-recordings/batch<ID>/ in the directory of the submission, absolute.
[ "$(ls "$T/forty-recordings/batch1" | wc -l)" -eq 40 ] || fail "not 40 recordings"
[ "$(pq "$U" "SELECT count(*) FROM runs WHERE recording LIKE '$T/forty-recordings/batch1/%.jsonl.gz'")" -eq 40 ] ||
  fail "recording paths: $(pq "$U" "SELECT recording FROM runs LIMIT 1")"
out=$("$L" batch "$S" --runs 20 --db "$U" --slurm --games-per-task 6)
has "$out" "nothing to submit"

# (g) task 0 cancelled mid-slice, the server restarted while task 1 writes; resubmitted.
U=$(newdb restarted)
export LLSF_DB_RETRY_S=60
out=$("$L" batch "$S" --runs 20 --db "$U" --slurm --games-per-task 8 --array-throttle 1)
job=$(sed -n 's/^submitted  job \([0-9]*\) .*/\1/p' <<<"$out")
[ -n "$job" ] || fail "no job id in: $out"
stored() { pq "$U" "SELECT count(*) FROM runs"; }
for _ in $(seq 600); do
  n=$(stored)
  [ "$n" -ge 2 ] && break
  sleep 0.05
done
[ "$n" -ge 2 ] && [ "$n" -lt 8 ] || fail "task 0 not caught mid-slice ($n runs)"
scancel "${job}_0"
# Task 1 (seeds 7-10: slices are seed-major) starts (throttle 1) and stores its first game; then
# the server goes away for 3 s, longer than a game, so that task 1 writes across the restart.
task1() { pq "$U" "SELECT count(*) FROM runs WHERE seed BETWEEN 7 AND 10" 2>/dev/null || echo 0; }
for _ in $(seq 600); do
  m=$(task1)
  [ "$m" -ge 1 ] && break
  sleep 0.05
done
[ "$m" -ge 1 ] && [ "$m" -lt 8 ] || fail "task 1 not caught mid-slice ($m runs)"
"$SRC/scripts/test-postgres" restart "$T/pg" 3
wait_batch "$U" --runs 20
out=$("$L" batch status "$S" --runs 20 --db "$U")
has "$out" "task 0 (job ${job}_0): CANCELLED"
has "$out" "resubmit"
# Task 1 outlived the restart: it reconnected, stored its whole slice (8 games), did not fail.
[ "$(task1)" -eq 8 ] || fail "task 1 lost runs across the restart"
[[ $out != *"task 1 (job"* ]] || fail "task 1 failed across the restart: $out"
left=$(( 40 - $(stored) ))
out=$("$L" batch "$S" --runs 20 --db "$U" --slurm --games-per-task 8)
has "$out" "$left of 40 runs missing"
has "$out" "(array 0)"
wait_batch "$U" --runs 20
# The resubmitted task skipped the runs of its slice that the server holds.
job=$(sed -n 's/^submitted  job \([0-9]*\) .*/\1/p' <<<"$out")
has "$(cat "$T/llsfsim-slurm/slurm-${job}_0.out")" "$left played, $((8 - left)) stored before, into $U"
once "$U" 40
[ "$(pg_rows "$U")" = "$local_rows" ] || fail "after the restart and the resubmission:
$(diff <(echo "$local_rows") <(pg_rows "$U"))"

# (h) two batches through Slurm at once into one new database (the first open creates the tables
# under the advisory lock), and a third played locally meanwhile.
U=$(newdb two)
"$L" batch "$S" --seeds 200-205 --db "$U" --slurm --games-per-task 2 > "$T/two-a.out" &
a=$!
"$L" batch "$S" --seeds 300-305 --db "$U" --slurm --games-per-task 3 > "$T/two-b.out" &
b=$!
wait "$a" || fail "the first submission: $(cat "$T/two-a.out")"
wait "$b" || fail "the second submission: $(cat "$T/two-b.out")"
"$L" batch "$S" --seeds 400-403 --db "$U" --jobs 1 -q --no-record || fail "the local batch beside them"
wait_batch "$U" --seeds 200-205
wait_batch "$U" --seeds 300-305
out=$("$L" batch status "$S" --seeds 200-205 --db "$U")
has "$out" "12 of 12 runs stored"
out=$("$L" batch status "$S" --seeds 300-305 --db "$U")
has "$out" "12 of 12 runs stored"
once "$U" 32
[ "$(pq "$U" "SELECT string_agg(n::text, ',' ORDER BY n) FROM (SELECT count(*) AS n FROM runs GROUP BY batch_id) c")" = "8,12,12" ] ||
  fail "runs per batch"
[ "$(pq "$U" "SELECT count(*) FROM runs r WHERE NOT EXISTS (SELECT 1 FROM statistics s WHERE s.run_id = r.id) OR NOT EXISTS (SELECT 1 FROM tests t WHERE t.run_id = r.id)")" -eq 0 ] ||
  fail "a half-written run"
# Created once: the same migrations as a store opened by one process.
[ "$(pq "$U" "SELECT count(*) FROM schema_migrations")" = "$(pq "$PG/forty" "SELECT count(*) FROM schema_migrations")" ] ||
  fail "schema_migrations"

# (i) an unreachable server: exit 2, nothing submitted.
jobs_before=$(squeue -h -t all -o %i | wc -l)
set +e
out=$("$L" batch "$S" --runs 20 --db "postgresql://llsf@127.0.0.1:1/nowhere" --slurm 2>&1)
rc=$?
set -e
[ "$rc" -eq 2 ] || fail "an unreachable server: exit $rc: $out"
has "$out" "127.0.0.1"
[ "$(squeue -h -t all -o %i | wc -l)" -eq "$jobs_before" ] || fail "submitted despite an unreachable server"
