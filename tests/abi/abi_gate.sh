#!/usr/bin/env bash
# The ABI gate: dumps the ABI of a fresh libdmi.so with abidw and compares it
# with the committed dump; fails on any difference (abidiff status != 0,
# including 4 = a compatible change).
#   abi_gate.sh DUMP LIBRARY            compare (the ctest abi_abidiff)
#   abi_gate.sh --update DUMP LIBRARY   write DUMP (scripts/update-abi.sh)
# The dump holds the exported functions and the public types they use (those
# of include/), without paths, source locations or DT_NEEDED, so that it is
# the same for every build type and checkout folder.  (The enum constants
# are not in it: tests/abi/check_symbols.py checks their released values.
# abidw --load-all-types would add them, but also internal declaration-only
# structs, so a change of internals would fail the gate.)
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
update=
if [[ ${1:-} == --update ]]; then update=1; shift; fi
dump=$1 lib=$2
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
for tool in abidw abidiff; do
  command -v $tool >/dev/null || { echo "$tool not found (Debian package abigail-tools)"; exit 1; }
done
if ! readelf -S --wide "$lib" | grep '\.debug_info' >/dev/null; then
  echo "$lib has no debug information (src/CMakeLists.txt builds it with -g)"; exit 1
fi

# abidw of LIBRARY into $1.
write_dump() {
  abidw --headers-dir "$root/include" --drop-private-types --drop-undefined-syms \
        --no-corpus-path --no-comp-dir-path --no-show-locs \
        --no-elf-needed --type-id-style hash --out-file "$1" "$lib"
  sed -i "s|path='$root/|path='|" "$1"
}

if [[ $update ]]; then
  write_dump "$dump"
  echo "wrote $dump"
  exit 0
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/dmi-abi.XXXXXX")
trap 'rm -rf "$work"' EXIT
write_dump "$work/fresh.abi"
rc=0
abidiff --no-corpus-path "$dump" "$work/fresh.abi" || rc=$?
if [[ $rc -ne 0 ]]; then
  cat <<MSG
ABI gate: abidiff exited with $rc (bit 1: error, 2: usage, 4: the ABI changed, 8: incompatibly).
If the change is deliberate, follow docs/abi.md (a new version node in src/libdmi.map, or a new
soname for an incompatible change) and run scripts/update-abi.sh to refresh $dump.
MSG
else
  echo "ABI gate: $lib matches $dump"
fi
exit $rc
