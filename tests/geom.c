/* The rolling-ball operator's geometry modules on their own (white-box, through
 * src/sfb_internal.h, linked from libsfb_internal.o): src/aabb.c, src/sparse.c, src/trimesh.c.
 * Checks:
 *   - AABB tree: structure (boxes nest, leaves of <= 4, every finite triangle once, non-finite
 *     ones left out); pairs of one tree with itself and of two trees equal the brute-force pairs
 *     of overlapping triangle boxes (grown by eps) on random soups, several seeds, with ids;
 *     stopping; the nearest point equals brute force over this test's own closest-point
 *     routine (projection on the plane, else the nearest edge), and sfb__closest_on_triangle
 *     agrees with that routine (degenerate triangles: the longest edge);
 *   - triangle-triangle: crossing triangles give the analytic segment and its source edges;
 *     disjoint and separated-plane pairs 0; touching at a vertex, along an edge, a shared edge and
 *     a shared vertex; coplanar overlapping (2), touching (2) and disjoint (0); 1e-15 offsets
 *     (touching, crossing, coplanar noise, a shared edge with perturbed ends); zero-area and
 *     needle triangles never meet; random pairs against an independent check (return 1 exactly
 *     when some edge of one crosses the other; endpoints on both triangles and on their named
 *     edges within 1e-9; every edge crossing on the segment; the swapped pair gives the same);
 *   - self-intersections: none on a subdivided icosahedron, a subdivided cube (coplanar
 *     neighbours) and a flat grid; some after pushing a vertex through the sphere; a fold (two
 *     coplanar triangles on one side of their edge), a duplicate face and two triangles through
 *     each other from a shared vertex count, a shared vertex or edge alone does not;
 *   - sparse: triplets summed and sorted; bad indices rejected; the product against a dense one;
 *     conjugate gradients on a 2-D grid Laplacian (Dirichlet) against a dense Cholesky solution
 *     within 1e-8; a warm start at the solution; b = 0; non-convergence reported for an
 *     indefinite matrix, for too few iterations and for a non-positive diagonal;
 *   - measures: a unit icosphere (outward) gives normals within 1e-2 rad of radial and H within
 *     5 % of 1 (inward: -1), a flat (jittered) grid H = 0 inside and on the boundary, an open
 *     cylinder of radius R H = 1/(2R) within 5 % away from its boundary rows and 0 on them; the
 *     public sfb_mesh_vertex_normals / sfb_mesh_mean_curvature agree with the internals and reject
 *     a quad mesh (SFB_INVALID_TOPOLOGY naming face 0) and NULL arguments.
 * Usage: geom [SEED]. */
#define SURFBLEND_EXPOSE_INTERNALS /* the internals below have external linkage in libsfb_internal.o */
#include "surfblend.h"
#include "src/sfb_internal.h" /* the library's internal interfaces (linked from libsfb_internal.o) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"

static sfb_context *g_ctx;

/* ---- small vector helpers (the test's own) ---- */
static void vsub(const double *a, const double *b, double *c) { c[0] = a[0] - b[0]; c[1] = a[1] - b[1]; c[2] = a[2] - b[2]; }
static double vdot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void vcross(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
static double vdist(const double *a, const double *b) {
    double d[3];
    vsub(a, b, d);
    return sqrt(vdot(d, d));
}
static double vlen(const double *a) { return sqrt(vdot(a, a)); }

/* Distance from p to segment u-v. */
static double seg_dist(const double *p, const double *u, const double *v) {
    double e[3], w[3], t, l2, q[3];
    int k;
    vsub(v, u, e);
    vsub(p, u, w);
    l2 = vdot(e, e);
    t = l2 > 0 ? vdot(w, e) / l2 : 0;
    if (t < 0) t = 0;
    if (t > 1) t = 1;
    for (k = 0; k < 3; ++k) q[k] = u[k] + t * e[k];
    return vdist(p, q);
}
/* Barycentric coordinates of x (assumed in the plane) on triangle a b c (Gram matrix). */
static void ref_bary(const double *x, const double *a, const double *b, const double *c, double *w) {
    double v0[3], v1[3], v2[3], d00, d01, d11, d20, d21, den;
    vsub(b, a, v0);
    vsub(c, a, v1);
    vsub(x, a, v2);
    d00 = vdot(v0, v0); d01 = vdot(v0, v1); d11 = vdot(v1, v1); d20 = vdot(v2, v0); d21 = vdot(v2, v1);
    den = d00 * d11 - d01 * d01;
    w[1] = (d11 * d20 - d01 * d21) / den;
    w[2] = (d00 * d21 - d01 * d20) / den;
    w[0] = 1.0 - w[1] - w[2];
}
/* The test's own distance from p to triangle abc: the projection on the plane when inside, else the
 * nearest edge (non-degenerate triangles). */
static double ref_tri_dist(const double *p, const double *a, const double *b, const double *c) {
    double n[3], e0[3], e1[3], d, x[3], w[3], m;
    int k;
    vsub(b, a, e0);
    vsub(c, a, e1);
    vcross(e0, e1, n);
    d = vdot(n, n);
    if (d > 0) {
        double s[3];
        vsub(p, a, s);
        d = vdot(s, n) / d;
        for (k = 0; k < 3; ++k) x[k] = p[k] - d * n[k];
        ref_bary(x, a, b, c, w);
        if (w[0] >= 0 && w[1] >= 0 && w[2] >= 0) return vdist(p, x);
    }
    m = seg_dist(p, a, b);
    if (seg_dist(p, b, c) < m) m = seg_dist(p, b, c);
    if (seg_dist(p, c, a) < m) m = seg_dist(p, c, a);
    return m;
}
/* Does segment p-q cross triangle abc (generic position)? X gets the point. */
static int ref_seg_tri(const double *p, const double *q, const double *a, const double *b, const double *c, double *X) {
    double n[3], e0[3], e1[3], s[3], dp, dq, t, w[3];
    int k;
    vsub(b, a, e0);
    vsub(c, a, e1);
    vcross(e0, e1, n);
    vsub(p, a, s); dp = vdot(n, s);
    vsub(q, a, s); dq = vdot(n, s);
    if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || dp == dq) return 0;
    t = dp / (dp - dq);
    for (k = 0; k < 3; ++k) X[k] = p[k] + t * (q[k] - p[k]);
    ref_bary(X, a, b, c, w);
    return w[0] >= 0 && w[1] >= 0 && w[2] >= 0;
}

static void set3(double *p, double x, double y, double z) { p[0] = x; p[1] = y; p[2] = z; }

/* ---- the AABB tree ---- */

static void random_soup(rng *g, int n, double *pos, int *tri, double size) {
    int i, k, c;
    for (i = 0; i < n; ++i) {
        double ctr[3];
        for (k = 0; k < 3; ++k) ctr[k] = rng_unit(g);
        for (c = 0; c < 3; ++c) {
            for (k = 0; k < 3; ++k) pos[9 * (size_t)i + 3 * c + k] = ctr[k] + size * rng_range(g, -1, 1) * rng_unit(g);
            tri[3 * i + c] = 3 * i + c;
        }
    }
}
static void tri_box(const double *pos, const int *t, double *lo, double *hi) {
    int k, c;
    for (k = 0; k < 3; ++k) { lo[k] = HUGE_VAL; hi[k] = -HUGE_VAL; }
    for (c = 0; c < 3; ++c)
        for (k = 0; k < 3; ++k) {
            const double x = pos[3 * (size_t)t[c] + k];
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
        }
}
static int boxes_meet(const double *pos1, const int *t1, const double *pos2, const int *t2, double eps) {
    double l1[3], h1[3], l2[3], h2[3];
    int k;
    tri_box(pos1, t1, l1, h1);
    tri_box(pos2, t2, l2, h2);
    for (k = 0; k < 3; ++k)
        if (l1[k] - eps > h2[k] + eps || l2[k] - eps > h1[k] + eps) return 0;
    return 1;
}

typedef struct pairlist { long long *k; int n, cap, stop_after; } pairlist;
static int pair_cb(int i, int j, void *user) {
    pairlist *L = (pairlist *)user;
    if (L->n == L->cap) {
        long long *nk = (long long *)xmalloc(sizeof(long long) * (size_t)(L->cap ? 2 * L->cap : 1024));
        if (L->n) memcpy(nk, L->k, sizeof(long long) * (size_t)L->n);
        free(L->k);
        L->k = nk;
        L->cap = L->cap ? 2 * L->cap : 1024;
    }
    L->k[L->n++] = ((long long)i << 32) | (unsigned)j;
    return L->stop_after > 0 && L->n >= L->stop_after;
}
static int cmp_ll(const void *a, const void *b) {
    const long long x = *(const long long *)a, y = *(const long long *)b;
    return x < y ? -1 : x > y;
}
/* self: normalise to (min, max) */
static void pairs_sort(pairlist *L, int self) {
    int i;
    if (self)
        for (i = 0; i < L->n; ++i) {
            const int a = (int)(L->k[i] >> 32), b = (int)(L->k[i] & 0xffffffff);
            if (a > b) L->k[i] = ((long long)b << 32) | (unsigned)a;
        }
    qsort(L->k, (size_t)L->n, sizeof(long long), cmp_ll);
}

