/* Manifold-based blending surfaces (SFB_SCHEME_MANIFOLD_BLEND, src/patch/manifold.c, seed 000) on every
 * backend, ref first. It reaches the patch table through src/sfb_internal.h (linked from libsfb_internal.o).
 * Checks (both weight kinds, Hermite and C-infinity, where it matters):
 *   - weights: the four blend weights sum to 1 and eta' matches differences of eta; a face whose
 *     four local geometries are one point is that point with zero derivatives;
 *   - interpolation: at every corner whose local geometry is a patch or a point the surface is
 *     that vertex (within 1e-6 of the diagonal); with only point geometries (every edge sharp)
 *     each face edge is the straight segment between its vertices;
 *   - smooth meshes: tangent-plane continuity across every edge, the normals of the two faces at
 *     51 points per edge within 1e-4 rad (quad meshes without sharp edges);
 *   - sharp features on a spherified cube (seed Fig. 3): along its 12 sharp edges both faces give
 *     the same points and normals more than 5 degrees apart; a dart edge is the straight segment
 *     with a normal jump across it; at a corner the three faces' normals are pairwise > 5 degrees
 *     apart;
 *   - analytic derivatives against central differences of positions (ref);
 *   - agreement of every backend with ref at random locations and at every corner: positions
 *     within 1e-5 of the diagonal, normals within 1e-3 rad, derivatives within 1e-4 relative;
 *   - bad configurations give the documented errors.
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

/* Angle between two vectors, accurate for small angles. */
static double angle3(const float *a, const float *b) {
    double cx = (double)a[1] * b[2] - (double)a[2] * b[1], cy = (double)a[2] * b[0] - (double)a[0] * b[2];
    double cz = (double)a[0] * b[1] - (double)a[1] * b[0], d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
    double la = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
    double lb = sqrt((double)b[0] * b[0] + (double)b[1] * b[1] + (double)b[2] * b[2]);
    if (la == 0.0 && lb == 0.0) return 0.0;
    if (la == 0.0 || lb == 0.0) return 10.0;
    return atan2(sqrt(cx * cx + cy * cy + cz * cz), d);
}
static double dist3(const float *a, const float *b) {
    double x = (double)a[0] - b[0], y = (double)a[1] - b[1], z = (double)a[2] - b[2];
    return sqrt(x * x + y * y + z * z);
}

static sfb_surface *make_surface(sfb_context *ctx, const sfb_mesh *m, int weights) {
    sfb_surface_config c = sfb_surface_config_init(SFB_SCHEME_MANIFOLD_BLEND, 0);
    sfb_surface *s = NULL;
    c.flags = SFB_REFINE_PATCHES;
    c.manifold.weights = weights;
    if (sfb_surface_create(ctx, m, &c, &s) != SFB_SUCCESS) return NULL;
    return s;
}

/* ---- built-in meshes: a cube of n x n quads per side, optionally pushed onto the unit sphere ---- */
enum { CUBE_SMOOTH = 0, CUBE_EDGES = 1, CUBE_ALL_SHARP = 2, CUBE_DART = 3 };
typedef struct cube_mesh { int nv, nf; float *p; int *fv; int nc; int *cv; } cube_mesh;

static int cube_vertex(cube_mesh *c, int *keys, int n, int x, int y, int z, int sph) {
    int key = (x * (n + 1) + y) * (n + 1) + z, i;
    if (keys[key] >= 0) return keys[key];
    {
        double px = 2.0 * x / n - 1.0, py = 2.0 * y / n - 1.0, pz = 2.0 * z / n - 1.0, l = sph ? sqrt(px * px + py * py + pz * pz) : 1.0;
        i = c->nv++;
        c->p[3 * i] = (float)(px / l); c->p[3 * i + 1] = (float)(py / l); c->p[3 * i + 2] = (float)(pz / l);
    }
    keys[key] = i;
    return i;
}

