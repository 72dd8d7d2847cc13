/* backends/gl/draw.h -- the draw path on the host's context: sfb_surface_draw_gl (seed 000's
 * vertex and fragment programs, transform feedback capture) and sfb_gl_trim_texture.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. */
#ifndef SFB__GL_DRAW_H
#define SFB__GL_DRAW_H

/* ---- the draw path: seed 000's vertex and fragment programs (sfb_surface_draw_gl) ---- */
/* Uniforms of the draw program: manifold.comp.glsl's shared five (sfb__gl_mf_common_uniforms),
 * then these. */
static const char *const sfb__gl_draw_uniforms[9] = {"u_mvp", "u_normal_matrix", "u_rate", "u_first_face", "u_trim",
                                                     "u_trim_on", "u_tiles", "u_light", "u_color"};

/* The gl state of `ctx` when it runs the gl backend on the host's context; else the error
 * (SFB_UNSUPPORTED, naming `fn` and what the context runs). */
static sfb_result sfb__gl_host_of(sfb_context *ctx, const char *fn, sfb__gl **out) {
    const sfb__backend_vtable *be = ctx->backend;
    sfb__gl *g = be && be->kind == SFB_BACKEND_GL ? (sfb__gl *)ctx->backend_state : NULL;
    *out = NULL;
    if (!g || g->mode != SFB__GL_HOST)
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "%s needs the gl backend on the host's current context (gl_use_current_context); this context runs %s%s", fn,
                          be ? be->name : "no backend", g ? " on its own context" : "");
    *out = g;
    return SFB_SUCCESS;
}

/* GL state the draw binds besides sfb__gl_enter's: texture units, vertex array, transform
 * feedback object and generic buffer, rasterizer discard. */
typedef struct sfb__gl_drawstate {
    sfb__gl_texstate tex;
    sfb__GLint vao, tfo, tf_buffer;
    sfb__GLboolean discard;
} sfb__gl_drawstate;

static void sfb__gl_draw_save(sfb__gl *g, sfb__gl_drawstate *d) {
    sfb__gl_tex_save(g, &d->tex);
    g->gl.GetIntegerv(SFB__GL_VERTEX_ARRAY_BINDING, &d->vao);
    g->gl.GetIntegerv(SFB__GL_TRANSFORM_FEEDBACK_BINDING, &d->tfo);
    g->gl.GetIntegerv(SFB__GL_TRANSFORM_FEEDBACK_BUFFER_BINDING, &d->tf_buffer);
    d->discard = g->gl.IsEnabled(SFB__GL_RASTERIZER_DISCARD);
}

static void sfb__gl_draw_restore(sfb__gl *g, const sfb__gl_drawstate *d) {
    if (d->discard) g->gl.Enable(SFB__GL_RASTERIZER_DISCARD);
    else g->gl.Disable(SFB__GL_RASTERIZER_DISCARD);
    g->gl.BindTransformFeedback(SFB__GL_TRANSFORM_FEEDBACK, (sfb__GLuint)d->tfo);
    g->gl.BindBuffer(SFB__GL_TRANSFORM_FEEDBACK_BUFFER, (sfb__GLuint)d->tf_buffer);
    g->gl.BindVertexArray((sfb__GLuint)d->vao);
    sfb__gl_tex_restore(g, &d->tex);
}

/* The draw program, with its vertex array (no attributes: the vertex program reads
 * gl_VertexID and gl_InstanceID), index buffer and transform feedback object. */
static sfb_result sfb__gl_draw_program(sfb__gl *g) {
    static const char *const varyings[2] = {"v_cap_pos", "v_cap_nrm"};
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->draw_program) return SFB_SUCCESS;
    if ((r = sfb__gl_mf_sampler(g)) != SFB_SUCCESS) return r;
    if ((r = sfb__gl_draw_stages(g, "#define SFB_MF_VERTEX\n", SFB__GL_MANIFOLD_SOURCE, "manifold.comp.glsl (vertex stage)",
                                 SFB__GL_MANIFOLD_FRAG_SOURCE, "manifold_draw.frag.glsl", varyings, 2, "the manifold draw program", &prog)) !=
        SFB_SUCCESS)
        return r;
    for (i = 0; i < 5; ++i) g->draw_loc[i] = g->gl.GetUniformLocation(prog, sfb__gl_mf_common_uniforms[i]);
    for (i = 0; i < 9; ++i) g->draw_loc[5 + i] = g->gl.GetUniformLocation(prog, sfb__gl_draw_uniforms[i]);
    g->draw_program = prog;
    g->gl.GenVertexArrays(1, &g->draw_vao);
    g->gl.GenBuffers(1, &g->draw_ibo);
    g->gl.GenTransformFeedbacks(1, &g->draw_tfo);
    g->draw_rate = 0;
    return sfb__gl_check(g, "building the manifold draw program");
}

