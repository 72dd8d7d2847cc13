/* Surfaces: compile a mesh into tables once (sfb_surface_create), apply them on the
 * context's backend as often as needed (sfb_surface_eval_stencils / sfb_surface_refine). */

SFB_API sfb_surface_config sfb_surface_config_init(sfb_scheme scheme, int level) {
    sfb_surface_config c;
    memset(&c, 0, sizeof c);
    c.scheme = scheme;
    c.refine_level = level;
    return c;
}

SFB_API void sfb_surface_destroy(sfb_surface *s) {
    sfb_context *ctx;
    int t;
    if (!s) return;
    ctx = s->ctx;
    for (t = 0; t < SFB_TABLE_COUNT_; ++t) {
        if (s->backend_tables[t] && s->uploaded_by && s->uploaded_by->release_stencils)
            s->uploaded_by->release_stencils(ctx->backend_state, s->backend_tables[t]);
        sfb__stencils_free(ctx, &s->tables[t]);
    }
    if (s->backend_patches && s->uploaded_by && s->uploaded_by->release_patches)
        s->uploaded_by->release_patches(ctx->backend_state, s->backend_patches);
    if (s->backend_normal_field && s->uploaded_by && s->uploaded_by->release_patches)
        s->uploaded_by->release_patches(ctx->backend_state, s->backend_normal_field);
    sfb__patch_table_free(ctx, &s->patches);
    if (s->shading) {
        int h;
        for (h = 0; h < 5; ++h)
            if (s->shading->handles[h] && s->uploaded_by && s->uploaded_by->release_stencils)
                s->uploaded_by->release_stencils(ctx->backend_state, s->shading->handles[h]);
        sfb__shading_free(ctx, s->shading);
    }
    sfb__level_free(ctx, &s->pbase);
    sfb__level_free(ctx, &s->top);
    sfb__level_free(ctx, &s->uv_top);
    sfb__level_free(ctx, &s->uv_base);
    sfb__free(ctx, s->base_positions);
    sfb__free(ctx, s->base_uvs);
    sfb__free(ctx, s);
}

/* Rough peak bytes of refining `m` to `level`: topology of the last two levels plus composed
 * stencil rows in double during construction. Used to refuse early, before any allocation
 * sized by the level. */
static double sfb__estimate_bytes(const sfb_mesh *m, int triangles, int level, int limit, double *faces_out) {
    double faces = m->base.nf, verts = m->base.nv;
    int L;
    for (L = 0; L < level; ++L) {
        if (triangles) faces *= 4.0;
        else faces = (L == 0) ? (double)m->base.nfv : faces * 4.0;
    }
    verts = triangles ? faces / 2.0 + 2.0 : faces + 2.0;
    if (level == 0) verts = m->base.nv;
    *faces_out = faces;
    return faces * 4.0 * 40.0 + verts * 16.0 * 12.0 * (limit ? 3.0 : 1.5);
}

/* Refuses a scheme, level, flag set or mesh that sfb_surface_create cannot build, before any
 * allocation (the size estimate against SFB_MAX_ELEMENTS and the memory budget included). */
static sfb_result sfb__surface_check(sfb_context *ctx, const sfb_mesh *mesh, const sfb_surface_config *cfg) {
    const sfb__scheme_info *si = sfb__scheme_info_of(cfg->scheme);
    double faces, bytes;
    int f;
    sfb_result r;
    if ((r = sfb__scheme_check_kind(ctx, si, cfg)) != SFB_SUCCESS) return r;
    if (cfg->refine_level < 0) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "refinement level %d is negative", cfg->refine_level);
    if (cfg->refine_level > SFB_MAX_LEVEL)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "refinement level %d is over the limit of %d (SFB_MAX_LEVEL)",
                          cfg->refine_level, SFB_MAX_LEVEL);
    if ((r = sfb__scheme_check_flags(ctx, si, cfg)) != SFB_SUCCESS) return r;
    if ((cfg->flags & SFB_REFINE_PATCHES) && (cfg->isolation_level < 0 || cfg->isolation_level > SFB_MAX_LEVEL))
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "isolation level %d is outside 0..%d (0 = default %d)",
                          cfg->isolation_level, SFB_MAX_LEVEL, SFB_DEFAULT_ISOLATION);
    if (si->caps & SFB__SCHEME_TRIANGLES)
        for (f = 0; f < mesh->base.nf; ++f)
            if (mesh->base.fv_off[f + 1] - mesh->base.fv_off[f] != 3)
                return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "%s subdivision needs triangles; this face has %d vertices (sfb_mesh_triangulate, "
                                  "the tools' --triangulate, splits faces into triangles)",
                                  si->title, mesh->base.fv_off[f + 1] - mesh->base.fv_off[f]);
    bytes = sfb__estimate_bytes(mesh, (si->caps & SFB__SCHEME_TRIANGLES) != 0, cfg->refine_level, (cfg->flags & SFB_REFINE_LIMIT) != 0, &faces);
    if (faces > (double)SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "refining to level %d would make %.0f faces, over the limit of %d", cfg->refine_level, faces, SFB_MAX_ELEMENTS);
    if (bytes > (double)(ctx->budget - ctx->live_bytes))
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "refining to level %d needs about %.0f MiB, over the memory budget of %.1f MiB",
                          cfg->refine_level, bytes / 1048576.0, (double)ctx->budget / 1048576.0);
    return SFB_SUCCESS;
}

/* Refines the vertex mesh into s: the vertex (and limit) tables, the shading tables and the
 * patch table the flags ask for (s keeps the prepared base level of a patch table). */
