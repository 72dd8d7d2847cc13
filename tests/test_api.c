/* surfblend: API tests (result strings, context life cycle and allocator, logger,
 * progress/cancellation, OBJ round trip, backend selection, argument checking). */
#define _POSIX_C_SOURCE 200809L /* setenv, unsetenv */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

/* ------------------------------------------------------------------------- */
/* helpers                                                                    */

static sfb_context *make_ctx(void)
{
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    sfb_context *ctx = NULL;
    sfb_result r = sfb_context_create(&cc, &ctx);
    cr_assert_eq(r, SFB_SUCCESS, "context: %s", sfb_result_string(r));
    cr_assert_not_null(ctx);
    return ctx;
}

/* a w x h grid of quads in the xy plane with a small bump in z */
typedef struct grid {
    int nv, nf;
    float *pos;
    int *sizes, *fv;
} grid;

static grid grid_make(int w, int h)
{
    grid g;
    g.nv = (w + 1) * (h + 1);
    g.nf = w * h;
    g.pos = malloc(sizeof(float) * 3 * g.nv);
    g.sizes = malloc(sizeof(int) * g.nf);
    g.fv = malloc(sizeof(int) * 4 * g.nf);
    cr_assert(g.pos && g.sizes && g.fv);
    for (int j = 0; j <= h; ++j)
        for (int i = 0; i <= w; ++i) {
            int v = j * (w + 1) + i;
            g.pos[3 * v + 0] = (float)i;
            g.pos[3 * v + 1] = (float)j;
            g.pos[3 * v + 2] = 0.1f * (float)((i * 7 + j * 3) % 5);
        }
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            int f = j * w + i;
            g.sizes[f] = 4;
            g.fv[4 * f + 0] = j * (w + 1) + i;
            g.fv[4 * f + 1] = j * (w + 1) + i + 1;
            g.fv[4 * f + 2] = (j + 1) * (w + 1) + i + 1;
            g.fv[4 * f + 3] = (j + 1) * (w + 1) + i;
        }
    return g;
}

static void grid_free(grid *g)
{
    free(g->pos);
    free(g->sizes);
    free(g->fv);
}

static sfb_mesh_desc grid_desc(const grid *g)
{
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = g->nv;
    d.positions = g->pos;
    d.face_count = g->nf;
    d.face_sizes = g->sizes;
    d.face_vertices = g->fv;
    return d;
}

/* growable in-memory output for the OBJ writer */
typedef struct membuf {
    char *buf;
    size_t len, cap;
    int calls;
} membuf;

static int mem_write(const void *data, size_t size, void *user)
{
    membuf *m = user;
    m->calls++;
    if (m->len + size + 1 > m->cap) {
        size_t cap = m->cap ? m->cap : 256;
        while (cap < m->len + size + 1) cap *= 2;
        char *nb = realloc(m->buf, cap);
        if (!nb) return 1;
        m->buf = nb;
        m->cap = cap;
    }
    memcpy(m->buf + m->len, data, size);
    m->len += size;
    m->buf[m->len] = 0;
    return 0;
}

static int fail_write(const void *data, size_t size, void *user)
{
    (void)data;
    (void)size;
    (void)user;
    return 1;
}

/* ------------------------------------------------------------------------- */
/* result strings                                                             */

Test(api, result_strings_nonempty_and_distinct)
{
#define X_CODE(name, value, text) name,
    static const sfb_result codes[] = { SFB_RESULT_LIST(X_CODE) };
#undef X_CODE
#define X_TEXT(name, value, text) text,
    static const char *const texts[] = { SFB_RESULT_LIST(X_TEXT) };
#undef X_TEXT
    const int n = (int)(sizeof codes / sizeof codes[0]);
    cr_assert_eq(n, 13);
    for (int i = 0; i < n; ++i) {
        const char *s = sfb_result_string(codes[i]);
        cr_assert_not_null(s, "code %d has no string", (int)codes[i]);
        cr_expect_gt(strlen(s), 0, "code %d has an empty string", (int)codes[i]);
        cr_expect_str_eq(s, texts[i], "code %d: \"%s\" vs list \"%s\"", (int)codes[i], s, texts[i]);
        cr_expect_str_neq(s, "unknown result", "code %d reads as unknown", (int)codes[i]);
        for (int j = 0; j < i; ++j)
            cr_expect_str_neq(s, sfb_result_string(codes[j]), "codes %d and %d share \"%s\"", (int)codes[i],
                              (int)codes[j], s);
    }
    cr_expect_eq((int)SFB_SUCCESS, 0);
    cr_expect_eq((int)SFB_INVALID_VALUE, -12);
    const char *u = sfb_result_string((sfb_result)-999);
    cr_assert_not_null(u);
    cr_expect_str_eq(u, "unknown result");
    cr_expect_str_eq(sfb_result_string((sfb_result)1), "unknown result");
}

/* ------------------------------------------------------------------------- */
/* counting allocator                                                         */

typedef struct counter {
    long live, total, bad_frees;
    long fail_after; /* > 0: allocations fail once `total` has reached it */
} counter;

typedef struct hdr {
    size_t size, magic;
} hdr; /* 16 bytes: keeps malloc's alignment */

#define HDR_MAGIC ((size_t)0x5fb0a11c)

static void *c_alloc(size_t n, void *user)
{
    counter *c = user;
    if (c->fail_after > 0 && c->total >= c->fail_after) return NULL;
    hdr *h = malloc(sizeof(hdr) + n);
    if (!h) return NULL;
    h->size = n;
    h->magic = HDR_MAGIC;
    c->live++;
    c->total++;
    return h + 1;
}

static void *c_realloc(void *p, size_t n, void *user)
{
    counter *c = user;
    if (!p) return c_alloc(n, user);
    hdr *h = (hdr *)p - 1;
    if (h->magic != HDR_MAGIC) {
        c->bad_frees++;
        return NULL;
    }
    hdr *nh = realloc(h, sizeof(hdr) + n);
    if (!nh) return NULL;
    nh->size = n;
    return nh + 1;
}

static void c_free(void *p, void *user)
{
    counter *c = user;
    if (!p) return;
    hdr *h = (hdr *)p - 1;
    if (h->magic != HDR_MAGIC) {
        c->bad_frees++;
        return;
    }
    h->magic = 0;
    c->live--;
    free(h);
}

static sfb_context_config counting_config(counter *c)
{
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    cc.allocator.alloc = c_alloc;
    cc.allocator.realloc = c_realloc;
    cc.allocator.free = c_free;
    cc.allocator.user = c;
    return cc;
}

