/* backends/gl/raster.h -- seed 003's proxy raster (the `raster` slot) in raster.vert.glsl and
 * raster.frag.glsl: the analysis proxy's triangles drawn by GL's rasteriser into an offscreen
 * framebuffer, read back into the job's per-pixel buffers.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. The framebuffer: an RGBA32UI texture of (u, v, view depth, face + 1) bits per
 * pixel (integer textures are colour-renderable in GLES 3 without extensions, float ones are
 * not), two more for the polygon-based method's interpolated position and normal, and a 32-bit
 * float depth texture holding the view depth scaled into [0, 1]. The triangles are an RGBA32F
 * texture of 5 texels each (11 with the polygon data), drawn with no vertex attributes
 * (gl_VertexID), in batches of up to 2^17. GL decides only which pixels a triangle covers: the
 * fragment stage computes the barycentric coordinates at the pixel centre from the triangle's
 * own corners, and every value from them, as ref does. (Leaving that to GL's interpolation
 * failed on NVIDIA's driver: with w = view depth the perspective-correct varyings came back
 * without their division by the interpolated 1 / w, a depth of 1 at every pixel, and the
 * corners snapped to its 8-bit sub-pixel grid moved the values by 1e-5 relative besides.)
 * Where GL differs from ref (sfb__ref_raster): the arithmetic in float, the tie rule for pixel
 * centres on an edge and GL's snapping of the edges, and the depth test in float. A picture
 * larger than GL_MAX_TEXTURE_SIZE or GL_MAX_VIEWPORT_DIMS, a parametric face number of 2^24 or
 * more (the texture holds it as a float), or an incomplete framebuffer go to ref's kernel
 * (with a log line). On the host's context (gl_use_current_context) every state the raster
 * changes is put back: framebuffer bindings, viewport, depth, scissor, stencil, cull and blend
 * switches, depth function and masks, the pixel-pack buffer and pack storage,
 * besides sfb__gl_enter's and the draw path's state (sfb__gl_draw_save: texture units, samplers,
 * unpack storage). Desktop GL's glPolygonMode is not touched: a host that leaves it at GL_LINE
 * gets a ref-like result only where lines cover. */
#ifndef SFB__GL_RASTER_H
#define SFB__GL_RASTER_H

typedef struct sfb__gl_rstate {
    sfb__GLint draw_fbo, read_fbo, viewport[4], depth_func, pack_buffer, pack[4];
    sfb__GLboolean depth_test, scissor, stencil, cull, blend, depth_mask, color_mask[4];
} sfb__gl_rstate;

static void sfb__gl_raster_save(sfb__gl *g, sfb__gl_rstate *r) {
    g->gl.GetIntegerv(SFB__GL_DRAW_FRAMEBUFFER_BINDING, &r->draw_fbo);
    g->gl.GetIntegerv(SFB__GL_READ_FRAMEBUFFER_BINDING, &r->read_fbo);
    g->gl.GetIntegerv(SFB__GL_VIEWPORT, r->viewport);
    g->gl.GetIntegerv(SFB__GL_DEPTH_FUNC, &r->depth_func);
    g->gl.GetIntegerv(SFB__GL_PIXEL_PACK_BUFFER_BINDING, &r->pack_buffer);
    g->gl.GetIntegerv(SFB__GL_PACK_ALIGNMENT, &r->pack[0]);
    g->gl.GetIntegerv(SFB__GL_PACK_ROW_LENGTH, &r->pack[1]);
    g->gl.GetIntegerv(SFB__GL_PACK_SKIP_ROWS, &r->pack[2]);
    g->gl.GetIntegerv(SFB__GL_PACK_SKIP_PIXELS, &r->pack[3]);
    g->gl.GetBooleanv(SFB__GL_DEPTH_WRITEMASK, &r->depth_mask);
    g->gl.GetBooleanv(SFB__GL_COLOR_WRITEMASK, r->color_mask);
    r->depth_test = g->gl.IsEnabled(SFB__GL_DEPTH_TEST);
    r->scissor = g->gl.IsEnabled(SFB__GL_SCISSOR_TEST);
    r->stencil = g->gl.IsEnabled(SFB__GL_STENCIL_TEST);
    r->cull = g->gl.IsEnabled(SFB__GL_CULL_FACE);
    r->blend = g->gl.IsEnabled(SFB__GL_BLEND);
}

