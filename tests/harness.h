/* Shared by the test programs that print PASS/FAIL/SKIP lines (every suite but the Criterion
 * unit tests and tests/osd_agree.cpp): the counts and the closing line "N passed, N failed,
 * N skipped", the seed and one deterministic random number generator, a clock, the backends
 * under test and the contexts on them, file reading. Include after surfblend.h (and after
 * _POSIX_C_SOURCE, for the monotonic clock). Everything is static inline, so a program that does
 * not use a helper gets no warning for it; C99 and C++. */
#ifndef SFB_TEST_HARNESS_H
#define SFB_TEST_HARNESS_H
#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#if defined(__GNUC__)
#define SFB_TEST_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define SFB_TEST_PRINTF(f, a)
#endif

/* ---- results ---- */

static int g_pass, g_fail, g_skip;
/* The seed of the run's random data (harness_seed); once set, every FAIL line ends in
 * " (seed S)" so that the failure can be replayed. */
static unsigned long long g_seed;
static int g_seed_in_fail;

/* Each line is flushed: a crash keeps what came before, a forked child does not repeat it. */
static inline void pass(const char *name) {
    g_pass++;
    printf("PASS %s\n", name);
    fflush(stdout);
}
static inline void vfail(const char *name, const char *fmt, va_list ap) {
    g_fail++;
    printf("FAIL %s: ", name);
    vprintf(fmt, ap);
    if (g_seed_in_fail) printf(" (seed %llu)", g_seed);
    printf("\n");
    fflush(stdout);
}
static inline void fail(const char *name, const char *fmt, ...) SFB_TEST_PRINTF(2, 3);
static inline void fail(const char *name, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt); vfail(name, fmt, ap); va_end(ap);
}
static inline void skip(const char *name, const char *why) {
    g_skip++;
    printf("SKIP %s: %s\n", name, why);
    fflush(stdout);
}
/* PASS when ok, else FAIL with the formatted reason. */
static inline void check(int ok, const char *name, const char *fmt, ...) SFB_TEST_PRINTF(3, 4);
static inline void check(int ok, const char *name, const char *fmt, ...) {
    va_list ap;
    if (ok) { pass(name); return; }
    va_start(ap, fmt); vfail(name, fmt, ap); va_end(ap);
}

/* The closing line alone (for programs without the backend table below); returns the exit code. */
static inline int close_tests(void) {
    printf("%d passed, %d failed, %d skipped\n", g_pass, g_fail, g_skip);
    return g_fail ? 1 : 0;
}

/* ---- seed, random numbers, clock ---- */

/* Sets g_seed: from `arg` (a --seed value) when not NULL, else SFB_SEED when set and not empty,
 * else the clock; FAIL lines name it from now on. Returns it. */
static inline unsigned long long harness_seed(const char *arg) {
    const char *env = getenv("SFB_SEED");
    if (arg) g_seed = strtoull(arg, NULL, 10);
    else if (env && *env) g_seed = strtoull(env, NULL, 10);
    else g_seed = (unsigned long long)time(NULL);
    g_seed_in_fail = 1;
    return g_seed;
}

