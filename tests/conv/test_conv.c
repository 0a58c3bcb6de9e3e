/*
 * Tests of dmi_set_convolution through the public API: the FFT method against
 * the direct sum on the paper's Examples 4.1-4.3 and on an n = 3 system with
 * a full matrix kernel, rollback after a failed step, exact state restore and
 * switching the method in the middle of a run.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <CUnit/CUnit.h>

#include "conv_run.h"
#include "dmi.h"
#include "paper.h"

/* ---- an n = 3 system with a full matrix kernel ---------------------------- */

typedef struct {
    long calls, fail_at; /* the resolvent fails at call number fail_at (0: never) */
} model3;

static int rhs3(double t, const double *u, double *out, void *user)
{
    (void)user;
    out[0] = 0.5 * u[1] - 0.2 * u[2] + sin(3 * t);
    out[1] = -0.4 * u[0] + 0.1 * u[2];
    out[2] = 0.3 * u[0] - 0.6 * u[1] + 0.7 * cos(t);
    return 0;
}

/* Dry friction 0.4 sigma on u_1 (called after W^p is computed). */
static int resolvent3(double lambda, const double *x, double *out, void *user)
{
    model3 *m = user;
    if (++m->calls == m->fail_at)
        return 7;
    double th = 0.4 * lambda;
    out[0] = x[0];
    out[1] = x[1] > th ? x[1] - th : x[1] < -th ? x[1] + th : 0.0;
    out[2] = x[2];
    return 0;
}

static int kernel3(double s, double *out, void *user)
{
    (void)user;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[i * 3 + j] = cos((1 + i + 2 * j) * s) * (i == j ? 2.0 : 0.5) + 0.1 * (i - j) * s;
    return 0;
}

static int history3(double t, double *out, void *user)
{
    (void)user;
    out[0] = cos(2 * t);
    out[1] = 1 + t;
    out[2] = sin(5 * t);
    return 0;
}

