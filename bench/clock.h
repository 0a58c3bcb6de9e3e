/*
 * The benchmarks' clock.  Include first: it asks for POSIX clock_gettime.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_BENCH_CLOCK_H
#define DMI_BENCH_CLOCK_H

#define _POSIX_C_SOURCE 200809L
#include <time.h>

/* Monotonic wall-clock time in seconds. */
static inline double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* CPU time of the process in seconds: not counting the time other processes
 * of a shared machine run instead of it. */
static inline double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

#endif
