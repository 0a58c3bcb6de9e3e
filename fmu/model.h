/*
 * The friction oscillator (4.1) of the paper as an FMU model (dmi_fmu.h):
 *
 *   w'' + b w + int_0^tau H(s) w(t - s) ds + alpha sigma(w') + g(t) ∋ 0,
 *   (w, w') = (w0, v0) on [-tau, 0],
 *
 * in the first-order form (4.3), u = (w, v): f(t, u) = (-v, b w + g(t)),
 * A = {0} x alpha sigma, kernel [[0, 0], [H, 0]], computed by libdmi.
 *   H(s) = H_c0 + H_c1 exp(-H_lambda s) + sum_{k=1..3} H_a{k} cos(H_omega{k} s),
 *   g(t) = g_offset + g_amp cos(g_omega t + g_phase) + g_in(t).
 *
 * Its variables are config.h's table; model.c configures the solver, computes
 * the outputs and warns of a coarse step.  The FMU framework (fmu/framework.c,
 * instance.c, the FMI adapters) does the rest, as for any model, and
 * CMakeLists.txt builds it with dmi_add_fmu.  This header gives the value
 * references and the saved state's layout for this model, which the tests
 * read (they are checked against the framework's in model.c).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_FMU_MODEL_H
#define DMI_FMU_MODEL_H

#include "config.h"
#include "dmi_fmu.h"

/* Value references (the numbers in both model descriptions): VR_<name>, in
 * the order of config.h.  The Real variables that are set (parameters and
 * g_in) come first, then the outputs, N, sticking, the event outputs, time. */
enum { MODEL_VARIABLES(DMI_FMU_VR) MODEL_NVARS };
#define MODEL_NREAL (VR_g_in + 1) /* Real variables that are set: parameters and g_in */

/* The length of the default experiment (both model descriptions' stopTime). */
#define MODEL_DEFAULT_T 30.0

/*
 * Saved state (the framework's layout, framework.h, for this model's one
 * integer N): the bytes hold a magic, a format version, the sizes, the
 * model's identity (a hash of its variables and GUID, its event counts, its
 * name), the variables, t_start, t_comm, an opaque 32-bit tag of the caller
 * (the FMI phase), libdmi's own checked state bytes (the whole history) and
 * a checksum.  Native endian, at these byte offsets (the tests read them
 * from here too); the last 8 bytes are the FNV-1a 64 (src/bytes.h) of all
 * bytes before them.  Format 2 (the FMUs of libdmi 1.1) had no identity: N
 * at 40, the Reals at 48.
 */
#define MODEL_STATE_MAGIC "dmiFMUst" /* its 8 bytes, without the NUL */
enum {
    MODEL_STATE_VERSION = 3, /* 1: FMUs of libdmi 1.0 (their libdmi state has format 1); 2: 1.1 */
    MODEL_STATE_AT_VERSION = 8, /* uint32 */
    MODEL_STATE_AT_TAG = 12,    /* uint32: the caller's tag */
    MODEL_STATE_AT_TOTAL = 16,  /* uint64: bytes of the whole state */
    MODEL_STATE_AT_NREAL = 24,  /* uint64: MODEL_NREAL */
    MODEL_STATE_AT_NDMI = 32,   /* uint64: bytes of libdmi's state (0: no solver) */
    MODEL_STATE_AT_HASH = 40,   /* uint64: the model's hash (variables, n, GUID) */
    MODEL_STATE_AT_NEVENTS = 48, /* uint64: stick_slip_events */
    MODEL_STATE_AT_EVENT_P = 56, /* uint64: the step of the last event */
    MODEL_STATE_AT_NAME = 64,   /* 64 bytes: the model's name, NUL-padded */
    MODEL_STATE_AT_N = 128,     /* int64 */
    MODEL_STATE_AT_REAL = 136,  /* MODEL_NREAL doubles, by value reference; t_start, t_comm */
    MODEL_STATE_AT_DMI = MODEL_STATE_AT_REAL + 8 * (MODEL_NREAL + 2) /* libdmi's state */
};

#endif