Test(api, context_custom_allocator_no_leaks)
{
    counter c = { 0, 0, 0, 0 };
    sfb_context_config cc = counting_config(&c);
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);

    grid g = grid_make(3, 2);
    sfb_mesh_desc d = grid_desc(&g);
    const int cv[2] = { 1, 5 };
    const float cs[1] = { 2.0f };
    d.crease_count = 1;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    sfb_mesh *mesh = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &mesh), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 2);
    sc.flags = SFB_REFINE_LIMIT;
    sfb_surface *surf = NULL;
    cr_assert_eq(sfb_surface_create(ctx, mesh, &sc, &surf), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    /* the surface keeps no reference into the mesh */
    sfb_mesh_destroy(mesh);
    sfb_mesh_data data;
    memset(&data, 0, sizeof data);
    cr_assert_eq(sfb_surface_refine(surf, &data), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_expect_gt(data.vertex_count, g.nv);
    /* a failing call must not leak either */
    sfb_mesh *bad = NULL;
    d.crease_vertices = NULL; /* crease_count 1 without vertices */
    cr_expect_neq(sfb_mesh_create(ctx, &d, &bad), SFB_SUCCESS);
    cr_expect_null(bad);

    cr_expect_gt(c.total, 0, "the custom allocator was never used");
    sfb_mesh_data_free(&data);
    sfb_surface_destroy(surf);
    sfb_context_destroy(ctx);
    cr_expect_eq(c.live, 0, "%ld allocations leaked (of %ld)", c.live, c.total);
    cr_expect_eq(c.bad_frees, 0, "%ld frees of pointers the allocator did not return", c.bad_frees);
    grid_free(&g);
}

/* ------------------------------------------------------------------------- */
/* logger                                                                     */

typedef struct logcount {
    int calls, bad;
} logcount;

static void count_log(int level, const char *msg, void *user)
{
    logcount *l = user;
    l->calls++;
    if (!msg || level < SFB_LOG_ERROR || level > SFB_LOG_DEBUG) l->bad++;
}

Test(api, logger_is_safe)
{
    logcount lc = { 0, 0 };
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    cc.logger.func = count_log;
    cc.logger.user = &lc;
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    /* a failing call (face index out of range) */
    static const float pos[12] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
    static const int sizes[1] = { 4 };
    static const int fv[4] = { 0, 1, 2, 9 };
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 4;
    d.positions = pos;
    d.face_count = 1;
    d.face_sizes = sizes;
    d.face_vertices = fv;
    sfb_mesh *m = NULL;
    cr_expect_neq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS);
    cr_expect_null(m);
    cr_expect_gt(strlen(sfb_last_error(ctx)), 0, "no error message after a failure");
    sfb_error_info info = sfb_last_error_info(ctx);
    cr_expect_neq(info.result, SFB_SUCCESS);
    cr_expect_not_null(info.message);
    sfb_clear_error(ctx);
    cr_expect_str_eq(sfb_last_error(ctx), "");
    /* and a successful one */
    static const int fv_ok[4] = { 0, 1, 2, 3 };
    d.face_vertices = fv_ok;
    cr_expect_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    /* the logger may or may not have been called; what it got must be well formed */
    cr_expect_eq(lc.bad, 0, "logger got a NULL message or a bad level");
}

/* ------------------------------------------------------------------------- */
/* progress and cancellation                                                  */

typedef struct prog {
    int calls, cancel_after, bad;
    float last;
} prog;

static int progress_cb(float done, const char *stage, void *user)
{
    prog *p = user;
    (void)stage;
    p->calls++;
    if (!(done >= 0.0f && done <= 1.0f)) p->bad++;
    p->last = done;
    return p->calls > p->cancel_after ? 1 : 0;
}

Test(api, progress_cancels_surface_create)
{
    counter c = { 0, 0, 0, 0 };
    prog p = { 0, 1 << 30, 0, 0.0f }; /* no cancel while the mesh is built */
    sfb_context_config cc = counting_config(&c);
    cc.progress.func = progress_cb;
    cc.progress.user = &p;
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    grid g = grid_make(40, 25); /* 1000 quads */
    sfb_mesh_desc d = grid_desc(&g);
    sfb_mesh *mesh = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &mesh), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 6);
    sfb_surface *surf = NULL;
    p.calls = 0;
    p.cancel_after = 0; /* cancel at the first report */
    sfb_result r = sfb_surface_create(ctx, mesh, &sc, &surf);
    cr_expect_eq(r, SFB_CANCELLED, "expected SFB_CANCELLED, got %s", sfb_result_string(r));
    cr_expect_null(surf);
    cr_expect_geq(p.calls, 1, "progress was never called");
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    cr_expect_eq(c.live, 0, "cancelled create leaked %ld allocations", c.live);
    grid_free(&g);
}

Test(api, progress_reports_each_level)
{
    prog p = { 0, 1 << 30, 0, 0.0f };
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    cc.progress.func = progress_cb;
    cc.progress.user = &p;
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    grid g = grid_make(4, 4);
    sfb_mesh_desc d = grid_desc(&g);
    sfb_mesh *mesh = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &mesh), SFB_SUCCESS);
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 3);
    sfb_surface *surf = NULL;
    p.calls = 0;
    cr_assert_eq(sfb_surface_create(ctx, mesh, &sc, &surf), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_expect_geq(p.calls, 3, "progress called %d times for 3 levels", p.calls);
    cr_expect_eq(p.bad, 0, "progress reported a value outside [0,1]");
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    grid_free(&g);
}

/* ------------------------------------------------------------------------- */
/* OBJ                                                                        */

static int has_edge(const sfb_mesh_desc *d, int a, int b, float s)
{
    for (int i = 0; i < d->crease_count; ++i) {
        int p = d->crease_vertices[2 * i], q = d->crease_vertices[2 * i + 1];
        if ((p == a && q == b) || (p == b && q == a)) {
            float t = d->crease_sharpness[i];
            if (s >= SFB_SHARPNESS_INFINITE) return t >= SFB_SHARPNESS_INFINITE;
            return fabsf(t - s) < 1e-5f;
        }
    }
    return 0;
}

static int count_positive_creases(const sfb_mesh_desc *d)
{
    int n = 0;
    for (int i = 0; i < d->crease_count; ++i)
        if (d->crease_sharpness[i] > 0.0f) ++n;
    return n;
}

