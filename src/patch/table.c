/* Reading a patch table (any scheme's): freeing it, the one locate (parametric face and (u,v)
 * to record and local (s,t) through the quadtree or triangle tree), the record kinds' registry
 * (sfb__patch_kind_of: which ref evaluator a record type has), and the ref kernel
 * (sfb__ref_eval_patches) that dispatches to them. Nothing here knows the scheme: the table's
 * domain says how to locate, a record's type says how to evaluate. */

void sfb__patch_table_free(sfb_context *ctx, sfb__patch_table *pt) {
    sfb__free(ctx, pt->ptype); sfb__free(ctx, pt->pfirst); sfb__free(ctx, pt->pparam); sfb__free(ctx, pt->pvalence);
    sfb__free(ctx, pt->cv); sfb__free(ctx, pt->ptex_face); sfb__free(ctx, pt->ptex_corner); sfb__free(ctx, pt->face_ptex);
    sfb__free(ctx, pt->ptex_root); sfb__free(ctx, pt->nodes); sfb__free(ctx, pt->point_data); sfb__free(ctx, pt->pcorner);
    sfb__free(ctx, pt->blend);
    sfb__tbz_features_free(ctx, pt->features);
    if (pt->normal_field) {
        sfb__patch_table_free(ctx, pt->normal_field);
        sfb__free(ctx, pt->normal_field);
    }
    memset(pt, 0, sizeof *pt);
}

/* Triangle param faces (Loop). A triangle's (u,v) is barycentric: the point is
 * (1-u-v) P0 + u P1 + v P2 for its corners in face order. One Loop step splits it into four
 * children, numbered like quadrants of a quadtree node (x + 2y bits of the param code):
 * 0 the corner at P0, (2u, 2v); 1 the corner at P1, (2u-1, 2v); 2 the corner at P2,
 * (2u, 2v-1); 3 the middle, turned by 180 degrees: (1-2u, 1-2v), so its derivatives change
 * sign. The corner bits of the code give the face slot of the child's param corner 0. */

/* Patch index (or -1: hole) and local (s,t) of a valid location; *scale = 2^depth. */
/* Refuses what a scheme of one patch per triangle cannot build (who names it in the message):
 * faces that are not triangles, non-manifold edges (and, with manifold_vertices, vertices whose
 * triangles are not one fan), non-finite positions, triangles with an area below 1e-12 of the
 * squared bounding-box diagonal. */
sfb_result sfb__tri_mesh_check(sfb_context *ctx, const sfb__level *l, const float *positions, const char *who, int manifold_vertices) {
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, diag2 = 0.0;
    int f, e, v, c;
    for (f = 0; f < l->nf; ++f)
        if (sfb__face_n(l, f) != 3)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "%s: face %d has %d vertices (triangles only)", who, f,
                              sfb__face_n(l, f));
    for (e = 0; e < l->ne; ++e)
        if (l->ef_off[e + 1] - l->ef_off[e] > 2)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, e, "%s: edge %d (%d-%d) is non-manifold (%d triangles)", who, e,
                              l->ev[2 * e], l->ev[2 * e + 1], l->ef_off[e + 1] - l->ef_off[e]);
    for (v = 0; v < l->nv; ++v) {
        if (manifold_vertices && (l->vtag[v] & SFB__TAG_NONMANIFOLD))
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, v, "%s: vertex %d is non-manifold (its triangles are not one fan)",
                              who, v);
        for (c = 0; c < 3; ++c) {
            const double x = positions[3 * (size_t)v + c];
            if (!(x == x) || x > 3.4e38 || x < -3.4e38)
                return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, v, "%s: vertex %d is not finite", who, v);
            if (v == 0 || x < lo[c]) lo[c] = x;
            if (v == 0 || x > hi[c]) hi[c] = x;
        }
    }
    for (c = 0; c < 3; ++c) diag2 += (hi[c] - lo[c]) * (hi[c] - lo[c]);
    for (f = 0; f < l->nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        double u[3], w[3], n[3], area;
        for (c = 0; c < 3; ++c) {
            u[c] = (double)positions[3 * (size_t)fv[1] + c] - positions[3 * (size_t)fv[0] + c];
            w[c] = (double)positions[3 * (size_t)fv[2] + c] - positions[3 * (size_t)fv[0] + c];
        }
        sfb__cross3(u, w, n);
        area = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(area > 1e-12 * diag2))
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "%s: triangle %d (%d %d %d) is degenerate (area %g)", who, f,
                              fv[0], fv[1], fv[2], area);
    }
    return SFB_SUCCESS;
}

