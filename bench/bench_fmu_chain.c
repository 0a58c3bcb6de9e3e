/*
 * Benchmark of FMU export (not a test): the Burridge-Knopoff chain
 * of examples/fmu-chain as its FMU (built in-tree with dmi_add_fmu, loaded
 * with tests/fmu's loader) against the native libdmi loop of the same model
 * (examples/fmu-chain/native.c, the same parameters, libdmi.so).  Each case
 * runs the default experiment (T = 100, tau = 10) at N steps per tau with
 * communication step dt (0.1, or h: one solver step per doStep), without or
 * with the outputs at every communication point:
 *   FMU     fmi2DoStep(t, dt) [then fmi2GetReal of the 9 outputs];
 *   native  dmi_advance to the same grid step [then the same outputs from
 *           dmi_get_state, dmi_get_past, dmi_get_step_terms, interpolated].
 * Rounds are interleaved (each round runs every case, FMU and native one after
 * the other, the order alternating), the fastest of the rounds counts; times
 * are CPU times of the process, initialization not timed.  Prints the time
 * per solver step and the ratio FMU / native (target <= 1.1), and, for the
 * reads alone (<= 1.2), the extra time of the runs that read the
 * outputs, FMU / native.  The native reads are one function, native_outputs,
 * so that callgrind gives their instructions per call beside fmi2GetReal's
 * (docs/fmu-export.md).
 * Usage: bench_fmu_chain [rounds] [N] [case]   (default 7, both N, all cases;
 * case 1-4: dt 0.1 without and with outputs, dt h without and with: one case
 * alone, for callgrind's instruction counts of fmu_run and native_run)
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "dmi.h"
#include "fmu_loader.h"

#define CHAIN_NATIVE_NO_MAIN
#include "native.c"

/* The chain's value references (examples/fmu-chain/chain.c's table). */
enum { VR_N = 11, VR_x1 = 16, NOUT = 9 };

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    (void)env;
    (void)category;
    fprintf(stderr, "bench_fmu_chain: %s: status %d: %s\n", name, (int)status, message);
}

/* Not inlined (GCC, Clang): callgrind counts each function's calls. */
#if defined(__GNUC__)
#define NOINLINE __attribute__((noinline))
#else
#define NOINLINE
#endif

/* CPU seconds of the FMU's loop to T; negative if a call failed. */
NOINLINE static double fmu_run(const fmu_api *f, int N, double T, double dt, int get, double *sink)
{
    const fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = f->instantiate("bench", fmi2CoSimulation, DMI_CHAIN_GUID, "", &cb,
                                     fmi2False, fmi2False);
    if (!c)
        return -1;
    const fmi2ValueReference vr_N = VR_N;
    fmi2ValueReference out[NOUT];
    for (int i = 0; i < NOUT; i++)
        out[i] = VR_x1 + (fmi2ValueReference)i;
    const fmi2Integer n = N;
    double secs = -1, y[NOUT];
    if (f->setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK &&
        f->set_integer(c, &vr_N, 1, &n) == fmi2OK && f->enter_init(c) == fmi2OK &&
        f->exit_init(c) == fmi2OK) {
        const long steps = lround(T / dt);
        long k = 0;
        const double t0 = cpu_now();
        y[0] = 0;
        while (k < steps && f->do_step(c, (double)k * dt, dt, fmi2True) == fmi2OK &&
               (!get || f->get_real(c, out, NOUT, y) == fmi2OK)) {
            *sink += y[0];
            k++;
        }
        secs = k == steps ? cpu_now() - t0 : -1;
    }
    f->terminate(c);
    f->free_instance(c);
    return secs;
}

/* The 9 outputs at t (step p of h) as the FMU computes them: u_h(t) and the
 * friction forces. */
NOINLINE static void native_outputs(const dmi_solver *s, const chain *c, double t, double h, double *y)
{
    double U[6], prev[6], W[6], X[6];
    uint64_t p = 0;
    dmi_get_step_index(s, &p);
    dmi_get_state(s, U);
    dmi_get_past(s, 1, prev);
    dmi_get_step_terms(s, W, X);
    const double theta = t / h - (double)(p - 1);
    for (int i = 0; i < 6; i++)
        y[i] = theta >= 1 - 1e-6 ? U[i] : prev[i] + theta * (U[i] - prev[i]);
    for (int i = 0; i < 3; i++)
        y[6 + i] = fmin(fmax((X[3 + i] - U[3 + i]) / h, -c->alpha[i]), c->alpha[i]);
}

/* CPU seconds of the native loop to T; negative on failure. */
NOINLINE static double native_run(int N, double T, double dt, int get, double *sink)
{
    chain c = CHAIN_DEFAULT;
    c.N = (size_t)N;
    dmi_solver *s = NULL;
    if (chain_solver(&s, &c, 1) != DMI_OK)
        return -1;
    const double h = dmi_get_h(s);
    const long steps = lround(T / dt);
    double y[NOUT];
    long k = 0;
    const double t0 = cpu_now();
    for (; k < steps; k++) {
        const double t = (double)(k + 1) * dt;
        uint64_t p = 0;
        dmi_get_step_index(s, &p);
        const double target = ceil(t / h - 1e-6);
        if (target > (double)p && dmi_advance(s, (size_t)(target - (double)p)) != DMI_OK)
            break;
        if (!get)
            continue;
        native_outputs(s, &c, t, h, y);
        *sink += y[0];
    }
    const double secs = k == steps ? cpu_now() - t0 : -1;
    dmi_free(&s);
    return secs;
}

