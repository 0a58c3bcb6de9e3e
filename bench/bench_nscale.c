/*
 * Benchmark of the delay term's cost as the system grows (not a
 * test).  A chain of m masses, n = 2m states u = (x_1..x_m, v_1..v_m):
 *     x' = v,   v' = -K x - int_0^tau G(s) B x(t - s) ds - alpha sign(v)
 * with K tridiagonal (2k on the diagonal, -k beside it), dry friction alpha
 * on every velocity (dmi_set_friction), tau = 1, h = 1/N, and the memory
 * kernel H(s) = [[0, 0], [G(s) B, 0]], G(s) = 0.5 e^{-s} + 0.3 e^{-3s} given
 * as two exponential terms (dmi_set_kernel_exp, C_k = c_k [[0, 0], [B, 0]]).
 * B is diagonal (1), tridiagonal (1, and 0.4 beside the diagonal) or dense
 * (0.9^|i-j|, every entry nonzero).  For m = 1, 4, 16, 64, 128 and N = 10^3,
 * 10^4 it times the methods AUTO, DIRECT, FFT and RECURSIVE beside the same
 * model without the kernel, and a plain loop of N nnz multiply-adds over
 * arrays of the kernel's size (the floor of DIRECT, compiled with the same
 * flags).  Each round steps every method for about `ms` milliseconds of wall
 * time, one after the other (interleaved, so the machine's drift hits them
 * alike); the fastest round counts.  AUTO's pick is identified by its first
 * steps' delay terms, which equal bitwise those of the method it runs; the
 * same for the kernel given as a callback (dmi_set_kernel), where AUTO
 * chooses between DIRECT and FFT by its cost model, and whose pick is
 * compared with the faster of the two as timed with the exponential kernel
 * (the same engines on the same sparsity).
 * Configurations whose kernel samples (N nnz doubles, which every solver
 * with the kernel holds, and the plain loop as much) would exceed `mem` MiB
 * are skipped for DIRECT, FFT and the plain loop (the recursion and AUTO
 * still run, to show the recursion at that size).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dmi.h"
#include "layout.h"

enum { NODELAY, AUTO, DIRECT, FFT, REC, PLAIN, KINDS };
enum { DIAG, TRI, DENSE, SHAPES };

static const char *kind_name[KINDS] = {"no delay", "AUTO", "DIRECT", "FFT", "RECURSIVE",
                                       "plain loop"};
static const char *shape_name[SHAPES] = {"diagonal", "tridiagonal", "dense"};
static const int kind_method[KINDS] = {DMI_CONV_AUTO, DMI_CONV_AUTO, DMI_CONV_DIRECT,
                                       DMI_CONV_FFT, DMI_CONV_RECURSIVE, 0};

typedef struct {
    size_t m;
    double k;  /* stiffness */
    int shape; /* of B */
} chain;

static int chain_rhs(double t, const double *u, double *out, void *user)
{
    (void)t;
    const chain *c = user;
    const size_t m = c->m;
    const double *x = u, *v = u + m;
    for (size_t i = 0; i < m; i++) { /* u' = -f(u): f = (-v, K x) */
        double kx = 2 * c->k * x[i];
        if (i > 0)
            kx -= c->k * x[i - 1];
        if (i + 1 < m)
            kx -= c->k * x[i + 1];
        out[i] = -v[i];
        out[m + i] = kx;
    }
    return 0;
}

static int chain_history(double t, double *u, void *user)
{
    (void)t;
    const chain *c = user;
    for (size_t i = 0; i < c->m; i++)
        u[i] = 0.01 * cos((double)i); /* at rest, displaced */
    return 0;
}

static double b_entry(int shape, size_t i, size_t j)
{
    size_t d = i > j ? i - j : j - i;
    if (shape == DIAG)
        return d == 0 ? 1.0 : 0.0;
    if (shape == TRI)
        return d == 0 ? 1.0 : d == 1 ? 0.4 : 0.0;
    return pow(0.9, (double)d);
}

/* The kernel as a callback: G(s) B in the lower left block. */
static int chain_kernel(double s, double *out, void *user)
{
    const chain *c = user;
    const size_t m = c->m, n = 2 * m;
    const double g = 0.5 * exp(-s) + 0.3 * exp(-3 * s);
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j < m; j++)
            out[(m + i) * n + j] = g * b_entry(c->shape, i, j);
    return 0;
}

