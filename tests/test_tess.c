/* surfblend: tessellation tests (sfb_surface_tessellate): watertightness and orientation on
 * closed meshes (quads, n-gons, triangles, creases), split creases, open meshes and holes,
 * vertex counts, agreement with sfb_surface_eval, adaptive mode, argument checks,
 * cancellation and allocation failures without leaks. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

/* ------------------------------------------------------------------------- */
/* meshes                                                                     */

static const char *cube_obj =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n";

/* the cube with creases: a closed loop of infinitely sharp edges around the top face, one
 * isolated infinitely sharp edge on the bottom (two darts) and a semi-sharp edge */
static const char *creased_cube_obj =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n"
    "t crease 2/1/0 0 1 10\nt crease 2/1/0 1 3 10\nt crease 2/1/0 3 2 10\nt crease 2/1/0 2 0 10\n"
    "t crease 2/1/0 4 5 10\nt crease 2/1/0 6 7 1.5\n";
#define CREASED_CUBE_INF_EDGES 5

/* a pentagonal prism: two pentagons and five quads */
static const char *prism_obj =
    "v 1 0 -1\nv 0.309017 0.951057 -1\nv -0.809017 0.587785 -1\nv -0.809017 -0.587785 -1\nv 0.309017 -0.951057 -1\n"
    "v 1 0 1\nv 0.309017 0.951057 1\nv -0.809017 0.587785 1\nv -0.809017 -0.587785 1\nv 0.309017 -0.951057 1\n"
    "f 6 7 8 9 10\nf 5 4 3 2 1\n"
    "f 1 2 7 6\nf 2 3 8 7\nf 3 4 9 8\nf 4 5 10 9\nf 5 1 6 10\n";

/* a square pyramid: one quad and four triangles */
static const char *pyramid_obj =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 0 0 1.5\n"
    "f 4 3 2 1\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";

/* a tetrahedron, with one infinitely sharp edge */
static const char *tet_obj =
    "v 1 1 1\nv -1 -1 1\nv -1 1 -1\nv 1 -1 -1\n"
    "f 1 2 4\nf 1 4 3\nf 1 3 2\nf 2 3 4\nt crease 2/1/0 0 1 10\n";

/* the prism with its top rim infinitely sharp (an n-gon beside split creases) */
static const char *prism_creased_tags =
    "t crease 2/1/0 5 6 10\nt crease 2/1/0 6 7 10\nt crease 2/1/0 7 8 10\nt crease 2/1/0 8 9 10\nt crease 2/1/0 9 5 10\n";

static sfb_context *tx_ctx(void)
{
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    return ctx;
}

static sfb_mesh *tx_mesh(sfb_context *ctx, const char *obj)
{
    sfb_mesh *m = NULL;
    sfb_result r = sfb_mesh_read_obj(ctx, obj, strlen(obj), &m);
    cr_assert_eq(r, SFB_SUCCESS, "mesh: %s", sfb_last_error(ctx));
    return m;
}

static sfb_surface *tx_surface(sfb_context *ctx, const sfb_mesh *m)
{
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 0);
    sc.flags = SFB_REFINE_PATCHES;
    sfb_surface *s = NULL;
    sfb_result r = sfb_surface_create(ctx, m, &sc, &s);
    cr_assert_eq(r, SFB_SUCCESS, "surface: %s", sfb_last_error(ctx));
    return s;
}

/* a w x h grid of quads over [0,w] x [0,h] (edge-and-corner boundary); a few interior
 * vertices near (1,1) get heights */
static char *grid_obj(int w, int h, double bump)
{
    size_t cap = (size_t)(w + 1) * (h + 1) * 64 + (size_t)w * h * 64 + 64, n = 0;
    char *s = malloc(cap);
    cr_assert_not_null(s);
    for (int j = 0; j <= h; ++j)
        for (int i = 0; i <= w; ++i) {
            int inner = i > 0 && j > 0 && i < w && j < h;
            /* a bump near the corner (1,1), flat elsewhere */
            double z = inner && i <= 2 && j <= 2 ? bump * (double)((i * 3 + j * 5) % 4) : 0.0;
            n += (size_t)snprintf(s + n, cap - n, "v %d %d %g\n", i, j, z);
        }
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            int a = j * (w + 1) + i + 1;
            n += (size_t)snprintf(s + n, cap - n, "f %d %d %d %d\n", a, a + 1, a + w + 2, a + w + 1);
        }
    /* corners pinned, so that the limit boundary is the grid's outline */
    n += (size_t)snprintf(s + n, cap - n, "t interpolateboundary 1/0/0 1\n");
    return s;
}

/* ------------------------------------------------------------------------- */
/* edge statistics of a triangle list                                         */

typedef struct edge_stats {
    long undirected, once, twice, more, directed_dup, degenerate;
} edge_stats;

