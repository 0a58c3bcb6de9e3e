/*
 * The delay sum's engine: see engine.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "engine.h"

#include "cells.h"
#include "core.h"
#include "errors.h"

#include <math.h>
#include <string.h>

/* The FFT engine's calls: conv.c's in a build with DMI_HAVE_FFT (libdmi),
 * none otherwise (the GSL-free core: DMI_CONV_FFT is refused, AUTO never
 * picks it).  The one place that depends on the build. */
#ifdef DMI_HAVE_FFT
enum { FFT_BUILT = 1 };
static int fft_create(dmi_conv **out, const dmi_kernel *k, size_t n, size_t N, int method)
{
    return dmi_conv_create(out, k, n, N, method);
}
static void fft_free(dmi_conv *c)
{
    dmi_conv_free(c);
}
static void fft_rebuild(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p)
{
    dmi_conv_rebuild(c, k, r, p);
}
static void fft_advance(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p)
{
    dmi_conv_advance(c, k, r, p);
}
static void fft_sum(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p, double h,
                    double *W)
{
    dmi_conv_sum(c, k, r, p, h, W);
}
#else
enum { FFT_BUILT = 0 };
static int fft_create(dmi_conv **out, const dmi_kernel *k, size_t n, size_t N, int method)
{
    (void)k, (void)n, (void)N, (void)method;
    *out = NULL;
    return 0;
}
static void fft_free(dmi_conv *c)
{
    (void)c;
}
static void fft_rebuild(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p)
{
    (void)c, (void)k, (void)r, (void)p;
}
static void fft_advance(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p)
{
    (void)c, (void)k, (void)r, (void)p;
}
static void fft_sum(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p, double h,
                    double *W)
{
    (void)c, (void)k, (void)r, (void)p, (void)h, (void)W;
}
#endif

/* ---- the method ------------------------------------------------------------ */

/* The recursion's limit on |b_k| h: beyond pi the samples cos(b_k l h)
 * alias a frequency below pi / h, and r = exp(i b h) and the samples lose
 * accuracy as |b| h grows (measured: 1.8e-7 apart at b h = 1e9). */
#define REC_MAX_BH 3.14159265358979323846

/* Index of the first term of the exponential kernel that the recursion
 * refuses at step h (C_k or D_k not zero, and growing, a_k > 0, or
 * |b_k| h > pi), or K; *aliased tells which. */
static size_t first_unfit(const dmi_solver *s, double h, int *aliased)
{
    const dmi_expk *x = &s->expk;
    for (size_t k = 0; k < x->K; k++) {
        *aliased = !(x->a[k] > 0);
        if ((x->a[k] > 0 || fabs(x->b[k]) * h > REC_MAX_BH) && dmi_expk_term_used(x, k))
            return k;
    }
    return x->K;
}

int dmi_engine_check_method(const dmi_solver *s, int method, const char *fn)
{
    if (method != DMI_CONV_AUTO && method != DMI_CONV_DIRECT && method != DMI_CONV_FFT &&
        method != DMI_CONV_RECURSIVE)
        return dmi_fail(s, DMI_EINVAL, "%s: unknown method %d", fn, method);
    if (method == DMI_CONV_FFT && !FFT_BUILT)
        return dmi_fail(s, DMI_EINVAL, "%s: DMI_CONV_FFT is not available, this libdmi was built "
                                       "without the FFT (no DMI_HAVE_FFT)", fn);
    if (method != DMI_CONV_RECURSIVE)
        return DMI_OK;
    if (s->H && !dmi_has_expk(s))
        return dmi_fail(s, DMI_EINVAL, "%s: method %d (DMI_CONV_RECURSIVE) needs a kernel given by "
                                       "dmi_set_kernel_exp, not a callback", fn, method);
    int aliased = 0;
    size_t k = first_unfit(s, s->h, &aliased);
    if (k == s->expk.K)
        return DMI_OK;
    if (aliased)
        return dmi_fail(s, DMI_EINVAL, "%s: method %d (DMI_CONV_RECURSIVE) refuses the term "
                                       "b[%zu] = %g: b h = %g is beyond [-pi, pi], where its "
                                       "samples alias a frequency below pi / h and r = exp(i b h) "
                                       "loses accuracy (use DIRECT or FFT, or a smaller h)",
                        fn, method, k, s->expk.b[k], s->expk.b[k] * s->h);
    return dmi_fail(s, DMI_EINVAL, "%s: method %d (DMI_CONV_RECURSIVE) refuses the growing "
                                   "term a[%zu] = %g > 0: the recursion would multiply its "
                                   "rounding errors by exp(a h) > 1 every step (use DIRECT or "
                                   "FFT)", fn, method, k, s->expk.a[k]);
}