int main(int argc, char **argv)
{
    size_t n_rounds = 7, only_N = 0, only_case = 0;
    const cli_arg args[] = {
        {"rounds", CLI_COUNT, &n_rounds, 1000, "interleaved rounds; the fastest of each counts"},
        {"N", CLI_COUNT, &only_N, 0, "only this N (steps per tau; default: 1000 and 100000)"},
        {"case", CLI_COUNT, &only_case, 4,
         "only this case: 1, 2 (dt = 0.1; outputs not read, read), 3, 4 (dt = h); default: all"}};
    const cli_program prog = {
        "bench_fmu_chain",
        "Times the Burridge-Knopoff chain of examples/fmu-chain (T = 100, tau = 10) as its FMU\n"
        "(fmi2DoStep, and fmi2GetReal of the 9 outputs when outputs are read) against the plain\n"
        "libdmi loop of the same model, at N = 1000 and 100000, in interleaved rounds (CPU time).",
        "stdout: a Markdown table of ns per solver step, native and FMU, and their ratio, and\n"
        "the reads alone (the runs reading the outputs minus those that do not);\n"
        "stderr: a checksum.\n"
        "exit status: 0, 1 if the FMU cannot be loaded or a run fails.",
        args, 3};
    cli_parse(&prog, argc, argv);
    const int rounds = (int)n_rounds;
    const double T = 100.0, tau = 10.0;
    const int Ns[] = {only_N ? (int)only_N : 1000, only_N ? (int)only_N : 100000};
    enum { NCASE = 8 }; /* N x (dt = 0.1, h) x (no outputs, outputs) */
    double best[NCASE][2];
    fmu_api f;
    if (fmu_load(&f, DMI_CHAIN_BINARY) != 0)
        return 1;
    for (int i = 0; i < NCASE; i++)
        best[i][0] = best[i][1] = INFINITY;
    double sink = 0;
    const int ncase = only_N ? NCASE / 2 : NCASE; /* one N: its four cases */
    for (int r = 0; r < rounds; r++)
        for (int i = 0; i < ncase; i++) {
            if (only_case && (size_t)(i % 4) + 1 != only_case)
                continue;
            const int N = Ns[i / 4], get = i % 2;
            const double dt = (i / 2) % 2 ? tau / N : 0.1;
            for (int j = 0; j < 2; j++) {
                const int fmu = (j + r + i) % 2; /* the order alternates */
                const double secs = fmu ? fmu_run(&f, N, T, dt, get, &sink)
                                        : native_run(N, T, dt, get, &sink);
                if (secs < 0) {
                    fprintf(stderr, "bench_fmu_chain: a run failed (N = %d)\n", N);
                    return 1;
                }
                if (secs < best[i][fmu])
                    best[i][fmu] = secs;
            }
        }
    printf("Burridge-Knopoff chain, T = %g, tau = %g, fastest of %d interleaved rounds "
           "(CPU time)\n", T, tau, rounds);
    printf("| N | communication step | outputs read | solver steps | native ns/step | "
           "FMU ns/step | FMU / native |\n|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < ncase; i++) {
        if (only_case && (size_t)(i % 4) + 1 != only_case)
            continue;
        const int N = Ns[i / 4];
        const double steps = T / tau * N;
        printf("| %d | %s | %s | %.0f | %.1f | %.1f | %.3f |\n", N, (i / 2) % 2 ? "h" : "0.1",
               i % 2 ? "9" : "none", steps, 1e9 * best[i][0] / steps, 1e9 * best[i][1] / steps,
               best[i][1] / best[i][0]);
    }
    if (only_case) {
        fflush(stdout);
        fprintf(stderr, "(checksum %g)\n", sink);
        fmu_unload(&f);
        return 0;
    }
    /* the reads after every solver step (dt = h): with 10 or 1000 steps per
     * read (dt = 0.1) the difference is within the timing's noise */
    printf("\nThe reads alone at dt = h (outputs read minus none), ns per read\n"
           "| N | native reads | FMU reads | FMU / native |\n|---|---|---|---|\n");
    for (int i = 2; i < ncase; i += 4) {
        const int N = Ns[i / 4];
        const double dt = tau / N, reads = T / dt;
        const double native = best[i + 1][0] - best[i][0], fmu = best[i + 1][1] - best[i][1];
        printf("| %d | %.1f | %.1f | %.3f |\n", N, 1e9 * native / reads, 1e9 * fmu / reads,
               fmu / native);
    }
    fflush(stdout);
    fprintf(stderr, "(checksum %g)\n", sink);
    fmu_unload(&f);
    return 0;
}
