/* test_bad.c - surfblend must refuse malformed input cleanly.
 *
 * Reads the manifest $SFB_BAD_DIR/EXPECTED.txt (default tests/bad/EXPECTED.txt, relative to the
 * working directory). One line per file:
 *
 *     filename RESULT_NAME stage keyword
 *
 *   stage    "parse"                      sfb_mesh_read_obj must fail with RESULT_NAME
 *            "refine:LEVEL[:BUDGET_BYTES]" the file parses; sfb_surface_create (catmark, LEVEL,
 *                                         context memory_budget = BUDGET_BYTES) must fail
 *   keyword  lowercase text that must occur in the lowercased sfb_last_error() message
 *
 * Blank lines and lines starting with '#' are skipped.
 *
 * For every file the test checks the result code, that the message is non-empty, contains the
 * keyword and (for SFB_PARSE_ERROR) names the line, that sfb_last_error_info agrees with the
 * returned code, that sfb_result_string gives text, and - through a counting allocator in the
 * context config - that every allocation is freed once the context is destroyed.
 *
 * Build: gcc -std=c99 -I. tests/test_bad.c build/libsfb.o -lcriterion -lm -lpthread -ldl
 */
#define _POSIX_C_SOURCE 200809L

#include <criterion/criterion.h>
#include <criterion/parameterized.h>

#include <ctype.h>
#include <math.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "surfblend.h"

#define MAX_CASES 512

struct bad_case {
    char file[128];
    char result_name[48];
    char stage[48];
    char keyword[64];
    int manifest_line;
};

/* ------------------------------------------------------------------ manifest */

static const char *bad_dir(void)
{
    const char *d = getenv("SFB_BAD_DIR");
    return (d && d[0]) ? d : "tests/bad";
}

/* dir + "/" + file into out (truncated to cap; file names in the manifest are short). */
static void join_path(char *out, size_t cap, const char *dir, const char *file)
{
    size_t dl = strlen(dir), fl = strlen(file);
    if (dl > cap / 2) dl = cap / 2;
    if (fl > cap - dl - 2) fl = cap - dl - 2;
    memcpy(out, dir, dl);
    out[dl] = '/';
    memcpy(out + dl + 1, file, fl);
    out[dl + 1 + fl] = '\0';
}

static int result_from_name(const char *name, sfb_result *out)
{
#define X(n, v, text) if (strcmp(name, #n) == 0) { *out = n; return 1; }
    SFB_RESULT_LIST(X)
#undef X
    return 0;
}

static const char *result_name(sfb_result r)
{
    switch (r) {
#define X(n, v, text) case n: return #n;
        SFB_RESULT_LIST(X)
#undef X
    default: return "(unknown code)";
    }
}

/* stage "parse" -> *level = -1000 (unused). "refine:L[:B]" -> level, budget. Returns 0 on a bad stage. */
static int parse_stage(const char *stage, int *is_refine, long *level, size_t *budget)
{
    *is_refine = 0; *level = 0; *budget = 0;
    if (strcmp(stage, "parse") == 0) return 1;
    if (strncmp(stage, "refine:", 7) != 0) return 0;
    char *end;
    const char *p = stage + 7;
    long l = strtol(p, &end, 10);
    if (end == p) return 0;
    *is_refine = 1;
    *level = l;
    if (*end == '\0') return 1;
    if (*end != ':') return 0;
    p = end + 1;
    unsigned long long b = strtoull(p, &end, 10);
    if (end == p || *end != '\0' || b == 0) return 0;
    *budget = (size_t)b;
    return 1;
}

/* Reads the manifest into cases (up to max). Returns the entry count, or -1 if unreadable. */
static int read_manifest(struct bad_case *cases, int max)
{
    char path[1024];
    join_path(path, sizeof path, bad_dir(), "EXPECTED.txt");
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    char line[1024];
    int n = 0, lineno = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        char *s = line;
        while (isspace((unsigned char)*s)) s++;
        if (*s == '\0' || *s == '#') continue;
        if (n >= max) break;
        struct bad_case c;
        memset(&c, 0, sizeof c);
        c.manifest_line = lineno;
        int got = sscanf(s, "%127s %47s %47s %63s", c.file, c.result_name, c.stage, c.keyword);
        if (got != 4) {
            /* keep it as an entry so that the malformed manifest line fails loudly */
            snprintf(c.stage, sizeof c.stage, "malformed-manifest-line");
        }
        cases[n++] = c;
    }
    fclose(f);
    return n;
}

