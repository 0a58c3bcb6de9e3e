# Errors in a model's table or code, built from an
# installed dmi: a duplicate name, an output with a start value, an unknown
# type or causality fail the build with a message naming the variable; a
# configure function that fails makes ExitInitializationMode log its message
# and return Error (the FMU goes on: Reset and a good run); the model's check
# there warns (Warning, the run goes on) or refuses (Error, no solver).  The control: the
# same model without the bad row builds and runs.  A model file named like a
# framework file is refused when configuring.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import pytest
from fmpy.fmi1 import FMICallException

from conftest import HISTORY_ONE, Instance, build, fmus, write_project

# w' = -k w + F, no friction, no kernel; ROW is the row under test.
MODEL = r"""#include <stdio.h>
#include "dmi_fmu.h"
#define VARS(X)                                              \
    X(tau, Float64, parameter, 1.0, "s", "delay")            \
    X(N, Int32, parameter, 10, "", "steps per tau")          \
    X(k, Float64, parameter, 1.0, "1/s", "decay rate")       \
    ROW                                                      \
    X(w, Float64, output, , "", "the state")
static const dmi_fmu_variable TABLE[] = {VARS(DMI_FMU_VARIABLE)};
static int rhs(double t, const double *u, double *out, void *user)
{
    const dmi_fmu_values *m = user;
    (void)t;
    out[0] = m->value[2] * u[0];
    return 0;
}
""" + HISTORY_ONE + r"""static int configure(const dmi_fmu_values *m, dmi_solver *s, char *err)
{
    const double negative[1] = {-1.0};
    if (m->value[2] < 0) {
        snprintf(err, DMI_FMU_ERRLEN, "k = %g: this model has no growing solution", m->value[2]);
        return -1;
    }
    if (m->value[2] == 0) /* libdmi refuses it: its message */
        return dmi_set_friction(s, negative);
    dmi_set_rhs(s, rhs, (void *)m);
    return dmi_set_history(s, one, NULL);
}
/* explicit in f: h k > 1 overshoots (a warning), h k > 2 grows (refused) */
static int check(const dmi_fmu_values *m, double T, char *msg)
{
    const double hk = m->value[0] / m->value[1] * m->value[2];
    if (hk <= 1)
        return 0;
    snprintf(msg, DMI_FMU_ERRLEN, "h k = %g over T = %g: %s", hk, T,
             hk > 2 ? "the scheme grows" : "the scheme overshoots");
    return hk > 2 ? -1 : 1;
}
static void outputs(const dmi_fmu_values *m, const dmi_fmu_point *pt, double *out)
{
    (void)m;
    out[DMI_FMU_COUNT(TABLE) - 1] = pt->u ? pt->u[0] : 1.0;
}
const dmi_fmu_model DMI_FMU_MODEL = {"w' + k w = 0", TABLE, DMI_FMU_COUNT(TABLE), 1, 0, 1, 1.0,
                                     0.1, configure, outputs, NULL, check, NULL, NULL};
"""


def project(tmp_path, row, file=None):
    return write_project(tmp_path / "src", "Bad", MODEL.replace("ROW", row), file)


@pytest.fixture(scope="module")
def good(prefix, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("good")
    build(project(tmp, ""), tmp / "build", prefix)
    return fmus(tmp / "build", "Bad")


@pytest.mark.parametrize("row,message", [
    ('X(k, Float64, parameter, 2.0, "", "again")', 'variable "k" is defined twice'),
    ('X(y, Float64, output, 1.0, "m", "an output")',
     'variable "y": an output or the independent variable has no start value (start 1.0 given)'),
    ('X(z, Float32, parameter, 1.0, "", "")', 'variable "z": unknown type "Float32"'),
    ('X(q, Float64, local, 1.0, "", "")', 'variable "q": unknown causality "local"'),
    ('X(p, Float64, parameter, , "", "")', 'variable "p": a parameter needs a start value'),
    # FMI 2.0 numbers the variables without it: anywhere but last its outputs' indices would be off
    ('X(time, Float64, independent, , "s", "time")',
     'variable "time": the independent variable must be the table\'s last'),
])
def test_bad_table_fails_the_build(prefix, tmp_path, row, message):
    rc, out = build(project(tmp_path, row), tmp_path / "build", prefix, check=False)
    assert rc != 0, out
    assert f"dmi_add_fmu(Bad): error: {message}" in out, out


def test_control_model_runs(good):
    for path in (good["2"], good["3"]):
        inst = Instance(str(path))
        inst.start()
        inst.fmu.doStep(0.0, 1.0)
        # u' + k u = 0 from u = 1, f explicit in the scheme, h = 0.1: (1 - 0.1 k)^10
        assert inst.get(["w"])[0] == pytest.approx(0.9 ** 10, rel=1e-14)
        inst.free()


@pytest.mark.parametrize("version", ["2", "3"])
@pytest.mark.parametrize("k,message", [
    (-2.0, "configuring the solver: k = -2: this model has no growing solution"),
    (0.0, "configuring the solver: dmi_set_friction"),
])
def test_failing_configure_is_an_error(good, version, k, message):
    inst = Instance(good[version])
    inst.set("k", k)
    with pytest.raises(FMICallException):
        inst.start()
    errors = [m for st, c, m in inst.log if st == 3 and c == "logStatusError"]
    assert len(errors) == 1 and message in errors[0], inst.log
    inst.fmu.reset()  # the instance is still usable
    inst.start()
    inst.fmu.doStep(0.0, 1.0)
    assert inst.get(["w"])[0] == pytest.approx(0.9 ** 10, rel=1e-14)
    inst.free()


def test_model_file_named_like_the_framework(prefix, tmp_path):
    """sources/ is one folder: a model file called instance.c is refused at
    configure time, naming the file."""
    src = project(tmp_path, "", "instance.c")
    rc, out = build(src, tmp_path / "build", prefix, check=False)
    assert rc != 0 and "dmi_add_fmu(Bad): the model's file" in out and "instance.c" in out, out


@pytest.mark.parametrize("version", ["2", "3"])
def test_check_warns_or_refuses(good, version):
    path = good[version]
    inst = Instance(path)
    inst.set("k", 15.0)  # h k = 1.5
    inst.start(stop=4.0)  # Warning: fmpy logs it and goes on
    assert [(st, c) for st, c, m in inst.log] == [(1, "logStatusWarning")], inst.log
    assert "h k = 1.5 over T = 4: the scheme overshoots" in inst.log[0][2]
    inst.fmu.doStep(0.0, 0.1)
    assert inst.get(["w"])[0] == pytest.approx(1 - 1.5, rel=1e-14)
    inst.free()
    inst = Instance(path)
    inst.set("k", 25.0)  # h k = 2.5
    with pytest.raises(FMICallException):
        inst.start()
    assert inst.log[-1][0] == 3 and "h k = 2.5 over T = 1: the scheme grows" in inst.log[-1][2]
    inst.free()
