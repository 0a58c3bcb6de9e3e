#!/usr/bin/env bash
# Installs what the build and the tests need and lacks, on Debian 12:
# Debian packages with apt-get, Python packages into ./.venv.
# Usage: scripts/deps.sh   (sourced by main.sh and test.sh; safe to run again)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# Debian packages (dpkg name) that the build and tests use.
# libtsan2: gcc's ThreadSanitizer runtime (the threads stage of test.sh).
debs=(build-essential cmake ninja-build pkg-config libgsl-dev libcunit1-dev gfortran
      abigail-tools clang libclang-rt-14-dev valgrind python3 python3-venv python3-pip libtsan2
      gcc-mingw-w64-x86-64 wine64)
missing=()
for d in "${debs[@]}"; do
  dpkg-query -W -f='${Status}' "$d" 2>/dev/null | grep -q "install ok installed" || missing+=("$d")
done
if ((${#missing[@]})); then
  echo "deps: installing Debian packages: ${missing[*]}"
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Python packages, pinned, in the project's virtual environment.
venv="$root/.venv"
req="$root/scripts/requirements.txt"
stamp="$venv/.requirements.stamp"
if [[ ! -x $venv/bin/python ]]; then
  python3 -m venv "$venv"
fi
if [[ ! -f $stamp ]] || ! cmp -s "$req" "$stamp"; then
  echo "deps: installing Python packages into .venv"
  "$venv/bin/python" -m pip install -q --upgrade pip
  "$venv/bin/python" -m pip install -q -r "$req"
  cp "$req" "$stamp"
fi

# dmi-sweep (python/), editable, its dependencies pinned above: reinstalled when
# python/pyproject.toml changes or the checkout moves.
sweep_stamp="$venv/.dmi-sweep.stamp"
sweep_want="$root $(sha256sum "$root/python/pyproject.toml" | cut -d' ' -f1)"
if [[ ! -x $venv/bin/dmi-sweep ]] || [[ $(cat "$sweep_stamp" 2>/dev/null) != "$sweep_want" ]]; then
  echo "deps: installing dmi-sweep (python/) into .venv"
  "$venv/bin/python" -m pip install -q --no-deps -e "$root/python"
  echo "$sweep_want" >"$sweep_stamp"
fi