static unsigned char *read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 4096, n = 0;
    unsigned char *buf = malloc(cap);
    if (!buf) { fclose(f); return NULL; }
    for (;;) {
        if (n == cap) {
            unsigned char *nb = realloc(buf, cap * 2);
            if (!nb) { free(buf); fclose(f); return NULL; }
            buf = nb; cap *= 2;
        }
        size_t r = fread(buf + n, 1, cap - n, f);
        n += r;
        if (r == 0) break;
    }
    int err = ferror(f);
    fclose(f);
    if (err) { free(buf); return NULL; }
    *size = n; /* buf is never NULL, even for an empty file */
    return buf;
}

/* ------------------------------------------------------------------ counting allocator */

typedef struct counting {
    long allocs, frees, bad_frees, failed;
    long calls;      /* alloc + realloc calls, for fault injection */
    long fail_at;    /* the call with this 0-based number returns NULL; < 0: never */
    size_t live_bytes, peak_bytes;
} counting;

#define HDR 16
#define MAGIC_LIVE 0x5fb1a11cu
#define MAGIC_DEAD 0xdeadf5fbu

typedef struct { size_t size; unsigned magic; } hdr_t;

static int inject_failure(counting *c)
{
    long k = c->calls++;
    if (c->fail_at >= 0 && k == c->fail_at) { c->failed++; return 1; }
    return 0;
}

static void *count_alloc(size_t size, void *user)
{
    counting *c = user;
    if (inject_failure(c)) return NULL;
    if (size > (size_t)-1 - HDR) return NULL;
    unsigned char *p = malloc(size + HDR);
    if (!p) return NULL;
    hdr_t h = { size, MAGIC_LIVE };
    memcpy(p, &h, sizeof h);
    c->allocs++;
    c->live_bytes += size;
    if (c->live_bytes > c->peak_bytes) c->peak_bytes = c->live_bytes;
    return p + HDR;
}

static void count_free(void *ptr, void *user)
{
    counting *c = user;
    if (!ptr) return;
    unsigned char *p = (unsigned char *)ptr - HDR;
    hdr_t h;
    memcpy(&h, p, sizeof h);
    if (h.magic != MAGIC_LIVE) { c->bad_frees++; return; } /* double free or foreign pointer: leak it */
    h.magic = MAGIC_DEAD;
    memcpy(p, &h, sizeof h);
    c->frees++;
    c->live_bytes -= h.size;
    free(p);
}

static void *count_realloc(void *ptr, size_t size, void *user)
{
    counting *c = user;
    if (!ptr) return count_alloc(size, user);
    unsigned char *p = (unsigned char *)ptr - HDR;
    hdr_t h;
    memcpy(&h, p, sizeof h);
    if (h.magic != MAGIC_LIVE) { c->bad_frees++; return NULL; }
    if (inject_failure(c)) return NULL;
    if (size > (size_t)-1 - HDR) return NULL;
    unsigned char *np = realloc(p, size + HDR);
    if (!np) return NULL;
    c->live_bytes = c->live_bytes - h.size + size;
    if (c->live_bytes > c->peak_bytes) c->peak_bytes = c->live_bytes;
    h.size = size;
    memcpy(np, &h, sizeof h);
    return np + HDR;
}

static sfb_context_config counting_config(counting *cnt, size_t budget)
{
    static const sfb_backend_kind ref_only[1] = { SFB_BACKEND_REF };
    sfb_context_config cfg = sfb_context_config_init();
    cfg.allocator.alloc = count_alloc;
    cfg.allocator.realloc = count_realloc;
    cfg.allocator.free = count_free;
    cfg.allocator.user = cnt;
    cfg.backends = ref_only;
    cfg.backend_count = 1;
    cfg.memory_budget = budget;
    cfg.ignore_environment = 1;
    return cfg;
}

static void lower(char *dst, const char *src, size_t cap)
{
    size_t i = 0;
    for (; src[i] && i + 1 < cap; i++) dst[i] = (char)tolower((unsigned char)src[i]);
    dst[i] = '\0';
}

/* ------------------------------------------------------------------ per-file test */

static void cleanup_params(struct criterion_test_params *p)
{
    cr_free(p->params);
}

