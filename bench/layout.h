/*
 * The allocator of a benchmark process as a fresh process has it: glibc
 * raises its mmap threshold when a block it mapped is freed, and the
 * configurations timed after that place their arrays otherwise, which moved
 * a step's cost by 25 % (docs/benchmarks-scale.md, section 1b).  Call once,
 * first thing in main.  Other C libraries: nothing.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_BENCH_LAYOUT_H
#define DMI_BENCH_LAYOUT_H

#ifdef __GLIBC__
#include <malloc.h>
#endif

static inline void fresh_allocator(void)
{
#ifdef __GLIBC__
    mallopt(M_MMAP_THRESHOLD, 128 * 1024); /* glibc's initial value, kept */
#endif
}

#endif
