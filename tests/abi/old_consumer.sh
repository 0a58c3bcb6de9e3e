#!/usr/bin/env bash
# A program built against libdmi 1.0 runs against this libdmi.so.1: builds
# the 1.0.0 release's sources (from the git history) with its example
# program ex43, runs ex43 against its own libdmi.so.1 and against LIBDMI (this
# build's), and requires the same output, byte for byte, and that the second
# run loaded LIBDMI.  Exits 77 (skipped) only for a shallow clone, whose
# history may lack the release commit; a full clone without that commit, or
# sources outside a git clone, are an error.
#   old_consumer.sh SOURCE_DIR LIBDMI
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
src=$1
new=$(readlink -f "$2")
git -C "$src" rev-parse --git-dir >/dev/null 2>&1 || { echo "$src is not a git clone: no 1.0.0 sources"; exit 1; }
# The libdmi 1.0.0 release commit.
old=5cd99dec437480a016750d3e30c966da19d925ca
if ! git -C "$src" cat-file -e "$old^{commit}" 2>/dev/null; then
  if [[ $(git -C "$src" rev-parse --is-shallow-repository) == true ]]; then
    echo "shallow clone without commit $old (1.0.0): skipped"; exit 77
  fi
  echo "commit $old (libdmi 1.0.0) is missing from a full clone"; exit 1
fi
git -C "$src" show "$old:CMakeLists.txt" | grep -q '^project(dmi VERSION 1\.0\.0' ||
  { echo "commit $old is not libdmi 1.0.0"; exit 1; }
work=$(mktemp -d "${TMPDIR:-/tmp}/dmi-old.XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir "$work/tree"
git -C "$src" archive "$old" | tar -x -C "$work/tree"
cmake -S "$work/tree" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DDMI_BUILD_TESTS=OFF \
      -DCMAKE_SKIP_BUILD_RPATH=ON >/dev/null
cmake --build "$work/build" --target ex43 >/dev/null
mkdir "$work/new"
cp "$new" "$work/new/libdmi.so.1"
ex=$work/build/examples/ex43
LD_LIBRARY_PATH=$work/build/src "$ex" 1000 3 10 >"$work/old.csv" 2>"$work/old.err"
LD_LIBRARY_PATH=$work/new "$ex" 1000 3 10 >"$work/new.csv" 2>"$work/new.err"
loaded=$(LD_LIBRARY_PATH=$work/new ldd "$ex" | grep 'libdmi\.so\.1')
[[ $loaded == *"$work/new/libdmi.so.1"* ]] || { echo "ex43 did not load the new library: $loaded"; exit 1; }
cmp "$work/old.csv" "$work/new.csv" || { echo "ex43 (built against 1.0 at $old) differs"; exit 1; }
echo "ex43 built against libdmi 1.0 ($old) runs against $(basename "$new"): $(wc -l <"$work/new.csv") identical lines"
