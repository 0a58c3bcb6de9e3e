/*
 * The friction oscillator (4.1) through libdmi's public API and dmi_fmu.h:
 * see model.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "model.h"

#include <math.h>
#include <stdio.h>

#include "framework.h" /* the state layout, checked against model.h's below */

/* model.h states the framework's layout for this model (the tests read it). */
typedef char state_layout_agrees[((int)MODEL_STATE_VERSION == (int)FMU_STATE_VERSION &&
                                  (int)MODEL_STATE_AT_TOTAL == (int)FMU_STATE_AT_TOTAL &&
                                  (int)MODEL_STATE_AT_NREAL == (int)FMU_STATE_AT_NREAL &&
                                  (int)MODEL_STATE_AT_NDMI == (int)FMU_STATE_AT_NDMI &&
                                  (int)MODEL_STATE_AT_HASH == (int)FMU_STATE_AT_HASH &&
                                  (int)MODEL_STATE_AT_NEVENTS == (int)FMU_STATE_AT_NEVENTS &&
                                  (int)MODEL_STATE_AT_EVENT_P == (int)FMU_STATE_AT_EVENT_P &&
                                  (int)MODEL_STATE_AT_NAME == (int)FMU_STATE_AT_NAME &&
                                  (int)MODEL_STATE_AT_N == (int)FMU_STATE_AT_INT &&
                                  (int)MODEL_STATE_AT_REAL == (int)FMU_STATE_AT_INT + 8)
                                     ? 1
                                     : -1];

/* Start values (Example 4.3: b = alpha = tau = 1, N = 1000,
 * H(s) = cos 2 pi s + cos 10 pi s + cos 20 pi s, g(t) = 1.3 cos 8t,
 * w0 = v0 = 0), from config.h. */
static const dmi_fmu_variable VARIABLES[] = {MODEL_VARIABLES(DMI_FMU_VARIABLE)};

static double forcing(const dmi_fmu_values *m, double t)
{
    const double *r = m->value;
    return r[VR_g_offset] + r[VR_g_amp] * cos(r[VR_g_omega] * t + r[VR_g_phase]) + r[VR_g_in];
}

static int rhs(double t, const double *u, double *out, void *user)
{
    const dmi_fmu_values *m = user;
    out[0] = -u[1];
    out[1] = m->value[VR_b] * u[0] + forcing(m, m->t_start + t);
    return 0;
}

static int history(double t, double *out, void *user)
{
    const dmi_fmu_values *m = user;
    (void)t;
    out[0] = m->value[VR_w0];
    out[1] = m->value[VR_v0];
    return 0;
}

/* The coefficients of H's terms, by value reference: H_c0, H_c1 exp(..),
 * H_a{k} cos(..); a term with a zero coefficient is left out of the kernel. */
static const unsigned KERNEL_COEF[5] = {VR_H_c0, VR_H_c1, VR_H_a1, VR_H_a2, VR_H_a3};

/* H(s) = H_c0 + H_c1 exp(-H_lambda s) + sum_k H_a{k} cos(H_omega{k} s) as a
 * sum of exponentials (entry (1, 0) of the kernel), the terms with a zero
 * coefficient left out, so that the default method is the O(1) recursion.
 * A growing term (H_lambda < 0, H_c1 != 0) is refused by the recursion; the
 * default method is then the direct sum (the FMU is built without the FFT). */
static int set_kernel(const dmi_fmu_values *m, dmi_solver *s)
{
    const double *r = m->value;
    const double rate[5] = {0.0, -r[VR_H_lambda], 0.0, 0.0, 0.0};
    const double freq[5] = {0.0, 0.0, r[VR_H_omega1], r[VR_H_omega2], r[VR_H_omega3]};
    double a[5], b[5], C[5 * 4] = {0};
    size_t K = 0;
    for (size_t k = 0; k < 5; k++)
        if (r[KERNEL_COEF[k]] != 0) {
            a[K] = rate[k];
            b[K] = freq[k];
            C[4 * K + 2] = r[KERNEL_COEF[k]];
            K++;
        }
    return K ? dmi_set_kernel_exp(s, K, a, b, C, NULL) : dmi_set_kernel(s, NULL, NULL);
}

