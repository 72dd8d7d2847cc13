/* An axis-aligned bounding-box tree over triangles and the robust triangle geometry built on it
 * (the rolling-ball operator's intersections and projections, seed 002, and the checks of any
 * triangle mesh): a top-down build by median split on the longest axis of each node's box
 * (leaves of at most SFB__AABB_LEAF triangles, so the depth is at most about log2(count) and
 * every traversal runs on a small fixed stack), all pairs of overlapping triangle boxes of two
 * trees or of one tree with itself by simultaneous descent, the nearest point by branch and
 * bound, the closest point on one triangle (the Voronoi-region method of Ericson's Real-Time
 * Collision Detection, written here from the geometry), the intersection segment of two
 * triangles (the interval method of Moller 1997 with the care of Guigue-Devillers 2003 for
 * vertices on planes and coplanar pairs) and a mesh's self-intersections. Storage: the node array
 * holds node_count tree nodes followed by item_count boxes, nodes[node_count + i] being the box of
 * triangle items[i] (sfb__aabb has no other place for them; the pair query tests them so that it
 * reports exactly the triangle pairs whose own boxes overlap). Everything is double; a built tree
 * is read-only and any number of threads may query it at once. */

#define SFB__AABB_LEAF 4
/* Median splits halve a node (the larger half has ceil(n/2) items), so a tree over at most
 * INT_MAX triangles with leaves of 4 is at most 30 levels deep: a descent of one tree pushes at
 * most 2 nodes per level, a simultaneous descent of two at most 3 pairs per step of at most 60. */
#define SFB__AABB_STACK 256

/* The tolerances of the triangle-triangle test (sfb__tri_tri_segment), relative to s, the
 * longest edge of the two triangles:
 *   - a triangle is degenerate (zero area) when |(v1 - v0) x (v2 - v0)| <= SFB__TT_AREA * L^2, L its
 *     own longest edge: its smallest height is below 1e-12 L (this also catches L = 0);
 *   - a vertex lies on the other triangle's plane when its signed distance to it (the unit normal
 *     dotted with the vertex minus a vertex of the plane's triangle) is within SFB__TT_DIST * s;
 *   - intervals on the line of the two planes, and projections of coplanar triangles on a
 *     separating axis, touch when their gap is within the same SFB__TT_DIST * s.
 * Rounding of these distances is a few units of 1e-16 s for triangles that are not needles, so
 * shared vertices and edges (bitwise equal coordinates) always land on the planes. */
#define SFB__TT_AREA 1e-12
#define SFB__TT_DIST 1e-12
/* A segment between two triangles that share one vertex is more than that vertex when it is
 * longer than SFB__SELF_LEN * s (sfb__trimesh_self_intersections). */
#define SFB__SELF_LEN 1e-10

