/*
 * libdmi — the implicit Euler scheme (3.12)-(3.13) with a Volterra delay term.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "dmi_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STR_(x) #x
#define STR(x) STR_(x)

enum { A_NONE, A_CALLBACK, A_FRICTION, A_BOX };

struct dmi_solver {
    size_t n, N;
    double tau, h;

    dmi_rhs_fn f;
    void *f_user;
    int a_kind;
    dmi_resolvent_fn r;
    void *r_user;
    double *a_lo;  /* friction: alpha (n); box: lo (n) */
    double *a_hi;  /* box: hi (n) */
    dmi_kernel_fn H;
    void *H_user;
    dmi_history_fn z;
    void *z_user;
    int conv_method;

    int initialized;
    uint64_t p;         /* step counter: t_p = p h */
    dmi_history ring;   /* U^{p-N..p} */
    dmi_kernel kernel;  /* nonzero entries of H(l h) */
    dmi_conv *conv;     /* FFT engine, or NULL: the direct sum is in use */
    double *last_W;     /* W^{p-1} (n) */
    double *last_X;     /* X^{p-1} (n) */
    double *work;       /* 5 n scratch values: U^p, f, W, X, U^{p+1} */

    char err[256];
};

/* The message buffer is not part of the numerical state: const functions may
 * write it (every solver is allocated by dmi_create, never const-defined). */
static int fail(const dmi_solver *cs, int code, const char *fmt, ...)
{
    dmi_solver *s = (dmi_solver *)cs;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->err, sizeof s->err, fmt, ap);
    va_end(ap);
    return code;
}

static size_t first_nonfinite(const double *x, size_t n)
{
    size_t i = 0;
    while (i < n && isfinite(x[i]))
        i++;
    return i;
}

/* ---- the delay sum's engine ------------------------------------------------
 * s->conv is the FFT engine, or NULL when the direct sum is in use.  Built
 * with DMI_NO_FFT (no conv.c, no GSL: the FMU's sources) there is none. */

/* *out = the engine that method asks for with kernel k (NULL: direct). */
static int conv_make(const dmi_solver *s, const dmi_kernel *k, int method, dmi_conv **out,
                     const char *fn)
{
    *out = NULL;
#ifndef DMI_NO_FFT
    if (dmi_conv_create(out, k, s->n, s->N, method) != 0)
        return fail(s, DMI_ENOMEM, "%s: out of memory for the FFT engine", fn);
#else
    (void)s, (void)k, (void)method, (void)fn;
#endif
    return DMI_OK;
}

static void conv_free(dmi_conv *c)
{
#ifndef DMI_NO_FFT
    dmi_conv_free(c);
#else
    (void)c;
#endif
}

/* Recomputes engine c for s's step p from the ring. */
static void conv_rebuild(const dmi_solver *s, dmi_conv *c)
{
#ifndef DMI_NO_FFT
    if (c)
        dmi_conv_rebuild(c, &s->kernel, &s->ring, s->p);
#else
    (void)s, (void)c;
#endif
}

/* W = W^p. */
static void delay_sum(const dmi_solver *s, double *W)
{
#ifndef DMI_NO_FFT
    if (s->conv) {
        dmi_conv_sum(s->conv, &s->kernel, &s->ring, s->p, s->h, W);
        return;
    }
#endif
    dmi_delay_sum(&s->kernel, &s->ring, s->h, W);
}

/* After a step was committed (U^p pushed, p counted). */
static void conv_advance(dmi_solver *s)
{
#ifndef DMI_NO_FFT
    if (s->conv)
        dmi_conv_advance(s->conv, &s->kernel, &s->ring, s->p);
#else
    (void)s;
#endif
}

const char *dmi_version(void)
{
    return STR(DMI_VERSION_MAJOR) "." STR(DMI_VERSION_MINOR) "." STR(DMI_VERSION_PATCH);
}

