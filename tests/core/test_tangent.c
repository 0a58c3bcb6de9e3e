/*
 * The tangent of the scheme (dmi_tangent_*): sensitivities of a forced
 * friction oscillator with memory against central differences of plain runs
 * (dmi_advance), in parameters of f, the friction, the kernel and the
 * history; the saltation at reversals against differences across a step
 * that moves the switching times; the refusals, and a failing callback that
 * leaves the solver where it was.
 *
 *   x' = v,  v' = -k x - c v - mu sign(v) - int_0^tau g e^{-s} v(t - s) ds + F cos(w t),
 *   x = z0 cos t, v = -z0 sin t on [-tau, 0];  p = (k, mu, g, z0).
 *
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core_test.h"

enum { n = 2, P = 4 };
static const double C_DAMP = 0.1, F_AMP = 0.9, OMEGA = 1.3, TAU = 2.0;

typedef struct {
    double p[P]; /* k, mu, g, z0 */
    int fail_at; /* f returns 7 from this call on (0: never) */
    int calls;
} model;

static int rhs(double t, const double *u, double *out, void *user)
{
    model *m = user;
    if (m->fail_at && ++m->calls >= m->fail_at)
        return 7;
    out[0] = -u[1];
    out[1] = m->p[0] * u[0] + C_DAMP * u[1] - F_AMP * cos(OMEGA * t);
    return 0;
}

static int history(double t, double *out, void *user)
{
    const model *m = user;
    out[0] = m->p[3] * cos(t);
    out[1] = -m->p[3] * sin(t);
    return 0;
}

static int kernel_callback(double s, double *out, void *user)
{
    const model *m = user;
    out[3] = m->p[2] * exp(-s);
    return 0;
}

/* The solver of model m (kernel by dmi_set_kernel_exp, or as a callback),
 * step h, initialised. */
static dmi_solver *make(model *m, double h, int callback_kernel)
{
    dmi_solver *s = NULL;
    const double alpha[n] = {0.0, m->p[1]};
    const double a[1] = {-1.0}, b[1] = {0.0}, C[4] = {0, 0, 0, m->p[2]};
    if (dmi_create_h(&s, n, TAU, h) != DMI_OK)
        return NULL;
    int rc = dmi_set_rhs(s, rhs, m);
    rc |= dmi_set_friction(s, alpha);
    rc |= callback_kernel ? dmi_set_kernel(s, kernel_callback, m)
                          : dmi_set_kernel_exp(s, 1, a, b, C, NULL);
    rc |= dmi_set_history(s, history, m);
    if (rc != DMI_OK || dmi_init(s) != DMI_OK)
        dmi_free(&s);
    return s;
}

/* U^q, q = 0..steps, of a plain run of the model at p ((steps + 1) n). */
static double *plain(const double *p, double h, size_t steps, int callback_kernel)
{
    model m = {{p[0], p[1], p[2], p[3]}, 0, 0};
    dmi_solver *s = make(&m, h, callback_kernel);
    double *U = malloc((steps + 1) * n * sizeof *U);
    if (!s || !U) {
        dmi_free(&s);
        free(U);
        return NULL;
    }
    dmi_get_state(s, U);
    for (size_t q = 0; q < steps; q++)
        if (dmi_step(s) != DMI_OK || dmi_get_state(s, U + (q + 1) * n) != DMI_OK)
            break;
    dmi_free(&s);
    return U;
}

/* Everything a tangent run of the model at p0 needs and gives. */
typedef struct {
    model base, pert[P];
    dmi_solver *s, *others[P];
    double delta[P];
    dmi_tangent *t;
    double *U, *X, *S, *S0, *dWU;
    signed char *sw;
    size_t steps, N;
} setup;

static const double P0[P] = {1.0, 0.6, 0.5, 1.0};

static void setup_free(setup *c)
{
    dmi_tangent_free(&c->t);
    dmi_free(&c->s);
    for (int j = 0; j < P; j++)
        dmi_free(&c->others[j]);
    free(c->U);
    free(c->X);
    free(c->S);
    free(c->S0);
    free(c->dWU);
    free(c->sw);
}

