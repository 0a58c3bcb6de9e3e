/*
 * dmi_set_quadrature (libdmi 1.3): the exact cell rule.
 * - the default and DMI_QUAD_LEFT set explicitly give bitwise the same runs;
 * - the cell weights against integrals written here: H = e^{-2s} cos 3s
 *   (its antiderivative), s^-1/2 through a callback (2 (sqrt b - sqrt a)),
 *   with h = tau / N and with a partial last cell (dmi_create_h);
 * - DIRECT, FFT, RECURSIVE and AUTO agree under the cell rule, for the
 *   exponential kernel and for the same kernel as a callback (tanh-sinh);
 * - dmi_set_kernel_near: W^0 against the exact integrals of a near kernel
 *   that differs from the sum (2 e^{-s} below delta, e^{-s} beyond), every
 *   method the same, the recursion's sum and the near cells together; errors;
 * - errors: an unknown rule, a call after dmi_init; a kernel callback that
 *   fails inside the cells' quadrature leaves the solver as it was.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core_test.h"

/* H(s) = e^{-2 s} cos 3 s as one exponential term, and as a callback. */
static const double KA[1] = {-2}, KB[1] = {3}, KC[1] = {1};

static int exp_kernel(double s, double *out, void *user)
{
    (void)user;
    out[0] = exp(-2 * s) * cos(3 * s);
    return 0;
}

/* int_0^x e^{-2 s} cos 3 s ds = [e^{-2 s} (3 sin 3 s - 2 cos 3 s)] / 13 from 0 to x. */
static double exp_antiderivative(double x)
{
    return (exp(-2 * x) * (3 * sin(3 * x) - 2 * cos(3 * x)) + 2) / 13;
}

static int power_kernel(double s, double *out, void *user)
{
    (void)user;
    out[0] = 1 / sqrt(s); /* infinite at 0: must never be called there */
    return s > 0 ? 0 : 1;
}

/* e^{-s} as a sum, and 2 e^{-s} for the near cells (dmi_set_kernel_near). */
static const double NA[1] = {-1}, NB[1] = {0}, NC[1] = {1};

static int twice_exp(double s, double *out, void *user)
{
    (void)user;
    out[0] = 2 * exp(-s);
    return 0;
}

/* A solver for u' + W = 0 (n = 1) with the kernel (0 exponential, 1 exp
 * callback, 2 power callback, 3 e^{-s} as a sum with 2 e^{-s} on the cells
 * below delta), the history z, the rule and method; h > 0: dmi_create_h,
 * else N cells.  Initialised, or NULL. */
static dmi_solver *solver_near(int kernel, dmi_history_fn z, int rule, int method, double tau,
                               size_t N, double h, double delta)
{
    dmi_solver *s = NULL;
    int rc = h > 0 ? dmi_create_h(&s, 1, tau, h) : dmi_create(&s, 1, tau, N);
    if (rc == DMI_OK)
        rc = kernel == 0   ? dmi_set_kernel_exp(s, 1, KA, KB, KC, NULL)
             : kernel == 1 ? dmi_set_kernel(s, exp_kernel, NULL)
             : kernel == 2 ? dmi_set_kernel(s, power_kernel, NULL)
                           : dmi_set_kernel_exp(s, 1, NA, NB, NC, NULL);
    if (rc == DMI_OK && kernel == 3)
        rc = dmi_set_kernel_near(s, twice_exp, NULL, delta);
    if (rc == DMI_OK)
        rc = dmi_set_history(s, z, NULL);
    if (rc == DMI_OK && rule >= 0)
        rc = dmi_set_quadrature(s, rule);
    if (rc == DMI_OK)
        rc = dmi_set_convolution(s, method);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    if (rc != DMI_OK) {
        printf("\n  solver(kernel %d, rule %d, method %d): %s\n", kernel, rule, method,
               dmi_last_error(s));
        dmi_free(&s);
    }
    return s;
}

