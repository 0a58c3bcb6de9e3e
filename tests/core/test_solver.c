/*
 * Solver life cycle and settings: independent solvers, dmi_free,
 * the last-wins rule among dmi_set_resolvent / dmi_set_friction / dmi_set_box,
 * the defaults (nothing set), a user resolvent equal to the built-in
 * friction, the clock t_p = p h, restarting with dmi_init.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core_test.h"

/* Two solvers stepped in turn give what each gives alone. */
static void test_interleaved(void)
{
    enum { K = 700 };
    paper_example ex = {42};
    core_model m1 = {0}, m2 = {0};
    dmi_solver *a = core_paper_solver(&ex, 200), *b = core_model_solver(&m1, 16);
    dmi_solver *a2 = core_paper_solver(&ex, 200), *b2 = core_model_solver(&m2, 16);
    dmi_solver *a3 = core_paper_solver(&ex, 200); /* same model, same user data as a2 */
    CU_ASSERT_FATAL(a && b && a2 && b2 && a3);
    CU_ASSERT_EQUAL(dmi_advance(a, K), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(b, K), DMI_OK);
    int ok = 1;
    for (int k = 0; k < K; k++)
        ok &= dmi_step(a2) == DMI_OK && dmi_step(b2) == DMI_OK && dmi_step(a3) == DMI_OK;
    CU_ASSERT(ok);
    CU_ASSERT(core_same_state(a, a2));
    CU_ASSERT(core_same_state(a, a3));
    CU_ASSERT(core_same_state(b, b2));
    CU_ASSERT(!core_same_state(a, b));
    dmi_free(&a);
    dmi_free(&b);
    dmi_free(&a2);
    dmi_free(&b2);
    dmi_free(&a3);
}

static void test_free(void)
{
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, 2, 1.0, 4), DMI_OK);
    CU_ASSERT_PTR_NOT_NULL(s);
    dmi_free(&s);
    CU_ASSERT_PTR_NULL(s);
    dmi_free(&s); /* again: *s == NULL */
    dmi_free(NULL);
    CU_ASSERT_PTR_NULL(s);
}

/* ---- the resolvent: which setting is in force ---------------------------------
 * n = 2, f = C constant, z = Z0 constant, no kernel, h = 1/4: the first step's
 * resolvent argument is X = Z0 - h C, so U^1 = (I + hA)^{-1} X is known. */

static const double H4 = 0.25, C[2] = {3, -2}, Z0[2] = {0.7, -0.4};
static const double ALPHA[2] = {0.1, 0.2}, LO[2] = {0, -1}, HI[2] = {1, 0.05};

static int const_rhs(double t, const double *u, double *out, void *user)
{
    (void)t;
    (void)u;
    (void)user;
    out[0] = C[0];
    out[1] = C[1];
    return 0;
}

static int const_history(double t, double *out, void *user)
{
    (void)t;
    (void)user;
    out[0] = Z0[0];
    out[1] = Z0[1];
    return 0;
}

enum { OP_IDENTITY, OP_FRICTION, OP_BOX, OP_CALLBACK };

/* (I + h A)^{-1} x computed here for each operator. */
static void expected_resolvent(int op, const double *x, double *out)
{
    for (int i = 0; i < 2; i++) {
        double lam = H4 * ALPHA[i];
        switch (op) {
        case OP_FRICTION: out[i] = fabs(x[i]) > lam ? copysign(fabs(x[i]) - lam, x[i]) : 0.0; break;
        case OP_BOX: out[i] = fmin(fmax(x[i], LO[i]), HI[i]); break;
        case OP_CALLBACK: out[i] = x[i] / (1 + H4 * (i == 0 ? 1.0 : 2.0)); break;
        default: out[i] = x[i];
        }
    }
}

static int apply(dmi_solver *s, int op, core_model *m)
{
    switch (op) {
    case OP_FRICTION: return dmi_set_friction(s, ALPHA);
    case OP_BOX: return dmi_set_box(s, LO, HI);
    case OP_CALLBACK: return dmi_set_resolvent(s, core_resolvent, m);
    default: return dmi_set_resolvent(s, NULL, NULL);
    }
}

/* Applies the settings ops[0..k-1] in order (before dmi_init if before_init,
 * else between dmi_init and the first step); the last one must be in force. */