const char *dmi_strerror(int code)
{
    switch (code) {
    case DMI_OK: return "success";
    case DMI_EINVAL: return "invalid argument";
    case DMI_ENOMEM: return "out of memory";
    case DMI_ECALLBACK: return "a callback reported failure";
    case DMI_ENONFINITE: return "a non-finite value (NaN or infinity) appeared";
    case DMI_ESTATE: return "call not allowed in the solver's current state";
    default: return "unknown error code";
    }
}

const char *dmi_last_error(const dmi_solver *s)
{
    return s ? s->err : "no solver (NULL handle)";
}

/* ---- life cycle ---------------------------------------------------------- */

int dmi_create(dmi_solver **out, size_t n, double tau, size_t N)
{
    if (!out)
        return DMI_EINVAL;
    *out = NULL;
    if (n == 0 || N == 0 || !isfinite(tau) || !(tau > 0))
        return DMI_EINVAL;
    double h = tau / (double)N;
    if (!isnormal(h))
        return DMI_EINVAL;
    if (N == SIZE_MAX || dmi_mul_size(2 * (N + 1) > N ? 2 * (N + 1) : 0, n, sizeof(double)) == 0 ||
        dmi_mul_size(5, n, sizeof(double)) == 0)
        return DMI_ENOMEM;

    dmi_solver *s = calloc(1, sizeof *s);
    if (!s)
        return DMI_ENOMEM;
    s->n = n;
    s->N = N;
    s->tau = tau;
    s->h = h;
    s->a_kind = A_NONE;
    s->conv_method = DMI_CONV_AUTO;
    s->work = malloc(5 * n * sizeof(double));
    s->last_W = calloc(n, sizeof(double));
    s->last_X = calloc(n, sizeof(double));
    if (!s->work || !s->last_W || !s->last_X || dmi_history_alloc(&s->ring, n, N) != 0) {
        dmi_free(&s);
        return DMI_ENOMEM;
    }
    *out = s;
    return DMI_OK;
}

void dmi_free(dmi_solver **ps)
{
    if (!ps || !*ps)
        return;
    dmi_solver *s = *ps;
    free(s->a_lo);
    free(s->a_hi);
    dmi_history_release(&s->ring);
    dmi_kernel_release(&s->kernel);
    conv_free(s->conv);
    free(s->last_W);
    free(s->last_X);
    free(s->work);
    free(s);
    *ps = NULL;
}

/* ---- setup ---------------------------------------------------------------- */

int dmi_set_rhs(dmi_solver *s, dmi_rhs_fn f, void *user)
{
    if (!s)
        return DMI_EINVAL;
    s->f = f;
    s->f_user = user;
    return DMI_OK;
}

static void set_operator(dmi_solver *s, int kind, double *lo, double *hi, dmi_resolvent_fn r,
                         void *user)
{
    free(s->a_lo);
    free(s->a_hi);
    s->a_kind = kind;
    s->a_lo = lo;
    s->a_hi = hi;
    s->r = r;
    s->r_user = user;
}

int dmi_set_resolvent(dmi_solver *s, dmi_resolvent_fn r, void *user)
{
    if (!s)
        return DMI_EINVAL;
    set_operator(s, r ? A_CALLBACK : A_NONE, NULL, NULL, r, user);
    return DMI_OK;
}

int dmi_set_friction(dmi_solver *s, const double *alpha)
{
    if (!s)
        return DMI_EINVAL;
    if (!alpha)
        return fail(s, DMI_EINVAL, "dmi_set_friction: alpha is NULL");
    for (size_t i = 0; i < s->n; i++)
        if (!isfinite(alpha[i]) || alpha[i] < 0)
            return fail(s, DMI_EINVAL,
                        "dmi_set_friction: alpha[%zu] = %g must be finite and >= 0", i, alpha[i]);
    double *a = malloc(s->n * sizeof *a);
    if (!a)
        return fail(s, DMI_ENOMEM, "dmi_set_friction: out of memory");
    memcpy(a, alpha, s->n * sizeof *a);
    set_operator(s, A_FRICTION, a, NULL, NULL, NULL);
    return DMI_OK;
}

