/*
 * Exponential-sum kernels and the recursive method of the delay sum W^p.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Accuracy.  A sum S = sum_{l<N} r^l U^{p-l} run by the recursion
 * S <- r S + U_new - r^N U_old weighs the state that entered l steps ago by
 * the product of the l multipliers used since.  With r rounded to double
 * (relative error up to 1.1e-16) that weight is off by l * 1.1e-16, 1e-10 at
 * l = 10^6, and the state leaves with a residue that never decays when
 * |r| = 1.  So r is computed in double-double (hi + lo, about 1e-32) from
 * (a + i b) h, itself the exact double-double product, and each step
 * multiplies by both parts; r^N is the double-double power of that r, so
 * the removal matches the weight the state carries.  What remains is the
 * rounding of each step's arithmetic (about 1e-16 of |S| per step, in
 * random directions); it decays with |r| < 1 but not with |r| = 1, so every
 * PERIOD N steps (at the steps p that are multiples of it) the sums are
 * anchored afresh from the stored states U^{p-N..p}: weights r^l accurate to
 * a few units of rounding (a double-double power every BLOCK lags times a
 * table of r^i, i < BLOCK), products summed with error-free transformations.
 * That costs N multiply-adds per sum every PERIOD N steps, O(1) per step.
 * Growing terms (a_k > 0, |r| > 1) would multiply each step's rounding by
 * |r| every step: dmi.c refuses them for this method.
 * Double-double needs only C99 (fma) and arithmetic evaluated in double
 * (FLT_EVAL_METHOD 0: SSE2, every 64-bit target; not the x87 of 32-bit x86);
 * no long double, whose precision differs between compilers.
 */
#include "exp.h"

#include "bytes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define BLOCK 64  /* lags per double-double weight in an anchor */
#define PERIOD 4  /* anchoring period in units of N */

/* ---- double-double arithmetic (setup and anchors only) -------------------- */

typedef struct {
    double hi, lo;
} dd;

typedef struct {
    dd re, im;
} cdd;

static dd two_sum(double a, double b)
{
    double s = a + b, bb = s - a;
    dd r = {s, (a - (s - bb)) + (b - bb)};
    return r;
}

static dd fast_two_sum(double a, double b) /* |a| >= |b| */
{
    double s = a + b;
    dd r = {s, b - (s - a)};
    return r;
}

static dd dd_add(dd a, dd b)
{
    dd s = two_sum(a.hi, b.hi);
    return fast_two_sum(s.hi, s.lo + (a.lo + b.lo));
}

static dd dd_neg(dd a)
{
    dd r = {-a.hi, -a.lo};
    return r;
}

static dd dd_mul(dd a, dd b)
{
    double p = a.hi * b.hi;
    double e = fma(a.hi, b.hi, -p);
    return fast_two_sum(p, e + (a.hi * b.lo + a.lo * b.hi));
}

static dd dd_div_int(dd a, double k) /* k a small positive integer */
{
    double q = a.hi / k;
    double rem = fma(-q, k, a.hi) + a.lo; /* a - q k, exactly up to a.lo's rounding */
    return fast_two_sum(q, rem / k);
}

static dd dd_scale(dd a, int e)
{
    dd r = {ldexp(a.hi, e), ldexp(a.lo, e)};
    return r;
}

static cdd cdd_add(cdd a, cdd b)
{
    cdd r = {dd_add(a.re, b.re), dd_add(a.im, b.im)};
    return r;
}

static cdd cdd_mul(cdd a, cdd b)
{
    cdd r = {dd_add(dd_mul(a.re, b.re), dd_neg(dd_mul(a.im, b.im))),
             dd_add(dd_mul(a.re, b.im), dd_mul(a.im, b.re))};
    return r;
}

static cdd cdd_one(void)
{
    cdd r = {{1.0, 0.0}, {0.0, 0.0}};
    return r;
}

/* exp(z), z = (x, y) in double-double: scaled to |z| <= 2^-10 (0.0009765625), Taylor
 * series (Horner, 14 terms), squared back. */