/* Nodes nest, leaves hold <= 4, the items are exactly `expect` (sorted copy given). */
static int tree_ok(const sfb__aabb *t, const int *expect, int ne, char *why, size_t wn) {
    int i, k, *seen;
    if (t->item_count != ne) { snprintf(why, wn, "%d items, expected %d", t->item_count, ne); return 0; }
    if (ne == 0) return t->node_count == 0;
    for (i = 0; i < t->node_count; ++i) {
        const sfb__aabb_node *n = &t->nodes[i];
        if (n->left < 0) {
            if (n->count < 1 || n->count > 4) { snprintf(why, wn, "leaf %d has %d items", i, n->count); return 0; }
            for (k = n->first; k < n->first + n->count; ++k) {
                const sfb__aabb_node *b = &t->nodes[t->node_count + k];
                int c;
                for (c = 0; c < 3; ++c)
                    if (b->lo[c] < n->lo[c] || b->hi[c] > n->hi[c]) { snprintf(why, wn, "item box outside leaf %d", i); return 0; }
            }
        } else {
            const sfb__aabb_node *ch[2];
            int c, s;
            ch[0] = &t->nodes[n->left];
            ch[1] = &t->nodes[n->right];
            if (ch[0]->count + ch[1]->count != n->count) { snprintf(why, wn, "node %d: children counts", i); return 0; }
            for (s = 0; s < 2; ++s)
                for (c = 0; c < 3; ++c)
                    if (ch[s]->lo[c] < n->lo[c] || ch[s]->hi[c] > n->hi[c]) { snprintf(why, wn, "node %d: child box outside", i); return 0; }
        }
    }
    seen = (int *)xmalloc(sizeof(int) * (size_t)ne);
    memcpy(seen, t->items, sizeof(int) * (size_t)ne);
    qsort(seen, (size_t)ne, sizeof(int), harness_cmp_int);
    for (i = 0; i < ne; ++i)
        if (seen[i] != expect[i]) { snprintf(why, wn, "items are not the finite triangles' ids"); free(seen); return 0; }
    free(seen);
    return 1;
}

static void test_tree(unsigned long long seed) {
    const int n = 400, n2 = 250;
    double *pos = (double *)xmalloc(sizeof(double) * 9 * (size_t)n), *pos2 = (double *)xmalloc(sizeof(double) * 9 * (size_t)n2);
    int *tri = (int *)xmalloc(sizeof(int) * 3 * (size_t)n), *tri2 = (int *)xmalloc(sizeof(int) * 3 * (size_t)n2);
    int *ids = (int *)xmalloc(sizeof(int) * (size_t)n), *expect = (int *)xmalloc(sizeof(int) * (size_t)n);
    int *row_of_id = (int *)xmalloc(sizeof(int) * (size_t)(7 * n + 10));
    rng g = rng_for(seed, 1);
    char nm[128], why[256];
    sfb__aabb t, t2;
    pairlist got, ref;
    int i, j, ok, ne = 0, bad = 0, q;
    const double eps = 1e-3;
    random_soup(&g, n, pos, tri, 0.08);
    random_soup(&g, n2, pos2, tri2, 0.12);
    pos[9 * 17 + 4] = NAN; /* triangle 17 is left out */
    pos[9 * 100 + 0] = HUGE_VAL; /* and 100 */
    for (i = 0; i < n; ++i) {
        ids[i] = 7 * i + 3;
        row_of_id[7 * i + 3] = i;
        if (i != 17 && i != 100) expect[ne++] = 7 * i + 3;
    }
    /* one tree with itself, ids */
    snprintf(nm, sizeof nm, "aabb/build (seed %llu)", seed);
    if (sfb__aabb_build(g_ctx, pos, tri, ids, n, &t) != SFB_SUCCESS) { fail(nm, "%s", sfb_last_error(g_ctx)); return; }
    why[0] = 0;
    check(tree_ok(&t, expect, ne, why, sizeof why), nm, "%s", why);
    memset(&got, 0, sizeof got);
    memset(&ref, 0, sizeof ref);
    sfb__aabb_pairs(&t, &t, eps, pair_cb, &got);
    pairs_sort(&got, 1);
    for (i = 0; i < n; ++i)
        for (j = i + 1; j < n; ++j) {
            if (i == 17 || i == 100 || j == 17 || j == 100) continue;
            if (boxes_meet(pos, tri + 3 * i, pos, tri + 3 * j, eps)) pair_cb(ids[i], ids[j], &ref);
        }
    pairs_sort(&ref, 1);
    ok = got.n == ref.n && (got.n == 0 || !memcmp(got.k, ref.k, sizeof(long long) * (size_t)got.n));
    snprintf(nm, sizeof nm, "aabb/pairs_self (seed %llu)", seed);
    check(ok && ref.n > 20, nm, "%d pairs, brute force %d", got.n, ref.n);
    /* two trees */
    if (sfb__aabb_build(g_ctx, pos2, tri2, NULL, n2, &t2) != SFB_SUCCESS) { fail(nm, "%s", sfb_last_error(g_ctx)); return; }
    got.n = ref.n = 0;
    sfb__aabb_pairs(&t, &t2, 0.0, pair_cb, &got);
    pairs_sort(&got, 0);
    for (i = 0; i < n; ++i)
        for (j = 0; j < n2; ++j) {
            if (i == 17 || i == 100) continue;
            if (boxes_meet(pos, tri + 3 * i, pos2, tri2 + 3 * j, 0.0)) pair_cb(ids[i], j, &ref);
        }
    pairs_sort(&ref, 0);
    ok = got.n == ref.n && (got.n == 0 || !memcmp(got.k, ref.k, sizeof(long long) * (size_t)got.n));
    snprintf(nm, sizeof nm, "aabb/pairs_two_trees (seed %llu)", seed);
    check(ok && ref.n > 50, nm, "%d pairs, brute force %d", got.n, ref.n);
    /* stopping */
    got.n = 0;
    got.stop_after = 5;
    i = sfb__aabb_pairs(&t, &t, eps, pair_cb, &got);
    snprintf(nm, sizeof nm, "aabb/pairs_stop (seed %llu)", seed);
    check(i == 1 && got.n == 5, nm, "returned %d after %d pairs", i, got.n);
    got.stop_after = 0;
    /* nearest: brute force over the test's own distance */
    for (q = 0; q < 300; ++q) {
        double p[3], pt[3], d2, bary[3], best = HUGE_VAL, x[3];
        int id, k;
        for (k = 0; k < 3; ++k) p[k] = rng_range(&g, -0.3, 1.3);
        id = sfb__aabb_nearest(&t, pos, tri, row_of_id, p, pt, &d2, bary);
        for (i = 0; i < n; ++i) {
            double d;
            if (i == 17 || i == 100) continue;
            d = ref_tri_dist(p, pos + 9 * i, pos + 9 * i + 3, pos + 9 * i + 6);
            if (d < best) best = d;
        }
        if (id < 0 || (id - 3) % 7 != 0) { bad++; continue; }
        j = row_of_id[id];
        for (k = 0; k < 3; ++k) x[k] = bary[0] * pos[9 * j + k] + bary[1] * pos[9 * j + 3 + k] + bary[2] * pos[9 * j + 6 + k];
        if (fabs(sqrt(d2) - best) > 1e-12 || vdist(x, pt) > 1e-12 || fabs(vdist(p, pt) - best) > 1e-12 ||
            fabs(bary[0] + bary[1] + bary[2] - 1) > 1e-12 || bary[0] < -1e-12 || bary[1] < -1e-12 || bary[2] < -1e-12)
            bad++;
    }
    snprintf(nm, sizeof nm, "aabb/nearest_brute_force (seed %llu)", seed);
    check(bad == 0, nm, "%d of 300 queries differ from brute force", bad);
    free(got.k);
    free(ref.k);
    sfb__aabb_free(g_ctx, &t);
    sfb__aabb_free(g_ctx, &t2);
    free(pos); free(pos2); free(tri); free(tri2); free(ids); free(expect); free(row_of_id);
}