static dmi_solver *solver(int kernel, dmi_history_fn z, int rule, int method, double tau, size_t N,
                          double h)
{
    return solver_near(kernel, z, rule, method, tau, N, h, 0);
}

/* U after steps more steps of s (NAN if a step fails). */
static double state_after(dmi_solver *s, size_t steps)
{
    double u = NAN;
    if (dmi_advance(s, steps) != DMI_OK || dmi_get_state(s, &u) != DMI_OK)
        return NAN;
    return u;
}

/* W^0 of s (one step taken). */
static double first_W(dmi_solver *s)
{
    double W = NAN;
    if (dmi_step(s) != DMI_OK || dmi_get_step_terms(s, &W, NULL) != DMI_OK)
        return NAN;
    return W;
}

static void test_default_is_left_bitwise(void)
{
    for (int method = DMI_CONV_DIRECT; method <= DMI_CONV_RECURSIVE; method++) {
        dmi_solver *a = solver(0, core_z_wave, -1, method, 1.0, 200, 0);
        dmi_solver *b = solver(0, core_z_wave, DMI_QUAD_LEFT, method, 1.0, 200, 0);
        dmi_solver *c = solver(0, core_z_wave, DMI_QUAD_CELL, method, 1.0, 200, 0);
        CU_ASSERT_FATAL(a && b && c);
        CU_ASSERT_EQUAL(dmi_advance(a, 700), DMI_OK);
        CU_ASSERT_EQUAL(dmi_advance(b, 700), DMI_OK);
        CU_ASSERT_EQUAL(dmi_advance(c, 700), DMI_OK);
        CU_ASSERT(core_same_state(a, b));
        CU_ASSERT(!core_same_state(a, c)); /* the cell rule is another sum */
        dmi_free(&a);
        dmi_free(&b);
        dmi_free(&c);
    }
}

/* W^0 = sum_l w_l z(-l h) with w_l the exact integrals, computed here. */
static double exact_W0(double tau, size_t N, double h, double (*F)(double), double (*z)(double))
{
    double W = 0;
    for (size_t l = 0; l < N; l++) {
        double lo = (double)l * h, hi = l + 1 == N ? tau : (double)(l + 1) * h;
        W += (F(hi) - F(lo)) * z(-(double)l * h);
    }
    return W;
}

static double cos5(double t)
{
    return cos(5 * t);
}

static double sqrt2(double x)
{
    return 2 * sqrt(x);
}

static double unit(double t)
{
    (void)t;
    return 1;
}

static void test_weights_against_integrals(void)
{
    /* (tau, N, h): h = tau / N, and a partial last cell */
    const double cases[3][3] = {{1.0, 40, 0}, {1.0, 0, 0.0237}, {2.0, 0, 0.3}};
    for (int c = 0; c < 3; c++) {
        double tau = cases[c][0], hgiven = cases[c][2];
        size_t Ngiven = (size_t)cases[c][1];
        for (int kernel = 0; kernel <= 2; kernel++) {
            dmi_solver *s = solver(kernel, kernel == 2 ? core_z_one : core_z_wave, DMI_QUAD_CELL,
                                   DMI_CONV_DIRECT, tau, Ngiven, hgiven);
            CU_ASSERT_FATAL(s != NULL);
            size_t N = dmi_get_N(s);
            double h = dmi_get_h(s);
            double ref = kernel == 2 ? exact_W0(tau, N, h, sqrt2, unit)
                                     : exact_W0(tau, N, h, exp_antiderivative, cos5);
            double got = first_W(s);
            char what[96];
            snprintf(what, sizeof what, "W^0, kernel %d, tau %g, N %zu, h %g", kernel, tau, N, h);
            CU_ASSERT(core_close_rel(what, got, ref, kernel == 2 ? 1e-12 : 1e-13));
            if (kernel == 2) /* the cells add up to int_0^tau s^-1/2 = 2 sqrt(tau) */
                CU_ASSERT(core_close_rel("sum of the power kernel's cells", got, 2 * sqrt(tau),
                                         1e-12));
            dmi_free(&s);
        }
    }
}

