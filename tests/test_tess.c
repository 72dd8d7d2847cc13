/* surfblend: tessellation tests (sfb_surface_tessellate): watertightness and orientation on
 * closed meshes (quads, n-gons, triangles, creases), split creases, open meshes and holes,
 * vertex counts, agreement with sfb_surface_eval, adaptive mode, argument checks,
 * cancellation and allocation failures without leaks; the same for Loop surfaces (suite
 * tess_loop, on OpenSubdiv's loop_* shapes from $SHAPES or ../shared/peers/opensubdiv-shapes,
 * skipped when absent), plus (u,v) tiling of each triangle param face. */
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
    sc.flags = SFB_REFINE_PATCHES | SFB_REFINE_UVS; /* UVs: only where the mesh has them */
    sfb_surface *s = NULL;
    sfb_result r = sfb_surface_create(ctx, m, &sc, &s);
    cr_assert_eq(r, SFB_SUCCESS, "surface: %s", sfb_last_error(ctx));
    return s;
}

static sfb_surface *tx_surface_loop(sfb_context *ctx, const sfb_mesh *m)
{
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_LOOP, 0);
    sc.flags = SFB_REFINE_PATCHES;
    sfb_surface *s = NULL;
    sfb_result r = sfb_surface_create(ctx, m, &sc, &s);
    cr_assert_eq(r, SFB_SUCCESS, "Loop surface: %s", sfb_last_error(ctx));
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

/* Builds the surface of `obj` (scheme, with patches) with nothing failing, then tessellates
 * at `rate` with allocation number base + k failing (or the k-th progress report cancelling)
 * for every k until the call succeeds; every failure must return the expected code, leave
 * `out` zeroed and leak nothing. The result is closed, or with split creases open along
 * `split_once` edges. */
