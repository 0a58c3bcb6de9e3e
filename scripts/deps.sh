#!/usr/bin/env bash
# Installs what the build and the tests need and lacks, on Debian 12:
# Debian packages with apt-get, Python packages into ./.venv.
# Usage: scripts/deps.sh   (sourced by main.sh and test.sh; safe to run again)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# Debian packages (dpkg name) that the build and tests use.
# libtsan2: gcc's ThreadSanitizer runtime (the threads stage of test.sh).
# openssl: the certificates of the TLS sweep test (python/tests/test_tls.py).
# slurmctld slurmd slurm-client munge: the one-node Slurm of the SLURM sweep test
# (python/tests/test_slurm.py; started by the test itself, never as services).
debs=(build-essential cmake ninja-build pkg-config libgsl-dev libcunit1-dev gfortran
      abigail-tools clang libclang-rt-14-dev valgrind python3 python3-venv python3-pip libtsan2
      gcc-mingw-w64-x86-64 wine64 openssl slurmctld slurmd slurm-client munge)
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

# The Python package dmi (pyproject.toml: the binding, libdmi built from src/,
# and dmi-sweep), its dependencies pinned above; built without isolation with
# the pinned scikit-build-core.  Reinstalled when a file it is built from
# changes or the checkout moves.  Replaces the former distribution dmi-sweep.
pkg_stamp="$venv/.dmi.stamp"
pkg_want="$root $(cd "$root" && find pyproject.toml CMakeLists.txt cmake src include python/CMakeLists.txt \
  python/run.c python/README.md python/dmi python/dmi_sweep -type f ! -name '*.pyc' -print0 |
  sort -z | xargs -0 sha256sum | sha256sum | cut -d' ' -f1)"
if [[ ! -x $venv/bin/dmi-sweep ]] || [[ $(cat "$pkg_stamp" 2>/dev/null) != "$pkg_want" ]]; then
  echo "deps: installing the Python package dmi (binding and dmi-sweep) into .venv"
  if "$venv/bin/python" -m pip show -q dmi-sweep >/dev/null 2>&1; then
    "$venv/bin/python" -m pip uninstall -q -y dmi-sweep
  fi
  "$venv/bin/python" -m pip install -q --no-deps --no-build-isolation "$root"
  echo "$pkg_want" >"$pkg_stamp"
fi
