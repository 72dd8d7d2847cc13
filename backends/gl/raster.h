/* backends/gl/raster.h -- seed 003's proxy raster (the `raster` slot) in raster.vert.glsl and
 * raster.frag.glsl: the analysis proxy's triangles drawn by GL's rasteriser into an offscreen
 * framebuffer, read back into the job's per-pixel buffers.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. The framebuffer: an RGBA32UI texture of (u, v, view depth, face + 1) bits per
 * pixel (integer textures are colour-renderable in GLES 3 without extensions, float ones are
 * not), two more for the polygon-based method's interpolated position and normal, and a 32-bit
 * float depth texture holding the view depth scaled into [0, 1]. The vertices are the job's in
 * one attribute buffer (x, y, z, u, v in float, the face as an integer: a proxy grid point
 * belongs to the triangles of one parametric face, which the kernel checks), the triangles an
 * index buffer. Where GL differs from ref (sfb__ref_raster): float interpolation (GL's
 * perspective-correct weights are ref's b_k q_k / sum in float), the tie rule for pixel centres
 * on an edge, and the depth test in float. A picture larger than GL_MAX_TEXTURE_SIZE or
 * GL_MAX_VIEWPORT_DIMS, vertices shared by faces, or an incomplete framebuffer go to ref's
 * kernel (with a log line). On the host's context (gl_use_current_context) every state the
 * raster changes is put back: framebuffer bindings, viewport, depth, scissor, stencil, cull
 * and blend switches, depth function and masks, the array and pixel-pack buffers and pack
 * storage, besides sfb__gl_enter's and the draw path's state (sfb__gl_draw_save). Desktop GL's
 * glPolygonMode is not touched: a host that leaves it at GL_LINE gets a ref-like result only
 * where lines cover. */
#ifndef SFB__GL_RASTER_H
#define SFB__GL_RASTER_H

typedef struct sfb__gl_rstate {
    sfb__GLint draw_fbo, read_fbo, viewport[4], depth_func, array_buffer, pack_buffer, pack[4];
    sfb__GLboolean depth_test, scissor, stencil, cull, blend, depth_mask, color_mask[4];
} sfb__gl_rstate;

static void sfb__gl_raster_save(sfb__gl *g, sfb__gl_rstate *r) {
    g->gl.GetIntegerv(SFB__GL_DRAW_FRAMEBUFFER_BINDING, &r->draw_fbo);
    g->gl.GetIntegerv(SFB__GL_READ_FRAMEBUFFER_BINDING, &r->read_fbo);
    g->gl.GetIntegerv(SFB__GL_VIEWPORT, r->viewport);
    g->gl.GetIntegerv(SFB__GL_DEPTH_FUNC, &r->depth_func);
    g->gl.GetIntegerv(SFB__GL_ARRAY_BUFFER_BINDING, &r->array_buffer);
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
    g->gl.BindBuffer(SFB__GL_ARRAY_BUFFER, (sfb__GLuint)r->array_buffer);
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
    static const char *const names[3] = {"u_size", "u_ortho", "u_zscale"};
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->raster_program) return SFB_SUCCESS;
    if ((r = sfb__gl_draw_stages(g, "", sfb__glsl_raster_vert_glsl, "raster.vert.glsl", sfb__glsl_raster_frag_glsl, "raster.frag.glsl", NULL,
                                 0, "the analysis raster program", &prog)) != SFB_SUCCESS)
        return r;
    for (i = 0; i < 3; ++i) g->raster_loc[i] = g->gl.GetUniformLocation(prog, names[i]);
    g->raster_program = prog;
    g->gl.GenVertexArrays(1, &g->raster_vao);
    g->gl.GenBuffers(2, g->raster_buf);
    return sfb__gl_check(g, "building the analysis raster program");
}

/* The vertices the triangles use, as the attribute buffer's words (stride: 6, or 12 with the
 * position and normal), the face as an int's bits; the indices; the largest depth. 0 when a
 * vertex is shared by two faces (the kernel's assumption), -1 out of memory. */