static void sfb__gl_raster_switch(sfb__gl *g, sfb__GLenum cap, sfb__GLboolean on) {
    if (on) g->gl.Enable(cap);
    else g->gl.Disable(cap);
}

static void sfb__gl_raster_restore(sfb__gl *g, const sfb__gl_rstate *r) {
    g->gl.BindFramebuffer(SFB__GL_DRAW_FRAMEBUFFER, (sfb__GLuint)r->draw_fbo);
    g->gl.BindFramebuffer(SFB__GL_READ_FRAMEBUFFER, (sfb__GLuint)r->read_fbo);
    g->gl.Viewport(r->viewport[0], r->viewport[1], r->viewport[2], r->viewport[3]);
    g->gl.DepthFunc((sfb__GLenum)r->depth_func);
    g->gl.BindBuffer(SFB__GL_PIXEL_PACK_BUFFER, (sfb__GLuint)r->pack_buffer);
    g->gl.PixelStorei(SFB__GL_PACK_ALIGNMENT, r->pack[0]);
    g->gl.PixelStorei(SFB__GL_PACK_ROW_LENGTH, r->pack[1]);
    g->gl.PixelStorei(SFB__GL_PACK_SKIP_ROWS, r->pack[2]);
    g->gl.PixelStorei(SFB__GL_PACK_SKIP_PIXELS, r->pack[3]);
    g->gl.DepthMask(r->depth_mask);
    g->gl.ColorMask(r->color_mask[0], r->color_mask[1], r->color_mask[2], r->color_mask[3]);
    sfb__gl_raster_switch(g, SFB__GL_DEPTH_TEST, r->depth_test);
    sfb__gl_raster_switch(g, SFB__GL_SCISSOR_TEST, r->scissor);
    sfb__gl_raster_switch(g, SFB__GL_STENCIL_TEST, r->stencil);
    sfb__gl_raster_switch(g, SFB__GL_CULL_FACE, r->cull);
    sfb__gl_raster_switch(g, SFB__GL_BLEND, r->blend);
}

static sfb_result sfb__gl_raster_program(sfb__gl *g) {
    static const char *const names[7] = {"u_tris", "u_size", "u_nt", "u_tpr", "u_ortho", "u_polygon", "u_zscale"};
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->raster_program) return SFB_SUCCESS;
    if ((r = sfb__gl_draw_stages(g, "", sfb__glsl_raster_vert_glsl, "raster.vert.glsl", sfb__glsl_raster_frag_glsl, "raster.frag.glsl", NULL,
                                 0, "the analysis raster program", &prog)) != SFB_SUCCESS)
        return r;
    for (i = 0; i < 7; ++i) g->raster_loc[i] = g->gl.GetUniformLocation(prog, names[i]);
    g->raster_program = prog;
    g->gl.GenVertexArrays(1, &g->raster_vao); /* bound empty: the vertex stage reads the texture */
    return sfb__gl_check(g, "building the analysis raster program");
}

/* Triangles [first, first + count) of the job as the triangle texture's texels (raster.frag.glsl
 * says which), `tpr` triangles of `nt` texels a row; the rest of the last row zero. */
static void sfb__gl_raster_texels(const sfb__raster_job *j, int first, int count, int nt, int tpr, float *out) {
    const size_t rows = ((size_t)count + (size_t)tpr - 1) / (size_t)tpr;
    int t, k, c;
    memset(out, 0, rows * (size_t)tpr * (size_t)nt * 4 * sizeof(float));
    for (t = 0; t < count; ++t) {
        const int *tv = j->tri + 4 * ((size_t)first + (size_t)t);
        float *o = out + ((size_t)(t / tpr) * (size_t)tpr + (size_t)(t % tpr)) * (size_t)nt * 4;
        for (k = 0; k < 3; ++k) {
            const sfb__raster_vertex *q = &j->vert[tv[k]];
            o[4 * k] = (float)q->x; o[4 * k + 1] = (float)q->y; o[4 * k + 2] = (float)q->q; o[4 * k + 3] = (float)q->z;
            o[12 + 2 * k] = (float)q->u; o[12 + 2 * k + 1] = (float)q->v;
            if (j->apos)
                for (c = 0; c < 3; ++c) {
                    o[20 + 4 * k + c] = j->apos[3 * (size_t)tv[k] + c];
                    o[32 + 4 * k + c] = j->anrm[3 * (size_t)tv[k] + c];
                }
        }
        o[18] = (float)tv[3]; /* the face, exact below 2^24 (checked by the caller) */
    }
}

