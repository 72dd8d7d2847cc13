/* Rolling-ball fillets (sfb_mesh_fillet, seed 002, src/fillet/fillet.c), held to exact geometry.
 * Shapes from examples/fillet_shapes.h (generated, so the exact answers are known):
 *   - a finely tessellated fold (two half-planes at an interior angle theta, edge on the x axis),
 *     convex and (triangles flipped) concave, at 90 and 120 degrees: every vertex that moved lies
 *     within 1 % of r of the exact circle of radius r tangent to both planes (centre on the
 *     bisector at r / sin(theta/2)) and stayed in its plane x = const; every vertex farther from
 *     the edge than the linkage distance r cot(theta/2) (plus 2 %) did not move at all, every one
 *     nearer than 98 % of it did; the conic profile's points lie on the exact rational quadratic
 *     (P1, P0, P2; 1, w, 1); Hermite's on the exact cubic;
 *   - sharpening the filleted 90-degree fold (radius 1.5 r, the curve given as the former edge's
 *     vertices) puts every vertex back on the two planes within 1 % of r and the edge's vertices on
 *     the edge;
 *   - the box-cylinder union's seam: one closed spine of length 2 pi (R + r) within 1 %, the same
 *     faces (connectivity unchanged), no self-intersecting triangles (sfb__trimesh_self_intersections,
 *     the operator's own AABB tree), normals continuous across both linkage curves (the largest
 *     dihedral angle of the edges where the fillet meets the base exceeds the 95th percentile of the
 *     fillet's own edge dihedrals -- the tessellation's resolution: h / r across the profile -- by
 *     less than 2 degrees; a kink of k degrees at a linkage curve adds about k), and the mean curvature
 *     along the former seam drops by a factor printed and required to be at least 2;
 *   - a floor with an L-shaped prism: the seam's spine self-intersects at the reflex corner with a
 *     large radius; the loop is cut (reported) and the result has no self-intersecting triangles;
 *   - bad input: radius <= 0, NaN, too large; no feature; a quad mesh; a non-manifold edge; a
 *     caller's curve that is not a chain of edges; bad profile, weight, angle: each a clear error
 *     code and message, *out NULL, the input's positions untouched;
 *   - progress stages in order, cancellation at each (SFB_CANCELLED, nothing kept), the memory
 *     budget (SFB_LIMIT_EXCEEDED before the work). */
#define SURFBLEND_EXPOSE_INTERNALS
#include "surfblend.h"
#include "src/sfb_internal.h"
#include "tests/harness.h"
#include "examples/fillet_shapes.h"

static sfb_context *g_ctx;

static double seg_dist2d(const double *p, const double *a, const double *b) {
    const double ab0 = b[0] - a[0], ab1 = b[1] - a[1], l2 = ab0 * ab0 + ab1 * ab1;
    double t = l2 > 0 ? ((p[0] - a[0]) * ab0 + (p[1] - a[1]) * ab1) / l2 : 0.0, x, y;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    x = a[0] + t * ab0 - p[0];
    y = a[1] + t * ab1 - p[1];
    return sqrt(x * x + y * y);
}

/* The exact profile in the fold's (y, z) plane: kind 0 arc, 1 conic weight w, 2 sharp, 3 Hermite
 * with the arc's tangent length; distance from q by dense sampling (20000 pieces). */
typedef struct fold_geo { double theta, r, c[2], P1[2], P2[2], P0[2], L; } fold_geo;
static fold_geo fold_geometry(double theta_deg, double r) {
    fold_geo g;
    const double th = theta_deg * SFB__PI / 180.0, a[2] = {-1.0, 0.0}, b[2] = {-cos(th), -sin(th)};
    double bis[2] = {a[0] + b[0], a[1] + b[1]}, lb = sqrt(bis[0] * bis[0] + bis[1] * bis[1]);
    g.theta = th;
    g.r = r;
    g.L = r / tan(0.5 * th);
    g.c[0] = bis[0] / lb * r / sin(0.5 * th);
    g.c[1] = bis[1] / lb * r / sin(0.5 * th);
    g.P1[0] = g.L * a[0]; g.P1[1] = g.L * a[1];
    g.P2[0] = g.L * b[0]; g.P2[1] = g.L * b[1];
    g.P0[0] = g.P0[1] = 0.0;
    return g;
}
static void profile_point(const fold_geo *g, int kind, double w, double u, double *o) {
    if (kind == 2) {
        if (u < 0.5) { o[0] = g->P1[0] * (1 - 2 * u); o[1] = g->P1[1] * (1 - 2 * u); }
        else { o[0] = g->P2[0] * (2 * u - 1); o[1] = g->P2[1] * (2 * u - 1); }
        return;
    }
    if (kind == 3) {
        const double phi = SFB__PI - g->theta, len = 4.0 * tan(phi / 4.0) * g->r;
        const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u, h01 = -2 * u * u * u + 3 * u * u, h11 = u * u * u - u * u;
        const double t1[2] = {-g->P1[0] / g->L * len, -g->P1[1] / g->L * len}, t2[2] = {g->P2[0] / g->L * len, g->P2[1] / g->L * len};
        int k;
        for (k = 0; k < 2; ++k) o[k] = h00 * g->P1[k] + h10 * t1[k] + h01 * g->P2[k] + h11 * t2[k];
        return;
    }
    {
        const double ww = kind == 0 ? cos(0.5 * (SFB__PI - g->theta)) : w;
        const double b0 = (1 - u) * (1 - u), b1 = 2 * u * (1 - u) * ww, b2 = u * u, s = b0 + b1 + b2;
        o[0] = (b0 * g->P1[0] + b1 * g->P0[0] + b2 * g->P2[0]) / s;
        o[1] = (b0 * g->P1[1] + b1 * g->P0[1] + b2 * g->P2[1]) / s;
    }
}
static double profile_distance(const fold_geo *g, int kind, double w, const double *q) {
    double best = HUGE_VAL, prev[2], cur[2];
    int k;
    if (kind == 0) { /* the circle itself */
        const double dx = q[0] - g->c[0], dy = q[1] - g->c[1];
        return fabs(sqrt(dx * dx + dy * dy) - g->r);
    }
    profile_point(g, kind, w, 0.0, prev);
    for (k = 1; k <= 20000; ++k) {
        double d;
        profile_point(g, kind, w, k / 20000.0, cur);
        d = seg_dist2d(q, prev, cur);
        if (d < best) best = d;
        prev[0] = cur[0]; prev[1] = cur[1];
    }
    return best;
}

static sfb_mesh *make_mesh(const fs_mesh *m) {
    sfb_mesh *out = NULL;
    if (fs_to_mesh(g_ctx, m, &out) != SFB_SUCCESS) return NULL;
    return out;
}

/* Holes in the blend region (seed 7's failure: its map needs a region that is a cylinder or a
 * disc): the faces whose centroids lie within `hr` of four points inside the band, two on each
 * face of the fold, are removed; the region then has four more boundary loops. */