/* Binds the draw vertex array with the index buffer of a rate x rate cell grid: cell (i, j)
 * as the triangles (00, 10, 11) and (00, 11, 01), counter-clockwise in (u,v). */
static sfb_result sfb__gl_draw_grid(sfb__gl *g, int rate) {
    g->gl.BindVertexArray(g->draw_vao);
    g->gl.BindBuffer(SFB__GL_ELEMENT_ARRAY_BUFFER, g->draw_ibo);
    if (g->draw_rate != rate) {
        size_t cells = (size_t)rate * (size_t)rate;
        unsigned *idx = (unsigned *)sfb__alloc(g->ctx, cells * 6 * sizeof(unsigned));
        int i, j, n = rate + 1;
        if (!idx) return sfb__oom(g->ctx, "gl draw grid");
        for (j = 0; j < rate; ++j)
            for (i = 0; i < rate; ++i) {
                unsigned *o = idx + 6 * ((size_t)j * (size_t)rate + (size_t)i), v00 = (unsigned)(j * n + i);
                o[0] = v00; o[1] = v00 + 1; o[2] = v00 + 1 + (unsigned)n;
                o[3] = v00; o[4] = v00 + 1 + (unsigned)n; o[5] = v00 + (unsigned)n;
            }
        g->gl.BufferData(SFB__GL_ELEMENT_ARRAY_BUFFER, (sfb__GLsizeiptr)(cells * 6 * sizeof(unsigned)), idx, SFB__GL_STATIC_DRAW);
        sfb__free(g->ctx, idx);
        g->draw_rate = 0;
        if (g->gl.GetError() != SFB__GL_NO_ERROR) {
            while (g->gl.GetError() != SFB__GL_NO_ERROR) {}
            return sfb__error(g->ctx, SFB_OUT_OF_MEMORY, SFB_ELEMENT_NONE, -1, "gl: the index buffer of a %d x %d sample grid could not be made", rate, rate);
        }
        g->draw_rate = rate;
    }
    return SFB_SUCCESS;
}

