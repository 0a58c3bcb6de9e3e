/*
 * The FMU framework's model layer: see framework.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "framework.h"

#include "bytes.h"  /* libdmi's: FNV-1a, values at a byte offset */
#include "core.h"   /* libdmi's: dmi_watch (the resolvent's hold step by step), dmi_core_bytes */

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MODEL (&DMI_FMU_MODEL)

static int fail(char *err, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, FMU_ERRLEN, fmt, ap);
    va_end(ap);
    return -1;
}

/* ---- the table ---- */

static unsigned kind_of(const dmi_fmu_variable *x)
{
    static const char *const TYPES[] = {"Float64", "Int32", "Boolean"};
    static const char *const CAUSALITIES[] = {"parameter", "input", "output", "independent"};
    unsigned type = 0, causality = 0;
    for (unsigned k = 0; k < 3; k++)
        if (strcmp(x->type, TYPES[k]) == 0)
            type = FMU_FLOAT64 << k;
    for (unsigned k = 0; k < 4; k++)
        if (strcmp(x->causality, CAUSALITIES[k]) == 0)
            causality = FMU_PARAMETER << k;
    return type && causality ? type | causality : 0;
}

/* The number of value references: the table's, and the time if it has no
 * independent variable. */
static unsigned count_vr(void)
{
    for (size_t i = 0; i < MODEL->nvariables; i++)
        if (kind_of(&MODEL->variables[i]) & FMU_INDEPENDENT)
            return (unsigned)MODEL->nvariables;
    return (unsigned)MODEL->nvariables + 1;
}

unsigned fmu_kind(unsigned vr)
{
    if (vr < MODEL->nvariables)
        return kind_of(&MODEL->variables[vr]);
    return vr < count_vr() ? FMU_FLOAT64 | FMU_INDEPENDENT : 0;
}

int fmu_is_set(unsigned kind)
{
    return (kind & (FMU_PARAMETER | FMU_INPUT)) != 0;
}

static const char *name_of(unsigned vr)
{
    return vr < MODEL->nvariables ? MODEL->variables[vr].name : "time";
}

/* "Real", "Integer", "Boolean": the FMI 2.0 names, as in the messages. */
static const char *type_name(unsigned type)
{
    return type & FMU_FLOAT64 ? "Real" : type & FMU_INT32 ? "Integer" : "Boolean";
}

/* ---- values ---- */

/* The values, writable: the block right after *m->v, which v->value (read
 * only for the model) points to (sizeof *m->v is a multiple of a double's
 * alignment). */
static double *values_of(const fmu_model *m)
{
    return (double *)(m->v + 1);
}

int fmu_model_new(fmu_model *m)
{
    const unsigned nvr = count_vr();
    const size_t n = MODEL->n, nind = MODEL->indicators || MODEL->held ? MODEL->nindicators : 0;
    m->v = malloc(sizeof *m->v + (2 * nvr + 5 * n) * sizeof(double) +
                  2 * nvr * sizeof(unsigned) + 2 * nind * sizeof(int) + nvr);
    if (!m->v)
        return -1;
    m->v->value = values_of(m);
    m->out = values_of(m) + nvr;
    m->work = m->out + nvr;
    m->run = (unsigned *)(m->work + 5 * n);
    m->out_run = m->run + nvr;
    m->ind = (int *)(m->out_run + nvr);
    m->ind_new = m->ind + nind;
    m->kind = (unsigned char *)(m->ind_new + nind);
    m->nvr = nvr;
    for (unsigned vr = 0; vr < nvr; vr++)
        m->kind[vr] = (unsigned char)fmu_kind(vr);
    for (unsigned vr = nvr; vr-- > 0;) {
        const unsigned kind = m->kind[vr];
        const int real = (kind & FMU_FLOAT64) && !(kind & FMU_INDEPENDENT);
        m->run[vr] = real ? 1 + (vr + 1 < nvr ? m->run[vr + 1] : 0) : 0;
        m->out_run[vr] = real && (kind & FMU_OUTPUT) ? 1 + (vr + 1 < nvr ? m->out_run[vr + 1] : 0) : 0;
    }
    m->solver = NULL;
    fmu_model_defaults(m);
    return 0;
}

unsigned fmu_model_kind(const fmu_model *m, unsigned vr)
{
    return vr < m->nvr ? m->kind[vr] : 0;
}

void fmu_model_defaults(fmu_model *m)
{
    dmi_free(&m->solver);
    m->v->t_start = 0.0;
    for (unsigned vr = 0; vr < m->nvr; vr++)
        values_of(m)[vr] = fmu_is_set(m->kind[vr]) ? MODEL->variables[vr].start : 0.0;
    m->t_comm = 0.0;
    m->out_valid = 0;
    m->p = m->nevents = m->event_p = 0;
    m->h = 0.0;
    m->event = 0;
}

