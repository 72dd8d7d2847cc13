/* backends/simd/patches_tri.h -- the triangle family of backends/simd/patches.h (BEZTRI15,
 * STAM_LOOP; ENDCAP_TRI runs the ref kernel): locating, the Stam-Loop locations beyond the
 * packed levels, the quartic Bezier triangle kernels per instruction set (in double), and
 * packing the triangles. Layout and numerics: patches.h. */

/* A Stam-Loop location nearer the EV than the packed levels: ref's own evaluation
 * (sfb__eval_stam_loop, only the outputs asked for), finished as sfb__simd_stam_far. */
static void sfb__simd_loop_far(const sfb__simd_pjob *j, int q) {
    const sfb__patch_table *pt = j->pt;
    const sfb_location *l = &j->locs[q];
    double s, t, sc, res[6][3], nres[2][3];
    const sfb__eigen_loop *e;
    const int p = sfb__patch_locate(pt, l->face, l->u, l->v, &s, &t, &sc);
    if (p < 0 || pt->ptype[p] != SFB__PATCH_STAM_LOOP || !(e = pt->eigl[pt->pvalence[p]]) || e->K > SFB__STAM_MAX_VALENCE + 6) {
        sfb__simd_ref_one(j, q);
        return;
    }
    sfb__eval_stam_loop(e, pt->point_data, pt->cv + pt->pfirst[p], SFB__PARAM_CORNER(pt->pparam[p]), s, t, j->second ? 6 : 3, res, nres);
    sfb__simd_far_finish(j, q, sc, res, nres);
}

/* prep for a Loop table: the triangle descent of sfb__patch_locate, in double with ref's very
 * operations (so the patch, (s, t) and the Stam-Loop level and sub-patch are ref's), without
 * branches on the child (random here): child c's (u, v) is sg (2u - a_u, 2v - a_v) with
 * sg = -1 for the middle child, whose 1 - 2u is -(2u - 1) exactly. sg is 1 - 2 c3 converted,
 * not `c3 ? -1.0 : 1.0`, which GCC made a branch: mispredicted for a quarter of the locations
 * at every level, it cost 3.5 ns a location of the 1 M random ones on the bench's torus. */
