/*
 * The loader of fmu_loader.h: dlopen/dlsym on POSIX, LoadLibrary/GetProcAddress
 * under _WIN32 (the C master built for Windows runs under Wine).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#else
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#endif
#include "fmu_loader.h"
#include "fmu_fmi3.h"

#include <stdio.h>
#include <string.h>

/* The platform's library calls.  lib_open prints the reason of a failure;
 * lib_sym gives the address of a function as an object pointer, or NULL. */
#ifdef _WIN32
static void *lib_open(const char *path)
{
    HMODULE lib = LoadLibraryA(path);
    if (!lib)
        fprintf(stderr, "fmu_load: LoadLibrary(%s) failed, error %lu\n", path,
                (unsigned long)GetLastError());
    return (void *)lib;
}

static void *lib_sym(void *lib, const char *name)
{
    FARPROC fn = GetProcAddress((HMODULE)lib, name);
    void *p;
    memcpy(&p, &fn, sizeof p); /* the same size on Windows, as on POSIX */
    return p;
}

static void lib_close(void *lib)
{
    FreeLibrary((HMODULE)lib);
}
#else
static void *lib_open(const char *path)
{
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib)
        fprintf(stderr, "fmu_load: %s\n", dlerror());
    return lib;
}

static void *lib_sym(void *lib, const char *name)
{
    return dlsym(lib, name);
}

static void lib_close(void *lib)
{
    dlclose(lib);
}
#endif

static void *lookup(void *lib, const char *name)
{
    void *p = lib_sym(lib, name);
    if (!p)
        fprintf(stderr, "fmu_load: %s not exported\n", name);
    return p;
}

int fmu_load(fmu_api *f, const char *so_path)
{
    memset(f, 0, sizeof *f);
    f->lib = lib_open(so_path);
    if (!f->lib)
        return -1;
    f->version = 2;
    if (lib_sym(f->lib, "fmi3InstantiateCoSimulation")) {
        f->version = 3;
        if (fmu_fmi3_attach(f, lookup) != 0) {
            fmu_unload(f);
            return -1;
        }
        return 0;
    }
    int missing = 0;
    /* object pointer to function pointer: the POSIX dlsym idiom */
#define SYM(field, name)                                                                          \
    do {                                                                                          \
        *(void **)(&f->field) = lookup(f->lib, name);                                             \
        if (!f->field)                                                                            \
            missing = 1;                                                                          \
    } while (0)
    SYM(instantiate, "fmi2Instantiate");
    SYM(free_instance, "fmi2FreeInstance");
    SYM(set_debug_logging, "fmi2SetDebugLogging");
    SYM(setup, "fmi2SetupExperiment");
    SYM(enter_init, "fmi2EnterInitializationMode");
    SYM(exit_init, "fmi2ExitInitializationMode");
    SYM(terminate, "fmi2Terminate");
    SYM(reset, "fmi2Reset");
    SYM(get_real, "fmi2GetReal");
    SYM(get_integer, "fmi2GetInteger");
    SYM(get_boolean, "fmi2GetBoolean");
    SYM(get_string, "fmi2GetString");
    SYM(set_real, "fmi2SetReal");
    SYM(set_integer, "fmi2SetInteger");
    SYM(set_boolean, "fmi2SetBoolean");
    SYM(set_string, "fmi2SetString");
    SYM(get_state, "fmi2GetFMUstate");
    SYM(set_state, "fmi2SetFMUstate");
    SYM(free_state, "fmi2FreeFMUstate");
    SYM(state_size, "fmi2SerializedFMUstateSize");
    SYM(serialize, "fmi2SerializeFMUstate");
    SYM(deserialize, "fmi2DeSerializeFMUstate");
    SYM(do_step, "fmi2DoStep");
    SYM(cancel_step, "fmi2CancelStep");
    SYM(get_real_status, "fmi2GetRealStatus");
#undef SYM
    if (missing) {
        fmu_unload(f);
        return -1;
    }
    return 0;
}

void fmu_unload(fmu_api *f)
{
    if (f->lib)
        lib_close(f->lib);
    memset(f, 0, sizeof *f);
}
