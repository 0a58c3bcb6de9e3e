# examples/fmu-fractional built from an installed dmi as a user would: the
# Bagley-Torvik oscillator with dry friction, its Caputo kernel
# s^-1/2 / Gamma(1/2) (singular at 0) run inside the FMU with exact cell
# weights, as the fitted exponential sum of caputo_fit.h with the near cells
# exact (the recursion, O(1) per step) and as the exact kernel by DIRECT.
# Each FMU (FMI 2.0 and 3.0, both kernels) gives at every communication point
# the state U^p and the delay term of a run of the same model by the Python
# binding (dmi.Solver, the coefficients read from caputo_fit.h, the kernel
# written here) to 1e-12; the fitted and the exact FMU agree within the fit's
# solution bound; tau beyond the fit's interval is refused with a logged
# message, and a run longer than tau warns.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import math
import os
import re

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

import dmi
from conftest import Instance, build, fmus

NAME = "FractionalOscillator"
# the model's start values (bagley.c)
C_DAMP, K, MU, F, OMEGA, W0, TAU = 0.5, 1.0, 0.2, 0.6, 1.0, 1.0, 10.0
COMM, STEPS = 0.05, 100  # communication steps: to t = 5


@pytest.fixture(scope="module")
def fractional(prefix, source_dir, tmp_path_factory):
    b = tmp_path_factory.mktemp("fractional")
    build(os.path.join(source_dir, "examples", "fmu-fractional"), b, prefix)
    return fmus(b, NAME)


@pytest.fixture(scope="module")
def caputo(source_dir):
    """The arrays of caputo_fit.h: name -> values, and its DELTA."""
    text = open(os.path.join(source_dir, "examples", "fmu-fractional", "caputo_fit.h")).read()
    arrays = {m.group(1): np.array([float(x) for x in m.group(2).replace("\n", " ").split(",")])
              for m in re.finditer(r"caputo_(\w)\[\d+\] = \{([^}]*)\}", text)}
    delta = float(re.search(r"#define CAPUTO_DELTA (\S+)", text).group(1))
    assert len(arrays["a"]) == int(re.search(r"caputo_K = (\d+)", text).group(1)) > 10
    return arrays, delta


def kernel(s):
    out = np.zeros((2, 2))
    out[1, 1] = C_DAMP / math.sqrt(math.pi * s)
    return out


def python_run(N, exact, caputo, steps):
    """(U^p, W^{p-1}) at p = 1..steps of dmi.Solver with the FMU's model."""
    s = dmi.Solver(2, TAU, N)
    s.set_rhs(lambda t, u: np.array([-u[1], K * u[0] - F * math.cos(OMEGA * t)]))
    s.set_friction([0.0, MU])
    s.set_history(lambda t: np.array([W0, 0.0]))
    s.set_quadrature("cell")
    if exact:
        s.set_kernel(kernel)
        s.set_convolution("direct")
    else:
        arrays, delta = caputo
        Cm, Dm = np.zeros((len(arrays["a"]), 2, 2)), np.zeros((len(arrays["a"]), 2, 2))
        Cm[:, 1, 1], Dm[:, 1, 1] = C_DAMP * arrays["C"], C_DAMP * arrays["D"]
        s.set_kernel_exp(arrays["a"], arrays["b"], Cm, Dm)
        s.set_kernel_near(kernel, delta)
    s.init()
    U, W = [], []
    for _ in range(steps):
        s.step()
        U.append(s.state)
        W.append(s.step_terms()[0])
    return np.array(U), np.array(W)


def fmu_run(path, N, exact, count):
    """(w, v, damping) after each of count communication steps of COMM."""
    inst = Instance(path)
    inst.set("N", N)
    if exact:
        inst.fmu.setBoolean([inst.vr["exact"]], [True])
    inst.start(count * COMM)
    rows = []
    for k in range(count):
        inst.fmu.doStep(k * COMM, COMM)
        rows.append(inst.get(["w", "v", "damping"]))
    inst.free()
    return np.array(rows)


@pytest.mark.parametrize("exact", [False, True], ids=["fitted", "exact"])
@pytest.mark.parametrize("version", ["2", "3"])
def test_fmu_equals_python(fractional, caputo, version, exact):
    N = 1000  # h = 0.01: 5 solver steps per communication step
    got = fmu_run(fractional[version], N, exact, STEPS)
    U, W = python_run(N, exact, caputo, 5 * STEPS)
    want = np.column_stack([U[4::5], W[4::5, 1]])
    err = np.max(np.abs(got - want))
    assert err <= 1e-12, f"max deviation {err:.3g}"
    assert np.max(np.abs(want[:, 2])) > 0.1  # the fractional damping is not trivial


def test_fitted_within_the_bound_of_exact(fractional):
    """The fitted kernel against the exact one, both FMUs, at N = 2000 to t = 2: within the
    scheme's solution bound eps u_max ((1 + h Gamma)^n - 1) / Gamma (docs/kernels.md), eps the
    fit's L1 error on [delta, tau] (1e-8 relative of the kernel's L1 norm bounds it), Gamma the
    Lipschitz constant of f (max(1, k)) plus c times the kernel's L1 norm 2 sqrt(tau / pi)."""
    N, h, count = 2000, TAU / 2000, 40
    fitted = fmu_run(fractional["2"], N, False, count)
    exact = fmu_run(fractional["2"], N, True, count)
    l1 = C_DAMP * 2 * math.sqrt(TAU / math.pi)
    eps, gamma = 1e-8 * l1, max(1.0, K) + l1
    u_max = np.max(np.abs(fitted[:, :2]))
    bound = eps * u_max * math.expm1((count * COMM / h) * math.log1p(h * gamma)) / gamma
    err = np.max(np.abs(fitted[:, :2] - exact[:, :2]))
    assert err <= bound, (err, bound)
    assert bound < 1e-5  # informative


@pytest.mark.parametrize("version", ["2", "3"])
def test_tau_beyond_the_fit_refused(fractional, version):
    inst = Instance(fractional[version])
    with pytest.raises(FMICallException):
        inst.set("tau", 10.5)
    assert any("tau = 10.5 exceeds the fitted kernel's 10 s" in m for _, _, m in inst.log), inst.log
    inst.set("tau", 2.0)  # accepted; a run of 5 s is longer than the memory: a warning
    inst.set("N", 200)
    inst.start(5.0)
    assert any("longer than the memory tau = 2" in m for _, _, m in inst.log), inst.log
    inst.fmu.doStep(0.0, 0.5)
    assert np.all(np.isfinite(inst.get(["w", "v"])))
    inst.free()