/* A solver for the n = 3 model (tau = 1.5) with the method. */
static dmi_solver *make3(size_t N, int method, model3 *m)
{
    dmi_solver *s = NULL;
    CU_ASSERT_FATAL(dmi_create(&s, 3, 1.5, N) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_rhs(s, rhs3, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_resolvent(s, resolvent3, m) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_kernel(s, kernel3, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_history(s, history3, NULL) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_convolution(s, method) == DMI_OK);
    CU_ASSERT_FATAL(dmi_init(s) == DMI_OK);
    return s;
}

static dmi_solver *make_paper(int example, size_t N, int method, paper_example *ex)
{
    dmi_solver *s = NULL;
    ex->example = example;
    CU_ASSERT_FATAL(dmi_create(&s, 2, 1.0, N) == DMI_OK);
    CU_ASSERT_FATAL(paper_setup(s, ex) == DMI_OK);
    CU_ASSERT_FATAL(dmi_set_convolution(s, method) == DMI_OK);
    CU_ASSERT_FATAL(dmi_init(s) == DMI_OK);
    return s;
}

/* ---- helpers -------------------------------------------------------------- */

static unsigned char *save(const dmi_solver *s, size_t *size)
{
    *size = dmi_state_size(s);
    unsigned char *b = malloc(*size);
    CU_ASSERT_FATAL(b != NULL);
    CU_ASSERT_FATAL(dmi_state_save(s, b, *size) == DMI_OK);
    return b;
}

static int same_state(const dmi_solver *a, const dmi_solver *b)
{
    size_t na, nb;
    unsigned char *x = save(a, &na), *y = save(b, &nb);
    int same = na == nb && memcmp(x, y, na) == 0;
    free(x);
    free(y);
    return same;
}

/*
 * Steps a (direct) and b (FFT) `steps` times; returns max_p |U_a - U_b| /
 * max_p |U_a| (sup norms over components and steps) and whether the delay
 * terms W^p of the two runs ever differed at all (*differ), which shows that
 * b did not use the direct sum (the states may agree bitwise: h W^p is small).
 */
static double compare_runs(dmi_solver *a, dmi_solver *b, size_t n, size_t steps, int *differ)
{
    double ua[3], ub[3], dev = 0, big = 0;
    *differ = 0;
    for (size_t p = 0; p < steps; p++) {
        CU_ASSERT_FATAL(dmi_step(a) == DMI_OK);
        CU_ASSERT_FATAL(dmi_step(b) == DMI_OK);
        dmi_get_state(a, ua);
        dmi_get_state(b, ub);
        for (size_t i = 0; i < n; i++) {
            dev = fmax(dev, fabs(ua[i] - ub[i]));
            big = fmax(big, fabs(ua[i]));
        }
        dmi_get_step_terms(a, ua, NULL);
        dmi_get_step_terms(b, ub, NULL);
        *differ |= memcmp(ua, ub, n * sizeof *ua) != 0;
    }
    return dev / big;
}

/* ---- tests ------------------------------------------------------------------ */

static void test_paper_examples(void)
{
    static const int examples[3] = {41, 42, 43};
    static const size_t Ns[2] = {1000, 4096};
    for (int e = 0; e < 3; e++)
        for (int t = 0; t < 2; t++) {
            paper_example xa, xb;
            dmi_solver *a = make_paper(examples[e], Ns[t], DMI_CONV_DIRECT, &xa);
            dmi_solver *b = make_paper(examples[e], Ns[t], DMI_CONV_FFT, &xb);
            int differ;
            double rel = compare_runs(a, b, 2, 3 * Ns[t], &differ); /* T = 3 tau */
            if (!(rel <= 1e-12))
                fprintf(stderr, "\n  Example %d, N = %zu: FFT vs DIRECT %.3g", examples[e], Ns[t],
                        rel);
            CU_ASSERT(rel <= 1e-12);
            CU_ASSERT(differ); /* rounding differs somewhere: the FFT path really ran */
            dmi_free(&a);
            dmi_free(&b);
        }
}

static void test_full_matrix_kernel(void)
{
    model3 ma = {0, 0}, mb = {0, 0};
    dmi_solver *a = make3(777, DMI_CONV_DIRECT, &ma), *b = make3(777, DMI_CONV_FFT, &mb);
    int differ;
    double rel = compare_runs(a, b, 3, 2500, &differ);
    CU_ASSERT(rel <= 1e-12);
    CU_ASSERT(differ);
    dmi_free(&a);
    dmi_free(&b);
}

/* A failing resolvent (called after W^p) in FFT mode leaves the state bitwise unchanged, and the retry
 * gives bitwise the run that never failed; checked at several block phases. */
static void test_rollback_fft(void)
{
    static const long fail_at[] = {1, 2, 33, 64, 65, 300, 1024};
    for (size_t t = 0; t < sizeof fail_at / sizeof *fail_at; t++) {
        model3 ma = {0, 0}, mb = {0, fail_at[t]};
        dmi_solver *a = make3(900, DMI_CONV_FFT, &ma), *b = make3(900, DMI_CONV_FFT, &mb);
        for (long k = 1; k < fail_at[t]; k++) {
            CU_ASSERT_FATAL(dmi_step(a) == DMI_OK);
            CU_ASSERT_FATAL(dmi_step(b) == DMI_OK);
        }
        size_t size;
        unsigned char *before = save(b, &size);
        CU_ASSERT(dmi_step(b) == DMI_ECALLBACK);
        unsigned char *after = save(b, &size);
        CU_ASSERT(memcmp(before, after, size) == 0);
        for (int i = 0; i < 1100; i++) {
            CU_ASSERT_FATAL(dmi_step(a) == DMI_OK);
            CU_ASSERT_FATAL(dmi_step(b) == DMI_OK);
        }
        CU_ASSERT(same_state(a, b));
        free(before);
        free(after);
        dmi_free(&a);
        dmi_free(&b);
    }
}

/* Save at p off any block boundary, step, load, step again: bitwise the same;
 * also into a second solver, and after a load into a solver far ahead. */
static void test_state_load_fft(void)
{
    paper_example xa, xb;
    dmi_solver *a = make_paper(43, 2000, DMI_CONV_FFT, &xa);
    dmi_solver *b = make_paper(43, 2000, DMI_CONV_FFT, &xb);
    CU_ASSERT_FATAL(dmi_advance(a, 2345) == DMI_OK); /* 2345: odd, no block boundary */
    CU_ASSERT_FATAL(dmi_advance(b, 5000) == DMI_OK);
    size_t size;
    unsigned char *at = save(a, &size);
    CU_ASSERT_FATAL(dmi_advance(a, 3001) == DMI_OK);
    unsigned char *ref = save(a, &size);
    CU_ASSERT_FATAL(dmi_state_load(a, at, size) == DMI_OK);
    CU_ASSERT_FATAL(dmi_advance(a, 3001) == DMI_OK);
    unsigned char *again = save(a, &size);
    CU_ASSERT(memcmp(ref, again, size) == 0);
    CU_ASSERT_FATAL(dmi_state_load(b, at, size) == DMI_OK);
    CU_ASSERT_FATAL(dmi_advance(b, 3001) == DMI_OK);
    CU_ASSERT(same_state(a, b));
    /* a DIRECT solver loading the same state continues close to it */
    paper_example xc;
    dmi_solver *c = make_paper(43, 2000, DMI_CONV_DIRECT, &xc);
    CU_ASSERT_FATAL(dmi_state_load(c, at, size) == DMI_OK);
    CU_ASSERT_FATAL(dmi_state_load(a, at, size) == DMI_OK);
    int differ;
    CU_ASSERT(compare_runs(c, a, 2, 3001, &differ) <= 1e-12);
    free(at);
    free(ref);
    free(again);
    dmi_free(&a);
    dmi_free(&b);
    dmi_free(&c);
}

/* Changing the method between steps: the run stays within rounding of the
 * direct run; re-selecting FFT in FFT mode changes nothing (bitwise); an
 * invalid method is rejected and changes nothing. */
static void test_switch_midrun(void)
{
    paper_example xa, xb, xc;
    dmi_solver *a = make_paper(43, 1500, DMI_CONV_DIRECT, &xa);
    dmi_solver *b = make_paper(43, 1500, DMI_CONV_AUTO, &xb);
    dmi_solver *c = make_paper(43, 1500, DMI_CONV_FFT, &xc);
    static const int methods[] = {DMI_CONV_DIRECT, DMI_CONV_FFT, DMI_CONV_AUTO, DMI_CONV_FFT,
                                  DMI_CONV_DIRECT, DMI_CONV_FFT};
    double dev = 0, big = 0;
    int differ = 0;
    for (size_t t = 0; t < sizeof methods / sizeof *methods; t++) {
        CU_ASSERT_FATAL(dmi_set_convolution(b, methods[t]) == DMI_OK);
        CU_ASSERT_FATAL(dmi_set_convolution(c, DMI_CONV_FFT) == DMI_OK); /* a rebuild */
        for (int k = 0; k < 777; k++) {
            double ua[2], ub[2];
            CU_ASSERT_FATAL(dmi_step(a) == DMI_OK);
            CU_ASSERT_FATAL(dmi_step(b) == DMI_OK);
            dmi_get_state(a, ua);
            dmi_get_state(b, ub);
            for (int i = 0; i < 2; i++) {
                dev = fmax(dev, fabs(ua[i] - ub[i]));
                big = fmax(big, fabs(ua[i]));
            }
            dmi_get_step_terms(a, ua, NULL);
            dmi_get_step_terms(b, ub, NULL);
            differ |= memcmp(ua, ub, sizeof ua) != 0;
        }
    }
    CU_ASSERT(dev <= 1e-12 * big);
    CU_ASSERT(differ);
    /* c was rebuilt 6 times; d never */
    paper_example xd;
    dmi_solver *d = make_paper(43, 1500, DMI_CONV_FFT, &xd);
    CU_ASSERT_FATAL(dmi_advance(d, 6 * 777) == DMI_OK);
    CU_ASSERT_FATAL(dmi_advance(c, 6 * 777) == DMI_OK);
    CU_ASSERT(same_state(c, d));
    /* invalid method: error, state and method unchanged */
    size_t size;
    unsigned char *before = save(c, &size);
    CU_ASSERT(dmi_set_convolution(c, 4) == DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(c), "4") != NULL);
    unsigned char *after = save(c, &size);
    CU_ASSERT(memcmp(before, after, size) == 0);
    free(after);
    CU_ASSERT_FATAL(dmi_advance(c, 100) == DMI_OK);
    CU_ASSERT_FATAL(dmi_advance(d, 100) == DMI_OK);
    CU_ASSERT(same_state(c, d));
    free(before);
    dmi_free(&a);
    dmi_free(&b);
    dmi_free(&c);
    dmi_free(&d);
}

int main(void)
{
    static CU_TestInfo tests[] = {
        {"FFT vs DIRECT, Examples 4.1-4.3", test_paper_examples},
        {"FFT vs DIRECT, n = 3 full kernel", test_full_matrix_kernel},
        {"rollback in FFT mode", test_rollback_fft},
        {"state load in FFT mode", test_state_load_fft},
        {"switching method mid-run", test_switch_midrun},
        CU_TEST_INFO_NULL,
    };
    return conv_run("conv", tests);
}
