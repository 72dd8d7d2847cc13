/* Uniform refinement: Catmull-Clark, Loop and bilinear with semi-sharp creases (DeRose et al.,
 * with OpenSubdiv 3.5's rules: fractional edge/vertex blending, uniform or Chaikin sharpness
 * decay, TRI_SUB_SMOOTH), compiled into stencil tables from the base vertices straight to the
 * last level, plus limit position and limit tangent tables at the last level's vertices.
 *
 * Child vertex order: children of vertices (same order), then of faces (Catmull-Clark and
 * bilinear only), then of edges. Child faces: for Catmull-Clark/bilinear face (v0..vn-1), the
 * quads (Vi, Ei, F, Ei-1) for i = 0..n-1; for Loop triangle (v0,v1,v2) the corners
 * (Vi, Ei, Ei-1) and then the middle (E0, E1, E2). Child edges: the two halves of each parent
 * edge (the half at its first vertex first), then the edges inside each face. */

/* ---- sharpness arithmetic, in float exactly as OpenSubdiv's Sdc::Crease ---- */
static float sfb__decrement(float s) {
    if (s <= 0.0f) return 0.0f;
    if (s >= SFB_SHARPNESS_INFINITE) return SFB_SHARPNESS_INFINITE;
    if (s > 1.0f) return s - 1.0f;
    return 0.0f;
}

static float sfb__sub_edge_at_vertex(float s, int chaikin, int vertex_edges, float semi_sum, int semi_count) {
    if (!chaikin || vertex_edges < 2) return sfb__decrement(s);
    if (s <= 0.0f) return 0.0f;
    if (s >= SFB_SHARPNESS_INFINITE) return SFB_SHARPNESS_INFINITE;
    if (semi_count > 1) {
        float avg = (semi_sum - s) / (float)(semi_count - 1);
        s = (0.75f * s) + (0.25f * avg);
    }
    s -= 1.0f;
    return s > 0.0f ? s : 0.0f;
}

/* The crease pair of a vertex: first and last incident edge with sharpness > 0 in the
 * vertex's edge order (OpenSubdiv's GetSharpEdgePairOfCrease). `sharp` is per incident edge. */
void sfb__crease_pair(const float *sharp, int n, int *a, int *b) {
    int i = 0, j = n - 1;
    while (i < n - 1 && sharp[i] <= 0.0f) ++i;
    while (j > 0 && sharp[j] <= 0.0f) --j;
    *a = i;
    *b = j;
}

/* Adds w * (vertex-vertex mask of `rule`) for vertex v; `sharp` holds the sharpness of v's
 * incident edges in ve order (parent or child values, as the rule requires). */
static void sfb__mask_vertex_rule(sfb__mask *m, const sfb__level *l, int v, int rule, const float *sharp,
                                  sfb_scheme scheme, double w) {
    int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0;
    int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0;
    int i;
    if (w == 0.0) return;
    if (rule == SFB__RULE_CORNER) {
        SFB__MASK_ADD(m, v, w);
        return;
    }
    if (rule == SFB__RULE_CREASE) {
        int a, b;
        sfb__crease_pair(sharp, ne, &a, &b);
        SFB__MASK_ADD(m, v, 0.75 * w);
        SFB__MASK_ADD(m, sfb__other_end(l, l->ve[e0 + a], v), 0.125 * w);
        SFB__MASK_ADD(m, sfb__other_end(l, l->ve[e0 + b], v), 0.125 * w);
        return;
    }
    /* smooth or dart: needs a manifold interior neighbourhood (guaranteed by sharpening:
     * boundary and non-manifold features are never smooth); guard anyway */
    if (nf != ne || nf == 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD)) {
        SFB__MASK_ADD(m, v, w);
        return;
    }
    if (scheme == SFB_SCHEME_LOOP) {
        double ew, vw;
        if (nf == 6) {
            ew = 0.0625;
            vw = 0.625;
        } else {
            double beta = 0.25 * cos(2.0 * SFB__PI / nf) + 0.375;
            ew = (0.625 - beta * beta) / nf;
            vw = 1.0 - ew * nf;
        }
        SFB__MASK_ADD(m, v, vw * w);
        for (i = 0; i < ne; ++i) SFB__MASK_ADD(m, sfb__other_end(l, l->ve[e0 + i], v), ew * w);
    } else {
        double n = nf, fw = 1.0 / (n * n);
        SFB__MASK_ADD(m, v, (n - 2.0) / n * w);
        for (i = 0; i < ne; ++i) SFB__MASK_ADD(m, sfb__other_end(l, l->ve[e0 + i], v), fw * w);
        for (i = 0; i < nf; ++i) sfb__mask_face(m, l, l->vf[f0 + i], fw * w);
    }
}

