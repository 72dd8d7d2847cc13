/* Topology of one level: adjacency, counter-clockwise ordering around manifold vertices,
 * boundary and non-manifold tags, vertex rules. */

void sfb__level_free(sfb_context *ctx, sfb__level *l) {
    sfb__free(ctx, l->fv_off); sfb__free(ctx, l->fv); sfb__free(ctx, l->fe); sfb__free(ctx, l->ev);
    sfb__free(ctx, l->ef_off); sfb__free(ctx, l->ef); sfb__free(ctx, l->ef_slot);
    sfb__free(ctx, l->vf_off); sfb__free(ctx, l->vf); sfb__free(ctx, l->vf_slot);
    sfb__free(ctx, l->ve_off); sfb__free(ctx, l->ve);
    sfb__free(ctx, l->es); sfb__free(ctx, l->vs);
    sfb__free(ctx, l->etag); sfb__free(ctx, l->vtag); sfb__free(ctx, l->vrule); sfb__free(ctx, l->fhole);
    memset(l, 0, sizeof *l);
}

/* OpenSubdiv's vertex rule: any vertex sharpness makes a corner; else by sharp edge count. */
int sfb__rule_from(float vertex_sharpness, int sharp_edge_count) {
    if (vertex_sharpness > 0.0f) return SFB__RULE_CORNER;
    if (sharp_edge_count > 2) return SFB__RULE_CORNER;
    return 1 << sharp_edge_count;
}

void sfb__level_compute_rules(sfb__level *l) {
    int v, i;
    for (v = 0; v < l->nv; ++v) {
        int sharp = 0;
        for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i) sharp += l->es[l->ve[i]] > 0.0f;
        l->vrule[v] = (unsigned char)sfb__rule_from(l->vs[v], sharp);
    }
}

/* Walk the faces around a manifold candidate; returns 1 and reorders vf/vf_slot/ve when the
 * faces form one fan (or one cycle). */
static int sfb__order_vertex(sfb__level *l, int v, int *tf, int *ts, int *te) {
    int f0 = l->vf_off[v], k = l->vf_off[v + 1] - f0;
    int e0 = l->ve_off[v], m = l->ve_off[v + 1] - e0;
    int i, start = -1, boundary = (m == k + 1);
    int f, slot, count = 0;
    if (k == 0) return 0;
    if (boundary) {
        /* start at the face whose outgoing edge (v -> next) is a boundary edge */
        for (i = 0; i < k; ++i) {
            int ff = l->vf[f0 + i], s = l->vf_slot[f0 + i];
            int eo = l->fe[l->fv_off[ff] + s];
            if (l->ef_off[eo + 1] - l->ef_off[eo] == 1) { start = i; break; }
        }
        if (start < 0) return 0;
    } else {
        start = 0;
    }
    f = l->vf[f0 + start];
    slot = l->vf_slot[f0 + start];
    for (;;) {
        int n = l->fv_off[f + 1] - l->fv_off[f];
        int eo = l->fe[l->fv_off[f] + slot];
        int ei = l->fe[l->fv_off[f] + (slot + n - 1) % n];
        int nf, a, b, g, gs = -1;
        if (count >= k) return 0;
        tf[count] = f; ts[count] = slot; te[count] = eo;
        ++count;
        a = l->ef_off[ei]; b = l->ef_off[ei + 1];
        if (b - a == 1) {
            if (!boundary) return 0;
            te[count] = ei;
            break;
        }
        g = l->ef[a] == f ? l->ef[a + 1] : l->ef[a];
        if (g == f) return 0;
        /* the slot of v in g */
        {
            int q, gn = l->fv_off[g + 1] - l->fv_off[g];
            for (q = 0; q < gn; ++q)
                if (l->fv[l->fv_off[g] + q] == v) { gs = q; break; }
        }
        if (gs < 0) return 0;
        nf = g;
        if (!boundary && nf == l->vf[f0 + start]) break;
        f = nf;
        slot = gs;
    }
    if (count != k) return 0;
    /* the walk visited k distinct faces; with no non-manifold edge their outgoing edges are
     * distinct too, so the count decides */
    if ((boundary ? count + 1 : count) != m) return 0;
    memcpy(l->vf + f0, tf, (size_t)k * sizeof(int));
    memcpy(l->vf_slot + f0, ts, (size_t)k * sizeof(int));
    memcpy(l->ve + e0, te, (size_t)m * sizeof(int));
    return 1;
}

