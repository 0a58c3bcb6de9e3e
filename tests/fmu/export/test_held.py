# Built-in indicators declared with dmi_fmu_model's held (libdmi takes them from each step) in
# a model built from an installed dmi, here with dmi_set_box's contact (the oscillator FMU has
# friction's): x'' + x = a cos(w t) with x kept in [-0.5, 0.5], u = (x, v), the box on x.  The
# events the FMUs count (an output from pt->nevents and pt->event_p), without and with early
# return, are the steps at which dmi_fmu_contact's value, computed here from a native run's X
# (dmi.Solver.step_terms), changes; a model whose solver has no box refuses
# ExitInitializationMode with a logged reason.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import math

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

import dmi
from conftest import Instance, built_fmus

MODEL = r"""#include "dmi_fmu.h"
#include <math.h>
#define VARS(X)                                                                  \
    X(tau, Float64, parameter, 1.0, "s", "delay")                                \
    X(N, Int32, parameter, 100, "", "steps per tau")                             \
    X(a, Float64, parameter, 1.0, "", "forcing amplitude")                       \
    X(w, Float64, parameter, 1.3, "", "forcing frequency")                       \
    X(nobox, Boolean, parameter, 0, "", "configure no box (refused)")            \
    X(x, Float64, output, , "", "position")                                      \
    X(events, Int32, output, , "", "contact changes so far")                     \
    X(last_event_time, Float64, output, , "", "the last one's time")
enum { VARS(DMI_FMU_VR) NVARS };
static const dmi_fmu_variable TABLE[] = {VARS(DMI_FMU_VARIABLE)};
static int rhs(double t, const double *u, double *out, void *user)
{
    const dmi_fmu_values *m = user;
    out[0] = -u[1];
    out[1] = u[0] - m->value[VR_a] * cos(m->value[VR_w] * (m->t_start + t));
    return 0;
}
static int configure(const dmi_fmu_values *m, dmi_solver *s, char *err)
{
    const double lo[2] = {-0.5, -INFINITY}, hi[2] = {0.5, INFINITY};
    (void)err;
    int rc = dmi_set_rhs(s, rhs, (void *)m);
    return rc || m->value[VR_nobox] ? rc : dmi_set_box(s, lo, hi);
}
static void outputs(const dmi_fmu_values *m, const dmi_fmu_point *pt, double *out)
{
    out[VR_x] = pt->u ? pt->u[0] : 0.0;
    out[VR_events] = (double)pt->nevents;
    out[VR_last_event_time] = m->t_start + (double)pt->event_p * pt->h;
}
static const size_t HELD[1] = {0};
const dmi_fmu_model DMI_FMU_MODEL = {"x'' + x = a cos w t, x in a box", TABLE, NVARS, 2,
                                     VR_tau, VR_N, 20.0, 0.1, configure, outputs, NULL, NULL,
                                     NULL, NULL, 1, NULL, NULL, HELD};
"""
T, H, LO, HI = 20.0, 0.01, -0.5, 0.5


@pytest.fixture(scope="module")
def held(prefix, tmp_path_factory):
    return built_fmus(tmp_path_factory, prefix, "Held", MODEL)


@pytest.fixture(scope="module")
def native():
    """The steps p at which dmi_fmu_contact(X^p) changes in the same scheme run natively
    (contact(0) from U^0 = 0: inside)."""
    s = dmi.Solver(2, 1.0, 100)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0] - 1.0 * math.cos(1.3 * t)]))
    s.set_box([LO, -math.inf], [HI, math.inf])
    s.init()
    contact, events = 0, []
    for p in range(1, round(T / H) + 1):
        s.step()
        x = s.step_terms()[1][0]
        now = -1 if x <= LO else 1 if x >= HI else 0
        if now != contact:
            events.append(p)
        contact = now
    s.close()
    assert len(events) >= 6  # the mass hits both faces again and again
    return events


@pytest.mark.parametrize("version", ["2", "3"])
def test_counts_are_the_contact_changes(held, native, version):
    r = simulate_fmu(held[version], stop_time=T, output_interval=0.1,
                     output=["events", "last_event_time"])
    t = r["time"]
    count = np.array([sum(1 for p in native if p * H <= x + 1e-9 * H) for x in t])
    assert np.array_equal(r["events"], count)
    last = np.array([max([p for p in native if p * H <= x + 1e-9 * H], default=0) * H for x in t])
    assert np.max(np.abs(r["last_event_time"] - last)) <= 1e-12


def test_early_return_at_each_change(held, native):
    """FMI 3.0 with early return: a row at every change that is not on the 0.1 grid."""
    r = simulate_fmu(held["3"], stop_time=T, output_interval=0.1, early_return_allowed=True,
                     output=["events"])
    grid = {round(k * 0.1 / H) for k in range(round(T / 0.1) + 1)}
    steps = {round(x / H) for x in r["time"]}
    off = [p for p in native if p not in grid]
    assert off and all(p in steps for p in off), (off, sorted(steps - grid))
    assert r["events"][-1] == len(native)


@pytest.mark.parametrize("version", ["2", "3"])
def test_no_box_refused(held, version):
    inst = Instance(held[version])
    (inst.fmu.setBoolean)([inst.vr["nobox"]], [True])
    with pytest.raises(FMICallException):
        inst.start()
    assert any("the model's built-in indicators (held)" in m and "dmi_set_box" in m
               for _, _, m in inst.log), inst.log
    inst.free()
