// A model written in C++ against include/dmi_fmu.h (and dmi.h through it):
// the headers must be valid C++11, with -Wall -Wextra -Wpedantic -Werror
// (fmu_header_cxx compiles this file only; it is not linked).
// Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
#include "dmi_fmu.h"

#define VARS(X)                                                                  \
    X(tau, Float64, parameter, 1.0, "s", "delay")                                \
    X(N, Int32, parameter, 10, "", "steps per tau")                              \
    X(k, Float64, parameter, 1.0, "1/s", "decay rate")                           \
    X(w, Float64, output, , "", "u")
enum { VARS(DMI_FMU_VR) NVARS };
static const dmi_fmu_variable TABLE[] = {VARS(DMI_FMU_VARIABLE)};

static int rhs(double t, const double *u, double *out, void *user)
{
    const dmi_fmu_values *m = static_cast<const dmi_fmu_values *>(user);
    (void)t;
    out[0] = m->value[VR_k] * u[0];
    return 0;
}

static int configure(const dmi_fmu_values *m, dmi_solver *s, char *err)
{
    (void)err;
    return dmi_set_rhs(s, rhs, const_cast<dmi_fmu_values *>(m));
}

static void outputs(const dmi_fmu_values *m, const dmi_fmu_point *pt, double *out)
{
    (void)m;
    out[VR_w] = pt->u ? pt->u[0] : 1.0;
}

const dmi_fmu_model DMI_FMU_MODEL = {"u' + k u = 0", TABLE, NVARS, 1, VR_tau, VR_N,
                                     1.0, 0.1, configure, outputs, NULL, NULL, NULL, NULL,
                                     0, NULL, NULL, NULL};