static int sfb__gl_all_finite(const float *v, int n) {
    int i;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

static int sfb__gl_all_zero(const float *v, int n) {
    int i;
    for (i = 0; i < n; ++i)
        if (v[i] != 0.0f) return 0;
    return 1;
}

/* A draw call's parameters, checked, with the defaults filled in. */
typedef struct sfb__gl_draw {
    sfb_gl_draw_params p;
    const float *mvp, *nm, *color;
    float light[3];
    int rate, n, first, count; /* n = rate + 1 samples a side; faces first .. first + count - 1 */
    size_t cap_bytes;          /* what the capture writes (capture_buffer set) */
} sfb__gl_draw;

static sfb_result sfb__gl_draw_settle(sfb_context *ctx, const sfb__patch_table *pt, const sfb_gl_draw_params *params, sfb__gl_draw *d) {
    static const float ident4[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, ident3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const float grey[4] = {0.8f, 0.8f, 0.8f, 1.0f};
    const sfb_gl_draw_params *p = &d->p;
    int nptex;
    d->p = *params;
    d->light[0] = 0.0f; d->light[1] = 0.0f; d->light[2] = 1.0f;
    d->cap_bytes = 0;
    d->rate = p->rate == 0 ? 16 : p->rate;
    if (d->rate < 1 || d->rate > 1024)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: rate %d is outside 1..1024 (0: 16)", p->rate);
    nptex = pt->nptex;
    d->first = p->first_face;
    d->count = p->face_count;
    if (d->first < 0 || d->count < 0 || d->first > nptex || d->count > nptex - d->first)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_draw_gl: faces %d (+%d) are outside the surface's %d parametric faces", d->first, d->count, nptex);
    if (d->count == 0) d->count = nptex - d->first;
    if (!sfb__gl_all_finite(p->mvp, 16) || !sfb__gl_all_finite(p->normal_matrix, 9) || !sfb__gl_all_finite(p->light, 3) ||
        !sfb__gl_all_finite(p->color, 4))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: a matrix, light or colour value is not finite");
    if (p->trim_tiles_u < 0 || p->trim_tiles_v < 0 || (p->trim_tiles_u == 0) != (p->trim_tiles_v == 0))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_draw_gl: trimming atlas tiles %d x %d (0 x 0, or both >= 1)", p->trim_tiles_u, p->trim_tiles_v);
    d->mvp = sfb__gl_all_zero(p->mvp, 16) ? ident4 : p->mvp;
    d->nm = sfb__gl_all_zero(p->normal_matrix, 9) ? ident3 : p->normal_matrix;
    d->color = sfb__gl_all_zero(p->color, 4) ? grey : p->color;
    if (!sfb__gl_all_zero(p->light, 3)) {
        /* in double: a tiny or huge light direction neither under- nor overflows */
        double lx = p->light[0], ly = p->light[1], lz = p->light[2], l = sqrt(lx * lx + ly * ly + lz * lz);
        d->light[0] = (float)(lx / l); d->light[1] = (float)(ly / l); d->light[2] = (float)(lz / l);
    }
    d->n = d->rate + 1;
    if (p->capture_buffer) d->cap_bytes = (size_t)d->count * (size_t)d->n * (size_t)d->n * 6 * sizeof(float);
    return SFB_SUCCESS;
}

/* The host's objects the draw names: the trimming texture and the capture buffer. */
static sfb_result sfb__gl_draw_host_objects(sfb__gl *g, const sfb__gl_draw *d) {
    sfb_context *ctx = g->ctx;
    const sfb_gl_draw_params *p = &d->p;
    if (p->trim_texture) {
        sfb__GLint w = 0, h = 0;
        if (!g->gl.IsTexture(p->trim_texture))
            return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: trim_texture %u is not a texture of the current context",
                              p->trim_texture);
        g->gl.ActiveTexture(SFB__GL_TEXTURE0 + 2);
        g->gl.BindTexture(SFB__GL_TEXTURE_2D, p->trim_texture);
        g->gl.GetTexLevelParameteriv(SFB__GL_TEXTURE_2D, 0, SFB__GL_TEXTURE_WIDTH, &w);
        g->gl.GetTexLevelParameteriv(SFB__GL_TEXTURE_2D, 0, SFB__GL_TEXTURE_HEIGHT, &h);
        if (g->gl.GetError() != SFB__GL_NO_ERROR || w < 1 || h < 1) {
            while (g->gl.GetError() != SFB__GL_NO_ERROR) {}
            return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: trim_texture %u is not a 2D texture with a level-0 image",
                              p->trim_texture);
        }
        if (p->trim_tiles_u > 0 && (w % p->trim_tiles_u != 0 || h % p->trim_tiles_v != 0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: the %d x %d trimming texture does not split into %d x %d equal tiles",
                              (int)w, (int)h, p->trim_tiles_u, p->trim_tiles_v);
    }
    if (p->capture_buffer) {
        sfb__GLint size = 0;
        if (!g->gl.IsBuffer(p->capture_buffer))
            return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: capture_buffer %u is not a buffer object of the current context",
                              p->capture_buffer);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p->capture_buffer);
        g->gl.GetBufferParameteriv(SFB__GL_SHADER_STORAGE_BUFFER, SFB__GL_BUFFER_SIZE, &size);
        if (size < 0 || (size_t)size < d->cap_bytes)
            return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                              "sfb_surface_draw_gl: capture_buffer %u has %d bytes; %d faces at rate %d need %zu", p->capture_buffer, (int)size, d->count,
                              d->rate, d->cap_bytes);
    }
    return SFB_SUCCESS;
}

/* With the draw program in use: the table's textures, the trimming mask on unit 2, and the
 * draw's uniforms. */
