/* backends/gl/manifold.h -- MANIFOLD4 tables (seed 000): two textures, the seed's Fig. 8
 * coefficients and the face and patch records, read by manifold.comp.glsl's compute stage
 * (sfb_surface_eval; the vertex stage is the draw path, draw.h).
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. */
#ifndef SFB__GL_MANIFOLD_H
#define SFB__GL_MANIFOLD_H

/* The kernel sources (both stages, and the draw path's fragment stage): build-time overrides, as
 * in stencils.h. */
#ifndef SFB__GL_MANIFOLD_SOURCE
#define SFB__GL_MANIFOLD_SOURCE sfb__glsl_manifold_comp_glsl
#endif
#ifndef SFB__GL_MANIFOLD_FRAG_SOURCE
#define SFB__GL_MANIFOLD_FRAG_SOURCE sfb__glsl_manifold_draw_frag_glsl
#endif

/* ---- MANIFOLD4 tables (seed 000): textures, and the compute kernel of manifold.comp.glsl ---- */
/* Texture units the manifold kernels use: 0 coefficients, 1 patch records, 2 trimming mask. */
enum { SFB__GL_MF_UNITS = 3 };

/* GL state a manifold call binds besides the program and storage buffers (sfb__gl_enter):
 * texture units with their samplers, the active unit, and the pixel unpack state uploads use. */
typedef struct sfb__gl_texstate {
    sfb__GLint active, tex[SFB__GL_MF_UNITS], sampler[SFB__GL_MF_UNITS];
    sfb__GLint unpack_buffer, align, row_length, skip_rows, skip_pixels;
} sfb__gl_texstate;

static void sfb__gl_tex_save(sfb__gl *g, sfb__gl_texstate *t) {
    int i;
    g->gl.GetIntegerv(SFB__GL_ACTIVE_TEXTURE, &t->active);
    for (i = 0; i < SFB__GL_MF_UNITS; ++i) {
        g->gl.ActiveTexture(SFB__GL_TEXTURE0 + (sfb__GLenum)i);
        g->gl.GetIntegerv(SFB__GL_TEXTURE_BINDING_2D, &t->tex[i]);
        g->gl.GetIntegerv(SFB__GL_SAMPLER_BINDING, &t->sampler[i]);
    }
    g->gl.GetIntegerv(SFB__GL_PIXEL_UNPACK_BUFFER_BINDING, &t->unpack_buffer);
    g->gl.GetIntegerv(SFB__GL_UNPACK_ALIGNMENT, &t->align);
    g->gl.GetIntegerv(SFB__GL_UNPACK_ROW_LENGTH, &t->row_length);
    g->gl.GetIntegerv(SFB__GL_UNPACK_SKIP_ROWS, &t->skip_rows);
    g->gl.GetIntegerv(SFB__GL_UNPACK_SKIP_PIXELS, &t->skip_pixels);
    g->gl.ActiveTexture((sfb__GLenum)t->active);
}

static void sfb__gl_tex_restore(sfb__gl *g, const sfb__gl_texstate *t) {
    int i;
    for (i = 0; i < SFB__GL_MF_UNITS; ++i) {
        g->gl.ActiveTexture(SFB__GL_TEXTURE0 + (sfb__GLenum)i);
        g->gl.BindTexture(SFB__GL_TEXTURE_2D, (sfb__GLuint)t->tex[i]);
        g->gl.BindSampler((sfb__GLuint)i, (sfb__GLuint)t->sampler[i]);
    }
    g->gl.ActiveTexture((sfb__GLenum)t->active);
    g->gl.BindBuffer(SFB__GL_PIXEL_UNPACK_BUFFER, (sfb__GLuint)t->unpack_buffer);
    g->gl.PixelStorei(SFB__GL_UNPACK_ALIGNMENT, t->align);
    g->gl.PixelStorei(SFB__GL_UNPACK_ROW_LENGTH, t->row_length);
    g->gl.PixelStorei(SFB__GL_UNPACK_SKIP_ROWS, t->skip_rows);
    g->gl.PixelStorei(SFB__GL_UNPACK_SKIP_PIXELS, t->skip_pixels);
}

/* Tightly packed rows from client memory, whatever the host set. */
static void sfb__gl_unpack_plain(sfb__gl *g, int align) {
    g->gl.BindBuffer(SFB__GL_PIXEL_UNPACK_BUFFER, 0);
    g->gl.PixelStorei(SFB__GL_UNPACK_ALIGNMENT, align);
    g->gl.PixelStorei(SFB__GL_UNPACK_ROW_LENGTH, 0);
    g->gl.PixelStorei(SFB__GL_UNPACK_SKIP_ROWS, 0);
    g->gl.PixelStorei(SFB__GL_UNPACK_SKIP_PIXELS, 0);
}