ParameterizedTestParameters(bad, file)
{
    struct bad_case *cases = cr_malloc(sizeof(struct bad_case) * MAX_CASES);
    int n = read_manifest(cases, MAX_CASES);
    if (n <= 0) {
        /* one entry with an empty name: the test reports the unreadable manifest */
        memset(&cases[0], 0, sizeof cases[0]);
        n = 1;
    }
    return cr_make_param_array(struct bad_case, cases, (size_t)n, cleanup_params);
}

ParameterizedTest(struct bad_case *c, bad, file)
{
    const char *f = c->file;
    cr_assert(f[0] != '\0', "manifest %s/EXPECTED.txt is missing, unreadable or empty", bad_dir());
    cr_assert(strcmp(c->stage, "malformed-manifest-line") != 0,
              "EXPECTED.txt line %d: expected 'filename RESULT_NAME stage keyword'", c->manifest_line);

    sfb_result expected;
    cr_assert(result_from_name(c->result_name, &expected),
              "%s: EXPECTED.txt line %d: unknown result name '%s'", f, c->manifest_line, c->result_name);
    cr_assert(expected != SFB_SUCCESS, "%s: a bad file cannot expect SFB_SUCCESS", f);
    int is_refine; long level; size_t budget;
    cr_assert(parse_stage(c->stage, &is_refine, &level, &budget),
              "%s: EXPECTED.txt line %d: bad stage '%s'", f, c->manifest_line, c->stage);

    char path[1024];
    join_path(path, sizeof path, bad_dir(), f);
    size_t size = 0;
    unsigned char *text = read_file(path, &size);
    cr_assert(text != NULL, "%s: cannot read %s", f, path);

    counting cnt;
    memset(&cnt, 0, sizeof cnt);
    cnt.fail_at = -1;
    sfb_context_config cfg = counting_config(&cnt, budget);
    sfb_context *ctx = NULL;
    sfb_result r = sfb_context_create(&cfg, &ctx);
    cr_assert_eq(r, SFB_SUCCESS, "%s: sfb_context_create failed: %s (%d)", f, result_name(r), (int)r);
    cr_assert(ctx != NULL, "%s: sfb_context_create succeeded without a context", f);

    sfb_mesh *mesh = NULL;
    sfb_surface *surface = NULL;
    const char *what;
    r = sfb_mesh_read_obj(ctx, (const char *)text, size, &mesh);
    if (!is_refine) {
        what = "sfb_mesh_read_obj";
        if (r != SFB_SUCCESS)
            cr_expect(mesh == NULL, "%s: failed sfb_mesh_read_obj left a non-NULL mesh in *out", f);
    } else {
        cr_assert_eq(r, SFB_SUCCESS, "%s: stage %s needs a file that parses, but sfb_mesh_read_obj gave %s: %s",
                     f, c->stage, result_name(r), sfb_last_error(ctx));
        cr_assert(mesh != NULL, "%s: sfb_mesh_read_obj succeeded without a mesh", f);
        what = "sfb_surface_create";
        sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, (int)level);
        sc.refine_level = (int)level;
        sc.flags = 0;
        r = sfb_surface_create(ctx, mesh, &sc, &surface);
        if (r != SFB_SUCCESS)
            cr_expect(surface == NULL, "%s: failed sfb_surface_create left a non-NULL surface in *out", f);
    }

    const char *msg = sfb_last_error(ctx);
    char msg_copy[2048];
    snprintf(msg_copy, sizeof msg_copy, "%s", msg ? msg : "(null)");

    cr_expect_eq(r, expected, "%s: %s returned %s (%d), expected %s; message: \"%s\"",
                 f, what, result_name(r), (int)r, c->result_name, msg_copy);

    if (r != SFB_SUCCESS) {
        cr_expect(msg != NULL && msg[0] != '\0', "%s: %s failed with %s but sfb_last_error is empty",
                  f, what, result_name(r));
        char low[2048];
        lower(low, msg_copy, sizeof low);
        cr_expect(strstr(low, c->keyword) != NULL, "%s: message \"%s\" lacks the keyword \"%s\"",
                  f, msg_copy, c->keyword);
        if (expected == SFB_PARSE_ERROR && r == SFB_PARSE_ERROR)
            cr_expect(strstr(low, "line") != NULL, "%s: parse error message \"%s\" does not name the line",
                      f, msg_copy);

        sfb_error_info info = sfb_last_error_info(ctx);
        cr_expect_eq(info.result, r, "%s: sfb_last_error_info().result is %s, the call returned %s",
                     f, result_name(info.result), result_name(r));
        cr_expect(info.message != NULL && strcmp(info.message, msg_copy) == 0,
                  "%s: sfb_last_error_info().message \"%s\" differs from sfb_last_error() \"%s\"",
                  f, info.message ? info.message : "(null)", msg_copy);
        if (r == SFB_PARSE_ERROR && info.element == SFB_ELEMENT_LINE)
            cr_expect(info.index >= 1, "%s: SFB_ELEMENT_LINE error with line number %ld", f, info.index);

        const char *rs = sfb_result_string(r);
        cr_expect(rs != NULL && rs[0] != '\0', "%s: sfb_result_string(%d) is empty", f, (int)r);
        const char *es = sfb_result_string(expected);
        cr_expect(es != NULL && es[0] != '\0', "%s: sfb_result_string(%s) is empty", f, c->result_name);
    }

    if (surface) sfb_surface_destroy(surface);
    if (mesh) sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    free(text);

    cr_expect(cnt.allocs > 0, "%s: the context's allocator was never called (allocator ignored?)", f);
    cr_expect_eq(cnt.allocs, cnt.frees, "%s: leak after %s: %ld allocations, %ld frees, %zu bytes live",
                 f, what, cnt.allocs, cnt.frees, cnt.live_bytes);
    cr_expect_eq(cnt.live_bytes, (size_t)0, "%s: %zu bytes still live after sfb_context_destroy",
                 f, cnt.live_bytes);
    cr_expect_eq(cnt.bad_frees, 0, "%s: %ld frees of pointers that were not live (double free?)",
                 f, cnt.bad_frees);
}

