/*
 * The solver's exact cell rule (dmi_set_quadrature, DMI_QUAD_CELL) and the
 * near cells (dmi_set_kernel_near): see cells.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Every engine sums h * samples[l] U^{p-l} (l < N) and then adds a last-cell
 * change; so the cell rule stores as samples the cells' means,
 *     samples[l] = (1/h) int_{l h}^{(l+1) h} H,
 * and as the change per kernel entry, last[e], what turns the last full
 * cell's h samples[N-1] into the integral over the partial last cell
 * [(N-1) h, tau] (0 when theta = 1).  Callback kernels are integrated cell
 * by cell by dmi_quad_integrate, the first cell with the singularity at 0
 * that quad.c handles (the exponent of dmi_set_kernel_singularity, or
 * estimated); a cell it cannot integrate to its tolerance fails dmi_init
 * with a message naming the cell and what was reached.
 */
#include "cells.h"

#include "bytes.h"
#include "errors.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Why the first cell's integration calls H close to 0. */
#define NEAR_ZERO                                                                                 \
    ": close to 0, where the cell rule reads the exponent of H's singularity; H must be "        \
    "computable there, or its exponent given (dmi_set_kernel_singularity)"

/* The message of a failed integration of cell l = [lo, hi] of the kernel
 * (near: the near cells' callback): the error code. */
static int quad_fail(const dmi_solver *s, const dmi_quad_report *r, int near, size_t l, double lo,
                     double hi)
{
    const char *who = near ? "near kernel (dmi_set_kernel_near)" : "kernel";
    const size_t n = s->n, i = r->entry / n, j = r->entry % n;
    switch (r->status) {
    case DMI_QUAD_ECALL:
        return dmi_fail(s, DMI_ECALLBACK, "dmi_init: %s callback returned %d at s = %.17g (cell "
                                          "%zu)%s", who, r->rc, r->at, l,
                        l == 0 && r->at < ldexp(hi, -50) ? NEAR_ZERO : "");
    case DMI_QUAD_ENONFINITE:
        return dmi_fail(s, DMI_ENONFINITE, "dmi_init: %s H(%.17g)[%zu][%zu] = %g (cell %zu)%s",
                        who, r->at, i, j, r->value, l,
                        l == 0 && r->at < ldexp(hi, -50) ? NEAR_ZERO : "");
    case DMI_QUAD_ENOTINTEGRABLE:
        return dmi_fail(s, DMI_EINVAL, "dmi_init: cell %zu = [0, %.17g]: %s entry (%zu, %zu) "
                                       "grows like s^-%.9g near s = 0 (from H at s = %.3g .. "
                                       "%.3g): exponent >= 1, not integrable; the cell rule "
                                       "takes H(s) = s^-alpha g(s), alpha < 1, g smooth",
                        l, hi, who, i, j, r->alpha, r->probe_lo, r->probe_hi);
    case DMI_QUAD_ENOTPOWER:
        if (!isnan(s->alpha))
            return dmi_fail(s, DMI_EINVAL, "dmi_init: cell %zu = [0, %.17g]: %s entry (%zu, %zu) "
                                           "does not fit the exponent declared by "
                                           "dmi_set_kernel_singularity(s, %.15g) closely enough: "
                                           "its exponent measured between s = %.3g and %.3g is "
                                           "%.17g, which leaves the part of the integral below "
                                           "them unknown to 1e-11 (estimate %.17g, error %.3g); "
                                           "declare the exponent measured, or NAN to have it "
                                           "estimated; if H is no power law s^-alpha g(s) near 0 "
                                           "(1/(s ln^2 s) looks like one), use DMI_QUAD_LEFT",
                            l, hi, who, i, j, s->alpha, r->probe_lo, r->probe_hi,
                            r->alpha_lo == s->alpha ? r->alpha_hi : r->alpha_lo, r->estimate,
                            r->error);
        return dmi_fail(s, DMI_EINVAL, "dmi_init: cell %zu = [0, %.17g]: %s entry (%zu, %zu): "
                                       "its local exponent runs from %.17g to %.17g between s = "
                                       "%.3g and %.3g, which leaves the part of the integral "
                                       "below them unknown to 1e-11 (estimate %.17g, error "
                                       "%.3g): either H is not s^-alpha g(s) with g smooth, "
                                       "g(0) != 0 near s = 0 (1/(s ln^2 s) looks so and no "
                                       "sampling tells it from 1/s), or its exponent is so "
                                       "close to 1 that the part below them is most of the "
                                       "integral; if H is a power law, give its exponent "
                                       "(dmi_set_kernel_singularity)",
                        l, hi, who, i, j, r->alpha_lo, r->alpha_hi, r->probe_lo, r->probe_hi,
                        r->estimate, r->error);
    case DMI_QUAD_ECONVERGE:
        return dmi_fail(s, DMI_EINVAL, "dmi_init: cell %zu = [%.17g, %.17g]: the integral of %s "
                                       "entry (%zu, %zu) does not converge to %g in %zu calls "
                                       "(estimate %.17g, error estimate %.3g): a jump or a "
                                       "singularity inside the cell that bisection does not "
                                       "resolve, or H computed to fewer digits (its values "
                                       "noisy beyond about 1e-10 of |H|); make H smooth "
                                       "within the cells and accurate, or use DMI_QUAD_LEFT",
                        l, lo, hi, who, i, j, DMI_QUAD_REL_TOL, r->calls, r->estimate, r->error);
    case DMI_QUAD_EDECLARED:
        if (r->slope >= DMI_QUAD_ALPHA_MAX)
            return dmi_fail(s, DMI_EINVAL, "dmi_init: cell %zu = [0, %.17g]: the exponent declared "
                                           "by dmi_set_kernel_singularity(s, %.15g) does not fit "
                                           "the %s: entry (%zu, %zu) grows like s^-%.9g near s = "
                                           "0 (the slope of log|H| against log s is -%.9g "
                                           "between s = %.3g and %.3g): exponent >= 1, not "
                                           "integrable whatever is declared; the cell rule takes "
                                           "H(s) = s^-alpha g(s), alpha < 1, g smooth",
                            l, hi, s->alpha, who, i, j, r->slope, r->slope, r->probe_lo,
                            r->probe_hi);
        return dmi_fail(s, DMI_EINVAL, "dmi_init: cell %zu = [0, %.17g]: the exponent declared by "
                                       "dmi_set_kernel_singularity(s, %.15g) is smaller than the "
                                       "%s's: entry (%zu, %zu) grows like s^-%.9g near s = 0 (the "
                                       "slope of log|H| against log s is -%.9g between s = %.3g "
                                       "and %.3g, so s^alpha H(s) is unbounded there); declare "
                                       "the exponent measured, dmi_set_kernel_singularity(s, "
                                       "%.9g), or NAN to have it estimated from H",
                        l, hi, s->alpha, who, i, j, r->slope, r->slope, r->probe_lo, r->probe_hi,
                        r->slope);
    case DMI_QUAD_EOVERFLOW:
        return dmi_fail(s, DMI_ENONFINITE, "dmi_init: cell %zu = [%.17g, %.17g]: the integral of "
                                           "%s entry (%zu, %zu) is beyond the largest double: "
                                           "scale the kernel down", l, lo, hi, who, i, j);
    default:
        return dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the cell weights");
    }
}

