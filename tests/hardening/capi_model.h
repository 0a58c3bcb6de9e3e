/*
 * A small n = 2 test model for the hardening tests whose callbacks can be
 * told to fail, or to return NaN, +-Inf or huge values, from a given call on.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 *
 *   f(t, u) = (-u_1 + 0.1 t, 0.5 u_0),  H(s) = [[0.5, 0], [0.25 + s, 0.1]],
 *   z(t) = (cos t, sin t),  resolvent of A = I: out = x / (1 + lambda).
 */
#ifndef CAPI_MODEL_H
#define CAPI_MODEL_H

#include <stddef.h>

#include "dmi.h"

enum { CB_OK, CB_FAIL, CB_NAN, CB_PINF, CB_NINF, CB_HUGE, CB_NEGHUGE };

typedef struct {
    int mode;     /* CB_* */
    size_t from;  /* misbehave from this call index on (0 = the first call) */
    size_t comp;  /* component that gets the bad value */
    size_t calls; /* calls so far */
} cb_ctl;

typedef struct {
    cb_ctl rhs, resolvent, kernel, history;
} model;

#define MODEL_n 2
#define MODEL_N 4
#define MODEL_TAU 1.0

/* All callbacks well-behaved. */
void model_default(model *m);
/* Back to well-behaved (call counters kept). */
void model_calm(model *m);

int model_rhs(double t, const double *u, double *out, void *user);
int model_resolvent(double lambda, const double *x, double *out, void *user);
int model_kernel(double s, double *out, void *user);
int model_history(double t, double *out, void *user);

/* Creates an n = 2, tau = 1, N = 4 solver with the four callbacks of m. */
int model_solver(dmi_solver **s, model *m);

#endif