static void test_engines_agree(void)
{
    const double hs[2] = {0, 0.0213};
    for (int hi = 0; hi < 2; hi++)
        for (int kernel = 0; kernel <= 1; kernel++) {
            dmi_solver *ref =
                solver(kernel, core_z_wave, DMI_QUAD_CELL, DMI_CONV_DIRECT, 1.0, 500, hs[hi]);
            CU_ASSERT_FATAL(ref != NULL);
            const double u_ref = state_after(ref, 1200);
            const int methods[3] = {DMI_CONV_FFT, DMI_CONV_RECURSIVE, DMI_CONV_AUTO};
            for (int m = 0; m < 3; m++) {
                if (kernel == 1 && methods[m] == DMI_CONV_RECURSIVE)
                    continue; /* (a callback runs no recursion) */
                dmi_solver *s =
                    solver(kernel, core_z_wave, DMI_QUAD_CELL, methods[m], 1.0, 500, hs[hi]);
                CU_ASSERT_FATAL(s != NULL);
                char what[64];
                snprintf(what, sizeof what, "kernel %d, h %g, method %d", kernel, hs[hi], methods[m]);
                CU_ASSERT(core_close_rel(what, state_after(s, 1200), u_ref, 1e-12));
                dmi_free(&s);
            }
            /* the callback's tanh-sinh weights equal the closed form's */
            dmi_solver *x =
                solver(1 - kernel, core_z_wave, DMI_QUAD_CELL, DMI_CONV_DIRECT, 1.0, 500, hs[hi]);
            CU_ASSERT_FATAL(x != NULL);
            CU_ASSERT(core_close_rel("callback vs closed form", state_after(x, 1200), u_ref, 1e-12));
            dmi_free(&x);
            dmi_free(&ref);
        }
}

/* e^{-2 s} cos 3 s, failing once *user (a call budget) is spent. */
static int budget_kernel(double s, double *out, void *user)
{
    long *left = user;
    if ((*left)-- <= 0)
        return 7;
    return exp_kernel(s, out, NULL);
}

