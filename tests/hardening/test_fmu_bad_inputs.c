/*
 * Every bad input of the FMU DelayFrictionOscillator, one row of
 * docs/bad-inputs.md per case, through the unpacked binary (dlopen): each
 * gives fmi2Error (or NULL from fmi2Instantiate), a logged reason (status
 * fmi2Error, category logStatusError, logging off), nothing printed, the
 * instance unchanged (its serialized state bitwise) and still usable.
 * Given the FMI 3.0 binary, the same rows run through its FMI 3.0 functions
 * (tests/fmu/fmu_fmi3.c) and are printed as G rows with the FMI 3.0 names;
 * the rows of FMI 2.0 functions without a counterpart are left out.
 *
 * Usage: test_fmu_bad_inputs <unpacked .so> <GUID> [--table]
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#define _POSIX_C_SOURCE 200809L
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include <CUnit/CUnit.h>

#include "bytes.h" /* libdmi's state layout and value accessors (src/) */
#include "dmi.h"
#include "fmu_host.h"
#include "hard_util.h"

const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}

static fmu_api F;
static const char *GUID;
static int print_table;

#define N_TEST 100 /* h = 0.01 */
#define H_TEST 0.01

/* The FMI 3.0 spelling of an FMI 2.0 function name or input text (into buf). */
static const char *fmi3_words(const char *text, char *buf, size_t size)
{
    static const char *const WORDS[][2] = {
        {"fmi2SetupExperiment", "fmi3EnterInitializationMode"},
        {"fmi2Instantiate", "fmi3InstantiateCoSimulation"},
        {"fmuType = fmi2ModelExchange", "a model-exchange instance"},
        {"DeSerialize", "Deserialize"}, {"FMUstate", "FMUState"}, {"Real", "Float64"},
        {"Integer", "Int32"}, {"fmi2", "fmi3"}};
    size_t n = 0;
    buf[0] = '\0';
    while (*text && n + 1 < size) {
        size_t k = 0;
        while (k < sizeof WORDS / sizeof WORDS[0] &&
               strncmp(text, WORDS[k][0], strlen(WORDS[k][0])) != 0)
            k++;
        const char *out = k < sizeof WORDS / sizeof WORDS[0] ? WORDS[k][1] : NULL;
        if (out) {
            n += (size_t)snprintf(buf + n, size - n, "%s", out);
            text += strlen(WORDS[k][0]);
        } else {
            buf[n++] = *text++;
            buf[n] = '\0';
        }
        if (n >= size)
            n = size - 1;
    }
    return buf;
}

static void row(const char *id, const char *fn, const char *input, const char *result,
                const char *msg)
{
    if (!print_table)
        return;
    if (F.version == 2) {
        printf("| %s | `%s` | %s | %s | %s |\n", id, fn, input, result, msg);
        return;
    }
    char fn3[128], input3[256], result3[64];
    if (strstr(input, "fmi2ModelExchange")) /* F05: the function of that interface type */
        fn = "fmi3InstantiateModelExchange";
    printf("| G%s | `%s` | %s | %s | %s |\n", id + 1, fmi3_words(fn, fn3, sizeof fn3),
           fmi3_words(input, input3, sizeof input3), fmi3_words(result, result3, sizeof result3),
           msg);
}

/* ---- setups ------------------------------------------------------------------- */

enum { F_NULL, F_INST, F_INIT, F_STEP, F_TERM, F_ERROR };
static const char *const SETUP_NAME[] = {"no instance", "instantiated", "initialization mode",
                                         "step complete (t = 0.05)", "terminated", "error"};

typedef struct {
    fmi2Component c;
    fmu_log log;
    fmi2CallbackFunctions *cb; /* alive as long as the instance */
    double t;                  /* the communication point */
} ctx;

static int build(ctx *x, int setup)
{
    memset(x, 0, sizeof *x);
    const fmi2CallbackFunctions cb = fmu_callbacks(&x->log);
    if (!(x->cb = malloc(sizeof cb)))
        return -1;
    memcpy(x->cb, &cb, sizeof cb);
    if (setup == F_NULL)
        return 0;
    x->c = fmu_new(&F, GUID, x->cb);
    if (!x->c)
        return -1;
    const fmi2ValueReference vrN = VR_N, vrg[2] = {VR_g_offset, VR_g_amp};
    const fmi2Integer N = N_TEST;
    const fmi2Real huge[2] = {1e308, 1e308};
    int ok = 1;
    if (setup >= F_INIT)
        ok = F.setup(x->c, fmi2False, 0, 0.0, fmi2False, 0) == fmi2OK &&
             F.enter_init(x->c) == fmi2OK && F.set_integer(x->c, &vrN, 1, &N) == fmi2OK;
    if (ok && setup == F_ERROR) /* g = 1e308 + 1e308 cos(8t) overflows */
        ok = F.set_real(x->c, vrg, 2, huge) == fmi2OK && F.exit_init(x->c) == fmi2OK &&
             F.do_step(x->c, 0.0, H_TEST, fmi2True) == fmi2Error;
    if (ok && (setup == F_STEP || setup == F_TERM)) {
        ok = F.exit_init(x->c) == fmi2OK;
        for (int k = 0; ok && k < 5; k++, x->t += H_TEST)
            ok = F.do_step(x->c, x->t, H_TEST, fmi2True) == fmi2OK;
    }
    if (ok && setup == F_TERM)
        ok = F.terminate(x->c) == fmi2OK;
    memset(&x->log, 0, sizeof x->log);
    return ok ? 0 : -1;
}