/* kind: CUBE_*. Faces counter-clockwise seen from outside. */
static sfb_mesh *cube(sfb_context *ctx, int n, int sph, int kind) {
    cube_mesh c;
    int *keys = (int *)malloc(sizeof(int) * (size_t)(n + 1) * (n + 1) * (n + 1));
    int *sizes, side, i, j, e;
    sfb_mesh_desc d;
    sfb_mesh *m = NULL;
    memset(&c, 0, sizeof c);
    for (i = 0; i < (n + 1) * (n + 1) * (n + 1); ++i) keys[i] = -1;
    c.p = (float *)malloc(sizeof(float) * 3 * (size_t)(6 * (n + 1) * (n + 1)));
    c.fv = (int *)malloc(sizeof(int) * 4 * (size_t)(6 * n * n));
    c.cv = (int *)malloc(sizeof(int) * 2 * (size_t)(12 * n * n + 24 * n));
    sizes = (int *)malloc(sizeof(int) * (size_t)(6 * n * n));
    for (side = 0; side < 6; ++side) {
        int axis = side / 2, hi = side % 2;
        for (i = 0; i < n; ++i)
            for (j = 0; j < n; ++j) {
                int q[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}}, k;
                for (k = 0; k < 4; ++k) {
                    int a = q[hi ? k : (4 - k) % 4][0], b = q[hi ? k : (4 - k) % 4][1], xyz[3];
                    xyz[axis] = hi ? n : 0; xyz[(axis + 1) % 3] = a; xyz[(axis + 2) % 3] = b;
                    c.fv[4 * c.nf + k] = cube_vertex(&c, keys, n, xyz[0], xyz[1], xyz[2], sph);
                }
                sizes[c.nf++] = 4;
            }
    }
    /* sharp edges */
    for (e = 0; e < c.nf; ++e) {
        int k;
        for (k = 0; k < 4; ++k) {
            int a = c.fv[4 * e + k], b = c.fv[4 * e + (k + 1) % 4], sharp = 0;
            const float *pa = c.p + 3 * a, *pb = c.p + 3 * b;
            if (a > b) continue; /* each edge once (it appears a->b in one face and b->a in the other) */
            (void)pa; (void)pb;
            if (kind == CUBE_ALL_SHARP) sharp = 1;
            if (sharp) { c.cv[2 * c.nc] = a; c.cv[2 * c.nc + 1] = b; c.nc++; }
        }
    }
    if (kind == CUBE_EDGES || kind == CUBE_DART) {
        /* by grid coordinates: an edge is on the cube's edges when both ends have two extreme coordinates */
        int x, y, z, ax;
        c.nc = 0;
        for (x = 0; x <= n; ++x)
            for (y = 0; y <= n; ++y)
                for (z = 0; z <= n; ++z) {
                    int g[3] = {x, y, z}, ext = 0, a;
                    a = (x * (n + 1) + y) * (n + 1) + z;
                    if (keys[a] < 0) continue;
                    for (ax = 0; ax < 3; ++ax) ext += g[ax] == 0 || g[ax] == n;
                    for (ax = 0; ax < 3; ++ax) {
                        int h[3] = {x, y, z}, ext2 = 0, b, bx;
                        h[ax]++;
                        if (h[ax] > n) continue;
                        b = (h[0] * (n + 1) + h[1]) * (n + 1) + h[2];
                        if (keys[b] < 0) continue;
                        for (bx = 0; bx < 3; ++bx) ext2 += h[bx] == 0 || h[bx] == n;
                        if (kind == CUBE_EDGES && ext >= 2 && ext2 >= 2) {
                            c.cv[2 * c.nc] = keys[a]; c.cv[2 * c.nc + 1] = keys[b]; c.nc++;
                        }
                        /* the dart: one edge in the middle of the x = n side, along y */
                        if (kind == CUBE_DART && x == n && ax == 1 && y == n / 2 - 1 && z == n / 2) {
                            c.cv[2 * c.nc] = keys[a]; c.cv[2 * c.nc + 1] = keys[b]; c.nc++;
                        }
                    }
                }
    }
    memset(&d, 0, sizeof d);
    d.vertex_count = c.nv; d.positions = c.p;
    d.face_count = c.nf; d.face_sizes = sizes; d.face_vertices = c.fv;
    if (c.nc) {
        float *sh = (float *)malloc(sizeof(float) * (size_t)c.nc);
        for (i = 0; i < c.nc; ++i) sh[i] = SFB_SHARPNESS_INFINITE;
        d.crease_count = c.nc; d.crease_vertices = c.cv; d.crease_sharpness = sh;
        if (sfb_mesh_create(ctx, &d, &m) != SFB_SUCCESS) m = NULL;
        free(sh);
    } else if (sfb_mesh_create(ctx, &d, &m) != SFB_SUCCESS) m = NULL;
    free(keys); free(c.p); free(c.fv); free(c.cv); free(sizes);
    return m;
}

/* ---- evaluation helpers ---- */
typedef struct evals { float *p, *du, *dv, *n, *duu, *duv, *dvv; } evals;
static void evals_free(evals *e) { free(e->p); free(e->du); free(e->dv); free(e->n); free(e->duu); free(e->duv); free(e->dvv); memset(e, 0, sizeof *e); }
static int eval_all(const sfb_surface *s, const sfb_location *L, int n, int second, evals *e) {
    sfb_eval_output o;
    memset(e, 0, sizeof *e);
    e->p = (float *)malloc(12 * (size_t)n + 12); e->du = (float *)malloc(12 * (size_t)n + 12);
    e->dv = (float *)malloc(12 * (size_t)n + 12); e->n = (float *)malloc(12 * (size_t)n + 12);
    memset(&o, 0, sizeof o);
    o.position = e->p; o.du = e->du; o.dv = e->dv; o.normal = e->n;
    if (second) {
        e->duu = (float *)malloc(12 * (size_t)n + 12); e->duv = (float *)malloc(12 * (size_t)n + 12); e->dvv = (float *)malloc(12 * (size_t)n + 12);
        o.duu = e->duu; o.duv = e->duv; o.dvv = e->dvv;
    }
    return sfb_surface_eval(s, L, n, &o) == SFB_SUCCESS;
}

/* Where a patch sits: its param face and sub-square. */
typedef struct patch_at { int pf, depth, qi, qj; } patch_at;
static patch_at *patch_places(const sfb__patch_table *pt) {
    patch_at *a = (patch_at *)calloc((size_t)pt->npatch + 1, sizeof *a);
    int f, q;
    for (f = 0; f < pt->nptex; ++f) {
        int r = pt->ptex_root[f];
        if (r <= -2) { a[-r - 2].pf = f; continue; }
        if (r < 0) continue;
        for (q = 0; q < 4; ++q) {
            int p = pt->nodes[4 * r + q];
            if (p <= -2) { a[-p - 2].pf = f; a[-p - 2].depth = 1; a[-p - 2].qi = q & 1; a[-p - 2].qj = q >> 1; }
        }
    }
    return a;
}
static void patch_loc(const patch_at *a, double s, double t, sfb_location *L) {
    double sc = a->depth ? 0.5 : 1.0;
    L->face = a->pf;
    L->u = (float)((a->qi + s) * sc);
    L->v = (float)((a->qj + t) * sc);
}
static const double g_corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

/* (u,v) of the point at t along edge `slot` of a base quad (from its vertex slot to slot + 1). */
static void edge_uv(int slot, double t, float *u, float *v) {
    switch (slot) {
    case 0: *u = (float)t; *v = 0.0f; break;
    case 1: *u = 1.0f; *v = (float)t; break;
    case 2: *u = (float)(1.0 - t); *v = 1.0f; break;
    default: *u = 0.0f; *v = (float)(1.0 - t); break;
    }
}

