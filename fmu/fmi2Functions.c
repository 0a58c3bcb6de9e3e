/*
 * The FMI 2.0 co-simulation interface of the model in model.h: instance
 * life cycle, the calling sequence (a bitmask of the states in which each
 * function is allowed), logging through the importer's callback, FMU states.
 * Nothing here knows about the oscillator.
 *
 * Errors: every fmi2Error is logged with its reason (category
 * logStatusError, sent whatever loggingOn says); category logCalls traces
 * the calls when debug logging is on.  A rejected call (bad argument, value,
 * state bytes, or a call not allowed in the current state) leaves the
 * instance as it was; only a failure of the solver inside fmi2DoStep puts
 * the instance into the error state (then fmi2SetFMUstate or fmi2Reset).
 *
 * Memory: libdmi allocates the solver with the C library, so all the FMU's
 * memory comes from there (calloc, malloc, free) and the model description
 * says canNotUseMemoryManagementFunctions="true": the importer's
 * allocateMemory and freeMemory are not called and may be NULL (FMI 2.0:
 * with the default "false", an FMU must not call malloc itself).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "model.h"

/* The instance's states (FMI 2.0 co-simulation state machine). */
enum {
    INSTANTIATED = 1 << 0,
    INIT_MODE = 1 << 1,
    STEP_COMPLETE = 1 << 2,
    TERMINATED = 1 << 3,
    ERROR_STATE = 1 << 4
};
#define ANY_STATE (INSTANTIATED | INIT_MODE | STEP_COMPLETE | TERMINATED | ERROR_STATE)
#define SAVABLE (INSTANTIATED | INIT_MODE | STEP_COMPLETE | TERMINATED)
#define READABLE (INIT_MODE | STEP_COMPLETE | TERMINATED | ERROR_STATE)
/* The states with a solver (after fmi2ExitInitializationMode): their saved
 * states hold the history. */
#define HAS_SOLVER (STEP_COMPLETE | TERMINATED)

/* Log categories, as declared in modelDescription.xml. */
static const char *const CATEGORY[] = {"logStatusError", "logCalls"};
enum { CAT_ERROR = 1 << 0, CAT_CALLS = 1 << 1, CAT_ALL = CAT_ERROR | CAT_CALLS };

typedef struct {
    char *name;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment environment;
    int logging_instantiate; /* loggingOn of fmi2Instantiate, restored by fmi2Reset */
    int logging_on;
    unsigned categories; /* CAT_* enabled for debug logging */
    unsigned state;
    model m;
} instance;

/* A saved FMU state: the bytes of model_state_save. */
typedef struct {
    size_t size;
    unsigned char bytes[];
} saved_state;

static void emit(const instance *in, fmi2Status status, int category, const char *msg)
{
    if (!in->logger)
        return;
    char text[2 * MODEL_ERRLEN];
    snprintf(text, sizeof text, "%s", msg);
    for (char *c = text; *c; c++) /* the message is a format for the importer */
        if (*c == '%')
            *c = '?';
    in->logger(in->environment, in->name, status, CATEGORY[category == CAT_ERROR ? 0 : 1], text);
}