static void punch_holes(fs_mesh *m, double theta, double band, double hr) {
    const double th = theta * SFB__PI / 180.0, s = 0.5 * band;
    const double c[4][3] = {{0.5, -s, 0.0}, {1.5, -s, 0.0}, {0.7, -cos(th) * s, -sin(th) * s}, {1.3, -cos(th) * s, -sin(th) * s}};
    int f, k = 0, h;
    for (f = 0; f < m->nf; ++f) {
        double g[3] = {0, 0, 0};
        int j, keep = 1;
        for (j = 0; j < 3; ++j) {
            g[0] += m->pos[3 * m->tri[3 * f + j]] / 3.0;
            g[1] += m->pos[3 * m->tri[3 * f + j] + 1] / 3.0;
            g[2] += m->pos[3 * m->tri[3 * f + j] + 2] / 3.0;
        }
        for (h = 0; h < 4; ++h)
            if ((g[0] - c[h][0]) * (g[0] - c[h][0]) + (g[1] - c[h][1]) * (g[1] - c[h][1]) + (g[2] - c[h][2]) * (g[2] - c[h][2]) < hr * hr) keep = 0;
        if (keep) { memmove(m->tri + 3 * k, m->tri + 3 * f, 3 * sizeof(int)); k++; }
    }
    m->nf = k;
}

/* The fold checks: kind/w the profile; holes: punch_holes first. Vertices no face uses any more
 * are not checked. */
static void test_fold_holes(double theta, int flip, int kind, double w, int holes, const char *name);
static void test_fold(double theta, int flip, int kind, double w, const char *name) { test_fold_holes(theta, flip, kind, w, 0, name); }
static void test_fold_holes(double theta, int flip, int kind, double w, int holes, const char *name) {
    fs_mesh fm;
    sfb_mesh *in, *out = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_report rep;
    sfb_result r;
    const double rad = 0.25;
    const fold_geo g = fold_geometry(theta, rad);
    char nm[160];
    memset(&fm, 0, sizeof fm);
    if (fs_fold(&fm, 60, 2.0f, 1.0f, (float)theta, flip) != 0 || (holes && (punch_holes(&fm, theta, g.L, 0.06), 0)) ||
        !(in = make_mesh(&fm))) {
        fail(name, "could not build the fold");
        fs_free(&fm);
        return;
    }
    cfg = sfb_fillet_config_init((float)rad);
    cfg.profile = kind;
    cfg.conic_weight = (float)w;
    r = sfb_mesh_fillet(g_ctx, in, &cfg, &out, &rep);
    snprintf(nm, sizeof nm, "%s/runs", name);
    check(r == SFB_SUCCESS && out, nm, "%s: %s", sfb_result_string(r), sfb_last_error(g_ctx));
    if (r == SFB_SUCCESS && out) {
        sfb_mesh_desc d;
        int v, moved = 0, bad_on = 0, bad_still = 0, bad_missed = 0, bad_plane = 0, f;
        double worst = 0.0;
        unsigned char *used = (unsigned char *)xmalloc((size_t)fm.nv + 1);
        memset(used, 0, (size_t)fm.nv + 1);
        for (f = 0; f < 3 * fm.nf; ++f) used[fm.tri[f]] = 1;
        sfb_mesh_get_desc(out, &d);
        snprintf(nm, sizeof nm, "%s/one open curve", name);
        check(rep.curve_count == 1 && !rep.curves[0].closed && rep.curves[0].convex == !flip, nm,
              "curves %d, closed %d, convex %d (want %d)", rep.curve_count, rep.curve_count ? rep.curves[0].closed : -1,
              rep.curve_count ? rep.curves[0].convex : -1, !flip);
        for (v = 0; v < fm.nv; ++v) {
            const float *p0 = fm.pos + 3 * v, *p1 = d.positions + 3 * v;
            const double s = sqrt((double)p0[1] * p0[1] + (double)p0[2] * p0[2]);
            const int changed = p0[0] != p1[0] || p0[1] != p1[1] || p0[2] != p1[2];
            if (!used[v]) continue;
            if (changed) {
                const double q[2] = {p1[1], p1[2]};
                const double e = profile_distance(&g, kind, w, q);
                moved++;
                if (e > worst) worst = e;
                if (e > 0.01 * rad) bad_on++;
                if (fabs((double)p1[0] - p0[0]) > 1e-6) bad_plane++;
            }
            if (s > 1.02 * g.L + 1e-6 && changed) bad_still++;
            if (s < 0.98 * g.L && !changed) bad_missed++;
        }
        snprintf(nm, sizeof nm, "%s/on the exact profile", name);
        check(moved > 0 && bad_on == 0, nm, "%d of %d moved vertices farther than 1%% of r from the exact profile (worst %.3g r)", bad_on,
              moved, worst / rad);
        snprintf(nm, sizeof nm, "%s/in their planes", name);
        check(bad_plane == 0, nm, "%d vertices left their plane x = const", bad_plane);
        snprintf(nm, sizeof nm, "%s/outside the band untouched", name);
        check(bad_still == 0, nm, "%d vertices beyond the linkage distance moved", bad_still);
        snprintf(nm, sizeof nm, "%s/inside the band moved", name);
        check(bad_missed == 0, nm, "%d vertices inside the band did not move", bad_missed);
        snprintf(nm, sizeof nm, "%s/report", name);
        check(rep.vertices_moved == moved && rep.faces_folded == 0 && rep.curves[0].vertices_kept == 0 &&
                  rep.curves[0].max_deviation < 0.01 * rad && rep.curves[0].samples >= 40 &&
                  fabs(rep.curves[0].spine_length - 2.0) < 1e-3,
              nm, "moved %d (counted %d), deviation %g, samples %d, spine %g", rep.vertices_moved, moved, rep.curves[0].max_deviation,
              rep.curves[0].samples, rep.curves[0].spine_length);
        if (holes) printf("%s: %d vertices moved around 4 holes, map %d (1 cotangent, 2 mean value, 0 direct)\n", name, moved,
                          rep.curves[0].map);
        free(used);
        sfb_fillet_report_free(&rep);
        sfb_mesh_destroy(out);
    }
    sfb_mesh_destroy(in);
    fs_free(&fm);
}

/* Several curves in one call: a step's convex and concave edges. First found by angle (two open
 * curves, one convex, one concave, the config's radius), then given by the caller with a radius
 * and a profile each (0.2 arc on the convex edge, 0.3 conic of weight 0.5 on the concave one):
 * every moved vertex on its own edge's exact profile, within 1 % of that edge's radius. */
