/*
 * A Burridge-Knopoff chain as an FMU model (dmi_fmu.h): three unit-mass
 * blocks on a rough surface, pulled by a plate moving at speed V through
 * springs k_p, coupled by springs k_c with viscoelastic memory, each with
 * dry friction:
 *
 *   x_i'' + k_p (x_i - V t) + k_c (L x)_i + int_0^tau G(s) (L x)_i(t - s) ds
 *         + alpha_i sigma(x_i') ∋ F_i(t),                        i = 1..3,
 *   L = [[1, -1, 0], [-1, 2, -1], [0, -1, 1]],
 *   G(s) = g1 exp(-s / theta1) + g2 exp(-s / theta2),   F = (F_in, 0, 0),
 *   x_i = x0_i and x_i' = 0 on [-tau, 0].
 *
 * In libdmi's form u = (x, v), n = 6: f(t, u) = (-v, k_p (x - V t) + k_c L x
 * - F(t)), A = {0}^3 x prod_i alpha_i sigma(v_i), the kernel [[0, 0],
 * [G(s) L, 0]] as two exponential terms, the history constant.
 * Built by dmi_add_fmu(BurridgeKnopoffChain SOURCES chain.c) (CMakeLists.txt).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>

#include "dmi_fmu.h"

#define VARIABLES(X)                                                                               \
    X(k_p, Float64, parameter, 1.0, "N/m", "stiffness of the plate springs")                       \
    X(k_c, Float64, parameter, 2.0, "N/m", "stiffness of the coupling springs")                    \
    X(V, Float64, parameter, 0.1, "m/s", "speed of the plate")                                     \
    X(alpha1, Float64, parameter, 1.0, "N", "dry friction of block 1 (>= 0)")                      \
    X(alpha2, Float64, parameter, 1.2, "N", "dry friction of block 2 (>= 0)")                      \
    X(alpha3, Float64, parameter, 0.9, "N", "dry friction of block 3 (>= 0)")                      \
    X(g1, Float64, parameter, 0.3, "N/(m.s)", "memory: amplitude of exp(-s/theta1)")               \
    X(theta1, Float64, parameter, 0.5, "s", "memory: relaxation time 1 (> 0)")                     \
    X(g2, Float64, parameter, 0.1, "N/(m.s)", "memory: amplitude of exp(-s/theta2)")               \
    X(theta2, Float64, parameter, 3.0, "s", "memory: relaxation time 2 (> 0)")                     \
    X(tau, Float64, parameter, 10.0, "s", "length of the memory (> 0)")                            \
    X(N, Int32, parameter, 1000, "", "steps per tau (h = tau / N)")                                \
    X(x0_1, Float64, parameter, 0.0, "m", "history of x1 on [-tau, 0]")                            \
    X(x0_2, Float64, parameter, 0.0, "m", "history of x2 on [-tau, 0]")                            \
    X(x0_3, Float64, parameter, 0.0, "m", "history of x3 on [-tau, 0]")                            \
    X(F_in, Float64, input, 0.0, "N", "force on block 1 (step p: the value set by t_p)")           \
    X(x1, Float64, output, , "m", "position of block 1 (piecewise-linear interpolant)")            \
    X(x2, Float64, output, , "m", "position of block 2")                                           \
    X(x3, Float64, output, , "m", "position of block 3")                                           \
    X(v1, Float64, output, , "m/s", "velocity of block 1 (piecewise-linear interpolant)")          \
    X(v2, Float64, output, , "m/s", "velocity of block 2")                                         \
    X(v3, Float64, output, , "m/s", "velocity of block 3")                                         \
    X(friction1, Float64, output, , "N", "element of alpha1 sigma(v1) of the step")                \
    X(friction2, Float64, output, , "N", "element of alpha2 sigma(v2) of the step")                \
    X(friction3, Float64, output, , "N", "element of alpha3 sigma(v3) of the step")

enum { VARIABLES(DMI_FMU_VR) NVARS };
static const dmi_fmu_variable TABLE[] = {VARIABLES(DMI_FMU_VARIABLE)};

/* L, the coupling of neighbours. */
static const double L[3][3] = {{1, -1, 0}, {-1, 2, -1}, {0, -1, 1}};

