/*
 * The exact cell rule of the delay sum (dmi_set_quadrature, DMI_QUAD_CELL):
 * each cell's weight is the integral of H over the cell instead of h H(l h).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Every engine sums h * samples[l] U^{p-l} (l < N) and then adds a last-cell
 * change; so the cell rule stores as samples the cells' means,
 *     samples[l] = (1/h) int_{l h}^{(l+1) h} H,
 * and as the change per kernel entry, last[e], what turns the last full
 * cell's h samples[N-1] into the integral over the partial last cell
 * [(N-1) h, tau] (0 when theta = 1).
 *
 * Exponential kernels in closed form: per term mu = a + i b, G = C - i D,
 *     int_{l h}^{(l+1) h} Re(G e^{mu s}) ds = h Re(G phi1(mu h) e^{mu l h}),
 * phi1(z) = (e^z - 1) / z: the cells' means are the samples of the
 * exponential kernel with the same (a, b) and C' - i D' = G phi1(mu h)
 * (dmi_quad_expk), which the recursion then runs as it is.  The partial last
 * cell is theta h Re(G phi1(mu theta h) e^{mu (N-1) h}).
 *
 * Callback kernels by tanh-sinh quadrature (the double-exponential rule of
 * Takahasi and Mori), written from its formulas: on [lo, hi], c = (lo + hi)/2,
 * d = (hi - lo)/2, u(t) = (pi/2) sinh t,
 *     int f = d sum_j w h f(c + d tanh u(t_j)),  t_j = j w,
 *     weight (pi/2) cosh t / cosh^2 u,
 * the nodes near an end placed by their distance to it, d 2 / (e^{2|u|} + 1),
 * so an integrable singularity at s = 0 (s^-alpha) is never evaluated at and
 * converges as fast as a smooth integrand.  The step w halves (new nodes
 * only) until two levels agree to REL_TOL of the cell's integral of |H|, or
 * MAX_LEVEL is reached.  One rule in every build: libdmi and the GSL-free
 * core inside FMUs give the same weights (GSL's QAGS would report a
 * round-off failure through GSL's error handler, which aborts unless it is
 * turned off process-wide: global state a library must not touch).
 */
#include "quad.h"

#include "bytes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_2 1.57079632679489661923
#define T_MAX 4.0     /* |t| <= T_MAX: the weights beyond are below 1e-36 of the middle's */
#define MAX_LEVEL 9   /* steps 1/2 .. 1/1024: at most 8193 nodes a cell */
#define REL_TOL 1e-14

/* ---- exponential kernels ------------------------------------------------- */

/* phi1(x + i y) = (e^z - 1) / z without cancellation near 0. */
static void phi1(double x, double y, double *re, double *im)
{
    const double r = hypot(x, y);
    if (r < 1e-5) { /* 1 + z/2 + z^2/6 */
        *re = 1 + x / 2 + (x * x - y * y) / 6;
        *im = y / 2 + x * y / 3;
        return;
    }
    const double sy = sin(y / 2);
    const double nr = expm1(x) * cos(y) - 2 * sy * sy, ni = exp(x) * sin(y);
    const double den = x * x + y * y; /* (nr + i ni) / (x + i y) */
    *re = (nr * x + ni * y) / den;
    *im = (ni * x - nr * y) / den;
}

int dmi_quad_expk(const dmi_expk *k, double h, dmi_expk *out)
{
    if (dmi_expk_copy(out, k->n, k->K, k->a, k->b, k->C, k->C) != 0) /* D: room for C' - i D' */
        return -1;
    const size_t nn = k->n * k->n;
    for (size_t t = 0; t < k->K; t++) {
        double pr, pi;
        phi1(k->a[t] * h, k->b[t] * h, &pr, &pi);
        for (size_t q = t * nn; q < (t + 1) * nn; q++) {
            const double C = k->C[q], D = k->D ? k->D[q] : 0.0;
            /* (C - i D)(pr + i pi) = (C pr + D pi) - i (D pr - C pi) */
            double Cn = C * pr + D * pi, Dn = D * pr - C * pi;
            if (Cn == 0 && Dn == 0 && (C != 0 || D != 0))
                Cn = 0x1p-1074; /* keep the entry used: the sums' layout is that of k */
            out->C[q] = Cn;
            out->D[q] = Dn;
        }
    }
    return 0;
}

