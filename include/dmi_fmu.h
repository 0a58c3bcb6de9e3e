/**
 * dmi_fmu.h: a dmi model as an FMI 2.0 and 3.0 co-simulation FMU.
 *
 * A model provides only what is its own: its variables (one table), a
 * function that configures a dmi_solver from the parameter values, a
 * function that computes the outputs at a communication point, and
 * optionally checks.  It defines them in one object, DMI_FMU_MODEL, in its
 * C file(s); the CMake function dmi_add_fmu() of find_package(dmi) compiles
 * them with the FMU framework and libdmi's GSL-free core into <name>.fmu
 * (FMI 2.0) and fmi3/<name>.fmu (FMI 3.0), both model descriptions written
 * from the table (docs/fmu-export.md).
 *
 * The framework owns everything else, for every model: the FMI 2.0 and 3.0
 * functions and their calling sequence; the time grid t_p = t_start + p h
 * (h = tau / N, or the model's step) from an integer step counter; a doStep takes every step whose
 * start t_p is before the end of the communication step; the outputs are
 * computed at any communication point from the piecewise-linear interpolant
 * of the scheme; inputs are held per step (step p uses the values set at or
 * before t_p); FMU states are checked bytes holding the variables and the
 * whole history; errors and warnings go to the importer's logger (never
 * printed, never aborting), with the memory the solver needs.
 *
 * Units: the model's own (the table's unit column); time in the units of the
 * FMU's time, tau in the same units.  Memory: the framework allocates
 * everything (through the C library); a model's functions allocate nothing
 * that outlives their call, and never keep the pointers they are given
 * beyond the lifetime the comments below state.  Threads: the framework
 * calls a model's functions for one instance at a time, but instances may
 * run in different threads at once: a model keeps no global mutable state
 * (everything it needs is in dmi_fmu_values).  Errors: a model's function
 * reports with its return value and a message in the buffer it is given;
 * it never prints, aborts or exits.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
/**/
#ifndef DMI_FMU_H
#define DMI_FMU_H

#include <stddef.h>
#include <stdint.h>

#include "dmi.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The size of the message buffers (err, msg) the framework passes to a
 * model's functions, with the NUL: longer messages are cut (use snprintf). */
#define DMI_FMU_ERRLEN 256

/**
 * One variable of the table, in the order of the value references 0, 1, ...
 * Write the table as an X-macro list and expand it with DMI_FMU_VARIABLE:
 *
 *   #define MY_VARIABLES(X)                                                 \
 *       X(tau, Float64, parameter, 10.0, "s", "delay of the convolution")    \
 *       X(N, Int32, parameter, 1000, "", "steps per tau")                   \
 *       X(x, Float64, output, , "m", "position")
 *   enum { MY_VARIABLES(DMI_FMU_VR) MY_NVARS };          (VR_tau, VR_N, VR_x)
 *   static const dmi_fmu_variable VARIABLES[] = {MY_VARIABLES(DMI_FMU_VARIABLE)};
 *
 * Columns: name (a C identifier, unique), type (Float64, Int32, Boolean),
 * causality (parameter: set before ExitInitializationMode, fixed after;
 * input: set at any time, held per step; output: computed, no start value;
 * independent: the time, Float64, no start value, at most one, the last
 * row; when the table has none, the framework adds "time" after the last
 * variable),
 * start value (a C constant; empty for outputs and the independent
 * variable; Boolean: 0 or 1), unit ("" for none) and description.
 * The model descriptions' generator (run by dmi_add_fmu at build time) checks
 * the table: a duplicate name, an output with a start value, a parameter or
 * input without one, an unknown type or causality fail the build with a
 * message naming the variable.
 * Fields (all strings static, from the macro): name; type ("Float64",
 * "Int32" or "Boolean"); causality ("parameter", "input", "output" or
 * "independent"); start_text (the start value as written, "" for none);
 * start (its value; Int32 and Boolean exact); unit ("" for none);
 * description.
 */