static cdd cdd_exp(dd x, dd y)
{
    cdd zero = {{0, 0}, {0, 0}};
    if (x.hi < -746.0) /* underflows whatever y is */
        return zero;
    int m = 0;
    for (double mag = fabs(x.hi) + fabs(y.hi); mag > 0.0009765625 && m < 2100; mag /= 2)
        m++;
    cdd w = {dd_scale(x, -m), dd_scale(y, -m)};
    cdd t = cdd_one();
    for (int k = 14; k >= 1; k--) {
        cdd wt = cdd_mul(w, t);
        wt.re = dd_div_int(wt.re, k);
        wt.im = dd_div_int(wt.im, k);
        t = cdd_add(cdd_one(), wt);
    }
    for (int i = 0; i < m; i++)
        t = cdd_mul(t, t);
    return t;
}

static cdd cdd_pow(cdd r, uint64_t e)
{
    cdd out = cdd_one();
    for (; e; e >>= 1) {
        if (e & 1)
            out = cdd_mul(out, r);
        r = cdd_mul(r, r);
    }
    return out;
}

/* Values below this are flushed to zero: their products would be subnormal
 * (slow on many processors) and their weight is nothing against the lag-0
 * weight 1. */
#define TINY 1e-290

static double flush(double x)
{
    return fabs(x) < TINY ? 0.0 : x;
}

/* ---- the kernel's parameters ----------------------------------------------- */

int dmi_expk_copy(dmi_expk *k, size_t n, size_t K, const double *a, const double *b,
                  const double *C, const double *D)
{
    memset(k, 0, sizeof *k);
    size_t mat = dmi_mul_size(K, n * n, sizeof(double)); /* n * n: the caller checked it */
    if (mat == 0)
        return -1;
    k->a = malloc(K * sizeof *k->a);
    k->b = malloc(K * sizeof *k->b);
    k->C = malloc(mat);
    k->D = D ? malloc(mat) : NULL;
    if (!k->a || !k->b || !k->C || (D && !k->D)) {
        dmi_expk_release(k);
        return -1;
    }
    memcpy(k->a, a, K * sizeof *k->a);
    memcpy(k->b, b, K * sizeof *k->b);
    memcpy(k->C, C, mat);
    if (D)
        memcpy(k->D, D, mat);
    k->n = n;
    k->K = K;
    return 0;
}

void dmi_expk_release(dmi_expk *k)
{
    free(k->a);
    free(k->b);
    free(k->C);
    free(k->D);
    memset(k, 0, sizeof *k);
}

/* e^{a_t s} cos(b_t s) and e^{a_t s} sin(b_t s): the one place both the
 * evaluation and the sampling compute them (the samples are bitwise the
 * values dmi_expk_eval gives). */
static void term_weights(const dmi_expk *k, size_t t, double s, double *c, double *sn)
{
    const double e = exp(k->a[t] * s);
    *c = e * cos(k->b[t] * s);
    *sn = e * sin(k->b[t] * s);
}

/* Whether entry q (row-major) of some C_t or D_t is nonzero. */
static int entry_used(const dmi_expk *k, size_t q)
{
    const size_t nn = k->n * k->n;
    for (size_t t = 0; t < k->K; t++)
        if (k->C[t * nn + q] != 0 || (k->D && k->D[t * nn + q] != 0))
            return 1;
    return 0;
}

int dmi_expk_eval(double s, double *out, void *user)
{
    const dmi_expk *k = user;
    const size_t nn = k->n * k->n;
    for (size_t t = 0; t < k->K; t++) {
        double c, sn;
        term_weights(k, t, s, &c, &sn);
        const double *C = k->C + t * nn, *D = k->D ? k->D + t * nn : NULL;
        for (size_t q = 0; q < nn; q++)
            out[q] += D ? C[q] * c + D[q] * sn : C[q] * c;
    }
    return 0;
}

