#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UBSan) and runs
# each for a bounded time, after replaying its kept regression inputs.
# Usage: fuzz/run.sh [seconds per target (default 60)] [target ...]
#   DMI_FUZZ_BUILD   build directory (default build-fuzz)
# The seed corpora in fuzz/corpus/<target>/ are copied, never modified; a crash
# is copied into fuzz/regressions/<target>/ (commit it with the fix) and the
# script fails.
# SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
seconds=${1:-60}
shift || true
build=${DMI_FUZZ_BUILD:-build-fuzz}
py="$root/.venv/bin/python"

targets=("$@")
if ((${#targets[@]} == 0)); then
  for c in fuzz/corpus/*/; do targets+=("$(basename "$c")"); done
fi

CC=clang cmake -S fuzz -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDMI_WERROR=ON \
  -DPython3_EXECUTABLE="$py" >/dev/null
cmake --build "$build" -j 2 --target fuzzers

export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# The sanitizer's error line, the top of its stack and its summary.
report() { grep -m1 -A12 -E "ERROR|runtime error|deadly signal|Running:" "$1" || tail -n 30 "$1"; grep -E "^SUMMARY" "$1" || true; }

status=0
for t in "${targets[@]}"; do
  exe="$build/fuzz_$t"
  [[ -x $exe ]] || { echo "fuzz: no target $t"; exit 2; }
  mkdir -p "fuzz/regressions/$t" "$build/artifacts/$t"
  work="$build/corpus/$t"
  rm -rf "$work" && mkdir -p "$work" && cp "fuzz/corpus/$t"/* "$work"/

  echo "fuzz: $t: replaying $(find "fuzz/regressions/$t" -type f | wc -l) regression inputs"
  regressions=(fuzz/regressions/"$t"/*)
  if [[ -e ${regressions[0]} ]] && ! "$exe" "${regressions[@]}" >"$build/artifacts/$t/replay.log" 2>&1; then
    echo "fuzz: $t: a regression input fails:"; report "$build/artifacts/$t/replay.log"
    status=1
    continue
  fi

  echo "fuzz: $t: fuzzing for $seconds s"
  if ! "$exe" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
       -artifact_prefix="$build/artifacts/$t/" "$work" >"$build/artifacts/$t/fuzz.log" 2>&1; then
    echo "fuzz: $t: crash found:"; report "$build/artifacts/$t/fuzz.log"
    for a in "$build/artifacts/$t"/crash-* "$build/artifacts/$t"/leak-* "$build/artifacts/$t"/timeout-* \
             "$build/artifacts/$t"/oom-*; do
      [[ -e $a ]] && cp "$a" "fuzz/regressions/$t/" && echo "fuzz: kept fuzz/regressions/$t/$(basename "$a")"
    done
    status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "$build/artifacts/$t/fuzz.log" | tail -n 2
  fi
done
exit $status