static void test_step(void) {
    fs_mesh fm;
    sfb_mesh *in = NULL, *out = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_curve curves[2];
    sfb_fillet_report rep;
    sfb_result r;
    const double depth = 1.0;
    int pass;
    memset(&fm, 0, sizeof fm);
    if (fs_step(&fm, 40, 2.0f, 1.0f, (float)depth) != 0 || !(in = make_mesh(&fm))) {
        fail("step/setup", "no step");
        fs_free(&fm);
        return;
    }
    for (pass = 0; pass < 2; ++pass) {
        const char *nm0 = pass ? "step/caller's curves" : "step/by angle";
        const double rad[2] = {pass ? 0.2 : 0.25, pass ? 0.3 : 0.25};
        const int kind[2] = {SFB_FILLET_ARC, pass ? SFB_FILLET_CONIC : SFB_FILLET_ARC};
        const double w[2] = {0.0, pass ? 0.5 : 0.0};
        char nm[160];
        cfg = sfb_fillet_config_init(0.25f);
        if (pass) {
            memset(curves, 0, sizeof curves);
            curves[0].vertices = fm.loop;
            curves[0].count = fm.loop_count;
            curves[0].radius = 0.2f;
            curves[1].vertices = fm.loop + fm.loop_count;
            curves[1].count = fm.loop_count;
            curves[1].radius = 0.3f;
            curves[1].profile = SFB_FILLET_CONIC + 1;
            curves[1].conic_weight = 0.5f;
            cfg.curves = curves;
            cfg.curve_count = 2;
        }
        r = sfb_mesh_fillet(g_ctx, in, &cfg, &out, &rep);
        snprintf(nm, sizeof nm, "%s/runs", nm0);
        check(r == SFB_SUCCESS && out, nm, "%s: %s", sfb_result_string(r), sfb_last_error(g_ctx));
        if (r != SFB_SUCCESS || !out) continue;
        {
            sfb_mesh_desc d;
            int v, moved[2] = {0, 0}, bad = 0, c, conv = -1;
            double worst = 0.0;
            sfb_mesh_get_desc(out, &d);
            for (c = 0; c < rep.curve_count; ++c)
                if (rep.curves[c].convex) conv = c;
            snprintf(nm, sizeof nm, "%s/two open curves, one convex", nm0);
            check(rep.curve_count == 2 && !rep.curves[0].closed && !rep.curves[1].closed && rep.curves[0].convex != rep.curves[1].convex, nm,
                  "curves %d", rep.curve_count);
            if (pass) {
                snprintf(nm, sizeof nm, "%s/the given radii reported", nm0);
                check(rep.curve_count == 2 && fabs(rep.curves[0].radius - 0.2) < 1e-6 && fabs(rep.curves[1].radius - 0.3) < 1e-6 && conv == 0, nm,
                      "radii %g %g, convex curve %d", rep.curves[0].radius, rep.curve_count > 1 ? rep.curves[1].radius : 0.0, conv);
            }
            for (v = 0; v < fm.nv; ++v) {
                const float *p0 = fm.pos + 3 * v, *p1 = d.positions + 3 * v;
                /* which edge: the nearer one before the fillet; q in that edge's fold frame */
                const double d0 = hypot(p0[1], p0[2]), d1 = hypot(p0[1], p0[2] + depth);
                const int e = d0 <= d1 ? 0 : 1;
                const fold_geo g = fold_geometry(90.0, rad[e]);
                double q[2], err;
                if (p0[0] == p1[0] && p0[1] == p1[1] && p0[2] == p1[2]) continue;
                moved[e]++;
                if (e == 0) { q[0] = p1[1]; q[1] = p1[2]; }
                else { q[0] = -p1[1]; q[1] = -(p1[2] + depth); }
                err = profile_distance(&g, kind[e], w[e], q) / rad[e];
                if (err > worst) worst = err;
                if (err > 0.01) bad++;
            }
            snprintf(nm, sizeof nm, "%s/each edge on its exact profile", nm0);
            check(moved[0] > 0 && moved[1] > 0 && bad == 0, nm, "moved %d + %d, %d off by more than 1%% of their radius (worst %.3g)", moved[0],
                  moved[1], bad, worst);
            sfb_fillet_report_free(&rep);
            sfb_mesh_destroy(out);
        }
    }
    sfb_mesh_destroy(in);
    fs_free(&fm);
}

/* Fillet the 90-degree fold, then sharpen it back with the former edge as the caller's curve. */
static void test_sharpen(void) {
    fs_mesh fm;
    sfb_mesh *in = NULL, *round_ = NULL, *sharp = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_curve curve;
    sfb_result r;
    const double r0 = 0.2, r1 = 1.5 * r0;
    memset(&fm, 0, sizeof fm);
    if (fs_fold(&fm, 60, 2.0f, 1.0f, 90.0f, 0) != 0 || !(in = make_mesh(&fm))) { fail("sharpen/setup", "no fold"); fs_free(&fm); return; }
    cfg = sfb_fillet_config_init((float)r0);
    r = sfb_mesh_fillet(g_ctx, in, &cfg, &round_, NULL);
    if (r != SFB_SUCCESS) { fail("sharpen/fillet", "%s", sfb_last_error(g_ctx)); goto done; }
    cfg = sfb_fillet_config_init((float)r1);
    cfg.profile = SFB_FILLET_SHARPEN;
    memset(&curve, 0, sizeof curve);
    curve.vertices = fm.loop;
    curve.count = fm.loop_count;
    cfg.curves = &curve;
    cfg.curve_count = 1;
    r = sfb_mesh_fillet(g_ctx, round_, &cfg, &sharp, NULL);
    check(r == SFB_SUCCESS, "sharpen/runs", "%s: %s", sfb_result_string(r), sfb_last_error(g_ctx));
    if (r == SFB_SUCCESS) {
        sfb_mesh_desc d, dr;
        int v, off = 0, edge_off = 0;
        double worst = 0.0, worst_edge = 0.0;
        sfb_mesh_get_desc(sharp, &d);
        sfb_mesh_get_desc(round_, &dr);
        for (v = 0; v < fm.nv; ++v) {
            const float *p = d.positions + 3 * v;
            /* distance to the union of the half-planes z = 0 (y <= 0) and y = 0 (z <= 0) */
            const double dA = p[1] <= 0 ? fabs(p[2]) : sqrt((double)p[1] * p[1] + (double)p[2] * p[2]);
            const double dB = p[2] <= 0 ? fabs(p[1]) : sqrt((double)p[1] * p[1] + (double)p[2] * p[2]);
            const double e = dA < dB ? dA : dB;
            if (e > worst) worst = e;
            if (e > 0.01 * r0) off++;
        }
        for (v = 0; v < fm.loop_count; ++v) {
            const float *p = d.positions + 3 * fm.loop[v];
            const double e = sqrt((double)p[1] * p[1] + (double)p[2] * p[2]);
            if (e > worst_edge) worst_edge = e;
            if (e > 0.01 * r0) edge_off++;
        }
        {
            /* the rounded mesh was round: its edge vertices were r0 (sqrt 2 - 1) off the edge */
            const float *p = dr.positions + 3 * fm.loop[fm.loop_count / 2];
            const double e = sqrt((double)p[1] * p[1] + (double)p[2] * p[2]);
            check(fabs(e - r0 * (sqrt(2.0) - 1.0)) < 0.01 * r0, "sharpen/was round", "the rounded edge's middle vertex is %g off the edge", e);
        }
        check(off == 0, "sharpen/on the planes", "%d vertices farther than 1%% of r from the sharp planes (worst %.3g r)", off, worst / r0);
        check(edge_off == 0, "sharpen/edge restored", "%d former edge vertices off the edge (worst %.3g r)", edge_off, worst_edge / r0);
        sfb_mesh_destroy(sharp);
    }
done:
    sfb_mesh_destroy(round_);
    sfb_mesh_destroy(in);
    fs_free(&fm);
}

