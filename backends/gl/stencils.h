/* backends/gl/stencils.h -- stencil tables: uploaded in pieces that fit one shader storage block,
 * applied by stencils.comp.glsl to caller memory or, on the host's context, to its buffers.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. */
#ifndef SFB__GL_STENCILS_H
#define SFB__GL_STENCILS_H

/* The kernel source: a build-time override, used by tests/gl_errors.c to exercise the failure
 * paths for real. */
#ifndef SFB__GL_STENCIL_SOURCE
#define SFB__GL_STENCIL_SOURCE sfb__glsl_stencils_comp_glsl
#endif

/* One piece of an uploaded stencil table: rows [row0, row1) with their entries, small enough
 * for GL_MAX_SHADER_STORAGE_BLOCK_SIZE. */
typedef struct sfb__gl_piece {
    int row0, row1, entry0;
    sfb__GLuint buf[4]; /* sizes, offsets, indices, weights */
} sfb__gl_piece;
typedef struct sfb__gl_table {
    int count;
    sfb__gl_piece *pieces;
} sfb__gl_table;

static const char *const sfb__gl_uniforms[8] = {"u_first", "u_last", "u_entry_base", "u_row_base",
                                                "u_src_offset", "u_src_stride", "u_dst_offset", "u_dst_stride"};

static sfb_result sfb__gl_program(sfb__gl *g, int length, sfb__GLuint *out) {
    char defines[48], label[64];
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->program[length]) { *out = g->program[length]; return SFB_SUCCESS; }
    snprintf(defines, sizeof defines, "#define SFB_LENGTH %d\n", length);
    snprintf(label, sizeof label, "stencils.comp.glsl (SFB_LENGTH %d)", length);
    if ((r = sfb__gl_compile(g, defines, SFB__GL_STENCIL_SOURCE, label, &prog)) != SFB_SUCCESS) return r;
    for (i = 0; i < 8; ++i) g->loc[length][i] = g->gl.GetUniformLocation(prog, sfb__gl_uniforms[i]);
    g->program[length] = prog;
    *out = prog;
    return sfb__gl_check(g, "building the stencil kernel");
}

/* ---- tables ---- */
static void sfb__gl_table_free(sfb__gl *g, sfb__gl_table *t) {
    int i;
    if (!t) return;
    for (i = 0; i < t->count; ++i) g->gl.DeleteBuffers(4, t->pieces[i].buf);
    sfb__free(g->ctx, t->pieces);
    sfb__free(g->ctx, t);
}

/* Uploads with the context already current. Rows are cut into pieces whose arrays each fit
 * one shader storage block (offsets in our tables are contiguous, row after row). */
static sfb_result sfb__gl_upload_current(sfb__gl *g, const sfb__stencils *t, sfb__gl_table **out) {
    size_t cap = (size_t)g->max_block / 4;
    int r0 = 0, count = 0, allocated = 0;
    sfb__gl_table *tab = (sfb__gl_table *)sfb__calloc(g->ctx, 1, sizeof *tab);
    sfb_result res;
    *out = NULL;
    if (!tab) return sfb__oom(g->ctx, "gl stencil table");
    while (r0 < t->rows) {
        int r1 = r0;
        size_t e0 = (size_t)t->offsets[r0], e1 = e0;
        sfb__gl_piece *p;
        while (r1 < t->rows && (size_t)(r1 - r0) < cap && (size_t)t->offsets[r1] + (size_t)t->sizes[r1] - e0 <= cap) {
            if ((size_t)t->offsets[r1] != e1) {
                sfb__gl_table_free(g, tab);
                return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: stencil rows are not contiguous (row %d)", r1);
            }
            e1 += (size_t)t->sizes[r1];
            ++r1;
        }
        if (r1 == r0) {
            sfb__gl_table_free(g, tab);
            return sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                              "gl: stencil row %d has %d entries, more than one storage block holds", r0, t->sizes[r0]);
        }
        if (count == allocated) {
            int na = allocated ? allocated * 2 : 4;
            sfb__gl_piece *np = (sfb__gl_piece *)sfb__realloc(g->ctx, tab->pieces, (size_t)na * sizeof *np);
            if (!np) { sfb__gl_table_free(g, tab); return sfb__oom(g->ctx, "gl stencil table"); }
            tab->pieces = np;
            allocated = na;
        }
        p = &tab->pieces[count];
        memset(p, 0, sizeof *p);
        p->row0 = r0;
        p->row1 = r1;
        p->entry0 = (int)e0;
        g->gl.GenBuffers(4, p->buf);
        tab->count = ++count;
        /* a zero-length storage buffer cannot be bound: keep at least one element */
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p->buf[0]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(r1 - r0) * 4, t->sizes + r0, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p->buf[1]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(r1 - r0) * 4, t->offsets + r0, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p->buf[2]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(e1 > e0 ? e1 - e0 : 1) * 4, t->indices + e0, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p->buf[3]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(e1 > e0 ? e1 - e0 : 1) * 4, t->weights + e0, SFB__GL_STATIC_DRAW);
        if ((res = sfb__gl_check(g, "uploading a stencil table")) != SFB_SUCCESS) {
            sfb__gl_table_free(g, tab);
            return res;
        }
        r0 = r1;
    }
    *out = tab;
    return SFB_SUCCESS;
}

