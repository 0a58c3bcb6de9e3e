/*
 * Every error path of the core library: invalid arguments, calls in
 * the wrong state, sizes too large to allocate, callbacks that fail or return
 * NaN / Inf at each stage, and the guarantee that after any failure the
 * solver is bitwise unchanged and, once the cause is fixed, goes on exactly
 * like a solver that never failed.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core_test.h"

/* ---- a solver and its twin ----------------------------------------------------
 * s receives the call under test; r is set up identically and never fails.
 * After the call both are stepped on: s must still agree with r bitwise. */

enum { STAGE_CREATED, STAGE_INITIALISED, STAGE_STEPPED };
enum { TWIN_N = 64, STEPPED = 3 * TWIN_N / 2 + 5 }; /* steps of STAGE_STEPPED: past N */

typedef struct {
    core_model ms, mr;
    dmi_solver *s, *r;
    unsigned char *before; /* state bytes of s before the call (initialised stages) */
    size_t size;
} twin;

static void twin_close(twin *tw)
{
    dmi_free(&tw->s);
    dmi_free(&tw->r);
    free(tw->before);
    tw->before = NULL;
}

/* The operator A of the twins: the model's resolvent callback, or built in. */
enum { OP_CALLBACK, OP_FRICTION, OP_BOX };

static int set_operator(dmi_solver *s, int op)
{
    static const double alpha[2] = {0.5, 2.0}, lo[2] = {-10, -INFINITY}, hi[2] = {10, 3};
    return op == OP_FRICTION ? dmi_set_friction(s, alpha)
           : op == OP_BOX    ? dmi_set_box(s, lo, hi)
                             : DMI_OK;
}

static int twin_open_op(twin *tw, int stage, int op, int method)
{
    memset(tw, 0, sizeof *tw);
    int ok = dmi_create(&tw->s, 2, 1.0, TWIN_N) == DMI_OK &&
             dmi_create(&tw->r, 2, 1.0, TWIN_N) == DMI_OK &&
             core_model_setup(tw->s, &tw->ms) == DMI_OK &&
             core_model_setup(tw->r, &tw->mr) == DMI_OK && set_operator(tw->s, op) == DMI_OK &&
             set_operator(tw->r, op) == DMI_OK && dmi_set_convolution(tw->s, method) == DMI_OK &&
             dmi_set_convolution(tw->r, method) == DMI_OK;
    if (ok && stage >= STAGE_INITIALISED)
        ok = dmi_init(tw->s) == DMI_OK && dmi_init(tw->r) == DMI_OK;
    if (ok && stage >= STAGE_STEPPED)
        ok = dmi_advance(tw->s, STEPPED) == DMI_OK && dmi_advance(tw->r, STEPPED) == DMI_OK;
    if (ok && stage >= STAGE_INITIALISED)
        ok = (tw->before = core_save(tw->s, &tw->size)) != NULL;
    if (!ok)
        twin_close(tw);
    return ok;
}

static int twin_open(twin *tw, int stage)
{
    return twin_open_op(tw, stage, OP_CALLBACK, DMI_CONV_AUTO);
}

/* Initialises both if needed, advances both k steps; 1 iff their states agree bitwise. */
static int twin_agree(twin *tw, size_t k)
{
    uint64_t p;
    if (dmi_get_step_index(tw->s, &p) == DMI_ESTATE &&
        (dmi_init(tw->s) != DMI_OK || dmi_init(tw->r) != DMI_OK))
        return 0;
    return dmi_advance(tw->s, k) == DMI_OK && dmi_advance(tw->r, k) == DMI_OK &&
           core_same_state(tw->s, tw->r);
}

/* rc must be code with a message, s unchanged and still the twin of r. */
static void check_error(twin *tw, int rc, int code, const char *what)
{
    if (rc != code)
        printf("\n  %s returned %d, expected %d", what, rc, code);
    CU_ASSERT_EQUAL(rc, code);
    if (dmi_last_error(tw->s)[0] == '\0')
        printf("\n  %s: no message", what);
    CU_ASSERT(dmi_last_error(tw->s)[0] != '\0');
    if (tw->before)
        CU_ASSERT(core_state_is(tw->s, tw->before, tw->size));
    CU_ASSERT(twin_agree(tw, 5));
}

