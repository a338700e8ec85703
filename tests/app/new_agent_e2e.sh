#!/bin/sh
# SPDX-License-Identifier: MIT
# `llsfsim new agent` from a fresh checkout (ctest: new_agent_e2e): in an empty temporary
# directory, with nothing but the built llsfsim (which finds its data as an installed one does:
# docs/install.md), write an agent, run its rule tests, play its scenario.
# Usage: new_agent_e2e.sh LLSFSIM
set -eu
bin=$1
tmp=$(mktemp -d "${TMPDIR:-/tmp}/llsfsim-new-agent.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "new_agent_e2e: $*" >&2; exit 1; }
unset LLSF_DATA_DIR LLSF_VIEWER_DIR LLSF_EXERCISES_DIR LLSF_TEST_INTERNAL_ERROR
cd "$tmp"

# new agent: writes the three files, prints them and the next commands.
"$bin" new agent "$tmp/a" >"$tmp/out" 2>&1 || fail "new agent: exit $?: $(cat "$tmp/out")"
for f in agent/agent.clp scenario.yaml tests/agent_test.yaml; do
  [ -s "$tmp/a/$f" ] || fail "new agent did not write $f"
  grep -q "wrote $tmp/a/$f" "$tmp/out" || fail "new agent did not print $f: $(cat "$tmp/out")"
done
grep -q "llsfsim test-agent $tmp/a" "$tmp/out" || fail "new agent: no next commands: $(cat "$tmp/out")"
# ... refuses a non-empty directory (exit 2), writes into it with --force.
code=0
"$bin" new agent "$tmp/a" >"$tmp/out" 2>&1 || code=$?
[ "$code" = 2 ] || fail "new agent into a non-empty directory: exit $code (expected 2)"
grep -q "is not empty" "$tmp/out" || fail "new agent: $(cat "$tmp/out")"
"$bin" new agent "$tmp/a" --force >/dev/null || fail "new agent --force"

# test-agent: the written test passes.
"$bin" test-agent "$tmp/a" >"$tmp/out" 2>&1 || fail "test-agent: exit $?: $(cat "$tmp/out")"
cat "$tmp/out"
grep -q "^PASS .*agent_test.yaml: " "$tmp/out" || fail "test-agent: no PASS line"
grep -q "passed, 0 failed" "$tmp/out" || fail "test-agent: summary"

# A failing expectation: exit 1, its file:line, the agent's facts; --filter; -v the agent's log.
cp -r "$tmp/a" "$tmp/b"
cat >>"$tmp/b/tests/agent_test.yaml" <<'YAML'

  - name: a wrong expectation
    given:
      - modify: (game (phase PRODUCTION) (state RUNNING))
    steps:
      - step: 1
      - expect: (parked yes)
YAML
line=$(grep -n "expect: (parked yes)" "$tmp/b/tests/agent_test.yaml" | cut -d: -f1)
code=0
"$bin" test-agent "$tmp/b" --filter wrong -v >"$tmp/out" 2>&1 || code=$?
[ "$code" = 1 ] || fail "test-agent with a failing case: exit $code (expected 1): $(cat "$tmp/out")"
grep -q "^FAIL .*: a wrong expectation" "$tmp/out" || fail "no FAIL line: $(cat "$tmp/out")"
grep -q "agent_test.yaml:$line: test a wrong expectation: expected a fact (parked yes) but there is none" \
  "$tmp/out" || fail "no file:line of the failure: $(cat "$tmp/out")"
grep -q "skill-call park{}" "$tmp/out" || fail "-v: no agent log: $(cat "$tmp/out")"
grep -q "(2 left out by --filter)" "$tmp/out" || fail "--filter: $(cat "$tmp/out")"
# A misspelt key: exit 2, file:line:column and "did you mean".
sed -i 's/expect: (parked yes)/expct: (parked yes)/' "$tmp/b/tests/agent_test.yaml"
code=0
"$bin" test-agent "$tmp/b" >"$tmp/out" 2>&1 || code=$?
[ "$code" = 2 ] || fail "test-agent with a bad file: exit $code (expected 2)"
grep -q "agent_test.yaml:$line:[0-9]*: .*unknown key 'expct' (did you mean 'expect'?)" "$tmp/out" ||
  fail "bad file: $(cat "$tmp/out")"

# run: the scenario plays and its test cases pass; nothing written beside it.
"$bin" run "$tmp/a/scenario.yaml" --no-db --no-record >"$tmp/out" 2>&1 ||
  fail "run: exit $?: $(cat "$tmp/out")"
cat "$tmp/out"
grep -q "PASS" "$tmp/out" || fail "run: no PASS verdict"
if grep -q "FAIL" "$tmp/out"; then fail "run: a test case failed"; fi
echo "new_agent_e2e: ok"