static void test_tree_edges(void) {
    sfb__aabb t;
    double pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, p[3] = {0.2, 0.2, 1}, pt[3], d2;
    int tri[3] = {0, 1, 2}, r, id;
    pairlist L;
    memset(&L, 0, sizeof L);
    r = sfb__aabb_build(g_ctx, pos, tri, NULL, 0, &t);
    id = sfb__aabb_nearest(&t, pos, tri, NULL, p, pt, &d2, NULL);
    check(r == SFB_SUCCESS && t.node_count == 0 && id == -1 && sfb__aabb_pairs(&t, &t, 0, pair_cb, &L) == 0 && L.n == 0, "aabb/empty",
          "r %d nodes %d id %d", r, t.node_count, id);
    sfb__aabb_free(g_ctx, &t);
    r = sfb__aabb_build(g_ctx, pos, tri, NULL, 1, &t);
    id = sfb__aabb_nearest(&t, pos, tri, NULL, p, pt, &d2, NULL);
    check(r == SFB_SUCCESS && id == 0 && fabs(d2 - 1) < 1e-15 && fabs(pt[0] - 0.2) < 1e-15 && fabs(pt[1] - 0.2) < 1e-15 && pt[2] == 0,
          "aabb/one_triangle", "id %d d2 %g", id, d2);
    sfb__aabb_pairs(&t, &t, 1.0, pair_cb, &L);
    check(L.n == 0, "aabb/self_pairs_skip_same_id", "%d pairs", L.n);
    sfb__aabb_free(g_ctx, &t);
    free(L.k);
    check(sfb__aabb_build(g_ctx, NULL, tri, NULL, 1, &t) == SFB_INVALID_ARGS, "aabb/null_arrays", "accepted");
}