/* OpenSubdiv's Crease::ComputeFractionalWeightAtVertex. */
static float sfb__fractional_weight(float pvs, float cvs, int n, const float *ps, const float *cs, int chaikin) {
    int count = 0, i;
    float sum = 0.0f, fw;
    if (pvs > 0.0f && cvs <= 0.0f) { count = 1; sum = pvs; }
    for (i = 0; i < n; ++i) {
        int transition = chaikin ? (ps[i] > 0.0f && cs[i] <= 0.0f) : (ps[i] > 0.0f && ps[i] <= 1.0f);
        if (transition) { sum += ps[i]; count++; }
    }
    if (!count) return 0.0f;
    fw = sum / (float)count;
    return fw > 1.0f ? 1.0f : fw;
}

/* ---- one refinement step ---- */
typedef struct sfb__step {
    sfb_context *ctx;
    const sfb__refine_options *opt;
    const sfb__level *p;
    sfb__level *c;
    float *half;           /* child sharpness of each parent edge half: [2e + side] */
} sfb__step;

static int sfb__half_at(const sfb__level *p, int e, int v) { return p->ev[2 * e] == v ? 0 : 1; }

static sfb_result sfb__build_child_topology(sfb__step *st) {
    sfb_context *ctx = st->ctx;
    const sfb__level *p = st->p;
    sfb__level *c = st->c;
    int loop = st->opt->scheme == SFB_SCHEME_LOOP;
    int nvF = loop ? 0 : p->nf;               /* face-children count */
    int vE = p->nv + nvF;                     /* first edge-child */
    int f, i, e, v;
    size_t nf64, nfv64, ne64, nv64;
    int chaikin = st->opt->crease_method == SFB_CREASE_CHAIKIN;
    float *semi_sum = NULL;
    int *semi_cnt = NULL;

    nv64 = (size_t)p->nv + (size_t)nvF + (size_t)p->ne;
    if (loop) { nf64 = (size_t)p->nf * 4; nfv64 = nf64 * 3; ne64 = (size_t)p->ne * 2 + (size_t)p->nf * 3; }
    else { nf64 = (size_t)p->nfv; nfv64 = nf64 * 4; ne64 = (size_t)p->ne * 2 + (size_t)p->nfv; }
    if (nv64 > SFB_MAX_ELEMENTS || nfv64 > SFB_MAX_ELEMENTS || ne64 > SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "refined mesh would have %zu face-vertices, over the limit of %d", nfv64, SFB_MAX_ELEMENTS);
    memset(c, 0, sizeof *c);
    c->nv = (int)nv64; c->nf = (int)nf64; c->ne = (int)ne64; c->nfv = (int)nfv64;
    c->fv_off = (int *)sfb__alloc(ctx, (nf64 + 1) * sizeof(int));
    c->fv = (int *)sfb__alloc(ctx, (nfv64 + 1) * sizeof(int));
    c->fe = (int *)sfb__alloc(ctx, (nfv64 + 1) * sizeof(int));
    c->ev = (int *)sfb__alloc(ctx, (ne64 * 2 + 1) * sizeof(int));
    c->es = (float *)sfb__calloc(ctx, ne64 + 1, sizeof(float));
    c->vs = (float *)sfb__calloc(ctx, nv64 + 1, sizeof(float));
    c->fhole = (unsigned char *)sfb__calloc(ctx, nf64 + 1, 1);
    st->half = (float *)sfb__alloc(ctx, ((size_t)p->ne * 2 + 1) * sizeof(float));
    semi_sum = (float *)sfb__calloc(ctx, (size_t)p->nv + 1, sizeof(float));
    semi_cnt = (int *)sfb__calloc(ctx, (size_t)p->nv + 1, sizeof(int));
    if (!c->fv_off || !c->fv || !c->fe || !c->ev || !c->es || !c->vs || !c->fhole || !st->half || !semi_sum || !semi_cnt) {
        sfb__free(ctx, semi_sum); sfb__free(ctx, semi_cnt);
        return SFB_OUT_OF_MEMORY;
    }
    /* edge sharpness of the two halves of each parent edge */
    if (chaikin) {
        for (v = 0; v < p->nv; ++v)
            for (i = p->ve_off[v]; i < p->ve_off[v + 1]; ++i) {
                float s = p->es[p->ve[i]];
                if (s > 0.0f && s < SFB_SHARPNESS_INFINITE) { semi_sum[v] += s; semi_cnt[v]++; }
            }
    }
    for (e = 0; e < p->ne; ++e) {
        int side;
        for (side = 0; side < 2; ++side) {
            int pv = p->ev[2 * e + side];
            st->half[2 * e + side] = sfb__sub_edge_at_vertex(p->es[e], chaikin, p->ve_off[pv + 1] - p->ve_off[pv],
                                                             semi_sum[pv], semi_cnt[pv]);
        }
        c->ev[4 * e + 0] = p->ev[2 * e];
        c->ev[4 * e + 1] = vE + e;
        c->ev[4 * e + 2] = vE + e;
        c->ev[4 * e + 3] = p->ev[2 * e + 1];
        c->es[2 * e] = st->half[2 * e];
        c->es[2 * e + 1] = st->half[2 * e + 1];
    }
    sfb__free(ctx, semi_sum);
    sfb__free(ctx, semi_cnt);
    for (v = 0; v < p->nv; ++v) c->vs[v] = sfb__decrement(p->vs[v]);
    /* faces and interior edges */
    if (loop) {
        for (f = 0; f < p->nf; ++f) {
            int o = p->fv_off[f], ie = 2 * p->ne + 3 * f;
            for (i = 0; i < 3; ++i) {
                int cf = 4 * f + i, ip = (i + 2) % 3;
                int vi = p->fv[o + i], ei = p->fe[o + i], ep = p->fe[o + ip];
                c->fv_off[cf] = 3 * cf;
                c->fv[3 * cf + 0] = vi;
                c->fv[3 * cf + 1] = vE + ei;
                c->fv[3 * cf + 2] = vE + ep;
                c->fe[3 * cf + 0] = 2 * ei + sfb__half_at(p, ei, vi);
                c->fe[3 * cf + 1] = ie + i;
                c->fe[3 * cf + 2] = 2 * ep + sfb__half_at(p, ep, vi);
                c->ev[2 * (ie + i)] = vE + ei;
                c->ev[2 * (ie + i) + 1] = vE + ep;
                c->fhole[cf] = p->fhole[f];
            }
            {
                int cf = 4 * f + 3;
                c->fv_off[cf] = 3 * cf;
                for (i = 0; i < 3; ++i) {
                    c->fv[3 * cf + i] = vE + p->fe[o + i];
                    c->fe[3 * cf + i] = ie + (i + 1) % 3;
                }
                c->fhole[cf] = p->fhole[f];
            }
        }
        c->fv_off[c->nf] = c->nfv;
    } else {
        for (f = 0; f < p->nf; ++f) {
            int o = p->fv_off[f], n = p->fv_off[f + 1] - o, ie = 2 * p->ne + o;
            for (i = 0; i < n; ++i) {
                int cf = o + i, ip = (i + n - 1) % n;
                int vi = p->fv[o + i], ei = p->fe[o + i], ep = p->fe[o + ip];
                c->fv_off[cf] = 4 * cf;
                c->fv[4 * cf + 0] = vi;
                c->fv[4 * cf + 1] = vE + ei;
                c->fv[4 * cf + 2] = p->nv + f;
                c->fv[4 * cf + 3] = vE + ep;
                c->fe[4 * cf + 0] = 2 * ei + sfb__half_at(p, ei, vi);
                c->fe[4 * cf + 1] = ie + i;
                c->fe[4 * cf + 2] = ie + ip;
                c->fe[4 * cf + 3] = 2 * ep + sfb__half_at(p, ep, vi);
                c->ev[2 * (ie + i)] = vE + ei;
                c->ev[2 * (ie + i) + 1] = p->nv + f;
                c->fhole[cf] = p->fhole[f];
            }
        }
        c->fv_off[c->nf] = c->nfv;
    }
    {
        sfb_result r = sfb__level_complete(ctx, c);
        if (r != SFB_SUCCESS) return r;
    }
    sfb__level_compute_rules(c);
    return SFB_SUCCESS;
}