static int sfb__gl_raster_data(sfb__gl *g, const sfb__raster_job *j, int stride, int nvert, float **vdata, sfb__GLuint **idx,
                               double *zmax) {
    float *v;
    sfb__GLuint *ix;
    int t, k, c;
    *vdata = v = (float *)sfb__calloc(g->ctx, (size_t)nvert * (size_t)stride + 1, sizeof(float));
    *idx = ix = (sfb__GLuint *)sfb__alloc(g->ctx, (size_t)j->ntri * 3 * sizeof(sfb__GLuint) + 1);
    if (!v || !ix) return -1;
    *zmax = 0.0;
    for (t = 0; t < nvert; ++t) {
        const int none = -1;
        memcpy(&v[(size_t)t * (size_t)stride + 5], &none, sizeof none);
    }
    for (t = 0; t < j->ntri; ++t) {
        const int *tv = j->tri + 4 * (size_t)t;
        for (k = 0; k < 3; ++k) {
            const sfb__raster_vertex *q = &j->vert[tv[k]];
            float *o = v + (size_t)tv[k] * (size_t)stride;
            int face;
            memcpy(&face, &o[5], sizeof face);
            if (face != -1 && face != tv[3]) return 0;
            ix[3 * (size_t)t + (size_t)k] = (sfb__GLuint)tv[k];
            if (face != -1) continue;
            o[0] = (float)q->x; o[1] = (float)q->y; o[2] = (float)q->z; o[3] = (float)q->u; o[4] = (float)q->v;
            memcpy(&o[5], &tv[3], sizeof(int));
            if (q->z > *zmax) *zmax = q->z;
            if (j->apos)
                for (c = 0; c < 3; ++c) {
                    o[6 + c] = j->apos[3 * (size_t)tv[k] + c];
                    o[9 + c] = j->anrm[3 * (size_t)tv[k] + c];
                }
        }
    }
    return 1;
}

/* Draws the triangles into a framebuffer of fresh textures and reads it back (the context
 * current, the state saved by the caller). */
static sfb_result sfb__gl_raster_draw(sfb__gl *g, const sfb__raster_job *j, const float *vdata, int nvert, int stride,
                                      const sfb__GLuint *idx, double zmax) {
    static const sfb__GLenum bufs[3] = {SFB__GL_COLOR_ATTACHMENT0, SFB__GL_COLOR_ATTACHMENT0 + 1, SFB__GL_COLOR_ATTACHMENT0 + 2};
    const sfb__GLuint clear_hit[4] = {0, 0, 0, 0};
    const float clear_depth = 1.0f;
    const int nout = j->apos ? 3 : 1;
    const size_t npix = (size_t)j->w * (size_t)j->h, bytes = (size_t)stride * sizeof(float);
    sfb__GLuint tex[4] = {0, 0, 0, 0}, fbo = 0, *px = NULL;
    sfb_result r;
    int i;
    size_t p;
    if ((r = sfb__gl_raster_program(g)) != SFB_SUCCESS) return r;
    px = (sfb__GLuint *)sfb__alloc(g->ctx, npix * 4 * sizeof(sfb__GLuint) + 1);
    if (!px) return sfb__oom(g->ctx, "the gl raster's read-back");
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
    g->gl.Uniform2f(g->raster_loc[0], (float)j->w, (float)j->h);
    g->gl.Uniform1i(g->raster_loc[1], j->ortho);
    g->gl.Uniform1f(g->raster_loc[2], (float)(1.0 / (zmax * 1.0001)));
    g->gl.BindVertexArray(g->raster_vao);
    g->gl.BindBuffer(SFB__GL_ARRAY_BUFFER, g->raster_buf[0]);
    g->gl.BufferData(SFB__GL_ARRAY_BUFFER, (sfb__GLsizeiptr)((size_t)nvert * bytes), vdata, SFB__GL_STREAM_DRAW);
    g->gl.EnableVertexAttribArray(0);
    g->gl.VertexAttribPointer(0, 3, SFB__GL_FLOAT, 0, (sfb__GLsizei)bytes, (const void *)0);
    g->gl.EnableVertexAttribArray(1);
    g->gl.VertexAttribPointer(1, 2, SFB__GL_FLOAT, 0, (sfb__GLsizei)bytes, (const void *)(3 * sizeof(float)));
    g->gl.EnableVertexAttribArray(2);
    g->gl.VertexAttribIPointer(2, 1, SFB__GL_INT, (sfb__GLsizei)bytes, (const void *)(5 * sizeof(float)));
    if (j->apos) {
        g->gl.EnableVertexAttribArray(3);
        g->gl.VertexAttribPointer(3, 3, SFB__GL_FLOAT, 0, (sfb__GLsizei)bytes, (const void *)(6 * sizeof(float)));
        g->gl.EnableVertexAttribArray(4);
        g->gl.VertexAttribPointer(4, 3, SFB__GL_FLOAT, 0, (sfb__GLsizei)bytes, (const void *)(9 * sizeof(float)));
    }
    g->gl.BindBuffer(SFB__GL_ELEMENT_ARRAY_BUFFER, g->raster_buf[1]);
    g->gl.BufferData(SFB__GL_ELEMENT_ARRAY_BUFFER, (sfb__GLsizeiptr)((size_t)j->ntri * 3 * sizeof(sfb__GLuint)), idx, SFB__GL_STREAM_DRAW);
    g->gl.DrawElementsInstanced(SFB__GL_TRIANGLES, 3 * j->ntri, SFB__GL_UNSIGNED_INT, NULL, 1);
    if ((r = sfb__gl_check(g, "drawing the analysis raster")) != SFB_SUCCESS) goto done;
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
    for (i = 0; i < 4; ++i)
        if (tex[i]) g->gl.DeleteTextures(1, &tex[i]);
    sfb__free(g->ctx, px);
    return r;
}