/* A table of one BEZIER_TRI15 patch with 15 points of its own per triangle of l that is not a
 * hole (one param face per triangle, depth 0), the points from net (45 doubles per triangle, our
 * patch order) -- the shape of schemes whose points are not masks (PN triangles, tribezier). */
/* The arrays of a table of npatch BEZIER_TRI15 patches (15 own points each) over nf triangles
 * with nnodes quadtree nodes; 0 (and the table freed) when out of memory. */
static int sfb__beztri_alloc(sfb_context *ctx, int nf, int npatch, int nnodes, sfb__patch_table *pt) {
    pt->domain = SFB__DOMAIN_TRI;
    pt->nptex = nf;
    pt->npatch = npatch;
    pt->ncv = 15 * npatch;
    pt->npoints = 15 * npatch;
    pt->nnodes = nnodes;
    pt->face_ptex = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    pt->ptex_face = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    pt->ptex_corner = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    pt->ptex_root = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    pt->nodes = (int *)sfb__alloc(ctx, ((size_t)nnodes + 1) * 4 * sizeof(int));
    pt->ptype = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(int));
    pt->pfirst = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(int));
    pt->pparam = (unsigned *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(unsigned));
    pt->pvalence = (int *)sfb__calloc(ctx, (size_t)npatch + 1, sizeof(int));
    pt->cv = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * 15 * sizeof(int));
    pt->point_data = (float *)sfb__alloc(ctx, ((size_t)npatch + 1) * 45 * sizeof(float));
    if (!pt->face_ptex || !pt->ptex_face || !pt->ptex_corner || !pt->ptex_root || !pt->nodes || !pt->ptype || !pt->pfirst ||
        !pt->pparam || !pt->pvalence || !pt->cv || !pt->point_data) {
        sfb__patch_table_free(ctx, pt);
        return 0;
    }
    return 1;
}

sfb_result sfb__patch_table_beztri_own(sfb_context *ctx, const sfb__level *l, const double *net, sfb__patch_table *pt) {
    int f, k, p = 0, npatch = 0;
    memset(pt, 0, sizeof *pt);
    for (f = 0; f < l->nf; ++f) npatch += !l->fhole[f];
    if (!sfb__beztri_alloc(ctx, l->nf, npatch, 0, pt)) return sfb__oom(ctx, "patch table");
    for (f = 0; f < l->nf; ++f) {
        pt->face_ptex[f] = pt->ptex_face[f] = f;
        pt->ptex_corner[f] = -1;
        if (l->fhole[f]) { pt->ptex_root[f] = -1; continue; }
        for (k = 0; k < 45; ++k) pt->point_data[45 * (size_t)p + k] = (float)net[45 * (size_t)f + k];
        pt->ptype[p] = SFB__PATCH_BEZTRI;
        pt->pfirst[p] = 15 * p;
        pt->pparam[p] = SFB__PARAM(0, 0, 0, 0);
        for (k = 0; k < 15; ++k) pt->cv[15 * p + k] = 15 * p + k;
        pt->ptex_root[f] = -(p + 2);
        p++;
    }
    pt->face_ptex[l->nf] = l->nf;
    pt->pfirst[npatch] = 15 * npatch;
    pt->counts[SFB__PATCH_BEZTRI] = npatch;
    return SFB_SUCCESS;
}

