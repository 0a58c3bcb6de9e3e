/*
 * dmi_create_h (libdmi 1.2): a step h that need not divide tau.
 * - h = tau / N as dmi_create computes it gives dmi_create's solver, bitwise,
 *   in every convolution method (saved states and windows after many steps);
 * - the delay term of a step is the quadrature written in dmi.h, computed
 *   here from the window with plain loops (the last cell weighted theta h);
 * - DIRECT, FFT, RECURSIVE and AUTO agree to 1e-12 with h not in tau / N;
 * - order 1 on Example 4.2 (exact solution (4.10)) with h not in tau / N;
 * - the history is sampled at t = -k h, k < N, and at -tau; the oldest
 *   stored state U^{p-N} is read by no step;
 * - saved states load only into a solver with the same h; bad arguments.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core_test.h"

static const double EXP_A[2] = {-1, 0}, EXP_B[2] = {0, 3}, EXP_C[8] = {0.5, 1, 0, 0, 0, 0, 1, -0.3};

/* Whether DMI_CONV_RECURSIVE takes the kernel (exponential, |b| h <= pi) at step h. */
static int recursive_takes(int expk, double h)
{
    return expk && EXP_B[1] * h <= 3.14159;
}

/* The n = 2 model of core_test.h on a new solver (h given: dmi_create_h;
 * h = 0: dmi_create with N), with its callback kernel, or the exponential
 * kernel above if expk; the method set; initialised.  NULL on failure. */
static dmi_solver *model(core_model *m, double tau, size_t N, double h, int expk, int method)
{
    dmi_solver *s = NULL;
    int rc = h > 0 ? dmi_create_h(&s, 2, tau, h) : dmi_create(&s, 2, tau, N);
    if (rc == DMI_OK)
        rc = core_model_setup(s, m);
    if (rc == DMI_OK && expk)
        rc = dmi_set_kernel_exp(s, 2, EXP_A, EXP_B, EXP_C, NULL);
    if (rc == DMI_OK)
        rc = dmi_set_convolution(s, method);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    if (rc != DMI_OK) {
        printf("\n  model(tau = %g, N = %zu, h = %g): %s\n", tau, N, h, dmi_last_error(s));
        dmi_free(&s);
    }
    return s;
}

/* The window of s (malloc'd, (N + 1) 2 values). */
static double *window(const dmi_solver *s)
{
    double *U = malloc((dmi_get_N(s) + 1) * 2 * sizeof *U);
    if (U && dmi_get_window(s, U) != DMI_OK) {
        free(U);
        U = NULL;
    }
    return U;
}

/* ---- h = tau / N: dmi_create's solver, bitwise ---------------------------------- */

