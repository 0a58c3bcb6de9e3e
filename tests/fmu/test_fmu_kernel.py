# The FMU's kernel as a sum of exponentials: the recursion, and the
# direct sum where the recursion refuses a growing term (H_lambda < 0), give
# the outputs of a native libdmi run with the kernel as a callback (sampled,
# default method) to 1e-12.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import glob
import subprocess

import numpy as np
import pytest
from fmpy import simulate_fmu

from native import Run

OUT = ["w", "v", "friction", "delay_force", "sticking"]


@pytest.mark.parametrize("params", [
    dict(H_c0=0.4, H_c1=0.8, H_lambda=3.0),    # constant, decaying, three cosines
    dict(H_c0=0.0, H_c1=0.05, H_lambda=-0.5),  # a growing term: the direct sum
    dict(N=4001, H_a2=0.0),                    # other N, a term left out
], ids=["decaying", "growing", "N4001"])
def test_kernel_terms_match_native(fmu_path, libdmi, params):
    T, dt = 10.0, 0.01
    r = simulate_fmu(fmu_path, stop_time=T, output_interval=dt, output=OUT, start_values=params)
    native = Run(libdmi, int(T * params.get("N", 1000)) + 2, **params)
    got = np.column_stack([r[n] for n in OUT]).astype(float)
    want = native.table(r["time"])
    err = np.max(np.abs(got[:, :4] - want[:, :4]))
    assert err <= 1e-12, f"max deviation {err:.3g}"
    assert np.array_equal(got[:, 4], want[:, 4])
    assert np.max(np.abs(got[:, 3])) > 1e-3  # the delay term is not trivial


def test_binary_has_no_fft_and_no_gsl(unzipdir):
    """The FMU is built from libdmi's GSL-free core: no gsl_ symbol at all (nm),
    defined or undefined, and no FFT engine."""
    so = glob.glob(f"{unzipdir}/binaries/*/*.so")  # linux64 (FMI 2.0) or x86_64-linux (3.0)
    assert len(so) == 1
    names = subprocess.run(["nm", so[0]], capture_output=True, text=True, check=True).stdout
    assert "dmi_set_kernel_exp" in names  # (nm sees the symbol table: the check is not blind)
    assert "gsl_" not in names
    assert "dmi_conv_" not in names