static fmi2Status error(instance *in, const char *fmt, ...)
{
    char msg[2 * MODEL_ERRLEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    emit(in, fmi2Error, CAT_ERROR, msg);
    return fmi2Error;
}

static const char *state_name(unsigned state)
{
    switch (state) {
    case INSTANTIATED: return "instantiated";
    case INIT_MODE: return "initialization mode";
    case STEP_COMPLETE: return "step complete";
    case TERMINATED: return "terminated";
    default: return "error";
    }
}

/* The instance if fn is allowed in its state; logs and gives NULL if not. */
static instance *enter(fmi2Component c, const char *fn, unsigned allowed)
{
    instance *in = c;
    if (!in)
        return NULL;
    if (!(in->state & allowed)) {
        error(in, "%s: not allowed in state %s", fn, state_name(in->state));
        return NULL;
    }
    if (in->logging_on && (in->categories & CAT_CALLS))
        emit(in, fmi2OK, CAT_CALLS, fn);
    return in;
}

static int bad_arrays(instance *in, const char *fn, const void *vr, size_t nvr, const void *value)
{
    if (nvr > 0 && (!vr || !value)) {
        error(in, "%s: NULL array", fn);
        return 1;
    }
    return 0;
}

/* A function this FMU does not provide: always fmi2Error, with the reason. */
static fmi2Status unsupported(fmi2Component c, const char *fn, unsigned allowed, const char *why)
{
    instance *in = enter(c, fn, allowed);
    return in ? error(in, "%s: %s", fn, why) : fmi2Error;
}

/* ---- common functions ---- */

const char *fmi2GetTypesPlatform(void)
{
    return fmi2TypesPlatform;
}

const char *fmi2GetVersion(void)
{
    return fmi2Version;
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    instance *in = enter(c, "fmi2SetDebugLogging", ANY_STATE);
    if (!in)
        return fmi2Error;
    unsigned set = nCategories == 0 ? CAT_ALL : 0;
    if (nCategories > 0 && !categories)
        return error(in, "fmi2SetDebugLogging: NULL categories");
    for (size_t i = 0; i < nCategories; i++) {
        unsigned bit = 0;
        for (unsigned k = 0; k < sizeof CATEGORY / sizeof *CATEGORY; k++)
            if (categories[i] && strcmp(categories[i], CATEGORY[k]) == 0)
                bit = 1u << k;
        if (!bit)
            return error(in, "fmi2SetDebugLogging: unknown log category \"%s\"",
                         categories[i] ? categories[i] : "(null)");
        set |= bit;
    }
    in->logging_on = loggingOn != fmi2False;
    in->categories = set;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn)
{
    (void)fmuResourceLocation;
    (void)visible;
    if (!functions)
        return NULL; /* no way to log why */
    instance probe = {.name = (char *)(instanceName ? instanceName : "?"),
                      .logger = functions->logger, .environment = functions->componentEnvironment};
    if (!instanceName || !*instanceName) {
        error(&probe, "fmi2Instantiate: the instance name is empty");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        error(&probe, "fmi2Instantiate: this FMU supports co-simulation only");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, DMI_FMU_GUID) != 0) {
        error(&probe, "fmi2Instantiate: GUID \"%s\" does not match the FMU's %s",
              fmuGUID ? fmuGUID : "(null)", DMI_FMU_GUID);
        return NULL;
    }
    instance *in = calloc(1, sizeof *in);
    size_t len = strlen(instanceName) + 1;
    char *name = malloc(len);
    if (!in || !name) {
        free(in);
        free(name);
        error(&probe, "fmi2Instantiate: out of memory");
        return NULL;
    }
    memcpy(name, instanceName, len);
    *in = (instance){.name = name, .logger = functions->logger,
                     .environment = functions->componentEnvironment,
                     .logging_instantiate = loggingOn != fmi2False,
                     .logging_on = loggingOn != fmi2False, .categories = CAT_ALL,
                     .state = INSTANTIATED};
    model_defaults(&in->m);
    return in;
}

void fmi2FreeInstance(fmi2Component c)
{
    instance *in = enter(c, "fmi2FreeInstance", ANY_STATE);
    if (!in)
        return;
    model_free(&in->m);
    free(in->name);
    free(in);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    instance *in = enter(c, "fmi2SetupExperiment", INSTANTIATED);
    (void)toleranceDefined;
    (void)tolerance;
    if (!in)
        return fmi2Error;
    if (!isfinite(startTime))
        return error(in, "fmi2SetupExperiment: the start time %g is not finite", startTime);
    if (stopTimeDefined && !(stopTime >= startTime))
        return error(in, "fmi2SetupExperiment: stop time %.17g before start time %.17g", stopTime,
                     startTime);
    in->m.t_start = startTime;
    in->m.t_comm = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    instance *in = enter(c, "fmi2EnterInitializationMode", INSTANTIATED);
    if (!in)
        return fmi2Error;
    in->state = INIT_MODE;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    instance *in = enter(c, "fmi2ExitInitializationMode", INIT_MODE);
    char err[MODEL_ERRLEN];
    if (!in)
        return fmi2Error;
    if (model_start(&in->m, in->m.t_start, err) != 0)
        return error(in, "fmi2ExitInitializationMode: %s", err);
    in->state = STEP_COMPLETE;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    instance *in = enter(c, "fmi2Terminate", STEP_COMPLETE);
    if (!in)
        return fmi2Error;
    in->state = TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c)
{
    instance *in = enter(c, "fmi2Reset", ANY_STATE);
    if (!in)
        return fmi2Error;
    model_free(&in->m);
    model_defaults(&in->m);
    in->logging_on = in->logging_instantiate; /* as if just instantiated (FMI 2.0) */
    in->categories = CAT_ALL;
    in->state = INSTANTIATED;
    return fmi2OK;
}

/* ---- getting and setting variables ---- */

/* Element i of a value array through the model's getter or setter. */
typedef int get_fn(const model *m, unsigned vr, void *values, size_t i, char *err);
typedef int set_fn(model *m, unsigned vr, const void *values, size_t i, char *err);

static int get_real(const model *m, unsigned vr, void *values, size_t i, char *err)
{
    return model_get_real(m, vr, (fmi2Real *)values + i, err);
}

static int get_integer(const model *m, unsigned vr, void *values, size_t i, char *err)
{
    return model_get_integer(m, vr, (fmi2Integer *)values + i, err);
}

