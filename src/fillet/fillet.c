/* Seed 002: rolling-ball blending (fillets) of sharp features on triangle meshes, connectivity
 * unchanged. sfb_mesh_fillet runs, per blending curve:
 *   curves   feature edges over a dihedral angle chained into closed loops and open chains, or
 *            the caller's vertex chains (fillet_curves_*);
 *   spine    base patches within d of the curve, one per side; per-side vertex normals; offset
 *            patches; their intersection through two AABB trees (aabb.c) chained, the longest
 *            loop (closed curves) or chain (open ones) kept; spine loops cut out (seed 4.3);
 *   surface  spine samples by arc length, refined by chord height / chord length (seed 4.1); per
 *            sample the linkage points (the spine point's nearest point on each offset patch,
 *            carried back to the base face by its barycentric coordinates: seed 3 step 4) and a
 *            profile (arc, conic, sharpening polyline, Hermite; seed 4.2); ruled surfaces between
 *            consecutive profiles (seed eq. 1);
 *   map      each vertex of the blend region gets (t, a): first directly (t from its nearest point
 *            on its side's linkage polyline, a from how far it lies past its side's linkage point
 *            toward the curve), then, inside the region, the cotangent (conformal) map with those
 *            boundary values solved by conjugate gradients (sparse.c); mean-value weights where the
 *            cotangent map folds, the direct values where both fold;
 *   project  the vertex moves to the ruled surface at (t, a).
 * Choices where the seed is silent, and why:
 *  - No splitting path: a closed spine's t is periodic and each edge of the map carries its jump
 *    (the smaller difference), so the region needs no disc topology; blend regions with holes or
 *    several boundary loops (seed 7's failure) map like any other, and open chains need no
 *    splitting either. SFB_FILLET_MAP_DIRECT keeps the direct values throughout. Across the
 *    region, a is arc-length-like: the blending curve goes to the profile's middle by arc length
 *    when both linkage distances are equal.
 *  - Region membership is a half-space test at the vertex's own linkage point (past it toward the
 *    curve), not a distance to the curve: at a reflex corner of the seam the ball sits in the
 *    corner and the vertices behind it have no profile plane of their own; the distance test left
 *    single vertices there out and stretched triangles across the corner (8014 intersecting pairs
 *    on the L prism of tests/fillet.c before, 0 after).
 *  - Consecutive profiles are joined at equal arc-length fractions (a ruled surface whose rulings
 *    join points at the same fraction a), not at equal rational parameter u: profiles of
 *    different opening angles then still pair corresponding points.
 *  - d grows with the curve's sharpest dihedral angle: the linkage points lie r tan(delta/2) from
 *    the curve (delta the dihedral angle between the face normals), beyond alpha r when delta >
 *    120 degrees; d = alpha r max(1, tan(delta/2)).
 *  - Sides: the face holding the curve's edge in the curve's direction is side 0. The two base
 *    patches grow breadth first at the same time, so around the ends of an open chain they meet
 *    halfway instead of one swallowing the other.
 *  - Convex or concave per curve: side 1's faces lie below side 0's tangent plane (summed over the
 *    curve's edges) for a convex edge. Convex: offsets against the normals; concave: along them.
 *  - Every curve is filleted on the input's positions (each writes its own region), and base
 *    patches stop at the edges of the call's other curves: where curves meet at a corner their
 *    regions then end at the corner's planes instead of wrapping round onto the third face. (One
 *    after the other, each on the positions the earlier ones left, the box's edges crumpled at
 *    the corners and the crumples fed the next curves' offsets: spines ran away to 44x their
 *    length.)
 *  - Corners (sfb__fil_corner): three arc curves of one convexity and radius ending at a vertex
 *    on three planes get the ball's sphere (exact: the rolling ball touching all three faces). Other
 *    junctions (mixed convexity, other profiles, curved faces, more than three curves) keep each
 *    curve's sweep ending at the plane through the vertex. */


#define SFB__FIL_TAB 48 /* profile arc-length table intervals */

typedef struct sfb__fil_curve {
    int *v;           /* vertices, closed: v[n-1] == v[0] */
    int n, closed;
    double radius;
    int profile;
    double conic_w;
    int corner[2];    /* per end (v[0], v[n-1]): the corner (sfb__fil_corner) it ends at, or -1 */
    double setback[2];/* per end at another junction (sfb__fil_junction): how far before it the sweep stops; 0: none */
} sfb__fil_curve;

/* A junction: any other vertex where two or more open curves end (curves of both convexities,
 * other profiles or radii, faces not on three planes, more than three curves: a prism's sharp
 * vertical edge standing on a filleted floor seam). There is no exact rolling-ball answer the
 * seed gives; each curve's sweep stops `s` before it (the largest reach of the curves there, r
 * max(1, tan(delta / 2))), so that their regions do not overlap, and the vertices around it that
 * no sweep moved take the harmonic interpolation of the moves around them (a membrane patch:
 * continuous, no exact geometry). Before, every sweep ran to the vertex and the regions overlapped:
 * the L prism with sharp vertical corners, filleted by angle, had 767 intersecting triangle pairs. */
typedef struct sfb__fil_junction {
    int v;
    double s;
} sfb__fil_junction;

/* A corner: a vertex where exactly three open curves end, all convex or all concave, all with the
 * arc profile and one radius, around
 * which the faces lie on three planes (within 2 % of r). The ball touches all three there: its
 * centre C is r from each plane (inside the solid for convex curves, outside for concave ones),
 * each curve's sweep ends in the plane through C across its end, and the vertices beyond all
 * three end planes move onto the ball's sphere. (The seed fillets closed curves only; this is the
 * rolling ball's own answer at a corner: the three cylinders meet the sphere along their end
 * circles, tangent-continuous.) */
typedef struct sfb__fil_corner {
    int v;            /* the corner vertex */
    double C[3], r;   /* the ball's centre and radius */
    double u[3][3];   /* per curve end: unit direction out of the curve into the corner */
    int curve[3];     /* the three curves */
    int moved;
} sfb__fil_corner;

typedef struct sfb__fil_prof {
    double P1[3], P0[3], P2[3], C[3], E[3];
    double w, r, L1, L2;   /* middle weight; radius; linkage distances from the curve, sides 0 and 1 */
    double T[SFB__FIL_TAB + 1][3];
    double acc[SFB__FIL_TAB + 1]; /* arc length fractions of T */
} sfb__fil_prof;

typedef struct sfb__fil {
    sfb_context *ctx;
    const sfb_fillet_config *cfg;
    const sfb__level *l;
    int nv, nf;
    const int *tri;
    double *pos, *fn;      /* the input's positions; unit face normals */
    double *npos;          /* positions after the current curve */
    double *opos;          /* the output's positions: every curve and corner writes its moved vertices */
    unsigned char *fmark;  /* per edge: on any blending curve of this call (base patches stop there) */
    sfb__fil_corner *corners;
    int ncorners;
    sfb__fil_junction *junctions;
    int njunctions;
    double scale;          /* bounding-box diagonal */
    sfb__fil_curve *curves;
    int ncurves, curves_cap;
    unsigned char *emark;  /* per edge: on the current curve */
} sfb__fil;

/* ---- small vector helpers ---- */
static double fil_dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void fil_sub(const double *a, const double *b, double *o) { o[0] = a[0] - b[0]; o[1] = a[1] - b[1]; o[2] = a[2] - b[2]; }
static double fil_len(const double *a) { return sqrt(fil_dot(a, a)); }
static double fil_dist(const double *a, const double *b) {
    double d[3];
    fil_sub(a, b, d);
    return fil_len(d);
}
static void fil_lerp(const double *a, const double *b, double t, double *o) {
    o[0] = a[0] + t * (b[0] - a[0]); o[1] = a[1] + t * (b[1] - a[1]); o[2] = a[2] + t * (b[2] - a[2]);
}
static void fil_cross(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1]; o[1] = a[2] * b[0] - a[0] * b[2]; o[2] = a[0] * b[1] - a[1] * b[0];
}
/* Nearest point of segment a-b to p: its parameter in [0,1]. */
static double fil_seg_param(const double *p, const double *a, const double *b) {
    double ab[3], ap[3], l2, t;
    fil_sub(b, a, ab); fil_sub(p, a, ap);
    l2 = fil_dot(ab, ab);
    if (!(l2 > 0.0)) return 0.0;
    t = fil_dot(ap, ab) / l2;
    return t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
}

static int fil_edge_of(const sfb__level *l, int a, int b) {
    int k;
    for (k = l->ve_off[a]; k < l->ve_off[a + 1]; ++k) {
        const int e = l->ve[k];
        if (sfb__other_end(l, e, a) == b) return e;
    }
    return -1;
}

static void fil_face_normals(sfb__fil *F) {
    int f;
    for (f = 0; f < F->nf; ++f) {
        const double *a = F->pos + 3 * (size_t)F->tri[3 * f], *b = F->pos + 3 * (size_t)F->tri[3 * f + 1],
                     *c = F->pos + 3 * (size_t)F->tri[3 * f + 2];
        double u[3], v[3], n[3], ln;
        fil_sub(b, a, u); fil_sub(c, a, v); fil_cross(u, v, n);
        ln = fil_len(n);
        if (ln > 0.0) { n[0] /= ln; n[1] /= ln; n[2] /= ln; } else n[0] = n[1] = n[2] = 0.0;
        memcpy(F->fn + 3 * (size_t)f, n, sizeof n);
    }
}

/* Angle between the normals of edge e's two faces (radians); -1 for an edge without two faces. */
static double fil_dihedral(const sfb__fil *F, int e) {
    const sfb__level *l = F->l;
    double c;
    if (l->ef_off[e + 1] - l->ef_off[e] != 2) return -1.0;
    c = fil_dot(F->fn + 3 * (size_t)l->ef[l->ef_off[e]], F->fn + 3 * (size_t)l->ef[l->ef_off[e] + 1]);
    c = c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c;
    return acos(c);
}

/* ---- curves ---- */
static sfb_result fil_add_curve(sfb__fil *F, const int *v, int n, int closed, double radius, int profile, double w) {
    sfb__fil_curve *c;
    if (F->ncurves == F->curves_cap) {
        const int cap = F->curves_cap ? 2 * F->curves_cap : 8;
        sfb__fil_curve *nc = (sfb__fil_curve *)sfb__realloc(F->ctx, F->curves, (size_t)cap * sizeof *nc);
        if (!nc) return sfb__oom(F->ctx, "the blending curves");
        F->curves = nc;
        F->curves_cap = cap;
    }
    c = &F->curves[F->ncurves];
    c->v = (int *)sfb__alloc(F->ctx, (size_t)n * sizeof(int));
    if (!c->v) return sfb__oom(F->ctx, "a blending curve");
    memcpy(c->v, v, (size_t)n * sizeof(int));
    c->n = n;
    c->closed = closed;
    c->corner[0] = c->corner[1] = -1;
    c->setback[0] = c->setback[1] = 0.0;
    c->radius = radius;
    c->profile = profile;
    c->conic_w = w;
    F->ncurves++;
    return SFB_SUCCESS;
}

/* How far from a curve the ball of radius r touches the faces: r tan(delta / 2) for the sharpest
 * dihedral angle delta (capped at 170 degrees), at least r. The base patches reach alpha times it;
 * a junction's setback is the largest of its curves'. */
static double fil_reach(double r, double delta) {
    const double t = tan(0.5 * (delta < 170.0 * SFB__PI / 180.0 ? delta : 170.0 * SFB__PI / 180.0));
    return r * (t > 1.0 ? t : 1.0);
}

/* Edge e (a-b, two faces): negative when convex -- each face's third vertex lies below the other
 * face's plane -- positive when concave; summed over a curve's edges it decides the curve. */
static double fil_edge_conv(const sfb__fil *F, int e, int a, int b) {
    const sfb__level *l = F->l;
    const int f0 = l->ef[l->ef_off[e]], f1 = l->ef[l->ef_off[e] + 1];
    double conv = 0.0;
    int j;
    for (j = 0; j < 3; ++j) {
        const int o1 = F->tri[3 * f1 + j], o0 = F->tri[3 * f0 + j];
        double dv[3];
        if (o1 != a && o1 != b) { fil_sub(F->pos + 3 * (size_t)o1, F->pos + 3 * (size_t)a, dv); conv += fil_dot(dv, F->fn + 3 * (size_t)f0); }
        if (o0 != a && o0 != b) { fil_sub(F->pos + 3 * (size_t)o0, F->pos + 3 * (size_t)a, dv); conv += fil_dot(dv, F->fn + 3 * (size_t)f1); }
    }
    return conv;
}

/* Feature edges (dihedral angle over the threshold, two faces) chained: chains start at vertices
 * with other than two feature edges, or with one convex and one concave (a curve has one
 * convexity: its offsets go one way); what is left are closed loops. */
static sfb_result fil_curves_from_angle(sfb__fil *F) {
    const sfb__level *l = F->l;
    const double limit = (F->cfg->angle > 0.0f ? F->cfg->angle : 30.0f) * SFB__PI / 180.0;
    unsigned char *feat = (unsigned char *)sfb__calloc(F->ctx, (size_t)l->ne + 1, 1);
    int *deg = (int *)sfb__calloc(F->ctx, (size_t)l->nv + 1, sizeof(int));
    int *chain = (int *)sfb__alloc(F->ctx, ((size_t)l->ne + 2) * sizeof(int));
    signed char *vsign = (signed char *)sfb__calloc(F->ctx, (size_t)l->nv + 1, 1); /* 2: both convexities meet here */
    int e, v, pass, total = 0;
    sfb_result r = SFB_SUCCESS;
    if (!feat || !deg || !chain || !vsign) {
        r = sfb__oom(F->ctx, "the feature edges");
        goto done;
    }
    for (e = 0; e < l->ne; ++e)
        if (fil_dihedral(F, e) > limit) {
            const signed char sg = fil_edge_conv(F, e, l->ev[2 * e], l->ev[2 * e + 1]) < 0.0 ? -1 : 1;
            int k;
            feat[e] = 1;
            deg[l->ev[2 * e]]++;
            deg[l->ev[2 * e + 1]]++;
            for (k = 0; k < 2; ++k) {
                signed char *vs = &vsign[l->ev[2 * e + k]];
                *vs = *vs == 0 ? sg : *vs == sg ? *vs : 2;
            }
            total++;
        }
    if (!total) {
        r = sfb__error(F->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                       "no feature edge: no edge's dihedral angle exceeds %g degrees", limit * 180.0 / SFB__PI);
        goto done;
    }
    /* pass 0: chains from end vertices (degree != 2); pass 1: closed loops */
    for (pass = 0; pass < 2 && r == SFB_SUCCESS; ++pass)
        for (v = 0; v < l->nv && r == SFB_SUCCESS; ++v) {
            int k;
            if (pass == 0 && deg[v] == 2 && vsign[v] != 2) continue;
            for (k = l->ve_off[v]; k < l->ve_off[v + 1] && r == SFB_SUCCESS; ++k) {
                int cur = v, ce = l->ve[k], n = 0;
                if (!feat[ce]) continue;
                chain[n++] = v;
                while (ce >= 0) {
                    int nx = sfb__other_end(l, ce, cur), j;
                    feat[ce] = 0;
                    chain[n++] = nx;
                    cur = nx;
                    ce = -1;
                    if (nx == v || deg[nx] != 2 || vsign[nx] == 2) break;
                    for (j = l->ve_off[nx]; j < l->ve_off[nx + 1]; ++j)
                        if (feat[l->ve[j]]) { ce = l->ve[j]; break; }
                }
                r = fil_add_curve(F, chain, n, chain[n - 1] == chain[0], F->cfg->radius, F->cfg->profile, F->cfg->conic_weight);
            }
        }
done:
    sfb__free(F->ctx, feat);
    sfb__free(F->ctx, deg);
    sfb__free(F->ctx, chain);
    sfb__free(F->ctx, vsign);
    return r;
}

