/**
 * dmi.h — public API of libdmi, the implicit Euler scheme for differential
 * inclusions with a delay term of convolution type:
 *
 *     u'(t) + A(u(t)) + f(t, u(t)) + int_0^tau H(s) u(t - s) ds  ∋ 0,   t in (0, T),
 *     u = z on [-tau, 0],
 *
 * in R^n, A maximal monotone. With h = tau / N and t_p = p h the scheme
 * (3.12)-(3.13) of Lamarque, Bastien & Holland is
 *
 *     U^p     = z(t_p),                                   p = -N .. 0,
 *     W^p     = h * sum_{l=0}^{N-1} H(l h) U^{p-l},
 *     U^{p+1} = (I + h A)^{-1} ( U^p - h f(t_p, U^p) - h W^p ).
 *
 * (Since 1.2) dmi_create_h takes h itself, tau / h need not be an integer:
 * the last of the N cells of the delay sum is then partial and weighted
 * theta h, 0 < theta <= 1 (see there).
 *
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Conventions that hold for every function below
 * -----------------------------------------------
 * - Vectors are arrays of n doubles; matrices are n*n doubles, row-major
 *   (entry (i, j) at index i*n + j).  Time, tau and h are in the time unit of
 *   the model (seconds for the oscillator); lambda in the resolvent has that
 *   same unit.
 * - Every function returning int returns DMI_OK (0) or one of the negative
 *   DMI_E* codes.  On failure the solver (if any) is left exactly as it was
 *   before the call, bitwise (all but the message buffer), and
 *   dmi_last_error(s) describes the reason.  (dmi_advance keeps the steps it
 *   took before the failing one.)
 * - The solver never keeps a pointer passed in as an array argument: arrays
 *   are copied.  Callback user pointers are stored and passed back untouched;
 *   their lifetime is the caller's business.
 * - The library has no global mutable state, never aborts, exits or prints.
 *   Distinct solvers may be used concurrently from distinct threads; one
 *   solver must not be used from two threads at once.
 */
/**/
#ifndef DMI_H
#define DMI_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Major version of this header; dmi_version() gives the version of the library. */
#define DMI_VERSION_MAJOR 1
/** Minor version of this header. */
#define DMI_VERSION_MINOR 6
/** Patch version of this header. */
#define DMI_VERSION_PATCH 0

/** DMI_API marks the exported functions of the shared library. */
#if defined(DMI_BUILDING_SHARED) && (defined(__GNUC__) || defined(__clang__))
#define DMI_API __attribute__((visibility("default")))
#else
#define DMI_API
#endif

/** Opaque solver handle. */
typedef struct dmi_solver dmi_solver;

/**
 * Callbacks.  Each returns 0 on success; any other value makes the calling
 * library function fail with DMI_ECALLBACK and leaves the solver unchanged.
 * The output array is set to zero before every call, so a callback may write
 * only the nonzero entries.  Non-finite outputs give DMI_ENONFINITE.
 */

/** out = f(t, u): n values.  t = t_p in time units. */
typedef int (*dmi_rhs_fn)(double t, const double *u, double *out, void *user);

/** out = (I + lambda A)^{-1} x: n values; lambda = h > 0.  x and out never
 * alias.  Must be the resolvent of a maximal monotone A for the theory to
 * hold (the library cannot check that). */
typedef int (*dmi_resolvent_fn)(double lambda, const double *x, double *out, void *user);

/** out = H(s): n*n values, row-major, for 0 <= s < tau (s = l h, l = 0..N-1). */
typedef int (*dmi_kernel_fn)(double s, double *out, void *user);

/** out = z(t): n values, for -tau <= t <= 0 (t = p h, p = -N..0). */
typedef int (*dmi_history_fn)(double t, double *out, void *user);

/** Error codes. */
enum {
    /** Success. */
    DMI_OK = 0,
    /** An argument is invalid (NULL, out of range, NaN). */
    DMI_EINVAL = -1,
    /** Memory could not be allocated (or its size overflows). */
    DMI_ENOMEM = -2,
    /** A user callback returned nonzero. */
    DMI_ECALLBACK = -3,
    /** A NaN or infinity appeared (callback output or new state). */
    DMI_ENONFINITE = -4,
    /** The call is not allowed in the solver's current state. */
    DMI_ESTATE = -5
};

/** Methods of computing the delay sum W^p (see dmi_set_convolution). */
enum {
    /** The default: the fastest method for this n and N. */
    DMI_CONV_AUTO = 0,
    /** The plain sum, N multiply-adds per nonzero kernel entry. */
    DMI_CONV_DIRECT = 1,
    /** Exact block convolution with FFTs (same sum, other rounding). */
    DMI_CONV_FFT = 2,
    /** (Since 1.1.)  O(1) recursion of an exponential-sum kernel. */
    DMI_CONV_RECURSIVE = 3
};

/** Quadrature rules of the delay sum (see dmi_set_quadrature; since 1.3). */
enum {
    /** The default: the paper's rectangle rule, h H(l h) per cell. */
    DMI_QUAD_LEFT = 0,
    /** Exact cell weights: the integral of H over each cell. */
    DMI_QUAD_CELL = 1
};

/** ---- version --------------------------------------------------------- */

/** "MAJOR.MINOR.PATCH" of the library actually linked.  Static string. */
DMI_API const char *dmi_version(void);

/** ---- life cycle ------------------------------------------------------ */

/**
 * Creates a solver for R^n with delay tau > 0 (time units) and N >= 1 steps
 * per tau, so h = tau / N.  Allocates the history ring of (N + 1) * n values.
 * Nothing else is set: f = 0, A = 0 (identity resolvent), H = 0, z = 0.
 * On success *out owns a new solver (release it with dmi_free).  On error
 * *out = NULL and the code tells the reason (no handle exists to carry a
 * message; dmi_strerror(code) gives a generic one):
 *   DMI_EINVAL  out NULL, n = 0, N = 0, tau <= 0 or not finite, or h = tau/N
 *               not a positive normal number;
 *   DMI_ENOMEM  (N + 1) * n doubles overflow size_t or cannot be allocated.
 */
