/* Subdivision shading (seed 001): subdivided normals N_S with crease regions, blend weights b
 * (variants A/B, darts smooth/sharp, semi-sharp re-seeding) and the blended normals
 * N_B = normalize((1 - b^p) N_L + b^p N_S).
 *
 * Everything that depends on topology and sharpness only is compiled here, on the CPU, into
 * flat tables when the surface is created (SFB_REFINE_SHADING):
 *   - the blend weights b of every output vertex (numbers: they depend on no position);
 *   - a stencil table from the normals-level sources (one normal per vertex region) to N_S of
 *     the output vertices, its rows with b > 0 first, so that N_S is computed only there;
 *   - local limit masks (limit position, two tangents) of every output vertex over the refined
 *     vertices: one row per region at split vertices;
 *   - the split of vertices along infinitely sharp creases (one output vertex per region).
 * sfb_surface_shade then runs: refined positions (vertex table), normals-level positions, face
 * normals averaged per region (CPU: one pass over the coarse level's faces), the N_S rows, the
 * limit rows, and the backend's finish_normals kernel.
 *
 * Averaging (sfb_shading_options.averaging): LINEAR, the default, is the above: N_S is one
 * composed table run by the backend. RENORMALIZED and SPHERICAL compute N_S one level at a
 * time instead, because a normalisation (or a spherical mean) between the levels is not linear
 * and cannot be folded into one table: the build keeps one region table per step instead of
 * the composed one (the same region masks the composed table is made of, each over the level
 * below alone; the last step's rows are the output rows, in the composed table's order) and
 * sfb_surface_shade runs them in the core, on the CPU in double, for every backend - each new
 * normal is normalize(sum w_i n_i) (RENORMALIZED) or the weighted spherical mean of the n_i
 * (SPHERICAL: see sfb__shade_spherical_mean). The limit tables and finish_normals still run on
 * the backend. Only the last step is restricted to the rows needed (b > 0, or all with
 * SFB_SHADE_ALL_SUBDIVIDED); the earlier levels are computed in full: the rows of level L-1 a
 * restricted last step reads are the support of its rows (and of the levels below, theirs),
 * different for the two row sets, so restricting would take per-level marks kept at build time
 * for each, while a level has about a quarter of the next one's vertices (Catmull-Clark and
 * Loop quadruple the faces per step): all earlier steps together cost about a third of the last
 * one, and near the extraordinary vertices, where b > 0, most of their rows are in that support
 * anyway. When the normals level is the last level there is no step: the output rows are the
 * face-weighted region means (the composed table) in every mode. Cost: on catmark_car at
 * level 3 on ref, sfb_surface_shade takes about as long with RENORMALIZED as with LINEAR and
 * about 6-8x as long with SPHERICAL (a few iterations per row, an atan2 per entry and
 * iteration where the angle is not small).
 *
 * Choices where the seed is silent (each tested in tests/shade.c):
 *   - Linear averaging by default (the seed's choice, §2.3), normalised once at the end (in
 *     finish_normals) rather than after every level. Renormalising a linear average only
 *     rescales it, so the direction differs from a per-level renormalisation by the small
 *     change of the stencil weights this rescaling makes; in exchange N_S is one linear map of
 *     the normals-level normals, which is what lets it compile to one stencil table run on the
 *     backend. Per-level renormalised and spherical averaging (the original subdivision
 *     shading's) are options, computed in the core (above): they differ from linear by small
 *     angles (tests/shade.c measures them) and cost a CPU pass per level.
 *   - A region is a maximal fan of a vertex's faces not separated by a sharp edge (sharpness
 *     > 0 at that level; boundary edges are sharp). A vertex with fewer than two sharp edges, or
 *     a non-manifold one, has one region.
 *   - A stencil entry that reaches a parent vertex with several regions takes the parent's
 *     region normals of the parent faces the new vertex's region lies in (the parent faces of
 *     the child faces of that region), weighted by how many of those faces each region has.
 *     When the new vertex lies in faces of several parent regions - a semi-sharp edge ran out
 *     of sharpness between the levels, so the child has fewer regions than the parent - this
 *     merges the separated regions' normals in proportion to the faces each contributes. No
 *     face of the new vertex at the parent vertex (cannot happen for Catmull-Clark or Loop
 *     masks): all of the parent's regions equally.
 *   - Output regions split only along infinitely sharp edges; N_S of an output vertex is the
 *     face-count weighted mean of the N_S regions it covers (a semi-sharp edge still sharp at
 *     the last level separates N_S regions but does not split the vertex).
 *   - Weights, re-seeding (seed §3.2): at the weights level b = 1 at every extraordinary vertex
 *     that is not held and at every vertex of its incident faces (its one-ring: edge
 *     neighbours, and for Catmull-Clark the face diagonals too), then b = 0 at every held
 *     vertex. Held: in variant B a vertex with two or more sharp edges at that level (crease or
 *     corner rule, boundary included) or, with sharp darts, a regular dart; in variant A no
 *     vertex is held. After every subdivision step of the weights (the scheme's stencils,
 *     creases included): b = 0 at every held vertex again (its sharpness has not run out); a
 *     vertex released at this step (held before, not now: its semi-sharp edges ran out) that is
 *     extraordinary is seeded as a smooth extraordinary vertex, it and its one-ring set to 1
 *     (Fig. 4 of the seed); and b = 1 at every extraordinary vertex that is not held (the
 *     vertex alone: away from held vertices this changes nothing, since a vertex whose one-ring
 *     is all 1 keeps 1; next to held vertices it keeps the limit value 1 at the extraordinary
 *     point, which the blended field needs to be smooth there).
 *   - Extraordinary: Catmull-Clark an interior vertex whose face count is not 4 or with a
 *     non-quad face, a boundary vertex whose face count is not 2; Loop 6 and 3 with triangles;
 *     non-manifold vertices count as extraordinary. A dart that is extraordinary is
 *     extraordinary whatever the dart option.
 *   - Limit normals of split vertices: at a crease vertex each side uses the crease tangent
 *     and that side's cross tangent (the limit masks of a boundary vertex on that side); at a
 *     corner each region uses the two edges of its first face, as the corner limit masks do. */

typedef struct sfb__regions {
    int *first;   /* nv + 1: first region-vertex of each vertex */
    int *of_vf;   /* per vf entry: region-vertex of that face at that vertex */
    int *faces;   /* per region-vertex: number of faces */
    int total;
} sfb__regions;

static void sfb__regions_free(sfb_context *ctx, sfb__regions *r) {
    sfb__free(ctx, r->first); sfb__free(ctx, r->of_vf); sfb__free(ctx, r->faces);
    memset(r, 0, sizeof *r);
}