/* The solvers, the history's S from the others' windows, the kernel's part
 * dWU from the plain run (g enters the kernel linearly: dG/dg = G / g, so
 * dWU = W^q / g in column 2), and the tangent object. */
static int setup_make(setup *c, double h, size_t steps, int callback_kernel)
{
    memset(c, 0, sizeof *c);
    c->steps = steps;
    c->base = (model){{P0[0], P0[1], P0[2], P0[3]}, 0, 0};
    c->s = make(&c->base, h, callback_kernel);
    if (!c->s)
        return -1;
    const size_t N = c->N = dmi_get_N(c->s);
    c->U = malloc((steps + 1) * n * sizeof *c->U);
    c->X = malloc(steps * n * sizeof *c->X);
    c->S = malloc((steps + 1) * n * P * sizeof *c->S);
    c->S0 = calloc((N + 1) * n * P, sizeof *c->S0);
    c->dWU = calloc(steps * n * P, sizeof *c->dWU);
    c->sw = malloc(steps * n);
    double *w0 = malloc((N + 1) * n * sizeof *w0), *w1 = malloc((N + 1) * n * sizeof *w1);
    int ok = c->U && c->X && c->S && c->S0 && c->dWU && c->sw && w0 && w1 &&
             dmi_get_window(c->s, w0) == DMI_OK;
    for (int j = 0; ok && j < P; j++) {
        c->pert[j] = c->base;
        const double step = 0x1p-26 * fmax(1.0, fabs(P0[j]));
        c->pert[j].p[j] = P0[j] + step;
        c->delta[j] = c->pert[j].p[j] - P0[j];
        c->others[j] = make(&c->pert[j], h, callback_kernel);
        ok = c->others[j] && dmi_get_window(c->others[j], w1) == DMI_OK;
        for (size_t r = 0; ok && r < (N + 1) * n; r++)
            c->S0[r * P + j] = (w1[r] - w0[r]) / c->delta[j];
    }
    /* the kernel's part from a plain run's W^q, then back to the start */
    for (size_t q = 0; ok && q < steps; q++) {
        double W[n];
        ok = dmi_step(c->s) == DMI_OK && dmi_get_step_terms(c->s, W, NULL) == DMI_OK;
        for (int i = 0; ok && i < n; i++)
            c->dWU[(q * n + (size_t)i) * P + 2] = W[i] / P0[2];
    }
    ok = ok && dmi_init(c->s) == DMI_OK;
    free(w0);
    free(w1);
    ok = ok && dmi_tangent_create(&c->t, c->s, P, (const dmi_solver *const *)c->others,
                                  c->delta) == DMI_OK;
    ok = ok && dmi_tangent_set_history(c->t, c->S0) == DMI_OK;
    return ok ? 0 : -1;
}

/* max over q >= first, i, j of |S - D| / (1 + |D|), D the central
 * differences of plain runs at p0 +- eps_j e_j, eps_j = rel max(1, |p_j|). */
static double against_differences(const setup *c, double h, double rel, int callback_kernel,
                                  size_t first)
{
    double worst = 0;
    for (int j = 0; j < P; j++) {
        double up[P], down[P];
        memcpy(up, P0, sizeof up);
        memcpy(down, P0, sizeof down);
        const double eps = rel * fmax(1.0, fabs(P0[j]));
        up[j] += eps;
        down[j] -= eps;
        double *Uu = plain(up, h, c->steps, callback_kernel);
        double *Ud = plain(down, h, c->steps, callback_kernel);
        if (!Uu || !Ud) {
            free(Uu);
            free(Ud);
            return INFINITY;
        }
        for (size_t q = first; q <= c->steps; q++)
            for (int i = 0; i < n; i++) {
                const double D = (Uu[q * n + (size_t)i] - Ud[q * n + (size_t)i]) / (up[j] - down[j]);
                const double e = fabs(c->S[(q * n + (size_t)i) * P + (size_t)j] - D) / (1 + fabs(D));
                worst = e > worst || isnan(e) ? e : worst;
            }
        free(Uu);
        free(Ud);
    }
    return worst;
}

static size_t count_switches(const setup *c, int kind)
{
    size_t k = 0;
    for (size_t q = 0; q < c->steps * n; q++)
        k += c->sw[q] == kind;
    return k;
}