void fmu_model_free(fmu_model *m)
{
    dmi_free(&m->solver); /* before the values its callbacks read */
    free(m->v);
    m->v = NULL;
}

/* The framework's own checks of a value for vr (before the model's). */
static int framework_check(const fmu_model *m, unsigned vr, unsigned type, double value,
                           char *err)
{
    const unsigned kind = fmu_model_kind(m, vr);
    if (!(kind & type) || !fmu_is_set(kind))
        return fail(err, "value reference %u is not a settable %s variable", vr, type_name(type));
    const char *name = name_of(vr);
    if (!isfinite(value))
        return fail(err, "%s = %g: the value must be finite", name, value);
    if ((type & FMU_BOOLEAN) && value != 0 && value != 1)
        return fail(err, "%s = %g: a Boolean is 0 or 1", name, value);
    if (vr == MODEL->tau && !(value > 0))
        return fail(err, "%s = %.17g: the delay must be > 0", name, value);
    if (vr == MODEL->N && !(value >= 1))
        return fail(err, "%s = %.0f: the number of steps per tau must be >= 1", name, value);
    return 0;
}

/* The model's accept of a value for vr (after the framework's checks). */
static int model_accept(const fmu_model *m, unsigned vr, double value, char *err)
{
    err[0] = '\0';
    if (MODEL->accept && MODEL->accept(m->v, vr, value, err) != 0) {
        if (!err[0])
            return fail(err, "%s = %.17g: refused by the model", name_of(vr), value);
        return -1;
    }
    return 0;
}

int fmu_model_check(const fmu_model *m, unsigned vr, unsigned type, double value, char *err)
{
    return framework_check(m, vr, type, value, err) != 0 ? -1 : model_accept(m, vr, value, err);
}

void fmu_model_store(fmu_model *m, unsigned vr, double value)
{
    values_of(m)[vr] = value;
    m->out_valid = 0;
}

/* ---- memory ---- */

/* The N parameter: dmi_create's N (a model without a step function). */
static size_t steps_per_tau(const dmi_fmu_values *v)
{
    return (size_t)v->value[MODEL->N];
}

/* The bytes the solver of N cells of h allocates: the model's figures, or
 * libdmi's (dmi_core_bytes) for the solver s as configured; without one (its
 * history did not fit), for a solver of one cell configured alike; failing
 * that, the bound of a dense kernel (the history ring, 2 (N + 1) n doubles;
 * n^2 N kernel samples kept, the same again while sampling). */
static void solver_bytes(const dmi_fmu_values *v, const dmi_solver *s, size_t N_cells, double h,
                         double *peak, double *kept)
{
    if (MODEL->bytes) {
        MODEL->bytes(v, peak, kept);
        return;
    }
    const double tau = v->value[MODEL->tau];
    if (!(h > 0))
        h = tau / (double)N_cells;
    if (s) {
        dmi_core_bytes(s, N_cells, h, peak, kept);
        return;
    }
    dmi_solver *one = NULL;
    char msg[FMU_ERRLEN] = "";
    if (dmi_create(&one, MODEL->n, tau, 1) == DMI_OK && MODEL->configure(v, one, msg) == 0) {
        dmi_core_bytes(one, N_cells, h, peak, kept);
        dmi_free(&one);
        return;
    }
    dmi_free(&one);
    const double n = (double)MODEL->n, N = (double)N_cells, d = sizeof(double);
    const double ring = 2 * (N + 1) * n * d, samples = n * n * N * d;
    *kept = ring + samples;
    *peak = 2 * ring + 2 * samples;
}

/* The solver's N (dmi_get_N) in messages: "N = 12" (the N parameter's name)
 * or, with a step function, "N = 12 cells of h = .." (libdmi's N for h). */
static void name_N(size_t N, double h, char *out, size_t size)
{
    if (MODEL->step)
        snprintf(out, size, "N = %zu cells of h = %.17g", N, h);
    else
        snprintf(out, size, "%s = %zu", name_of(MODEL->N), N);
}

/* "N = .. steps per tau: <bytes> while initialising, <bytes> after" into out
 * (size bytes; cut to fit) for the solver's N and h (name_N). */
static void describe_bytes(const dmi_fmu_values *v, const dmi_solver *s, size_t N, double h,
                           char *out, size_t size)
{
    double kept, peak;
    solver_bytes(v, s, N, h, &peak, &kept);
    char what[96];
    name_N(N, h, what, sizeof what);
    snprintf(out, size, "%s %s: the solver allocates %.0f bytes (%.3g GB) "
                        "while initialising and keeps %.0f bytes (%.3g GB): a history of "
                        "2(N+1) states and N kernel samples",
             what, MODEL->step ? "in tau" : "steps per tau", peak, peak / 1e9, kept, kept / 1e9);
}

