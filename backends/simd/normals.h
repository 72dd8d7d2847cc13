/* backends/simd/normals.h -- the simd backend's normal-blend family: finish_normals (seed 001).
 * Part of backends/simd/sfb_simd.h.
 *
 * The vtable's finish_normals (ref: sfb__ref_finish_normals), in double as ref. Elements are
 * taken in blocks of SFB__SIMD_NBLOCK:
 *   1. a scalar pass gathers the block into double arrays (one per component): L = tu x tv
 *      (ref's expression: products of floats are exact in double, so L matches ref bit for
 *      bit before normalising), S = ns[k] (0 when k < 0), and w = b^p where the blend applies
 *      (k >= 0, b given, b > 0), else -1 (sfb__simd_bpow: b = 1 gives exactly 1, and b = 0
 *      never blends);
 *   2. the instruction set's vector pass (2 lanes sse2 and AArch64 neon, 4 avx2, 8 avx512, 1
 *      portable and 32-bit neon) normalises L and S, forms B = (1 - w) L + w S and normalises
 *      it, and keeps B = L where w < 0. A vector is normalised as v * (1 / |v|) where ref
 *      divides each component by |v| (at most an ulp of double apart), and a zero vector (|v|
 *      not > 0) stays zero;
 *   3. a scalar pass writes B, and L and S when asked, as floats.
 * The block is padded to a multiple of 8 lanes with zero vectors (w = -1): no partial
 * vectors, and nothing outside [first, last) is read or written. Threads: equal chunks of
 * elements over the pool from SFB__SIMD_INLINE_NORMALS elements on (smaller calls run on the
 * caller's thread).
 */
#define SFB__SIMD_NBLOCK 64
#define SFB__SIMD_INLINE_NORMALS 8192

typedef struct sfb__simd_njob {
    const float *tu, *tv, *ns, *b;
    const int *ns_index;
    float p;
    int pmode;         /* sfb__simd_bpow's case for p: 1, 2, 3 (p), 4 (p = 0.5), 0 (any other) */
    float *blend, *limit, *sub;
} sfb__simd_njob;

/* b^p for 0 < b <= 1: exact products for p = 1, 2 (b^2 is exact in double) and 3 (rounded
 * once), the correctly rounded sqrt for p = 0.5, and powf otherwise (within an ulp of float,
 * ~6e-8 relative, and 2-3 times faster than pow; B then moves by ~1e-7 / |(1 - w) L + w S|,
 * the blend's own conditioning). Each gives exactly 1 for b = 1. */
static double sfb__simd_bpow(float b, float p, int mode) {
    const double x = b;
    switch (mode) {
    case 1: return x;
    case 2: return x * x;
    case 3: return x * x * x;
    case 4: return sqrt(x);
    default: return (double)powf(b, p);
    }
}

/* The arrays of a block, SFB__SIMD_NBLOCK doubles each: L, S, w, then B. */
enum { SFB__SIMD_NLX, SFB__SIMD_NLY, SFB__SIMD_NLZ, SFB__SIMD_NSX, SFB__SIMD_NSY, SFB__SIMD_NSZ, SFB__SIMD_NW,
       SFB__SIMD_NBX, SFB__SIMD_NBY, SFB__SIMD_NBZ, SFB__SIMD_NARRAYS };

/* The vector pass over lanes [0, count) of a block (count a multiple of 8). */
typedef void (*sfb__simd_nvec_fn)(double *blk, int count);

/* Pass 1: elements [i0, i0 + n) into blk, lanes up to the next multiple of 8 padded. */
static void sfb__simd_normals_gather(const sfb__simd_njob *j, int i0, int n, double *blk) {
    double *lx = blk + SFB__SIMD_NLX * SFB__SIMD_NBLOCK, *ly = blk + SFB__SIMD_NLY * SFB__SIMD_NBLOCK;
    double *lz = blk + SFB__SIMD_NLZ * SFB__SIMD_NBLOCK, *sx = blk + SFB__SIMD_NSX * SFB__SIMD_NBLOCK;
    double *sy = blk + SFB__SIMD_NSY * SFB__SIMD_NBLOCK, *sz = blk + SFB__SIMD_NSZ * SFB__SIMD_NBLOCK;
    double *w = blk + SFB__SIMD_NW * SFB__SIMD_NBLOCK;
    const float *a = j->tu + 3 * (size_t)i0, *d = j->tv + 3 * (size_t)i0;
    int m;
    for (m = 0; m < n; ++m, a += 3, d += 3) {
        const int k = j->ns_index ? j->ns_index[i0 + m] : -1;
        lx[m] = (double)a[1] * d[2] - (double)a[2] * d[1];
        ly[m] = (double)a[2] * d[0] - (double)a[0] * d[2];
        lz[m] = (double)a[0] * d[1] - (double)a[1] * d[0];
        if (k >= 0) {
            const float *q = j->ns + 3 * (size_t)k;
            const float bb = j->b ? j->b[i0 + m] : 0.0f;
            sx[m] = q[0];
            sy[m] = q[1];
            sz[m] = q[2];
            w[m] = bb > 0.0f ? sfb__simd_bpow(bb, j->p, j->pmode) : -1.0;
        } else {
            sx[m] = sy[m] = sz[m] = 0.0;
            w[m] = -1.0;
        }
    }
    for (; m < ((n + 7) & ~7); ++m) {
        lx[m] = ly[m] = lz[m] = sx[m] = sy[m] = sz[m] = 0.0;
        w[m] = -1.0;
    }
}

