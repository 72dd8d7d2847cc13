/* backends/simd/stencils.h -- the simd backend's stencil family: eval_stencils (dst rows =
 * weighted sums of src elements), kernels per instruction set. Part of backends/simd/sfb_simd.h.
 *
 * Work layout: every kernel walks rows in order and keeps a row's components in vector lanes
 * (xyz in 3 lanes of 4), one index and one weight per source entry; lengths above 4 are done
 * 4 (sse2, neon, portable) or 8 (avx2) components per pass over the rows, or 8/16 at once
 * (avx512). For lengths <= 4, avx2 puts two entries side by side in a 256-bit register and
 * avx512 four in a 512-bit one, which is what makes them faster than one entry per step.
 *
 * Numerics: float accumulation from 0 (ref accumulates in double), row by row:
 *   portable, neon, and avx2/avx512 for lengths > 4: one sum per component, entries in
 *     stored order;
 *   sse2 (all lengths) and avx2 (lengths <= 4): two partial sums, even and odd entries,
 *     added at the end of the row, then the last entry when the count is odd;
 *   avx512 (lengths <= 4): four partial sums s0..s3 of the entries k = 0..3 mod 4 (with the
 *     count's remainder entries added to s0 afterwards), combined as (s0 + s2) + (s1 + s3).
 * avx2, avx512 and neon on AArch64 use fused multiply-add, sse2, portable and 32-bit neon a
 * rounded product then a sum. So the kernels differ from each other and from ref in the last
 * float bits: relative differences of ~1e-7 of the largest term, far below the 1e-5 x bounding
 * box diagonal agreement target.
 *
 * Memory bounds: a source element is read only inside [src_desc.offset, src_desc.offset +
 * (sources-1)*stride + length), and only the `length` components of each destination row are
 * written (other components in the stride are the caller's). avx2 and avx512 load with masks
 * (vmaskmovps / AVX-512 zero-masking: masked-off lanes are neither read nor faulted on). sse2
 * and neon use full 4-float loads, which may read a little past an element's `length`
 * components into the next element or the caller's padding (lanes then ignored), only for
 * sources whose whole load lies in the range above (sfb__simd_safe_count); the last source
 * or two take an exact partial load instead. Stores are exact: partial or masked.
 */

#define SFB__SIMD_INLINE_ENTRIES 32768 /* calls with fewer entries stay on the caller's thread */

/* One call's arguments, offsets already applied. */
typedef struct sfb__simd_job {
    const int *sizes, *offsets, *indices;
    const float *weights;
    const float *src;  /* src + src_desc.offset */
    float *dst;        /* dst + dst_desc.offset */
    size_t sstride, dstride;
    int length, sources;
} sfb__simd_job;

/* Applies rows [first, last) of the job. */
typedef void (*sfb__simd_kernel)(const sfb__simd_job *job, int first, int last);

#if defined(SFB__SIMD_SSE2) || defined(SFB__SIMD_NEON)
/* Sources i in [0, result) may be read with a `span`-float load at src + i*sstride without
 * leaving the source range [0, (sources-1)*sstride + length). */
static int sfb__simd_safe_count(const sfb__simd_job *j, int span) {
    size_t end, n;
    if (j->sources <= 0) return 0;
    end = (size_t)(j->sources - 1) * j->sstride + (size_t)j->length;
    if (end < (size_t)span) return 0;
    n = (end - (size_t)span) / j->sstride + 1;
    return n < (size_t)j->sources ? (int)n : j->sources;
}
#endif

/* ---- portable ---- */
/* Components [c, c+m) (m <= 4) of every row, in four scalar accumulators. */
static void sfb__simd_portable_span(const sfb__simd_job *j, int first, int last, int c, int m) {
    int r, k;
    for (r = first; r < last; ++r) {
        const int *idx = j->indices + j->offsets[r];
        const float *w = j->weights + j->offsets[r];
        const int n = j->sizes[r];
        float *out = j->dst + (size_t)r * j->dstride + c;
        float a0 = 0.0f, a1 = 0.0f, a2 = 0.0f, a3 = 0.0f;
        for (k = 0; k < n; ++k) {
            const float *p = j->src + (size_t)idx[k] * j->sstride + c;
            const float wk = w[k];
            a0 += wk * p[0];
            if (m > 1) a1 += wk * p[1];
            if (m > 2) a2 += wk * p[2];
            if (m > 3) a3 += wk * p[3];
        }
        out[0] = a0;
        if (m > 1) out[1] = a1;
        if (m > 2) out[2] = a2;
        if (m > 3) out[3] = a3;
    }
}