/* sfb__level_complete, or with ordered set sfb__level_complete_ordered: the rings are the
 * caller's, and only checked by their counts */
static sfb_result sfb__level_finish(sfb_context *ctx, sfb__level *l, int ordered) {
    int v, f, e, i, maxval = 0;
    int *fill = NULL, *tf = NULL, *ts = NULL, *te = NULL;
    l->nfv = l->fv_off[l->nf];
    l->ef_off = (int *)sfb__calloc(ctx, (size_t)l->ne + 1, sizeof(int));
    l->ef = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    l->ef_slot = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    if (!ordered) {
        l->vf_off = (int *)sfb__calloc(ctx, (size_t)l->nv + 1, sizeof(int));
        l->vf = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
        l->vf_slot = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
        l->ve_off = (int *)sfb__calloc(ctx, (size_t)l->nv + 1, sizeof(int));
        l->ve = (int *)sfb__alloc(ctx, ((size_t)l->ne * 2 + 1) * sizeof(int));
    }
    l->etag = (unsigned char *)sfb__calloc(ctx, (size_t)l->ne + 1, 1);
    l->vtag = (unsigned char *)sfb__calloc(ctx, (size_t)l->nv + 1, 1);
    l->vrule = (unsigned char *)sfb__calloc(ctx, (size_t)l->nv + 1, 1);
    if (!l->fhole) l->fhole = (unsigned char *)sfb__calloc(ctx, (size_t)l->nf + 1, 1);
    fill = (int *)sfb__calloc(ctx, (size_t)(l->nv > l->ne ? l->nv : l->ne) + 1, sizeof(int));
    if (!l->ef_off || !l->ef || !l->ef_slot || !l->vf_off || !l->vf || !l->vf_slot || !l->ve_off || !l->ve ||
        !l->etag || !l->vtag || !l->vrule || !l->fhole || !fill)
        goto oom;
    /* edge -> faces */
    for (i = 0; i < l->nfv; ++i) l->ef_off[l->fe[i] + 1]++;
    for (e = 0; e < l->ne; ++e) l->ef_off[e + 1] += l->ef_off[e];
    for (f = 0; f < l->nf; ++f)
        for (i = l->fv_off[f]; i < l->fv_off[f + 1]; ++i) {
            int ed = l->fe[i], at = l->ef_off[ed] + fill[ed]++;
            l->ef[at] = f;
            l->ef_slot[at] = i - l->fv_off[f];
        }
    if (ordered) goto tags;
    /* vertex -> faces (face order) */
    for (i = 0; i < l->nfv; ++i) l->vf_off[l->fv[i] + 1]++;
    for (v = 0; v < l->nv; ++v) l->vf_off[v + 1] += l->vf_off[v];
    memset(fill, 0, sizeof(int) * (size_t)l->nv);
    for (f = 0; f < l->nf; ++f)
        for (i = l->fv_off[f]; i < l->fv_off[f + 1]; ++i) {
            int vv = l->fv[i], at = l->vf_off[vv] + fill[vv]++;
            l->vf[at] = f;
            l->vf_slot[at] = i - l->fv_off[f];
        }
    /* vertex -> edges (edge order) */
    for (e = 0; e < l->ne; ++e) { l->ve_off[l->ev[2 * e] + 1]++; l->ve_off[l->ev[2 * e + 1] + 1]++; }
    for (v = 0; v < l->nv; ++v) l->ve_off[v + 1] += l->ve_off[v];
    memset(fill, 0, sizeof(int) * (size_t)l->nv);
    for (e = 0; e < l->ne; ++e) {
        int a = l->ev[2 * e], b = l->ev[2 * e + 1];
        l->ve[l->ve_off[a] + fill[a]++] = e;
        l->ve[l->ve_off[b] + fill[b]++] = e;
    }
tags:
    /* edge tags: boundary (one face), non-manifold (more than two faces, two faces running the
     * same direction, or no face at all) */
    for (e = 0; e < l->ne; ++e) {
        int a = l->ef_off[e], n = l->ef_off[e + 1] - a;
        if (n == 1) l->etag[e] |= SFB__TAG_BOUNDARY;
        /* a degenerate edge (both ends the same vertex, from a face that repeats a vertex) is
         * non-manifold, as OpenSubdiv treats it */
        if (n == 0 || n > 2 || l->ev[2 * e] == l->ev[2 * e + 1]) l->etag[e] |= SFB__TAG_NONMANIFOLD;
        if (n == 2) {
            int f1 = l->ef[a], s1 = l->ef_slot[a], f2 = l->ef[a + 1], s2 = l->ef_slot[a + 1];
            if (l->fv[l->fv_off[f1] + s1] == l->fv[l->fv_off[f2] + s2]) l->etag[e] |= SFB__TAG_NONMANIFOLD;
        }
    }
    for (v = 0; v < l->nv; ++v) {
        int d = l->ve_off[v + 1] - l->ve_off[v];
        if (d > maxval) maxval = d;
    }
    tf = (int *)sfb__alloc(ctx, ((size_t)maxval + 2) * sizeof(int));
    ts = (int *)sfb__alloc(ctx, ((size_t)maxval + 2) * sizeof(int));
    te = (int *)sfb__alloc(ctx, ((size_t)maxval + 2) * sizeof(int));
    if (!tf || !ts || !te) goto oom;
    for (v = 0; v < l->nv; ++v) {
        int k = l->vf_off[v + 1] - l->vf_off[v], m = l->ve_off[v + 1] - l->ve_off[v];
        int nm = 0, bnd = 0;
        for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i) {
            if (l->etag[l->ve[i]] & SFB__TAG_NONMANIFOLD) nm = 1;
            if (l->etag[l->ve[i]] & SFB__TAG_BOUNDARY) bnd++;
        }
        if (bnd) l->vtag[v] |= SFB__TAG_BOUNDARY;
        if (nm || k == 0 || !((m == k && bnd == 0) || (m == k + 1 && bnd == 2)) || (!ordered && !sfb__order_vertex(l, v, tf, ts, te)))
            l->vtag[v] |= SFB__TAG_NONMANIFOLD;
    }
    sfb__free(ctx, fill); sfb__free(ctx, tf); sfb__free(ctx, ts); sfb__free(ctx, te);
    return SFB_SUCCESS;