static void test_bitwise_dmi_create(void)
{
    static const double taus[] = {1.0, 0.7, 3.3};
    static const size_t Ns[] = {1, 3, 7, 40, 100, 383, 1000};
    static const int methods[] = {DMI_CONV_AUTO, DMI_CONV_DIRECT, DMI_CONV_FFT,
                                  DMI_CONV_RECURSIVE};
    size_t cases = 0, same = 0, rounded = 0;
    for (size_t it = 0; it < sizeof taus / sizeof *taus; it++)
        for (size_t iN = 0; iN < sizeof Ns / sizeof *Ns; iN++)
            for (int expk = 0; expk < 2; expk++)
                for (size_t im = 0; im < sizeof methods / sizeof *methods; im++) {
                    const double tau = taus[it];
                    const size_t N = Ns[iN];
                    const int method = methods[im];
                    const double h = tau / (double)N;
                    if (method == DMI_CONV_RECURSIVE && !recursive_takes(expk, h))
                        continue;
                    /* h N < tau in exact arithmetic, or tau / h rounds above N:
                     * ceil would give N + 1 or a theta != 1 */
                    rounded += ceil(tau / h) != (double)N || fma((double)N, h, -tau) < 0;
                    core_model ma = {0}, mb = {0};
                    dmi_solver *a = model(&ma, tau, N, 0, expk, method);
                    dmi_solver *b = model(&mb, tau, N, h, expk, method);
                    CU_ASSERT_FATAL(a != NULL && b != NULL);
                    CU_ASSERT_EQUAL(dmi_get_N(b), N);
                    CU_ASSERT_EQUAL(dmi_get_h(b), dmi_get_h(a));
                    int ok = core_same_state(a, b); /* the history */
                    const size_t steps = 4 * N + 2 * N + 7; /* past the recursion's anchor */
                    CU_ASSERT_EQUAL(dmi_advance(a, steps), DMI_OK);
                    CU_ASSERT_EQUAL(dmi_advance(b, steps), DMI_OK);
                    ok &= core_same_state(a, b);
                    double *Ua = window(a), *Ub = window(b);
                    ok &= Ua && Ub && memcmp(Ua, Ub, (N + 1) * 2 * sizeof *Ua) == 0;
                    free(Ua);
                    free(Ub);
                    if (!ok)
                        printf("\n  tau = %g, N = %zu, kernel %s, method %d: not bitwise\n", tau,
                               N, expk ? "exp" : "callback", method);
                    cases++;
                    same += ok;
                    dmi_free(&a);
                    dmi_free(&b);
                }
    printf("\n  %zu of %zu cases bitwise equal (%zu with h N != tau or ceil(tau / h) != N)\n",
           same, cases, rounded);
    CU_ASSERT_EQUAL(same, cases);
    CU_ASSERT(rounded > 0); /* the exception of dmi.h is exercised */
}

/* ---- the quadrature ------------------------------------------------------------- */

/* W^p = h sum_{l<N-1} H(l h) U^{p-l} + theta h H((N-1) h) U^{p-N+1}, from the
 * window rows (row N - l is U^{p-l}), theta h = tau - (N - 1) h. */
static void quadrature(const double *U, size_t N, double tau, double h, int expk, double *W)
{
    W[0] = W[1] = 0;
    for (size_t l = 0; l < N; l++) {
        const double s = (double)l * h, w = l + 1 < N ? h : tau - (double)(N - 1) * h;
        double H[4] = {0, 0, 0, 0};
        if (expk)
            for (int k = 0; k < 2; k++)
                for (int e = 0; e < 4; e++)
                    H[e] += exp(EXP_A[k] * s) * cos(EXP_B[k] * s) * EXP_C[4 * k + e];
        else {
            core_model m = {0};
            core_kernel(s, H, &m);
        }
        const double *u = U + 2 * (N - l);
        W[0] += w * (H[0] * u[0] + H[1] * u[1]);
        W[1] += w * (H[2] * u[0] + H[3] * u[1]);
    }
}

/* Steps s, and checks at a few steps that the step's W (dmi_get_step_terms)
 * is the quadrature of the window before it.  The worst relative error. */
static double check_quadrature(dmi_solver *s, double tau, double h, int expk, size_t steps)
{
    const size_t N = dmi_get_N(s);
    double worst = 0;
    for (size_t p = 0; p < steps; p++) {
        double *U = p % 37 == 0 || p + 1 == steps ? window(s) : NULL;
        CU_ASSERT_EQUAL_FATAL(dmi_step(s), DMI_OK);
        if (!U)
            continue;
        double Wq[2], W[2];
        quadrature(U, N, tau, h, expk, Wq);
        CU_ASSERT_EQUAL(dmi_get_step_terms(s, W, NULL), DMI_OK);
        for (int i = 0; i < 2; i++)
            worst = fmax(worst, fabs(W[i] - Wq[i]) / fmax(fabs(Wq[i]), 1e-3));
        free(U);
    }
    return worst;
}

