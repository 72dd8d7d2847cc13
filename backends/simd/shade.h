/* backends/simd/shade.h -- the simd backend's analysis family: the `shade` kernel of seed 003's
 * per-pixel surface analysis (sfb_surface_analyze, src/analyze.c). Part of backends/simd/sfb_simd.h.
 *
 * The pixels are cut into equal chunks over the thread pool from SFB__SIMD_INLINE_SHADE pixels
 * on (smaller calls run on the caller's thread); each chunk runs ref's per-pixel mathematics
 * (sfb__ref_shade, in double), so the values are ref's bit for bit. Not vectorised: the
 * branches per mode (a ray that misses the light plane, the plane's extent, the curvature's
 * degenerate forms) dominate, and the analysis spends its time in eval_patches (the projection
 * onto the exact surface), which is vectorised (patches.h). */
#define SFB__SIMD_INLINE_SHADE 16384

#ifdef SFB__SIMD_THREADS
static void sfb__simd_shade_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    (void)s;
    sfb__ref_shade(NULL, (const sfb__shade_job *)arg, a, b);
}
#endif

static sfb_result sfb__simd_shade(void *state, const sfb__shade_job *job, int first, int last) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    if (!s || !job || first < 0 || first > last) return SFB_INVALID_ARGS;
#ifdef SFB__SIMD_THREADS
    if (last - first >= SFB__SIMD_INLINE_SHADE && sfb__simd_pool_run(s, sfb__simd_shade_task, job, first, last, NULL, 0, 0))
        return SFB_SUCCESS;
#endif
    return sfb__ref_shade(NULL, job, first, last);
}

static void sfb__simd_shade_bind(sfb__backend_vtable *vt) { vt->shade = sfb__simd_shade; }