Test(obj, write_read_round_trip)
{
    sfb_context *ctx = make_ctx();
    grid g = grid_make(3, 3); /* 16 vertices, 9 quads */
    sfb_mesh_desc d = grid_desc(&g);
    const int cv[6] = { 5, 6, 6, 10, 9, 10 };
    const float cs[3] = { 2.5f, 10.0f, 0.75f };
    const int kv[2] = { 5, 0 };
    const float ks[2] = { 3.0f, 10.0f };
    const int holes[1] = { 4 };
    d.crease_count = 3;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    d.corner_count = 2;
    d.corner_vertices = kv;
    d.corner_sharpness = ks;
    d.hole_count = 1;
    d.holes = holes;
    d.boundary = SFB_BOUNDARY_EDGE_AND_CORNER;
    d.crease_method = SFB_CREASE_CHAIKIN;
    sfb_mesh *m1 = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m1), SFB_SUCCESS, "%s", sfb_last_error(ctx));

    membuf out = { NULL, 0, 0, 0 };
    cr_assert_eq(sfb_mesh_write_obj(m1, mem_write, &out), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_assert_gt(out.len, 0);

    sfb_mesh *m2 = NULL;
    sfb_result r = sfb_mesh_read_obj(ctx, out.buf, out.len, &m2);
    cr_assert_eq(r, SFB_SUCCESS, "re-reading our own OBJ: %s: %s\n%s", sfb_result_string(r), sfb_last_error(ctx),
                 out.buf);

    sfb_mesh_desc a, b;
    sfb_mesh_get_desc(m1, &a);
    sfb_mesh_get_desc(m2, &b);
    cr_expect_eq(b.vertex_count, a.vertex_count);
    cr_expect_eq(b.face_count, a.face_count);
    cr_expect_eq(b.vertex_count, 16);
    cr_expect_eq(b.face_count, 9);
    for (int i = 0; i < 3 * 16 && b.vertex_count == 16; ++i)
        cr_expect(fabsf(b.positions[i] - g.pos[i]) < 1e-5f, "position component %d: %f vs %f", i, b.positions[i],
                  g.pos[i]);
    for (int i = 0; i < 36 && b.face_count == 9; ++i) cr_expect_eq(b.face_vertices[i], g.fv[i]);
    /* creases (as a set) */
    cr_expect_eq(count_positive_creases(&b), 3, "crease count %d after round trip", count_positive_creases(&b));
    cr_expect(has_edge(&b, 5, 6, 2.5f), "crease (5,6) 2.5 lost");
    cr_expect(has_edge(&b, 6, 10, 10.0f), "crease (6,10) infinite lost");
    cr_expect(has_edge(&b, 9, 10, 0.75f), "crease (9,10) 0.75 lost");
    /* corners */
    cr_expect_eq(b.corner_count, 2);
    for (int i = 0; i < b.corner_count; ++i) {
        int v = b.corner_vertices[i];
        float s = b.corner_sharpness[i];
        if (v == 5)
            cr_expect(fabsf(s - 3.0f) < 1e-5f, "corner 5 sharpness %f", s);
        else if (v == 0)
            cr_expect(s >= SFB_SHARPNESS_INFINITE, "corner 0 sharpness %f", s);
        else
            cr_expect_fail("unexpected corner vertex %d", v);
    }
    /* holes, boundary, crease method */
    cr_expect_eq(b.hole_count, 1);
    if (b.hole_count == 1) cr_expect_eq(b.holes[0], 4);
    cr_expect_eq(b.boundary, SFB_BOUNDARY_EDGE_AND_CORNER);
    cr_expect_eq(b.crease_method, SFB_CREASE_CHAIKIN);

    /* the writer reports its callback's failure */
    cr_expect_neq(sfb_mesh_write_obj(m1, fail_write, NULL), SFB_SUCCESS);

    free(out.buf);
    sfb_mesh_destroy(m1);
    sfb_mesh_destroy(m2);
    sfb_context_destroy(ctx);
    grid_free(&g);
}

/* Extreme floats survive the round trip exactly: FLT_MAX (written as 3.40282347e+38, a double
 * above FLT_MAX that rounds back to it), the smallest normal and denormal; a number that rounds
 * to infinity as a float is refused. (Found by fuzz_mesh: -FLT_MAX was refused on re-reading.) */
Test(obj, float_extremes_round_trip)
{
    sfb_context *ctx = make_ctx();
    const float big = 3.40282347e+38f, tiny = 1.17549435e-38f, denorm = 1.4e-45f;
    const float pos[12] = { -big, 0, big, big, tiny, 0, 0, -denorm, denorm, 1, 1, -tiny };
    const int sizes[1] = { 4 }, fv[4] = { 0, 1, 2, 3 };
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 4;
    d.positions = pos;
    d.face_count = 1;
    d.face_sizes = sizes;
    d.face_vertices = fv;
    sfb_mesh *m1 = NULL, *m2 = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m1), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    membuf out = { NULL, 0, 0, 0 };
    cr_assert_eq(sfb_mesh_write_obj(m1, mem_write, &out), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_result r = sfb_mesh_read_obj(ctx, out.buf, out.len, &m2);
    cr_assert_eq(r, SFB_SUCCESS, "re-reading: %s\n%s", sfb_last_error(ctx), out.buf);
    sfb_mesh_desc b;
    sfb_mesh_get_desc(m2, &b);
    cr_assert_eq(b.vertex_count, 4);
    for (int i = 0; i < 12; ++i) cr_expect(b.positions[i] == pos[i], "component %d: %.9g became %.9g", i, pos[i], b.positions[i]);
    sfb_mesh_destroy(m2);
    m2 = NULL;
    static const char over[] = "v 3.4028236e38 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    cr_expect_eq(sfb_mesh_read_obj(ctx, over, sizeof over - 1, &m2), SFB_INVALID_VALUE);
    cr_expect_null(m2);
    static const char at[] = "v -3.40282347e+38 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    cr_expect_eq(sfb_mesh_read_obj(ctx, at, sizeof at - 1, &m2), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_mesh_destroy(m2);
    free(out.buf);
    sfb_mesh_destroy(m1);
    sfb_context_destroy(ctx);
}

