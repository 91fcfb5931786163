/*
 * A minimal FMI 2.0 co-simulation host in C, as every non-Python tool is: dlopen the FMU's
 * binary, look up the fmi2 functions, call them.  It links no Python and needs no
 * environment.  It reads a job file (written by the test) and prints every output it reads
 * with %.17g, one line per communication point, so that the test can compare with FMPy and
 * with mechcosim on the same FMUs.
 *
 * Job file, one directive per line:
 *   sequence <start> <steps>          every FMU below in turn: the full call sequence
 *   jacobi <start> <stop> <step> <steps> [threads]   the FMUs below coupled, fixed-step
 *                                     Jacobi; "threads": each FMU steps on a thread of its
 *                                     own, all at once, as parallel hosts do
 *   fmu <instance> <unzipped dir> <model identifier> <guid>
 *   step <size>                       the communication step of the sequence (last fmu)
 *   set <r|i|b> <vr> <value>          a start value, set in initialization mode (last fmu)
 *   out <r|i> <vr>                    an output printed after each step (last fmu)
 *   derivative <vr> <value>           the first derivative of a Real input, set by
 *                                     fmi2SetRealInputDerivatives after initialization
 *   connect <r|i> <from instance> <vr> <to instance> <vr>
 *
 * Output lines: "<instance>:<label> <t> <values...>" (sequence) or "<instance> <t>
 * <values...>" (jacobi); the logger prints "log <status> <instance>: <message>".  The exit code is 0 when every call returned what it should.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define MAX_FMUS 16
#define MAX_VARS 64

typedef struct {
    char type; /* 'r', 'i' or 'b' */
    fmi2ValueReference vr;
    double value;
} Var;

typedef struct {
    char name[64];
    char dir[4096];
    char id[256];
    char guid[128];
    char uri[4200];
    void* library;
    Var sets[MAX_VARS];
    int n_sets;
    Var outs[MAX_VARS];
    int n_outs;
    Var derivatives[MAX_VARS];
    int n_derivatives;
    double h;
    fmi2Component c;
    fmi2InstantiateTYPE* instantiate;
    fmi2FreeInstanceTYPE* free_instance;
    fmi2SetupExperimentTYPE* setup;
    fmi2EnterInitializationModeTYPE* enter_init;
    fmi2ExitInitializationModeTYPE* exit_init;
    fmi2TerminateTYPE* terminate;
    fmi2ResetTYPE* reset;
    fmi2GetRealTYPE* get_real;
    fmi2SetRealTYPE* set_real;
    fmi2GetIntegerTYPE* get_integer;
    fmi2SetIntegerTYPE* set_integer;
    fmi2GetBooleanTYPE* get_boolean;
    fmi2SetBooleanTYPE* set_boolean;
    fmi2GetFMUstateTYPE* get_state;
    fmi2SetFMUstateTYPE* set_state;
    fmi2FreeFMUstateTYPE* free_state;
    fmi2DoStepTYPE* do_step;
    fmi2SetRealInputDerivativesTYPE* set_derivatives;
    fmi2GetTypesPlatformTYPE* types_platform;
    fmi2GetVersionTYPE* version;
} Fmu;

typedef struct {
    char type;
    int from, to;
    fmi2ValueReference from_vr, to_vr;
} Connection;

typedef struct {
    Fmu* fmu;
    double t, h;
    fmi2Status status;
} StepJob;

static void* step_on_thread(void* data) {
    StepJob* job = data;
    job->status = job->fmu->do_step(job->fmu->c, job->t, job->h, fmi2True);
    return NULL;
}

static Fmu fmus[MAX_FMUS];
static int n_fmus;
static Connection connections[MAX_VARS];
static int n_connections;
static int failures;

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    (void)env;
    (void)category;
    static const char* names[] = {"OK", "Warning", "Discard", "Error", "Fatal", "Pending"};
    char text[8192];
    va_list args;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args);
    va_end(args);
    for (char* p = text; *p; ++p)
        if (*p == '\n') *p = ' ';
    printf("log %s %s: %s\n", names[status], instance ? instance : "?", text);
    fflush(stdout);
}

