/* surfblend: curved PN triangles (SFB_SCHEME_PN, ALGORITHMS.md section 5.3): the corners are
 * the vertices with their angle-weighted normals (recomputed here independently), flat input
 * stays flat, the surface is closed across edges (C0: both triangles give the same edge
 * points) and a cubic along each edge whose tangents at the ends lie in the vertices' tangent
 * planes, the normals are the method's quadratic field, the backends agree, and bad input is refused with nothing left behind. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

/* live blocks of the counting allocator */
static long pn_live;
static void *pn_alloc(size_t n, void *u) { (void)u; void *p = malloc(n); if (p) pn_live++; return p; }
static void *pn_realloc(void *p, size_t n, void *u) { (void)u; if (!p) return pn_alloc(n, u); return realloc(p, n); }
static void pn_free(void *p, void *u) { (void)u; if (p) { pn_live--; free(p); } }

/* a context on `backend` (-1: the default order, with the counting allocator); NULL when that
 * backend is not available here */
static sfb_context *pn_ctx(int backend)
{
    static sfb_backend_kind kind;
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    if (backend >= 0) {
        char info[512];
        kind = (sfb_backend_kind)backend;
        if (sfb_backend_probe(kind, NULL, info, sizeof info) != SFB_SUCCESS) return NULL;
        cc.backends = &kind;
        cc.backend_count = 1;
    } else {
        cc.allocator.alloc = pn_alloc;
        cc.allocator.realloc = pn_realloc;
        cc.allocator.free = pn_free;
    }
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    return ctx;
}

static sfb_mesh *pn_mesh(sfb_context *ctx, const char *obj)
{
    sfb_mesh *m = NULL;
    cr_assert_eq(sfb_mesh_read_obj(ctx, obj, strlen(obj), &m), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    return m;
}

static sfb_surface *pn_surface(sfb_context *ctx, const sfb_mesh *m)
{
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_PN, 0);
    sc.flags = SFB_REFINE_PATCHES;
    sfb_surface *s = NULL;
    cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    return s;
}

/* an octahedron with its vertices pushed about (a seed), so that no normal is symmetric */
static char *jittered_octahedron(unsigned seed)
{
    static const int P[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    char *s = malloc(4096);
    size_t at = 0;
    for (int i = 0; i < 6; ++i) {
        double q[3];
        for (int c = 0; c < 3; ++c) {
            seed = seed * 1103515245u + 12345u;
            q[c] = P[i][c] * (1.0 + 0.3 * ((seed >> 8) & 0xffff) / 65535.0) + 0.1 * (((seed >> 4) & 0xff) / 255.0 - 0.5);
        }
        at += (size_t)snprintf(s + at, 4096 - at, "v %.9g %.9g %.9g\n", q[0], q[1], q[2]);
    }
    at += (size_t)snprintf(s + at, 4096 - at,
                           "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n");
    return s;
}

static void expected_normals(const sfb_mesh_desc *d, double *vn)
{
    memset(vn, 0, sizeof(double) * 3 * (size_t)d->vertex_count);
    for (int f = 0; f < d->face_count; ++f) {
        const int *fv = d->face_vertices + 3 * f;
        for (int k = 0; k < 3; ++k) {
            const float *a = d->positions + 3 * fv[k], *b = d->positions + 3 * fv[(k + 1) % 3], *c = d->positions + 3 * fv[(k + 2) % 3];
            double u[3], w[3], n[3];
            for (int i = 0; i < 3; ++i) { u[i] = (double)b[i] - a[i]; w[i] = (double)c[i] - a[i]; }
            n[0] = u[1] * w[2] - u[2] * w[1]; n[1] = u[2] * w[0] - u[0] * w[2]; n[2] = u[0] * w[1] - u[1] * w[0];
            double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]),
                   lw = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
            double ang = acos((u[0] * w[0] + u[1] * w[1] + u[2] * w[2]) / (lu * lw));
            for (int i = 0; i < 3; ++i) vn[3 * fv[k] + i] += ang * n[i] / ln;
        }
    }
    for (int v = 0; v < d->vertex_count; ++v) {
        double *n = vn + 3 * v, l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int i = 0; i < 3; ++i) n[i] /= l;
    }
}