static SFB__SIMD_FORCEINLINE void sfb__simd_prep_tri(const sfb__simd_pjob *j, int q, sfb__simd_slot *o) {
    const sfb__simd_patches *h = j->h;
    const sfb_location *l = &j->locs[q];
    int node = h->root[l->face], code;
    double s = l->u, t = l->v, sc = 1.0;
    while (node >= 0) {
        const int c1 = s >= 0.5, c2 = !c1 & (t >= 0.5), c3 = !c1 & !c2 & !(s + t < 0.5);
        const double sg = (double)(1 - 2 * c3);
        s = (s + s - (double)(c1 | c3)) * sg;
        t = (t + t - (double)(c2 | c3)) * sg;
        sc = (sc + sc) * sg;
        node = h->node[4 * node + (c1 | 2 * c2 | 3 * c3)];
    }
    code = -node - 1;
    o->run = SFB__SIMD_RUN_REF;
    if ((code & 3) == SFB__SIMD_LEAF_TRI) {
        o->blk = h->blk + 4 * (size_t)(code >> 4);
        o->s = (float)s; o->t = (float)t; o->dsc = (float)sc; o->cs = 10; o->rot = 0;
        o->run = SFB__SIMD_RUN_TRI;
        SFB__SIMD_PREFETCH(o->blk);
        SFB__SIMD_PREFETCH(o->blk + 16);
        SFB__SIMD_PREFETCH(o->blk + 32);
    } else if ((code & 3) == SFB__SIMD_LEAF_STAM) {
        /* ref's frame turn ((1 - s) - t written as 1 + (-1) s + (-1) t, exactly the same), its
         * level n (n - 1 doublings bring u + v to [1/2, 1]: read off the exponent of u + v,
         * which doubling scales exactly) and sub-patch k (0: u >= 1/2, 1: v >= 1/2, 2: the
         * middle, turned). The corner is 0..2 (upload checks). */
        static const double frame[3][6] = {{0, 1, 0, 0, 0, 1}, {0, 0, 1, 1, -1, -1}, {1, -1, -1, 0, 1, 0}};
        const int corner = (code >> 2) & 3;
        const double *f = frame[corner];
        double u = (f[0] + f[1] * s) + f[2] * t, v = (f[3] + f[4] * s) + f[5] * t, sum, sg, lv;
        uint64_t bits;
        int n, c0, c1, c2;
        if (u < 0.0) u = 0.0;
        if (v < 0.0) v = 0.0;
        sum = u + v;
        if (!(sum >= 1.0 / (double)(1 << SFB__SIMD_LOOP_LEVELS))) {
            if (sum > 0.0) o->run = SFB__SIMD_RUN_LOOP_FAR; /* else the EV itself: ref */
            return;
        }
        memcpy(&bits, &sum, sizeof bits);
        n = 1022 - (int)((bits >> 52) & 0x7FF); /* sum in [1/2, 1): 0 doublings; [1/4, 1/2): 1 ... */
        if (n < 0) n = 0;
        lv = (double)(1 << n);
        u *= lv;
        v *= lv;
        ++n;
        c0 = u >= 0.5;
        c1 = !c0 & (v >= 0.5);
        c2 = !c0 & !c1;
        sg = (double)(1 - 2 * c2);
        o->s = (float)((u + u - (double)(c0 | c2)) * sg);
        o->t = (float)((v + v - (double)(c1 | c2)) * sg);
        o->blk = h->blk + 4 * (size_t)(code >> 4) + (size_t)(n - 1) * 3 * SFB__SIMD_TRI_FLOATS + (size_t)(c1 + 2 * c2) * SFB__SIMD_TRI_FLOATS;
        o->dsc = (float)(sc * sg * lv * 2.0);
        o->cs = 10;
        o->rot = corner ? corner + 3 : 0;
        o->run = SFB__SIMD_RUN_TRI;
        SFB__SIMD_PREFETCH(o->blk);
        SFB__SIMD_PREFETCH(o->blk + 16);
        SFB__SIMD_PREFETCH(o->blk + 32);
    }
}

/* Quartic Bezier triangle at (s, t) (a triangle of the layout in patches.h), in double: de Casteljau
 * steps on the points (convex combinations, weights w = 1 - s - t, s, t of the points (i, j),
 * (i + 1, j), (i, j + 1) of the row layout, in place) from degree 4 down: at degree 2 the
 * second derivatives are 12 x second differences, at degree 1 the first derivatives
 * 4 x differences, at degree 0 the point, to which the origin is added. The step lists
 * SFB__SIMD_DC4/3/2(X), X(to, from, above), are shared by every triangle kernel. */
#define SFB__SIMD_DC4(X) X(0, 0, 5) X(1, 1, 6) X(2, 2, 7) X(3, 3, 8) X(4, 5, 9) X(5, 6, 10) X(6, 7, 11) X(7, 9, 12) X(8, 10, 13) X(9, 12, 14)
#define SFB__SIMD_DC3(X) X(0, 0, 4) X(1, 1, 5) X(2, 2, 6) X(3, 4, 7) X(4, 5, 8) X(5, 7, 9)
#define SFB__SIMD_DC2(X) X(0, 0, 3) X(1, 1, 4) X(2, 3, 5)
static float sfb__simd_tri_portable(const float *blk, float s, float t, int second, float r[6][4]) {
    const double w = (1.0 - s) - t;
    double p[15][3];
    int a, c;
    for (c = 0; c < 3; ++c) p[0][c] = 0.0;
    for (a = 1; a < 15; ++a)
        for (c = 0; c < 3; ++c) p[a][c] = blk[3 * (a - 1) + c];
    for (a = 0; a < 6; ++a) r[a][3] = 0.0f;
    for (c = 0; c < 3; ++c) {
#define SFB__SIMD_DC_SCALAR(to, from, above) p[to][c] = t * p[above][c] + (s * p[(from) + 1][c] + w * p[from][c]);
        SFB__SIMD_DC4(SFB__SIMD_DC_SCALAR)
        SFB__SIMD_DC3(SFB__SIMD_DC_SCALAR)
        if (second) {
            r[3][c] = (float)(12.0 * ((p[2][c] - p[1][c]) - (p[1][c] - p[0][c])));
            r[4][c] = (float)(12.0 * ((p[4][c] - p[3][c]) - (p[1][c] - p[0][c])));
            r[5][c] = (float)(12.0 * ((p[5][c] - p[3][c]) - (p[3][c] - p[0][c])));
        } else {
            r[3][c] = r[4][c] = r[5][c] = 0.0f;
        }
        SFB__SIMD_DC2(SFB__SIMD_DC_SCALAR)
#undef SFB__SIMD_DC_SCALAR
        r[1][c] = (float)(4.0 * (p[1][c] - p[0][c]));
        r[2][c] = (float)(4.0 * (p[2][c] - p[0][c]));
        r[0][c] = (float)((t * p[2][c] + (s * p[1][c] + w * p[0][c])) + blk[SFB__SIMD_TRI_ORIGIN + c]);
    }
    return 1.0f;
}