static double angle_between(const double *a, const double *b) {
    const double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
    c = c > 1 ? 1 : c < -1 ? -1 : c;
    return acos(c);
}
static void face_normal(const float *pos, const int *t, double *n) {
    const float *a = pos + 3 * t[0], *b = pos + 3 * t[1], *c = pos + 3 * t[2];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
}
static int cmp_double(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}

static long self_intersections(const sfb_mesh *m, int nf) {
    sfb_mesh_desc d;
    double *pos;
    long pairs = -1;
    int i, first[2];
    sfb_mesh_get_desc(m, &d);
    pos = (double *)xmalloc((size_t)d.vertex_count * 3 * sizeof(double));
    for (i = 0; i < 3 * d.vertex_count; ++i) pos[i] = d.positions[i];
    if (sfb__trimesh_self_intersections(g_ctx, pos, d.face_vertices, nf, &pairs, first) != SFB_SUCCESS) pairs = -1;
    free(pos);
    return pairs;
}

/* The box-cylinder union with every feature found by angle: the box's twelve edges end three at a
 * time at its eight corners, where the ball's sphere joins them. Exact: a vertex of the box (away
 * from the cylinder) lies r from the box shrunk by r -- on a face, an edge's quarter cylinder or a
 * corner's sphere -- within 1 % of r; the 8 corners are reported; no triangles intersect. */
static void test_box_corners(void) {
    fs_mesh fm;
    sfb_mesh *in = NULL, *out = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_report rep;
    sfb_result r;
    const double half = 1.0, height = 0.6, R = 0.5, rad = 0.15;
    memset(&fm, 0, sizeof fm);
    if (fs_box_cylinder(&fm, 48, (float)half, (float)height, (float)R, 0.6f) != 0 || !(in = make_mesh(&fm))) {
        fail("corners/setup", "no box-cylinder");
        fs_free(&fm);
        return;
    }
    cfg = sfb_fillet_config_init((float)rad);
    r = sfb_mesh_fillet(g_ctx, in, &cfg, &out, &rep);
    check(r == SFB_SUCCESS && out, "corners/runs", "%s: %s", sfb_result_string(r), sfb_last_error(g_ctx));
    if (r == SFB_SUCCESS && out) {
        sfb_mesh_desc d;
        int v, n = 0, bad = 0, on_sphere = 0;
        double worst = 0.0;
        long pairs;
        sfb_mesh_get_desc(out, &d);
        for (v = 0; v < fm.nv; ++v) {
            const float *p0 = fm.pos + 3 * v, *p = d.positions + 3 * v;
            const double lo[3] = {-half + rad, -half + rad, -height + rad}, hi[3] = {half - rad, half - rad, -rad};
            double q[3], dist, e;
            int k, out_of = 0;
            if (hypot(p0[0], p0[1]) < R + 2.0 * rad && p0[2] > -2.0 * rad) continue; /* the seam's and the cylinder's */
            for (k = 0; k < 3; ++k) {
                q[k] = p[k] < lo[k] ? lo[k] : p[k] > hi[k] ? hi[k] : p[k];
                out_of += p[k] < lo[k] || p[k] > hi[k];
            }
            dist = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
            e = fabs(dist - rad) / rad;
            if (out_of == 3) on_sphere++;
            if (e > worst) worst = e;
            if (e > 0.01) bad++;
            n++;
        }
        printf("corners: %d corners, %d vertices on their spheres (%d beyond all three planes); box vertices %d, worst %.2g r off the rounded box\n",
               rep.corner_count, rep.corner_vertices_moved, on_sphere, n, worst);
        check(rep.corner_count == 8 && rep.corner_vertices_moved > 0 && on_sphere == rep.corner_vertices_moved && rep.faces_folded == 0,
              "corners/eight spheres", "%d corners, %d vertices moved onto spheres, %d found beyond the three planes, %d faces folded",
              rep.corner_count, rep.corner_vertices_moved, on_sphere, rep.faces_folded);
        check(n > 1000 && bad == 0, "corners/on the exact rounded box", "%d of %d box vertices farther than 1%% of r from it (worst %.3g r)", bad, n,
              worst);
        pairs = self_intersections(out, fm.nf);
        check(pairs == 0, "corners/no self-intersections", "%ld intersecting triangle pairs", pairs);
        sfb_fillet_report_free(&rep);
        sfb_mesh_destroy(out);
    }
    sfb_mesh_destroy(in);
    fs_free(&fm);
}

/* The smallest angle of each triangle whose three vertices moved, sorted (n returned). */
static int moved_min_angles(const fs_mesh *fm, const float *pos, double *out) {
    int f, n = 0, k, c;
    for (f = 0; f < fm->nf; ++f) {
        const int *t = fm->tri + 3 * f;
        double m = 180.0;
        int all = 1;
        for (k = 0; k < 3; ++k) all &= memcmp(fm->pos + 3 * t[k], pos + 3 * t[k], 3 * sizeof(float)) != 0;
        if (!all) continue;
        for (k = 0; k < 3; ++k) {
            const float *p = pos + 3 * t[k], *q = pos + 3 * t[(k + 1) % 3], *r = pos + 3 * t[(k + 2) % 3];
            double u[3], w[3], lu = 0, lw = 0, d = 0, a;
            for (c = 0; c < 3; ++c) { u[c] = q[c] - p[c]; w[c] = r[c] - p[c]; lu += u[c] * u[c]; lw += w[c] * w[c]; d += u[c] * w[c]; }
            a = lu > 0 && lw > 0 ? acos(fmax(-1.0, fmin(1.0, d / sqrt(lu * lw)))) * 180.0 / SFB__PI : 0.0;
            if (a < m) m = a;
        }
        out[n++] = m;
    }
    qsort(out, (size_t)n, sizeof(double), cmp_double);
    return n;
}

/* config.relax, seed 5.2's Laplacian optimisation in 2D, on the seam: kept, still on the sweep,
 * nothing turned over, and the triangles evened out (the 5th percentile of their smallest angles
 * rises); off by default (see fil_relax for why), so the default run is not relaxed. */
