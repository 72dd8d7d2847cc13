/* Patch tables for exact limit evaluation (Catmull-Clark), built by feature-adaptive
 * isolation, and the ref kernel that evaluates them.
 *
 * Parametric faces ("param faces", as OpenSubdiv's ptex faces): a base quad is one, with
 * (u,v) = (0,0) at its first vertex, (1,0) at the second, (0,1) at the last; an n-gon (n != 4)
 * is n of them, sub-face i being the quad (v_i, mid(v_i,v_i+1), centroid, mid(v_i-1,v_i)) of the
 * first Catmull-Clark step, in that corner order.
 *
 * Isolation. Level 0 is the prepared base mesh. A quad face becomes a patch when
 * - all four corners are regular for it: smooth valence 4 with no sharp edge (R1), a crease
 *   vertex with two infinitely sharp edges and two faces on this face's side (R2), or a corner
 *   (infinitely sharp) alone in its sector (R3) -> BSPLINE16, missing points mirrored
 *   (phantoms) across the crease/boundary, which is exact: the crease is then the uniform
 *   cubic B-spline of its vertices, as the crease rules make it;
 * - one corner is a smooth extraordinary vertex with no sharp edge (valence 3..256) and the
 *   other three are R1 -> STAM (eigen form, stam.c);
 * - otherwise it is refined: the next level is built only for these faces and the faces
 *   around them (the 1-ring whose vertices the masks read), and its children are classified
 *   in turn. Semi-sharp sharpness decays by one per level, so after ceil(s) levels the region
 *   is smooth and becomes exact patches.
 * At the isolation limit (default 8; semi-sharp features continue until smooth, at most
 * SFB_MAX_LEVEL + 1) a face that is still irregular (a crease or corner vertex with an
 * extraordinary sector, a dart, a non-manifold vertex) gets the END CAP: the bilinear patch
 * through the limit positions of its four corners, with normals blended from the corners'
 * limit normals (exact at the corners; oriented as the cap). Its distance to the limit surface is O(h^2) with
 * h = 2^-limit of the base face (measured by tests/limit.c and quoted in the README).
 * Holes produce no patches. */

enum { SFB__CORNER_R1 = 1, SFB__CORNER_R2_D1 = 2, SFB__CORNER_R2_D2 = 3, SFB__CORNER_R3 = 4, SFB__CORNER_EV = 5,
       SFB__CORNER_IRREGULAR = 0 };


void sfb__patch_table_free(sfb_context *ctx, sfb__patch_table *pt) {
    sfb__free(ctx, pt->ptype); sfb__free(ctx, pt->pfirst); sfb__free(ctx, pt->pparam); sfb__free(ctx, pt->pvalence);
    sfb__free(ctx, pt->cv); sfb__free(ctx, pt->ptex_face); sfb__free(ctx, pt->ptex_corner); sfb__free(ctx, pt->face_ptex);
    sfb__free(ctx, pt->ptex_root); sfb__free(ctx, pt->nodes); sfb__free(ctx, pt->point_data); sfb__free(ctx, pt->pcorner);
    memset(pt, 0, sizeof *pt);
}

/* Triangle param faces (Loop). A triangle's (u,v) is barycentric: the point is
 * (1-u-v) P0 + u P1 + v P2 for its corners in face order. One Loop step splits it into four
 * children, numbered like quadrants of a quadtree node (x + 2y bits of the param code):
 * 0 the corner at P0, (2u, 2v); 1 the corner at P1, (2u-1, 2v); 2 the corner at P2,
 * (2u, 2v-1); 3 the middle, turned by 180 degrees: (1-2u, 1-2v), so its derivatives change
 * sign. The corner bits of the code give the face slot of the child's param corner 0. */

/* ---- builder state ---- */
typedef struct sfb__pbuild {
    sfb_context *ctx;
    sfb__patch_table *pt;
    int cap_patch, cap_cv, cap_nodes;
    sfb__rows prow;          /* patch point rows over base vertices */
    size_t cap_rows;
    sfb__accum A;
    sfb__mask m;
    int *vrow;               /* point row of each vertex of the working level, -1 if none yet */
} sfb__pbuild;

static int sfb__pb_grow_int(sfb_context *ctx, int **a, int *cap, int need) {
    int nc;
    int *n;
    if (need <= *cap) return 1;
    nc = *cap ? *cap : 256;
    while (nc < need) nc *= 2;
    n = (int *)sfb__realloc(ctx, *a, (size_t)nc * sizeof(int));
    if (!n) return 0;
    *a = n;
    *cap = nc;
    return 1;
}

/* Adds a point row = mask over working-level vertices composed with their rows. A single
 * vertex with weight 1 is shared through vrow. Returns the row or -1 on allocation failure. */
static int sfb__pb_point(sfb__pbuild *b, const sfb__rows *wrows, const sfb__mask *m) {
    int row;
    if (m->n == 1 && m->w[0] == 1.0 && b->vrow[m->idx[0]] >= 0) return b->vrow[m->idx[0]];
    row = b->prow.rows;
    if ((size_t)row + 2 > b->cap_rows) {
        size_t nc = b->cap_rows ? b->cap_rows * 2 : 1024;
        size_t *no = (size_t *)sfb__realloc(b->ctx, b->prow.off, nc * sizeof(size_t));
        if (!no) return -1;
        b->prow.off = no;
        b->cap_rows = nc;
        if (row == 0) b->prow.off[0] = 0;
    }
    if (!sfb__compose_row(b->ctx, &b->A, wrows, m, &b->prow, row)) return -1;
    b->prow.rows = row + 1;
    if (m->n == 1 && m->w[0] == 1.0) b->vrow[m->idx[0]] = row;
    return row;
}

/* ---- corner classification ---- */
static int sfb__is_inf(float s) { return s >= SFB_SHARPNESS_INFINITE; }

/* Fan position of face g (corner slot `slot`) around vertex v, or -1. */
static int sfb__fan_pos(const sfb__level *l, int v, int g, int slot) {
    int i;
    for (i = l->vf_off[v]; i < l->vf_off[v + 1]; ++i)
        if (l->vf[i] == g && l->vf_slot[i] == slot) return i - l->vf_off[v];
    return -1;
}

static int sfb__face_n(const sfb__level *l, int f) { return l->fv_off[f + 1] - l->fv_off[f]; }

/* Class of vertex v as a corner of quad g; *pos = g's fan position. */
static int sfb__corner_class(const sfb__level *l, int v, int g, int slot, int *pos) {
    int nF = l->vf_off[v + 1] - l->vf_off[v], nE = l->ve_off[v + 1] - l->ve_off[v];
    int e0 = l->ve_off[v], f0 = l->vf_off[v];
    int p = sfb__fan_pos(l, v, g, slot), i, nsharp = 0, ninf = 0, cyclic = nE == nF;
    int rule = l->vrule[v];
    float vs = l->vs[v];
    *pos = p;
    if (p < 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD)) return SFB__CORNER_IRREGULAR;
    for (i = 0; i < nE; ++i) {
        float s = l->es[l->ve[e0 + i]];
        nsharp += s > 0.0f;
        ninf += sfb__is_inf(s);
    }
    if (rule == SFB__RULE_SMOOTH && vs == 0.0f && nsharp == 0 && cyclic) {
        for (i = 0; i < nF; ++i)
            if (sfb__face_n(l, l->vf[f0 + i]) != 4) return SFB__CORNER_IRREGULAR;
        return nF == 4 ? SFB__CORNER_R1 : (nF >= 3 ? SFB__CORNER_EV : SFB__CORNER_IRREGULAR);
    }
    if (rule == SFB__RULE_CREASE && vs == 0.0f && nsharp == 2 && ninf == 2) {
        /* the sector of g: faces reachable without crossing a sharp edge */
        int e_d1 = l->ve[e0 + p], e_d2 = l->ve[e0 + (p + 1) % nE];
        if (!cyclic && p + 1 >= nE) return SFB__CORNER_IRREGULAR;
        if (sfb__face_n(l, g) != 4) return SFB__CORNER_IRREGULAR;
        if (sfb__is_inf(l->es[e_d1]) && !sfb__is_inf(l->es[e_d2])) {
            /* sector {g, next}: next face exists, is a quad, and the edge after it is sharp */
            int q = p + 1, e_next;
            if (q >= nF && !cyclic) return SFB__CORNER_IRREGULAR;
            q %= nF;
            e_next = l->ve[e0 + (p + 2) % nE];
            if (!cyclic && p + 2 >= nE) return SFB__CORNER_IRREGULAR;
            if (sfb__face_n(l, l->vf[f0 + q]) != 4 || !sfb__is_inf(l->es[e_next])) return SFB__CORNER_IRREGULAR;
            return SFB__CORNER_R2_D1; /* crease along d1 / -d1: phantoms at b = -1 */
        }
        if (!sfb__is_inf(l->es[e_d1]) && sfb__is_inf(l->es[e_d2])) {
            int q = p - 1, e_prev;
            if (q < 0 && !cyclic) return SFB__CORNER_IRREGULAR;
            q = (q + nF) % nF;
            e_prev = l->ve[e0 + (p - 1 + nE) % nE];
            if (!cyclic && p - 1 < 0) return SFB__CORNER_IRREGULAR;
            if (sfb__face_n(l, l->vf[f0 + q]) != 4 || !sfb__is_inf(l->es[e_prev])) return SFB__CORNER_IRREGULAR;
            return SFB__CORNER_R2_D2; /* crease along d2 / -d2: phantoms at a = -1 */
        }
        return SFB__CORNER_IRREGULAR;
    }
    if (rule == SFB__RULE_CORNER && (vs == 0.0f || sfb__is_inf(vs)) && nsharp == ninf) {
        int e_d1 = l->ve[e0 + p];
        int e_d2;
        if (!cyclic && p + 1 >= nE) return SFB__CORNER_IRREGULAR;
        e_d2 = l->ve[e0 + (p + 1) % nE];
        if (sfb__face_n(l, g) == 4 && sfb__is_inf(l->es[e_d1]) && sfb__is_inf(l->es[e_d2])) return SFB__CORNER_R3;
    }
    return SFB__CORNER_IRREGULAR;
}

/* Does anything at g's corners still have to decay (semi-sharp edge or vertex)? */
static int sfb__face_semisharp(const sfb__level *l, int g) {
    int k, i;
    for (k = l->fv_off[g]; k < l->fv_off[g + 1]; ++k) {
        int v = l->fv[k];
        if (l->vs[v] > 0.0f && !sfb__is_inf(l->vs[v])) return 1;
        for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i) {
            float s = l->es[l->ve[i]];
            if (s > 0.0f && !sfb__is_inf(s)) return 1;
        }
    }
    return 0;
}

/* ---- gathering ---- */
/* A grid cell's mask: up to 4 (vertex, weight) terms. */
typedef struct sfb__cell { int n, real; int v[4]; double w[4]; } sfb__cell;