/* Out of memory in a solver of N cells of h (describe_bytes): the error
 * names N and the bytes needed. */
static int memory_fail(char *err, const char *what, const dmi_fmu_values *v, const dmi_solver *s,
                       size_t N, double h)
{
    int len = snprintf(err, FMU_ERRLEN, "%s: out of memory: ", what);
    if (len >= 0 && len < FMU_ERRLEN)
        describe_bytes(v, s, N, h, err + len, (size_t)(FMU_ERRLEN - len));
    return -1;
}

static int solver_fail(char *err, const char *what, dmi_solver *s, int rc)
{
    snprintf(err, FMU_ERRLEN, "%s: %s", what, s ? dmi_last_error(s) : dmi_strerror(rc));
    return -1;
}

/* ---- the solver ---- */

/* A new solver for the values v, configured by the model, not initialised:
 * only the history ring is allocated (with what the model's configure
 * allocates: the kernel's terms), nothing is sampled yet. */
static int solver_create(const dmi_fmu_values *v, dmi_solver **out, char *err)
{
    const double tau = v->value[MODEL->tau];
    int rc;
    if (MODEL->step) { /* the model's h: libdmi's N for it */
        const double h = MODEL->step(v);
        if (!isfinite(h) || !(h > 0))
            return fail(err, "creating the solver: the model's step h = %.17g must be finite "
                             "and > 0", h);
        rc = dmi_create_h(out, MODEL->n, tau, h);
        if (rc == DMI_ENOMEM)
            return fail(err, "creating the solver: out of memory: tau = %.17g, h = %.17g: a "
                             "history of tau / h = %.17g states", tau, h, tau / h);
        if (rc != DMI_OK)
            return fail(err, "creating the solver (tau = %.17g, h = %.17g): %s", tau, h,
                        dmi_strerror(rc));
    } else {
        rc = dmi_create(out, MODEL->n, tau, steps_per_tau(v));
        if (rc == DMI_ENOMEM) /* N is the parameter: no solver to ask */
            return memory_fail(err, "creating the solver", v, NULL, steps_per_tau(v), 0.0);
        if (rc != DMI_OK)
            return solver_fail(err, "creating the solver (tau, N)", NULL, rc);
    }
    char msg[FMU_ERRLEN] = "";
    if ((rc = MODEL->configure(v, *out, msg)) != 0) {
        if (rc == DMI_ENOMEM)
            memory_fail(err, "configuring the solver", v, *out, dmi_get_N(*out),
                        dmi_get_h(*out));
        else { /* the model's message after the prefix, cut to fit */
            const char *why = msg[0] ? msg : dmi_last_error(*out);
            size_t len = strlen(strcpy(err, "configuring the solver: "));
            for (size_t i = 0; why[i] && len + 1 < FMU_ERRLEN; i++)
                err[len++] = why[i];
            err[len] = '\0';
        }
        dmi_free(out);
        return -1;
    }
    return 0;
}

/* Samples the kernel and the history (dmi_init). */
static int solver_init(const dmi_fmu_values *v, dmi_solver *s, char *err)
{
    int rc = dmi_init(s);
    if (rc == DMI_ENOMEM)
        return memory_fail(err, "initialising the solver", v, s, dmi_get_N(s), dmi_get_h(s));
    return rc == DMI_OK ? 0 : solver_fail(err, "initialising the solver", s, rc);
}

int fmu_model_check_start(const fmu_model *m, double T, char *msg)
{
    msg[0] = '\0';
    return MODEL->check ? MODEL->check(m->v, T, msg) : 0;
}

/* The number of the model's indicators (0 without them). */
static size_t n_indicators(void)
{
    return MODEL->indicators || MODEL->held ? MODEL->nindicators : 0;
}

/* The watch of the model's built-in indicators (held) on m->ind. */
static dmi_watch held_watch(const fmu_model *m)
{
    dmi_watch w = {MODEL->nindicators, MODEL->held, m->ind, 0, 0};
    return w;
}

/* *pt: the point at time t of the solver's step p, in m->work (u, U,
 * U^{p-1}, W, X): u = U = U^p, W and X of step p (W = 0, X = U^0 when p = 0). */
static void step_point(fmu_model *m, double t, dmi_fmu_point *pt)
{
    const size_t n = MODEL->n;
    double *U = m->work + n, *W = U + 2 * n, *X = W + n;
    dmi_get_state(m->solver, U);
    if (m->p == 0) {
        for (size_t i = 0; i < n; i++) {
            X[i] = U[i];
            W[i] = 0.0;
        }
    } else {
        dmi_get_step_terms(m->solver, W, X);
    }
    pt->t = t;
    pt->h = m->h;
    pt->p = m->p;
    pt->u = pt->U = U;
    pt->W = W;
    pt->X = X;
}