static const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

static void fail(const char* what, const char* fmu) {
    printf("FAILED %s (%s)\n", what, fmu);
    fflush(stdout);
    failures++;
}

#define CHECK(call, what, fmu)                                                                  \
    do {                                                                                        \
        if ((call) != fmi2OK) fail(what, fmu);                                                  \
    } while (0)

static void* function(Fmu* f, const char* name) {
    void* p = dlsym(f->library, name);
    if (p == NULL) {
        printf("FAILED no %s in %s\n", name, f->id);
        exit(2);
    }
    return p;
}

static void load(Fmu* f) {
    char path[4400];
    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", f->dir, f->id);
    f->library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (f->library == NULL) {
        printf("FAILED dlopen: %s\n", dlerror());
        exit(2);
    }
    f->instantiate = function(f, "fmi2Instantiate");
    f->free_instance = function(f, "fmi2FreeInstance");
    f->setup = function(f, "fmi2SetupExperiment");
    f->enter_init = function(f, "fmi2EnterInitializationMode");
    f->exit_init = function(f, "fmi2ExitInitializationMode");
    f->terminate = function(f, "fmi2Terminate");
    f->reset = function(f, "fmi2Reset");
    f->get_real = function(f, "fmi2GetReal");
    f->set_real = function(f, "fmi2SetReal");
    f->get_integer = function(f, "fmi2GetInteger");
    f->set_integer = function(f, "fmi2SetInteger");
    f->get_boolean = function(f, "fmi2GetBoolean");
    f->set_boolean = function(f, "fmi2SetBoolean");
    f->get_state = function(f, "fmi2GetFMUstate");
    f->set_state = function(f, "fmi2SetFMUstate");
    f->free_state = function(f, "fmi2FreeFMUstate");
    f->do_step = function(f, "fmi2DoStep");
    f->set_derivatives = function(f, "fmi2SetRealInputDerivatives");
    f->types_platform = function(f, "fmi2GetTypesPlatform");
    f->version = function(f, "fmi2GetVersion");
    if (f->uri[0] == '\0') snprintf(f->uri, sizeof f->uri, "file://%s/resources", f->dir);
    if (strcmp(f->version(), "2.0") != 0 || strcmp(f->types_platform(), "default") != 0)
        fail("version", f->id);
}

static fmi2Component instantiate(Fmu* f, const char* name) {
    fmi2Component c =
        f->instantiate(name, fmi2CoSimulation, f->guid, f->uri, &callbacks, fmi2False, fmi2False);
    if (c == NULL) printf("instantiate %s returned NULL\n", name);
    return c;
}

/* setup, initialization mode with the start values, out of it */
static void initialize(Fmu* f, fmi2Component c, double start) {
    CHECK(f->setup(c, fmi2False, 0.0, start, fmi2False, 0.0), "fmi2SetupExperiment", f->id);
    CHECK(f->enter_init(c), "fmi2EnterInitializationMode", f->id);
    for (int k = 0; k < f->n_sets; ++k) {
        Var* v = &f->sets[k];
        if (v->type == 'r') {
            CHECK(f->set_real(c, &v->vr, 1, &v->value), "fmi2SetReal", f->id);
        } else if (v->type == 'i') {
            fmi2Integer x = (fmi2Integer)v->value;
            CHECK(f->set_integer(c, &v->vr, 1, &x), "fmi2SetInteger", f->id);
        } else {
            fmi2Boolean x = v->value != 0.0;
            CHECK(f->set_boolean(c, &v->vr, 1, &x), "fmi2SetBoolean", f->id);
        }
    }
    CHECK(f->exit_init(c), "fmi2ExitInitializationMode", f->id);
    for (int k = 0; k < f->n_derivatives; ++k) {
        Var* v = &f->derivatives[k];
        const fmi2Integer order = 1;
        CHECK(f->set_derivatives(c, &v->vr, 1, &order, &v->value), "fmi2SetRealInputDerivatives",
              f->id);
    }
}