static void check_last_wins(const int *ops, int k, int before_init)
{
    core_model m = {0};
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, 2, 1.0, 4), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_rhs(s, const_rhs, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_history(s, const_history, NULL), DMI_OK);
    for (int i = 0; before_init && i < k; i++)
        CU_ASSERT_EQUAL(apply(s, ops[i], &m), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    for (int i = 0; !before_init && i < k; i++)
        CU_ASSERT_EQUAL(apply(s, ops[i], &m), DMI_OK);
    CU_ASSERT_EQUAL(dmi_step(s), DMI_OK);
    double x[2] = {Z0[0] - H4 * C[0], Z0[1] - H4 * C[1]}, want[2], got[2], X[2];
    expected_resolvent(k ? ops[k - 1] : OP_IDENTITY, x, want);
    CU_ASSERT_EQUAL(dmi_get_state(s, got), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_step_terms(s, NULL, X), DMI_OK);
    int ok = got[0] == want[0] && got[1] == want[1] && X[0] == x[0] && X[1] == x[1];
    if (!ok)
        printf("\n  settings ending with %d: U^1 = (%.17g, %.17g), expected (%.17g, %.17g)",
               k ? ops[k - 1] : -1, got[0], got[1], want[0], want[1]);
    CU_ASSERT(ok);
    dmi_free(&s);
}

static void test_last_wins(void)
{
    static const int seqs[][3] = {
        {OP_FRICTION, OP_BOX, -1},      {OP_BOX, OP_FRICTION, -1},
        {OP_BOX, OP_CALLBACK, -1},      {OP_CALLBACK, OP_FRICTION, -1},
        {OP_FRICTION, OP_CALLBACK, -1}, {OP_CALLBACK, OP_BOX, -1},
        {OP_FRICTION, OP_IDENTITY, -1}, {OP_BOX, OP_IDENTITY, -1},
        {OP_CALLBACK, OP_IDENTITY, -1}, {OP_BOX, OP_CALLBACK, OP_FRICTION},
        {OP_FRICTION, OP_BOX, OP_CALLBACK}};
    /* the four results differ, so the check tells them apart */
    double x[2] = {Z0[0] - H4 * C[0], Z0[1] - H4 * C[1]}, r[4][2];
    for (int op = 0; op < 4; op++)
        expected_resolvent(op, x, r[op]);
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < i; j++)
            CU_ASSERT(r[i][0] != r[j][0] || r[i][1] != r[j][1]);
    for (int before = 0; before <= 1; before++) {
        check_last_wins(NULL, 0, before);
        for (size_t q = 0; q < sizeof seqs / sizeof *seqs; q++)
            check_last_wins(seqs[q], seqs[q][2] < 0 ? 2 : 3, before);
    }
}

/* Setters between steps change nothing stored and act from the next step on;
 * dmi_set_rhs(s, NULL, ...) restores f = 0. */
static void test_settings_between_steps(void)
{
    core_model m = {0};
    dmi_solver *s = core_model_solver(&m, 8);
    CU_ASSERT_FATAL(s != NULL);
    CU_ASSERT_EQUAL(dmi_advance(s, 11), DMI_OK);
    size_t size;
    unsigned char *before = core_save(s, &size);
    CU_ASSERT_EQUAL(dmi_set_rhs(s, NULL, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_friction(s, ALPHA), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_box(s, LO, HI), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_resolvent(s, NULL, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_convolution(s, DMI_CONV_DIRECT), DMI_OK);
    CU_ASSERT(core_state_is(s, before, size));
    /* now f = 0, A = 0: U^{p+1} = U^p - h W^p with W^p computed here */
    double U[2], W[2] = {0, 0}, U1[2], z[2], Hl[4];
    CU_ASSERT_EQUAL(dmi_get_state(s, U), DMI_OK);
    const double h = 1.0 / 8;
    core_model quiet = {0};
    for (size_t l = 0; l < 8; l++) {
        CU_ASSERT_EQUAL(dmi_get_past(s, l, z), DMI_OK);
        memset(Hl, 0, sizeof Hl);
        core_kernel((double)l * h, Hl, &quiet);
        W[0] += Hl[0] * z[0] + Hl[1] * z[1];
        W[1] += Hl[2] * z[0] + Hl[3] * z[1];
    }
    CU_ASSERT_EQUAL(dmi_step(s), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_state(s, U1), DMI_OK);
    for (int i = 0; i < 2; i++)
        CU_ASSERT_DOUBLE_EQUAL(U1[i], U[i] - h * h * W[i], 1e-14);
    free(before);
    dmi_free(&s);
}

/* ---- defaults -------------------------------------------------------------------- */

static void test_defaults(void)
{
    /* nothing set: z = 0, f = 0, A = 0, H = 0, so U = 0 for ever */
    dmi_solver *s = NULL;
    double u[3] = {1, 1, 1};
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, 3, 0.5, 5), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    int zero = 1;
    for (size_t lag = 0; lag <= 5; lag++)
        zero &= dmi_get_past(s, lag, u) == DMI_OK && u[0] == 0 && u[1] == 0 && u[2] == 0;
    CU_ASSERT_EQUAL(dmi_advance(s, 50), DMI_OK);
    zero &= dmi_get_state(s, u) == DMI_OK && u[0] == 0 && u[1] == 0 && u[2] == 0;
    CU_ASSERT(zero);
    dmi_free(&s);

    /* only the history: U^p = z(t_p) for p <= 0, then z(0) exactly */
    core_model m = {0}, quiet = {0};
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, 2, 1.0, 10), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_history(s, core_history, &m), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    double z[2], z0[2];
    int exact = 1;
    for (size_t lag = 0; lag <= 10; lag++) {
        core_history(-(double)lag * 0.1, z, &quiet);
        exact &= dmi_get_past(s, lag, u) == DMI_OK && u[0] == z[0] && u[1] == z[1];
    }
    CU_ASSERT(exact);
    core_history(0.0, z0, &quiet);
    for (int p = 1; p <= 40; p++)
        exact &= dmi_step(s) == DMI_OK && dmi_get_state(s, u) == DMI_OK && u[0] == z0[0] &&
                 u[1] == z0[1];
    CU_ASSERT(exact);
    dmi_free(&s);
}