static void test_relax(void) {
    fs_mesh fm;
    sfb_mesh *in = NULL, *out0 = NULL, *out1 = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_curve curve;
    sfb_fillet_report r0, r1;
    double *a0 = NULL, *a1 = NULL;
    memset(&fm, 0, sizeof fm);
    if (fs_box_cylinder(&fm, 48, 1.0f, 0.6f, 0.5f, 0.6f) != 0 || !(in = make_mesh(&fm))) {
        fail("relax/setup", "no box-cylinder");
        fs_free(&fm);
        return;
    }
    cfg = sfb_fillet_config_init(0.15f);
    memset(&curve, 0, sizeof curve);
    curve.vertices = fm.loop;
    curve.count = fm.loop_count;
    cfg.curves = &curve;
    cfg.curve_count = 1;
    if (sfb_mesh_fillet(g_ctx, in, &cfg, &out0, &r0) == SFB_SUCCESS) {
        cfg.relax = 10;
        if (sfb_mesh_fillet(g_ctx, in, &cfg, &out1, &r1) == SFB_SUCCESS) {
            sfb_mesh_desc d0, d1;
            int n0, n1;
            a0 = (double *)xmalloc(sizeof(double) * (size_t)fm.nf);
            a1 = (double *)xmalloc(sizeof(double) * (size_t)fm.nf);
            sfb_mesh_get_desc(out0, &d0);
            sfb_mesh_get_desc(out1, &d1);
            n0 = moved_min_angles(&fm, d0.positions, a0);
            n1 = moved_min_angles(&fm, d1.positions, a1);
            printf("relax: smallest angles of the moved triangles, 5th percentile %.2f deg (conformal map) -> %.2f (10 steps); smallest %.2f -> %.2f\n",
                   a0[n0 / 20], a1[n1 / 20], a0[0], a1[0]);
            check(!r0.curves[0].relaxed && r1.curves[0].relaxed && r1.faces_folded == 0 && r1.curves[0].max_deviation < 1e-3 * 0.15 &&
                      n0 == n1 && a1[n1 / 20] > a0[n0 / 20],
                  "relax/kept, on the sweep, evened out", "relaxed %d %d, folded %d, deviation %g, p5 %.2f -> %.2f", r0.curves[0].relaxed,
                  r1.curves[0].relaxed, r1.faces_folded, r1.curves[0].max_deviation, n0 ? a0[n0 / 20] : 0.0, n1 ? a1[n1 / 20] : 0.0);
            free(a0);
            free(a1);
            sfb_fillet_report_free(&r1);
            sfb_mesh_destroy(out1);
        } else fail("relax/runs", "%s", sfb_last_error(g_ctx));
        sfb_fillet_report_free(&r0);
        sfb_mesh_destroy(out0);
    } else fail("relax/runs", "%s", sfb_last_error(g_ctx));
    sfb_mesh_destroy(in);
    fs_free(&fm);
}

static void test_seam(void) {
    fs_mesh fm;
    sfb_mesh *in = NULL, *out = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_curve curve;
    sfb_fillet_report rep;
    sfb_result r;
    const double R = 0.5, rad = 0.15;
    memset(&fm, 0, sizeof fm);
    if (fs_box_cylinder(&fm, 48, 1.0f, 0.6f, (float)R, 0.6f) != 0 || !(in = make_mesh(&fm))) {
        fail("seam/setup", "no box-cylinder");
        fs_free(&fm);
        return;
    }
    cfg = sfb_fillet_config_init((float)rad);
    memset(&curve, 0, sizeof curve);
    curve.vertices = fm.loop;
    curve.count = fm.loop_count;
    cfg.curves = &curve;
    cfg.curve_count = 1;
    r = sfb_mesh_fillet(g_ctx, in, &cfg, &out, &rep);
    check(r == SFB_SUCCESS, "seam/runs", "%s: %s", sfb_result_string(r), sfb_last_error(g_ctx));
    if (r == SFB_SUCCESS) {
        sfb_mesh_desc d0, d1;
        int f, same = 1, e;
        long pairs;
        sfb_mesh_get_desc(in, &d0);
        sfb_mesh_get_desc(out, &d1);
        check(rep.curve_count == 1 && rep.curves[0].closed && !rep.curves[0].convex &&
                  fabs(rep.curves[0].spine_length - 2 * SFB__PI * (R + rad)) < 0.01 * 2 * SFB__PI * (R + rad),
              "seam/one closed concave spine", "curves %d closed %d convex %d spine %g (want %g)", rep.curve_count,
              rep.curves[0].closed, rep.curves[0].convex, rep.curves[0].spine_length, 2 * SFB__PI * (R + rad));
        for (f = 0; f < 3 * d0.face_count; ++f) same &= d0.face_vertices[f] == d1.face_vertices[f];
        check(same && d0.vertex_count == d1.vertex_count && d0.face_count == d1.face_count, "seam/connectivity unchanged", "faces differ");
        pairs = self_intersections(out, d1.face_count);
        check(pairs == 0, "seam/no self-intersections", "%ld intersecting triangle pairs", pairs);
        {
            /* normals across the linkage curves: faces all moved (fillet) vs all still (base) */
            const sfb__level *l = &in->base;
            unsigned char *mv = (unsigned char *)xmalloc((size_t)d0.vertex_count);
            double *inner = (double *)xmalloc(((size_t)l->ne + 1) * sizeof(double)), link_max = 0.0, med;
            int ni = 0, nl = 0, v;
            for (v = 0; v < d0.vertex_count; ++v)
                mv[v] = d0.positions[3 * v] != d1.positions[3 * v] || d0.positions[3 * v + 1] != d1.positions[3 * v + 1] ||
                        d0.positions[3 * v + 2] != d1.positions[3 * v + 2];
            for (e = 0; e < l->ne; ++e) {
                int fa, fb, ma = 0, mb = 0, c;
                double na[3], nb[3], ang;
                if (l->ef_off[e + 1] - l->ef_off[e] != 2) continue;
                fa = l->ef[l->ef_off[e]];
                fb = l->ef[l->ef_off[e] + 1];
                for (c = 0; c < 3; ++c) { ma += mv[d1.face_vertices[3 * fa + c]]; mb += mv[d1.face_vertices[3 * fb + c]]; }
                face_normal(d1.positions, d1.face_vertices + 3 * fa, na);
                face_normal(d1.positions, d1.face_vertices + 3 * fb, nb);
                ang = angle_between(na, nb);
                if (ma == 3 && mb == 3) inner[ni++] = ang;
                else if ((ma > 0 || mb > 0) && (ma < 3 || mb < 3)) { if (ang > link_max) link_max = ang; nl++; }
            }
            qsort(inner, (size_t)ni, sizeof(double), cmp_double);
            med = ni ? inner[(size_t)(0.95 * (ni - 1))] : 0.0;
            printf("seam: fillet edges %d (95th percentile dihedral %.2f deg: the tessellation's resolution), linkage edges %d "
                   "(largest dihedral %.2f deg)\n", ni, med * 180 / SFB__PI, nl, link_max * 180 / SFB__PI);
            check(ni > 0 && nl > 0 && (link_max - med) * 180 / SFB__PI < 2.0, "seam/normals continuous across the linkage",
                  "largest linkage dihedral %.2f deg exceeds the fillet's own %.2f deg by 2 deg or more", link_max * 180 / SFB__PI,
                  med * 180 / SFB__PI);
            free(mv);
            free(inner);
        }
        {
            /* mean curvature along the former seam, before and after */
            float *h0 = (float *)xmalloc((size_t)d0.vertex_count * sizeof(float)), *h1 = (float *)xmalloc((size_t)d0.vertex_count * sizeof(float));
            double m0 = 0.0, m1 = 0.0;
            int i, ok = sfb_mesh_mean_curvature(g_ctx, in, h0) == SFB_SUCCESS && sfb_mesh_mean_curvature(g_ctx, out, h1) == SFB_SUCCESS;
            for (i = 0; ok && i + 1 < fm.loop_count; ++i) {
                m0 += fabs(h0[fm.loop[i]]);
                m1 += fabs(h1[fm.loop[i]]);
            }
            if (fm.loop_count > 1) { m0 /= fm.loop_count - 1; m1 /= fm.loop_count - 1; }
            printf("seam: mean |H| along the seam %.3f before, %.3f after (ideal 1/(2r) = %.3f): %.1fx lower\n", m0, m1, 0.5 / rad,
                   m1 > 0 ? m0 / m1 : 0.0);
            check(ok && m1 > 0 && m0 / m1 >= 2.0, "seam/mean curvature drops", "before %g after %g", m0, m1);
            free(h0);
            free(h1);
        }
        sfb_fillet_report_free(&rep);
        sfb_mesh_destroy(out);
    }
    sfb_mesh_destroy(in);
    fs_free(&fm);
}