int dmi_expk_sample(const dmi_expk *k, size_t N, double h, dmi_kernel *out)
{
    const size_t n = k->n, nn = n * n, K = k->K;
    dmi_kernel_alloc(out, n, N, NULL);
    /* per term and sample: e^{a s} cos(b s) and e^{a s} sin(b s), as dmi_expk_eval */
    size_t bytes = dmi_mul_size(2 * K, N, sizeof(double));
    double *cs = bytes ? malloc(bytes) : NULL;
    if (!cs)
        return -1;
    int finite = 1;
    for (size_t t = 0; t < K; t++)
        for (size_t l = 0; l < N; l++) {
            double c, sn;
            term_weights(k, t, (double)l * h, &c, &sn);
            cs[(2 * t) * N + l] = c;
            cs[(2 * t + 1) * N + l] = sn;
            finite &= isfinite(c) && isfinite(sn);
        }
    size_t cand = 0;
    for (size_t q = 0; q < nn; q++)
        cand += (size_t)entry_used(k, q);
    int rc = finite ? 0 : 1;
    if (rc == 0 && cand > 0) {
        out->row = malloc(cand * sizeof *out->row);
        out->col = malloc(cand * sizeof *out->col);
        out->samples = malloc(cand * N * sizeof *out->samples); /* <= N n n doubles */
        rc = out->row && out->col && out->samples ? 0 : -1;
    }
    size_t e = 0;
    for (size_t q = 0; q < nn && rc == 0; q++) {
        if (!entry_used(k, q))
            continue;
        double *x = out->samples + e * N;
        int nonzero = 0;
        for (size_t l = 0; l < N; l++) {
            double v = 0;
            for (size_t t = 0; t < K; t++) {
                const double C = k->C[t * nn + q], c = cs[(2 * t) * N + l];
                v += k->D ? C * c + k->D[t * nn + q] * cs[(2 * t + 1) * N + l] : C * c;
            }
            x[l] = v;
            nonzero |= v != 0;
            if (!isfinite(v))
                rc = 1;
        }
        if (nonzero) {
            out->row[e] = q / n;
            out->col[e] = q % n;
            e++;
        }
    }
    free(cs);
    out->nnz = e;
    if (rc != 0)
        dmi_kernel_release(out);
    return rc;
}

/* Whether column j of term t has a nonzero entry in C_t or D_t. */
static int column_used(const dmi_expk *k, size_t t, size_t j)
{
    const size_t n = k->n, nn = n * n;
    for (size_t i = 0; i < n; i++) {
        size_t q = t * nn + i * n + j;
        if (k->C[q] != 0 || (k->D && k->D[q] != 0))
            return 1;
    }
    return 0;
}

int dmi_expk_term_used(const dmi_expk *k, size_t t)
{
    for (size_t j = 0; j < k->n; j++)
        if (column_used(k, t, j))
            return 1;
    return 0;
}

size_t dmi_expk_sums(const dmi_expk *k)
{
    size_t count = 0;
    for (size_t t = 0; t < k->K; t++)
        for (size_t j = 0; j < k->n; j++)
            count += (size_t)column_used(k, t, j);
    return count;
}

static uint64_t hash_word(uint64_t hsh, uint64_t w)
{
    unsigned char b[sizeof w];
    memcpy(b, &w, sizeof w);
    return dmi_fnv1a(hsh, b, sizeof b);
}

static uint64_t bits(double x)
{
    uint64_t w;
    memcpy(&w, &x, sizeof w);
    return w;
}

uint64_t dmi_expk_signature(const dmi_expk *k, size_t N, double h)
{
    uint64_t hsh = hash_word(hash_word(DMI_FNV1A_INIT, (uint64_t)N), bits(h));
    for (size_t t = 0; t < k->K; t++)
        for (size_t j = 0; j < k->n; j++)
            if (column_used(k, t, j))
                hsh = hash_word(hash_word(hash_word(hsh, bits(k->a[t])), bits(k->b[t])), j);
    return hsh;
}

/* ---- the engine -------------------------------------------------------------- */

