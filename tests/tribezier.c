/* Quartic triangular Bezier surfaces with sharpness (SFB_SCHEME_TRIBEZIER, src/patch/tribezier.c,
 * seed 004), in double from the builder's own points (src/sfb_internal.h, linked from
 * libsfb_internal.o) and through sfb_surface_eval on every backend:
 *   - s = 0: the normal jump across every interior edge (atan2 form, ALGORITHMS.md 8.6, 11 points
 *     per edge) <= 1e-9 rad and the position gap <= 1e-7 x diagonal, on disks around one vertex of
 *     valence 3..12, jittered, and on closed meshes whose extraordinary vertices touch;
 *   - regular regions (every corner of the triangle regular, two rings from any irregular vertex)
 *     equal SFB_SCHEME_LOOP's limit surface within 1e-7 x diagonal;
 *   - s = 1 on a regular crease: the crease curve is the degree-raised cubic B-spline of its
 *     vertices; corners at s = 1 pass through the corner vertex;
 *   - 0 < s < 1: positions are (1 - s) P(0) + s P(1) within 1e-9 x diagonal, the normal jump
 *     across the crease grows with s, and is continuous in s;
 *   - the undulation of the crease curve at s = 0.25, 0.5, 0.75 near extraordinary crease
 *     vertices of valence 4, 5, 7 (ours against the seed's tangent plane, against ours in one
 *     pass and against Loop's smooth and sharp limits blended, printed; ours with no curvature
 *     sign change within two edges, flatter than all three and as fair as one pass; within
 *     1e-3 mean edges of the crease's vertical plane where the mesh's rows are level, within
 *     10 % of Loop's own offset from it where they are not);
 *   - the seed-plane fallback per vertex (two creased disks in one mesh);
 *   - the solves' shortcuts give the nets of the plain ones: templates and per-region factors
 *     against CGLS alone, the sharp net alone (s = 1 at every vertex) against both nets built,
 *     the smooth net's regions reused in the sharp net against solving them again;
 *   - every backend's sfb_surface_eval agrees with the builder's points (positions 1e-6 x
 *     diagonal, normal jumps across edges <= 1e-5 rad);
 *   - bad input: s outside [0, 1] or NaN, quads, non-manifold edges, degenerate triangles.
 * A backend that is unavailable SKIPs (FAILs when listed in SFB_REQUIRE_BACKENDS). */
#define SURFBLEND_EXPOSE_INTERNALS /* the internals below have external linkage in libsfb_internal.o */
#include "surfblend.h"
#include "src/sfb_internal.h" /* the library's internal interfaces (linked from libsfb_internal.o) */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "tribezier_mesh.h"

/* ---- quartic Bezier triangles in double (our point order: row by row in v, u rising) ---- */

static int qij(int i, int j) { return 5 * j - j * (j - 1) / 2 + i; }

/* Position and the derivatives along u and v at (u, v). */
static void bez_eval(const double *b, double u, double v, double P[3], double Du[3], double Dv[3]) {
    const double w = 1.0 - u - v;
    double pw[3][5];
    int i, j, k, c;
    static const double f[5] = {1, 1, 2, 6, 24};
    for (k = 0; k < 5; ++k) {
        pw[0][k] = pow(w, k); pw[1][k] = pow(u, k); pw[2][k] = pow(v, k);
    }
    for (c = 0; c < 3; ++c) P[c] = Du[c] = Dv[c] = 0.0;
    for (j = 0; j <= 4; ++j)
        for (i = 0; i + j <= 4; ++i) {
            k = 4 - i - j;
            for (c = 0; c < 3; ++c) P[c] += 24.0 / (f[i] * f[j] * f[k]) * pw[0][k] * pw[1][i] * pw[2][j] * b[3 * qij(i, j) + c];
        }
    /* derivatives: 4 sum over degree 3 (exponents i, j, k of u, v, w) */
    for (j = 0; j <= 3; ++j)
        for (i = 0; i + j <= 3; ++i) {
            const double B = 6.0 / (f[i] * f[j] * f[3 - i - j]) * pw[0][3 - i - j] * pw[1][i] * pw[2][j];
            for (c = 0; c < 3; ++c) {
                Du[c] += 4.0 * B * (b[3 * qij(i + 1, j) + c] - b[3 * qij(i, j) + c]);
                Dv[c] += 4.0 * B * (b[3 * qij(i, j + 1) + c] - b[3 * qij(i, j) + c]);
            }
        }
}

/* The second derivatives at (u, v): 12 sum over degree 2 of the second differences. */
static void bez_eval2(const double *b, double u, double v, double Duu[3], double Duv[3], double Dvv[3]) {
    const double w = 1.0 - u - v;
    static const double f[3] = {1, 1, 2};
    int i, j, c;
    for (c = 0; c < 3; ++c) Duu[c] = Duv[c] = Dvv[c] = 0.0;
    for (j = 0; j <= 2; ++j)
        for (i = 0; i + j <= 2; ++i) {
            const double B = 2.0 / (f[i] * f[j] * f[2 - i - j]) * pow(w, 2 - i - j) * pow(u, i) * pow(v, j);
            for (c = 0; c < 3; ++c) {
                const double b00 = b[3 * qij(i, j) + c];
                Duu[c] += 12.0 * B * (b[3 * qij(i + 2, j) + c] - 2.0 * b[3 * qij(i + 1, j) + c] + b00);
                Duv[c] += 12.0 * B * (b[3 * qij(i + 1, j + 1) + c] - b[3 * qij(i + 1, j) + c] - b[3 * qij(i, j + 1) + c] + b00);
                Dvv[c] += 12.0 * B * (b[3 * qij(i, j + 2) + c] - 2.0 * b[3 * qij(i, j + 1) + c] + b00);
            }
        }
}

