/*
 * The FMI 3.0 co-simulation interface of the model: a thin adapter over the
 * version-neutral instance layer (instance.h), which checks the calling
 * sequence, logs and keeps the FMU states.  Here: FMI 3.0's types and names,
 * the checks of fmi3InstantiateCoSimulation's arguments, and fmi3DoStep's
 * flags.
 *
 * Events (a model's indicators, dmi_fmu.h): with earlyReturnAllowed,
 * fmi3DoStep returns early at the first solver step at which an indicator
 * changes (earlyReturn = true, lastSuccessfulTime = that step's time
 * t_start + p h), after calling intermediateUpdate (if given; the importer
 * may decline the early return there); with eventModeUsed it reports
 * eventHandlingNeeded when an indicator changed in the step, and the FMU
 * is in event mode after fmi3ExitInitializationMode and after
 * fmi3EnterEventMode until fmi3EnterStepMode.  terminateSimulation is
 * always false.  Its variables are Float64, Int32 and Boolean scalars (the model's table,
 * dmi_fmu.h); the functions of the other types, of
 * clocks, of model exchange and scheduled execution are exported as the
 * standard asks and refuse with fmi3Error and a logged reason.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <string.h>

#include "fmi3Functions.h"
#include "instance.h"

#define ENTER(c, which, fn)                                                                       \
    fmu_instance *in = fmu_enter(c, which, fn);                                                   \
    if (!in)                                                                                      \
    return fmi3Error

static void sink(fmu_callback logger, void *environment, const char *name, fmu_status status,
                 const char *category, const char *message)
{
    (void)name;
    ((fmi3LogMessageCallback)logger)(environment, (fmi3Status)status, category, message);
}

/* intermediateUpdate at an event of time t: the step is finished there; no
 * variable is to be set or got. */
static int ask(fmu_callback intermediate, void *environment, double t, int can_return)
{
    fmi3Boolean requested = fmi3False;
    fmi3Float64 when = t;
    ((fmi3IntermediateUpdateCallback)intermediate)(environment, t, fmi3False, fmi3False,
                                                   fmi3True, can_return ? fmi3True : fmi3False,
                                                   &requested, &when);
    return requested != fmi3False;
}

/* The reason every function of model exchange or scheduled execution gives. */
#define NO_ME "the FMU supports co-simulation only"

/* ---- version, logging, instances ---- */

const char *fmi3GetVersion(void)
{
    return fmi3Version;
}

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    ENTER(instance, FN_SET_DEBUG_LOGGING, "fmi3SetDebugLogging");
    return (fmi3Status)fmu_set_debug_logging(in, "fmi3SetDebugLogging", loggingOn, nCategories,
                                             categories);
}

fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
    fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate)
{
    static const char fn[] = "fmi3InstantiateCoSimulation";
    const fmu_callback logger = (fmu_callback)logMessage;
    (void)resourcePath, (void)visible, (void)requiredIntermediateVariables;
    if (instanceName && *instanceName) { /* (an empty name: refused by fmu_instantiate) */
        if (!instantiationToken || strcmp(instantiationToken, dmi_fmu_guid) != 0) {
            fmu_log_error(fn, instanceName, sink, logger, instanceEnvironment,
                          "instantiation token \"%s\" is not the FMU's GUID %s",
                          instantiationToken ? instantiationToken : "(null)", dmi_fmu_guid);
            return NULL;
        }
        if (nRequiredIntermediateVariables > 0) {
            fmu_log_error(fn, instanceName, sink, logger, instanceEnvironment, "%s",
                          "the FMU has no intermediate variables (intermediateUpdate is "
                          "called at events, without getting or setting variables)");
            return NULL;
        }
    }
    fmu_instance *in = fmu_instantiate(fn, instanceName, sink, logger, instanceEnvironment,
                                       loggingOn);
    if (in)
        fmu_set_cosimulation(in, eventModeUsed, earlyReturnAllowed,
                             (fmu_callback)intermediateUpdate, ask);
    return in;
}

