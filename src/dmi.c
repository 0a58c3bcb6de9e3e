/*
 * libdmi — the implicit Euler scheme (3.12)-(3.13) with a Volterra delay term:
 * the solver's life cycle (dmi_create, dmi_free, dmi_init with the sampling
 * of the kernel and the history), its step (dmi_step, dmi_advance) and the
 * watch of the resolvent's holds (core.h).  Its setters and queries are in
 * dmi_io.c, its saved state in state.c, the delay sum's engines in
 * engine.c, the cell rule in cells.c (with quad.c's integration), the
 * errors in errors.c.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "solver.h"

#include "cells.h"
#include "core.h"
#include "engine.h"
#include "errors.h"
#include "holds.h"

#include "bytes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- life cycle ---------------------------------------------------------- */

/* A new solver with N cells of width h, the last weighted theta h; the
 * arguments are checked, but not the sizes. */
static int create(dmi_solver **out, size_t n, double tau, size_t N, double h, double theta)
{
    if (N == SIZE_MAX || dmi_mul_size(2 * (N + 1) > N ? 2 * (N + 1) : 0, n, sizeof(double)) == 0 ||
        dmi_mul_size(5, n, sizeof(double)) == 0)
        return DMI_ENOMEM;

    dmi_solver *s = calloc(1, sizeof *s);
    if (!s)
        return DMI_ENOMEM;
    s->n = n;
    s->N = N;
    s->tau = tau;
    s->h = h;
    s->theta = theta;
    s->a_kind = A_NONE;
    s->conv_method = DMI_CONV_AUTO;
    s->alpha = NAN;
    s->work = malloc(5 * n * sizeof(double));
    s->last_W = calloc(n, sizeof(double));
    s->last_X = calloc(n, sizeof(double));
    if (!s->work || !s->last_W || !s->last_X || dmi_history_alloc(&s->ring, n, N) != 0) {
        dmi_free(&s);
        return DMI_ENOMEM;
    }
    *out = s;
    return DMI_OK;
}

int dmi_create(dmi_solver **out, size_t n, double tau, size_t N)
{
    if (!out)
        return DMI_EINVAL;
    *out = NULL;
    if (n == 0 || N == 0 || !isfinite(tau) || !(tau > 0))
        return DMI_EINVAL;
    double h = tau / (double)N;
    if (!isnormal(h))
        return DMI_EINVAL;
    return create(out, n, tau, N, h, 1.0);
}

/* Beyond this many cells no machine holds the ring (2^50 rows of 16 bytes a
 * component); below it tau / h and its integers are exact enough for the
 * rule of dmi_create_h (round(q) is the M of h == tau / M). */
#define MAX_CELLS 0x1p50

int dmi_create_h(dmi_solver **out, size_t n, double tau, double h)
{
    if (!out)
        return DMI_EINVAL;
    *out = NULL;
    if (n == 0 || !isfinite(tau) || !(tau > 0) || !isnormal(h) || !(h > 0))
        return DMI_EINVAL;
    const double q = tau / h; /* > 0; +inf when it overflows */
    if (!(q < MAX_CELLS) || !(q < (double)(SIZE_MAX / 4)))
        return DMI_ENOMEM;
    const double M = round(q);
    if (M >= 1 && tau / M == h) /* dmi_create(n, tau, M)'s h: its solver */
        return create(out, n, tau, (size_t)M, h, 1.0);
    const double N = q > 1 ? ceil(q) : 1;
    return create(out, n, tau, (size_t)N, h, q - (N - 1)); /* exact (N - 1 <= q <= 2 (N - 1)) */
}

void dmi_free(dmi_solver **ps)
{
    if (!ps || !*ps)
        return;
    dmi_solver *s = *ps;
    free(s->a_lo);
    free(s->a_hi);
    dmi_history_release(&s->ring);
    dmi_kernel_release(&s->kernel);
    dmi_expk_release(&s->expk);
    dmi_expk_release(&s->cell_expk);
    free(s->cell_last);
    dmi_kernel_release(&s->near);
    dmi_engine_free(s->conv, s->rec);
    free(s->last_W);
    free(s->last_X);
    free(s->work);
    free(s);
    *ps = NULL;
}

/* ---- init ------------------------------------------------------------------ */

/* Samples H(l h), l = 0..N-1, into k (nonzero entries only), for fn's
 * messages.  An exponential kernel is sampled entry by entry
 * (dmi_expk_sample: no N n n array); where a sample is not finite, the
 * general path below names it. */