static void cross(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1]; c[1] = a[2] * b[0] - a[0] * b[2]; c[2] = a[0] * b[1] - a[1] * b[0];
}
static double norm3(const double *a) { return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
static double angle_between(const double *a, const double *b) {
    double x[3];
    cross(a, b, x);
    return atan2(norm3(x), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

/* (u, v) of barycentric weights (1 - t) on slot k and t on slot k+1 of a triangle. */
static void edge_uv(int k, double t, double *u, double *v) {
    double w[3] = {0, 0, 0};
    w[k] = 1.0 - t; w[(k + 1) % 3] = t;
    *u = w[1]; *v = w[2];
}

typedef struct g1_result {
    double jump, gap;      /* largest normal jump (rad) and position gap */
    double flat;           /* smallest |du x dv| / (|du| |dv|) on the edges (0: a degenerate patch) */
    int edges;
} g1_result;

/* Normal jumps across the interior edges of l (those with skip_sharp set and sharpness > 0 left
 * out), 11 points per edge. */
static g1_result g1_measure_ex(const sfb__level *l, const double *net, int skip_sharp, int inner);
static g1_result g1_measure(const sfb__level *l, const double *net, int skip_sharp) { return g1_measure_ex(l, net, skip_sharp, 0); }
/* inner: the samples strictly inside the edges (t = 0.1 .. 0.9), not at its end vertices */
static g1_result g1_measure_ex(const sfb__level *l, const double *net, int skip_sharp, int inner) {
    g1_result g = {0, 0, 1, 0};
    int e, q, c;
    for (e = 0; e < l->ne; ++e) {
        int f0, f1, s0, s1;
        if (l->ef_off[e + 1] - l->ef_off[e] != 2) continue;
        if (skip_sharp && l->es[e] > 0.0f) continue;
        f0 = l->ef[l->ef_off[e]]; s0 = l->ef_slot[l->ef_off[e]];
        f1 = l->ef[l->ef_off[e] + 1]; s1 = l->ef_slot[l->ef_off[e] + 1];
        g.edges++;
        for (q = inner; q <= 10 - inner; ++q) {
            const double t = q / 10.0;
            double u0, v0, u1, v1, P0[3], P1[3], a0[3], b0[3], a1[3], b1[3], n0[3], n1[3], d[3];
            edge_uv(s0, t, &u0, &v0);
            edge_uv(s1, 1.0 - t, &u1, &v1); /* the other face runs the edge the other way */
            bez_eval(net + 45 * (size_t)f0, u0, v0, P0, a0, b0);
            bez_eval(net + 45 * (size_t)f1, u1, v1, P1, a1, b1);
            cross(a0, b0, n0); cross(a1, b1, n1);
            g.flat = fmin(g.flat, fmin(norm3(n0) / (norm3(a0) * norm3(b0) + 1e-300), norm3(n1) / (norm3(a1) * norm3(b1) + 1e-300)));
            for (c = 0; c < 3; ++c) d[c] = P0[c] - P1[c];
            if (norm3(d) > g.gap) g.gap = norm3(d);
            {
                const double j = angle_between(n0, n1);
                if (j > g.jump) {
                    g.jump = j;
                    if (getenv("TBZ_DEBUG") && j > 1e-6)
                        printf("  worst so far: edge %d (%d-%d) valences %d %d t %.1f jump %.3g\n", e, l->ev[2 * e], l->ev[2 * e + 1],
                               l->vf_off[l->ev[2 * e] + 1] - l->vf_off[l->ev[2 * e]],
                               l->vf_off[l->ev[2 * e + 1] + 1] - l->vf_off[l->ev[2 * e + 1]], t, j);
                }
            }
        }
    }
    return g;
}

static double diag_of(const float *p, int nv) {
    double lo[3], hi[3], d = 0;
    int v, c;
    for (c = 0; c < 3; ++c) { lo[c] = 1e300; hi[c] = -1e300; }
    for (v = 0; v < nv; ++v)
        for (c = 0; c < 3; ++c) { lo[c] = fmin(lo[c], p[3 * v + c]); hi[c] = fmax(hi[c], p[3 * v + c]); }
    for (c = 0; c < 3; ++c) d += (hi[c] - lo[c]) * (hi[c] - lo[c]);
    return sqrt(d);
}

/* A mesh from OBJ text and its prepared level. */
typedef struct tmesh {
    sfb_mesh *m;
    sfb__level prep;
    double diag;
} tmesh;

static int tmesh_load(sfb_context *ctx, const char *obj, tmesh *t) {
    memset(t, 0, sizeof *t);
    if (sfb_mesh_read_obj(ctx, obj, strlen(obj), &t->m) != SFB_SUCCESS) return 0;
    if (sfb__level_prepare(ctx, &t->m->base, 1, 0, &t->prep) != SFB_SUCCESS) return 0;
    t->diag = diag_of(t->m->positions, t->m->base.nv);
    return 1;
}
static void tmesh_free(sfb_context *ctx, tmesh *t) {
    sfb__level_free(ctx, &t->prep);
    sfb_mesh_destroy(t->m);
}

static double *net_of(sfb_context *ctx, tmesh *t, const sfb_tribezier_options *o, unsigned flags, sfb__tbz_stats *st) {
    double *net = NULL;
    if (sfb__tribezier_points(ctx, &t->prep, t->m->positions, o, flags, &net, st) != SFB_SUCCESS) {
        printf("  build: %s\n", sfb_last_error(ctx));
        return NULL;
    }
    return net;
}

static void test_g1_disks(sfb_context *ctx) {
    int n, jit;
    for (jit = 0; jit < 2; ++jit)
        for (n = 3; n <= 12; ++n) {
            tbm_opts o;
            tmesh t;
            char name[96], *obj;
            double *net;
            sfb__tbz_stats st;
            memset(&o, 0, sizeof o);
            o.n = n; o.R = 5; o.bump = 1.0; o.jitter = jit ? 0.3 : 0.0; o.seed = 7u + (unsigned)n;
            snprintf(name, sizeof name, "g1_disk_valence_%d%s", n, jit ? "_jittered" : "");
            obj = tbm_obj(&o);
            if (!tmesh_load(ctx, obj, &t)) { fail(name, "load: %s", sfb_last_error(ctx)); free(obj); continue; }
            net = net_of(ctx, &t, NULL, 0, &st);
            if (!net) fail(name, "not built");
            else {
                g1_result g = g1_measure(&t.prep, net, 0);
                check(g.jump <= 1e-9 && g.gap <= 1e-7 * t.diag && g.flat > 1e-3, name, "flatness %.3g, normal jump %.3g rad, gap %.3g (diag %.3g), %d edges, residual %.3g, %ld it",
                      g.flat, g.jump, g.gap, t.diag, g.edges, st.residual, st.iterations);
                printf("  %s: jump %.3g rad gap %.3g, %ld unknowns %ld rows %ld iterations residual %.3g\n", name, g.jump, g.gap,
                       st.unknowns, st.constraints, st.iterations, st.residual);
            }
            sfb__free(ctx, net);
            tmesh_free(ctx, &t);
            free(obj);
        }
}

static const char *octahedron =
    "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
    "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

/* An icosahedron (valence 5 everywhere: every edge joins two extraordinary vertices). */
static char *icosahedron(void) {
    const double p = (1.0 + sqrt(5.0)) / 2.0;
    static const int F[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6},
                                 {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10},
                                 {8, 6, 7}, {9, 8, 1}};
    const double V[12][3] = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                             {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
    char *s = (char *)malloc(4096);
    size_t len = 0;
    int i;
    for (i = 0; i < 12; ++i) len += (size_t)snprintf(s + len, 4096 - len, "v %.17g %.17g %.17g\n", V[i][0], V[i][1], V[i][2]);
    for (i = 0; i < 20; ++i) len += (size_t)snprintf(s + len, 4096 - len, "f %d %d %d\n", F[i][0] + 1, F[i][1] + 1, F[i][2] + 1);
    return s;
}

/* G1 on one mesh given as OBJ text. */
static void g1_one(sfb_context *ctx, const char *name, const char *obj, double tol) {
    tmesh t;
    double *net;
    sfb__tbz_stats st;
    if (!tmesh_load(ctx, obj, &t)) { fail(name, "load: %s", sfb_last_error(ctx)); return; }
    net = net_of(ctx, &t, NULL, 0, &st);
    if (!net) fail(name, "not built");
    else {
        g1_result g = g1_measure(&t.prep, net, 0);
        check(g.jump <= tol && g.gap <= 1e-7 * t.diag && g.flat > 1e-3, name, "flatness %.3g, normal jump %.3g rad, gap %.3g (diag %.3g), %d edges, residual %.3g",
              g.flat, g.jump, g.gap, t.diag, g.edges, st.residual);
        printf("  %s: jump %.3g rad gap %.3g, %ld unknowns %ld rows %ld iterations residual %.3g\n", name, g.jump, g.gap, st.unknowns,
               st.constraints, st.iterations, st.residual);
    }
    sfb__free(ctx, net);
    tmesh_free(ctx, &t);
}

static void test_g1_closed(sfb_context *ctx) {
    char *ico = icosahedron();
    g1_one(ctx, "g1_octahedron_adjacent_valence_4", octahedron, 1e-9);
    g1_one(ctx, "g1_icosahedron_adjacent_valence_5", ico, 1e-9);
    free(ico);
}

/* Non-manifold vertices: split into one vertex per fan (tbz_split), each sheet built as a mesh
 * of its own through the vertex (a corner, as the subdivision schemes make it). Two octahedra
 * touching at a vertex: G1 on both, both through the shared vertex (fails when the fans are not
 * split, split wrongly, or the copies lose the corner: they then part by 1.13); two fans of an
 * open disk touching at a boundary vertex; and the real meshes with such vertices (cow.obj,
 * teapot.obj: refused before). */
static void refined_one(sfb_context *ctx, const char *name, const char *obj);

static void test_nonmanifold_vertices(sfb_context *ctx, const char *dir) {
    /* octahedron A around the origin; B shifted by (2, 0, 0), its vertex (-1, 0, 0) A's (1, 0, 0) */
    static const char *pinch =
        "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
        "v 3 0 0\nv 2 1 0\nv 2 -1 0\nv 2 0 1\nv 2 0 -1\n"
        "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n"
        "f 7 8 10\nf 8 1 10\nf 1 9 10\nf 9 7 10\nf 8 7 11\nf 1 8 11\nf 9 1 11\nf 7 9 11\n";
    /* two fans of three triangles around vertex 1, each with its own boundary */
    static const char *bowtie =
        "v 0 0 0\nv 1 0 0.1\nv 0.5 0.8 0.2\nv -0.5 0.8 0.1\nv -1 0 0.3\nv 0.5 -0.8 0.1\nv -0.5 -0.8 0.2\nv 1 -0.1 -0.2\nv -1 -0.1 -0.1\n"
        "f 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 9 7\nf 1 7 6\nf 1 6 8\n";
    tmesh t;
    double *net = NULL;
    sfb__tbz_stats st;
    if (tmesh_load(ctx, pinch, &t)) {
        check((t.prep.vtag[0] & SFB__TAG_NONMANIFOLD) != 0, "nonmanifold/pinch_is_non_manifold", "vertex 0 tag %d", t.prep.vtag[0]);
        net = net_of(ctx, &t, NULL, 0, &st);
        if (!net) fail("nonmanifold/pinch_built", "not built");
        else {
            g1_result g = g1_measure(&t.prep, net, 0);
            double off = 0.0;
            int c;
            check(g.jump <= 1e-9 && g.gap <= 1e-7 * t.diag && g.flat > 1e-3, "nonmanifold/pinch_g1_on_both_sheets",
                  "normal jump %.3g rad, gap %.3g, residual %.3g", g.jump, g.gap, st.residual);
            /* triangle 0 (1 3 5) starts at the shared vertex; triangle 9 (8 1 10) has it second,
             * (u, v) = (1, 0): point q = 4 */
            for (c = 0; c < 3; ++c)
                off = fmax(off, fmax(fabs(net[c] - t.m->positions[c]), fabs(net[45 * 9 + 3 * 4 + c] - t.m->positions[c])));
            check(off <= 1e-12, "nonmanifold/pinch_both_sheets_through_the_vertex", "a sheet passes %.3g off it", off);
        }
        sfb__free(ctx, net);
        net = NULL;
        tmesh_free(ctx, &t);
    } else fail("nonmanifold/pinch_load", "%s", sfb_last_error(ctx));
    if (tmesh_load(ctx, bowtie, &t)) {
        net = net_of(ctx, &t, NULL, 0, &st);
        if (!net) fail("nonmanifold/bowtie_built", "not built");
        else {
            g1_result g = g1_measure(&t.prep, net, 0);
            double off = 0.0;
            int c;
            check(g.jump <= 1e-9 && g.gap <= 1e-7 * t.diag, "nonmanifold/bowtie_g1_inside_both_fans", "normal jump %.3g rad, gap %.3g", g.jump, g.gap);
            /* triangles 0 (1 2 3) and 3 (1 9 7), one of each fan, start at the shared vertex */
            for (c = 0; c < 3; ++c) off = fmax(off, fmax(fabs(net[c] - t.m->positions[c]), fabs(net[45 * 3 + c] - t.m->positions[c])));
            check(off <= 1e-12, "nonmanifold/bowtie_both_fans_through_the_vertex", "a fan passes %.3g off it", off);
        }
        sfb__free(ctx, net);
        net = NULL;
        {
            /* through the public API: a surface, evaluated on both fans at the shared vertex */
            sfb_surface *sf = NULL;
            sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
            sfb_location loc[2] = {{0, 0.0f, 0.0f}, {3, 0.0f, 0.0f}};
            sc.flags = SFB_REFINE_PATCHES;
            float P[6];
            sfb_eval_output eo;
            memset(&eo, 0, sizeof eo);
            eo.position = P;
            check(sfb_surface_create(ctx, t.m, &sc, &sf) == SFB_SUCCESS && sfb_surface_eval(sf, loc, 2, &eo) == SFB_SUCCESS &&
                      isfinite(P[0]) && isfinite(P[3]),
                  "nonmanifold/bowtie_surface", "%s", sfb_last_error(ctx));
            sfb_surface_destroy(sf);
        }
        tmesh_free(ctx, &t);
    } else fail("nonmanifold/bowtie_load", "%s", sfb_last_error(ctx));
    {
        /* two triangles on the same three vertices (a closed pillow), one a hole: after one Loop
         * step four triangles share each inner edge, so the fallback there is refused and the
         * mesh's own net kept (it read rings of non-manifold vertices before: fuzz_tribezier) */
        sfb_mesh *m = NULL;
        sfb_surface *sf = NULL;
        sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
        static const char *pillow = "v 0 1 0\nv 5 -1 0\nv 0 0 -1\nt hole 1/0/0 0\nf 1 2 3\nf 2 1 3\n";
        sc.flags = SFB_REFINE_PATCHES;
        check(sfb_mesh_read_obj(ctx, pillow, strlen(pillow), &m) == SFB_SUCCESS && sfb_surface_create(ctx, m, &sc, &sf) == SFB_SUCCESS,
              "nonmanifold/pillow_after_one_step_refused_own_net_kept", "%s", sfb_last_error(ctx));
        /* the refused step is not reported as the context's last failure: an earlier one stays */
        sfb_surface_destroy(sf);
        sf = NULL;
        (void)sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "an earlier failure");
        check(sfb_surface_create(ctx, m, &sc, &sf) == SFB_SUCCESS && strcmp(sfb_last_error(ctx), "an earlier failure") == 0 &&
                  sfb_last_error_info(ctx).result == SFB_INVALID_ARGS,
              "nonmanifold/pillow_refused_step_keeps_the_last_error", "last error \"%s\"", sfb_last_error(ctx));
        sfb_surface_destroy(sf);
        sfb_mesh_destroy(m);
    }
    {
        char path[1024];
        size_t n;
        char *obj;
        /* cow.obj: one vertex where two closed sheets touch; its extraordinary vertices of
         * different valences touch, as spot's: G1 after Loop steps */
        snprintf(path, sizeof path, "%s/cow.obj", dir);
        obj = slurp(path, &n);
        if (!obj) skip("nonmanifold/real_mesh_cow", "cow.obj not found (pass the real-meshes folder)");
        else { refined_one(ctx, "nonmanifold/real_mesh_cow", obj); free(obj); }
        /* teapot.obj: 38 vertices on the seams of its parts, G1 inside every edge. Its open
         * seams (a boundary vertex whose two boundary neighbours coincide: the boundary curve has
         * a cusp there) leave degenerate patch corners at those vertices (counted, printed) */
        snprintf(path, sizeof path, "%s/teapot.obj", dir);
        obj = slurp(path, &n);
        if (!obj) skip("nonmanifold/real_mesh_teapot", "teapot.obj not found (pass the real-meshes folder)");
        else if (tmesh_load(ctx, obj, &t)) {
            net = net_of(ctx, &t, NULL, 0, &st);
            if (!net) fail("nonmanifold/real_mesh_teapot", "not built");
            else {
                g1_result g = g1_measure_ex(&t.prep, net, 0, 1), ga = g1_measure(&t.prep, net, 0);
                check(g.jump <= 1e-9 && ga.gap <= 1e-7 * t.diag && st.residual <= 1e-12, "nonmanifold/real_mesh_teapot_g1_inside_edges",
                      "normal jump %.3g rad inside the edges, gap %.3g, residual %.3g", g.jump, ga.gap, st.residual);
                printf("  nonmanifold/real_mesh_teapot: inside the edges jump %.3g rad; with their ends %.3g rad (flatness %.3g: the cusps of "
                       "its open seams)\n", g.jump, ga.jump, ga.flat);
            }
            sfb__free(ctx, net);
            tmesh_free(ctx, &t);
            free(obj);
        } else { fail("nonmanifold/real_mesh_teapot", "load: %s", sfb_last_error(ctx)); free(obj); }
    }
}

/* Triangles of the disk whose corners all lie in rings lo..hi. */
static int in_rings(const tbm_opts *o, const sfb__level *l, int f, int lo, int hi) {
    int k;
    for (k = 0; k < 3; ++k) {
        const int v = l->fv[l->fv_off[f] + k];
        int r = 0;
        while (v > 0 && !(v >= 1 + o->n * r * (r + 1) / 2 && v < 1 + o->n * (r + 1) * (r + 2) / 2)) ++r;
        if (v == 0) r = -1;
        if (r + 1 < lo || r + 1 > hi) return 0;
    }
    return 1;
}

/* Regular regions equal the Loop limit surface (SFB_SCHEME_LOOP's sfb_surface_eval). */
static void test_regular_is_loop(sfb_context *ctx) {
    int n;
    for (n = 4; n <= 7; n += 3) {
        tbm_opts o;
        tmesh t;
        char name[96], *obj;
        double *net, worst = 0.0;
        sfb_surface *loop = NULL;
        sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_LOOP, 0);
        int f, q, count = 0;
        memset(&o, 0, sizeof o);
        o.n = n; o.R = 8; o.bump = 2.0; o.jitter = 0.2; o.seed = 3u;
        snprintf(name, sizeof name, "regular_region_is_loop_valence_%d", n);
        obj = tbm_obj(&o);
        if (!tmesh_load(ctx, obj, &t)) { fail(name, "load"); free(obj); continue; }
        net = net_of(ctx, &t, NULL, 0, NULL);
        sc.flags = SFB_REFINE_PATCHES;
        if (!net || sfb_surface_create(ctx, t.m, &sc, &loop) != SFB_SUCCESS) { fail(name, "%s", sfb_last_error(ctx)); }
        else {
            for (f = 0; f < t.prep.nf; ++f) {
                if (!in_rings(&o, &t.prep, f, 3, 5)) continue;
                for (q = 0; q < 6; ++q) {
                    sfb_location loc;
                    float P[3];
                    sfb_eval_output eo;
                    double B[3], du[3], dv[3], d;
                    memset(&eo, 0, sizeof eo);
                    eo.position = P;
                    loc.face = f; loc.u = (float)((q % 3) / 4.0 + 0.1); loc.v = (float)((q / 3) / 3.0 + 0.1);
                    if (sfb_surface_eval(loop, &loc, 1, &eo) != SFB_SUCCESS) continue;
                    bez_eval(net + 45 * (size_t)f, loc.u, loc.v, B, du, dv);
                    d = sqrt((B[0] - P[0]) * (B[0] - P[0]) + (B[1] - P[1]) * (B[1] - P[1]) + (B[2] - P[2]) * (B[2] - P[2]));
                    worst = fmax(worst, d);
                    count++;
                }
            }
            /* Loop's own points are floats: 1e-7 x diagonal is a few float ulps of the coordinates */
            check(count > 100 && worst <= 1e-7 * t.diag * 4, name, "%d points, worst %.3g (diag %.3g)", count, worst, t.diag);
        }
        if (loop) sfb_surface_destroy(loop);
        sfb__free(ctx, net);
        tmesh_free(ctx, &t);
        free(obj);
    }
}

/* The crease curve (edge points of the crease edges) of the disk's ray 0, ring r to r+1. */
static void crease_edge_points(const tbm_opts *o, const sfb__level *l, const double *net, int r, double out[5][3]) {
    const int a = tbm_index(o, 0, r, 0), b = tbm_index(o, 0, r + 1, 0);
    int f, k, j, c;
    for (f = 0; f < l->nf; ++f)
        for (k = 0; k < 3; ++k)
            if (l->fv[l->fv_off[f] + k] == a && l->fv[l->fv_off[f] + (k + 1) % 3] == b) {
                for (j = 0; j <= 4; ++j) {
                    int w[3] = {0, 0, 0}, i2, j2;
                    w[k] = 4 - j; w[(k + 1) % 3] = j;
                    i2 = w[1]; j2 = w[2];
                    for (c = 0; c < 3; ++c) out[j][c] = net[45 * (size_t)f + 3 * qij(i2, j2) + c];
                }
                return;
            }
}

static void bspline_edge(const double *A0, const double *A, const double *B, const double *B1, double out[5][3]) {
    int c;
    for (c = 0; c < 3; ++c) {
        const double P0 = (A0[c] + 4 * A[c] + B[c]) / 6, P1 = (2 * A[c] + B[c]) / 3, P2 = (A[c] + 2 * B[c]) / 3, P3 = (A[c] + 4 * B[c] + B1[c]) / 6;
        out[0][c] = P0; out[1][c] = (P0 + 3 * P1) / 4; out[2][c] = (P1 + P2) / 2; out[3][c] = (3 * P2 + P3) / 4; out[4][c] = P3;
    }
}

/* Creases: s = 1 on a regular crease is the B-spline; the blend; the jump grows with s; corners. */
static void test_creases(sfb_context *ctx) {
    tbm_opts o;
    tmesh t;
    char *obj;
    double *net[5] = {NULL, NULL, NULL, NULL, NULL};
    const double S[5] = {0.0, 0.25, 0.5, 0.75, 1.0};
    int i, k, c, r;
    memset(&o, 0, sizeof o);
    o.n = 6; o.R = 7; o.crease_k = 3; o.sharp = 1.0; o.ridge = 0.6; o.bump = 1.0; o.jitter = 0.2; o.seed = 11u;
    obj = tbm_obj(&o);
    if (!tmesh_load(ctx, obj, &t)) { fail("crease/load", "%s", sfb_last_error(ctx)); free(obj); return; }
    for (i = 0; i < 5; ++i) {
        sfb_tribezier_options to;
        to.sharpness_set = 1; to.sharpness = (float)S[i];
        net[i] = net_of(ctx, &t, &to, 0, NULL);
        if (!net[i]) { fail("crease/build", "s %g", S[i]); goto done; }
    }
    {
        /* s = 1: the crease ring 1..2 .. 4..5 (regular crease vertices) is the cubic B-spline */
        double worst = 0.0;
        for (r = 1; r <= 4; ++r) {
            double got[5][3], want[5][3], V[4][3];
            for (k = 0; k < 4; ++k)
                for (c = 0; c < 3; ++c) V[k][c] = t.m->positions[3 * tbm_index(&o, 0, r - 1 + k, 0) + c];
            crease_edge_points(&o, &t.prep, net[4], r, got);
            bspline_edge(V[0], V[1], V[2], V[3], want);
            for (k = 0; k < 5; ++k)
                for (c = 0; c < 3; ++c) worst = fmax(worst, fabs(got[k][c] - want[k][c]));
        }
        check(worst <= 1e-7 * t.diag, "crease/s1_regular_crease_is_loop_bspline", "worst %.3g (diag %.3g)", worst, t.diag);
    }
    {
        /* the blend, point by point */
        double worst = 0.0;
        size_t q;
        for (i = 1; i < 4; ++i)
            for (q = 0; q < 45 * (size_t)t.prep.nf; ++q) worst = fmax(worst, fabs(net[i][q] - ((1 - S[i]) * net[0][q] + S[i] * net[4][q])));
        check(worst <= 1e-9 * t.diag, "crease/blend_is_exact", "worst %.3g", worst);
    }
    {
        /* G1 at s = 0 (the crease smooth), the jump across the crease grows with s */
        g1_result g0 = g1_measure(&t.prep, net[0], 0), gs[5];
        int mono = 1;
        check(g0.jump <= 1e-9 && g0.flat > 1e-3, "crease/s0_is_g1_across_the_crease", "jump %.3g flat %.3g", g0.jump, g0.flat);
        for (i = 0; i < 5; ++i) {
            /* jumps across the tagged edges only: measure all, subtract nothing (the others are G1) */
            gs[i] = g1_measure(&t.prep, net[i], 0);
            if (i > 0 && !(gs[i].jump > gs[i - 1].jump)) mono = 0;
        }
        check(mono && gs[4].jump > 0.1, "crease/jump_grows_with_s", "jumps %.3g %.3g %.3g %.3g %.3g", gs[0].jump, gs[1].jump, gs[2].jump,
              gs[3].jump, gs[4].jump);
        {
            /* G1 across the edges that are not tagged, at s = 1 */
            g1_result g1 = g1_measure(&t.prep, net[4], 1);
            check(g1.jump <= 1e-9, "crease/s1_g1_off_the_crease", "jump %.3g", g1.jump);
        }
    }
    {
        /* continuity in s */
        sfb_tribezier_options to;
        double *a, *b, worst = 0.0;
        size_t q;
        to.sharpness_set = 1; to.sharpness = 0.5f;
        a = net_of(ctx, &t, &to, 0, NULL);
        to.sharpness = 0.5f + 1e-6f;
        b = net_of(ctx, &t, &to, 0, NULL);
        for (q = 0; a && b && q < 45 * (size_t)t.prep.nf; ++q) worst = fmax(worst, fabs(a[q] - b[q]));
        check(a && b && worst <= 1e-4 * t.diag, "crease/continuous_in_s", "a change of 1e-6 in s moves points by %.3g", worst);
        sfb__free(ctx, a); sfb__free(ctx, b);
    }
done:
    for (i = 0; i < 5; ++i) sfb__free(ctx, net[i]);
    tmesh_free(ctx, &t);
    free(obj);
}

/* Creases at extraordinary vertices of valence 3..12 and a corner: G1 off the crease at s = 1,
 * G1 everywhere at s = 0, corners interpolated at s = 1. */
static void test_crease_evs(sfb_context *ctx) {
    int n, corner;
    for (corner = 0; corner < 2; ++corner)
        for (n = corner ? 3 : 4; n <= 12; ++n) {
            tbm_opts o;
            tmesh t;
            char name[128], *obj;
            double *n0, *n1;
            sfb_tribezier_options to;
            sfb__tbz_stats st;
            memset(&o, 0, sizeof o);
            o.n = n; o.R = 5; o.crease_k = corner ? 0 : n / 2; o.corner3 = corner; o.sharp = 1.0; o.ridge = 0.5; o.bump = 1.0;
            o.jitter = 0.15; o.seed = 5u + (unsigned)n;
            obj = tbm_obj(&o);
            snprintf(name, sizeof name, "%s_valence_%d", corner ? "corner" : "crease", n);
            if (!tmesh_load(ctx, obj, &t)) { fail(name, "load"); free(obj); continue; }
            to.sharpness_set = 1; to.sharpness = 0.0f;
            n0 = net_of(ctx, &t, &to, 0, &st);
            if (st.fallbacks) printf("  %s: the smooth net fell back to the seed's tangent plane\n", name);
            to.sharpness = 1.0f;
            n1 = net_of(ctx, &t, &to, 0, NULL);
            if (!n0 || !n1) fail(name, "not built");
            else {
                g1_result g0 = g1_measure(&t.prep, n0, 0), g1 = g1_measure(&t.prep, n1, 1);
                char nm[160];
                snprintf(nm, sizeof nm, "%s/s0_g1", name);
                check(g0.jump <= 1e-9 && g0.flat > 1e-3, nm, "jump %.3g flat %.3g", g0.jump, g0.flat);
                snprintf(nm, sizeof nm, "%s/s1_g1_off_the_creases", name);
                check(g1.jump <= 1e-9 && g1.flat > 1e-3, nm, "jump %.3g flat %.3g", g1.jump, g1.flat);
                if (corner) {
                    double d = 0;
                    int c;
                    for (c = 0; c < 3; ++c) d += fabs(n1[c] - t.m->positions[c]); /* the centre is corner 0 of triangle 0 */
                    snprintf(nm, sizeof nm, "%s/s1_through_the_corner_vertex", name);
                    check(d <= 1e-12, nm, "distance %.3g", d);
                }
            }
            sfb__free(ctx, n0); sfb__free(ctx, n1);
            tmesh_free(ctx, &t);
            free(obj);
        }
}

/* A corner tag on a vertex without sharp edges (valence 3..8, a bump under it): at s = 1 the
 * surface passes through the vertex and stays G1 everywhere, its spokes too (the vertex keeps
 * Loop's smooth tangents: a cone point there, as the tag's subdivision reading has, would need
 * a normal jump along every spoke, 0.04-0.1 rad with the tangents along the spokes). */
static void test_corner_only(sfb_context *ctx) {
    int n;
    for (n = 3; n <= 8; ++n) {
        tbm_opts o;
        tmesh t;
        char name[96], *obj, *tagged;
        double *net;
        sfb_tribezier_options to;
        memset(&o, 0, sizeof o);
        o.n = n; o.R = 4; o.bump = 4.0; o.jitter = 0.1; o.seed = 11u + (unsigned)n;
        obj = tbm_obj(&o);
        tagged = (char *)malloc(strlen(obj) + 32);
        sprintf(tagged, "%st corner 1/1/0 0 1\n", obj);
        snprintf(name, sizeof name, "corner_only/valence_%d", n);
        if (!tmesh_load(ctx, tagged, &t)) { fail(name, "load"); free(obj); free(tagged); continue; }
        to.sharpness_set = 1; to.sharpness = 1.0f;
        net = net_of(ctx, &t, &to, 0, NULL);
        if (!net) fail(name, "not built");
        else {
            g1_result g = g1_measure(&t.prep, net, 0);
            double d = 0.0;
            int c;
            char nm[160];
            for (c = 0; c < 3; ++c) d += fabs(net[c] - t.m->positions[c]); /* the centre is corner 0 of triangle 0 */
            snprintf(nm, sizeof nm, "%s/s1_g1_through_the_vertex", name);
            check(g.jump <= 1e-9 && g.flat > 1e-3 && d <= 1e-12, nm, "normal jump %.3g rad, flatness %.3g, off the vertex by %.3g", g.jump, g.flat, d);
        }
        sfb__free(ctx, net);
        tmesh_free(ctx, &t);
        free(obj);
        free(tagged);
    }
}

static double net_curvature_energy(const double *net, int nf);

/* The subdivision reading of the slider, for comparison with ours: (1 - s) x Loop's limit of the
 * untagged mesh + s x Loop's limit with the crease infinitely sharp, point by point along the
 * same crease edges (rays 0 and k, rings 0..2, 200 samples per edge, the extraordinary vertex
 * itself left out: Loop's parametric derivatives vanish or diverge there), measured as ours is:
 * the curvature sign changes of the (x, z) projection (where |k| x mean edge > 1e-3) and the
 * height range. Returns 0 when a surface cannot be built or evaluated. */
static int loop_blend_profile(sfb_context *ctx, const tbm_opts *o, double s, double mean_edge, int *changes, double *range) {
    sfb_mesh *M[2] = {NULL, NULL};
    sfb_surface *S[2] = {NULL, NULL};
    double zlo = 1e300, zhi = -1e300;
    int m, ok = 1, side, r;
    *changes = 0;
    for (m = 0; m < 2 && ok; ++m) {
        tbm_opts q = *o;
        char *obj;
        sfb_surface_config c = sfb_surface_config_init(SFB_SCHEME_LOOP, 0);
        sfb_mesh_data d;
        q.sharp = m ? 10.0 : 0.0; /* >= 10: infinitely sharp */
        obj = tbm_obj(&q);
        memset(&d, 0, sizeof d);
        c.flags = SFB_REFINE_PATCHES;
        ok = sfb_mesh_read_obj(ctx, obj, strlen(obj), &M[m]) == SFB_SUCCESS && sfb_surface_create(ctx, M[m], &c, &S[m]) == SFB_SUCCESS &&
             sfb_surface_refine(S[m], &d) == SFB_SUCCESS;
        sfb_mesh_data_free(&d);
        free(obj);
    }
    for (side = 0; side < 2 && ok; ++side) {
        double prev_k = 0.0;
        for (r = 0; r < 2 && ok; ++r) {
            const int a = tbm_index(o, side ? o->crease_k : 0, r, 0), b = tbm_index(o, side ? o->crease_k : 0, r + 1, 0);
            sfb_mesh_desc d;
            int f, k = -1, off = 0, face = -1, q;
            sfb_mesh_get_desc(M[0], &d);
            for (f = 0; f < d.face_count && face < 0; off += d.face_sizes[f], ++f)
                for (k = 0; k < 3; ++k)
                    if (d.face_vertices[off + k] == a && d.face_vertices[off + (k + 1) % 3] == b) { face = f; break; }
            if (face < 0) { ok = 0; break; }
            {
                /* the edge from corner k to corner k + 1 at t = q / 200 (one eval call per
                 * surface), its direction (du, dv) in (u, v) */
                const double du = k == 0 ? 1.0 : k == 1 ? -1.0 : 0.0, dv = k == 0 ? 0.0 : k == 1 ? 1.0 : -1.0;
                sfb_location L[201];
                float P[2][201 * 3], Du[2][201 * 3], Dv[2][201 * 3], Duu[2][201 * 3], Duv[2][201 * 3], Dvv[2][201 * 3];
                for (q = 0; q <= 200; ++q) {
                    const double t = q / 200.0;
                    L[q].face = face;
                    L[q].u = (float)(k == 0 ? t : k == 1 ? 1.0 - t : 0.0);
                    L[q].v = (float)(k == 0 ? 0.0 : k == 1 ? t : 1.0 - t);
                }
                for (m = 0; m < 2 && ok; ++m) {
                    sfb_eval_output out;
                    memset(&out, 0, sizeof out);
                    out.position = P[m]; out.du = Du[m]; out.dv = Dv[m]; out.duu = Duu[m]; out.duv = Duv[m]; out.dvv = Dvv[m];
                    ok = sfb_surface_eval(S[m], L, 201, &out) == SFB_SUCCESS;
                }
                for (q = (r == 0); q <= 200 && ok; ++q) {
                    double X[3], D1[3], D2[3], k2;
                    int c;
                    for (c = 0; c < 3; ++c) {
                        const int i = 3 * q + c;
                        X[c] = (1 - s) * P[0][i] + s * P[1][i];
                        D1[c] = (1 - s) * (du * Du[0][i] + dv * Dv[0][i]) + s * (du * Du[1][i] + dv * Dv[1][i]);
                        D2[c] = (1 - s) * (du * du * Duu[0][i] + 2 * du * dv * Duv[0][i] + dv * dv * Dvv[0][i]) +
                                s * (du * du * Duu[1][i] + 2 * du * dv * Duv[1][i] + dv * dv * Dvv[1][i]);
                    }
                    zlo = fmin(zlo, X[2]); zhi = fmax(zhi, X[2]);
                    k2 = (D1[0] * D2[2] - D1[2] * D2[0]) / pow(D1[0] * D1[0] + D1[2] * D1[2] + 1e-300, 1.5);
                    if (fabs(k2) * mean_edge > 1e-3) {
                        if (prev_k != 0.0 && (k2 > 0) != (prev_k > 0)) ++*changes;
                        prev_k = k2;
                    }
                }
            }
        }
    }
    *range = zhi - zlo;
    for (m = 0; m < 2; ++m) { sfb_surface_destroy(S[m]); sfb_mesh_destroy(M[m]); }
    return ok;
}

/* The seed's open problem: the crease curve near an extraordinary crease vertex at s = 0.25,
 * 0.5, 0.75: (a) its largest distance from the vertical plane through the (straight) crease
 * line y = 0, (b) the curvature sign changes of its projection into that plane (x, z) within two
 * edges of the vertex; ours (mode 0) against the seed's tangent plane (1) and against ours with
 * the smooth net solved once (2: SFB__TBZ_NO_STRAIGHT, its crease curve bent by the solve), whose
 * surface ours must be as fair as (curvature energy at s = 0).
 * Two layouts of each disk (tbm_opts.level). Level rows ("undulation_level/..."): the lattice
 * rows on both sides of the crease at the same heights, so that Loop's limit surface, which
 * ours equals where the mesh is regular, lies in the crease's vertical plane along the crease
 * by symmetry; there (a) measures the construction at the vertex alone, and the issue's bound
 * of 1e-3 mean edges is asserted. Fanned rays ("undulation/..."): the rays spread evenly over
 * each side's pi, the rows of a side with two or four wedges at other heights than the other
 * side's; Loop's own limit lies 0.015-0.02 mean edges off the plane at valence 5 and 7 there,
 * a bound no construction that keeps Loop's surface can beat, and ours is asserted within 10 %
 * of it. */
static void test_undulation(sfb_context *ctx) {
    static const int vals[3] = {4, 5, 7};
    static const char *mode_name[3] = {"ours", "ours_no_worse_than_the_seed_plane", "ours_against_one_pass"};
    double ours_dev[4] = {0, 0, 0, 0}, ours_range[4] = {0, 0, 0, 0}, ours_energy = 0.0;
    int vi, mode, si, ours_changes[4] = {0, 0, 0, 0}, level;
    for (level = 0; level < 2; ++level)
    for (vi = 0; vi < 3; ++vi)
        for (mode = 0; mode < 3; ++mode) {
            const char *un = level ? "undulation_level" : "undulation";
            tbm_opts o;
            tmesh t;
            char *obj;
            double *n0, *n1, mean_edge = 0.0, loop_off = 0.0;
            sfb_tribezier_options to;
            int e;
            memset(&o, 0, sizeof o);
            o.n = vals[vi]; o.R = 5; o.crease_k = vals[vi] / 2; o.sharp = 1.0; o.ridge = 0.5; o.bump = 0.0; o.level = level;
            obj = tbm_obj(&o);
            if (!tmesh_load(ctx, obj, &t)) { fail(un, "load"); free(obj); continue; }
            for (e = 0; e < t.prep.ne; ++e) {
                const float *a = t.m->positions + 3 * t.prep.ev[2 * e], *b = t.m->positions + 3 * t.prep.ev[2 * e + 1];
                mean_edge += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2])) / t.prep.ne;
            }
            {
                /* Loop's own limit surface of the same mesh (untagged) at the crease vertices of
                 * rings 1 and 2: it lies loop_off off the crease plane where the mesh is not
                 * symmetric about it (valence 5, 7), and s = 0 equals it at regular vertices, so
                 * at s the crease curve is at least (1 - s) loop_off off the plane: the issue's
                 * 1e-3 mean edges cannot be met there by any construction that keeps Loop's
                 * surface where the mesh is regular */
                sfb_mesh *lm = NULL;
                sfb_surface *ls = NULL;
                sfb_mesh_data ld;
                sfb_surface_config lc = sfb_surface_config_init(SFB_SCHEME_LOOP, 0);
                tbm_opts lo = o;
                char *lobj;
                lo.sharp = 0.0;
                lobj = tbm_obj(&lo);
                memset(&ld, 0, sizeof ld);
                lc.flags = SFB_REFINE_LIMIT;
                if (sfb_mesh_read_obj(ctx, lobj, strlen(lobj), &lm) == SFB_SUCCESS && sfb_surface_create(ctx, lm, &lc, &ls) == SFB_SUCCESS &&
                    sfb_surface_refine(ls, &ld) == SFB_SUCCESS) {
                    int r2, sd;
                    for (sd = 0; sd < 2; ++sd)
                        for (r2 = 1; r2 <= 2; ++r2)
                            loop_off = fmax(loop_off, fabs(ld.limit_positions[3 * tbm_index(&o, sd ? o.crease_k : 0, r2, 0) + 1]));
                } else fail(un, "Loop limit: %s", sfb_last_error(ctx));
                sfb_mesh_data_free(&ld);
                sfb_surface_destroy(ls);
                sfb_mesh_destroy(lm);
                free(lobj);
            }
            to.sharpness_set = 1; to.sharpness = 0.0f;
            {
                const unsigned fl = mode == 1 ? SFB__TBZ_SEED_PLANE : mode == 2 ? SFB__TBZ_NO_STRAIGHT : 0;
                sfb__tbz_stats st;
                n0 = net_of(ctx, &t, &to, fl, &st);
                to.sharpness = 1.0f;
                n1 = net_of(ctx, &t, &to, fl, NULL);
                if (n0 && mode != 1) {
                    /* the surface beside the crease: the s = 0 net's curvature energy */
                    const double en = net_curvature_energy(n0, t.prep.nf);
                    char nb[160];
                    if (mode == 0) {
                        ours_energy = en;
                        /* on the level disks the crease is held across too (tbz_take_second) */
                        snprintf(nb, sizeof nb, "%s/valence_%d/second_pass_taken", un, o.n);
                        check(st.straight == 1 && st.straight_kept_first == 0 && st.straight_unfair == 0 && st.crease_weighted > 0 &&
                                  (!level || st.straight_across == 1),
                              nb, "second passes %d, first nets kept %d, components given back as less fair %d, held across too %d, crease "
                              "unknowns weighted %ld", st.straight, st.straight_kept_first, st.straight_unfair, st.straight_across, st.crease_weighted);
                    } else {
                        /* asserted: holding the crease costs the surface beside it at most 3 % of
                         * its curvature energy (measured -0.2 to +1.4 %, +2.0 % on the level disk
                         * of valence 5, held across too; held in every direction as well, M = I
                         * in tbz_mix, +4.4 % at valence 5; coarse_one asserts the same on bumped
                         * disks) */
                        snprintf(nb, sizeof nb, "%s/valence_%d/as_fair_as_one_pass", un, o.n);
                        check(ours_energy <= 1.03 * en && st.straight == 0, nb, "curvature energy at s = 0: ours %.4g, one pass %.4g", ours_energy,
                              en);
                        printf("  %s: curvature energy at s = 0: ours %.4g, one pass %.4g\n", nb, ours_energy, en);
                    }
                }
            }
            for (si = 1; n0 && n1 && si <= 3; ++si) {
                const double s = 0.25 * si;
                double dev = 0.0, prev_k = 0.0, zlo = 1e300, zhi = -1e300;
                int changes = 0, side, r, q, c;
                char nm[160];
                /* both rays of the crease: ray 0 and ray k, rings 0..2 */
                for (side = 0; side < 2; ++side) {
                    prev_k = 0.0;
                    for (r = 0; r < 2; ++r) {
                        double B0[5][3], B1[5][3];
                        {
                            const int a = side ? tbm_index(&o, o.crease_k, r, 0) : tbm_index(&o, 0, r, 0);
                            const int b = side ? tbm_index(&o, o.crease_k, r + 1, 0) : tbm_index(&o, 0, r + 1, 0);
                            int f, k, j;
                            for (f = 0; f < t.prep.nf; ++f)
                                for (k = 0; k < 3; ++k)
                                    if (t.prep.fv[t.prep.fv_off[f] + k] == a && t.prep.fv[t.prep.fv_off[f] + (k + 1) % 3] == b)
                                        for (j = 0; j <= 4; ++j) {
                                            int w[3] = {0, 0, 0};
                                            w[k] = 4 - j; w[(k + 1) % 3] = j;
                                            for (c = 0; c < 3; ++c) {
                                                B0[j][c] = n0[45 * (size_t)f + 3 * qij(w[1], w[2]) + c];
                                                B1[j][c] = n1[45 * (size_t)f + 3 * qij(w[1], w[2]) + c];
                                            }
                                        }
                        }
                        for (q = 0; q <= 50; ++q) {
                            const double u = q / 50.0, bb[5] = {pow(1 - u, 4), 4 * u * pow(1 - u, 3), 6 * u * u * (1 - u) * (1 - u), 4 * u * u * u * (1 - u), pow(u, 4)};
                            const double d1[4] = {pow(1 - u, 3), 3 * u * (1 - u) * (1 - u), 3 * u * u * (1 - u), u * u * u};
                            const double d2[3] = {(1 - u) * (1 - u), 2 * u * (1 - u), u * u};
                            double X[3] = {0, 0, 0}, D1[3] = {0, 0, 0}, D2[3] = {0, 0, 0}, k2;
                            int j;
                            for (j = 0; j < 5; ++j)
                                for (c = 0; c < 3; ++c) X[c] += bb[j] * ((1 - s) * B0[j][c] + s * B1[j][c]);
                            for (j = 0; j < 4; ++j)
                                for (c = 0; c < 3; ++c) D1[c] += 4 * d1[j] * ((1 - s) * (B0[j + 1][c] - B0[j][c]) + s * (B1[j + 1][c] - B1[j][c]));
                            for (j = 0; j < 3; ++j)
                                for (c = 0; c < 3; ++c)
                                    D2[c] += 12 * d2[j] * ((1 - s) * (B0[j + 2][c] - 2 * B0[j + 1][c] + B0[j][c]) + s * (B1[j + 2][c] - 2 * B1[j + 1][c] + B1[j][c]));
                            dev = fmax(dev, fabs(X[1]));
                            zlo = fmin(zlo, X[2]); zhi = fmax(zhi, X[2]);
                            /* signed curvature of the (x, z) projection */
                            /* the curvature, counted where it exceeds 1e-3 / mean edge (a straight
                             * stretch is not a sign change) */
                            k2 = (D1[0] * D2[2] - D1[2] * D2[0]) / pow(D1[0] * D1[0] + D1[2] * D1[2] + 1e-300, 1.5);
                            if (fabs(k2) * mean_edge > 1e-3) {
                                if (prev_k != 0.0 && (k2 > 0) != (prev_k > 0)) changes++;
                                prev_k = k2;
                            }
                        }
                    }
                }
                snprintf(nm, sizeof nm, "%s/valence_%d/s_%.2f/%s", un, o.n, s, mode_name[mode]);
                /* (a) the deviation from the vertical plane; (b) the curvature sign changes of the
                 * projection into it; and the undulation within the plane, the height range of
                 * the projection (the crease line is straight and level: 0 at s = 1) */
                printf("  %s: deviation from the crease plane %.3g (%.3g mean edges; Loop's limit forces >= %.3g), curvature sign "
                       "changes %d, height range in the plane %.3g mean edges\n",
                       nm, dev, dev / mean_edge, (1.0 - s) * loop_off / mean_edge, changes, (zhi - zlo) / mean_edge);
                if (!mode) {
                    char nb[200];
                    int lchanges;
                    double lrange;
                    ours_dev[si] = dev; ours_changes[si] = changes; ours_range[si] = zhi - zlo;
                    /* asserted: ours undulates within the plane less than the subdivision
                     * reading of the slider (Loop's smooth and sharp limits blended), whose
                     * smooth half bends along the crease line near the vertex by itself */
                    snprintf(nb, sizeof nb, "%s_flatter_than_the_loop_blend", nm);
                    if (!loop_blend_profile(ctx, &o, s, mean_edge, &lchanges, &lrange)) fail(nb, "Loop: %s", sfb_last_error(ctx));
                    else {
                        printf("  %s: the Loop smooth/sharp blend: curvature sign changes %d, height range in the plane %.3g mean edges\n",
                               nm, lchanges, lrange / mean_edge);
                        check(zhi - zlo < lrange, nb, "height range %.3g against the Loop blend's %.3g mean edges", (zhi - zlo) / mean_edge,
                              lrange / mean_edge);
                    }
                    if (level) {
                        /* asserted: the issue's check (a), within 1e-3 mean edges of the plane */
                        snprintf(nb, sizeof nb, "%s_in_the_crease_plane", nm);
                        check(dev <= 1e-3 * mean_edge && loop_off <= 1e-6 * mean_edge, nb, "deviation %.3g mean edges (Loop's limit %.3g)",
                              dev / mean_edge, loop_off / mean_edge);
                    } else {
                        /* asserted: ours is within 10% of the deviation Loop's limit forces */
                        snprintf(nb, sizeof nb, "%s_near_the_loop_bound", nm);
                        check(dev <= 1.1 * (1.0 - s) * loop_off + 1e-12 * mean_edge, nb, "deviation %.3g, Loop's bound %.3g", dev,
                              (1.0 - s) * loop_off);
                    }
                    /* asserted: the issue's check (b), no curvature sign change within two edges */
                    snprintf(nb, sizeof nb, "%s_no_curvature_sign_change", nm);
                    check(changes == 0, nb, "%d curvature sign changes, height range %.3g mean edges", changes, (zhi - zlo) / mean_edge);
                } else if (mode == 1) {
                    /* asserted: ours deviates from the crease plane, and undulates within it, no
                     * more than the seed's kind; printed: ours within the issue's bound of 1e-3
                     * mean edges (on the fanned disks not at valence 5 and 7: Loop's own offset
                     * is larger) */
                    check(ours_dev[si] <= dev + 1e-12 && ours_range[si] <= zhi - zlo + 1e-12, nm,
                          "ours %.3g against the seed's %.3g, height range %.3g against %.3g (sign changes %d against %d)", ours_dev[si], dev,
                          ours_range[si] / mean_edge, (zhi - zlo) / mean_edge, ours_changes[si], changes);
                    printf("  %s: ours within 1e-3 mean edges: %s\n", nm, ours_dev[si] <= 1e-3 * mean_edge ? "yes" : "no");
                } else {
                    /* asserted: the one-pass net bends the crease (what the second pass removes:
                     * were it straight already, the check above would not tell the two apart) */
                    check(changes > 0 && ours_range[si] * 10.0 < zhi - zlo, nm, "one pass: %d sign changes, height range %.3g mean edges (ours %.3g)",
                          changes, (zhi - zlo) / mean_edge, ours_range[si] / mean_edge);
                }
            }
            sfb__free(ctx, n0); sfb__free(ctx, n1);
            tmesh_free(ctx, &t);
            free(obj);
        }
}

