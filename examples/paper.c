/*
 * The paper's Examples 4.1-4.3.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "paper.h"

#include <math.h>
#include <stdlib.h>

static const double PI = 3.14159265358979323846;

/* sigma-like term of the forcings: -1, 0 or +1 on either side of a switch */
static double side(double t, double at)
{
    return t < at ? -1.0 : t > at ? 1.0 : 0.0;
}

double paper_g(int example, double t)
{
    switch (example) {
    case 41: /* (4.7): jump at t = 2 */
        return (-t + 4) * exp(-t) + (-t + 1) * exp(-t + 1) + side(t, 2);
    case 42: { /* (4.9): +1 before 1, -1 on ]1, 2[, +1 after 2, 0 at the switches */
        double base = (-t * t + 7 * t - 4) * exp(-t) + (-t * t + t - 2) * exp(-t + 1);
        if (t < 1)
            return base + 1;
        if (t == 1 || t == 2)
            return base;
        return t < 2 ? base - 1 : base + 1;
    }
    default:
        return 1.3 * cos(8 * t);
    }
}

double paper_H(int example, double s)
{
    if (example == 43)
        return cos(2 * PI * s) + cos(10 * PI * s) + cos(20 * PI * s);
    return 1.0;
}

int paper_has_exact(int example)
{
    return example == 41 || example == 42;
}

double paper_w(int example, double t)
{
    if (example == 41)
        return (t - 1) * exp(-t);
    if (example == 42)
        return (t * t - t + 1) * exp(-t);
    return 0;
}

double paper_v(int example, double t)
{
    if (example == 41)
        return (2 - t) * exp(-t);
    if (example == 42)
        return (-t * t + 3 * t - 2) * exp(-t);
    return 0;
}

int paper_rhs(double t, const double *u, double *out, void *user)
{
    const paper_example *ex = user;
    out[0] = -u[1];
    out[1] = u[0] + paper_g(ex->example, t); /* b = 1 */
    return 0;
}

int paper_kernel(double s, double *out, void *user)
{
    const paper_example *ex = user;
    out[2] = paper_H(ex->example, s); /* entry (1, 0) */
    return 0;
}

int paper_history(double t, double *out, void *user)
{
    const paper_example *ex = user;
    out[0] = paper_w(ex->example, t);
    out[1] = paper_v(ex->example, t);
    return 0;
}

int paper_setup(dmi_solver *s, paper_example *ex)
{
    static const double alpha[2] = {0.0, 1.0};
    int rc = dmi_set_rhs(s, paper_rhs, ex);
    if (rc == DMI_OK)
        rc = dmi_set_kernel(s, paper_kernel, ex);
    if (rc == DMI_OK)
        rc = dmi_set_history(s, paper_history, ex);
    if (rc == DMI_OK)
        rc = dmi_set_friction(s, alpha);
    return rc;
}

int paper_set_kernel_exp43(dmi_solver *s)
{
    const double a[3] = {0, 0, 0}, b[3] = {2 * PI, 10 * PI, 20 * PI};
    const double C[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0}; /* entry (1, 0) of each */
    return dmi_set_kernel_exp(s, 3, a, b, C, NULL);
}

static void track(int example, double t, const double *u, paper_result *res)
{
    if (!paper_has_exact(example))
        return;
    double ew = fabs(u[0] - paper_w(example, t)), ev = fabs(u[1] - paper_v(example, t));
    double es = sqrt(ew * ew + ev * ev);
    res->max_err_w = fmax(res->max_err_w, ew);
    res->max_err_v = fmax(res->max_err_v, ev);
    res->max_err_state = fmax(res->max_err_state, es);
}

static void row(FILE *csv, int example, double t, const double *u)
{
    if (!csv)
        return;
    if (paper_has_exact(example))
        fprintf(csv, "%.17g,%.17g,%.17g,%.17g,%.17g\n", t, u[0], u[1], paper_w(example, t),
                paper_v(example, t));
    else
        fprintf(csv, "%.17g,%.17g,%.17g\n", t, u[0], u[1]);
}

int paper_run(int example, size_t N, double T, int method, FILE *csv, size_t stride,
              paper_result *res)
{
    paper_example ex = {example};
    paper_result r = {0};
    dmi_solver *s = NULL;
    double u[2];
    int rc = dmi_create(&s, 2, 1.0, N);
    if (rc != DMI_OK)
        return rc;
    rc = paper_setup(s, &ex);
    if (rc == DMI_OK)
        rc = dmi_set_convolution(s, method);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    if (rc != DMI_OK) {
        dmi_free(&s);
        return rc;
    }
    if (stride == 0)
        stride = 1;
    const double h = dmi_get_h(s);
    if (!(T >= 0 && T / h <= 1e15)) { /* M = T/h steps must be a sane count */
        dmi_free(&s);
        return DMI_EINVAL;
    }
    if (csv)
        fprintf(csv, paper_has_exact(example) ? "t,w,v,w_exact,v_exact\n" : "t,w,v\n");
    for (size_t lag = N; lag > 0; lag--) { /* the history, t_p = -lag h */
        dmi_get_past(s, lag, u);
        double t = -(double)lag * h;
        track(example, t, u, &r);
        if (paper_has_exact(example) && lag % stride == 0)
            row(csv, example, t, u);
    }
    const size_t M = (size_t)llround(T / h);
    size_t run = 0;      /* length of the current run of v == 0 */
    int in_dynamic = 0;  /* a dynamic phase is open */
    for (size_t p = 0;; p++) {
        dmi_get_state(s, u);
        double t = dmi_time(s);
        track(example, t, u, &r);
        if (p % stride == 0 || p == M)
            row(csv, example, t, u);
        if (p > 0 && u[1] == 0.0) {
            if (++run == 2) {
                r.static_phases++;
                in_dynamic = 0;
            }
        } else if (p > 0) {
            run = 0;
            if (!in_dynamic) {
                r.dynamic_phases++;
                in_dynamic = 1;
            }
        }
        if (p == M)
            break;
        rc = dmi_step(s);
        if (rc != DMI_OK)
            break;
    }
    r.steps = M;
    dmi_free(&s);
    if (rc == DMI_OK && res)
        *res = r;
    return rc;
}
