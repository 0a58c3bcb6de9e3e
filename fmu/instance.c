/*
 * The FMI side common to FMI 2.0 and 3.0: see instance.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "instance.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ANY_STATE                                                                                 \
    (FMU_INSTANTIATED | FMU_INIT_MODE | FMU_STEP_MODE | FMU_TERMINATED | FMU_ERROR_STATE |      \
     FMU_EVENT_MODE)
/* The states an FMU state can be taken in (and restored to). */
#define SAVABLE (FMU_INSTANTIATED | FMU_INIT_MODE | FMU_STEP_MODE | FMU_TERMINATED | FMU_EVENT_MODE)
/* The states with a solver (after ExitInitializationMode): their saved
 * states hold the history. */
#define HAS_SOLVER (FMU_STEP_MODE | FMU_TERMINATED | FMU_EVENT_MODE)

/* The calling sequence: the states in which each function is allowed. */
static const unsigned ALLOWED[FN_COUNT] = {
    [FN_SET_DEBUG_LOGGING] = ANY_STATE,
    [FN_FREE_INSTANCE] = ANY_STATE,
    [FN_SETUP_EXPERIMENT] = FMU_INSTANTIATED,
    [FN_ENTER_INIT] = FMU_INSTANTIATED,
    [FN_EXIT_INIT] = FMU_INIT_MODE,
    [FN_TERMINATE] = FMU_STEP_MODE | FMU_EVENT_MODE,
    [FN_RESET] = ANY_STATE,
    [FN_GET] = FMU_INIT_MODE | FMU_STEP_MODE | FMU_TERMINATED | FMU_ERROR_STATE | FMU_EVENT_MODE,
    [FN_SET] = FMU_INSTANTIATED | FMU_INIT_MODE | FMU_STEP_MODE | FMU_EVENT_MODE,
    [FN_GET_STATE] = SAVABLE,
    [FN_SET_STATE] = ANY_STATE,
    [FN_FREE_STATE] = ANY_STATE,
    [FN_STATE_SIZE] = ANY_STATE,
    [FN_SERIALIZE] = ANY_STATE,
    [FN_DESERIALIZE] = ANY_STATE,
    [FN_DO_STEP] = FMU_STEP_MODE,
    [FN_ENTER_EVENT] = FMU_STEP_MODE,
    [FN_ENTER_STEP] = FMU_EVENT_MODE,
    [FN_UPDATE_DISCRETE] = FMU_EVENT_MODE,
    [FN_STATUS] = FMU_INIT_MODE | FMU_STEP_MODE | FMU_TERMINATED | FMU_ERROR_STATE,
    [FN_UNSUPPORTED] = ANY_STATE,
};

/* Log categories, as declared in both model descriptions. */
#define CAT_NAME(name, description) #name,
static const char *const CATEGORY[] = {FMU_LOG_CATEGORIES(CAT_NAME)};
#undef CAT_NAME
enum { CAT_ERROR, CAT_WARNING, CAT_CALLS, CAT_MEMORY, NCAT };
#define CAT_ALL ((1u << NCAT) - 1)

struct fmu_instance {
    char *name;
    fmu_sink *sink;
    fmu_callback logger;
    void *environment;
    int logging_instantiate; /* loggingOn of Instantiate, restored by Reset */
    int logging_on;
    unsigned categories; /* bits 1 << CAT_* enabled for debug logging */
    int logged;          /* the current call has logged its outcome */
    unsigned state;
    int stop_defined;
    double stop_time;
    int event_mode_used, early_return_allowed; /* FMI 3.0's options */
    fmu_callback intermediate;                 /* FMI 3.0's intermediateUpdate, or NULL */
    fmu_ask_fn *ask;                           /* calls it */
    fmu_model m;
};

/* A saved FMU state: the bytes of fmu_model_state_save. */
typedef struct {
    size_t size;
    unsigned char bytes[];
} saved_state;