/* The largest angle between the normals sfb_surface_eval gives on the two faces of every interior
 * edge of l (skip_tagged: untagged edges only), 9 points per edge; 1e30 when eval fails. */
/* stride: every stride-th edge (1: all) */
static double eval_edge_jump_every(sfb_context *ctx, const sfb_surface *sf, const sfb__level *l, int skip_tagged, int stride) {
    /* every sample pair in one call (one call per pair took 30 s on spot's 8,800 edges over the
     * four backends) */
    double jump = 0.0;
    int e, k2, n = 0, i;
    sfb_location *loc = (sfb_location *)malloc((size_t)l->ne * 18 * sizeof(sfb_location) + 1);
    float *N = (float *)malloc((size_t)l->ne * 54 * sizeof(float) + 1);
    sfb_eval_output eo;
    if (!loc || !N) { free(loc); free(N); printf("  eval: out of memory\n"); return 1e30; }
    for (e = 0; e < l->ne; e += stride) {
        int s0, s1, f0, f1;
        if (l->ef_off[e + 1] - l->ef_off[e] != 2 || (skip_tagged && l->es[e] > 0.0f)) continue;
        f0 = l->ef[l->ef_off[e]]; s0 = l->ef_slot[l->ef_off[e]];
        f1 = l->ef[l->ef_off[e] + 1]; s1 = l->ef_slot[l->ef_off[e] + 1];
        for (k2 = 1; k2 < 10; ++k2) {
            double u, v;
            sfb_location *a = loc + n, *b = loc + n + 1;
            edge_uv(s0, k2 / 10.0, &u, &v); a->face = f0; a->u = (float)u; a->v = (float)v;
            edge_uv(s1, 1.0 - k2 / 10.0, &u, &v); b->face = f1; b->u = (float)u; b->v = (float)v;
            /* on the edge u + v = 1 in double after rounding to float */
            while ((double)a->u + a->v > 1.0) a->v = nextafterf(a->v, 0.0f);
            while ((double)b->u + b->v > 1.0) b->v = nextafterf(b->v, 0.0f);
            n += 2;
        }
    }
    memset(&eo, 0, sizeof eo);
    eo.normal = N;
    if (n > 0 && sfb_surface_eval(sf, loc, n, &eo) != SFB_SUCCESS) { printf("  eval: %s\n", sfb_last_error(ctx)); jump = 1e30; n = 0; }
    for (i = 0; i < n; i += 2) {
        double a[3], bb[3];
        a[0] = N[3 * i]; a[1] = N[3 * i + 1]; a[2] = N[3 * i + 2];
        bb[0] = N[3 * i + 3]; bb[1] = N[3 * i + 4]; bb[2] = N[3 * i + 5];
        jump = fmax(jump, angle_between(a, bb));
    }
    free(loc);
    free(N);
    return jump;
}
static double eval_edge_jump(sfb_context *ctx, const sfb_surface *sf, const sfb__level *l, int skip_tagged) {
    return eval_edge_jump_every(ctx, sf, l, skip_tagged, 1);
}