/* round: the footprint's convex corners rounded (0: sharp, where the ball touches the prism's
 * vertical edges in single points); the reflex corner stays sharp either way. */
static void test_self_intersection(float round, const char *name) {
    char nm[160];
    fs_mesh fm;
    sfb_mesh *in = NULL, *out = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_curve curve;
    sfb_fillet_report rep;
    sfb_result r;
    memset(&fm, 0, sizeof fm);
    if (fs_floor_lprism_round(&fm, 40, 2.5f, 0.3f, 1.0f, 0.4f, 0.5f, round) != 0 || !(in = make_mesh(&fm))) {
        snprintf(nm, sizeof nm, "%s/setup", name);
        fail(nm, "no L prism");
        fs_free(&fm);
        return;
    }
    cfg = sfb_fillet_config_init(0.25f);
    memset(&curve, 0, sizeof curve);
    curve.vertices = fm.loop;
    curve.count = fm.loop_count;
    cfg.curves = &curve;
    cfg.curve_count = 1;
    r = sfb_mesh_fillet(g_ctx, in, &cfg, &out, &rep);
    snprintf(nm, sizeof nm, "%s/runs", name);
    check(r == SFB_SUCCESS, nm, "%s: %s", sfb_result_string(r), sfb_last_error(g_ctx));
    if (r == SFB_SUCCESS) {
        const long pairs = self_intersections(out, fm.nf);
        printf("%s: %d spine loops cut, %d vertices moved, map %d, %ld intersecting triangle pairs\n", name, rep.curves[0].self_intersections,
               rep.curves[0].vertices_moved, rep.curves[0].map, pairs);
        snprintf(nm, sizeof nm, "%s/loop cut", name);
        check(rep.curves[0].self_intersections >= 1, nm, "%d spine loops cut", rep.curves[0].self_intersections);
        snprintf(nm, sizeof nm, "%s/no intersecting triangles", name);
        check(pairs == 0, nm, "%ld intersecting triangle pairs", pairs);
        sfb_fillet_report_free(&rep);
        sfb_mesh_destroy(out);
    }
    sfb_mesh_destroy(in);
    fs_free(&fm);
}

/* A failing call: the code, a message, *out NULL, the input's positions as they were. */
static void expect_error(sfb_mesh *in, const sfb_fillet_config *cfg, sfb_result want, const char *name) {
    sfb_mesh_desc d;
    sfb_mesh *out = (sfb_mesh *)(void *)&d; /* not NULL before the call */
    float *copy;
    sfb_result r;
    int same;
    sfb_mesh_get_desc(in, &d);
    copy = (float *)xmalloc((size_t)d.vertex_count * 3 * sizeof(float));
    memcpy(copy, d.positions, (size_t)d.vertex_count * 3 * sizeof(float));
    sfb_clear_error(g_ctx);
    r = sfb_mesh_fillet(g_ctx, in, cfg, &out, NULL);
    same = memcmp(copy, d.positions, (size_t)d.vertex_count * 3 * sizeof(float)) == 0;
    check(r == want && out == NULL && same && sfb_last_error(g_ctx)[0], name, "got %s (want %s), out %p, input %s, message '%s'",
          sfb_result_string(r), sfb_result_string(want), (void *)out, same ? "kept" : "CHANGED", sfb_last_error(g_ctx));
    if (r == SFB_SUCCESS && out) sfb_mesh_destroy(out);
    free(copy);
}

/* Junctions of curves of both convexities: the L prism with sharp vertical corners filleted all by
 * angle (the floor seam concave, the prism's edges convex, meeting at the footprint's corners).
 * No exact blend there (see sfb__fil_junction): the call succeeds, every position is finite, and
 * the regions no longer overlap wholesale -- at most 60 intersecting triangle pairs are left
 * around the junctions (27 measured; 767 when every sweep ran to the junction vertex). */
static void test_junctions(void) {
    fs_mesh fm;
    sfb_mesh *in = NULL, *out = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_report rep;
    sfb_result r;
    memset(&fm, 0, sizeof fm);
    if (fs_floor_lprism(&fm, 40, 2.5f, 0.3f, 1.0f, 0.4f, 0.5f) != 0 || !(in = make_mesh(&fm))) {
        fail("junctions/setup", "no L prism");
        fs_free(&fm);
        return;
    }
    cfg = sfb_fillet_config_init(0.1f);
    r = sfb_mesh_fillet(g_ctx, in, &cfg, &out, &rep);
    check(r == SFB_SUCCESS && out, "junctions/runs", "%s: %s", sfb_result_string(r), sfb_last_error(g_ctx));
    if (r == SFB_SUCCESS && out) {
        sfb_mesh_desc d;
        int v, finite = 1;
        long pairs;
        sfb_mesh_get_desc(out, &d);
        for (v = 0; v < 3 * d.vertex_count; ++v) finite &= isfinite(d.positions[v]) != 0;
        pairs = self_intersections(out, fm.nf);
        printf("junctions: %d curves, %d corners, %d vertices moved, %d faces turned over, %ld intersecting triangle pairs\n", rep.curve_count,
               rep.corner_count, rep.vertices_moved, rep.faces_folded, pairs);
        check(finite && rep.curve_count >= 10 && rep.corner_count == 6 && pairs >= 0 && pairs <= 60, "junctions/the regions do not overlap",
              "finite %d, %d curves, %d corners, %ld intersecting pairs", finite, rep.curve_count, rep.corner_count, pairs);
        sfb_fillet_report_free(&rep);
        sfb_mesh_destroy(out);
    }
    sfb_mesh_destroy(in);
    fs_free(&fm);
}

/* A logger that counts the skip_failed lines and keeps the last. */
typedef struct skip_log {
    int skips;
    char msg[1024];
} skip_log;
static void skip_logger(int level, const char *msg, void *user) {
    skip_log *l = (skip_log *)user;
    if (level == SFB_LOG_WARN && strstr(msg, "left sharp (skip_failed)")) {
        l->skips++;
        snprintf(l->msg, sizeof l->msg, "%s", msg);
    }
}

/* config.skip_failed: the step's concave edge given a radius its base patches cannot hold (2.0 on
 * a 1.0 deep step): refused whole without it; with it, that curve is reported skipped and its
 * vertices stay, the convex edge is filleted; every curve failing is still an error. */
