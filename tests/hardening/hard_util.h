/*
 * Helpers shared by the hardening tests: CUnit checks with a formatted
 * message, resident memory, and a check that nothing is printed.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef HARD_UTIL_H
#define HARD_UTIL_H

#include <stddef.h>

#include <CUnit/CUnit.h>

/* Records a CUnit assertion (non-fatal) with a printf-style message that
 * names the case, so that a failure in a table-driven loop says which row. */
void hard_check(int ok, unsigned line, const char *file, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
#define CHECK(cond, ...) hard_check((cond) ? 1 : 0, __LINE__, __FILE__, __VA_ARGS__)

/* Resident set size of this process in KiB (from /proc/self/statm), or -1. */
long hard_rss_kib(void);

/* Runs the CUnit registry with the basic interface (silent: no progress
 * output); returns 0 if every test passed, 1 otherwise. */
int hard_run_tests(int silent);

/* While "quiet" is active, file descriptors 1 and 2 go to a temporary file.
 * hard_quiet_end restores them and returns the number of bytes that were
 * written meanwhile, not counting lines of the sanitizers' runtimes (-1 if
 * the redirection failed). */
typedef struct {
    int saved_out, saved_err, fd;
} hard_quiet;
int hard_quiet_begin(hard_quiet *q);
long hard_quiet_end(hard_quiet *q);

#endif
