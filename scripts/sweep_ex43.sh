#!/usr/bin/env bash
# The main job's bifurcation diagram (scripts/main.sh runs it): dmi-sweep runs
# the spec (default examples/python/oscillator_tau.toml: the oscillator over the delay
# tau, Poincare section of w) into OUT/sweep_ex43 and plots, over the
# spec's first swept parameter, OUT/bifurcation_ex43.png and
# OUT/stick_fraction_ex43.png; prints the points, N and T of the spec and the
# time it took on this machine's cores.  Exit status 1, with a message, when the
# FMU or dmi-sweep is missing or the sweep fails.
# Usage: scripts/sweep_ex43.sh OUT [SPEC]
# Environment: DMI_BUILD_DIR (default build; the FMU is its
# fmu/DelayFrictionOscillator.fmu), DMI_SWEEP (default .venv/bin/dmi-sweep).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [[ $# -lt 1 || $# -gt 2 ]]; then
  echo "usage: scripts/sweep_ex43.sh OUT [SPEC]" >&2
  exit 2
fi
out=$1
spec=${2:-$root/examples/python/oscillator_tau.toml}
build=${DMI_BUILD_DIR:-$root/build}
fmu="$build/fmu/DelayFrictionOscillator.fmu"
sweep=${DMI_SWEEP:-$root/.venv/bin/dmi-sweep}
py="$root/.venv/bin/python"
fail() { echo "sweep_ex43: $*" >&2; exit 1; }
[[ -f $fmu ]] || fail "the FMU $fmu does not exist (the build makes it)"
[[ -x $sweep ]] || fail "dmi-sweep ($sweep) is not installed (scripts/deps.sh installs it into .venv)"
[[ -f $spec ]] || fail "the spec $spec does not exist"

rm -rf "$out/sweep_ex43"
mkdir -p "$out"
start=$SECONDS
DMI_FMU="$fmu" "$sweep" run "$spec" --out "$out/sweep_ex43" --quiet || fail "the sweep failed"
x=$("$py" -c 'import json, sys; print(json.load(open(sys.argv[1]))["params"][0])' "$out/sweep_ex43/_meta.json")
"$sweep" plot "$out/sweep_ex43" --x "$x" -o "$out/bifurcation_ex43.png" || fail "the plot failed"
"$sweep" plot "$out/sweep_ex43" --x "$x" --metric sticking_mean -o "$out/stick_fraction_ex43.png" ||
  fail "the plot failed"
seconds=$((SECONDS - start))
# the points as the sweep counted them (its metadata), N and T as the spec gives them
what=$("$py" - "$out/sweep_ex43/_meta.json" "$spec" <<'PY'
import json, sys, tomllib
meta = json.load(open(sys.argv[1]))
spec = tomllib.load(open(sys.argv[2], "rb"))
n = spec.get("start", {}).get("N", "the FMU's default")
print(f"{meta['points']} points of {', '.join(meta['params'])} (N = {n}, T = {spec['stop_time']:g})")
PY
)
echo "bifurcation diagram: $what in $seconds s on $(nproc) cores"
