/*
 * dmi_init prepares only what the chosen method uses (on libdmi's GSL-free
 * core, with the solver's private layout): under the recursion no kernel
 * samples are taken, and a switch to DIRECT after dmi_init takes them then,
 * so that it steps bitwise as a solver initialised with DIRECT; a restart
 * keeps the recursion's engine and steps bitwise as a fresh solver; a sample
 * that is not finite is named by the switch, which then leaves the method
 * as it was; dmi_create_h's partial cell (theta < 1), which needs the last
 * sample, still samples at dmi_init.  dmi_set_window, which checks the
 * window in blocks, names its first non-finite value.
 *
 *   n = 2, u' = (-u_1, u_0 + 1.3 cos 8t) + friction (0, 1), history
 *   (0.1 t, 0.2), H(s) = cos 2 pi s + cos 10 pi s + cos 20 pi s in entry
 *   (1, 0) as three exponential terms, tau = 1.
 *
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <CUnit/Basic.h>

#include "forced_oscillator.h"
#include "solver.h"

#define PI 3.14159265358979323846
enum { n = 2, STEPS = 3000 };


/* A solver of the model, the kernel's coefficients scaled by c, h = 1/N (or
 * h given, h > 0), method set before dmi_init; NULL on failure. */
static dmi_solver *solver(size_t N, double h, int method, double c)
{
    dmi_solver *s = NULL;
    const double alpha[n] = {0.0, 1.0}, a[3] = {0, 0, 0}, b[3] = {2 * PI, 10 * PI, 20 * PI};
    double C[3 * n * n] = {0};
    C[2] = C[6] = C[10] = c;
    if ((h > 0 ? dmi_create_h(&s, n, 1.0, h) : dmi_create(&s, n, 1.0, N)) != DMI_OK)
        return NULL;
    if (dmi_set_rhs(s, rhs, NULL) != DMI_OK || dmi_set_history(s, history, NULL) != DMI_OK ||
        dmi_set_friction(s, alpha) != DMI_OK || dmi_set_kernel_exp(s, 3, a, b, C, NULL) != DMI_OK ||
        dmi_set_convolution(s, method) != DMI_OK || dmi_init(s) != DMI_OK)
        dmi_free(&s);
    return s;
}

/* The state after steps steps. */
static void run(dmi_solver *s, size_t steps, double *U)
{
    CU_ASSERT_EQUAL_FATAL(dmi_advance(s, steps), DMI_OK);
    dmi_get_state(s, U);
}

static void test_recursion_takes_no_samples(void)
{
    dmi_solver *r = solver(500, 0, DMI_CONV_AUTO, 1.0), *d = solver(500, 0, DMI_CONV_DIRECT, 1.0);
    CU_ASSERT_PTR_NOT_NULL_FATAL(r);
    CU_ASSERT_PTR_NOT_NULL_FATAL(d);
    CU_ASSERT_PTR_NOT_NULL(r->rec);
    CU_ASSERT_EQUAL(r->kernel.nnz, 0); /* the recursion has none */
    CU_ASSERT_EQUAL(d->kernel.nnz, 1); /* DIRECT: entry (1, 0) */
    /* the switch at p = 0 samples: then bitwise DIRECT's run */
    CU_ASSERT_EQUAL_FATAL(dmi_set_convolution(r, DMI_CONV_DIRECT), DMI_OK);
    CU_ASSERT_EQUAL(r->kernel.nnz, 1);
    CU_ASSERT_PTR_NULL(r->rec);
    double a[n], b[n];
    run(r, STEPS, a);
    run(d, STEPS, b);
    CU_ASSERT(memcmp(a, b, sizeof a) == 0);
    CU_ASSERT(fabs(a[0]) + fabs(a[1]) > 1e-3); /* the run moved */
    dmi_free(&r);
    dmi_free(&d);
}