static void sfb__simd_portable(const sfb__simd_job *j, int first, int last) {
    int c;
    for (c = 0; c < j->length; c += 4) sfb__simd_portable_span(j, first, last, c, j->length - c < 4 ? j->length - c : 4);
}

/* ---- sse2 (and the 128-bit helpers shared with avx2) ---- */
#ifdef SFB__SIMD_SSE2
/* Loads n (1..4) floats, zeroing the other lanes; reads exactly n floats. */
static __m128 sfb__simd_sse2_load_n(const float *p, int n) {
    switch (n) {
    case 1: return _mm_load_ss(p);
    case 2: return _mm_unpacklo_ps(_mm_load_ss(p), _mm_load_ss(p + 1));
    case 3: return _mm_movelh_ps(_mm_unpacklo_ps(_mm_load_ss(p), _mm_load_ss(p + 1)), _mm_load_ss(p + 2));
    default: return _mm_loadu_ps(p);
    }
}

/* Stores the first n (1..4) lanes; writes exactly n floats. */
static void sfb__simd_sse2_store_n(float *p, __m128 v, int n) {
    switch (n) {
    case 1: _mm_store_ss(p, v); break;
    case 2: _mm_storel_pi((__m64 *)(void *)p, v); break;
    case 3:
        _mm_storel_pi((__m64 *)(void *)p, v);
        _mm_store_ss(p + 2, _mm_movehl_ps(v, v));
        break;
    default: _mm_storeu_ps(p, v); break;
    }
}

/* Components [c, c+4) (c+4 may pass `length`) of every row, one 4-lane accumulator. Full
 * loads for sources below `safe`, partial loads of the `m` valid floats above it. */
static void sfb__simd_sse2_span(const sfb__simd_job *j, int first, int last, int c, int m, unsigned safe) {
    int r, k;
    for (r = first; r < last; ++r) {
        const int *idx = j->indices + j->offsets[r];
        const float *w = j->weights + j->offsets[r];
        const int n = j->sizes[r];
        const float *base = j->src + c;
        __m128 acc = _mm_setzero_ps(), acc1 = _mm_setzero_ps();
        for (k = 0; k + 2 <= n; k += 2) {
            const float *p = base + (size_t)idx[k] * j->sstride;
            const float *q = base + (size_t)idx[k + 1] * j->sstride;
            __m128 v = (unsigned)idx[k] < safe ? _mm_loadu_ps(p) : sfb__simd_sse2_load_n(p, m);
            __m128 u = (unsigned)idx[k + 1] < safe ? _mm_loadu_ps(q) : sfb__simd_sse2_load_n(q, m);
            acc = _mm_add_ps(acc, _mm_mul_ps(_mm_set1_ps(w[k]), v));
            acc1 = _mm_add_ps(acc1, _mm_mul_ps(_mm_set1_ps(w[k + 1]), u));
        }
        acc = _mm_add_ps(acc, acc1);
        if (k < n) {
            const float *p = base + (size_t)idx[k] * j->sstride;
            __m128 v = (unsigned)idx[k] < safe ? _mm_loadu_ps(p) : sfb__simd_sse2_load_n(p, m);
            acc = _mm_add_ps(acc, _mm_mul_ps(_mm_set1_ps(w[k]), v));
        }
        sfb__simd_sse2_store_n(j->dst + (size_t)r * j->dstride + c, acc, m);
    }
}

static void sfb__simd_sse2(const sfb__simd_job *j, int first, int last) {
    const int L = j->length;
    const unsigned safe = (unsigned)sfb__simd_safe_count(j, (L + 3) & ~3);
    int c;
    /* Lengths over 4: one pass over the rows per 4 components (entries re-read from cache). */
    for (c = 0; c < L; c += 4) sfb__simd_sse2_span(j, first, last, c, L - c < 4 ? L - c : 4, safe);
}
#endif /* SFB__SIMD_SSE2 */

/* ---- avx2 + fma ---- */
/* Loads are masked (vmaskmovps: no fault and no read on the lanes left out), so exactly
 * `length` floats of each source are read and no bound is needed. */
#ifdef SFB__SIMD_X86_DISPATCH
static const int sfb__simd_avx2_masks[16] = {-1, -1, -1, -1, -1, -1, -1, -1, 0, 0, 0, 0, 0, 0, 0, 0};

