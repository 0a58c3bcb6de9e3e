/*
 * The FMI 2.0 co-simulation interface of the model: a thin adapter over the
 * version-neutral instance layer (instance.h), which checks the calling
 * sequence, logs and keeps the FMU states.  Here: FMI 2.0's types, names and
 * the checks of fmi2Instantiate's arguments.
 *
 * The model description says canNotUseMemoryManagementFunctions="true": the
 * importer's allocateMemory and freeMemory are not called and may be NULL
 * (FMI 2.0: with the default "false", an FMU must not call malloc itself).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <string.h>

#include "fmi2Functions.h"
#include "instance.h"

#define ENTER(c, which, fn)                                                                       \
    fmu_instance *in = fmu_enter(c, which, fn);                                                   \
    if (!in)                                                                                      \
    return fmi2Error

static void sink(fmu_callback logger, void *environment, const char *name, fmu_status status,
                 const char *category, const char *message)
{
    ((fmi2CallbackLogger)logger)(environment, name, (fmi2Status)status, category, message);
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
    ENTER(c, FN_SET_DEBUG_LOGGING, "fmi2SetDebugLogging");
    return (fmi2Status)fmu_set_debug_logging(in, "fmi2SetDebugLogging", loggingOn != fmi2False,
                                             nCategories, categories);
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn)
{
    static const char fn[] = "fmi2Instantiate";
    (void)fmuResourceLocation;
    (void)visible;
    if (!functions)
        return NULL; /* no way to log why */
    const fmu_callback logger = (fmu_callback)functions->logger;
    void *env = functions->componentEnvironment;
    if (instanceName && *instanceName) { /* (an empty name: refused by fmu_instantiate) */
        if (fmuType != fmi2CoSimulation) {
            fmu_log_error(fn, instanceName, sink, logger, env,
                          "this FMU supports co-simulation only");
            return NULL;
        }
        if (!fmuGUID || strcmp(fmuGUID, dmi_fmu_guid) != 0) {
            fmu_log_error(fn, instanceName, sink, logger, env,
                          "GUID \"%s\" does not match the FMU's %s",
                          fmuGUID ? fmuGUID : "(null)", dmi_fmu_guid);
            return NULL;
        }
    }
    return fmu_instantiate(fn, instanceName, sink, logger, env, loggingOn != fmi2False);
}

void fmi2FreeInstance(fmi2Component c)
{
    fmu_instance *in = fmu_enter(c, FN_FREE_INSTANCE, "fmi2FreeInstance");
    if (in)
        fmu_free_instance(in, "fmi2FreeInstance");
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    (void)toleranceDefined;
    (void)tolerance;
    ENTER(c, FN_SETUP_EXPERIMENT, "fmi2SetupExperiment");
    return (fmi2Status)fmu_setup_experiment(in, "fmi2SetupExperiment", startTime,
                                            stopTimeDefined != fmi2False, stopTime);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    ENTER(c, FN_ENTER_INIT, "fmi2EnterInitializationMode");
    return (fmi2Status)fmu_enter_init(in, "fmi2EnterInitializationMode", NULL, 0, 0.0);
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    ENTER(c, FN_EXIT_INIT, "fmi2ExitInitializationMode");
    return (fmi2Status)fmu_exit_init(in, "fmi2ExitInitializationMode");
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    ENTER(c, FN_TERMINATE, "fmi2Terminate");
    return (fmi2Status)fmu_terminate(in, "fmi2Terminate");
}

fmi2Status fmi2Reset(fmi2Component c)
{
    ENTER(c, FN_RESET, "fmi2Reset");
    return (fmi2Status)fmu_reset(in, "fmi2Reset");
}

/* ---- getting and setting variables ---- */

static void put_integer(void *values, size_t i, double x)
{
    ((fmi2Integer *)values)[i] = (fmi2Integer)x;
}

static void put_boolean(void *values, size_t i, double x)
{
    ((fmi2Boolean *)values)[i] = x != 0 ? fmi2True : fmi2False;
}

static double take_real(const void *values, size_t i)
{
    return ((const fmi2Real *)values)[i];
}

static double take_integer(const void *values, size_t i)
{
    return ((const fmi2Integer *)values)[i];
}

static double take_boolean(const void *values, size_t i)
{
    return ((const fmi2Boolean *)values)[i] != fmi2False;
}

