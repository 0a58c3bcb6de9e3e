/*
 * Exponential-sum kernels (issue 13): dmi_set_kernel_exp's errors, the choice
 * of DMI_CONV_RECURSIVE, and what must stay exact with it: a failed step
 * leaves the solver bitwise unchanged, a loaded state continues bitwise
 * (across the recursion's anchors), the method may change between steps;
 * and Example 4.3 with its kernel as three exponential terms against the
 * callback kernel summed by DIRECT.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core_test.h"

static const double PI = 3.14159265358979323846;

/* A kernel of the 2 x 2 fault-injection model with every kind of decaying
 * or undamped term: a cosine (a = 0, |r| = 1), a constant, a decaying and a
 * damped oscillatory term with full C_k and D_k. */
enum { MK = 4 };
static const double MA[MK] = {0.0, 0.0, -1.5, -0.7};
static const double MB[MK] = {2.0, 0.0, 0.0, 9.0};
static const double MC[MK * 4] = {0.2, 0.0, 0.1, -0.3, /* cosine */
                                  -0.1, 0.05, 0.0, 0.2, /* constant */
                                  0.3, -0.2, 0.4, 0.1,  /* decaying */
                                  0.1, 0.2, -0.3, 0.25}; /* damped oscillatory */
static const double MD[MK * 4] = {0.1, 0.0, 0.0, 0.05, 0, 0, 0, 0, 0, 0, 0, 0,
                                  -0.2, 0.1, 0.15, 0.3};

enum { EN = 50 }; /* the recursion anchors every 4 N = 200 steps */

/* The model solver with the exponential kernel and method, initialised. */
static dmi_solver *exp_solver(core_model *m, size_t N, int method)
{
    dmi_solver *s = NULL;
    if (dmi_create(&s, 2, 1.0, N) != DMI_OK)
        return NULL;
    if (core_model_setup(s, m) != DMI_OK || dmi_set_kernel_exp(s, MK, MA, MB, MC, MD) != DMI_OK ||
        dmi_set_convolution(s, method) != DMI_OK || dmi_init(s) != DMI_OK)
        dmi_free(&s);
    return s;
}

/* Whether dmi_last_error(s) contains each of the (NULL-ended) words. */
static int says(const dmi_solver *s, const char *w1, const char *w2)
{
    const char *msg = dmi_last_error(s);
    int ok = strstr(msg, w1) != NULL && (!w2 || strstr(msg, w2) != NULL);
    if (!ok)
        printf("\n  message \"%s\" lacks \"%s\"%s%s", msg, w1, w2 ? " or " : "", w2 ? w2 : "");
    return ok;
}

static void test_errors(void)
{
    const double a[2] = {0, -1}, b[2] = {1, 0}, C[8] = {1, 0, 0, 1, 0, 1, 1, 0};
    dmi_solver *s = NULL;
    CU_ASSERT_FATAL(dmi_create(&s, 2, 1.0, 10) == DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(NULL, 2, a, b, C, NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 0, a, b, C, NULL), DMI_EINVAL);
    CU_ASSERT(says(s, "K = 0", NULL));
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, NULL, b, C, NULL), DMI_EINVAL);
    CU_ASSERT(says(s, "a is NULL", NULL));
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, a, NULL, C, NULL), DMI_EINVAL);
    CU_ASSERT(says(s, "b is NULL", NULL));
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, a, b, NULL, NULL), DMI_EINVAL);
    CU_ASSERT(says(s, "C is NULL", NULL));
    const double bad_a[2] = {0, NAN}, bad_b[2] = {INFINITY, 0};
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, bad_a, b, C, NULL), DMI_EINVAL);
    CU_ASSERT(says(s, "a[1]", "nan"));
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, a, bad_b, C, NULL), DMI_EINVAL);
    CU_ASSERT(says(s, "b[0]", "inf"));
    double bad_C[8], bad_D[8] = {0};
    memcpy(bad_C, C, sizeof bad_C);
    bad_C[6] = -INFINITY;
    bad_D[3] = NAN;
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, a, b, bad_C, NULL), DMI_EINVAL);
    CU_ASSERT(says(s, "C[6]", "term 1, entry (1, 0)"));
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, a, b, C, bad_D), DMI_EINVAL);
    CU_ASSERT(says(s, "D[3]", "term 0, entry (1, 1)"));
    /* a callback kernel: RECURSIVE refused at once, and again by dmi_init
     * when the kernel became a callback after the method was chosen */
    core_model m = {0};
    CU_ASSERT_FATAL(core_model_setup(s, &m) == DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_convolution(s, DMI_CONV_RECURSIVE), DMI_EINVAL);
    CU_ASSERT(says(s, "DMI_CONV_RECURSIVE", "callback"));
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, a, b, C, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_convolution(s, DMI_CONV_RECURSIVE), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel(s, core_kernel, &m), DMI_OK); /* replaces it */
    CU_ASSERT_EQUAL(dmi_init(s), DMI_EINVAL);
    CU_ASSERT(says(s, "dmi_init", "callback"));
    /* a growing term: refused by RECURSIVE (with the reason), not if its
     * matrices are zero */
    const double grow[2] = {0.5, -1}, zero_first[8] = {0, 0, 0, 0, 0, 1, 1, 0};
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, grow, b, C, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_EINVAL);
    CU_ASSERT(says(s, "a[0] = 0.5", "growing"));
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, grow, b, zero_first, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, a, b, C, NULL), DMI_ESTATE);
    CU_ASSERT(says(s, "dmi_set_kernel_exp", "dmi_init"));
    dmi_free(&s);
}