sfb_result sfb__patch_table_beztri_children(sfb_context *ctx, const sfb__level *l, const double *net, int depth, sfb__patch_table *pt) {
    const int per = depth == 2 ? 16 : 4, nodes = depth == 2 ? 5 : 1;
    int f, k, i, p = 0, nn = 0, npatch = 0;
    memset(pt, 0, sizeof *pt);
    for (f = 0; f < l->nf; ++f) npatch += l->fhole[f] ? 0 : per;
    if (!sfb__beztri_alloc(ctx, l->nf, npatch, npatch / per * nodes, pt)) return sfb__oom(ctx, "patch table");
    pt->max_depth = depth;
    for (f = 0; f < l->nf; ++f) {
        pt->face_ptex[f] = pt->ptex_face[f] = f;
        pt->ptex_corner[f] = -1;
        if (l->fhole[f]) { pt->ptex_root[f] = -1; continue; }
        pt->ptex_root[f] = nn;
        if (depth == 2)
            for (i = 0; i < 4; ++i) pt->nodes[4 * nn + i] = nn + 1 + i;
        for (i = 0; i < per; ++i, ++p) {
            /* child i (depth 1), or grandchild i & 3 of child i >> 2 (depth 2); quadrant x + 2y
             * per level, the first level in the high bit (sfb__pb_insert's encoding) */
            const int c0 = depth == 2 ? i >> 2 : i, c1 = i & 3;
            if (net)
                for (k = 0; k < 45; ++k) pt->point_data[45 * (size_t)p + k] = (float)net[45 * ((size_t)per * f + (size_t)i) + k];
            pt->ptype[p] = SFB__PATCH_BEZTRI;
            pt->pfirst[p] = 15 * p;
            pt->pparam[p] = depth == 2 ? SFB__PARAM(2, (c0 & 1) << 1 | (c1 & 1), (c0 >> 1) << 1 | (c1 >> 1), 0) : SFB__PARAM(1, i & 1, i >> 1, 0);
            for (k = 0; k < 15; ++k) pt->cv[15 * p + k] = 15 * p + k;
            if (depth == 2) pt->nodes[4 * (nn + 1 + c0) + c1] = -(p + 2);
            else pt->nodes[4 * nn + i] = -(p + 2);
        }
        nn += nodes;
    }
    pt->face_ptex[l->nf] = l->nf;
    pt->pfirst[npatch] = 15 * npatch;
    pt->counts[SFB__PATCH_BEZTRI] = npatch;
    return SFB_SUCCESS;
}

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

