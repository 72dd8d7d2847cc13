/* backends/simd/patches_quad.h -- the quad family of backends/simd/patches.h (BSPLINE16, STAM;
 * ENDCAP runs the ref kernel): locating, the Stam locations beyond the packed levels, the 4 x 4
 * B-spline window kernels per instruction set, and packing the grids. Layout and numerics:
 * patches.h. */


/* B-spline basis b_k(t) = C0[k] + C1[k] t + C2[k] t^2 + C3[k] t^3 (k = 0..3) as coefficient
 * rows for Horner's rule; 2 C2, 3 C3 and 6 C3 for the derivatives. */
static const float sfb__simd_bsc[5][4] = {
    {1.0f / 6.0f, 2.0f / 3.0f, 1.0f / 6.0f, 0.0f},   /* C0 */
    {-0.5f, 0.0f, 0.5f, 0.0f},                       /* C1 (the derivative's constant term) */
    {0.5f, -1.0f, 0.5f, 0.0f},                       /* C2 */
    {-1.0f / 6.0f, 0.5f, -0.5f, 1.0f / 6.0f},        /* C3 */
    {1.0f, -2.0f, 1.0f, 0.0f}};                      /* 2 C2 */
static const float sfb__simd_bsc3[2][4] = {
    {-0.5f, 1.5f, -1.5f, 0.5f},                      /* 3 C3 */
    {-1.0f, 3.0f, -3.0f, 1.0f}};                     /* 6 C3 */

static void sfb__simd_basis(float t, float b[4], float d[4], float dd[4]) {
    int k;
    for (k = 0; k < 4; ++k) {
        b[k] = ((sfb__simd_bsc[3][k] * t + sfb__simd_bsc[2][k]) * t + sfb__simd_bsc[1][k]) * t + sfb__simd_bsc[0][k];
        d[k] = (sfb__simd_bsc3[0][k] * t + sfb__simd_bsc[4][k]) * t + sfb__simd_bsc[1][k];
        dd[k] = sfb__simd_bsc3[1][k] * t + sfb__simd_bsc[4][k];
    }
}

/* A Stam location nearer the EV than the stored levels: ref's own evaluation
 * (sfb__eval_stam, only the outputs asked for) and a normal from its finite tangent frame;
 * a degenerate frame goes to the ref kernel (its normal fallbacks). */
static void sfb__simd_stam_far(const sfb__simd_pjob *j, int q) {
    const sfb__patch_table *pt = j->pt;
    const sfb_location *l = &j->locs[q];
    double s, t, sc, res[6][3], nres[2][3];
    const sfb__eigen_cc *e;
    const int p = sfb__patch_locate(pt, l->face, l->u, l->v, &s, &t, &sc);
    if (p < 0 || pt->ptype[p] != SFB__PATCH_STAM || !(e = pt->eig[pt->pvalence[p]])) { sfb__simd_ref_one(j, q); return; }
    sfb__eval_stam(e, pt->point_data, pt->cv + pt->pfirst[p], SFB__PARAM_CORNER(pt->pparam[p]), s, t, j->second ? 6 : 3, res, nres);
    sfb__simd_far_finish(j, q, sc, res, nres);
}