typedef struct {
    int real;                    /* b = 0: r is real and the sums stay real */
    double rh_re, rh_im;         /* r = rh + rl */
    double rl_re, rl_im;
    double rN_re, rN_im;         /* r^N */
    cdd rB;                      /* r^BLOCK, for the anchors */
    double tab[2 * BLOCK];       /* r^i, i < BLOCK: re, im */
    double tabx[2 * BLOCK];      /* i r^i: -im, re (the anchor's weights in two lanes) */
    double keep[2];              /* 1, and 0 for a real r (the anchor's imaginary lane) */
} term;

/*
 * The sums are kept in the order real ones first (nreal of them), then the
 * complex ones, each group padded to an even count with a sum that no part
 * uses (its multipliers 0, its series column 0's: it only holds the newest
 * state), so that the step runs two branch-free loops over pairs of sums,
 * which the compiler turns into vector operations: the k-th sum is at
 * internal index k below nreal, nreal2 + k - nreal above, of cap in all.
 * The step's data are kept pair by pair, each pair's in one block of PAIR
 * doubles (field F of sum q at pair[PAIR (q / 2) + F + q % 2]):
 *     re' = x hr - y hi + ((x lr - y li) + (unew - rNr uold))
 *     im' = x hi + y hr + ((x li + y lr) + (0 - rNi uold))
 * with S = x + i y, r = (hr + i hi) + (lr + i li), r^N = rNr + i rNi; a
 * real sum has y = hi = li = rNi = 0 and only the first line.  slot[q] is
 * the place of sum q in the saved order (term by term, used columns
 * ascending).
 * The parts C, D of row i are parts [row_start[i], row_start[i + 1]), in the
 * saved order of their sums (summed in two partial sums, see update_W).  W
 * (h times the sum, n values) is recomputed whenever the sums change, so
 * dmi_exp_sum only copies it.
 */
struct dmi_exp {
    size_t n, N, nterms, nsums, nreal, nparts;
    size_t nreal2, cap;           /* nreal rounded up to even; the internal count */
    double h;
    uint64_t period;
    uint64_t next; /* the next anchoring step: the multiple of period after the last anchor */
    term *terms;
    size_t *term_of, *col, *slot; /* per internal index */
    size_t *series;               /* per internal index: its column's series in the ring */
    double *pair;                 /* cap / 2 blocks: the sums and their multipliers */
    size_t *row_start;            /* n + 1 */
    size_t *psum;                 /* per part: its sum's place in pair (F_SRE's) */
    double *pC, *pD;              /* per part: W_row += C Re S + D Im S */
    int has_D;                    /* some part has D != 0 */
    /* the parts as a matrix when it is small or full enough: the rows with a
     * part (nrows of them, listed in rows), each a row of cap C (and D)
     * values over the internal index, zero where no part is */
    size_t nrows, *rows;
    double *Cm, *Dm;
    double *W;                    /* n: h sum of the parts, W^p */
};

/* The fields of a pair's block (two doubles each). */
enum { F_SRE = 0, F_SIM = 2, F_HR = 4, F_HI = 6, F_LR = 8, F_LI = 10, F_RNR = 12, F_RNI = 14,
       PAIR = 16 };

/* Field f of the sum at internal index q. */
static double *field(const dmi_exp *e, size_t q, int f)
{
    return e->pair + PAIR * (q / 2) + (size_t)f + q % 2;
}

void dmi_exp_free(dmi_exp *e)
{
    if (!e)
        return;
    free(e->terms);
    free(e->term_of);
    free(e->col);
    free(e->slot);
    free(e->series);
    free(e->pair);
    free(e->row_start);
    free(e->psum);
    free(e->pC);
    free(e->pD);
    free(e->W);
    free(e->rows);
    free(e->Cm);
    free(e->Dm);
    free(e);
}

