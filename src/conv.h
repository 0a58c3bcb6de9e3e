/*
 * The FFT method of the delay sum (conv.c; present only when libdmi is built
 * with DMI_HAVE_FFT): an exact block convolution engine whose whole state is a
 * function of p, the kernel and the history ring, so it can be rebuilt from
 * them at any p with bitwise the same future results.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_CONV_H
#define DMI_CONV_H

#include <stdint.h>

#include "delay.h"
#include "dmi.h" /* the methods DMI_CONV_* */

typedef struct dmi_conv dmi_conv;

/* For method DMI_CONV_FFT, or DMI_CONV_AUTO when its cost model predicts
 * the engine faster than the direct sum: *out = a new engine for kernel k
 * (its kernel spectra computed; call dmi_conv_rebuild before use).  Else
 * *out = NULL (use dmi_delay_sum).  0, or -1 when out of memory. */
int dmi_conv_create(dmi_conv **out, const dmi_kernel *k, size_t n, size_t N, int method);
void dmi_conv_free(dmi_conv *c);
/* Recomputes the engine's state for step p from the ring (U^{p-N..p}). */
void dmi_conv_rebuild(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p);
/* After U^p was pushed (p the new step counter): updates the blocks due at p. */
void dmi_conv_advance(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p);
/* W^p, as dmi_delay_sum, without changing the engine's state (c holds the
 * scratch of a low-rank kernel). */
void dmi_conv_sum(dmi_conv *c, const dmi_kernel *k, const dmi_history *r, uint64_t p, double h,
                  double *W);
/* Number of FFT block sizes in use (0: the engine degenerated to direct sums). */
size_t dmi_conv_levels(const dmi_conv *c);
/* The number of basis series of a low-rank kernel (conv.c), 0 when every
 * nonzero entry is convolved on its own. */
size_t dmi_conv_rank(const dmi_conv *c);

#endif