/* AUTO takes the recursion (bitwise the RECURSIVE run), and with a growing
 * term the method its cost model picks for the samples (bitwise DIRECT or
 * FFT). */
static void test_auto(void)
{
    core_model m1 = {0}, m2 = {0};
    dmi_solver *a = exp_solver(&m1, 1000, DMI_CONV_AUTO);
    dmi_solver *r = exp_solver(&m2, 1000, DMI_CONV_RECURSIVE);
    CU_ASSERT_FATAL(a && r);
    CU_ASSERT(dmi_advance(a, 3000) == DMI_OK && dmi_advance(r, 3000) == DMI_OK);
    CU_ASSERT(core_same_state(a, r));
    dmi_free(&a);
    dmi_free(&r);

    double ga[MK];
    memcpy(ga, MA, sizeof ga);
    ga[2] = 0.8; /* growing */
    dmi_solver *s[3] = {NULL, NULL, NULL};
    const int method[3] = {DMI_CONV_AUTO, DMI_CONV_DIRECT, DMI_CONV_FFT};
    core_model m[3];
    memset(m, 0, sizeof m);
    for (int i = 0; i < 3; i++) {
        CU_ASSERT_FATAL(dmi_create(&s[i], 2, 1.0, 1000) == DMI_OK);
        CU_ASSERT(core_model_setup(s[i], &m[i]) == DMI_OK);
        CU_ASSERT(dmi_set_kernel_exp(s[i], MK, ga, MB, MC, MD) == DMI_OK);
        CU_ASSERT(dmi_set_convolution(s[i], method[i]) == DMI_OK);
        CU_ASSERT(dmi_init(s[i]) == DMI_OK);
        CU_ASSERT(dmi_advance(s[i], 1500) == DMI_OK);
    }
    CU_ASSERT_EQUAL(dmi_set_convolution(s[0], DMI_CONV_RECURSIVE), DMI_EINVAL);
    CU_ASSERT(says(s[0], "a[2] = 0.8", "growing"));
    CU_ASSERT(core_same_state(s[0], s[1]) || core_same_state(s[0], s[2]));
    for (int i = 0; i < 3; i++)
        dmi_free(&s[i]);
}

/* A failing callback at the steps before, at and after an anchor (p = 200)
 * leaves the solver bitwise unchanged; the retry gives the clean run. */
static void test_failed_step(void)
{
    core_model mc = {0}, mf = {0};
    dmi_solver *clean = exp_solver(&mc, EN, DMI_CONV_RECURSIVE);
    dmi_solver *s = exp_solver(&mf, EN, DMI_CONV_RECURSIVE);
    CU_ASSERT_FATAL(clean && s);
    const int faults[3] = {FAULT_RETURN, FAULT_NAN, FAULT_INF};
    const int kinds[2] = {CB_RHS, CB_RESOLVENT};
    for (size_t p = 0; p < 4 * EN + 3; p++) {
        if (p + 2 >= 4 * EN) { /* p = 198..202 */
            for (int k = 0; k < 2; k++)
                for (int f = 0; f < 3; f++) {
                    size_t size;
                    unsigned char *before = core_save(s, &size);
                    mf.fault[kinds[k]] = faults[f];
                    mf.fail_after[kinds[k]] = mf.calls[kinds[k]];
                    CU_ASSERT(dmi_step(s) != DMI_OK);
                    CU_ASSERT(core_state_is(s, before, size));
                    mf.fault[kinds[k]] = FAULT_NONE;
                    free(before);
                }
        }
        CU_ASSERT_FATAL(dmi_step(s) == DMI_OK && dmi_step(clean) == DMI_OK);
        CU_ASSERT(core_same_state(s, clean));
    }
    dmi_free(&clean);
    dmi_free(&s);
}

