/*
 * The history ring and the delay sum W^p of libdmi.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "delay.h"

#include "bytes.h"

#include <stdlib.h>
#include <string.h>

int dmi_history_alloc(dmi_history *r, size_t n, size_t N)
{
    memset(r, 0, sizeof *r);
    size_t L = N + 1;
    if (L == 0 || dmi_mul_size(n, L, 2 * sizeof(double)) == 0) /* the series and its mirror */
        return -1;
    r->buf = calloc(2 * L * n, sizeof(double));
    if (!r->buf)
        return -1;
    r->n = n;
    r->N = N;
    r->L = L;
    r->head = 0;
    return 0;
}

void dmi_history_release(dmi_history *r)
{
    free(r->buf);
    memset(r, 0, sizeof *r);
}

void dmi_history_put_window(dmi_history *r, const double *U)
{
    const size_t n = r->n, N = r->N, L = r->L;
    for (size_t j = 0; j < n; j++) { /* row k is U^{p-(N-k)}: slot N - k, head 0 */
        double *series = r->buf + j * 2 * L;
        for (size_t k = 0; k <= N; k++) {
            const double x = U[k * n + j];
            series[N - k] = x;
            series[N - k + L] = x;
        }
    }
}

void dmi_history_push(dmi_history *r, const double *u)
{
    r->head = r->head == 0 ? r->L - 1 : r->head - 1;
    dmi_history_write_slot(r, r->head, u);
}

int dmi_kernel_alloc(dmi_kernel *k, size_t n, size_t N, const double *dense)
{
    memset(k, 0, sizeof *k);
    k->n = n;
    k->N = N;
    if (!dense)
        return 0;
    const size_t nn = n * n;
    size_t nnz = 0;
    for (size_t e = 0; e < nn; e++)
        for (size_t l = 0; l < N; l++)
            if (dense[l * nn + e] != 0) {
                nnz++;
                break;
            }
    if (nnz == 0)
        return 0;
    k->row = malloc(nnz * sizeof *k->row);
    k->col = malloc(nnz * sizeof *k->col);
    k->samples = malloc(nnz * N * sizeof *k->samples); /* nnz * N <= N * n * n: no overflow */
    if (!k->row || !k->col || !k->samples) {
        dmi_kernel_release(k);
        return -1;
    }
    size_t q = 0;
    for (size_t e = 0; e < nn; e++) {
        int nonzero = 0;
        for (size_t l = 0; l < N && !nonzero; l++)
            nonzero = dense[l * nn + e] != 0;
        if (!nonzero)
            continue;
        k->row[q] = e / n;
        k->col[q] = e % n;
        for (size_t l = 0; l < N; l++)
            k->samples[q * N + l] = dense[l * nn + e];
        q++;
    }
    k->nnz = nnz;
    return 0;
}

void dmi_kernel_release(dmi_kernel *k)
{
    free(k->row);
    free(k->col);
    free(k->samples);
    memset(k, 0, sizeof *k);
}

double dmi_dot(const double *a, const double *b, size_t len)
{
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    size_t l = 0;
    for (; l + 4 <= len; l += 4) {
        s0 += a[l] * b[l];
        s1 += a[l + 1] * b[l + 1];
        s2 += a[l + 2] * b[l + 2];
        s3 += a[l + 3] * b[l + 3];
    }
    for (; l < len; l++)
        s0 += a[l] * b[l];
    return (s0 + s1) + (s2 + s3);
}

void dmi_delay_sum(const dmi_kernel *k, const dmi_history *r, double h, double *W)
{
    size_t e = 0; /* the entries of a row are contiguous (dmi_kernel_alloc) */
    for (size_t row = 0; row < r->n; row++) {
        double w = 0;
        for (; e < k->nnz && k->row[e] == row; e++)
            w += dmi_dot(k->samples + e * k->N, dmi_history_series(r, k->col[e]), k->N);
        W[row] = w * h;
    }
}

void dmi_delay_last(const dmi_kernel *k, const dmi_history *r, double w, double *W)
{
    const size_t last = k->N - 1;
    for (size_t e = 0; e < k->nnz; e++)
        W[k->row[e]] += w * (k->samples[e * k->N + last] * dmi_history_series(r, k->col[e])[last]);
}