static sfb_result sfb__gl_raster(void *state, const sfb__raster_job *j) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved saved;
    sfb__gl_drawstate ds;
    sfb__gl_rstate rs;
    sfb__GLint dims[2] = {0, 0};
    sfb__GLuint *idx = NULL;
    float *vdata = NULL;
    double zmax = 0.0;
    int nvert = 0, t, k, ok;
    const int stride = j && j->apos ? 12 : 6;
    const char *why = NULL;
    sfb_result r;
    if (!g || !j || j->w < 1 || j->h < 1 || j->ntri < 0) return SFB_INVALID_ARGS;
    if (j->ntri == 0) return SFB_SUCCESS;
    for (t = 0; t < j->ntri; ++t)
        for (k = 0; k < 3; ++k)
            if (j->tri[4 * (size_t)t + (size_t)k] >= nvert) nvert = j->tri[4 * (size_t)t + (size_t)k] + 1;
    if ((r = sfb__gl_enter(g, &saved)) != SFB_SUCCESS) return r;
    g->gl.GetIntegerv(SFB__GL_MAX_VIEWPORT_DIMS, dims);
    if (j->w > g->max_texture || j->h > g->max_texture || j->w > dims[0] || j->h > dims[1]) why = "the picture exceeds GL's texture or viewport size";
    else if ((size_t)nvert * (size_t)stride * sizeof(float) > (size_t)0x7fffffff || (size_t)j->ntri * 12 > (size_t)0x7fffffff)
        why = "the proxy exceeds one GL buffer";
    else if ((ok = sfb__gl_raster_data(g, j, stride, nvert, &vdata, &idx, &zmax)) < 0) r = sfb__oom(g->ctx, "the gl raster's vertices");
    else if (ok == 0) why = "a proxy vertex is shared by two faces";
    if (r == SFB_SUCCESS && !why) {
        sfb__gl_draw_save(g, &ds);
        sfb__gl_raster_save(g, &rs);
        r = sfb__gl_raster_draw(g, j, vdata, nvert, stride, idx, zmax > 0.0 ? zmax : 1.0);
        sfb__gl_raster_restore(g, &rs);
        sfb__gl_draw_restore(g, &ds);
        if (r == SFB_UNSUPPORTED) { why = "the framebuffer is incomplete"; r = SFB_SUCCESS; }
    }
    sfb__gl_leave(g, &saved);
    sfb__free(g->ctx, vdata);
    sfb__free(g->ctx, idx);
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