static sfb_result sfb__surface_build_vertex(sfb_surface *s, const sfb_mesh *mesh, const sfb_surface_config *cfg) {
    sfb_context *ctx = s->ctx;
    const sfb__scheme_info *si = sfb__scheme_info_of(cfg->scheme);
    sfb__level prep;
    sfb__refine_options opt;
    sfb_result r;
    r = sfb__level_prepare(ctx, &mesh->base, mesh->boundary == SFB_BOUNDARY_EDGE_AND_CORNER,
                           mesh->boundary == SFB_BOUNDARY_NONE && (si->caps & SFB__SCHEME_BOUNDARY_HOLES), &prep);
    if (r != SFB_SUCCESS) return r;
    memset(&opt, 0, sizeof opt);
    opt.scheme = si->rules;
    opt.crease_method = mesh->crease_method;
    opt.triangle_rule = mesh->triangle_rule;
    opt.want_limit = (cfg->flags & SFB_REFINE_LIMIT) != 0;
    {
        /* the shading tables need every level and each step's own table: the vertex refinement
         * hands its over instead of the shading build refining a second time */
        const int shading = (cfg->flags & SFB_REFINE_SHADING) != 0, keep = shading && cfg->refine_level > 0;
        sfb__refine_kept kept;
        kept.lev = keep ? (sfb__level *)sfb__calloc(ctx, (size_t)cfg->refine_level, sizeof *kept.lev) : NULL;
        kept.T = keep ? (sfb__stencils *)sfb__calloc(ctx, (size_t)cfg->refine_level, sizeof *kept.T) : NULL;
        if (keep && (!kept.lev || !kept.T)) r = sfb__oom(ctx, "refinement");
        else r = sfb__refine_keep_levels(ctx, &prep, &opt, cfg->refine_level, &s->top, &s->tables[SFB_TABLE_VERTEX],
                                         opt.want_limit ? &s->tables[SFB_TABLE_LIMIT] : NULL, keep ? &kept : NULL, 0.0f, 0.8f);
        if (r == SFB_SUCCESS && shading)
            r = sfb__shading_build(ctx, &prep, &opt, cfg->refine_level, &cfg->shading, keep ? &kept : NULL, &s->top, &s->shading);
        sfb__free(ctx, kept.lev);
        sfb__free(ctx, kept.T);
    }
    if (r == SFB_SUCCESS && (cfg->flags & SFB_REFINE_PATCHES)) {
        r = si->build_patches(ctx, &prep, &opt, cfg, s->base_positions, &s->patches);
        if (r == SFB_SUCCESS) { s->has_patches = 1; s->pbase = prep; memset(&prep, 0, sizeof prep); }
    }
    sfb__level_free(ctx, &prep);
    if (r != SFB_SUCCESS) return r;
    s->built[SFB_TABLE_VERTEX] = 1;
    if (opt.want_limit) s->built[SFB_TABLE_LIMIT] = s->built[SFB_TABLE_TANGENT_U] = s->built[SFB_TABLE_TANGENT_V] = 1;
    return SFB_SUCCESS;
}

/* The UV layout is refined as a mesh of its own: its vertices are the UV values, so a seam (an
 * edge whose two faces disagree on a UV) is a boundary of the layout. It keeps the vertex
 * mesh's creases and corners; its own corners (one face, two edges) are pinned, as
 * OpenSubdiv's "linear corners only" face-varying mode. SFB_UV_LINEAR uses bilinear masks on
 * the same face split. Builds the UV table into s (the base UVs are copied by the caller). */
static sfb_result sfb__surface_build_uvs(sfb_surface *s, const sfb_mesh *mesh, const sfb_surface_config *cfg) {
    sfb_context *ctx = s->ctx;
    sfb__level uvl, uvp;
    sfb__refine_options opt;
    sfb__stencils dummy;
    sfb_result r;
    int f, o, i;
    r = sfb__level_from_faces(ctx, mesh->uv_count, mesh->base.nf, mesh->face_sizes, mesh->face_uvs, NULL, SFB_ELEMENT_UV, &uvl);
    if (r != SFB_SUCCESS) return r;
    for (f = 0; f < mesh->base.nf; ++f)
        for (o = mesh->base.fv_off[f], i = 0; o + i < mesh->base.fv_off[f + 1]; ++i) {
            int ue = uvl.fe[o + i], e = mesh->base.fe[o + i], uvv = mesh->face_uvs[o + i], vv = mesh->base.fv[o + i];
            if (mesh->base.es[e] > uvl.es[ue]) uvl.es[ue] = mesh->base.es[e];
            if (mesh->base.vs[vv] > uvl.vs[uvv]) uvl.vs[uvv] = mesh->base.vs[vv];
        }
    r = sfb__level_prepare(ctx, &uvl, 1, 0, &uvp);
    sfb__level_free(ctx, &uvl);
    if (r != SFB_SUCCESS) return r;
    memset(&opt, 0, sizeof opt);
    opt.scheme = sfb__scheme_info_of(cfg->scheme)->rules;
    opt.crease_method = mesh->crease_method;
    opt.triangle_rule = mesh->triangle_rule;
    opt.linear = mesh->uv_interp == SFB_UV_LINEAR;
    memset(&dummy, 0, sizeof dummy);
    r = sfb__refine(ctx, &uvp, &opt, cfg->refine_level, &s->uv_top, &s->tables[SFB_TABLE_UV], NULL, 0.8f, 1.0f);
    /* kept for tessellated UVs (SFB_TESS_UVS builds their patch table from it when asked) */
    if (r == SFB_SUCCESS && (cfg->flags & SFB_REFINE_PATCHES)) { s->uv_base = uvp; memset(&uvp, 0, sizeof uvp); }
    sfb__level_free(ctx, &uvp);
    if (r != SFB_SUCCESS) return r;
    s->built[SFB_TABLE_UV] = 1;
    s->has_uvs = 1;
    s->base_uv_count = mesh->uv_count;
    return SFB_SUCCESS;
}

/* Whether tessellated UVs are the limit of the UV layout (its own patch table,
 * sfb__surface_uv_patches), or follow each face linearly: SFB_UV_LINEAR, and the schemes marked
 * SFB__SCHEME_LINEAR_UVS or without a patch builder. */
int sfb__surface_smooth_uvs(const sfb_surface *s) {
    const sfb__scheme_info *si = sfb__scheme_info_of(s->config.scheme);
    return s->uv_interp != SFB_UV_LINEAR && si && si->build_patches && !(si->caps & SFB__SCHEME_LINEAR_UVS);
}