/* A solver of the chain for kind (not PLAIN), the kernel as exponential
 * terms, or as a callback if callback; 0 or the error. */
static int make(dmi_solver **s, chain *c, int shape, size_t N, int kind, int callback)
{
    const size_t m = c->m, n = 2 * m;
    int rc = dmi_create(s, n, 1.0, N);
    double *alpha = calloc(n, sizeof *alpha), *C = calloc(2 * n * n, sizeof *C);
    if (!alpha || !C)
        rc = rc == DMI_OK ? DMI_ENOMEM : rc;
    if (rc == DMI_OK)
        rc = dmi_set_rhs(*s, chain_rhs, c);
    if (rc == DMI_OK)
        rc = dmi_set_history(*s, chain_history, c);
    for (size_t i = 0; rc == DMI_OK && i < m; i++)
        alpha[m + i] = 0.05;
    if (rc == DMI_OK)
        rc = dmi_set_friction(*s, alpha);
    if (rc == DMI_OK && kind != NODELAY) {
        const double a[2] = {-1.0, -3.0}, b[2] = {0.0, 0.0}, coef[2] = {0.5, 0.3};
        for (size_t t = 0; t < 2; t++)
            for (size_t i = 0; i < m; i++)
                for (size_t j = 0; j < m; j++)
                    C[t * n * n + (m + i) * n + j] = coef[t] * b_entry(shape, i, j);
        rc = callback ? dmi_set_kernel(*s, chain_kernel, c)
                      : dmi_set_kernel_exp(*s, 2, a, b, C, NULL);
        if (rc == DMI_OK)
            rc = dmi_set_convolution(*s, kind_method[kind]);
    }
    if (rc == DMI_OK)
        rc = dmi_init(*s);
    free(alpha);
    free(C);
    return rc;
}

/* The plain loop: w_row += sum_{l<N} a_e[l] u_col[l] over the nnz entries. */
typedef struct {
    size_t n, N, nnz, *row, *col;
    double *a, *u, *w;
} plain;

static int plain_make(plain *p, size_t m, int shape, size_t N)
{
    memset(p, 0, sizeof *p);
    p->n = 2 * m;
    p->N = N;
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j < m; j++)
            p->nnz += b_entry(shape, i, j) != 0;
    p->row = malloc(p->nnz * sizeof *p->row);
    p->col = malloc(p->nnz * sizeof *p->col);
    p->a = malloc(p->nnz * N * sizeof *p->a);
    p->u = malloc(p->n * N * sizeof *p->u);
    p->w = calloc(p->n, sizeof *p->w);
    if (!p->row || !p->col || !p->a || !p->u || !p->w)
        return DMI_ENOMEM;
    size_t e = 0;
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j < m; j++)
            if (b_entry(shape, i, j) != 0) {
                p->row[e] = m + i;
                p->col[e] = j;
                for (size_t l = 0; l < N; l++)
                    p->a[e * N + l] = b_entry(shape, i, j) * exp(-(double)l / (double)N);
                e++;
            }
    for (size_t q = 0; q < p->n * N; q++)
        p->u[q] = cos((double)q);
    return DMI_OK;
}

static void plain_step(plain *p)
{
    for (size_t e = 0; e < p->nnz; e++) {
        const double *a = p->a + e * p->N, *u = p->u + p->col[e] * p->N;
        double s = 0;
        for (size_t l = 0; l < p->N; l++)
            s += a[l] * u[l];
        p->w[p->row[e]] += s;
    }
}

static void plain_free(plain *p)
{
    free(p->row);
    free(p->col);
    free(p->a);
    free(p->u);
    free(p->w);
}

/* Steps (or plain passes) for about ms milliseconds; *ns = ns per step. */
static int timed(dmi_solver *s, plain *p, double ms, size_t *steps, double *ns)
{
    double t0 = now(), t = t0;
    size_t done = 0;
    while (done < *steps || (t - t0) * 1e3 < 0.2 * ms) {
        if (s) {
            int rc = dmi_step(s);
            if (rc != DMI_OK)
                return rc;
        } else {
            plain_step(p);
        }
        done++;
        if ((done & 7) == 0 || done >= *steps)
            t = now();
    }
    t = now();
    *ns = 1e9 * (t - t0) / (double)done;
    /* the next round's count: about ms milliseconds */
    double want = ms * 1e6 / *ns;
    *steps = want < 1 ? 1 : (size_t)want;
    return DMI_OK;
}