/* The next regular call of the setup's phase: must succeed after a rejected call. */
static int usable(ctx *x, int setup)
{
    switch (setup) {
    case F_INST:
        return F.setup(x->c, fmi2False, 0, 0.0, fmi2False, 0) == fmi2OK &&
               F.enter_init(x->c) == fmi2OK;
    case F_INIT: return F.exit_init(x->c) == fmi2OK;
    case F_STEP: return F.do_step(x->c, x->t, H_TEST, fmi2True) == fmi2OK;
    case F_TERM:
    case F_ERROR: return F.reset(x->c) == fmi2OK;
    }
    return 1;
}

/* ---- state bytes (layout: fmu/model.h, libdmi's part src/bytes.h) --------------- */

#define AT_REAL(vr) (MODEL_STATE_AT_REAL + 8 * (vr))     /* t_start: MODEL_NREAL, t_comm: + 1 */
#define AT_DMI(at) (MODEL_STATE_AT_DMI + (size_t)(at)) /* offset at in libdmi's part */
enum { FIX_NONE, FIX_BOTH, FIX_OUTER };

/* Deserializes bytes into a state and sets it; the first failure's status. */
static fmi2Status restore(ctx *x, const unsigned char *b, size_t size)
{
    fmi2FMUstate st = NULL;
    fmi2Status rc = F.deserialize(x->c, (const fmi2Byte *)b, size, &st);
    if (rc == fmi2OK) {
        rc = F.set_state(x->c, st);
        F.free_state(x->c, &st);
    }
    return rc;
}

enum { E_NONE, E_XOR, E_U32, E_U64, E_F64 };
/* The instance's own state, edited (at byte offset at), resized by extra
 * bytes, with the checksums fixed if fix, then restored. */
static fmi2Status restore_edited(ctx *x, int edit, size_t at, double value, long extra, int fix)
{
    size_t size;
    unsigned char *own = fmu_snapshot(&F, x->c, &size);
    if (!own)
        return fmi2Fatal;
    size_t len = (size_t)((long)size + extra);
    unsigned char *b = calloc(len > size ? len : size, 1);
    if (!b) {
        free(own);
        return fmi2Fatal;
    }
    memcpy(b, own, size);
    free(own);
    switch (edit) {
    case E_XOR: b[at] ^= 0x24; break;
    case E_U32: dmi_put_u32(b, at, (uint32_t)value); break;
    case E_U64: dmi_put_u64(b, at, (uint64_t)value); break;
    case E_F64: dmi_put_double(b, at, value); break;
    }
    if (fix != FIX_NONE)
        fmu_state_fix_checksums(b, size, fix == FIX_BOTH);
    fmi2Status rc = restore(x, b, len);
    free(b);
    return rc;
}

/* ---- the cases ------------------------------------------------------------------- */

#define CALL(name, ...)                                                                           \
    static fmi2Status name(ctx *x)                                                                \
    {                                                                                             \
        fmi2Component c = x->c;                                                                   \
        (void)c;                                                                                  \
        __VA_ARGS__                                                                               \
    }
static fmi2Status set_r(fmi2Component c, fmi2ValueReference vr, double v)
{
    return F.set_real(c, &vr, 1, &v);
}
static fmi2Status set_i(fmi2Component c, fmi2ValueReference vr, int v)
{
    return F.set_integer(c, &vr, 1, &v);
}
static fmi2Real rbuf[4];
static fmi2Integer ibuf[4];
static fmi2Boolean bbuf[4];

CALL(p_tau0, return set_r(c, VR_tau, 0.0);)
CALL(p_tau_neg, return set_r(c, VR_tau, -1.0);)
CALL(p_tau_nan, return set_r(c, VR_tau, NAN);)
CALL(p_tau_inf, return set_r(c, VR_tau, INFINITY);)
CALL(p_alpha_neg, return set_r(c, VR_alpha, -1.0);)
CALL(p_alpha_nan, return set_r(c, VR_alpha, NAN);)
CALL(p_alpha_ninf, return set_r(c, VR_alpha, -INFINITY);)
CALL(p_b_nan, return set_r(c, VR_b, NAN);)
CALL(p_b_inf, return set_r(c, VR_b, INFINITY);)
CALL(p_w0_ninf, return set_r(c, VR_w0, -INFINITY);)
CALL(p_v0_nan, return set_r(c, VR_v0, NAN);)
CALL(p_hl_inf, return set_r(c, VR_H_lambda, INFINITY);)
CALL(p_ho_nan, return set_r(c, VR_H_omega3, NAN);)
CALL(p_gamp_nan, return set_r(c, VR_g_amp, NAN);)
CALL(p_gph_inf, return set_r(c, VR_g_phase, INFINITY);)
CALL(p_N0, return set_i(c, VR_N, 0);)
CALL(p_Nneg, return set_i(c, VR_N, -1);)
CALL(p_Nmin, return set_i(c, VR_N, INT_MIN);)
CALL(p_two, const fmi2ValueReference vr[2] = {VR_b, VR_tau}; const fmi2Real v[2] = {2.0, -1.0};
     return F.set_real(c, vr, 2, v);)
