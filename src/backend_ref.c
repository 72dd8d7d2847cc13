/* The `ref` backend: plain C, the numeric oracle. Float storage, double accumulation in
 * table order (row by row, entries in stored order). */

static sfb_result sfb__ref_init(sfb_context *ctx, void **state, char *why, size_t why_size) {
    (void)ctx; (void)why; (void)why_size;
    *state = NULL;
    return SFB_SUCCESS;
}

static void sfb__ref_shutdown(sfb_context *ctx, void *state) { (void)ctx; (void)state; }

static sfb_result sfb__ref_eval_stencils(void *state, const sfb__stencils *t, void *handle, int first, int last,
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

/* in patches.c */
static sfb_result sfb__ref_eval_patches(void *state, const sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                        int last, const sfb_eval_output *out);

static const sfb__backend_vtable sfb__ref_vtable = {
    "ref", SFB_BACKEND_REF, SFB__CAP_EVAL_STENCILS | SFB__CAP_EVAL_PATCHES,
    sfb__ref_init, sfb__ref_shutdown, NULL, NULL, NULL, sfb__ref_eval_stencils, NULL,
    NULL, NULL, sfb__ref_eval_patches
};

const sfb__backend_vtable *sfb__backend_ref(void) { return &sfb__ref_vtable; }
