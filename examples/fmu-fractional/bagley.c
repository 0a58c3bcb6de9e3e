/*
 * The Bagley-Torvik oscillator with dry friction as an FMU:
 *
 *   w'' + c D^{1/2} w + k w + mu sigma(w') ∋ F cos(omega t),  w = w0, w' = 0 on [-tau, 0],
 *
 * D^{1/2} the Caputo derivative, D^{1/2} w(t) = int_0^t s^-1/2 / Gamma(1/2) w'(t - s) ds: with
 * w' = 0 on the history it is the delay integral over [0, tau] while t <= tau (a run longer than
 * tau truncates the memory to tau; ExitInitializationMode then warns).  In libdmi's form
 * u = (w, v), n = 2: f(t, u) = (-v, k w - F cos(omega t)), A = {0} x mu sigma, the kernel
 * [[0, 0], [0, c H]], H(s) = s^-1/2 / Gamma(1/2), singular at 0, with exact cell weights
 * (DMI_QUAD_CELL).
 *
 * The kernel two ways (the Boolean parameter exact):
 *   exact = false  the fitted exponential sum of caputo_fit.h (on [1e-4, 10]) for the cells beyond
 *                  1e-4 and H itself for the cells below (dmi_set_kernel_near): the recursion, O(1)
 *                  per step;
 *   exact = true   H as a callback: DIRECT, O(N) per step (the FMU carries no FFT).
 * tau may not exceed the fit's 10 s.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>

#include "caputo_fit.h"
#include "dmi_fmu.h"

#define VARIABLES(X)                                                                          \
    X(c, Float64, parameter, 0.5, "N/(m.s^0.5)", "fractional damping (>= 0)")                 \
    X(k, Float64, parameter, 1.0, "N/m", "spring stiffness")                                  \
    X(mu, Float64, parameter, 0.2, "N", "dry friction (>= 0)")                                \
    X(F, Float64, parameter, 0.6, "N", "forcing amplitude")                                   \
    X(omega, Float64, parameter, 1.0, "1/s", "forcing frequency")                             \
    X(w0, Float64, parameter, 1.0, "m", "position on [-tau, 0]")                              \
    X(tau, Float64, parameter, 10.0, "s", "memory length (<= 10, the fit's interval)")        \
    X(N, Int32, parameter, 1000, "", "steps per tau")                                         \
    X(exact, Boolean, parameter, 0, "", "the exact kernel by DIRECT instead of the fit")      \
    X(w, Float64, output, , "m", "position")                                                  \
    X(v, Float64, output, , "m/s", "velocity")                                                \
    X(damping, Float64, output, , "N", "the fractional damping force c D^{1/2} w of the step")

enum { VARIABLES(DMI_FMU_VR) NVARS };
static const dmi_fmu_variable TABLE[] = {VARIABLES(DMI_FMU_VARIABLE)};

static int rhs(double t, const double *u, double *out, void *user)
{
    const dmi_fmu_values *p = user;
    out[0] = -u[1];
    out[1] = p->value[VR_k] * u[0] - p->value[VR_F] * cos(p->value[VR_omega] * t);
    return 0;
}

static int history(double t, double *out, void *user)
{
    const dmi_fmu_values *p = user;
    (void)t;
    out[0] = p->value[VR_w0];
    out[1] = 0.0;
    return 0;
}

/* [[0, 0], [0, c s^-1/2 / Gamma(1/2)]], s > 0 (never called at 0 under DMI_QUAD_CELL) */
static int kernel(double s, double *out, void *user)
{
    const dmi_fmu_values *p = user;
    out[0] = out[1] = out[2] = 0.0;
    out[3] = p->value[VR_c] / sqrt(3.141592653589793 * s);
    return 0;
}

static int configure(const dmi_fmu_values *p, dmi_solver *s, char *err)
{
    const double friction[2] = {0.0, p->value[VR_mu]};
    double C[4 * caputo_K] = {0}, D[4 * caputo_K] = {0};
    int rc;
    (void)err; /* libdmi's own message tells why */
    if ((rc = dmi_set_rhs(s, rhs, (void *)p)) || (rc = dmi_set_friction(s, friction)) ||
        (rc = dmi_set_history(s, history, (void *)p)) ||
        (rc = dmi_set_quadrature(s, DMI_QUAD_CELL)))
        return rc;
    if (p->value[VR_exact] != 0) {
        if ((rc = dmi_set_kernel(s, kernel, (void *)p)))
            return rc;
        return dmi_set_convolution(s, DMI_CONV_DIRECT);
    }
    for (size_t j = 0; j < caputo_K; j++) { /* entry (1, 1) of each term, times c */
        C[4 * j + 3] = p->value[VR_c] * caputo_C[j];
        D[4 * j + 3] = p->value[VR_c] * caputo_D[j];
    }
    if ((rc = dmi_set_kernel_exp(s, caputo_K, caputo_a, caputo_b, C, D)))
        return rc;
    return dmi_set_kernel_near(s, kernel, (void *)p, CAPUTO_DELTA);
}

static void outputs(const dmi_fmu_values *p, const dmi_fmu_point *pt, double *out)
{
    out[VR_w] = pt->u ? pt->u[0] : p->value[VR_w0];
    out[VR_v] = pt->u ? pt->u[1] : 0.0;
    out[VR_damping] = pt->W ? pt->W[1] : 0.0;
}

static int accept(const dmi_fmu_values *p, unsigned vr, double value, char *err)
{
    (void)p;
    if ((vr == VR_c || vr == VR_mu) && value < 0) {
        snprintf(err, DMI_FMU_ERRLEN, "%s = %g: expected >= 0", TABLE[vr].name, value);
        return -1;
    }
    if (vr == VR_tau && value > CAPUTO_TAU) {
        snprintf(err, DMI_FMU_ERRLEN, "tau = %g exceeds the fitted kernel's %g s", value,
                 CAPUTO_TAU);
        return -1;
    }
    return 0;
}

static int check(const dmi_fmu_values *p, double T, char *msg)
{
    if (T > p->value[VR_tau]) {
        snprintf(msg, DMI_FMU_ERRLEN, "the run (%g s) is longer than the memory tau = %g s: "
                 "D^{1/2} forgets what is older than tau", T, p->value[VR_tau]);
        return 1;
    }
    return 0;
}

const dmi_fmu_model DMI_FMU_MODEL = {
    .description = "the Bagley-Torvik oscillator with dry friction (fractional damping, order 1/2)",
    .variables = TABLE, .nvariables = NVARS, .n = 2, .tau = VR_tau, .N = VR_N,
    .stop_time = 10.0, .step_size = 0.05,
    .configure = configure, .outputs = outputs, .accept = accept, .check = check,
};