/* Regions of every vertex: edges with sharpness > 0 separate them (>= infinite with inf_only). */
static sfb_result sfb__regions_build(sfb_context *ctx, const sfb__level *l, int inf_only, sfb__regions *r) {
    int v, i, nvf = l->vf_off[l->nv];
    memset(r, 0, sizeof *r);
    r->first = (int *)sfb__alloc(ctx, ((size_t)l->nv + 1) * sizeof(int));
    r->of_vf = (int *)sfb__alloc(ctx, ((size_t)nvf + 1) * sizeof(int));
    if (!r->first || !r->of_vf) { sfb__regions_free(ctx, r); return sfb__oom(ctx, "shading regions"); }
    r->total = 0;
    for (v = 0; v < l->nv; ++v) {
        int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0;
        int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0;
        int sharp = 0, reg = 0, interior = nf == ne && !(l->vtag[v] & SFB__TAG_BOUNDARY);
        r->first[v] = r->total;
        if (!(l->vtag[v] & SFB__TAG_NONMANIFOLD) && (nf == ne || nf == ne - 1))
            for (i = 0; i < ne; ++i) {
                float s = l->es[l->ve[e0 + i]];
                sharp += inf_only ? s >= SFB_SHARPNESS_INFINITE : s > 0.0f;
            }
        if (sharp < 2) {
            for (i = 0; i < nf; ++i) r->of_vf[f0 + i] = r->total;
            r->total += 1;
            continue;
        }
        for (i = 0; i < nf; ++i) {
            float s = l->es[l->ve[e0 + i]]; /* edge i precedes face i */
            if (i > 0 && (inf_only ? s >= SFB_SHARPNESS_INFINITE : s > 0.0f)) reg++;
            r->of_vf[f0 + i] = reg;
        }
        if (interior && reg > 0) {
            float s0 = l->es[l->ve[e0]];
            if (!(inf_only ? s0 >= SFB_SHARPNESS_INFINITE : s0 > 0.0f)) {
                /* the fan closes through edge 0: the last run joins the first region */
                for (i = 0; i < nf; ++i)
                    if (r->of_vf[f0 + i] == reg) r->of_vf[f0 + i] = 0;
                reg--;
            }
        }
        for (i = 0; i < nf; ++i) r->of_vf[f0 + i] += r->total;
        r->total += reg + 1;
    }
    r->first[l->nv] = r->total;
    r->faces = (int *)sfb__calloc(ctx, (size_t)r->total + 1, sizeof(int));
    if (!r->faces) { sfb__regions_free(ctx, r); return sfb__oom(ctx, "shading regions"); }
    for (i = 0; i < nvf; ++i) r->faces[r->of_vf[i]]++;
    return SFB_SUCCESS;
}

void sfb__shading_free(sfb_context *ctx, sfb__shading *sh) {
    int t;
    if (!sh) return;
    sfb__level_free(ctx, &sh->nlev);
    sfb__free(ctx, sh->nsrc_of_vf);
    sfb__stencils_free(ctx, &sh->npos);
    sfb__free(ctx, sh->out_origin); sfb__free(ctx, sh->out_fv); sfb__free(ctx, sh->b);
    sfb__free(ctx, sh->ns_idx_w); sfb__free(ctx, sh->ns_idx_all);
    sfb__stencils_free(ctx, &sh->ns);
    for (t = 0; t < 3; ++t) sfb__stencils_free(ctx, &sh->lim[t]);
    if (sh->steps) {
        for (t = 0; t < sh->nsteps; ++t) sfb__stencils_free(ctx, &sh->steps[t]);
        sfb__free(ctx, sh->steps);
    }
    sfb__free(ctx, sh);
}

int sfb__shade_extraordinary(const sfb__level *l, int v, int loop) {
    int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0, i, reg;
    if (l->ve_off[v + 1] == l->ve_off[v]) return 0; /* bare vertex */
    if (l->vtag[v] & SFB__TAG_NONMANIFOLD) return 1;
    reg = (l->vtag[v] & SFB__TAG_BOUNDARY) ? (loop ? 3 : 2) : (loop ? 6 : 4);
    if (nf != reg) return 1;
    for (i = 0; i < nf; ++i) {
        int f = l->vf[f0 + i];
        if (l->fv_off[f + 1] - l->fv_off[f] != (loop ? 3 : 4)) return 1;
    }
    return 0;
}

int sfb__shade_held(const sfb__level *l, int v, int loop, int variant, int darts) {
    int rule = l->vrule[v];
    if (variant != SFB_SHADE_VARIANT_B) return 0;
    if (rule == SFB__RULE_CREASE || rule == SFB__RULE_CORNER) return 1;
    return darts == SFB_SHADE_DARTS_SHARP && rule == SFB__RULE_DART && !sfb__shade_extraordinary(l, v, loop);
}

/* The seeding of the blend weights on level l (see the top of this file): b = 1 at every
 * extraordinary vertex that is not held, and at its one-ring when `ring` says so (all of them
 * with ring == NULL; else those with ring[v] set); then b = 0 at every held vertex. */
static void sfb__shade_seed(const sfb__level *l, double *b, int loop, int variant, int darts, const unsigned char *ring) {
    int v, i, j;
    for (v = 0; v < l->nv; ++v) {
        if (!sfb__shade_extraordinary(l, v, loop) || sfb__shade_held(l, v, loop, variant, darts)) continue;
        b[v] = 1.0;
        if (ring && !ring[v]) continue;
        for (i = l->vf_off[v]; i < l->vf_off[v + 1]; ++i) {
            int f = l->vf[i];
            for (j = l->fv_off[f]; j < l->fv_off[f + 1]; ++j) b[l->fv[j]] = 1.0;
        }
    }
    for (v = 0; v < l->nv; ++v)
        if (sfb__shade_held(l, v, loop, variant, darts)) b[v] = 0.0;
}

/* Parent face of every child face of one step. */
static int *sfb__shade_parent_faces(sfb_context *ctx, const sfb__level *p, const sfb__level *c, int loop) {
    int *pf = (int *)sfb__alloc(ctx, ((size_t)c->nf + 1) * sizeof(int));
    int f, i;
    if (!pf) return NULL;
    if (loop) {
        for (f = 0; f < c->nf; ++f) pf[f] = f / 4;
    } else {
        for (f = 0; f < p->nf; ++f)
            for (i = p->fv_off[f]; i < p->fv_off[f + 1]; ++i) pf[i] = f; /* child faces of f: its face-vertex slots */
    }
    return pf;
}

/* Scratch of the region masks. */
typedef struct sfb__shade_scratch {
    int *fset, nfset;          /* parent faces of the child region being built */
    double *cnt;               /* per region of the parent vertex */
} sfb__shade_scratch;

/* Adds scale * (the step's mask of child vertex cv, restricted to its region creg - a
 * region-vertex of cr, or -1 for all of cv's faces) over the parent's region-vertices. */
static int sfb__shade_region_mask(sfb_context *ctx, const sfb__level *p, const sfb__regions *pr, const sfb__level *c,
                                  const sfb__regions *cr, const int *cparent, const sfb__stencils *T, int cv, int creg,
                                  double scale, sfb__mask *m, sfb__shade_scratch *sc) {
    int i, j, k, n = T->sizes[cv], o = T->offsets[cv];
    sc->nfset = 0;
    for (i = c->vf_off[cv]; i < c->vf_off[cv + 1]; ++i) {
        int pf;
        if (creg >= 0 && cr->of_vf[i] != creg) continue;
        pf = cparent[c->vf[i]];
        for (j = 0; j < sc->nfset && sc->fset[j] != pf; ++j) {}
        if (j == sc->nfset) sc->fset[sc->nfset++] = pf;
    }
    for (k = 0; k < n; ++k) {
        int pj = T->indices[o + k], nr = pr->first[pj + 1] - pr->first[pj];
        double w = (double)T->weights[o + k] * scale, tot = 0.0;
        if (!sfb__mask_grow(ctx, m, nr)) return 0;
        if (nr == 1) { SFB__MASK_ADD(m, pr->first[pj], w); continue; }
        for (i = 0; i < nr; ++i) sc->cnt[i] = 0.0;
        for (i = p->vf_off[pj]; i < p->vf_off[pj + 1]; ++i)
            for (j = 0; j < sc->nfset; ++j)
                if (sc->fset[j] == p->vf[i]) { sc->cnt[pr->of_vf[i] - pr->first[pj]] += 1.0; tot += 1.0; break; }
        for (i = 0; i < nr; ++i) {
            double f = tot > 0.0 ? sc->cnt[i] / tot : 1.0 / nr;
            if (f != 0.0) SFB__MASK_ADD(m, pr->first[pj] + i, w * f);
        }
    }
    return 1;
}

/* Rows of the identity over n sources. */
static int sfb__shade_identity(sfb_context *ctx, sfb__rows *r, int n) {
    int i;
    memset(r, 0, sizeof *r);
    r->rows = n;
    r->off = (size_t *)sfb__alloc(ctx, ((size_t)n + 1) * sizeof(size_t));
    if (!r->off || !sfb__rows_reserve(ctx, r, (size_t)n + 1)) return 0;
    for (i = 0; i < n; ++i) { r->off[i] = (size_t)i; r->idx[i] = i; r->w[i] = 1.0; }
    r->off[n] = (size_t)n;
    r->n = (size_t)n;
    return 1;
}

