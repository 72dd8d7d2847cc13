/* surfblend: unit tests for the subdivision rules (Catmull-Clark, Loop, bilinear,
 * creases, corners, boundaries, limit masks, face-varying UVs).
 *
 * Every expected value below is computed directly from the textbook (OpenSubdiv 3.5)
 * formulas with explicit arithmetic on the base coordinates, or written as a literal
 * derived by hand. The library is never used to produce an expected value, except for
 * the limit tests, where the limit masks are applied to the level-1 positions that the
 * library returns (the masks are what is being tested there).
 *
 * Refined vertex order (guaranteed by the library and relied on below):
 *   Catmull-Clark / bilinear, one level:
 *     [0, nv)             one child per base vertex, same order as the base vertices
 *     [nv, nv+nf)         one face point per base face, face order
 *     [nv+nf, nv+nf+ne)   one edge point per base edge, edge order
 *   Loop, one level:
 *     [0, nv)             vertex children
 *     [nv, nv+ne)         edge points
 *   Base edge order: walk the faces in order; face f contributes its edges
 *   i = (v_i, v_{i+1 mod n}) in order; an edge takes the next index the first time it
 *   is seen (edge_index() below implements exactly this).
 *   Child faces (consecutive per parent face, parent face order):
 *     Catmull-Clark face (v0..v_{n-1}), corner i: (V_i', E_i, F, E_{i-1}) with E_i the
 *     edge point of (v_i, v_{i+1}) and F the face point.
 *     Loop triangle (v0,v1,v2): (V_i', E_i, E_{i-1}) for i = 0,1,2, then (E_0, E_1, E_2).
 *
 * Sharpness >= 10 is infinite; boundary edges are infinitely sharp.
 */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

#define TOL 1e-5
#define PI 3.14159265358979323846
#define INF_SHARP 10.0f

/* ------------------------------------------------------------------------- */
/* small vector helpers (double precision)                                    */

typedef struct { double x, y, z; } v3;

static v3 V(double x, double y, double z) { v3 r; r.x = x; r.y = y; r.z = z; return r; }
static v3 vadd(v3 a, v3 b) { return V(a.x + b.x, a.y + b.y, a.z + b.z); }
static v3 vsub(v3 a, v3 b) { return V(a.x - b.x, a.y - b.y, a.z - b.z); }
static v3 vmul(v3 a, double s) { return V(a.x * s, a.y * s, a.z * s); }
static double vdist(v3 a, v3 b) { v3 d = vsub(a, b); return sqrt(d.x * d.x + d.y * d.y + d.z * d.z); }
/* w*a + (1-w)*b */
static v3 vblend(double w, v3 a, v3 b) { return vadd(vmul(a, w), vmul(b, 1.0 - w)); }

/* base position i of an xyz float array */
static v3 P(const float *pos, int i) { return V(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]); }

/* average of the listed points */
static v3 avg_idx(const float *pos, int n, const int *idx)
{
    v3 s = V(0, 0, 0);
    for (int i = 0; i < n; ++i) s = vadd(s, P(pos, idx[i]));
    return vmul(s, 1.0 / n);
}

static v3 sum_pts(int n, const v3 *p)
{
    v3 s = V(0, 0, 0);
    for (int i = 0; i < n; ++i) s = vadd(s, p[i]);
    return s;
}

static v3 midpoint(v3 a, v3 b) { return vmul(vadd(a, b), 0.5); }

/* Catmull-Clark smooth edge point: 1/4(v0+v1) + 1/4(F0+F1) */
static v3 cc_edge(v3 a, v3 b, v3 f0, v3 f1)
{
    return vadd(vmul(vadd(a, b), 0.25), vmul(vadd(f0, f1), 0.25));
}

/* Catmull-Clark smooth vertex point, interior valence n:
 * (n-2)/n v + 1/n^2 sum(edge neighbours) + 1/n^2 sum(face points) */
static v3 cc_vertex(v3 v, int n, const v3 *nbrs, const v3 *fpts)
{
    double nn = (double)n * n;
    return vadd(vmul(v, (n - 2.0) / n),
                vadd(vmul(sum_pts(n, nbrs), 1.0 / nn), vmul(sum_pts(n, fpts), 1.0 / nn)));
}

/* crease vertex: 3/4 v + 1/8 (a + b) */
static v3 crease_vertex(v3 v, v3 a, v3 b) { return vadd(vmul(v, 0.75), vmul(vadd(a, b), 0.125)); }

/* Loop smooth vertex of valence n */
static v3 loop_vertex(v3 v, int n, const v3 *nbrs)
{
    double beta = 0.375 + 0.25 * cos(2.0 * PI / n);
    double w = (0.625 - beta * beta) / n;
    return vadd(vmul(v, 1.0 - n * w), vmul(sum_pts(n, nbrs), w));
}

/* Loop smooth edge: 3/8(v0+v1) + 1/8(o0+o1) */
static v3 loop_edge(v3 a, v3 b, v3 o0, v3 o1)
{
    return vadd(vmul(vadd(a, b), 0.375), vmul(vadd(o0, o1), 0.125));
}

/* ------------------------------------------------------------------------- */
/* topology order helper: the documented base edge order                      */

static int edge_index(int nf, const int *sizes, const int *fv, int a, int b)
{
    int seen[512][2];
    int ne = 0, off = 0;
    for (int f = 0; f < nf; ++f) {
        int n = sizes[f];
        for (int i = 0; i < n; ++i) {
            int p = fv[off + i], q = fv[off + (i + 1) % n];
            int found = -1;
            for (int e = 0; e < ne; ++e)
                if ((seen[e][0] == p && seen[e][1] == q) || (seen[e][0] == q && seen[e][1] == p)) {
                    found = e;
                    break;
                }
            if (found < 0) {
                cr_assert_lt(ne, 512);
                seen[ne][0] = p;
                seen[ne][1] = q;
                found = ne++;
            }
            if ((p == a && q == b) || (p == b && q == a)) return found;
        }
        off += n;
    }
    cr_assert_fail("edge (%d,%d) is not an edge of the test mesh", a, b);
    return -1;
}

/* ------------------------------------------------------------------------- */
/* running the library                                                        */

typedef struct run {
    sfb_context *ctx;
    sfb_mesh *mesh;
    sfb_surface *surf;
    sfb_mesh_data data;
} run;

static void run_refine(run *r, const sfb_mesh_desc *d, sfb_scheme scheme, int level, unsigned flags)
{
    memset(r, 0, sizeof *r);
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    sfb_result res = sfb_context_create(&cc, &r->ctx);
    cr_assert_eq(res, SFB_SUCCESS, "context: %s", sfb_result_string(res));
    res = sfb_mesh_create(r->ctx, d, &r->mesh);
    cr_assert_eq(res, SFB_SUCCESS, "mesh: %s: %s", sfb_result_string(res), sfb_last_error(r->ctx));
    sfb_surface_config sc = sfb_surface_config_init(scheme, level);
    sc.flags = flags;
    res = sfb_surface_create(r->ctx, r->mesh, &sc, &r->surf);
    cr_assert_eq(res, SFB_SUCCESS, "surface: %s: %s", sfb_result_string(res), sfb_last_error(r->ctx));
    res = sfb_surface_refine(r->surf, &r->data);
    cr_assert_eq(res, SFB_SUCCESS, "refine: %s: %s", sfb_result_string(res), sfb_last_error(r->ctx));
}

static void run_free(run *r)
{
    sfb_mesh_data_free(&r->data);
    sfb_surface_destroy(r->surf);
    sfb_mesh_destroy(r->mesh);
    sfb_context_destroy(r->ctx);
    memset(r, 0, sizeof *r);
}

static v3 out_pt(const float *arr, int i) { return V(arr[3 * i], arr[3 * i + 1], arr[3 * i + 2]); }

static void check_vec(const char *what, int idx, const float *arr, v3 e)
{
    v3 a = out_pt(arr, idx);
    cr_expect(fabs(a.x - e.x) < TOL && fabs(a.y - e.y) < TOL && fabs(a.z - e.z) < TOL,
              "%s (refined vertex %d): expected (%.7f, %.7f, %.7f), got (%.7f, %.7f, %.7f)",
              what, idx, e.x, e.y, e.z, a.x, a.y, a.z);
}

static void check_pt(const sfb_mesh_data *d, const char *what, int idx, v3 e)
{
    cr_assert_lt(idx, d->vertex_count, "%s: index %d out of range (%d vertices)", what, idx, d->vertex_count);
    check_vec(what, idx, d->positions, e);
}

/* remaining sharpness of refined edge (a,b): 0 when not listed */
static float refined_sharpness(const sfb_mesh_data *d, int a, int b, int *found)
{
    *found = 0;
    for (int i = 0; i < d->crease_count; ++i) {
        int p = d->crease_vertices[2 * i], q = d->crease_vertices[2 * i + 1];
        if ((p == a && q == b) || (p == b && q == a)) {
            *found = 1;
            return d->crease_sharpness[i];
        }
    }
    return 0.0f;
}

static void check_face(const sfb_mesh_data *d, int face, int n, const int *expect)
{
    cr_assert_lt(face, d->face_count);
    int off = 0;
    for (int f = 0; f < face; ++f) off += d->face_sizes[f];
    cr_assert_eq(d->face_sizes[face], n, "refined face %d: size %d, expected %d", face, d->face_sizes[face], n);
    for (int i = 0; i < n; ++i)
        cr_expect_eq(d->face_vertices[off + i], expect[i], "refined face %d corner %d: vertex %d, expected %d",
                     face, i, d->face_vertices[off + i], expect[i]);
}

static int face_offset(const sfb_mesh_data *d, int face)
{
    int off = 0;
    for (int f = 0; f < face; ++f) off += d->face_sizes[f];
    return off;
}

/* ------------------------------------------------------------------------- */
/* test meshes                                                                */

/* A closed cube with every vertex moved off the unit cube so that all weights matter.
 *   faces: f0 bottom (0,3,2,1), f1 top (4,5,6,7), f2 front (0,1,5,4),
 *          f3 right (1,2,6,5), f4 back (2,3,7,6), f5 left (3,0,4,7)   (outward)
 *   edges in documented order:
 *     e0 (0,3) e1 (3,2) e2 (2,1) e3 (1,0) e4 (4,5) e5 (5,6) e6 (6,7) e7 (7,4)
 *     e8 (1,5) e9 (4,0) e10 (2,6) e11 (3,7)
 *   level 1: vertices 0..7, face points 8..13, edge points 14..25 (14 + e). */