int dmi_set_box(dmi_solver *s, const double *lo, const double *hi)
{
    if (!s)
        return DMI_EINVAL;
    if (!lo || !hi)
        return fail(s, DMI_EINVAL, "dmi_set_box: %s is NULL", lo ? "hi" : "lo");
    for (size_t i = 0; i < s->n; i++) {
        if (isnan(lo[i]) || isnan(hi[i]))
            return fail(s, DMI_EINVAL, "dmi_set_box: lo[%zu] or hi[%zu] is NaN", i, i);
        if (lo[i] > hi[i])
            return fail(s, DMI_EINVAL, "dmi_set_box: lo[%zu] = %g > hi[%zu] = %g", i, lo[i], i,
                        hi[i]);
        if (lo[i] == INFINITY || hi[i] == -INFINITY)
            return fail(s, DMI_EINVAL, "dmi_set_box: the box is empty in component %zu", i);
    }
    double *l = malloc(s->n * sizeof *l), *u = malloc(s->n * sizeof *u);
    if (!l || !u) {
        free(l);
        free(u);
        return fail(s, DMI_ENOMEM, "dmi_set_box: out of memory");
    }
    memcpy(l, lo, s->n * sizeof *l);
    memcpy(u, hi, s->n * sizeof *u);
    set_operator(s, A_BOX, l, u, NULL, NULL);
    return DMI_OK;
}

int dmi_set_kernel(dmi_solver *s, dmi_kernel_fn H, void *user)
{
    if (!s)
        return DMI_EINVAL;
    if (s->initialized)
        return fail(s, DMI_ESTATE, "dmi_set_kernel: the kernel is sampled by dmi_init and "
                                   "cannot change afterwards");
    s->H = H;
    s->H_user = user;
    return DMI_OK;
}

int dmi_set_history(dmi_solver *s, dmi_history_fn z, void *user)
{
    if (!s)
        return DMI_EINVAL;
    if (s->initialized)
        return fail(s, DMI_ESTATE, "dmi_set_history: the history is sampled by dmi_init and "
                                   "cannot change afterwards");
    s->z = z;
    s->z_user = user;
    return DMI_OK;
}

int dmi_set_convolution(dmi_solver *s, int method)
{
    if (!s)
        return DMI_EINVAL;
    if (method != DMI_CONV_AUTO && method != DMI_CONV_DIRECT && method != DMI_CONV_FFT)
        return fail(s, DMI_EINVAL, "dmi_set_convolution: unknown method %d", method);
#ifdef DMI_NO_FFT
    if (method == DMI_CONV_FFT)
        return fail(s, DMI_EINVAL, "dmi_set_convolution: DMI_CONV_FFT is not available, this "
                                   "libdmi was built without the FFT (DMI_NO_FFT)");
#endif
    if (s->initialized) { /* the engine follows the method from the next step on */
        dmi_conv *c = NULL;
        int rc = conv_make(s, &s->kernel, method, &c, "dmi_set_convolution");
        if (rc != DMI_OK)
            return rc;
        conv_rebuild(s, c);
        conv_free(s->conv);
        s->conv = c;
    }
    s->conv_method = method;
    return DMI_OK;
}

/* ---- init ------------------------------------------------------------------ */

