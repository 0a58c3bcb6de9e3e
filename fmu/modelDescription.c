/*
 * Writes the FMU's modelDescription.xml for FMI 2.0 or 3.0 from the one
 * variable table of config.h; run at build time.
 *
 * Usage: modelDescription 2|3 VERSION OUTPUT [SOURCE...]
 * (the GUID / instantiationToken is config.h's DMI_FMU_GUID)
 * The SOURCEs (FMI 2.0: the C files of sources/) go into <SourceFiles>; FMI
 * 3.0 lists them in sources/buildDescription.xml instead.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <stdio.h>
#include <string.h>

#include "config.h"
#include "model.h"

typedef struct {
    const char *name, *start, *description;
    int kind;
} variable;

#define VAR_X(name, kind, start, description) {#name, #start, description, kind},
#define VAR_Y(name, kind, description) {#name, NULL, description, kind},
static const variable VARS[] = {MODEL_VARIABLES(VAR_X, VAR_Y)};
#define NVARS (sizeof VARS / sizeof VARS[0])

static const char *const CAUSALITY[] = {"parameter", "input",  "output",
                                        "parameter", "output", "independent"};
static const char *const VARIABILITY[] = {"fixed", "continuous", "continuous",
                                          "fixed", "discrete",   "continuous"};
static const char *const TYPE2[] = {"Real", "Real", "Real", "Integer", "Boolean", NULL};
static const char *const TYPE3[] = {"Float64", "Float64", "Float64", "Int32", "Boolean", "Float64"};

/* Outputs: no start value, not the time. */
static int is_output(const variable *x)
{
    return !x->start && x->kind != MODEL_TIME;
}

#define CAT(name, description) {#name, description},
static const char *const CATEGORIES[][2] = {MODEL_LOG_CATEGORIES(CAT)};
#undef CAT

/* Writes text as an XML attribute value (without the quotes). */
static void attr(FILE *f, const char *text)
{
    for (const char *c = text; *c; c++)
        switch (*c) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*c, f);
        }
}

static void header(FILE *f, int v, const char *version, int nsources,
                   char **sources)
{
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<!-- The friction oscillator (4.1) with a delay term of convolution, by libdmi.\n"
               "     Written by fmu/modelDescription.c from the variables of fmu/config.h.\n"
               "     Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: "
               "GPL-3.0-or-later -->\n"
               "<fmiModelDescription\n"
               "  fmiVersion=\"%s\"\n"
               "  modelName=\"%s\"\n"
               "  %s=\"%s\"\n"
               "  description=\"w'' + b w + int_0^tau H(s) w(t-s) ds + alpha sigma(w') + g(t) "
               "contains 0, implicit Euler scheme with h = tau/N (libdmi %s)\"\n"
               "  author=\"the dmi authors\"\n"
               "  version=\"%s\"\n"
               "  license=\"GPL-3.0-or-later\"\n"
               "  generationTool=\"dmi\"\n"
               "  variableNamingConvention=\"flat\"%s>\n",
            v == 2 ? "2.0" : "3.0", MODEL_NAME, v == 2 ? "guid" : "instantiationToken", DMI_FMU_GUID,
            version, version, v == 2 ? "\n  numberOfEventIndicators=\"0\"" : "");
    if (v == 2)
        fprintf(f, "  <CoSimulation\n"
                   "    modelIdentifier=\"%s\"\n"
                   "    canHandleVariableCommunicationStepSize=\"true\"\n"
                   "    canInterpolateInputs=\"false\"\n"
                   "    maxOutputDerivativeOrder=\"0\"\n"
                   "    canNotUseMemoryManagementFunctions=\"true\"\n"
                   "    canGetAndSetFMUstate=\"true\"\n"
                   "    canSerializeFMUstate=\"true\"",
                MODEL_NAME);
    if (v == 2 && nsources == 0)
        fprintf(f, "/>\n");
    if (v == 2 && nsources > 0) {
        fprintf(f, ">\n    <SourceFiles>\n");
        for (int k = 0; k < nsources; k++) {
            fprintf(f, "      <File name=\"");
            attr(f, sources[k]);
            fprintf(f, "\"/>\n");
        }
        fprintf(f, "    </SourceFiles>\n  </CoSimulation>\n");
    }
    if (v == 3) /* no event mode, no early return, no intermediate update */
        fprintf(f, "  <CoSimulation\n"
                   "    modelIdentifier=\"%s\"\n"
                   "    canHandleVariableCommunicationStepSize=\"true\"\n"
                   "    canGetAndSetFMUState=\"true\"\n"
                   "    canSerializeFMUState=\"true\"\n"
                   "    providesIntermediateUpdate=\"false\"\n"
                   "    canReturnEarlyAfterIntermediateUpdate=\"false\"\n"
                   "    hasEventMode=\"false\"\n"
                   "    maxOutputDerivativeOrder=\"0\"/>\n",
                MODEL_NAME);
    fprintf(f, "  <LogCategories>\n");
    for (size_t k = 0; k < sizeof CATEGORIES / sizeof CATEGORIES[0]; k++)
    {
        fprintf(f, "    <Category name=\"%s\" description=\"", CATEGORIES[k][0]);
        attr(f, CATEGORIES[k][1]);
        fprintf(f, "\"/>\n");
    }
    fprintf(f, "  </LogCategories>\n"
               "  <DefaultExperiment startTime=\"0.0\" stopTime=\"%.1f\" stepSize=\"0.01\"/>\n",
            MODEL_DEFAULT_T);
}

