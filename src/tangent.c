/*
 * libdmi's tangent of the scheme (dmi_tangent_*, see dmi.h): the states and
 * their sensitivities S = dU/dp stepped together, with the saltation factor
 * at friction reversals.  The plain run is the solver's own (dmi_step); the
 * tangent's delay sum is the solver's engine run on each column of S (a
 * shallow copy of the solver with its own window and engine), its resolvent
 * rule that of the step (holds.h).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "solver.h"

#include "bytes.h"
#include "engine.h"
#include "errors.h"
#include "holds.h"
#include "quad.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The relative step of f_u's forward-difference columns (about the square
 * root of the unit roundoff). */
#define REL_STEP 0x1p-26

/* What the tangent reads of a model at p + delta_j e_j. */
typedef struct {
    dmi_rhs_fn f;
    void *f_user;
    dmi_resolvent_fn r;
    void *r_user;
    dmi_history_fn z;
    void *z_user;
} model;

struct dmi_tangent {
    dmi_solver *s;
    size_t P;
    model *m;      /* P + 1: s's, then the others' */
    double *delta; /* P */
    int *depends;  /* P: whether f depends on p_j */
    double *dlo;   /* n P: friction's dalpha, or the box's dlo (NULL: none) */
    double *dhi;   /* n P: the box's dhi (NULL: none) */
    double *S0;    /* (N + 1) n P, or NULL: zero */
    /* the exponential kernel's terms' derivatives (dmi_tangent_set_kernel_terms; K = 0: none) */
    size_t K;
    double complex *dE; /* K n n P: d(C_k - i D_k)[i][m]/dp_j at ((k n + i) n + m) P + j */
    double complex *dl; /* K P: d(a_k + i b_k)/dp_j at k P + j */
};

/* ---- the object -------------------------------------------------------------- */

/* d = (b - a) / delta, 0 where a and b are the same infinity; -1 where d is
 * not finite. */
static int bound_diff(double a, double b, double delta, double *d)
{
    *d = a == b ? 0.0 : (b - a) / delta;
    return isfinite(*d) ? 0 : -1;
}

/* The differences of others[j]'s friction or box to s's into t->dlo, t->dhi. */
static int resolvent_diffs(dmi_tangent *t, const dmi_solver *const *others)
{
    const dmi_solver *s = t->s;
    const size_t n = s->n, P = t->P;
    if (s->a_kind != A_FRICTION && s->a_kind != A_BOX)
        return DMI_OK;
    t->dlo = malloc(n * P * sizeof *t->dlo);
    t->dhi = s->a_kind == A_BOX ? malloc(n * P * sizeof *t->dhi) : NULL;
    if (!t->dlo || (s->a_kind == A_BOX && !t->dhi))
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_create: out of memory");
    for (size_t j = 0; j < P; j++)
        for (size_t i = 0; i < n; i++) {
            const double *lo = others[j]->a_lo, *hi = others[j]->a_hi;
            if (bound_diff(s->a_lo[i], lo[i], t->delta[j], &t->dlo[i * P + j]) != 0)
                return dmi_fail(s, DMI_EINVAL, "dmi_tangent_create: others[%zu] moves %s[%zu] "
                                "from %g to %g: its derivative is not finite", j,
                                s->a_kind == A_BOX ? "the box's lo" : "the friction alpha", i,
                                s->a_lo[i], lo[i]);
            if (t->dhi && bound_diff(s->a_hi[i], hi[i], t->delta[j], &t->dhi[i * P + j]) != 0)
                return dmi_fail(s, DMI_EINVAL, "dmi_tangent_create: others[%zu] moves the box's "
                                "hi[%zu] from %g to %g: its derivative is not finite", j, i,
                                s->a_hi[i], hi[i]);
        }
    return DMI_OK;
}

/* Why others[j] cannot be a perturbed model of s ("" when it can). */
static const char *mismatch(const dmi_solver *s, const dmi_solver *o)
{
    if (o->n != s->n)
        return "another n";
    if (o->N != s->N)
        return "another N";
    if (o->h != s->h || o->theta != s->theta)
        return "another h or last cell";
    if (o->a_kind != s->a_kind)
        return "another kind of A (resolvent, friction, box, none)";
    return "";
}

int dmi_tangent_create(dmi_tangent **out, dmi_solver *s, size_t P, const dmi_solver *const *others,
                       const double *delta)
{
    if (!out)
        return DMI_EINVAL;
    *out = NULL;
    if (!s)
        return DMI_EINVAL;
    if (P == 0 || !others || !delta)
        return dmi_fail(s, DMI_EINVAL, "dmi_tangent_create: %s", P == 0 ? "P = 0 parameters"
                        : !others ? "others is NULL" : "delta is NULL");
    for (size_t j = 0; j < P; j++) {
        if (!others[j])
            return dmi_fail(s, DMI_EINVAL, "dmi_tangent_create: others[%zu] is NULL", j);
        const char *why = mismatch(s, others[j]);
        if (*why)
            return dmi_fail(s, DMI_EINVAL, "dmi_tangent_create: others[%zu] has %s than s: a "
                            "parameter may change the model's values, not its structure", j, why);
        if (!isfinite(delta[j]) || delta[j] == 0)
            return dmi_fail(s, DMI_EINVAL, "dmi_tangent_create: delta[%zu] = %g, expected a finite "
                            "nonzero step", j, delta[j]);
    }
    if (dmi_mul_size(s->n, P, sizeof(double)) == 0 || P + 1 < P)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_create: n P overflows");
    dmi_tangent *t = calloc(1, sizeof *t);
    if (!t)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_create: out of memory");
    t->s = s;
    t->P = P;
    t->m = malloc((P + 1) * sizeof *t->m);
    t->delta = malloc(P * sizeof *t->delta);
    t->depends = malloc(P * sizeof *t->depends);
    int rc = t->m && t->delta && t->depends
                 ? DMI_OK : dmi_fail(s, DMI_ENOMEM, "dmi_tangent_create: out of memory");
    if (rc == DMI_OK) {
        memcpy(t->delta, delta, P * sizeof *delta);
        t->m[0] = (model){s->f, s->f_user, s->r, s->r_user, s->z, s->z_user};
        for (size_t j = 0; j < P; j++) {
            const dmi_solver *o = others[j];
            t->m[j + 1] = (model){o->f, o->f_user, o->r, o->r_user, o->z, o->z_user};
        }
        dmi_tangent_set_rhs_parameters(t, NULL);
        rc = resolvent_diffs(t, others);
    }
    if (rc != DMI_OK) {
        dmi_tangent_free(&t);
        return rc;
    }
    *out = t;
    return DMI_OK;
}