/* The integral over [(N-1) h, (N-1+theta) h] of entry q of k. */
static double expk_last(const dmi_expk *k, size_t q, size_t N, double h, double theta)
{
    const size_t nn = k->n * k->n;
    const double s0 = (double)(N - 1) * h, w = theta * h;
    double sum = 0;
    for (size_t t = 0; t < k->K; t++) {
        const double C = k->C[t * nn + q], D = k->D ? k->D[t * nn + q] : 0.0;
        if (C == 0 && D == 0)
            continue;
        double pr, pi;
        phi1(k->a[t] * w, k->b[t] * w, &pr, &pi);
        const double e = exp(k->a[t] * s0), er = e * cos(k->b[t] * s0), ei = e * sin(k->b[t] * s0);
        const double zr = pr * er - pi * ei, zi = pr * ei + pi * er; /* phi1 e^{mu s0} */
        sum += w * (C * zr + D * zi); /* Re((C - i D)(zr + i zi)) */
    }
    return sum;
}

/* ---- callback kernels ---------------------------------------------------- */

typedef struct {
    dmi_solver *s;
    dmi_kernel_fn H;
    void *user;
    size_t nn;
    double *val; /* nn: H at the node */
} integrand;

/* acc += wt H(x); a failing or non-finite callback is an error (message set). */
static int add_node(integrand *g, double x, double wt, double *acc, double *absacc)
{
    memset(g->val, 0, g->nn * sizeof *g->val);
    int rc = g->H(x, g->val, g->user);
    if (rc != 0)
        return dmi_fail(g->s, DMI_ECALLBACK, "dmi_init: kernel callback returned %d at s = %.17g",
                        rc, x);
    size_t bad = dmi_first_nonfinite(g->val, g->nn);
    if (bad < g->nn)
        return dmi_fail(g->s, DMI_ENONFINITE, "dmi_init: kernel H(%.17g)[%zu][%zu] = %g", x,
                        bad / g->s->n, bad % g->s->n, g->val[bad]);
    for (size_t q = 0; q < g->nn; q++) {
        acc[q] += wt * g->val[q];
        absacc[q] += wt * fabs(g->val[q]);
    }
    return DMI_OK;
}

/* The nodes t = j w, j odd (all j at level 0), of the rule on [lo, hi]
 * added into acc (nn sums of weight * H, without the factor w d). */
static int add_level(integrand *g, double lo, double hi, double w, int first, double *acc,
                     double *absacc)
{
    const double d = (hi - lo) / 2, c = lo + d;
    for (long j = first ? 0 : 1; (double)j * w <= T_MAX; j += first ? 1 : 2) {
        const double t = (double)j * w, u = PI_2 * sinh(t), ch = cosh(u);
        const double wt = PI_2 * cosh(t) / (ch * ch);
        if (j == 0) {
            int rc = add_node(g, c, wt, acc, absacc);
            if (rc != DMI_OK)
                return rc;
            continue;
        }
        const double off = d * 2 / (exp(2 * u) + 1); /* distance of the node to the end */
        if (!(off > 0))
            break;
        int rc = add_node(g, lo + off, wt, acc, absacc);
        if (rc == DMI_OK)
            rc = add_node(g, hi - off, wt, acc, absacc);
        if (rc != DMI_OK)
            return rc;
    }
    return DMI_OK;
}