static void variables2(FILE *f)
{
    fprintf(f, "  <ModelVariables>\n");
    for (size_t i = 0; i < NVARS; i++) {
        const variable *x = &VARS[i];
        if (!TYPE2[x->kind])
            continue; /* FMI 2.0 has no independent variable (ModelVariables index = i + 1) */
        fprintf(f, "    <!-- index %zu -->\n"
                   "    <ScalarVariable name=\"%s\" valueReference=\"%zu\" causality=\"%s\" "
                   "variability=\"%s\"%s\n"
                   "                    description=\"",
                i + 1, x->name, i, CAUSALITY[x->kind], VARIABILITY[x->kind],
                x->kind == MODEL_REAL_INPUT ? ""
                : x->start                  ? " initial=\"exact\""
                                            : " initial=\"calculated\"");
        attr(f, x->description);
        fprintf(f, "\">\n");
        if (x->start)
            fprintf(f, "      <%s start=\"%s\"/>\n", TYPE2[x->kind], x->start);
        else
            fprintf(f, "      <%s/>\n", TYPE2[x->kind]);
        fprintf(f, "    </ScalarVariable>\n");
    }
    fprintf(f, "  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n");
    for (size_t i = 0; i < NVARS; i++)
        if (is_output(&VARS[i]))
            fprintf(f, "      <Unknown index=\"%zu\" dependencies=\"\"/>\n", i + 1);
    fprintf(f, "    </Outputs>\n    <InitialUnknowns>\n");
    for (size_t i = 0; i < NVARS; i++)
        if (is_output(&VARS[i]))
            fprintf(f, "      <Unknown index=\"%zu\"/>\n", i + 1);
    fprintf(f, "    </InitialUnknowns>\n  </ModelStructure>\n");
}

static void variables3(FILE *f)
{
    fprintf(f, "  <ModelVariables>\n");
    for (size_t i = 0; i < NVARS; i++) {
        const variable *x = &VARS[i];
        fprintf(f, "    <%s name=\"%s\" valueReference=\"%zu\" causality=\"%s\" "
                   "variability=\"%s\"%s",
                TYPE3[x->kind], x->name, i, CAUSALITY[x->kind], VARIABILITY[x->kind],
                x->kind == MODEL_REAL_INPUT || x->kind == MODEL_TIME ? ""
                : x->start                                          ? " initial=\"exact\""
                                                                    : "");
        if (x->start)
            fprintf(f, " start=\"%s\"", x->start);
        fprintf(f, "\n      description=\"");
        attr(f, x->description);
        fprintf(f, "\"/>\n");
    }
    fprintf(f, "  </ModelVariables>\n  <ModelStructure>\n");
    for (size_t i = 0; i < NVARS; i++)
        if (is_output(&VARS[i]))
            fprintf(f, "    <Output valueReference=\"%zu\" dependencies=\"\"/>\n", i);
    for (size_t i = 0; i < NVARS; i++)
        if (is_output(&VARS[i]))
            fprintf(f, "    <InitialUnknown valueReference=\"%zu\" dependencies=\"\"/>\n", i);
    fprintf(f, "  </ModelStructure>\n");
}

int main(int argc, char **argv)
{
    if (argc < 4 || (strcmp(argv[1], "2") != 0 && strcmp(argv[1], "3") != 0)) {
        fprintf(stderr, "usage: modelDescription 2|3 VERSION OUTPUT [SOURCE...]\n");
        return 2;
    }
    const int v = argv[1][0] - '0';
    FILE *f = fopen(argv[3], "w");
    if (!f) {
        perror(argv[3]);
        return 1;
    }
    header(f, v, argv[2], argc - 4, argv + 4);
    if (v == 2)
        variables2(f);
    else
        variables3(f);
    fprintf(f, "</fmiModelDescription>\n");
    return fclose(f) == 0 ? 0 : 1;
}