DMI_API int dmi_create(dmi_solver **out, size_t n, double tau, size_t N);

/**
 * (Since 1.2.)  Creates a solver for R^n with delay tau > 0 and step h > 0
 * (both in time units), where tau / h need not be an integer (a period or a
 * delay that moves freely while the step stays put).  The delay integral
 * over [0, tau) is cut into N cells [l h, (l + 1) h), the last one cut off
 * at tau, and summed by the rectangle rule at the cells' left ends:
 *
 *     W^p = h * sum_{l=0}^{N-2} H(l h) U^{p-l}  +  theta h * H((N-1) h) U^{p-N+1},
 *
 * with N = ceil(q), q = tau / h (the double quotient), N >= 1, and
 * theta = q - (N - 1) in (0, 1] (theta h = tau - (N - 1) h is the last
 * cell's length), so that the cells' weights add up to tau.  The scheme keeps
 * order 1 (docs/mathematics.md) and is continuous in h: as theta -> 0 the
 * last cell's term vanishes, and the sum tends to that of N - 1 full cells.
 * One exception: when h == tau / M in double for the integer M nearest q
 * (the h that dmi_create(out, n, tau, M) computes), N = M and theta = 1, and
 * the solver is dmi_create's, bitwise (the same steps in every convolution
 * method, the same saved states).
 * h > tau is allowed: N = 1 and theta = tau / h, i.e. W^p = tau H(0) U^p.
 * The kernel is sampled at s = l h, l = 0..N-1 (all < tau); the history at
 * t = -k h, k = 0..N-1, and the oldest stored state U^{-N} (row 0 of
 * dmi_get_window, read by no step: the sum reaches back to U^{p-N+1}) is
 * z(-tau), so z is called on [-tau, 0] only.  The ring, the window
 * (dmi_get_window) and the saved state have N + 1 rows, as for dmi_create
 * with that N (dmi_get_N tells it); dmi_get_h returns h.  Every convolution
 * method computes this sum (the exponential kernel's recursion too).  The
 * saved state records h when it is not tau / N, so that it loads only into
 * a solver with the same h (dmi_state_load).
 * Ownership and errors as dmi_create: on success *out owns a new solver;
 * on error *out = NULL and
 *   DMI_EINVAL  out NULL, n = 0, tau <= 0 or not finite, h <= 0, not finite
 *               or not a normal number;
 *   DMI_ENOMEM  tau / h >= 2^50 cells, (N + 1) * n doubles overflow size_t,
 *               or they cannot be allocated.
 */
DMI_API int dmi_create_h(dmi_solver **out, size_t n, double tau, double h);

/** Frees *s and everything it owns and sets *s = NULL.  s == NULL and
 * *s == NULL are allowed and do nothing. */
DMI_API void dmi_free(dmi_solver **s);

/** ---- setup ------------------------------------------------------------
 * dmi_set_rhs, dmi_set_resolvent, dmi_set_friction, dmi_set_box and
 * dmi_set_convolution may be called at any time: they take effect from the
 * next step on and do not alter U^p or the history.  dmi_set_kernel and
 * dmi_set_history define data sampled by dmi_init, so after dmi_init they
 * return DMI_ESTATE (create a new solver to change them).
 * All return DMI_EINVAL if s is NULL.
 */

/** f: n -> n right-hand side; f = NULL restores f = 0. */
DMI_API int dmi_set_rhs(dmi_solver *s, dmi_rhs_fn f, void *user);

/** A through its resolvent (I + lambda A)^{-1}; r = NULL restores A = 0.
 * Replaces any earlier dmi_set_resolvent / dmi_set_friction / dmi_set_box. */
DMI_API int dmi_set_resolvent(dmi_solver *s, dmi_resolvent_fn r, void *user);

/** Built-in dry friction: A(u) = (alpha_1 sigma(u_1), ..., alpha_n sigma(u_n)),
 * sigma the sign graph (sigma(0) = [-1, 1]); the resolvent is the soft
 * threshold out_i = sign(x_i) max(|x_i| - lambda alpha_i, 0).  Copies the n
 * values of alpha, each finite and >= 0 (alpha_i = 0: no friction on u_i).
 * DMI_EINVAL if alpha is NULL or a value is negative, NaN or infinite.
 * Replaces any earlier resolvent setting. */
DMI_API int dmi_set_friction(dmi_solver *s, const double *alpha);

/** Built-in normal cone of the box K = prod_i [lo_i, hi_i]: the resolvent is
 * the projection onto K, out_i = min(max(x_i, lo_i), hi_i).  Copies n values
 * of each; lo_i = -INFINITY and hi_i = +INFINITY are allowed.  DMI_EINVAL if
 * lo or hi is NULL, a value is NaN, lo_i > hi_i, lo_i = +INFINITY or
 * hi_i = -INFINITY (K must be nonempty).  Replaces any earlier resolvent. */
DMI_API int dmi_set_box(dmi_solver *s, const double *lo, const double *hi);

/** Kernel H(s), n*n row-major; H = NULL restores H = 0 (no delay term).
 * Sampled at s = l h, l = 0..N-1, once by dmi_init (l h < tau; for
 * dmi_create_h too).  DMI_ESTATE after init. */
DMI_API int dmi_set_kernel(dmi_solver *s, dmi_kernel_fn H, void *user);