static int cmp_u64(const void *a, const void *b)
{
    unsigned long long x = *(const unsigned long long *)a, y = *(const unsigned long long *)b;
    return x < y ? -1 : x > y;
}

/* Every undirected edge with its number of uses; `directed_dup` counts directed edges used
 * more than once (0 on a consistently oriented manifold). Boundary edges (used once) are
 * returned in *bnd as vertex pairs when bnd is not NULL. */
static edge_stats stats_of(const sfb_tess_data *t, int **bnd)
{
    edge_stats st;
    memset(&st, 0, sizeof st);
    size_t n = (size_t)t->triangle_count * 3;
    unsigned long long *u = malloc((n + 1) * sizeof *u), *d = malloc((n + 1) * sizeof *d);
    cr_assert(u && d);
    for (size_t i = 0; i < (size_t)t->triangle_count; ++i) {
        const int *v = t->triangles + 3 * i;
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) st.degenerate++;
        for (int c = 0; c < 3; ++c) {
            unsigned long long a = (unsigned)v[c], b = (unsigned)v[(c + 1) % 3];
            d[3 * i + c] = a << 32 | b;
            u[3 * i + c] = a < b ? (a << 32 | b) : (b << 32 | a);
        }
    }
    qsort(u, n, sizeof *u, cmp_u64);
    qsort(d, n, sizeof *d, cmp_u64);
    if (bnd) *bnd = malloc((n + 1) * 2 * sizeof(int));
    for (size_t i = 0; i < n;) {
        size_t j = i;
        while (j < n && u[j] == u[i]) ++j;
        st.undirected++;
        if (j - i == 1) {
            if (bnd) {
                (*bnd)[2 * st.once] = (int)(u[i] >> 32);
                (*bnd)[2 * st.once + 1] = (int)(u[i] & 0xffffffffu);
            }
            st.once++;
        } else if (j - i == 2) st.twice++;
        else st.more++;
        i = j;
    }
    for (size_t i = 0; i + 1 < n; ++i)
        if (d[i] == d[i + 1]) st.directed_dup++;
    free(u);
    free(d);
    return st;
}

/* structural checks every tessellation passes */
static void check_basic(const sfb_surface *s, const sfb_tess_data *t)
{
    int np = sfb_surface_param_face_count(s);
    cr_assert_gt(t->vertex_count, 0);
    cr_assert_gt(t->triangle_count, 0);
    cr_assert(t->positions && t->normals && t->locations && t->triangles && t->triangle_faces);
    for (int i = 0; i < 3 * t->triangle_count; ++i)
        cr_assert(t->triangles[i] >= 0 && t->triangles[i] < t->vertex_count, "triangle index %d out of range", t->triangles[i]);
    for (int i = 0; i < t->triangle_count; ++i)
        cr_assert(t->triangle_faces[i] >= 0 && t->triangle_faces[i] < np);
    for (int v = 0; v < t->vertex_count; ++v) {
        const sfb_location *l = &t->locations[v];
        cr_assert(l->face >= 0 && l->face < np && l->u >= 0.0f && l->u <= 1.0f && l->v >= 0.0f && l->v <= 1.0f,
                  "vertex %d has location (%d, %g, %g)", v, l->face, l->u, l->v);
        const float *n = t->normals + 3 * v;
        double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        cr_assert(fabs(len - 1.0) < 1e-4, "vertex %d normal has length %g", v, len);
    }
}

static sfb_tess_data tess_ok(const sfb_surface *s, sfb_context *ctx, int rate, float tol, unsigned flags)
{
    sfb_tess_config c = sfb_tess_config_init(rate);
    c.tolerance = tol;
    c.flags = flags;
    sfb_tess_data t;
    sfb_result r = sfb_surface_tessellate(s, &c, &t);
    cr_assert_eq(r, SFB_SUCCESS, "tessellate rate %d: %s: %s", rate, sfb_result_string(r), sfb_last_error(ctx));
    check_basic(s, &t);
    return t;
}

static void expect_closed(const sfb_tess_data *t, const char *what, int rate)
{
    edge_stats st = stats_of(t, NULL);
    cr_expect_eq(st.once, 0, "%s rate %d: %ld boundary edges", what, rate, st.once);
    cr_expect_eq(st.more, 0, "%s rate %d: %ld edges used more than twice", what, rate, st.more);
    cr_expect_eq(st.directed_dup, 0, "%s rate %d: %ld directed edges used twice (inconsistent orientation)", what, rate,
                 st.directed_dup);
    cr_expect_eq(st.degenerate, 0, "%s rate %d: %ld degenerate triangles", what, rate, st.degenerate);
    /* Euler characteristic of a sphere */
    cr_expect_eq((long)t->vertex_count - st.undirected + t->triangle_count, 2, "%s rate %d: V - E + F = %ld", what, rate,
                 (long)t->vertex_count - st.undirected + t->triangle_count);
}

