/* backends/gl/shade.h -- seed 003's per-pixel analysis values (the `shade` slot) in
 * shade.comp.glsl.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. The pixels go in batches whose every buffer fits one shader storage block (xyz per
 * pixel in, value and value2 out); arrays the mode does not read get the positions' buffer (a
 * binding must name a buffer). In float: the values agree with ref's (double) to float
 * rounding, which tests/analyze.c bounds. */
#ifndef SFB__GL_SHADE_H
#define SFB__GL_SHADE_H

static const char *const sfb__gl_shade_uniforms[14] = {"u_first", "u_last", "u_mode", "u_curvature", "u_ortho", "u_eye", "u_fwd",
                                                       "u_lc", "u_lm", "u_lu", "u_lv", "u_dir", "u_size_periods", NULL};

static sfb_result sfb__gl_shade_program(sfb__gl *g, sfb__GLuint *out) {
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->shade_program) { *out = g->shade_program; return SFB_SUCCESS; }
    if ((r = sfb__gl_compile(g, "", sfb__glsl_shade_comp_glsl, "shade.comp.glsl", &prog)) != SFB_SUCCESS) return r;
    for (i = 0; i < 13; ++i) g->shade_loc[i] = g->gl.GetUniformLocation(prog, sfb__gl_shade_uniforms[i]);
    g->shade_program = prog;
    *out = prog;
    return sfb__gl_check(g, "building the shade kernel");
}

static void sfb__gl_shade_vec3(sfb__gl *g, int loc, const double *v) {
    g->gl.Uniform3f(g->shade_loc[loc], (float)v[0], (float)v[1], (float)v[2]);
}

static sfb_result sfb__gl_shade(void *state, const sfb__shade_job *j, int first, int last) {
    sfb__gl *g = (sfb__gl *)state;
    const float *in[7];
    sfb__gl_saved s;
    sfb__GLuint prog;
    sfb_result res;
    size_t cap;
    int a, k;
    if (!g || !j || first < 0 || first > last) return SFB_INVALID_ARGS;
    if (first == last) return SFB_SUCCESS;
    in[0] = j->position; in[1] = j->normal;
    in[2] = j->du; in[3] = j->dv; in[4] = j->duu; in[5] = j->duv; in[6] = j->dvv;
    if (!in[0] || !in[1] || !j->value) return SFB_INVALID_ARGS;
    if (j->mode == SFB_ANALYZE_CURVATURE)
        for (k = 2; k < 7; ++k)
            if (!in[k]) return SFB_INVALID_ARGS;
    cap = (size_t)g->max_block / (3 * sizeof(float));
    if (cap < 1) cap = 1;
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    if ((res = sfb__gl_shade_program(g, &prog)) != SFB_SUCCESS) goto done;
    g->gl.UseProgram(prog);
    g->gl.Uniform1i(g->shade_loc[2], j->mode);
    g->gl.Uniform1i(g->shade_loc[3], j->curvature);
    g->gl.Uniform1i(g->shade_loc[4], j->ortho);
    sfb__gl_shade_vec3(g, 5, j->eye); sfb__gl_shade_vec3(g, 6, j->fwd); sfb__gl_shade_vec3(g, 7, j->lc);
    sfb__gl_shade_vec3(g, 8, j->lm); sfb__gl_shade_vec3(g, 9, j->lu); sfb__gl_shade_vec3(g, 10, j->lv);
    sfb__gl_shade_vec3(g, 11, j->dir);
    g->gl.Uniform4f(g->shade_loc[12], (float)j->lsize[0], (float)j->lsize[1], (float)j->periods[0], (float)j->periods[1]);
    for (a = first; a < last;) {
        const int n = (size_t)(last - a) > cap ? (int)cap : last - a;
        const size_t bytes = (size_t)n * 3 * sizeof(float);
        const float *mapped;
        int i;
        for (k = 0; k < 7; ++k) {
            if (k >= 2 && j->mode != SFB_ANALYZE_CURVATURE) {
                g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)k, g->shade_buf[0]);
                continue;
            }
            if ((res = sfb__gl_grow(g, &g->shade_buf[k], &g->shade_cap[k], bytes, SFB__GL_STREAM_DRAW)) != SFB_SUCCESS) goto done;
            g->gl.BufferSubData(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)bytes, in[k] + 3 * (size_t)a);
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)k, g->shade_buf[k]);
        }
        if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, (size_t)n * 2 * sizeof(float), SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS)
            goto done;
        g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 7, g->scratch_dst);
        sfb__gl_dispatch_range(g, g->shade_loc[0], g->shade_loc[1], 0, n);
        if ((res = sfb__gl_check(g, "the shade kernel")) != SFB_SUCCESS) goto done;
        if ((res = sfb__gl_map_results(g, (size_t)n * 2 * sizeof(float), &mapped)) != SFB_SUCCESS) goto done;
        for (i = 0; i < n; ++i) {
            j->value[a + i] = mapped[2 * i];
            if (j->value2) j->value2[a + i] = mapped[2 * i + 1];
        }
        if ((res = sfb__gl_unmap_results(g)) != SFB_SUCCESS) goto done;
        a += n;
    }
done:
    sfb__gl_leave(g, &s);
    return res;
}

/* The shade slot. */
static void sfb__gl_shade_bind(sfb__backend_vtable *vt) {
    vt->shade = sfb__gl_shade;
}

#endif /* SFB__GL_SHADE_H */
