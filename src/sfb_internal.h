/* Private declarations shared by the core's modules (everything here is sfb__ prefixed). */
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
/* Transparent huge pages for the default allocator's big blocks (sfb__alloc): madvise and
 * MADV_HUGEPAGE are declared when the implementation's translation unit sees the BSD/GNU names
 * (C++, gnu99/gnu11, or _DEFAULT_SOURCE defined first); under strict -std=c99 they are not, and
 * the advice is simply left out. SFB_NO_HUGE_PAGES leaves it out everywhere. */
#if defined(__linux__) && !defined(SFB_NO_HUGE_PAGES)
#  include <sys/mman.h>
#endif

#ifndef SFB__PI
#define SFB__PI 3.14159265358979323846
#endif

/* Linkage of the module interfaces declared below (SFB__IF). In the amalgamation, surfblend.h,
 * the whole library is one translation unit and they are static: the compiler inlines across
 * modules as freely as within one, and a program that includes the implementation exports no
 * sfb__ names. A later definition without `static` keeps that internal linkage (C99 6.2.2p4,
 * and C++ likewise), so the modules' definitions are written plain. Modules compiled as their
 * own translation units (`make check-modules`, src/sfb_module.h) and the white-box suites, which
 * call internals from a library object built with SURFBLEND_EXPOSE_INTERNALS, get external
 * linkage. */
#if defined(SFB__SEPARATE_MODULES) || defined(SURFBLEND_EXPOSE_INTERNALS)
#  define SFB__IF
#elif defined(__GNUC__)
#  define SFB__IF static __attribute__((unused))
#else
#  define SFB__IF static
#endif

/* ---- a CPU thread pool a backend owns and lends (src/pool.c) ---- */
#if !defined(_WIN32) && (defined(__unix__) || defined(__unix) || defined(__APPLE__))
#  define SFB__THREADS 1
#  include <pthread.h>
#  include <unistd.h>
#endif
#define SFB__POOL_MAX_THREADS 64
typedef struct sfb__pool {
    int threads; /* threads sharing one run, the caller included (1: no workers) */
#ifdef SFB__THREADS
    int workers; /* pool threads running (threads - 1 once started) */
    pthread_t tid[SFB__POOL_MAX_THREADS];
    pthread_mutex_t busy; /* held by the one run using the pool */
    pthread_mutex_t lock; /* guards everything below */
    pthread_cond_t wake, done;
    unsigned long generation; /* bumped per job; idle workers wait for a change */
    int quit;
    /* the current job: items [first, last) cut into `chunks`, each run by task(owner, arg, a, b);
     * with `offsets` (stencil rows) chunks hold about equal entry counts, else equal items */
    void (*task)(const void *owner, const void *arg, int a, int b);
    const void *owner, *arg;
    const int *offsets;
    int first, last, chunks, next_chunk, chunks_done;
    size_t entry0, entries;
#endif
} sfb__pool;
/* Threads for a requested count (0: one per online core), at most SFB__POOL_MAX_THREADS; 1
 * where no thread support is known. */
SFB__IF int sfb__pool_threads(int requested);
/* Starts threads - 1 workers (a zeroed pool of one thread for threads <= 1): 1, or 0 with
 * `why` filled and nothing left running. */
SFB__IF int sfb__pool_start(sfb__pool *p, int threads, char *why, size_t why_size);
SFB__IF void sfb__pool_stop(sfb__pool *p);
/* Runs task over [first, last) on the pool, the caller included, and returns 1; returns 0
 * having run nothing when the pool has one thread or another run holds it. */
SFB__IF int sfb__pool_run(sfb__pool *p, void (*task)(const void *owner, const void *arg, int a, int b), const void *owner,
                          const void *arg, int first, int last, const int *offsets, size_t e0, size_t entries);
/* The `parallel` slot's contract on a backend's pool: task(arg, a, b) over [first, last). */
SFB__IF int sfb__pool_lend(sfb__pool *p, void (*task)(void *arg, int first, int last), void *arg, int first, int last);

/* ---- backend vtable ---- */
struct sfb__patch_table;
/* A stencil table: row r reads sizes[r] entries starting at offsets[r] from indices/weights. */
typedef struct sfb__stencils {
    int rows, sources;
    int *sizes, *offsets, *indices;
    float *weights;
    size_t entries;
} sfb__stencils;

/* The kernels a backend implements, filled by NAME in the backend's bind function
 * (sfb__ref_bind, sfb__simd_bind, sfb__gl_bind, sfb__osmesa_bind) on a zeroed table: a backend
 * that lacks a kernel writes nothing for it, and a NULL kernel slot makes the core run `ref`'s
 * (with a log line). Every slot but name/kind/init/shutdown may be NULL. A context keeps its
 * own copy of the bound table (no global state). */
struct sfb__shade_job;
struct sfb__raster_job;
typedef struct sfb__backend_vtable {
    const char *name;
    sfb_backend_kind kind;
    /* Returns SFB_SUCCESS and a state, or an error with `why` filled. The backend reads its
     * settings (threads, gl_use_current_context) from ctx and may keep ctx for errors/allocs. */
    sfb_result (*init)(sfb_context *ctx, void **state, char *why, size_t why_size);
    void (*shutdown)(sfb_context *ctx, void *state);
    /* One line saying what runs: ISA and threads, GL version and renderer. */
    void (*describe)(void *state, char *buf, size_t size);
    /* Called once per built table when a surface is created (upload to device memory);
     * `*handle` may stay NULL. release_stencils frees what upload made. */
    sfb_result (*upload_stencils)(void *state, const sfb__stencils *table, void **handle);
    void (*release_stencils)(void *state, void *handle);
    /* dst rows [first,last) = stencils applied to src; length components per element.
     * `handle` is what upload_stencils returned for this table (or NULL). */
    sfb_result (*eval_stencils)(void *state, const sfb__stencils *table, void *handle, int first, int last,
                                const float *src, sfb_buffer_desc src_desc,
                                float *dst, sfb_buffer_desc dst_desc);
    /* Same on GL buffer objects of the current (host) context: no copy through the CPU. */
    sfb_result (*eval_stencils_gl)(void *state, const sfb__stencils *table, void *handle,
                                   unsigned src_buffer, sfb_buffer_desc src_desc,
                                   unsigned dst_buffer, sfb_buffer_desc dst_desc);
    /* Patch tables (limit evaluation): upload once per surface, then evaluate locations
     * [first,last) (already validated) into the non-NULL arrays of `out` (xyz per location). */
    sfb_result (*upload_patches)(void *state, const struct sfb__patch_table *table, void **handle);
    void (*release_patches)(void *state, void *handle);
    sfb_result (*eval_patches)(void *state, const struct sfb__patch_table *table, void *handle,
                               const sfb_location *locations, int first, int last, const sfb_eval_output *out);
    /* Seed 001's blend, for elements i in [first,last) (xyz arrays, stride 3):
     *   L = tu[i] x tv[i], normalised (a zero cross product stays zero);
     *   k = ns_index ? ns_index[i] : -1; when k >= 0 and b[i] > 0: S = ns[k] normalised (zero stays
     *   zero), B = (1 - b[i]^p) L + b[i]^p S, else B = L; out_blend[i] = B normalised (zero stays zero).
     * out_limit[i] = L and out_sub[i] = S (zero when k < 0) when those pointers are not NULL.
     * b in [0,1] and p > 0 are checked by the caller; b^p is pow(b, p) (b == 1 gives exactly 1). */
    sfb_result (*finish_normals)(void *state, int first, int last, const float *tu, const float *tv,
                                 const float *ns, const int *ns_index, const float *b, float p,
                                 float *out_blend, float *out_limit, float *out_sub);
    /* Seed 003's per-pixel analysis (analyze.c): items [first,last) of `job` (exact limit
     * position, derivatives and normal per pixel) -> the mode's values (sfb__shade_job). */
    sfb_result (*shade)(void *state, const struct sfb__shade_job *job, int first, int last);
    /* Seed 003's proxy raster (analyze.c): every triangle of `job` into its per-pixel buffers,
     * the nearest one kept (sfb__raster_job). */
    sfb_result (*raster)(void *state, const struct sfb__raster_job *job);
    /* The backend's CPU threads lent to the core (sfb__parallel): runs task(arg, a, b) over
     * chunks [a, b) covering [first, last) on its threads, the caller's included, and returns 1
     * once all have run; returns 0 having run nothing (no threads, or a call of another thread
     * holds them). Not a kernel: a NULL slot means the core runs the task itself, on ref too. */
    int (*parallel)(void *state, void (*task)(void *arg, int first, int last), void *arg, int first, int last);
    /* 1: the kernels may also be called inside a task lent through `parallel` (each call then
     * runs on that one thread: simd, whose analysis rounds run in chunks so); 0: from the
     * calling thread only (gl, osmesa: their GL context is current there alone). */
    int kernels_in_tasks;
} sfb__backend_vtable;

