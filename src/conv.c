/*
 * The FFT method of the delay sum W^p = h sum_{l=0}^{N-1} H(l h) U^{p-l}:
 * an exact online block convolution (non-uniformly partitioned overlap-save
 * with a frequency-domain delay line per block size).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Layout of the lags.  The lags l = 0..N-1 are cut into
 *   - a direct head [0, S_1 - 1) and a direct tail [tail, N), summed every step;
 *   - partitions of block sizes S_1 < S_2 < ... < S_L (powers of two).  A
 *     partition of size S and index k holds the lags [S-1 + kS, S-1 + (k+1)S).
 * The sizes grow from the head (S_i's partitions fill [S_i - 1, S_{i+1} - 1)),
 * S_L fills the middle, and the sizes shrink again towards lag N, so that
 * every partition ends at least S before N + 1.
 *
 * Block convolution.  For size S and block j (the outputs p = jS .. jS+S-1)
 * the window b holds the 2S states U^m, m = (b-1)S + 1 .. (b+1)S, and the
 * partition k contributes to block j through the window b = j - 1 - k: its
 * part of the outputs is the upper half of the cyclic convolution (length
 * M = 2S) of the window with the partition's kernel samples (overlap-save).
 * The spectra of the windows b = j-depth .. j-1 are kept per component in a
 * ring (the frequency-domain delay line), so each block costs one forward FFT
 * per kernel column, one complex multiply-add per partition and nonzero
 * kernel entry, and one inverse FFT per kernel row.
 *
 * Exactness of restarts.  Everything the engine holds at step p is a function
 * of (p, the kernel, the stored states U^{p-N..p}): the window spectra and the
 * block sums are computed by the same code from the same numbers whether they
 * are updated step by step or rebuilt from the history ring, because every
 * window of a partition that ends S before N + 1 stays inside the ring until
 * its block is over.  So dmi_conv_rebuild after a state load or a change of
 * method gives bitwise the engine of an uninterrupted run.  The history z is
 * no exception: dmi_init rebuilds the engine at p = 0, so the history's FFT
 * part is transformed before the first step.
 */
#include "conv.h"

#include "bytes.h"

#include <gsl/gsl_fft_halfcomplex.h>
#include <gsl/gsl_fft_real.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/*
 * Cost model of one step in nanoseconds, fitted (least squares) to the CPU
 * time per step of Example 4.3 run with 16 layouts at each of N = 1000, 9991,
 * 100000 (GCC 12 -O2, x86-64): per lag and nonzero kernel entry of the
 * engine's direct head and tail, per partition and nonzero entry (M/2 complex
 * multiply-adds every S steps), per FFT of a used row or column (two per
 * block of S steps), and a fixed cost per block size.  The fit was made with
 * GSL's radix-2 FFT (in use) and one product per multiply-add pass;
 * COST_PART is that fit scaled by the instruction count (callgrind) of the
 * paired multiply-add now in use (0.9).
 * Past length M = 4096 (32 KiB of data) a radix-2 FFT leaves the L1 cache
 * and its cost per step of the block, flat below, grows: measured on two
 * x86-64 machines (GSL 2.7), M = 8192 costs 1.6 to 2.8 times as much per
 * step as M = 4096, and every further doubling adds 0.5 to 1.2 times the
 * cost at 4096, so the model charges an FFT of block size S > 2048 as
 * 1 + log2(S / 2048) FFTs (fft_weight).
 * COST_DIRECT is the lag of the plain sum (DMI_CONV_DIRECT).  DMI_CONV_AUTO
 * takes the FFT method when the model says it is cheaper: for one nonzero
 * kernel entry (the oscillator) from N = 382 on, for a full 3 x 3 kernel
 * from N = 174 on.
 */
#define COST_LAG 0.58
#define COST_PART 2.45
#define COST_FFT 40.4
#define COST_LEVEL 13.0
#define COST_DIRECT 0.42

/* ---- layout ---------------------------------------------------------------- */

#define MAX_LEVELS 8

typedef struct {
    size_t L;
    size_t S[MAX_LEVELS];
    size_t kfirst[MAX_LEVELS][2], kcount[MAX_LEVELS][2]; /* [0] front run, [1] back run */
    size_t head, tail;
} layout;

/* A partition of size S starting at lag a fits if it ends S before N + 1. */
static int fits(size_t a, size_t S, size_t N)
{
    return a + 2 * S <= N + 1;
}