/* Samples H(l h), l = 0..N-1, into k (nonzero entries only). */
static int sample_kernel(dmi_solver *s, dmi_kernel *k)
{
    const size_t n = s->n, N = s->N, nn = n * n;
    if (!s->H)
        return dmi_kernel_alloc(k, n, N, NULL) == 0 ? DMI_OK
                                                   : fail(s, DMI_ENOMEM, "dmi_init: out of memory");
    /* (0 also when n * n overflows) */
    size_t bytes = dmi_mul_size(n, n, 1) ? dmi_mul_size(N, nn, sizeof(double)) : 0;
    double *dense = bytes ? malloc(bytes) : NULL;
    if (!dense)
        return fail(s, DMI_ENOMEM, "dmi_init: cannot allocate %zu x %zu x %zu kernel samples", N,
                    n, n);
    for (size_t l = 0; l < N; l++) {
        double t = (double)l * s->h;
        double *Hl = dense + l * nn;
        memset(Hl, 0, nn * sizeof *Hl);
        int rc = s->H(t, Hl, s->H_user);
        if (rc != 0) {
            free(dense);
            return fail(s, DMI_ECALLBACK, "dmi_init: kernel callback returned %d at s = %.17g", rc,
                        t);
        }
        size_t bad = first_nonfinite(Hl, nn);
        if (bad < nn) {
            rc = fail(s, DMI_ENONFINITE, "dmi_init: kernel H(%.17g)[%zu][%zu] = %g", t, bad / n,
                      bad % n, Hl[bad]);
            free(dense);
            return rc;
        }
    }
    int rc = dmi_kernel_alloc(k, n, N, dense);
    free(dense);
    return rc == 0 ? DMI_OK : fail(s, DMI_ENOMEM, "dmi_init: out of memory for kernel samples");
}

/* Samples z(p h), p = -N..0, into ring. */
static int sample_history(dmi_solver *s, dmi_history *ring)
{
    const size_t n = s->n, N = s->N;
    double *u = s->work;
    for (size_t k = 0; k <= N; k++) { /* U^{-k} = z(-k h) */
        /* t_{-k} = -k h, exactly -tau at k = N (-N h may round below it) */
        double t = k == s->N ? -s->tau : k == 0 ? 0.0 : -(double)k * s->h;
        memset(u, 0, n * sizeof *u);
        if (s->z) {
            int rc = s->z(t, u, s->z_user);
            if (rc != 0)
                return fail(s, DMI_ECALLBACK, "dmi_init: history callback returned %d at t = %.17g",
                            rc, t);
            size_t bad = first_nonfinite(u, n);
            if (bad < n)
                return fail(s, DMI_ENONFINITE, "dmi_init: history z(%.17g)[%zu] = %g", t, bad,
                            u[bad]);
        }
        dmi_history_put(ring, k, u);
    }
    return DMI_OK;
}

int dmi_init(dmi_solver *s)
{
    if (!s)
        return DMI_EINVAL;
    dmi_kernel k = {0};
    dmi_history ring = {0};
    if (dmi_history_alloc(&ring, s->n, s->N) != 0)
        return fail(s, DMI_ENOMEM, "dmi_init: out of memory for the history");
    dmi_conv *c = NULL;
    int rc = sample_kernel(s, &k);
    if (rc == DMI_OK)
        rc = sample_history(s, &ring);
    if (rc == DMI_OK)
        rc = conv_make(s, &k, s->conv_method, &c, "dmi_init");
    if (rc != DMI_OK) {
        dmi_kernel_release(&k);
        dmi_history_release(&ring);
        return rc;
    }
    dmi_kernel_release(&s->kernel);
    dmi_history_release(&s->ring);
    s->kernel = k;
    s->ring = ring;
    conv_free(s->conv);
    s->conv = c;
    s->p = 0;
    conv_rebuild(s, c); /* the history's part, before the first step */
    memset(s->last_W, 0, s->n * sizeof *s->last_W); /* a restart saves the bytes of a new run */
    memset(s->last_X, 0, s->n * sizeof *s->last_X);
    s->initialized = 1;
    return DMI_OK;
}

/* ---- stepping -------------------------------------------------------------- */

