/*
 * libdmi — the solver's setters and queries: the right-hand side, the
 * operator A (a resolvent callback, friction, a box), the kernel and its
 * quadrature, the history and the delay sum's method (dmi_set_*), the
 * window rewritten in place (dmi_set_window), and what a solver tells
 * (dmi_time, dmi_get_*: its step, states, last step's terms and the kernel's
 * weights), with the library's version.  The life cycle, the sampling and
 * the step are in dmi.c; both share the solver of solver.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "solver.h"

#include "engine.h"
#include "errors.h"

#include "bytes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define STR_(x) #x
#define STR(x) STR_(x)

const char *dmi_version(void)
{
    return STR(DMI_VERSION_MAJOR) "." STR(DMI_VERSION_MINOR) "." STR(DMI_VERSION_PATCH);
}

/* ---- setup ---------------------------------------------------------------- */

int dmi_set_rhs(dmi_solver *s, dmi_rhs_fn f, void *user)
{
    if (!s)
        return DMI_EINVAL;
    s->f = f;
    s->f_user = user;
    return DMI_OK;
}

static void set_operator(dmi_solver *s, int kind, double *lo, double *hi, dmi_resolvent_fn r,
                         void *user)
{
    free(s->a_lo);
    free(s->a_hi);
    s->a_kind = kind;
    s->a_lo = lo;
    s->a_hi = hi;
    s->r = r;
    s->r_user = user;
}

int dmi_set_resolvent(dmi_solver *s, dmi_resolvent_fn r, void *user)
{
    if (!s)
        return DMI_EINVAL;
    set_operator(s, r ? A_CALLBACK : A_NONE, NULL, NULL, r, user);
    return DMI_OK;
}

int dmi_set_friction(dmi_solver *s, const double *alpha)
{
    if (!s)
        return DMI_EINVAL;
    if (!alpha)
        return dmi_fail(s, DMI_EINVAL, "dmi_set_friction: alpha is NULL");
    for (size_t i = 0; i < s->n; i++)
        if (!isfinite(alpha[i]) || alpha[i] < 0)
            return dmi_fail(s, DMI_EINVAL,
                            "dmi_set_friction: alpha[%zu] = %g must be finite and >= 0", i,
                            alpha[i]);
    double *a = malloc(s->n * sizeof *a);
    if (!a)
        return dmi_fail(s, DMI_ENOMEM, "dmi_set_friction: out of memory");
    memcpy(a, alpha, s->n * sizeof *a);
    set_operator(s, A_FRICTION, a, NULL, NULL, NULL);
    return DMI_OK;
}

int dmi_set_box(dmi_solver *s, const double *lo, const double *hi)
{
    if (!s)
        return DMI_EINVAL;
    if (!lo || !hi)
        return dmi_fail(s, DMI_EINVAL, "dmi_set_box: %s is NULL", lo ? "hi" : "lo");
    for (size_t i = 0; i < s->n; i++) {
        if (isnan(lo[i]) || isnan(hi[i]))
            return dmi_fail(s, DMI_EINVAL, "dmi_set_box: lo[%zu] or hi[%zu] is NaN", i, i);
        if (lo[i] > hi[i])
            return dmi_fail(s, DMI_EINVAL, "dmi_set_box: lo[%zu] = %g > hi[%zu] = %g", i, lo[i], i,
                            hi[i]);
        if (lo[i] == INFINITY || hi[i] == -INFINITY)
            return dmi_fail(s, DMI_EINVAL, "dmi_set_box: the box is empty in component %zu", i);
    }
    double *l = malloc(s->n * sizeof *l), *u = malloc(s->n * sizeof *u);
    if (!l || !u) {
        free(l);
        free(u);
        return dmi_fail(s, DMI_ENOMEM, "dmi_set_box: out of memory");
    }
    memcpy(l, lo, s->n * sizeof *l);
    memcpy(u, hi, s->n * sizeof *u);
    set_operator(s, A_BOX, l, u, NULL, NULL);
    return DMI_OK;
}