/* Lays out the sizes S_1 = s1, S_{i+1} = g S_i, i < L; 0 if impossible. */
static int make_layout(size_t N, size_t s1, size_t g, size_t L, layout *out)
{
    layout y;
    memset(&y, 0, sizeof y);
    y.L = L;
    size_t pos = s1 - 1;
    y.head = pos;
    for (size_t i = 0; i < L; i++) {
        size_t S = i == 0 ? s1 : y.S[i - 1] * g;
        y.S[i] = S;
        y.kfirst[i][0] = (pos + 1) / S - 1;
        if (i + 1 < L) {
            size_t target = S * g - 1;
            for (; pos < target; pos += S) {
                if (!fits(pos, S, N))
                    return 0;
                y.kcount[i][0]++;
            }
        } else { /* as many as fit, counted without a loop (N may be huge) */
            if (!fits(pos, S, N))
                return 0;
            y.kcount[i][0] = (N + 1 - 2 * S - pos) / S + 1;
            pos += y.kcount[i][0] * S;
        }
    }
    for (size_t i = L - 1; i-- > 0;) {
        size_t S = y.S[i];
        y.kfirst[i][1] = (pos + 1) / S - 1;
        for (; fits(pos, S, N); pos += S)
            y.kcount[i][1]++;
    }
    y.tail = pos;
    *out = y;
    return 1;
}

/* Cost of an FFT of block size S in units of COST_FFT (see above). */
static double fft_weight(size_t S)
{
    double w = 1.0;
    for (; S > 2048; S /= 2)
        w += 1.0;
    return w;
}

static double layout_cost(const layout *y, size_t N, size_t nnz, size_t ffts)
{
    double c = COST_LAG * (double)nnz * (double)(y->head + (N - y->tail));
    for (size_t i = 0; i < y->L; i++)
        c += COST_LEVEL + COST_FFT * fft_weight(y->S[i]) * (double)ffts +
             COST_PART * (double)nnz * (double)(y->kcount[i][0] + y->kcount[i][1]);
    return c;
}

/* The cheapest layout with at least one level; 0 if none fits. */
static int best_layout(size_t N, size_t nnz, size_t ffts, layout *best)
{

    double best_cost = 0;
    int found = 0;
    for (size_t s1 = 4; s1 <= 4096 && s1 <= N; s1 *= 2)
        for (size_t g = 2; g <= 256; g *= 2)
            for (size_t L = g == 2 ? 1 : 2; L <= MAX_LEVELS; L++) { /* (L = 1: any g) */
                layout y;
                if (!make_layout(N, s1, g, L, &y))
                    break;
                double c = layout_cost(&y, N, nnz, ffts);
                if (!found || c < best_cost) {
                    best_cost = c;
                    *best = y;
                    found = 1;
                }
            }
    return found;
}

/* ---- the engine -------------------------------------------------------------- */

typedef struct {
    size_t S, M;          /* block size and FFT length 2S */
    size_t nparts, depth; /* partitions; windows kept (largest k + 1) */
    size_t *k;            /* partition indices */
    double *kspec;        /* nspec * nparts * M: kernel spectra / M (split layout) */
    double *xspec;        /* ncols * depth * M: spectrum of window b in slot b mod depth */
    double *out;          /* n * S: block sums (before the factor h) of the current block */
} level;

/*
 * Low-rank kernels.  When the N-sample series of the kernel's nnz entries
 * span only r dimensions (H(s) = G(s) B, or a few relaxation functions times
 * constant matrices: a modal model with viscoelastic parts), each entry is
 * s_e = sum_k c_ek q_k with q_k orthonormal series, and
 *     W_i = h sum_{e in row i} sum_k c_ek (q_k * U_col(e))(p).
 * The engine then convolves the virtual kernel whose entry (row k n + j,
 * column j) is q_k, for the columns j that some entry with c_ek != 0 uses:
 * at most r n entries instead of nnz, so one forward transform per state
 * column, one inverse per virtual row and r ncols products per partition,
 * with the spectra of the r series only (shared by the columns, so they
 * stay in cache); W costs nnz r multiply-adds more.  The series are found
 * by Gram-Schmidt (each projection done twice) in the entries' order; an
 * entry is represented when its residual's sum of |.| is at most LOWRANK_TOL
 * of its samples' (so W moves by at most LOWRANK_TOL of
 * h sum_l ||H(l h)|| max |U|); the virtual kernel is used only when it has
 * at most half the entries.  The engine's state stays a function of (p, the
 * kernel, the ring): rebuilds are exact as before.
 */