/* Composed rows of level k+1 from those of level k through the step's stencils (positions). */
static int sfb__shade_compose_step(sfb_context *ctx, sfb__accum *A, const sfb__rows *prow, const sfb__stencils *T,
                                   sfb__mask *m, sfb__rows *out) {
    int cv, k;
    memset(out, 0, sizeof *out);
    out->rows = T->rows;
    out->off = (size_t *)sfb__alloc(ctx, ((size_t)T->rows + 1) * sizeof(size_t));
    if (!out->off) return 0;
    out->off[0] = 0;
    for (cv = 0; cv < T->rows; ++cv) {
        m->n = 0;
        if (!sfb__mask_grow(ctx, m, T->sizes[cv])) return 0;
        for (k = 0; k < T->sizes[cv]; ++k) SFB__MASK_ADD(m, T->indices[T->offsets[cv] + k], (double)T->weights[T->offsets[cv] + k]);
        if (!sfb__compose_row(ctx, A, prow, m, out, cv)) return 0;
    }
    return 1;
}

static sfb_result sfb__shade_level_arg(sfb_context *ctx, int given, int level, const char *what, int *out) {
    int l = given == 0 ? 1 : given == SFB_SHADE_LEVEL_CONTROL ? 0 : given;
    if (given < SFB_SHADE_LEVEL_CONTROL || given > SFB_MAX_LEVEL)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                          "shading %s level %d is outside %d..%d (0 = default 1, SFB_SHADE_LEVEL_CONTROL = the control mesh)",
                          what, given, SFB_SHADE_LEVEL_CONTROL, SFB_MAX_LEVEL);
    *out = l < level ? l : level; /* a start level above the refinement level starts at the last level */
    return SFB_SUCCESS;
}

/* The working state of sfb__shading_build: the levels one step apart with their local
 * stencils, regions and parent faces, the output regions, and the scratch of composing rows. */
typedef struct sfb__shade_build {
    sfb_context *ctx;
    const sfb__level *prep;
    const sfb__refine_options *opt;
    const sfb_shading_options *o;
    sfb__shading *sh;
    int L, Ln, Lw;         /* last, normals and weights level */
    int loop, per_level;   /* Loop scheme; N_S one level at a time (averaging not linear) */
    sfb__level *lev;       /* L + 1 levels: lev[0] borrowed (prep), lev[Ln] moved to sh->nlev */
    sfb__stencils *T;      /* L + 1: T[k] the step from level k to k + 1 */
    sfb__regions *reg;     /* L + 1: regions (sharpness > 0) from the normals level up */
    sfb__regions outreg;   /* regions of the last level split by infinitely sharp edges only */
    int **parent;          /* L + 1: parent face of every face of level k (k >= 1) */
    const sfb__level *top; /* the last level */
    sfb__refine_kept *kept;    /* the vertex refinement's levels and steps, taken over (or NULL) */
    const sfb__level *kept_top; /* with kept: the vertex refinement's last level, lev[L] borrows it */
    sfb__rows prow, crow;
    sfb__accum A;
    sfb__mask m, mm[3];
    sfb__shade_scratch sc;
    double *bw, *bn;       /* blend weights of the current and the next level */
    int *order;            /* output vertices in N_S row order (b > 0 first) */
} sfb__shade_build;

/* Frees the working state of sfb__shading_build (not the shading it builds). */
static void sfb__shade_build_free(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    int k, t, L = B->L;
    if (B->lev) {
        if (B->kept_top) memset(&B->lev[L], 0, sizeof B->lev[L]); /* borrowed */
        for (k = 1; k <= L; ++k) sfb__level_free(ctx, &B->lev[k]);
        sfb__free(ctx, B->lev);
    }
    if (B->T) { for (k = 0; k <= L; ++k) sfb__stencils_free(ctx, &B->T[k]); sfb__free(ctx, B->T); }
    if (B->reg) { for (k = 0; k <= L; ++k) sfb__regions_free(ctx, &B->reg[k]); sfb__free(ctx, B->reg); }
    if (B->parent) { for (k = 0; k <= L; ++k) sfb__free(ctx, B->parent[k]); sfb__free(ctx, B->parent); }
    sfb__regions_free(ctx, &B->outreg);
    sfb__rows_free(ctx, &B->prow); sfb__rows_free(ctx, &B->crow);
    sfb__free(ctx, B->A.acc); sfb__free(ctx, B->A.mark); sfb__free(ctx, B->A.touched);
    sfb__free(ctx, B->m.idx); sfb__free(ctx, B->m.w);
    for (t = 0; t < 3; ++t) { sfb__free(ctx, B->mm[t].idx); sfb__free(ctx, B->mm[t].w); }
    sfb__free(ctx, B->sc.fset); sfb__free(ctx, B->sc.cnt);
    sfb__free(ctx, B->bw); sfb__free(ctx, B->bn); sfb__free(ctx, B->order);
}

/* Checks the shading options against refinement level L; the normals and weights levels they
 * give into *Ln and *Lw. */
static sfb_result sfb__shade_check_options(sfb_context *ctx, const sfb_shading_options *o, int L, int *Ln, int *Lw) {
    sfb_result r;
    if ((r = sfb__shade_level_arg(ctx, o->normals_level, L, "normals", Ln)) != SFB_SUCCESS) return r;
    if ((r = sfb__shade_level_arg(ctx, o->weights_level, L, "weights", Lw)) != SFB_SUCCESS) return r;
    if (o->variant != SFB_SHADE_VARIANT_A && o->variant != SFB_SHADE_VARIANT_B)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "shading variant %d is not SFB_SHADE_VARIANT_A or _B", o->variant);
    if (o->darts != SFB_SHADE_DARTS_SMOOTH && o->darts != SFB_SHADE_DARTS_SHARP)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "shading darts option %d is not SFB_SHADE_DARTS_SMOOTH or _SHARP", o->darts);
    if (o->averaging != SFB_SHADE_AVERAGE_LINEAR && o->averaging != SFB_SHADE_AVERAGE_RENORMALIZED && o->averaging != SFB_SHADE_AVERAGE_SPHERICAL)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                          "shading averaging %d is not SFB_SHADE_AVERAGE_LINEAR, _RENORMALIZED or _SPHERICAL", o->averaging);
    return SFB_SUCCESS;
}

/* Allocates the shading and the per-level arrays, then the levels one step at a time with each
 * step's local stencils and parent faces, the region-mask scratch, the regions from the
 * normals level up and the output regions of the last level. */