/* Locates location q (in float: exact, as above) and prepares its slot; prefetches the window. */
static SFB__SIMD_FORCEINLINE void sfb__simd_prep(const sfb__simd_pjob *j, int q, sfb__simd_slot *o) {
    const sfb__simd_patches *h = j->h;
    const sfb_location *l = &j->locs[q];
    int node = h->root[l->face], code;
    float s = l->u, t = l->v, sc = 1.0f;
    while (node >= 0) {
        int qx, qy;
        s += s; t += t; sc += sc;
        qx = s >= 1.0f; qy = t >= 1.0f;
        s -= (float)qx; /* not `if (qx)`: random quadrants would mispredict */
        t -= (float)qy;
        node = h->node[4 * node + qx + 2 * qy];
    }
    code = -node - 1;
    o->run = SFB__SIMD_RUN_REF;
    if ((code & 3) == SFB__SIMD_LEAF_BSPLINE) {
        o->blk = h->blk + 4 * (size_t)(code >> 4);
        o->s = s; o->t = t; o->dsc = sc; o->cs = 16; o->rot = 0;
        o->run = SFB__SIMD_RUN_KERNEL;
        SFB__SIMD_PREFETCH(o->blk);
        SFB__SIMD_PREFETCH(o->blk + 16);
        SFB__SIMD_PREFETCH(o->blk + 32);
        SFB__SIMD_PREFETCH(o->blk + 48);
    } else if ((code & 3) == SFB__SIMD_LEAF_STAM) {
        /* Level n and sub-patch k as ref finds them, without branches (they are random here).
         * Float is exact for these decisions: (u, v) is (s, t) turned to the EV's frame, 1 - s
         * is exact for s >= 0.5 and >= 0.5 otherwise, doubling is exact, and n - 1 (the number
         * of doublings that bring max(u, v) to [0.5, 1]) is read off max(u, v)'s exponent. */
        static const float frame[4][6] = {{0, 1, 0, 0, 0, 1}, {0, 0, 1, 1, -1, 0}, {1, -1, 0, 1, 0, -1}, {1, 0, -1, 0, 1, 0}};
        static const int window[4] = {0, 20, 4, 24}; /* (u >= 1/2) + 2 (v >= 1/2) -> sub-patch 1, 3, 2 */
        const int corner = (code >> 2) & 3;
        const float *f = frame[corner];
        float u = (f[0] + f[1] * s) + f[2] * t, v = (f[3] + f[4] * s) + f[5] * t, m = u > v ? u : v, sc2;
        uint32_t bits;
        int n, hu, hv;
        memcpy(&bits, &m, sizeof bits);
        n = 127 - (int)(bits >> 23); /* m in [0.5, 1): 1; [0.25, 0.5): 2; ...; 0 and denormals: >= 127 */
        if (n < 1) n = 1;            /* m = 1 */
        if (n > SFB__SIMD_STAM_LEVELS) {
            if (m > 0.0f) o->run = SFB__SIMD_RUN_STAM_FAR; /* else the EV itself: ref */
            return;
        }
        sc2 = (float)(1 << (n - 1));
        u *= sc2;
        v *= sc2;
        hu = u >= 0.5f;
        hv = v >= 0.5f;
        o->s = u + u - (float)hu;
        o->t = v + v - (float)hv;
        o->blk = h->blk + 4 * (size_t)(code >> 4) + (size_t)(n - 1) * 100 + (size_t)window[hu + 2 * hv];
        o->dsc = sc * sc2 * 2.0f;
        o->cs = 20;
        o->rot = corner;
        o->run = SFB__SIMD_RUN_KERNEL;
        SFB__SIMD_PREFETCH(o->blk);
        SFB__SIMD_PREFETCH(o->blk + 16);
        SFB__SIMD_PREFETCH(o->blk + 32);
        SFB__SIMD_PREFETCH(o->blk + 48);
        SFB__SIMD_PREFETCH(o->blk + 64);
        SFB__SIMD_PREFETCH(o->blk + 75);
    }
}

/* ---- portable window kernel and the scalar-finishing range (portable, neon) ---- */
static void sfb__simd_bs_portable(const float *blk, int cs, float s, float t, int second, float r[6][4]) {
    float bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4];
    int i, jj, c, k;
    sfb__simd_basis(s, bu, du, ddu);
    sfb__simd_basis(t, bv, dv, ddv);
    for (k = 0; k < 6; ++k) r[k][0] = r[k][1] = r[k][2] = r[k][3] = 0.0f;
    for (jj = 0; jj < 4; ++jj) {
        float rp[3] = {0.0f, 0.0f, 0.0f}, rd[3] = {0.0f, 0.0f, 0.0f}, rdd[3] = {0.0f, 0.0f, 0.0f};
        for (i = 0; i < 4; ++i) {
            const float *pnt = blk + i * cs + 4 * jj;
            for (c = 0; c < 3; ++c) { rp[c] += bu[i] * pnt[c]; rd[c] += du[i] * pnt[c]; rdd[c] += ddu[i] * pnt[c]; }
        }
        for (c = 0; c < 3; ++c) {
            r[0][c] += bv[jj] * rp[c]; r[1][c] += bv[jj] * rd[c]; r[2][c] += dv[jj] * rp[c];
            if (second) { r[3][c] += bv[jj] * rdd[c]; r[4][c] += dv[jj] * rd[c]; r[5][c] += ddv[jj] * rp[c]; }
        }
    }
    for (c = 0; c < 3; ++c) r[0][c] += blk[c * cs + 4 * c + 3]; /* origin: w of the diagonal */
}