/* Our sampler object (nearest, clamped): bound beside our textures, it makes them complete
 * whatever their own filter state (a host's mask texture may ask for mipmaps it lacks) and
 * keeps a host's sampler object off our units. */
static sfb_result sfb__gl_mf_sampler(sfb__gl *g) {
    if (g->sampler) return SFB_SUCCESS;
    g->gl.GenSamplers(1, &g->sampler);
    g->gl.SamplerParameteri(g->sampler, SFB__GL_TEXTURE_MIN_FILTER, SFB__GL_NEAREST);
    g->gl.SamplerParameteri(g->sampler, SFB__GL_TEXTURE_MAG_FILTER, SFB__GL_NEAREST);
    g->gl.SamplerParameteri(g->sampler, SFB__GL_TEXTURE_WRAP_S, SFB__GL_CLAMP_TO_EDGE);
    g->gl.SamplerParameteri(g->sampler, SFB__GL_TEXTURE_WRAP_T, SFB__GL_CLAMP_TO_EDGE);
    return sfb__gl_check(g, "making the manifold sampler");
}

/* A 2D texture of `width` x `height` texels (one level, nearest) from tightly packed `data`,
 * made on the active unit (whose binding the caller restores). */
static sfb__GLuint sfb__gl_mf_texture(sfb__gl *g, sfb__GLint internal, int width, int height, sfb__GLenum format, sfb__GLenum type,
                                      const void *data) {
    sfb__GLuint tex = 0;
    g->gl.GenTextures(1, &tex);
    g->gl.BindTexture(SFB__GL_TEXTURE_2D, tex);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_MIN_FILTER, SFB__GL_NEAREST);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_MAG_FILTER, SFB__GL_NEAREST);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_WRAP_S, SFB__GL_CLAMP_TO_EDGE);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_WRAP_T, SFB__GL_CLAMP_TO_EDGE);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_BASE_LEVEL, 0);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_MAX_LEVEL, 0);
    g->gl.TexImage2D(SFB__GL_TEXTURE_2D, 0, internal, width, height, 0, format, type, data);
    return tex;
}

static void sfb__gl_mf_free(sfb__gl *g, sfb__gl_ptable *t) {
    int i;
    if (!t) return;
    for (i = 0; i < 2; ++i)
        if (t->mf_tex[i]) g->gl.DeleteTextures(1, &t->mf_tex[i]);
    sfb__free(g->ctx, t->pieces);
    sfb__free(g->ctx, t);
}

/* Uploads a MANIFOLD4 table with the context current: the seed's Fig. 8 coefficient texture
 * with one 9-row column per patch corner (RGBA32F, 37 texels per patch: its origin, then the
 * corners' rows, position rows relative to the origin, formed in double) and the RGBA32I
 * texture of parametric face records and corner codes (layout in manifold.comp.glsl). Texel n
 * sits at (n % W, n / W) with W = min(4096, GL_MAX_TEXTURE_SIZE). Per-patch origins, rather
 * than the shared per-vertex texture of the seed, keep float's error at the size of a patch:
 * the tangents near a point corner are differences of nearly equal local geometries, which
 * absolute positions would drown. A curve's rows 1 and 2 are positions too. */
