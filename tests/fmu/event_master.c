/*
 * A plain FMI 3.0 co-simulation master with early return: the
 * oscillator FMU (Example 4.3, its default parameters) drives a second FMU,
 * the Burridge-Knopoff chain of examples/fmu-chain, with its friction force
 * (the chain's input F_in = the oscillator's friction).  Communication step
 * dt; the oscillator is instantiated with earlyReturnAllowed, so that each
 * fmi3DoStep ends at the first solver step at which the friction sticks or
 * slips: the master then steps the chain to that time too, and the chain
 * gets the new force at the transition's step rather than at the next
 * communication point.
 *
 * Usage: event_master OSC.so OSC_TOKEN CHAIN.so CHAIN_TOKEN T dt
 * stdout: one line "event <t> <early>" per transition (the FMU's time after
 * the fmi3DoStep that counted it, t_start + p h, and 1 if it returned early
 * there), then "chain x1 <x1> time <t>" and "events <count> early <n>".
 * Exit status 0, 1 if a call fails (the FMU's log on stderr).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "fmi3FunctionTypes.h"
#include "model.h"

/* The chain's value references (examples/fmu-chain/chain.c's table). */
enum { CHAIN_F_IN = 15, CHAIN_X1 = 16 };

typedef struct {
    void *lib;
    fmi3InstantiateCoSimulationTYPE *instantiate;
    fmi3EnterInitializationModeTYPE *enter_init;
    fmi3ExitInitializationModeTYPE *exit_init;
    fmi3GetFloat64TYPE *get_float64;
    fmi3SetFloat64TYPE *set_float64;
    fmi3GetInt32TYPE *get_int32;
    fmi3DoStepTYPE *do_step;
    fmi3TerminateTYPE *terminate;
    fmi3FreeInstanceTYPE *free_instance;
} fmi3_api;

static void *sym(void *lib, const char *name, int *bad)
{
    void *f = dlsym(lib, name);
    if (!f) {
        fprintf(stderr, "event_master: %s not exported\n", name);
        *bad = 1;
    }
    return f;
}

static int load(fmi3_api *f, const char *path)
{
    int bad = 0;
    if (!(f->lib = dlopen(path, RTLD_NOW | RTLD_LOCAL))) {
        fprintf(stderr, "event_master: %s\n", dlerror());
        return -1;
    }
    /* a function pointer from dlsym's void * (POSIX guarantees the conversion) */
#define SYM(field, name) *(void **)&f->field = sym(f->lib, name, &bad)
    SYM(instantiate, "fmi3InstantiateCoSimulation");
    SYM(enter_init, "fmi3EnterInitializationMode");
    SYM(exit_init, "fmi3ExitInitializationMode");
    SYM(get_float64, "fmi3GetFloat64");
    SYM(set_float64, "fmi3SetFloat64");
    SYM(get_int32, "fmi3GetInt32");
    SYM(do_step, "fmi3DoStep");
    SYM(terminate, "fmi3Terminate");
    SYM(free_instance, "fmi3FreeInstance");
#undef SYM
    return bad ? -1 : 0;
}

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                   fmi3String message)
{
    fprintf(stderr, "event_master: %s: status %d (%s): %s\n", (const char *)env, (int)status,
            category, message);
}

static fmi3Instance start(const fmi3_api *f, const char *name, const char *token, int early,
                          double T)
{
    fmi3Instance c = f->instantiate(name, token, NULL, fmi3False, fmi3False, fmi3False,
                                    early ? fmi3True : fmi3False, NULL, 0, (void *)name, logger,
                                    NULL);
    if (!c || f->enter_init(c, fmi3False, 0.0, 0.0, fmi3True, T) != fmi3OK ||
        f->exit_init(c) != fmi3OK)
        return NULL;
    return c;
}

int main(int argc, char **argv)
{
    if (argc != 7) {
        fprintf(stderr, "usage: event_master OSC.so OSC_TOKEN CHAIN.so CHAIN_TOKEN T dt\n");
        return 2;
    }
    const double T = atof(argv[5]), dt = atof(argv[6]);
    fmi3_api osc, chain;
    if (!(T > 0) || !(dt > 0) || load(&osc, argv[1]) != 0 || load(&chain, argv[3]) != 0)
        return 1;
    fmi3Instance a = start(&osc, "oscillator", argv[2], 1, T);
    fmi3Instance b = a ? start(&chain, "chain", argv[4], 0, T) : NULL;
    if (!b)
        return 1;
    const fmi3ValueReference vr_friction = VR_friction, vr_count = VR_stick_slip_events;
    const fmi3ValueReference vr_F = CHAIN_F_IN, vr_x1 = CHAIN_X1;
    double t = 0.0;
    long k = 0, early_returns = 0;
    fmi3Int32 count = 0;
    int ok = 1;
    while (ok && t < T && fabs(T - t) > 1e-9 * dt) {
        /* the chain's force: the oscillator's friction at t */
        double force = 0, x1 = 0, last = 0;
        fmi3Boolean handling, terminate, early;
        const double next = fmin((double)(k + 1) * dt, T);
        ok = osc.get_float64(a, &vr_friction, 1, &force, 1) == fmi3OK &&
             chain.set_float64(b, &vr_F, 1, &force, 1) == fmi3OK &&
             osc.do_step(a, t, next - t, fmi3True, &handling, &terminate, &early, &last) == fmi3OK;
        if (!ok)
            break;
        const double reached = early ? last : next;
        fmi3Int32 now = 0;
        ok = chain.do_step(b, t, reached - t, fmi3True, &handling, &terminate, &early, &last) ==
                 fmi3OK && osc.get_int32(a, &vr_count, 1, &now, 1) == fmi3OK &&
             chain.get_float64(b, &vr_x1, 1, &x1, 1) == fmi3OK;
        if (ok && now != count) {
            const int was_early = reached != next;
            early_returns += was_early;
            printf("event %.17g %d\n", reached, was_early);
            count = now;
        }
        if (reached == next)
            k++;
        t = reached;
        if (ok && !(t < T && fabs(T - t) > 1e-9 * dt))
            printf("chain x1 %.17g time %.17g\n", x1, t);
    }
    printf("events %ld early %ld\n", (long)count, early_returns);
    osc.terminate(a);
    chain.terminate(b);
    osc.free_instance(a);
    chain.free_instance(b);
    return ok ? 0 : 1;
}
