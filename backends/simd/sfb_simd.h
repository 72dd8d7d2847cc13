/* backends/simd/sfb_simd.h -- the `simd` backend: stencil tables applied, patch tables evaluated
 * (limit evaluation of Catmull-Clark and Loop, and the MANIFOLD4 blends of manifold-based
 * blending surfaces; second derivatives of those run the ref kernel), and seed 001's normal
 * blend (finish_normals), with SIMD kernels on a small thread pool.
 *
 * Not a public header: surfblend.h compiles this file at the end of its implementation when
 * SURFBLEND_SIMD (or SURFBLEND_ALL_BACKENDS) is defined with SURFBLEND_IMPLEMENTATION. It sees
 * the core's private declarations (src/sfb_internal.h); do not include it directly.
 *
 * Files. This one is the runtime: what can be compiled here, the instruction set chosen at
 * init (CPU detection, SURFBLEND_SIMD_ISA), the thread pool, the vector operations the kernels
 * are written on (below: one set of X##_op per instruction set, float and double lanes), the
 * backend state, init / shutdown / describe, and what the patch families share (the packed
 * table handle, a call's job). Then one file per kernel family, each holding its kernels for
 * every instruction set, its choice of them for the state's instruction set (a select
 * function of the family), and its bind (the vtable slots it fills) or, for the families of
 * patch tables, its sfb__simd_patch_family:
 *   stencils.h   eval_stencils
 *   patches.h    eval_patches on quad and triangle polynomial tables (BSPLINE16, STAM, ENDCAP;
 *                BEZTRI15, STAM_LOOP, ENDCAP_TRI), kernels in patches_quad.h and patches_tri.h
 *   manifold.h   eval_patches on manifold tables (MANIFOLD4)
 *   normals.h    finish_normals
 *   vtable.h     upload/release/eval_patches dispatched by the families a table holds, and
 *                sfb__simd_bind: one line per family.
 * backends/sfb_simd.h includes this runtime, then the family files in that order. A new kernel
 * family is a new file, its #include there and its line in vtable.h (sfb__simd_bind, or
 * sfb__simd_patch_families for a patch family).
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
 * only. An unknown or unavailable name is logged (warning) and the best one is used. A family
 * without kernels of its own for an instruction set runs its portable ones (or, for NEON on
 * 32-bit ARM, those the family has there).
 *
 * Threads: a pool (src/pool.c) of ctx->threads - 1 workers (0: one thread per online core, at most 64;
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
#ifdef SFB__THREADS /* the core's thread pool (src/pool.c) runs here */
#  define SFB__SIMD_THREADS 1
#endif

#if defined(__GNUC__) || defined(__clang__)
#  define SFB__SIMD_PREFETCH(p) __builtin_prefetch(p)
#  define SFB__SIMD_FORCEINLINE __attribute__((always_inline)) inline /* kernels into each range loop */
#else
#  define SFB__SIMD_PREFETCH(p) ((void)0)
#  define SFB__SIMD_FORCEINLINE inline
#endif

/* ---- instruction set choice ---- */
enum { SFB__SIMD_PORTABLE, SFB__SIMD_ISA_SSE2, SFB__SIMD_AVX2, SFB__SIMD_AVX512, SFB__SIMD_ISA_NEON, SFB__SIMD_ISA_COUNT };
static const char *const sfb__simd_isa_names[SFB__SIMD_ISA_COUNT] = {"portable", "sse2", "avx2", "avx512", "neon"};

/* Whether `isa` is compiled in and this CPU runs it. (The families' select functions then
 * only map the state's instruction set to their kernels.) */