/* out[q] = int_lo^hi H_q (nn values); scratch: 4 nn doubles. */
static int integrate(integrand *g, double lo, double hi, double *out, double *scratch)
{
    const size_t nn = g->nn;
    double *acc = scratch, *absacc = acc + nn, *prev = absacc + nn;
    memset(acc, 0, 2 * nn * sizeof *acc);
    double w = 0.5;
    const double d = (hi - lo) / 2;
    int rc = add_level(g, lo, hi, w, 1, acc, absacc);
    for (int level = 1; rc == DMI_OK; level++) {
        for (size_t q = 0; q < nn; q++)
            prev[q] = acc[q] * w * d;
        w /= 2;
        rc = add_level(g, lo, hi, w, 0, acc, absacc);
        if (rc != DMI_OK)
            break;
        double change = 0, size = 0;
        for (size_t q = 0; q < nn; q++) {
            change = fmax(change, fabs(acc[q] * w * d - prev[q]));
            size = fmax(size, absacc[q] * w * d);
        }
        if (change <= REL_TOL * size || level == MAX_LEVEL)
            break;
    }
    for (size_t q = 0; q < nn; q++)
        out[q] = acc[q] * w * d;
    return rc;
}

/* ---- the cells ------------------------------------------------------------ */

int dmi_quad_sample(dmi_solver *s, dmi_kernel *k, double **last)
{
    const size_t n = s->n, N = s->N, nn = n * n;
    const double h = s->h, theta = s->theta;
    *last = NULL;
    dmi_kernel_alloc(k, n, N, NULL);
    if (!s->H)
        return DMI_OK;
    if (dmi_has_expk(s)) {
        int rc = dmi_expk_sample(&s->cell_expk, N, h, k);
        if (rc < 0)
            return dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the cell weights");
        if (rc > 0)
            return dmi_fail(s, DMI_ENONFINITE, "dmi_init: a cell weight of the exponential kernel "
                                               "is not finite (a h or b h out of range)");
        *last = calloc(k->nnz ? k->nnz : 1, sizeof **last);
        if (!*last) {
            dmi_kernel_release(k);
            return dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the cell weights");
        }
        if (theta != 1)
            for (size_t e = 0; e < k->nnz; e++) /* the partial cell's integral less h mean */
                (*last)[e] = expk_last(&s->expk, k->row[e] * n + k->col[e], N, h, theta) -
                             h * k->samples[e * N + N - 1];
        return DMI_OK;
    }
    size_t bytes = dmi_mul_size(n, n, 1) ? dmi_mul_size(N, nn, sizeof(double)) : 0;
    size_t sbytes = dmi_mul_size(5, nn, sizeof(double));
    double *dense = bytes ? malloc(bytes) : NULL, *scratch = sbytes ? malloc(sbytes) : NULL;
    if (!dense || !scratch) {
        free(dense);
        free(scratch);
        return dmi_fail(s, DMI_ENOMEM, "dmi_init: cannot allocate %zu x %zu x %zu cell weights", N,
                        n, n);
    }
    integrand g = {s, s->H, s->H_user, nn, scratch + 4 * nn};
    int rc = DMI_OK;
    for (size_t l = 0; l < N && rc == DMI_OK; l++) {
        const double lo = (double)l * h, hi = l + 1 == N ? s->tau : (double)(l + 1) * h;
        const double width = l + 1 == N ? theta * h : h; /* the mean over the cell */
        rc = integrate(&g, lo, hi, dense + l * nn, scratch);
        for (size_t q = 0; q < nn && rc == DMI_OK; q++)
            dense[l * nn + q] /= width;
    }
    free(scratch);
    if (rc == DMI_OK && dmi_kernel_alloc(k, n, N, dense) != 0)
        rc = dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the cell weights");
    free(dense);
    if (rc == DMI_OK) {
        *last = calloc(k->nnz ? k->nnz : 1, sizeof **last);
        if (!*last) {
            dmi_kernel_release(k);
            rc = dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the cell weights");
        }
    }
    if (rc == DMI_OK) /* the last mean is the partial cell's: weight theta h, not h */
        for (size_t e = 0; e < k->nnz; e++)
            (*last)[e] = (theta - 1) * h * k->samples[e * N + N - 1];
    return rc;
}

