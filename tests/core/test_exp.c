/*
 * Exponential-sum kernels: dmi_set_kernel_exp's errors, the choice
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

/* A kernel whose parts are all in row 1 (W_0 = 0), so that the recursion
 * sums W in its step: a real term on column 0 only (an odd number of real
 * sums) and two complex ones on columns 0, 1 and 1 (an odd number of
 * complex sums), with D_k (a real term's D multiplies sin 0 = 0). */
enum { OK_ = 3 };
static const double OA[OK_] = {-1.0, 0.0, -0.5};
static const double OB[OK_] = {0.0, 2.0, 7.0};
static const double OC[OK_ * 4] = {0, 0, 0.3, 0, 0, 0, 0.2, -0.1, 0, 0, 0, 0.25};
static const double OD[OK_ * 4] = {0, 0, 0.1, 0, 0, 0, 0.05, 0.1, 0, 0, 0, -0.2};

/* The model solver with an exponential kernel and method, initialised. */
static dmi_solver *kernel_solver(core_model *m, size_t N, int method, size_t K, const double *a,
                                 const double *b, const double *C, const double *D)
{
    dmi_solver *s = NULL;
    if (dmi_create(&s, 2, 1.0, N) != DMI_OK)
        return NULL;
    if (core_model_setup(s, m) != DMI_OK || dmi_set_kernel_exp(s, K, a, b, C, D) != DMI_OK ||
        dmi_set_convolution(s, method) != DMI_OK || dmi_init(s) != DMI_OK)
        dmi_free(&s);
    return s;
}

/* The model solver with the kernel M*. */
static dmi_solver *exp_solver(core_model *m, size_t N, int method)
{
    return kernel_solver(m, N, method, MK, MA, MB, MC, MD);
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
 * term the method its cost model picks for the samples: FFT (all 4 entries
 * of the 2 x 2 kernel are nonzero, N = 1000; FFT from N = 174 for a full
 * 3 x 3 kernel and N = 382 for one entry, see dmi.h), bitwise. */
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
    CU_ASSERT(core_same_state(s[0], s[2]));
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
    /* the RECURSIVE state of p = 150 loaded by a solver at p = 750 (whose
     * next anchor was 800) and by a fresh one: both anchor next at p = 200,
     * bitwise the same run */
    core_model m6 = {0};
    dmi_solver *f = exp_solver(&m6, EN, DMI_CONV_RECURSIVE);
    CU_ASSERT_FATAL(f != NULL);
    CU_ASSERT_EQUAL(dmi_state_load(a, saved, size), DMI_OK);
    CU_ASSERT_EQUAL(dmi_state_load(f, saved, size), DMI_OK);
    CU_ASSERT(dmi_advance(a, 300) == DMI_OK && dmi_advance(f, 300) == DMI_OK);
    CU_ASSERT(core_same_state(a, f));
    dmi_free(&f);
    free(saved);
    free(dsaved);
    dmi_free(&a);
    dmi_free(&b);
    dmi_free(&c);
    dmi_free(&d);
    dmi_free(&d2);
}

/* The scale of the recursion's bound: h sum_l max_i sum_j |H_ij(l h)| max |U|
 * over the stored states, H summed here from the model kernel's formula. */
static double bound_scale(const dmi_solver *s, size_t N)
{
    const double h = dmi_get_h(s);
    double hsum = 0, umax = 0, u[2];
    for (size_t l = 0; l < N; l++) {
        double row[2] = {0, 0}, x = (double)l * h;
        for (int k = 0; k < MK; k++) {
            double e = exp(MA[k] * x), c = e * cos(MB[k] * x), sn = e * sin(MB[k] * x);
            for (int q = 0; q < 4; q++)
                row[q / 2] += fabs(MC[4 * k + q] * c + MD[4 * k + q] * sn);
        }
        hsum += fmax(row[0], row[1]);
    }
    for (size_t lag = 0; lag <= N; lag++) {
        dmi_get_past(s, lag, u);
        umax = fmax(umax, fmax(fabs(u[0]), fabs(u[1])));
    }
    return h * hsum * umax;
}

