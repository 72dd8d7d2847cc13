/* backends/gl/normals.h -- seed 001's normal blend (finish_normals) in normals.comp.glsl.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. */
#ifndef SFB__GL_NORMALS_H
#define SFB__GL_NORMALS_H

/* The kernel source: a build-time override, used by tests/gl_errors.c to exercise the failure
 * paths for real. */
#ifndef SFB__GL_NORMALS_SOURCE
#define SFB__GL_NORMALS_SOURCE sfb__glsl_normals_comp_glsl
#endif

/* ---- seed 001's normal blend (finish_normals) ---- */
static const char *const sfb__gl_normals_uniforms[8] = {"u_first", "u_last", "u_ns_base", "u_flags",
                                                        "u_stride", "u_limit_slot", "u_sub_slot", "u_p"};

static sfb_result sfb__gl_normals_program(sfb__gl *g, sfb__GLuint *out) {
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->normals_program) { *out = g->normals_program; return SFB_SUCCESS; }
    if ((r = sfb__gl_compile(g, "", SFB__GL_NORMALS_SOURCE, "normals.comp.glsl", &prog)) != SFB_SUCCESS) return r;
    for (i = 0; i < 8; ++i) g->normals_loc[i] = g->gl.GetUniformLocation(prog, sfb__gl_normals_uniforms[i]);
    g->normals_program = prog;
    *out = prog;
    return sfb__gl_check(g, "building the normals kernel");
}

/* Uploads `bytes` of `data` into finish_normals input buffer `slot` (grown as needed) and binds
 * it to storage binding `slot`. */
static sfb_result sfb__gl_normals_input(sfb__gl *g, int slot, const void *data, size_t bytes) {
    sfb_result r = sfb__gl_grow(g, &g->normals_buf[slot], &g->normals_cap[slot], bytes, SFB__GL_STREAM_DRAW);
    if (r != SFB_SUCCESS) return r;
    g->gl.BufferSubData(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)bytes, data);
    g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)slot, g->normals_buf[slot]);
    return SFB_SUCCESS;
}

/* Elements go in batches whose every buffer fits one shader storage block: the per-element
 * arrays of the batch, and the rows of ns between the smallest and largest index the batch
 * uses. Where those rows would not fit (indices spread wider than a block holds), the batch's
 * rows are gathered here instead, one per element that has one, and its indices renumbered to
 * them. Results come back compact, B (L, S) per element, and are copied into the caller's
 * arrays. */
