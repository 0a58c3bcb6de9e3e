/*
 * The misbehaving test model of capi_model.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "capi_model.h"

#include <float.h>
#include <math.h>

void model_default(model *m)
{
    cb_ctl ok = {CB_OK, 0, 0, 0};
    m->rhs = m->resolvent = m->kernel = m->history = ok;
}

void model_calm(model *m)
{
    m->rhs.mode = m->resolvent.mode = m->kernel.mode = m->history.mode = CB_OK;
}

/* Applies the misbehaviour of c to out[0..len-1]; returns the callback's code. */
static int misbehave(cb_ctl *c, double *out, size_t len)
{
    size_t call = c->calls++;
    if (c->mode == CB_OK || call < c->from)
        return 0;
    switch (c->mode) {
    case CB_FAIL: return 7;
    case CB_NAN: out[c->comp] = NAN; break;
    case CB_PINF: out[c->comp] = INFINITY; break;
    case CB_NINF: out[c->comp] = -INFINITY; break;
    case CB_HUGE:
    case CB_NEGHUGE:
        for (size_t i = 0; i < len; i++)
            out[i] = c->mode == CB_HUGE ? DBL_MAX : -DBL_MAX;
        break;
    }
    return 0;
}

int model_rhs(double t, const double *u, double *out, void *user)
{
    model *m = user;
    out[0] = -u[1] + 0.1 * t;
    out[1] = 0.5 * u[0];
    return misbehave(&m->rhs, out, 2);
}

int model_resolvent(double lambda, const double *x, double *out, void *user)
{
    model *m = user;
    out[0] = x[0] / (1 + lambda);
    out[1] = x[1] / (1 + lambda);
    return misbehave(&m->resolvent, out, 2);
}

int model_kernel(double s, double *out, void *user)
{
    model *m = user;
    out[0] = 0.5;
    out[2] = 0.25 + s;
    out[3] = 0.1;
    return misbehave(&m->kernel, out, 4);
}

int model_history(double t, double *out, void *user)
{
    model *m = user;
    out[0] = cos(t);
    out[1] = sin(t);
    return misbehave(&m->history, out, 2);
}

int model_solver(dmi_solver **s, model *m)
{
    int rc = dmi_create(s, MODEL_n, MODEL_TAU, MODEL_N);
    if (rc == DMI_OK)
        rc = dmi_set_rhs(*s, model_rhs, m);
    if (rc == DMI_OK)
        rc = dmi_set_resolvent(*s, model_resolvent, m);
    if (rc == DMI_OK)
        rc = dmi_set_kernel(*s, model_kernel, m);
    if (rc == DMI_OK)
        rc = dmi_set_history(*s, model_history, m);
    if (rc != DMI_OK)
        dmi_free(s);
    return rc;
}
