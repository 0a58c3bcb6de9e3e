/*
 * dmi_py_run: the loop behind dmi.Solver.run (python/dmi/_solver.py): steps a
 * solver and records the states in C, with no Python between the steps.
 * dmi_py_linear: out = M x, the rhs and the resolvent of the tangent map of
 * dmi.analysis (python/dmi/analysis/_model.py), called by libdmi directly.
 * Part of the Python package dmi only (libdmipy.so beside libdmi.so.1 in the
 * package): libdmi's own API has no such call.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <stddef.h>

#include "dmi.h"

#if defined(__GNUC__) || defined(__clang__)
#define DMI_PY_API __attribute__((visibility("default")))
#else
#define DMI_PY_API
#endif

/*
 * From the solver's step p0 (dmi_init done), takes `steps` steps and records
 * t_p and U^p (n values, rows of U) at p = p0, p0 + stride, ..., every
 * stride-th step, and at p0 + steps if that is not among them: at most
 * steps / stride + 2 rows, the caller's arrays t and U hold that many.
 * *rows = the number of rows written, also on failure.  X: NULL, or room for
 * as many rows less one: row r - 1 = X^{q-1}, the resolvent's argument of the
 * last step into row r (at step q) of U (dmi_get_step_terms).  Returns DMI_OK
 * or the code of the first failing step (the steps before it are kept, as in
 * dmi_advance).  stride >= 1.
 */
DMI_PY_API int dmi_py_run(dmi_solver *s, size_t n, size_t steps, size_t stride, double *t,
                          double *U, double *X, size_t *rows)
{
    size_t r = 0;
    int rc = dmi_get_state(s, U);
    if (rc == DMI_OK) {
        t[r++] = dmi_time(s);
        for (size_t done = 0; done < steps;) {
            size_t chunk = steps - done < stride ? steps - done : stride;
            rc = dmi_advance(s, chunk);
            if (rc != DMI_OK)
                break;
            done += chunk;
            t[r] = dmi_time(s);
            dmi_get_state(s, U + r * n);
            if (X != NULL)
                dmi_get_step_terms(s, NULL, X + (r - 1) * n);
            r++;
        }
    }
    *rows = r;
    return rc;
}

/* A dense n x n matrix, row-major (ctypes builds it in _model.py). */
typedef struct {
    size_t n;
    double m[];
} dmi_py_matrix;

/*
 * out = M x for M = *user (a dmi_py_matrix): libdmi's rhs signature (t
 * ignored: f(t, u) = J u) and its resolvent signature (lam ignored: the
 * resolvent's derivative D x).  Always returns 0.
 */
DMI_PY_API int dmi_py_linear(double t, const double *x, double *out, void *user)
{
    const dmi_py_matrix *a = user;
    const size_t n = a->n;
    (void)t;
    for (size_t i = 0; i < n; i++) {
        double sum = 0.0;
        for (size_t j = 0; j < n; j++)
            sum += a->m[i * n + j] * x[j];
        out[i] = sum;
    }
    return 0;
}