/* The plain tangent is the derivative of the scheme: against central
 * differences of plain runs with a step small enough that no hold changes. */
static void test_plain_tangent_is_the_schemes_derivative(void)
{
    const double h = 0.01;
    const size_t steps = 1500;
    for (int callback_kernel = 0; callback_kernel <= 1; callback_kernel++) {
        setup c;
        CU_ASSERT_FATAL(setup_make(&c, h, steps, callback_kernel) == 0);
        CU_ASSERT_FATAL(dmi_tangent_run(c.t, steps, DMI_TANGENT_PLAIN, c.dWU, c.U, c.X, c.S, NULL,
                                        c.sw) == DMI_OK);
        /* the run is dmi_advance's, bitwise */
        double *U = plain(P0, h, steps, callback_kernel);
        CU_ASSERT_FATAL(U != NULL);
        CU_ASSERT(memcmp(U, c.U, (steps + 1) * n * sizeof *U) == 0);
        free(U);
        uint64_t p = 0;
        CU_ASSERT(dmi_get_step_index(c.s, &p) == DMI_OK && p == steps);
        const double err = against_differences(&c, h, 1e-7, callback_kernel, 0);
        printf("  plain tangent, %s kernel: max |S - D| / (1 + |D|) = %.3g\n",
               callback_kernel ? "callback" : "exponential", err);
        CU_ASSERT(err < 1e-5);
        /* the model sticks and slips: the test passes through holds */
        size_t held = 0;
        for (size_t q = 1; q <= steps; q++)
            held += c.U[q * n + 1] == 0.0;
        printf("  held in %zu of %zu steps\n", held, steps);
        CU_ASSERT(held > 10 && held < steps - 10);
        /* f_u by columns (f depends on k only) gives the same S to the differences' error */
        double *S1 = malloc((steps + 1) * n * P * sizeof *S1);
        CU_ASSERT_FATAL(S1 != NULL);
        memcpy(S1, c.S, (steps + 1) * n * P * sizeof *S1);
        const int depends[P] = {1, 0, 0, 0};
        CU_ASSERT_FATAL(dmi_init(c.s) == DMI_OK);
        CU_ASSERT_FATAL(dmi_tangent_set_rhs_parameters(c.t, depends) == DMI_OK);
        CU_ASSERT_FATAL(dmi_tangent_run(c.t, steps, DMI_TANGENT_PLAIN, c.dWU, NULL, NULL, c.S,
                                        NULL, NULL) == DMI_OK);
        double diff = 0;
        for (size_t k = 0; k < (steps + 1) * n * P; k++)
            diff = fmax(diff, fabs(S1[k] - c.S[k]) / (1 + fabs(S1[k])));
        CU_ASSERT(diff < 1e-6);
        if (!callback_kernel) {
            /* the kernel's part from its term's derivative (dC_0[1][1]/dg = 1) in the loop, not
             * from dWU: the same S to rounding */
            const double da[P] = {0}, db[P] = {0};
            double dC[4 * P] = {0};
            dC[3 * P + 2] = 1.0;
            CU_ASSERT_FATAL(dmi_init(c.s) == DMI_OK);
            CU_ASSERT_FATAL(dmi_tangent_set_kernel_terms(c.t, da, db, dC, NULL) == DMI_OK);
            CU_ASSERT_FATAL(dmi_tangent_run(c.t, steps, DMI_TANGENT_PLAIN, NULL, NULL, NULL, S1,
                                            NULL, NULL) == DMI_OK);
            diff = 0;
            for (size_t k = 0; k < (steps + 1) * n * P; k++)
                diff = fmax(diff, fabs(S1[k] - c.S[k]) / (1 + fabs(c.S[k])));
            printf("  kernel terms' derivatives against dWU: %.3g\n", diff);
            CU_ASSERT(diff < 1e-12);
            dC[3 * P + 2] = NAN;
            CU_ASSERT(dmi_tangent_set_kernel_terms(c.t, da, db, dC, NULL) == DMI_EINVAL);
            CU_ASSERT(strstr(dmi_last_error(c.s), "dC[") != NULL);
            CU_ASSERT(dmi_tangent_set_kernel_terms(c.t, NULL, NULL, NULL, NULL) == DMI_OK);
        } else {
            const double zeros[4 * P] = {0};
            CU_ASSERT(dmi_tangent_set_kernel_terms(c.t, zeros, zeros, zeros, NULL) == DMI_EINVAL);
            CU_ASSERT(strstr(dmi_last_error(c.s), "dmi_set_kernel_exp") != NULL);
        }
        free(S1);
        setup_free(&c);
    }
}