static void test_restart_keeps_the_engine(void)
{
    dmi_solver *r = solver(500, 0, DMI_CONV_AUTO, 1.0), *f = solver(500, 0, DMI_CONV_AUTO, 1.0);
    CU_ASSERT_PTR_NOT_NULL_FATAL(r);
    CU_ASSERT_PTR_NOT_NULL_FATAL(f);
    double a[n], b[n];
    run(r, 2100, a); /* past an anchor (every 4 N = 2000 steps) */
    const dmi_exp *engine = r->rec;
    CU_ASSERT_EQUAL_FATAL(dmi_init(r), DMI_OK);
    CU_ASSERT_PTR_EQUAL(r->rec, engine);
    run(r, STEPS, a);
    run(f, STEPS, b);
    CU_ASSERT(memcmp(a, b, sizeof a) == 0);
    dmi_free(&r);
    dmi_free(&f);
}

static void test_nonfinite_sample_named_at_the_switch(void)
{
    dmi_solver *r = solver(100, 0, DMI_CONV_AUTO, 1e308); /* H(0) = 3e308: inf */
    CU_ASSERT_PTR_NOT_NULL_FATAL(r);
    CU_ASSERT_EQUAL(dmi_set_convolution(r, DMI_CONV_DIRECT), DMI_ENONFINITE);
    CU_ASSERT_PTR_NOT_NULL(strstr(dmi_last_error(r), "dmi_set_convolution: kernel H(0)[1][0]"));
    CU_ASSERT_PTR_NOT_NULL(r->rec); /* the recursion stays */
    CU_ASSERT_EQUAL(r->kernel.nnz, 0);
    dmi_free(&r);
}

static void test_partial_cell_samples(void)
{
    dmi_solver *r = solver(0, 1.0 / 99.5, DMI_CONV_AUTO, 1.0); /* theta = 0.5 */
    CU_ASSERT_PTR_NOT_NULL_FATAL(r);
    CU_ASSERT(r->theta < 1);
    CU_ASSERT_PTR_NOT_NULL(r->rec);
    CU_ASSERT_EQUAL(r->kernel.nnz, 1); /* the last cell's change reads H((N - 1) h) */
    dmi_free(&r);
}

/* set_window checks long windows in blocks: the first non-finite value is
 * still the one named, wherever it lies in its block. */
static void test_set_window_names_the_first_nonfinite(void)
{
    dmi_solver *r = solver(20, 0, DMI_CONV_AUTO, 1.0);
    CU_ASSERT_PTR_NOT_NULL_FATAL(r);
    double U[21 * n], V[21 * n];
    CU_ASSERT_EQUAL_FATAL(dmi_get_window(r, U), DMI_OK);
    for (size_t bad = 0; bad < 21 * n; bad += 5) {
        memcpy(V, U, sizeof V);
        V[bad] = INFINITY;
        if (bad + 3 < 21 * n)
            V[bad + 3] = NAN;
        CU_ASSERT_EQUAL(dmi_set_window(r, V), DMI_EINVAL);
        char want[64];
        snprintf(want, sizeof want, "U[%zu] (row %zu", bad, bad / n);
        CU_ASSERT_PTR_NOT_NULL(strstr(dmi_last_error(r), want));
    }
    CU_ASSERT_EQUAL(dmi_get_window(r, V), DMI_OK); /* unchanged */
    CU_ASSERT(memcmp(U, V, sizeof U) == 0);
    dmi_free(&r);
}

int main(void)
{
    if (CU_initialize_registry() != CUE_SUCCESS)
        return 1;
    CU_pSuite suite = CU_add_suite("lazy", NULL, NULL);
    CU_add_test(suite, "recursion takes no samples", test_recursion_takes_no_samples);
    CU_add_test(suite, "restart keeps the engine", test_restart_keeps_the_engine);
    CU_add_test(suite, "non-finite sample at the switch",
                test_nonfinite_sample_named_at_the_switch);
    CU_add_test(suite, "partial cell samples", test_partial_cell_samples);
    CU_add_test(suite, "set_window names the first non-finite value",
                test_set_window_names_the_first_nonfinite);
    CU_basic_set_mode(CU_BRM_VERBOSE);
    CU_basic_run_tests();
    const unsigned failed = CU_get_number_of_failures() + CU_get_number_of_tests_failed();
    CU_cleanup_registry();
    return failed ? 1 : 0;
}