/* The model's indicators at the solver's step p into st. */
static void indicators_at(fmu_model *m, int *st)
{
    dmi_fmu_point pt = {0.0, 0.0, 0, MODEL->n, NULL, NULL, NULL, NULL, m->nevents, m->event_p};
    step_point(m, m->v->t_start + (double)m->p * m->h, &pt);
    MODEL->indicators(m->v, &pt, st);
}

/* The indicators at the solver's step into m->ind (none: nothing): 0, or -1
 * with the reason in err (built-ins of an operator that has none). */
static int indicators_start(fmu_model *m, char *err)
{
    if (!n_indicators())
        return 0;
    if (!MODEL->held) {
        indicators_at(m, m->ind);
        return 0;
    }
    dmi_watch w = held_watch(m);
    return dmi_watch_start(m->solver, &w) == DMI_OK
               ? 0
               : fail(err, "the model's built-in indicators (held): %s",
                      dmi_last_error(m->solver));
}

int fmu_model_start(fmu_model *m, double t_start, char *err, char *note)
{
    note[0] = '\0';
    dmi_solver *s = NULL;
    if (solver_create(m->v, &s, err) != 0) /* allocates the ring only */
        return -1;
    double kept, peak; /* for libdmi's N, before dmi_init allocates the rest */
    solver_bytes(m->v, s, dmi_get_N(s), dmi_get_h(s), &peak, &kept);
    if (peak > FMU_NOTE_BYTES)
        describe_bytes(m->v, s, dmi_get_N(s), dmi_get_h(s), note, FMU_ERRLEN);
    if (solver_init(m->v, s, err) != 0) {
        dmi_free(&s);
        return -1;
    }
    dmi_free(&m->solver);
    m->solver = s;
    m->p = 0;
    m->h = dmi_get_h(s);
    m->v->t_start = t_start;
    m->t_comm = t_start;
    m->out_valid = 0;
    m->nevents = m->event_p = 0;
    m->event = 0;
    if (indicators_start(m, err) != 0) {
        dmi_free(&m->solver);
        return -1;
    }
    return 0;
}

/* The number of steps taken when the FMU is at time t: every step whose start
 * t_p = t_start + p h is before t by more than FMU_TIME_TOL h. */
static double steps_before(double t_start, double t, double h)
{
    return ceil((t - t_start) / h - FMU_TIME_TOL);
}

/* Steps the solver from step p to step target, one at a time, the
 * indicators after each (see fmu_model_do_step): 0, 1 when stopped early at
 * an event, or a libdmi error code (negative).  Not inlined (GCC, Clang):
 * the doStep of a model without indicators stays short. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static int steps_with_events(fmu_model *m, uint64_t p, uint64_t target, fmu_stop_fn *stop,
                             void *ctx)
{
    const size_t nind = n_indicators();
    const double h = m->h;
    while (p < target) {
        int rc = dmi_step(m->solver);
        if (rc != DMI_OK)
            return rc;
        m->p = ++p;
        indicators_at(m, m->ind_new);
        int changed = 0;
        for (size_t k = 0; k < nind; k++) {
            changed |= m->ind_new[k] != m->ind[k];
            m->ind[k] = m->ind_new[k];
        }
        if (!changed)
            continue;
        m->nevents++;
        m->event_p = p;
        m->event = 1;
        const double t_p = m->v->t_start + (double)p * h;
        if (p < target && stop && stop(ctx, t_p)) {
            m->t_comm = t_p;
            return 1;
        }
    }
    return 0;
}

/* steps_with_events for the built-in indicators (held): libdmi counts the
 * changes as it steps, and stops at one only when it may end the
 * communication step (stop). */
static int steps_with_held(fmu_model *m, uint64_t p, uint64_t target, fmu_stop_fn *stop,
                           void *ctx)
{
    dmi_watch w = held_watch(m);
    while (p < target) {
        size_t taken = 0;
        w.changes = 0;
        int rc = dmi_advance_watch(m->solver, (size_t)(target - p), &w, stop != NULL, &taken);
        m->p = p += taken;
        if (w.changes) {
            m->nevents += w.changes;
            m->event_p = w.last_p;
            m->event = 1;
        }
        if (rc != DMI_OK)
            return rc;
        if (w.changes && p < target && stop && stop(ctx, m->v->t_start + (double)p * m->h)) {
            m->t_comm = m->v->t_start + (double)p * m->h;
            return 1;
        }
    }
    return 0;
}