/* With the saltation factor S follows the equation's sensitivity through
 * reversals, which the plain tangent misses by O(1): against differences of
 * plain runs whose step in p moves each reversal by many steps h. */
static void test_saltation_follows_the_equation(void)
{
    const double h = 2e-4;
    const size_t steps = 20000; /* t = 4: past the first reversals */
    setup c;
    CU_ASSERT_FATAL(setup_make(&c, h, steps, 0) == 0);
    CU_ASSERT_FATAL(dmi_tangent_run(c.t, steps, 0, c.dWU, c.U, c.X, c.S, NULL, c.sw) == DMI_OK);
    const size_t reversals = count_switches(&c, DMI_SWITCH_REVERSAL);
    CU_ASSERT(reversals >= 1);
    /* differences over 2e-3 relative: each switching time moves by about 1e-3, 5 steps */
    const double with = against_differences(&c, h, 1e-3, 0, steps);
    CU_ASSERT_FATAL(dmi_init(c.s) == DMI_OK);
    CU_ASSERT_FATAL(dmi_tangent_run(c.t, steps, DMI_TANGENT_PLAIN, c.dWU, NULL, NULL, c.S, NULL,
                                    NULL) == DMI_OK);
    const double without = against_differences(&c, h, 1e-3, 0, steps);
    printf("  %zu reversal(s); against differences: %.3g with the saltation, %.3g without\n",
           reversals, with, without);
    CU_ASSERT(with < 0.02);
    CU_ASSERT(without > 0.1);
    setup_free(&c);
}

/* The history's S sampled by libdmi from the history callbacks is the
 * difference of the initialised windows, bit for bit; a failing history
 * callback is named and leaves the object as it was. */