/* One analysis's shading (the `shade` slot). Per item i: P = position[3i..], N = normal (unit),
 * turned toward the viewer (V = eye - P, or -fwd when orthographic); R = -V/|V| reflected
 * about N. The mode's values (value2 may be NULL for modes without a second one):
 *   REFLECTION: mu = ((lc - P).lm) / (R.lm); mu <= 0 or |R.lm| < 1e-9: NaN (missed); X = P + mu R,
 *     value = ((X - lc).lu / lsize[0] + 0.5) * periods[0], value2 = ((X - lc).lv / lsize[1] + 0.5) * periods[1];
 *     X outside the plane's extent (either coordinate outside [0, periods]): NaN;
 *   HIGHLIGHT: the same with Dir = N and mu of any sign (only |N.lm| < 1e-9 misses), no extent;
 *   ZEBRA: value = periods[0] * acos(R.dir) / pi;  ISOPHOTE: value = N.dir;
 *   CURVATURE: Gaussian K = (LN - M^2) / (EG - F^2), mean H = -(EN - 2FM + GL) / (2 (EG - F^2)) (convex
 *     toward the viewer > 0), or
 *     max |k| = |H| + sqrt(max(H^2 - K, 0)), from du, dv (E, F, G) and duu, duv, dvv along N (L, M, N);
 *     a degenerate first fundamental form gives NaN;
 *   NORMALS, SHADED: value = N.dir (the diffuse term). */
typedef struct sfb__shade_job {
    int mode, curvature, ortho;
    double eye[3], fwd[3];
    double lc[3], lm[3], lu[3], lv[3], lsize[2], periods[2], dir[3];
    const float *position, *du, *dv, *normal, *duu, *duv, *dvv;
    float *value, *value2;
} sfb__shade_job;
SFB__IF sfb_result sfb__ref_shade(void *state, const sfb__shade_job *job, int first, int last);

/* One analysis's proxy raster (the `raster` slot). Vertices are in the picture: x, y in pixels
 * (y down, pixel (i, j)'s centre at (i + 0.5, j + 0.5)), z the view depth (> 0), q = 1 / z
 * (perspective) or 1 (orthographic), (u, v) in the face's frame. A triangle (three vertices
 * and its parametric face, in order) covers the pixel centres inside it or on its edges; its
 * attributes there are the vertices' weighted by b_k q_k / sum(b_j q_j) (b the barycentric
 * coordinates in the picture: perspective-correct), its depth the interpolated z (that is
 * 1 / sum(b_j q_j) in perspective). A pixel keeps the triangle of the smallest depth below
 * what it holds (the first of equal ones, in order): depth[pix], face[pix], uv[2 pix..] (clamped
 * to [0, 1]) and, with apos and anrm (3 per vertex each), pos[3 pix..] and nrm[3 pix..].
 * The caller fills depth with +inf and face with -1. Triangles whose screen area is below
 * 1e-12 square pixels cover nothing; kernels may differ from ref on pixels whose centre lies on
 * an edge (GL's tie rule) and by float rounding of the interpolation.
 * nfront (0: all) and zmax (NULL: none; h rows of (w + 7) / 8 floats of scratch) are a hint: the
 * triangles from nfront on are likely hidden by those before, and a kernel may skip any whose
 * pixels would all fail the depth test (ref's: the largest depth per 8 pixels of a row, taken
 * after the first nfront triangles, against the triangle's smallest vertex depth). */
typedef struct sfb__raster_vertex { double x, y, z, q, u, v; } sfb__raster_vertex;
typedef struct sfb__raster_job {
    int w, h, ortho;
    int ntri, nfront;
    const sfb__raster_vertex *vert;
    const float *apos, *anrm; /* NULL, or the vertices' positions and normals to interpolate */
    const int *tri;          /* 4 per triangle: three vertices, the parametric face */
    float *depth;
    int *face;
    float *uv, *pos, *nrm;
    float *zmax;
    const float *ybox; /* NULL, or per triangle (in order) its vertices' smallest and largest y, rounded outward to
                          float: a hint for skipping the triangles outside a band of rows before reading them */
} sfb__raster_job;
/* A triangle's set-up in the picture: its signed doubled area, barycentric planes (b_k = ea[k] x + eb[k] y + ec[k]) and the pixel box of the
 * centres within `grow` pixels of it (x0 > x1 or y0 > y1: none); 0 when it is degenerate. */
typedef struct sfb__raster_edges {
    double area, ea[3], eb[3], ec[3];
    int x0, x1, y0, y1;
} sfb__raster_edges;
SFB__IF int sfb__raster_setup(const sfb__raster_vertex *const S[3], int w, int h, double grow, sfb__raster_edges *t);
SFB__IF sfb_result sfb__ref_raster(void *state, const sfb__raster_job *job);
/* ref's raster of the picture's rows [row0, row1) only (each pixel is written by the triangles
 * over it in order, so disjoint row ranges may run at once: the simd backend's threads). */
SFB__IF void sfb__raster_rows(const sfb__raster_job *job, int row0, int row1);

/* Optional backends (backends/sfb_*.h), compiled in by SURFBLEND_SIMD / _GL / _OSMESA or
 * SURFBLEND_ALL_BACKENDS; the headers are included at the end of the implementation. */
#if defined(SURFBLEND_ALL_BACKENDS)
#  ifndef SURFBLEND_SIMD
#    define SURFBLEND_SIMD
#  endif
#  ifndef SURFBLEND_GL
#    define SURFBLEND_GL
#  endif
#  ifndef SURFBLEND_OSMESA
#    define SURFBLEND_OSMESA
#  endif
#endif
#if defined(SURFBLEND_OSMESA) && !defined(SURFBLEND_GL)
#  define SURFBLEND_GL /* osmesa runs the gl kernels */
#endif
/* Each fills the slots its backend implements (see sfb__backend_vtable). */
typedef void (*sfb__backend_bind_fn)(sfb__backend_vtable *vt);
SFB__IF void sfb__ref_bind(sfb__backend_vtable *vt);
/* Zeroes *vt and binds the backend `kind` into it; 0 when that backend is not built in. */
SFB__IF int sfb__backend_bind(sfb_backend_kind kind, sfb__backend_vtable *vt);
#ifdef SURFBLEND_SIMD
SFB__IF void sfb__simd_bind(sfb__backend_vtable *vt);
#endif
#ifdef SURFBLEND_GL
SFB__IF void sfb__gl_bind(sfb__backend_vtable *vt);
#endif
#ifdef SURFBLEND_OSMESA
SFB__IF void sfb__osmesa_bind(sfb__backend_vtable *vt);
#endif
/* The ref kernels, callable directly (the oracle; other backends hand it what they cannot do). */
SFB__IF sfb_result sfb__ref_eval_stencils(void *state, const sfb__stencils *t, void *handle, int first, int last, const float *src,
                                  sfb_buffer_desc sd, float *dst, sfb_buffer_desc dd);
struct sfb__patch_table;
SFB__IF sfb_result sfb__ref_eval_patches(void *state, const struct sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                 int last, const sfb_eval_output *out);
SFB__IF sfb_result sfb__ref_finish_normals(void *state, int first, int last, const float *tu, const float *tv, const float *ns,
                                   const int *ns_index, const float *b, float p, float *out_blend, float *out_limit, float *out_sub);

/* ---- Stam eigen structures (patch/eigen.c) ---- */
#define SFB__STAM_MAX_VALENCE 256

typedef struct sfb__eigen_cc {
    int N, K;
    int dominant;      /* index of lambda = 1 (right eigenvector all ones) */
    double sub;        /* largest |lambda| among the others (the subdominant eigenvalue) */
    double error;      /* max |A - V L V^-1| found by the build */
    double *lambda;    /* K */
    double *vinv;      /* K x K, row i = left eigenvector i */
    double *phi;       /* 3 x 16 x K: phi[((k-1)*16 + j)*K + i] */
    double *v;         /* K x K right eigenvectors (columns), only when asked to keep them */
    double *a;         /* K x K subdivision matrix, only when asked to keep it */
} sfb__eigen_cc;

typedef struct sfb__eigen_loop {
    int N, K;          /* K = N + 6 */
    int dominant;      /* index of lambda = 1 */
    double sub;        /* the subdominant eigenvalue 3/8 + cos(2 pi/N)/4 */
    double error;      /* max |A - V J V^-1| found by the build */
    double *lambda;    /* K */
    int *head;         /* K: the Jordan head of a block's second vector, -1 for the others */
    double *vinv;      /* K x K */
    double *phi;       /* 3 x 15 x K: Bezier points phi[(k*15 + j)*K + i] of sub-patch k */
    double *v, *a;     /* V (K x K) and A with Abar's 6 extra rows ((K+6) x K), only when kept */
} sfb__eigen_loop;


