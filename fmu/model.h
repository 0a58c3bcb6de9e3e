/*
 * The friction oscillator (4.1) of the paper as an FMU model:
 *
 *   w'' + b w + int_0^tau H(s) w(t - s) ds + alpha sigma(w') + g(t) ∋ 0,
 *   (w, w') = (w0, v0) on [-tau, 0],
 *
 * in the first-order form (4.3), u = (w, v): f(t, u) = (-v, b w + g(t)),
 * A = {0} x alpha sigma, kernel [[0, 0], [H, 0]], computed by libdmi.
 *   H(s) = H_c0 + H_c1 exp(-H_lambda s) + sum_{k=1..3} H_a{k} cos(H_omega{k} s),
 *   g(t) = g_offset + g_amp cos(g_omega t + g_phase) + g_in(t).
 *
 * This file is the model's side of the FMU: its variables (value references,
 * start values, checks), its time stepping on the grid t_p = t_start + p h
 * and its saved state.  instance.c, the FMI side common to FMI 2.0 and 3.0,
 * checks the calling sequence and does the logging; fmi2Functions.c and
 * fmi3Functions.c adapt it to each standard.  Neither knows about the
 * oscillator.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_FMU_MODEL_H
#define DMI_FMU_MODEL_H

#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "dmi.h"

/* Value references (the numbers in both model descriptions): VR_<name>, in
 * the order of config.h.  The Real variables that are set (parameters and
 * g_in) come first, then the outputs, N, sticking. */
#define MODEL_VR(name, kind, ...) VR_##name,
enum { MODEL_VARIABLES(MODEL_VR, MODEL_VR) MODEL_NVARS };
#undef MODEL_VR
#define MODEL_NREAL (VR_g_in + 1) /* Real variables that are set: parameters and g_in */

/* Interpolation and communication points: times closer than this fraction
 * of h are the same time. */
#define MODEL_TIME_TOL 1e-6

typedef struct {
    double real[MODEL_NREAL]; /* by value reference: parameters, g_in */
    int N;                    /* steps per tau */
    double t_start;           /* start time of the experiment: t_p = t_start + p h */
    double t_comm;            /* the last communication point (t_start before any step) */
    dmi_solver *solver;       /* NULL until model_start */
} model;

/* Longest message written into the err buffers below. */
#define MODEL_ERRLEN 256

/* Start values (Example 4.3), no solver. */
void model_defaults(model *m);
/* Frees the solver; m can be reused after model_defaults. */
void model_free(model *m);

/* Whether vr is a parameter (set only before the experiment starts), the
 * input g_in, or an output. */
int model_is_parameter(unsigned vr);

/* Sets one variable after checking it (finite, tau > 0, alpha >= 0, N >= 1);
 * a rejected value leaves m unchanged and writes the reason to err.
 * 0 on success. */
int model_set_real(model *m, unsigned vr, double value, char *err);
int model_set_integer(model *m, unsigned vr, int value, char *err);
/* Reads one variable; outputs come from the solver (before model_start:
 * w0, v0, friction = delay_force = 0, sticking = (v0 == 0)). */
int model_get_real(const model *m, unsigned vr, double *value, char *err);
int model_get_integer(const model *m, unsigned vr, int *value, char *err);
int model_get_boolean(const model *m, unsigned vr, int *value, char *err);

/* The length of the default experiment (both model descriptions' stopTime). */
#define MODEL_DEFAULT_T 30.0

/* Creates and initialises the solver from the parameters, at t_start.  On
 * failure, err tells why (for memory: N and the bytes needed).  note gets a
 * message with N and the bytes (allocated while initialising, kept after:
 * from libdmi's layout, in model.c) when the solver allocates more than
 * MODEL_NOTE_BYTES, else "". */
#define MODEL_NOTE_BYTES 100e6
int model_start(model *m, double t_start, char *err, char *note);

/* Whether the step h = tau/N is coarse for an experiment of length T: the
 * explicit part of the scheme amplifies an undamped oscillation by about
 * (1 + h^2 b) per step (b > 0), so by (1 + h^2 b)^(T/h) ~ exp(b h T) over the
 * run; coarse when that exceeds MODEL_COARSE_GROWTH.  1 with the reason in
 * msg, 0 if not. */
#define MODEL_COARSE_GROWTH 2.0
int model_coarse_step(const model *m, double T, char *msg);

/* The communication step from t_current (which must be t_comm to within
 * MODEL_TIME_TOL h) to t_end = t_current + step, step > 0: takes every step
 * whose start t_p is before t_end (by more than MODEL_TIME_TOL h).
 * Returns -1 for bad arguments (m unchanged), -2 for a solver failure (the
 * steps already taken are kept); err tells why. */
int model_do_step(model *m, double t_current, double step, char *err);

/*
 * Saved state: the bytes hold a magic, a format version, the sizes, the
 * variables, t_start, t_comm, an opaque 32-bit tag of the caller (the FMI
 * phase), libdmi's own checked state bytes (the whole history) and a
 * checksum.  model_state_size is the byte count model_state_save writes.
 * Native endian, at these byte offsets (the tests read them from here too);
 * the last 8 bytes are the FNV-1a 64 (src/bytes.h) of all bytes before them.
 */
#define MODEL_STATE_MAGIC "dmiFMUst" /* its 8 bytes, without the NUL */
enum {
    MODEL_STATE_VERSION = 2, /* 1: FMUs of libdmi 1.0 (their libdmi state has format 1) */
    MODEL_STATE_AT_VERSION = 8, /* uint32 */
    MODEL_STATE_AT_TAG = 12,    /* uint32: the caller's tag */
    MODEL_STATE_AT_TOTAL = 16,  /* uint64: bytes of the whole state */
    MODEL_STATE_AT_NREAL = 24,  /* uint64: MODEL_NREAL */
    MODEL_STATE_AT_NDMI = 32,   /* uint64: bytes of libdmi's state (0: no solver) */
    MODEL_STATE_AT_N = 40,      /* int64 */
    MODEL_STATE_AT_REAL = 48,   /* MODEL_NREAL doubles, by value reference; t_start, t_comm */
    MODEL_STATE_AT_DMI = MODEL_STATE_AT_REAL + 8 * (MODEL_NREAL + 2) /* libdmi's state */
};
size_t model_state_size(const model *m);
void model_state_save(const model *m, uint32_t tag, unsigned char *buf);
/* Checks the bytes and, when into is not NULL, replaces *into by the saved
 * model (a fresh solver loaded with the saved history).  *tag gets the saved
 * tag, which must be a single bit of tags; the state holds libdmi's bytes if
 * and only if that bit is in solver_tags (the phases that have a solver).
 * The memory allocated is bounded by a multiple of size: the history's size
 * is checked against N before the solver is created.  The saved t_comm must
 * not be beyond the saved solver's t_p (t_start if there is no solver), so
 * that the next step's work is bounded by its own length.  Bad bytes:
 * nonzero, the reason in err, *into unchanged. */
int model_state_load(model *into, uint32_t tags, uint32_t solver_tags, uint32_t *tag,
                     const unsigned char *buf, size_t size, char *err);

#endif