/* ---- checks ---- */

static void weights_unit(void) {
    int kind, q;
    unsigned seed = 12345u;
    for (kind = 0; kind < 2; ++kind) {
        double worst_sum = 0.0, worst_d = 0.0, worst_pt = 0.0;
        char nm[128];
        float pts[4 * 27];
        int cv[4] = {0, 1, 2, 3};
        unsigned codes[4];
        memset(pts, 0, sizeof pts);
        for (q = 0; q < 4; ++q) {
            pts[27 * q] = 1.5f; pts[27 * q + 1] = -2.0f; pts[27 * q + 2] = 0.25f;
            codes[q] = SFB__MF_CODE(SFB__MF_POINT, 0, 0, 0, 0);
        }
        for (q = 0; q < 20000; ++q) {
            double c, d, sum = 0.0, e0, e1, de, t, S[3], Sc[3], Sd[3], x;
            int j;
            seed = seed * 1664525u + 1013904223u; c = (seed >> 8) / 16777216.0;
            seed = seed * 1664525u + 1013904223u; d = (seed >> 8) / 16777216.0;
            {
                double a[4] = {c, d, 1.0 - c, 1.0 - d}, b[4] = {d, 1.0 - c, 1.0 - d, c}, dd;
                for (j = 0; j < 4; ++j) sum += sfb__mf_eta(kind, a[j], &dd) * sfb__mf_eta(kind, b[j], &dd);
            }
            if (fabs(sum - 1.0) > worst_sum) worst_sum = fabs(sum - 1.0);
            t = 0.001 + 0.998 * c;
            sfb__mf_eta(kind, t, &de);
            e0 = sfb__mf_eta(kind, t - 1e-6, &x); e1 = sfb__mf_eta(kind, t + 1e-6, &x);
            if (fabs((e1 - e0) / 2e-6 - de) > worst_d) worst_d = fabs((e1 - e0) / 2e-6 - de);
            sfb__mf_eval(pts, cv, codes, kind, c, d, S, Sc, Sd);
            x = fabs(S[0] - 1.5) + fabs(S[1] + 2.0) + fabs(S[2] - 0.25) + fabs(Sc[0]) + fabs(Sc[1]) + fabs(Sc[2]) + fabs(Sd[0]) + fabs(Sd[1]) + fabs(Sd[2]);
            if (x > worst_pt) worst_pt = x;
        }
        snprintf(nm, sizeof nm, "weights/%s/sum to 1", kind ? "cinf" : "hermite");
        check(worst_sum < 1e-12, nm, "max |sum - 1| = %g", worst_sum);
        snprintf(nm, sizeof nm, "weights/%s/eta' matches differences", kind ? "cinf" : "hermite");
        check(worst_d < 1e-6, nm, "max error %g", worst_d);
        snprintf(nm, sizeof nm, "weights/%s/four equal points blend to that point", kind ? "cinf" : "hermite");
        check(worst_pt < 1e-12, nm, "max error %g", worst_pt);
    }
    {
        /* the C-infinity eta is flat at the ends, the Hermite one only to first order */
        double d1, d2, e1 = sfb__mf_eta(1, 0.02, &d1), e2 = sfb__mf_eta(0, 0.02, &d2);
        check(1.0 - e1 < 1e-15 && 1.0 - e2 > 1e-4, "weights/cinf is flat at 0, hermite is not", "1 - eta(0.02): cinf %g, hermite %g", 1.0 - e1, 1.0 - e2);
    }
}

/* Surface at corners whose local geometry is a patch or a point == the vertex. */
static void interpolation(const char *name, const sfb_surface *s, double diag) {
    const sfb__patch_table *pt = &s->patches;
    patch_at *at = patch_places(pt);
    sfb_location *L = (sfb_location *)malloc(sizeof *L * (size_t)(4 * pt->npatch + 1));
    int *who = (int *)malloc(sizeof(int) * (size_t)(4 * pt->npatch + 1));
    int n = 0, p, j, i;
    double worst = 0.0;
    evals e;
    char nm[1024];
    memset(&e, 0, sizeof e);
    for (p = 0; p < pt->npatch; ++p)
        for (j = 0; j < 4; ++j) {
            if (SFB__MF_KIND(pt->pcorner[4 * p + j]) == SFB__MF_CURVE) continue;
            patch_loc(&at[p], g_corner[j][0], g_corner[j][1], &L[n]);
            who[n++] = pt->cv[4 * p + j];
        }
    snprintf(nm, sizeof nm, "ref/%s/passes through patch and point vertices", name);
    if (n == 0) skip(nm, "no patch or point corner");
    else if (!eval_all(s, L, n, 0, &e)) fail(nm, "eval: %s", sfb_last_error(s->ctx));
    else {
        for (i = 0; i < n; ++i) {
            double d = dist3(e.p + 3 * i, pt->point_data + 27 * (size_t)who[i]);
            if (d > worst) worst = d;
        }
        check(worst <= 1e-6 * diag, nm, "max distance %g (diag %g) over %d corners", worst, diag, n);
    }
    evals_free(&e);
    free(L); free(who); free(at);
}