/* Lengths up to 4: two entries per step, one in each 128-bit half of a 256-bit accumulator
 * (entries k, k+2, ... in the low half, k+1, k+3, ... in the high half; the halves are
 * added at the end of the row, then an odd last entry). */
SFB__SIMD_TARGET_AVX2 static void sfb__simd_avx2_4(const sfb__simd_job *j, int first, int last) {
    const __m128i part = _mm_loadu_si128((const __m128i *)(const void *)(sfb__simd_avx2_masks + 8 - j->length));
    const __m256i spread = _mm256_set_epi32(1, 1, 1, 1, 0, 0, 0, 0);
    const float *src = j->src;
    const size_t st = j->sstride;
    int r, k;
    for (r = first; r < last; ++r) {
        const int *idx = j->indices + j->offsets[r];
        const float *w = j->weights + j->offsets[r];
        const int n = j->sizes[r];
        __m256 acc2 = _mm256_setzero_ps();
        __m128 acc;
        for (k = 0; k + 2 <= n; k += 2) {
            __m256 v = _mm256_castps128_ps256(_mm_maskload_ps(src + (size_t)idx[k] * st, part));
            __m128 w2 = _mm_loadl_pi(_mm_setzero_ps(), (const __m64 *)(const void *)(w + k));
            v = _mm256_insertf128_ps(v, _mm_maskload_ps(src + (size_t)idx[k + 1] * st, part), 1);
            acc2 = _mm256_fmadd_ps(_mm256_permutevar8x32_ps(_mm256_castps128_ps256(w2), spread), v, acc2);
        }
        acc = _mm_add_ps(_mm256_castps256_ps128(acc2), _mm256_extractf128_ps(acc2, 1));
        if (k < n) acc = _mm_fmadd_ps(_mm_set1_ps(w[k]), _mm_maskload_ps(src + (size_t)idx[k] * st, part), acc);
        sfb__simd_sse2_store_n(j->dst + (size_t)r * j->dstride, acc, j->length);
    }
}

/* Components [c, c+m) (m <= 8) of every row, one 8-lane accumulator. */
SFB__SIMD_TARGET_AVX2 static void sfb__simd_avx2_span8(const sfb__simd_job *j, int first, int last, int c, int m) {
    const __m256i part = _mm256_loadu_si256((const __m256i *)(const void *)(sfb__simd_avx2_masks + 8 - m));
    const float *src = j->src + c;
    const size_t st = j->sstride;
    int r, k;
    for (r = first; r < last; ++r) {
        const int *idx = j->indices + j->offsets[r];
        const float *w = j->weights + j->offsets[r];
        const int n = j->sizes[r];
        float *out = j->dst + (size_t)r * j->dstride + c;
        __m256 acc = _mm256_setzero_ps();
        for (k = 0; k < n; ++k)
            acc = _mm256_fmadd_ps(_mm256_set1_ps(w[k]), _mm256_maskload_ps(src + (size_t)idx[k] * st, part), acc);
        if (m > 4) {
            _mm_storeu_ps(out, _mm256_castps256_ps128(acc));
            sfb__simd_sse2_store_n(out + 4, _mm256_extractf128_ps(acc, 1), m - 4);
        } else {
            sfb__simd_sse2_store_n(out, _mm256_castps256_ps128(acc), m);
        }
    }
}

SFB__SIMD_TARGET_AVX2 static void sfb__simd_avx2(const sfb__simd_job *j, int first, int last) {
    const int L = j->length;
    int c;
    if (L <= 4) {
        sfb__simd_avx2_4(j, first, last);
        return;
    }
    /* Longer: one pass over the rows per 8 components (the entries are re-read from cache). */
    for (c = 0; c < L; c += 8) sfb__simd_avx2_span8(j, first, last, c, L - c < 8 ? L - c : 8);
}

/* ---- avx512 (F + VL) ---- */
/* Zero-masked loads and masked stores touch exactly `length` floats: no bound to check. */

/* Lengths up to 4: four entries per step, one in each 128-bit lane of a 512-bit accumulator
 * (lane i sums entries k = i mod 4, then the 1-3 entries left over go to lane 0); the lanes
 * are added as (0 + 2) + (1 + 3) at the end of the row. (The maskz forms of permutexvar,
 * broadcast and shuffle avoid g++ 12's maybe-uninitialized warnings on the plain intrinsics'
 * undefined fill, GCC bug 105593.) */
