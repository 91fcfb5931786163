/*
 * The Linux binary of every mechcosim FMU (binaries/linux64/<model>.so).
 *
 * pythonfmu's runtime (packed beside this file as libpythonfmu-export.so) runs the FMU's
 * Python code in the interpreter of the host process, but does not link libpython: a host
 * that is not Python (a C or C++ tool) cannot even load it ("undefined symbol:
 * _Py_NoneStruct").  This loader is what the host loads instead.  On the first
 * fmi2Instantiate it makes sure the process has a running Python, then loads the runtime and
 * forwards every FMI 2.0 call to it:
 *
 *   1. Python already in the process (a Python host, whether its executable links libpython
 *      or has it built in): use it.  The loader never loads a second libpython.
 *   2. Else load the shared libpython named in resources/python.txt (written at build time,
 *      the Python that built the FMU) or found beside $MECHCOSIM_PYTHON, globally, and start
 *      it as that Python's executable would start: a virtual environment's pyvenv.cfg is
 *      read, so its site-packages (the FMU's requirements) resolve.
 *
 * The loader also passes on what the runtime logs: every message whose status is not fmi2OK
 * reaches the host's logger whatever the logging setting (the runtime alone forwards
 * nothing unless debug logging is on), fmi2OK messages only with debug logging on.  A
 * failure of its own (no Python, a wrong version) is logged to the host and fmi2Instantiate
 * returns NULL.  After the runtime answers fmi2Fatal the instance is not passed to it again
 * (the runtime has released its Python objects and would crash): further calls return
 * fmi2Error and fmi2FreeInstance frees only what the loader holds.
 *
 * Input derivatives (FMI 2.0 fmi2SetRealInputDerivatives, which pythonfmu's runtime does not
 * serve) are the loader's: where the build wrote resources/input_derivatives.txt (the
 * value references of each input the component ramps and of its input with the role
 * rate_of it; the model description then says canInterpolateInputs="true"), a first
 * derivative du of input u set by the host means u(t) = u + du (t - tc) over the next step
 * (tc: its start, u: the input's value there).  The component ramps its input about the
 * step's middle, u_mid + rate (t - tc - h/2), so the loader sets u to u + du h/2 and the
 * rate input to du, steps, and then sets the input to where its ramp ends, u + du h (to u
 * where the step was not taken), and the rate input back: after the step fmi2GetReal of
 * the input gives its value at the step end, and the outputs that depend on it directly
 * are computed with that value.  The derivative stays in force, the ramp going on from
 * there, until it is set again or the instance is reset; a value set by fmi2SetReal starts
 * the next ramp.  A derivative overrides the rate input for its input.  An FMU state
 * holds the derivatives set.  A derivative of the rate input itself, or of order 2
 * or more, is accepted and not used (the component ramps to first order); of any other
 * variable, or of order 0, it is refused with fmi2Error.
 *
 * Compiled at build time against the headers of the Python that builds the FMU (PyConfig's
 * layout is that version's), without linking libpython: every Python function is looked up
 * at run time.
 */
#define _GNU_SOURCE
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <dlfcn.h>
#include <limits.h>
#include <link.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define EXPORT __attribute__((visibility("default")))
#define RUNTIME_FILE "libpythonfmu-export.so"
#define PYTHON_FILE "python.txt"
#define RAMPS_FILE "input_derivatives.txt"
#define MAX_RAMPS 16
#define PYTHON_VARIABLE "MECHCOSIM_PYTHON"
#define WHY_SIZE 2048

/* -- FMI 2.0 types (as the standard defines them) --------------------------------------- */
typedef void* fmi2Component;
typedef void* fmi2ComponentEnvironment;
typedef void* fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char* fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum {
    fmi2DoStepStatus,
    fmi2PendingStatus,
    fmi2LastSuccessfulTime,
    fmi2Terminated
} fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String,
                                   fmi2String, ...);
