/*
 * The delay sum's engine (engine.c): which method runs (the choice of
 * DMI_CONV_AUTO and the checks of the others), and the dispatch of every
 * engine call to the direct sum, the FFT engine (conv.c, only when built
 * with DMI_HAVE_FFT) or the recursion (exp.c), with the cell rule's and
 * near cells' terms (cells.c).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_ENGINE_H
#define DMI_ENGINE_H

#include "solver.h"

/* Whether method is allowed with s's kernel (DMI_EINVAL and a message
 * naming fn if not). */
int dmi_engine_check_method(const dmi_solver *s, int method, const char *fn);

/* Whether method is the recursion (AUTO: for an exponential kernel whose
 * every term it takes), which needs no kernel samples. */
int dmi_engine_is_recursion(const dmi_solver *s, int method);

/* Whether method's engine needs the kernel's weights per cell: all but the
 * recursion with full cells, the paper's rule and no near cells. */
int dmi_engine_needs_samples(const dmi_solver *s, int method);

/* The engines that method asks for with kernel weights k (both NULL: the
 * direct sum).  DMI_OK, or DMI_ENOMEM with a message naming fn. */
int dmi_engine_make(const dmi_solver *s, const dmi_kernel *k, int method, dmi_conv **conv,
                    dmi_exp **rec, const char *fn);
void dmi_engine_free(dmi_conv *conv, dmi_exp *rec);

/* Recomputes the engines (either may be NULL) for s's step p from the ring. */
void dmi_engine_rebuild(const dmi_solver *s, dmi_conv *conv, dmi_exp *rec);

/* dmi_engine_sum but for the recursion alone (full cells, no near cells). */
const double *dmi_engine_sum_other(const dmi_solver *s, double *W);

/* W^p of s's engines, the last cell weighted theta h: the recursion's own
 * array (valid until the engine moves on), or W (n values) filled.  (The
 * recursion alone inline: the step's common case pays no call for the
 * dispatch.) */
static inline const double *dmi_engine_sum(const dmi_solver *s, double *W)
{
    if (s->rec && !s->near.nnz && s->theta == 1)
        return dmi_exp_sum(s->rec);
    return dmi_engine_sum_other(s, W);
}

/* The FFT engine's part of dmi_engine_advance. */
void dmi_engine_advance_fft(dmi_solver *s);

/* After a step was committed (U^p pushed, p counted). */
static inline void dmi_engine_advance(dmi_solver *s)
{
    if (s->rec)
        dmi_exp_advance(s->rec, &s->ring, s->p);
    else if (s->conv)
        dmi_engine_advance_fft(s);
}

#endif