/* Pass 3: B (and L, S when asked) of elements [i0, i0 + n) out as floats. */
static void sfb__simd_normals_scatter(const sfb__simd_njob *j, int i0, int n, const double *blk) {
    const size_t o = 3 * (size_t)i0;
    int m, c;
    for (m = 0; m < n; ++m)
        for (c = 0; c < 3; ++c) j->blend[o + 3 * (size_t)m + (size_t)c] = (float)blk[(SFB__SIMD_NBX + c) * SFB__SIMD_NBLOCK + m];
    if (j->limit)
        for (m = 0; m < n; ++m)
            for (c = 0; c < 3; ++c) j->limit[o + 3 * (size_t)m + (size_t)c] = (float)blk[(SFB__SIMD_NLX + c) * SFB__SIMD_NBLOCK + m];
    if (j->sub)
        for (m = 0; m < n; ++m)
            for (c = 0; c < 3; ++c) j->sub[o + 3 * (size_t)m + (size_t)c] = (float)blk[(SFB__SIMD_NSX + c) * SFB__SIMD_NBLOCK + m];
}

/* Pass 2 of one instruction set, W lanes of type V (comparison masks of type M) per step, with
 * the operations SFB__SIMD_N_LD/ST/SET1/ADD/SUB/MUL/DIV/SQRT/GT/SEL(mask, if set, if clear)
 * defined around the instantiation. */
#define SFB__SIMD_NUNIT(V, M, x, y, z)                                                                 \
    do {                                                                                           \
        const V len_ = SFB__SIMD_N_SQRT(SFB__SIMD_N_ADD(SFB__SIMD_N_ADD(SFB__SIMD_N_MUL(x, x), SFB__SIMD_N_MUL(y, y)), \
                                                        SFB__SIMD_N_MUL(z, z)));                   \
        const M nz_ = SFB__SIMD_N_GT(len_, zero);                                                  \
        const V inv_ = SFB__SIMD_N_DIV(one, SFB__SIMD_N_SEL(nz_, len_, one));                      \
        x = SFB__SIMD_N_SEL(nz_, SFB__SIMD_N_MUL(x, inv_), zero);                                  \
        y = SFB__SIMD_N_SEL(nz_, SFB__SIMD_N_MUL(y, inv_), zero);                                  \
        z = SFB__SIMD_N_SEL(nz_, SFB__SIMD_N_MUL(z, inv_), zero);                                  \
    } while (0)
