/* backends/simd/raster.h -- the simd backend's `raster` kernel: seed 003's proxy raster
 * (sfb_surface_analyze, src/analyze.c). Part of backends/simd/sfb_simd.h.
 *
 * ref's raster (sfb__raster_rows, in double, so the buffers are ref's bit for bit) over bands of
 * rows on the thread pool from SFB__SIMD_INLINE_RASTER pixels on: a pixel's triangles are
 * visited in order within its band, so the bands are independent. Each band skips the
 * triangles outside its rows before setting them up. Not vectorised: a proxy triangle covers a
 * couple of pixels at the default level, so the set-up, not the pixel loop, is the work. */
#define SFB__SIMD_INLINE_RASTER 65536

#ifdef SFB__SIMD_THREADS
static void sfb__simd_raster_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    (void)s;
    sfb__raster_rows((const sfb__raster_job *)arg, a, b);
}
#endif

static sfb_result sfb__simd_raster(void *state, const sfb__raster_job *job) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    if (!s || !job || job->w < 1 || job->h < 1 || job->ntri < 0) return SFB_INVALID_ARGS;
#ifdef SFB__SIMD_THREADS
    if ((double)job->w * job->h >= SFB__SIMD_INLINE_RASTER && sfb__simd_pool_run(s, sfb__simd_raster_task, job, 0, job->h, NULL, 0, 0))
        return SFB_SUCCESS;
#endif
    sfb__raster_rows(job, 0, job->h);
    return SFB_SUCCESS;
}

static void sfb__simd_raster_bind(sfb__backend_vtable *vt) { vt->raster = sfb__simd_raster; }
