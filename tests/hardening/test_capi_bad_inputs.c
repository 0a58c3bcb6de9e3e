/*
 * Every bad input of the C API (include/dmi.h), one row of
 * docs/bad-inputs.md per case.  Each case checks the error code the header
 * documents, a message naming the cause, that the solver is bitwise unchanged
 * (step counter, all N + 1 stored states, last step terms) and that it then
 * steps on exactly like a solver that never saw the bad call.
 *
 * Usage: test_capi_bad_inputs            run the tests (CUnit)
 *        test_capi_bad_inputs --table    print the table rows with the messages
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <CUnit/CUnit.h>

#include "bytes.h" /* the state's layout (src/) */
#include "capi_model.h"
#include "core_test.h" /* core_state_v1: a state of libdmi 1.0 */
#include "dmi.h"
#include "hard_util.h"

/* Under AddressSanitizer, impossible allocations must return NULL (as malloc
 * does) instead of aborting: the N-too-large cases test exactly that. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}

static int print_table; /* --table: print the rows instead of only testing */

static const char *code_name(int code)
{
    static const char *const names[] = {"DMI_OK", "DMI_EINVAL", "DMI_ENOMEM", "DMI_ECALLBACK",
                                        "DMI_ENONFINITE", "DMI_ESTATE"};
    return code <= 0 && code >= DMI_ESTATE ? names[-code] : "?";
}

static void row(const char *id, const char *fn, const char *input, int code, const char *msg)
{
    if (print_table)
        printf("| %s | `%s` | %s | `%s` | %s |\n", id, fn, input, code_name(code), msg);
}

/* ---- snapshots: everything observable of a solver's time-stepping state ---- */

typedef struct {
    int init;
    uint64_t p;
    size_t size;
    unsigned char *bytes;
    int terms_rc;
    double W[MODEL_n], X[MODEL_n];
    double time;
} snapshot;

static void snap_take(const dmi_solver *s, snapshot *sn)
{
    memset(sn, 0, sizeof *sn);
    sn->init = dmi_get_step_index(s, &sn->p) == DMI_OK;
    sn->size = dmi_state_size(s);
    if (sn->init)
        sn->bytes = core_save(s, &sn->size);
    sn->terms_rc = dmi_get_step_terms(s, sn->W, sn->X);
    sn->time = dmi_time(s);
}

static int snap_equal(const snapshot *a, const snapshot *b)
{
    if (a->init != b->init || a->p != b->p || a->size != b->size || a->terms_rc != b->terms_rc ||
        memcmp(&a->time, &b->time, sizeof a->time) != 0)
        return 0;
    if (a->init && (!a->bytes || !b->bytes || memcmp(a->bytes, b->bytes, a->size) != 0))
        return 0;
    return a->terms_rc != DMI_OK ||
           (memcmp(a->W, b->W, sizeof a->W) == 0 && memcmp(a->X, b->X, sizeof a->X) == 0);
}

static void snap_free(snapshot *sn)
{
    free(sn->bytes);
    sn->bytes = NULL;
}

/* ---- setups ------------------------------------------------------------------ */

enum {
    S_NULL,  /* no solver: the call passes NULL */
    S_FRESH, /* created, callbacks set, not initialised */
    S_INIT0, /* initialised, no step */
    S_INIT   /* initialised, two steps taken */
};
#define REF_STEPS 3 /* every case ends at p = 3 and is compared with the reference */

static int build(int setup, model *m, dmi_solver **s)
{
    *s = NULL;
    if (setup == S_NULL)
        return DMI_OK;
    int rc = model_solver(s, m);
    if (rc == DMI_OK && setup != S_FRESH)
        rc = dmi_init(*s);
    if (rc == DMI_OK && setup == S_INIT)
        rc = dmi_advance(*s, 2);
    return rc;
}

/* State bytes of the well-behaved model after init and REF_STEPS steps. */
static unsigned char *reference_state(size_t *size)
{
    model m;
    model_default(&m);
    dmi_solver *s = NULL;
    unsigned char *b = NULL;
    if (build(S_INIT0, &m, &s) == DMI_OK && dmi_advance(s, REF_STEPS) == DMI_OK)
        b = core_save(s, size);
    dmi_free(&s);
    return b;
}

/* Valid state bytes of another well-behaved solver (n, tau, N given) after one
 * step; caller frees. */
static unsigned char *saved_state(size_t n, double tau, size_t N, size_t *size)
{
    model m;
    model_default(&m);
    dmi_solver *s = NULL;
    unsigned char *b = NULL;
    *size = 0;
    if (dmi_create(&s, n, tau, N) == DMI_OK && dmi_set_history(s, model_history, &m) == DMI_OK &&
        dmi_init(s) == DMI_OK && dmi_step(s) == DMI_OK)
        b = core_save(s, size);
    dmi_free(&s);
    return b;
}

/* The state's checksum, recomputed after an edit (layout: src/bytes.h) so
 * that the edit reaches the checks behind it. */
static void fix_checksum(unsigned char *b, size_t size)
{
    dmi_put_u64(b, DMI_STATE_AT_CHECKSUM, dmi_fnv1a_skip(b, size, DMI_STATE_AT_CHECKSUM));
}
/* A state of libdmi 1.0 (format version 1, which libdmi reads since 1.2)
 * given with 24 bytes more, the size of a version-2 state of s: refused by
 * its size. */
static int load_v1_long(dmi_solver *s)
{
    size_t size;
    unsigned char *b = core_state_v1(s, MODEL_n, MODEL_N, MODEL_TAU, &size);
    unsigned char *longer = b ? calloc(size + 24, 1) : NULL;
    int rc = -100;
    if (longer) {
        memcpy(longer, b, size);
        rc = dmi_state_load(s, longer, size + 24);
    }
    free(longer);
    free(b);
    return rc;
}

/* Byte offset of U_j^{p-lag} (lag N + 2: X^{p-1}) in the model's state. */
#define AT_DOUBLE(lag, j) dmi_state_at_double(MODEL_n, (lag), (j))

/* ---- the cases ------------------------------------------------------------------ */

#define CALL(name, ...)                                                                           \
    static int name(dmi_solver *s, model *m)                                                      \
    {                                                                                             \
        (void)s;                                                                                  \
        (void)m;                                                                                  \
        __VA_ARGS__                                                                               \
    }
#define MIS(cb, md, at, component)                                                                \
    do {                                                                                          \
        m->cb.mode = (md);                                                                        \
        m->cb.from = m->cb.calls + (at);                                                          \
        m->cb.comp = (component);                                                                 \
    } while (0)

static double out2[MODEL_n];
static uint64_t out_p;

CALL(c_rhs_null, return dmi_set_rhs(NULL, model_rhs, m);)
CALL(c_res_null, return dmi_set_resolvent(NULL, model_resolvent, m);)
CALL(c_fric_null_s, const double a[2] = {1, 1}; return dmi_set_friction(NULL, a);)
CALL(c_fric_null, return dmi_set_friction(s, NULL);)
CALL(c_fric_neg, const double a[2] = {1, -1}; return dmi_set_friction(s, a);)
CALL(c_fric_nan, const double a[2] = {NAN, 1}; return dmi_set_friction(s, a);)
CALL(c_fric_pinf, const double a[2] = {1, INFINITY}; return dmi_set_friction(s, a);)
CALL(c_fric_ninf, const double a[2] = {-INFINITY, 1}; return dmi_set_friction(s, a);)
CALL(c_box_null_s, const double l[2] = {-1, -1}, u[2] = {1, 1}; return dmi_set_box(NULL, l, u);)
CALL(c_box_lo_null, const double u[2] = {1, 1}; return dmi_set_box(s, NULL, u);)
CALL(c_box_hi_null, const double l[2] = {-1, -1}; return dmi_set_box(s, l, NULL);)
CALL(c_box_lo_nan, const double l[2] = {-1, NAN}, u[2] = {1, 1}; return dmi_set_box(s, l, u);)
CALL(c_box_hi_nan, const double l[2] = {-1, -1}, u[2] = {NAN, 1}; return dmi_set_box(s, l, u);)
CALL(c_box_empty, const double l[2] = {0, 2}, u[2] = {1, 1}; return dmi_set_box(s, l, u);)
CALL(c_box_lo_inf, const double l[2] = {INFINITY, -1}, u[2] = {INFINITY, 1};
     return dmi_set_box(s, l, u);)