void dmi_quad_last(const dmi_kernel *k, const dmi_history *r, const double *last, double *W)
{
    const size_t lag = k->N - 1;
    for (size_t e = 0; e < k->nnz; e++)
        W[k->row[e]] += last[e] * dmi_history_series(r, k->col[e])[lag];
}

/* ---- the near cells of a fitted kernel ---------------------------------- */

int dmi_quad_near(dmi_solver *s, dmi_kernel *k, double **last, dmi_kernel *near)
{
    const size_t n = s->n, N = s->N, nn = n * n;
    const double h = s->h;
    dmi_kernel_alloc(near, n, 0, NULL);
    const double q = s->near_delta / h;
    const size_t m = q >= (double)N ? N : (size_t)ceil(q); /* the cells with l h < delta */
    if (m == 0)
        return DMI_OK;
    if (m + 1 > N)
        return dmi_fail(s, DMI_EINVAL, "dmi_init: the near cells (delta = %g, %zu cells of h = %g) "
                                       "must leave at least the last of the N = %zu cells to the "
                                       "exponential sum", s->near_delta, m, h, N);
    /* (m < N <= the ring's rows: m n n doubles fit) */
    size_t bytes = dmi_mul_size(N, nn, sizeof(double)), sbytes = dmi_mul_size(5, nn, sizeof(double));
    double *dense = bytes ? calloc(N * nn, sizeof *dense) : NULL;
    double *diff = calloc(m * nn, sizeof *diff), *scratch = sbytes ? malloc(sbytes) : NULL;
    double *last2 = calloc(nn, sizeof *last2); /* by entry, then by the new kernel's entries */
    dmi_kernel k2 = {0};
    int rc = dense && diff && scratch && last2 ? DMI_OK
                                               : dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory "
                                                          "for the near cells");
    for (size_t e = 0; rc == DMI_OK && e < k->nnz; e++) { /* the sum's means, dense */
        const size_t qe = k->row[e] * n + k->col[e];
        for (size_t l = 0; l < N; l++)
            dense[l * nn + qe] = k->samples[e * N + l];
        if (*last)
            last2[qe] = (*last)[e];
    }
    integrand g = {s, s->near_H, s->near_user, nn, scratch ? scratch + 4 * nn : NULL};
    for (size_t l = 0; l < m && rc == DMI_OK; l++) { /* the exact means of the near cells */
        double *row = dense + l * nn;
        rc = integrate(&g, (double)l * h, (double)(l + 1) * h, diff + l * nn, scratch);
        for (size_t qe = 0; qe < nn && rc == DMI_OK; qe++) {
            const double exact = diff[l * nn + qe] / h;
            diff[l * nn + qe] = exact - row[qe]; /* what the recursion's sum lacks */
            row[qe] = exact;
        }
    }
    if (rc == DMI_OK && (dmi_kernel_alloc(&k2, n, N, dense) != 0 ||
                         dmi_kernel_alloc(near, n, m, diff) != 0))
        rc = dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the near cells");
    double *l2 = NULL;
    if (rc == DMI_OK && *last) {
        l2 = calloc(k2.nnz ? k2.nnz : 1, sizeof *l2);
        if (!l2)
            rc = dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the near cells");
        for (size_t e = 0; l2 && e < k2.nnz; e++)
            l2[e] = last2[k2.row[e] * n + k2.col[e]];
    }
    free(dense);
    free(diff);
    free(scratch);
    free(last2);
    if (rc != DMI_OK) {
        dmi_kernel_release(&k2);
        dmi_kernel_release(near);
        return rc;
    }
    dmi_kernel_release(k);
    *k = k2;
    if (*last) {
        free(*last);
        *last = l2;
    }
    return DMI_OK;
}

void dmi_quad_near_add(const dmi_kernel *near, const dmi_history *r, double h, double *W)
{
    for (size_t e = 0; e < near->nnz; e++)
        W[near->row[e]] += h * dmi_dot(near->samples + e * near->N,
                                       dmi_history_series(r, near->col[e]), near->N);
}