static sfb_result sfb__gl_upload(void *state, const sfb__stencils *t, void **handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved s;
    sfb__gl_table *tab = NULL;
    sfb_result r = sfb__gl_enter(g, &s);
    if (r != SFB_SUCCESS) return r;
    r = sfb__gl_upload_current(g, t, &tab);
    sfb__gl_leave(g, &s);
    *handle = tab;
    return r;
}

static void sfb__gl_release(void *state, void *handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved s;
    if (!handle) return;
    if (sfb__gl_enter(g, &s) == SFB_SUCCESS) {
        sfb__gl_table_free(g, (sfb__gl_table *)handle);
        sfb__gl_leave(g, &s);
    } else {
        sfb__free(g->ctx, ((sfb__gl_table *)handle)->pieces);
        sfb__free(g->ctx, handle);
    }
}

/* Runs the kernel over rows [first,last) with the given src/dst buffers bound whole. */
static sfb_result sfb__gl_dispatch(sfb__gl *g, const sfb__gl_table *tab, int first, int last, sfb__GLuint src,
                                   int src_offset, int src_stride, sfb__GLuint dst, int dst_offset, int dst_stride,
                                   int length) {
    sfb__GLuint prog;
    const sfb__GLint *loc;
    int i;
    sfb_result r = sfb__gl_program(g, length, &prog);
    if (r != SFB_SUCCESS) return r;
    loc = g->loc[length];
    g->gl.UseProgram(prog);
    g->gl.Uniform1i(loc[4], src_offset);
    g->gl.Uniform1i(loc[5], src_stride);
    g->gl.Uniform1i(loc[6], dst_offset);
    g->gl.Uniform1i(loc[7], dst_stride);
    g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 4, src);
    g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 5, dst);
    for (i = 0; i < tab->count; ++i) {
        const sfb__gl_piece *p = &tab->pieces[i];
        int a = first > p->row0 ? first : p->row0, b = last < p->row1 ? last : p->row1, k;
        if (a >= b) continue;
        for (k = 0; k < 4; ++k) g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)k, p->buf[k]);
        g->gl.Uniform1i(loc[2], p->entry0);
        g->gl.Uniform1i(loc[3], p->row0);
        sfb__gl_dispatch_range(g, loc[0], loc[1], a - p->row0, b - p->row0);
    }
    return sfb__gl_check(g, "the stencil kernel");
}

