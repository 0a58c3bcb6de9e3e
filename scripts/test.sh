#!/usr/bin/env bash
# Runs every test: installs what is missing, builds, runs ctest (CUnit, pytest,
# gfortran and packaging tests), then the same suite built with
# -fsanitize=address,undefined.  Usage: scripts/test.sh
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
scripts/deps.sh
jobs=$(nproc)
py="$root/.venv/bin/python"

stage() { printf '\n==== %s ====\n' "$*"; }

stage "build (RelWithDebInfo) and ctest"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPython3_EXECUTABLE="$py" >/dev/null
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

stage "build with -fsanitize=address,undefined and ctest"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DDMI_SANITIZE=ON -DPython3_EXECUTABLE="$py" >/dev/null
cmake --build build-asan -j "$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE nosan

stage "all tests passed"