/* A user resolvent that is the soft threshold sign(x) max(|x| - lambda alpha, 0)
 * gives bitwise the run of the built-in friction (Example 4.3, with static
 * phases); the step terms give the friction force of the step. */
static int soft_threshold(double lambda, const double *x, double *out, void *user)
{
    const double *alpha = user;
    for (int i = 0; i < 2; i++) {
        double m = fabs(x[i]) - lambda * alpha[i];
        out[i] = m > 0 ? copysign(m, x[i]) : 0.0;
    }
    return 0;
}

static void test_user_friction(void)
{
    paper_example ex = {43};
    double alpha[2] = {0.0, 1.0}, u[2];
    dmi_solver *a = NULL, *b = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create(&a, 2, 1.0, 500), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(dmi_create(&b, 2, 1.0, 500), DMI_OK);
    CU_ASSERT_EQUAL(paper_setup(a, &ex), DMI_OK);
    CU_ASSERT_EQUAL(paper_setup(b, &ex), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_resolvent(b, soft_threshold, alpha), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(a), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(b), DMI_OK);
    int same = 1, force_ok = 1;
    size_t stuck = 0;
    const double h = 1.0 / 500;
    for (int k = 0; k < 2500; k++) {
        same &= dmi_step(a) == DMI_OK && dmi_step(b) == DMI_OK;
        if (k % 50 == 0)
            same &= core_same_state(a, b);
        double X[2];
        force_ok &= dmi_get_state(a, u) == DMI_OK && dmi_get_step_terms(a, NULL, X) == DMI_OK;
        stuck += u[1] == 0.0;
        /* (X - U^{p+1}) / h is the element of A(U^{p+1}) = {0} x sigma(v) selected:
         * the friction force, sign(v) when sliding, in [-1, 1] when stuck */
        double force = (X[1] - u[1]) / h;
        force_ok &= fabs(X[0] - u[0]) == 0.0 && fabs(force) <= 1 + 1e-9 &&
                    (u[1] == 0.0 || fabs(force - copysign(1.0, u[1])) <= 1e-9);
    }
    CU_ASSERT(same && core_same_state(a, b));
    CU_ASSERT(stuck > 100); /* the dead zone of the threshold was used */
    CU_ASSERT(force_ok);
    dmi_free(&a);
    dmi_free(&b);
}

/* ---- the clock and restarting ------------------------------------------------------ */

static void test_time(void)
{
    const double tau = 0.7;
    const size_t N = 3;
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, 1, tau, N), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_h(s), tau / (double)N);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    int exact = 1;
    uint64_t p = 99;
    for (size_t k = 0; k <= 3000; k++) {
        exact &= dmi_time(s) == (double)k * (tau / (double)N);
        exact &= dmi_get_step_index(s, &p) == DMI_OK && p == k;
        if (k < 3000)
            exact &= dmi_step(s) == DMI_OK;
    }
    CU_ASSERT(exact);
    CU_ASSERT_EQUAL(dmi_advance(s, 0), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_step_index(s, &p), DMI_OK);
    CU_ASSERT_EQUAL(p, 3000);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK); /* restart */
    CU_ASSERT_EQUAL(dmi_time(s), 0.0);
    CU_ASSERT_EQUAL(dmi_get_step_index(s, &p), DMI_OK);
    CU_ASSERT_EQUAL(p, 0);
    dmi_free(&s);
}