int fmu_model_do_step(fmu_model *m, double t_current, double step, fmu_stop_fn *stop,
                      void *ctx, int *early, char *err)
{
    *early = 0;
    const double h = m->h;
    if (!isfinite(t_current) || !isfinite(step) || !(step > 0))
        return fail(err, "the time %.17g and the step %.17g must be finite and the step > 0",
                    t_current, step);
    if (fabs(t_current - m->t_comm) > FMU_TIME_TOL * h)
        return fail(err, "the communication point %.17g is not the FMU's time %.17g", t_current,
                    m->t_comm);
    const double t_end = t_current + step;
    const double target = steps_before(m->v->t_start, t_end, h);
    const uint64_t p = m->p;
    if (!(target < 9007199254740992.0)) /* 2^53: beyond it p h has no meaning */
        return fail(err, "t = %.17g is too far from the start for the step h", t_end);
    m->out_valid = 0;
    m->event = 0;
    if (target > (double)p) {
        int rc = MODEL->held     ? steps_with_held(m, p, (uint64_t)target, stop, ctx)
                 : n_indicators() ? steps_with_events(m, p, (uint64_t)target, stop, ctx)
                                  : dmi_advance(m->solver, (size_t)(target - (double)p));
        if (rc == 1) {
            *early = 1;
            return 0;
        }
        if (rc != DMI_OK) {
            dmi_get_step_index(m->solver, &m->p); /* the steps taken are kept */
            solver_fail(err, "the solver failed", m->solver, rc);
            return -2;
        }
        m->p = (uint64_t)target;
    }
    m->t_comm = t_end;
    return 0;
}

/* ---- outputs ---- */

/* The model's outputs at t_comm into m->out: u = u_h(t_comm) interpolated
 * between U^{p-1} and U^p, W and X of that step.  Before the first step: U^0
 * (u = X = U^0, W = 0); before the solver: no state. */
static void outputs(fmu_model *m)
{
    const size_t n = MODEL->n;
    double *u = m->work, *U = u + n, *prev = U + n;
    dmi_fmu_point pt = {m->t_comm, 0.0, 0, n, NULL, NULL, NULL, NULL, m->nevents, m->event_p};
    if (m->solver) {
        step_point(m, m->t_comm, &pt);
        const double theta =
            m->p > 0 ? (m->t_comm - m->v->t_start) / m->h - (double)(m->p - 1) : 1.0;
        if (theta < 1.0 - FMU_TIME_TOL) { /* between t_{p-1} and t_p */
            const double th = theta > 0.0 ? theta : 0.0;
            dmi_get_past(m->solver, 1, prev);
            for (size_t i = 0; i < n; i++)
                u[i] = prev[i] + th * (U[i] - prev[i]);
            pt.u = u;
        } /* else at t_p (or before the first step): u = U^p */
    }
    MODEL->outputs(m->v, &pt, m->out);
    m->out_valid = 1;
}

int fmu_model_get(fmu_model *m, unsigned vr, unsigned type, double *value, char *err)
{
    const unsigned kind = fmu_model_kind(m, vr);
    if (!(kind & type & (FMU_FLOAT64 | FMU_INT32 | FMU_BOOLEAN)) ||
        ((type & FMU_NO_INDEPENDENT) && (kind & FMU_INDEPENDENT)))
        return fail(err, "value reference %u is not %s %s variable", vr,
                    type & FMU_INT32 ? "an" : "a", type_name(type));
    if (fmu_is_set(kind)) {
        *value = m->v->value[vr];
    } else if (kind & FMU_INDEPENDENT) {
        *value = m->t_comm;
    } else {
        if (!m->out_valid)
            outputs(m);
        *value = m->out[vr];
    }
    return 0;
}

int fmu_model_get_reals(fmu_model *m, const unsigned vr[], size_t nvr, unsigned type,
                        double *values, char *err)
{
    /* the bulk path: vr[0], vr[0] + 1, ..., all Float64 parameters, inputs
     * and outputs (run), read from the values and the outputs */
    const unsigned first = nvr > 0 ? vr[0] : 0;
    if (nvr > 0 && first < m->nvr && m->run[first] >= nvr) {
        if (!m->out_valid)
            outputs(m);
        const double *value = m->v->value + first, *out = m->out + first;
        const unsigned char *kind = m->kind + first;
        size_t i = 0;
        if (m->out_run[first] >= nvr) /* outputs only: a copy */
            for (; i < nvr && vr[i] == first + i; i++)
                values[i] = out[i];
        else
            for (; i < nvr && vr[i] == first + i; i++)
                values[i] = kind[i] & FMU_OUTPUT ? out[i] : value[i];
        if (i == nvr)
            return 0;
        /* not a run after all: value by value (values[] is rewritten) */
    }
    for (size_t i = 0; i < nvr; i++)
        if (fmu_model_get(m, vr[i], type, &values[i], err) != 0)
            return -1;
    return 0;
}

void fmu_model_set_start(fmu_model *m, double t_start)
{
    m->v->t_start = t_start;
    m->t_comm = t_start;
    m->out_valid = 0;
}

