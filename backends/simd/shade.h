/* backends/simd/shade.h -- the simd backend's analysis family: the `shade` kernel of seed 003's
 * per-pixel surface analysis (sfb_surface_analyze, src/analyze.c). Part of backends/simd/sfb_simd.h.
 *
 * The contract is sfb__shade_job's (src/sfb_internal.h); ref's kernel is sfb__ref_shade. Pixels
 * are taken in blocks of SFB__SIMD_SBLOCK, as normals.h does:
 *   1. a scalar pass gathers the block's positions and normals into double arrays (one per
 *      component);
 *   2. the vector pass, written once on the double lanes of sfb_simd.h's vector operations
 *      (2 lanes sse2 and AArch64 neon, 4 avx2, 8 avx512, 1 portable and 32-bit neon), runs
 *      ref's expressions in ref's order of operations -- the view direction normalised by a
 *      division, the normal turned toward the viewer by an exact negation, the reflected ray,
 *      and per mode the light-plane intersection with its tests (as selects to NaN), the zebra
 *      angle's cosine, or n.dir -- so the values are ref's bit for bit (no fused multiply-add:
 *      the operations are separate multiplies and adds);
 *   3. a scalar pass writes the values as floats; ZEBRA's arc cosine is taken there (libm's, as
 *      ref's).
 * CURVATURE runs ref's per-pixel code (its degenerate forms branch per pixel, and it is the
 * mode with the fewest pixels per second of evaluation: the second derivatives dominate).
 * The block is padded to a multiple of 8 lanes with copies of its first pixel: no partial
 * vectors, and nothing outside [first, last) is written. Threads: equal chunks of pixels over
 * the pool from SFB__SIMD_INLINE_SHADE pixels on (smaller calls run on the caller's thread). */
#define SFB__SIMD_INLINE_SHADE 16384
#define SFB__SIMD_SBLOCK 64

/* The arrays of a block, SFB__SIMD_SBLOCK doubles each: P, N in; the two values out. */
enum { SFB__SIMD_SPX, SFB__SIMD_SPY, SFB__SIMD_SPZ, SFB__SIMD_SNX, SFB__SIMD_SNY, SFB__SIMD_SNZ, SFB__SIMD_SV1, SFB__SIMD_SV2,
       SFB__SIMD_SARRAYS };

/* The vector pass over lanes [0, count) of a block (count a multiple of 8). */
typedef void (*sfb__simd_svec_fn)(const sfb__shade_job *j, double *blk, int count);

/* Pass 1: pixels [i0, i0 + n) into blk, lanes up to the next multiple of 8 padded. */
static void sfb__simd_shade_gather(const sfb__shade_job *j, int i0, int n, double *blk) {
    int m, c;
    for (m = 0; m < ((n + 7) & ~7); ++m) {
        const size_t i = (size_t)i0 + (size_t)(m < n ? m : 0);
        for (c = 0; c < 3; ++c) {
            blk[(SFB__SIMD_SPX + c) * SFB__SIMD_SBLOCK + m] = j->position[3 * i + (size_t)c];
            blk[(SFB__SIMD_SNX + c) * SFB__SIMD_SBLOCK + m] = j->normal[3 * i + (size_t)c];
        }
    }
}

/* Pass 3: the values of pixels [i0, i0 + n) out as floats (ZEBRA: its arc cosine here). */
static void sfb__simd_shade_scatter(const sfb__shade_job *j, int i0, int n, const double *blk) {
    int m;
    for (m = 0; m < n; ++m) {
        double v = blk[SFB__SIMD_SV1 * SFB__SIMD_SBLOCK + m];
        if (j->mode == SFB_ANALYZE_ZEBRA) {
            v = v < -1.0 ? -1.0 : v > 1.0 ? 1.0 : v;
            v = j->periods[0] * acos(v) / SFB__PI;
        }
        j->value[i0 + m] = (float)v;
        if (j->value2) j->value2[i0 + m] = (float)blk[SFB__SIMD_SV2 * SFB__SIMD_SBLOCK + m];
    }
}

/* Pass 2, written once on the double lanes of the vector operations (sfb_simd.h). A dot
 * product is ref's (a0 b0 + a1 b1) + a2 b2; `dir` of REFLECTION is the reflected ray, of
 * HIGHLIGHT the normal. */
