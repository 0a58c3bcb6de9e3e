/*
 * The oscillator FMU's variables, defined once, in the order of their value
 * references 0, 1, ...: MODEL_VARIABLES(X) calls
 *
 *   X(name, type, causality, start, unit, description)
 *
 * for every variable (dmi_fmu.h: DMI_FMU_VARIABLE; an output has no start).
 * This one list gives the value references (model.h), the start values,
 * names and checks (the framework), both model descriptions (written at
 * build time by dmi_add_fmu) and, through the model descriptions, the tests'
 * variable lists.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_FMU_CONFIG_H
#define DMI_FMU_CONFIG_H

/* The GUID (FMI 2.0) and instantiationToken (FMI 3.0); fmu/CMakeLists.txt
 * reads it from here for dmi_add_fmu and the tests. */
#define DMI_FMU_GUID "{5f0c3a8e-6d2b-4c71-9e15-a3d4b7c80e42}"

/* The coarse-step criterion of the N description: check_coarse_step (model.c). */
#define MODEL_VARIABLES(X)                                                                         \
    X(b, Float64, parameter, 1.0, "", "stiffness coefficient b in b w")                            \
    X(alpha, Float64, parameter, 1.0, "", "dry friction coefficient alpha (>= 0)")                 \
    X(tau, Float64, parameter, 1.0, "", "delay tau of the convolution (> 0)")                      \
    X(w0, Float64, parameter, 0.0, "", "history w on [-tau, 0]")                                   \
    X(v0, Float64, parameter, 0.0, "", "history w' on [-tau, 0]")                                  \
    X(H_c0, Float64, parameter, 0.0, "", "kernel: constant term")                                  \
    X(H_c1, Float64, parameter, 0.0, "", "kernel: coefficient of exp(-H_lambda s)")                \
    X(H_lambda, Float64, parameter, 0.0, "", "kernel: decay rate")                                 \
    X(H_a1, Float64, parameter, 1.0, "", "kernel: amplitude of cos(H_omega1 s)")                   \
    X(H_omega1, Float64, parameter, 6.283185307179586, "", "kernel: angular frequency 1")          \
    X(H_a2, Float64, parameter, 1.0, "", "kernel: amplitude of cos(H_omega2 s)")                   \
    X(H_omega2, Float64, parameter, 31.41592653589793, "", "kernel: angular frequency 2")          \
    X(H_a3, Float64, parameter, 1.0, "", "kernel: amplitude of cos(H_omega3 s)")                   \
    X(H_omega3, Float64, parameter, 62.83185307179586, "", "kernel: angular frequency 3")          \
    X(g_offset, Float64, parameter, 0.0, "", "forcing: constant term")                             \
    X(g_amp, Float64, parameter, 1.3, "", "forcing: amplitude of cos(g_omega t + g_phase)")        \
    X(g_omega, Float64, parameter, 8.0, "", "forcing: angular frequency")                          \
    X(g_phase, Float64, parameter, 0.0, "", "forcing: phase")                                      \
    X(g_in, Float64, input, 0.0, "",                                                               \
      "forcing input added to g(t); step p uses the value set at or before t_p")                   \
    X(w, Float64, output, , "", "displacement w: the scheme's piecewise-linear interpolant")       \
    X(v, Float64, output, , "", "velocity w': the scheme's piecewise-linear interpolant")         \
    X(friction, Float64, output, , "",                                                             \
      "the element r of alpha sigma(v) selected by the step containing t, in [-alpha, alpha]")     \
    X(delay_force, Float64, output, , "", "the delay term W of the step containing t")            \
    X(N, Int32, parameter, 1000, "",                                                               \
      "steps per tau (h = tau / N); the solver takes about 32 N bytes (N = 10^8: 3.2 GB).  "       \
      "ExitInitializationMode warns (status Warning) when the step is coarse: the explicit part "  \
      "of the scheme amplifies an undamped oscillation by about (1 + h^2 b) per step (b > 0), "    \
      "so warning when (1 + h^2 b)^(T/h) > 2, T the experiment's length (stop - start time, 30 "   \
      "if not given), about N < tau b T / ln 2 (N < 44 for the default experiment)")               \
    X(sticking, Boolean, output, , "", "v = 0 at the end of the step containing t")               \
    X(stick_slip_events, Int32, output, , "",                                                      \
      "the stick-slip transitions so far: solver steps at which the friction's state (stuck: "    \
      "|X_v| <= h alpha) differs from the step before")                                          \
    X(last_event_time, Float64, output, , "",                                                      \
      "the time t_start + p h of the last stick-slip transition's step p (t_start if none)")      \
    X(time, Float64, independent, , "", "the simulation time, the last communication point")

#endif