/* The instantiation of an interface type the FMU does not provide: NULL,
 * the reason logged. */
static fmi3Instance refuse_instantiate(const char *fn, fmi3String instanceName,
                                       fmi3InstanceEnvironment instanceEnvironment,
                                       fmi3LogMessageCallback logMessage)
{
    fmu_log_error(fn, instanceName ? instanceName : "?", sink, (fmu_callback)logMessage,
                  instanceEnvironment, "%s", NO_ME);
    return NULL;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible,
                                          fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn;
    return refuse_instantiate("fmi3InstantiateModelExchange", instanceName, instanceEnvironment,
                              logMessage);
}

fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
    fmi3LockPreemptionCallback lockPreemption, fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn;
    (void)clockUpdate, (void)lockPreemption, (void)unlockPreemption;
    return refuse_instantiate("fmi3InstantiateScheduledExecution", instanceName,
                              instanceEnvironment, logMessage);
}

void fmi3FreeInstance(fmi3Instance instance)
{
    fmu_instance *in = fmu_enter(instance, FN_FREE_INSTANCE, "fmi3FreeInstance");
    if (in)
        fmu_free_instance(in, "fmi3FreeInstance");
}

/* ---- modes ---- */

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    (void)toleranceDefined, (void)tolerance;
    ENTER(instance, FN_ENTER_INIT, "fmi3EnterInitializationMode");
    return (fmi3Status)fmu_enter_init(in, "fmi3EnterInitializationMode", &startTime,
                                      stopTimeDefined, stopTime);
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    ENTER(instance, FN_EXIT_INIT, "fmi3ExitInitializationMode");
    return (fmi3Status)fmu_exit_init(in, "fmi3ExitInitializationMode");
}

fmi3Status fmi3Terminate(fmi3Instance instance)
{
    ENTER(instance, FN_TERMINATE, "fmi3Terminate");
    return (fmi3Status)fmu_terminate(in, "fmi3Terminate");
}

fmi3Status fmi3Reset(fmi3Instance instance)
{
    ENTER(instance, FN_RESET, "fmi3Reset");
    return (fmi3Status)fmu_reset(in, "fmi3Reset");
}

/* ---- getting and setting values ---- */

static void put_int32(void *values, size_t i, double x)
{
    ((fmi3Int32 *)values)[i] = (fmi3Int32)x;
}

static void put_boolean(void *values, size_t i, double x)
{
    ((fmi3Boolean *)values)[i] = x != 0;
}

static double take_float64(const void *values, size_t i)
{
    return ((const fmi3Float64 *)values)[i];
}

static double take_int32(const void *values, size_t i)
{
    return ((const fmi3Int32 *)values)[i];
}

static double take_boolean(const void *values, size_t i)
{
    return ((const fmi3Boolean *)values)[i] != 0;
}

/* All variables are scalars: one value per value reference. */
static int bad_count(fmu_instance *in, const char *fn, size_t nvr, size_t nValues)
{
    if (nValues != nvr) {
        fmu_error(in, fn, "%zu values for %zu value references of scalar variables", nValues,
                  nvr);
        return 1;
    }
    return 0;
}