static sfb_result sfb__gl_mf_upload_current(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable **out) {
    const char *who = g->mode == SFB__GL_OSMESA ? "osmesa" : "gl";
    int nv = pt->npoints / 9, np = pt->npatch, nf = pt->nptex, W = g->max_texture < 4096 ? g->max_texture : 4096, p, f, j, c, r;
    size_t ncoef = 37 * (size_t)np, nint = (size_t)nf + (size_t)np, hc = (ncoef + (size_t)W - 1) / (size_t)W,
           hi = (nint + (size_t)W - 1) / (size_t)W;
    float *coef = NULL;
    unsigned *recs = NULL;
    sfb__gl_ptable *tab = NULL;
    sfb__gl_texstate ts;
    sfb_result res = SFB_SUCCESS;
    *out = NULL;
    if (hc < 1) hc = 1;
    if (hi < 1) hi = 1;
    if (pt->npoints % 9 != 0 || !pt->pcorner || !pt->ptex_root || (pt->max_depth > 1))
        return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: malformed manifold table (%d points, depth %d)", who,
                          pt->npoints, pt->max_depth);
    if (hc > (size_t)g->max_texture || hi > (size_t)g->max_texture)
        return sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "%s: a manifold table of %d patches needs textures of %zu and %zu rows of %d texels (GL_MAX_TEXTURE_SIZE %d)",
                          who, np, hc, hi, W, (int)g->max_texture);
    coef = (float *)sfb__calloc(g->ctx, hc * (size_t)W * 4, sizeof(float));
    recs = (unsigned *)sfb__calloc(g->ctx, hi * (size_t)W * 4, sizeof(unsigned));
    tab = (sfb__gl_ptable *)sfb__calloc(g->ctx, 1, sizeof *tab);
    if (!coef || !recs || !tab) { res = sfb__oom(g->ctx, "gl manifold table"); goto done; }
    for (p = 0; p < np; ++p) {
        int first = pt->pfirst[p], nrow[4];
        double lo[3], hi3[3], origin[3];
        float *blk = coef + 4 * 37 * (size_t)p;
        if (pt->ptype[p] != SFB__PATCH_MANIFOLD4 || pt->pfirst[p + 1] - first != 4) {
            res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: manifold patch %d (type %d, %d points) is malformed", who, p,
                             pt->ptype[p], pt->pfirst[p + 1] - first);
            goto done;
        }
        for (c = 0; c < 3; ++c) { lo[c] = HUGE_VAL; hi3[c] = -HUGE_VAL; }
        for (j = 0; j < 4; ++j) {
            unsigned code = pt->pcorner[4 * (size_t)p + (size_t)j];
            int kind = SFB__MF_KIND(code), v = pt->cv[first + j];
            if (v < 0 || v >= nv || kind > SFB__MF_CURVE || (kind == SFB__MF_PATCH && SFB__MF_K(code) < 1)) {
                res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: manifold patch %d corner %d (vertex %d of %d, code 0x%x) is malformed",
                                 who, p, j, v, nv, code);
                goto done;
            }
            nrow[j] = kind == SFB__MF_CURVE ? 3 : 1; /* rows holding positions */
            for (r = 0; r < nrow[j]; ++r)
                for (c = 0; c < 3; ++c) {
                    double x = pt->point_data[27 * (size_t)v + 3 * (size_t)r + (size_t)c];
                    if (x < lo[c]) lo[c] = x;
                    if (x > hi3[c]) hi3[c] = x;
                }
        }
        /* the origin: the centre of the patch's positions, as a float (exactly what is added back) */
        for (c = 0; c < 3; ++c) {
            origin[c] = isfinite(lo[c]) && isfinite(hi3[c]) ? (double)(float)(0.5 * (lo[c] + hi3[c])) : 0.0;
            blk[c] = (float)origin[c];
        }
        for (j = 0; j < 4; ++j) {
            const float *src = pt->point_data + 27 * (size_t)pt->cv[first + j];
            for (r = 0; r < 9; ++r)
                for (c = 0; c < 3; ++c)
                    blk[4 * (1 + 9 * j + r) + c] = (float)(r < nrow[j] ? (double)src[3 * r + c] - origin[c] : (double)src[3 * r + c]);
        }
        for (j = 0; j < 4; ++j) recs[4 * ((size_t)nf + (size_t)p) + (size_t)j] = pt->pcorner[4 * (size_t)p + (size_t)j];
    }
    /* face records: a hole, one patch, or the patches of the four quadrants */
    for (f = 0; f < nf; ++f) {
        int root = pt->ptex_root[f], q;
        unsigned *o = recs + 4 * (size_t)f;
        if (root == -1) {
            for (q = 0; q < 4; ++q) o[q] = (unsigned)-1;
        } else if (root <= -2) {
            o[0] = (unsigned)(-root - 2);
            o[1] = o[2] = o[3] = (unsigned)-2;
        } else {
            for (q = 0; q < 4; ++q) {
                int ch = root < pt->nnodes ? pt->nodes[4 * root + q] : 0;
                if (ch >= 0) {
                    res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: manifold face %d is refined deeper than one level", who, f);
                    goto done;
                }
                o[q] = ch == -1 ? (unsigned)-1 : (unsigned)(-ch - 2);
            }
        }
    }
    tab->family = SFB__FAMILY_MANIFOLD;
    tab->mf_width = W;
    tab->mf_patch_base = nf;
    sfb__gl_tex_save(g, &ts);
    sfb__gl_unpack_plain(g, 4);
    g->gl.ActiveTexture(SFB__GL_TEXTURE0);
    tab->mf_tex[0] = sfb__gl_mf_texture(g, SFB__GL_RGBA32F, W, (int)hc, SFB__GL_RGBA, SFB__GL_FLOAT, coef);
    tab->mf_tex[1] = sfb__gl_mf_texture(g, SFB__GL_RGBA32I, W, (int)hi, SFB__GL_RGBA_INTEGER, SFB__GL_INT, recs);
    res = sfb__gl_check(g, "uploading a manifold table");
    sfb__gl_tex_restore(g, &ts);