typedef struct dmi_fmu_variable dmi_fmu_variable;
struct dmi_fmu_variable {
    const char *name, *type, *causality, *start_text;
    double start;
    const char *unit, *description;
};

/** One table entry from an X-macro row (see dmi_fmu_variable).  An empty
 * start gives start_text "" (the value is then unused). */
#define DMI_FMU_VARIABLE(name, type, causality, start, unit, description)                        \
    {#name, #type, #causality, #start, (start - 0.0), unit, description},

/** The value reference VR_<name> of an X-macro row, for an enum. */
#define DMI_FMU_VR(name, ...) VR_##name,

/**
 * The values of an instance's variables that are set (parameters, inputs),
 * owned by the framework.  value[vr] holds variable vr, by value reference
 * (Int32 and Boolean as exact doubles; outputs: unspecified); value points
 * into the framework's memory (a pointer, not an array member, so that the
 * header is valid C++ too); t_start is the experiment's start time (the
 * solver's time t is the FMU's t_start + t).
 * A model's functions get a const pointer that stays valid, with the same
 * address, as long as the solver they configure (so the solver's callbacks
 * may keep it as their user data and read the inputs at each step); they
 * never write through it.
 */
typedef struct dmi_fmu_values dmi_fmu_values;
struct dmi_fmu_values {
    double t_start;
    const double *value;
};

/**
 * The outputs' arguments at a communication point t (the FMU's time), in
 * step p (from t_{p-1} to t_p, t_{p-1} < t <= t_p; p = 0 before the first
 * step): t; h, the solver's step (tau / N, or the model's step); p; n, the solver's dimension; u = u_h(t), the
 * scheme's piecewise-linear interpolant, NULL before ExitInitializationMode
 * (no solver yet: give the outputs from the parameters); U = U^p; W, the
 * delay term of step p (zeros when p = 0); X, the resolvent's argument of
 * step p, U^p = J(X) (U^0 when p = 0).  Arrays of n values, owned by the
 * framework, valid during the call; U, W, X are NULL when u is.
 */
typedef struct dmi_fmu_point dmi_fmu_point;
struct dmi_fmu_point {
    double t, h;
    uint64_t p;
    size_t n;
    const double *u, *U, *W, *X;
    /* The model's events (see dmi_fmu_indicators_fn) up to step p: nevents,
     * the number of solver steps at which an indicator changed since the
     * start (or since ExitInitializationMode); event_p, the last such step
     * (0: none yet), whose time is t_start + event_p h. */
    uint64_t nevents, event_p;
};

/**
 * Configures the new solver s, created by the framework with dmi_create(s,
 * model n, tau, N) from the parameters (dmi_create_h(s, n, tau, h) for a
 * model with a step function): sets rhs, the maximal monotone part
 * (dmi_set_friction, dmi_set_box or dmi_set_resolvent), the kernel
 * (dmi_set_kernel_exp or dmi_set_kernel) and the history, with v as user
 * data if the callbacks need the variables.  The framework calls dmi_init
 * after it.  Returns 0, or nonzero with the reason in err (DMI_FMU_ERRLEN
 * bytes; when err is left empty, dmi_last_error(s) is used; DMI_ENOMEM gives
 * the framework's out-of-memory message with N and the bytes).  The FMU then
 * logs "configuring the solver: <err>" and returns Error.
 */
typedef int (*dmi_fmu_configure_fn)(const dmi_fmu_values *v, dmi_solver *s, char *err);

/** Writes the outputs at pt into out[vr] for every output vr (Int32 and
 * Boolean outputs as exact doubles); the other entries are not read.  Called
 * at the first get of an output after a step, a set or a restored state
 * (the values are kept until the next change); out has one entry per value
 * reference and is owned by the framework. */
typedef void (*dmi_fmu_outputs_fn)(const dmi_fmu_values *v, const dmi_fmu_point *pt,
                                   double *out);

/** Optional: accepts the value of parameter or input vr (before it is
 * stored; v holds the values before the call): 0, or nonzero with the reason
 * in err (the set call is refused, nothing changes).  When an FMU state is
 * restored, v holds all of the state's values (vr's too) and each is checked
 * against them; one refused value refuses the state.  The framework already
 * refuses non-finite values, tau <= 0 and N < 1. */
typedef int (*dmi_fmu_accept_fn)(const dmi_fmu_values *v, unsigned vr, double value, char *err);

/** Optional: run at ExitInitializationMode, before the solver is created,
 * for an experiment of length T (stop - start time, or the default
 * experiment's stop time).  0: fine; 1: a warning (msg, status Warning);
 * -1: refused (msg, status Error). */
typedef int (*dmi_fmu_check_fn)(const dmi_fmu_values *v, double T, char *msg);

/** Optional: the bytes the solver allocates while initialising (peak) and
 * keeps (kept), for the memory messages (logMemory when peak > 100 MB, and
 * the out-of-memory error).  Without it the framework asks libdmi for the
 * solver as the model configured it (its kernel, rule and method: the
 * history ring, 2 (N + 1) n doubles, and the kernel's weights per cell
 * unless the recursion runs alone, a callback kernel's counted for every
 * entry); a model need not restate libdmi's layout. */
typedef void (*dmi_fmu_bytes_fn)(const dmi_fmu_values *v, double *peak, double *kept);

/**
 * Optional: the model's event indicators, the discrete states whose changes
 * are the model's events (a stick-slip transition, a contact).  Writes
 * state[k], k < nindicators (the model's field), for the step pt->p: any
 * integer; an event is a solver step at which one of them differs from the
 * step before.  Called by the framework after ExitInitializationMode (step 0:
 * X = U = U^0), after every solver step and after a state is restored, with
 * u = U = U^p and W, X of that step (never with u NULL).
 *
 * The framework steps one solver step at a time then (bitwise the same
 * steps as without indicators), counts the events (dmi_fmu_point's nevents
 * and event_p, which a model may give as outputs: an FMI 2.0 master reads
 * them) and, in the FMI 3.0 FMU, returns early from fmi3DoStep at an event
 * (earlyReturnAllowed) and asks for event mode (eventModeUsed): see
 * docs/fmu-export.md.  The built-ins below give the usual indicators.
 */
typedef void (*dmi_fmu_indicators_fn)(const dmi_fmu_values *v, const dmi_fmu_point *pt,
                                      int *state);

/* Built-in indicators without an indicators function: see dmi_fmu_model's
 * held, which takes dmi_fmu_stuck or dmi_fmu_contact of the solver's own
 * operator from the solver's step. */

/** dmi_fmu_stuck(pt, i, alpha_i), a built-in indicator of dmi_set_friction's
 * component i with coefficient alpha_i (>= 0): 1 (stuck) when the resolvent's argument lies within
 * h alpha_i of zero, |X_i| <= h alpha_i (then U_i = 0), else 0 (slipping). */
static inline int dmi_fmu_stuck(const dmi_fmu_point *pt, size_t i, double alpha_i)
{
    const double x = pt->X[i];
    return (x < 0 ? -x : x) <= pt->h * alpha_i;
}

/** dmi_fmu_contact(pt, i, lo_i, hi_i), a built-in indicator of dmi_set_box's
 * component i with faces lo_i <= hi_i: -1 in contact with the lower face (X_i <= lo_i, then U_i = lo_i), +1 with
 * the upper face (X_i >= hi_i, U_i = hi_i), 0 inside. */
static inline int dmi_fmu_contact(const dmi_fmu_point *pt, size_t i, double lo_i, double hi_i)
{
    const double x = pt->X[i];
    return x <= lo_i ? -1 : x >= hi_i ? 1 : 0;
}

/**
 * Optional (since libdmi 1.2): the step h of the solver from the parameters
 * (e.g. 2 pi / (omega steps) for a whole number of steps per forcing period),
 * in the units of the FMU's time; tau / h need not be an integer.  With it,
 * the framework creates the solver with dmi_create_h(s, n, tau, h) (the last
 * cell of the delay sum partial, weighted as dmi.h says) instead of
 * dmi_create(s, n, tau, N); the solver's N, the number of cells of the delay
 * sum, is then libdmi's (dmi_get_N: ceil(tau / h), or tau / h when h is
 * tau / N exactly), and it is that N the memory messages and the saved
 * states' checks use.  The model's N variable stays an Int32 parameter >= 1
 * that the model may read here (e.g. the steps per period).  Called at
 * ExitInitializationMode and when a state with a solver is restored, with
 * the values the solver is made for; an h that is not finite and > 0 (or
 * not a normal double) refuses them with a logged error ("creating the
 * solver: ...").  Without it (NULL), h = tau / N.
 */
typedef double (*dmi_fmu_step_fn)(const dmi_fmu_values *v);

/**
 * A model: what dmi_add_fmu builds an FMU of.  Fields: description (the
 * model descriptions', with " (libdmi <version>)" appended); variables and
 * nvariables (the table, value reference = index); n (the components of u);
 * tau and N (the value references of the delay, a Float64 parameter, and of
 * the steps per tau, an Int32 parameter); stop_time and step_size (the
 * default experiment, which starts at 0); configure and outputs (required);
 * accept, check and bytes (optional: NULL for none; without bytes,
 * libdmi's figures for the configured solver); author (the model descriptions' author, NULL
 * for none); nindicators and indicators (optional: 0 and NULL for none; see
 * dmi_fmu_indicators_fn); step (optional: NULL for h = tau / N; see
 * dmi_fmu_step_fn); held (optional, the last field: the built-in indicators
 * from the solver's step instead of an indicators function).  The model
 * descriptions' generator checks it at build time (a table as described
 * above, tau and N as said, n >= 1, configure and outputs given).
 */
typedef struct dmi_fmu_model dmi_fmu_model;
struct dmi_fmu_model {
    const char *description;
    const dmi_fmu_variable *variables;
    size_t nvariables;
    size_t n;
    unsigned tau, N;
    double stop_time, step_size;
    dmi_fmu_configure_fn configure;
    dmi_fmu_outputs_fn outputs;
    dmi_fmu_accept_fn accept;
    dmi_fmu_check_fn check;
    dmi_fmu_bytes_fn bytes;
    const char *author;
    size_t nindicators;
    dmi_fmu_indicators_fn indicators;
    /* (Since libdmi 1.2.)  Optional, NULL for none: see dmi_fmu_step_fn. */
    dmi_fmu_step_fn step;
    /* (Since libdmi 1.3.)  Optional, NULL for none: the built-in indicators
     * of the solver's own operator, indicator k (k < nindicators) for
     * component held[k]: dmi_fmu_stuck(pt, i, alpha_i) with the alpha of
     * dmi_set_friction, or dmi_fmu_contact(pt, i, lo_i, hi_i) with the faces
     * of dmi_set_box.  libdmi takes them from each step's resolvent argument
     * as it steps (no indicators call, no state read back: the FMU steps at
     * about libdmi's own speed, docs/fmu-export.md); indicators is then not
     * called (leave it NULL).  A solver configured with another operator (a
     * resolvent callback, none) fails ExitInitializationMode with a logged
     * error. */
    const size_t *held;
};

/** The model of the FMU: define it once, in one of its C files:
 *   const dmi_fmu_model DMI_FMU_MODEL = {...}; */
#define DMI_FMU_MODEL dmi_fmu_model_definition
extern const dmi_fmu_model DMI_FMU_MODEL;

/** The number of entries of a table array. */
#define DMI_FMU_COUNT(table) (sizeof(table) / sizeof((table)[0]))

#ifdef __cplusplus
}
#endif

#endif