/* Makes call (which may use tw.s and the arrays u, big) on a fresh twin at
 * the stage given and checks the outcome with check_error. */
#define EXPECT_ERROR(stage, call, code)                                                   \
    do {                                                                                  \
        twin tw;                                                                          \
        double u[2 * TWIN_N + 64] = {0}, big[2 * TWIN_N + 64] = {0};                      \
        CU_ASSERT_FATAL(twin_open(&tw, stage));                                           \
        CU_ASSERT_STRING_EQUAL(dmi_last_error(tw.s), "");                                 \
        check_error(&tw, (call), code, #call);                                            \
        (void)u;                                                                          \
        (void)big;                                                                        \
        twin_close(&tw);                                                                  \
    } while (0)

/* ---- dmi_create ------------------------------------------------------------------ */

static void expect_create(size_t n, double tau, size_t N, int code1, int code2)
{
    static char sentinel; /* *out must be set to NULL on error */
    dmi_solver *s = (dmi_solver *)(void *)&sentinel;
    int rc = dmi_create(&s, n, tau, N);
    if (rc != code1 && rc != code2)
        printf("\n  dmi_create(n = %zu, tau = %g, N = %zu) returned %d", n, tau, N, rc);
    CU_ASSERT(rc == code1 || rc == code2);
    CU_ASSERT_PTR_NULL(s);
    dmi_free(&s);
}

static void test_create(void)
{
    CU_ASSERT_EQUAL(dmi_create(NULL, 2, 1.0, 4), DMI_EINVAL);
    expect_create(0, 1.0, 4, DMI_EINVAL, DMI_EINVAL);
    expect_create(2, 1.0, 0, DMI_EINVAL, DMI_EINVAL);
    const double bad_tau[] = {0.0, -0.0, -1.0, -DBL_MAX, NAN, -NAN, INFINITY, -INFINITY};
    for (size_t i = 0; i < sizeof bad_tau / sizeof *bad_tau; i++)
        expect_create(2, bad_tau[i], 4, DMI_EINVAL, DMI_EINVAL);
    expect_create(2, DBL_MIN, 4, DMI_EINVAL, DMI_EINVAL);     /* h = tau / N subnormal */
    expect_create(2, DBL_MIN / 4, 1, DMI_EINVAL, DMI_EINVAL); /* tau itself subnormal */
    /* sizes that overflow size_t or no machine has: an error, never a crash */
    expect_create(SIZE_MAX / 4, 1.0, 1, DMI_ENOMEM, DMI_EINVAL);
    expect_create(SIZE_MAX, 1.0, 1, DMI_ENOMEM, DMI_EINVAL);
    expect_create(1, 1.0, SIZE_MAX, DMI_ENOMEM, DMI_EINVAL);
    expect_create(2, 1.0, SIZE_MAX / 2, DMI_ENOMEM, DMI_EINVAL);
    expect_create(SIZE_MAX / 2, 1.0, SIZE_MAX / 2, DMI_ENOMEM, DMI_EINVAL);
#if SIZE_MAX > 0xffffffffu
    expect_create((size_t)1 << 33, 1.0, (size_t)1 << 31, DMI_ENOMEM, DMI_EINVAL);
    /* 2^62 bytes: no overflow, but beyond any address space */
    expect_create(1, 1.0, (size_t)1 << 58, DMI_ENOMEM, DMI_ENOMEM);
#endif
    /* and the edge that is valid: the largest tau */
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL(dmi_create(&s, 1, DBL_MAX, 1), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_h(s), DBL_MAX);
    dmi_free(&s);
}

static int unit_kernel(double s, double *out, void *user)
{
    (void)s;
    (void)user;
    out[0] = 1;
    return 0;
}

/* N n^2 kernel samples of 2^49 bytes (n = 2^23, N = 1; beyond any address
 * space) while the history ring is modest: dmi_init must fail cleanly. */
static void test_kernel_too_large(void)
{
#if SIZE_MAX > 0xffffffffu
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, (size_t)1 << 23, 1.0, 1), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel(s, unit_kernel, NULL), DMI_OK);
    int rc = dmi_init(s);
    CU_ASSERT(rc == DMI_ENOMEM || rc == DMI_EINVAL);
    CU_ASSERT(dmi_last_error(s)[0] != '\0');
    CU_ASSERT_EQUAL(dmi_step(s), DMI_ESTATE);
    dmi_free(&s);
    CU_ASSERT_PTR_NULL(s);