/* Largest |U^p - U'^p| of two solvers' stored states, relative to max |U|. */
static double state_deviation(const dmi_solver *a, const dmi_solver *b, size_t N)
{
    double d = 0, mx = 0, ua[2], ub[2];
    for (size_t lag = 0; lag <= N; lag++) {
        dmi_get_past(a, lag, ua);
        dmi_get_past(b, lag, ub);
        for (int i = 0; i < 2; i++) {
            d = fmax(d, fabs(ua[i] - ub[i]));
            mx = fmax(mx, fabs(ub[i]));
        }
    }
    return d / mx;
}

/* Saved at p = 150, loaded into fresh solvers, run past the anchors at 200
 * and 400: RECURSIVE continues bitwise; DIRECT loads the same bytes and
 * differs by rounding only; a RECURSIVE solver loading a DIRECT solver's
 * state anchors its sums afresh (rounding only). */
static void test_state(void)
{
    core_model m[5];
    memset(m, 0, sizeof m);
    dmi_solver *a = exp_solver(&m[0], EN, DMI_CONV_RECURSIVE);
    dmi_solver *b = exp_solver(&m[1], EN, DMI_CONV_RECURSIVE);
    dmi_solver *d = exp_solver(&m[2], EN, DMI_CONV_DIRECT);
    dmi_solver *d2 = exp_solver(&m[3], EN, DMI_CONV_DIRECT);
    dmi_solver *c = core_model_solver(&m[4], EN); /* callback kernel */
    CU_ASSERT_FATAL(a && b && d && d2 && c);
    CU_ASSERT_FATAL(dmi_advance(a, 150) == DMI_OK && dmi_advance(d2, 150) == DMI_OK);
    size_t size, dsize;
    unsigned char *saved = core_save(a, &size), *dsaved = core_save(d2, &dsize);
    CU_ASSERT_FATAL(saved && dsaved);
    CU_ASSERT_EQUAL(size, dsize); /* the size depends on the kernel, not the method */
    CU_ASSERT(size > dmi_state_size(c));
    CU_ASSERT_EQUAL(dmi_state_load(c, saved, size), DMI_EINVAL); /* another kernel's size */
    CU_ASSERT_EQUAL(dmi_state_load(b, saved, size), DMI_OK);
    CU_ASSERT_EQUAL(dmi_state_load(d, saved, size), DMI_OK);
    CU_ASSERT(core_state_is(b, saved, size));
    CU_ASSERT(dmi_advance(a, 300) == DMI_OK && dmi_advance(b, 300) == DMI_OK &&
              dmi_advance(d, 300) == DMI_OK);
    CU_ASSERT(core_same_state(a, b));
    double dev = state_deviation(d, a, EN);
    printf("\n  DIRECT from the RECURSIVE state: %.2e", dev);
    CU_ASSERT(dev <= 1e-13);
    CU_ASSERT_EQUAL(dmi_state_load(b, dsaved, dsize), DMI_OK); /* sums anchored afresh */
    CU_ASSERT_EQUAL(dmi_state_load(a, dsaved, dsize), DMI_OK);
    CU_ASSERT(dmi_advance(b, 300) == DMI_OK && dmi_advance(d2, 300) == DMI_OK &&
              dmi_advance(a, 300) == DMI_OK);
    CU_ASSERT(core_same_state(a, b));
    dev = state_deviation(b, d2, EN);
    printf("; RECURSIVE from the DIRECT state: %.2e\n", dev);
    CU_ASSERT(dev <= 1e-13);
    free(saved);
    free(dsaved);
    dmi_free(&a);
    dmi_free(&b);
    dmi_free(&c);
    dmi_free(&d);
    dmi_free(&d2);
}

/* The method changed between steps (RECURSIVE, DIRECT, FFT, AUTO, back to
 * RECURSIVE) against RECURSIVE all along: rounding only. */
