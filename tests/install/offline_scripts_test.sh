#!/bin/sh
# SPDX-License-Identifier: MIT
# The scripts of the hackathon's set-up that can be tested without network or root changes
# (docs/organizer.md): scripts/install-deps --list / --offline on a bundle whose packages are all
# present / bad arguments, and scripts/check-links on a small tree with good and broken links.
# Usage: offline_scripts_test.sh SOURCE_DIR. About a second.
set -eu
src="$1"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "offline_scripts_test: $*" >&2; exit 1; }

# install-deps: the list, bad arguments, an offline bundle with nothing to install.
"$src/scripts/install-deps" --list | grep -qx cmake || fail "--list does not name cmake"
code=0; "$src/scripts/install-deps" --bogus 2>"$work/err" || code=$?
[ "$code" = 2 ] && grep -q "unknown argument '--bogus'" "$work/err" || fail "--bogus: exit $code"
code=0; "$src/scripts/install-deps" --offline "$work/none" 2>"$work/err" || code=$?
[ "$code" = 2 ] && grep -q "needs a bundle" "$work/err" || fail "--offline without a bundle: exit $code"
mkdir -p "$work/bundle/debs"
printf '# test\ndpkg\n\n' >"$work/bundle/packages.txt"
out=$("$src/scripts/install-deps" --offline "$work/bundle")
[ "$out" = "install-deps: all 1 packages of $work/bundle/packages.txt present" ] ||
  fail "--offline with everything present said: $out"

# check-links: a good tree passes, each kind of broken link is named with file:line.
mkdir -p "$work/tree/docs" "$work/tree/exercises/01"
printf '# Top\n[a](docs/a.md) [b](docs/a.md#two-words) [c](#top) [d](https://example.org/x)\n' \
  >"$work/tree/README.md"
printf '# A\n## Two words\n```\n[not a link](nowhere.md)\n```\n' >"$work/tree/docs/a.md"
printf '[up](../../README.md)\n' >"$work/tree/exercises/01/README.md"
"$src/scripts/check-links" "$work/tree" >"$work/out" || fail "good tree: $(cat "$work/out")"
printf 'x [gone](missing.md) [h](a.md#no-such) `../../../outside.md`\n' >>"$work/tree/docs/a.md"
code=0; "$src/scripts/check-links" "$work/tree" >"$work/out" 2>&1 || code=$?
[ "$code" = 1 ] || fail "broken links: exit $code"
grep -q "docs/a.md:6: missing.md: no such file" "$work/out" || fail "missing file: $(cat "$work/out")"
grep -q "docs/a.md:6: a.md#no-such: no heading '#no-such'" "$work/out" || fail "heading: $(cat "$work/out")"
grep -q "docs/a.md:6: ../../../outside.md: outside the source tree" "$work/out" ||
  fail "outside: $(cat "$work/out")"
echo "offline_scripts_test: ok"