static void term_init(term *t, double a, double b, double h, size_t N)
{
    dd x = {a * h, fma(a, h, -(a * h))}, y = {b * h, fma(b, h, -(b * h))};
    cdd r = cdd_exp(x, y);
    if (b == 0) /* exp of a real number is real: no rounding in im */
        r.im.hi = r.im.lo = 0;
    t->real = b == 0;
    t->rh_re = r.re.hi;
    t->rh_im = r.im.hi;
    t->rl_re = fabs(r.re.hi) < 1e-270 ? 0.0 : r.re.lo;
    t->rl_im = fabs(r.im.hi) < 1e-270 ? 0.0 : r.im.lo;
    cdd rN = cdd_pow(r, (uint64_t)N);
    t->rN_re = flush(rN.re.hi);
    t->rN_im = flush(rN.im.hi);
    cdd w = cdd_one();
    for (size_t i = 0; i < BLOCK; i++) {
        t->tab[2 * i] = flush(w.re.hi);
        t->tab[2 * i + 1] = flush(w.im.hi);
        t->tabx[2 * i] = -t->tab[2 * i + 1];
        t->tabx[2 * i + 1] = t->tab[2 * i];
        w = cdd_mul(w, r);
    }
    t->keep[0] = 1.0;
    t->keep[1] = b == 0 ? 0.0 : 1.0;
    t->rB = w;
    /* Only N = 1 can have finite samples H(0) but an r that overflows (a h
     * or b h beyond the range): then r^l, l >= 1, weighs nothing. */
    if (!(isfinite(t->rh_re) && isfinite(t->rh_im) && isfinite(t->rl_re) &&
          isfinite(t->rl_im) && isfinite(t->rN_re) && isfinite(t->rN_im))) {
        memset(t, 0, sizeof *t);
        t->real = b == 0;
        t->tab[0] = t->tabx[1] = t->keep[0] = 1.0;
        t->keep[1] = b == 0 ? 0.0 : 1.0;
    }
}

static void *array(size_t count, size_t size)
{
    return calloc(count ? count : 1, size);
}