/* Every corner a point: each face edge is the straight segment between its corners. */
static void only_points(const char *name, const sfb_surface *s, double diag) {
    const sfb__patch_table *pt = &s->patches;
    patch_at *at = patch_places(pt);
    int p, j, k, pts = 1, n = 0;
    sfb_location *L = (sfb_location *)malloc(sizeof *L * (size_t)(4 * 11 * pt->npatch + 1));
    double worst = 0.0;
    evals e;
    char nm[1024];
    for (p = 0; p < pt->npatch; ++p)
        for (j = 0; j < 4; ++j) {
            pts &= SFB__MF_KIND(pt->pcorner[4 * p + j]) == SFB__MF_POINT;
            for (k = 0; k <= 10; ++k) {
                double t = k / 10.0, a0 = g_corner[j][0], b0 = g_corner[j][1], a1 = g_corner[(j + 1) % 4][0], b1 = g_corner[(j + 1) % 4][1];
                patch_loc(&at[p], a0 + t * (a1 - a0), b0 + t * (b1 - b0), &L[n++]);
            }
        }
    snprintf(nm, sizeof nm, "ref/%s/every corner is a point", name);
    check(pts, nm, "a corner is not a point geometry");
    snprintf(nm, sizeof nm, "ref/%s/only points: face edges are the straight segments", name);
    if (!eval_all(s, L, n, 0, &e)) fail(nm, "eval: %s", sfb_last_error(s->ctx));
    else {
        for (p = 0, n = 0; p < pt->npatch; ++p)
            for (j = 0; j < 4; ++j) {
                const float *A = pt->point_data + 27 * (size_t)pt->cv[4 * p + j], *B = pt->point_data + 27 * (size_t)pt->cv[4 * p + (j + 1) % 4];
                for (k = 0; k <= 10; ++k, ++n) {
                    /* distance from the segment AB */
                    double ab[3], ap[3], l2 = 0.0, t = 0.0, d = 0.0;
                    int c;
                    for (c = 0; c < 3; ++c) { ab[c] = (double)B[c] - A[c]; ap[c] = (double)e.p[3 * n + c] - A[c]; l2 += ab[c] * ab[c]; t += ab[c] * ap[c]; }
                    t = l2 > 0.0 ? t / l2 : 0.0;
                    if (t < 0.0) t = 0.0;
                    if (t > 1.0) t = 1.0;
                    for (c = 0; c < 3; ++c) d += (ap[c] - t * ab[c]) * (ap[c] - t * ab[c]);
                    if (sqrt(d) > worst) worst = sqrt(d);
                }
            }
        check(worst <= 1e-6 * diag, nm, "max distance from the segment %g (diag %g)", worst, diag);
    }
    evals_free(&e);
    free(L); free(at);
}

/* Across every edge of a quad mesh (not refined): positions and normals from the two faces at
 * 51 points. sharp_only: only sharp edges (and require a normal jump > min_jump on those whose
 * ends are crease vertices); else only non-sharp edges, normals within tol. */
static void across_edges(const char *name, const sfb_surface *s, double diag, int sharp_only, double tol, double min_jump) {
    const sfb__level *l = &s->pbase;
    int e, k, n = 0, edges = 0;
    sfb_location *L = (sfb_location *)malloc(sizeof *L * (size_t)(2 * 51 * l->ne + 2));
    double worst_p = 0.0, worst_n = 0.0, least_jump = 1e9;
    evals ev;
    char nm[1024];
    for (e = 0; e < l->ne; ++e) {
        int f1, f2, s1, s2, same;
        if (l->ef_off[e + 1] - l->ef_off[e] != 2 || (l->es[e] > 0.0f) != (sharp_only != 0)) continue;
        if (l->fhole[l->ef[l->ef_off[e]]] || l->fhole[l->ef[l->ef_off[e] + 1]]) continue;
        f1 = l->ef[l->ef_off[e]]; f2 = l->ef[l->ef_off[e] + 1];
        s1 = l->ef_slot[l->ef_off[e]]; s2 = l->ef_slot[l->ef_off[e] + 1];
        same = l->fv[l->fv_off[f1] + s1] == l->fv[l->fv_off[f2] + s2];
        for (k = 0; k <= 50; ++k) {
            double t = k / 50.0;
            L[n].face = f1; edge_uv(s1, t, &L[n].u, &L[n].v); n++;
            L[n].face = f2; edge_uv(s2, same ? t : 1.0 - t, &L[n].u, &L[n].v); n++;
        }
    }
    snprintf(nm, sizeof nm, "ref/%s/%s edges: both faces give the same points", name, sharp_only ? "sharp" : "smooth");
    if (n == 0) {
        if (!sharp_only) skip(nm, "no such edge"); /* sharp only: nothing to assert (boundary-only sharp edges) */
        free(L);
        return;
    }
    if (!eval_all(s, L, n, 0, &ev)) { fail(nm, "eval: %s", sfb_last_error(s->ctx)); free(L); return; }
    for (e = 0, n = 0; e < l->ne; ++e) {
        int crease_ends;
        if (l->ef_off[e + 1] - l->ef_off[e] != 2 || (l->es[e] > 0.0f) != (sharp_only != 0)) continue;
        if (l->fhole[l->ef[l->ef_off[e]]] || l->fhole[l->ef[l->ef_off[e] + 1]]) continue;
        crease_ends = l->vrule[l->ev[2 * e]] == SFB__RULE_CREASE && l->vrule[l->ev[2 * e + 1]] == SFB__RULE_CREASE;
        edges++;
        for (k = 0; k <= 50; ++k, n += 2) {
            double dp = dist3(ev.p + 3 * n, ev.p + 3 * n + 3), an = angle3(ev.n + 3 * n, ev.n + 3 * n + 3);
            if (dp > worst_p) worst_p = dp;
            if (!sharp_only && an > worst_n) worst_n = an;
            if (sharp_only && crease_ends && k > 0 && k < 50 && an < least_jump) least_jump = an;
        }
    }
    check(worst_p <= 1e-6 * diag, nm, "max gap %g (diag %g) over %d edges", worst_p, diag, edges);
    if (!sharp_only) {
        snprintf(nm, sizeof nm, "ref/%s/tangent-plane continuity across %d edges (51 points each)", name, edges);
        check(worst_n < tol, nm, "max normal angle %g rad", worst_n);
    } else if (min_jump > 0.0) {
        snprintf(nm, sizeof nm, "ref/%s/creases: normals differ by more than %.0f degrees", name, min_jump * 180.0 / 3.14159265358979);
        if (least_jump > 1e8) skip(nm, "no sharp edge between crease vertices");
        else check(least_jump > min_jump, nm, "smallest normal jump %g rad", least_jump);
    }
    evals_free(&ev);
    free(L);
}