void dmi_tangent_free(dmi_tangent **pt)
{
    if (!pt || !*pt)
        return;
    dmi_tangent *t = *pt;
    free(t->m);
    free(t->delta);
    free(t->depends);
    free(t->dlo);
    free(t->dhi);
    free(t->S0);
    free(t->dE);
    free(t->dl);
    free(t);
    *pt = NULL;
}

int dmi_tangent_set_history(dmi_tangent *t, const double *S0)
{
    if (!t)
        return DMI_EINVAL;
    const dmi_solver *s = t->s;
    if (!S0) {
        free(t->S0);
        t->S0 = NULL;
        return DMI_OK;
    }
    const size_t count = (s->N + 1) * s->n * t->P; /* (N + 1) n fits; n P fits */
    if (dmi_mul_size(s->N + 1, s->n * t->P, sizeof(double)) == 0)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_set_history: (N + 1) n P overflows");
    const size_t bad = dmi_first_nonfinite_long(S0, count);
    if (bad < count)
        return dmi_fail(s, DMI_EINVAL, "dmi_tangent_set_history: S0 row %zu, component %zu, "
                        "parameter %zu is %g", bad / (s->n * t->P), bad / t->P % s->n, bad % t->P,
                        S0[bad]);
    double *copy = malloc(count * sizeof *copy);
    if (!copy)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_set_history: out of memory");
    memcpy(copy, S0, count * sizeof *copy);
    free(t->S0);
    t->S0 = copy;
    return DMI_OK;
}

/* out = z(t) of model m (0 without z), checked; DMI_OK or the error naming
 * the model (j = 0: s, else others[j - 1]). */
static int call_z(const dmi_solver *s, const model *m, size_t j, double t, double *out)
{
    for (size_t i = 0; i < s->n; i++)
        out[i] = 0;
    const int rc = m->z ? m->z(t, out, m->z_user) : 0;
    if (rc != 0)
        return j == 0 ? dmi_fail(s, DMI_ECALLBACK, "dmi_tangent_sample_history: history callback "
                                 "of s returned %d at t = %.17g", rc, t)
                      : dmi_fail(s, DMI_ECALLBACK, "dmi_tangent_sample_history: history callback "
                                 "of others[%zu] returned %d at t = %.17g", j - 1, rc, t);
    const size_t bad = dmi_first_nonfinite(out, s->n);
    if (bad < s->n)
        return j == 0 ? dmi_fail(s, DMI_ENONFINITE, "dmi_tangent_sample_history: history z(%.17g)"
                                 "[%zu] = %g of s", t, bad, out[bad])
                      : dmi_fail(s, DMI_ENONFINITE, "dmi_tangent_sample_history: history z(%.17g)"
                                 "[%zu] = %g of others[%zu]", t, bad, out[bad], j - 1);
    return DMI_OK;
}

int dmi_tangent_sample_history(dmi_tangent *t, const int *columns)
{
    if (!t)
        return DMI_EINVAL;
    const dmi_solver *s = t->s;
    const size_t n = s->n, N = s->N, P = t->P;
    if (dmi_mul_size(N + 1, n * P, sizeof(double)) == 0)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_sample_history: (N + 1) n P overflows");
    double *S0 = calloc((N + 1) * n * P, sizeof *S0);
    double *base = malloc(2 * n * sizeof *base), *other = base ? base + n : NULL;
    int rc = S0 && base ? DMI_OK
                        : dmi_fail(s, DMI_ENOMEM, "dmi_tangent_sample_history: out of memory");
    for (size_t k = 0; k <= N && rc == DMI_OK; k++) { /* U^{-k}: row N - k */
        const double tk = dmi_history_time(s, k);
        int sampled = 0;
        for (size_t j = 0; j < P && rc == DMI_OK; j++) {
            const model *m = &t->m[j + 1];
            if (columns ? !columns[j] : m->z == t->m[0].z && m->z_user == t->m[0].z_user)
                continue;
            if (!sampled)
                rc = call_z(s, &t->m[0], 0, tk, base);
            sampled = 1;
            if (rc == DMI_OK)
                rc = call_z(s, m, j + 1, tk, other);
            for (size_t i = 0; i < n && rc == DMI_OK; i++)
                S0[((N - k) * n + i) * P + j] = (other[i] - base[i]) / t->delta[j];
        }
    }
    free(base);
    if (rc != DMI_OK) {
        free(S0);
        return rc;
    }
    free(t->S0);
    t->S0 = S0;
    return DMI_OK;
}

int dmi_tangent_set_kernel_terms(dmi_tangent *t, const double *da, const double *db,
                                 const double *dC, const double *dD)
{
    if (!t)
        return DMI_EINVAL;
    const dmi_solver *s = t->s;
    if (!da) {
        free(t->dE);
        free(t->dl);
        t->dE = t->dl = NULL;
        t->K = 0;
        return DMI_OK;
    }
    if (!db || !dC)
        return dmi_fail(s, DMI_EINVAL, "dmi_tangent_set_kernel_terms: %s is NULL", !db ? "db" : "dC");
    if (!dmi_has_expk(s))
        return dmi_fail(s, DMI_EINVAL, "dmi_tangent_set_kernel_terms: the kernel of s is not one "
                        "of dmi_set_kernel_exp");
    const size_t K = s->expk.K, n = s->n, P = t->P, KP = K * P, KnnP = K * n * n * P;
    if (dmi_mul_size(K * n * n, P, sizeof(double complex)) == 0)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_set_kernel_terms: K n n P overflows");
    const double *arrays[4] = {da, db, dC, dD};
    const char *names[4] = {"da", "db", "dC", "dD"};
    for (int a = 0; a < 4; a++) {
        const size_t count = a < 2 ? KP : KnnP;
        const size_t bad = arrays[a] ? dmi_first_nonfinite_long(arrays[a], count) : count;
        if (bad < count)
            return dmi_fail(s, DMI_EINVAL, "dmi_tangent_set_kernel_terms: %s[%zu] = %g", names[a],
                            bad, arrays[a][bad]);
    }
    double complex *dE = malloc(KnnP * sizeof *dE), *dl = malloc(KP * sizeof *dl);
    if (!dE || !dl) {
        free(dE);
        free(dl);
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_set_kernel_terms: out of memory");
    }
    for (size_t q = 0; q < KP; q++)
        dl[q] = da[q] + I * db[q];
    for (size_t q = 0; q < KnnP; q++)
        dE[q] = dC[q] - I * (dD ? dD[q] : 0.0);
    free(t->dE);
    free(t->dl);
    t->dE = dE;
    t->dl = dl;
    t->K = K;
    return DMI_OK;
}

