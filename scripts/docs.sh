#!/usr/bin/env bash
# Builds the documentation site into <build>/docs/html (open index.html there).  Installs what it
# lacks (scripts/deps.sh; the pinned docs/requirements.txt into .venv), builds the project when
# the build folder has no FMU yet, copies docs/ into <build>/docs/src, generates there the FMU
# variable tables from the model description of every FMU the build produced
# (docs/gen/fmu_variables.py), and runs Sphinx with warnings as errors (docs/conf.py): the C API
# from the headers by hawkmoth, the Python reference by autodoc, the gallery by running every
# examples/python/plot_*.py (a failing example fails the build), the maths for MathJax, which
# the site carries.
# With --check it then installs Debian's chromium when missing and checks the site
# (tests/docs/check_site.py: the references against the header, the FMUs, dmi-sweep's parser
# and the Python packages; links and images; headless Chromium).  The ctest tests
# docs_browser_* check it further in Chromium (tests/docs/browser_check.py).
# With --install it only installs what the site and its checks need, and exits
# (scripts/test.sh runs it before ctest, so the tests docs_* install nothing).
# Usage: scripts/docs.sh [--check | --install]
# Environment: DMI_BUILD_DIR (default build).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
check=0
install_only=0
case "${1:-}" in
  "") ;;
  --check) check=1 ;;
  --install) install_only=1 ;;
  *) echo "usage: scripts/docs.sh [--check | --install]" >&2; exit 2 ;;
esac
build=${DMI_BUILD_DIR:-build}
py="$root/.venv/bin/python"

scripts/deps.sh
req=docs/requirements.txt
stamp="$root/.venv/.docs-requirements.stamp"
if [[ ! -f $stamp ]] || ! cmp -s "$req" "$stamp"; then
  echo "docs: installing the documentation's Python packages into .venv"
  "$py" -m pip install -q -r "$req"
  cp "$req" "$stamp"
fi
if ((check || install_only)) && ! command -v chromium >/dev/null; then
  echo "docs: installing chromium (Debian) for the rendering check"
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends chromium >/dev/null
fi
((install_only)) && exit 0

if [[ -z $(find "$build/fmu" -name '*.fmu' 2>/dev/null | head -n 1) ]]; then
  echo "docs: building the project in $build (the FMU reference is read from the built FMUs)"
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPython3_EXECUTABLE="$py" >/dev/null
  cmake --build "$build" -j "$(nproc)" >/dev/null
fi

build_abs=$(cd "$build" && pwd)
src="$build/docs/src"
html="$build/docs/html"
rm -rf "$src" "$html"
mkdir -p "$src"
cp -r docs/. "$src/"
mkdir -p "$src/include" && cp include/*.h "$src/include/"     # c-api.md shows the structures as declared
mapfile -t fmus < <(find "$build" -name '*.fmu' -not -path "$build/docs/*" -not -path '*/Testing/*' | sort)
((${#fmus[@]})) || { echo "docs: no FMU in $build" >&2; exit 1; }
"$py" docs/gen/fmu_variables.py "$build" "${fmus[@]}" >"$src/fmu-variables.md"

# the gallery's examples import dmi from the build and dmi_sweep from the checkout, and find the FMU
DMI_SOURCE_DIR="$root" DMI_BUILD_DIR="$build_abs" PYTHONPATH="$build_abs/python:$root/python" MPLBACKEND=Agg \
  OPENBLAS_NUM_THREADS=1 "$py" -m sphinx -W --keep-going -q -b html "$src" "$html"
echo "docs: the site is in $html/index.html"

if ((check)); then
  "$py" tests/docs/check_site.py "$root" "$build"
fi
