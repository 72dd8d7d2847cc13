/* backends/sfb_simd.h -- the `simd` backend: stencil tables applied, patch tables evaluated
 * (limit evaluation of Catmull-Clark and Loop, eval_patches: see "limit evaluation" below; the
 * MANIFOLD4 blends of manifold-based blending surfaces: see "manifold blending" below; second
 * derivatives of those run the ref kernel), and seed 001's normal blend (finish_normals: see
 * "normal blend" below), with SIMD kernels on a small thread pool.
 *
 * Not a public header: surfblend.h compiles this file at the end of its implementation when
 * SURFBLEND_SIMD (or SURFBLEND_ALL_BACKENDS) is defined with SURFBLEND_IMPLEMENTATION. It sees
 * the core's private declarations (src/sfb_internal.h); do not include it directly.
 *
 * Kernels (one instruction set per backend state, chosen at init):
 *   portable  plain C, any compiler and CPU
 *   sse2      x86-64 baseline (also 32-bit x86 built with SSE2)
 *   avx2      AVX2 + FMA        } compiled with __attribute__((target)) on GCC >= 6 and Clang,
 *   avx512    AVX-512 F + VL    } so the translation unit needs no -m flags; used when
 *                                 __builtin_cpu_supports says the CPU (and OS) run them.
 *                                 Other compilers (MSVC) get sse2 and portable only.
 *   neon      ARM NEON (when __ARM_NEON is defined at compile time)
 * The best one available is used. SURFBLEND_SIMD_ISA=portable|sse2|avx2|avx512|neon forces
 * one (for tests); it is read even with ignore_environment, which is about SURFBLEND_BACKEND
 * only. An unknown or unavailable name is logged (warning) and the best one is used.
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
 *
 * Threads: a pool of ctx->threads - 1 workers (0: one thread per online core, at most 64;
 * 1: no pool), started in init and joined in shutdown. A call cuts its rows into 4 chunks per
 * thread of about equal entry counts (from offsets; eval_patches and finish_normals: equal
 * numbers of locations or elements); the caller and the workers claim chunks until none is
 * left, and the caller returns once every claimed chunk is done (it never waits for a worker
 * still asleep). Calls under 32768 entries (eval_patches: 4096 locations; finish_normals:
 * 8192 elements) run on the caller alone, as
 * do calls made while another thread's call holds the pool (pthread_mutex_trylock), so
 * concurrent calls on one backend state are safe. On _WIN32, and wherever POSIX threads are
 * not known to exist, the backend runs single-threaded (describe says "1 thread"). A process
 * that forks must not use a context created before the fork in the child (no workers there).
 */
#ifndef SFB__SIMD_H
#define SFB__SIMD_H

/* ---- what can be compiled here ---- */
#if defined(__SSE2__) || defined(_M_X64) || defined(_M_AMD64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2)
#  define SFB__SIMD_SSE2 1
#  include <emmintrin.h>
#  if (defined(__x86_64__) || defined(__i386__)) && (defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 6)) && \
      !defined(_MSC_VER) /* clang-cl: __builtin_cpu_supports needs a runtime it does not link */
#    define SFB__SIMD_X86_DISPATCH 1 /* avx2 / avx512 via target attributes + __builtin_cpu_supports */
#    include <immintrin.h>
#    define SFB__SIMD_TARGET_AVX2 __attribute__((target("avx2,fma")))
#    define SFB__SIMD_TARGET_AVX512 __attribute__((target("avx2,fma,avx512f,avx512vl")))
#  endif
#endif
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
#  define SFB__SIMD_NEON 1
#  include <arm_neon.h>
#endif
#if !defined(_WIN32) && (defined(__unix__) || defined(__unix) || defined(__APPLE__))
#  define SFB__SIMD_THREADS 1
#  include <pthread.h>
#  include <unistd.h>
#endif

#define SFB__SIMD_MAX_THREADS 64
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

/* ==== limit evaluation: eval_patches ====
 *
 * (Catmull-Clark and Loop tables. A manifold-blending table (MANIFOLD4 patches) shares the
 * quadtree copy and the thread pool but packs and runs its own kernel: see "manifold blending".)
 *
 * Data packed at upload_patches (sfb__simd_patches), read-only afterwards:
 *   blk     xyzw points in "grids" of columns: point (i, j) (i along u, j along v) of a 4x4
 *           B-spline control net at blk + i * cs + 4 * j (cs, the column stride, in floats), so
 *           that the four points of a column are 64 contiguous bytes (one AVX-512 load, two
 *           AVX2 loads, four 128-bit loads).
 *           - a B-spline patch: its 16 points (cs = 16; 256 bytes, 64-byte aligned);
 *           - a Stam patch (EV at frame corner c): for each level n = 1..SFB__SIMD_STAM_LEVELS
 *             one 5 x 5 grid (cs = 20; 400 bytes) of the level-n points around the EV: the
 *             three sub-patches k = 1, 2, 3 of that level are the 4 x 4 windows at lattice
 *             (0,-1), (0,0), (-1,0) (the EV at (0,0)), 24 distinct points (the corner (-1,-1)
 *             is unused). Their control points Q[j] = sum_i lambda_i^(n-1) phi_k[j][i] c_i are
 *             computed in double once, so a location near an EV costs what a B-spline
 *             location costs. (Upload checks that the windows agree on their shared points;
 *             a patch whose eigen data said otherwise would be left to the ref kernel.)
 *           Points are stored relative to the grid's origin o (the centroid, in float):
 *           differences of nearby points then keep float's relative precision however far the
 *           patch lies from the coordinate origin and however deep it is, which is what lets
 *           float derivatives and normals agree with ref's double ones. The w lanes of the
 *           window diagonal (0,0), (1,1), (2,2), (3,3) hold o.x, o.y, o.z and E, the largest
 *           |coordinate| of the grid's relative points (the scale of float's rounding errors);
 *           the three Stam windows have disjoint diagonals, so every window finds them there.
 *           Other w lanes are 0; the kernels' w lanes are never stored as results.
 *           Loop tables (triangles) use "triangles" of 16 xyzw points (64 floats, 256 bytes,
 *           64-byte aligned): the 15 control points of a quartic Bezier triangle in the
 *           table's order (row j = 0..4 by row in t, i = 0..4-j rising in s), relative to
 *           their centroid o, then (o.x, o.y, o.z, 4 E) as point 15 (E as above, times
 *           SFB__SIMD_TRI_EFACTOR; at float 63, where 3 cs + 15 finds it with cs = 16).
 *           - a Bezier triangle patch (BEZTRI): its 15 points;
 *           - a Stam-Loop patch (EV at frame corner c): for each level n = 1..
 *             SFB__SIMD_LOOP_LEVELS the three sub-patches k = 0, 1, 2 of that level as
 *             triangles (192 floats per level), control points Q[j] = sum_i (lambda_i^m
 *             phi_k[j][i] + m lambda_i^(m-1) phi_k[j][head_i]) c_i, m = n - 1 (the second term
 *             for the second vector of a Jordan block), computed in double once. (Upload
 *             checks that the sub-patches agree on their shared edges, as for Stam.)
 *   root, node  a copy of the table's quadtree (ptex_root, nodes) whose leaves say directly
 *           what to run: -(code + 1) with code = offset / 4 << 4 | corner << 2 | kind, kind 0
 *           B-spline grid, 1 Stam grids (Stam-Loop triangles in a Loop table), 2 the ref
 *           kernel (end caps, holes), 3 a Bezier triangle. One dependent load less per
 *           location than going through the patch arrays.
 * Everything is derived from the table's point_data at upload time (the table is immutable).
 * Locations nearer an EV than level SFB__SIMD_STAM_LEVELS (a 4^-L share of a Stam patch) are
 * evaluated from the eigen structure in double (sfb__simd_stam_far; Stam-Loop beyond
 * SFB__SIMD_LOOP_LEVELS: sfb__simd_loop_far); the EV itself, end caps (quad and triangle)
 * and degenerate normals go to the ref kernel, one location at a time.
 *
 * Numerics. Locating is done in float and is exact (u, v are floats; doubling, and subtracting
 * 1 from a value in [1,2), are exact), so the patch and (s, t) are ref's; so are a Stam
 * location's level and sub-patch (see sfb__simd_prep). The B-spline sums run in float on the
 * relative points (errors ~1e-7 of the patch size). Triangles are located in double with
 * ref's operations (sfb__simd_prep_tri: the same patch, (s, t), Stam-Loop level and
 * sub-patch), and their kernels run de Casteljau in double on the float relative points: a
 * quartic's second derivatives (12 x second differences, times 4^depth) lose too much in
 * float at depth 8, and in double they cost AVX2/AVX-512 about as many instructions (one xyzw
 * point per 256-bit register). A normal is made from float tangents only when the estimated angle
 * error, ~2e-7 E (|Pu| + |Pv|) / |Pu x Pv|, is below 1e-4 rad (triangles: 4 E, their
 * derivatives weigh the points by up to 8 where a B-spline's weigh them by 1); otherwise
 * (collapsed or nearly parallel tangents, overflow, NaN) the location goes to ref, whose
 * double evaluation and degenerate-tangent rule then decide the normal.
 *
 * Kernels: avx512 (a column of 4 points per register), avx2 (2 points per register), sse2
 * (xyz in 4 lanes per point; no FMA); these finish (scale, rotate, normal, stores) in 128-bit
 * registers. portable and neon evaluate into a float[6][4] and finish in scalar C (double).
 * Triangles: one point per 256-bit register of doubles (avx2, avx512), two 128-bit ones (sse2,
 * neon on AArch64), scalar double (portable, 32-bit neon).
 * Locations are prepared (located, grids prefetched) SFB__SIMD_AHEAD ahead of the kernel, so
 * that the loads of several locations are in flight at once. Threads: the locations are cut
 * into equal chunks over the pool (calls under SFB__SIMD_INLINE_LOCATIONS stay on the caller). */
#define SFB__SIMD_STAM_LEVELS 3
#define SFB__SIMD_LOOP_LEVELS 3     /* Stam-Loop levels packed (192 floats each) */
#define SFB__SIMD_TRI_EFACTOR 4.0f  /* a triangle's E is scaled by this for the normal test */
#define SFB__SIMD_INLINE_LOCATIONS 4096
#define SFB__SIMD_AHEAD 16
enum { SFB__SIMD_LEAF_BSPLINE = 0, SFB__SIMD_LEAF_STAM = 1, SFB__SIMD_LEAF_REF = 2, SFB__SIMD_LEAF_TRI = 3 };

typedef struct sfb__simd_patches {
    int npatch, nptex;
    int mf;            /* a manifold table: blk holds records (see "manifold blending" below) */
    int *root, *node;  /* nptex, 4 * nnodes: the quadtree with leaf codes */
    float *blk;        /* grids, 64-byte aligned inside raw */
    void *raw;
    size_t bytes;      /* everything above */
} sfb__simd_patches;

/* Evaluates the 4 x 4 window at blk (column stride cs) at (s, t): r[0] position (origin
 * added), r[1..2] d/ds, d/dt, r[3..5] second derivatives (only when `second`) in the window's
 * own parameters; lanes 0..2. (The generic range loop's kernel: portable, neon.) */
typedef void (*sfb__simd_bs_fn)(const float *blk, int cs, float s, float t, int second, float r[6][4]);
/* The same for a quartic Bezier triangle at blk (15 points, then the origin; see the layout). */
typedef void (*sfb__simd_tri_fn)(const float *blk, float s, float t, int second, float r[6][4]);

typedef struct sfb__simd_pjob {
    const sfb__patch_table *pt;
    const sfb__simd_patches *h;
    const sfb_location *locs;
    const sfb_eval_output *out;
    int second;        /* any of duu, duv, dvv asked */
    int tri;           /* a Loop table: triangle param faces */
    sfb__simd_bs_fn bs;
    sfb__simd_tri_fn tri_eval;
    void (*range)(const struct sfb__simd_pjob *j, int first, int last); /* what a pool chunk runs */
} sfb__simd_pjob;

typedef void (*sfb__simd_prange_fn)(const sfb__simd_pjob *j, int first, int last);

/* One location made ready for a kernel: the window, where to evaluate it, and how to map its
 * derivatives to the parametric face's: rotate by the Stam frame corner `rot`, (Ps, Pt) =
 * (Pu, Pv), (-Pv, Pu), (-Pu, -Pv), (Pv, -Pu) for rot 0..3, and for the Stam-Loop frames of
 * corners 1 and 2, rot 4: (-Pv, Pu - Pv), rot 5: (Pv - Pu, -Pu) (second derivatives likewise;
 * det 1, so the normal is unchanged), then multiply by dsc = 2^(n + depth) (Loop: negative
 * after an odd number of middle children). run: the square window kernel (KERNEL), the
 * triangle kernel (TRI: blk is a 16-point triangle, cs 16), or the double paths. */
enum { SFB__SIMD_RUN_REF = 0, SFB__SIMD_RUN_KERNEL = 1, SFB__SIMD_RUN_STAM_FAR = 2, SFB__SIMD_RUN_TRI = 3, SFB__SIMD_RUN_LOOP_FAR = 4 };
typedef struct sfb__simd_slot {
    const float *blk;
    float s, t, dsc;
    int cs, rot, run;
} sfb__simd_slot;

#if defined(__GNUC__) || defined(__clang__)
#  define SFB__SIMD_PREFETCH(p) __builtin_prefetch(p)
#  define SFB__SIMD_FORCEINLINE __attribute__((always_inline)) inline /* kernels into each range loop */
#else
#  define SFB__SIMD_PREFETCH(p) ((void)0)
#  define SFB__SIMD_FORCEINLINE inline
#endif

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

/* Location q on the ref kernel (rare cases; writes exactly q's three floats per output). */
static void sfb__simd_ref_one(const sfb__simd_pjob *j, int q) {
    sfb__ref_eval_patches(NULL, j->pt, NULL, j->locs, q, q + 1, j->out);
}

/* Writes location q (exactly three floats per asked output). */
static void sfb__simd_write(const sfb__simd_pjob *j, int q, double res[6][3], const double nrm[3]) {
    const sfb_eval_output *o = j->out;
    float *dst[7];
    const double *src[7];
    int k, c;
    dst[0] = o->position; dst[1] = o->du; dst[2] = o->dv; dst[3] = o->duu; dst[4] = o->duv; dst[5] = o->dvv; dst[6] = o->normal;
    for (k = 0; k < 6; ++k) src[k] = res[k];
    src[6] = nrm;
    for (k = 0; k < 7; ++k)
        if (dst[k])
            for (c = 0; c < 3; ++c) dst[k][3 * (size_t)q + c] = (float)src[k][c];
}

static double sfb__simd_ipow(double x, int m) {
    double r = 1.0;
    for (; m > 0; m >>= 1, x *= x)
        if (m & 1) r *= x;
    return r;
}

/* A Stam location nearer the EV than the stored levels: the eigen-structure sums of ref's
 * kernel in double (integer powers instead of pow, only the outputs asked for). The EV
 * itself and degenerate tangents go to ref. */