/* Draws the triangles, in batches that fit one triangle texture, into a framebuffer of fresh
 * textures and reads it back (the context current, the state saved by the caller). */
static sfb_result sfb__gl_raster_draw(sfb__gl *g, const sfb__raster_job *j, double zmax) {
    static const sfb__GLenum bufs[3] = {SFB__GL_COLOR_ATTACHMENT0, SFB__GL_COLOR_ATTACHMENT0 + 1, SFB__GL_COLOR_ATTACHMENT0 + 2};
    const sfb__GLuint clear_hit[4] = {0, 0, 0, 0};
    const float clear_depth = 1.0f;
    const int nout = j->apos ? 3 : 1, nt = j->apos ? 11 : 5;
    /* rows of up to 4096 texels (or GL's limit), batches of up to 2^17 triangles (23 MB of
     * texels with the polygon data) and as many rows as GL allows */
    const int tw = (g->max_texture < 4096 ? g->max_texture : 4096) / nt * nt, tpr = tw / nt;
    const long long most = (long long)tpr * g->max_texture < (1 << 17) ? (long long)tpr * g->max_texture : (1 << 17);
    const int batch = (int)(most > (long long)j->ntri ? j->ntri : most);
    const size_t npix = (size_t)j->w * (size_t)j->h;
    sfb__GLuint tex[5] = {0, 0, 0, 0, 0}, fbo = 0, *px = NULL;
    float *texels = NULL;
    sfb_result r;
    int i, first;
    size_t p;
    if ((r = sfb__gl_raster_program(g)) != SFB_SUCCESS) return r;
    if ((r = sfb__gl_mf_sampler(g)) != SFB_SUCCESS) return r;
    px = (sfb__GLuint *)sfb__alloc(g->ctx, npix * 4 * sizeof(sfb__GLuint) + 1);
    texels = (float *)sfb__alloc(g->ctx, ((size_t)batch + (size_t)tpr) * (size_t)nt * 4 * sizeof(float));
    if (!px || !texels) {
        sfb__free(g->ctx, px);
        sfb__free(g->ctx, texels);
        return sfb__oom(g->ctx, "the gl raster's read-back");
    }
    g->gl.ActiveTexture(SFB__GL_TEXTURE0); /* unit 0 is among those sfb__gl_draw_save keeps */
    for (i = 0; i < nout; ++i)
        tex[i] = sfb__gl_mf_texture(g, SFB__GL_RGBA32UI, j->w, j->h, SFB__GL_RGBA_INTEGER, SFB__GL_UNSIGNED_INT, NULL);
    tex[3] = sfb__gl_mf_texture(g, SFB__GL_DEPTH_COMPONENT32F, j->w, j->h, SFB__GL_DEPTH_COMPONENT, SFB__GL_FLOAT, NULL);
    g->gl.GenFramebuffers(1, &fbo);
    g->gl.BindFramebuffer(SFB__GL_FRAMEBUFFER, fbo);
    for (i = 0; i < nout; ++i) g->gl.FramebufferTexture2D(SFB__GL_FRAMEBUFFER, bufs[i], SFB__GL_TEXTURE_2D, tex[i], 0);
    g->gl.FramebufferTexture2D(SFB__GL_FRAMEBUFFER, SFB__GL_DEPTH_ATTACHMENT, SFB__GL_TEXTURE_2D, tex[3], 0);
    g->gl.DrawBuffers(nout, bufs);
    if ((r = sfb__gl_check(g, "setting up the analysis raster")) != SFB_SUCCESS) goto done;
    if (g->gl.CheckFramebufferStatus(SFB__GL_FRAMEBUFFER) != SFB__GL_FRAMEBUFFER_COMPLETE) {
        r = SFB_UNSUPPORTED;
        goto done;
    }
    g->gl.Viewport(0, 0, j->w, j->h);
    g->gl.Disable(SFB__GL_SCISSOR_TEST);
    g->gl.Disable(SFB__GL_STENCIL_TEST);
    g->gl.Disable(SFB__GL_CULL_FACE);
    g->gl.Disable(SFB__GL_BLEND);
    g->gl.Disable(SFB__GL_RASTERIZER_DISCARD);
    g->gl.Enable(SFB__GL_DEPTH_TEST);
    g->gl.DepthFunc(SFB__GL_LESS);
    g->gl.DepthMask(1);
    g->gl.ColorMask(1, 1, 1, 1);
    for (i = 0; i < nout; ++i) g->gl.ClearBufferuiv(SFB__GL_COLOR, i, clear_hit);
    g->gl.ClearBufferfv(SFB__GL_DEPTH, 0, &clear_depth);
    g->gl.UseProgram(g->raster_program);
    g->gl.Uniform1i(g->raster_loc[0], 0);
    g->gl.Uniform2f(g->raster_loc[1], (float)j->w, (float)j->h);
    g->gl.Uniform1i(g->raster_loc[2], nt);
    g->gl.Uniform1i(g->raster_loc[3], tpr);
    g->gl.Uniform1i(g->raster_loc[4], j->ortho);
    g->gl.Uniform1i(g->raster_loc[5], j->apos != NULL);
    g->gl.Uniform1f(g->raster_loc[6], (float)(1.0 / (zmax * 1.0001)));
    g->gl.BindVertexArray(g->raster_vao);
    g->gl.BindSampler(0, g->sampler);
    sfb__gl_unpack_plain(g, 4);
    tex[4] = sfb__gl_mf_texture(g, SFB__GL_RGBA32F, tw, 1, SFB__GL_RGBA, SFB__GL_FLOAT, NULL);
    /* batches in the job's order, so that the first of equal depths keeps a pixel */
    for (first = 0; first < j->ntri && r == SFB_SUCCESS; first += batch) {
        const int count = j->ntri - first < batch ? j->ntri - first : batch, rows = (count + tpr - 1) / tpr;
        sfb__gl_raster_texels(j, first, count, nt, tpr, texels);
        g->gl.BindTexture(SFB__GL_TEXTURE_2D, tex[4]);
        g->gl.TexImage2D(SFB__GL_TEXTURE_2D, 0, SFB__GL_RGBA32F, tw, rows, 0, SFB__GL_RGBA, SFB__GL_FLOAT, texels);
        g->gl.DrawArraysInstanced(SFB__GL_TRIANGLES, 0, 3 * count, 1);
        r = sfb__gl_check(g, "drawing the analysis raster");
    }
    if (r != SFB_SUCCESS) goto done;
    g->gl.BindBuffer(SFB__GL_PIXEL_PACK_BUFFER, 0);
    g->gl.PixelStorei(SFB__GL_PACK_ALIGNMENT, 4);
    g->gl.PixelStorei(SFB__GL_PACK_ROW_LENGTH, 0);
    g->gl.PixelStorei(SFB__GL_PACK_SKIP_ROWS, 0);
    g->gl.PixelStorei(SFB__GL_PACK_SKIP_PIXELS, 0);
    g->gl.BindFramebuffer(SFB__GL_READ_FRAMEBUFFER, fbo);
    g->gl.ReadBuffer(SFB__GL_COLOR_ATTACHMENT0);
    g->gl.ReadPixels(0, 0, j->w, j->h, SFB__GL_RGBA_INTEGER, SFB__GL_UNSIGNED_INT, px);
    if ((r = sfb__gl_check(g, "reading the analysis raster back")) != SFB_SUCCESS) goto done;
    /* GL's row 0 is the picture's bottom row */
    for (p = 0; p < npix; ++p) {
        const sfb__GLuint *q = px + 4 * p;
        const size_t pix = ((size_t)j->h - 1 - p / (size_t)j->w) * (size_t)j->w + p % (size_t)j->w;
        float z;
        if (q[3] == 0) continue;
        memcpy(&z, &q[2], sizeof z);
        if (!(z < j->depth[pix])) continue;
        j->depth[pix] = z;
        j->face[pix] = (int)q[3] - 1;
        memcpy(&j->uv[2 * pix], &q[0], sizeof(float));
        memcpy(&j->uv[2 * pix + 1], &q[1], sizeof(float));
    }
    for (i = 1; i < nout; ++i) {
        float *dst = i == 1 ? j->pos : j->nrm;
        g->gl.ReadBuffer(bufs[i]);
        g->gl.ReadPixels(0, 0, j->w, j->h, SFB__GL_RGBA_INTEGER, SFB__GL_UNSIGNED_INT, px);
        if ((r = sfb__gl_check(g, "reading the analysis raster back")) != SFB_SUCCESS) goto done;
        for (p = 0; p < npix; ++p) {
            const size_t pix = ((size_t)j->h - 1 - p / (size_t)j->w) * (size_t)j->w + p % (size_t)j->w;
            memcpy(&dst[3 * pix], px + 4 * p, 3 * sizeof(float));
        }
    }
done:
    g->gl.BindFramebuffer(SFB__GL_FRAMEBUFFER, 0);
    if (fbo) g->gl.DeleteFramebuffers(1, &fbo);
    for (i = 0; i < 5; ++i)
        if (tex[i]) g->gl.DeleteTextures(1, &tex[i]);
    sfb__free(g->ctx, px);
    sfb__free(g->ctx, texels);
    return r;
}