static sfb_result fil_curves_from_caller(sfb__fil *F) {
    const sfb_fillet_config *cfg = F->cfg;
    int c, i;
    for (c = 0; c < cfg->curve_count; ++c) {
        const sfb_fillet_curve *cc = &cfg->curves[c];
        sfb_result r;
        double radius = cc->radius != 0.0f ? cc->radius : cfg->radius;
        int profile = cc->profile ? cc->profile - 1 : cfg->profile;
        double w = cc->conic_weight != 0.0f ? cc->conic_weight : cfg->conic_weight;
        if (!cc->vertices || cc->count < 2)
            return sfb__error(F->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "blending curve %d: needs at least 2 vertices", c);
        if (!(radius > 0.0) || !isfinite(radius))
            return sfb__error(F->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "blending curve %d: radius %g is not a positive number", c, radius);
        if (profile < 0 || profile > SFB_FILLET_HERMITE)
            return sfb__error(F->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "blending curve %d: unknown profile %d", c, profile);
        if (!(w >= 0.0) || !isfinite(w))
            return sfb__error(F->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "blending curve %d: conic weight %g is not >= 0", c, w);
        for (i = 0; i < cc->count; ++i)
            if (cc->vertices[i] < 0 || cc->vertices[i] >= F->nv)
                return sfb__error(F->ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, cc->vertices[i],
                                  "blending curve %d: vertex %d is not a vertex of the mesh", c, cc->vertices[i]);
        for (i = 0; i + 1 < cc->count; ++i) {
            const int e = fil_edge_of(F->l, cc->vertices[i], cc->vertices[i + 1]);
            if (e < 0)
                return sfb__error(F->ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, cc->vertices[i + 1],
                                  "blending curve %d is not a chain of mesh edges: no edge from vertex %d to vertex %d", c,
                                  cc->vertices[i], cc->vertices[i + 1]);
            if (F->l->ef_off[e + 1] - F->l->ef_off[e] != 2)
                return sfb__error(F->ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, e,
                                  "blending curve %d: the edge from vertex %d to vertex %d is not between two faces", c,
                                  cc->vertices[i], cc->vertices[i + 1]);
        }
        r = fil_add_curve(F, cc->vertices, cc->count, cc->vertices[0] == cc->vertices[cc->count - 1] && cc->count > 3, radius,
                          profile, w);
        if (r != SFB_SUCCESS) return r;
    }
    return SFB_SUCCESS;
}

/* The corners (sfb__fil_corner): vertices where exactly three open curves end, with one
 * convexity, whose faces lie on three planes. Marks every curve's edges in fmark too. */
static sfb_result fil_find_corners(sfb__fil *F) {
    const sfb__level *l = F->l;
    int *ends = (int *)sfb__calloc(F->ctx, (size_t)F->nv + 1, sizeof(int));
    int c, k, i;
    if (!ends) return sfb__oom(F->ctx, "the corners");
    for (c = 0; c < F->ncurves; ++c) {
        const sfb__fil_curve *cv = &F->curves[c];
        for (i = 0; i + 1 < cv->n; ++i) {
            const int e = fil_edge_of(l, cv->v[i], cv->v[i + 1]);
            if (e >= 0) F->fmark[e] = 1;
        }
        if (!cv->closed) { ends[cv->v[0]]++; ends[cv->v[cv->n - 1]]++; }
    }
    for (c = 0; c < F->ncurves; ++c) {
        sfb__fil_curve *cv = &F->curves[c];
        for (k = 0; k < 2 && !cv->closed; ++k) {
            const int v = k ? cv->v[cv->n - 1] : cv->v[0];
            int members[3][2], nm = 0, sign = 0, ok = 1, d, j, known = -1;
            double A[3][3] = {{0}}, rhs[3] = {0}, det, tr, X[3], r = 0.0;
            sfb__fil_corner *K;
            if (ends[v] != 3) continue;
            for (j = 0; j < F->ncorners; ++j)
                if (F->corners[j].v == v) known = j;
            if (known >= 0) { cv->corner[k] = known; continue; }
            /* the three curve ends at v: one convexity, one radius */
            for (d = 0; d < F->ncurves && nm <= 3; ++d) {
                const sfb__fil_curve *w = &F->curves[d];
                int kk;
                for (kk = 0; kk < 2 && !w->closed; ++kk)
                    if ((kk ? w->v[w->n - 1] : w->v[0]) == v && nm < 3) {
                        double conv = 0.0;
                        for (j = 0; j + 1 < w->n; ++j) {
                            const int e = fil_edge_of(l, w->v[j], w->v[j + 1]);
                            if (e >= 0 && l->ef_off[e + 1] - l->ef_off[e] == 2) conv += fil_edge_conv(F, e, w->v[j], w->v[j + 1]);
                        }
                        if (sign == 0) sign = conv < 0 ? -1 : 1;
                        else if ((conv < 0 ? -1 : 1) != sign) ok = 0;
                        if (w->profile != SFB_FILLET_ARC) ok = 0; /* the sphere continues the arc only */
                        if (nm == 0) r = w->radius;
                        else if (fabs(w->radius - r) > 1e-9 * r) ok = 0;
                        members[nm][0] = d;
                        members[nm][1] = kk;
                        nm++;
                    }
            }
            if (!ok || nm != 3) continue;
            /* the ball's centre: r from every face plane around v, least squares (angle weighted) */
            for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j) {
                const int f = l->vf[j];
                const double *n = F->fn + 3 * (size_t)f;
                int q, p2;
                for (q = 0; q < 3; ++q) {
                    for (p2 = 0; p2 < 3; ++p2) A[q][p2] += n[q] * n[p2];
                    rhs[q] += n[q] * (fil_dot(n, F->pos + 3 * (size_t)v) + sign * r);
                }
            }
            det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                  A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
            tr = A[0][0] + A[1][1] + A[2][2];
            if (!(fabs(det) > 1e-3 * tr * tr * tr)) continue; /* fewer than three independent planes */
            for (j = 0; j < 3; ++j) {
                double M[3][3];
                int q;
                memcpy(M, A, sizeof M);
                for (q = 0; q < 3; ++q) M[q][j] = rhs[q];
                X[j] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                        M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
            }
            /* every face plane r from it (the faces around v lie on three planes) */
            for (j = l->vf_off[v]; j < l->vf_off[v + 1] && ok; ++j) {
                const double *n = F->fn + 3 * (size_t)l->vf[j];
                double dv[3];
                fil_sub(X, F->pos + 3 * (size_t)v, dv);
                if (fabs(fil_dot(n, dv) - sign * r) > 0.02 * r) ok = 0;
            }
            if (!ok) continue;
            if (F->ncorners % 8 == 0) {
                sfb__fil_corner *nc = (sfb__fil_corner *)sfb__realloc(F->ctx, F->corners, (size_t)(F->ncorners + 8) * sizeof *nc);
                if (!nc) { sfb__free(F->ctx, ends); return sfb__oom(F->ctx, "the corners"); }
                F->corners = nc;
            }
            K = &F->corners[F->ncorners];
            memset(K, 0, sizeof *K);
            K->v = v;
            K->r = r;
            memcpy(K->C, X, sizeof X);
            for (j = 0; j < 3; ++j) {
                const sfb__fil_curve *w = &F->curves[members[j][0]];
                const int a = members[j][1] ? w->v[w->n - 1] : w->v[0], b = members[j][1] ? w->v[w->n - 2] : w->v[1];
                double u[3], lu;
                fil_sub(F->pos + 3 * (size_t)a, F->pos + 3 * (size_t)b, u);
                lu = fil_len(u);
                for (d = 0; d < 3; ++d) K->u[j][d] = lu > 0 ? u[d] / lu : 0.0;
                K->curve[j] = members[j][0];
            }
            cv->corner[k] = F->ncorners++;
        }
    }
    /* the other junctions: the largest reach of the curves ending there */
    for (c = 0; c < F->ncurves; ++c) {
        sfb__fil_curve *cv = &F->curves[c];
        for (k = 0; k < 2 && !cv->closed; ++k) {
            const int v = k ? cv->v[cv->n - 1] : cv->v[0];
            double s = 0.0;
            int d, j, known = -1;
            if (ends[v] < 2 || cv->corner[k] >= 0) continue;
            for (j = 0; j < F->njunctions; ++j)
                if (F->junctions[j].v == v) known = j;
            if (known < 0) {
                for (d = 0; d < F->ncurves; ++d) {
                    const sfb__fil_curve *w = &F->curves[d];
                    double dm = 0.0, reach;
                    if (w->closed || (w->v[0] != v && w->v[w->n - 1] != v)) continue;
                    for (j = 0; j + 1 < w->n; ++j) {
                        const int e = fil_edge_of(l, w->v[j], w->v[j + 1]);
                        if (e >= 0 && fil_dihedral(F, e) > dm) dm = fil_dihedral(F, e);
                    }
                    reach = fil_reach(w->radius, dm);
                    if (reach > s) s = reach;
                }
                if (F->njunctions % 8 == 0) {
                    sfb__fil_junction *nj = (sfb__fil_junction *)sfb__realloc(F->ctx, F->junctions, (size_t)(F->njunctions + 8) * sizeof *nj);
                    if (!nj) { sfb__free(F->ctx, ends); return sfb__oom(F->ctx, "the junctions"); }
                    F->junctions = nj;
                }
                F->junctions[F->njunctions].v = v;
                F->junctions[F->njunctions].s = s;
                known = F->njunctions++;
            }
            cv->setback[k] = F->junctions[known].s;
        }
    }
    sfb__free(F->ctx, ends);
    return SFB_SUCCESS;
}

/* The junctions' membranes: around each junction vertex (within 2 s), the vertices no sweep or
 * corner moved get the harmonic interpolation (uniform weights, sparse CG) of the moves of the
 * vertices around them; those at 2 s and beyond keep theirs (mostly none). */
static sfb_result fil_junctions_fill(sfb__fil *F) {
    sfb_context *ctx = F->ctx;
    const sfb__level *l = F->l;
    int *loc = NULL, *list = NULL, *rowi = NULL, *coli = NULL, jn;
    double *val = NULL, *b = NULL, *x = NULL;
    sfb_result res = SFB_SUCCESS;
    if (F->njunctions == 0) return SFB_SUCCESS;
    loc = (int *)sfb__alloc(ctx, ((size_t)F->nv + 1) * sizeof(int));
    list = (int *)sfb__alloc(ctx, ((size_t)F->nv + 1) * sizeof(int));
    if (!loc || !list) { res = sfb__oom(ctx, "the junctions"); goto done; }
    for (jn = 0; jn < F->nv; ++jn) loc[jn] = -1;
    for (jn = 0; jn < F->njunctions; ++jn) {
        const sfb__fil_junction *J = &F->junctions[jn];
        const double *V = F->pos + 3 * (size_t)J->v, R = 1.25 * J->s;
        int head = 0, n = 0, nu = 0, i, j, c, nt = 0, it;
        double resid;
        /* the vertices within R of V, reached over edges; loc: -2 seen and fixed, >= 0 unknown */
        list[n++] = J->v;
        loc[J->v] = -2;
        while (head < n) {
            const int v = list[head++];
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                const int w = sfb__other_end(l, l->ve[j], v);
                if (loc[w] != -1 || fil_dist(F->pos + 3 * (size_t)w, V) >= R) continue;
                loc[w] = -2;
                list[n++] = w;
            }
        }
        for (i = 0; i < n; ++i) {
            const int v = list[i];
            int boundary = 0;
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) boundary |= l->ef_off[l->ve[j] + 1] - l->ef_off[l->ve[j]] != 2;
            if (!boundary && memcmp(F->pos + 3 * (size_t)v, F->opos + 3 * (size_t)v, 3 * sizeof(double)) == 0) loc[v] = nu++;
        }
        if (nu > 0) {
            size_t cap = 0;
            sfb__sparse A;
            memset(&A, 0, sizeof A);
            for (i = 0; i < n; ++i)
                if (loc[list[i]] >= 0) cap += (size_t)(l->ve_off[list[i] + 1] - l->ve_off[list[i]]) + 1;
            rowi = (int *)sfb__alloc(ctx, cap * sizeof(int));
            coli = (int *)sfb__alloc(ctx, cap * sizeof(int));
            val = (double *)sfb__alloc(ctx, cap * sizeof(double));
            b = (double *)sfb__calloc(ctx, (size_t)nu * 3, sizeof(double));
            x = (double *)sfb__calloc(ctx, (size_t)nu, sizeof(double));
            if (!rowi || !coli || !val || !b || !x) { res = sfb__oom(ctx, "the junctions"); goto done; }
            for (i = 0; i < n; ++i) {
                const int v = list[i], u = loc[v];
                if (u < 0) continue;
                rowi[nt] = u; coli[nt] = u; val[nt] = (double)(l->ve_off[v + 1] - l->ve_off[v]); nt++;
                for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                    const int w = sfb__other_end(l, l->ve[j], v);
                    if (loc[w] >= 0) { rowi[nt] = u; coli[nt] = loc[w]; val[nt] = -1.0; nt++; }
                    else
                        for (c = 0; c < 3; ++c) b[3 * (size_t)u + c] += F->opos[3 * (size_t)w + c] - F->pos[3 * (size_t)w + c];
                }
            }
            res = sfb__sparse_from_triplets(ctx, nu, nt, rowi, coli, val, &A);
            for (c = 0; c < 3 && res == SFB_SUCCESS; ++c) {
                double *bc = (double *)sfb__alloc(ctx, (size_t)nu * sizeof(double));
                if (!bc) { res = sfb__oom(ctx, "the junctions"); break; }
                for (i = 0; i < nu; ++i) { bc[i] = b[3 * (size_t)i + c]; x[i] = 0.0; }
                {
                    /* best effort: a solve that does not converge keeps its last iterate, said to
                     * the logger; the caller's last error is put back */
                    sfb__error_state kept;
                    sfb__error_keep(ctx, &kept);
                    if (sfb__sparse_cg(ctx, &A, bc, x, 1e-12, 4 * nu + 200, &it, &resid) != SFB_SUCCESS) {
                        sfb__log(ctx, SFB_LOG_INFO, "fillet junctions: %s; the last iterate is kept", ctx->error);
                        sfb__error_put_back(ctx, &kept);
                    }
                }
                for (i = 0; i < n; ++i)
                    if (loc[list[i]] >= 0 && isfinite(x[loc[list[i]]])) F->opos[3 * (size_t)list[i] + c] = F->pos[3 * (size_t)list[i] + c] + x[loc[list[i]]];
                sfb__free(ctx, bc);
            }
            sfb__sparse_free(ctx, &A);
            sfb__free(ctx, rowi); sfb__free(ctx, coli); sfb__free(ctx, val); sfb__free(ctx, b); sfb__free(ctx, x);
            rowi = coli = NULL; val = b = x = NULL;
            if (res != SFB_SUCCESS) goto done;
        }
        for (i = 0; i < n; ++i) loc[list[i]] = -1;
    }
done:
    sfb__free(ctx, loc); sfb__free(ctx, list);
    sfb__free(ctx, rowi); sfb__free(ctx, coli); sfb__free(ctx, val); sfb__free(ctx, b); sfb__free(ctx, x);
    return res;
}

/* The corners' spheres: from the corner vertex through the vertices beyond all three end planes
 * (within 4 r of the ball's centre), each moved to the sphere along the ray from the centre. */