#define SFB__SIMD_SDOT(X, ax, ay, az, bx, by, bz) X##_add(X##_add(X##_mul(ax, bx), X##_mul(ay, by)), X##_mul(az, bz))
#define SFB__SIMD_SHADE_DEFINE(X, ATTR)                                                                                  \
    ATTR static void X##_shade_vec(const sfb__shade_job *j, double *blk, int count) {                                    \
        const X##_v zero = X##_set1(0.0), minus = X##_set1(-1.0), two = X##_set1(2.0), nan = X##_set1(NAN);              \
        const X##_v eps = X##_set1(1e-9), big = X##_set1(1e7), nbig = X##_set1(-1e7), half = X##_set1(0.5);              \
        const X##_v lmx = X##_set1(j->lm[0]), lmy = X##_set1(j->lm[1]), lmz = X##_set1(j->lm[2]);                       \
        const X##_v dx = X##_set1(j->dir[0]), dy = X##_set1(j->dir[1]), dz = X##_set1(j->dir[2]);                        \
        const X##_v per0 = X##_set1(j->periods[0]), per1 = X##_set1(j->periods[1]);                                     \
        const int refl = j->mode == SFB_ANALYZE_REFLECTION, plane = refl || j->mode == SFB_ANALYZE_HIGHLIGHT;             \
        int m;                                                                                                           \
        for (m = 0; m < count; m += X##_W) {                                                                             \
            double *at = blk + m;                                                                                        \
            const X##_v px = X##_loadu(at + SFB__SIMD_SPX * SFB__SIMD_SBLOCK);                                           \
            const X##_v py = X##_loadu(at + SFB__SIMD_SPY * SFB__SIMD_SBLOCK);                                           \
            const X##_v pz = X##_loadu(at + SFB__SIMD_SPZ * SFB__SIMD_SBLOCK);                                           \
            X##_v nx = X##_loadu(at + SFB__SIMD_SNX * SFB__SIMD_SBLOCK);                                                 \
            X##_v ny = X##_loadu(at + SFB__SIMD_SNY * SFB__SIMD_SBLOCK);                                                 \
            X##_v nz = X##_loadu(at + SFB__SIMD_SNZ * SFB__SIMD_SBLOCK);                                                 \
            X##_v vx, vy, vz, vl, vn, rx, ry, rz, v1 = nan, v2 = nan;                                                    \
            X##_m pos, flip;                                                                                             \
            if (j->ortho) {                                                                                              \
                vx = X##_set1(-j->fwd[0]); vy = X##_set1(-j->fwd[1]); vz = X##_set1(-j->fwd[2]);                         \
            } else {                                                                                                     \
                vx = X##_sub(X##_set1(j->eye[0]), px); vy = X##_sub(X##_set1(j->eye[1]), py);                            \
                vz = X##_sub(X##_set1(j->eye[2]), pz);                                                                   \
            }                                                                                                            \
            vl = X##_sqrt(SFB__SIMD_SDOT(X, vx, vy, vz, vx, vy, vz));                                                    \
            pos = X##_gt(vl, zero);                                                                                      \
            vx = X##_sel(pos, X##_div(vx, vl), vx); vy = X##_sel(pos, X##_div(vy, vl), vy);                              \
            vz = X##_sel(pos, X##_div(vz, vl), vz);                                                                      \
            vn = SFB__SIMD_SDOT(X, vx, vy, vz, nx, ny, nz);                                                              \
            flip = X##_gt(zero, vn);                                                                                     \
            nx = X##_sel(flip, X##_mul(nx, minus), nx); ny = X##_sel(flip, X##_mul(ny, minus), ny);                      \
            nz = X##_sel(flip, X##_mul(nz, minus), nz); vn = X##_sel(flip, X##_mul(vn, minus), vn);                      \
            rx = X##_sub(X##_mul(X##_mul(two, vn), nx), vx); ry = X##_sub(X##_mul(X##_mul(two, vn), ny), vy);            \
            rz = X##_sub(X##_mul(X##_mul(two, vn), nz), vz);                                                             \
            if (plane) {                                                                                                 \
                const X##_v ex = refl ? rx : nx, ey = refl ? ry : ny, ez = refl ? rz : nz;                               \
                const X##_v dm = SFB__SIMD_SDOT(X, ex, ey, ez, lmx, lmy, lmz);                                            \
                const X##_v ax = X##_sub(X##_set1(j->lc[0]), px), ay = X##_sub(X##_set1(j->lc[1]), py);                  \
                const X##_v az = X##_sub(X##_set1(j->lc[2]), pz);                                                        \
                const X##_v mu = X##_div(SFB__SIMD_SDOT(X, ax, ay, az, lmx, lmy, lmz), dm);                              \
                const X##_v xx = X##_sub(X##_add(px, X##_mul(mu, ex)), X##_set1(j->lc[0]));                              \
                const X##_v xy = X##_sub(X##_add(py, X##_mul(mu, ey)), X##_set1(j->lc[1]));                              \
                const X##_v xz = X##_sub(X##_add(pz, X##_mul(mu, ez)), X##_set1(j->lc[2]));                              \
                X##_v a = X##_mul(X##_add(X##_div(SFB__SIMD_SDOT(X, xx, xy, xz, X##_set1(j->lu[0]), X##_set1(j->lu[1]),    \
                                                                 X##_set1(j->lu[2])), X##_set1(j->lsize[0])), half), per0); \
                X##_v b = X##_mul(X##_add(X##_div(SFB__SIMD_SDOT(X, xx, xy, xz, X##_set1(j->lv[0]), X##_set1(j->lv[1]),    \
                                                                 X##_set1(j->lv[2])), X##_set1(j->lsize[1])), half), per1); \
                /* |dm| > 1e-9, else missed */                                                                           \
                const X##_m hit = X##_gt(dm, eps), hitn = X##_gt(X##_mul(dm, minus), eps);                              \
                a = X##_sel(hit, a, X##_sel(hitn, a, nan));                                                              \
                if (refl) {                                                                                              \
                    /* mu > 0, and X within the plane's extent */                                                        \
                    a = X##_sel(X##_gt(mu, zero), a, nan);                                                               \
                    a = X##_sel(X##_gt(zero, a), nan, X##_sel(X##_gt(a, per0), nan, a));                                 \
                    a = X##_sel(X##_gt(zero, b), nan, X##_sel(X##_gt(b, per1), nan, a));                                 \
                }                                                                                                        \
                /* finite and under 1e7 in size (a NaN fails every comparison) */                                        \
                a = X##_sel(X##_gt(a, nbig), X##_sel(X##_gt(big, a), a, nan), nan);                                      \
                a = X##_sel(X##_gt(b, nbig), X##_sel(X##_gt(big, b), a, nan), nan);                                      \
                v2 = X##_sel(X##_gt(a, nbig), b, nan); /* a NaN here: both missed */                                     \
                v1 = a;                                                                                                  \
            } else if (j->mode == SFB_ANALYZE_ZEBRA) {                                                                   \
                v1 = SFB__SIMD_SDOT(X, rx, ry, rz, dx, dy, dz);                                                          \
            } else {                                                                                                     \
                v1 = SFB__SIMD_SDOT(X, nx, ny, nz, dx, dy, dz);                                                          \
            }                                                                                                            \
            X##_storeu(at + SFB__SIMD_SV1 * SFB__SIMD_SBLOCK, v1);                                                       \
            X##_storeu(at + SFB__SIMD_SV2 * SFB__SIMD_SBLOCK, v2);                                                       \
        }                                                                                                                \
    }