static int get_boolean(const model *m, unsigned vr, void *values, size_t i, char *err)
{
    int b = 0;
    if (model_get_boolean(m, vr, &b, err) != 0)
        return -1;
    ((fmi2Boolean *)values)[i] = b ? fmi2True : fmi2False;
    return 0;
}

static int set_real(model *m, unsigned vr, const void *values, size_t i, char *err)
{
    return model_set_real(m, vr, ((const fmi2Real *)values)[i], err);
}

static int set_integer(model *m, unsigned vr, const void *values, size_t i, char *err)
{
    return model_set_integer(m, vr, ((const fmi2Integer *)values)[i], err);
}

static fmi2Status get_values(fmi2Component c, const char *fn, const fmi2ValueReference vr[],
                             size_t nvr, void *value, get_fn *get)
{
    instance *in = enter(c, fn, READABLE);
    char err[MODEL_ERRLEN];
    if (!in || bad_arrays(in, fn, vr, nvr, value))
        return fmi2Error;
    for (size_t i = 0; i < nvr; i++)
        if (get(&in->m, vr[i], value, i, err) != 0)
            return error(in, "%s: %s", fn, err);
    return fmi2OK;
}

/* Whether the variable vr may be set in the instance's state. */
static int settable(const instance *in, unsigned vr)
{
    return model_is_parameter(vr) ? (in->state & (INSTANTIATED | INIT_MODE)) != 0 : 1;
}

/* All values or none. */
static fmi2Status set_values(fmi2Component c, const char *fn, const fmi2ValueReference vr[],
                             size_t nvr, const void *value, set_fn *set)
{
    instance *in = enter(c, fn, INSTANTIATED | INIT_MODE | STEP_COMPLETE);
    char err[MODEL_ERRLEN];
    if (!in || bad_arrays(in, fn, vr, nvr, value))
        return fmi2Error;
    model next = in->m;
    for (size_t i = 0; i < nvr; i++) {
        if (!settable(in, vr[i]))
            return error(in, "%s: the parameter with value reference %u cannot be changed after "
                             "initialization", fn, vr[i]);
        if (set(&next, vr[i], value, i, err) != 0)
            return error(in, "%s: %s", fn, err);
    }
    in->m = next;
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[])
{
    return get_values(c, "fmi2GetReal", vr, nvr, value, get_real);
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[])
{
    return get_values(c, "fmi2GetInteger", vr, nvr, value, get_integer);
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[])
{
    return get_values(c, "fmi2GetBoolean", vr, nvr, value, get_boolean);
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[])
{
    instance *in = enter(c, "fmi2GetString", READABLE);
    if (!in)
        return fmi2Error;
    (void)vr;
    (void)value;
    return nvr == 0 ? fmi2OK : error(in, "fmi2GetString: the FMU has no String variables");
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[])
{
    return set_values(c, "fmi2SetReal", vr, nvr, value, set_real);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[])
{
    return set_values(c, "fmi2SetInteger", vr, nvr, value, set_integer);
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[])
{
    instance *in = enter(c, "fmi2SetBoolean", INSTANTIATED | INIT_MODE | STEP_COMPLETE);
    if (!in)
        return fmi2Error;
    (void)vr;
    (void)value;
    return nvr == 0 ? fmi2OK
                    : error(in, "fmi2SetBoolean: the FMU has no settable Boolean variable");
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[])
{
    instance *in = enter(c, "fmi2SetString", INSTANTIATED | INIT_MODE | STEP_COMPLETE);
    if (!in)
        return fmi2Error;
    (void)vr;
    (void)value;
    return nvr == 0 ? fmi2OK : error(in, "fmi2SetString: the FMU has no String variables");
}

