#!/usr/bin/env bash
# examples/chain and examples/box built as a user builds them: libdmi installed into a temporary
# prefix, each example configured on its own with its CMakeLists.txt (find_package(dmi) through
# CMAKE_PREFIX_PATH), compiled as C99 with -Wall -Wextra -Wpedantic -Werror, run, and its output
# compared with the same model computed independently (examples_reference.py, numpy).
#   user_examples.sh SOURCE_DIR BUILD_DIR PYTHON
# CC names the compiler.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
src=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
py=$3
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/dmi-examples.XXXXXX")
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
unset LD_LIBRARY_PATH
N=200 T=10 stride=20
for ex in chain box; do
  grep -E '^#include' "$src/examples/$ex/$ex.c" | grep -v -E '<(dmi|math|stdio|stdlib|string)\.h>' &&
    { echo "$ex.c includes more than <dmi.h> and the C library"; exit 1; }
  cmake -S "$src/examples/$ex" -B "$work/$ex" -DCMAKE_PREFIX_PATH="$work/prefix" \
        -DCMAKE_C_FLAGS="-Wall -Wextra -Wpedantic -Werror" -DCMAKE_BUILD_TYPE=Release >"$work/$ex.log" 2>&1 ||
    { cat "$work/$ex.log"; exit 1; }
  cmake --build "$work/$ex" >>"$work/$ex.log" 2>&1 || { cat "$work/$ex.log"; exit 1; }
  "$work/$ex/$ex" "$N" "$T" "$stride" >"$work/$ex.csv"
  "$py" "$here/examples_reference.py" "$ex" "$N" "$T" "$stride" "$work/$ex.csv"
done
echo "examples/chain and examples/box build against the installed library and match the independent scheme"