static void sfb__simd_stam_far(const sfb__simd_pjob *j, int q) {
    const sfb__patch_table *pt = j->pt;
    const sfb_location *l = &j->locs[q];
    double s, t, sc, u, v, uu, vv, J[2][2], bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4], w[6][16];
    double acc[6][3], res[6][3], nres[2][3], nrm[3], len, sub, sc1, sc2;
    const sfb__eigen_cc *e;
    const double *phi;
    const int *cv;
    const int p = sfb__patch_locate(pt, l->face, l->u, l->v, &s, &t, &sc), nw = j->second ? 6 : 3;
    int n = 1, k, i, jj, c, m;
    if (p < 0 || pt->ptype[p] != SFB__PATCH_STAM || !(e = pt->eig[pt->pvalence[p]])) { sfb__simd_ref_one(j, q); return; }
    switch (SFB__PARAM_CORNER(pt->pparam[p])) {
    default: u = s; v = t; J[0][0] = 1; J[0][1] = 0; J[1][0] = 0; J[1][1] = 1; break;
    case 1: u = t; v = 1.0 - s; J[0][0] = 0; J[0][1] = 1; J[1][0] = -1; J[1][1] = 0; break;
    case 2: u = 1.0 - s; v = 1.0 - t; J[0][0] = -1; J[0][1] = 0; J[1][0] = 0; J[1][1] = -1; break;
    case 3: u = 1.0 - t; v = s; J[0][0] = 0; J[0][1] = -1; J[1][0] = 1; J[1][1] = 0; break;
    }
    if (u == 0.0 && v == 0.0) { sfb__simd_ref_one(j, q); return; }
    while (u < 0.5 && v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
    if (v < 0.5) { k = 1; uu = 2.0 * u - 1.0; vv = 2.0 * v; }
    else if (u < 0.5) { k = 3; uu = 2.0 * u; vv = 2.0 * v - 1.0; }
    else { k = 2; uu = 2.0 * u - 1.0; vv = 2.0 * v - 1.0; }
    for (i = 0; i < 2; ++i) {
        const double x = i ? vv : uu, x2 = x * x, x3 = x2 * x, y = 1.0 - x;
        double *b = i ? bv : bu, *d = i ? dv : du, *dd = i ? ddv : ddu;
        b[0] = y * y * y / 6.0; b[1] = (3.0 * x3 - 6.0 * x2 + 4.0) / 6.0; b[2] = (-3.0 * x3 + 3.0 * x2 + 3.0 * x + 1.0) / 6.0; b[3] = x3 / 6.0;
        d[0] = -0.5 * y * y; d[1] = 1.5 * x2 - 2.0 * x; d[2] = -1.5 * x2 + x + 0.5; d[3] = 0.5 * x2;
        dd[0] = y; dd[1] = 3.0 * x - 2.0; dd[2] = -3.0 * x + 1.0; dd[3] = x;
    }
    for (jj = 0; jj < 16; ++jj) {
        const int a = jj % 4, b = jj / 4;
        w[0][jj] = bu[a] * bv[b]; w[1][jj] = du[a] * bv[b]; w[2][jj] = bu[a] * dv[b];
        w[3][jj] = ddu[a] * bv[b]; w[4][jj] = du[a] * dv[b]; w[5][jj] = bu[a] * ddv[b];
    }
    memset(acc, 0, sizeof acc);
    sub = e->sub;
    phi = e->phi + (size_t)(k - 1) * 16 * (size_t)e->K;
    cv = pt->cv + pt->pfirst[p];
    for (i = 0; i < e->K; ++i) {
        /* position: lambda^(n-1); derivatives normalised by sub^(n-1) (finite down to the EV) */
        const double lp = sfb__simd_ipow(e->lambda[i], n - 1), ln = i == e->dominant ? 0.0 : sfb__simd_ipow(e->lambda[i] / sub, n - 1);
        const float *pnt = pt->point_data + 3 * (size_t)cv[i];
        const double *ph = phi + i;
        double f[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        /* the eigenbasis function i and its derivatives at (uu, vv); named accumulators keep
         * the sums in registers */
        if (nw == 3) {
            double f0 = 0.0, f1 = 0.0, f2 = 0.0;
            for (jj = 0; jj < 16; ++jj, ph += e->K) { f0 += w[0][jj] * *ph; f1 += w[1][jj] * *ph; f2 += w[2][jj] * *ph; }
            f[0] = f0; f[1] = f1; f[2] = f2;
        } else {
            double f0 = 0.0, f1 = 0.0, f2 = 0.0, f3 = 0.0, f4 = 0.0, f5 = 0.0;
            for (jj = 0; jj < 16; ++jj, ph += e->K) {
                f0 += w[0][jj] * *ph; f1 += w[1][jj] * *ph; f2 += w[2][jj] * *ph;
                f3 += w[3][jj] * *ph; f4 += w[4][jj] * *ph; f5 += w[5][jj] * *ph;
            }
            f[0] = f0; f[1] = f1; f[2] = f2; f[3] = f3; f[4] = f4; f[5] = f5;
        }
        f[0] *= lp;
        for (m = 1; m < nw; ++m) f[m] *= ln;
        for (m = 0; m < nw; ++m)
            for (c = 0; c < 3; ++c) acc[m][c] += f[m] * pnt[c];
    }
    sc1 = sfb__simd_ipow(sub, n - 1) * ldexp(1.0, n) * sc;
    sc2 = sfb__simd_ipow(sub, n - 1) * ldexp(1.0, 2 * n) * sc * sc;
    for (c = 0; c < 3; ++c) {
        nres[0][c] = acc[1][c] * J[0][0] + acc[2][c] * J[1][0];
        nres[1][c] = acc[1][c] * J[0][1] + acc[2][c] * J[1][1];
    }
    nrm[0] = nres[0][1] * nres[1][2] - nres[0][2] * nres[1][1];
    nrm[1] = nres[0][2] * nres[1][0] - nres[0][0] * nres[1][2];
    nrm[2] = nres[0][0] * nres[1][1] - nres[0][1] * nres[1][0];
    len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (j->out->normal && !(len > 0.0 && len <= 1e300)) { sfb__simd_ref_one(j, q); return; }
    for (c = 0; c < 3; ++c) {
        const double Puu = acc[3][c], Puv = acc[4][c], Pvv = acc[5][c];
        if (j->out->normal) nrm[c] /= len;
        res[0][c] = acc[0][c];
        res[1][c] = nres[0][c] * sc1;
        res[2][c] = nres[1][c] * sc1;
        if (j->second) {
            res[3][c] = sc2 * (Puu * J[0][0] * J[0][0] + 2.0 * Puv * J[0][0] * J[1][0] + Pvv * J[1][0] * J[1][0]);
            res[4][c] = sc2 * (Puu * J[0][0] * J[0][1] + Puv * (J[0][0] * J[1][1] + J[0][1] * J[1][0]) + Pvv * J[1][0] * J[1][1]);
            res[5][c] = sc2 * (Puu * J[0][1] * J[0][1] + 2.0 * Puv * J[0][1] * J[1][1] + Pvv * J[1][1] * J[1][1]);
        } else {
            res[3][c] = res[4][c] = res[5][c] = 0.0;
        }
    }
    sfb__simd_write(j, q, res, nrm);
}

/* Quartic Bernstein basis on a triangle in double, the table's point order (row j by row in
 * t, s rising in a row): B[0..5][15] = value, d/ds, d/dt, d2/ds2, d2/dsdt, d2/dt2 (the last three
 * only when nw = 6). Powers up to 4 of s, t and w = 1 - s - t, and the binomial weights. */
static void sfb__simd_bez15(double s, double t, int nw, double B[6][15]) {
    static const double mult[15] = {1, 4, 6, 4, 1, 4, 12, 12, 4, 6, 12, 6, 4, 4, 1};
    double ps[5], pt[5], pw[5];
    int i, j, q = 0;
    const double w = 1.0 - s - t;
    ps[0] = pt[0] = pw[0] = 1.0;
    for (i = 1; i < 5; ++i) { ps[i] = ps[i - 1] * s; pt[i] = pt[i - 1] * t; pw[i] = pw[i - 1] * w; }
    for (j = 0; j <= 4; ++j)
        for (i = 0; i + j <= 4; ++i, ++q) {
            const int k = 4 - i - j;
            const double c = mult[q];
            /* s^a t^b w^c with negative exponents as 0 */
#define SFB__SIMD_M(a, b, e) ((a) < 0 || (b) < 0 || (e) < 0 ? 0.0 : ps[(a) < 0 ? 0 : (a)] * pt[(b) < 0 ? 0 : (b)] * pw[(e) < 0 ? 0 : (e)])
            B[0][q] = c * SFB__SIMD_M(i, j, k);
            B[1][q] = c * (i * SFB__SIMD_M(i - 1, j, k) - k * SFB__SIMD_M(i, j, k - 1));
            B[2][q] = c * (j * SFB__SIMD_M(i, j - 1, k) - k * SFB__SIMD_M(i, j, k - 1));
            if (nw > 3) {
                B[3][q] = c * (i * (i - 1) * SFB__SIMD_M(i - 2, j, k) - 2 * i * k * SFB__SIMD_M(i - 1, j, k - 1) + k * (k - 1) * SFB__SIMD_M(i, j, k - 2));
                B[4][q] = c * (i * j * SFB__SIMD_M(i - 1, j - 1, k) - i * k * SFB__SIMD_M(i - 1, j, k - 1) - j * k * SFB__SIMD_M(i, j - 1, k - 1) +
                               k * (k - 1) * SFB__SIMD_M(i, j, k - 2));
                B[5][q] = c * (j * (j - 1) * SFB__SIMD_M(i, j - 2, k) - 2 * j * k * SFB__SIMD_M(i, j - 1, k - 1) + k * (k - 1) * SFB__SIMD_M(i, j, k - 2));
            }
#undef SFB__SIMD_M
        }
}

/* A Stam-Loop location nearer the EV than the packed levels: ref's eigen-structure sums in
 * double (integer powers, the Jordan term of valence 3, only the outputs asked for). The EV
 * itself and degenerate tangents go to ref. */
static void sfb__simd_loop_far(const sfb__simd_pjob *j, int q) {
    const sfb__patch_table *pt = j->pt;
    const sfb_location *l = &j->locs[q];
    double s, t, sc, u, v, ss, tt, J[2][2], B[6][15], f[SFB__STAM_MAX_VALENCE + 6][6];
    double acc[6][3], res[6][3], nres[2][3], nrm[3], len, sub, subm, sign = 1.0, sc1, sc2;
    const sfb__eigen_loop *e;
    const double *phi;
    const int *cv;
    const int p = sfb__patch_locate(pt, l->face, l->u, l->v, &s, &t, &sc), nw = j->second ? 6 : 3;
    int n = 1, k, i, jj, c, m, w;
    if (p < 0 || pt->ptype[p] != SFB__PATCH_STAM_LOOP || !(e = pt->eigl[pt->pvalence[p]]) || e->K > SFB__STAM_MAX_VALENCE + 6) {
        sfb__simd_ref_one(j, q);
        return;
    }
    switch (SFB__PARAM_CORNER(pt->pparam[p])) {
    default: u = s; v = t; J[0][0] = 1; J[0][1] = 0; J[1][0] = 0; J[1][1] = 1; break;
    case 1: u = t; v = 1.0 - s - t; J[0][0] = 0; J[0][1] = 1; J[1][0] = -1; J[1][1] = -1; break;
    case 2: u = 1.0 - s - t; v = s; J[0][0] = -1; J[0][1] = -1; J[1][0] = 1; J[1][1] = 0; break;
    }
    if (u < 0.0) u = 0.0;
    if (v < 0.0) v = 0.0;
    if (u + v == 0.0) { sfb__simd_ref_one(j, q); return; }
    while (u + v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
    if (u >= 0.5) { k = 0; ss = 2.0 * u - 1.0; tt = 2.0 * v; }
    else if (v >= 0.5) { k = 1; ss = 2.0 * u; tt = 2.0 * v - 1.0; }
    else { k = 2; ss = 1.0 - 2.0 * u; tt = 1.0 - 2.0 * v; sign = -1.0; }
    m = n - 1;
    sfb__simd_bez15(ss, tt, nw, B);
    phi = e->phi + (size_t)k * 15 * (size_t)e->K;
    for (i = 0; i < e->K; ++i) {
        /* eigenbasis function i and its derivatives at (ss, tt); named accumulators keep the
         * sums in registers */
        const double *ph = phi + i;
        double f0 = 0.0, f1 = 0.0, f2 = 0.0, f3 = 0.0, f4 = 0.0, f5 = 0.0;
        if (nw == 3) {
            for (jj = 0; jj < 15; ++jj, ph += e->K) { f0 += B[0][jj] * *ph; f1 += B[1][jj] * *ph; f2 += B[2][jj] * *ph; }
        } else {
            for (jj = 0; jj < 15; ++jj, ph += e->K) {
                f0 += B[0][jj] * *ph; f1 += B[1][jj] * *ph; f2 += B[2][jj] * *ph;
                f3 += B[3][jj] * *ph; f4 += B[4][jj] * *ph; f5 += B[5][jj] * *ph;
            }
        }
        f[i][0] = f0; f[i][1] = f1; f[i][2] = f2; f[i][3] = f3; f[i][4] = f4; f[i][5] = f5;
    }
    memset(acc, 0, sizeof acc);
    sub = e->sub;
    subm = sfb__simd_ipow(sub, m);
    cv = pt->cv + pt->pfirst[p];
    for (i = 0; i < e->K; ++i) {
        /* position: lambda^m; derivatives normalised by sub^m (finite down to the EV) */
        const float *pnt = pt->point_data + 3 * (size_t)cv[i];
        const double lp = sfb__simd_ipow(e->lambda[i], m), ln = i == e->dominant ? 0.0 : sfb__simd_ipow(e->lambda[i] / sub, m);
        double g[6];
        for (w = 0; w < nw; ++w) g[w] = (w ? ln : lp) * f[i][w];
        if (e->head[i] >= 0 && m > 0) {
            /* the second vector of a Jordan block: m lambda^(m-1) of its head's function */
            const int hd = e->head[i];
            const double jl = m * sfb__simd_ipow(e->lambda[i], m - 1), jn = jl / subm;
            for (w = 0; w < nw; ++w) g[w] += (w ? jn : jl) * f[hd][w];
        }
        {
            const double x = pnt[0], y = pnt[1], z = pnt[2];
            for (w = 0; w < nw; ++w) { acc[w][0] += g[w] * x; acc[w][1] += g[w] * y; acc[w][2] += g[w] * z; }
        }
    }
    sc1 = subm * ldexp(1.0, n) * sc;
    sc2 = subm * ldexp(1.0, 2 * n) * sc * sc;
    for (c = 0; c < 3; ++c) {
        const double Pu = sign * acc[1][c], Pv = sign * acc[2][c];
        nres[0][c] = Pu * J[0][0] + Pv * J[1][0];
        nres[1][c] = Pu * J[0][1] + Pv * J[1][1];
    }
    nrm[0] = nres[0][1] * nres[1][2] - nres[0][2] * nres[1][1];
    nrm[1] = nres[0][2] * nres[1][0] - nres[0][0] * nres[1][2];
    nrm[2] = nres[0][0] * nres[1][1] - nres[0][1] * nres[1][0];
    len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (j->out->normal && !(len > 0.0 && len <= 1e300)) { sfb__simd_ref_one(j, q); return; }
    for (c = 0; c < 3; ++c) {
        const double Puu = acc[3][c], Puv = acc[4][c], Pvv = acc[5][c];
        if (j->out->normal) nrm[c] /= len;
        res[0][c] = acc[0][c];
        res[1][c] = nres[0][c] * sc1;
        res[2][c] = nres[1][c] * sc1;
        if (j->second) {
            res[3][c] = sc2 * (Puu * J[0][0] * J[0][0] + 2.0 * Puv * J[0][0] * J[1][0] + Pvv * J[1][0] * J[1][0]);
            res[4][c] = sc2 * (Puu * J[0][0] * J[0][1] + Puv * (J[0][0] * J[1][1] + J[0][1] * J[1][0]) + Pvv * J[1][0] * J[1][1]);
            res[5][c] = sc2 * (Puu * J[0][1] * J[0][1] + 2.0 * Puv * J[0][1] * J[1][1] + Pvv * J[1][1] * J[1][1]);
        } else {
            res[3][c] = res[4][c] = res[5][c] = 0.0;
        }
    }
    sfb__simd_write(j, q, res, nrm);
}

/* Locates location q (in float: exact, as above) and prepares its slot; prefetches the window. */
static void sfb__simd_prep(const sfb__simd_pjob *j, int q, sfb__simd_slot *o) {
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

/* prep for a Loop table: the triangle descent of sfb__patch_locate, in double with ref's very
 * operations (so the patch, (s, t) and the Stam-Loop level and sub-patch are ref's), without
 * branches on the child (random here): child c's (u, v) is sg (2u - a_u, 2v - a_v) with
 * sg = -1 for the middle child, whose 1 - 2u is -(2u - 1) exactly. */
static void sfb__simd_prep_tri(const sfb__simd_pjob *j, int q, sfb__simd_slot *o) {
    const sfb__simd_patches *h = j->h;
    const sfb_location *l = &j->locs[q];
    int node = h->root[l->face], code;
    double s = l->u, t = l->v, sc = 1.0;
    while (node >= 0) {
        const int c1 = s >= 0.5, c2 = !c1 & (t >= 0.5), c3 = !c1 & !c2 & !(s + t < 0.5);
        const double sg = c3 ? -1.0 : 1.0;
        s = (s + s - (double)(c1 | c3)) * sg;
        t = (t + t - (double)(c2 | c3)) * sg;
        sc = (sc + sc) * sg;
        node = h->node[4 * node + (c1 | 2 * c2 | 3 * c3)];
    }
    code = -node - 1;
    o->run = SFB__SIMD_RUN_REF;
    if ((code & 3) == SFB__SIMD_LEAF_TRI) {
        o->blk = h->blk + 4 * (size_t)(code >> 4);
        o->s = (float)s; o->t = (float)t; o->dsc = (float)sc; o->cs = 16; o->rot = 0;
        o->run = SFB__SIMD_RUN_TRI;
        SFB__SIMD_PREFETCH(o->blk);
        SFB__SIMD_PREFETCH(o->blk + 16);
        SFB__SIMD_PREFETCH(o->blk + 32);
        SFB__SIMD_PREFETCH(o->blk + 48);
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
        sg = c2 ? -1.0 : 1.0;
        o->s = (float)((u + u - (double)(c0 | c2)) * sg);
        o->t = (float)((v + v - (double)(c1 | c2)) * sg);
        o->blk = h->blk + 4 * (size_t)(code >> 4) + (size_t)(n - 1) * 192 + (size_t)(c1 + 2 * c2) * 64;
        o->dsc = (float)(sc * sg * lv * 2.0);
        o->cs = 16;
        o->rot = corner ? corner + 3 : 0;
        o->run = SFB__SIMD_RUN_TRI;
        SFB__SIMD_PREFETCH(o->blk);
        SFB__SIMD_PREFETCH(o->blk + 16);
        SFB__SIMD_PREFETCH(o->blk + 32);
        SFB__SIMD_PREFETCH(o->blk + 48);
    }
}

/* Unit normal from window tangents du, dv (lanes 0..2), or 0 where float cannot be trusted to
 * give it within ~1e-4 rad (see Numerics): |n| >= 2e-3 E (|du| + |dv|), using
 * (|du| + |dv|)^2 <= 2 (|du|^2 + |dv|^2). */
static int sfb__simd_unit_normal(const float *du, const float *dv, float E, double n[3]) {
    double a = 0.0, b = 0.0, c, e = (double)E;
    int k;
    n[0] = (double)du[1] * dv[2] - (double)du[2] * dv[1];
    n[1] = (double)du[2] * dv[0] - (double)du[0] * dv[2];
    n[2] = (double)du[0] * dv[1] - (double)du[1] * dv[0];
    for (k = 0; k < 3; ++k) { a += (double)du[k] * du[k]; b += (double)dv[k] * dv[k]; }
    c = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (!(c > 0.0 && c >= 8e-6 * e * e * (a + b) && c <= 1e300)) return 0;
    c = sqrt(c);
    for (k = 0; k < 3; ++k) n[k] /= c;
    return 1;
}

/* Finishes a window result r in double (portable, neon); returns 0, having written nothing,
 * where the normal must come from ref. */
static int sfb__simd_put_generic(const sfb__simd_pjob *j, int q, float r[6][4], const sfb__simd_slot *sl) {
    double res[6][3], nrm[3] = {0.0, 0.0, 0.0};
    const double d = sl->dsc, d2 = d * d;
    int c;
    if (j->out->normal && !sfb__simd_unit_normal(r[1], r[2], sl->blk[3 * sl->cs + 15], nrm)) return 0;
    for (c = 0; c < 3; ++c) {
        const double Pu = d * r[1][c], Pv = d * r[2][c];
        res[0][c] = r[0][c];
        switch (sl->rot) {
        default: res[1][c] = Pu; res[2][c] = Pv; break;
        case 1: res[1][c] = -Pv; res[2][c] = Pu; break;
        case 2: res[1][c] = -Pu; res[2][c] = -Pv; break;
        case 3: res[1][c] = Pv; res[2][c] = -Pu; break;
        case 4: res[1][c] = -Pv; res[2][c] = Pu - Pv; break;
        case 5: res[1][c] = Pv - Pu; res[2][c] = -Pu; break;
        }
        if (!j->second) {
            res[3][c] = res[4][c] = res[5][c] = 0.0;
        } else if (sl->rot == 4) {
            res[3][c] = d2 * r[5][c]; res[4][c] = d2 * ((double)r[5][c] - r[4][c]); res[5][c] = d2 * (((double)r[3][c] - 2.0 * r[4][c]) + r[5][c]);
        } else if (sl->rot == 5) {
            res[3][c] = d2 * (((double)r[3][c] - 2.0 * r[4][c]) + r[5][c]); res[4][c] = d2 * ((double)r[3][c] - r[4][c]); res[5][c] = d2 * r[3][c];
        } else if (sl->rot & 1) {
            res[3][c] = d2 * r[5][c]; res[4][c] = -d2 * r[4][c]; res[5][c] = d2 * r[3][c];
        } else {
            res[3][c] = d2 * r[3][c]; res[4][c] = d2 * r[4][c]; res[5][c] = d2 * r[5][c];
        }
    }
    sfb__simd_write(j, q, res, nrm);
    return 1;
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

/* Quartic Bezier triangle at (s, t) (a triangle of the layout above), in double: de Casteljau
 * steps on the points (convex combinations, weights w = 1 - s - t, s, t of the points (i, j),
 * (i + 1, j), (i, j + 1) of the row layout, in place) from degree 4 down: at degree 2 the
 * second derivatives are 12 x second differences, at degree 1 the first derivatives
 * 4 x differences, at degree 0 the point, to which the origin is added. The step lists
 * SFB__SIMD_DC4/3/2(X), X(to, from, above), are shared by every triangle kernel. */
#define SFB__SIMD_DC4(X) X(0, 0, 5) X(1, 1, 6) X(2, 2, 7) X(3, 3, 8) X(4, 5, 9) X(5, 6, 10) X(6, 7, 11) X(7, 9, 12) X(8, 10, 13) X(9, 12, 14)
#define SFB__SIMD_DC3(X) X(0, 0, 4) X(1, 1, 5) X(2, 2, 6) X(3, 4, 7) X(4, 5, 8) X(5, 7, 9)
#define SFB__SIMD_DC2(X) X(0, 0, 3) X(1, 1, 4) X(2, 3, 5)
static void sfb__simd_tri_portable(const float *blk, float s, float t, int second, float r[6][4]) {
    const double w = (1.0 - s) - t;
    double p[15][3];
    int a, c;
    for (a = 0; a < 15; ++a)
        for (c = 0; c < 3; ++c) p[a][c] = blk[4 * a + c];
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
        r[0][c] = (float)((t * p[2][c] + (s * p[1][c] + w * p[0][c])) + blk[60 + c]);
    }
}

static void sfb__simd_prange_generic(const sfb__simd_pjob *j, int first, int last) {
    sfb__simd_slot ring[SFB__SIMD_AHEAD];
    int q;
    for (q = first; q < last && q < first + SFB__SIMD_AHEAD; ++q) {
        if (j->tri) sfb__simd_prep_tri(j, q, &ring[q % SFB__SIMD_AHEAD]);
        else sfb__simd_prep(j, q, &ring[q % SFB__SIMD_AHEAD]);
    }
    for (q = first; q < last; ++q) {
        const sfb__simd_slot sl = ring[q % SFB__SIMD_AHEAD];
        float r[6][4];
        if (q + SFB__SIMD_AHEAD < last) {
            if (j->tri) sfb__simd_prep_tri(j, q + SFB__SIMD_AHEAD, &ring[q % SFB__SIMD_AHEAD]);
            else sfb__simd_prep(j, q + SFB__SIMD_AHEAD, &ring[q % SFB__SIMD_AHEAD]);
        }
        if (sl.run == SFB__SIMD_RUN_KERNEL || sl.run == SFB__SIMD_RUN_TRI) {
            if (sl.run == SFB__SIMD_RUN_TRI) j->tri_eval(sl.blk, sl.s, sl.t, j->second, r);
            else j->bs(sl.blk, sl.cs, sl.s, sl.t, j->second, r);
            if (!sfb__simd_put_generic(j, q, r, &sl)) sfb__simd_ref_one(j, q);
        } else if (sl.run == SFB__SIMD_RUN_STAM_FAR) {
            sfb__simd_stam_far(j, q);
        } else if (sl.run == SFB__SIMD_RUN_LOOP_FAR) {
            sfb__simd_loop_far(j, q);
        } else {
            sfb__simd_ref_one(j, q);
        }
    }
}

/* ---- sse2 (and the 128-bit finishing shared with avx2 and avx512) ---- */
#ifdef SFB__SIMD_SSE2
#define SFB__SIMD_BC(v, i) _mm_shuffle_ps(v, v, _MM_SHUFFLE(i, i, i, i))
#define SFB__SIMD_YZX(v) _mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 0, 2, 1))

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

/* Stores lanes 0..2 of v at dst[at..at+2]; with `full` a 4-float store, whose 4th float is the
 * next location's x, which the same range writes afterwards. */
static inline void sfb__simd_sse2_store3(float *dst, size_t at, __m128 v, int full) {
    if (full) {
        _mm_storeu_ps(dst + at, v);
    } else {
        _mm_storel_pi((__m64 *)(void *)(dst + at), v);
        _mm_store_ss(dst + at + 2, _mm_movehl_ps(v, v));
    }
}

/* Maps the derivatives (rotation, scale), makes the normal and stores location q from a window
 * result; returns 0, having written nothing, where the normal must come from ref. */
static SFB__SIMD_FORCEINLINE int sfb__simd_sse2_put(const sfb__simd_pjob *j, int q, int full, const __m128 r[6], const sfb__simd_slot *sl) {
    const sfb_eval_output *o = j->out;
    const size_t at = 3 * (size_t)q;
    const __m128 xyz = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
    const __m128 Pu = _mm_and_ps(r[1], xyz), Pv = _mm_and_ps(r[2], xyz), vsc = _mm_set1_ps(sl->dsc);
    __m128 du, dv;
    if (o->normal) {
        const float E = sl->blk[3 * sl->cs + 15];
        const __m128 n = SFB__SIMD_YZX(_mm_sub_ps(_mm_mul_ps(Pu, SFB__SIMD_YZX(Pv)), _mm_mul_ps(SFB__SIMD_YZX(Pu), Pv)));
        const __m128 x = _mm_mul_ps(Pu, Pu), y = _mm_mul_ps(Pv, Pv), z = _mm_mul_ps(n, n);
        __m128 ab = _mm_add_ps(_mm_unpacklo_ps(x, y), _mm_unpackhi_ps(x, y)); /* x0+x2 y0+y2 x1+x3 y1+y3 */
        __m128 cc = _mm_add_ps(z, _mm_movehl_ps(z, z));
        float a, b, c;
        ab = _mm_add_ps(ab, _mm_movehl_ps(ab, ab));
        cc = _mm_add_ss(cc, SFB__SIMD_BC(cc, 1));
        a = _mm_cvtss_f32(ab);
        b = _mm_cvtss_f32(SFB__SIMD_BC(ab, 1));
        c = _mm_cvtss_f32(cc);
        /* the float-trust test of sfb__simd_unit_normal, with c in float's comfortable range */
        if (!(c > 1e-30f && c <= 1e30f && c >= 8e-6f * E * E * (a + b))) return 0;
        sfb__simd_sse2_store3(o->normal, at, _mm_div_ps(n, _mm_sqrt_ps(SFB__SIMD_BC(cc, 0))), full);
    }
    {
        /* (Ps, Pt) = (a Pu + b Pv, c Pu + d Pv) dsc, (a, b, c, d) by frame (rot): a table, not
         * a branch (B-spline and Stam locations come in random order) */
        static const float rot[6][4] = {{1, 0, 0, 1}, {0, -1, 1, 0}, {-1, 0, 0, -1}, {0, 1, -1, 0}, {0, -1, 1, -1}, {-1, 1, -1, 0}};
        const __m128 k = _mm_mul_ps(_mm_loadu_ps(rot[sl->rot]), vsc);
        du = _mm_add_ps(_mm_mul_ps(Pu, SFB__SIMD_BC(k, 0)), _mm_mul_ps(Pv, SFB__SIMD_BC(k, 1)));
        dv = _mm_add_ps(_mm_mul_ps(Pu, SFB__SIMD_BC(k, 2)), _mm_mul_ps(Pv, SFB__SIMD_BC(k, 3)));
    }
    if (o->position) sfb__simd_sse2_store3(o->position, at, r[0], full);
    if (o->du) sfb__simd_sse2_store3(o->du, at, du, full);
    if (o->dv) sfb__simd_sse2_store3(o->dv, at, dv, full);
    if (j->second) {
        const __m128 sc2 = _mm_mul_ps(vsc, vsc);
        __m128 uu, uv, vv;
        if (sl->rot < 4) {
            const int odd = sl->rot & 1; /* frames turned by 90 degrees swap u and v */
            uu = _mm_mul_ps(odd ? r[5] : r[3], sc2);
            vv = _mm_mul_ps(odd ? r[3] : r[5], sc2);
            uv = _mm_mul_ps(r[4], odd ? _mm_xor_ps(sc2, _mm_set1_ps(-0.0f)) : sc2);
        } else if (sl->rot == 4) { /* Pss = Pvv, Pst = Pvv - Puv, Ptt = Puu - 2 Puv + Pvv */
            uu = _mm_mul_ps(r[5], sc2);
            uv = _mm_mul_ps(_mm_sub_ps(r[5], r[4]), sc2);
            vv = _mm_mul_ps(_mm_add_ps(_mm_sub_ps(r[3], _mm_add_ps(r[4], r[4])), r[5]), sc2);
        } else {                   /* Pss = Puu - 2 Puv + Pvv, Pst = Puu - Puv, Ptt = Puu */
            uu = _mm_mul_ps(_mm_add_ps(_mm_sub_ps(r[3], _mm_add_ps(r[4], r[4])), r[5]), sc2);
            uv = _mm_mul_ps(_mm_sub_ps(r[3], r[4]), sc2);
            vv = _mm_mul_ps(r[3], sc2);
        }
        if (o->duu) sfb__simd_sse2_store3(o->duu, at, uu, full);
        if (o->duv) sfb__simd_sse2_store3(o->duv, at, uv, full);
        if (o->dvv) sfb__simd_sse2_store3(o->dvv, at, vv, full);
    }
    return 1;
}

/* The quartic triangle kernel (see sfb__simd_tri_portable) in double, each point as two
 * registers (xy, zw); the signature of the window kernels (cs unused). */
static SFB__SIMD_FORCEINLINE void sfb__simd_sse2_tri(const float *blk, int cs, float s, float t, int second, __m128 r[6]) {
    const double sd = s, td = t;
    const __m128d vs = _mm_set1_pd(sd), vt = _mm_set1_pd(td), vw = _mm_set1_pd((1.0 - sd) - td);
    __m128d pl[15], ph[15];
    int a;
    (void)cs;
    for (a = 0; a < 15; ++a) {
        const __m128 v = _mm_loadu_ps(blk + 4 * a);
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
        const __m128 o = _mm_loadu_ps(blk + 60);
        r[1] = SFB__SIMD_PS2(_mm_mul_pd(four, _mm_sub_pd(pl[1], pl[0])), _mm_mul_pd(four, _mm_sub_pd(ph[1], ph[0])));
        r[2] = SFB__SIMD_PS2(_mm_mul_pd(four, _mm_sub_pd(pl[2], pl[0])), _mm_mul_pd(four, _mm_sub_pd(ph[2], ph[0])));
        r[0] = SFB__SIMD_PS2(_mm_add_pd(_mm_add_pd(_mm_mul_pd(vt, pl[2]), _mm_add_pd(_mm_mul_pd(vs, pl[1]), _mm_mul_pd(vw, pl[0]))), _mm_cvtps_pd(o)),
                             _mm_add_pd(_mm_add_pd(_mm_mul_pd(vt, ph[2]), _mm_add_pd(_mm_mul_pd(vs, ph[1]), _mm_mul_pd(vw, ph[0]))),
                                        _mm_cvtps_pd(_mm_movehl_ps(o, o))));
    }
#undef SFB__SIMD_DC_SSE2
#undef SFB__SIMD_PS2
}

/* The range loop of the 128-bit-finishing kernels. */
#define SFB__SIMD_PATCH_RANGE(NAME, ATTR, EVAL, TRI)                                                             \
    ATTR static void NAME(const sfb__simd_pjob *j, int first, int last) {                                        \
        sfb__simd_slot ring[SFB__SIMD_AHEAD];                                                                    \
        int q;                                                                                                   \
        for (q = first; q < last && q < first + SFB__SIMD_AHEAD; ++q) {                                          \
            if (j->tri) sfb__simd_prep_tri(j, q, &ring[q % SFB__SIMD_AHEAD]);                                    \
            else sfb__simd_prep(j, q, &ring[q % SFB__SIMD_AHEAD]);                                               \
        }                                                                                                        \
        for (q = first; q < last; ++q) {                                                                         \
            const sfb__simd_slot sl = ring[q % SFB__SIMD_AHEAD];                                                 \
            __m128 r[6];                                                                                         \
            if (q + SFB__SIMD_AHEAD < last) {                                                                    \
                if (j->tri) sfb__simd_prep_tri(j, q + SFB__SIMD_AHEAD, &ring[q % SFB__SIMD_AHEAD]);              \
                else sfb__simd_prep(j, q + SFB__SIMD_AHEAD, &ring[q % SFB__SIMD_AHEAD]);                         \
            }                                                                                                    \
            if (sl.run == SFB__SIMD_RUN_KERNEL) {                                                                \
                EVAL(sl.blk, sl.cs, sl.s, sl.t, j->second, r);                                                   \
                if (!sfb__simd_sse2_put(j, q, q + 1 < last, r, &sl)) sfb__simd_ref_one(j, q);                    \
            } else if (sl.run == SFB__SIMD_RUN_TRI) {                                                            \
                TRI(sl.blk, sl.cs, sl.s, sl.t, j->second, r);                                                    \
                if (!sfb__simd_sse2_put(j, q, q + 1 < last, r, &sl)) sfb__simd_ref_one(j, q);                    \
            } else if (sl.run == SFB__SIMD_RUN_STAM_FAR) {                                                       \
                sfb__simd_stam_far(j, q);                                                                        \
            } else if (sl.run == SFB__SIMD_RUN_LOOP_FAR) {                                                       \
                sfb__simd_loop_far(j, q);                                                                        \
            } else {                                                                                             \
                sfb__simd_ref_one(j, q);                                                                         \
            }                                                                                                    \
        }                                                                                                        \
    }

SFB__SIMD_PATCH_RANGE(sfb__simd_prange_sse2, , sfb__simd_sse2_eval, sfb__simd_sse2_tri)
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

/* The quartic triangle kernel (see sfb__simd_tri_portable) in double, one point (xyzw) per
 * 256-bit register: as many instructions as in float. Shared with avx512. */
#define SFB__SIMD_TRI_PD(NAME, ATTR)                                                                                 \
    ATTR static SFB__SIMD_FORCEINLINE void NAME(const float *blk, int cs, float s, float t, int second, __m128 r[6]) { \
        const double sd = s, td = t;                                                                                 \
        const __m256d vs = _mm256_set1_pd(sd), vt = _mm256_set1_pd(td), vw = _mm256_set1_pd((1.0 - sd) - td);      \
        __m256d p[15];                                                                                               \
        int a;                                                                                                       \
        (void)cs;                                                                                                    \
        for (a = 0; a < 15; ++a) p[a] = _mm256_cvtps_pd(_mm_loadu_ps(blk + 4 * a));                                 \
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
                                             _mm256_cvtps_pd(_mm_loadu_ps(blk + 60))));                              \
    }
#define SFB__SIMD_DC_PD(to, from, above) p[to] = _mm256_fmadd_pd(vt, p[above], _mm256_fmadd_pd(vs, p[(from) + 1], _mm256_mul_pd(vw, p[from])));
SFB__SIMD_TRI_PD(sfb__simd_avx2_tri, SFB__SIMD_TARGET_AVX2)
SFB__SIMD_PATCH_RANGE(sfb__simd_prange_avx2, SFB__SIMD_TARGET_AVX2, sfb__simd_avx2_eval, sfb__simd_avx2_tri)

/* ---- avx512: a whole column (4 points) per register ---- */
/* Sum of the four 128-bit lanes. (maskz forms: see the note on GCC bug 105593 above.) */
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

SFB__SIMD_TRI_PD(sfb__simd_avx512_tri, SFB__SIMD_TARGET_AVX512)
SFB__SIMD_PATCH_RANGE(sfb__simd_prange_avx512, SFB__SIMD_TARGET_AVX512, sfb__simd_avx512_eval, sfb__simd_avx512_tri)
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

#if defined(__aarch64__)
#define SFB__SIMD_TRI_NEON 1
/* The quartic triangle kernel (see sfb__simd_tri_portable) in double, each point as two
 * registers (xy, zw). (32-bit ARM, without double vectors, runs the portable one.) */
static void sfb__simd_tri_neon(const float *blk, float s, float t, int second, float r[6][4]) {
    const double sd = s, td = t;
    const float64x2_t vs = vdupq_n_f64(sd), vt = vdupq_n_f64(td), vw = vdupq_n_f64((1.0 - sd) - td);
    float64x2_t pl[15], ph[15];
    int a;
    for (a = 0; a < 15; ++a) {
        const float32x4_t v = vld1q_f32(blk + 4 * a);
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
        const float32x4_t o = vld1q_f32(blk + 60);
        SFB__SIMD_ST2(r[1], vmulq_n_f64(vsubq_f64(pl[1], pl[0]), 4.0), vmulq_n_f64(vsubq_f64(ph[1], ph[0]), 4.0));
        SFB__SIMD_ST2(r[2], vmulq_n_f64(vsubq_f64(pl[2], pl[0]), 4.0), vmulq_n_f64(vsubq_f64(ph[2], ph[0]), 4.0));
        SFB__SIMD_ST2(r[0], vaddq_f64(vfmaq_f64(vfmaq_f64(vmulq_f64(vw, pl[0]), vs, pl[1]), vt, pl[2]), vcvt_f64_f32(vget_low_f32(o))),
                      vaddq_f64(vfmaq_f64(vfmaq_f64(vmulq_f64(vw, ph[0]), vs, ph[1]), vt, ph[2]), vcvt_high_f64_f32(o)));
    }
#undef SFB__SIMD_DC_NEON
#undef SFB__SIMD_ST2
}
#endif
#endif /* SFB__SIMD_NEON */

/* ==== manifold blending: eval_patches on MANIFOLD4 tables (seed 000, src/manifold.c) ====
 *
 * The function is ref's sfb__mf_eval (src/manifold.c holds the spec), evaluated in float on W
 * locations at once, one location per vector lane (structure of arrays): W = 16 avx512, 8 avx2,
 * 4 sse2 and neon on AArch64, 1 portable and 32-bit neon.
 *
 * Data packed at upload_patches (sfb__simd_upload_mf): one record of SFB__SIMD_MF_REC floats
 * per patch (the seed's section V.1 texture, turned into the unified form of V.3):
 *   [0..2] the centre o (the mean of the four corner vertices, in float), [3], [4] the error
 *   scales of the normal test (below), then per corner j at SFB__SIMD_MF_CORNER(j) 27
 *   coefficient floats, rows r = 3m + n (coordinates x, y, z) of C in
 *   P = [1 u u^2] C [1 v v^2]^T, and the corner's constants:
 *     patch (no sharp edge): C as fitted, C_00 (the vertex) made relative to o; e = 4/k,
 *       (cos phi, sin phi) and e (cos phi, sin phi), phi = 2 pi h / k, and whether k = 4;
 *       (u, v) = the chart z = zeta^e e^(i phi) of the corner coordinates zeta = a + i b;
 *     curve (two sharp edges): the quadratic Bezier q0 q1 q2 in the power basis of its
 *       parameter sigma, rows 0..2 = (q0 - o, 2 (q1 - q0), q0 - 2 q1 + q2); u = 0 and
 *       v = sigma = s0 + sa a + sb b (s0 = 1/2, sa and sb = +-1/2 or 0 from the axes of e1 and
 *       e2 in this face);
 *     point: row 0 = the vertex - o, all else 0 (u = v = 0).
 *   So every corner is P = [1 u u^2] C [1 v v^2]^T with (u, v) chosen by kind, Table 2's
 *   vector pairs: a lane evaluates any kind without branching on it (selects).
 * The records sit after one zero record (offset 0: lanes that ref evaluates read it), and the
 * quadtree leaves (root, node, as for Catmull-Clark) hold -(offset / 4 << 4 | 0) - 1, or the
 * ref leaf for a patch that cannot be packed (a corner code or vertex out of range).
 *
 * Kernel: locations are located SFB__SIMD_MF_CHUNK at a time (float quadtree descent: exact,
 * the patch and (s, t) are ref's) ahead of the blocks. A block is the next W locations when
 * they share a patch (its record then read with broadcasts), or their leading run in one patch
 * when that holds at least W/4 (a face's samples in one quadrant of a depth-1 face), else W
 * locations reading their records with gathers. Per block: the weights eta(t), eta(1 - t),
 * eta'(t) at t = c and d (Hermite written (1 - t)^2 (1 + 2t) and t^2 (3 - 2t), accurate near
 * both ends; C-infinity 1 / (1 + E) and E / (1 + E), E = exp((2t - 1) / (t (1 - t))), the
 * exponent clamped to [-80, 80]); per corner its coordinates (a, b), the chart (valence 4:
 * z = zeta e^(i phi), no transcendental function; other valences, when a lane has one: polar
 * form, r^e = exp2(e/2 log2 r^2), theta = atan2(b, a) in the first quadrant, cos and sin of
 * e theta rotated by phi, polynomial approximations with errors below 2e-9 so that float
 * rounding dominates; dz/dzeta = e z / zeta, and ref's e e^(i phi) at zeta = 0), then
 * P, dP/da, dP/db (conformal for patches: d(u,v)/db = (-Im, Re) of dz/dzeta; curves:
 * (0, sa), (0, sb)) and the blend S, dS/dc, dS/dd (eq. 5 and the chain rule of sfb__mf_eval);
 * derivatives times 2^depth. Blocks skip the patch arithmetic of a corner where no lane has a
 * patch corner there. A lane's result does not depend on the other lanes of its block, so it
 * is the same bits whatever the batch, chunking or thread count.
 *
 * Numerics: coefficients relative to the record's centre keep positions to ~1e-7 of the patch
 * size wherever the patch lies. Lanes go to the ref kernel (sfb__simd_ref_one) where float
 * cannot be trusted: a non-valence-4 patch corner at 0 < |zeta|^2 < 1e-24 (zeta = 0 itself is
 * evaluated here, as ref does), and, when normals are asked, where the estimated error of the
 * float normal exceeds 1e-4 rad. The estimate: dS/dc has a float error ~ K eps E Gc, dS/dd
 * ~ K eps E Gd (E the record's largest coefficient, Gc and Gd the sums over the corners of
 * |wa| + |w| |d(u,v)/da| or |wb| + |w| |d(u,v)/db|, whichever feeds that derivative: the
 * weights of the coefficient terms in it), plus ref's own rounding where it is larger (below);
 * the angle error is then ~ (errc |Sd| + errd |Sc|) / |Sc x Sd|. That sends collapsed
 * tangents (a face corner at a point, dart or crease vertex, where ref takes the normal a step
 * inside), overflow and NaN to ref, and, with C-infinity weights, the strips along sharp edges
 * where a derivative is ~exp(-1/t) and below ref's double rounding (there ref's normal is its
 * rounding, which float cannot reproduce).
 * Second derivatives (duu, duv, dvv asked): the whole call runs ref's kernel (central
 * differences of its analytic first derivatives, in double) on the thread pool; a float
 * difference quotient would lose 3 to 4 digits.
 *
 * The kernel is written once (SFB__SIMD_MF_DEFINE) over a small set of vector operations,
 * X##_op with X the instruction set's prefix (sfb__vp portable, sfb__vs sse2, sfb__va avx2,
 * sfb__vz avx512, sfb__vn neon), each a line or two of intrinsics. */
#define SFB__SIMD_MF_REC 176                  /* floats per record (a multiple of 16: 64-byte aligned) */
#define SFB__SIMD_MF_CORNER(j) (8 + 40 * (j)) /* a corner's 27 coefficients, then its constants */
enum {
    SFB__SIMD_MF_E = 27, SFB__SIMD_MF_CPHI = 28, SFB__SIMD_MF_SPHI = 29, SFB__SIMD_MF_ECPHI = 30, SFB__SIMD_MF_ESPHI = 31,
    SFB__SIMD_MF_S0 = 32, SFB__SIMD_MF_SA = 33, SFB__SIMD_MF_SB = 34, SFB__SIMD_MF_ISPATCH = 35, SFB__SIMD_MF_UNIT = 36
};
#define SFB__SIMD_LEAF_MF 0 /* a manifold table's leaf kind: a record (other kinds: SFB__SIMD_LEAF_REF) */
/* The normal test: (errc |Sd| + errd |Sc|)^2 <= 2 (errc^2 |Sd|^2 + errd^2 |Sc|^2), so with
 * record[3] = sqrt(2) K eps E / 1e-4 and record[4] the same for the floor below, gc =
 * record[3] Gc + record[4] (and gd) and the test reads |Sc x Sd|^2 >= gc^2 |Sd|^2 + gd^2 |Sc|^2.
 * K = 2 from measurements: over the peer shapes the accepted lanes' normals agree with ref
 * within ~3e-5 rad, their derivatives within ~2e-5 relative. */
#define SFB__SIMD_MF_KEPS 1.2e-7 /* K eps: K = 2 float roundings of the largest term */
/* ref's own error where it exceeds ours: its derivative of the C-infinity eta is a difference
 * of products ~1, so ~1e-15 absolute even where the derivative itself is ~exp(-1/t), times
 * absolute positions: ~4e-15 (|o| + E) in dS/dc and dS/dd. The floor, GFLOOR K eps (|o| + E)
 * = 1.2e-14 (|o| + E), keeps a margin of 3. Where the true derivative is below that, ref's
 * normal is its rounding, and the lane goes to ref. */
#define SFB__SIMD_MF_GFLOOR 1e-7

/* Reads constant k of the record (or corner block) at p: a broadcast, or a gather over the
 * lanes' record offsets vidx (the kernel's `gather`, a constant after inlining). */
#define SFB__SIMD_MF_F(X, p, k) (gather ? X##_gather((p) + (k), vidx) : X##_set1((p)[k]))

#define SFB__SIMD_MF_CHUNK 128 /* locations located ahead of the blocks */
/* Locates locations [q, end) (end - q <= SFB__SIMD_MF_CHUNK) into off (record offsets; 0, the
 * zero record, for a ref leaf), cs, ds (the patch's (s, t)) and sc (2^depth) from index 0, with
 * 16 copies of the last one after them (the lanes of a block past `end`). The float descent of
 * sfb__simd_prep: exact, so the patch and (s, t) are ref's. */
static void sfb__simd_mf_locate(const sfb__simd_patches *h, const sfb_location *locs, int q, int end, int *off, float *cs, float *ds,
                                float *sc) {
    int i, l;
    for (i = 0; q + i < end; ++i) {
        const sfb_location *loc = &locs[q + i];
        int node = h->root[loc->face], code;
        float s = loc->u, t = loc->v, f = 1.0f;
        while (node >= 0) {
            int qx, qy;
            s += s; t += t; f += f;
            qx = s >= 1.0f; qy = t >= 1.0f;
            s -= (float)qx;
            t -= (float)qy;
            node = h->node[4 * node + qx + 2 * qy];
        }
        code = -node - 1;
        off[i] = (code & 3) == SFB__SIMD_LEAF_MF ? (code >> 4) * 4 : 0;
        cs[i] = s; ds[i] = t; sc[i] = f;
    }
    for (l = 0; l < 16; ++l) {
        off[i + l] = off[i - 1]; cs[i + l] = cs[i - 1]; ds[i + l] = ds[i - 1]; sc[i + l] = sc[i - 1];
    }
}

#define SFB__SIMD_MF_DEFINE(X, ATTR)                                                                                                                   \
/* 2^x, x clamped to [-126, 126] */                                                                                                                    \
ATTR static SFB__SIMD_FORCEINLINE X##_v X##_exp2(X##_v x) {                                                                                            \
    X##_v n, f, p;                                                                                                                                     \
    x = X##_min(X##_max(x, X##_set1(-126.0f)), X##_set1(126.0f));                                                                                      \
    n = X##_round(x);                                                                                                                                  \
    f = X##_sub(x, n);                                                                                                                                 \
    p = X##_fma(X##_set1(1.534640198e-4f), f, X##_set1(1.339993820e-3f));                                                                              \
    p = X##_fma(p, f, X##_set1(9.618486785e-3f));                                                                                                      \
    p = X##_fma(p, f, X##_set1(5.550328755e-2f));                                                                                                      \
    p = X##_fma(p, f, X##_set1(2.402264691e-1f));                                                                                                      \
    p = X##_fma(p, f, X##_set1(6.931472058e-1f));                                                                                                      \
    p = X##_fma(p, f, X##_set1(1.0f));                                                                                                                 \
    return X##_mul(p, X##_pow2i(n));                                                                                                                   \
}                                                                                                                                                      \
/* log2 x for normal x > 0: exponent + 2 atanh((m - 1) / (m + 1)) / ln 2, m in [sqrt(1/2), sqrt(2)) */                                                 \
ATTR static SFB__SIMD_FORCEINLINE X##_v X##_log2(X##_v x) {                                                                                            \
    X##_v m = X##_mant(x), e = X##_expo(x), y, z, p;                                                                                                   \
    const X##_m big = X##_gt(m, X##_set1(1.41421356f));                                                                                                \
    m = X##_sel(big, X##_mul(m, X##_set1(0.5f)), m);                                                                                                   \
    e = X##_sel(big, X##_add(e, X##_set1(1.0f)), e);                                                                                                   \
    y = X##_div(X##_sub(m, X##_set1(1.0f)), X##_add(m, X##_set1(1.0f)));                                                                               \
    z = X##_mul(y, y);                                                                                                                                 \
    p = X##_fma(X##_set1(1.0f / 9.0f), z, X##_set1(1.0f / 7.0f));                                                                                      \
    p = X##_fma(p, z, X##_set1(0.2f));                                                                                                                 \
    p = X##_fma(p, z, X##_set1(1.0f / 3.0f));                                                                                                          \
    p = X##_fma(p, z, X##_set1(1.0f));                                                                                                                 \
    return X##_fma(X##_mul(y, p), X##_set1(2.88539008f), e);                                                                                           \
}                                                                                                                                                      \
/* atan2(b, a) for a, b >= 0 (0 at a = b = 0): one division, |t| <= tan(pi/8) */                                                                       \
ATTR static SFB__SIMD_FORCEINLINE X##_v X##_angle(X##_v a, X##_v b) {                                                                                  \
    const X##_v mn = X##_min(a, b), mx = X##_max(a, b);                                                                                                \
    const X##_m big = X##_gt(mn, X##_mul(mx, X##_set1(0.414213562f)));                                                                                 \
    const X##_v t = X##_div(X##_sel(big, X##_sub(mn, mx), mn), X##_max(X##_sel(big, X##_add(mn, mx), mx), X##_set1(1e-37f)));                          \
    const X##_v z = X##_mul(t, t);                                                                                                                     \
    X##_v p = X##_fma(X##_set1(-0.0608424948f), z, X##_set1(0.105963986f));                                                                            \
    p = X##_fma(p, z, X##_set1(-0.142439180f));                                                                                                        \
    p = X##_fma(p, z, X##_set1(0.199984942f));                                                                                                         \
    p = X##_fma(p, z, X##_set1(-0.333333156f));                                                                                                        \
    p = X##_fma(X##_mul(t, z), p, t);                                                                                                                  \
    p = X##_sel(big, X##_add(p, X##_set1(0.785398163f)), p);                                                                                           \
    return X##_sel(X##_gt(b, a), X##_sub(X##_set1(1.57079633f), p), p);                                                                                \
}                                                                                                                                                      \
/* eta(t), eta(1 - t) and eta'(t) (= eta'(1 - t)) of the weights kind */                                                                               \
ATTR static SFB__SIMD_FORCEINLINE void X##_eta(X##_v t, const int cinf, X##_v *e0, X##_v *e1, X##_v *de) {                                             \
    const X##_v one = X##_set1(1.0f), ot = X##_sub(one, t);                                                                                            \
    if (!cinf) {                                                                                                                                       \
        *e0 = X##_mul(X##_mul(ot, ot), X##_fma(X##_set1(2.0f), t, one));                                                                               \
        *e1 = X##_mul(X##_mul(t, t), X##_fma(X##_set1(2.0f), ot, one));                                                                                \
        *de = X##_mul(X##_mul(X##_set1(-6.0f), t), ot);                                                                                                \
    } else {                                                                                                                                           \
        /* eta(t) = 1 / (1 + E), eta(1 - t) = E / (1 + E), E = exp((2t - 1) / (t (1 - t))) */                                                          \
        const X##_v m = X##_max(X##_mul(t, ot), X##_set1(1e-4f));                                                                                      \
        const X##_v x = X##_min(X##_max(X##_div(X##_sub(t, ot), m), X##_set1(-80.0f)), X##_set1(80.0f));                                               \
        const X##_v E = X##_exp2(X##_mul(x, X##_set1(1.44269504f)));                                                                                   \
        const X##_v r = X##_div(one, X##_add(one, E)), Er = X##_mul(E, r);                                                                             \
        *e0 = r;                                                                                                                                       \
        *e1 = Er;                                                                                                                                      \
        *de = X##_neg(X##_div(X##_mul(X##_mul(Er, r), X##_fma(t, t, X##_mul(ot, ot))), X##_mul(m, m)));                                                \
    }                                                                                                                                                  \
}                                                                                                                                                      \
/* The chart of a patch corner: (u, v) = zeta^e e^(i phi), (ar, ai) = dz/dzeta; lanes of patch                                                         \
 * corners at 0 < |zeta|^2 < 1e-24 are marked bad */                                                                                                   \