CALL(c_box_hi_ninf, const double l[2] = {-1, -INFINITY}, u[2] = {1, -INFINITY};
     return dmi_set_box(s, l, u);)
CALL(c_kern_null, return dmi_set_kernel(NULL, model_kernel, m);)
CALL(c_kern_late, return dmi_set_kernel(s, model_kernel, m);)
/* dmi_set_kernel_exp: a 2-term kernel of the n = 2 model (C and D 2 x 2 x 2) */
static const double xa[2] = {0, -1}, xb[2] = {2, 0};
static const double xC[8] = {0.1, 0, 0, 0.1, 0.2, 0, 0, 0.2}, xD[8] = {0.3, 0, 0, 0, 0, 0, 0, 0};
/* x with x[at] = v: the arrays of a bad call */
static const double *with(const double *x, size_t len, size_t at, double v)
{
    static double out[8];
    memcpy(out, x, len * sizeof *x);
    out[at] = v;
    return out;
}
CALL(c_kexp_null, return dmi_set_kernel_exp(NULL, 2, xa, xb, xC, xD);)
CALL(c_kexp_k0, return dmi_set_kernel_exp(s, 0, xa, xb, xC, xD);)
CALL(c_kexp_a_null, return dmi_set_kernel_exp(s, 2, NULL, xb, xC, xD);)
CALL(c_kexp_b_null, return dmi_set_kernel_exp(s, 2, xa, NULL, xC, xD);)
CALL(c_kexp_C_null, return dmi_set_kernel_exp(s, 2, xa, xb, NULL, xD);)
CALL(c_kexp_a_nan, return dmi_set_kernel_exp(s, 2, with(xa, 2, 1, NAN), xb, xC, xD);)
CALL(c_kexp_a_inf, return dmi_set_kernel_exp(s, 2, with(xa, 2, 0, -INFINITY), xb, xC, xD);)
CALL(c_kexp_b_nan, return dmi_set_kernel_exp(s, 2, xa, with(xb, 2, 0, NAN), xC, xD);)
CALL(c_kexp_b_inf, return dmi_set_kernel_exp(s, 2, xa, with(xb, 2, 1, INFINITY), xC, xD);)
CALL(c_kexp_C_nan, return dmi_set_kernel_exp(s, 2, xa, xb, with(xC, 8, 6, NAN), xD);)
CALL(c_kexp_C_inf, return dmi_set_kernel_exp(s, 2, xa, xb, with(xC, 8, 1, INFINITY), xD);)
CALL(c_kexp_D_nan, return dmi_set_kernel_exp(s, 2, xa, xb, xC, with(xD, 8, 3, NAN));)
CALL(c_kexp_D_inf, return dmi_set_kernel_exp(s, 2, xa, xb, xC, with(xD, 8, 5, -INFINITY));)
CALL(c_kexp_late, return dmi_set_kernel_exp(s, 2, xa, xb, xC, xD);)
CALL(c_conv_rec_callback, return dmi_set_convolution(s, DMI_CONV_RECURSIVE);)
CALL(c_hist_null, return dmi_set_history(NULL, model_history, m);)
CALL(c_hist_late, return dmi_set_history(s, model_history, m);)
CALL(c_conv_null, return dmi_set_convolution(NULL, DMI_CONV_DIRECT);)
CALL(c_conv_m1, return dmi_set_convolution(s, -1);)
CALL(c_conv_3, return dmi_set_convolution(s, 3);)
CALL(c_conv_max, return dmi_set_convolution(s, INT_MAX);)
CALL(c_conv_min, return dmi_set_convolution(s, INT_MIN);)
CALL(c_init_null, return dmi_init(NULL);)
CALL(c_init_kfail, MIS(kernel, CB_FAIL, 0, 0); return dmi_init(s);)
CALL(c_init_kfail_last, MIS(kernel, CB_FAIL, MODEL_N - 1, 0); return dmi_init(s);)
CALL(c_init_knan, MIS(kernel, CB_NAN, 0, 2); return dmi_init(s);)
CALL(c_init_kpinf, MIS(kernel, CB_PINF, 1, 3); return dmi_init(s);)
CALL(c_init_kninf, MIS(kernel, CB_NINF, 2, 0); return dmi_init(s);)
CALL(c_init_hfail, MIS(history, CB_FAIL, 0, 0); return dmi_init(s);)
CALL(c_init_hfail_last, MIS(history, CB_FAIL, MODEL_N, 0); return dmi_init(s);)
CALL(c_init_hnan, MIS(history, CB_NAN, 0, 0); return dmi_init(s);)
CALL(c_init_hpinf, MIS(history, CB_PINF, 2, 1); return dmi_init(s);)
CALL(c_init_hninf, MIS(history, CB_NINF, 3, 1); return dmi_init(s);)
CALL(c_step_null, return dmi_step(NULL);)
CALL(c_step_early, return dmi_step(s);)
CALL(c_step_ffail, MIS(rhs, CB_FAIL, 0, 0); return dmi_step(s);)
CALL(c_step_fnan, MIS(rhs, CB_NAN, 0, 1); return dmi_step(s);)
CALL(c_step_fpinf, MIS(rhs, CB_PINF, 0, 0); return dmi_step(s);)
CALL(c_step_fninf, MIS(rhs, CB_NINF, 0, 1); return dmi_step(s);)
CALL(c_step_rfail, MIS(resolvent, CB_FAIL, 0, 0); return dmi_step(s);)
CALL(c_step_rnan, MIS(resolvent, CB_NAN, 0, 0); return dmi_step(s);)
CALL(c_step_rpinf, MIS(resolvent, CB_PINF, 0, 1); return dmi_step(s);)
CALL(c_step_rninf, MIS(resolvent, CB_NINF, 0, 1); return dmi_step(s);)
CALL(c_adv_null, return dmi_advance(NULL, 3);)
CALL(c_adv_early, return dmi_advance(s, 3);)
CALL(c_adv_ffail, MIS(rhs, CB_FAIL, 0, 0); return dmi_advance(s, 5);)
CALL(c_idx_null_s, return dmi_get_step_index(NULL, &out_p);)
CALL(c_idx_null, return dmi_get_step_index(s, NULL);)
CALL(c_idx_early, return dmi_get_step_index(s, &out_p);)
CALL(c_state_null_s, return dmi_get_state(NULL, out2);)
CALL(c_state_null, return dmi_get_state(s, NULL);)
CALL(c_state_early, return dmi_get_state(s, out2);)
CALL(c_past_null_s, return dmi_get_past(NULL, 0, out2);)
CALL(c_past_null, return dmi_get_past(s, 1, NULL);)
CALL(c_past_early, return dmi_get_past(s, 0, out2);)
CALL(c_past_lag, return dmi_get_past(s, MODEL_N + 1, out2);)
CALL(c_past_lagmax, return dmi_get_past(s, SIZE_MAX, out2);)
CALL(c_terms_null_s, return dmi_get_step_terms(NULL, out2, out2);)
CALL(c_terms_early, return dmi_get_step_terms(s, out2, NULL);)
CALL(c_terms_nostep, return dmi_get_step_terms(s, NULL, out2);)

