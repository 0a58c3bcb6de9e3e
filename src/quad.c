/*
 * Numerical integration for the exact cell rule (dmi_set_quadrature,
 * DMI_QUAD_CELL; dmi_set_kernel_near): see quad.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Exponential kernels in closed form: per term mu = a + i b, G = C - i D,
 *     int_{l h}^{(l+1) h} Re(G e^{mu s}) ds = h Re(G phi1(mu h) e^{mu l h}),
 * phi1(z) = (e^z - 1) / z: the cells' means are the samples of the
 * exponential kernel with the same (a, b) and C' - i D' = G phi1(mu h)
 * (dmi_quad_expk), which the recursion then runs as it is.  The partial last
 * cell is theta h Re(G phi1(mu theta h) e^{mu (N-1) h}).
 *
 * Other integrands by tanh-sinh quadrature (the double-exponential rule of
 * Takahasi and Mori), written from its formulas: on [lo, hi], c = (lo + hi)/2,
 * d = (hi - lo)/2, u(t) = (pi/2) sinh t,
 *     int f = d sum_j w f(c + d tanh u(t_j)) wt_j,  t_j = j w,
 *     wt = (pi/2) cosh t / cosh^2 u,
 * the nodes near an end placed by their distance to it, d 2 / (e^{2|u|} + 1)
 * (from the table of dmi_quad_nodes_make), and never at an end: a node that
 * rounds onto an end is moved to the nearest double inside, its weight kept
 * (left out, the weights of such nodes add up to about l 2^-52 of cell l's:
 * enough to keep the levels of a cell far from 0 from agreeing).
 * The step w halves (new nodes only) until two levels agree to
 * DMI_QUAD_REL_TOL of the integral of |f|, the terms at |t| = T_MAX (the
 * truncation) included in the error; where that fails by LEVEL_WHOLE, the
 * interval is bisected, depth first, each piece accepted once it converges
 * by LEVEL_PIECE, within MAX_DEPTH halvings and MAX_CALLS calls.
 *
 * Sums are kept per value q scaled by 2^-e_q, e_q following the largest |f_q|
 * seen, so that a kernel near the largest double does not overflow them.
 *
 * A power singularity at 0, f = s^-alpha g(s): the exponent is read from f
 * at s = hi 2^-E0, .., hi 2^-(E0-4 gap) (five probes 2^gap apart, gap = 60
 * for E0 >= 300: the local exponents log2(|f(s_k)| / |f(s_k+1)|) / gap are
 * alpha there, whatever g's value, to rounding); then s = hi x^p, p = 1 / (1 - alpha), turns
 * int_{s_min}^{hi} f ds into int_{x_min}^1 f(hi x^p) hi p x^{p-1} dx, whose
 * integrand is g(hi x^p) hi p: smooth and bounded; the part below
 * s_min = hi 2^-E0 is s_min^{1-alpha} g(0) / (1 - alpha) = s_min f(s_min) /
 * (1 - alpha), to a relative error g's change over [0, s_min] (nothing) and
 * alpha's error over 1 - alpha.
 */
#include "quad.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_2 1.57079632679489661923
#define T_MAX 4.0        /* |t| <= T_MAX: the weights beyond are below 1e-35 of the middle's */
#define L_FINE 10        /* the table's step 2^-10 */
#define LEVEL_MIN 3      /* a converged estimate compares at least steps 1/4 and 1/8 */
#define LEVEL_WHOLE 7    /* steps down to 1/128 on the whole interval (1025 nodes) */
#define LEVEL_PIECE 5    /* and to 1/32 on each piece of a bisection (257 nodes) */
#define MAX_DEPTH 60     /* halvings of a piece */
#define MAX_CALLS 200000 /* calls of f in one integration */
#define SLOPE_TOL 1e-10  /* local exponents of a power law agree to this */
#define TAIL_TOL 1e-11   /* the part below s_min known to this share of the integral of |f| */

/* ---- exponential kernels ------------------------------------------------- */

/* phi1(x + i y) = (e^z - 1) / z without cancellation near 0. */
void dmi_quad_phi1(double x, double y, double *re, double *im)
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