#ifdef SFB__SIMD_SSE2
/* The quartic triangle kernel (see sfb__simd_tri_portable) in double, each point as two
 * registers (xy, zw); the signature of the window kernels (cs unused). */
static SFB__SIMD_FORCEINLINE void sfb__simd_sse2_tri(const float *blk, int cs, float s, float t, int second, __m128 r[6]) {
    const double sd = s, td = t;
    const __m128d vs = _mm_set1_pd(sd), vt = _mm_set1_pd(td), vw = _mm_set1_pd((1.0 - sd) - td);
    __m128d pl[15], ph[15];
    int a;
    (void)cs;
    pl[0] = ph[0] = _mm_setzero_pd();
    for (a = 1; a < 15; ++a) {
        const __m128 v = _mm_loadu_ps(blk + 3 * (a - 1));
        pl[a] = _mm_cvtps_pd(v);
        ph[a] = _mm_cvtps_pd(_mm_movehl_ps(v, v));
    }
#define SFB__SIMD_DC_SSE2(to, from, above)                                                                          \
    pl[to] = _mm_add_pd(_mm_mul_pd(vt, pl[above]), _mm_add_pd(_mm_mul_pd(vs, pl[(from) + 1]), _mm_mul_pd(vw, pl[from]))); \
    ph[to] = _mm_add_pd(_mm_mul_pd(vt, ph[above]), _mm_add_pd(_mm_mul_pd(vs, ph[(from) + 1]), _mm_mul_pd(vw, ph[from])));
#define SFB__SIMD_PS2(lo, hi) _mm_movelh_ps(_mm_cvtpd_ps(lo), _mm_cvtpd_ps(hi))
    SFB__SIMD_DC4(SFB__SIMD_DC_SSE2)
    SFB__SIMD_DC3(SFB__SIMD_DC_SSE2)
    if (second) {
        const __m128d twelve = _mm_set1_pd(12.0);
#define SFB__SIMD_D2_SSE2(x, y, z, w) _mm_mul_pd(twelve, _mm_sub_pd(_mm_sub_pd(x, y), _mm_sub_pd(z, w)))
        r[3] = SFB__SIMD_PS2(SFB__SIMD_D2_SSE2(pl[2], pl[1], pl[1], pl[0]), SFB__SIMD_D2_SSE2(ph[2], ph[1], ph[1], ph[0]));
        r[4] = SFB__SIMD_PS2(SFB__SIMD_D2_SSE2(pl[4], pl[3], pl[1], pl[0]), SFB__SIMD_D2_SSE2(ph[4], ph[3], ph[1], ph[0]));
        r[5] = SFB__SIMD_PS2(SFB__SIMD_D2_SSE2(pl[5], pl[3], pl[3], pl[0]), SFB__SIMD_D2_SSE2(ph[5], ph[3], ph[3], ph[0]));
#undef SFB__SIMD_D2_SSE2
    } else {
        r[3] = r[4] = r[5] = _mm_setzero_ps();
    }
    SFB__SIMD_DC2(SFB__SIMD_DC_SSE2)
    {
        const __m128d four = _mm_set1_pd(4.0);
        const __m128 o = _mm_loadu_ps(blk + SFB__SIMD_TRI_ORIGIN);
        r[1] = SFB__SIMD_PS2(_mm_mul_pd(four, _mm_sub_pd(pl[1], pl[0])), _mm_mul_pd(four, _mm_sub_pd(ph[1], ph[0])));
        r[2] = SFB__SIMD_PS2(_mm_mul_pd(four, _mm_sub_pd(pl[2], pl[0])), _mm_mul_pd(four, _mm_sub_pd(ph[2], ph[0])));
        r[0] = SFB__SIMD_PS2(_mm_add_pd(_mm_add_pd(_mm_mul_pd(vt, pl[2]), _mm_add_pd(_mm_mul_pd(vs, pl[1]), _mm_mul_pd(vw, pl[0]))), _mm_cvtps_pd(o)),
                             _mm_add_pd(_mm_add_pd(_mm_mul_pd(vt, ph[2]), _mm_add_pd(_mm_mul_pd(vs, ph[1]), _mm_mul_pd(vw, ph[0]))),
                                        _mm_cvtps_pd(_mm_movehl_ps(o, o))));
    }
#undef SFB__SIMD_DC_SSE2
#undef SFB__SIMD_PS2
}

