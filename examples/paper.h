/*
 * The paper's oscillator (4.1) and its Examples 4.1-4.3, shared by the
 * examples, the tests and the benchmark.
 *
 *   w'' + b w + int_0^tau H(s) w(t-s) ds + alpha sigma(w') + g(t) ∋ 0,
 *
 * in the first-order form (4.3): u = (w, v), f(t, u) = (-v, b w + g(t)),
 * A = {0} x alpha sigma, kernel [[0, 0], [H, 0]].
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_PAPER_H
#define DMI_PAPER_H

#include <stdio.h>

#include "dmi.h"

/* b = alpha = tau = 1 for every example, (4.5). */
typedef struct {
    int example; /* 41, 42 or 43 */
} paper_example;

/* Forcing g(t) of Example 4.1, 4.2 ((4.7), (4.9)) or 4.3 (1.3 cos 8t). */
double paper_g(int example, double t);
/* Kernel H(s): 1 for 4.1 and 4.2, cos 2 pi s + cos 10 pi s + cos 20 pi s for 4.3. */
double paper_H(int example, double s);
/* Exact solution w(t) and w'(t) of 4.1 (4.8) and 4.2 (4.10); 0 for 4.3. */
double paper_w(int example, double t);
double paper_v(int example, double t);
/* Whether an exact solution is known (4.1, 4.2). */
int paper_has_exact(int example);

/* The callbacks; user points to a paper_example. */
int paper_rhs(double t, const double *u, double *out, void *user);
int paper_kernel(double s, double *out, void *user);
int paper_history(double t, double *out, void *user);

/* Sets rhs, kernel, history and the built-in friction alpha = (0, 1) on s. */
int paper_setup(dmi_solver *s, paper_example *ex);

/* Replaces the kernel of s by Example 4.3's (paper_H) given as the exponential
 * sum of dmi_set_kernel_exp: K = 3 terms cos(b_k s), a_k = 0,
 * b = 2 pi, 10 pi, 20 pi, each in the entry (1, 0) (so that
 * DMI_CONV_RECURSIVE can take it).  The error of dmi_set_kernel_exp. */
int paper_set_kernel_exp43(dmi_solver *s);

typedef struct {
    double max_err_state; /* max over t_p in [-tau, T] of |U^p - (w, w')(t_p)| (Euclidean) */
    double max_err_w, max_err_v;
    size_t static_phases; /* maximal runs of >= 2 consecutive t_p > 0 with v == 0 exactly */
    size_t dynamic_phases;
    size_t steps;
} paper_result;

/*
 * Runs an example with h = 1/N to T (T/h steps, rounded to the nearest
 * integer).  Writes CSV rows "t,w,v[,w_exact,v_exact]" for every stride-th
 * t_p (from t = -tau for examples with exact solutions, else from 0) if csv is
 * not NULL.  Returns a DMI_* code (DMI_EINVAL also for T < 0, NaN or
 * T/h > 1e15); res is filled on success.
 */
int paper_run(int example, size_t N, double T, int method, FILE *csv, size_t stride,
              paper_result *res);

#endif
