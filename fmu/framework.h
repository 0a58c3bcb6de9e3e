/*
 * The FMU framework's model layer, for any model of dmi_fmu.h: the values of
 * the variables (set and checked through the table), the solver on the grid
 * t_p = t_start + p h, the outputs at any communication point, and the saved
 * state.  instance.c, the FMI side common to FMI 2.0 and 3.0, checks the
 * calling sequence and does the logging; fmi2Functions.c and fmi3Functions.c
 * adapt it to each standard.  None of them knows about a particular model.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_FMU_FRAMEWORK_H
#define DMI_FMU_FRAMEWORK_H

#include <stddef.h>
#include <stdint.h>

#include "dmi.h"
#include "dmi_fmu.h"

/* The FMU's GUID (FMI 2.0) and instantiationToken (FMI 3.0): written by
 * dmi_add_fmu into the generated fmu_identity.c. */
extern const char dmi_fmu_guid[];
/* The FMU's model name (modelIdentifier), from dmi_add_fmu's NAME, in the
 * same file. */
extern const char dmi_fmu_model_name[];

/* The log categories of both model descriptions: C(name, description), in
 * the order of instance.c's CAT_* numbers. */
#define FMU_LOG_CATEGORIES(C)                                                                      \
    C(logStatusError, "the reason of every error (always sent)")                                   \
    C(logStatusWarning, "every warning, e.g. a coarse step (always sent)")                         \
    C(logCalls, "each FMI call with its outcome, when debug logging is on")                        \
    C(logMemory, "what initialization allocates when it is more than 100 MB (always sent)")

/* Longest message written into the err buffers below. */
#define FMU_ERRLEN DMI_FMU_ERRLEN

/* Interpolation and communication points: times closer than this fraction
 * of h are the same time. */
#define FMU_TIME_TOL 1e-6

/* The memory note: sent (category logMemory) when initialising allocates more. */
#define FMU_NOTE_BYTES 100e6

/* A variable's type and causality (from the table's strings). */
enum { FMU_FLOAT64 = 1, FMU_INT32 = 2, FMU_BOOLEAN = 4 };
enum { FMU_PARAMETER = 8, FMU_INPUT = 16, FMU_OUTPUT = 32, FMU_INDEPENDENT = 64 };
/* With a type in fmu_model_get: the independent variable is not one (FMI 2.0). */
#define FMU_NO_INDEPENDENT 128u
/* The kind (type | causality) of value reference vr; 0 if there is none.
 * The independent variable is vr = DMI_FMU_MODEL.nvariables when the table
 * has none. */
unsigned fmu_kind(unsigned vr);
/* Whether vr is a parameter or an input: the values set and saved. */
int fmu_is_set(unsigned kind);

typedef struct {
    dmi_fmu_values *v;  /* the values (heap, fixed address: the solver's callbacks keep it) */
    double t_comm;      /* the last communication point (t_start before any step) */
    dmi_solver *solver; /* NULL until fmu_model_start */
    uint64_t p;         /* the solver's step index and step h, kept beside it (no query */
    double h;           /* per doStep or get): set with the solver and by every step */
    double *out;        /* the outputs by value reference (with v's block) */
    double *work;       /* 5 n values: u, U, U^{p-1}, W, X (with v's block) */
    unsigned char *kind; /* fmu_kind of every value reference (with v's block) */
    unsigned *run;      /* run[vr]: the Float64 variables vr, vr + 1, ... in a row, the
                           independent one left out (the bulk get; with v's block) */
    unsigned *out_run;  /* out_run[vr]: the same for Float64 outputs only (with v's block) */
    int *ind, *ind_new; /* the model's indicators at the solver's step; scratch (v's block) */
    uint64_t nevents;   /* steps at which an indicator changed (dmi_fmu_point) */
    uint64_t event_p;   /* the last of them, 0 if none */
    int event;          /* an indicator changed in the last doStep */
    unsigned nvr;       /* the number of value references */
    int out_valid;      /* out holds the outputs at t_comm */
} fmu_model;

/* fmu_kind(vr) from m's copy (no string compared). */
unsigned fmu_model_kind(const fmu_model *m, unsigned vr);

/* Allocates the values with their start values (no solver): 0, or -1 when
 * out of memory. */
int fmu_model_new(fmu_model *m);
/* Back to the start values, no solver (m keeps its block). */
void fmu_model_defaults(fmu_model *m);
/* Frees the solver and the block. */
void fmu_model_free(fmu_model *m);

/* Checks value for variable vr (of type type, FMU_FLOAT64, ...): a parameter
 * or input of that type, finite, tau > 0, N >= 1, then the model's accept.
 * 0, or -1 with the reason in err. */
int fmu_model_check(const fmu_model *m, unsigned vr, unsigned type, double value, char *err);
/* Stores a checked value. */
void fmu_model_store(fmu_model *m, unsigned vr, double value);
/* Reads variable vr of type type: values set from m->v, outputs from the
 * model's outputs at t_comm, the independent variable t_comm.  0, or -1 with
 * the reason in err. */
int fmu_model_get(fmu_model *m, unsigned vr, unsigned type, double *value, char *err);

