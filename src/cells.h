/*
 * The solver's exact cell rule (cells.c): the kernel's weights per cell as
 * the cells' means (closed forms for exponential kernels, quad.c's
 * integration for callbacks), the change of the partial last cell, and the
 * near cells of a kernel singular at 0 (dmi_set_kernel_near).  The messages
 * of a refused kernel are written here, from quad.c's reports.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_CELLS_H
#define DMI_CELLS_H

#include "quad.h"
#include "solver.h"

/* The cell rule's samples of s's kernel into k (the means over the N cells,
 * the last one over [(N-1) h, tau]) and *last = nnz values (malloc'd, NULL
 * for no kernel) to be added times U^{p-N+1} by dmi_cells_last: with them
 * every engine's sum is sum_l int_{cell l} H U^{p-l}.  Callback kernels by
 * dmi_quad_integrate (nodes: made here if empty, then kept for the caller
 * to free), exponential ones in closed form (s->cell_expk must be
 * dmi_quad_expk of s->expk).  DMI_OK or an error (message set; k and *last
 * empty). */
int dmi_cells_sample(dmi_solver *s, dmi_quad_nodes *nodes, dmi_kernel *k, double **last);

/* W += last[e] U_{col e}^{p-N+1} for each stored kernel entry e. */
void dmi_cells_last(const dmi_kernel *k, const dmi_history *r, const double *last, double *W);

/* The near cells of a kernel given as an exponential sum (the far part, in k
 * and *last as sampled for s's rule) and an exact callback below delta
 * (dmi_set_kernel_near): k's first m = ceil(delta / h) cells become the
 * callback's exact cell means, *last is re-indexed to the new entries, and
 * near = the m cells' exact means less the sum's, which the recursion adds
 * (dmi_cells_near_add).  m = 0: nothing changes, near empty.  DMI_OK or an
 * error (message set; k, *last unchanged, near empty). */
int dmi_cells_near(dmi_solver *s, dmi_quad_nodes *nodes, dmi_kernel *k, double **last,
                   dmi_kernel *near);

/* W += h sum_{l<m} near_l U^{p-l}. */
void dmi_cells_near_add(const dmi_kernel *near, const dmi_history *r, double h, double *W);

#endif