/* The dart edge (a sharp edge whose ends have no other sharp edge): straight, with a normal jump
 * across it inside; and at corners (>= 3 sharp edges) the faces' normals pairwise apart. */
static void darts_corners(const char *name, const sfb_surface *s, double diag, double min_jump) {
    const sfb__level *l = &s->pbase;
    int e, v, k, i, j, darts = 0, corners = 0;
    double worst_line = 0.0, least_jump = 1e9, least_corner = 1e9;
    char nm[1024];
    for (e = 0; e < l->ne; ++e) {
        int a = l->ev[2 * e], b = l->ev[2 * e + 1], f1, f2, s1, s2, same;
        sfb_location L[2 * 21];
        evals ev;
        if (!(l->es[e] > 0.0f) || l->vrule[a] != SFB__RULE_DART || l->vrule[b] != SFB__RULE_DART || l->ef_off[e + 1] - l->ef_off[e] != 2) continue;
        darts++;
        f1 = l->ef[l->ef_off[e]]; f2 = l->ef[l->ef_off[e] + 1];
        s1 = l->ef_slot[l->ef_off[e]]; s2 = l->ef_slot[l->ef_off[e] + 1];
        same = l->fv[l->fv_off[f1] + s1] == l->fv[l->fv_off[f2] + s2];
        for (k = 0; k <= 20; ++k) {
            double t = k / 20.0;
            L[2 * k].face = f1; edge_uv(s1, t, &L[2 * k].u, &L[2 * k].v);
            L[2 * k + 1].face = f2; edge_uv(s2, same ? t : 1.0 - t, &L[2 * k + 1].u, &L[2 * k + 1].v);
        }
        if (!eval_all(s, L, 42, 0, &ev)) { fail(name, "eval"); continue; }
        {
            const float *A = ev.p, *B = ev.p + 3 * 40;
            for (k = 0; k <= 20; ++k) {
                double ab[3], ap[3], l2 = 0.0, t = 0.0, d = 0.0;
                int c;
                for (c = 0; c < 3; ++c) { ab[c] = (double)B[c] - A[c]; ap[c] = (double)ev.p[6 * k + c] - A[c]; l2 += ab[c] * ab[c]; t += ab[c] * ap[c]; }
                t /= l2;
                for (c = 0; c < 3; ++c) d += (ap[c] - t * ab[c]) * (ap[c] - t * ab[c]);
                if (sqrt(d) > worst_line) worst_line = sqrt(d);
            }
            /* the jump in the middle half of the edge */
            for (k = 5; k <= 15; ++k) {
                double an = angle3(ev.n + 6 * k, ev.n + 6 * k + 3);
                if (an < least_jump) least_jump = an;
            }
        }
        evals_free(&ev);
    }
    if (darts) {
        snprintf(nm, sizeof nm, "ref/%s/dart edges are straight (%d)", name, darts);
        check(worst_line <= 1e-6 * diag, nm, "max distance from the segment %g", worst_line);
        snprintf(nm, sizeof nm, "ref/%s/darts: normals jump across the dart edge by more than %.1f degrees", name, min_jump * 180.0 / 3.14159265358979);
        check(least_jump > min_jump, nm, "smallest jump %g rad", least_jump);
    }
    for (v = 0; v < l->nv; ++v) {
        int nf = l->vf_off[v + 1] - l->vf_off[v];
        sfb_location L[64];
        evals ev;
        if (l->vrule[v] != SFB__RULE_CORNER || nf < 2 || nf > 64) continue;
        corners++;
        for (i = 0; i < nf; ++i) {
            int f = l->vf[l->vf_off[v] + i], sl = l->vf_slot[l->vf_off[v] + i];
            L[i].face = f; L[i].u = (float)g_corner[sl][0]; L[i].v = (float)g_corner[sl][1];
        }
        if (!eval_all(s, L, nf, 0, &ev)) { fail(name, "eval"); continue; }
        for (i = 0; i < nf; ++i)
            for (j = i + 1; j < nf; ++j) {
                double an = angle3(ev.n + 3 * i, ev.n + 3 * j);
                if (an < least_corner) least_corner = an;
            }
        evals_free(&ev);
    }
    if (corners) {
        snprintf(nm, sizeof nm, "ref/%s/corners: the faces' normals at each of %d corners pairwise more than %.1f degrees apart", name, corners,
                 min_jump * 180.0 / 3.14159265358979);
        check(least_corner > min_jump, nm, "smallest angle %g rad", least_corner);
    }
}

