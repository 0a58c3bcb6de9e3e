/*
 * Helpers shared by the hardening tests.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#define _POSIX_C_SOURCE 200809L
#include "hard_util.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <CUnit/Basic.h>

void hard_check(int ok, unsigned line, const char *file, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    CU_assertImplementation(ok ? CU_TRUE : CU_FALSE, line, msg, file, "", CU_FALSE);
}

long hard_rss_kib(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f)
        return -1;
    long size = 0, resident = -1;
    int got = fscanf(f, "%ld %ld", &size, &resident);
    fclose(f);
    if (got != 2)
        return -1;
    return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

int hard_run_tests(int silent)
{
    CU_basic_set_mode(silent ? CU_BRM_SILENT : CU_BRM_VERBOSE);
    CU_basic_run_tests();
    unsigned failures = CU_get_number_of_failures() + CU_get_number_of_tests_failed();
    int status = CU_get_error() != CUE_SUCCESS || failures != 0;
    CU_cleanup_registry();
    return status;
}

int hard_quiet_begin(hard_quiet *q)
{
    fflush(stdout);
    fflush(stderr);
    FILE *tmp = tmpfile();
    q->fd = tmp ? dup(fileno(tmp)) : -1;
    if (tmp)
        fclose(tmp);
    q->saved_out = dup(1);
    q->saved_err = dup(2);
    if (q->fd < 0 || q->saved_out < 0 || q->saved_err < 0 || dup2(q->fd, 1) < 0 ||
        dup2(q->fd, 2) < 0)
        return -1;
    return 0;
}

long hard_quiet_end(hard_quiet *q)
{
    fflush(stdout);
    fflush(stderr);
    long written = -1;
    if (q->saved_out >= 0)
        dup2(q->saved_out, 1);
    if (q->saved_err >= 0)
        dup2(q->saved_err, 2);
    if (q->fd >= 0 && lseek(q->fd, 0, SEEK_SET) == 0) {
        /* count what was written, except the sanitizers' own warnings (e.g.
         * "==1==WARNING: AddressSanitizer failed to allocate ...") */
        char line[1024];
        size_t len = 0;
        char c;
        written = 0;
        for (;;) {
            ssize_t got = read(q->fd, &c, 1);
            if (got == 1 && len + 1 < sizeof line)
                line[len++] = c;
            if (got != 1 || c == '\n') {
                line[len] = '\0';
                if (!strstr(line, "Sanitizer"))
                    written += (long)len;
                len = 0;
                if (got != 1)
                    break;
            }
        }
    }
    int fds[3] = {q->saved_out, q->saved_err, q->fd};
    for (int i = 0; i < 3; i++)
        if (fds[i] >= 0)
            close(fds[i]);
    return written;
}
