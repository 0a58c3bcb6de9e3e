/*
 * A right-hand side for the threads test of the Python binding
 * (test_threads.py): on its first call it announces itself on a
 * counter shared by two solvers and waits until the other solver's callback
 * has arrived too.  Both can be inside it at once only if the two threads are
 * inside libdmi at the same time, i.e. the binding released the GIL.  The wait
 * is bounded (limit seconds), so a held GIL ends the wait with met = 0
 * instead of hanging.  f = 0 otherwise.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#define _POSIX_C_SOURCE 200809L
#include <sched.h>
#include <time.h>

typedef struct {
    int *arrived;  /* shared by the two solvers */
    double limit;  /* seconds to wait at most */
    int calls;     /* calls of this solver's rhs */
    int met;       /* 1: the other one had arrived within the limit */
} meet_data;

static double seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int meet_rhs(double t, const double *u, double *out, void *user)
{
    meet_data *d = user;
    (void)t;
    (void)u;
    (void)out;
    if (d->calls++ == 0) {
        __atomic_add_fetch(d->arrived, 1, __ATOMIC_SEQ_CST);
        const double end = seconds() + d->limit;
        while (__atomic_load_n(d->arrived, __ATOMIC_SEQ_CST) < 2 && seconds() < end)
            sched_yield();
        d->met = __atomic_load_n(d->arrived, __ATOMIC_SEQ_CST) >= 2;
    }
    return 0;
}