/* The one-row kernel O*: W summed in the recursion's step, and by the
 * function that sums it after an anchor or a load.  At every step p from
 * 150 to 450 (across the anchors at 200 and 400), a's state is loaded into
 * b and both take a step: the W^p each used (a's summed in the step, b's
 * after the load) are bitwise equal, and so are the states after it (this
 * fails if the two summations differ in any bit, at any step).  DIRECT from
 * the state of p = 150 stays within 1e-13. */
static void test_one_row(void)
{
    core_model m[3];
    memset(m, 0, sizeof m);
    dmi_solver *a = kernel_solver(&m[0], EN, DMI_CONV_RECURSIVE, OK_, OA, OB, OC, OD);
    dmi_solver *b = kernel_solver(&m[1], EN, DMI_CONV_RECURSIVE, OK_, OA, OB, OC, OD);
    dmi_solver *d = kernel_solver(&m[2], EN, DMI_CONV_DIRECT, OK_, OA, OB, OC, OD);
    CU_ASSERT_FATAL(a && b && d);
    CU_ASSERT_FATAL(dmi_advance(a, 150) == DMI_OK);
    size_t size, differ = 0;
    unsigned char *saved = core_save(a, &size);
    CU_ASSERT_FATAL(saved != NULL);
    CU_ASSERT_EQUAL(dmi_state_load(d, saved, size), DMI_OK);
    for (int p = 150; p < 450; p++) {
        unsigned char *now = core_save(a, &size);
        CU_ASSERT_FATAL(now != NULL);
        CU_ASSERT_FATAL(dmi_state_load(b, now, size) == DMI_OK);
        free(now);
        CU_ASSERT_FATAL(dmi_step(a) == DMI_OK && dmi_step(b) == DMI_OK);
        double wa[2], wb[2];
        CU_ASSERT_FATAL(dmi_get_step_terms(a, wa, NULL) == DMI_OK &&
                        dmi_get_step_terms(b, wb, NULL) == DMI_OK);
        differ += memcmp(wa, wb, sizeof wa) != 0 || !core_same_state(a, b);
        CU_ASSERT(wa[0] == 0 && wa[1] != 0); /* the parts are in row 1 */
    }
    CU_ASSERT_EQUAL(differ, 0);
    CU_ASSERT(dmi_advance(d, 300) == DMI_OK);
    double dev = state_deviation(d, a, EN);
    printf("\n  DIRECT from the RECURSIVE state: %.2e\n", dev);
    CU_ASSERT(dev <= 1e-13);
    free(saved);
    dmi_free(&a);
    dmi_free(&b);
    dmi_free(&d);
}

/* The method changed between steps (RECURSIVE, DIRECT, FFT, AUTO, back to
 * RECURSIVE) against RECURSIVE all along: the delay term W of the step
 * right after each switch agrees to 1e-13 of the bound's scale (a switch
 * to the recursion whose sums were not computed afresh gives a W off by the
 * whole sum), and the states after 500 more steps agree to rounding. */
static void test_switch(void)
{
    core_model m1 = {0}, m2 = {0};
    dmi_solver *a = exp_solver(&m1, EN, DMI_CONV_RECURSIVE);
    dmi_solver *b = exp_solver(&m2, EN, DMI_CONV_RECURSIVE);
    CU_ASSERT_FATAL(a && b);
    const int seq[5] = {DMI_CONV_DIRECT, DMI_CONV_RECURSIVE, DMI_CONV_FFT, DMI_CONV_AUTO,
                        DMI_CONV_RECURSIVE};
    double worst = 0;
    for (int i = 0; i < 5; i++) {
        CU_ASSERT(dmi_advance(a, 77) == DMI_OK && dmi_advance(b, 77) == DMI_OK);
        CU_ASSERT(dmi_set_convolution(b, seq[i]) == DMI_OK);
        double Wa[2], Wb[2];
        const double scale = bound_scale(a, EN);
        CU_ASSERT(dmi_step(a) == DMI_OK && dmi_step(b) == DMI_OK);
        CU_ASSERT(dmi_get_step_terms(a, Wa, NULL) == DMI_OK &&
                  dmi_get_step_terms(b, Wb, NULL) == DMI_OK);
        const double d = fmax(fabs(Wa[0] - Wb[0]), fabs(Wa[1] - Wb[1])) / scale;
        printf("%s W after switch %d: %.2e of the scale %.2e", i ? "," : "\n ", i, d, scale);
        CU_ASSERT(scale > 1e-3);
        worst = fmax(worst, d);
    }
    CU_ASSERT(worst <= 1e-13);
    CU_ASSERT(dmi_advance(a, 500) == DMI_OK && dmi_advance(b, 500) == DMI_OK);
    double dev = state_deviation(b, a, EN);
    printf("\n  switched 5 times, states: %.2e\n", dev);
    CU_ASSERT(dev <= 1e-13);
    dmi_free(&a);
    dmi_free(&b);
}