static void print_outputs(Fmu* f, fmi2Component c, const char* label, double t) {
    if (label[0])
        printf("%s:%s %.17g", f->name, label, t);
    else
        printf("%s %.17g", f->name, t);
    for (int k = 0; k < f->n_outs; ++k) {
        Var* v = &f->outs[k];
        if (v->type == 'r') {
            fmi2Real x = 0;
            CHECK(f->get_real(c, &v->vr, 1, &x), "fmi2GetReal", f->id);
            printf(" %.17g", x);
        } else {
            fmi2Integer x = 0;
            CHECK(f->get_integer(c, &v->vr, 1, &x), "fmi2GetInteger", f->id);
            printf(" %d", x);
        }
    }
    printf("\n");
}

static void steps(Fmu* f, fmi2Component c, const char* label, double start, double h, int from,
                  int to) {
    for (int k = from; k < to; ++k) {
        CHECK(f->do_step(c, start + k * h, h, fmi2True), "fmi2DoStep", f->id);
        print_outputs(f, c, label, start + (k + 1) * h);
    }
}

/* The full call sequence on one FMU; every labelled run must print what "run" printed. */
static void sequence(Fmu* f, double start, int n) {
    double h = f->h;
    char name[128];
    snprintf(name, sizeof name, "%s_a", f->name);
    fmi2Component a = instantiate(f, name);
    if (a == NULL) {
        fail("fmi2Instantiate", f->id);
        return;
    }
    initialize(f, a, start);
    print_outputs(f, a, "run", start);
    /* no Boolean variables in our FMUs: the calls must still answer */
    fmi2Boolean none = 0;
    CHECK(f->get_boolean(a, NULL, 0, &none), "fmi2GetBoolean", f->id);
    CHECK(f->set_boolean(a, NULL, 0, &none), "fmi2SetBoolean", f->id);
    int half = n / 2;
    steps(f, a, "run", start, h, 0, half);
    fmi2FMUstate state = NULL;
    CHECK(f->get_state(a, &state), "fmi2GetFMUstate", f->id);
    steps(f, a, "run", start, h, half, n);
    CHECK(f->set_state(a, state), "fmi2SetFMUstate", f->id);
    steps(f, a, "restored", start, h, half, n);
    CHECK(f->free_state(a, &state), "fmi2FreeFMUstate", f->id);
    /* a step of zero size is refused, and the host hears why at default logging */
    printf("%s:zero step status %d\n", f->name, f->do_step(a, start + n * h, 0.0, fmi2True));
    CHECK(f->reset(a), "fmi2Reset", f->id);
    initialize(f, a, start);
    steps(f, a, "reset", start, h, 0, n);
    CHECK(f->terminate(a), "fmi2Terminate", f->id);
    f->free_instance(a);

    /* instantiate again after freeing, then two instances side by side */
    snprintf(name, sizeof name, "%s_b", f->name);
    fmi2Component b = instantiate(f, name);
    snprintf(name, sizeof name, "%s_c", f->name);
    fmi2Component c = instantiate(f, name);
    if (b == NULL || c == NULL) {
        fail("fmi2Instantiate again", f->id);
        return;
    }
    initialize(f, b, start);
    initialize(f, c, start);
    for (int k = 0; k < n; ++k) {
        steps(f, b, "twin_b", start, h, k, k + 1);
        steps(f, c, "twin_c", start, h, k, k + 1);
    }
    CHECK(f->terminate(b), "fmi2Terminate", f->id);
    CHECK(f->terminate(c), "fmi2Terminate", f->id);
    f->free_instance(b);
    f->free_instance(c);

    /* An unknown value reference: fmi2Error, the instance is in the error state and refuses
     * a step, and freeing it does not crash.  No resource location: the FMU finds its own. */
    snprintf(name, sizeof name, "%s_d", f->name);
    fmi2Component d =
        f->instantiate(name, fmi2CoSimulation, f->guid, NULL, &callbacks, fmi2False, fmi2False);
    if (d == NULL) {
        fail("fmi2Instantiate without a resource location", f->id);
        return;
    }
    initialize(f, d, start);
    fmi2ValueReference unknown = 999999;
    fmi2Real x = 0;
    fmi2Status first = f->get_real(d, &unknown, 1, &x);
    fmi2Status then = f->do_step(d, start, h, fmi2True);
    printf("%s:after an unknown value reference %d, then %d\n", f->name, first, then);
    f->free_instance(d);
}