int dmi_tangent_set_rhs_parameters(dmi_tangent *t, const int *depends)
{
    if (!t)
        return DMI_EINVAL;
    for (size_t j = 0; j < t->P; j++)
        t->depends[j] = depends ? depends[j] != 0
                                : t->m[j + 1].f != t->m[0].f || t->m[j + 1].f_user != t->m[0].f_user;
    return DMI_OK;
}

/* ---- the saltation test -------------------------------------------------------- */

/* What friction component i does in step q of a run of `steps` steps with
 * states U ((steps + 1) n) and resolvent arguments X (steps n): the
 * DMI_SWITCH_* code and, for a reversal, the saltation factor rho = F+ / F-
 * (the velocities just after and before it, phi = (U - X) / h interpolated
 * linearly at the crossing of u_i through 0).  The component slips at U^q
 * (U_i^q != 0, alpha_i > 0); it reverses when it changes sign in the step,
 * or lands at 0 and changes sign in the next; it sticks when it lands at 0
 * and stays. */
static int reversal(size_t q, size_t i, size_t n, size_t steps, const double *U, const double *X,
                    double h, double alpha, double *rho)
{
    *rho = 0;
    const double u = U[q * n + i], nxt = U[(q + 1) * n + i];
    if (u == 0 || !(alpha > 0))
        return DMI_SWITCH_NONE;
    const double sm = copysign(1.0, u);
    if (nxt * sm > 0)
        return DMI_SWITCH_NONE;
    if (nxt == 0 && !(q + 2 <= steps && U[(q + 2) * n + i] * sm < 0))
        return DMI_SWITCH_STICK;
    const double frac = u / (u - nxt);
    const double ph0 = (u - X[q * n + i]) / h;
    double ph = ph0;
    if (q + 1 < steps) {
        const double ph1 = (nxt - X[(q + 1) * n + i]) / h;
        ph = (1.0 - frac) * ph0 + frac * ph1;
    }
    const double before = sm * ph + alpha; /* -s F-: the speed towards 0 before */
    const double after = sm * ph - alpha;  /* s F+: the speed away from 0 after */
    if (before <= 0 || after <= 0)
        return DMI_SWITCH_UNPLACED;
    *rho = after / before;
    return DMI_SWITCH_REVERSAL;
}

/* ---- the run ------------------------------------------------------------------- */

/* The delay sum of the tangent: one shallow copy of the solver per
 * parameter with its own window of that column of S and its own engine. */
typedef struct {
    size_t P;
    dmi_solver *col; /* P copies of the solver (NULL: no kernel) */
    size_t made;     /* the copies whose window exists */
    double *zeros;   /* the sums of a zero window (NULL: none) */
} columns;

static void columns_free(columns *c)
{
    for (size_t j = 0; j < c->made; j++) {
        dmi_history_release(&c->col[j].ring);
        dmi_engine_free(c->col[j].conv, c->col[j].rec);
    }
    free(c->col);
    free(c->zeros);
}

/* The method of s's engine now (its engines as dmi_init or
 * dmi_set_convolution made them). */
static int engine_method(const dmi_solver *s)
{
    return s->rec ? DMI_CONV_RECURSIVE : s->conv ? s->conv_method : DMI_CONV_DIRECT;
}

static int columns_make(columns *c, const dmi_solver *s, size_t P, const double *S0, double *row)
{
    const size_t n = s->n, N = s->N;
    c->P = P;
    c->made = 0;
    c->col = NULL;
    c->zeros = NULL;
    if (!s->H)
        return DMI_OK;
    c->col = malloc(P * sizeof *c->col);
    if (!c->col)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_run: out of memory");
    /* zero sums for the recursion's engines of zero columns (2 doubles a sum) */
    const dmi_expk *x = s->quad == DMI_QUAD_CELL ? &s->cell_expk : &s->expk;
    c->zeros = s->rec ? calloc(2 * dmi_expk_sums(x) + 1, sizeof *c->zeros) : NULL;
    const double *sums = c->zeros;
    for (size_t j = 0; j < P; j++) {
        dmi_solver *col = &c->col[j];
        *col = *s;
        col->conv = NULL;
        col->rec = NULL;
        if (dmi_history_alloc(&col->ring, n, N) != 0)
            return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_run: out of memory for the windows of S");
        c->made++;
        int zero = 1; /* whether this column of S0 is zero */
        if (S0) {
            for (size_t k = 0; k <= N; k++) /* row k: S^{p-N+k} */
                for (size_t i = 0; i < n; i++) {
                    row[k * n + i] = S0[(k * n + i) * P + j];
                    zero &= row[k * n + i] == 0;
                }
            dmi_history_put_window(&col->ring, row);
        }
        int rc = dmi_engine_make(s, &s->kernel, engine_method(s), &col->conv, &col->rec,
                                 "dmi_tangent_run");
        if (rc != DMI_OK)
            return rc;
        if (zero && col->rec && sums) /* the recursion's sums of a zero window: zero, no O(N) */
            dmi_exp_set(col->rec, sums, col->p);
        else
            dmi_engine_rebuild(col, col->conv, col->rec);
    }
    return DMI_OK;
}

/* The delay sum of all P columns of S at once where the solver's engine is
 * the recursion alone (an exponential kernel, full cells, no near cells):
 * per used column c of term k (C_k or D_k nonzero in column c) and per
 * parameter j the sum Z = sum_{l<N} r_k^l S_c^{q-l}[j], stepped by
 * Z <- r Z + S^{q+1} - r^N S^{q+1-N} and started (and restarted every
 * BLOCK_PERIOD N steps) by Horner's rule over the stored rows of S; then
 * W[i][j] = h sum (C Re Z + D Im Z) over the parts of row i, as the engine
 * sums them.  r in double: the weights r^l are off by up to l units of
 * rounding, so the block is taken for N <= BLOCK_MAX_N (relative error
 * below about 1e-12 of the sum) and the engines per column beyond. */
