/*
 * The FMI side of the FMU common to FMI 2.0 and 3.0: an instance of the
 * model (framework.h over the model's dmi_fmu.h definition), the calling
 * sequence (one table of the states in which each function is allowed),
 * logging through the importer's callback,
 * all-or-nothing get/set, FMU states as checked bytes.  fmi2Functions.c and
 * fmi3Functions.c are thin adapters over it: they convert types and names
 * and call these functions.  Nothing here knows about a particular model, or
 * about a version of the standard beyond the states both share.
 *
 * Every function takes the FMI function's name (fn, "fmi2SetReal", ...) for
 * the log.  Each call is logged once, with its outcome: an error (status
 * FMU_ERROR, category logStatusError) or a warning (FMU_WARNING, category
 * logStatusWarning) is always sent, whatever loggingOn says; a call that
 * succeeds is logged as "fn" with status FMU_OK (category logCalls) when debug logging is
 * on.  A rejected call (bad argument, value, state bytes, or a call not
 * allowed in the current state) leaves the instance as it was; only a
 * failure of the solver in a step puts the instance into the error state
 * (then SetFMUstate or Reset).
 *
 * Memory: libdmi allocates the solver with the C library, so all the FMU's
 * memory comes from there (calloc, malloc, free); the importer's memory
 * callbacks (FMI 2.0) are never called.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_FMU_INSTANCE_H
#define DMI_FMU_INSTANCE_H

#include <stddef.h>

#include "framework.h"

/* Status codes: the same numbers as fmi2Status and fmi3Status. */
typedef enum { FMU_OK, FMU_WARNING, FMU_DISCARD, FMU_ERROR, FMU_FATAL } fmu_status;

/* The instance's states; FMI 3.0's step mode is FMI 2.0's step complete;
 * event mode is FMI 3.0's (with eventModeUsed). */
enum {
    FMU_INSTANTIATED = 1 << 0,
    FMU_INIT_MODE = 1 << 1,
    FMU_STEP_MODE = 1 << 2,
    FMU_TERMINATED = 1 << 3,
    FMU_ERROR_STATE = 1 << 4,
    FMU_EVENT_MODE = 1 << 5
};

/* The functions of the calling sequence: each has one mask of allowed
 * states in instance.c (ALLOWED). */
typedef enum {
    FN_SET_DEBUG_LOGGING,
    FN_FREE_INSTANCE,
    FN_SETUP_EXPERIMENT,
    FN_ENTER_INIT,
    FN_EXIT_INIT,
    FN_TERMINATE,
    FN_RESET,
    FN_GET,
    FN_SET,
    FN_GET_STATE,
    FN_SET_STATE,
    FN_FREE_STATE,
    FN_STATE_SIZE,
    FN_SERIALIZE,
    FN_DESERIALIZE,
    FN_DO_STEP,
    FN_ENTER_EVENT, /* FMI 3.0 event mode */
    FN_ENTER_STEP,
    FN_UPDATE_DISCRETE,
    FN_STATUS,      /* FMI 2.0 status queries */
    FN_UNSUPPORTED, /* a function this FMU does not provide: always an error */
    FN_COUNT
} fmu_fn;

/* The importer's logger, as a generic function pointer that the adapter's
 * sink converts back to its own type and calls. */
typedef void (*fmu_callback)(void);
typedef void fmu_sink(fmu_callback logger, void *environment, const char *instance_name,
                      fmu_status status, const char *category, const char *message);

typedef struct fmu_instance fmu_instance;

/* A new instance (state instantiated, start values), or NULL with the reason
 * logged through logger (if any): empty name, out of memory. */
fmu_instance *fmu_instantiate(const char *fn, const char *name, fmu_sink *sink,
                              fmu_callback logger, void *environment, int logging_on);
/* Logs through the callbacks given without an instance (fmi2Instantiate's
 * checks before the instance exists). */
void fmu_log_error(const char *fn, const char *name, fmu_sink *sink, fmu_callback logger,
                   void *environment, const char *fmt, ...);

/* The instance if fn is allowed in its state, NULL if not (logged) or if c
 * is NULL.  The adapters call it before any argument is read. */
fmu_instance *fmu_enter(void *c, fmu_fn which, const char *fn);
/* Logs the error fmt (prefixed with fn) and returns FMU_ERROR. */
fmu_status fmu_error(fmu_instance *in, const char *fn, const char *fmt, ...);
/* The end of a call: logs fn with its status st unless the call logged
 * already (an error or warning), returns st. */
fmu_status fmu_leave(fmu_instance *in, const char *fn, fmu_status st);

fmu_status fmu_set_debug_logging(fmu_instance *in, const char *fn, int on, size_t n,
                                 const char *const categories[]);