/* The patch table of the base UV layout (its vertices the UV values, z = 0) by the scheme's own
 * builder, for tessellated UVs (tess.c); its parametric faces are the surface's.
 * A layout that is not a manifold (a UV value shared by faces that do not form one fan, as
 * placeholder UVs are: OpenSubdiv's car has 4 UV values for 1575 faces) is sharpened there like
 * any non-manifold vertex, and every face beside such a vertex is irregular: isolating them to
 * the surface's level costs seconds and gigabytes for a label, not a layout. Such a layout is
 * isolated one level only; end caps approximate it near its irregular features. */
sfb_result sfb__surface_uv_patches(const sfb_surface *s, sfb__patch_table *upt) {
    sfb_context *ctx = s->ctx;
    const sfb__scheme_info *si = sfb__scheme_info_of(s->config.scheme);
    sfb__refine_options opt;
    sfb_surface_config ucfg;
    float *P;
    sfb_result r;
    int i;
    memset(upt, 0, sizeof *upt);
    if (!si || !si->build_patches || !s->uv_base.fv)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "tessellated UVs: the surface has no UV layout to evaluate");
    memset(&opt, 0, sizeof opt);
    opt.scheme = si->rules;
    opt.crease_method = s->crease_method;
    opt.triangle_rule = s->triangle_rule;
    P = (float *)sfb__alloc(ctx, ((size_t)s->uv_base.nv + 1) * 3 * sizeof(float));
    if (!P) return sfb__oom(ctx, "tessellated UVs");
    for (i = 0; i < s->uv_base.nv; ++i) {
        P[3 * i] = s->base_uvs[2 * i];
        P[3 * i + 1] = s->base_uvs[2 * i + 1];
        P[3 * i + 2] = 0.0f;
    }
    ucfg = s->config;
    ucfg.tribezier.slider = 0; /* the layout's own surface is built for this s only */
    for (i = 0; i < s->uv_base.nv; ++i)
        if (s->uv_base.vtag[i] & SFB__TAG_NONMANIFOLD) break;
    if (i < s->uv_base.nv) {
        ucfg.isolation_level = 1;
        sfb__log(ctx, SFB_LOG_INFO, "tessellated UVs: the UV layout is not a manifold (UV %d): isolated one level", i);
    }
    r = si->build_patches(ctx, &s->uv_base, &opt, &ucfg, P, upt);
    sfb__free(ctx, P);
    if (r == SFB_SUCCESS && upt->nptex != s->patches.nptex) {
        r = sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellated UVs: the UV layout has %d parametric faces, the surface %d",
                       upt->nptex, s->patches.nptex);
        sfb__patch_table_free(ctx, upt);
    }
    return r;
}

/* Hands the built tables (stencils, shading, patches) to the context's backend once (device
 * upload); failures come back here. */
