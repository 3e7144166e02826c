/* A small FMI 2.0 co-simulation host without Python, for the tests and the benchmark.
 *
 * One-shot mode (the Python FMU, run with libpython preloaded):
 *   fmi2_host BINARY RESOURCE_URI GUID N_IN VR VALUE ... N_OUT VR ...
 * instantiates the FMU, sets the inputs, performs one doStep and prints the status and the
 * outputs, one per line with 17 significant digits. Exit code 0 on success.
 *
 * Script mode (the native FMUs: no preload, no Python in the process):
 *   fmi2_host --script BINARY RESOURCE_URI GUID  < commands
 * reads one command a line and prints one answer line each (statuses are fmi2Status numbers,
 * values %.17g); the FMU's log goes to stderr as "log STATUS CATEGORY NAME: MESSAGE".
 *   new I [GUID]                  instantiate slot I (0-7)        -> new I ok|null
 *   init I                        setup (t = 0), enter, exit       -> init I S
 *   set I VR VALUE                fmi2SetReal                      -> set I S
 *   get I VR...                   fmi2GetReal                      -> get I S V...
 *   step I T H                    fmi2DoStep                       -> step I S
 *   save|load|drop I K            Get/Set/FreeFMUstate, state K    -> save I S ...
 *   roundtrip I K                 serialize state K, deserialize it into K -> roundtrip I S
 *   reset|terminate|free I                                         -> reset I S ...
 *   allocs                        allocateMemory calls so far      -> allocs N FREES
 *   maps                          mapped files naming python/numba -> maps N
 *   sweep I NIN VR.. NOUT VR.. N  then N lines of NIN values: set, doStep (h = 1 ms), get
 *                                 -> N lines "S V..."
 *   bench I NIN VR.. NOUT VR.. N REPEAT  then N lines of inputs: REPEAT passes of set + doStep +
 *                                 get over the rows, then REPEAT passes of doStep alone
 *                                 -> bench NS_PER_STEP NS_PER_DOSTEP ALLOCS_DURING STATUS
 *                                    CPU_NS_PER_STEP CPU_NS_PER_DOSTEP (wall clock, then this
 *                                    thread's CPU time: on a busy machine, the time it ran)
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef void *Component;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*release)(void *);
    void (*step_finished)(void *, int);
    void *environment;
} Callbacks;

static long n_allocs = 0, n_frees = 0;

static void *counting_calloc(size_t n, size_t size) {
    n_allocs++;
    return calloc(n, size);
}

static void counting_free(void *p) {
    if (p != NULL) n_frees++;
    free(p);
}

static void logger(void *env, const char *name, int status, const char *category,
                   const char *message, ...) {
    va_list args;
    (void)env;
    va_start(args, message);
    fprintf(stderr, "log %d %s %s: ", status, category, name);
    vfprintf(stderr, message, args);
    fprintf(stderr, "\n");
    va_end(args);
}

typedef struct {
    Component (*instantiate)(const char *, int, const char *, const char *, const Callbacks *,
                             int, int);
    void (*free_instance)(Component);
    int (*setup)(Component, int, double, double, int, double);
    int (*enter)(Component);
    int (*leave)(Component);
    int (*terminate)(Component);
    int (*reset)(Component);
    int (*set_real)(Component, const unsigned *, size_t, const double *);
    int (*get_real)(Component, const unsigned *, size_t, double *);
    int (*do_step)(Component, double, double, int);
    int (*get_state)(Component, void **);
    int (*set_state)(Component, void *);
    int (*free_state)(Component, void **);
    int (*state_size)(Component, void *, size_t *);
    int (*serialize)(Component, void *, char *, size_t);
    int (*deserialize)(Component, const char *, size_t, void **);
} Api;

static int bind(void *lib, Api *api) {
    api->instantiate = dlsym(lib, "fmi2Instantiate");
    api->free_instance = dlsym(lib, "fmi2FreeInstance");
    api->setup = dlsym(lib, "fmi2SetupExperiment");
    api->enter = dlsym(lib, "fmi2EnterInitializationMode");
    api->leave = dlsym(lib, "fmi2ExitInitializationMode");
    api->terminate = dlsym(lib, "fmi2Terminate");
    api->reset = dlsym(lib, "fmi2Reset");
    api->set_real = dlsym(lib, "fmi2SetReal");
    api->get_real = dlsym(lib, "fmi2GetReal");
    api->do_step = dlsym(lib, "fmi2DoStep");
    api->get_state = dlsym(lib, "fmi2GetFMUstate");
    api->set_state = dlsym(lib, "fmi2SetFMUstate");
    api->free_state = dlsym(lib, "fmi2FreeFMUstate");
    api->state_size = dlsym(lib, "fmi2SerializedFMUstateSize");
    api->serialize = dlsym(lib, "fmi2SerializeFMUstate");
    api->deserialize = dlsym(lib, "fmi2DeSerializeFMUstate");
    return api->instantiate && api->free_instance && api->setup && api->enter && api->leave &&
           api->set_real && api->get_real && api->do_step;
}

static const Callbacks callbacks = {logger, counting_calloc, counting_free, NULL, NULL};

static int one_shot(const Api *api, int argc, char **argv) {
    Component c = api->instantiate("host", 1, argv[3], argv[2], &callbacks, 0, 0);
    int i = 4, n_in, status, n_out;
    if (!c) {
        printf("instantiate failed\n");
        return 4;
    }
    if (api->setup(c, 0, 0.0, 0, 0, 0.0) || api->enter(c) || api->leave(c)) return 5;
    n_in = atoi(argv[i++]);
    for (int k = 0; k < n_in && i + 1 < argc; k++, i += 2) {
        unsigned vr = (unsigned)strtoul(argv[i], NULL, 10);
        double value = strtod(argv[i + 1], NULL);
        if (api->set_real(c, &vr, 1, &value)) return 6;
    }
    status = api->do_step(c, 0.0, 1e-3, 1);
    printf("status %d\n", status);
    n_out = i < argc ? atoi(argv[i++]) : 0;
    for (int k = 0; k < n_out && i < argc; k++, i++) {
        unsigned vr = (unsigned)strtoul(argv[i], NULL, 10);
        double value;
        if (api->get_real(c, &vr, 1, &value)) return 7;
        printf("%.17g\n", value);
    }
    api->free_instance(c);
    return status;
}

/* ---- script mode -------------------------------------------------------------------------- */