static void test_skip_failed(void) {
    fs_mesh fm;
    sfb_mesh *in = NULL, *out = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_curve curves[2];
    sfb_fillet_report rep;
    sfb_result r;
    memset(&fm, 0, sizeof fm);
    if (fs_step(&fm, 40, 2.0f, 1.0f, 1.0f) != 0 || !(in = make_mesh(&fm))) {
        fail("skip/setup", "no step");
        fs_free(&fm);
        return;
    }
    cfg = sfb_fillet_config_init(0.2f);
    memset(curves, 0, sizeof curves);
    curves[0].vertices = fm.loop;
    curves[0].count = fm.loop_count;
    curves[1].vertices = fm.loop + fm.loop_count;
    curves[1].count = fm.loop_count;
    curves[1].radius = 2.0f;
    cfg.curves = curves;
    cfg.curve_count = 2;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "skip/without it the call fails");
    cfg.skip_failed = 1;
    r = sfb_mesh_fillet(g_ctx, in, &cfg, &out, &rep);
    check(r == SFB_SUCCESS && out, "skip/with it the call succeeds", "%s: %s", sfb_result_string(r), sfb_last_error(g_ctx));
    if (r == SFB_SUCCESS && out) {
        sfb_mesh_desc d;
        int v, moved_near[2] = {0, 0};
        sfb_mesh_get_desc(out, &d);
        for (v = 0; v < fm.nv; ++v) {
            const float *p0 = fm.pos + 3 * v, *p1 = d.positions + 3 * v;
            const int e = hypot(p0[1], p0[2]) <= hypot(p0[1], p0[2] + 1.0) ? 0 : 1;
            if (p0[0] != p1[0] || p0[1] != p1[1] || p0[2] != p1[2]) moved_near[e]++;
        }
        check(rep.curve_count == 2 && !rep.curves[0].skipped && rep.curves[1].skipped && rep.curves_skipped == 1 && moved_near[0] > 0 &&
                  moved_near[1] == 0 && rep.vertices_moved == moved_near[0],
              "skip/the failing curve skipped and left as it was", "skipped %d %d (count %d), moved near the edges %d %d, reported %d",
              rep.curve_count > 0 ? rep.curves[0].skipped : -1, rep.curve_count > 1 ? rep.curves[1].skipped : -1, rep.curves_skipped,
              moved_near[0], moved_near[1], rep.vertices_moved);
        sfb_fillet_report_free(&rep);
        sfb_mesh_destroy(out);
    }
    {
        /* the skipped curve's reason goes to the logger, and the caller's last error is left as
         * it was (a context of its own, with a logger) */
        sfb_context_config cc = sfb_context_config_init();
        sfb_context *lc = NULL;
        skip_log lg;
        memset(&lg, 0, sizeof lg);
        cc.logger.func = skip_logger;
        cc.logger.user = &lg;
        if (sfb_context_create(&cc, &lc) != SFB_SUCCESS) fail("skip/logger context", "none");
        else {
            sfb_fillet_config bad = sfb_fillet_config_init(-1.0f);
            sfb_mesh *o2 = NULL;
            char earlier[1024];
            snprintf(earlier, sizeof earlier, "%s", sfb_mesh_fillet(lc, in, &bad, &o2, NULL) != SFB_SUCCESS ? sfb_last_error(lc) : "");
            r = sfb_mesh_fillet(lc, in, &cfg, &o2, NULL);
            check(r == SFB_SUCCESS && o2 && earlier[0] && strcmp(sfb_last_error(lc), earlier) == 0 && lg.skips == 1 && strstr(lg.msg, "curve 1"),
                  "skip/the reason logged, the caller's last error kept", "%s; last error '%s' (earlier '%s'); %d skip lines, last '%s'",
                  sfb_result_string(r), sfb_last_error(lc), earlier, lg.skips, lg.msg);
            if (o2) sfb_mesh_destroy(o2);
            sfb_context_destroy(lc);
        }
    }
    curves[0].radius = 2.0f;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "skip/every curve failing is still an error");
    sfb_mesh_destroy(in);
    fs_free(&fm);
}