/**
 * (Since 1.1.)  Kernel as a sum of K exponential terms,
 *
 *     H(s) = sum_{k<K} exp(a[k] s) * (C_k cos(b[k] s) + D_k sin(b[k] s)),
 *
 * C_k = C + k*n*n and D_k = D + k*n*n, row-major n x n; D == NULL means
 * every D_k = 0.  a (decay rate if negative) and b (angular frequency) are
 * in 1 / time unit, C and D in the kernel's unit (that of H).  The arrays
 * (K, K, K n n and K n n doubles) are copied.  Replaces a kernel set by
 * dmi_set_kernel, and dmi_set_kernel replaces this one.
 * With it every method computes the same rectangle-rule sum of the samples
 * H(l h), which dmi_init takes from this formula; DMI_CONV_RECURSIVE (and
 * AUTO, see dmi_set_convolution) computes it in O(K n^2) per step, whatever
 * N is, by the recursion S^{p+1} = r S^p + U^{p+1} - r^N U^{p+1-N},
 * r = exp((a + i b) h), per term.
 * Errors: DMI_EINVAL if s is NULL; K = 0; a, b or C is NULL; or a value of
 * a, b, C or D is NaN or infinite (the message names the argument and index);
 * DMI_ENOMEM; DMI_ESTATE after dmi_init.
 */
DMI_API int dmi_set_kernel_exp(dmi_solver *s, size_t K, const double *a, const double *b,
                               const double *C, const double *D);

/**
 * (Since 1.3.)  The quadrature rule of the delay integral, before dmi_init:
 *   DMI_QUAD_LEFT  (the default) the paper's rule, the weight h H(l h) per
 *                  cell (theta h H((N-1) h) for a partial last cell); the
 *                  results of libdmi 1.2, bitwise.
 *   DMI_QUAD_CELL  exact cell weights: each cell's weight is the integral of
 *                  H over it,
 *                    W^p = sum_{l<N-1} int_{l h}^{(l+1) h} H(s) ds U^{p-l}
 *                        + int_{(N-1) h}^{tau} H(s) ds U^{p-N+1},
 *                  the last cell partial as for dmi_create_h.  A kernel that
 *                  is singular at s = 0 but integrable (s^-alpha, alpha < 1:
 *                  fractional damping) then runs: H is never evaluated at 0.
 *                  Exponential kernels (dmi_set_kernel_exp) in closed form,
 *                  per term mu = a + i b the cell weight
 *                  h Re((C - i D) phi1(mu h) e^{mu l h}), phi1(z) = (e^z - 1)/z
 *                  (the partial last cell: theta h and phi1(mu theta h)); the
 *                  recursion runs the same weights at the same cost.  Callback
 *                  kernels by tanh-sinh quadrature on each cell (since 1.4:
 *                  the nodes computed once per dmi_init; the step halved
 *                  until two levels agree, with the rule's truncation, to
 *                  1e-13 of the cell's integral of |H|, else the cell
 *                  bisected, a jump so located; typically 30 to 130 calls for
 *                  a smooth kernel), by dmi_init, which then calls H only
 *                  strictly inside the cells: 0 < s < tau, never at l h.
 *                  (Since 1.4.)  What is promised: each cell's weight within
 *                  1e-10 of its integral (relative), for H smooth within
 *                  cells or with jumps, and in the first cell for
 *                  H(s) = s^-alpha g(s) with alpha < 1, g smooth and
 *                  g(0) != 0, entry by entry: alpha is given by
 *                  dmi_set_kernel_singularity or estimated from H at
 *                  s = h 2^-960 .. h 2^-720 (where H must be computable),
 *                  and the part below those points is added in closed form.
 *                  What is refused, by dmi_init with DMI_EINVAL and a message
 *                  naming the cell and entry: an exponent >= 1 (1/s is not
 *                  integrable); an exponent so close to 1 (about 0.9999 and
 *                  above) that the part below those points, most of the
 *                  integral, is not known to 1e-11 from the estimate:
 *                  give it (dmi_set_kernel_singularity); an exponent
 *                  given that H's samples near 0 contradict (see
 *                  dmi_set_kernel_singularity); a singularity
 *                  that is no such power law
 *                  (1/(s ln^2 s): no sampling tells it from 1/s); a cell whose
 *                  integral does not converge (the estimate reached is in the
 *                  message), as for H computed to fewer digits (values noisy
 *                  beyond about 1e-10 of |H|: use DMI_QUAD_LEFT).  A cell
 *                  integral beyond the largest double: DMI_ENONFINITE.  The
 *                  sums are scaled, so kernels up to the largest double are
 *                  integrated.
 *                  Every method (DIRECT, FFT, RECURSIVE) computes this same
 *                  sum (up to rounding).  The error of the rule is that of the
 *                  product U(t - s) ~ U^{p-l} on the cell, order 1 in h, as the
 *                  left rule's for smooth H (docs/kernels.md).
 * The rule is not part of the saved state (set it alike on the solver that
 * loads one).  Errors: DMI_EINVAL for s NULL or another rule; DMI_ESTATE
 * after dmi_init (the weights are computed there; create a new solver).
 */
DMI_API int dmi_set_quadrature(dmi_solver *s, int rule);

/**
 * (Since 1.3.)  A kernel singular at 0 in O(1) per step: the exponential sum
 * set by dmi_set_kernel_exp (a fit of the kernel on [delta, tau], e.g. by
 * Python's dmi.kernels.fit or dmi-kernel-fit) for the far cells, and the
 * exact kernel H (n*n row-major, a dmi_kernel_fn) for the m = ceil(delta / h)
 * near cells [l h, (l + 1) h), l < m, whose weights are H's exact integrals
 * over them (tanh-sinh quadrature by dmi_init, as for DMI_QUAD_CELL: H is
 * called inside those cells, 0 < s <= m h, never at 0).  The far cells
 * follow the rule of dmi_set_quadrature (use DMI_QUAD_CELL: the left rule
 * samples the sum at l h).  Every method computes the same sum;
 * RECURSIVE (and AUTO) runs the recursion of the sum over all N cells and
 * adds the near cells' exact weights less the sum's: O(K n^2 + m nnz) per
 * step.  delta = 0 (m = 0) or H = NULL: no near cells (H = NULL removes
 * them).  The user pointer is stored and passed back.
 * Errors: DMI_EINVAL for s NULL or delta negative or not finite; from
 * dmi_init, DMI_EINVAL when the kernel is not one of dmi_set_kernel_exp or
 * when m + 1 > N (the last cell must be the sum's), and the kernel
 * callback's errors (DMI_ECALLBACK, DMI_ENONFINITE) and the refusals of
 * DMI_QUAD_CELL (an exponent at 0 >= 1, a singularity that is no power law,
 * a cell that does not converge: DMI_EINVAL with the cell in the message);
 * DMI_ESTATE after dmi_init.  (Since 1.4: H's singularity at 0 is handled
 * as for DMI_QUAD_CELL, its exponent given by dmi_set_kernel_singularity or
 * estimated.)
 */