CALL(p_gin_nan, return set_r(c, VR_g_in, NAN);)
CALL(p_gin_inf, return set_r(c, VR_g_in, -INFINITY);)
CALL(p_late, return set_r(c, VR_tau, 2.0);)
CALL(p_late_N, return set_i(c, VR_N, 50);)
CALL(v_unknown, return set_r(c, 999, 1.0);)
CALL(v_output, return set_r(c, VR_w, 1.0);)
CALL(v_int_on_real, return set_i(c, VR_tau, 2);)
CALL(v_get_unknown, const fmi2ValueReference vr = 999; return F.get_real(c, &vr, 1, rbuf);)
CALL(v_get_int_wrong, const fmi2ValueReference vr = VR_w; return F.get_integer(c, &vr, 1, ibuf);)
CALL(v_get_bool_wrong, const fmi2ValueReference vr = VR_tau; return F.get_boolean(c, &vr, 1, bbuf);)
CALL(v_vr_null, const fmi2Real v = 1; return F.set_real(c, NULL, 1, &v);)
CALL(v_val_null, const fmi2ValueReference vr = VR_b; return F.set_real(c, &vr, 1, NULL);)
CALL(v_get_null, const fmi2ValueReference vr = VR_w; return F.get_real(c, &vr, 1, NULL);)
CALL(v_set_bool, const fmi2ValueReference vr = VR_sticking; const fmi2Boolean v = fmi2True;
     return F.set_boolean(c, &vr, 1, &v);)
CALL(v_set_string, const fmi2ValueReference vr = 0; const fmi2String v = "x";
     return F.set_string(c, &vr, 1, &v);)
/* FMI 3.0 takes the times in fmi3EnterInitializationMode */
CALL(x_start_nan, fmi2Status r = F.setup(c, fmi2False, 0, NAN, fmi2False, 0);
     if (r == fmi2OK && F.version == 3) r = F.enter_init(c); return r;)
CALL(x_stop_before, fmi2Status r = F.setup(c, fmi2False, 0, 1.0, fmi2True, 0.5);
     if (r == fmi2OK && F.version == 3) r = F.enter_init(c); return r;)
/* tau is set back to 1 after the failure so that only the failed call is judged */
CALL(x_h_subnormal, fmi2Status r = set_r(c, VR_tau, 1e-310);
     if (r == fmi2OK) r = F.exit_init(c); set_r(c, VR_tau, 1.0); return r;)
CALL(s_step_inst, return F.do_step(c, 0.0, H_TEST, fmi2True);)
CALL(s_exit_inst, return F.exit_init(c);)
CALL(s_enter_twice, return F.enter_init(c);)
CALL(s_setup_late, return F.setup(c, fmi2False, 0, 0.0, fmi2False, 0);)
CALL(s_term_inst, return F.terminate(c);)
CALL(s_get_inst, const fmi2ValueReference vr = VR_w; return F.get_real(c, &vr, 1, rbuf);)
CALL(s_set_term, return set_r(c, VR_g_in, 1.0);)
CALL(s_getstate_err, fmi2FMUstate st = NULL; fmi2Status r = F.get_state(c, &st);
     if (st) F.free_state(c, &st); return r;)
CALL(s_cancel, return F.cancel_step(c);)
CALL(l_unknown, const fmi2String cat[1] = {"nonsense"}; return F.set_debug_logging(c, fmi2True, 1, cat);)
CALL(l_null, return F.set_debug_logging(c, fmi2True, 1, NULL);)
CALL(q_null, return F.get_real_status(c, fmi2LastSuccessfulTime, NULL);)
CALL(q_string, const fmi2ValueReference vr = 0; fmi2String v = NULL; return F.get_string(c, &vr, 1, &v);)
CALL(d_ahead, return F.do_step(c, x->t + 0.5, H_TEST, fmi2True);)
CALL(d_behind, return F.do_step(c, x->t - H_TEST, H_TEST, fmi2True);)
CALL(d_off_tol, return F.do_step(c, x->t + 1e-5 * H_TEST, H_TEST, fmi2True);)
CALL(d_neg, return F.do_step(c, x->t, -H_TEST, fmi2True);)
CALL(d_zero, return F.do_step(c, x->t, 0.0, fmi2True);)
CALL(d_nan, return F.do_step(c, x->t, NAN, fmi2True);)
CALL(d_inf, return F.do_step(c, x->t, INFINITY, fmi2True);)
CALL(d_t_nan, return F.do_step(c, NAN, H_TEST, fmi2True);)
CALL(d_t_ninf, return F.do_step(c, -INFINITY, H_TEST, fmi2True);)
CALL(d_far, return F.do_step(c, x->t, 1e300, fmi2True);)
CALL(t_set_null, return F.set_state(c, NULL);)
CALL(t_get_null, return F.get_state(c, NULL);)
CALL(t_deser_null, fmi2FMUstate st = NULL; return F.deserialize(c, NULL, 100, &st);)
CALL(t_deser_null_out, const fmi2Byte b[8] = {0}; return F.deserialize(c, b, 8, NULL);)
CALL(t_size_null, fmi2FMUstate st = NULL; fmi2Status r = F.get_state(c, &st);
     if (r == fmi2OK) r = F.state_size(c, st, NULL); if (st) F.free_state(c, &st); return r;)
CALL(t_ser_short, fmi2FMUstate st = NULL; size_t n = 0; fmi2Byte b[16];
     fmi2Status r = F.get_state(c, &st); if (r == fmi2OK) r = F.state_size(c, st, &n);
     if (r == fmi2OK) r = F.serialize(c, st, b, sizeof b); if (st) F.free_state(c, &st); return r;)
CALL(t_short1, return restore_edited(x, E_NONE, 0, 0, -1, 0);)
CALL(t_short20, fmi2Status r = fmi2Fatal; size_t n; unsigned char *b = fmu_snapshot(&F, c, &n);
     if (b) r = restore(x, b, 20); free(b); return r;)
