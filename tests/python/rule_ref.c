/*
 * libdmi's own rule for the built-in resolvents, for the test of its Python
 * mirror (dmi._resolvent, test_resolvent_rule.py): for each line of stdin,
 * "friction alpha x" or "box lo hi x" (numbers as strtod reads them, hex
 * floats included), a solver of one component (tau = 1, N = 4: h = 1/4, no
 * rhs, no kernel) with that friction or box and the constant history x is
 * started, its hold read by dmi_watch_start (held_of at X = U^0 = x), and one
 * step taken: the line printed is "held R X h" with R the new state R(x) and X
 * the step's resolvent argument (%a: exact), or "refused" when libdmi refuses
 * the friction or the box.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dmi.h"
#include "core.h"

static int constant(double t, double *out, void *user)
{
    (void)t;
    out[0] = *(const double *)user;
    return 0;
}

/* One case: prints its line; 0, or 1 when libdmi fails where it should not. */
static int one(int box, double a, double b, double x)
{
    dmi_solver *s = NULL;
    if (dmi_create(&s, 1, 1.0, 4) != DMI_OK)
        return 1;
    const int rc = box ? dmi_set_box(s, &a, &b) : dmi_set_friction(s, &a);
    if (rc != DMI_OK) {
        printf("refused\n");
        dmi_free(&s);
        return 0;
    }
    const size_t comp = 0;
    int held = 0;
    dmi_watch w = {1, &comp, &held, 0, 0};
    double R, W, X;
    int bad = dmi_set_history(s, constant, &x) != DMI_OK || dmi_init(s) != DMI_OK
              || dmi_watch_start(s, &w) != DMI_OK || dmi_step(s) != DMI_OK
              || dmi_get_state(s, &R) != DMI_OK || dmi_get_step_terms(s, &W, &X) != DMI_OK;
    if (!bad)
        printf("%d %a %a %a\n", held, R, X, dmi_get_h(s));
    dmi_free(&s);
    return bad;
}

int main(void)
{
    char kind[16];
    double a, b = 0.0, x;
    while (scanf("%15s", kind) == 1) {
        const int box = strcmp(kind, "box") == 0;
        if (scanf(box ? "%lf %lf %lf" : "%lf %lf", &a, box ? &b : &x, &x) != (box ? 3 : 2))
            return 2;
        if (one(box, a, b, x))
            return 1;
    }
    return 0;
}