oom:
    sfb__free(ctx, fill); sfb__free(ctx, tf); sfb__free(ctx, ts); sfb__free(ctx, te);
    return sfb__oom(ctx, "building topology");
}

sfb_result sfb__level_complete(sfb_context *ctx, sfb__level *l) { return sfb__level_finish(ctx, l, 0); }
sfb_result sfb__level_complete_ordered(sfb_context *ctx, sfb__level *l) { return sfb__level_finish(ctx, l, 1); }

static void *sfb__dup(sfb_context *ctx, const void *p, size_t bytes) {
    void *q = sfb__alloc(ctx, bytes ? bytes : 1);
    if (q && bytes) memcpy(q, p, bytes);
    return q;
}

/* Applies OpenSubdiv's preparation of the base level: faces at uninterpolated boundaries
 * become holes (boundary NONE), boundary and non-manifold edges become infinitely sharp,
 * topological corners (EDGE_AND_CORNER) and non-manifold vertices infinitely sharp, except
 * a vertex on a non-manifold crease (two non-manifold edges, no boundary, more faces than
 * edges), which keeps its own sharpness. */
sfb_result sfb__level_prepare(sfb_context *ctx, const sfb__level *s, int sharpen_corners, int make_boundary_holes,
                              sfb__level *d) {
    int v, e, i;
    memset(d, 0, sizeof *d);
    d->nv = s->nv; d->nf = s->nf; d->ne = s->ne; d->nfv = s->nfv;
#define SFB__DUP(field, count, type) d->field = (type *)sfb__dup(ctx, s->field, (size_t)(count) * sizeof(type))
    SFB__DUP(fv_off, s->nf + 1, int); SFB__DUP(fv, s->nfv, int); SFB__DUP(fe, s->nfv, int);
    SFB__DUP(ev, 2 * s->ne, int); SFB__DUP(ef_off, s->ne + 1, int); SFB__DUP(ef, s->nfv, int);
    SFB__DUP(ef_slot, s->nfv, int); SFB__DUP(vf_off, s->nv + 1, int); SFB__DUP(vf, s->nfv, int);
    SFB__DUP(vf_slot, s->nfv, int); SFB__DUP(ve_off, s->nv + 1, int); SFB__DUP(ve, 2 * s->ne, int);
    SFB__DUP(es, s->ne, float); SFB__DUP(vs, s->nv, float); SFB__DUP(etag, s->ne, unsigned char);
    SFB__DUP(vtag, s->nv, unsigned char); SFB__DUP(vrule, s->nv, unsigned char); SFB__DUP(fhole, s->nf, unsigned char);
#undef SFB__DUP
    if (!d->fv_off || !d->fv || !d->fe || !d->ev || !d->ef_off || !d->ef || !d->ef_slot || !d->vf_off || !d->vf ||
        !d->vf_slot || !d->ve_off || !d->ve || !d->es || !d->vs || !d->etag || !d->vtag || !d->vrule || !d->fhole) {
        sfb__level_free(ctx, d);
        return sfb__oom(ctx, "copying topology");
    }
    if (make_boundary_holes) {
        for (v = 0; v < d->nv; ++v) {
            int k = d->vf_off[v + 1] - d->vf_off[v], m = d->ve_off[v + 1] - d->ve_off[v], exclude = 0;
            if (k == m && !(d->vtag[v] & SFB__TAG_NONMANIFOLD)) continue;
            for (i = d->ve_off[v]; i < d->ve_off[v + 1] && !exclude; ++i) {
                int ed = d->ve[i];
                exclude = (d->ef_off[ed + 1] - d->ef_off[ed] == 1) && d->es[ed] < SFB_SHARPNESS_INFINITE;
            }
            if (exclude)
                for (i = d->vf_off[v]; i < d->vf_off[v + 1]; ++i) d->fhole[d->vf[i]] = 1;
        }
    }
    for (e = 0; e < d->ne; ++e) {
        if (d->etag[e] & (SFB__TAG_BOUNDARY | SFB__TAG_NONMANIFOLD)) d->es[e] = SFB_SHARPNESS_INFINITE;
        if (d->es[e] > SFB_SHARPNESS_INFINITE) d->es[e] = SFB_SHARPNESS_INFINITE;
    }
    for (v = 0; v < d->nv; ++v) {
        if (sfb__level_forced_sharp(d, v, sharpen_corners)) d->vs[v] = SFB_SHARPNESS_INFINITE;
        if (d->vs[v] > SFB_SHARPNESS_INFINITE) d->vs[v] = SFB_SHARPNESS_INFINITE;
    }
    sfb__level_compute_rules(d);
    return SFB_SUCCESS;
}

int sfb__level_forced_sharp(const sfb__level *d, int v, int sharpen_corners) {
    const int k = d->vf_off[v + 1] - d->vf_off[v], m = d->ve_off[v + 1] - d->ve_off[v];
    int nm_edges = 0, bnd_edges = 0, i;
    for (i = d->ve_off[v]; i < d->ve_off[v + 1]; ++i) {
        nm_edges += (d->etag[d->ve[i]] & SFB__TAG_NONMANIFOLD) != 0;
        bnd_edges += (d->etag[d->ve[i]] & SFB__TAG_BOUNDARY) != 0;
    }
    if (k == 1 && m == 2) return sharpen_corners;
    return (d->vtag[v] & SFB__TAG_NONMANIFOLD) && !(nm_edges == 2 && bnd_edges == 0 && k > m);
}

/* The end of edge e that is not v. */
int sfb__other_end(const sfb__level *l, int e, int v) {
    return l->ev[2 * e] == v ? l->ev[2 * e + 1] : l->ev[2 * e];
}
