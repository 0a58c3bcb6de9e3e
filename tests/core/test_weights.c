/*
 * dmi_get_kernel_weights (libdmi 1.5): the delay sum's weights G_l against
 * closed forms written here, for every way dmi_init computes them:
 * - the left rule, a callback kernel: h H(l h), and theta h H((N-1) h) for a
 *   partial last cell (dmi_create_h);
 * - an exponential kernel under RECURSIVE (no samples kept by dmi_init):
 *   h C e^{a l h}; under the cell rule: C (e^{a (l+1) h} - e^{a l h}) / a;
 * - the cell rule, a callback kernel s^-1/2 (1 + s): its cells' integrals to
 *   1e-10 (relative);
 * - near cells (an exponential sum with the near kernel s^-1/2): the near
 *   cells' integrals of s^-1/2, the sum's cell weights beyond, and G_near the
 *   difference on the near cells, zero beyond;
 * - an n = 2 kernel with one nonzero entry: placed row-major;
 * - the step's W (dmi_get_step_terms) is sum_l G_l U^{p-l} over the window,
 *   for RECURSIVE with near cells and for DIRECT;
 * - a slice of lags is the same slice of the whole;
 * - NULL, both arrays NULL, lags beyond N, before dmi_init: refused.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core_test.h"

/* e^{-s} (n = 1). */
static int decay(double s, double *out, void *user)
{
    (void)user;
    out[0] = exp(-s);
    return 0;
}

/* s^-1/2 (1 + s) (n = 1). */
static int singular(double s, double *out, void *user)
{
    (void)user;
    out[0] = (1 + s) / sqrt(s);
    return 0;
}

/* s^-1/2 (n = 1). */
static int half(double s, double *out, void *user)
{
    (void)user;
    out[0] = 1 / sqrt(s);
    return 0;
}

/* [[0, e^{-s}], [0, 0]] (n = 2). */
static int corner(double s, double *out, void *user)
{
    (void)user;
    out[1] = exp(-s);
    return 0;
}

/* int_0^x s^-1/2 (1 + s) ds */
static double singular_integral(double x)
{
    return 2 * sqrt(x) + 2.0 / 3.0 * x * sqrt(x);
}

/* z(t) = cos(3 t) + 0.2 t (n = 1): values that tell the lags apart. */
static int wave(double t, double *out, void *user)
{
    (void)user;
    out[0] = cos(3 * t) + 0.2 * t;
    return 0;
}

enum { NC = 16 };

/* A new initialised solver of n components, tau = 1, N = NC, with the kernel
 * callback H under the quadrature rule. */