static int save_with(dmi_solver *s, size_t size, int null_buf)
{
    size_t need = dmi_state_size(s) ? dmi_state_size(s) : 1024;
    unsigned char *b = malloc(need);
    int rc = b ? dmi_state_save(s, null_buf ? NULL : b, size) : -100;
    free(b);
    return rc;
}
CALL(c_save_null_s, return save_with(NULL, 1024, 0);)
CALL(c_save_null, return save_with(s, dmi_state_size(s), 1);)
CALL(c_save_early, return save_with(s, dmi_state_size(s), 0);)
CALL(c_save_short, return save_with(s, dmi_state_size(s) - 1, 0);)
CALL(c_save_zero, return save_with(s, 0, 0);)

/* Loads the state of an (n, tau, N) solver after one step, edited by edit at
 * byte offset at (see the edit kinds below), with length size + extra. */
enum { E_NONE, E_BYTE, E_WORD, E_DOUBLE_FIXED, E_WORD_FIXED };
static int load_edited(dmi_solver *s, size_t n, double tau, size_t N, int edit, size_t at,
                       double value, long extra, int null_buf)
{
    size_t size;
    unsigned char *b = saved_state(n, tau, N, &size);
    if (!b)
        return -100;
    size_t len = (size_t)((long)size + extra);
    unsigned char *c = calloc(len > size ? len : size, 1);
    if (!c) {
        free(b);
        return -100;
    }
    memcpy(c, b, size);
    free(b);
    uint64_t w = (uint64_t)value;
    switch (edit) {
    case E_BYTE: c[at] ^= 0x5a; break;
    case E_WORD:
    case E_WORD_FIXED: memcpy(c + at, &w, sizeof w); break;
    case E_DOUBLE_FIXED: memcpy(c + at, &value, sizeof value); break;
    }
    if (edit == E_WORD_FIXED || edit == E_DOUBLE_FIXED)
        fix_checksum(c, size);
    int rc = dmi_state_load(s, null_buf ? NULL : c, len);
    free(c);
    return rc;
}
#define LOAD(s, ...) load_edited(s, MODEL_n, MODEL_TAU, MODEL_N, __VA_ARGS__)
CALL(c_load_null_s, return LOAD(NULL, E_NONE, 0, 0, 0, 0);)
CALL(c_load_null, return LOAD(s, E_NONE, 0, 0, 0, 1);)
CALL(c_load_early, return LOAD(s, E_NONE, 0, 0, 0, 0);)
CALL(c_load_short, return LOAD(s, E_NONE, 0, 0, -1, 0);)
CALL(c_load_long, return LOAD(s, E_NONE, 0, 0, 1, 0);)
CALL(c_load_empty, return load_edited(s, MODEL_n, MODEL_TAU, MODEL_N, E_NONE, 0, 0,
                                      -(long)dmi_state_size(s), 0);)
CALL(c_load_magic, return LOAD(s, E_BYTE, 0, 0, 0, 0);)
CALL(c_load_version, return load_v1_long(s);)
CALL(c_load_foreign_nN, return load_edited(s, 1, MODEL_TAU, 11, E_NONE, 0, 0, 0, 0);)
CALL(c_load_foreign_tau, return load_edited(s, MODEL_n, 2.0, MODEL_N, E_NONE, 0, 0, 0, 0);)
CALL(c_load_foreign_n_hdr, return LOAD(s, E_WORD_FIXED, DMI_STATE_AT_n, 3, 0, 0);)
CALL(c_load_checksum, return LOAD(s, E_BYTE, DMI_STATE_AT_CHECKSUM + 4, 0, 0, 0);)
CALL(c_load_data, return LOAD(s, E_BYTE, AT_DOUBLE(0, 0) + 3, 0, 0, 0);)
CALL(c_load_have_last, return LOAD(s, E_WORD_FIXED, DMI_STATE_AT_STEPPED, 2, 0, 0);)
CALL(c_load_flag0, return LOAD(s, E_WORD_FIXED, DMI_STATE_AT_STEPPED, 0, 0, 0);)
CALL(c_load_step_huge, return LOAD(s, E_WORD, DMI_STATE_AT_P, 1e19, 0, 0);)
CALL(c_load_nan, return LOAD(s, E_DOUBLE_FIXED, AT_DOUBLE(0, 0), NAN, 0, 0);)
CALL(c_load_inf, return LOAD(s, E_DOUBLE_FIXED, AT_DOUBLE(MODEL_N + 2, 0), -INFINITY, 0, 0);)

typedef struct {
    const char *id, *fn, *input;
    int setup;
    int (*call)(dmi_solver *s, model *m);
    int expect;
    const char *msg; /* a part of dmi_last_error(s) (NULL: not checked) */
} bad_case;