Test(pn, corners_are_the_vertices_with_their_normals)
{
    for (unsigned seed = 1; seed <= 5; ++seed) {
        sfb_context *ctx = pn_ctx(-1);
        char *obj = jittered_octahedron(seed);
        sfb_mesh *m = pn_mesh(ctx, obj);
        sfb_surface *s = pn_surface(ctx, m);
        sfb_mesh_desc d;
        sfb_mesh_get_desc(m, &d);
        double vn[18];
        expected_normals(&d, vn);
        for (int f = 0; f < 8; ++f) {
            sfb_location L[3] = {{f, 0, 0}, {f, 1, 0}, {f, 0, 1}};
            float P[9], N[9];
            sfb_eval_output o;
            memset(&o, 0, sizeof o);
            o.position = P;
            o.normal = N;
            cr_assert_eq(sfb_surface_eval(s, L, 3, &o), SFB_SUCCESS);
            for (int k = 0; k < 3; ++k) {
                int v = d.face_vertices[3 * f + k];
                for (int c = 0; c < 3; ++c) {
                    cr_expect_lt(fabs(P[3 * k + c] - d.positions[3 * v + c]), 1e-6, "seed %u face %d corner %d: %.9g, vertex %.9g", seed, f, k, P[3 * k + c], d.positions[3 * v + c]);
                    cr_expect_lt(fabs(N[3 * k + c] - vn[3 * v + c]), 1e-5, "seed %u face %d corner %d normal %d: %g, want %g", seed, f, k, c,
                                 N[3 * k + c], vn[3 * v + c]);
                }
            }
        }
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
        sfb_context_destroy(ctx);
        free(obj);
    }
}

/* the edges: the point at t along the shared edge is the same from both triangles (C0), and
 * it is the cubic of the method: (1-t)^3 P0 + 3(1-t)^2 t b1 + 3(1-t) t^2 b2 + t^3 P1 with
 * b1 = (2P0 + P1 - ((P1 - P0).N0) N0) / 3, b2 likewise from P1 */
Test(pn, edges_are_shared_cubics)
{
    sfb_context *ctx = pn_ctx(-1);
    char *obj = jittered_octahedron(7);
    sfb_mesh *m = pn_mesh(ctx, obj);
    sfb_surface *s = pn_surface(ctx, m);
    sfb_mesh_desc d;
    sfb_mesh_get_desc(m, &d);
    double vn[18];
    expected_normals(&d, vn);
    int checked = 0;
    for (int f = 0; f < 8; ++f)
        for (int k = 0; k < 3; ++k) {
            int a = d.face_vertices[3 * f + k], b = d.face_vertices[3 * f + (k + 1) % 3];
            for (int g = 0; g < 8; ++g)
                for (int j = 0; j < 3; ++j) {
                    if (d.face_vertices[3 * g + j] != b || d.face_vertices[3 * g + (j + 1) % 3] != a) continue;
                    for (int q = 1; q < 8; ++q) {
                        double t = q / 8.0;
                        /* (u,v) of the point at t from corner k to k+1 of a triangle */
                        float cu[3][2][2] = {{{0, 0}, {1, 0}}, {{1, 0}, {0, 1}}, {{0, 1}, {0, 0}}};
                        sfb_location L[2];
                        L[0].face = f;
                        L[0].u = (float)((1 - t) * cu[k][0][0] + t * cu[k][1][0]);
                        L[0].v = (float)((1 - t) * cu[k][0][1] + t * cu[k][1][1]);
                        L[1].face = g;
                        L[1].u = (float)(t * cu[j][0][0] + (1 - t) * cu[j][1][0]);
                        L[1].v = (float)(t * cu[j][0][1] + (1 - t) * cu[j][1][1]);
                        float P[6];
                        sfb_eval_output o;
                        memset(&o, 0, sizeof o);
                        o.position = P;
                        cr_assert_eq(sfb_surface_eval(s, L, 2, &o), SFB_SUCCESS);
                        const float *pa = d.positions + 3 * a, *pb = d.positions + 3 * b;
                        double wa = 0, wb = 0;
                        for (int c = 0; c < 3; ++c) { wa += (pb[c] - pa[c]) * vn[3 * a + c]; wb += (pa[c] - pb[c]) * vn[3 * b + c]; }
                        for (int c = 0; c < 3; ++c) {
                            double b1 = (2.0 * pa[c] + pb[c] - wa * vn[3 * a + c]) / 3.0, b2 = (2.0 * pb[c] + pa[c] - wb * vn[3 * b + c]) / 3.0;
                            double want = (1 - t) * (1 - t) * (1 - t) * pa[c] + 3 * (1 - t) * (1 - t) * t * b1 + 3 * (1 - t) * t * t * b2 +
                                          t * t * t * pb[c];
                            cr_expect_lt(fabs(P[c] - P[3 + c]), 2e-6, "edge %d-%d t %g: the two sides differ", a, b, t);
                            cr_expect_lt(fabs(P[c] - want), 2e-6, "edge %d-%d t %g: %g, the cubic %g", a, b, t, P[c], want);
                        }
                        checked++;
                    }
                }
        }
    cr_expect_eq(checked, 24 * 7, "%d edge points checked", checked);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    free(obj);
}