ATTR static SFB__SIMD_FORCEINLINE void X##_chart(X##_v a, X##_v b, X##_v e, X##_v cphi, X##_v sphi, X##_v ecphi, X##_v esphi,                          \
                                                 X##_m isp, X##_v *u, X##_v *v, X##_v *ar, X##_v *ai, X##_m *bad) {                                    \
    const X##_v zero = X##_zero(), r2 = X##_fma(a, a, X##_mul(b, b)), r2c = X##_max(r2, X##_set1(1e-37f));                                             \
    const X##_m at0 = X##_mand(X##_eq(a, zero), X##_eq(b, zero));                                                                                      \
    const X##_v rz = X##_exp2(X##_mul(X##_mul(X##_set1(0.5f), e), X##_log2(r2c)));                                                                     \
    /* y = e theta - pi/2 in [-pi/2, pi/2]: cos(e theta) = -sin y, sin(e theta) = cos y */                                                             \
    const X##_v y = X##_fma(e, X##_angle(a, b), X##_set1(-1.57079633f)), y2 = X##_mul(y, y);                                                           \
    X##_v sn = X##_fma(X##_set1(-2.39099661e-8f), y2, X##_set1(2.75266661e-6f)), cs;                                                                   \
    X##_v cr, sr, uu, vv, ia, ib, k;                                                                                                                   \
    sn = X##_fma(sn, y2, X##_set1(-1.98408952e-4f));                                                                                                   \
    sn = X##_fma(sn, y2, X##_set1(8.33333133e-3f));                                                                                                    \
    sn = X##_fma(sn, y2, X##_set1(-1.66666666e-1f));                                                                                                   \
    sn = X##_fma(X##_mul(y, y2), sn, y);                                                                                                               \
    cs = X##_fma(X##_set1(-2.60775814e-7f), y2, X##_set1(2.47619208e-5f));                                                                             \
    cs = X##_fma(cs, y2, X##_set1(-1.38884044e-3f));                                                                                                   \
    cs = X##_fma(cs, y2, X##_set1(4.16666408e-2f));                                                                                                    \
    cs = X##_fma(cs, y2, X##_set1(-4.99999996e-1f));                                                                                                   \
    cs = X##_fma(cs, y2, X##_set1(1.0f));                                                                                                              \
    cr = X##_neg(X##_fma(sn, cphi, X##_mul(cs, sphi)));                                                                                                \
    sr = X##_fnma(sn, sphi, X##_mul(cs, cphi));                                                                                                        \
    uu = X##_mul(rz, cr);                                                                                                                              \
    vv = X##_mul(rz, sr);                                                                                                                              \
    /* e z / zeta = e z conj(zeta) / |zeta|^2 */                                                                                                       \
    k = X##_div(e, r2c);                                                                                                                               \
    ia = X##_mul(a, k);                                                                                                                                \
    ib = X##_mul(b, k);                                                                                                                                \
    *u = X##_sel(at0, zero, uu);                                                                                                                       \
    *v = X##_sel(at0, zero, vv);                                                                                                                       \
    *ar = X##_sel(at0, ecphi, X##_fma(uu, ia, X##_mul(vv, ib)));                                                                                       \
    *ai = X##_sel(at0, esphi, X##_fnma(uu, ib, X##_mul(vv, ia)));                                                                                      \
    *bad = X##_mor(*bad, X##_mand(isp, X##_mand(X##_lt(r2, X##_set1(1e-24f)), X##_mnot(at0))));                                                        \
}                                                                                                                                                      \
/* Adds corner j's terms for coordinate x: w P to *S, and the derivatives of w P along the                                                             \
 * corner's a and b, mapped to d/dc and d/dd, to *Sc and *Sd ((a, b) = (c, d), (d, 1 - c),                                                             \
 * (1 - c, 1 - d), (1 - d, c) for j = 0..3: see sfb__mf_eval). P = [1 u u^2] C [1 v v^2]^T with                                                        \
 * (u, v) moving along a and b at (jua, jva) and (jub, jvb), here times w; pc: u = 0 in every                                                          \
 * lane (points and curves: C's rows 0..2 alone), cf: every lane conformal (patch corners:                                                             \
 * (jub, jvb) = (-jva, jua)). j, x, pc and cf are constants after inlining. */                                                                         \
