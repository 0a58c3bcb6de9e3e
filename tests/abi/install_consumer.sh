#!/usr/bin/env bash
# Installs a build tree into a temporary prefix and builds and runs the
# consumer programs (tests/abi/consumer) from a copy outside the source tree,
# as a user of the installed package would.
#   install_consumer.sh cmake|pkg-config BUILD_DIR LIBDIR INCLUDEDIR [fortran] [FILE...]
# cmake: a CMake project with find_package(dmi) (shared, static and, with
# "fortran", the Fortran module); pkg-config: the compilers with the flags of
# dmi.pc (and dmi-fortran.pc), whose libdir and includedir must be exactly
# <prefix>/LIBDIR and <prefix>/INCLUDEDIR, the prefix given to cmake --install
# (given with a trailing slash, which the .pc files drop), and follow the tree
# when it is moved (pkg-config --define-prefix).  LIBDIR and INCLUDEDIR are the build's
# CMAKE_INSTALL_LIBDIR and CMAKE_INSTALL_INCLUDEDIR (relative to the prefix).
# FILEs (relative to the prefix) must be installed too (e.g. the FMU).
# CC and FC name the compilers.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
set -euo pipefail
mode=$1
build=$(cd "$2" && pwd)
lib=$3
inc=$4
shift 4
fortran=
if [[ ${1:-} == fortran ]]; then fortran=1; shift; fi
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/dmi-install.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
cd "$work" # (gfortran writes module files into the current folder)

given=$prefix
[[ $mode != pkg-config ]] || given=$prefix/ # the .pc files must still say <prefix>/lib
cmake --install "$build" --prefix "$given" >/dev/null
cp -r "$here/consumer" "$work/src"
for f in "$inc/dmi.h" "$lib/libdmi.so.1" "$lib/libdmi.a" "$lib/cmake/dmi/dmiConfig.cmake" \
         "$lib/cmake/dmi/dmiConfigVersion.cmake" "$lib/pkgconfig/dmi.pc" "$@"; do
  [[ -e $prefix/$f ]] || { echo "not installed: $f"; exit 1; }
done
if [[ $fortran ]]; then
  for f in "$inc/dmi.mod" "$lib/libdmi_fortran.a" "$lib/pkgconfig/dmi-fortran.pc"; do
    [[ -e $prefix/$f ]] || { echo "not installed: $f"; exit 1; }
  done
fi

# Runs a consumer program; a dynamically linked one must load the installed libdmi.so.1.
run() {
  local exe=$1 loaded
  loaded=$(ldd "$exe" | awk '$1 == "libdmi.so.1" { print $3 }')
  if [[ $2 == shared && $(realpath -m "$loaded") != $(realpath "$prefix/$lib/libdmi.so.1") ]]; then
    echo "$exe loads libdmi.so.1 from '$loaded', not from the installed prefix"; exit 1
  fi
  if [[ $2 == static && -n $loaded ]]; then
    echo "$exe should not need libdmi.so.1 (static link), loads $loaded"; exit 1
  fi
  "$exe"
}

case $mode in
cmake)
  cmake -S "$work/src" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" \
        -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DWITH_FORTRAN="${fortran:+ON}" >/dev/null
  cmake --build "$work/build" >/dev/null
  run "$work/build/consumer" shared
  run "$work/build/consumer_static" static
  [[ -z $fortran ]] || run "$work/build/consumer_fortran" shared
  ;;
pkg-config)
  export PKG_CONFIG_PATH=$prefix/$lib/pkgconfig
  # Exact strings: "$prefix/lib", not "$prefix/lib/pkgconfig/../..//lib".
  expect() { # expect PACKAGE VARIABLE VALUE [pkg-config option]
    local got
    got=$(pkg-config ${4:-} --variable="$2" "$1")
    [[ $got == "$3" ]] || { echo "$1.pc${4:+ ($4)}: $2 is '$got', expected '$3'"; exit 1; }
  }
  for pc in dmi ${fortran:+dmi-fortran}; do
    expect $pc libdir "$prefix/$lib"
    expect $pc includedir "$prefix/$inc"
  done
  libdir=$(pkg-config --variable=libdir dmi)
  # shellcheck disable=SC2046  # the flags are lists of words
  "${CC:-cc}" "$work/src/consumer.c" -o "$work/consumer" $(pkg-config --cflags --libs dmi) -lm \
      -Wl,-rpath,"$libdir"
  run "$work/consumer" shared
  # Static: libdmi.a and the private dependencies (Requires.private: gsl).
  static_libs=$(pkg-config --static --libs dmi | tr ' ' '\n' | grep -vx -- '-ldmi' | tr '\n' ' ')
  # shellcheck disable=SC2046,SC2086
  "${CC:-cc}" "$work/src/consumer.c" -o "$work/consumer_static" $(pkg-config --cflags dmi) \
      "$libdir/libdmi.a" $static_libs
  run "$work/consumer_static" static
  if [[ $fortran ]]; then
    # shellcheck disable=SC2046
    "${FC:-gfortran}" "$work/src/consumer.f90" -o "$work/consumer_fortran" \
        $(pkg-config --cflags --libs dmi-fortran) -Wl,-rpath,"$libdir"
    run "$work/consumer_fortran" shared
  fi
  # A tree moved after installing: pkg-config --define-prefix finds it.
  mv "$prefix" "$work/moved"
  export PKG_CONFIG_PATH=$work/moved/$lib/pkgconfig
  for pc in dmi ${fortran:+dmi-fortran}; do
    expect $pc libdir "$work/moved/$lib" --define-prefix
    expect $pc includedir "$work/moved/$inc" --define-prefix
  done
  ;;
*)
  echo "usage: install_consumer.sh cmake|pkg-config BUILD_DIR LIBDIR INCLUDEDIR [fortran] [FILE...]"
  exit 2 ;;
esac
echo "installed package works ($mode)"