/* Local mask of child vertex `cv` in terms of parent vertices. */
static int sfb__child_mask(sfb__step *st, int cv, sfb__mask *m, float *ps, float *cs) {
    sfb_context *ctx = st->ctx;
    const sfb__level *p = st->p;
    const sfb__level *c = st->c;
    sfb_scheme scheme = st->opt->scheme;
    int loop = scheme == SFB_SCHEME_LOOP;
    int linear = scheme == SFB_SCHEME_BILINEAR || st->opt->linear;
    int nvF = loop ? 0 : p->nf;
    int i;
    m->n = 0;
    if (cv < p->nv) {
        /* vertex child */
        int v = cv, prule = p->vrule[v], crule = c->vrule[cv];
        int e0 = p->ve_off[v], ne = p->ve_off[v + 1] - e0;
        if (!sfb__mask_grow(ctx, m, 2 * sfb__mask_need_vertex(p, v) + 2)) return 0;
        if (linear) { SFB__MASK_ADD(m, v, 1.0); return 1; }
        for (i = 0; i < ne; ++i) {
            int e = p->ve[e0 + i];
            ps[i] = p->es[e];
            cs[i] = st->half[2 * e + sfb__half_at(p, e, v)];
        }
        if (prule == SFB__RULE_SMOOTH || prule == SFB__RULE_DART) {
            sfb__mask_vertex_rule(m, p, v, SFB__RULE_SMOOTH, ps, scheme, 1.0);
        } else if (crule == prule) {
            sfb__mask_vertex_rule(m, p, v, prule, ps, scheme, 1.0);
        } else {
            double pw = sfb__fractional_weight(p->vs[v], c->vs[cv], ne, ps, cs,
                                               st->opt->crease_method == SFB_CREASE_CHAIKIN);
            sfb__mask_vertex_rule(m, p, v, prule, ps, scheme, pw);
            sfb__mask_vertex_rule(m, p, v, crule == SFB__RULE_DART ? SFB__RULE_SMOOTH : crule, cs, scheme, 1.0 - pw);
        }
        return 1;
    }
    if (cv < p->nv + nvF) {
        int f = cv - p->nv, n = p->fv_off[f + 1] - p->fv_off[f];
        if (!sfb__mask_grow(ctx, m, n)) return 0;
        sfb__mask_face(m, p, f, 1.0);
        return 1;
    }
    {
        int e = cv - p->nv - nvF;
        int a = p->ev[2 * e], b = p->ev[2 * e + 1];
        int f0 = p->ef_off[e], nf = p->ef_off[e + 1] - f0;
        float s = p->es[e];
        double pw, cw;
        int need = 2;
        for (i = 0; i < nf; ++i) need += p->fv_off[p->ef[f0 + i] + 1] - p->fv_off[p->ef[f0 + i]];
        if (!sfb__mask_grow(ctx, m, need + 2)) return 0;
        if (linear || (s > 0.0f && c->vrule[cv] == SFB__RULE_CREASE)) {
            SFB__MASK_ADD(m, a, 0.5);
            SFB__MASK_ADD(m, b, 0.5);
            return 1;
        }
        /* smooth mask, blended with the midpoint by the parent sharpness when 0 < s */
        pw = s > 0.0f ? (double)s : 0.0;
        cw = 1.0 - pw;
        if (pw != 0.0) {
            SFB__MASK_ADD(m, a, 0.5 * pw);
            SFB__MASK_ADD(m, b, 0.5 * pw);
        }
        if (loop) {
            double vw = 0.375, fw = nf == 2 ? 0.125 : 0.125 * 2.0 / (nf ? nf : 1);
            SFB__MASK_ADD(m, a, vw * cw);
            SFB__MASK_ADD(m, b, vw * cw);
            for (i = 0; i < nf; ++i) {
                int f = p->ef[f0 + i], slot = p->ef_slot[f0 + i], o = p->fv_off[f];
                int n = p->fv_off[f + 1] - o;
                SFB__MASK_ADD(m, p->fv[o + (slot + 2) % n], fw * cw);
            }
        } else {
            double vw = 0.25, fw0 = 0.25, fw1 = 0.25;
            int tri = st->opt->triangle_rule == SFB_TRI_SMOOTH && nf == 2;
            if (tri) {
                int n0 = p->fv_off[p->ef[f0] + 1] - p->fv_off[p->ef[f0]];
                int n1 = p->fv_off[p->ef[f0 + 1] + 1] - p->fv_off[p->ef[f0 + 1]];
                tri = (n0 == 3) || (n1 == 3);
                if (tri) {
                    /* OpenSubdiv's CATMARK_SMOOTH_TRI_EDGE_WEIGHT, in float as it computes it */
                    float t0 = n0 == 3 ? 0.470f : 0.25f, t1 = n1 == 3 ? 0.470f : 0.25f;
                    float fw = 0.5f * (t0 + t1);
                    fw0 = fw1 = fw;
                    vw = 0.5f * (1.0f - 2.0f * fw);
                }
            }
            SFB__MASK_ADD(m, a, vw * cw);
            SFB__MASK_ADD(m, b, vw * cw);
            if (nf == 2) {
                sfb__mask_face(m, p, p->ef[f0], fw0 * cw);
                sfb__mask_face(m, p, p->ef[f0 + 1], fw1 * cw);
            } else {
                for (i = 0; i < nf; ++i) sfb__mask_face(m, p, p->ef[f0 + i], 0.5 / nf * cw);
            }
        }
        return 1;
    }
}