#define BLOCK_MAX_N 4096
#define BLOCK_PERIOD 4

typedef struct {
    int on;                   /* the block is taken (else the engines per column) */
    size_t nu;                /* the sums (used columns of the terms) */
    size_t *col;              /* nu: the column of S each sum runs over */
    double *rr, *ri, *nr, *ni; /* nu: r and r^N of each sum's term */
    double *Zr, *Zi;          /* nu P: sum u of parameter j at u P + j */
    size_t nparts;
    size_t *prow, *psum;      /* per part: its row of W, its sum */
    double *pC, *pD;          /* per part: W_row += C Re Z + D Im Z */
    double *W;                /* n P: h times the sum, W[i P + j] */
    size_t since;
} block;

static void block_free(block *b)
{
    free(b->col);
    free(b->rr);
    free(b->Zr);
    free(b->prow);
    free(b->pC);
    free(b->W);
    memset(b, 0, sizeof *b);
}

/* Whether s's engine is the recursion alone at a size the block takes. */
static int block_applies(const dmi_solver *s)
{
    return s->H && s->rec && !s->near.nnz && s->theta == 1 && s->N <= BLOCK_MAX_N;
}

static int block_make(block *b, const dmi_solver *s, size_t P)
{
    memset(b, 0, sizeof *b);
    if (!block_applies(s))
        return DMI_OK;
    const dmi_expk *x = s->quad == DMI_QUAD_CELL ? &s->cell_expk : &s->expk;
    const size_t n = s->n, nn = n * n, K = x->K, N = s->N;
    size_t nu = 0, np = 0;
    for (size_t q = 0; q < K * nn; q++)
        np += x->C[q] != 0 || (x->D && x->D[q] != 0);
    for (size_t k = 0; k < K; k++)
        for (size_t c = 0; c < n; c++) {
            int used = 0;
            for (size_t i = 0; i < n; i++)
                used |= x->C[k * nn + i * n + c] != 0 || (x->D && x->D[k * nn + i * n + c] != 0);
            nu += used;
        }
    const size_t su = nu ? nu : 1, spart = np ? np : 1;
    b->col = malloc(su * sizeof *b->col);
    b->rr = malloc(4 * su * sizeof *b->rr);
    b->Zr = calloc(2 * su * P, sizeof *b->Zr);
    b->prow = malloc(2 * spart * sizeof *b->prow);
    b->pC = malloc(2 * spart * sizeof *b->pC);
    b->W = calloc(n * P, sizeof *b->W);
    if (!b->col || !b->rr || !b->Zr || !b->prow || !b->pC || !b->W) {
        block_free(b);
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_run: out of memory");
    }
    b->ri = b->rr + su, b->nr = b->ri + su, b->ni = b->nr + su;
    b->Zi = b->Zr + su * P;
    b->psum = b->prow + spart;
    b->pD = b->pC + spart;
    b->on = 1;
    b->nu = nu;
    b->nparts = np;
    size_t u = 0, p = 0;
    for (size_t k = 0; k < K; k++) {
        const double complex r = cexp((x->a[k] + I * x->b[k]) * s->h);
        const double complex rN = cpow(r, (double)N);
        for (size_t c = 0; c < n; c++) {
            int used = 0;
            for (size_t i = 0; i < n; i++) {
                const size_t q = k * nn + i * n + c;
                const double C = x->C[q], D = x->D ? x->D[q] : 0.0;
                if (C == 0 && D == 0)
                    continue;
                b->prow[p] = i, b->psum[p] = u, b->pC[p] = C, b->pD[p] = D;
                p++;
                used = 1;
            }
            if (!used)
                continue;
            b->col[u] = c;
            b->rr[u] = creal(r), b->ri[u] = x->b[k] == 0 ? 0.0 : cimag(r);
            b->nr[u] = creal(rN), b->ni[u] = x->b[k] == 0 ? 0.0 : cimag(rN);
            if (!isfinite(b->rr[u]) || !isfinite(b->ri[u]) || !isfinite(b->nr[u]) ||
                !isfinite(b->ni[u]))
                b->rr[u] = b->ri[u] = b->nr[u] = b->ni[u] = 0; /* (N = 1 only: r^l, l >= 1, 0) */
            u++;
        }
    }
    return DMI_OK;
}

/* Row m of S (n P), -N <= m: the window's (S0, NULL: zero) for m < 0. */
static const double *block_row(const double *S0, const double *S, size_t N, size_t nP, long long m)
{
    if (m >= 0)
        return S + (size_t)m * nP;
    return S0 ? S0 + (size_t)((long long)N + m) * nP : NULL;
}

/* W from the sums. */
static void block_w(block *b, size_t n, size_t P, double h)
{
    for (size_t i = 0; i < n * P; i++)
        b->W[i] = 0;
    for (size_t p = 0; p < b->nparts; p++) {
        const double C = b->pC[p], D = b->pD[p];
        const double *zr = b->Zr + b->psum[p] * P, *zi = b->Zi + b->psum[p] * P;
        double *W = b->W + b->prow[p] * P;
        for (size_t j = 0; j < P; j++)
            W[j] += C * zr[j] + D * zi[j];
    }
    for (size_t i = 0; i < n * P; i++)
        b->W[i] *= h;
}

/* The sums at step q by Horner's rule over S^{q-N+1..q}. */
static void block_anchor(block *b, const dmi_solver *s, size_t P, const double *S0,
                         const double *S, size_t q)
{
    const size_t n = s->n, N = s->N, nP = n * P;
    for (size_t i = 0; i < 2 * b->nu * P; i++)
        b->Zr[i] = 0;
    for (long long m = (long long)q - (long long)N + 1; m <= (long long)q; m++) {
        const double *row = block_row(S0, S, N, nP, m);
        for (size_t u = 0; u < b->nu; u++) {
            const double rr = b->rr[u], ri = b->ri[u];
            double *zr = b->Zr + u * P, *zi = b->Zi + u * P;
            const double *v = row ? row + b->col[u] * P : NULL;
            for (size_t j = 0; j < P; j++) {
                const double x = zr[j], y = zi[j];
                zr[j] = (x * rr - y * ri) + (v ? v[j] : 0.0);
                zi[j] = x * ri + y * rr;
            }
        }
    }
    b->since = 0;
    block_w(b, n, P, s->h);
}