Test(obj, round_trip_uvs)
{
    sfb_context *ctx = make_ctx();
    static const char text[] = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n"
                               "vt 0 0\nvt 0.4 0\nvt 0.4 1\nvt 0 1\nvt 0.6 0\nvt 1 0\nvt 1 1\nvt 0.6 1\n"
                               "f 1/1 2/2 5/3 4/4\nf 2/5 3/6 6/7 5/8\n";
    sfb_mesh *m1 = NULL;
    cr_assert_eq(sfb_mesh_read_obj(ctx, text, strlen(text), &m1), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    membuf out = { NULL, 0, 0, 0 };
    cr_assert_eq(sfb_mesh_write_obj(m1, mem_write, &out), SFB_SUCCESS);
    sfb_mesh *m2 = NULL;
    cr_assert_eq(sfb_mesh_read_obj(ctx, out.buf, out.len, &m2), SFB_SUCCESS, "%s\n%s", sfb_last_error(ctx), out.buf);
    sfb_mesh_desc a, b;
    sfb_mesh_get_desc(m1, &a);
    sfb_mesh_get_desc(m2, &b);
    cr_expect_eq(a.uv_count, 8);
    cr_expect_eq(b.uv_count, a.uv_count);
    cr_assert_not_null(b.face_uvs);
    for (int i = 0; i < 8; ++i) {
        int ka = a.face_uvs[i], kb = b.face_uvs[i];
        cr_expect(fabsf(a.uvs[2 * ka] - b.uvs[2 * kb]) < 1e-5f && fabsf(a.uvs[2 * ka + 1] - b.uvs[2 * kb + 1]) < 1e-5f,
                  "face-vertex %d uv differs after round trip", i);
    }
    free(out.buf);
    sfb_mesh_destroy(m1);
    sfb_mesh_destroy(m2);
    sfb_context_destroy(ctx);
}

Test(obj, negative_indices)
{
    sfb_context *ctx = make_ctx();
    static const char pos_text[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                   "f 1/1 2/2 3/3 4/4\nf 2/1 5/2 6/3 3/4\n";
    /* the same with relative indices: after 6 v, -6 = 1, -5 = 2, ...; after 4 vt, -4 = 1 */
    static const char neg_text[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                   "f -6/-4 -5/-3 -4/-2 -3/-1\nf -5/-4 -2/-3 -1/-2 -4/-1\n";
    /* relative indices count from the vertices read so far */
    static const char mid_text[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n"
                                   "v 2 0 0\nv 2 1 0\nf -5 -2 -1 -4\n";
    sfb_mesh *mp = NULL, *mn = NULL, *mm = NULL;
    cr_assert_eq(sfb_mesh_read_obj(ctx, pos_text, strlen(pos_text), &mp), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_assert_eq(sfb_mesh_read_obj(ctx, neg_text, strlen(neg_text), &mn), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_assert_eq(sfb_mesh_read_obj(ctx, mid_text, strlen(mid_text), &mm), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_mesh_desc a, b, c;
    sfb_mesh_get_desc(mp, &a);
    sfb_mesh_get_desc(mn, &b);
    sfb_mesh_get_desc(mm, &c);
    cr_assert_eq(a.face_count, 2);
    cr_assert_eq(b.face_count, 2);
    cr_assert_eq(c.face_count, 2);
    static const int expect[8] = { 0, 1, 2, 3, 1, 4, 5, 2 };
    for (int i = 0; i < 8; ++i) {
        cr_expect_eq(a.face_vertices[i], expect[i]);
        cr_expect_eq(b.face_vertices[i], expect[i], "negative index face-vertex %d: %d vs %d", i, b.face_vertices[i],
                     expect[i]);
        cr_expect_eq(c.face_vertices[i], expect[i], "interleaved negative index face-vertex %d: %d vs %d", i,
                     c.face_vertices[i], expect[i]);
    }
    cr_expect_eq(b.uv_count, a.uv_count);
    if (a.face_uvs && b.face_uvs)
        for (int i = 0; i < 8; ++i) cr_expect_eq(b.face_uvs[i], a.face_uvs[i]);
    /* out of range relative index */
    static const char bad_text[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf -4 -3 -2\n";
    sfb_mesh *mb = NULL;
    cr_expect_neq(sfb_mesh_read_obj(ctx, bad_text, strlen(bad_text), &mb), SFB_SUCCESS);
    cr_expect_null(mb);
    sfb_mesh_destroy(mp);
    sfb_mesh_destroy(mn);
    sfb_mesh_destroy(mm);
    sfb_context_destroy(ctx);
}

Test(obj, text_need_not_be_nul_terminated)
{
    sfb_context *ctx = make_ctx();
    static const char text[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n";
    size_t n = strlen(text);
    char *buf = malloc(n);
    memcpy(buf, text, n); /* no terminator */
    sfb_mesh *m = NULL;
    cr_expect_eq(sfb_mesh_read_obj(ctx, buf, n, &m), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_mesh_destroy(m);
    free(buf);
    sfb_context_destroy(ctx);
}

/* ------------------------------------------------------------------------- */
/* backends                                                                   */

/* The default order is simd, ref: the first of them that initialises wins. */
Test(backend, bogus_environment_falls_back_to_default_order)
{
    cr_assert_eq(setenv("SURFBLEND_BACKEND", "bogus", 1), 0);
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 0;
    sfb_context *ctx = NULL;
    sfb_result r = sfb_context_create(&cc, &ctx);
    cr_assert_eq(r, SFB_SUCCESS, "context with SURFBLEND_BACKEND=bogus: %s", sfb_result_string(r));
    char report[2048], probe[512];
    memset(report, 0, sizeof report);
    const char *want = sfb_backend_probe(SFB_BACKEND_SIMD, NULL, probe, sizeof probe) == SFB_SUCCESS ? "simd" : "ref";
    cr_expect_str_eq(sfb_context_backend_name(ctx), want);
    cr_expect_eq(sfb_context_backend_report(ctx, report, sizeof report), SFB_SUCCESS);
    cr_expect_not_null(strstr(report, "SURFBLEND_BACKEND=bogus: unavailable (unknown backend name"),
                       "backend report does not name the bad setting: %s", report);
    char line[64];
    snprintf(line, sizeof line, "%s: selected", want);
    cr_expect_not_null(strstr(report, line), "backend report lacks \"%s\": %s", line, report);

    /* the context works: a quad refined once */
    static const float pos[12] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
    static const int sizes[1] = { 4 };
    static const int fv[4] = { 0, 1, 2, 3 };
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 4;
    d.positions = pos;
    d.face_count = 1;
    d.face_sizes = sizes;
    d.face_vertices = fv;
    sfb_mesh *m = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS);
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_BILINEAR, 1);
    sfb_surface *s = NULL;
    cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS);
    sfb_mesh_data data;
    memset(&data, 0, sizeof data);
    cr_assert_eq(sfb_surface_refine(s, &data), SFB_SUCCESS);
    cr_expect_eq(data.vertex_count, 9);
    /* the face point of the unit square */
    cr_expect(fabsf(data.positions[3 * 4] - 0.5f) < 1e-6f && fabsf(data.positions[3 * 4 + 1] - 0.5f) < 1e-6f);
    sfb_mesh_data_free(&data);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    unsetenv("SURFBLEND_BACKEND");
}

Test(backend, explicit_ref)
{
    const sfb_backend_kind pref[1] = { SFB_BACKEND_REF };
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    cc.backends = pref;
    cc.backend_count = 1;
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    cr_expect_str_eq(sfb_context_backend_name(ctx), "ref");
    char report[512];
    cr_expect_eq(sfb_context_backend_report(ctx, report, sizeof report), SFB_SUCCESS);
    cr_expect_not_null(strstr(report, "ref"), "report: %s", report);
    sfb_context_destroy(ctx);

    cr_expect_str_eq(sfb_backend_kind_name(SFB_BACKEND_REF), "ref");
    cr_expect_eq(sfb_backend_kind_parse("ref"), SFB_BACKEND_REF);
    cr_expect_eq(sfb_backend_kind_parse("REF"), SFB_BACKEND_REF);
    cr_expect_eq(sfb_backend_kind_parse("Simd"), SFB_BACKEND_SIMD);
    cr_expect_eq(sfb_backend_kind_parse("gl"), SFB_BACKEND_GL);
    cr_expect_eq(sfb_backend_kind_parse("osmesa"), SFB_BACKEND_OSMESA);
    cr_expect_eq(sfb_backend_kind_parse("bogus"), SFB_BACKEND_DEFAULT);
}

Test(backend, environment_ignored_when_asked)
{
    cr_assert_eq(setenv("SURFBLEND_BACKEND", "bogus", 1), 0);
    sfb_context *ctx = make_ctx(); /* ignore_environment = 1 */
    char report[2048];
    memset(report, 0, sizeof report);
    cr_expect_eq(sfb_context_backend_report(ctx, report, sizeof report), SFB_SUCCESS);
    cr_expect_null(strstr(report, "bogus"), "environment read although ignore_environment = 1: %s", report);
    sfb_context_destroy(ctx);
    unsetenv("SURFBLEND_BACKEND");
}

/* ------------------------------------------------------------------------- */
/* argument checking                                                          */

Test(api, null_arguments)
{
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    cr_expect_eq(sfb_context_create(&cc, NULL), SFB_INVALID_ARGS);

    sfb_context *ctx = make_ctx();
    static const float pos[12] = { 0, 0, 0, 1, 0, 0, 1, 1, 0.2f, 0, 1, 0 };
    static const int sizes[1] = { 4 };
    static const int fv[4] = { 0, 1, 2, 3 };
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 4;
    d.positions = pos;
    d.face_count = 1;
    d.face_sizes = sizes;
    d.face_vertices = fv;

    sfb_mesh *m = NULL;
    cr_expect_eq(sfb_mesh_create(ctx, NULL, &m), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_mesh_create(ctx, &d, NULL), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_mesh_read_obj(ctx, NULL, 10, &m), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_mesh_read_obj(ctx, "v 0 0 0\n", 8, NULL), SFB_INVALID_ARGS);
    cr_expect_null(m);

    cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS);
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 1);
    sfb_surface *s = NULL;
    cr_expect_eq(sfb_surface_create(ctx, NULL, &sc, &s), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_surface_create(ctx, m, &sc, NULL), SFB_INVALID_ARGS);
    cr_expect_null(s);

    cr_expect_eq(sfb_write_obj(NULL, mem_write, NULL), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_mesh_write_obj(NULL, mem_write, NULL), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_mesh_write_obj(m, NULL, NULL), SFB_INVALID_ARGS);

    cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS);
    sfb_mesh_data data;
    memset(&data, 0, sizeof data);
    cr_expect_eq(sfb_surface_refine(NULL, &data), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_surface_refine(s, NULL), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_surface_refine_positions(s, NULL, 4, &data), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_surface_refine_positions(NULL, pos, 4, &data), SFB_INVALID_ARGS);

    sfb_stencil_info info;
    cr_expect_eq(sfb_surface_stencil_info(NULL, SFB_TABLE_VERTEX, &info), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_surface_stencil_info(s, SFB_TABLE_VERTEX, NULL), SFB_INVALID_ARGS);
    /* documented: a table that was not built (no SFB_REFINE_LIMIT) */
    cr_expect_eq(sfb_surface_stencil_info(s, SFB_TABLE_LIMIT, &info), SFB_INVALID_ARGS);

    float dst[3 * 9];
    sfb_buffer_desc sd = { 0, 3, 3 }, dd = { 0, 3, 3 }; /* offset, components, stride */
    cr_expect_eq(sfb_surface_eval_stencils(NULL, SFB_TABLE_VERTEX, pos, sd, dst, dd), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_surface_eval_stencils(s, SFB_TABLE_VERTEX, NULL, sd, dst, dd), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_surface_eval_stencils(s, SFB_TABLE_VERTEX, pos, sd, NULL, dd), SFB_INVALID_ARGS);

    char buf[64];
    cr_expect_eq(sfb_context_backend_report(NULL, buf, sizeof buf), SFB_INVALID_ARGS);

    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* sfb_scheme_caps says what each scheme supports; patch info says the parametric domain. */
Test(api, scheme_caps_and_domain)
{
    cr_expect_eq(sfb_scheme_caps(SFB_SCHEME_CATMARK), SFB_SCHEME_CAN_REFINE | SFB_SCHEME_CAN_SHADE | SFB_SCHEME_CAN_EVAL);
    cr_expect_eq(sfb_scheme_caps(SFB_SCHEME_LOOP),
                 SFB_SCHEME_CAN_REFINE | SFB_SCHEME_CAN_SHADE | SFB_SCHEME_CAN_EVAL | SFB_SCHEME_TRIANGLES);
    cr_expect_eq(sfb_scheme_caps(SFB_SCHEME_BILINEAR), SFB_SCHEME_CAN_REFINE);
    cr_expect_eq(sfb_scheme_caps(SFB_SCHEME_MANIFOLD_BLEND), SFB_SCHEME_CAN_EVAL);
    cr_expect_eq(sfb_scheme_caps((sfb_scheme)99), 0u);
    cr_expect_eq(sfb_scheme_caps((sfb_scheme)-1), 0u);

    sfb_context *ctx = make_ctx();
    static const float pos[12] = { 0, 0, 0, 1, 0, 0, 1, 1, 0.2f, 0, 1, 0 };
    static const int quad[4] = { 0, 1, 2, 3 }, tris[6] = { 0, 1, 2, 0, 2, 3 };
    static const int qsizes[1] = { 4 }, tsizes[2] = { 3, 3 };
    for (int t = 0; t < 2; ++t) {
        sfb_mesh_desc d;
        memset(&d, 0, sizeof d);
        d.vertex_count = 4;
        d.positions = pos;
        d.face_count = t ? 2 : 1;
        d.face_sizes = t ? tsizes : qsizes;
        d.face_vertices = t ? tris : quad;
        sfb_mesh *m = NULL;
        cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS);
        sfb_surface_config sc = sfb_surface_config_init(t ? SFB_SCHEME_LOOP : SFB_SCHEME_CATMARK, 0);
        sc.flags = SFB_REFINE_PATCHES;
        sfb_surface *s = NULL;
        cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS);
        sfb_patch_info pi;
        cr_assert_eq(sfb_surface_patch_info(s, &pi), SFB_SUCCESS);
        cr_expect_eq(pi.domain_sides, t ? 3 : 4, "scheme %s", sfb_scheme_name(sc.scheme));
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
    }
    sfb_context_destroy(ctx);
}

/* sfb_surface_eval checks every location before writing anything: one bad location among
 * 200000 valid ones, at the first, the last and positions between (either side of 1024 and of
 * the check's first block end), is refused with SFB_INVALID_VALUE and its index, and the
 * outputs stay as they were. Kinds: face -1, face out of range, u NaN, u + v > 1 on a triangle
 * (Loop), a hole (the Catmull-Clark grid's face 4 is tagged `t hole`). */
Test(api, eval_checks_every_location_first)
{
    static const char *grid =
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 0 1 0\nv 1 1 0.2\nv 2 1 0.1\nv 3 1 0\nv 0 2 0\nv 1 2 0\nv 2 2 0.3\nv 3 2 0\n"
        "v 0 3 0\nv 1 3 0\nv 2 3 0\nv 3 3 0\n"
        "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\nf 9 10 14 13\nf 10 11 15 14\nf 11 12 16 15\n"
        "t hole 1/0/0 4\n";
    static const char *tris =
        "v 0 0 0\nv 1 0 0\nv 1 1 0.2\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
    /* 200000 locations: the check runs in 64 blocks of 3125 over the threads (simd, 2 threads,
     * where simd is built in): either side of a block's end, and two faults in different
     * blocks, the later block's first (the first one must be reported) */
    const int n = 200000, at[6] = { 0, 1023, 1024, 3124, 3125, 199999 };
    sfb_context *ctx = NULL;
    {
        sfb_context_config cc = sfb_context_config_init();
        sfb_backend_kind kind = SFB_BACKEND_SIMD;
        cc.ignore_environment = 1;
        cc.backends = &kind; cc.backend_count = 1; cc.threads = 2;
        if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) ctx = make_ctx();
    }
    for (int t = 0; t < 2; ++t) {
        sfb_mesh *m = NULL;
        sfb_surface *s = NULL;
        sfb_surface_config sc = sfb_surface_config_init(t ? SFB_SCHEME_LOOP : SFB_SCHEME_CATMARK, 0);
        const char *obj = t ? tris : grid;
        sc.flags = SFB_REFINE_PATCHES;
        cr_assert_eq(sfb_mesh_read_obj(ctx, obj, strlen(obj), &m), SFB_SUCCESS, "%s", sfb_last_error(ctx));
        cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS, "%s", sfb_last_error(ctx));
        const int nf = sfb_surface_param_face_count(s);
        sfb_location *L = (sfb_location *)malloc(sizeof *L * (size_t)n);
        float *P = (float *)malloc(sizeof(float) * 3 * (size_t)n);
        cr_assert(L && P);
        for (int q = 0; q < n; ++q) {
            L[q].face = (q * 7) % nf;
            if (!t && L[q].face == 4) L[q].face = 3; /* off the hole */
            L[q].u = (float)((q % 13) / 13.0 * (t ? 0.5 : 1.0));
            L[q].v = (float)((q % 7) / 7.0 * (t ? 0.5 : 1.0));
        }
        sfb_eval_output o;
        memset(&o, 0, sizeof o);
        o.position = P;
        cr_expect_eq(sfb_surface_eval(s, L, n, &o), SFB_SUCCESS, "%s", sfb_last_error(ctx));
        for (int kind = 0; kind < 5; ++kind) {
            if (kind == 4 && t) continue;           /* holes: the grid */
            if (kind == 3 && !t) continue;          /* u + v > 1: the triangles */
            for (int a = 0; a < 6; ++a) {
                const sfb_location keep = L[at[a]];
                switch (kind) {
                case 0: L[at[a]].face = -1; break;
                case 1: L[at[a]].face = nf; break;
                case 2: L[at[a]].u = NAN; break;
                case 3: L[at[a]].u = 0.75f; L[at[a]].v = 0.25f + 1e-7f; break;
                default: L[at[a]].face = 4; break;
                }
                for (int q = 0; q < 3 * n; ++q) P[q] = -7.0f;
                cr_expect_eq(sfb_surface_eval(s, L, n, &o), SFB_INVALID_VALUE, "kind %d at %d accepted", kind, at[a]);
                sfb_error_info e = sfb_last_error_info(ctx);
                cr_expect_eq(e.index, at[a], "kind %d at %d: index %ld (%s)", kind, at[a], e.index, e.message);
                int untouched = 1;
                for (int q = 0; q < 3 * n; ++q) untouched &= P[q] == -7.0f;
                cr_expect(untouched, "kind %d at %d: outputs written", kind, at[a]);
                sfb_clear_error(ctx);
                L[at[a]] = keep;
            }
        }
        {
            const sfb_location k1 = L[150000], k2 = L[3125];
            L[150000].face = -1;
            L[3125].u = NAN;
            cr_expect_eq(sfb_surface_eval(s, L, n, &o), SFB_INVALID_VALUE);
            sfb_error_info e = sfb_last_error_info(ctx);
            cr_expect_eq(e.index, 3125, "two faults: index %ld (%s)", e.index, e.message);
            cr_expect(strstr(e.message, "outside") != NULL, "two faults: %s", e.message);
            sfb_clear_error(ctx);
            L[150000] = k1; L[3125] = k2;
        }
        free(L);
        free(P);
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
    }
    sfb_context_destroy(ctx);
}

/* --crease-angle's library half: the cube's 12 edges (90 degrees) become infinitely sharp for a
 * limit under 90 and none for one over it; sharper edges keep their sharpness (not counted),
 * semi-sharp ones under the limit stay semi-sharp, the rest of the mesh is copied. */
Test(api, crease_by_angle)
{
    static const float pos[24] = { -1, -1, 1, 1, -1, 1, -1, 1, 1, 1, 1, 1, -1, 1, -1, 1, 1, -1, -1, -1, -1, 1, -1, -1 };
    static const int sizes[6] = { 4, 4, 4, 4, 4, 4 };
    static const int fv[24] = { 0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4 };
    static const int cv[4] = { 0, 1, 1, 3 };
    static const float cs[2] = { 10.0f, 2.0f };
    sfb_context *ctx = make_ctx();
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 8;
    d.positions = pos;
    d.face_count = 6;
    d.face_sizes = sizes;
    d.face_vertices = fv;
    d.boundary = SFB_BOUNDARY_EDGE_AND_CORNER;
    sfb_mesh *m = NULL, *c = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    int added = -1;
    sfb_mesh_info in;
    cr_assert_eq(sfb_mesh_crease_by_angle(ctx, m, 30.0f, &c, &added), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_expect_eq(added, 12);
    sfb_mesh_get_info(c, &in);
    cr_expect_eq(in.infsharp_edges, 12);
    sfb_mesh_desc got;
    sfb_mesh_get_desc(c, &got);
    cr_expect_eq(got.boundary, SFB_BOUNDARY_EDGE_AND_CORNER, "the rest is copied");
    sfb_mesh_destroy(c);
    c = NULL;
    cr_assert_eq(sfb_mesh_crease_by_angle(ctx, m, 100.0f, &c, &added), SFB_SUCCESS);
    cr_expect_eq(added, 0);
    sfb_mesh_get_info(c, &in);
    cr_expect_eq(in.sharp_edges, 0);
    sfb_mesh_destroy(c);
    c = NULL;
    sfb_mesh_destroy(m);
    /* one edge infinitely sharp already, one semi-sharp */
    d.crease_count = 2;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS);
    cr_assert_eq(sfb_mesh_crease_by_angle(ctx, m, 100.0f, &c, &added), SFB_SUCCESS);
    sfb_mesh_get_info(c, &in);
    cr_expect_eq(added, 0);
    cr_expect_eq(in.infsharp_edges, 1);
    cr_expect_eq(in.semisharp_edges, 1, "the semi-sharp edge keeps its sharpness");
    sfb_mesh_destroy(c);
    c = NULL;
    cr_assert_eq(sfb_mesh_crease_by_angle(ctx, m, 45.0f, &c, &added), SFB_SUCCESS);
    sfb_mesh_get_info(c, &in);
    cr_expect_eq(added, 11, "the infinitely sharp edge is not counted again");
    cr_expect_eq(in.infsharp_edges, 12);
    sfb_mesh_destroy(c);
    c = NULL;
    /* bad angles */
    cr_expect_eq(sfb_mesh_crease_by_angle(ctx, m, -1.0f, &c, &added), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_mesh_crease_by_angle(ctx, m, 181.0f, &c, &added), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_mesh_crease_by_angle(ctx, m, NAN, &c, &added), SFB_INVALID_ARGS);
    cr_expect_null(c);
    cr_expect_eq(sfb_mesh_crease_by_angle(ctx, NULL, 30.0f, &c, &added), SFB_INVALID_ARGS);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* the edge a-b among a triangle mesh's faces: how many faces have it */
static int faces_with_edge(const sfb_mesh_desc *d, int a, int b)
{
    int n = 0;
    for (int f = 0; f < d->face_count; ++f)
        for (int k = 0; k < 3; ++k) {
            const int p = d->face_vertices[3 * f + k], q = d->face_vertices[3 * f + (k + 1) % 3];
            n += (p == a && q == b) || (p == b && q == a);
        }
    return n;
}

/* twice the signed area of triangle f's projection on z */
static double tri_area_z(const sfb_mesh_desc *d, int f)
{
    const float *a = d->positions + 3 * d->face_vertices[3 * f], *b = d->positions + 3 * d->face_vertices[3 * f + 1],
                *c = d->positions + 3 * d->face_vertices[3 * f + 2];
    return ((double)b[0] - a[0]) * ((double)c[1] - a[1]) - ((double)b[1] - a[1]) * ((double)c[0] - a[0]);
}

/* sfb_mesh_triangulate: quads along the shorter diagonal that lies inside them, polygons by ear
 * clipping (no flipped or overlapping triangle: the areas add up), tags, UVs and holes carried,
 * no diagonal made twice (a valence-2 vertex whose two quads share two edges), the result usable
 * by the triangle schemes; bad arguments and allocation failures leave nothing behind. */
Test(api, triangulate)
{
    /* face 0: a quad whose diagonal 1-3 (2.2) is shorter than 0-2 (4.1);
     * face 1: an arrowhead quad (reflex corner 5) whose shorter diagonal 4-6 lies outside;
     * face 2: a concave L-shaped hexagon of area 3; face 3: a triangle */
    static const float pos[] = { 0, 0, 0, 3, 0, 0, 4, 1, 0, 1, 1, 0,                   /* 0-3 */
                                 10, 0, 0, 12, 0.8f, 0, 14, 0, 0, 12, 6, 0,          /* 4-7 */
                                 20, 0, 0, 22, 0, 0, 22, 1, 0, 21, 1, 0, 21, 2, 0, 20, 2, 0, /* 8-13 */
                                 30, 0, 0, 31, 0, 0, 30, 1, 0 };                     /* 14-16 */
    static const int sizes[4] = { 4, 4, 6, 3 };
    static const int fv[] = { 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16 };
    static const float uvs[] = { 0, 0, 1, 0, 1, 1, 0, 1 };
    static const int fuv[] = { 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 0, 1, 2 };
    static const int cv[2] = { 8, 9 };
    static const float cs[1] = { 2.5f };
    static const int cornv[1] = { 11 };
    static const float corns[1] = { 3.0f };
    static const int holes[1] = { 1 };
    counter cnt = { 0, 0, 0, 0 };
    sfb_context_config cc = counting_config(&cnt);
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 17;
    d.positions = pos;
    d.face_count = 4;
    d.face_sizes = sizes;
    d.face_vertices = fv;
    d.uv_count = 4;
    d.uvs = uvs;
    d.face_uvs = fuv;
    d.crease_count = 1;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    d.corner_count = 1;
    d.corner_vertices = cornv;
    d.corner_sharpness = corns;
    d.hole_count = 1;
    d.holes = holes;
    d.boundary = SFB_BOUNDARY_EDGE_AND_CORNER;
    sfb_mesh *m = NULL, *t = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    int split = -1;
    cr_assert_eq(sfb_mesh_triangulate(ctx, m, &t, &split), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_expect_eq(split, 3);
    sfb_mesh_desc o;
    sfb_mesh_get_desc(t, &o);
    cr_assert_eq(o.face_count, 2 + 2 + 4 + 1);
    for (int f = 0; f < o.face_count; ++f) cr_expect_eq(o.face_sizes[f], 3, "face %d", f);
    cr_expect_eq(o.vertex_count, 17);
    cr_expect_eq(faces_with_edge(&o, 1, 3), 2, "the quad's shorter diagonal");
    cr_expect_eq(faces_with_edge(&o, 0, 2), 0);
    cr_expect_eq(faces_with_edge(&o, 5, 7), 2, "the arrowhead's diagonal inside it");
    cr_expect_eq(faces_with_edge(&o, 4, 6), 0, "not the shorter one outside it");
    /* every triangle keeps the faces' orientation (+z), and the pieces of each face cover its
     * area once: 2 x area 3, 2 x 5.2 (the arrowhead: 4 x 6 / 2 - 4 x 0.8 / 2), 2 x 3, 2 x 0.5 */
    static const double want[4] = { 6.0, 20.8, 6.0, 1.0 };
    static const int first[5] = { 0, 2, 4, 8, 9 }, fo[4] = { 0, 4, 8, 14 }; /* pieces, corners of each face */
    for (int f = 0; f < 4; ++f) {
        double sum = 0.0;
        for (int k = first[f]; k < first[f + 1]; ++k) {
            cr_expect_gt(tri_area_z(&o, k), 1e-6, "triangle %d of face %d flipped or flat", k, f);
            sum += tri_area_z(&o, k);
        }
        cr_expect(fabs(sum - want[f]) < 1e-5, "face %d: the pieces' area %g, the polygon's %g", f, sum, want[f]);
        /* each piece's corners come from its face, with their UVs */
        for (int k = 3 * first[f]; k < 3 * first[f + 1]; ++k) {
            int j = 0;
            while (j < sizes[f] && fv[fo[f] + j] != o.face_vertices[k]) ++j;
            cr_expect_lt(j, sizes[f], "corner %d of piece of face %d is not one of its vertices", k, f);
            if (j < sizes[f]) cr_expect_eq(o.face_uvs[k], fuv[fo[f] + j], "corner %d's UV", k);
        }
    }
    /* the tags: the crease, the corner and the rules kept; both pieces of the hole are holes */
    cr_expect_eq(o.crease_count, 1);
    cr_expect(o.crease_count == 1 && o.crease_sharpness[0] == 2.5f);
    cr_expect(o.corner_count == 1 && o.corner_vertices[0] == 11 && o.corner_sharpness[0] == 3.0f);
    cr_expect_eq(o.boundary, SFB_BOUNDARY_EDGE_AND_CORNER);
    cr_expect(o.hole_count == 2 && o.holes[0] == 2 && o.holes[1] == 3, "holes %d: %d %d", o.hole_count, o.hole_count > 0 ? o.holes[0] : -1,
              o.hole_count > 1 ? o.holes[1] : -1);
    sfb_mesh_destroy(t);
    t = NULL;
    sfb_mesh_destroy(m);
    m = NULL;

    /* a valence-2 vertex v (0) whose two quads (a v b x) and (b v a y) share the edges v-a and
     * v-b: both quads' shorter diagonal is a-b; made twice it would be an edge of four triangles */
    static const float pos2[] = { 0, 0, 1, -1, 0, 0, 1, 0, 0, 0, 2, 0, 0, -2, 0 };
    static const int sizes2[2] = { 4, 4 };
    static const int fv2[8] = { 1, 0, 2, 3, 2, 0, 1, 4 };
    memset(&d, 0, sizeof d);
    d.vertex_count = 5;
    d.positions = pos2;
    d.face_count = 2;
    d.face_sizes = sizes2;
    d.face_vertices = fv2;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_assert_eq(sfb_mesh_triangulate(ctx, m, &t, NULL), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_mesh_info in;
    sfb_mesh_get_info(t, &in);
    cr_expect_eq(in.face_count, 4);
    cr_expect_eq(in.nonmanifold_edges, 0, "a diagonal made twice");
    sfb_mesh_get_desc(t, &o);
    cr_expect_eq(faces_with_edge(&o, 1, 2), 2, "the first quad takes a-b");
    sfb_mesh_destroy(t);
    t = NULL;
    sfb_mesh_destroy(m);
    m = NULL;

    /* a quad grid, triangulated, is what the triangle schemes take; untouched faces are copied */
    grid g = grid_make(3, 3);
    d = grid_desc(&g);
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS);
    sfb_surface *s = NULL;
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
    sc.flags = SFB_REFINE_PATCHES;
    cr_expect_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_INVALID_TOPOLOGY, "quads are refused");
    cr_assert_eq(sfb_mesh_triangulate(ctx, m, &t, &split), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_expect_eq(split, 9);
    sfb_mesh_info in2;
    sfb_mesh_get_info(t, &in2);
    cr_expect_eq(in2.triangles, 18);
    cr_expect_eq(in2.nonmanifold_edges, 0);
    const sfb_scheme schemes[3] = { SFB_SCHEME_TRIBEZIER, SFB_SCHEME_PN, SFB_SCHEME_LOOP };
    for (int i = 0; i < 3; ++i) {
        sc = sfb_surface_config_init(schemes[i], schemes[i] == SFB_SCHEME_LOOP ? 1 : 0);
        if (schemes[i] != SFB_SCHEME_LOOP) sc.flags = SFB_REFINE_PATCHES;
        cr_expect_eq(sfb_surface_create(ctx, t, &sc, &s), SFB_SUCCESS, "scheme %d: %s", (int)schemes[i], sfb_last_error(ctx));
        sfb_surface_destroy(s);
        s = NULL;
    }
    sfb_mesh *t2 = NULL;
    cr_assert_eq(sfb_mesh_triangulate(ctx, t, &t2, &split), SFB_SUCCESS);
    cr_expect_eq(split, 0, "a triangle mesh has nothing to split");
    sfb_mesh_get_desc(t, &d);
    sfb_mesh_get_desc(t2, &o);
    cr_expect(o.face_count == d.face_count && !memcmp(o.face_vertices, d.face_vertices, sizeof(int) * 3 * (size_t)d.face_count),
              "a triangle mesh is copied as it is");
    sfb_mesh_destroy(t2);
    sfb_mesh_destroy(t);
    t = NULL;

    /* bad arguments */
    cr_expect_eq(sfb_mesh_triangulate(NULL, m, &t, &split), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_mesh_triangulate(ctx, NULL, &t, &split), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_mesh_triangulate(ctx, m, NULL, &split), SFB_INVALID_ARGS);
    cr_expect_null(t);

    /* every allocation failing in turn: out of memory, nothing returned, nothing leaked */
    int fails = 0;
    for (long k = 0;; ++k) {
        cnt.fail_after = cnt.total + k;
        split = -1;
        sfb_result r = sfb_mesh_triangulate(ctx, m, &t, &split);
        cnt.fail_after = 0;
        if (r == SFB_SUCCESS) {
            cr_expect_eq(split, 9);
            sfb_mesh_destroy(t);
            t = NULL;
            break;
        }
        cr_expect_eq(r, SFB_OUT_OF_MEMORY, "allocation %ld failing: %s", k, sfb_result_string(r));
        cr_expect_null(t);
        cr_expect_eq(split, 0);
        ++fails;
        cr_assert_lt(k, 200, "no success after 200 failing allocations");
    }
    cr_expect_gt(fails, 5, "the failures were not reached (%d)", fails);
    sfb_mesh_destroy(m);
    grid_free(&g);
    sfb_context_destroy(ctx);
    cr_expect_eq(cnt.live, 0, "%ld allocations leaked", cnt.live);
}

/* the stencil tables and sfb_surface_refine agree, and refine_positions follows new positions */
Test(api, stencils_match_refine)
{
    sfb_context *ctx = make_ctx();
    grid g = grid_make(2, 2);
    sfb_mesh_desc d = grid_desc(&g);
    sfb_mesh *m = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS);
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 2);
    sfb_surface *s = NULL;
    cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS);
    sfb_stencil_info info;
    cr_assert_eq(sfb_surface_stencil_info(s, SFB_TABLE_VERTEX, &info), SFB_SUCCESS);
    cr_expect_eq(info.sources, g.nv);
    sfb_mesh_data data;
    memset(&data, 0, sizeof data);
    cr_assert_eq(sfb_surface_refine(s, &data), SFB_SUCCESS);
    cr_assert_eq(info.rows, data.vertex_count);
    float *dst = calloc((size_t)info.rows * 4, sizeof(float));
    /* {offset, length = components per element, stride}: a padded destination with an offset */
    sfb_buffer_desc sd = { 0, 3, 3 }, dd = { 1, 3, 4 };
    cr_assert_eq(sfb_surface_eval_stencils(s, SFB_TABLE_VERTEX, g.pos, sd, dst, dd), SFB_SUCCESS);
    for (int i = 0; i < info.rows; ++i)
        for (int c = 0; c < 3; ++c)
            cr_expect(fabsf(dst[1 + 4 * i + c] - data.positions[3 * i + c]) < 1e-5f, "row %d comp %d", i, c);
    /* translated base positions translate the refined mesh */
    float *moved = malloc(sizeof(float) * 3 * g.nv);
    for (int i = 0; i < g.nv; ++i) {
        moved[3 * i] = g.pos[3 * i] + 1.0f;
        moved[3 * i + 1] = g.pos[3 * i + 1] - 2.0f;
        moved[3 * i + 2] = g.pos[3 * i + 2] + 0.5f;
    }
    sfb_mesh_data d2;
    memset(&d2, 0, sizeof d2);
    cr_assert_eq(sfb_surface_refine_positions(s, moved, g.nv, &d2), SFB_SUCCESS);
    cr_assert_eq(d2.vertex_count, data.vertex_count);
    for (int i = 0; i < data.vertex_count; ++i) {
        cr_expect(fabsf(d2.positions[3 * i] - data.positions[3 * i] - 1.0f) < 1e-5f);
        cr_expect(fabsf(d2.positions[3 * i + 1] - data.positions[3 * i + 1] + 2.0f) < 1e-5f);
        cr_expect(fabsf(d2.positions[3 * i + 2] - data.positions[3 * i + 2] - 0.5f) < 1e-5f);
    }
    free(moved);
    free(dst);
    sfb_mesh_data_free(&d2);
    sfb_mesh_data_free(&data);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    grid_free(&g);
}