int dmi_set_kernel(dmi_solver *s, dmi_kernel_fn H, void *user)
{
    if (!s)
        return DMI_EINVAL;
    if (s->initialized)
        return dmi_fail(s, DMI_ESTATE, "dmi_set_kernel: the kernel is sampled by dmi_init and "
                                       "cannot change afterwards");
    dmi_expk_release(&s->expk);
    s->H = H;
    s->H_user = user;
    return DMI_OK;
}

int dmi_set_kernel_exp(dmi_solver *s, size_t K, const double *a, const double *b,
                       const double *C, const double *D)
{
    static const char fn[] = "dmi_set_kernel_exp";
    if (!s)
        return DMI_EINVAL;
    if (s->initialized)
        return dmi_fail(s, DMI_ESTATE, "%s: the kernel is sampled by dmi_init and cannot change "
                                       "afterwards", fn);
    if (K == 0)
        return dmi_fail(s, DMI_EINVAL, "%s: K = 0 terms (dmi_set_kernel(s, NULL, NULL) removes the "
                                       "kernel)", fn);
    if (!a || !b || !C)
        return dmi_fail(s, DMI_EINVAL, "%s: %s is NULL", fn, !a ? "a" : !b ? "b" : "C");
    for (size_t k = 0; k < K; k++) {
        if (!isfinite(a[k]))
            return dmi_fail(s, DMI_EINVAL, "%s: a[%zu] = %g is not finite", fn, k, a[k]);
        if (!isfinite(b[k]))
            return dmi_fail(s, DMI_EINVAL, "%s: b[%zu] = %g is not finite", fn, k, b[k]);
    }
    const size_t n = s->n, nn = n * n; /* (used only if n n K doubles fit in size_t) */
    if (dmi_mul_size(n, n, 1) == 0 || dmi_mul_size(K, nn, sizeof(double)) == 0)
        return dmi_fail(s, DMI_ENOMEM, "%s: %zu terms of %zu x %zu matrices overflow", fn, K, n, n);
    for (size_t q = 0; q < K * nn; q++) {
        if (!isfinite(C[q]))
            return dmi_fail(s, DMI_EINVAL, "%s: C[%zu] (term %zu, entry (%zu, %zu)) = %g is not "
                                           "finite", fn, q, q / nn, q % nn / n, q % n, C[q]);
        if (D && !isfinite(D[q]))
            return dmi_fail(s, DMI_EINVAL, "%s: D[%zu] (term %zu, entry (%zu, %zu)) = %g is not "
                                           "finite", fn, q, q / nn, q % nn / n, q % n, D[q]);
    }
    dmi_expk k;
    if (dmi_expk_copy(&k, n, K, a, b, C, D) != 0)
        return dmi_fail(s, DMI_ENOMEM, "%s: out of memory", fn);
    dmi_expk_release(&s->expk);
    s->expk = k;
    s->H = dmi_expk_eval;
    s->H_user = &s->expk;
    return DMI_OK;
}

int dmi_set_quadrature(dmi_solver *s, int rule)
{
    if (!s)
        return DMI_EINVAL;
    if (rule != DMI_QUAD_LEFT && rule != DMI_QUAD_CELL)
        return dmi_fail(s, DMI_EINVAL, "dmi_set_quadrature: unknown rule %d (DMI_QUAD_LEFT = 0, "
                                       "DMI_QUAD_CELL = 1)", rule);
    if (s->initialized)
        return dmi_fail(s, DMI_ESTATE, "dmi_set_quadrature: the kernel's weights are computed by "
                                       "dmi_init and cannot change afterwards: call it before "
                                       "dmi_init (or create a new solver)");
    s->quad = rule;
    return DMI_OK;
}

int dmi_set_kernel_near(dmi_solver *s, dmi_kernel_fn H, void *user, double delta)
{
    if (!s)
        return DMI_EINVAL;
    if (s->initialized)
        return dmi_fail(s, DMI_ESTATE, "dmi_set_kernel_near: the kernel's weights are computed by "
                                       "dmi_init and cannot change afterwards");
    if (H && !(isfinite(delta) && delta >= 0))
        return dmi_fail(s, DMI_EINVAL, "dmi_set_kernel_near: delta = %g; expected a finite "
                                       "delta >= 0", delta);
    s->near_H = H;
    s->near_user = H ? user : NULL;
    s->near_delta = H ? delta : 0.0;
    return DMI_OK;
}

