/*
 * White-box tests of the engines on matrix kernels: the FFT
 * engine (with its low-rank form) and the recursion against the direct sum,
 * at every step of 10^5 steps with random states, on diagonal, banded and
 * dense blocks for n up to 64; the sparse sampling of exponential kernels
 * against the dense one.
 * The kernel is [[0, 0], [C(s), 0]] (n = 2m) with C(s) = sum_k e^{a_k s}
 * cos(b_k s) c_k B_k; one B for every term gives a kernel of rank 1 over the
 * samples, a second B a kernel of rank 2, a random B per term no low rank.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <CUnit/CUnit.h>

#include "conv.h"
#include "conv_run.h"
#include "exp.h"

enum { DIAG, BAND, DENSE };
enum { SAME_B, TWO_B, RANDOM_B };

/* Deterministic pseudo-random numbers in [-1, 1) (xorshift64*). */
static double rnd(uint64_t *x)
{
    *x ^= *x >> 12;
    *x ^= *x << 25;
    *x ^= *x >> 27;
    return (double)((*x * UINT64_C(2685821657736338717)) >> 11) / 4503599627370496.0 - 1.0;
}

static double b_entry(int shape, size_t i, size_t j)
{
    size_t d = i > j ? i - j : j - i;
    if (shape == DIAG)
        return d == 0 ? 1.0 : 0.0;
    if (shape == BAND)
        return d == 0 ? 1.0 : d <= 2 ? 0.4 / (double)d : 0.0;
    return pow(0.9, (double)d);
}

/* The exponential kernel of the case: three terms (a decaying one, a slower
 * one, a damped oscillation). */
static int make_kernel(dmi_expk *k, size_t m, int shape, int kind, uint64_t *seed)
{
    const size_t n = 2 * m, nn = n * n;
    const double a[3] = {-1.0, -3.0, -0.5}, b[3] = {0.0, 0.0, 7.0}, coef[3] = {0.5, 0.3, 0.2};
    double *C = calloc(3 * nn, sizeof *C);
    if (!C)
        return -1;
    for (size_t t = 0; t < 3; t++)
        for (size_t i = 0; i < m; i++)
            for (size_t j = 0; j < m; j++) {
                double B = b_entry(shape, i, j);
                if (kind == TWO_B && t == 1)
                    B = b_entry(shape, i, m - 1 - j) * 0.7 + B * 0.1;
                if (kind == RANDOM_B && B != 0)
                    B = rnd(seed);
                C[t * nn + (m + i) * n + j] = coef[t] * B;
            }
    int rc = dmi_expk_copy(k, n, 3, a, b, C, NULL);
    free(C);
    return rc;
}

/* The FFT engine (its rank in [rank_lo, rank_hi]; 0: none) and the recursion against
 * dmi_delay_sum at every step; a second FFT engine rebuilt every `every`
 * steps gives bitwise the same sum. */
static void check(size_t m, size_t N, int shape, int kind, size_t steps, size_t every,
                  size_t rank_lo, size_t rank_hi)
{
    const size_t n = 2 * m;
    const double h = 1.0 / (double)N;
    uint64_t seed = 0x9e3779b97f4a7c15u + m * 131 + N * 7 + (uint64_t)shape * 3 + (uint64_t)kind;
    dmi_expk x;
    dmi_kernel k;
    dmi_history r;
    CU_ASSERT_FATAL(make_kernel(&x, m, shape, kind, &seed) == 0);
    CU_ASSERT_FATAL(dmi_expk_sample(&x, N, h, &k) == 0);
    CU_ASSERT_FATAL(dmi_history_alloc(&r, n, N) == 0);
    double *u = malloc(n * sizeof *u), *W = malloc(4 * n * sizeof *W);
    CU_ASSERT_FATAL(u && W);
    double *Wd = W + n, *Wr = W + 2 * n, *We = W + 3 * n;
    for (size_t lag = 0; lag <= N; lag++) {
        for (size_t j = 0; j < n; j++)
            u[j] = rnd(&seed);
        dmi_history_put(&r, lag, u);
    }
    dmi_conv *c = NULL, *c2 = NULL;
    dmi_exp *e = NULL;
    CU_ASSERT_FATAL(dmi_conv_create(&c, &k, n, N, DMI_CONV_FFT) == 0 && c);
    CU_ASSERT_FATAL(dmi_conv_create(&c2, &k, n, N, DMI_CONV_FFT) == 0 && c2);
    CU_ASSERT_FATAL(dmi_exp_create(&e, &x, N, h) == 0);
    CU_ASSERT(dmi_conv_rank(c) >= rank_lo && dmi_conv_rank(c) <= rank_hi);
    CU_ASSERT(dmi_conv_levels(c) > 0);
    dmi_conv_rebuild(c, &k, &r, 0);
    dmi_exp_anchor(e, &r, 0);
    double worst_fft = 0, worst_rec = 0;
    int diff = 0;
    for (uint64_t p = 0; p <= steps && !diff; p++) {
        if (p > 0) {
            for (size_t j = 0; j < n; j++)
                u[j] = rnd(&seed); /* max |U| = 1 */
            dmi_history_push(&r, u);
            dmi_conv_advance(c, &k, &r, p);
            dmi_exp_advance(e, &r, p);
        }
        dmi_conv_sum(c, &k, &r, p, h, W);
        memcpy(We, dmi_exp_sum(e), n * sizeof *We);
        dmi_delay_sum(&k, &r, h, Wd);
        for (size_t i = 0; i < n; i++) {
            worst_fft = fmax(worst_fft, fabs(W[i] - Wd[i]));
            worst_rec = fmax(worst_rec, fabs(We[i] - Wd[i]));
        }
        if (p % every == 0) {
            dmi_conv_rebuild(c2, &k, &r, p);
            dmi_conv_sum(c2, &k, &r, p, h, Wr);
            diff = memcmp(W, Wr, n * sizeof *W) != 0;
        }
    }
    printf("\n  m = %zu, N = %zu, B %d, kind %d, rank %zu: max |W - W_DIRECT| / max |U|: "
           "FFT %.2e, recursion %.2e", m, N, shape, kind, dmi_conv_rank(c), worst_fft,
           worst_rec);
    CU_ASSERT(worst_fft <= 1e-12);
    CU_ASSERT(worst_rec <= 1e-12);
    CU_ASSERT(!diff);
    dmi_conv_free(c);
    dmi_conv_free(c2);
    dmi_exp_free(e);
    dmi_kernel_release(&k);
    dmi_expk_release(&x);
    dmi_history_release(&r);
    free(u);
    free(W);
}