static const float cube_pos[24] = {
    -0.10f, 0.05f, -0.20f, /* 0 */
    1.00f, -0.10f, 0.10f,  /* 1 */
    1.10f, 1.00f, -0.05f,  /* 2 */
    0.00f, 0.90f, 0.00f,   /* 3 */
    0.05f, -0.05f, 1.00f,  /* 4 */
    0.90f, 0.10f, 1.10f,   /* 5 */
    1.20f, 1.10f, 1.30f,   /* 6 */
    -0.15f, 1.05f, 0.95f,  /* 7 */
};
static const float unit_cube_pos[24] = {
    0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1,
};
static const int cube_sizes[6] = { 4, 4, 4, 4, 4, 4 };
static const int cube_fv[24] = {
    0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7,
};
enum { CUBE_NV = 8, CUBE_NF = 6, CUBE_FP = 8, CUBE_EP = 14 };

static void cube_desc(sfb_mesh_desc *d, const float *pos)
{
    memset(d, 0, sizeof *d);
    d->vertex_count = 8;
    d->positions = pos;
    d->face_count = 6;
    d->face_sizes = cube_sizes;
    d->face_vertices = cube_fv;
}

static int cube_e(int a, int b) { return CUBE_EP + edge_index(6, cube_sizes, cube_fv, a, b); }
static v3 cube_F(const float *pos, int f) { return avg_idx(pos, 4, cube_fv + 4 * f); }

/* smooth Catmull-Clark vertex points of the cube (all valence 3), from the face lists */
static v3 cube_smooth_vertex(const float *pos, int v)
{
    /* neighbours and incident faces, written out by hand */
    static const int nb[8][3] = {
        { 1, 3, 4 }, { 0, 2, 5 }, { 1, 3, 6 }, { 0, 2, 7 }, { 0, 5, 7 }, { 1, 4, 6 }, { 2, 5, 7 }, { 3, 4, 6 },
    };
    static const int fc[8][3] = {
        { 0, 2, 5 }, { 0, 2, 3 }, { 0, 3, 4 }, { 0, 4, 5 }, { 1, 2, 5 }, { 1, 2, 3 }, { 1, 3, 4 }, { 1, 4, 5 },
    };
    v3 n[3], f[3];
    for (int i = 0; i < 3; ++i) {
        n[i] = P(pos, nb[v][i]);
        f[i] = cube_F(pos, fc[v][i]);
    }
    return cc_vertex(P(pos, v), 3, n, f);
}

/* smooth Catmull-Clark edge point of the cube edge (a,b) between faces fa and fb */
static v3 cube_smooth_edge(const float *pos, int a, int b, int fa, int fb)
{
    return cc_edge(P(pos, a), P(pos, b), cube_F(pos, fa), cube_F(pos, fb));
}

/* ========================================================================= */
/* Catmull-Clark smooth                                                       */

Test(catmark_smooth, unit_cube_literals)
{
    sfb_mesh_desc d;
    cube_desc(&d, unit_cube_pos);
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    cr_assert_eq(r.data.vertex_count, 8 + 6 + 12);
    cr_assert_eq(r.data.face_count, 24);
    /* vertex 0 at the origin, valence 3:
     *   1/3*(0,0,0) + 1/9*((1,0,0)+(0,1,0)+(0,0,1)) + 1/9*((.5,.5,0)+(.5,0,.5)+(0,.5,.5))
     *   = (1/9,1/9,1/9) + (1/9,1/9,1/9) = (2/9, 2/9, 2/9) */
    check_pt(&r.data, "unit cube vertex 0", 0, V(2.0 / 9, 2.0 / 9, 2.0 / 9));
    /* vertex 6 at (1,1,1): by symmetry 1 - 2/9 = 7/9 */
    check_pt(&r.data, "unit cube vertex 6", 6, V(7.0 / 9, 7.0 / 9, 7.0 / 9));
    /* face point of f0 (bottom) = (0.5, 0.5, 0) */
    check_pt(&r.data, "unit cube face point f0", CUBE_FP + 0, V(0.5, 0.5, 0));
    /* face point of f1 (top) = (0.5, 0.5, 1) */
    check_pt(&r.data, "unit cube face point f1", CUBE_FP + 1, V(0.5, 0.5, 1));
    /* edge (0,1) = e3 -> vertex 17: 1/4((0,0,0)+(1,0,0)) + 1/4((.5,.5,0)+(.5,0,.5)) = (0.5, 0.125, 0.125) */
    check_pt(&r.data, "unit cube edge (0,1)", 17, V(0.5, 0.125, 0.125));
    /* edge (2,6) = e10 -> vertex 24, between right (1,.5,.5) and back (.5,1,.5):
     *   1/4((1,1,0)+(1,1,1)) + 1/4((1,.5,.5)+(.5,1,.5)) = (.5,.5,.25)+(.375,.375,.25) = (0.875, 0.875, 0.5) */
    check_pt(&r.data, "unit cube edge (2,6)", 24, V(0.875, 0.875, 0.5));
    run_free(&r);
}

Test(catmark_smooth, perturbed_cube)
{
    const float *p = cube_pos;
    sfb_mesh_desc d;
    cube_desc(&d, p);
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    cr_assert_eq(r.data.vertex_count, 26);

    /* face points: averages of the four corners */
    for (int f = 0; f < 6; ++f) {
        char what[64];
        snprintf(what, sizeof what, "face point f%d", f);
        check_pt(&r.data, what, CUBE_FP + f, cube_F(p, f));
    }
    /* literal for f0 (0,3,2,1): x = (-0.1+0+1.1+1)/4 = 0.5, y = (0.05+0.9+1-0.1)/4 = 0.4625,
     * z = (-0.2+0-0.05+0.1)/4 = -0.0375 */
    check_pt(&r.data, "face point f0 literal", CUBE_FP + 0, V(0.5, 0.4625, -0.0375));

    /* vertex points (valence 3): 1/3 v + 1/9 sum(nbrs) + 1/9 sum(face points) */
    {
        v3 n[3] = { P(p, 1), P(p, 3), P(p, 4) };
        v3 f[3] = { cube_F(p, 0), cube_F(p, 2), cube_F(p, 5) };
        check_pt(&r.data, "vertex 0 (valence 3)", 0, cc_vertex(P(p, 0), 3, n, f));
    }
    for (int v = 0; v < 8; ++v) {
        char what[64];
        snprintf(what, sizeof what, "vertex %d (valence 3)", v);
        check_pt(&r.data, what, v, cube_smooth_vertex(p, v));
    }
    /* edge points: e3 (0,1) between f0 and f2, e10 (2,6) between f3 and f4, e7 (7,4) between f1 and f5 */
    cr_assert_eq(cube_e(0, 1), 17);
    check_pt(&r.data, "edge (0,1)", cube_e(0, 1), cube_smooth_edge(p, 0, 1, 0, 2));
    check_pt(&r.data, "edge (2,6)", cube_e(2, 6), cube_smooth_edge(p, 2, 6, 3, 4));
    check_pt(&r.data, "edge (7,4)", cube_e(7, 4), cube_smooth_edge(p, 7, 4, 1, 5));
    check_pt(&r.data, "edge (3,7)", cube_e(3, 7), cube_smooth_edge(p, 3, 7, 4, 5));
    run_free(&r);
}

Test(catmark_smooth, cube_child_faces)
{
    sfb_mesh_desc d;
    cube_desc(&d, cube_pos);
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    cr_assert_eq(r.data.face_count, 24);
    cr_assert_eq(r.data.face_vertex_count, 96);
    for (int f = 0; f < 24; ++f) cr_expect_eq(r.data.face_sizes[f], 4);
    /* f0 = (0,3,2,1): E0 = (0,3) -> 14, E1 = (3,2) -> 15, E2 = (2,1) -> 16, E3 = (1,0) -> 17, F = 8 */
    const int c0[4] = { 0, 14, 8, 17 }; /* (V0', E0, F, E3) */
    const int c1[4] = { 3, 15, 8, 14 }; /* (V3', E1, F, E0) */
    const int c2[4] = { 2, 16, 8, 15 };
    const int c3[4] = { 1, 17, 8, 16 };
    check_face(&r.data, 0, 4, c0);
    check_face(&r.data, 1, 4, c1);
    check_face(&r.data, 2, 4, c2);
    check_face(&r.data, 3, 4, c3);
    /* f2 = (0,1,5,4): E0 = (0,1) -> 17, E1 = (1,5) -> 22, E2 = (5,4) -> 18, E3 = (4,0) -> 23, F = 10 */
    const int f2c0[4] = { 0, 17, 10, 23 };
    const int f2c2[4] = { 5, 18, 10, 22 };
    check_face(&r.data, 8, 4, f2c0);
    check_face(&r.data, 10, 4, f2c2);
    run_free(&r);
}

/* Pentagonal pyramid: a pentagon (base) and five triangles around a valence-5 apex.
 *   vertices 0..4 ring, 5 apex
 *   faces: f0 (4,3,2,1,0) pentagon, f1 (0,1,5), f2 (1,2,5), f3 (2,3,5), f4 (3,4,5), f5 (4,0,5)
 *   edges: e0 (4,3) e1 (3,2) e2 (2,1) e3 (1,0) e4 (0,4) e5 (1,5) e6 (5,0) e7 (2,5) e8 (3,5) e9 (4,5)
 *   level 1: vertices 0..5, face points 6..11, edge points 12..21 */
static const float pyr_pos[18] = {
    1.00f, 0.00f, 0.00f,   /* 0 */
    0.35f, 0.95f, 0.10f,   /* 1 */
    -0.80f, 0.60f, -0.05f, /* 2 */
    -0.75f, -0.60f, 0.08f, /* 3 */
    0.30f, -1.00f, -0.10f, /* 4 */
    0.10f, -0.05f, 1.20f,  /* 5 apex */
};
static const int pyr_sizes[6] = { 5, 3, 3, 3, 3, 3 };
static const int pyr_fv[20] = { 4, 3, 2, 1, 0, 0, 1, 5, 1, 2, 5, 2, 3, 5, 3, 4, 5, 4, 0, 5 };
static const int pyr_off[6] = { 0, 5, 8, 11, 14, 17 };