#endif
}

/* Every function with a NULL solver. */
static void test_null_solver(void)
{
    double u[4] = {0}, alpha[2] = {1, 1}, lo[2] = {0, 0}, hi[2] = {1, 1};
    unsigned char buf[512] = {0};
    uint64_t p;
    CU_ASSERT_EQUAL(dmi_set_rhs(NULL, core_rhs, NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_resolvent(NULL, core_resolvent, NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_friction(NULL, alpha), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_box(NULL, lo, hi), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_kernel(NULL, core_kernel, NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_history(NULL, core_history, NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_convolution(NULL, DMI_CONV_DIRECT), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_init(NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_step(NULL), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_advance(NULL, 1), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_get_state(NULL, u), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_get_past(NULL, 0, u), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_get_step_index(NULL, &p), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_get_step_terms(NULL, u, u + 2), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_state_save(NULL, buf, sizeof buf), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_state_load(NULL, buf, sizeof buf), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_time(NULL), 0.0);
    CU_ASSERT_EQUAL(dmi_get_h(NULL), 0.0);
    CU_ASSERT_EQUAL(dmi_state_size(NULL), 0);
    CU_ASSERT_PTR_NOT_NULL_FATAL(dmi_last_error(NULL));
    CU_ASSERT(dmi_last_error(NULL)[0] != '\0');
    dmi_free(NULL);
    dmi_solver *s = NULL;
    dmi_free(&s);
    CU_ASSERT_PTR_NULL(s);
}

/* Invalid arguments on a valid solver: DMI_EINVAL, message, solver unchanged
 * (a failed setter keeps the former setting: s goes on like its twin). */
static void test_invalid_arguments(void)
{
    static const double ok2[2] = {1, 1}, neg[2] = {1, -1}, nan2[2] = {1, NAN},
                        inf2[2] = {INFINITY, 1}, ninf2[2] = {1, -INFINITY},
                        tiny_neg[2] = {-DBL_MIN, 1};
    for (int stage = STAGE_CREATED; stage <= STAGE_STEPPED; stage++) {
        EXPECT_ERROR(stage, dmi_set_friction(tw.s, NULL), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_set_friction(tw.s, neg), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_set_friction(tw.s, tiny_neg), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_set_friction(tw.s, nan2), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_set_friction(tw.s, inf2), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_set_friction(tw.s, ninf2), DMI_EINVAL);
        static const double lo_gt_hi[2] = {0, 2}, hi_small[2] = {1, 1.5};
        static const double pinf[2] = {INFINITY, INFINITY}, minf[2] = {-INFINITY, -INFINITY};
        EXPECT_ERROR(stage, dmi_set_box(tw.s, NULL, ok2), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_set_box(tw.s, ok2, NULL), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_set_box(tw.s, lo_gt_hi, hi_small), DMI_EINVAL); /* lo > hi */
        EXPECT_ERROR(stage, dmi_set_box(tw.s, nan2, pinf), DMI_EINVAL);         /* NaN lo */
        EXPECT_ERROR(stage, dmi_set_box(tw.s, minf, nan2), DMI_EINVAL);         /* NaN hi */
        EXPECT_ERROR(stage, dmi_set_box(tw.s, pinf, pinf), DMI_EINVAL);         /* empty */
        EXPECT_ERROR(stage, dmi_set_box(tw.s, minf, minf), DMI_EINVAL);         /* empty */
        EXPECT_ERROR(stage, dmi_set_convolution(tw.s, 3), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_set_convolution(tw.s, -1), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_set_convolution(tw.s, INT_MAX), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_get_state(tw.s, NULL), DMI_EINVAL);
    }
    for (int stage = STAGE_INITIALISED; stage <= STAGE_STEPPED; stage++) {
        EXPECT_ERROR(stage, dmi_get_past(tw.s, TWIN_N + 1, u), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_get_past(tw.s, SIZE_MAX, u), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_get_past(tw.s, 0, NULL), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_get_step_index(tw.s, NULL), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_state_save(tw.s, NULL, tw.size), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_state_save(tw.s, big, tw.size - 1), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_state_save(tw.s, big, 0), DMI_EINVAL);
        EXPECT_ERROR(stage, dmi_state_load(tw.s, NULL, tw.size), DMI_EINVAL);
    }
}

/* Calls not allowed in the solver's current state: DMI_ESTATE. */
static void test_wrong_state(void)
{
    uint64_t p;
    EXPECT_ERROR(STAGE_CREATED, dmi_step(tw.s), DMI_ESTATE);
    EXPECT_ERROR(STAGE_CREATED, dmi_advance(tw.s, 1), DMI_ESTATE);
    EXPECT_ERROR(STAGE_CREATED, dmi_get_state(tw.s, u), DMI_ESTATE);
    EXPECT_ERROR(STAGE_CREATED, dmi_get_past(tw.s, 0, u), DMI_ESTATE);
    EXPECT_ERROR(STAGE_CREATED, dmi_get_step_index(tw.s, &p), DMI_ESTATE);
    EXPECT_ERROR(STAGE_CREATED, dmi_get_step_terms(tw.s, u, u + 2), DMI_ESTATE);
    EXPECT_ERROR(STAGE_CREATED, dmi_state_save(tw.s, big, sizeof big), DMI_ESTATE);
    EXPECT_ERROR(STAGE_CREATED, dmi_state_load(tw.s, big, dmi_state_size(tw.s)), DMI_ESTATE);
    /* the last step's terms do not exist right after dmi_init */
    EXPECT_ERROR(STAGE_INITIALISED, dmi_get_step_terms(tw.s, u, u + 2), DMI_ESTATE);
    EXPECT_ERROR(STAGE_INITIALISED, dmi_get_step_terms(tw.s, NULL, NULL), DMI_ESTATE);
    /* kernel and history are sampled by dmi_init: fixed afterwards */
    for (int stage = STAGE_INITIALISED; stage <= STAGE_STEPPED; stage++) {
        EXPECT_ERROR(stage, dmi_set_kernel(tw.s, core_kernel, &tw.ms), DMI_ESTATE);
        EXPECT_ERROR(stage, dmi_set_kernel(tw.s, NULL, NULL), DMI_ESTATE);
        EXPECT_ERROR(stage, dmi_set_history(tw.s, core_history, &tw.ms), DMI_ESTATE);
        EXPECT_ERROR(stage, dmi_set_history(tw.s, NULL, NULL), DMI_ESTATE);
    }
    /* before dmi_init the clock reads 0 */
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, 1, 2.0, 3), DMI_OK);
    CU_ASSERT_EQUAL(dmi_time(s), 0.0);
    CU_ASSERT_EQUAL(dmi_get_h(s), 2.0 / 3.0);
    dmi_free(&s);
}

static void test_strerror(void)
{
    const int codes[] = {DMI_OK, DMI_EINVAL, DMI_ENOMEM, DMI_ECALLBACK, DMI_ENONFINITE, DMI_ESTATE};
    const size_t nc = sizeof codes / sizeof *codes;
    const char *unknown = dmi_strerror(12345);
    CU_ASSERT_PTR_NOT_NULL_FATAL(unknown);
    CU_ASSERT(unknown[0] != '\0');
    for (size_t i = 0; i < nc; i++) {
        const char *m = dmi_strerror(codes[i]);
        CU_ASSERT_PTR_NOT_NULL_FATAL(m);
        CU_ASSERT(m[0] != '\0');
        CU_ASSERT(strcmp(m, unknown) != 0);
        for (size_t j = 0; j < i; j++)
            CU_ASSERT(strcmp(m, dmi_strerror(codes[j])) != 0);
        printf("\n  %2d: %s", codes[i], m);
    }
    printf("\n");
    const int others[] = {1, -6, 100, INT_MIN, INT_MAX};
    for (size_t i = 0; i < sizeof others / sizeof *others; i++)
        CU_ASSERT_STRING_EQUAL(dmi_strerror(others[i]), unknown);
}

/* ---- failing callbacks ---------------------------------------------------------- */

static const int FAULTS[] = {FAULT_RETURN, FAULT_NAN, FAULT_INF, FAULT_NEGINF};
enum { NFAULTS = sizeof FAULTS / sizeof *FAULTS };

static int expected_code(int fault)
{
    return fault == FAULT_RETURN ? DMI_ECALLBACK : DMI_ENONFINITE;
}

static const char *KIND_NAME[CB_KINDS] = {"rhs", "resolvent", "kernel", "history"};

/* Kernel or history failing in the first dmi_init (at the first or a later
 * sample): the solver stays uninitialised; fixed, it runs like its twin. */
static void test_init_callbacks(void)
{
    const int kinds[] = {CB_KERNEL, CB_HISTORY};
    double u[2];
    for (int k = 0; k < 2; k++)
        for (int f = 0; f < NFAULTS; f++)
            for (long after = 0; after <= 4; after += 4) {
                twin tw;
                CU_ASSERT_FATAL(twin_open(&tw, STAGE_CREATED));
                tw.ms.fault[kinds[k]] = FAULTS[f];
                tw.ms.fail_after[kinds[k]] = after;
                int rc = dmi_init(tw.s);
                if (rc != expected_code(FAULTS[f]))
                    printf("\n  %s fault %d after %ld calls in dmi_init: %d (%s)",
                           KIND_NAME[kinds[k]], FAULTS[f], after, rc, dmi_last_error(tw.s));
                CU_ASSERT_EQUAL(dmi_step(tw.s), DMI_ESTATE);
                CU_ASSERT_EQUAL(dmi_get_state(tw.s, u), DMI_ESTATE);
                CU_ASSERT_EQUAL(dmi_time(tw.s), 0.0);
                tw.ms.fault[kinds[k]] = FAULT_NONE;
                check_error(&tw, rc, expected_code(FAULTS[f]), "dmi_init");
                twin_close(&tw);
            }
}

/* The same in a second dmi_init of a solver at t_p: it stays at t_p with its
 * former kernel samples and history, bitwise. */
static void test_reinit_callbacks(void)
{
    const int kinds[] = {CB_KERNEL, CB_HISTORY};
    for (int k = 0; k < 2; k++)
        for (int f = 0; f < NFAULTS; f++) {
            twin tw;
            CU_ASSERT_FATAL(twin_open(&tw, STAGE_STEPPED));
            tw.ms.fault[kinds[k]] = FAULTS[f];
            tw.ms.fail_after[kinds[k]] = tw.ms.calls[kinds[k]] + 3;
            int rc = dmi_init(tw.s);
            CU_ASSERT_EQUAL(dmi_time(tw.s), (double)STEPPED * (1.0 / TWIN_N));
            tw.ms.fault[kinds[k]] = FAULT_NONE;
            check_error(&tw, rc, expected_code(FAULTS[f]), "dmi_init again");
            twin_close(&tw);
        }
}

/* One callback fault in the next dmi_step of a twin at the given stage. */
static void check_step_fault(int stage, int method, int op, int kind, int fault)
{
    twin tw;
    CU_ASSERT_FATAL(twin_open_op(&tw, stage, op, method));
    tw.ms.fault[kind] = fault;
    tw.ms.fail_after[kind] = tw.ms.calls[kind];
    int rc = dmi_step(tw.s);
    CU_ASSERT_EQUAL(dmi_step(tw.s), rc);
    CU_ASSERT_EQUAL(dmi_advance(tw.s, 2), rc);
    CU_ASSERT(core_state_is(tw.s, tw.before, tw.size));
    if (rc != expected_code(fault))
        printf("\n  %s fault %d with operator %d, method %d, stage %d: %d", KIND_NAME[kind], fault,
               op, method, stage, rc);
    tw.ms.fault[kind] = FAULT_NONE;
    check_error(&tw, rc, expected_code(fault), "dmi_step");
    twin_close(&tw);
}

/* f or the resolvent failing in dmi_step, with the model's resolvent callback
 * or (f only) the built-in friction or box, with the direct and the FFT delay
 * sum, in the first step after dmi_init or later: DMI_ECALLBACK / DMI_ENONFINITE,
 * bitwise unchanged, a retry with the fault still there fails the same way,
 * and once fixed the run is that of the twin that never failed.  With the
 * friction this is the trap of the soft threshold, which maps NaN to 0. */
static void test_step_callbacks(void)
{
    const struct {
        int kind, op;
    } cases[] = {{CB_RHS, OP_CALLBACK}, {CB_RESOLVENT, OP_CALLBACK}, {CB_RHS, OP_FRICTION},
                 {CB_RHS, OP_BOX}};
    const int methods[] = {DMI_CONV_DIRECT, DMI_CONV_FFT};
    for (int stage = STAGE_INITIALISED; stage <= STAGE_STEPPED; stage++)
        for (int meth = 0; meth < 2; meth++)
            for (size_t c = 0; c < sizeof cases / sizeof *cases; c++)
                for (int f = 0; f < NFAULTS; f++)
                    check_step_fault(stage, methods[meth], cases[c].op, cases[c].kind, FAULTS[f]);
}

/* dmi_advance stops at the first failure and keeps the steps before it. */
static void test_advance_stops(void)
{
    twin tw;
    uint64_t p = 0;
    CU_ASSERT_FATAL(twin_open(&tw, STAGE_STEPPED));
    tw.ms.fault[CB_RHS] = FAULT_RETURN;
    tw.ms.fail_after[CB_RHS] = tw.ms.calls[CB_RHS] + 4;
    CU_ASSERT_EQUAL(dmi_advance(tw.s, 10), DMI_ECALLBACK);
    CU_ASSERT(dmi_last_error(tw.s)[0] != '\0');
    CU_ASSERT_EQUAL(dmi_get_step_index(tw.s, &p), DMI_OK);
    CU_ASSERT_EQUAL(p, STEPPED + 4);
    CU_ASSERT_EQUAL(dmi_advance(tw.r, 4), DMI_OK);
    CU_ASSERT(core_same_state(tw.s, tw.r));
    tw.ms.fault[CB_RHS] = FAULT_NONE;
    CU_ASSERT(twin_agree(&tw, 6));
    twin_close(&tw);
}

/* Finite callbacks whose values overflow inside the step. */
static int value_rhs(double t, const double *u, double *out, void *user)
{
    (void)t;
    (void)u;
    out[0] = *(const double *)user;
    return 0;
}

static int value_fn(double s, double *out, void *user)
{
    (void)s;
    out[0] = *(const double *)user;
    return 0;
}

/* n = 1, h = tau / N, constant f, H, z; friction alpha if alpha >= 0. */
static void expect_overflow(double tau, size_t N, double f, double H, double z, double alpha)
{
    dmi_solver *s = NULL;
    size_t size;
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, 1, tau, N), DMI_OK);
    if (alpha >= 0)
        CU_ASSERT_EQUAL(dmi_set_friction(s, &alpha), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_rhs(s, value_rhs, &f), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel(s, value_fn, &H), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_history(s, value_fn, &z), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    unsigned char *before = core_save(s, &size);
    CU_ASSERT_EQUAL(dmi_step(s), DMI_ENONFINITE);
    CU_ASSERT(dmi_last_error(s)[0] != '\0');
    CU_ASSERT(core_state_is(s, before, size));
    CU_ASSERT_EQUAL(dmi_time(s), 0.0);
    free(before);
    dmi_free(&s);
}

static void test_overflow(void)
{
    expect_overflow(1, 4, 0.0, 1e300, 1e300, -1);      /* W^p = inf */
    expect_overflow(1, 1, -DBL_MAX, 0.0, DBL_MAX, -1); /* X^p = U^p - h f = inf */
    expect_overflow(1, 2, 0.0, -DBL_MAX, DBL_MAX, -1); /* h W^p overflows: X^p = inf */
    /* h = 2: h f = inf and h W^p = -inf, so X^p = inf - inf = NaN, which the
     * soft threshold would turn into 0: X^p must be checked before it */
    expect_overflow(2, 1, DBL_MAX, -DBL_MAX / 2, 1.0, 1.0);
    expect_overflow(2, 1, DBL_MAX, -DBL_MAX / 2, 1.0, -1);
}

CORE_MAIN("core: error paths",
          {"dmi_create: invalid n, N, tau and sizes too large", test_create},
          {"dmi_init: N n^2 kernel samples too large to allocate", test_kernel_too_large},
          {"every function with a NULL solver", test_null_solver},
          {"invalid arguments: error, message, solver unchanged", test_invalid_arguments},
          {"calls in the wrong state: DMI_ESTATE", test_wrong_state},
          {"dmi_strerror of every code", test_strerror},
          {"kernel / history callbacks failing in the first dmi_init", test_init_callbacks},
          {"kernel / history callbacks failing in a second dmi_init", test_reinit_callbacks},
          {"f / resolvent failing in dmi_step: rollback and retry", test_step_callbacks},
          {"dmi_advance stops at the first failure", test_advance_stops},
          {"finite callbacks overflowing inside a step", test_overflow})
