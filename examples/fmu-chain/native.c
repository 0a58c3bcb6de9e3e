/*
 * The Burridge-Knopoff chain of chain.c as a plain libdmi program (dmi.h
 * only, no FMU): the independent computation the FMU is tested against, and
 * the native loop of the benchmark (bench/bench_fmu_chain.c, which compiles
 * this file with CHAIN_NATIVE_NO_MAIN).
 *
 * Usage: chain_native [stop [step [t_F F]]]
 * Prints CSV "t,x1,x2,x3,v1,v2,v3,friction1,friction2,friction3" at the
 * communication points k step, k = 1.. up to stop (default 100 and 0.1),
 * with the model's start values; the force on block 1 is 0 until t_F and F
 * from the step that starts at t_F on (default: no force).  u_h(t) is the
 * piecewise-linear interpolant of the scheme's states on the grid p h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dmi.h"

typedef struct {
    double k_p, k_c, V, alpha[3], g[2], theta[2], tau, x0[3];
    size_t N;
    double t_F, F; /* the force on block 1: F from t_F on */
} chain;

/* The start values of the model. */
static const chain CHAIN_DEFAULT = {1.0, 2.0, 0.1, {1.0, 1.2, 0.9}, {0.3, 0.1}, {0.5, 3.0}, 10.0,
                                    {0.0, 0.0, 0.0}, 1000, INFINITY, 0.0};

static const double COUPLING[3][3] = {{1, -1, 0}, {-1, 2, -1}, {0, -1, 1}};

static int chain_rhs(double t, const double *u, double *out, void *user)
{
    const chain *c = user;
    const double h = c->tau / (double)c->N;
    const double force = t > c->t_F - 1e-6 * h ? c->F : 0.0;
    for (int i = 0; i < 3; i++) {
        double Lx = 0;
        for (int j = 0; j < 3; j++)
            Lx += COUPLING[i][j] * u[j];
        out[i] = -u[3 + i];
        out[3 + i] = c->k_p * (u[i] - c->V * t) + c->k_c * Lx - (i == 0 ? force : 0.0);
    }
    return 0;
}

static int chain_history(double t, double *out, void *user)
{
    const chain *c = user;
    (void)t;
    for (int i = 0; i < 3; i++)
        out[i] = c->x0[i];
    return 0;
}

/* G(s) L in the v rows, x columns, sampled from the formula. */
static int chain_kernel(double s, double *out, void *user)
{
    const chain *c = user;
    const double G = c->g[0] * exp(-s / c->theta[0]) + c->g[1] * exp(-s / c->theta[1]);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[6 * (3 + i) + j] = G * COUPLING[i][j];
    return 0;
}

/* A solver of the chain c, initialised: DMI_OK or libdmi's error. */
int chain_solver(dmi_solver **s, const chain *c, int exponential_kernel)
{
    const double alpha[6] = {0, 0, 0, c->alpha[0], c->alpha[1], c->alpha[2]};
    int rc = dmi_create(s, 6, c->tau, c->N);
    if (rc != DMI_OK)
        return rc;
    if (exponential_kernel) { /* two terms exp(-s / theta_k) g_k [[0, 0], [L, 0]] */
        double a[2], b[2] = {0, 0}, C[72] = {0};
        for (int k = 0; k < 2; k++) {
            a[k] = -1 / c->theta[k];
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    C[36 * k + 6 * (3 + i) + j] = c->g[k] * COUPLING[i][j];
        }
        rc = dmi_set_kernel_exp(*s, 2, a, b, C, NULL);
    } else {
        rc = dmi_set_kernel(*s, chain_kernel, (void *)c);
    }
    if (rc == DMI_OK && (rc = dmi_set_rhs(*s, chain_rhs, (void *)c)) == DMI_OK &&
        (rc = dmi_set_friction(*s, alpha)) == DMI_OK &&
        (rc = dmi_set_history(*s, chain_history, (void *)c)) == DMI_OK)
        rc = dmi_init(*s);
    if (rc != DMI_OK)
        dmi_free(s);
    return rc;
}

#ifndef CHAIN_NATIVE_NO_MAIN
int main(int argc, char **argv)
{
    chain c = CHAIN_DEFAULT;
    const double stop = argc > 1 ? atof(argv[1]) : 100.0, dt = argc > 2 ? atof(argv[2]) : 0.1;
    if (argc > 4) {
        c.t_F = atof(argv[3]);
        c.F = atof(argv[4]);
    }
    dmi_solver *s = NULL;
    int rc = chain_solver(&s, &c, 1);
    if (rc != DMI_OK) {
        fprintf(stderr, "chain_native: %s\n", dmi_strerror(rc));
        return 1;
    }
    const double h = dmi_get_h(s);
    double U[6], prev[6], W[6], X[6];
    printf("t,x1,x2,x3,v1,v2,v3,friction1,friction2,friction3\n");
    for (long k = 1; k * dt <= stop + 1e-9; k++) {
        const double t = (double)k * dt;
        uint64_t p = 0;
        dmi_get_step_index(s, &p);
        const double target = ceil(t / h - 1e-6);
        if (target > (double)p && dmi_advance(s, (size_t)(target - (double)p)) != DMI_OK) {
            fprintf(stderr, "chain_native: %s\n", dmi_last_error(s));
            dmi_free(&s);
            return 1;
        }
        dmi_get_step_index(s, &p);
        dmi_get_state(s, U);
        dmi_get_past(s, 1, prev);
        dmi_get_step_terms(s, W, X);
        const double theta = t / h - (double)(p - 1); /* t in (t_{p-1}, t_p] */
        printf("%.17g", t);
        for (int i = 0; i < 6; i++)
            printf(",%.17g", theta >= 1 - 1e-6 ? U[i] : prev[i] + theta * (U[i] - prev[i]));
        for (int i = 0; i < 3; i++) {
            const double r = (X[3 + i] - U[3 + i]) / h;
            printf(",%.17g", fmin(fmax(r, -c.alpha[i]), c.alpha[i]));
        }
        printf("\n");
    }
    dmi_free(&s);
    return 0;
}
#endif