CALL(t_empty, fmi2Status r = fmi2Fatal; size_t n; unsigned char *b = fmu_snapshot(&F, c, &n);
     if (b) r = restore(x, b, 0); free(b); return r;)
CALL(t_long1, return restore_edited(x, E_NONE, 0, 0, 1, 0);)
CALL(t_magic, return restore_edited(x, E_XOR, 2, 0, 0, 0);) /* a byte of the magic (0-7) */
CALL(t_version, return restore_edited(x, E_U32, MODEL_STATE_AT_VERSION, 4, 0, 1);)
CALL(t_tag0, return restore_edited(x, E_U32, MODEL_STATE_AT_TAG, 0, 0, 1);)
CALL(t_tag_error, return restore_edited(x, E_U32, MODEL_STATE_AT_TAG, 16, 0, 1);)
CALL(t_tag_two, return restore_edited(x, E_U32, MODEL_STATE_AT_TAG, 6, 0, 1);)
CALL(t_total, return restore_edited(x, E_U64, MODEL_STATE_AT_TOTAL, 1e6, 0, 1);)
CALL(t_checksum, size_t n; unsigned char *b = fmu_snapshot(&F, c, &n); free(b);
     return restore_edited(x, E_XOR, n - 3, 0, 0, 0);)
CALL(t_data, return restore_edited(x, E_XOR, AT_DMI(100), 0, 0, 0);)
CALL(t_real_nan, return restore_edited(x, E_F64, AT_REAL(VR_b), NAN, 0, 1);)
CALL(t_tau_neg, return restore_edited(x, E_F64, AT_REAL(VR_tau), -1.0, 0, 1);)
CALL(t_N0, return restore_edited(x, E_U64, MODEL_STATE_AT_N, 0, 0, 1);)
CALL(t_times, return restore_edited(x, E_F64, AT_REAL(MODEL_NREAL + 1), -1.0, 0, 1);)
CALL(t_comm_far, return restore_edited(x, E_F64, AT_REAL(MODEL_NREAL + 1), 1.5e10, 0, 1);)
CALL(t_comm_init, return restore_edited(x, E_F64, AT_REAL(MODEL_NREAL + 1), 0.5, 0, 1);)
CALL(t_inner, return restore_edited(x, E_XOR, AT_DMI(DMI_STATE_HEADER + 8), 0, 0, FIX_OUTER);)
CALL(t_inner_fixed, return restore_edited(x, E_F64, AT_DMI(dmi_state_at_double(2, 0, 0)), NAN, 0, 1);)
CALL(t_inner_N, return restore_edited(x, E_U64, MODEL_STATE_AT_N, 50, 0, 1);)

/* Foreign bytes: libdmi's own state format, of the right length. */
CALL(t_foreign_dmi, size_t n; unsigned char *own = fmu_snapshot(&F, c, &n); free(own);
     dmi_solver *s = NULL; unsigned char *b = calloc(n, 1); fmi2Status r = fmi2Fatal;
     if (b && dmi_create(&s, 1, 1.0, 1) == DMI_OK && dmi_init(s) == DMI_OK &&
         dmi_state_save(s, b, dmi_state_size(s)) == DMI_OK) r = restore(x, b, n);
     dmi_free(&s); free(b); return r;)
/* Foreign bytes: pseudo-random, of the right length. */
CALL(t_random, size_t n; unsigned char *b = fmu_snapshot(&F, c, &n); fmi2Status r = fmi2Fatal;
     uint64_t z = 0x9e3779b97f4a7c15u;
     if (b) { for (size_t i = 0; i < n; i++) { z ^= z << 13; z ^= z >> 7; z ^= z << 17;
                                              b[i] = (unsigned char)z; }
              r = restore(x, b, n); }
     free(b); return r;)
/* A state claiming the step-complete phase without any history (ndmi = 0). */
CALL(t_no_history, size_t n; unsigned char *own = fmu_snapshot(&F, c, &n); fmi2Status r = fmi2Fatal;
     if (own && n > MODEL_STATE_AT_DMI + 8) {
         size_t m = MODEL_STATE_AT_DMI + 8;
         unsigned char *b = malloc(m);
         if (b) { memcpy(b, own, MODEL_STATE_AT_DMI); dmi_put_u64(b, MODEL_STATE_AT_TOTAL, m);
                  dmi_put_u64(b, MODEL_STATE_AT_NDMI, 0);
                  fmu_state_fix_checksums(b, m, 1); r = restore(x, b, m); free(b); } }
     free(own); return r;)

typedef struct {
    const char *id, *fn, *input;
    int setup;
    fmi2Status (*call)(ctx *x);
    const char *msg; /* part of the logged reason */
    int fmi2_only;   /* an FMI 2.0 function without an FMI 3.0 counterpart */
} bad_case;