static void test_sampled_history(void)
{
    const double h = 0.01;
    const size_t steps = 300;
    setup c;
    CU_ASSERT_FATAL(setup_make(&c, h, steps, 0) == 0);
    const size_t count = (steps + 1) * n * P;
    double *S1 = malloc(count * sizeof *S1);
    CU_ASSERT_FATAL(S1 != NULL);
    CU_ASSERT_FATAL(dmi_tangent_run(c.t, steps, 0, c.dWU, NULL, NULL, S1, NULL, NULL) == DMI_OK);
    int any = 0; /* (the history moves with z0 only) */
    for (size_t k = 0; k < (c.N + 1) * n * P; k++)
        any |= c.S0[k] != 0 && k % P != 3;
    CU_ASSERT(!any);
    CU_ASSERT_FATAL(dmi_init(c.s) == DMI_OK);
    CU_ASSERT_FATAL(dmi_tangent_set_history(c.t, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_tangent_sample_history(c.t, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_tangent_run(c.t, steps, 0, c.dWU, NULL, NULL, c.S, NULL, NULL) == DMI_OK);
    CU_ASSERT(memcmp(S1, c.S, count * sizeof *S1) == 0);
    /* only z0's column asked for: the same, as the others are 0 */
    const int only_z0[P] = {0, 0, 0, 1};
    CU_ASSERT_FATAL(dmi_init(c.s) == DMI_OK);
    CU_ASSERT_FATAL(dmi_tangent_sample_history(c.t, only_z0) == DMI_OK);
    CU_ASSERT_FATAL(dmi_tangent_run(c.t, steps, 0, c.dWU, NULL, NULL, c.S, NULL, NULL) == DMI_OK);
    CU_ASSERT(memcmp(S1, c.S, count * sizeof *S1) == 0);
    /* none asked for: S^0 = 0 */
    const int none[P] = {0, 0, 0, 0};
    CU_ASSERT_FATAL(dmi_init(c.s) == DMI_OK);
    CU_ASSERT_FATAL(dmi_tangent_sample_history(c.t, none) == DMI_OK);
    CU_ASSERT_FATAL(dmi_tangent_run(c.t, 1, 0, NULL, NULL, NULL, c.S, NULL, NULL) == DMI_OK);
    CU_ASSERT(c.S[3] == 0.0 && c.S[n * P - 1] == 0.0);
    free(S1);
    setup_free(&c);
}

/* A resolvent callback (differenced by the loop) against the built-in box it
 * computes (its hold rule): u' + a u = cos 2t clipped to [-0.4, b], p = (a, b). */
typedef struct {
    double a, b;
} clip_model;

static int clip_rhs(double t, const double *u, double *out, void *user)
{
    const clip_model *m = user;
    out[0] = m->a * u[0] - cos(2 * t);
    return 0;
}

static int clip_resolvent(double lambda, const double *x, double *out, void *user)
{
    const clip_model *m = user;
    (void)lambda;
    out[0] = x[0] < -0.4 ? -0.4 : x[0] > m->b ? m->b : x[0];
    return 0;
}

static dmi_solver *clip_solver(clip_model *m, int callback)
{
    dmi_solver *s = NULL;
    const double lo[1] = {-0.4}, hi[1] = {m->b};
    if (dmi_create(&s, 1, 1.0, 50) != DMI_OK)
        return NULL;
    int rc = dmi_set_rhs(s, clip_rhs, m);
    rc |= callback ? dmi_set_resolvent(s, clip_resolvent, m) : dmi_set_box(s, lo, hi);
    if (rc != DMI_OK || dmi_init(s) != DMI_OK)
        dmi_free(&s);
    return s;
}

static void test_resolvent_callback(void)
{
    enum { STEPS = 400, NP = 2 };
    double S[2][(STEPS + 1) * NP];
    signed char sw[STEPS];
    size_t clipped = 0;
    for (int callback = 0; callback <= 1; callback++) {
        clip_model base = {0.5, 0.3}, pert[NP] = {{0.5 + 0x1p-26, 0.3}, {0.5, 0.3 + 0x1p-26}};
        dmi_solver *s = clip_solver(&base, callback);
        dmi_solver *o[NP] = {clip_solver(&pert[0], callback), clip_solver(&pert[1], callback)};
        const double delta[NP] = {pert[0].a - base.a, pert[1].b - base.b};
        CU_ASSERT_FATAL(s && o[0] && o[1]);
        dmi_tangent *t = NULL;
        double U[STEPS + 1];
        CU_ASSERT_FATAL(dmi_tangent_create(&t, s, NP, (const dmi_solver *const *)o, delta) ==
                        DMI_OK);
        CU_ASSERT_FATAL(dmi_tangent_run(t, STEPS, 0, NULL, U, NULL, S[callback], NULL, sw) ==
                        DMI_OK);
        for (size_t q = 1; callback && q <= STEPS; q++)
            clipped += U[q] == 0.3 || U[q] == -0.4;
        dmi_tangent_free(&t);
        dmi_free(&o[0]);
        dmi_free(&o[1]);
        dmi_free(&s);
    }
    double diff = 0;
    for (size_t k = 0; k < (STEPS + 1) * NP; k++)
        diff = fmax(diff, fabs(S[0][k] - S[1][k]) / (1 + fabs(S[0][k])));
    printf("  resolvent callback against the box: %.3g (%zu clipped steps)\n", diff, clipped);
    CU_ASSERT(clipped > 20 && clipped < STEPS - 20);
    CU_ASSERT(diff < 1e-6);
}

/* A failing callback leaves the solver bitwise where it was, with a message
 * naming the model; the refusals name their argument. */
static void test_failures_and_refusals(void)
{
    const double h = 0.01;
    const size_t steps = 200;
    setup c;
    CU_ASSERT_FATAL(setup_make(&c, h, steps, 0) == 0);
    CU_ASSERT_FATAL(dmi_advance(c.s, 7) == DMI_OK);
    size_t before_size = 0, after_size = 0;
    unsigned char *before = core_save(c.s, &before_size);
    CU_ASSERT_FATAL(before != NULL);
    c.pert[1].fail_at = 50; /* others[1]'s f, in the tangent */
    CU_ASSERT(dmi_tangent_run(c.t, steps, 0, NULL, NULL, NULL, c.S, NULL, NULL) ==
              DMI_ECALLBACK);
    CU_ASSERT(strstr(dmi_last_error(c.s), "others[1]") != NULL);
    unsigned char *after = core_save(c.s, &after_size);
    CU_ASSERT_FATAL(after != NULL);
    CU_ASSERT(before_size == after_size && memcmp(before, after, before_size) == 0);
    free(after);
    c.pert[1].fail_at = 0;
    c.base.fail_at = c.base.calls + 30; /* s's own f, in the plain run */
    CU_ASSERT(dmi_tangent_run(c.t, steps, 0, NULL, NULL, NULL, c.S, NULL, NULL) ==
              DMI_ECALLBACK);
    after = core_save(c.s, &after_size);
    CU_ASSERT_FATAL(after != NULL);
    CU_ASSERT(before_size == after_size && memcmp(before, after, before_size) == 0);
    free(after);
    free(before);
    c.base.fail_at = 0;
    /* refusals */
    CU_ASSERT(dmi_tangent_run(c.t, 0, 0, NULL, NULL, NULL, c.S, NULL, NULL) == DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(c.s), "steps = 0") != NULL);
    CU_ASSERT(dmi_tangent_run(c.t, 5, 4, NULL, NULL, NULL, c.S, NULL, NULL) == DMI_EINVAL);
    CU_ASSERT(dmi_tangent_run(c.t, 5, 0, NULL, NULL, NULL, NULL, NULL, NULL) == DMI_EINVAL);
    dmi_tangent *t2 = NULL;
    double bad[P] = {1e-8, 0.0, 1e-8, 1e-8};
    CU_ASSERT(dmi_tangent_create(&t2, c.s, P, (const dmi_solver *const *)c.others, bad) ==
              DMI_EINVAL && t2 == NULL);
    CU_ASSERT(strstr(dmi_last_error(c.s), "delta[1]") != NULL);
    dmi_solver *other_n = NULL;
    CU_ASSERT_FATAL(dmi_create_h(&other_n, 3, TAU, h) == DMI_OK);
    const dmi_solver *mixed[P] = {c.others[0], other_n, c.others[2], c.others[3]};
    CU_ASSERT(dmi_tangent_create(&t2, c.s, P, mixed, c.delta) == DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(c.s), "others[1] has another n") != NULL);
    dmi_free(&other_n);
    CU_ASSERT(dmi_tangent_create(&t2, c.s, 0, (const dmi_solver *const *)c.others, c.delta) ==
              DMI_EINVAL);
    c.S0[5] = NAN;
    CU_ASSERT(dmi_tangent_set_history(c.t, c.S0) == DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(c.s), "S0 row 0, component 1, parameter 1") != NULL);
    dmi_solver *fresh = NULL;
    CU_ASSERT_FATAL(dmi_create_h(&fresh, n, TAU, h) == DMI_OK);
    CU_ASSERT(dmi_tangent_create(&t2, fresh, 1, (const dmi_solver *const *)c.others, c.delta) ==
              DMI_EINVAL); /* others[0] has friction, fresh has none */
    const dmi_solver *self[1] = {fresh};
    CU_ASSERT_FATAL(dmi_tangent_create(&t2, fresh, 1, self, c.delta) == DMI_OK);
    CU_ASSERT(dmi_tangent_run(t2, 3, 0, NULL, NULL, NULL, c.S, NULL, NULL) == DMI_ESTATE);
    dmi_tangent_free(&t2);
    dmi_tangent_free(&t2); /* (NULL: nothing) */
    dmi_free(&fresh);
    setup_free(&c);
}

CORE_MAIN("core: the tangent of the scheme",
          {"the plain tangent is the scheme's derivative", test_plain_tangent_is_the_schemes_derivative},
          {"the saltation follows the equation through reversals", test_saltation_follows_the_equation},
          {"the history's S sampled from its callbacks", test_sampled_history},
          {"a resolvent callback against the built-in box", test_resolvent_callback},
          {"failures leave the solver as it was; refusals", test_failures_and_refusals})