/* The note of dmi_init (no failure) when the exponent declared is larger than
 * every entry's near 0 (cell 0 = [0, hi] integrated, r->over). */
static void over_note(const dmi_solver *s, const dmi_quad_report *r, int near, double hi)
{
    const char *who = near ? "near kernel (dmi_set_kernel_near)" : "kernel";
    char grows[160] = "is 0";
    if (r->slope_entry != (size_t)-1) {
        const size_t i = r->slope_entry / s->n, j = r->slope_entry % s->n;
        const double slope = (0.0 - r->slope) + 0.0; /* (no -0) */
        if (r->slope > 0)
            snprintf(grows, sizeof grows, "grows at most like s^-%.9g (entry (%zu, %zu): "
                                          "the slope of log|H| against log s is %.9g)",
                     r->slope, i, j, slope);
        else
            snprintf(grows, sizeof grows, "is bounded (entry (%zu, %zu): the slope of "
                                          "log|H| against log s is %.9g)", i, j, slope);
    }
    dmi_fail(s, DMI_OK, "dmi_init: note: the exponent declared by dmi_set_kernel_singularity(s, "
                        "%.15g) is larger than needed: between s = %.3g and %.3g the %s %s, so "
                        "s^alpha H(s) tends to 0; cell 0 = [0, %.17g] is integrated to the "
                        "rule's tolerance all the same, but declare the exponent measured, "
                        "dmi_set_kernel_singularity(s, %.9g), or NAN to have it estimated from H",
             s->alpha, r->probe_lo, r->probe_hi, who, grows, hi, r->slope > 0 ? r->slope : 0.0);
}

/* The means over cells [l h, (l+1) h] (the last one up to end, when
 * partial), l < m, of H into dense (m nn values), by dmi_quad_integrate. */