static int rhs(double t, const double *u, double *out, void *user)
{
    const dmi_fmu_values *m = user;
    const double *p = m->value, *x = u, *v = u + 3;
    const double plate = p[VR_V] * (m->t_start + t);
    for (int i = 0; i < 3; i++) {
        const double Lx = L[i][0] * x[0] + L[i][1] * x[1] + L[i][2] * x[2];
        out[i] = -v[i];
        out[3 + i] = p[VR_k_p] * (x[i] - plate) + p[VR_k_c] * Lx - (i == 0 ? p[VR_F_in] : 0.0);
    }
    return 0;
}

static int history(double t, double *out, void *user)
{
    const dmi_fmu_values *m = user;
    (void)t;
    out[0] = m->value[VR_x0_1];
    out[1] = m->value[VR_x0_2];
    out[2] = m->value[VR_x0_3]; /* v = 0 */
    return 0;
}

static int configure(const dmi_fmu_values *m, dmi_solver *s, char *err)
{
    const double *p = m->value;
    const double alpha[6] = {0, 0, 0, p[VR_alpha1], p[VR_alpha2], p[VR_alpha3]};
    const double a[2] = {-1 / p[VR_theta1], -1 / p[VR_theta2]}, b[2] = {0, 0};
    const double g[2] = {p[VR_g1], p[VR_g2]};
    double C[2 * 36] = {0}; /* C_k = g_k [[0, 0], [L, 0]] */
    for (int k = 0; k < 2; k++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                C[36 * k + 6 * (3 + i) + j] = g[k] * L[i][j];
    (void)err; /* libdmi's message says why */
    int rc;
    if ((rc = dmi_set_rhs(s, rhs, (void *)m)) != DMI_OK ||
        (rc = dmi_set_friction(s, alpha)) != DMI_OK ||
        (rc = dmi_set_kernel_exp(s, 2, a, b, C, NULL)) != DMI_OK ||
        (rc = dmi_set_history(s, history, (void *)m)) != DMI_OK)
        return rc;
    return 0;
}

static void outputs(const dmi_fmu_values *m, const dmi_fmu_point *pt, double *out)
{
    static const unsigned ALPHA[3] = {VR_alpha1, VR_alpha2, VR_alpha3};
    for (int i = 0; i < 3; i++) {
        if (!pt->u) { /* before the solver: the history, at rest */
            out[VR_x1 + i] = m->value[VR_x0_1 + i];
            out[VR_v1 + i] = out[VR_friction1 + i] = 0.0;
            continue;
        }
        const double alpha = m->value[ALPHA[i]];
        out[VR_x1 + i] = pt->u[i];
        out[VR_v1 + i] = pt->u[3 + i];
        /* (X - U)/h of the step: alpha_i sigma(v_i), clamped against rounding */
        out[VR_friction1 + i] = fmin(fmax((pt->X[3 + i] - pt->U[3 + i]) / pt->h, -alpha), alpha);
    }
}

/* alpha_i >= 0 and theta_k > 0 (the framework refuses non-finite values,
 * tau <= 0 and N < 1). */
static int accept(const dmi_fmu_values *m, unsigned vr, double value, char *err)
{
    (void)m;
    if ((vr == VR_alpha1 || vr == VR_alpha2 || vr == VR_alpha3) && !(value >= 0)) {
        snprintf(err, DMI_FMU_ERRLEN, "%s = %.17g: a friction coefficient must be >= 0",
                 TABLE[vr].name, value);
        return -1;
    }
    if ((vr == VR_theta1 || vr == VR_theta2) && !(value > 0)) {
        snprintf(err, DMI_FMU_ERRLEN, "%s = %.17g: a relaxation time must be > 0", TABLE[vr].name,
                 value);
        return -1;
    }
    return 0;
}

const dmi_fmu_model DMI_FMU_MODEL = {
    .description = "Burridge-Knopoff chain of three blocks with dry friction and viscoelastic "
                   "coupling memory",
    .variables = TABLE,
    .nvariables = NVARS,
    .n = 6,
    .tau = VR_tau,
    .N = VR_N,
    .stop_time = 100.0,
    .step_size = 0.1,
    .configure = configure,
    .outputs = outputs,
    .accept = accept,
};
