#!/bin/sh
# SPDX-License-Identifier: MIT
# The installed package end to end (ctest: install_out_of_tree): `cmake --install` of this build
# into a temporary prefix, which is then moved (relocatable); the installed llsfsim finds its data
# beside itself and LLSF_DATA_DIR overrides it; examples/out-of-tree is configured, built against
# the package and run.
# Usage: out_of_tree_test.sh BUILD_DIR SOURCE_DIR VERSION CMAKE CXX_COMPILER
set -eu
build=$1 source=$2 version=$3 cmake=$4 cxx=$5
tmp=$(mktemp -d "${TMPDIR:-/tmp}/llsfsim-install.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "out_of_tree_test: $*" >&2; exit 1; }
unset LLSF_DATA_DIR LLSF_VIEWER_DIR LLSF_EXERCISES_DIR LLSF_TEST_INTERNAL_ERROR

"$cmake" --install "$build" --prefix "$tmp/first" >/dev/null
mv "$tmp/first" "$tmp/prefix"
prefix=$tmp/prefix
bin=$prefix/bin/llsfsim
data=$prefix/share/llsfsim
for f in include/llsfsim/llsfsim.h lib/cmake/llsfsim/llsfsimConfig.cmake \
    lib/cmake/llsfsim/llsfsimDependencies.cmake share/llsfsim/clips/agents share/llsfsim/lua/skills \
    share/llsfsim/scenarios/default.yaml share/llsfsim/proto/llsf_msgs/GameState.proto \
    share/doc/llsfsim/LICENSE; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done
# The one installed header is the interface: no other header of llsfsim's (the modules', the test
# helpers', the generated messages').
others=$(cd "$prefix/include" && find . -type f ! -path ./llsfsim/llsfsim.h)
[ -z "$others" ] || fail "headers besides llsfsim/llsfsim.h installed: $others"
# The exported targets name their dependencies as targets, never a library path of this machine.
if grep -n 'INTERFACE_LINK_LIBRARIES.*"[^"]*/[^"]*\.\(so\|a\)' "$prefix"/lib/cmake/llsfsim/llsfsimTargets*.cmake; then
  fail "an exported target links a library by path"
fi

# The installed command: its version, its data beside it (an exercise removed from the installed
# copy is gone from the list), LLSF_DATA_DIR over that, a scenario with its agents and skills.
[ "$("$bin" --version)" = "llsfsim $version" ] || fail "llsfsim --version: $("$bin" --version)"
rm -r "$data/exercises/05-two-robots"
list=$(cd "$tmp" && "$bin" exercise --list)
echo "$list" | grep -q '^01-drive-to-point' || fail "exercise --list: $list"
echo "$list" | grep -q '^05-two-robots' && fail "exercise --list read the source tree"
mkdir "$tmp/empty"
if LLSF_DATA_DIR=$tmp/empty "$bin" exercise --list 2>"$tmp/err"; then fail "LLSF_DATA_DIR ignored"; fi
grep -q "no exercises in $tmp/empty/exercises" "$tmp/err" || fail "LLSF_DATA_DIR: $(cat "$tmp/err")"
(cd "$tmp" && "$bin" check "$data/scenarios/default.yaml") || fail "llsfsim check"
# The installed agents' rule tests, and a new agent's (its files name nothing outside its folder).
(cd "$tmp" && "$bin" test-agent "$data/clips/agents" >/dev/null) || fail "llsfsim test-agent"
(cd "$tmp" && "$bin" new agent "$tmp/new-agent" >/dev/null &&
  "$bin" test-agent "$tmp/new-agent" >/dev/null) || fail "llsfsim new agent + test-agent"

# A project of one's own: find_package(llsfsim), link llsf::llsfsim, include only
# <llsfsim/llsfsim.h>, play.
"$cmake" -S "$source/examples/out-of-tree" -B "$tmp/example" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_CXX_COMPILER="$cxx" >/dev/null
"$cmake" --build "$tmp/example" >/dev/null
"$tmp/example/llsfsim-example" >"$tmp/out"
cat "$tmp/out"
grep -qx "llsfsim   $version" "$tmp/out" || fail "example: version"
grep -qx "data      $data" "$tmp/out" || fail "example: data directory"
grep -q '^result    [0-9a-f]\{16\}$' "$tmp/out" || fail "example: no result"
grep -q '^products  [0-9]* P3$' "$tmp/out" || fail "example: no statistics"
# Bad input reaches the program as llsfsim::Error, naming the file.
echo "robots: {count: 99}" > "$tmp/bad.yaml"
if "$tmp/example/llsfsim-example" "$tmp/bad.yaml" 2>"$tmp/err"; then fail "example: bad scenario played"; fi
grep -q "bad.yaml" "$tmp/err" || fail "example: the error does not name the file: $(cat "$tmp/err")"
echo "out_of_tree_test: ok"