static void pyr_desc(sfb_mesh_desc *d)
{
    memset(d, 0, sizeof *d);
    d->vertex_count = 6;
    d->positions = pyr_pos;
    d->face_count = 6;
    d->face_sizes = pyr_sizes;
    d->face_vertices = pyr_fv;
}
static v3 pyr_F(int f) { return avg_idx(pyr_pos, pyr_sizes[f], pyr_fv + pyr_off[f]); }
static int pyr_e(int a, int b) { return 12 + edge_index(6, pyr_sizes, pyr_fv, a, b); }

/* expected smooth vertex points of the pyramid (same under both triangle rules) */
static void pyr_check_vertices(const sfb_mesh_data *d)
{
    const float *p = pyr_pos;
    /* apex, valence 5: 3/5 v + 1/25 sum(ring) + 1/25 sum(F1..F5) */
    {
        v3 n[5] = { P(p, 0), P(p, 1), P(p, 2), P(p, 3), P(p, 4) };
        v3 f[5] = { pyr_F(1), pyr_F(2), pyr_F(3), pyr_F(4), pyr_F(5) };
        v3 e = cc_vertex(P(p, 5), 5, n, f);
        /* the same, spelt out: */
        v3 e2 = vadd(vmul(P(p, 5), 0.6), vmul(vadd(sum_pts(5, n), sum_pts(5, f)), 0.04));
        cr_assert_lt(vdist(e, e2), 1e-12);
        check_pt(d, "apex (valence 5, all triangles)", 5, e);
    }
    /* ring vertex 0, valence 3: neighbours 1, 4, 5; faces f0 (pentagon), f1, f5 */
    {
        v3 n[3] = { P(p, 1), P(p, 4), P(p, 5) };
        v3 f[3] = { pyr_F(0), pyr_F(1), pyr_F(5) };
        check_pt(d, "ring vertex 0 (valence 3)", 0, cc_vertex(P(p, 0), 3, n, f));
    }
    /* ring vertex 2: neighbours 1, 3, 5; faces f0, f2, f3 */
    {
        v3 n[3] = { P(p, 1), P(p, 3), P(p, 5) };
        v3 f[3] = { pyr_F(0), pyr_F(2), pyr_F(3) };
        check_pt(d, "ring vertex 2 (valence 3)", 2, cc_vertex(P(p, 2), 3, n, f));
    }
}

Test(catmark_smooth, pentagon_triangles_valence5)
{
    const float *p = pyr_pos;
    sfb_mesh_desc d;
    pyr_desc(&d);
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    cr_assert_eq(r.data.vertex_count, 6 + 6 + 10);
    cr_assert_eq(r.data.face_count, 5 + 5 * 3);

    /* pentagon face point: average of 5 corners.
     * x = (1+0.35-0.8-0.75+0.3)/5 = 0.02, y = (0+0.95+0.6-0.6-1)/5 = -0.01, z = (0+0.1-0.05+0.08-0.1)/5 = 0.006 */
    check_pt(&r.data, "pentagon face point", 6, V(0.02, -0.01, 0.006));
    /* triangle f1 (0,1,5): x = (1+0.35+0.1)/3, y = (0+0.95-0.05)/3 = 0.3, z = (0+0.1+1.2)/3 */
    check_pt(&r.data, "triangle face point f1", 7, V(1.45 / 3, 0.3, 1.3 / 3));
    check_pt(&r.data, "triangle face point f4", 10, pyr_F(4));

    pyr_check_vertices(&r.data);

    /* edges (catmark triangle rule = plain smooth rule) */
    cr_assert_eq(pyr_e(0, 1), 15);
    cr_assert_eq(pyr_e(5, 0), 18);
    check_pt(&r.data, "edge (0,1) pentagon|triangle", pyr_e(0, 1), cc_edge(P(p, 0), P(p, 1), pyr_F(0), pyr_F(1)));
    check_pt(&r.data, "edge (0,5) triangle|triangle", pyr_e(0, 5), cc_edge(P(p, 0), P(p, 5), pyr_F(5), pyr_F(1)));
    check_pt(&r.data, "edge (3,5) triangle|triangle", pyr_e(3, 5), cc_edge(P(p, 3), P(p, 5), pyr_F(3), pyr_F(4)));

    /* the pentagon has 5 child quads (V_i', E_i, F, E_{i-1}); corner 0 is v4:
     * E0 = (4,3) -> 12, E4 = (0,4) -> 16, F = 6 */
    const int c0[4] = { 4, 12, 6, 16 };
    check_face(&r.data, 0, 4, c0);
    /* triangle f1 (0,1,5) children start at face 5: corner 0 = (V0', E(0,1)=15, F=7, E(5,0)=18) */
    const int t0[4] = { 0, 15, 7, 18 };
    check_face(&r.data, 5, 4, t0);
    run_free(&r);
}

Test(catmark_smooth, smooth_triangle_rule)
{
    const float *p = pyr_pos;
    sfb_mesh_desc d;
    pyr_desc(&d);
    d.triangle_rule = SFB_TRI_SMOOTH;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);

    /* face points and vertex points are unchanged by the triangle rule */
    check_pt(&r.data, "pentagon face point", 6, pyr_F(0));
    check_pt(&r.data, "triangle face point", 7, pyr_F(1));
    pyr_check_vertices(&r.data);

    /* triangle|triangle: fw = (0.47+0.47)/2 = 0.47, vw = (1-0.94)/2 = 0.03 */
    {
        v3 e = vadd(vmul(vadd(P(p, 0), P(p, 5)), 0.03), vmul(vadd(pyr_F(1), pyr_F(5)), 0.47));
        check_pt(&r.data, "edge (0,5) tri|tri, smooth triangles", pyr_e(0, 5), e);
    }
    /* pentagon|triangle: fw = (0.25+0.47)/2 = 0.36, vw = (1-0.72)/2 = 0.14 */
    {
        v3 e = vadd(vmul(vadd(P(p, 0), P(p, 1)), 0.14), vmul(vadd(pyr_F(0), pyr_F(1)), 0.36));
        check_pt(&r.data, "edge (0,1) pentagon|tri, smooth triangles", pyr_e(0, 1), e);
    }
    run_free(&r);
}

/* ========================================================================= */
/* Catmull-Clark creases, corners, darts                                      */

/* the top face's four edges: (4,5) (5,6) (6,7) (7,4) */
static const int top_loop[8] = { 4, 5, 5, 6, 6, 7, 7, 4 };

Test(catmark_crease, infinite_crease_loop)
{
    const float *p = cube_pos;
    const float s[4] = { INF_SHARP, INF_SHARP, INF_SHARP, INF_SHARP };
    sfb_mesh_desc d;
    cube_desc(&d, p);
    d.crease_count = 4;
    d.crease_vertices = top_loop;
    d.crease_sharpness = s;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);

    /* crease vertices: 3/4 v + 1/8 (a + b), a, b the loop neighbours */
    check_pt(&r.data, "crease vertex 4", 4, crease_vertex(P(p, 4), P(p, 5), P(p, 7)));
    check_pt(&r.data, "crease vertex 6", 6, crease_vertex(P(p, 6), P(p, 5), P(p, 7)));
    /* literal for vertex 4: x = .75*.05 + .125*(.9-.15) = 0.13125,
     * y = .75*-.05 + .125*(.1+1.05) = 0.10625, z = .75*1 + .125*(1.1+.95) = 1.00625 */
    check_pt(&r.data, "crease vertex 4 literal", 4, V(0.13125, 0.10625, 1.00625));
    /* crease edges: midpoints */
    check_pt(&r.data, "crease edge (4,5)", cube_e(4, 5), midpoint(P(p, 4), P(p, 5)));
    check_pt(&r.data, "crease edge (6,7)", cube_e(6, 7), midpoint(P(p, 6), P(p, 7)));
    /* off the crease everything is smooth */
    check_pt(&r.data, "smooth vertex 0", 0, cube_smooth_vertex(p, 0));
    check_pt(&r.data, "smooth edge (0,4)", cube_e(0, 4), cube_smooth_edge(p, 0, 4, 2, 5));
    check_pt(&r.data, "smooth edge (0,1)", cube_e(0, 1), cube_smooth_edge(p, 0, 1, 0, 2));
    check_pt(&r.data, "face point f1", CUBE_FP + 1, cube_F(p, 1));

    /* the crease edges' children stay infinitely sharp */
    int found;
    float cs = refined_sharpness(&r.data, 4, cube_e(4, 5), &found);
    cr_expect(found && cs >= INF_SHARP, "child edge (V4', E45) sharpness %f, expected infinite", cs);
    cs = refined_sharpness(&r.data, cube_e(4, 5), 5, &found);
    cr_expect(found && cs >= INF_SHARP, "child edge (E45, V5') sharpness %f, expected infinite", cs);
    run_free(&r);
}