/* sse2 has no pair kernel (the range loop's PAIR is 0 there, so this is never called). */
static SFB__SIMD_FORCEINLINE void sfb__simd_sse2_tri2_none(const float *b0, float s0, float t0, const float *b1, float s1, float t1, __m128 r0[6],
                                                           __m128 r1[6]) {
    (void)b0; (void)s0; (void)t0; (void)b1; (void)s1; (void)t1; (void)r0; (void)r1;
}
#endif /* SFB__SIMD_SSE2 */

#ifdef SFB__SIMD_X86_DISPATCH
/* The quartic triangle kernel (see sfb__simd_tri_portable) in double, one point (xyzw) per
 * 256-bit register: as many instructions as in float. Shared with avx512. */
#define SFB__SIMD_TRI_PD(NAME, ATTR)                                                                                 \
    ATTR static SFB__SIMD_FORCEINLINE void NAME(const float *blk, int cs, float s, float t, int second, __m128 r[6]) { \
        const double sd = s, td = t;                                                                                 \
        const __m256d vs = _mm256_set1_pd(sd), vt = _mm256_set1_pd(td), vw = _mm256_set1_pd((1.0 - sd) - td);      \
        __m256d p[15];                                                                                               \
        int a;                                                                                                       \
        (void)cs;                                                                                                    \
        p[0] = _mm256_setzero_pd();                                                                                  \
        for (a = 1; a < 15; ++a) p[a] = _mm256_cvtps_pd(_mm_loadu_ps(blk + 3 * (a - 1)));                            \
        SFB__SIMD_DC4(SFB__SIMD_DC_PD)                                                                               \
        SFB__SIMD_DC3(SFB__SIMD_DC_PD)                                                                               \
        if (second) {                                                                                                \
            const __m256d twelve = _mm256_set1_pd(12.0), d10 = _mm256_sub_pd(p[1], p[0]), d30 = _mm256_sub_pd(p[3], p[0]); \
            r[3] = _mm256_cvtpd_ps(_mm256_mul_pd(twelve, _mm256_sub_pd(_mm256_sub_pd(p[2], p[1]), d10)));            \
            r[4] = _mm256_cvtpd_ps(_mm256_mul_pd(twelve, _mm256_sub_pd(_mm256_sub_pd(p[4], p[3]), d10)));            \
            r[5] = _mm256_cvtpd_ps(_mm256_mul_pd(twelve, _mm256_sub_pd(_mm256_sub_pd(p[5], p[3]), d30)));            \
        } else {                                                                                                     \
            r[3] = r[4] = r[5] = _mm_setzero_ps();                                                                   \
        }                                                                                                            \
        SFB__SIMD_DC2(SFB__SIMD_DC_PD)                                                                               \
        r[1] = _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_set1_pd(4.0), _mm256_sub_pd(p[1], p[0])));                      \
        r[2] = _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_set1_pd(4.0), _mm256_sub_pd(p[2], p[0])));                      \
        r[0] = _mm256_cvtpd_ps(_mm256_add_pd(_mm256_fmadd_pd(vt, p[2], _mm256_fmadd_pd(vs, p[1], _mm256_mul_pd(vw, p[0]))), \
                                             _mm256_cvtps_pd(_mm_loadu_ps(blk + SFB__SIMD_TRI_ORIGIN))));                              \
    }