/* ------------------------------------------------------------------------- */
/* closed meshes                                                              */

Test(tess, config_init_and_free_of_empty)
{
    sfb_tess_config c = sfb_tess_config_init(7);
    cr_expect_eq(c.rate, 7);
    cr_expect_eq(c.tolerance, 0.0f);
    cr_expect_eq(c.flags, 0u);
    sfb_tess_data t;
    memset(&t, 0, sizeof t);
    sfb_tess_data_free(&t);
    sfb_tess_data_free(NULL);
}

Test(tess, cube_closed_with_vertex_formula)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = tx_mesh(ctx, cube_obj);
    sfb_surface *s = tx_surface(ctx, m);
    static const int rates[] = { 1, 2, 5, 8 };
    for (int k = 0; k < 4; ++k) {
        int r = rates[k];
        sfb_tess_data t = tess_ok(s, ctx, r, 0.0f, 0);
        expect_closed(&t, "cube", r);
        /* V = nv + ne (r-1) + nf (r-1)^2, T = 2 nf r^2 for a pure quad mesh */
        cr_expect_eq(t.vertex_count, 8 + 12 * (r - 1) + 6 * (r - 1) * (r - 1), "rate %d: %d vertices", r, t.vertex_count);
        cr_expect_eq(t.triangle_count, 2 * 6 * r * r);
        sfb_tess_data_free(&t);
        cr_expect_null(t.positions);
        cr_expect_eq(t.vertex_count, 0);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

Test(tess, ngons_and_triangles_closed)
{
    const char *list[3] = { prism_obj, pyramid_obj, tet_obj };
    static const char *names[3] = { "pentagonal prism", "pyramid", "tetrahedron" };
    for (int k = 0; k < 3; ++k) {
        sfb_context *ctx = tx_ctx();
        sfb_mesh *m = tx_mesh(ctx, list[k]);
        sfb_surface *s = tx_surface(ctx, m);
        for (int r = 1; r <= 5; r += (r == 2 ? 3 : 1)) {
            sfb_tess_data t = tess_ok(s, ctx, r, 0.0f, 0);
            expect_closed(&t, names[k], r);
            sfb_tess_data_free(&t);
        }
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
        sfb_context_destroy(ctx);
    }
}

Test(tess, triangles_follow_the_normals)
{
    sfb_context *ctx = tx_ctx();
    const char *list[2] = { cube_obj, prism_obj };
    for (int k = 0; k < 2; ++k) {
        sfb_mesh *m = tx_mesh(ctx, list[k]);
        sfb_surface *s = tx_surface(ctx, m);
        sfb_tess_data t = tess_ok(s, ctx, 6, 0.0f, 0);
        for (int i = 0; i < t.triangle_count; ++i) {
            const int *v = t.triangles + 3 * i;
            const float *a = t.positions + 3 * v[0], *b = t.positions + 3 * v[1], *c = t.positions + 3 * v[2];
            double e1[3], e2[3], n[3], avg[3] = { 0, 0, 0 };
            for (int q = 0; q < 3; ++q) {
                e1[q] = (double)b[q] - a[q];
                e2[q] = (double)c[q] - a[q];
            }
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            for (int j = 0; j < 3; ++j)
                for (int q = 0; q < 3; ++q) avg[q] += t.normals[3 * v[j] + q];
            double dot = n[0] * avg[0] + n[1] * avg[1] + n[2] * avg[2];
            double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            cr_assert_gt(len, 1e-9, "mesh %d triangle %d has no area", k, i);
            /* every vertex is where its neighbours expect it: no edge spans more than a few
             * cells (control edges are at most 2 long; rate 6) */
            for (int q = 0; q < 3; ++q) {
                const float *x = t.positions + 3 * v[q], *y = t.positions + 3 * v[(q + 1) % 3];
                double dx = (double)x[0] - y[0], dy = (double)x[1] - y[1], dz = (double)x[2] - y[2];
                cr_assert_lt(sqrt(dx * dx + dy * dy + dz * dz), 2.0 / 6.0, "mesh %d triangle %d has a long edge", k, i);
            }
            cr_assert_gt(dot / len, 0.5, "mesh %d triangle %d faces away from its normals (%g)", k, i, dot / len);
        }
        sfb_tess_data_free(&t);
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
    }
    sfb_context_destroy(ctx);
}

Test(tess, positions_match_eval_at_locations)
{
    sfb_context *ctx = tx_ctx();
    const char *list[3] = { creased_cube_obj, prism_obj, pyramid_obj };
    for (int k = 0; k < 3; ++k) {
        sfb_mesh *m = tx_mesh(ctx, list[k]);
        sfb_surface *s = tx_surface(ctx, m);
        sfb_tess_data t = tess_ok(s, ctx, 4, 0.0f, SFB_TESS_SPLIT_CREASES);
        float *p = malloc(sizeof(float) * 3 * (size_t)t.vertex_count);
        float *n = malloc(sizeof(float) * 3 * (size_t)t.vertex_count);
        sfb_eval_output eo;
        memset(&eo, 0, sizeof eo);
        eo.position = p;
        eo.normal = n;
        cr_assert_eq(sfb_surface_eval(s, t.locations, t.vertex_count, &eo), SFB_SUCCESS, "%s", sfb_last_error(ctx));
        for (int i = 0; i < 3 * t.vertex_count; ++i) {
            cr_assert(fabsf(p[i] - t.positions[i]) <= 1e-5f, "mesh %d: position %d: %g vs eval %g", k, i / 3, t.positions[i], p[i]);
            cr_assert(fabsf(n[i] - t.normals[i]) <= 1e-4f, "mesh %d: normal %d: %g vs eval %g", k, i / 3, t.normals[i], n[i]);
        }
        free(p);
        free(n);
        sfb_tess_data_free(&t);
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
    }
    sfb_context_destroy(ctx);
}

/* Tessellation evaluates on the context's backend: every available backend gives the same
 * triangles and locations as ref (uniform mode is topology only) and positions within the
 * agreement tolerance (1e-5 x the bounding-box diagonal, about 3.5 here). */
Test(tess, backends_agree_with_ref)
{
    static const sfb_backend_kind kinds[4] = { SFB_BACKEND_REF, SFB_BACKEND_SIMD, SFB_BACKEND_GL, SFB_BACKEND_OSMESA };
    sfb_tess_data ref;
    memset(&ref, 0, sizeof ref);
    sfb_context *rctx = NULL;
    for (int k = 0; k < 4; ++k) {
        char info[512];
        if (sfb_backend_probe(kinds[k], NULL, info, sizeof info) != SFB_SUCCESS) continue;
        sfb_context_config cc = sfb_context_config_init();
        cc.ignore_environment = 1;
        cc.backends = &kinds[k];
        cc.backend_count = 1;
        sfb_context *ctx = NULL;
        cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
        sfb_mesh *m = tx_mesh(ctx, creased_cube_obj);
        sfb_surface *s = tx_surface(ctx, m);
        sfb_tess_data t = tess_ok(s, ctx, 6, 0.0f, SFB_TESS_SPLIT_CREASES);
        if (k == 0) {
            ref = t;
            rctx = ctx;
        } else {
            cr_assert_eq(t.vertex_count, ref.vertex_count);
            cr_assert_eq(t.triangle_count, ref.triangle_count);
            cr_expect_eq(memcmp(t.triangles, ref.triangles, sizeof(int) * 3 * (size_t)t.triangle_count), 0);
            cr_expect_eq(memcmp(t.locations, ref.locations, sizeof(sfb_location) * (size_t)t.vertex_count), 0);
            for (int i = 0; i < 3 * t.vertex_count; ++i) {
                cr_assert(fabsf(t.positions[i] - ref.positions[i]) <= 3.5e-5f, "%s: position %d: %g, ref %g",
                          sfb_backend_kind_name(kinds[k]), i / 3, t.positions[i], ref.positions[i]);
                cr_assert(fabsf(t.normals[i] - ref.normals[i]) <= 1e-4f, "%s: normal %d: %g, ref %g", sfb_backend_kind_name(kinds[k]),
                          i / 3, t.normals[i], ref.normals[i]);
            }
            sfb_tess_data_free(&t);
        }
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
        if (k != 0) sfb_context_destroy(ctx);
    }
    cr_assert_not_null(rctx, "ref is always available");
    sfb_tess_data_free(&ref);
    sfb_context_destroy(rctx);
}

/* ------------------------------------------------------------------------- */
/* creases                                                                    */

/* with split creases, the boundary edges are exactly the two sides of every infinitely sharp
 * edge (rate segments per side on a quad mesh; 2 * rate where an n-gon uses the edge), and
 * every boundary vertex has a twin at the same position on the other side, except the dart
 * vertices where an isolated crease ends (one sector: one vertex). An isolated crease edge
 * with a single segment has no point to split, so it stays closed. */
static void check_split(const char *obj, int inf_edges, int seg_factor, int isolated, int darts, const char *what)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = tx_mesh(ctx, obj);
    sfb_surface *s = tx_surface(ctx, m);
    for (int r = 1; r <= 5; r += 2) {
        sfb_tess_data t = tess_ok(s, ctx, r, 0.0f, 0);
        expect_closed(&t, what, r); /* without the flag the creases are shared */
        int plain_v = t.vertex_count;
        sfb_tess_data_free(&t);
        t = tess_ok(s, ctx, r, 0.0f, SFB_TESS_SPLIT_CREASES);
        int *bnd = NULL;
        edge_stats st = stats_of(&t, &bnd);
        int one = seg_factor * r == 1;
        long want = 2L * inf_edges * seg_factor * r - (one ? 2L * isolated : 0L);
        cr_expect_eq(st.once, want, "%s rate %d: %ld boundary edges, expected %ld", what, r, st.once, want);
        cr_expect_eq(st.more, 0);
        cr_expect_eq(st.directed_dup, 0);
        cr_expect_gt(t.vertex_count, plain_v);
        unsigned char *seen = calloc((size_t)t.vertex_count, 1);
        int lonely = 0;
        for (long e = 0; e < st.once; ++e)
            for (int c = 0; c < 2; ++c) {
                int v = bnd[2 * e + c], twin = 0;
                if (seen[v]) continue;
                seen[v] = 1;
                for (int w = 0; w < t.vertex_count && !twin; ++w) {
                    if (w == v) continue;
                    const float *a = t.positions + 3 * v, *b = t.positions + 3 * w;
                    twin = fabsf(a[0] - b[0]) < 1e-5f && fabsf(a[1] - b[1]) < 1e-5f && fabsf(a[2] - b[2]) < 1e-5f;
                }
                lonely += !twin;
            }
        cr_expect_eq(lonely, one ? 0 : darts, "%s rate %d: %d boundary vertices without a twin across a crease (darts: %d)", what, r,
                     lonely, darts);
        free(seen);
        free(bnd);
        sfb_tess_data_free(&t);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

Test(tess, split_creases_cube)
{
    check_split(creased_cube_obj, CREASED_CUBE_INF_EDGES, 1, 1, 2, "creased cube");
}

Test(tess, split_creases_triangles)
{
    check_split(tet_obj, 1, 2, 1, 2, "tetrahedron with a sharp edge");
}

Test(tess, split_creases_beside_an_ngon)
{
    size_t n = strlen(prism_obj) + strlen(prism_creased_tags) + 1;
    char *obj = malloc(n);
    snprintf(obj, n, "%s%s", prism_obj, prism_creased_tags);
    check_split(obj, 5, 2, 0, 0, "prism with a sharp rim");
    free(obj);
}

Test(tess, split_crease_normals_differ_across_the_crease)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = tx_mesh(ctx, creased_cube_obj);
    sfb_surface *s = tx_surface(ctx, m);
    sfb_tess_data t = tess_ok(s, ctx, 4, 0.0f, SFB_TESS_SPLIT_CREASES);
    /* pairs of vertices at the same position: their normals are those of the two sides, which
     * meet at an angle along the top rim of the cube */
    int pairs = 0, differ = 0;
    for (int v = 0; v < t.vertex_count; ++v)
        for (int w = v + 1; w < t.vertex_count; ++w) {
            const float *a = t.positions + 3 * v, *b = t.positions + 3 * w;
            if (fabsf(a[0] - b[0]) < 1e-6f && fabsf(a[1] - b[1]) < 1e-6f && fabsf(a[2] - b[2]) < 1e-6f) {
                const float *na = t.normals + 3 * v, *nb = t.normals + 3 * w;
                pairs++;
                differ += na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2] < 0.99f;
            }
        }
    cr_expect_gt(pairs, 0);
    cr_expect_eq(differ, pairs, "%d of %d split pairs have the same normal", pairs - differ, pairs);
    sfb_tess_data_free(&t);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* ------------------------------------------------------------------------- */
/* open meshes and holes                                                      */

/* boundary edges of a tessellated w x h grid lie on the grid's outline (its boundary vertices
 * are collinear per side, so the limit boundary stays on those lines) */
static void expect_outline_boundary(const sfb_tess_data *t, int w, int h, long want, const char *what)
{
    int *bnd = NULL;
    edge_stats st = stats_of(t, &bnd);
    if (want >= 0) cr_expect_eq(st.once, want, "%s: %ld boundary edges, expected %ld", what, st.once, want);
    cr_expect_eq(st.more, 0);
    cr_expect_eq(st.directed_dup, 0, "%s: inconsistent orientation", what);
    cr_expect_eq(st.degenerate, 0);
    for (long e = 0; e < st.once; ++e)
        for (int c = 0; c < 2; ++c) {
            const float *p = t->positions + 3 * bnd[2 * e + c];
            int on = fabsf(p[0]) < 1e-4f || fabsf(p[0] - (float)w) < 1e-4f || fabsf(p[1]) < 1e-4f || fabsf(p[1] - (float)h) < 1e-4f;
            cr_assert(on, "%s: boundary vertex %d at (%g %g %g) is inside the mesh", what, bnd[2 * e + c], p[0], p[1], p[2]);
        }
    free(bnd);
}

Test(tess, open_grid_boundary_only_on_the_outline)
{
    sfb_context *ctx = tx_ctx();
    char *obj = grid_obj(3, 2, 0.3);
    sfb_mesh *m = tx_mesh(ctx, obj);
    sfb_surface *s = tx_surface(ctx, m);
    for (int r = 1; r <= 5; r += 2) {
        sfb_tess_data t = tess_ok(s, ctx, r, 0.0f, SFB_TESS_SPLIT_CREASES); /* boundary edges are never split */
        /* V = nv + ne (r-1) + nf (r-1)^2 holds for open quad meshes too */
        cr_expect_eq(t.vertex_count, 12 + 17 * (r - 1) + 6 * (r - 1) * (r - 1));
        expect_outline_boundary(&t, 3, 2, 2L * (3 + 2) * r, "grid");
        sfb_tess_data_free(&t);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    free(obj);
}

Test(tess, holes_make_nothing)
{
    sfb_context *ctx = tx_ctx();
    char *obj = grid_obj(3, 3, 0.0);
    size_t n = strlen(obj) + 32;
    obj = realloc(obj, n);
    strcat(obj, "t hole 1/0/0 4\n"); /* the middle face */
    sfb_mesh *m = tx_mesh(ctx, obj);
    sfb_surface *s = tx_surface(ctx, m);
    int r = 3;
    sfb_tess_data t = tess_ok(s, ctx, r, 0.0f, 0);
    cr_expect_eq(t.triangle_count, 8 * 2 * r * r);
    for (int i = 0; i < t.triangle_count; ++i) cr_expect_neq(t.triangle_faces[i], 4);
    for (int v = 0; v < t.vertex_count; ++v) cr_expect_neq(t.locations[v].face, 4);
    /* the hole's rim is a boundary too: 4 edges around it, rate segments each */
    edge_stats st = stats_of(&t, NULL);
    cr_expect_eq(st.once, 2L * (3 + 3) * r + 4L * r);
    cr_expect_eq(st.directed_dup, 0);
    sfb_tess_data_free(&t);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    free(obj);
}

/* ------------------------------------------------------------------------- */
/* adaptive                                                                   */

Test(tess, adaptive_watertight_and_coarser_on_flat_regions)
{
    sfb_context *ctx = tx_ctx();
    char *obj = grid_obj(6, 6, 0.4);
    sfb_mesh *m = tx_mesh(ctx, obj);
    sfb_surface *s = tx_surface(ctx, m);
    int rate = 16;
    sfb_tess_data u = tess_ok(s, ctx, rate, 0.0f, 0);
    sfb_tess_data a = tess_ok(s, ctx, rate, 1e-3f, 0);
    cr_expect_eq(u.triangle_count, 36 * 2 * rate * rate);
    cr_expect_lt(a.triangle_count, u.triangle_count / 2, "adaptive %d triangles, uniform %d", a.triangle_count, u.triangle_count);
    expect_outline_boundary(&a, 6, 6, -1, "adaptive grid");
    /* the flat faces far from the bump are a single cell: some face has exactly 2 triangles
     * and some face (on the bump) more than 2 * 4 * 4 */
    int counts[36];
    memset(counts, 0, sizeof counts);
    for (int i = 0; i < a.triangle_count; ++i) counts[a.triangle_faces[i]]++;
    int coarse = 0, fine = 0;
    for (int f = 0; f < 36; ++f) {
        coarse += counts[f] == 2;
        fine += counts[f] >= 32;
    }
    cr_expect_gt(coarse, 0, "no flat face was tessellated at rate 1");
    cr_expect_gt(fine, 0, "no curved face was tessellated finely");
    sfb_tess_data_free(&u);
    sfb_tess_data_free(&a);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    free(obj);
}

Test(tess, adaptive_closed_meshes)
{
    sfb_context *ctx = tx_ctx();
    const char *list[4] = { cube_obj, prism_obj, pyramid_obj, creased_cube_obj };
    static const float tols[3] = { 1e-1f, 1e-2f, 1e-4f };
    for (int k = 0; k < 4; ++k) {
        sfb_mesh *m = tx_mesh(ctx, list[k]);
        sfb_surface *s = tx_surface(ctx, m);
        int prev = 0;
        for (int q = 0; q < 3; ++q) {
            sfb_tess_data t = tess_ok(s, ctx, 12, tols[q], 0);
            expect_closed(&t, "adaptive", 12);
            cr_expect_geq(t.triangle_count, prev, "a smaller tolerance gave fewer triangles");
            prev = t.triangle_count;
            sfb_tess_data_free(&t);
        }
        /* a huge tolerance: every face at rate 1 (n-gon edges still have two segments) */
        sfb_tess_data t = tess_ok(s, ctx, 12, 1e6f, 0);
        sfb_tess_data one = tess_ok(s, ctx, 1, 0.0f, 0);
        cr_expect_eq(t.triangle_count, one.triangle_count);
        cr_expect_eq(t.vertex_count, one.vertex_count);
        sfb_tess_data_free(&t);
        sfb_tess_data_free(&one);
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
    }
    sfb_context_destroy(ctx);
}

/* ------------------------------------------------------------------------- */
/* arguments, limits, cancellation, allocation failures                        */

Test(tess, bad_arguments)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = tx_mesh(ctx, cube_obj);
    sfb_surface *s = tx_surface(ctx, m);
    sfb_tess_config c = sfb_tess_config_init(4);
    sfb_tess_data t;
    memset(&t, 0x5a, sizeof t);
    cr_expect_eq(sfb_surface_tessellate(NULL, &c, &t), SFB_INVALID_ARGS);
    cr_expect_eq(t.vertex_count, 0, "out is zeroed on failure");
    cr_expect_null(t.positions);
    cr_expect_eq(sfb_surface_tessellate(s, NULL, &t), SFB_INVALID_ARGS);
    cr_expect_eq(sfb_surface_tessellate(s, &c, NULL), SFB_INVALID_ARGS);
    static const int bad_rates[] = { 0, -1, 1025 };
    for (int i = 0; i < 3; ++i) {
        c = sfb_tess_config_init(bad_rates[i]);
        cr_expect_eq(sfb_surface_tessellate(s, &c, &t), SFB_INVALID_ARGS, "rate %d", bad_rates[i]);
        cr_expect(strstr(sfb_last_error(ctx), "rate") != NULL, "message: %s", sfb_last_error(ctx));
        cr_expect_null(t.triangles);
    }
    c = sfb_tess_config_init(4);
    c.tolerance = -1.0f;
    cr_expect_eq(sfb_surface_tessellate(s, &c, &t), SFB_INVALID_ARGS);
    cr_expect(strstr(sfb_last_error(ctx), "tolerance") != NULL);
    c.tolerance = NAN;
    cr_expect_eq(sfb_surface_tessellate(s, &c, &t), SFB_INVALID_ARGS);
    c.tolerance = 0.0f;
    c.flags = 1u << 7;
    cr_expect_eq(sfb_surface_tessellate(s, &c, &t), SFB_INVALID_ARGS);
    /* rate 1024 is allowed */
    c = sfb_tess_config_init(1024);
    sfb_mesh *one = tx_mesh(ctx, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    sfb_surface *s1 = tx_surface(ctx, one);
    cr_expect_eq(sfb_surface_tessellate(s1, &c, &t), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_expect_eq(t.vertex_count, 1025 * 1025);
    sfb_tess_data_free(&t);
    /* a surface without patches */
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 1);
    sfb_surface *plain = NULL;
    cr_assert_eq(sfb_surface_create(ctx, m, &sc, &plain), SFB_SUCCESS);
    c = sfb_tess_config_init(4);
    cr_expect_eq(sfb_surface_tessellate(plain, &c, &t), SFB_INVALID_ARGS);
    cr_expect(strstr(sfb_last_error(ctx), "SFB_REFINE_PATCHES") != NULL, "message: %s", sfb_last_error(ctx));
    sfb_surface_destroy(plain);
    sfb_surface_destroy(s1);
    sfb_mesh_destroy(one);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

Test(tess, too_many_elements_is_refused_before_allocating)
{
    sfb_context *ctx = tx_ctx();
    char *obj = grid_obj(14, 14, 0.0); /* 196 faces x 1024^2 > SFB_MAX_ELEMENTS */
    sfb_mesh *m = tx_mesh(ctx, obj);
    sfb_surface *s = tx_surface(ctx, m);
    sfb_tess_config c = sfb_tess_config_init(1024);
    sfb_tess_data t;
    cr_expect_eq(sfb_surface_tessellate(s, &c, &t), SFB_LIMIT_EXCEEDED, "%s", sfb_last_error(ctx));
    cr_expect(strstr(sfb_last_error(ctx), "SFB_MAX_ELEMENTS") != NULL, "message: %s", sfb_last_error(ctx));
    cr_expect_null(t.positions);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    free(obj);
}

/* a counting allocator that can be told to fail */
typedef struct tx_alloc {
    long live, total, fail_at; /* fail_at: the allocation number (from 1) that fails; 0: never */
} tx_alloc;

typedef struct tx_hdr {
    size_t size;
    size_t pad;
} tx_hdr;

static void *tx_malloc(size_t n, void *user)
{
    tx_alloc *a = user;
    if (a->fail_at && a->total + 1 == a->fail_at) {
        a->total++;
        return NULL;
    }
    tx_hdr *h = malloc(sizeof *h + n);
    if (!h) return NULL;
    h->size = n;
    a->live++;
    a->total++;
    return h + 1;
}

static void *tx_realloc(void *p, size_t n, void *user)
{
    tx_alloc *a = user;
    if (!p) return tx_malloc(n, user);
    if (a->fail_at && a->total + 1 == a->fail_at) {
        a->total++;
        return NULL;
    }
    tx_hdr *h = realloc((tx_hdr *)p - 1, sizeof *h + n);
    if (!h) return NULL;
    h->size = n;
    a->total++;
    return h + 1;
}

static void tx_free(void *p, void *user)
{
    tx_alloc *a = user;
    if (!p) return;
    a->live--;
    free((tx_hdr *)p - 1);
}

typedef struct tx_prog {
    int calls, cancel_at; /* cancel at call number cancel_at (from 1); 0: never */
    int bad;
    float last;
} tx_prog;

static int tx_progress(float done, const char *stage, void *user)
{
    tx_prog *p = user;
    p->calls++;
    if (!(done >= 0.0f && done <= 1.0f) || !stage) p->bad++;
    if (strcmp(stage, "tessellate") == 0) {
        if (done + 1e-6f < p->last) p->bad++;
        p->last = done;
    }
    return p->cancel_at && p->calls == p->cancel_at;
}

/* Builds the surface with nothing failing, then tessellates with allocation number
 * base + k failing (or the k-th progress report cancelling) for every k until the call
 * succeeds; every failure must return the expected code, leave `out` zeroed and leak
 * nothing. */
static void failure_sweep(int cancel, float tol, unsigned flags)
{
    tx_alloc al = { 0, 0, 0 };
    tx_prog pr = { 0, 0, 0, 0.0f };
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    cc.allocator.alloc = tx_malloc;
    cc.allocator.realloc = tx_realloc;
    cc.allocator.free = tx_free;
    cc.allocator.user = &al;
    cc.progress.func = tx_progress;
    cc.progress.user = &pr;
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    size_t n = strlen(prism_obj) + strlen(prism_creased_tags) + 1;
    char *obj = malloc(n);
    snprintf(obj, n, "%s%s", prism_obj, prism_creased_tags);
    sfb_mesh *m = tx_mesh(ctx, obj);
    sfb_surface *s = tx_surface(ctx, m);
    free(obj);
    sfb_tess_config c = sfb_tess_config_init(70); /* more vertices than one evaluation chunk */
    c.tolerance = tol;
    c.flags = flags;
    int failures = 0;
    for (int k = 1; k < 10000; ++k) {
        long live_before = al.live;
        sfb_tess_data t;
        pr.calls = 0;
        pr.last = 0.0f;
        if (cancel) pr.cancel_at = k;
        else al.fail_at = al.total + k;
        sfb_result r = sfb_surface_tessellate(s, &c, &t);
        al.fail_at = 0;
        pr.cancel_at = 0;
        if (r == SFB_SUCCESS) {
            cr_expect_gt(failures, 1, "only %d failure points", failures);
            if (flags & SFB_TESS_SPLIT_CREASES) {
                edge_stats st = stats_of(&t, NULL); /* open along the five rim edges, 2 x 70 segments a side */
                cr_expect_eq(st.once, 2L * 5 * 2 * 70);
                cr_expect_eq(st.directed_dup, 0);
            } else {
                expect_closed(&t, "after the failures", 70);
            }
            sfb_tess_data_free(&t);
            break;
        }
        failures++;
        cr_assert_eq(r, cancel ? SFB_CANCELLED : SFB_OUT_OF_MEMORY, "step %d: %s: %s", k, sfb_result_string(r), sfb_last_error(ctx));
        cr_assert_eq(al.live, live_before, "step %d leaked %ld blocks", k, al.live - live_before);
        cr_assert_null(t.positions);
        cr_assert_null(t.triangles);
        cr_assert_eq(t.vertex_count, 0);
    }
    cr_expect_eq(pr.bad, 0, "progress values out of order or outside [0,1]");
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    cr_expect_eq(al.live, 0, "%ld blocks leaked", al.live);
}

Test(tess, cancellation_at_every_report)
{
    failure_sweep(1, 0.0f, 0);
}

Test(tess, cancellation_at_every_report_adaptive)
{
    failure_sweep(1, 1e-3f, SFB_TESS_SPLIT_CREASES);
}

Test(tess, allocation_failure_at_every_step)
{
    failure_sweep(0, 0.0f, SFB_TESS_SPLIT_CREASES);
}

Test(tess, allocation_failure_at_every_step_adaptive)
{
    failure_sweep(0, 1e-3f, 0);
}

Test(tess, memory_budget_refuses)
{
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    cc.memory_budget = (size_t)4 << 20;
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    sfb_mesh *m = tx_mesh(ctx, cube_obj);
    sfb_surface *s = tx_surface(ctx, m);
    sfb_tess_config c = sfb_tess_config_init(512); /* 1.5M vertices: far over 4 MiB */
    sfb_tess_data t;
    cr_expect_eq(sfb_surface_tessellate(s, &c, &t), SFB_LIMIT_EXCEEDED, "%s", sfb_last_error(ctx));
    cr_expect(strstr(sfb_last_error(ctx), "tessellation") != NULL, "message: %s", sfb_last_error(ctx));
    cr_expect_null(t.positions);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}
