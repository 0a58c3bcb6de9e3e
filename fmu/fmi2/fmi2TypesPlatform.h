/*
 * FMI 2.0 platform types, written from the interface documented in the
 * "Functional Mock-up Interface for Model Exchange and Co-Simulation 2.0"
 * standard (section 2.1.2, "default" platform).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef fmi2TypesPlatform_h
#define fmi2TypesPlatform_h

#define fmi2TypesPlatform "default"

typedef void *fmi2Component;            /* an instance of the FMU */
typedef void *fmi2ComponentEnvironment; /* the importer's pointer, passed back to callbacks */
typedef void *fmi2FMUstate;             /* a saved internal state of an instance */
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;

#define fmi2True 1
#define fmi2False 0

#endif