#define SFB__SIMD_DC_PD(to, from, above) p[to] = _mm256_fmadd_pd(vt, p[above], _mm256_fmadd_pd(vs, p[(from) + 1], _mm256_mul_pd(vw, p[from])));
SFB__SIMD_TRI_PD(sfb__simd_avx2_tri, SFB__SIMD_TARGET_AVX2)
SFB__SIMD_TRI_PD(sfb__simd_avx512_tri, SFB__SIMD_TARGET_AVX512)

/* Two locations' quartic triangles at once, position and first derivatives only, in float: the
 * two points (i, j) as one 256-bit register (xyzw of b0, xyzw of b1), the same de Casteljau steps
 * as sfb__simd_tri_portable. Half the instructions of two calls of the double kernel: 1 M random
 * locations (position, du, dv; one thread, avx512 on an AMD EPYC) took 21 instead of 23 ns each
 * on the bench's torus, and 12.8 instead of 15.5 on tribezier_crease_v5.obj, whose patches stay
 * in cache (spot.obj, 17 MB of patches, is bound by memory at 37 ns either way).
 * Its error: the points are float already (2^-24 E each, E as in patches.h), and each of the
 * three steps down to degree 1 adds up to about one rounding of E, so the tangents
 * (4 x differences) carry up to ~4 times the double kernel's error: the normal's float-trust
 * test weighs this kernel's E by SFB__SIMD_TRI2_EFACTOR (16 E in all). Measured against ref on
 * spot, cow, teapot and the bench's torus (tribezier, 300,000 random locations each): positions
 * within 5e-8 x diagonal, about one rounding of the coordinates (double kernel 4e-9), du and
 * dv within 9e-7 of their length (3e-7), normals within 3.1e-6 rad (4.6e-7). Second
 * derivatives, which would lose too much in float (12 x second differences, times 4^depth),
 * stay with the double kernel. */
#define SFB__SIMD_TRI2_PS(NAME, ATTR)                                                                                \
    ATTR static SFB__SIMD_FORCEINLINE void NAME(const float *b0, float s0, float t0, const float *b1, float s1, float t1, \
                                               __m128 r0[6], __m128 r1[6]) {                                        \
        const __m256 vs = _mm256_insertf128_ps(_mm256_set1_ps(s0), _mm_set1_ps(s1), 1);                            \
        const __m256 vt = _mm256_insertf128_ps(_mm256_set1_ps(t0), _mm_set1_ps(t1), 1);                            \
        const __m256 vw = _mm256_insertf128_ps(_mm256_set1_ps((float)((1.0 - s0) - t0)), _mm_set1_ps((float)((1.0 - s1) - t1)), 1); \
        __m256 p[15], x;                                                                                             \
        int a;                                                                                                       \
        p[0] = _mm256_setzero_ps();                                                                                  \
        for (a = 1; a < 15; ++a) p[a] = SFB__SIMD_LD2(b0 + 3 * (a - 1), b1 + 3 * (a - 1));                           \
        SFB__SIMD_DC4(SFB__SIMD_DC_PS)                                                                               \
        SFB__SIMD_DC3(SFB__SIMD_DC_PS)                                                                               \
        SFB__SIMD_DC2(SFB__SIMD_DC_PS)                                                                               \
        x = _mm256_add_ps(_mm256_fmadd_ps(vt, p[2], _mm256_fmadd_ps(vs, p[1], _mm256_mul_ps(vw, p[0]))),           \
                          SFB__SIMD_LD2(b0 + SFB__SIMD_TRI_ORIGIN, b1 + SFB__SIMD_TRI_ORIGIN));                     \
        r0[0] = _mm256_castps256_ps128(x);                                                                           \
        r1[0] = _mm256_extractf128_ps(x, 1);                                                                         \
        x = _mm256_mul_ps(_mm256_set1_ps(4.0f), _mm256_sub_ps(p[1], p[0]));                                          \
        r0[1] = _mm256_castps256_ps128(x);                                                                           \
        r1[1] = _mm256_extractf128_ps(x, 1);                                                                         \
        x = _mm256_mul_ps(_mm256_set1_ps(4.0f), _mm256_sub_ps(p[2], p[0]));                                          \
        r0[2] = _mm256_castps256_ps128(x);                                                                           \
        r1[2] = _mm256_extractf128_ps(x, 1);                                                                         \
        r0[3] = r0[4] = r0[5] = r1[3] = r1[4] = r1[5] = _mm_setzero_ps();                                            \
    }
