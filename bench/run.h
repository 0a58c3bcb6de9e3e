/*
 * A solver of the benchmarks, stepped in chunks and keeping its trajectory.
 * Include after clock.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_BENCH_RUN_H
#define DMI_BENCH_RUN_H

#include <stdlib.h>

#include "paper.h"

typedef struct {
    dmi_solver *s;
    paper_example ex;
    double mem, secs, *w; /* w: the trajectory (w, v) of every step */
} run;

/* Frees the solver and the trajectory (r may be zero-initialised). */
static inline void finish(run *r)
{
    dmi_free(&r->s);
    free(r->w);
    r->w = NULL;
}

/* Steps from..to-1, keeping the states; secs grows by the time taken on
 * clock (now or cpu_now of clock.h). */
static inline int chunk(run *r, size_t from, size_t to, double (*clock)(void))
{
    double t0 = clock();
    for (size_t p = from; p < to; p++) {
        int rc = dmi_step(r->s);
        if (rc != DMI_OK)
            return rc;
        dmi_get_state(r->s, r->w + 2 * p);
    }
    r->secs += clock() - t0;
    return DMI_OK;
}

#endif