#define LOWRANK_TOL 1e-14
#define LOWRANK_MAX 8 /* basis series at most */

typedef struct {
    size_t r;          /* basis series (0: not in use) */
    size_t n;          /* the real n */
    dmi_kernel kv;     /* the virtual kernel, kv.n = r n */
    size_t *tstart;    /* n + 1: the terms of row i are [tstart[i], tstart[i + 1]) */
    size_t *tv;        /* per term: its virtual row */
    double *tc;        /* per term: its coefficient c_ek */
    double *Y;         /* r n: the virtual rows' sums (scratch of dmi_conv_sum) */
} lowrank;

struct dmi_conv {
    lowrank z;
    size_t n, N, nnz;
    size_t head, tail;
    size_t nlevels;
    level lv[MAX_LEVELS];
    size_t ncols;                       /* kernel columns used */
    size_t *col_slot;                   /* n: 1 + index of a used column among them, 0 */
    unsigned char *row_used;            /* n */
    double *acc;                        /* M of the largest level */
    double *zero;                       /* M of the largest level: zeros, the partner of an
                                           unpaired product in multiply_add2 */
};

/*
 * Spectra are kept in a split layout: the real parts re_0 .. re_{M/2-1} at
 * [0, M/2), the real re_{M/2} at M/2 (the slot of im_0), the imaginary parts
 * im_1 .. im_{M/2-1} at [M/2 + 1, M), so the multiply-add is a plain loop
 * over the bins.  The transforms are GSL's radix-2 real FFTs, in place; their
 * halfcomplex layout re_0 .. re_{M/2}, im_{M/2-1} .. im_1 differs from the
 * split layout only by the order of the imaginary parts, which is reversed in
 * place.  They allocate nothing and, M being a power of two, have no error
 * path: GSL's error handler (which aborts by default) is never reached.
 * GSL's mixed-radix FFT is faster (about 12 % at N = 9991) but its
 * wavetables are allocated by functions that call that handler when malloc
 * fails, and the library must never abort.
 */
static void reverse_imaginary(double *x, size_t M)
{
    for (size_t a = M / 2 + 1, b = M - 1; a < b; a++, b--) {
        double t = x[a];
        x[a] = x[b];
        x[b] = t;
    }
}

/* x (M values) -> its spectrum, split layout. */
static void forward(double *x, size_t M)
{
    gsl_fft_real_radix2_transform(x, 1, M);
    reverse_imaginary(x, M);
}

/* x (split layout) -> its unscaled inverse transform (M values). */
static void backward(double *x, size_t M)
{
    reverse_imaginary(x, M);
    gsl_fft_halfcomplex_radix2_backward(x, 1, M);
}

/* acc += K1 * X1 + K2 * X2 bin by bin (split layout; M/2 even).  Two
 * products per pass halve the loads and stores of acc.  Bin 0 (re_0 and
 * re_{M/2}) goes through the complex loop too and is then corrected; the
 * loop is unrolled by two bins for the SLP vectoriser. */
static void multiply_add2(double *restrict acc, const double *restrict K1,
                          const double *restrict X1, const double *restrict K2,
                          const double *restrict X2, size_t M)
{
    const size_t H = M / 2;
    const double a0 = acc[0] + (K1[0] * X1[0] + K2[0] * X2[0]);
    const double aH = acc[H] + (K1[H] * X1[H] + K2[H] * X2[H]);
    double *restrict ar = acc, *restrict ai = acc + H;
    const double *kr = K1, *ki = K1 + H, *xr = X1, *xi = X1 + H;
    const double *lr = K2, *li = K2 + H, *yr = X2, *yi = X2 + H;
    for (size_t q = 0; q < H; q += 2) {
        double r0 = (kr[q] * xr[q] - ki[q] * xi[q]) + (lr[q] * yr[q] - li[q] * yi[q]);
        double r1 = (kr[q + 1] * xr[q + 1] - ki[q + 1] * xi[q + 1]) +
                    (lr[q + 1] * yr[q + 1] - li[q + 1] * yi[q + 1]);
        double i0 = (kr[q] * xi[q] + ki[q] * xr[q]) + (lr[q] * yi[q] + li[q] * yr[q]);
        double i1 = (kr[q + 1] * xi[q + 1] + ki[q + 1] * xr[q + 1]) +
                    (lr[q + 1] * yi[q + 1] + li[q + 1] * yr[q + 1]);
        ar[q] += r0;
        ar[q + 1] += r1;
        ai[q] += i0;
        ai[q + 1] += i1;
    }
    acc[0] = a0;
    acc[H] = aH;
}