static sfb_result fil_corners_project(sfb__fil *F, const sfb_fillet_curve_report *reps) {
    const sfb__level *l = F->l;
    int *stack = (int *)sfb__alloc(F->ctx, ((size_t)F->nv + 1) * sizeof(int));
    unsigned char *seen = (unsigned char *)sfb__calloc(F->ctx, (size_t)F->nv + 1, 1);
    int k;
    if (!stack || !seen) { sfb__free(F->ctx, stack); sfb__free(F->ctx, seen); return sfb__oom(F->ctx, "the corners"); }
    for (k = 0; k < F->ncorners; ++k) {
        sfb__fil_corner *K = &F->corners[k];
        int sp = 0, j;
        if (reps[K->curve[0]].skipped || reps[K->curve[1]].skipped || reps[K->curve[2]].skipped) continue; /* left sharp */
        stack[sp++] = K->v;
        seen[K->v] |= 1;
        while (sp > 0) {
            const int v = stack[--sp];
            const double *p = F->pos + 3 * (size_t)v;
            double dv[3], ld;
            int inside = 1;
            fil_sub(p, K->C, dv);
            ld = fil_len(dv);
            for (j = 0; j < 3; ++j) inside &= fil_dot(dv, K->u[j]) >= -1e-9 * K->r;
            if (!inside || !(ld > 0) || ld > 4.0 * K->r) continue;
            if (!(seen[v] & 2)) { /* a vertex two corners reach (a tiny mesh) moves once, for the first */
                for (j = 0; j < 3; ++j) F->opos[3 * (size_t)v + j] = K->C[j] + K->r * dv[j] / ld;
                K->moved++;
                seen[v] |= 2;
            }
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                const int w = sfb__other_end(l, l->ve[j], v);
                if (!(seen[w] & 1)) { seen[w] |= 1; stack[sp++] = w; }
            }
        }
        /* reset seen for the next corner: the visited set is small, walk it again */
        stack[0] = K->v;
        sp = 1;
        seen[K->v] &= (unsigned char)~1u;
        while (sp > 0) {
            const int v = stack[--sp];
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                const int w = sfb__other_end(l, l->ve[j], v);
                if (seen[w] & 1) { seen[w] &= (unsigned char)~1u; stack[sp++] = w; }
            }
        }
    }
    sfb__free(F->ctx, stack);
    sfb__free(F->ctx, seen);
    return SFB_SUCCESS;
}

/* ---- one curve ---- */
typedef struct sfb__fil_seg { double a[3], b[3]; } sfb__fil_seg;
typedef struct sfb__fil_pairs {
    sfb__fil *F;
    const double *op0, *op1;
    const int *t0, *t1;
    sfb__fil_seg *segs;
    size_t n, cap;
    int failed;
} sfb__fil_pairs;

static int fil_pair_cb(int i, int j, void *user) {
    sfb__fil_pairs *P = (sfb__fil_pairs *)user;
    const int *a = P->t0 + 3 * (size_t)i, *b = P->t1 + 3 * (size_t)j;
    double s0[3], s1[3];
    if (sfb__tri_tri_segment(P->op0 + 3 * (size_t)a[0], P->op0 + 3 * (size_t)a[1], P->op0 + 3 * (size_t)a[2],
                             P->op1 + 3 * (size_t)b[0], P->op1 + 3 * (size_t)b[1], P->op1 + 3 * (size_t)b[2], s0, s1, NULL,
                             NULL) != 1)
        return 0;
    if (P->n == P->cap) {
        const size_t cap = P->cap ? 2 * P->cap : 256;
        sfb__fil_seg *ns = (sfb__fil_seg *)sfb__realloc(P->F->ctx, P->segs, cap * sizeof *ns);
        if (!ns) { P->failed = 1; return 1; }
        P->segs = ns;
        P->cap = cap;
    }
    memcpy(P->segs[P->n].a, s0, sizeof s0);
    memcpy(P->segs[P->n].b, s1, sizeof s1);
    P->n++;
    return 0;
}

typedef struct sfb__fil_key { double x; int id; } sfb__fil_key;
static int fil_key_cmp(const void *a, const void *b) {
    const double x = ((const sfb__fil_key *)a)->x, y = ((const sfb__fil_key *)b)->x;
    return x < y ? -1 : x > y ? 1 : 0;
}

/* Chains intersection segments into the spine: endpoints welded within tol, duplicate pieces
 * dropped, then walks along unused pieces (through a node where pieces cross, the straightest way
 * on); stray bits and non-manifold branches end up in walks of their own and are dropped by
 * keeping one walk: the longest closed loop when `want_closed` (else the longest walk), the longest
 * open chain otherwise (a closed loop when there is none). Writes the points (closed: not repeated). */
static sfb_result fil_chain(sfb_context *ctx, const sfb__fil_seg *segs, size_t ns, double tol, int want_closed, double **out,
                            int *out_n, int *out_closed) {
    const size_t np = 2 * ns;
    sfb__fil_key *keys = (sfb__fil_key *)sfb__alloc(ctx, (np + 1) * sizeof *keys);
    int *node = (int *)sfb__alloc(ctx, (np + 1) * sizeof(int));
    int *deg = NULL, *path = NULL, *best = NULL;
    double *npos = NULL;
    int nn = 0, best_n = 0, best_closed = 0;
    double best_len = -1.0;
    size_t i, k;
    sfb_result r = SFB_SUCCESS;
    *out = NULL;
    *out_n = 0;
    *out_closed = 0;
    if (!keys || !node) { r = sfb__oom(ctx, "the spine's points"); goto done; }
    for (i = 0; i < np; ++i) {
        keys[i].x = (i & 1) ? segs[i / 2].b[0] : segs[i / 2].a[0];
        keys[i].id = (int)i;
        node[i] = -1;
    }
    qsort(keys, np, sizeof *keys, fil_key_cmp);
    npos = (double *)sfb__alloc(ctx, (np + 1) * 3 * sizeof(double));
    if (!npos) { r = sfb__oom(ctx, "the spine's points"); goto done; }
    for (i = 0; i < np; ++i) {
        const int id = keys[i].id;
        const double *p = (id & 1) ? segs[id / 2].b : segs[id / 2].a;
        if (node[id] >= 0) continue;
        node[id] = nn;
        memcpy(npos + 3 * (size_t)nn, p, 3 * sizeof(double));
        for (k = i + 1; k < np && keys[k].x - keys[i].x <= tol; ++k) {
            const int jd = keys[k].id;
            const double *q = (jd & 1) ? segs[jd / 2].b : segs[jd / 2].a;
            if (node[jd] < 0 && fil_dist(p, q) <= tol) node[jd] = nn;
        }
        nn++;
    }
    /* edges between distinct nodes, each once; adjacency lists (compressed) */
    {
        int *eu = (int *)sfb__alloc(ctx, (ns + 1) * 2 * sizeof(int)), ne = 0, *off = NULL, *inc = NULL, *fill = NULL;
        unsigned char *eused = NULL;
        int s, e;
        deg = (int *)sfb__calloc(ctx, (size_t)nn + 1, sizeof(int));
        path = (int *)sfb__alloc(ctx, ((size_t)ns + 2) * sizeof(int));
        best = (int *)sfb__alloc(ctx, ((size_t)ns + 2) * sizeof(int));
        off = (int *)sfb__calloc(ctx, (size_t)nn + 2, sizeof(int));
        if (!eu || !deg || !path || !best || !off) { sfb__free(ctx, eu); sfb__free(ctx, off); r = sfb__oom(ctx, "the spine's chains"); goto done; }
        for (i = 0; i < ns; ++i) {
            const int a = node[2 * i], b = node[2 * i + 1];
            if (a == b) continue;
            eu[2 * ne] = a < b ? a : b;
            eu[2 * ne + 1] = a < b ? b : a;
            ne++;
        }
        /* the same piece found from two triangle pairs: drop duplicates (sort by key) */
        {
            sfb__fil_key *ek = (sfb__fil_key *)sfb__alloc(ctx, ((size_t)ne + 1) * sizeof *ek);
            int *keep = (int *)sfb__alloc(ctx, ((size_t)ne + 1) * 2 * sizeof(int)), nk = 0;
            if (!ek || !keep) { sfb__free(ctx, ek); sfb__free(ctx, keep); sfb__free(ctx, eu); sfb__free(ctx, off); r = sfb__oom(ctx, "the spine's chains"); goto done; }
            for (e = 0; e < ne; ++e) { ek[e].x = (double)eu[2 * e] * ((double)nn + 1.0) + eu[2 * e + 1]; ek[e].id = e; }
            qsort(ek, (size_t)ne, sizeof *ek, fil_key_cmp);
            for (e = 0; e < ne; ++e)
                if (e == 0 || ek[e].x != ek[e - 1].x) { keep[2 * nk] = eu[2 * ek[e].id]; keep[2 * nk + 1] = eu[2 * ek[e].id + 1]; nk++; }
            memcpy(eu, keep, (size_t)nk * 2 * sizeof(int));
            ne = nk;
            sfb__free(ctx, ek);
            sfb__free(ctx, keep);
        }
        for (e = 0; e < ne; ++e) { off[eu[2 * e] + 1]++; off[eu[2 * e + 1] + 1]++; }
        for (s = 0; s < nn; ++s) { deg[s] = off[s + 1]; off[s + 1] += off[s]; }
        inc = (int *)sfb__alloc(ctx, ((size_t)2 * ne + 1) * sizeof(int));
        fill = (int *)sfb__calloc(ctx, (size_t)nn + 1, sizeof(int));
        eused = (unsigned char *)sfb__calloc(ctx, (size_t)ne + 1, 1);
        if (!inc || !fill || !eused) {
            sfb__free(ctx, eu); sfb__free(ctx, off); sfb__free(ctx, inc); sfb__free(ctx, fill); sfb__free(ctx, eused);
            r = sfb__oom(ctx, "the spine's chains");
            goto done;
        }
        for (e = 0; e < ne; ++e) {
            inc[off[eu[2 * e]] + fill[eu[2 * e]]++] = e;
            inc[off[eu[2 * e + 1]] + fill[eu[2 * e + 1]]++] = e;
        }
        /* walks: from ends (odd degree) first, then whatever is left; at a node of degree > 2 (two
         * pieces crossing: a spine that intersects itself, seed 4.3) the walk goes on along the
         * straightest unused edge, so a self-crossing spine stays one curve for the loop removal */
        for (k = 0; k < 2; ++k)
            for (s = 0; s < nn; ++s) {
                int n = 0, cur = s, closed = 0;
                double len = 0.0;
                if (k == 0 && !(deg[s] & 1)) continue;
                for (;;) {
                    int j2, pick = -1, nx;
                    double bestd = -HUGE_VAL;
                    path[n++] = cur;
                    if (n > (int)ns + 1) break;
                    for (j2 = off[cur]; j2 < off[cur + 1]; ++j2) {
                        const int ed = inc[j2];
                        double dir[3], din[3], ld, li, dd;
                        if (eused[ed]) continue;
                        nx = eu[2 * ed] == cur ? eu[2 * ed + 1] : eu[2 * ed];
                        if (n < 2) { pick = ed; break; }
                        fil_sub(npos + 3 * (size_t)nx, npos + 3 * (size_t)cur, dir);
                        fil_sub(npos + 3 * (size_t)cur, npos + 3 * (size_t)path[n - 2], din);
                        ld = fil_len(dir); li = fil_len(din);
                        dd = (ld > 0 && li > 0) ? fil_dot(dir, din) / (ld * li) : -1.0;
                        if (dd > bestd) { bestd = dd; pick = ed; }
                    }
                    if (pick < 0) break;
                    eused[pick] = 1;
                    nx = eu[2 * pick] == cur ? eu[2 * pick + 1] : eu[2 * pick];
                    len += fil_dist(npos + 3 * (size_t)cur, npos + 3 * (size_t)nx);
                    cur = nx;
                    if (cur == s) {
                        /* back at the start: closed unless the start has more to walk (then go on) */
                        int more = 0;
                        for (j2 = off[cur]; j2 < off[cur + 1]; ++j2) more |= !eused[inc[j2]];
                        if (!more) { closed = 1; break; }
                    }
                }
                if (n < 2) continue;
                {
                    const int match = closed == want_closed, best_match = best_closed == want_closed;
                    if (best_n == 0 || (match && !best_match) || (match == best_match && len > best_len)) {
                        memcpy(best, path, (size_t)n * sizeof(int));
                        best_n = n;
                        best_len = len;
                        best_closed = closed;
                    }
                }
            }
        sfb__free(ctx, eu); sfb__free(ctx, off); sfb__free(ctx, inc); sfb__free(ctx, fill); sfb__free(ctx, eused);
    }
    if (best_n >= 2) {
        double *o = (double *)sfb__alloc(ctx, (size_t)best_n * 3 * sizeof(double));
        if (!o) { r = sfb__oom(ctx, "the spine"); goto done; }
        for (i = 0; i < (size_t)best_n; ++i) memcpy(o + 3 * i, npos + 3 * (size_t)best[i], 3 * sizeof(double));
        *out = o;
        *out_n = best_n;
        *out_closed = best_closed;
    }
done:
    sfb__free(ctx, keys); sfb__free(ctx, node); sfb__free(ctx, deg); sfb__free(ctx, path); sfb__free(ctx, best); sfb__free(ctx, npos);
    return r;
}

/* Nearest point to p on polyline pts (n points; closed: the last joins the first): the segment i
 * (from point i to i+1 mod n), its parameter and the squared distance. */
static void fil_polyline_nearest(const double *pts, int n, int closed, const double *p, int *seg, double *t, double *d2) {
    const int segs = closed ? n : n - 1;
    int i;
    *seg = 0; *t = 0.0; *d2 = HUGE_VAL;
    for (i = 0; i < segs; ++i) {
        const double *a = pts + 3 * (size_t)i, *b = pts + 3 * (size_t)((i + 1) % n);
        const double s = fil_seg_param(p, a, b);
        double q[3], dd;
        fil_lerp(a, b, s, q);
        dd = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) + (q[2] - p[2]) * (q[2] - p[2]);
        if (dd < *d2) { *d2 = dd; *seg = i; *t = s; }
    }
}

/* The Hermite segment that reconnects a spine's regressive points (seed 4.3): from A with the
 * direction ta to B with tb, both tangents scaled to the chord; writes its 7 inner points (8
 * pieces) to out and returns 7. */
static int fil_hermite_bridge(const double *A, const double *ta_dir, const double *B, const double *tb_dir, double *out) {
    const int m = 8;
    const double L = fil_dist(A, B), la = fil_len(ta_dir), lb = fil_len(tb_dir);
    double ta[3], tb[3];
    int k, c;
    for (c = 0; c < 3; ++c) { ta[c] = ta_dir[c] * (la > 0 ? L / la : 0); tb[c] = tb_dir[c] * (lb > 0 ? L / lb : 0); }
    for (k = 1; k < m; ++k) {
        const double s = (double)k / m, h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s, h01 = -2 * s * s * s + 3 * s * s,
                     h11 = s * s * s - s * s;
        for (c = 0; c < 3; ++c) out[3 * (size_t)(k - 1) + c] = h00 * A[c] + h10 * ta[c] + h01 * B[c] + h11 * tb[c];
    }
    return m - 1;
}

/* Spine self-intersections (seed 4.3): two spine pieces closer than tol, apart along the spine by
 * more than `gap`, close a loop; the loop (the shorter way round for a closed spine, the part
 * between them for an open one) is cut out and its ends Q1, Q2 -- the points `gap` before and
 * after it -- are joined by a cubic Hermite segment with the spine's tangents there. Then
 * non-shrinking Taubin smoothing (lambda 0.5, mu -0.53) of the whole spine. Returns the loops cut. */