static int sfb__simd_isa_runs(int isa) {
    switch (isa) {
    case SFB__SIMD_PORTABLE: return 1;
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: return 1;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2:
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case SFB__SIMD_AVX512:
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("avx512f") &&
               __builtin_cpu_supports("avx512vl");
#endif
#ifdef SFB__SIMD_NEON
    case SFB__SIMD_ISA_NEON: return 1;
#endif
    default: return 0;
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
        if (sfb__simd_isa_runs(isa)) { best = isa; break; }
    if (!env || !*env) return best;
    for (isa = 0; isa < SFB__SIMD_ISA_COUNT; ++isa) {
        if (!sfb__simd_streq(env, sfb__simd_isa_names[isa])) continue;
        if (sfb__simd_isa_runs(isa)) return isa;
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
    int isa;        /* every family runs its kernels of this instruction set */
    sfb__pool pool; /* pool.threads share one call, the caller included (src/pool.c) */
} sfb__simd_state;

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
    if (!sfb__pool_start(&s->pool, sfb__pool_threads(ctx->threads), why, why_size)) {
        sfb__free(ctx, s);
        return SFB_BACKEND_UNAVAILABLE;
    }
    *state = s;
    return SFB_SUCCESS;
}

static void sfb__simd_shutdown(sfb_context *ctx, void *state) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    if (!s) return;
    sfb__pool_stop(&s->pool);
    sfb__free(ctx, s);
}

#ifdef SFB__SIMD_THREADS
/* Runs task over items [first, last) on the pool (the caller takes chunks too) and returns 1,
 * or returns 0 without running anything when there is no pool or another call holds it. */
typedef struct sfb__simd_job_of {
    void (*task)(const struct sfb__simd_state *, const void *, int, int);
    const void *arg;
} sfb__simd_job_of;

static void sfb__simd_job_run(const void *owner, const void *arg, int a, int b) {
    const sfb__simd_job_of *j = (const sfb__simd_job_of *)arg;
    j->task((const sfb__simd_state *)owner, j->arg, a, b);
}

static int sfb__simd_pool_run(sfb__simd_state *s, void (*task)(const struct sfb__simd_state *, const void *, int, int),
                              const void *arg, int first, int last, const int *offsets, size_t e0, size_t entries) {
    sfb__simd_job_of j;
    j.task = task;
    j.arg = arg;
    return sfb__pool_run(&s->pool, sfb__simd_job_run, s, &j, first, last, offsets, e0, entries);
}
#endif

/* The `parallel` slot: the pool lent to the core (sfb__parallel). */
static int sfb__simd_parallel(void *state, void (*task)(void *arg, int first, int last), void *arg, int first, int last) {
    return state ? sfb__pool_lend(&((sfb__simd_state *)state)->pool, task, arg, first, last) : 0;
}

static void sfb__simd_describe(void *state, char *buf, size_t size) {
    const sfb__simd_state *s = (const sfb__simd_state *)state;
    if (!s || !buf || size == 0) return;
    snprintf(buf, size, "%s kernels, %d thread%s", sfb__simd_isa_names[s->isa], s->pool.threads, s->pool.threads == 1 ? "" : "s");
}

static void sfb__simd_runtime_bind(sfb__backend_vtable *vt) {
    vt->name = "simd";
    vt->kind = SFB_BACKEND_SIMD;
    vt->init = sfb__simd_init;
    vt->shutdown = sfb__simd_shutdown;
    vt->describe = sfb__simd_describe;
    vt->parallel = sfb__simd_parallel;
    vt->kernels_in_tasks = 1; /* a kernel called in a lent task runs on that thread alone */
}