static const int sfb__corner_pos[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
static const int sfb__corner_d1[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
static const int sfb__corner_d2[4][2] = {{0, 1}, {-1, 0}, {0, -1}, {1, 0}};

static int sfb__diag(const sfb__level *l, int f, int v) {
    int o = l->fv_off[f], k;
    for (k = 0; k < 4; ++k)
        if (l->fv[o + k] == v) return l->fv[o + (k + 2) % 4];
    return -1;
}

/* The real points around corner vertex v (fan position p of g): local (a,b) -> vertex, for
 * the quadrants present (mask bit q: 0 = (+,+) g, 1 = (-,+), 2 = (-,-), 3 = (+,-)). */
static void sfb__corner_ring(const sfb__level *l, int v, int p, unsigned quads, int out[3][3]) {
    int e0 = l->ve_off[v], f0 = l->vf_off[v], nE = l->ve_off[v + 1] - e0, nF = l->vf_off[v + 1] - f0;
    int a, b;
#define SFB__EDGE(k) sfb__other_end(l, l->ve[e0 + ((p + (k)) % nE + nE) % nE], v)
#define SFB__FACE(k) l->vf[f0 + ((p + (k)) % nF + nF) % nF]
    for (a = 0; a < 3; ++a)
        for (b = 0; b < 3; ++b) out[a][b] = -1;
    out[1][1] = v;
    /* quadrant 0 (g) always: edges d1 (k=0) and d2 (k=1) */
    out[2][1] = SFB__EDGE(0);
    out[1][2] = SFB__EDGE(1);
    out[2][2] = sfb__diag(l, SFB__FACE(0), v);
    if (quads & 2u) { out[0][1] = SFB__EDGE(2); out[0][2] = sfb__diag(l, SFB__FACE(1), v); }
    if (quads & 4u) { out[0][1] = SFB__EDGE(2); out[1][0] = SFB__EDGE(3); out[0][0] = sfb__diag(l, SFB__FACE(2), v); }
    if (quads & 8u) { out[1][0] = SFB__EDGE(-1 + nE); out[2][0] = sfb__diag(l, SFB__FACE(-1 + nF), v); }
#undef SFB__EDGE
#undef SFB__FACE
}

/* Fills the 4x4 grid (cells x,y in -1..2 -> [y+1][x+1]) of quad g in the frame whose corner 0
 * is slot `rot`, for corners whose class is given (R1/R2/R3; skip = corner not gathered, for
 * the EV of a Stam patch). Returns 0 when the corners disagree. */
static int sfb__gather(const sfb__level *l, int g, int rot, const int cls[4], const int pos[4], int skip, sfb__cell grid[4][4]) {
    int k, a, b, x, y;
    for (y = 0; y < 4; ++y)
        for (x = 0; x < 4; ++x) grid[y][x].n = 0, grid[y][x].real = 0;
    /* real points first */
    for (k = 0; k < 4; ++k) {
        int ring[3][3], v;
        unsigned quads;
        if (k == skip) continue;
        v = l->fv[l->fv_off[g] + (rot + k) % 4];
        quads = cls[k] == SFB__CORNER_R1 ? 15u : cls[k] == SFB__CORNER_R2_D1 ? 3u : cls[k] == SFB__CORNER_R2_D2 ? 9u : 1u;
        sfb__corner_ring(l, v, pos[k], quads, ring);
        for (a = -1; a <= 1; ++a)
            for (b = -1; b <= 1; ++b) {
                int vv = ring[a + 1][b + 1];
                sfb__cell *c;
                if (vv < 0) continue;
                x = sfb__corner_pos[k][0] + a * sfb__corner_d1[k][0] + b * sfb__corner_d2[k][0];
                y = sfb__corner_pos[k][1] + a * sfb__corner_d1[k][1] + b * sfb__corner_d2[k][1];
                if (x < -1 || x > 2 || y < -1 || y > 2) continue;
                c = &grid[y + 1][x + 1];
                if (c->real && c->v[0] != vv) return 0;
                c->real = 1; c->n = 1; c->v[0] = vv; c->w[0] = 1.0;
            }
    }
    /* phantoms: mirror across the crease lines, corner by corner */
    for (k = 0; k < 4; ++k) {
        int pass;
        if (k == skip || cls[k] == SFB__CORNER_R1) continue;
        for (pass = 0; pass < 2; ++pass)
            for (a = -1; a <= 1; ++a)
                for (b = -1; b <= 1; ++b) {
                    int mirror_b = (cls[k] == SFB__CORNER_R2_D1 || cls[k] == SFB__CORNER_R3) && b == -1;
                    int mirror_a = (cls[k] == SFB__CORNER_R2_D2 || cls[k] == SFB__CORNER_R3) && a == -1;
                    int sa, sb, t;
                    sfb__cell *c, *p0, *p1;
                    /* pass 0: one mirrored index; pass 1: the (-1,-1) cell of R3 from pass-0 phantoms */
                    if (!(mirror_a || mirror_b) || (pass == 0) != !(mirror_a && mirror_b)) continue;
                    x = sfb__corner_pos[k][0] + a * sfb__corner_d1[k][0] + b * sfb__corner_d2[k][0];
                    y = sfb__corner_pos[k][1] + a * sfb__corner_d1[k][1] + b * sfb__corner_d2[k][1];
                    if (x < -1 || x > 2 || y < -1 || y > 2) continue;
                    c = &grid[y + 1][x + 1];
                    if (c->real) return 0;
                    if (c->n) continue;
                    /* P = 2 P(mirror line) - P(inside) along the mirrored direction */
                    if (mirror_b) { sa = a; sb = 0; }
                    else { sa = 0; sb = b; }
                    {
                        int x0 = sfb__corner_pos[k][0] + sa * sfb__corner_d1[k][0] + sb * sfb__corner_d2[k][0];
                        int y0 = sfb__corner_pos[k][1] + sa * sfb__corner_d1[k][1] + sb * sfb__corner_d2[k][1];
                        int ia = mirror_b ? a : 1, ib = mirror_b ? 1 : b;
                        int x1 = sfb__corner_pos[k][0] + ia * sfb__corner_d1[k][0] + ib * sfb__corner_d2[k][0];
                        int y1 = sfb__corner_pos[k][1] + ia * sfb__corner_d1[k][1] + ib * sfb__corner_d2[k][1];
                        p0 = &grid[y0 + 1][x0 + 1];
                        p1 = &grid[y1 + 1][x1 + 1];
                    }
                    if (!p0->n || !p1->n || p0->n + p1->n > 4) return 0;
                    c->n = 0;
                    for (t = 0; t < p0->n; ++t) { c->v[c->n] = p0->v[t]; c->w[c->n++] = 2.0 * p0->w[t]; }
                    for (t = 0; t < p1->n; ++t) { c->v[c->n] = p1->v[t]; c->w[c->n++] = -p1->w[t]; }
                }
    }
    return 1;
}

/* ---- the table ---- */
static int sfb__pb_patch(sfb__pbuild *b, int type, unsigned param, int valence, int ncv) {
    sfb__patch_table *pt = b->pt;
    int n = pt->npatch;
    if (n + 1 > b->cap_patch) {
        int nc = b->cap_patch ? b->cap_patch * 2 : 256;
        int *t1 = (int *)sfb__realloc(b->ctx, pt->ptype, (size_t)nc * sizeof(int));
        if (!t1) return -1;
        pt->ptype = t1;
        t1 = (int *)sfb__realloc(b->ctx, pt->pfirst, (size_t)(nc + 1) * sizeof(int));
        if (!t1) return -1;
        pt->pfirst = t1;
        t1 = (int *)sfb__realloc(b->ctx, pt->pvalence, (size_t)nc * sizeof(int));
        if (!t1) return -1;
        pt->pvalence = t1;
        {
            unsigned *t2 = (unsigned *)sfb__realloc(b->ctx, pt->pparam, (size_t)nc * sizeof(unsigned));
            if (!t2) return -1;
            pt->pparam = t2;
        }
        b->cap_patch = nc;
    }
    if (!sfb__pb_grow_int(b->ctx, &pt->cv, &b->cap_cv, pt->ncv + ncv)) return -1;
    pt->ptype[n] = type;
    pt->pfirst[n] = pt->ncv;
    pt->pparam[n] = param;
    pt->pvalence[n] = valence;
    pt->ncv += ncv;
    pt->pfirst[n + 1] = pt->ncv;
    pt->npatch = n + 1;
    pt->counts[type]++;
    return n;
}

/* Inserts patch `patch` (or -1 for a hole) at (ptex, depth, i, j) in the quadtree. */
static int sfb__pb_insert(sfb__pbuild *b, int ptex, unsigned param, int patch) {
    sfb__patch_table *pt = b->pt;
    int depth = SFB__PARAM_DEPTH(param), pi = SFB__PARAM_I(param), pj = SFB__PARAM_J(param);
    int *slot = &pt->ptex_root[ptex], d;
    for (d = 0; d < depth; ++d) {
        int qx = (pi >> (depth - 1 - d)) & 1, qy = (pj >> (depth - 1 - d)) & 1, node;
        if (*slot < 0) {
            /* a new internal node (its slot may only be empty: -1) */
            int k;
            ptrdiff_t off = slot - pt->nodes;
            int in_nodes = pt->nodes && slot >= pt->nodes && slot < pt->nodes + 4 * (size_t)pt->nnodes;
            if (!sfb__pb_grow_int(b->ctx, &pt->nodes, &b->cap_nodes, 4 * (pt->nnodes + 1))) return 0;
            if (in_nodes) slot = pt->nodes + off;
            node = pt->nnodes++;
            for (k = 0; k < 4; ++k) pt->nodes[4 * node + k] = -1;
            *slot = node;
        }
        node = *slot;
        slot = &pt->nodes[4 * node + qx + 2 * qy];
    }
    *slot = patch >= 0 ? -(patch + 2) : -1;
    return 1;
}

typedef struct sfb__wlevel {
    sfb__level l;
    sfb__rows rows;
    int *fptex;          /* param face of a candidate face, -1 otherwise */
    unsigned *fparam;    /* depth, i, j and rotation (in the corner bits) of candidates */
    unsigned char *vcomp, *ecomp;
    int owns_level;
} sfb__wlevel;

static void sfb__wlevel_free(sfb_context *ctx, sfb__wlevel *w) {
    if (w->owns_level) sfb__level_free(ctx, &w->l);
    sfb__rows_free(ctx, &w->rows);
    sfb__free(ctx, w->fptex); sfb__free(ctx, w->fparam); sfb__free(ctx, w->vcomp); sfb__free(ctx, w->ecomp);
    memset(w, 0, sizeof *w);
}

/* End cap of face g (n = 3 or 4 corners, frame corner 0 at slot rot): the limit positions of
 * the corners in frame order (points 0..n-1), then the two limit tangents of each corner
 * (points n + 2k, n + 2k + 1) for the normals. */
static sfb_result sfb__pb_endcap(sfb__pbuild *b, sfb__wlevel *w, int g, int rot, int n, unsigned param) {
    const sfb__level *l = &w->l;
    int base, k, patch;
    sfb__mask mp, m1, m2;
    sfb_result er = SFB_SUCCESS;
    patch = sfb__pb_patch(b, n == 4 ? SFB__PATCH_ENDCAP : SFB__PATCH_ENDCAP_TRI, param, 0, 3 * n);
    if (patch < 0) return sfb__oom(b->ctx, "patch table");
    memset(&mp, 0, sizeof mp); memset(&m1, 0, sizeof m1); memset(&m2, 0, sizeof m2);
    base = b->pt->pfirst[patch];
    for (k = 0; k < n && er == SFB_SUCCESS; ++k) {
        int v = l->fv[l->fv_off[g] + (rot + k) % n], r0, r1, r2, need = 3 * sfb__mask_need_vertex(l, v) + 8;
        if (!sfb__mask_grow(b->ctx, &mp, need) || !sfb__mask_grow(b->ctx, &m1, need) || !sfb__mask_grow(b->ctx, &m2, need)) {
            er = sfb__oom(b->ctx, "patch points");
            break;
        }
        sfb__limit_masks(l, v, n == 4 ? SFB_SCHEME_CATMARK : SFB_SCHEME_LOOP, &mp, &m1, &m2);
        r0 = sfb__pb_point(b, &w->rows, &mp);
        r1 = sfb__pb_point(b, &w->rows, &m1);
        r2 = sfb__pb_point(b, &w->rows, &m2);
        if (r0 < 0 || r1 < 0 || r2 < 0) er = sfb__oom(b->ctx, "patch points");
        b->pt->cv[base + k] = r0;
        b->pt->cv[base + n + 2 * k] = r1;
        b->pt->cv[base + n + 1 + 2 * k] = r2;
    }
    sfb__free(b->ctx, mp.idx); sfb__free(b->ctx, mp.w); sfb__free(b->ctx, m1.idx); sfb__free(b->ctx, m1.w);
    sfb__free(b->ctx, m2.idx); sfb__free(b->ctx, m2.w);
    if (er != SFB_SUCCESS) return er;
    return sfb__pb_insert(b, w->fptex[g], param, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
}

/* Classifies candidate g; adds its patch, or returns 1 in *refine. */
static sfb_result sfb__pb_face(sfb__pbuild *b, sfb__wlevel *w, int g, int level, int limit, int *refine) {
    const sfb__level *l = &w->l;
    unsigned par = w->fparam[g];
    int rot = SFB__PARAM_CORNER(par), ptex = w->fptex[g];
    int cls[4], pos[4], k, nev = 0, evk = -1, nirr = 0, patch;
    unsigned out_param;
    sfb__cell grid[4][4];
    *refine = 0;
    if (l->fhole[g]) return sfb__pb_insert(b, ptex, par & ~(3u << 30), -1) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    if (sfb__face_n(l, g) != 4) { *refine = 1; return SFB_SUCCESS; }
    for (k = 0; k < 4; ++k) {
        int slot = (rot + k) % 4, v = l->fv[l->fv_off[g] + slot];
        cls[k] = sfb__corner_class(l, v, g, slot, &pos[k]);
        if (cls[k] == SFB__CORNER_EV) { nev++; evk = k; }
        else if (cls[k] == SFB__CORNER_IRREGULAR) nirr++;
    }
    if (nirr == 0 && nev == 0 && sfb__gather(l, g, rot, cls, pos, -1, grid)) {
        int x, y, base;
        patch = sfb__pb_patch(b, SFB__PATCH_BSPLINE, par & ~(3u << 30), 0, 16);
        if (patch < 0) return sfb__oom(b->ctx, "patch table");
        base = b->pt->pfirst[patch];
        for (y = 0; y < 4; ++y)
            for (x = 0; x < 4; ++x) {
                sfb__cell *c = &grid[y][x];
                int t, row;
                b->m.n = 0;
                for (t = 0; t < c->n; ++t) SFB__MASK_ADD(&b->m, c->v[t], c->w[t]);
                row = sfb__pb_point(b, &w->rows, &b->m);
                if (row < 0) return sfb__oom(b->ctx, "patch points");
                b->pt->cv[base + 4 * y + x] = row;
            }
        return sfb__pb_insert(b, ptex, par & ~(3u << 30), patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    }
    if (nev == 1 && nirr == 0 && cls[(evk + 1) % 4] == SFB__CORNER_R1 && cls[(evk + 2) % 4] == SFB__CORNER_R1 &&
        cls[(evk + 3) % 4] == SFB__CORNER_R1) {
        int ev = l->fv[l->fv_off[g] + (rot + evk) % 4];
        int N = l->vf_off[ev + 1] - l->vf_off[ev];
        const sfb__eigen_cc *e = sfb__eigen_cc_get(b->ctx, N);
        int scls[4], spos[4];
        if (e) {
            /* gather in the Stam frame: corner 0 = the EV */
            for (k = 0; k < 4; ++k) { scls[k] = cls[(evk + k) % 4]; spos[k] = pos[(evk + k) % 4]; }
            if (sfb__gather(l, g, (rot + evk) % 4, scls, spos, 0, grid)) {
                int K = e->K, i, m, pE = spos[0], e0 = l->ve_off[ev], f0 = l->vf_off[ev], base;
                int *C = (int *)sfb__alloc(b->ctx, (size_t)K * sizeof(int));
                static const int outer[7][2] = {{2, 2}, {2, 1}, {2, 0}, {2, -1}, {1, 2}, {0, 2}, {-1, 2}};
                if (!C) return sfb__oom(b->ctx, "patch table");
                C[0] = ev;
                for (i = 1; i <= N; ++i) {
                    int re = ((pE + (3 - i)) % N + N) % N, rf = ((pE + (2 - i)) % N + N) % N;
                    C[2 * i - 1] = sfb__other_end(l, l->ve[e0 + re], ev);
                    C[2 * i] = sfb__diag(l, l->vf[f0 + rf], ev);
                }
                for (i = 0; i < 7; ++i) {
                    sfb__cell *c = &grid[outer[i][1] + 1][outer[i][0] + 1];
                    C[2 * N + 1 + i] = (c->real && c->n == 1) ? c->v[0] : -1;
                }
                for (i = 0; i < K; ++i)
                    if (C[i] < 0) { sfb__free(b->ctx, C); C = NULL; break; }
                if (C) {
                    out_param = SFB__PARAM(SFB__PARAM_DEPTH(par), SFB__PARAM_I(par), SFB__PARAM_J(par), evk);
                    patch = sfb__pb_patch(b, SFB__PATCH_STAM, out_param, N, K);
                    if (patch < 0 || !sfb__mask_grow(b->ctx, &b->m, K)) { sfb__free(b->ctx, C); return sfb__oom(b->ctx, "patch table"); }
                    base = b->pt->pfirst[patch];
                    b->pt->eig[N] = e; /* the context's cache outlives the surface */
                    for (i = 0; i < K; ++i) {
                        int row;
                        b->m.n = 0;
                        for (m = 0; m < K; ++m) {
                            double wgt = e->vinv[(size_t)i * K + m];
                            if (wgt != 0.0) SFB__MASK_ADD(&b->m, C[m], wgt);
                        }
                        row = sfb__pb_point(b, &w->rows, &b->m);
                        if (row < 0) { sfb__free(b->ctx, C); return sfb__oom(b->ctx, "patch points"); }
                        b->pt->cv[base + i] = row;
                    }
                    sfb__free(b->ctx, C);
                    return sfb__pb_insert(b, ptex, out_param, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
                }
            }
        }
    }
    if ((level >= limit && !sfb__face_semisharp(l, g)) || level >= SFB_MAX_LEVEL + 1)
        return sfb__pb_endcap(b, w, g, rot, 4, par & ~(3u << 30));
    *refine = 1;
    return SFB_SUCCESS;
}

/* ---- triangles (Loop) ----
 * A corner of a triangle is R1 (smooth valence 6, no sharp edge), EV (smooth, valence 3..256,
 * no sharp edge), R2 (a crease vertex, two infinitely sharp edges, whose sector on this face's
 * side has 3 triangles) or R3 (a corner whose sector is this triangle alone). In the lattice of
 * the regular triangulation the face's param corners are at (0,0), (1,0), (0,1); corner k's
 * ring, counter-clockwise from the next corner, runs along the lattice directions
 * sfb__hexdir[2k], [2k+1], ... Points missing across a crease are phantoms: X = A + B - C for
 * the real triangle (A,B,C) across the edge AB from X, and X = 2A - B opposite a real neighbour B
 * at a corner (the points that make the box spline's boundary the crease's cubic B-spline, as
 * for OpenSubdiv's regular Loop boundary patches). */
static const int sfb__hexdir[6][2] = {{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}};
static const int sfb__tri_origin[3][2] = {{0, 0}, {1, 0}, {0, 1}};

/* Class of vertex v as a corner of triangle g; *pos = g's fan position; *sec = offset (from
 * *pos) of the first edge of g's sector for R2 (-2..0), 0 for R3. */
static int sfb__tri_corner_class(const sfb__level *l, int v, int g, int slot, int *pos, int *sec) {
    int nF = l->vf_off[v + 1] - l->vf_off[v], nE = l->ve_off[v + 1] - l->ve_off[v];
    int e0 = l->ve_off[v], f0 = l->vf_off[v];
    int p = sfb__fan_pos(l, v, g, slot), i, nsharp = 0, ninf = 0, cyclic = nE == nF;
    int rule = l->vrule[v];
    float vs = l->vs[v];
    *pos = p;
    *sec = 0;
    if (p < 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD)) return SFB__CORNER_IRREGULAR;
    for (i = 0; i < nE; ++i) {
        float s = l->es[l->ve[e0 + i]];
        nsharp += s > 0.0f;
        ninf += sfb__is_inf(s);
    }
    if (rule == SFB__RULE_SMOOTH && vs == 0.0f && nsharp == 0 && cyclic) {
        for (i = 0; i < nF; ++i)
            if (sfb__face_n(l, l->vf[f0 + i]) != 3) return SFB__CORNER_IRREGULAR;
        return nF == 6 ? SFB__CORNER_R1 : (nF >= 3 ? SFB__CORNER_EV : SFB__CORNER_IRREGULAR);
    }
#define SFB__TE(k) l->es[l->ve[e0 + ((p + (k)) % nE + nE) % nE]]
#define SFB__TIN(k, n) (cyclic || (p + (k) >= 0 && p + (k) < (n)))
    if (rule == SFB__RULE_CREASE && vs == 0.0f && nsharp == 2 && ninf == 2) {
        int st;
        for (st = 0; st >= -2; --st) {
            if (!SFB__TIN(st, nE)) return SFB__CORNER_IRREGULAR;
            if (sfb__is_inf(SFB__TE(st))) break;
        }
        if (st < -2) return SFB__CORNER_IRREGULAR;
        for (i = 0; i < 3; ++i) {
            if (!SFB__TIN(st + i, nF) || sfb__face_n(l, l->vf[f0 + ((p + st + i) % nF + nF) % nF]) != 3) return SFB__CORNER_IRREGULAR;
            if (i > 0 && SFB__TE(st + i) > 0.0f) return SFB__CORNER_IRREGULAR;
        }
        if (!SFB__TIN(st + 3, nE) || !sfb__is_inf(SFB__TE(st + 3))) return SFB__CORNER_IRREGULAR;
        *sec = st;
        return SFB__CORNER_R2_D1;
    }
    if (rule == SFB__RULE_CORNER && (vs == 0.0f || sfb__is_inf(vs)) && nsharp == ninf) {
        if (!SFB__TIN(1, nE) || sfb__face_n(l, g) != 3) return SFB__CORNER_IRREGULAR;
        if (sfb__is_inf(SFB__TE(0)) && sfb__is_inf(SFB__TE(1))) return SFB__CORNER_R3;
    }
#undef SFB__TE
#undef SFB__TIN
    return SFB__CORNER_IRREGULAR;
}

/* Fills grid[y+1][x+1] (x, y in -1..3) with the box-spline points of triangle g in the frame
 * whose corner 0 is slot `rot`; corner `skip` (the EV of a Stam patch) is not gathered.
 * Returns 0 when the corners disagree. */
static int sfb__gather_tri(const sfb__level *l, int g, int rot, const int cls[3], const int pos[3], const int sec[3], int skip,
                           sfb__cell grid[5][5]) {
    int k, x, y;
    for (y = 0; y < 5; ++y)
        for (x = 0; x < 5; ++x) grid[y][x].n = 0, grid[y][x].real = 0;
#define SFB__CELL(d) grid[sfb__tri_origin[k][1] + sfb__hexdir[((2 * k + (d)) % 6 + 6) % 6][1] + 1] \
                         [sfb__tri_origin[k][0] + sfb__hexdir[((2 * k + (d)) % 6 + 6) % 6][0] + 1]
    for (k = 0; k < 3; ++k) {
        int v, e0, nE, lo, hi, d;
        sfb__cell *c;
        if (k == skip) continue;
        v = l->fv[l->fv_off[g] + (rot + k) % 3];
        e0 = l->ve_off[v];
        nE = l->ve_off[v + 1] - e0;
        lo = cls[k] == SFB__CORNER_R1 ? 0 : sec[k];
        hi = cls[k] == SFB__CORNER_R1 ? 5 : cls[k] == SFB__CORNER_R3 ? 1 : sec[k] + 3;
        c = &grid[sfb__tri_origin[k][1] + 1][sfb__tri_origin[k][0] + 1];
        if (c->real && c->v[0] != v) return 0;
        c->real = 1; c->n = 1; c->v[0] = v; c->w[0] = 1.0;
        for (d = lo; d <= hi; ++d) {
            int vv = sfb__other_end(l, l->ve[e0 + ((pos[k] + d) % nE + nE) % nE], v);
            c = &SFB__CELL(d);
            if (c->real && c->v[0] != vv) return 0;
            c->real = 1; c->n = 1; c->v[0] = vv; c->w[0] = 1.0;
        }
    }
    for (k = 0; k < 3; ++k) {
        int lo, hi, d;
        if (k == skip || cls[k] == SFB__CORNER_R1) continue;
        lo = sec[k];
        hi = cls[k] == SFB__CORNER_R3 ? 1 : sec[k] + 3;
        for (d = hi + 1; d <= lo + 5; ++d) {
            sfb__cell *c = &SFB__CELL(d), *B, *C = NULL;
            const sfb__cell *A = &grid[sfb__tri_origin[k][1] + 1][sfb__tri_origin[k][0] + 1]; /* the corner itself */
            if (c->real) return 0;
            if (c->n) continue;
            if (d == hi + 1) { B = &SFB__CELL(hi); C = &SFB__CELL(hi - 1); }
            else if (d == lo + 5) { B = &SFB__CELL(lo); C = &SFB__CELL(lo + 1); }
            else if (d == hi + 2) B = &SFB__CELL(lo);     /* R3: opposite the first edge */
            else B = &SFB__CELL(hi);                      /* R3: opposite the second edge */
            c->n = 0;
            if (C) {
                c->v[c->n] = A->v[0]; c->w[c->n++] = 1.0;
                c->v[c->n] = B->v[0]; c->w[c->n++] = 1.0;
                c->v[c->n] = C->v[0]; c->w[c->n++] = -1.0;
            } else {
                c->v[c->n] = A->v[0]; c->w[c->n++] = 2.0;
                c->v[c->n] = B->v[0]; c->w[c->n++] = -1.0;
            }
        }
    }
#undef SFB__CELL
    return 1;
}

/* Adds one point: the combination sum_i w[i]/24 cell(box12[i]) of the grid (Sabin's rules). */
static int sfb__pb_bez_point(sfb__pbuild *b, const sfb__rows *rows, sfb__cell grid[5][5], const unsigned char w[12]) {
    int i, t;
    b->m.n = 0;
    for (i = 0; i < 12; ++i) {
        const sfb__cell *c = &grid[sfb__box12[i][1] + 1][sfb__box12[i][0] + 1];
        if (!w[i]) continue;
        for (t = 0; t < c->n; ++t) SFB__MASK_ADD(&b->m, c->v[t], c->w[t] * w[i] / 24.0);
    }
    return sfb__pb_point(b, rows, &b->m);
}

/* Classifies candidate triangle g; adds its patch, or returns 1 in *refine. */
static sfb_result sfb__pb_face_tri(sfb__pbuild *b, sfb__wlevel *w, int g, int level, int limit, int *refine) {
    const sfb__level *l = &w->l;
    unsigned par = w->fparam[g], plain = par & ~(3u << 30);
    int rot = SFB__PARAM_CORNER(par), ptex = w->fptex[g];
    int cls[3], pos[3], sec[3], k, nev = 0, evk = -1, nirr = 0, patch, base, j;
    sfb__cell grid[5][5];
    *refine = 0;
    if (l->fhole[g]) return sfb__pb_insert(b, ptex, plain, -1) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    if (sfb__face_n(l, g) != 3) { *refine = 1; return SFB_SUCCESS; }
    for (k = 0; k < 3; ++k) {
        int slot = (rot + k) % 3, v = l->fv[l->fv_off[g] + slot];
        cls[k] = sfb__tri_corner_class(l, v, g, slot, &pos[k], &sec[k]);
        if (cls[k] == SFB__CORNER_EV) { nev++; evk = k; }
        else if (cls[k] == SFB__CORNER_IRREGULAR) nirr++;
    }
    if (nirr == 0 && nev == 0 && sfb__gather_tri(l, g, rot, cls, pos, sec, -1, grid)) {
        patch = sfb__pb_patch(b, SFB__PATCH_BEZTRI, plain, 0, 15);
        if (patch < 0) return sfb__oom(b->ctx, "patch table");
        base = b->pt->pfirst[patch];
        for (j = 0; j < 15; ++j) {
            int row = sfb__pb_bez_point(b, &w->rows, grid, sfb__bez15_from_box[j]);
            if (row < 0) return sfb__oom(b->ctx, "patch points");
            b->pt->cv[base + j] = row;
        }
        return sfb__pb_insert(b, ptex, plain, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    }
    if (nev == 1 && nirr == 0 && cls[(evk + 1) % 3] == SFB__CORNER_R1 && cls[(evk + 2) % 3] == SFB__CORNER_R1) {
        int ev = l->fv[l->fv_off[g] + (rot + evk) % 3];
        int N = l->vf_off[ev + 1] - l->vf_off[ev];
        const sfb__eigen_loop *e = sfb__eigen_loop_get(b->ctx, N);
        int scls[3], spos[3], ssec[3];
        for (k = 0; k < 3; ++k) { scls[k] = cls[(evk + k) % 3]; spos[k] = pos[(evk + k) % 3]; ssec[k] = sec[(evk + k) % 3]; }
        if (e && sfb__gather_tri(l, g, (rot + evk) % 3, scls, spos, ssec, 0, grid)) {
            static const int outer[5][2] = {{1, 1}, {2, 0}, {2, -1}, {0, 2}, {-1, 2}};
            int K = e->K, i, m, e0 = l->ve_off[ev], ok = 1;
            int *C = (int *)sfb__alloc(b->ctx, (size_t)K * sizeof(int));
            unsigned sp = SFB__PARAM(SFB__PARAM_DEPTH(par), SFB__PARAM_I(par), SFB__PARAM_J(par), evk);
            if (!C) return sfb__oom(b->ctx, "patch table");
            C[0] = ev;
            for (i = 0; i < N; ++i) C[1 + i] = sfb__other_end(l, l->ve[e0 + (spos[0] + i) % N], ev);
            for (i = 0; i < 5; ++i) {
                sfb__cell *c = &grid[outer[i][1] + 1][outer[i][0] + 1];
                C[N + 1 + i] = (c->real && c->n == 1) ? c->v[0] : -1;
                ok &= C[N + 1 + i] >= 0;
            }
            /* the regular corners' rings must close around the EV's ring as the lattice says */
            ok &= grid[1][1].real && grid[1][1].v[0] == ev && grid[1][2].v[0] == C[1] && grid[2][1].v[0] == C[2] &&
                  grid[0][2].real && grid[0][2].v[0] == C[N] && grid[2][0].real && grid[2][0].v[0] == C[1 + 2 % N];
            if (ok) {
                patch = sfb__pb_patch(b, SFB__PATCH_STAM_LOOP, sp, N, K);
                if (patch < 0 || !sfb__mask_grow(b->ctx, &b->m, K)) { sfb__free(b->ctx, C); return sfb__oom(b->ctx, "patch table"); }
                base = b->pt->pfirst[patch];
                b->pt->eigl[N] = e;
                for (i = 0; i < K; ++i) {
                    int row;
                    b->m.n = 0;
                    for (m = 0; m < K; ++m) {
                        double wgt = e->vinv[(size_t)i * K + m];
                        if (wgt != 0.0) SFB__MASK_ADD(&b->m, C[m], wgt);
                    }
                    row = sfb__pb_point(b, &w->rows, &b->m);
                    if (row < 0) { sfb__free(b->ctx, C); return sfb__oom(b->ctx, "patch points"); }
                    b->pt->cv[base + i] = row;
                }
                sfb__free(b->ctx, C);
                return sfb__pb_insert(b, ptex, sp, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
            }
            sfb__free(b->ctx, C);
        }
    }
    if ((level >= limit && !sfb__face_semisharp(l, g)) || level >= SFB_MAX_LEVEL + 1)
        return sfb__pb_endcap(b, w, g, rot, 3, plain);
    *refine = 1;
    return SFB_SUCCESS;
}

/* The sub-mesh to refine: `mark` faces (active and their 1-ring), renumbered. */
static sfb_result sfb__pb_submesh(sfb_context *ctx, const sfb__wlevel *w, const unsigned char *mark, sfb__level *sub,
                                  int *vmap, int *emap, int *fmap, unsigned char *vcomp, unsigned char *ecomp) {
    const sfb__level *l = &w->l;
    int f, k, nv = 0, ne = 0, nf = 0, nfv = 0;
    sfb_result r;
    memset(sub, 0, sizeof *sub);
    for (k = 0; k < l->nv; ++k) vmap[k] = -1;
    for (k = 0; k < l->ne; ++k) emap[k] = -1;
    for (f = 0; f < l->nf; ++f) {
        fmap[f] = -1;
        if (!mark[f]) continue;
        fmap[f] = nf++;
        for (k = l->fv_off[f]; k < l->fv_off[f + 1]; ++k) {
            if (vmap[l->fv[k]] < 0) vmap[l->fv[k]] = nv++;
            if (emap[l->fe[k]] < 0) emap[l->fe[k]] = ne++;
            nfv++;
        }
    }
    sub->nv = nv; sub->ne = ne; sub->nf = nf; sub->nfv = nfv;
    sub->fv_off = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    sub->fv = (int *)sfb__alloc(ctx, ((size_t)nfv + 1) * sizeof(int));
    sub->fe = (int *)sfb__alloc(ctx, ((size_t)nfv + 1) * sizeof(int));
    sub->ev = (int *)sfb__alloc(ctx, ((size_t)ne * 2 + 1) * sizeof(int));
    sub->es = (float *)sfb__alloc(ctx, ((size_t)ne + 1) * sizeof(float));
    sub->vs = (float *)sfb__alloc(ctx, ((size_t)nv + 1) * sizeof(float));
    sub->fhole = (unsigned char *)sfb__calloc(ctx, (size_t)nf + 1, 1);
    if (!sub->fv_off || !sub->fv || !sub->fe || !sub->ev || !sub->es || !sub->vs || !sub->fhole) {
        sfb__level_free(ctx, sub);
        return sfb__oom(ctx, "adaptive refinement");
    }
    nfv = 0;
    for (f = 0; f < l->nf; ++f) {
        int sf = fmap[f];
        if (sf < 0) continue;
        sub->fv_off[sf] = nfv;
        sub->fhole[sf] = l->fhole[f];
        for (k = l->fv_off[f]; k < l->fv_off[f + 1]; ++k) {
            sub->fv[nfv] = vmap[l->fv[k]];
            sub->fe[nfv] = emap[l->fe[k]];
            nfv++;
        }
    }
    sub->fv_off[nf] = nfv;
    for (k = 0; k < l->ne; ++k)
        if (emap[k] >= 0) {
            sub->ev[2 * emap[k]] = vmap[l->ev[2 * k]];
            sub->ev[2 * emap[k] + 1] = vmap[l->ev[2 * k + 1]];
            sub->es[emap[k]] = l->es[k];
        }
    for (k = 0; k < l->nv; ++k)
        if (vmap[k] >= 0) sub->vs[vmap[k]] = l->vs[k];
    r = sfb__level_complete(ctx, sub);
    if (r != SFB_SUCCESS) { sfb__level_free(ctx, sub); return r; }
    sfb__level_compute_rules(sub);
    /* complete in the sub-mesh: complete before and nothing around it left out */
    for (k = 0; k < l->nv; ++k)
        if (vmap[k] >= 0)
            vcomp[vmap[k]] = w->vcomp[k] && (sub->vf_off[vmap[k] + 1] - sub->vf_off[vmap[k]] == l->vf_off[k + 1] - l->vf_off[k]);
    for (k = 0; k < l->ne; ++k)
        if (emap[k] >= 0)
            ecomp[emap[k]] = w->ecomp[k] && (sub->ef_off[emap[k] + 1] - sub->ef_off[emap[k]] == l->ef_off[k + 1] - l->ef_off[k]);
    return SFB_SUCCESS;
}

sfb_result sfb__patches_build(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int limit,
                              const float *positions, sfb__patch_table *pt) {
    sfb__pbuild b;
    sfb__wlevel w, nw;
    sfb_result r = SFB_SUCCESS;
    float *ps = NULL, *cs = NULL;
    int f, k, level, nptex = 0;
    int *active = NULL, nactive = 0, tri;
    memset(&b, 0, sizeof b);
    memset(&w, 0, sizeof w);
    memset(&nw, 0, sizeof nw);
    memset(pt, 0, sizeof *pt);
    b.ctx = ctx;
    b.pt = pt;
    tri = opt->scheme == SFB_SCHEME_LOOP;
    pt->domain = tri ? SFB__DOMAIN_TRI : SFB__DOMAIN_QUAD;
    pt->isolation = limit;
    /* param faces */
    pt->face_ptex = (int *)sfb__alloc(ctx, ((size_t)base->nf + 1) * sizeof(int));
    if (!pt->face_ptex) goto oom;
    for (f = 0; f < base->nf; ++f) {
        pt->face_ptex[f] = nptex;
        nptex += (tri || sfb__face_n(base, f) == 4) ? 1 : sfb__face_n(base, f);
    }
    pt->face_ptex[base->nf] = nptex;
    pt->nptex = nptex;
    pt->ptex_face = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_corner = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_root = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    if (!pt->ptex_face || !pt->ptex_corner || !pt->ptex_root) goto oom;
    for (f = 0; f < base->nf; ++f)
        for (k = pt->face_ptex[f]; k < pt->face_ptex[f + 1]; ++k) {
            pt->ptex_face[k] = f;
            pt->ptex_corner[k] = (tri || sfb__face_n(base, f) == 4) ? -1 : k - pt->face_ptex[f];
            pt->ptex_root[k] = -1;
        }
    /* level 0 */
    w.l = *base;
    w.owns_level = 0;
    w.rows.rows = base->nv;
    w.rows.off = (size_t *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(size_t));
    w.fptex = (int *)sfb__alloc(ctx, ((size_t)base->nf + 1) * sizeof(int));
    w.fparam = (unsigned *)sfb__calloc(ctx, (size_t)base->nf + 1, sizeof(unsigned));
    w.vcomp = (unsigned char *)sfb__alloc(ctx, (size_t)base->nv + 1);
    w.ecomp = (unsigned char *)sfb__alloc(ctx, (size_t)base->ne + 1);
    b.A.acc = (double *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(double));
    b.A.mark = (unsigned *)sfb__calloc(ctx, (size_t)base->nv + 1, sizeof(unsigned));
    b.A.touched = (int *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(int));
    ps = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    cs = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    b.vrow = (int *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(int));
    if (!w.rows.off || !w.fptex || !w.fparam || !w.vcomp || !w.ecomp || !b.A.acc || !b.A.mark || !b.A.touched || !ps || !cs ||
        !b.vrow || !sfb__rows_reserve(ctx, &w.rows, (size_t)base->nv + 1) || !sfb__mask_grow(ctx, &b.m, 64))
        goto oom;
    for (k = 0; k < base->nv; ++k) { w.rows.off[k] = (size_t)k; w.rows.idx[k] = k; w.rows.w[k] = 1.0; }
    w.rows.off[base->nv] = (size_t)base->nv;
    w.rows.n = (size_t)base->nv;
    memset(w.vcomp, 1, (size_t)base->nv + 1);
    memset(w.ecomp, 1, (size_t)base->ne + 1);
    for (f = 0; f < base->nf; ++f) w.fptex[f] = (tri || sfb__face_n(base, f) == 4) ? pt->face_ptex[f] : -1;
    for (level = 0;; ++level) {
        unsigned char *mark = NULL, *vc = NULL, *ec = NULL;
        int *vmap = NULL, *emap = NULL, *fmap = NULL;
        sfb__level sub;
        sfb__rows subrows;
        r = sfb__progress(ctx, 0.8f + 0.15f * (float)level / (float)(SFB_MAX_LEVEL + 2), "patches");
        if (r != SFB_SUCCESS) goto done;
        for (k = 0; k < w.l.nv; ++k) b.vrow[k] = -1;
        sfb__free(ctx, active);
        active = (int *)sfb__alloc(ctx, ((size_t)w.l.nf + 1) * sizeof(int));
        if (!active) goto oom;
        nactive = 0;
        for (f = 0; f < w.l.nf; ++f) {
            int refine = 0;
            if (!tri && level == 0 && sfb__face_n(&w.l, f) != 4) {
                if (!w.l.fhole[f]) active[nactive++] = f;
                continue;
            }
            if (w.fptex[f] < 0) continue;
            r = tri ? sfb__pb_face_tri(&b, &w, f, level, limit, &refine) : sfb__pb_face(&b, &w, f, level, limit, &refine);
            if (r != SFB_SUCCESS) goto done;
            if (refine) active[nactive++] = f;
        }
        if (nactive == 0) break;
        if (level > SFB_MAX_LEVEL + 1) {
            r = sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "adaptive isolation did not terminate");
            goto done;
        }
        /* mark the active faces and their 1-ring */
        mark = (unsigned char *)sfb__calloc(ctx, (size_t)w.l.nf + 1, 1);
        vmap = (int *)sfb__alloc(ctx, ((size_t)w.l.nv + 1) * sizeof(int));
        emap = (int *)sfb__alloc(ctx, ((size_t)w.l.ne + 1) * sizeof(int));
        fmap = (int *)sfb__alloc(ctx, ((size_t)w.l.nf + 1) * sizeof(int));
        vc = (unsigned char *)sfb__alloc(ctx, (size_t)w.l.nv + 1);
        ec = (unsigned char *)sfb__alloc(ctx, (size_t)w.l.ne + 1);
        if (!mark || !vmap || !emap || !fmap || !vc || !ec) {
            sfb__free(ctx, mark); sfb__free(ctx, vmap); sfb__free(ctx, emap); sfb__free(ctx, fmap); sfb__free(ctx, vc); sfb__free(ctx, ec);
            goto oom;
        }
        for (k = 0; k < nactive; ++k) {
            int g = active[k], q, i;
            mark[g] = 1;
            for (q = w.l.fv_off[g]; q < w.l.fv_off[g + 1]; ++q) {
                int v = w.l.fv[q];
                if (!w.vcomp[v]) {
                    r = sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "adaptive isolation reached an incomplete vertex");
                    sfb__free(ctx, mark); sfb__free(ctx, vmap); sfb__free(ctx, emap); sfb__free(ctx, fmap); sfb__free(ctx, vc); sfb__free(ctx, ec);
                    goto done;
                }
                for (i = w.l.vf_off[v]; i < w.l.vf_off[v + 1]; ++i) mark[w.l.vf[i]] = 1;
            }
        }
        r = sfb__pb_submesh(ctx, &w, mark, &sub, vmap, emap, fmap, vc, ec);
        if (r != SFB_SUCCESS) {
            sfb__free(ctx, mark); sfb__free(ctx, vmap); sfb__free(ctx, emap); sfb__free(ctx, fmap); sfb__free(ctx, vc); sfb__free(ctx, ec);
            goto done;
        }
        /* rows of the sub-mesh's vertices */
        memset(&subrows, 0, sizeof subrows);
        subrows.rows = sub.nv;
        subrows.off = (size_t *)sfb__alloc(ctx, ((size_t)sub.nv + 1) * sizeof(size_t));
        r = SFB_SUCCESS;
        if (!subrows.off) r = sfb__oom(ctx, "adaptive refinement");
        else {
            int v;
            subrows.off[0] = 0;
            {
                int *inv = (int *)sfb__alloc(ctx, ((size_t)sub.nv + 1) * sizeof(int));
                if (!inv) r = sfb__oom(ctx, "adaptive refinement");
                else {
                    for (v = 0; v < w.l.nv; ++v)
                        if (vmap[v] >= 0) inv[vmap[v]] = v;
                    for (v = 0; v < sub.nv && r == SFB_SUCCESS; ++v) {
                        size_t a = w.rows.off[inv[v]], z = w.rows.off[inv[v] + 1];
                        if (!sfb__rows_reserve(ctx, &subrows, subrows.n + (z - a))) { r = sfb__oom(ctx, "adaptive refinement"); break; }
                        memcpy(subrows.idx + subrows.n, w.rows.idx + a, (z - a) * sizeof(int));
                        memcpy(subrows.w + subrows.n, w.rows.w + a, (z - a) * sizeof(double));
                        subrows.n += z - a;
                        subrows.off[v + 1] = subrows.n;
                    }
                    sfb__free(ctx, inv);
                }
            }
        }
        if (r == SFB_SUCCESS) {
            memset(&nw, 0, sizeof nw);
            r = sfb__refine_step(ctx, opt, &sub, &subrows, &nw.l, &nw.rows, &b.A, &b.m, ps, cs, 0.0f, 0.0f);
            nw.owns_level = 1;
        }
        if (r == SFB_SUCCESS) {
            /* flags and candidates of the child level */
            const sfb__level *p = &sub;
            nw.fptex = (int *)sfb__alloc(ctx, ((size_t)nw.l.nf + 1) * sizeof(int));
            nw.fparam = (unsigned *)sfb__calloc(ctx, (size_t)nw.l.nf + 1, sizeof(unsigned));
            nw.vcomp = (unsigned char *)sfb__calloc(ctx, (size_t)nw.l.nv + 1, 1);
            nw.ecomp = (unsigned char *)sfb__calloc(ctx, (size_t)nw.l.ne + 1, 1);
            if (!nw.fptex || !nw.fparam || !nw.vcomp || !nw.ecomp) r = sfb__oom(ctx, "adaptive refinement");
            else {
                int v, e, nvf = tri ? 0 : p->nf; /* Loop has no face points */
                for (v = 0; v < p->nv; ++v) nw.vcomp[v] = vc[v];
                for (f = 0; f < nvf; ++f) nw.vcomp[p->nv + f] = 1;
                for (e = 0; e < p->ne; ++e) {
                    nw.vcomp[p->nv + nvf + e] = ec[e];
                    nw.ecomp[2 * e] = nw.ecomp[2 * e + 1] = ec[e];
                }
                for (e = 2 * p->ne; e < nw.l.ne; ++e) nw.ecomp[e] = 1;
                for (f = 0; f < nw.l.nf; ++f) nw.fptex[f] = -1;
                for (k = 0; k < nactive; ++k) {
                    int g = active[k], sf = fmap[g], o = p->fv_off[sf], n = p->fv_off[sf + 1] - o, i;
                    unsigned par = w.fparam[g];
                    if (tri) {
                        /* children 4 sf + i: the corner at slot i (i < 3), the middle (i = 3) */
                        int rot = SFB__PARAM_CORNER(par);
                        for (i = 0; i < 4; ++i) {
                            int c = i == 3 ? 3 : (i - rot + 3) % 3;
                            int crot = i == 3 ? (rot + 1) % 3 : c == 0 ? 0 : c == 1 ? 2 : 1;
                            nw.fptex[4 * sf + i] = w.fptex[g];
                            nw.fparam[4 * sf + i] = SFB__PARAM(SFB__PARAM_DEPTH(par) + 1, 2 * SFB__PARAM_I(par) + (c & 1),
                                                               2 * SFB__PARAM_J(par) + (c >> 1), crot);
                        }
                        continue;
                    }
                    for (i = 0; i < n; ++i) {
                        int cf = o + i;
                        if (level == 0 && sfb__face_n(&w.l, g) != 4) {
                            nw.fptex[cf] = pt->face_ptex[g] + i;
                            nw.fparam[cf] = 0;
                        } else {
                            int rot = SFB__PARAM_CORNER(par), c = ((i - rot) % 4 + 4) % 4;
                            int ox = (c == 1 || c == 2), oy = (c >= 2);
                            nw.fptex[cf] = w.fptex[g];
                            nw.fparam[cf] = SFB__PARAM(SFB__PARAM_DEPTH(par) + 1, 2 * SFB__PARAM_I(par) + ox, 2 * SFB__PARAM_J(par) + oy,
                                                       ((rot - i) % 4 + 4) % 4);
                        }
                    }
                }
            }
        }
        sfb__rows_free(ctx, &subrows);
        sfb__level_free(ctx, &sub);
        sfb__free(ctx, mark); sfb__free(ctx, vmap); sfb__free(ctx, emap); sfb__free(ctx, fmap); sfb__free(ctx, vc); sfb__free(ctx, ec);
        if (r != SFB_SUCCESS) { sfb__wlevel_free(ctx, &nw); goto done; }
        sfb__wlevel_free(ctx, &w);
        w = nw;
        memset(&nw, 0, sizeof nw);
        {
            int *nv = (int *)sfb__realloc(ctx, b.vrow, ((size_t)w.l.nv + 1) * sizeof(int));
            if (!nv) goto oom;
            b.vrow = nv;
        }
        if (level + 1 > pt->max_depth) pt->max_depth = level + 1;
    }
    r = SFB_SUCCESS;
    pt->npoints = b.prow.rows;
    if (r == SFB_SUCCESS) {
        /* The points straight from the double rows (no float stencil table): a Stam point is an
         * eigen coefficient, a combination with weights of both signs summing to 0 whose result
         * is small next to the coordinates; float weights would cost it its precision (normals
         * off by ~1e-4 rad on meshes far from the origin). */
        int row, c;
        pt->point_data = (float *)sfb__alloc(ctx, ((size_t)b.prow.rows + 1) * 3 * sizeof(float));
        if (!pt->point_data) r = sfb__oom(ctx, "patch points");
        for (row = 0; r == SFB_SUCCESS && row < b.prow.rows; ++row) {
            double acc[3] = {0.0, 0.0, 0.0};
            size_t q;
            for (q = b.prow.off[row]; q < b.prow.off[row + 1]; ++q)
                for (c = 0; c < 3; ++c) acc[c] += b.prow.w[q] * positions[3 * (size_t)b.prow.idx[q] + c];
            for (c = 0; c < 3; ++c) pt->point_data[3 * (size_t)row + c] = (float)acc[c];
        }
    }
    goto done;
oom:
    r = sfb__oom(ctx, "patch table");
done:
    sfb__wlevel_free(ctx, &w);
    sfb__wlevel_free(ctx, &nw);
    sfb__rows_free(ctx, &b.prow);
    sfb__free(ctx, b.A.acc); sfb__free(ctx, b.A.mark); sfb__free(ctx, b.A.touched);
    sfb__free(ctx, b.m.idx); sfb__free(ctx, b.m.w);
    sfb__free(ctx, b.vrow);
    sfb__free(ctx, ps); sfb__free(ctx, cs);
    sfb__free(ctx, active);
    if (r != SFB_SUCCESS) sfb__patch_table_free(ctx, pt);
    return r;
}

/* ---- locating and evaluating ---- */

/* Patch index (or -1: hole) and local (s,t) of a valid location; *scale = 2^depth. */
int sfb__patch_locate(const sfb__patch_table *pt, int ptex, double u, double v, double *s, double *t, double *scale) {
    int node = pt->ptex_root[ptex];
    double sc = 1.0;
    if (pt->domain == SFB__DOMAIN_TRI) {
        /* triangles: *scale is negative after an odd number of middle children */
        while (node >= 0) {
            int c;
            sc *= 2.0;
            if (u >= 0.5) { c = 1; u = 2.0 * u - 1.0; v = 2.0 * v; }
            else if (v >= 0.5) { c = 2; u = 2.0 * u; v = 2.0 * v - 1.0; }
            else if (u + v < 0.5) { c = 0; u = 2.0 * u; v = 2.0 * v; }
            else { c = 3; u = 1.0 - 2.0 * u; v = 1.0 - 2.0 * v; sc = -sc; }
            node = pt->nodes[4 * node + c];
        }
        *s = u; *t = v; *scale = sc;
        return node <= -2 ? -node - 2 : -1;
    }
    while (node >= 0) {
        int qx, qy;
        u *= 2.0; v *= 2.0; sc *= 2.0;
        qx = u >= 1.0; qy = v >= 1.0;
        if (qx) u -= 1.0;
        if (qy) v -= 1.0;
        node = pt->nodes[4 * node + qx + 2 * qy];
    }
    *s = u; *t = v; *scale = sc;
    return node <= -2 ? -node - 2 : -1;
}

static void sfb__bspline_basis(double t, double *b, double *d, double *dd) {
    double t2 = t * t, t3 = t2 * t, s = 1.0 - t;
    b[0] = s * s * s / 6.0; b[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0; b[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0; b[3] = t3 / 6.0;
    d[0] = -0.5 * s * s; d[1] = 1.5 * t2 - 2.0 * t; d[2] = -1.5 * t2 + t + 0.5; d[3] = 0.5 * t2;
    dd[0] = s; dd[1] = 3.0 * t - 2.0; dd[2] = -3.0 * t + 1.0; dd[3] = t;
}

static void sfb__cross(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* res[0..5]: P, Ps, Pt, Pss, Pst, Ptt in the patch's (s,t); nrm: an unnormalised normal
 * direction (a positive multiple of Ps x Pt, finite where Ps x Pt under- or overflows). */
static void sfb__eval_bspline16(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    double bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4];
    int i, j, c;
    sfb__bspline_basis(s, bu, du, ddu);
    sfb__bspline_basis(t, bv, dv, ddv);
    memset(res, 0, sizeof(double) * 18);
    for (j = 0; j < 4; ++j)
        for (i = 0; i < 4; ++i) {
            const float *p = pts + 3 * (size_t)cv[4 * j + i];
            double w[6];
            w[0] = bu[i] * bv[j]; w[1] = du[i] * bv[j]; w[2] = bu[i] * dv[j];
            w[3] = ddu[i] * bv[j]; w[4] = du[i] * dv[j]; w[5] = bu[i] * ddv[j];
            for (c = 0; c < 3; ++c) {
                int q;
                for (q = 0; q < 6; ++q) res[q][c] += w[q] * p[c];
            }
        }
}

static void sfb__eval_endcap(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    const float *p0 = pts + 3 * (size_t)cv[0], *p1 = pts + 3 * (size_t)cv[1], *p2 = pts + 3 * (size_t)cv[2], *p3 = pts + 3 * (size_t)cv[3];
    int c;
    for (c = 0; c < 3; ++c) {
        res[0][c] = (1 - s) * (1 - t) * p0[c] + s * (1 - t) * p1[c] + s * t * p2[c] + (1 - s) * t * p3[c];
        res[1][c] = (1 - t) * ((double)p1[c] - p0[c]) + t * ((double)p2[c] - p3[c]);
        res[2][c] = (1 - s) * ((double)p3[c] - p0[c]) + s * ((double)p2[c] - p1[c]);
        res[3][c] = 0.0;
        res[4][c] = (double)p0[c] - p1[c] + p2[c] - p3[c];
        res[5][c] = 0.0;
    }
}

/* End-cap normal: the bilinear blend of the corners' limit normals (from the limit tangents),
 * so that the normal at a corner is the limit normal there. A corner whose limit normal is
 * more than 45 degrees from the cap's own (chord) normal at that corner belongs to another
 * sector (a corner or non-manifold vertex): that corner uses the chord normal instead. */
static void sfb__endcap_normal(const float *pts, const int *cv, int nc, double s, double t, double nrm[3]) {
    double wts[4], n[3] = {0, 0, 0};
    int k, c;
    if (nc == 3) { wts[0] = 1 - s - t; wts[1] = s; wts[2] = t; }
    else { wts[0] = (1 - s) * (1 - t); wts[1] = s * (1 - t); wts[2] = s * t; wts[3] = (1 - s) * t; }
    for (k = 0; k < nc; ++k) {
        const float *p = pts + 3 * (size_t)cv[k], *pn = pts + 3 * (size_t)cv[(k + 1) % nc], *pp = pts + 3 * (size_t)cv[(k + nc - 1) % nc];
        const float *t1 = pts + 3 * (size_t)cv[nc + 2 * k], *t2 = pts + 3 * (size_t)cv[nc + 1 + 2 * k];
        double a[3], bb[3], ch[3], ln[3], lc, ll;
        for (c = 0; c < 3; ++c) { a[c] = (double)pn[c] - p[c]; bb[c] = (double)pp[c] - p[c]; }
        sfb__cross(a, bb, ch);
        for (c = 0; c < 3; ++c) { a[c] = t1[c]; bb[c] = t2[c]; }
        sfb__cross(a, bb, ln);
        lc = sqrt(ch[0] * ch[0] + ch[1] * ch[1] + ch[2] * ch[2]);
        ll = sqrt(ln[0] * ln[0] + ln[1] * ln[1] + ln[2] * ln[2]);
        if (lc > 0.0) for (c = 0; c < 3; ++c) ch[c] /= lc;
        if (ll > 0.0) for (c = 0; c < 3; ++c) ln[c] /= ll;
        {
            /* the tangent masks' orientation is the vertex's, not necessarily this face's */
            double d = ln[0] * ch[0] + ln[1] * ch[1] + ln[2] * ch[2];
            if (d < 0.0) { ln[0] = -ln[0]; ln[1] = -ln[1]; ln[2] = -ln[2]; d = -d; }
            if (!(ll > 0.0) || d < 0.70710678118654752) memcpy(ln, ch, sizeof ln);
        }
        for (c = 0; c < 3; ++c) n[c] += wts[k] * ln[c];
    }
    memcpy(nrm, n, sizeof n);
}

/* The end of both Stam kernels: nr holds the normalised first derivatives and sr the position
 * (row 0) and the second derivatives (rows 3..5) in the EV frame's (u,v); J = d(u,v)/d(s,t).
 * Writes res (P, Ps, Pt, Pss, Pst, Ptt; first derivatives times sc1, second times sc2) and nres
 * (the normalised first derivatives in (s,t)). */
static void sfb__stam_finish(double J[2][2], double sc1, double sc2, double sr[6][3], double nr[2][3], double res[6][3],
                             double nres[2][3]) {
    int c;
    for (c = 0; c < 3; ++c) {
        double Pu = nr[0][c], Pv = nr[1][c], Puu = sr[3][c], Puv = sr[4][c], Pvv = sr[5][c];
        res[0][c] = sr[0][c];
        nres[0][c] = Pu * J[0][0] + Pv * J[1][0];
        nres[1][c] = Pu * J[0][1] + Pv * J[1][1];
        res[1][c] = nres[0][c] * sc1;
        res[2][c] = nres[1][c] * sc1;
        res[3][c] = sc2 * (Puu * J[0][0] * J[0][0] + 2.0 * Puv * J[0][0] * J[1][0] + Pvv * J[1][0] * J[1][0]);
        res[4][c] = sc2 * (Puu * J[0][0] * J[0][1] + Puv * (J[0][0] * J[1][1] + J[0][1] * J[1][0]) + Pvv * J[1][0] * J[1][1]);
        res[5][c] = sc2 * (Puu * J[0][1] * J[0][1] + 2.0 * Puv * J[0][1] * J[1][1] + Pvv * J[1][1] * J[1][1]);
    }
}

/* Quartic Bernstein basis on a triangle, our point order (row by row in t, s rising in a
 * row): B[0..5][15] = value, d/ds, d/dt, d2/ds2, d2/dsdt, d2/dt2. */
static double sfb__tpow(double x, int e) {
    double r = 1.0;
    if (e < 0) return 0.0;
    while (e-- > 0) r *= x;
    return r;
}

static void sfb__bez15_basis(double s, double t, double B[6][15]) {
    static const double fact[5] = {1, 1, 2, 6, 24};
    double w = 1.0 - s - t;
    int i, j, q = 0;
    for (j = 0; j <= 4; ++j)
        for (i = 0; i + j <= 4; ++i, ++q) {
            int k = 4 - i - j;
            double c = 24.0 / (fact[i] * fact[j] * fact[k]);
#define SFB__M(a, b, cc) (sfb__tpow(s, a) * sfb__tpow(t, b) * sfb__tpow(w, cc))
            B[0][q] = c * SFB__M(i, j, k);
            B[1][q] = c * (i * SFB__M(i - 1, j, k) - k * SFB__M(i, j, k - 1));
            B[2][q] = c * (j * SFB__M(i, j - 1, k) - k * SFB__M(i, j, k - 1));
            B[3][q] = c * (i * (i - 1) * SFB__M(i - 2, j, k) - 2.0 * i * k * SFB__M(i - 1, j, k - 1) + k * (k - 1) * SFB__M(i, j, k - 2));
            B[4][q] = c * (i * j * SFB__M(i - 1, j - 1, k) - i * k * SFB__M(i - 1, j, k - 1) - j * k * SFB__M(i, j - 1, k - 1) +
                           k * (k - 1) * SFB__M(i, j, k - 2));
            B[5][q] = c * (j * (j - 1) * SFB__M(i, j - 2, k) - 2.0 * j * k * SFB__M(i, j - 1, k - 1) + k * (k - 1) * SFB__M(i, j, k - 2));
#undef SFB__M
        }
}

static void sfb__eval_beztri(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    double B[6][15];
    int j, q, c;
    sfb__bez15_basis(s, t, B);
    memset(res, 0, sizeof(double) * 18);
    for (j = 0; j < 15; ++j) {
        const float *p = pts + 3 * (size_t)cv[j];
        for (q = 0; q < 6; ++q)
            for (c = 0; c < 3; ++c) res[q][c] += B[q][j] * p[c];
    }
}

static void sfb__eval_endcap_tri(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    const float *p0 = pts + 3 * (size_t)cv[0], *p1 = pts + 3 * (size_t)cv[1], *p2 = pts + 3 * (size_t)cv[2];
    int c;
    memset(res, 0, sizeof(double) * 18);
    for (c = 0; c < 3; ++c) {
        res[0][c] = (1 - s - t) * p0[c] + s * p1[c] + t * p2[c];
        res[1][c] = (double)p1[c] - p0[c];
        res[2][c] = (double)p2[c] - p0[c];
    }
}

/* Stam-Loop: (s,t) in the patch, the EV at frame corner `corner`; nres as sfb__eval_stam. */
static void sfb__eval_stam_loop(const sfb__eigen_loop *e, const float *pts, const int *cv, int corner, double s, double t,
                                double res[6][3], double nres[2][3]) {
    int K = e->K, i, j, c, k, n = 1, at_ev, m;
    double u, v, J[2][2], B[6][15], ss, tt, sign = 1.0;
    double sr[6][3], nr[2][3];
    double f[SFB__STAM_MAX_VALENCE + 6][6];
    const double *phi;
    switch (corner) {
    default: u = s; v = t; J[0][0] = 1; J[0][1] = 0; J[1][0] = 0; J[1][1] = 1; break;
    case 1: u = t; v = 1.0 - s - t; J[0][0] = 0; J[0][1] = 1; J[1][0] = -1; J[1][1] = -1; break;
    case 2: u = 1.0 - s - t; v = s; J[0][0] = -1; J[0][1] = -1; J[1][0] = 1; J[1][1] = 0; break;
    }
    if (u < 0.0) u = 0.0;
    if (v < 0.0) v = 0.0;
    memset(sr, 0, sizeof sr);
    memset(nr, 0, sizeof nr);
    at_ev = u + v == 0.0;
    if (at_ev) {
        /* the limit point; tangents: the normalised derivatives' limit, which only the
         * subdominant pair reaches (evaluated anywhere in a sub-patch: the same plane) */
        k = 0; ss = 0.25; tt = 0.25;
    } else {
        while (u + v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
        if (u >= 0.5) { k = 0; ss = 2.0 * u - 1.0; tt = 2.0 * v; }
        else if (v >= 0.5) { k = 1; ss = 2.0 * u; tt = 2.0 * v - 1.0; }
        else { k = 2; ss = 1.0 - 2.0 * u; tt = 1.0 - 2.0 * v; sign = -1.0; }
    }
    m = n - 1;
    sfb__bez15_basis(ss, tt, B);
    phi = e->phi + (size_t)k * 15 * K;
    for (i = 0; i < K; ++i) {
        int q;
        for (q = 0; q < 6; ++q) f[i][q] = 0.0;
        for (j = 0; j < 15; ++j) {
            double ph = phi[(size_t)j * K + i];
            for (q = 0; q < 6; ++q) f[i][q] += B[q][j] * ph;
        }
    }
    for (i = 0; i < K; ++i) {
        const float *p = pts + 3 * (size_t)cv[i];
        double g[6];
        int q;
        for (q = 0; q < 6; ++q) g[q] = 0.0;
        if (at_ev) {
            g[0] = i == e->dominant ? f[i][0] : 0.0;
            if (i != e->dominant && fabs(e->lambda[i] - e->sub) <= 1e-12)
                for (q = 1; q < 3; ++q) g[q] = f[i][q];
        } else {
            double lp = pow(e->lambda[i], m), ln = i == e->dominant ? 0.0 : pow(e->lambda[i] / e->sub, m);
            g[0] = lp * f[i][0];
            for (q = 1; q < 6; ++q) g[q] = ln * f[i][q];
            if (e->head[i] >= 0 && m > 0) {
                /* the second vector of a Jordan block: m lambda^(m-1) of its head's function */
                int h = e->head[i];
                double jl = m * pow(e->lambda[i], m - 1), jn = jl / pow(e->sub, m);
                g[0] += jl * f[h][0];
                for (q = 1; q < 6; ++q) g[q] += jn * f[h][q];
            }
        }
        for (c = 0; c < 3; ++c) {
            sr[0][c] += g[0] * p[c];
            nr[0][c] += g[1] * p[c];
            nr[1][c] += g[2] * p[c];
            sr[3][c] += g[3] * p[c];
            sr[4][c] += g[4] * p[c];
            sr[5][c] += g[5] * p[c];
        }
    }
    for (c = 0; c < 3; ++c) { nr[0][c] *= sign; nr[1][c] *= sign; } /* the middle sub-patch is turned */
    sfb__stam_finish(J, at_ev ? 1.0 : pow(e->sub, m) * ldexp(1.0, n), at_ev ? 0.0 : pow(e->sub, m) * ldexp(1.0, 2 * n), sr, nr, res, nres);
}

/* Stam: (s,t) in the patch, the EV at frame corner `corner`. nres[2] gets the derivatives
 * divided by sub^(n-1) 2^n (a finite tangent frame down to the EV). */
static void sfb__eval_stam(const sfb__eigen_cc *e, const float *pts, const int *cv, int corner, double s, double t, double res[6][3],
                           double nres[2][3]) {
    int K = e->K, i, j, c, k, n = 1, at_ev;
    double u, v, J[2][2], bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4], uu, vv;
    double sr[6][3], nr[2][3];
    const double *phi;
    switch (corner) {
    default: u = s; v = t; J[0][0] = 1; J[0][1] = 0; J[1][0] = 0; J[1][1] = 1; break;
    case 1: u = t; v = 1.0 - s; J[0][0] = 0; J[0][1] = 1; J[1][0] = -1; J[1][1] = 0; break;
    case 2: u = 1.0 - s; v = 1.0 - t; J[0][0] = -1; J[0][1] = 0; J[1][0] = 0; J[1][1] = -1; break;
    case 3: u = 1.0 - t; v = s; J[0][0] = 0; J[0][1] = -1; J[1][0] = 1; J[1][1] = 0; break;
    }
    /* J[a][b] = d(u,v)_a / d(s,t)_b */
    memset(sr, 0, sizeof sr);
    memset(nr, 0, sizeof nr);
    at_ev = (u == 0.0 && v == 0.0);
    if (at_ev) {
        /* the limit point; tangents: the n -> infinity limit of the normalised derivatives */
        k = 2; uu = 0.0; vv = 0.0;
    } else {
        while (u < 0.5 && v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
        if (v < 0.5) { k = 1; uu = 2.0 * u - 1.0; vv = 2.0 * v; }
        else if (u < 0.5) { k = 3; uu = 2.0 * u; vv = 2.0 * v - 1.0; }
        else { k = 2; uu = 2.0 * u - 1.0; vv = 2.0 * v - 1.0; }
    }
    sfb__bspline_basis(uu, bu, du, ddu);
    sfb__bspline_basis(vv, bv, dv, ddv);
    phi = e->phi + (size_t)(k - 1) * 16 * K;
    for (i = 0; i < K; ++i) {
        double f[6] = {0, 0, 0, 0, 0, 0}, lp, ln;
        const float *p = pts + 3 * (size_t)cv[i];
        for (j = 0; j < 16; ++j) {
            double ph = phi[(size_t)j * K + i];
            int a = j % 4, b = j / 4;
            f[0] += bu[a] * bv[b] * ph; f[1] += du[a] * bv[b] * ph; f[2] += bu[a] * dv[b] * ph;
            f[3] += ddu[a] * bv[b] * ph; f[4] += du[a] * dv[b] * ph; f[5] += bu[a] * ddv[b] * ph;
        }
        if (at_ev) {
            lp = i == e->dominant ? 1.0 : 0.0;
            ln = (i != e->dominant && fabs(fabs(e->lambda[i]) - e->sub) <= 1e-12) ? 1.0 : 0.0;
        } else {
            lp = pow(e->lambda[i], n - 1);
            ln = i == e->dominant ? 0.0 : pow(e->lambda[i] / e->sub, n - 1);
        }
        for (c = 0; c < 3; ++c) {
            sr[0][c] += lp * f[0] * p[c];
            nr[0][c] += ln * f[1] * p[c];
            nr[1][c] += ln * f[2] * p[c];
            sr[3][c] += ln * f[3] * p[c];
            sr[4][c] += ln * f[4] * p[c];
            sr[5][c] += ln * f[5] * p[c];
        }
    }
    sfb__stam_finish(J, at_ev ? 1.0 : pow(e->sub, n - 1) * ldexp(1.0, n), at_ev ? 0.0 : pow(e->sub, n - 1) * ldexp(1.0, 2 * n), sr, nr,
                     res, nres);
}

/* The ref kernel: one location, double precision throughout. want2: the second derivatives are
 * asked for (a manifold blend only forms them then: they cost it four more blends). */
static void sfb__ref_eval_one(const sfb__patch_table *pt, const float *pts, const sfb_location *loc, int want2, double res[6][3],
                              double nrm[3]) {
    double s, t, sc, nres[2][3];
    int patch = sfb__patch_locate(pt, loc->face, loc->u, loc->v, &s, &t, &sc), c;
    const int *cv;
    double len;
    memset(res, 0, sizeof(double) * 18);
    nrm[0] = nrm[1] = nrm[2] = 0.0;
    if (patch < 0) return;
    cv = pt->cv + pt->pfirst[patch];
    switch (pt->ptype[patch]) {
    case SFB__PATCH_MANIFOLD4:
        sfb__mf_eval_patch(pt, pts, patch, s, t, want2, res, nrm); /* its normal is final (manifold.c) */
        goto scale;
    case SFB__PATCH_STAM:
        sfb__eval_stam(pt->eig[pt->pvalence[patch]], pts, cv, SFB__PARAM_CORNER(pt->pparam[patch]), s, t, res, nres);
        sfb__cross(nres[0], nres[1], nrm);
        break;
    case SFB__PATCH_ENDCAP:
        sfb__eval_endcap(pts, cv, s, t, res);
        sfb__endcap_normal(pts, cv, 4, s, t, nrm);
        break;
    case SFB__PATCH_ENDCAP_TRI:
        sfb__eval_endcap_tri(pts, cv, s, t, res);
        sfb__endcap_normal(pts, cv, 3, s, t, nrm);
        break;
    case SFB__PATCH_STAM_LOOP:
        sfb__eval_stam_loop(pt->eigl[pt->pvalence[patch]], pts, cv, SFB__PARAM_CORNER(pt->pparam[patch]), s, t, res, nres);
        sfb__cross(nres[0], nres[1], nrm);
        break;
    case SFB__PATCH_BEZTRI:
        sfb__eval_beztri(pts, cv, s, t, res);
        sfb__cross(res[1], res[2], nrm);
        break;
    default:
        sfb__eval_bspline16(pts, cv, s, t, res);
        sfb__cross(res[1], res[2], nrm);
        break;
    }
    len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(len > 0.0) || !isfinite(len)) {
        /* degenerate tangents (a collapsed control net): the normal a step inside the patch */
        double r2[6][3];
        int ty = pt->ptype[patch], tri = pt->domain == SFB__DOMAIN_TRI;
        double s2 = s + (s < 0.5 ? 1e-3 : -1e-3), t2 = t + (t < 0.5 ? 1e-3 : -1e-3);
        if (tri && s2 + t2 > 1.0) { s2 = s - 1e-3; t2 = t - 1e-3; }
        if (tri && s + t < 2e-3) { s2 = s + 1e-3; t2 = t + 1e-3; }
        if (ty == SFB__PATCH_BSPLINE) sfb__eval_bspline16(pts, cv, s2, t2, r2);
        else if (ty == SFB__PATCH_ENDCAP) sfb__eval_endcap(pts, cv, s2, t2, r2);
        else if (ty == SFB__PATCH_BEZTRI) sfb__eval_beztri(pts, cv, s2, t2, r2);
        else if (ty == SFB__PATCH_ENDCAP_TRI) sfb__eval_endcap_tri(pts, cv, s2, t2, r2);
        else if (ty == SFB__PATCH_STAM_LOOP) { sfb__eval_stam_loop(pt->eigl[pt->pvalence[patch]], pts, cv, SFB__PARAM_CORNER(pt->pparam[patch]), s2, t2, r2, nres); memcpy(r2[1], nres[0], sizeof nres[0]); memcpy(r2[2], nres[1], sizeof nres[1]); }
        else { sfb__eval_stam(pt->eig[pt->pvalence[patch]], pts, cv, SFB__PARAM_CORNER(pt->pparam[patch]), s2, t2, r2, nres); memcpy(r2[1], nres[0], sizeof nres[0]); memcpy(r2[2], nres[1], sizeof nres[1]); }
        sfb__cross(r2[1], r2[2], nrm);
        len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    }
    if (len > 0.0 && isfinite(len)) for (c = 0; c < 3; ++c) nrm[c] /= len;
    else nrm[0] = nrm[1] = nrm[2] = 0.0;
scale:
    for (c = 0; c < 3; ++c) {
        res[1][c] *= sc; res[2][c] *= sc;
        res[3][c] *= sc * sc; res[4][c] *= sc * sc; res[5][c] *= sc * sc;
    }
}

sfb_result sfb__ref_eval_patches(void *state, const sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                        int last, const sfb_eval_output *out) {
    int q, c;
    (void)state; (void)handle;
    for (q = first; q < last; ++q) {
        double res[6][3], nrm[3];
        size_t o = 3 * (size_t)q;
        sfb__ref_eval_one(pt, pt->point_data, &locs[q], out->duu || out->duv || out->dvv, res, nrm);
        for (c = 0; c < 3; ++c) {
            if (out->position) out->position[o + c] = (float)res[0][c];
            if (out->du) out->du[o + c] = (float)res[1][c];
            if (out->dv) out->dv[o + c] = (float)res[2][c];
            if (out->duu) out->duu[o + c] = (float)res[3][c];
            if (out->duv) out->duv[o + c] = (float)res[4][c];
            if (out->dvv) out->dvv[o + c] = (float)res[5][c];
            if (out->normal) out->normal[o + c] = (float)nrm[c];
        }
    }
    return SFB_SUCCESS;
}