static int apply_resolvent(dmi_solver *s, const double *x, double *out)
{
    const size_t n = s->n;
    const double h = s->h;
    switch (s->a_kind) {
    case A_CALLBACK: {
        memset(out, 0, n * sizeof *out);
        int rc = s->r(h, x, out, s->r_user);
        if (rc != 0)
            return fail(s, DMI_ECALLBACK, "dmi_step: resolvent callback returned %d at t = %.17g",
                        rc, dmi_time(s));
        break;
    }
    case A_FRICTION:
        for (size_t i = 0; i < n; i++) {
            double lam = h * s->a_lo[i];
            out[i] = x[i] > lam ? x[i] - lam : x[i] < -lam ? x[i] + lam : 0.0;
        }
        break;
    case A_BOX:
        for (size_t i = 0; i < n; i++)
            out[i] = x[i] < s->a_lo[i] ? s->a_lo[i] : x[i] > s->a_hi[i] ? s->a_hi[i] : x[i];
        break;
    default:
        memcpy(out, x, n * sizeof *out);
    }
    return DMI_OK;
}

int dmi_step(dmi_solver *s)
{
    if (!s)
        return DMI_EINVAL;
    if (!s->initialized)
        return fail(s, DMI_ESTATE, "dmi_step: call dmi_init first");
    const size_t n = s->n;
    const double h = s->h, t = (double)s->p * h; /* dmi_time */
    double *U = s->work, *fv = U + n, *W = fv + n, *X = W + n, *U1 = X + n;
    dmi_history_get(&s->ring, 0, U);

    for (size_t i = 0; i < n; i++) /* (loops, not memset/memcpy: n is small) */
        fv[i] = 0;
    if (s->f) {
        int rc = s->f(t, U, fv, s->f_user);
        if (rc != 0)
            return fail(s, DMI_ECALLBACK, "dmi_step: rhs callback returned %d at t = %.17g", rc, t);
    }
    delay_sum(s, W);
    for (size_t i = 0; i < n; i++)
        X[i] = U[i] - h * fv[i] - h * W[i];
    /* A non-finite f or W makes X non-finite (U^p and h are finite), so one
     * check of X guards all three; the culprit is named on the error path. */
    size_t bad = first_nonfinite(X, n);
    if (bad < n) {
        size_t bf = first_nonfinite(fv, n), bw = first_nonfinite(W, n);
        if (bf < n)
            return fail(s, DMI_ENONFINITE, "dmi_step: f(%.17g, U)[%zu] = %g", t, bf, fv[bf]);
        if (bw < n)
            return fail(s, DMI_ENONFINITE, "dmi_step: delay term W[%zu] = %g at t = %.17g", bw,
                        W[bw], t);
        return fail(s, DMI_ENONFINITE, "dmi_step: resolvent argument X[%zu] = %g at t = %.17g",
                    bad, X[bad], t);
    }
    int rc = apply_resolvent(s, X, U1);
    if (rc != DMI_OK)
        return rc;
    bad = first_nonfinite(U1, n);
    if (bad < n)
        return fail(s, DMI_ENONFINITE, "dmi_step: new state U[%zu] = %g at t = %.17g", bad,
                    U1[bad], t + h);

    /* commit */
    dmi_history_push(&s->ring, U1);
    for (size_t i = 0; i < n; i++) {
        s->last_W[i] = W[i];
        s->last_X[i] = X[i];
    }
    s->p++;
    conv_advance(s);
    return DMI_OK;
}

int dmi_advance(dmi_solver *s, size_t steps)
{
    if (!s)
        return DMI_EINVAL;
    for (size_t k = 0; k < steps; k++) {
        int rc = dmi_step(s);
        if (rc != DMI_OK)
            return rc;
    }
    return DMI_OK;
}

/* ---- queries ---------------------------------------------------------------- */

double dmi_time(const dmi_solver *s)
{
    return s && s->initialized ? (double)s->p * s->h : 0.0;
}

double dmi_get_h(const dmi_solver *s)
{
    return s ? s->h : 0.0;
}