#define GET(Type, kind, put)                                                                      \
    fmi3Status fmi3Get##Type(fmi3Instance instance, const fmi3ValueReference valueReferences[],   \
                             size_t nValueReferences, fmi3##Type values[], size_t nValues)        \
    {                                                                                             \
        ENTER(instance, FN_GET, "fmi3Get" #Type);                                                 \
        if (bad_count(in, "fmi3Get" #Type, nValueReferences, nValues))                            \
            return fmi3Error;                                                                     \
        return (fmi3Status)fmu_get(in, "fmi3Get" #Type, valueReferences, nValueReferences,        \
                                   values, kind, put);                                            \
    }
#define SET(Type, kind, take)                                                                     \
    fmi3Status fmi3Set##Type(fmi3Instance instance, const fmi3ValueReference valueReferences[],   \
                             size_t nValueReferences, const fmi3##Type values[], size_t nValues)  \
    {                                                                                             \
        ENTER(instance, FN_SET, "fmi3Set" #Type);                                                 \
        if (bad_count(in, "fmi3Set" #Type, nValueReferences, nValues))                            \
            return fmi3Error;                                                                     \
        return (fmi3Status)fmu_set(in, "fmi3Set" #Type, valueReferences, nValueReferences,        \
                                   values, kind, take);                                           \
    }
GET(Float64, FMU_FLOAT64, NULL) /* the values are doubles */
GET(Int32, FMU_INT32, put_int32)
GET(Boolean, FMU_BOOLEAN, put_boolean)
SET(Float64, FMU_FLOAT64, take_float64)
SET(Int32, FMU_INT32, take_int32)
SET(Boolean, FMU_BOOLEAN, take_boolean)

/* The types of which the FMU has no variable. */
#define NONE(Name, which, Type, what)                                                             \
    fmi3Status fmi3##Name(fmi3Instance instance, const fmi3ValueReference valueReferences[],      \
                          size_t nValueReferences, Type values[], size_t nValues)                 \
    {                                                                                             \
        (void)valueReferences, (void)values, (void)nValues;                                       \
        ENTER(instance, which, "fmi3" #Name);                                                     \
        return (fmi3Status)fmu_no_variables(in, "fmi3" #Name, nValueReferences, what);            \
    }
NONE(GetFloat32, FN_GET, fmi3Float32, "Float32 variables")
NONE(GetInt8, FN_GET, fmi3Int8, "Int8 variables")
NONE(GetUInt8, FN_GET, fmi3UInt8, "UInt8 variables")
NONE(GetInt16, FN_GET, fmi3Int16, "Int16 variables")
NONE(GetUInt16, FN_GET, fmi3UInt16, "UInt16 variables")
NONE(GetUInt32, FN_GET, fmi3UInt32, "UInt32 variables")
NONE(GetInt64, FN_GET, fmi3Int64, "Int64 variables")
NONE(GetUInt64, FN_GET, fmi3UInt64, "UInt64 variables")
NONE(GetString, FN_GET, fmi3String, "String variables")
NONE(SetFloat32, FN_SET, const fmi3Float32, "Float32 variables")
NONE(SetInt8, FN_SET, const fmi3Int8, "Int8 variables")
NONE(SetUInt8, FN_SET, const fmi3UInt8, "UInt8 variables")
NONE(SetInt16, FN_SET, const fmi3Int16, "Int16 variables")
NONE(SetUInt16, FN_SET, const fmi3UInt16, "UInt16 variables")
NONE(SetUInt32, FN_SET, const fmi3UInt32, "UInt32 variables")
NONE(SetInt64, FN_SET, const fmi3Int64, "Int64 variables")
NONE(SetUInt64, FN_SET, const fmi3UInt64, "UInt64 variables")
NONE(SetString, FN_SET, const fmi3String, "String variables")

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, size_t valueSizes[], fmi3Binary values[],
                         size_t nValues)
{
    (void)valueReferences, (void)valueSizes, (void)values, (void)nValues;
    ENTER(instance, FN_GET, "fmi3GetBinary");
    return (fmi3Status)fmu_no_variables(in, "fmi3GetBinary", nValueReferences, "Binary variables");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues)
{
    (void)valueReferences, (void)valueSizes, (void)values, (void)nValues;
    ENTER(instance, FN_SET, "fmi3SetBinary");
    return (fmi3Status)fmu_no_variables(in, "fmi3SetBinary", nValueReferences, "Binary variables");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Clock values[])
{
    (void)valueReferences, (void)values;
    ENTER(instance, FN_GET, "fmi3GetClock");
    return (fmi3Status)fmu_no_variables(in, "fmi3GetClock", nValueReferences, "Clock variables");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Clock values[])
{
    (void)valueReferences, (void)values;
    ENTER(instance, FN_SET, "fmi3SetClock");
    return (fmi3Status)fmu_no_variables(in, "fmi3SetClock", nValueReferences, "Clock variables");
}

/* ---- FMU states: the same checked bytes as the FMI 2.0 FMU's ---- */

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    ENTER(instance, FN_GET_STATE, "fmi3GetFMUState");
    return (fmi3Status)fmu_get_state(in, "fmi3GetFMUState", FMUState);
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    ENTER(instance, FN_SET_STATE, "fmi3SetFMUState");
    return (fmi3Status)fmu_set_state(in, "fmi3SetFMUState", FMUState);
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    ENTER(instance, FN_FREE_STATE, "fmi3FreeFMUState");
    return (fmi3Status)fmu_free_state(in, "fmi3FreeFMUState", FMUState);
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    ENTER(instance, FN_STATE_SIZE, "fmi3SerializedFMUStateSize");
    return (fmi3Status)fmu_state_size(in, "fmi3SerializedFMUStateSize", FMUState, size);
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState,
                                 fmi3Byte serializedState[], size_t size)
{
    ENTER(instance, FN_SERIALIZE, "fmi3SerializeFMUState");
    return (fmi3Status)fmu_serialize(in, "fmi3SerializeFMUState", FMUState, serializedState,
                                     size);
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[],
                                   size_t size, fmi3FMUState *FMUState)
{
    ENTER(instance, FN_DESERIALIZE, "fmi3DeserializeFMUState");
    return (fmi3Status)fmu_deserialize(in, "fmi3DeserializeFMUState", serializedState, size,
                                       FMUState);
}

/* ---- co-simulation ---- */

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(instance, FN_DO_STEP, "fmi3DoStep");
    if (!eventHandlingNeeded || !terminateSimulation || !earlyReturn || !lastSuccessfulTime)
        return (fmi3Status)fmu_error(in, "fmi3DoStep", "NULL output argument");
    int early = 0, event = 0;
    const fmi3Status st = (fmi3Status)fmu_do_step(in, "fmi3DoStep", currentCommunicationPoint,
                                                  communicationStepSize, &early, &event);
    *eventHandlingNeeded = event ? fmi3True : fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = early ? fmi3True : fmi3False;
    *lastSuccessfulTime = fmu_time(in);
    return st;
}

/* ---- what this FMU does not provide ---- */

#define UNSUPPORTED(call, why) return (fmi3Status)fmu_unsupported(instance, call, why)
#define NO_EVENTS "the FMU has no clocks"

fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    ENTER(instance, FN_ENTER_EVENT, "fmi3EnterEventMode");
    return (fmi3Status)fmu_enter_event_mode(in, "fmi3EnterEventMode");
}

fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    ENTER(instance, FN_ENTER_STEP, "fmi3EnterStepMode");
    return (fmi3Status)fmu_enter_step_mode(in, "fmi3EnterStepMode");
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance,
                                               fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    (void)valueReference, (void)nDependencies;
    UNSUPPORTED("fmi3GetNumberOfVariableDependencies",
                "dependencies are in the model description only");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    (void)dependent, (void)elementIndicesOfDependent, (void)independents;
    (void)elementIndicesOfIndependents, (void)dependencyKinds, (void)nDependencies;
    UNSUPPORTED("fmi3GetVariableDependencies", "dependencies are in the model description only");
}

#define DERIVATIVE(Name)                                                                          \
    fmi3Status fmi3##Name(fmi3Instance instance, const fmi3ValueReference unknowns[],             \
                          size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,    \
                          const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],      \
                          size_t nSensitivity)                                                    \
    {                                                                                             \
        (void)unknowns, (void)nUnknowns, (void)knowns, (void)nKnowns, (void)seed, (void)nSeed;    \
        (void)sensitivity, (void)nSensitivity;                                                    \
        UNSUPPORTED("fmi3" #Name, "not provided by this FMU");                                    \
    }
DERIVATIVE(GetDirectionalDerivative)
DERIVATIVE(GetAdjointDerivative)

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[],
                                    fmi3Float64 values[], size_t nValues)
{
    (void)valueReferences, (void)nValueReferences, (void)orders, (void)values, (void)nValues;
    UNSUPPORTED("fmi3GetOutputDerivatives", "the FMU provides no output derivatives");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    UNSUPPORTED("fmi3EnterConfigurationMode", "the FMU has no structural parameters");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    UNSUPPORTED("fmi3ExitConfigurationMode", "the FMU has no structural parameters");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance,
                                  const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences, (void)nValueReferences, (void)intervals, (void)qualifiers;
    UNSUPPORTED("fmi3GetIntervalDecimal", NO_EVENTS);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance,
                                   const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[],
                                   fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    (void)qualifiers;
    UNSUPPORTED("fmi3GetIntervalFraction", NO_EVENTS);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[])
{
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    UNSUPPORTED("fmi3GetShiftDecimal", NO_EVENTS);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[],
                                fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    UNSUPPORTED("fmi3GetShiftFraction", NO_EVENTS);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance,
                                  const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)valueReferences, (void)nValueReferences, (void)intervals;
    UNSUPPORTED("fmi3SetIntervalDecimal", NO_EVENTS);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance,
                                   const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    UNSUPPORTED("fmi3SetIntervalFraction", NO_EVENTS);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    UNSUPPORTED("fmi3SetShiftDecimal", NO_EVENTS);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[],
                                const fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    UNSUPPORTED("fmi3SetShiftFraction", NO_EVENTS);
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    UNSUPPORTED("fmi3EvaluateDiscreteStates", "the FMU does not provide it "
                                              "(providesEvaluateDiscreteStates=\"false\")");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation,
                                    fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged,
                                    fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime)
{
    ENTER(instance, FN_UPDATE_DISCRETE, "fmi3UpdateDiscreteStates");
    if (!discreteStatesNeedUpdate || !terminateSimulation || !nominalsOfContinuousStatesChanged ||
        !valuesOfContinuousStatesChanged || !nextEventTimeDefined || !nextEventTime)
        return (fmi3Status)fmu_error(in, "fmi3UpdateDiscreteStates", "NULL output argument");
    /* the indicators are those of the current step already; no time event */
    *discreteStatesNeedUpdate = fmi3False;
    *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False;
    *valuesOfContinuousStatesChanged = fmi3False;
    *nextEventTimeDefined = fmi3False;
    *nextEventTime = 0.0;
    return (fmi3Status)fmu_update_discrete_states(in, "fmi3UpdateDiscreteStates");
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{
    UNSUPPORTED("fmi3EnterContinuousTimeMode", NO_ME);
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance,
                                       fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode,
                                       fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint, (void)enterEventMode, (void)terminateSimulation;
    UNSUPPORTED("fmi3CompletedIntegratorStep", NO_ME);
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    (void)time;
    UNSUPPORTED("fmi3SetTime", NO_ME);
}

/* The model-exchange functions on arrays of continuous states or event indicators. */
#define ME_ARRAY(Name, Type)                                                                      \
    fmi3Status fmi3##Name(fmi3Instance instance, Type values[], size_t n)                         \
    {                                                                                             \
        (void)values, (void)n;                                                                    \
        UNSUPPORTED("fmi3" #Name, NO_ME);                                                         \
    }
ME_ARRAY(SetContinuousStates, const fmi3Float64)
ME_ARRAY(GetContinuousStateDerivatives, fmi3Float64)
ME_ARRAY(GetEventIndicators, fmi3Float64)
ME_ARRAY(GetContinuousStates, fmi3Float64)
ME_ARRAY(GetNominalsOfContinuousStates, fmi3Float64)

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    (void)nEventIndicators;
    UNSUPPORTED("fmi3GetNumberOfEventIndicators", NO_ME);
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    (void)nContinuousStates;
    UNSUPPORTED("fmi3GetNumberOfContinuousStates", NO_ME);
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    (void)clockReference, (void)activationTime;
    UNSUPPORTED("fmi3ActivateModelPartition", NO_ME);
}
