/* The Catmull-Clark and Loop scheme builders' common part: the patch-table builder (records,
 * points from the working levels' double positions, the quadtree), the shared corner helpers, and
 * feature-adaptive isolation (sfb__patches_build). The record kinds themselves are built and
 * evaluated in patch/quad.c (BSPLINE16, STAM, ENDCAP) and patch/tri.c (BEZTRI15, STAM_LOOP,
 * ENDCAP_TRI); patch/table.c reads a finished table.
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
 *   other three are R1 -> STAM (eigen form, patch/eigen.c);
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


int sfb__is_inf(float s) { return s >= SFB_SHARPNESS_INFINITE; }

/* Fan position of face g (corner slot `slot`) around vertex v, or -1. */
int sfb__fan_pos(const sfb__level *l, int v, int g, int slot) {
    int i;
    for (i = l->vf_off[v]; i < l->vf_off[v + 1]; ++i)
        if (l->vf[i] == g && l->vf_slot[i] == slot) return i - l->vf_off[v];
    return -1;
}

int sfb__face_n(const sfb__level *l, int f) { return l->fv_off[f + 1] - l->fv_off[f]; }

/* Does anything at g's corners still have to decay (semi-sharp edge or vertex)? */
int sfb__face_semisharp(const sfb__level *l, int g) {
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

/* acc = the weighted sum of the xyz points pos[idx[i]] (zero weights skipped), in double. */
static void sfb__pb_combine(const int *idx, const double *w, size_t n, const double *pos, double acc[3]) {
    size_t i;
    int c;
    acc[0] = acc[1] = acc[2] = 0.0;
    for (i = 0; i < n; ++i) {
        const double *q = pos + 3 * (size_t)idx[i];
        if (w[i] == 0.0) continue;
        for (c = 0; c < 3; ++c) acc[c] += w[i] * q[c];
    }
}

/* Adds a point: mask m over working-level vertices applied to their double positions, rounded
 * to float once (a Stam point is an eigen coefficient, weights of both signs summing to 0 and a
 * result small next to the coordinates: it needs the double sum). A single vertex with weight 1 is shared through vrow. Returns the point's index
 * or -1 on allocation failure. Positions rather than rows composed over the base vertices:
 * nothing needs the rows once the points are made, and on a triangle mesh under Catmull-Clark
 * (an extraordinary vertex in every face) composing them was most of the build's time and
 * memory. */
int sfb__pb_point(sfb__pbuild *b, const double *wpos, const sfb__mask *m) {
    double acc[3];
    int c, row;
    if (m->n == 1 && m->w[0] == 1.0 && b->vrow[m->idx[0]] >= 0) return b->vrow[m->idx[0]];
    row = b->npts;
    if (row + 1 > b->cap_pts) {
        int nc = b->cap_pts ? b->cap_pts : 1024;
        float *np;
        while (nc < row + 1) {
            if (nc > 0x3fffffff) return -1; /* the int indices of cv */
            nc *= 2;
        }
        np = (float *)sfb__realloc(b->ctx, b->pts, (size_t)nc * 3 * sizeof(float));
        if (!np) return -1;
        b->pts = np;
        b->cap_pts = nc;
    }
    sfb__pb_combine(m->idx, m->w, (size_t)m->n, wpos, acc);
    for (c = 0; c < 3; ++c) b->pts[3 * (size_t)row + c] = (float)acc[c];
    b->npts = row + 1;
    if (m->n == 1 && m->w[0] == 1.0) b->vrow[m->idx[0]] = row;
    return row;
}

int sfb__pb_patch(sfb__pbuild *b, int type, unsigned param, int valence, int ncv) {
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
int sfb__pb_insert(sfb__pbuild *b, int ptex, unsigned param, int patch) {
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

void sfb__wlevel_free(sfb_context *ctx, sfb__wlevel *w) {
    if (w->owns_level) sfb__level_free(ctx, &w->l);
    sfb__free(ctx, w->pos);
    sfb__free(ctx, w->fptex); sfb__free(ctx, w->fparam); sfb__free(ctx, w->vcomp); sfb__free(ctx, w->ecomp);
    memset(w, 0, sizeof *w);
}

/* End cap of face g (n = 3 or 4 corners, frame corner 0 at slot rot): the limit positions of
 * the corners in frame order (points 0..n-1), then the two limit tangents of each corner
 * (points n + 2k, n + 2k + 1) for the normals. */
sfb_result sfb__pb_endcap(sfb__pbuild *b, sfb__wlevel *w, int g, int rot, int n, unsigned param) {
    const sfb__level *l = &w->l;
    int base, k, patch;
    /* the builder's masks, grown once: a UV layout of placeholder values has vertices of
     * valence in the thousands, whose masks were allocated and freed at every cap */
    sfb__mask *mp = &b->cap[0], *m1 = &b->cap[1], *m2 = &b->cap[2];
    sfb_result er = SFB_SUCCESS;
    patch = sfb__pb_patch(b, n == 4 ? SFB__PATCH_ENDCAP : SFB__PATCH_ENDCAP_TRI, param, 0, 3 * n);
    if (patch < 0) return sfb__oom(b->ctx, "patch table");
    base = b->pt->pfirst[patch];
    for (k = 0; k < n && er == SFB_SUCCESS; ++k) {
        int v = l->fv[l->fv_off[g] + (rot + k) % n], r0, r1, r2, need = 3 * sfb__mask_need_vertex(l, v) + 8;
        mp->n = m1->n = m2->n = 0;
        if (!sfb__mask_grow(b->ctx, mp, need) || !sfb__mask_grow(b->ctx, m1, need) || !sfb__mask_grow(b->ctx, m2, need)) {
            er = sfb__oom(b->ctx, "patch points");
            break;
        }
        sfb__limit_masks(l, v, n == 4 ? SFB_SCHEME_CATMARK : SFB_SCHEME_LOOP, mp, m1, m2);
        r0 = sfb__pb_point(b, w->pos, mp);
        r1 = sfb__pb_point(b, w->pos, m1);
        r2 = sfb__pb_point(b, w->pos, m2);
        if (r0 < 0 || r1 < 0 || r2 < 0) er = sfb__oom(b->ctx, "patch points");
        b->pt->cv[base + k] = r0;
        b->pt->cv[base + n + 2 * k] = r1;
        b->pt->cv[base + n + 1 + 2 * k] = r2;
    }
    if (er != SFB_SUCCESS) return er;
    return sfb__pb_insert(b, w->fptex[g], param, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
}

/* A Stam-kind record (type STAM or STAM_LOOP, valence N) of K eigen-coefficient points, point i
 * = sum_m vinv[i K + m] C[m] over working-level vertices C; inserted at (ptex, param). Frees C. */
sfb_result sfb__pb_eigen_patch(sfb__pbuild *b, sfb__wlevel *w, int type, int ptex, unsigned param, int N, int K, const double *vinv,
                               int *C) {
    int patch = sfb__pb_patch(b, type, param, N, K), base, i, m;
    if (patch < 0 || !sfb__mask_grow(b->ctx, &b->m, K)) { sfb__free(b->ctx, C); return sfb__oom(b->ctx, "patch table"); }
    base = b->pt->pfirst[patch];
    for (i = 0; i < K; ++i) {
        int row;
        b->m.n = 0;
        for (m = 0; m < K; ++m) {
            double wgt = vinv[(size_t)i * K + m];
            if (wgt != 0.0) SFB__MASK_ADD(&b->m, C[m], wgt);
        }
        row = sfb__pb_point(b, w->pos, &b->m);
        if (row < 0) { sfb__free(b->ctx, C); return sfb__oom(b->ctx, "patch points"); }
        b->pt->cv[base + i] = row;
    }
    sfb__free(b->ctx, C);
    return sfb__pb_insert(b, ptex, param, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
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

/* ---- the isolation driver ---- */

/* Parametric faces of the base level: one per quad (or triangle, tri), n per other n-gon. */
static sfb_result sfb__pb_param_faces(sfb_context *ctx, const sfb__level *base, int tri, sfb__patch_table *pt) {
    int f, k, nptex = 0;
    pt->face_ptex = (int *)sfb__alloc(ctx, ((size_t)base->nf + 1) * sizeof(int));
    if (!pt->face_ptex) return sfb__oom(ctx, "patch table");
    for (f = 0; f < base->nf; ++f) {
        pt->face_ptex[f] = nptex;
        nptex += (tri || sfb__face_n(base, f) == 4) ? 1 : sfb__face_n(base, f);
    }
    pt->face_ptex[base->nf] = nptex;
    pt->nptex = nptex;
    pt->ptex_face = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_corner = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_root = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    if (!pt->ptex_face || !pt->ptex_corner || !pt->ptex_root) return sfb__oom(ctx, "patch table");
    for (f = 0; f < base->nf; ++f)
        for (k = pt->face_ptex[f]; k < pt->face_ptex[f + 1]; ++k) {
            pt->ptex_face[k] = f;
            pt->ptex_corner[k] = (tri || sfb__face_n(base, f) == 4) ? -1 : k - pt->face_ptex[f];
            pt->ptex_root[k] = -1;
        }
    return SFB_SUCCESS;
}

/* Level 0: the base level with its positions in double, its faces the candidates, and the
 * builder's scratch (mask, vertex points; ps/cs for the refinement steps). */
static sfb_result sfb__pb_start(sfb__pbuild *b, sfb__wlevel *w, const sfb__level *base, int tri, const float *positions, float **ps,
                                float **cs) {
    sfb_context *ctx = b->ctx;
    int f;
    size_t k;
    w->l = *base;
    w->owns_level = 0;
    w->pos = (double *)sfb__alloc(ctx, ((size_t)base->nv + 1) * 3 * sizeof(double));
    w->fptex = (int *)sfb__alloc(ctx, ((size_t)base->nf + 1) * sizeof(int));
    w->fparam = (unsigned *)sfb__calloc(ctx, (size_t)base->nf + 1, sizeof(unsigned));
    w->vcomp = (unsigned char *)sfb__alloc(ctx, (size_t)base->nv + 1);
    w->ecomp = (unsigned char *)sfb__alloc(ctx, (size_t)base->ne + 1);
    *ps = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    *cs = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    b->vrow = (int *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(int));
    if (!w->pos || !w->fptex || !w->fparam || !w->vcomp || !w->ecomp || !*ps || !*cs || !b->vrow || !sfb__mask_grow(ctx, &b->m, 64))
        return sfb__oom(ctx, "patch table");
    for (k = 0; k < 3 * (size_t)base->nv; ++k) w->pos[k] = (double)positions[k];
    memset(w->vcomp, 1, (size_t)base->nv + 1);
    memset(w->ecomp, 1, (size_t)base->ne + 1);
    for (f = 0; f < base->nf; ++f) w->fptex[f] = (tri || sfb__face_n(base, f) == 4) ? b->pt->face_ptex[f] : -1;
    return SFB_SUCCESS;
}

/* Classifies every candidate of the working level (patches added); the faces to refine go to
 * active[0 .. *nactive). At level 0 a Catmull-Clark n-gon is refined into its n quads. */
static sfb_result sfb__pb_classify(sfb__pbuild *b, sfb__wlevel *w, int level, int limit, int tri, int *active, int *nactive) {
    int f;
    sfb_result r;
    *nactive = 0;
    for (f = 0; f < w->l.nf; ++f) {
        int refine = 0;
        if (!tri && level == 0 && sfb__face_n(&w->l, f) != 4) {
            if (!w->l.fhole[f]) active[(*nactive)++] = f;
            continue;
        }
        if (w->fptex[f] < 0) continue;
        r = tri ? sfb__pb_face_tri(b, w, f, level, limit, &refine) : sfb__pb_face_quad(b, w, f, level, limit, &refine);
        if (r != SFB_SUCCESS) return r;
        if (refine) active[(*nactive)++] = f;
    }
    return SFB_SUCCESS;
}

/* Marks the active faces and their 1-ring (the faces the next level's masks read). */
static sfb_result sfb__pb_mark_ring(sfb_context *ctx, const sfb__wlevel *w, const int *active, int nactive, unsigned char *mark) {
    int k, q, i;
    for (k = 0; k < nactive; ++k) {
        int g = active[k];
        mark[g] = 1;
        for (q = w->l.fv_off[g]; q < w->l.fv_off[g + 1]; ++q) {
            int v = w->l.fv[q];
            if (!w->vcomp[v]) return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "adaptive isolation reached an incomplete vertex");
            for (i = w->l.vf_off[v]; i < w->l.vf_off[v + 1]; ++i) mark[w->l.vf[i]] = 1;
        }
    }
    return SFB_SUCCESS;
}

/* The positions of the sub-mesh's vertices (vmap: working-level vertex -> sub-mesh vertex). */
static double *sfb__pb_sub_pos(sfb_context *ctx, const sfb__wlevel *w, const int *vmap, int nsub) {
    int v, c;
    double *sp = (double *)sfb__alloc(ctx, ((size_t)nsub + 1) * 3 * sizeof(double));
    if (!sp) return NULL;
    for (v = 0; v < w->l.nv; ++v)
        if (vmap[v] >= 0)
            for (c = 0; c < 3; ++c) sp[3 * (size_t)vmap[v] + c] = w->pos[3 * (size_t)v + c];
    return sp;
}

/* Completeness flags and candidates of the child level nw of sub-mesh p: the children of the
 * active faces, with their parametric face and sub-square (see sfb__patch_locate). */
static sfb_result sfb__pb_children(sfb_context *ctx, const sfb__patch_table *pt, const sfb__wlevel *w, const sfb__level *p,
                                   sfb__wlevel *nw, const int *active, int nactive, const int *fmap, const unsigned char *vc,
                                   const unsigned char *ec, int level, int tri) {
    int v, e, f, k, nvf = tri ? 0 : p->nf; /* Loop has no face points */
    nw->fptex = (int *)sfb__alloc(ctx, ((size_t)nw->l.nf + 1) * sizeof(int));
    nw->fparam = (unsigned *)sfb__calloc(ctx, (size_t)nw->l.nf + 1, sizeof(unsigned));
    nw->vcomp = (unsigned char *)sfb__calloc(ctx, (size_t)nw->l.nv + 1, 1);
    nw->ecomp = (unsigned char *)sfb__calloc(ctx, (size_t)nw->l.ne + 1, 1);
    if (!nw->fptex || !nw->fparam || !nw->vcomp || !nw->ecomp) return sfb__oom(ctx, "adaptive refinement");
    for (v = 0; v < p->nv; ++v) nw->vcomp[v] = vc[v];
    for (f = 0; f < nvf; ++f) nw->vcomp[p->nv + f] = 1;
    for (e = 0; e < p->ne; ++e) {
        nw->vcomp[p->nv + nvf + e] = ec[e];
        nw->ecomp[2 * e] = nw->ecomp[2 * e + 1] = ec[e];
    }
    for (e = 2 * p->ne; e < nw->l.ne; ++e) nw->ecomp[e] = 1;
    for (f = 0; f < nw->l.nf; ++f) nw->fptex[f] = -1;
    for (k = 0; k < nactive; ++k) {
        int g = active[k], sf = fmap[g], o = p->fv_off[sf], n = p->fv_off[sf + 1] - o, i;
        unsigned par = w->fparam[g];
        if (tri) {
            /* children 4 sf + i: the corner at slot i (i < 3), the middle (i = 3) */
            int rot = SFB__PARAM_CORNER(par);
            for (i = 0; i < 4; ++i) {
                int c = i == 3 ? 3 : (i - rot + 3) % 3;
                int crot = i == 3 ? (rot + 1) % 3 : c == 0 ? 0 : c == 1 ? 2 : 1;
                nw->fptex[4 * sf + i] = w->fptex[g];
                nw->fparam[4 * sf + i] = SFB__PARAM(SFB__PARAM_DEPTH(par) + 1, 2 * SFB__PARAM_I(par) + (c & 1),
                                                    2 * SFB__PARAM_J(par) + (c >> 1), crot);
            }
            continue;
        }
        for (i = 0; i < n; ++i) {
            int cf = o + i;
            if (level == 0 && sfb__face_n(&w->l, g) != 4) {
                nw->fptex[cf] = pt->face_ptex[g] + i;
                nw->fparam[cf] = 0;
            } else {
                int rot = SFB__PARAM_CORNER(par), c = ((i - rot) % 4 + 4) % 4;
                int ox = (c == 1 || c == 2), oy = (c >= 2);
                nw->fptex[cf] = w->fptex[g];
                nw->fparam[cf] = SFB__PARAM(SFB__PARAM_DEPTH(par) + 1, 2 * SFB__PARAM_I(par) + ox, 2 * SFB__PARAM_J(par) + oy,
                                            ((rot - i) % 4 + 4) % 4);
            }
        }
    }
    return SFB_SUCCESS;
}

/* The next working level nw: the active faces and their 1-ring refined one step (positions
 * through the step's own masks, in double), with the children of the active faces as its
 * candidates. */
static sfb_result sfb__pb_next_level(sfb__pbuild *b, const sfb__refine_options *opt, const sfb__wlevel *w, sfb__wlevel *nw,
                                     const int *active, int nactive, int level, int tri, float *ps, float *cs) {
    sfb_context *ctx = b->ctx;
    const sfb__level *l = &w->l;
    unsigned char *mark, *vc, *ec;
    int *vmap, *emap, *fmap;
    sfb__level sub;
    sfb__rows local;
    double *subpos = NULL;
    sfb_result r;
    memset(&sub, 0, sizeof sub);
    memset(&local, 0, sizeof local);
    mark = (unsigned char *)sfb__calloc(ctx, (size_t)l->nf + 1, 1);
    vmap = (int *)sfb__alloc(ctx, ((size_t)l->nv + 1) * sizeof(int));
    emap = (int *)sfb__alloc(ctx, ((size_t)l->ne + 1) * sizeof(int));
    fmap = (int *)sfb__alloc(ctx, ((size_t)l->nf + 1) * sizeof(int));
    vc = (unsigned char *)sfb__alloc(ctx, (size_t)l->nv + 1);
    ec = (unsigned char *)sfb__alloc(ctx, (size_t)l->ne + 1);
    if (!mark || !vmap || !emap || !fmap || !vc || !ec) r = sfb__oom(ctx, "patch table");
    else r = sfb__pb_mark_ring(ctx, w, active, nactive, mark);
    if (r == SFB_SUCCESS) r = sfb__pb_submesh(ctx, w, mark, &sub, vmap, emap, fmap, vc, ec);
    if (r == SFB_SUCCESS && !(subpos = sfb__pb_sub_pos(ctx, w, vmap, sub.nv))) r = sfb__oom(ctx, "adaptive refinement");
    if (r == SFB_SUCCESS) {
        memset(nw, 0, sizeof *nw);
        r = sfb__refine_step_local(ctx, opt, &sub, NULL, &nw->l, NULL, &local, NULL, &b->m, ps, cs, 0.0f, 0.0f);
        nw->owns_level = 1;
    }
    if (r == SFB_SUCCESS) {
        int v;
        nw->pos = (double *)sfb__alloc(ctx, ((size_t)nw->l.nv + 1) * 3 * sizeof(double));
        if (!nw->pos) r = sfb__oom(ctx, "adaptive refinement");
        for (v = 0; r == SFB_SUCCESS && v < nw->l.nv; ++v)
            sfb__pb_combine(local.idx + local.off[v], local.w + local.off[v], local.off[v + 1] - local.off[v], subpos, nw->pos + 3 * (size_t)v);
    }
    if (r == SFB_SUCCESS) r = sfb__pb_children(ctx, b->pt, w, &sub, nw, active, nactive, fmap, vc, ec, level, tri);
    sfb__rows_free(ctx, &local);
    sfb__free(ctx, subpos);
    sfb__level_free(ctx, &sub);
    sfb__free(ctx, mark); sfb__free(ctx, vmap); sfb__free(ctx, emap); sfb__free(ctx, fmap); sfb__free(ctx, vc); sfb__free(ctx, ec);
    return r;
}

/* Catmull-Clark and Loop patch tables by feature-adaptive isolation (see the top of this file):
 * classify the working level's candidates, refine the ones left around them, repeat. */
sfb_result sfb__patches_build(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int limit,
                              const float *positions, sfb__patch_table *pt) {
    sfb__pbuild b;
    sfb__wlevel w, nw;
    sfb_result r;
    float *ps = NULL, *cs = NULL;
    int level, k, *active = NULL, nactive = 0, tri = opt->scheme == SFB_SCHEME_LOOP;
    memset(&b, 0, sizeof b);
    memset(&w, 0, sizeof w);
    memset(&nw, 0, sizeof nw);
    memset(pt, 0, sizeof *pt);
    b.ctx = ctx;
    b.pt = pt;
    pt->domain = tri ? SFB__DOMAIN_TRI : SFB__DOMAIN_QUAD;
    pt->isolation = limit;
    r = sfb__pb_param_faces(ctx, base, tri, pt);
    if (r == SFB_SUCCESS) r = sfb__pb_start(&b, &w, base, tri, positions, &ps, &cs);
    for (level = 0; r == SFB_SUCCESS; ++level) {
        int k, *nv;
        r = sfb__progress(ctx, 0.8f + 0.15f * (float)level / (float)(SFB_MAX_LEVEL + 2), "patches");
        if (r != SFB_SUCCESS) break;
        for (k = 0; k < w.l.nv; ++k) b.vrow[k] = -1;
        sfb__free(ctx, active);
        active = (int *)sfb__alloc(ctx, ((size_t)w.l.nf + 1) * sizeof(int));
        if (!active) { r = sfb__oom(ctx, "patch table"); break; }
        r = sfb__pb_classify(&b, &w, level, limit, tri, active, &nactive);
        if (r != SFB_SUCCESS || nactive == 0) break;
        if (level > SFB_MAX_LEVEL + 1) {
            r = sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "adaptive isolation did not terminate");
            break;
        }
        r = sfb__pb_next_level(&b, opt, &w, &nw, active, nactive, level, tri, ps, cs);
        if (r != SFB_SUCCESS) break;
        sfb__wlevel_free(ctx, &w);
        w = nw;
        memset(&nw, 0, sizeof nw);
        nv = (int *)sfb__realloc(ctx, b.vrow, ((size_t)w.l.nv + 1) * sizeof(int));
        if (!nv) { r = sfb__oom(ctx, "patch table"); break; }
        b.vrow = nv;
        if (level + 1 > pt->max_depth) pt->max_depth = level + 1;
    }
    if (r == SFB_SUCCESS) {
        pt->npoints = b.npts;
        if (b.npts > 0) {
            /* the table takes the points, trimmed to their count (or as grown, if trimming fails) */
            float *trimmed = (float *)sfb__realloc(ctx, b.pts, (size_t)b.npts * 3 * sizeof(float));
            pt->point_data = trimmed ? trimmed : b.pts;
            b.pts = NULL;
        } else if (!(pt->point_data = (float *)sfb__alloc(ctx, 3 * sizeof(float)))) {
            r = sfb__oom(ctx, "patch points");
        }
    }
    sfb__wlevel_free(ctx, &w);
    sfb__wlevel_free(ctx, &nw);
    sfb__free(ctx, b.pts);
    sfb__free(ctx, b.m.idx); sfb__free(ctx, b.m.w);
    for (k = 0; k < 3; ++k) { sfb__free(ctx, b.cap[k].idx); sfb__free(ctx, b.cap[k].w); }
    sfb__free(ctx, b.vrow);
    sfb__free(ctx, ps); sfb__free(ctx, cs);
    sfb__free(ctx, active);
    if (r != SFB_SUCCESS) sfb__patch_table_free(ctx, pt);
    return r;
}