int dmi_sample_kernel(const dmi_solver *s, dmi_kernel *k, const char *fn)
{
    const size_t n = s->n, N = s->N, nn = n * n;
    if (!s->H)
        return dmi_kernel_alloc(k, n, N, NULL) == 0
                   ? DMI_OK
                   : dmi_fail(s, DMI_ENOMEM, "%s: out of memory", fn);
    if (dmi_has_expk(s)) {
        int rc = dmi_expk_sample(&s->expk, N, s->h, k);
        if (rc < 0)
            return dmi_fail(s, DMI_ENOMEM, "%s: out of memory for kernel samples", fn);
        if (rc == 0)
            return DMI_OK;
    }
    /* (0 also when n * n overflows) */
    size_t bytes = dmi_mul_size(n, n, 1) ? dmi_mul_size(N, nn, sizeof(double)) : 0;
    double *dense = bytes ? malloc(bytes) : NULL;
    if (!dense)
        return dmi_fail(s, DMI_ENOMEM, "%s: cannot allocate %zu x %zu x %zu kernel samples",
                        fn, N, n, n);
    for (size_t l = 0; l < N; l++) {
        double t = (double)l * s->h;
        double *Hl = dense + l * nn;
        memset(Hl, 0, nn * sizeof *Hl);
        int rc = s->H(t, Hl, s->H_user);
        if (rc != 0) {
            free(dense);
            return dmi_fail(s, DMI_ECALLBACK, "%s: kernel callback returned %d at s = %.17g",
                            fn, rc, t);
        }
        size_t bad = dmi_first_nonfinite(Hl, nn);
        if (bad < nn) {
            rc = dmi_fail(s, DMI_ENONFINITE, "%s: kernel H(%.17g)[%zu][%zu] = %g", fn, t,
                          bad / n, bad % n, Hl[bad]);
            free(dense);
            return rc;
        }
    }
    int rc = dmi_kernel_alloc(k, n, N, dense);
    free(dense);
    return rc == 0 ? DMI_OK : dmi_fail(s, DMI_ENOMEM, "%s: out of memory for kernel samples", fn);
}

/* Samples z(p h), p = -N..0, into ring. */
static int sample_history(dmi_solver *s, dmi_history *ring)
{
    const size_t n = s->n, N = s->N;
    double *u = s->work;
    for (size_t k = 0; k <= N; k++) { /* U^{-k} = z(-k h) */
        const double t = dmi_history_time(s, k);
        for (size_t j = 0; j < n; j++) /* (a loop: n is small) */
            u[j] = 0;
        if (s->z) {
            int rc = s->z(t, u, s->z_user);
            if (rc != 0)
                return dmi_fail(s, DMI_ECALLBACK,
                                "dmi_init: history callback returned %d at t = %.17g", rc, t);
            size_t bad = dmi_first_nonfinite(u, n);
            if (bad < n)
                return dmi_fail(s, DMI_ENONFINITE, "dmi_init: history z(%.17g)[%zu] = %g", t, bad,
                                u[bad]);
        }
        dmi_history_put(ring, k, u);
    }
    return DMI_OK;
}

/* The cell rule's samples into k and its last-cell change into *last
 * (cells.c), and s->cell_expk, the kernel the recursion runs: a function of
 * the exponential terms and h alone, so that setting it before dmi_init can
 * still fail changes no result. */
static int quad_prepare(dmi_solver *s, dmi_quad_nodes *nodes, dmi_kernel *k, double **last)
{
    if (dmi_has_expk(s)) { /* (an initialised solver gets the same values again) */
        dmi_expk x;
        if (dmi_quad_expk(&s->expk, s->h, &x) != 0)
            return dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the cell weights");
        dmi_expk_release(&s->cell_expk);
        s->cell_expk = x;
    }
    return dmi_cells_sample(s, nodes, k, last);
}

