/*
 * White-box tests of the FFT engine (src/conv.c) against a plain triple loop
 * written here: every lag layout for N = 1..300 and some larger N, n = 1..3
 * with full and sparse kernels, stepping and rebuilding at every phase.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <CUnit/CUnit.h>

#include "conv_run.h"
#include "conv.h"

/* Deterministic pseudo-random numbers in [-1, 1) (xorshift64*). */
static double rnd(uint64_t *x)
{
    *x ^= *x >> 12;
    *x ^= *x << 25;
    *x ^= *x >> 27;
    return (double)((*x * UINT64_C(2685821657736338717)) >> 11) / 4503599627370496.0 - 1.0;
}

/* W_i = h sum_l sum_j H_ij(l h) U_j^{p-l}, from the dense samples and the ring. */
static void naive(const double *dense, const dmi_history *r, size_t n, size_t N, double h,
                  double *W, double *scale)
{
    *scale = 0;
    for (size_t i = 0; i < n; i++) {
        double w = 0, a = 0;
        for (size_t l = 0; l < N; l++)
            for (size_t j = 0; j < n; j++) {
                double t = dense[l * n * n + i * n + j] * dmi_history_series(r, j)[l];
                w += t;
                a += fabs(t);
            }
        W[i] = h * w;
        *scale = fmax(*scale, h * a);
    }
}

/*
 * Runs one case: random kernel (entries with mask bit (i*n+j) set are nonzero),
 * random history, `steps` steps with random new states.  Checks at every step
 * that the engine's sum matches the naive sum to 1e-13 of sum |terms|, and at
 * every `every`-th step that an engine rebuilt from the ring gives bitwise the
 * same sum.
 */
static void check_steps(size_t n, size_t N, unsigned mask, size_t steps, size_t every,
                        uint64_t seed)
{
    const size_t nn = n * n;
    const double h = 1.0 / (double)N;
    double *dense = calloc(N * nn, sizeof *dense), *u = malloc(n * sizeof *u);
    double W[3], Wn[3], Wr[3], scale;
    CU_ASSERT_FATAL(dense && u);
    for (size_t l = 0; l < N; l++)
        for (size_t e = 0; e < nn; e++)
            if (mask >> e & 1u)
                dense[l * nn + e] = rnd(&seed);
    dmi_kernel k;
    dmi_history r;
    CU_ASSERT_FATAL(dmi_kernel_alloc(&k, n, N, dense) == 0);
    CU_ASSERT_FATAL(dmi_history_alloc(&r, n, N) == 0);
    for (size_t lag = 0; lag <= N; lag++) {
        for (size_t j = 0; j < n; j++)
            u[j] = rnd(&seed);
        dmi_history_put(&r, lag, u);
    }
    dmi_conv *c = NULL, *c2 = NULL;
    CU_ASSERT_FATAL(dmi_conv_create(&c, &k, n, N, DMI_CONV_FFT) == 0 && c);
    CU_ASSERT_FATAL(dmi_conv_create(&c2, &k, n, N, DMI_CONV_FFT) == 0 && c2);
    CU_ASSERT(dmi_conv_rank(c) == 0); /* random samples: no low-rank form */
    dmi_conv_rebuild(c, &k, &r, 0);
    int bad = 0, diff = 0;
    for (uint64_t p = 0; p <= steps && !bad && !diff; p++) {
        if (p > 0) {
            for (size_t j = 0; j < n; j++)
                u[j] = rnd(&seed);
            dmi_history_push(&r, u);
            dmi_conv_advance(c, &k, &r, p);
        }
        dmi_conv_sum(c, &k, &r, p, h, W);
        naive(dense, &r, n, N, h, Wn, &scale);
        for (size_t i = 0; i < n; i++)
            if (!(fabs(W[i] - Wn[i]) <= 1e-13 * scale + 1e-300))
                bad = 1;
        if (p % every == 0) {
            dmi_conv_rebuild(c2, &k, &r, p);
            dmi_conv_sum(c2, &k, &r, p, h, Wr);
            diff = memcmp(W, Wr, n * sizeof *W) != 0;
        }
        if (bad || diff) /* the first component, which may not be the one that differs */
            fprintf(stderr, "\n  n = %zu, N = %zu, mask %x, p = %llu: W %.17g", n, N, mask,
                    (unsigned long long)p, W[0]);
        if (bad)
            fprintf(stderr, " naive %.17g", Wn[0]);
        if (diff) /* set only at a step with a rebuild, so Wr is this step's */
            fprintf(stderr, " rebuilt %.17g", Wr[0]);
    }
    CU_ASSERT(!bad);
    CU_ASSERT(!diff);
    dmi_conv_free(c);
    dmi_conv_free(c2);
    dmi_kernel_release(&k);
    dmi_history_release(&r);
    free(dense);
    free(u);
}