/* ---- saved state ---- */

/* The numbers of Float64 and of other values set (the state's layout). */
static void count_set(size_t *nreal, size_t *nint)
{
    *nreal = *nint = 0;
    for (unsigned vr = 0; vr < MODEL->nvariables; vr++) {
        const unsigned kind = fmu_kind(vr);
        if (fmu_is_set(kind))
            ++*(kind & FMU_FLOAT64 ? nreal : nint);
    }
}

/* The offsets, in a state of format version, of the integers, of the
 * Float64 values (after the integers) and of libdmi's part (after them,
 * t_start and t_comm). */
static size_t at_int(uint32_t version)
{
    return version >= 3 ? FMU_STATE_AT_INT : FMU_STATE_AT_INT_V2;
}

static size_t at_real(uint32_t version)
{
    size_t nreal, nint;
    count_set(&nreal, &nint);
    return at_int(version) + 8 * nint;
}

static size_t at_dmi(uint32_t version)
{
    size_t nreal, nint;
    count_set(&nreal, &nint);
    return at_int(version) + 8 * (nint + nreal + 2);
}

/* FNV-1a 64 of a string and its NUL. */
static uint64_t hash_text(uint64_t x, const char *text)
{
    return dmi_fnv1a(x, (const unsigned char *)text, strlen(text) + 1);
}

uint64_t fmu_model_hash(void)
{
    uint64_t x = DMI_FNV1A_INIT;
    for (size_t vr = 0; vr < MODEL->nvariables; vr++) {
        const dmi_fmu_variable *v = &MODEL->variables[vr];
        const char *const text[] = {v->name, v->type, v->causality, v->start_text, v->unit,
                                    v->description};
        for (size_t k = 0; k < DMI_FMU_COUNT(text); k++)
            x = hash_text(x, text[k] ? text[k] : "");
    }
    const uint64_t n = MODEL->n;
    x = dmi_fnv1a(x, (const unsigned char *)&n, sizeof n);
    return hash_text(x, dmi_fmu_guid);
}

size_t fmu_model_state_size(const fmu_model *m)
{
    return at_dmi(FMU_STATE_VERSION) + dmi_state_size(m->solver) + 8;
}

void fmu_model_state_save(const fmu_model *m, uint32_t tag, unsigned char *buf)
{
    const size_t total = fmu_model_state_size(m), ndmi = dmi_state_size(m->solver);
    size_t nreal, nint, at_i = at_int(FMU_STATE_VERSION), at_r = at_real(FMU_STATE_VERSION);
    count_set(&nreal, &nint);
    memcpy(buf, FMU_STATE_MAGIC, 8);
    dmi_put_u32(buf, FMU_STATE_AT_VERSION, FMU_STATE_VERSION);
    dmi_put_u32(buf, FMU_STATE_AT_TAG, tag);
    dmi_put_u64(buf, FMU_STATE_AT_TOTAL, total);
    dmi_put_u64(buf, FMU_STATE_AT_NREAL, nreal);
    dmi_put_u64(buf, FMU_STATE_AT_NDMI, ndmi);
    dmi_put_u64(buf, FMU_STATE_AT_HASH, fmu_model_hash());
    dmi_put_u64(buf, FMU_STATE_AT_NEVENTS, m->nevents);
    dmi_put_u64(buf, FMU_STATE_AT_EVENT_P, m->event_p);
    memset(buf + FMU_STATE_AT_NAME, 0, FMU_STATE_NAMELEN);
    for (size_t i = 0; dmi_fmu_model_name[i] && i + 1 < FMU_STATE_NAMELEN; i++)
        buf[FMU_STATE_AT_NAME + i] = (unsigned char)dmi_fmu_model_name[i];
    for (unsigned vr = 0; vr < MODEL->nvariables; vr++) {
        const unsigned kind = m->kind[vr];
        if (!fmu_is_set(kind))
            continue;
        if (kind & FMU_FLOAT64) {
            dmi_put_double(buf, at_r, m->v->value[vr]);
            at_r += 8;
        } else {
            dmi_put_u64(buf, at_i, (uint64_t)(int64_t)m->v->value[vr]);
            at_i += 8;
        }
    }
    dmi_put_double(buf, at_r, m->v->t_start);
    dmi_put_double(buf, at_r + 8, m->t_comm);
    if (m->solver)
        dmi_state_save(m->solver, buf + at_r + 16, ndmi);
    dmi_put_u64(buf, total - 8, dmi_fnv1a(DMI_FNV1A_INIT, buf, total - 8));
}

/* The values of the state bytes (format version) into m (checked as if
 * set); 0 or -1 (err). */
