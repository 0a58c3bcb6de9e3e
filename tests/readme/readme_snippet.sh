#!/usr/bin/env bash
# The C snippet of README.md ("The C API in a few lines") built as the README
# says a user of the installed library builds it: installed into a temporary
# prefix, compiled with `cc app.c $(pkg-config --cflags --libs dmi) -lm`
# and -Wl,-rpath, run; it must exit 0 without printing an error.  The
# snippet's callbacks stay at file scope, its statements go into main().
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

# The first ```c block that includes <dmi.h>; main() opens before its first
# statement (the line declaring the solver) and closes after its last line.
awk '/^```c$/ { inside = 1; next }
     inside && /^```$/ { if (found) { print "return 0;\n}"; exit } inside = 0; next }
     inside && /#include <dmi.h>/ { found = 1 }
     inside && found && /^dmi_solver \*s/ { print "int main(void)\n{" }
     inside && found { print }' "$readme" >"$work/app.c"
grep -q '^int main' "$work/app.c" || { echo "no C snippet with <dmi.h> and a solver in $readme"; exit 1; }

export PKG_CONFIG_PATH=$work/prefix/$lib/pkgconfig
unset LD_LIBRARY_PATH
# shellcheck disable=SC2046  # the flags are lists of words
"${CC:-cc}" -std=c99 -Werror=implicit-function-declaration "$work/app.c" -o "$work/app" \
    $(pkg-config --cflags --libs dmi) -lm -Wl,-rpath,"$(pkg-config --variable=libdir dmi)"
out=$("$work/app" 2>&1)
[[ -z $out ]] || { echo "the snippet printed: $out"; exit 1; }
echo "the README's snippet builds with pkg-config, -lm and -Wl,-rpath, and runs"