static sfb_result sfb__shade_build_levels(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    const sfb_shading_options *o = B->o;
    sfb__shading *sh;
    sfb__level *lev;
    sfb_result r;
    int L = B->L, k, v, maxv = 1;
    sh = B->sh = (sfb__shading *)sfb__calloc(ctx, 1, sizeof *sh);
    lev = B->lev = (sfb__level *)sfb__calloc(ctx, (size_t)L + 1, sizeof *lev);
    B->T = (sfb__stencils *)sfb__calloc(ctx, (size_t)L + 1, sizeof *B->T);
    B->reg = (sfb__regions *)sfb__calloc(ctx, (size_t)L + 1, sizeof *B->reg);
    B->parent = (int **)sfb__calloc(ctx, (size_t)L + 1, sizeof *B->parent);
    if (!sh || !lev || !B->T || !B->reg || !B->parent) {
        if (B->kept) sfb__refine_kept_free(ctx, B->kept, L);
        B->kept_top = NULL;
        return sfb__oom(ctx, "shading tables");
    }
    sh->normals_level = B->Ln; sh->weights_level = B->Lw; sh->level = L; sh->variant = o->variant; sh->darts = o->darts;
    sh->averaging = o->averaging;
    B->per_level = o->averaging != SFB_SHADE_AVERAGE_LINEAR && L > B->Ln;

    /* the levels, one step at a time, with each step's local stencils: those the vertex
     * refinement made (taken over; its last level borrowed), or refined here */
    lev[0] = *B->prep; /* borrowed */
    if (B->kept) {
        for (k = 0; k < L; ++k) {
            if (k > 0) lev[k] = B->kept->lev[k];
            B->T[k] = B->kept->T[k];
            memset(&B->kept->lev[k], 0, sizeof B->kept->lev[k]);
            memset(&B->kept->T[k], 0, sizeof B->kept->T[k]);
        }
        lev[L] = *B->kept_top;
    }
    for (k = 0; k < L; ++k) {
        if (!B->kept) {
            r = sfb__refine(ctx, &lev[k], B->opt, 1, &lev[k + 1], &B->T[k], NULL, 0.8f, 0.8f);
            if (r != SFB_SUCCESS) return r;
        }
        B->parent[k + 1] = sfb__shade_parent_faces(ctx, &lev[k], &lev[k + 1], B->loop);
        if (!B->parent[k + 1]) return sfb__oom(ctx, "shading tables");
    }
    B->top = &lev[L];
    for (k = 0; k <= L; ++k)
        for (v = 0; v < lev[k].nv; ++v) {
            int n = lev[k].vf_off[v + 1] - lev[k].vf_off[v];
            if (n + 1 > maxv) maxv = n + 1;
        }
    B->sc.fset = (int *)sfb__alloc(ctx, (size_t)maxv * sizeof(int));
    B->sc.cnt = (double *)sfb__alloc(ctx, (size_t)maxv * sizeof(double));
    if (!B->sc.fset || !B->sc.cnt) return sfb__oom(ctx, "shading tables");

    /* regions (sharpness > 0) from the normals level up */
    for (k = B->Ln; k <= L; ++k)
        if ((r = sfb__regions_build(ctx, &lev[k], 0, &B->reg[k])) != SFB_SUCCESS) return r;
    return sfb__regions_build(ctx, B->top, 0, &B->outreg);
}

/* The normals level: its topology (sh->nlev: prepared from the base, or moved out of lev[Ln]),
 * the source of every face at every vertex, the composing accumulator and, when it lies between
 * the base and the last level, the table of its positions over the base vertices (sh->npos). */
static sfb_result sfb__shade_normals_level(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *prep = B->prep;
    sfb_result r = SFB_SUCCESS;
    int L = B->L, Ln = B->Ln, k, asz;
    if (Ln == 0) r = sfb__level_prepare(ctx, prep, 0, 0, &sh->nlev);
    else if (Ln == L && B->kept_top) r = sfb__level_prepare(ctx, &B->lev[Ln], 0, 0, &sh->nlev); /* borrowed: a copy */
    else { sh->nlev = B->lev[Ln]; memset(&B->lev[Ln], 0, sizeof B->lev[Ln]); }
    if (r != SFB_SUCCESS) return r;
    if (Ln == L) B->top = &sh->nlev;
    sh->nsrc = B->reg[Ln].total;
    sh->nsrc_of_vf = (int *)sfb__alloc(ctx, ((size_t)sh->nlev.vf_off[sh->nlev.nv] + 1) * sizeof(int));
    if (!sh->nsrc_of_vf) return sfb__oom(ctx, "shading tables");
    memcpy(sh->nsrc_of_vf, B->reg[Ln].of_vf, (size_t)sh->nlev.vf_off[sh->nlev.nv] * sizeof(int));
    asz = prep->nv > sh->nsrc ? prep->nv : sh->nsrc;
    for (k = Ln; B->per_level && k < L; ++k)
        if (B->reg[k].total > asz) asz = B->reg[k].total; /* per level: rows over each level's regions */
    B->A.acc = (double *)sfb__alloc(ctx, ((size_t)asz + 1) * sizeof(double));
    B->A.mark = (unsigned *)sfb__calloc(ctx, (size_t)asz + 1, sizeof(unsigned));
    B->A.touched = (int *)sfb__alloc(ctx, ((size_t)asz + 1) * sizeof(int));
    if (!B->A.acc || !B->A.mark || !B->A.touched) return sfb__oom(ctx, "shading tables");
    sh->npos_mode = Ln == 0 ? 0 : Ln == L ? 2 : 1;
    if (sh->npos_mode == 1) {
        if (!sfb__shade_identity(ctx, &B->prow, prep->nv)) return sfb__oom(ctx, "shading tables");
        for (k = 0; k < Ln; ++k) {
            if (!sfb__shade_compose_step(ctx, &B->A, &B->prow, &B->T[k], &B->m, &B->crow)) return sfb__oom(ctx, "shading tables");
            sfb__rows_free(ctx, &B->prow);
            B->prow = B->crow;
            memset(&B->crow, 0, sizeof B->crow);
        }
        r = sfb__rows_move_to_stencils(ctx, &B->prow, prep->nv, &sh->npos);
        if (r != SFB_SUCCESS) return sfb__oom(ctx, "shading tables");
        sfb__rows_free(ctx, &B->prow);
    }
    return SFB_SUCCESS;
}

/* The blend weights from the weights level to the last (B->bw): seeded, then one subdivision
 * step at a time, the held vertices and those released at the step seeded again. */
static sfb_result sfb__shade_weights(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    const sfb_shading_options *o = B->o;
    sfb__shading *sh = B->sh;
    const sfb__level *lev = B->lev;
    int L = B->L, Ln = B->Ln, Lw = B->Lw, loop = B->loop, k, v, i;
    B->bw = (double *)sfb__calloc(ctx, (size_t)(Lw == Ln ? &sh->nlev : &lev[Lw])->nv + 1, sizeof(double));
    if (!B->bw) return sfb__oom(ctx, "shading weights");
    sfb__shade_seed(Lw == Ln ? &sh->nlev : &lev[Lw], B->bw, loop, o->variant, o->darts, NULL);
    for (k = Lw; k < L; ++k) {
        const sfb__stencils *S = &B->T[k];
        const sfb__level *pl = k == Ln ? &sh->nlev : &lev[k], *cl = k + 1 == Ln ? &sh->nlev : &lev[k + 1];
        unsigned char *released;
        B->bn = (double *)sfb__calloc(ctx, (size_t)S->rows + 1, sizeof(double));
        released = (unsigned char *)sfb__calloc(ctx, (size_t)S->rows + 1, 1);
        if (!B->bn || !released) { sfb__free(ctx, released); return sfb__oom(ctx, "shading weights"); }
        for (v = 0; v < S->rows; ++v) {
            double acc = 0.0;
            for (i = 0; i < S->sizes[v]; ++i) acc += (double)S->weights[S->offsets[v] + i] * B->bw[S->indices[S->offsets[v] + i]];
            B->bn[v] = acc < 0.0 ? 0.0 : acc > 1.0 ? 1.0 : acc;
        }
        /* vertex children whose parent was held and who are not: released at this level */
        for (v = 0; v < pl->nv; ++v)
            released[v] = sfb__shade_held(pl, v, loop, o->variant, o->darts) && !sfb__shade_held(cl, v, loop, o->variant, o->darts);
        sfb__shade_seed(cl, B->bn, loop, o->variant, o->darts, released);
        sfb__free(ctx, released);
        sfb__free(ctx, B->bw);
        B->bw = B->bn;
        B->bn = NULL;
    }
    return SFB_SUCCESS;
}

/* The output vertices, one per region of the infinitely sharp partition of the last level:
 * their origin, face-vertex slots and blend weight, and the order of the N_S rows (those with
 * b > 0 first, B->order). */
