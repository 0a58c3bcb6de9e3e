/*
 * Exponential-sum kernels and the recursive method of the delay sum (exp.c).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 *
 * H(s) = sum_{k<K} exp(a_k s) (C_k cos(b_k s) + D_k sin(b_k s)) is the real
 * part of sum_k (C_k - i D_k) r_k^{s/h} with r_k = exp((a_k + i b_k) h), so
 * the delay sum is W^p = h sum_k Re[(C_k - i D_k) S_k^p] with, per used
 * column j of term k, S_kj^p = sum_{l<N} r_k^l U_j^{p-l}, which obeys
 *     S^{p+1} = r S^p + U^{p+1} - r^N U^{p+1-N}.
 */
#ifndef DMI_EXP_H
#define DMI_EXP_H

#include <stdint.h>

#include "delay.h"

/* The kernel's parameters (copies of the caller's arrays). */
typedef struct {
    size_t n, K;
    double *a, *b; /* K each */
    double *C, *D; /* K n n each, row-major per term; D NULL: all zero */
} dmi_expk;

/* Copies the arrays into k (D may be NULL).  0, or -1 when out of memory (or
 * K n n overflows); k is then empty. */
int dmi_expk_copy(dmi_expk *k, size_t n, size_t K, const double *a, const double *b,
                  const double *C, const double *D);
void dmi_expk_release(dmi_expk *k);

/* H(s) of the kernel: a dmi_kernel_fn, user = the dmi_expk. */
int dmi_expk_eval(double s, double *out, void *user);

/* The samples H(l h), l < N, of the entries that some C_k or D_k has, as
 * dmi_kernel_alloc would store them from dense samples of dmi_expk_eval
 * (bitwise the same values; entries zero at every sample left out), without
 * the N n n dense array.  0; -1 when out of memory; 1 when a sample is not
 * finite (the dense path then tells which).  out is empty unless 0. */
int dmi_expk_sample(const dmi_expk *k, size_t N, double h, dmi_kernel *out);

/* Whether term t has a nonzero entry in C_t or D_t. */
int dmi_expk_term_used(const dmi_expk *k, size_t t);

/* Number of sums S_kj of the recursion (terms times their used columns). */
size_t dmi_expk_sums(const dmi_expk *k);

/* A hash of what the sums depend on: N, h and every (a_k, b_k) with its
 * used columns.  States carry it so that sums are only taken back by the
 * same recursion. */
uint64_t dmi_expk_signature(const dmi_expk *k, size_t N, double h);

/*
 * The engine.  Its sums are updated by the recursion each step and anchored
 * afresh from the history ring (exactly sampled weights, compensated sums)
 * every dmi_exp_period steps, at the steps p that are multiples of it, so
 * rounding cannot accumulate for more than one period.  Requires every
 * a_k <= 0 (the caller checks).
 */
typedef struct dmi_exp dmi_exp;

/* *out = a new engine for the kernel, N and h (the sums zero: call
 * dmi_exp_anchor before use).  0, or -1 when out of memory. */
int dmi_exp_create(dmi_exp **out, const dmi_expk *k, size_t N, double h);
void dmi_exp_free(dmi_exp *e);
/* Computes the sums S^p from the ring (U^{p-N..p}) at step p. */
void dmi_exp_anchor(dmi_exp *e, const dmi_history *r, uint64_t p);
/* After U^p was pushed (p the new step counter): S^{p-1} -> S^p (anchored
 * afresh when p is the next multiple of the period; the engine keeps that
 * step, set by dmi_exp_anchor and dmi_exp_set from their p, so that its
 * sums stay a function of p and the states). */
void dmi_exp_advance(dmi_exp *e, const dmi_history *r, uint64_t p);
/* W^p (n values, the engine's own: computed, times h, whenever the sums
 * change; valid until the next call that changes them). */
const double *dmi_exp_sum(const dmi_exp *e);
/* The anchoring period in steps. */
uint64_t dmi_exp_period(const dmi_exp *e);
/* The sums as 2 dmi_expk_sums doubles (re, im): written to bytes (any
 * alignment), or set from the doubles as those of step p. */
void dmi_exp_get(const dmi_exp *e, unsigned char *bytes);
void dmi_exp_set(dmi_exp *e, const double *sums, uint64_t p);

#endif