void fmu_free_instance(fmu_instance *in, const char *fn);
/* fmi2SetupExperiment: the start time, and the stop time if defined. */
fmu_status fmu_setup_experiment(fmu_instance *in, const char *fn, double start_time,
                                int stop_time_defined, double stop_time);
/* Enters initialization mode; FMI 3.0 gives the experiment's times here
 * (start_time not NULL: checked and set as by fmu_setup_experiment). */
fmu_status fmu_enter_init(fmu_instance *in, const char *fn, const double *start_time,
                          int stop_time_defined, double stop_time);
/* Runs the model's check (a refusal: FMU_ERROR, nothing started) and starts
 * the solver; FMU_WARNING (logged) when the check warns. */
fmu_status fmu_exit_init(fmu_instance *in, const char *fn);
fmu_status fmu_terminate(fmu_instance *in, const char *fn);
fmu_status fmu_reset(fmu_instance *in, const char *fn);

/* Element i of an FMI value array from or to a double (the adapter converts
 * its type; Int32 and Boolean values are exact doubles, Boolean 0 or 1). */
typedef void fmu_put_fn(void *values, size_t i, double value);
typedef double fmu_take_fn(const void *values, size_t i);
/* The variables vr of type (FMU_FLOAT64, ..., with FMU_NO_INDEPENDENT for
 * FMI 2.0's Real); put converts each value (NULL for FMU_FLOAT64: values is
 * an array of doubles). */
fmu_status fmu_get(fmu_instance *in, const char *fn, const unsigned vr[], size_t nvr,
                   void *values, unsigned type, fmu_put_fn *put);
/* All values or none. */
fmu_status fmu_set(fmu_instance *in, const char *fn, const unsigned vr[], size_t nvr,
                   const void *values, unsigned type, fmu_take_fn *take);
/* A type of which the FMU has no variable (nothing to get or set): nvr = 0 is
 * OK; what: "String variables", ... */
fmu_status fmu_no_variables(fmu_instance *in, const char *fn, size_t nvr, const char *type);

/* FMU states: *state is an opaque pointer owned by the importer until freed. */
fmu_status fmu_get_state(fmu_instance *in, const char *fn, void **state);
fmu_status fmu_set_state(fmu_instance *in, const char *fn, const void *state);
fmu_status fmu_free_state(fmu_instance *in, const char *fn, void **state);
fmu_status fmu_state_size(fmu_instance *in, const char *fn, const void *state, size_t *size);
fmu_status fmu_serialize(fmu_instance *in, const char *fn, const void *state,
                         unsigned char *bytes, size_t size);
fmu_status fmu_deserialize(fmu_instance *in, const char *fn, const unsigned char *bytes,
                           size_t size, void **state);

/* FMI 3.0 co-simulation's options: eventModeUsed, earlyReturnAllowed and the
 * intermediateUpdate callback (NULL for none), which ask calls at an event
 * of time t with canReturnEarly = can_return and gives earlyReturnRequested. */
typedef int fmu_ask_fn(fmu_callback intermediate, void *environment, double t, int can_return);
void fmu_set_cosimulation(fmu_instance *in, int event_mode_used, int early_return_allowed,
                          fmu_callback intermediate, fmu_ask_fn *ask);

/* The communication step from t to t + h (fmu_model_do_step).  At an event
 * (a step at which one of the model's indicators changes) before the end:
 * intermediateUpdate is called, if given; with earlyReturnAllowed the step
 * ends there (*early = 1, the FMU's time is that step's) unless the callback
 * declined the early return.  *event_handling: eventModeUsed and an
 * indicator changed during the step.  early and event_handling may be NULL
 * (FMI 2.0: never early). */
fmu_status fmu_do_step(fmu_instance *in, const char *fn, double t, double h, int *early,
                       int *event_handling);
/* FMI 3.0: event mode (from step mode, with eventModeUsed) and back. */
fmu_status fmu_enter_event_mode(fmu_instance *in, const char *fn);
fmu_status fmu_enter_step_mode(fmu_instance *in, const char *fn);
/* FMI 3.0's fmi3UpdateDiscreteStates in event mode: the model's discrete
 * states (its indicators) are already those of the current step; nothing
 * more to update, no time event. */
fmu_status fmu_update_discrete_states(fmu_instance *in, const char *fn);
/* The FMU's time (the last communication point). */
double fmu_time(const fmu_instance *in);

/* A function the FMU does not provide: FMU_ERROR with the reason. */
fmu_status fmu_unsupported(void *c, const char *fn, const char *why);
/* A status the FMU cannot give: FMU_DISCARD, the reason logged as the call's
 * outcome when debug logging is on; FMU_ERROR if value is NULL. */
fmu_status fmu_discard(fmu_instance *in, const char *fn, const void *value, const char *why);

#endif