Test(catmark_crease, corners)
{
    const float *p = cube_pos;
    /* vertex 0 gets three infinitely sharp edges -> corner rule */
    const int cv[6] = { 0, 1, 0, 3, 0, 4 };
    const float cs[3] = { INF_SHARP, INF_SHARP, INF_SHARP };
    /* vertex 6: infinite corner sharpness; vertex 2: finite corner sharpness 2.5 (still > 0 after one level) */
    const int kv[2] = { 6, 2 };
    const float ks[2] = { INF_SHARP, 2.5f };
    sfb_mesh_desc d;
    cube_desc(&d, p);
    d.crease_count = 3;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    d.corner_count = 2;
    d.corner_vertices = kv;
    d.corner_sharpness = ks;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);

    check_pt(&r.data, "3-sharp-edge corner vertex 0 stays", 0, P(p, 0));
    check_pt(&r.data, "infinite corner vertex 6 stays", 6, P(p, 6));
    check_pt(&r.data, "corner-sharpness-2.5 vertex 2 stays", 2, P(p, 2));
    /* sharp edges at the corner: midpoints */
    check_pt(&r.data, "sharp edge (0,1)", cube_e(0, 1), midpoint(P(p, 0), P(p, 1)));
    check_pt(&r.data, "sharp edge (0,4)", cube_e(0, 4), midpoint(P(p, 0), P(p, 4)));
    /* vertex sharpness does not change edge points */
    check_pt(&r.data, "smooth edge (2,6) between two corners", cube_e(2, 6), cube_smooth_edge(p, 2, 6, 3, 4));
    /* vertex 1 has one sharp edge (0,1): dart -> smooth rule */
    check_pt(&r.data, "dart vertex 1", 1, cube_smooth_vertex(p, 1));
    /* vertex 5 is untouched */
    check_pt(&r.data, "smooth vertex 5", 5, cube_smooth_vertex(p, 5));

    /* the finite corner sharpness decays by one: 2.5 -> 1.5 at vertex 2's child (index 2) */
    int seen2 = 0, seen6 = 0;
    for (int i = 0; i < r.data.corner_count; ++i) {
        if (r.data.corner_vertices[i] == 2) {
            seen2 = 1;
            cr_expect(fabsf(r.data.corner_sharpness[i] - 1.5f) < TOL, "child corner sharpness %f, expected 1.5",
                      r.data.corner_sharpness[i]);
        }
        if (r.data.corner_vertices[i] == 6) {
            seen6 = 1;
            cr_expect(r.data.corner_sharpness[i] >= INF_SHARP, "infinite corner sharpness lost: %f",
                      r.data.corner_sharpness[i]);
        }
    }
    cr_expect(seen2, "refined corner list lacks vertex 2 (sharpness 1.5 remains)");
    cr_expect(seen6, "refined corner list lacks vertex 6 (infinite)");
    run_free(&r);
}

Test(catmark_crease, dart)
{
    const float *p = cube_pos;
    const int cv[2] = { 0, 1 };
    const float cs[1] = { INF_SHARP };
    sfb_mesh_desc d;
    cube_desc(&d, p);
    d.crease_count = 1;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    /* both ends of the single sharp edge are darts: smooth vertex rule */
    check_pt(&r.data, "dart vertex 0", 0, cube_smooth_vertex(p, 0));
    check_pt(&r.data, "dart vertex 1", 1, cube_smooth_vertex(p, 1));
    /* the sharp edge itself: midpoint */
    check_pt(&r.data, "dart edge (0,1)", cube_e(0, 1), midpoint(P(p, 0), P(p, 1)));
    /* literal: ((-0.1+1)/2, (0.05-0.1)/2, (-0.2+0.1)/2) */
    check_pt(&r.data, "dart edge (0,1) literal", cube_e(0, 1), V(0.45, -0.025, -0.05));
    /* neighbouring edges are smooth */
    check_pt(&r.data, "smooth edge (0,3)", cube_e(0, 3), cube_smooth_edge(p, 0, 3, 0, 5));
    check_pt(&r.data, "smooth edge (1,2)", cube_e(1, 2), cube_smooth_edge(p, 1, 2, 0, 3));
    run_free(&r);
}

Test(catmark_crease, fractional_edge)
{
    const float *p = cube_pos;
    const int cv[2] = { 0, 1 };
    const float cs[1] = { 0.5f };
    sfb_mesh_desc d;
    cube_desc(&d, p);
    d.crease_count = 1;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    /* s = 0.5: 0.5 * midpoint + 0.5 * smooth */
    v3 e = vblend(0.5, midpoint(P(p, 0), P(p, 1)), cube_smooth_edge(p, 0, 1, 0, 2));
    check_pt(&r.data, "edge (0,1) s=0.5", cube_e(0, 1), e);
    /* ends are darts (one edge with s > 0): smooth rule, no blend */
    check_pt(&r.data, "dart vertex 0", 0, cube_smooth_vertex(p, 0));
    check_pt(&r.data, "dart vertex 1", 1, cube_smooth_vertex(p, 1));
    /* child edges are smooth: sharpness 0.5 - 1 -> 0 */
    int found;
    float s = refined_sharpness(&r.data, 0, cube_e(0, 1), &found);
    cr_expect(!found || s == 0.0f, "child of s=0.5 edge keeps sharpness %f", s);
    run_free(&r);
}

Test(catmark_crease, fractional_vertex_blend)
{
    const float *p = cube_pos;
    /* top loop (4,5) (5,6) (6,7) = 0.5, (7,4) = 0.25 */
    const float s[4] = { 0.5f, 0.5f, 0.5f, 0.25f };
    sfb_mesh_desc d;
    cube_desc(&d, p);
    d.crease_count = 4;
    d.crease_vertices = top_loop;
    d.crease_sharpness = s;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);

    /* vertex 5: crease (two edges > 0) at the parent, smooth at the child;
     * transitions: edges 0.5 and 0.5 -> w = 0.5 */
    v3 c5 = crease_vertex(P(p, 5), P(p, 4), P(p, 6));
    check_pt(&r.data, "vertex 5 blend w=0.5", 5, vblend(0.5, c5, cube_smooth_vertex(p, 5)));
    /* vertex 4: edges (4,5)=0.5 and (7,4)=0.25 -> w = 0.375 */
    v3 c4 = crease_vertex(P(p, 4), P(p, 5), P(p, 7));
    check_pt(&r.data, "vertex 4 blend w=0.375", 4, vblend(0.375, c4, cube_smooth_vertex(p, 4)));
    /* vertex 7: edges (6,7)=0.5 and (7,4)=0.25 -> w = 0.375 */
    v3 c7 = crease_vertex(P(p, 7), P(p, 6), P(p, 4));
    check_pt(&r.data, "vertex 7 blend w=0.375", 7, vblend(0.375, c7, cube_smooth_vertex(p, 7)));
    /* fractional edges */
    check_pt(&r.data, "edge (5,6) s=0.5", cube_e(5, 6),
             vblend(0.5, midpoint(P(p, 5), P(p, 6)), cube_smooth_edge(p, 5, 6, 1, 3)));
    check_pt(&r.data, "edge (7,4) s=0.25", cube_e(7, 4),
             vblend(0.25, midpoint(P(p, 7), P(p, 4)), cube_smooth_edge(p, 7, 4, 1, 5)));
    /* bottom vertex 0 is untouched */
    check_pt(&r.data, "smooth vertex 0", 0, cube_smooth_vertex(p, 0));
    run_free(&r);
}

Test(catmark_crease, fractional_corner_sharpness)
{
    const float *p = cube_pos;
    /* vertex 6: corner sharpness 0.5 -> corner at the parent, smooth at the child, w = 0.5;
     * vertex 0: corner sharpness 1.0 -> w = 1 -> stays;
     * vertex 3: corner sharpness 0.25 -> w = 0.25 */
    const int kv[3] = { 6, 0, 3 };
    const float ks[3] = { 0.5f, 1.0f, 0.25f };
    sfb_mesh_desc d;
    cube_desc(&d, p);
    d.corner_count = 3;
    d.corner_vertices = kv;
    d.corner_sharpness = ks;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    check_pt(&r.data, "vertex 6 corner 0.5", 6, vblend(0.5, P(p, 6), cube_smooth_vertex(p, 6)));
    check_pt(&r.data, "vertex 0 corner 1.0", 0, P(p, 0));
    check_pt(&r.data, "vertex 3 corner 0.25", 3, vblend(0.25, P(p, 3), cube_smooth_vertex(p, 3)));
    check_pt(&r.data, "vertex 5 smooth", 5, cube_smooth_vertex(p, 5));
    run_free(&r);
}

/* s = 2 on the top loop, two levels. Level 1: crease edges give midpoints, crease vertices the
 * crease rule (child edges keep sharpness 1, so no blend). Level 2: the level-1 crease edges have
 * sharpness 1 -> midpoints; level-1 crease vertices have parent rule crease, child rule smooth,
 * and their transitions are two edges of sharpness 1 -> w = 1 -> pure crease rule. So along the
 * crease the surface follows two steps of cubic B-spline curve subdivision of the loop 4,5,6,7.
 * Level-2 indices < 26 are the children of the level-1 vertices with the same index. */
Test(catmark_crease, semisharp_two_levels)
{
    const float *p = cube_pos;
    const float s2[4] = { 2.0f, 2.0f, 2.0f, 2.0f };
    sfb_mesh_desc d;
    cube_desc(&d, p);
    d.crease_count = 4;
    d.crease_vertices = top_loop;
    d.crease_sharpness = s2;

    /* level 1 */
    run r1;
    run_refine(&r1, &d, SFB_SCHEME_CATMARK, 1, 0);
    v3 P4 = crease_vertex(P(p, 4), P(p, 5), P(p, 7));
    v3 P5 = crease_vertex(P(p, 5), P(p, 4), P(p, 6));
    v3 P7 = crease_vertex(P(p, 7), P(p, 6), P(p, 4));
    v3 M45 = midpoint(P(p, 4), P(p, 5));
    v3 M47 = midpoint(P(p, 4), P(p, 7));
    check_pt(&r1.data, "level 1 crease vertex 4", 4, P4);
    check_pt(&r1.data, "level 1 crease edge (4,5)", cube_e(4, 5), M45);
    /* the eight child crease edges keep sharpness 2 - 1 = 1 */
    int n1 = 0;
    for (int i = 0; i < r1.data.crease_count; ++i) {
        if (r1.data.crease_sharpness[i] > 0.0f) {
            ++n1;
            cr_expect(fabsf(r1.data.crease_sharpness[i] - 1.0f) < TOL, "level 1 crease %d sharpness %f, expected 1", i,
                      r1.data.crease_sharpness[i]);
        }
    }
    cr_expect_eq(n1, 8, "level 1 should have 8 sharp child edges, has %d", n1);
    int found;
    float cs = refined_sharpness(&r1.data, 4, cube_e(4, 5), &found);
    cr_expect(found && fabsf(cs - 1.0f) < TOL, "child edge (V4', E45): %f, expected 1", cs);
    run_free(&r1);

    /* level 2 */
    run r2;
    run_refine(&r2, &d, SFB_SCHEME_CATMARK, 2, 0);
    cr_assert_eq(r2.data.vertex_count, 26 + 24 + 48);
    /* child of base vertex 4: crease rule on the level-1 polygon (.., M47, P4, M45, ..) */
    v3 e4 = crease_vertex(P4, M45, M47);
    check_pt(&r2.data, "level 2 vertex 4 on s=2 crease", 4, e4);
    /* child of the level-1 edge point of (4,5) (index 18): neighbours P4 and P5 */
    v3 e18 = crease_vertex(M45, P4, P5);
    check_pt(&r2.data, "level 2 child of E(4,5) on s=2 crease", cube_e(4, 5), e18);
    /* child of the level-1 edge point of (7,4) (index 21): neighbours P7 and P4 */
    check_pt(&r2.data, "level 2 child of E(7,4) on s=2 crease", cube_e(7, 4), crease_vertex(M47, P7, P4));
    /* all sharpness is used up at level 2 */
    for (int i = 0; i < r2.data.crease_count; ++i)
        cr_expect(r2.data.crease_sharpness[i] <= 0.0f, "level 2 crease %d keeps sharpness %f", i,
                  r2.data.crease_sharpness[i]);
    run_free(&r2);

    /* contrast: with s = 1 the level-1 child edges are smooth, so level 2 uses the smooth rule
     * and the crease-curve value above must NOT come out */
    const float s1[4] = { 1.0f, 1.0f, 1.0f, 1.0f };
    d.crease_sharpness = s1;
    run r3;
    run_refine(&r3, &d, SFB_SCHEME_CATMARK, 2, 0);
    cr_expect_gt(vdist(out_pt(r3.data.positions, 4), e4), 1e-3, "s=1 level 2 should differ from the s=2 crease curve");
    run_free(&r3);
}

