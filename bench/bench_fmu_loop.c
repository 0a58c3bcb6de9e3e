/*
 * Benchmark of the FMU without Python (not a test): a C master loads the
 * FMU's binary (tests/fmu/fmu_loader, dlopen) and calls fmi2DoStep (or
 * fmi3DoStep) with communication step 0.01 on Example 4.3 (the FMU's
 * defaults: the kernel as three exponential terms, so the recursion) at
 * N = 10^3, 10^4, 10^5, 10^6, against libdmi's own loop on the very solver
 * the FMU's model builds: the model's configure (fmu/model.c, linked in)
 * on the same parameter values, dmi_init, then dmi_advance over the solver
 * steps of each communication step, exactly the steps the FMU takes.  Each
 * round runs every N once, the FMU and the library one after the other (the
 * order alternating between rounds), so machine load hits them alike; the
 * fastest round counts for each.  Times are CPU times of the process (the
 * machine may be shared); the initialization is not timed.  With returns =
 * early (an FMI 3.0 binary) the FMU is instantiated with earlyReturnAllowed: each
 * fmi3DoStep ends at the first stick-slip transition and the master goes on
 * from there (the event detection's cost).  Prints the time per doStep, per
 * solver step of the FMU and of the library, and their ratio; and the
 * library's loop counting the model's built-in indicators as the FMU does
 * (dmi_advance_watch) over the plain loop: what counting the events costs.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dmi_fmu.h"
#include "fmi3FunctionTypes.h"
#include "fmu_loader.h"
#include "model.h"  /* VR_N, VR_tau */
#include "core.h" /* libdmi's core: dmi_advance_watch, the FMU's count of its indicators */

#ifndef DMI_FMU_BINARY
#define DMI_FMU_BINARY "DelayFrictionOscillator.so"
#endif

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    (void)env;
    (void)category;
    fprintf(stderr, "bench_fmu_loop: %s: status %d: %s\n", name, (int)status, message);
}

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                    fmi3String message)
{
    (void)env;
    fprintf(stderr, "bench_fmu_loop: status %d (%s): %s\n", (int)status, category, message);
}

/* The solver steps p of the FMU after the communication step ending at t:
 * every step whose start is before t by more than 1e-6 h (framework.c). */
static uint64_t steps_before(double t, double h)
{
    return (uint64_t)ceil(t / h - 1e-6);
}

/* CPU seconds of the doStep loop from 0 to T of a new instance at N, with
 * tau (the FMU's) in *tau; a negative value if a call failed. */
static double fmu_run(const fmu_api *f, int N, double T, double dt, double *tau)
{
    const fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = f->instantiate("bench", fmi2CoSimulation, DMI_FMU_GUID, "", &cb, fmi2False,
                                     fmi2False);
    if (!c)
        return -1;
    const fmi2ValueReference vr_N = VR_N, vr_tau = VR_tau;
    const fmi2Integer n = N;
    double secs = -1;
    if (f->setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK &&
        f->enter_init(c) == fmi2OK && f->set_integer(c, &vr_N, 1, &n) == fmi2OK &&
        f->exit_init(c) == fmi2OK && f->get_real(c, &vr_tau, 1, tau) == fmi2OK) {
        const long steps = lround(T / dt);
        double t0 = cpu_now();
        long k = 0;
        while (k < steps && f->do_step(c, (double)k * dt, dt, fmi2True) == fmi2OK)
            k++;
        secs = k == steps ? cpu_now() - t0 : -1;
    }
    f->terminate(c);
    f->free_instance(c);
    return secs;
}

/* fmu_run of an FMI 3.0 binary instantiated with earlyReturnAllowed: a
 * doStep that returns early is followed by one from its lastSuccessfulTime
 * to the same end.  *early gets the early returns. */
