#!/bin/sh
# Checks that docs/bad-inputs.md lists exactly the rows a test program runs,
# with the same function, input, answer and message (regenerate a row with the
# program's --table output).
# Usage: check_table.sh <doc> <row prefix C|F> <test program> [args...]
# SPDX-License-Identifier: GPL-3.0-or-later
set -eu
doc=$1 prefix=$2
shift 2
cols() { grep -E "^\| $prefix[0-9]+ \|" | cut -d'|' -f2-6 | sort; }
"$@" --table | cols >"${TMPDIR:-/tmp}/run.$$" || true
cols <"$doc" >"${TMPDIR:-/tmp}/doc.$$"
status=0
if ! [ -s "${TMPDIR:-/tmp}/run.$$" ]; then
  echo "check_table: $1 printed no $prefix rows"; status=1
elif ! diff "${TMPDIR:-/tmp}/doc.$$" "${TMPDIR:-/tmp}/run.$$"; then
  echo "check_table: $doc differs from the rows of $1 (< doc, > run)"; status=1
fi
rm -f "${TMPDIR:-/tmp}/run.$$" "${TMPDIR:-/tmp}/doc.$$"
exit $status