/* clang-format off */
static const bad_case cases[] = {
    {"C20", "dmi_set_rhs", "s = NULL", S_NULL, c_rhs_null, DMI_EINVAL, NULL},
    {"C21", "dmi_set_resolvent", "s = NULL", S_NULL, c_res_null, DMI_EINVAL, NULL},
    {"C22", "dmi_set_friction", "s = NULL", S_NULL, c_fric_null_s, DMI_EINVAL, NULL},
    {"C23", "dmi_set_friction", "alpha = NULL", S_INIT, c_fric_null, DMI_EINVAL, "alpha"},
    {"C24", "dmi_set_friction", "alpha = {1, -1}", S_INIT, c_fric_neg, DMI_EINVAL, "alpha[1]"},
    {"C25", "dmi_set_friction", "alpha = {NaN, 1}", S_INIT, c_fric_nan, DMI_EINVAL, "alpha[0]"},
    {"C26", "dmi_set_friction", "alpha = {1, +Inf}", S_INIT, c_fric_pinf, DMI_EINVAL, "alpha[1]"},
    {"C27", "dmi_set_friction", "alpha = {-Inf, 1}", S_FRESH, c_fric_ninf, DMI_EINVAL, "alpha[0]"},
    {"C28", "dmi_set_box", "s = NULL", S_NULL, c_box_null_s, DMI_EINVAL, NULL},
    {"C29", "dmi_set_box", "lo = NULL", S_INIT, c_box_lo_null, DMI_EINVAL, "lo"},
    {"C30", "dmi_set_box", "hi = NULL", S_INIT, c_box_hi_null, DMI_EINVAL, "hi"},
    {"C31", "dmi_set_box", "lo[1] = NaN", S_INIT, c_box_lo_nan, DMI_EINVAL, "NaN"},
    {"C32", "dmi_set_box", "hi[0] = NaN", S_FRESH, c_box_hi_nan, DMI_EINVAL, "NaN"},
    {"C33", "dmi_set_box", "lo[1] = 2 > hi[1] = 1", S_INIT, c_box_empty, DMI_EINVAL, "lo[1]"},
    {"C34", "dmi_set_box", "lo[0] = hi[0] = +Inf (empty box)", S_INIT, c_box_lo_inf, DMI_EINVAL, "empty"},
    {"C35", "dmi_set_box", "lo[1] = hi[1] = -Inf (empty box)", S_INIT, c_box_hi_ninf, DMI_EINVAL, "empty"},
    {"C36", "dmi_set_kernel", "s = NULL", S_NULL, c_kern_null, DMI_EINVAL, NULL},
    {"C37", "dmi_set_kernel", "after dmi_init", S_INIT, c_kern_late, DMI_ESTATE, "dmi_set_kernel"},
    {"C115", "dmi_set_kernel_exp", "s = NULL", S_NULL, c_kexp_null, DMI_EINVAL, NULL},
    {"C116", "dmi_set_kernel_exp", "K = 0", S_FRESH, c_kexp_k0, DMI_EINVAL, "K = 0"},
    {"C117", "dmi_set_kernel_exp", "a = NULL", S_FRESH, c_kexp_a_null, DMI_EINVAL, "a is NULL"},
    {"C118", "dmi_set_kernel_exp", "b = NULL", S_FRESH, c_kexp_b_null, DMI_EINVAL, "b is NULL"},
    {"C119", "dmi_set_kernel_exp", "C = NULL", S_FRESH, c_kexp_C_null, DMI_EINVAL, "C is NULL"},
    {"C120", "dmi_set_kernel_exp", "a[1] = NaN", S_FRESH, c_kexp_a_nan, DMI_EINVAL, "a[1] = nan"},
    {"C121", "dmi_set_kernel_exp", "a[0] = -Inf", S_FRESH, c_kexp_a_inf, DMI_EINVAL, "a[0] = -inf"},
    {"C122", "dmi_set_kernel_exp", "b[0] = NaN", S_FRESH, c_kexp_b_nan, DMI_EINVAL, "b[0] = nan"},
    {"C123", "dmi_set_kernel_exp", "b[1] = +Inf", S_FRESH, c_kexp_b_inf, DMI_EINVAL, "b[1] = inf"},
    {"C124", "dmi_set_kernel_exp", "C[6] = NaN", S_FRESH, c_kexp_C_nan, DMI_EINVAL, "C[6] (term 1, entry (1, 0))"},
    {"C125", "dmi_set_kernel_exp", "C[1] = +Inf", S_FRESH, c_kexp_C_inf, DMI_EINVAL, "C[1] (term 0, entry (0, 1))"},
    {"C126", "dmi_set_kernel_exp", "D[3] = NaN", S_FRESH, c_kexp_D_nan, DMI_EINVAL, "D[3] (term 0, entry (1, 1))"},
    {"C127", "dmi_set_kernel_exp", "D[5] = -Inf", S_FRESH, c_kexp_D_inf, DMI_EINVAL, "D[5] (term 1, entry (0, 1))"},
    {"C128", "dmi_set_kernel_exp", "after dmi_init", S_INIT, c_kexp_late, DMI_ESTATE, "dmi_init"},
    {"C129", "dmi_set_convolution", "DMI_CONV_RECURSIVE with a callback kernel, after dmi_init", S_INIT, c_conv_rec_callback, DMI_EINVAL, "callback"},
    {"C38", "dmi_set_history", "s = NULL", S_NULL, c_hist_null, DMI_EINVAL, NULL},
    {"C39", "dmi_set_history", "after dmi_init", S_INIT0, c_hist_late, DMI_ESTATE, "dmi_set_history"},
    {"C40", "dmi_set_convolution", "s = NULL", S_NULL, c_conv_null, DMI_EINVAL, NULL},
    {"C41", "dmi_set_convolution", "method = -1", S_INIT, c_conv_m1, DMI_EINVAL, "-1"},
    {"C42", "dmi_set_convolution", "method = 3", S_FRESH, c_conv_3, DMI_EINVAL, "3"},
    {"C43", "dmi_set_convolution", "method = INT_MAX", S_INIT, c_conv_max, DMI_EINVAL, "method"},
    {"C44", "dmi_set_convolution", "method = INT_MIN", S_INIT, c_conv_min, DMI_EINVAL, "method"},
    {"C45", "dmi_init", "s = NULL", S_NULL, c_init_null, DMI_EINVAL, NULL},
    {"C46", "dmi_init", "kernel callback returns 7 at s = 0", S_FRESH, c_init_kfail, DMI_ECALLBACK, "kernel"},
    {"C47", "dmi_init", "kernel callback returns 7 at the last sample s = (N-1)h", S_FRESH, c_init_kfail_last, DMI_ECALLBACK, "0.75"},
    {"C48", "dmi_init", "kernel H(0)[1][0] = NaN", S_FRESH, c_init_knan, DMI_ENONFINITE, "kernel"},
    {"C49", "dmi_init", "kernel H(h)[1][1] = +Inf", S_FRESH, c_init_kpinf, DMI_ENONFINITE, "kernel"},
    {"C50", "dmi_init", "kernel H(2h)[0][0] = -Inf, re-init of a solver at p = 2", S_INIT, c_init_kninf, DMI_ENONFINITE, "kernel"},
    {"C51", "dmi_init", "history callback returns 7 at t = 0", S_FRESH, c_init_hfail, DMI_ECALLBACK, "history"},
    {"C52", "dmi_init", "history callback returns 7 at t = -tau", S_FRESH, c_init_hfail_last, DMI_ECALLBACK, "t = -1"},
    {"C53", "dmi_init", "history z(0)[0] = NaN", S_FRESH, c_init_hnan, DMI_ENONFINITE, "history"},
    {"C54", "dmi_init", "history z(-2h)[1] = +Inf, re-init of a solver at p = 2", S_INIT, c_init_hpinf, DMI_ENONFINITE, "history"},
    {"C55", "dmi_init", "history z(-3h)[1] = -Inf", S_FRESH, c_init_hninf, DMI_ENONFINITE, "history"},
    {"C56", "dmi_step", "s = NULL", S_NULL, c_step_null, DMI_EINVAL, NULL},
    {"C57", "dmi_step", "before dmi_init", S_FRESH, c_step_early, DMI_ESTATE, "dmi_init"},
    {"C58", "dmi_step", "rhs callback returns 7", S_INIT, c_step_ffail, DMI_ECALLBACK, "rhs"},
    {"C59", "dmi_step", "rhs f[1] = NaN", S_INIT, c_step_fnan, DMI_ENONFINITE, "f("},
    {"C60", "dmi_step", "rhs f[0] = +Inf", S_INIT0, c_step_fpinf, DMI_ENONFINITE, "f("},
    {"C61", "dmi_step", "rhs f[1] = -Inf", S_INIT, c_step_fninf, DMI_ENONFINITE, "f("},
    {"C62", "dmi_step", "resolvent callback returns 7", S_INIT, c_step_rfail, DMI_ECALLBACK, "resolvent"},
    {"C63", "dmi_step", "resolvent out[0] = NaN", S_INIT, c_step_rnan, DMI_ENONFINITE, "new state"},
    {"C64", "dmi_step", "resolvent out[1] = +Inf", S_INIT0, c_step_rpinf, DMI_ENONFINITE, "new state"},
    {"C65", "dmi_step", "resolvent out[1] = -Inf", S_INIT, c_step_rninf, DMI_ENONFINITE, "new state"},
    {"C66", "dmi_advance", "s = NULL", S_NULL, c_adv_null, DMI_EINVAL, NULL},
    {"C67", "dmi_advance", "before dmi_init", S_FRESH, c_adv_early, DMI_ESTATE, "dmi_init"},
    {"C68", "dmi_advance", "rhs callback returns 7 in the first of 5 steps", S_INIT, c_adv_ffail, DMI_ECALLBACK, "rhs"},
    {"C69", "dmi_get_step_index", "s = NULL", S_NULL, c_idx_null_s, DMI_EINVAL, NULL},
    {"C70", "dmi_get_step_index", "p = NULL", S_INIT, c_idx_null, DMI_EINVAL, "NULL"},
    {"C71", "dmi_get_step_index", "before dmi_init", S_FRESH, c_idx_early, DMI_ESTATE, "dmi_init"},
    {"C72", "dmi_get_state", "s = NULL", S_NULL, c_state_null_s, DMI_EINVAL, NULL},
    {"C73", "dmi_get_state", "u = NULL", S_INIT, c_state_null, DMI_EINVAL, "NULL"},
    {"C74", "dmi_get_state", "before dmi_init", S_FRESH, c_state_early, DMI_ESTATE, "dmi_init"},
    {"C75", "dmi_get_past", "s = NULL", S_NULL, c_past_null_s, DMI_EINVAL, NULL},
    {"C76", "dmi_get_past", "u = NULL", S_INIT, c_past_null, DMI_EINVAL, "NULL"},
    {"C77", "dmi_get_past", "before dmi_init", S_FRESH, c_past_early, DMI_ESTATE, "dmi_init"},
    {"C78", "dmi_get_past", "lag = N + 1", S_INIT, c_past_lag, DMI_EINVAL, "lag 5"},
    {"C79", "dmi_get_past", "lag = SIZE_MAX", S_INIT, c_past_lagmax, DMI_EINVAL, "lag"},
    {"C80", "dmi_get_step_terms", "s = NULL", S_NULL, c_terms_null_s, DMI_EINVAL, NULL},
    {"C81", "dmi_get_step_terms", "before dmi_init", S_FRESH, c_terms_early, DMI_ESTATE, "no step"},
    {"C82", "dmi_get_step_terms", "after dmi_init, before the first step", S_INIT0, c_terms_nostep, DMI_ESTATE, "no step"},
    {"C83", "dmi_state_save", "s = NULL", S_NULL, c_save_null_s, DMI_EINVAL, NULL},
    {"C84", "dmi_state_save", "buf = NULL", S_INIT, c_save_null, DMI_EINVAL, "NULL"},
    {"C85", "dmi_state_save", "before dmi_init", S_FRESH, c_save_early, DMI_ESTATE, "dmi_init"},
    {"C86", "dmi_state_save", "size = dmi_state_size(s) - 1", S_INIT, c_save_short, DMI_EINVAL, "needed"},
    {"C87", "dmi_state_save", "size = 0", S_INIT, c_save_zero, DMI_EINVAL, "needed"},
    {"C88", "dmi_state_load", "s = NULL", S_NULL, c_load_null_s, DMI_EINVAL, NULL},
    {"C89", "dmi_state_load", "buf = NULL", S_INIT, c_load_null, DMI_EINVAL, "NULL"},
    {"C90", "dmi_state_load", "valid bytes, before dmi_init", S_FRESH, c_load_early, DMI_ESTATE, "dmi_init"},
    {"C91", "dmi_state_load", "truncated by one byte", S_INIT, c_load_short, DMI_EINVAL, "bytes"},
    {"C92", "dmi_state_load", "one byte too many", S_INIT, c_load_long, DMI_EINVAL, "bytes"},
    {"C93", "dmi_state_load", "size = 0", S_INIT, c_load_empty, DMI_EINVAL, "bytes"},
    {"C94", "dmi_state_load", "magic altered", S_INIT, c_load_magic, DMI_EINVAL, "magic"},
    {"C95", "dmi_state_load", "a state of libdmi 1.0 (format version 1) with 24 bytes more (a version-2 size)", S_INIT, c_load_version, DMI_EINVAL, "in format version 1"},
    {"C96", "dmi_state_load", "foreign: saved with n = 1, N = 11 (same byte count)", S_INIT, c_load_foreign_nN, DMI_EINVAL, "n = 1"},
    {"C97", "dmi_state_load", "foreign: saved with tau = 2 (same n, N)", S_INIT0, c_load_foreign_tau, DMI_EINVAL, "tau = 2"},
    {"C98", "dmi_state_load", "header says n = 3 (checksum valid)", S_INIT, c_load_foreign_n_hdr, DMI_EINVAL, "n = 3"},
    {"C99", "dmi_state_load", "checksum byte altered", S_INIT, c_load_checksum, DMI_EINVAL, "checksum"},
    {"C100", "dmi_state_load", "a data byte altered", S_INIT, c_load_data, DMI_EINVAL, "checksum"},
    {"C101", "dmi_state_load", "last-step flag = 2 (checksum valid)", S_INIT, c_load_have_last, DMI_EINVAL, "corrupted"},
    {"C114", "dmi_state_load", "last-step flag = 0 at p > 0 (checksum valid)", S_INIT, c_load_flag0, DMI_EINVAL, "corrupted"},
    {"C102", "dmi_state_load", "step counter 1e19 (checksum not fixed)", S_INIT, c_load_step_huge, DMI_EINVAL, "checksum"},
    {"C103", "dmi_state_load", "U^p[0] = NaN (checksum valid)", S_INIT, c_load_nan, DMI_EINVAL, "non-finite"},
    {"C104", "dmi_state_load", "last W[0] = -Inf (checksum valid)", S_INIT, c_load_inf, DMI_EINVAL, "non-finite"},
};
/* clang-format on */
#define NCASES (sizeof cases / sizeof cases[0])

