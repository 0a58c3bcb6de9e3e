/*
 * Numerical integration for the exact cell rule (quad.c): integrals of a
 * vector-valued function over an interval by tanh-sinh quadrature (an
 * integrable power singularity at s = 0 handled exactly), and the closed
 * forms of exponential kernels over cells.  A numerical module: it knows
 * nothing of the solver; it returns a status and a report, and the caller
 * writes the message.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_QUAD_H
#define DMI_QUAD_H

#include <stddef.h>

#include "exp.h"

/* phi1(z) = (e^z - 1) / z = int_0^1 e^{z x} dx at z = x + i y, without
 * cancellation near 0: *re + i *im. */
void dmi_quad_phi1(double x, double y, double *re, double *im);

/* psi(z) = int_0^1 x e^{z x} dx = (e^z (z - 1) + 1) / z^2, by its series
 * for |z| < 1: *re + i *im. */
void dmi_quad_psi(double x, double y, double *re, double *im);

/* out = the exponential kernel with k's (a, b) whose samples at l h are
 * k's cells' means (1/h) int_{l h}^{(l+1) h} H: C' - i D' = (C - i D)
 * phi1((a + i b) h), entry by entry; it uses the same entries as k (its
 * recursion has the same sums).  0, or -1 when out of memory. */
int dmi_quad_expk(const dmi_expk *k, double h, dmi_expk *out);

/* The integral over [(N-1) h, (N-1+theta) h] of entry q (row-major) of k. */
double dmi_quad_expk_last(const dmi_expk *k, size_t q, size_t N, double h, double theta);

/* The integrand: f(s, out, user) writes nn values at s (0 < s, strictly
 * inside the interval integrated), 0 on success. */
typedef int (*dmi_quad_fn)(double s, double *out, void *user);

/* The tanh-sinh nodes, computed once (dmi_quad_nodes_make) and used for
 * every interval: at t_j = j 2^-L (0 <= j <= J), the weight
 * (pi/2) cosh t / cosh^2((pi/2) sinh t) and the node's distance to the
 * nearer end as a fraction of the half width, 2 / (e^{2u} + 1), so that
 * nodes near an end are placed by their distance to it. */
typedef struct {
    size_t J;
    double *wt, *dist; /* J + 1 each (malloc'd) */
} dmi_quad_nodes;

/* 0, or -1 when out of memory (t then empty).  Made once, read by any
 * number of integrations (they do not write it). */
int dmi_quad_nodes_make(dmi_quad_nodes *t);
void dmi_quad_nodes_free(dmi_quad_nodes *t);

/* What an integration reached (the caller's message says it). */
enum {
    DMI_QUAD_OK,
    DMI_QUAD_ECALL,          /* f returned rc at s = at */
    DMI_QUAD_ENONFINITE,     /* f's value[entry] at s = at is value (not finite) */
    DMI_QUAD_ENOTINTEGRABLE, /* |f[entry]| grows like s^-alpha, alpha >= 1, near s = 0 */
    DMI_QUAD_ENOTPOWER,      /* f[entry] is not s^-alpha g(s), g smooth, near 0: its local
                              * exponents between s = probe_lo and probe_hi span
                              * [alpha_lo, alpha_hi] */
    DMI_QUAD_ECONVERGE,      /* no estimate of f[entry] within the tolerance after calls calls:
                              * estimate, error */
    DMI_QUAD_EOVERFLOW,      /* the integral of f[entry] is beyond the largest double */
    DMI_QUAD_ENOMEM,
    DMI_QUAD_EDECLARED       /* the exponent given (alpha) is below f[entry]'s: |f| grows like
                              * s^-slope, slope > alpha, between probe_lo and probe_hi */
};

typedef struct {
    int status;
    int rc;
    size_t entry;
    double at, value;
    double alpha;              /* the exponent at s = 0 used (0: none) */
    double alpha_lo, alpha_hi; /* local exponents near 0 (ENOTPOWER) */
    double probe_lo, probe_hi; /* where they were measured */
    double slope;              /* the exponent given: f[entry]'s measured exponent near 0
                                * (EDECLARED; with over, the largest of the entries') */
    int over;                  /* the exponent given is above every entry's (OK: a note) */
    size_t slope_entry;        /* with over: the entry of the largest exponent (-1 if none) */
    double estimate, error;    /* the integral and its error estimate reached */
    size_t calls;              /* calls of f */
} dmi_quad_report;

/* The doubles of scratch that dmi_quad_integrate needs for nn values (0 when
 * that overflows). */
size_t dmi_quad_scratch(size_t nn);

/* The relative accuracy asked of each integral (of the integral of |f|). */
#define DMI_QUAD_REL_TOL 1e-13

/* A given exponent and the one measured agree to this. */
#define DMI_QUAD_SLOPE_TOL 1e-6

/* Exponents alpha of s^-alpha at or beyond this are taken as not integrable. */
#define DMI_QUAD_ALPHA_MAX (1 - 1e-6)

/*
 * out[q] = int_lo^hi f_q(s) ds, q < nn, each within DMI_QUAD_REL_TOL of
 * int |f_q| (error estimates that include the truncation of the rule), f
 * called only strictly inside (lo, hi).  Where the rule does not converge
 * the interval is bisected (a jump is located that way), within a budget of
 * calls; reaching it is an error (ECONVERGE), never a result.
 *
 * singular_lo (lo must then be 0): f may be s^-alpha g(s) near 0 with g
 * smooth, g(0) != 0 and alpha < 1 (entry by entry).  alpha is estimated
 * from f at five probes s = hi 2^-E0 (s_min) .. hi 2^-(E0 - 240), E0 = 960
 * (or 900, .., 120 when f fails or is not finite at one of them: the probes
 * move up, staying below hi 2^-60), or given (alpha_hint in [0, 1), not
 * NAN): the five probes then go from s_min = hi 2^-E0 up to at most
 * hi 2^-20, E0 down to 60, and each entry's exponent there (from the two
 * probes closest to 0) is checked against alpha: an entry that grows faster
 * than s^-alpha (by more than DMI_QUAD_SLOPE_TOL) is refused (EDECLARED);
 * an alpha above every entry's exponent (s^alpha f tends to 0) is reported
 * (rep->over, the integral computed: the mismatch enters the error of the
 * part below s_min, refused as ENOTPOWER where it matters).  The integral
 * from the smallest probe s_min to hi is then taken in
 * the variable x with s = hi x^{1/(1 - alpha)} (smooth in x), and the part
 * below s_min added as s_min f(s_min) / (1 - alpha).  An entry whose
 * exponent is >= DMI_QUAD_ALPHA_MAX is refused (ENOTINTEGRABLE), one whose
 * local exponents disagree so that the part below s_min is not known to
 * 1e-11 of the integral of |f| (1 / (s ln^2 s), which no sampling tells from
 * 1 / s) too (ENOTPOWER).
 *
 * scratch: dmi_quad_scratch(nn) doubles.  Returns rep->status; rep filled.
 */
int dmi_quad_integrate(const dmi_quad_nodes *t, dmi_quad_fn f, void *user, size_t nn, double lo,
                       double hi, int singular_lo, double alpha_hint, double *out,
                       double *scratch, dmi_quad_report *rep);

#endif