void dmi_quad_psi(double x, double y, double *re, double *im)
{
    if (hypot(x, y) < 1) { /* sum_k z^k / (k! (k + 2)): 30 terms to below 1e-17 */
        double pr = 1, pi = 0; /* z^k / k! */
        *re = 0.5;
        *im = 0;
        for (int k = 1; k < 30; k++) {
            const double nr = (pr * x - pi * y) / k, ni = (pr * y + pi * x) / k;
            pr = nr;
            pi = ni;
            *re += pr / (k + 2);
            *im += pi / (k + 2);
        }
        return;
    }
    /* (e^z (z - 1) + 1) / z^2 */
    const double er = exp(x) * cos(y), ei = exp(x) * sin(y);
    const double nr = er * (x - 1) - ei * y + 1, ni = er * y + ei * (x - 1);
    const double zr = x * x - y * y, zi = 2 * x * y, den = zr * zr + zi * zi;
    *re = (nr * zr + ni * zi) / den;
    *im = (ni * zr - nr * zi) / den;
}

int dmi_quad_expk(const dmi_expk *k, double h, dmi_expk *out)
{
    if (dmi_expk_copy(out, k->n, k->K, k->a, k->b, k->C, k->C) != 0) /* D: room for C' - i D' */
        return -1;
    const size_t nn = k->n * k->n;
    for (size_t t = 0; t < k->K; t++) {
        double pr, pi;
        dmi_quad_phi1(k->a[t] * h, k->b[t] * h, &pr, &pi);
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
double dmi_quad_expk_last(const dmi_expk *k, size_t q, size_t N, double h, double theta)
{
    const size_t nn = k->n * k->n;
    const double s0 = (double)(N - 1) * h, w = theta * h;
    double sum = 0;
    for (size_t t = 0; t < k->K; t++) {
        const double C = k->C[t * nn + q], D = k->D ? k->D[t * nn + q] : 0.0;
        if (C == 0 && D == 0)
            continue;
        double pr, pi;
        dmi_quad_phi1(k->a[t] * w, k->b[t] * w, &pr, &pi);
        const double e = exp(k->a[t] * s0), er = e * cos(k->b[t] * s0), ei = e * sin(k->b[t] * s0);
        const double zr = pr * er - pi * ei, zi = pr * ei + pi * er; /* phi1 e^{mu s0} */
        sum += w * (C * zr + D * zi); /* Re((C - i D)(zr + i zi)) */
    }
    return sum;
}

/* ---- the node table ------------------------------------------------------ */

int dmi_quad_nodes_make(dmi_quad_nodes *t)
{
    const size_t J = (size_t)T_MAX << L_FINE;
    t->J = 0;
    t->wt = malloc((J + 1) * sizeof *t->wt);
    t->dist = malloc((J + 1) * sizeof *t->dist);
    if (!t->wt || !t->dist) {
        dmi_quad_nodes_free(t);
        return -1;
    }
    for (size_t j = 0; j <= J; j++) {
        const double tj = ldexp((double)j, -L_FINE), u = PI_2 * sinh(tj), ch = cosh(u);
        t->wt[j] = PI_2 * cosh(tj) / (ch * ch);
        t->dist[j] = 2 / (exp(2 * u) + 1);
    }
    t->J = J;
    return 0;
}

void dmi_quad_nodes_free(dmi_quad_nodes *t)
{
    free(t->wt);
    free(t->dist);
    t->wt = t->dist = NULL;
    t->J = 0;
}

/* ---- one integration ----------------------------------------------------- */

/* The scaled sums, nn values each (block k at sc + k nn), in units of 2^e_q:
 * the current level's sum of wt f and of wt |f|, the previous level's
 * integral, the truncation terms (|t| = T_MAX), a piece's integral and error
 * estimate, the accepted total, its |f| integral and error, the tolerance of
 * a piece, the uncertainty of the part below s_min. */
enum { S_SUM, S_ABS, S_PREV, S_EDGE, S_VAL, S_ERR, S_TOT, S_TABS, S_TERR, S_TOL, S_UNC, S_COUNT };

#define PROBES 5
#define PROBE_GAP 60 /* binary orders between probes */

size_t dmi_quad_scratch(size_t nn)
{
    const size_t per = 3 + S_COUNT + PROBES + 2;
    return nn && nn <= (size_t)-1 / per / sizeof(double) ? per * nn : 0;
}

typedef struct {
    const dmi_quad_nodes *t;
    dmi_quad_fn f;
    void *user;
    size_t nn;
    double s_lo, s_hi; /* f is called in the open (s_lo, s_hi) only */
    double a, p;       /* p == 1: s = x; else s = a x^p */
    double *val;       /* nn: f at the node */
    double *ex, *mul;  /* nn each: e_q (an integer) and 2^-e_q */
    double *sc;        /* S_COUNT nn */
    double *probe;     /* PROBES nn: f at the probes */
    double *sig;       /* 2 nn: the least and largest local exponent near 0 */
    dmi_quad_report *rep;
} ctx;

static double *blk(const ctx *c, int k)
{
    return c->sc + (size_t)k * c->nn;
}

/* v (finite, not 0) in q's scaled units; the sums of q rescaled first when
 * it would be beyond 2^60 there. */
static double scaled(ctx *c, size_t q, double v)
{
    double y = v * c->mul[q];
    if (fabs(y) > 0x1p60) { /* (a bound far from overflow, far above every weight) */
        const int e = ilogb(v);
        const double factor = ldexp(1.0, (int)c->ex[q] - e);
        for (int k = 0; k < S_COUNT; k++)
            blk(c, k)[q] *= factor;
        c->ex[q] = e;
        c->mul[q] = ldexp(1.0, -e);
        y = v * c->mul[q];
    }
    return y;
}

/* f at s into c->val: DMI_QUAD_OK, or the failure (reported). */
static int call(ctx *c, double s)
{
    memset(c->val, 0, c->nn * sizeof *c->val);
    c->rep->calls++;
    const int rc = c->f(s, c->val, c->user);
    if (rc != 0) {
        c->rep->rc = rc;
        c->rep->at = s;
        return c->rep->status = DMI_QUAD_ECALL;
    }
    for (size_t q = 0; q < c->nn; q++)
        if (!isfinite(c->val[q])) {
            c->rep->entry = q;
            c->rep->at = s;
            c->rep->value = c->val[q];
            return c->rep->status = DMI_QUAD_ENONFINITE;
        }
    return DMI_QUAD_OK;
}

/* Adds wt f(s(x)) jac(x) to the level's sums (and to the truncation terms
 * when edge); a node whose s rounds onto an end of the interval is moved to
 * the nearest double inside, keeping its weight. */
static int node(ctx *c, double x, double wt, int edge)
{
    double s = x, jac = 1;
    if (c->p != 1) {
        const double xp = pow(x, c->p - 1);
        s = c->a * (xp * x);
        jac = c->a * c->p * xp;
    }
    if (!(s > c->s_lo)) /* rounded onto the end: the nearest double inside, weight kept */
        s = nextafter(c->s_lo, c->s_hi);
    else if (!(s < c->s_hi))
        s = nextafter(c->s_hi, c->s_lo);
    if (!(s > c->s_lo && s < c->s_hi)) /* (an interval of one ulp) */
        return DMI_QUAD_OK;
    const int rc = call(c, s);
    if (rc != DMI_QUAD_OK)
        return rc;
    double *sum = blk(c, S_SUM), *abs_ = blk(c, S_ABS), *e = blk(c, S_EDGE);
    for (size_t q = 0; q < c->nn; q++) {
        if (c->val[q] == 0)
            continue;
        const double y = scaled(c, q, c->val[q]) * jac * wt;
        sum[q] += y;
        abs_[q] += fabs(y);
        if (edge)
            e[q] += fabs(y);
    }
    return DMI_QUAD_OK;
}

/* The nodes of level k of the rule on [x0, x1] not in a coarser level (all of
 * them at k = 1): t = j 2^-k, j odd. */
static int level(ctx *c, double x0, double x1, int k)
{
    const double d = (x1 - x0) / 2;
    const size_t step = (size_t)1 << (L_FINE - k), J = c->t->J;
    int rc = k == 1 ? node(c, x0 + d, c->t->wt[0], 0) : DMI_QUAD_OK;
    for (size_t j = step; j <= J && rc == DMI_QUAD_OK; j += k == 1 ? step : 2 * step) {
        const double off = d * c->t->dist[j], wt = c->t->wt[j];
        rc = node(c, x0 + off, wt, j == J);
        if (rc == DMI_QUAD_OK)
            rc = node(c, x1 - off, wt, j == J);
    }
    return rc;
}

/* The rule on [x0, x1], levels 1 .. max_level: S_VAL, S_ERR (level change
 * plus truncation terms) and S_ABS (the integral of |f|) of the last level;
 * *conv = whether every error is within its tolerance: S_TOL, or with
 * own_tol DMI_QUAD_REL_TOL of (S_ABS + |S_TOT|). */
static int piece(ctx *c, double x0, double x1, int max_level, int own_tol, int *conv)
{
    const size_t nn = c->nn;
    const double d = (x1 - x0) / 2;
    double *sum = blk(c, S_SUM), *abs_ = blk(c, S_ABS), *prev = blk(c, S_PREV);
    double *e = blk(c, S_EDGE), *val = blk(c, S_VAL), *err = blk(c, S_ERR);
    double *tot = blk(c, S_TOT), *tol = blk(c, S_TOL);
    for (int k = S_SUM; k <= S_ERR; k++)
        memset(blk(c, k), 0, nn * sizeof *sum);
    *conv = 0;
    for (int k = 1; k <= max_level && !*conv; k++) {
        for (size_t q = 0; q < nn; q++)
            prev[q] = ldexp(sum[q], 1 - k) * d;
        const int rc = level(c, x0, x1, k);
        if (rc != DMI_QUAD_OK)
            return rc;
        int ok = k >= LEVEL_MIN;
        for (size_t q = 0; q < nn; q++) {
            val[q] = ldexp(sum[q], -k) * d;
            err[q] = fabs(val[q] - prev[q]) + e[q] * d;
            const double t = own_tol ? DMI_QUAD_REL_TOL * (ldexp(abs_[q], -k) * d + fabs(tot[q]))
                                     : tol[q];
            ok = ok && err[q] <= t;
        }
        *conv = ok;
        if (*conv || k == max_level)
            for (size_t q = 0; q < nn; q++)
                abs_[q] = ldexp(abs_[q], -k) * d;
    }
    return DMI_QUAD_OK;
}

/* Adds the piece just integrated to the accepted total. */
static void accept_piece(ctx *c)
{
    const double *val = blk(c, S_VAL), *err = blk(c, S_ERR), *abs_ = blk(c, S_ABS);
    double *tot = blk(c, S_TOT), *tabs = blk(c, S_TABS), *terr = blk(c, S_TERR);
    for (size_t q = 0; q < c->nn; q++) {
        tot[q] += val[q];
        tabs[q] += abs_[q];
        terr[q] += err[q];
    }
}

/* The exponent at 0 from the probes (or the hint, checked against them) and
 * the part below the smallest probe into S_TOT (its uncertainty in S_UNC);
 * the variable of the rest: [*x0, *x1] with c->a, c->p. */
static int singular_start(ctx *c, double hint, double *x0, double *x1)
{
    const size_t nn = c->nn;
    const double a = c->s_hi;
    /* five probes from s_min = hi 2^-E0 up to hi 2^-(E0-4 gap), gap = 60 (less
     * once E0 < 300: the probes stay below hi 2^-60, or below hi 2^-20 with a
     * hint); E0 = 960, 900, .., 120 (60 with a hint) until f is finite at
     * every probe */
    const int given = !isnan(hint);
    const int top_probe = given ? 20 : 60;
    int E0 = 960, gap = PROBE_GAP, rc = DMI_QUAD_OK;
    if (E0 > ilogb(a) + 1021) /* s_min stays a normal number */
        E0 = ilogb(a) + 1021;
    for (;; E0 -= PROBE_GAP) {
        gap = E0 - top_probe < PROBE_GAP * (PROBES - 1) ? (E0 - top_probe) / (PROBES - 1)
                                                          : PROBE_GAP;
        for (int j = 0; j < PROBES && rc == DMI_QUAD_OK; j++) {
            rc = call(c, ldexp(a, -E0 + gap * j));
            if (rc == DMI_QUAD_OK)
                memcpy(c->probe + (size_t)j * nn, c->val, nn * sizeof *c->val);
        }
        if (rc == DMI_QUAD_OK || E0 - PROBE_GAP < (given ? 60 : 120))
            break;
        rc = c->rep->status = DMI_QUAD_OK; /* not finite or refused this close to 0: move up */
    }
    if (rc != DMI_QUAD_OK)
        return rc;
    const double s_min = ldexp(a, -E0);
    c->rep->probe_lo = s_min;
    /* (with a hint the exponents compared are those of the two probes closest to 0) */
    c->rep->probe_hi = ldexp(a, -E0 + gap * (given ? 1 : PROBES - 1));
    double top = 0;          /* the largest exponent */
    double measured = -1e300; /* with a hint: the largest exponent measured */
    size_t at_top = (size_t)-1;
    int all_known = 1;       /* with a hint: every entry a power law or 0 at the probes */
    double *tot = blk(c, S_TOT), *unc = blk(c, S_UNC);
    for (size_t q = 0; q < nn; q++) {
        const double *y = c->probe + q;
        double alpha = 0, lo = 0, hi = 0, big = 0;
        int power = 1, zero = 1;
        for (int k = 0; k < PROBES; k++) {
            big = fmax(big, fabs(y[k * nn]));
            power = power && y[k * nn] != 0 && (y[k * nn] > 0) == (y[0] > 0);
            zero = zero && y[k * nn] == 0;
        }
        if (power) { /* the local exponents log2(|f(s_k)| / |f(s_k+1)|) / gap */
            for (int k = 0; k + 1 < PROBES; k++) {
                const double sig = (log2(fabs(y[k * nn])) - log2(fabs(y[(k + 1) * nn]))) / gap;
                lo = k ? fmin(lo, sig) : sig;
                hi = k ? fmax(hi, sig) : sig;
                if (k == 0)
                    alpha = sig;
            }
        }
        if (given) {
            /* the exponent closest to 0 against the hint: above it, refused; the
             * difference is the uncertainty of the part below s_min */
            /* (a difference within the measurement's rounding, that of the two
             * logarithms over gap, counts as none) */
            const double ulps = power ? 0x1p-49 * (fabs(log2(fabs(y[0]))) +
                                                   fabs(log2(fabs(y[nn]))) + 1) / gap : 0;
            /* steeper than declared, or not integrable (1 within rounding): refused */
            if (power && (alpha > hint + DMI_QUAD_SLOPE_TOL ||
                          alpha + ulps >= 1.0)) {
                c->rep->entry = q;
                c->rep->alpha = hint;
                c->rep->slope = alpha;
                return c->rep->status = DMI_QUAD_EDECLARED;
            }
            if (power && alpha > measured) {
                measured = alpha;
                at_top = q;
            }
            all_known = all_known && (power || zero);
            const double off = fmax(fabs(alpha - hint) - ulps, 0);
            lo = hint - (alpha < hint ? off : 0);
            hi = hint + (alpha > hint ? off : 0);
            alpha = hint;
            power = y[0] != 0; /* (the hint taken for every entry) */
        } else if (power && alpha >= DMI_QUAD_ALPHA_MAX) {
            c->rep->entry = q;
            c->rep->alpha = alpha;
            return c->rep->status = DMI_QUAD_ENOTINTEGRABLE;
        }
        c->sig[q] = lo;
        c->sig[nn + q] = hi;
        if (y[0] != 0) {
            /* below s_min: s_min f(s_min) / (1 - alpha); a non-power, bounded f: s_min f */
            const double tail = s_min * y[0] / (power ? 1 - alpha : 1);
            tot[q] = scaled(c, q, tail);
            unc[q] = power ? fabs(tot[q]) * ((hi - lo) / (1 - alpha) + 1e-15)
                           : scaled(c, q, 2 * s_min * big);
        }
        if (power && alpha > top)
            top = alpha;
    }
    if (given && all_known && hint > fmax(measured, 0) + DMI_QUAD_SLOPE_TOL) {
        /* s^hint f tends to 0 in every entry: the hint is larger than needed */
        c->rep->over = 1;
        c->rep->slope = measured;
        c->rep->slope_entry = at_top;
    }
    c->rep->alpha = top;
    c->a = a;
    if (top > 0 && 1 / (1 - top) != 1) { /* (an exponent within rounding of 0: s itself) */
        c->p = 1 / (1 - top);
        *x0 = exp2(-(double)E0 / c->p);
        *x1 = 1;
    } else {
        *x0 = s_min;
        *x1 = a;
    }
    return DMI_QUAD_OK;
}

/* The entry q whose error is the largest against its tolerance. */
static size_t worst(const ctx *c, const double *err, const double *tol)
{
    size_t w = 0;
    double r = -1;
    for (size_t q = 0; q < c->nn; q++) {
        const double x = tol[q] > 0 ? err[q] / tol[q] : err[q] > 0 ? INFINITY : 0;
        if (x > r) {
            r = x;
            w = q;
        }
    }
    return w;
}

int dmi_quad_integrate(const dmi_quad_nodes *t, dmi_quad_fn f, void *user, size_t nn, double lo,
                       double hi, int singular_lo, double alpha_hint, double *out,
                       double *scratch, dmi_quad_report *rep)
{
    memset(rep, 0, sizeof *rep);
    ctx c = {t, f, user, nn, lo, hi, hi, 1, scratch, scratch + nn, scratch + 2 * nn,
             scratch + 3 * nn, scratch + (3 + S_COUNT) * nn,
             scratch + (3 + S_COUNT + PROBES) * nn, rep};
    for (size_t q = 0; q < nn; q++) {
        c.ex[q] = 0;
        c.mul[q] = 1;
    }
    memset(c.sc, 0, S_COUNT * nn * sizeof *c.sc);
    double x0 = lo, x1 = hi;
    int rc = singular_lo ? singular_start(&c, alpha_hint, &x0, &x1) : DMI_QUAD_OK;
    int conv = 0;
    if (rc == DMI_QUAD_OK)
        rc = piece(&c, x0, x1, LEVEL_WHOLE, 1, &conv);
    if (rc != DMI_QUAD_OK)
        return rc;
    double *tol = blk(&c, S_TOL), *tot = blk(&c, S_TOT), *terr = blk(&c, S_TERR);
    double *unc = blk(&c, S_UNC), *tabs = blk(&c, S_TABS);
    for (size_t q = 0; q < nn; q++) /* the pieces' share of the whole's tolerance */
        tol[q] = DMI_QUAD_REL_TOL / 4 * (blk(&c, S_ABS)[q] + fabs(tot[q]));
    if (conv) {
        accept_piece(&c);
    } else { /* bisected, depth first, the left piece first */
        const size_t q = worst(&c, blk(&c, S_ERR), tol);
        rep->entry = q;
        rep->estimate = ldexp(tot[q] + blk(&c, S_VAL)[q], (int)c.ex[q]);
        rep->error = ldexp(blk(&c, S_ERR)[q], (int)c.ex[q]);
        struct { double x0, x1; int depth; } stack[MAX_DEPTH + 2];
        size_t top = 0;
        stack[top].x0 = x0 + (x1 - x0) / 2;
        stack[top].x1 = x1;
        stack[top++].depth = 1;
        stack[top].x0 = x0;
        stack[top].x1 = x0 + (x1 - x0) / 2;
        stack[top++].depth = 1;
        while (top > 0) {
            const double a = stack[top - 1].x0, b = stack[top - 1].x1;
            const int depth = stack[--top].depth;
            rc = piece(&c, a, b, LEVEL_PIECE, 0, &conv);
            if (rc != DMI_QUAD_OK)
                return rc;
            const double m = a + (b - a) / 2;
            if (conv) {
                accept_piece(&c);
                continue;
            }
            if (depth >= MAX_DEPTH || rep->calls > MAX_CALLS || !(m > a && m < b)) {
                /* the estimate reached: the whole rule's (rep->estimate, error) */
                return rep->status = DMI_QUAD_ECONVERGE;
            }
            stack[top].x0 = m;
            stack[top].x1 = b;
            stack[top++].depth = depth + 1;
            stack[top].x0 = a;
            stack[top].x1 = m;
            stack[top++].depth = depth + 1;
        }
    }
    for (size_t q = 0; q < nn; q++) {
        if (unc[q] > TAIL_TOL * (tabs[q] + fabs(tot[q]))) {
            rep->entry = q;
            rep->alpha_lo = c.sig[q];
            rep->alpha_hi = c.sig[nn + q];
            rep->estimate = ldexp(tot[q], (int)c.ex[q]);
            rep->error = ldexp(unc[q] + terr[q], (int)c.ex[q]);
            return rep->status = DMI_QUAD_ENOTPOWER;
        }
        out[q] = ldexp(tot[q], (int)c.ex[q]);
        if (!isfinite(out[q])) {
            rep->entry = q;
            return rep->status = DMI_QUAD_EOVERFLOW;
        }
        const double e = ldexp(terr[q] + unc[q], (int)c.ex[q]);
        if (e > rep->error) {
            rep->error = e;
            rep->estimate = out[q];
        }
    }
    return rep->status = DMI_QUAD_OK;
}