#define SLOTS 8
#define MAX_VARS 256
#define LINE 1048576

static char line[LINE];

static char *token(void) { return strtok(NULL, " \t\r\n"); }

static int read_refs(unsigned *refs) {
    int n = atoi(token());
    for (int k = 0; k < n && k < MAX_VARS; k++) refs[k] = (unsigned)strtoul(token(), NULL, 10);
    return n;
}

static double *read_rows(int rows, int n_in) {
    double *values = malloc(sizeof(double) * (size_t)(rows * n_in + 1));
    for (int r = 0; r < rows; r++) {
        char *t;
        if (!fgets(line, LINE, stdin)) exit(65);
        t = strtok(line, " \t\r\n");
        for (int k = 0; k < n_in; k++, t = strtok(NULL, " \t\r\n"))
            values[r * n_in + k] = t ? strtod(t, NULL) : 0.0;
    }
    return values;
}

static double seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static double cpu_seconds(void) { /* this thread's CPU time: not the time it waited */
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int script(const Api *api, const char *resources, const char *guid) {
    Component slot[SLOTS] = {0};
    void *state[SLOTS] = {0};
    double time[SLOTS] = {0};
    unsigned in[MAX_VARS], out[MAX_VARS];
    double values[MAX_VARS];
    while (fgets(line, LINE, stdin)) {
        char *cmd = strtok(line, " \t\r\n"), *arg;
        int i, s = 0;
        if (cmd == NULL) continue;
        if (strcmp(cmd, "quit") == 0) break;
        if (strcmp(cmd, "maps") == 0) { /* is a Python library mapped into this process? */
            FILE *maps = fopen("/proc/self/maps", "r");
            char row[4096];
            int python = 0;
            while (maps && fgets(row, sizeof row, maps))
                python += strstr(row, "python") != NULL || strstr(row, "numba") != NULL;
            if (maps) fclose(maps);
            printf("maps %d\n", python);
            fflush(stdout);
            continue;
        }
        if (strcmp(cmd, "allocs") == 0) {
            printf("allocs %ld %ld\n", n_allocs, n_frees);
            fflush(stdout);
            continue;
        }
        arg = token();
        i = arg ? atoi(arg) % SLOTS : 0;
        if (strcmp(cmd, "new") == 0) {
            char *g = token();
            char name[16];
            snprintf(name, sizeof name, "i%d", i);
            slot[i] = api->instantiate(name, 1, g ? g : guid, resources, &callbacks, 0, 0);
            printf("new %d %s\n", i, slot[i] ? "ok" : "null");
        } else if (strcmp(cmd, "init") == 0) {
            s = api->setup(slot[i], 0, 0.0, 0.0, 0, 0.0);
            if (s == 0) s = api->enter(slot[i]);
            if (s == 0) s = api->leave(slot[i]);
            printf("init %d %d\n", i, s);
        } else if (strcmp(cmd, "set") == 0) {
            unsigned vr = (unsigned)strtoul(token(), NULL, 10);
            double v = strtod(token(), NULL);
            printf("set %d %d\n", i, api->set_real(slot[i], &vr, 1, &v));
        } else if (strcmp(cmd, "get") == 0) {
            int n = 0;
            for (char *t = token(); t && n < MAX_VARS; t = token()) in[n++] = strtoul(t, NULL, 10);
            s = api->get_real(slot[i], in, (size_t)n, values);
            printf("get %d %d", i, s);
            for (int k = 0; k < n; k++) printf(" %.17g", values[k]);
            printf("\n");
        } else if (strcmp(cmd, "step") == 0) {
            double t = strtod(token(), NULL), h = strtod(token(), NULL);
            printf("step %d %d\n", i, api->do_step(slot[i], t, h, 0));
        } else if (strcmp(cmd, "save") == 0 || strcmp(cmd, "load") == 0 ||
                   strcmp(cmd, "drop") == 0 || strcmp(cmd, "roundtrip") == 0) {
            int k = atoi(token()) % SLOTS;
            if (cmd[0] == 's') s = api->get_state(slot[i], &state[k]);
            else if (cmd[0] == 'l') s = api->set_state(slot[i], state[k]);
            else if (cmd[0] == 'd') s = api->free_state(slot[i], &state[k]);
            else {
                size_t size = 0;
                char *bytes;
                s = api->state_size(slot[i], state[k], &size);
                bytes = malloc(size ? size : 1);
                if (s == 0) s = api->serialize(slot[i], state[k], bytes, size);
                if (s == 0) s = api->free_state(slot[i], &state[k]);
                if (s == 0) s = api->deserialize(slot[i], bytes, size, &state[k]);
                free(bytes);
            }
            printf("%s %d %d\n", cmd, i, s);
        } else if (strcmp(cmd, "reset") == 0) {
            printf("reset %d %d\n", i, api->reset(slot[i]));
        } else if (strcmp(cmd, "terminate") == 0) {
            printf("terminate %d %d\n", i, api->terminate(slot[i]));
        } else if (strcmp(cmd, "free") == 0) {
            api->free_instance(slot[i]);
            slot[i] = NULL;
            printf("free %d 0\n", i);
        } else if (strcmp(cmd, "sweep") == 0 || strcmp(cmd, "bench") == 0) {
            int sweep = cmd[1] == 'w'; /* before read_rows overwrites the line */
            int n_in = read_refs(in), n_out = read_refs(out), rows = atoi(token());
            int repeat = sweep ? 1 : atoi(token());
            double *table = read_rows(rows, n_in), t0, c0, t_full, t_step, c_full, c_step;
            long allocs_before = n_allocs;
            if (sweep) {
                for (int r = 0; r < rows; r++) {
                    s = api->set_real(slot[i], in, (size_t)n_in, table + r * n_in);
                    if (s == 0) s = api->do_step(slot[i], time[i], 1e-3, 1);
                    time[i] += 1e-3;
                    if (s == 0) s = api->get_real(slot[i], out, (size_t)n_out, values);
                    printf("%d", s);
                    for (int k = 0; k < n_out; k++) printf(" %.17g", s == 0 ? values[k] : 0.0);
                    printf("\n");
                }
            } else {
                t0 = seconds();
                c0 = cpu_seconds();
                for (int p = 0; p < repeat; p++)
                    for (int r = 0; r < rows; r++) {
                        s |= api->set_real(slot[i], in, (size_t)n_in, table + r * n_in);
                        s |= api->do_step(slot[i], time[i], 1e-3, 1);
                        time[i] += 1e-3;
                        s |= api->get_real(slot[i], out, (size_t)n_out, values);
                    }
                t_full = (seconds() - t0) / ((double)repeat * rows);
                c_full = (cpu_seconds() - c0) / ((double)repeat * rows);
                t0 = seconds();
                c0 = cpu_seconds();
                for (int p = 0; p < repeat; p++)
                    for (int r = 0; r < rows; r++) {
                        s |= api->do_step(slot[i], time[i], 1e-3, 1);
                        time[i] += 1e-3;
                    }
                t_step = (seconds() - t0) / ((double)repeat * rows);
                c_step = (cpu_seconds() - c0) / ((double)repeat * rows);
                printf("bench %.3f %.3f %ld %d %.3f %.3f\n", t_full * 1e9, t_step * 1e9,
                       n_allocs - allocs_before, s, c_full * 1e9, c_step * 1e9);
            }
            free(table);
        } else {
            printf("unknown %s\n", cmd);
        }
        fflush(stdout);
    }
    return 0;
}

int main(int argc, char **argv) {
    int scripted = argc > 1 && strcmp(argv[1], "--script") == 0;
    char **a = argv + scripted;
    void *lib;
    Api api;
    if (argc - scripted < 4) return 64;
    lib = dlopen(a[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        printf("dlopen failed: %s\n", dlerror());
        return 3;
    }
    if (!bind(lib, &api)) {
        printf("missing FMI functions\n");
        return 8;
    }
    return scripted ? script(&api, a[2], a[3]) : one_shot(&api, argc, argv);
}