static void failure_sweep_mesh(int cancel, float tol, unsigned flags, const char *obj, sfb_scheme scheme, int rate, long split_once)
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
    sfb_mesh *m = tx_mesh(ctx, obj);
    sfb_surface *s = scheme == SFB_SCHEME_LOOP ? tx_surface_loop(ctx, m) : tx_surface(ctx, m);
    sfb_tess_config c = sfb_tess_config_init(rate);
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
            if (flags & (SFB_TESS_SPLIT_CREASES | SFB_TESS_UVS)) {
                edge_stats st = stats_of(&t, NULL);
                if (tol == 0.0f) cr_expect_eq(st.once, split_once);
                else cr_expect_gt(st.once, 0);
                cr_expect_eq(st.directed_dup, 0);
            } else {
                expect_closed(&t, "after the failures", rate);
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

static void failure_sweep(int cancel, float tol, unsigned flags)
{
    size_t n = strlen(prism_obj) + strlen(prism_creased_tags) + 1;
    char *obj = malloc(n);
    snprintf(obj, n, "%s%s", prism_obj, prism_creased_tags);
    /* rate 70: more vertices than one evaluation chunk; with split creases open along the five
     * rim edges, 2 x 70 segments a side */
    failure_sweep_mesh(cancel, tol, flags, obj, SFB_SCHEME_CATMARK, 70, 2L * 5 * 2 * 70);
    free(obj);
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

/* ------------------------------------------------------------------------- */
/* Loop surfaces: every param face is a base triangle, (u,v) barycentric      */

/* OpenSubdiv's regression shapes: $SHAPES (as tests/run_all.sh), else the default relative to
 * the repository root (where the unit tests run) or to build/. */
static char *shape_text(const char *name, size_t *size)
{
    const char *env = getenv("SHAPES");
    const char *dirs[3] = { env && env[0] ? env : "../shared/peers/opensubdiv-shapes", "../shared/peers/opensubdiv-shapes",
                            "../../shared/peers/opensubdiv-shapes" };
    for (int k = 0; k < 3; ++k) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s.obj", dirs[k], name);
        FILE *f = fopen(path, "rb");
        if (!f) continue;
        fseek(f, 0, SEEK_END);
        long n = ftell(f);
        fseek(f, 0, SEEK_SET);
        char *buf = malloc((size_t)n + 1);
        cr_assert_not_null(buf);
        cr_assert_eq(fread(buf, 1, (size_t)n, f), (size_t)n);
        fclose(f);
        buf[n] = '\0';
        *size = (size_t)n;
        return buf;
    }
    return NULL;
}

/* a peer shape as a Loop surface; skips the test when the shapes are not there */
static sfb_surface *loop_shape(sfb_context *ctx, const char *name, sfb_mesh **mesh)
{
    size_t size = 0;
    char *text = shape_text(name, &size);
    if (!text) {
        sfb_context_destroy(ctx);
        cr_skip_test("peer shape %s.obj not found (set SHAPES to opensubdiv-shapes)", name);
    }
    sfb_result r = sfb_mesh_read_obj(ctx, text, size, mesh);
    free(text);
    cr_assert_eq(r, SFB_SUCCESS, "%s: %s", name, sfb_last_error(ctx));
    return tx_surface_loop(ctx, *mesh);
}

/* Loop locations: inside the triangle (u + v <= 1, as evaluation requires) */
static void check_loop_locations(const sfb_tess_data *t, const char *what)
{
    for (int v = 0; v < t->vertex_count; ++v) {
        const sfb_location *l = &t->locations[v];
        cr_assert((double)l->u + (double)l->v <= 1.0, "%s: vertex %d at (%d, %.9g, %.9g): u + v > 1", what, v, l->face, l->u, l->v);
    }
}

/* closed, consistently oriented, no degenerate triangles, V - E + F = chi */
static void expect_closed_chi(const sfb_tess_data *t, const char *what, int rate, long chi)
{
    edge_stats st = stats_of(t, NULL);
    cr_expect_eq(st.once, 0, "%s rate %d: %ld boundary edges", what, rate, st.once);
    cr_expect_eq(st.more, 0, "%s rate %d: %ld edges used more than twice", what, rate, st.more);
    cr_expect_eq(st.directed_dup, 0, "%s rate %d: %ld directed edges used twice (inconsistent orientation)", what, rate,
                 st.directed_dup);
    cr_expect_eq(st.degenerate, 0, "%s rate %d: %ld degenerate triangles", what, rate, st.degenerate);
    cr_expect_eq((long)t->vertex_count - st.undirected + t->triangle_count, chi, "%s rate %d: V - E + F = %ld", what, rate,
                 (long)t->vertex_count - st.undirected + t->triangle_count);
}

/* positions (and normals) are those sfb_surface_eval gives at the output's locations */
static void expect_eval_agrees(const sfb_surface *s, sfb_context *ctx, const sfb_tess_data *t, const char *what)
{
    float *p = malloc(sizeof(float) * 3 * (size_t)t->vertex_count);
    float *n = malloc(sizeof(float) * 3 * (size_t)t->vertex_count);
    cr_assert(p && n);
    sfb_eval_output eo;
    memset(&eo, 0, sizeof eo);
    eo.position = p;
    eo.normal = n;
    cr_assert_eq(sfb_surface_eval(s, t->locations, t->vertex_count, &eo), SFB_SUCCESS, "%s: %s", what, sfb_last_error(ctx));
    for (int i = 0; i < 3 * t->vertex_count; ++i) {
        cr_assert(fabsf(p[i] - t->positions[i]) <= 1e-5f, "%s: position %d: %g vs eval %g", what, i / 3, t->positions[i], p[i]);
        cr_assert(fabsf(n[i] - t->normals[i]) <= 1e-4f, "%s: normal %d: %g vs eval %g", what, i / 3, t->normals[i], n[i]);
    }
    free(p);
    free(n);
}

/* every triangle faces the side its vertices' normals point to */
static void expect_follows_normals(const sfb_tess_data *t, const char *what)
{
    int bad = 0;
    for (int i = 0; i < t->triangle_count; ++i) {
        const int *v = t->triangles + 3 * i;
        const float *a = t->positions + 3 * v[0], *b = t->positions + 3 * v[1], *c = t->positions + 3 * v[2];
        double e1[3], e2[3], n[3], avg[3] = { 0, 0, 0 };
        for (int q = 0; q < 3; ++q) {
            e1[q] = (double)b[q] - a[q];
            e2[q] = (double)c[q] - a[q];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        for (int j = 0; j < 3; ++j)
            for (int q = 0; q < 3; ++q) avg[q] += t->normals[3 * v[j] + q];
        double dot = n[0] * avg[0] + n[1] * avg[1] + n[2] * avg[2];
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        bad += !(len > 0.0 && dot / len > 0.5);
    }
    cr_expect_eq(bad, 0, "%s: %d of %d triangles face away from their normals", what, bad, t->triangle_count);
}

/* Where a tessellation vertex sits on the base mesh, from its location: a base vertex (a
 * corner of its param face), a point inside a base edge (an undirected vertex pair), or
 * inside a face. */
typedef struct loop_where {
    int kind; /* 0 base vertex a, 1 inside edge (a,b) with a < b, 2 inside a face */
    int a, b;
} loop_where;

static loop_where where_of(const sfb_mesh_desc *d, const sfb_location *l)
{
    loop_where w = { 2, -1, -1 };
    const int *fv = d->face_vertices + 3 * l->face; /* all faces are triangles */
    double u = l->u, v = l->v, eps = 1e-6;
    int s0 = fabs(v) < eps, s1 = fabs(u + v - 1.0) < eps, s2 = fabs(u) < eps;
    if (s0 && s2) { w.kind = 0; w.a = fv[0]; }
    else if (s0 && s1) { w.kind = 0; w.a = fv[1]; }
    else if (s1 && s2) { w.kind = 0; w.a = fv[2]; }
    else if (s0 || s1 || s2) {
        int k = s0 ? 0 : s1 ? 1 : 2, a = fv[k], b = fv[(k + 1) % 3];
        w.kind = 1;
        w.a = a < b ? a : b;
        w.b = a < b ? b : a;
    }
    return w;
}

/* Checks that each boundary edge of the tessellation lies along one base edge that `allowed`
 * accepts (both ends inside that edge or at its end vertices); returns how many base edges
 * carry boundary edges (through *covered: their segment counts per base edge, keyed by pair). */
typedef int (*edge_pred)(const sfb_mesh_desc *d, int a, int b, void *user);

static long expect_boundary_along(const sfb_mesh_desc *d, const sfb_tess_data *t, edge_pred allowed, void *user, const char *what)
{
    int *bnd = NULL;
    edge_stats st = stats_of(t, &bnd);
    cr_expect_eq(st.more, 0, "%s: edges used more than twice", what);
    cr_expect_eq(st.directed_dup, 0, "%s: inconsistent orientation", what);
    cr_expect_eq(st.degenerate, 0, "%s: degenerate triangles", what);
    long bad = 0;
    for (long e = 0; e < st.once; ++e) {
        loop_where p = where_of(d, &t->locations[bnd[2 * e]]), q = where_of(d, &t->locations[bnd[2 * e + 1]]);
        int a = -1, b = -1, ok = 1;
        if (p.kind == 2 || q.kind == 2) ok = 0;
        else if (p.kind == 1 && q.kind == 1) { ok = p.a == q.a && p.b == q.b; a = p.a; b = p.b; }
        else if (p.kind == 1) { ok = q.a == p.a || q.a == p.b; a = p.a; b = p.b; }
        else if (q.kind == 1) { ok = p.a == q.a || p.a == q.b; a = q.a; b = q.b; }
        else { a = p.a < q.a ? p.a : q.a; b = p.a < q.a ? q.a : p.a; } /* a single segment: the whole edge */
        if (ok) ok = allowed(d, a, b, user);
        if (!ok && bad < 5)
            cr_expect(0, "%s: boundary edge %d-%d is not along an allowed base edge (kinds %d,%d)", what, bnd[2 * e], bnd[2 * e + 1], p.kind,
                      q.kind);
        bad += !ok;
    }
    cr_expect_eq(bad, 0, "%s: %ld of %ld boundary edges are not along allowed base edges", what, bad, st.once);
    free(bnd);
    return st.once;
}

/* the number of faces of the base mesh using edge (a,b) */
static int edge_uses(const sfb_mesh_desc *d, int a, int b)
{
    int n = 0;
    for (int f = 0; f < d->face_count; ++f)
        for (int k = 0; k < 3; ++k) {
            int x = d->face_vertices[3 * f + k], y = d->face_vertices[3 * f + (k + 1) % 3];
            n += (x == a && y == b) || (x == b && y == a);
        }
    return n;
}

static int is_base_boundary(const sfb_mesh_desc *d, int a, int b, void *user)
{
    (void)user;
    return edge_uses(d, a, b) == 1;
}

static long base_boundary_edges(const sfb_mesh_desc *d)
{
    long n = 0;
    for (int f = 0; f < d->face_count; ++f)
        for (int k = 0; k < 3; ++k) n += edge_uses(d, d->face_vertices[3 * f + k], d->face_vertices[3 * f + (k + 1) % 3]) == 1;
    return n;
}

/* (u,v) of tessellation vertex `v` in param face f's own coordinates: located on f, or on a
 * corner or an edge f shares with the face it was located on. Returns 0 when it is neither. */
static int uv_in_face(const sfb_mesh_desc *d, const sfb_tess_data *t, int v, int f, double *u, double *w)
{
    const sfb_location *l = &t->locations[v];
    const int *ff = d->face_vertices + 3 * f, *fg = d->face_vertices + 3 * l->face;
    static const double cu[3] = { 0, 1, 0 }, cv[3] = { 0, 0, 1 };
    if (l->face == f) {
        *u = l->u;
        *w = l->v;
        return 1;
    }
    loop_where p = where_of(d, l);
    if (p.kind == 2) return 0;
    /* the point as (1-s) A + s B on a side A -> B of the face it was located on */
    int A, B;
    double sp;
    if (p.kind == 0) { A = B = p.a; sp = 0.0; }
    else {
        double eps = 1e-6;
        int k = fabs((double)l->v) < eps ? 0 : fabs((double)l->u + l->v - 1.0) < eps ? 1 : 2;
        A = fg[k];
        B = fg[(k + 1) % 3];
        sp = k == 0 ? l->u : k == 1 ? l->v : 1.0 - l->v;
    }
    int ia = -1, ib = -1;
    for (int k = 0; k < 3; ++k) {
        if (ff[k] == A) ia = k;
        if (ff[k] == B) ib = k;
    }
    if (ia < 0 || ib < 0) return 0;
    *u = (1.0 - sp) * cu[ia] + sp * cu[ib];
    *w = (1.0 - sp) * cv[ia] + sp * cv[ib];
    return 1;
}

/* The triangles of each param face tile its (u,v) triangle: every one counter-clockwise with
 * positive area, together area 1/2. */
static void expect_tiles_param_faces(const sfb_mesh *m, const sfb_tess_data *t, const char *what)
{
    sfb_mesh_desc d;
    sfb_mesh_get_desc(m, &d);
    double *area = calloc((size_t)d.face_count, sizeof(double));
    int bad = 0;
    for (int i = 0; i < t->triangle_count; ++i) {
        int f = t->triangle_faces[i];
        double u[3], v[3];
        int ok = 1;
        for (int c = 0; c < 3; ++c) ok &= uv_in_face(&d, t, t->triangles[3 * i + c], f, &u[c], &v[c]);
        double a2 = (u[1] - u[0]) * (v[2] - v[0]) - (v[1] - v[0]) * (u[2] - u[0]);
        if (!ok || !(a2 > 1e-9)) {
            if (bad < 3) cr_expect(0, "%s: triangle %d of face %d: %s, twice its area %g", what, i, f, ok ? "not counter-clockwise" : "vertex not on the face", a2);
            bad++;
        }
        area[f] += 0.5 * a2;
    }
    cr_expect_eq(bad, 0, "%s: %d bad triangles in (u,v)", what, bad);
    for (int f = 0; f < d.face_count; ++f)
        cr_expect(fabs(area[f] - 0.5) < 1e-5, "%s: face %d: triangles cover an area %g in (u,v), not 1/2", what, f, area[f]);
    free(area);
}

/* The closed shapes; loop_pole8 (a valence-8 pole) is an open disc, closed everywhere but
 * along its 8 base boundary edges. */
static const char *loop_shapes[3] = { "loop_cube", "loop_icosahedron", "loop_pole8" };

/* Structural checks of a Loop tessellation without split creases: locations inside their
 * triangles; open only along base boundary edges (rate segments each in uniform mode,
 * rate < 0: adaptive); consistently oriented; the base mesh's Euler characteristic. */
static void check_loop_tess(const sfb_mesh *m, const sfb_tess_data *t, const char *what, int rate)
{
    sfb_mesh_desc d;
    sfb_mesh_info mi;
    sfb_mesh_get_desc(m, &d);
    sfb_mesh_get_info(m, &mi);
    check_loop_locations(t, what);
    expect_tiles_param_faces(m, t, what);
    long nb = base_boundary_edges(&d);
    long once = expect_boundary_along(&d, t, is_base_boundary, NULL, what);
    if (rate > 0) cr_expect_eq(once, nb * rate, "%s rate %d: %ld boundary edges, base boundary %ld", what, rate, once, nb);
    else cr_expect_geq(once, nb, "%s adaptive: %ld boundary edges, base boundary %ld", what, once, nb);
    if (nb == 0) expect_closed_chi(t, what, rate, (long)mi.vertex_count - mi.edge_count + mi.face_count);
    else {
        edge_stats st = stats_of(t, NULL);
        cr_expect_eq((long)t->vertex_count - st.undirected + t->triangle_count, (long)mi.vertex_count - mi.edge_count + mi.face_count,
                     "%s rate %d: Euler characteristic differs from the base mesh's", what, rate);
    }
}

Test(tess_loop, closed_uniform_counts_and_orientation)
{
    for (int k = 0; k < 3; ++k) {
        sfb_context *ctx = tx_ctx();
        sfb_mesh *m = NULL;
        sfb_surface *s = loop_shape(ctx, loop_shapes[k], &m);
        sfb_mesh_info mi;
        sfb_mesh_get_info(m, &mi);
        cr_assert_eq(sfb_surface_param_face_count(s), mi.face_count, "a Loop param face is a base triangle");
        static const int rates[] = { 1, 2, 3, 5, 8 };
        for (int q = 0; q < 5; ++q) {
            int r = rates[q];
            sfb_tess_data t = tess_ok(s, ctx, r, 0.0f, 0);
            check_loop_tess(m, &t, loop_shapes[k], r);
            cr_expect_eq(t.triangle_count, mi.face_count * r * r, "%s rate %d: %d triangles", loop_shapes[k], r, t.triangle_count);
            /* V = nv + ne (r-1) + nf (r-1)(r-2)/2: every base vertex, edge point and face point once */
            cr_expect_eq(t.vertex_count, mi.vertex_count + mi.edge_count * (r - 1) + mi.face_count * (r - 1) * (r - 2) / 2,
                         "%s rate %d: %d vertices", loop_shapes[k], r, t.vertex_count);
            for (int i = 0; i < t.triangle_count; ++i) cr_assert_eq(t.triangle_faces[i], i / (r * r), "faces in order, r^2 each");
            if (r == 5) {
                expect_follows_normals(&t, loop_shapes[k]);
                expect_eval_agrees(s, ctx, &t, loop_shapes[k]);
            }
            sfb_tess_data_free(&t);
        }
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
        sfb_context_destroy(ctx);
    }
}

/* the locations of a uniform rate-r face: exactly the points (i/r, j/r), i + j <= r */
Test(tess_loop, uniform_grid_locations)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = NULL;
    sfb_surface *s = loop_shape(ctx, "loop_icosahedron", &m);
    int r = 7;
    sfb_tess_data t = tess_ok(s, ctx, r, 0.0f, 0);
    /* every triangle of face f uses vertices at grid points of f: its vertices located on f
     * sit on the grid; the ones located on a neighbour are on a shared edge */
    long on_grid = 0, total = 0;
    for (int v = 0; v < t.vertex_count; ++v) {
        const sfb_location *l = &t.locations[v];
        double i = (double)l->u * r, j = (double)l->v * r;
        total++;
        on_grid += fabs(i - floor(i + 0.5)) < 1e-4 && fabs(j - floor(j + 0.5)) < 1e-4;
    }
    cr_expect_eq(on_grid, total, "%ld of %ld vertices off the rate-%d grid", total - on_grid, total, r);
    /* each triangle covers area 1/(2 r^2) of its face in (u,v), counter-clockwise, when all
     * three vertices were located on that face */
    int checked = 0;
    for (int i = 0; i < t.triangle_count; ++i) {
        const int *v = t.triangles + 3 * i;
        int f = t.triangle_faces[i];
        if (t.locations[v[0]].face != f || t.locations[v[1]].face != f || t.locations[v[2]].face != f) continue;
        const sfb_location *a = &t.locations[v[0]], *b = &t.locations[v[1]], *c = &t.locations[v[2]];
        double area2 = ((double)b->u - a->u) * ((double)c->v - a->v) - ((double)b->v - a->v) * ((double)c->u - a->u);
        cr_expect(fabs(area2 - 1.0 / (r * r)) < 1e-5, "triangle %d: twice its (u,v) area is %g", i, area2);
        checked++;
    }
    cr_expect_gt(checked, t.triangle_count / 2);
    sfb_tess_data_free(&t);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* adaptive: the three shapes, and two whose faces get different rates (zipper strips) */
Test(tess_loop, closed_adaptive)
{
    static const char *names[5] = { "loop_cube", "loop_icosahedron", "loop_pole8", "loop_cube_asymmetric", "loop_pole64" };
    static const float tols[4] = { 1e-1f, 3e-2f, 1e-2f, 3e-3f };
    for (int k = 0; k < 5; ++k) {
        sfb_context *ctx = tx_ctx();
        sfb_mesh *m = NULL;
        sfb_surface *s = loop_shape(ctx, names[k], &m);
        int prev = 0, mixed = 0, np = sfb_surface_param_face_count(s);
        for (int q = 0; q < 4; ++q) {
            sfb_tess_data t = tess_ok(s, ctx, 12, tols[q], 0);
            check_loop_tess(m, &t, names[k], -1);
            expect_follows_normals(&t, names[k]);
            expect_eval_agrees(s, ctx, &t, names[k]);
            cr_expect_geq(t.triangle_count, prev, "%s: a smaller tolerance gave fewer triangles", names[k]);
            prev = t.triangle_count;
            /* faces with different triangle counts: zipper strips were needed */
            int *counts = calloc((size_t)np, sizeof(int));
            for (int i = 0; i < t.triangle_count; ++i) counts[t.triangle_faces[i]]++;
            for (int f = 1; f < np; ++f) mixed += counts[f] != counts[0];
            free(counts);
            sfb_tess_data_free(&t);
        }
        if (k >= 3) cr_expect_gt(mixed, 0, "%s: every face got the same count at every tolerance", names[k]);
        /* a huge tolerance: every face at rate 1, the base triangles */
        sfb_tess_data t = tess_ok(s, ctx, 12, 1e6f, 0);
        sfb_tess_data one = tess_ok(s, ctx, 1, 0.0f, 0);
        cr_expect_eq(t.triangle_count, one.triangle_count);
        cr_expect_eq(t.vertex_count, one.vertex_count);
        cr_expect_eq(memcmp(t.triangles, one.triangles, sizeof(int) * 3 * (size_t)t.triangle_count), 0);
        sfb_tess_data_free(&t);
        sfb_tess_data_free(&one);
        /* a tolerance no face meets: uniform at the full rate */
        t = tess_ok(s, ctx, 6, 1e-9f, 0);
        sfb_tess_data u = tess_ok(s, ctx, 6, 0.0f, 0);
        cr_expect_eq(t.triangle_count, u.triangle_count);
        cr_expect_eq(t.vertex_count, u.vertex_count);
        sfb_tess_data_free(&t);
        sfb_tess_data_free(&u);
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
        sfb_context_destroy(ctx);
    }
}

Test(tess_loop, open_mesh_boundary_along_base_boundary_edges)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = NULL;
    sfb_surface *s = loop_shape(ctx, "loop_triangle_edgecorner", &m);
    sfb_mesh_desc d;
    sfb_mesh_get_desc(m, &d);
    long nb = base_boundary_edges(&d);
    cr_assert_gt(nb, 0);
    for (int r = 1; r <= 6; r += (r < 3 ? 1 : 3)) {
        for (int split = 0; split < 2; ++split) { /* boundary edges are never split */
            sfb_tess_data t = tess_ok(s, ctx, r, 0.0f, split ? SFB_TESS_SPLIT_CREASES : 0);
            check_loop_locations(&t, "edgecorner");
            cr_expect_eq(t.triangle_count, d.face_count * r * r);
            long once = expect_boundary_along(&d, &t, is_base_boundary, NULL, "loop_triangle_edgecorner");
            cr_expect_eq(once, nb * r, "rate %d: %ld boundary edges, base boundary %ld x %d", r, once, nb, r);
            sfb_tess_data_free(&t);
        }
    }
    /* adaptive: still open only along the base boundary, every base boundary edge at least once */
    static const float tols[2] = { 1e-2f, 1e-4f };
    for (int q = 0; q < 2; ++q) {
        sfb_tess_data t = tess_ok(s, ctx, 16, tols[q], 0);
        check_loop_locations(&t, "edgecorner adaptive");
        long once = expect_boundary_along(&d, &t, is_base_boundary, NULL, "loop_triangle_edgecorner adaptive");
        cr_expect_geq(once, nb);
        expect_eval_agrees(s, ctx, &t, "loop_triangle_edgecorner adaptive");
        sfb_tess_data_free(&t);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* infinitely sharp interior edges of the base mesh */
static int is_inf_crease(const sfb_mesh_desc *d, int a, int b, void *user)
{
    (void)user;
    for (int c = 0; c < d->crease_count; ++c) {
        int x = d->crease_vertices[2 * c], y = d->crease_vertices[2 * c + 1];
        if (((x == a && y == b) || (x == b && y == a)) && d->crease_sharpness[c] >= SFB_SHARPNESS_INFINITE)
            return edge_uses(d, a, b) == 2;
    }
    return 0;
}

/* base vertices where exactly one infinitely sharp interior edge ends (darts: one sector) */
static int inf_crease_count_at(const sfb_mesh_desc *d, int v)
{
    int n = 0;
    for (int c = 0; c < d->crease_count; ++c) {
        int x = d->crease_vertices[2 * c], y = d->crease_vertices[2 * c + 1];
        if ((x == v || y == v) && is_inf_crease(d, x, y, NULL)) n++;
    }
    return n;
}

static void check_loop_split(const char *name, long chi)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = NULL;
    sfb_surface *s = loop_shape(ctx, name, &m);
    sfb_mesh_desc d;
    sfb_mesh_get_desc(m, &d);
    long ninf = 0, isolated = 0;
    for (int c = 0; c < d.crease_count; ++c) {
        int a = d.crease_vertices[2 * c], b = d.crease_vertices[2 * c + 1];
        if (!is_inf_crease(&d, a, b, NULL)) continue;
        ninf++;
        isolated += inf_crease_count_at(&d, a) == 1 && inf_crease_count_at(&d, b) == 1;
    }
    cr_assert_gt(ninf, 0, "%s has no infinitely sharp interior edge", name);
    for (int pass = 0; pass < 4; ++pass) {
        int r = pass < 3 ? 1 + 2 * pass : 12;
        float tol = pass < 3 ? 0.0f : 1e-2f; /* mixed rates on both shapes */
        sfb_tess_data t = tess_ok(s, ctx, r, tol, 0);
        expect_closed_chi(&t, name, r, chi); /* without the flag the creases are shared */
        int plain_v = t.vertex_count;
        sfb_tess_data_free(&t);
        t = tess_ok(s, ctx, r, tol, SFB_TESS_SPLIT_CREASES);
        check_loop_locations(&t, name);
        expect_tiles_param_faces(m, &t, name);
        expect_eval_agrees(s, ctx, &t, name);
        long once = expect_boundary_along(&d, &t, is_inf_crease, NULL, name);
        /* an isolated sharp edge (a dart at each end) with one segment has no point to split */
        if (tol == 0.0f)
            cr_expect_eq(once, 2 * ninf * r - (r == 1 ? 2 * isolated : 0), "%s rate %d: %ld boundary edges, %ld sharp edges, %ld isolated",
                         name, r, once, ninf, isolated);
        else cr_expect_geq(once, 2 * ninf);
        cr_expect_gt(t.vertex_count, plain_v);
        /* every boundary vertex has a twin at the same position across the crease, except at
         * the end of a crease inside the surface (a dart: one sector, one vertex) */
        int *bnd = NULL;
        edge_stats st = stats_of(&t, &bnd);
        unsigned char *seen = calloc((size_t)t.vertex_count, 1);
        int lonely = 0, lonely_dart = 0;
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
                if (!twin) {
                    loop_where p = where_of(&d, &t.locations[v]);
                    lonely++;
                    lonely_dart += p.kind == 0 && inf_crease_count_at(&d, p.a) == 1;
                }
            }
        cr_expect_eq(lonely, lonely_dart, "%s rate %d: %d boundary vertices without a twin, %d of them darts", name, r, lonely, lonely_dart);
        free(seen);
        free(bnd);
        sfb_tess_data_free(&t);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

Test(tess_loop, split_creases_cubes_infsharp)
{
    check_loop_split("loop_cubes_infsharp", 2L * 4); /* four closed cubes */
}

Test(tess_loop, split_creases_icos_infsharp)
{
    check_loop_split("loop_icos_infsharp", 2L * 4); /* four closed icosahedra */
}

/* an octahedron (Loop: six valence-4 extraordinary vertices) with its equator infinitely sharp */
static const char *octa_creased_obj =
    "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
    "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n"
    "t crease 2/1/0 0 2 10\nt crease 2/1/0 2 1 10\nt crease 2/1/0 1 3 10\nt crease 2/1/0 3 0 10\n";

/* rate 130: 6 + 12 x 129 + 8 x 129 x 128 / 2 = 67602 vertices, more than one evaluation
 * chunk; split: open along the 4 equator edges, 130 segments a side */
#define OCTA_RATE 130

Test(tess_loop, octahedron_counts)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = tx_mesh(ctx, octa_creased_obj);
    sfb_surface *s = tx_surface_loop(ctx, m);
    sfb_tess_data t = tess_ok(s, ctx, OCTA_RATE, 0.0f, 0);
    check_loop_tess(m, &t, "octahedron", OCTA_RATE);
    cr_expect_eq(t.vertex_count, 67602);
    cr_expect_eq(t.triangle_count, 8 * OCTA_RATE * OCTA_RATE);
    sfb_tess_data_free(&t);
    t = tess_ok(s, ctx, 4, 0.0f, SFB_TESS_SPLIT_CREASES);
    expect_follows_normals(&t, "octahedron split");
    expect_eval_agrees(s, ctx, &t, "octahedron split");
    /* the equator's vertices: 4 x 4 points, twice */
    cr_expect_eq(t.vertex_count, 6 + 12 * 3 + 8 * 3 * 2 / 2 + 4 * 4);
    sfb_tess_data_free(&t);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

Test(tess_loop, cancellation_at_every_report)
{
    failure_sweep_mesh(1, 0.0f, SFB_TESS_SPLIT_CREASES, octa_creased_obj, SFB_SCHEME_LOOP, OCTA_RATE, 2L * 4 * OCTA_RATE);
}

Test(tess_loop, cancellation_at_every_report_adaptive)
{
    failure_sweep_mesh(1, 1e-3f, 0, octa_creased_obj, SFB_SCHEME_LOOP, OCTA_RATE, 0);
}

Test(tess_loop, allocation_failure_at_every_step)
{
    failure_sweep_mesh(0, 0.0f, 0, octa_creased_obj, SFB_SCHEME_LOOP, OCTA_RATE, 0);
}

Test(tess_loop, allocation_failure_at_every_step_adaptive)
{
    failure_sweep_mesh(0, 1e-3f, SFB_TESS_SPLIT_CREASES, octa_creased_obj, SFB_SCHEME_LOOP, OCTA_RATE, 2L * 4 * OCTA_RATE);
}

/* a hole in a Loop surface makes nothing; its rim (3 base edges) is a boundary */
Test(tess_loop, holes_make_nothing)
{
    sfb_context *ctx = tx_ctx();
    size_t size = 0;
    char *text = shape_text("loop_icosahedron", &size);
    if (!text) {
        sfb_context_destroy(ctx);
        cr_skip_test("peer shape loop_icosahedron.obj not found (set SHAPES to opensubdiv-shapes)");
    }
    text = realloc(text, size + 32);
    size += (size_t)snprintf(text + size, 32, "\nt hole 1/0/0 3\n");
    sfb_mesh *m = NULL;
    cr_assert_eq(sfb_mesh_read_obj(ctx, text, size, &m), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    free(text);
    sfb_surface *s = tx_surface_loop(ctx, m);
    for (int q = 0; q < 2; ++q) {
        int r = 4;
        sfb_tess_data t = tess_ok(s, ctx, r, q ? 1e-3f : 0.0f, 0);
        check_loop_locations(&t, "icosahedron with a hole");
        if (!q) cr_expect_eq(t.triangle_count, 19 * r * r);
        for (int i = 0; i < t.triangle_count; ++i) cr_expect_neq(t.triangle_faces[i], 3);
        for (int v = 0; v < t.vertex_count; ++v) cr_expect_neq(t.locations[v].face, 3);
        edge_stats st = stats_of(&t, NULL);
        if (!q) cr_expect_eq(st.once, 3L * r);
        else cr_expect_geq(st.once, 3L);
        cr_expect_eq(st.more, 0);
        cr_expect_eq(st.directed_dup, 0);
        sfb_tess_data_free(&t);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* loop_cube_creases1 has semi-sharp creases only (sharpness 5 and less): nothing is split */
Test(tess_loop, split_creases_semisharp_only_stays_closed)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = NULL;
    sfb_surface *s = loop_shape(ctx, "loop_cube_creases1", &m);
    for (int r = 1; r <= 4; r += 3) {
        sfb_tess_data a = tess_ok(s, ctx, r, 0.0f, 0);
        sfb_tess_data b = tess_ok(s, ctx, r, 0.0f, SFB_TESS_SPLIT_CREASES);
        check_loop_tess(m, &b, "loop_cube_creases1", r);
        cr_expect_eq(a.vertex_count, b.vertex_count);
        cr_expect_eq(a.triangle_count, b.triangle_count);
        cr_expect_eq(memcmp(a.triangles, b.triangles, sizeof(int) * 3 * (size_t)a.triangle_count), 0);
        sfb_tess_data_free(&a);
        sfb_tess_data_free(&b);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* ------------------------------------------------------------------------- */
/* tessellated UVs (SFB_TESS_UVS)                                             */

/* A flat disk around a pentagon (loop: around a vertex of valence 5), every vertex given the
 * UV 0.25 * (x, y) + 0.5: the UV layout is the position mesh under an affine map, so the limit
 * UVs must be that map of the limit positions exactly -- creases included, which the layout
 * keeps (an infinitely sharp spoke ending in a dart, a semi-sharp ring edge). Catmull-Clark:
 * a pentagon and a ring of 5 quads (n-gon sub-faces, interior valence-3 vertices, a
 * boundary); Loop: 5 triangles around the centre, 10 around them. */
static char *flat_uv_disk(int loop)
{
    double P[40][2];
    int np = 0, F[40][4], nf = 0, fs = loop ? 3 : 4;
    const double pi = 3.14159265358979323846;
    if (!loop) {
        for (int i = 0; i < 5; ++i) { P[np][0] = cos(2 * pi * i / 5); P[np][1] = sin(2 * pi * i / 5); np++; }
        for (int i = 0; i < 5; ++i) { P[np][0] = 2 * cos(2 * pi * i / 5); P[np][1] = 2 * sin(2 * pi * i / 5); np++; }
        for (int i = 0; i < 5; ++i) { /* the quad beside pentagon edge (i, i+1), out to the outer ring */
            int a = i, b = (i + 1) % 5;
            F[nf][0] = b; F[nf][1] = a; F[nf][2] = 5 + a; F[nf][3] = 5 + b; nf++;
        }
    } else {
        P[np][0] = 0; P[np][1] = 0; np++;
        for (int i = 0; i < 5; ++i) { P[np][0] = cos(2 * pi * i / 5); P[np][1] = sin(2 * pi * i / 5); np++; }
        for (int i = 0; i < 5; ++i) { P[np][0] = 2 * cos(2 * pi * (i + 0.5) / 5); P[np][1] = 2 * sin(2 * pi * (i + 0.5) / 5); np++; }
        for (int i = 0; i < 5; ++i) {
            int a = 1 + i, b = 1 + (i + 1) % 5, o = 6 + i, on = 6 + (i + 1) % 5;
            F[nf][0] = 0; F[nf][1] = a; F[nf][2] = b; nf++;
            F[nf][0] = b; F[nf][1] = a; F[nf][2] = o; nf++;
            F[nf][0] = b; F[nf][1] = o; F[nf][2] = on; nf++;
        }
    }
    size_t cap = 8192;
    char *s = malloc(cap);
    size_t at = 0;
    for (int i = 0; i < np; ++i) at += (size_t)snprintf(s + at, cap - at, "v %.9g %.9g 0\n", P[i][0], P[i][1]);
    for (int i = 0; i < np; ++i) at += (size_t)snprintf(s + at, cap - at, "vt %.9g %.9g\n", 0.25 * P[i][0] + 0.5, 0.25 * P[i][1] + 0.5);
    if (!loop) at += (size_t)snprintf(s + at, cap - at, "f 1/1 2/2 3/3 4/4 5/5\n");
    for (int f = 0; f < nf; ++f) {
        at += (size_t)snprintf(s + at, cap - at, "f");
        for (int k = 0; k < fs; ++k) at += (size_t)snprintf(s + at, cap - at, " %d/%d", F[f][k] + 1, F[f][k] + 1);
        at += (size_t)snprintf(s + at, cap - at, "\n");
    }
    /* an infinitely sharp spoke (a dart inside) and a semi-sharp edge */
    at += (size_t)snprintf(s + at, cap - at, loop ? "t crease 2/1/0 0 1 10\nt crease 2/1/0 2 3 1.5\n"
                                                  : "t crease 2/1/0 0 5 10\nt crease 2/1/0 1 2 1.5\n");
    cr_assert_lt(at, cap);
    return s;
}

static sfb_surface *uv_surface(sfb_context *ctx, const sfb_mesh *m, sfb_scheme scheme)
{
    sfb_surface_config sc = sfb_surface_config_init(scheme, 0);
    sc.flags = SFB_REFINE_PATCHES | SFB_REFINE_UVS;
    sfb_surface *s = NULL;
    sfb_result r = sfb_surface_create(ctx, m, &sc, &s);
    cr_assert_eq(r, SFB_SUCCESS, "surface (%s): %s", sfb_scheme_name(scheme), sfb_last_error(ctx));
    return s;
}

static void expect_affine_uvs(const sfb_tess_data *t, const char *what)
{
    double worst = 0.0;
    cr_assert_not_null(t->uvs, "%s: no UVs", what);
    for (int v = 0; v < t->vertex_count; ++v)
        for (int c = 0; c < 2; ++c) {
            double d = fabs((double)t->uvs[2 * v + c] - (0.25 * t->positions[3 * v + c] + 0.5));
            if (d > worst) worst = d;
        }
    cr_expect_lt(worst, 2e-6, "%s: UVs are %g from the affine map of the positions", what, worst);
}

Test(tess_uv, limit_uvs_are_the_layout_map_of_the_limit_positions)
{
    static const struct { sfb_scheme scheme; int loop; const char *name; } cases[] = {
        { SFB_SCHEME_CATMARK, 0, "Catmull-Clark" }, { SFB_SCHEME_LOOP, 1, "Loop" }, { SFB_SCHEME_MANIFOLD_BLEND, 0, "manifold" },
        { SFB_SCHEME_TRIBEZIER, 1, "tribezier" } };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
        sfb_context *ctx = tx_ctx();
        char *obj = flat_uv_disk(cases[k].loop);
        sfb_mesh *m = tx_mesh(ctx, obj);
        sfb_surface *s = uv_surface(ctx, m, cases[k].scheme);
        const float tols[2] = { 0.0f, 1e-3f };
        for (int j = 0; j < 2; ++j) {
            sfb_tess_data t = tess_ok(s, ctx, 9, tols[j], SFB_TESS_UVS | SFB_TESS_SPLIT_CREASES);
            expect_affine_uvs(&t, cases[k].name);
            sfb_tess_data_free(&t);
        }
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
        sfb_context_destroy(ctx);
        free(obj);
    }
}

/* The UVs of a tribezier tessellation (rate 4, SFB_TESS_UVS) of obj, copied out (count pairs). */
static float *tribezier_tess_uvs(const char *obj, int *count)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = tx_mesh(ctx, obj);
    sfb_surface *s = uv_surface(ctx, m, SFB_SCHEME_TRIBEZIER);
    sfb_tess_data t = tess_ok(s, ctx, 4, 0.0f, SFB_TESS_UVS);
    cr_assert_not_null(t.uvs);
    float *uv = malloc(2 * sizeof(float) * (size_t)t.vertex_count);
    memcpy(uv, t.uvs, 2 * sizeof(float) * (size_t)t.vertex_count);
    *count = t.vertex_count;
    sfb_tess_data_free(&t);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    return uv;
}

/* A UV layout tribezier's builder refuses (every corner given the one UV (0.3, 0.6): one UV
 * value shared by every face, no fan): the tessellation still succeeds, with the linear UVs
 * (here that value everywhere), instead of failing. */
Test(tess_uv, tribezier_falls_back_to_linear_uvs)
{
    char *obj = flat_uv_disk(1);
    /* every vt line becomes the same value */
    size_t n = strlen(obj), at = 0;
    char *out = malloc(2 * n + 64);
    const char *p = obj;
    while (*p) {
        const char *e = strchr(p, '\n');
        size_t len = e ? (size_t)(e - p) + 1 : strlen(p);
        if (!strncmp(p, "vt ", 3)) at += (size_t)sprintf(out + at, "vt 0.3 0.6\n");
        else { memcpy(out + at, p, len); at += len; }
        p += len;
    }
    out[at] = 0;
    int count = 0;
    float *uv = tribezier_tess_uvs(out, &count);
    double worst = 0.0;
    for (int v = 0; v < count; ++v) worst = fmax(worst, fmax(fabs(uv[2 * v] - 0.3), fabs(uv[2 * v + 1] - 0.6)));
    cr_expect_lt(worst, 1e-6, "linear UVs of one value: %g off", worst);
    free(uv);
    free(out);
    free(obj);
}

/* A manifold UV layout the tribezier builder refuses (a UV triangle of zero area: the first ring
 * vertex given the centre's UV): linear UVs again, the tessellation does not fail. */
Test(tess_uv, tribezier_flat_uv_triangle_falls_back_to_linear_uvs)
{
    char *obj = flat_uv_disk(1);
    char *second = strstr(obj, "vt ");
    cr_assert_not_null(second);
    second = strstr(second + 3, "vt "); /* the UV of ring vertex 1 */
    cr_assert_not_null(second);
    char *end = strchr(second, '\n');
    size_t head = (size_t)(second - obj);
    char *out = malloc(strlen(obj) + 64);
    memcpy(out, obj, head);
    sprintf(out + head, "vt 0.5 0.5%s", end);
    int count = 0, outside = 0;
    float *uv = tribezier_tess_uvs(out, &count);
    for (int v = 0; v < count; ++v)
        for (int c = 0; c < 2; ++c) outside += !(uv[2 * v + c] >= 0.0f && uv[2 * v + c] <= 1.0f);
    cr_expect_eq(outside, 0, "%d UV coordinates outside the layout's [0, 1]", outside);
    free(uv);
    free(out);
    free(obj);
}

/* Seams the flat disk has none of: with SFB_TESS_UVS alone nothing is split, and the
 * triangles are those of the plain tessellation. */
Test(tess_uv, no_seams_no_split)
{
    sfb_context *ctx = tx_ctx();
    char *obj = flat_uv_disk(0);
    sfb_mesh *m = tx_mesh(ctx, obj);
    sfb_surface *s = uv_surface(ctx, m, SFB_SCHEME_CATMARK);
    sfb_tess_data a = tess_ok(s, ctx, 6, 0.0f, 0), b = tess_ok(s, ctx, 6, 0.0f, SFB_TESS_UVS);
    cr_expect_null(a.uvs);
    cr_expect_eq(a.vertex_count, b.vertex_count);
    cr_expect_eq(a.triangle_count, b.triangle_count);
    cr_expect_eq(memcmp(a.triangles, b.triangles, sizeof(int) * 3 * (size_t)a.triangle_count), 0);
    cr_expect_eq(memcmp(a.positions, b.positions, sizeof(float) * 3 * (size_t)a.vertex_count), 0);
    sfb_tess_data_free(&a);
    sfb_tess_data_free(&b);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    free(obj);
}

/* The cube with every face its own UV island (four UVs of its own), the unit square in the
 * face's vertex order:
 * every edge is a seam, so each face has its own (R+1)^2 vertices; the island is one quad with
 * pinned corners, whose limit is exactly its bilinear map, so a vertex's UV is its (u,v) in
 * its face. Welding by position gives the plain tessellation back. Trimmed too (the cut
 * points carry their face's UVs). */
static const char *cube_islands_obj =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "f 1/1 2/2 4/3 3/4\nf 3/5 4/6 6/7 5/8\nf 5/9 6/10 8/11 7/12\nf 7/13 8/14 2/15 1/16\nf 2/17 8/18 6/19 4/20\n"
    "f 7/21 1/22 3/23 5/24\n";

/* vertices with no earlier vertex within 1e-5 (copies are evaluated once per side) */
static long distinct_positions(const sfb_tess_data *t)
{
    long d = 0;
    for (int i = 0; i < t->vertex_count; ++i) {
        int dup = 0;
        for (int j = 0; j < i && !dup; ++j)
            dup = fabs(t->positions[3 * i] - t->positions[3 * j]) < 1e-5 && fabs(t->positions[3 * i + 1] - t->positions[3 * j + 1]) < 1e-5 &&
                  fabs(t->positions[3 * i + 2] - t->positions[3 * j + 2]) < 1e-5;
        d += !dup;
    }
    return d;
}

Test(tess_uv, every_edge_a_seam)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = tx_mesh(ctx, cube_islands_obj);
    sfb_surface *s = uv_surface(ctx, m, SFB_SCHEME_CATMARK);
    for (int R = 1; R <= 8; R += 7) {
        sfb_tess_data t = tess_ok(s, ctx, R, 0.0f, SFB_TESS_UVS);
        cr_expect_eq(t.vertex_count, 6 * (R + 1) * (R + 1), "rate %d: %d vertices", R, t.vertex_count);
        cr_expect_eq(distinct_positions(&t), 6L * R * R + 2, "rate %d: welded", R);
        double worst = 0.0;
        for (int v = 0; v < t.vertex_count; ++v) {
            double du = fabs(t.uvs[2 * v] - t.locations[v].u), dv = fabs(t.uvs[2 * v + 1] - t.locations[v].v);
            if (du > worst) worst = du;
            if (dv > worst) worst = dv;
        }
        cr_expect_lt(worst, 1e-6, "rate %d: UV is %g from the location", R, worst);
        /* every triangle's vertices are located in the triangle's own face */
        for (int i = 0; i < 3 * t.triangle_count; ++i)
            cr_expect_eq(t.locations[t.triangles[i]].face, t.triangle_faces[i / 3]);
        sfb_tess_data_free(&t);
    }
    /* trimmed: keep u < 0.5 of every face */
    unsigned char tex[16 * 16];
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) tex[16 * y + x] = x < 8 ? 255 : 0;
    sfb_trim_mask mask;
    memset(&mask, 0, sizeof mask);
    mask.texels = tex;
    mask.width = mask.height = 16;
    sfb_tess_config c = sfb_tess_config_init(4);
    c.flags = SFB_TESS_UVS;
    c.trim = &mask;
    sfb_tess_data t;
    cr_assert_eq(sfb_surface_tessellate(s, &c, &t), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_assert_not_null(t.uvs);
    for (int v = 0; v < t.vertex_count; ++v) {
        cr_expect_lt(fabs(t.uvs[2 * v] - t.locations[v].u), 1e-6);
        cr_expect_lt(fabs(t.uvs[2 * v + 1] - t.locations[v].v), 1e-6);
    }
    sfb_tess_data_free(&t);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* SFB_UV_LINEAR: a pentagon's sub-face i between its corner, the edge midpoints and the
 * centroid, bilinearly; checked at the corners of the sub-faces against the refined UVs of
 * level 1 (which the linear masks make exact), and inside against the bilinear map. */
Test(tess_uv, linear_uvs)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m0 = tx_mesh(ctx, prism_obj);
    sfb_mesh_desc d;
    sfb_mesh_get_desc(m0, &d);
    /* UVs: each vertex's (x, z) squashed into [0,1], one per vertex */
    float uv[20];
    int fuv[64];
    for (int i = 0; i < 10; ++i) { uv[2 * i] = 0.5f + 0.4f * d.positions[3 * i]; uv[2 * i + 1] = 0.5f + 0.25f * d.positions[3 * i + 2] + 0.1f * d.positions[3 * i + 1]; }
    int nfv = 0;
    for (int f = 0; f < d.face_count; ++f) nfv += d.face_sizes[f];
    cr_assert_leq(nfv, 64);
    for (int i = 0; i < nfv; ++i) fuv[i] = d.face_vertices[i];
    d.uv_count = 10; d.uvs = uv; d.face_uvs = fuv;
    d.uv_interp = SFB_UV_LINEAR;
    sfb_mesh *m = NULL;
    cr_assert_eq(sfb_mesh_create(ctx, &d, &m), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_surface *s = uv_surface(ctx, m, SFB_SCHEME_CATMARK);
    sfb_tess_data t = tess_ok(s, ctx, 4, 0.0f, SFB_TESS_UVS);
    int checked = 0;
    for (int v = 0; v < t.vertex_count; ++v) {
        int base, sub;
        cr_assert_eq(sfb_surface_param_face_base(s, t.locations[v].face, &base, &sub), SFB_SUCCESS);
        int o = 0;
        for (int f = 0; f < base; ++f) o += d.face_sizes[f];
        int n = d.face_sizes[base];
        double q[4][2], u = t.locations[v].u, w = t.locations[v].v;
        for (int c = 0; c < 2; ++c) {
            if (sub < 0) {
                for (int k = 0; k < 4; ++k) q[k][c] = uv[2 * fuv[o + k] + c];
            } else {
                double mean = 0;
                for (int k = 0; k < n; ++k) mean += uv[2 * fuv[o + k] + c];
                q[0][c] = uv[2 * fuv[o + sub] + c];
                q[1][c] = 0.5 * (q[0][c] + uv[2 * fuv[o + (sub + 1) % n] + c]);
                q[2][c] = mean / n;
                q[3][c] = 0.5 * (q[0][c] + uv[2 * fuv[o + (sub + n - 1) % n] + c]);
            }
            double want = (1 - u) * (1 - w) * q[0][c] + u * (1 - w) * q[1][c] + u * w * q[2][c] + (1 - u) * w * q[3][c];
            cr_expect_lt(fabs(t.uvs[2 * v + c] - want), 1e-6, "vertex %d uv %d: %g, want %g", v, c, t.uvs[2 * v + c], want);
        }
        checked += sub >= 0;
    }
    cr_expect_gt(checked, 0, "no vertex on a pentagon's sub-face");
    /* the refinement agrees at level 1: the centroid of the top pentagon is refined UV ... */
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 1);
    sc.flags = SFB_REFINE_UVS;
    sfb_surface *s1 = NULL;
    cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s1), SFB_SUCCESS);
    sfb_mesh_data md;
    cr_assert_eq(sfb_surface_refine(s1, &md), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    /* ... every refined UV value is some tessellated vertex's UV (rate 4 holds level 1's points) */
    for (int i = 0; i < md.uv_count; ++i) {
        double best = 1e9;
        for (int v = 0; v < t.vertex_count; ++v) {
            double e = fabs(md.uvs[2 * i] - t.uvs[2 * v]) + fabs(md.uvs[2 * i + 1] - t.uvs[2 * v + 1]);
            if (e < best) best = e;
        }
        cr_expect_lt(best, 1e-6, "refined UV %d (%g, %g) is no tessellated UV", i, md.uvs[2 * i], md.uvs[2 * i + 1]);
    }
    sfb_mesh_data_free(&md);
    sfb_surface_destroy(s1);
    sfb_tess_data_free(&t);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_mesh_destroy(m0);
    sfb_context_destroy(ctx);
}

Test(tess_uv, refused_without_uvs)
{
    sfb_context *ctx = tx_ctx();
    sfb_mesh *m = tx_mesh(ctx, cube_obj);
    sfb_surface *s = uv_surface(ctx, m, SFB_SCHEME_CATMARK);
    sfb_tess_config c = sfb_tess_config_init(3);
    c.flags = SFB_TESS_UVS;
    sfb_tess_data t;
    cr_expect_eq(sfb_surface_tessellate(s, &c, &t), SFB_INVALID_ARGS);
    cr_expect(strstr(sfb_last_error(ctx), "no UVs") != NULL, "message: %s", sfb_last_error(ctx));
    cr_expect_null(t.positions);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    /* a mesh with UVs, but a surface built without SFB_REFINE_UVS */
    m = tx_mesh(ctx, cube_islands_obj);
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 0);
    sc.flags = SFB_REFINE_PATCHES;
    s = NULL;
    cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS);
    cr_expect_eq(sfb_surface_tessellate(s, &c, &t), SFB_INVALID_ARGS);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

Test(tess_uv, failures_and_cancellation)
{
    /* the cube of islands: every face open along its 4 x 70 boundary edges */
    failure_sweep_mesh(0, 0.0f, SFB_TESS_UVS, cube_islands_obj, SFB_SCHEME_CATMARK, 70, 6L * 4 * 70);
    failure_sweep_mesh(1, 0.0f, SFB_TESS_UVS, cube_islands_obj, SFB_SCHEME_CATMARK, 70, 6L * 4 * 70);
}