Test(backend, negative_threads_is_invalid)
{
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    cc.threads = -1;
    cr_expect_eq(sfb_context_create(&cc, &ctx), SFB_INVALID_ARGS);
    cr_expect_null(ctx);
}

/* Every backend kind probes to a definite answer with a reason; ref always works and
 * sfb_context_backend_info describes what the selected backend runs on. */
Test(backend, probe_and_info)
{
    char info[512];
    cr_expect_eq(sfb_backend_probe(SFB_BACKEND_REF, NULL, info, sizeof info), SFB_SUCCESS);
    cr_expect_eq(sfb_backend_probe(SFB_BACKEND_DEFAULT, NULL, info, sizeof info), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_backend_probe(SFB_BACKEND_REF, NULL, NULL, 0), SFB_INVALID_ARGS);
    for (int k = SFB_BACKEND_SIMD; k < SFB_BACKEND_KIND_COUNT_; ++k) {
        info[0] = 0;
        sfb_result r = sfb_backend_probe((sfb_backend_kind)k, NULL, info, sizeof info);
        cr_expect(r == SFB_SUCCESS || r == SFB_BACKEND_UNAVAILABLE, "probe %d: %s", k, sfb_result_string(r));
        cr_expect(info[0] != 0, "probe of %s says nothing", sfb_backend_kind_name((sfb_backend_kind)k));
        if (r == SFB_SUCCESS && k == SFB_BACKEND_SIMD) {
            const sfb_backend_kind one = SFB_BACKEND_SIMD;
            sfb_context_config cc = sfb_context_config_init();
            sfb_context *ctx = NULL;
            char line[512];
            cc.backends = &one;
            cc.backend_count = 1;
            cc.ignore_environment = 1;
            cc.threads = 1;
            cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
            cr_expect_eq(sfb_context_backend_info(ctx, line, sizeof line), SFB_SUCCESS);
            cr_expect_not_null(strstr(line, "1 thread"), "simd with threads = 1 says: %s", line);
            sfb_context_destroy(ctx);
        }
    }
}
