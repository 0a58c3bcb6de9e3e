/*
 * The friction oscillator (4.1) through libdmi's public API: see model.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "model.h"

#include "bytes.h" /* libdmi's: FNV-1a, values at a byte offset */

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Start values (Example 4.3: b = alpha = tau = 1, N = 1000,
 * H(s) = cos 2 pi s + cos 10 pi s + cos 20 pi s, g(t) = 1.3 cos 8t,
 * w0 = v0 = 0) and names, from config.h as the model descriptions. */
#define START_X(name, kind, start, description) [VR_##name] = start,
#define START_Y(name, kind, description)
static const double START[MODEL_NVARS] = {MODEL_VARIABLES(START_X, START_Y)};
#undef START_X
#undef START_Y
#define NAME_X(name, kind, ...) [VR_##name] = #name,
static const char *const NAME[MODEL_NVARS] = {MODEL_VARIABLES(NAME_X, NAME_X)};
#undef NAME_X

static int fail(char *err, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, MODEL_ERRLEN, fmt, ap);
    va_end(ap);
    return -1;
}

void model_defaults(model *m)
{
    memcpy(m->real, START, sizeof m->real);
    m->N = (int)START[VR_N];
    m->t_start = 0.0;
    m->t_comm = 0.0;
    m->solver = NULL;
}

void model_free(model *m)
{
    dmi_free(&m->solver);
}

int model_is_parameter(unsigned vr)
{
    return vr < VR_g_in || vr == VR_N;
}

int model_set_real(model *m, unsigned vr, double value, char *err)
{
    if (vr >= MODEL_NREAL)
        return fail(err, "value reference %u is not a settable Real variable", vr);
    const char *name = NAME[vr];
    if (!isfinite(value))
        return fail(err, "%s = %g: the value must be finite", name, value);
    if (vr == VR_tau && !(value > 0))
        return fail(err, "%s = %.17g: the delay must be > 0", name, value);
    if (vr == VR_alpha && !(value >= 0))
        return fail(err, "%s = %.17g: the friction coefficient must be >= 0", name, value);
    m->real[vr] = value;
    return 0;
}

int model_set_integer(model *m, unsigned vr, int value, char *err)
{
    if (vr != VR_N)
        return fail(err, "value reference %u is not a settable Integer variable", vr);
    if (value < 1)
        return fail(err, "N = %d: the number of steps per tau must be >= 1", value);
    m->N = value;
    return 0;
}

/* ---- the model's callbacks ---- */

static double forcing(const model *m, double t)
{
    const double *r = m->real;
    return r[VR_g_offset] + r[VR_g_amp] * cos(r[VR_g_omega] * t + r[VR_g_phase]) + r[VR_g_in];
}

static int rhs(double t, const double *u, double *out, void *user)
{
    const model *m = user;
    out[0] = -u[1];
    out[1] = m->real[VR_b] * u[0] + forcing(m, m->t_start + t);
    return 0;
}

/* The coefficients of H's terms, by value reference: H_c0, H_c1 exp(..),
 * H_a{k} cos(..); a term with a zero coefficient is left out of the kernel. */
static const unsigned KERNEL_COEF[5] = {VR_H_c0, VR_H_c1, VR_H_a1, VR_H_a2, VR_H_a3};

/* H(s) = H_c0 + H_c1 exp(-H_lambda s) + sum_k H_a{k} cos(H_omega{k} s) as a
 * sum of exponentials (entry (1, 0) of the kernel), the terms with a zero
 * coefficient left out, so that the default method is the O(1) recursion.
 * A growing term (H_lambda < 0, H_c1 != 0) is refused by the recursion; the
 * default method is then the direct sum (the FMU is built without the FFT). */
static int set_kernel(const model *m, dmi_solver *s)
{
    const double *r = m->real;
    const double rate[5] = {0.0, -r[VR_H_lambda], 0.0, 0.0, 0.0};
    const double freq[5] = {0.0, 0.0, r[VR_H_omega1], r[VR_H_omega2], r[VR_H_omega3]};
    double a[5], b[5], C[5 * 4] = {0};
    size_t K = 0;
    for (size_t k = 0; k < 5; k++)
        if (r[KERNEL_COEF[k]] != 0) {
            a[K] = rate[k];
            b[K] = freq[k];
            C[4 * K + 2] = r[KERNEL_COEF[k]];
            K++;
        }
    return K ? dmi_set_kernel_exp(s, K, a, b, C, NULL) : dmi_set_kernel(s, NULL, NULL);
}