/* Extraordinary vertices of different valences that touch: the mesh's own G1 constraints have
 * no exact solution (near-G1 only); after one Loop step they do (sfb__tribezier_refined_points),
 * and after two (what sfb__tribezier_build switches to there: sixteen patches per triangle, every
 * component solved by a template). A cube cut into
 * triangles (valences 3 to 6, all touching) and spot.obj. */
static const char *tri_cube =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
    "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

/* The refined level's rings, which tbz_refine writes from the parent's (tbz_child_rings), are
 * the ones sfb__level_complete finds by walking around every vertex: the same arrays, entry for
 * entry (so the nets are bit for bit what they were). */
static void rings_as_walked(sfb_context *ctx, const char *name, const sfb__level *rl) {
    sfb__level c;
    int same = 1, bad = -1;
    memset(&c, 0, sizeof c);
    c.nv = rl->nv; c.nf = rl->nf; c.ne = rl->ne;
    c.fv_off = (int *)sfb__alloc(ctx, ((size_t)rl->nf + 1) * sizeof(int));
    c.fv = (int *)sfb__alloc(ctx, ((size_t)rl->nfv + 1) * sizeof(int));
    c.fe = (int *)sfb__alloc(ctx, ((size_t)rl->nfv + 1) * sizeof(int));
    c.ev = (int *)sfb__alloc(ctx, (2 * (size_t)rl->ne + 1) * sizeof(int));
    if (!c.fv_off || !c.fv || !c.fe || !c.ev) { fail(name, "out of memory"); sfb__level_free(ctx, &c); return; }
    memcpy(c.fv_off, rl->fv_off, ((size_t)rl->nf + 1) * sizeof(int));
    memcpy(c.fv, rl->fv, (size_t)rl->nfv * sizeof(int));
    memcpy(c.fe, rl->fe, (size_t)rl->nfv * sizeof(int));
    memcpy(c.ev, rl->ev, 2 * (size_t)rl->ne * sizeof(int));
    if (sfb__level_complete(ctx, &c) != SFB_SUCCESS) {
        fail(name, "sfb__level_complete: %s", sfb_last_error(ctx));
        sfb__level_free(ctx, &c);
        return;
    }
#define RINGS_SAME(field, count) \
    if (same && memcmp(c.field, rl->field, (size_t)(count) * sizeof(*c.field)) != 0) { same = 0; bad = __LINE__; }
    RINGS_SAME(vf_off, rl->nv + 1) RINGS_SAME(vf, rl->nfv) RINGS_SAME(vf_slot, rl->nfv) RINGS_SAME(ve_off, rl->nv + 1)
    RINGS_SAME(ve, 2 * rl->ne) RINGS_SAME(ef_off, rl->ne + 1) RINGS_SAME(ef, rl->nfv) RINGS_SAME(ef_slot, rl->nfv)
    RINGS_SAME(etag, rl->ne) RINGS_SAME(vtag, rl->nv)
#undef RINGS_SAME
    check(same, name, "%d vertices, %d triangles; first array that differs: line %d", rl->nv, rl->nf, bad);
    sfb__level_free(ctx, &c);
}

static void refined_one(sfb_context *ctx, const char *name, const char *obj) {
    tmesh t;
    double *net = NULL, *net4 = NULL;
    sfb__tbz_stats st, st4;
    sfb__level rl;
    char nm[160];
    memset(&rl, 0, sizeof rl);
    if (!tmesh_load(ctx, obj, &t)) { fail(name, "load: %s", sfb_last_error(ctx)); return; }
    net = net_of(ctx, &t, NULL, 0, &st);
    if (sfb__tribezier_refined_points(ctx, &t.prep, t.m->positions, NULL, 0, &rl, &net4, &st4) != SFB_SUCCESS || !net) {
        fail(name, "not built: %s", sfb_last_error(ctx));
    } else {
        g1_result g0 = g1_measure(&t.prep, net, 0), g = g1_measure(&rl, net4, 0);
        snprintf(nm, sizeof nm, "%s_one_loop_step_rings_as_walked", name);
        rings_as_walked(ctx, nm, &rl);
        snprintf(nm, sizeof nm, "%s_unrefined_is_not_g1", name);
        check(st.residual > 1e-10 && g0.jump > 1e-6, nm, "residual %.3g, normal jump %.3g rad", st.residual, g0.jump);
        snprintf(nm, sizeof nm, "%s_after_one_loop_step_is_g1", name);
        check(g.jump <= 1e-9 && g.gap <= 1e-7 * t.diag && g.flat > 1e-3 && st4.residual <= 1e-12, nm,
              "normal jump %.3g rad (unrefined %.3g), gap %.3g, flatness %.3g, residual %.3g", g.jump, g0.jump, g.gap, g.flat, st4.residual);
        printf("  %s: unrefined jump %.3g rad residual %.3g; one Loop step: jump %.3g rad, gap %.3g, %ld unknowns, residual %.3g\n", name,
               g0.jump, st.residual, g.jump, g.gap, st4.unknowns, st4.residual);
    }
    sfb__free(ctx, net4);
    sfb__level_free(ctx, &rl);
    net4 = NULL;
    /* two Loop steps (what sfb__tribezier_build uses): every component around one extraordinary
     * vertex, solved by the templates */
    memset(&st4, 0, sizeof st4);
    snprintf(nm, sizeof nm, "%s_after_two_loop_steps_is_g1", name);
    if (sfb__tribezier_refined_points(ctx, &t.prep, t.m->positions, NULL, SFB__TBZ_TWO_STEPS, &rl, &net4, &st4) != SFB_SUCCESS) {
        fail(nm, "not built: %s", sfb_last_error(ctx));
    } else {
        g1_result g = g1_measure(&rl, net4, 0);
        char rn[160];
        snprintf(rn, sizeof rn, "%s_two_loop_steps_rings_as_walked", name);
        rings_as_walked(ctx, rn, &rl);
        check(rl.nf == 16 * t.prep.nf && g.jump <= 1e-9 && g.gap <= 1e-7 * t.diag && g.flat > 1e-3 && st4.residual <= 1e-12 && st4.templated > 0, nm,
              "%d triangles, normal jump %.3g rad, gap %.3g, flatness %.3g, residual %.3g, %d components by %d templates, %ld CGLS iterations",
              rl.nf, g.jump, g.gap, g.flat, st4.residual, st4.templated, st4.templates, st4.iterations);
        printf("  %s: two Loop steps: jump %.3g rad, %d components by %d templates, %ld CGLS iterations, residual %.3g\n", name, g.jump,
               st4.templated, st4.templates, st4.iterations, st4.residual);
    }
    sfb__free(ctx, net);
    sfb__free(ctx, net4);
    sfb__level_free(ctx, &rl);
    tmesh_free(ctx, &t);
}

/* Templates (tbz_templates: one dense minimum-norm solve per shape of neighbourhood, used on
 * every component of that shape) give the net CGLS gives (SFB__TBZ_NO_TEMPLATES) within 1e-9 of
 * the diagonal, with fewer iterations; on a mesh's own net (only some components qualify) and
 * after two Loop steps (all do). */
/* The nets of t with flags `steps` and with steps | more, after Loop steps (refined: one, two
 * with steps SFB__TBZ_TWO_STEPS) or on the mesh itself, into *a and *b (45 doubles per
 * triangle, *n of them in all; 0 when either failed) with their stats and refined meshes. */
static void two_nets(sfb_context *ctx, tmesh *t, int refined, unsigned steps, unsigned more, double **a, double **b, sfb__tbz_stats *sa,
                     sfb__tbz_stats *sb, sfb__level *ra, sfb__level *rb, size_t *n) {
    *n = 0;
    if (refined) {
        if (sfb__tribezier_refined_points(ctx, &t->prep, t->m->positions, NULL, steps, ra, a, sa) == SFB_SUCCESS &&
            sfb__tribezier_refined_points(ctx, &t->prep, t->m->positions, NULL, steps | more, rb, b, sb) == SFB_SUCCESS)
            *n = 45 * (size_t)ra->nf;
    } else {
        *a = net_of(ctx, t, NULL, steps, sa);
        *b = net_of(ctx, t, NULL, steps | more, sb);
        *n = 45 * (size_t)t->prep.nf;
    }
}

/* want_direct: some regions (shapes met once) must have had a factor of their own */
static void templates_one(sfb_context *ctx, const char *name, const char *obj, unsigned steps, int want_direct) {
    tmesh t;
    double *a = NULL, *b = NULL, worst = 0.0;
    sfb__tbz_stats sa, sb;
    sfb__level ra, rb;
    char nm[160];
    size_t i, n = 0;
    memset(&ra, 0, sizeof ra); memset(&rb, 0, sizeof rb);
    memset(&sa, 0, sizeof sa); memset(&sb, 0, sizeof sb);
    snprintf(nm, sizeof nm, "templates/%s/same_net_as_cgls", name);
    if (!tmesh_load(ctx, obj, &t)) { fail(nm, "load: %s", sfb_last_error(ctx)); return; }
    two_nets(ctx, &t, steps != 0, steps, SFB__TBZ_NO_TEMPLATES, &a, &b, &sa, &sb, &ra, &rb, &n);
    if (!a || !b || n == 0) {
        fail(nm, "not built: %s", sfb_last_error(ctx));
    } else {
        for (i = 0; i < n; ++i) worst = fmax(worst, fabs(a[i] - b[i]));
        check(worst <= 1e-9 * t.diag && sa.templated > 0 && sa.templates < sa.templated && sb.templated == 0 &&
                  sa.iterations < sb.iterations && sa.residual <= 1e-12 + sb.residual && (!want_direct || sa.direct > 0), nm,
              "largest difference %.3g (diag %.3g); %d components by %d templates and %d factors of their own, CGLS iterations %ld vs %ld, "
              "residual %.3g vs %.3g", worst, t.diag, sa.templated, sa.templates, sa.direct, sa.iterations, sb.iterations, sa.residual, sb.residual);
        printf("  %s: largest difference from CGLS alone %.3g of the diagonal; %d regions by %d templates and %d factors of their own, "
               "%ld CGLS iterations left (CGLS alone: %ld); residual %.3g (CGLS alone %.3g)\n",
               nm, worst / t.diag, sa.templated, sa.templates, sa.direct, sa.iterations, sb.iterations, sa.residual, sb.residual);
    }
    sfb__free(ctx, a); sfb__free(ctx, b);
    sfb__level_free(ctx, &ra); sfb__level_free(ctx, &rb);
    tmesh_free(ctx, &t);
}

/* A template or factor whose check fails leaves the net bit for bit as it was, and CGLS solves
 * its region: with every check failed (SFB__TBZ_REJECT_TEMPLATES) the net must be bit for bit
 * the one CGLS alone builds (SFB__TBZ_NO_TEMPLATES), teapot's own net (templates and regions'
 * own factors both made). */
static void templates_rejected(sfb_context *ctx, const char *obj) {
    const char *nm = "templates/teapot_own_net/rejected_regions_go_to_cgls";
    tmesh t;
    double *a = NULL, *b = NULL;
    sfb__tbz_stats sa, sb;
    if (!tmesh_load(ctx, obj, &t)) { fail(nm, "load: %s", sfb_last_error(ctx)); return; }
    memset(&sa, 0, sizeof sa); memset(&sb, 0, sizeof sb);
    a = net_of(ctx, &t, NULL, SFB__TBZ_REJECT_TEMPLATES, &sa);
    b = net_of(ctx, &t, NULL, SFB__TBZ_NO_TEMPLATES, &sb);
    if (!a || !b) fail(nm, "not built: %s", sfb_last_error(ctx));
    else {
        const int same = memcmp(a, b, 45 * (size_t)t.prep.nf * sizeof(double)) == 0;
        check(same && sa.templated == 0 && sa.templates > 0 && sa.direct > 0 && sa.iterations == sb.iterations, nm,
              "nets %s; %d templates and %d factors made, %d used; CGLS iterations %ld vs %ld", same ? "equal" : "differ", sa.templates,
              sa.direct, sa.templated, sa.iterations, sb.iterations);
    }
    sfb__free(ctx, a); sfb__free(ctx, b);
    tmesh_free(ctx, &t);
}

/* obj (malloc'd copy) with a crease tag of sharpness `s` on the first edge of every `every`-th
 * face; *tags: how many. NULL when out of memory. */
static char *obj_tag_creases(const char *obj, int every, double s, int *tags) {
    const size_t n = strlen(obj);
    size_t at;
    const char *fl = obj;
    int faces = 0;
    char *text = (char *)malloc(2 * n + 64);
    *tags = 0;
    if (!text) return NULL;
    memcpy(text, obj, n);
    at = n;
    text[at++] = '\n';
    while ((fl = strstr(fl, "\nf ")) != NULL) {
        /* its first two vertex indices (v, v/vt or v/vt/vn) */
        char *e;
        const long v0 = strtol(fl + 3, &e, 10);
        long v1;
        while (*e && *e != ' ' && *e != '\n') ++e;
        v1 = strtol(e, NULL, 10);
        ++fl;
        if (faces++ % every != 0 || v0 < 1 || v1 < 1 || at + 64 > 2 * n) continue;
        at += (size_t)snprintf(text + at, 64, "t crease 2/1/0 %ld %ld %g\n", v0 - 1, v1 - 1, s);
        ++*tags;
    }
    text[at] = 0;
    return text;
}

