/*
 * The FMI 3.0 FMU behind FMI 2.0 function types: see fmu_fmi3.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "fmu_fmi3.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3FunctionTypes.h"

/* The FMI 3.0 functions of the one loaded FMI 3.0 library. */
static struct {
    fmi3InstantiateCoSimulationTYPE *instantiate;
    fmi3InstantiateModelExchangeTYPE *instantiate_me;
    fmi3FreeInstanceTYPE *free_instance;
    fmi3SetDebugLoggingTYPE *set_debug_logging;
    fmi3EnterInitializationModeTYPE *enter_init;
    fmi3ExitInitializationModeTYPE *exit_init;
    fmi3TerminateTYPE *terminate;
    fmi3ResetTYPE *reset;
    fmi3GetFloat64TYPE *get_float64;
    fmi3GetInt32TYPE *get_int32;
    fmi3GetBooleanTYPE *get_boolean;
    fmi3GetStringTYPE *get_string;
    fmi3SetFloat64TYPE *set_float64;
    fmi3SetInt32TYPE *set_int32;
    fmi3SetBooleanTYPE *set_boolean;
    fmi3SetStringTYPE *set_string;
    fmi3GetFMUStateTYPE *get_state;
    fmi3SetFMUStateTYPE *set_state;
    fmi3FreeFMUStateTYPE *free_state;
    fmi3SerializedFMUStateSizeTYPE *state_size;
    fmi3SerializeFMUStateTYPE *serialize;
    fmi3DeserializeFMUStateTYPE *deserialize;
    fmi3DoStepTYPE *do_step;
} F3;

/* An FMI 2.0 component: the FMI 3.0 instance, the FMI 2.0 logger, the times
 * of fmi2SetupExperiment. */
typedef struct {
    fmi3Instance instance;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment environment;
    char name[64];
    double start, stop;
    int stop_defined;
} component;

static fmi3Instance inst(fmi2Component c)
{
    return c ? ((component *)c)->instance : NULL;
}

static void log3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                 fmi3String message)
{
    const component *w = env;
    if (w && w->logger)
        w->logger(w->environment, w->name, (fmi2Status)status, category, "%s", message);
}

static fmi2Component instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                 fmi2String resources, const fmi2CallbackFunctions *cb,
                                 fmi2Boolean visible, fmi2Boolean logging_on)
{
    component *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    if (cb) {
        w->logger = cb->logger;
        w->environment = cb->componentEnvironment;
    }
    snprintf(w->name, sizeof w->name, "%s", name ? name : "?");
    w->instance = type == fmi2ModelExchange
                      ? F3.instantiate_me(name, guid, resources, visible != 0, logging_on != 0, w,
                                          log3)
                      : F3.instantiate(name, guid, resources, visible != 0, logging_on != 0,
                                       fmi3False, fmi3False, NULL, 0, w, log3, NULL);
    if (!w->instance) {
        free(w);
        return NULL;
    }
    return w;
}

static void free_instance(fmi2Component c)
{
    F3.free_instance(inst(c));
    free(c);
}

static fmi2Status set_debug_logging(fmi2Component c, fmi2Boolean on, size_t n,
                                    const fmi2String categories[])
{
    return (fmi2Status)F3.set_debug_logging(inst(c), on != 0, n, categories);
}

/* No FMI 3.0 call: the times go to fmi3EnterInitializationMode. */
static fmi2Status setup(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                        fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop)
{
    component *w = c;
    (void)tolerance_defined, (void)tolerance;
    if (!w)
        return fmi2Error;
    w->start = start;
    w->stop_defined = stop_defined != 0;
    w->stop = stop;
    return fmi2OK;
}

static fmi2Status enter_init(fmi2Component c)
{
    const component *w = c;
    return (fmi2Status)F3.enter_init(inst(c), fmi3False, 0.0, w ? w->start : 0.0,
                                     w && w->stop_defined, w ? w->stop : 0.0);
}

static fmi2Status exit_init(fmi2Component c)
{
    return (fmi2Status)F3.exit_init(inst(c));
}

static fmi2Status terminate(fmi2Component c)
{
    return (fmi2Status)F3.terminate(inst(c));
}

static fmi2Status reset(fmi2Component c)
{
    if (c)
        setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
    return (fmi2Status)F3.reset(inst(c));
}

static fmi2Status get_real(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                           fmi2Real v[])
{
    return (fmi2Status)F3.get_float64(inst(c), vr, n, v, n);
}

static fmi2Status get_integer(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                              fmi2Integer v[])
{
    return (fmi2Status)F3.get_int32(inst(c), vr, n, v, n);
}

static fmi2Status set_real(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                           const fmi2Real v[])
{
    return (fmi2Status)F3.set_float64(inst(c), vr, n, v, n);
}

static fmi2Status set_integer(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                              const fmi2Integer v[])
{
    return (fmi2Status)F3.set_int32(inst(c), vr, n, v, n);
}

/* Booleans: int (FMI 2.0) against bool (FMI 3.0); NULL arrays stay NULL. */
static fmi2Status get_boolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                              fmi2Boolean v[])
{
    fmi3Boolean *b = v && n ? calloc(n, sizeof *b) : NULL;
    if (v && n && !b)
        return fmi2Fatal;
    fmi2Status st = (fmi2Status)F3.get_boolean(inst(c), vr, n, b, n);
    for (size_t i = 0; b && st <= fmi2Warning && i < n; i++)
        v[i] = b[i] ? fmi2True : fmi2False;
    free(b);
    return st;
}