static void test_failed_init_leaves_solver(void)
{
    long left = 1000000;
    dmi_solver *s = NULL;
    CU_ASSERT_FATAL(dmi_create_h(&s, 1, 1.0, 0.0213) == DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel(s, budget_kernel, &left), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_history(s, core_z_wave, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_quadrature(s, DMI_QUAD_CELL), DMI_OK);
    CU_ASSERT_FATAL(dmi_init(s) == DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(s, 30), DMI_OK);
    size_t size = 0;
    unsigned char *before = core_save(s, &size);
    CU_ASSERT_FATAL(before != NULL);
    left = 500; /* the quadrature of the cells runs out of calls: the restart fails */
    CU_ASSERT_EQUAL(dmi_init(s), DMI_ECALLBACK);
    CU_ASSERT(strstr(dmi_last_error(s), "kernel callback returned 7") != NULL);
    CU_ASSERT(core_state_is(s, before, size));
    /* stepping on is the run that never restarted */
    dmi_solver *ref = solver(1, core_z_wave, DMI_QUAD_CELL, DMI_CONV_AUTO, 1.0, 0, 0.0213);
    CU_ASSERT_FATAL(ref != NULL);
    CU_ASSERT_EQUAL(dmi_advance(ref, 30), DMI_OK);
    CU_ASSERT(core_close_rel("after a failed restart", state_after(s, 40), state_after(ref, 40), 0));
    free(before);
    dmi_free(&ref);
    dmi_free(&s);
}

static void test_errors(void)
{
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL(dmi_set_quadrature(NULL, DMI_QUAD_CELL), DMI_EINVAL);
    CU_ASSERT_FATAL(dmi_create(&s, 1, 1.0, 10) == DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_quadrature(s, 2), DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(s), "unknown rule 2") != NULL);
    CU_ASSERT_EQUAL(dmi_set_quadrature(s, -1), DMI_EINVAL);
    /* the left rule samples H(0): the power kernel's callback refuses s = 0 */
    CU_ASSERT_EQUAL(dmi_set_kernel(s, power_kernel, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_ECALLBACK);
    CU_ASSERT_EQUAL(dmi_set_quadrature(s, DMI_QUAD_CELL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_quadrature(s, DMI_QUAD_LEFT), DMI_ESTATE);
    CU_ASSERT(strstr(dmi_last_error(s), "dmi_init") != NULL);
    dmi_free(&s);
}

static void test_near_cells(void)
{
    const double hs[2] = {0, 0.0237};
    for (int hi = 0; hi < 2; hi++)
        for (int method = DMI_CONV_DIRECT; method <= DMI_CONV_RECURSIVE; method++) {
            /* z = 1: W^0 = int_0^{m h} 2 e^{-s} + int_{m h}^tau e^{-s}, m = ceil(delta / h) */
            dmi_solver *s =
                solver_near(3, core_z_one, DMI_QUAD_CELL, method, 1.0, 100, hs[hi], 0.05);
            CU_ASSERT_FATAL(s != NULL);
            const double h = dmi_get_h(s), mh = ceil(0.05 / h) * h;
            const double ref = 2 * (1 - exp(-mh)) + (exp(-mh) - exp(-1.0));
            char what[64];
            snprintf(what, sizeof what, "W^0 with near cells, h %g, method %d", h, method);
            CU_ASSERT(core_close_rel(what, first_W(s), ref, 1e-13));
            dmi_free(&s);
        }
    /* a wave history over many steps (the recursion anchored and run): every method the same */
    dmi_solver *ref =
        solver_near(3, core_z_wave, DMI_QUAD_CELL, DMI_CONV_DIRECT, 1.0, 300, 0, 0.02);
    CU_ASSERT_FATAL(ref != NULL);
    const double u_ref = state_after(ref, 2000);
    for (int method = DMI_CONV_FFT; method <= DMI_CONV_RECURSIVE; method++) {
        dmi_solver *s = solver_near(3, core_z_wave, DMI_QUAD_CELL, method, 1.0, 300, 0, 0.02);
        CU_ASSERT_FATAL(s != NULL);
        CU_ASSERT(core_close_rel("near cells, method against DIRECT", state_after(s, 2000), u_ref,
                                 1e-12));
        dmi_free(&s);
    }
    dmi_free(&ref);
}

static void test_near_errors(void)
{
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL(dmi_set_kernel_near(NULL, twice_exp, NULL, 0.1), DMI_EINVAL);
    CU_ASSERT_FATAL(dmi_create(&s, 1, 1.0, 10) == DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel_near(s, twice_exp, NULL, -0.1), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_kernel_near(s, twice_exp, NULL, NAN), DMI_EINVAL);
    /* a callback kernel has no sum to complete */
    CU_ASSERT_EQUAL(dmi_set_kernel(s, exp_kernel, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel_near(s, twice_exp, NULL, 0.1), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(s), "dmi_set_kernel_exp") != NULL);
    /* the near cells must leave the last cell to the sum: delta = 0.95 is 10 of 10 cells */
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 1, NA, NB, NC, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel_near(s, twice_exp, NULL, 0.95), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(s), "near cells") != NULL);
    CU_ASSERT_EQUAL(dmi_set_kernel_near(s, twice_exp, NULL, 0.85), DMI_OK); /* 9 cells */
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel_near(s, NULL, NULL, 0), DMI_ESTATE);
    dmi_free(&s);
}

CORE_MAIN("quad",
          {"default and DMI_QUAD_LEFT bitwise the same", test_default_is_left_bitwise},
          {"cell weights against exact integrals", test_weights_against_integrals},
          {"every engine, the same sum", test_engines_agree},
          {"errors", test_errors},
          {"a failed restart leaves the solver as it was", test_failed_init_leaves_solver},
          {"near cells of a singular kernel", test_near_cells},
          {"near cells: errors", test_near_errors})
