#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `llsfsim batch --slurm` on a real single-node Slurm (scripts/test-slurm-cluster: munged,
# slurmctld, slurmd in a temporary directory, stopped on every way out; docs/cluster.md):
#  (a) a 40-game batch played locally and through Slurm (SQLite shards + merge): the same result
#      hash per (variant, seed), the same `report` table;
#  (b) an array task cancelled mid-slice (scancel), reported by `batch status`; resubmitted:
#      every run present exactly once, every run whole;
#  (c) merging twice changes nothing;
#  (d) --dry-run prints the script with the options given and writes nothing;
#  (e) --runs / --seeds beyond the scenario's seed list;
#  (f)-(i) the same through a real PostgreSQL server (cluster_postgres.sh): the 40-game batch, a
#      cancelled task and a server restart, two batches at once, an unreachable server.
# Usage: cluster_test.sh LLSFSIM SOURCE_DIR
# LLSF_CLUSTER_PARTS=sqlite or =postgres runs one half (the local batch always); default both.
set -euo pipefail
L=$(realpath "$1")
SRC=$(realpath "$2")
HERE=$(dirname "$(realpath "${BASH_SOURCE[0]}")")
T=$(mktemp -d /tmp/llsf-cluster-test.XXXXXX)
PARTS=${LLSF_CLUSTER_PARTS:-sqlite,postgres}
cleanup() {
  "$SRC/scripts/test-slurm-cluster" stop "$T/slurm" || true
  [ ! -d "$T/pg" ] || "$SRC/scripts/test-postgres" stop "$T/pg" || true
  rm -rf "$T"
}
trap cleanup EXIT
trap 'exit 143' TERM INT
fail() { echo "cluster_test: FAIL: $*" >&2; exit 1; }
has() { grep -qF -- "$2" <<<"$1" || fail "expected '$2' in: $1"; }

eval "$("$SRC/scripts/test-slurm-cluster" start "$T/slurm")"
export SLURM_CONF

# A short scenario: 120 s of production, 2 variants; seeds [3, 4] in the file, --runs 20 beyond.
A=$SRC/clips/agents
cat > "$T/tiny.yaml" <<YAML
name: tiny
seeds: [3, 4]
start: production
duration_s: 120
robots:
  count: 2
  agent: [$A/common, $A/llsf2013]
  config:
    roles: [P1P2, P3]
    recycle: never
matrix:
  config:
    P3-P3: {robots.config.roles: [P3, P3]}
    P1P2-P3: {}
tests:
  - no_agent_errors: true
YAML
# The scenario by a relative path: the tasks start in this directory (#SBATCH --chdir).
cd "$T"
S=tiny.yaml
hashes() { sqlite3 "$1" "SELECT variant, seed, result_hash FROM runs ORDER BY variant, seed"; }
wait_batch() {  # db, runs args...: follow until nothing is left running or queued
  local db=$1; shift
  "$L" batch status "$S" "$@" --db "$db" --wait --interval 0.5 >/dev/null 2>&1 || true
}

# (d) --dry-run: the script, nothing submitted, nothing written.
out=$("$L" batch "$S" --runs 20 --db "$T/dry.db" --slurm --dry-run --partition debug \
  --time-limit 0:10:00 --array-throttle 3 --games-per-task 7 --sbatch-arg=--mem=1G --jobs 2)
has "$out" "#SBATCH --array=0-5%3"
has "$out" "#SBATCH --partition=debug"
has "$out" "#SBATCH --time=0:10:00"
has "$out" "#SBATCH --mem=1G"
has "$out" "#SBATCH --cpus-per-task=2"
has "$out" "#SBATCH --requeue"
has "$out" "#SBATCH --chdir=$T"
has "$out" "batch tiny.yaml --db $T/dry.db"
has "$out" "--games-per-task 7 --jobs 2 --runs 20"
has "$out" '--task "$SLURM_ARRAY_TASK_ID"'
[ ! -e "$T/dry.db" ] || fail "--dry-run wrote the store"
[ -z "$(squeue -h -o %i)" ] || fail "--dry-run submitted a job"