static sfb_result sfb__shade_outputs(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *top = B->top;
    const sfb__regions *outreg = &B->outreg;
    int *order;
    int v, i;
    sh->nout = outreg->total;
    sh->out_origin = (int *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(int));
    sh->out_fv = (int *)sfb__alloc(ctx, ((size_t)top->nfv + 1) * sizeof(int));
    sh->b = (float *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(float));
    sh->ns_idx_w = (int *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(int));
    sh->ns_idx_all = (int *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(int));
    order = B->order = (int *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(int));
    if (!sh->out_origin || !sh->out_fv || !sh->b || !sh->ns_idx_w || !sh->ns_idx_all || !order) return sfb__oom(ctx, "shading tables");
    for (v = 0; v < top->nv; ++v) {
        int nr = outreg->first[v + 1] - outreg->first[v];
        if (nr > 1) sh->nsplit++;
        for (i = 0; i < nr; ++i) {
            sh->out_origin[outreg->first[v] + i] = v;
            sh->b[outreg->first[v] + i] = (float)B->bw[v];
        }
        for (i = top->vf_off[v]; i < top->vf_off[v + 1]; ++i) {
            int f = top->vf[i];
            sh->out_fv[top->fv_off[f] + top->vf_slot[i]] = outreg->of_vf[i];
        }
    }
    /* N_S rows: those with b > 0 first */
    for (v = 0, i = 0; v < sh->nout; ++v) if (sh->b[v] > 0.0f) order[i++] = v;
    sh->nweighted = i;
    for (v = 0; v < sh->nout; ++v) if (!(sh->b[v] > 0.0f)) order[i++] = v;
    for (i = 0; i < sh->nout; ++i) {
        sh->ns_idx_all[order[i]] = i;
        sh->ns_idx_w[order[i]] = i < sh->nweighted ? i : -1;
    }
    return SFB_SUCCESS;
}

/* N_S: region rows composed from the normals level up to the level below the last (B->prow).
 * Per level (averaging not linear): each step's rows over the regions of the level below alone
 * (composed with an identity, which merges repeated sources), kept as a table of its own. */
static sfb_result sfb__shade_ns_steps(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *lev = B->lev;
    const sfb__regions *reg = B->reg;
    sfb_result r;
    int L = B->L, Ln = B->Ln, k;
    if (B->per_level) {
        sh->steps = (sfb__stencils *)sfb__calloc(ctx, (size_t)(L - Ln), sizeof *sh->steps);
        if (!sh->steps) return sfb__oom(ctx, "shading tables");
        sh->nsteps = L - Ln;
    }
    if (!sfb__shade_identity(ctx, &B->prow, sh->nsrc)) return sfb__oom(ctx, "shading tables");
    for (k = Ln; k < L - 1; ++k) {
        const sfb__level *pl = k == Ln ? &sh->nlev : &lev[k];
        int cv, rv;
        memset(&B->crow, 0, sizeof B->crow);
        B->crow.rows = reg[k + 1].total;
        B->crow.off = (size_t *)sfb__alloc(ctx, ((size_t)B->crow.rows + 1) * sizeof(size_t));
        if (!B->crow.off) return sfb__oom(ctx, "shading tables");
        B->crow.off[0] = 0;
        for (cv = 0; cv < lev[k + 1].nv; ++cv)
            for (rv = reg[k + 1].first[cv]; rv < reg[k + 1].first[cv + 1]; ++rv) {
                int creg = reg[k + 1].first[cv + 1] - reg[k + 1].first[cv] > 1 ? rv : -1;
                B->m.n = 0;
                if (!sfb__shade_region_mask(ctx, pl, &reg[k], &lev[k + 1], &reg[k + 1], B->parent[k + 1], &B->T[k], cv, creg, 1.0, &B->m,
                                            &B->sc) ||
                    !sfb__compose_row(ctx, &B->A, &B->prow, &B->m, &B->crow, rv))
                    return sfb__oom(ctx, "shading tables");
            }
        sfb__rows_free(ctx, &B->prow);
        if (B->per_level) {
            r = sfb__rows_move_to_stencils(ctx, &B->crow, reg[k].total, &sh->steps[k - Ln]);
            if (r != SFB_SUCCESS) { if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "shading tables"); return r; }
            sfb__rows_free(ctx, &B->crow);
            if (!sfb__shade_identity(ctx, &B->prow, reg[k + 1].total)) return sfb__oom(ctx, "shading tables");
        } else {
            B->prow = B->crow;
        }
        memset(&B->crow, 0, sizeof B->crow);
        r = sfb__progress(ctx, 0.8f, "shading");
        if (r != SFB_SUCCESS) return r;
    }
    return SFB_SUCCESS;
}

/* The output rows of N_S, in B->order: each the face-weighted mean of the N_S regions of the
 * last level it covers; then the N_S table (sh->ns), or per level the last step's table and the
 * sizes of the steps. */
static sfb_result sfb__shade_ns_output(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *top = B->top;
    const sfb__regions *reg = B->reg, *outreg = &B->outreg;
    sfb_result r;
    int L = B->L, Ln = B->Ln, i, k;
    memset(&B->crow, 0, sizeof B->crow);
    B->crow.rows = sh->nout;
    B->crow.off = (size_t *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(size_t));
    /* room for rows as long as the composed rows they come from, at once */
    if (!B->crow.off || !sfb__rows_reserve(ctx, &B->crow, (size_t)sh->nout * (B->prow.n / (size_t)(B->prow.rows > 0 ? B->prow.rows : 1) + 4) + 16))
        return sfb__oom(ctx, "shading tables");
    B->crow.off[0] = 0;
    for (i = 0; i < sh->nout; ++i) {
        int ov = B->order[i], cv = sh->out_origin[ov], rv, j;
        int faces = outreg->faces[ov];
        B->m.n = 0;
        for (rv = reg[L].first[cv]; rv < reg[L].first[cv + 1]; ++rv) {
            /* the output region of N_S region rv: that of any of its faces (a bare vertex has
             * one of each) */
            int in = faces == 0;
            double frac;
            int creg = reg[L].first[cv + 1] - reg[L].first[cv] > 1 ? rv : -1;
            for (j = top->vf_off[cv]; j < top->vf_off[cv + 1]; ++j)
                if (reg[L].of_vf[j] == rv) { in = outreg->of_vf[j] == ov; break; }
            if (!in) continue;
            frac = faces ? (double)reg[L].faces[rv] / faces : 1.0;
            if (L == Ln) {
                if (!sfb__mask_grow(ctx, &B->m, 1)) return sfb__oom(ctx, "shading tables");
                SFB__MASK_ADD(&B->m, rv, frac);
            } else if (!sfb__shade_region_mask(ctx, L - 1 == Ln ? &sh->nlev : &B->lev[L - 1], &reg[L - 1], top, &reg[L],
                                               B->parent[L], &B->T[L - 1], cv, creg, frac, &B->m, &B->sc)) {
                return sfb__oom(ctx, "shading tables");
            }
        }
        if (!sfb__compose_row(ctx, &B->A, &B->prow, &B->m, &B->crow, i)) return sfb__oom(ctx, "shading tables");
    }
    if (B->per_level) {
        r = sfb__rows_move_to_stencils(ctx, &B->crow, reg[L - 1].total, &sh->steps[sh->nsteps - 1]);
        if (r != SFB_SUCCESS) { if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "shading tables"); return r; }
        for (k = 0; k < sh->nsteps; ++k) {
            const sfb__stencils *S = &sh->steps[k];
            if (S->rows > sh->step_rows_max) sh->step_rows_max = S->rows;
            if (S->sources > sh->step_rows_max) sh->step_rows_max = S->sources;
            for (i = 0; i < S->rows; ++i)
                if (S->sizes[i] > sh->step_size_max) sh->step_size_max = S->sizes[i];
        }
    } else {
        r = sfb__rows_move_to_stencils(ctx, &B->crow, sh->nsrc, &sh->ns);
        if (r != SFB_SUCCESS) return sfb__oom(ctx, "shading tables");
    }
    sfb__rows_free(ctx, &B->crow);
    sfb__rows_free(ctx, &B->prow);
    return SFB_SUCCESS;
}