/* One step: refines `p` (whose vertices have composed rows `prow`) into `c`, with the
 * composed rows of c's vertices in `crow`. Progress is reported from p0 over a span of dp. */
sfb_result sfb__refine_step(sfb_context *ctx, const sfb__refine_options *opt, const sfb__level *p, const sfb__rows *prow,
                                   sfb__level *c, sfb__rows *crow, sfb__accum *A, sfb__mask *m, float *ps, float *cs,
                                   float p0, float dp) {
    return sfb__refine_step_local(ctx, opt, p, prow, c, crow, NULL, A, m, ps, cs, p0, dp);
}

/* sfb__refine_step that also gives the step's own rows (each child over the parent's
 * vertices: its local mask, duplicates merged) in `local` when that is not NULL. With prow
 * NULL (and local given) only the local rows are made: crow and A are not read. */
sfb_result sfb__refine_step_local(sfb_context *ctx, const sfb__refine_options *opt, const sfb__level *p, const sfb__rows *prow,
                                  sfb__level *c, sfb__rows *crow, sfb__rows *local, sfb__accum *A, sfb__mask *m, float *ps,
                                  float *cs, float p0, float dp) {
    sfb__step st;
    sfb_result r;
    int cv;
    st.ctx = ctx; st.opt = opt; st.p = p; st.c = c; st.half = NULL;
    r = sfb__build_child_topology(&st);
    if (r != SFB_SUCCESS) {
        sfb__free(ctx, st.half);
        return r == SFB_OUT_OF_MEMORY ? sfb__oom(ctx, "refinement topology") : r;
    }
    if (prow) {
        crow->rows = c->nv;
        crow->n = 0;
        crow->off = (size_t *)sfb__alloc(ctx, ((size_t)c->nv + 1) * sizeof(size_t));
        /* room for the child rows at once: a child's row spans about twice its parents' average
         * (it grows by doubling, copied by realloc, where this falls short; growing from 4 per row
         * copied the table five times over at level 3) */
        if (!crow->off || !sfb__rows_reserve(ctx, crow, (size_t)c->nv * (2 * (prow->n / (size_t)(prow->rows > 0 ? prow->rows : 1)) + 4) + 16)) {
            sfb__free(ctx, st.half);
            return sfb__oom(ctx, "stencil table");
        }
        crow->off[0] = 0;
    } else if (!local) {
        sfb__free(ctx, st.half);
        return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "refinement step with neither composed nor local rows");
    }
    if (local) {
        memset(local, 0, sizeof *local);
        local->rows = c->nv;
        local->off = (size_t *)sfb__alloc(ctx, ((size_t)c->nv + 1) * sizeof(size_t));
        if (!local->off || !sfb__rows_reserve(ctx, local, (size_t)c->nv * 8 + 16)) {
            sfb__free(ctx, st.half);
            return sfb__oom(ctx, "stencil table");
        }
        local->off[0] = 0;
    }
    for (cv = 0; cv < c->nv; ++cv) {
        if (!sfb__child_mask(&st, cv, m, ps, cs) || (prow && !sfb__compose_row(ctx, A, prow, m, crow, cv)) ||
            (local && !sfb__rows_append_mask(ctx, local, m, cv))) {
            sfb__free(ctx, st.half);
            return sfb__oom(ctx, "stencil table");
        }
        if ((cv & 0xffff) == 0xffff) {
            r = sfb__progress(ctx, p0 + dp * (float)cv / (float)c->nv, "refine");
            if (r != SFB_SUCCESS) { sfb__free(ctx, st.half); return r; }
        }
    }
    sfb__free(ctx, st.half);
    return SFB_SUCCESS;
}

