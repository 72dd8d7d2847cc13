/* backends/sfb_simd.h -- the `simd` backend: stencil tables applied with SIMD kernels on a
 * small thread pool.
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
 * thread of about equal entry counts (from offsets); the caller and the workers claim chunks
 * until none is left, and the caller returns once every claimed chunk is done (it never
 * waits for a worker still asleep). Calls under 32768 entries run on the caller alone, as
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
    int threads;                 /* threads sharing one call, the caller included */
#ifdef SFB__SIMD_THREADS
    int workers;                 /* pool threads running (threads - 1 once init succeeded) */
    pthread_t tid[SFB__SIMD_MAX_THREADS];
    pthread_mutex_t busy;        /* held by the one call using the pool */
    pthread_mutex_t lock;        /* guards everything below */
    pthread_cond_t wake, done;
    unsigned long generation;    /* bumped per job; idle workers wait for a change */
    int quit;
    const sfb__simd_job *job;    /* the current job: rows [first, last) cut into `chunks` */
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

/* First row of chunk c of the current job: chunks hold about equal numbers of entries. */
static int sfb__simd_chunk_start(const sfb__simd_state *s, int c) {
    if (c <= 0) return s->first;
    if (c >= s->chunks) return s->last;
    return sfb__simd_row_at(s->job->offsets, s->first, s->last, s->entry0 + s->entries / (size_t)s->chunks * (size_t)c);
}

/* Runs chunks of the current job until none is left to claim. Called and returns with
 * s->lock held. A worker that wakes late finds nothing to claim (or joins the next job):
 * the job is only touched between claiming a chunk and counting it done. */
static void sfb__simd_drain(sfb__simd_state *s) {
    while (s->next_chunk < s->chunks) {
        const int c = s->next_chunk++;
        const int a = sfb__simd_chunk_start(s, c), b = sfb__simd_chunk_start(s, c + 1);
        const sfb__simd_job *j = s->job;
        pthread_mutex_unlock(&s->lock);
        if (a < b) s->kernel(j, a, b);
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
        if (s->threads > 1 && e1 - e0 >= SFB__SIMD_INLINE_ENTRIES && pthread_mutex_trylock(&s->busy) == 0) {
            pthread_mutex_lock(&s->lock);
            s->job = &j;
            s->first = first;
            s->last = last;
            s->entry0 = e0;
            s->entries = e1 - e0;
            s->chunks = 4 * s->threads; /* several per thread: a late or slow thread takes fewer */
            s->next_chunk = 0;
            s->chunks_done = 0;
            ++s->generation;
            pthread_cond_broadcast(&s->wake);
            sfb__simd_drain(s);
            /* wait for chunks still running on workers, not for workers still asleep */
            while (s->chunks_done < s->chunks) pthread_cond_wait(&s->done, &s->lock);
            s->job = NULL;
            pthread_mutex_unlock(&s->lock);
            pthread_mutex_unlock(&s->busy);
            return SFB_SUCCESS;
        }
    }
#endif
    s->kernel(&j, first, last);
    return SFB_SUCCESS;
}

static const sfb__backend_vtable sfb__simd_vtable = {
    "simd", SFB_BACKEND_SIMD, SFB__CAP_EVAL_STENCILS,
    sfb__simd_init, sfb__simd_shutdown, sfb__simd_describe, NULL, NULL, sfb__simd_eval_stencils, NULL,
    NULL, NULL, NULL
};

const sfb__backend_vtable *sfb__backend_simd(void) { return &sfb__simd_vtable; }

#endif /* SFB__SIMD_H */
