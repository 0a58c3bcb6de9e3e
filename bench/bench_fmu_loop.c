/*
 * Benchmark of the FMU without Python (issue 13; not a test): a C master
 * loads the FMU's binary (tests/fmu/fmu_loader, dlopen) and calls fmi2DoStep
 * (or fmi3DoStep) with communication step 0.01 on Example 4.3 (the FMU's
 * defaults: the kernel as three exponential terms, so the recursion) at
 * N = 10^3, 10^4, 10^5, 10^6.  Each round runs every N once, one after the
 * other, so machine load hits them alike; the fastest round counts for each N.
 * Times are CPU times of the process (the machine may be shared); the
 * initialization is not timed.  Prints the time per doStep and per solver
 * step h = tau/N, and each N's time per solver step over N = 10^3's.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "fmu_loader.h"
#include "model.h" /* VR_N, VR_tau */

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

/* CPU seconds of the doStep loop from 0 to T of a new instance at N, with
 * tau (the FMU's) in *tau; a negative value if a call failed. */
static double one_run(const fmu_api *f, int N, double T, double dt, double *tau)
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

int main(int argc, char **argv)
{
    double T = 10;
    size_t rounds = 3;
    const char *binary = DMI_FMU_BINARY;
    const cli_arg args[] = {
        {"T", CLI_TIME, &T, 1000, "model time of each run, seconds (communication step 0.01)"},
        {"rounds", CLI_COUNT, &rounds, 100, "rounds over every N; the fastest counts for each N"},
        {"binary", CLI_PATH, &binary, 0,
         "the FMU's binary (.so of an unpacked FMU, FMI 2.0 or 3.0; the default is the build's)"}};
    const cli_program prog = {
        "bench_fmu_loop",
        "Times the FMU's doStep loop from C (no Python): Example 4.3, communication step\n"
        "0.01, at N = 1e3 .. 1e6 (tau/N per solver step).",
        "stdout: a table of us per doStep, ns per solver step and the ratio of each N to\n"
        "N = 1e3 per solver step (tens of seconds with the defaults).\n"
        "exit status: 0, 1 if the binary does not load or a call fails, 2 for a bad argument.",
        args, 3};
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
    enum { NN = 4 };
    const int Ns[NN] = {1000, 10000, 100000, 1000000};
    double best[NN], tau = 0;
    for (int i = 0; i < NN; i++)
        best[i] = INFINITY;
    for (size_t r = 0; r < rounds; r++)
        for (int i = 0; i < NN; i++) {
            double s = one_run(&f, Ns[i], T, dt, &tau);
            if (s < 0) {
                fprintf(stderr, "bench_fmu_loop: N = %d: a call to the FMU failed\n", Ns[i]);
                fmu_unload(&f);
                return 1;
            }
            best[i] = fmin(best[i], s);
        }
    const int version = f.version;
    fmu_unload(&f);

    const double comm = (double)lround(T / dt);
    printf("C loop over fmi%dDoStep, communication step %g, T = %g per run, tau = %g, "
           "best of %zu rounds (CPU time)\n", version, dt, T, tau, rounds);
    printf("%8s | %13s | %18s | %17s\n", "N", "us per doStep", "ns per solver step",
           "vs N = 1e3 per step");
    double first = 0;
    for (int i = 0; i < NN; i++) {
        const double per_step = 1e9 * best[i] / (comm * dt * Ns[i] / tau);
        if (i == 0)
            first = per_step;
        printf("%8d | %13.2f | %18.1f | %16.2fx\n", Ns[i], 1e6 * best[i] / comm, per_step,
               per_step / first);
    }
    return 0;
}