/* Vertex 4 with edges (4,5) s=1 and (7,4) s=3 (the other edges smooth). */
static void chaikin_case(int method, float expect_45_at4, float expect_45_at5, float expect_47_at4,
                         float expect_47_at7)
{
    const float *p = cube_pos;
    const int cv[4] = { 4, 5, 7, 4 };
    const float cs[2] = { 1.0f, 3.0f };
    sfb_mesh_desc d;
    cube_desc(&d, p);
    d.crease_count = 2;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    d.crease_method = method;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    cr_assert_eq(r.data.crease_method, method);
    int e45 = cube_e(4, 5), e47 = cube_e(7, 4);
    cr_assert_eq(e45, 18);
    cr_assert_eq(e47, 21);
    int found;
    float s;
    s = refined_sharpness(&r.data, 4, e45, &found);
    cr_expect(fabsf(s - expect_45_at4) < TOL, "method %d: child of (4,5) at V4: %f (listed %d), expected %f", method, s,
              found, expect_45_at4);
    s = refined_sharpness(&r.data, e45, 5, &found);
    cr_expect(fabsf(s - expect_45_at5) < TOL, "method %d: child of (4,5) at V5: %f (listed %d), expected %f", method, s,
              found, expect_45_at5);
    s = refined_sharpness(&r.data, 4, e47, &found);
    cr_expect(fabsf(s - expect_47_at4) < TOL, "method %d: child of (7,4) at V4: %f (listed %d), expected %f", method, s,
              found, expect_47_at4);
    s = refined_sharpness(&r.data, e47, 7, &found);
    cr_expect(fabsf(s - expect_47_at7) < TOL, "method %d: child of (7,4) at V7: %f (listed %d), expected %f", method, s,
              found, expect_47_at7);
    /* positions: vertex 4 is a crease at the parent. Uniform: child rule dart, transition edge s=1
     * -> w = 1; Chaikin: child still crease. Both give the pure crease point. Edges s >= 1: midpoints. */
    check_pt(&r.data, "vertex 4 crease", 4, crease_vertex(P(p, 4), P(p, 5), P(p, 7)));
    check_pt(&r.data, "edge (4,5) s=1", e45, midpoint(P(p, 4), P(p, 5)));
    check_pt(&r.data, "edge (7,4) s=3", e47, midpoint(P(p, 4), P(p, 7)));
    run_free(&r);
}

Test(catmark_crease, uniform_decay)
{
    /* uniform: s - 1 clamped at 0 everywhere: 1 -> 0, 3 -> 2 */
    chaikin_case(SFB_CREASE_UNIFORM, 0.0f, 0.0f, 2.0f, 2.0f);
}

Test(catmark_crease, chaikin_decay)
{
    /* Chaikin at V4 (two semi-sharp edges 1 and 3):
     *   (4,5): 3/4*1 + 1/4*3 - 1 = 0.5     (7,4): 3/4*3 + 1/4*1 - 1 = 1.5
     * at V5 and V7 only one semi-sharp edge: plain s - 1 -> 0 and 2 */
    chaikin_case(SFB_CREASE_CHAIKIN, 0.5f, 0.0f, 1.5f, 2.0f);
}

/* ========================================================================= */
/* boundaries: open 3x3 quad grid                                             */

/* vertex (i,j) = 4j + i, i,j in 0..3; face (i,j) = 3j + i = (v(i,j), v(i+1,j), v(i+1,j+1), v(i,j+1)) */
static float grid_pos[48];
static int grid_sizes[9];
static int grid_fv[36];

static void grid_build(void)
{
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            int v = 4 * j + i;
            grid_pos[3 * v + 0] = (float)i + 0.07f * j;
            grid_pos[3 * v + 1] = (float)j - 0.04f * i * i;
            grid_pos[3 * v + 2] = 0.1f * ((i * j) % 3) - 0.05f * i + 0.08f * (j == 2) + 0.03f * (i == 0);
        }
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
            int f = 3 * j + i;
            grid_sizes[f] = 4;
            grid_fv[4 * f + 0] = 4 * j + i;
            grid_fv[4 * f + 1] = 4 * j + i + 1;
            grid_fv[4 * f + 2] = 4 * (j + 1) + i + 1;
            grid_fv[4 * f + 3] = 4 * (j + 1) + i;
        }
}

static void grid_desc(sfb_mesh_desc *d, int boundary)
{
    grid_build();
    memset(d, 0, sizeof *d);
    d->vertex_count = 16;
    d->positions = grid_pos;
    d->face_count = 9;
    d->face_sizes = grid_sizes;
    d->face_vertices = grid_fv;
    d->boundary = boundary;
}

/* level-1 index of a grid edge point: 16 + 9 + edge */
static int grid_e(int a, int b) { return 25 + edge_index(9, grid_sizes, grid_fv, a, b); }
static v3 grid_F(int f) { return avg_idx(grid_pos, 4, grid_fv + 4 * f); }

/* checks shared by all three boundary modes */
static void grid_common_checks(const sfb_mesh_data *d)
{
    const float *p = grid_pos;
    cr_assert_eq(d->vertex_count, 16 + 9 + 24);
    /* boundary vertex 1: boundary edges to 0 and 2 are infinitely sharp, (1,5) smooth -> crease */
    check_pt(d, "boundary vertex 1 crease rule", 1, crease_vertex(P(p, 1), P(p, 0), P(p, 2)));
    check_pt(d, "boundary vertex 8 crease rule", 8, crease_vertex(P(p, 8), P(p, 4), P(p, 12)));
    /* boundary edges: midpoints */
    check_pt(d, "boundary edge (0,1)", grid_e(0, 1), midpoint(P(p, 0), P(p, 1)));
    check_pt(d, "boundary edge (11,15)", grid_e(11, 15), midpoint(P(p, 11), P(p, 15)));
    /* interior edge (1,5) between faces f0 and f1 */
    check_pt(d, "interior edge (1,5)", grid_e(1, 5), cc_edge(P(p, 1), P(p, 5), grid_F(0), grid_F(1)));
    /* interior vertex 5, valence 4: 1/2 v + 1/16 sum(1,4,6,9) + 1/16 sum(F0,F1,F3,F4) */
    {
        v3 n[4] = { P(p, 1), P(p, 4), P(p, 6), P(p, 9) };
        v3 f[4] = { grid_F(0), grid_F(1), grid_F(3), grid_F(4) };
        check_pt(d, "interior vertex 5", 5, cc_vertex(P(p, 5), 4, n, f));
    }
    check_pt(d, "face point f4", 16 + 4, grid_F(4));
}

Test(boundary, edge_only)
{
    sfb_mesh_desc d;
    grid_desc(&d, SFB_BOUNDARY_EDGE_ONLY);
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    grid_common_checks(&r.data);
    const float *p = grid_pos;
    /* corner of the grid (1 face, 2 boundary edges) -> crease rule 3/4 v0 + 1/8 (v1 + v4) */
    check_pt(&r.data, "boundary corner 0, edge-only", 0, crease_vertex(P(p, 0), P(p, 1), P(p, 4)));
    check_pt(&r.data, "boundary corner 15, edge-only", 15, crease_vertex(P(p, 15), P(p, 14), P(p, 11)));
    cr_expect_eq(r.data.hole_count, 0);
    cr_expect_eq(r.data.boundary, SFB_BOUNDARY_EDGE_ONLY);
    run_free(&r);
}

Test(boundary, edge_and_corner)
{
    sfb_mesh_desc d;
    grid_desc(&d, SFB_BOUNDARY_EDGE_AND_CORNER);
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    grid_common_checks(&r.data);
    const float *p = grid_pos;
    check_pt(&r.data, "boundary corner 0 stays", 0, P(p, 0));
    check_pt(&r.data, "boundary corner 3 stays", 3, P(p, 3));
    check_pt(&r.data, "boundary corner 15 stays", 15, P(p, 15));
    cr_expect_eq(r.data.hole_count, 0);
    cr_expect_eq(r.data.boundary, SFB_BOUNDARY_EDGE_AND_CORNER);
    run_free(&r);
}

