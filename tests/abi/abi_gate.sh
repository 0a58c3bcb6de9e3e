#!/usr/bin/env bash
# The ABI gate: compares a fresh libdmi.so with the committed abidw dump and
# fails on any difference (abidiff status != 0, including 4 = compatible
# change).  Usage: abi_gate.sh DUMP LIBRARY HEADERS_DIR
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -uo pipefail
dump=$1 lib=$2 headers=$3
command -v abidiff >/dev/null || { echo "abidiff not found (Debian package abigail-tools)"; exit 1; }
abidiff --fail-no-debug-info --drop-private-types --no-corpus-path --hd2 "$headers" "$dump" "$lib"
rc=$?
if [[ $rc -ne 0 ]]; then
  cat <<MSG
ABI gate: abidiff exited with $rc (bit 1: error, 2: usage, 4: the ABI changed, 8: incompatibly).
If the change is deliberate, follow docs/abi.md (new version node in src/libdmi.map, or a new
soname for an incompatible change) and run scripts/update-abi.sh to refresh $dump.
MSG
else
  echo "ABI gate: $lib matches $dump"
fi
exit $rc