ATTR static SFB__SIMD_FORCEINLINE void X##_coord(const float *cr, X##_i vidx, const int gather, const int j, const int x, const int pc, const int cf,  \
                                                 X##_v u, X##_v v, X##_v jua, X##_v jva, X##_v jub, X##_v jvb, X##_v w, X##_v wa, X##_v wb,            \
                                                 X##_v *S, X##_v *Sc, X##_v *Sd) {                                                                     \
    X##_v p, pa, pb, ga, gb;                                                                                                                           \
    const X##_v c00 = SFB__SIMD_MF_F(X, cr, x), c01 = SFB__SIMD_MF_F(X, cr, 3 + x), c02 = SFB__SIMD_MF_F(X, cr, 6 + x);                                \
    const X##_v v2 = X##_add(v, v), r0 = X##_fma(v, X##_fma(v, c02, c01), c00), d0 = X##_fma(v2, c02, c01);                                            \
    if (pc) {                                                                                                                                          \
        p = r0;                                                                                                                                        \
        pa = X##_mul(d0, jva);                                                                                                                         \
        pb = X##_mul(d0, jvb);                                                                                                                         \
    } else {                                                                                                                                           \
        /* R_m = C_m0 + v C_m1 + v^2 C_m2 and d/dv, then P = R_0 + u R_1 + u^2 R_2 */                                                                  \
        const X##_v c10 = SFB__SIMD_MF_F(X, cr, 9 + x), c11 = SFB__SIMD_MF_F(X, cr, 12 + x), c12 = SFB__SIMD_MF_F(X, cr, 15 + x);                      \
        const X##_v c20 = SFB__SIMD_MF_F(X, cr, 18 + x), c21 = SFB__SIMD_MF_F(X, cr, 21 + x), c22 = SFB__SIMD_MF_F(X, cr, 24 + x);                     \
        const X##_v r1 = X##_fma(v, X##_fma(v, c12, c11), c10), d1 = X##_fma(v2, c12, c11);                                                            \
        const X##_v r2 = X##_fma(v, X##_fma(v, c22, c21), c20), d2 = X##_fma(v2, c22, c21);                                                            \
        const X##_v pu = X##_fma(X##_add(u, u), r2, r1), pv = X##_fma(u, X##_fma(u, d2, d1), d0);                                                      \
        p = X##_fma(u, X##_fma(u, r2, r1), r0);                                                                                                        \
        pa = X##_fma(pu, jua, X##_mul(pv, jva));                                                                                                       \
        pb = cf ? X##_fnma(pu, jva, X##_mul(pv, jua)) : X##_fma(pu, jub, X##_mul(pv, jvb));                                                            \
    }                                                                                                                                                  \
    ga = X##_fma(wa, p, pa);                                                                                                                           \
    gb = X##_fma(wb, p, pb);                                                                                                                           \
    *S = X##_fma(w, p, *S);                                                                                                                            \
    switch (j) {                                                                                                                                       \
    case 0: *Sc = X##_add(*Sc, ga); *Sd = X##_add(*Sd, gb); break;                                                                                     \
    case 1: *Sc = X##_sub(*Sc, gb); *Sd = X##_add(*Sd, ga); break;                                                                                     \
    case 2: *Sc = X##_sub(*Sc, ga); *Sd = X##_sub(*Sd, gb); break;                                                                                     \
    default: *Sc = X##_add(*Sc, gb); *Sd = X##_sub(*Sd, ga); break;                                                                                    \
    }                                                                                                                                                  \
}                                                                                                                                                      \
/* Corner j at its coordinates (a, b) with weight w and derivatives wa, wb: adds to the blend                                                          \
 * acc (S xyz, dS/dc xyz, dS/dd xyz; constant indices only, so that they stay in registers)                                                            \
 * and to the error weights G (see the normal test) */                                                                                                 \
