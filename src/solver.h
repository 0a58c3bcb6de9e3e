/*
 * The solver of libdmi (its life cycle, sampling and step in dmi.c, its
 * setters and queries in dmi_io.c), for the files that handle its innards:
 * those two, the engine (engine.c), the cell rule (cells.c), the errors
 * (errors.c) and the saved state (state.c).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_SOLVER_H
#define DMI_SOLVER_H

#include <stdint.h>

#include "conv.h"
#include "delay.h"
#include "dmi.h"
#include "exp.h"

/* The kinds of the operator A (s->a_kind): none (U = X), a resolvent
 * callback, friction, a box (dmi_io.c sets it, dmi.c's step applies it). */
enum { A_NONE, A_CALLBACK, A_FRICTION, A_BOX };

struct dmi_solver {
    size_t n, N;
    double tau, h;
    double theta;       /* the last cell's weight is theta h, 0 < theta <= 1 (dmi_create: 1) */

    dmi_rhs_fn f;
    void *f_user;
    int a_kind;         /* A_NONE, A_CALLBACK, A_FRICTION, A_BOX */
    dmi_resolvent_fn r;
    void *r_user;
    double *a_lo;  /* friction: alpha (n); box: lo (n) */
    double *a_hi;  /* box: hi (n) */
    dmi_kernel_fn H;    /* dmi_expk_eval for a kernel set by dmi_set_kernel_exp */
    void *H_user;
    dmi_expk expk;      /* that kernel's parameters (K = 0: none) */
    dmi_history_fn z;
    void *z_user;
    int conv_method;

    int initialized;
    uint64_t p;         /* step counter: t_p = p h */
    dmi_history ring;   /* U^{p-N..p} */
    dmi_kernel kernel;  /* nonzero entries of H(l h) */
    int kernel_sampled; /* kernel holds them (dmi_init leaves them out for the recursion) */
    dmi_conv *conv;     /* FFT engine, or NULL */
    dmi_exp *rec;       /* recursion engine, or NULL (both NULL: the direct sum) */
    double *last_W;     /* W^{p-1} (n) */
    double *last_X;     /* X^{p-1} (n) */
    double *work;       /* 5 n scratch values: U^p, f, W, X, U^{p+1} */

    char err[1024]; /* dmi_last_error: room for the cell rule's messages and their advice */

    /* (since 1.3) the quadrature rule DMI_QUAD_* of the delay sum; for the cell
     * rule: what the last cell adds (nnz values, quad.c) and the exponential
     * kernel whose samples are the cells' means (the recursion's, K = 0: none) */
    int quad;
    double *cell_last;
    dmi_expk cell_expk;
    /* (since 1.4) the exponent alpha of the kernel's singularity s^-alpha at
     * s = 0 (dmi_set_kernel_singularity; NAN: estimated from samples) */
    double alpha;
    /* (since 1.3) the exact kernel of the cells below near_delta
     * (dmi_set_kernel_near; NULL: none) and what those cells add to the
     * recursion's sum (nonzero entries over the m near cells) */
    dmi_kernel_fn near_H;
    void *near_user;
    double near_delta;
    dmi_kernel near;
};

/* Samples H(l h), l = 0..N-1, into k (nonzero entries only), for fn's
 * messages (dmi.c: dmi_init; dmi_set_convolution when the recursion went
 * without them).  DMI_OK, or an error code with the message set. */
int dmi_sample_kernel(const dmi_solver *s, dmi_kernel *k, const char *fn);

/* Whether s's kernel is the exponential one of dmi_set_kernel_exp. */
static inline int dmi_has_expk(const dmi_solver *s)
{
    return s->H == dmi_expk_eval;
}

/* The time t_{-k} at which dmi_init samples the history for U^{-k},
 * k = 0..N: -k h, and -tau at k = N (-N h may round below it, and is below
 * it for a partial last cell of dmi_create_h; U^{-N} is read by no step), so
 * that z is called on [-tau, 0] only (dmi.c's init, tangent.c's sampling). */
static inline double dmi_history_time(const dmi_solver *s, size_t k)
{
    const double tk = -(double)k * s->h; /* (fmax of the two, without a libm call) */
    return k == s->N ? -s->tau : k == 0 ? 0.0 : tk < -s->tau ? -s->tau : tk;
}

/* Whether h is the tau / N of dmi_create(n, tau, N) (not only theta = 1:
 * the state format records h when it is not, state.c). */
static inline int dmi_h_is_tau_over_N(const dmi_solver *s)
{
    return s->h == s->tau / (double)s->N;
}

#endif