static int fil_spine_untangle(sfb_context *ctx, double **pts_io, int *n_io, int closed, double tol, double gap) {
    int n = *n_io, cuts = 0, guard;
    double *pts = *pts_io;
    for (guard = 0; guard < 16; ++guard) {
        double *acc;
        int found = 0;
        int i, j, bi = -1, bj = -1;
        /* arc length positions */
        acc = (double *)sfb__alloc(ctx, ((size_t)n + 1) * sizeof(double));
        if (!acc) break;
        acc[0] = 0.0;
        for (i = 1; i < n; ++i) acc[i] = acc[i - 1] + fil_dist(pts + 3 * (size_t)(i - 1), pts + 3 * (size_t)i);
        acc[n] = acc[n - 1] + (closed ? fil_dist(pts + 3 * (size_t)(n - 1), pts) : 0.0);
        for (i = 0; i < n && !found; ++i)
            for (j = i + 2; j < n; ++j) {
                double along = acc[j] - acc[i];
                if (closed && acc[n] - along < along) along = acc[n] - along;
                if (along <= 2.0 * gap) continue;
                if (fil_dist(pts + 3 * (size_t)i, pts + 3 * (size_t)j) < tol) { bi = i; bj = j; found = 1; break; }
            }
        if (!found) { sfb__free(ctx, acc); break; }
        {
            /* the loop is i..j (inner), or for a closed spine the shorter of i..j and j..i */
            int keep_inner = 0, q1, q2, k, o = 0;
            double *np_;
            if (closed && (acc[bj] - acc[bi]) > acc[n] / 2) keep_inner = 1; /* the outer part is the loop */
            if (keep_inner) {
                /* keep bi..bj, drop the wrap-around part */
                q1 = bi; q2 = bj;
                while (q1 < bj && acc[q1] - acc[bi] < gap) q1++;
                while (q2 > q1 && acc[bj] - acc[q2] < gap) q2--;
                np_ = (double *)sfb__alloc(ctx, ((size_t)(q2 - q1 + 1) + 16) * 3 * sizeof(double));
                if (!np_) { sfb__free(ctx, acc); break; }
                for (k = q1; k <= q2; ++k) memcpy(np_ + 3 * (size_t)o++, pts + 3 * (size_t)k, 3 * sizeof(double));
                /* Hermite from q2 back to q1 across the cut */
                {
                    double ta[3], tb[3];
                    fil_sub(pts + 3 * (size_t)q2, pts + 3 * (size_t)(q2 - 1), ta);
                    fil_sub(pts + 3 * (size_t)(q1 + 1), pts + 3 * (size_t)q1, tb);
                    o += fil_hermite_bridge(pts + 3 * (size_t)q2, ta, pts + 3 * (size_t)q1, tb, np_ + 3 * (size_t)o);
                }
            } else {
                q1 = bi; q2 = bj;
                while (q1 > 0 && acc[bi] - acc[q1] < gap) q1--;
                while (q2 < n - 1 && acc[q2] - acc[bj] < gap) q2++;
                np_ = (double *)sfb__alloc(ctx, ((size_t)n + 16) * 3 * sizeof(double));
                if (!np_) { sfb__free(ctx, acc); break; }
                for (k = 0; k <= q1; ++k) memcpy(np_ + 3 * (size_t)o++, pts + 3 * (size_t)k, 3 * sizeof(double));
                {
                    double ta[3], tb[3];
                    fil_sub(pts + 3 * (size_t)q1, pts + 3 * (size_t)(q1 > 0 ? q1 - 1 : q1), ta);
                    if (q1 == 0) fil_sub(pts + 3 * (size_t)1, pts, ta);
                    fil_sub(pts + 3 * (size_t)(q2 + 1 < n ? q2 + 1 : q2), pts + 3 * (size_t)q2, tb);
                    if (q2 + 1 >= n) fil_sub(pts + 3 * (size_t)q2, pts + 3 * (size_t)(q2 - 1), tb);
                    o += fil_hermite_bridge(pts + 3 * (size_t)q1, ta, pts + 3 * (size_t)q2, tb, np_ + 3 * (size_t)o);
                }
                for (k = q2; k < n; ++k) memcpy(np_ + 3 * (size_t)o++, pts + 3 * (size_t)k, 3 * sizeof(double));
            }
            sfb__free(ctx, pts);
            pts = np_;
            n = o;
        }
        sfb__free(ctx, acc);
        cuts++;
    }
    if (cuts) {
        /* Taubin lambda|mu smoothing, ends of an open spine fixed */
        double *tmp = (double *)sfb__alloc(ctx, (size_t)n * 3 * sizeof(double));
        int it, i, c;
        if (tmp)
            for (it = 0; it < 20; ++it) {
                const double f = (it & 1) ? -0.53 : 0.5;
                memcpy(tmp, pts, (size_t)n * 3 * sizeof(double));
                for (i = 0; i < n; ++i) {
                    int a = i - 1, b = i + 1;
                    if (!closed && (i == 0 || i == n - 1)) continue;
                    if (a < 0) a = n - 1;
                    if (b >= n) b = 0;
                    for (c = 0; c < 3; ++c)
                        pts[3 * (size_t)i + c] = tmp[3 * (size_t)i + c] + f * (0.5 * (tmp[3 * (size_t)a + c] + tmp[3 * (size_t)b + c]) - tmp[3 * (size_t)i + c]);
                }
            }
        sfb__free(ctx, tmp);
    }
    *pts_io = pts;
    *n_io = n;
    return cuts;
}

/* ---- profiles (seed 4.2) ---- */
/* A profile from spine point C and linkage points P1 (u = 0), P2 (u = 1): P0 is the end tangents'
 * intersection, P0 = C + (a + b) / (1 + cos phi) with a = P1 - C, b = P2 - C (seed eq. 2), phi the
 * central angle; the arc is the rational quadratic (P1, P0, P2) with middle weight cos(phi / 2)
 * (ALGORITHMS.md 6: the central angle, not the angle at P0). */
static void fil_prof_eval(const sfb__fil_prof *P, int kind, double hs, double u, double *o) {
    int c;
    if (kind == SFB_FILLET_SHARPEN) {
        const double l1 = fil_dist(P->P1, P->P0), l2 = fil_dist(P->P0, P->P2), s = u * (l1 + l2);
        if (s <= l1 && l1 > 0.0) fil_lerp(P->P1, P->P0, s / l1, o);
        else if (l2 > 0.0) fil_lerp(P->P0, P->P2, (s - l1) / l2, o);
        else memcpy(o, P->P2, 3 * sizeof(double));
        return;
    }
    if (kind == SFB_FILLET_HERMITE) {
        double t1[3], t2[3], l1, l2, chord = fil_dist(P->P1, P->P2), len;
        const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u, h01 = -2 * u * u * u + 3 * u * u,
                     h11 = u * u * u - u * u;
        double phi;
        fil_sub(P->P0, P->P1, t1);
        fil_sub(P->P2, P->P0, t2);
        l1 = fil_len(t1);
        l2 = fil_len(t2);
        {
            double a[3], b[3], cphi;
            fil_sub(P->P1, P->C, a);
            fil_sub(P->P2, P->C, b);
            cphi = fil_dot(a, b) / (fil_len(a) * fil_len(b) + 1e-300);
            phi = acos(cphi > 1 ? 1 : cphi < -1 ? -1 : cphi);
        }
        /* the arc's own: a cubic Bezier arm of 4/3 tan(phi/4) r is a Hermite tangent of 4 tan(phi/4) r */
        len = hs > 0.0 ? hs * chord : 4.0 * tan(phi / 4.0) * P->r;
        for (c = 0; c < 3; ++c) {
            const double a = l1 > 0 ? t1[c] / l1 * len : 0.0, b = l2 > 0 ? t2[c] / l2 * len : 0.0;
            o[c] = h00 * P->P1[c] + h10 * a + h01 * P->P2[c] + h11 * b;
        }
        return;
    }
    {
        const double b0 = (1 - u) * (1 - u), b1 = 2 * u * (1 - u) * P->w, b2 = u * u, den = b0 + b1 + b2;
        for (c = 0; c < 3; ++c) o[c] = (b0 * P->P1[c] + b1 * P->P0[c] + b2 * P->P2[c]) / den;
    }
}

static void fil_prof_build(sfb__fil_prof *P, const double *C, const double *P1, const double *P2, const double *E, int kind,
                           double conic_w, double hs) {
    double a[3], b[3], la, lb, cphi;
    int k;
    memcpy(P->C, C, sizeof P->C);
    memcpy(P->P1, P1, sizeof P->P1);
    memcpy(P->P2, P2, sizeof P->P2);
    memcpy(P->E, E, sizeof P->E);
    fil_sub(P1, C, a);
    fil_sub(P2, C, b);
    la = fil_len(a);
    lb = fil_len(b);
    P->r = 0.5 * (la + lb);
    cphi = (la > 0 && lb > 0) ? fil_dot(a, b) / (la * lb) : 1.0;
    cphi = cphi > 1 ? 1 : cphi < -1 ? -1 : cphi;
    if (1.0 + cphi > 1e-9) {
        for (k = 0; k < 3; ++k) P->P0[k] = C[k] + (a[k] + b[k]) / (1.0 + cphi);
        P->w = sqrt(0.5 * (1.0 + cphi)); /* cos(phi / 2) */
    } else { /* half a turn: no corner to round; a straight profile */
        fil_lerp(P1, P2, 0.5, P->P0);
        P->w = 1.0;
    }
    if (kind == SFB_FILLET_CONIC && conic_w > 0.0) P->w = conic_w;
    P->L1 = fil_dist(P1, E);
    P->L2 = fil_dist(P2, E);
    P->acc[0] = 0.0;
    for (k = 0; k <= SFB__FIL_TAB; ++k) {
        fil_prof_eval(P, kind, hs, (double)k / SFB__FIL_TAB, P->T[k]);
        if (k) P->acc[k] = P->acc[k - 1] + fil_dist(P->T[k - 1], P->T[k]);
    }
    if (P->acc[SFB__FIL_TAB] > 0.0)
        for (k = 1; k <= SFB__FIL_TAB; ++k) P->acc[k] /= P->acc[SFB__FIL_TAB];
}

/* The profile's point at arc-length fraction a in [0,1]. The table only finds the parameter: the
 * point is evaluated on the curve itself, so it lies on the exact arc or conic. */
static void fil_prof_at(const sfb__fil_prof *P, int kind, double hs, double a, double *o) {
    int lo = 0, hi = SFB__FIL_TAB;
    double u, span;
    if (kind == SFB_FILLET_SHARPEN) { fil_prof_eval(P, kind, hs, a, o); return; }
    a = a < 0 ? 0 : a > 1 ? 1 : a;
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (P->acc[mid] <= a) lo = mid; else hi = mid;
    }
    span = P->acc[hi] - P->acc[lo];
    u = (lo + (span > 0 ? (a - P->acc[lo]) / span : 0.0)) / SFB__FIL_TAB;
    fil_prof_eval(P, kind, hs, u, o);
}

/* Distance from q to profile P's curve (its table, refined around the nearest piece). */
static double fil_prof_distance(const sfb__fil_prof *P, int kind, double hs, const double *q) {
    double best = HUGE_VAL;
    int k, bk = 0;
    if (kind == SFB_FILLET_ARC) return fabs(fil_dist(q, P->C) - P->r);
    for (k = 0; k < SFB__FIL_TAB; ++k) {
        const double t = fil_seg_param(q, P->T[k], P->T[k + 1]);
        double x[3], d;
        fil_lerp(P->T[k], P->T[k + 1], t, x);
        d = fil_dist(x, q);
        if (d < best) { best = d; bk = k; }
    }
    if (kind != SFB_FILLET_SHARPEN) { /* a finer look on the nearest two pieces */
        const double u0 = (bk > 0 ? bk - 1 : 0) / (double)SFB__FIL_TAB, u1 = (bk + 2 < SFB__FIL_TAB ? bk + 2 : SFB__FIL_TAB) / (double)SFB__FIL_TAB;
        double prev[3], cur[3];
        fil_prof_eval(P, kind, hs, u0, prev);
        for (k = 1; k <= 64; ++k) {
            double t, x[3], d;
            fil_prof_eval(P, kind, hs, u0 + (u1 - u0) * k / 64.0, cur);
            t = fil_seg_param(q, prev, cur);
            fil_lerp(prev, cur, t, x);
            d = fil_dist(x, q);
            if (d < best) best = d;
            memcpy(prev, cur, sizeof cur);
        }
    }
    return best;
}

/* ---- spine sampling (seed 4.1) ---- */
static void fil_point_at(const double *pts, const double *cum, int n, int closed, double s, double *o) {
    const int segs = closed ? n : n - 1;
    int lo = 0, hi = segs;
    double len;
    if (s <= 0) { memcpy(o, pts, 3 * sizeof(double)); return; }
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (cum[mid] <= s) lo = mid; else hi = mid;
    }
    len = cum[lo + 1] - cum[lo];
    fil_lerp(pts + 3 * (size_t)lo, pts + 3 * (size_t)((lo + 1) % n), len > 0 ? (s - cum[lo]) / len : 0.0, o);
}

/* Chord height of the spine between arc lengths s0 < s1 over the chord's length. */
static double fil_chord_ratio(const double *pts, const double *cum, int n, int closed, double s0, double s1) {
    double a[3], b[3], ab[3], l, h = 0.0;
    int i;
    fil_point_at(pts, cum, n, closed, s0, a);
    fil_point_at(pts, cum, n, closed, s1, b);
    fil_sub(b, a, ab);
    l = fil_len(ab);
    if (!(l > 0)) return 0.0;
    for (i = 0; i < (closed ? n : n - 1); ++i)
        if (cum[i] > s0 && cum[i] < s1) {
            const double t = fil_seg_param(pts + 3 * (size_t)i, a, b);
            double x[3];
            fil_lerp(a, b, t, x);
            if (fil_dist(x, pts + 3 * (size_t)i) > h) h = fil_dist(x, pts + 3 * (size_t)i);
        }
    return h / l;
}

typedef struct sfb__fil_samples {
    sfb_context *ctx;
    const double *pts, *cum;
    int n, closed;
    double ratio, min_len;
    double *s;
    int cnt, cap, failed;
} sfb__fil_samples;

static void fil_sample_push(sfb__fil_samples *S, double v) {
    if (S->failed) return;
    if (S->cnt == S->cap) {
        const int cap = S->cap ? 2 * S->cap : 128;
        double *ns = (double *)sfb__realloc(S->ctx, S->s, (size_t)cap * sizeof(double));
        if (!ns) { S->failed = 1; return; }
        S->s = ns;
        S->cap = cap;
    }
    S->s[S->cnt++] = v;
}

/* Halves [a, b] while its chord ratio exceeds the threshold (at most 12 times), pushing the
 * inner sample arc lengths in order. */
static void fil_sample_refine(sfb__fil_samples *S, double a, double b, int depth) {
    double m;
    if (depth >= 12 || b - a <= S->min_len || fil_chord_ratio(S->pts, S->cum, S->n, S->closed, a, b) <= S->ratio) return;
    m = 0.5 * (a + b);
    fil_sample_refine(S, a, m, depth + 1);
    fil_sample_push(S, m);
    fil_sample_refine(S, m, b, depth + 1);
}

/* Sample arc lengths: `want` by arc length, then intervals halved while their chord height over
 * chord length exceeds `ratio`. Closed spines: samples in [0, L), the last joins the first. */
static sfb_result fil_sample(sfb_context *ctx, const double *pts, const double *cum, int n, int closed, int want, double ratio,
                             double **out, int *out_n) {
    const double L = cum[closed ? n : n - 1];
    const int intervals = closed ? want : want - 1;
    sfb__fil_samples S;
    int k;
    memset(&S, 0, sizeof S);
    S.ctx = ctx; S.pts = pts; S.cum = cum; S.n = n; S.closed = closed; S.ratio = ratio;
    S.min_len = L * 1e-6;
    for (k = 0; k < intervals; ++k) {
        const double a = L * k / intervals, b = L * (k + 1) / intervals;
        fil_sample_push(&S, a);
        fil_sample_refine(&S, a, b, 0);
    }
    if (!closed) fil_sample_push(&S, L);
    if (S.failed) {
        sfb__free(ctx, S.s);
        return sfb__oom(ctx, "the spine samples");
    }
    *out = S.s;
    *out_n = S.cnt;
    return SFB_SUCCESS;
}

