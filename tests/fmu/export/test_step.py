# A model that gives its step h (dmi_fmu_model's step): a forced
# dry-friction oscillator with an exponential memory kernel whose h is a
# whole fraction of the forcing period, h = period / N with period =
# 2 pi / omega, so that tau / h is not an integer (tau = 1, omega = 1.3,
# N = 50: tau / h = 10.35, libdmi's N = 11 cells, the last partial).  Its
# FMUs (both FMI versions) run through fmpy give U^p bitwise equal to
# dmi.Solver(2, tau, h=h) in Python with the same model at the same steps p
# (t_p = p h, p = ceil(t / h)); an FMU state
# restores bitwise; a step that is 0, < 0, NaN, subnormal or too small for
# memory refuses ExitInitializationMode with a logged error, no crash.
# Model: u = (w, v), u' + A u + f(t, u) + int_0^tau H(s) u(t - s) ds ∋ 0,
# f = (-v, b w + g cos(omega t)), A = {0} x alpha sigma, H = [[0, 0], [c
# exp(-lam s), 0]], u = (w0, 0) on [-tau, 0].
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import math

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

import dmi
from conftest import Instance, build, fmus, write_project

MODEL = r"""#include <math.h>
#include "dmi_fmu.h"
#define VARS(X)                                                                  \
    X(tau, Float64, parameter, 1.0, "s", "delay")                                \
    X(N, Int32, parameter, 50, "", "steps per forcing period")                   \
    X(omega, Float64, parameter, 1.3, "1/s", "forcing frequency")                \
    X(period, Float64, parameter, 4.83321946706122, "s", "h = period / N")     \
    X(nan_step, Boolean, parameter, 0, "", "the step is NaN (a broken model)")   \
    X(w, Float64, output, , "m", "U^p_0")                                        \
    X(v, Float64, output, , "m/s", "U^p_1")                                      \
    X(steps, Int32, output, , "", "p")
enum { VARS(DMI_FMU_VR) NVARS };
static const dmi_fmu_variable TABLE[] = {VARS(DMI_FMU_VARIABLE)};
static int rhs(double t, const double *u, double *out, void *user)
{
    const dmi_fmu_values *m = user;
    out[0] = -u[1];
    out[1] = 1.5 * u[0] + 0.9 * cos(m->value[VR_omega] * t);
    return 0;
}
static int history(double t, double *out, void *user)
{
    (void)t, (void)user;
    out[0] = 0.2;
    out[1] = 0.0;
    return 0;
}
static int configure(const dmi_fmu_values *m, dmi_solver *s, char *err)
{
    const double alpha[2] = {0.0, 0.4}, a[1] = {-2.0}, b[1] = {0.0}, C[4] = {0, 0, 0.5, 0};
    (void)err;
    int rc = dmi_set_rhs(s, rhs, (void *)m);
    if (!rc)
        rc = dmi_set_friction(s, alpha);
    if (!rc)
        rc = dmi_set_kernel_exp(s, 1, a, b, C, NULL);
    return rc ? rc : dmi_set_history(s, history, NULL);
}
static void outputs(const dmi_fmu_values *m, const dmi_fmu_point *pt, double *out)
{
    (void)m;
    out[VR_w] = pt->U ? pt->U[0] : 0.2;
    out[VR_v] = pt->U ? pt->U[1] : 0.0;
    out[VR_steps] = (double)pt->p;
}
static double step(const dmi_fmu_values *m)
{
    return m->value[VR_nan_step] ? NAN : m->value[VR_period] / m->value[VR_N];
}
const dmi_fmu_model DMI_FMU_MODEL = {
    .description = "a forced oscillator with h = period / N", .variables = TABLE,
    .nvariables = NVARS, .n = 2, .tau = VR_tau, .N = VR_N, .stop_time = 10.0,
    .step_size = 0.1, .configure = configure, .outputs = outputs, .step = step,
};
"""

TAU, N_PERIOD, OMEGA = 1.0, 50, 1.3
PERIOD = 4.83321946706122  # the model's start value: 2 pi / 1.3


@pytest.fixture(scope="module")
def stepped(prefix, tmp_path_factory):
    src = write_project(tmp_path_factory.mktemp("step"), "Stepped", MODEL)
    build(src, src / "build", prefix)
    return fmus(src / "build", "Stepped")


def python_run(h, steps):
    """U^1..U^steps of dmi.Solver(2, tau, h=h) with the FMU's model."""
    s = dmi.Solver(2, TAU, h=h)
    s.set_rhs(lambda t, u: np.array([-u[1], 1.5 * u[0] + 0.9 * math.cos(OMEGA * t)]))
    s.set_friction([0.0, 0.4])
    s.set_kernel_exp([-2.0], [0.0], [[[0.0, 0.0], [0.5, 0.0]]])
    s.set_history(lambda t: np.array([0.2, 0.0]))
    s.init()
    rows = []
    for _ in range(steps):
        s.step()
        rows.append(s.state)
    return np.array(rows), s.N


def fmu_rows(inst, t0, comm, count):
    """(p, w, v) after each of count communication steps of comm from t0."""
    out, t = [], t0
    for _ in range(count):
        inst.fmu.doStep(t, comm)
        t += comm
        p = (inst.fmu.getInt32 if inst.v3 else inst.fmu.getInteger)([inst.vr["steps"]])[0]
        out.append((p, *inst.get(["w", "v"])))
    return out, t


def test_period_is_the_start_value():
    assert PERIOD == 2 * math.pi / OMEGA


@pytest.mark.parametrize("version", ["2", "3"])
def test_step_model_equals_python(stepped, version):
    h = PERIOD / N_PERIOD
    assert TAU / h != round(TAU / h)  # a partial last cell
    inst = Instance(stepped[version])
    inst.start()
    rows, t = fmu_rows(inst, 0.0, 0.25, 40)  # t = 10: p = ceil(10 / h) = 104 steps
    want, N = python_run(h, rows[-1][0])
    assert N == math.ceil(TAU / h) == 11
    for k, (p, w, v) in enumerate(rows):
        assert p == math.ceil((k + 1) * 0.25 / h - 1e-6)
        assert (w, v) == tuple(want[p - 1]), (k, p)
    # a state restores bitwise: run on, restore, run on again
    data = inst.save()
    more, _ = fmu_rows(inst, t, 0.25, 8)
    inst.restore(data)
    again, _ = fmu_rows(inst, t, 0.25, 8)
    assert more == again
    inst.free()


@pytest.mark.parametrize("version", ["2", "3"])
@pytest.mark.parametrize("name, value, says", [
    ("period", 0.0, "the model's step h = 0 must be finite and > 0"),
    ("period", -1.0, "the model's step h = -0.02 must be finite and > 0"),
    ("nan_step", True, "the model's step h = nan must be finite and > 0"),
    ("period", 1e-310, "creating the solver (tau = 1, h = 2.0000000000018713e-312): "),
    ("period", 1e-300, "creating the solver: out of memory: tau = 1, h = 1.9999999999999999e-302"),
])
def test_bad_step(stepped, version, name, value, says):
    inst = Instance(stepped[version])
    if isinstance(value, bool):
        inst.fmu.setBoolean([inst.vr[name]], [value])
    else:
        inst.set(name, value)
    with pytest.raises(FMICallException):
        inst.start()
    errors = [m for st, c, m in inst.log if st == 3]
    assert errors and says in errors[-1], inst.log
    inst.free()