int dmi_init(dmi_solver *s)
{
    if (!s)
        return DMI_EINVAL;
    int rc = dmi_engine_check_method(s, s->conv_method, "dmi_init"); /* the kernel may have changed */
    if (rc != DMI_OK)
        return rc;
    dmi_kernel k = {0};
    dmi_history ring = {0};
    if (dmi_history_alloc(&ring, s->n, s->N) != 0)
        return dmi_fail(s, DMI_ENOMEM, "dmi_init: out of memory for the history");
    dmi_conv *c = NULL;
    dmi_exp *e = NULL;
    double *last = NULL;
    dmi_kernel near = {0};
    dmi_quad_nodes nodes = {0}; /* the quadrature's, made once when a callback is integrated */
    if (s->near_H && !dmi_has_expk(s))
        rc = dmi_fail(s, DMI_EINVAL, "dmi_init: the near cells of dmi_set_kernel_near need a kernel "
                                     "given by dmi_set_kernel_exp");
    /* without samples where the method needs none: taken if another method is chosen later
     * (dmi_set_convolution) */
    const int sample = dmi_engine_needs_samples(s, s->conv_method);
    if (rc == DMI_OK && !sample)
        dmi_kernel_alloc(&k, s->n, s->N, NULL); /* none (allocates nothing) */
    else if (rc == DMI_OK)
        rc = s->quad == DMI_QUAD_CELL ? quad_prepare(s, &nodes, &k, &last)
                                      : dmi_sample_kernel(s, &k, "dmi_init");
    if (rc == DMI_OK && s->near_H)
        rc = dmi_cells_near(s, &nodes, &k, &last, &near);
    dmi_quad_nodes_free(&nodes);
    if (rc == DMI_OK)
        rc = sample_history(s, &ring);
    /* a restart keeps the recursion's engine: it depends on the kernel, N and
     * h only, which cannot change after dmi_init, and is anchored below */
    const int keep_rec = s->initialized && s->rec && dmi_engine_is_recursion(s, s->conv_method);
    if (rc == DMI_OK && keep_rec)
        e = s->rec;
    else if (rc == DMI_OK)
        rc = dmi_engine_make(s, &k, s->conv_method, &c, &e, "dmi_init");
    if (rc != DMI_OK) {
        dmi_kernel_release(&k);
        dmi_history_release(&ring);
        free(last);
        dmi_kernel_release(&near);
        return rc;
    }
    free(s->cell_last);
    s->cell_last = last;
    dmi_kernel_release(&s->near);
    s->near = near;
    dmi_kernel_release(&s->kernel);
    dmi_history_release(&s->ring);
    s->kernel = k;
    s->kernel_sampled = sample;
    s->ring = ring;
    if (!keep_rec)
        dmi_engine_free(s->conv, s->rec);
    s->conv = c;
    s->rec = e;
    s->p = 0;
    dmi_engine_rebuild(s, c, e); /* the history's part, before the first step */
    memset(s->last_W, 0, s->n * sizeof *s->last_W); /* a restart saves the bytes of a new run */
    memset(s->last_X, 0, s->n * sizeof *s->last_X);
    s->initialized = 1;
    return DMI_OK;
}

/* ---- stepping -------------------------------------------------------------- */

static int apply_resolvent(dmi_solver *s, const double *x, double *out)
{
    const size_t n = s->n;
    const double h = s->h;
    switch (s->a_kind) {
    case A_CALLBACK: {
        memset(out, 0, n * sizeof *out);
        int rc = s->r(h, x, out, s->r_user);
        if (rc != 0)
            return dmi_fail(s, DMI_ECALLBACK, "dmi_step: resolvent callback returned %d at "
                                              "t = %.17g", rc, (double)s->p * s->h);
        break;
    }
    case A_FRICTION:
        for (size_t i = 0; i < n; i++) {
            const double lam = h * s->a_lo[i];
            const int side = friction_side(x[i], lam);
            out[i] = side > 0 ? x[i] - lam : side < 0 ? x[i] + lam : 0.0;
        }
        break;
    case A_BOX:
        for (size_t i = 0; i < n; i++) {
            const int side = box_side(x[i], s->a_lo[i], s->a_hi[i]);
            out[i] = side < 0 ? s->a_lo[i] : side > 0 ? s->a_hi[i] : x[i];
        }
        break;
    default:
        memcpy(out, x, n * sizeof *out);
    }
    return DMI_OK;
}