int dmi_exp_create(dmi_exp **out, const dmi_expk *k, size_t N, double h)
{
    *out = NULL;
    const size_t n = k->n, nn = n * n;
    dmi_exp *e = calloc(1, sizeof *e);
    if (!e)
        return -1;
    e->n = n;
    e->N = N;
    e->h = h;
    e->period = (uint64_t)PERIOD * (uint64_t)N;
    e->nsums = dmi_expk_sums(k);
    for (size_t q = 0; q < k->K * nn; q++) /* k->K n n was checked by dmi_expk_copy */
        e->nparts += k->C[q] != 0 || (k->D && k->D[q] != 0);
    e->nterms = k->K;
    for (size_t t = 0; t < k->K; t++)
        for (size_t j = 0; j < n; j++)
            e->nreal += k->b[t] == 0 && column_used(k, t, j);
    e->nreal2 = e->nreal + (e->nreal & 1);
    e->cap = e->nreal2 + (e->nsums - e->nreal) + ((e->nsums - e->nreal) & 1);
    const size_t ns = e->cap, np = e->nparts;
    e->terms = array(k->K, sizeof *e->terms);
    e->term_of = array(ns, sizeof *e->term_of);
    e->col = array(ns, sizeof *e->col);
    e->slot = array(ns, sizeof *e->slot);
    e->series = array(ns, sizeof *e->series);
    e->pair = array(ns / 2 * PAIR, sizeof *e->pair);
    e->row_start = array(n + 1, sizeof *e->row_start);
    e->psum = array(np, sizeof *e->psum);
    e->pC = array(np, sizeof *e->pC);
    e->pD = array(np, sizeof *e->pD);
    e->W = array(n, sizeof *e->W);
    size_t *index = array(k->K * n, sizeof *index); /* (t, j) -> internal sum index */
    if (!e->pair || !e->terms || !e->term_of || !e->col || !e->slot || !e->series ||
        !e->row_start || !e->psum || !e->pC || !e->pD || !e->W || !index) {
        free(index);
        dmi_exp_free(e);
        return -1;
    }
    for (size_t t = 0; t < k->K; t++)
        term_init(&e->terms[t], k->a[t], k->b[t], h, N);
    /* internal order: the real sums, then the complex ones, each in saved
     * order (the pads: zero multipliers, column 0, from calloc) */
    for (int pass = 0; pass < 2; pass++)
        for (size_t t = 0, sv = 0, q = pass == 0 ? 0 : e->nreal2; t < k->K; t++)
            for (size_t j = 0; j < n; j++) {
                if (!column_used(k, t, j))
                    continue;
                if (e->terms[t].real == (pass == 0)) {
                    const term *tm = &e->terms[t];
                    *field(e, q, F_HR) = tm->rh_re;
                    *field(e, q, F_HI) = tm->rh_im;
                    *field(e, q, F_LR) = tm->rl_re;
                    *field(e, q, F_LI) = tm->rl_im;
                    *field(e, q, F_RNR) = tm->rN_re;
                    *field(e, q, F_RNI) = tm->rN_im;
                    e->term_of[q] = t;
                    e->col[q] = j;
                    e->slot[q] = sv;
                    e->series[q] = j * 2 * (N + 1); /* the ring's layout, L = N + 1 */
                    index[t * n + j] = q++;
                }
                sv++;
            }
    /* parts row by row; within a row in the saved order (term, column) */
    size_t pp = 0;
    for (size_t i = 0; i < n; i++) {
        e->row_start[i] = pp;
        for (size_t t = 0; t < k->K; t++)
            for (size_t j = 0; j < n; j++) {
                size_t x = t * nn + i * n + j;
                double C = k->C[x], D = k->D ? k->D[x] : 0.0;
                if (C == 0 && D == 0)
                    continue;
                e->psum[pp] = field(e, index[t * n + j], F_SRE) - e->pair;
                e->pC[pp] = C;
                e->pD[pp] = D;
                e->has_D |= D != 0;
                pp++;
            }
    }
    e->row_start[n] = pp;
    free(index);
    for (size_t i = 0; i < n; i++)
        e->nrows += e->row_start[i + 1] > e->row_start[i];
    if (e->nrows * ns <= 2 * np + 8) { /* (nrows ns <= n (n K + 2): no overflow) */
        e->rows = array(e->nrows, sizeof *e->rows);
        e->Cm = array(e->nrows * ns, sizeof *e->Cm);
        e->Dm = e->has_D ? array(e->nrows * ns, sizeof *e->Dm) : NULL;
        if (!e->rows || !e->Cm || (e->has_D && !e->Dm)) {
            dmi_exp_free(e);
            return -1;
        }
        for (size_t i = 0, r = 0; i < n; i++) {
            if (e->row_start[i + 1] == e->row_start[i])
                continue;
            e->rows[r] = i;
            for (size_t x = e->row_start[i]; x < e->row_start[i + 1]; x++) {
                const size_t q = e->psum[x] / PAIR * 2 + e->psum[x] % 2; /* internal index */
                e->Cm[r * ns + q] = e->pC[x];
                if (e->Dm)
                    e->Dm[r * ns + q] = e->pD[x];
            }
            r++;
        }
    }
    *out = e;
    return 0;
}

/* Adds the parts of the pair of sums at internal indices q, q + 1 (their
 * block pr) to a row of the matrix form: lanes w of C Re S, d of D Im S (Dr
 * NULL: no D).  update_W and dmi_exp_advance both sum a row through it, so
 * the two give the same bits by construction. */
static inline void add_pair(const double *Cr, const double *Dr, size_t q, const double *pr,
                            double w[2], double d[2])
{
    for (int c = 0; c < 2; c++)
        w[c] += Cr[q + c] * pr[F_SRE + c];
    if (Dr)
        for (int c = 0; c < 2; c++)
            d[c] += Dr[q + c] * pr[F_SIM + c];
}

/* A row of W in the matrix form from its partial sums: lanes w of the C
 * parts, d of the D parts (NULL: none). */
static double row_total(const double w[2], const double d[2], double h)
{
    return d ? ((w[0] + d[0]) + (w[1] + d[1])) * h : (w[0] + w[1]) * h;
}

