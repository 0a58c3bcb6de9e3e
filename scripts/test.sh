#!/usr/bin/env bash
# Runs every test: installs what is missing, builds, runs ctest (CUnit, pytest,
# gfortran and packaging tests), then the core, FMU and install tests in the
# builds a packager or user picks (gcc Release, MinSizeRel, Debug, clang
# Release), then the same suite built with
# -fsanitize=address,undefined, then the threads test (label "threads")
# built with -fsanitize=thread, then the suite under valgrind memcheck, then
# each libFuzzer target for a bounded time.  Usage: scripts/test.sh
#   DMI_BUILD_PREFIX   build directories <prefix>, <prefix>-<cc>-<type>, <prefix>-asan,
#                      <prefix>-tsan, <prefix>-fuzz (default: build)
#   DMI_FUZZ_SECONDS   fuzzing time per target (default: 60)
# Test labels: "nosan" = not run in the sanitizer build nor under valgrind
# (Python loading a sanitized .so, abidiff, resident-memory bounds),
# "slow" = not run under valgrind (valgrind makes it take many minutes).
# Tests that run an external program (compiler, Python, CMake) are not
# memchecked either.
# Every build here is configured with -DDMI_WERROR=ON: a compiler warning fails
# it (a user's build has no -Werror: test build_default_flags).
# SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
scripts/deps.sh
scripts/docs.sh --install   # the site's packages and chromium, before ctest runs docs_site
jobs=$(nproc)
py="$root/.venv/bin/python"
build=${DMI_BUILD_PREFIX:-build}
fuzz_seconds=${DMI_FUZZ_SECONDS:-60}

timings=()
stage_name=""
stage_start=$SECONDS
stage() {
  [[ -n $stage_name ]] && timings+=("$(printf '%5d s  %s' $((SECONDS - stage_start)) "$stage_name")")
  stage_name="$*"
  stage_start=$SECONDS
  printf '\n==== %s ====\n' "$*"
}

stage "build (RelWithDebInfo) and ctest"
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDMI_WERROR=ON -DPython3_EXECUTABLE="$py" \
  -DMEMORYCHECK_COMMAND_OPTIONS="--error-exitcode=1 --leak-check=full --show-leak-kinds=definite,indirect,possible --errors-for-leak-kinds=definite,indirect,possible" \
  >/dev/null
cmake --build "$build" -j "$jobs"
ctest --test-dir "$build" --output-on-failure -j "$jobs"

stage "builds: gcc Release, MinSizeRel, Debug, clang Release; core, FMU and install tests"
# The configurations packagers and users pick (other optimizers, other
# warnings: the full suite runs above), each built whole with -Werror and
# installed into a temporary prefix with a consumer built against it (the
# README's install command; install_cmake, install_pkg-config).
for config in "gcc Release" "gcc MinSizeRel" "gcc Debug" "clang Release"; do
  read -r cc type <<<"$config"
  dir="$build-$cc-${type,,}"
  echo "---- $cc $type ($dir)"
  CC=$cc cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE="$type" -DDMI_WERROR=ON \
    -DPython3_EXECUTABLE="$py" >/dev/null
  cmake --build "$dir" -j "$jobs" >"$dir/build.log" || { tail -n 40 "$dir/build.log"; exit 1; }
  ctest --test-dir "$dir" --output-on-failure --no-tests=error -j "$jobs" -R '^(core_|conv_|fmu_master|hardening_fmu|install_)'
done

stage "build with -fsanitize=address,undefined and ctest"
cmake -S . -B "$build-asan" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DDMI_SANITIZE=ON -DDMI_WERROR=ON \
  -DPython3_EXECUTABLE="$py" >/dev/null
cmake --build "$build-asan" -j "$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir "$build-asan" --output-on-failure -j "$jobs" -LE nosan

stage "build with -fsanitize=thread and the threads test"
# Only what tests/threads needs (libdmi, the FMU, the test): solvers and FMU
# instances on 8 threads.  A data race stops the test with exit code 66.
cmake -S . -B "$build-tsan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDMI_SANITIZE_THREAD=ON \
  -DDMI_WERROR=ON -DPython3_EXECUTABLE="$py" >/dev/null
cmake --build "$build-tsan" -j "$jobs" --target test_threads
TSAN_OPTIONS=halt_on_error=1:exitcode=66 ctest --test-dir "$build-tsan" --output-on-failure -L threads

stage "valgrind memcheck of the ctest suite"
# Each test runs under valgrind; an invalid access or a leak makes valgrind
# exit with 1, which fails the test.  Not memchecked: tests labelled nosan or
# slow, and tests whose command is not a program of the build tree (the
# compiler, Python, CMake: valgrind would check that tool, not our code).
external=$("$py" - "$root/$build" <<'EOF_PY'
import json, os, re, subprocess, sys
build = os.path.realpath(sys.argv[1])
out = subprocess.run(["ctest", "--show-only=json-v1"], cwd=build, capture_output=True,
                     text=True, check=True).stdout
names = [t["name"] for t in json.loads(out)["tests"]
         if not os.path.realpath((t.get("command") or [""])[0]).startswith(build + os.sep)]
print("|".join("^" + re.escape(n) + "$" for n in names))
EOF_PY
)
echo "not memchecked (external programs): ${external:-none}"
if ! ctest --test-dir "$build" -T memcheck --output-on-failure -j "$jobs" -LE 'nosan|slow' \
     ${external:+-E "$external"}; then
  for log in "$build"/Testing/Temporary/MemoryChecker.*.log; do
    grep -q "ERROR SUMMARY: [1-9]" "$log" && { echo "---- $log"; head -n 60 "$log"; }
  done
  exit 1
fi

stage "libFuzzer targets, $fuzz_seconds s each"
DMI_FUZZ_BUILD="$build-fuzz" fuzz/run.sh "$fuzz_seconds"

stage "all tests passed"
printf '%s\n' "${timings[@]}" "$(printf '%5d s  total' "$SECONDS")"