/* ---- one curve: base patches, offsets, spine, samples, profiles, projection ---- */
typedef struct sfb__fil_work {
    int *fside;         /* nf: -1, or the side (0, 1) of a base-patch face */
    double *vd;         /* nv: distance to the curve (-1: not computed) */
    int *vdlist;        /* the vertices whose vd was computed */
    int nvd;
    int *queue;         /* nf */
    double *nrm[2];     /* nv x 3 per side: vertex normals of that side's faces */
    double *op[2];      /* nv x 3 per side: offset positions */
    int *rows[2];       /* per side: the base-patch triangles (3 vertex indices each) */
    int nrows[2];
    unsigned char *vin; /* nv: bit 1 side 0, bit 2 side 1, bit 4 on the curve */
    int *vlist;         /* the vertices with vin != 0 */
    int nvlist;
    double *ta;         /* nv x 2: a blend-region vertex's (t, a) on the sweep (vin bit 8) */
} sfb__fil_work;

static sfb_result fil_stage(sfb__fil *F, int ci, int stage, const char *name) {
    return sfb__progress(F->ctx, (float)((ci + stage / 5.0) / (F->ncurves > 0 ? F->ncurves : 1)), name);
}

/* A polyline with an AABB tree over its segments (each a degenerate triangle i, i+1, i+1, whose
 * nearest point aabb.c finds on the segment): nearest-point queries in log time. Short polylines
 * (fewer than 32 segments) are searched linearly. The nearest segment of two at equal distance
 * may differ from fil_polyline_nearest's choice; the point and distance do not. */
typedef struct sfb__fil_poly {
    const double *pts;
    int n, closed;
    int *tri;
    sfb__aabb tree;
} sfb__fil_poly;
static sfb_result fil_poly_build(sfb_context *ctx, sfb__fil_poly *P, const double *pts, int n, int closed) {
    const int segs = closed ? n : n - 1;
    int i;
    memset(P, 0, sizeof *P);
    P->pts = pts;
    P->n = n;
    P->closed = closed;
    if (segs < 32) return SFB_SUCCESS;
    P->tri = (int *)sfb__alloc(ctx, (size_t)segs * 3 * sizeof(int));
    if (!P->tri) return sfb__oom(ctx, "a polyline's segment tree");
    for (i = 0; i < segs; ++i) {
        P->tri[3 * i] = i;
        P->tri[3 * i + 1] = P->tri[3 * i + 2] = (i + 1) % n;
    }
    return sfb__aabb_build(ctx, pts, P->tri, NULL, segs, &P->tree);
}
static void fil_poly_free(sfb_context *ctx, sfb__fil_poly *P) {
    sfb__aabb_free(ctx, &P->tree);
    sfb__free(ctx, P->tri);
    P->tri = NULL;
}
static void fil_poly_nearest(const sfb__fil_poly *P, const double *p, int *seg, double *t, double *d2) {
    double bary[3];
    int id;
    if (!P->tri || P->tree.node_count == 0 ||
        (id = sfb__aabb_nearest(&P->tree, P->pts, P->tri, NULL, p, NULL, d2, bary)) < 0) {
        fil_polyline_nearest(P->pts, P->n, P->closed, p, seg, t, d2);
        return;
    }
    *seg = id;
    *t = 1.0 - bary[0];
    *t = *t < 0.0 ? 0.0 : *t > 1.0 ? 1.0 : *t;
}


/* ---- the conformal map (seed 5), on the direct map's boundary ----
 * The seed splits the cylinder-like region along a shortest path and maps it onto a rectangle with
 * its boundary fixed there (so the region's boundary vertices are pulled onto the linkage curves).
 * Here the region's boundary vertices (blend vertices with a neighbour outside) keep the direct
 * map's (t, a) -- they stay where they are on the sweep -- and the inside solves the cotangent
 * Laplace equation for t and a (the discrete conformal map: angle preserving, the seed's "inner
 * fairness" in one step) by preconditioned conjugate gradients. A closed spine's t is periodic:
 * instead of cutting the region, every edge carries the jump (0 or +-T) the direct map's values
 * show across it, so the equations are those of the split region, with no vertex copied; holes and
 * several boundary loops are just more boundary (seed 7's failure does not arise). When the
 * cotangent map folds a triangle (negative weights on obtuse triangles) or does not solve, the
 * symmetrised mean-value weights (positive: no fold with a convex boundary) are tried, then the
 * direct map is kept. *used gets 1 (conformal), 2 (mean value) or 0 (direct). */
static double fil_corner_angle(const double *p, const double *a, const double *b) {
    double u[3], v[3], c, lu, lv;
    fil_sub(a, p, u);
    fil_sub(b, p, v);
    lu = fil_len(u);
    lv = fil_len(v);
    if (!(lu > 0 && lv > 0)) return 0.0;
    c = fil_dot(u, v) / (lu * lv);
    return acos(c > 1 ? 1 : c < -1 ? -1 : c);
}

static sfb_result fil_harmonic(sfb__fil *F, sfb__fil_work *W, double T, int periodic, int *used) {
    sfb_context *ctx = F->ctx;
    const sfb__level *l = F->l;
    int *mv = NULL, *inner = NULL, *rowi = NULL, *coli = NULL, *full = NULL;
    double *val = NULL, *x = NULL, *b = NULL, *sol = NULL;
    int n = 0, ni = 0, nfull = 0, i, k, pass, f;
    size_t cap, nt;
    sfb_result res = SFB_SUCCESS;
    sfb__error_state kept;
    *used = 0;
    mv = (int *)sfb__alloc(ctx, ((size_t)W->nvlist + 1) * sizeof(int));
    if (!mv) { res = sfb__oom(ctx, "the conformal map"); goto done; }
    /* local ids: blend vertices; inner ones (every face around them all blend) are the unknowns */
    for (i = 0; i < W->nvlist; ++i)
        if (W->vin[W->vlist[i]] & 8) mv[n++] = W->vlist[i];
    if (n == 0) goto done;
    inner = (int *)sfb__alloc(ctx, (size_t)n * sizeof(int));
    full = (int *)sfb__alloc(ctx, ((size_t)l->nf + 1) * sizeof(int));
    if (!inner || !full) { res = sfb__oom(ctx, "the conformal map"); goto done; }
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        int ok = 1, j;
        for (j = l->vf_off[v]; j < l->vf_off[v + 1] && ok; ++j) {
            const int g = l->vf[j];
            for (k = 0; k < 3; ++k) ok &= (W->vin[F->tri[3 * g + k]] & 8) != 0;
        }
        if (l->vf_off[v + 1] == l->vf_off[v]) ok = 0;
        /* a boundary vertex of the mesh itself stays where the direct map puts it */
        for (j = l->ve_off[v]; j < l->ve_off[v + 1] && ok; ++j) ok &= l->ef_off[l->ve[j] + 1] - l->ef_off[l->ve[j]] == 2;
        inner[i] = ok ? ni++ : -1;
    }
    if (ni == 0) goto done;
    /* the faces with three blend vertices (each once: found from its smallest local vertex) */
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        int j;
        for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j) {
            const int g = l->vf[j];
            int all = 1, lowest = 1;
            for (k = 0; k < 3; ++k) {
                const int u = F->tri[3 * g + k];
                all &= (W->vin[u] & 8) != 0;
                if (u < v) lowest = 0;
            }
            if (all && lowest) full[nfull++] = g;
        }
    }
    cap = (size_t)nfull * 12 + 16;
    rowi = (int *)sfb__alloc(ctx, cap * sizeof(int));
    coli = (int *)sfb__alloc(ctx, cap * sizeof(int));
    val = (double *)sfb__alloc(ctx, cap * sizeof(double));
    x = (double *)sfb__alloc(ctx, (size_t)ni * 2 * sizeof(double));
    b = (double *)sfb__alloc(ctx, (size_t)ni * 2 * sizeof(double));
    sol = (double *)sfb__alloc(ctx, (size_t)n * 2 * sizeof(double));
    if (!rowi || !coli || !val || !x || !b || !sol) { res = sfb__oom(ctx, "the conformal map"); goto done; }
    /* a blend vertex's local index, kept in vd (the base patches are found: vd is free now; reset below) */
    for (i = 0; i < n; ++i) W->vd[mv[i]] = (double)i;
    for (pass = 1; pass <= 2 && *used == 0; ++pass) {
        sfb__sparse A;
        int fold = 0, comp, it;
        double resid, orient = 0.0;
        memset(&A, 0, sizeof A);
        nt = 0;
        for (i = 0; i < 2 * ni; ++i) b[i] = 0.0;
        /* edge weights per face corner, symmetric */
        for (k = 0; k < nfull; ++k) {
            const int g = full[k];
            int c;
            for (c = 0; c < 3; ++c) {
                const int vi = F->tri[3 * g + c], vj = F->tri[3 * g + (c + 1) % 3], vk = F->tri[3 * g + (c + 2) % 3];
                const double *pi = F->pos + 3 * (size_t)vi, *pj = F->pos + 3 * (size_t)vj, *pk = F->pos + 3 * (size_t)vk;
                const int li = (int)W->vd[vi], lj = (int)W->vd[vj];
                double w;
                if (pass == 1) { /* cot of the angle at k, for edge i-j */
                    const double ang = fil_corner_angle(pk, pi, pj), sn = sin(ang);
                    w = sn > 1e-12 ? 0.5 * cos(ang) / sn : 0.0;
                } else { /* mean value: tan(half the angle at i) / |ij| + tan(half the angle at j) / |ij|, halved */
                    const double ai = fil_corner_angle(pi, pj, pk), aj = fil_corner_angle(pj, pk, pi), len = fil_dist(pi, pj);
                    w = len > 0 ? 0.5 * (tan(0.5 * ai) + tan(0.5 * aj)) / len : 0.0;
                }
                /* row of each inner endpoint: diagonal +w, the other -w (inner) or into b (boundary) */
                for (comp = 0; comp < 2; ++comp) {
                    const int a_ = comp ? lj : li, o_ = comp ? li : lj, ia = inner[a_], io = inner[o_];
                    const int va = mv[a_], vo = mv[o_];
                    double jump;
                    if (ia < 0) continue;
                    /* t_o as seen from a: t_o + jump, the jump making the difference smallest */
                    jump = 0.0;
                    if (periodic && T > 0) {
                        const double dd = W->ta[2 * (size_t)vo] - W->ta[2 * (size_t)va];
                        jump = dd > 0.5 * T ? -T : dd < -0.5 * T ? T : 0.0;
                    }
                    rowi[nt] = ia; coli[nt] = ia; val[nt] = w; nt++;
                    if (io >= 0) { rowi[nt] = ia; coli[nt] = io; val[nt] = -w; nt++; }
                    else {
                        b[2 * (size_t)ia] += w * W->ta[2 * (size_t)vo];
                        b[2 * (size_t)ia + 1] += w * W->ta[2 * (size_t)vo + 1];
                    }
                    b[2 * (size_t)ia] += w * jump;
                }
            }
        }
        res = sfb__sparse_from_triplets(ctx, ni, (int)nt, rowi, coli, val, &A);
        if (res != SFB_SUCCESS) goto done;
        for (comp = 0; comp < 2 && !fold; ++comp) {
            double *bb = (double *)sfb__alloc(ctx, (size_t)ni * sizeof(double)), *xx = (double *)sfb__alloc(ctx, (size_t)ni * sizeof(double));
            sfb_result cr;
            if (!bb || !xx) { sfb__free(ctx, bb); sfb__free(ctx, xx); sfb__sparse_free(ctx, &A); res = sfb__oom(ctx, "the conformal map"); goto done; }
            for (i = 0; i < n; ++i)
                if (inner[i] >= 0) { bb[inner[i]] = b[2 * (size_t)inner[i] + comp]; xx[inner[i]] = W->ta[2 * (size_t)mv[i] + comp]; }
            sfb__error_keep(ctx, &kept);
            cr = sfb__sparse_cg(ctx, &A, bb, xx, 1e-10, 4 * ni + 200, &it, &resid);
            if (cr != SFB_SUCCESS) { /* not positive definite (cotangent weights) or no convergence: the next map */
                sfb__log(ctx, SFB_LOG_INFO, "fillet: the %s map's solve failed (%s); trying the next", pass == 1 ? "conformal" : "mean-value", ctx->error);
                sfb__error_put_back(ctx, &kept);
                fold = 1;
            }
            for (i = 0; i < ni; ++i) x[2 * (size_t)i + comp] = xx[i];
            sfb__free(ctx, bb);
            sfb__free(ctx, xx);
        }
        sfb__sparse_free(ctx, &A);
        if (fold) continue;
        /* the solution with the boundary's own values; folds: a face whose (t, a) orientation
         * disagrees with the direct map's prevailing one */
        for (i = 0; i < n; ++i) {
            const int q = inner[i];
            sol[2 * (size_t)i] = q >= 0 ? x[2 * (size_t)q] : W->ta[2 * (size_t)mv[i]];
            sol[2 * (size_t)i + 1] = q >= 0 ? x[2 * (size_t)q + 1] : W->ta[2 * (size_t)mv[i] + 1];
        }
        for (f = 0; f < 2 && !fold; ++f) /* f = 0: the direct map's orientation; f = 1: the solution's */
            for (k = 0; k < nfull; ++k) {
                const int g = full[k];
                double uv[3][2], ar;
                int c;
                for (c = 0; c < 3; ++c) {
                    const int li = (int)W->vd[F->tri[3 * g + c]];
                    uv[c][0] = f ? sol[2 * (size_t)li] : W->ta[2 * (size_t)mv[li]];
                    uv[c][1] = f ? sol[2 * (size_t)li + 1] : W->ta[2 * (size_t)mv[li] + 1];
                    if (periodic && T > 0 && c > 0) {
                        const double dd = uv[c][0] - uv[0][0];
                        uv[c][0] += dd > 0.5 * T ? -T : dd < -0.5 * T ? T : 0.0;
                    }
                }
                ar = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
                if (f == 0) orient += ar;
                else if (ar * orient <= 0.0) { fold = 1; break; }
            }
        if (fold) continue;
        for (i = 0; i < n; ++i) {
            W->ta[2 * (size_t)mv[i]] = sol[2 * (size_t)i];
            W->ta[2 * (size_t)mv[i] + 1] = sol[2 * (size_t)i + 1];
        }
        *used = pass;
    }
done:
    for (i = 0; i < n; ++i) W->vd[mv[i]] = -1.0;
    sfb__free(ctx, mv); sfb__free(ctx, inner); sfb__free(ctx, full);
    sfb__free(ctx, rowi); sfb__free(ctx, coli); sfb__free(ctx, val); sfb__free(ctx, x); sfb__free(ctx, b); sfb__free(ctx, sol);
    return res;
}

/* Seed 5.2's inner fairness, Laplacian optimisation in 2D (its Fig. 9): `iters` Jacobi steps
 * moving each inner region vertex's (t, a) to its neighbours' mean (uniform weights: they even
 * out the triangles' sizes, which the conformal map keeps from the input), the boundary fixed. A
 * closed spine's t is periodic: neighbours are unwrapped to the nearer copy. Kept only when no
 * region face turns over in (t, a); *done says whether it was kept.
 * Off by default (config.relax 0): measured on the box-cylinder seam (r 0.15), the smallest
 * angle of the moved triangles is 26.8 degrees after the conformal map alone and 16.7 / 12.7 /
 * 10.9 after 10 / 30 / 100 steps (the 1st percentile 27.7 -> 29.1 / 26.3 / 23.1, the median
 * unchanged): the conformal map, which keeps the input's angles, is already the fairer one here. */