static int history(double t, double *out, void *user)
{
    const model *m = user;
    (void)t;
    out[0] = m->real[VR_w0];
    out[1] = m->real[VR_v0];
    return 0;
}

static int solver_fail(char *err, const char *what, dmi_solver *s, int rc)
{
    snprintf(err, MODEL_ERRLEN, "%s: %s", what, s ? dmi_last_error(s) : dmi_strerror(rc));
    return -1;
}

/* The bytes libdmi allocates for the model's solver, from its layout
 * (src/delay.h, src/exp.h, dmi_create and dmi_init in src/dmi.c): n = 2
 * components, N steps per tau, nnz nonzero kernel entries (H(s) acts on w
 * in the v equation: 1, or 0 without a kernel), K exponential terms.
 * After initialisation (kept): the history ring, 2 (N + 1) n doubles (the
 * series and its mirror), the kernel samples, nnz N doubles, and the
 * recursion's sums, one complex sum per term and column used: 2 K doubles.
 * While dmi_init samples the kernel (peak): dmi_create's ring, dmi_init's
 * new ring, the dense samples, N n^2 doubles, and the kept samples. */
static void solver_bytes(const model *m, double *kept, double *peak)
{
    const double n = 2, N = m->N, d = sizeof(double);
    double K = 0;
    for (size_t k = 0; k < 5; k++)
        K += m->real[KERNEL_COEF[k]] != 0;
    const double nnz = K > 0, ring = 2 * (N + 1) * n * d, samples = nnz * N * d;
    *kept = ring + samples + 2 * K * d;
    *peak = 2 * ring + N * n * n * d + samples;
}

/* "N = .. steps per tau: <bytes> while initialising, <bytes> after", the
 * sizes of solver_bytes, into out (size bytes; cut to fit). */
static void describe_bytes(const model *m, char *out, size_t size)
{
    double kept, peak;
    solver_bytes(m, &kept, &peak);
    snprintf(out, size, "N = %d steps per tau: the solver allocates %.0f bytes (%.3g GB) "
                        "while initialising and keeps %.0f bytes (%.3g GB): a history of "
                        "2(N+1) states and N kernel samples",
             m->N, peak, peak / 1e9, kept, kept / 1e9);
}

/* Out of memory for N: the error names N and the bytes needed. */
static int memory_fail(char *err, const char *what, const model *m)
{
    int len = snprintf(err, MODEL_ERRLEN, "%s: out of memory: ", what);
    if (len >= 0 && len < MODEL_ERRLEN)
        describe_bytes(m, err + len, (size_t)(MODEL_ERRLEN - len));
    return -1;
}

/* A new solver for the parameters of m: only the history ring of (N + 1) * 2
 * values is allocated and the kernel's terms are set (they make part of the
 * state's size), nothing is sampled yet. */
static int solver_create(const model *m, dmi_solver **out, char *err)
{
    int rc = dmi_create(out, 2, m->real[VR_tau], (size_t)m->N);
    if (rc == DMI_ENOMEM)
        return memory_fail(err, "creating the solver", m);
    if (rc != DMI_OK)
        return solver_fail(err, "creating the solver (tau, N)", NULL, rc);
    if ((rc = set_kernel(m, *out)) != DMI_OK) {
        if (rc == DMI_ENOMEM)
            memory_fail(err, "setting the kernel", m);
        else
            solver_fail(err, "setting the kernel", *out, rc);
        dmi_free(out);
        return -1;
    }
    return 0;
}

/* Sets the model's callbacks and friction on s and samples the kernel and
 * the history (dmi_init). */
static int solver_init(model *m, dmi_solver *s, char *err)
{
    const double alpha[2] = {0.0, m->real[VR_alpha]};
    int rc;
    if ((rc = dmi_set_rhs(s, rhs, m)) != DMI_OK ||
        (rc = dmi_set_history(s, history, m)) != DMI_OK ||
        (rc = dmi_set_friction(s, alpha)) != DMI_OK || (rc = dmi_init(s)) != DMI_OK)
        return rc == DMI_ENOMEM ? memory_fail(err, "initialising the solver", m)
                                : solver_fail(err, "initialising the solver", s, rc);
    return 0;
}