DMI_API int dmi_set_kernel_near(dmi_solver *s, dmi_kernel_fn H, void *user, double delta);

/**
 * (Since 1.4.)  The exponent alpha of the kernel's singularity at 0,
 * H(s) = s^-alpha g(s) near s = 0 with g smooth and g(0) != 0 (alpha
 * dimensionless, 0 <= alpha < 1), for the first cell's integral under
 * DMI_QUAD_CELL (of the kernel of dmi_set_kernel) and of the near kernel
 * (dmi_set_kernel_near).  Without it (alpha = NAN, the default) dmi_init
 * estimates alpha entry by entry from H at s = h 2^-960 .. h 2^-720 and
 * refuses a kernel whose local exponents there disagree; with it, the
 * exponent is taken for every entry (an entry that is not singular loses
 * nothing: the part below h 2^-960 is below 1e-280 of its integral), and
 * dmi_init checks it against H: the slope of log|H| against
 * log s between the two of five samples closest to 0 (s = h 2^-960 and
 * h 2^-900, or higher up to h 2^-60 .. h 2^-50 where H cannot be computed
 * that close to 0; four calls of H more than unchecked) must not be steeper than -alpha by
 * more than 1e-6 in any entry (s^alpha H(s) unbounded: the first cell would
 * be wrong, or a divergent integral finite): refused by dmi_init with
 * DMI_EINVAL, the message naming this call, the entry and the exponent
 * measured (and "not integrable" for one >= 1).  An alpha above every
 * entry's exponent (s^alpha H(s) tends to 0: larger than needed) leaves the
 * weights right; dmi_init then succeeds and leaves a note in dmi_last_error
 * (starting "dmi_init: note: "), naming the exponent measured.  An alpha
 * whose mismatch leaves the part of the first cell below those samples
 * unknown to 1e-11 (a kernel whose exponent drifts, 1/(s ln^2 s)) is
 * refused as well.
 * Not part of the saved state.  Errors: DMI_EINVAL for s NULL or alpha
 * outside [0, 1) and not NAN (the message says why); DMI_ESTATE after
 * dmi_init.
 */
DMI_API int dmi_set_kernel_singularity(dmi_solver *s, double alpha);

/** History z(t) on [-tau, 0]; z = NULL restores z = 0.  Sampled at t = p h,
 * p = -(N-1)..0, and at t = -tau for U^{-N} (= -N h for dmi_create, not for
 * a partial last cell of dmi_create_h), once by dmi_init.  DMI_ESTATE after
 * init. */
DMI_API int dmi_set_history(dmi_solver *s, dmi_history_fn z, void *user);

/**
 * Method for the delay sum W^p: DMI_CONV_AUTO (default), DMI_CONV_DIRECT,
 * DMI_CONV_FFT or DMI_CONV_RECURSIVE.  All compute the same sum (the same
 * rectangle rule) and differ only by rounding (about 1e-16 relative on the
 * paper's examples; RECURSIVE: see there).
 *   DIRECT  the plain sum: N multiply-adds per nonzero kernel entry and step.
 *   FFT     an exact block convolution: the newest and the oldest lags are
 *           summed directly, the others in blocks of power-of-two sizes by
 *           FFT (GSL radix-2), O(log N)-ish work per step; extra memory about
 *           2 N per nonzero kernel entry and 2 N per kernel column and block
 *           size (a few block sizes), i.e. still O(N n^2).
 *   RECURSIVE  (since 1.1) for a kernel set by dmi_set_kernel_exp whose
 *           terms all have a[k] <= 0 and |b[k]| h <= pi (or for no kernel at
 *           all: H = 0 is the empty sum, K = 0, and W^p = 0 exactly): per
 *           term k and used column j the
 *           sum S = sum_{l<N} r^l U_j^{p-l}, r = exp((a + i b) h), follows
 *           S <- r S + U_j^{p+1} - r^N U_j^{p+1-N}: O(K n^2) work per step
 *           and O(K n) memory besides the samples, whatever N is.  r and r^N
 *           are computed in double-double, and every 4 N steps (at the steps
 *           p that are multiples of 4 N) the sums are recomputed from the
 *           stored states with compensated sums, so rounding never piles up
 *           for longer; the result stays within about 1e-11 of
 *           h sum_l |H(l h)| max|U| of the direct sum (tested over 10^6 steps,
 *           N up to 10^6).  A growing term (a[k] > 0, |r| > 1) would multiply
 *           each step's rounding by |r| every step: RECURSIVE refuses it.
 *           Beyond |b[k]| h = pi the samples cos(b l h) alias a frequency
 *           below pi / h (the kernel is not resolved by the step h) and
 *           r = exp(i b h) and the samples lose accuracy as |b| h grows (the
 *           methods differ by 1.8e-7 at b h = 1e9): RECURSIVE refuses such a
 *           term too (the message names it; use a smaller h).  Terms whose
 *           C_k and D_k are zero are never refused.  DMI_EINVAL also for a
 *           kernel given as a callback.
 *   AUTO    RECURSIVE for an exponential kernel that RECURSIVE takes, else
 *           FFT when a cost model measured on x86-64 predicts it faster
 *           than DIRECT for this N and kernel pattern, else DIRECT; for one
 *           nonzero kernel entry that is N >= 382 (a full 3 x 3 kernel:
 *           N >= 174; the model also picks FFT for 158 <= N <= 164).
 *           The choice is made by dmi_init and by this call.
 * Kernel entries that are zero at every sample cost nothing in either method.
 * May be called at any time, also between steps: the FFT engine is then
 * (re)built from the stored states U^{p-N..p}, and stepping on is bitwise the
 * same as in a solver that used FFT all along from the same state; this is
 * also how dmi_state_load restores it.  The recursion's sums are computed
 * afresh from the stored states (as at its periodic anchors), so switching
 * to RECURSIVE agrees with a run that used it all along up to rounding; its
 * sums are part of the saved state, so a state load continues bitwise.  A
 * failed step leaves the engines untouched, as the rest of the solver.
 * Errors: DMI_EINVAL for another value (solver unchanged), for RECURSIVE as
 * said there (checked again by dmi_init, since the kernel may change), and for
 * DMI_CONV_FFT in a libdmi built without the FFT and GSL (its core sources
 * without the definition DMI_HAVE_FFT, as inside the FMU; AUTO then never
 * picks it); DMI_ENOMEM if the
 * FFT engine cannot be allocated after dmi_init (the former method stays).
 * Leaving the recursion after dmi_init samples the kernel (see dmi_init):
 * DMI_ENOMEM or DMI_ENONFINITE (a sample, named) then, the former method
 * staying.
 */