/* clang-format off */
static const bad_case cases[] = {
    {"F10", "fmi2SetReal", "tau = 0", F_INIT, p_tau0, "tau", 0},
    {"F11", "fmi2SetReal", "tau = -1", F_INST, p_tau_neg, "tau", 0},
    {"F12", "fmi2SetReal", "tau = NaN", F_INIT, p_tau_nan, "tau", 0},
    {"F13", "fmi2SetReal", "tau = +Inf", F_INIT, p_tau_inf, "tau", 0},
    {"F14", "fmi2SetReal", "alpha = -1", F_INIT, p_alpha_neg, "alpha", 0},
    {"F15", "fmi2SetReal", "alpha = NaN", F_INST, p_alpha_nan, "alpha", 0},
    {"F16", "fmi2SetReal", "alpha = -Inf", F_INIT, p_alpha_ninf, "alpha", 0},
    {"F17", "fmi2SetReal", "b = NaN", F_INIT, p_b_nan, "b =", 0},
    {"F18", "fmi2SetReal", "b = +Inf", F_INIT, p_b_inf, "b =", 0},
    {"F19", "fmi2SetReal", "w0 = -Inf", F_INIT, p_w0_ninf, "w0", 0},
    {"F20", "fmi2SetReal", "v0 = NaN", F_INIT, p_v0_nan, "v0", 0},
    {"F21", "fmi2SetReal", "H_lambda = +Inf", F_INIT, p_hl_inf, "H_lambda", 0},
    {"F22", "fmi2SetReal", "H_omega3 = NaN", F_INIT, p_ho_nan, "H_omega3", 0},
    {"F23", "fmi2SetReal", "g_amp = NaN", F_INIT, p_gamp_nan, "g_amp", 0},
    {"F24", "fmi2SetReal", "g_phase = +Inf", F_INIT, p_gph_inf, "g_phase", 0},
    {"F25", "fmi2SetInteger", "N = 0", F_INIT, p_N0, "N = 0", 0},
    {"F26", "fmi2SetInteger", "N = -1", F_INST, p_Nneg, "N = -1", 0},
    {"F27", "fmi2SetInteger", "N = INT_MIN", F_INIT, p_Nmin, "N =", 0},
    {"F28", "fmi2SetReal", "{b = 2, tau = -1} in one call: neither is set", F_INIT, p_two, "tau", 0},
    {"F29", "fmi2SetReal", "input g_in = NaN", F_STEP, p_gin_nan, "g_in", 0},
    {"F30", "fmi2SetReal", "input g_in = -Inf", F_STEP, p_gin_inf, "g_in", 0},
    {"F31", "fmi2SetReal", "parameter tau = 2 after initialization", F_STEP, p_late, "cannot be changed", 0},
    {"F32", "fmi2SetInteger", "parameter N = 50 after initialization", F_STEP, p_late_N, "cannot be changed", 0},
    {"F33", "fmi2SetReal", "unknown value reference 999", F_INIT, v_unknown, "999", 0},
    {"F34", "fmi2SetReal", "the output w", F_STEP, v_output, "value reference", 0},
    {"F35", "fmi2SetInteger", "the Real tau", F_INIT, v_int_on_real, "value reference", 0},
    {"F36", "fmi2GetReal", "unknown value reference 999", F_STEP, v_get_unknown, "999", 0},
    {"F37", "fmi2GetInteger", "the Real w", F_STEP, v_get_int_wrong, "value reference", 0},
    {"F38", "fmi2GetBoolean", "the Real tau", F_STEP, v_get_bool_wrong, "value reference", 0},
    {"F39", "fmi2SetReal", "vr = NULL, nvr = 1", F_INIT, v_vr_null, "NULL", 0},
    {"F40", "fmi2SetReal", "value = NULL, nvr = 1", F_INIT, v_val_null, "NULL", 0},
    {"F41", "fmi2GetReal", "value = NULL, nvr = 1", F_STEP, v_get_null, "NULL", 0},
    {"F42", "fmi2SetBoolean", "the output sticking", F_STEP, v_set_bool, "Boolean", 0},
    {"F43", "fmi2SetString", "a String (there is none)", F_INIT, v_set_string, "String", 0},
    {"F44", "fmi2SetupExperiment", "startTime = NaN", F_INST, x_start_nan, "start time", 0},
    {"F45", "fmi2SetupExperiment", "stopTime 0.5 < startTime 1", F_INST, x_stop_before, "stop time", 0},
    {"F46", "fmi2ExitInitializationMode", "tau = 1e-310 (h = tau/N not a normal number)", F_INIT, x_h_subnormal, "solver", 0},
    {"F50", "fmi2DoStep", "before initialization", F_INST, s_step_inst, "not allowed", 0},
    {"F51", "fmi2DoStep", "in initialization mode", F_INIT, s_step_inst, "not allowed", 0},
    {"F52", "fmi2DoStep", "after fmi2Terminate", F_TERM, s_step_inst, "not allowed", 0},
    {"F53", "fmi2DoStep", "in the error state", F_ERROR, s_step_inst, "not allowed", 0},
    {"F54", "fmi2ExitInitializationMode", "before fmi2EnterInitializationMode", F_INST, s_exit_inst, "not allowed", 0},
    {"F55", "fmi2EnterInitializationMode", "twice", F_INIT, s_enter_twice, "not allowed", 0},
    {"F56", "fmi2EnterInitializationMode", "after initialization", F_STEP, s_enter_twice, "not allowed", 0},
    {"F57", "fmi2SetupExperiment", "in initialization mode", F_INIT, s_setup_late, "not allowed", 1},
    {"F58", "fmi2SetupExperiment", "after initialization", F_STEP, s_setup_late, "not allowed", 1},
    {"F59", "fmi2Terminate", "before initialization", F_INST, s_term_inst, "not allowed", 0},
    {"F60", "fmi2Terminate", "in initialization mode", F_INIT, s_term_inst, "not allowed", 0},
    {"F61", "fmi2GetReal", "before initialization mode", F_INST, s_get_inst, "not allowed", 0},
    {"F62", "fmi2SetReal", "input g_in after fmi2Terminate", F_TERM, s_set_term, "not allowed", 0},
    {"F63", "fmi2GetFMUstate", "in the error state", F_ERROR, s_getstate_err, "not allowed", 0},
    {"F64", "fmi2CancelStep", "(steps are synchronous)", F_STEP, s_cancel, "fmi2CancelStep", 1},
    {"F65", "fmi2SetDebugLogging", "unknown category \"nonsense\"", F_STEP, l_unknown, "nonsense", 0},
    {"F66", "fmi2SetDebugLogging", "nCategories = 1, categories = NULL", F_INIT, l_null, "NULL", 0},
    {"F68", "fmi2GetRealStatus", "value = NULL", F_STEP, q_null, "NULL", 1},
    {"F69", "fmi2GetString", "nvr = 1 (there is no String variable)", F_STEP, q_string, "String", 0},
    {"F70", "fmi2DoStep", "communication point 0.5 ahead of the FMU's time", F_STEP, d_ahead, "communication point", 0},
    {"F71", "fmi2DoStep", "communication point one h behind", F_STEP, d_behind, "communication point", 0},
    {"F72", "fmi2DoStep", "communication point off by 1e-5 h (tolerance 1e-6 h)", F_STEP, d_off_tol, "communication point", 0},
    {"F73", "fmi2DoStep", "step = -h", F_STEP, d_neg, "step", 0},
    {"F74", "fmi2DoStep", "step = 0", F_STEP, d_zero, "step", 0},
    {"F75", "fmi2DoStep", "step = NaN", F_STEP, d_nan, "step", 0},
    {"F76", "fmi2DoStep", "step = +Inf", F_STEP, d_inf, "step", 0},
    {"F77", "fmi2DoStep", "communication point NaN", F_STEP, d_t_nan, "time", 0},
    {"F78", "fmi2DoStep", "communication point -Inf", F_STEP, d_t_ninf, "time", 0},
    {"F79", "fmi2DoStep", "step = 1e300 (beyond 2^53 h)", F_STEP, d_far, "too far", 0},
    {"F80", "fmi2SetFMUstate", "state = NULL", F_STEP, t_set_null, "NULL", 0},
    {"F81", "fmi2GetFMUstate", "FMUstate = NULL", F_STEP, t_get_null, "NULL", 0},
    {"F82", "fmi2DeSerializeFMUstate", "bytes = NULL", F_STEP, t_deser_null, "NULL", 0},
    {"F83", "fmi2DeSerializeFMUstate", "FMUstate = NULL", F_STEP, t_deser_null_out, "NULL", 0},
    {"F84", "fmi2SerializedFMUstateSize", "size = NULL", F_STEP, t_size_null, "NULL", 0},
    {"F85", "fmi2SerializeFMUstate", "buffer of 16 bytes", F_STEP, t_ser_short, "needed", 0},
    {"F86", "fmi2DeSerializeFMUstate", "truncated by one byte", F_STEP, t_short1, "state", 0},
    {"F87", "fmi2DeSerializeFMUstate", "truncated to 20 bytes", F_STEP, t_short20, "too short", 0},
    {"F88", "fmi2DeSerializeFMUstate", "size = 0", F_INIT, t_empty, "too short", 0},
    {"F89", "fmi2DeSerializeFMUstate", "one byte too many", F_STEP, t_long1, "state", 0},
    {"F90", "fmi2DeSerializeFMUstate", "magic altered", F_STEP, t_magic, "magic", 0},
    {"F91", "fmi2DeSerializeFMUstate", "format version 4, unknown (checksums valid)", F_STEP, t_version, "version", 0},
    {"F92", "fmi2DeSerializeFMUstate", "phase tag 0 (checksums valid)", F_STEP, t_tag0, "tag", 0},
    {"F93", "fmi2DeSerializeFMUstate", "phase tag = the error state (checksums valid)", F_STEP, t_tag_error, "tag", 0},
    {"F94", "fmi2DeSerializeFMUstate", "phase tag with two bits (checksums valid)", F_INIT, t_tag_two, "tag", 0},
    {"F95", "fmi2DeSerializeFMUstate", "recorded total size 1e6 (checksums valid)", F_STEP, t_total, "sizes", 0},
    {"F96", "fmi2DeSerializeFMUstate", "checksum byte altered", F_STEP, t_checksum, "checksum", 0},
    {"F97", "fmi2DeSerializeFMUstate", "a history byte altered", F_STEP, t_data, "checksum", 0},
    {"F98", "fmi2DeSerializeFMUstate", "b = NaN (checksums valid)", F_STEP, t_real_nan, "finite", 0},
    {"F99", "fmi2DeSerializeFMUstate", "tau = -1 (checksums valid)", F_INIT, t_tau_neg, "tau", 0},
    {"F100", "fmi2DeSerializeFMUstate", "N = 0 (checksums valid)", F_STEP, t_N0, "N", 0},
    {"F101", "fmi2DeSerializeFMUstate", "start time after the communication point (checksums valid)", F_STEP, t_times, "times", 0},
    {"F111", "fmi2DeSerializeFMUstate", "communication point 1.5e10 with a history at t = 0.05 (checksums valid)", F_STEP, t_comm_far, "communication point", 0},
    {"F112", "fmi2DeSerializeFMUstate", "initialization-mode state with communication point 0.5 != start time 0 (checksums valid)", F_INIT, t_comm_init, "times", 0},
    {"F102", "fmi2DeSerializeFMUstate", "a byte of libdmi's part altered, outer checksum valid", F_STEP, t_inner, "history", 0},
    {"F103", "fmi2DeSerializeFMUstate", "U^p = NaN in libdmi's part (all checksums valid)", F_STEP, t_inner_fixed, "history", 0},
    {"F104", "fmi2DeSerializeFMUstate", "N = 50 while the history is for N = 100 (checksums valid)", F_STEP, t_inner_N, "history", 0},
    {"F105", "fmi2DeSerializeFMUstate", "foreign: libdmi's own state bytes", F_STEP, t_foreign_dmi, "magic", 0},
    {"F106", "fmi2DeSerializeFMUstate", "foreign: pseudo-random bytes of the right length", F_STEP, t_random, "magic", 0},
    {"F107", "fmi2DeSerializeFMUstate", "phase step complete without any history (checksums valid)", F_STEP, t_no_history, "state", 0},
};
/* clang-format on */
#define NCASES (sizeof cases / sizeof cases[0])