static int cell_means(dmi_solver *s, dmi_quad_nodes *nodes, dmi_kernel_fn H, void *user, int near,
                      size_t m, double end, double *dense)
{
    const size_t nn = s->n * s->n, N = s->N;
    const double h = s->h;
    if (nodes->J == 0 && dmi_quad_nodes_make(nodes) != 0)
        return dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the quadrature's nodes");
    const size_t words = dmi_quad_scratch(nn);
    double *scratch = words ? malloc(words * sizeof *scratch) : NULL;
    if (!scratch)
        return dmi_fail(s, DMI_ENOMEM, "dmi_init: cannot allocate the quadrature's scratch for "
                                       "%zu x %zu kernel entries", s->n, s->n);
    int rc = DMI_OK;
    for (size_t l = 0; l < m && rc == DMI_OK; l++) {
        const double lo = (double)l * h, hi = l + 1 == N ? end : (double)(l + 1) * h;
        double *row = dense + l * nn;
        dmi_quad_report r;
        if (dmi_quad_integrate(nodes, H, user, nn, lo, hi, l == 0, s->alpha, row, scratch, &r) !=
            DMI_QUAD_OK) {
            rc = quad_fail(s, &r, near, l, lo, hi);
            break;
        }
        if (r.over)
            over_note(s, &r, near, hi);
        const double width = hi - lo;
        for (size_t q = 0; q < nn && rc == DMI_OK; q++) {
            row[q] /= width;
            if (!isfinite(row[q]))
                rc = dmi_fail(s, DMI_ENONFINITE, "dmi_init: cell %zu = [%.17g, %.17g]: the mean "
                                                 "of %s entry (%zu, %zu) over the cell is beyond "
                                                 "the largest double: scale the kernel down",
                              l, lo, hi, near ? "the near kernel's" : "the kernel's", q / s->n,
                              q % s->n);
        }
    }
    free(scratch);
    return rc;
}

int dmi_cells_sample(dmi_solver *s, dmi_quad_nodes *nodes, dmi_kernel *k, double **last)
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
                (*last)[e] = dmi_quad_expk_last(&s->expk, k->row[e] * n + k->col[e], N, h, theta) -
                             h * k->samples[e * N + N - 1];
        return DMI_OK;
    }
    size_t bytes = dmi_mul_size(n, n, 1) ? dmi_mul_size(N, nn, sizeof(double)) : 0;
    double *dense = bytes ? malloc(bytes) : NULL;
    if (!dense)
        return dmi_fail(s, DMI_ENOMEM, "dmi_init: cannot allocate %zu x %zu x %zu cell weights", N,
                        n, n);
    int rc = cell_means(s, nodes, s->H, s->H_user, 0, N, s->tau, dense);
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

void dmi_cells_last(const dmi_kernel *k, const dmi_history *r, const double *last, double *W)
{
    const size_t lag = k->N - 1;
    for (size_t e = 0; e < k->nnz; e++)
        W[k->row[e]] += last[e] * dmi_history_series(r, k->col[e])[lag];
}

/* ---- the near cells of a fitted kernel ---------------------------------- */

int dmi_cells_near(dmi_solver *s, dmi_quad_nodes *nodes, dmi_kernel *k, double **last,
                   dmi_kernel *near)
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
    size_t bytes = dmi_mul_size(N, nn, sizeof(double));
    double *dense = bytes ? calloc(N * nn, sizeof *dense) : NULL;
    double *diff = calloc(m * nn, sizeof *diff);
    double *last2 = calloc(nn, sizeof *last2); /* by entry, then by the new kernel's entries */
    dmi_kernel k2 = {0};
    int rc = dense && diff && last2 ? DMI_OK
                                    : dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the "
                                                              "near cells");
    for (size_t e = 0; rc == DMI_OK && e < k->nnz; e++) { /* the sum's means, dense */
        const size_t qe = k->row[e] * n + k->col[e];
        for (size_t l = 0; l < N; l++)
            dense[l * nn + qe] = k->samples[e * N + l];
        if (*last)
            last2[qe] = (*last)[e];
    }
    if (rc == DMI_OK) /* the exact means of the near cells (full cells: m < N) */
        rc = cell_means(s, nodes, s->near_H, s->near_user, 1, m, s->tau, diff);
    for (size_t l = 0; l < m && rc == DMI_OK; l++) {
        double *row = dense + l * nn;
        for (size_t qe = 0; qe < nn; qe++) {
            const double exact = diff[l * nn + qe];
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

void dmi_cells_near_add(const dmi_kernel *near, const dmi_history *r, double h, double *W)
{
    for (size_t e = 0; e < near->nnz; e++)
        W[near->row[e]] += h * dmi_dot(near->samples + e * near->N,
                                       dmi_history_series(r, near->col[e]), near->N);
}