/* Analytic first derivatives against central differences of the double-precision blend. */
static void derivatives(const char *name, const sfb_surface *s) {
    const sfb__patch_table *pt = &s->patches;
    int p, q, kind;
    double worst = 0.0;
    unsigned seed = 777u;
    char nm[1024];
    for (kind = 0; kind < 2; ++kind)
        for (p = 0; p < pt->npatch; ++p)
            for (q = 0; q < 8; ++q) {
                double c, d, S[3], Sc[3], Sd[3], A[3], B[3], X[3], Y[3], h = 1e-6, scale = 0.0;
                int x;
                seed = seed * 1664525u + 1013904223u; c = 0.02 + 0.96 * ((seed >> 8) / 16777216.0);
                seed = seed * 1664525u + 1013904223u; d = 0.02 + 0.96 * ((seed >> 8) / 16777216.0);
                sfb__mf_eval(pt->point_data, pt->cv + 4 * p, pt->pcorner + 4 * p, kind, c, d, S, Sc, Sd);
                sfb__mf_eval(pt->point_data, pt->cv + 4 * p, pt->pcorner + 4 * p, kind, c + h, d, A, X, Y);
                sfb__mf_eval(pt->point_data, pt->cv + 4 * p, pt->pcorner + 4 * p, kind, c - h, d, B, X, Y);
                for (x = 0; x < 3; ++x) scale = fmax(scale, fmax(fabs(Sc[x]), fabs(Sd[x])));
                for (x = 0; x < 3; ++x) worst = fmax(worst, fabs((A[x] - B[x]) / (2 * h) - Sc[x]) / (scale + 1e-3));
                sfb__mf_eval(pt->point_data, pt->cv + 4 * p, pt->pcorner + 4 * p, kind, c, d + h, A, X, Y);
                sfb__mf_eval(pt->point_data, pt->cv + 4 * p, pt->pcorner + 4 * p, kind, c, d - h, B, X, Y);
                for (x = 0; x < 3; ++x) worst = fmax(worst, fabs((A[x] - B[x]) / (2 * h) - Sd[x]) / (scale + 1e-3));
            }
    snprintf(nm, sizeof nm, "ref/%s/analytic derivatives match central differences (both weights)", name);
    check(worst < 1e-5, nm, "max relative error %g", worst);
}

/* Every available backend against ref at random locations, corners and edge midpoints. */
static void agreement(const char *name, const sfb_mesh *m, int weights, const sfb_surface *sref, double diag) {
    int nptex = sfb_surface_param_face_count(sref), n = 0, i, b, q;
    int cap = 4000 + 9 * nptex;
    sfb_location *L = (sfb_location *)malloc(sizeof *L * (size_t)cap);
    unsigned seed = 4242u;
    evals er;
    char nm[1024];
    for (i = 0; i < nptex; ++i) {
        static const float uv[9][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5f, 0}, {1, 0.5f}, {0.5f, 1}, {0, 0.5f}, {1e-6f, 1e-6f}};
        if (sref->patches.ptex_root[i] == -1) continue;
        for (q = 0; q < 9; ++q) { L[n].face = i; L[n].u = uv[q][0]; L[n].v = uv[q][1]; n++; }
    }
    for (q = 0; q < 4000 && nptex > 0; ++q) {
        int f;
        seed = seed * 1664525u + 1013904223u; f = (int)((seed >> 8) % (unsigned)nptex);
        if (sref->patches.ptex_root[f] == -1) continue;
        L[n].face = f;
        seed = seed * 1664525u + 1013904223u; L[n].u = (float)((seed >> 8) / 16777216.0);
        seed = seed * 1664525u + 1013904223u; L[n].v = (float)((seed >> 8) / 16777216.0);
        n++;
    }
    if (!eval_all(sref, L, n, 1, &er)) { fail(name, "ref eval: %s", sfb_last_error(sref->ctx)); free(L); return; }
    for (b = 1; b < g_nbe; ++b) {
        sfb_surface *s;
        evals eb;
        double wp = 0.0, wn = 0.0, wd = 0.0, wdd = 0.0;
        snprintf(nm, sizeof nm, "%s/%s/%s agrees with ref at %d locations", g_be[b].name, name, weights ? "cinf" : "hermite", n);
        if (!g_be[b].available) { backend_missing(&g_be[b], nm); continue; }
        s = make_surface(g_be[b].ctx, m, weights);
        if (!s) { fail(nm, "create: %s", sfb_last_error(g_be[b].ctx)); continue; }
        if (!eval_all(s, L, n, 1, &eb)) { fail(nm, "eval: %s", sfb_last_error(g_be[b].ctx)); sfb_surface_destroy(s); evals_free(&eb); continue; }
        for (i = 0; i < n; ++i) {
            const float *du = er.du + 3 * i, *dv = er.dv + 3 * i;
            double ldu = sqrt((double)du[0] * du[0] + (double)du[1] * du[1] + (double)du[2] * du[2]);
            double ldv = sqrt((double)dv[0] * dv[0] + (double)dv[1] * dv[1] + (double)dv[2] * dv[2]);
            double sn = angle3(du, dv), floor1 = 1e-2 * diag, dd;
            int c;
            wp = fmax(wp, dist3(er.p + 3 * i, eb.p + 3 * i));
            /* normals where ref's tangents span a plane (not at point or curve corners) */
            if (ldu > 1e-3 * diag && ldv > 1e-3 * diag && sn > 1e-2 && sn < 3.13) wn = fmax(wn, angle3(er.n + 3 * i, eb.n + 3 * i));
            dd = fmax(dist3(er.du + 3 * i, eb.du + 3 * i) / fmax(ldu, floor1), dist3(er.dv + 3 * i, eb.dv + 3 * i) / fmax(ldv, floor1));
            wd = fmax(wd, dd);
            for (c = 0; c < 3; ++c) {
                const float *r2 = c == 0 ? er.duu : c == 1 ? er.duv : er.dvv, *b2 = c == 0 ? eb.duu : c == 1 ? eb.duv : eb.dvv;
                double lr = sqrt((double)r2[3 * i] * r2[3 * i] + (double)r2[3 * i + 1] * r2[3 * i + 1] + (double)r2[3 * i + 2] * r2[3 * i + 2]);
                wdd = fmax(wdd, dist3(r2 + 3 * i, b2 + 3 * i) / fmax(lr, diag));
            }
        }
        check(wp <= 1e-5 * diag && wn <= 1e-3 && wd <= 1e-3 && wdd <= 2e-2, nm,
              "position %g (tol %g), normal %g rad (tol 1e-3), du/dv relative %g (tol 1e-3), second derivatives relative %g (tol 2e-2)", wp,
              1e-5 * diag, wn, wd, wdd);
        evals_free(&eb);
        sfb_surface_destroy(s);
    }
    evals_free(&er);
    free(L);
}