static void test_table(void)
{
    for (size_t i = 0; i < NCASES; i++) {
        const bad_case *k = &cases[i];
        if (k->fmi2_only && F.version != 2)
            continue;
        ctx x;
        int rc = build(&x, k->setup);
        CHECK(rc == 0, "%s: setup %s failed", k->id, SETUP_NAME[k->setup]);
        if (rc != 0) {
            if (x.c)
                F.free_instance(x.c);
            free(x.cb);
            continue;
        }
        size_t size0 = 0, size1 = 0;
        unsigned char *before = fmu_snapshot(&F, x.c, &size0);
        memset(&x.log, 0, sizeof x.log);
        hard_quiet q;
        int quiet = hard_quiet_begin(&q);
        fmi2Status st = k->call(&x);
        long printed = hard_quiet_end(&q);
        CHECK(quiet == 0 && printed == 0, "%s: the FMU printed %ld bytes", k->id, printed);
        CHECK(st == fmi2Error, "%s %s(%s) in %s: status %d, expected fmi2Error", k->id, k->fn,
              k->input, SETUP_NAME[k->setup], (int)st);
        CHECK(x.log.errors >= 1 && x.log.status == fmi2Error &&
                  strcmp(x.log.category, "logStatusError") == 0,
              "%s: no fmi2Error logged (%u messages, last category \"%s\")", k->id, x.log.count,
              x.log.category);
        CHECK(strstr(x.log.message, k->msg) != NULL, "%s: logged \"%s\" lacks \"%s\"", k->id,
              x.log.message, k->msg);
        row(k->id, k->fn, k->input,
            st == fmi2Error ? "`fmi2Error`" : st == fmi2OK ? "**`fmi2OK`**" : "other",
            x.log.message);
        unsigned char *after = fmu_snapshot(&F, x.c, &size1);
        CHECK((before == NULL) == (after == NULL) && size0 == size1 &&
                  (!before || memcmp(before, after, size0) == 0),
              "%s: the instance changed", k->id);
        CHECK(usable(&x, k->setup), "%s: the instance is not usable afterwards: %s", k->id,
              x.log.message);
        free(before);
        free(after);
        F.free_instance(x.c);
        free(x.cb);
    }
}