#define SFB__SIMD_NORMALS_VEC(NAME, ATTR, W, V, M)                                                  \
    ATTR static void NAME(double *blk, int count) {                                                 \
        const V zero = SFB__SIMD_N_SET1(0.0), one = SFB__SIMD_N_SET1(1.0), nob = SFB__SIMD_N_SET1(-0.5); \
        int m;                                                                                      \
        for (m = 0; m < count; m += (W)) {                                                          \
            double *at = blk + m;                                                                   \
            V lx = SFB__SIMD_N_LD(at + SFB__SIMD_NLX * SFB__SIMD_NBLOCK);                           \
            V ly = SFB__SIMD_N_LD(at + SFB__SIMD_NLY * SFB__SIMD_NBLOCK);                           \
            V lz = SFB__SIMD_N_LD(at + SFB__SIMD_NLZ * SFB__SIMD_NBLOCK);                           \
            V sx = SFB__SIMD_N_LD(at + SFB__SIMD_NSX * SFB__SIMD_NBLOCK);                           \
            V sy = SFB__SIMD_N_LD(at + SFB__SIMD_NSY * SFB__SIMD_NBLOCK);                           \
            V sz = SFB__SIMD_N_LD(at + SFB__SIMD_NSZ * SFB__SIMD_NBLOCK);                           \
            const V wb = SFB__SIMD_N_LD(at + SFB__SIMD_NW * SFB__SIMD_NBLOCK);                      \
            const M blend = SFB__SIMD_N_GT(wb, nob);                                               \
            const V w = SFB__SIMD_N_SEL(blend, wb, zero), w1 = SFB__SIMD_N_SUB(one, w);             \
            V bx, by, bz;                                                                           \
            SFB__SIMD_NUNIT(V, M, lx, ly, lz);                                                   \
            SFB__SIMD_NUNIT(V, M, sx, sy, sz);                                                   \
            bx = SFB__SIMD_N_ADD(SFB__SIMD_N_MUL(w1, lx), SFB__SIMD_N_MUL(w, sx));                  \
            by = SFB__SIMD_N_ADD(SFB__SIMD_N_MUL(w1, ly), SFB__SIMD_N_MUL(w, sy));                  \
            bz = SFB__SIMD_N_ADD(SFB__SIMD_N_MUL(w1, lz), SFB__SIMD_N_MUL(w, sz));                  \
            SFB__SIMD_NUNIT(V, M, bx, by, bz);                                                   \
            SFB__SIMD_N_ST(at + SFB__SIMD_NLX * SFB__SIMD_NBLOCK, lx);                              \
            SFB__SIMD_N_ST(at + SFB__SIMD_NLY * SFB__SIMD_NBLOCK, ly);                              \
            SFB__SIMD_N_ST(at + SFB__SIMD_NLZ * SFB__SIMD_NBLOCK, lz);                              \
            SFB__SIMD_N_ST(at + SFB__SIMD_NSX * SFB__SIMD_NBLOCK, sx);                              \
            SFB__SIMD_N_ST(at + SFB__SIMD_NSY * SFB__SIMD_NBLOCK, sy);                              \
            SFB__SIMD_N_ST(at + SFB__SIMD_NSZ * SFB__SIMD_NBLOCK, sz);                              \
            SFB__SIMD_N_ST(at + SFB__SIMD_NBX * SFB__SIMD_NBLOCK, SFB__SIMD_N_SEL(blend, bx, lx));  \
            SFB__SIMD_N_ST(at + SFB__SIMD_NBY * SFB__SIMD_NBLOCK, SFB__SIMD_N_SEL(blend, by, ly));  \
            SFB__SIMD_N_ST(at + SFB__SIMD_NBZ * SFB__SIMD_NBLOCK, SFB__SIMD_N_SEL(blend, bz, lz));  \
        }                                                                                           \
    }

/* portable (and 32-bit neon): one double per step */
#define SFB__SIMD_N_LD(p) (*(p))
#define SFB__SIMD_N_ST(p, v) (*(p) = (v))
#define SFB__SIMD_N_SET1(x) (x)
#define SFB__SIMD_N_ADD(a, b) ((a) + (b))
#define SFB__SIMD_N_SUB(a, b) ((a) - (b))
#define SFB__SIMD_N_MUL(a, b) ((a) * (b))
#define SFB__SIMD_N_DIV(a, b) ((a) / (b))
#define SFB__SIMD_N_SQRT(a) sqrt(a)
#define SFB__SIMD_N_GT(a, b) ((a) > (b))
#define SFB__SIMD_N_SEL(m, a, b) ((m) ? (a) : (b))
SFB__SIMD_NORMALS_VEC(sfb__simd_nvec_portable, , 1, double, int)
#undef SFB__SIMD_N_LD
#undef SFB__SIMD_N_ST
#undef SFB__SIMD_N_SET1
#undef SFB__SIMD_N_ADD
#undef SFB__SIMD_N_SUB
#undef SFB__SIMD_N_MUL
#undef SFB__SIMD_N_DIV
#undef SFB__SIMD_N_SQRT
#undef SFB__SIMD_N_GT
#undef SFB__SIMD_N_SEL