/* The sums from step q to q + 1, S^{q+1} stored. */
static void block_advance(block *b, const dmi_solver *s, size_t P, const double *S0,
                          const double *S, size_t q)
{
    const size_t n = s->n, N = s->N, nP = n * P;
    if (++b->since >= BLOCK_PERIOD * N) {
        block_anchor(b, s, P, S0, S, q + 1);
        return;
    }
    const double *unew = S + (q + 1) * nP;
    const double *uold = block_row(S0, S, N, nP, (long long)q + 1 - (long long)N);
    for (size_t u = 0; u < b->nu; u++) {
        const double rr = b->rr[u], ri = b->ri[u], nr = b->nr[u], ni = b->ni[u];
        double *zr = b->Zr + u * P, *zi = b->Zi + u * P;
        const double *a = unew + b->col[u] * P, *o = uold ? uold + b->col[u] * P : NULL;
        for (size_t j = 0; j < P; j++) {
            const double x = zr[j], y = zi[j], old = o ? o[j] : 0.0;
            zr[j] = (x * rr - y * ri) + (a[j] - nr * old);
            zi[j] = (x * ri + y * rr) - ni * old;
        }
    }
    block_w(b, n, P, s->h);
}

/* out = f(t, u) of model m (0 without f); nonzero where f fails. */
static int call_f(const model *m, double t, const double *u, double *out, size_t n)
{
    for (size_t i = 0; i < n; i++)
        out[i] = 0;
    return m->f ? m->f(t, u, out, m->f_user) : 0;
}

/* Scratch of the tangent loop. */
typedef struct {
    double *T, *Fd, *J, *f0, *fj, *moved, *W, *Snew;
} scratch;

/* T = S - h (f_u S + f_p) at (t, u) (T n P); DMI_OK or the callback's error. */
static int rhs_part(const dmi_tangent *t, double tq, const double *u, const double *Sq, int any_f,
                    int columns_mode, scratch *w)
{
    const dmi_solver *s = t->s;
    const size_t n = s->n, P = t->P;
    const double h = s->h;
    if (!any_f) {
        memcpy(w->T, Sq, n * P * sizeof *w->T);
        return DMI_OK;
    }
    size_t who = 0; /* the failing model */
    int rc = call_f(&t->m[0], tq, u, w->f0, n);
    if (rc == 0 && columns_mode) {
        for (size_t c = 0; c < n && rc == 0; c++) { /* J[:, c] = (f(U + e_c e) - f(U)) / e_c */
            memcpy(w->moved, u, n * sizeof *u);
            const double e = (u[c] + REL_STEP * fmax(1.0, fabs(u[c]))) - u[c];
            w->moved[c] = u[c] + e;
            rc = call_f(&t->m[0], tq, w->moved, w->fj, n);
            for (size_t i = 0; i < n && rc == 0; i++)
                w->J[i * n + c] = (w->fj[i] - w->f0[i]) / e;
        }
        for (size_t i = 0; i < n && rc == 0; i++)
            for (size_t j = 0; j < P; j++) {
                double v = 0;
                for (size_t c = 0; c < n; c++)
                    v += w->J[i * n + c] * Sq[c * P + j];
                w->Fd[i * P + j] = v;
            }
        for (size_t j = 0; j < P && rc == 0; j++) { /* f_p_j by one call for each p_j f has */
            if (!t->depends[j])
                continue;
            who = j + 1;
            rc = call_f(&t->m[j + 1], tq, u, w->fj, n);
            for (size_t i = 0; i < n && rc == 0; i++)
                w->Fd[i * P + j] += (w->fj[i] - w->f0[i]) / t->delta[j];
        }
        for (size_t i = 0; i < n * P && rc == 0; i++)
            w->T[i] = Sq[i] - h * w->Fd[i];
    } else if (rc == 0) {
        for (size_t j = 0; j < P && rc == 0; j++) { /* (f_j(U + delta_j S_j) - f(U)) / delta_j */
            for (size_t i = 0; i < n; i++)
                w->moved[i] = u[i] + t->delta[j] * Sq[i * P + j];
            who = j + 1;
            rc = call_f(&t->m[j + 1], tq, w->moved, w->fj, n);
            for (size_t i = 0; i < n && rc == 0; i++)
                w->T[i * P + j] = Sq[i * P + j] - h * ((w->fj[i] - w->f0[i]) / t->delta[j]);
        }
    }
    if (rc != 0)
        return who == 0 ? dmi_fail(s, DMI_ECALLBACK, "dmi_tangent_run: rhs callback of s "
                                   "returned %d at t = %.17g", rc, tq)
                        : dmi_fail(s, DMI_ECALLBACK, "dmi_tangent_run: rhs callback of "
                                   "others[%zu] returned %d at t = %.17g", who - 1, rc, tq);
    return DMI_OK;
}