static void aabb_sub3(const double *a, const double *b, double *c) {
    c[0] = a[0] - b[0];
    c[1] = a[1] - b[1];
    c[2] = a[2] - b[2];
}
static double aabb_dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void aabb_cross3(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
static int aabb_finite3(const double *p) {
    /* x - x is 0 for finite x and NaN for inf and NaN */
    return p[0] - p[0] == 0.0 && p[1] - p[1] == 0.0 && p[2] - p[2] == 0.0;
}

/* ---- build ---- */

/* Reorders perm[lo, hi) so that perm[k] holds the item whose key (cen[3 * item + axis]) would be
 * there sorted, with no larger key before it and no smaller one after (Hoare partitions around
 * the median of three). */
static void aabb_select(int *perm, int lo, int hi, int k, const double *cen, int axis) {
    hi--;
    while (hi > lo) {
        const int mid = lo + (hi - lo) / 2;
        double x = cen[3 * (size_t)perm[lo] + axis], y = cen[3 * (size_t)perm[mid] + axis], z = cen[3 * (size_t)perm[hi] + axis];
        double pv;
        int i = lo, j = hi;
        if (x > y) { double s = x; x = y; y = s; }
        pv = z < x ? x : z > y ? y : z;
        while (i <= j) {
            while (cen[3 * (size_t)perm[i] + axis] < pv) i++;
            while (cen[3 * (size_t)perm[j] + axis] > pv) j--;
            if (i <= j) {
                const int s = perm[i];
                perm[i] = perm[j];
                perm[j] = s;
                i++;
                j--;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else break;
    }
}

sfb_result sfb__aabb_build(sfb_context *ctx, const double *pos, const int *tri, const int *ids, int count, sfb__aabb *out) {
    double *tbox = NULL, *cen = NULL;
    int *perm = NULL, m = 0, i, sp = 0;
    int stack[3 * SFB__AABB_STACK];
    size_t bytes, nodes_cap;
    sfb__aabb t;
    if (!out) return ctx ? sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb__aabb_build: NULL tree") : SFB_INVALID_ARGS;
    memset(out, 0, sizeof *out);
    if (!ctx) return SFB_INVALID_ARGS;
    if (count < 0 || (count > 0 && (!pos || !tri)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb__aabb_build: %d triangles without their arrays", count);
    if (count == 0) return SFB_SUCCESS;
    memset(&t, 0, sizeof t);
    if (!sfb__mul_size((size_t)count, 6 * sizeof(double), &bytes) || !(tbox = (double *)sfb__alloc(ctx, bytes)) ||
        !(cen = (double *)sfb__alloc(ctx, bytes / 2)) || !(perm = (int *)sfb__alloc(ctx, (size_t)count * sizeof(int)))) {
        sfb__free(ctx, tbox);
        sfb__free(ctx, cen);
        return sfb__oom(ctx, "an AABB tree's triangle boxes");
    }
    /* the finite triangles, each with its box and centroid */
    for (i = 0; i < count; ++i) {
        const int *v = tri + 3 * (size_t)i;
        double *lo = tbox + 6 * (size_t)m, *hi = lo + 3;
        int c, k, ok = v[0] >= 0 && v[1] >= 0 && v[2] >= 0;
        for (c = 0; c < 3 && ok; ++c) ok = aabb_finite3(pos + 3 * (size_t)v[c]);
        if (!ok) continue;
        for (k = 0; k < 3; ++k) {
            const double x = pos[3 * (size_t)v[0] + k], y = pos[3 * (size_t)v[1] + k], z = pos[3 * (size_t)v[2] + k];
            lo[k] = x < y ? (x < z ? x : z) : (y < z ? y : z);
            hi[k] = x > y ? (x > z ? x : z) : (y > z ? y : z);
            cen[3 * (size_t)m + k] = (x + y + z) * (1.0 / 3.0);
        }
        perm[m] = i;
        m++;
    }
    /* perm[j] is the j-th finite triangle; its box and centroid are at slot j */
    if (m == 0) goto done;
    nodes_cap = 2 * (size_t)m - 1 + (size_t)m;
    if (!sfb__mul_size(nodes_cap, sizeof(sfb__aabb_node), &bytes) || !(t.nodes = (sfb__aabb_node *)sfb__alloc(ctx, bytes)) ||
        !(t.items = (int *)sfb__alloc(ctx, (size_t)m * sizeof(int)))) {
        sfb__free(ctx, t.nodes);
        sfb__free(ctx, tbox);
        sfb__free(ctx, cen);
        sfb__free(ctx, perm);
        return sfb__oom(ctx, "an AABB tree");
    }
    {
        /* slots 0..m-1 sorted in place of ord; the tree refers to slots, items are filled last */
        int *ord = t.items;
        for (i = 0; i < m; ++i) ord[i] = i;
        t.node_count = 1;
        stack[sp++] = 0; stack[sp++] = 0; stack[sp++] = m;
        while (sp > 0) {
            const int e = stack[--sp], b = stack[--sp], nd = stack[--sp];
            sfb__aabb_node *N = &t.nodes[nd];
            int k, j, axis = 0;
            for (k = 0; k < 3; ++k) { N->lo[k] = HUGE_VAL; N->hi[k] = -HUGE_VAL; }
            for (j = b; j < e; ++j) {
                const double *bx = tbox + 6 * (size_t)ord[j];
                for (k = 0; k < 3; ++k) {
                    if (bx[k] < N->lo[k]) N->lo[k] = bx[k];
                    if (bx[3 + k] > N->hi[k]) N->hi[k] = bx[3 + k];
                }
            }
            N->first = b;
            N->count = e - b;
            if (e - b <= SFB__AABB_LEAF) {
                N->left = N->right = -1;
                continue;
            }
            for (k = 1; k < 3; ++k)
                if (N->hi[k] - N->lo[k] > N->hi[axis] - N->lo[axis]) axis = k;
            aabb_select(ord, b, e, b + (e - b) / 2, cen, axis);
            N->left = t.node_count++;
            N->right = t.node_count++;
            stack[sp++] = N->right; stack[sp++] = b + (e - b) / 2; stack[sp++] = e;
            stack[sp++] = N->left; stack[sp++] = b; stack[sp++] = b + (e - b) / 2;
        }
        t.item_count = m;
        for (i = 0; i < m; ++i) {
            const int slot = ord[i];
            sfb__aabb_node *B = &t.nodes[t.node_count + i];
            int k;
            for (k = 0; k < 3; ++k) {
                B->lo[k] = tbox[6 * (size_t)slot + k];
                B->hi[k] = tbox[6 * (size_t)slot + 3 + k];
            }
            B->left = B->right = -1;
            B->first = i;
            B->count = 1;
            ord[i] = ids ? ids[perm[slot]] : perm[slot];
        }
    }
done:
    sfb__free(ctx, tbox);
    sfb__free(ctx, cen);
    sfb__free(ctx, perm);
    *out = t;
    return SFB_SUCCESS;
}

void sfb__aabb_free(sfb_context *ctx, sfb__aabb *t) {
    if (!t) return;
    if (ctx) {
        sfb__free(ctx, t->nodes);
        sfb__free(ctx, t->items);
    }
    memset(t, 0, sizeof *t);
}

/* ---- pairs ---- */

static int aabb_overlap(const sfb__aabb_node *p, const sfb__aabb_node *q, double eps) {
    int k;
    for (k = 0; k < 3; ++k)
        if (p->lo[k] - eps > q->hi[k] + eps || q->lo[k] - eps > p->hi[k] + eps) return 0;
    return 1;
}

/* The triangles of leaves p of a and q of b (p == q within one tree: each pair of it once). */
static int aabb_leaf_pairs(const sfb__aabb *a, const sfb__aabb *b, const sfb__aabb_node *p, const sfb__aabb_node *q, int self,
                           double eps, int (*fn)(int, int, void *), void *user) {
    int i, j;
    for (i = p->first; i < p->first + p->count; ++i) {
        const sfb__aabb_node *bi = &a->nodes[a->node_count + i];
        for (j = (p == q ? i + 1 : q->first); j < q->first + q->count; ++j) {
            if (self && a->items[i] == b->items[j]) continue;
            if (aabb_overlap(bi, &b->nodes[b->node_count + j], eps) && fn(a->items[i], b->items[j], user)) return 1;
        }
    }
    return 0;
}

int sfb__aabb_pairs(const sfb__aabb *a, const sfb__aabb *b, double eps, int (*fn)(int, int, void *), void *user) {
    int stack[2 * SFB__AABB_STACK], sp = 0;
    const int self = a == b;
    if (!a || !b || !fn || a->node_count == 0 || b->node_count == 0) return 0;
    if (!(eps >= 0.0)) eps = 0.0;
    stack[sp++] = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const int j = stack[--sp], i = stack[--sp];
        const sfb__aabb_node *P = &a->nodes[i], *Q = &b->nodes[j];
        if (self && i == j) {
            /* one subtree with itself: its children with themselves and with each other */
            if (P->left < 0) {
                if (aabb_leaf_pairs(a, b, P, P, 1, eps, fn, user)) return 1;
                continue;
            }
            stack[sp++] = P->left; stack[sp++] = P->right;
            stack[sp++] = P->right; stack[sp++] = P->right;
            stack[sp++] = P->left; stack[sp++] = P->left;
            continue;
        }
        if (!aabb_overlap(P, Q, eps)) continue;
        if (P->left < 0 && Q->left < 0) {
            if (aabb_leaf_pairs(a, b, P, Q, self, eps, fn, user)) return 1;
        } else if (P->left < 0 || (Q->left >= 0 && Q->count > P->count)) {
            stack[sp++] = i; stack[sp++] = Q->right;
            stack[sp++] = i; stack[sp++] = Q->left;
        } else {
            stack[sp++] = P->right; stack[sp++] = j;
            stack[sp++] = P->left; stack[sp++] = j;
        }
    }
    return 0;
}

/* ---- nearest point ---- */

static double aabb_box_dist2(const sfb__aabb_node *n, const double *p) {
    double d = 0.0;
    int k;
    for (k = 0; k < 3; ++k) {
        const double e = p[k] < n->lo[k] ? n->lo[k] - p[k] : p[k] > n->hi[k] ? p[k] - n->hi[k] : 0.0;
        d += e * e;
    }
    return d;
}

int sfb__aabb_nearest(const sfb__aabb *t, const double *pos, const int *tri, const int *tri_of_id, const double p[3],
                      double out_point[3], double *out_dist2, double out_bary[3]) {
    int stack[SFB__AABB_STACK], sp = 0, best = -1, k;
    double bestd = HUGE_VAL, bq[3] = {0, 0, 0}, bb[3] = {0, 0, 0};
    if (t && t->node_count > 0 && pos && tri && p && aabb_finite3(p)) {
        stack[sp++] = 0;
        while (sp > 0) {
            const sfb__aabb_node *n = &t->nodes[stack[--sp]];
            if (aabb_box_dist2(n, p) >= bestd) continue;
            if (n->left < 0) {
                int i;
                for (i = n->first; i < n->first + n->count; ++i) {
                    const int id = t->items[i], row = tri_of_id ? tri_of_id[id] : id;
                    const int *v = tri + 3 * (size_t)row;
                    double q[3], bc[3], d[3], d2;
                    sfb__closest_on_triangle(p, pos + 3 * (size_t)v[0], pos + 3 * (size_t)v[1], pos + 3 * (size_t)v[2], q, bc);
                    aabb_sub3(q, p, d);
                    d2 = aabb_dot3(d, d);
                    if (d2 < bestd) {
                        bestd = d2;
                        best = id;
                        memcpy(bq, q, sizeof q);
                        memcpy(bb, bc, sizeof bc);
                    }
                }
            } else {
                const double dl = aabb_box_dist2(&t->nodes[n->left], p), dr = aabb_box_dist2(&t->nodes[n->right], p);
                /* the nearer child is searched first: pushed last */
                if (dl <= dr) {
                    if (dr < bestd) stack[sp++] = n->right;
                    if (dl < bestd) stack[sp++] = n->left;
                } else {
                    if (dl < bestd) stack[sp++] = n->left;
                    if (dr < bestd) stack[sp++] = n->right;
                }
            }
        }
    }
    if (out_point)
        for (k = 0; k < 3; ++k) out_point[k] = bq[k];
    if (out_dist2) *out_dist2 = bestd;
    if (out_bary)
        for (k = 0; k < 3; ++k) out_bary[k] = bb[k];
    return best;
}

/* ---- closest point on a triangle ---- */

/* The point of segment u-v nearest p, at u + s (v - u). */
static double aabb_closest_on_segment(const double *p, const double *u, const double *v, double *q) {
    double e[3], w[3], s, l2;
    aabb_sub3(v, u, e);
    aabb_sub3(p, u, w);
    l2 = aabb_dot3(e, e);
    s = l2 > 0.0 ? aabb_dot3(w, e) / l2 : 0.0;
    s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
    q[0] = u[0] + s * e[0];
    q[1] = u[1] + s * e[1];
    q[2] = u[2] + s * e[2];
    return s;
}

void sfb__closest_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3], double q[3],
                              double bary[3]) {
    double ab[3], ac[3], bc[3], ap[3], bp[3], cp[3], n[3], w[3] = {0, 0, 0};
    double lab, lac, lbc, lmax, d1, d2, d3, d4, d5, d6, va, vb, vc;
    int k;
    aabb_sub3(b, a, ab);
    aabb_sub3(c, a, ac);
    aabb_sub3(c, b, bc);
    aabb_cross3(ab, ac, n);
    lab = aabb_dot3(ab, ab);
    lac = aabb_dot3(ac, ac);
    lbc = aabb_dot3(bc, bc);
    lmax = lab > lac ? (lab > lbc ? lab : lbc) : (lac > lbc ? lac : lbc);
    if (!(aabb_dot3(n, n) > SFB__TT_AREA * SFB__TT_AREA * lmax * lmax)) {
        /* degenerate: the longest edge */
        double s;
        if (lmax == lab) { s = aabb_closest_on_segment(p, a, b, q); w[0] = 1.0 - s; w[1] = s; }
        else if (lmax == lac) { s = aabb_closest_on_segment(p, a, c, q); w[0] = 1.0 - s; w[2] = s; }
        else { s = aabb_closest_on_segment(p, b, c, q); w[1] = 1.0 - s; w[2] = s; }
        if (bary) memcpy(bary, w, sizeof w);
        return;
    }
    /* p's Voronoi region: the corners, then the edges, else the face. d1..d6 are the projections
     * of p - corner on the two edges from a; va, vb, vc are (up to a common factor) the
     * barycentric coordinates of p's projection on the plane. */
    aabb_sub3(p, a, ap);
    d1 = aabb_dot3(ab, ap);
    d2 = aabb_dot3(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) { w[0] = 1.0; goto out; }
    aabb_sub3(p, b, bp);
    d3 = aabb_dot3(ab, bp);
    d4 = aabb_dot3(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) { w[1] = 1.0; goto out; }
    vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double s = d1 / (d1 - d3);
        w[0] = 1.0 - s; w[1] = s;
        goto out;
    }
    aabb_sub3(p, c, cp);
    d5 = aabb_dot3(ab, cp);
    d6 = aabb_dot3(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) { w[2] = 1.0; goto out; }
    vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double s = d2 / (d2 - d6);
        w[0] = 1.0 - s; w[2] = s;
        goto out;
    }
    va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w[1] = 1.0 - s; w[2] = s;
        goto out;
    }
    {
        const double inv = 1.0 / (va + vb + vc);
        w[1] = vb * inv;
        w[2] = vc * inv;
        w[0] = 1.0 - w[1] - w[2];
    }