void dmi_conv_free(dmi_conv *c)
{
    if (!c)
        return;
    for (size_t i = 0; i < c->nlevels; i++) {
        free(c->lv[i].k);
        free(c->lv[i].kspec);
        free(c->lv[i].xspec);
        free(c->lv[i].out);
    }
    free(c->col_slot);
    free(c->row_used);
    dmi_kernel_release(&c->z.kv);
    free(c->z.tstart);
    free(c->z.tv);
    free(c->z.tc);
    free(c->z.Y);
    free(c->acc);
    free(c->zero);
    free(c);
}

/* a * b doubles, zeroed if zero; NULL if out of memory or the size
 * overflows.  a, b >= 1; a product passed as a or b (nparts M, ncols depth)
 * is bounded by the ring's size, which dmi_create checked. */
static double *doubles(size_t a, size_t b, int zero)
{
    size_t bytes = dmi_mul_size(a, b, sizeof(double));
    if (bytes == 0)
        return NULL;
    return zero ? calloc(1, bytes) : malloc(bytes);
}

static int level_alloc(level *v, const layout *y, size_t i, size_t n, size_t ncols, size_t nspec)
{
    v->S = y->S[i];
    v->M = 2 * v->S;
    v->nparts = y->kcount[i][0] + y->kcount[i][1];
    v->k = malloc(v->nparts * sizeof *v->k);
    if (!v->k)
        return -1;
    size_t q = 0;
    for (int run = 0; run < 2; run++)
        for (size_t t = 0; t < y->kcount[i][run]; t++)
            v->k[q++] = y->kfirst[i][run] + t;
    v->depth = v->k[v->nparts - 1] + 1;
    /* nparts M <= 2 (N + 1) and depth M <= 2 (N + 1 + S): a few times the
     * kernel samples and the ring, which may still overflow size_t on a
     * 32-bit target. */
    v->kspec = doubles(nspec, v->nparts * v->M, 0);
    v->xspec = doubles(ncols * v->depth, v->M, 1);
    v->out = doubles(n, v->S, 1);
    return v->kspec && v->xspec && v->out ? 0 : -1;
}

/* Spectrum / M of the kernel samples of each distinct series on the
 * partition's lags: those of the entries of k, or of a low-rank form's r
 * basis series (virtual entry e has series kv.row[e] / n). */
static void kernel_spectra(level *v, const dmi_kernel *k, const lowrank *z)
{
    const size_t S = v->S, M = v->M;
    for (size_t e = 0; e < k->nnz; e++) {
        if (z->r && e > 0 && k->row[e] / z->n == k->row[e - 1] / z->n)
            continue; /* (the entries of a basis series are contiguous) */
        const size_t sp = z->r ? k->row[e] / z->n : e;
        for (size_t q = 0; q < v->nparts; q++) {
            double *x = v->kspec + (sp * v->nparts + q) * M;
            const double *h = k->samples + e * k->N + (S - 1 + v->k[q] * S);
            for (size_t t = 0; t < S; t++)
                x[t] = h[t] / (double)M;
            memset(x + S, 0, S * sizeof *x);
            forward(x, M);
        }
    }
}

/* sum |x_l|, l < N. */
static double norm1(const double *x, size_t N)
{
    double a = 0;
    for (size_t l = 0; l < N; l++)
        a += fabs(x[l]);
    return a;
}

/* The low-rank form of k in z (see above): 1 made, 0 not low rank enough
 * (z empty), -1 out of memory. */
