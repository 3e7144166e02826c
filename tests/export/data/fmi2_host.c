/* A minimal FMI 2.0 co-simulation host without Python, to check that the creep-force FMU runs
 * from a non-Python simulator (given the Python shared library and the package on the host).
 *
 * usage: fmi2_host BINARY RESOURCE_URI GUID N_IN VR VALUE ... N_OUT VR ...
 * Instantiates the FMU, sets the inputs, performs one doStep and prints the status and the
 * outputs, one per line with 17 significant digits. Exit code 0 on success. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

typedef void *Component;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*release)(void *);
    void (*step_finished)(void *, int);
    void *environment;
} Callbacks;

static void logger(void *env, const char *name, int status, const char *category,
                   const char *message, ...) {
    va_list args;
    (void)env;
    (void)name;
    va_start(args, message);
    fprintf(stderr, "[%d %s] ", status, category);
    vfprintf(stderr, message, args);
    fprintf(stderr, "\n");
    va_end(args);
}

int main(int argc, char **argv) {
    if (argc < 5) return 64;
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        printf("dlopen failed: %s\n", dlerror());
        return 3;
    }
    Component (*instantiate)(const char *, int, const char *, const char *, const Callbacks *,
                             int, int) = dlsym(lib, "fmi2Instantiate");
    int (*setup)(Component, int, double, double, int, double) = dlsym(lib, "fmi2SetupExperiment");
    int (*enter)(Component) = dlsym(lib, "fmi2EnterInitializationMode");
    int (*leave)(Component) = dlsym(lib, "fmi2ExitInitializationMode");
    int (*set_real)(Component, const unsigned *, size_t, const double *) =
        dlsym(lib, "fmi2SetReal");
    int (*get_real)(Component, const unsigned *, size_t, double *) = dlsym(lib, "fmi2GetReal");
    int (*do_step)(Component, double, double, int) = dlsym(lib, "fmi2DoStep");
    void (*release)(Component) = dlsym(lib, "fmi2FreeInstance");
    Callbacks callbacks = {logger, calloc, free, NULL, NULL};
    Component c = instantiate("host", 1, argv[3], argv[2], &callbacks, 0, 0);
    if (!c) {
        printf("instantiate failed\n");
        return 4;
    }
    if (setup(c, 0, 0.0, 0, 0, 0.0) || enter(c) || leave(c)) return 5;
    int i = 4, n_in = atoi(argv[i++]);
    for (int k = 0; k < n_in; k++, i += 2) {
        unsigned vr = (unsigned)strtoul(argv[i], NULL, 10);
        double value = strtod(argv[i + 1], NULL);
        if (set_real(c, &vr, 1, &value)) return 6;
    }
    int status = do_step(c, 0.0, 1e-3, 1);
    printf("status %d\n", status);
    int n_out = atoi(argv[i++]);
    for (int k = 0; k < n_out; k++, i++) {
        unsigned vr = (unsigned)strtoul(argv[i], NULL, 10);
        double value;
        if (get_real(c, &vr, 1, &value)) return 7;
        printf("%.17g\n", value);
    }
    release(c);
    return status;
}