/* portable (and 32-bit neon): one double per step; sse2 and AArch64 neon 2, avx2 4, avx512 8 */
SFB__SIMD_SHADE_DEFINE(sfb__vpd, )
#ifdef SFB__SIMD_SSE2
SFB__SIMD_SHADE_DEFINE(sfb__vsd, )
#endif
#ifdef SFB__SIMD_X86_DISPATCH
SFB__SIMD_SHADE_DEFINE(sfb__vad, SFB__SIMD_TARGET_AVX2)
SFB__SIMD_SHADE_DEFINE(sfb__vzd, SFB__SIMD_TARGET_AVX512)
#endif
#ifdef SFB__SIMD_VN
SFB__SIMD_SHADE_DEFINE(sfb__vnd, )
#endif
#undef SFB__SIMD_SHADE_DEFINE
#undef SFB__SIMD_SDOT

/* The vector pass of the state's instruction set. */
static sfb__simd_svec_fn sfb__simd_shade_select(int isa) {
    switch (isa) {
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: return sfb__vsd_shade_vec;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2: return sfb__vad_shade_vec;
    case SFB__SIMD_AVX512: return sfb__vzd_shade_vec;
#endif
#ifdef SFB__SIMD_VN
    case SFB__SIMD_ISA_NEON: return sfb__vnd_shade_vec;
#endif
    default: return sfb__vpd_shade_vec;
    }
}

/* Pixels [first, last) of the job with vector pass `vec` (CURVATURE: ref's code). */
static void sfb__simd_shade_range(const sfb__shade_job *j, int first, int last, sfb__simd_svec_fn vec) {
    double blk[SFB__SIMD_SARRAYS * SFB__SIMD_SBLOCK];
    int i0;
    if (j->mode == SFB_ANALYZE_CURVATURE) {
        sfb__ref_shade(NULL, j, first, last);
        return;
    }
    for (i0 = first; i0 < last; i0 += SFB__SIMD_SBLOCK) {
        const int n = last - i0 < SFB__SIMD_SBLOCK ? last - i0 : SFB__SIMD_SBLOCK;
        sfb__simd_shade_gather(j, i0, n, blk);
        vec(j, blk, (n + 7) & ~7);
        sfb__simd_shade_scatter(j, i0, n, blk);
    }
}

#ifdef SFB__SIMD_THREADS
static void sfb__simd_shade_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    sfb__simd_shade_range((const sfb__shade_job *)arg, a, b, sfb__simd_shade_select(s->isa));
}
#endif

static sfb_result sfb__simd_shade(void *state, const sfb__shade_job *job, int first, int last) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    if (!s || !job || first < 0 || first > last) return SFB_INVALID_ARGS;
    if (first == last) return SFB_SUCCESS;
#ifdef SFB__SIMD_THREADS
    if (last - first >= SFB__SIMD_INLINE_SHADE && sfb__simd_pool_run(s, sfb__simd_shade_task, job, first, last, NULL, 0, 0))
        return SFB_SUCCESS;
#endif
    sfb__simd_shade_range(job, first, last, sfb__simd_shade_select(s->isa));
    return SFB_SUCCESS;
}

static void sfb__simd_shade_bind(sfb__backend_vtable *vt) { vt->shade = sfb__simd_shade; }