/* The limit masks (position, two tangents) into mm of output vertex ov, one of the regions of
 * split vertex v of the last level: at a crease vertex the crease tangent and that side's cross
 * tangent, at a corner the two edges of the region's first face. */
static void sfb__shade_split_limit_masks(const sfb__level *top, const sfb__regions *outreg, int v, int ov, int loop, sfb__mask *mm) {
    int e0 = top->ve_off[v], ne = top->ve_off[v + 1] - e0;
    int f0 = top->vf_off[v], nf = top->vf_off[v + 1] - f0, i;
    /* the region's faces: a run first..first+len-1 around v (mod nf) */
    int first = -1, len = 0;
    for (i = 0; i < nf; ++i) {
        int prev = i > 0 ? outreg->of_vf[f0 + i - 1] : (nf == ne ? outreg->of_vf[f0 + nf - 1] : -1);
        if (outreg->of_vf[f0 + i] == ov) { len++; if (prev != ov) first = i; }
    }
    if (first < 0) first = 0;
    if (top->vrule[v] == SFB__RULE_CREASE) {
        float sharp[SFB_MAX_VALENCE + 1];
        int a, b;
        for (i = 0; i < ne && i <= SFB_MAX_VALENCE; ++i) sharp[i] = top->es[top->ve[e0 + i]];
        sfb__crease_pair(sharp, ne, &a, &b);
        SFB__MASK_ADD(&mm[0], v, 2.0 / 3.0);
        SFB__MASK_ADD(&mm[0], sfb__other_end(top, top->ve[e0 + a], v), 1.0 / 6.0);
        SFB__MASK_ADD(&mm[0], sfb__other_end(top, top->ve[e0 + b], v), 1.0 / 6.0);
        sfb__crease_tangent_masks(top, v, first, first + len, loop, &mm[1], &mm[2]);
    } else {
        SFB__MASK_ADD(&mm[0], v, 1.0);
        SFB__MASK_ADD(&mm[1], v, -1.0);
        SFB__MASK_ADD(&mm[1], sfb__other_end(top, top->ve[e0 + first % ne], v), 1.0);
        SFB__MASK_ADD(&mm[2], v, -1.0);
        SFB__MASK_ADD(&mm[2], sfb__other_end(top, top->ve[e0 + (first + 1) % ne], v), 1.0);
    }
}

/* Appends mask mk to the local rows lr as row ov (duplicates merged); 0 when out of memory. */
static int sfb__shade_rows_append(sfb_context *ctx, sfb__rows *lr, const sfb__mask *mk, int ov) {
    size_t at;
    int a2, b2;
    if (!sfb__rows_reserve(ctx, lr, lr->n + (size_t)mk->n)) return 0;
    at = lr->n;
    for (a2 = 0; a2 < mk->n; ++a2) {
        for (b2 = (int)at; b2 < (int)lr->n && lr->idx[b2] != mk->idx[a2]; ++b2) {}
        if (b2 < (int)lr->n) lr->w[b2] += mk->w[a2];
        else { lr->idx[lr->n] = mk->idx[a2]; lr->w[lr->n] = mk->w[a2]; lr->n++; }
    }
    lr->off[ov + 1] = lr->n;
    return 1;
}

/* Limit position and tangents of every output vertex over the refined vertices of the last
 * level (sh->lim[0..2]): local rows, one region of a split vertex at a time. */
static sfb_result sfb__shade_limits(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *top = B->top;
    const sfb__regions *outreg = &B->outreg;
    sfb__mask *mm = B->mm;
    sfb__rows lr[3];
    sfb_result r = SFB_SUCCESS;
    int v, t;
    memset(lr, 0, sizeof lr);
    for (t = 0; t < 3; ++t) {
        lr[t].rows = sh->nout;
        lr[t].off = (size_t *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(size_t));
        /* room for a vertex's masks (9 entries at a regular quad vertex, its tangents 6-8) at once: grown
         * from nothing, the tables were copied by realloc over and over */
        if (!lr[t].off || !sfb__rows_reserve(ctx, &lr[t], (size_t)sh->nout * 12 + 16)) r = sfb__oom(ctx, "shading limit tables");
        else lr[t].off[0] = 0;
    }
    for (v = 0; v < top->nv && r == SFB_SUCCESS; ++v) {
        int nr = outreg->first[v + 1] - outreg->first[v], rr;
        int need = 3 * sfb__mask_need_vertex(top, v) + 8;
        for (rr = 0; rr < nr && r == SFB_SUCCESS; ++rr) {
            int ov = outreg->first[v] + rr;
            for (t = 0; t < 3; ++t) {
                mm[t].n = 0;
                if (!sfb__mask_grow(ctx, &mm[t], need)) r = sfb__oom(ctx, "shading limit tables");
            }
            if (r != SFB_SUCCESS) break;
            if (nr == 1) sfb__limit_masks(top, v, B->opt->scheme, &mm[0], &mm[1], &mm[2]);
            else sfb__shade_split_limit_masks(top, outreg, v, ov, B->loop, mm);
            for (t = 0; t < 3; ++t)
                if (!sfb__shade_rows_append(ctx, &lr[t], &mm[t], ov)) { r = sfb__oom(ctx, "shading limit tables"); break; }
        }
    }
    for (t = 0; t < 3; ++t) {
        if (r == SFB_SUCCESS) {
            r = sfb__rows_move_to_stencils(ctx, &lr[t], top->nv, &sh->lim[t]);
            if (r != SFB_SUCCESS) r = sfb__oom(ctx, "shading limit tables");
        }
        sfb__rows_free(ctx, &lr[t]);
    }
    return r;
}

sfb_result sfb__shading_build(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt, int L,
                              const sfb_shading_options *o, sfb__refine_kept *kept, const sfb__level *top, sfb__shading **out) {
    sfb__shade_build B;
    sfb__shading *sh;
    sfb_result r;
    int k;
    *out = NULL;
    memset(&B, 0, sizeof B);
    B.ctx = ctx; B.prep = prep; B.opt = opt; B.o = o; B.L = L;
    B.kept = kept && top && L > 0 ? kept : NULL;
    B.kept_top = B.kept ? top : NULL;
    B.loop = opt->scheme == SFB_SCHEME_LOOP;
    if ((r = sfb__shade_check_options(ctx, o, L, &B.Ln, &B.Lw)) != SFB_SUCCESS) {
        if (B.kept) sfb__refine_kept_free(ctx, B.kept, L);
        return r;
    }
    if ((r = sfb__shade_build_levels(&B)) != SFB_SUCCESS) goto done;
    if ((r = sfb__shade_normals_level(&B)) != SFB_SUCCESS) goto done;
    /* blend weights from the weights level to the last */
    if ((r = sfb__shade_weights(&B)) != SFB_SUCCESS) goto done;
    /* output vertices: one per region of the infinitely sharp partition */
    if ((r = sfb__shade_outputs(&B)) != SFB_SUCCESS) goto done;
    /* N_S rows up to the level below the last, then the output rows */
    if ((r = sfb__shade_ns_steps(&B)) != SFB_SUCCESS) goto done;
    if ((r = sfb__shade_ns_output(&B)) != SFB_SUCCESS) goto done;
    /* limit position and tangents of every output vertex over the refined vertices */
    if ((r = sfb__shade_limits(&B)) != SFB_SUCCESS) goto done;
    sh = B.sh;
    sh->bytes = sizeof *sh + (sh->ns.entries + sh->npos.entries + sh->lim[0].entries + sh->lim[1].entries + sh->lim[2].entries) * 8 +
                (size_t)sh->nout * 6 * sizeof(int) + (size_t)B.top->nfv * sizeof(int) + (size_t)sh->nlev.nfv * 3 * sizeof(int);
    for (k = 0; k < sh->nsteps; ++k) sh->bytes += sizeof *sh->steps + sh->steps[k].entries * 8 + (size_t)sh->steps[k].rows * 2 * sizeof(int);
done:
    sfb__shade_build_free(&B);
    if (r != SFB_SUCCESS) { sfb__shading_free(ctx, B.sh); return r; }
    *out = B.sh;
    return SFB_SUCCESS;
}