/* Limit tangent masks of a crease vertex for the side whose faces lie between its crease
 * edges a and b (in v's edge order; b may exceed the edge count to go around an interior
 * vertex: indices are taken modulo it): m1 along the crease (from b's end towards a's), m2
 * into that side. The other side of an interior crease is (b, a + edge count). */
void sfb__crease_tangent_masks(const sfb__level *l, int v, int a, int b, int loop, sfb__mask *m1, sfb__mask *m2) {
    int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0;
    int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0;
    double tscale = loop ? 3.0 : 1.0;
    int i, k = b - a - 1; /* interior edges between the crease edges */
#define SFB__E(i) sfb__other_end(l, l->ve[e0 + (i) % ne], v)
#define SFB__HASF(i) ((i) % ne < nf)
#define SFB__D(i) l->fv[l->fv_off[l->vf[f0 + (i) % ne]] + (l->vf_slot[f0 + (i) % ne] + 2) % (l->fv_off[l->vf[f0 + (i) % ne] + 1] - l->fv_off[l->vf[f0 + (i) % ne]])]
    SFB__MASK_ADD(m1, SFB__E(a), 0.5 * tscale);
    SFB__MASK_ADD(m1, SFB__E(b), -0.5 * tscale);
    if (loop) {
        if (k == 0) {
            SFB__MASK_ADD(m2, v, -6.0); SFB__MASK_ADD(m2, SFB__E(a), 3.0); SFB__MASK_ADD(m2, SFB__E(b), 3.0);
        } else if (k == 1) {
            SFB__MASK_ADD(m2, v, -3.0); SFB__MASK_ADD(m2, SFB__E(a + 1), 3.0);
        } else if (k == 2) {
            double r3 = 1.73205080756887729352;
            SFB__MASK_ADD(m2, v, -r3); SFB__MASK_ADD(m2, SFB__E(a), -r3 / 2); SFB__MASK_ADD(m2, SFB__E(b), -r3 / 2);
            SFB__MASK_ADD(m2, SFB__E(a + 1), r3); SFB__MASK_ADD(m2, SFB__E(a + 2), r3);
        } else {
            double th = SFB__PI / (k + 1), cwt = -3.0 * sin(th), ec = -3.0 * 2.0 * (cos(th) - 1.0);
            SFB__MASK_ADD(m2, SFB__E(a), cwt); SFB__MASK_ADD(m2, SFB__E(b), cwt);
            for (i = 1; i <= k; ++i) SFB__MASK_ADD(m2, SFB__E(a + i), ec * sin(i * th));
        }
    } else {
        if (k == 0) {
            SFB__MASK_ADD(m2, v, -6.0); SFB__MASK_ADD(m2, SFB__E(a), 3.0); SFB__MASK_ADD(m2, SFB__E(b), 3.0);
        } else if (k == 1) {
            SFB__MASK_ADD(m2, v, -4.0 / 6.0);
            SFB__MASK_ADD(m2, SFB__E(a), -1.0 / 6.0); SFB__MASK_ADD(m2, SFB__E(a + 1), 4.0 / 6.0);
            SFB__MASK_ADD(m2, SFB__E(b), -1.0 / 6.0);
            if (SFB__HASF(a)) SFB__MASK_ADD(m2, SFB__D(a), 1.0 / 6.0);
            if (SFB__HASF(a + 1)) SFB__MASK_ADD(m2, SFB__D(a + 1), 1.0 / 6.0);
        } else {
            double kk = k + 1, th = SFB__PI / kk, ct = cos(th), st = sin(th);
            double den = 1.0 / (kk * (3.0 + ct)), R = (ct + 1.0) / st;
            SFB__MASK_ADD(m2, v, 4.0 * R * (ct - 1.0) * den);
            SFB__MASK_ADD(m2, SFB__E(a), -R * (1.0 + 2.0 * ct) * den);
            SFB__MASK_ADD(m2, SFB__E(b), -R * (1.0 + 2.0 * ct) * den);
            if (SFB__HASF(a)) SFB__MASK_ADD(m2, SFB__D(a), st * den);
            for (i = 1; i < kk; ++i) {
                double si = sin(i * th), si1 = sin((i + 1) * th);
                SFB__MASK_ADD(m2, SFB__E(a + i), 4.0 * si * den);
                if (SFB__HASF(a + i)) SFB__MASK_ADD(m2, SFB__D(a + i), (si + si1) * den);
            }
        }
    }
#undef SFB__E
#undef SFB__HASF
#undef SFB__D
}