int model_start(model *m, double t_start, char *err, char *note)
{
    double kept, peak;
    solver_bytes(m, &kept, &peak);
    note[0] = '\0';
    if (peak > MODEL_NOTE_BYTES)
        describe_bytes(m, note, MODEL_ERRLEN);
    dmi_solver *s = NULL;
    if (solver_create(m, &s, err) != 0)
        return -1;
    if (solver_init(m, s, err) != 0) {
        dmi_free(&s);
        return -1;
    }
    dmi_free(&m->solver);
    m->solver = s;
    m->t_start = t_start;
    m->t_comm = t_start;
    return 0;
}

int model_coarse_step(const model *m, double T, char *msg)
{
    const double b = m->real[VR_b], tau = m->real[VR_tau], h = tau / m->N;
    if (!(b > 0) || !(T > 0))
        return 0;
    /* log of the growth (1 + h^2 b)^(T/h) over the experiment */
    const double ln_growth = T / h * log1p(h * h * b);
    if (!(ln_growth > log(MODEL_COARSE_GROWTH)))
        return 0;
    /* h b T <= ln 2 keeps the growth below 2: N >= tau b T / ln 2 */
    const double n_min = ceil(tau * b * T / log(MODEL_COARSE_GROWTH));
    snprintf(msg, MODEL_ERRLEN, "N = %d (h = %.3g) is a coarse step for b = %.3g: the scheme's "
                                "explicit part amplifies an undamped oscillation by about "
                                "(1 + h^2 b) = %.6g per step, \xc3\x97%.3g over T = %.3g; N >= %.3g "
                                "keeps it below %g",
             m->N, h, b, 1.0 + h * h * b, exp(ln_growth), T, n_min, MODEL_COARSE_GROWTH);
    return 1;
}

/* The number of steps taken when the FMU is at time t: every step whose start
 * t_p = t_start + p h is before t by more than MODEL_TIME_TOL h. */
static double steps_before(const model *m, double t, double h)
{
    return ceil((t - m->t_start) / h - MODEL_TIME_TOL);
}

int model_do_step(model *m, double t_current, double step, char *err)
{
    const double h = dmi_get_h(m->solver);
    if (!isfinite(t_current) || !isfinite(step) || !(step > 0))
        return fail(err, "the time %.17g and the step %.17g must be finite and the step > 0",
                    t_current, step);
    if (fabs(t_current - m->t_comm) > MODEL_TIME_TOL * h)
        return fail(err, "the communication point %.17g is not the FMU's time %.17g", t_current,
                    m->t_comm);
    const double t_end = t_current + step;
    const double target = steps_before(m, t_end, h);
    uint64_t p = 0;
    dmi_get_step_index(m->solver, &p);
    if (!(target < 9007199254740992.0)) /* 2^53: beyond it p h has no meaning */
        return fail(err, "t = %.17g is too far from the start for the step h", t_end);
    if (target > (double)p) {
        int rc = dmi_advance(m->solver, (size_t)(target - (double)p));
        if (rc != DMI_OK) {
            solver_fail(err, "the solver failed", m->solver, rc);
            return -2;
        }
    }
    m->t_comm = t_end;
    return 0;
}

/* The outputs at t_comm: w, v = u_h(t_comm), interpolated between U^{p-1}
 * and U^p; friction, delay force and sticking of the last step (from t_{p-1}
 * to t_p).  Before the first step: U^0, no forces. */
typedef struct {
    double w, v, friction, delay_force;
    int sticking;
} output_values;

static output_values outputs(const model *m)
{
    output_values o = {m->real[VR_w0], m->real[VR_v0], 0.0, 0.0, m->real[VR_v0] == 0.0};
    uint64_t p = 0;
    double U[2], prev[2], W[2], X[2];
    if (!m->solver || dmi_get_step_index(m->solver, &p) != DMI_OK || p == 0)
        return o;
    const double h = dmi_get_h(m->solver);
    dmi_get_state(m->solver, U);
    dmi_get_past(m->solver, 1, prev);
    dmi_get_step_terms(m->solver, W, X);
    const double theta = (m->t_comm - m->t_start) / h - (double)(p - 1);
    if (theta >= 1.0 - MODEL_TIME_TOL) {
        o.w = U[0];
        o.v = U[1];
    } else {
        const double th = theta > 0.0 ? theta : 0.0;
        o.w = prev[0] + th * (U[0] - prev[0]);
        o.v = prev[1] + th * (U[1] - prev[1]);
    }
    /* the element of alpha sigma(v) the step selected: in [-alpha, alpha],
     * up to the rounding of (X - U)/h, which the clamp removes */
    const double alpha = m->real[VR_alpha];
    o.friction = fmin(fmax((X[1] - U[1]) / h, -alpha), alpha);
    o.delay_force = W[1];
    o.sticking = U[1] == 0.0;
    return o;
}

