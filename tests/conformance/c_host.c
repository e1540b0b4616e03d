/* A host that is not Python, as a C or C++ co-simulation tool is: it loads each FMU's library
   with dlopen (so pythonfmu starts the interpreter and owns it), instantiates one instance of
   each, steps them with their inputs at start values, frees them and unloads the libraries
   ("free") or leaves them alive ("keep"), and returns from main (exit()). Prints the worst
   fmi2DoStep status. Used by test_exit.py.

   Usage: c_host free|keep STEPS LIBRARY GUID RESOURCE_URI [LIBRARY GUID RESOURCE_URI ...] */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct { void *logger, *allocate, *release, *step_finished, *env; } callbacks;
typedef void *(*instantiate_t)(const char *, int, const char *, const char *, const callbacks *, int, int);
typedef int (*setup_t)(void *, int, double, double, int, double);
typedef int (*call_t)(void *);
typedef int (*step_t)(void *, double, double, int);
typedef void (*free_t)(void *);

static void logger(void *env, const char *name, int status, const char *category, const char *message, ...) {
    fprintf(stderr, "[%d] %s: %s\n", status, name, message);
}

int main(int argc, char **argv) {
    if (argc < 6 || (argc - 3) % 3 != 0 || (argc - 3) / 3 > 16) {
        fprintf(stderr, "usage: c_host free|keep STEPS LIBRARY GUID RESOURCE_URI ...\n");
        return 2;
    }
    int keep = strcmp(argv[1], "keep") == 0, steps = atoi(argv[2]), n = (argc - 3) / 3;
    callbacks cb = {(void *)logger, (void *)calloc, (void *)free, NULL, NULL};
    void *lib[16], *comp[16];
    for (int i = 0; i < n; i++) {
        lib[i] = dlopen(argv[3 + 3 * i], RTLD_NOW | RTLD_LOCAL);
        if (!lib[i]) { fprintf(stderr, "%s\n", dlerror()); return 3; }
        instantiate_t inst = (instantiate_t)dlsym(lib[i], "fmi2Instantiate");
        comp[i] = inst("c", 1, argv[4 + 3 * i], argv[5 + 3 * i], &cb, 0, 0);
        if (!comp[i]) { fprintf(stderr, "fmi2Instantiate failed\n"); return 4; }
        ((setup_t)dlsym(lib[i], "fmi2SetupExperiment"))(comp[i], 0, 0.0, 0.0, 0, 0.0);
        ((call_t)dlsym(lib[i], "fmi2EnterInitializationMode"))(comp[i]);
        ((call_t)dlsym(lib[i], "fmi2ExitInitializationMode"))(comp[i]);
    }
    int worst = 0;
    for (int k = 0; k < steps; k++)
        for (int i = 0; i < n; i++) {
            int s = ((step_t)dlsym(lib[i], "fmi2DoStep"))(comp[i], k * 0.05, 0.05, 1);
            if (s > worst) worst = s;
        }
    if (!keep)
        for (int i = 0; i < n; i++) {
            ((call_t)dlsym(lib[i], "fmi2Terminate"))(comp[i]);
            ((free_t)dlsym(lib[i], "fmi2FreeInstance"))(comp[i]);
            dlclose(lib[i]);
        }
    printf("worst status %d\n", worst);
    return 0;   /* exit() */
}