typedef void* (*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void*);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);
typedef struct {
    fmi2CallbackLogger logger;
    fmi2CallbackAllocateMemory allocateMemory;
    fmi2CallbackFreeMemory freeMemory;
    fmi2StepFinished stepFinished;
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

/* An instance as the host sees it: the runtime's instance and how to log for it. */
typedef struct {
    fmi2Component inner;
    fmi2CallbackFunctions host;    /* the host's callbacks, copied */
    fmi2CallbackFunctions relayed; /* given to the runtime: its messages come through relay() */
    char* name;
    int debug;          /* the host's debug logging setting */
    size_t n_categories; /* 0: all categories */
    char** categories;
    int failed;         /* the runtime answered fmi2Fatal: do not call it again */
    int phase;          /* where the instance is in FMI 2.0's state machine (Phase) */
    int refused;        /* the runtime logged an fmi2Error message during the current call */
    size_t n_ramps;     /* the inputs the component ramps (RAMPS_FILE) */
    fmi2ValueReference ramped[MAX_RAMPS]; /* each input */
    fmi2ValueReference rate[MAX_RAMPS];   /* its input with the role rate_of it */
    fmi2Real slope[MAX_RAMPS];            /* the derivative the host set; NaN: none */
} Instance;

/* FMI 2.0's co-simulation states (4.2.4, figure "Calling sequence of Co-Simulation C
 * functions").  Every step is synchronous here: "step in progress" and "step canceled"
 * are never entered, and fmi2CancelStep is never allowed. */
enum Phase {
    INSTANTIATED,
    INITIALIZATION_MODE,
    STEP_COMPLETE,
    STEP_IN_PROGRESS,
    STEP_FAILED,
    STEP_CANCELED,
    TERMINATED,
    ERROR_STATE,
    FATAL_STATE,
    N_PHASES
};
static const char* const PHASE_NAMES[N_PHASES] = {
    "instantiated",      "initialization mode", "step complete",
    "step in progress",  "step failed",         "step canceled",
    "terminated",        "error",               "fatal"};
#define IN(p) (1u << (p))
#define ANY_BUT_FATAL                                                                           \
    (IN(INSTANTIATED) | IN(INITIALIZATION_MODE) | IN(STEP_COMPLETE) | IN(STEP_FAILED) |         \
     IN(STEP_CANCELED) | IN(TERMINATED) | IN(ERROR_STATE))
#define SETTABLE (IN(INSTANTIATED) | IN(INITIALIZATION_MODE) | IN(STEP_COMPLETE))
#define READABLE                                                                                \
    (IN(INITIALIZATION_MODE) | IN(STEP_COMPLETE) | IN(STEP_FAILED) | IN(STEP_CANCELED) |        \
     IN(TERMINATED) | IN(ERROR_STATE))
#define AFTER_STEPS (IN(STEP_COMPLETE) | IN(STEP_FAILED) | IN(STEP_CANCELED) | IN(TERMINATED))

/* The functions that take an instance: the states FMI 2.0 allows each in, and how the
 * loader calls the runtime's.  The forwarded ones change no state themselves; the
 * loader's own wrappers (below) move the instance from state to state. */
#define FORWARDED_FUNCTIONS(X)                                                                  \
    X(fmi2SetupExperiment, IN(INSTANTIATED),                                                    \
      (fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance, fmi2Real startTime,   \
       fmi2Boolean stopTimeDefined, fmi2Real stopTime),                                         \
      (i->inner, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime))            \
    X(fmi2GetReal, READABLE,                                                                    \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real v[]),               \
      (i->inner, vr, nvr, v))                                                                   \
    X(fmi2GetInteger, READABLE,                                                                 \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer v[]),            \
      (i->inner, vr, nvr, v))                                                                   \
    X(fmi2GetBoolean, READABLE,                                                                 \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean v[]),            \
      (i->inner, vr, nvr, v))                                                                   \
    X(fmi2GetString, READABLE,                                                                  \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String v[]),             \
      (i->inner, vr, nvr, v))                                                                   \
    X(fmi2SetReal, SETTABLE,                                                                    \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real v[]),         \
      (i->inner, vr, nvr, v))                                                                   \
    X(fmi2SetInteger, SETTABLE,                                                                 \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer v[]),      \
      (i->inner, vr, nvr, v))                                                                   \
    X(fmi2SetBoolean, SETTABLE,                                                                 \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean v[]),      \
      (i->inner, vr, nvr, v))                                                                   \
    X(fmi2SetString, SETTABLE,                                                                  \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String v[]),       \
      (i->inner, vr, nvr, v))                                                                   \
    X(fmi2GetDirectionalDerivative, READABLE,                                                   \
      (fmi2Component c, const fmi2ValueReference unknown[], size_t n_unknown,                   \
       const fmi2ValueReference known[], size_t n_known, const fmi2Real dv_known[],             \
       fmi2Real dv_unknown[]),                                                                  \
      (i->inner, unknown, n_unknown, known, n_known, dv_known, dv_unknown))                     \
    X(fmi2GetRealOutputDerivatives, AFTER_STEPS | IN(ERROR_STATE),                             \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer order[],   \
       fmi2Real v[]),                                                                           \
      (i->inner, vr, nvr, order, v))                                                            \
    X(fmi2CancelStep, IN(STEP_IN_PROGRESS), (fmi2Component c), (i->inner))                      \
    X(fmi2GetStatus, AFTER_STEPS,                                                               \
      (fmi2Component c, const fmi2StatusKind s, fmi2Status * v),                                \
      (i->inner, s, v))                                                                         \
    X(fmi2GetRealStatus, AFTER_STEPS,                                                           \
      (fmi2Component c, const fmi2StatusKind s, fmi2Real * v),                                  \
      (i->inner, s, v))                                                                         \
    X(fmi2GetIntegerStatus, AFTER_STEPS,                                                        \
      (fmi2Component c, const fmi2StatusKind s, fmi2Integer * v),                               \
      (i->inner, s, v))                                                                         \
    X(fmi2GetBooleanStatus, AFTER_STEPS,                                                        \
      (fmi2Component c, const fmi2StatusKind s, fmi2Boolean * v),                               \
      (i->inner, s, v))                                                                         \
    X(fmi2GetStringStatus, AFTER_STEPS,                                                         \
      (fmi2Component c, const fmi2StatusKind s, fmi2String * v),                                \
      (i->inner, s, v))

#define OWN_FUNCTIONS(X)                                                                        \
    X(fmi2EnterInitializationMode, IN(INSTANTIATED), (fmi2Component c), (i->inner))             \
    X(fmi2ExitInitializationMode, IN(INITIALIZATION_MODE), (fmi2Component c), (i->inner))       \
    X(fmi2Terminate, IN(STEP_COMPLETE) | IN(STEP_FAILED) | IN(STEP_CANCELED),                   \
      (fmi2Component c),                                                                        \
      (i->inner))                                                                               \
    X(fmi2Reset, ANY_BUT_FATAL, (fmi2Component c), (i->inner))                                  \
    X(fmi2GetFMUstate, ANY_BUT_FATAL, (fmi2Component c, fmi2FMUstate * state), (i->inner, state)) \
    X(fmi2SetFMUstate, ANY_BUT_FATAL, (fmi2Component c, fmi2FMUstate state), (i->inner, state)) \
    X(fmi2FreeFMUstate, ANY_BUT_FATAL, (fmi2Component c, fmi2FMUstate * state), (i->inner, state)) \
    X(fmi2SerializedFMUstateSize, ANY_BUT_FATAL,                                                \
      (fmi2Component c, fmi2FMUstate state, size_t * size),                                     \
      (i->inner, state, size))                                                                  \
    X(fmi2SerializeFMUstate, ANY_BUT_FATAL,                                                     \
      (fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size),                     \
      (i->inner, state, bytes, size))                                                           \
    X(fmi2DeSerializeFMUstate, ANY_BUT_FATAL,                                                   \
      (fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate * state),             \
      (i->inner, bytes, size, state))                                                           \
    X(fmi2SetRealInputDerivatives, SETTABLE,                                                    \
      (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer order[],   \
       const fmi2Real v[]),                                                                     \
      (i->inner, vr, nvr, order, v))                                                            \
    X(fmi2DoStep, IN(STEP_COMPLETE),                                                            \
      (fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,     \
       fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint),                              \
      (i->inner, currentCommunicationPoint, communicationStepSize,                              \
       noSetFMUStatePriorToCurrentCommunicationPoint))

#define INSTANCE_FUNCTIONS(X) FORWARDED_FUNCTIONS(X) OWN_FUNCTIONS(X)

#define DECLARE(name, allowed, params, args) EXPORT fmi2Status name params;
INSTANCE_FUNCTIONS(DECLARE)

/* The runtime's entry points, found once. */
static struct {
    void* handle;
    fmi2Component (*fmi2Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                     const fmi2CallbackFunctions*, fmi2Boolean, fmi2Boolean);
    void (*fmi2FreeInstance)(fmi2Component);
    void (*finalizePythonInterpreter)(void);
#define POINTER(name, allowed, params, args) fmi2Status(*name) params;
    INSTANCE_FUNCTIONS(POINTER)
} runtime;

/* The Python functions the loader itself calls. */
static struct {
    int (*Py_IsInitialized)(void);
    const char* (*Py_GetVersion)(void);
    void (*PyConfig_InitPythonConfig)(PyConfig*);
    PyStatus (*PyConfig_SetBytesString)(PyConfig*, wchar_t**, const char*);
    PyStatus (*Py_InitializeFromConfig)(const PyConfig*);
    void (*PyConfig_Clear)(PyConfig*);
    int (*PyStatus_Exception)(PyStatus);
    PyThreadState* (*PyEval_SaveThread)(void);
} py;