/* ==== the vector operations ====
 *
 * Kernels that keep one location or element per vector lane (structure of arrays) are written
 * once over these operations, X##_op with X an instruction set's prefix, each a line or two of
 * intrinsics (the families instantiate them, e.g. SFB__SIMD_MF_DEFINE(X, ATTR) in manifold.h,
 * SFB__SIMD_NORMALS_DEFINE(X, ATTR) in normals.h, with ATTR the target attribute):
 *   float lanes:  sfb__vp portable (1 lane), sfb__vs sse2 (4), sfb__va avx2 + fma (8),
 *                 sfb__vz avx512 (16), sfb__vn neon on AArch64 (4; SFB__SIMD_VN)
 *   double lanes: sfb__vpd portable (1), sfb__vsd sse2 (2), sfb__vad avx2 (4), sfb__vzd
 *                 avx512 (8), sfb__vnd neon on AArch64 (2)
 * Each has the types X##_v (a vector), X##_m (a comparison mask), X##_i (float lanes: lane
 * indices for gathers) and the lane count X##_W. fma(a, b, c) is a b + c, fused where the
 * instruction set has it (avx2, avx512, AArch64 neon), a rounded product then a sum
 * elsewhere; fnma(a, b, c) is c - a b; sel(m, a, b) is a where m is set, else b. Comparisons
 * are ordered (false on NaN). Double lanes have only what their kernels use (loadu, storeu,
 * set1, add, sub, mul, div, sqrt, gt, sel). Intrinsic-level layouts (the stencils' entries
 * side by side in 256- and 512-bit registers, the B-spline windows' points per register) are
 * not expressible here and stay in their families' files. */

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
typedef double sfb__vpd_v;
typedef int sfb__vpd_m;
enum { sfb__vpd_W = 1 };
static inline double sfb__vpd_loadu(const double *p) { return *p; }
static inline void sfb__vpd_storeu(double *p, double v) { *p = v; }
static inline double sfb__vpd_set1(double x) { return x; }
static inline double sfb__vpd_add(double a, double b) { return a + b; }
static inline double sfb__vpd_sub(double a, double b) { return a - b; }
static inline double sfb__vpd_mul(double a, double b) { return a * b; }
static inline double sfb__vpd_div(double a, double b) { return a / b; }
static inline double sfb__vpd_sqrt(double a) { return sqrt(a); }
static inline int sfb__vpd_gt(double a, double b) { return a > b; }
static inline double sfb__vpd_sel(int m, double a, double b) { return m ? a : b; }

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
/* sse2, double lanes: 2 */
typedef __m128d sfb__vsd_v;
typedef __m128d sfb__vsd_m;
enum { sfb__vsd_W = 2 };
static inline __m128d sfb__vsd_loadu(const double *p) { return _mm_loadu_pd(p); }
static inline void sfb__vsd_storeu(double *p, __m128d v) { _mm_storeu_pd(p, v); }
static inline __m128d sfb__vsd_set1(double x) { return _mm_set1_pd(x); }
static inline __m128d sfb__vsd_add(__m128d a, __m128d b) { return _mm_add_pd(a, b); }
static inline __m128d sfb__vsd_sub(__m128d a, __m128d b) { return _mm_sub_pd(a, b); }
static inline __m128d sfb__vsd_mul(__m128d a, __m128d b) { return _mm_mul_pd(a, b); }
static inline __m128d sfb__vsd_div(__m128d a, __m128d b) { return _mm_div_pd(a, b); }
static inline __m128d sfb__vsd_sqrt(__m128d a) { return _mm_sqrt_pd(a); }
static inline __m128d sfb__vsd_gt(__m128d a, __m128d b) { return _mm_cmpgt_pd(a, b); }
static inline __m128d sfb__vsd_sel(__m128d m, __m128d a, __m128d b) { return _mm_or_pd(_mm_and_pd(m, a), _mm_andnot_pd(m, b)); }
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
/* avx2, double lanes: 4 */
typedef __m256d sfb__vad_v;
typedef __m256d sfb__vad_m;
enum { sfb__vad_W = 4 };
SFB__VA __m256d sfb__vad_loadu(const double *p) { return _mm256_loadu_pd(p); }
SFB__VA void sfb__vad_storeu(double *p, __m256d v) { _mm256_storeu_pd(p, v); }
SFB__VA __m256d sfb__vad_set1(double x) { return _mm256_set1_pd(x); }
SFB__VA __m256d sfb__vad_add(__m256d a, __m256d b) { return _mm256_add_pd(a, b); }
SFB__VA __m256d sfb__vad_sub(__m256d a, __m256d b) { return _mm256_sub_pd(a, b); }
SFB__VA __m256d sfb__vad_mul(__m256d a, __m256d b) { return _mm256_mul_pd(a, b); }
SFB__VA __m256d sfb__vad_div(__m256d a, __m256d b) { return _mm256_div_pd(a, b); }
SFB__VA __m256d sfb__vad_sqrt(__m256d a) { return _mm256_sqrt_pd(a); }
SFB__VA __m256d sfb__vad_gt(__m256d a, __m256d b) { return _mm256_cmp_pd(a, b, _CMP_GT_OQ); }
SFB__VA __m256d sfb__vad_sel(__m256d m, __m256d a, __m256d b) { return _mm256_blendv_pd(b, a, m); }
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
/* avx512, double lanes: 8 */
typedef __m512d sfb__vzd_v;
typedef __mmask8 sfb__vzd_m;
enum { sfb__vzd_W = 8 };
SFB__VZ __m512d sfb__vzd_loadu(const double *p) { return _mm512_loadu_pd(p); }
SFB__VZ void sfb__vzd_storeu(double *p, __m512d v) { _mm512_storeu_pd(p, v); }
SFB__VZ __m512d sfb__vzd_set1(double x) { return _mm512_set1_pd(x); }
SFB__VZ __m512d sfb__vzd_add(__m512d a, __m512d b) { return _mm512_add_pd(a, b); }
SFB__VZ __m512d sfb__vzd_sub(__m512d a, __m512d b) { return _mm512_sub_pd(a, b); }
SFB__VZ __m512d sfb__vzd_mul(__m512d a, __m512d b) { return _mm512_mul_pd(a, b); }
SFB__VZ __m512d sfb__vzd_div(__m512d a, __m512d b) { return _mm512_div_pd(a, b); }
SFB__VZ __m512d sfb__vzd_sqrt(__m512d a) { return _mm512_sqrt_pd(a); }
SFB__VZ __mmask8 sfb__vzd_gt(__m512d a, __m512d b) { return _mm512_cmp_pd_mask(a, b, _CMP_GT_OQ); }
SFB__VZ __m512d sfb__vzd_sel(__mmask8 m, __m512d a, __m512d b) { return _mm512_mask_blend_pd(m, b, a); }
#undef SFB__VZ
#endif /* SFB__SIMD_X86_DISPATCH */

