/* Shared by the test programs that print PASS/FAIL/SKIP lines (tests/shade.c, tests/trim.c,
 * tests/manifold.c): the counts and the closing line, the backends under test, file reading.
 * Include after surfblend.h. Everything is static inline, so a program that does not use a
 * helper gets no warning for it. */
#ifndef SFB_TEST_HARNESS_H
#define SFB_TEST_HARNESS_H
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_pass, g_fail, g_skip;

static inline void pass(const char *name) { g_pass++; printf("PASS %s\n", name); }
static inline void vfail(const char *name, const char *fmt, va_list ap) {
    g_fail++;
    printf("FAIL %s: ", name);
    vprintf(fmt, ap);
    printf("\n");
}
static inline void fail(const char *name, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt); vfail(name, fmt, ap); va_end(ap);
}
static inline void skip(const char *name, const char *why) { g_skip++; printf("SKIP %s: %s\n", name, why); }
/* PASS when ok, else FAIL with the formatted reason. */
static inline void check(int ok, const char *name, const char *fmt, ...) {
    va_list ap;
    if (ok) { pass(name); return; }
    va_start(ap, fmt); vfail(name, fmt, ap); va_end(ap);
}

/* The backends under test, ref first: each with its own context when available. */
typedef struct backend { sfb_backend_kind kind; const char *name; sfb_context *ctx; int available, required; char why[512]; } backend;
static backend g_be[4];
static int g_nbe;

/* Is `name` an item of the comma-separated `list`? */
static inline int listed(const char *list, const char *name) {
    size_t n = strlen(name);
    const char *p = list;
    while (p && *p) {
        if (!strncmp(p, name, n) && (p[n] == 0 || p[n] == ',')) return 1;
        p = strchr(p, ',');
        if (p) p++;
    }
    return 0;
}

/* A context on exactly this backend, ignoring the environment (NULL when it cannot start). */
static inline sfb_context *make_context(sfb_backend_kind kind) {
    sfb_context_config cfg = sfb_context_config_init();
    sfb_context *ctx = NULL;
    cfg.backends = &kind;
    cfg.backend_count = 1;
    cfg.ignore_environment = 1;
    if (sfb_context_create(&cfg, &ctx) != SFB_SUCCESS) return NULL;
    return ctx;
}

/* Probes ref, simd, gl and osmesa into g_be, printing "# name: available" or why not; a backend
 * named in SFB_REQUIRE_BACKENDS is marked required (its checks then FAIL when it is missing).
 * Returns 0 (after printing a failure and the closing line) when ref itself is unavailable. */
static inline int probe_backends(void) {
    static const sfb_backend_kind kinds[4] = {SFB_BACKEND_REF, SFB_BACKEND_SIMD, SFB_BACKEND_GL, SFB_BACKEND_OSMESA};
    const char *req = getenv("SFB_REQUIRE_BACKENDS");
    int i;
    for (i = 0; i < 4; ++i) {
        backend *b = &g_be[g_nbe];
        memset(b, 0, sizeof *b);
        b->kind = kinds[i];
        b->name = sfb_backend_kind_name(kinds[i]);
        b->required = req && listed(req, b->name);
        if (sfb_backend_probe(b->kind, NULL, b->why, sizeof b->why) == SFB_SUCCESS && (b->ctx = make_context(b->kind)) != NULL &&
            !strcmp(sfb_context_backend_name(b->ctx), b->name))
            b->available = 1;
        printf("# %s: %s\n", b->name, b->available ? "available" : b->why);
        g_nbe++;
    }
    if (!g_be[0].available) { printf("FAIL probe/ref: %s\n0 passed, 1 failed, 0 skipped\n", g_be[0].why); return 0; }
    return 1;
}

/* Records the check `name` of an unavailable backend: FAIL when required, else SKIP. */
static inline void backend_missing(const backend *b, const char *name) {
    if (b->required) fail(name, "required backend unavailable: %s", b->why);
    else skip(name, b->why);
}

/* Destroys the backends' contexts and prints the closing line; returns the exit code. */
static inline int finish_tests(void) {
    int i;
    for (i = 0; i < g_nbe; ++i)
        if (g_be[i].ctx) sfb_context_destroy(g_be[i].ctx);
    printf("%d passed, %d failed, %d skipped\n", g_pass, g_fail, g_skip);
    return g_fail ? 1 : 0;
}

/* The whole file (NUL-terminated), or NULL. */
static inline char *slurp(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    char *b;
    long len;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END); len = ftell(f); fseek(f, 0, SEEK_SET);
    if (len < 0) { fclose(f); return NULL; }
    b = (char *)malloc((size_t)len + 1);
    if (!b || fread(b, 1, (size_t)len, f) != (size_t)len) { fclose(f); free(b); return NULL; }
    fclose(f);
    b[len] = 0;
    *n = (size_t)len;
    return b;
}
#endif
