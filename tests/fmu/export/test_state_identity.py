# FMU state format 3 names its model: two models with the same
# variable counts (the same table, or one variable renamed) no longer accept
# each other's states; the refusal names both models.  Each model's own state
# still restores.  Built from an installed dmi as a user does (conftest.py).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import pytest
from fmpy.fmi1 import FMICallException

from conftest import Instance, build, fmus, write_project

SOURCE = r"""
#include "dmi_fmu.h"

#define VARS(X)                                                                  \
    X(@K@, Float64, parameter, 1.0, "", "rate")                                  \
    X(tau, Float64, parameter, 1.0, "", "delay")                                 \
    X(N, Int32, parameter, 10, "", "steps per tau")                              \
    X(w, Float64, output, , "", "the solution")
enum { VARS(DMI_FMU_VR) NVARS };
static const dmi_fmu_variable TABLE[] = {VARS(DMI_FMU_VARIABLE)};

static int rhs(double t, const double *u, double *out, void *user)
{
    const dmi_fmu_values *m = user;
    (void)t;
    out[0] = m->value[VR_@K@] * u[0];
    return 0;
}

static int history(double t, double *out, void *user)
{
    (void)t, (void)user;
    out[0] = 1.0;
    return 0;
}

static int configure(const dmi_fmu_values *m, dmi_solver *s, char *err)
{
    int rc;
    (void)err;
    if ((rc = dmi_set_rhs(s, rhs, (void *)m)) != DMI_OK ||
        (rc = dmi_set_history(s, history, NULL)) != DMI_OK)
        return rc;
    return 0;
}

static void outputs(const dmi_fmu_values *m, const dmi_fmu_point *pt, double *out)
{
    (void)m;
    out[VR_w] = pt->u ? pt->u[0] : 1.0;
}

const dmi_fmu_model DMI_FMU_MODEL = {.description = "u' + k u = 0", .variables = TABLE,
                                     .nvariables = NVARS, .n = 1, .tau = VR_tau, .N = VR_N,
                                     .stop_time = 1.0, .step_size = 0.1,
                                     .configure = configure, .outputs = outputs};
"""


@pytest.fixture(scope="module")
def twins(tmp_path_factory, prefix):
    """TwinA and TwinB (one source, two names, so two GUIDs) and, in another
    project, a TwinA whose rate is called c instead of k (one GUID given)."""
    root = tmp_path_factory.mktemp("twins")
    paths = {}
    for project, names, var, guid in (("same", ["TwinA", "TwinB"], "k", None),
                                      ("renamed", ["TwinA"], "c", "{0f0e0d0c-0b0a-4908-8706-050403020100}")):
        src = write_project(root / project, names, SOURCE.replace("@K@", var), "twin.c", guid)
        build(src, root / (project + "-build"), prefix)
        for n in names:
            paths[(project, n)] = fmus(root / (project + "-build"), n)
    return paths


@pytest.mark.parametrize("version", ["2", "3"])
def test_states_name_their_model(twins, version):
    """Equal sizes, another model: refused, both models named; own: restored."""
    cases = [(("same", "TwinA"), ("same", "TwinB"), "TwinA", "TwinB"),
             (("same", "TwinB"), ("same", "TwinA"), "TwinB", "TwinA"),
             (("renamed", "TwinA"), ("same", "TwinA"), "TwinA", "TwinA")]
    for saved_by, restored_by, saved_name, own_name in cases:
        inst = Instance(twins[saved_by][version], "saver")
        inst.start()
        state = inst.save()
        inst.free()
        inst = Instance(twins[restored_by][version], "restorer")
        inst.start()
        own = inst.save()
        assert len(own) == len(state)  # the same layout: only the identity differs
        with pytest.raises(FMICallException):
            inst.restore(state)
        msg = inst.log[-1][2]
        assert (f'the state is of model "{saved_name}"' in msg
                and f'this FMU is model "{own_name}"' in msg), inst.log
        inst.restore(own)
        inst.free()