/* One run: instantiate (at the job's resource location), initialize, step, free. */
static void plain(Fmu* f, double start, int n) {
    fmi2Component a = instantiate(f, f->name);
    if (a == NULL) {
        fail("fmi2Instantiate", f->id);
        return;
    }
    initialize(f, a, start);
    print_outputs(f, a, "run", start);
    steps(f, a, "run", start, f->h, 0, n);
    CHECK(f->terminate(a), "fmi2Terminate", f->id);
    f->free_instance(a);
}

/* Fixed-step Jacobi: every FMU steps with the outputs of the last communication point. */
static void jacobi(double start, double stop, double h, int n, int threaded) {
    double held[MAX_VARS];
    fmi2Integer held_i[MAX_VARS];
    for (int j = 0; j < n_fmus; ++j) {
        fmus[j].c = instantiate(&fmus[j], fmus[j].name);
        if (fmus[j].c == NULL) {
            fail("fmi2Instantiate", fmus[j].id);
            return;
        }
        Fmu* f = &fmus[j];
        CHECK(f->setup(f->c, fmi2False, 0.0, start, fmi2True, stop), "fmi2SetupExperiment", f->id);
        CHECK(f->enter_init(f->c), "fmi2EnterInitializationMode", f->id);
        for (int k = 0; k < f->n_sets; ++k) {
            Var* v = &f->sets[k];
            if (v->type == 'r') {
                CHECK(f->set_real(f->c, &v->vr, 1, &v->value), "fmi2SetReal", f->id);
            } else {
                fmi2Integer x = (fmi2Integer)v->value;
                CHECK(f->set_integer(f->c, &v->vr, 1, &x), "fmi2SetInteger", f->id);
            }
        }
        CHECK(f->exit_init(f->c), "fmi2ExitInitializationMode", f->id);
    }
    /* read every connection's source, then set every input (in FMU order) */
#define READ_SOURCES()                                                                          \
    for (int k = 0; k < n_connections; ++k) {                                                   \
        Connection* w = &connections[k];                                                        \
        Fmu* s = &fmus[w->from];                                                                \
        if (w->type == 'r')                                                                     \
            CHECK(s->get_real(s->c, &w->from_vr, 1, &held[k]), "fmi2GetReal", s->id);           \
        else                                                                                    \
            CHECK(s->get_integer(s->c, &w->from_vr, 1, &held_i[k]), "fmi2GetInteger", s->id);   \
    }
#define FEED(j)                                                                                 \
    for (int k = 0; k < n_connections; ++k) {                                                   \
        Connection* w = &connections[k];                                                        \
        Fmu* d = &fmus[w->to];                                                                  \
        if (w->to != (j)) continue;                                                             \
        if (w->type == 'r')                                                                     \
            CHECK(d->set_real(d->c, &w->to_vr, 1, &held[k]), "fmi2SetReal", d->id);             \
        else                                                                                    \
            CHECK(d->set_integer(d->c, &w->to_vr, 1, &held_i[k]), "fmi2SetInteger", d->id);     \
    }
    /* outputs with direct feedthrough depend on inputs: settle the initial exchange */
    for (int round = 0; round <= n_fmus; ++round) {
        READ_SOURCES();
        for (int j = 0; j < n_fmus; ++j) FEED(j);
    }
    READ_SOURCES();
    for (int k = 0; k < n; ++k) {
        double t = start + k * h;
        if (threaded) {
            pthread_t threads[MAX_FMUS];
            StepJob jobs[MAX_FMUS];
            for (int j = 0; j < n_fmus; ++j) FEED(j);
            for (int j = 0; j < n_fmus; ++j) {
                jobs[j] = (StepJob){&fmus[j], t, h, fmi2Error};
                if (pthread_create(&threads[j], NULL, step_on_thread, &jobs[j]) != 0) {
                    fail("pthread_create", fmus[j].id);
                    return;
                }
            }
            for (int j = 0; j < n_fmus; ++j) {
                pthread_join(threads[j], NULL);
                if (jobs[j].status != fmi2OK) fail("fmi2DoStep on a thread", fmus[j].id);
            }
        } else {
            for (int j = 0; j < n_fmus; ++j) {
                FEED(j);
                CHECK(fmus[j].do_step(fmus[j].c, t, h, fmi2True), "fmi2DoStep", fmus[j].id);
            }
        }
        READ_SOURCES();
        for (int j = 0; j < n_fmus; ++j) print_outputs(&fmus[j], fmus[j].c, "", start + (k + 1) * h);
    }
    for (int j = 0; j < n_fmus; ++j) {
        CHECK(fmus[j].terminate(fmus[j].c), "fmi2Terminate", fmus[j].id);
        fmus[j].free_instance(fmus[j].c);
    }
}