static void test_closest(unsigned long long seed) {
    rng g = rng_for(seed, 2);
    int i, bad = 0, k;
    for (i = 0; i < 2000; ++i) {
        double a[3], b[3], c[3], p[3], q[3], w[3], x[3];
        for (k = 0; k < 3; ++k) { a[k] = rng_unit(&g); b[k] = rng_unit(&g); c[k] = rng_unit(&g); p[k] = rng_range(&g, -1, 2); }
        sfb__closest_on_triangle(p, a, b, c, q, w);
        for (k = 0; k < 3; ++k) x[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
        if (fabs(vdist(p, q) - ref_tri_dist(p, a, b, c)) > 1e-12 || vdist(x, q) > 1e-12 || w[0] < -1e-12 || w[1] < -1e-12 ||
            w[2] < -1e-12 || fabs(w[0] + w[1] + w[2] - 1) > 1e-12)
            bad++;
    }
    check(bad == 0, "closest/random_vs_reference", "%d of 2000 differ", bad);
    {
        /* degenerate: collinear a, b, c (longest edge a-c), and one point */
        double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {3, 0, 0}, p[3] = {2.5, 1, 0}, q[3], w[3];
        sfb__closest_on_triangle(p, a, b, c, q, w);
        check(fabs(q[0] - 2.5) < 1e-15 && q[1] == 0 && q[2] == 0 && fabs(w[0] - 1.0 / 6) < 1e-15 && w[1] == 0 && fabs(w[2] - 5.0 / 6) < 1e-15,
              "closest/degenerate_longest_edge", "q %g %g %g w %g %g %g", q[0], q[1], q[2], w[0], w[1], w[2]);
        sfb__closest_on_triangle(p, a, a, a, q, w);
        check(q[0] == 0 && q[1] == 0 && q[2] == 0 && fabs(w[0] + w[1] + w[2] - 1) < 1e-15, "closest/degenerate_point", "q %g %g %g", q[0], q[1], q[2]);
    }
}

/* ---- triangle-triangle ---- */

typedef struct ttres { int r, src0, src1; double s0[3], s1[3]; } ttres;
static ttres tt(const double *A, const double *B) {
    ttres o;
    memset(&o, 0, sizeof o);
    o.src0 = o.src1 = -9;
    o.r = sfb__tri_tri_segment(A, A + 3, A + 6, B, B + 3, B + 6, o.s0, o.s1, &o.src0, &o.src1);
    return o;
}
/* Is the segment {s0, s1} equal (either order) to {p, q} within tol? */
static int seg_is(const ttres *o, const double *p, const double *q, double tol) {
    return (vdist(o->s0, p) <= tol && vdist(o->s1, q) <= tol) || (vdist(o->s0, q) <= tol && vdist(o->s1, p) <= tol);
}
static const double *tt_edge(const double *A, const double *B, int src, int end) {
    const double *T = src < 3 ? A : B;
    const int k = src % 3;
    return T + 3 * ((k + end) % 3);
}

static void test_tritri_cases(void) {
    double A[9] = {0, 0, 0, 2, 0, 0, 0, 2, 0}, B[9], p[3], q[3];
    ttres o;
    int k;
    /* crossing: b in the plane x = 0.5 meets a along y in [0, 1] */
    {
        double Bx[9] = {0.5, -1, -1, 0.5, 3, -1, 0.5, -1, 1};
        memcpy(B, Bx, sizeof B);
    }
    o = tt(A, B);
    set3(p, 0.5, 0, 0);
    set3(q, 0.5, 1, 0);
    check(o.r == 1 && vdist(o.s0, p) < 1e-14 && vdist(o.s1, q) < 1e-14 && o.src0 == 0 && o.src1 == 4, "tritri/crossing",
          "r %d s0 %g %g %g s1 %g %g %g src %d %d", o.r, o.s0[0], o.s0[1], o.s0[2], o.s1[0], o.s1[1], o.s1[2], o.src0, o.src1);
    o = tt(B, A); /* swapped: the same segment, sources the other way */
    check(o.r == 1 && seg_is(&o, p, q, 1e-14) && ((o.src0 == 3 && o.src1 == 1) || (o.src0 == 1 && o.src1 == 3)), "tritri/crossing_swapped",
          "r %d src %d %d", o.r, o.src0, o.src1);
    /* disjoint: moved away along x, and b wholly above a's plane */
    for (k = 0; k < 3; ++k) B[3 * k] += 10;
    check(tt(A, B).r == 0, "tritri/disjoint", "met");
    {
        double Bz[9] = {0.2, 0.2, 0.5, 1.0, 0.2, 0.7, 0.2, 1.0, 0.6};
        check(tt(A, Bz).r == 0, "tritri/separated_planes", "met");
        /* b crosses a's plane, but beside a (a's interval and b's disjoint on the line) */
    }
    {
        double Bs[9] = {3, 3, -1, 4, 3, 1, 3, 4, 1};
        check(tt(A, Bs).r == 0, "tritri/planes_cross_beside", "met");
    }
    /* touching at a vertex: b's vertex on a's interior, the rest above */
    {
        double Bt[9] = {0.5, 0.5, 0, 1, 0.5, 1, 0.5, 1, 1};
        set3(p, 0.5, 0.5, 0);
        o = tt(A, Bt);
        check(o.r == 1 && vdist(o.s0, p) < 1e-15 && vdist(o.s1, p) < 1e-15, "tritri/touch_vertex", "r %d s0 %g %g %g", o.r, o.s0[0], o.s0[1], o.s0[2]);
        /* a's vertex on b's interior */
        {
            double At[9] = {0.3, 0.3, 0, 1, 1, 1, 0.5, 0.2, 2}, Bb[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
            set3(p, 0.3, 0.3, 0);
            o = tt(At, Bb);
            check(o.r == 1 && vdist(o.s0, p) < 1e-15 && vdist(o.s1, p) < 1e-15, "tritri/touch_vertex_of_a", "r %d", o.r);
        }
    }
    /* touching along an edge: b's edge v0-v1 in a's interior, v2 above */
    {
        double Be[9] = {0.2, 0.3, 0, 0.9, 0.4, 0, 0.5, 0.5, 1};
        o = tt(A, Be);
        check(o.r == 1 && seg_is(&o, Be, Be + 3, 1e-15) && o.src0 == 3 && o.src1 == 3, "tritri/touch_edge", "r %d src %d %d", o.r, o.src0, o.src1);
        /* the edge runs out of a: clipped at a's hypotenuse x + y = 2 */
        {
            double Bf[9] = {0.5, 0.5, 0, 3, 0.5, 0, 1, 1, -1};
            set3(q, 1.5, 0.5, 0);
            o = tt(A, Bf);
            check(o.r == 1 && seg_is(&o, Bf, q, 1e-14), "tritri/touch_edge_clipped", "r %d s0 %g %g %g s1 %g %g %g", o.r, o.s0[0], o.s0[1],
                  o.s0[2], o.s1[0], o.s1[1], o.s1[2]);
        }
    }
    /* a shared edge (a's edge 0), b folded up: the edge; a shared vertex: the vertex */
    {
        double Bse[9] = {0, 0, 0, 2, 0, 0, 0.3, -0.2, 0.7}, Bsv[9] = {0, 0, 0, -1, -0.5, 0.3, -0.2, -1, -0.4};
        o = tt(A, Bse);
        check(o.r == 1 && seg_is(&o, A, A + 3, 0) && o.src0 % 3 == 0 && o.src1 % 3 == 0, "tritri/shared_edge", "r %d src %d %d", o.r, o.src0,
              o.src1);
        o = tt(A, Bsv);
        check(o.r == 1 && vdist(o.s0, A) == 0 && vdist(o.s1, A) == 0, "tritri/shared_vertex", "r %d s0 %g %g %g s1 %g %g %g", o.r, o.s0[0],
              o.s0[1], o.s0[2], o.s1[0], o.s1[1], o.s1[2]);
    }
    /* coplanar */
    {
        double Bo[9] = {0.5, 0.5, 0, 3, 0.5, 0, 0.5, 3, 0}, Bd[9] = {1.5, 1.5, 0, 3, 1.5, 0, 1.5, 3, 0}, Bt[9] = {2, 0, 0, 0, 2, 0, 2, 2, 0};
        double Bin[9] = {0.1, 0.1, 0, 0.5, 0.1, 0, 0.1, 0.5, 0}, Bv[9] = {2, 0, 0, 3, 0, 0, 3, 1, 0};
        check(tt(A, Bo).r == 2, "tritri/coplanar_overlap", "r %d", tt(A, Bo).r);
        check(tt(A, Bin).r == 2 && tt(Bin, A).r == 2, "tritri/coplanar_inside", "r %d", tt(A, Bin).r);
        check(tt(A, Bd).r == 0, "tritri/coplanar_disjoint", "r %d", tt(A, Bd).r);
        check(tt(A, Bt).r == 2, "tritri/coplanar_touching_edge", "r %d", tt(A, Bt).r);
        check(tt(A, Bv).r == 2, "tritri/coplanar_touching_vertex", "r %d", tt(A, Bv).r);
    }
    /* 1e-15 offsets */
    {
        double Bu[9] = {0.5, 0.5, 1e-15, 1, 0.5, 1, 0.5, 1, 1}, Bd[9] = {0.5, 0.5, -1e-15, 1, 0.5, 1, 0.5, 1, 1};
        double Bn[9] = {0.5, 0.5, 1e-15, 3, 0.5, -1e-15, 0.5, 3, 2e-15};
        double Bse[9] = {1e-15, -1e-15, 1e-15, 2 - 1e-15, 1e-15, -1e-15, 0.3, -0.2, 0.7};
        set3(p, 0.5, 0.5, 0);
        o = tt(A, Bu);
        check(o.r == 1 && vdist(o.s0, p) < 1e-14 && vdist(o.s1, p) < 1e-14, "tritri/near_touch_above", "r %d", o.r);
        o = tt(A, Bd);
        check(o.r == 1 && vdist(o.s0, p) < 1e-14 && vdist(o.s1, p) < 1e-14, "tritri/near_touch_below", "r %d", o.r);
        check(tt(A, Bn).r == 2, "tritri/near_coplanar", "r %d", tt(A, Bn).r);
        o = tt(A, Bse);
        check(o.r == 1 && seg_is(&o, A, A + 3, 1e-14), "tritri/near_shared_edge", "r %d s0 %g %g %g s1 %g %g %g", o.r, o.s0[0], o.s0[1], o.s0[2],
              o.s1[0], o.s1[1], o.s1[2]);
    }
    /* zero area */
    {
        double Bl[9] = {0.5, 0.5, -1, 0.5, 0.5, 0, 0.5, 0.5, 1}, Bp[9] = {0.5, 0.5, 0, 0.5, 0.5, 0, 0.5, 0.5, 0};
        double Bneedle[9] = {0.5, 0.5, -1, 0.5, 0.5, 1, 0.5, 0.5 + 1e-14, 0};
        double Across[9] = {0.5, -1, -1, 0.5, 3, -1, 0.5, -1, 1};
        check(tt(A, Bl).r == 0 && tt(Bl, A).r == 0, "tritri/zero_area_collinear", "met");
        check(tt(A, Bp).r == 0 && tt(Bp, A).r == 0, "tritri/zero_area_point", "met");
        check(tt(A, Bneedle).r == 0 && tt(Bneedle, A).r == 0, "tritri/zero_area_needle", "met");
        check(tt(Bl, Bl).r == 0 && tt(Across, Across).r == 2, "tritri/self_pair", "degenerate met itself or a triangle missed itself");
    }
}

static void test_tritri_random(unsigned long long seed) {
    rng g = rng_for(seed, 3);
    int i, k, bad = 0, hits = 0, firstbad = -1;
    char nm[96], what[200] = "";
    for (i = 0; i < 20000; ++i) {
        double A[9], B[9], X[3];
        ttres o, o2;
        int crossings = 0, e, ok = 1;
        double cx[6][3];
        for (k = 0; k < 9; ++k) { A[k] = rng_unit(&g); B[k] = rng_unit(&g); }
        o = tt(A, B);
        o2 = tt(B, A);
        for (e = 0; e < 3; ++e) {
            if (ref_seg_tri(A + 3 * e, A + 3 * ((e + 1) % 3), B, B + 3, B + 6, X)) memcpy(cx[crossings++], X, sizeof X);
            if (ref_seg_tri(B + 3 * e, B + 3 * ((e + 1) % 3), A, A + 3, A + 6, X)) memcpy(cx[crossings++], X, sizeof X);
        }
        if ((o.r == 1) != (crossings > 0) || o.r == 2) { ok = 0; snprintf(what, sizeof what, "r %d with %d crossings", o.r, crossings); }
        else if (o.r == 1) {
            const double d0a = ref_tri_dist(o.s0, A, A + 3, A + 6), d0b = ref_tri_dist(o.s0, B, B + 3, B + 6);
            const double d1a = ref_tri_dist(o.s1, A, A + 3, A + 6), d1b = ref_tri_dist(o.s1, B, B + 3, B + 6);
            hits++;
            if (d0a > 1e-9 || d0b > 1e-9 || d1a > 1e-9 || d1b > 1e-9) { ok = 0; snprintf(what, sizeof what, "endpoint off a triangle"); }
            if (o.src0 < 0 || o.src0 > 5 || o.src1 < 0 || o.src1 > 5 ||
                seg_dist(o.s0, tt_edge(A, B, o.src0, 0), tt_edge(A, B, o.src0, 1)) > 1e-9 ||
                seg_dist(o.s1, tt_edge(A, B, o.src1, 0), tt_edge(A, B, o.src1, 1)) > 1e-9) {
                ok = 0;
                snprintf(what, sizeof what, "endpoint not on its source edge (%d %d)", o.src0, o.src1);
            }
            for (e = 0; e < crossings; ++e)
                if (seg_dist(cx[e], o.s0, o.s1) > 1e-9) { ok = 0; snprintf(what, sizeof what, "a crossing off the segment"); }
            if (o2.r != 1 || !seg_is(&o2, o.s0, o.s1, 1e-12)) { ok = 0; snprintf(what, sizeof what, "swapped pair differs"); }
        } else if (o2.r != 0) { ok = 0; snprintf(what, sizeof what, "swapped pair met"); }
        if (!ok) { bad++; if (firstbad < 0) firstbad = i; }
    }
    snprintf(nm, sizeof nm, "tritri/random_vs_edge_crossings (seed %llu)", seed);
    check(bad == 0 && hits > 2000, nm, "%d of 20000 pairs wrong (first %d: %s), %d meeting", bad, firstbad, what, hits);
}

/* ---- meshes ---- */

typedef struct tmesh { int nv, nf; double *pos; int *tri; } tmesh;
static void tmesh_free(tmesh *m) { free(m->pos); free(m->tri); memset(m, 0, sizeof *m); }

/* A unit icosphere (level subdivisions of the icosahedron, outward). */
static tmesh icosphere(int level) {
    const double ph = (1 + sqrt(5.0)) / 2;
    const double base[12][3] = {{-1, ph, 0}, {1, ph, 0}, {-1, -ph, 0}, {1, -ph, 0}, {0, -1, ph}, {0, 1, ph},
                                {0, -1, -ph}, {0, 1, -ph}, {ph, 0, -1}, {ph, 0, 1}, {-ph, 0, -1}, {-ph, 0, 1}};
    int nvmax = 12, nfmax = 20, l, i, j, k, f;
    tmesh m;
    for (l = 0; l < level; ++l) { nvmax += nfmax * 3 / 2; nfmax *= 4; }
    m.pos = (double *)xmalloc(sizeof(double) * 3 * (size_t)nvmax);
    m.tri = (int *)xmalloc(sizeof(int) * 3 * (size_t)nfmax);
    m.nv = 12;
    m.nf = 0;
    for (i = 0; i < 12; ++i)
        for (k = 0; k < 3; ++k) m.pos[3 * i + k] = base[i][k];
    /* the 20 faces: triples at mutual distance 2, turned outward */
    for (i = 0; i < 12; ++i)
        for (j = i + 1; j < 12; ++j)
            for (k = j + 1; k < 12; ++k)
                if (fabs(vdist(base[i], base[j]) - 2) < 1e-9 && fabs(vdist(base[j], base[k]) - 2) < 1e-9 && fabs(vdist(base[i], base[k]) - 2) < 1e-9) {
                    double e0[3], e1[3], n[3];
                    vsub(base[j], base[i], e0);
                    vsub(base[k], base[i], e1);
                    vcross(e0, e1, n);
                    m.tri[3 * m.nf] = i;
                    m.tri[3 * m.nf + 1] = vdot(n, base[i]) > 0 ? j : k;
                    m.tri[3 * m.nf + 2] = vdot(n, base[i]) > 0 ? k : j;
                    m.nf++;
                }
    for (l = 0; l < level; ++l) {
        /* midpoints, found through each vertex's list of (neighbour, midpoint) */
        int *nb = (int *)xmalloc(sizeof(int) * 16 * (size_t)m.nv), *nn = (int *)calloc((size_t)m.nv, sizeof(int));
        int *nt = (int *)xmalloc(sizeof(int) * 12 * (size_t)m.nf);
        for (f = 0; f < m.nf; ++f) {
            int mid[3], c;
            for (c = 0; c < 3; ++c) {
                const int a = m.tri[3 * f + c], b = m.tri[3 * f + (c + 1) % 3], lo = a < b ? a : b, hi = a < b ? b : a;
                int s, found = -1;
                for (s = 0; s < nn[lo]; ++s)
                    if (nb[16 * lo + 2 * s] == hi) found = nb[16 * lo + 2 * s + 1];
                if (found < 0) {
                    found = m.nv++;
                    for (k = 0; k < 3; ++k) m.pos[3 * found + k] = 0.5 * (m.pos[3 * a + k] + m.pos[3 * b + k]);
                    nb[16 * lo + 2 * nn[lo]] = hi;
                    nb[16 * lo + 2 * nn[lo] + 1] = found;
                    nn[lo]++;
                }
                mid[c] = found;
            }
            {
                const int *t = m.tri + 3 * f;
                const int q[12] = {t[0], mid[0], mid[2], mid[0], t[1], mid[1], mid[2], mid[1], t[2], mid[0], mid[1], mid[2]};
                memcpy(nt + 12 * f, q, sizeof q);
            }
        }
        free(m.tri);
        m.tri = nt;
        m.nf *= 4;
        free(nb);
        free(nn);
        /* nb was sized for the old vertex count: grow it next time from m.nv */
    }
    for (i = 0; i < m.nv; ++i) {
        const double r = vlen(m.pos + 3 * i);
        for (k = 0; k < 3; ++k) m.pos[3 * i + k] /= r;
    }
    return m;
}

/* A cube [-1,1]^3 with an n x n grid of quads per side, welded, two triangles per quad, outward. */
static tmesh grid_cube(int n) {
    tmesh m;
    const int per = (n + 1) * (n + 1);
    int *idx = (int *)xmalloc(sizeof(int) * 6 * (size_t)per), s, i, j, k, v;
    m.pos = (double *)xmalloc(sizeof(double) * 3 * 6 * (size_t)per);
    m.tri = (int *)xmalloc(sizeof(int) * 6 * 6 * (size_t)n * (size_t)n);
    m.nv = m.nf = 0;
    for (s = 0; s < 6; ++s) {
        const int ax = s / 2;
        const double sg = s % 2 ? 1.0 : -1.0;
        for (i = 0; i <= n; ++i)
            for (j = 0; j <= n; ++j) {
                double p[3];
                p[ax] = sg;
                p[(ax + 1) % 3] = -1 + 2.0 * i / n;
                p[(ax + 2) % 3] = -1 + 2.0 * j / n;
                for (v = 0; v < m.nv; ++v)
                    if (vdist(m.pos + 3 * v, p) < 1e-12) break;
                if (v == m.nv) { memcpy(m.pos + 3 * v, p, sizeof p); m.nv++; }
                idx[s * per + i * (n + 1) + j] = v;
            }
        for (i = 0; i < n; ++i)
            for (j = 0; j < n; ++j) {
                const int a = idx[s * per + i * (n + 1) + j], b = idx[s * per + (i + 1) * (n + 1) + j], c = idx[s * per + (i + 1) * (n + 1) + j + 1],
                          d = idx[s * per + i * (n + 1) + j + 1];
                const int q[6] = {a, b, c, a, c, d};
                for (k = 0; k < 2; ++k) {
                    double e0[3], e1[3], nrm[3];
                    int *t = m.tri + 3 * m.nf;
                    memcpy(t, q + 3 * k, 3 * sizeof(int));
                    vsub(m.pos + 3 * t[1], m.pos + 3 * t[0], e0);
                    vsub(m.pos + 3 * t[2], m.pos + 3 * t[0], e1);
                    vcross(e0, e1, nrm);
                    if (nrm[ax] * sg < 0) { const int x = t[1]; t[1] = t[2]; t[2] = x; }
                    m.nf++;
                }
            }
    }
    free(idx);
    return m;
}

/* An (nx+1) x (ny+1) grid of the unit square in z = 0 (interior vertices jittered in the plane by
 * up to `jitter` of a cell), or, with R > 0, an open cylinder of radius R around z: nx around,
 * ny rows of height h. Two triangles per cell, normals +z (or outward). */
static tmesh grid(int nx, int ny, double jitter, double R, double h, rng *g) {
    tmesh m;
    const int cols = R > 0 ? nx : nx + 1;
    int i, j;
    m.nv = cols * (ny + 1);
    m.nf = 2 * nx * ny;
    m.pos = (double *)xmalloc(sizeof(double) * 3 * (size_t)m.nv);
    m.tri = (int *)xmalloc(sizeof(int) * 3 * (size_t)m.nf);
    for (j = 0; j <= ny; ++j)
        for (i = 0; i < cols; ++i) {
            double *p = m.pos + 3 * (j * cols + i);
            if (R > 0) {
                const double th = 2 * SFB__PI * i / nx;
                set3(p, R * cos(th), R * sin(th), h * j);
            } else {
                set3(p, (double)i / nx, (double)j / ny, 0);
                if (i > 0 && i < nx && j > 0 && j < ny && g) {
                    p[0] += jitter / nx * rng_range(g, -1, 1);
                    p[1] += jitter / ny * rng_range(g, -1, 1);
                }
            }
        }
    for (j = 0; j < ny; ++j)
        for (i = 0; i < nx; ++i) {
            const int a = j * cols + i, b = j * cols + (i + 1) % cols, c = (j + 1) * cols + (i + 1) % cols, d = (j + 1) * cols + i;
            int *t = m.tri + 6 * (j * nx + i);
            t[0] = a; t[1] = b; t[2] = c;
            t[3] = a; t[4] = c; t[5] = d;
        }
    return m;
}

static void test_self(void) {
    tmesh s = icosphere(3), c = grid_cube(4), f = grid(8, 8, 0.3, 0, 0, NULL);
    long n = -1;
    int first[2] = {0, 0}, v, k;
    sfb_result r;
    r = sfb__trimesh_self_intersections(g_ctx, s.pos, s.tri, s.nf, &n, first);
    check(r == SFB_SUCCESS && n == 0 && first[0] == -1 && first[1] == -1, "self/icosphere_none", "r %d pairs %ld (first %d %d)", r, n, first[0],
          first[1]);
    r = sfb__trimesh_self_intersections(g_ctx, c.pos, c.tri, c.nf, &n, first);
    check(r == SFB_SUCCESS && n == 0, "self/cube_none", "r %d pairs %ld (first %d %d)", r, n, first[0], first[1]);
    r = sfb__trimesh_self_intersections(g_ctx, f.pos, f.tri, f.nf, &n, NULL);
    check(r == SFB_SUCCESS && n == 0, "self/flat_grid_none", "r %d pairs %ld", r, n);
    /* push vertex 0 through the sphere */
    v = 0;
    for (k = 0; k < 3; ++k) s.pos[3 * v + k] *= -1.5; /* out through the far side */
    r = sfb__trimesh_self_intersections(g_ctx, s.pos, s.tri, s.nf, &n, first);
    check(r == SFB_SUCCESS && n > 0 && first[0] >= 0 && first[0] < first[1] && first[1] < s.nf, "self/icosphere_pushed_through",
          "r %d pairs %ld first %d %d", r, n, first[0], first[1]);
    /* push a cube vertex through: the corner (1,1,1) to (-0.5,-0.5,-0.5) */
    for (v = 0; v < c.nv; ++v)
        if (c.pos[3 * v] == 1 && c.pos[3 * v + 1] == 1 && c.pos[3 * v + 2] == 1) break;
    if (v < c.nv) {
        set3(c.pos + 3 * v, -1.5, -1.5, -1.5);
        r = sfb__trimesh_self_intersections(g_ctx, c.pos, c.tri, c.nf, &n, first);
        check(r == SFB_SUCCESS && n > 0, "self/cube_pushed_through", "r %d pairs %ld", r, n);
    } else fail("self/cube_pushed_through", "no corner vertex");
    {
        /* small cases: a fold (same side), two sides of an edge, a duplicate face, through each other
         * from a shared vertex, a shared vertex alone */
        const double P[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.6, 0.2, 0, 0.2, -1, 0, 0.5, 0.2, -0.5, 0.2, 0.5, 0.5, -1, -1, 0.3, -0.5, -1, -0.4};
        const int fold[] = {0, 1, 2, 0, 1, 3}, flat[] = {0, 1, 2, 1, 0, 4}, dup[] = {0, 1, 2, 2, 1, 0}, thru[] = {0, 1, 2, 0, 5, 6},
                  vert[] = {0, 1, 2, 0, 7, 8};
        sfb__trimesh_self_intersections(g_ctx, P, fold, 2, &n, NULL);
        check(n == 1, "self/coplanar_fold_counts", "%ld", n);
        sfb__trimesh_self_intersections(g_ctx, P, flat, 2, &n, NULL);
        check(n == 0, "self/coplanar_across_edge_none", "%ld", n);
        sfb__trimesh_self_intersections(g_ctx, P, dup, 2, &n, NULL);
        check(n == 1, "self/duplicate_face_counts", "%ld", n);
        sfb__trimesh_self_intersections(g_ctx, P, thru, 2, &n, NULL);
        check(n == 1, "self/through_from_shared_vertex_counts", "%ld", n);
        sfb__trimesh_self_intersections(g_ctx, P, vert, 2, &n, NULL);
        check(n == 0, "self/shared_vertex_alone_none", "%ld", n);
    }
    tmesh_free(&s);
    tmesh_free(&c);
    tmesh_free(&f);
}

/* ---- sparse ---- */

/* Dense Cholesky solve of the n x n SPD matrix M (row-major, overwritten) for b (overwritten). */
static int cholesky_solve(int n, double *M, double *b) {
    int i, j, k;
    for (j = 0; j < n; ++j) {
        double d = M[j * n + j];
        for (k = 0; k < j; ++k) d -= M[j * n + k] * M[j * n + k];
        if (!(d > 0)) return 0;
        M[j * n + j] = sqrt(d);
        for (i = j + 1; i < n; ++i) {
            double s = M[i * n + j];
            for (k = 0; k < j; ++k) s -= M[i * n + k] * M[j * n + k];
            M[i * n + j] = s / M[j * n + j];
        }
    }
    for (i = 0; i < n; ++i) {
        double s = b[i];
        for (k = 0; k < i; ++k) s -= M[i * n + k] * b[k];
        b[i] = s / M[i * n + i];
    }
    for (i = n - 1; i >= 0; --i) {
        double s = b[i];
        for (k = i + 1; k < n; ++k) s -= M[k * n + i] * b[k];
        b[i] = s / M[i * n + i];
    }
    return 1;
}

static void test_sparse(unsigned long long seed) {
    rng g = rng_for(seed, 4);
    sfb__sparse A;
    sfb_result r;
    {
        /* summing and sorting */
        const int row[] = {2, 0, 2, 1, 0, 2, 0}, col[] = {1, 2, 1, 1, 0, 0, 2};
        const double val[] = {1, 2, 3, 4, 5, 6, 7};
        const int eoff[] = {0, 2, 3, 5}, ecol[] = {0, 2, 1, 0, 1};
        const double evl[] = {5, 9, 4, 6, 4};
        int ok;
        r = sfb__sparse_from_triplets(g_ctx, 3, 7, row, col, val, &A);
        ok = r == SFB_SUCCESS && A.n == 3 && !memcmp(A.row_off, eoff, sizeof eoff) && !memcmp(A.col, ecol, sizeof ecol) &&
             !memcmp(A.val, evl, sizeof evl);
        check(ok, "sparse/triplets_summed_sorted", "r %d", r);
        sfb__sparse_free(g_ctx, &A);
    }
    {
        const int row[] = {0, 3}, col[] = {0, 1}, rown[] = {0, -1};
        const double val[] = {1, 1};
        r = sfb__sparse_from_triplets(g_ctx, 3, 2, row, col, val, &A);
        check(r == SFB_INVALID_ARGS && A.row_off == NULL && strstr(sfb_last_error(g_ctx), "triplet 1") != NULL, "sparse/bad_index_rejected",
              "r %d: %s", r, sfb_last_error(g_ctx));
        r = sfb__sparse_from_triplets(g_ctx, 3, 2, row, rown, val, &A);
        check(r == SFB_INVALID_ARGS, "sparse/negative_index_rejected", "r %d", r);
        r = sfb__sparse_from_triplets(g_ctx, 3, 2, NULL, col, val, &A);
        check(r == SFB_INVALID_ARGS, "sparse/null_arrays_rejected", "r %d", r);
    }
    {
        /* the 2-D Dirichlet Laplacian on an m x m grid of unknowns, shuffled triplets with split diagonals */
        const int m = 14, n = m * m;
        int *row = (int *)xmalloc(sizeof(int) * 6 * (size_t)n), *col = (int *)xmalloc(sizeof(int) * 6 * (size_t)n), nt = 0, i, j, k, it = -1;
        double *val = (double *)xmalloc(sizeof(double) * 6 * (size_t)n), *M = (double *)calloc((size_t)n * n, sizeof(double));
        double *b = (double *)xmalloc(sizeof(double) * (size_t)n), *x = (double *)calloc((size_t)n, sizeof(double));
        double *xd = (double *)xmalloc(sizeof(double) * (size_t)n), *y = (double *)xmalloc(sizeof(double) * (size_t)n), res = -1, err = 0,
               xmax = 0, merr = 0;
        for (i = 0; i < m; ++i)
            for (j = 0; j < m; ++j) {
                const int u = i * m + j;
                row[nt] = u; col[nt] = u; val[nt++] = 1.5;
                row[nt] = u; col[nt] = u; val[nt++] = 2.5;
                if (i > 0) { row[nt] = u; col[nt] = u - m; val[nt++] = -1; }
                if (i < m - 1) { row[nt] = u; col[nt] = u + m; val[nt++] = -1; }
                if (j > 0) { row[nt] = u; col[nt] = u - 1; val[nt++] = -1; }
                if (j < m - 1) { row[nt] = u; col[nt] = u + 1; val[nt++] = -1; }
            }
        for (k = nt - 1; k > 0; --k) {
            const int s = rng_int(&g, k + 1);
            int t = row[k]; row[k] = row[s]; row[s] = t;
            t = col[k]; col[k] = col[s]; col[s] = t;
            {
                const double v = val[k];
                val[k] = val[s];
                val[s] = v;
            }
        }
        for (k = 0; k < nt; ++k) M[row[k] * n + col[k]] += val[k];
        for (i = 0; i < n; ++i) { b[i] = rng_range(&g, -1, 1); xd[i] = b[i]; }
        r = sfb__sparse_from_triplets(g_ctx, n, nt, row, col, val, &A);
        if (r != SFB_SUCCESS) fail("sparse/grid_laplacian", "%s", sfb_last_error(g_ctx));
        else {
            sfb__sparse_mul(&A, b, y);
            for (i = 0; i < n; ++i) {
                double s = 0;
                for (j = 0; j < n; ++j) s += M[i * n + j] * b[j];
                if (fabs(s - y[i]) > merr) merr = fabs(s - y[i]);
            }
            check(merr < 1e-14 && A.row_off[n] == 5 * n - 4 * m, "sparse/mul_vs_dense", "max diff %g, %d entries", merr, A.row_off[n]);
            r = sfb__sparse_cg(g_ctx, &A, b, x, 1e-13, 1000, &it, &res);
            if (!cholesky_solve(n, M, xd)) fail("sparse/cg_grid_laplacian", "dense Cholesky failed");
            for (i = 0; i < n; ++i) {
                if (fabs(x[i] - xd[i]) > err) err = fabs(x[i] - xd[i]);
                if (fabs(xd[i]) > xmax) xmax = fabs(xd[i]);
            }
            check(r == SFB_SUCCESS && err <= 1e-8 && res <= 1e-13 && it > 5 && it < 200, "sparse/cg_grid_laplacian",
                  "r %d, %d iterations, residual %g, max diff %g from Cholesky (|x| %g)", r, it, res, err, xmax);
            r = sfb__sparse_cg(g_ctx, &A, b, x, 1e-10, 1000, &it, &res);
            check(r == SFB_SUCCESS && it == 0, "sparse/cg_warm_start", "r %d, %d iterations", r, it);
            memset(x, 0, sizeof(double) * (size_t)n);
            r = sfb__sparse_cg(g_ctx, &A, b, x, 1e-12, 3, &it, &res);
            check(r == SFB_INVALID_VALUE && it == 3 && res > 1e-12 && strstr(sfb_last_error(g_ctx), "converge") != NULL, "sparse/cg_max_iter",
                  "r %d, %d iterations, residual %g: %s", r, it, res, sfb_last_error(g_ctx));
            for (i = 0; i < n; ++i) { y[i] = 0; x[i] = 1; }
            r = sfb__sparse_cg(g_ctx, &A, y, x, 1e-12, 10, &it, &res);
            for (i = 0, k = 1; i < n; ++i) k &= x[i] == 0;
            check(r == SFB_SUCCESS && k, "sparse/cg_zero_rhs", "r %d", r);
            sfb__sparse_free(g_ctx, &A);
            /* indefinite with a positive diagonal: the same grid shifted by -2.5 I (eigenvalues of both signs) */
            for (k = 0; k < nt; ++k)
                if (row[k] == col[k]) val[k] -= 1.25;
            r = sfb__sparse_from_triplets(g_ctx, n, nt, row, col, val, &A);
            memset(x, 0, sizeof(double) * (size_t)n);
            if (r == SFB_SUCCESS) r = sfb__sparse_cg(g_ctx, &A, b, x, 1e-12, 100000, &it, &res);
            check(r == SFB_INVALID_VALUE, "sparse/cg_indefinite_grid", "r %d after %d iterations", r, it);
            sfb__sparse_free(g_ctx, &A);
        }
        free(row); free(col); free(val); free(M); free(b); free(x); free(xd); free(y);
    }
    {
        const int row[] = {0, 0, 1, 1}, col[] = {0, 1, 0, 1}, row1[] = {0, 1}, col1[] = {0, 1};
        const double val[] = {1, 2, 2, 1}, neg[] = {1, -1};
        double b[2] = {1, -1}, x[2] = {0, 0};
        int it;
        r = sfb__sparse_from_triplets(g_ctx, 2, 4, row, col, val, &A);
        if (r == SFB_SUCCESS) r = sfb__sparse_cg(g_ctx, &A, b, x, 1e-12, 100, &it, NULL);
        check(r == SFB_INVALID_VALUE && strstr(sfb_last_error(g_ctx), "positive definite") != NULL, "sparse/cg_indefinite_2x2", "r %d: %s", r,
              sfb_last_error(g_ctx));
        sfb__sparse_free(g_ctx, &A);
        r = sfb__sparse_from_triplets(g_ctx, 2, 2, row1, col1, neg, &A);
        x[0] = x[1] = 0;
        if (r == SFB_SUCCESS) r = sfb__sparse_cg(g_ctx, &A, b, x, 1e-12, 100, &it, NULL);
        check(r == SFB_INVALID_VALUE && strstr(sfb_last_error(g_ctx), "diagonal") != NULL, "sparse/cg_negative_diagonal", "r %d: %s", r,
              sfb_last_error(g_ctx));
        b[0] = NAN;
        if (A.n == 2) r = sfb__sparse_cg(g_ctx, &A, b, x, 1e-12, 100, &it, NULL);
        check(r == SFB_INVALID_VALUE, "sparse/cg_nan_rhs", "r %d", r);
        sfb__sparse_free(g_ctx, &A);
    }
}

/* ---- normals and mean curvature ---- */

static void test_measures(unsigned long long seed) {
    rng g = rng_for(seed, 5);
    tmesh s = icosphere(4);
    double *N = (double *)xmalloc(sizeof(double) * 3 * (size_t)s.nv), *H = (double *)xmalloc(sizeof(double) * (size_t)s.nv);
    double worst = 0, hmin = HUGE_VAL, hmax = -HUGE_VAL;
    int v, f, k;
    sfb_result r;
    sfb__trimesh_vertex_normals(s.nv, s.pos, s.nf, s.tri, N);
    for (v = 0; v < s.nv; ++v) {
        double c[3], a;
        vcross(N + 3 * v, s.pos + 3 * v, c);
        a = atan2(vlen(c), vdot(N + 3 * v, s.pos + 3 * v));
        if (a > worst) worst = a;
    }
    check(worst < 1e-2, "measures/sphere_normals_radial", "worst %g rad (%d vertices)", worst, s.nv);
    r = sfb__trimesh_mean_curvature(g_ctx, s.nv, s.pos, s.nf, s.tri, H);
    for (v = 0; v < s.nv; ++v) {
        if (H[v] < hmin) hmin = H[v];
        if (H[v] > hmax) hmax = H[v];
    }
    check(r == SFB_SUCCESS && hmin > 0.95 && hmax < 1.05, "measures/sphere_H_1", "r %d, H in [%g, %g]", r, hmin, hmax);
    for (f = 0; f < s.nf; ++f) { const int x = s.tri[3 * f + 1]; s.tri[3 * f + 1] = s.tri[3 * f + 2]; s.tri[3 * f + 2] = x; }
    r = sfb__trimesh_mean_curvature(g_ctx, s.nv, s.pos, s.nf, s.tri, H);
    hmin = HUGE_VAL; hmax = -HUGE_VAL;
    for (v = 0; v < s.nv; ++v) {
        if (H[v] < hmin) hmin = H[v];
        if (H[v] > hmax) hmax = H[v];
    }
    check(r == SFB_SUCCESS && hmin > -1.05 && hmax < -0.95, "measures/sphere_inward_H_-1", "r %d, H in [%g, %g]", r, hmin, hmax);
    for (f = 0; f < s.nf; ++f) { const int x = s.tri[3 * f + 1]; s.tri[3 * f + 1] = s.tri[3 * f + 2]; s.tri[3 * f + 2] = x; }
    /* a radius-2 sphere: H = 1/2 */
    for (k = 0; k < 3 * s.nv; ++k) s.pos[k] *= 2;
    r = sfb__trimesh_mean_curvature(g_ctx, s.nv, s.pos, s.nf, s.tri, H);
    hmin = HUGE_VAL; hmax = -HUGE_VAL;
    for (v = 0; v < s.nv; ++v) {
        if (H[v] < hmin) hmin = H[v];
        if (H[v] > hmax) hmax = H[v];
    }
    check(r == SFB_SUCCESS && hmin > 0.475 && hmax < 0.525, "measures/sphere_radius2_H_half", "r %d, H in [%g, %g]", r, hmin, hmax);
    for (k = 0; k < 3 * s.nv; ++k) s.pos[k] *= 0.5;
    {
        /* flat jittered grid: 0 inside and on the boundary; normals +z. The jitter (0.15 of a
         * cell per coordinate) cannot fold a triangle over: at 0.3, (i,j), (i+1,j+1), (i,j+1)
         * could turn clockwise (1 seed in ~30: a fold has no flat cotangent Laplacian) */
        tmesh fl = grid(12, 10, 0.15, 0, 0, &g);
        double *h = (double *)xmalloc(sizeof(double) * (size_t)fl.nv), *n = (double *)xmalloc(sizeof(double) * 3 * (size_t)fl.nv), big = 0, nz = 0;
        r = sfb__trimesh_mean_curvature(g_ctx, fl.nv, fl.pos, fl.nf, fl.tri, h);
        sfb__trimesh_vertex_normals(fl.nv, fl.pos, fl.nf, fl.tri, n);
        for (v = 0; v < fl.nv; ++v) {
            if (fabs(h[v]) > big) big = fabs(h[v]);
            if (fabs(n[3 * v + 2] - 1) > nz) nz = fabs(n[3 * v + 2] - 1);
        }
        check(r == SFB_SUCCESS && big < 1e-9 && nz < 1e-15, "measures/flat_grid_H_0", "r %d, max |H| %g, normal off +z %g", r, big, nz);
        tmesh_free(&fl);
        free(h);
        free(n);
    }
    {
        /* open cylinder, R = 2: 1/(2R) = 0.25 away from the two boundary rows, 0 on them */
        const double R = 2;
        tmesh cy = grid(64, 24, 0, R, 2 * SFB__PI * R / 64, NULL);
        double *h = (double *)xmalloc(sizeof(double) * (size_t)cy.nv), lo = HUGE_VAL, hi = -HUGE_VAL, bmax = 0;
        int j;
        r = sfb__trimesh_mean_curvature(g_ctx, cy.nv, cy.pos, cy.nf, cy.tri, h);
        for (j = 0; j <= 24; ++j)
            for (v = 0; v < 64; ++v) {
                const double x = h[j * 64 + v];
                if (j == 0 || j == 24) { if (fabs(x) > bmax) bmax = fabs(x); }
                else if (j >= 2 && j <= 22) { if (x < lo) lo = x; if (x > hi) hi = x; }
            }
        check(r == SFB_SUCCESS && bmax == 0 && lo > 0.25 * 0.95 && hi < 0.25 * 1.05, "measures/cylinder_H_half_over_R",
              "r %d, H in [%g, %g] (1/(2R) = 0.25), boundary max %g", r, lo, hi, bmax);
        tmesh_free(&cy);
        free(h);
    }
    {
        /* an unused vertex and a degenerate face: zero, no NaN */
        const double P[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5, 2, 0, 0};
        const int T[] = {0, 1, 2, 0, 1, 4};
        double h[5], n[15];
        r = sfb__trimesh_mean_curvature(g_ctx, 5, P, 2, T, h);
        sfb__trimesh_vertex_normals(5, P, 2, T, n);
        check(r == SFB_SUCCESS && h[3] == 0 && n[9] == 0 && n[10] == 0 && n[11] == 0 && h[0] == 0 && fabs(n[2] - 1) < 1e-15,
              "measures/unused_vertex_degenerate_face", "r %d h3 %g n3 %g %g %g", r, h[3], n[9], n[10], n[11]);
    }
    {
        /* public: the icosphere as an sfb_mesh */
        sfb_mesh_desc d;
        sfb_mesh *m = NULL;
        float *fp = (float *)xmalloc(sizeof(float) * 3 * (size_t)s.nv), *fn = (float *)xmalloc(sizeof(float) * 3 * (size_t)s.nv);
        float *fh = (float *)xmalloc(sizeof(float) * (size_t)s.nv);
        int *fs = (int *)xmalloc(sizeof(int) * (size_t)s.nf);
        double dn = 0, dh = 0, *dp = (double *)xmalloc(sizeof(double) * 3 * (size_t)s.nv);
        for (k = 0; k < 3 * s.nv; ++k) { fp[k] = (float)s.pos[k]; dp[k] = fp[k]; }
        for (f = 0; f < s.nf; ++f) fs[f] = 3;
        memset(&d, 0, sizeof d);
        d.vertex_count = s.nv;
        d.positions = fp;
        d.face_count = s.nf;
        d.face_sizes = fs;
        d.face_vertices = s.tri;
        r = sfb_mesh_create(g_ctx, &d, &m);
        if (r != SFB_SUCCESS) fail("measures/public", "sfb_mesh_create: %s", sfb_last_error(g_ctx));
        else {
            sfb_result r1 = sfb_mesh_vertex_normals(g_ctx, m, fn), r2 = sfb_mesh_mean_curvature(g_ctx, m, fh);
            sfb__trimesh_vertex_normals(s.nv, dp, s.nf, s.tri, N);
            sfb__trimesh_mean_curvature(g_ctx, s.nv, dp, s.nf, s.tri, H);
            for (v = 0; v < s.nv; ++v) {
                for (k = 0; k < 3; ++k)
                    if (fabs(fn[3 * v + k] - N[3 * v + k]) > dn) dn = fabs(fn[3 * v + k] - N[3 * v + k]);
                if (fabs(fh[v] - H[v]) > dh) dh = fabs(fh[v] - H[v]);
            }
            check(r1 == SFB_SUCCESS && r2 == SFB_SUCCESS && dn < 1e-6 && dh < 1e-5, "measures/public_agrees", "r %d %d, normals %g, H %g", r1, r2, dn,
                  dh);
            check(sfb_mesh_vertex_normals(g_ctx, NULL, fn) == SFB_INVALID_ARGS && sfb_mesh_vertex_normals(g_ctx, m, NULL) == SFB_INVALID_ARGS &&
                      sfb_mesh_mean_curvature(g_ctx, m, NULL) == SFB_INVALID_ARGS && sfb_mesh_mean_curvature(NULL, m, fh) == SFB_INVALID_ARGS,
                  "measures/public_null_args", "accepted");
            sfb_mesh_destroy(m);
        }
        free(fp); free(fn); free(fh); free(fs); free(dp);
    }
    {
        /* a quad cube is refused, naming face 0 */
        const float P[] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
        const int fs[] = {4, 4, 4, 4, 4, 4}, fv[] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
        sfb_mesh_desc d;
        sfb_mesh *m = NULL;
        float out[24];
        memset(&d, 0, sizeof d);
        d.vertex_count = 8;
        d.positions = P;
        d.face_count = 6;
        d.face_sizes = fs;
        d.face_vertices = fv;
        if (sfb_mesh_create(g_ctx, &d, &m) != SFB_SUCCESS) fail("measures/quads_rejected", "sfb_mesh_create: %s", sfb_last_error(g_ctx));
        else {
            sfb_result r1 = sfb_mesh_vertex_normals(g_ctx, m, out);
            sfb_error_info e1 = sfb_last_error_info(g_ctx);
            sfb_result r2 = sfb_mesh_mean_curvature(g_ctx, m, out);
            sfb_error_info e2 = sfb_last_error_info(g_ctx);
            check(r1 == SFB_INVALID_TOPOLOGY && r2 == SFB_INVALID_TOPOLOGY && e1.element == SFB_ELEMENT_FACE && e1.index == 0 &&
                      e2.element == SFB_ELEMENT_FACE && e2.index == 0,
                  "measures/quads_rejected", "r %d %d, element %d index %ld: %s", r1, r2, (int)e2.element, e2.index, sfb_last_error(g_ctx));
            sfb_mesh_destroy(m);
        }
    }
    tmesh_free(&s);
    free(N);
    free(H);
}

/* Counting allocator: every block the modules took is given back (checked at the end). */
static long g_live;
static void *cnt_alloc(size_t n, void *u) { void *p = malloc(n); (void)u; if (p) g_live++; return p; }
static void *cnt_realloc(void *p, size_t n, void *u) { (void)u; if (!p) return cnt_alloc(n, u); return realloc(p, n); }
static void cnt_free(void *p, void *u) { (void)u; if (p) { g_live--; free(p); } }

int main(int argc, char **argv) {
    const unsigned long long seed = harness_seed(argc > 1 ? argv[1] : NULL);
    const unsigned long long seeds[3] = {1, 2, 0};
    sfb_context_config cfg = sfb_context_config_init();
    int i;
    const double t0 = now_s();
    cfg.ignore_environment = 1;
    cfg.allocator.alloc = cnt_alloc; cfg.allocator.realloc = cnt_realloc; cfg.allocator.free = cnt_free;
    if (sfb_context_create(&cfg, &g_ctx) != SFB_SUCCESS) {
        fail("setup", "context");
        return close_tests();
    }
    printf("# seed %llu\n", seed);
    for (i = 0; i < 3; ++i) {
        const unsigned long long s = i == 2 ? seed : seeds[i];
        test_tree(s);
        test_closest(s);
        test_tritri_random(s);
    }
    test_tree_edges();
    test_tritri_cases();
    test_self();
    test_sparse(seed);
    test_measures(seed);
    {
        const long live = g_live;
        sfb_context_destroy(g_ctx);
        /* the context's own blocks are freed by the destroy: nothing may be left after it */
        check(g_live == 0, "memory/nothing_leaked", "%ld blocks still allocated (%ld before the context's own)", g_live, live);
    }
    printf("# %.2f s\n", now_s() - t0);
    return close_tests();
}
