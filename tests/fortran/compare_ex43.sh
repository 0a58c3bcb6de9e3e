#!/usr/bin/env bash
# Runs the C and the Fortran Example 4.3 with the same arguments and checks
# that their CSV "t,w,v" have the same rows and agree to TOL in every column.
# Usage: compare_ex43.sh C_EXE FORTRAN_EXE N T STRIDE TOL
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
c_exe=$1 f_exe=$2 N=$3 T=$4 stride=$5 tol=$6
work=$(mktemp -d "${TMPDIR:-/tmp}/dmi-ex43.XXXXXX")
trap 'rm -rf "$work"' EXIT
"$c_exe" "$N" "$T" "$stride" >"$work/c.csv" 2>/dev/null
"$f_exe" "$N" "$T" "$stride" >"$work/f.csv"
# Rows expected: t_p for p = 0, stride, 2 stride, ... and p = M = round(T N).
rows=$(awk -v N="$N" -v T="$T" -v s="$stride" \
  'BEGIN { M = int(T * N + 0.5); print int(M / s) + 1 + (M % s != 0) }')
awk -F, -v tol="$tol" -v rows="$rows" '
  FNR == NR { c[FNR] = $0; nc = FNR; next }
  { nf = FNR; f[FNR] = $0 }
  END {
    if (nc != rows + 1 || nf != rows + 1) {
      printf "rows: C %d, Fortran %d, expected %d (+ header)\n", nc - 1, nf - 1, rows; exit 1
    }
    if (c[1] != "t,w,v" || f[1] != "t,w,v") { print "header differs from t,w,v"; exit 1 }
    max = 0
    for (i = 2; i <= nc; i++) {
      if (split(c[i], a, ",") != 3 || split(f[i], b, ",") != 3) { print "bad row " i; exit 1 }
      for (j = 1; j <= 3; j++) {
        d = a[j] - b[j]; if (d < 0) d = -d
        if (d > max) max = d
        if (!(d <= tol)) { printf "row %d column %d: C %s, Fortran %s\n", i, j, a[j], b[j]; bad++ }
      }
    }
    printf "%d rows, max |C - Fortran| = %.3g (tolerance %g)\n", nc - 1, max, tol
    exit bad > 0
  }' "$work/c.csv" "$work/f.csv"