static int lowrank_make(lowrank *z, const dmi_kernel *k, size_t n, size_t ncols)
{
    memset(z, 0, sizeof *z);
    const size_t N = k->N, nnz = k->nnz;
    size_t rmax = ncols ? nnz / (2 * ncols) : 0;
    if (rmax > LOWRANK_MAX)
        rmax = LOWRANK_MAX;
    if (rmax == 0)
        return 0;
    double *q = doubles(rmax + 1, N, 0), *c = doubles(nnz, rmax, 1);
    if (!q || !c) {
        free(q);
        free(c);
        return -1;
    }
    size_t r = 0;
    int ok = 1;
    double *res = q + rmax * N; /* the residual of the entry at hand */
    for (size_t e = 0; e < nnz && ok; e++) {
        const double *x = k->samples + e * N;
        memcpy(res, x, N * sizeof *res);
        for (int pass = 0; pass < 2; pass++)
            for (size_t b = 0; b < r; b++) {
                const double *qb = q + b * N;
                double d = dmi_dot(qb, res, N);
                for (size_t l = 0; l < N; l++)
                    res[l] -= d * qb[l];
                c[e * rmax + b] += d;
            }
        const double len = sqrt(dmi_dot(res, res, N)), size = norm1(x, N);
        if (!isfinite(size) || !isfinite(len)) { /* (samples near DBL_MAX) */
            ok = 0;
            break;
        }
        if (norm1(res, N) <= LOWRANK_TOL * size)
            continue;
        if (r == rmax) {
            ok = 0;
            break;
        }
        for (size_t l = 0; l < N; l++)
            q[r * N + l] = res[l] / len;
        c[e * rmax + r] = len;
        r++;
    }
    /* the virtual entries (b, j) that some c_ej != 0 uses */
    size_t nv = 0;
    unsigned char *used = ok ? calloc(rmax * n, 1) : NULL;
    if (ok && used)
        for (size_t e = 0; e < nnz; e++)
            for (size_t b = 0; b < r; b++)
                if (c[e * rmax + b] != 0 && !used[b * n + k->col[e]]) {
                    used[b * n + k->col[e]] = 1;
                    nv++;
                }
    if (!ok || !used || r == 0 || 2 * nv > nnz) {
        free(q);
        free(c);
        free(used);
        return ok && !used ? -1 : 0;
    }
    size_t terms = 0;
    for (size_t e = 0; e < nnz * rmax; e++)
        terms += c[e] != 0;
    z->r = r;
    z->n = n;
    z->kv.n = r * n;
    z->kv.N = N;
    z->kv.row = malloc(nv * sizeof *z->kv.row);
    z->kv.col = malloc(nv * sizeof *z->kv.col);
    z->kv.samples = doubles(nv, N, 0);
    z->tstart = malloc((n + 1) * sizeof *z->tstart);
    z->tv = malloc((terms ? terms : 1) * sizeof *z->tv);
    z->tc = malloc((terms ? terms : 1) * sizeof *z->tc);
    z->Y = doubles(r, n, 1);
    int rc = z->kv.row && z->kv.col && z->kv.samples && z->tstart && z->tv && z->tc && z->Y;
    if (rc) {
        size_t v = 0; /* rows b n + j ascending: the entries of a row contiguous */
        for (size_t b = 0; b < r; b++)
            for (size_t j = 0; j < n; j++)
                if (used[b * n + j]) {
                    z->kv.row[v] = b * n + j;
                    z->kv.col[v] = j;
                    memcpy(z->kv.samples + v * N, q + b * N, N * sizeof *q);
                    v++;
                }
        z->kv.nnz = nv;
        size_t t = 0, e = 0; /* the entries of a row are contiguous in k */
        for (size_t i = 0; i < n; i++) {
            z->tstart[i] = t;
            for (; e < nnz && k->row[e] == i; e++)
                for (size_t b = 0; b < r; b++)
                    if (c[e * rmax + b] != 0) {
                        z->tv[t] = b * n + k->col[e];
                        z->tc[t] = c[e * rmax + b];
                        t++;
                    }
        }
        z->tstart[n] = t;
    }
    free(q);
    free(c);
    free(used);
    if (!rc) {
        dmi_kernel_release(&z->kv);
        free(z->tstart);
        free(z->tv);
        free(z->tc);
        free(z->Y);
        memset(z, 0, sizeof *z);
        return -1;
    }
    return 1;
}

/* The used columns (cu[j] = 1 + their index, 0 if unused) and rows of k;
 * *ncols columns used, *ffts transforms per block (columns and rows). */
static void usage(const dmi_kernel *k, size_t *cu, unsigned char *ru, size_t *ncols, size_t *ffts)
{
    *ffts = *ncols = 0;
    for (size_t e = 0; e < k->nnz; e++) {
        if (!cu[k->col[e]])
            cu[k->col[e]] = ++*ncols;
        *ffts += !ru[k->row[e]];
        ru[k->row[e]] = 1;
    }
    *ffts += *ncols;
}