/* ------------------------------------------------------------------ manifest checks */

Test(bad_manifest, has_enough_entries)
{
    static struct bad_case cases[MAX_CASES];
    int n = read_manifest(cases, MAX_CASES);
    cr_assert(n >= 0, "cannot read %s/EXPECTED.txt", bad_dir());
    cr_expect(n >= 25, "EXPECTED.txt lists only %d files, want at least 25", n);
}

Test(bad_manifest, entries_are_well_formed_and_complete)
{
    static struct bad_case cases[MAX_CASES];
    int n = read_manifest(cases, MAX_CASES);
    cr_assert(n >= 0, "cannot read %s/EXPECTED.txt", bad_dir());
    for (int i = 0; i < n; i++) {
        const struct bad_case *c = &cases[i];
        sfb_result r;
        int is_refine; long level; size_t budget;
        cr_expect(strcmp(c->stage, "malformed-manifest-line") != 0, "EXPECTED.txt line %d is malformed",
                  c->manifest_line);
        cr_expect(result_from_name(c->result_name, &r), "EXPECTED.txt line %d: unknown result '%s'",
                  c->manifest_line, c->result_name);
        cr_expect(parse_stage(c->stage, &is_refine, &level, &budget), "EXPECTED.txt line %d: bad stage '%s'",
                  c->manifest_line, c->stage);
        for (const char *k = c->keyword; *k; k++)
            cr_expect(!isupper((unsigned char)*k), "EXPECTED.txt line %d: keyword '%s' is not lowercase",
                      c->manifest_line, c->keyword);
        for (int j = 0; j < i; j++)
            cr_expect(strcmp(cases[j].file, c->file) != 0, "EXPECTED.txt lists %s twice", c->file);
        char path[1024];
        struct stat st;
        join_path(path, sizeof path, bad_dir(), c->file);
        cr_expect(stat(path, &st) == 0 && S_ISREG(st.st_mode), "EXPECTED.txt names %s, which is missing",
                  c->file);
    }
    /* every file in the directory is in the manifest */
    DIR *d = opendir(bad_dir());
    cr_assert(d != NULL, "cannot open %s", bad_dir());
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.' || strcmp(e->d_name, "EXPECTED.txt") == 0) continue;
        int found = 0;
        for (int i = 0; i < n && !found; i++) found = strcmp(cases[i].file, e->d_name) == 0;
        cr_expect(found, "%s/%s is not listed in EXPECTED.txt", bad_dir(), e->d_name);
    }
    closedir(d);
}