static sfb_result sfb__surface_upload(sfb_surface *s) {
    sfb_context *ctx = s->ctx;
    sfb_result r;
    if (ctx->backend && ctx->backend->upload_stencils) {
        int t;
        s->uploaded_by = ctx->backend;
        for (t = 0; t < SFB_TABLE_COUNT_; ++t) {
            if (!s->built[t] || s->tables[t].rows == 0) continue;
            r = ctx->backend->upload_stencils(ctx->backend_state, &s->tables[t], &s->backend_tables[t]);
            if (r != SFB_SUCCESS) return r;
        }
        if (s->shading) {
            sfb__shading *sh = s->shading;
            const sfb__stencils *st[5];
            st[0] = &sh->npos; st[1] = &sh->ns; st[2] = &sh->lim[0]; st[3] = &sh->lim[1]; st[4] = &sh->lim[2];
            for (t = 0; t < 5; ++t) {
                if (st[t]->rows == 0) continue;
                r = ctx->backend->upload_stencils(ctx->backend_state, st[t], &sh->handles[t]);
                if (r != SFB_SUCCESS) return r;
            }
        }
    }
    if (s->has_patches && ctx->backend && ctx->backend->upload_patches) {
        s->uploaded_by = ctx->backend;
        r = ctx->backend->upload_patches(ctx->backend_state, &s->patches, &s->backend_patches);
        if (r == SFB_SUCCESS && s->patches.normal_field)
            r = ctx->backend->upload_patches(ctx->backend_state, s->patches.normal_field, &s->backend_normal_field);
        if (r != SFB_SUCCESS) return r;
    }
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_surface_create(sfb_context *ctx, const sfb_mesh *mesh, const sfb_surface_config *cfg, sfb_surface **out) {
    sfb_surface *s;
    sfb_result r;
    int oom = 0;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!mesh || !cfg || !out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_create: NULL argument");
    *out = NULL;
    if ((r = sfb__surface_check(ctx, mesh, cfg)) != SFB_SUCCESS) return r;
    s = (sfb_surface *)sfb__calloc(ctx, 1, sizeof *s);
    if (!s) return sfb__oom(ctx, "surface");
    s->ctx = ctx;
    s->serial = ++ctx->surfaces_made;
    s->config = *cfg;
    s->boundary = mesh->boundary; s->crease_method = mesh->crease_method;
    s->triangle_rule = mesh->triangle_rule; s->uv_interp = mesh->uv_interp;
    s->base_vertex_count = mesh->base.nv;
    s->base_face_count = mesh->base.nf;
    s->base_positions = (float *)sfb__alloc(ctx, (size_t)mesh->base.nv * 3 * sizeof(float) + 1);
    if (!s->base_positions) { oom = 1; goto fail; }
    memcpy(s->base_positions, mesh->positions, (size_t)mesh->base.nv * 3 * sizeof(float));
    if ((r = sfb__surface_build_vertex(s, mesh, cfg)) != SFB_SUCCESS) goto fail;
    if ((cfg->flags & SFB_REFINE_UVS) && mesh->uv_count > 0) {
        if ((r = sfb__surface_build_uvs(s, mesh, cfg)) != SFB_SUCCESS) goto fail;
        s->base_uvs = (float *)sfb__alloc(ctx, (size_t)mesh->uv_count * 2 * sizeof(float));
        if (!s->base_uvs) { oom = 1; goto fail; }
        memcpy(s->base_uvs, mesh->uvs, (size_t)mesh->uv_count * 2 * sizeof(float));
    }
    if ((r = sfb__progress(ctx, 1.0f, "refine")) != SFB_SUCCESS) goto fail;
    if ((r = sfb__surface_upload(s)) != SFB_SUCCESS) goto fail;
    *out = s;
    return SFB_SUCCESS;
fail:
    /* the one cleanup path: everything s holds; an allocation failure is reported after it (the
     * message gives the bytes still in use) */
    sfb_surface_destroy(s);
    return oom ? sfb__oom(ctx, "surface") : r;
}

/* The slider: the nets kept at create (patch/tribezier.c, pt->blend) blended for `o` into a new
 * point array; the backend gets a new upload of it before the old one is released, so an error
 * anywhere leaves the points as they were (0 and the error then). */
static sfb_result sfb__surface_reblend(sfb_surface *s, const sfb_tribezier_options *o) {
    sfb_context *ctx = s->ctx;
    sfb__patch_table *pt = &s->patches;
    float *old, *fresh = (float *)sfb__alloc(ctx, 3 * (size_t)pt->npoints * sizeof(float) + 1);
    void *handle = NULL;
    if (!fresh || !sfb__tribezier_blend(ctx, pt, o, fresh)) {
        sfb__free(ctx, fresh);
        return sfb__oom(ctx, "the sharpness slider");
    }
    old = pt->point_data;
    pt->point_data = fresh;
    if (s->backend_patches && s->uploaded_by && s->uploaded_by->upload_patches) {
        const sfb_result r = s->uploaded_by->upload_patches(ctx->backend_state, pt, &handle);
        if (r != SFB_SUCCESS) {
            pt->point_data = old;
            sfb__free(ctx, fresh);
            return r;
        }
        if (s->uploaded_by->release_patches) s->uploaded_by->release_patches(ctx->backend_state, s->backend_patches);
        s->backend_patches = handle;
    }
    sfb__free(ctx, old);
    s->serial = ++ctx->surfaces_made;
    return SFB_SUCCESS;
}

/* A slider surface, or the error why not (who: the caller's name). */
static sfb_result sfb__surface_slider(sfb_surface *s, const char *who) {
    if (s->config.scheme != SFB_SCHEME_TRIBEZIER || !s->has_patches || !s->patches.blend || !s->patches.features)
        return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "%s: the surface %s", who,
                          s->config.scheme != SFB_SCHEME_TRIBEZIER ? "is not SFB_SCHEME_TRIBEZIER"
                                                                    : "was built without tribezier.slider (its smooth and sharp nets were not kept)");
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_surface_set_sharpness(sfb_surface *s, const sfb_tribezier_options *options) {
    sfb_tribezier_options o;
    sfb_result r;
    if (!s) return SFB_INVALID_ARGS;
    if (!options) return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_set_sharpness: options is NULL");
    if ((r = sfb__surface_slider(s, "sfb_surface_set_sharpness")) != SFB_SUCCESS) return r;
    if (options->sharpness_set && !(options->sharpness >= 0.0f && options->sharpness <= 1.0f))
        return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_set_sharpness: sharpness %g is not in [0, 1]",
                          (double)options->sharpness);
    o = *options;
    o.slider = 1;
    if ((r = sfb__surface_reblend(s, &o)) == SFB_SUCCESS) s->config.tribezier = o;
    return r;
}

/* The base edge from a to b (the surface's prepared base level), or -1. */
static int sfb__surface_edge(const sfb_surface *s, int a, int b) {
    const sfb__level *l = &s->pbase;
    int i;
    if (a < 0 || b < 0 || a >= l->nv || b >= l->nv) return -1;
    for (i = l->ve_off[a]; i < l->ve_off[a + 1]; ++i)
        if (sfb__other_end(l, l->ve[i], a) == b) return l->ve[i];
    return -1;
}

SFB_API sfb_result sfb_surface_set_feature_sharpness(sfb_surface *s, int crease_count, const int *crease_vertices,
                                                     const float *crease_sharpness, int corner_count, const int *corner_vertices,
                                                     const float *corner_sharpness) {
    static const char *who = "sfb_surface_set_feature_sharpness";
    sfb_context *ctx;
    sfb__tbz_features *F;
    float *es = NULL, *cs = NULL;
    sfb_tribezier_options o;
    sfb_result r;
    int i;
    if (!s) return SFB_INVALID_ARGS;
    ctx = s->ctx;
    if ((r = sfb__surface_slider(s, who)) != SFB_SUCCESS) return r;
    if (crease_count < 0 || corner_count < 0 || (crease_count && (!crease_vertices || !crease_sharpness)) ||
        (corner_count && (!corner_vertices || !corner_sharpness)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "%s: a negative count, or a NULL array with a count", who);
    F = s->patches.features;
    /* checked whole first: nothing changes on an error */
    for (i = 0; i < crease_count; ++i) {
        const int a = crease_vertices[2 * i], b = crease_vertices[2 * i + 1], e = sfb__surface_edge(s, a, b);
        if (!(crease_sharpness[i] >= 0.0f))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_EDGE, e, "%s: crease %d (%d, %d): sharpness %g is not >= 0", who, i, a, b,
                              (double)crease_sharpness[i]);
        if (e < 0 || e >= F->nbe || !(s->pbase.es[e] > 0.0f))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_EDGE, e,
                              "%s: crease %d (%d, %d) is not a tagged edge of the surface's mesh (the nets depend on which edges are "
                              "creases: build the surface again to add one)", who, i, a, b);
    }
    for (i = 0; i < corner_count; ++i) {
        const int v = corner_vertices[i];
        if (!(corner_sharpness[i] >= 0.0f))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, v, "%s: corner %d (vertex %d): sharpness %g is not >= 0", who, i, v,
                              (double)corner_sharpness[i]);
        if (v < 0 || v >= F->nbv || !(s->pbase.vs[v] > 0.0f))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, v,
                              "%s: corner %d (vertex %d) is not a tagged corner of the surface's mesh (build the surface again to add one)", who,
                              i, v);
    }
    es = (float *)sfb__alloc(ctx, ((size_t)F->nbe + 1) * sizeof(float));
    cs = (float *)sfb__alloc(ctx, ((size_t)F->nbv + 1) * sizeof(float));
    if (!es || !cs) {
        sfb__free(ctx, es);
        sfb__free(ctx, cs);
        return sfb__oom(ctx, who);
    }
    memcpy(es, F->es, (size_t)F->nbe * sizeof(float));
    memcpy(cs, F->cs, (size_t)F->nbv * sizeof(float));
    /* as the build takes a tag: clamped to [0, 1] (a crease at 0 stays one: the smooth net's) */
    for (i = 0; i < crease_count; ++i)
        F->es[sfb__surface_edge(s, crease_vertices[2 * i], crease_vertices[2 * i + 1])] = crease_sharpness[i] < 1.0f ? crease_sharpness[i] : 1.0f;
    /* a vertex the preparation made sharp whatever its tag (non-manifold) stays so, as at create */
    for (i = 0; i < corner_count; ++i)
        if (!sfb__level_forced_sharp(&s->pbase, corner_vertices[i], s->boundary == SFB_BOUNDARY_EDGE_AND_CORNER))
            F->cs[corner_vertices[i]] = corner_sharpness[i] < 1.0f ? corner_sharpness[i] : 1.0f;
    o = s->config.tribezier;
    o.sharpness_set = 0;
    o.slider = 1;
    if ((r = sfb__surface_reblend(s, &o)) == SFB_SUCCESS) s->config.tribezier = o;
    else {
        memcpy(F->es, es, (size_t)F->nbe * sizeof(float));
        memcpy(F->cs, cs, (size_t)F->nbv * sizeof(float));
    }
    sfb__free(ctx, es);
    sfb__free(ctx, cs);
    return r;
}