int dmi_set_kernel_singularity(dmi_solver *s, double alpha)
{
    if (!s)
        return DMI_EINVAL;
    if (s->initialized)
        return dmi_fail(s, DMI_ESTATE, "dmi_set_kernel_singularity: the kernel's weights are "
                                       "computed by dmi_init and cannot change afterwards: call "
                                       "it before dmi_init (or create a new solver)");
    if (!isnan(alpha) && !(alpha >= 0 && alpha < 1))
        return dmi_fail(s, DMI_EINVAL, "dmi_set_kernel_singularity: alpha = %g; expected 0 <= "
                                       "alpha < 1 (s^-alpha is not integrable at 0 for alpha >= "
                                       "1), or NAN to estimate it from the kernel", alpha);
    s->alpha = alpha;
    return DMI_OK;
}

int dmi_set_history(dmi_solver *s, dmi_history_fn z, void *user)
{
    if (!s)
        return DMI_EINVAL;
    if (s->initialized)
        return dmi_fail(s, DMI_ESTATE, "dmi_set_history: the history is sampled by dmi_init and "
                                       "cannot change afterwards");
    s->z = z;
    s->z_user = user;
    return DMI_OK;
}

int dmi_set_convolution(dmi_solver *s, int method)
{
    if (!s)
        return DMI_EINVAL;
    int rc = dmi_engine_check_method(s, method, "dmi_set_convolution");
    if (rc != DMI_OK)
        return rc;
    if (s->initialized) { /* the engine follows the method from the next step on */
        dmi_conv *c = NULL;
        dmi_exp *e = NULL;
        dmi_kernel k = {0};
        /* dmi_init went without samples only under the paper's rule with full cells and no
         * near cells (needs_samples): the plain samples are then the weights */
        const int sample = !s->kernel_sampled && dmi_engine_needs_samples(s, method);
        if (sample && (rc = dmi_sample_kernel(s, &k, "dmi_set_convolution")) != DMI_OK)
            return rc;
        rc = dmi_engine_make(s, sample ? &k : &s->kernel, method, &c, &e, "dmi_set_convolution");
        if (rc != DMI_OK) {
            dmi_kernel_release(&k);
            return rc;
        }
        if (sample) { /* the samples the recursion went without, now */
            dmi_kernel_release(&s->kernel);
            s->kernel = k;
            s->kernel_sampled = 1;
        }
        dmi_engine_rebuild(s, c, e);
        dmi_engine_free(s->conv, s->rec);
        s->conv = c;
        s->rec = e;
    }
    s->conv_method = method;
    return DMI_OK;
}

/* ---- queries ---------------------------------------------------------------- */

double dmi_time(const dmi_solver *s)
{
    return s && s->initialized ? (double)s->p * s->h : 0.0;
}

double dmi_get_h(const dmi_solver *s)
{
    return s ? s->h : 0.0;
}

size_t dmi_get_N(const dmi_solver *s)
{
    return s ? s->N : 0;
}

int dmi_get_step_index(const dmi_solver *s, uint64_t *p)
{
    int rc = dmi_check_query(s, p, "dmi_get_step_index");
    if (rc == DMI_OK)
        *p = s->p;
    return rc;
}

int dmi_get_state(const dmi_solver *s, double *u)
{
    int rc = dmi_check_query(s, u, "dmi_get_state");
    if (rc == DMI_OK)
        dmi_history_get(&s->ring, 0, u);
    return rc;
}

int dmi_get_past(const dmi_solver *s, size_t lag, double *u)
{
    int rc = dmi_check_query(s, u, "dmi_get_past");
    if (rc != DMI_OK)
        return rc;
    if (lag > s->N)
        return dmi_fail(s, DMI_EINVAL, "dmi_get_past: lag %zu > N = %zu", lag, s->N);
    dmi_history_get(&s->ring, lag, u);
    return DMI_OK;
}