#ifdef SFB__SIMD_SSE2
/* The window's origin from the w lanes of its diagonal (see the layout). */
static inline __m128 sfb__simd_sse2_origin(const float *blk, int cs) {
    const __m128 t0 = _mm_unpackhi_ps(_mm_loadu_ps(blk), _mm_loadu_ps(blk + cs + 4));               /* z0 z1 w0 w1 */
    const __m128 t1 = _mm_unpackhi_ps(_mm_loadu_ps(blk + 2 * cs + 8), _mm_loadu_ps(blk + 3 * cs + 12)); /* z2 z3 w2 w3 */
    return _mm_movehl_ps(t1, t0);                                                                   /* w0 w1 w2 w3 */
}

/* Four basis values at x: Horner on the coefficient rows (b), derivative (d), second (dd). */
static inline __m128 sfb__simd_sse2_b(__m128 x) {
    return _mm_add_ps(_mm_mul_ps(_mm_add_ps(_mm_mul_ps(_mm_add_ps(_mm_mul_ps(_mm_loadu_ps(sfb__simd_bsc[3]), x), _mm_loadu_ps(sfb__simd_bsc[2])), x),
                                            _mm_loadu_ps(sfb__simd_bsc[1])), x), _mm_loadu_ps(sfb__simd_bsc[0]));
}
static inline __m128 sfb__simd_sse2_d(__m128 x) {
    return _mm_add_ps(_mm_mul_ps(_mm_add_ps(_mm_mul_ps(_mm_loadu_ps(sfb__simd_bsc3[0]), x), _mm_loadu_ps(sfb__simd_bsc[4])), x),
                      _mm_loadu_ps(sfb__simd_bsc[1]));
}
static inline __m128 sfb__simd_sse2_dd(__m128 x) {
    return _mm_add_ps(_mm_mul_ps(_mm_loadu_ps(sfb__simd_bsc3[1]), x), _mm_loadu_ps(sfb__simd_bsc[4]));
}

/* sum_i w_i a_i with w_i = lane i of w broadcast */
static inline __m128 sfb__simd_sse2_dot4(__m128 w, __m128 a0, __m128 a1, __m128 a2, __m128 a3) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(SFB__SIMD_BC(w, 0), a0), _mm_mul_ps(SFB__SIMD_BC(w, 1), a1)),
                      _mm_add_ps(_mm_mul_ps(SFB__SIMD_BC(w, 2), a2), _mm_mul_ps(SFB__SIMD_BC(w, 3), a3)));
}

/* Window at (s, t), one point per register: rows (fixed v index) reduced along u first. */
static SFB__SIMD_FORCEINLINE void sfb__simd_sse2_eval(const float *blk, int cs, float s, float t, int second, __m128 r[6]) {
    const __m128 vs = _mm_set1_ps(s), vt = _mm_set1_ps(t);
    const __m128 Bu = sfb__simd_sse2_b(vs), Du = sfb__simd_sse2_d(vs), Bv = sfb__simd_sse2_b(vt), Dv = sfb__simd_sse2_d(vt);
    __m128 rp[4], rd[4];
    int jj;
    for (jj = 0; jj < 4; ++jj) {
        const __m128 a0 = _mm_loadu_ps(blk + 4 * jj), a1 = _mm_loadu_ps(blk + cs + 4 * jj);
        const __m128 a2 = _mm_loadu_ps(blk + 2 * cs + 4 * jj), a3 = _mm_loadu_ps(blk + 3 * cs + 4 * jj);
        rp[jj] = sfb__simd_sse2_dot4(Bu, a0, a1, a2, a3);
        rd[jj] = sfb__simd_sse2_dot4(Du, a0, a1, a2, a3);
    }
    r[0] = _mm_add_ps(sfb__simd_sse2_dot4(Bv, rp[0], rp[1], rp[2], rp[3]), sfb__simd_sse2_origin(blk, cs));
    r[1] = sfb__simd_sse2_dot4(Bv, rd[0], rd[1], rd[2], rd[3]);
    r[2] = sfb__simd_sse2_dot4(Dv, rp[0], rp[1], rp[2], rp[3]);
    if (second) {
        const __m128 DDu = sfb__simd_sse2_dd(vs), DDv = sfb__simd_sse2_dd(vt);
        __m128 rdd[4];
        for (jj = 0; jj < 4; ++jj)
            rdd[jj] = sfb__simd_sse2_dot4(DDu, _mm_loadu_ps(blk + 4 * jj), _mm_loadu_ps(blk + cs + 4 * jj), _mm_loadu_ps(blk + 2 * cs + 4 * jj),
                                          _mm_loadu_ps(blk + 3 * cs + 4 * jj));
        r[3] = sfb__simd_sse2_dot4(Bv, rdd[0], rdd[1], rdd[2], rdd[3]);
        r[4] = sfb__simd_sse2_dot4(Dv, rd[0], rd[1], rd[2], rd[3]);
        r[5] = sfb__simd_sse2_dot4(DDv, rp[0], rp[1], rp[2], rp[3]);
    } else {
        r[3] = r[4] = r[5] = _mm_setzero_ps();
    }
}
#endif /* SFB__SIMD_SSE2 */