/* splitmix64: deterministic, any 64-bit state is a good one. */
typedef struct rng { unsigned long long s; } rng;
static inline unsigned long long rng_next(rng *g) {
    unsigned long long z = (g->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
/* 0 .. n-1 (0 when n <= 1) */
static inline int rng_int(rng *g, int n) { return n <= 1 ? 0 : (int)(rng_next(g) % (unsigned long long)n); }
/* [0, 1), 53 bits */
static inline double rng_unit(rng *g) { return (double)(rng_next(g) >> 11) * (1.0 / 9007199254740992.0); }
static inline double rng_range(rng *g, double lo, double hi) { return lo + (hi - lo) * rng_unit(g); }
/* The generator of one stream of a seed: streams of one seed are independent. */
static inline rng rng_for(unsigned long long seed, unsigned long long stream) {
    rng g;
    g.s = seed ^ (stream * 0xD1B54A32D192ED03ull);
    rng_next(&g);
    return g;
}

/* Seconds on a monotonic clock (CPU time where the program did not ask for POSIX). */
static inline double now_s(void) {
#if defined(CLOCK_MONOTONIC)
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#else
    return (double)clock() / (double)CLOCKS_PER_SEC;
#endif
}

/* ---- memory and files ---- */

/* malloc that never returns NULL (an allocation failure ends the program with exit 2). */
static inline void *xmalloc(size_t n) {
    void *p = malloc(n ? n : 1);
    if (!p) {
        printf("FAIL setup: out of memory (%lu bytes)\n", (unsigned long)n);
        fflush(stdout);
        exit(2);
    }
    return p;
}

/* The whole file (NUL-terminated), or NULL. */
static inline char *slurp(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    char *b;
    long len;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) { fclose(f); return NULL; }
    b = (char *)malloc((size_t)len + 1);
    if (!b || fread(b, 1, (size_t)len, f) != (size_t)len) { fclose(f); free(b); return NULL; }
    fclose(f);
    b[len] = 0;
    *n = (size_t)len;
    return b;
}

static inline int harness_cmp_int(const void *a, const void *b) { const int x = *(const int *)a, y = *(const int *)b; return (x > y) - (x < y); }
static inline int harness_cmp_str(const void *a, const void *b) { return strcmp(*(const char *const *)a, *(const char *const *)b); }

/* The names of the .obj files in `dir` (the peer shapes) that start with one of the
 * comma-separated `prefixes` (NULL: any) and contain `match` (NULL: any), sorted; *n their
 * count. NULL (*n = 0, and a SKIP of "shapes") when the directory cannot be opened. Free with
 * free_names. */
static inline char **list_shapes(const char *dir, const char *prefixes, const char *match, int *n) {
    DIR *dp = dir ? opendir(dir) : NULL;
    struct dirent *de;
    char **names;
    int cap = 64;
    *n = 0;
    if (!dp) {
        char why[600];
        snprintf(why, sizeof why, "peer shapes directory not found (%s): pass it as the first argument", dir ? dir : "none given");
        skip("shapes", why);
        return NULL;
    }
    names = (char **)xmalloc(sizeof(char *) * (size_t)cap);
    while ((de = readdir(dp)) != NULL) {
        size_t len = strlen(de->d_name);
        int ok = !prefixes;
        const char *p = prefixes;
        if (len < 5 || strcmp(de->d_name + len - 4, ".obj") != 0) continue;
        while (p && *p && !ok) {
            const char *end = strchr(p, ',');
            size_t pl = end ? (size_t)(end - p) : strlen(p);
            ok = pl > 0 && strncmp(de->d_name, p, pl) == 0;
            p = end ? end + 1 : NULL;
        }
        if (!ok || (match && !strstr(de->d_name, match))) continue;
        if (*n == cap) {
            char **nn = (char **)xmalloc(sizeof(char *) * (size_t)cap * 2);
            memcpy(nn, names, sizeof(char *) * (size_t)cap);
            free(names);
            names = nn;
            cap *= 2;
        }
        names[*n] = (char *)xmalloc(len + 1);
        memcpy(names[(*n)++], de->d_name, len + 1);
    }
    closedir(dp);
    if (*n) qsort(names, (size_t)*n, sizeof *names, harness_cmp_str);
    return names;
}
static inline void free_names(char **names, int n) {
    int i;
    for (i = 0; i < n; ++i) free(names[i]);
    free(names);
}

/* The mesh of the .obj file dir/name, read on ctx; NULL, with the reason in why ("cannot read
 * PATH" or "sfb_mesh_read_obj: ERROR"), when it cannot be read. */
static inline sfb_mesh *load_obj(sfb_context *ctx, const char *dir, const char *name, char *why, size_t wn) {
    char path[4096];
    size_t size = 0;
    char *text;
    sfb_mesh *m = NULL;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    text = slurp(path, &size);
    if (!text) snprintf(why, wn, "cannot read %s/%s", dir, name);
    else if (sfb_mesh_read_obj(ctx, text, size, &m) != SFB_SUCCESS) {
        snprintf(why, wn, "sfb_mesh_read_obj: %s", sfb_last_error(ctx));
        m = NULL;
    }
    free(text);
    return m;
}

/* The diagonal of a mesh's bounding box. */
static inline double mesh_diag(const sfb_mesh *m) {
    sfb_mesh_info info;
    double d = 0.0;
    int k;
    sfb_mesh_get_info(m, &info);
    for (k = 0; k < 3; ++k) {
        double e = info.bbox_max[k] - info.bbox_min[k];
        d += e * e;
    }
    return sqrt(d);
}

/* ---- backends ---- */

/* Is `name` an item of the comma-separated `list` (spaces around items ignored)? */
static inline int listed(const char *list, const char *name) {
    size_t n = strlen(name);
    const char *p = list;
    while (p && *p) {
        const char *end = strchr(p, ',');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        while (len > 0 && *p == ' ') { ++p; --len; }
        while (len > 0 && p[len - 1] == ' ') --len;
        if (len == n && strncmp(p, name, n) == 0) return 1;
        p = end ? end + 1 : NULL;
    }
    return 0;
}

/* Does SFB_REQUIRE_BACKENDS (set by CI: "simd,gl,osmesa") name this backend? */
static inline int backend_required(const char *name) {
    const char *req = getenv("SFB_REQUIRE_BACKENDS");
    return req && listed(req, name);
}

/* Records a check that cannot run for want of a backend: FAIL when required, else SKIP; why
 * (a probe's report, say) loses its trailing newlines and spaces. */
static inline void unavailable(const char *name, int required, const char *why) {
    char line[700];
    size_t n;
    snprintf(line, sizeof line, "%s", why);
    n = strlen(line);
    while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == ' ')) line[--n] = 0;
    if (required) fail(name, "%s (required by SFB_REQUIRE_BACKENDS)", line);
    else skip(name, line);
}