static fmi2Status set_boolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                              const fmi2Boolean v[])
{
    fmi3Boolean *b = v && n ? calloc(n, sizeof *b) : NULL;
    if (v && n && !b)
        return fmi2Fatal;
    for (size_t i = 0; b && i < n; i++)
        b[i] = v[i] != fmi2False;
    fmi2Status st = (fmi2Status)F3.set_boolean(inst(c), vr, n, b, n);
    free(b);
    return st;
}

static fmi2Status get_string(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                             fmi2String v[])
{
    return (fmi2Status)F3.get_string(inst(c), vr, n, v, n);
}

static fmi2Status set_string(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                             const fmi2String v[])
{
    return (fmi2Status)F3.set_string(inst(c), vr, n, v, n);
}

static fmi2Status get_state(fmi2Component c, fmi2FMUstate *s)
{
    return (fmi2Status)F3.get_state(inst(c), s);
}

static fmi2Status set_state(fmi2Component c, fmi2FMUstate s)
{
    return (fmi2Status)F3.set_state(inst(c), s);
}

static fmi2Status free_state(fmi2Component c, fmi2FMUstate *s)
{
    return (fmi2Status)F3.free_state(inst(c), s);
}

static fmi2Status state_size(fmi2Component c, fmi2FMUstate s, size_t *size)
{
    return (fmi2Status)F3.state_size(inst(c), s, size);
}

static fmi2Status serialize(fmi2Component c, fmi2FMUstate s, fmi2Byte bytes[], size_t size)
{
    return (fmi2Status)F3.serialize(inst(c), s, (fmi3Byte *)bytes, size);
}

static fmi2Status deserialize(fmi2Component c, const fmi2Byte bytes[], size_t size,
                              fmi2FMUstate *s)
{
    return (fmi2Status)F3.deserialize(inst(c), (const fmi3Byte *)bytes, size, s);
}

/* fmi3DoStep; its flags must say: no event, no termination, no early return. */
static fmi2Status do_step(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_set_prior)
{
    fmi3Boolean event = fmi3True, stop = fmi3True, early = fmi3True;
    fmi3Float64 reached = -1.0;
    fmi2Status st = (fmi2Status)F3.do_step(inst(c), t, h, no_set_prior != 0, &event, &stop,
                                           &early, &reached);
    if (st <= fmi2Warning && (event || stop || early)) {
        fprintf(stderr, "fmi3DoStep: event %d, terminate %d, early return %d\n", event, stop,
                early);
        return fmi2Fatal;
    }
    return st;
}

int fmu_fmi3_attach(fmu_api *f, void *(*lookup)(void *lib, const char *name))
{
    int missing = 0;
    /* object pointer to function pointer: the POSIX dlsym idiom */
#define SYM3(field, name)                                                                         \
    do {                                                                                          \
        *(void **)(&F3.field) = lookup(f->lib, name);                                             \
        missing |= F3.field == NULL;                                                              \
    } while (0)
    SYM3(instantiate, "fmi3InstantiateCoSimulation");
    SYM3(instantiate_me, "fmi3InstantiateModelExchange");
    SYM3(free_instance, "fmi3FreeInstance");
    SYM3(set_debug_logging, "fmi3SetDebugLogging");
    SYM3(enter_init, "fmi3EnterInitializationMode");
    SYM3(exit_init, "fmi3ExitInitializationMode");
    SYM3(terminate, "fmi3Terminate");
    SYM3(reset, "fmi3Reset");
    SYM3(get_float64, "fmi3GetFloat64");
    SYM3(get_int32, "fmi3GetInt32");
    SYM3(get_boolean, "fmi3GetBoolean");
    SYM3(get_string, "fmi3GetString");
    SYM3(set_float64, "fmi3SetFloat64");
    SYM3(set_int32, "fmi3SetInt32");
    SYM3(set_boolean, "fmi3SetBoolean");
    SYM3(set_string, "fmi3SetString");
    SYM3(get_state, "fmi3GetFMUState");
    SYM3(set_state, "fmi3SetFMUState");
    SYM3(free_state, "fmi3FreeFMUState");
    SYM3(state_size, "fmi3SerializedFMUStateSize");
    SYM3(serialize, "fmi3SerializeFMUState");
    SYM3(deserialize, "fmi3DeserializeFMUState");
    SYM3(do_step, "fmi3DoStep");
#undef SYM3
    if (missing)
        return -1;
    f->instantiate = instantiate;
    f->free_instance = free_instance;
    f->set_debug_logging = set_debug_logging;
    f->setup = setup;
    f->enter_init = enter_init;
    f->exit_init = exit_init;
    f->terminate = terminate;
    f->reset = reset;
    f->get_real = get_real;
    f->get_integer = get_integer;
    f->get_boolean = get_boolean;
    f->get_string = get_string;
    f->set_real = set_real;
    f->set_integer = set_integer;
    f->set_boolean = set_boolean;
    f->set_string = set_string;
    f->get_state = get_state;
    f->set_state = set_state;
    f->free_state = free_state;
    f->state_size = state_size;
    f->serialize = serialize;
    f->deserialize = deserialize;
    f->do_step = do_step;
    f->cancel_step = NULL;     /* FMI 3.0 has none */
    f->get_real_status = NULL; /* FMI 3.0: the time is the variable "time" */
    return 0;
}