/* n = 64: a short delay (N = 16), so that the direct sum of 10^5 steps
 * stays quick. */
static void test_n64(void)
{
    check(32, 16, DIAG, SAME_B, 100000, 9973, 0, 0); /* nnz = ncols: no low rank */
    check(32, 16, BAND, SAME_B, 100000, 9973, 1, 1); /* rank 1 of 5 entries a column */
    check(32, 16, DENSE, SAME_B, 100000, 9973, 1, 1);
    /* rank 2 in exact arithmetic; the rounding of the samples may ask for a third
     * series where an entry's two parts nearly cancel */
    check(32, 16, DENSE, TWO_B, 100000, 9973, 2, 3);
    check(32, 16, DENSE, RANDOM_B, 100000, 9973, 3, 3); /* three functions of s */
}

/* n = 8: a longer delay (N = 1000, several block sizes). */
static void test_n8(void)
{
    check(4, 1000, DIAG, SAME_B, 100000, 4999, 0, 0);
    check(4, 1000, BAND, SAME_B, 100000, 4999, 1, 1); /* 14 entries, 4 columns */
    check(4, 1000, DENSE, SAME_B, 100000, 4999, 1, 1);
    check(4, 1000, DENSE, TWO_B, 100000, 4999, 2, 3);
}

/* Sampled entry by entry, the kernel is bitwise the one of the dense path
 * (dmi_expk_eval into N n n samples, dmi_kernel_alloc). */
static void test_sampling(void)
{
    for (int shape = DIAG; shape <= DENSE; shape++) {
        uint64_t seed = 7;
        const size_t m = 5, n = 2 * m, N = 300;
        dmi_expk x;
        dmi_kernel a, b;
        CU_ASSERT_FATAL(make_kernel(&x, m, shape, RANDOM_B, &seed) == 0);
        double *dense = calloc(N * n * n, sizeof *dense);
        CU_ASSERT_FATAL(dense != NULL);
        for (size_t l = 0; l < N; l++)
            dmi_expk_eval((double)l * (1.0 / (double)N), dense + l * n * n, &x);
        CU_ASSERT_FATAL(dmi_kernel_alloc(&a, n, N, dense) == 0);
        CU_ASSERT_FATAL(dmi_expk_sample(&x, N, 1.0 / (double)N, &b) == 0);
        CU_ASSERT(a.nnz == b.nnz && a.nnz > 0);
        CU_ASSERT(memcmp(a.row, b.row, a.nnz * sizeof *a.row) == 0);
        CU_ASSERT(memcmp(a.col, b.col, a.nnz * sizeof *a.col) == 0);
        CU_ASSERT(memcmp(a.samples, b.samples, a.nnz * N * sizeof *a.samples) == 0);
        dmi_kernel_release(&a);
        dmi_kernel_release(&b);
        dmi_expk_release(&x);
        free(dense);
    }
}

int main(void)
{
    static CU_TestInfo tests[] = {
        {"n = 64, N = 16: diagonal, banded, dense (rank 1, 2, none), 10^5 steps", test_n64},
        {"n = 8, N = 1000: diagonal, banded, dense (rank 1, 2), 10^5 steps", test_n8},
        {"exponential kernel sampled entry by entry = the dense path, bitwise", test_sampling},
        CU_TEST_INFO_NULL};
    return conv_run("conv: matrix kernels, FFT (low rank) and recursion vs DIRECT", tests);
}
