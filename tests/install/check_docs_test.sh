#!/bin/sh
# SPDX-License-Identifier: MIT
# scripts/check-docs (the doc_examples test) on small trees with a stand-in llsfsim: a shown
# command whose output matches passes, a different output fails; a command shown with its output
# but without the `$ ` prompt fails (it would not be checked), as do llsfsim's output shown
# without its command and a doc-test block without a `$ ` line; commands shown without output
# pass. Usage: check_docs_test.sh SOURCE_DIR. About a second.
set -eu
src="$1"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "check_docs_test: $*" >&2; exit 1; }
mkdir -p "$work/bin" "$work/tree/docs"
printf '#!/bin/sh\necho "hello $*"\n' >"$work/bin/llsfsim"
chmod +x "$work/bin/llsfsim"
page="$work/tree/docs/a.md"
check() {  # expected exit code; the output in $work/out
  code=0
  python3 "$src/scripts/check-docs" --llsfsim "$work/bin/llsfsim" "$work/tree" >"$work/out" 2>&1 ||
    code=$?
  [ "$code" = "$1" ] || fail "exit $code, not $1: $(cat "$work/out")"
}
fence='```'

# Checked and matching; commands shown without output (continuations, comments) need no check.
cat >"$page" <<EOT
<!-- doc-test -->
$fence
\$ llsfsim run x
hello run x
$fence

$fence sh
llsfsim run x    # plays x
build/release/llsfsim batch x --runs 2 \\
    --db y.db
make test
$fence
EOT
check 0
grep -q "check-docs: 1 command(s) checked" "$work/out" || fail "good page: $(cat "$work/out")"

# A different output is a failure with file:line.
sed -i 's/^hello run x$/hello run y/' "$page"
check 1
grep -q "docs/a.md:3: \`llsfsim run x\`: the output differs" "$work/out" || fail "diff: $(cat "$work/out")"

# A command with its output but no prompt: not checked, so a failure naming the command's line.
cat >"$page" <<EOT
Text.

$fence
build/release/llsfsim exercise 02 --skill x.lua --submit http://h:8080/ \\
    --team t
submitted x.lua: submission 17
$fence
EOT
check 1
grep -q "docs/a.md:4: a command is shown with its output but without the \`\$ \` prompt" \
  "$work/out" || fail "no prompt: $(cat "$work/out")"
# ... unless it says why it is not run.
sed -i '2a <!-- doc-test skip: a server -->' "$page"
check 0

# A doc-test block without a \`$ \` line would check nothing.
cat >"$page" <<EOT
<!-- doc-test -->
$fence
llsfsim run x
hello run x
$fence
EOT
check 1
grep -q "docs/a.md:2: a doc-test block without a \`\$ \` line checks nothing" "$work/out" ||
  fail "doc-test without \$: $(cat "$work/out")"
# llsfsim's output shown without its command (the command in the prose): not checked either.
cat >"$page" <<EOT
\`llsfsim run x --trace robot1\` prints:

$fence
[   6.22] robot1 ==> f-181 (time 6 216666)
[   6.22] robot1 msg -> LockMasterAnnounce {agent: "robot2"}
$fence

A diagram, not output:

$fence
NONE --request--> REQUESTED
$fence
EOT
check 1
grep -q "docs/a.md:3: the block shows llsfsim's output without the command" "$work/out" ||
  fail "output without command: $(cat "$work/out")"
[ "$(grep -c "docs/a.md:" "$work/out")" = 1 ] || fail "the diagram was taken for output: $(cat "$work/out")"
sed -i '2a <!-- doc-test skip: an illustration -->' "$page"
check 0
echo "check_docs_test: ok"