/* Steps s (which must be in a good state) to p = REF_STEPS and compares its
 * state bytes with the reference. */
static int continues_like_reference(dmi_solver *s, const unsigned char *ref, size_t ref_size)
{
    uint64_t p = 0;
    if (dmi_get_step_index(s, &p) == DMI_ESTATE && dmi_init(s) != DMI_OK)
        return 0;
    if (dmi_get_step_index(s, &p) != DMI_OK || p > REF_STEPS || dmi_advance(s, REF_STEPS - p) != DMI_OK)
        return 0;
    size_t size = dmi_state_size(s);
    unsigned char *b = malloc(size);
    int same = b && size == ref_size && dmi_state_save(s, b, size) == DMI_OK &&
               memcmp(b, ref, size) == 0;
    free(b);
    return same;
}

static void test_table(void)
{
    size_t ref_size = 0;
    unsigned char *ref = reference_state(&ref_size);
    CU_ASSERT_PTR_NOT_NULL_FATAL(ref);
    for (size_t i = 0; i < NCASES; i++) {
        const bad_case *c = &cases[i];
        model m;
        model_default(&m);
        dmi_solver *s = NULL;
        int rc = build(c->setup, &m, &s);
        CHECK(rc == DMI_OK, "%s: setup failed (%d)", c->id, rc);
        if (rc != DMI_OK)
            continue;
        snapshot before, after;
        snap_take(s, &before);
        hard_quiet q;
        int quiet = hard_quiet_begin(&q);
        rc = c->call(s, &m);
        long printed = hard_quiet_end(&q);
        model_calm(&m);
        CHECK(quiet == 0 && printed == 0, "%s: the library printed %ld bytes", c->id, printed);
        CHECK(rc == c->expect, "%s %s(%s): returned %d, expected %d", c->id, c->fn, c->input, rc,
              c->expect);
        const char *msg = s ? dmi_last_error(s) : dmi_strerror(rc);
        CHECK(msg != NULL && msg[0] != '\0', "%s: empty message", c->id);
        if (c->msg)
            CHECK(msg && strstr(msg, c->msg) != NULL, "%s: message \"%s\" lacks \"%s\"", c->id,
                  msg ? msg : "(null)", c->msg);
        row(c->id, c->fn, c->input, rc, msg ? msg : "");
        if (s) {
            snap_take(s, &after);
            CHECK(snap_equal(&before, &after), "%s: solver changed by a failed call", c->id);
            CHECK(continues_like_reference(s, ref, ref_size),
                  "%s: the solver does not continue bitwise like one that never failed", c->id);
            snap_free(&after);
        }
        snap_free(&before);
        dmi_free(&s);
    }
    free(ref);
}