# (a) 40 games locally and through Slurm.
"$L" batch "$S" --runs 20 --db "$T/local.db" --jobs 2 -q || fail "local batch"
"$L" report --db "$T/local.db" > "$T/report-local.txt"
if [[ $PARTS == *postgres* ]]; then
  # shellcheck source=cluster_postgres.sh
  source "$HERE/cluster_postgres.sh"
  echo "cluster_test: postgres ok"
fi
[[ $PARTS == *sqlite* ]] || { echo "cluster_test: ok"; exit 0; }
out=$("$L" batch "$S" --runs 20 --db "$T/cluster.db" --slurm --games-per-task 6)
has "$out" "40 of 40 runs missing, 6 games per task"
has "$out" "(array 0-6)"
wait_batch "$T/cluster.db" --runs 20
out=$("$L" batch status "$S" --runs 20 --db "$T/cluster.db")
has "$out" "40 of 40 runs stored"
out=$("$L" batch merge --db "$T/cluster.db")
has "$out" "7 shards into $T/cluster.db: 40 runs added, 0 already there"
[ "$(hashes "$T/local.db")" = "$(hashes "$T/cluster.db")" ] || fail "hashes differ"
[ "$(hashes "$T/local.db" | wc -l)" -eq 40 ] || fail "not 40 runs"
"$L" report --db "$T/cluster.db" > "$T/report-cluster.txt"
diff "$T/report-local.txt" "$T/report-cluster.txt" || fail "the reports differ"
# Recordings named as in a local batch: <recordings>/batch<ID>/, paths relative to the store.
[ "$(ls "$T/cluster-recordings/batch1" | wc -l)" -eq 40 ] || fail "not 40 recordings"
[ "$(sqlite3 "$T/cluster.db" "SELECT count(*) FROM runs WHERE recording LIKE 'cluster-recordings/batch1/%'")" -eq 40 ] ||
  fail "recording paths"
# Resubmitting a complete batch submits nothing.
out=$("$L" batch "$S" --runs 20 --db "$T/cluster.db" --slurm --games-per-task 6)
has "$out" "nothing to submit"

# (c) merging twice changes nothing.
before=$(sqlite3 "$T/cluster.db" .dump | md5sum)
out=$("$L" batch merge --db "$T/cluster.db")
has "$out" "0 runs added, 40 already there"
[ "$(sqlite3 "$T/cluster.db" .dump | md5sum)" = "$before" ] || fail "the second merge changed the store"
# A shard whose copy of a stored run differs (another program played it): said, the store's kept.
cp "$T/cluster.db" "$T/c2.db"
cp "$T/cluster.shard-00000.db" "$T/c2-shard.db"
sqlite3 "$T/c2-shard.db" "UPDATE runs SET result_hash = '0000000000000000' WHERE id = 1"
out=$("$L" batch merge "$T/c2-shard.db" --db "$T/c2.db" 2>&1)
has "$out" "1 runs of the shards have another result hash"
[ "$(hashes "$T/c2.db")" = "$(hashes "$T/local.db")" ] || fail "a differing shard changed the store"

# (b) one array task cancelled mid-slice; status names it; resubmission plays only what is missing.
out=$("$L" batch "$S" --runs 20 --db "$T/cancel.db" --slurm --games-per-task 8 --array-throttle 1)
job=$(sed -n 's/^submitted  job \([0-9]*\) .*/\1/p' <<<"$out")
[ -n "$job" ] || fail "no job id in: $out"
shard=$T/cancel.shard-00000.db
for _ in $(seq 600); do
  n=$(sqlite3 "$shard" "SELECT count(*) FROM runs" 2>/dev/null || echo 0)
  [ "$n" -ge 2 ] && break
  sleep 0.05
