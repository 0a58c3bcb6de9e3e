# A model's accept that compares two variables, through an FMU state: the
# inputs lo <= hi (start 0 and 1).  An instance that set hi = 10, then lo = 5,
# saves a state; a fresh instance (lo = 0, hi = 1) restores it.  The state's
# values were accepted together, so the restore must not check lo = 5 against
# the fresh instance's hi = 1 (it did: the framework stored and checked the
# values one by one).  After the restore the model's values are the state's:
# lo = 7 is accepted (hi = 10), lo = 11 refused.  Both FMI versions.
# Model: u' + u = 0, u = 1 on [-tau, 0]; w = u + lo + hi.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import pytest
from fmpy.fmi1 import FMICallException

from conftest import HISTORY_ONE, Instance, built_fmus

MODEL = r"""#include <stdio.h>
#include "dmi_fmu.h"
#define VARS(X)                                                                  \
    X(tau, Float64, parameter, 1.0, "s", "delay")                                \
    X(N, Int32, parameter, 10, "", "steps per tau")                              \
    X(lo, Float64, input, 0.0, "", "lower bound, <= hi")                         \
    X(hi, Float64, input, 1.0, "", "upper bound, >= lo")                         \
    X(w, Float64, output, , "", "u + lo + hi")
enum { VARS(DMI_FMU_VR) NVARS };
static const dmi_fmu_variable TABLE[] = {VARS(DMI_FMU_VARIABLE)};
static int rhs(double t, const double *u, double *out, void *user)
{
    (void)t, (void)user;
    out[0] = u[0];
    return 0;
}
""" + HISTORY_ONE + r"""static int configure(const dmi_fmu_values *m, dmi_solver *s, char *err)
{
    (void)m, (void)err;
    int rc = dmi_set_rhs(s, rhs, NULL);
    return rc ? rc : dmi_set_history(s, one, NULL);
}
static void outputs(const dmi_fmu_values *m, const dmi_fmu_point *pt, double *out)
{
    out[VR_w] = (pt->u ? pt->u[0] : 1.0) + m->value[VR_lo] + m->value[VR_hi];
}
static int accept(const dmi_fmu_values *m, unsigned vr, double value, char *err)
{
    if ((vr == VR_lo && value > m->value[VR_hi]) || (vr == VR_hi && value < m->value[VR_lo])) {
        snprintf(err, DMI_FMU_ERRLEN, "%s = %g: lo must be <= hi", TABLE[vr].name, value);
        return -1;
    }
    return 0;
}
const dmi_fmu_model DMI_FMU_MODEL = {"u' + u = 0", TABLE, NVARS, 1, VR_tau, VR_N, 1.0, 0.1,
                                     configure, outputs, accept, NULL, NULL, NULL};
"""


@pytest.fixture(scope="module")
def pair(prefix, tmp_path_factory):
    return built_fmus(tmp_path_factory, prefix, "Pair", MODEL)


@pytest.mark.parametrize("version", ["2", "3"])
def test_state_checked_as_a_whole(pair, version):
    a = Instance(pair[version], "a")
    with pytest.raises(FMICallException):  # lo = 5 > hi = 1: the model refuses it
        a.set("lo", 5.0)
    a.set("hi", 10.0)
    a.set("lo", 5.0)
    a.start()
    for s in range(3):
        a.fmu.doStep(s * 0.1, 0.1)
    data, w = a.save(), a.get(["w"])[0]
    assert w == pytest.approx(0.9 ** 3 + 15, rel=1e-14)  # U^p = (1 - h)^p, computed here
    a.free()

    b = Instance(pair[version], "b")
    b.start()
    b.restore(data)  # lo = 5, hi = 10 against b's lo = 0, hi = 1
    assert b.get(["w"])[0] == w
    b.set("lo", 7.0)  # accepted against the restored hi = 10
    with pytest.raises(FMICallException):
        b.set("lo", 11.0)
    b.fmu.doStep(0.3, 0.1)
    assert b.get(["w"])[0] == pytest.approx(0.9 ** 4 + 17, rel=1e-14)
    b.free()