#define SFB__SIMD_LD2(a, b) _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(a)), _mm_loadu_ps(b), 1)
#define SFB__SIMD_DC_PS(to, from, above) p[to] = _mm256_fmadd_ps(vt, p[above], _mm256_fmadd_ps(vs, p[(from) + 1], _mm256_mul_ps(vw, p[from])));
SFB__SIMD_TRI2_PS(sfb__simd_avx2_tri2, SFB__SIMD_TARGET_AVX2)
SFB__SIMD_TRI2_PS(sfb__simd_avx512_tri2, SFB__SIMD_TARGET_AVX512)
#endif /* SFB__SIMD_X86_DISPATCH */

#ifdef SFB__SIMD_NEON
#if defined(__aarch64__)
#define SFB__SIMD_TRI_NEON 1
/* The quartic triangle kernel (see sfb__simd_tri_portable). Without second derivatives in float,
 * one point (xyzw) per register: the steps of the x86 float pair kernel (sfb__simd_avx2_tri2,
 * the same fused operations in the same order, so its lanes' bits), half the instructions of the
 * double kernel, and its error (the normal's float-trust test weighs E by
 * SFB__SIMD_TRI2_EFACTOR, returned); with them in double, each point as two registers (xy, zw),
 * as second derivatives need. (32-bit ARM, without double vectors, runs the portable one.) */