/* S^{q+1} = R'(X^q) T + dR/dp into w->Snew, with the saltation at reversals. */
static int resolvent_part(const dmi_tangent *t, size_t q, size_t steps, const double *U,
                          const double *X, int jumps, scratch *w, signed char *switches)
{
    const dmi_solver *s = t->s;
    const size_t n = s->n, P = t->P;
    const double h = s->h, *x = X + q * n, *u1 = U + (q + 1) * n;
    const double *T = w->T;
    double *Snew = w->Snew;
    switch (s->a_kind) {
    case A_FRICTION:
        for (size_t i = 0; i < n; i++) {
            const int side = friction_side(x[i], h * s->a_lo[i]);
            for (size_t j = 0; j < P; j++) /* slipping: T -+ h dalpha; held: 0 */
                Snew[i * P + j] = side > 0 ? T[i * P + j] - h * t->dlo[i * P + j]
                                : side < 0 ? T[i * P + j] + h * t->dlo[i * P + j] : 0.0;
        }
        for (size_t i = 0; jumps && i < n; i++) {
            double rho;
            const int what = reversal(q, i, n, steps, U, X, h, s->a_lo[i], &rho);
            if (what == DMI_SWITCH_REVERSAL) {
                const double sm = copysign(h, U[q * n + i]);
                for (size_t j = 0; j < P; j++)
                    Snew[i * P + j] = rho * (T[i * P + j] - sm * t->dlo[i * P + j]);
            }
            if (switches)
                switches[q * n + i] = (signed char)what;
        }
        break;
    case A_BOX:
        for (size_t i = 0; i < n; i++) {
            const int side = box_side(x[i], s->a_lo[i], s->a_hi[i]);
            for (size_t j = 0; j < P; j++)
                Snew[i * P + j] = side < 0 ? t->dlo[i * P + j]
                                : side > 0 ? t->dhi[i * P + j] : T[i * P + j];
        }
        break;
    case A_CALLBACK:
        for (size_t j = 0; j < P; j++) { /* (r_j(h, X + delta_j T_j) - U^{q+1}) / delta_j */
            for (size_t i = 0; i < n; i++) {
                w->moved[i] = x[i] + t->delta[j] * T[i * P + j];
                w->fj[i] = 0;
            }
            const model *m = &t->m[j + 1];
            int rc = m->r(h, w->moved, w->fj, m->r_user);
            if (rc != 0)
                return dmi_fail(s, DMI_ECALLBACK, "dmi_tangent_run: resolvent callback of "
                                "others[%zu] returned %d at t = %.17g", j, rc,
                                (double)(s->p + q) * h);
            for (size_t i = 0; i < n; i++)
                Snew[i * P + j] = (w->fj[i] - u1[i]) / t->delta[j];
        }
        break;
    default:
        memcpy(Snew, T, n * P * sizeof *Snew);
    }
    return DMI_OK;
}

/* The kernel parameters' part of the tangent's delay sum for an exponential
 * kernel, sum_l dG_l U^{q-l} = Re sum_k (dE_k A_k + dl_k E_k B_k) with
 * A_k = sum_l w_k(l) U^{q-l}, B_k = sum_l dw_k(l)/dl_k U^{q-l}, w_k(l) the
 * weight of e^{l_k s} over cell l (h r^l by the left rule, its integral by
 * the cell rule; the last cell's its own): from the recursions of
 * Y_k = sum_{l<N} r_k^l U^{q-l} and Y1_k = sum_{l<N} l r_k^l U^{q-l},
 * r_k = e^{l_k h}, started (and restarted every 4 N steps) by Horner's rule
 * over the window. */
typedef struct {
    size_t K;
    double complex *buf;                       /* everything below */
    double complex *r, *rN, *rlast, *cw, *c1, *wlast, *wslast; /* K each */
    double complex *E0;                        /* K n n: C_k - i D_k of s */
    double complex *Y, *Y1, *A, *EB, *B;       /* K n, K n, K n, K n, n */
    const double *window;                      /* U^{p0-N..p0}, (N + 1) n */
    const double *U;                           /* U^{p0..p0+steps} */
    size_t since;
    /* the nonzero derivatives, listed once: dl_k in p_j (nl of them: index k P + j), dE_k
     * [i][m] in p_j (ne: index ((k n + i) n + m) P + j) */
    size_t nl, ne, *li, *ei;
    double *acc;                               /* n P: the sum of each entry of T */
} kpart;

/* U^{p0+m}, -N <= m. */
static const double *state_at(const kpart *kp, const dmi_solver *s, long long m)
{
    return m <= 0 ? kp->window + (size_t)((long long)s->N + m) * s->n : kp->U + (size_t)m * s->n;
}

static int kpart_make(kpart *kp, const dmi_tangent *t, const double *window, const double *U)
{
    const dmi_solver *s = t->s;
    const size_t K = t->K, n = s->n, N = s->N;
    const double h = s->h;
    memset(kp, 0, sizeof *kp);
    kp->K = K;
    if (K == 0)
        return DMI_OK;
    kp->buf = malloc((7 * K + K * n * n + 4 * K * n + n) * sizeof *kp->buf);
    if (!kp->buf)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_run: out of memory");
    double complex *b = kp->buf;
    kp->r = b, kp->rN = b + K, kp->rlast = b + 2 * K, kp->cw = b + 3 * K, kp->c1 = b + 4 * K;
    kp->wlast = b + 5 * K, kp->wslast = b + 6 * K, kp->E0 = b + 7 * K;
    kp->Y = kp->E0 + K * n * n, kp->Y1 = kp->Y + K * n, kp->A = kp->Y1 + K * n;
    kp->EB = kp->A + K * n, kp->B = kp->EB + K * n;
    kp->window = window;
    kp->U = U;
    const dmi_expk *x = &s->expk;
    const double lastlag = (double)(N - 1) * h, lastlen = s->theta * h;
    for (size_t k = 0; k < K; k++) {
        const double complex lam = x->a[k] + I * x->b[k];
        kp->r[k] = cexp(lam * h);
        kp->rN[k] = cexp(lam * h * (double)N);
        kp->rlast[k] = cexp(lam * lastlag);
        if (s->quad == DMI_QUAD_CELL) { /* int_0^L e^{lam x} dx = L phi1, int_0^L x e^{..} = L^2 psi */
            double pr, pi, qr, qi;
            dmi_quad_phi1(x->a[k] * h, x->b[k] * h, &pr, &pi);
            dmi_quad_psi(x->a[k] * h, x->b[k] * h, &qr, &qi);
            kp->cw[k] = h * (pr + I * pi);
            kp->c1[k] = h * h * (qr + I * qi);
            dmi_quad_phi1(x->a[k] * lastlen, x->b[k] * lastlen, &pr, &pi);
            dmi_quad_psi(x->a[k] * lastlen, x->b[k] * lastlen, &qr, &qi);
            const double complex i0 = lastlen * (pr + I * pi);
            const double complex i1 = lastlen * lastlen * (qr + I * qi);
            kp->wlast[k] = kp->rlast[k] * i0;
            kp->wslast[k] = kp->rlast[k] * (lastlag * i0 + i1);
        } else {
            kp->cw[k] = h;
            kp->c1[k] = 0;
            kp->wlast[k] = lastlen * kp->rlast[k];
            kp->wslast[k] = lastlen * lastlag * kp->rlast[k];
        }
        for (size_t q = 0; q < n * n; q++)
            kp->E0[k * n * n + q] = x->C[k * n * n + q] - I * (x->D ? x->D[k * n * n + q] : 0.0);
    }
    const size_t P = t->P, KP = K * P, KnnP = K * n * n * P;
    kp->li = malloc((KP + KnnP) * sizeof *kp->li);
    kp->acc = malloc(n * P * sizeof *kp->acc);
    if (!kp->li || !kp->acc)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_run: out of memory");
    kp->ei = kp->li + KP;
    for (size_t q = 0; q < KP; q++)
        if (t->dl[q] != 0)
            kp->li[kp->nl++] = q;
    for (size_t q = 0; q < KnnP; q++)
        if (t->dE[q] != 0)
            kp->ei[kp->ne++] = q;
    return DMI_OK;
}