/* ---- avx2 + fma: two points (rows j, j+1 of one column) per register ---- */
#ifdef SFB__SIMD_X86_DISPATCH
SFB__SIMD_TARGET_AVX2 static inline __m128 sfb__simd_avx2_hadd(__m256 v) {
    return _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
}

SFB__SIMD_TARGET_AVX2 static SFB__SIMD_FORCEINLINE void sfb__simd_avx2_eval(const float *blk, int cs, float s, float t, int second, __m128 r[6]) {
    /* s in the low half, t in the high half: one Horner pass makes both bases */
    const __m256 st = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_set1_ps(s)), _mm_set1_ps(t), 1);
    const __m256 c0 = _mm256_broadcast_ps((const __m128 *)(const void *)sfb__simd_bsc[0]);
    const __m256 c1 = _mm256_broadcast_ps((const __m128 *)(const void *)sfb__simd_bsc[1]);
    const __m256 c2 = _mm256_broadcast_ps((const __m128 *)(const void *)sfb__simd_bsc[2]);
    const __m256 c3 = _mm256_broadcast_ps((const __m128 *)(const void *)sfb__simd_bsc[3]);
    const __m256 c22 = _mm256_broadcast_ps((const __m128 *)(const void *)sfb__simd_bsc[4]);
    const __m256 c33 = _mm256_broadcast_ps((const __m128 *)(const void *)sfb__simd_bsc3[0]);
    const __m256 B = _mm256_fmadd_ps(_mm256_fmadd_ps(_mm256_fmadd_ps(c3, st, c2), st, c1), st, c0);
    const __m256 D = _mm256_fmadd_ps(_mm256_fmadd_ps(c33, st, c22), st, c1);
    const __m256 Bu = _mm256_permute2f128_ps(B, B, 0x00), Bv = _mm256_permute2f128_ps(B, B, 0x11);
    const __m256 Du = _mm256_permute2f128_ps(D, D, 0x00), Dv = _mm256_permute2f128_ps(D, D, 0x11);
    const __m256i sel01 = _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1), sel23 = _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3);
    const __m256 bv01 = _mm256_permutevar_ps(Bv, sel01), bv23 = _mm256_permutevar_ps(Bv, sel23);
    const __m256 dv01 = _mm256_permutevar_ps(Dv, sel01), dv23 = _mm256_permutevar_ps(Dv, sel23);
    __m256 y0[4], y1[4], rp0, rp1, rd0, rd1;
    int i;
    for (i = 0; i < 4; ++i) {
        y0[i] = _mm256_loadu_ps(blk + i * cs);     /* points (i,0) (i,1) */
        y1[i] = _mm256_loadu_ps(blk + i * cs + 8); /* points (i,2) (i,3) */
    }
