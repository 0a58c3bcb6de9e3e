/*
 * The FMI 3.0 FMU behind the FMI 2.0 function types of fmu_loader.h, so that
 * the C importers (fmu_master, the hardening tests, the FMU fuzzer) run the
 * same checks on both FMUs.  Each fmi2-typed function forwards to its FMI 3.0
 * counterpart: Real is Float64, Integer is Int32 (Boolean converted), the
 * FMUstate functions are the FMUState ones, fmi2SetupExperiment keeps the
 * times for fmi3EnterInitializationMode, fmi2Instantiate is
 * fmi3InstantiateCoSimulation (fmi3InstantiateModelExchange for
 * fmi2ModelExchange), and the FMI 3.0 logger calls the FMI 2.0 one.  FMI 2.0
 * functions without a counterpart (fmi2CancelStep, fmi2GetRealStatus) are
 * left NULL.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef FMU_FMI3_H
#define FMU_FMI3_H

#include "fmu_loader.h"

/* Looks the FMI 3.0 functions up in f->lib with lookup and fills f with the
 * forwarding functions; 0 on success, -1 (message on stderr) if one is
 * missing.  The FMI 3.0 functions are kept in this file's one table: one
 * FMI 3.0 library per process. */
int fmu_fmi3_attach(fmu_api *f, void *(*lookup)(void *lib, const char *name));

#endif