/* The sharp net takes the smooth net's solution of every constraint component that is the same
 * system in both (tbz_prev): the net must be bit for bit the one solved in full
 * (SFB__TBZ_NO_REUSE), with components reused and fewer CGLS iterations. obj gets crease tags
 * of s = 0.5 (so that both nets are built: with s = 1 everywhere the smooth net is not) on the
 * first edge of every 256th face, so that the nets differ near them (rows, and points the rows
 * read) and agree away from them. */
static void reuse_one(sfb_context *ctx, const char *name, const char *obj) {
    tmesh t;
    double *a = NULL, *b = NULL;
    sfb__tbz_stats sa, sb;
    sfb__level ra, rb;
    char nm[160], *text;
    int tags = 0;
    memset(&ra, 0, sizeof ra); memset(&rb, 0, sizeof rb);
    memset(&sa, 0, sizeof sa); memset(&sb, 0, sizeof sb);
    text = obj_tag_creases(obj, 256, 0.5, &tags);
    if (!text) { fail(name, "out of memory"); return; }
    snprintf(nm, sizeof nm, "%s/sharp_net_reuse_is_exact", name);
    if (!tmesh_load(ctx, text, &t)) { fail(nm, "load: %s", sfb_last_error(ctx)); free(text); return; }
    if (sfb__tribezier_refined_points(ctx, &t.prep, t.m->positions, NULL, 0, &ra, &a, &sa) != SFB_SUCCESS ||
        sfb__tribezier_refined_points(ctx, &t.prep, t.m->positions, NULL, SFB__TBZ_NO_REUSE, &rb, &b, &sb) != SFB_SUCCESS) {
        fail(nm, "not built: %s", sfb_last_error(ctx));
    } else {
        const int same = ra.nf == rb.nf && memcmp(a, b, 45 * (size_t)ra.nf * sizeof(double)) == 0;
        check(same && sa.reused > 0 && sb.reused == 0 && sa.iterations + sa.direct < sb.iterations + sb.direct && sa.residual == sb.residual &&
                  !sa.sharp_only, nm,
              "identical %d, components reused %d (without: %d), CGLS iterations %ld vs %ld, direct solves %d vs %d, residual %.3g vs %.3g",
              same, sa.reused, sb.reused, sa.iterations, sb.iterations, sa.direct, sb.direct, sa.residual, sb.residual);
        printf("  %s: %d crease tags, %d sharp-net components reused, CGLS iterations %ld instead of %ld\n", name, tags, sa.reused,
               sa.iterations, sb.iterations);
    }
    sfb__free(ctx, a); sfb__free(ctx, b);
    sfb__level_free(ctx, &ra); sfb__level_free(ctx, &rb);
    tmesh_free(ctx, &t);
    free(text);
}

/* Where s = 1 at every vertex the blend is the sharp net everywhere and the smooth net is not
 * built (tbz_points): the net must be the one built with both (SFB__TBZ_BOTH_NETS) within
 * 1e-12 x diagonal (the same systems; a template may come from another component of its shape).
 * `every` > 0: obj gets s = 1 crease tags on
 * every `every`-th face's first edge, 0: its own tags (the corners of its split non-manifold
 * vertices); refined: the net after Loop steps (one, two with steps = SFB__TBZ_TWO_STEPS), else
 * the mesh's own. */
static void sharp_only_one(sfb_context *ctx, const char *name, const char *obj, int every, int refined, unsigned steps) {
    tmesh t;
    double *a = NULL, *b = NULL, worst = 0.0;
    sfb__tbz_stats sa, sb;
    sfb__level ra, rb;
    char nm[160], *text = NULL;
    size_t i, n = 0;
    int tags = 0;
    memset(&ra, 0, sizeof ra); memset(&rb, 0, sizeof rb);
    memset(&sa, 0, sizeof sa); memset(&sb, 0, sizeof sb);
    snprintf(nm, sizeof nm, "sharp_only/%s/same_net_as_both_nets", name);
    if (every > 0 && !(text = obj_tag_creases(obj, every, 1.0, &tags))) { fail(nm, "out of memory"); return; }
    if (!tmesh_load(ctx, text ? text : obj, &t)) { fail(nm, "load: %s", sfb_last_error(ctx)); free(text); return; }
    two_nets(ctx, &t, refined, steps, SFB__TBZ_BOTH_NETS, &a, &b, &sa, &sb, &ra, &rb, &n);
    if (!a || !b || n == 0) {
        fail(nm, "not built: %s", sfb_last_error(ctx));
    } else {
        for (i = 0; i < n; ++i) worst = fmax(worst, fabs(a[i] - b[i]));
        check(worst <= 1e-12 * t.diag && sa.sharp_only && !sb.sharp_only && sa.residual <= 1e-12 + sb.residual, nm,
              "largest difference %.3g (diag %.3g); %d tags added; CGLS iterations %ld vs %ld, templates %d vs %d, residual %.3g vs %.3g",
              worst, t.diag, tags, sa.iterations, sb.iterations, sa.templates, sb.templates, sa.residual, sb.residual);
    }
    sfb__free(ctx, a); sfb__free(ctx, b);
    sfb__level_free(ctx, &ra); sfb__level_free(ctx, &rb);
    tmesh_free(ctx, &t);
    free(text);
}

/* Two OBJ texts in the forms tbm_obj writes (v, f, t crease, t corner) as one mesh: b's
 * vertex indices moved past a's vertices (malloc'd); with share, b's centre (its first vertex)
 * is a's, b's other vertices follow a's, lifted by 2 in z (two disks through one non-manifold
 * vertex). */
static char *obj_join_ex(const char *a, const char *b, int share) {
    const size_t la = strlen(a), lb = strlen(b), cap = la + 2 * lb + 64;
    char *s = (char *)malloc(cap), line[512];
    const char *p;
    size_t len;
    int nva = 0, seen_v = 0;
    if (!s) return NULL;
    memcpy(s, a, la);
    len = la;
    for (p = a; (p = strstr(p, "v ")) != NULL; ++p)
        if (p == a || p[-1] == '\n') ++nva;
    for (p = b; *p; ) {
        const char *e = strchr(p, '\n');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        int i, j, k;
        double x, y, z;
#define OBJ_MAP(q) (share ? ((q) == 1 ? 1 : (q) + nva - 1) : (q) + nva)
        if (n >= sizeof line) n = sizeof line - 1;
        memcpy(line, p, n);
        line[n] = 0;
        if (share && sscanf(line, "v %lf %lf %lf", &x, &y, &z) == 3) {
            if (seen_v++) len += (size_t)snprintf(s + len, cap - len, "v %.17g %.17g %.17g\n", x, y, z + 2.0);
        } else if (sscanf(line, "f %d %d %d", &i, &j, &k) == 3)
            len += (size_t)snprintf(s + len, cap - len, "f %d %d %d\n", OBJ_MAP(i), OBJ_MAP(j), OBJ_MAP(k));
        else if (sscanf(line, "t crease 2/1/0 %d %d %lf", &i, &j, &x) == 3) /* 0-based */
            len += (size_t)snprintf(s + len, cap - len, "t crease 2/1/0 %d %d %.17g\n", OBJ_MAP(i + 1) - 1, OBJ_MAP(j + 1) - 1, x);
        else if (sscanf(line, "t corner 1/1/0 %d %lf", &i, &x) == 2)
            len += (size_t)snprintf(s + len, cap - len, "t corner 1/1/0 %d %.17g\n", OBJ_MAP(i + 1) - 1, x);
        else len += (size_t)snprintf(s + len, cap - len, "%s\n", line);
#undef OBJ_MAP
        p += e ? (size_t)(e - p) + 1 : n;
    }
    return s;
}

/* Two test disks in one OBJ (obj_join_ex; with share through one vertex): a, of valence an and
 * aR rings, a straight crease tagged asharp through its centre on a ridge, b untagged; both
 * bumpy and jittered (malloc'd). */
static char *two_disks(int an, int aR, double asharp, double aridge, double ajit, unsigned aseed, int bn, int bR, double bjit, unsigned bseed,
                       int share) {
    tbm_opts o;
    char *a, *b, *j;
    memset(&o, 0, sizeof o);
    o.n = an; o.R = aR; o.crease_k = an / 2; o.sharp = asharp; o.ridge = aridge; o.bump = 1.0; o.jitter = ajit; o.seed = aseed;
    a = tbm_obj(&o);
    memset(&o, 0, sizeof o);
    o.n = bn; o.R = bR; o.bump = 1.0; o.jitter = bjit; o.seed = bseed;
    b = tbm_obj(&o);
    j = a && b ? obj_join_ex(a, b, share) : NULL;
    free(a);
    free(b);
    return j;
}

/* The surface's curvature energy, integral of k1^2 + k2^2 dA (geometric: the same whatever the
 * parametrisation, so a mesh's net and the net after a Loop step compare), of a net of nf quartic
 * triangles (45 doubles each): by the 7-point rule on a 4 x 4 split of each triangle's domain. */
static double net_curvature_energy(const double *net, int nf) {
    static const double qp[7][3] = {{1.0 / 3, 1.0 / 3, 0.225},
                                    {0.0597158717, 0.4701420641, 0.1323941527}, {0.4701420641, 0.0597158717, 0.1323941527},
                                    {0.4701420641, 0.4701420641, 0.1323941527}, {0.7974269853, 0.1012865073, 0.1259391805},
                                    {0.1012865073, 0.7974269853, 0.1259391805}, {0.1012865073, 0.1012865073, 0.1259391805}};
    const int S = 4;
    double e = 0.0;
    int f, a, b, up, m, c;
    for (f = 0; f < nf; ++f)
        for (a = 0; a < S; ++a)
            for (b = 0; a + b < S; ++b)
                for (up = 0; up < 2; ++up) {
                    /* sub-triangle corners in (u, v) */
                    double c0[2], c1[2], c2[2];
                    if (up && a + b + 1 >= S) continue;
                    if (!up) { c0[0] = a; c0[1] = b; c1[0] = a + 1; c1[1] = b; c2[0] = a; c2[1] = b + 1; }
                    else { c0[0] = a + 1; c0[1] = b; c1[0] = a + 1; c1[1] = b + 1; c2[0] = a; c2[1] = b + 1; }
                    for (m = 0; m < 7; ++m) {
                        const double u = (c0[0] + qp[m][0] * (c1[0] - c0[0]) + qp[m][1] * (c2[0] - c0[0])) / S;
                        const double v = (c0[1] + qp[m][0] * (c1[1] - c0[1]) + qp[m][1] * (c2[1] - c0[1])) / S;
                        double P[3], Pu[3], Pv[3], Puu[3], Puv[3], Pvv[3], n[3], len, E, F, G, L, M, N, H, K, det;
                        bez_eval(net + 45 * (size_t)f, u, v, P, Pu, Pv);
                        bez_eval2(net + 45 * (size_t)f, u, v, Puu, Puv, Pvv);
                        cross(Pu, Pv, n);
                        len = norm3(n);
                        if (!(len > 0.0)) continue;
                        for (c = 0; c < 3; ++c) n[c] /= len;
                        E = Pu[0] * Pu[0] + Pu[1] * Pu[1] + Pu[2] * Pu[2];
                        F = Pu[0] * Pv[0] + Pu[1] * Pv[1] + Pu[2] * Pv[2];
                        G = Pv[0] * Pv[0] + Pv[1] * Pv[1] + Pv[2] * Pv[2];
                        L = Puu[0] * n[0] + Puu[1] * n[1] + Puu[2] * n[2];
                        M = Puv[0] * n[0] + Puv[1] * n[1] + Puv[2] * n[2];
                        N = Pvv[0] * n[0] + Pvv[1] * n[1] + Pvv[2] * n[2];
                        det = E * G - F * F;
                        H = (E * N - 2.0 * F * M + G * L) / (2.0 * det);
                        K = (L * N - M * M) / det;
                        /* dA = |Pu x Pv| du dv; the sub-triangle's (u, v) area is 1 / (2 S^2) */
                        e += qp[m][2] * (4.0 * H * H - 2.0 * K) * len / (2.0 * S * S);
                    }
                }
    return e;
}

/* One coarse-mesh case of test_coarse: t's nets (s from to) on the mesh and after a Loop step,
 * and what sfb__tribezier_build makes of it: `refined` says which is expected. The curvature
 * energies of both are printed, not asserted (what the step removes, waves in the highlight
 * lines, is curvature variation; the energy itself moves by -27 % to +18 %). */
static void coarse_one(sfb_context *ctx, const char *nm, tmesh *t, const sfb_tribezier_options *to, int refined) {
    double *net = NULL, *net4 = NULL;
    sfb__tbz_stats st, st4;
    sfb__level rl;
    sfb__patch_table pt;
    memset(&rl, 0, sizeof rl);
    memset(&pt, 0, sizeof pt);
    memset(&st4, 0, sizeof st4);
    net = net_of(ctx, t, to, 0, &st);
    if (!net || sfb__tribezier_refined_points(ctx, &t->prep, t->m->positions, to, 0, &rl, &net4, &st4) != SFB_SUCCESS ||
        sfb__tribezier_build(ctx, &t->prep, t->m->positions, to, &pt) != SFB_SUCCESS) {
        fail(nm, "not built: %s", sfb_last_error(ctx));
    } else {
        const int np = t->prep.nv + 3 * t->prep.ne + 3 * t->prep.nf;
        const double cover = (double)st.unknowns / ((st.sharp_only ? 1.0 : 2.0) * np);
        const double e0 = net_curvature_energy(net, t->prep.nf), e1 = net_curvature_energy(net4, rl.nf);
        char nb[200];
        printf("  %s: the solve may move %.0f %% of the points; curvature energy %.4g on the mesh, %.4g after a Loop step; "
               "built with %d patches for %d triangles\n",
               nm, 100.0 * cover, e0, e1, pt.npatch, t->prep.nf);
        snprintf(nb, sizeof nb, "%s_%s", nm, refined ? "built_after_a_loop_step" : "built_on_the_mesh");
        check(refined ? pt.npatch == 4 * t->prep.nf && cover > 0.5 : pt.npatch == t->prep.nf && cover < 0.5, nb,
              "%d patches for %d triangles, %.0f %% of the points moved", pt.npatch, t->prep.nf, 100.0 * cover);
        if (!refined && !st.sharp_only) {
            /* asserted: the second pass, which holds the crease near the extraordinary vertex
             * (tbz_mix), leaves the surface about as fair as the one-pass net (measured -0.3 to
             * +0.9 %; at valence 5 tbz_take_second gives it back, which kept gives +8 %; with
             * the crease held in every direction +19 to +25 %) */
            double *one = net_of(ctx, t, to, SFB__TBZ_NO_STRAIGHT, NULL);
            const double e2 = one ? net_curvature_energy(one, t->prep.nf) : 0.0;
            snprintf(nb, sizeof nb, "%s_as_fair_as_one_pass", nm);
            check(one && st.straight == 1 && e0 <= 1.03 * e2, nb, "curvature energy %.4g, one pass %.4g (second passes %d)", e0, e2, st.straight);
            printf("  %s: curvature energy %.4g, one pass %.4g\n", nb, e0, e2);
            sfb__free(ctx, one);
        }
    }
    sfb__patch_table_free(ctx, &pt);
    sfb__free(ctx, net);
    sfb__free(ctx, net4);
    sfb__level_free(ctx, &rl);
}

/* Coarse meshes (TBZ_COVER in src/patch/tribezier.c): where the G1 solve may move over half of a
 * net's points, sfb__tribezier_build takes a Loop step first, and the correction's waves across
 * whole faces go from the highlight lines (the panel's, the box's: looked at, not measured here);
 * a mesh whose extraordinary vertex is a small part of it is built on itself, as before. The panel's kind of disk (two and three
 * rings around a crease through a vertex of valence 4, 5, 7) and the creased box cut into
 * triangles (examples/data/creased_box.obj, sfb_mesh_triangulate) are of the first kind, a disk
 * of five rings of the second. */
static void test_coarse(sfb_context *ctx) {
    static const int vals[3] = {4, 5, 7};
    int vi, R, sh;
    char nm[160];
    for (vi = 0; vi < 3; ++vi)
        for (R = 2; R <= 5; R += R == 3 ? 2 : 1)
            for (sh = 0; sh < 2; ++sh) {
                tbm_opts o;
                tmesh t;
                char *obj;
                sfb_tribezier_options to;
                memset(&o, 0, sizeof o);
                memset(&to, 0, sizeof to);
                o.n = vals[vi]; o.R = R; o.crease_k = vals[vi] / 2; o.sharp = 1.0; o.ridge = 0.5; o.bump = 1.0;
                to.sharpness_set = 1;
                to.sharpness = (float)sh;
                obj = tbm_obj(&o);
                snprintf(nm, sizeof nm, "coarse/valence_%d_rings_%d_s_%d", o.n, R, sh);
                if (!tmesh_load(ctx, obj, &t)) fail(nm, "load");
                else {
                    coarse_one(ctx, nm, &t, &to, R <= 3);
                    tmesh_free(ctx, &t);
                }
                free(obj);
            }
    {
        size_t n;
        char *obj = slurp("examples/data/creased_box.obj", &n);
        sfb_mesh *m = NULL;
        tmesh t;
        memset(&t, 0, sizeof t);
        if (!obj) { skip("coarse/creased_box_triangulated", "examples/data/creased_box.obj not found (run from the repository)"); return; }
        if (sfb_mesh_read_obj(ctx, obj, n, &m) != SFB_SUCCESS || sfb_mesh_triangulate(ctx, m, &t.m, NULL) != SFB_SUCCESS ||
            sfb__level_prepare(ctx, &t.m->base, 1, 0, &t.prep) != SFB_SUCCESS) {
            fail("coarse/creased_box_triangulated", "load: %s", sfb_last_error(ctx));
        } else {
            sfb_tribezier_options to;
            for (sh = 0; sh < 2; ++sh) {
                memset(&to, 0, sizeof to);
                to.sharpness_set = 1;
                to.sharpness = (float)sh;
                snprintf(nm, sizeof nm, "coarse/creased_box_triangulated_s_%d", sh);
                coarse_one(ctx, nm, &t, &to, 1);
            }
        }
        sfb_mesh_destroy(m);
        if (t.m) tmesh_free(ctx, &t);
        free(obj);
    }
}