Test(pn, flat_input_stays_flat)
{
    /* a triangulated planar grid, 4 x 3 quads cut by alternating diagonals, in the plane z = 2 */
    char obj[4096];
    size_t at = 0;
    for (int j = 0; j <= 3; ++j)
        for (int i = 0; i <= 4; ++i) at += (size_t)snprintf(obj + at, sizeof obj - at, "v %g %g 2\n", i + 0.13 * ((i * 7 + j * 3) % 5), j + 0.1 * (i % 3));
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) {
            int a = j * 5 + i + 1, b = a + 1, c = a + 6, e = a + 5;
            if ((i + j) % 2) at += (size_t)snprintf(obj + at, sizeof obj - at, "f %d %d %d\nf %d %d %d\n", a, b, c, a, c, e);
            else at += (size_t)snprintf(obj + at, sizeof obj - at, "f %d %d %d\nf %d %d %d\n", a, b, e, b, c, e);
        }
    sfb_context *ctx = pn_ctx(-1);
    sfb_mesh *m = pn_mesh(ctx, obj);
    sfb_surface *s = pn_surface(ctx, m);
    sfb_tess_config tc = sfb_tess_config_init(6);
    sfb_tess_data t;
    cr_assert_eq(sfb_surface_tessellate(s, &tc, &t), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    for (int v = 0; v < t.vertex_count; ++v) {
        cr_expect_eq(t.positions[3 * v + 2], 2.0f, "vertex %d: z = %g", v, t.positions[3 * v + 2]);
        cr_expect_lt(fabs(t.normals[3 * v + 2] - 1.0), 1e-6, "vertex %d: normal z %g", v, t.normals[3 * v + 2]);
    }
    sfb_tess_data_free(&t);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* one backend against ref at 400 random locations: positions, du (the derivative scaled by
 * 1/4, as the patch's edges are that much longer than its points' spacing) and normals (the
 * quadratic field, evaluated on the backend and normalised); skipped when the backend is not
 * available here */
static void pn_agree(sfb_backend_kind kind)
{
    sfb_context *c = pn_ctx((int)kind);
    if (!c) cr_skip_test("backend %s is not available here", kind == SFB_BACKEND_SIMD ? "simd" : kind == SFB_BACKEND_GL ? "gl" : "osmesa");
    char *obj = jittered_octahedron(11);
    sfb_context *rc = pn_ctx(SFB_BACKEND_REF);
    cr_assert_not_null(rc);
    sfb_mesh *rm = pn_mesh(rc, obj);
    sfb_surface *rs = pn_surface(rc, rm);
    enum { N = 400 };
    sfb_location L[N];
    unsigned g = 5;
    for (int i = 0; i < N; ++i) {
        g = g * 1103515245u + 12345u;
        L[i].face = (int)((g >> 16) % 8);
        float u = ((g >> 4) & 1023) / 1023.0f, v = ((g >> 14) & 1023) / 1023.0f;
        if (u + v > 1.0f) { u = 1.0f - u; v = 1.0f - v; }
        L[i].u = u;
        L[i].v = v;
    }
    float P0[3 * N], D0[3 * N], N0[3 * N], P1[3 * N], D1[3 * N], N1[3 * N];
    sfb_eval_output o;
    memset(&o, 0, sizeof o);
    o.position = P0;
    o.du = D0;
    o.normal = N0;
    cr_assert_eq(sfb_surface_eval(rs, L, N, &o), SFB_SUCCESS);
    sfb_mesh *m = pn_mesh(c, obj);
    sfb_surface *s = pn_surface(c, m);
    o.position = P1;
    o.du = D1;
    o.normal = N1;
    cr_assert_eq(sfb_surface_eval(s, L, N, &o), SFB_SUCCESS, "%s: %s", sfb_context_backend_name(c), sfb_last_error(c));
    double worst = 0, worst_n = 0;
    for (int i = 0; i < 3 * N; ++i) {
        worst = fmax(worst, fabs(P1[i] - P0[i]));
        worst = fmax(worst, fabs(D1[i] - D0[i]) * 0.25);
        worst_n = fmax(worst_n, fabs(N1[i] - N0[i]));
    }
    cr_expect_lt(worst, 2e-5, "%s differs from ref by %g", sfb_context_backend_name(c), worst);
    cr_expect_lt(worst_n, 2e-6, "%s's normals differ from ref's by %g", sfb_context_backend_name(c), worst_n);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(c);
    sfb_surface_destroy(rs);
    sfb_mesh_destroy(rm);
    sfb_context_destroy(rc);
    free(obj);
}

Test(pn, simd_agrees_with_ref) { pn_agree(SFB_BACKEND_SIMD); }
Test(pn, gl_agrees_with_ref) { pn_agree(SFB_BACKEND_GL); }
Test(pn, osmesa_agrees_with_ref) { pn_agree(SFB_BACKEND_OSMESA); }

/* the normals are the method's quadratic field (Vlachos et al.), recomputed here: corners N_i,
 * edge middles h_ij = normalize(N_i + N_j - v_ij (P_j - P_i)), v_ij = 2 (P_j - P_i).(N_i + N_j)
 * / |P_j - P_i|^2, n(u,v) = normalize(sum of the quadratic Bernstein terms); not the
 * geometry's du x dv, which this check also shows to differ */
Test(pn, normals_are_the_quadratic_field)
{
    sfb_context *ctx = pn_ctx(-1);
    char *obj = jittered_octahedron(3);
    sfb_mesh *m = pn_mesh(ctx, obj);
    sfb_surface *s = pn_surface(ctx, m);
    sfb_mesh_desc d;
    sfb_mesh_get_desc(m, &d);
    double vn[18], worst = 0, geometric = 0;
    expected_normals(&d, vn);
    for (int f = 0; f < 8; ++f) {
        const int *fv = d.face_vertices + 3 * f;
        double h[3][3]; /* middles of edges 01, 12, 20 */
        for (int e = 0; e < 3; ++e) {
            const int a = fv[e], b = fv[(e + 1) % 3];
            double dd = 0, dn = 0, l = 0;
            for (int c = 0; c < 3; ++c) {
                double x = (double)d.positions[3 * b + c] - d.positions[3 * a + c];
                dd += x * x;
                dn += x * (vn[3 * a + c] + vn[3 * b + c]);
            }
            for (int c = 0; c < 3; ++c) {
                h[e][c] = vn[3 * a + c] + vn[3 * b + c] - 2 * dn / dd * ((double)d.positions[3 * b + c] - d.positions[3 * a + c]);
                l += h[e][c] * h[e][c];
            }
            for (int c = 0; c < 3; ++c) h[e][c] /= sqrt(l);
        }
        for (int q = 0; q < 12; ++q) {
            sfb_location L = {f, (float)((q % 4 + 0.5) / 5.0), (float)((q / 4 + 0.3) / 4.0)};
            if (L.u + L.v > 1.0f) { L.u = 1.0f - L.u; L.v = 1.0f - L.v; }
            const double u = L.u, v = L.v, w = 1.0 - u - v;
            float N[3], du[3], dv[3];
            sfb_eval_output o;
            memset(&o, 0, sizeof o);
            o.normal = N;
            o.du = du;
            o.dv = dv;
            cr_assert_eq(sfb_surface_eval(s, &L, 1, &o), SFB_SUCCESS);
            double want[3], l = 0, g[3], lg = 0;
            for (int c = 0; c < 3; ++c) {
                want[c] = w * w * vn[3 * fv[0] + c] + u * u * vn[3 * fv[1] + c] + v * v * vn[3 * fv[2] + c] + 2 * w * u * h[0][c] +
                          2 * u * v * h[1][c] + 2 * v * w * h[2][c];
                l += want[c] * want[c];
            }
            g[0] = (double)du[1] * dv[2] - (double)du[2] * dv[1];
            g[1] = (double)du[2] * dv[0] - (double)du[0] * dv[2];
            g[2] = (double)du[0] * dv[1] - (double)du[1] * dv[0];
            for (int c = 0; c < 3; ++c) lg += g[c] * g[c];
            for (int c = 0; c < 3; ++c) {
                worst = fmax(worst, fabs(N[c] - want[c] / sqrt(l)));
                geometric = fmax(geometric, fabs(N[c] - g[c] / sqrt(lg)));
            }
        }
    }
    cr_expect_lt(worst, 2e-6, "normals off the quadratic field by %g", worst);
    cr_expect_gt(geometric, 1e-3, "the normals are du x dv's (%g): no quadratic field", geometric);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    free(obj);
}

Test(pn, bad_input_is_refused)
{
    static const struct { const char *obj, *words; sfb_result r; } cases[] = {
        { "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", "triangle", SFB_INVALID_TOPOLOGY },
        /* three triangles on the edge 1-2 */
        { "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n", "non-manifold", SFB_INVALID_TOPOLOGY },
        /* a triangle with no area */
        { "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 4 2\n", "degenerate", SFB_INVALID_TOPOLOGY },
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
        sfb_context *ctx = pn_ctx(-1);
        long live0 = pn_live;
        sfb_mesh *m = NULL;
        sfb_result r = sfb_mesh_read_obj(ctx, cases[k].obj, strlen(cases[k].obj), &m);
        if (r == SFB_SUCCESS) {
            sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_PN, 0);
            sc.flags = SFB_REFINE_PATCHES;
            sfb_surface *s = (sfb_surface *)1;
            r = sfb_surface_create(ctx, m, &sc, &s);
            cr_expect_null(s, "case %zu: a surface came back", k);
            sfb_mesh_destroy(m);
        }
        cr_expect_eq(r, cases[k].r, "case %zu: %s (%s)", k, sfb_result_string(r), sfb_last_error(ctx));
        cr_expect(strstr(sfb_last_error(ctx), cases[k].words) != NULL, "case %zu: message '%s' lacks '%s'", k, sfb_last_error(ctx), cases[k].words);
        cr_expect_eq(pn_live, live0, "case %zu: %ld blocks left behind", k, pn_live - live0);
        sfb_context_destroy(ctx);
    }
    /* refinement is not the scheme's */
    sfb_context *ctx = pn_ctx(-1);
    char *obj = jittered_octahedron(3);
    sfb_mesh *m = pn_mesh(ctx, obj);
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_PN, 2);
    sfb_surface *s = NULL;
    cr_expect_neq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS);
    cr_expect_eq(sfb_scheme_caps(SFB_SCHEME_PN) & (SFB_SCHEME_CAN_REFINE | SFB_SCHEME_CAN_SHADE), 0u);
    cr_expect_neq(sfb_scheme_caps(SFB_SCHEME_PN) & SFB_SCHEME_CAN_EVAL, 0u);
    sfb_scheme parsed;
    cr_expect(sfb_scheme_parse("pn", &parsed) && parsed == SFB_SCHEME_PN);
    cr_expect_str_eq(sfb_scheme_name(SFB_SCHEME_PN), "pn");
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    free(obj);
}