int model_get_real(const model *m, unsigned vr, double *value, char *err)
{
    if (vr < MODEL_NREAL) {
        *value = m->real[vr];
        return 0;
    }
    const output_values o = outputs(m);
    switch (vr) {
    case VR_w: *value = o.w; return 0;
    case VR_v: *value = o.v; return 0;
    case VR_friction: *value = o.friction; return 0;
    case VR_delay_force: *value = o.delay_force; return 0;
    case VR_time: *value = m->t_comm; return 0;
    default:
        return fail(err, "value reference %u is not a Real variable", vr);
    }
}

int model_get_integer(const model *m, unsigned vr, int *value, char *err)
{
    if (vr != VR_N)
        return fail(err, "value reference %u is not an Integer variable", vr);
    *value = m->N;
    return 0;
}

int model_get_boolean(const model *m, unsigned vr, int *value, char *err)
{
    if (vr != VR_sticking)
        return fail(err, "value reference %u is not a Boolean variable", vr);
    *value = outputs(m).sticking;
    return 0;
}

/* ---- saved state ---- */

size_t model_state_size(const model *m)
{
    return MODEL_STATE_AT_DMI + dmi_state_size(m->solver) + 8;
}

void model_state_save(const model *m, uint32_t tag, unsigned char *buf)
{
    const size_t total = model_state_size(m), ndmi = dmi_state_size(m->solver);
    memcpy(buf, MODEL_STATE_MAGIC, 8);
    dmi_put_u32(buf, MODEL_STATE_AT_VERSION, MODEL_STATE_VERSION);
    dmi_put_u32(buf, MODEL_STATE_AT_TAG, tag);
    dmi_put_u64(buf, MODEL_STATE_AT_TOTAL, total);
    dmi_put_u64(buf, MODEL_STATE_AT_NREAL, MODEL_NREAL);
    dmi_put_u64(buf, MODEL_STATE_AT_NDMI, ndmi);
    dmi_put_u64(buf, MODEL_STATE_AT_N, (uint64_t)(int64_t)m->N);
    for (unsigned vr = 0; vr < MODEL_NREAL; vr++)
        dmi_put_double(buf, MODEL_STATE_AT_REAL + 8 * vr, m->real[vr]);
    dmi_put_double(buf, MODEL_STATE_AT_REAL + 8 * MODEL_NREAL, m->t_start);
    dmi_put_double(buf, MODEL_STATE_AT_REAL + 8 * (MODEL_NREAL + 1), m->t_comm);
    if (m->solver)
        dmi_state_save(m->solver, buf + MODEL_STATE_AT_DMI, ndmi);
    dmi_put_u64(buf, total - 8, dmi_fnv1a(DMI_FNV1A_INIT, buf, total - 8));
}