#if defined(SFB__SIMD_NEON) && defined(__aarch64__)
#define SFB__SIMD_VN 1 /* the neon vector operations (AArch64) */
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
/* neon (AArch64), double lanes: 2 */
typedef float64x2_t sfb__vnd_v;
typedef uint64x2_t sfb__vnd_m;
enum { sfb__vnd_W = 2 };
static inline float64x2_t sfb__vnd_loadu(const double *p) { return vld1q_f64(p); }
static inline void sfb__vnd_storeu(double *p, float64x2_t v) { vst1q_f64(p, v); }
static inline float64x2_t sfb__vnd_set1(double x) { return vdupq_n_f64(x); }
static inline float64x2_t sfb__vnd_add(float64x2_t a, float64x2_t b) { return vaddq_f64(a, b); }
static inline float64x2_t sfb__vnd_sub(float64x2_t a, float64x2_t b) { return vsubq_f64(a, b); }
static inline float64x2_t sfb__vnd_mul(float64x2_t a, float64x2_t b) { return vmulq_f64(a, b); }
static inline float64x2_t sfb__vnd_div(float64x2_t a, float64x2_t b) { return vdivq_f64(a, b); }
static inline float64x2_t sfb__vnd_sqrt(float64x2_t a) { return vsqrtq_f64(a); }
static inline uint64x2_t sfb__vnd_gt(float64x2_t a, float64x2_t b) { return vcgtq_f64(a, b); }
static inline float64x2_t sfb__vnd_sel(uint64x2_t m, float64x2_t a, float64x2_t b) { return vbslq_f64(m, a, b); }
#endif

/* ==== patch tables: what the patch families share ====
 *
 * A packed table (sfb__simd_patches, made by a family's upload at upload_patches, read-only
 * afterwards): the family's data in blk (64-byte aligned), and a copy of the table's quadtree
 * (ptex_root, nodes) whose leaves say directly what to run: -(code + 1) with code = offset / 4
 * << 4 | corner << 2 | kind, the kind the family's (SFB__SIMD_LEAF_*; SFB__SIMD_LEAF_REF: the
 * ref kernel, for holes and patches the family does not pack). One dependent load less per
 * location than going through the patch arrays. vtable.h sends a table to the family that
 * evaluates the families it holds (sfb__patch_families), and each call to the family's
 * prepare, which picks its kernels for the state's instruction set. */