done:
    sfb__free(g->ctx, coef); sfb__free(g->ctx, recs);
    if (res != SFB_SUCCESS) {
        if (tab) sfb__gl_mf_free(g, tab);
        return res;
    }
    *out = tab;
    return SFB_SUCCESS;
}

/* Uniforms of manifold.comp.glsl shared by both stages, at these indices of a location table. */
static const char *const sfb__gl_mf_common_uniforms[5] = {"u_coef", "u_index", "u_width", "u_patch_base", "u_weights"};

/* With `prog` in use: the table's textures on units 0 and 1 with our sampler, and the shared
 * uniforms (loc: their locations). */
static void sfb__gl_mf_bind(sfb__gl *g, const sfb__gl_ptable *tab, int weights, const sfb__GLint *loc) {
    int i;
    for (i = 0; i < 2; ++i) {
        g->gl.ActiveTexture(SFB__GL_TEXTURE0 + (sfb__GLenum)i);
        g->gl.BindTexture(SFB__GL_TEXTURE_2D, tab->mf_tex[i]);
        g->gl.BindSampler((sfb__GLuint)i, g->sampler);
    }
    g->gl.Uniform1i(loc[0], 0);
    g->gl.Uniform1i(loc[1], 1);
    g->gl.Uniform1i(loc[2], tab->mf_width);
    g->gl.Uniform1i(loc[3], tab->mf_patch_base);
    g->gl.Uniform1i(loc[4], weights);
}

static sfb_result sfb__gl_mf_program(sfb__gl *g, sfb__GLuint *out) {
    static const char *const own[4] = {"u_first", "u_last", "u_stride", "u_slot"};
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->mf_program) { *out = g->mf_program; return SFB_SUCCESS; }
    if ((r = sfb__gl_mf_sampler(g)) != SFB_SUCCESS) return r;
    if ((r = sfb__gl_compile(g, "", SFB__GL_MANIFOLD_SOURCE, "manifold.comp.glsl", &prog)) != SFB_SUCCESS) return r;
    for (i = 0; i < 5; ++i) g->mf_loc[i] = g->gl.GetUniformLocation(prog, sfb__gl_mf_common_uniforms[i]);
    for (i = 0; i < 4; ++i) g->mf_loc[5 + i] = g->gl.GetUniformLocation(prog, own[i]);
    g->mf_program = prog;
    *out = prog;
    return sfb__gl_check(g, "building the manifold kernel");
}

/* The second derivatives of locations [first, last), on the CPU as ref forms them. */
static void sfb__gl_mf_second(const sfb__patch_table *pt, const sfb_location *locs, int first, int last, const sfb_eval_output *out) {
    int q;
    for (q = first; q < last; ++q) {
        double u, v, sc, res2[6][3], nrm[3];
        int patch = sfb__patch_locate(pt, locs[q].face, locs[q].u, locs[q].v, &u, &v, &sc), c;
        sfb__mf_eval_patch(pt, pt->point_data, patch, u, v, 1, res2, nrm);
        for (c = 0; c < 3; ++c) {
            size_t at = 3 * (size_t)q + (size_t)c;
            if (out->duu) out->duu[at] = (float)(res2[3][c] * sc * sc);
            if (out->duv) out->duv[at] = (float)(res2[4][c] * sc * sc);
            if (out->dvv) out->dvv[at] = (float)(res2[5][c] * sc * sc);
        }
    }
}

/* Runs the manifold kernel (in use, bound to the table) over `count` located queries in
 * batches that fit one storage block, and scatters the results into dst[] from location
 * `first` on. */
