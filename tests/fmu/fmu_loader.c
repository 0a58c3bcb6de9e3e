/*
 * The loader of fmu_loader.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#define _POSIX_C_SOURCE 200809L
#include "fmu_loader.h"
#include "fmu_fmi3.h"

#include <dlfcn.h>
#include <stdio.h>
#include <string.h>

static void *lookup(void *lib, const char *name)
{
    void *p = dlsym(lib, name);
    if (!p)
        fprintf(stderr, "fmu_load: %s not exported\n", name);
    return p;
}

int fmu_load(fmu_api *f, const char *so_path)
{
    memset(f, 0, sizeof *f);
    f->lib = dlopen(so_path, RTLD_NOW | RTLD_LOCAL);
    if (!f->lib) {
        fprintf(stderr, "fmu_load: %s\n", dlerror());
        return -1;
    }
    f->version = 2;
    if (dlsym(f->lib, "fmi3InstantiateCoSimulation")) {
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
        *(void **)(&f->field) = dlsym(f->lib, name);                                              \
        if (!f->field) {                                                                          \
            fprintf(stderr, "fmu_load: %s not exported\n", name);                                 \
            missing = 1;                                                                          \
        }                                                                                         \
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
        dlclose(f->lib);
    memset(f, 0, sizeof *f);
}