/* dmi_set_kernel_exp copies a, b, C and D: overwriting them before dmi_init
 * gives bitwise the run of a solver whose arrays stayed untouched. */
static void test_copies(void)
{
    double a[MK], b[MK], C[4 * MK], D[4 * MK];
    memcpy(a, MA, sizeof a);
    memcpy(b, MB, sizeof b);
    memcpy(C, MC, sizeof C);
    memcpy(D, MD, sizeof D);
    core_model m1 = {0}, m2 = {0};
    dmi_solver *s = NULL;
    dmi_solver *ref = exp_solver(&m2, EN, DMI_CONV_AUTO);
    CU_ASSERT_FATAL(ref && dmi_create(&s, 2, 1.0, EN) == DMI_OK);
    CU_ASSERT(core_model_setup(s, &m1) == DMI_OK);
    CU_ASSERT(dmi_set_kernel_exp(s, MK, a, b, C, D) == DMI_OK);
    for (int k = 0; k < MK; k++) {
        a[k] -= 1;
        b[k] += 1;
    }
    for (int q = 0; q < 4 * MK; q++) {
        C[q] = -C[q];
        D[q] = 2 * D[q] + 1;
    }
    CU_ASSERT_FATAL(dmi_init(s) == DMI_OK);
    CU_ASSERT(dmi_advance(s, 300) == DMI_OK && dmi_advance(ref, 300) == DMI_OK);
    CU_ASSERT(core_same_state(s, ref));
    dmi_free(&s);
    dmi_free(&ref);
}

/* No kernel at all (H = 0, the empty exponential sum): RECURSIVE is taken
 * and the delay term is exactly 0, the run bitwise that of DIRECT. */
static void test_no_kernel(void)
{
    core_model m[2];
    memset(m, 0, sizeof m);
    dmi_solver *s[2] = {NULL, NULL};
    const int method[2] = {DMI_CONV_RECURSIVE, DMI_CONV_DIRECT};
    for (int i = 0; i < 2; i++) {
        CU_ASSERT_FATAL(dmi_create(&s[i], 2, 1.0, EN) == DMI_OK);
        CU_ASSERT(core_model_setup(s[i], &m[i]) == DMI_OK);
        CU_ASSERT(dmi_set_kernel(s[i], NULL, NULL) == DMI_OK);
        CU_ASSERT(dmi_set_convolution(s[i], method[i]) == DMI_OK);
        CU_ASSERT_FATAL(dmi_init(s[i]) == DMI_OK);
        CU_ASSERT(dmi_advance(s[i], 120) == DMI_OK);
    }
    double W[2] = {1, 1};
    CU_ASSERT(dmi_get_step_terms(s[0], W, NULL) == DMI_OK);
    CU_ASSERT(W[0] == 0 && W[1] == 0);
    CU_ASSERT(core_same_state(s[0], s[1]));
    for (int i = 0; i < 2; i++)
        dmi_free(&s[i]);
}

/* Example 4.3 with the kernel sum_k cos(b_k s) as K <= 3 terms (a = 0)
 * under the default method (the recursion), against DIRECT (the callback
 * kernel cos 2 pi s + cos 10 pi s + cos 20 pi s, or with other b the same
 * exponential kernel), to T = 30: states within 1e-11 max |U|. */