static pthread_mutex_t prepare_lock = PTHREAD_MUTEX_INITIALIZER;

/* -- logging ------------------------------------------------------------------------------ */
static const char* status_category(fmi2Status status) {
    switch (status) {
        case fmi2Warning: return "logStatusWarning";
        case fmi2Discard: return "logStatusDiscard";
        case fmi2Error: return "logStatusError";
        case fmi2Fatal: return "logStatusFatal";
        default: return "logAll";
    }
}

/* The host's logger takes a printf format: a message is passed as one, its '%' doubled. */
static void emit(const fmi2CallbackFunctions* host, fmi2String name, fmi2Status status,
                 fmi2String category, const char* message) {
    if (host == NULL || host->logger == NULL) return;
    if (category == NULL || category[0] == '\0') category = status_category(status);
    if (message == NULL) message = "";
    if (strchr(message, '%') == NULL) {
        host->logger(host->componentEnvironment, name, status, category, message);
        return;
    }
    size_t n = strlen(message);
    char* escaped = malloc(2 * n + 1);
    if (escaped == NULL) return;
    char* out = escaped;
    for (const char* p = message; *p; ++p) {
        *out++ = *p;
        if (*p == '%') *out++ = '%';
    }
    *out = '\0';
    host->logger(host->componentEnvironment, name, status, category, escaped);
    free(escaped);
}

/* What the runtime logs for an instance: every message that is not fmi2OK, the others as
 * the host's debug logging setting says. */
static void relay(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                  fmi2String category, fmi2String message, ...) {
    Instance* i = env;
    if (i == NULL) return;
    if (status == fmi2Error) i->refused = 1;
    if (status == fmi2OK) {
        if (!i->debug) return;
        if (i->n_categories > 0) {
            size_t k = 0;
            while (k < i->n_categories && !(category && strcmp(category, i->categories[k]) == 0))
                ++k;
            if (k == i->n_categories) return;
        }
    }
    emit(&i->host, name ? name : i->name, status, category, message);
}

/* -- finding Python ------------------------------------------------------------------------ */
/* The directory this binary is in (binaries/linux64 of the unpacked FMU). */
static int own_directory(char* dir, size_t size, char* why) {
    Dl_info info;
    if (dladdr((void*)&own_directory, &info) == 0 || info.dli_fname == NULL) {
        snprintf(why, WHY_SIZE, "cannot tell where the FMU's binary is (dladdr failed)");
        return 0;
    }
    char resolved[PATH_MAX];
    if (realpath(info.dli_fname, resolved) == NULL) {
        snprintf(why, WHY_SIZE, "cannot resolve the path of the FMU's binary %s", info.dli_fname);
        return 0;
    }
    char* slash = strrchr(resolved, '/');
    if (slash) *slash = '\0';
    snprintf(dir, size, "%s", resolved);
    return 1;
}

static int find_libpython(struct dl_phdr_info* info, size_t size, void* data) {
    (void)size;
    const char* base = info->dlpi_name ? strrchr(info->dlpi_name, '/') : NULL;
    base = base ? base + 1 : info->dlpi_name;
    if (base && strncmp(base, "libpython3", 10) == 0 && strstr(base, ".so")) {
        snprintf((char*)data, PATH_MAX, "%s", info->dlpi_name);
        return 1;
    }
    return 0;
}

/* The Python this FMU starts where the process has none: $MECHCOSIM_PYTHON, else the
 * executable and library that resources/python.txt names. */
typedef struct {
    char executable[PATH_MAX];
    char library[PATH_MAX];
    char source[PATH_MAX + 64]; /* where the choice came from, for messages */
} PythonChoice;

static void trim(char* s) {
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == '\n' || s[n - 1] == '\r' || s[n - 1] == ' ')) s[--n] = '\0';
}

/* What can be told of a Python executable without running it: the directory of its base
 * installation's executable (a virtual environment's pyvenv.cfg names it as "home") and its
 * version (pyvenv.cfg's "version", else the name python3.X the executable resolves to;
 * 0.0 when neither says). */
static void inspect_executable(const char* executable, char* base_bin, int* major, int* minor) {
    *major = *minor = 0;
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s", executable);
    char* slash = strrchr(dir, '/');
    if (slash) *slash = '\0';
    char real[PATH_MAX] = "";
    if (realpath(executable, real)) {
        const char* name = strrchr(real, '/') ? strrchr(real, '/') + 1 : real;
        sscanf(name, "python%d.%d", major, minor);
        slash = strrchr(real, '/');
        if (slash) *slash = '\0';
        snprintf(base_bin, PATH_MAX, "%s", real);
    } else {
        snprintf(base_bin, PATH_MAX, "%s", dir);
    }
    char cfg_path[PATH_MAX + 16];
    snprintf(cfg_path, sizeof cfg_path, "%s/../pyvenv.cfg", dir);
    FILE* cfg = fopen(cfg_path, "r");
    if (cfg == NULL) return;
    char line[PATH_MAX + 32];
    while (fgets(line, sizeof line, cfg)) {
        char* value = strchr(line, '=');
        if (value == NULL) continue;
        value++;
        while (*value == ' ') value++;
        trim(value);
        if (strncmp(line, "home", 4) == 0)
            snprintf(base_bin, PATH_MAX, "%s", value);
        else if (strncmp(line, "version", 7) == 0)
            sscanf(value, "%d.%d", major, minor);
    }
    fclose(cfg);
}

/* The shared libpython of an executable: <base installation>/lib/libpython3.X.so.1.0, else
 * that name on the system's library path (Debian's, for /usr/bin/python3). */
static void library_beside(const char* base_bin, int major, int minor, char* library) {
    if (major == 0) {
        major = PY_MAJOR_VERSION;
        minor = PY_MINOR_VERSION;
    }
    char soname[64];
    snprintf(soname, sizeof soname, "libpython%d.%d.so.1.0", major, minor);
    char candidate[PATH_MAX + 80];
    snprintf(candidate, sizeof candidate, "%s/../lib/%s", base_bin, soname);
    if (access(candidate, R_OK) == 0 && strlen(candidate) < PATH_MAX)
        snprintf(library, PATH_MAX, "%s", candidate);
    else
        snprintf(library, PATH_MAX, "%s", soname);
}

/* The executable must be of the Python the loader was built for (PyConfig's layout is that
 * version's); its library, when not named, is found beside it. */