static double fmu3_early_run(void *lib, int N, double T, double dt, double *tau, long *early)
{
    fmi3InstantiateCoSimulationTYPE *inst;
    fmi3EnterInitializationModeTYPE *enter;
    fmi3ExitInitializationModeTYPE *exit_init;
    fmi3SetInt32TYPE *set_int32;
    fmi3GetFloat64TYPE *get_float64;
    fmi3DoStepTYPE *do_step;
    fmi3TerminateTYPE *terminate;
    fmi3FreeInstanceTYPE *free_instance;
    /* function pointers from dlsym's void * (POSIX guarantees the conversion) */
    *(void **)&inst = dlsym(lib, "fmi3InstantiateCoSimulation");
    *(void **)&enter = dlsym(lib, "fmi3EnterInitializationMode");
    *(void **)&exit_init = dlsym(lib, "fmi3ExitInitializationMode");
    *(void **)&set_int32 = dlsym(lib, "fmi3SetInt32");
    *(void **)&get_float64 = dlsym(lib, "fmi3GetFloat64");
    *(void **)&do_step = dlsym(lib, "fmi3DoStep");
    *(void **)&terminate = dlsym(lib, "fmi3Terminate");
    *(void **)&free_instance = dlsym(lib, "fmi3FreeInstance");
    if (!inst || !enter || !exit_init || !set_int32 || !get_float64 || !do_step || !terminate ||
        !free_instance)
        return -1;
    fmi3Instance c = inst("bench", DMI_FMU_GUID, NULL, fmi3False, fmi3False, fmi3False, fmi3True,
                          NULL, 0, NULL, logger3, NULL);
    if (!c)
        return -1;
    const fmi3ValueReference vr_N = VR_N, vr_tau = VR_tau;
    const fmi3Int32 n = N;
    double secs = -1;
    *early = 0;
    if (enter(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) == fmi3OK &&
        set_int32(c, &vr_N, 1, &n, 1) == fmi3OK && exit_init(c) == fmi3OK &&
        get_float64(c, &vr_tau, 1, tau, 1) == fmi3OK) {
        const long steps = lround(T / dt);
        double t0 = cpu_now(), t = 0.0;
        long k = 0;
        while (k < steps) {
            fmi3Boolean handling, stop, back;
            double last = 0, next = (double)(k + 1) * dt;
            if (do_step(c, t, next - t, fmi3True, &handling, &stop, &back, &last) != fmi3OK)
                break;
            *early += back != fmi3False;
            t = back ? last : next;
            k += !back;
        }
        secs = k == steps ? cpu_now() - t0 : -1;
    }
    terminate(c);
    free_instance(c);
    return secs;
}

/* CPU seconds of libdmi's loop on the solver the FMU's model configures
 * (its start values, N), stepping the FMU's solver steps of each
 * communication step with dmi_advance, or with watch, with libdmi's count
 * of the model's built-in indicators (dmi_advance_watch, as the FMU does
 * without early return); negative if a call failed. */
static double library_run(int N, double T, double dt, int watch)
{
    const dmi_fmu_model *model = &DMI_FMU_MODEL;
    double value[64];
    if (model->nvariables > 64)
        return -1;
    for (size_t vr = 0; vr < model->nvariables; vr++)
        value[vr] = model->variables[vr].start;
    value[VR_N] = N;
    const dmi_fmu_values v = {0.0, value};
    dmi_solver *s = NULL;
    char err[DMI_FMU_ERRLEN] = "";
    double secs = -1;
    int held[8];
    dmi_watch w = {model->nindicators, model->held, held, 0, 0};
    if (dmi_create(&s, model->n, value[VR_tau], (size_t)N) == DMI_OK &&
        model->configure(&v, s, err) == 0 && dmi_init(s) == DMI_OK && w.m <= 8 &&
        (!watch || dmi_watch_start(s, &w) == DMI_OK)) {
        const long steps = lround(T / dt);
        const double h = dmi_get_h(s);
        uint64_t p = 0;
        double t0 = cpu_now();
        long k = 0;
        for (; k < steps; k++) {
            const uint64_t target = steps_before((double)(k + 1) * dt, h);
            size_t taken;
            if ((watch ? dmi_advance_watch(s, (size_t)(target - p), &w, 0, &taken)
                       : dmi_advance(s, (size_t)(target - p))) != DMI_OK)
                break;
            p = target;
        }
        secs = k == steps ? cpu_now() - t0 : -1;
    }
    dmi_free(&s);
    return secs;
}