static void kpart_free(kpart *kp)
{
    free(kp->buf);
    free(kp->li);
    free(kp->acc);
}

/* Y and Y1 at step q by Horner's rule over U^{q-N+1..q}. */
static void kpart_anchor(kpart *kp, const dmi_solver *s, size_t q)
{
    const size_t n = s->n, N = s->N;
    for (size_t k = 0; k < kp->K; k++) {
        const double complex r = kp->r[k];
        double complex *Y = kp->Y + k * n, *Y1 = kp->Y1 + k * n;
        for (size_t i = 0; i < n; i++)
            Y[i] = Y1[i] = 0;
        for (long long m = (long long)q - (long long)N + 1; m <= (long long)q; m++) {
            const double *u = state_at(kp, s, m);
            for (size_t i = 0; i < n; i++) {
                Y1[i] = r * (Y1[i] + Y[i]);
                Y[i] = r * Y[i] + u[i];
            }
        }
    }
    kp->since = 0;
}

/* T -= h Re sum_k (dE_k A_k + dl_k E_k B_k) at step q. */
static void kpart_apply(kpart *kp, const dmi_tangent *t, size_t q, double *T)
{
    const dmi_solver *s = t->s;
    const size_t n = s->n, N = s->N, P = t->P, K = kp->K;
    const double h = s->h;
    if (q == 0 || kp->since >= 4 * N)
        kpart_anchor(kp, s, q);
    const double *ulast = state_at(kp, s, (long long)q - (long long)N + 1);
    for (size_t k = 0; k < K; k++) {
        const double complex cw = kp->cw[k], c1 = kp->c1[k];
        const double complex fa = kp->wlast[k] - cw * kp->rlast[k];
        const double complex fb = kp->wslast[k] - kp->rlast[k] * ((double)(N - 1) * h * cw + c1);
        for (size_t i = 0; i < n; i++) {
            kp->A[k * n + i] = cw * kp->Y[k * n + i] + fa * ulast[i];
            kp->B[i] = h * cw * kp->Y1[k * n + i] + c1 * kp->Y[k * n + i] + fb * ulast[i];
        }
        for (size_t i = 0; i < n; i++) {
            double complex v = 0;
            for (size_t m = 0; m < n; m++)
                v += kp->E0[(k * n + i) * n + m] * kp->B[m];
            kp->EB[k * n + i] = v;
        }
    }
    /* Re(dl_k EB_k) and Re(dE_k A_k) of the nonzero derivatives only */
    double *acc = kp->acc;
    for (size_t e = 0; e < n * P; e++)
        acc[e] = 0;
    for (size_t e = 0; e < kp->nl; e++) {
        const size_t x = kp->li[e], k = x / P, j = x % P;
        const double dr = creal(t->dl[x]), di = cimag(t->dl[x]);
        for (size_t i = 0; i < n; i++) {
            const double complex eb = kp->EB[k * n + i];
            acc[i * P + j] += dr * creal(eb) - di * cimag(eb);
        }
    }
    for (size_t e = 0; e < kp->ne; e++) {
        const size_t x = kp->ei[e], j = x % P, m = x / P % n, i = x / P / n % n, k = x / P / n / n;
        const double complex a = kp->A[k * n + m];
        acc[i * P + j] += creal(t->dE[x]) * creal(a) - cimag(t->dE[x]) * cimag(a);
    }
    for (size_t e = 0; e < n * P; e++)
        T[e] -= h * acc[e];
}

/* Y, Y1 from step q to q + 1. */
static void kpart_advance(kpart *kp, const dmi_solver *s, size_t q)
{
    const size_t n = s->n, N = s->N;
    const double *unew = state_at(kp, s, (long long)q + 1);
    const double *ulast = state_at(kp, s, (long long)q + 1 - (long long)N);
    for (size_t k = 0; k < kp->K; k++) {
        const double complex r = kp->r[k], rN = kp->rN[k];
        for (size_t i = 0; i < n; i++) {
            double complex *Y = kp->Y + k * n + i, *Y1 = kp->Y1 + k * n + i;
            *Y1 = r * (*Y1 + *Y) - (double)N * rN * ulast[i];
            *Y = r * *Y + unew[i] - rN * ulast[i];
        }
    }
    kp->since++;
}