out:
    for (k = 0; k < 3; ++k) q[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
    if (bary) memcpy(bary, w, sizeof w);
}

/* ---- triangle-triangle intersection ---- */

/* The points where triangle V (signed distances d to the other plane, snapped: exact zeros are
 * on it) meets that plane: 1 (a vertex touching it) or 2, with the edge each lies on (off + k
 * for edge k; a vertex names an edge from it, the edge between them when two vertices are on the
 * plane). */
static int tt_plane_points(const double *const V[3], const double d[3], int off, double P[2][3], int src[2]) {
    int k, n = 0;
    for (k = 0; k < 3; ++k) {
        const int k1 = (k + 1) % 3;
        if (d[k] == 0.0 && d[k1] == 0.0) {
            memcpy(P[0], V[k], 3 * sizeof(double));
            memcpy(P[1], V[k1], 3 * sizeof(double));
            src[0] = src[1] = off + k;
            return 2;
        }
    }
    for (k = 0; k < 3 && n < 2; ++k)
        if (d[k] == 0.0) {
            memcpy(P[n], V[k], 3 * sizeof(double));
            src[n++] = off + k;
        }
    for (k = 0; k < 3 && n < 2; ++k) {
        const int k1 = (k + 1) % 3;
        if ((d[k] > 0.0 && d[k1] < 0.0) || (d[k] < 0.0 && d[k1] > 0.0)) {
            const double s = d[k] / (d[k] - d[k1]);
            int c;
            for (c = 0; c < 3; ++c) P[n][c] = V[k][c] + s * (V[k1][c] - V[k][c]);
            src[n++] = off + k;
        }
    }
    return n;
}