static void test_quadrature(void)
{
    static const struct {
        double tau, h;
        size_t N;
    } cases[] = {
        {1.0, 1.0 / 40.37, 41},   /* theta = 0.37 */
        {1.0, 1.0 / 40.93, 41},   /* theta = 0.93 */
        {2.5, 2.5 / 300.05, 301}, /* theta = 0.05 */
        {0.6, 0.25, 3},           /* theta = 0.4 */
        {0.6, 1.5, 1},            /* h > tau: theta = 0.4 */
    };
    static const int methods[] = {DMI_CONV_DIRECT, DMI_CONV_FFT, DMI_CONV_RECURSIVE, DMI_CONV_AUTO};
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++)
        for (int expk = 0; expk < 2; expk++)
            for (size_t im = 0; im < sizeof methods / sizeof *methods; im++) {
                if (methods[im] == DMI_CONV_RECURSIVE && !recursive_takes(expk, cases[c].h))
                    continue;
                core_model m = {0};
                dmi_solver *s = model(&m, cases[c].tau, 0, cases[c].h, expk, methods[im]);
                CU_ASSERT_FATAL(s != NULL);
                CU_ASSERT_EQUAL(dmi_get_N(s), cases[c].N);
                double worst = check_quadrature(s, cases[c].tau, cases[c].h, expk, 5 * cases[c].N + 40);
                if (!(worst <= 1e-12))
                    printf("\n  tau = %g, h = %.17g, kernel %s, method %d: W off the quadrature by "
                           "%.3e (relative)\n", cases[c].tau, cases[c].h, expk ? "exp" : "callback",
                           methods[im], worst);
                CU_ASSERT(worst <= 1e-12);
                dmi_free(&s);
            }
}

/* ---- the methods agree ------------------------------------------------------------ */

static void test_methods_agree(void)
{
    static const int methods[] = {DMI_CONV_DIRECT, DMI_CONV_FFT, DMI_CONV_RECURSIVE, DMI_CONV_AUTO};
    const double tau = 1.0, h = 1.0 / 700.37; /* N = 701 (FFT blocks in use), theta = 0.37 */
    const size_t steps = 5 * 701 + 11;
    for (int expk = 0; expk < 2; expk++) {
        core_model m[4];
        memset(m, 0, sizeof m);
        dmi_solver *s[4] = {NULL, NULL, NULL, NULL};
        size_t used = 0;
        for (size_t im = 0; im < 4; im++)
            if (methods[im] != DMI_CONV_RECURSIVE || expk) {
                s[used] = model(&m[used], tau, 0, h, expk, methods[im]);
                CU_ASSERT_FATAL(s[used] != NULL);
                used++;
            }
        double worst = 0, size = 0, u0[2], u[2];
        for (size_t p = 0; p < steps; p++)
            for (size_t i = 0; i < used; i++) {
                CU_ASSERT_EQUAL_FATAL(dmi_step(s[i]), DMI_OK);
                dmi_get_state(s[i], i ? u : u0);
                for (int j = 0; i && j < 2; j++)
                    worst = fmax(worst, fabs(u[j] - u0[j]));
                size = fmax(size, fabs(u0[0]) + fabs(u0[1]));
            }
        printf("\n  %s kernel, %zu methods, %zu steps: largest difference %.3e (|U| up to %.3g)",
               expk ? "exponential" : "callback", used, steps, worst, size);
        CU_ASSERT(worst <= 1e-12);
        CU_ASSERT(size > 0.1); /* not a comparison of zeros */
        for (size_t i = 0; i < used; i++)
            dmi_free(&s[i]);
    }
    printf("\n");
}

/* ---- order 1 on Example 4.2 ----------------------------------------------------------- */

/* max over t_p in [-1, 10] of |U^p - (w, w')(t_p)| of Example 4.2 with step h,
 * the history's rows at t = -k h (k < N) and -tau. */