static sfb_result sfb__gl_eval(void *state, const sfb__stencils *t, void *handle, int first, int last, const float *src,
                               sfb_buffer_desc sd, float *dst, sfb_buffer_desc dd) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_table *tab = (sfb__gl_table *)handle, *temp = NULL;
    sfb__gl_saved s;
    size_t src_bytes = sfb__gl_span(t->sources, sd), dst_bytes;
    int rows = last - first, length = sd.length, r, c;
    sfb_result res;
    const float *mapped;
    if (rows <= 0) return SFB_SUCCESS;
    if (sd.length != dd.length || length < 1 || length > 16) return SFB_INVALID_ARGS;
    dst_bytes = (size_t)rows * (size_t)length * sizeof(float);
    /* src is uploaded from its first element; dst comes back compact and is scattered here */
    if (src_bytes - (size_t)sd.offset * sizeof(float) > (size_t)g->max_block || dst_bytes > (size_t)g->max_block)
        return sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "%s: buffers of %zu and %zu bytes exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE (%d)", g->mode == SFB__GL_OSMESA ? "osmesa" : "gl",
                          src_bytes, dst_bytes, (int)g->max_block);
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    if (!tab) {
        if ((res = sfb__gl_upload_current(g, t, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    if ((res = sfb__gl_grow(g, &g->scratch_src, &g->scratch_src_cap, src_bytes > 0 ? src_bytes : 4, SFB__GL_STREAM_DRAW)) != SFB_SUCCESS) goto done;
    if (src_bytes > (size_t)sd.offset * sizeof(float))
        g->gl.BufferSubData(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)(src_bytes - (size_t)sd.offset * sizeof(float)), src + sd.offset);
    if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, dst_bytes, SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS) goto done;
    res = sfb__gl_dispatch(g, tab, first, last, g->scratch_src, 0, sd.stride, g->scratch_dst, -first * length, length, length);
    if (res != SFB_SUCCESS) goto done;
    if ((res = sfb__gl_map_results(g, dst_bytes, &mapped)) != SFB_SUCCESS) goto done;
    for (r = 0; r < rows; ++r) {
        float *o = dst + dd.offset + (size_t)(first + r) * (size_t)dd.stride;
        const float *i = mapped + (size_t)r * (size_t)length;
        for (c = 0; c < length; ++c) o[c] = i[c];
    }
    res = sfb__gl_unmap_results(g);
done:
    if (temp) sfb__gl_table_free(g, temp);
    sfb__gl_leave(g, &s);
    return res;
}

static sfb_result sfb__gl_eval_buffers(void *state, const sfb__stencils *t, void *handle, unsigned src_buffer,
                                       sfb_buffer_desc sd, unsigned dst_buffer, sfb_buffer_desc dd) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_table *tab = (sfb__gl_table *)handle, *temp = NULL;
    sfb__gl_saved s;
    sfb__GLint src_size = 0, dst_size = 0;
    size_t need_src = sfb__gl_span(t->sources, sd), need_dst = sfb__gl_span(t->rows, dd);
    sfb_result res;
    if (g->mode != SFB__GL_HOST)
        return sfb__error(g->ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_eval_stencils_gl: the %s backend runs on its own context; set gl_use_current_context to share the host's buffers",
                          g->mode == SFB__GL_OSMESA ? "osmesa" : "gl");
    if (need_src > (size_t)g->max_block || need_dst > (size_t)g->max_block)
        return sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "gl: buffer views of %zu and %zu bytes exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE (%d)", need_src, need_dst, (int)g->max_block);
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, src_buffer);
    g->gl.GetBufferParameteriv(SFB__GL_SHADER_STORAGE_BUFFER, SFB__GL_BUFFER_SIZE, &src_size);
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, dst_buffer);
    g->gl.GetBufferParameteriv(SFB__GL_SHADER_STORAGE_BUFFER, SFB__GL_BUFFER_SIZE, &dst_size);
    if (g->gl.GetError() != SFB__GL_NO_ERROR) {
        while (g->gl.GetError() != SFB__GL_NO_ERROR) {}
        res = sfb__error(g->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "gl: buffer %u or %u is not a buffer object of the current context",
                         src_buffer, dst_buffer);
        goto done;
    }
    if ((size_t)src_size < need_src || (size_t)dst_size < need_dst) {
        res = sfb__error(g->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                         "gl: buffer too small: source %u has %d bytes (needs %zu), destination %u has %d bytes (needs %zu)",
                         src_buffer, (int)src_size, need_src, dst_buffer, (int)dst_size, need_dst);
        goto done;
    }
    if (!tab) {
        if ((res = sfb__gl_upload_current(g, t, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    res = sfb__gl_dispatch(g, tab, 0, t->rows, src_buffer, sd.offset, sd.stride, dst_buffer, dd.offset, dd.stride, sd.length);
    /* the host may draw from, map or copy the result next */
    if (res == SFB_SUCCESS) g->gl.MemoryBarrier(SFB__GL_ALL_BARRIER_BITS);
done:
    if (temp) sfb__gl_table_free(g, temp);
    sfb__gl_leave(g, &s);
    return res;
}

/* The stencil slots (both gl and osmesa; eval_stencils_gl, on the host's buffers, is gl's alone). */
static void sfb__gl_stencils_bind(sfb__backend_vtable *vt) {
    vt->upload_stencils = sfb__gl_upload;
    vt->release_stencils = sfb__gl_release;
    vt->eval_stencils = sfb__gl_eval;
}

#endif /* SFB__GL_STENCILS_H */