static void test_bad_input(void) {
    fs_mesh fm, flat;
    sfb_mesh *in = NULL, *fl = NULL, *quad = NULL, *nonman = NULL;
    sfb_fillet_config cfg;
    sfb_fillet_curve curve;
    int bogus[3];
    memset(&fm, 0, sizeof fm);
    memset(&flat, 0, sizeof flat);
    if (fs_fold(&fm, 20, 2.0f, 1.0f, 90.0f, 0) != 0 || !(in = make_mesh(&fm))) { fail("bad/setup", "no fold"); fs_free(&fm); return; }
    cfg = sfb_fillet_config_init(0.0f);
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/radius 0");
    cfg.radius = -1.0f;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/radius negative");
    cfg.radius = (float)NAN;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/radius NaN");
    cfg.radius = (float)INFINITY;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/radius infinite");
    cfg.radius = 10.0f;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/radius too large");
    cfg.radius = 1e30f; /* every face a base patch, the offsets 1e30 away: refused, not a sweep of radius 1e30 */
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/radius far beyond the mesh");
    cfg.radius = 3.4e38f;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/radius FLT_MAX");
    cfg = sfb_fillet_config_init(0.2f);
    cfg.profile = SFB_FILLET_HERMITE;
    cfg.hermite_scale = 1e30f;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/Hermite scale");
    cfg = sfb_fillet_config_init(0.2f);
    cfg.profile = 7;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/profile");
    cfg = sfb_fillet_config_init(0.2f);
    cfg.conic_weight = -1.0f;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/conic weight");
    cfg = sfb_fillet_config_init(0.2f);
    cfg.angle = 200.0f;
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/angle");
    cfg = sfb_fillet_config_init(0.2f);
    cfg.angle = 120.0f; /* the fold's 90 degrees is no feature then */
    expect_error(in, &cfg, SFB_INVALID_VALUE, "bad/no feature over the angle");
    if (fs_fold(&flat, 10, 2.0f, 1.0f, 180.0f, 0) == 0 && (fl = make_mesh(&flat))) {
        cfg = sfb_fillet_config_init(0.2f);
        expect_error(fl, &cfg, SFB_INVALID_VALUE, "bad/flat: no feature");
    } else fail("bad/flat: no feature", "no flat sheet");
    /* a caller's curve that is not a chain of edges */
    cfg = sfb_fillet_config_init(0.2f);
    bogus[0] = fm.loop[0];
    bogus[1] = fm.loop[fm.loop_count - 1];
    bogus[2] = fm.loop[1];
    memset(&curve, 0, sizeof curve);
    curve.vertices = bogus;
    curve.count = 2;
    cfg.curves = &curve;
    cfg.curve_count = 1;
    expect_error(in, &cfg, SFB_INVALID_TOPOLOGY, "bad/curve not a chain of edges");
    bogus[1] = fm.nv + 5;
    expect_error(in, &cfg, SFB_INVALID_TOPOLOGY, "bad/curve vertex out of range");
    curve.count = 1;
    expect_error(in, &cfg, SFB_INVALID_ARGS, "bad/curve of one vertex");
    {
        /* a quad mesh; a non-manifold edge (three triangles on one edge) */
        static const float qp[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
        static const int qs[] = {4}, qv[] = {0, 1, 2, 3};
        static const float np_[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0};
        static const int ns[] = {3, 3, 3}, nv_[] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
        sfb_mesh_desc d;
        memset(&d, 0, sizeof d);
        d.vertex_count = 4; d.positions = qp; d.face_count = 1; d.face_sizes = qs; d.face_vertices = qv;
        if (sfb_mesh_create(g_ctx, &d, &quad) == SFB_SUCCESS) {
            cfg = sfb_fillet_config_init(0.2f);
            expect_error(quad, &cfg, SFB_INVALID_TOPOLOGY, "bad/quad mesh");
        } else fail("bad/quad mesh", "could not build it: %s", sfb_last_error(g_ctx));
        memset(&d, 0, sizeof d);
        d.vertex_count = 5; d.positions = np_; d.face_count = 3; d.face_sizes = ns; d.face_vertices = nv_;
        if (sfb_mesh_create(g_ctx, &d, &nonman) == SFB_SUCCESS) {
            cfg = sfb_fillet_config_init(0.2f);
            expect_error(nonman, &cfg, SFB_INVALID_TOPOLOGY, "bad/non-manifold mesh");
        } else skip("bad/non-manifold mesh", "sfb_mesh_create refuses it already");
    }
    {
        sfb_mesh *o = NULL;
        check(sfb_mesh_fillet(g_ctx, in, NULL, &o, NULL) == SFB_INVALID_ARGS && !o, "bad/NULL config", "accepted");
        cfg = sfb_fillet_config_init(0.2f);
        check(sfb_mesh_fillet(g_ctx, NULL, &cfg, &o, NULL) == SFB_INVALID_ARGS && !o, "bad/NULL mesh", "accepted");
    }
    sfb_mesh_destroy(quad);
    sfb_mesh_destroy(nonman);
    sfb_mesh_destroy(fl);
    sfb_mesh_destroy(in);
    fs_free(&fm);
    fs_free(&flat);
}

/* ---- progress, cancellation, budget ---- */
typedef struct prog { char stages[32][32]; int n, cancel_at; } prog;
static int on_progress(float done, const char *stage, void *user) {
    prog *p = (prog *)user;
    (void)done;
    if (p->n < 32) snprintf(p->stages[p->n], sizeof p->stages[0], "%s", stage);
    p->n++;
    return p->cancel_at >= 0 && p->n > p->cancel_at;
}

static void test_progress(void) {
    fs_mesh fm;
    prog p;
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx;
    sfb_mesh *in = NULL, *out = NULL;
    sfb_fillet_config cfg = sfb_fillet_config_init(0.2f);
    int k, total, ok = 1;
    memset(&fm, 0, sizeof fm);
    memset(&p, 0, sizeof p);
    p.cancel_at = -1;
    cc.progress.func = on_progress;
    cc.progress.user = &p;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) { fail("progress/context", "none"); return; }
    if (fs_fold(&fm, 20, 2.0f, 1.0f, 90.0f, 0) != 0 || fs_to_mesh(ctx, &fm, &in) != SFB_SUCCESS) { fail("progress/setup", "no fold"); goto done; }
    check(sfb_mesh_fillet(ctx, in, &cfg, &out, NULL) == SFB_SUCCESS && p.n >= 5, "progress/reports", "%d reports", p.n);
    {
        static const char *order[] = {"fillet curves", "fillet spine", "fillet surface", "fillet map", "fillet project"};
        for (k = 0; k < 5 && k < p.n; ++k) ok &= strcmp(p.stages[k], order[k]) == 0;
        check(ok, "progress/stages in order", "first stages %s, %s, ...", p.stages[0], p.stages[1]);
    }
    sfb_mesh_destroy(out);
    out = NULL;
    total = p.n;
    ok = 1;
    for (k = 0; k < total; ++k) {
        sfb_result r;
        p.n = 0;
        p.cancel_at = k;
        r = sfb_mesh_fillet(ctx, in, &cfg, &out, NULL);
        ok &= r == SFB_CANCELLED && out == NULL;
        if (out) { sfb_mesh_destroy(out); out = NULL; }
    }
    check(ok, "progress/cancel at every report", "a cancelled fillet returned something");
    sfb_mesh_destroy(in);
    in = NULL;
    sfb_context_destroy(ctx);
    ctx = NULL;
    {
        /* a budget too small for the work arrays, large enough for the mesh */
        sfb_context_config bc = sfb_context_config_init();
        sfb_result r;
        bc.memory_budget = 200000;
        if (sfb_context_create(&bc, &ctx) != SFB_SUCCESS) { fail("budget/context", "none"); goto done; }
        if (fs_to_mesh(ctx, &fm, &in) != SFB_SUCCESS) { fail("budget/setup", "%s", sfb_last_error(ctx)); goto done; }
        r = sfb_mesh_fillet(ctx, in, &cfg, &out, NULL);
        check(r == SFB_LIMIT_EXCEEDED && out == NULL, "budget/refused before the work", "%s: %s", sfb_result_string(r), sfb_last_error(ctx));
        if (out) sfb_mesh_destroy(out);
    }
done:
    sfb_mesh_destroy(in);
    if (ctx) sfb_context_destroy(ctx);
    fs_free(&fm);
}

int main(void) {
    if (sfb_context_create(NULL, &g_ctx) != SFB_SUCCESS) { printf("0 passed, 1 failed\n"); return 1; }
    test_fold(90.0, 0, SFB_FILLET_ARC, 0.0, "fold 90 convex arc");
    test_fold(90.0, 1, SFB_FILLET_ARC, 0.0, "fold 90 concave arc");
    test_fold(120.0, 0, SFB_FILLET_ARC, 0.0, "fold 120 convex arc");
    test_fold(120.0, 1, SFB_FILLET_ARC, 0.0, "fold 120 concave arc");
    test_fold(90.0, 0, SFB_FILLET_CONIC, 0.4, "fold 90 conic 0.4");
    test_fold(90.0, 1, SFB_FILLET_CONIC, 1.6, "fold 90 concave conic 1.6");
    test_fold(120.0, 0, SFB_FILLET_HERMITE, 0.0, "fold 120 hermite");
    test_fold_holes(90.0, 0, SFB_FILLET_ARC, 0.0, 1, "fold 90 convex arc, 4 holes in the region");
    test_fold_holes(90.0, 1, SFB_FILLET_CONIC, 0.6, 1, "fold 90 concave conic 0.6, 4 holes in the region");
    test_step();
    test_box_corners();
    test_relax();
    test_sharpen();
    test_seam();
    test_self_intersection(0.0f, "self-intersection");
    test_self_intersection(0.1f, "self-intersection rounded");
    test_bad_input();
    test_skip_failed();
    test_junctions();
    test_progress();
    sfb_context_destroy(g_ctx);
    return close_tests();
}