int model_state_load(model *into, uint32_t tags, uint32_t solver_tags, uint32_t *tag,
                     const unsigned char *buf, size_t size, char *err)
{
    if (!buf || size < MODEL_STATE_AT_DMI + 8)
        return fail(err, "state: %zu bytes is too short for a saved state", size);
    if (memcmp(buf, MODEL_STATE_MAGIC, 8) != 0)
        return fail(err, "state: the bytes are not a saved state of this FMU (bad magic)");
    const uint32_t version = dmi_get_u32(buf, MODEL_STATE_AT_VERSION);
    const uint64_t total = dmi_get_u64(buf, MODEL_STATE_AT_TOTAL);
    const uint64_t nreal = dmi_get_u64(buf, MODEL_STATE_AT_NREAL);
    const uint64_t ndmi = dmi_get_u64(buf, MODEL_STATE_AT_NDMI);
    const int64_t N = (int64_t)dmi_get_u64(buf, MODEL_STATE_AT_N);
    *tag = dmi_get_u32(buf, MODEL_STATE_AT_TAG);
    if (*tag == 0 || (*tag & (*tag - 1)) != 0 || (*tag & tags) == 0)
        return fail(err, "state: the saved phase tag %lu is not allowed", (unsigned long)*tag);
    if (version != MODEL_STATE_VERSION)
        return fail(err, "state: format version %lu is not supported (this FMU reads version %d%s)",
                    (unsigned long)version, MODEL_STATE_VERSION,
                    version == 1 ? "; version 1 was written by the FMU of libdmi 1.0" : "");
    if (nreal != MODEL_NREAL || total != size || ndmi != size - (MODEL_STATE_AT_DMI + 8))
        return fail(err, "state: the sizes recorded in the state do not match (%zu bytes given)",
                    size);
    if (dmi_get_u64(buf, size - 8) != dmi_fnv1a(DMI_FNV1A_INIT, buf, size - 8))
        return fail(err, "state: the checksum does not match (corrupted bytes)");
    double real[MODEL_NREAL];
    for (unsigned vr = 0; vr < MODEL_NREAL; vr++)
        real[vr] = dmi_get_double(buf, MODEL_STATE_AT_REAL + 8 * vr);
    const double t_start = dmi_get_double(buf, MODEL_STATE_AT_REAL + 8 * MODEL_NREAL);
    const double t_comm = dmi_get_double(buf, MODEL_STATE_AT_REAL + 8 * (MODEL_NREAL + 1));
    const unsigned char *b = buf + MODEL_STATE_AT_DMI;

    model m;
    model_defaults(&m);
    for (unsigned vr = 0; vr < MODEL_NREAL; vr++)
        if (model_set_real(&m, vr, real[vr], err) != 0)
            return -1;
    if (N < 1 || N > INT32_MAX || model_set_integer(&m, VR_N, (int)N, err) != 0)
        return fail(err, "state: N = %lld is invalid", (long long)N);
    if (!isfinite(t_start) || !isfinite(t_comm) || t_comm < t_start)
        return fail(err, "state: invalid times (start %.17g, communication point %.17g)", t_start,
                    t_comm);
    const int has_solver = (*tag & solver_tags) != 0;
    if (has_solver != (ndmi > 0))
        return fail(err, "state: the saved phase tag %lu %s the solver's history, the state has "
                         "%llu bytes of it", (unsigned long)*tag, has_solver ? "needs" : "has no",
                    (unsigned long long)ndmi);
    if (has_solver) {
        /* libdmi's state holds the N + 1 stored states U^{p-N..p} of 2 doubles:
         * fewer bytes cannot be a history for this N (checked before the
         * solver for N is allocated); then the exact size from libdmi. */
        if (ndmi / (2 * sizeof(double)) < (uint64_t)N + 1)
            return fail(err, "state: the solver's history of %llu bytes is too short for N = %lld",
                        (unsigned long long)ndmi, (long long)N);
        dmi_solver *s = NULL;
        if (solver_create(&m, &s, err) != 0)
            return -1;
        const size_t need = dmi_state_size(s);
        if (need != ndmi) {
            dmi_free(&s);
            return fail(err, "state: the solver's history has %llu bytes, N = %lld needs %zu",
                        (unsigned long long)ndmi, (long long)N, need);
        }
        int rc = solver_init(&m, s, err);
        if (rc == 0 && (rc = dmi_state_load(s, b, (size_t)ndmi)) != DMI_OK)
            solver_fail(err, "state: the solver's history", s, rc);
        /* The FMU's time is never beyond the solver's t_p (a doStep takes the
         * steps up to it): a communication point far ahead would make the
         * next doStep take all the steps to it. */
        uint64_t p = 0;
        m.t_start = t_start;
        if (rc == 0 && (dmi_get_step_index(s, &p) != DMI_OK ||
                        steps_before(&m, t_comm, dmi_get_h(s)) > (double)p))
            rc = fail(err, "state: the communication point %.17g is beyond the solver's step "
                           "%llu", t_comm, (unsigned long long)p);
        if (rc != 0) {
            dmi_free(&s);
            return -1;
        }
        m.solver = s;
    } else if (t_comm != t_start) { /* before initialization: no step taken */
        return fail(err, "state: invalid times (start %.17g, communication point %.17g)",
                    t_start, t_comm);
    }
    m.t_start = t_start;
    m.t_comm = t_comm;
    if (!into) {
        model_free(&m);
        return 0;
    }
    model_free(into);
    *into = m;
    /* the step's right-hand side reads the variables of *into from now on (the
     * kernel and history callbacks keep &m, but they are called by dmi_init only) */
    if (into->solver)
        dmi_set_rhs(into->solver, rhs, into);
    return 0;
}