static int check_query(const dmi_solver *s, const void *out, const char *fn)
{
    if (!s)
        return DMI_EINVAL;
    if (!out)
        return fail(s, DMI_EINVAL, "%s: output pointer is NULL", fn);
    if (!s->initialized)
        return fail(s, DMI_ESTATE, "%s: call dmi_init first", fn);
    return DMI_OK;
}

int dmi_get_step_index(const dmi_solver *s, uint64_t *p)
{
    int rc = check_query(s, p, "dmi_get_step_index");
    if (rc == DMI_OK)
        *p = s->p;
    return rc;
}

int dmi_get_state(const dmi_solver *s, double *u)
{
    int rc = check_query(s, u, "dmi_get_state");
    if (rc == DMI_OK)
        dmi_history_get(&s->ring, 0, u);
    return rc;
}

int dmi_get_past(const dmi_solver *s, size_t lag, double *u)
{
    int rc = check_query(s, u, "dmi_get_past");
    if (rc != DMI_OK)
        return rc;
    if (lag > s->N)
        return fail(s, DMI_EINVAL, "dmi_get_past: lag %zu > N = %zu", lag, s->N);
    dmi_history_get(&s->ring, lag, u);
    return DMI_OK;
}

int dmi_get_step_terms(const dmi_solver *s, double *W, double *X)
{
    if (!s)
        return DMI_EINVAL;
    if (!s->initialized || s->p == 0)
        return fail(s, DMI_ESTATE, "dmi_get_step_terms: no step taken since dmi_init");
    if (W)
        memcpy(W, s->last_W, s->n * sizeof *W);
    if (X)
        memcpy(X, s->last_X, s->n * sizeof *X);
    return DMI_OK;
}

/* ---- state save / load ---------------------------------------------------------
 * Layout (native endian): header of 8 uint64 words
 *   magic, version, n, N, bits of tau, p, p != 0 (a step was taken), checksum
 * then (N + 1) n doubles U^{p-lag} for lag = 0..N, n doubles W, n doubles X.
 * checksum = FNV-1a 64 of every other byte (header with checksum word 0).
 */
#define STATE_MAGIC UINT64_C(0x444d495354415445) /* "DMISTATE" */
#define STATE_VERSION UINT64_C(1)
#define STATE_WORDS 8

static uint64_t fnv1a(uint64_t hsh, const unsigned char *b, size_t len)
{
    for (size_t i = 0; i < len; i++) {
        hsh ^= b[i];
        hsh *= UINT64_C(0x100000001b3);
    }
    return hsh;
}

static uint64_t state_checksum(const unsigned char *buf, size_t size)
{
    const size_t cks = 7 * sizeof(uint64_t);
    static const unsigned char zero[sizeof(uint64_t)];
    uint64_t hsh = fnv1a(UINT64_C(0xcbf29ce484222325), buf, cks);
    hsh = fnv1a(hsh, zero, sizeof zero);
    return fnv1a(hsh, buf + cks + sizeof(uint64_t), size - cks - sizeof(uint64_t));
}

size_t dmi_state_size(const dmi_solver *s)
{
    if (!s)
        return 0;
    return STATE_WORDS * sizeof(uint64_t) + ((s->N + 1) * s->n + 2 * s->n) * sizeof(double);
}

