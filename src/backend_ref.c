/* The `ref` backend: plain C, the numeric oracle. Float storage, double accumulation in
 * table order (row by row, entries in stored order). */

static sfb_result sfb__ref_init(sfb_context *ctx, void **state, char *why, size_t why_size) {
    (void)ctx; (void)why; (void)why_size;
    *state = NULL;
    return SFB_SUCCESS;
}

static void sfb__ref_shutdown(sfb_context *ctx, void *state) { (void)ctx; (void)state; }

sfb_result sfb__ref_eval_stencils(void *state, const sfb__stencils *t, void *handle, int first, int last,
                                         const float *src, sfb_buffer_desc sd, float *dst, sfb_buffer_desc dd) {
    int r, c, k;
    double acc[16];
    (void)state; (void)handle;
    if (sd.length != dd.length || sd.length <= 0 || sd.length > 16) return SFB_INVALID_ARGS;
    for (r = first; r < last; ++r) {
        const int *idx = t->indices + t->offsets[r];
        const float *w = t->weights + t->offsets[r];
        int n = t->sizes[r];
        float *out = dst + dd.offset + (size_t)r * dd.stride;
        for (c = 0; c < sd.length; ++c) acc[c] = 0.0;
        for (k = 0; k < n; ++k) {
            const float *in = src + sd.offset + (size_t)idx[k] * sd.stride;
            double wk = w[k];
            for (c = 0; c < sd.length; ++c) acc[c] += wk * in[c];
        }
        for (c = 0; c < sd.length; ++c) out[c] = (float)acc[c];
    }
    return SFB_SUCCESS;
}

/* Seed 001's blend N_B = normalize((1 - b^p) N_L + b^p N_S), in double (see the vtable). */
static void sfb__ref_unit3(double *v) {
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len > 0.0) { v[0] /= len; v[1] /= len; v[2] /= len; }
    else v[0] = v[1] = v[2] = 0.0;
}

sfb_result sfb__ref_finish_normals(void *state, int first, int last, const float *tu, const float *tv,
                                          const float *ns, const int *ns_index, const float *b, float p,
                                          float *out_blend, float *out_limit, float *out_sub) {
    int i, c;
    (void)state;
    for (i = first; i < last; ++i) {
        const float *a = tu + 3 * (size_t)i, *d = tv + 3 * (size_t)i;
        double L[3], S[3] = {0.0, 0.0, 0.0}, B[3];
        int k = ns_index ? ns_index[i] : -1;
        L[0] = (double)a[1] * d[2] - (double)a[2] * d[1];
        L[1] = (double)a[2] * d[0] - (double)a[0] * d[2];
        L[2] = (double)a[0] * d[1] - (double)a[1] * d[0];
        sfb__ref_unit3(L);
        if (k >= 0) {
            for (c = 0; c < 3; ++c) S[c] = ns[3 * (size_t)k + c];
            sfb__ref_unit3(S);
        }
        if (k >= 0 && b && b[i] > 0.0f) {
            double bp = pow((double)b[i], (double)p);
            for (c = 0; c < 3; ++c) B[c] = (1.0 - bp) * L[c] + bp * S[c];
            sfb__ref_unit3(B);
        } else {
            for (c = 0; c < 3; ++c) B[c] = L[c];
        }
        for (c = 0; c < 3; ++c) {
            out_blend[3 * (size_t)i + c] = (float)B[c];
            if (out_limit) out_limit[3 * (size_t)i + c] = (float)L[c];
            if (out_sub) out_sub[3 * (size_t)i + c] = (float)S[c];
        }
    }
    return SFB_SUCCESS;
}

/* Every kernel (sfb__ref_eval_patches is in patches.c). */
void sfb__ref_bind(sfb__backend_vtable *vt) {
    vt->name = "ref";
    vt->kind = SFB_BACKEND_REF;
    vt->init = sfb__ref_init;
    vt->shutdown = sfb__ref_shutdown;
    vt->eval_stencils = sfb__ref_eval_stencils;
    vt->eval_patches = sfb__ref_eval_patches;
    vt->finish_normals = sfb__ref_finish_normals;
}
