/*
 * The history ring, the kernel samples and the direct delay sum (delay.c).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_DELAY_H
#define DMI_DELAY_H

#include <stddef.h>

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
/* u (n values) into slot slot of every series and of its mirror. */
static inline void dmi_history_write_slot(dmi_history *r, size_t slot, const double *u)
{
    for (size_t j = 0; j < r->n; j++) {
        double *series = r->buf + j * 2 * r->L;
        series[slot] = u[j];
        series[slot + r->L] = u[j];
    }
}
/* U^{p-lag} = u (only while filling a fresh ring: head must be 0). */
static inline void dmi_history_put(dmi_history *r, size_t lag, const double *u)
{
    const size_t slot = r->head + lag; /* (head, lag < L: no division) */
    dmi_history_write_slot(r, slot < r->L ? slot : slot - r->L, u);
}
/* Every state from the window U, (N + 1) rows of n values, oldest first:
 * row k is U^{p-(N-k)} (only while filling a fresh ring: head must be 0). */
void dmi_history_put_window(dmi_history *r, const double *U);
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

/* W += w * H((N-1) h) U^{p-N+1}: with w = (theta - 1) h, it turns the sum of
 * any method (whose last cell has the weight h) into the sum whose last cell
 * has the weight theta h (dmi_create_h). */
void dmi_delay_last(const dmi_kernel *k, const dmi_history *r, double w, double *W);

#endif