DMI_API int dmi_set_convolution(dmi_solver *s, int method);

/** ---- time stepping ----------------------------------------------------- */

/**
 * Samples the kernel H(l h), l = 0..N-1, and the history U^p = z(p h),
 * p = -N..0, and sets p = 0.  May be called again to restart from t = 0.
 * Memory: the nonzero kernel entries take N doubles each (at most N n^2).
 * (Since 1.2.)  Under DMI_CONV_RECURSIVE (also as chosen by AUTO) with full
 * cells (dmi_create, or theta = 1) the kernel is not sampled: the recursion
 * needs no samples (its O(K n) sums are computed from the history instead),
 * and a later dmi_set_convolution to another method samples it then; a
 * restart keeps the recursion's engine.
 * Errors: DMI_ECALLBACK / DMI_ENONFINITE (kernel or history callback),
 * DMI_EINVAL (a kernel the cell rule refuses, see dmi_set_quadrature, or
 * whose singularity is steeper than dmi_set_kernel_singularity declares),
 * DMI_ENOMEM; the solver is then unchanged (still uninitialised, or still at
 * its former t_p if it had been initialised).
 */
DMI_API int dmi_init(dmi_solver *s);

/**
 * One step t_p -> t_{p+1}: evaluates f(t_p, U^p), W^p, the resolvent's
 * argument X^p = U^p - h f(t_p, U^p) - h W^p and U^{p+1} = (I + hA)^{-1} X^p.
 * Errors: DMI_ESTATE before dmi_init; DMI_ECALLBACK if f or the resolvent
 * returned nonzero; DMI_ENONFINITE if f, W^p, X^p or U^{p+1} has a NaN or
 * infinity (X^p is checked before the resolvent sees it).  On any error the
 * solver is bitwise unchanged, and retrying gives the result of a run that
 * never failed.
 */
DMI_API int dmi_step(dmi_solver *s);

/** steps calls of dmi_step.  Stops at the first failure and returns its code;
 * the steps done before it are kept (dmi_time tells where the solver is). */
DMI_API int dmi_advance(dmi_solver *s, size_t steps);

/** ---- queries ------------------------------------------------------------ */

/** t_p = p * h (time units), computed from the integer step counter; 0 before
 * init and for s == NULL. */
DMI_API double dmi_time(const dmi_solver *s);

/** *p = the step counter p (number of steps since dmi_init).  DMI_EINVAL for
 * NULL arguments, DMI_ESTATE before dmi_init. */
DMI_API int dmi_get_step_index(const dmi_solver *s, uint64_t *p);

/** Step size h (time units): tau / N for dmi_create, the h given to
 * dmi_create_h; 0 for s == NULL. */
DMI_API double dmi_get_h(const dmi_solver *s);

/** (Since 1.2.)  The number N of cells of the delay sum (steps per tau for
 * dmi_create; ceil(tau / h) for dmi_create_h): the window and the ring have
 * N + 1 rows.  0 for s == NULL. */
DMI_API size_t dmi_get_N(const dmi_solver *s);

/** u[0..n-1] = U^p.  DMI_EINVAL for NULL, DMI_ESTATE before dmi_init. */
DMI_API int dmi_get_state(const dmi_solver *s, double *u);

/** u[0..n-1] = U^{p-lag}, 0 <= lag <= N (history values z(t) for p - lag <= 0).
 * DMI_EINVAL for NULL or lag > N, DMI_ESTATE before dmi_init. */
DMI_API int dmi_get_past(const dmi_solver *s, size_t lag, double *u);

/**
 * (Since 1.2.)  The window of stored states, the solution over the last delay
 * that the next steps read: U[(k * n) + j] = U_j^{p-N+k}, k = 0..N, oldest
 * first (row k = 0 is U^{p-N}, row N is U^p); (N + 1) * n doubles, written by
 * dmi_get_window and read by dmi_set_window.  Together with the step counter
 * p (t_p, for a rhs that depends on time) the window is the whole state of
 * the scheme's step map: stepping on from a window set by dmi_set_window is
 * the scheme started at t_p from that history.  This is the state that
 * shooting for periodic orbits and the linearisation of the step map
 * (characteristic roots, Floquet multipliers) work on.
 * dmi_set_window replaces the stored states and keeps p; the delay sum's
 * engine (FFT blocks, the recursion's sums) is recomputed from the new
 * states, as dmi_set_convolution does (bitwise the same as a solver whose
 * states were those all along for DIRECT and FFT; up to rounding for
 * RECURSIVE); the last step's terms (dmi_get_step_terms) still describe the
 * step before the call.  The array is copied (set: into the solver's own
 * storage, nothing is allocated).
 * Errors: DMI_EINVAL for NULL arguments or (set) a NaN or infinite value
 * (the message names its row and component); DMI_ESTATE before dmi_init.
 * On error the solver is unchanged.
 */
