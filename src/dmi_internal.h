/*
 * Internal pieces of libdmi: the history ring and the delay sum.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_INTERNAL_H
#define DMI_INTERNAL_H

#include "dmi.h"

/* a * b elements of size sz, or 0 on overflow. */
static inline size_t dmi_mul_size(size_t a, size_t b, size_t sz)
{
    if (a != 0 && b > SIZE_MAX / a)
        return 0;
    if (a * b != 0 && sz > SIZE_MAX / (a * b))
        return 0;
    return a * b * sz;
}

/* FNV-1a 64 of len bytes, continuing from hsh (DMI_FNV1A_INIT to start). */
#define DMI_FNV1A_INIT UINT64_C(0xcbf29ce484222325)
static inline uint64_t dmi_fnv1a(uint64_t hsh, const unsigned char *b, size_t len)
{
    for (size_t i = 0; i < len; i++) {
        hsh ^= b[i];
        hsh *= UINT64_C(0x100000001b3);
    }
    return hsh;
}

/*
 * History ring of the N + 1 states U^{p-N..p}, stored per component as a
 * series with a mirror copy, so that U_j^{p-l}, l = 0..N, are contiguous:
 * buf[j * 2L + head + l], L = N + 1.  A new state moves head one slot back.
 */
typedef struct {
    size_t n, N, L, head;
    double *buf; /* n * 2L values */
} dmi_history;

int dmi_history_alloc(dmi_history *r, size_t n, size_t N); /* 0 or -1; zero-filled, head = 0 */
void dmi_history_release(dmi_history *r);
/* U^{p-lag} = u (only while filling a fresh ring: head must be 0). */
void dmi_history_put(dmi_history *r, size_t lag, const double *u);
/* Makes u the newest state U^{p+1}; U^{p-N} is dropped. */
void dmi_history_push(dmi_history *r, const double *u);
/* Pointer to U_j^{p-l}, l = 0..N (contiguous). */
static inline const double *dmi_history_series(const dmi_history *r, size_t j)
{
    return r->buf + j * 2 * r->L + r->head;
}
/* u = U^{p-lag}, 0 <= lag <= N. */
static inline void dmi_history_get(const dmi_history *r, size_t lag, double *u)
{
    for (size_t j = 0; j < r->n; j++)
        u[j] = dmi_history_series(r, j)[lag];
}

/*
 * Kernel samples H(l h), l = 0..N-1, of the entries (i, j) that are nonzero
 * at some sample; entries zero at every sample are not stored and cost
 * nothing.  They are stored row by row (e = row n + col ascending), so the
 * entries of a row are contiguous.
 */
typedef struct {
    size_t n, N, nnz;
    size_t *row, *col; /* nnz each */
    double *samples;   /* nnz * N: samples[e * N + l] = H_{row[e] col[e]}(l h) */
} dmi_kernel;

/* From dense samples (N * n * n, row-major per l), or none if dense == NULL.
 * 0 or -1 (out of memory). */
int dmi_kernel_alloc(dmi_kernel *k, size_t n, size_t N, const double *dense);
void dmi_kernel_release(dmi_kernel *k);

/* sum_{l<len} a[l] b[l] with four partial sums in a fixed order. */
double dmi_dot(const double *a, const double *b, size_t len);

/* W = h * sum_{l=0}^{N-1} H(l h) U^{p-l} (n values): the direct method. */
void dmi_delay_sum(const dmi_kernel *k, const dmi_history *r, double h, double *W);

/*
 * The FFT method (conv.c, absent when built with DMI_NO_FFT): an exact block
 * convolution engine whose whole state is a function of p, the kernel and
 * the history ring, so it can be rebuilt from them at any p with bitwise the
 * same future results.
 */
typedef struct dmi_conv dmi_conv;

/* For method DMI_CONV_FFT, or DMI_CONV_AUTO when its cost model predicts
 * the engine faster than the direct sum: *out = a new engine for kernel k
 * (its kernel spectra computed; call dmi_conv_rebuild before use).  Else
 * *out = NULL (use dmi_delay_sum).  0, or -1 when out of memory. */
int dmi_conv_create(dmi_conv **out, const dmi_kernel *k, size_t n, size_t N, int method);
void dmi_conv_free(dmi_conv *c);
/* Recomputes the engine's state for step p from the ring (U^{p-N..p}). */
void dmi_conv_rebuild(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p);
/* After U^p was pushed (p the new step counter): updates the blocks due at p. */
void dmi_conv_advance(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p);
/* W^p, as dmi_delay_sum, without changing the engine. */
void dmi_conv_sum(const dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p,
                  double h, double *W);
/* Number of FFT block sizes in use (0: the engine degenerated to direct sums). */
size_t dmi_conv_levels(const dmi_conv *c);

#endif