/* The same on two disks in one mesh: a crease through a valence-5 vertex (its component differs
 * between the nets and must be solved) and an untagged valence-7 vertex (the same system in both:
 * reused). */
static void test_reuse_disks(sfb_context *ctx) {
    tmesh t;
    char *obj;
    double *x = NULL, *y = NULL;
    sfb__tbz_stats sa, sb;
    const char *nm = "sharp_net_reuse_is_exact/crease_disk_and_smooth_disk";
    obj = two_disks(5, 5, 1.0, 0.5, 0.15, 11u, 7, 5, 0.15, 12u, 0);
    memset(&sa, 0, sizeof sa); memset(&sb, 0, sizeof sb);
    if (!obj || !tmesh_load(ctx, obj, &t)) {
        fail(nm, "load");
    } else {
        x = net_of(ctx, &t, NULL, 0, &sa);
        y = net_of(ctx, &t, NULL, SFB__TBZ_NO_REUSE, &sb);
        if (!x || !y) fail(nm, "not built");
        else {
            const int same = memcmp(x, y, 45 * (size_t)t.prep.nf * sizeof(double)) == 0;
            check(same && sa.reused > 0 && sb.reused == 0 && sa.iterations + sa.direct < sb.iterations + sb.direct, nm,
                  "identical %d, components reused %d (without: %d), CGLS iterations %ld vs %ld, direct solves %d vs %d", same, sa.reused,
                  sb.reused, sa.iterations, sb.iterations, sa.direct, sb.direct);
        }
        tmesh_free(ctx, &t);
    }
    sfb__free(ctx, x); sfb__free(ctx, y);
    free(obj);
}

/* The seed-plane fallback is per vertex: one mesh of two creased disks, a crease turning by 60
 * degrees at a regular-lattice vertex of valence 6 (one triangle on one side: our plane makes
 * that triangle's corner degenerate, its two crease tangents opposite) and a straight one through
 * a valence-5 vertex; only the first gets the seed's plane, the second keeps ours and its second
 * pass, and the smooth net is G1 everywhere. */
static void test_partial_fallback(sfb_context *ctx) {
    const char *nm = "partial_fallback/two_creased_disks";
    tbm_opts o;
    char *a, *b, *j = NULL, *a2 = NULL;
    tmesh t;
    int r;
    memset(&o, 0, sizeof o);
    o.n = 6; o.R = 5; o.bump = 2.0; o.seed = 9u;
    a = tbm_obj(&o);
    if (a && (a2 = (char *)malloc(strlen(a) + 64 * (size_t)o.R + 1)) != NULL) {
        size_t len = strlen(a);
        memcpy(a2, a, len + 1);
        for (r = 0; r < o.R; ++r)
            len += (size_t)sprintf(a2 + len, "t crease 2/1/0 %d %d 0.5\nt crease 2/1/0 %d %d 0.5\n", tbm_index(&o, 0, r, 0),
                                   tbm_index(&o, 0, r + 1, 0), tbm_index(&o, 1, r, 0), tbm_index(&o, 1, r + 1, 0));
    }
    memset(&o, 0, sizeof o);
    o.n = 5; o.R = 5; o.crease_k = 2; o.sharp = 0.5; o.ridge = 0.4; o.bump = 2.0; o.seed = 10u;
    b = tbm_obj(&o);
    if (a2 && b) j = obj_join_ex(a2, b, 0);
    if (!j || !tmesh_load(ctx, j, &t)) {
        fail(nm, "load");
    } else {
        sfb_tribezier_options to;
        sfb__tbz_stats st;
        double *net;
        memset(&to, 0, sizeof to);
        to.sharpness_set = 1; to.sharpness = 0.0f;
        net = net_of(ctx, &t, &to, 0, &st);
        if (!net) fail(nm, "not built");
        else {
            const g1_result g = g1_measure(&t.prep, net, 0);
            check(st.fallbacks == 1 && st.seed_vertices == 1 && st.straight == 1 && st.straight_kept_first == 0 && g.jump <= 1e-9 &&
                      g.gap <= 1e-7 * t.diag,
                  nm, "fallbacks %d, vertices with the seed's plane %d, second passes %d (first kept %d), normal jump %.3g rad, gap %.3g",
                  st.fallbacks, st.seed_vertices, st.straight, st.straight_kept_first, g.jump, g.gap);
        }
        sfb__free(ctx, net);
        tmesh_free(ctx, &t);
    }
    free(a); free(a2); free(b); free(j);
}

static void test_refined(sfb_context *ctx, const char *dir) {
    char path[4096], *obj;
    size_t n;
    refined_one(ctx, "touching_evs/triangulated_cube", tri_cube);
    snprintf(path, sizeof path, "%s/spot.obj", dir);
    obj = slurp(path, &n);
    if (!obj) { skip("touching_evs/spot", "spot.obj not found (pass the real-meshes folder)"); return; }
    refined_one(ctx, "touching_evs/spot", obj);
    reuse_one(ctx, "touching_evs/spot", obj);
    sharp_only_one(ctx, "spot_one_loop_step", obj, 256, 1, 0);
    templates_one(ctx, "spot_two_loop_steps", obj, SFB__TBZ_TWO_STEPS, 0);
    free(obj);
    snprintf(path, sizeof path, "%s/teapot.obj", dir);
    obj = slurp(path, &n);
    if (!obj) { skip("templates/teapot_own_net/same_net_as_cgls", "teapot.obj not found (pass the real-meshes folder)"); return; }
    templates_one(ctx, "teapot_own_net", obj, 0, 1);
    {
        /* its open parts (boundary edges and vertices) and split non-manifold vertices, refined
         * twice for the rings alone */
        tmesh t;
        sfb__level rl;
        double *net = NULL;
        sfb__tbz_stats st;
        memset(&rl, 0, sizeof rl);
        if (!tmesh_load(ctx, obj, &t)) fail("refine/teapot_two_loop_steps_rings_as_walked", "load: %s", sfb_last_error(ctx));
        else {
            if (sfb__tribezier_refined_points(ctx, &t.prep, t.m->positions, NULL, SFB__TBZ_TWO_STEPS, &rl, &net, &st) != SFB_SUCCESS)
                fail("refine/teapot_two_loop_steps_rings_as_walked", "not built: %s", sfb_last_error(ctx));
            else {
                int bnd = 0, e;
                for (e = 0; e < rl.ne; ++e) bnd += (rl.etag[e] & SFB__TAG_BOUNDARY) != 0;
                check(bnd > 0, "refine/teapot_two_loop_steps_has_boundary_edges", "%d boundary edges", bnd);
                rings_as_walked(ctx, "refine/teapot_two_loop_steps_rings_as_walked", &rl);
            }
            sfb__free(ctx, net);
            sfb__level_free(ctx, &rl);
            tmesh_free(ctx, &t);
        }
    }
    templates_rejected(ctx, obj);
    sharp_only_one(ctx, "teapot_own_net", obj, 0, 0, 0);
    free(obj);
}

/* Through sfb_surface_eval on every backend: the triangulated cube's surface (its 8 extraordinary
 * vertices one group: built after one Loop step, four patches per triangle) and spot.obj's
 * (groups of up to 73: two steps, sixteen) are G1 across every triangle's edges and match the
 * refined net at the child's or grandchild's (s, t) (sfb__patch_locate's frames, once or twice). */
static void test_backends_refined(const char *dir) {
    char path[4096], *spot;
    size_t sn;
    int b, cs;
    snprintf(path, sizeof path, "%s/spot.obj", dir);
    spot = slurp(path, &sn);
    for (cs = 0; cs < 2; ++cs)
    for (b = 0; b < g_nbe; ++b) {
        const int depth = cs + 1, per = cs ? 16 : 4;
        const char *obj = cs ? spot : tri_cube;
        char nm[160];
        sfb_context *ctx = g_be[b].ctx;
        tmesh t;
        sfb__level rl;
        double *net4 = NULL, worst = 0.0, jump = 0.0;
        sfb_surface *sf = NULL;
        sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
        sfb_patch_info pi;
        int f, q;
        memset(&rl, 0, sizeof rl);
        snprintf(nm, sizeof nm, "%s/touching_evs_eval_is_g1/%s", g_be[b].name, cs ? "spot_sixteen_grandchildren" : "cube_four_children");
        if (!g_be[b].available) { backend_missing(&g_be[b], nm); continue; }
        if (!obj) { skip(nm, "spot.obj not found (pass the real-meshes folder)"); continue; }
        if (!tmesh_load(ctx, obj, &t)) { fail(nm, "load"); continue; }
        sc.flags = SFB_REFINE_PATCHES;
        if (sfb__tribezier_refined_points(ctx, &t.prep, t.m->positions, NULL, cs ? SFB__TBZ_TWO_STEPS : 0, &rl, &net4, NULL) != SFB_SUCCESS ||
            sfb_surface_create(ctx, t.m, &sc, &sf) != SFB_SUCCESS) {
            fail(nm, "%s", sfb_last_error(ctx));
        } else {
            memset(&pi, 0, sizeof pi);
            sfb_surface_patch_info(sf, &pi);
            /* spot: every 7th triangle and edge (the gl and osmesa runs on llvmpipe took 13-18 s
             * each over all of them) */
            for (f = 0; f < t.prep.nf; f += cs ? 7 : 1)
                for (q = 0; q < 12; ++q) {
                    sfb_location loc;
                    float P[3];
                    sfb_eval_output eo;
                    double B[3], du[3], dv[3], u, v, su = 0, sv = 0;
                    int c, child = 0, level, path = 0;
                    memset(&eo, 0, sizeof eo);
                    eo.position = P;
                    loc.face = f; loc.u = (float)(0.03 + 0.08 * q); loc.v = (float)(0.95 - loc.u) * (q % 3) / 2.0f;
                    if (sfb_surface_eval(sf, &loc, 1, &eo) != SFB_SUCCESS) { worst = 1e30; continue; }
                    u = loc.u; v = loc.v;
                    for (level = 0; level < depth; ++level) {
                        if (u >= 0.5) { child = 1; su = 2 * u - 1; sv = 2 * v; }
                        else if (v >= 0.5) { child = 2; su = 2 * u; sv = 2 * v - 1; }
                        else if (u + v < 0.5) { child = 0; su = 2 * u; sv = 2 * v; }
                        else { child = 3; su = 1 - 2 * u; sv = 1 - 2 * v; }
                        path = 4 * path + child;
                        u = su; v = sv;
                    }
                    bez_eval(net4 + 45 * ((size_t)per * f + (size_t)path), su, sv, B, du, dv);
                    for (c = 0; c < 3; ++c) worst = fmax(worst, fabs(B[c] - P[c]));
                }
            jump = eval_edge_jump_every(ctx, sf, &t.prep, 0, cs ? 7 : 1);
            {
                /* the points are stored in float: on spot's small grandchild patches (a net step
                 * of 0.002 on a diagonal of 2.6) that alone makes normal jumps of 1e-4 rad, so
                 * the bound is the jump of the net rounded to float (measured in double), or
                 * 1e-5 rad where that is smaller */
                const size_t np = 45 * (size_t)rl.nf;
                double *rounded = (double *)malloc(np * sizeof(double) + 1), jf = 0.0;
                size_t i;
                if (rounded) {
                    for (i = 0; i < np; ++i) rounded[i] = (double)(float)net4[i];
                    jf = g1_measure(&rl, rounded, 0).jump;
                    free(rounded);
                }
                check(rounded && pi.patches == per * t.prep.nf && pi.max_depth == depth && worst <= 1e-6 * t.diag && jump <= fmax(1e-5, 2.0 * jf), nm,
                      "%d patches for %d triangles (depth %d), position %.3g (diag %.3g), normal jump %.3g rad (of the net in float: %.3g)",
                      pi.patches, t.prep.nf, pi.max_depth, worst, t.diag, jump, jf);
            }
        }
        if (sf) sfb_surface_destroy(sf);
        sfb__free(ctx, net4);
        sfb__level_free(ctx, &rl);
        tmesh_free(ctx, &t);
    }
    free(spot);
}

/* Bad input: clear errors, nothing left allocated (the counting allocator). */
static long g_live;
static int g_fail_next; /* the next allocation fails */
static void *cnt_alloc(size_t n, void *u) {
    void *p;
    (void)u;
    if (g_fail_next) { g_fail_next = 0; return NULL; }
    p = malloc(n);
    if (p) g_live++;
    return p;
}
static void *cnt_realloc(void *p, size_t n, void *u) { (void)u; if (!p) return cnt_alloc(n, u); return realloc(p, n); }
static void cnt_free(void *p, void *u) { (void)u; if (p) { g_live--; free(p); } }

static void bad_one(const char *name, const char *obj, float s, int set, sfb_result want) {
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *m = NULL;
    sfb_surface *sf = NULL;
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
    sfb_result r;
    long before;
    cc.ignore_environment = 1;
    cc.allocator.alloc = cnt_alloc; cc.allocator.realloc = cnt_realloc; cc.allocator.free = cnt_free;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) { fail(name, "context"); return; }
    if (sfb_mesh_read_obj(ctx, obj, strlen(obj), &m) != SFB_SUCCESS) { fail(name, "read: %s", sfb_last_error(ctx)); sfb_context_destroy(ctx); return; }
    before = g_live;
    sc.flags = SFB_REFINE_PATCHES;
    sc.tribezier.sharpness_set = set; sc.tribezier.sharpness = s;
    r = sfb_surface_create(ctx, m, &sc, &sf);
    check(r == want && !sf && g_live == before && (strstr(sfb_last_error(ctx), "tribezier") != NULL || strstr(sfb_last_error(ctx), "triangles") != NULL), name, "result %d (want %d), %ld blocks left, '%s'", (int)r,
          (int)want, g_live - before, sfb_last_error(ctx));
    printf("  %s: %s\n", name, sfb_last_error(ctx));
    if (sf) sfb_surface_destroy(sf);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