static sfb_result sfb__gl_finish_normals(void *state, int first, int last, const float *tu, const float *tv, const float *ns,
                                         const int *ns_index, const float *b, float p, float *out_blend, float *out_limit,
                                         float *out_sub) {
    sfb__gl *g = (sfb__gl *)state;
    const int stride = 3 * (1 + (out_limit != NULL) + (out_sub != NULL));
    const int flags = (ns_index ? 1 : 0) | (ns_index && b ? 2 : 0);
    long long per;
    size_t cap;
    sfb__gl_saved s;
    sfb__GLuint prog;
    sfb_result res;
    float *rows = NULL;   /* gathered rows and renumbered indices of a batch (when needed) */
    int *renum = NULL, a;
    if (!g || first < 0 || first > last) return SFB_INVALID_ARGS;
    if (first == last) return SFB_SUCCESS;
    if (!tu || !tv || !out_blend || (ns_index && !ns)) return SFB_INVALID_ARGS;
    per = (long long)g->max_groups * 64;
    /* the results (>= 12 bytes per element) are the largest per-element buffer */
    cap = (size_t)g->max_block / ((size_t)stride * sizeof(float));
    if (cap < 1) cap = 1;
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    if ((res = sfb__gl_normals_program(g, &prog)) != SFB_SUCCESS) goto done;
    g->gl.UseProgram(prog);
    g->gl.Uniform1i(g->normals_loc[3], flags);
    g->gl.Uniform1i(g->normals_loc[4], stride);
    g->gl.Uniform1i(g->normals_loc[5], out_limit ? 3 : -1);
    g->gl.Uniform1i(g->normals_loc[6], out_sub ? (out_limit ? 6 : 3) : -1);
    g->gl.Uniform1f(g->normals_loc[7], p);
    for (a = first; a < last;) {
        const int n = (size_t)(last - a) > cap ? (int)cap : last - a;
        int kmin = 0, kmax = -1, i, d;
        const int *index = ns_index ? ns_index + a : NULL;
        size_t rbytes;
        const float *mapped;
        for (i = 0; index && i < n; ++i) {
            const int k = index[i];
            if (k < 0) continue;
            if (kmax < 0 || k < kmin) kmin = k;
            if (k > kmax) kmax = k;
        }
        if ((res = sfb__gl_normals_input(g, 0, tu + 3 * (size_t)a, (size_t)n * 3 * sizeof(float))) != SFB_SUCCESS) goto done;
        if ((res = sfb__gl_normals_input(g, 1, tv + 3 * (size_t)a, (size_t)n * 3 * sizeof(float))) != SFB_SUCCESS) goto done;
        /* arrays the kernel does not read get tu's buffer: a binding must name a buffer */
        if (kmax >= 0 && ((size_t)kmax - (size_t)kmin + 1) * 3 * sizeof(float) <= (size_t)g->max_block) {
            res = sfb__gl_normals_input(g, 2, ns + 3 * (size_t)kmin, ((size_t)kmax - (size_t)kmin + 1) * 3 * sizeof(float));
            if (res != SFB_SUCCESS) goto done;
        } else if (kmax >= 0) {
            int used = 0;
            if (!rows) { /* for the largest batch of this call */
                const size_t most = (size_t)(last - a) < cap ? (size_t)(last - a) : cap;
                rows = (float *)sfb__alloc(g->ctx, most * 3 * sizeof(float));
                renum = (int *)sfb__alloc(g->ctx, most * sizeof(int));
                if (!rows || !renum) { res = sfb__oom(g->ctx, "gl finish_normals"); goto done; }
            }
            for (i = 0; i < n; ++i) {
                const int k = index[i];
                renum[i] = k >= 0 ? used : -1;
                if (k >= 0) memcpy(rows + 3 * (size_t)used++, ns + 3 * (size_t)k, 3 * sizeof(float));
            }
            index = renum;
            kmin = 0;
            if ((res = sfb__gl_normals_input(g, 2, rows, (size_t)used * 3 * sizeof(float))) != SFB_SUCCESS) goto done;
        } else {
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 2, g->normals_buf[0]);
        }
        if (flags & 1) {
            if ((res = sfb__gl_normals_input(g, 3, index, (size_t)n * sizeof(int))) != SFB_SUCCESS) goto done;
        } else {
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 3, g->normals_buf[0]);
        }
        if (flags & 2) {
            if ((res = sfb__gl_normals_input(g, 4, b + a, (size_t)n * sizeof(float))) != SFB_SUCCESS) goto done;
        } else {
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 4, g->normals_buf[0]);
        }
        rbytes = (size_t)n * (size_t)stride * sizeof(float);
        if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, rbytes, SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS) goto done;
        g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 5, g->scratch_dst);
        g->gl.Uniform1i(g->normals_loc[2], kmax >= 0 ? kmin : 0);
        for (d = 0; d < n;) {
            int m = (long long)(n - d) > per ? (int)per : n - d;
            g->gl.Uniform1i(g->normals_loc[0], d);
            g->gl.Uniform1i(g->normals_loc[1], d + m);
            g->gl.DispatchCompute((sfb__GLuint)((m + 63) / 64), 1, 1);
            d += m;
        }
        if ((res = sfb__gl_check(g, "the normals kernel")) != SFB_SUCCESS) goto done;
        g->gl.MemoryBarrier(SFB__GL_BUFFER_UPDATE_BARRIER_BIT);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, g->scratch_dst);
        mapped = (const float *)g->gl.MapBufferRange(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)rbytes, SFB__GL_MAP_READ_BIT);
        if (!mapped) {
            res = sfb__gl_check(g, "mapping the results");
            if (res == SFB_SUCCESS) res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: glMapBufferRange returned NULL");
            goto done;
        }
        if (stride == 3) {
            memcpy(out_blend + 3 * (size_t)a, mapped, rbytes);
        } else {
            for (i = 0; i < n; ++i) {
                const float *r = mapped + (size_t)i * (size_t)stride;
                float *o = out_blend + 3 * ((size_t)a + (size_t)i);
                o[0] = r[0]; o[1] = r[1]; o[2] = r[2];
                if (out_limit) {
                    o = out_limit + 3 * ((size_t)a + (size_t)i);
                    o[0] = r[3]; o[1] = r[4]; o[2] = r[5];
                }
                if (out_sub) {
                    r += out_limit ? 6 : 3;
                    o = out_sub + 3 * ((size_t)a + (size_t)i);
                    o[0] = r[0]; o[1] = r[1]; o[2] = r[2];
                }
            }
        }
        g->gl.UnmapBuffer(SFB__GL_SHADER_STORAGE_BUFFER);
        if ((res = sfb__gl_check(g, "reading the results back")) != SFB_SUCCESS) goto done;
        a += n;
    }
done:
    sfb__free(g->ctx, rows);
    sfb__free(g->ctx, renum);
    sfb__gl_leave(g, &s);
    return res;
}

#endif /* SFB__GL_NORMALS_H */
