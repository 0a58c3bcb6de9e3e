#!/usr/bin/env python3
# Checks that the public API is the same in the header, the linker version
# script, the libraries and (optionally) the Fortran binding.
#   check_symbols.py library HEADER MAP LIBSHARED LIBSTATIC
#       the functions declared DMI_API in HEADER = the global symbols of MAP
#       = the defined dynamic symbols of LIBSHARED, each with the version of
#       its MAP node; SONAME libdmi.so.<major>; LIBSTATIC defines only dmi_*
#       global symbols; the enum constants keep their released values.
#   check_symbols.py fortran HEADER MODULE_SOURCE
#       every DMI_API function has an interface bound to it (bind(C, name=...))
#       and a public Fortran procedure of the same name in MODULE_SOURCE, and
#       every DMI_* constant of HEADER is a parameter of the same value there.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import re
import subprocess
import sys

failures = []

# The enum constants of the released ABI (soname libdmi.so.1): a program compiled
# with them must keep working, so a value never changes within a soname.
# New constants may be added (and then listed here when released).
RELEASED_CONSTANTS = {
    "DMI_OK": 0, "DMI_EINVAL": -1, "DMI_ENOMEM": -2, "DMI_ECALLBACK": -3,
    "DMI_ENONFINITE": -4, "DMI_ESTATE": -5,
    "DMI_CONV_AUTO": 0, "DMI_CONV_DIRECT": 1, "DMI_CONV_FFT": 2,
    "DMI_CONV_RECURSIVE": 3,  # libdmi 1.1
    "DMI_QUAD_LEFT": 0, "DMI_QUAD_CELL": 1,  # libdmi 1.3
}


def check(ok, message):
    if not ok:
        failures.append(message)


def header_functions(path):
    """Names of the functions declared with DMI_API."""
    text = open(path, encoding="utf-8").read()
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    names = re.findall(r"^\s*DMI_API\b[^;(]*?\b(\w+)\s*\(", text, flags=re.M)
    check(len(names) == len(set(names)), f"{path}: a function is declared twice: {names}")
    check(names, f"{path}: no DMI_API function found")
    return set(names)


def header_constants(path):
    """{name: value} of the DMI_* enumerators and #defines with integer values."""
    text = open(path, encoding="utf-8").read()
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    found = re.findall(r"^\s*(DMI_\w+)\s*=\s*(-?\d+)\s*,?\s*$", text, flags=re.M)
    found += re.findall(r"^\s*#\s*define\s+(DMI_\w+)\s+(-?\d+)\s*$", text, flags=re.M)
    return {name: int(value) for name, value in found}


def version_nodes(path):
    """[(node, inherited node or None, [global symbols])] of a version script."""
    text = open(path, encoding="utf-8").read()
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    nodes = []
    for name, body, parent in re.findall(r"([\w.]+)\s*\{(.*?)\}\s*([\w.]*)\s*;", text, flags=re.S):
        globs = []
        section = "global"
        for item in re.split(r"[;\s]+", body):
            if item in ("global:", "local:"):
                section = item[:-1]
            elif item and section == "global":
                globs.append(item)
        nodes.append((name, parent or None, globs))
    return nodes


def dynamic_symbols(lib):
    """{name: version} of the defined dynamic symbols (version nodes excluded)."""
    out = subprocess.run(["readelf", "--dyn-syms", "--wide", lib], check=True,
                         capture_output=True, text=True).stdout
    syms = {}
    for line in out.splitlines():
        f = line.split()
        if len(f) < 8 or not f[0][:-1].isdigit() or f[6] == "UND":
            continue
        name, _, version = f[7].partition("@")
        version = version.lstrip("@")
        if f[6] == "ABS" and f[3] == "OBJECT" and not version and re.fullmatch(r"[\w.]+", name):
            continue  # the definition of a version node (e.g. DMI_1.0)
        syms[name] = version
    return syms