static int check_version(PythonChoice* choice, char* why) {
    char base_bin[PATH_MAX];
    int major, minor;
    if (access(choice->executable, X_OK) != 0) {
        snprintf(why, WHY_SIZE, "the Python executable %s (from %s) is not there or not "
                 "executable; set %s to a Python %d.%d executable", choice->executable,
                 choice->source, PYTHON_VARIABLE, PY_MAJOR_VERSION, PY_MINOR_VERSION);
        return 0;
    }
    inspect_executable(choice->executable, base_bin, &major, &minor);
    if (major == 0) {
        /* neither its name nor a pyvenv.cfg tells: its installation's standard library does */
        char stdlib[PATH_MAX + 64], real[PATH_MAX] = "";
        snprintf(stdlib, sizeof stdlib, "%s/../lib/python%d.%d/os.py", base_bin,
                 PY_MAJOR_VERSION, PY_MINOR_VERSION);
        const char* name = realpath(choice->executable, real) ? strrchr(real, '/') : NULL;
        if (name == NULL || strncmp(name + 1, "python", 6) != 0 || access(stdlib, R_OK) != 0) {
            snprintf(why, WHY_SIZE,
                     "%s (from %s) is not a Python %d.%d executable (not named python%d.%d, "
                     "no pyvenv.cfg beside it, or no lib/python%d.%d/os.py in its "
                     "installation); set %s to a Python %d.%d executable",
                     choice->executable, choice->source, PY_MAJOR_VERSION, PY_MINOR_VERSION,
                     PY_MAJOR_VERSION, PY_MINOR_VERSION, PY_MAJOR_VERSION, PY_MINOR_VERSION,
                     PYTHON_VARIABLE, PY_MAJOR_VERSION, PY_MINOR_VERSION);
            return 0;
        }
    }
    if (major != 0 && (major != PY_MAJOR_VERSION || minor != PY_MINOR_VERSION)) {
        snprintf(why, WHY_SIZE,
                 "the FMU was built for Python %d.%d, but %s (from %s) is Python %d.%d; set "
                 "%s to a Python %d.%d executable",
                 PY_MAJOR_VERSION, PY_MINOR_VERSION, choice->executable, choice->source, major,
                 minor, PYTHON_VARIABLE, PY_MAJOR_VERSION, PY_MINOR_VERSION);
        return 0;
    }
    if (choice->library[0] == '\0') library_beside(base_bin, major, minor, choice->library);
    return 1;
}

static int choose_python(const char* binaries, PythonChoice* choice, char* why) {
    memset(choice, 0, sizeof *choice);
    const char* variable = getenv(PYTHON_VARIABLE);
    if (variable && variable[0]) {
        snprintf(choice->executable, PATH_MAX, "%s", variable);
        snprintf(choice->source, sizeof choice->source, "$%s", PYTHON_VARIABLE);
        return check_version(choice, why);
    }
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/../../resources/%s", binaries, PYTHON_FILE);
    snprintf(choice->source, sizeof choice->source, "resources/%s", PYTHON_FILE);
    FILE* f = fopen(path, "r");
    if (f == NULL) {
        snprintf(why, WHY_SIZE,
                 "no Python in this process and no resources/%s to name one; set %s to a "
                 "Python %d.%d executable",
                 PYTHON_FILE, PYTHON_VARIABLE, PY_MAJOR_VERSION, PY_MINOR_VERSION);
        return 0;
    }
    char line[PATH_MAX + 32];
    while (fgets(line, sizeof line, f)) {
        trim(line);
        if (strncmp(line, "executable=", 11) == 0)
            snprintf(choice->executable, PATH_MAX, "%s", line + 11);
        else if (strncmp(line, "library=", 8) == 0)
            snprintf(choice->library, PATH_MAX, "%s", line + 8);
    }
    fclose(f);
    if (choice->executable[0] == '\0') {
        snprintf(why, WHY_SIZE, "resources/%s names no executable; set %s to a Python %d.%d "
                 "executable", PYTHON_FILE, PYTHON_VARIABLE, PY_MAJOR_VERSION, PY_MINOR_VERSION);
        return 0;
    }
    return check_version(choice, why);
}