/* ---- patch tables (patch/table.c reads them, the scheme builders write them) ---- */
/* Patch kinds of the patch table (patches.c, manifold.c). */
enum { SFB__PATCH_BSPLINE = 0, SFB__PATCH_STAM = 1, SFB__PATCH_ENDCAP = 2, SFB__PATCH_BEZTRI = 3, SFB__PATCH_STAM_LOOP = 4,
       SFB__PATCH_ENDCAP_TRI = 5, SFB__PATCH_MANIFOLD4 = 6, SFB__PATCH_TYPE_COUNT = 7 };
/* Kernel families: the record types one backend kernel evaluates together (one file per backend
 * each, docs/ARCHITECTURE.md). */
enum { SFB__FAMILY_QUAD = 0,     /* BSPLINE16, STAM, ENDCAP: polynomial quad patches */
       SFB__FAMILY_TRI = 1,      /* BEZTRI15, STAM_LOOP, ENDCAP_TRI: polynomial triangle patches */
       SFB__FAMILY_MANIFOLD = 2, /* MANIFOLD4: seed 000's blend of chart geometries */
       SFB__FAMILY_COUNT = 3 };
static inline int sfb__patch_family(int type) {
    return type <= SFB__PATCH_ENDCAP ? SFB__FAMILY_QUAD : type <= SFB__PATCH_ENDCAP_TRI ? SFB__FAMILY_TRI : SFB__FAMILY_MANIFOLD;
}
/* A patch's sub-square of its parametric face: depth | i << 4 | j << 17 | corner << 30. */
#define SFB__PARAM(depth, i, j, corner) ((unsigned)(depth) | ((unsigned)(i) << 4) | ((unsigned)(j) << 17) | ((unsigned)(corner) << 30))
#define SFB__PARAM_DEPTH(p) ((int)((p) & 15u))
#define SFB__PARAM_I(p) ((int)(((p) >> 4) & 8191u))
#define SFB__PARAM_J(p) ((int)(((p) >> 17) & 8191u))
#define SFB__PARAM_CORNER(p) ((int)(((p) >> 30) & 3u))
/* Sabin's rules (stam.c): the 12 box-spline points' lattice offsets and the quartic Bezier
 * points from them (ALGORITHMS.md 5.1). */
extern const signed char sfb__box12[12][2];
extern const unsigned char sfb__bez15_from_box[15][12];

/* What a patch table is, for its readers (locate, evaluation kernels, tessellation): the
 * parametric DOMAIN of its faces, and per record a kernel FAMILY (from the record's type,
 * sfb__patch_family). Only the scheme builders know the scheme; nothing reading a table asks it. */
enum { SFB__DOMAIN_QUAD = 0,   /* (u,v) in [0,1]^2, quadtree sub-patches */
       SFB__DOMAIN_TRI = 1 };  /* barycentric (u,v), u + v <= 1, triangle-tree sub-patches */
typedef struct sfb__patch_table {
    int domain;            /* SFB__DOMAIN_*, set by the builder */
    int isolation, max_depth;
    int npatch, ncv, nptex, nnodes;
    int *ptype;            /* SFB__PATCH_* per patch */
    int *pfirst;           /* npatch + 1: first control point of each patch in cv */
    unsigned *pparam;      /* depth | i << 4 | j << 17 | corner << 30 (sub-square of the param face) */
    int *pvalence;         /* Stam patches: valence of the extraordinary vertex */
    int *cv;               /* control points: rows of `points` */
    int *ptex_face, *ptex_corner; /* per param face: base face, sub-face (-1 for a quad) */
    int *face_ptex;        /* per base face + 1: first param face */
    int *ptex_root;        /* per param face: >= 0 node, <= -2 patch -(p+2), -1 hole */
    int *nodes;            /* 4 per quadtree node, by quadrant x + 2y, same encoding */
    int counts[SFB__PATCH_TYPE_COUNT]; /* patches of each type (SFB__PATCH_*) */
    unsigned *pcorner;     /* MANIFOLD4: 4 corner codes per patch (SFB__MF_CODE) */
    int mf_weights;        /* MANIFOLD4: SFB_MANIFOLD_WEIGHTS_* */
    int npoints;           /* patch points */
    float *point_data;     /* xyz per patch point, for the surface's base positions */
    /* NULL, or (tribezier with the slider option) per patch SFB__TBZ_BLEND floats: its 15
     * points in the smooth net (45) and in the sharp net (45); point_data is their blend
     * (sfb__tribezier_blend), each point's s from `features`. Owned, both. */
    float *blend;
    struct sfb__tbz_features *features;
    const sfb__eigen_cc *eig[SFB__STAM_MAX_VALENCE + 1]; /* valences used (the context's cache) */
    const sfb__eigen_loop *eigl[SFB__STAM_MAX_VALENCE + 1]; /* Loop: the same */
    /* NULL, or a table of the same parametric faces whose evaluated position, normalised, is
     * the surface's normal in place of du x dv (PN triangles' quadratic normal field); its own
     * normal_field is NULL. Owned: sfb__patch_table_free frees it. */
    struct sfb__patch_table *normal_field;
} sfb__patch_table;

/* ---- context ---- */
struct sfb_context {
    sfb_allocator allocator;
    sfb_logger logger;
    sfb_progress progress;
    size_t budget, live_bytes, peak_bytes;
    int budget_refused;                /* the last failed allocation was refused by the budget */
    unsigned long surfaces_made;       /* sfb_surface.serial */
    int threads, gl_use_current_context;
    sfb_backend_kind order[SFB_BACKEND_KIND_COUNT_];
    int order_count;
    const sfb__backend_vtable *backend; /* &backend_vt once a backend is selected, else NULL */
    void *backend_state;
    sfb__backend_vtable backend_vt;     /* the selected backend's bound table */
    sfb__backend_vtable ref_vt;         /* ref's, for the kernels the selected backend lacks */
    sfb__eigen_cc *eigen_cc[SFB__STAM_MAX_VALENCE + 1]; /* per valence, built on first use */
    unsigned char eigen_cc_failed[SFB__STAM_MAX_VALENCE + 1];
    sfb__eigen_loop *eigen_loop[SFB__STAM_MAX_VALENCE + 1];
    unsigned char eigen_loop_failed[SFB__STAM_MAX_VALENCE + 1];
    char report[2048];
    char error[1024];
    sfb_error_info error_info;
};

