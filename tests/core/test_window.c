/*
 * dmi_get_window / dmi_set_window (libdmi 1.2): the window is the stored
 * states U^{p-N..p} oldest first (checked against dmi_get_past); a window set
 * into another solver at the same step makes it step on as the solver it came
 * from (bitwise for DIRECT and FFT, to rounding for RECURSIVE); a history
 * set as a window equals the same history sampled by dmi_init; bad input is
 * refused with the solver unchanged.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core_test.h"

enum { N = 40, AT = 97, MORE = 60 }; /* AT > 2 N: the ring has wrapped twice */

static void test_rows_are_the_past(void)
{
    core_model m = {0};
    dmi_solver *s = core_model_solver(&m, N);
    CU_ASSERT_FATAL(s != NULL);
    CU_ASSERT_EQUAL(dmi_advance(s, AT), DMI_OK);
    double U[(N + 1) * 2], u[2];
    CU_ASSERT_EQUAL(dmi_get_window(s, U), DMI_OK);
    int same = 1;
    for (size_t k = 0; k <= N; k++)
        same &= dmi_get_past(s, N - k, u) == DMI_OK && memcmp(u, U + 2 * k, sizeof u) == 0;
    CU_ASSERT(same);
    dmi_free(&s);
}

/* A new initialised solver of the model but with the history z = 0, or NULL. */
static dmi_solver *zero_history_twin(core_model *m)
{
    dmi_solver *s = NULL;
    if (dmi_create(&s, 2, 1.0, N) != DMI_OK)
        return NULL;
    if (core_model_setup(s, m) != DMI_OK || dmi_set_history(s, NULL, NULL) != DMI_OK ||
        dmi_init(s) != DMI_OK)
        dmi_free(&s);
    return s;
}

/* b, stepped to AT from the zero history, takes a's window at AT: both step
 * on alike. */
static void window_moves_run(int method, double tol)
{
    core_model ma = {0}, mb = {0};
    dmi_solver *a = core_model_solver(&ma, N), *b = zero_history_twin(&mb);
    CU_ASSERT_FATAL(a != NULL && b != NULL);
    CU_ASSERT_EQUAL(dmi_set_convolution(a, method), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_convolution(b, method), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(a, AT), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(b, AT), DMI_OK);
    double U[(N + 1) * 2], ua[2], ub[2];
    CU_ASSERT_EQUAL(dmi_get_window(a, U), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_state(b, ub), DMI_OK);
    CU_ASSERT(memcmp(U + 2 * N, ub, sizeof ub) != 0); /* b was elsewhere */
    CU_ASSERT_EQUAL(dmi_set_window(b, U), DMI_OK);
    double worst = 0;
    for (int k = 0; k < MORE; k++) {
        CU_ASSERT_EQUAL(dmi_step(a), DMI_OK);
        CU_ASSERT_EQUAL(dmi_step(b), DMI_OK);
        dmi_get_state(a, ua);
        dmi_get_state(b, ub);
        for (int j = 0; j < 2; j++)
            worst = fmax(worst, fabs(ua[j] - ub[j]));
    }
    if (tol == 0)
        CU_ASSERT(core_same_state(a, b));
    CU_ASSERT(worst <= tol);
    dmi_free(&a);
    dmi_free(&b);
}

static void test_moves_direct(void) { window_moves_run(DMI_CONV_DIRECT, 0); }
static void test_moves_fft(void) { window_moves_run(DMI_CONV_FFT, 0); }

/* An exponential kernel under the recursion: the sums are recomputed from the
 * window, so the run agrees to rounding. */