#define SFB__SIMD_AVX2_COL(w, y)                                                                                   \
    _mm256_fmadd_ps(_mm256_permute_ps(w, 0xFF), y[3],                                                              \
                    _mm256_fmadd_ps(_mm256_permute_ps(w, 0xAA), y[2],                                              \
                                    _mm256_fmadd_ps(_mm256_permute_ps(w, 0x55), y[1], _mm256_mul_ps(_mm256_permute_ps(w, 0x00), y[0]))))
    rp0 = SFB__SIMD_AVX2_COL(Bu, y0);
    rp1 = SFB__SIMD_AVX2_COL(Bu, y1);
    rd0 = SFB__SIMD_AVX2_COL(Du, y0);
    rd1 = SFB__SIMD_AVX2_COL(Du, y1);
    r[0] = _mm_add_ps(sfb__simd_avx2_hadd(_mm256_fmadd_ps(rp1, bv23, _mm256_mul_ps(rp0, bv01))), sfb__simd_sse2_origin(blk, cs));
    r[1] = sfb__simd_avx2_hadd(_mm256_fmadd_ps(rd1, bv23, _mm256_mul_ps(rd0, bv01)));
    r[2] = sfb__simd_avx2_hadd(_mm256_fmadd_ps(rp1, dv23, _mm256_mul_ps(rp0, dv01)));
    if (second) {
        const __m256 DD = _mm256_fmadd_ps(_mm256_broadcast_ps((const __m128 *)(const void *)sfb__simd_bsc3[1]), st, c22);
        const __m256 DDu = _mm256_permute2f128_ps(DD, DD, 0x00), DDv = _mm256_permute2f128_ps(DD, DD, 0x11);
        const __m256 ddv01 = _mm256_permutevar_ps(DDv, sel01), ddv23 = _mm256_permutevar_ps(DDv, sel23);
        const __m256 rdd0 = SFB__SIMD_AVX2_COL(DDu, y0), rdd1 = SFB__SIMD_AVX2_COL(DDu, y1);
        r[3] = sfb__simd_avx2_hadd(_mm256_fmadd_ps(rdd1, bv23, _mm256_mul_ps(rdd0, bv01)));
        r[4] = sfb__simd_avx2_hadd(_mm256_fmadd_ps(rd1, dv23, _mm256_mul_ps(rd0, dv01)));
        r[5] = sfb__simd_avx2_hadd(_mm256_fmadd_ps(rp1, ddv23, _mm256_mul_ps(rp0, ddv01)));
    } else {
        r[3] = r[4] = r[5] = _mm_setzero_ps();
    }
#undef SFB__SIMD_AVX2_COL
}

/* ---- avx512: a whole column (4 points) per register ---- */
/* Sum of the four 128-bit lanes. (maskz forms: see the note on GCC bug 105593 in stencils.h.) */
SFB__SIMD_TARGET_AVX512 static inline __m128 sfb__simd_avx512_hadd(__m512 v) {
    const __m512d d = _mm512_castps_pd(v);
    const __m256 y = _mm256_add_ps(_mm256_castpd_ps(_mm512_maskz_extractf64x4_pd((__mmask8)0xF, d, 0)),
                                   _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd((__mmask8)0xF, d, 1)));
    return _mm_add_ps(_mm256_castps256_ps128(y), _mm256_extractf128_ps(y, 1));
}