static int configure(const dmi_fmu_values *m, dmi_solver *s, char *err)
{
    const double alpha[2] = {0.0, m->value[VR_alpha]};
    int rc;
    (void)err; /* libdmi's message (dmi_last_error) says why */
    if ((rc = set_kernel(m, s)) != DMI_OK || (rc = dmi_set_rhs(s, rhs, (void *)m)) != DMI_OK ||
        (rc = dmi_set_history(s, history, (void *)m)) != DMI_OK ||
        (rc = dmi_set_friction(s, alpha)) != DMI_OK)
        return rc;
    return 0;
}

/* The outputs at pt: w, v = u_h(t); friction, delay force and sticking of
 * the step containing t.  Before the solver: the history at 0, no forces. */
static void outputs(const dmi_fmu_values *m, const dmi_fmu_point *pt, double *out)
{
    if (!pt->u) {
        out[VR_w] = m->value[VR_w0];
        out[VR_v] = m->value[VR_v0];
        out[VR_friction] = out[VR_delay_force] = 0.0;
        out[VR_sticking] = m->value[VR_v0] == 0.0;
        out[VR_stick_slip_events] = 0.0;
        out[VR_last_event_time] = m->t_start;
        return;
    }
    /* the element of alpha sigma(v) the step selected: in [-alpha, alpha],
     * up to the rounding of (X - U)/h, which the clamp removes */
    const double alpha = m->value[VR_alpha];
    out[VR_w] = pt->u[0];
    out[VR_v] = pt->u[1];
    out[VR_friction] = fmin(fmax((pt->X[1] - pt->U[1]) / pt->h, -alpha), alpha);
    out[VR_delay_force] = pt->W[1];
    out[VR_sticking] = pt->U[1] == 0.0;
    out[VR_stick_slip_events] = (double)pt->nevents;
    out[VR_last_event_time] = m->t_start + (double)pt->event_p * pt->h;
}

/* The one event indicator: the velocity's friction sticks or slips, the
 * built-in dmi_fmu_stuck of component 1 with the solver's alpha, which
 * libdmi takes from each step (dmi_fmu_model's held). */
static const size_t HELD[1] = {1};

static int accept(const dmi_fmu_values *m, unsigned vr, double value, char *err)
{
    (void)m;
    if (vr == VR_alpha && !(value >= 0)) {
        snprintf(err, DMI_FMU_ERRLEN, "alpha = %.17g: the friction coefficient must be >= 0",
                 value);
        return -1;
    }
    return 0;
}

/* Whether the step h = tau/N is coarse for an experiment of length T: the
 * explicit part of the scheme amplifies an undamped oscillation by about
 * (1 + h^2 b) per step (b > 0), so by (1 + h^2 b)^(T/h) ~ exp(b h T) over the
 * run; coarse (a warning) when that exceeds COARSE_GROWTH. */
#define COARSE_GROWTH 2.0
static int check_coarse_step(const dmi_fmu_values *m, double T, char *msg)
{
    const double b = m->value[VR_b], tau = m->value[VR_tau], N = m->value[VR_N], h = tau / N;
    if (!(b > 0) || !(T > 0))
        return 0;
    /* log of the growth (1 + h^2 b)^(T/h) over the experiment */
    const double ln_growth = T / h * log1p(h * h * b);
    if (!(ln_growth > log(COARSE_GROWTH)))
        return 0;
    /* h b T <= ln 2 keeps the growth below 2: N >= tau b T / ln 2 */
    const double n_min = ceil(tau * b * T / log(COARSE_GROWTH));
    snprintf(msg, DMI_FMU_ERRLEN, "N = %d (h = %.3g) is a coarse step for b = %.3g: the scheme's "
                                  "explicit part amplifies an undamped oscillation by about "
                                  "(1 + h^2 b) = %.6g per step, \xc3\x97%.3g over T = %.3g; "
                                  "N >= %.3g keeps it below %g",
             (int)N, h, b, 1.0 + h * h * b, exp(ln_growth), T, n_min, COARSE_GROWTH);
    return 1;
}

const dmi_fmu_model DMI_FMU_MODEL = {
    .description = "w'' + b w + int_0^tau H(s) w(t-s) ds + alpha sigma(w') + g(t) contains 0, "
                   "implicit Euler scheme with h = tau/N",
    .variables = VARIABLES,
    .nvariables = DMI_FMU_COUNT(VARIABLES),
    .n = 2,
    .tau = VR_tau,
    .N = VR_N,
    .stop_time = MODEL_DEFAULT_T,
    .step_size = 0.01,
    .configure = configure,
    .outputs = outputs,
    .accept = accept,
    .check = check_coarse_step,
    .author = "the dmi authors",
    .nindicators = 1,
    .held = HELD,
};