static dmi_solver *callback_solver(size_t n, dmi_kernel_fn H, int rule)
{
    dmi_solver *s = NULL;
    CU_ASSERT_FATAL(dmi_create(&s, n, 1.0, NC) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_kernel(s, H, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_quadrature(s, rule) == DMI_OK);
    CU_ASSERT_FATAL(dmi_init(s) == DMI_OK);
    return s;
}

static void test_left_callback(void)
{
    const double h = 1.0 / NC;
    dmi_solver *s = callback_solver(1, decay, DMI_QUAD_LEFT);
    double G[NC], G_near[NC];
    CU_ASSERT_FATAL(dmi_get_kernel_weights(s, 0, NC, G, G_near) == DMI_OK);
    int ok = 1;
    for (size_t l = 0; l < NC; l++)
        ok &= core_close_rel("left rule weight", G[l], h * exp(-(double)l * h), 1e-15) &&
              G_near[l] == 0.0;
    CU_ASSERT(ok);
    dmi_free(&s);
    /* a partial last cell: tau = 1, h = 0.07, N = 15, theta h = 1 - 14 * 0.07 */
    CU_ASSERT_FATAL(dmi_create_h(&s, 1, 1.0, 0.07) == DMI_OK);
    CU_ASSERT_FATAL(dmi_get_N(s) == 15);
    CU_ASSERT_FATAL(dmi_set_kernel(s, decay, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_init(s) == DMI_OK);
    double G15[15];
    CU_ASSERT_FATAL(dmi_get_kernel_weights(s, 0, 15, G15, NULL) == DMI_OK);
    ok = 1;
    for (size_t l = 0; l < 14; l++)
        ok &= core_close_rel("left rule weight", G15[l], 0.07 * exp(-0.07 * (double)l), 1e-15);
    ok &= core_close_rel("partial last cell", G15[14], (1.0 - 14 * 0.07) * exp(-0.07 * 14), 1e-13);
    CU_ASSERT(ok);
    dmi_free(&s);
}

static void test_exponential(void)
{
    const double a[1] = {-0.8}, b[1] = {0.0}, C[1] = {1.5}, h = 1.0 / NC;
    for (int rule = DMI_QUAD_LEFT; rule <= DMI_QUAD_CELL; rule++) {
        dmi_solver *s = NULL;
        CU_ASSERT_FATAL(dmi_create(&s, 1, 1.0, NC) == DMI_OK);
        CU_ASSERT_FATAL(dmi_set_kernel_exp(s, 1, a, b, C, NULL) == DMI_OK);
        CU_ASSERT_FATAL(dmi_set_quadrature(s, rule) == DMI_OK);
        CU_ASSERT_FATAL(dmi_set_convolution(s, DMI_CONV_RECURSIVE) == DMI_OK);
        CU_ASSERT_FATAL(dmi_init(s) == DMI_OK);
        double G[NC];
        CU_ASSERT_FATAL(dmi_get_kernel_weights(s, 0, NC, G, NULL) == DMI_OK);
        int ok = 1;
        for (size_t l = 0; l < NC; l++) {
            const double lo = (double)l * h, want =
                rule == DMI_QUAD_LEFT ? h * C[0] * exp(a[0] * lo)
                                      : C[0] * (exp(a[0] * (lo + h)) - exp(a[0] * lo)) / a[0];
            ok &= core_close_rel(rule == DMI_QUAD_LEFT ? "exp, left" : "exp, cell", G[l], want,
                                 1e-13);
        }
        CU_ASSERT(ok);
        dmi_free(&s);
    }
}

static void test_cell_callback(void)
{
    const double h = 1.0 / NC;
    dmi_solver *s = callback_solver(1, singular, DMI_QUAD_CELL);
    double G[NC];
    CU_ASSERT_FATAL(dmi_get_kernel_weights(s, 0, NC, G, NULL) == DMI_OK);
    int ok = 1;
    for (size_t l = 0; l < NC; l++)
        ok &= core_close_rel("cell rule weight", G[l],
                             singular_integral((double)(l + 1) * h) -
                                 singular_integral((double)l * h),
                             1e-10);
    CU_ASSERT(ok);
    dmi_free(&s);
}

/* u' + W = 0 with the sum 0.9 e^{-2 s} for the far cells and s^-1/2 on the
 * first three cells (delta = 2.5 h: m = 3), the cell rule, method. */
static dmi_solver *near_solver(int method)
{
    const double a[1] = {-2.0}, b[1] = {0.0}, C[1] = {0.9};
    dmi_solver *s = NULL;
    CU_ASSERT_FATAL(dmi_create(&s, 1, 1.0, NC) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_kernel_exp(s, 1, a, b, C, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_kernel_near(s, half, NULL, 2.5 / NC) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_quadrature(s, DMI_QUAD_CELL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_convolution(s, method) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_history(s, wave, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_init(s) == DMI_OK);
    return s;
}

static void test_near_cells(void)
{
    const double h = 1.0 / NC;
    dmi_solver *s = near_solver(DMI_CONV_RECURSIVE);
    double G[NC], G_near[NC];
    CU_ASSERT_FATAL(dmi_get_kernel_weights(s, 0, NC, G, G_near) == DMI_OK);
    int ok = 1;
    for (size_t l = 0; l < NC; l++) {
        const double lo = (double)l * h, hi = lo + h;
        const double sum = 0.9 * (exp(-2 * hi) - exp(-2 * lo)) / -2.0;
        const double exact = 2 * (sqrt(hi) - sqrt(lo));
        if (l < 3) {
            ok &= core_close_rel("near cell", G[l], exact, 1e-10);
            ok &= core_close_rel("near part", G_near[l], exact - sum, 1e-10);
        } else {
            ok &= core_close_rel("far cell", G[l], sum, 1e-13) && G_near[l] == 0.0;
        }
    }
    CU_ASSERT(ok);
    dmi_free(&s);
}

static void test_matrix_entry(void)
{
    const double h = 1.0 / NC;
    dmi_solver *s = callback_solver(2, corner, DMI_QUAD_LEFT);
    double G[4 * NC];
    CU_ASSERT_FATAL(dmi_get_kernel_weights(s, 0, NC, G, NULL) == DMI_OK);
    int ok = 1;
    for (size_t l = 0; l < NC; l++)
        ok &= G[4 * l] == 0.0 && G[4 * l + 2] == 0.0 && G[4 * l + 3] == 0.0 &&
              core_close_rel("entry (0, 1)", G[4 * l + 1], h * exp(-(double)l * h), 1e-15);
    CU_ASSERT(ok);
    dmi_free(&s);
}

/* W^{p-1} of the last step against sum_l G_l U^{p-1-l} from the window. */
static void check_step_sum(int method)
{
    dmi_solver *s = near_solver(method);
    CU_ASSERT_FATAL(dmi_advance(s, 5) == DMI_OK);
    double U[NC + 1], G[NC], W, X;
    CU_ASSERT_FATAL(dmi_get_window(s, U) == DMI_OK); /* U[k] = U^{p-N+k}, p = 5 */
    CU_ASSERT_FATAL(dmi_get_kernel_weights(s, 0, NC, G, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_get_step_terms(s, &W, &X) == DMI_OK);
    /* the last step's sum reads U^{4-l}, l < N: U^{4-l} = U[NC - 1 - l] ... down to
     * U^{4-N+1} = U[0] */
    double want = 0.0, size = 0.0;
    for (size_t l = 0; l < NC; l++) {
        want += G[l] * U[NC - 1 - l];
        size += fabs(G[l] * U[NC - 1 - l]);
    }
    CU_ASSERT(fabs(W - want) <= 1e-14 * size);
    dmi_free(&s);
}

static void test_step_sum(void)
{
    check_step_sum(DMI_CONV_RECURSIVE);
    check_step_sum(DMI_CONV_DIRECT);
}

static void test_slice(void)
{
    dmi_solver *s = near_solver(DMI_CONV_AUTO);
    double G[NC], G_near[NC], part[5], part_near[5];
    CU_ASSERT_FATAL(dmi_get_kernel_weights(s, 0, NC, G, G_near) == DMI_OK);
    CU_ASSERT_FATAL(dmi_get_kernel_weights(s, 2, 5, part, part_near) == DMI_OK);
    CU_ASSERT(memcmp(part, G + 2, sizeof part) == 0);
    CU_ASSERT(memcmp(part_near, G_near + 2, sizeof part_near) == 0);
    CU_ASSERT_EQUAL(dmi_get_kernel_weights(s, NC, 0, G, NULL), DMI_OK); /* nothing asked */
    dmi_free(&s);
}

static void test_refused(void)
{
    double G[NC];
    CU_ASSERT_EQUAL(dmi_get_kernel_weights(NULL, 0, 1, G, NULL), DMI_EINVAL);
    dmi_solver *s = NULL;
    CU_ASSERT_FATAL(dmi_create(&s, 1, 1.0, NC) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_kernel(s, decay, NULL) == DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_kernel_weights(s, 0, 1, G, NULL), DMI_ESTATE);
    CU_ASSERT(strstr(dmi_last_error(s), "dmi_init") != NULL);
    CU_ASSERT_FATAL(dmi_init(s) == DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_kernel_weights(s, 0, 1, NULL, NULL), DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(s), "NULL") != NULL);
    CU_ASSERT_EQUAL(dmi_get_kernel_weights(s, 10, NC - 9, G, NULL), DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(s), "N = 16") != NULL);
    CU_ASSERT_EQUAL(dmi_get_kernel_weights(s, NC + 1, 0, G, NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_get_kernel_weights(s, 1, (size_t)-1, G, NULL), DMI_EINVAL);
    dmi_free(&s);
}

CORE_MAIN("core: the delay sum's weights",
          {"the left rule: h H(l h), a partial last cell theta h", test_left_callback},
          {"an exponential kernel, RECURSIVE: left and cell rule in closed form", test_exponential},
          {"the cell rule, s^-1/2 (1 + s): the cells' integrals", test_cell_callback},
          {"near cells: their integrals, the sum's weights beyond, G_near", test_near_cells},
          {"an n = 2 kernel: row-major", test_matrix_entry},
          {"the step's W is sum_l G_l U^{p-l} (RECURSIVE with near cells, DIRECT)",
           test_step_sum},
          {"a slice of lags", test_slice},
          {"NULL, no array, lags beyond N, before init: refused", test_refused})