SFB__SIMD_TARGET_AVX512 static SFB__SIMD_FORCEINLINE void sfb__simd_avx512_eval(const float *blk, int cs, float s, float t, int second, __m128 r[6]) {
    const __mmask16 all = (__mmask16)0xFFFF;
    const __m128 vs = _mm_set1_ps(s), vt = _mm_set1_ps(t);
    const __m512 Bu = _mm512_castps128_ps512(sfb__simd_sse2_b(vs)), Du = _mm512_castps128_ps512(sfb__simd_sse2_d(vs));
    const __m512 Bv = _mm512_castps128_ps512(sfb__simd_sse2_b(vt)), Dv = _mm512_castps128_ps512(sfb__simd_sse2_d(vt));
    /* v side: basis value j in the 128-bit lane of row j (the lanes of a column register) */
    const __m512i spread = _mm512_set_epi32(3, 3, 3, 3, 2, 2, 2, 2, 1, 1, 1, 1, 0, 0, 0, 0);
    const __m512i i0 = _mm512_set1_epi32(0), i1 = _mm512_set1_epi32(1), i2 = _mm512_set1_epi32(2), i3 = _mm512_set1_epi32(3);
    const __m512 vb = _mm512_maskz_permutexvar_ps(all, spread, Bv), vd = _mm512_maskz_permutexvar_ps(all, spread, Dv);
    const __m512 z0 = _mm512_loadu_ps(blk), z1 = _mm512_loadu_ps(blk + cs), z2 = _mm512_loadu_ps(blk + 2 * cs), z3 = _mm512_loadu_ps(blk + 3 * cs);
    __m512 rp, rd;
#define SFB__SIMD_AVX512_COL(w)                                                                                       \
    _mm512_fmadd_ps(_mm512_maskz_permutexvar_ps(all, i3, w), z3,                                                      \
                    _mm512_fmadd_ps(_mm512_maskz_permutexvar_ps(all, i2, w), z2,                                      \
                                    _mm512_fmadd_ps(_mm512_maskz_permutexvar_ps(all, i1, w), z1,                      \
                                                    _mm512_mul_ps(_mm512_maskz_permutexvar_ps(all, i0, w), z0))))
    rp = SFB__SIMD_AVX512_COL(Bu);
    rd = SFB__SIMD_AVX512_COL(Du);
    r[0] = _mm_add_ps(sfb__simd_avx512_hadd(_mm512_mul_ps(rp, vb)), sfb__simd_sse2_origin(blk, cs));
    r[1] = sfb__simd_avx512_hadd(_mm512_mul_ps(rd, vb));
    r[2] = sfb__simd_avx512_hadd(_mm512_mul_ps(rp, vd));
    if (second) {
        const __m512 DDu = _mm512_castps128_ps512(sfb__simd_sse2_dd(vs));
        const __m512 vdd = _mm512_maskz_permutexvar_ps(all, spread, _mm512_castps128_ps512(sfb__simd_sse2_dd(vt)));
        const __m512 rdd = SFB__SIMD_AVX512_COL(DDu);
        r[3] = sfb__simd_avx512_hadd(_mm512_mul_ps(rdd, vb));
        r[4] = sfb__simd_avx512_hadd(_mm512_mul_ps(rd, vd));
        r[5] = sfb__simd_avx512_hadd(_mm512_mul_ps(rp, vdd));
    } else {
        r[3] = r[4] = r[5] = _mm_setzero_ps();
    }
#undef SFB__SIMD_AVX512_COL
}
#endif /* SFB__SIMD_X86_DISPATCH */

/* ---- neon: one point per register, finished in scalar ---- */
#ifdef SFB__SIMD_NEON
static void sfb__simd_bs_neon(const float *blk, int cs, float s, float t, int second, float r[6][4]) {
    float bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4];
    float32x4_t P = vdupq_n_f32(0.0f), Pu = P, Pv = P, Puu = P, Puv = P, Pvv = P;
    int i, jj, c;
    sfb__simd_basis(s, bu, du, ddu);
    sfb__simd_basis(t, bv, dv, ddv);
    for (jj = 0; jj < 4; ++jj) {
        float32x4_t rp = vdupq_n_f32(0.0f), rd = rp, rdd = rp;
        for (i = 0; i < 4; ++i) {
            const float32x4_t a = vld1q_f32(blk + i * cs + 4 * jj);
            rp = SFB__SIMD_NEON_MADD(rp, vdupq_n_f32(bu[i]), a);
            rd = SFB__SIMD_NEON_MADD(rd, vdupq_n_f32(du[i]), a);
            if (second) rdd = SFB__SIMD_NEON_MADD(rdd, vdupq_n_f32(ddu[i]), a);
        }
        P = SFB__SIMD_NEON_MADD(P, vdupq_n_f32(bv[jj]), rp);
        Pu = SFB__SIMD_NEON_MADD(Pu, vdupq_n_f32(bv[jj]), rd);
        Pv = SFB__SIMD_NEON_MADD(Pv, vdupq_n_f32(dv[jj]), rp);
        if (second) {
            Puu = SFB__SIMD_NEON_MADD(Puu, vdupq_n_f32(bv[jj]), rdd);
            Puv = SFB__SIMD_NEON_MADD(Puv, vdupq_n_f32(dv[jj]), rd);
            Pvv = SFB__SIMD_NEON_MADD(Pvv, vdupq_n_f32(ddv[jj]), rp);
        }
    }
    vst1q_f32(r[0], P); vst1q_f32(r[1], Pu); vst1q_f32(r[2], Pv);
    vst1q_f32(r[3], Puu); vst1q_f32(r[4], Puv); vst1q_f32(r[5], Pvv);
    for (c = 0; c < 3; ++c) r[0][c] += blk[c * cs + 4 * c + 3]; /* origin: w of the diagonal */
}
#endif /* SFB__SIMD_NEON */