/* The history is asked for z(t) with -tau <= t <= 0 only, as dmi.h promises,
 * even where -N * (tau / N) rounds below -tau (tau = 0.7999999999999999,
 * N = 3), and its samples are z(0), z(-h), ..., z(-tau). */
typedef struct {
    double tau;
    double t[4];
    int calls;
} domain_check;

static int history_in_domain(double t, double *out, void *user)
{
    domain_check *d = user;
    if (t < -d->tau || t > 0 || d->calls >= 4)
        return 1;
    d->t[d->calls++] = t;
    out[0] = t;
    return 0;
}

static void test_history_domain(void)
{
    const double tau = 0.7999999999999999;
    const size_t N = 3;
    CU_ASSERT(-(double)N * (tau / (double)N) < -tau); /* the case that needs care */
    domain_check d = {tau, {0}, 0};
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, 1, tau, N), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_history(s, history_in_domain, &d), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    CU_ASSERT_EQUAL(d.calls, 4);
    double u = 1;
    CU_ASSERT(dmi_get_past(s, N, &u) == DMI_OK && u == -tau);
    CU_ASSERT(dmi_get_past(s, 0, &u) == DMI_OK && u == 0.0 && !signbit(u));
    dmi_free(&s);
}

/* a: a model solver that ran 45 steps and was then restarted by dmi_init;
 * b: a new one. */
static int restarted_pair(core_model *m1, core_model *m2, dmi_solver **a, dmi_solver **b)
{
    *a = core_model_solver(m1, 16);
    *b = core_model_solver(m2, 16);
    return *a && *b && dmi_advance(*a, 45) == DMI_OK && dmi_init(*a) == DMI_OK;
}

/* dmi_init on a solver that has run restarts it exactly as a new one: same
 * counter, history and no last step; the same run afterwards, bitwise. */
static void test_restart(void)
{
    core_model m1 = {0}, m2 = {0};
    dmi_solver *a, *b;
    CU_ASSERT_FATAL(restarted_pair(&m1, &m2, &a, &b));
    uint64_t pa = 1, pb = 2;
    CU_ASSERT(dmi_get_step_index(a, &pa) == DMI_OK && dmi_get_step_index(b, &pb) == DMI_OK &&
              pa == pb);
    double ua[2], ub[2];
    int same = 1;
    for (size_t lag = 0; lag <= 16; lag++)
        same &= dmi_get_past(a, lag, ua) == DMI_OK && dmi_get_past(b, lag, ub) == DMI_OK &&
                memcmp(ua, ub, sizeof ua) == 0;
    CU_ASSERT(same);
    CU_ASSERT_EQUAL(dmi_get_step_terms(a, ua, NULL), DMI_ESTATE);
    CU_ASSERT_EQUAL(dmi_advance(a, 30), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(b, 30), DMI_OK);
    CU_ASSERT(core_same_state(a, b));
    dmi_free(&a);
    dmi_free(&b);
}

/* The saved bytes are a function of the solver's state: right after dmi_init a
 * restarted solver saves the same bytes as a new one (no leftovers of the
 * former run, such as the last step's terms). */
static void test_restart_bytes(void)
{
    core_model m1 = {0}, m2 = {0};
    dmi_solver *a, *b;
    CU_ASSERT_FATAL(restarted_pair(&m1, &m2, &a, &b));
    int same = core_same_state(a, b);
    if (!same)
        printf("\n  BUG (src/dmi.c): after dmi_init the saved state still holds the former "
               "run's last_W / last_X\n");
    CU_ASSERT(same);
    dmi_free(&a);
    dmi_free(&b);
}

CORE_MAIN("core: solver life cycle and settings",
          {"two solvers interleaved = each alone", test_interleaved},
          {"dmi_free sets NULL, accepts NULL", test_free},
          {"last of set_resolvent / set_friction / set_box wins", test_last_wins},
          {"setters between steps: nothing stored changes, act from the next step",
           test_settings_between_steps},
          {"defaults: nothing set gives U = z(0) exactly", test_defaults},
          {"user soft-threshold resolvent = built-in friction, bitwise", test_user_friction},
          {"dmi_time = p * (tau / N) from the counter", test_time},
          {"history sampled on [-tau, 0] only, z(-tau) at lag N", test_history_domain},
          {"dmi_init restarts a solver exactly", test_restart},
          {"after dmi_init a restarted solver saves the bytes of a new one", test_restart_bytes})