void sfb__cross3(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* End-cap normal: the bilinear blend of the corners' limit normals (from the limit tangents),
 * so that the normal at a corner is the limit normal there. A corner whose limit normal is
 * more than 45 degrees from the cap's own (chord) normal at that corner belongs to another
 * sector (a corner or non-manifold vertex): that corner uses the chord normal instead. */
void sfb__endcap_normal(const float *pts, const int *cv, int nc, double s, double t, double nrm[3]) {
    double wts[4], n[3] = {0, 0, 0};
    int k, c;
    if (nc == 3) { wts[0] = 1 - s - t; wts[1] = s; wts[2] = t; }
    else { wts[0] = (1 - s) * (1 - t); wts[1] = s * (1 - t); wts[2] = s * t; wts[3] = (1 - s) * t; }
    for (k = 0; k < nc; ++k) {
        const float *p = pts + 3 * (size_t)cv[k], *pn = pts + 3 * (size_t)cv[(k + 1) % nc], *pp = pts + 3 * (size_t)cv[(k + nc - 1) % nc];
        const float *t1 = pts + 3 * (size_t)cv[nc + 2 * k], *t2 = pts + 3 * (size_t)cv[nc + 1 + 2 * k];
        double a[3], bb[3], ch[3], ln[3], lc, ll;
        for (c = 0; c < 3; ++c) { a[c] = (double)pn[c] - p[c]; bb[c] = (double)pp[c] - p[c]; }
        sfb__cross3(a, bb, ch);
        for (c = 0; c < 3; ++c) { a[c] = t1[c]; bb[c] = t2[c]; }
        sfb__cross3(a, bb, ln);
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
double sfb__ipow(double x, int m) {
    double r = 1.0;
    for (; m > 0; m >>= 1, x *= x)
        if (m & 1) r *= x;
    return r;
}

void sfb__stam_finish(double J[2][2], double sc1, double sc2, double sr[6][3], double nr[2][3], double res[6][3],
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

/* The ref evaluator of a record type: one line per kind. MANIFOLD4 records are evaluated by
 * patch/manifold.c's sfb__mf_eval_patch (their normal is final), see sfb__ref_eval_one. */
sfb__patch_kind sfb__patch_kind_of(int type) {
    sfb__patch_kind k;
    memset(&k, 0, sizeof k);
    switch (type) {
    case SFB__PATCH_STAM: k.eval = sfb__kind_stam; break;
    case SFB__PATCH_ENDCAP: k.poly = sfb__eval_endcap; k.cap_corners = 4; break;
    case SFB__PATCH_BEZTRI: k.poly = sfb__eval_beztri; break;
    case SFB__PATCH_STAM_LOOP: k.eval = sfb__kind_stam_loop; break;
    case SFB__PATCH_ENDCAP_TRI: k.poly = sfb__eval_endcap_tri; k.cap_corners = 3; break;
    default: k.poly = sfb__eval_bspline16; break;
    }
    return k;
}

/* res and the tangent directions dir of kind k at (s,t). */
static void sfb__kind_eval(const sfb__patch_kind *k, const sfb__patch_table *pt, const float *pts, int patch, const int *cv, double s,
                           double t, double res[6][3], double dir[2][3]) {
    if (!k->poly) { k->eval(pt, pts, patch, cv, s, t, res, dir); return; }
    k->poly(pts, cv, s, t, res);
    memcpy(dir[0], res[1], sizeof dir[0]);
    memcpy(dir[1], res[2], sizeof dir[1]);
}

/* The ref kernel: one location, double precision throughout. want2: the second derivatives are
 * asked for (a manifold blend only forms them then: they cost it four more blends); want_n: the
 * normal is (without it nrm stays 0 where the patch kind's normal is work of its own: end caps). */
static void sfb__ref_eval_one(const sfb__patch_table *pt, const float *pts, const sfb_location *loc, int want2, int want_n,
                              double res[6][3], double nrm[3]) {
    double s, t, sc, dir[2][3], len;
    int patch = sfb__patch_locate(pt, loc->face, loc->u, loc->v, &s, &t, &sc), c;
    const int *cv;
    sfb__patch_kind kind;
    memset(res, 0, sizeof(double) * 18);
    nrm[0] = nrm[1] = nrm[2] = 0.0;
    if (patch < 0) return;
    cv = pt->cv + pt->pfirst[patch];
    if (sfb__patch_family(pt->ptype[patch]) == SFB__FAMILY_MANIFOLD) {
        sfb__mf_eval_patch(pt, pts, patch, s, t, want2, res, nrm); /* its normal is final (patch/manifold.c) */
    } else {
        kind = sfb__patch_kind_of(pt->ptype[patch]);
        sfb__kind_eval(&kind, pt, pts, patch, cv, s, t, res, dir);
        if (kind.cap_corners && !want_n) { nrm[2] = 1.0; /* not asked for: any unit vector */ }
        else if (kind.cap_corners) sfb__endcap_normal(pts, cv, kind.cap_corners, s, t, nrm);
        else sfb__cross3(dir[0], dir[1], nrm);
        len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        if (!(len > 0.0) || !isfinite(len)) {
            /* degenerate tangents (a collapsed control net): the normal a step inside the patch */
            double r2[6][3];
            int tri = pt->domain == SFB__DOMAIN_TRI;
            double s2 = s + (s < 0.5 ? 1e-3 : -1e-3), t2 = t + (t < 0.5 ? 1e-3 : -1e-3);
            if (tri && s2 + t2 > 1.0) { s2 = s - 1e-3; t2 = t - 1e-3; }
            if (tri && s + t < 2e-3) { s2 = s + 1e-3; t2 = t + 1e-3; }
            sfb__kind_eval(&kind, pt, pts, patch, cv, s2, t2, r2, dir);
            sfb__cross3(dir[0], dir[1], nrm);
            len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        }
        if (len > 0.0 && isfinite(len)) for (c = 0; c < 3; ++c) nrm[c] /= len;
        else nrm[0] = nrm[1] = nrm[2] = 0.0;
    }
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
        sfb__ref_eval_one(pt, pt->point_data, &locs[q], out->duu || out->duv || out->dvv, out->normal != NULL, res, nrm);
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