int dmi_state_save(const dmi_solver *s, void *buf, size_t size)
{
    int rc = check_query(s, buf, "dmi_state_save");
    if (rc != DMI_OK)
        return rc;
    const size_t need = dmi_state_size(s), n = s->n;
    if (size < need)
        return fail(s, DMI_EINVAL, "dmi_state_save: buffer of %zu bytes, %zu needed", size, need);
    uint64_t hdr[STATE_WORDS] = {STATE_MAGIC, STATE_VERSION, (uint64_t)n, (uint64_t)s->N, 0,
                                 s->p, (uint64_t)(s->p != 0), 0};
    memcpy(&hdr[4], &s->tau, sizeof(double));
    unsigned char *b = buf;
    memcpy(b, hdr, sizeof hdr);
    unsigned char *d = b + sizeof hdr; /* buf may be unaligned: copy bytes */
    for (size_t lag = 0; lag <= s->N; lag++)
        for (size_t j = 0; j < n; j++, d += sizeof(double))
            memcpy(d, &dmi_history_series(&s->ring, j)[lag], sizeof(double));
    memcpy(d, s->last_W, n * sizeof(double));
    memcpy(d + n * sizeof(double), s->last_X, n * sizeof(double));
    hdr[7] = state_checksum(b, need);
    memcpy(b + 7 * sizeof(uint64_t), &hdr[7], sizeof(uint64_t));
    return DMI_OK;
}

int dmi_state_load(dmi_solver *s, const void *buf, size_t size)
{
    int rc = check_query(s, buf, "dmi_state_load");
    if (rc != DMI_OK)
        return rc;
    const size_t need = dmi_state_size(s), n = s->n;
    if (size != need)
        return fail(s, DMI_EINVAL, "dmi_state_load: %zu bytes, this solver's state has %zu", size,
                    need);
    const unsigned char *b = buf;
    uint64_t hdr[STATE_WORDS];
    memcpy(hdr, b, sizeof hdr);
    double tau;
    memcpy(&tau, &hdr[4], sizeof tau);
    if (hdr[0] != STATE_MAGIC)
        return fail(s, DMI_EINVAL, "dmi_state_load: not a dmi state (bad magic)");
    if (hdr[1] != STATE_VERSION)
        return fail(s, DMI_EINVAL, "dmi_state_load: state format version %llu, expected %llu",
                    (unsigned long long)hdr[1], (unsigned long long)STATE_VERSION);
    if (hdr[2] != (uint64_t)n || hdr[3] != (uint64_t)s->N || memcmp(&tau, &s->tau, sizeof tau))
        return fail(s, DMI_EINVAL,
                    "dmi_state_load: state of a solver with n = %llu, N = %llu, tau = %g; this "
                    "one has n = %zu, N = %zu, tau = %g",
                    (unsigned long long)hdr[2], (unsigned long long)hdr[3], tau, n, s->N, s->tau);
    if (hdr[7] != state_checksum(b, need))
        return fail(s, DMI_EINVAL, "dmi_state_load: corrupted state (checksum mismatch)");
    if (hdr[6] != (uint64_t)(hdr[5] != 0))
        return fail(s, DMI_EINVAL, "dmi_state_load: corrupted state (step flag %llu at p = %llu)",
                    (unsigned long long)hdr[6], (unsigned long long)hdr[5]);
    const size_t nd = (s->N + 3) * n;
    double *d = malloc(nd * sizeof *d);
    if (!d)
        return fail(s, DMI_ENOMEM, "dmi_state_load: out of memory");
    memcpy(d, b + sizeof hdr, nd * sizeof *d);
    if (first_nonfinite(d, nd) < nd) {
        free(d);
        return fail(s, DMI_EINVAL, "dmi_state_load: state holds a non-finite value");
    }
    dmi_history ring = {0};
    if (dmi_history_alloc(&ring, n, s->N) != 0) {
        free(d);
        return fail(s, DMI_ENOMEM, "dmi_state_load: out of memory");
    }
    for (size_t lag = 0; lag <= s->N; lag++)
        dmi_history_put(&ring, lag, d + lag * n);
    dmi_history_release(&s->ring);
    s->ring = ring;
    memcpy(s->last_W, d + (s->N + 1) * n, n * sizeof *d);
    memcpy(s->last_X, d + (s->N + 2) * n, n * sizeof *d);
    s->p = hdr[5];
    conv_rebuild(s, s->conv);
    free(d);
    return DMI_OK;
}