/* W = h sum of the parts, row by row (each row in locals, written once).
 * Two partial sums in a fixed order (even and odd internal indices in the
 * matrix form, each with its C and D parts apart: add_pair), so a long row
 * (a dense block) is not one chain of dependent additions; without D (no
 * sine part in any term) the imaginary parts are not read.  A pad's entries
 * are 0 and its sums finite, so it adds +-0, which leaves any sum that
 * starts at +0 unchanged. */
static void update_W(dmi_exp *e)
{
    const double *S = e->pair, *C = e->pC, *D = e->pD;
    const size_t *ps = e->psum, ns = e->cap;
    if (e->Cm) { /* the matrix form: no indices (the other rows stay 0) */
        for (size_t r = 0; r < e->nrows; r++) {
            const double *Cr = e->Cm + r * ns, *Dr = e->Dm ? e->Dm + r * ns : NULL;
            double w[2] = {0, 0}, d[2] = {0, 0};
            for (size_t q = 0; q < ns; q += 2)
                add_pair(Cr, Dr, q, S + PAIR * (q / 2), w, d);
            e->W[e->rows[r]] = row_total(w, Dr ? d : NULL, e->h);
        }
        return;
    }
    for (size_t i = 0; i < e->n; i++) {
        const size_t end = e->row_start[i + 1];
        size_t q = e->row_start[i];
        double w0 = 0, w1 = 0;
        if (e->has_D) {
            for (; q + 1 < end; q += 2) {
                w0 += C[q] * S[ps[q]] + D[q] * S[ps[q] + (F_SIM - F_SRE)];
                w1 += C[q + 1] * S[ps[q + 1]] + D[q + 1] * S[ps[q + 1] + (F_SIM - F_SRE)];
            }
            if (q < end)
                w0 += C[q] * S[ps[q]] + D[q] * S[ps[q] + (F_SIM - F_SRE)];
        } else {
            for (; q + 1 < end; q += 2) {
                w0 += C[q] * S[ps[q]];
                w1 += C[q + 1] * S[ps[q + 1]];
            }
            if (q < end)
                w0 += C[q] * S[ps[q]];
        }
        e->W[i] = (w0 + w1) * e->h;
    }
}

/* The internal index of the k-th sum (k < nsums). */
static size_t internal(const dmi_exp *e, size_t k)
{
    return k < e->nreal ? k : e->nreal2 + (k - e->nreal);
}

/* The step after p at which the sums are anchored next. */
static void set_next(dmi_exp *e, uint64_t p)
{
    e->next = p - p % e->period + e->period;
}

void dmi_exp_anchor(dmi_exp *e, const dmi_history *r, uint64_t p)
{
    set_next(e, p);
    for (size_t k = 0; k < e->nsums; k++) {
        const size_t q = internal(e, k);
        const term *t = &e->terms[e->term_of[q]];
        const double *u = dmi_history_series(r, e->col[q]); /* u[l] = U^{p-l} */
        /* lanes c = 0, 1: the real and imaginary parts, each summed error-free
         * (two_sum into hi, its rounding into lo), side by side (vector
         * operations; a real sum's lane 1 stays 0) */
        double hi[2] = {0, 0}, lo[2] = {0, 0};
        const double *keep = t->keep; /* (read from memory: both lanes multiply) */
        cdd base = cdd_one(); /* r^l0 */
        for (size_t l0 = 0; l0 < e->N; l0 += BLOCK) {
            const double br = base.re.hi, bi = base.im.hi;
            if (fabs(br) + fabs(bi) < TINY)
                break;
            const size_t len = e->N - l0 < BLOCK ? e->N - l0 : BLOCK;
            const double *ul = u + l0;
            for (size_t i = 0; i < len; i++) {
                /* the weight r^(l0 + i) = (br + i bi) r^i: re = br Re r^i - bi Im r^i,
                 * im = br Im r^i + bi Re r^i */
                const double *T = t->tab + 2 * i, *X = t->tabx + 2 * i;
                double w[2];
                for (int c = 0; c < 2; c++)
                    w[c] = (br * T[c] + bi * X[c]) * keep[c];
                for (int c = 0; c < 2; c++) {
                    const double x = w[c] * ul[i], sum = hi[c] + x, bb = sum - hi[c];
                    lo[c] += (hi[c] - (sum - bb)) + (x - bb);
                    hi[c] = sum;
                }
            }
            base = cdd_mul(base, t->rB);
        }
        *field(e, q, F_SRE) = hi[0] + lo[0];
        *field(e, q, F_SIM) = hi[1] + lo[1];
    }
    update_W(e);
}