/* ---- cases that need their own setup ---------------------------------------- */

/* The checks of a creation fn(input) that returned rc, *out = s (sentinel
 * before the call; out NULL if null_out), having printed printed bytes (quiet:
 * hard_quiet_begin's code): nothing printed, the expected code, *out NULL
 * after a failure (untouched for out = NULL); the table's row. */
static void created(const char *id, const char *fn, const char *input, int rc, int expect,
                    int null_out, dmi_solver *s, const dmi_solver *sentinel, int quiet,
                    long printed)
{
    CHECK(quiet == 0 && printed == 0, "%s: printed %ld bytes", id, printed);
    CHECK(rc == expect, "%s %s(%s): %d, expected %d", id, fn, input, rc, expect);
    CHECK(null_out ? s == sentinel : s == NULL, "%s: *out not NULL after failure", id);
    row(id, fn, input, rc, dmi_strerror(rc));
    if (rc == DMI_OK && s != sentinel)
        dmi_free(&s);
}

/* dmi_create (N) or, if by_h, dmi_create_h (h) of case id, its output a
 * sentinel (the address of the case's row, never dereferenced) or NULL if
 * null_out, with the library's messages quietened; the outcome checked by
 * created. */
static void create_case(const void *case_row, const char *id, const char *input, int null_out,
                        size_t n, double tau, int by_h, size_t N, double h, int expect)
{
    dmi_solver *sentinel = (dmi_solver *)case_row;
    dmi_solver *s = sentinel;
    hard_quiet q;
    int quiet = hard_quiet_begin(&q);
    int rc = by_h ? dmi_create_h(null_out ? NULL : &s, n, tau, h)
                  : dmi_create(null_out ? NULL : &s, n, tau, N);
    created(id, by_h ? "dmi_create_h" : "dmi_create", input, rc, expect, null_out, s, sentinel,
            quiet, hard_quiet_end(&q));
}