static sfb_result sfb__gl_raster(void *state, const sfb__raster_job *j) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved saved;
    sfb__gl_drawstate ds;
    sfb__gl_rstate rs;
    sfb__GLint dims[2] = {0, 0};
    double zmax = 0.0;
    int t, k;
    const char *why = NULL;
    sfb_result r;
    if (!g || !j || j->w < 1 || j->h < 1 || j->ntri < 0) return SFB_INVALID_ARGS;
    if (j->ntri == 0) return SFB_SUCCESS;
    for (t = 0; t < j->ntri && !why; ++t) {
        if (j->tri[4 * (size_t)t + 3] < 0 || j->tri[4 * (size_t)t + 3] >= (1 << 24)) why = "a parametric face number is 2^24 or more";
        for (k = 0; k < 3; ++k)
            if (j->vert[j->tri[4 * (size_t)t + (size_t)k]].z > zmax) zmax = j->vert[j->tri[4 * (size_t)t + (size_t)k]].z;
    }
    if ((r = sfb__gl_enter(g, &saved)) != SFB_SUCCESS) return r;
    g->gl.GetIntegerv(SFB__GL_MAX_VIEWPORT_DIMS, dims);
    if (j->w > g->max_texture || j->h > g->max_texture || j->w > dims[0] || j->h > dims[1]) why = "the picture exceeds GL's texture or viewport size";
    if (!why) {
        sfb__gl_draw_save(g, &ds);
        sfb__gl_raster_save(g, &rs);
        r = sfb__gl_raster_draw(g, j, zmax > 0.0 ? zmax : 1.0);
        sfb__gl_raster_restore(g, &rs);
        sfb__gl_draw_restore(g, &ds);
        if (r == SFB_UNSUPPORTED) { why = "the framebuffer is incomplete"; r = SFB_SUCCESS; }
    }
    sfb__gl_leave(g, &saved);
    if (r != SFB_SUCCESS) return r;
    if (why) {
        sfb__log(g->ctx, SFB_LOG_INFO, "%s: the analysis raster runs on the CPU (%s)", g->mode == SFB__GL_OSMESA ? "osmesa" : "gl", why);
        return sfb__ref_raster(NULL, j);
    }
    return SFB_SUCCESS;
}

/* The raster slot. */
static void sfb__gl_raster_bind(sfb__backend_vtable *vt) {
    vt->raster = sfb__gl_raster;
}

#endif /* SFB__GL_RASTER_H */