/* fmi2Instantiate: NULL and a logged reason (if there is a logger). */
static void test_instantiate(void)
{
    fmu_log log;
    const fmi2CallbackFunctions cb = fmu_callbacks(&log);
    static const struct {
        const char *id, *input, *name, *guid, *msg;
        int type, callbacks; /* 0: NULL (FMI 2.0 only: FMI 3.0 has no callback structure), 1: cb */
    } t[] = {
        {"F01", "functions = NULL", "x", NULL, NULL, fmi2CoSimulation, 0},
        {"F03", "instanceName = NULL", NULL, NULL, "name", fmi2CoSimulation, 1},
        {"F04", "instanceName = \"\"", "", NULL, "name", fmi2CoSimulation, 1},
        {"F05", "fmuType = fmi2ModelExchange", "x", NULL, "co-simulation", fmi2ModelExchange, 1},
        {"F06", "GUID of another FMU", "x", "{00000000-0000-0000-0000-000000000000}", "GUID",
         fmi2CoSimulation, 1},
        {"F07", "GUID = NULL", "x", "", "GUID", fmi2CoSimulation, 1},
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        if (t[i].callbacks == 0 && F.version != 2)
            continue;
        memset(&log, 0, sizeof log);
        const char *guid = t[i].guid ? (t[i].guid[0] ? t[i].guid : NULL) : GUID;
        const fmi2CallbackFunctions *fns = t[i].callbacks == 0 ? NULL : &cb;
        fmi2Component c = F.instantiate(t[i].name, (fmi2Type)t[i].type, guid, "", fns, fmi2False,
                                        fmi2False);
        CHECK(c == NULL, "%s fmi2Instantiate(%s) returned an instance", t[i].id, t[i].input);
        if (t[i].msg)
            CHECK(log.errors == 1 && strstr(log.message, t[i].msg) != NULL,
                  "%s: logged %u errors, \"%s\"", t[i].id, log.errors, log.message);
        row(t[i].id, "fmi2Instantiate", t[i].input, c ? "**an instance**" : "`NULL`",
            t[i].msg ? log.message : "(no logger to call)");
        if (c)
            F.free_instance(c);
    }
}