Test(bad_api, result_strings)
{
#define X(n, v, text) cr_expect(sfb_result_string(n) && strcmp(sfb_result_string(n), text) == 0, \
                                "sfb_result_string(%s) is \"%s\", want \"%s\"", #n,               \
                                sfb_result_string(n) ? sfb_result_string(n) : "(null)", text);
    SFB_RESULT_LIST(X)
#undef X
    const char *u = sfb_result_string((sfb_result)-999);
    cr_expect(u != NULL && u[0] != '\0', "sfb_result_string(-999) is empty");
}

/* ------------------------------------------------------------------ limits, both sides */

/* The files in tests/bad are built for the limits of their day; these follow the macros: a
 * mesh exactly at SFB_MAX_VALENCE / SFB_MAX_FACE_SIZE is accepted, one past it is refused. */

typedef struct textbuf { char *p; size_t n, cap; } textbuf;

static void tb_append(textbuf *t, const char *str)
{
    size_t k = strlen(str);
    if (t->n + k + 1 > t->cap) {
        size_t cap = t->cap ? t->cap * 2 : 65536;
        while (cap < t->n + k + 1) cap *= 2;
        char *np = realloc(t->p, cap);
        cr_assert(np != NULL, "out of memory building a test mesh");
        t->p = np;
        t->cap = cap;
    }
    memcpy(t->p + t->n, str, k + 1);
    t->n += k;
}

static void tb_circle_vertices(textbuf *t, int k)
{
    char line[96];
    for (int i = 0; i < k; i++) {
        double a = 6.283185307179586 * i / k;
        snprintf(line, sizeof line, "v %.6f %.6f 0\n", cos(a), sin(a));
        tb_append(t, line);
    }
}

/* Closed fan of k triangles around vertex 1 (valence k). */
static textbuf fan_obj(int k)
{
    textbuf t = { NULL, 0, 0 };
    char line[96];
    tb_append(&t, "v 0 0 0\n");
    tb_circle_vertices(&t, k);
    for (int i = 0; i < k; i++) {
        snprintf(line, sizeof line, "f 1 %d %d\n", i + 2, (i + 1) % k + 2);
        tb_append(&t, line);
    }
    return t;
}

/* One convex face with k corners. */
static textbuf ngon_obj(int k)
{
    textbuf t = { NULL, 0, 0 };
    char idx[32];
    tb_circle_vertices(&t, k);
    tb_append(&t, "f");
    for (int i = 0; i < k; i++) {
        snprintf(idx, sizeof idx, " %d", i + 1);
        tb_append(&t, idx);
    }
    tb_append(&t, "\n");
    return t;
}

static void expect_read(const char *what, textbuf t, sfb_result want, const char *keyword)
{
    counting cnt;
    memset(&cnt, 0, sizeof cnt);
    cnt.fail_at = -1;
    sfb_context_config cfg = counting_config(&cnt, 0);
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cfg, &ctx), SFB_SUCCESS);
    sfb_mesh *mesh = NULL;
    sfb_result r = sfb_mesh_read_obj(ctx, t.p, t.n, &mesh);
    char msg[1024], low[1024];
    snprintf(msg, sizeof msg, "%s", sfb_last_error(ctx));
    lower(low, msg, sizeof low);
    cr_expect_eq(r, want, "%s: sfb_mesh_read_obj returned %s, expected %s; message: \"%s\"",
                 what, result_name(r), result_name(want), msg);
    if (keyword && r != SFB_SUCCESS)
        cr_expect(strstr(low, keyword) != NULL, "%s: message \"%s\" lacks the keyword \"%s\"", what, msg, keyword);
    if (mesh) sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    free(t.p);
    cr_expect_eq(cnt.allocs, cnt.frees, "%s: %ld allocations, %ld frees", what, cnt.allocs, cnt.frees);
}

Test(bad_limits, valence_at_and_past_the_limit)
{
    expect_read("fan of SFB_MAX_VALENCE triangles", fan_obj(SFB_MAX_VALENCE), SFB_SUCCESS, NULL);
    expect_read("fan of SFB_MAX_VALENCE + 1 triangles", fan_obj(SFB_MAX_VALENCE + 1), SFB_LIMIT_EXCEEDED, "valence");
}