static double example42_error(double h)
{
    paper_example ex = {42};
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create_h(&s, 2, 1.0, h), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(paper_setup(s, &ex), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(dmi_init(s), DMI_OK);
    const size_t N = dmi_get_N(s), M = (size_t)floor(10.0 / h);
    double u[2], err = 0;
    for (size_t k = 0; k <= N + M; k++) {
        double t;
        if (k <= N) {
            t = k == 0 ? -1.0 : -(double)(N - k) * h;
            CU_ASSERT_EQUAL_FATAL(dmi_get_past(s, N - k, u), DMI_OK);
        } else {
            CU_ASSERT_EQUAL_FATAL(dmi_step(s), DMI_OK);
            CU_ASSERT_EQUAL_FATAL(dmi_get_state(s, u), DMI_OK);
            t = dmi_time(s);
        }
        err = fmax(err, hypot(u[0] - paper_w(42, t), u[1] - paper_v(42, t)));
    }
    dmi_free(&s);
    return err;
}

static void test_order_example42(void)
{
    enum { K = 8 };
    double logh[K], loge[K];
    printf("\n  Example 4.2, h = 1/(1001 + 50 k + 0.37), k = 1..%d: max state errors", K);
    for (int k = 1; k <= K; k++) {
        const double h = 1.0 / (1001 + 50 * k + 0.37);
        const double e = example42_error(h);
        printf("%s%.4e", k == 1 ? " " : ", ", e);
        logh[k - 1] = log(h);
        loge[k - 1] = log(e);
    }
    const double slope = core_ls_slope(logh, loge, K);
    printf("\n  observed order (least-squares slope of log error against log h): %.4f\n", slope);
    CU_ASSERT(slope >= 0.95 && slope <= 1.05);
}

/* ---- the history's times ---------------------------------------------------------- */

typedef struct {
    size_t calls;
    double t[64];
} recorder;

static int record_history(double t, double *out, void *user)
{
    recorder *r = user;
    if (r->calls < 64)
        r->t[r->calls] = t;
    r->calls++;
    out[0] = t;
    out[1] = 1 + t * t;
    return 0;
}

static void history_times(double tau, double h, size_t N)
{
    recorder r = {0};
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create_h(&s, 2, tau, h), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(dmi_get_N(s), N);
    CU_ASSERT_EQUAL(dmi_set_history(s, record_history, &r), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(dmi_init(s), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(r.calls, N + 1);
    double U[2 * 64];
    CU_ASSERT_EQUAL_FATAL(dmi_get_window(s, U), DMI_OK);
    int ok = 1;
    for (size_t k = 0; k <= N; k++) { /* U^{-k}: row N - k, at -k h (k < N), -tau (k = N) */
        const double t = k == N ? -tau : -(double)k * h;
        ok &= r.t[k] == t && r.t[k] >= -tau && U[2 * (N - k)] == t &&
              U[2 * (N - k) + 1] == 1 + t * t;
    }
    CU_ASSERT(ok);
    dmi_free(&s);
}

static void test_history_times(void)
{
    history_times(1.0, 0.3, 4);   /* -0, -0.3, -0.6, -0.9 and -1 (not -1.2) */
    history_times(1.0, 0.25, 4);  /* h = tau / 4: -0.75 and -1 = -4 h */
    history_times(0.6, 2.0, 1);   /* h > tau: 0 and -0.6 */
}

/* The oldest row of the window, U^{p-N}, is read by no step (dmi.h): two
 * solvers whose windows differ only there step alike, bitwise, every method. */
static void test_oldest_row_unread(void)
{
    static const int methods[] = {DMI_CONV_DIRECT, DMI_CONV_FFT, DMI_CONV_RECURSIVE};
    const double h = 1.0 / 500.37; /* N = 501 */
    for (size_t im = 0; im < 3; im++) {
        core_model ma = {0}, mb = {0};
        dmi_solver *a = model(&ma, 1.0, 0, h, 1, methods[im]);
        dmi_solver *b = model(&mb, 1.0, 0, h, 1, methods[im]);
        CU_ASSERT_FATAL(a && b);
        CU_ASSERT_EQUAL(dmi_advance(a, 777), DMI_OK);
        CU_ASSERT_EQUAL(dmi_advance(b, 777), DMI_OK); /* (the same t_p) */
        double *U = window(a);
        CU_ASSERT_FATAL(U != NULL);
        CU_ASSERT_EQUAL(dmi_set_window(a, U), DMI_OK); /* (both engines rebuilt alike) */
        U[0] = 1e3;
        U[1] = -7;
        CU_ASSERT_EQUAL(dmi_set_window(b, U), DMI_OK);
        int same = 1;
        double ua[2], ub[2];
        for (int k = 0; k < 3 * 501; k++) {
            same &= dmi_step(a) == DMI_OK && dmi_step(b) == DMI_OK;
            dmi_get_state(a, ua);
            dmi_get_state(b, ub);
            same &= memcmp(ua, ub, sizeof ua) == 0;
        }
        CU_ASSERT(same);
        free(U);
        dmi_free(&a);
        dmi_free(&b);
    }
}

/* ---- saved states ------------------------------------------------------------------ */

/* dmi_state_load of a's state into b: the code, and b unchanged on failure. */
static int load_from(const dmi_solver *a, dmi_solver *b)
{
    size_t na, nb;
    unsigned char *sa = core_save(a, &na), *sb = core_save(b, &nb);
    int rc = sa && sb ? dmi_state_load(b, sa, na) : DMI_ENOMEM;
    if (rc != DMI_OK) {
        CU_ASSERT(core_state_is(b, sb, nb));
        printf("\n  refused: %s", dmi_last_error(b));
    } else {
        CU_ASSERT(core_same_state(a, b));
    }
    free(sa);
    free(sb);
    return rc;
}

static void test_states(void)
{
    const double h = 1.0 / 40.37, h2 = 1.0 / 40.5; /* both N = 41, theta 0.37 and 0.5 */
    core_model m[5];
    memset(m, 0, sizeof m);
    dmi_solver *a = model(&m[0], 1.0, 0, h, 0, DMI_CONV_AUTO);
    dmi_solver *same = model(&m[1], 1.0, 0, h, 0, DMI_CONV_AUTO);
    dmi_solver *other_h = model(&m[2], 1.0, 0, h2, 0, DMI_CONV_AUTO);
    dmi_solver *plain = model(&m[3], 1.0, 41, 0, 0, DMI_CONV_AUTO);
    dmi_solver *plain_h = model(&m[4], 1.0, 0, 1.0 / 41, 0, DMI_CONV_AUTO);
    CU_ASSERT_FATAL(a && same && other_h && plain && plain_h);
    CU_ASSERT_EQUAL(dmi_get_N(a), 41);
    CU_ASSERT_EQUAL(dmi_get_N(other_h), 41);
    CU_ASSERT_EQUAL(dmi_get_N(plain_h), 41);
    /* h recorded: 8 bytes more than dmi_create's (n, N) state */
    CU_ASSERT_EQUAL(dmi_state_size(a), dmi_state_size(plain) + 8);
    CU_ASSERT_EQUAL(dmi_state_size(plain_h), dmi_state_size(plain));
    dmi_advance(a, 100);
    CU_ASSERT_EQUAL(load_from(a, same), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(a, 50), DMI_OK); /* and it steps on bitwise */
    CU_ASSERT_EQUAL(dmi_advance(same, 50), DMI_OK);
    CU_ASSERT(core_same_state(a, same));
    CU_ASSERT_EQUAL(load_from(a, other_h), DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(other_h), "h = ") != NULL);
    CU_ASSERT_EQUAL(load_from(a, plain), DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(plain), "dmi_create_h") != NULL);
    CU_ASSERT_EQUAL(load_from(plain, a), DMI_EINVAL);
    CU_ASSERT(strstr(dmi_last_error(a), "dmi_create_h") != NULL);
    dmi_advance(plain, 70);
    CU_ASSERT_EQUAL(load_from(plain, plain_h), DMI_OK); /* h = 1/41: dmi_create's */
    printf("\n");
    dmi_free(&a);
    dmi_free(&same);
    dmi_free(&other_h);
    dmi_free(&plain);
    dmi_free(&plain_h);
}

/* ---- bad arguments ------------------------------------------------------------------ */

static void test_refused(void)
{
    dmi_solver *s = (dmi_solver *)&s; /* must be set to NULL on error */
    const double bad_h[] = {0.0, -0.1, NAN, INFINITY, -INFINITY, 1e-310 /* subnormal */};
    for (size_t i = 0; i < sizeof bad_h / sizeof *bad_h; i++) {
        s = (dmi_solver *)&s;
        CU_ASSERT_EQUAL(dmi_create_h(&s, 2, 1.0, bad_h[i]), DMI_EINVAL);
        CU_ASSERT_PTR_NULL(s);
    }
    const double bad_tau[] = {0.0, -1.0, NAN, INFINITY};
    for (size_t i = 0; i < sizeof bad_tau / sizeof *bad_tau; i++) {
        s = (dmi_solver *)&s;
        CU_ASSERT_EQUAL(dmi_create_h(&s, 2, bad_tau[i], 0.1), DMI_EINVAL);
        CU_ASSERT_PTR_NULL(s);
    }
    s = (dmi_solver *)&s;
    CU_ASSERT_EQUAL(dmi_create_h(&s, 0, 1.0, 0.1), DMI_EINVAL);
    CU_ASSERT_PTR_NULL(s);
    CU_ASSERT_EQUAL(dmi_create_h(NULL, 2, 1.0, 0.1), DMI_EINVAL);
    /* more cells than any memory: tau / h = 1e300, 2^50, and (N + 1) n overflowing */
    s = (dmi_solver *)&s;
    CU_ASSERT_EQUAL(dmi_create_h(&s, 2, 1.0, 1e-300), DMI_ENOMEM);
    CU_ASSERT_PTR_NULL(s);
    CU_ASSERT_EQUAL(dmi_create_h(&s, 2, 1.0, 0x1p-50), DMI_ENOMEM);
    CU_ASSERT_EQUAL(dmi_create_h(&s, (size_t)1 << 62, 1.0, 0.5), DMI_ENOMEM);
    CU_ASSERT_PTR_NULL(s);
    CU_ASSERT_EQUAL(dmi_create_h(&s, 2, 1e308, 1e-10), DMI_ENOMEM);
    /* h > tau, h = tau: one cell */
    CU_ASSERT_EQUAL_FATAL(dmi_create_h(&s, 2, 1.0, 3.0), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_N(s), 1);
    CU_ASSERT_EQUAL(dmi_get_h(s), 3.0);
    dmi_free(&s);
    CU_ASSERT_EQUAL_FATAL(dmi_create_h(&s, 2, 1.0, 1.0), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_N(s), 1);
    dmi_free(&s);
    CU_ASSERT_EQUAL(dmi_get_N(NULL), 0);
}

CORE_MAIN("core: dmi_create_h",
          {"h = tau / N gives dmi_create's solver bitwise, every method", test_bitwise_dmi_create},
          {"the step's W is the quadrature with the partial last cell", test_quadrature},
          {"DIRECT = FFT = RECURSIVE = AUTO to 1e-12, h not in tau / N", test_methods_agree},
          {"order 1 on Example 4.2 with h not in tau / N", test_order_example42},
          {"the history is sampled at -k h, k < N, and at -tau", test_history_times},
          {"the window's oldest row is read by no step", test_oldest_row_unread},
          {"saved states record h", test_states},
          {"bad arguments", test_refused})
