/*
 * The FMU's variables, defined once.  MODEL_VARIABLES(X, Y) calls
 *
 *   X(name, kind, start, description)   a variable with a start value
 *   Y(name, kind, description)          an output (calculated, no start)
 *
 * for every variable in the order of their value references 0, 1, ...:
 * kind is one of the MODEL_* kinds below, start the start value as written
 * in both model descriptions.
 * This one list gives the value references (model.h), the start values and
 * names (model.c), both model descriptions (modelDescription.c, run at build
 * time) and, through the model descriptions, the tests' variable lists.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_FMU_CONFIG_H
#define DMI_FMU_CONFIG_H

#define MODEL_NAME "DelayFrictionOscillator"
/* The GUID (FMI 2.0) and instantiationToken (FMI 3.0); fmu/CMakeLists.txt
 * reads it from here for the model descriptions and the tests. */
#define DMI_FMU_GUID "{5f0c3a8e-6d2b-4c71-9e15-a3d4b7c80e42}"

/* Kinds: type, causality and variability. */
#define MODEL_REAL_PARAMETER 0 /* Real (Float64), parameter, fixed */
#define MODEL_REAL_INPUT 1     /* Real (Float64), input, continuous */
#define MODEL_REAL_OUTPUT 2    /* Real (Float64), output, continuous */
#define MODEL_INT_PARAMETER 3  /* Integer (Int32), parameter, fixed */
#define MODEL_BOOL_OUTPUT 4    /* Boolean, output, discrete */
#define MODEL_TIME 5           /* Float64, independent: FMI 3.0 only (FMI 2.0 has none) */

/* The coarse-step criterion of the N description: model_coarse_step (model.h). */
#define MODEL_VARIABLES(X, Y)                                                                      \
    X(b, MODEL_REAL_PARAMETER, 1.0, "stiffness coefficient b in b w")                              \
    X(alpha, MODEL_REAL_PARAMETER, 1.0, "dry friction coefficient alpha (>= 0)")                   \
    X(tau, MODEL_REAL_PARAMETER, 1.0, "delay tau of the convolution (> 0)")                        \
    X(w0, MODEL_REAL_PARAMETER, 0.0, "history w on [-tau, 0]")                                     \
    X(v0, MODEL_REAL_PARAMETER, 0.0, "history w' on [-tau, 0]")                                    \
    X(H_c0, MODEL_REAL_PARAMETER, 0.0, "kernel: constant term")                                    \
    X(H_c1, MODEL_REAL_PARAMETER, 0.0, "kernel: coefficient of exp(-H_lambda s)")                  \
    X(H_lambda, MODEL_REAL_PARAMETER, 0.0, "kernel: decay rate")                                   \
    X(H_a1, MODEL_REAL_PARAMETER, 1.0, "kernel: amplitude of cos(H_omega1 s)")                     \
    X(H_omega1, MODEL_REAL_PARAMETER, 6.283185307179586, "kernel: angular frequency 1")            \
    X(H_a2, MODEL_REAL_PARAMETER, 1.0, "kernel: amplitude of cos(H_omega2 s)")                     \
    X(H_omega2, MODEL_REAL_PARAMETER, 31.41592653589793, "kernel: angular frequency 2")            \
    X(H_a3, MODEL_REAL_PARAMETER, 1.0, "kernel: amplitude of cos(H_omega3 s)")                     \
    X(H_omega3, MODEL_REAL_PARAMETER, 62.83185307179586, "kernel: angular frequency 3")            \
    X(g_offset, MODEL_REAL_PARAMETER, 0.0, "forcing: constant term")                               \
    X(g_amp, MODEL_REAL_PARAMETER, 1.3, "forcing: amplitude of cos(g_omega t + g_phase)")          \
    X(g_omega, MODEL_REAL_PARAMETER, 8.0, "forcing: angular frequency")                            \
    X(g_phase, MODEL_REAL_PARAMETER, 0.0, "forcing: phase")                                        \
    X(g_in, MODEL_REAL_INPUT, 0.0,                                                                 \
      "forcing input added to g(t); step p uses the value set at or before t_p")                   \
    Y(w, MODEL_REAL_OUTPUT, "displacement w: the scheme's piecewise-linear interpolant")           \
    Y(v, MODEL_REAL_OUTPUT, "velocity w': the scheme's piecewise-linear interpolant")              \
    Y(friction, MODEL_REAL_OUTPUT,                                                                 \
      "the element r of alpha sigma(v) selected by the step containing t, in [-alpha, alpha]")     \
    Y(delay_force, MODEL_REAL_OUTPUT, "the delay term W of the step containing t")                 \
    X(N, MODEL_INT_PARAMETER, 1000,                                                                \
      "steps per tau (h = tau / N); the solver takes about 40 N bytes (N = 10^8: 4 GB).  "         \
      "ExitInitializationMode warns (status Warning) when the step is coarse: the explicit part "  \
      "of the scheme amplifies an undamped oscillation by about (1 + h^2 b) per step (b > 0), "    \
      "so warning when (1 + h^2 b)^(T/h) > 2, T the experiment's length (stop - start time, 30 "   \
      "if not given), about N < tau b T / ln 2 (N < 44 for the default experiment)")               \
    Y(sticking, MODEL_BOOL_OUTPUT, "v = 0 at the end of the step containing t")                    \
    Y(time, MODEL_TIME, "the simulation time, the last communication point")

/* The log categories of both model descriptions: C(name, description), in
 * the order of instance.c's CAT_* numbers. */
#define MODEL_LOG_CATEGORIES(C)                                                                    \
    C(logStatusError, "the reason of every error (always sent)")                                   \
    C(logStatusWarning, "every warning, e.g. a coarse step (always sent)")                         \
    C(logCalls, "each FMI call with its outcome, when debug logging is on")                        \
    C(logMemory, "what initialization allocates when it is more than 100 MB (always sent)")

#endif