SFB__IF void *sfb__alloc(sfb_context *ctx, size_t size);
SFB__IF void *sfb__calloc(sfb_context *ctx, size_t count, size_t size);
SFB__IF void *sfb__realloc(sfb_context *ctx, void *ptr, size_t size);
SFB__IF void sfb__free(sfb_context *ctx, void *ptr);
/* count*size with overflow check; returns 0 on overflow. */
SFB__IF int sfb__mul_size(size_t a, size_t b, size_t *out);
SFB__IF sfb_result sfb__error(sfb_context *ctx, sfb_result r, sfb_element_kind kind, long index, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
SFB__IF void sfb__log(sfb_context *ctx, int level, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Reports a failed allocation: SFB_LIMIT_EXCEEDED when the memory budget refused it,
 * SFB_OUT_OF_MEMORY when the allocator itself failed. */
SFB__IF sfb_result sfb__oom(sfb_context *ctx, const char *what);
/* The context's last error, kept across an internal attempt whose failure the caller recovers
 * from (the caller's earlier error, not the attempt's, is what sfb_last_error reads after a
 * successful call): sfb__error_keep before the attempt, sfb__error_put_back after it failed. */
typedef struct sfb__error_state {
    char message[sizeof(((sfb_context *)0)->error)];
    sfb_error_info info;
} sfb__error_state;
SFB__IF void sfb__error_keep(const sfb_context *ctx, sfb__error_state *st);
SFB__IF void sfb__error_put_back(sfb_context *ctx, const sfb__error_state *st);
/* Returns SFB_CANCELLED (with the error set) when the callback asks to stop. */
SFB__IF sfb_result sfb__progress(sfb_context *ctx, float done, const char *stage);
/* Runs task(arg, a, b) over [first, last): in chunks on the backend's threads when it lends
 * them (the `parallel` slot), else as one call task(arg, first, last) here. The results must
 * not depend on the chunks: a task writes only its own items' memory (or per-item slots the
 * caller reduces afterwards) and calls nothing on ctx (errors, logs, allocations, progress:
 * those are not thread-safe). Worth it from a few thousand items of ~100 ns on. */
SFB__IF void sfb__parallel(sfb_context *ctx, void (*task)(void *arg, int first, int last), void *arg, int first, int last);
SFB__IF sfb_result sfb__select_backend(sfb_context *ctx, const char *env_override);
SFB__IF sfb_result sfb__context_create_reporting(const sfb_context_config *config, sfb_context **out, char *report, size_t size);
SFB__IF void sfb__eigen_cc_free(sfb_context *ctx, sfb__eigen_cc *e);
SFB__IF sfb_result sfb__eigen_cc_build(sfb_context *ctx, int N, int keep, sfb__eigen_cc **out);
SFB__IF const sfb__eigen_cc *sfb__eigen_cc_get(sfb_context *ctx, int N);
SFB__IF void sfb__eigen_loop_free(sfb_context *ctx, sfb__eigen_loop *e);
SFB__IF sfb_result sfb__eigen_loop_build(sfb_context *ctx, int N, int keep, sfb__eigen_loop **out);
SFB__IF const sfb__eigen_loop *sfb__eigen_loop_get(sfb_context *ctx, int N);
/* Index of the lattice point (x, y) in the enlarged set of the Loop eigen structure of valence
 * N, -1 if not in it (patch/eigen.c). */
SFB__IF int sfb__loop_index(int N, int x, int y);

/* ---- topology of one level ---- */
enum { SFB__TAG_BOUNDARY = 1, SFB__TAG_NONMANIFOLD = 2 };
enum { SFB__RULE_SMOOTH = 1, SFB__RULE_DART = 2, SFB__RULE_CREASE = 4, SFB__RULE_CORNER = 8 };

typedef struct sfb__level {
    int nv, nf, ne, nfv;
    int *fv_off, *fv, *fe;      /* face vertices, face edges (edge i runs fv[i] -> fv[i+1]) */
    int *ev;                    /* 2 per edge */
    int *ef_off, *ef, *ef_slot; /* faces of each edge, and the edge's slot in that face */
    int *vf_off, *vf, *vf_slot; /* faces around each vertex (counter-clockwise when manifold) */
    int *ve_off, *ve;           /* edges around each vertex (edge i precedes face i) */
    float *es, *vs;             /* edge and vertex sharpness */
    unsigned char *etag, *vtag, *vrule, *fhole;
} sfb__level;

SFB__IF void sfb__level_free(sfb_context *ctx, sfb__level *l);
/* From nv, nf, fv_off, fv, fe, ne, ev: builds every adjacency array and the tags. */
SFB__IF sfb_result sfb__level_complete(sfb_context *ctx, sfb__level *l);
/* The same where the caller has set vf_off, vf, vf_slot, ve_off and ve already, each manifold
 * vertex's rings as sfb__level_complete orders them (counter-clockwise, from the face of the
 * lowest index, or at a boundary from the face whose outgoing edge is a boundary edge); only
 * their counts are checked (the non-manifold and boundary tags). A refinement step that knows
 * its children's rings from the parent's spares the walk around every vertex. */
SFB__IF sfb_result sfb__level_complete_ordered(sfb_context *ctx, sfb__level *l);
/* Sharpness/rule helpers shared by refinement and info. */
SFB__IF int sfb__rule_from(float vertex_sharpness, int sharp_edge_count);
SFB__IF void sfb__level_compute_rules(sfb__level *l);
/* The end of edge e that is not v (topology.c). */
SFB__IF int sfb__other_end(const sfb__level *l, int e, int v);

/* ---- the stencil algebra (stencil.c) ---- */
/* Composed rows (double weights): row r holds entries [off[r], off[r+1]) of idx/w. */
typedef struct sfb__rows {
    int rows;
    size_t *off;   /* rows + 1 */
    int *idx;
    double *w;
    size_t n, cap;
} sfb__rows;
/* A local mask: (vertex, weight) pairs, duplicates allowed. */
typedef struct sfb__mask {
    int *idx;
    double *w;
    int n, cap;
} sfb__mask;
#define SFB__MASK_ADD(m, i, wt) do { (m)->idx[(m)->n] = (i); (m)->w[(m)->n] = (wt); (m)->n++; } while (0)
/* A dense accumulator over source vertices, for composing masks with rows. */
typedef struct sfb__accum {
    double *acc;
    unsigned *mark;
    int *touched;
    unsigned stamp;
} sfb__accum;
SFB__IF void sfb__rows_free(sfb_context *ctx, sfb__rows *r);
/* Room for `need` entries in all; 0 on allocation failure. */
SFB__IF int sfb__rows_reserve(sfb_context *ctx, sfb__rows *r, size_t need);
/* Room for `need` more pairs; 0 on allocation failure. */
SFB__IF int sfb__mask_grow(sfb_context *ctx, sfb__mask *m, int need);
/* Adds w * (face centroid of f). */
SFB__IF void sfb__mask_face(sfb__mask *m, const sfb__level *l, int f, double w);
/* An upper bound of the pairs a vertex rule of v adds. */
SFB__IF int sfb__mask_need_vertex(const sfb__level *l, int v);
/* Row `row` of `out` = mask m composed with the parent rows prow; 0 on allocation failure or when
 * the accumulator's stamp wrapped (the caller resets it). */
SFB__IF int sfb__compose_row(sfb_context *ctx, sfb__accum *A, const sfb__rows *prow, const sfb__mask *m, sfb__rows *out, int row);
/* Mask m as row `row` of out, as sfb__compose_row over identity rows gives it (stencil.c). */
SFB__IF int sfb__rows_append_mask(sfb_context *ctx, sfb__rows *out, const sfb__mask *m, int row);
/* The float stencil table of r (over `sources` source elements). */
SFB__IF sfb_result sfb__rows_to_stencils(sfb_context *ctx, const sfb__rows *r, int sources, sfb__stencils *s);
/* The same for rows the caller would free next: their blocks become the table's (r left empty;
 * on failure as it was). */
SFB__IF sfb_result sfb__rows_move_to_stencils(sfb_context *ctx, sfb__rows *r, int sources, sfb__stencils *s);

/* ---- mesh (mesh.c) ---- */
/* Line numbers of OBJ statements, so that errors found while building the mesh can name the
 * line they came from. Internal: sfb_mesh_read_obj passes it, sfb_mesh_create does not. */
typedef struct sfb__src_lines {
    const int *face, *crease, *corner, *hole;
} sfb__src_lines;
/* Builds a level (topology only, zero sharpness) from faces; validates indices. */
SFB__IF sfb_result sfb__level_from_faces(sfb_context *ctx, int nv, int nf, const int *sizes, const int *fvin, const sfb__src_lines *lines,
                                 sfb_element_kind vkind, sfb__level *l);
/* sfb_mesh_create with OBJ line numbers for the errors (lines may be NULL). */
SFB__IF sfb_result sfb__mesh_create(sfb_context *ctx, const sfb_mesh_desc *d, const sfb__src_lines *lines, sfb_mesh **out);
struct sfb_mesh {
    sfb_context *ctx;
    sfb__level base;            /* topology, with user sharpness (not yet boundary-sharpened) */
    float *positions;
    int uv_count;
    float *uvs;
    int *face_uvs;
    int boundary, crease_method, triangle_rule, uv_interp;
    /* desc view arrays */
    int *face_sizes;
    int crease_count; int *crease_vertices; float *crease_sharpness;
    int corner_count; int *corner_vertices; float *corner_sharpness;
    int hole_count; int *holes;
};

/* ---- subdivision shading (shade.c) ---- */
typedef struct sfb__shading {
    int normals_level, weights_level, level, variant, darts;
    sfb__level nlev;           /* topology at the normals level (face normals are taken there) */
    int *nsrc_of_vf;           /* per nlev vf entry: the source (region normal) the face feeds */
    int nsrc;                  /* sources: one normal per vertex region at the normals level */
    int npos_mode;             /* normals-level positions: 0 base positions, 1 the npos table, 2 refined positions */
    sfb__stencils npos;        /* base -> normals-level positions (npos_mode 1) */
    int nout, nweighted, nsplit;
    int *out_origin;           /* nout: refined vertex of each output vertex */
    int *out_fv;               /* per refined face-vertex: output vertex */
    float *b;                  /* nout: blend weight */
    int *ns_idx_w, *ns_idx_all;/* nout: row of N_S for finish_normals (-1 where b = 0 / every row) */
    sfb__stencils ns;          /* sources -> N_S rows, the nweighted rows with b > 0 first */
    sfb__stencils lim[3];      /* refined positions -> limit position, tangent u, tangent v per output vertex */
    void *handles[5];          /* the backend's uploads of npos, ns, lim[0..2] */
    size_t bytes;
    int averaging;             /* sfb_shade_averaging */
    int nsteps;                /* per-level N_S (averaging != linear and level > normals level): steps, else 0 and ns is used */
    sfb__stencils *steps;      /* nsteps: region normals of level normals+k -> level normals+k+1; the last -> N_S rows in ns's order */
    int step_rows_max, step_size_max; /* largest row count and row size over the steps (scratch) */
} sfb__shading;
/* ---- surfaces ---- */
struct sfb_surface {
    sfb_context *ctx;
    unsigned long serial;        /* the context's count of surfaces at its creation (from 1), and again at each
                                    sfb_surface_set_sharpness or _set_feature_sharpness, the calls that change a
                                    surface: data derived from it alone may be kept under it (sfb_analysis_workspace) */
    sfb_surface_config config;
    int base_vertex_count, base_uv_count, base_face_count;
    float *base_positions, *base_uvs;
    sfb__level top;              /* topology of the refined level */
    sfb__level uv_top;           /* topology of the refined UV layout (when built) */
    sfb__level uv_base;          /* the prepared base UV layout (UVs and patches): tessellated UVs (tess.c) */
    int has_uvs;
    sfb__stencils tables[SFB_TABLE_COUNT_];
    int built[SFB_TABLE_COUNT_];
    void *backend_tables[SFB_TABLE_COUNT_]; /* the backend's uploaded copies (upload_stencils) */
    const sfb__backend_vtable *uploaded_by;
    int boundary, crease_method, triangle_rule, uv_interp;
    int has_patches;
    sfb__patch_table patches;    /* limit evaluation (SFB_REFINE_PATCHES) */
    sfb__level pbase;            /* the prepared base level the patches were built from (tessellation
                                    shares vertices along its edges) */
    void *backend_patches;       /* the backend's uploaded copy */
    void *backend_normal_field;  /* ... and of patches.normal_field, when there is one */
    sfb__shading *shading;       /* SFB_REFINE_SHADING */
};

typedef struct sfb__refine_options {
    sfb_scheme scheme;   /* boundary options are applied beforehand, by sfb__level_prepare */
    int crease_method, triangle_rule;
    int want_limit;
    int linear;          /* bilinear masks on the scheme's own face split (linear UVs) */
} sfb__refine_options;

/* ---- schemes at the API edge (scheme.c) ---- */
/* The public SFB_SCHEME_CAN_* bits, plus the ones only the library reads. */
enum { SFB__SCHEME_REFINES = SFB_SCHEME_CAN_REFINE,    /* uniform refinement (and limit stencils) by its rules */
       SFB__SCHEME_SHADES = SFB_SCHEME_CAN_SHADE,      /* subdivision shading (seed 001) */
       SFB__SCHEME_TRIANGLES = SFB_SCHEME_TRIANGLES,   /* faces must be triangles */
       SFB__SCHEME_BOUNDARY_HOLES = 1u << 3, /* boundary NONE makes boundary faces holes (OpenSubdiv) */
       SFB__SCHEME_LINEAR_UVS = 1u << 4,     /* tessellated UVs follow each face linearly (PN: the scheme on a
                                                planar layout is the linear map, and a UV triangle may be flat) */
       SFB__SCHEME_UVS_OR_LINEAR = 1u << 5   /* tessellated UVs: the scheme's own surface of the UV layout, or
                                                linear per face where its builder refuses the layout (tribezier:
                                                a flat or non-manifold UV triangle) */ };
typedef struct sfb__scheme_info {
    sfb_scheme scheme;
    const char *name;   /* sfb_scheme_name, sfb_scheme_parse */
    const char *title;  /* for messages */
    sfb_scheme rules;   /* the rules refine.c (and shade.c) apply for it */
    unsigned caps;      /* SFB__SCHEME_* */
    /* Its patch table for SFB_REFINE_PATCHES (NULL: not evaluated); prep is the prepared base
     * level, opt has the rules. A scheme without REFINES but with a builder is evaluated only
     * (level 0). */
    sfb_result (*build_patches)(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt,
                                const sfb_surface_config *cfg, const float *positions, sfb__patch_table *pt);
} sfb__scheme_info;
SFB__IF const sfb__scheme_info *sfb__scheme_info_of(sfb_scheme s);  /* NULL for a value that is no scheme */
/* Refuses a scheme that cannot be built as configured (NULL si, not refinable, evaluated only). */
SFB__IF sfb_result sfb__scheme_check_kind(sfb_context *ctx, const sfb__scheme_info *si, const sfb_surface_config *cfg);
/* Refuses flags (SFB_REFINE_PATCHES, SFB_REFINE_SHADING) the scheme does not support. */
SFB__IF sfb_result sfb__scheme_check_flags(sfb_context *ctx, const sfb__scheme_info *si, const sfb_surface_config *cfg);

/* Refines `base` (already sharpened) `level` times; fills `top` and the stencil tables
 * (vertex, and limit/tangents when asked). */
SFB__IF sfb_result sfb__refine(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int level,
                       sfb__level *top, sfb__stencils *vertex_table, sfb__stencils *limit_tables /* [3] or NULL */,
                       float progress_from, float progress_to);
/* What sfb__refine_keep_levels hands over besides `top`: the levels 1 .. level-1 (lev[0] is
 * left empty: the base is the caller's) and the step tables T[k] from level k to k + 1 (rows over
 * level k's vertices), in caller-allocated arrays of `level` zeroed entries; the receiver owns
 * them (freed on failure). The shading build takes them instead of refining again. */
typedef struct sfb__refine_kept {
    sfb__level *lev;
    sfb__stencils *T;
} sfb__refine_kept;
SFB__IF sfb_result sfb__refine_keep_levels(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int level,
                                   sfb__level *top, sfb__stencils *vertex_table, sfb__stencils *limit_tables,
                                   sfb__refine_kept *keep, float progress_from, float progress_to);
SFB__IF void sfb__refine_kept_free(sfb_context *ctx, sfb__refine_kept *keep, int level);
SFB__IF void sfb__stencils_free(sfb_context *ctx, sfb__stencils *s);
/* sfb__refine_step that also writes the step's own rows (children over the parent's vertices)
 * into `local` when not NULL; with prow NULL only `local` (crow and A unused) (refine.c). */
SFB__IF sfb_result sfb__refine_step_local(sfb_context *ctx, const sfb__refine_options *opt, const sfb__level *p,
                                  const sfb__rows *prow, sfb__level *c, sfb__rows *crow, sfb__rows *local, sfb__accum *A,
                                  sfb__mask *m, float *ps, float *cs, float p0, float dp);
/* One refinement step of `p` (composed rows prow) into `c` (composed rows crow); A, m, ps, cs are
 * the caller's scratch; progress from p0 over dp. */
SFB__IF sfb_result sfb__refine_step(sfb_context *ctx, const sfb__refine_options *opt, const sfb__level *p, const sfb__rows *prow,
                            sfb__level *c, sfb__rows *crow, sfb__accum *A, sfb__mask *m, float *ps, float *cs, float p0, float dp);
/* The crease pair of a vertex: first and last incident edge with sharpness > 0 in ve order. */
SFB__IF void sfb__crease_pair(const float *sharp, int n, int *a, int *b);
/* Crease limit tangent masks at v between its crease edges a and b (either order; loop: Loop's scale). */
SFB__IF void sfb__crease_tangent_masks(const sfb__level *l, int v, int a, int b, int loop, sfb__mask *m1, sfb__mask *m2);
/* Limit position and tangent masks of vertex v by its rule. */
SFB__IF void sfb__limit_masks(const sfb__level *l, int v, sfb_scheme scheme, sfb__mask *mp, sfb__mask *m1, sfb__mask *m2);
/* Copy of the base level with OpenSubdiv's boundary/non-manifold sharpening and holes applied. */
SFB__IF sfb_result sfb__level_prepare(sfb_context *ctx, const sfb__level *src, int sharpen_corners, int make_boundary_holes,
                              sfb__level *dst);
/* Does sfb__level_prepare make vertex v of a prepared level infinitely sharp whatever its tag (a
 * boundary vertex of one face with sharpen_corners; a non-manifold vertex, unless it joins two
 * sheets along two non-manifold edges)? */
SFB__IF int sfb__level_forced_sharp(const sfb__level *d, int v, int sharpen_corners);

/* Rows [0, rows) of table t on the context's backend (handle: its upload of t), or on ref when
 * the backend lacks eval_stencils (surface.c). */
SFB__IF sfb_result sfb__surface_apply(const sfb_surface *s, const sfb__stencils *t, void *handle, int rows, const float *src,
                              sfb_buffer_desc sd, float *dst, sfb_buffer_desc dd);
/* Small helpers of the software pictures (render.c), shared with the analysis (analyze.c): 3-vector
 * dot, cross and normalise (returns the length; a zero or non-finite vector is left as it is),
 * clamp; the share of the footprint [w - fw/2, w + fw/2] a unit-periodic band [a, b] covers (band
 * filtering); the blue-cyan-green-yellow-red map of t in [0,1]; a [0,1] value as a byte. */
SFB__IF double sfb__rdot(const double *a, const double *b);
SFB__IF void sfb__rcross(const double *a, const double *b, double *o);
SFB__IF double sfb__rnormalize(double *a);
SFB__IF double sfb__rclamp(double x, double lo, double hi);
SFB__IF void sfb__orbit_up(const float up[3], double dir[3], double right[3]);
SFB__IF double sfb__band_cover(double w, double fw, double a, double b);
SFB__IF void sfb__colormap(double t, double *rgb);
SFB__IF unsigned char sfb__to_byte(double v);
/* sfb_surface_eval without the per-location checks, for locations the library made itself
 * (analyze.c): the context's backend or ref (surface.c). */
SFB__IF sfb_result sfb__surface_eval_unchecked(const sfb_surface *s, const sfb_location *loc, int count, const sfb_eval_output *out);
/* The refined (or limit) mesh of a surface into o (surface.c). */
/* Tessellated UVs (surface.c, where the scheme is read): smooth (the layout's limit) or linear,
 * and the patch table of the base UV layout. */
SFB__IF int sfb__surface_smooth_uvs(const sfb_surface *s);
SFB__IF sfb_result sfb__surface_uv_patches(const sfb_surface *s, struct sfb__patch_table *upt);
SFB__IF sfb_result sfb__refine_output(const sfb_surface *s, const float *base, int base_count, int want_limit, sfb_mesh_data *o);

SFB__IF void sfb__shading_free(sfb_context *ctx, sfb__shading *sh);
/* shade.c's vertex classes and spherical mean (also read by tests/shade.c): is v a smooth
 * extraordinary vertex; is v's blend weight held (by the variant and the darts option); the
 * weighted spherical mean of count vectors (returns the iterations taken, 0 for the zero result,
 * -1 where the linear average was returned; see shade.c). */
SFB__IF int sfb__shade_extraordinary(const sfb__level *l, int v, int loop);
SFB__IF int sfb__shade_held(const sfb__level *l, int v, int loop, int variant, int darts);
SFB__IF int sfb__shade_spherical_mean(int count, const double *n, const double *w, double out[3]);
/* The shading tables of `prep` refined `level` times; kept (with top, its last level): the vertex
 * refinement's levels and steps, taken over (freed on failure) instead of refining again; NULL:
 * refined here. */
SFB__IF sfb_result sfb__shading_build(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt, int level,
                              const sfb_shading_options *o, sfb__refine_kept *kept, const sfb__level *top, sfb__shading **out);

/* ---- patch tables (patch/) ---- */
SFB__IF void sfb__patch_table_free(sfb_context *ctx, sfb__patch_table *pt);
/* Refuses non-triangles, non-manifold edges (vertices: manifold_vertices), non-finite positions and
 * degenerate triangles for a one-patch-per-triangle scheme named who (patch/table.c). */
SFB__IF sfb_result sfb__tri_mesh_check(sfb_context *ctx, const sfb__level *l, const float *positions, const char *who, int manifold_vertices);
/* One BEZIER_TRI15 patch of its own 15 points (net: 45 doubles per triangle) per triangle of l that
 * is not a hole (patch/table.c; PN triangles, tribezier). */
SFB__IF sfb_result sfb__patch_table_beztri_own(sfb_context *ctx, const sfb__level *l, const double *net, sfb__patch_table *pt);
/* The same with the 4 (depth 1) or 16 (depth 2) child patches of every triangle f: 45 doubles
 * each at net + 45 (4 f + i), child i of the parametric triangle's quadtree (corners 0, 1, 2,
 * the middle 3), or at net + 45 (16 f + 4 i + j), child j of child i (sfb__tribezier_refined_points
 * after one or two Loop steps). net NULL: pt's point_data left for the caller to write, 45 floats
 * per patch, the patches of the triangles that are not holes in their order, each triangle's
 * children in net's order (sfb__tribezier_build writes them there directly). */
SFB__IF sfb_result sfb__patch_table_beztri_children(sfb_context *ctx, const sfb__level *l, const double *net, int depth,
                                                    sfb__patch_table *pt);
/* The families present in a table, as bits 1 << SFB__FAMILY_*. */
static inline unsigned sfb__patch_families(const sfb__patch_table *pt) {
    unsigned m = 0;
    int t;
    for (t = 0; t < SFB__PATCH_TYPE_COUNT; ++t)
        if (pt->counts[t] > 0) m |= 1u << sfb__patch_family(t);
    return m;
}
/* Manifold blending (patch/manifold.c): a corner code packs the corner vertex's local geometry kind,
 * its valence k and the index h of the face in its star (the chart), and for a curve the axes
 * (1: a, 2: b, 0: not in this face) of its sharp edges e1 and e2. */
enum { SFB__MF_PATCH = 0, SFB__MF_POINT = 1, SFB__MF_CURVE = 2 };
#define SFB__MF_CODE(kind, k, h, a1, a2) \
    ((unsigned)(kind) | ((unsigned)(k) << 2) | ((unsigned)(h) << 15) | ((unsigned)(a1) << 28) | ((unsigned)(a2) << 30))
#define SFB__MF_KIND(c) ((int)((c) & 3u))
#define SFB__MF_K(c) ((int)(((c) >> 2) & 8191u))
#define SFB__MF_H(c) ((int)(((c) >> 15) & 8191u))
#define SFB__MF_A1(c) ((int)(((c) >> 28) & 3u))
#define SFB__MF_A2(c) ((int)(((c) >> 30) & 3u))
/* Curved PN triangles (patch/pn.c): one BEZIER_TRI15 patch per triangle of base. */
SFB__IF sfb_result sfb__pn_build(sfb_context *ctx, const sfb__level *base, const float *positions, sfb__patch_table *pt);
/* Quartic triangular Bezier surfaces with sharpness (patch/tribezier.c, seed 004): the 15 points
 * of every triangle of base (patch order, double, 45 per triangle, freed by the caller) and what
 * the G1 solve did; flags SFB__TBZ_SEED_PLANE builds the seed's smooth net at crease vertices (a
 * tangent plane that ignores the crease, for the undulation measurement), SFB__TBZ_NO_REUSE solves every
 * component of the sharp net's constraints even where the smooth net solved the same system (for the test
 * that the reuse changes nothing), SFB__TBZ_PAR_SMALL runs the loops of every component of 1024 unknowns or
 * more on the backend's threads (for the test that the net stays bit for bit the same there; the
 * default is 65536), SFB__TBZ_NO_TEMPLATES solves every component by CGLS (for the test that the
 * templates give the same net), SFB__TBZ_TWO_STEPS makes sfb__tribezier_refined_points take two
 * Loop steps, SFB__TBZ_BOTH_NETS builds the smooth net even where s = 1 at every vertex (for the
 * test that skipping it gives the same net), SFB__TBZ_REJECT_TEMPLATES fails every template's
 * check (for the test that what fails goes to CGLS from the net as it was), SFB__TBZ_NO_STRAIGHT
 * solves the smooth net in one pass, its crease curves bent as the least-norm solve leaves them
 * (no second pass: tbz_crease_points; for the undulation measurement). Progress (stage
 * "tribezier") runs over [0, 1], or [0, 0.5] with SFB__TBZ_PROGRESS_LOW and [0.5, 1] with
 * SFB__TBZ_PROGRESS_HIGH (sfb__tribezier_build: the mesh's own net, then the one after a Loop
 * step); a cancel returns SFB_CANCELLED. */
enum { SFB__TBZ_SEED_PLANE = 1, SFB__TBZ_NO_REUSE = 2, SFB__TBZ_PAR_SMALL = 4, SFB__TBZ_PROGRESS_LOW = 8, SFB__TBZ_PROGRESS_HIGH = 16,
       SFB__TBZ_NO_TEMPLATES = 32, SFB__TBZ_TWO_STEPS = 64, SFB__TBZ_BOTH_NETS = 128, SFB__TBZ_REJECT_TEMPLATES = 256,
       SFB__TBZ_NO_STRAIGHT = 512 };
typedef struct sfb__tbz_stats {
    long iterations;   /* CGLS iterations, all coordinates and nets */
    long unknowns;     /* points moved by the G1 solve, per coordinate and net */
    long constraints;  /* G1 rows */
    double residual;   /* largest G1 row left, relative to the net's largest coordinate */
    double ours_residual; /* the same within the constraint components around extraordinary crease vertices with
                             our tangent plane */
    int fallbacks;     /* smooth nets rebuilt with the seed's tangent plane at some vertices (ours unsolvable there;
                          1: at those, 2: then at every vertex) */
    int seed_vertices; /* extraordinary crease vertices given the seed's plane in the smooth net (fallbacks) */
    long crease_weighted; /* unknowns on the smooth net's crease curves, whose moves the solve weighs (tbz_crease_points;
                             SFB__TBZ_NO_STRAIGHT: none) */
    int straight;      /* smooth nets solved again with the crease weighted (SFB__TBZ_NO_STRAIGHT: none) */
    int straight_kept_first; /* of those, the second solve left a row unmet: the first net kept */
    int straight_across;  /* components where it holds the crease's place across it too (tbz_take_second) */
    int straight_unfair;  /* components where the second pass bent the net more than the first (tbz_take_second): the first's */
    int straight_skipped; /* components around our vertices too large for the second pass's dense solve: the first pass's */
    int reused;        /* sharp-net constraint components that were the same system as a smooth-net one and took its
                          solution (SFB__TBZ_NO_REUSE: none) */
    int templates;     /* templates made (tbz_templates: one dense solve per shape of neighbourhood met twice or more) */
    int templated;     /* components solved with a template (SFB__TBZ_NO_TEMPLATES: none, every one by CGLS) */
    int direct;        /* templates made for one component alone (a shape met once; TBZ_DIRECT_ROWS rows at most) */
    int sharp_only;    /* 1: s = 1 at every vertex, the sharp net alone built (SFB__TBZ_BOTH_NETS: never) */
    int large;         /* components solved with each iteration's loops on the backend's threads (65536 unknowns
                          or more, 1024 with SFB__TBZ_PAR_SMALL) */
} sfb__tbz_stats;
SFB__IF sfb_result sfb__tribezier_points(sfb_context *ctx, const sfb__level *base, const float *positions,
                                         const sfb_tribezier_options *opt, unsigned flags, double **out, sfb__tbz_stats *stats);
/* The same on the mesh after one Loop step, or two with SFB__TBZ_TWO_STEPS (*rl, free with
 * sfb__level_free): 45 doubles per child face 4 f + i (child i of triangle f in its parametric
 * triangle's quadtree frame), or per grandchild face 16 f + 4 i + j (child j of child i). */
SFB__IF sfb_result sfb__tribezier_refined_points(sfb_context *ctx, const sfb__level *base, const float *positions,
                                                 const sfb_tribezier_options *opt, unsigned flags, sfb__level *rl, double **out,
                                                 sfb__tbz_stats *stats);
/* The same as one BEZIER_TRI15 patch per triangle, or sixteen (two Loop steps) where the mesh's
 * own G1 constraints have no exact solution. */
SFB__IF sfb_result sfb__tribezier_build(sfb_context *ctx, const sfb__level *base, const float *positions,
                                        const sfb_tribezier_options *opt, sfb__patch_table *pt);
/* The slider (tribezier.slider; sfb_surface_set_sharpness, sfb_surface_set_feature_sharpness):
 * per patch 45 + 45 floats in pt->blend, and how each patch point's s follows from the s of the
 * base mesh's tagged creases and corners. L is the level the nets were built on: the base mesh,
 * its non-manifold vertices split, or after one or two Loop steps. */
#define SFB__TBZ_BLEND 90
typedef struct sfb__tbz_features {
    int nv;              /* L's vertices */
    int *src;            /* per L vertex: the L vertex whose features give its s (the nearest, breadth first), -1: none */
    int *eoff, *eid;     /* per L vertex: its tagged interior edges in ring order, as base edges */
    int *corner;         /* per L vertex: the base vertex whose corner tag counts there, -1: none */
    int *pv;             /* per patch: its triangle's three L vertices, in order */
    int nbe, nbv;        /* the base mesh's edges and vertices */
    float *es, *cs;      /* per base edge / vertex: the crease's / corner's tag now, clamped to [0, 1] (0: none) */
} sfb__tbz_features;
SFB__IF void sfb__tbz_features_free(sfb_context *ctx, sfb__tbz_features *F);
/* The patch points for opt (its override s, or the features' s) into point_data (3 floats per
 * patch point). Returns 0 when out of memory. */
SFB__IF int sfb__tribezier_blend(sfb_context *ctx, const sfb__patch_table *pt, const sfb_tribezier_options *opt, float *point_data);
SFB__IF sfb_result sfb__manifold_build(sfb_context *ctx, const sfb__level *base, int weights, const float *positions, sfb__patch_table *pt);
SFB__IF void sfb__mf_eval(const float *pts, const int *cv, const unsigned *codes, int kind, double c, double d, double S[3], double Sc[3],
                  double Sd[3]);
SFB__IF void sfb__mf_eval_patch(const sfb__patch_table *pt, const float *pts, int patch, double s, double t, int want2, double res[6][3],
                        double nrm[3]);
SFB__IF sfb_result sfb__mf_pinv(sfb_context *ctx, int k, double **out);
/* The blend weight eta of SFB_MANIFOLD_WEIGHTS_* `kind` at t, and its derivative in *dt. */
SFB__IF double sfb__mf_eta(int kind, double t, double *dt);
SFB__IF sfb_result sfb__patches_build(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int limit,
                              const float *positions, sfb__patch_table *pt);
/* Patch index (or -1: a hole) and local (s,t) of a valid location; *scale = 2^depth, negative
 * after an odd number of middle triangle children (patch/table.c). */
SFB__IF int sfb__patch_locate(const sfb__patch_table *pt, int ptex, double u, double v, double *s, double *t, double *scale);

/* ---- reading records (patch/table.c) and the record kinds (patch/quad.c, patch/tri.c) ---- */
/* A record type's ref evaluation. res = P, Ps, Pt, Pss, Pst, Ptt in the record's (s,t) (before
 * the sub-patch scale). A polynomial kind gives `poly` (the normal's direction is Ps x Pt); a
 * Stam kind gives `eval`, which also returns the normalised tangent frame dir (the normal's
 * direction is dir[0] x dir[1], finite down to the extraordinary vertex). An end cap's normal
 * blends its cap_corners corners' limit normals (sfb__endcap_normal). */
typedef void (*sfb__patch_eval_fn)(const sfb__patch_table *pt, const float *pts, int patch, const int *cv, double s, double t,
                                   double res[6][3], double dir[2][3]);
typedef struct sfb__patch_kind {
    void (*poly)(const float *pts, const int *cv, double s, double t, double res[6][3]);
    sfb__patch_eval_fn eval;
    int cap_corners;
} sfb__patch_kind;
/* The ref evaluator of a (non-MANIFOLD4) record type. */
SFB__IF sfb__patch_kind sfb__patch_kind_of(int type);
SFB__IF void sfb__kind_stam(const sfb__patch_table *pt, const float *pts, int patch, const int *cv, double s, double t, double res[6][3],
                    double dir[2][3]);
SFB__IF void sfb__kind_stam_loop(const sfb__patch_table *pt, const float *pts, int patch, const int *cv, double s, double t, double res[6][3],
                         double dir[2][3]);
/* The record evaluations themselves (res as above; the Stam kinds' nres: the first derivatives
 * divided by their scale, a finite tangent frame down to the extraordinary vertex). */
SFB__IF void sfb__bspline_basis(double t, double *b, double *d, double *dd);   /* uniform cubic B-spline: value, d, d2 */
SFB__IF void sfb__bez15_basis(double s, double t, int nw, double B[6][15]);   /* quartic Bernstein on a triangle (nw 3 or 6) */
SFB__IF double sfb__ipow(double x, int m);                                    /* x^m, m >= 0, by repeated squaring */
SFB__IF void sfb__eval_bspline16(const float *pts, const int *cv, double s, double t, double res[6][3]);
SFB__IF void sfb__eval_endcap(const float *pts, const int *cv, double s, double t, double res[6][3]);
/* The Stam kinds take nw: 3 for P and its first derivatives (res[3..5] = 0), 6 for all. */
SFB__IF void sfb__eval_stam(const sfb__eigen_cc *e, const float *pts, const int *cv, int corner, double s, double t, int nw,
                    double res[6][3], double nres[2][3]);
SFB__IF void sfb__eval_beztri(const float *pts, const int *cv, double s, double t, double res[6][3]);
SFB__IF void sfb__eval_endcap_tri(const float *pts, const int *cv, double s, double t, double res[6][3]);
SFB__IF void sfb__eval_stam_loop(const sfb__eigen_loop *e, const float *pts, const int *cv, int corner, double s, double t, int nw,
                         double res[6][3], double nres[2][3]);
/* Shared by the kinds (patch/table.c): c = a x b; an end cap's normal (nc = 3 or 4 corners); the
 * end of both Stam kernels (the EV frame's derivatives mapped to (s,t) through J, scaled). */
SFB__IF void sfb__cross3(const double *a, const double *b, double *c);
SFB__IF void sfb__endcap_normal(const float *pts, const int *cv, int nc, double s, double t, double nrm[3]);
SFB__IF void sfb__stam_finish(double J[2][2], double sc1, double sc2, double sr[6][3], double nr[2][3], double res[6][3], double nres[2][3]);

/* ---- building records (patch/build.c), for the scheme builders ---- */
/* Classes of a face's corner for the regular records. */
enum { SFB__CORNER_R1 = 1, SFB__CORNER_R2_D1 = 2, SFB__CORNER_R2_D2 = 3, SFB__CORNER_R3 = 4, SFB__CORNER_EV = 5,
       SFB__CORNER_IRREGULAR = 0 };
/* The builder: the table under construction and its points (xyz floats, each computed in double
 * from the working level's double positions). */
typedef struct sfb__pbuild {
    sfb_context *ctx;
    sfb__patch_table *pt;
    int cap_patch, cap_cv, cap_nodes;
    float *pts;              /* the points, 3 per point */
    int npts, cap_pts;
    sfb__mask m;
    sfb__mask cap[3];        /* an end cap's limit masks (position, two tangents), kept between caps */
    int *vrow;               /* point row of each vertex of the working level, -1 if none yet */
} sfb__pbuild;
/* A working level of feature-adaptive isolation: its topology, the positions of its vertices
 * (xyz doubles), and its candidate faces. */
typedef struct sfb__wlevel {
    sfb__level l;
    double *pos;
    int *fptex;          /* param face of a candidate face, -1 otherwise */
    unsigned *fparam;    /* depth, i, j and rotation (in the corner bits) of candidates */
    unsigned char *vcomp, *ecomp;
    int owns_level;
} sfb__wlevel;
/* A grid cell's mask: up to 4 (vertex, weight) terms. */
typedef struct sfb__cell { int n, real; int v[4]; double w[4]; } sfb__cell;
SFB__IF int sfb__is_inf(float s);                                          /* s is SFB_SHARPNESS_INFINITE */
SFB__IF int sfb__face_n(const sfb__level *l, int f);                       /* corners of face f */
SFB__IF int sfb__fan_pos(const sfb__level *l, int v, int g, int slot);     /* g's position around v, or -1 */
SFB__IF int sfb__face_semisharp(const sfb__level *l, int g);               /* something at g's corners still decays */
/* A point = mask m over working-level vertices applied to their positions wpos (a single vertex
 * with weight 1 is shared); its index, or -1 on allocation failure. */
SFB__IF int sfb__pb_point(sfb__pbuild *b, const double *wpos, const sfb__mask *m);
/* A new record of `type` with ncv points; its index, or -1 on allocation failure. */
SFB__IF int sfb__pb_patch(sfb__pbuild *b, int type, unsigned param, int valence, int ncv);
/* Inserts record `patch` (-1: a hole) at (ptex, depth, i, j of param) in the tree; 0 on failure. */
SFB__IF int sfb__pb_insert(sfb__pbuild *b, int ptex, unsigned param, int patch);
SFB__IF void sfb__wlevel_free(sfb_context *ctx, sfb__wlevel *w);
/* The end cap of face g (n = 3 or 4 corners, frame corner 0 at slot rot). */
SFB__IF sfb_result sfb__pb_endcap(sfb__pbuild *b, sfb__wlevel *w, int g, int rot, int n, unsigned param);
/* A Stam-kind record of K eigen-coefficient points over the vertices C (freed). */
SFB__IF sfb_result sfb__pb_eigen_patch(sfb__pbuild *b, sfb__wlevel *w, int type, int ptex, unsigned param, int N, int K, const double *vinv,
                               int *C);
/* Classifies candidate g of the working level: adds its record, or sets *refine. */
SFB__IF sfb_result sfb__pb_face_quad(sfb__pbuild *b, sfb__wlevel *w, int g, int level, int limit, int *refine);
SFB__IF sfb_result sfb__pb_face_tri(sfb__pbuild *b, sfb__wlevel *w, int g, int level, int limit, int *refine);

/* ---- an AABB tree over triangles, robust triangle-triangle intersection (aabb.c) ----
 * Reusable geometry for the rolling-ball operator (seed 002) and its checks. Positions are xyz
 * doubles; triangles are index triples into them. A built tree is read-only: many threads may
 * query it at once. */
typedef struct sfb__aabb_node {
    double lo[3], hi[3];
    int left, right;            /* inner node: children; leaf: left = -1, items [first, first+count) */
    int first, count;
} sfb__aabb_node;
typedef struct sfb__aabb {
    int node_count, item_count;
    sfb__aabb_node *nodes;      /* node 0 is the root (node_count 0: an empty tree) */
    int *items;                 /* triangle ids (as passed in `ids`, or 0..count-1) in leaf order */
} sfb__aabb;
/* A tree over `count` triangles tri[3*i..3*i+2] of pos (ids: NULL, or the id reported for each).
 * Triangles with a non-finite vertex are left out. */
SFB__IF sfb_result sfb__aabb_build(sfb_context *ctx, const double *pos, const int *tri, const int *ids, int count, sfb__aabb *out);
SFB__IF void sfb__aabb_free(sfb_context *ctx, sfb__aabb *t);
/* Calls fn(id_a, id_b, user) for every pair of triangles whose boxes, grown by eps, overlap: one of
 * a, one of b; when b == a, every unordered pair of different ids once. fn returns non-zero to stop;
 * the function returns 1 when stopped, else 0. */
SFB__IF int sfb__aabb_pairs(const sfb__aabb *a, const sfb__aabb *b, double eps, int (*fn)(int, int, void *), void *user);
/* The point of the tree's triangles nearest to p: returns the triangle id (-1 for an empty tree),
 * writes the point, its squared distance and its barycentric coordinates on that triangle
 * (any of the out pointers may be NULL). tri is the same array the tree was built on, indexed by
 * id when ids were NULL, else tri_of_id[id] gives the triangle's row (NULL: id is the row). */
SFB__IF int sfb__aabb_nearest(const sfb__aabb *t, const double *pos, const int *tri, const int *tri_of_id,
                              const double p[3], double out_point[3], double *out_dist2, double out_bary[3]);
/* Closest point to p on triangle (a, b, c), with barycentric coordinates (any pointer may be NULL
 * but q); degenerate triangles give the closest point on their longest edge. */
SFB__IF void sfb__closest_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3],
                                      double q[3], double bary[3]);