static void sfb__gl_draw_uniforms_set(sfb__gl *g, const sfb__gl_ptable *tab, int weights, const sfb__gl_draw *d) {
    g->gl.UseProgram(g->draw_program);
    sfb__gl_mf_bind(g, tab, weights, g->draw_loc);
    g->gl.ActiveTexture(SFB__GL_TEXTURE0 + 2);
    if (d->p.trim_texture) g->gl.BindTexture(SFB__GL_TEXTURE_2D, d->p.trim_texture);
    g->gl.BindSampler(2, g->sampler);
    g->gl.UniformMatrix4fv(g->draw_loc[5], 1, 0, d->mvp);
    g->gl.UniformMatrix3fv(g->draw_loc[6], 1, 0, d->nm);
    g->gl.Uniform1i(g->draw_loc[7], d->rate);
    g->gl.Uniform1i(g->draw_loc[8], d->first);
    g->gl.Uniform1i(g->draw_loc[9], 2);
    g->gl.Uniform1i(g->draw_loc[10], d->p.trim_texture != 0);
    g->gl.Uniform2i(g->draw_loc[11], d->p.trim_tiles_u, d->p.trim_tiles_v);
    g->gl.Uniform3f(g->draw_loc[12], d->light[0], d->light[1], d->light[2]);
    g->gl.Uniform4f(g->draw_loc[13], d->color[0], d->color[1], d->color[2], d->color[3]);
}

/* The capture (when asked) and the draw, on the surface's manifold table (`tab`: its upload
 * to this backend, or NULL). `ds` is the host's state, saved. */
static sfb_result sfb__gl_draw_run(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable *tab, const sfb__gl_draw *d,
                                   const sfb__gl_drawstate *ds) {
    sfb__gl_ptable *temp = NULL;
    sfb_result r;
    if (!tab || tab->family != SFB__FAMILY_MANIFOLD) {
        if ((r = sfb__gl_mf_upload_current(g, pt, &temp)) != SFB_SUCCESS) return r;
        tab = temp;
    }
    if ((r = sfb__gl_draw_program(g)) != SFB_SUCCESS) goto done;
    if ((r = sfb__gl_draw_grid(g, d->rate)) != SFB_SUCCESS) goto done;
    sfb__gl_draw_uniforms_set(g, tab, pt->mf_weights, d);
    if ((r = sfb__gl_check(g, "setting up the manifold draw")) != SFB_SUCCESS) goto done;
    if (d->p.capture_buffer) {
        /* the samples once each, as points, into the capture buffer */
        g->gl.BindTransformFeedback(SFB__GL_TRANSFORM_FEEDBACK, g->draw_tfo);
        g->gl.BindBufferRange(SFB__GL_TRANSFORM_FEEDBACK_BUFFER, 0, d->p.capture_buffer, 0, (sfb__GLsizeiptr)d->cap_bytes);
        g->gl.Enable(SFB__GL_RASTERIZER_DISCARD);
        g->gl.BeginTransformFeedback(SFB__GL_POINTS);
        g->gl.DrawArraysInstanced(SFB__GL_POINTS, 0, d->n * d->n, d->count);
        g->gl.EndTransformFeedback();
        if (!ds->discard) g->gl.Disable(SFB__GL_RASTERIZER_DISCARD);
        g->gl.BindTransformFeedback(SFB__GL_TRANSFORM_FEEDBACK, (sfb__GLuint)ds->tfo);
        if ((r = sfb__gl_check(g, "capturing the manifold samples")) != SFB_SUCCESS) goto done;
    }
    g->gl.DrawElementsInstanced(SFB__GL_TRIANGLES, 6 * d->rate * d->rate, SFB__GL_UNSIGNED_INT, NULL, d->count);
    r = sfb__gl_check(g, "drawing the manifold surface");
    /* the host may read the capture (map, copy, draw from it) next */
    if (r == SFB_SUCCESS && d->p.capture_buffer) g->gl.MemoryBarrier(SFB__GL_ALL_BARRIER_BITS);
done:
    if (temp) sfb__gl_mf_free(g, temp);
    return r;
}