SFB_API int sfb_surface_param_face_count(const sfb_surface *s) { return s && s->has_patches ? s->patches.nptex : 0; }

SFB_API sfb_result sfb_surface_param_faces(const sfb_surface *s, int base_face, int *first, int *count) {
    if (!s || !first || !count) return SFB_INVALID_ARGS;
    if (!s->has_patches) return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the surface has no patch table (SFB_REFINE_PATCHES)");
    if (base_face < 0 || !s->patches.face_ptex || base_face >= s->base_face_count)
        return sfb__error(s->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_FACE, base_face, "base face %d is out of range (0..%d)", base_face, s->base_face_count - 1);
    *first = s->patches.face_ptex[base_face];
    *count = s->patches.face_ptex[base_face + 1] - *first;
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_surface_param_face_base(const sfb_surface *s, int pf, int *base_face, int *sub_face) {
    if (!s || !base_face || !sub_face) return SFB_INVALID_ARGS;
    if (!s->has_patches) return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the surface has no patch table (SFB_REFINE_PATCHES)");
    if (pf < 0 || pf >= s->patches.nptex)
        return sfb__error(s->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_FACE, pf, "parametric face %d is out of range (0..%d)", pf, s->patches.nptex - 1);
    *base_face = s->patches.ptex_face[pf];
    *sub_face = s->patches.ptex_corner[pf];
    return SFB_SUCCESS;
}

/* The memory of a patch table and its points, its normal field's included. */
static size_t sfb__patch_table_bytes(const sfb__patch_table *pt) {
    return (size_t)pt->npatch * (4 * sizeof(int)) + (size_t)pt->ncv * sizeof(int) + (size_t)pt->nptex * 3 * sizeof(int) +
           (size_t)pt->nnodes * 4 * sizeof(int) + (size_t)pt->npoints * 3 * sizeof(float) +
           (pt->pcorner ? (size_t)pt->npatch * 4 * sizeof(unsigned) : 0) + (pt->normal_field ? sfb__patch_table_bytes(pt->normal_field) : 0) +
           (pt->blend ? (size_t)pt->npatch * SFB__TBZ_BLEND * sizeof(float) : 0) +
           (pt->features ? ((size_t)pt->features->nv * 4 + (size_t)pt->features->eoff[pt->features->nv] + 3 * (size_t)pt->npatch) * sizeof(int) +
                               ((size_t)pt->features->nbe + pt->features->nbv) * sizeof(float)
                         : 0);
}

SFB_API sfb_result sfb_surface_patch_info(const sfb_surface *s, sfb_patch_info *o) {
    const sfb__patch_table *pt;
    if (!s || !o) return SFB_INVALID_ARGS;
    memset(o, 0, sizeof *o);
    if (!s->has_patches) return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the surface has no patch table (SFB_REFINE_PATCHES)");
    pt = &s->patches;
    o->param_faces = pt->nptex;
    o->patches = pt->npatch;
    o->bspline = pt->counts[SFB__PATCH_BSPLINE];
    o->bezier = pt->counts[SFB__PATCH_BEZTRI];
    o->stam = pt->counts[SFB__PATCH_STAM] + pt->counts[SFB__PATCH_STAM_LOOP];
    o->end_caps = pt->counts[SFB__PATCH_ENDCAP] + pt->counts[SFB__PATCH_ENDCAP_TRI];
    o->manifold = pt->counts[SFB__PATCH_MANIFOLD4];
    o->max_depth = pt->max_depth;
    o->points = pt->npoints;
    o->domain_sides = pt->domain == SFB__DOMAIN_TRI ? 3 : 4;
    o->bytes = sfb__patch_table_bytes(pt);
    return SFB_SUCCESS;
}

/* What is wrong with location l: 0 nothing, 1 its face is out of range, 2 (u,v) is outside
 * [0,1]^2, 3 outside the triangle u + v <= 1, 4 its face is a hole (holes are whole parametric
 * faces, since a hole is a base face: the root says it). */
static int sfb__location_fault(const sfb_surface *s, const sfb_location *l) {
    if (l->face < 0 || l->face >= s->patches.nptex) return 1;
    if (!(l->u >= 0.0f && l->u <= 1.0f && l->v >= 0.0f && l->v <= 1.0f)) return 2;
    if (s->patches.domain == SFB__DOMAIN_TRI && (double)l->u + (double)l->v > 1.0) return 3;
    if (s->patches.ptex_root[l->face] == -1) return 4;
    return 0;
}

/* The location check of sfb_surface_eval in blocks over the backend's threads: block b's first
 * faulty location (or -1) into first_bad[b]. */
#define SFB__EVAL_CHECK_BLOCKS 64
#define SFB__EVAL_CHECK_PARALLEL 131072 /* locations: from this many on the check goes to the threads */
typedef struct sfb__eval_check_job {
    const sfb_surface *s;
    const sfb_location *loc;
    int count, block;
    int first_bad[SFB__EVAL_CHECK_BLOCKS];
} sfb__eval_check_job;

static void sfb__eval_check_blocks(void *arg, int a, int b) {
    sfb__eval_check_job *J = (sfb__eval_check_job *)arg;
    int k, q;
    for (k = a; k < b; ++k) {
        const int end = (int)((long long)(k + 1) * J->block < J->count ? (long long)(k + 1) * J->block : J->count);
        J->first_bad[k] = -1;
        for (q = k * J->block; q < end; ++q)
            if (sfb__location_fault(J->s, &J->loc[q])) { J->first_bad[k] = q; break; }
    }
}

SFB_API sfb_result sfb_surface_eval(const sfb_surface *s, const sfb_location *loc, int count, const sfb_eval_output *out) {
    sfb_context *ctx;
    int q = -1, fault = 0;
    if (!s) return SFB_INVALID_ARGS;
    ctx = s->ctx;
    if (!s->has_patches) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_eval: the surface has no patch table (create it with SFB_REFINE_PATCHES)");
    if (count < 0 || (count > 0 && (!loc || !out)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_eval: %s", count < 0 ? "negative count" : "NULL locations or outputs");
    /* every location is checked before anything is written; the first faulty one is reported */
    if (count >= SFB__EVAL_CHECK_PARALLEL) {
        sfb__eval_check_job J;
        int k;
        J.s = s; J.loc = loc; J.count = count;
        J.block = (count + SFB__EVAL_CHECK_BLOCKS - 1) / SFB__EVAL_CHECK_BLOCKS;
        sfb__parallel(ctx, sfb__eval_check_blocks, &J, 0, SFB__EVAL_CHECK_BLOCKS);
        for (k = 0; k < SFB__EVAL_CHECK_BLOCKS && q < 0; ++k) q = J.first_bad[k];
        if (q >= 0) fault = sfb__location_fault(s, &loc[q]);
    } else {
        for (q = 0; q < count && !(fault = sfb__location_fault(s, &loc[q])); ++q) {}
    }
    if (fault) {
        const sfb_location *l = &loc[q];
        if (fault == 1)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, q, "location %d: parametric face %d is out of range (0..%d)", q, l->face,
                              s->patches.nptex - 1);
        if (fault == 2)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, q, "location %d: (u,v) = (%g,%g) is outside [0,1]^2", q, (double)l->u,
                              (double)l->v);
        if (fault == 3)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, q, "location %d: (u,v) = (%g,%g) is outside the triangle u + v <= 1", q,
                              (double)l->u, (double)l->v);
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, q, "location %d: parametric face %d is a hole", q, l->face);
    }
    return sfb__surface_eval_unchecked(s, loc, count, out);
}