static void send(fmu_sink *sink, fmu_callback logger, void *environment, const char *name,
                 fmu_status status, int category, const char *fn, const char *msg)
{
    if (!sink || !logger)
        return;
    char text[2 * FMU_ERRLEN + 64];
    if (msg)
        snprintf(text, sizeof text, "%s: %s", fn, msg);
    else /* a call that succeeded: its name, the outcome in the status */
        snprintf(text, sizeof text, "%s", fn);
    for (char *c = text; *c; c++) /* FMI 2.0: the message is a format for the importer */
        if (*c == '%')
            *c = '?';
    sink(logger, environment, name, status, CATEGORY[category], text);
}

static void emit(fmu_instance *in, fmu_status status, int category, const char *fn,
                 const char *msg)
{
    in->logged = 1;
    send(in->sink, in->logger, in->environment, in->name, status, category, fn, msg);
}

static void emitv(fmu_instance *in, fmu_status status, int category, const char *fn,
                  const char *fmt, va_list ap)
{
    char msg[2 * FMU_ERRLEN];
    vsnprintf(msg, sizeof msg, fmt, ap);
    emit(in, status, category, fn, msg);
}

void fmu_log_error(const char *fn, const char *name, fmu_sink *sink, fmu_callback logger,
                   void *environment, const char *fmt, ...)
{
    char msg[2 * FMU_ERRLEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    send(sink, logger, environment, name, FMU_ERROR, CAT_ERROR, fn, msg);
}

fmu_status fmu_error(fmu_instance *in, const char *fn, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    emitv(in, FMU_ERROR, CAT_ERROR, fn, fmt, ap);
    va_end(ap);
    return FMU_ERROR;
}

static int debug_on(const fmu_instance *in, int category)
{
    return in->logging_on && (in->categories & (1u << category));
}

fmu_status fmu_leave(fmu_instance *in, const char *fn, fmu_status st)
{
    if (in && !in->logged && debug_on(in, CAT_CALLS))
        emit(in, st, CAT_CALLS, fn, NULL);
    return st;
}

static const char *state_name(unsigned state)
{
    switch (state) {
    case FMU_INSTANTIATED: return "instantiated";
    case FMU_INIT_MODE: return "initialization mode";
    case FMU_STEP_MODE: return "step mode";
    case FMU_TERMINATED: return "terminated";
    case FMU_EVENT_MODE: return "event mode";
    default: return "error";
    }
}

fmu_instance *fmu_enter(void *c, fmu_fn which, const char *fn)
{
    fmu_instance *in = c;
    if (!in)
        return NULL;
    in->logged = 0;
    if (!(in->state & ALLOWED[which])) {
        fmu_error(in, fn, "not allowed in state %s", state_name(in->state));
        return NULL;
    }
    return in;
}

double fmu_time(const fmu_instance *in)
{
    return in->m.t_comm;
}

fmu_instance *fmu_instantiate(const char *fn, const char *name, fmu_sink *sink,
                              fmu_callback logger, void *environment, int logging_on)
{
    const char *shown = name ? name : "?";
    if (!name || !*name) {
        fmu_log_error(fn, shown, sink, logger, environment, "the instance name is empty");
        return NULL;
    }
    fmu_instance *in = calloc(1, sizeof *in);
    size_t len = strlen(name) + 1;
    char *copy = malloc(len);
    fmu_model m = {0};
    if (!in || !copy || fmu_model_new(&m) != 0) {
        free(in);
        free(copy);
        fmu_model_free(&m);
        fmu_log_error(fn, shown, sink, logger, environment, "out of memory");
        return NULL;
    }
    memcpy(copy, name, len);
    *in = (fmu_instance){.name = copy, .sink = sink, .logger = logger,
                         .environment = environment, .logging_instantiate = logging_on != 0,
                         .logging_on = logging_on != 0, .categories = CAT_ALL,
                         .state = FMU_INSTANTIATED, .m = m};
    fmu_leave(in, fn, FMU_OK);
    return in;
}

void fmu_free_instance(fmu_instance *in, const char *fn)
{
    fmu_leave(in, fn, FMU_OK);
    fmu_model_free(&in->m);
    free(in->name);
    free(in);
}

fmu_status fmu_set_debug_logging(fmu_instance *in, const char *fn, int on, size_t n,
                                 const char *const categories[])
{
    unsigned set = n == 0 ? CAT_ALL : 0;
    if (n > 0 && !categories)
        return fmu_error(in, fn, "NULL categories");
    for (size_t i = 0; i < n; i++) {
        unsigned bit = 0;
        for (unsigned k = 0; k < NCAT; k++)
            if (categories[i] && strcmp(categories[i], CATEGORY[k]) == 0)
                bit = 1u << k;
        if (!bit)
            return fmu_error(in, fn, "unknown log category \"%s\"",
                             categories[i] ? categories[i] : "(null)");
        set |= bit;
    }
    in->logging_on = on != 0;
    in->categories = set;
    return fmu_leave(in, fn, FMU_OK);
}

/* The start and stop time, not logged. */
static fmu_status setup(fmu_instance *in, const char *fn, double start_time,
                        int stop_time_defined, double stop_time)
{
    if (!isfinite(start_time))
        return fmu_error(in, fn, "the start time %g is not finite", start_time);
    if (stop_time_defined && !(stop_time >= start_time))
        return fmu_error(in, fn, "stop time %.17g before start time %.17g", stop_time,
                         start_time);
    fmu_model_set_start(&in->m, start_time);
    in->stop_defined = stop_time_defined != 0;
    in->stop_time = stop_time;
    return FMU_OK;
}

fmu_status fmu_setup_experiment(fmu_instance *in, const char *fn, double start_time,
                                int stop_time_defined, double stop_time)
{
    return fmu_leave(in, fn, setup(in, fn, start_time, stop_time_defined, stop_time));
}

fmu_status fmu_enter_init(fmu_instance *in, const char *fn, const double *start_time,
                          int stop_time_defined, double stop_time)
{
    if (start_time && setup(in, fn, *start_time, stop_time_defined, stop_time) != FMU_OK)
        return FMU_ERROR;
    in->state = FMU_INIT_MODE;
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_exit_init(fmu_instance *in, const char *fn)
{
    char err[FMU_ERRLEN], note[FMU_ERRLEN], msg[FMU_ERRLEN];
    const double T = in->stop_defined ? in->stop_time - in->m.v->t_start
                                      : DMI_FMU_MODEL.stop_time;
    const int check = fmu_model_check_start(&in->m, T, msg);
    if (check < 0)
        return fmu_error(in, fn, "%s", msg);
    if (fmu_model_start(&in->m, in->m.v->t_start, err, note) != 0)
        return fmu_error(in, fn, "%s", err);
    /* FMI 3.0: with eventModeUsed the FMU is in event mode after initialization */
    in->state = in->event_mode_used ? FMU_EVENT_MODE : FMU_STEP_MODE;
    if (note[0])
        send(in->sink, in->logger, in->environment, in->name, FMU_OK, CAT_MEMORY, fn, note);
    if (check > 0) {
        emit(in, FMU_WARNING, CAT_WARNING, fn, msg);
        return FMU_WARNING;
    }
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_terminate(fmu_instance *in, const char *fn)
{
    in->state = FMU_TERMINATED;
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_reset(fmu_instance *in, const char *fn)
{
    fmu_model_defaults(&in->m);
    in->logging_on = in->logging_instantiate; /* as if just instantiated */
    in->categories = CAT_ALL;
    in->state = FMU_INSTANTIATED;
    in->stop_defined = 0;
    return fmu_leave(in, fn, FMU_OK);
}

/* ---- getting and setting variables ---- */

static int bad_arrays(fmu_instance *in, const char *fn, const void *vr, size_t nvr,
                      const void *value)
{
    if (nvr > 0 && (!vr || !value)) {
        fmu_error(in, fn, "NULL array");
        return 1;
    }
    return 0;
}

fmu_status fmu_get(fmu_instance *in, const char *fn, const unsigned vr[], size_t nvr,
                   void *values, unsigned type, fmu_put_fn *put)
{
    char err[FMU_ERRLEN];
    if (bad_arrays(in, fn, vr, nvr, values))
        return FMU_ERROR;
    if (type & FMU_FLOAT64) { /* the values are doubles already */
        if (fmu_model_get_reals(&in->m, vr, nvr, type, values, err) != 0)
            return fmu_error(in, fn, "%s", err);
        return fmu_leave(in, fn, FMU_OK);
    }
    for (size_t i = 0; i < nvr; i++) {
        double x;
        if (fmu_model_get(&in->m, vr[i], type, &x, err) != 0)
            return fmu_error(in, fn, "%s", err);
        put(values, i, x);
    }
    return fmu_leave(in, fn, FMU_OK);
}

/* Whether the variable vr may be set in the instance's state. */
static int settable(const fmu_instance *in, unsigned vr)
{
    if (fmu_model_kind(&in->m, vr) & FMU_PARAMETER)
        return (in->state & (FMU_INSTANTIATED | FMU_INIT_MODE)) != 0;
    return 1;
}

fmu_status fmu_set(fmu_instance *in, const char *fn, const unsigned vr[], size_t nvr,
                   const void *values, unsigned type, fmu_take_fn *take)
{
    char err[FMU_ERRLEN];
    if (bad_arrays(in, fn, vr, nvr, values))
        return FMU_ERROR;
    for (size_t i = 0; i < nvr; i++) { /* every value checked before any is stored */
        if (!settable(in, vr[i]))
            return fmu_error(in, fn, "the parameter with value reference %u cannot be changed "
                                     "after initialization", vr[i]);
        if (fmu_model_check(&in->m, vr[i], type, take(values, i), err) != 0)
            return fmu_error(in, fn, "%s", err);
    }
    for (size_t i = 0; i < nvr; i++)
        fmu_model_store(&in->m, vr[i], take(values, i));
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_no_variables(fmu_instance *in, const char *fn, size_t nvr, const char *type)
{
    return nvr == 0 ? fmu_leave(in, fn, FMU_OK)
                    : fmu_error(in, fn, "the FMU has no %s", type);
}

/* ---- FMU states ---- */

fmu_status fmu_get_state(fmu_instance *in, const char *fn, void **state)
{
    if (!state)
        return fmu_error(in, fn, "NULL pointer");
    const size_t size = fmu_model_state_size(&in->m);
    saved_state *s = *state;
    if (!s || s->size != size) {
        saved_state *fresh = malloc(sizeof *s + size);
        if (!fresh)
            return fmu_error(in, fn, "out of memory (%zu bytes)", size);
        free(s);
        s = fresh;
    }
    s->size = size;
    fmu_model_state_save(&in->m, in->state, s->bytes);
    *state = s;
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_set_state(fmu_instance *in, const char *fn, const void *state)
{
    const saved_state *s = state;
    uint32_t tag = 0;
    char err[FMU_ERRLEN];
    if (!s)
        return fmu_error(in, fn, "NULL state");
    if (fmu_model_state_load(&in->m, SAVABLE, HAS_SOLVER, &tag, s->bytes, s->size, err) != 0)
        return fmu_error(in, fn, "%s", err);
    /* a state saved in event mode, restored into an instance without it (FMI
     * 2.0, or eventModeUsed = false): step mode, the event handled */
    in->state = tag == FMU_EVENT_MODE && !in->event_mode_used ? FMU_STEP_MODE : tag;
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_free_state(fmu_instance *in, const char *fn, void **state)
{
    if (state && *state) {
        free(*state);
        *state = NULL;
    }
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_state_size(fmu_instance *in, const char *fn, const void *state, size_t *size)
{
    const saved_state *s = state;
    if (!s || !size)
        return fmu_error(in, fn, "NULL argument");
    *size = s->size;
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_serialize(fmu_instance *in, const char *fn, const void *state,
                         unsigned char *bytes, size_t size)
{
    const saved_state *s = state;
    if (!s || !bytes)
        return fmu_error(in, fn, "NULL argument");
    if (size < s->size)
        return fmu_error(in, fn, "buffer of %zu bytes, %zu needed", size, s->size);
    memcpy(bytes, s->bytes, s->size);
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_deserialize(fmu_instance *in, const char *fn, const unsigned char *bytes,
                           size_t size, void **state)
{
    uint32_t tag = 0;
    char err[FMU_ERRLEN];
    if (!bytes || !state)
        return fmu_error(in, fn, "NULL argument");
    if (fmu_model_state_load(NULL, SAVABLE, HAS_SOLVER, &tag, bytes, size, err) != 0)
        return fmu_error(in, fn, "%s", err);
    saved_state *s = malloc(sizeof *s + size);
    if (!s)
        return fmu_error(in, fn, "out of memory (%zu bytes)", size);
    s->size = size;
    memcpy(s->bytes, bytes, size);
    *state = s;
    return fmu_leave(in, fn, FMU_OK);
}

/* ---- stepping ---- */

void fmu_set_cosimulation(fmu_instance *in, int event_mode_used, int early_return_allowed,
                          fmu_callback intermediate, fmu_ask_fn *ask)
{
    in->event_mode_used = event_mode_used != 0;
    in->early_return_allowed = early_return_allowed != 0;
    in->intermediate = intermediate;
    in->ask = ask;
}

/* fmu_stop_fn of a doStep: at an event before the end, the importer's
 * intermediateUpdate (if any) is told; the step ends there if early return
 * is allowed and the importer did not decline it. */
static int stop_at_event(void *ctx, double t)
{
    fmu_instance *in = ctx;
    int stop = in->early_return_allowed;
    if (in->intermediate && in->ask)
        stop = in->ask(in->intermediate, in->environment, t, stop) && stop;
    return stop;
}

fmu_status fmu_do_step(fmu_instance *in, const char *fn, double t, double h, int *early,
                       int *event_handling)
{
    char err[FMU_ERRLEN];
    int stopped = 0;
    /* without early return nor callback, never asked: FMI 2.0 runs as before */
    const int asks = early && (in->early_return_allowed || in->intermediate);
    int rc = fmu_model_do_step(&in->m, t, h, asks ? stop_at_event : NULL, in, &stopped, err);
    if (rc == -2)
        in->state = FMU_ERROR_STATE;
    if (early)
        *early = rc == 0 && stopped;
    if (event_handling)
        *event_handling = rc == 0 && in->event_mode_used && in->m.event;
    return rc == 0 ? fmu_leave(in, fn, FMU_OK) : fmu_error(in, fn, "%s", err);
}

fmu_status fmu_enter_event_mode(fmu_instance *in, const char *fn)
{
    if (!in->event_mode_used)
        return fmu_error(in, fn, "the instance was created with eventModeUsed = false");
    in->state = FMU_EVENT_MODE;
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_enter_step_mode(fmu_instance *in, const char *fn)
{
    in->state = FMU_STEP_MODE;
    in->m.event = 0;
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_update_discrete_states(fmu_instance *in, const char *fn)
{
    in->m.event = 0;
    return fmu_leave(in, fn, FMU_OK);
}

fmu_status fmu_unsupported(void *c, const char *fn, const char *why)
{
    fmu_instance *in = fmu_enter(c, FN_UNSUPPORTED, fn);
    return in ? fmu_error(in, fn, "%s", why) : FMU_ERROR;
}

fmu_status fmu_discard(fmu_instance *in, const char *fn, const void *value, const char *why)
{
    if (!value)
        return fmu_error(in, fn, "value is NULL");
    if (debug_on(in, CAT_CALLS))
        emit(in, FMU_DISCARD, CAT_CALLS, fn, why);
    return FMU_DISCARD;
}