done
[ "$n" -ge 2 ] && [ "$n" -lt 8 ] || fail "task 0 not caught mid-slice ($n runs)"
scancel "${job}_0"
wait_batch "$T/cancel.db" --runs 20
out=$("$L" batch status "$S" --runs 20 --db "$T/cancel.db")
has "$out" "task 0 (job ${job}_0): CANCELLED"
has "$out" "resubmit"
stored=$(sqlite3 "$shard" "SELECT count(*) FROM runs")
[ "$stored" -lt 8 ] || fail "the cancelled task stored its whole slice"
out=$("$L" batch "$S" --runs 20 --db "$T/cancel.db" --slurm --games-per-task 8)
has "$out" "$((8 - stored)) of 40 runs missing"
has "$out" "(array 0)"
wait_batch "$T/cancel.db" --runs 20
"$L" batch merge --db "$T/cancel.db" -q
[ "$(sqlite3 "$T/cancel.db" "SELECT count(*), count(DISTINCT variant || '/' || seed) FROM runs")" = "40|40" ] ||
  fail "not every run exactly once"
# Whole runs: each has its statistics and its test verdict.
[ "$(sqlite3 "$T/cancel.db" "SELECT count(*) FROM runs r WHERE (SELECT count(*) FROM statistics s WHERE s.run_id = r.id) = 0 OR (SELECT count(*) FROM tests t WHERE t.run_id = r.id) = 0")" -eq 0 ] ||
  fail "a half-written run"
[ "$(hashes "$T/local.db")" = "$(hashes "$T/cancel.db")" ] || fail "hashes differ after the resubmission"

# (b') the same, retried by `batch status --wait --resubmit 1`: 12 games, tasks of 6, one at a time.
out=$("$L" batch "$S" --seeds 100-105 --db "$T/retry.db" --slurm --games-per-task 6 --array-throttle 1)
job=$(sed -n 's/^submitted  job \([0-9]*\) .*/\1/p' <<<"$out")
for _ in $(seq 600); do
  n=$(sqlite3 "$T/retry.shard-00000.db" "SELECT count(*) FROM runs" 2>/dev/null || echo 0)
  [ "$n" -ge 1 ] && break
  sleep 0.05
done
scancel "${job}_0"
"$L" batch status "$S" --seeds 100-105 --db "$T/retry.db" --wait --resubmit 1 --interval 0.5 \
  > "$T/retry.out" 2> "$T/retry.err" || fail "--resubmit did not complete: $(cat "$T/retry.out" "$T/retry.err")"
has "$(cat "$T/retry.err")" "resubmitted the tasks holding the"
has "$(cat "$T/retry.err")" "(array 0)"
has "$(cat "$T/retry.out")" "12 of 12 runs stored"

# (e) --runs and --seeds beyond the file's list [3, 4]: seeds after the largest, counting up.
[ "$(sqlite3 "$T/local.db" "SELECT group_concat(seed) FROM (SELECT DISTINCT seed FROM runs ORDER BY seed)")" = \
  "3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22" ] || fail "--runs 20 seeds"
"$L" batch "$S" --seeds 21-22,40 --db "$T/local.db" -q --no-record || fail "--seeds"
[ "$(sqlite3 "$T/local.db" "SELECT count(*) FROM batches")" -eq 2 ] || fail "--seeds 21-22,40 is its own batch"
# The same (variant, seed) gives the same result in either batch.
[ "$(sqlite3 "$T/local.db" "SELECT count(DISTINCT result_hash) FROM runs WHERE seed = 21 GROUP BY variant" | sort -u)" = 1 ] ||
  fail "seed 21 played differently"
# --seeds equal to --runs N's seeds is that batch (nothing played).
out=$("$L" batch "$S" --seeds 3-22 --db "$T/local.db")
has "$out" "40 runs, 0 played, 40 stored before"
out=$("$L" batch "$S" --seeds 3,x --db "$T/local.db" 2>&1) && fail "--seeds 3,x accepted"
has "$out" "'x' is not a seed"
out=$("$L" batch "$S" --runs 2 --seeds 3 --db "$T/local.db" 2>&1) && fail "--runs with --seeds accepted"
echo "cluster_test: ok"