/* ---- limit masks at the last level ---- */
void sfb__limit_masks(const sfb__level *l, int v, sfb_scheme scheme, sfb__mask *mp, sfb__mask *m1, sfb__mask *m2) {
    int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0;
    int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0;
    int rule = l->vrule[v], i;
    int loop = scheme == SFB_SCHEME_LOOP;
    double tscale = loop ? 3.0 : 1.0;
    mp->n = m1->n = m2->n = 0;
    if (scheme == SFB_SCHEME_BILINEAR || ne == 0) rule = SFB__RULE_CORNER;
    if ((rule == SFB__RULE_SMOOTH || rule == SFB__RULE_DART) &&
        (nf != ne || (l->vtag[v] & SFB__TAG_NONMANIFOLD) || (!loop && nf == 2)))
        rule = SFB__RULE_CORNER; /* Catmull-Clark valence 2 is a corner for the limit (as OpenSubdiv) */
    if (rule == SFB__RULE_CORNER) {
        SFB__MASK_ADD(mp, v, 1.0);
        if (ne >= 2) {
            SFB__MASK_ADD(m1, v, -tscale);
            SFB__MASK_ADD(m1, sfb__other_end(l, l->ve[e0], v), tscale);
            SFB__MASK_ADD(m2, v, -tscale);
            SFB__MASK_ADD(m2, sfb__other_end(l, l->ve[e0 + 1], v), tscale);
        }
        return;
    }
    if (rule == SFB__RULE_CREASE) {
        float sharp[SFB_MAX_VALENCE + 1];
        int a, b;
        for (i = 0; i < ne && i <= SFB_MAX_VALENCE; ++i) sharp[i] = l->es[l->ve[e0 + i]];
        sfb__crease_pair(sharp, ne, &a, &b);
        SFB__MASK_ADD(mp, v, 2.0 / 3.0);
        SFB__MASK_ADD(mp, sfb__other_end(l, l->ve[e0 + a], v), 1.0 / 6.0);
        SFB__MASK_ADD(mp, sfb__other_end(l, l->ve[e0 + b], v), 1.0 / 6.0);
        sfb__crease_tangent_masks(l, v, a, b, loop, m1, m2);
        return;
    }
    /* smooth */
#define SFB__E(i) sfb__other_end(l, l->ve[e0 + (i)], v)
#define SFB__D(i) l->fv[l->fv_off[l->vf[f0 + (i)]] + (l->vf_slot[f0 + (i)] + 2) % (l->fv_off[l->vf[f0 + (i)] + 1] - l->fv_off[l->vf[f0 + (i)]])]
    if (loop) {
        double ew, vw;
        if (nf == 6) {
            ew = 1.0 / 12.0;
            vw = 0.5;
        } else {
            double beta = 0.25 * cos(2.0 * SFB__PI / nf) + 0.375;
            double gamma = (0.625 - beta * beta) / nf;
            ew = 1.0 / (nf + 3.0 / (8.0 * gamma));
            vw = 1.0 - ew * nf;
        }
        SFB__MASK_ADD(mp, v, vw);
        for (i = 0; i < ne; ++i) {
            double al = 2.0 * SFB__PI * i / ne;
            SFB__MASK_ADD(mp, SFB__E(i), ew);
            SFB__MASK_ADD(m1, SFB__E(i), cos(al));
            SFB__MASK_ADD(m2, SFB__E(i), sin(al));
        }
    } else {
        double n = nf, fw = 1.0 / (n * (n + 5.0)), ew = 4.0 * fw;
        double th = 2.0 * SFB__PI / n, ct = cos(th), ch = cos(0.5 * th);
        double lambda = 5.0 / 16.0 + (ct + ch * sqrt(2.0 * (9.0 + ct))) / 16.0;
        double fscale = 1.0 / (4.0 * lambda - 1.0);
        if (nf == 4) { fw = 1.0 / 36.0; ew = 1.0 / 9.0; }
        SFB__MASK_ADD(mp, v, nf == 4 ? 4.0 / 9.0 : 1.0 - n * (ew + fw));
        for (i = 0; i < nf; ++i) {
            int ip = (i + nf - 1) % nf;
            double c0 = cos(i * th), c1 = cos((i + 1) * th);
            double t1e = 4.0 * c0, t1f = fscale * (c0 + c1);
            double cp0 = cos(ip * th), cp1 = cos((ip + 1) * th);
            double t2e = 4.0 * cp0, t2f = fscale * (cp0 + cp1);
            if (nf == 4) {
                static const double E1[4] = {4, 0, -4, 0}, F1[4] = {1, -1, -1, 1};
                static const double E2[4] = {0, 4, 0, -4}, F2[4] = {1, 1, -1, -1};
                t1e = E1[i]; t1f = F1[i]; t2e = E2[i]; t2f = F2[i];
            }
            SFB__MASK_ADD(mp, SFB__E(i), ew);
            SFB__MASK_ADD(mp, SFB__D(i), fw);
            SFB__MASK_ADD(m1, SFB__E(i), t1e);
            SFB__MASK_ADD(m1, SFB__D(i), t1f);
            SFB__MASK_ADD(m2, SFB__E(i), t2e);
            SFB__MASK_ADD(m2, SFB__D(i), t2f);
        }
    }
#undef SFB__E
#undef SFB__D
}