ATTR static SFB__SIMD_FORCEINLINE void X##_corner(const float *rec, X##_i vidx, const int gather, const int j, X##_v a, X##_v b,                       \
                                                  X##_v w, X##_v wa, X##_v wb, X##_v acc[9], X##_v G[2], X##_m *bad) {                                 \
    const float *cr = rec + SFB__SIMD_MF_CORNER(j);                                                                                                    \
    const X##_v zero = X##_zero();                                                                                                                     \
    const X##_m isp = X##_gt(SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_ISPATCH), X##_set1(0.5f));                                                             \
    const X##_v sa = SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_SA), sb = SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_SB);                                              \
    const X##_v s = X##_fma(sa, a, X##_fma(sb, b, SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_S0)));                                                            \
    X##_v ea, eb;                                                                                                                                      \
    if (X##_none(isp)) {                                                                                                                               \
        /* points and curves only: u = 0, v = sigma */                                                                                                 \
        const X##_v wsa = X##_mul(w, sa), wsb = X##_mul(w, sb);                                                                                        \
        X##_coord(cr, vidx, gather, j, 0, 1, 0, zero, s, zero, wsa, zero, wsb, w, wa, wb, &acc[0], &acc[3], &acc[6]);                                  \
        X##_coord(cr, vidx, gather, j, 1, 1, 0, zero, s, zero, wsa, zero, wsb, w, wa, wb, &acc[1], &acc[4], &acc[7]);                                  \
        X##_coord(cr, vidx, gather, j, 2, 1, 0, zero, s, zero, wsa, zero, wsb, w, wa, wb, &acc[2], &acc[5], &acc[8]);                                  \
        ea = X##_fma(X##_abs(w), X##_abs(sa), X##_abs(wa));                                                                                            \
        eb = X##_fma(X##_abs(w), X##_abs(sb), X##_abs(wb));                                                                                            \
    } else {                                                                                                                                           \
        const X##_v cphi = SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_CPHI), sphi = SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_SPHI);                                  \
        const X##_m unit = X##_mand(isp, X##_gt(SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_UNIT), X##_set1(0.5f)));                                            \
        const int allp = X##_all(isp);                                                                                                                 \
        /* valence 4: z = zeta e^(i phi), no transcendental functions; the polar chart where any                                                       \
         * lane needs it (a lane's result never depends on the other lanes) */                                                                         \
        X##_v u = X##_fnma(b, sphi, X##_mul(a, cphi)), v = X##_fma(b, cphi, X##_mul(a, sphi)), ar = cphi, ai = sphi;                                   \
        X##_v jua, jva, jub, jvb;                                                                                                                      \
        if (!X##_all(unit)) {                                                                                                                          \
            X##_v cu, cv, car, cai;                                                                                                                    \
            X##_chart(a, b, SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_E), cphi, sphi, SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_ECPHI),                              \
                      SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_ESPHI), X##_mand(isp, X##_mnot(unit)), &cu, &cv, &car, &cai, bad);                            \
            u = X##_sel(unit, u, cu);                                                                                                                  \
            v = X##_sel(unit, v, cv);                                                                                                                  \
            ar = X##_sel(unit, ar, car);                                                                                                               \
            ai = X##_sel(unit, ai, cai);                                                                                                               \
        }                                                                                                                                              \
        /* d(u,v)/da = (ar, ai), d(u,v)/db = (-ai, ar) (conformal); curves: (0, sa), (0, sb) */                                                        \
        jua = X##_sel(isp, ar, zero);                                                                                                                  \
        jva = X##_sel(isp, ai, sa);                                                                                                                    \
        jub = X##_sel(isp, X##_neg(ai), zero);                                                                                                         \
        jvb = X##_sel(isp, ar, sb);                                                                                                                    \
        u = X##_sel(isp, u, zero);                                                                                                                     \
        v = X##_sel(isp, v, s);                                                                                                                        \
        ea = X##_fma(X##_abs(w), X##_add(X##_abs(jua), X##_abs(jva)), X##_abs(wa));                                                                    \
        eb = X##_fma(X##_abs(w), X##_add(X##_abs(jub), X##_abs(jvb)), X##_abs(wb));                                                                    \
        jua = X##_mul(w, jua);                                                                                                                         \
        jva = X##_mul(w, jva);                                                                                                                         \
        if (allp) {                                                                                                                                    \
            X##_coord(cr, vidx, gather, j, 0, 0, 1, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[0], &acc[3], &acc[6]);                                   \
            X##_coord(cr, vidx, gather, j, 1, 0, 1, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[1], &acc[4], &acc[7]);                                   \
            X##_coord(cr, vidx, gather, j, 2, 0, 1, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[2], &acc[5], &acc[8]);                                   \
        } else {                                                                                                                                       \
            jub = X##_mul(w, jub);                                                                                                                     \
            jvb = X##_mul(w, jvb);                                                                                                                     \
            X##_coord(cr, vidx, gather, j, 0, 0, 0, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[0], &acc[3], &acc[6]);                                   \
            X##_coord(cr, vidx, gather, j, 1, 0, 0, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[1], &acc[4], &acc[7]);                                   \
            X##_coord(cr, vidx, gather, j, 2, 0, 0, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[2], &acc[5], &acc[8]);                                   \
        }                                                                                                                                              \
    }                                                                                                                                                  \
    G[0] = X##_add(G[0], (j & 1) ? eb : ea); /* dS/dc takes dP/da (j even) or dP/db (j odd) */                                                         \
    G[1] = X##_add(G[1], (j & 1) ? ea : eb);                                                                                                           \
}                                                                                                                                                      \
/* The blend at face coordinates (c, d): acc = S, dS/dc, dS/dd (xyz each); *G the normal                                                               \
 * test's error scale; *bad the lanes ref must take. rec: the record (gather = 0) or the first                                                         \
 * record with the lanes' offsets vidx (gather = 1). */                                                                                                \
ATTR static SFB__SIMD_FORCEINLINE void X##_block(const float *rec, X##_i vidx, const int gather, const int cinf, X##_v c, X##_v d,                     \
                                                 X##_v acc[9], X##_v G[2], X##_m *bad) {                                                               \
    const X##_v one = X##_set1(1.0f), oc = X##_sub(one, c), od = X##_sub(one, d);                                                                      \
    X##_v ec0, ec1, dc, ed0, ed1, dd;                                                                                                                  \
    X##_eta(c, cinf, &ec0, &ec1, &dc);                                                                                                                 \
    X##_eta(d, cinf, &ed0, &ed1, &dd);                                                                                                                 \
    acc[0] = acc[1] = acc[2] = acc[3] = acc[4] = acc[5] = acc[6] = acc[7] = acc[8] = G[0] = G[1] = X##_zero();                                         \
    *bad = X##_mfalse();                                                                                                                               \
    X##_corner(rec, vidx, gather, 0, c, d, X##_mul(ec0, ed0), X##_mul(dc, ed0), X##_mul(ec0, dd), acc, G, bad);                                        \
    X##_corner(rec, vidx, gather, 1, d, oc, X##_mul(ed0, ec1), X##_mul(dd, ec1), X##_mul(ed0, dc), acc, G, bad);                                       \
    X##_corner(rec, vidx, gather, 2, oc, od, X##_mul(ec1, ed1), X##_mul(dc, ed1), X##_mul(ec1, dd), acc, G, bad);                                      \
    X##_corner(rec, vidx, gather, 3, od, c, X##_mul(ed1, ec0), X##_mul(dd, ec0), X##_mul(ed1, dc), acc, G, bad);                                       \
    acc[0] = X##_add(acc[0], SFB__SIMD_MF_F(X, rec, 0));                                                                                               \
    acc[1] = X##_add(acc[1], SFB__SIMD_MF_F(X, rec, 1));                                                                                               \
    acc[2] = X##_add(acc[2], SFB__SIMD_MF_F(X, rec, 2));                                                                                               \
    G[0] = X##_fma(G[0], SFB__SIMD_MF_F(X, rec, 3), SFB__SIMD_MF_F(X, rec, 4));                                                                        \
    G[1] = X##_fma(G[1], SFB__SIMD_MF_F(X, rec, 3), SFB__SIMD_MF_F(X, rec, 4));                                                                        \
}                                                                                                                                                      \
/* Locations [first, last) of a manifold table, up to W at a time: a block is the next W                                                               \
 * locations when they share a patch, or the leading run of them that does when it holds at                                                            \
 * least W/4 (runs of a face's samples within one quadrant), else W locations gathered.                                                                \
 * Locations are located SFB__SIMD_MF_CHUNK at a time ahead of the blocks (sfb__simd_mf_locate),                                                       \
 * so that a block's vector loads do not wait on the scalar stores of the locating. */                                                                 \
ATTR static void X##_mf_range(const sfb__simd_pjob *jb, int first, int last) {                                                                         \
    const sfb__simd_patches *h = jb->h;                                                                                                                \
    const sfb_eval_output *o = jb->out;                                                                                                                \
    const int cinf = jb->pt->mf_weights == SFB_MANIFOLD_WEIGHTS_CINF;                                                                                  \
    float cs[SFB__SIMD_MF_CHUNK + 16], ds[SFB__SIMD_MF_CHUNK + 16], sc[SFB__SIMD_MF_CHUNK + 16];                                                       \
    int off[SFB__SIMD_MF_CHUNK + 16], q0, n, cbase = first, cend = first;                                                                              \
    for (q0 = first; q0 < last; q0 += n) {                                                                                                             \
        int i0, l, uni, run;                                                                                                                           \
        unsigned refl = 0;                                                                                                                             \
        X##_v acc[9], G[2], c, d, k;                                                                                                                   \
        X##_m bad;                                                                                                                                     \
        X##_i vidx;                                                                                                                                    \
        if (q0 + X##_W > cend && cend < last) {                                                                                                        \
            cbase = q0;                                                                                                                                \
            cend = last - q0 < SFB__SIMD_MF_CHUNK ? last : q0 + SFB__SIMD_MF_CHUNK;                                                                    \
            sfb__simd_mf_locate(h, jb->locs, cbase, cend, off, cs, ds, sc);                                                                            \
        }                                                                                                                                              \
        i0 = q0 - cbase;                                                                                                                               \
        n = last - q0 < X##_W ? last - q0 : X##_W;                                                                                                     \
        for (run = 1; run < n && off[i0 + run] == off[i0]; ++run) {}                                                                                   \
        uni = run >= n || 4 * run >= X##_W;                                                                                                            \
        if (run < n && uni) n = run;                                                                                                                   \
        for (l = 0; l < n; ++l)                                                                                                                        \
            if (off[i0 + l] == 0) refl |= 1u << l; /* the zero record: a ref leaf */                                                                   \
        c = X##_loadu(cs + i0);                                                                                                                        \
        d = X##_loadu(ds + i0);                                                                                                                        \
        vidx = X##_loadi(off + i0);                                                                                                                    \
        if (uni) X##_block(h->blk + off[i0], vidx, 0, cinf, c, d, acc, G, &bad);                                                                       \
        else X##_block(h->blk, vidx, 1, cinf, c, d, acc, G, &bad);                                                                                     \
        refl |= X##_bits(bad);                                                                                                                         \
        if (o->normal) {                                                                                                                               \
            const X##_v nx = X##_fnma(acc[5], acc[7], X##_mul(acc[4], acc[8]));                                                                        \
            const X##_v ny = X##_fnma(acc[3], acc[8], X##_mul(acc[5], acc[6]));                                                                        \
            const X##_v nz = X##_fnma(acc[4], acc[6], X##_mul(acc[3], acc[7]));                                                                        \
            const X##_v nn = X##_fma(nx, nx, X##_fma(ny, ny, X##_mul(nz, nz)));                                                                        \
            const X##_v uu = X##_fma(acc[3], acc[3], X##_fma(acc[4], acc[4], X##_mul(acc[5], acc[5])));                                                \
            const X##_v vv = X##_fma(acc[6], acc[6], X##_fma(acc[7], acc[7], X##_mul(acc[8], acc[8])));                                                \
            const X##_v tol = X##_fma(X##_mul(G[0], G[0]), vv, X##_mul(X##_mul(G[1], G[1]), uu));                                                      \
            const X##_m ok = X##_mand(X##_mand(X##_gt(nn, X##_set1(1e-30f)), X##_le(nn, X##_set1(1e30f))), X##_ge(nn, tol));                           \
            const X##_v inv = X##_div(X##_set1(1.0f), X##_sqrt(nn));                                                                                   \
            refl |= X##_bits(X##_mnot(ok));                                                                                                            \
            X##_store3(o->normal + 3 * (size_t)q0, X##_mul(nx, inv), X##_mul(ny, inv), X##_mul(nz, inv), n);                                           \
        }                                                                                                                                              \
        if (o->position) X##_store3(o->position + 3 * (size_t)q0, acc[0], acc[1], acc[2], n);                                                          \
        k = X##_loadu(sc + i0);                                                                                                                        \
        if (o->du) X##_store3(o->du + 3 * (size_t)q0, X##_mul(acc[3], k), X##_mul(acc[4], k), X##_mul(acc[5], k), n);                                  \
        if (o->dv) X##_store3(o->dv + 3 * (size_t)q0, X##_mul(acc[6], k), X##_mul(acc[7], k), X##_mul(acc[8], k), n);                                  \
        for (l = 0; l < n; ++l)                                                                                                                        \
            if ((refl >> l) & 1u) sfb__simd_ref_one(jb, q0 + l);                                                                                       \
    }                                                                                                                                                  \
}

/* ---- the vector operations of each instruction set ---- */
/* portable: one lane, plain C */
typedef float sfb__vp_v;
typedef int sfb__vp_m;
typedef const int *sfb__vp_i;
enum { sfb__vp_W = 1 };
static inline float sfb__vp_zero(void) { return 0.0f; }
static inline float sfb__vp_set1(float x) { return x; }
static inline float sfb__vp_add(float a, float b) { return a + b; }
static inline float sfb__vp_sub(float a, float b) { return a - b; }
static inline float sfb__vp_mul(float a, float b) { return a * b; }
static inline float sfb__vp_div(float a, float b) { return a / b; }
static inline float sfb__vp_fma(float a, float b, float c) { return a * b + c; }
static inline float sfb__vp_fnma(float a, float b, float c) { return c - a * b; }
static inline float sfb__vp_neg(float a) { return -a; }
static inline float sfb__vp_abs(float a) { return fabsf(a); }
static inline float sfb__vp_min(float a, float b) { return a < b ? a : b; }
static inline float sfb__vp_max(float a, float b) { return a > b ? a : b; }
static inline float sfb__vp_sqrt(float a) { return sqrtf(a); }
static inline int sfb__vp_lt(float a, float b) { return a < b; }
static inline int sfb__vp_le(float a, float b) { return a <= b; }
static inline int sfb__vp_gt(float a, float b) { return a > b; }
static inline int sfb__vp_ge(float a, float b) { return a >= b; }
static inline int sfb__vp_eq(float a, float b) { return a == b; }
static inline float sfb__vp_sel(int m, float a, float b) { return m ? a : b; }
static inline int sfb__vp_mand(int a, int b) { return a & b; }
static inline int sfb__vp_mor(int a, int b) { return a | b; }
static inline int sfb__vp_mnot(int a) { return !a; }
static inline int sfb__vp_mfalse(void) { return 0; }
static inline int sfb__vp_all(int m) { return m; }
static inline int sfb__vp_none(int m) { return !m; }
static inline unsigned sfb__vp_bits(int m) { return m ? 1u : 0u; }
static inline float sfb__vp_round(float x) { return floorf(x + 0.5f); }
static inline float sfb__vp_pow2i(float n) { return ldexpf(1.0f, (int)n); }
static inline float sfb__vp_expo(float x) { int e; (void)frexpf(x, &e); return (float)(e - 1); }
static inline float sfb__vp_mant(float x) { int e; return 2.0f * frexpf(x, &e); }
static inline float sfb__vp_loadu(const float *p) { return *p; }
static inline const int *sfb__vp_loadi(const int *p) { return p; }
static inline float sfb__vp_gather(const float *p, const int *idx) { return p[idx[0]]; }
static inline void sfb__vp_store3(float *dst, float x, float y, float z, int n) {
    (void)n;
    dst[0] = x; dst[1] = y; dst[2] = z;
}
SFB__SIMD_MF_DEFINE(sfb__vp, )