Test(boundary, none_makes_holes)
{
    sfb_mesh_desc d;
    grid_desc(&d, SFB_BOUNDARY_NONE);
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, 0);
    /* same vertex count and the same (crease) rules on the boundary */
    grid_common_checks(&r.data);
    const float *p = grid_pos;
    /* corners are not sharpened in this mode: crease rule as with edge-only */
    check_pt(&r.data, "boundary corner 0, none", 0, crease_vertex(P(p, 0), P(p, 1), P(p, 4)));
    /* every base face except the centre one (f4 = 5,6,10,9) touches the boundary -> holes;
     * their 8 * 4 = 32 children are holes at level 1 */
    cr_expect_gt(r.data.hole_count, 0);
    cr_expect_eq(r.data.hole_count, 32, "hole count %d, expected 32", r.data.hole_count);
    int centre_hole = 0;
    for (int i = 0; i < r.data.hole_count; ++i) {
        cr_expect(r.data.holes[i] >= 0 && r.data.holes[i] < r.data.face_count);
        if (r.data.holes[i] >= 16 && r.data.holes[i] < 20) centre_hole = 1;
    }
    cr_expect(!centre_hole, "a child of the centre face is marked as a hole");
    cr_expect_eq(r.data.boundary, SFB_BOUNDARY_NONE);
    run_free(&r);
}

/* ========================================================================= */
/* Loop                                                                       */

/* Octahedron (all valence 4), moved off the regular shape.
 *   0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z
 *   faces: f0 (0,2,4) f1 (2,1,4) f2 (1,3,4) f3 (3,0,4) f4 (2,0,5) f5 (1,2,5) f6 (3,1,5) f7 (0,3,5)
 *   edges: e0 (0,2) e1 (2,4) e2 (4,0) e3 (2,1) e4 (1,4) e5 (1,3) e6 (3,4) e7 (3,0) e8 (0,5)
 *          e9 (5,2) e10 (5,1) e11 (5,3)
 *   level 1: vertices 0..5, edge points 6..17 (6 + e) */
static const float oct_pos[18] = {
    1.00f, 0.10f, -0.05f,  /* 0 */
    -1.10f, -0.05f, 0.10f, /* 1 */
    0.05f, 0.90f, 0.08f,   /* 2 */
    -0.10f, -1.05f, -0.02f,/* 3 */
    0.12f, -0.07f, 1.15f,  /* 4 */
    -0.06f, 0.11f, -0.95f, /* 5 */
};
static const int oct_sizes[8] = { 3, 3, 3, 3, 3, 3, 3, 3 };
static const int oct_fv[24] = { 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5 };

static void oct_desc(sfb_mesh_desc *d)
{
    memset(d, 0, sizeof *d);
    d->vertex_count = 6;
    d->positions = oct_pos;
    d->face_count = 8;
    d->face_sizes = oct_sizes;
    d->face_vertices = oct_fv;
}
static int oct_e(int a, int b) { return 6 + edge_index(8, oct_sizes, oct_fv, a, b); }

Test(loop, octahedron_smooth)
{
    const float *p = oct_pos;
    sfb_mesh_desc d;
    oct_desc(&d);
    run r;
    run_refine(&r, &d, SFB_SCHEME_LOOP, 1, 0);
    cr_assert_eq(r.data.vertex_count, 6 + 12);
    cr_assert_eq(r.data.face_count, 32);

    /* valence 4: beta = 3/8 + 1/4 cos(pi/2) = 3/8; w = (5/8 - 9/64)/4 = 31/256; centre 1 - 124/256 = 33/64 */
    {
        v3 n[4] = { P(p, 2), P(p, 4), P(p, 3), P(p, 5) };
        v3 e = vadd(vmul(P(p, 0), 33.0 / 64), vmul(sum_pts(4, n), 31.0 / 256));
        cr_assert_lt(vdist(e, loop_vertex(P(p, 0), 4, n)), 1e-12);
        check_pt(&r.data, "loop vertex 0 (valence 4)", 0, e);
    }
    {
        v3 n[4] = { P(p, 0), P(p, 2), P(p, 1), P(p, 3) };
        check_pt(&r.data, "loop vertex 4 (valence 4)", 4, loop_vertex(P(p, 4), 4, n));
    }
    /* unperturbed literal check of the weights: on the regular octahedron vertex +x would move to
     * 33/64 * 1 + 31/256 * (0 + 0 + 0 + 0) = 0.515625 in x; here: the perturbed one via the formula */

    /* edge (0,2): faces f0 (0,2,4) and f4 (2,0,5) -> opposite 4 and 5 */
    cr_assert_eq(oct_e(0, 2), 6);
    check_pt(&r.data, "loop edge (0,2)", 6, loop_edge(P(p, 0), P(p, 2), P(p, 4), P(p, 5)));
    /* edge (0,4): faces f0 (opposite 2) and f3 (3,0,4) (opposite 3) */
    check_pt(&r.data, "loop edge (0,4)", oct_e(0, 4), loop_edge(P(p, 0), P(p, 4), P(p, 2), P(p, 3)));
    /* edge (5,1): faces f5 (1,2,5) (opposite 2) and f6 (3,1,5) (opposite 3) */
    check_pt(&r.data, "loop edge (5,1)", oct_e(5, 1), loop_edge(P(p, 5), P(p, 1), P(p, 2), P(p, 3)));

    /* child triangles of f0 (0,2,4): E0 = (0,2) -> 6, E1 = (2,4) -> 7, E2 = (4,0) -> 8 */
    const int t0[3] = { 0, 6, 8 }, t1[3] = { 2, 7, 6 }, t2[3] = { 4, 8, 7 }, t3[3] = { 6, 7, 8 };
    check_face(&r.data, 0, 3, t0);
    check_face(&r.data, 1, 3, t1);
    check_face(&r.data, 2, 3, t2);
    check_face(&r.data, 3, 3, t3);
    run_free(&r);
}

Test(loop, regular_octahedron_literals)
{
    /* regular octahedron: vertex +x has neighbours +-y, +-z which sum to 0:
     *   v' = 33/64 (1,0,0) = (0.515625, 0, 0)
     * edge (+x,+y): 3/8 ((1,0,0)+(0,1,0)) + 1/8 ((0,0,1)+(0,0,-1)) = (0.375, 0.375, 0) */
    static const float reg[18] = { 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1 };
    sfb_mesh_desc d;
    oct_desc(&d);
    d.positions = reg;
    run r;
    run_refine(&r, &d, SFB_SCHEME_LOOP, 1, 0);
    check_pt(&r.data, "regular octahedron vertex +x", 0, V(0.515625, 0, 0));
    check_pt(&r.data, "regular octahedron edge (+x,+y)", 6, V(0.375, 0.375, 0));
    run_free(&r);
}

Test(loop, crease_and_corner)
{
    const float *p = oct_pos;
    /* equator (0,2) (2,1) (1,3) (3,0) infinitely sharp; apex 4 an infinite corner */
    const int cv[8] = { 0, 2, 2, 1, 1, 3, 3, 0 };
    const float cs[4] = { INF_SHARP, INF_SHARP, INF_SHARP, INF_SHARP };
    const int kv[1] = { 4 };
    const float ks[1] = { INF_SHARP };
    sfb_mesh_desc d;
    oct_desc(&d);
    d.crease_count = 4;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    d.corner_count = 1;
    d.corner_vertices = kv;
    d.corner_sharpness = ks;
    run r;
    run_refine(&r, &d, SFB_SCHEME_LOOP, 1, 0);
    check_pt(&r.data, "loop crease vertex 0", 0, crease_vertex(P(p, 0), P(p, 2), P(p, 3)));
    check_pt(&r.data, "loop crease vertex 1", 1, crease_vertex(P(p, 1), P(p, 2), P(p, 3)));
    check_pt(&r.data, "loop crease edge (0,2)", oct_e(0, 2), midpoint(P(p, 0), P(p, 2)));
    check_pt(&r.data, "loop crease edge (1,3)", oct_e(1, 3), midpoint(P(p, 1), P(p, 3)));
    check_pt(&r.data, "loop corner 4 stays", 4, P(p, 4));
    /* vertex 5 (valence 4, no sharp edges) smooth */
    {
        v3 n[4] = { P(p, 0), P(p, 2), P(p, 1), P(p, 3) };
        check_pt(&r.data, "loop smooth vertex 5", 5, loop_vertex(P(p, 5), 4, n));
    }
    /* off-crease edge (0,5): faces f4 (2,0,5) (opposite 2) and f7 (0,3,5) (opposite 3) */
    check_pt(&r.data, "loop smooth edge (0,5)", oct_e(0, 5), loop_edge(P(p, 0), P(p, 5), P(p, 2), P(p, 3)));
    run_free(&r);
}

/* ========================================================================= */
/* bilinear                                                                   */

Test(bilinear, quad_and_triangle)
{
    /* a non-planar quad (0,1,2,3) and a triangle (1,4,2) */
    static const float pos[15] = {
        0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.2f, 1.1f, 0.9f, 0.5f, -0.1f, 1.0f, 0.1f, 2.0f, 0.4f, -0.3f,
    };
    static const int sizes[2] = { 4, 3 };
    static const int fv[7] = { 0, 1, 2, 3, 1, 4, 2 };
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 5;
    d.positions = pos;
    d.face_count = 2;
    d.face_sizes = sizes;
    d.face_vertices = fv;
    run r;
    run_refine(&r, &d, SFB_SCHEME_BILINEAR, 1, 0);
    /* edges: e0 (0,1) e1 (1,2) e2 (2,3) e3 (3,0) e4 (1,4) e5 (4,2) -> 5 + 2 + 6 = 13 vertices */
    cr_assert_eq(r.data.vertex_count, 13);
    cr_assert_eq(r.data.face_count, 4 + 3);
    for (int v = 0; v < 5; ++v) check_pt(&r.data, "bilinear vertex stays", v, P(pos, v));
    /* quad face point: ((0+1+1.1-0.1)/4, (0+0+0.9+1)/4, (0+0.2+0.5+0.1)/4) = (0.5, 0.475, 0.2) */
    check_pt(&r.data, "bilinear quad face point", 5, V(0.5, 0.475, 0.2));
    /* triangle face point: ((1+2+1.1)/3, (0+0.4+0.9)/3, (0.2-0.3+0.5)/3) */
    check_pt(&r.data, "bilinear triangle face point", 6, V(4.1 / 3, 1.3 / 3, 0.4 / 3));
    /* edge midpoints */
    check_pt(&r.data, "bilinear edge (0,1)", 7, V(0.5, 0.0, 0.1));
    check_pt(&r.data, "bilinear edge (1,2)", 8, V(1.05, 0.45, 0.35));
    check_pt(&r.data, "bilinear edge (2,3)", 9, V(0.5, 0.95, 0.3));
    check_pt(&r.data, "bilinear edge (3,0)", 10, V(-0.05, 0.5, 0.05));
    check_pt(&r.data, "bilinear edge (1,4)", 11, V(1.5, 0.2, -0.05));
    check_pt(&r.data, "bilinear edge (4,2)", 12, V(1.55, 0.65, 0.1));
    /* child quads of the quad: corner i = (V_i', E_i, F, E_{i-1}) */
    const int q0[4] = { 0, 7, 5, 10 }, q2[4] = { 2, 9, 5, 8 };
    check_face(&r.data, 0, 4, q0);
    check_face(&r.data, 2, 4, q2);
    /* the triangle (1,4,2) gives 3 quads: corner 0 = (V1', E(1,4)=11, F=6, E(2,1)=8) */
    const int t0[4] = { 1, 11, 6, 8 };
    check_face(&r.data, 4, 4, t0);
    run_free(&r);
}