/* Intersection of two triangles. Returns 0 when they do not meet, 1 when they meet in a segment
 * s0-s1 (a single point gives s0 == s1), 2 when they are coplanar and overlap (no segment written).
 * Robust: exact zeros from orientation determinants within a tolerance relative to the triangles'
 * size are treated as on the plane, shared vertices and edges give the shared point or edge, and
 * degenerate (zero-area) triangles never meet anything. src0/src1 (may be NULL) say where each
 * endpoint lies: 0..2 edge k (vertex k to k+1) of triangle a, 3..5 edge k-3 of triangle b. */
SFB__IF int sfb__tri_tri_segment(const double a0[3], const double a1[3], const double a2[3],
                                 const double b0[3], const double b1[3], const double b2[3],
                                 double s0[3], double s1[3], int *src0, int *src1);
/* Pairs of triangles of one mesh that intersect other than in what they share (a common vertex
 * or edge, compared by index); *pairs gets the count, first[2] (may be NULL) the first pair found
 * (-1 -1 when none). Coplanar overlaps count, except between triangles that share an edge and lie
 * on opposite sides of it. */
SFB__IF sfb_result sfb__trimesh_self_intersections(sfb_context *ctx, const double *pos, const int *tri, int count,
                                                   long *pairs, int first[2]);