#define SFB__SIMD_INLINE_LOCATIONS 4096 /* eval_patches calls with fewer locations stay on the caller's thread */
/* Locations a patch range loop prepares in one go, a batch ahead of its kernels (patches.h);
 * eval_patches cuts a call over the pool in whole batches from its first location, so that every
 * location is in the same place of the same batch whatever the threads (the float pair kernel
 * pairs neighbours within a batch: the same bits on 1 thread and on 4). */
#define SFB__SIMD_BATCH 64
enum { SFB__SIMD_LEAF_BSPLINE = 0, SFB__SIMD_LEAF_STAM = 1, SFB__SIMD_LEAF_REF = 2, SFB__SIMD_LEAF_TRI = 3 };

struct sfb__simd_patch_family;
typedef struct sfb__simd_patches {
    int npatch, nptex;
    const struct sfb__simd_patch_family *family; /* the family that packed it (and evaluates it) */
    int *root, *node;  /* nptex, 4 * nnodes: the quadtree with leaf codes */
    float *blk;        /* the family's data, 64-byte aligned inside raw */
    void *raw;
    size_t bytes;      /* everything above */
} sfb__simd_patches;

/* Evaluates the 4 x 4 window at blk (column stride cs) at (s, t): r[0] position (origin
 * added), r[1..2] d/ds, d/dt, r[3..5] second derivatives (only when `second`) in the window's
 * own parameters; lanes 0..2. (The polynomial families' generic range loop's kernel: portable,
 * neon; patches.h.) */
typedef void (*sfb__simd_bs_fn)(const float *blk, int cs, float s, float t, int second, float r[6][4]);
/* The same for a quartic Bezier triangle at blk (15 points, then the origin; patches.h). */
/* returns the factor on the window's E for the normal's float-trust test (1: a double kernel;
 * SFB__SIMD_TRI2_EFACTOR: neon's float kernel, patches_tri.h) */
typedef float (*sfb__simd_tri_fn)(const float *blk, float s, float t, int second, float r[6][4]);

/* One eval_patches call; the family's prepare fills range (and bs, tri_eval where its range
 * loop calls them). */
typedef struct sfb__simd_pjob {
    const sfb__patch_table *pt;
    const sfb__simd_patches *h;
    const sfb_location *locs;
    const sfb_eval_output *out;
    int second;        /* any of duu, duv, dvv asked */
    int tri;           /* a triangle-domain table (pt->domain): triangle param faces */
    sfb__simd_bs_fn bs;
    sfb__simd_tri_fn tri_eval;
    void (*range)(const struct sfb__simd_pjob *j, int first, int last); /* what a pool chunk runs */
    int first, last;   /* the call's locations (pool chunks: batches first + k SFB__SIMD_BATCH ..) */
} sfb__simd_pjob;

typedef void (*sfb__simd_prange_fn)(const sfb__simd_pjob *j, int first, int last);

/* A patch family of this backend (patches.h, manifold.h; listed in vtable.h): the table
 * families (bits 1 << SFB__FAMILY_*) it evaluates; upload packs a table (*handle may stay NULL:
 * ref then evaluates it); prepare picks a call's kernels for the state's instruction set. */
typedef struct sfb__simd_patch_family {
    unsigned families;
    sfb_result (*upload)(sfb__simd_state *s, const sfb__patch_table *pt, void **handle);
    void (*prepare)(const sfb__simd_state *s, sfb__simd_pjob *j);
} sfb__simd_patch_family;

/* Location q on the ref kernel (rare cases; writes exactly q's three floats per output). */
static void sfb__simd_ref_one(const sfb__simd_pjob *j, int q) {
    sfb__ref_eval_patches(NULL, j->pt, NULL, j->locs, q, q + 1, j->out);
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


#endif /* SFB__SIMD_H */