/* Do coplanar triangles A and B (in the plane of unit normal n) meet, touching included? Their
 * projections on the coordinate plane across n's largest component, separated by none of the six
 * edge normals (separating axes of two convex polygons) by more than tol along it. */
static int tt_coplanar_meet(const double *const A[3], const double *const B[3], const double *n, double tol) {
    const double ax = fabs(n[0]), ay = fabs(n[1]), az = fabs(n[2]);
    const int i0 = ax >= ay && ax >= az ? 1 : 0, i1 = ax >= ay && ax >= az ? 2 : ay >= az ? 2 : 1;
    double P[6][2];
    int e, k;
    for (k = 0; k < 3; ++k) {
        P[k][0] = A[k][i0]; P[k][1] = A[k][i1];
        P[3 + k][0] = B[k][i0]; P[3 + k][1] = B[k][i1];
    }
    for (e = 0; e < 6; ++e) {
        const double *p = P[e], *q = P[e < 3 ? (e + 1) % 3 : 3 + (e - 2) % 3];
        const double nx = -(q[1] - p[1]), ny = q[0] - p[0], len = sqrt(nx * nx + ny * ny);
        double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
        if (!(len > 0.0)) continue;
        for (k = 0; k < 6; ++k) {
            const double x = (nx * P[k][0] + ny * P[k][1]) / len;
            const int s = k / 3;
            if (x < lo[s]) lo[s] = x;
            if (x > hi[s]) hi[s] = x;
        }
        if (lo[1] > hi[0] + tol || lo[0] > hi[1] + tol) return 0;
    }
    return 1;
}

