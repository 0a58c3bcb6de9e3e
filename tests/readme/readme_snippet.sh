#!/usr/bin/env bash
# The C program of README.md ("A complete C program") built as the README says a user of the
# installed library builds it: installed into a temporary prefix, compiled as C99 with
# `cc -std=c99 app.c $(pkg-config --cflags --libs dmi) -lm -Wl,-rpath,...` (and -Wall -Wextra
# -Wpedantic -Werror), run.  It must print the line the README says it prints, and that line
# must agree with the last row of the paper's Example 4.3 run by build/examples/ex43 at the same
# h (another program: the kernel as a callback, the model in examples/paper.c).
#   readme_snippet.sh README.md BUILD_DIR LIBDIR   (LIBDIR: CMAKE_INSTALL_LIBDIR)
# CC names the compiler.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
readme=$1
build=$(cd "$2" && pwd)
lib=$3
work=$(mktemp -d "${TMPDIR:-/tmp}/dmi-readme.XXXXXX")
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null

# The first ```c block that includes <dmi.h>, a whole program.
awk '/^```c$/ { inside = 1; block = ""; next }
     inside && /^```$/ { if (block ~ /#include <dmi.h>/) { printf "%s", block; exit } inside = 0; next }
     inside { block = block $0 "\n" }' "$readme" >"$work/app.c"
grep -q '^int main' "$work/app.c" || { echo "no C program with <dmi.h> and main() in $readme"; exit 1; }
if grep -q 'M_PI' "$work/app.c"; then echo "the README's program uses M_PI, which C99 does not define"; exit 1; fi

export PKG_CONFIG_PATH=$work/prefix/$lib/pkgconfig
unset LD_LIBRARY_PATH
# shellcheck disable=SC2046  # the flags are lists of words
"${CC:-cc}" -std=c99 -Wall -Wextra -Wpedantic -Werror "$work/app.c" -o "$work/app" \
    $(pkg-config --cflags --libs dmi) -lm -Wl,-rpath,"$(pkg-config --variable=libdir dmi)"
out=$("$work/app")
said=$(grep -o -m1 'It prints `[^`]*`' "$readme" | sed 's/^It prints `//; s/`$//')
[[ $out == "$said" ]] || { echo "the program printed '$out'; the README says '$said'"; exit 1; }
# Example 4.3 with N = 1000 to T = 30 by build/examples/ex43: its last row t,w,v
ref=$("$build/examples/ex43" 1000 30 30000 | tail -n 1 |
      awk -F, '{ printf "t = %g: w = %.6f, w'"'"' = %.6f", $1, $2, $3 }')
[[ $out == "$ref" ]] || { echo "the program printed '$out'; ex43 gives '$ref'"; exit 1; }
echo "the README's program builds with pkg-config, -lm and -Wl,-rpath, and prints $out as ex43 does"