SFB_API sfb_result sfb_surface_draw_gl(const sfb_surface *surface, const sfb_gl_draw_params *params) {
    sfb_context *ctx;
    sfb__gl *g = NULL;
    const sfb__patch_table *pt;
    sfb__gl_ptable *tab;
    sfb__gl_saved saved;
    sfb__gl_drawstate ds;
    sfb__gl_draw d;
    sfb_result r;
    if (!surface) return SFB_INVALID_ARGS;
    ctx = surface->ctx;
    if (!params) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: params is NULL");
    if ((r = sfb__gl_host_of(ctx, "sfb_surface_draw_gl", &g)) != SFB_SUCCESS) return r;
    pt = &surface->patches;
    if (!surface->has_patches || !(sfb__patch_families(pt) & (1u << SFB__FAMILY_MANIFOLD)))
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_draw_gl needs a MANIFOLD4 patch table (SFB_SCHEME_MANIFOLD_BLEND with SFB_REFINE_PATCHES); this surface has %s",
                          !surface->has_patches ? "no patch table" : sfb__patch_families(pt) & (1u << SFB__FAMILY_TRI) ? "a table of triangle patches"
                          : sfb__patch_families(pt) ? "a table of quad patches" : "an empty patch table");
    if ((r = sfb__gl_draw_settle(ctx, pt, params, &d)) != SFB_SUCCESS) return r;
    if (d.count == 0) return SFB_SUCCESS;
    if ((r = sfb__gl_enter(g, &saved)) != SFB_SUCCESS) return r;
    sfb__gl_draw_save(g, &ds);
    if ((r = sfb__gl_draw_host_objects(g, &d)) == SFB_SUCCESS) {
        tab = surface->uploaded_by && surface->uploaded_by->kind == SFB_BACKEND_GL ? (sfb__gl_ptable *)surface->backend_patches : NULL;
        r = sfb__gl_draw_run(g, pt, tab, &d, &ds);
    }
    sfb__gl_draw_restore(g, &ds);
    sfb__gl_leave(g, &saved);
    return r;
}

SFB_API sfb_result sfb_gl_trim_texture(sfb_context *ctx, const struct sfb_trim_mask *mask, unsigned int *texture) {
    sfb__gl *g = NULL;
    sfb__gl_saved saved;
    sfb__gl_texstate ts;
    sfb__GLuint tex = 0;
    sfb_result r;
    if (texture) *texture = 0;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!mask || !texture) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_gl_trim_texture: %s is NULL", mask ? "texture" : "mask");
    if ((r = sfb__gl_host_of(ctx, "sfb_gl_trim_texture", &g)) != SFB_SUCCESS) return r;
    /* as sfb_surface_tessellate checks a mask */
    if (!mask->texels) return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: texels is NULL");
    if (mask->width < 1 || mask->width > 16384 || mask->height < 1 || mask->height > 16384)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: %d x %d texels, each side must be 1..16384", mask->width,
                          mask->height);
    if (mask->tiles_u < 0 || mask->tiles_v < 0 || (mask->tiles_u == 0) != (mask->tiles_v == 0))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: atlas tiles %d x %d (0 x 0, or both >= 1)", mask->tiles_u,
                          mask->tiles_v);
    if (mask->tiles_u > 0 && (mask->width % mask->tiles_u != 0 || mask->height % mask->tiles_v != 0))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: %d x %d texels do not split into %d x %d equal tiles",
                          mask->width, mask->height, mask->tiles_u, mask->tiles_v);
    if (mask->width > g->max_texture || mask->height > g->max_texture)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "trimming mask: %d x %d texels exceed GL_MAX_TEXTURE_SIZE (%d)", mask->width,
                          mask->height, (int)g->max_texture);
    if ((r = sfb__gl_enter(g, &saved)) != SFB_SUCCESS) return r;
    sfb__gl_tex_save(g, &ts);
    sfb__gl_unpack_plain(g, 1);
    g->gl.ActiveTexture(SFB__GL_TEXTURE0 + 2);
    tex = sfb__gl_mf_texture(g, SFB__GL_R8, mask->width, mask->height, SFB__GL_RED, SFB__GL_UNSIGNED_BYTE, mask->texels);
    r = sfb__gl_check(g, "uploading a trimming mask");
    if (r != SFB_SUCCESS && tex) g->gl.DeleteTextures(1, &tex);
    else *texture = tex;
    sfb__gl_tex_restore(g, &ts);
    sfb__gl_leave(g, &saved);
    return r;
}

/* ---- seed 003's analysis on the host's framebuffer (sfb_analysis_draw_gl) ---- */
static sfb_result sfb__gl_an_program(sfb__gl *g) {
    static const char *const names[3] = {"u_picture", "u_viewport", "u_size"};
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->an_program) return SFB_SUCCESS;
    if ((r = sfb__gl_mf_sampler(g)) != SFB_SUCCESS) return r;
    if ((r = sfb__gl_draw_stages(g, "", sfb__glsl_analysis_draw_vert_glsl, "analysis_draw.vert.glsl", sfb__glsl_analysis_draw_frag_glsl,
                                 "analysis_draw.frag.glsl", NULL, 0, "the analysis draw program", &prog)) != SFB_SUCCESS)
        return r;
    for (i = 0; i < 3; ++i) g->an_loc[i] = g->gl.GetUniformLocation(prog, names[i]);
    g->an_program = prog;
    g->gl.GenVertexArrays(1, &g->an_vao);
    return sfb__gl_check(g, "building the analysis draw program");
}