#define PY_FUNCTION(handle, name)                                                               \
    do {                                                                                        \
        *(void**)&py.name = dlsym(handle, #name);                                               \
        if (py.name == NULL) {                                                                  \
            snprintf(why, WHY_SIZE, "the Python in this process has no %s", #name);             \
            return 0;                                                                           \
        }                                                                                       \
    } while (0)

/* What starting Python takes (a Python host's interpreter is used as it is: only
 * Py_IsInitialized is asked of it). */
static int python_functions(void* handle, char* why) {
    PY_FUNCTION(handle, Py_GetVersion);
    PY_FUNCTION(handle, PyConfig_InitPythonConfig);
    PY_FUNCTION(handle, PyConfig_SetBytesString);
    PY_FUNCTION(handle, Py_InitializeFromConfig);
    PY_FUNCTION(handle, PyConfig_Clear);
    PY_FUNCTION(handle, PyStatus_Exception);
    PY_FUNCTION(handle, PyEval_SaveThread);
    return 1;
}

/* Start Python as `choice->executable` would start (its prefix, a virtual environment's
 * site-packages), without taking over the host's signals; then let go of the GIL. */
static int start_python(const PythonChoice* choice, char* why) {
    const char* version = py.Py_GetVersion();
    int major = 0, minor = 0;
    if (sscanf(version, "%d.%d", &major, &minor) != 2 || major != PY_MAJOR_VERSION ||
        minor != PY_MINOR_VERSION) {
        snprintf(why, WHY_SIZE,
                 "the FMU was built for Python %d.%d, but the Python to start (%s) is %.20s; "
                 "set %s to a Python %d.%d executable",
                 PY_MAJOR_VERSION, PY_MINOR_VERSION, choice->library, version, PYTHON_VARIABLE,
                 PY_MAJOR_VERSION, PY_MINOR_VERSION);
        return 0;
    }
    if (access(choice->executable, X_OK) != 0) {
        snprintf(why, WHY_SIZE, "the Python executable %s (from %s) is not there", 
                 choice->executable, choice->source);
        return 0;
    }
    PyConfig config;
    py.PyConfig_InitPythonConfig(&config);
    config.install_signal_handlers = 0;
    config.parse_argv = 0;
    PyStatus status =
        py.PyConfig_SetBytesString(&config, &config.program_name, choice->executable);
    if (!py.PyStatus_Exception(status)) status = py.Py_InitializeFromConfig(&config);
    py.PyConfig_Clear(&config);
    if (py.PyStatus_Exception(status)) {
        snprintf(why, WHY_SIZE, "cannot start Python %s (from %s): %s%s%s", choice->executable,
                 choice->source, status.func ? status.func : "",
                 status.func ? ": " : "", status.err_msg ? status.err_msg : "failed");
        return 0;
    }
    py.PyEval_SaveThread(); /* the runtime takes the GIL for each call, from any thread */
    return 1;
}

/* Make sure the process has a running Python whose symbols the runtime can see. */
static int python_ready(const char* binaries, char* why) {
    void* handle = RTLD_DEFAULT;
    PythonChoice choice;
    int chosen = 0;
    if (dlsym(RTLD_DEFAULT, "Py_IsInitialized") == NULL) {
        /* A libpython some other part of the process loaded privately: make it global. */
        char loaded[PATH_MAX] = "";
        dl_iterate_phdr(find_libpython, loaded);
        if (loaded[0]) {
            handle = dlopen(loaded, RTLD_NOW | RTLD_NOLOAD | RTLD_GLOBAL);
        } else {
            if (!choose_python(binaries, &choice, why)) return 0;
            chosen = 1;
            handle = dlopen(choice.library, RTLD_NOW | RTLD_GLOBAL);
            if (handle == NULL) {
                snprintf(why, WHY_SIZE,
                         "no Python in this process and cannot load %s (from %s): %s; set %s "
                         "to a Python %d.%d executable",
                         choice.library, choice.source, dlerror(), PYTHON_VARIABLE,
                         PY_MAJOR_VERSION, PY_MINOR_VERSION);
                return 0;
            }
        }
        if (handle == NULL) {
            snprintf(why, WHY_SIZE, "cannot use the libpython %s of this process: %s", loaded,
                     dlerror());
            return 0;
        }
    }
    PY_FUNCTION(handle, Py_IsInitialized);
    if (py.Py_IsInitialized()) return 1; /* a Python host: its interpreter, as it is */
    if (!python_functions(handle, why)) return 0;
    if (!chosen && !choose_python(binaries, &choice, why)) return 0;
    return start_python(&choice, why);
}

/* -- the runtime ---------------------------------------------------------------------------- */
/* Registered after the runtime's static constructors, so run at exit before its static
 * destructors: the runtime's own library destructor would otherwise reset its interpreter
 * state once those have freed it (heap corruption at exit). */
static void release_runtime(void) {
    if (runtime.finalizePythonInterpreter) runtime.finalizePythonInterpreter();
}

#define RUNTIME_FUNCTION(name)                                                                  \
    do {                                                                                        \
        *(void**)&runtime.name = dlsym(handle, #name);                                          \
        if (runtime.name == NULL) {                                                             \
            snprintf(why, WHY_SIZE, "pythonfmu's runtime %s has no %s", path, #name);          \
            return 0;                                                                           \
        }                                                                                       \
    } while (0)
#define RESOLVE(name, allowed, params, args) RUNTIME_FUNCTION(name);

static int load_runtime(const char* binaries, char* why) {
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/%s", binaries, RUNTIME_FILE);
    void* handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (handle == NULL) {
        snprintf(why, WHY_SIZE, "cannot load pythonfmu's runtime: %s", dlerror());
        return 0;
    }
    RUNTIME_FUNCTION(fmi2Instantiate);
    RUNTIME_FUNCTION(fmi2FreeInstance);
    INSTANCE_FUNCTIONS(RESOLVE)
    *(void**)&runtime.finalizePythonInterpreter = dlsym(handle, "finalizePythonInterpreter");
    /* The runtime is never unloaded (pythonfmu's runtime does not survive it), so neither is
     * this loader, which holds its entry points: a host that unloads and loads the FMU again
     * finds both as they were. */
    Dl_info info;
    if (dladdr((void*)&load_runtime, &info) && info.dli_fname)
        dlopen(info.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
    atexit(release_runtime);
    runtime.handle = handle;
    return 1;
}

static int prepare(char* why) {
    char binaries[PATH_MAX];
    pthread_mutex_lock(&prepare_lock);
    int ok = runtime.handle != NULL ||
             (own_directory(binaries, sizeof binaries, why) && python_ready(binaries, why) &&
              load_runtime(binaries, why));
    pthread_mutex_unlock(&prepare_lock);
    return ok;
}

/* -- the resource location ------------------------------------------------------------- */
static int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* The resource location as pythonfmu's runtime takes it, "file://" and a plain absolute path
 * (it strips exactly that prefix).  FMI 2.0 (2.1.6, fmi2Instantiate) gives the location as a
 * URI (RFC 3986): "file:///p", "file:/p" and "file://localhost/p" name the same directory,
 * its characters may be percent-escaped ("%20" for a space), and a plain absolute path is
 * taken as it is. */
static int resource_path(const char* location, char* out, size_t size, char* why) {
    const char* path = location;
    if (strncmp(location, "file:", 5) == 0) {
        path = location + 5;
        if (strncmp(path, "//", 2) == 0) {
            path += 2; /* an authority: empty or localhost, then the absolute path */
            if (strncmp(path, "localhost/", 10) == 0) path += 9;
        }
    }
    if (path[0] != '/') {
        snprintf(why, WHY_SIZE,
                 "fmi2Instantiate: resource location \"%.1024s\" is no file URI of a local "
                 "absolute path (expected file:///path, file:/path or file://localhost/path)",
                 location);
        return 0;
    }
    size_t n = (size_t)snprintf(out, size, "file://");
    for (const char* p = path; *p; ++p) {
        char c = *p;
        if (c == '%') {
            int high = hex_digit(p[1]), low = high < 0 ? -1 : hex_digit(p[2]);
            if (low < 0) {
                snprintf(why, WHY_SIZE,
                         "fmi2Instantiate: resource location \"%.1024s\" has a '%%' that is not "
                         "followed by two hexadecimal digits", location);
                return 0;
            }
            c = (char)(high * 16 + low);
            p += 2;
        }
        if (c == '\0' || n + 1 >= size) {
            snprintf(why, WHY_SIZE, "fmi2Instantiate: resource location \"%.1024s\" is %s",
                     location, c == '\0' ? "a path with an escaped NUL" : "too long");
            return 0;
        }
        out[n++] = c;
    }
    out[n] = '\0';
    /* the runtime reads the name of the slave's module there, and crashes without it */
    char marker[PATH_MAX + 64];
    snprintf(marker, sizeof marker, "%s/slavemodule.txt", out + 7);
    if (access(marker, R_OK) != 0) {
        snprintf(why, WHY_SIZE,
                 "fmi2Instantiate: resource location \"%.1024s\" is not this FMU's resources "
                 "directory (no slavemodule.txt in %.1024s)", location, out + 7);
        return 0;
    }
    return 1;
}

/* -- what is instantiated ---------------------------------------------------------------- */
/* The GUID of this FMU's model description (FMI 2.0, 2.1.6: fmi2Instantiate checks the one
 * the host read against it); "" where the unpacked FMU has no modelDescription.xml. */
static void own_guid(char* guid, size_t size) {
    guid[0] = '\0';
    char binaries[PATH_MAX], why[WHY_SIZE];
    if (!own_directory(binaries, sizeof binaries, why)) return;
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/../../modelDescription.xml", binaries);
    FILE* f = fopen(path, "r");
    if (f == NULL) return;
    char text[16384];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    const char* root = strstr(text, "<fmiModelDescription");
    const char* at = root ? strstr(root, " guid=\"") : NULL;
    if (at == NULL) return;
    at += 7;
    const char* end = strchr(at, '"');
    if (end == NULL || (size_t)(end - at) >= size) return;
    memcpy(guid, at, (size_t)(end - at));
    guid[end - at] = '\0';
}

/* The inputs this FMU ramps, from resources/input_derivatives.txt beside its binary: lines
 * "<value reference of the input> <value reference of its rate input>"; none without it. */
static void read_ramps(Instance* i) {
    char binaries[PATH_MAX], why[WHY_SIZE];
    i->n_ramps = 0;
    if (!own_directory(binaries, sizeof binaries, why)) return;
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/../../resources/%s", binaries, RAMPS_FILE);
    FILE* f = fopen(path, "r");
    if (f == NULL) return;
    char line[256];
    unsigned input, rate;
    while (fgets(line, sizeof line, f) && i->n_ramps < MAX_RAMPS) {
        if (line[0] == '#' || sscanf(line, "%u %u", &input, &rate) != 2) continue;
        i->ramped[i->n_ramps] = input;
        i->rate[i->n_ramps] = rate;
        i->slope[i->n_ramps] = NAN;
        i->n_ramps++;
    }
    fclose(f);
}

static void forget_slopes(Instance* i) {
    for (size_t k = 0; k < i->n_ramps; ++k) i->slope[k] = NAN;
}

static int instantiable(fmi2Type type, fmi2String guid, char* why) {
    if (type != fmi2CoSimulation) {
        snprintf(why, WHY_SIZE, "fmi2Instantiate: this FMU is for co-simulation only "
                 "(fmuType %d asked, fmi2CoSimulation is %d)", (int)type, (int)fmi2CoSimulation);
        return 0;
    }
    char own[128];
    own_guid(own, sizeof own);
    if (own[0] && (guid == NULL || strcmp(guid, own) != 0)) {
        snprintf(why, WHY_SIZE, "fmi2Instantiate: GUID \"%.200s\" is not this FMU's (%s): the "
                 "model description the host read is of another FMU or another build of it",
                 guid ? guid : "(null)", own);
        return 0;
    }
    return 1;
}

/* -- FMI 2.0 ---------------------------------------------------------------------------------- */
EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }

EXPORT const char* fmi2GetVersion(void) { return "2.0"; }

static void free_categories(Instance* i) {
    for (size_t k = 0; k < i->n_categories; ++k) free(i->categories[k]);
    free(i->categories);
    i->categories = NULL;
    i->n_categories = 0;
}

static void free_instance(Instance* i) {
    free_categories(i);
    free(i->name);
    free(i);
}

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                     fmi2String fmuResourceLocation,
                                     const fmi2CallbackFunctions* functions, fmi2Boolean visible,
                                     fmi2Boolean loggingOn) {
    char why[WHY_SIZE];
    const char* name = instanceName ? instanceName : "";
    if (!prepare(why)) {
        emit(functions, name, fmi2Error, "logStatusError", why);
        return NULL;
    }
    if (!instantiable(fmuType, fmuGUID, why)) {
        emit(functions, name, fmi2Error, "logStatusError", why);
        return NULL;
    }
    Instance* i = calloc(1, sizeof *i);
    if (i == NULL || (i->name = strdup(name)) == NULL) {
        free(i);
        emit(functions, name, fmi2Error, "logStatusError", "out of memory");
        return NULL;
    }
    if (functions) i->host = *functions;
    i->relayed = i->host;
    i->relayed.logger = relay;
    i->relayed.componentEnvironment = i;
    i->debug = loggingOn;
    read_ramps(i);
    /* The runtime cannot do without the resource location: where a host gives none, the
     * FMU's own resources/ beside binaries/ is meant. */
    char resources[PATH_MAX + 32];
    if (fmuResourceLocation == NULL || fmuResourceLocation[0] == '\0') {
        char binaries[PATH_MAX];
        if (!own_directory(binaries, sizeof binaries, why)) {
            emit(functions, name, fmi2Error, "logStatusError", why);
            free_instance(i);
            return NULL;
        }
        snprintf(resources, sizeof resources, "file://%s/../../resources", binaries);
    } else if (!resource_path(fmuResourceLocation, resources, sizeof resources, why)) {
        emit(functions, name, fmi2Error, "logStatusError", why);
        free_instance(i);
        return NULL;
    }
    /* The runtime logs with debug logging on, always: relay() does the filtering. */
    i->inner = runtime.fmi2Instantiate(instanceName, fmuType, fmuGUID, resources, &i->relayed,
                                       visible, 1);
    if (i->inner == NULL) { /* the runtime has logged why */
        free_instance(i);
        return NULL;
    }
    return i;
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    Instance* i = c;
    if (i == NULL) return;
    if (!i->failed) runtime.fmi2FreeInstance(i->inner);
    free_instance(i);
}

/* Whether `function` may be called now; if not, why is logged and the instance is in the
 * error state (FMI 2.0, 2.1.3: after fmi2Error only fmi2SetFMUstate to an earlier state,
 * fmi2Reset, reading values and fmi2FreeInstance). */
static int admit(Instance* i, const char* function, unsigned allowed) {
    if (i == NULL) return 0;
    if (i->failed) {
        char why[256];
        snprintf(why, sizeof why, "%s: the instance failed fatally before; only "
                 "fmi2FreeInstance may be called", function);
        emit(&i->host, i->name, fmi2Error, "logStatusError", why);
        return 0;
    }
    if (allowed & IN(i->phase)) {
        i->refused = 0;
        return 1;
    }
    char why[512];
    int n = snprintf(why, sizeof why, "%s: not allowed in state %s (FMI 2.0 allows it in: ",
                     function, PHASE_NAMES[i->phase]);
    const char* sep = "";
    for (int p = 0; p < N_PHASES && n > 0 && (size_t)n < sizeof why; ++p) {
        if (!(allowed & IN(p))) continue;
        n += snprintf(why + n, sizeof why - (size_t)n, "%s%s", sep, PHASE_NAMES[p]);
        sep = ", ";
    }
    if (n > 0 && (size_t)n < sizeof why)
        snprintf(why + n, sizeof why - (size_t)n, "%s)", allowed ? "" : "no state");
    emit(&i->host, i->name, fmi2Error, "logStatusError", why);
    i->phase = ERROR_STATE;
    return 0;
}

/* The status to answer: the runtime's, but fmi2Error where the FMU's code refused the call
 * (it logs why with fmi2Error and returns normally: an exception would be fmi2Fatal in
 * pythonfmu's runtime).  fmi2Error and fmi2Fatal move the instance to those states. */
static fmi2Status settle(Instance* i, fmi2Status status) {
    if (status == fmi2OK && i->refused) status = fmi2Error;
    if (status == fmi2Error) i->phase = ERROR_STATE;
    if (status == fmi2Fatal) {
        i->phase = FATAL_STATE;
        i->failed = 1;
    }
    return status;
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                                      const fmi2String categories[]) {
    Instance* i = c;
    if (!admit(i, "fmi2SetDebugLogging", ANY_BUT_FATAL)) return fmi2Error;
    free_categories(i);
    if (nCategories > 0 && categories) {
        i->categories = calloc(nCategories, sizeof *i->categories);
        if (i->categories == NULL) return fmi2Error;
        for (size_t k = 0; k < nCategories; ++k) {
            i->categories[k] = strdup(categories[k] ? categories[k] : "");
            if (i->categories[k] == NULL) return fmi2Error;
            i->n_categories = k + 1;
        }
    }
    i->debug = loggingOn;
    return fmi2OK;
}

#define FORWARD(name, allowed, params, args)                                                    \
    EXPORT fmi2Status name params {                                                             \
        Instance* i = c;                                                                        \
        if (!admit(i, #name, allowed)) return fmi2Error;                                        \
        return settle(i, runtime.name args);                                                    \
    }
FORWARDED_FUNCTIONS(FORWARD)

/* The calls that move the instance: to `next` when the runtime accepts. */
#define MOVE(name, next)                                                                        \
    EXPORT fmi2Status name(fmi2Component c) {                                                   \
        Instance* i = c;                                                                        \
        if (!admit(i, #name, ALLOWED_##name)) return fmi2Error;                                 \
        fmi2Status status = settle(i, runtime.name(i->inner));                                  \
        if (status == fmi2OK) i->phase = next;                                                  \
        return status;                                                                          \
    }
#define ALLOWED(name, allowed, params, args) enum { ALLOWED_##name = allowed };
OWN_FUNCTIONS(ALLOWED)
MOVE(fmi2EnterInitializationMode, INITIALIZATION_MODE)
MOVE(fmi2ExitInitializationMode, STEP_COMPLETE)
MOVE(fmi2Terminate, TERMINATED)

EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    Instance* i = c;
    if (!admit(i, "fmi2Reset", ALLOWED_fmi2Reset)) return fmi2Error;
    fmi2Status status = settle(i, runtime.fmi2Reset(i->inner));
    if (status == fmi2OK) {
        i->phase = INSTANTIATED;
        forget_slopes(i);
    }
    return status;
}

/* -- input derivatives ----------------------------------------------------------------------- */
/* Where u is among the inputs the FMU ramps (its index), -1 where it is a rate input (whose
 * derivative is not used), -2 where it is neither. */
static long ramp_of(const Instance* i, fmi2ValueReference vr) {
    for (size_t k = 0; k < i->n_ramps; ++k) {
        if (i->ramped[k] == vr) return (long)k;
        if (i->rate[k] == vr) return -1;
    }
    return -2;
}

EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                              size_t nvr, const fmi2Integer order[],
                                              const fmi2Real v[]) {
    Instance* i = c;
    if (!admit(i, "fmi2SetRealInputDerivatives", ALLOWED_fmi2SetRealInputDerivatives))
        return fmi2Error;
    char why[512];
    for (size_t n = 0; n < nvr; ++n) { /* all checked first: a refused call changes nothing */
        long k = ramp_of(i, vr[n]);
        if (i->n_ramps == 0)
            snprintf(why, sizeof why, "fmi2SetRealInputDerivatives: this FMU does not "
                     "interpolate its inputs (canInterpolateInputs is false)");
        else if (k == -2)
            snprintf(why, sizeof why, "fmi2SetRealInputDerivatives: value reference %u is no "
                     "input this FMU ramps through a step", (unsigned)vr[n]);
        else if (order[n] < 1)
            snprintf(why, sizeof why, "fmi2SetRealInputDerivatives: order %d of value "
                     "reference %u; the order of a derivative is 1 or more", (int)order[n],
                     (unsigned)vr[n]);
        else if (!isfinite(v[n]))
            snprintf(why, sizeof why, "fmi2SetRealInputDerivatives: the derivative of value "
                     "reference %u is not finite", (unsigned)vr[n]);
        else
            continue;
        emit(&i->host, i->name, fmi2Error, "logStatusError", why);
        return settle(i, fmi2Error);
    }
    for (size_t n = 0; n < nvr; ++n) {
        long k = ramp_of(i, vr[n]);
        if (k >= 0 && order[n] == 1) i->slope[k] = v[n];
    }
    return fmi2OK;
}

/* Set the inputs of the step's ramps (the value at the step's middle and the rate) into
 * the runtime, and what they were into `held`; 0 where no derivative is set. */
static size_t set_ramps(Instance* i, fmi2Real h, fmi2ValueReference vrs[], fmi2Real held[],
                        fmi2Status* status) {
    size_t n = 0;
    for (size_t k = 0; k < i->n_ramps; ++k) {
        if (isnan(i->slope[k])) continue;
        vrs[n] = i->ramped[k];
        vrs[n + 1] = i->rate[k];
        n += 2;
    }
    *status = fmi2OK;
    if (n == 0) return 0;
    *status = settle(i, runtime.fmi2GetReal(i->inner, vrs, n, held));
    if (*status != fmi2OK && *status != fmi2Warning) return 0;
    fmi2Real ramp[2 * MAX_RAMPS];
    size_t m = 0;
    for (size_t k = 0; k < i->n_ramps; ++k) {
        if (isnan(i->slope[k])) continue;
        ramp[m] = held[m] + i->slope[k] * (0.5 * h);
        ramp[m + 1] = i->slope[k];
        m += 2;
    }
    *status = settle(i, runtime.fmi2SetReal(i->inner, vrs, n, ramp));
    return (*status == fmi2OK || *status == fmi2Warning) ? n : 0;
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                             fmi2Real communicationStepSize,
                             fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint) {
    Instance* i = c;
    if (!admit(i, "fmi2DoStep", ALLOWED_fmi2DoStep)) return fmi2Error;
    fmi2ValueReference vrs[2 * MAX_RAMPS];
    fmi2Real held[2 * MAX_RAMPS];
    fmi2Status status;
    size_t ramped = set_ramps(i, communicationStepSize, vrs, held, &status);
    if (status != fmi2OK && status != fmi2Warning) return status;
    status = settle(i, runtime.fmi2DoStep(i->inner, currentCommunicationPoint,
                                          communicationStepSize,
                                          noSetFMUStatePriorToCurrentCommunicationPoint));
    if (ramped > 0 && !i->failed) {
        /* each input where its ramp is at the step end (where the step was not taken:
         * as set), each rate input as it was */
        if (status == fmi2OK || status == fmi2Warning) {
            size_t m = 0;
            for (size_t k = 0; k < i->n_ramps; ++k) {
                if (isnan(i->slope[k])) continue;
                held[m] += i->slope[k] * communicationStepSize;
                m += 2;
            }
        }
        fmi2Status back = settle(i, runtime.fmi2SetReal(i->inner, vrs, ramped, held));
        if (back > status) status = back;
    }
    if (status == fmi2OK) i->phase = STEP_COMPLETE;
    if (status == fmi2Discard) i->phase = STEP_FAILED;
    return status;
}

/* -- FMU states ------------------------------------------------------------------------------ */
/* What the host holds as an FMU state: the runtime's, with the state-machine state it was
 * taken in, marked as this FMU's (a state of another FMU is refused, not handed on). */
#define STATE_MARK 0x6d637373u /* "mcss" */
typedef struct {
    unsigned mark;
    const void* owner; /* this loader's copy: one per FMU binary */
    int phase;
    fmi2Real slope[MAX_RAMPS]; /* the input derivatives set */
    fmi2FMUstate inner;
} SavedState;

static SavedState* own_state(Instance* i, const char* function, fmi2FMUstate state) {
    SavedState* saved = state;
    if (saved != NULL && saved->mark == STATE_MARK && saved->owner == (const void*)&runtime)
        return saved;
    char why[256];
    snprintf(why, sizeof why, "%s: the FMU state given is %s", function,
             state == NULL ? "NULL" : "not one this FMU made (another FMU's, or freed)");
    emit(&i->host, i->name, fmi2Error, "logStatusError", why);
    i->phase = ERROR_STATE;
    return NULL;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* state) {
    Instance* i = c;
    if (!admit(i, "fmi2GetFMUstate", ALLOWED_fmi2GetFMUstate)) return fmi2Error;
    if (state == NULL) {
        emit(&i->host, i->name, fmi2Error, "logStatusError", "fmi2GetFMUstate: state is NULL");
        return settle(i, fmi2Error);
    }
    SavedState* saved = NULL;
    if (*state != NULL) { /* FMI 2.0: a state given is updated in place */
        if ((saved = own_state(i, "fmi2GetFMUstate", *state)) == NULL) return fmi2Error;
        fmi2Status freed = settle(i, runtime.fmi2FreeFMUstate(i->inner, &saved->inner));
        if (freed != fmi2OK) return freed;
    } else if ((saved = calloc(1, sizeof *saved)) == NULL) {
        emit(&i->host, i->name, fmi2Error, "logStatusError", "fmi2GetFMUstate: out of memory");
        return settle(i, fmi2Error);
    }
    saved->inner = NULL;
    fmi2Status status = settle(i, runtime.fmi2GetFMUstate(i->inner, &saved->inner));
    if (status != fmi2OK) {
        free(saved);
        *state = NULL;
        return status;
    }
    saved->mark = STATE_MARK;
    saved->owner = (const void*)&runtime;
    saved->phase = i->phase;
    memcpy(saved->slope, i->slope, sizeof saved->slope);
    *state = saved;
    return status;
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    Instance* i = c;
    if (!admit(i, "fmi2SetFMUstate", ALLOWED_fmi2SetFMUstate)) return fmi2Error;
    SavedState* saved = own_state(i, "fmi2SetFMUstate", state);
    if (saved == NULL) return fmi2Error;
    fmi2Status status = settle(i, runtime.fmi2SetFMUstate(i->inner, saved->inner));
    if (status == fmi2OK) {
        i->phase = saved->phase;
        memcpy(i->slope, saved->slope, sizeof i->slope);
    }
    return status;
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* state) {
    Instance* i = c;
    if (!admit(i, "fmi2FreeFMUstate", ALLOWED_fmi2FreeFMUstate)) return fmi2Error;
    if (state == NULL || *state == NULL) return fmi2OK; /* nothing to free */
    SavedState* saved = own_state(i, "fmi2FreeFMUstate", *state);
    if (saved == NULL) return fmi2Error;
    fmi2Status status = settle(i, runtime.fmi2FreeFMUstate(i->inner, &saved->inner));
    saved->mark = 0;
    free(saved);
    *state = NULL;
    return status;
}

/* Serialized: a mark and the state-machine state (4 bytes each), the input derivatives,
 * then the runtime's bytes. */
#define STATE_HEADER (8 + MAX_RAMPS * sizeof(fmi2Real))
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t* size) {
    Instance* i = c;
    if (!admit(i, "fmi2SerializedFMUstateSize", ALLOWED_fmi2SerializedFMUstateSize))
        return fmi2Error;
    SavedState* saved = own_state(i, "fmi2SerializedFMUstateSize", state);
    if (saved == NULL) return fmi2Error;
    size_t inner = 0;
    fmi2Status status =
        settle(i, runtime.fmi2SerializedFMUstateSize(i->inner, saved->inner, &inner));
    if (status == fmi2OK && size) *size = inner + STATE_HEADER;
    return status;
}

EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[],
                                        size_t size) {
    Instance* i = c;
    if (!admit(i, "fmi2SerializeFMUstate", ALLOWED_fmi2SerializeFMUstate)) return fmi2Error;
    SavedState* saved = own_state(i, "fmi2SerializeFMUstate", state);
    if (saved == NULL) return fmi2Error;
    if (size < STATE_HEADER) return settle(i, fmi2Error);
    unsigned header[2] = {STATE_MARK, (unsigned)saved->phase};
    memcpy(bytes, header, sizeof header);
    memcpy(bytes + sizeof header, saved->slope, sizeof saved->slope);
    return settle(i, runtime.fmi2SerializeFMUstate(i->inner, saved->inner, bytes + STATE_HEADER,
                                                   size - STATE_HEADER));
}

EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size,
                                          fmi2FMUstate* state) {
    Instance* i = c;
    if (!admit(i, "fmi2DeSerializeFMUstate", ALLOWED_fmi2DeSerializeFMUstate)) return fmi2Error;
    unsigned header[2] = {0, 0};
    if (bytes != NULL && size >= STATE_HEADER) memcpy(header, bytes, sizeof header);
    if (state == NULL || header[0] != STATE_MARK || header[1] >= N_PHASES) {
        emit(&i->host, i->name, fmi2Error, "logStatusError",
             "fmi2DeSerializeFMUstate: the bytes given are no FMU state this FMU serialized");
        return settle(i, fmi2Error);
    }
    SavedState* saved = calloc(1, sizeof *saved);
    if (saved == NULL) return settle(i, fmi2Error);
    fmi2Status status = settle(i, runtime.fmi2DeSerializeFMUstate(
                                      i->inner, bytes + STATE_HEADER, size - STATE_HEADER,
                                      &saved->inner));
    if (status != fmi2OK) {
        free(saved);
        return status;
    }
    saved->mark = STATE_MARK;
    saved->owner = (const void*)&runtime;
    saved->phase = (int)header[1];
    memcpy(saved->slope, bytes + sizeof header, sizeof saved->slope);
    *state = saved;
    return status;
}