#ifdef SFB__SIMD_SSE2
#define SFB__SIMD_N_LD(p) _mm_loadu_pd(p)
#define SFB__SIMD_N_ST(p, v) _mm_storeu_pd(p, v)
#define SFB__SIMD_N_SET1(x) _mm_set1_pd(x)
#define SFB__SIMD_N_ADD(a, b) _mm_add_pd(a, b)
#define SFB__SIMD_N_SUB(a, b) _mm_sub_pd(a, b)
#define SFB__SIMD_N_MUL(a, b) _mm_mul_pd(a, b)
#define SFB__SIMD_N_DIV(a, b) _mm_div_pd(a, b)
#define SFB__SIMD_N_SQRT(a) _mm_sqrt_pd(a)
#define SFB__SIMD_N_GT(a, b) _mm_cmpgt_pd(a, b)
#define SFB__SIMD_N_SEL(m, a, b) _mm_or_pd(_mm_and_pd(m, a), _mm_andnot_pd(m, b))
SFB__SIMD_NORMALS_VEC(sfb__simd_nvec_sse2, , 2, __m128d, __m128d)
#undef SFB__SIMD_N_LD
#undef SFB__SIMD_N_ST
#undef SFB__SIMD_N_SET1
#undef SFB__SIMD_N_ADD
#undef SFB__SIMD_N_SUB
#undef SFB__SIMD_N_MUL
#undef SFB__SIMD_N_DIV
#undef SFB__SIMD_N_SQRT
#undef SFB__SIMD_N_GT
#undef SFB__SIMD_N_SEL
#endif

#ifdef SFB__SIMD_X86_DISPATCH
#define SFB__SIMD_N_LD(p) _mm256_loadu_pd(p)
#define SFB__SIMD_N_ST(p, v) _mm256_storeu_pd(p, v)
#define SFB__SIMD_N_SET1(x) _mm256_set1_pd(x)
#define SFB__SIMD_N_ADD(a, b) _mm256_add_pd(a, b)
#define SFB__SIMD_N_SUB(a, b) _mm256_sub_pd(a, b)
#define SFB__SIMD_N_MUL(a, b) _mm256_mul_pd(a, b)
#define SFB__SIMD_N_DIV(a, b) _mm256_div_pd(a, b)
#define SFB__SIMD_N_SQRT(a) _mm256_sqrt_pd(a)
#define SFB__SIMD_N_GT(a, b) _mm256_cmp_pd(a, b, _CMP_GT_OQ)
#define SFB__SIMD_N_SEL(m, a, b) _mm256_blendv_pd(b, a, m)
SFB__SIMD_NORMALS_VEC(sfb__simd_nvec_avx2, SFB__SIMD_TARGET_AVX2, 4, __m256d, __m256d)
#undef SFB__SIMD_N_LD
#undef SFB__SIMD_N_ST
#undef SFB__SIMD_N_SET1
#undef SFB__SIMD_N_ADD
#undef SFB__SIMD_N_SUB
#undef SFB__SIMD_N_MUL
#undef SFB__SIMD_N_DIV
#undef SFB__SIMD_N_SQRT
#undef SFB__SIMD_N_GT
#undef SFB__SIMD_N_SEL

#define SFB__SIMD_N_LD(p) _mm512_loadu_pd(p)
#define SFB__SIMD_N_ST(p, v) _mm512_storeu_pd(p, v)
#define SFB__SIMD_N_SET1(x) _mm512_set1_pd(x)
#define SFB__SIMD_N_ADD(a, b) _mm512_add_pd(a, b)
#define SFB__SIMD_N_SUB(a, b) _mm512_sub_pd(a, b)
#define SFB__SIMD_N_MUL(a, b) _mm512_mul_pd(a, b)
#define SFB__SIMD_N_DIV(a, b) _mm512_div_pd(a, b)
#define SFB__SIMD_N_SQRT(a) _mm512_sqrt_pd(a)
#define SFB__SIMD_N_GT(a, b) _mm512_cmp_pd_mask(a, b, _CMP_GT_OQ)
#define SFB__SIMD_N_SEL(m, a, b) _mm512_mask_blend_pd(m, b, a)
SFB__SIMD_NORMALS_VEC(sfb__simd_nvec_avx512, SFB__SIMD_TARGET_AVX512, 8, __m512d, __mmask8)
#undef SFB__SIMD_N_LD
#undef SFB__SIMD_N_ST
#undef SFB__SIMD_N_SET1
#undef SFB__SIMD_N_ADD
#undef SFB__SIMD_N_SUB
#undef SFB__SIMD_N_MUL
#undef SFB__SIMD_N_DIV
#undef SFB__SIMD_N_SQRT
#undef SFB__SIMD_N_GT
#undef SFB__SIMD_N_SEL
#endif /* SFB__SIMD_X86_DISPATCH */