SFB_API sfb_shade_params sfb_shade_params_init(void) {
    sfb_shade_params p;
    memset(&p, 0, sizeof p);
    p.p = 1.0f;
    return p;
}

/* One shading table on the context's backend (surface.c's sfb__surface_apply), xyz rows. */
static sfb_result sfb__shade_apply(const sfb_surface *s, const sfb__stencils *t, void *handle, int rows, const float *src, float *dst) {
    sfb_buffer_desc d3 = {0, 3, 3};
    if (rows <= 0) return SFB_SUCCESS;
    return sfb__surface_apply(s, t, handle, rows, src, d3, dst, d3);
}

/* The weighted spherical mean of `count` vectors n (xyz, unit length expected) with weights w:
 * the unit vector q minimising sum w_i angle(q, n_i)^2, where sum w_i log_q(n_i) = 0. Start at
 * the normalised linear average, then q <- exp_q(sum (w_i / W) log_q(n_i)), W = sum w_i, until
 * the step is shorter than 1e-12 or after 32 iterations, with
 *   log_q(n) = (n - (q.n) q) theta / sin(theta), theta = angle(q, n)  (the tangent at q towards n),
 *   exp_q(t) = cos|t| q + sin|t| t / |t|                                (walk |t| along t).
 * A zero linear average gives zero (as linear averaging does). A zero input with a nonzero
 * weight, a weight sum <= 0, an input within 1e-6 rad of -q (log_q undefined there) or a
 * non-finite iterate give the normalised linear average instead. Returns the iterations taken
 * (>= 1), 0 for the zero result, -1 where the linear average was returned. Pure: safe from any
 * thread. */
int sfb__shade_spherical_mean(int count, const double *n, const double *w, double out[3]) {
    double s[3] = {0.0, 0.0, 0.0}, q[3], W = 0.0, len;
    int i, c, it, degenerate = 0;
    for (i = 0; i < count; ++i) {
        const double *v = n + 3 * (size_t)i;
        for (c = 0; c < 3; ++c) s[c] += w[i] * v[c];
        W += w[i];
        if (w[i] != 0.0 && v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0) degenerate = 1;
    }
    out[0] = out[1] = out[2] = 0.0;
    len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (!(len > 0.0)) return 0;
    for (c = 0; c < 3; ++c) out[c] = q[c] = s[c] / len;
    if (degenerate || !(W > 0.0)) return -1;
    for (it = 1;; ++it) {
        double t[3] = {0.0, 0.0, 0.0}, tl, st;
        for (i = 0; i < count; ++i) {
            const double *v = n + 3 * (size_t)i;
            double vl = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), d, u[3], sv, theta, f;
            if (w[i] == 0.0) continue;
            d = (q[0] * v[0] + q[1] * v[1] + q[2] * v[2]) / vl;
            for (c = 0; c < 3; ++c) u[c] = v[c] / vl - d * q[c];
            sv = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            if (d > 0.0 && sv < 0.03) {
                /* theta / sin(theta) = asin(s) / s = 1 + s^2/6 + 3 s^4/40 + 5 s^6/112 + O(s^8):
                 * below s = 0.03 the rest is under 1e-14 of it (most entries: neighbouring
                 * normals), and no atan2 is needed */
                const double s2 = sv * sv;
                f = 1.0 + s2 * (1.0 / 6.0 + s2 * (3.0 / 40.0 + s2 * (5.0 / 112.0)));
            } else {
                theta = atan2(sv, d);
                if (theta > SFB__PI - 1e-6) return -1; /* nearly opposite q: no tangent towards it */
                f = theta / sv;
            }
            for (c = 0; c < 3; ++c) t[c] += (w[i] / W) * f * u[c];
        }
        tl = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        if (tl < 1e-12) break;
        st = sin(tl) / tl;
        tl = cos(tl);
        for (c = 0; c < 3; ++c) q[c] = tl * q[c] + st * t[c];
        len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        if (!(len > 0.5) || !(len < 2.0)) return -1; /* not finite */
        for (c = 0; c < 3; ++c) q[c] /= len;
        if (it == 32) break;
    }
    for (c = 0; c < 3; ++c) out[c] = q[c];
    return it;
}

/* N_S one level at a time (averaging renormalised or spherical), on the CPU in double: `src`
 * holds the normals-level region normals (nsh->nsrc xyz); each step's rows average the
 * previous level's normals (RENORMALIZED: normalize(sum w_i n_i); SPHERICAL: the weighted
 * spherical mean); the last step's rows [0, rows) go to ns as floats. */