/* dmi_engine_is_recursion at step h. */
static int recursion_at(const dmi_solver *s, int method, double h)
{
    int aliased;
    return method == DMI_CONV_RECURSIVE ||
           (method == DMI_CONV_AUTO && dmi_has_expk(s) &&
            first_unfit(s, h, &aliased) == s->expk.K);
}

int dmi_engine_is_recursion(const dmi_solver *s, int method)
{
    return recursion_at(s, method, s->h);
}

int dmi_engine_needs_samples(const dmi_solver *s, int method)
{
    return s->theta != 1 || !dmi_engine_is_recursion(s, method) || s->quad == DMI_QUAD_CELL ||
           s->near_H;
}

int dmi_engine_make(const dmi_solver *s, const dmi_kernel *k, int method, dmi_conv **conv,
                    dmi_exp **rec, const char *fn)
{
    *conv = NULL;
    *rec = NULL;
    if (dmi_engine_is_recursion(s, method)) {
        const dmi_expk *x = s->quad == DMI_QUAD_CELL ? &s->cell_expk : &s->expk;
        if (dmi_has_expk(s) && dmi_exp_create(rec, x, s->N, s->h) != 0)
            return dmi_fail(s, DMI_ENOMEM, "%s: out of memory for the recursion's sums", fn);
        return DMI_OK;
    }
    if (fft_create(conv, k, s->n, s->N, method) != 0)
        return dmi_fail(s, DMI_ENOMEM, "%s: out of memory for the FFT engine", fn);
    return DMI_OK;
}

void dmi_engine_free(dmi_conv *conv, dmi_exp *rec)
{
    if (conv)
        fft_free(conv);
    dmi_exp_free(rec);
}

void dmi_engine_rebuild(const dmi_solver *s, dmi_conv *conv, dmi_exp *rec)
{
    if (conv)
        fft_rebuild(conv, &s->kernel, &s->ring, s->p);
    if (rec)
        dmi_exp_anchor(rec, &s->ring, s->p);
}

/* ---- the sum ---------------------------------------------------------------- */

/* W^p with every cell's weight h: the recursion's own array, or W filled. */
static const double *sum_full(const dmi_solver *s, double *W)
{
    if (s->rec && s->near.nnz) { /* the near cells' exact weights less the sum's */
        memcpy(W, dmi_exp_sum(s->rec), s->n * sizeof *W);
        dmi_cells_near_add(&s->near, &s->ring, s->h, W);
        return W;
    }
    if (s->rec)
        return dmi_exp_sum(s->rec);
    if (s->conv) {
        fft_sum(s->conv, &s->kernel, &s->ring, s->p, s->h, W);
        return W;
    }
    dmi_delay_sum(&s->kernel, &s->ring, s->h, W);
    return W;
}

/* Every method: its full sum, then the last cell's change (theta = 1
 * leaves the full sum's bits alone). */
const double *dmi_engine_sum_other(const dmi_solver *s, double *W)
{
    const double *full = sum_full(s, W);
    if (s->theta == 1)
        return full;
    if (full != W)
        memcpy(W, full, s->n * sizeof *W);
    if (s->quad == DMI_QUAD_CELL)
        dmi_cells_last(&s->kernel, &s->ring, s->cell_last, W);
    else
        dmi_delay_last(&s->kernel, &s->ring, (s->theta - 1) * s->h, W);
    return W;
}

void dmi_engine_advance_fft(dmi_solver *s)
{
    fft_advance(s->conv, &s->kernel, &s->ring, s->p);
}

/* ---- memory (core.h) ---------------------------------------------------------- */

void dmi_core_bytes(const dmi_solver *s, size_t N_cells, double h, double *peak, double *kept)
{
    const double n = (double)s->n, N = (double)N_cells, d = sizeof(double);
    const double ring = 2 * (N + 1) * n * d;
    double nnz = 0, sums = 0; /* kernel entries kept, the recursion's complex sums */
    if (dmi_has_expk(s)) {
        const size_t nn = s->n * s->n;
        for (size_t q = 0; q < nn; q++) {
            int used = 0;
            for (size_t k = 0; k < s->expk.K && !used; k++)
                used = s->expk.C[k * nn + q] != 0 || (s->expk.D && s->expk.D[k * nn + q] != 0);
            nnz += used;
        }
    } else if (s->H) {
        nnz = n * n; /* a callback: every entry, at most */
    }
    const int rec = recursion_at(s, s->conv_method, h) && dmi_has_expk(s);
    if (rec)
        sums = (double)dmi_expk_sums(&s->expk);
    const int sample = s->H && (h != s->tau / N || !rec || s->quad == DMI_QUAD_CELL || s->near_H);
    const double samples = sample ? nnz * N * d : 0;
    *kept = ring + samples + 2 * sums * d;
    *peak = 2 * ring + (sample ? N * n * n * d + samples : 0);
}