static void test_create(void)
{
    static const struct {
        const char *id, *input;
        int null_out;
        size_t n;
        double tau;
        size_t N;
        int expect;
    } t[] = {
        {"C01", "out = NULL", 1, 2, 1.0, 4, DMI_EINVAL},
        {"C02", "n = 0", 0, 0, 1.0, 4, DMI_EINVAL},
        {"C03", "N = 0", 0, 2, 1.0, 0, DMI_EINVAL},
        {"C04", "tau = 0", 0, 2, 0.0, 4, DMI_EINVAL},
        {"C05", "tau = -0.0", 0, 2, -0.0, 4, DMI_EINVAL},
        {"C06", "tau = -1", 0, 2, -1.0, 4, DMI_EINVAL},
        {"C07", "tau = NaN", 0, 2, NAN, 4, DMI_EINVAL},
        {"C08", "tau = +Inf", 0, 2, INFINITY, 4, DMI_EINVAL},
        {"C09", "tau = -Inf", 0, 2, -INFINITY, 4, DMI_EINVAL},
        {"C10", "tau = 1e-300, N = 1e10: h = 1e-310 subnormal", 0, 2, 1e-300, 10000000000u,
         DMI_EINVAL},
        {"C11", "N = SIZE_MAX (size overflows)", 0, 2, 1.0, SIZE_MAX, DMI_ENOMEM},
        {"C12", "N = SIZE_MAX / 4 (size overflows)", 0, 1, 1.0, SIZE_MAX / 4, DMI_ENOMEM},
        {"C13", "N = 2^44: history of 256 TiB cannot be allocated", 0, 1, 1.0, (size_t)1 << 44,
         DMI_ENOMEM},
        {"C14", "n = SIZE_MAX (size overflows)", 0, SIZE_MAX, 1.0, 4, DMI_ENOMEM},
        {"C15", "n = 2^44, N = 1: history of 1 PiB cannot be allocated", 0, (size_t)1 << 44, 1.0,
         1, DMI_ENOMEM},
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        create_case(&t[i], t[i].id, t[i].input, t[i].null_out, t[i].n, t[i].tau, 0, t[i].N, 0.0,
                    t[i].expect);
}

/* dmi_create_h (libdmi 1.2): the same checks as dmi_create, on h. */
static void test_create_h(void)
{
    static const struct {
        const char *id, *input;
        int null_out;
        size_t n;
        double tau, h;
        int expect;
    } t[] = {
        {"C134", "out = NULL", 1, 2, 1.0, 0.3, DMI_EINVAL},
        {"C135", "n = 0", 0, 0, 1.0, 0.3, DMI_EINVAL},
        {"C136", "h = 0", 0, 2, 1.0, 0.0, DMI_EINVAL},
        {"C137", "h = -0.0", 0, 2, 1.0, -0.0, DMI_EINVAL},
        {"C138", "h = -0.3", 0, 2, 1.0, -0.3, DMI_EINVAL},
        {"C139", "h = NaN", 0, 2, 1.0, NAN, DMI_EINVAL},
        {"C140", "h = +Inf", 0, 2, 1.0, INFINITY, DMI_EINVAL},
        {"C141", "h = 1e-310 (subnormal)", 0, 2, 1.0, 1e-310, DMI_EINVAL},
        {"C142", "tau = NaN", 0, 2, NAN, 0.3, DMI_EINVAL},
        {"C143", "tau = 0", 0, 2, 0.0, 0.3, DMI_EINVAL},
        {"C144", "tau / h = 1e300 cells", 0, 2, 1.0, 1e-300, DMI_ENOMEM},
        {"C145", "tau / h = 2^50 cells", 0, 1, 1.0, 0x1p-50, DMI_ENOMEM},
        {"C146", "n = SIZE_MAX (size overflows)", 0, SIZE_MAX, 1.0, 0.3, DMI_ENOMEM},
        {"C147", "n = 2^44, h > tau (N = 1): history of 1 PiB cannot be allocated", 0,
         (size_t)1 << 44, 1.0, 3.0, DMI_ENOMEM},
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        create_case(&t[i], t[i].id, t[i].input, t[i].null_out, t[i].n, t[i].tau, 1, 0, t[i].h,
                    t[i].expect);
    /* a state loads only into a solver with the same h (N = 41 for all three) */
    dmi_solver *a = NULL, *b = NULL, *c = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create_h(&a, 2, 1.0, 1.0 / 40.37), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(dmi_create_h(&b, 2, 1.0, 1.0 / 40.5), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(dmi_create(&c, 2, 1.0, 41), DMI_OK);
    CU_ASSERT(dmi_init(a) == DMI_OK && dmi_init(b) == DMI_OK && dmi_init(c) == DMI_OK);
    static const struct {
        const char *id, *input;
        int to_b;
        const char *msg;
    } L[] = {
        {"C148", "the state of dmi_create_h(2, 1, 1/40.37) into dmi_create_h(2, 1, 1/40.5) (both N = 41)",
         1, "h = 0.024770869457517962"},
        {"C149", "the state of dmi_create(2, 1, 41) into dmi_create_h(2, 1, 1/40.5) (N = 41)", 0,
         "state of a solver with h = tau / N"},
    };
    for (size_t i = 0; i < sizeof L / sizeof L[0]; i++) {
        const dmi_solver *from = L[i].to_b ? a : c;
        size_t size = dmi_state_size(from), bsize = dmi_state_size(b);
        unsigned char *bytes = malloc(size), *before = malloc(bsize), *after = malloc(bsize);
        CU_ASSERT_FATAL(bytes && before && after);
        CU_ASSERT(dmi_state_save(from, bytes, size) == DMI_OK);
        CU_ASSERT(dmi_state_save(b, before, bsize) == DMI_OK);
        int rc = dmi_state_load(b, bytes, size);
        CHECK(rc == DMI_EINVAL, "%s dmi_state_load: %d, expected %d", L[i].id, rc, DMI_EINVAL);
        CHECK(strstr(dmi_last_error(b), L[i].msg) != NULL, "%s: message \"%s\"", L[i].id,
              dmi_last_error(b));
        CHECK(dmi_state_save(b, after, bsize) == DMI_OK && memcmp(before, after, bsize) == 0,
              "%s: the solver changed", L[i].id);
        row(L[i].id, "dmi_state_load", L[i].input, rc, dmi_last_error(b));
        free(bytes);
        free(before);
        free(after);
    }
    dmi_free(&a);
    dmi_free(&b);
    dmi_free(&c);
}

/* N * n^2 kernel samples too many to allocate (2^48 bytes), while the history
 * ((N + 1) n doubles, twice) is allocatable: dmi_init fails with DMI_ENOMEM and
 * the solver stays uninitialised and usable. */
static void test_init_kernel_too_large(void)
{
    const size_t n = (size_t)1 << 22, N = 2;
    dmi_solver *s = NULL;
    int rc = dmi_create(&s, n, 1.0, N);
    CU_ASSERT_EQUAL_FATAL(rc, DMI_OK);
    model m;
    model_default(&m);
    CU_ASSERT_EQUAL(dmi_set_kernel(s, model_kernel, &m), DMI_OK);
    rc = dmi_init(s);
    CHECK(rc == DMI_ENOMEM, "C16 dmi_init with N n^2 = 2^45 kernel samples: %d, expected %d", rc,
          DMI_ENOMEM);
    CHECK(m.kernel.calls == 0, "C16: the kernel was called %zu times", m.kernel.calls);
    CHECK(strstr(dmi_last_error(s), "kernel") != NULL, "C16: message \"%s\"", dmi_last_error(s));
    row("C16", "dmi_init", "n = 2^22, N = 2 with a kernel: 2^45 samples cannot be allocated", rc,
        dmi_last_error(s));
    uint64_t p;
    CHECK(dmi_get_step_index(s, &p) == DMI_ESTATE, "C16: solver initialised after a failed init");
    CHECK(dmi_step(s) == DMI_ESTATE, "C16: step after failed init not refused");
    dmi_free(&s);
}

/* DMI_CONV_RECURSIVE refuses an exponential kernel with a growing term or
 * with |b| h > pi, by dmi_set_convolution (the method stays AUTO, which
 * picks another method) and by dmi_init (when the kernel came after the
 * method); the solver is then still uninitialised. */
static void test_recursive_refusals(void)
{
    static const struct {
        const char *id, *fn, *input;
        double a0, b0;
        int init;
        const char *msg;
    } t[] = {
        {"C130", "dmi_set_convolution", "DMI_CONV_RECURSIVE, growing term a[0] = 0.5", 0.5, 2, 0,
         "a[0] = 0.5 > 0"},
        {"C131", "dmi_init", "DMI_CONV_RECURSIVE chosen before a kernel with a growing term", 0.5,
         2, 1, "a[0] = 0.5 > 0"},
        {"C132", "dmi_set_convolution", "DMI_CONV_RECURSIVE, b[0] = 13 with h = 0.25: b h = 3.25 > pi",
         0, 13, 0, "b h = 3.25 is beyond [-pi, pi]"},
        {"C133", "dmi_init", "DMI_CONV_RECURSIVE chosen before a kernel with b h = -3.25 < -pi", 0,
         -13, 1, "b h = -3.25 is beyond [-pi, pi]"},
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        model m;
        model_default(&m);
        dmi_solver *s = NULL;
        CU_ASSERT_EQUAL_FATAL(model_solver(&s, &m), DMI_OK);
        const double a[2] = {t[i].a0, -1}, b[2] = {t[i].b0, 0};
        int rc = DMI_OK;
        if (t[i].init)
            rc = dmi_set_kernel(s, NULL, NULL) == DMI_OK && /* no kernel: RECURSIVE taken */
                         dmi_set_convolution(s, DMI_CONV_RECURSIVE) == DMI_OK &&
                         dmi_set_kernel_exp(s, 2, a, b, xC, xD) == DMI_OK
                     ? dmi_init(s)
                     : -100;
        else
            rc = dmi_set_kernel_exp(s, 2, a, b, xC, xD) == DMI_OK
                     ? dmi_set_convolution(s, DMI_CONV_RECURSIVE)
                     : -100;
        CHECK(rc == DMI_EINVAL, "%s %s(%s): %d, expected DMI_EINVAL", t[i].id, t[i].fn,
              t[i].input, rc);
        CHECK(strstr(dmi_last_error(s), t[i].msg) != NULL, "%s: message \"%s\" lacks \"%s\"",
              t[i].id, dmi_last_error(s), t[i].msg);
        row(t[i].id, t[i].fn, t[i].input, rc, dmi_last_error(s));
        uint64_t p;
        CHECK(dmi_get_step_index(s, &p) == DMI_ESTATE, "%s: solver initialised", t[i].id);
        /* the same kernel under AUTO (the default, kept by the refused call):
         * accepted, another method than the recursion */
        if (t[i].init)
            CU_ASSERT_EQUAL(dmi_set_convolution(s, DMI_CONV_AUTO), DMI_OK);
        CHECK(dmi_init(s) == DMI_OK && dmi_step(s) == DMI_OK, "%s: AUTO refused the kernel: %s",
              t[i].id, dmi_last_error(s));
        dmi_free(&s);
    }
}

/* W^p overflows although every callback output is finite. */
static void test_delay_term_overflow(void)
{
    model m;
    model_default(&m);
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(model_solver(&s, &m), DMI_OK);
    m.kernel.mode = CB_HUGE; /* H(s) = DBL_MAX in every entry: finite */
    CU_ASSERT_EQUAL_FATAL(dmi_init(s), DMI_OK);
    snapshot before, after;
    snap_take(s, &before);
    int rc = dmi_step(s);
    CHECK(rc == DMI_ENONFINITE, "C17 dmi_step with W overflowing: %d", rc);
    CHECK(strstr(dmi_last_error(s), "delay term") != NULL, "C17: message \"%s\"",
          dmi_last_error(s));
    row("C17", "dmi_step", "kernel entries DBL_MAX: W^p overflows to Inf", rc, dmi_last_error(s));
    snap_take(s, &after);
    CHECK(snap_equal(&before, &after), "C17: solver changed");
    snap_free(&before);
    snap_free(&after);
    dmi_free(&s);
}

/* X^p = U^p - h f - h W overflows with finite f and W; the box resolvent would
 * map Inf to a finite bound, so only a check before the resolvent sees it. */
static void test_resolvent_argument_overflow(void)
{
    model m;
    model_default(&m);
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(model_solver(&s, &m), DMI_OK);
    const double lo[2] = {-1, -1}, hi[2] = {1, 1};
    CU_ASSERT_EQUAL(dmi_set_box(s, lo, hi), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel(s, NULL, NULL), DMI_OK);
    m.history.mode = CB_HUGE; /* U^0 = (DBL_MAX, DBL_MAX) */
    CU_ASSERT_EQUAL_FATAL(dmi_init(s), DMI_OK);
    m.rhs.mode = CB_NEGHUGE; /* f = -DBL_MAX: X = DBL_MAX + h DBL_MAX = Inf */
    snapshot before, after;
    snap_take(s, &before);
    int rc = dmi_step(s);
    CHECK(rc == DMI_ENONFINITE, "C18 dmi_step with X overflowing before a box resolvent: %d", rc);
    CHECK(strstr(dmi_last_error(s), "resolvent argument") != NULL, "C18: message \"%s\"",
          dmi_last_error(s));
    row("C18", "dmi_step", "finite f = -DBL_MAX, U = DBL_MAX: X^p overflows (box resolvent)", rc,
        dmi_last_error(s));
    snap_take(s, &after);
    CHECK(snap_equal(&before, &after), "C18: solver changed");
    snap_free(&before);
    snap_free(&after);
    dmi_free(&s);
}

/* dmi_advance keeps the steps before a failure; the retry continues like a
 * run that never failed. */
static void test_advance_partial(void)
{
    size_t ref_size = 0;
    unsigned char *ref = reference_state(&ref_size);
    CU_ASSERT_PTR_NOT_NULL_FATAL(ref);
    model m;
    model_default(&m);
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(build(S_INIT0, &m, &s), DMI_OK);
    m.rhs.mode = CB_FAIL;
    m.rhs.from = m.rhs.calls + 2; /* the third step fails */
    int rc = dmi_advance(s, 5);
    uint64_t p = 99;
    CU_ASSERT_EQUAL(dmi_get_step_index(s, &p), DMI_OK);
    CHECK(rc == DMI_ECALLBACK && p == 2, "C19 dmi_advance(5), third step fails: rc %d, p %llu",
          rc, (unsigned long long)p);
    row("C19", "dmi_advance", "rhs fails in the 3rd of 5 steps: the 2 steps before are kept", rc,
        dmi_last_error(s));
    model_calm(&m);
    CHECK(continues_like_reference(s, ref, ref_size), "C19: retry differs from the reference");
    dmi_free(&s);
    free(ref);
}

/* Functions without an error code: NULL and uninitialised solvers. */
static void test_queries_without_code(void)
{
    model m;
    model_default(&m);
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(model_solver(&s, &m), DMI_OK);
    CHECK(dmi_time(NULL) == 0.0, "C105 dmi_time(NULL) = %g", dmi_time(NULL));
    CHECK(dmi_time(s) == 0.0, "C106 dmi_time before init = %g", dmi_time(s));
    CHECK(dmi_get_h(NULL) == 0.0, "C107 dmi_get_h(NULL) = %g", dmi_get_h(NULL));
    CHECK(dmi_state_size(NULL) == 0, "C108 dmi_state_size(NULL) = %zu", dmi_state_size(NULL));
    const char *e = dmi_last_error(NULL);
    CHECK(e != NULL && e[0] != '\0', "C109 dmi_last_error(NULL) empty");
    row("C105", "dmi_time", "s = NULL", 0, "returns 0");
    row("C106", "dmi_time", "before dmi_init", 0, "returns 0");
    row("C107", "dmi_get_h", "s = NULL", 0, "returns 0");
    row("C108", "dmi_state_size", "s = NULL", 0, "returns 0");
    row("C109", "dmi_last_error", "s = NULL", 0, e ? e : "");
    static const int unknown[] = {1, -6, 42, INT_MIN, INT_MAX};
    for (size_t i = 0; i < sizeof unknown / sizeof unknown[0]; i++)
        CHECK(strcmp(dmi_strerror(unknown[i]), "unknown error code") == 0,
              "C110 dmi_strerror(%d) = \"%s\"", unknown[i], dmi_strerror(unknown[i]));
    row("C110", "dmi_strerror", "code = 1, -6, 42, INT_MIN, INT_MAX", 0, dmi_strerror(1));
    static const int known[] = {DMI_OK, DMI_EINVAL, DMI_ENOMEM, DMI_ECALLBACK, DMI_ENONFINITE,
                                DMI_ESTATE};
    for (size_t i = 0; i < 6; i++)
        for (size_t j = 0; j < 6; j++)
            CHECK((i == j) == (strcmp(dmi_strerror(known[i]), dmi_strerror(known[j])) == 0),
                  "dmi_strerror(%d) and (%d) not distinct", known[i], known[j]);
    /* dmi_free: NULL, pointer to NULL, and twice on the same handle. */
    dmi_free(NULL);
    dmi_solver *none = NULL;
    dmi_free(&none);
    dmi_free(&s);
    CHECK(s == NULL, "C111 dmi_free does not set *s = NULL");
    dmi_free(&s);
    row("C111", "dmi_free", "s = NULL; *s = NULL; the same handle twice", 0,
        "nothing (sets *s = NULL)");
}

/* Every single-byte corruption and every truncation of a state buffer. */
static void test_every_corruption(void)
{
    model m;
    model_default(&m);
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(build(S_INIT, &m, &s), DMI_OK);
    size_t size = 0;
    unsigned char *good = saved_state(MODEL_n, MODEL_TAU, MODEL_N, &size);
    CU_ASSERT_PTR_NOT_NULL_FATAL(good);
    CU_ASSERT_EQUAL_FATAL(size, dmi_state_size(s));
    unsigned char *b = malloc(size);
    CU_ASSERT_PTR_NOT_NULL_FATAL(b);
    snapshot before, after;
    snap_take(s, &before);
    size_t accepted = 0, changed = 0;
    for (size_t i = 0; i < size; i++)
        for (int bit = 0; bit < 8; bit++) {
            memcpy(b, good, size);
            b[i] ^= (unsigned char)(1u << bit);
            if (dmi_state_load(s, b, size) != DMI_EINVAL)
                accepted++;
        }
    for (size_t len = 0; len < size; len++)
        if (dmi_state_load(s, good, len) != DMI_EINVAL)
            accepted++;
    snap_take(s, &after);
    changed = !snap_equal(&before, &after);
    CHECK(accepted == 0 && !changed,
          "C112/C113: %zu corrupted or truncated states not rejected, solver changed: %zu",
          accepted, changed);
    row("C112", "dmi_state_load", "each of the 8 x size single-bit flips", DMI_EINVAL,
        "(as C94-C101)");
    row("C113", "dmi_state_load", "each truncation to 0 .. size-1 bytes", DMI_EINVAL,
        "(as C91)");
    /* The intact buffer is accepted: the rejections above are not blanket. */
    CHECK(dmi_state_load(s, good, size) == DMI_OK, "intact state rejected: %s", dmi_last_error(s));
    snap_free(&before);
    snap_free(&after);
    free(b);
    free(good);
    dmi_free(&s);
}

int main(int argc, char **argv)
{
    print_table = argc > 1 && strcmp(argv[1], "--table") == 0;
    if (CU_initialize_registry() != CUE_SUCCESS)
        return 2;
    CU_pSuite suite = CU_add_suite("capi_bad_inputs", NULL, NULL);
    if (!suite || !CU_add_test(suite, "dmi_create", test_create) ||
        !CU_add_test(suite, "dmi_create_h", test_create_h) ||
        !CU_add_test(suite, "init: kernel too large", test_init_kernel_too_large) ||
        !CU_add_test(suite, "step: delay term overflow", test_delay_term_overflow) ||
        !CU_add_test(suite, "step: resolvent argument overflow", test_resolvent_argument_overflow) ||
        !CU_add_test(suite, "advance: partial", test_advance_partial) ||
        !CU_add_test(suite, "table of bad calls", test_table) ||
        !CU_add_test(suite, "recursion refusals", test_recursive_refusals) ||
        !CU_add_test(suite, "queries without code", test_queries_without_code) ||
        !CU_add_test(suite, "every corruption", test_every_corruption)) {
        CU_cleanup_registry();
        return 2;
    }
    return hard_run_tests(print_table);
}