def check_library(header, mapfile, shared, static):
    api = header_functions(header)
    constants = header_constants(header)
    for name, value in RELEASED_CONSTANTS.items():
        check(constants.get(name) == value,
              f"{header}: {name} is {constants.get(name)}, released as {value}")
    major = constants.get("DMI_VERSION_MAJOR")
    nodes = version_nodes(mapfile)
    check(nodes and nodes[0][0] == f"DMI_{major}.0" and nodes[0][1] is None,
          f"{mapfile}: the first node must be DMI_{major}.0 (inheriting nothing)")
    node_of = {}
    for i, (name, parent, globs) in enumerate(nodes):
        check(re.fullmatch(rf"DMI_{major}\.\d+", name), f"{mapfile}: node {name} is not DMI_{major}.<minor>")
        if i > 0:
            check(parent == nodes[i - 1][0], f"{mapfile}: node {name} must inherit {nodes[i - 1][0]}")
        for g in globs:
            check("*" not in g and "?" not in g, f"{mapfile}: wildcard {g} in {name}")
            check(g not in node_of, f"{mapfile}: {g} is listed twice")
            node_of[g] = name
    check(set(node_of) == api,
          f"version script vs header: only in the script {sorted(set(node_of) - api)}, "
          f"only in the header {sorted(api - set(node_of))}")

    syms = dynamic_symbols(shared)
    check(set(syms) == api,
          f"{shared} vs header: only exported {sorted(set(syms) - api)}, "
          f"not exported {sorted(api - set(syms))}")
    for name, version in sorted(syms.items()):
        check(name.startswith("dmi_"), f"{shared}: exports {name}, not a dmi_ name")
        check(version == node_of.get(name), f"{shared}: {name} has version '{version}', "
              f"the script says '{node_of.get(name)}'")

    dyn = subprocess.run(["readelf", "-d", shared], check=True, capture_output=True, text=True).stdout
    soname = re.search(r"\(SONAME\).*\[(.*)\]", dyn)
    check(soname and soname.group(1) == f"libdmi.so.{major}",
          f"{shared}: SONAME {soname and soname.group(1)} is not libdmi.so.<DMI_VERSION_MAJOR>")

    out = subprocess.run(["nm", "--defined-only", "--extern-only", static], check=True,
                         capture_output=True, text=True).stdout
    defined = set(f[2] for f in map(str.split, out.splitlines()) if len(f) == 3)
    for name in sorted(defined):
        check(name.startswith("dmi_"), f"{static}: defines the global symbol {name}, not dmi_*")
    check(api <= defined, f"{static}: does not define {sorted(api - defined)}")


def check_fortran(header, module):
    api = header_functions(header)
    text = open(module, encoding="utf-8").read()
    text = re.sub(r"!.*", "", text)
    bound = set(re.findall(r"bind\s*\(\s*C\s*,\s*name\s*=\s*['\"](\w+)['\"]", text, flags=re.I))
    procedures = set(n.lower() for n in re.findall(r"^\s*(?:function|subroutine)\s+(\w+)", text,
                                                   flags=re.M | re.I))
    public = set(n.lower() for line in re.findall(r"^\s*public\s*::(.*)$", text, flags=re.M | re.I)
                 for n in re.findall(r"\w+", line))
    for name in sorted(api):
        check(name in bound, f"{module}: no interface bound to the C function {name}")
        check(name.lower() in procedures and name.lower() in public,  # (Fortran ignores case)
              f"{module}: no public Fortran procedure named {name}")
    parameters = {}  # name: (value, public)
    for attrs, name, value in re.findall(r"^\s*integer\b(.*\bparameter\b.*)::\s*(DMI_\w+)\s*=\s*(-?\d+)",
                                         text, flags=re.I | re.M):
        parameters[name.upper()] = (int(value), bool(re.search(r"\bpublic\b", attrs, flags=re.I))
                                    or name.lower() in public)
    constants = header_constants(header)
    check(constants, f"{header}: no DMI_* constant found")
    for name, value in sorted(constants.items()):
        check(parameters.get(name) == (value, True),
              f"{module}: public parameter {name} = {value} expected, found {parameters.get(name)}")


def main(argv):
    if len(argv) == 6 and argv[1] == "library":
        check_library(*argv[2:])
    elif len(argv) == 4 and argv[1] == "fortran":
        check_fortran(*argv[2:])
    else:
        sys.exit("usage: check_symbols.py library HEADER MAP LIBSHARED LIBSTATIC\n"
                 "       check_symbols.py fortran HEADER MODULE_SOURCE")
    for f in failures:
        print("FAIL:", f)
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