/* ---- FMU states ---- */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    instance *in = enter(c, "fmi2GetFMUstate", SAVABLE);
    if (!in)
        return fmi2Error;
    if (!FMUstate)
        return error(in, "fmi2GetFMUstate: NULL pointer");
    const size_t size = model_state_size(&in->m);
    saved_state *s = *FMUstate;
    if (!s || s->size != size) {
        saved_state *fresh = malloc(sizeof *s + size);
        if (!fresh)
            return error(in, "fmi2GetFMUstate: out of memory (%zu bytes)", size);
        free(s);
        s = fresh;
    }
    s->size = size;
    model_state_save(&in->m, in->state, s->bytes);
    *FMUstate = s;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    instance *in = enter(c, "fmi2SetFMUstate", ANY_STATE);
    const saved_state *s = FMUstate;
    uint32_t tag = 0;
    char err[MODEL_ERRLEN];
    if (!in)
        return fmi2Error;
    if (!s)
        return error(in, "fmi2SetFMUstate: NULL state");
    if (model_state_load(&in->m, SAVABLE, HAS_SOLVER, &tag, s->bytes, s->size, err) != 0)
        return error(in, "fmi2SetFMUstate: %s", err);
    in->state = tag;
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    instance *in = enter(c, "fmi2FreeFMUstate", ANY_STATE);
    if (!in)
        return fmi2Error;
    if (FMUstate && *FMUstate) {
        free(*FMUstate);
        *FMUstate = NULL;
    }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    instance *in = enter(c, "fmi2SerializedFMUstateSize", ANY_STATE);
    const saved_state *s = FMUstate;
    if (!in)
        return fmi2Error;
    if (!s || !size)
        return error(in, "fmi2SerializedFMUstateSize: NULL argument");
    *size = s->size;
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate,
                                 fmi2Byte serializedState[], size_t size)
{
    instance *in = enter(c, "fmi2SerializeFMUstate", ANY_STATE);
    const saved_state *s = FMUstate;
    if (!in)
        return fmi2Error;
    if (!s || !serializedState)
        return error(in, "fmi2SerializeFMUstate: NULL argument");
    if (size < s->size)
        return error(in, "fmi2SerializeFMUstate: buffer of %zu bytes, %zu needed", size, s->size);
    memcpy(serializedState, s->bytes, s->size);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[],
                                   size_t size, fmi2FMUstate *FMUstate)
{
    instance *in = enter(c, "fmi2DeSerializeFMUstate", ANY_STATE);
    uint32_t tag = 0;
    char err[MODEL_ERRLEN];
    if (!in)
        return fmi2Error;
    if (!serializedState || !FMUstate)
        return error(in, "fmi2DeSerializeFMUstate: NULL argument");
    if (model_state_load(NULL, SAVABLE, HAS_SOLVER, &tag, (const unsigned char *)serializedState,
                         size, err) != 0)
        return error(in, "fmi2DeSerializeFMUstate: %s", err);
    saved_state *s = malloc(sizeof *s + size);
    if (!s)
        return error(in, "fmi2DeSerializeFMUstate: out of memory (%zu bytes)", size);
    s->size = size;
    memcpy(s->bytes, serializedState, size);
    *FMUstate = s;
    return fmi2OK;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[])
{
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown,
        (void)dvUnknown;
    return unsupported(c, "fmi2GetDirectionalDerivative", ANY_STATE, "not provided by this FMU");
}

/* ---- co-simulation ---- */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives", ANY_STATE,
                       "the FMU does not interpolate inputs");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[], fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives", ANY_STATE,
                       "the FMU provides no output derivatives");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    instance *in = enter(c, "fmi2DoStep", STEP_COMPLETE);
    char err[MODEL_ERRLEN];
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!in)
        return fmi2Error;
    int rc = model_do_step(&in->m, currentCommunicationPoint, communicationStepSize, err);
    if (rc == -2)
        in->state = ERROR_STATE;
    return rc == 0 ? fmi2OK : error(in, "fmi2DoStep: %s", err);
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    return unsupported(c, "fmi2CancelStep", ANY_STATE, "steps are never asynchronous");
}

/* A status query the FMU cannot answer (this kind of status is not
 * available): fmi2Discard (FMI 2.0, 4.2.3), the reason logged only when debug
 * logging of calls is on. */
static fmi2Status no_status(fmi2Component c, const char *fn, const void *value, const char *why)
{
    instance *in = enter(c, fn, READABLE);
    if (!in)
        return fmi2Error;
    if (!value)
        return error(in, "%s: value is NULL", fn);
    if (in->logging_on && (in->categories & CAT_CALLS)) {
        char msg[2 * MODEL_ERRLEN];
        snprintf(msg, sizeof msg, "%s: %s", fn, why);
        emit(in, fmi2Discard, CAT_CALLS, msg);
    }
    return fmi2Discard;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s;
    return no_status(c, "fmi2GetStatus", value, "steps are never asynchronous");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    if (s != fmi2LastSuccessfulTime)
        return no_status(c, "fmi2GetRealStatus", value, "only fmi2LastSuccessfulTime is available");
    instance *in = enter(c, "fmi2GetRealStatus", READABLE);
    if (!in)
        return fmi2Error;
    if (!value)
        return error(in, "fmi2GetRealStatus: value is NULL");
    *value = in->m.t_comm;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s;
    return no_status(c, "fmi2GetIntegerStatus", value, "no Integer status is defined");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    if (s != fmi2Terminated)
        return no_status(c, "fmi2GetBooleanStatus", value, "only fmi2Terminated is available");
    instance *in = enter(c, "fmi2GetBooleanStatus", READABLE);
    if (!in)
        return fmi2Error;
    if (!value)
        return error(in, "fmi2GetBooleanStatus: value is NULL");
    *value = fmi2False; /* the FMU never asks to stop */
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)s;
    return no_status(c, "fmi2GetStringStatus", value, "no String status is defined");
}