/* Longest squared edge of triangle V; n gets its (unnormalised) normal. */
static double tt_setup(const double *const V[3], double *n) {
    double e0[3], e1[3], e2[3], l0, l1, l2;
    aabb_sub3(V[1], V[0], e0);
    aabb_sub3(V[2], V[0], e1);
    aabb_sub3(V[2], V[1], e2);
    aabb_cross3(e0, e1, n);
    l0 = aabb_dot3(e0, e0);
    l1 = aabb_dot3(e1, e1);
    l2 = aabb_dot3(e2, e2);
    return l0 > l1 ? (l0 > l2 ? l0 : l2) : (l1 > l2 ? l1 : l2);
}

int sfb__tri_tri_segment(const double a0[3], const double a1[3], const double a2[3], const double b0[3], const double b1[3],
                         const double b2[3], double s0[3], double s1[3], int *src0, int *src1) {
    const double *const A[3] = {a0, a1, a2}, *const B[3] = {b0, b1, b2};
    double na[3], nb[3], la2, lb2, lna, lnb, s, eps, da[3], db[3], D[3], lD;
    double PA[2][3], PB[2][3], ta[2], tb[2], lo, hi;
    int sa[2], sb[2], k, pos_a = 0, neg_a = 0, pos_b = 0, neg_b = 0, nA, nB;
    const double *plo, *phi;
    int slo, shi;
    for (k = 0; k < 3; ++k)
        if (!aabb_finite3(A[k]) || !aabb_finite3(B[k])) return 0;
    la2 = tt_setup(A, na);
    lb2 = tt_setup(B, nb);
    lna = sqrt(aabb_dot3(na, na));
    lnb = sqrt(aabb_dot3(nb, nb));
    if (!(lna > SFB__TT_AREA * la2) || !(lnb > SFB__TT_AREA * lb2)) return 0; /* zero area */
    s = sqrt(la2 > lb2 ? la2 : lb2);
    eps = SFB__TT_DIST * s;
    for (k = 0; k < 3; ++k) {
        na[k] /= lna;
        nb[k] /= lnb;
    }
    /* signed distances of each triangle's vertices to the other's plane, near zeros made zero */
    for (k = 0; k < 3; ++k) {
        double w[3];
        aabb_sub3(A[k], b0, w);
        da[k] = aabb_dot3(nb, w);
        if (fabs(da[k]) <= eps) da[k] = 0.0;
        pos_a += da[k] > 0.0;
        neg_a += da[k] < 0.0;
        aabb_sub3(B[k], a0, w);
        db[k] = aabb_dot3(na, w);
        if (fabs(db[k]) <= eps) db[k] = 0.0;
        pos_b += db[k] > 0.0;
        neg_b += db[k] < 0.0;
    }
    if (pos_a == 3 || neg_a == 3 || pos_b == 3 || neg_b == 3) return 0;
    aabb_cross3(na, nb, D);
    lD = sqrt(aabb_dot3(D, D));
    if (pos_a + neg_a == 0 || pos_b + neg_b == 0 || !(lD > 1e-15))
        return tt_coplanar_meet(A, B, pos_a + neg_a == 0 ? nb : na, eps) ? 2 : 0;
    for (k = 0; k < 3; ++k) D[k] /= lD;
    /* each triangle's piece of the line where the planes meet, as an interval along D */
    nA = tt_plane_points(A, da, 0, PA, sa);
    nB = tt_plane_points(B, db, 3, PB, sb);
    if (nA < 1 || nB < 1) return 0; /* cannot happen with the signs above */
    if (nA == 1) { memcpy(PA[1], PA[0], sizeof PA[0]); sa[1] = sa[0]; }
    if (nB == 1) { memcpy(PB[1], PB[0], sizeof PB[0]); sb[1] = sb[0]; }
    for (k = 0; k < 2; ++k) {
        ta[k] = aabb_dot3(D, PA[k]);
        tb[k] = aabb_dot3(D, PB[k]);
    }
    if (ta[1] < ta[0]) {
        double x = ta[0], tmp[3];
        int si = sa[0];
        ta[0] = ta[1]; ta[1] = x;
        sa[0] = sa[1]; sa[1] = si;
        memcpy(tmp, PA[0], sizeof tmp); memcpy(PA[0], PA[1], sizeof tmp); memcpy(PA[1], tmp, sizeof tmp);
    }
    if (tb[1] < tb[0]) {
        double x = tb[0], tmp[3];
        int si = sb[0];
        tb[0] = tb[1]; tb[1] = x;
        sb[0] = sb[1]; sb[1] = si;
        memcpy(tmp, PB[0], sizeof tmp); memcpy(PB[0], PB[1], sizeof tmp); memcpy(PB[1], tmp, sizeof tmp);
    }
    /* the overlap: each end is the inner of the two, a's on a tie */
    if (ta[0] >= tb[0]) { lo = ta[0]; plo = PA[0]; slo = sa[0]; }
    else { lo = tb[0]; plo = PB[0]; slo = sb[0]; }
    if (ta[1] <= tb[1]) { hi = ta[1]; phi = PA[1]; shi = sa[1]; }
    else { hi = tb[1]; phi = PB[1]; shi = sb[1]; }
    if (lo > hi + eps) return 0;
    if (lo > hi) { phi = plo; shi = slo; } /* touching within the tolerance: one point */
    if (s0) memcpy(s0, plo, 3 * sizeof(double));
    if (s1) memcpy(s1, phi, 3 * sizeof(double));
    if (src0) *src0 = slo;
    if (src1) *src1 = shi;
    return 1;
}