/* One of the surface's patch tables (`handle`: its upload) on the context's backend, or on ref
 * when the backend lacks eval_patches. */
static sfb_result sfb__surface_eval_table(const sfb_surface *s, const sfb__patch_table *pt, void *handle, const sfb_location *loc,
                                          int count, const sfb_eval_output *out) {
    sfb_context *ctx = s->ctx;
    const sfb__backend_vtable *be = ctx->backend;
    if (!be || !be->eval_patches) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks eval_patches; using ref", be ? be->name : "none");
        return sfb__ref_eval_patches(NULL, pt, NULL, loc, 0, count, out);
    }
    return be->eval_patches(ctx->backend_state, pt, s->uploaded_by == be ? handle : NULL, loc, 0, count, out);
}

/* With a normal field (PN triangles), the normals are that field's values normalised, in
 * double (a zero vector stays zero), and the patches give the rest. */
sfb_result sfb__surface_eval_unchecked(const sfb_surface *s, const sfb_location *loc, int count, const sfb_eval_output *out) {
    const sfb__patch_table *nf = s->patches.normal_field;
    sfb_eval_output rest;
    sfb_result r;
    int q;
    if (count == 0) return SFB_SUCCESS;
    if (!nf || !out->normal) return sfb__surface_eval_table(s, &s->patches, s->backend_patches, loc, count, out);
    memset(&rest, 0, sizeof rest);
    rest.position = out->normal;
    if ((r = sfb__surface_eval_table(s, nf, s->backend_normal_field, loc, count, &rest)) != SFB_SUCCESS) return r;
    for (q = 0; q < count; ++q) {
        float *n = out->normal + 3 * (size_t)q;
        const double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (len > 0.0) {
            n[0] = (float)(n[0] / len); n[1] = (float)(n[1] / len); n[2] = (float)(n[2] / len);
        }
    }
    rest = *out;
    rest.normal = NULL;
    if (!rest.position && !rest.du && !rest.dv && !rest.duu && !rest.duv && !rest.dvv) return SFB_SUCCESS;
    return sfb__surface_eval_table(s, &s->patches, s->backend_patches, loc, count, &rest);
}

SFB_API sfb_result sfb_surface_stencil_info(const sfb_surface *s, sfb_table t, sfb_stencil_info *out) {
    if (!s || !out || (int)t < 0 || t >= SFB_TABLE_COUNT_ || !s->built[t]) return SFB_INVALID_ARGS;
    out->rows = s->tables[t].rows;
    out->sources = s->tables[t].sources;
    out->entries = (int)s->tables[t].entries;
    return SFB_SUCCESS;
}

static int sfb__desc_ok(sfb_buffer_desc d) { return d.offset >= 0 && d.length >= 1 && d.length <= 16 && d.stride >= d.length; }