/* A context on exactly this backend, with the rest of cfg (threads, logger,
 * gl_use_current_context), ignoring the environment; NULL when it cannot start. */
static inline sfb_context *make_context_with(sfb_context_config cfg, sfb_backend_kind kind) {
    sfb_context *ctx = NULL;
    cfg.backends = &kind;
    cfg.backend_count = 1;
    cfg.ignore_environment = 1;
    if (sfb_context_create(&cfg, &ctx) != SFB_SUCCESS) return NULL;
    return ctx;
}
static inline sfb_context *make_context(sfb_backend_kind kind) { return make_context_with(sfb_context_config_init(), kind); }
static inline sfb_context *make_context_threads(sfb_backend_kind kind, int threads) {
    sfb_context_config cfg = sfb_context_config_init();
    cfg.threads = threads;
    return make_context_with(cfg, kind);
}

/* A logger counting the lines that say seed 003's proxy raster ran on ref's kernel or on the
 * CPU instead of the context's backend's own (simd's bands, gl's and osmesa's GL raster):
 * suites check that a backend ran its own. */
static inline int *cpu_rasters(void) {
    static int count;
    return &count;
}
static inline void cpu_raster_logger(int level, const char *msg, void *user) {
    (void)level; (void)user;
    if (strstr(msg, "raster runs on the CPU") || strstr(msg, "lacks raster")) ++*cpu_rasters();
}

/* The backends under test, ref first: each with its own context when available. */
typedef struct backend {
    sfb_backend_kind kind;
    const char *name;
    sfb_context *ctx;
    int available, required;
    int excluded; /* left out of the run (--only): not tested, not reported */
    char why[512];
} backend;
static backend g_be[4];
static int g_nbe;

/* Probes ref, simd, gl and osmesa into g_be, printing "# name: available" or why not, each
 * context made from cfg (NULL: the defaults); with `only` (a comma-separated list, NULL: all)
 * the backends it does not name, ref aside, are left out of g_be. A backend named in
 * SFB_REQUIRE_BACKENDS is marked required (its checks then FAIL when it is missing). Returns 0
 * (after printing a failure and the closing line) when ref itself is unavailable. */
static inline int probe_backends_with(const sfb_context_config *cfg, const char *only) {
    static const sfb_backend_kind kinds[4] = {SFB_BACKEND_REF, SFB_BACKEND_SIMD, SFB_BACKEND_GL, SFB_BACKEND_OSMESA};
    int i;
    for (i = 0; i < 4; ++i) {
        backend *b = &g_be[g_nbe];
        memset(b, 0, sizeof *b);
        b->kind = kinds[i];
        b->name = sfb_backend_kind_name(kinds[i]);
        if (i > 0 && only && !listed(only, b->name)) continue;
        b->required = backend_required(b->name);
        if (sfb_backend_probe(b->kind, NULL, b->why, sizeof b->why) == SFB_SUCCESS &&
            (b->ctx = make_context_with(cfg ? *cfg : sfb_context_config_init(), b->kind)) != NULL &&
            !strcmp(sfb_context_backend_name(b->ctx), b->name))
            b->available = 1;
        printf("# %s: %s\n", b->name, b->available ? "available" : b->why);
        g_nbe++;
    }
    if (!g_be[0].available) { printf("FAIL probe/ref: %s\n0 passed, 1 failed, 0 skipped\n", g_be[0].why); return 0; }
    return 1;
}
static inline int probe_backends(void) { return probe_backends_with(NULL, NULL); }

/* The check `name` needs the backend named `backend`, unavailable for `why`: FAIL when
 * SFB_REQUIRE_BACKENDS names it, else SKIP ("BACKEND unavailable: why"). */
static inline void backend_unavailable(const char *name, const char *backend, const char *why) {
    char w[600];
    snprintf(w, sizeof w, "%s unavailable: %s", backend, why);
    unavailable(name, backend_required(backend), w);
}

/* Records the check `name` of an unavailable backend of g_be: FAIL when required, else SKIP. */
static inline void backend_missing(const backend *b, const char *name) {
    char why[600];
    if (b->excluded) return;
    snprintf(why, sizeof why, "%s unavailable: %s", b->name, b->why);
    unavailable(name, b->required, why);
}

/* Destroys the backends' contexts and prints the closing line; returns the exit code. */
static inline int finish_tests(void) {
    int i;
    for (i = 0; i < g_nbe; ++i)
        if (g_be[i].ctx) sfb_context_destroy(g_be[i].ctx);
    return close_tests();
}
#endif
