/*
 * libdmi's errors (errors.c): the message of dmi_last_error, the codes'
 * texts, the checks shared by the queries, and the search for a non-finite
 * value that names the culprit.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_ERRORS_H
#define DMI_ERRORS_H

#include <math.h>
#include <stddef.h>

#include "dmi.h"

/* Writes the message (printf format) for dmi_last_error; returns code.  The
 * message buffer is not part of the numerical state: s may be const. */
int dmi_fail(const dmi_solver *s, int code, const char *fmt, ...);

/* The index of the first non-finite x[i], or n.  (Inline: the step checks
 * its n values twice, and a call costs more than the loop.) */
static inline size_t dmi_first_nonfinite(const double *x, size_t n)
{
    size_t i = 0;
    while (i < n && isfinite(x[i]))
        i++;
    return i;
}

/* The same for long arrays (blocks of 8 without a branch per value). */
size_t dmi_first_nonfinite_long(const double *x, size_t n);

/* The checks of a query fn writing to out: s not NULL (else DMI_EINVAL),
 * out not NULL, s initialized.  DMI_OK or the error. */
int dmi_check_query(const dmi_solver *s, const void *out, const char *fn);

#endif