int main(int argc, char **argv)
{
    double T = 10;
    size_t rounds = 3;
    const char *binary = DMI_FMU_BINARY, *returns_arg = "off";
    const cli_arg args[] = {
        {"T", CLI_TIME, &T, 1000, "model time of each run, seconds (communication step 0.01)"},
        {"rounds", CLI_COUNT, &rounds, 100, "rounds over every N; the fastest counts for each N"},
        {"binary", CLI_PATH, &binary, 0,
         "the FMU's binary (.so of an unpacked FMU, FMI 2.0 or 3.0; the default is the build's)"},
        {"returns", CLI_PATH, &returns_arg, 0,
         "early: an FMI 3.0 binary instantiated with earlyReturnAllowed (fmi3DoStep returns at "
         "every stick-slip transition); off: no early return"}};
    const cli_program prog = {
        "bench_fmu_loop",
        "Times the FMU's doStep loop from C (no Python) against libdmi's dmi_advance on the\n"
        "solver the FMU's model builds: Example 4.3, communication step 0.01, N = 1e3 .. 1e6.",
        "stdout: a table of us per doStep, ns per solver step of the FMU and of the library,\n"
        "and their ratio (tens of seconds with the defaults).\n"
        "exit status: 0, 1 if the binary does not load or a call fails, 2 for a bad argument.",
        args, 4};
    cli_parse(&prog, argc, argv);
    const double dt = 0.01;
    if (lround(T / dt) < 1)
        cli_reject(&prog, "T", argv[1], "gives no communication step");

    FILE *fp = fopen(binary, "rb");
    if (!fp)
        cli_reject(&prog, "binary", binary, "cannot be opened (build the project first)");
    fclose(fp);
    fmu_api f;
    if (fmu_load(&f, binary) != 0)
        return 1;
    const int early = strcmp(returns_arg, "early") == 0;
    if (!early && strcmp(returns_arg, "off") != 0) {
        fmu_unload(&f);
        cli_reject(&prog, "returns", returns_arg, "must be early or off");
    }
    if (early && f.version != 3) {
        fmu_unload(&f);
        cli_reject(&prog, "returns", returns_arg, "needs an FMI 3.0 binary");
    }
    enum { NN = 4 };
    const int Ns[NN] = {1000, 10000, 100000, 1000000};
    double best[NN], lib[NN], watched[NN], tau = 0;
    long returns[NN] = {0};
    for (int i = 0; i < NN; i++)
        best[i] = lib[i] = watched[i] = INFINITY;
    for (size_t r = 0; r < rounds; r++)
        for (int i = 0; i < NN; i++) {
            double s = -1, l = -1, w = -1;
            for (int j = 0; j < 3; j++) { /* the order rotates between rounds */
                const int which = (j + (int)r) % 3;
                if (which == 0)
                    s = early ? fmu3_early_run(f.lib, Ns[i], T, dt, &tau, &returns[i])
                              : fmu_run(&f, Ns[i], T, dt, &tau);
                else
                    *(which == 1 ? &l : &w) = library_run(Ns[i], T, dt, which == 2);
            }
            if (s < 0 || l < 0 || w < 0) {
                fprintf(stderr, "bench_fmu_loop: N = %d: a call to the %s failed\n", Ns[i],
                        s < 0 ? "FMU" : "library");
                fmu_unload(&f);
                return 1;
            }
            best[i] = fmin(best[i], s);
            lib[i] = fmin(lib[i], l);
            watched[i] = fmin(watched[i], w);
        }
    const int version = f.version;
    fmu_unload(&f);

    const double comm = (double)lround(T / dt);
    printf("C loop over fmi%dDoStep%s, communication step %g, T = %g per run, tau = %g, best of "
           "%zu interleaved rounds (CPU time); libdmi: dmi_advance on the model's solver\n",
           version, early ? " with early return" : "", dt, T, tau, rounds);
    printf("%8s | %13s | %11s | %14s | %12s | %15s%s\n", "N", "us per doStep", "FMU ns/step",
           "libdmi ns/step", "FMU / libdmi", "counted / libdmi", early ? " | early returns" : "");
    for (int i = 0; i < NN; i++) {
        const double steps = comm * dt * Ns[i] / tau;
        printf("%8d | %13.2f | %11.1f | %14.1f | %11.3fx | %15.3fx", Ns[i], 1e6 * best[i] / comm,
               1e9 * best[i] / steps, 1e9 * lib[i] / steps, best[i] / lib[i], watched[i] / lib[i]);
        if (early)
            printf(" | %14ld", returns[i]);
        printf("\n");
    }
    return 0;
}