static int load_values(fmu_model *m, uint32_t version, const unsigned char *buf, char *err)
{
    /* Two rounds: each value read, checked by the framework and stored; then
     * each accepted by the model, so that an accept that compares two
     * variables sees the state's values (all of them checked already), not
     * the start values beside them.  (m is a fresh model: a refusal frees it.) */
    for (int round = 0; round < 2; round++) {
        size_t at_i = at_int(version), at_r = at_real(version);
        for (int pass = 0; pass < 2; pass++) /* the Float64 values first, then the others */
            for (unsigned vr = 0; vr < MODEL->nvariables; vr++) {
                const unsigned kind = m->kind[vr];
                if (!fmu_is_set(kind) || ((kind & FMU_FLOAT64) != 0) != (pass == 0))
                    continue;
                const int64_t x = pass == 0 ? 0 : (int64_t)dmi_get_u64(buf, at_i);
                const double value = pass == 0 ? dmi_get_double(buf, at_r) : (double)x;
                *(pass == 0 ? &at_r : &at_i) += 8;
                int bad;
                if (round == 0) {
                    bad = (pass == 1 && (x < INT32_MIN || x > INT32_MAX)) ||
                          framework_check(m, vr, kind, value, err) != 0;
                    if (!bad)
                        fmu_model_store(m, vr, value);
                } else {
                    bad = model_accept(m, vr, value, err) != 0;
                }
                if (bad)
                    return pass == 0 ? -1
                                     : fail(err, "state: %s = %lld is invalid", name_of(vr),
                                            (long long)x);
            }
    }
    return 0;
}

/* The solver of the saved history b (ndmi bytes, in a state of format
 * version) for the values of m. */
static int load_solver(fmu_model *m, uint32_t version, const unsigned char *b, uint64_t ndmi,
                       char *err)
{
    /* libdmi's state holds the N + 1 stored states U^{p-N..p} of n doubles:
     * fewer bytes cannot be a history for this N, refused before the
     * solver's ring for N is allocated when N is dmi_create's, the N
     * parameter (a model's step gives libdmi's N only from the created
     * solver: the exact size below); then the exact size from libdmi. */
    if (!MODEL->step &&
        ndmi / (MODEL->n * sizeof(double)) < (uint64_t)steps_per_tau(m->v) + 1)
        return fail(err, "state: the solver's history of %llu bytes is too short for %s = %zu",
                    (unsigned long long)ndmi, name_of(MODEL->N), steps_per_tau(m->v));
    dmi_solver *s = NULL;
    if (solver_create(m->v, &s, err) != 0)
        return -1;
    /* format 1 (the FMU of libdmi 1.0) holds libdmi's state of format 1,
     * which ends before the recursion's part (bytes.h) */
    const size_t need = version == 1 ? dmi_state_at_rec(MODEL->n, dmi_get_N(s))
                                     : dmi_state_size(s);
    if (need != ndmi) {
        char N[96];
        name_N(dmi_get_N(s), dmi_get_h(s), N, sizeof N);
        dmi_free(&s);
        return fail(err, "state: the solver's history has %llu bytes, %s needs %zu",
                    (unsigned long long)ndmi, N, need);
    }
    int rc = solver_init(m->v, s, err);
    if (rc == 0 && (rc = dmi_state_load(s, b, (size_t)ndmi)) != DMI_OK)
        solver_fail(err, "state: the solver's history", s, rc);
    /* The FMU's time is never beyond the solver's t_p (a doStep takes the
     * steps up to it): a communication point far ahead would make the next
     * doStep take all the steps to it. */
    uint64_t p = 0;
    if (rc == 0 && (dmi_get_step_index(s, &p) != DMI_OK ||
                    steps_before(m->v->t_start, m->t_comm, dmi_get_h(s)) > (double)p))
        rc = fail(err, "state: the communication point %.17g is beyond the solver's step %llu",
                  m->t_comm, (unsigned long long)p);
    if (rc != 0) {
        dmi_free(&s);
        return -1;
    }
    m->solver = s;
    m->p = p;
    m->h = dmi_get_h(s);
    return 0;
}

/* A state of format 3 names its model: another model's is refused (0 or -1). */
static int check_identity(const unsigned char *buf, char *err)
{
    char name[FMU_STATE_NAMELEN];
    memcpy(name, buf + FMU_STATE_AT_NAME, FMU_STATE_NAMELEN);
    name[FMU_STATE_NAMELEN - 1] = '\0';
    for (char *c = name; *c; c++) /* shown in a message: printable ASCII only */
        if (*c < ' ' || *c > '~')
            *c = '?';
    const uint64_t hash = dmi_get_u64(buf, FMU_STATE_AT_HASH), own = fmu_model_hash();
    /* the saved name is cut to FMU_STATE_NAMELEN - 1 characters */
    if (hash == own && strncmp(name, dmi_fmu_model_name, FMU_STATE_NAMELEN - 1) == 0)
        return 0;
    return fail(err, "state: the state is of model \"%s\" (variables and GUID hash %016llx), "
                     "this FMU is model \"%s\" (hash %016llx)",
                name, (unsigned long long)hash, dmi_fmu_model_name, (unsigned long long)own);
}