/* The picture (with alpha 0 off the surface) as a texture on unit 0, drawn over the viewport;
 * the host's state saved in ds and by sfb__gl_enter. */
static sfb_result sfb__gl_an_draw(sfb__gl *g, const sfb_analysis *a, const unsigned char *rgba) {
    sfb__GLint vp[4] = {0, 0, 0, 0};
    sfb__GLboolean depth, cull, blend;
    sfb__GLuint tex;
    sfb_result r;
    if ((r = sfb__gl_an_program(g)) != SFB_SUCCESS) return r;
    g->gl.GetIntegerv(SFB__GL_VIEWPORT, vp);
    depth = g->gl.IsEnabled(SFB__GL_DEPTH_TEST);
    cull = g->gl.IsEnabled(SFB__GL_CULL_FACE);
    blend = g->gl.IsEnabled(SFB__GL_BLEND);
    sfb__gl_unpack_plain(g, 4);
    g->gl.ActiveTexture(SFB__GL_TEXTURE0);
    tex = sfb__gl_mf_texture(g, SFB__GL_RGBA8, a->width, a->height, SFB__GL_RGBA, SFB__GL_UNSIGNED_BYTE, rgba);
    g->gl.BindSampler(0, g->sampler);
    g->gl.UseProgram(g->an_program);
    g->gl.Uniform1i(g->an_loc[0], 0);
    g->gl.Uniform4f(g->an_loc[1], (float)vp[0], (float)vp[1], (float)(vp[2] > 0 ? vp[2] : 1), (float)(vp[3] > 0 ? vp[3] : 1));
    g->gl.Uniform2i(g->an_loc[2], a->width, a->height);
    g->gl.BindVertexArray(g->an_vao);
    g->gl.Disable(SFB__GL_DEPTH_TEST);
    g->gl.Disable(SFB__GL_CULL_FACE);
    g->gl.Disable(SFB__GL_BLEND);
    g->gl.DrawArraysInstanced(SFB__GL_TRIANGLES, 0, 3, 1);
    r = sfb__gl_check(g, "drawing the analysis");
    if (depth) g->gl.Enable(SFB__GL_DEPTH_TEST);
    if (cull) g->gl.Enable(SFB__GL_CULL_FACE);
    if (blend) g->gl.Enable(SFB__GL_BLEND);
    if (tex) g->gl.DeleteTextures(1, &tex);
    return r;
}

SFB_API sfb_result sfb_analysis_draw_gl(sfb_context *ctx, const sfb_analysis *a) {
    sfb__gl *g = NULL;
    sfb__gl_saved saved;
    sfb__gl_drawstate ds;
    unsigned char *rgba;
    size_t n, k;
    sfb_result r;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!a || !a->rgba || !a->classes || a->width < 1 || a->height < 1)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_analysis_draw_gl: %s", a ? "the analysis has no picture" : "analysis is NULL");
    if ((r = sfb__gl_host_of(ctx, "sfb_analysis_draw_gl", &g)) != SFB_SUCCESS) return r;
    if (a->width > g->max_texture || a->height > g->max_texture)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "sfb_analysis_draw_gl: a %d x %d picture exceeds GL_MAX_TEXTURE_SIZE (%d)", a->width,
                          a->height, (int)g->max_texture);
    n = (size_t)a->width * (size_t)a->height;
    rgba = (unsigned char *)sfb__alloc(ctx, n * 4);
    if (!rgba) return sfb__oom(ctx, "sfb_analysis_draw_gl");
    for (k = 0; k < n; ++k) {
        memcpy(rgba + 4 * k, a->rgba + 4 * k, 3);
        rgba[4 * k + 3] = a->classes[k] ? 255 : 0;
    }
    if ((r = sfb__gl_enter(g, &saved)) == SFB_SUCCESS) {
        sfb__gl_draw_save(g, &ds);
        r = sfb__gl_an_draw(g, a, rgba);
        sfb__gl_draw_restore(g, &ds);
        sfb__gl_leave(g, &saved);
    }
    sfb__free(ctx, rgba);
    return r;
}

#endif /* SFB__GL_DRAW_H */