static void test_switch(void)
{
    core_model m1 = {0}, m2 = {0};
    dmi_solver *a = exp_solver(&m1, EN, DMI_CONV_RECURSIVE);
    dmi_solver *b = exp_solver(&m2, EN, DMI_CONV_RECURSIVE);
    CU_ASSERT_FATAL(a && b);
    const int seq[5] = {DMI_CONV_DIRECT, DMI_CONV_RECURSIVE, DMI_CONV_FFT, DMI_CONV_AUTO,
                        DMI_CONV_RECURSIVE};
    for (int i = 0; i < 5; i++) {
        CU_ASSERT(dmi_advance(a, 77) == DMI_OK && dmi_advance(b, 77) == DMI_OK);
        CU_ASSERT(dmi_set_convolution(b, seq[i]) == DMI_OK);
    }
    CU_ASSERT(dmi_advance(a, 500) == DMI_OK && dmi_advance(b, 500) == DMI_OK);
    double dev = state_deviation(b, a, EN);
    printf("\n  switched 5 times: %.2e\n", dev);
    CU_ASSERT(dev <= 1e-13);
    dmi_free(&a);
    dmi_free(&b);
}

/* Example 4.3's kernel cos 2 pi s + cos 10 pi s + cos 20 pi s as three terms
 * (a = 0) under the default method (the recursion), against the callback
 * kernel under DIRECT, to T = 30: states within 1e-11 max |U|. */
static void ex43_exp_vs_direct(size_t N)
{
    paper_example e1 = {43}, e2 = {43};
    dmi_solver *r = NULL, *d = NULL;
    CU_ASSERT_FATAL(dmi_create(&r, 2, 1.0, N) == DMI_OK && dmi_create(&d, 2, 1.0, N) == DMI_OK);
    const double a[3] = {0, 0, 0}, b[3] = {2 * PI, 10 * PI, 20 * PI};
    const double C[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    CU_ASSERT(paper_setup(r, &e1) == DMI_OK && dmi_set_kernel_exp(r, 3, a, b, C, NULL) == DMI_OK);
    CU_ASSERT(paper_setup(d, &e2) == DMI_OK && dmi_set_convolution(d, DMI_CONV_DIRECT) == DMI_OK);
    CU_ASSERT_FATAL(dmi_init(r) == DMI_OK && dmi_init(d) == DMI_OK);
    const size_t steps = 30 * N;
    double dev = 0, mx = 0, ur[2], ud[2];
    for (size_t p = 0; p < steps; p++) {
        if (dmi_step(r) != DMI_OK || dmi_step(d) != DMI_OK) {
            CU_FAIL("a step failed");
            break;
        }
        dmi_get_state(r, ur);
        dmi_get_state(d, ud);
        for (int i = 0; i < 2; i++) {
            dev = fmax(dev, fabs(ur[i] - ud[i]));
            mx = fmax(mx, fabs(ud[i]));
        }
    }
    printf("\n  N = %zu: max |U_rec - U_direct| = %.2e = %.2e max|U|\n", N, dev, dev / mx);
    CU_ASSERT(mx > 1e-3);
    CU_ASSERT(dev <= 1e-11 * mx);
    dmi_free(&r);
    dmi_free(&d);
}

static void test_ex43_1000(void)
{
    ex43_exp_vs_direct(1000);
}

static void test_ex43_9991(void)
{
    ex43_exp_vs_direct(9991);
}

int main(int argc, char **argv)
{
    static const core_test tests[] = {
        {"dmi_set_kernel_exp: bad arguments, callback kernels and growing terms refused",
         test_errors},
        {"AUTO = RECURSIVE bitwise; with a growing term = its DIRECT or FFT pick", test_auto},
        {"RECURSIVE: failed steps around an anchor leave the solver bitwise unchanged",
         test_failed_step},
        {"RECURSIVE: state save/load continues bitwise across anchors", test_state},
        {"RECURSIVE: switching methods between steps", test_switch},
        {"Example 4.3 as exponentials, N = 1000: RECURSIVE = DIRECT to 1e-11", test_ex43_1000},
        {"Example 4.3 as exponentials, N = 9991: RECURSIVE = DIRECT to 1e-11", test_ex43_9991},
        {NULL, NULL}};
    return core_main(argc, argv, "core: exponential-sum kernels", tests);
}
