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

/* A finish_normals call's inputs and the rows it gathers (sfb__gl_normals_inputs). */
typedef struct sfb__gl_ncall {
    const float *tu, *tv, *ns, *b;
    const int *ns_index;
    int flags, last;
    size_t cap;           /* elements per batch */
    float *rows;          /* gathered rows and renumbered indices of a batch (when needed) */
    int *renum;
} sfb__gl_ncall;

/* Uploads and binds the inputs of elements [a, a + n) and returns (in *ns_base) the ns row the
 * batch's indices count from. Arrays the kernel does not read get tu's buffer: a binding must
 * name a buffer. */
static sfb_result sfb__gl_normals_inputs(sfb__gl *g, sfb__gl_ncall *c, int a, int n, int *ns_base) {
    int kmin = 0, kmax = -1, i;
    const int *index = c->ns_index ? c->ns_index + a : NULL;
    sfb_result res;
    for (i = 0; index && i < n; ++i) {
        const int k = index[i];
        if (k < 0) continue;
        if (kmax < 0 || k < kmin) kmin = k;
        if (k > kmax) kmax = k;
    }
    if ((res = sfb__gl_normals_input(g, 0, c->tu + 3 * (size_t)a, (size_t)n * 3 * sizeof(float))) != SFB_SUCCESS) return res;
    if ((res = sfb__gl_normals_input(g, 1, c->tv + 3 * (size_t)a, (size_t)n * 3 * sizeof(float))) != SFB_SUCCESS) return res;
    if (kmax >= 0 && ((size_t)kmax - (size_t)kmin + 1) * 3 * sizeof(float) <= (size_t)g->max_block) {
        res = sfb__gl_normals_input(g, 2, c->ns + 3 * (size_t)kmin, ((size_t)kmax - (size_t)kmin + 1) * 3 * sizeof(float));
        if (res != SFB_SUCCESS) return res;
    } else if (kmax >= 0) {
        int used = 0;
        if (!c->rows) { /* for the largest batch of this call */
            const size_t most = (size_t)(c->last - a) < c->cap ? (size_t)(c->last - a) : c->cap;
            c->rows = (float *)sfb__alloc(g->ctx, most * 3 * sizeof(float));
            c->renum = (int *)sfb__alloc(g->ctx, most * sizeof(int));
            if (!c->rows || !c->renum) return sfb__oom(g->ctx, "gl finish_normals");
        }
        for (i = 0; i < n; ++i) {
            const int k = index[i];
            c->renum[i] = k >= 0 ? used : -1;
            if (k >= 0) memcpy(c->rows + 3 * (size_t)used++, c->ns + 3 * (size_t)k, 3 * sizeof(float));
        }
        index = c->renum;
        kmin = 0;
        if ((res = sfb__gl_normals_input(g, 2, c->rows, (size_t)used * 3 * sizeof(float))) != SFB_SUCCESS) return res;
    } else {
        g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 2, g->normals_buf[0]);
    }
    if (c->flags & 1) {
        if ((res = sfb__gl_normals_input(g, 3, index, (size_t)n * sizeof(int))) != SFB_SUCCESS) return res;
    } else {
        g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 3, g->normals_buf[0]);
    }
    if (c->flags & 2) {
        if ((res = sfb__gl_normals_input(g, 4, c->b + a, (size_t)n * sizeof(float))) != SFB_SUCCESS) return res;
    } else {
        g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 4, g->normals_buf[0]);
    }
    *ns_base = kmax >= 0 ? kmin : 0;
    return SFB_SUCCESS;
}

/* Copies a batch's compact results, B (L, S) per element, into the caller's arrays. */
static void sfb__gl_normals_out(const float *mapped, int stride, int a, int n, float *out_blend, float *out_limit, float *out_sub) {
    int i;
    if (stride == 3) {
        memcpy(out_blend + 3 * (size_t)a, mapped, (size_t)n * 3 * sizeof(float));
        return;
    }
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
    sfb__gl_ncall c;
    sfb__gl_saved s;
    sfb__GLuint prog;
    sfb_result res;
    int a;
    if (!g || first < 0 || first > last) return SFB_INVALID_ARGS;
    if (first == last) return SFB_SUCCESS;
    if (!tu || !tv || !out_blend || (ns_index && !ns)) return SFB_INVALID_ARGS;
    memset(&c, 0, sizeof c);
    c.tu = tu; c.tv = tv; c.ns = ns; c.b = b; c.ns_index = ns_index; c.last = last;
    c.flags = (ns_index ? 1 : 0) | (ns_index && b ? 2 : 0);
    /* the results (>= 12 bytes per element) are the largest per-element buffer */
    c.cap = (size_t)g->max_block / ((size_t)stride * sizeof(float));
    if (c.cap < 1) c.cap = 1;
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    if ((res = sfb__gl_normals_program(g, &prog)) != SFB_SUCCESS) goto done;
    g->gl.UseProgram(prog);
    g->gl.Uniform1i(g->normals_loc[3], c.flags);
    g->gl.Uniform1i(g->normals_loc[4], stride);
    g->gl.Uniform1i(g->normals_loc[5], out_limit ? 3 : -1);
    g->gl.Uniform1i(g->normals_loc[6], out_sub ? (out_limit ? 6 : 3) : -1);
    g->gl.Uniform1f(g->normals_loc[7], p);
    for (a = first; a < last;) {
        const int n = (size_t)(last - a) > c.cap ? (int)c.cap : last - a;
        size_t rbytes = (size_t)n * (size_t)stride * sizeof(float);
        const float *mapped;
        int ns_base = 0;
        if ((res = sfb__gl_normals_inputs(g, &c, a, n, &ns_base)) != SFB_SUCCESS) goto done;
        if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, rbytes, SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS) goto done;
        g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 5, g->scratch_dst);
        g->gl.Uniform1i(g->normals_loc[2], ns_base);
        sfb__gl_dispatch_range(g, g->normals_loc[0], g->normals_loc[1], 0, n);
        if ((res = sfb__gl_check(g, "the normals kernel")) != SFB_SUCCESS) goto done;
        if ((res = sfb__gl_map_results(g, rbytes, &mapped)) != SFB_SUCCESS) goto done;
        sfb__gl_normals_out(mapped, stride, a, n, out_blend, out_limit, out_sub);
        if ((res = sfb__gl_unmap_results(g)) != SFB_SUCCESS) goto done;
        a += n;
    }
done:
    sfb__free(g->ctx, c.rows);
    sfb__free(g->ctx, c.renum);
    sfb__gl_leave(g, &s);
    return res;
}

/* The finish_normals slot. */
static void sfb__gl_normals_bind(sfb__backend_vtable *vt) {
    vt->finish_normals = sfb__gl_finish_normals;
}

#endif /* SFB__GL_NORMALS_H */
