/*
 * Example 4.3 of the paper: the friction oscillator (4.1) with
 * H(s) = cos 2 pi s + cos 10 pi s + cos 20 pi s, g(t) = 1.3 cos 8t, z = 0,
 * b = alpha = tau = 1, to T = 30.  Checked against a straightforward
 * computation written here (the errata's scalar update, plain arrays, no
 * libdmi) and against ../shared/reference/ex43_N9991.csv; the motion must
 * alternate between static phases (v exactly 0 over an interval) and dynamic
 * ones.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core_test.h"

static const double T_END = 30;

/* Trajectory (w, v)(t_p), p = 0..M. */
typedef struct {
    size_t N, M;
    double *w, *v;
} trajectory;

static void trajectory_free(trajectory *tr)
{
    free(tr->w);
    free(tr->v);
    tr->w = tr->v = NULL;
}

static int trajectory_alloc(trajectory *tr, size_t N)
{
    tr->N = N;
    tr->M = (size_t)llround(T_END * (double)N);
    tr->w = calloc(tr->M + 1, sizeof(double));
    tr->v = calloc(tr->M + 1, sizeof(double));
    if (tr->w && tr->v)
        return 0;
    trajectory_free(tr);
    return -1;
}

/* (4.11), written again from the paper so that examples/paper.c is checked too. */
static double H43(double s)
{
    const double pi = 3.14159265358979323846;
    return cos(2 * pi * s) + cos(10 * pi * s) + cos(20 * pi * s);
}

static double g43(double t)
{
    return 1.3 * cos(8 * t);
}

/*
 * The errata's oscillator update with h = 1/N:
 *   W^p = h sum_{l=0}^{N-1} H(l h) u^{p-l},   u^{p+1} = u^p + h v^p,
 *   v^{p+1} = (I + h sigma)^{-1}(v^p - h (u^p + g(t_p)) - h W^p),
 * (I + lambda sigma)^{-1}(x) = sign(x) max(|x| - lambda, 0), u = v = 0 on [-1, 0].
 */
static int independent_ex43(size_t N, trajectory *tr)
{
    if (trajectory_alloc(tr, N) != 0)
        return -1;
    const double h = 1.0 / (double)N;
    const size_t M = tr->M;
    double *Hs = malloc(N * sizeof *Hs);
    double *u = calloc(N + M + 1, sizeof *u); /* u[N + p] = u^p, p = -N..M */
    if (!Hs || !u) {
        free(Hs);
        free(u);
        trajectory_free(tr);
        return -1;
    }
    for (size_t l = 0; l < N; l++)
        Hs[l] = H43((double)l * h);
    double v = 0;
    for (size_t p = 0;; p++) {
        tr->w[p] = u[N + p];
        tr->v[p] = v;
        if (p == M)
            break;
        double sum = 0;
        for (size_t l = 0; l < N; l++)
            sum += Hs[l] * u[N + p - l];
        double W = h * sum, t = (double)p * h;
        double x = v - h * (u[N + p] + g43(t)) - h * W;
        u[N + p + 1] = u[N + p] + h * v;
        v = fabs(x) > h ? copysign(fabs(x) - h, x) : 0.0;
    }
    free(Hs);
    free(u);
    return 0;
}

/* The same with libdmi, the model of examples/paper.c and the given method
 * of the delay sum. */
static int dmi_ex43(size_t N, int method, trajectory *tr)
{
    if (trajectory_alloc(tr, N) != 0)
        return DMI_ENOMEM;
    paper_example ex = {43};
    dmi_solver *s = core_paper_solver(&ex, N);
    double u[2];
    int rc = s ? dmi_set_convolution(s, method) : DMI_ENOMEM;
    for (size_t p = 0; rc == DMI_OK && p <= tr->M; p++) {
        if (p > 0)
            rc = dmi_step(s);
        if (rc == DMI_OK)
            rc = dmi_get_state(s, u);
        if (rc == DMI_OK && dmi_time(s) != (double)p * (1.0 / (double)N))
            rc = DMI_EINVAL;
        tr->w[p] = u[0];
        tr->v[p] = u[1];
    }
    dmi_free(&s);
    if (rc != DMI_OK)
        trajectory_free(tr);
    return rc;
}

/* A static phase: a maximal run p = first..last (last > first, p >= 1) with v == 0 exactly. */
typedef struct {
    size_t first, last;
} phase;

/* Finds the static phases of tr (at most cap); returns their number. */
static size_t static_phases(const trajectory *tr, phase *ph, size_t cap)
{
    size_t count = 0;
    for (size_t p = 1; p <= tr->M;) {
        size_t q = p;
        while (q <= tr->M && tr->v[q] == 0.0)
            q++;
        if (q - p >= 2) {
            if (count < cap)
                ph[count] = (phase){p, q - 1};
            count++;
        }
        p = q > p ? q : p + 1;
    }
    return count;
}

enum { MAX_PHASES = 1000 };

/*
 * The phase structure of a run: at least two static phases; during each, w
 * stays exactly constant (v = 0 gives u^{p+1} = u^p); between the start and
 * the first static phase, between two static phases and after the last one
 * the oscillator really moves (max |v| > 1e-3).  Returns the number of
 * static phases.
 */