/* ---- sparse symmetric systems (sparse.c) ----
 * Compressed rows, each row's columns ascending, duplicates summed; for the conformal map of the
 * rolling-ball operator and whatever else needs a Laplacian solve. */
typedef struct sfb__sparse {
    int n;                      /* rows = columns */
    int *row_off;               /* n + 1 */
    int *col;
    double *val;
} sfb__sparse;
/* A = sum of the triplets (row[k], col[k], val[k]); indices checked against n (SFB_INVALID_ARGS). */
SFB__IF sfb_result sfb__sparse_from_triplets(sfb_context *ctx, int n, int count, const int *row, const int *col,
                                             const double *val, sfb__sparse *out);
SFB__IF void sfb__sparse_free(sfb_context *ctx, sfb__sparse *m);
/* y = A x */
SFB__IF void sfb__sparse_mul(const sfb__sparse *A, const double *x, double *y);
/* Solves A x = b for symmetric positive definite A by conjugate gradients with a Jacobi
 * (diagonal) preconditioner, starting from x's contents, until |r| <= tol |b| or max_iter steps.
 * *iters and *residual (|r|/|b|; may be NULL) say how it went. SFB_INVALID_VALUE (with the error
 * set) when it did not converge, a diagonal entry is not positive or a non-finite value appears;
 * x then holds the last iterate. */
SFB__IF sfb_result sfb__sparse_cg(sfb_context *ctx, const sfb__sparse *A, const double *b, double *x, double tol,
                                  int max_iter, int *iters, double *residual);

/* ---- triangle-mesh measures (trimesh.c) ---- */
/* Angle-weighted vertex normals (unit; zero where no face contributes) over faces tri[3f..]. */
SFB__IF void sfb__trimesh_vertex_normals(int nv, const double *pos, int nf, const int *tri, double *normals);
/* Mean curvature per vertex from the cotangent Laplacian, H = |Delta x| / 2 with mixed Voronoi
 * areas (Meyer et al.), signed positive where the surface bends away from its normal (a sphere
 * with outward normals: +1/R); boundary vertices get 0. */
SFB__IF sfb_result sfb__trimesh_mean_curvature(sfb_context *ctx, int nv, const double *pos, int nf, const int *tri, double *H);