static void test_moves_recursive(void)
{
    const double a[2] = {-1, 0}, b[2] = {0, 3}, C[8] = {0, 1, 0, 0, 0, 0, 1, 0};
    core_model m = {0};
    dmi_solver *s[2] = {NULL, NULL};
    for (int i = 0; i < 2; i++) {
        CU_ASSERT_EQUAL_FATAL(dmi_create(&s[i], 2, 1.0, N), DMI_OK);
        CU_ASSERT_EQUAL(dmi_set_kernel_exp(s[i], 2, a, b, C, NULL), DMI_OK);
        CU_ASSERT_EQUAL(dmi_set_convolution(s[i], DMI_CONV_RECURSIVE), DMI_OK);
        CU_ASSERT_EQUAL(dmi_set_history(s[i], i ? NULL : core_history, &m), DMI_OK);
        CU_ASSERT_EQUAL(dmi_init(s[i]), DMI_OK);
        CU_ASSERT_EQUAL(dmi_advance(s[i], AT), DMI_OK);
    }
    double U[(N + 1) * 2], u0[2], u1[2], worst = 0;
    CU_ASSERT_EQUAL(dmi_get_window(s[0], U), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_window(s[1], U), DMI_OK);
    for (int k = 0; k < MORE; k++) {
        CU_ASSERT_EQUAL(dmi_step(s[0]), DMI_OK);
        CU_ASSERT_EQUAL(dmi_step(s[1]), DMI_OK);
        dmi_get_state(s[0], u0);
        dmi_get_state(s[1], u1);
        for (int j = 0; j < 2; j++)
            worst = fmax(worst, fabs(u0[j] - u1[j]));
    }
    CU_ASSERT(worst <= 1e-13);
    /* and the run did not stay at rest: the comparison is not of zeros */
    CU_ASSERT(fabs(u0[0]) + fabs(u0[1]) > 1e-3);
    dmi_free(&s[0]);
    dmi_free(&s[1]);
}

/* At p = 0 the window is the history: setting z's samples as a window equals
 * sampling z in dmi_init, bitwise, all the way on. */
static void test_window_is_history(void)
{
    core_model ma = {0}, mb = {0};
    dmi_solver *a = core_model_solver(&ma, N), *b = zero_history_twin(&mb);
    CU_ASSERT_FATAL(a != NULL && b != NULL);
    core_model mz = {0};
    double U[(N + 1) * 2];
    for (size_t k = 0; k <= N; k++) { /* lag N - k at t = -(N - k) h, as dmi_init samples */
        const size_t lag = N - k;
        core_history(lag == N ? -1.0 : -(double)lag * (1.0 / N), U + 2 * k, &mz);
    }
    CU_ASSERT_EQUAL(dmi_set_window(b, U), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(a, AT), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(b, AT), DMI_OK);
    CU_ASSERT(core_same_state(a, b));
    dmi_free(&a);
    dmi_free(&b);
}

static void test_refused(void)
{
    core_model m = {0};
    dmi_solver *s = NULL;
    double U[(N + 1) * 2] = {0};
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, 2, 1.0, N), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_window(s, U), DMI_ESTATE);
    CU_ASSERT_EQUAL(dmi_set_window(s, U), DMI_ESTATE);
    dmi_free(&s);
    CU_ASSERT_EQUAL(dmi_get_window(NULL, U), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_window(NULL, U), DMI_EINVAL);

    s = core_model_solver(&m, N);
    CU_ASSERT_FATAL(s != NULL);
    CU_ASSERT_EQUAL(dmi_advance(s, AT), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_window(s, NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_window(s, NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_get_window(s, U), DMI_OK);
    size_t size;
    unsigned char *before = core_save(s, &size);
    CU_ASSERT_FATAL(before != NULL);
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    for (int i = 0; i < 3; i++) {
        double V[(N + 1) * 2];
        memcpy(V, U, sizeof V);
        V[2 * 7 + 1] = bad[i]; /* row 7 = U^{p-33}, component 1 */
        CU_ASSERT_EQUAL(dmi_set_window(s, V), DMI_EINVAL);
        CU_ASSERT(strstr(dmi_last_error(s), "row 7") != NULL);
        CU_ASSERT(strstr(dmi_last_error(s), "component 1") != NULL);
        CU_ASSERT(core_state_is(s, before, size));
    }
    free(before);
    dmi_free(&s);
}

int main(int argc, char **argv)
{
    static const core_test tests[] = {
        {"the window's rows are dmi_get_past(N - k)", test_rows_are_the_past},
        {"a window set at the same step: the same run on (DIRECT, bitwise)", test_moves_direct},
        {"a window set at the same step: the same run on (FFT, bitwise)", test_moves_fft},
        {"a window set at the same step: the same run on (RECURSIVE, 1e-13)",
         test_moves_recursive},
        {"a window set at p = 0 is the history sampled by dmi_init", test_window_is_history},
        {"NULL, before init, non-finite: refused, solver unchanged", test_refused},
        {NULL, NULL}};
    return core_main(argc, argv, "core: the window of stored states", tests);
}