/* ========================================================================= */
/* limit positions and normals                                                */

static void flat_grid(float *pos, int *sizes, int *fv, double a, double b)
{
    /* 5x5 vertices, 4x4 quads, unit spacing, z = a x + b y (a plane) */
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i) {
            int v = 5 * j + i;
            pos[3 * v + 0] = (float)i;
            pos[3 * v + 1] = (float)j;
            pos[3 * v + 2] = (float)(a * i + b * j);
        }
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            int f = 4 * j + i;
            sizes[f] = 4;
            fv[4 * f + 0] = 5 * j + i;
            fv[4 * f + 1] = 5 * j + i + 1;
            fv[4 * f + 2] = 5 * (j + 1) + i + 1;
            fv[4 * f + 3] = 5 * (j + 1) + i;
        }
}

static void check_unit_normal(const sfb_mesh_data *d, int idx, v3 expect)
{
    v3 n = out_pt(d->normals, idx);
    double len = sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    cr_expect(fabs(len - 1.0) < TOL, "normal %d not unit: length %f", idx, len);
    check_vec("limit normal", idx, d->normals, expect);
}

Test(limit, flat_grid_regular_vertex)
{
    float pos[75];
    int sizes[16], fv[64];
    flat_grid(pos, sizes, fv, 0.0, 0.0);
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 25;
    d.positions = pos;
    d.face_count = 16;
    d.face_sizes = sizes;
    d.face_vertices = fv;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, SFB_REFINE_LIMIT);
    cr_assert_not_null(r.data.limit_positions);
    cr_assert_not_null(r.data.normals);
    /* centre vertex (2,2) = index 12: regular, flat -> refined = limit = (2,2,0), normal +z */
    check_pt(&r.data, "flat grid centre refined", 12, V(2, 2, 0));
    check_vec("flat grid centre limit", 12, r.data.limit_positions, V(2, 2, 0));
    check_unit_normal(&r.data, 12, V(0, 0, 1));
    /* the face point of the inner face (1,1) (index 25 + 5 = 30) is regular too: (1.5, 1.5, 0) */
    check_vec("flat grid inner face point limit", 30, r.data.limit_positions, V(1.5, 1.5, 0));
    check_unit_normal(&r.data, 30, V(0, 0, 1));
    run_free(&r);
}

Test(limit, tilted_plane_linear_precision)
{
    /* z = 0.3 x - 0.2 y: Catmull-Clark reproduces linear functions on a regular grid, so at the
     * regular centre vertex limit = (2, 2, 0.6 - 0.4 = 0.2), normal = (-0.3, 0.2, 1)/|.| */
    float pos[75];
    int sizes[16], fv[64];
    flat_grid(pos, sizes, fv, 0.3, -0.2);
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 25;
    d.positions = pos;
    d.face_count = 16;
    d.face_sizes = sizes;
    d.face_vertices = fv;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, SFB_REFINE_LIMIT);
    check_vec("tilted grid centre limit", 12, r.data.limit_positions, V(2, 2, 0.2));
    double len = sqrt(0.09 + 0.04 + 1.0);
    check_unit_normal(&r.data, 12, V(-0.3 / len, 0.2 / len, 1.0 / len));
    run_free(&r);
}

/* Catmull-Clark limit masks, applied to the level-1 positions the library returns:
 *   smooth valence n: n/(n+5) v + 4/(n(n+5)) sum(edge nbrs) + 1/(n(n+5)) sum(diagonals)
 *   n = 3: 3/8, 1/6, 1/24; n = 4: 4/9, 1/9, 1/36 */
Test(limit, catmark_cube)
{
    sfb_mesh_desc d;
    cube_desc(&d, cube_pos);
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, SFB_REFINE_LIMIT);
    cr_assert_not_null(r.data.limit_positions);
    const float *q = r.data.positions; /* level-1 positions */
    /* V0' (index 0), valence 3 at level 1: edge neighbours E(0,3)=14, E(1,0)=17, E(4,0)=23;
     * diagonals: face points F0=8, F2=10, F5=13 */
    {
        v3 e = vadd(vmul(P(q, 0), 3.0 / 8),
                    vadd(vmul(vadd(vadd(P(q, 14), P(q, 17)), P(q, 23)), 1.0 / 6),
                         vmul(vadd(vadd(P(q, 8), P(q, 10)), P(q, 13)), 1.0 / 24)));
        check_vec("cube limit at V0'", 0, r.data.limit_positions, e);
    }
    /* face point F0 (index 8), valence 4: neighbours the edge points of f0 (14,15,16,17),
     * diagonals the corner children 0,3,2,1 */
    {
        v3 en = vadd(vadd(P(q, 14), P(q, 15)), vadd(P(q, 16), P(q, 17)));
        v3 dg = vadd(vadd(P(q, 0), P(q, 1)), vadd(P(q, 2), P(q, 3)));
        v3 e = vadd(vmul(P(q, 8), 4.0 / 9), vadd(vmul(en, 1.0 / 9), vmul(dg, 1.0 / 36)));
        check_vec("cube limit at F0", 8, r.data.limit_positions, e);
    }
    /* edge point E(0,1) (index 17), valence 4: neighbours V0'=0, V1'=1, F0=8, F2=10;
     * diagonals (opposite corners in its 4 child quads): E(2,1)=16, E(0,3)=14, E(4,0)=23, E(1,5)=22 */
    {
        v3 en = vadd(vadd(P(q, 0), P(q, 1)), vadd(P(q, 8), P(q, 10)));
        v3 dg = vadd(vadd(P(q, 16), P(q, 14)), vadd(P(q, 23), P(q, 22)));
        v3 e = vadd(vmul(P(q, 17), 4.0 / 9), vadd(vmul(en, 1.0 / 9), vmul(dg, 1.0 / 36)));
        check_vec("cube limit at E(0,1)", 17, r.data.limit_positions, e);
    }
    /* normals are unit length everywhere */
    for (int i = 0; i < r.data.vertex_count; ++i) {
        v3 n = out_pt(r.data.normals, i);
        double len = sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
        cr_expect(fabs(len - 1.0) < TOL, "normal %d length %f", i, len);
    }
    /* outward: the normal at V6' (the far corner) points away from the cube's centre */
    {
        v3 n = out_pt(r.data.normals, 6), c = V(0.5, 0.5, 0.5);
        v3 dir = vsub(P(q, 6), c);
        cr_expect_gt(n.x * dir.x + n.y * dir.y + n.z * dir.z, 0.0, "normal at vertex 6 points inward");
    }
    run_free(&r);
}

Test(limit, catmark_crease_corner_boundary)
{
    /* infinite crease loop on the cube top: at level 1, V4' is a crease vertex between
     * E(4,5)=18 and E(7,4)=21 -> limit 2/3 v + 1/6 (a + b) */
    {
        const float s[4] = { INF_SHARP, INF_SHARP, INF_SHARP, INF_SHARP };
        sfb_mesh_desc d;
        cube_desc(&d, cube_pos);
        d.crease_count = 4;
        d.crease_vertices = top_loop;
        d.crease_sharpness = s;
        run r;
        run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, SFB_REFINE_LIMIT);
        const float *q = r.data.positions;
        v3 e = vadd(vmul(P(q, 4), 2.0 / 3), vmul(vadd(P(q, 18), P(q, 21)), 1.0 / 6));
        check_vec("crease limit at V4'", 4, r.data.limit_positions, e);
        /* E(4,5) (index 18) is a crease vertex between V4' and V5' */
        v3 e2 = vadd(vmul(P(q, 18), 2.0 / 3), vmul(vadd(P(q, 4), P(q, 5)), 1.0 / 6));
        check_vec("crease limit at E(4,5)", 18, r.data.limit_positions, e2);
        run_free(&r);
    }
    /* open grid, edge-only: corner vertex 0 is a crease between E(0,1) and E(4,0) */
    {
        sfb_mesh_desc d;
        grid_desc(&d, SFB_BOUNDARY_EDGE_ONLY);
        run r;
        run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, SFB_REFINE_LIMIT);
        const float *q = r.data.positions;
        int a = grid_e(0, 1), b = grid_e(0, 4);
        v3 e = vadd(vmul(P(q, 0), 2.0 / 3), vmul(vadd(P(q, a), P(q, b)), 1.0 / 6));
        check_vec("edge-only boundary corner limit", 0, r.data.limit_positions, e);
        run_free(&r);
    }
    /* open grid, edge-and-corner: corner vertex 0 stays (limit = position = base position) */
    {
        sfb_mesh_desc d;
        grid_desc(&d, SFB_BOUNDARY_EDGE_AND_CORNER);
        run r;
        run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, SFB_REFINE_LIMIT);
        check_vec("edge-and-corner boundary corner limit", 0, r.data.limit_positions, P(grid_pos, 0));
        run_free(&r);
    }
}

/* Loop limit: neighbour weight 1/(n + 3/(8 gamma)), gamma = (5/8 - beta^2)/n.
 *   n = 4: gamma = 31/256, 3/(8 gamma) = 96/31, weight = 31/220, centre 1 - 124/220 = 24/55
 *   n = 6: 1/12 each, centre 1/2 */