static size_t check_phases(const trajectory *tr, phase *ph)
{
    size_t count = static_phases(tr, ph, MAX_PHASES);
    CU_ASSERT(count >= 2 && count <= MAX_PHASES);
    if (count > MAX_PHASES)
        count = MAX_PHASES;
    size_t dynamic = 0, from = 1;
    for (size_t k = 0; k <= count; k++) {
        size_t to = k < count ? ph[k].first : tr->M + 1; /* dynamic stretch p = from..to-1 */
        double vmax = 0;
        for (size_t p = from; p < to; p++)
            vmax = fmax(vmax, fabs(tr->v[p]));
        if (to > from) {
            CU_ASSERT(vmax > 1e-3);
            dynamic++;
        }
        if (k < count) {
            int constant = 1;
            for (size_t p = ph[k].first; p <= ph[k].last; p++)
                constant &= tr->w[p] == tr->w[ph[k].first];
            CU_ASSERT(constant);
            from = ph[k].last + 1;
        }
    }
    /* alternation: a dynamic phase before each static one (the first one too) */
    CU_ASSERT(dynamic >= count);
    CU_ASSERT(count == 0 || ph[0].first > 1);
    printf("\n  h = 1/%zu: %zu static and %zu dynamic phases on [0, %g]", tr->N, count, dynamic,
           T_END);
    return count;
}

/* libdmi (each method of the delay sum) against the straightforward
 * computation at N = 1000. */
static void test_against_independent(void)
{
    const size_t N = 1000;
    const int methods[] = {DMI_CONV_AUTO, DMI_CONV_DIRECT, DMI_CONV_FFT};
    trajectory b = {0};
    CU_ASSERT_FATAL(independent_ex43(N, &b) == 0);
    static phase pa[MAX_PHASES], pb[MAX_PHASES];
    size_t nb = check_phases(&b, pb);
    for (int m = 0; m < 3; m++) {
        trajectory a = {0};
        if (dmi_ex43(N, methods[m], &a) != DMI_OK) {
            trajectory_free(&b);
            CU_FAIL_FATAL("libdmi run of Example 4.3 failed");
        }
        double dw = 0, dv = 0, scale = 0;
        for (size_t p = 0; p <= a.M; p++) {
            dw = fmax(dw, fabs(a.w[p] - b.w[p]));
            dv = fmax(dv, fabs(a.v[p] - b.v[p]));
            scale = fmax(scale, fmax(fabs(b.w[p]), fabs(b.v[p])));
        }
        printf("\n  N = 1000, method %d: max |w - w_indep| = %.3e, max |v - v_indep| = %.3e "
               "(max |u| = %.3f)",
               methods[m], dw, dv, scale);
        CU_ASSERT(dw <= 1e-12);
        CU_ASSERT(dv <= 1e-12);
        CU_ASSERT(scale > 0.01); /* the comparison is not of two zero solutions */
        size_t na = check_phases(&a, pa);
        CU_ASSERT_EQUAL(na, nb);
        int same = na == nb;
        for (size_t k = 0; same && k < na && k < MAX_PHASES; k++)
            same = pa[k].first == pb[k].first && pa[k].last == pb[k].last;
        CU_ASSERT(same);
        trajectory_free(&a);
    }
    printf("\n");
    trajectory_free(&b);
}

/* libdmi at h = 1/9991 against the reference (every 100th step: p, t, w, v). */
static void test_against_reference(void)
{
    const size_t N = 9991;
    const double tol = 1e-11;
    size_t rows;
    double *ref = core_read_csv("ex43_N9991.csv", 4, &rows);
    CU_ASSERT_PTR_NOT_NULL_FATAL(ref);
    trajectory a = {0};
    if (dmi_ex43(N, DMI_CONV_AUTO, &a) != DMI_OK) {
        free(ref);
        CU_FAIL_FATAL("libdmi run of Example 4.3 failed");
    }
    CU_ASSERT(rows >= 2990); /* covers [0, 30] */
    double dw = 0, dv = 0, dt = 0;
    size_t zero_mismatch = 0, bad_rows = 0;
    for (size_t r = 0; r < rows; r++) {
        const double *row = ref + 4 * r;
        if (!(row[0] >= 0 && row[0] <= (double)a.M && row[0] == floor(row[0]))) {
            bad_rows++;
            continue;
        }
        size_t p = (size_t)row[0];
        dt = fmax(dt, fabs((double)p * (1.0 / (double)N) - row[1]));
        dw = fmax(dw, fabs(a.w[p] - row[2]));
        dv = fmax(dv, fabs(a.v[p] - row[3]));
        zero_mismatch += (a.v[p] == 0.0) != (row[3] == 0.0);
    }
    printf("\n  h = 1/9991 vs reference (%zu rows): max |dt| = %.1e, |dw| = %.3e, |dv| = %.3e", rows,
           dt, dw, dv);
    CU_ASSERT_EQUAL(bad_rows, 0);
    CU_ASSERT(dt == 0.0);
    CU_ASSERT(dw <= tol);
    CU_ASSERT(dv <= tol);
    CU_ASSERT_EQUAL(zero_mismatch, 0); /* static at the same sampled instants */

    static phase ph[MAX_PHASES];
    check_phases(&a, ph);
    printf("\n");
    trajectory_free(&a);
    free(ref);
}

int main(int argc, char **argv)
{
    static const core_test tests[] = {
        {"Example 4.3, N = 1000: libdmi (each method) = straightforward computation, phases",
         test_against_independent},
        {"Example 4.3, h = 1/9991, T = 30: reference values and phases", test_against_reference},
        {NULL, NULL}};
    return core_main(argc, argv, "core: paper Example 4.3", tests);
}