static void test_bad_input(void) {
    const char *tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
    bad_one("bad/sharpness_above_1", tri, 1.5f, 1, SFB_INVALID_ARGS);
    bad_one("bad/sharpness_negative", tri, -0.1f, 1, SFB_INVALID_ARGS);
    bad_one("bad/sharpness_nan", tri, (float)NAN, 1, SFB_INVALID_ARGS);
    bad_one("bad/quad", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", 0, 0, SFB_INVALID_TOPOLOGY);
    bad_one("bad/non_manifold_edge", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n", 0, 0, SFB_INVALID_TOPOLOGY);
    /* two triangles that run their edge the same way */
    bad_one("bad/inconsistent_orientation", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nf 1 2 3\nf 1 2 4\n", 0, 0, SFB_INVALID_TOPOLOGY);
    bad_one("bad/degenerate_triangle", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 4 2\n", 0, 0, SFB_INVALID_TOPOLOGY);
}

/* Every backend's sfb_surface_eval against the builder's points, and its normals across edges. */
static void test_backends(void) {
    tbm_opts o;
    char *obj;
    int b;
    memset(&o, 0, sizeof o);
    o.n = 5; o.R = 4; o.crease_k = 2; o.sharp = 0.5; o.ridge = 0.4; o.bump = 1.0; o.jitter = 0.2; o.seed = 9u;
    obj = tbm_obj(&o);
    for (b = 0; b < g_nbe; ++b) {
        char nm[160];
        sfb_context *ctx = g_be[b].ctx;
        tmesh t;
        double *net = NULL, worst = 0.0, jump = 0.0;
        sfb_surface *sf = NULL;
        sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
        int f, q;
        snprintf(nm, sizeof nm, "%s/eval_matches_the_builder_and_is_g1", g_be[b].name);
        if (!g_be[b].available) { backend_missing(&g_be[b], nm); continue; }
        if (!tmesh_load(ctx, obj, &t)) { fail(nm, "load"); continue; }
        net = net_of(ctx, &t, NULL, 0, NULL);
        sc.flags = SFB_REFINE_PATCHES;
        if (!net || sfb_surface_create(ctx, t.m, &sc, &sf) != SFB_SUCCESS) { fail(nm, "%s", sfb_last_error(ctx)); }
        else {
            for (f = 0; f < t.prep.nf; ++f)
                for (q = 0; q < 10; ++q) {
                    sfb_location loc;
                    float P[3];
                    sfb_eval_output eo;
                    double B[3], du[3], dv[3];
                    int c;
                    memset(&eo, 0, sizeof eo);
                    eo.position = P;
                    loc.face = f; loc.u = (float)(0.05 + 0.09 * q); loc.v = (float)(0.9 - loc.u) * 0.5f;
                    if (sfb_surface_eval(sf, &loc, 1, &eo) != SFB_SUCCESS) { worst = 1e30; continue; }
                    bez_eval(net + 45 * (size_t)f, loc.u, loc.v, B, du, dv);
                    for (c = 0; c < 3; ++c) worst = fmax(worst, fabs(B[c] - P[c]));
                }
            /* normals across the untagged interior edges, both faces */
            jump = eval_edge_jump(ctx, sf, &t.prep, 1);
            check(worst <= 1e-6 * t.diag && jump <= 1e-5, nm, "position %.3g (diag %.3g), normal jump %.3g rad", worst, t.diag, jump);
        }
        if (sf) sfb_surface_destroy(sf);
        sfb__free(ctx, net);
        tmesh_free(ctx, &t);
    }
    free(obj);
}

/* The slider (sfb_surface_set_sharpness) on every backend: a surface built once with
 * tribezier.slider at s = 1 and moved to s = 0, 0.3, its tags' s and 1 evaluates (positions and
 * first derivatives, 300 locations) bit for bit as one built afresh with those options and the
 * slider, and within float rounding (2e-7 x diagonal) as one built without it; s = 0 and s = 1
 * differ. Meshes: a creased disk with semi-sharp tags and a hole, joined to an untagged disk (the
 * mesh's own net); the triangulated cube with two tagged edges (extraordinary vertices touching:
 * the net after a Loop step, written straight into the table); a coarse creased disk (the net
 * after a Loop step for coverage). */
static int slider_eval(sfb_surface *sf, int nf, float *P, float *D) {
    /* slider_mesh(0)'s hole: its next face instead */
    const int hole = nf == 180 + 54 ? 40 : -1;
    sfb_location L[300];
    sfb_eval_output eo;
    unsigned seed = 7u;
    int q;
    for (q = 0; q < 300; ++q) {
        float u = (float)tbm_unit(&seed), v = (float)tbm_unit(&seed);
        if (u + v > 1.0f) { u = 1.0f - u; v = 1.0f - v; }
        L[q].face = (int)(tbm_rand(&seed) % (unsigned)nf);
        if (L[q].face == hole) L[q].face++;
        L[q].u = u; L[q].v = v;
    }
    memset(&eo, 0, sizeof eo);
    eo.position = P; eo.du = D; eo.dv = D + 900;
    memset(P, 0, 900 * sizeof(float));
    memset(D, 0, 1800 * sizeof(float));
    return sfb_surface_eval(sf, L, 300, &eo) == SFB_SUCCESS;
}

static char *slider_mesh(int which) {
    tbm_opts o;
    memset(&o, 0, sizeof o);
    if (which == 0) {
        char *j = two_disks(5, 6, 0.5, 0.4, 0.2, 9u, 6, 3, 0.15, 12u, 0), *obj = NULL;
        if (j) {
            obj = (char *)malloc(strlen(j) + 64);
            if (obj) sprintf(obj, "%st hole 1/0/0 40\n", j);
        }
        free(j);
        return obj;
    }
    if (which == 1) {
        char *obj = (char *)malloc(strlen(tri_cube) + 64);
        if (obj) sprintf(obj, "%st crease 2/1/0 0 1 0.3\nt crease 2/1/0 1 2 1\n", tri_cube);
        return obj;
    }
    o.n = 5; o.R = 2; o.crease_k = 2; o.sharp = 0.6; o.ridge = 0.5; o.bump = 1.0;
    return tbm_obj(&o);
}

static void test_slider(void) {
    static const char *names[3] = {"creased_disk_hole_and_untagged_disk", "cube_touching_evs", "coarse_creased_disk"};
    static const float svals[4] = {0.0f, 0.3f, -1.0f, 1.0f}; /* -1: the tags' s (the surface is built with s = 1) */
    int b, w, i;
    for (w = 0; w < 3; ++w) {
        char *obj = slider_mesh(w);
        for (b = 0; b < g_nbe; ++b) {
            char nm[200];
            sfb_context *ctx = g_be[b].ctx;
            sfb_mesh *m = NULL;
            sfb_surface *sl = NULL;
            sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
            float *buf = (float *)malloc(6 * 2700 * sizeof(float));
            float *P0 = buf, *D0 = buf + 900, *P1 = buf + 2700, *D1 = buf + 3600, *P2 = buf + 5400, *D2 = buf + 6300;
            double diag = 0.0, far01 = 0.0;
            int nf = 0, bits_ok = 1, near_ok = 1, evals = 1;
            double worst = 0.0;
            snprintf(nm, sizeof nm, "%s/slider/%s", g_be[b].name, names[w]);
            if (!g_be[b].available) { backend_missing(&g_be[b], nm); free(buf); continue; }
            if (!obj || !buf || sfb_mesh_read_obj(ctx, obj, strlen(obj), &m) != SFB_SUCCESS) { fail(nm, "load: %s", sfb_last_error(ctx)); free(buf); continue; }
            {
                sfb_mesh_desc d;
                sfb_mesh_get_desc(m, &d);
                nf = d.face_count;
                diag = diag_of(d.positions, d.vertex_count);
            }
            sc.flags = SFB_REFINE_PATCHES;
            sc.tribezier.slider = 1;
            sc.tribezier.sharpness_set = 1;
            sc.tribezier.sharpness = 1.0f;
            if (sfb_surface_create(ctx, m, &sc, &sl) != SFB_SUCCESS) { fail(nm, "create: %s", sfb_last_error(ctx)); sfb_mesh_destroy(m); free(buf); continue; }
            for (i = 0; i < 4; ++i) {
                sfb_tribezier_options to;
                sfb_surface *fresh = NULL, *plain = NULL;
                size_t q;
                memset(&to, 0, sizeof to);
                to.sharpness_set = svals[i] >= 0.0f;
                to.sharpness = svals[i] >= 0.0f ? svals[i] : 0.0f;
                sc.tribezier = to;
                sc.tribezier.slider = 1;
                if (sfb_surface_set_sharpness(sl, &to) != SFB_SUCCESS || sfb_surface_create(ctx, m, &sc, &fresh) != SFB_SUCCESS) {
                    fail(nm, "s %g: %s", (double)svals[i], sfb_last_error(ctx));
                    evals = 0;
                    break;
                }
                sc.tribezier.slider = 0;
                if (sfb_surface_create(ctx, m, &sc, &plain) != SFB_SUCCESS) { fail(nm, "plain: %s", sfb_last_error(ctx)); evals = 0; sfb_surface_destroy(fresh); break; }
                evals = evals && slider_eval(sl, nf, P0, D0) && slider_eval(fresh, nf, P1, D1) && slider_eval(plain, nf, P2, D2);
                bits_ok = bits_ok && memcmp(P0, P1, 900 * sizeof(float)) == 0 && memcmp(D0, D1, 1800 * sizeof(float)) == 0;
                for (q = 0; q < 900; ++q) worst = fmax(worst, fabs((double)P0[q] - P2[q]));
                if (i == 0) memcpy(buf + 8100, P0, 900 * sizeof(float)); /* s = 0 kept (after the six arrays) */
                if (i == 3)
                    for (q = 0; q < 900; ++q) far01 = fmax(far01, fabs((double)P0[q] - buf[8100 + q]));
                sfb_surface_destroy(fresh);
                sfb_surface_destroy(plain);
            }
            near_ok = worst <= 2e-7 * diag;
            {
                /* the build's path: the mesh's own net (depth 0), the net after a Loop step (1) */
                static const int depth[3] = {0, 1, 1};
                sfb_patch_info pi;
                memset(&pi, 0, sizeof pi);
                sfb_surface_patch_info(sl, &pi);
                check(evals && bits_ok && near_ok && far01 > 1e-3 * diag && pi.max_depth == depth[w], nm,
                      "evaluated %d, bit for bit as built afresh %d, off the build without the slider by %.3g (diag %.3g), s = 0 to 1 moves %.3g, "
                      "patch depth %d",
                      evals, bits_ok, worst, diag, far01, pi.max_depth);
                printf("  %s: off the build without the slider by %.3g diagonals, s = 0 to 1 moves %.3g diagonals, patch depth %d\n", nm,
                       worst / diag, far01 / diag, pi.max_depth);
            }
            sfb_surface_destroy(sl);
            sfb_mesh_destroy(m);
            free(buf);
        }
        free(obj);
    }
}

/* sfb_surface_set_sharpness's refusals leave the surface as it was (evaluated bit for bit the
 * same) and allocate nothing: a surface built without the slider, a Loop surface, an s outside
 * [0, 1] or NaN, NULL options, an allocation that fails; and the slider's repeated moves leave
 * nothing behind. An analysis workspace that saw the surface before a move gives the picture a
 * fresh analysis gives after it. */
static void test_slider_refusals(void) {
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *m = NULL;
    sfb_surface *sl = NULL, *plain = NULL, *loop = NULL;
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0), lc = sfb_surface_config_init(SFB_SCHEME_LOOP, 0);
    char *obj = slider_mesh(0);
    static float P0[900], D0[1800], P1[900], D1[1800];
    sfb_mesh_desc d;
    long before;
    int k;
    cc.ignore_environment = 1;
    cc.allocator.alloc = cnt_alloc; cc.allocator.realloc = cnt_realloc; cc.allocator.free = cnt_free;
    if (!obj || sfb_context_create(&cc, &ctx) != SFB_SUCCESS) { fail("slider/refusals", "context"); free(obj); return; }
    if (sfb_mesh_read_obj(ctx, obj, strlen(obj), &m) != SFB_SUCCESS) { fail("slider/refusals", "load"); sfb_context_destroy(ctx); free(obj); return; }
    sfb_mesh_get_desc(m, &d);
    sc.flags = lc.flags = SFB_REFINE_PATCHES;
    if (sfb_surface_create(ctx, m, &sc, &plain) != SFB_SUCCESS || sfb_surface_create(ctx, m, &lc, &loop) != SFB_SUCCESS)
        fail("slider/refusals", "create: %s", sfb_last_error(ctx));
    before = g_live; /* after the context's caches (Loop's eigen structures) are made */
    sc.tribezier.slider = 1;
    if (sfb_surface_create(ctx, m, &sc, &sl) != SFB_SUCCESS) fail("slider/refusals", "create: %s", sfb_last_error(ctx));
    if (sl && plain && loop && slider_eval(sl, d.face_count, P0, D0)) {
        static const char *cases[7] = {"not_built_with_the_slider", "loop_surface", "sharpness_above_1", "sharpness_nan", "sharpness_negative",
                                       "null_options", "allocation_fails"};
        static const char *says[7] = {"slider", "not SFB_SCHEME_TRIBEZIER", "not in [0, 1]", "not in [0, 1]", "not in [0, 1]", "NULL", "memory"};
        static const sfb_result want[7] = {SFB_INVALID_ARGS, SFB_INVALID_ARGS, SFB_INVALID_ARGS, SFB_INVALID_ARGS, SFB_INVALID_ARGS, SFB_INVALID_ARGS,
                                           SFB_OUT_OF_MEMORY};
        for (k = 0; k < 7; ++k) {
            sfb_tribezier_options to;
            char nm[120];
            long live;
            sfb_result r;
            memset(&to, 0, sizeof to);
            to.sharpness_set = 1;
            to.sharpness = k == 2 ? 1.5f : k == 3 ? (float)NAN : k == 4 ? -0.25f : 0.5f;
            snprintf(nm, sizeof nm, "slider/refused/%s", cases[k]);
            live = g_live;
            g_fail_next = k == 6;
            r = sfb_surface_set_sharpness(k == 0 ? plain : k == 1 ? loop : sl, k == 5 ? NULL : &to);
            g_fail_next = 0;
            check(r == want[k] && strstr(sfb_last_error(ctx), says[k]) && g_live == live && slider_eval(sl, d.face_count, P1, D1) &&
                      memcmp(P0, P1, sizeof P0) == 0 && memcmp(D0, D1, sizeof D0) == 0,
                  nm, "result %d (want %d), '%s', %ld blocks left", (int)r, (int)want[k], sfb_last_error(ctx), g_live - live);
        }
    } else fail("slider/refusals", "surfaces: %s", sfb_last_error(ctx));
    {
        /* the workspace: an analysis at s = 0.3 with it, the surface moved to s = 1, analysed
         * again with it and without one */
        sfb_analysis_workspace *ws = NULL;
        sfb_analysis a0, a1, a2;
        sfb_analyze_config ac = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
        sfb_tribezier_options to;
        int ok;
        memset(&a0, 0, sizeof a0); memset(&a1, 0, sizeof a1); memset(&a2, 0, sizeof a2);
        memset(&to, 0, sizeof to);
        ac.width = 96; ac.height = 72;
        to.sharpness_set = 1; to.sharpness = 0.3f;
        ok = sl && sfb_analysis_workspace_create(ctx, &ws) == SFB_SUCCESS && sfb_surface_set_sharpness(sl, &to) == SFB_SUCCESS;
        ac.workspace = ws;
        ok = ok && sfb_surface_analyze(sl, &ac, &a0) == SFB_SUCCESS;
        to.sharpness = 1.0f;
        ok = ok && sfb_surface_set_sharpness(sl, &to) == SFB_SUCCESS && sfb_surface_analyze(sl, &ac, &a1) == SFB_SUCCESS;
        ac.workspace = NULL;
        ok = ok && sfb_surface_analyze(sl, &ac, &a2) == SFB_SUCCESS;
        check(ok && memcmp(a1.rgba, a2.rgba, 96 * 72 * 4) == 0 && memcmp(a0.rgba, a1.rgba, 96 * 72 * 4) != 0, "slider/analysis_workspace_sees_the_move",
              "analysed %d, with the workspace as without %d, the move changed the picture %d", ok, ok && !memcmp(a1.rgba, a2.rgba, 96 * 72 * 4),
              ok && memcmp(a0.rgba, a1.rgba, 96 * 72 * 4) != 0);
        sfb_analysis_free(&a0); sfb_analysis_free(&a1); sfb_analysis_free(&a2);
        sfb_analysis_workspace_destroy(ws);
    }
    {
        /* twenty moves leave nothing behind */
        long live = g_live;
        sfb_tribezier_options to;
        memset(&to, 0, sizeof to);
        for (k = 0; k < 20 && sl; ++k) {
            to.sharpness_set = k % 5 != 4;
            to.sharpness = (float)(k % 5) * 0.25f;
            if (sfb_surface_set_sharpness(sl, &to) != SFB_SUCCESS) break;
        }
        check(k == 20 && g_live == live, "slider/moves_leak_nothing", "%d moves, %ld blocks left", k, g_live - live);
    }
    sfb_surface_destroy(sl);
    check(g_live == before, "slider/destroyed_leaves_nothing", "%ld blocks left", g_live - before);
    sfb_surface_destroy(plain); sfb_surface_destroy(loop);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    free(obj);
}

/* The slider per feature (sfb_surface_set_feature_sharpness): on every backend, a surface built
 * with the slider has every other tagged crease (and its corner) given a new value (0.05, 0.35,
 * 0.8, 2.5: clamped to 1; corners 0.9); it must evaluate bit for bit as a surface built afresh
 * from the mesh with those tags (and within 2e-7 diagonals of one built so without the slider,
 * whose points take their s another way), and so again after an override and back
 * (sfb_surface_set_sharpness without it shows the features' values). Meshes: slider_mesh 0 (own
 * net) with a corner tag at its extraordinary vertex, 1 (after a Loop step, touching), two disks
 * through one vertex with a corner there (split in two: its copy's corner mapped back); on ref
 * also teapot.obj with its edges over 40 degrees creased (38 non-manifold vertices split). Then the refusals: an untagged edge, an untagged corner, a negative or NaN value, a
 * vertex out of range, NULL arrays with a count, a surface without the slider: an error, the
 * surface unchanged. */
static int feature_mesh(sfb_context *ctx, int which, const char *dir, sfb_mesh **out) {
    char *obj = NULL;
    size_t n = 0;
    sfb_result r;
    *out = NULL;
    if (which == 2) {
        /* a creased disk and a smooth one through the same centre, a corner there */
        char *j = two_disks(5, 3, 0.4, 0.4, 0.1, 5u, 6, 3, 0.1, 6u, 1);
        obj = j ? (char *)malloc(strlen(j) + 64) : NULL;
        if (obj) sprintf(obj, "%st corner 1/1/0 0 0.2\n", j);
        free(j);
        r = obj ? sfb_mesh_read_obj(ctx, obj, strlen(obj), out) : SFB_OUT_OF_MEMORY;
        free(obj);
        return r == SFB_SUCCESS;
    }
    if (which == 3) {
        char path[1024];
        sfb_mesh *m0 = NULL;
        snprintf(path, sizeof path, "%s/teapot.obj", dir);
        if (!(obj = slurp(path, &n))) return -1;
        r = sfb_mesh_read_obj(ctx, obj, n, &m0);
        if (r == SFB_SUCCESS) r = sfb_mesh_crease_by_angle(ctx, m0, 40.0f, out, NULL);
        sfb_mesh_destroy(m0);
        free(obj);
        return r == SFB_SUCCESS;
    }
    obj = slider_mesh(which);
    if (obj && which == 0) {
        char *c = (char *)malloc(strlen(obj) + 64);
        if (c) sprintf(c, "%st corner 1/1/0 0 0.6\n", obj);
        free(obj);
        obj = c;
    }
    r = obj ? sfb_mesh_read_obj(ctx, obj, strlen(obj), out) : SFB_OUT_OF_MEMORY;
    free(obj);
    return r == SFB_SUCCESS;
}

static void test_feature_slider(const char *dir) {
    static const char *names[4] = {"creased_disk_corner", "cube_touching_evs", "bowtie_split_corner", "teapot_creased_40_degrees"};
    static const float vals[4] = {0.05f, 0.35f, 0.8f, 2.5f};
    int w, b;
    for (w = 0; w < 4; ++w)
        for (b = 0; b < g_nbe; ++b) {
            char nm[200];
            sfb_context *ctx = g_be[b].ctx;
            sfb_mesh *m = NULL, *m2 = NULL;
            sfb_surface *sl = NULL, *fresh = NULL, *plain = NULL;
            sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
            sfb_mesh_desc d, d2;
            int *cv = NULL, nc = 0, i, got, ok = 1, same = 0, same2 = 0;
            double worst = 0.0, diag = 0.0;
            static float P2[900], D2[1800];
            float *csh = NULL, *nsh = NULL, *ksh = NULL;
            static float P0[900], D0[1800], P1[900], D1[1800];
            snprintf(nm, sizeof nm, "%s/feature_slider/%s", g_be[b].name, names[w]);
            if (!g_be[b].available) { backend_missing(&g_be[b], nm); continue; }
            if (w == 3 && g_be[b].kind != SFB_BACKEND_REF) continue; /* the real mesh on ref alone */
            got = feature_mesh(ctx, w, dir, &m);
            if (got < 0) { skip(nm, "teapot.obj not found (pass the real-meshes folder)"); continue; }
            if (!got) { fail(nm, "load: %s", sfb_last_error(ctx)); continue; }
            sfb_mesh_get_desc(m, &d);
            /* every other crease and every corner a new value */
            cv = (int *)malloc(sizeof(int) * 2 * (size_t)(d.crease_count + 1));
            csh = (float *)malloc(sizeof(float) * (size_t)(d.crease_count + 1));
            nsh = (float *)malloc(sizeof(float) * (size_t)(d.crease_count + 1));
            ksh = (float *)malloc(sizeof(float) * (size_t)(d.corner_count + 1));
            if (!cv || !csh || !nsh || !ksh) { fail(nm, "test memory"); ok = 0; }
            for (i = 0; ok && i < d.crease_count; ++i) {
                nsh[i] = d.crease_sharpness[i];
                if (i % 2 == 0) {
                    cv[2 * nc] = d.crease_vertices[2 * i];
                    cv[2 * nc + 1] = d.crease_vertices[2 * i + 1];
                    csh[nc] = vals[(i / 2) % 4];
                    nsh[i] = csh[nc];
                    nc++;
                }
            }
            for (i = 0; ok && i < d.corner_count; ++i) ksh[i] = 0.9f; /* above its creases' mean: the corner's max counts */
            d2 = d;
            d2.crease_sharpness = nsh;
            d2.corner_sharpness = ksh;
            sc.flags = SFB_REFINE_PATCHES;
            sc.tribezier.slider = 1;
            ok = ok && nc > 0 && sfb_surface_create(ctx, m, &sc, &sl) == SFB_SUCCESS && sfb_mesh_create(ctx, &d2, &m2) == SFB_SUCCESS &&
                 sfb_surface_create(ctx, m2, &sc, &fresh) == SFB_SUCCESS;
            /* and the build without the slider, whose s per point comes another way
             * (tbz_vertex_s on the level itself, not the features mapped to the base mesh) */
            sc.tribezier.slider = 0;
            ok = ok && sfb_surface_create(ctx, m2, &sc, &plain) == SFB_SUCCESS;
            diag = diag_of(d.positions, d.vertex_count);
            if (!ok) { fail(nm, "build: %s", sfb_last_error(ctx)); }
            else if (sfb_surface_set_feature_sharpness(sl, nc, cv, csh, d.corner_count, d.corner_vertices, ksh) != SFB_SUCCESS) {
                fail(nm, "set: %s", sfb_last_error(ctx));
            } else {
                sfb_tribezier_options to;
                int moved = 0;
                ok = slider_eval(sl, d.face_count, P0, D0) && slider_eval(fresh, d.face_count, P1, D1) && slider_eval(plain, d.face_count, P2, D2);
                same = ok && !memcmp(P0, P1, sizeof P0) && !memcmp(D0, D1, sizeof D0);
                for (i = 0; i < 900; ++i) worst = fmax(worst, fabs((double)P0[i] - P2[i]));
                memset(&to, 0, sizeof to);
                to.sharpness_set = 1;
                to.sharpness = 0.5f;
                ok = ok && sfb_surface_set_sharpness(sl, &to) == SFB_SUCCESS && slider_eval(sl, d.face_count, P0, D0);
                moved = ok && memcmp(P0, P1, sizeof P0) != 0;
                to.sharpness_set = 0;
                ok = ok && sfb_surface_set_sharpness(sl, &to) == SFB_SUCCESS && slider_eval(sl, d.face_count, P0, D0);
                same2 = ok && !memcmp(P0, P1, sizeof P0) && !memcmp(D0, D1, sizeof D0);
                check(ok && same && moved && same2 && worst <= 2e-7 * diag, nm,
                      "%d creases and %d corners set; bit for bit as built with those tags %d, the override moved it %d, and back %d; "
                      "off the build without the slider by %.3g (diag %.3g)", nc, d.corner_count, same, moved, same2, worst, diag);
                printf("  %s: %d of %d creases and %d corners set\n", nm, nc, d.crease_count, d.corner_count);
            }
            sfb_surface_destroy(sl);
            sfb_surface_destroy(fresh);
            sfb_surface_destroy(plain);
            sfb_mesh_destroy(m);
            sfb_mesh_destroy(m2);
            free(cv); free(csh); free(nsh); free(ksh);
        }
}

static void test_feature_slider_refusals(void) {
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *m = NULL;
    sfb_surface *sl = NULL, *plain = NULL;
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
    static float P0[900], D0[1800], P1[900], D1[1800];
    sfb_mesh_desc d;
    int k;
    cc.ignore_environment = 1;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS || feature_mesh(ctx, 0, NULL, &m) != 1) { fail("feature_slider/refusals", "setup"); sfb_context_destroy(ctx); return; }
    sfb_mesh_get_desc(m, &d);
    sc.flags = SFB_REFINE_PATCHES;
    sc.tribezier.slider = 1;
    if (sfb_surface_create(ctx, m, &sc, &sl) != SFB_SUCCESS) fail("feature_slider/refusals", "create: %s", sfb_last_error(ctx));
    sc.tribezier.slider = 0;
    if (sfb_surface_create(ctx, m, &sc, &plain) != SFB_SUCCESS) fail("feature_slider/refusals", "create: %s", sfb_last_error(ctx));
    if (sl && plain && slider_eval(sl, d.face_count, P0, D0)) {
        /* an untagged edge: the first ring's edge from ray 1 (vertices 0 and 2; rays 0 and 2 are the crease) */
        static const int untagged[2] = {0, 2}, tagged[2] = {0, 1}, corner0[1] = {0}, corner_untagged[1] = {5}, far[1] = {100000};
        static const char *cases[8] = {"untagged_edge", "untagged_corner", "negative", "nan", "vertex_out_of_range", "null_array",
                                       "not_built_with_the_slider", "negative_count"};
        static const char *says[8] = {"not a tagged edge", "not a tagged corner", "not >= 0", "not >= 0", "not a tagged edge", "NULL",
                                      "slider", "negative"};
        static const sfb_result want[8] = {SFB_INVALID_VALUE, SFB_INVALID_VALUE, SFB_INVALID_VALUE, SFB_INVALID_VALUE, SFB_INVALID_VALUE,
                                           SFB_INVALID_ARGS, SFB_INVALID_ARGS, SFB_INVALID_ARGS};
        const float half[1] = {0.5f}, neg[1] = {-0.5f}, nan1[1] = {(float)NAN};
        const int oob[2] = {0, 100000};
        (void)far;
        for (k = 0; k < 8; ++k) {
            char nm[120];
            sfb_result r;
            snprintf(nm, sizeof nm, "feature_slider/refused/%s", cases[k]);
            switch (k) {
            case 0: r = sfb_surface_set_feature_sharpness(sl, 1, untagged, half, 0, NULL, NULL); break;
            case 1: r = sfb_surface_set_feature_sharpness(sl, 1, tagged, half, 1, corner_untagged, half); break;
            case 2: r = sfb_surface_set_feature_sharpness(sl, 1, tagged, neg, 0, NULL, NULL); break;
            case 3: r = sfb_surface_set_feature_sharpness(sl, 0, NULL, NULL, 1, corner0, nan1); break;
            case 4: r = sfb_surface_set_feature_sharpness(sl, 1, oob, half, 0, NULL, NULL); break;
            case 5: r = sfb_surface_set_feature_sharpness(sl, 1, NULL, half, 0, NULL, NULL); break;
            case 6: r = sfb_surface_set_feature_sharpness(plain, 1, tagged, half, 0, NULL, NULL); break;
            default: r = sfb_surface_set_feature_sharpness(sl, -1, tagged, half, 0, NULL, NULL); break;
            }
            check(r == want[k] && strstr(sfb_last_error(ctx), says[k]) && slider_eval(sl, d.face_count, P1, D1) && !memcmp(P0, P1, sizeof P0) &&
                      !memcmp(D0, D1, sizeof D0),
                  nm, "result %d (want %d), '%s'", (int)r, (int)want[k], sfb_last_error(ctx));
        }
        {
            /* a crease at 0 is still a feature: accepted, and the surface moves */
            const float zero[1] = {0.0f};
            check(sfb_surface_set_feature_sharpness(sl, 1, tagged, zero, 0, NULL, NULL) == SFB_SUCCESS && slider_eval(sl, d.face_count, P1, D1) &&
                      memcmp(P0, P1, sizeof P0) != 0,
                  "feature_slider/a_crease_at_0_is_accepted", "%s", sfb_last_error(ctx));
        }
    } else fail("feature_slider/refusals", "surfaces: %s", sfb_last_error(ctx));
    sfb_surface_destroy(sl);
    sfb_surface_destroy(plain);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}

/* The constraint regions are solved in blocks on the backend's threads (tbz_solve_todo), and a
 * large region with each iteration's loops on them: the nets must be bit for bit those of a
 * context that lends no threads (ref, one thread), the smooth and the sharp (crease tags on every
 * 64th face's first edge, so the sharp net has its own regions) net after one Loop step of a real
 * mesh, spot.obj: its many regions fill several blocks, and where its extraordinary vertices are
 * close their regions merge into large ones (SFB__TBZ_PAR_SMALL: those of 1024 unknowns or more
 * are solved with their loops on the threads, asserted: at least one). */
static void test_threads(const char *dir, const char *mesh) {
    static const sfb_backend_kind kinds[2] = {SFB_BACKEND_REF, SFB_BACKEND_SIMD};
    sfb_context *c[2] = {NULL, NULL};
    double *net[2][2] = {{NULL, NULL}, {NULL, NULL}};
    sfb__level rl[2][2];
    sfb__tbz_stats st[2][2];
    char path[1024], name[96], named[128], *obj, *tagged = NULL;
    size_t n;
    int k, j, ok = 1, ntags = 0;
    snprintf(path, sizeof path, "%s/%s.obj", dir, mesh);
    snprintf(name, sizeof name, "threads/net_bit_for_bit_%s", mesh);
    obj = slurp(path, &n);
    if (!obj) { skip(name, "the mesh was not found (pass the real-meshes folder)"); return; }
    memset(rl, 0, sizeof rl);
    memset(st, 0, sizeof st);
    tagged = obj_tag_creases(obj, 64, 0.5, &ntags);
    if (!tagged || ntags == 0) { fail(name, "no crease tags"); free(obj); free(tagged); return; }
    for (k = 0; k < 2; ++k) {
        sfb_context_config cc = sfb_context_config_init();
        cc.ignore_environment = 1;
        cc.backends = &kinds[k];
        cc.backend_count = 1;
        cc.threads = k ? 4 : 1;
        if (sfb_context_create(&cc, &c[k]) != SFB_SUCCESS) {
            if (k) skip(name, "no simd backend here");
            else fail(name, "no ref context");
            ok = 0;
            break;
        }
        for (j = 0; j < 2; ++j) {
            tmesh t;
            if (!tmesh_load(c[k], j ? tagged : obj, &t)) { fail(name, "load: %s", sfb_last_error(c[k])); ok = 0; continue; }
            if (sfb__tribezier_refined_points(c[k], &t.prep, t.m->positions, NULL, SFB__TBZ_PAR_SMALL, &rl[k][j], &net[k][j], &st[k][j]) != SFB_SUCCESS) {
                fail(name, "build: %s", sfb_last_error(c[k]));
                ok = 0;
            }
            tmesh_free(c[k], &t);
        }
    }
    if (ok) {
        for (j = 0; j < 2; ++j) {
            const size_t nd = (size_t)rl[0][j].nf * 45;
            const int same = rl[0][j].nf == rl[1][j].nf && memcmp(net[0][j], net[1][j], nd * sizeof(double)) == 0;
            snprintf(named, sizeof named, "%s%s", name, j ? "_creased" : "");
            check(same && st[0][j].iterations == st[1][j].iterations && st[0][j].iterations > 0 && st[1][j].large > 0,
                  named, "%d child faces, %ld CGLS iterations on one thread, %ld on four, %d large regions; nets %s", rl[0][j].nf,
                  st[0][j].iterations, st[1][j].iterations, st[1][j].large, same ? "equal" : "differ");
        }
    }
    for (k = 0; k < 2; ++k) {
        for (j = 0; j < 2; ++j) {
            if (c[k]) { sfb__free(c[k], net[k][j]); sfb__level_free(c[k], &rl[k][j]); }
        }
        sfb_context_destroy(c[k]);
    }
    free(obj);
    free(tagged);
}

/* Progress and cancellation of the build (stage "tribezier"): a recorder counts the reports,
 * checks that they never fall and that the last is 1, and cancels at report `cancel_at` (0:
 * never). */
typedef struct tbz_rec {
    int count, cancel_at, falls;
    float first, last;
} tbz_rec;
static int tbz_rec_cb(float done, const char *stage, void *user) {
    tbz_rec *R = (tbz_rec *)user;
    if (strcmp(stage, "tribezier") != 0) return 0;
    if (R->count == 0) R->first = done;
    else if (done < R->last) R->falls++;
    R->last = done;
    return ++R->count == R->cancel_at;
}
/* One build of obj on a ref context with the recorder (cancel_at as given); internal: through
 * sfb__tribezier_refined_points with SFB__TBZ_PAR_SMALL (so that the reports inside a large
 * component's CGLS iterations come too), else sfb_surface_create. Returns the result; made: a
 * net or surface came back; says_cancelled: the context's last error says so. */
static sfb_result tbz_rec_build(const char *obj, int internal, tbz_rec *R, int *made, int *says_cancelled) {
    static const sfb_backend_kind ref = SFB_BACKEND_REF;
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_result r = SFB_NO_BACKEND; /* no ref context */
    *made = 0;
    *says_cancelled = 0;
    cc.ignore_environment = 1;
    cc.backends = &ref;
    cc.backend_count = 1;
    cc.progress.func = tbz_rec_cb;
    cc.progress.user = R;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) return r;
    if (internal) {
        tmesh t;
        sfb__level rl;
        double *net = NULL;
        if (tmesh_load(ctx, obj, &t)) {
            r = sfb__tribezier_refined_points(ctx, &t.prep, t.m->positions, NULL, SFB__TBZ_PAR_SMALL, &rl, &net, NULL);
            *made = net != NULL;
            *says_cancelled = strstr(sfb_last_error(ctx), "cancelled") != NULL;
            if (r == SFB_SUCCESS) sfb__level_free(ctx, &rl);
            sfb__free(ctx, net);
        }
        tmesh_free(ctx, &t);
    } else {
        sfb_mesh *m = NULL;
        sfb_surface *sf = NULL;
        sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
        sc.flags = SFB_REFINE_PATCHES;
        if (sfb_mesh_read_obj(ctx, obj, strlen(obj), &m) == SFB_SUCCESS) {
            r = sfb_surface_create(ctx, m, &sc, &sf);
            *made = sf != NULL;
            *says_cancelled = strstr(sfb_last_error(ctx), "cancelled") != NULL;
        }
        sfb_surface_destroy(sf);
        sfb_mesh_destroy(m);
    }
    sfb_context_destroy(ctx);
    return r;
}
/* Builds on spot.obj (after one Loop step: its regions' CGLS on the threads' path with
 * SFB__TBZ_PAR_SMALL) and on a creased disk (the mesh's own smooth and sharp nets): the reports
 * rise to 1; a cancel at the first report, one in the middle and the last gives SFB_CANCELLED and
 * nothing made (what the build allocated is freed: the sanitizer run checks it). */
static void test_progress(const char *dir) {
    char path[1024], *spot;
    size_t n;
    int c, made, said;
    tbm_opts o;
    char *disk;
    memset(&o, 0, sizeof o);
    o.n = 5; o.R = 4; o.crease_k = 2; o.sharp = 0.5; o.ridge = 0.5; o.bump = 1.0;
    disk = tbm_obj(&o);
    snprintf(path, sizeof path, "%s/spot.obj", dir);
    spot = slurp(path, &n);
    for (c = 0; c < 3; ++c) {
        const char *obj = c == 2 ? disk : spot, *what = c == 0 ? "spot_surface" : c == 1 ? "spot_refined_net_large_path" : "creased_disk_surface";
        char name[128];
        tbz_rec R;
        sfb_result r;
        int k;
        snprintf(name, sizeof name, "progress/%s/rises_to_1", what);
        if (!obj) { skip(name, "spot.obj not found (pass the real-meshes folder)"); continue; }
        memset(&R, 0, sizeof R);
        r = tbz_rec_build(obj, c == 1, &R, &made, &said);
        check(r == SFB_SUCCESS && made && R.count >= 3 && R.falls == 0 && R.first == 0.0f && (c == 1 || R.last == 1.0f) && R.last > 0.9f, name,
              "%s, %d reports from %g to %g, %d falls", sfb_result_string(r), R.count, R.first, R.last, R.falls);
        for (k = 0; k < 3 && R.count >= 3; ++k) {
            const int at = k == 0 ? 1 : k == 1 ? R.count / 2 : R.count;
            tbz_rec C;
            memset(&C, 0, sizeof C);
            C.cancel_at = at;
            snprintf(name, sizeof name, "progress/%s/cancel_at_report_%d_of_%d", what, at, R.count);
            r = tbz_rec_build(obj, c == 1, &C, &made, &said);
            check(r == SFB_CANCELLED && !made && said && C.count == at, name, "%s, %d reports, %s", sfb_result_string(r), C.count,
                  made ? "made" : "nothing made");
        }
    }
    free(spot);
    free(disk);
}

int main(int argc, char **argv) {
    sfb_context *ctx = NULL;
    sfb_context_config cc = sfb_context_config_init();
    (void)argc; (void)argv;
    cc.ignore_environment = 1;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) { printf("no context\n"); return 1; }
    test_g1_disks(ctx);
    test_g1_closed(ctx);
    test_regular_is_loop(ctx);
    test_creases(ctx);
    test_crease_evs(ctx);
    test_corner_only(ctx);
    test_undulation(ctx);
    test_coarse(ctx);
    test_reuse_disks(ctx);
    test_partial_fallback(ctx);
    test_bad_input();
    {
        /* a real mesh whose extraordinary vertices of different valences touch: there the
         * constraints have no exact solution and the least-squares point is near-G1 (asserted
         * 1e-2 rad, printed) */
        const char *dir = argc > 1 ? argv[1] : "../shared/peers/real-meshes";
        char path[1024];
        size_t n;
        char *obj;
        snprintf(path, sizeof path, "%s/spot.obj", dir);
        obj = slurp(path, &n);
        if (!obj) skip("g1_real_mesh_spot_near_g1", "spot.obj not found (pass the real-meshes folder)");
        else { g1_one(ctx, "g1_real_mesh_spot_near_g1", obj, 1e-2); free(obj); }
        test_refined(ctx, dir);
        test_nonmanifold_vertices(ctx, dir);
        test_threads(dir, "spot");
        test_progress(dir);
    }
    sfb_context_destroy(ctx);
    if (!probe_backends()) return 1;
    test_backends();
    test_backends_refined(argc > 1 ? argv[1] : "../shared/peers/real-meshes");
    test_slider();
    test_slider_refusals();
    test_feature_slider(argc > 1 ? argv[1] : "../shared/peers/real-meshes");
    test_feature_slider_refusals();
    return close_tests();
}