Test(limit, loop_octahedron)
{
    sfb_mesh_desc d;
    oct_desc(&d);
    run r;
    run_refine(&r, &d, SFB_SCHEME_LOOP, 1, SFB_REFINE_LIMIT);
    cr_assert_not_null(r.data.limit_positions);
    const float *q = r.data.positions;
    /* V0' (valence 4): neighbours E(0,2)=6, E(4,0)=8, E(3,0)=13, E(0,5)=14 */
    {
        double beta = 0.375 + 0.25 * cos(2.0 * PI / 4);
        double gamma = (0.625 - beta * beta) / 4;
        double w = 1.0 / (4 + 3.0 / (8 * gamma));
        cr_assert(fabs(w - 31.0 / 220) < 1e-12);
        v3 nb = vadd(vadd(P(q, 6), P(q, 8)), vadd(P(q, 13), P(q, 14)));
        v3 e = vadd(vmul(P(q, 0), 24.0 / 55), vmul(nb, 31.0 / 220));
        check_vec("loop limit at V0' (valence 4)", 0, r.data.limit_positions, e);
    }
    /* E(0,2) (index 6, valence 6): V0'=0, V2'=2, E(2,4)=7, E(4,0)=8, E(0,5)=14, E(5,2)=15 */
    {
        v3 nb = vadd(vadd(vadd(P(q, 0), P(q, 2)), vadd(P(q, 7), P(q, 8))), vadd(P(q, 14), P(q, 15)));
        v3 e = vadd(vmul(P(q, 6), 0.5), vmul(nb, 1.0 / 12));
        check_vec("loop limit at E(0,2) (valence 6)", 6, r.data.limit_positions, e);
    }
    run_free(&r);

    /* Loop crease limit: equator infinitely sharp; V0' lies between E(0,2)=6 and E(3,0)=13 */
    const int cv[8] = { 0, 2, 2, 1, 1, 3, 3, 0 };
    const float cs[4] = { INF_SHARP, INF_SHARP, INF_SHARP, INF_SHARP };
    oct_desc(&d);
    d.crease_count = 4;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    run_refine(&r, &d, SFB_SCHEME_LOOP, 1, SFB_REFINE_LIMIT);
    q = r.data.positions;
    v3 e = vadd(vmul(P(q, 0), 2.0 / 3), vmul(vadd(P(q, 6), P(q, 13)), 1.0 / 6));
    check_vec("loop crease limit at V0'", 0, r.data.limit_positions, e);
    run_free(&r);
}

/* ========================================================================= */
/* face-varying UVs                                                           */

/* 2x1 quads: vertices 0 (0,0) 1 (1,0) 2 (2,0) 3 (0,1) 4 (1,1) 5 (2,1), faces f0 (0,1,4,3), f1 (1,2,5,4)
 * edges: e0 (0,1) e1 (1,4) e2 (4,3) e3 (3,0) e4 (1,2) e5 (2,5) e6 (5,4)
 * level 1: vertices 0..5, face points 6,7, edge points 8..14 */
static const float strip_pos[18] = {
    0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.1f, 2.0f, 0.0f, -0.1f, 0.0f, 1.0f, 0.2f, 1.0f, 1.0f, 0.0f, 2.0f, 1.0f, 0.15f,
};
static const int strip_sizes[2] = { 4, 4 };
static const int strip_fv[8] = { 0, 1, 4, 3, 1, 2, 5, 4 };

typedef struct { double u, v; } uv2;
static uv2 UV(double u, double v) { uv2 r; r.u = u; r.v = v; return r; }
static uv2 uvmid(uv2 a, uv2 b) { return UV(0.5 * (a.u + b.u), 0.5 * (a.v + b.v)); }
static uv2 uvavg4(uv2 a, uv2 b, uv2 c, uv2 d) { return UV(0.25 * (a.u + b.u + c.u + d.u), 0.25 * (a.v + b.v + c.v + d.v)); }

static void check_face_uvs(const sfb_mesh_data *d, int face, const uv2 *expect, const char *what)
{
    cr_assert_not_null(d->uvs);
    cr_assert_not_null(d->face_uvs);
    cr_assert_eq(d->face_sizes[face], 4);
    int off = face_offset(d, face);
    for (int i = 0; i < 4; ++i) {
        int k = d->face_uvs[off + i];
        cr_assert(k >= 0 && k < d->uv_count, "%s: uv index %d out of range", what, k);
        double u = d->uvs[2 * k], v = d->uvs[2 * k + 1];
        cr_expect(fabs(u - expect[i].u) < TOL && fabs(v - expect[i].v) < TOL,
                  "%s: face %d corner %d: expected uv (%f, %f), got (%f, %f)", what, face, i, expect[i].u,
                  expect[i].v, u, v);
    }
}

Test(uvs, linear_no_seam)
{
    /* one UV per vertex, not a plain scaling of the positions */
    static const float uvs[12] = { 0.0f, 0.0f, 0.45f, 0.05f, 1.0f, 0.0f, 0.0f, 1.0f, 0.55f, 0.9f, 1.0f, 1.0f };
    static const int fuv[8] = { 0, 1, 4, 3, 1, 2, 5, 4 };
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 6;
    d.positions = strip_pos;
    d.face_count = 2;
    d.face_sizes = strip_sizes;
    d.face_vertices = strip_fv;
    d.uv_count = 6;
    d.uvs = uvs;
    d.face_uvs = fuv;
    d.uv_interp = SFB_UV_LINEAR;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, SFB_REFINE_UVS);
    cr_assert_eq(r.data.vertex_count, 15);
    cr_expect_eq(r.data.uv_count, 15, "no seam: one UV per refined vertex, got %d", r.data.uv_count);
    uv2 t[6];
    for (int i = 0; i < 6; ++i) t[i] = UV(uvs[2 * i], uvs[2 * i + 1]);
    /* f0 corner 1: (V1', E(1,4), F0, E(0,1)) */
    {
        uv2 e[4] = { t[1], uvmid(t[1], t[4]), uvavg4(t[0], t[1], t[4], t[3]), uvmid(t[0], t[1]) };
        const int fv[4] = { 1, 9, 6, 8 };
        check_face(&r.data, 1, 4, fv);
        check_face_uvs(&r.data, 1, e, "no seam f0 corner 1");
    }
    /* f1 corner 0: (V1', E(1,2), F1, E(4,1)) */
    {
        uv2 e[4] = { t[1], uvmid(t[1], t[2]), uvavg4(t[1], t[2], t[5], t[4]), uvmid(t[4], t[1]) };
        const int fv[4] = { 1, 12, 7, 9 };
        check_face(&r.data, 4, 4, fv);
        check_face_uvs(&r.data, 4, e, "no seam f1 corner 0");
        /* literal for the face UV: ((0.45+1+1+0.55)/4, (0.05+0+1+0.9)/4) = (0.75, 0.4875) */
        cr_expect(fabs(e[2].u - 0.75) < 1e-6 && fabs(e[2].v - 0.4875) < 1e-6);
    }
    run_free(&r);
}

Test(uvs, linear_with_seam)
{
    /* the two faces are separate UV islands: f0 uses 0..3, f1 uses 4..7; the shared
     * vertices 1 and 4 get different UVs on each side */
    static const float uvs[16] = {
        0.0f, 0.0f, 0.4f, 0.0f, 0.4f, 1.0f, 0.0f, 1.0f,  /* f0: v0, v1, v4, v3 */
        0.6f, 0.0f, 1.0f, 0.1f, 1.0f, 1.0f, 0.6f, 0.9f,  /* f1: v1, v2, v5, v4 */
    };
    static const int fuv[8] = { 0, 1, 2, 3, 4, 5, 6, 7 };
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 6;
    d.positions = strip_pos;
    d.face_count = 2;
    d.face_sizes = strip_sizes;
    d.face_vertices = strip_fv;
    d.uv_count = 8;
    d.uvs = uvs;
    d.face_uvs = fuv;
    d.uv_interp = SFB_UV_LINEAR;
    run r;
    run_refine(&r, &d, SFB_SCHEME_CATMARK, 1, SFB_REFINE_UVS);
    cr_assert_eq(r.data.vertex_count, 15);
    /* seam vertices V1', V4' and E(1,4) carry two values each: 15 + 3 = 18 */
    cr_expect_gt(r.data.uv_count, r.data.vertex_count);
    cr_expect_eq(r.data.uv_count, 18, "uv count %d, expected 18", r.data.uv_count);
    uv2 t[8];
    for (int i = 0; i < 8; ++i) t[i] = UV(uvs[2 * i], uvs[2 * i + 1]);
    /* f0 corner 1: (V1', E(1,4), F0, E(0,1)) with f0's UVs t1 (v1), t2 (v4), t0 (v0), t3 (v3):
     * (0.4,0), (0.4,0.5), (0.2,0.5), (0.2,0) */
    uv2 e0[4] = { t[1], uvmid(t[1], t[2]), uvavg4(t[0], t[1], t[2], t[3]), uvmid(t[0], t[1]) };
    cr_expect(fabs(e0[2].u - 0.2) < 1e-7 && fabs(e0[2].v - 0.5) < 1e-7);
    check_face_uvs(&r.data, 1, e0, "seam f0 corner 1");
    /* f1 corner 0: (V1', E(1,2), F1, E(4,1)) with f1's UVs t4 (v1), t5 (v2), t6 (v5), t7 (v4) */
    uv2 e1[4] = { t[4], uvmid(t[4], t[5]), uvavg4(t[4], t[5], t[6], t[7]), uvmid(t[7], t[4]) };
    check_face_uvs(&r.data, 4, e1, "seam f1 corner 0");
    /* f1 corner 3: (V4', E(4,1), F1, E(5,4)) */
    uv2 e3[4] = { t[7], uvmid(t[7], t[4]), uvavg4(t[4], t[5], t[6], t[7]), uvmid(t[6], t[7]) };
    check_face_uvs(&r.data, 7, e3, "seam f1 corner 3");
    /* the same refined vertex (V1' = 1) uses different UV indices on the two sides */
    int k0 = r.data.face_uvs[face_offset(&r.data, 1) + 0];
    int k1 = r.data.face_uvs[face_offset(&r.data, 4) + 0];
    cr_expect_neq(k0, k1, "seam vertex shares one UV value");
    run_free(&r);
}