static sfb_result sfb__gl_mf_run(sfb__gl *g, const sfb__gl_query *queries, int count, int first, float *const *dst, const sfb__GLint *slot,
                                 int stride) {
    size_t batch = sfb__gl_query_batch(g, stride);
    int q;
    sfb_result res;
    for (q = 0; q < count;) {
        int n = (size_t)(count - q) > batch ? (int)batch : count - q;
        const float *mapped;
        size_t qbytes = (size_t)n * sizeof(sfb__gl_query), rbytes = (size_t)n * (size_t)stride * sizeof(float);
        if ((res = sfb__gl_query_buffers(g, queries + q, qbytes, rbytes)) != SFB_SUCCESS) return res;
        sfb__gl_dispatch_range(g, g->mf_loc[5], g->mf_loc[6], 0, n);
        if ((res = sfb__gl_check(g, "the manifold kernel")) != SFB_SUCCESS) return res;
        if ((res = sfb__gl_map_results(g, rbytes, &mapped)) != SFB_SUCCESS) return res;
        sfb__gl_scatter(dst, slot, 4, mapped, stride, n, NULL, first + q);
        if ((res = sfb__gl_unmap_results(g)) != SFB_SUCCESS) return res;
        q += n;
    }
    return SFB_SUCCESS;
}

/* sfb_surface_eval on a MANIFOLD4 table: located on the CPU (sfb__patch_locate), evaluated by
 * manifold.comp.glsl in batches that fit one storage block (position, du, dv, normal). Second
 * derivatives are formed on the CPU, as ref forms them (sfb__mf_eval_patch: central differences
 * of the analytic first derivatives, step 2^-17, in double): in float a difference quotient
 * of that step would keep no digits, and a wider one would no longer be ref's function. */
static sfb_result sfb__gl_mf_eval(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable *tab, const sfb_location *locs, int first,
                                  int last, const sfb_eval_output *out) {
    float *dst[4];
    sfb__GLint slot[4];
    sfb__gl_query *queries = NULL;
    sfb__gl_ptable *temp = NULL;
    int count = last - first, nout = 0, o, q, stride;
    sfb__gl_saved s;
    sfb__gl_texstate ts;
    sfb__GLuint prog;
    sfb_result res;
    dst[0] = out->position; dst[1] = out->du; dst[2] = out->dv; dst[3] = out->normal;
    for (o = 0; o < 4; ++o) slot[o] = dst[o] ? nout++ : -1;
    if (count <= 0) return SFB_SUCCESS;
    for (q = 0; q < count; ++q) {
        double u, v, sc;
        const sfb_location *l = &locs[first + q];
        if (sfb__patch_locate(pt, l->face, l->u, l->v, &u, &v, &sc) < 0)
            return sfb__error(g->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, first + q, "location %d: parametric face %d is a hole", first + q, l->face);
    }
    if (out->duu || out->duv || out->dvv) sfb__gl_mf_second(pt, locs, first, last, out);
    if (nout == 0) return SFB_SUCCESS;
    stride = 3 * nout;
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    sfb__gl_tex_save(g, &ts);
    if (!tab || tab->family != SFB__FAMILY_MANIFOLD) {
        /* the surface was uploaded to another backend: a temporary copy for this call */
        if ((res = sfb__gl_mf_upload_current(g, pt, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    if ((res = sfb__gl_mf_program(g, &prog)) != SFB_SUCCESS) goto done;
    queries = (sfb__gl_query *)sfb__alloc(g->ctx, (size_t)count * sizeof *queries);
    if (!queries) { res = sfb__oom(g->ctx, "gl manifold evaluation"); goto done; }
    for (q = 0; q < count; ++q) {
        const sfb_location *l = &locs[first + q];
        double u, v, sc;
        queries[q].patch = sfb__patch_locate(pt, l->face, l->u, l->v, &u, &v, &sc);
        queries[q].s = (float)u; /* exact: u, 2u or 2u - 1 of a float */
        queries[q].t = (float)v;
        queries[q].scale = (float)sc;
    }
    g->gl.UseProgram(prog);
    sfb__gl_mf_bind(g, tab, pt->mf_weights, g->mf_loc);
    g->gl.Uniform1i(g->mf_loc[7], stride);
    g->gl.Uniform1iv(g->mf_loc[8], 4, slot);
    res = sfb__gl_mf_run(g, queries, count, first, dst, slot, stride);
done:
    sfb__free(g->ctx, queries);
    if (temp) sfb__gl_mf_free(g, temp);
    sfb__gl_tex_restore(g, &ts);
    sfb__gl_leave(g, &s);
    return res;
}

/* The patch-table slots, for MANIFOLD4 tables (vtable.h hands them their tables). */
static void sfb__gl_manifold_bind(sfb__backend_vtable *vt) {
    vt->upload_patches = sfb__gl_upload_patches;
    vt->release_patches = sfb__gl_release_patches;
    vt->eval_patches = sfb__gl_eval_patches;
}

#endif /* SFB__GL_MANIFOLD_H */
