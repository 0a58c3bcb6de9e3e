# Every kind of variable of dmi_fmu.h through both FMI versions, in a small
# model built from an installed dmi: a Boolean parameter, an Int32 input, Int32
# and Boolean outputs beside the Float64 ones; set, get, the parameter fixed
# after initialization, and an FMU state holding them (the framework's layout
# with two integers before the Float64 values).  Model: u' + k u = 0, u = 1 on
# [-tau, 0]; the scheme (f explicit) gives U^p = (1 - h k)^p, computed here.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import pytest
from fmpy.fmi1 import FMICallException

from conftest import HISTORY_ONE, Instance, built_fmus

MODEL = r"""#include "dmi_fmu.h"
#define VARS(X)                                                                  \
    X(tau, Float64, parameter, 1.0, "s", "delay")                                \
    X(N, Int32, parameter, 10, "", "steps per tau")                              \
    X(k, Float64, parameter, 1.0, "1/s", "decay rate")                           \
    X(negate, Boolean, parameter, 0, "", "w = -u")                               \
    X(offset, Int32, input, 0, "", "added to w")                                 \
    X(w, Float64, output, , "", "(negate ? -u : u) + offset")                    \
    X(steps, Int32, output, , "", "the step containing t")                       \
    X(positive, Boolean, output, , "", "u > 0")
enum { VARS(DMI_FMU_VR) NVARS };
static const dmi_fmu_variable TABLE[] = {VARS(DMI_FMU_VARIABLE)};
static int rhs(double t, const double *u, double *out, void *user)
{
    const dmi_fmu_values *m = user;
    (void)t;
    out[0] = m->value[VR_k] * u[0];
    return 0;
}
""" + HISTORY_ONE + r"""static int configure(const dmi_fmu_values *m, dmi_solver *s, char *err)
{
    (void)err;
    int rc = dmi_set_rhs(s, rhs, (void *)m);
    return rc ? rc : dmi_set_history(s, one, NULL);
}
static void outputs(const dmi_fmu_values *m, const dmi_fmu_point *pt, double *out)
{
    const double u = pt->u ? pt->u[0] : 1.0;
    out[VR_w] = (m->value[VR_negate] ? -u : u) + m->value[VR_offset];
    out[VR_steps] = (double)pt->p;
    out[VR_positive] = u > 0;
}
const dmi_fmu_model DMI_FMU_MODEL = {"u' + k u = 0", TABLE, NVARS, 1, VR_tau, VR_N, 1.0, 0.1,
                                     configure, outputs, NULL, NULL, NULL, NULL};
"""


@pytest.fixture(scope="module")
def kinds(prefix, tmp_path_factory):
    return built_fmus(tmp_path_factory, prefix, "Kinds", MODEL)


class Typed:
    """Int32/Integer and Boolean set and get of an Instance."""

    def __init__(self, inst):
        self.i, f = inst, inst.fmu
        self.set_int = f.setInt32 if inst.v3 else f.setInteger
        self.get_int = f.getInt32 if inst.v3 else f.getInteger
        self.set_bool, self.get_bool = f.setBoolean, f.getBoolean

    def outputs(self):
        """w (to 1e-14: the recurrence, computed otherwise), steps, positive."""
        vr = self.i.vr
        return (pytest.approx(self.i.get(["w"])[0], rel=1e-14, abs=1e-14),
                self.get_int([vr["steps"]])[0], bool(self.get_bool([vr["positive"]])[0]))


@pytest.mark.parametrize("version", ["2", "3"])
def test_every_kind(kinds, version):
    inst = Instance(kinds[version])
    t, vr = Typed(inst), inst.vr
    md = {v.name: v for v in inst.md.modelVariables}
    assert md["negate"].type == "Boolean" and md["negate"].start in ("false", "0")
    assert md["steps"].type == ("Int32" if version == "3" else "Integer")
    t.set_bool([vr["negate"]], [True])
    t.set_int([vr["offset"]], [3])
    with pytest.raises(FMICallException):  # a Boolean parameter is 0 or 1, not an Int32
        t.set_int([vr["negate"]], [2])
    inst.start()
    assert t.outputs() == (-1.0 + 3, 0, True)
    for s in range(5):
        inst.fmu.doStep(s * 0.1, 0.1)
    assert t.outputs() == (-(0.9 ** 5) + 3, 5, True)
    with pytest.raises(FMICallException):  # a parameter after initialization
        t.set_bool([vr["negate"]], [False])
    assert [st for st, c, m in inst.log][-1] == 3
    data = inst.save()
    t.set_int([vr["offset"]], [-7])  # an input in step mode
    inst.fmu.doStep(0.5, 0.1)
    assert t.outputs() == (-(0.9 ** 6) - 7, 6, True)
    inst.restore(data)  # offset 3 and negate true again, at step 5
    assert t.outputs() == (-(0.9 ** 5) + 3, 5, True)
    inst.fmu.doStep(0.5, 0.1)
    assert t.outputs() == (-(0.9 ** 6) + 3, 6, True)
    inst.free()