void dmi_exp_advance(dmi_exp *e, const dmi_history *r, uint64_t p)
{
    if (p == e->next) {
        dmi_exp_anchor(e, r, p);
        return;
    }
    const double *buf = r->buf + r->head;
    const size_t N = e->N, nr = e->nreal2, ns = e->cap, *off = e->series;
    /* W's one row of the matrix form, if so, is summed here as the sums are
     * made, by update_W's add_pair */
    const double *Cr = e->nrows == 1 ? e->Cm : NULL, *Dr = Cr ? e->Dm : NULL;
    double w[2] = {0, 0}, d[2] = {0, 0};
    { /* (v, restrict, is the only access to the pairs in this block) */
        double *restrict v = e->pair;
        /* two sums at a time: vector operations */
        for (size_t q = 0; q < nr; q += 2, v += PAIR) {
            double a[2];
            for (int c = 0; c < 2; c++) {
                const double unew = buf[off[q + c]], uold = buf[off[q + c] + N], x = v[F_SRE + c];
                a[c] = x * v[F_HR + c] + (x * v[F_LR + c] + (unew - v[F_RNR + c] * uold));
            }
            for (int c = 0; c < 2; c++)
                v[F_SRE + c] = a[c];
            if (Cr)
                add_pair(Cr, Dr, q, v, w, d);
        }
        for (size_t q = nr; q < ns; q += 2, v += PAIR) {
            double a[2], b[2];
            for (int c = 0; c < 2; c++) {
                const double unew = buf[off[q + c]], uold = buf[off[q + c] + N], x = v[F_SRE + c],
                             y = v[F_SIM + c];
                a[c] = (x * v[F_HR + c] - y * v[F_HI + c]) +
                       ((x * v[F_LR + c] - y * v[F_LI + c]) + (unew - v[F_RNR + c] * uold));
                b[c] = (x * v[F_HI + c] + y * v[F_HR + c]) +
                       ((x * v[F_LI + c] + y * v[F_LR + c]) + (0.0 - v[F_RNI + c] * uold));
            }
            for (int c = 0; c < 2; c++) {
                v[F_SRE + c] = a[c];
                v[F_SIM + c] = b[c];
            }
            if (Cr)
                add_pair(Cr, Dr, q, v, w, d);
        }
    }
    if (!Cr) {
        update_W(e);
        return;
    }
    e->W[e->rows[0]] = row_total(w, Dr ? d : NULL, e->h);
}

const double *dmi_exp_sum(const dmi_exp *e)
{
    return e->W;
}

uint64_t dmi_exp_period(const dmi_exp *e)
{
    return e->period;
}

void dmi_exp_get(const dmi_exp *e, unsigned char *bytes)
{
    for (size_t k = 0; k < e->nsums; k++) {
        const size_t q = internal(e, k), s = e->slot[q];
        memcpy(bytes + 2 * s * sizeof(double), field(e, q, F_SRE), sizeof(double));
        memcpy(bytes + (2 * s + 1) * sizeof(double), field(e, q, F_SIM), sizeof(double));
    }
}

void dmi_exp_set(dmi_exp *e, const double *sums, uint64_t p)
{
    set_next(e, p);
    for (size_t k = 0; k < e->nsums; k++) {
        const size_t q = internal(e, k);
        *field(e, q, F_SRE) = sums[2 * e->slot[q]];
        /* (a real sum's imaginary part is 0, whatever the bytes say) */
        *field(e, q, F_SIM) = k < e->nreal ? 0.0 : sums[2 * e->slot[q] + 1];
    }
    update_W(e);
}