int dmi_conv_create(dmi_conv **out, const dmi_kernel *k, size_t n, size_t N, int method)
{
    *out = NULL;
    if (method == DMI_CONV_DIRECT)
        return 0;
    lowrank z;
    size_t *cu = calloc(n, sizeof *cu), ncols, ffts;
    unsigned char *ru = calloc(n, 1);
    int lr = cu && ru ? 0 : -1;
    if (lr == 0) {
        usage(k, cu, ru, &ncols, &ffts);
        lr = lowrank_make(&z, k, n, ncols);
    }
    const dmi_kernel *kk = k; /* the kernel the engine convolves */
    size_t nn = n;
    if (lr == 1) { /* the virtual kernel's rows and columns */
        kk = &z.kv;
        nn = z.kv.n;
        free(cu);
        free(ru);
        cu = calloc(nn, sizeof *cu);
        ru = calloc(nn, 1);
        if (cu && ru)
            usage(kk, cu, ru, &ncols, &ffts);
    }
    dmi_conv *c = lr >= 0 && cu && ru ? calloc(1, sizeof *c) : NULL;
    if (!c) {
        free(cu);
        free(ru);
        if (lr == 1) {
            c = calloc(1, sizeof *c); /* (only to free z through dmi_conv_free) */
            if (c)
                c->z = z;
            dmi_conv_free(c);
        }
        return -1;
    }
    if (lr == 1)
        c->z = z;
    c->n = nn;
    c->N = N;
    c->nnz = kk->nnz;
    c->ncols = ncols;
    c->col_slot = cu;
    c->row_used = ru;
    layout y;
    int have = kk->nnz > 0 && best_layout(N, kk->nnz, ffts, &y);
    /* the low-rank form adds nnz r multiply-adds per step, priced as lags */
    double extra = lr == 1 ? COST_LAG * (double)z.tstart[n] : 0;
    if (method == DMI_CONV_AUTO &&
        (!have || layout_cost(&y, N, kk->nnz, ffts) + extra >=
                      COST_DIRECT * (double)k->nnz * (double)N)) {
        dmi_conv_free(c);
        return 0;
    }
    if (!have) { /* no kernel, or too short for any block: only direct sums */
        memset(&y, 0, sizeof y);
        y.head = y.tail = N;
    }
    c->head = y.head;
    c->tail = y.tail;
    int rc = 0;
    for (size_t i = 0; i < y.L && rc == 0; i++) {
        c->nlevels = i + 1;
        rc = level_alloc(&c->lv[i], &y, i, nn, ncols, lr == 1 ? z.r : kk->nnz);
    }
    c->acc = malloc((y.L ? 2 * y.S[y.L - 1] : 1) * sizeof *c->acc);
    c->zero = calloc(y.L ? 2 * y.S[y.L - 1] : 1, sizeof *c->zero);
    if (rc != 0 || !c->acc || !c->zero) {
        dmi_conv_free(c);
        return -1;
    }
    for (size_t i = 0; i < c->nlevels; i++)
        kernel_spectra(&c->lv[i], kk, &c->z);
    *out = c;
    return 0;
}

/* The kernel c convolves: the virtual one of a low-rank form, or k. */
static const dmi_kernel *convolved(const dmi_conv *c, const dmi_kernel *k)
{
    return c->z.r ? &c->z.kv : k;
}

/* Spectra of window b of the used columns into its slot; the window's oldest
 * state U^{(b-1)S+1} is at lag `lag0` of the ring. */
static void window(const dmi_conv *c, level *v, const dmi_history *r, size_t lag0, size_t slot)
{
    for (size_t col = 0; col < c->n; col++) {
        if (!c->col_slot[col])
            continue;
        double *x = v->xspec + ((c->col_slot[col] - 1) * v->depth + slot) * v->M;
        const double *u = dmi_history_series(r, col) + lag0; /* u[-t] = U^{(b-1)S+1+t} */
        for (size_t t = 0; t < v->M; t++)
            x[t] = *(u - t);
        forward(x, v->M);
    }
}