static sfb_result fil_relax(sfb__fil *F, sfb__fil_work *W, double T, int periodic, int iters, int *done) {
    sfb_context *ctx = F->ctx;
    const sfb__level *l = F->l;
    int *mv = NULL, *inner = NULL, n = 0, i, j, k, it, ok = 1;
    double *cur = NULL, *nxt = NULL;
    signed char *orient = NULL;
    *done = 0;
    mv = (int *)sfb__alloc(ctx, ((size_t)W->nvlist + 1) * sizeof(int));
    if (!mv) return sfb__oom(ctx, "the 2D optimisation");
    for (i = 0; i < W->nvlist; ++i)
        if (W->vin[W->vlist[i]] & 8) mv[n++] = W->vlist[i];
    inner = (int *)sfb__alloc(ctx, ((size_t)n + 1) * sizeof(int));
    cur = (double *)sfb__alloc(ctx, ((size_t)n + 1) * 2 * sizeof(double));
    nxt = (double *)sfb__alloc(ctx, ((size_t)n + 1) * 2 * sizeof(double));
    orient = (signed char *)sfb__alloc(ctx, ((size_t)l->nf + 1));
    if (!inner || !cur || !nxt || !orient) { sfb__free(ctx, mv); sfb__free(ctx, inner); sfb__free(ctx, cur); sfb__free(ctx, nxt); sfb__free(ctx, orient); return sfb__oom(ctx, "the 2D optimisation"); }
    for (i = 0; i < n; ++i) W->vd[mv[i]] = -2.0 - i; /* local index -(vd + 2) while this runs (vd is reset below) */
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        int in_ = l->vf_off[v + 1] > l->vf_off[v];
        for (j = l->vf_off[v]; j < l->vf_off[v + 1] && in_; ++j)
            for (k = 0; k < 3; ++k) in_ &= (W->vin[F->tri[3 * l->vf[j] + k]] & 8) != 0;
        for (j = l->ve_off[v]; j < l->ve_off[v + 1] && in_; ++j) in_ &= l->ef_off[l->ve[j] + 1] - l->ef_off[l->ve[j]] == 2;
        inner[i] = in_ && !(W->vin[v] & 4) ? 1 : 0; /* the curve's own vertices stay: they carry the profile's middle */
        cur[2 * i] = W->ta[2 * (size_t)v];
        cur[2 * i + 1] = W->ta[2 * (size_t)v + 1];
    }
    /* every region face's orientation in (t, a) before */
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j) {
            const int f = l->vf[j];
            double uv[3][2], ar;
            int c, all = 1;
            for (c = 0; c < 3; ++c) all &= (W->vin[F->tri[3 * f + c]] & 8) != 0;
            if (!all) continue;
            for (c = 0; c < 3; ++c) {
                const int li = (int)(-W->vd[F->tri[3 * f + c]] - 2.0);
                uv[c][0] = cur[2 * li];
                uv[c][1] = cur[2 * li + 1];
                if (periodic && T > 0 && c > 0) uv[c][0] += uv[c][0] - uv[0][0] > 0.5 * T ? -T : uv[c][0] - uv[0][0] < -0.5 * T ? T : 0.0;
            }
            ar = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
            orient[f] = (signed char)(ar > 0 ? 1 : ar < 0 ? -1 : 0);
        }
    }
    for (it = 0; it < iters; ++it) {
        for (i = 0; i < n; ++i) {
            const int v = mv[i];
            double st = 0.0, sa = 0.0;
            int cnt = 0;
            nxt[2 * i] = cur[2 * i];
            nxt[2 * i + 1] = cur[2 * i + 1];
            if (!inner[i]) continue;
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                const int w = sfb__other_end(l, l->ve[j], v), lw = (int)(-W->vd[w] - 2.0);
                double t = cur[2 * lw];
                if (periodic && T > 0) t += t - cur[2 * i] > 0.5 * T ? -T : t - cur[2 * i] < -0.5 * T ? T : 0.0;
                st += t;
                sa += cur[2 * lw + 1];
                cnt++;
            }
            if (cnt) { nxt[2 * i] = st / cnt; nxt[2 * i + 1] = sa / cnt; }
        }
        { double *sw = cur; cur = nxt; nxt = sw; }
    }
    /* no face may turn over (a face that was flat may go either way) */
    for (i = 0; i < n && ok; ++i) {
        const int v = mv[i];
        for (j = l->vf_off[v]; j < l->vf_off[v + 1] && ok; ++j) {
            const int f = l->vf[j];
            double uv[3][2], ar;
            int c, all = 1;
            for (c = 0; c < 3; ++c) all &= (W->vin[F->tri[3 * f + c]] & 8) != 0;
            if (!all || orient[f] == 0) continue;
            for (c = 0; c < 3; ++c) {
                const int li = (int)(-W->vd[F->tri[3 * f + c]] - 2.0);
                uv[c][0] = cur[2 * li];
                uv[c][1] = cur[2 * li + 1];
                if (periodic && T > 0 && c > 0) uv[c][0] += uv[c][0] - uv[0][0] > 0.5 * T ? -T : uv[c][0] - uv[0][0] < -0.5 * T ? T : 0.0;
            }
            ar = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
            if (ar * orient[f] <= 0.0) ok = 0;
        }
    }
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        if (ok) {
            double t = cur[2 * i];
            if (periodic && T > 0) { t = fmod(t, T); if (t < 0) t += T; }
            W->ta[2 * (size_t)v] = t;
            W->ta[2 * (size_t)v + 1] = cur[2 * i + 1];
        }
        W->vd[v] = -1.0;
    }
    *done = ok && iters > 0;
    sfb__free(ctx, mv); sfb__free(ctx, inner); sfb__free(ctx, cur); sfb__free(ctx, nxt); sfb__free(ctx, orient);
    return SFB_SUCCESS;
}

