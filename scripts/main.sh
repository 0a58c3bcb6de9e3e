#!/usr/bin/env bash
# The main job: reproduces the paper's Section 4.  Installs what it lacks
# (scripts/deps.sh), builds everything in build/, runs the paper's examples and
# writes into out/: the CSV of each example, Figures 4.1-4.5, the FMU's
# Example 4.3 run by fmpy over the native run, the evidence for the erratum in
# (4.4), the oscillator with a Prony-series memory (exponential kernel terms,
# the recursion against the FFT), a bifurcation diagram of the oscillator over the
# delay tau (dmi-sweep) and its periodic orbits continued over it (dmi.analysis,
# examples/python/orbit_tau.py), the stability chart of the distributed-delay
# oscillator (dmi.analysis), the belt with memory from its equilibrium to its
# stick-slip branch (dmi.analysis, self-excited), the forced Bagley-Torvik oscillator with dry
# friction (fractional damping, dmi.analysis); prints the summary table.  Copies the figures
# to docs/figures/.
# Usage: scripts/main.sh
# Environment: DMI_BUILD_DIR (default build), DMI_OUT_DIR (default out).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
build=${DMI_BUILD_DIR:-build}
out=${DMI_OUT_DIR:-out}
py="$root/.venv/bin/python"
ref="$root/../shared/reference"

stage() { printf '\n==== %s ====\n' "$*"; }

stage "dependencies"
scripts/deps.sh

stage "build ($build, log in $out/build.log)"
mkdir -p "$out"
if ! { cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPython3_EXECUTABLE="$py" &&
       cmake --build "$build" -j "$(nproc)"; } >"$out/build.log" 2>&1; then
  tail -n 40 "$out/build.log"
  echo "main: the build failed (full log: $out/build.log)"
  exit 1
fi
echo "built"
ex="$build/examples"

stage "Examples 4.1-4.3 at h = 1/9991: CSV in $out/"
for e in 41 42 43; do
  T=10
  [[ $e == 43 ]] && T=30
  "$ex/ex$e" 9991 "$T" 1 >"$out/ex$e.csv" 2>"$out/ex$e.log"
  cat "$out/ex$e.log"
done

stage "summary table (order study of Figure 4.3 in $out/order.csv)"
"$ex/paper_summary" "$out/order.csv" | tee "$out/summary.txt"

stage "erratum: scheme (4.4) as printed against (3.12)-(3.13), Example 4.2"
"$ex/scheme44_as_printed" 10 10 2>&1 >"$out/scheme44.csv" | tee "$out/scheme44.txt"

stage "Prony-series (viscoelastic) memory at N = 1e5: the recursion beside the FFT"
"$ex/prony" 100000 20 | tee "$out/prony.txt"

stage "FMU: Example 4.3 with fmpy"
rm -f "$out/fmu43.csv" "$out/ex43_fmu_native.csv"
fmu="$build/fmu/DelayFrictionOscillator.fmu"
if [[ -f scripts/fmu_run.py && -f $fmu ]]; then
  # The paper's h = 1/9991 for the FMU (start value N = 1000) and the native run of the overlay.
  fmu_N=9991
  "$py" scripts/fmu_run.py --fmu "$fmu" --out "$out/fmu43.csv" --start N=$fmu_N
  "$ex/ex43" "$fmu_N" 30 1 >"$out/ex43_fmu_native.csv"
else
  echo "skipped: scripts/fmu_run.py or $fmu does not exist (no FMU in this checkout)"
fi

stage "dmi-sweep: bifurcation diagram of the oscillator over the delay tau (Poincare section of w)"
DMI_BUILD_DIR="$build" scripts/sweep_ex43.sh "$out"

stage "periodic orbits: the oscillator's branches over tau (dmi.analysis) over the sweep's diagram"
OPENBLAS_NUM_THREADS=1 MPLBACKEND=Agg "$py" examples/python/orbit_tau.py "$out" --M 4000 | tee "$out/orbit_tau.txt"

stage "dmi.analysis: stability chart of the distributed-delay oscillator (100 x 100, N = 128)"
PYTHONPATH="$build/python" MPLBACKEND=Agg "$py" examples/python/stability_chart.py "$out/stability_chart.png"

stage "dmi.analysis: the belt with memory from its equilibrium to the stick-slip branch"
PYTHONPATH="$build/python" MPLBACKEND=Agg DMI_FIGURE="$out/belt_selfexcited.png" "$py" \
  examples/python/plot_belt_selfexcited.py | tee "$out/belt_selfexcited.txt"

stage "dmi.analysis: the forced Bagley-Torvik oscillator with dry friction (fitted s^-1/2 kernel, O(1))"
PYTHONPATH="$build/python" MPLBACKEND=Agg DMI_FIGURE="$out/bagley_torvik.png" "$py" \
  examples/python/plot_bagley_torvik.py | tee "$out/bagley_torvik.txt"

stage "dmi.analysis: Stribeck friction split at the static level, verified stability of the belt's orbits"
PYTHONPATH="$build/python:examples/python" MPLBACKEND=Agg DMI_FIGURE="$out/stribeck_belt.png" "$py" \
  examples/python/plot_stribeck_belt.py | tee "$out/stribeck_belt.txt"

stage "dmi.analysis: a stick-slip orbit of the equation with memory by collocation"
PYTHONPATH="$build/python" MPLBACKEND=Agg DMI_FIGURE="$out/collocation_stickslip.png" "$py" \
  examples/python/plot_collocation_stickslip.py | tee "$out/collocation_stickslip.txt"

stage "dmi.analysis: the belt with memory in its (belt speed, damping) plane: Hopf curve, grid, regions"
PYTHONPATH="$build/python" MPLBACKEND=Agg DMI_PLANE_ROWS=8 DMI_FIGURE="$out/belt_plane.png" \
  DMI_FIGURE_HTML="$out/belt_plane.html" "$py" examples/python/plot_belt_plane.py | tee "$out/belt_plane.txt"

stage "dmi.identify: a friction oscillator with a viscoelastic memory identified from noisy data"
PYTHONPATH="$build/python" MPLBACKEND=Agg DMI_FIGURE="$out/identify_friction_memory.png" "$py" \
  examples/python/plot_identify_friction_memory.py | tee "$out/identify_friction_memory.txt"

stage "dmi.identify: data that leave the friction level undetermined, and the fit saying so"
PYTHONPATH="$build/python" MPLBACKEND=Agg DMI_FIGURE="$out/identify_unidentifiable.png" "$py" \
  examples/python/plot_identify_unidentifiable.py | tee "$out/identify_unidentifiable.txt"

stage "figures and comparison with the paper and ../shared/reference"
refarg=()
if [[ -d $ref ]]; then
  refarg=("$ref")
else
  echo "note: $ref not found, no comparison with the reference values"
fi
MPLBACKEND=Agg "$py" examples/plot_paper.py "$out" "${refarg[@]}" | tee "$out/comparison.txt"

mkdir -p docs/figures
cp "$out"/*.png docs/figures/

stage "done in ${SECONDS} s: results in $out/, figures also in docs/figures/"