/* The checks both eval entry points share: a built table and two compatible views. */
static sfb_result sfb__eval_args(const sfb_surface *s, sfb_table t, int have_buffers, sfb_buffer_desc sd, sfb_buffer_desc dd,
                                 const char *what) {
    if ((int)t < 0 || t >= SFB_TABLE_COUNT_ || !s->built[t])
        return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "stencil table %d was not built for this surface", (int)t);
    if (!have_buffers || !sfb__desc_ok(sd) || !sfb__desc_ok(dd) || sd.length != dd.length)
        return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "invalid %s or buffer descriptors for stencil evaluation", what);
    return SFB_SUCCESS;
}

/* Rows [0, rows) of table `t` on the context's backend (`handle`: its upload of t), or on ref
 * when the backend lacks eval_stencils. Arguments already checked. */
sfb_result sfb__surface_apply(const sfb_surface *s, const sfb__stencils *t, void *handle, int rows, const float *src,
                                     sfb_buffer_desc sd, float *dst, sfb_buffer_desc dd) {
    sfb_context *ctx = s->ctx;
    const sfb__backend_vtable *be = ctx->backend;
    if (!be || !be->eval_stencils) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks eval_stencils; using ref", be ? be->name : "none");
        return sfb__ref_eval_stencils(NULL, t, NULL, 0, rows, src, sd, dst, dd);
    }
    if (rows <= 0) return SFB_SUCCESS;
    return be->eval_stencils(ctx->backend_state, t, s->uploaded_by == be ? handle : NULL, 0, rows, src, sd, dst, dd);
}

SFB_API sfb_result sfb_surface_eval_stencils(const sfb_surface *s, sfb_table t, const float *src, sfb_buffer_desc sd,
                                             float *dst, sfb_buffer_desc dd) {
    sfb_result r;
    if (!s) return SFB_INVALID_ARGS;
    if ((r = sfb__eval_args(s, t, src && dst, sd, dd, "buffers")) != SFB_SUCCESS) return r;
    return sfb__surface_apply(s, &s->tables[t], s->backend_tables[t], s->tables[t].rows, src, sd, dst, dd);
}

SFB_API sfb_result sfb_surface_eval_stencils_gl(const sfb_surface *s, sfb_table t, unsigned int src_buffer, sfb_buffer_desc sd,
                                                unsigned int dst_buffer, sfb_buffer_desc dd) {
    sfb_context *ctx;
    const sfb__backend_vtable *be;
    sfb_result r;
    if (!s) return SFB_INVALID_ARGS;
    ctx = s->ctx;
    if ((r = sfb__eval_args(s, t, src_buffer && dst_buffer, sd, dd, "GL buffers")) != SFB_SUCCESS) return r;
    be = ctx->backend;
    if (!be || !be->eval_stencils_gl)
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_eval_stencils_gl needs the gl backend on the host's context (gl_use_current_context); this context runs %s",
                          be ? be->name : "no backend");
    if (s->tables[t].rows == 0) return SFB_SUCCESS;
    return be->eval_stencils_gl(ctx->backend_state, &s->tables[t], s->uploaded_by == be ? s->backend_tables[t] : NULL,
                                src_buffer, sd, dst_buffer, dd);
}

SFB_API void sfb_mesh_data_free(sfb_mesh_data *d) {
    sfb_context *ctx;
    if (!d || !d->ctx_) return;
    ctx = d->ctx_;
    sfb__free(ctx, d->positions); sfb__free(ctx, d->limit_positions); sfb__free(ctx, d->tangents_u);
    sfb__free(ctx, d->tangents_v); sfb__free(ctx, d->normals); sfb__free(ctx, d->uvs);
    sfb__free(ctx, d->face_sizes); sfb__free(ctx, d->face_vertices); sfb__free(ctx, d->face_uvs);
    sfb__free(ctx, d->crease_vertices); sfb__free(ctx, d->crease_sharpness);
    sfb__free(ctx, d->corner_vertices); sfb__free(ctx, d->corner_sharpness); sfb__free(ctx, d->holes);
    sfb__free(ctx, d->blend_weights); sfb__free(ctx, d->limit_normals); sfb__free(ctx, d->subdivided_normals);
    sfb__free(ctx, d->vertex_origin);
    memset(d, 0, sizeof *d);
}


SFB_API sfb_result sfb_surface_refine(const sfb_surface *s, sfb_mesh_data *out) {
    if (!s) return SFB_INVALID_ARGS;
    return sfb_surface_refine_positions(s, s->base_positions, s->base_vertex_count, out);
}

SFB_API sfb_result sfb_surface_refine_positions(const sfb_surface *s, const float *base, int base_count, sfb_mesh_data *o) {
    return sfb__refine_output(s, base, base_count, 1, o);
}

