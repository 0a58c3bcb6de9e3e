/*
 * What libdmi's core offers the FMU framework beyond dmi.h (not exported:
 * the framework compiles the core's sources into each FMU): the
 * resolvent's hold watched step by step (dmi.c) and the memory a solver
 * takes (engine.c), so that the framework asks libdmi instead of restating
 * its method choice or its layout.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_CORE_H
#define DMI_CORE_H

#include <stddef.h>
#include <stdint.h>

#include "dmi.h"

/*
 * The hold of component i at step p, from the resolvent's argument X^p
 * (U^0 at p = 0): with dmi_set_friction, 1 when |X_i| <= h alpha_i (the
 * resolvent held U_i at 0), else 0; with dmi_set_box, -1 when X_i <= lo_i,
 * +1 when X_i >= hi_i, else 0.
 */
typedef struct {
    size_t m;           /* the watched components comp[0..m-1], each < n */
    const size_t *comp;
    int *held;          /* their holds at the solver's step (m values, the caller's) */
    uint64_t changes;   /* steps at which a hold changed: counted on */
    uint64_t last_p;    /* the last of them (set when one is counted) */
} dmi_watch;

/* Fills w->held for s's current step: DMI_OK; DMI_ESTATE before dmi_init;
 * DMI_EINVAL when its operator is neither friction nor a box or a
 * component is not below n (with a message). */
int dmi_watch_start(dmi_solver *s, dmi_watch *w);

/* dmi_advance of up to steps steps that updates w (started) after each
 * step; with stop nonzero it returns after the first step at which a hold
 * changed.  *taken: the steps taken (also on an error, which leaves the
 * failed step untaken, as dmi_advance). */
int dmi_advance_watch(dmi_solver *s, size_t steps, dmi_watch *w, int stop, size_t *taken);

/* The bytes a solver configured as s (its n, kernel, rule and method;
 * dmi_init need not have run) allocates with N_cells cells of h: *peak while
 * dmi_init runs (dmi_create's ring, the new ring, the dense samples when it
 * samples the kernel, and the kept samples), *kept after it (the history
 * ring, 2 (N + 1) n doubles; the kernel's weights, N per entry used, unless
 * the recursion runs alone; the recursion's complex sums).  A callback
 * kernel counts every entry.  The FFT engine's buffers are not counted
 * (the core has none). */
void dmi_core_bytes(const dmi_solver *s, size_t N_cells, double h, double *peak, double *kept);

#endif