static sfb_result fil_one(sfb__fil *F, sfb__fil_work *W, const sfb__fil_curve *cv, int ci, sfb_fillet_curve_report *rep) {
    sfb_context *ctx = F->ctx;
    const sfb__level *l = F->l;
    const double r = cv->radius;
    const int kind = cv->profile;
    const double hs = F->cfg->hermite_scale;
    const int m = cv->closed ? cv->n - 1 : cv->n; /* distinct curve points */
    double *cp = NULL, *spine = NULL, *cum = NULL, *sarc = NULL, *C = NULL, *S = NULL, *LK[2] = {NULL, NULL};
    sfb__fil_prof *prof = NULL, *ip = NULL;
    sfb__aabb tree[2];
    sfb__fil_pairs P;
    sfb__fil_poly PC, PS, PL[2];
    int *cedge = NULL, nce = 0, i, k, side, qh = 0, qt = 0, ns = 0, sclosed = 0, nsamp = 0, moved = 0, convex;
    double dmax = 0.0, d, conv = 0.0, maxdev = 0.0;
    sfb_result res = SFB_SUCCESS;
    memset(tree, 0, sizeof tree);
    memset(&P, 0, sizeof P);
    memset(&PC, 0, sizeof PC);
    memset(&PS, 0, sizeof PS);
    memset(PL, 0, sizeof PL);
    memset(rep, 0, sizeof *rep);
    rep->closed = cv->closed;
    rep->curve_vertices = m;
    rep->radius = (float)r;
    if (m < 2) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "blending curve %d has fewer than 2 vertices", ci);

    res = fil_stage(F, ci, 0, "fillet curves");
    if (res != SFB_SUCCESS) return res;
    cp = (double *)sfb__alloc(ctx, (size_t)m * 3 * sizeof(double));
    cedge = (int *)sfb__alloc(ctx, (size_t)cv->n * sizeof(int));
    if (!cp || !cedge) { res = sfb__oom(ctx, "the blending curve"); goto done; }
    for (i = 0; i < m; ++i) memcpy(cp + 3 * (size_t)i, F->pos + 3 * (size_t)cv->v[i], 3 * sizeof(double));
    for (i = 0; i + 1 < cv->n; ++i) rep->curve_length += (float)fil_dist(F->pos + 3 * (size_t)cv->v[i], F->pos + 3 * (size_t)cv->v[i + 1]);
    res = fil_poly_build(ctx, &PC, cp, m, cv->closed);
    if (res != SFB_SUCCESS) goto done;
    /* curve edges, the sides' seed faces, the sharpest dihedral angle */
    for (i = 0; i + 1 < cv->n; ++i) {
        const int a = cv->v[i], b = cv->v[i + 1], e = fil_edge_of(l, a, b);
        int f0, f1, j;
        if (e < 0 || l->ef_off[e + 1] - l->ef_off[e] != 2) continue; /* checked for callers' curves */
        cedge[nce++] = e;
        F->emark[e] = 1;
        f0 = l->ef[l->ef_off[e]];
        f1 = l->ef[l->ef_off[e] + 1];
        for (j = 0; j < 3; ++j) /* side 0 holds a -> b */
            if (F->tri[3 * f1 + j] == a && F->tri[3 * f1 + (j + 1) % 3] == b) { const int t = f0; f0 = f1; f1 = t; break; }
        if (fil_dihedral(F, e) > dmax) dmax = fil_dihedral(F, e);
        if (W->fside[f0] < 0) { W->fside[f0] = 0; W->queue[qt++] = f0; }
        if (W->fside[f1] < 0) { W->fside[f1] = 1; W->queue[qt++] = f1; }
        conv += fil_edge_conv(F, e, a, b);
    }
    convex = conv < 0.0;
    rep->convex = convex;
    d = (F->cfg->alpha > 0.0f ? F->cfg->alpha : 1.75) * fil_reach(r, dmax);
    if (!(d <= F->scale)) {
        /* base patches reaching past the whole mesh: every face would be one, the offsets lie a
         * radius away from everything, and no check below could tell (they scale with r) */
        res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, cv->v[0],
                         "blending curve %d (from vertex %d): radius %g is too large for this mesh: its base patches would reach %g from "
                         "the curve, beyond the mesh's size (bounding-box diagonal %g), and the offset patches do not meet within it",
                         ci, cv->v[0], r, d, F->scale);
        goto done;
    }

    /* base patches: both sides grow breadth first together through faces within d */
    while (qh < qt) {
        const int f = W->queue[qh++];
        for (k = 0; k < 3; ++k) {
            const int e = l->fe[l->fv_off[f] + k];
            int j;
            if (F->emark[e] || F->fmark[e]) continue;
            for (j = l->ef_off[e]; j < l->ef_off[e + 1]; ++j) {
                const int g = l->ef[j];
                int c, near_ = 0;
                if (W->fside[g] >= 0) continue;
                for (c = 0; c < 3; ++c) {
                    const int v = F->tri[3 * g + c];
                    if (W->vd[v] < 0) {
                        {
                            int sg;
                            double tt, dd;
                            fil_poly_nearest(&PC, F->pos + 3 * (size_t)v, &sg, &tt, &dd);
                            W->vd[v] = sqrt(dd);
                        }
                        W->vdlist[W->nvd++] = v;
                    }
                    if (W->vd[v] < d) near_ = 1;
                }
                if (!near_) continue;
                W->fside[g] = W->fside[f];
                W->queue[qt++] = g;
            }
        }
    }
    /* per side: rows, vertex normals (angle weighted over that side's faces), offsets */
    for (side = 0; side < 2; ++side) {
        W->rows[side] = (int *)sfb__alloc(ctx, ((size_t)qt + 1) * 3 * sizeof(int));
        if (!W->rows[side]) { res = sfb__oom(ctx, "the base patches"); goto done; }
        W->nrows[side] = 0;
    }
    for (i = 0; i < qt; ++i) {
        const int f = W->queue[i], s = W->fside[f];
        int c;
        memcpy(W->rows[s] + 3 * (size_t)W->nrows[s], F->tri + 3 * (size_t)f, 3 * sizeof(int));
        W->nrows[s]++;
        for (c = 0; c < 3; ++c) {
            const int v = F->tri[3 * f + c];
            const double *p = F->pos + 3 * (size_t)v, *pa = F->pos + 3 * (size_t)F->tri[3 * f + (c + 1) % 3],
                         *pb = F->pos + 3 * (size_t)F->tri[3 * f + (c + 2) % 3];
            double ea[3], eb[3], la, lb, cang, ang;
            fil_sub(pa, p, ea); fil_sub(pb, p, eb);
            la = fil_len(ea); lb = fil_len(eb);
            cang = (la > 0 && lb > 0) ? fil_dot(ea, eb) / (la * lb) : 1.0;
            ang = acos(cang > 1 ? 1 : cang < -1 ? -1 : cang);
            if (!W->vin[v]) W->vlist[W->nvlist++] = v;
            W->vin[v] |= (unsigned char)(1 << s);
            W->nrm[s][3 * (size_t)v] += ang * F->fn[3 * (size_t)f];
            W->nrm[s][3 * (size_t)v + 1] += ang * F->fn[3 * (size_t)f + 1];
            W->nrm[s][3 * (size_t)v + 2] += ang * F->fn[3 * (size_t)f + 2];
        }
    }
    for (i = 0; i < cv->n; ++i) W->vin[cv->v[i]] |= 4;
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        for (side = 0; side < 2; ++side) {
            double *n = W->nrm[side] + 3 * (size_t)v, ln = fil_len(n), *o = W->op[side] + 3 * (size_t)v;
            const double sg = convex ? -r : r;
            if (ln > 0) { n[0] /= ln; n[1] /= ln; n[2] /= ln; }
            for (k = 0; k < 3; ++k) o[k] = F->pos[3 * (size_t)v + k] + sg * n[k];
        }
    }

    /* CSC: the offset patches' intersection */
    res = fil_stage(F, ci, 1, "fillet spine");
    if (res != SFB_SUCCESS) goto done;
    for (side = 0; side < 2; ++side) {
        res = sfb__aabb_build(ctx, W->op[side], W->rows[side], NULL, W->nrows[side], &tree[side]);
        if (res != SFB_SUCCESS) goto done;
    }
    P.F = F;
    P.op0 = W->op[0]; P.op1 = W->op[1];
    P.t0 = W->rows[0]; P.t1 = W->rows[1];
    sfb__aabb_pairs(&tree[0], &tree[1], 1e-9 * F->scale, fil_pair_cb, &P);
    if (P.failed) { res = sfb__oom(ctx, "the offset patches' intersection"); goto done; }
    res = fil_chain(ctx, P.segs, P.n, 1e-8 * (F->scale + r), cv->closed, &spine, &ns, &sclosed);
    if (res != SFB_SUCCESS) goto done;
    if (ns < 2) {
        res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, cv->v[0],
                         "blending curve %d (from vertex %d): the offset patches at radius %g do not meet -- the radius is too large "
                         "for the base patches (faces within %g of the curve) or the feature is too flat", ci, cv->v[0], r, d);
        goto done;
    }
    if (!cv->closed && !sclosed) {
        /* orient the spine like the curve, then clip it to the planes through the curve's ends */
        double t0[3], t1[3], a[3], b[3];
        int lo = 0, hi = ns - 1;
        fil_sub(spine + 3 * (size_t)(ns - 1), spine, a);
        fil_sub(cp + 3 * (size_t)(m - 1), cp, b);
        if (fil_dot(a, b) < 0)
            for (i = 0; i < ns / 2; ++i)
                for (k = 0; k < 3; ++k) {
                    const double t = spine[3 * (size_t)i + k];
                    spine[3 * (size_t)i + k] = spine[3 * (size_t)(ns - 1 - i) + k];
                    spine[3 * (size_t)(ns - 1 - i) + k] = t;
                }
        /* the end planes: through the curve's end point, or through the corner ball's centre where
         * the end is at a corner (the sweep stops where the ball starts touching the third face) */
        double jp[2][3];
        const double *pl0 = cv->corner[0] >= 0 ? F->corners[cv->corner[0]].C : cp;
        const double *pl1 = cv->corner[1] >= 0 ? F->corners[cv->corner[1]].C : cp + 3 * (size_t)(m - 1);
        /* ... or `setback` before another junction (at most 0.45 of the curve's length) */
        for (k = 0; k < 2; ++k)
            if (cv->setback[k] > 0.0) {
                const double *e = k ? cp + 3 * (size_t)(m - 1) : cp, *e2 = k ? cp + 3 * (size_t)(m - 2) : cp + 3;
                const double sb = cv->setback[k] < 0.45 * rep->curve_length ? cv->setback[k] : 0.45 * rep->curve_length;
                double u[3], lu;
                fil_sub(e2, e, u);
                lu = fil_len(u);
                for (i = 0; i < 3; ++i) jp[k][i] = e[i] + (lu > 0 ? sb * u[i] / lu : 0.0);
                if (k) pl1 = jp[1]; else pl0 = jp[0];
            }
        fil_sub(cp + 3, cp, t0);                                              /* into the curve at its start */
        fil_sub(cp + 3 * (size_t)(m - 1), cp + 3 * (size_t)(m - 2), t1);       /* out of it at its end */
        while (lo < ns - 1) {
            fil_sub(spine + 3 * (size_t)(lo + 1), pl0, a);
            if (fil_dot(a, t0) > 0) break;
            lo++;
        }
        while (hi > lo) {
            fil_sub(spine + 3 * (size_t)(hi - 1), pl1, a);
            if (fil_dot(a, t1) < 0) break;
            hi--;
        }
        /* points lo and hi may lie beyond the planes: move them onto them */
        if (hi > lo) {
            double da, db;
            fil_sub(spine + 3 * (size_t)lo, pl0, a); da = fil_dot(a, t0);
            fil_sub(spine + 3 * (size_t)(lo + 1), pl0, b); db = fil_dot(b, t0);
            if (da < 0 && db > da) fil_lerp(spine + 3 * (size_t)lo, spine + 3 * (size_t)(lo + 1), da / (da - db), spine + 3 * (size_t)lo);
            fil_sub(spine + 3 * (size_t)hi, pl1, a); da = fil_dot(a, t1);
            fil_sub(spine + 3 * (size_t)(hi - 1), pl1, b); db = fil_dot(b, t1);
            if (da > 0 && db < da) fil_lerp(spine + 3 * (size_t)hi, spine + 3 * (size_t)(hi - 1), da / (da - db), spine + 3 * (size_t)hi);
            memmove(spine, spine + 3 * (size_t)lo, (size_t)(hi - lo + 1) * 3 * sizeof(double));
            ns = hi - lo + 1;
        }
    }
    {
        /* spine loops (seed 4.3): pieces closer than 1.5 mean spine steps (at most r/10) while apart
         * along the spine by more than r/2 */
        double mean = 0.0, tol;
        for (i = 0; i + 1 < ns; ++i) mean += fil_dist(spine + 3 * (size_t)i, spine + 3 * (size_t)(i + 1));
        mean /= (ns > 1 ? ns - 1 : 1);
        tol = 1.5 * mean < 0.1 * r ? 1.5 * mean : 0.1 * r;
        rep->self_intersections = fil_spine_untangle(ctx, &spine, &ns, sclosed, tol, 0.25 * r);
    }
    {
        /* the spine must follow the curve: the ball's centre lies r / cos(delta / 2) from it, within
         * d. On real meshes the offsets' intersection can run off along another branch near a
         * curve's end (spot.obj's short creases: a curve vertex moved 14 r). An open spine keeps its
         * longest run of points within 1.5 d of the curve; a closed one that strays fails. */
        int best_lo = 0, best_n = 0, run_lo = 0, run_n = 0, bad = 0;
        for (i = 0; i < ns; ++i) {
            int sg;
            double tt, dd;
            fil_poly_nearest(&PC, spine + 3 * (size_t)i, &sg, &tt, &dd);
            if (sqrt(dd) <= 1.5 * d) {
                if (run_n == 0) run_lo = i;
                if (++run_n > best_n) { best_n = run_n; best_lo = run_lo; }
            } else { run_n = 0; bad++; }
        }
        if (bad && (sclosed || best_n < 2)) {
            res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, cv->v[0],
                             "blending curve %d (from vertex %d): the offset patches at radius %g meet away from the curve (%d of %d spine points "
                             "farther than %g from it) -- the surface around the curve is too uneven for this radius",
                             ci, cv->v[0], r, bad, ns, 1.5 * d);
            goto done;
        }
        if (bad) {
            memmove(spine, spine + 3 * (size_t)best_lo, (size_t)best_n * 3 * sizeof(double));
            ns = best_n;
        }
    }
    cum = (double *)sfb__alloc(ctx, ((size_t)ns + 1) * sizeof(double));
    if (!cum) { res = sfb__oom(ctx, "the spine"); goto done; }
    cum[0] = 0.0;
    for (i = 1; i <= ns; ++i)
        cum[i] = cum[i - 1] + (i < ns ? fil_dist(spine + 3 * (size_t)(i - 1), spine + 3 * (size_t)i)
                                      : (sclosed ? fil_dist(spine + 3 * (size_t)(ns - 1), spine) : 0.0));
    rep->spine_length = (float)cum[sclosed ? ns : ns - 1];

    /* virtual surface: samples and their profiles */
    res = fil_stage(F, ci, 2, "fillet surface");
    if (res != SFB_SUCCESS) goto done;
    res = fil_sample(ctx, spine, cum, ns, sclosed, F->cfg->samples > 0 ? F->cfg->samples : 40,
                     F->cfg->chord_ratio > 0.0f ? F->cfg->chord_ratio : 0.002, &sarc, &nsamp);
    if (res != SFB_SUCCESS) goto done;
    rep->samples = nsamp;
    C = (double *)sfb__alloc(ctx, (size_t)nsamp * 3 * sizeof(double));
    prof = (sfb__fil_prof *)sfb__alloc(ctx, (size_t)nsamp * sizeof *prof);
    if (!C || !prof) { res = sfb__oom(ctx, "the sweep's profiles"); goto done; }
    for (i = 0; i < nsamp; ++i) {
        double link[2][3], E[3], bary[3];
        fil_point_at(spine, cum, ns, sclosed, sarc[i], C + 3 * (size_t)i);
        for (side = 0; side < 2; ++side) {
            const int row = sfb__aabb_nearest(&tree[side], W->op[side], W->rows[side], NULL, C + 3 * (size_t)i, NULL, NULL, bary);
            const int *t = W->rows[side] + 3 * (size_t)(row < 0 ? 0 : row);
            for (k = 0; k < 3; ++k)
                link[side][k] = bary[0] * F->pos[3 * (size_t)t[0] + k] + bary[1] * F->pos[3 * (size_t)t[1] + k] +
                                bary[2] * F->pos[3 * (size_t)t[2] + k];
        }
        {
            int sg;
            double tt, dd;
            fil_poly_nearest(&PC, C + 3 * (size_t)i, &sg, &tt, &dd);
            fil_lerp(cp + 3 * (size_t)sg, cp + 3 * (size_t)((sg + 1) % m), tt, E);
        }
        fil_prof_build(&prof[i], C + 3 * (size_t)i, link[0], link[1], E, kind, cv->conic_w, hs);
    }

    /* map: every base-patch vertex between the linkage curves gets (t, a): t the arc length of its
     * nearest point on the samples' polyline, a its place across */
    res = fil_stage(F, ci, 3, "fillet map");
    if (res != SFB_SUCCESS) goto done;
    ip = (sfb__fil_prof *)sfb__alloc(ctx, sizeof *ip);
    S = (double *)sfb__alloc(ctx, ((size_t)nsamp + 1) * sizeof(double));
    LK[0] = (double *)sfb__alloc(ctx, (size_t)nsamp * 3 * sizeof(double));
    LK[1] = (double *)sfb__alloc(ctx, (size_t)nsamp * 3 * sizeof(double));
    if (!ip || !S || !LK[0] || !LK[1]) { res = sfb__oom(ctx, "the sweep's profiles"); goto done; }
    for (i = 0; i < nsamp; ++i) {
        memcpy(LK[0] + 3 * (size_t)i, prof[i].P1, 3 * sizeof(double));
        memcpy(LK[1] + 3 * (size_t)i, prof[i].P2, 3 * sizeof(double));
    }
    if ((res = fil_poly_build(ctx, &PS, C, nsamp, sclosed)) != SFB_SUCCESS || (res = fil_poly_build(ctx, &PL[0], LK[0], nsamp, sclosed)) != SFB_SUCCESS ||
        (res = fil_poly_build(ctx, &PL[1], LK[1], nsamp, sclosed)) != SFB_SUCCESS)
        goto done;
    S[0] = 0.0;
    for (i = 1; i <= nsamp; ++i)
        S[i] = S[i - 1] + (i < nsamp ? fil_dist(C + 3 * (size_t)(i - 1), C + 3 * (size_t)i) : sclosed ? fil_dist(C + 3 * (size_t)(nsamp - 1), C) : 0.0);
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        const double *p = F->pos + 3 * (size_t)v;
        int seg, j, vs = 0;
        double t, d2, E[3], L1, L2, s;
        fil_poly_nearest(&PS, p, &seg, &t, &d2);
        j = (seg + 1) % nsamp;
        if (!sclosed && ((seg == 0 && t <= 0.0) || (seg == nsamp - 2 && t >= 1.0))) {
            /* beyond an end of an open spine: outside unless on the end plane */
            const int e = seg == 0 && t <= 0.0 ? 0 : nsamp - 1, e2 = e == 0 ? 1 : nsamp - 2;
            double out[3], dv[3];
            fil_sub(C + 3 * (size_t)e, C + 3 * (size_t)e2, out);
            fil_sub(p, C + 3 * (size_t)e, dv);
            if (fil_dot(dv, out) > 1e-9 * fil_len(out) * (F->scale + r)) continue;
        }
        if (!(W->vin[v] & 4)) {
            /* t off the curve: the nearest point on the vertex's own side's linkage polyline, not
             * on the spine. Both agree where the sweep is a plain tube; where the spine was cut and
             * bridged (a reflex corner, seed 4.3) the profile planes there are not the spine's
             * normal planes, and the vertices near the linkage curve -- the region's boundary,
             * which the conformal map keeps -- find their own profile only this way. */
            int sg0, sg1;
            double t0, t1, e0, e1;
            fil_poly_nearest(&PL[0], p, &sg0, &t0, &e0);
            fil_poly_nearest(&PL[1], p, &sg1, &t1, &e1);
            vs = (W->vin[v] & 1) ? 0 : 1;
            if ((W->vin[v] & 3) == 3) vs = e0 <= e1 ? 0 : 1; /* both sides (around an open chain's end): the nearer */
            seg = vs == 0 ? sg0 : sg1;
            t = vs == 0 ? t0 : t1;
            j = (seg + 1) % nsamp;
        }
        fil_lerp(prof[seg].E, prof[j].E, t, E);
        L1 = prof[seg].L1 + t * (prof[j].L1 - prof[seg].L1);
        L2 = prof[seg].L2 + t * (prof[j].L2 - prof[seg].L2);
        if (!(L1 + L2 > 0)) continue;
        if (W->vd[v] < 0) { /* its distance to the curve, if the base patches' search did not need it */
            int sg;
            double tt, dd;
            fil_poly_nearest(&PC, p, &sg, &tt, &dd);
            W->vd[v] = sqrt(dd);
            W->vdlist[W->nvd++] = v;
        }
        /* a base-patch face's far corner (the patches take whole faces) is no region vertex */
        if (W->vd[v] > d) continue;
        if (W->vin[v] & 4) { s = 0.0; vs = 0; }
        else {
            /* s: how far the vertex lies past its side's linkage point toward the curve, measured
             * along the line from the one to the other. Inside the region when s > 0. (The distance
             * to the curve's foot E, used before, decides differently for neighbouring vertices
             * where the spine turns sharply -- a reflex corner of the seam, where the ball sits in
             * the corner and the vertices behind it have no profile plane of their own -- and left
             * single vertices out, stretching triangles across the corner.) */
            double l0[3], l1[3], lk[3], u[3], dv[3], lu;
            fil_lerp(prof[seg].P1, prof[j].P1, t, l0);
            fil_lerp(prof[seg].P2, prof[j].P2, t, l1);
            memcpy(lk, vs == 0 ? l0 : l1, sizeof lk);
            fil_sub(E, lk, u);
            lu = fil_len(u);
            if (!(lu > 0)) continue;
            fil_sub(p, lk, dv);
            s = fil_dot(dv, u) / lu;
            if (s <= 0.0) continue;
            s = (vs == 0 ? L1 : L2) - (s < lu ? s : lu) * (vs == 0 ? L1 : L2) / lu; /* as a distance from the curve */
        }
        W->ta[2 * (size_t)v] = S[seg] + t * (S[seg + 1] - S[seg]);
        W->ta[2 * (size_t)v + 1] = vs == 0 ? (L1 - s) / (L1 + L2) : (L1 + s) / (L1 + L2);
        W->vin[v] |= 8;
        moved++;
    }
    rep->map = 0;
    if (F->cfg->map == SFB_FILLET_MAP_CONFORMAL) {
        res = fil_harmonic(F, W, S[sclosed ? nsamp : nsamp - 1], sclosed, &rep->map);
        if (res != SFB_SUCCESS) goto done;
        if (F->cfg->relax > 0) {
            res = fil_relax(F, W, S[sclosed ? nsamp : nsamp - 1], sclosed, F->cfg->relax, &rep->relaxed);
            if (res != SFB_SUCCESS) goto done;
        }
    }

    /* project: (t, a) onto the ruled surface between the two profiles around t */
    res = fil_stage(F, ci, 4, "fillet project");
    if (res != SFB_SUCCESS) goto done;
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        const double T = S[sclosed ? nsamp : nsamp - 1];
        double t = W->ta[2 * (size_t)v], a = W->ta[2 * (size_t)v + 1], th, qa[3], qb[3], np_[3], Ct[3], P1t[3], P2t[3], Et[3], dev;
        int lo = 0, hi = sclosed ? nsamp : nsamp - 1, j;
        if (!(W->vin[v] & 8)) continue;
        if (sclosed) { t = fmod(t, T); if (t < 0) t += T; }
        else t = t < 0 ? 0 : t > T ? T : t;
        a = a < 0 ? 0 : a > 1 ? 1 : a;
        while (hi - lo > 1) {
            const int mid = (lo + hi) / 2;
            if (S[mid] <= t) lo = mid; else hi = mid;
        }
        j = (lo + 1) % nsamp;
        th = S[lo + 1] > S[lo] ? (t - S[lo]) / (S[lo + 1] - S[lo]) : 0.0;
        th = th < 0 ? 0 : th > 1 ? 1 : th;
        fil_prof_at(&prof[lo], kind, hs, a, qa);
        fil_prof_at(&prof[j], kind, hs, a, qb);
        fil_lerp(qa, qb, th, np_);
        if (fil_dist(np_, F->pos + 3 * (size_t)v) > 2.0 * d) { /* no profile near it: it stays (counted) */
            W->vin[v] &= (unsigned char)~8u;
            moved--;
            rep->vertices_kept++;
            continue;
        }
        memcpy(F->npos + 3 * (size_t)v, np_, sizeof np_);
        /* the ideal surface here: the profile built from the interpolated spine and linkage points */
        fil_lerp(prof[lo].C, prof[j].C, th, Ct);
        fil_lerp(prof[lo].P1, prof[j].P1, th, P1t);
        fil_lerp(prof[lo].P2, prof[j].P2, th, P2t);
        fil_lerp(prof[lo].E, prof[j].E, th, Et);
        fil_prof_build(ip, Ct, P1t, P2t, Et, kind, cv->conic_w, hs);
        if (kind == SFB_FILLET_ARC) ip->r = r; /* the ideal arc has the ball's radius */
        dev = fil_prof_distance(ip, kind, hs, np_);
        if (dev > maxdev) maxdev = dev;
    }
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        if (W->vin[v] & 8) memcpy(F->opos + 3 * (size_t)v, F->npos + 3 * (size_t)v, 3 * sizeof(double));
    }
    rep->vertices_moved = moved;
    rep->max_deviation = (float)maxdev;