/* FMI 2.0 has no independent variable: FMI 3.0's time is not a Real here. */
#define GET(Type, type, kind, put)                                                                \
    fmi2Status fmi2Get##Type(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,          \
                             type value[])                                                        \
    {                                                                                             \
        ENTER(c, FN_GET, "fmi2Get" #Type);                                                        \
        return (fmi2Status)fmu_get(in, "fmi2Get" #Type, vr, nvr, value,                           \
                                   (kind) | FMU_NO_INDEPENDENT, put);                             \
    }
#define SET(Type, type, kind, take)                                                               \
    fmi2Status fmi2Set##Type(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,          \
                             const type value[])                                                  \
    {                                                                                             \
        ENTER(c, FN_SET, "fmi2Set" #Type);                                                        \
        return (fmi2Status)fmu_set(in, "fmi2Set" #Type, vr, nvr, value, kind, take);              \
    }
GET(Real, fmi2Real, FMU_FLOAT64, NULL) /* the values are doubles */
GET(Integer, fmi2Integer, FMU_INT32, put_integer)
GET(Boolean, fmi2Boolean, FMU_BOOLEAN, put_boolean)
SET(Real, fmi2Real, FMU_FLOAT64, take_real)
SET(Integer, fmi2Integer, FMU_INT32, take_integer)
SET(Boolean, fmi2Boolean, FMU_BOOLEAN, take_boolean)

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[])
{
    (void)vr, (void)value;
    ENTER(c, FN_GET, "fmi2GetString");
    return (fmi2Status)fmu_no_variables(in, "fmi2GetString", nvr, "String variables");
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[])
{
    (void)vr, (void)value;
    ENTER(c, FN_SET, "fmi2SetString");
    return (fmi2Status)fmu_no_variables(in, "fmi2SetString", nvr, "String variables");
}

/* ---- FMU states ---- */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    ENTER(c, FN_GET_STATE, "fmi2GetFMUstate");
    return (fmi2Status)fmu_get_state(in, "fmi2GetFMUstate", FMUstate);
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    ENTER(c, FN_SET_STATE, "fmi2SetFMUstate");
    return (fmi2Status)fmu_set_state(in, "fmi2SetFMUstate", FMUstate);
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    ENTER(c, FN_FREE_STATE, "fmi2FreeFMUstate");
    return (fmi2Status)fmu_free_state(in, "fmi2FreeFMUstate", FMUstate);
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    ENTER(c, FN_STATE_SIZE, "fmi2SerializedFMUstateSize");
    return (fmi2Status)fmu_state_size(in, "fmi2SerializedFMUstateSize", FMUstate, size);
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate,
                                 fmi2Byte serializedState[], size_t size)
{
    ENTER(c, FN_SERIALIZE, "fmi2SerializeFMUstate");
    return (fmi2Status)fmu_serialize(in, "fmi2SerializeFMUstate", FMUstate,
                                     (unsigned char *)serializedState, size);
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[],
                                   size_t size, fmi2FMUstate *FMUstate)
{
    ENTER(c, FN_DESERIALIZE, "fmi2DeSerializeFMUstate");
    return (fmi2Status)fmu_deserialize(in, "fmi2DeSerializeFMUstate",
                                       (const unsigned char *)serializedState, size, FMUstate);
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[])
{
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown,
        (void)dvUnknown;
    return (fmi2Status)fmu_unsupported(c, "fmi2GetDirectionalDerivative",
                                       "not provided by this FMU");
}

/* ---- co-simulation ---- */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return (fmi2Status)fmu_unsupported(c, "fmi2SetRealInputDerivatives",
                                       "the FMU does not interpolate inputs");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[], fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return (fmi2Status)fmu_unsupported(c, "fmi2GetRealOutputDerivatives",
                                       "the FMU provides no output derivatives");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(c, FN_DO_STEP, "fmi2DoStep");
    return (fmi2Status)fmu_do_step(in, "fmi2DoStep", currentCommunicationPoint,
                                   communicationStepSize, NULL, NULL);
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    return (fmi2Status)fmu_unsupported(c, "fmi2CancelStep", "steps are never asynchronous");
}

/* A status query the FMU cannot answer (this kind of status is not
 * available): fmi2Discard (FMI 2.0, 4.2.3). */
#define NO_STATUS(fn, value, why)                                                                 \
    do {                                                                                          \
        ENTER(c, FN_STATUS, fn);                                                                  \
        return (fmi2Status)fmu_discard(in, fn, value, why);                                       \
    } while (0)

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s;
    NO_STATUS("fmi2GetStatus", value, "steps are never asynchronous");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    if (s != fmi2LastSuccessfulTime)
        NO_STATUS("fmi2GetRealStatus", value, "only fmi2LastSuccessfulTime is available");
    ENTER(c, FN_STATUS, "fmi2GetRealStatus");
    if (!value)
        return (fmi2Status)fmu_error(in, "fmi2GetRealStatus", "value is NULL");
    *value = fmu_time(in);
    return (fmi2Status)fmu_leave(in, "fmi2GetRealStatus", FMU_OK);
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s;
    NO_STATUS("fmi2GetIntegerStatus", value, "no Integer status is defined");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    if (s != fmi2Terminated)
        NO_STATUS("fmi2GetBooleanStatus", value, "only fmi2Terminated is available");
    ENTER(c, FN_STATUS, "fmi2GetBooleanStatus");
    if (!value)
        return (fmi2Status)fmu_error(in, "fmi2GetBooleanStatus", "value is NULL");
    *value = fmi2False; /* the FMU never asks to stop */
    return (fmi2Status)fmu_leave(in, "fmi2GetBooleanStatus", FMU_OK);
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)s;
    NO_STATUS("fmi2GetStringStatus", value, "no String status is defined");
}