int dmi_get_window(const dmi_solver *s, double *U)
{
    int rc = dmi_check_query(s, U, "dmi_get_window");
    if (rc != DMI_OK)
        return rc;
    for (size_t k = 0; k <= s->N; k++)
        dmi_history_get(&s->ring, s->N - k, U + k * s->n);
    return DMI_OK;
}

int dmi_set_window(dmi_solver *s, const double *U)
{
    int rc = dmi_check_query(s, U, "dmi_set_window");
    if (rc != DMI_OK)
        return rc;
    const size_t n = s->n, N = s->N, bad = dmi_first_nonfinite_long(U, (N + 1) * n);
    if (bad < (N + 1) * n)
        return dmi_fail(s, DMI_EINVAL, "dmi_set_window: U[%zu] (row %zu = U^{p-%zu}, component "
                        "%zu) is not finite", bad, bad / n, N - bad / n, bad % n);
    s->ring.head = 0; /* the ring rewritten in place: every slot and its mirror */
    dmi_history_put_window(&s->ring, U);
    dmi_engine_rebuild(s, s->conv, s->rec);
    return DMI_OK;
}

int dmi_get_step_terms(const dmi_solver *s, double *W, double *X)
{
    if (!s)
        return DMI_EINVAL;
    if (!s->initialized || s->p == 0)
        return dmi_fail(s, DMI_ESTATE, "dmi_get_step_terms: no step taken since dmi_init");
    if (W)
        memcpy(W, s->last_W, s->n * sizeof *W);
    if (X)
        memcpy(X, s->last_X, s->n * sizeof *X);
    return DMI_OK;
}

/* Adds the weights of kernel k (nonzero entries, lags 0..k->N - 1) times h
 * for the lags first .. first + count - 1 into G (count n n values); the
 * last lag N - 1 of the delay sum gets its change, per entry last[e] (the
 * cell rule's) or (theta - 1) h samples (the left rule's), when last_of. */
static void add_weights(const dmi_solver *s, const dmi_kernel *k, size_t first, size_t count,
                        int last_of, double *G)
{
    const size_t n = s->n, nn = n * n, N = s->N;
    for (size_t e = 0; e < k->nnz; e++) {
        const size_t q = k->row[e] * n + k->col[e];
        const double *x = k->samples + e * k->N;
        for (size_t l = first; l < first + count && l < k->N; l++)
            G[(l - first) * nn + q] += s->h * x[l];
        if (last_of && s->theta != 1 && N - 1 >= first && N - 1 < first + count)
            G[(N - 1 - first) * nn + q] += s->quad == DMI_QUAD_CELL
                                               ? s->cell_last[e]
                                               : (s->theta - 1) * s->h * x[N - 1];
    }
}

int dmi_get_kernel_weights(const dmi_solver *s, size_t first, size_t count, double *G,
                           double *G_near)
{
    static const char fn[] = "dmi_get_kernel_weights";
    if (!s)
        return DMI_EINVAL;
    if (!s->initialized)
        return dmi_fail(s, DMI_ESTATE, "%s: the weights are computed by dmi_init: call it first",
                        fn);
    const size_t n = s->n, nn = n * n, N = s->N;
    if (first > N || count > N - first)
        return dmi_fail(s, DMI_EINVAL, "%s: lags %zu .. %zu + %zu - 1 are not all below N = %zu",
                        fn, first, first, count, N);
    if (!G && !G_near)
        return dmi_fail(s, DMI_EINVAL, "%s: G and G_near are both NULL", fn);
    dmi_kernel k = {0}; /* the samples dmi_init left out for the recursion, now */
    const dmi_kernel *used = &s->kernel;
    if (G && count > 0 && !s->kernel_sampled && dmi_has_expk(s)) {
        int rc = dmi_sample_kernel(s, &k, fn);
        if (rc != DMI_OK)
            return rc;
        used = &k;
    }
    if (G) {
        for (size_t q = 0; q < count * nn; q++)
            G[q] = 0.0;
        add_weights(s, used, first, count, 1, G);
    }
    if (G_near) {
        for (size_t q = 0; q < count * nn; q++)
            G_near[q] = 0.0;
        add_weights(s, &s->near, first, count, 0, G_near);
    }
    dmi_kernel_release(&k);
    return DMI_OK;
}