/* Every function with a NULL instance: fmi2Error, no crash. */
static void test_null_instance(void)
{
    fmi2FMUstate st = NULL;
    size_t n = 0;
    fmi2Real r = 0;
    fmi2Integer i = 0;
    fmi2Boolean b = 0;
    fmi2String s = NULL;
    const fmi2ValueReference vr = 0;
    fmi2Byte bytes[8] = {0};
    fmi2Status got[] = {
        F.set_debug_logging(NULL, fmi2True, 0, NULL),
        F.setup(NULL, fmi2False, 0, 0, fmi2False, 0),
        F.enter_init(NULL),
        F.exit_init(NULL),
        F.terminate(NULL),
        F.reset(NULL),
        F.get_real(NULL, &vr, 1, &r),
        F.get_integer(NULL, &vr, 1, &i),
        F.get_boolean(NULL, &vr, 1, &b),
        F.get_string(NULL, &vr, 1, &s),
        F.set_real(NULL, &vr, 1, &r),
        F.set_integer(NULL, &vr, 1, &i),
        F.set_boolean(NULL, &vr, 1, &b),
        F.set_string(NULL, &vr, 1, &s),
        F.get_state(NULL, &st),
        F.set_state(NULL, st),
        F.free_state(NULL, &st),
        F.state_size(NULL, st, &n),
        F.serialize(NULL, st, bytes, sizeof bytes),
        F.deserialize(NULL, bytes, sizeof bytes, &st),
        F.do_step(NULL, 0, 0.01, fmi2True),
        F.cancel_step ? F.cancel_step(NULL) : fmi2Error, /* (FMI 3.0: none) */
        F.get_real_status ? F.get_real_status(NULL, fmi2LastSuccessfulTime, &r) : fmi2Error,
    };
    F.free_instance(NULL);
    for (size_t k = 0; k < sizeof got / sizeof got[0]; k++)
        CHECK(got[k] == fmi2Error, "F08: function %zu with c = NULL: status %d", k, (int)got[k]);
    row("F08", "every fmi2 function", "c = NULL", "`fmi2Error` (fmi2FreeInstance: nothing)",
        "(no instance, no logger)");
}

/* Every single-bit flip and every truncation of a serialized state. */
static void test_every_corruption(void)
{
    ctx x;
    CU_ASSERT_EQUAL_FATAL(build(&x, F_STEP), 0);
    size_t size = 0;
    unsigned char *good = fmu_snapshot(&F, x.c, &size);
    unsigned char *b = malloc(size ? size : 1);
    CU_ASSERT_FATAL(good != NULL && b != NULL);
    size_t accepted = 0, silent = 0;
    for (size_t i = 0; i < size; i++)
        for (int bit = 0; bit < 8; bit++) {
            memcpy(b, good, size);
            b[i] ^= (unsigned char)(1u << bit);
            unsigned before = x.log.errors;
            if (restore(&x, b, size) != fmi2Error)
                accepted++;
            else if (x.log.errors == before)
                silent++;
        }
    for (size_t len = 0; len < size; len++)
        if (restore(&x, good, len) != fmi2Error)
            accepted++;
    size_t size1;
    unsigned char *after = fmu_snapshot(&F, x.c, &size1);
    CHECK(accepted == 0 && silent == 0, "F108/F109: %zu bad states accepted, %zu not logged",
          accepted, silent);
    CHECK(after && size1 == size && memcmp(after, good, size) == 0, "F108/F109: instance changed");
    row("F108", "fmi2DeSerializeFMUstate", "each single-bit flip of a state", "`fmi2Error`",
        "(as F90-F97)");
    row("F109", "fmi2DeSerializeFMUstate", "each truncation to 0 .. size-1 bytes", "`fmi2Error`",
        "(as F86-F88)");
    free(after);
    free(good);
    free(b);
    F.free_instance(x.c);
    free(x.cb);
}

/* A state of a few hundred bytes claiming N = 2^22 steps per tau (checksums
 * valid): rejected without allocating memory for 2^22 steps. */
static void test_state_claiming_huge_N(void)
{
    ctx x;
    CU_ASSERT_EQUAL_FATAL(build(&x, F_STEP), 0);
    struct rusage ru0, ru1;
    getrusage(RUSAGE_SELF, &ru0);
    fmi2Status st = restore_edited(&x, E_U64, MODEL_STATE_AT_N, (double)(1 << 22), 0, 1);
    getrusage(RUSAGE_SELF, &ru1);
    long grown = ru1.ru_maxrss - ru0.ru_maxrss; /* KiB */
    CHECK(st == fmi2Error, "F110: state with N = 2^22 and a history for N = 100: status %d",
          (int)st);
    CHECK(grown < 65536, "F110: rejecting it raised the peak resident memory by %ld KiB", grown);
    row("F110", "fmi2DeSerializeFMUstate",
        "N = 2^22 with the history of N = 100 (checksums valid): peak memory grows < 64 MiB",
        st == fmi2Error ? "`fmi2Error`" : "other", x.log.message);
    F.free_instance(x.c);
    free(x.cb);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s <unpacked FMU .so> <GUID> [--table]\n", argv[0]);
        return 2;
    }
    GUID = argv[2];
    print_table = argc > 3 && strcmp(argv[3], "--table") == 0;
    if (fmu_load(&F, argv[1]) != 0)
        return 2;
    if (CU_initialize_registry() != CUE_SUCCESS)
        return 2;
    CU_pSuite suite = CU_add_suite("fmu_bad_inputs", NULL, NULL);
    if (!suite || !CU_add_test(suite, "fmi2Instantiate", test_instantiate) ||
        !CU_add_test(suite, "NULL instance", test_null_instance) ||
        !CU_add_test(suite, "table of bad calls", test_table) ||
        !CU_add_test(suite, "every corruption", test_every_corruption) ||
        !CU_add_test(suite, "state claiming a huge N", test_state_claiming_huge_N)) {
        CU_cleanup_registry();
        return 2;
    }
    int status = hard_run_tests(print_table);
    fmu_unload(&F);
    return status;
}