/* W of the first two steps of a fresh solver of kind (2 n values). */
static int first_terms(chain *c, int shape, size_t N, int kind, int callback, double *W)
{
    dmi_solver *s = NULL;
    int rc = make(&s, c, shape, N, kind, callback);
    for (int k = 0; k < 2 && rc == DMI_OK; k++) {
        rc = dmi_step(s);
        if (rc == DMI_OK)
            rc = dmi_get_step_terms(s, W + (size_t)k * 2 * c->m, NULL);
    }
    dmi_free(&s);
    return rc;
}

/* Which method AUTO runs: the one whose first delay terms equal AUTO's
 * (with the kernel as a callback: DIRECT or FFT). */
static int auto_pick(chain *c, int shape, size_t N, int callback, int *pick)
{
    const size_t len = 4 * c->m;
    double *w = malloc(2 * len * sizeof *w);
    if (!w)
        return DMI_ENOMEM;
    int rc = first_terms(c, shape, N, AUTO, callback, w);
    *pick = -1;
    for (int k = DIRECT; k <= (callback ? FFT : REC) && rc == DMI_OK; k++) {
        rc = first_terms(c, shape, N, k, callback, w + len);
        if (rc == DMI_OK && memcmp(w, w + len, len * sizeof *w) == 0)
            *pick = k;
    }
    free(w);
    return rc;
}