/* ---- a mesh's self-intersections ---- */

typedef struct sfb__aabb_self {
    const double *pos;
    const int *tri;
    long pairs;
    int first[2];
} sfb__aabb_self;

/* In the plane of unit normal n: does the corner of triangle (v, p0, p1) at v overlap that of
 * (v, q0, q1) in more than v (a ray of one inside the other's closed wedge, touching included)? */
static int self_wedges_meet(const double *n, const double *v, const double *p0, const double *p1, const double *q0,
                            const double *q1) {
    double r[4][3], c[3];
    int w, k;
    aabb_sub3(p0, v, r[0]);
    aabb_sub3(p1, v, r[1]);
    aabb_sub3(q0, v, r[2]);
    aabb_sub3(q1, v, r[3]);
    for (k = 0; k < 4; ++k) {
        const double l = sqrt(aabb_dot3(r[k], r[k]));
        if (!(l > 0.0)) return 1;
        r[k][0] /= l; r[k][1] /= l; r[k][2] /= l;
    }
    /* orient both wedges counter-clockwise about n */
    for (w = 0; w < 4; w += 2) {
        aabb_cross3(r[w], r[w + 1], c);
        if (aabb_dot3(c, n) < 0.0)
            for (k = 0; k < 3; ++k) {
                const double x = r[w][k];
                r[w][k] = r[w + 1][k];
                r[w + 1][k] = x;
            }
    }
    for (w = 0; w < 4; ++w) {
        const double *e0 = r[w < 2 ? 2 : 0], *e1 = r[w < 2 ? 3 : 1];
        double c0[3], c1[3];
        aabb_cross3(e0, r[w], c0);
        aabb_cross3(r[w], e1, c1);
        if (aabb_dot3(c0, n) >= -SFB__SELF_LEN && aabb_dot3(c1, n) >= -SFB__SELF_LEN) return 1;
    }
    return 0;
}

