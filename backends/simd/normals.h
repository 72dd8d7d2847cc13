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
 *   2. the vector pass, written once on the double lanes of sfb_simd.h's vector operations
 *      (2 lanes sse2 and AArch64 neon, 4 avx2, 8 avx512, 1 portable and 32-bit neon),
 *      normalises L and S, forms B = (1 - w) L + w S and normalises
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

/* Pass 2, written once on the double lanes of the vector operations (sfb_simd.h): X##_W lanes
 * per step. */
#define SFB__SIMD_NUNIT(X, x, y, z)                                                                      \
    do {                                                                                                 \
        const X##_v len_ = X##_sqrt(X##_add(X##_add(X##_mul(x, x), X##_mul(y, y)), X##_mul(z, z)));      \
        const X##_m nz_ = X##_gt(len_, zero);                                                            \
        const X##_v inv_ = X##_div(one, X##_sel(nz_, len_, one));                                        \
        x = X##_sel(nz_, X##_mul(x, inv_), zero);                                                        \
        y = X##_sel(nz_, X##_mul(y, inv_), zero);                                                        \
        z = X##_sel(nz_, X##_mul(z, inv_), zero);                                                        \
    } while (0)
#define SFB__SIMD_NORMALS_DEFINE(X, ATTR)                                                               \
    ATTR static void X##_normals_vec(double *blk, int count) {                                          \
        const X##_v zero = X##_set1(0.0), one = X##_set1(1.0), nob = X##_set1(-0.5);                   \
        int m;                                                                                          \
        for (m = 0; m < count; m += X##_W) {                                                            \
            double *at = blk + m;                                                                       \
            X##_v lx = X##_loadu(at + SFB__SIMD_NLX * SFB__SIMD_NBLOCK);                                \
            X##_v ly = X##_loadu(at + SFB__SIMD_NLY * SFB__SIMD_NBLOCK);                                \
            X##_v lz = X##_loadu(at + SFB__SIMD_NLZ * SFB__SIMD_NBLOCK);                                \
            X##_v sx = X##_loadu(at + SFB__SIMD_NSX * SFB__SIMD_NBLOCK);                                \
            X##_v sy = X##_loadu(at + SFB__SIMD_NSY * SFB__SIMD_NBLOCK);                                \
            X##_v sz = X##_loadu(at + SFB__SIMD_NSZ * SFB__SIMD_NBLOCK);                                \
            const X##_v wb = X##_loadu(at + SFB__SIMD_NW * SFB__SIMD_NBLOCK);                           \
            const X##_m blend = X##_gt(wb, nob);                                                        \
            const X##_v w = X##_sel(blend, wb, zero), w1 = X##_sub(one, w);                             \
            X##_v bx, by, bz;                                                                           \
            SFB__SIMD_NUNIT(X, lx, ly, lz);                                                             \
            SFB__SIMD_NUNIT(X, sx, sy, sz);                                                             \
            bx = X##_add(X##_mul(w1, lx), X##_mul(w, sx));                                              \
            by = X##_add(X##_mul(w1, ly), X##_mul(w, sy));                                              \
            bz = X##_add(X##_mul(w1, lz), X##_mul(w, sz));                                              \
            SFB__SIMD_NUNIT(X, bx, by, bz);                                                             \
            X##_storeu(at + SFB__SIMD_NLX * SFB__SIMD_NBLOCK, lx);                                      \
            X##_storeu(at + SFB__SIMD_NLY * SFB__SIMD_NBLOCK, ly);                                      \
            X##_storeu(at + SFB__SIMD_NLZ * SFB__SIMD_NBLOCK, lz);                                      \
            X##_storeu(at + SFB__SIMD_NSX * SFB__SIMD_NBLOCK, sx);                                      \
            X##_storeu(at + SFB__SIMD_NSY * SFB__SIMD_NBLOCK, sy);                                      \
            X##_storeu(at + SFB__SIMD_NSZ * SFB__SIMD_NBLOCK, sz);                                      \
            X##_storeu(at + SFB__SIMD_NBX * SFB__SIMD_NBLOCK, X##_sel(blend, bx, lx));                  \
            X##_storeu(at + SFB__SIMD_NBY * SFB__SIMD_NBLOCK, X##_sel(blend, by, ly));                  \
            X##_storeu(at + SFB__SIMD_NBZ * SFB__SIMD_NBLOCK, X##_sel(blend, bz, lz));                  \
        }                                                                                               \
    }

/* portable (and 32-bit neon): one double per step; sse2 and AArch64 neon 2, avx2 4, avx512 8 */
SFB__SIMD_NORMALS_DEFINE(sfb__vpd, )
#ifdef SFB__SIMD_SSE2
SFB__SIMD_NORMALS_DEFINE(sfb__vsd, )
#endif
#ifdef SFB__SIMD_X86_DISPATCH
SFB__SIMD_NORMALS_DEFINE(sfb__vad, SFB__SIMD_TARGET_AVX2)
SFB__SIMD_NORMALS_DEFINE(sfb__vzd, SFB__SIMD_TARGET_AVX512)
#endif
#ifdef SFB__SIMD_VN
SFB__SIMD_NORMALS_DEFINE(sfb__vnd, )
#endif
#undef SFB__SIMD_NORMALS_DEFINE
#undef SFB__SIMD_NUNIT

/* The vector pass of the state's instruction set. */
static sfb__simd_nvec_fn sfb__simd_normals_select(int isa) {
    switch (isa) {
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: return sfb__vsd_normals_vec;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2: return sfb__vad_normals_vec;
    case SFB__SIMD_AVX512: return sfb__vzd_normals_vec;
#endif
#ifdef SFB__SIMD_VN
    case SFB__SIMD_ISA_NEON: return sfb__vnd_normals_vec;
#endif
    default: return sfb__vpd_normals_vec;
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