int main(int argc, char **argv)
{
    size_t rounds = 7, mem = 1024, mmax = 128;
    double ms = 30;
    const cli_arg args[] = {
        {"rounds", CLI_COUNT, &rounds, 1000, "interleaved rounds; the fastest counts"},
        {"ms", CLI_TIME, &ms, 1e5, "wall time of one method in one round, milliseconds"},
        {"mem", CLI_COUNT, &mem, 1e6,
         "MiB: skip DIRECT, FFT and the plain loop where N nnz doubles of samples exceed it"},
        {"mmax", CLI_COUNT, &mmax, 128, "the largest chain (m = 1, 4, 16, 64, 128 up to it)"}};
    const cli_program prog = {
        "bench_nscale",
        "Times a chain of m masses (n = 2m states, friction on every velocity, tridiagonal\n"
        "stiffness) with the memory kernel [[0, 0], [G(s) B, 0]], G two exponential terms,\n"
        "B diagonal, tridiagonal or dense, at m = 1, 4, 16, 64, 128 and N = 1e3, 1e4: the\n"
        "methods AUTO, DIRECT, FFT and RECURSIVE beside the model without the kernel and\n"
        "a plain loop of N nnz multiply-adds, in interleaved rounds, and AUTO's pick for\n"
        "the kernel given as a callback (a few minutes).",
        "stdout: one line per configuration as it is measured, then the table in Markdown\n"
        "(ns per step, AUTO's pick, ratios).\n"
        "exit status: 0, 1 if a solver fails, 2 for a bad argument.",
        args, 4};
    cli_parse(&prog, argc, argv);
    fresh_allocator(); /* every configuration allocates as a fresh process does */

    static const size_t ms_list[5] = {1, 4, 16, 64, 128}, Ns[2] = {1000, 10000};
    char table[128][320];
    size_t rows = 0;
    double worst_auto = 0, worst_cb = 0;
    printf("chain of m masses, tau = 1, h = 1/N; %zu interleaved rounds of %g ms per method\n",
           rounds, ms);
    for (int mi = 0; mi < 5 && ms_list[mi] <= mmax; mi++)
        for (int shape = 0; shape < SHAPES; shape++)
            for (int ni = 0; ni < 2; ni++) {
                const size_t m = ms_list[mi], n = 2 * m, N = Ns[ni];
                chain c = {m, 10.0, shape};
                if (shape != DIAG && m == 1)
                    continue; /* the same as diagonal */
                size_t nnz = 0;
                for (size_t i = 0; i < m; i++)
                    for (size_t j = 0; j < m; j++)
                        nnz += b_entry(shape, i, j) != 0;
                const double MiB = (double)mem * 1048576.0;
                const int sampled = (double)N * (double)nnz * 8.0 <= MiB;
                /* a callback kernel is sampled through an N n n array */
                const int cb = (double)N * (double)n * (double)n * 8.0 <= MiB;
                dmi_solver *s[KINDS] = {NULL};
                plain p;
                memset(&p, 0, sizeof p);
                int rc = sampled ? plain_make(&p, m, shape, N) : DMI_OK;
                for (int k = 0; k < PLAIN && rc == DMI_OK; k++)
                    if (sampled || k == NODELAY || k == REC || k == AUTO)
                        rc = make(&s[k], &c, shape, N, k, 0);
                int pick = -1, cb_pick = -1;
                if (rc == DMI_OK && sampled)
                    rc = auto_pick(&c, shape, N, 0, &pick);
                if (rc == DMI_OK && sampled && cb)
                    rc = auto_pick(&c, shape, N, 1, &cb_pick);
                double best[KINDS];
                size_t steps[KINDS];
                for (int k = 0; k < KINDS; k++) {
                    best[k] = INFINITY;
                    steps[k] = 1;
                }
                for (size_t r = 0; r <= rounds && rc == DMI_OK; r++) /* round 0: warm-up */
                    for (int k = 0; k < KINDS && rc == DMI_OK; k++) {
                        if ((k != PLAIN && !s[k]) || (k == PLAIN && !sampled))
                            continue;
                        double ns = INFINITY;
                        rc = timed(k == PLAIN ? NULL : s[k], &p, ms, &steps[k], &ns);
                        if (r > 0)
                            best[k] = fmin(best[k], ns);
                    }
                for (int k = 0; k < PLAIN; k++)
                    dmi_free(&s[k]);
                plain_free(&p);
                if (rc != DMI_OK) {
                    fprintf(stderr, "bench_nscale: m = %zu, %s, N = %zu: %s\n", m,
                            shape_name[shape], N, dmi_strerror(rc));
                    return 1;
                }
                int fastest = REC; /* of the methods AUTO chooses from */
                for (int k = DIRECT; k <= FFT; k++)
                    if (best[k] < best[fastest])
                        fastest = k;
                const double auto_ratio = best[AUTO] / best[fastest];
                worst_auto = fmax(worst_auto, auto_ratio);
                /* the callback: AUTO's pick among DIRECT and FFT, timed as they ran above */
                const int cb_fast = best[DIRECT] < best[FFT] ? DIRECT : FFT;
                const double cb_ratio = cb_pick < 0 ? NAN : best[cb_pick] / best[cb_fast];
                if (cb_pick >= 0)
                    worst_cb = fmax(worst_cb, cb_ratio);
                char cell[KINDS][24], ratio[5][24];
                for (int k = 0; k < KINDS; k++) {
                    if (isinf(best[k]))
                        snprintf(cell[k], sizeof cell[k], "skipped");
                    else
                        snprintf(cell[k], sizeof cell[k], "%.4g", best[k]);
                }
                const double q[5] = {auto_ratio, best[REC] / best[NODELAY], best[FFT] / best[REC],
                                     best[DIRECT] / best[PLAIN], cb_ratio};
                for (int k = 0; k < 5; k++)
                    snprintf(ratio[k], sizeof ratio[k], isnan(q[k]) || isinf(q[k]) ? "-" : "%.2f",
                             q[k]);
                snprintf(table[rows], sizeof table[rows],
                         "| %zu | %zu | %s | %zu | %s | %s | %s | %s | %s | %s | %s | %s | %s | "
                         "%s | %s | %s | %s |",
                         m, n, shape_name[shape], N, cell[NODELAY], cell[DIRECT], cell[FFT],
                         cell[REC], cell[AUTO], pick < 0 ? "-" : kind_name[pick],
                         kind_name[fastest], ratio[0], ratio[1], ratio[2], ratio[3],
                         cb_pick < 0 ? "-" : kind_name[cb_pick], ratio[4]);
                printf("%s\n", table[rows]);
                fflush(stdout);
                rows++;
            }
    printf("\nns per step, fastest of %zu interleaved rounds of %g ms (wall time); AUTO / fastest "
           "at most %.2f;\ncallback kernel: AUTO's pick / the faster of DIRECT and FFT at most "
           "%.2f\n\n", rounds, ms, worst_auto, worst_cb);
    printf("| m | n | B | N | no delay | DIRECT | FFT | RECURSIVE | AUTO | AUTO's pick | fastest "
           "| AUTO / fastest | REC / no delay | FFT / REC | DIRECT / plain loop "
           "| callback: AUTO's pick | callback: pick / faster |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (size_t r = 0; r < rows; r++)
        printf("%s\n", table[r]);
    return 0;
}