static int self_pair_cb(int i, int j, void *user) {
    sfb__aabb_self *S = (sfb__aabb_self *)user;
    const int *a = S->tri + 3 * (size_t)i, *b = S->tri + 3 * (size_t)j;
    const double *A[3], *B[3];
    double s0[3], s1[3];
    int shared = 0, ia = -1, ib = -1, ja = -1, jb = -1, k, l, r, hit = 0;
    for (k = 0; k < 3; ++k) {
        A[k] = S->pos + 3 * (size_t)a[k];
        B[k] = S->pos + 3 * (size_t)b[k];
    }
    r = sfb__tri_tri_segment(A[0], A[1], A[2], B[0], B[1], B[2], s0, s1, NULL, NULL);
    if (r == 0) return 0;
    /* both have an area, so each one's three indices differ */
    for (k = 0; k < 3; ++k)
        for (l = 0; l < 3; ++l)
            if (a[k] == b[l]) {
                if (shared == 0) { ia = k; ib = l; } else { ja = k; jb = l; }
                shared++;
            }
    if (shared == 0 || shared >= 3) hit = 1;
    else if (shared == 1) {
        if (r == 1) {
            /* they meet in a segment through the shared vertex: more than it when it has a length */
            double d[3], e[3], sc = 0.0;
            for (k = 0; k < 3; ++k) {
                aabb_sub3(A[(k + 1) % 3], A[k], e);
                if (aabb_dot3(e, e) > sc) sc = aabb_dot3(e, e);
                aabb_sub3(B[(k + 1) % 3], B[k], e);
                if (aabb_dot3(e, e) > sc) sc = aabb_dot3(e, e);
            }
            aabb_sub3(s1, s0, d);
            hit = sqrt(aabb_dot3(d, d)) > SFB__SELF_LEN * sqrt(sc);
        } else {
            double n[3], e0[3], e1[3];
            aabb_sub3(A[1], A[0], e0);
            aabb_sub3(A[2], A[0], e1);
            aabb_cross3(e0, e1, n);
            hit = self_wedges_meet(n, A[ia], A[(ia + 1) % 3], A[(ia + 2) % 3], B[(ib + 1) % 3], B[(ib + 2) % 3]);
        }
    } else {
        /* an edge in common: coplanar with the third vertices on the same side of it */
        if (r == 2) {
            const int pa = 3 - ia - ja, pb = 3 - ib - jb;
            double e[3], u[3], w[3], cu[3], cw[3];
            aabb_sub3(A[ja], A[ia], e);
            aabb_sub3(A[pa], A[ia], u);
            aabb_sub3(B[pb], A[ia], w);
            aabb_cross3(e, u, cu);
            aabb_cross3(e, w, cw);
            hit = aabb_dot3(cu, cw) > 0.0;
        }
    }
    if (hit) {
        if (S->pairs == 0) {
            S->first[0] = i < j ? i : j;
            S->first[1] = i < j ? j : i;
        }
        S->pairs++;
    }
    return 0;
}