/* A planar n x n grid of unit quads, u along +x and v along +y in every face. */
static sfb_mesh *grid(sfb_context *ctx, int n) {
    float *p = (float *)malloc(sizeof(float) * 3 * (size_t)(n + 1) * (n + 1));
    int *fv = (int *)malloc(sizeof(int) * 4 * (size_t)n * n), *sz = (int *)malloc(sizeof(int) * (size_t)n * n), i, j;
    sfb_mesh_desc d;
    sfb_mesh *m = NULL;
    for (j = 0; j <= n; ++j)
        for (i = 0; i <= n; ++i) { p[3 * (j * (n + 1) + i)] = (float)i; p[3 * (j * (n + 1) + i) + 1] = (float)j; p[3 * (j * (n + 1) + i) + 2] = 0.0f; }
    for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) {
            int *q = fv + 4 * (j * n + i);
            q[0] = j * (n + 1) + i; q[1] = q[0] + 1; q[2] = q[1] + n + 1; q[3] = q[0] + n + 1;
            sz[j * n + i] = 4;
        }
    memset(&d, 0, sizeof d);
    d.vertex_count = (n + 1) * (n + 1); d.positions = p; d.face_count = n * n; d.face_sizes = sz; d.face_vertices = fv;
    if (sfb_mesh_create(ctx, &d, &m) != SFB_SUCCESS) m = NULL;
    free(p); free(fv); free(sz);
    return m;
}

/* Trimming a manifold surface (seed V.5) on every backend. On a planar regular grid the blend of a
 * face whose four corners are interior vertices is an affine image of its (u,v) square (each
 * corner's fitted patch reproduces the plane), so 3-D areas there are parameter areas: a mask
 * whose left half (u < 1/2) is black keeps half of each such face within one texel's worth, and
 * nothing is kept left of the contour by more than one texel. */
static void trimming(void) {
    enum { W = 32, N = 6 };
    unsigned char tex[W * W];
    sfb_trim_mask mask;
    sfb_mesh *m = grid(g_be[0].ctx, N);
    int b, i, j;
    if (!m) { fail("trim/grid", "mesh"); return; }
    for (j = 0; j < W; ++j)
        for (i = 0; i < W; ++i) tex[j * W + i] = i < W / 2 ? 0 : 255;
    memset(&mask, 0, sizeof mask);
    mask.width = mask.height = W; mask.texels = tex;
    for (b = 0; b < g_nbe; ++b) {
        char nm[1024];
        sfb_surface *s;
        sfb_tess_config tc = sfb_tess_config_init(4);
        sfb_tess_data td;
        snprintf(nm, sizeof nm, "%s/grid6/trim: a half-black mask keeps half of every inner face, nothing left of the contour", g_be[b].name);
        if (!g_be[b].available) { backend_missing(&g_be[b], nm); continue; }
        s = make_surface(g_be[b].ctx, m, 0);
        tc.trim = &mask;
        if (!s || sfb_surface_tessellate(s, &tc, &td) != SFB_SUCCESS) { fail(nm, "%s", sfb_last_error(g_be[b].ctx)); if (s) sfb_surface_destroy(s); continue; }
        {
            double area[N * N], worst = 0.0, worst_left = 0.0;
            int t, inner = 0;
            memset(area, 0, sizeof area);
            for (t = 0; t < td.triangle_count; ++t) {
                const float *a = td.positions + 3 * td.triangles[3 * t], *c1 = td.positions + 3 * td.triangles[3 * t + 1], *c2 = td.positions + 3 * td.triangles[3 * t + 2];
                int f = td.triangle_faces[t];
                if (f >= 0 && f < N * N) area[f] += 0.5 * fabs(((double)c1[0] - a[0]) * ((double)c2[1] - a[1]) - ((double)c2[0] - a[0]) * ((double)c1[1] - a[1]));
                for (i = 0; i < 3; ++i) {
                    const float *q = td.positions + 3 * td.triangles[3 * t + i];
                    double fx = q[0] - floor(q[0]);
                    int col = (int)floor(q[0]), row = (int)floor(q[1]);
                    /* inside an inner face, away from its left edge: left of x = col + 1/2 is trimmed */
                    if (col >= 1 && col < N - 1 && row >= 1 && row < N - 1 && fx > 1e-4 && fx < 0.5) worst_left = fmax(worst_left, 0.5 - fx);
                }
            }
            for (j = 1; j < N - 1; ++j)
                for (i = 1; i < N - 1; ++i) { worst = fmax(worst, fabs(area[j * N + i] - 0.5)); inner++; }
            check(inner > 0 && worst <= 1.0 / W && worst_left <= 1.0 / W, nm, "max |kept area - 1/2| %g over %d faces (tol %g); kept %g left of the contour",
                  worst, inner, 1.0 / W, worst_left);
        }
        sfb_tess_data_free(&td);
        sfb_surface_destroy(s);
    }
    sfb_mesh_destroy(m);
}