static sfb_result sfb__shade_levels(sfb_context *ctx, const sfb__shading *sh, const double *src, int rows, float *ns) {
    size_t nrow = (size_t)sh->step_rows_max * 3 + 1, nsz = (size_t)sh->step_size_max + 1;
    double *a = (double *)sfb__alloc(ctx, nrow * sizeof(double)), *b = (double *)sfb__alloc(ctx, nrow * sizeof(double));
    double *vec = (double *)sfb__alloc(ctx, nsz * 3 * sizeof(double)), *w = (double *)sfb__alloc(ctx, nsz * sizeof(double));
    const double *cur = src;
    int k, i, j, c;
    if (!a || !b || !vec || !w) {
        sfb__free(ctx, a); sfb__free(ctx, b); sfb__free(ctx, vec); sfb__free(ctx, w);
        return sfb__oom(ctx, "shading normals");
    }
    for (k = 0; k < sh->nsteps; ++k) {
        const sfb__stencils *T = &sh->steps[k];
        const int last = k == sh->nsteps - 1, n = last ? rows : T->rows;
        double *nx = cur == a ? b : a;
        for (i = 0; i < n; ++i) {
            const int o = T->offsets[i], cnt = T->sizes[i];
            double q[3];
            if (sh->averaging == SFB_SHADE_AVERAGE_SPHERICAL) {
                for (j = 0; j < cnt; ++j) {
                    const double *p = cur + 3 * (size_t)T->indices[o + j];
                    w[j] = (double)T->weights[o + j];
                    vec[3 * j] = p[0]; vec[3 * j + 1] = p[1]; vec[3 * j + 2] = p[2];
                }
                sfb__shade_spherical_mean(cnt, vec, w, q);
            } else {
                double len;
                q[0] = q[1] = q[2] = 0.0;
                for (j = 0; j < cnt; ++j) {
                    const double *p = cur + 3 * (size_t)T->indices[o + j], wj = (double)T->weights[o + j];
                    for (c = 0; c < 3; ++c) q[c] += wj * p[c];
                }
                len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                for (c = 0; c < 3; ++c) q[c] = len > 0.0 ? q[c] / len : 0.0;
            }
            if (last) for (c = 0; c < 3; ++c) ns[3 * (size_t)i + c] = (float)q[c];
            else for (c = 0; c < 3; ++c) nx[3 * (size_t)i + c] = q[c];
        }
        cur = nx;
    }
    sfb__free(ctx, a); sfb__free(ctx, b); sfb__free(ctx, vec); sfb__free(ctx, w);
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_surface_shade(const sfb_surface *s, const sfb_shade_params *params, sfb_mesh_data *o) {
    sfb_context *ctx;
    const sfb__shading *sh;
    const sfb__backend_vtable *be;
    sfb_shade_params prm;
    float *refined = NULL, *npos_buf = NULL, *src = NULL, *ns = NULL, *fnrm = NULL;
    double *srcd = NULL; /* the sources in double (per-level averaging) */
    const float *npos;
    sfb_result r;
    int all, rows, v, f, i, c;
    if (!s || !o) return SFB_INVALID_ARGS;
    memset(o, 0, sizeof *o);
    ctx = s->ctx;
    sh = s->shading;
    if (!sh) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_shade: the surface was created without SFB_REFINE_SHADING");
    prm = params ? *params : sfb_shade_params_init();
    if (prm.p == 0.0f) prm.p = 1.0f;
    if (!(prm.p > 0.0f) || !(prm.p < 1e6f))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "blend exponent p = %g: it must be a finite number > 0", (double)prm.p);
    if (prm.flags & ~(unsigned)SFB_SHADE_ALL_SUBDIVIDED)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_shade: unknown flags 0x%x", prm.flags & ~(unsigned)SFB_SHADE_ALL_SUBDIVIDED);
    all = (prm.flags & SFB_SHADE_ALL_SUBDIVIDED) != 0;
    rows = all ? sh->nout : sh->nweighted;

    /* refined positions, normals-level positions */
    r = sfb__refine_output(s, s->base_positions, s->base_vertex_count, 0, o);
    if (r != SFB_SUCCESS) return r;
    refined = o->positions;
    o->positions = NULL;
    if (sh->npos_mode == 0) npos = s->base_positions;
    else if (sh->npos_mode == 2) npos = refined;
    else {
        npos_buf = (float *)sfb__alloc(ctx, (size_t)sh->npos.rows * 3 * sizeof(float) + 1);
        if (!npos_buf) goto oom;
        r = sfb__shade_apply(s, &sh->npos, sh->handles[0], sh->npos.rows, s->base_positions, npos_buf);
        if (r != SFB_SUCCESS) goto fail;
        npos = npos_buf;
    }
    /* face normals at the normals level (Newell), averaged per region into the sources */
    fnrm = (float *)sfb__alloc(ctx, (size_t)sh->nlev.nf * 3 * sizeof(float) + 1);
    src = (float *)sfb__calloc(ctx, (size_t)sh->nsrc * 3 + 1, sizeof(float));
    if (!fnrm || !src) goto oom;
    for (f = 0; f < sh->nlev.nf; ++f) {
        double n[3] = {0.0, 0.0, 0.0}, len;
        int a = sh->nlev.fv_off[f], cnt = sh->nlev.fv_off[f + 1] - a;
        for (i = 0; i < cnt; ++i) {
            const float *p = npos + 3 * (size_t)sh->nlev.fv[a + i], *q = npos + 3 * (size_t)sh->nlev.fv[a + (i + 1) % cnt];
            n[0] += ((double)p[1] - q[1]) * ((double)p[2] + q[2]);
            n[1] += ((double)p[2] - q[2]) * ((double)p[0] + q[0]);
            n[2] += ((double)p[0] - q[0]) * ((double)p[1] + q[1]);
        }
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (c = 0; c < 3; ++c) fnrm[3 * (size_t)f + c] = len > 0.0 ? (float)(n[c] / len) : 0.0f;
    }
    {
        double *acc = (double *)sfb__calloc(ctx, (size_t)sh->nsrc * 3 + 1, sizeof(double));
        if (!acc) goto oom;
        for (v = 0; v < sh->nlev.nv; ++v)
            for (i = sh->nlev.vf_off[v]; i < sh->nlev.vf_off[v + 1]; ++i)
                for (c = 0; c < 3; ++c) acc[3 * (size_t)sh->nsrc_of_vf[i] + c] += fnrm[3 * (size_t)sh->nlev.vf[i] + c];
        for (i = 0; i < sh->nsrc; ++i) {
            double *a = acc + 3 * (size_t)i, len = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
            for (c = 0; c < 3; ++c) {
                a[c] = len > 0.0 ? a[c] / len : 0.0;
                src[3 * (size_t)i + c] = (float)a[c];
            }
        }
        if (sh->nsteps > 0) srcd = acc;
        else sfb__free(ctx, acc);
    }
    /* output arrays */
    o->positions = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->limit_positions = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->tangents_u = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->tangents_v = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->normals = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->limit_normals = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->subdivided_normals = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->blend_weights = (float *)sfb__alloc(ctx, (size_t)sh->nout * sizeof(float) + 1);
    o->vertex_origin = (int *)sfb__alloc(ctx, (size_t)sh->nout * sizeof(int) + 1);
    ns = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    if (!o->positions || !o->limit_positions || !o->tangents_u || !o->tangents_v || !o->normals || !o->limit_normals ||
        !o->subdivided_normals || !o->blend_weights || !o->vertex_origin || !ns) goto oom;
    if ((r = sh->nsteps > 0 ? sfb__shade_levels(ctx, sh, srcd, rows, ns) : sfb__shade_apply(s, &sh->ns, sh->handles[1], rows, src, ns)) != SFB_SUCCESS ||
        (r = sfb__shade_apply(s, &sh->lim[0], sh->handles[2], sh->nout, refined, o->limit_positions)) != SFB_SUCCESS ||
        (r = sfb__shade_apply(s, &sh->lim[1], sh->handles[3], sh->nout, refined, o->tangents_u)) != SFB_SUCCESS ||
        (r = sfb__shade_apply(s, &sh->lim[2], sh->handles[4], sh->nout, refined, o->tangents_v)) != SFB_SUCCESS)
        goto fail;
    be = ctx->backend;
    if (!be || !be->finish_normals) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks finish_normals; using ref", be ? be->name : "none");
        be = &ctx->ref_vt;
    }
    r = be->finish_normals(be == ctx->backend ? ctx->backend_state : NULL, 0, sh->nout, o->tangents_u, o->tangents_v, ns,
                           all ? sh->ns_idx_all : sh->ns_idx_w, sh->b, prm.p, o->normals, o->limit_normals, o->subdivided_normals);
    if (r != SFB_SUCCESS) goto fail;
    for (v = 0; v < sh->nout; ++v) {
        int ov = sh->out_origin[v];
        for (c = 0; c < 3; ++c) o->positions[3 * (size_t)v + c] = refined[3 * (size_t)ov + c];
    }
    memcpy(o->blend_weights, sh->b, (size_t)sh->nout * sizeof(float));
    memcpy(o->vertex_origin, sh->out_origin, (size_t)sh->nout * sizeof(int));
    memcpy(o->face_vertices, sh->out_fv, (size_t)o->face_vertex_count * sizeof(int));
    o->refined_vertex_count = o->vertex_count;
    o->vertex_count = sh->nout;
    o->subdivided_count = rows;
    sfb__free(ctx, refined); sfb__free(ctx, npos_buf); sfb__free(ctx, src); sfb__free(ctx, ns); sfb__free(ctx, fnrm); sfb__free(ctx, srcd);
    return SFB_SUCCESS;
oom:
    r = sfb__oom(ctx, "shading output");
fail:
    sfb__free(ctx, refined); sfb__free(ctx, npos_buf); sfb__free(ctx, src); sfb__free(ctx, ns); sfb__free(ctx, fnrm); sfb__free(ctx, srcd);
    sfb_mesh_data_free(o);
    return r;
}

SFB_API sfb_result sfb_surface_shade_info(const sfb_surface *s, sfb_shade_info *out) {
    const sfb__shading *sh;
    if (!s || !out) return SFB_INVALID_ARGS;
    memset(out, 0, sizeof *out);
    sh = s->shading;
    if (!sh) return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_shade_info: the surface was created without SFB_REFINE_SHADING");
    out->refined_vertices = s->top.nv;
    out->output_vertices = sh->nout;
    out->split_vertices = sh->nsplit;
    out->weighted = sh->nweighted;
    out->normals_level = sh->normals_level;
    out->weights_level = sh->weights_level;
    out->sources = sh->nsrc;
    out->bytes = sh->bytes;
    return SFB_SUCCESS;
}