SFB__SIMD_TARGET_AVX512 static void sfb__simd_avx512_4(const sfb__simd_job *j, int first, int last) {
    const __mmask8 m = (__mmask8)((1u << j->length) - 1u);
    const __m512i spread = _mm512_set_epi32(3, 3, 3, 3, 2, 2, 2, 2, 1, 1, 1, 1, 0, 0, 0, 0);
    const __mmask16 all = (__mmask16)0xFFFF;
    const float *src = j->src;
    const size_t st = j->sstride;
    int r, k;
    for (r = first; r < last; ++r) {
        const int *idx = j->indices + j->offsets[r];
        const float *w = j->weights + j->offsets[r];
        const int n = j->sizes[r];
        __m512 acc = _mm512_setzero_ps();
        for (k = 0; k + 4 <= n; k += 4) {
            __m512 v = _mm512_castps128_ps512(_mm_maskz_loadu_ps(m, src + (size_t)idx[k] * st));
            __m512 w4 = _mm512_maskz_permutexvar_ps(all, spread, _mm512_maskz_broadcast_f32x4(all, _mm_loadu_ps(w + k)));
            v = _mm512_insertf32x4(v, _mm_maskz_loadu_ps(m, src + (size_t)idx[k + 1] * st), 1);
            v = _mm512_insertf32x4(v, _mm_maskz_loadu_ps(m, src + (size_t)idx[k + 2] * st), 2);
            v = _mm512_insertf32x4(v, _mm_maskz_loadu_ps(m, src + (size_t)idx[k + 3] * st), 3);
            acc = _mm512_fmadd_ps(w4, v, acc);
        }
        for (; k < n; ++k)
            acc = _mm512_fmadd_ps(_mm512_set1_ps(w[k]), _mm512_maskz_loadu_ps(m, src + (size_t)idx[k] * st), acc);
        acc = _mm512_add_ps(acc, _mm512_maskz_shuffle_f32x4(all, acc, acc, _MM_SHUFFLE(1, 0, 3, 2)));
        acc = _mm512_add_ps(acc, _mm512_maskz_shuffle_f32x4(all, acc, acc, _MM_SHUFFLE(2, 3, 0, 1)));
        _mm512_mask_storeu_ps(j->dst + (size_t)r * j->dstride, m, acc);
    }
}

SFB__SIMD_TARGET_AVX512 static void sfb__simd_avx512_8(const sfb__simd_job *j, int first, int last) {
    const __mmask8 m = (__mmask8)((1u << j->length) - 1u);
    int r, k;
    for (r = first; r < last; ++r) {
        const int *idx = j->indices + j->offsets[r];
        const float *w = j->weights + j->offsets[r];
        const int n = j->sizes[r];
        __m256 acc = _mm256_setzero_ps();
        for (k = 0; k < n; ++k)
            acc = _mm256_fmadd_ps(_mm256_set1_ps(w[k]), _mm256_maskz_loadu_ps(m, j->src + (size_t)idx[k] * j->sstride), acc);
        _mm256_mask_storeu_ps(j->dst + (size_t)r * j->dstride, m, acc);
    }
}

SFB__SIMD_TARGET_AVX512 static void sfb__simd_avx512_16(const sfb__simd_job *j, int first, int last) {
    const __mmask16 m = (__mmask16)((1u << j->length) - 1u);
    int r, k;
    for (r = first; r < last; ++r) {
        const int *idx = j->indices + j->offsets[r];
        const float *w = j->weights + j->offsets[r];
        const int n = j->sizes[r];
        __m512 acc = _mm512_setzero_ps();
        for (k = 0; k < n; ++k)
            acc = _mm512_fmadd_ps(_mm512_set1_ps(w[k]), _mm512_maskz_loadu_ps(m, j->src + (size_t)idx[k] * j->sstride), acc);
        _mm512_mask_storeu_ps(j->dst + (size_t)r * j->dstride, m, acc);
    }
}

SFB__SIMD_TARGET_AVX512 static void sfb__simd_avx512(const sfb__simd_job *j, int first, int last) {
    if (j->length <= 4) sfb__simd_avx512_4(j, first, last);
    else if (j->length <= 8) sfb__simd_avx512_8(j, first, last);
    else sfb__simd_avx512_16(j, first, last);
}
#endif /* SFB__SIMD_X86_DISPATCH */