/* The tangent along the run U, X from the solver's step p0 = s->p. */
static int tangent_loop(const dmi_tangent *t, size_t steps, int flags, const double *dWU,
                        const double *U, const double *X, double *S, double *dX,
                        signed char *switches, columns *cols, block *bk, kpart *kp, scratch *w)
{
    const dmi_solver *s = t->s;
    const size_t n = s->n, P = t->P, nP = n * P;
    const double h = s->h;
    int any_f = s->f != NULL;
    size_t count = 0;
    for (size_t j = 0; j < P; j++) {
        any_f |= t->m[j + 1].f != NULL;
        count += t->depends[j] != 0;
    }
    const int columns_mode = n + count < P; /* fewer calls of f than one per parameter */
    const int jumps = !(flags & DMI_TANGENT_PLAIN);
    if (bk->on && t->S0) /* (a zero window: zero sums, as made) */
        block_anchor(bk, s, P, t->S0, S, 0);
    for (size_t q = 0; q < steps; q++) {
        const double tq = (double)(s->p + q) * h; /* as dmi_time */
        const double *Sq = S + q * nP;
        int rc = rhs_part(t, tq, U + q * n, Sq, any_f, columns_mode, w);
        if (rc != DMI_OK)
            return rc;
        for (size_t j = 0; cols->col && j < P; j++) { /* T -= h (sum_l G_l S^{q-l} + dW) */
            const double *Wj = dmi_engine_sum(&cols->col[j], w->W);
            for (size_t i = 0; i < n; i++)
                w->T[i * P + j] -= h * (Wj[i] + (dWU ? dWU[q * nP + i * P + j] : 0.0));
        }
        if (bk->on)
            for (size_t i = 0; i < nP; i++) /* T -= h (sum_l G_l S^{q-l} + dW), all columns */
                w->T[i] -= h * (bk->W[i] + (dWU ? dWU[q * nP + i] : 0.0));
        else if (!cols->col && dWU)
            for (size_t i = 0; i < nP; i++)
                w->T[i] -= h * dWU[q * nP + i];
        if (kp->K)
            kpart_apply(kp, t, q, w->T);
        if (dX)
            memcpy(dX + q * nP, w->T, nP * sizeof *dX);
        rc = resolvent_part(t, q, steps, U, X, jumps, w, switches);
        if (rc != DMI_OK)
            return rc;
        const size_t bad = dmi_first_nonfinite(w->Snew, nP);
        if (bad < nP)
            return dmi_fail(s, DMI_ENONFINITE, "dmi_tangent_run: dU_%zu/dp_%zu = %g at "
                            "t = %.17g (step %zu of the run)", bad / P, bad % P, w->Snew[bad],
                            tq + h, q + 1);
        memcpy(S + (q + 1) * nP, w->Snew, nP * sizeof *S);
        if (kp->K)
            kpart_advance(kp, s, q);
        if (bk->on)
            block_advance(bk, s, P, t->S0, S, q);
        for (size_t j = 0; cols->col && j < P; j++) { /* the windows and engines move on */
            dmi_solver *col = &cols->col[j];
            for (size_t i = 0; i < n; i++)
                w->W[i] = w->Snew[i * P + j];
            dmi_history_push(&col->ring, w->W);
            col->p++;
            dmi_engine_advance(col);
        }
    }
    return DMI_OK;
}

int dmi_tangent_run(dmi_tangent *t, size_t steps, int flags, const double *dWU, double *U,
                    double *X, double *S, double *dX, signed char *switches)
{
    if (!t)
        return DMI_EINVAL;
    dmi_solver *s = t->s;
    if (!S || steps == 0 || (flags & ~DMI_TANGENT_PLAIN))
        return dmi_fail(s, DMI_EINVAL, "dmi_tangent_run: %s", !S ? "S is NULL"
                        : steps == 0 ? "steps = 0" : "unknown flags");
    if (!s->initialized)
        return dmi_fail(s, DMI_ESTATE, "dmi_tangent_run: call dmi_init on the solver first");
    const size_t n = s->n, P = t->P, N = s->N;
    if (steps == SIZE_MAX || dmi_mul_size(steps + 1, n * P, sizeof(double)) == 0 ||
        dmi_mul_size(steps + 1, n * (P + 2), sizeof(double)) == 0)
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_run: %zu steps of n P = %zu overflow the "
                        "memory", steps, n * P);
    const size_t saved_size = dmi_state_size(s);
    unsigned char *saved = malloc(saved_size);
    double *Ub = U ? NULL : malloc((steps + 1) * n * sizeof *Ub);
    double *Xb = X ? NULL : malloc(steps * n * sizeof *Xb);
    double *pool = malloc((5 * n * P + n * n + 4 * n + 2 * (N + 1) * n) * sizeof *pool);
    columns cols = {0};
    block bk = {0};
    kpart kp = {0};
    if (!saved || (!U && !Ub) || (!X && !Xb) || !pool) {
        free(saved);
        free(Ub);
        free(Xb);
        free(pool);
        return dmi_fail(s, DMI_ENOMEM, "dmi_tangent_run: out of memory for a run of %zu steps",
                        steps);
    }
    U = U ? U : Ub;
    X = X ? X : Xb;
    scratch w = {pool, pool + n * P, pool + 2 * n * P, pool + 2 * n * P + n * n, NULL, NULL,
                 NULL, NULL};
    w.fj = w.f0 + n;
    w.moved = w.fj + n;
    w.W = w.moved + n;
    w.Snew = w.W + n;
    double *row = w.Snew + n * P;    /* (N + 1) n: a window of one column of S */
    double *window = row + (N + 1) * n; /* (N + 1) n: the states' window at the start */
    const uint64_t p0 = s->p;
    int rc = dmi_state_save(s, saved, saved_size);
    if (rc == DMI_OK && t->K && !s->rec)
        rc = dmi_fail(s, DMI_EINVAL, "dmi_tangent_run: the kernel terms' derivatives "
                      "(dmi_tangent_set_kernel_terms) need the recursion (DMI_CONV_RECURSIVE, or "
                      "AUTO choosing it): give the kernel's part as dWU");
    if (rc == DMI_OK)
        rc = block_applies(s) ? block_make(&bk, s, P) : columns_make(&cols, s, P, t->S0, row);
    if (rc == DMI_OK)
        rc = kpart_make(&kp, t, window, U);
    for (size_t k = 0; k <= N && rc == DMI_OK; k++) /* row k: U^{p-N+k} */
        dmi_history_get(&s->ring, N - k, window + k * n);
    /* the plain run, as dmi_advance */
    dmi_history_get(&s->ring, 0, U);
    for (size_t q = 0; q < steps && rc == DMI_OK; q++) {
        rc = dmi_step(s);
        if (rc == DMI_OK) {
            dmi_history_get(&s->ring, 0, U + (q + 1) * n);
            memcpy(X + q * n, s->last_X, n * sizeof *X);
        }
    }
    const uint64_t p_end = s->p;
    if (rc == DMI_OK) {
        s->p = p0; /* (the loop reads t_q from the start's p) */
        if (switches)
            memset(switches, DMI_SWITCH_NONE, steps * n);
        for (size_t i = 0; i < n * P; i++) /* S^p: the window's last row */
            S[i] = t->S0 ? t->S0[N * n * P + i] : 0.0;
        rc = tangent_loop(t, steps, flags, dWU, U, X, S, dX, switches, &cols, &bk, &kp, &w);
        s->p = p_end;
    }
    if (rc != DMI_OK && s->p != p0) {
        /* back to the state before the call (the message of the failure kept) */
        char msg[sizeof s->err];
        memcpy(msg, s->err, sizeof msg);
        dmi_state_load(s, saved, saved_size);
        memcpy(s->err, msg, sizeof msg);
    }
    columns_free(&cols);
    block_free(&bk);
    kpart_free(&kp);
    free(saved);
    free(Ub);
    free(Xb);
    free(pool);
    return rc;
}