sfb_result sfb__refine(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int level,
                       sfb__level *top, sfb__stencils *vt, sfb__stencils *lt, float prog0, float prog1) {
    return sfb__refine_keep_levels(ctx, base, opt, level, top, vt, lt, NULL, prog0, prog1);
}

void sfb__refine_kept_free(sfb_context *ctx, sfb__refine_kept *keep, int level) {
    int k;
    for (k = 0; k < level; ++k) {
        sfb__level_free(ctx, &keep->lev[k]);
        sfb__stencils_free(ctx, &keep->T[k]);
    }
}

sfb_result sfb__refine_keep_levels(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int level,
                                   sfb__level *top, sfb__stencils *vt, sfb__stencils *lt, sfb__refine_kept *keep, float prog0,
                                   float prog1) {
    sfb__rows prow, crow, local;
    sfb__level cur, next;
    sfb__accum A;
    sfb__mask m;
    float *ps = NULL, *cs = NULL;
    sfb_result r = SFB_SUCCESS;
    int L, i, owns_cur = 0;
    memset(&prow, 0, sizeof prow); memset(&crow, 0, sizeof crow); memset(&local, 0, sizeof local);
    memset(&A, 0, sizeof A); memset(&m, 0, sizeof m);
    memset(&next, 0, sizeof next);
    cur = *base;
    A.acc = (double *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(double));
    A.mark = (unsigned *)sfb__calloc(ctx, (size_t)base->nv + 1, sizeof(unsigned));
    A.touched = (int *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(int));
    ps = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    cs = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    prow.rows = base->nv;
    prow.off = (size_t *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(size_t));
    if (!A.acc || !A.mark || !A.touched || !ps || !cs || !prow.off || !sfb__rows_reserve(ctx, &prow, (size_t)base->nv + 1)) {
        r = sfb__oom(ctx, "refinement");
        goto done;
    }
    for (i = 0; i < base->nv; ++i) { prow.off[i] = (size_t)i; prow.idx[i] = i; prow.w[i] = 1.0; }
    prow.off[base->nv] = (size_t)base->nv;
    prow.n = (size_t)base->nv;
    for (L = 0; L < level; ++L) {
        r = sfb__progress(ctx, prog0 + (prog1 - prog0) * (float)L / (float)(level + 1), "refine");
        if (r != SFB_SUCCESS) goto done;
        r = sfb__refine_step_local(ctx, opt, &cur, &prow, &next, &crow, keep ? &local : NULL, &A, &m, ps, cs,
                                   prog0 + (prog1 - prog0) * (float)L / (float)(level + 1), (prog1 - prog0) / (float)(level + 1));
        if (r != SFB_SUCCESS) goto done;
        if (keep) {
            r = sfb__rows_move_to_stencils(ctx, &local, cur.nv, &keep->T[L]);
            sfb__rows_free(ctx, &local);
            if (r != SFB_SUCCESS) { if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "stencil table"); goto done; }
        }
        sfb__rows_free(ctx, &prow);
        prow = crow;
        memset(&crow, 0, sizeof crow);
        if (owns_cur && keep) keep->lev[L] = cur; /* handed over: level L of the caller's copy */
        else if (owns_cur) sfb__level_free(ctx, &cur);
        cur = next;
        owns_cur = 1;
        memset(&next, 0, sizeof next);
    }
    /* the limit tables below compose over prow: moved only where there are none */
    r = lt ? sfb__rows_to_stencils(ctx, &prow, base->nv, vt) : sfb__rows_move_to_stencils(ctx, &prow, base->nv, vt);
    if (r != SFB_SUCCESS) { if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "stencil table"); goto done; }
    if (lt) {
        sfb__rows out[3];
        sfb__mask mm[3];
        int t, v;
        memset(out, 0, sizeof out);
        memset(mm, 0, sizeof mm);
        for (t = 0; t < 3 && r == SFB_SUCCESS; ++t) {
            out[t].rows = cur.nv;
            out[t].off = (size_t *)sfb__alloc(ctx, ((size_t)cur.nv + 1) * sizeof(size_t));
            if (!out[t].off) r = sfb__oom(ctx, "limit stencil table");
            else out[t].off[0] = 0;
        }
        for (v = 0; v < cur.nv && r == SFB_SUCCESS; ++v) {
            int need = 3 * sfb__mask_need_vertex(&cur, v) + 8;
            for (t = 0; t < 3; ++t)
                if (!sfb__mask_grow(ctx, &mm[t], need)) r = sfb__oom(ctx, "limit stencil table");
            if (r != SFB_SUCCESS) break;
            sfb__limit_masks(&cur, v, opt->scheme, &mm[0], &mm[1], &mm[2]);
            for (t = 0; t < 3; ++t)
                if (!sfb__compose_row(ctx, &A, &prow, &mm[t], &out[t], v)) { r = sfb__oom(ctx, "limit stencil table"); break; }
        }
        for (t = 0; t < 3; ++t) {
            if (r == SFB_SUCCESS) {
                r = sfb__rows_move_to_stencils(ctx, &out[t], base->nv, &lt[t]);
                if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "limit stencil table");
            }
            sfb__rows_free(ctx, &out[t]);
            sfb__free(ctx, mm[t].idx);
            sfb__free(ctx, mm[t].w);
        }
        if (r != SFB_SUCCESS) goto done;
    }
    if (owns_cur) {
        *top = cur;
        owns_cur = 0;
    } else {
        /* level 0: the caller's base is the top; hand back an independent copy (the base is
         * already prepared, so preparing it again changes nothing) */
        r = sfb__level_prepare(ctx, base, 0, 0, top);
    }
done:
    if (owns_cur) sfb__level_free(ctx, &cur);
    sfb__level_free(ctx, &next);
    sfb__rows_free(ctx, &prow);
    sfb__rows_free(ctx, &crow);
    sfb__rows_free(ctx, &local);
    sfb__free(ctx, A.acc); sfb__free(ctx, A.mark); sfb__free(ctx, A.touched);
    sfb__free(ctx, m.idx); sfb__free(ctx, m.w);
    sfb__free(ctx, ps); sfb__free(ctx, cs);
    if (r != SFB_SUCCESS) {
        sfb__stencils_free(ctx, vt);
        if (lt) { sfb__stencils_free(ctx, &lt[0]); sfb__stencils_free(ctx, &lt[1]); sfb__stencils_free(ctx, &lt[2]); }
        if (keep) sfb__refine_kept_free(ctx, keep, level);
    }
    return r;
}
