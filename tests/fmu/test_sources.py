# The FMU's sources/ (both FMUs): every C file it needs, listed in its model
# description (FMI 2.0 <SourceFiles>) or sources/buildDescription.xml (FMI 3.0).  Without
# its binaries/, the unpacked FMU is built by fmpy (build_platform_binary:
# CMake and the system's C compiler) and by a plain `cc -std=c99` with libc
# and libm alone; the rebuilt FMU's outputs equal the shipped binary's to 1e-12.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import re
import shutil
import subprocess

import fmpy
import numpy as np
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.build import build_platform_binary

OUT = ["w", "v", "friction", "delay_force", "sticking"]


def test_sources_rebuild_the_fmu(fmu_path, tmp_path):
    unzipdir = extract(fmu_path, str(tmp_path / "fmu"))
    sources = os.path.join(unzipdir, "sources")
    md = read_model_description(unzipdir)
    units = md.buildConfigurations[0].sourceFileSets[0].sourceFiles
    shipped = sorted(os.listdir(sources))
    # The list is every C file shipped (a tool may compile either): the model, instance layer, adapter
    # and libdmi's core, and no FFT engine.
    assert sorted(units) == sorted(n for n in shipped if n.endswith(".c"))
    assert {"model.c", "instance.c", "dmi.c", "delay.c", "exp.c", "state.c"} <= set(units)
    assert "conv.c" not in units
    for name in shipped:  # no GSL, no FMI header of our own (the importer brings those)
        assert not re.match(r"fmi[23]\w*\.h$", name), name
        if name.endswith((".c", ".h")):
            text = open(os.path.join(sources, name)).read()
            assert not re.search(r"#\s*include\s*<gsl/", text), name
    shutil.rmtree(os.path.join(unzipdir, "binaries"))

    # A C99 compiler, libc and libm: every symbol resolved (--no-undefined).
    headers = os.path.join(os.path.dirname(fmpy.__file__), "c-code")
    subprocess.run(["cc", "-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", "-shared",
                    "-fPIC", "-I", headers, "-I", sources, "-o", str(tmp_path / "plain.so")]
                   + [os.path.join(sources, u) for u in units]
                   + ["-Wl,--no-undefined", "-lm"], check=True)

    (tmp_path / "build").mkdir()
    build_platform_binary(unzipdir, build_dir=str(tmp_path / "build"))
    platform = fmpy.platform if md.fmiVersion == "2.0" else fmpy.platform_tuple
    assert os.path.isfile(os.path.join(unzipdir, "binaries", platform,
                                       md.coSimulation.modelIdentifier + fmpy.sharedLibraryExtension))
    run = dict(stop_time=30.0, output_interval=0.01, output=OUT)  # Example 4.3, N = 1000
    shipped_run = simulate_fmu(fmu_path, **run)
    rebuilt_run = simulate_fmu(unzipdir, **run)
    assert len(rebuilt_run) == len(shipped_run) == 3001
    assert np.array_equal(rebuilt_run["time"], shipped_run["time"])
    for name in OUT[:-1]:
        assert np.max(np.abs(rebuilt_run[name] - shipped_run[name])) <= 1e-12, name
    assert np.array_equal(rebuilt_run["sticking"], shipped_run["sticking"])
