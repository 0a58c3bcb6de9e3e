#!/usr/bin/env bash
# A build configured as a user or a packager does (Release, default options)
# compiles our code with the warning flags but without -Werror: the next
# compiler's new warning must not break it (-Werror is for the test command,
# scripts/test.sh, through -DDMI_WERROR=ON).  Configures the source tree into
# a temporary folder, builds nothing, and reads the compile commands
# (compile_commands.json) and the generated build files (the mingw-w64 command
# lines of fmu/ and tests/wine/ are custom commands, not in the JSON).
#   default_flags.sh SOURCE_DIR GENERATOR [CMAKE_ARGUMENT...]
# (extra arguments, e.g. -DDMI_WERROR=ON, show that the check fails.)
# CC and FC name the compilers.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
src=$1
generator=$2
shift 2
work=$(mktemp -d "${TMPDIR:-/tmp}/dmi-flags.XXXXXX")
trap 'rm -rf "$work"' EXIT

cmake -S "$src" -B "$work" -G "$generator" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_EXPORT_COMPILE_COMMANDS=ON "$@" >/dev/null
# The flags are there (the check reads the right files)...
grep -q -- "-Wall -Wextra -Wpedantic" "$work/compile_commands.json" \
  || { echo "no compile command with -Wall -Wextra -Wpedantic in $work/compile_commands.json"; exit 1; }
# ... and -Werror is in none of them, nor in a custom command.
found=$(grep -rl --include=compile_commands.json --include=build.ninja --include='*.make' \
             -e "-Werror" "$work" || true)
if [[ -n $found ]]; then
  echo "-Werror in a default Release build:"
  grep -rho --include=compile_commands.json --include=build.ninja --include='*.make' \
       -e "[^ ]*-Werror[^ ]*" "$work" | sort | uniq -c
  echo "in: $found"
  exit 1
fi
echo "default Release build: warning flags without -Werror"