DMI_API int dmi_get_window(const dmi_solver *s, double *U);
/** (Since 1.2.)  Replaces the window of stored states by U: see dmi_get_window. */
DMI_API int dmi_set_window(dmi_solver *s, const double *U);

/**
 * Terms of the last step taken, from t_{p-1} to t_p: W[0..n-1] = W^{p-1} and
 * X[0..n-1] = X^{p-1}, the resolvent's argument, so that (X - U^p) / h is the
 * element of A(U^p) the step selected (the friction force, for friction).
 * Either pointer may be NULL if not wanted.  DMI_EINVAL for s NULL,
 * DMI_ESTATE before dmi_init or before the first step.
 */
DMI_API int dmi_get_step_terms(const dmi_solver *s, double *W, double *X);

/**
 * (Since 1.5.)  The weights of the delay sum as the steps use them: with
 * them the sum of every step is
 *
 *     W^p = sum_{l=0}^{N-1} G_l U^{p-l},
 *
 * G_l an n x n matrix (row-major: G_l[i n + j] weighs U_j^{p-l} in W_i^p),
 * in the kernel's unit times the time unit (a weight is an integral of H
 * over a cell, or h H(l h)).  They are what dmi_init computed: under
 * DMI_QUAD_LEFT h H(l h) (theta h H((N-1) h) for a partial last cell);
 * under DMI_QUAD_CELL the cells' integrals of H (exponential kernels in
 * closed form, callback kernels by the tanh-sinh rule of dmi_init); with
 * near cells (dmi_set_kernel_near) the near kernel's integrals over the m
 * near cells and the exponential sum's weights beyond.  The steps compute
 * the same sum: DIRECT and FFT from these weights, RECURSIVE (and AUTO's
 * recursion) as the exponential sum's recursion plus the near cells' part
 * G_near below, equal to it up to rounding.
 * Writes G[(l - first) n n + i n + j] = G_l[i n + j] for the lags
 * l = first .. first + count - 1, and G_near alike: the part of G_l that
 * the near cells add to the exponential sum's weights (the near kernel's
 * integral over cell l less the sum's weight there; zero for l >= m and
 * without near cells), what RECURSIVE adds to its recursion's sum.  Either
 * array may be NULL (count n n doubles each otherwise, written whole; the
 * solver keeps no pointer).  A call under RECURSIVE with full cells,
 * DMI_QUAD_LEFT and no near cells, where dmi_init kept no samples, computes
 * them from the exponential terms (N n n doubles of memory for the call).
 * Does not change the solver.
 * Errors: DMI_EINVAL for s NULL, both arrays NULL, or first + count > N
 * (the message names the lags); DMI_ESTATE before dmi_init; DMI_ENOMEM when
 * the samples of the recursion cannot be allocated; DMI_ENONFINITE when one
 * of them is not finite.
 */
DMI_API int dmi_get_kernel_weights(const dmi_solver *s, size_t first, size_t count, double *G,
                                   double *G_near);

/** ---- saving and restoring the time-stepping state -----------------------
 * The state is the step counter, the N + 1 stored states U^{p-N..p}, the
 * last step's terms and, for a kernel set by dmi_set_kernel_exp, the
 * recursion's sums (so its size depends on that kernel; format version 2
 * since libdmi 1.1); it does not include the callbacks, the resolvent choice,
 * the convolution method or the kernel (these stay as set on the solver that
 * loads it).  A solver of dmi_create_h whose h is not tau / N writes format
 * version 3 (since libdmi 1.2: version 2 and h, 8 bytes more); every other
 * solver still writes version 2.  dmi_state_load reads versions 1, 2 and 3:
 * version 1, written by libdmi 1.0 (version 2 without the recursion's sums,
 * refused by libdmi 1.1), loads since libdmi 1.2 into a solver whose h is
 * tau / N, and the sums of an exponential kernel's recursion are then
 * anchored afresh from the stored states (as for a state of another method;
 * stepping on agrees with the saving run to rounding).  The bytes
 * are native-endian, begin with a magic and a format version, and are
 * checked on load: a state saved by a solver with other n, N, tau or h, or a
 * truncated or corrupted buffer, is rejected with DMI_EINVAL and the solver
 * is unchanged.
 */

/** Number of bytes dmi_state_save writes; 0 for s == NULL. */
DMI_API size_t dmi_state_size(const dmi_solver *s);

/** Writes the state into buf[0..size-1].  DMI_EINVAL for NULL or size smaller
 * than dmi_state_size(s); DMI_ESTATE before dmi_init. */
DMI_API int dmi_state_save(const dmi_solver *s, void *buf, size_t size);

/** Restores a state written by dmi_state_save; size must equal
 * dmi_state_size(s) (for a state of format version 1, of libdmi 1.0: the
 * size that version had, dmi_state_size(s) less the recursion's part of 24
 * bytes and its sums; the error message says which size it expected).  Requires dmi_init to have run (the kernel samples come
 * from it).  DMI_EINVAL for bad bytes or another size, DMI_ESTATE before
 * dmi_init, DMI_ENOMEM; the solver is unchanged on error.  Stepping on from a
 * restored state gives bitwise the same results as the saving solver if both
 * use the same callbacks and convolution method (another method differs by
 * rounding only). */
DMI_API int dmi_state_load(dmi_solver *s, const void *buf, size_t size);