#ifdef SFB__SIMD_SSE2
/* sse2: 4 lanes, no fused multiply-add */
typedef __m128 sfb__vs_v;
typedef __m128 sfb__vs_m;
typedef const int *sfb__vs_i;
enum { sfb__vs_W = 4 };
static inline __m128 sfb__vs_zero(void) { return _mm_setzero_ps(); }
static inline __m128 sfb__vs_set1(float x) { return _mm_set1_ps(x); }
static inline __m128 sfb__vs_add(__m128 a, __m128 b) { return _mm_add_ps(a, b); }
static inline __m128 sfb__vs_sub(__m128 a, __m128 b) { return _mm_sub_ps(a, b); }
static inline __m128 sfb__vs_mul(__m128 a, __m128 b) { return _mm_mul_ps(a, b); }
static inline __m128 sfb__vs_div(__m128 a, __m128 b) { return _mm_div_ps(a, b); }
static inline __m128 sfb__vs_fma(__m128 a, __m128 b, __m128 c) { return _mm_add_ps(_mm_mul_ps(a, b), c); }
static inline __m128 sfb__vs_fnma(__m128 a, __m128 b, __m128 c) { return _mm_sub_ps(c, _mm_mul_ps(a, b)); }
static inline __m128 sfb__vs_neg(__m128 a) { return _mm_xor_ps(a, _mm_set1_ps(-0.0f)); }
static inline __m128 sfb__vs_abs(__m128 a) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), a); }
static inline __m128 sfb__vs_min(__m128 a, __m128 b) { return _mm_min_ps(a, b); }
static inline __m128 sfb__vs_max(__m128 a, __m128 b) { return _mm_max_ps(a, b); }
static inline __m128 sfb__vs_sqrt(__m128 a) { return _mm_sqrt_ps(a); }
static inline __m128 sfb__vs_lt(__m128 a, __m128 b) { return _mm_cmplt_ps(a, b); }
static inline __m128 sfb__vs_le(__m128 a, __m128 b) { return _mm_cmple_ps(a, b); }
static inline __m128 sfb__vs_gt(__m128 a, __m128 b) { return _mm_cmpgt_ps(a, b); }
static inline __m128 sfb__vs_ge(__m128 a, __m128 b) { return _mm_cmpge_ps(a, b); }
static inline __m128 sfb__vs_eq(__m128 a, __m128 b) { return _mm_cmpeq_ps(a, b); }
static inline __m128 sfb__vs_sel(__m128 m, __m128 a, __m128 b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }
static inline __m128 sfb__vs_mand(__m128 a, __m128 b) { return _mm_and_ps(a, b); }
static inline __m128 sfb__vs_mor(__m128 a, __m128 b) { return _mm_or_ps(a, b); }
static inline __m128 sfb__vs_mnot(__m128 a) { return _mm_xor_ps(a, _mm_castsi128_ps(_mm_set1_epi32(-1))); }
static inline __m128 sfb__vs_mfalse(void) { return _mm_setzero_ps(); }
static inline int sfb__vs_all(__m128 m) { return _mm_movemask_ps(m) == 15; }
static inline int sfb__vs_none(__m128 m) { return _mm_movemask_ps(m) == 0; }
static inline unsigned sfb__vs_bits(__m128 m) { return (unsigned)_mm_movemask_ps(m); }
static inline __m128 sfb__vs_round(__m128 x) { return _mm_cvtepi32_ps(_mm_cvtps_epi32(x)); }
static inline __m128 sfb__vs_pow2i(__m128 n) { return _mm_castsi128_ps(_mm_slli_epi32(_mm_add_epi32(_mm_cvtps_epi32(n), _mm_set1_epi32(127)), 23)); }
static inline __m128 sfb__vs_expo(__m128 x) { return _mm_cvtepi32_ps(_mm_sub_epi32(_mm_srli_epi32(_mm_castps_si128(x), 23), _mm_set1_epi32(127))); }
static inline __m128 sfb__vs_mant(__m128 x) {
    return _mm_castsi128_ps(_mm_or_si128(_mm_and_si128(_mm_castps_si128(x), _mm_set1_epi32(0x007FFFFF)), _mm_set1_epi32(0x3F800000)));
}
static inline __m128 sfb__vs_loadu(const float *p) { return _mm_loadu_ps(p); }
static inline const int *sfb__vs_loadi(const int *p) { return p; }
static inline __m128 sfb__vs_gather(const float *p, const int *idx) { return _mm_setr_ps(p[idx[0]], p[idx[1]], p[idx[2]], p[idx[3]]); }
/* n (1..4) xyz triples from lanes of x, y, z (4x3 transpose: x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3) */
static inline void sfb__vs_store3(float *dst, __m128 x, __m128 y, __m128 z, int n) {
    if (n == 4) {
        const __m128 xy0 = _mm_unpacklo_ps(x, y), xy1 = _mm_unpackhi_ps(x, y); /* x0 y0 x1 y1, x2 y2 x3 y3 */
        const __m128 zx = _mm_shuffle_ps(z, x, _MM_SHUFFLE(3, 1, 2, 0));      /* z0 z2 x1 x3 */
        const __m128 zy = _mm_shuffle_ps(z, y, _MM_SHUFFLE(3, 1, 3, 1));      /* z1 z3 y1 y3 */
        _mm_storeu_ps(dst, _mm_shuffle_ps(xy0, zx, _MM_SHUFFLE(2, 0, 1, 0)));      /* x0 y0 z0 x1 */
        _mm_storeu_ps(dst + 4, _mm_shuffle_ps(zy, xy1, _MM_SHUFFLE(1, 0, 0, 2)));  /* y1 z1 x2 y2 */
        _mm_storeu_ps(dst + 8, _mm_shuffle_ps(zx, zy, _MM_SHUFFLE(1, 3, 3, 1)));   /* z2 x3 y3 z3 */
    } else {
        float t[12];
        int l;
        _mm_storeu_ps(t, x);
        _mm_storeu_ps(t + 4, y);
        _mm_storeu_ps(t + 8, z);
        for (l = 0; l < n; ++l) {
            dst[3 * l] = t[l];
            dst[3 * l + 1] = t[4 + l];
            dst[3 * l + 2] = t[8 + l];
        }
    }
}
SFB__SIMD_MF_DEFINE(sfb__vs, )
#endif /* SFB__SIMD_SSE2 */

#ifdef SFB__SIMD_X86_DISPATCH
/* avx2 + fma: 8 lanes */
typedef __m256 sfb__va_v;
typedef __m256 sfb__va_m;
typedef __m256i sfb__va_i;
enum { sfb__va_W = 8 };
#define SFB__VA SFB__SIMD_TARGET_AVX2 static inline
SFB__VA __m256 sfb__va_zero(void) { return _mm256_setzero_ps(); }
SFB__VA __m256 sfb__va_set1(float x) { return _mm256_set1_ps(x); }
SFB__VA __m256 sfb__va_add(__m256 a, __m256 b) { return _mm256_add_ps(a, b); }
SFB__VA __m256 sfb__va_sub(__m256 a, __m256 b) { return _mm256_sub_ps(a, b); }
SFB__VA __m256 sfb__va_mul(__m256 a, __m256 b) { return _mm256_mul_ps(a, b); }
SFB__VA __m256 sfb__va_div(__m256 a, __m256 b) { return _mm256_div_ps(a, b); }
SFB__VA __m256 sfb__va_fma(__m256 a, __m256 b, __m256 c) { return _mm256_fmadd_ps(a, b, c); }
SFB__VA __m256 sfb__va_fnma(__m256 a, __m256 b, __m256 c) { return _mm256_fnmadd_ps(a, b, c); }
SFB__VA __m256 sfb__va_neg(__m256 a) { return _mm256_xor_ps(a, _mm256_set1_ps(-0.0f)); }
SFB__VA __m256 sfb__va_abs(__m256 a) { return _mm256_andnot_ps(_mm256_set1_ps(-0.0f), a); }
SFB__VA __m256 sfb__va_min(__m256 a, __m256 b) { return _mm256_min_ps(a, b); }
SFB__VA __m256 sfb__va_max(__m256 a, __m256 b) { return _mm256_max_ps(a, b); }
SFB__VA __m256 sfb__va_sqrt(__m256 a) { return _mm256_sqrt_ps(a); }
SFB__VA __m256 sfb__va_lt(__m256 a, __m256 b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
SFB__VA __m256 sfb__va_le(__m256 a, __m256 b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
SFB__VA __m256 sfb__va_gt(__m256 a, __m256 b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
SFB__VA __m256 sfb__va_ge(__m256 a, __m256 b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
SFB__VA __m256 sfb__va_eq(__m256 a, __m256 b) { return _mm256_cmp_ps(a, b, _CMP_EQ_OQ); }
SFB__VA __m256 sfb__va_sel(__m256 m, __m256 a, __m256 b) { return _mm256_blendv_ps(b, a, m); }
SFB__VA __m256 sfb__va_mand(__m256 a, __m256 b) { return _mm256_and_ps(a, b); }
SFB__VA __m256 sfb__va_mor(__m256 a, __m256 b) { return _mm256_or_ps(a, b); }
SFB__VA __m256 sfb__va_mnot(__m256 a) { return _mm256_xor_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(-1))); }
SFB__VA __m256 sfb__va_mfalse(void) { return _mm256_setzero_ps(); }
SFB__VA int sfb__va_all(__m256 m) { return _mm256_movemask_ps(m) == 255; }
SFB__VA int sfb__va_none(__m256 m) { return _mm256_movemask_ps(m) == 0; }
SFB__VA unsigned sfb__va_bits(__m256 m) { return (unsigned)_mm256_movemask_ps(m); }
SFB__VA __m256 sfb__va_round(__m256 x) { return _mm256_round_ps(x, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC); }
SFB__VA __m256 sfb__va_pow2i(__m256 n) {
    return _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_add_epi32(_mm256_cvtps_epi32(n), _mm256_set1_epi32(127)), 23));
}
SFB__VA __m256 sfb__va_expo(__m256 x) {
    return _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_srli_epi32(_mm256_castps_si256(x), 23), _mm256_set1_epi32(127)));
}
SFB__VA __m256 sfb__va_mant(__m256 x) {
    return _mm256_castsi256_ps(_mm256_or_si256(_mm256_and_si256(_mm256_castps_si256(x), _mm256_set1_epi32(0x007FFFFF)),
                                               _mm256_set1_epi32(0x3F800000)));
}
SFB__VA __m256 sfb__va_loadu(const float *p) { return _mm256_loadu_ps(p); }
SFB__VA __m256i sfb__va_loadi(const int *p) { return _mm256_loadu_si256((const __m256i *)(const void *)p); }
SFB__VA __m256 sfb__va_gather(const float *p, __m256i idx) {
    return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), p, idx, _mm256_castsi256_ps(_mm256_set1_epi32(-1)), 4);
}
SFB__VA void sfb__va_store3(float *dst, __m256 x, __m256 y, __m256 z, int n) {
    sfb__vs_store3(dst, _mm256_castps256_ps128(x), _mm256_castps256_ps128(y), _mm256_castps256_ps128(z), n < 4 ? n : 4);
    if (n > 4) sfb__vs_store3(dst + 12, _mm256_extractf128_ps(x, 1), _mm256_extractf128_ps(y, 1), _mm256_extractf128_ps(z, 1), n - 4);
}
SFB__SIMD_MF_DEFINE(sfb__va, SFB__SIMD_TARGET_AVX2)
#undef SFB__VA

/* avx512: 16 lanes, masks in mask registers */
typedef __m512 sfb__vz_v;
typedef __mmask16 sfb__vz_m;
typedef __m512i sfb__vz_i;
enum { sfb__vz_W = 16 };
#define SFB__VZ SFB__SIMD_TARGET_AVX512 static inline
SFB__VZ __m512 sfb__vz_zero(void) { return _mm512_setzero_ps(); }
SFB__VZ __m512 sfb__vz_set1(float x) { return _mm512_set1_ps(x); }
SFB__VZ __m512 sfb__vz_add(__m512 a, __m512 b) { return _mm512_add_ps(a, b); }
SFB__VZ __m512 sfb__vz_sub(__m512 a, __m512 b) { return _mm512_sub_ps(a, b); }
SFB__VZ __m512 sfb__vz_mul(__m512 a, __m512 b) { return _mm512_mul_ps(a, b); }
SFB__VZ __m512 sfb__vz_div(__m512 a, __m512 b) { return _mm512_div_ps(a, b); }
SFB__VZ __m512 sfb__vz_fma(__m512 a, __m512 b, __m512 c) { return _mm512_fmadd_ps(a, b, c); }
SFB__VZ __m512 sfb__vz_fnma(__m512 a, __m512 b, __m512 c) { return _mm512_fnmadd_ps(a, b, c); }
SFB__VZ __m512 sfb__vz_neg(__m512 a) { return _mm512_sub_ps(_mm512_setzero_ps(), a); }
SFB__VZ __m512 sfb__vz_abs(__m512 a) { return _mm512_abs_ps(a); }
SFB__VZ __m512 sfb__vz_min(__m512 a, __m512 b) { return _mm512_min_ps(a, b); }
SFB__VZ __m512 sfb__vz_max(__m512 a, __m512 b) { return _mm512_max_ps(a, b); }
SFB__VZ __m512 sfb__vz_sqrt(__m512 a) { return _mm512_sqrt_ps(a); }
SFB__VZ __mmask16 sfb__vz_lt(__m512 a, __m512 b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
SFB__VZ __mmask16 sfb__vz_le(__m512 a, __m512 b) { return _mm512_cmp_ps_mask(a, b, _CMP_LE_OQ); }
SFB__VZ __mmask16 sfb__vz_gt(__m512 a, __m512 b) { return _mm512_cmp_ps_mask(a, b, _CMP_GT_OQ); }
SFB__VZ __mmask16 sfb__vz_ge(__m512 a, __m512 b) { return _mm512_cmp_ps_mask(a, b, _CMP_GE_OQ); }
SFB__VZ __mmask16 sfb__vz_eq(__m512 a, __m512 b) { return _mm512_cmp_ps_mask(a, b, _CMP_EQ_OQ); }
SFB__VZ __m512 sfb__vz_sel(__mmask16 m, __m512 a, __m512 b) { return _mm512_mask_blend_ps(m, b, a); }
SFB__VZ __mmask16 sfb__vz_mand(__mmask16 a, __mmask16 b) { return (__mmask16)(a & b); }
SFB__VZ __mmask16 sfb__vz_mor(__mmask16 a, __mmask16 b) { return (__mmask16)(a | b); }
SFB__VZ __mmask16 sfb__vz_mnot(__mmask16 a) { return (__mmask16)(~(unsigned)a & 0xFFFFu); }
SFB__VZ __mmask16 sfb__vz_mfalse(void) { return (__mmask16)0; }
SFB__VZ int sfb__vz_all(__mmask16 m) { return m == 0xFFFF; }
SFB__VZ int sfb__vz_none(__mmask16 m) { return m == 0; }
SFB__VZ unsigned sfb__vz_bits(__mmask16 m) { return (unsigned)m; }
SFB__VZ __m512 sfb__vz_round(__m512 x) { return _mm512_roundscale_ps(x, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC); }
SFB__VZ __m512 sfb__vz_pow2i(__m512 n) {
    return _mm512_castsi512_ps(_mm512_slli_epi32(_mm512_add_epi32(_mm512_cvtps_epi32(n), _mm512_set1_epi32(127)), 23));
}
SFB__VZ __m512 sfb__vz_expo(__m512 x) {
    return _mm512_cvtepi32_ps(_mm512_sub_epi32(_mm512_srli_epi32(_mm512_castps_si512(x), 23), _mm512_set1_epi32(127)));
}
SFB__VZ __m512 sfb__vz_mant(__m512 x) {
    return _mm512_castsi512_ps(_mm512_or_si512(_mm512_and_si512(_mm512_castps_si512(x), _mm512_set1_epi32(0x007FFFFF)),
                                               _mm512_set1_epi32(0x3F800000)));
}
SFB__VZ __m512 sfb__vz_loadu(const float *p) { return _mm512_loadu_ps(p); }
SFB__VZ __m512i sfb__vz_loadi(const int *p) { return _mm512_loadu_si512((const void *)p); }
SFB__VZ __m512 sfb__vz_gather(const float *p, __m512i idx) { return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), (__mmask16)0xFFFF, idx, p, 4); }
/* n (1..16) xyz triples: two two-source permutes per 16 output floats, masked stores */
SFB__VZ void sfb__vz_store3(float *dst, __m512 x, __m512 y, __m512 z, int n) {
    static const int ia[3][16] = {{0, 16, 0, 1, 17, 0, 2, 18, 0, 3, 19, 0, 4, 20, 0, 5},
                                  {21, 0, 6, 22, 0, 7, 23, 0, 8, 24, 0, 9, 25, 0, 10, 26},
                                  {0, 11, 27, 0, 12, 28, 0, 13, 29, 0, 14, 30, 0, 15, 31, 0}};
    static const int ib[3][16] = {{0, 1, 16, 3, 4, 17, 6, 7, 18, 9, 10, 19, 12, 13, 20, 15},
                                  {0, 21, 2, 3, 22, 5, 6, 23, 8, 9, 24, 11, 12, 25, 14, 15},
                                  {26, 1, 2, 27, 4, 5, 28, 7, 8, 29, 10, 11, 30, 13, 14, 31}};
    int k;
    for (k = 0; k < 3; ++k) {
        const int cnt = 3 * n - 16 * k;
        const __m512 xy = _mm512_permutex2var_ps(x, _mm512_loadu_si512((const void *)ia[k]), y);
        const __m512 r = _mm512_permutex2var_ps(xy, _mm512_loadu_si512((const void *)ib[k]), z);
        if (cnt >= 16) _mm512_storeu_ps(dst + 16 * k, r);
        else if (cnt > 0) _mm512_mask_storeu_ps(dst + 16 * k, (__mmask16)((1u << cnt) - 1u), r);
    }
}
SFB__SIMD_MF_DEFINE(sfb__vz, SFB__SIMD_TARGET_AVX512)
#undef SFB__VZ
#endif /* SFB__SIMD_X86_DISPATCH */

#if defined(SFB__SIMD_NEON) && defined(__aarch64__)
#define SFB__SIMD_MF_NEON 1
/* neon (AArch64): 4 lanes, fused multiply-add; 32-bit ARM (no vector division or square
 * root) runs the portable kernel */
