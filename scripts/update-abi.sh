#!/usr/bin/env bash
# Regenerates the committed ABI dump abi/libdmi.abi from libdmi.so built in
# BUILD_DIR (default build/, configured as RelWithDebInfo if it does not exist
# yet; any build type works, not a sanitizer build).  Run it only for a
# deliberate ABI change (docs/abi.md) and commit abi/libdmi.abi with it.
# Needs abigail-tools (abidw, abidiff).  Usage: scripts/update-abi.sh [BUILD_DIR]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
if [[ ! -f $build/CMakeCache.txt ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
fi
if grep -q '^DMI_SANITIZE:BOOL=ON' "$build/CMakeCache.txt"; then
  echo "update-abi.sh: $build is a sanitizer build; use a plain one" >&2; exit 1
fi
cmake --build "$build" --target dmi_shared
lib=$(readlink -f "$build/src/libdmi.so")
mkdir -p "$root/abi"
"$root/tests/abi/abi_gate.sh" --update "$root/abi/libdmi.abi" "$lib"
"$root/tests/abi/abi_gate.sh" "$root/abi/libdmi.abi" "$lib"
git -C "$root" diff --stat -- abi/libdmi.abi