/** ---- sensitivities: the tangent of the scheme (since 1.6) ---------------
 * The states U^q and their sensitivities S^q = dU^q/dp in P parameters p_j,
 * stepped together: with X^q = U^q - h f(t_q, U^q) - h W^q the resolvent's
 * argument and T^q = dX^q/dp,
 *
 *     T^q     = S^q - h (f_u S^q + f_p) - h (sum_l G_l S^{q-l} + dW^q),
 *     S^{q+1} = R'(X^q) T^q + dR/dp,
 *
 * G_l the weights of the delay sum (dmi_get_kernel_weights, summed by the
 * solver's own engine) and dW^q = sum_l dG_l/dp U^{q-l} the kernel
 * parameters' part, which the caller gives (dmi_tangent_run).  f_u S + f_p
 * comes from the model at p (the solver s) and the models at
 * p + delta_j e_j (the solvers others[j], built by the caller with the same
 * n, N, h and kind of A): one call of each f per step and parameter (the
 * directional difference (f_j(U + delta_j S_j) - f(U)) / delta_j), or,
 * where that makes fewer calls, n forward-difference columns of f_u (relative
 * step 2^-26 max(1, |u_i|), as applied) and one call for each parameter that
 * f depends on (dmi_tangent_set_rhs_parameters).  R' is the resolvent's rule
 * of the step: friction holds a component (S_i = 0) or slips
 * (S_i = T_i -+ h dalpha_i/dp); the box holds at a bound (S_i = dlo_i/dp or
 * dhi_i/dp) or passes T_i; a resolvent callback is differenced,
 * (r_j(h, X + delta_j T_j) - U^{q+1}) / delta_j.  Where a friction component
 * reverses during a step (to the other sign at once, or through one step in
 * the dead zone), S_i of that component becomes rho (T_i - h s dalpha_i/dp),
 * rho = F+ / F- the saltation factor (F = u' just before and after the
 * reversal, phi = (U - X) / h interpolated linearly at the crossing, s the
 * sign of U_i^q), so that S converges at O(h) to the equation's
 * sensitivity, which the plain tangent misses by O(1) there.
 * Parameters are dimensionless here: S_j has the unit of U per unit of p_j.
 * The object keeps the handle s (which must outlive it and is stepped by
 * dmi_tangent_run) and copies from others what it needs (their f and
 * resolvent callbacks with their user pointers, which must stay valid, and
 * the differences of their friction or box, their history callbacks with
 * their user pointers); others may be freed after
 * dmi_tangent_create.  No other state is kept between calls.
 */
/**/

/** Opaque tangent object (dmi_tangent_create). */
typedef struct dmi_tangent dmi_tangent;

/** Flags of dmi_tangent_run (since 1.6). */
enum {
    /** The plain tangent of the scheme everywhere: no saltation factor. */
    DMI_TANGENT_PLAIN = 1
};

/** What a friction component does in a step, written by dmi_tangent_run
 * (since 1.6). */
enum {
    /** Nothing to report. */
    DMI_SWITCH_NONE = 0,
    /** It lands in the dead zone and stays (starts to stick). */
    DMI_SWITCH_STICK = 1,
    /** It reverses during the step: S_i was multiplied by the saltation factor. */
    DMI_SWITCH_REVERSAL = 2,
    /** It meets zero or changes sign, but the velocities interpolated at the
     * crossing do not have the signs of a reversal: no saltation factor (S_i
     * is the plain tangent there, off by O(1); a smaller h resolves it). */
    DMI_SWITCH_UNPLACED = 3
};

/**
 * (Since 1.6.)  A tangent object for the model s at p and the models
 * others[0..P-1] at p + delta_j e_j (delta: P finite nonzero values, the
 * steps actually applied, in the unit of p_j).  s must be an initialised
 * solver when dmi_tangent_run is called; others need not be (only their f,
 * resolvent and history callbacks, friction or box are read, here, and copied).  f
 * depends on p_j unless others[j]'s f and user pointer equal s's
 * (dmi_tangent_set_rhs_parameters overrides); the history's sensitivity is 0
 * unless dmi_tangent_set_history sets it.  On success *out owns the object
 * (dmi_tangent_free).
 * Errors (the message in dmi_last_error(s)): DMI_EINVAL for out or s NULL
 * (no message), P = 0, others or delta NULL, others[j] NULL, with another n,
 * N, h, last-cell weight or kind of A than s, a delta_j zero or not finite,
 * a friction or box of others[j] whose difference to s's is not finite
 * (a bound moved to or from infinity); DMI_ENOMEM.  *out is NULL on error.
 */
DMI_API int dmi_tangent_create(dmi_tangent **out, dmi_solver *s, size_t P,
                               const dmi_solver *const *others, const double *delta);

/**
 * (Since 1.6.)  The sensitivity of the window of stored states at the start
 * of the next dmi_tangent_run: S0[(k n + i) P + j] = dU_i^{p-N+k}/dp_j,
 * k = 0..N, oldest first as in dmi_get_window ((N + 1) n P doubles, copied;
 * NULL: zero again).  For a history z(t; p): (z(t_k; p + delta_j e_j) -
 * z(t_k; p)) / delta_j, e.g. from the windows of the initialised others.
 * Errors: DMI_EINVAL for t NULL or a value not finite (the message names
 * it); DMI_ENOMEM.  On error the object is unchanged.
 */
DMI_API int dmi_tangent_set_history(dmi_tangent *t, const double *S0);

/**
 * (Since 1.6.)  The sensitivity of the window from the history callbacks, as
 * dmi_init samples them (at t_{-k} = -k h, k = 0..N, and -tau at k = N):
 * for the parameters j with columns[j] nonzero (P values; NULL: those whose
 * others[j] has another history callback or user pointer than s),
 * S0 = (z_j(t_{-k}) - z(t_{-k})) / delta_j, z_j the history of others[j]
 * and z s's (0 where a model has none), computed once here (2 calls a time
 * at most: s's once for all parameters) and used by every later
 * dmi_tangent_run as dmi_tangent_set_history's S0; the other columns are 0.
 * (For a run from the window dmi_init sampled: p = 0.)
 * Errors (the message in dmi_last_error(s)): DMI_EINVAL for t NULL;
 * DMI_ECALLBACK when a history callback returns nonzero, DMI_ENONFINITE when
 * it gives a value that is not finite (the message names the model, s or
 * others[j], and t); DMI_ENOMEM.  On error the object is unchanged.
 */