typedef float32x4_t sfb__vn_v;
typedef uint32x4_t sfb__vn_m;
typedef const int *sfb__vn_i;
enum { sfb__vn_W = 4 };
static inline float32x4_t sfb__vn_zero(void) { return vdupq_n_f32(0.0f); }
static inline float32x4_t sfb__vn_set1(float x) { return vdupq_n_f32(x); }
static inline float32x4_t sfb__vn_add(float32x4_t a, float32x4_t b) { return vaddq_f32(a, b); }
static inline float32x4_t sfb__vn_sub(float32x4_t a, float32x4_t b) { return vsubq_f32(a, b); }
static inline float32x4_t sfb__vn_mul(float32x4_t a, float32x4_t b) { return vmulq_f32(a, b); }
static inline float32x4_t sfb__vn_div(float32x4_t a, float32x4_t b) { return vdivq_f32(a, b); }
static inline float32x4_t sfb__vn_fma(float32x4_t a, float32x4_t b, float32x4_t c) { return vfmaq_f32(c, a, b); }
static inline float32x4_t sfb__vn_fnma(float32x4_t a, float32x4_t b, float32x4_t c) { return vfmsq_f32(c, a, b); }
static inline float32x4_t sfb__vn_neg(float32x4_t a) { return vnegq_f32(a); }
static inline float32x4_t sfb__vn_abs(float32x4_t a) { return vabsq_f32(a); }
static inline float32x4_t sfb__vn_min(float32x4_t a, float32x4_t b) { return vminq_f32(a, b); }
static inline float32x4_t sfb__vn_max(float32x4_t a, float32x4_t b) { return vmaxq_f32(a, b); }
static inline float32x4_t sfb__vn_sqrt(float32x4_t a) { return vsqrtq_f32(a); }
static inline uint32x4_t sfb__vn_lt(float32x4_t a, float32x4_t b) { return vcltq_f32(a, b); }
static inline uint32x4_t sfb__vn_le(float32x4_t a, float32x4_t b) { return vcleq_f32(a, b); }
static inline uint32x4_t sfb__vn_gt(float32x4_t a, float32x4_t b) { return vcgtq_f32(a, b); }
static inline uint32x4_t sfb__vn_ge(float32x4_t a, float32x4_t b) { return vcgeq_f32(a, b); }
static inline uint32x4_t sfb__vn_eq(float32x4_t a, float32x4_t b) { return vceqq_f32(a, b); }
static inline float32x4_t sfb__vn_sel(uint32x4_t m, float32x4_t a, float32x4_t b) { return vbslq_f32(m, a, b); }
static inline uint32x4_t sfb__vn_mand(uint32x4_t a, uint32x4_t b) { return vandq_u32(a, b); }
static inline uint32x4_t sfb__vn_mor(uint32x4_t a, uint32x4_t b) { return vorrq_u32(a, b); }
static inline uint32x4_t sfb__vn_mnot(uint32x4_t a) { return vmvnq_u32(a); }
static inline uint32x4_t sfb__vn_mfalse(void) { return vdupq_n_u32(0u); }
static inline int sfb__vn_all(uint32x4_t m) { return vminvq_u32(m) != 0u; }
static inline int sfb__vn_none(uint32x4_t m) { return vmaxvq_u32(m) == 0u; }
static inline unsigned sfb__vn_bits(uint32x4_t m) {
    return (vgetq_lane_u32(m, 0) & 1u) | (vgetq_lane_u32(m, 1) & 2u) | (vgetq_lane_u32(m, 2) & 4u) | (vgetq_lane_u32(m, 3) & 8u);
}
static inline float32x4_t sfb__vn_round(float32x4_t x) { return vrndnq_f32(x); }
static inline float32x4_t sfb__vn_pow2i(float32x4_t n) { return vreinterpretq_f32_s32(vshlq_n_s32(vaddq_s32(vcvtq_s32_f32(n), vdupq_n_s32(127)), 23)); }
static inline float32x4_t sfb__vn_expo(float32x4_t x) {
    return vcvtq_f32_s32(vsubq_s32(vreinterpretq_s32_u32(vshrq_n_u32(vreinterpretq_u32_f32(x), 23)), vdupq_n_s32(127)));
}
static inline float32x4_t sfb__vn_mant(float32x4_t x) {
    return vreinterpretq_f32_u32(vorrq_u32(vandq_u32(vreinterpretq_u32_f32(x), vdupq_n_u32(0x007FFFFFu)), vdupq_n_u32(0x3F800000u)));
}
static inline float32x4_t sfb__vn_loadu(const float *p) { return vld1q_f32(p); }
static inline const int *sfb__vn_loadi(const int *p) { return p; }
static inline float32x4_t sfb__vn_gather(const float *p, const int *idx) {
    float t[4];
    t[0] = p[idx[0]]; t[1] = p[idx[1]]; t[2] = p[idx[2]]; t[3] = p[idx[3]];
    return vld1q_f32(t);
}
static inline void sfb__vn_store3(float *dst, float32x4_t x, float32x4_t y, float32x4_t z, int n) {
    float32x4x3_t v;
    v.val[0] = x; v.val[1] = y; v.val[2] = z;
    if (n == 4) {
        vst3q_f32(dst, v);
    } else {
        float t[12];
        int l;
        vst3q_f32(t, v);
        for (l = 0; l < 3 * n; ++l) dst[l] = t[l];
    }
}
SFB__SIMD_MF_DEFINE(sfb__vn, )
#endif

/* ==== normal blend: finish_normals (seed 001) ====
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

/* ---- instruction set choice ---- */
enum { SFB__SIMD_PORTABLE, SFB__SIMD_ISA_SSE2, SFB__SIMD_AVX2, SFB__SIMD_AVX512, SFB__SIMD_ISA_NEON, SFB__SIMD_ISA_COUNT };
static const char *const sfb__simd_isa_names[SFB__SIMD_ISA_COUNT] = {"portable", "sse2", "avx2", "avx512", "neon"};

/* The kernel of `isa` when it is compiled in and this CPU runs it, else NULL. */
static sfb__simd_kernel sfb__simd_kernel_of(int isa) {
    switch (isa) {
    case SFB__SIMD_PORTABLE: return sfb__simd_portable;
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: return sfb__simd_sse2;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2:
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") ? sfb__simd_avx2 : NULL;
    case SFB__SIMD_AVX512:
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("avx512f") &&
                       __builtin_cpu_supports("avx512vl")
                   ? sfb__simd_avx512
                   : NULL;
#endif
#ifdef SFB__SIMD_NEON
    case SFB__SIMD_ISA_NEON: return sfb__simd_neon;
#endif
    default: return NULL;
    }
}

/* The finish_normals vector pass of an instruction set that sfb__simd_kernel_of accepted. */
static sfb__simd_nvec_fn sfb__simd_nvec_of(int isa) {
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

/* The eval_patches kernels of an instruction set that sfb__simd_kernel_of accepted: a range
 * loop, and for the generic (scalar-finishing) range loop its window kernel. */
static void sfb__simd_patch_kernels_of(int isa, sfb__simd_prange_fn *range, sfb__simd_bs_fn *bs, sfb__simd_tri_fn *tri) {
    *range = sfb__simd_prange_generic;
    *bs = sfb__simd_bs_portable;
    *tri = sfb__simd_tri_portable;
    switch (isa) {
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: *range = sfb__simd_prange_sse2; break;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2: *range = sfb__simd_prange_avx2; break;
    case SFB__SIMD_AVX512: *range = sfb__simd_prange_avx512; break;
#endif
#ifdef SFB__SIMD_NEON
    case SFB__SIMD_ISA_NEON:
        *bs = sfb__simd_bs_neon;
#ifdef SFB__SIMD_TRI_NEON
        *tri = sfb__simd_tri_neon;
#endif
        break;
#endif
    default: break;
    }
}

/* The manifold range loop of an instruction set that sfb__simd_kernel_of accepted. */
static sfb__simd_prange_fn sfb__simd_mf_range_of(int isa) {
    switch (isa) {
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: return sfb__vs_mf_range;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2: return sfb__va_mf_range;
    case SFB__SIMD_AVX512: return sfb__vz_mf_range;
#endif
#ifdef SFB__SIMD_MF_NEON
    case SFB__SIMD_ISA_NEON: return sfb__vn_mf_range;
#endif
    default: return sfb__vp_mf_range;
    }
}

static int sfb__simd_streq(const char *a, const char *b) {
    for (; *a && *b; ++a, ++b) {
        int ca = (*a >= 'A' && *a <= 'Z') ? *a + 32 : *a;
        if (ca != *b) return 0;
    }
    return *a == *b;
}

/* The best instruction set, or the one SURFBLEND_SIMD_ISA names when it runs here. */
static int sfb__simd_choose_isa(sfb_context *ctx) {
    const char *env = getenv("SURFBLEND_SIMD_ISA");
    int isa, best = SFB__SIMD_PORTABLE;
    for (isa = SFB__SIMD_ISA_COUNT - 1; isa > SFB__SIMD_PORTABLE; --isa)
        if (sfb__simd_kernel_of(isa)) { best = isa; break; }
    if (!env || !*env) return best;
    for (isa = 0; isa < SFB__SIMD_ISA_COUNT; ++isa) {
        if (!sfb__simd_streq(env, sfb__simd_isa_names[isa])) continue;
        if (sfb__simd_kernel_of(isa)) return isa;
        sfb__log(ctx, SFB_LOG_WARN, "SURFBLEND_SIMD_ISA=%s: not supported by this build or CPU; using %s",
                 sfb__simd_isa_names[isa], sfb__simd_isa_names[best]);
        return best;
    }
    sfb__log(ctx, SFB_LOG_WARN, "SURFBLEND_SIMD_ISA=%.32s: unknown (portable, sse2, avx2, avx512, neon); using %s", env,
             sfb__simd_isa_names[best]);
    return best;
}

/* ---- backend state and thread pool ---- */
typedef struct sfb__simd_state {
    sfb_context *ctx;
    int isa;
    sfb__simd_kernel kernel;
    sfb__simd_prange_fn prange;  /* eval_patches: range loop and block evaluator of `isa` */
    sfb__simd_bs_fn pbs;
    sfb__simd_tri_fn ptri;
    sfb__simd_prange_fn mfrange; /* eval_patches on manifold tables */
    sfb__simd_nvec_fn nvec;      /* finish_normals: the vector pass of `isa` */
    int threads;                 /* threads sharing one call, the caller included */
#ifdef SFB__SIMD_THREADS
    int workers;                 /* pool threads running (threads - 1 once init succeeded) */
    pthread_t tid[SFB__SIMD_MAX_THREADS];
    pthread_mutex_t busy;        /* held by the one call using the pool */
    pthread_mutex_t lock;        /* guards everything below */
    pthread_cond_t wake, done;
    unsigned long generation;    /* bumped per job; idle workers wait for a change */
    int quit;
    /* the current job: items [first, last) cut into `chunks`, each run by task(arg, a, b);
     * with `offsets` (stencil rows) chunks hold about equal entry counts, else equal items */
    void (*task)(const struct sfb__simd_state *s, const void *arg, int a, int b);
    const void *arg;
    const int *offsets;
    int first, last, chunks, next_chunk, chunks_done;
    size_t entry0, entries;
#endif
} sfb__simd_state;

#ifdef SFB__SIMD_THREADS
/* First row in [first, last) whose entries start at or after `e` (last when none). */
static int sfb__simd_row_at(const int *offsets, int first, int last, size_t e) {
    int lo = first, hi = last;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if ((size_t)offsets[mid] < e) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* First item of chunk c of the current job: chunks hold about equal numbers of entries
 * (stencil rows) or of items. */
static int sfb__simd_chunk_start(const sfb__simd_state *s, int c) {
    if (c <= 0) return s->first;
    if (c >= s->chunks) return s->last;
    if (!s->offsets) return s->first + (int)((long long)(s->last - s->first) * c / s->chunks);
    return sfb__simd_row_at(s->offsets, s->first, s->last, s->entry0 + s->entries / (size_t)s->chunks * (size_t)c);
}

/* Runs chunks of the current job until none is left to claim. Called and returns with
 * s->lock held. A worker that wakes late finds nothing to claim (or joins the next job):
 * the job is only touched between claiming a chunk and counting it done. */
static void sfb__simd_drain(sfb__simd_state *s) {
    while (s->next_chunk < s->chunks) {
        const int c = s->next_chunk++;
        const int a = sfb__simd_chunk_start(s, c), b = sfb__simd_chunk_start(s, c + 1);
        void (*task)(const struct sfb__simd_state *, const void *, int, int) = s->task;
        const void *arg = s->arg;
        pthread_mutex_unlock(&s->lock);
        if (a < b) task(s, arg, a, b);
        pthread_mutex_lock(&s->lock);
        if (++s->chunks_done == s->chunks) pthread_cond_signal(&s->done);
    }
}

static void *sfb__simd_worker(void *arg) {
    sfb__simd_state *s = (sfb__simd_state *)arg;
    unsigned long seen = 0;
    pthread_mutex_lock(&s->lock);
    for (;;) {
        while (!s->quit && s->generation == seen) pthread_cond_wait(&s->wake, &s->lock);
        if (s->quit) break;
        seen = s->generation;
        sfb__simd_drain(s);
    }
    pthread_mutex_unlock(&s->lock);
    return NULL;
}

/* Stops and joins the workers, destroys the sync objects. */
static void sfb__simd_pool_stop(sfb__simd_state *s) {
    int i;
    pthread_mutex_lock(&s->lock);
    s->quit = 1;
    pthread_cond_broadcast(&s->wake);
    pthread_mutex_unlock(&s->lock);
    for (i = 0; i < s->workers; ++i) pthread_join(s->tid[i], NULL);
    s->workers = 0;
    pthread_cond_destroy(&s->done);
    pthread_cond_destroy(&s->wake);
    pthread_mutex_destroy(&s->lock);
    pthread_mutex_destroy(&s->busy);
}

/* Starts threads - 1 workers; on failure nothing is left running or allocated. */
static int sfb__simd_pool_start(sfb__simd_state *s, char *why, size_t why_size) {
    int i, e;
    if (pthread_mutex_init(&s->busy, NULL) != 0) goto fail0;
    if (pthread_mutex_init(&s->lock, NULL) != 0) goto fail1;
    if (pthread_cond_init(&s->wake, NULL) != 0) goto fail2;
    if (pthread_cond_init(&s->done, NULL) != 0) goto fail3;
    for (i = 0; i < s->threads - 1; ++i) {
        e = pthread_create(&s->tid[i], NULL, sfb__simd_worker, s);
        if (e != 0) {
            snprintf(why, why_size, "could not start worker thread %d of %d: %s", i + 1, s->threads - 1, strerror(e));
            sfb__simd_pool_stop(s); /* joins the i already running */
            return 0;
        }
        s->workers = i + 1;
    }
    return 1;
fail3:
    pthread_cond_destroy(&s->wake);
fail2:
    pthread_mutex_destroy(&s->lock);
fail1:
    pthread_mutex_destroy(&s->busy);
fail0:
    snprintf(why, why_size, "could not create the thread pool's locks");
    return 0;
}
#endif /* SFB__SIMD_THREADS */

static int sfb__simd_thread_count(int requested) {
    long n = requested;
    if (n <= 0) {
#if defined(SFB__SIMD_THREADS) && defined(_SC_NPROCESSORS_ONLN)
        n = sysconf(_SC_NPROCESSORS_ONLN);
#else
        n = 1;
#endif
    }
    if (n < 1) n = 1;
    if (n > SFB__SIMD_MAX_THREADS) n = SFB__SIMD_MAX_THREADS;
#ifndef SFB__SIMD_THREADS
    n = 1; /* no thread support known here (_WIN32 and others): single-threaded */
#endif
    return (int)n;
}

static sfb_result sfb__simd_init(sfb_context *ctx, void **state, char *why, size_t why_size) {
    sfb__simd_state *s;
    *state = NULL;
    s = (sfb__simd_state *)sfb__alloc(ctx, sizeof *s);
    if (!s) {
        const int budget = ctx->budget_refused;
        ctx->budget_refused = 0;
        snprintf(why, why_size, "%s for the backend state", budget ? "over the memory budget" : "out of memory");
        return budget ? SFB_LIMIT_EXCEEDED : SFB_OUT_OF_MEMORY;
    }
    memset(s, 0, sizeof *s);
    s->ctx = ctx;
    s->isa = sfb__simd_choose_isa(ctx);
    s->kernel = sfb__simd_kernel_of(s->isa);
    sfb__simd_patch_kernels_of(s->isa, &s->prange, &s->pbs, &s->ptri);
    s->mfrange = sfb__simd_mf_range_of(s->isa);
    s->nvec = sfb__simd_nvec_of(s->isa);
    s->threads = sfb__simd_thread_count(ctx->threads);
#ifdef SFB__SIMD_THREADS
    if (s->threads > 1 && !sfb__simd_pool_start(s, why, why_size)) {
        sfb__free(ctx, s);
        return SFB_BACKEND_UNAVAILABLE;
    }
#endif
    *state = s;
    return SFB_SUCCESS;
}

static void sfb__simd_shutdown(sfb_context *ctx, void *state) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    if (!s) return;
#ifdef SFB__SIMD_THREADS
    if (s->threads > 1) sfb__simd_pool_stop(s);
#endif
    sfb__free(ctx, s);
}

#ifdef SFB__SIMD_THREADS
/* Runs task over items [first, last) on the pool (the caller takes chunks too) and returns 1,
 * or returns 0 without running anything when there is no pool or another call holds it. */
static int sfb__simd_pool_run(sfb__simd_state *s, void (*task)(const struct sfb__simd_state *, const void *, int, int),
                              const void *arg, int first, int last, const int *offsets, size_t e0, size_t entries) {
    if (s->threads <= 1 || pthread_mutex_trylock(&s->busy) != 0) return 0;
    pthread_mutex_lock(&s->lock);
    s->task = task;
    s->arg = arg;
    s->offsets = offsets;
    s->first = first;
    s->last = last;
    s->entry0 = e0;
    s->entries = entries;
    s->chunks = 4 * s->threads; /* several per thread: a late or slow thread takes fewer */
    s->next_chunk = 0;
    s->chunks_done = 0;
    ++s->generation;
    pthread_cond_broadcast(&s->wake);
    sfb__simd_drain(s);
    /* wait for chunks still running on workers, not for workers still asleep */
    while (s->chunks_done < s->chunks) pthread_cond_wait(&s->done, &s->lock);
    s->task = NULL;
    s->arg = NULL;
    pthread_mutex_unlock(&s->lock);
    pthread_mutex_unlock(&s->busy);
    return 1;
}

static void sfb__simd_stencil_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    s->kernel((const sfb__simd_job *)arg, a, b);
}
#endif

static void sfb__simd_describe(void *state, char *buf, size_t size) {
    const sfb__simd_state *s = (const sfb__simd_state *)state;
    if (!s || !buf || size == 0) return;
    snprintf(buf, size, "%s kernels, %d thread%s", sfb__simd_isa_names[s->isa], s->threads, s->threads == 1 ? "" : "s");
}

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
    s->kernel(&j, first, last);
    return SFB_SUCCESS;
}

/* ---- patch tables ---- */
/* Packs the points q[gx * rows + gy] (double xyz; set[] = 0: an unused slot) of a grid with
 * `rows` points per column into g (layout above): relative to their centroid, with o and E in
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

/* Floats of patch p's grids: 64 (B-spline, Bezier triangle), 100 per level (Stam with its
 * eigen structure), 192 per level (Stam-Loop), 0 (the ref kernel evaluates it). */
static size_t sfb__simd_patch_floats(const sfb__patch_table *pt, int p) {
    const int n = pt->pfirst[p + 1] - pt->pfirst[p];
    if (pt->ptype[p] == SFB__PATCH_BSPLINE) return n == 16 ? 64 : 0;
    if (pt->ptype[p] == SFB__PATCH_BEZTRI) return n == 15 ? 64 : 0;
    if (pt->ptype[p] == SFB__PATCH_STAM) {
        const int N = pt->pvalence[p];
        const sfb__eigen_cc *e = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eig[N] : NULL;
        return e && e->K == n && e->lambda && e->phi ? 100 * SFB__SIMD_STAM_LEVELS : 0;
    }
    if (pt->ptype[p] == SFB__PATCH_STAM_LOOP) {
        const int N = pt->pvalence[p];
        const sfb__eigen_loop *e = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eigl[N] : NULL;
        return e && e->K == n && e->lambda && e->phi && e->head ? 192 * SFB__SIMD_LOOP_LEVELS : 0;
    }
    return 0;
}

/* Packs a quartic Bezier triangle (15 double xyz points, the table's order) into g (64 floats):
 * the points relative to their centroid o, then (o, E x SFB__SIMD_TRI_EFACTOR) as point 15
 * (so E is at g[63], where the square windows of cs = 16 keep it too). Returns E. */