/* Packs the points q[gx * rows + gy] (double xyz; set[] = 0: an unused slot) of a grid with
 * `rows` points per column into g (layout: patches.h): relative to their centroid, with o and E in
 * the w lanes of the diagonals of the windows starting at win[k] (grid indices). Returns E. */
static float sfb__simd_pack_grid(float *g, int cols, int rows, double (*q)[3], const unsigned char *set, const int (*win)[2],
                                 int nwin) {
    double o[3] = {0.0, 0.0, 0.0};
    float of[4], E = 0.0f;
    int k, c, cnt = 0;
    for (k = 0; k < cols * rows; ++k)
        if (set[k]) {
            for (c = 0; c < 3; ++c) o[c] += q[k][c];
            ++cnt;
        }
    for (c = 0; c < 3; ++c) of[c] = (float)(o[c] / (cnt ? cnt : 1));
    for (k = 0; k < cols * rows; ++k) {
        float *dst = g + 4 * k;
        for (c = 0; c < 3; ++c) {
            dst[c] = set[k] ? (float)(q[k][c] - (double)of[c]) : 0.0f;
            if (fabsf(dst[c]) > E) E = fabsf(dst[c]);
        }
        dst[3] = 0.0f;
    }
    of[3] = E;
    for (k = 0; k < nwin; ++k)
        for (c = 0; c < 4; ++c) g[4 * ((win[k][0] + c) * rows + win[k][1] + c) + 3] = of[c];
    return E;
}

/* The Stam grids of patch p at g; 0 where the three sub-patches of a level do not agree on
 * the points they share (they are windows of one level-n mesh; a table whose eigen data said
 * otherwise is left to the ref kernel). */
static int sfb__simd_pack_stam(float *g, const sfb__patch_table *pt, int p, double *lp) {
    static const int win[3][2] = {{1, 0}, {1, 1}, {0, 1}}; /* sub-patch k = 1, 2, 3: lattice (0,-1), (0,0), (-1,0) */
    const sfb__eigen_cc *e = pt->eig[pt->pvalence[p]];
    const int K = e->K, *cv = pt->cv + pt->pfirst[p];
    double q[25][3], x[48][3], scale = 0.0, diff = 0.0;
    unsigned char set[25];
    int n, k, i, jj, c;
    for (i = 0; i < K; ++i) lp[i] = 1.0;
    for (n = 1; n <= SFB__SIMD_STAM_LEVELS; ++n) {
        /* control point jj = 4 b + a of sub-patch k + 1 (x[16 k + jj]): sum_i lambda_i^(n-1)
         * phi[jj][i] c_i, the sums over i in order, all 48 at once (independent chains: the
         * same sums bit for bit as one point after the other) */
        for (k = 0; k < 48; ++k) x[k][0] = x[k][1] = x[k][2] = 0.0;
        for (i = 0; i < K; ++i) {
            const float *c_i = pt->point_data + 3 * (size_t)cv[i];
            const double c0 = c_i[0], c1 = c_i[1], c2 = c_i[2], l = lp[i];
            const double *phi = e->phi + i;
            for (k = 0; k < 48; ++k) {
                const double w = l * phi[(size_t)k * (size_t)K];
                x[k][0] += w * c0; x[k][1] += w * c1; x[k][2] += w * c2;
            }
        }
        memset(set, 0, sizeof set);
        for (k = 0; k < 3; ++k)
            for (jj = 0; jj < 16; ++jj) {
                const int slot = (win[k][0] + jj % 4) * 5 + win[k][1] + jj / 4;
                const double *xk = x[16 * k + jj];
                for (c = 0; c < 3; ++c) {
                    if (set[slot] && fabs(xk[c] - q[slot][c]) > diff) diff = fabs(xk[c] - q[slot][c]);
                    q[slot][c] = xk[c];
                }
                set[slot] = 1;
            }
        {
            const float E = sfb__simd_pack_grid(g + (size_t)(n - 1) * 100, 5, 5, q, set, win, 3);
            if ((double)E > scale) scale = E;
        }
        for (i = 0; i < K; ++i) lp[i] *= e->lambda[i];
    }
    return diff <= 1e-6 * scale;
}