done:
    /* reset the work arrays for the next curve */
    for (i = 0; i < qt; ++i) W->fside[W->queue[i]] = -1;
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        int c;
        W->vin[v] = 0;
        for (c = 0; c < 3; ++c) W->nrm[0][3 * (size_t)v + c] = W->nrm[1][3 * (size_t)v + c] = 0.0;
    }
    for (i = 0; i < cv->n; ++i) W->vin[cv->v[i]] = 0;
    W->nvlist = 0;
    for (i = 0; i < W->nvd; ++i) W->vd[W->vdlist[i]] = -1.0;
    W->nvd = 0;
    for (i = 0; i < nce; ++i) F->emark[cedge[i]] = 0;
    for (side = 0; side < 2; ++side) {
        sfb__aabb_free(ctx, &tree[side]);
        sfb__free(ctx, W->rows[side]);
        W->rows[side] = NULL;
    }
    sfb__free(ctx, P.segs);
    sfb__free(ctx, cp); sfb__free(ctx, cedge); sfb__free(ctx, spine); sfb__free(ctx, cum);
    sfb__free(ctx, sarc); sfb__free(ctx, C); sfb__free(ctx, prof); sfb__free(ctx, ip); sfb__free(ctx, S);
    sfb__free(ctx, LK[0]); sfb__free(ctx, LK[1]);
    fil_poly_free(ctx, &PC); fil_poly_free(ctx, &PS); fil_poly_free(ctx, &PL[0]); fil_poly_free(ctx, &PL[1]);
    return res;
}

/* ---- the API ---- */
SFB_API sfb_fillet_config sfb_fillet_config_init(float radius) {
    sfb_fillet_config c;
    memset(&c, 0, sizeof c);
    c.radius = radius;
    return c;
}

SFB_API void sfb_fillet_report_free(sfb_fillet_report *report) {
    if (!report) return;
    if (report->ctx_) sfb__free(report->ctx_, report->curves);
    memset(report, 0, sizeof *report);
}

static sfb_result fil_check(sfb_context *ctx, const sfb_mesh *mesh, const sfb_fillet_config *c) {
    const sfb__level *l = &mesh->base;
    int f, e;
    if (!(c->radius > 0.0f) || !isfinite(c->radius))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "fillet radius %g is not a positive number", (double)c->radius);
    if (!(c->angle >= 0.0f && c->angle < 180.0f))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "feature angle %g is not a number of degrees in [0, 180)", (double)c->angle);
    if (c->profile < 0 || c->profile > SFB_FILLET_HERMITE)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "unknown fillet profile %d", c->profile);
    if (!(c->conic_weight >= 0.0f) || !isfinite(c->conic_weight))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "conic weight %g is not a number >= 0", (double)c->conic_weight);
    if (!(c->hermite_scale >= 0.0f && c->hermite_scale <= 10.0f))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "Hermite scale %g is not in [0, 10] (tangent length over the chord)",
                          (double)c->hermite_scale);
    if (!(c->alpha == 0.0f || (c->alpha >= 1.0f && c->alpha <= 100.0f)))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "base patch factor alpha %g is not 0 or in [1, 100]", (double)c->alpha);
    if (c->samples < 0 || c->samples == 1 || c->samples > 100000)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "spine samples %d is not 0 or in [2, 100000]", c->samples);
    if (!(c->chord_ratio >= 0.0f && c->chord_ratio < 1.0f))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "chord ratio %g is not in [0, 1)", (double)c->chord_ratio);
    if (c->map != SFB_FILLET_MAP_CONFORMAL && c->map != SFB_FILLET_MAP_DIRECT)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "unknown fillet map %d", c->map);
    if (c->curve_count < 0 || (c->curve_count > 0 && !c->curves))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "curve_count %d with %s curves", c->curve_count, c->curves ? "its" : "no");
    if (l->nf == 0) return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_NONE, -1, "the mesh has no faces");
    for (f = 0; f < l->nf; ++f)
        if (l->fv_off[f + 1] - l->fv_off[f] != 3)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "it has %d vertices: fillets need a triangle mesh (sfb_mesh_triangulate, "
                              "the tools' --triangulate, splits faces into triangles)",
                              l->fv_off[f + 1] - l->fv_off[f]);
    for (e = 0; e < l->ne; ++e)
        if (l->ef_off[e + 1] - l->ef_off[e] > 2)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, e, "edge %d (vertices %d-%d) has %d faces: the mesh is not manifold", e,
                              l->ev[2 * e], l->ev[2 * e + 1], l->ef_off[e + 1] - l->ef_off[e]);
    {
        sfb_mesh_info info;
        sfb_mesh_get_info(mesh, &info);
        if (info.nonmanifold_vertices > 0) {
            int v, first = -1;
            for (v = 0; v < l->nv && first < 0; ++v)
                if ((l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v]) first = v;
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, first,
                              "the mesh has %d non-manifold vertices (where separate fans of faces meet; this is the first): "
                              "fillets need a manifold mesh", info.nonmanifold_vertices);
        }
    }
    for (e = 0; e < 3 * l->nv; ++e)
        if (!isfinite(mesh->positions[e]))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, e / 3, "vertex %d is not finite", e / 3);
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_mesh_fillet(sfb_context *ctx, const sfb_mesh *mesh, const sfb_fillet_config *config, sfb_mesh **out,
                                   sfb_fillet_report *report) {
    sfb__fil F;
    sfb__fil_work W;
    sfb_fillet_curve_report *reps = NULL;
    float *fpos = NULL;
    int *cvert = NULL, i, nc = 0, nskip = 0;
    float *csharp = NULL;
    sfb_result res;
    sfb__error_state kept;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, need;
    if (out) *out = NULL;
    if (report) memset(report, 0, sizeof *report);
    if (!ctx || !mesh || !config || !out) return ctx ? sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_mesh_fillet: NULL argument") : SFB_INVALID_ARGS;
    res = fil_check(ctx, mesh, config);
    if (res != SFB_SUCCESS) return res;
    memset(&F, 0, sizeof F);
    memset(&W, 0, sizeof W);
    F.ctx = ctx;
    F.cfg = config;
    F.l = &mesh->base;
    F.nv = mesh->base.nv;
    F.nf = mesh->base.nf;
    F.tri = mesh->base.fv;
    /* the memory budget, before the work: per vertex 11 doubles x 3 and some ints, per face a few */
    need = (double)F.nv * (13.0 * 3 * sizeof(double) + 4 * sizeof(int) + 2) + (double)F.nf * (3 * sizeof(double) + 12 * sizeof(int)) +
           (double)mesh->base.ne;
    if (need > (double)ctx->budget - (double)ctx->live_bytes)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "filleting a mesh of %d vertices and %d faces needs about %.0f MB, over the memory budget (%zu bytes, %zu in use)",
                          F.nv, F.nf, need / 1048576.0, ctx->budget, ctx->live_bytes);
    F.pos = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(double));
    F.npos = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(double));
    F.opos = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(double));
    F.fmark = (unsigned char *)sfb__calloc(ctx, (size_t)mesh->base.ne + 1, 1);
    F.fn = (double *)sfb__alloc(ctx, ((size_t)F.nf + 1) * 3 * sizeof(double));
    F.emark = (unsigned char *)sfb__calloc(ctx, (size_t)mesh->base.ne + 1, 1);
    W.fside = (int *)sfb__alloc(ctx, ((size_t)F.nf + 1) * sizeof(int));
    W.queue = (int *)sfb__alloc(ctx, ((size_t)F.nf + 1) * sizeof(int));
    W.vd = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * sizeof(double));
    W.vdlist = (int *)sfb__alloc(ctx, ((size_t)F.nv + 1) * sizeof(int));
    W.vlist = (int *)sfb__alloc(ctx, ((size_t)F.nv + 1) * sizeof(int));
    W.vin = (unsigned char *)sfb__calloc(ctx, (size_t)F.nv + 1, 1);
    W.ta = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 2 * sizeof(double));
    for (i = 0; i < 2; ++i) {
        W.nrm[i] = (double *)sfb__calloc(ctx, ((size_t)F.nv + 1) * 3, sizeof(double));
        W.op[i] = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(double));
    }
    if (!F.pos || !F.npos || !F.opos || !F.fmark || !F.fn || !F.emark || !W.fside || !W.queue || !W.vd || !W.vdlist || !W.vlist || !W.vin || !W.ta || !W.nrm[0] ||
        !W.nrm[1] || !W.op[0] || !W.op[1]) {
        res = sfb__oom(ctx, "the fillet's work arrays");
        goto done;
    }
    for (i = 0; i < 3 * F.nv; ++i) {
        F.pos[i] = F.opos[i] = mesh->positions[i];
        if (F.pos[i] < lo[i % 3]) lo[i % 3] = F.pos[i];
        if (F.pos[i] > hi[i % 3]) hi[i % 3] = F.pos[i];
    }
    F.scale = F.nv ? sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2])) : 1.0;
    for (i = 0; i < F.nf; ++i) W.fside[i] = -1;
    for (i = 0; i < F.nv; ++i) W.vd[i] = -1.0;
    fil_face_normals(&F);
    res = config->curves ? fil_curves_from_caller(&F) : fil_curves_from_angle(&F);
    if (res != SFB_SUCCESS) goto done;
    reps = (sfb_fillet_curve_report *)sfb__calloc(ctx, (size_t)F.ncurves + 1, sizeof *reps);
    if (!reps) { res = sfb__oom(ctx, "the fillet report"); goto done; }
    res = fil_find_corners(&F);
    if (res != SFB_SUCCESS) goto done;
    /* every curve on the input's positions (each writes its own region into opos; the regions of
     * curves that meet at a corner end at the corner's planes, so they do not overlap) */
    sfb__error_keep(ctx, &kept);
    for (i = 0; i < F.ncurves; ++i) {
        res = fil_one(&F, &W, &F.curves[i], i, &reps[i]);
        if (res == SFB_INVALID_VALUE && config->skip_failed) {
            /* this curve cannot be filleted with this radius (fil_one wrote nothing): left sharp, said */
            reps[i].skipped = 1;
            nskip++;
            /* the reason goes to the logger; the caller's last error is put back (the call succeeds) */
            sfb__log(ctx, SFB_LOG_WARN, "fillet: curve %d left sharp (skip_failed): %s", i, ctx->error);
            sfb__error_put_back(ctx, &kept);
            res = SFB_SUCCESS;
            continue;
        }
        if (res != SFB_SUCCESS) goto done;
    }
    if (nskip == F.ncurves) {
        res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                         "none of the %d blending curves could be filleted: radius %g is too large for the base patches or for the "
                         "surface around the curves (the offset patches do not meet, or meet away from the curves)", F.ncurves,
                         (double)config->radius);
        goto done;
    }
    res = fil_corners_project(&F, reps);
    if (res == SFB_SUCCESS) res = fil_junctions_fill(&F);
    if (res != SFB_SUCCESS) goto done;
    res = sfb__progress(ctx, 1.0f, "fillet project");
    if (res != SFB_SUCCESS) goto done;
    {
        /* the output: the input's arrays with the new positions; filleted edges lose their crease tags */
        sfb_mesh_desc d;
        int c;
        sfb_mesh_get_desc(mesh, &d);
        fpos = (float *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(float));
        cvert = (int *)sfb__alloc(ctx, ((size_t)d.crease_count + 1) * 2 * sizeof(int));
        csharp = (float *)sfb__alloc(ctx, ((size_t)d.crease_count + 1) * sizeof(float));
        if (!fpos || !cvert || !csharp) { res = sfb__oom(ctx, "the filleted mesh"); goto done; }
        for (i = 0; i < 3 * F.nv; ++i) fpos[i] = (float)F.opos[i];
        for (c = 0; c < F.ncurves; ++c)
            for (i = 0; i + 1 < F.curves[c].n && !reps[c].skipped; ++i) {
                const int e = fil_edge_of(F.l, F.curves[c].v[i], F.curves[c].v[i + 1]);
                if (e >= 0) F.emark[e] = 1;
            }
        for (i = 0; i < d.crease_count; ++i) {
            const int e = fil_edge_of(F.l, d.crease_vertices[2 * i], d.crease_vertices[2 * i + 1]);
            if (e >= 0 && F.emark[e]) continue;
            cvert[2 * nc] = d.crease_vertices[2 * i];
            cvert[2 * nc + 1] = d.crease_vertices[2 * i + 1];
            csharp[nc++] = d.crease_sharpness[i];
        }
        d.positions = fpos;
        d.crease_count = nc;
        d.crease_vertices = cvert;
        d.crease_sharpness = csharp;
        res = sfb_mesh_create(ctx, &d, out);
        if (res != SFB_SUCCESS) goto done;
    }
    if (report) {
        report->curve_count = F.ncurves;
        report->curves = reps;
        report->ctx_ = ctx;
        for (i = 0; i < F.ncurves; ++i) report->vertices_moved += reps[i].vertices_moved;
        report->curves_skipped = nskip;
        for (i = 0; i < F.ncorners; ++i) report->corner_count += F.corners[i].moved > 0;
        /* faces the fillet turned over (normal more than 90 degrees from the input's): a radius too
         * large for the surface around a curve; said, not refused (the caller decides) */
        for (i = 0; i < F.nf; ++i) {
            const int *t = F.tri + 3 * (size_t)i;
            double u[3], w[3], n[3];
            fil_sub(F.opos + 3 * (size_t)t[1], F.opos + 3 * (size_t)t[0], u);
            fil_sub(F.opos + 3 * (size_t)t[2], F.opos + 3 * (size_t)t[0], w);
            fil_cross(u, w, n);
            if (fil_dot(n, F.fn + 3 * (size_t)i) < 0.0) report->faces_folded++;
        }
        for (i = 0; i < F.ncorners; ++i) report->corner_vertices_moved += F.corners[i].moved;
        report->vertices_moved += report->corner_vertices_moved;
        reps = NULL;
    }
done:
    if (res != SFB_SUCCESS && out && *out) { sfb_mesh_destroy(*out); *out = NULL; }
    for (i = 0; i < F.ncurves; ++i) sfb__free(ctx, F.curves[i].v);
    sfb__free(ctx, F.curves);
    sfb__free(ctx, reps);
    sfb__free(ctx, F.pos); sfb__free(ctx, F.npos); sfb__free(ctx, F.fn); sfb__free(ctx, F.emark);
    sfb__free(ctx, F.opos); sfb__free(ctx, F.fmark); sfb__free(ctx, F.corners); sfb__free(ctx, F.junctions);
    sfb__free(ctx, W.fside); sfb__free(ctx, W.queue); sfb__free(ctx, W.vd); sfb__free(ctx, W.vdlist);
    sfb__free(ctx, W.vlist); sfb__free(ctx, W.vin); sfb__free(ctx, W.ta);
    for (i = 0; i < 2; ++i) { sfb__free(ctx, W.nrm[i]); sfb__free(ctx, W.op[i]); }
    sfb__free(ctx, fpos); sfb__free(ctx, cvert); sfb__free(ctx, csharp);
    return res;
}