DMI_API int dmi_tangent_sample_history(dmi_tangent *t, const int *columns);

/**
 * (Since 1.6.)  The derivatives of the exponential kernel's terms of s
 * (dmi_set_kernel_exp) in the parameters, for the kernel parameters' part of
 * the tangent's delay sum, computed by dmi_tangent_run in O(K n^2 P) a step
 * (the recursions of sum_l r_k^l U^{q-l} and sum_l l r_k^l U^{q-l},
 * r_k = e^{(a_k + i b_k) h}, restarted every 4 N steps from the states):
 * da[k P + j] = da_k/dp_j, db alike (K P values each; 1 / time unit per unit
 * of p_j), dC[((k n + i) n + m) P + j] = d(C_k)_{im}/dp_j and dD alike (K n n P
 * values each, dD NULL: all zero), under either quadrature rule (the cells'
 * weights of each term and their derivatives in a_k + i b_k in closed form).
 * This is the part dmi_tangent_run's dWU would otherwise carry (both are
 * added: give dWU only for what the terms do not say, e.g. the near cells of
 * dmi_set_kernel_near).  da NULL removes them.  The arrays are copied.
 * dmi_tangent_run then needs s's delay sum to be the recursion
 * (DMI_CONV_RECURSIVE, or AUTO choosing it) and refuses with DMI_EINVAL
 * otherwise.  Errors (the message in dmi_last_error(s)): DMI_EINVAL for t
 * NULL, db or dC NULL with da given, a kernel of s that is not of
 * dmi_set_kernel_exp, a value not finite (named); DMI_ENOMEM.  On error the
 * object is unchanged.
 */
DMI_API int dmi_tangent_set_kernel_terms(dmi_tangent *t, const double *da, const double *db,
                                         const double *dC, const double *dD);

/**
 * (Since 1.6.)  Which parameters f depends on: depends[j] nonzero when p_j
 * enters f (P values; NULL: the rule of dmi_tangent_create again).  A
 * parameter marked 0 gets f_p_j = 0 where f_u comes by columns; the
 * directional differences call every others[j]'s f (exact either way when
 * the mark is right).  Errors: DMI_EINVAL for t NULL.
 */
DMI_API int dmi_tangent_set_rhs_parameters(dmi_tangent *t, const int *depends);

/**
 * (Since 1.6.)  Steps s and its sensitivities steps times from its current
 * step p (t_q = (p + q) h):
 *   S         (steps + 1) n P doubles, required: S[(q n + i) P + j] =
 *             dU_i^{p+q}/dp_j (row 0 from dmi_tangent_set_history);
 *   dWU       steps n P doubles, or NULL (zero: the kernel does not depend
 *             on p): dWU[(q n + i) P + j] = sum_l dG_l/dp_j U^{p+q-l}, the
 *             kernel parameters' part of the delay sum at step q (the
 *             weights' derivatives, e.g. differences of the others'
 *             dmi_get_kernel_weights, applied to the states of this run:
 *             with dWU given, the run is usually made once without it to
 *             get the states, then again from the same start);
 *   U         (steps + 1) n doubles or NULL: U^{p+q};
 *   X         steps n doubles or NULL: X^{p+q}, the resolvent's argument of
 *             the step into U^{p+q+1};
 *   dX        steps n P doubles or NULL: T^q = dX^{p+q}/dp;
 *   switches  steps n values or NULL: DMI_SWITCH_* of component i in step q
 *             at [q n + i] (friction only, and not with DMI_TANGENT_PLAIN;
 *             all DMI_SWITCH_NONE otherwise).
 * flags: 0 or DMI_TANGENT_PLAIN.  The arrays are row-major, written whole,
 * and not kept.  s is stepped as by dmi_advance (the same states, bitwise),
 * then the tangent is run along those states with s's own delay-sum engine
 * (one per parameter, on the columns of S), its weights and its resolvent
 * rule.  Memory: about (steps + 1) n (2 + P) doubles beside the outputs
 * given, and one engine and window of S per parameter.
 * Errors (the message in dmi_last_error(s)): DMI_EINVAL for t NULL, S NULL,
 * steps = 0, or unknown flags; DMI_ESTATE when s is not initialised;
 * DMI_EINVAL also for kernel terms' derivatives without the recursion
 * (dmi_tangent_set_kernel_terms); DMI_ENOMEM (also when the sizes
 * overflow); the errors of dmi_step;
 * DMI_ECALLBACK when f or the resolvent callback of s or others[j] returns
 * nonzero in the tangent (the message names j and t); DMI_ENONFINITE when a
 * sensitivity is not finite (the message names the step, component and
 * parameter).  On error s is bitwise the solver it was before the call
 * (its state is saved and restored) and the outputs are unspecified.
 */
DMI_API int dmi_tangent_run(dmi_tangent *t, size_t steps, int flags, const double *dWU,
                            double *U, double *X, double *S, double *dX, signed char *switches);

/** (Since 1.6.)  Frees *t and sets *t = NULL (not the solvers); t == NULL
 * and *t == NULL are allowed and do nothing. */
DMI_API void dmi_tangent_free(dmi_tangent **t);

/** ---- errors -------------------------------------------------------------- */

/** Message of the last failure on s ("" if none, a generic text if s is
 * NULL), or the note of a dmi_init that succeeded with something to say
 * (starting "dmi_init: note: ": an exponent of dmi_set_kernel_singularity
 * larger than the kernel's).  Owned by s, valid until the next call on s. */
DMI_API const char *dmi_last_error(const dmi_solver *s);

/** Static description of an error code ("unknown error code" otherwise). */
DMI_API const char *dmi_strerror(int code);

#ifdef __cplusplus
}
#endif

#endif /* DMI_H */