static float sfb__simd_tri_neon(const float *blk, float s, float t, int second, float r[6][4]) {
    const double sd = s, td = t;
    const float64x2_t vs = vdupq_n_f64(sd), vt = vdupq_n_f64(td), vw = vdupq_n_f64((1.0 - sd) - td);
    float64x2_t pl[15], ph[15];
    int a;
    if (!second) {
        const float32x4_t fs = vdupq_n_f32(s), ft = vdupq_n_f32(t), fw = vdupq_n_f32((float)((1.0 - sd) - td));
        float32x4_t p[15];
        p[0] = vdupq_n_f32(0.0f);
        for (a = 1; a < 15; ++a) p[a] = vld1q_f32(blk + 3 * (a - 1));
#define SFB__SIMD_DC_NEON_F32(to, from, above) p[to] = vfmaq_f32(vfmaq_f32(vmulq_f32(fw, p[from]), fs, p[(from) + 1]), ft, p[above]);
        SFB__SIMD_DC4(SFB__SIMD_DC_NEON_F32)
        SFB__SIMD_DC3(SFB__SIMD_DC_NEON_F32)
        SFB__SIMD_DC2(SFB__SIMD_DC_NEON_F32)
#undef SFB__SIMD_DC_NEON_F32
        vst1q_f32(r[0], vaddq_f32(vfmaq_f32(vfmaq_f32(vmulq_f32(fw, p[0]), fs, p[1]), ft, p[2]), vld1q_f32(blk + SFB__SIMD_TRI_ORIGIN)));
        vst1q_f32(r[1], vmulq_n_f32(vsubq_f32(p[1], p[0]), 4.0f));
        vst1q_f32(r[2], vmulq_n_f32(vsubq_f32(p[2], p[0]), 4.0f));
        vst1q_f32(r[3], vdupq_n_f32(0.0f)); vst1q_f32(r[4], vdupq_n_f32(0.0f)); vst1q_f32(r[5], vdupq_n_f32(0.0f));
        return SFB__SIMD_TRI2_EFACTOR;
    }
    pl[0] = ph[0] = vdupq_n_f64(0.0);
    for (a = 1; a < 15; ++a) {
        const float32x4_t v = vld1q_f32(blk + 3 * (a - 1));
        pl[a] = vcvt_f64_f32(vget_low_f32(v));
        ph[a] = vcvt_high_f64_f32(v);
    }
#define SFB__SIMD_DC_NEON(to, from, above)                                        \
    pl[to] = vfmaq_f64(vfmaq_f64(vmulq_f64(vw, pl[from]), vs, pl[(from) + 1]), vt, pl[above]); \
    ph[to] = vfmaq_f64(vfmaq_f64(vmulq_f64(vw, ph[from]), vs, ph[(from) + 1]), vt, ph[above]);
#define SFB__SIMD_ST2(dst, lo, hi) vst1q_f32(dst, vcvt_high_f32_f64(vcvt_f32_f64(lo), hi))
    SFB__SIMD_DC4(SFB__SIMD_DC_NEON)
    SFB__SIMD_DC3(SFB__SIMD_DC_NEON)
    if (second) {
#define SFB__SIMD_D2_NEON(x, y, z, w) vmulq_n_f64(vsubq_f64(vsubq_f64(x, y), vsubq_f64(z, w)), 12.0)
        SFB__SIMD_ST2(r[3], SFB__SIMD_D2_NEON(pl[2], pl[1], pl[1], pl[0]), SFB__SIMD_D2_NEON(ph[2], ph[1], ph[1], ph[0]));
        SFB__SIMD_ST2(r[4], SFB__SIMD_D2_NEON(pl[4], pl[3], pl[1], pl[0]), SFB__SIMD_D2_NEON(ph[4], ph[3], ph[1], ph[0]));
        SFB__SIMD_ST2(r[5], SFB__SIMD_D2_NEON(pl[5], pl[3], pl[3], pl[0]), SFB__SIMD_D2_NEON(ph[5], ph[3], ph[3], ph[0]));
#undef SFB__SIMD_D2_NEON
    } else {
        vst1q_f32(r[3], vdupq_n_f32(0.0f)); vst1q_f32(r[4], vdupq_n_f32(0.0f)); vst1q_f32(r[5], vdupq_n_f32(0.0f));
    }
    SFB__SIMD_DC2(SFB__SIMD_DC_NEON)
    {
        const float32x4_t o = vld1q_f32(blk + SFB__SIMD_TRI_ORIGIN);
        SFB__SIMD_ST2(r[1], vmulq_n_f64(vsubq_f64(pl[1], pl[0]), 4.0), vmulq_n_f64(vsubq_f64(ph[1], ph[0]), 4.0));
        SFB__SIMD_ST2(r[2], vmulq_n_f64(vsubq_f64(pl[2], pl[0]), 4.0), vmulq_n_f64(vsubq_f64(ph[2], ph[0]), 4.0));
        SFB__SIMD_ST2(r[0], vaddq_f64(vfmaq_f64(vfmaq_f64(vmulq_f64(vw, pl[0]), vs, pl[1]), vt, pl[2]), vcvt_f64_f32(vget_low_f32(o))),
                      vaddq_f64(vfmaq_f64(vfmaq_f64(vmulq_f64(vw, ph[0]), vs, ph[1]), vt, ph[2]), vcvt_high_f64_f32(o)));
    }
#undef SFB__SIMD_DC_NEON
#undef SFB__SIMD_ST2
    return 1.0f;
}
#endif
#endif /* SFB__SIMD_NEON */

/* Packs a quartic Bezier triangle (15 double xyz points, the table's order) into g (48 floats,
 * patches.h): points 1..14 relative to o = point 0 rounded to float, o, E x
 * SFB__SIMD_TRI_EFACTOR, two zeros. Returns E. (Point 0 is taken as o itself: it differs by
 * point 0's rounding to float, as the old centroid origin did by its own.) */