static void bad_configs(sfb_context *ctx, const sfb_mesh *m) {
    sfb_surface_config c = sfb_surface_config_init(SFB_SCHEME_MANIFOLD_BLEND, 0);
    sfb_surface *s = NULL;
    sfb_result r;
    r = sfb_surface_create(ctx, m, &c, &s);
    check(r == SFB_UNSUPPORTED && !s, "bad/manifold without SFB_REFINE_PATCHES", "result %d", (int)r);
    c.flags = SFB_REFINE_PATCHES; c.refine_level = 2;
    r = sfb_surface_create(ctx, m, &c, &s);
    check(r == SFB_UNSUPPORTED && !s, "bad/manifold with a refinement level", "result %d", (int)r);
    c.refine_level = 0; c.flags = SFB_REFINE_PATCHES | SFB_REFINE_LIMIT;
    r = sfb_surface_create(ctx, m, &c, &s);
    check(r == SFB_UNSUPPORTED && !s, "bad/manifold with SFB_REFINE_LIMIT", "result %d", (int)r);
    c.flags = SFB_REFINE_PATCHES; c.manifold.weights = 7;
    r = sfb_surface_create(ctx, m, &c, &s);
    check(r == SFB_INVALID_VALUE && !s && strstr(sfb_last_error(ctx), "weights"), "bad/unknown weights kind", "result %d: %s", (int)r,
          sfb_last_error(ctx));
    c.manifold.weights = 0;
    r = sfb_surface_create(ctx, m, &c, &s);
    if (r == SFB_SUCCESS) {
        sfb_location L = {0, 1.5f, 0.0f};
        float P[3];
        sfb_eval_output o;
        sfb_patch_info pi;
        memset(&o, 0, sizeof o); o.position = P;
        memset(&pi, 0, sizeof pi);
        check(sfb_surface_eval(s, &L, 1, &o) == SFB_INVALID_VALUE, "bad/manifold eval outside [0,1]^2", "accepted");
        check(sfb_surface_patch_info(s, &pi) == SFB_SUCCESS && pi.manifold == pi.patches && pi.patches > 0, "api/patch info counts the blends",
              "%d of %d", pi.manifold, pi.patches);
        sfb_surface_destroy(s);
    } else fail("bad/valid manifold surface", "%s", sfb_last_error(ctx));
}

static int has_sharp(const sfb_surface *s) {
    int e;
    int v;
    for (e = 0; e < s->pbase.ne; ++e) if (s->pbase.es[e] > 0.0f) return 1;
    for (v = 0; v < s->pbase.nv; ++v) if (s->pbase.vs[v] > 0.0f) return 1; /* a corner tag */
    return 0;
}
static int all_quads(const sfb_mesh *m) {
    int f;
    for (f = 0; f < m->base.nf; ++f) if (m->base.fv_off[f + 1] - m->base.fv_off[f] != 4) return 0;
    return 1;
}

/* Every check that applies to one mesh. */
/* features: the mesh is one of the seed's Fig. 3 configurations (built in), whose creases, darts
 * and corners must show. */
static void run_mesh(const char *name, const sfb_mesh *m, int features) {
    int w;
    double diag = mesh_diag(m);
    for (w = 0; w < 2; ++w) {
        char nm[700];
        sfb_surface *s = make_surface(g_be[0].ctx, m, w);
        snprintf(nm, sizeof nm, "%s%s", name, w ? "/cinf" : "");
        if (!s) { fail(nm, "create: %s", sfb_last_error(g_be[0].ctx)); continue; }
        interpolation(nm, s, diag);
        if (w == 0) derivatives(nm, s);
        if (all_quads(m)) {
            if (!has_sharp(s)) across_edges(nm, s, diag, 0, 1e-4, 0.0);
            else {
                across_edges(nm, s, diag, 1, 0.0, features ? 5.0 * 3.14159265358979 / 180.0 : 0.0);
                if (features) darts_corners(nm, s, diag, 5.0 * 3.14159265358979 / 180.0);
            }
        }
        agreement(name, m, w, s, diag);
        sfb_surface_destroy(s);
    }
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : NULL, *match = argc > 2 ? argv[2] : NULL;
    char **names;
    int n = 0, i;
    if (!probe_backends()) return 1;
    weights_unit();
    trimming();
    {
        sfb_mesh *m;
        if ((m = cube(g_be[0].ctx, 3, 0, CUBE_SMOOTH)) != NULL) { run_mesh("cube3_smooth", m, 1); bad_configs(g_be[0].ctx, m); sfb_mesh_destroy(m); }
        else fail("cube", "mesh");
        if ((m = cube(g_be[0].ctx, 4, 1, CUBE_SMOOTH)) != NULL) { run_mesh("sphere4_smooth", m, 1); sfb_mesh_destroy(m); } else fail("cube", "mesh");
        if ((m = cube(g_be[0].ctx, 4, 1, CUBE_EDGES)) != NULL) { run_mesh("sphere4_creased_edges", m, 1); sfb_mesh_destroy(m); } else fail("cube", "mesh");
        if ((m = cube(g_be[0].ctx, 4, 1, CUBE_DART)) != NULL) { run_mesh("sphere4_dart", m, 1); sfb_mesh_destroy(m); } else fail("cube", "mesh");
        if ((m = cube(g_be[0].ctx, 2, 1, CUBE_ALL_SHARP)) != NULL) {
            sfb_surface *s = make_surface(g_be[0].ctx, m, 0);
            if (s) { only_points("sphere2_all_sharp", s, mesh_diag(m)); sfb_surface_destroy(s); } else fail("sphere2_all_sharp", "create");
            run_mesh("sphere2_all_sharp", m, 1);
            sfb_mesh_destroy(m);
        } else fail("cube", "mesh");
    }
    names = list_shapes(dir, "catmark_", match, &n);
    for (i = 0; i < n; ++i) {
        char why[1200];
        sfb_mesh *m = load_obj(g_be[0].ctx, dir, names[i], why, sizeof why);
        if (!m) {
            char nm[1024];
            snprintf(nm, sizeof nm, "shape/%s", names[i]);
            skip(nm, "not readable as a mesh");
        } else run_mesh(names[i], m, 0);
        if (m) sfb_mesh_destroy(m);
        fflush(stdout);
    }
    free_names(names, n);
    return finish_tests();
}