/* ---- neon ---- */
#ifdef SFB__SIMD_NEON
#  if defined(__aarch64__) || defined(__ARM_FEATURE_FMA)
#    define SFB__SIMD_NEON_MADD(acc, w, v) vfmaq_f32(acc, w, v)
#  else
#    define SFB__SIMD_NEON_MADD(acc, w, v) vmlaq_f32(acc, w, v)
#  endif
static void sfb__simd_neon_span(const sfb__simd_job *j, int first, int last, int c, int m, unsigned safe) {
    int r, k;
    for (r = first; r < last; ++r) {
        const int *idx = j->indices + j->offsets[r];
        const float *w = j->weights + j->offsets[r];
        const int n = j->sizes[r];
        const float *base = j->src + c;
        float tmp[4];
        float32x4_t acc = vdupq_n_f32(0.0f);
        for (k = 0; k < n; ++k) {
            const float *p = base + (size_t)idx[k] * j->sstride;
            float32x4_t v;
            if ((unsigned)idx[k] < safe) {
                v = vld1q_f32(p);
            } else { /* partial: copy the m valid floats */
                tmp[0] = tmp[1] = tmp[2] = tmp[3] = 0.0f;
                memcpy(tmp, p, (size_t)m * sizeof(float));
                v = vld1q_f32(tmp);
            }
            acc = SFB__SIMD_NEON_MADD(acc, vdupq_n_f32(w[k]), v);
        }
        if (m == 4) {
            vst1q_f32(j->dst + (size_t)r * j->dstride + c, acc);
        } else {
            vst1q_f32(tmp, acc);
            memcpy(j->dst + (size_t)r * j->dstride + c, tmp, (size_t)m * sizeof(float));
        }
    }
}

static void sfb__simd_neon(const sfb__simd_job *j, int first, int last) {
    const int L = j->length;
    const unsigned safe = (unsigned)sfb__simd_safe_count(j, (L + 3) & ~3);
    int c;
    for (c = 0; c < L; c += 4) sfb__simd_neon_span(j, first, last, c, L - c < 4 ? L - c : 4, safe);
}
#endif /* SFB__SIMD_NEON */

/* The kernel of the state's instruction set (sfb__simd_choose_isa checked that it runs here). */
static sfb__simd_kernel sfb__simd_stencils_select(int isa) {
    switch (isa) {
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: return sfb__simd_sse2;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2: return sfb__simd_avx2;
    case SFB__SIMD_AVX512: return sfb__simd_avx512;
#endif
#ifdef SFB__SIMD_NEON
    case SFB__SIMD_ISA_NEON: return sfb__simd_neon;
#endif
    default: return sfb__simd_portable;
    }
}

#ifdef SFB__SIMD_THREADS
static void sfb__simd_stencil_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    sfb__simd_stencils_select(s->isa)((const sfb__simd_job *)arg, a, b);
}
#endif

static sfb_result sfb__simd_eval_stencils(void *state, const sfb__stencils *t, void *handle, int first, int last,
                                          const float *src, sfb_buffer_desc sd, float *dst, sfb_buffer_desc dd) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    sfb__simd_job j;
    (void)handle;
    if (!s || sd.length != dd.length || sd.length <= 0 || sd.length > 16 || sd.stride < sd.length ||
        dd.stride < dd.length || sd.offset < 0 || dd.offset < 0 || first < 0 || last > t->rows)
        return SFB_INVALID_ARGS;
    if (first >= last) return SFB_SUCCESS;
    j.sizes = t->sizes;
    j.offsets = t->offsets;
    j.indices = t->indices;
    j.weights = t->weights;
    j.src = src + sd.offset;
    j.dst = dst + dd.offset;
    j.sstride = (size_t)sd.stride;
    j.dstride = (size_t)dd.stride;
    j.length = sd.length;
    j.sources = t->sources;
#ifdef SFB__SIMD_THREADS
    {
        /* offsets[rows] is not stored: the range ends where its last row's entries end */
        const size_t e0 = (size_t)t->offsets[first];
        const size_t e1 = (size_t)t->offsets[last - 1] + (size_t)t->sizes[last - 1];
        if (e1 - e0 >= SFB__SIMD_INLINE_ENTRIES && sfb__simd_pool_run(s, sfb__simd_stencil_task, &j, first, last, t->offsets, e0, e1 - e0))
            return SFB_SUCCESS;
    }
#endif
    sfb__simd_stencils_select(s->isa)(&j, first, last);
    return SFB_SUCCESS;
}

static void sfb__simd_stencils_bind(sfb__backend_vtable *vt) { vt->eval_stencils = sfb__simd_eval_stencils; }