sfb_result sfb__trimesh_self_intersections(sfb_context *ctx, const double *pos, const int *tri, int count, long *pairs,
                                           int first[2]) {
    sfb__aabb t;
    sfb__aabb_self S;
    sfb_result r;
    double diag = 0.0;
    int k;
    if (first) first[0] = first[1] = -1;
    if (pairs) *pairs = 0;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!pairs || count < 0 || (count > 0 && (!pos || !tri)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb__trimesh_self_intersections: bad arguments");
    r = sfb__aabb_build(ctx, pos, tri, NULL, count, &t);
    if (r != SFB_SUCCESS) return r;
    S.pos = pos;
    S.tri = tri;
    S.pairs = 0;
    S.first[0] = S.first[1] = -1;
    if (t.node_count > 0) {
        for (k = 0; k < 3; ++k) diag += (t.nodes[0].hi[k] - t.nodes[0].lo[k]) * (t.nodes[0].hi[k] - t.nodes[0].lo[k]);
        sfb__aabb_pairs(&t, &t, SFB__TT_DIST * sqrt(diag), self_pair_cb, &S);
    }
    sfb__aabb_free(ctx, &t);
    *pairs = S.pairs;
    if (first) {
        first[0] = S.first[0];
        first[1] = S.first[1];
    }
    return SFB_SUCCESS;
}