static void ex43_exp_vs(size_t N, size_t K, const double *b, int callback)
{
    paper_example e1 = {43}, e2 = {43};
    dmi_solver *r = NULL, *d = NULL;
    CU_ASSERT_FATAL(dmi_create(&r, 2, 1.0, N) == DMI_OK && dmi_create(&d, 2, 1.0, N) == DMI_OK);
    const double a[3] = {0, 0, 0};
    const double C[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    CU_ASSERT(paper_setup(r, &e1) == DMI_OK && dmi_set_kernel_exp(r, K, a, b, C, NULL) == DMI_OK);
    CU_ASSERT(paper_setup(d, &e2) == DMI_OK && dmi_set_convolution(d, DMI_CONV_DIRECT) == DMI_OK);
    if (!callback)
        CU_ASSERT(dmi_set_kernel_exp(d, K, a, b, C, NULL) == DMI_OK);
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

static const double EX43_B[3] = {2 * PI, 10 * PI, 20 * PI};

static void test_ex43_1000(void)
{
    ex43_exp_vs(1000, 3, EX43_B, 1);
}

static void test_ex43_9991(void)
{
    ex43_exp_vs(9991, 3, EX43_B, 1);
}

/* The recursion's limit |b| h <= pi (dmi.h): at its edge, b h = pi, -pi
 * (the largest such |b| in double) and 0.9 pi, the 1e-11 bound holds; one
 * ulp beyond, RECURSIVE is refused (the message says why) and AUTO takes
 * the cost model's method, here FFT (bitwise). */
static void test_bh_limit(void)
{
    const size_t N = 1000;
    const double h = 1.0 / (double)N;
    double edge = PI / h;
    while (edge * h > PI) /* (PI is pi rounded down) */
        edge = nextafter(edge, 0);
    const double b[3] = {edge, -edge, 0.9 * edge};
    printf("\n  b h = %.17g:", edge * h);
    ex43_exp_vs(N, 3, b, 0);

    const double a1[1] = {0}, over[1] = {nextafter(edge, INFINITY)}, C[4] = {0, 0, 1, 0};
    dmi_solver *s[3] = {NULL, NULL, NULL};
    paper_example e[3] = {{43}, {43}, {43}};
    const int method[3] = {DMI_CONV_AUTO, DMI_CONV_DIRECT, DMI_CONV_FFT};
    for (int i = 0; i < 3; i++) {
        CU_ASSERT_FATAL(dmi_create(&s[i], 2, 1.0, N) == DMI_OK);
        CU_ASSERT(paper_setup(s[i], &e[i]) == DMI_OK);
        CU_ASSERT(dmi_set_kernel_exp(s[i], 1, a1, over, C, NULL) == DMI_OK);
        CU_ASSERT(dmi_set_convolution(s[i], method[i]) == DMI_OK);
        CU_ASSERT_FATAL(dmi_init(s[i]) == DMI_OK);
        CU_ASSERT(dmi_advance(s[i], 2 * N) == DMI_OK);
    }
    CU_ASSERT(core_same_state(s[0], s[2])); /* FFT: one kernel entry, N >= 382 */
    CU_ASSERT_EQUAL(dmi_set_convolution(s[0], DMI_CONV_RECURSIVE), DMI_EINVAL);
    CU_ASSERT(says(s[0], "b[0] = 3141.59", "is beyond [-pi, pi], where its samples alias"));
    for (int i = 0; i < 3; i++)
        dmi_free(&s[i]);
}

int main(int argc, char **argv)
{
    static const core_test tests[] = {
        {"dmi_set_kernel_exp: bad arguments, callback kernels and growing terms refused",
         test_errors},
        {"AUTO = RECURSIVE bitwise; with a growing term = FFT, its cost model's pick", test_auto},
        {"RECURSIVE: failed steps around an anchor leave the solver bitwise unchanged",
         test_failed_step},
        {"RECURSIVE: state save/load continues bitwise across anchors", test_state},
        {"RECURSIVE, parts in one row: W summed in the step = after a load, bitwise; = DIRECT",
         test_one_row},
        {"RECURSIVE: switching methods between steps", test_switch},
        {"dmi_set_kernel_exp copies its arrays", test_copies},
        {"RECURSIVE without a kernel: W = 0, bitwise DIRECT", test_no_kernel},
        {"Example 4.3 as exponentials, N = 1000: RECURSIVE = DIRECT to 1e-11", test_ex43_1000},
        {"Example 4.3 as exponentials, N = 9991: RECURSIVE = DIRECT to 1e-11", test_ex43_9991},
        {"RECURSIVE's limit |b| h <= pi: 1e-11 at the edge, refused beyond", test_bh_limit},
        {NULL, NULL}};
    return core_main(argc, argv, "core: exponential-sum kernels", tests);
}