Test(bad_limits, face_size_at_and_past_the_limit)
{
    expect_read("face of SFB_MAX_FACE_SIZE corners", ngon_obj(SFB_MAX_FACE_SIZE), SFB_SUCCESS, NULL);
    expect_read("face of SFB_MAX_FACE_SIZE + 1 corners", ngon_obj(SFB_MAX_FACE_SIZE + 1), SFB_LIMIT_EXCEEDED, "face");
}

/* ------------------------------------------------------------------ allocation failures */

/* A valid mesh with creases, a corner, UVs and fs/as lines. Every allocation is made to fail in
 * turn; each failure must come back as SFB_OUT_OF_MEMORY with a message and leave nothing
 * allocated once everything is destroyed. */
static const char oom_obj[] =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "f 1/1 2/2 4/3 3/4\nf 3/1 4/2 6/3 5/4\nf 5/1 6/2 8/3 7/4\n"
    "fs 0 2 0 0\n"
    "as 1 1 1 1 1\n"
    "f 7/1 8/2 2/3 1/4\nf 2/1 8/2 6/3 4/4\nf 7/1 1/2 3/3 5/4\n"
    "t crease 2/1/0 0 1 3.0\n"
    "t corner 1/1/0 6 10\n";

Test(bad_alloc, every_allocation_failure_is_clean)
{
    int completed = 0;
    long wrong_code = 0, tried = 0;
    for (long k = 0; k < 20000 && !completed; k++) {
        counting cnt;
        memset(&cnt, 0, sizeof cnt);
        cnt.fail_at = k;
        tried++;
        sfb_context_config cfg = counting_config(&cnt, 0);
        sfb_context *ctx = NULL;
        sfb_mesh *mesh = NULL;
        sfb_surface *surface = NULL;
        sfb_mesh_data data;
        memset(&data, 0, sizeof data);
        const char *step = "sfb_context_create";
        sfb_result r = sfb_context_create(&cfg, &ctx);
        if (r == SFB_SUCCESS) {
            step = "sfb_mesh_read_obj";
            r = sfb_mesh_read_obj(ctx, oom_obj, sizeof oom_obj - 1, &mesh);
        }
        if (r == SFB_SUCCESS) {
            step = "sfb_surface_create";
            sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 2);
            sc.flags = SFB_REFINE_LIMIT | SFB_REFINE_UVS;
            r = sfb_surface_create(ctx, mesh, &sc, &surface);
        }
        if (r == SFB_SUCCESS) {
            step = "sfb_surface_refine";
            r = sfb_surface_refine(surface, &data);
            if (r == SFB_SUCCESS) sfb_mesh_data_free(&data);
        }
        if (r != SFB_SUCCESS) {
            if (r != SFB_OUT_OF_MEMORY && ++wrong_code <= 3)
                cr_expect_eq(r, SFB_OUT_OF_MEMORY, "allocation #%ld failed: %s returned %s (%d), want "
                             "SFB_OUT_OF_MEMORY: \"%s\"", k, step, result_name(r), (int)r,
                             ctx ? sfb_last_error(ctx) : "(no context)");
            if (ctx) {
                const char *m = sfb_last_error(ctx);
                cr_expect(m && m[0], "allocation #%ld failed: %s gave %s with an empty message",
                          k, step, result_name(r));
            }
        }
        if (cnt.failed == 0) {
            cr_expect_eq(r, SFB_SUCCESS, "allocation #%ld never made, yet %s failed with %s",
                         k, step, result_name(r));
            completed = 1;
        }
        if (surface) sfb_surface_destroy(surface);
        if (mesh) sfb_mesh_destroy(mesh);
        if (ctx) sfb_context_destroy(ctx);
        cr_expect_eq(cnt.allocs, cnt.frees, "allocation #%ld failed in %s: %ld allocations, %ld frees",
                     k, step, cnt.allocs, cnt.frees);
        cr_expect_eq(cnt.bad_frees, 0, "allocation #%ld failed in %s: %ld bad frees", k, step, cnt.bad_frees);
        if (cnt.allocs != cnt.frees || cnt.bad_frees) break; /* one report is enough */
    }
    cr_expect(completed, "the pipeline never completed without hitting the injected failure");
    cr_expect_eq(wrong_code, 0, "%ld of %ld injected allocation failures came back as a code other than "
                 "SFB_OUT_OF_MEMORY (first ones reported above)", wrong_code, tried);
}