static int find(const char* name) {
    for (int j = 0; j < n_fmus; ++j)
        if (strcmp(fmus[j].name, name) == 0) return j;
    printf("FAILED no fmu %s\n", name);
    exit(2);
}

int main(int argc, char** argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s JOB\n", argv[0]);
        return 2;
    }
    FILE* job = fopen(argv[1], "r");
    if (job == NULL) {
        perror(argv[1]);
        return 2;
    }
    char mode[32] = "";
    double start = 0, stop = 0, h = 0;
    int n = 0, threaded = 0;
    char line[8192];
    while (fgets(line, sizeof line, job)) {
        char word[32];
        if (sscanf(line, "%31s", word) != 1) continue;
        if (strcmp(word, "sequence") == 0 || strcmp(word, "plain") == 0) {
            snprintf(mode, sizeof mode, "%s", word);
            sscanf(line, "%*s %lf %d", &start, &n);
        } else if (strcmp(word, "jacobi") == 0) {
            snprintf(mode, sizeof mode, "%s", word);
            char option[32] = "";
            sscanf(line, "%*s %lf %lf %lf %d %31s", &start, &stop, &h, &n, option);
            threaded = strcmp(option, "threads") == 0;
        } else if (strcmp(word, "fmu") == 0) {
            Fmu* f = &fmus[n_fmus++];
            sscanf(line, "%*s %63s %4095s %255s %127s", f->name, f->dir, f->id, f->guid);
        } else if (strcmp(word, "uri") == 0) { /* the resource location, as written */
            sscanf(line, "%*s %4199s", fmus[n_fmus - 1].uri);
        } else if (strcmp(word, "step") == 0) {
            sscanf(line, "%*s %lf", &fmus[n_fmus - 1].h);
        } else if (strcmp(word, "set") == 0 || strcmp(word, "out") == 0) {
            Fmu* f = &fmus[n_fmus - 1];
            Var* v = word[0] == 's' ? &f->sets[f->n_sets++] : &f->outs[f->n_outs++];
            sscanf(line, "%*s %c %u %lf", &v->type, &v->vr, &v->value);
        } else if (strcmp(word, "derivative") == 0) {
            Fmu* f = &fmus[n_fmus - 1];
            Var* v = &f->derivatives[f->n_derivatives++];
            v->type = 'r';
            sscanf(line, "%*s %u %lf", &v->vr, &v->value);
        } else if (strcmp(word, "connect") == 0) {
            Connection* w = &connections[n_connections++];
            char from[64], to[64];
            sscanf(line, "%*s %c %63s %u %63s %u", &w->type, from, &w->from_vr, to, &w->to_vr);
            w->from = find(from);
            w->to = find(to);
        }
    }
    fclose(job);
    for (int j = 0; j < n_fmus; ++j) load(&fmus[j]);
    if (strcmp(mode, "sequence") == 0) {
        for (int j = 0; j < n_fmus; ++j) sequence(&fmus[j], start, n);
    } else if (strcmp(mode, "plain") == 0) {
        for (int j = 0; j < n_fmus; ++j) plain(&fmus[j], start, n);
    } else if (strcmp(mode, "jacobi") == 0) {
        jacobi(start, stop, h, n, threaded);
    }
    printf("done %d failures\n", failures);
    return failures ? 1 : 0;
}
