/*
 * libdmi's errors: see errors.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "errors.h"

#include "solver.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

/* Every solver is allocated by dmi_create, never const-defined: writing
 * the message through a const handle is defined. */
int dmi_fail(const dmi_solver *cs, int code, const char *fmt, ...)
{
    dmi_solver *s = (dmi_solver *)cs;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->err, sizeof s->err, fmt, ap);
    va_end(ap);
    return code;
}

/* x * 0 is 0 for a finite x, NaN otherwise: a block of 8 with one is then
 * searched value by value. */
size_t dmi_first_nonfinite_long(const double *x, size_t n)
{
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        double z[2] = {0, 0};
        for (size_t k = 0; k < 8; k += 2)
            for (int c = 0; c < 2; c++)
                z[c] += x[i + k + (size_t)c] * 0.0;
        if (!(z[0] == 0 && z[1] == 0))
            break;
    }
    return i + dmi_first_nonfinite(x + i, n - i);
}

int dmi_check_query(const dmi_solver *s, const void *out, const char *fn)
{
    if (!s)
        return DMI_EINVAL;
    if (!out)
        return dmi_fail(s, DMI_EINVAL, "%s: output pointer is NULL", fn);
    if (!s->initialized)
        return dmi_fail(s, DMI_ESTATE, "%s: call dmi_init first", fn);
    return DMI_OK;
}

const char *dmi_strerror(int code)
{
    switch (code) {
    case DMI_OK: return "success";
    case DMI_EINVAL: return "invalid argument";
    case DMI_ENOMEM: return "out of memory";
    case DMI_ECALLBACK: return "a callback reported failure";
    case DMI_ENONFINITE: return "a non-finite value (NaN or infinity) appeared";
    case DMI_ESTATE: return "call not allowed in the solver's current state";
    default: return "unknown error code";
    }
}

const char *dmi_last_error(const dmi_solver *s)
{
    return s ? s->err : "no solver (NULL handle)";
}