int fmu_model_state_load(fmu_model *into, uint32_t tags, uint32_t solver_tags, uint32_t *tag,
                         const unsigned char *buf, size_t size, char *err)
{
    size_t nreal_model, nint;
    count_set(&nreal_model, &nint);
    if (!buf || size < FMU_STATE_AT_VERSION + 4)
        return fail(err, "state: %zu bytes is too short for a saved state", size);
    if (memcmp(buf, FMU_STATE_MAGIC, 8) != 0)
        return fail(err, "state: the bytes are not a saved state of this FMU (bad magic)");
    const uint32_t version = dmi_get_u32(buf, FMU_STATE_AT_VERSION);
    if (version < 1 || version > FMU_STATE_VERSION)
        return fail(err, "state: format version %lu is not supported (this FMU reads versions 1 "
                         "to %d)", (unsigned long)version, FMU_STATE_VERSION);
    const size_t AT_DMI = at_dmi(version), AT_REAL = at_real(version);
    if (size < AT_DMI + 8)
        return fail(err, "state: %zu bytes is too short for a saved state", size);
    if (version >= 3 && check_identity(buf, err) != 0)
        return -1;
    const uint64_t total = dmi_get_u64(buf, FMU_STATE_AT_TOTAL);
    const uint64_t nreal = dmi_get_u64(buf, FMU_STATE_AT_NREAL);
    const uint64_t ndmi = dmi_get_u64(buf, FMU_STATE_AT_NDMI);
    *tag = dmi_get_u32(buf, FMU_STATE_AT_TAG);
    if (*tag == 0 || (*tag & (*tag - 1)) != 0 || (*tag & tags) == 0)
        return fail(err, "state: the saved phase tag %lu is not allowed", (unsigned long)*tag);
    if (nreal != nreal_model || total != size || ndmi != size - (AT_DMI + 8))
        return fail(err, "state: the sizes recorded in the state do not match (%zu bytes given)",
                    size);
    if (dmi_get_u64(buf, size - 8) != dmi_fnv1a(DMI_FNV1A_INIT, buf, size - 8))
        return fail(err, "state: the checksum does not match (corrupted bytes)");
    const double t_start = dmi_get_double(buf, AT_REAL + 8 * nreal);
    const double t_comm = dmi_get_double(buf, AT_REAL + 8 * (nreal + 1));

    fmu_model m;
    if (fmu_model_new(&m) != 0)
        return fail(err, "state: out of memory");
    if (load_values(&m, version, buf, err) != 0)
        goto refused;
    if (!isfinite(t_start) || !isfinite(t_comm) || t_comm < t_start) {
        fail(err, "state: invalid times (start %.17g, communication point %.17g)", t_start,
             t_comm);
        goto refused;
    }
    m.v->t_start = t_start;
    m.t_comm = t_comm;
    const int has_solver = (*tag & solver_tags) != 0;
    if (has_solver != (ndmi > 0)) {
        fail(err, "state: the saved phase tag %lu %s the solver's history, the state has %llu "
                  "bytes of it", (unsigned long)*tag, has_solver ? "needs" : "has no",
             (unsigned long long)ndmi);
        goto refused;
    }
    if (has_solver) {
        if (load_solver(&m, version, buf + AT_DMI, ndmi, err) != 0)
            goto refused;
    } else if (t_comm != t_start) { /* before initialization: no step taken */
        fail(err, "state: invalid times (start %.17g, communication point %.17g)", t_start,
             t_comm);
        goto refused;
    }
    m.out_valid = 0;
    if (version >= 3) {
        const uint64_t p = m.solver ? m.p : 0;
        m.nevents = dmi_get_u64(buf, FMU_STATE_AT_NEVENTS);
        m.event_p = dmi_get_u64(buf, FMU_STATE_AT_EVENT_P);
        if (m.event_p > p || m.nevents > p || (m.event_p > 0) != (m.nevents > 0)) {
            fail(err, "state: the events (%llu, the last at step %llu) do not fit the solver's "
                      "step %llu", (unsigned long long)m.nevents, (unsigned long long)m.event_p,
                 (unsigned long long)p);
            goto refused;
        }
    }
    if (m.solver && indicators_start(&m, err) != 0)
        goto refused;
    if (into) {
        fmu_model_free(into);
        *into = m; /* the solver's callbacks keep m.v, which moves with it */
    } else {
        fmu_model_free(&m);
    }
    return 0;
refused:
    fmu_model_free(&m);
    return -1;
}