static float sfb__simd_pack_tri(float *g, double (*q)[3]) {
    double o[3] = {0.0, 0.0, 0.0};
    float E = 0.0f;
    int k, c;
    for (k = 0; k < 15; ++k)
        for (c = 0; c < 3; ++c) o[c] += q[k][c] / 15.0;
    for (c = 0; c < 3; ++c) g[60 + c] = (float)o[c];
    for (k = 0; k < 15; ++k) {
        for (c = 0; c < 3; ++c) {
            g[4 * k + c] = (float)(q[k][c] - (double)g[60 + c]);
            if (fabsf(g[4 * k + c]) > E) E = fabsf(g[4 * k + c]);
        }
        g[4 * k + 3] = 0.0f;
    }
    g[63] = E * SFB__SIMD_TRI_EFACTOR;
    return E;
}

/* The Stam-Loop triangles of patch p at g: for each level n = 1..SFB__SIMD_LOOP_LEVELS the
 * three sub-patches k = 0, 1, 2 (64 floats each, as sfb__simd_pack_tri), control points
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
        for (k = 0; k < 3; ++k)
            for (jj = 0; jj < 15; ++jj) {
                const double *phi = e->phi + ((size_t)k * 15 + (size_t)jj) * (size_t)K;
                for (c = 0; c < 3; ++c) q[k][jj][c] = 0.0;
                for (i = 0; i < K; ++i) {
                    const float *c_i = pt->point_data + 3 * (size_t)cv[i];
                    double w = sfb__simd_ipow(e->lambda[i], m) * phi[i];
                    if (e->head[i] >= 0 && e->head[i] < K && m > 0) w += m * sfb__simd_ipow(e->lambda[i], m - 1) * phi[e->head[i]];
                    for (c = 0; c < 3; ++c) q[k][jj][c] += w * c_i[c];
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
            const float E = sfb__simd_pack_tri(g + (size_t)(n - 1) * 192 + (size_t)k * 64, q[k]);
            if ((double)E > scale) scale = E;
        }
    }
    return diff <= 1e-6 * scale;
}

/* The Stam grids of patch p at g; 0 where the three sub-patches of a level do not agree on
 * the points they share (they are windows of one level-n mesh; a table whose eigen data said
 * otherwise is left to the ref kernel). */
static int sfb__simd_pack_stam(float *g, const sfb__patch_table *pt, int p, double *lp) {
    static const int win[3][2] = {{1, 0}, {1, 1}, {0, 1}}; /* sub-patch k = 1, 2, 3: lattice (0,-1), (0,0), (-1,0) */
    const sfb__eigen_cc *e = pt->eig[pt->pvalence[p]];
    const int K = e->K, *cv = pt->cv + pt->pfirst[p];
    double q[25][3], scale = 0.0, diff = 0.0;
    unsigned char set[25];
    int n, k, i, jj, c;
    for (i = 0; i < K; ++i) lp[i] = 1.0;
    for (n = 1; n <= SFB__SIMD_STAM_LEVELS; ++n) {
        memset(set, 0, sizeof set);
        for (k = 0; k < 3; ++k)
            for (jj = 0; jj < 16; ++jj) {
                /* control point jj = 4 b + a of sub-patch k + 1: sum_i lambda_i^(n-1) phi[jj][i] c_i */
                const double *phi = e->phi + ((size_t)k * 16 + (size_t)jj) * (size_t)K;
                const int slot = (win[k][0] + jj % 4) * 5 + win[k][1] + jj / 4;
                double x[3] = {0.0, 0.0, 0.0};
                for (i = 0; i < K; ++i) {
                    const double w = lp[i] * phi[i];
                    const float *c_i = pt->point_data + 3 * (size_t)cv[i];
                    for (c = 0; c < 3; ++c) x[c] += w * c_i[c];
                }
                for (c = 0; c < 3; ++c) {
                    if (set[slot] && fabs(x[c] - q[slot][c]) > diff) diff = fabs(x[c] - q[slot][c]);
                    q[slot][c] = x[c];
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

static void sfb__simd_release_patches(void *state, void *handle) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    sfb__simd_patches *h = (sfb__simd_patches *)handle;
    if (!s || !h) return;
    sfb__free(s->ctx, h->raw);
    sfb__free(s->ctx, h->root);
    sfb__free(s->ctx, h->node);
    sfb__free(s->ctx, h);
}

/* Leaf code of a table entry (>= 0 node, -1 hole, <= -2 patch -(p+2)). */
static int sfb__simd_leaf(const int *pcode, int v) { return v >= 0 ? v : v == -1 ? -(SFB__SIMD_LEAF_REF + 1) : pcode[-v - 2]; }

/* Packs manifold patch p's record at rec (layout: "manifold blending" above); 0 where a corner
 * code or vertex is out of range (that patch is left to ref). */
static int sfb__simd_pack_mf(float *rec, const sfb__patch_table *pt, int p) {
    const int *cv = pt->cv + pt->pfirst[p];
    const unsigned *codes = pt->pcorner + 4 * (size_t)p;
    double C[4][9][3], o[3] = {0.0, 0.0, 0.0};
    float of[3], E = 0.0f;
    int j, r, c;
    if (pt->ptype[p] != SFB__PATCH_MANIFOLD4 || pt->pfirst[p + 1] - pt->pfirst[p] != 4) return 0;
    memset(rec, 0, SFB__SIMD_MF_REC * sizeof(float));
    memset(C, 0, sizeof C);
    for (j = 0; j < 4; ++j) {
        const int kind = SFB__MF_KIND(codes[j]);
        const float *q;
        float *k = rec + SFB__SIMD_MF_CORNER(j);
        if (cv[j] < 0 || (size_t)cv[j] >= (size_t)pt->npoints / 9) return 0;
        q = pt->point_data + 27 * (size_t)cv[j];
        if (kind == SFB__MF_PATCH) {
            const int kv = SFB__MF_K(codes[j]), hv = SFB__MF_H(codes[j]);
            const double e = 4.0 / kv, phi = 2.0 * SFB__PI * hv / kv;
            if (kv < 2 || hv >= kv) return 0;
            for (r = 0; r < 9; ++r)
                for (c = 0; c < 3; ++c) C[j][r][c] = q[3 * r + c];
            k[SFB__SIMD_MF_E] = (float)e;
            k[SFB__SIMD_MF_CPHI] = (float)cos(phi);
            k[SFB__SIMD_MF_SPHI] = (float)sin(phi);
            k[SFB__SIMD_MF_ECPHI] = (float)(e * cos(phi));
            k[SFB__SIMD_MF_ESPHI] = (float)(e * sin(phi));
            k[SFB__SIMD_MF_ISPATCH] = 1.0f;
            k[SFB__SIMD_MF_UNIT] = kv == 4 ? 1.0f : 0.0f;
            for (c = 0; c < 3; ++c) o[c] += q[c];
        } else if (kind == SFB__MF_CURVE) {
            const int a1 = SFB__MF_A1(codes[j]), a2 = SFB__MF_A2(codes[j]);
            if (a1 > 2 || a2 > 2) return 0;
            for (c = 0; c < 3; ++c) { /* q0 + s 2 (q1 - q0) + s^2 (q0 - 2 q1 + q2) */
                C[j][0][c] = q[c];
                C[j][1][c] = 2.0 * ((double)q[3 + c] - q[c]);
                C[j][2][c] = ((double)q[c] - 2.0 * q[3 + c]) + q[6 + c];
                o[c] += q[3 + c];
            }
            k[SFB__SIMD_MF_S0] = 0.5f;
            k[SFB__SIMD_MF_SA] = 0.5f * (float)((a2 == 1) - (a1 == 1));
            k[SFB__SIMD_MF_SB] = 0.5f * (float)((a2 == 2) - (a1 == 2));
        } else if (kind == SFB__MF_POINT) {
            for (c = 0; c < 3; ++c) {
                C[j][0][c] = q[c];
                o[c] += q[c];
            }
        } else {
            return 0;
        }
    }
    for (c = 0; c < 3; ++c) {
        of[c] = (float)(o[c] / 4.0);
        rec[c] = of[c];
    }
    for (j = 0; j < 4; ++j) {
        float *k = rec + SFB__SIMD_MF_CORNER(j);
        for (c = 0; c < 3; ++c) C[j][0][c] -= of[c];
        for (r = 0; r < 9; ++r)
            for (c = 0; c < 3; ++c) {
                k[3 * r + c] = (float)C[j][r][c];
                if (fabsf(k[3 * r + c]) > E) E = fabsf(k[3 * r + c]);
            }
    }
    {
        const double om = fmax(fabs((double)of[0]), fmax(fabs((double)of[1]), fabs((double)of[2])));
        rec[3] = (float)(SFB__SIMD_MF_KEPS * 1.41421356 / 1e-4 * E);
        rec[4] = (float)(SFB__SIMD_MF_KEPS * 1.41421356 / 1e-4 * SFB__SIMD_MF_GFLOOR * (E + om));
    }
    return 1;
}

/* upload_patches for a manifold table: one record per patch after a zero record. */
static sfb_result sfb__simd_upload_mf(sfb__simd_state *s, const sfb__patch_table *pt, void **handle) {
    sfb_context *ctx = s->ctx;
    sfb__simd_patches *h;
    int *pcode;
    size_t nf;
    int p;
    if (!pt->ptype || !pt->pfirst || !pt->cv || !pt->pcorner) return SFB_SUCCESS; /* eval goes to ref */
    nf = ((size_t)pt->npatch + 1) * SFB__SIMD_MF_REC;
    if (nf / 4 >= ((size_t)1 << 27)) /* leaf codes hold offset / 4 in 27 bits */
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "simd: the patch table is too large to pack (%zu floats)", nf);
    h = (sfb__simd_patches *)sfb__alloc(ctx, sizeof *h);
    if (!h) return sfb__oom(ctx, "the simd backend's patch data");
    memset(h, 0, sizeof *h);
    h->npatch = pt->npatch;
    h->nptex = pt->nptex;
    h->mf = 1;
    h->root = (int *)sfb__alloc(ctx, (size_t)pt->nptex * sizeof(int));
    h->node = (int *)sfb__alloc(ctx, ((size_t)pt->nnodes * 4 + 1) * sizeof(int));
    h->raw = sfb__alloc(ctx, nf * sizeof(float) + 64);
    pcode = (int *)sfb__alloc(ctx, (size_t)pt->npatch * sizeof(int));
    if (!h->root || !h->node || !h->raw || !pcode) {
        sfb__free(ctx, pcode);
        sfb__simd_release_patches(s, h);
        return sfb__oom(ctx, "the simd backend's patch data");
    }
    h->bytes = sizeof *h + ((size_t)pt->nptex + (size_t)pt->nnodes * 4 + 1) * sizeof(int) + nf * sizeof(float) + 64;
    h->blk = (float *)(void *)((char *)h->raw + ((64 - ((uintptr_t)h->raw & 63)) & 63));
    memset(h->blk, 0, SFB__SIMD_MF_REC * sizeof(float));
    for (p = 0; p < pt->npatch; ++p) {
        const size_t at = ((size_t)p + 1) * SFB__SIMD_MF_REC;
        pcode[p] = sfb__simd_pack_mf(h->blk + at, pt, p) ? -((int)((at / 4) << 4 | SFB__SIMD_LEAF_MF) + 1) : -(SFB__SIMD_LEAF_REF + 1);
    }
    for (p = 0; p < pt->nptex; ++p) h->root[p] = sfb__simd_leaf(pcode, pt->ptex_root[p]);
    for (p = 0; p < 4 * pt->nnodes; ++p) h->node[p] = sfb__simd_leaf(pcode, pt->nodes[p]);
    sfb__free(ctx, pcode);
    *handle = h;
    return SFB_SUCCESS;
}

static sfb_result sfb__simd_upload_patches(void *state, const sfb__patch_table *pt, void **handle) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    sfb_context *ctx;
    sfb__simd_patches *h;
    double *lp = NULL;
    int *pcode = NULL;
    size_t nf = 0, at;
    int p, maxK = 0, pass;
    if (!s || !pt || !handle) return SFB_INVALID_ARGS;
    *handle = NULL;
    ctx = s->ctx;
    if (pt->npatch <= 0 || pt->nptex <= 0 || !pt->point_data) return SFB_SUCCESS; /* nothing to pack: eval goes to ref */
    if (sfb__patch_families(pt) & (1u << SFB__FAMILY_MANIFOLD)) return sfb__simd_upload_mf(s, pt, handle);
    for (p = 0; p < pt->npatch; ++p) {
        const size_t f = sfb__simd_patch_floats(pt, p);
        nf += f;
        if (pt->ptype[p] == SFB__PATCH_STAM && f > 0 && pt->pfirst[p + 1] - pt->pfirst[p] > maxK) maxK = pt->pfirst[p + 1] - pt->pfirst[p];
    }
    if (nf / 4 >= ((size_t)1 << 27)) /* leaf codes hold offset / 4 in 27 bits */
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "simd: the patch table is too large to pack (%zu floats)", nf);
    h = (sfb__simd_patches *)sfb__alloc(ctx, sizeof *h);
    if (!h) return sfb__oom(ctx, "the simd backend's patch data");
    memset(h, 0, sizeof *h);
    h->npatch = pt->npatch;
    h->nptex = pt->nptex;
    h->root = (int *)sfb__alloc(ctx, (size_t)pt->nptex * sizeof(int));
    h->node = (int *)sfb__alloc(ctx, ((size_t)pt->nnodes * 4 + 1) * sizeof(int));
    h->raw = sfb__alloc(ctx, nf * sizeof(float) + 64);
    pcode = (int *)sfb__alloc(ctx, (size_t)pt->npatch * sizeof(int));
    if (maxK > 0) lp = (double *)sfb__alloc(ctx, (size_t)maxK * sizeof(double));
    if (!h->root || !h->node || !h->raw || !pcode || (maxK > 0 && !lp)) {
        sfb__free(ctx, lp);
        sfb__free(ctx, pcode);
        sfb__simd_release_patches(s, h);
        return sfb__oom(ctx, "the simd backend's patch data");
    }
    h->bytes = sizeof *h + ((size_t)pt->nptex + (size_t)pt->nnodes * 4 + 1) * sizeof(int) + nf * sizeof(float) + 64;
    /* 64-byte alignment: a B-spline column is then one cache line */
    h->blk = (float *)(void *)((char *)h->raw + ((64 - ((uintptr_t)h->raw & 63)) & 63));
    /* B-spline grids first (all 64-byte aligned), then the Stam ones */
    at = 0;
    for (pass = 0; pass < 2; ++pass)
        for (p = 0; p < pt->npatch; ++p) {
            const size_t f = sfb__simd_patch_floats(pt, p);
            const int *cv = pt->cv + pt->pfirst[p];
            if (pass == 0) pcode[p] = -(SFB__SIMD_LEAF_REF + 1);
            if (f == 0 || (f == 64) != (pass == 0)) continue;
            if (f == 64 && pt->ptype[p] == SFB__PATCH_BEZTRI) {
                double q[15][3];
                int k, c;
                for (k = 0; k < 15; ++k)
                    for (c = 0; c < 3; ++c) q[k][c] = pt->point_data[3 * (size_t)cv[k] + c];
                sfb__simd_pack_tri(h->blk + at, q);
                pcode[p] = -((int)((at / 4) << 4 | SFB__SIMD_LEAF_TRI) + 1);
            } else if (f == 64) {
                static const int win[1][2] = {{0, 0}};
                double q[16][3];
                unsigned char set[16];
                int k, c;
                for (k = 0; k < 16; ++k) {
                    const int slot = (k % 4) * 4 + k / 4; /* cv[4 j + i] is point (i, j) */
                    for (c = 0; c < 3; ++c) q[slot][c] = pt->point_data[3 * (size_t)cv[k] + c];
                    set[k] = 1;
                }
                sfb__simd_pack_grid(h->blk + at, 4, 4, q, set, win, 1);
                pcode[p] = -((int)((at / 4) << 4 | SFB__SIMD_LEAF_BSPLINE) + 1);
            } else if (pt->ptype[p] == SFB__PATCH_STAM_LOOP ? SFB__PARAM_CORNER(pt->pparam[p]) < 3 && sfb__simd_pack_stam_loop(h->blk + at, pt, p)
                                                             : sfb__simd_pack_stam(h->blk + at, pt, p, lp)) {
                pcode[p] = -((int)((at / 4) << 4 | (size_t)SFB__PARAM_CORNER(pt->pparam[p]) << 2 | SFB__SIMD_LEAF_STAM) + 1);
            }
            at += f;
        }
    for (p = 0; p < pt->nptex; ++p) h->root[p] = sfb__simd_leaf(pcode, pt->ptex_root[p]);
    for (p = 0; p < 4 * pt->nnodes; ++p) h->node[p] = sfb__simd_leaf(pcode, pt->nodes[p]);
    sfb__free(ctx, lp);
    sfb__free(ctx, pcode);
    *handle = h;
    return SFB_SUCCESS;
}

/* Locations [first, last) on the ref kernel (manifold tables with second derivatives asked). */
static void sfb__simd_ref_range(const sfb__simd_pjob *j, int first, int last) {
    sfb__ref_eval_patches(NULL, j->pt, NULL, j->locs, first, last, j->out);
}

static void sfb__simd_patch_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    const sfb__simd_pjob *j = (const sfb__simd_pjob *)arg;
    (void)s;
    j->range(j, a, b);
}

static sfb_result sfb__simd_eval_patches(void *state, const sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                         int last, const sfb_eval_output *out) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    const sfb__simd_patches *h = (const sfb__simd_patches *)handle;
    sfb__simd_pjob j;
    if (!s || !pt || !locs || !out || first < 0 || first > last) return SFB_INVALID_ARGS;
    if (first == last) return SFB_SUCCESS;
    /* no packed data (not uploaded here, or an empty table): ref evaluates the call */
    if (!h || h->npatch != pt->npatch || h->nptex != pt->nptex) return sfb__ref_eval_patches(NULL, pt, NULL, locs, first, last, out);
    j.pt = pt;
    j.h = h;
    j.locs = locs;
    j.out = out;
    j.second = out->duu || out->duv || out->dvv;
    j.tri = pt->domain == SFB__DOMAIN_TRI;
    j.bs = s->pbs;
    j.tri_eval = s->ptri;
    j.range = s->prange;
    if (h->mf) j.range = j.second ? sfb__simd_ref_range : s->mfrange;
#ifdef SFB__SIMD_THREADS
    if (last - first >= SFB__SIMD_INLINE_LOCATIONS && sfb__simd_pool_run(s, sfb__simd_patch_task, &j, first, last, NULL, 0, 0))
        return SFB_SUCCESS;
#endif
    j.range(&j, first, last);
    return SFB_SUCCESS;
}

#ifdef SFB__SIMD_THREADS
static void sfb__simd_normals_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    sfb__simd_normals_range((const sfb__simd_njob *)arg, a, b, s->nvec);
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
    sfb__simd_normals_range(&j, first, last, s->nvec);
    return SFB_SUCCESS;
}

void sfb__simd_bind(sfb__backend_vtable *vt) {
    vt->name = "simd";
    vt->kind = SFB_BACKEND_SIMD;
    vt->init = sfb__simd_init;
    vt->shutdown = sfb__simd_shutdown;
    vt->describe = sfb__simd_describe;
    vt->eval_stencils = sfb__simd_eval_stencils;
    vt->upload_patches = sfb__simd_upload_patches;
    vt->release_patches = sfb__simd_release_patches;
    vt->eval_patches = sfb__simd_eval_patches;
    vt->finish_normals = sfb__simd_finish_normals;
}

#endif /* SFB__SIMD_H */