int dmi_step(dmi_solver *s)
{
    if (!s)
        return DMI_EINVAL;
    if (!s->initialized)
        return dmi_fail(s, DMI_ESTATE, "dmi_step: call dmi_init first");
    const size_t n = s->n;
    const double h = s->h, t = (double)s->p * h; /* dmi_time */
    double *U = s->work, *fv = U + n, *Wbuf = fv + n, *X = Wbuf + n, *U1 = X + n;
    dmi_history_get(&s->ring, 0, U);

    for (size_t i = 0; i < n; i++) /* (loops, not memset/memcpy: n is small) */
        fv[i] = 0;
    if (s->f) {
        int rc = s->f(t, U, fv, s->f_user);
        if (rc != 0)
            return dmi_fail(s, DMI_ECALLBACK, "dmi_step: rhs callback returned %d at t = %.17g", rc,
                            t);
    }
    const double *W = dmi_engine_sum(s, Wbuf);
    for (size_t i = 0; i < n; i++)
        X[i] = U[i] - h * fv[i] - h * W[i];
    /* A non-finite f or W makes X non-finite (U^p and h are finite), so one
     * check of X guards all three; the culprit is named on the error path. */
    size_t bad = dmi_first_nonfinite(X, n);
    if (bad < n) {
        size_t bf = dmi_first_nonfinite(fv, n), bw = dmi_first_nonfinite(W, n);
        if (bf < n)
            return dmi_fail(s, DMI_ENONFINITE, "dmi_step: f(%.17g, U)[%zu] = %g", t, bf, fv[bf]);
        if (bw < n)
            return dmi_fail(s, DMI_ENONFINITE, "dmi_step: delay term W[%zu] = %g at t = %.17g", bw,
                            W[bw], t);
        return dmi_fail(s, DMI_ENONFINITE, "dmi_step: resolvent argument X[%zu] = %g at t = %.17g",
                        bad, X[bad], t);
    }
    int rc = apply_resolvent(s, X, U1);
    if (rc != DMI_OK)
        return rc;
    bad = dmi_first_nonfinite(U1, n);
    if (bad < n)
        return dmi_fail(s, DMI_ENONFINITE, "dmi_step: new state U[%zu] = %g at t = %.17g", bad,
                        U1[bad], t + h);

    /* commit */
    dmi_history_push(&s->ring, U1);
    for (size_t i = 0; i < n; i++) {
        s->last_W[i] = W[i];
        s->last_X[i] = X[i];
    }
    s->p++;
    dmi_engine_advance(s);
    return DMI_OK;
}

int dmi_advance(dmi_solver *s, size_t steps)
{
    if (!s)
        return DMI_EINVAL;
    for (size_t k = 0; k < steps; k++) {
        int rc = dmi_step(s);
        if (rc != DMI_OK)
            return rc;
    }
    return DMI_OK;
}

/* The hold of component i for the resolvent's argument x (see dmi_watch). */
static int held_of(const dmi_solver *s, size_t i, double x)
{
    if (s->a_kind == A_FRICTION)
        return friction_side(x, s->h * s->a_lo[i]) == 0;
    return box_side(x, s->a_lo[i], s->a_hi[i]);
}

int dmi_watch_start(dmi_solver *s, dmi_watch *w)
{
    if (!s || !w)
        return DMI_EINVAL;
    if (!s->initialized)
        return dmi_fail(s, DMI_ESTATE, "dmi_watch_start: call dmi_init first");
    if (s->a_kind != A_FRICTION && s->a_kind != A_BOX)
        return dmi_fail(s, DMI_EINVAL, "dmi_watch_start: the hold of a component needs "
                                       "dmi_set_friction or dmi_set_box");
    for (size_t k = 0; k < w->m; k++)
        if (w->comp[k] >= s->n)
            return dmi_fail(s, DMI_EINVAL, "dmi_watch_start: component %zu >= n = %zu",
                            w->comp[k], s->n);
    const double *X = s->last_X;
    if (s->p == 0) {
        dmi_history_get(&s->ring, 0, s->work);
        X = s->work;
    }
    for (size_t k = 0; k < w->m; k++)
        w->held[k] = held_of(s, w->comp[k], X[w->comp[k]]);
    return DMI_OK;
}

int dmi_advance_watch(dmi_solver *s, size_t steps, dmi_watch *w, int stop, size_t *taken)
{
    *taken = 0;
    if (!s)
        return DMI_EINVAL;
    for (size_t k = 0; k < steps; k++) {
        int rc = dmi_step(s);
        if (rc != DMI_OK)
            return rc;
        ++*taken;
        int changed = 0;
        for (size_t j = 0; j < w->m; j++) {
            const int now = held_of(s, w->comp[j], s->last_X[w->comp[j]]);
            changed |= now != w->held[j];
            w->held[j] = now;
        }
        if (changed) {
            w->changes++;
            w->last_p = s->p;
            if (stop)
                break;
        }
    }
    return DMI_OK;
}
