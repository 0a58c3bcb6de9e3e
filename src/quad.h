/*
 * The exact cell rule of the delay sum (quad.c): cells' means as the kernel
 * samples, the change of the partial last cell, and the exponential kernel
 * whose samples are its cells' means (what the recursion runs).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_QUAD_H
#define DMI_QUAD_H

#include "solver.h"

/* out = the exponential kernel with k's (a, b) whose samples at l h are
 * k's cells' means (1/h) int_{l h}^{(l+1) h} H: C' - i D' = (C - i D)
 * phi1((a + i b) h), entry by entry; it uses the same entries as k (its
 * recursion has the same sums).  0, or -1 when out of memory. */
int dmi_quad_expk(const dmi_expk *k, double h, dmi_expk *out);

/* The cell rule's samples of s's kernel into k (the means over the N cells,
 * the last one over [(N-1) h, tau]) and *last = nnz values (malloc'd, NULL
 * for no kernel) to be added times U^{p-N+1} by dmi_quad_last: with them
 * every engine's sum is sum_l int_{cell l} H U^{p-l}.  Callback kernels by
 * tanh-sinh quadrature, exponential ones in closed form (from
 * s->cell_expk, dmi_quad_expk of s->expk).  DMI_OK or an error (message
 * set; k and *last empty). */
int dmi_quad_sample(dmi_solver *s, dmi_kernel *k, double **last);

/* W += last[e] U_{col e}^{p-N+1} for each stored kernel entry e. */
void dmi_quad_last(const dmi_kernel *k, const dmi_history *r, const double *last, double *W);

/* The near cells of a kernel given as an exponential sum (the far part, in k
 * and *last as sampled for s's rule) and an exact callback below delta
 * (dmi_set_kernel_near): k's first m = ceil(delta / h) cells become the
 * callback's exact cell means (tanh-sinh), *last is re-indexed to the new
 * entries, and near = the m cells' exact means less the sum's, which the
 * recursion adds (dmi_quad_near_add).  m = 0: nothing changes, near empty.
 * DMI_OK or an error (message set; k, *last unchanged, near empty). */
int dmi_quad_near(dmi_solver *s, dmi_kernel *k, double **last, dmi_kernel *near);

/* W += h sum_{l<m} near_l U^{p-l}. */
void dmi_quad_near_add(const dmi_kernel *near, const dmi_history *r, double h, double *W);

#endif