/* The block sums of block j from the windows j-1-k in the delay line. */
static void block(const dmi_conv *c, level *v, const dmi_kernel *k, uint64_t j, double *acc)
{
    const size_t M = v->M, S = v->S;
    const size_t base = (size_t)(j % v->depth) + v->depth - 1;
    for (size_t i = 0; i < c->n; i++) {
        if (!c->row_used[i])
            continue;
        memset(acc, 0, M * sizeof *acc);
        const double *K1 = NULL, *X1 = NULL; /* a product waiting for its partner */
        for (size_t e = 0; e < k->nnz; e++) {
            if (k->row[e] != i)
                continue;
            const double *xs = v->xspec + (c->col_slot[k->col[e]] - 1) * v->depth * M;
            const size_t sp = c->z.r ? k->row[e] / c->z.n : e; /* its spectra */
            for (size_t q = 0; q < v->nparts; q++) {
                size_t slot = base - v->k[q]; /* (j - 1 - k) mod depth */
                if (slot >= v->depth)
                    slot -= v->depth;
                const double *K = v->kspec + (sp * v->nparts + q) * M, *X = xs + slot * M;
                if (!K1) {
                    K1 = K;
                    X1 = X;
                } else {
                    multiply_add2(acc, K1, X1, K, X, M);
                    K1 = NULL;
                }
            }
        }
        if (K1)
            multiply_add2(acc, K1, X1, c->zero, c->zero, M);
        backward(acc, M);
        memcpy(v->out + i * S, acc + S, S * sizeof *acc);
    }
}

void dmi_conv_rebuild(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p)
{
    k = convolved(c, k);
    for (size_t i = 0; i < c->nlevels; i++) {
        level *v = &c->lv[i];
        const size_t S = v->S;
        const uint64_t j = p / S;
        const size_t rem = (size_t)(p - j * S);
        for (size_t t = 0; t < v->depth; t++) { /* window b = j - depth + t */
            size_t lag0 = rem + (v->depth - t + 1) * S - 1;
            size_t slot = (size_t)((j + t) % v->depth);
            window(c, v, r, lag0, slot);
        }
        block(c, v, k, j, c->acc);
    }
}

void dmi_conv_advance(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p)
{
    if (c->nlevels == 0 || (p & (c->lv[0].S - 1)) != 0) /* the sizes are multiples of S_1 */
        return;
    k = convolved(c, k);
    for (size_t i = 0; i < c->nlevels; i++) {
        level *v = &c->lv[i];
        if ((p & (v->S - 1)) != 0) /* S is a power of two */
            continue;
        const uint64_t j = p / v->S; /* new window b = j - 1: oldest state at lag 2S - 1 */
        size_t slot = (size_t)((j + v->depth - 1) % v->depth);
        window(c, v, r, 2 * v->S - 1, slot);
        block(c, v, k, j, c->acc);
    }
}

/* The engine's sums of kernel k (W: c->n values).  Each row is summed in a
 * local and W written once (a vector load of values just stored one by one
 * stalls).  The kernel entries of a row are contiguous (dmi_kernel_alloc
 * stores them row by row). */
static void engine_sum(const dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p,
                       double h, double *W)
{
    size_t e = 0;
    for (size_t row = 0; row < c->n; row++) {
        double w = 0;
        for (; e < k->nnz && k->row[e] == row; e++) {
            const double *a = k->samples + e * k->N, *u = dmi_history_series(r, k->col[e]);
            w += dmi_dot(a, u, c->head) + dmi_dot(a + c->tail, u + c->tail, c->N - c->tail);
        }
        if (c->row_used[row])
            for (size_t i = 0; i < c->nlevels; i++) {
                const level *v = &c->lv[i];
                w += v->out[row * v->S + (size_t)(p & (v->S - 1))];
            }
        W[row] = w * h;
    }
}

void dmi_conv_sum(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p, double h,
                  double *W)
{
    const lowrank *z = &c->z;
    if (z->r) { /* the virtual rows' sums, then W_i = h sum c_ek Y_(k n + col) */
        engine_sum(c, &z->kv, r, p, 1.0, z->Y);
        for (size_t i = 0; i < z->n; i++) {
            double w = 0;
            for (size_t t = z->tstart[i]; t < z->tstart[i + 1]; t++)
                w += z->tc[t] * z->Y[z->tv[t]];
            W[i] = w * h;
        }
        return;
    }
    engine_sum(c, k, r, p, h, W);
}

size_t dmi_conv_levels(const dmi_conv *c)
{
    return c ? c->nlevels : 0;
}

size_t dmi_conv_rank(const dmi_conv *c)
{
    return c ? c->z.r : 0;
}