static void check_case(size_t n, size_t N, unsigned mask, size_t steps, uint64_t seed)
{
    check_steps(n, N, mask, steps, 1, seed);
}

/* Every N up to 300 (every layout the planner makes there), scalar kernel. */
static void test_small_N(void)
{
    for (size_t N = 1; N <= 300; N++)
        check_case(1, N, 1u, N < 40 ? 2 * N + 3 : 70, 1000 + N);
}

/* Several block sizes in one layout, stepping over more than a block of each. */
static void test_large_N(void)
{
    static const size_t Ns[] = {1024, 2047, 3001, 8192};
    for (size_t t = 0; t < sizeof Ns / sizeof *Ns; t++)
        check_case(1, Ns[t], 1u, 600, 7 + t);
}

/* The benchmark's N = 100000 (block sizes 32, 256 and 2048 when this was
 * written), stepped past the end of the first block of 2048; rebuilt every
 * 100 steps (a rebuild transforms every window of every size). */
static void test_largest_blocks(void)
{
    check_steps(1, 100000, 1u, 2100, 100, 21);
}

/* n = 2 with the oscillator's pattern (one nonzero entry of four) and n = 3 with
 * a full kernel and with sparse ones (all columns used; a single column). */
static void test_matrix_kernels(void)
{
    check_case(2, 700, 1u << 2, 300, 11);
    check_case(3, 333, 0x1ffu, 200, 12);
    check_case(3, 1000, (1u << 1) | (1u << 5) | (1u << 6), 300, 13);
    check_case(3, 600, (1u << 1) | (1u << 4), 300, 14); /* one column, two rows */
}

/* A kernel that is zero everywhere: the engine holds no FFT level at all. */
static void test_zero_kernel(void)
{
    dmi_kernel k;
    CU_ASSERT_FATAL(dmi_kernel_alloc(&k, 2, 500, NULL) == 0);
    dmi_conv *c = NULL;
    CU_ASSERT_FATAL(dmi_conv_create(&c, &k, 2, 500, DMI_CONV_FFT) == 0 && c);
    CU_ASSERT(dmi_conv_levels(c) == 0);
    dmi_conv_free(c);
    CU_ASSERT(dmi_conv_create(&c, &k, 2, 500, DMI_CONV_AUTO) == 0 && c == NULL);
    dmi_kernel_release(&k);
}

/* The planner: FFT levels exist for N >= 1000 when forced, AUTO takes the
 * direct sum for tiny N and the engine for large N, DIRECT never an engine. */
static void test_planner(void)
{
    const size_t Ns[] = {4, 1000, 100000};
    for (size_t t = 0; t < 3; t++) {
        size_t N = Ns[t];
        double *dense = calloc(N * 4, sizeof *dense);
        CU_ASSERT_FATAL(dense != NULL);
        for (size_t l = 0; l < N; l++)
            dense[l * 4 + 2] = 1.0;
        dmi_kernel k;
        CU_ASSERT_FATAL(dmi_kernel_alloc(&k, 2, N, dense) == 0);
        dmi_conv *c = NULL;
        CU_ASSERT(dmi_conv_create(&c, &k, 2, N, DMI_CONV_DIRECT) == 0 && c == NULL);
        CU_ASSERT(dmi_conv_create(&c, &k, 2, N, DMI_CONV_AUTO) == 0);
        CU_ASSERT((c != NULL) == (N >= 1000));
        dmi_conv_free(c);
        CU_ASSERT(dmi_conv_create(&c, &k, 2, N, DMI_CONV_FFT) == 0 && c != NULL);
        CU_ASSERT((dmi_conv_levels(c) > 0) == (N >= 1000));
        dmi_conv_free(c);
        dmi_kernel_release(&k);
        free(dense);
    }
}

int main(void)
{
    static CU_TestInfo tests[] = {
        {"every N up to 300", test_small_N},
        {"large N, several block sizes", test_large_N},
        {"N = 100000, the largest blocks", test_largest_blocks},
        {"matrix kernels n = 2, 3", test_matrix_kernels},
        {"zero kernel", test_zero_kernel},
        {"planner", test_planner},
        CU_TEST_INFO_NULL,
    };
    return conv_run("conv_engine", tests);
}