/* The experiment's start time t_start, the FMU's time (no solver yet). */
void fmu_model_set_start(fmu_model *m, double t_start);

/* fmu_model_get of nvr Float64 variables vr[i] into values[i] (type has
 * FMU_FLOAT64): one call for an FMI get of Float64 values.  A run of
 * consecutive value references of Float64 parameters, inputs and outputs
 * (the common case: all outputs) is copied without a check per value; any
 * other array goes value by value (the same values and messages). */
int fmu_model_get_reals(fmu_model *m, const unsigned vr[], size_t nvr, unsigned type,
                        double *values, char *err);

/* The model's check at ExitInitializationMode for an experiment of length T
 * (DMI_FMU_MODEL.check, 0 without one). */
int fmu_model_check_start(const fmu_model *m, double T, char *msg);
/* Creates and initialises the solver, at t_start.  On failure, err tells why
 * (for memory: N and the bytes needed).  note gets the bytes allocated when
 * more than FMU_NOTE_BYTES, else "". */
int fmu_model_start(fmu_model *m, double t_start, char *err, char *note);

/* Whether to end a communication step early at the event of time t (a
 * solver step t_p = t_start + p h before the step's end): nonzero to stop. */
typedef int fmu_stop_fn(void *ctx, double t);

/* The communication step from t_current (which must be t_comm to within
 * FMU_TIME_TOL h) to t_current + step, step > 0: takes every step whose start
 * t_p is before the end (by more than FMU_TIME_TOL h).  With the model's
 * indicators, one solver step at a time: m->event tells whether an indicator
 * changed (nevents and event_p count them); at such a step t_p before the
 * step's last, stop(ctx, t_p) (when stop is not NULL) may end the
 * communication step there: t_comm = t_p (start + p h) and *early = 1.  -1
 * for bad arguments (m unchanged), -2 for a solver failure (the steps taken
 * are kept). */
int fmu_model_do_step(fmu_model *m, double t_current, double step, fmu_stop_fn *stop,
                      void *ctx, int *early, char *err);

/*
 * Saved state, native endian, at these byte offsets: a magic, the format
 * version, the caller's 32-bit tag (the FMI phase), the total size, the
 * number of Float64 values set (nreal), the size of libdmi's state (0: no
 * solver); format 3: the model's hash (the FNV-1a 64 of its variable table,
 * n and GUID: fmu_model_hash), the events (nevents and event_p, uint64) and
 * the model's name (FMU_STATE_NAMELEN bytes, NUL-padded, cut to fit); then
 * one int64 per Int32 or Boolean parameter or input in the order of the
 * value references, the Float64 parameters and inputs (in that order),
 * t_start, t_comm, libdmi's own checked state bytes (the whole history) and
 * the FNV-1a 64 (src/bytes.h) of all bytes before it.  States are saved in
 * format 3; format 2 (the FMUs of libdmi 1.1, without identity and events:
 * the oscillator FMU's layout, with its one integer parameter N) still
 * restores, and so does format 1 (the FMU of libdmi 1.0: format 2's layout,
 * holding libdmi's state of format 1, without the recursion's sums, which
 * libdmi rebuilds from the stored states).  A state of format 3 of another
 * model (name or hash) is refused with both models' names.
 */
#define FMU_STATE_MAGIC "dmiFMUst"
enum {
    FMU_STATE_VERSION = 3,
    FMU_STATE_AT_VERSION = 8,
    FMU_STATE_AT_TAG = 12,
    FMU_STATE_AT_TOTAL = 16,
    FMU_STATE_AT_NREAL = 24,
    FMU_STATE_AT_NDMI = 32,
    FMU_STATE_AT_INT_V2 = 40, /* format 2: the values */
    FMU_STATE_AT_HASH = 40,   /* format 3: uint64 */
    FMU_STATE_AT_NEVENTS = 48, /* format 3: uint64 */
    FMU_STATE_AT_EVENT_P = 56, /* format 3: uint64 */
    FMU_STATE_AT_NAME = 64,   /* format 3: the name */
    FMU_STATE_NAMELEN = 64,
    FMU_STATE_AT_INT = FMU_STATE_AT_NAME + FMU_STATE_NAMELEN /* format 3: the values */
};
/* The model's hash: FNV-1a 64 of its variable table (every column), n, and
 * the GUID. */
uint64_t fmu_model_hash(void);
size_t fmu_model_state_size(const fmu_model *m);
void fmu_model_state_save(const fmu_model *m, uint32_t tag, unsigned char *buf);
/* Checks the bytes and, when into is not NULL, replaces *into by the saved
 * model (new values and a fresh solver loaded with the saved history).
 * *tag gets the saved tag, a single bit of tags; the state holds libdmi's
 * bytes if and only if that bit is in solver_tags.  The memory allocated is
 * bounded by a multiple of size (the history's size is checked against n and
 * N before the solver is created); the saved t_comm is not beyond the saved
 * solver's t_p.  Bad bytes: nonzero, the reason in err, *into unchanged. */
int fmu_model_state_load(fmu_model *into, uint32_t tags, uint32_t solver_tags, uint32_t *tag,
                         const unsigned char *buf, size_t size, char *err);

#endif