/* The refined mesh; with want_limit the limit tables too (when built). */
sfb_result sfb__refine_output(const sfb_surface *s, const float *base, int base_count, int want_limit, sfb_mesh_data *o) {
    sfb_context *ctx;
    const sfb__level *l;
    sfb_buffer_desc d3 = {0, 3, 3}, d2 = {0, 2, 2};
    sfb_result r;
    int i, e, v, f, nv;
    if (!s || !o) return SFB_INVALID_ARGS;
    memset(o, 0, sizeof *o);
    ctx = s->ctx;
    if (!base || base_count != s->base_vertex_count)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "expected %d base positions, got %d", s->base_vertex_count, base_count);
    l = &s->top;
    nv = l->nv;
    o->ctx_ = ctx;
    o->vertex_count = nv;
    o->face_count = l->nf;
    o->face_vertex_count = l->nfv;
    o->boundary = s->boundary; o->crease_method = s->crease_method;
    o->triangle_rule = s->triangle_rule; o->uv_interp = s->uv_interp;
    o->positions = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
    o->face_sizes = (int *)sfb__alloc(ctx, (size_t)l->nf * sizeof(int) + 1);
    o->face_vertices = (int *)sfb__alloc(ctx, (size_t)l->nfv * sizeof(int) + 1);
    if (!o->positions || !o->face_sizes || !o->face_vertices) goto oom;
    r = sfb_surface_eval_stencils(s, SFB_TABLE_VERTEX, base, d3, o->positions, d3);
    if (r != SFB_SUCCESS) { sfb_mesh_data_free(o); return r; }
    if (s->built[SFB_TABLE_LIMIT] && want_limit) {
        o->limit_positions = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
        o->tangents_u = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
        o->tangents_v = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
        o->normals = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
        if (!o->limit_positions || !o->tangents_u || !o->tangents_v || !o->normals) goto oom;
        if ((r = sfb_surface_eval_stencils(s, SFB_TABLE_LIMIT, base, d3, o->limit_positions, d3)) != SFB_SUCCESS ||
            (r = sfb_surface_eval_stencils(s, SFB_TABLE_TANGENT_U, base, d3, o->tangents_u, d3)) != SFB_SUCCESS ||
            (r = sfb_surface_eval_stencils(s, SFB_TABLE_TANGENT_V, base, d3, o->tangents_v, d3)) != SFB_SUCCESS) {
            sfb_mesh_data_free(o);
            return r;
        }
        for (v = 0; v < nv; ++v) {
            const float *a = o->tangents_u + 3 * (size_t)v, *b = o->tangents_v + 3 * (size_t)v;
            double n0 = (double)a[1] * b[2] - (double)a[2] * b[1];
            double n1 = (double)a[2] * b[0] - (double)a[0] * b[2];
            double n2 = (double)a[0] * b[1] - (double)a[1] * b[0];
            double len = sqrt(n0 * n0 + n1 * n1 + n2 * n2);
            float *n = o->normals + 3 * (size_t)v;
            /* degenerate tangents (e.g. a corner with collinear edges) give a zero normal */
            if (len > 0.0) { n[0] = (float)(n0 / len); n[1] = (float)(n1 / len); n[2] = (float)(n2 / len); }
            else { n[0] = n[1] = n[2] = 0.0f; }
        }
    }
    for (f = 0; f < l->nf; ++f) o->face_sizes[f] = l->fv_off[f + 1] - l->fv_off[f];
    memcpy(o->face_vertices, l->fv, (size_t)l->nfv * sizeof(int));
    if (s->has_uvs) {
        o->uv_count = s->uv_top.nv;
        o->uvs = (float *)sfb__alloc(ctx, (size_t)o->uv_count * 2 * sizeof(float) + 1);
        o->face_uvs = (int *)sfb__alloc(ctx, (size_t)l->nfv * sizeof(int) + 1);
        if (!o->uvs || !o->face_uvs) goto oom;
        r = sfb_surface_eval_stencils(s, SFB_TABLE_UV, s->base_uvs, d2, o->uvs, d2);
        if (r != SFB_SUCCESS) { sfb_mesh_data_free(o); return r; }
        memcpy(o->face_uvs, s->uv_top.fv, (size_t)l->nfv * sizeof(int));
    }
    /* remaining sharpness: edges with sharpness that are not boundary edges (those are always
     * sharp), vertices with sharpness, hole faces */
    for (e = 0; e < l->ne; ++e) o->crease_count += l->es[e] > 0.0f && !(l->etag[e] & SFB__TAG_BOUNDARY);
    for (v = 0; v < nv; ++v) o->corner_count += l->vs[v] > 0.0f;
    for (f = 0; f < l->nf; ++f) o->hole_count += l->fhole[f] != 0;
    o->crease_vertices = (int *)sfb__alloc(ctx, (size_t)o->crease_count * 2 * sizeof(int) + 1);
    o->crease_sharpness = (float *)sfb__alloc(ctx, (size_t)o->crease_count * sizeof(float) + 1);
    o->corner_vertices = (int *)sfb__alloc(ctx, (size_t)o->corner_count * sizeof(int) + 1);
    o->corner_sharpness = (float *)sfb__alloc(ctx, (size_t)o->corner_count * sizeof(float) + 1);
    o->holes = (int *)sfb__alloc(ctx, (size_t)o->hole_count * sizeof(int) + 1);
    if (!o->crease_vertices || !o->crease_sharpness || !o->corner_vertices || !o->corner_sharpness || !o->holes) goto oom;
    for (i = 0, e = 0; e < l->ne; ++e)
        if (l->es[e] > 0.0f && !(l->etag[e] & SFB__TAG_BOUNDARY)) {
            o->crease_vertices[2 * i] = l->ev[2 * e];
            o->crease_vertices[2 * i + 1] = l->ev[2 * e + 1];
            o->crease_sharpness[i++] = l->es[e];
        }
    for (i = 0, v = 0; v < nv; ++v)
        if (l->vs[v] > 0.0f) { o->corner_vertices[i] = v; o->corner_sharpness[i++] = l->vs[v]; }
    for (i = 0, f = 0; f < l->nf; ++f)
        if (l->fhole[f]) o->holes[i++] = f;
    return SFB_SUCCESS;
oom:
    sfb_mesh_data_free(o);
    return sfb__oom(ctx, "refined mesh output");
}

SFB_API void sfb_mesh_data_desc(const sfb_mesh_data *m, sfb_mesh_desc *d) {
    if (!d) return;
    memset(d, 0, sizeof *d);
    if (!m) return;
    d->vertex_count = m->vertex_count; d->positions = m->positions;
    d->face_count = m->face_count; d->face_sizes = m->face_sizes; d->face_vertices = m->face_vertices;
    d->crease_count = m->crease_count; d->crease_vertices = m->crease_vertices; d->crease_sharpness = m->crease_sharpness;
    d->corner_count = m->corner_count; d->corner_vertices = m->corner_vertices; d->corner_sharpness = m->corner_sharpness;
    d->hole_count = m->hole_count; d->holes = m->holes;
    d->uv_count = m->uv_count; d->uvs = m->uvs; d->face_uvs = m->face_uvs;
    d->boundary = m->boundary; d->crease_method = m->crease_method;
    d->triangle_rule = m->triangle_rule; d->uv_interp = m->uv_interp;
}