#if defined(SFB__SIMD_NEON) && defined(__aarch64__)
#define SFB__SIMD_NEON_F64 1
#define SFB__SIMD_N_LD(p) vld1q_f64(p)
#define SFB__SIMD_N_ST(p, v) vst1q_f64(p, v)
#define SFB__SIMD_N_SET1(x) vdupq_n_f64(x)
#define SFB__SIMD_N_ADD(a, b) vaddq_f64(a, b)
#define SFB__SIMD_N_SUB(a, b) vsubq_f64(a, b)
#define SFB__SIMD_N_MUL(a, b) vmulq_f64(a, b)
#define SFB__SIMD_N_DIV(a, b) vdivq_f64(a, b)
#define SFB__SIMD_N_SQRT(a) vsqrtq_f64(a)
#define SFB__SIMD_N_GT(a, b) vcgtq_f64(a, b)
#define SFB__SIMD_N_SEL(m, a, b) vbslq_f64(m, a, b)
SFB__SIMD_NORMALS_VEC(sfb__simd_nvec_neon, , 2, float64x2_t, uint64x2_t)
#undef SFB__SIMD_N_LD
#undef SFB__SIMD_N_ST
#undef SFB__SIMD_N_SET1
#undef SFB__SIMD_N_ADD
#undef SFB__SIMD_N_SUB
#undef SFB__SIMD_N_MUL
#undef SFB__SIMD_N_DIV
#undef SFB__SIMD_N_SQRT
#undef SFB__SIMD_N_GT
#undef SFB__SIMD_N_SEL
#endif
#undef SFB__SIMD_NORMALS_VEC
#undef SFB__SIMD_NUNIT

/* The vector pass of the state's instruction set. */
static sfb__simd_nvec_fn sfb__simd_normals_select(int isa) {
    switch (isa) {
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: return sfb__simd_nvec_sse2;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2: return sfb__simd_nvec_avx2;
    case SFB__SIMD_AVX512: return sfb__simd_nvec_avx512;
#endif
#ifdef SFB__SIMD_NEON_F64
    case SFB__SIMD_ISA_NEON: return sfb__simd_nvec_neon;
#endif
    default: return sfb__simd_nvec_portable;
    }
}

/* Elements [first, last) of the job with vector pass `vec`. */
static void sfb__simd_normals_range(const sfb__simd_njob *j, int first, int last, sfb__simd_nvec_fn vec) {
    double blk[SFB__SIMD_NARRAYS * SFB__SIMD_NBLOCK];
    int i0;
    for (i0 = first; i0 < last; i0 += SFB__SIMD_NBLOCK) {
        const int n = last - i0 < SFB__SIMD_NBLOCK ? last - i0 : SFB__SIMD_NBLOCK;
        sfb__simd_normals_gather(j, i0, n, blk);
        vec(blk, (n + 7) & ~7);
        sfb__simd_normals_scatter(j, i0, n, blk);
    }
}

#ifdef SFB__SIMD_THREADS
static void sfb__simd_normals_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    sfb__simd_normals_range((const sfb__simd_njob *)arg, a, b, sfb__simd_normals_select(s->isa));
}
#endif

static sfb_result sfb__simd_finish_normals(void *state, int first, int last, const float *tu, const float *tv, const float *ns,
                                           const int *ns_index, const float *b, float p, float *out_blend, float *out_limit,
                                           float *out_sub) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    sfb__simd_njob j;
    if (!s || first < 0 || first > last) return SFB_INVALID_ARGS;
    if (first == last) return SFB_SUCCESS;
    if (!tu || !tv || !out_blend || (ns_index && !ns)) return SFB_INVALID_ARGS;
    j.tu = tu;
    j.tv = tv;
    j.ns = ns;
    j.b = b;
    j.ns_index = ns_index;
    j.p = p;
    j.pmode = p == 1.0f ? 1 : p == 2.0f ? 2 : p == 3.0f ? 3 : p == 0.5f ? 4 : 0;
    j.blend = out_blend;
    j.limit = out_limit;
    j.sub = out_sub;
#ifdef SFB__SIMD_THREADS
    if (last - first >= SFB__SIMD_INLINE_NORMALS && sfb__simd_pool_run(s, sfb__simd_normals_task, &j, first, last, NULL, 0, 0))
        return SFB_SUCCESS;
#endif
    sfb__simd_normals_range(&j, first, last, sfb__simd_normals_select(s->isa));
    return SFB_SUCCESS;
}

static void sfb__simd_normals_bind(sfb__backend_vtable *vt) { vt->finish_normals = sfb__simd_finish_normals; }