static float sfb__simd_pack_tri(float *g, double (*q)[3]) {
    float E = 0.0f;
    int k, c;
    for (c = 0; c < 3; ++c) g[SFB__SIMD_TRI_ORIGIN + c] = (float)q[0][c];
    for (k = 1; k < 15; ++k)
        for (c = 0; c < 3; ++c) {
            float *d = &g[3 * (k - 1) + c];
            *d = (float)(q[k][c] - (double)g[SFB__SIMD_TRI_ORIGIN + c]);
            if (fabsf(*d) > E) E = fabsf(*d);
        }
    g[SFB__SIMD_TRI_ORIGIN + 3] = E * SFB__SIMD_TRI_EFACTOR;
    g[SFB__SIMD_TRI_ORIGIN + 4] = g[SFB__SIMD_TRI_ORIGIN + 5] = 0.0f;
    return E;
}

/* The Stam-Loop triangles of patch p at g: for each level n = 1..SFB__SIMD_LOOP_LEVELS the
 * three sub-patches k = 0, 1, 2 (48 floats each, as sfb__simd_pack_tri), control points
 * Q[j] = sum_i (lambda_i^m phi_k[j][i] + m lambda_i^(m-1) phi_k[j][head_i]) c_i, m = n - 1 (the
 * second term only for the second vector of a Jordan block). 0 where the sub-patches of a
 * level do not agree on their shared edges (sub-patch 0's edge s = 0 is the middle's s = 0
 * reversed, sub-patch 1's edge t = 0 the middle's t = 0 reversed): such a table is left to ref. */
static int sfb__simd_pack_stam_loop(float *g, const sfb__patch_table *pt, int p) {
    const sfb__eigen_loop *e = pt->eigl[pt->pvalence[p]];
    const int K = e->K, *cv = pt->cv + pt->pfirst[p];
    double q[3][15][3], scale = 0.0, diff = 0.0;
    int n, k, i, jj, c;
    for (n = 1; n <= SFB__SIMD_LOOP_LEVELS; ++n) {
        const int m = n - 1;
        /* the 45 points' sums over i in order, all at once (independent chains: the same sums
         * bit for bit as one point after the other) */
        for (k = 0; k < 3; ++k)
            for (jj = 0; jj < 15; ++jj)
                for (c = 0; c < 3; ++c) q[k][jj][c] = 0.0;
        for (i = 0; i < K; ++i) {
            const float *c_i = pt->point_data + 3 * (size_t)cv[i];
            const double c0 = c_i[0], c1 = c_i[1], c2 = c_i[2], l = sfb__ipow(e->lambda[i], m);
            const int hd = e->head[i] >= 0 && e->head[i] < K && m > 0 ? e->head[i] : -1;
            const double lh = hd >= 0 ? m * sfb__ipow(e->lambda[i], m - 1) : 0.0;
            int r;
            for (r = 0; r < 45; ++r) {
                const double *phi = e->phi + (size_t)r * (size_t)K;
                double *qr = q[r / 15][r % 15];
                double w = l * phi[i];
                if (hd >= 0) w += lh * phi[hd];
                qr[0] += w * c0; qr[1] += w * c1; qr[2] += w * c2;
            }
        }
        for (jj = 0; jj < 5; ++jj) {
            /* row index of (i, j): j (11 - j) / 2 + i */
            const int e0 = jj * (11 - jj) / 2, e2 = (4 - jj) * (11 - (4 - jj)) / 2; /* (0, jj), (0, 4 - jj) */
            for (c = 0; c < 3; ++c) {
                diff = fmax(diff, fabs(q[0][e0][c] - q[2][e2][c]));
                diff = fmax(diff, fabs(q[1][jj][c] - q[2][4 - jj][c]));
            }
        }
        for (k = 0; k < 3; ++k) {
            const float E = sfb__simd_pack_tri(g + (size_t)(n - 1) * 3 * SFB__SIMD_TRI_FLOATS + (size_t)k * SFB__SIMD_TRI_FLOATS, q[k]);
            if ((double)E > scale) scale = E;
        }
    }
    return diff <= 1e-6 * scale;
}
