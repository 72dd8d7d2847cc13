/* surfblend.h -- subdivision surfaces with sharp and semi-sharp creases, evaluated on
 * several backends. Single-header library: GENERATED from src/ by `make amalgamate`; edit
 * src/ instead.
 *
 * In exactly one C or C++ file:
 *     #define SURFBLEND_IMPLEMENTATION
 *     #include "surfblend.h"
 * Optional backends (code in backends/ beside this file): also define SURFBLEND_SIMD,
 * SURFBLEND_GL, SURFBLEND_OSMESA or SURFBLEND_ALL_BACKENDS there; link -lm -lpthread -ldl.
 */
#ifndef SURFBLEND_H
#define SURFBLEND_H
#line 1 "src/sfb_api.h"
/* surfblend public API.
 *
 * Life cycle:  sfb_context -> sfb_mesh -> sfb_surface (compiled tables) -> refine/eval.
 * Every fallible call returns sfb_result (0 = success, negative = error); details of the
 * last failure are in sfb_last_error(ctx). Nothing is global: all state lives in objects.
 *
 * Thread safety: a context is used by one thread at a time. A built sfb_surface is
 * immutable; on the ref and simd backends sfb_surface_eval_stencils may be called from
 * several threads at once on the same surface as long as each call passes its own output
 * buffers. The gl and osmesa backends use one GL context: call them from one thread (with
 * gl_use_current_context, the thread where the host's context is current).
 *
 * Backends: ref is always compiled. simd, gl and osmesa are compiled into the implementation
 * when SURFBLEND_SIMD, SURFBLEND_GL, SURFBLEND_OSMESA (or SURFBLEND_ALL_BACKENDS) are defined
 * next to SURFBLEND_IMPLEMENTATION; their code is in backends/ beside this header. GL, EGL
 * and OSMesa are loaded at run time: link with -lm -lpthread -ldl only.
 */
#include <stddef.h>

#ifndef SFB_API
#  if defined(SURFBLEND_STATIC)
#    define SFB_API static
#  else
#    define SFB_API extern
#  endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define SFB_VERSION_MAJOR 0
#define SFB_VERSION_MINOR 1
#define SFB_VERSION_PATCH 0

/* Hard limits on untrusted input; exceeding one returns SFB_LIMIT_EXCEEDED before any
 * allocation sized by the offending value. */
#define SFB_MAX_LEVEL    10        /* uniform refinement levels */
#define SFB_MAX_VALENCE  4096      /* edges (or faces) around one vertex */
#define SFB_MAX_FACE_SIZE 1024     /* vertices of one face */
#define SFB_MAX_ELEMENTS 200000000 /* vertices, faces, face-vertices in one mesh */
#define SFB_DEFAULT_MEMORY_BUDGET ((size_t)4 << 30) /* bytes, when the config says 0 */

/* Sharpness at or above this value is infinitely sharp (OpenSubdiv's convention). */
#define SFB_SHARPNESS_INFINITE 10.0f

/* ---- results: one X-macro list makes the enum and the strings ---- */
#define SFB_RESULT_LIST(X)                                                              \
    X(SFB_SUCCESS, 0, "success")                                                       \
    X(SFB_INVALID_ARGS, -1, "invalid arguments")                                       \
    X(SFB_OUT_OF_MEMORY, -2, "out of memory")                                          \
    X(SFB_PARSE_ERROR, -3, "parse error")                                              \
    X(SFB_INVALID_TOPOLOGY, -4, "invalid topology")                                    \
    X(SFB_LIMIT_EXCEEDED, -5, "limit exceeded")                                        \
    X(SFB_UNSUPPORTED, -6, "unsupported")                                              \
    X(SFB_NO_BACKEND, -7, "no backend available")                                      \
    X(SFB_BACKEND_UNAVAILABLE, -8, "backend unavailable")                              \
    X(SFB_BACKEND_ERROR, -9, "backend error")                                          \
    X(SFB_CANCELLED, -10, "cancelled")                                                 \
    X(SFB_IO_ERROR, -11, "i/o error")                                                  \
    X(SFB_INVALID_VALUE, -12, "invalid value")

typedef enum sfb_result {
#define SFB__RESULT_ENUM(name, value, text) name = value,
    SFB_RESULT_LIST(SFB__RESULT_ENUM)
#undef SFB__RESULT_ENUM
    SFB_RESULT_MIN_ = -12
} sfb_result;

/* Static string for a result code ("unknown result" for values outside the list). */
SFB_API const char *sfb_result_string(sfb_result r);

/* ---- context ---- */
typedef struct sfb_allocator {
    void *(*alloc)(size_t size, void *user);
    void *(*realloc)(void *ptr, size_t size, void *user);
    void (*free)(void *ptr, void *user);
    void *user;
} sfb_allocator;

enum { SFB_LOG_ERROR = 0, SFB_LOG_WARN = 1, SFB_LOG_INFO = 2, SFB_LOG_DEBUG = 3 };
typedef struct sfb_logger {
    void (*func)(int level, const char *msg, void *user);
    void *user;
} sfb_logger;

/* Called during long operations with done in [0,1]; return non-zero to cancel
 * (the operation then returns SFB_CANCELLED and frees what it made). */
typedef struct sfb_progress {
    int (*func)(float done, const char *stage, void *user);
    void *user;
} sfb_progress;

typedef enum sfb_backend_kind {
    SFB_BACKEND_DEFAULT = 0, SFB_BACKEND_REF, SFB_BACKEND_SIMD, SFB_BACKEND_GL, SFB_BACKEND_OSMESA,
    SFB_BACKEND_KIND_COUNT_
} sfb_backend_kind;

typedef struct sfb_context_config {
    sfb_allocator allocator;           /* all NULL: libc */
    sfb_logger logger;                 /* NULL func: silent */
    sfb_progress progress;             /* NULL func: no reports, no cancel */
    const sfb_backend_kind *backends;  /* ordered preference; NULL: default order */
    int backend_count;
    int threads;                       /* 0: one per core, 1: no threads (simd; gl, osmesa: the CPU work between kernels); negative: invalid */
    size_t memory_budget;              /* bytes; 0: SFB_DEFAULT_MEMORY_BUDGET */
    int gl_use_current_context;        /* gl backend: run on the caller's current context */
    int ignore_environment;            /* 1: do not read SURFBLEND_BACKEND (SURFBLEND_SIMD_ISA,
                                          which pins the simd kernels for tests, is still read) */
} sfb_context_config;

typedef struct sfb_context sfb_context;

SFB_API sfb_context_config sfb_context_config_init(void);
SFB_API sfb_result sfb_context_create(const sfb_context_config *config, sfb_context **out);
SFB_API void sfb_context_destroy(sfb_context *ctx);

typedef enum sfb_element_kind {
    SFB_ELEMENT_NONE = 0, SFB_ELEMENT_VERTEX, SFB_ELEMENT_EDGE, SFB_ELEMENT_FACE,
    SFB_ELEMENT_LINE, SFB_ELEMENT_UV
} sfb_element_kind;

typedef struct sfb_error_info {
    sfb_result result;
    sfb_element_kind element; /* what `index` counts */
    long index;               /* 0-based element index, or 1-based line number for SFB_ELEMENT_LINE; -1 if none */
    const char *message;      /* full message, includes the element */
} sfb_error_info;

/* Message of the last failure on this context ("" if none). Valid until the next call. A call
 * that succeeds leaves it as it was, also when it recovered from an internal failure (an eigen
 * basis that could not be built, a fillet curve skipped by skip_failed, a map's solve that fell
 * back to the next): those reasons go to the context's logger. */
SFB_API const char *sfb_last_error(const sfb_context *ctx);
SFB_API sfb_error_info sfb_last_error_info(const sfb_context *ctx);
SFB_API void sfb_clear_error(sfb_context *ctx);

SFB_API const char *sfb_backend_kind_name(sfb_backend_kind kind);
/* Parses "ref", "simd", "gl", "osmesa" (case-insensitive). Returns SFB_BACKEND_DEFAULT when unknown. */
SFB_API sfb_backend_kind sfb_backend_kind_parse(const char *name);
SFB_API const char *sfb_context_backend_name(const sfb_context *ctx);
/* One line per backend attempt: "name: selected (what runs)" or "name: unavailable (reason)". */
SFB_API sfb_result sfb_context_backend_report(const sfb_context *ctx, char *buf, size_t size);
/* What the selected backend runs on, one line: ISA and threads for simd, GL version and
 * renderer for gl/osmesa ("" for ref). */
SFB_API sfb_result sfb_context_backend_info(const sfb_context *ctx, char *buf, size_t size);
/* Initialises `kind` alone on a scratch context (config: NULL for defaults; its backend list
 * and environment are ignored). SFB_SUCCESS: available, `info` says what runs. Otherwise
 * (SFB_BACKEND_UNAVAILABLE, ...) `info` says why not. */
SFB_API sfb_result sfb_backend_probe(sfb_backend_kind kind, const sfb_context_config *config, char *info, size_t size);

/* ---- mesh ---- */
typedef enum sfb_boundary {
    SFB_BOUNDARY_EDGE_ONLY = 0,      /* default (OpenSubdiv's shape loader default) */
    SFB_BOUNDARY_EDGE_AND_CORNER = 1,/* also valence-2 boundary vertices are corners */
    SFB_BOUNDARY_NONE = 2            /* faces at the boundary are not part of the surface */
} sfb_boundary;
typedef enum sfb_crease_method { SFB_CREASE_UNIFORM = 0, SFB_CREASE_CHAIKIN = 1 } sfb_crease_method;
typedef enum sfb_triangle_rule { SFB_TRI_CATMARK = 0, SFB_TRI_SMOOTH = 1 } sfb_triangle_rule;
typedef enum sfb_uv_interp {
    SFB_UV_SMOOTH_CORNERS = 0, /* smooth inside UV islands, seams act as boundaries, UV corners pinned */
    SFB_UV_LINEAR = 1          /* bilinear: UVs follow each face linearly */
} sfb_uv_interp;

typedef struct sfb_mesh_desc {
    int vertex_count; const float *positions;             /* xyz per vertex */
    int face_count; const int *face_sizes; const int *face_vertices;
    int crease_count; const int *crease_vertices;           /* pairs (a,b) naming an existing edge */
    const float *crease_sharpness;                          /* per pair, >= 0; >= 10 infinite */
    int corner_count; const int *corner_vertices; const float *corner_sharpness;
    int hole_count; const int *holes;                       /* face indices */
    int uv_count; const float *uvs; const int *face_uvs;    /* optional face-varying UVs: uv per face-vertex */
    const float *face_edge_sharpness; /* optional, per face-vertex: sharpness of the edge from face vertex i
                                         to vertex i+1 (seed 001's fs/as lines); the highest value wins */
    int boundary, crease_method, triangle_rule, uv_interp;  /* enums above, 0 = defaults */
} sfb_mesh_desc;

typedef struct sfb_mesh sfb_mesh;

/* Validates and copies the arrays, builds topology. Errors name the offending element. */
SFB_API sfb_result sfb_mesh_create(sfb_context *ctx, const sfb_mesh_desc *desc, sfb_mesh **out);
/* Parses OBJ text from memory (need not be NUL-terminated). Errors name the line. */
SFB_API sfb_result sfb_mesh_read_obj(sfb_context *ctx, const char *text, size_t size, sfb_mesh **out);
SFB_API void sfb_mesh_destroy(sfb_mesh *mesh);
/* Pointers into the mesh's own arrays, valid while the mesh lives. Creases are per edge
 * (fs/as input is folded into them). */
SFB_API void sfb_mesh_get_desc(const sfb_mesh *mesh, sfb_mesh_desc *out);

/* A copy of `mesh` whose edges with a dihedral angle over `degrees` (0..180) are infinitely sharp
 * creases: what a faceted (CAD-like) mesh with no crease tags needs for its hard edges to stay
 * hard. The angle of an edge is the angle between the (Newell) normals of its two faces, so 0
 * for a flat edge; edges with one face (boundaries), more than two (non-manifold), a hole face
 * or a degenerate face keep their sharpness, as do edges that are sharper already. Everything
 * else (UVs, corners, holes, rules) is copied. *added (may be NULL) gets the number of edges
 * made sharp. */
SFB_API sfb_result sfb_mesh_crease_by_angle(sfb_context *ctx, const sfb_mesh *mesh, float degrees, sfb_mesh **out, int *added);

typedef int (*sfb_write_fn)(const void *data, size_t size, void *user); /* returns non-zero on failure */
/* Writes OBJ (v, vt, f, t crease/corner/hole/interpolateboundary/creasemethod/smoothtriangles). */
SFB_API sfb_result sfb_write_obj(const sfb_mesh_desc *desc, sfb_write_fn write, void *user);
SFB_API sfb_result sfb_mesh_write_obj(const sfb_mesh *mesh, sfb_write_fn write, void *user);

typedef struct sfb_mesh_info {
    int vertex_count, face_count, edge_count, face_vertex_count, uv_count;
    int triangles, quads, ngons, max_face_size;
    int boundary_edges, boundary_vertices, nonmanifold_edges, nonmanifold_vertices, bare_vertices;
    int sharp_edges, semisharp_edges, infsharp_edges, corners, holes;
    int darts, crease_vertices, corner_vertices;     /* by vertex rule */
    int extraordinary_catmark, extraordinary_loop;   /* interior valence != 4 / != 6, boundary != 2 / != 3 */
    int max_valence;
    float bbox_min[3], bbox_max[3];
} sfb_mesh_info;
SFB_API void sfb_mesh_get_info(const sfb_mesh *mesh, sfb_mesh_info *out);
/* counts[v] = number of vertices with v incident edges, for v < max_valence; returns the number of
 * vertices whose valence did not fit. */
SFB_API int sfb_mesh_valence_histogram(const sfb_mesh *mesh, int *counts, int max_valence);

/* ---- surfaces ---- */
typedef enum sfb_scheme {
    SFB_SCHEME_CATMARK = 0, SFB_SCHEME_LOOP, SFB_SCHEME_BILINEAR,
    SFB_SCHEME_MANIFOLD_BLEND, SFB_SCHEME_TRIBEZIER,
    SFB_SCHEME_PN  /* curved PN triangles (evaluated only: SFB_REFINE_PATCHES), on triangle meshes */
} sfb_scheme;
SFB_API const char *sfb_scheme_name(sfb_scheme s);
/* The scheme named `name` ("catmark" or "catmull-clark", "loop", "bilinear", "manifold",
 * "tribezier", "pn": sfb_scheme_name's names) into *out; returns 1, or 0 for an unknown name. */
SFB_API int sfb_scheme_parse(const char *name, sfb_scheme *out);
/* What a scheme supports (the SFB_SCHEME_CAN_* bits), so that callers ask a capability instead of
 * comparing schemes; 0 for a value that is not an sfb_scheme. */
enum {
    SFB_SCHEME_CAN_REFINE = 1u << 0,   /* uniform refinement by its rules (sfb_surface_refine) */
    SFB_SCHEME_CAN_SHADE = 1u << 1,    /* subdivision shading (SFB_REFINE_SHADING, sfb_surface_shade) */
    SFB_SCHEME_TRIANGLES = 1u << 2,    /* faces must be triangles; its parametric faces are triangles */
    SFB_SCHEME_CAN_EVAL = 1u << 4      /* a patch table (SFB_REFINE_PATCHES: sfb_surface_eval, tessellate) */
};
SFB_API unsigned sfb_scheme_caps(sfb_scheme s);

enum {
    SFB_REFINE_LIMIT = 1u << 0,  /* also build limit position + limit tangent tables */
    SFB_REFINE_UVS = 1u << 1,    /* also build the face-varying UV table (when the mesh has UVs) */
    SFB_REFINE_PATCHES = 1u << 2, /* also build the patch table: sfb_surface_eval, sfb_surface_tessellate */
    SFB_REFINE_SHADING = 1u << 3  /* also build the subdivision-shading tables: sfb_surface_shade */
};

/* Subdivision shading (seed 001), compiled by SFB_REFINE_SHADING; zero = defaults. */
typedef enum sfb_shade_variant {
    SFB_SHADE_VARIANT_B = 0, /* default: sharp vertices (>= 2 sharp edges) get blend weight 0 */
    SFB_SHADE_VARIANT_A = 1  /* sharp vertices are treated as smooth ones */
} sfb_shade_variant;
typedef enum sfb_shade_darts {
    SFB_SHADE_DARTS_SMOOTH = 0, /* default: a dart is a smooth vertex for the blend weights */
    SFB_SHADE_DARTS_SHARP = 1   /* a regular dart is a sharp vertex (weight 0 in variant B) */
} sfb_shade_darts;
typedef enum sfb_shade_averaging {
    SFB_SHADE_AVERAGE_LINEAR = 0,      /* default: the scheme's stencils on the normals, normalised once at the end
                                          (one composed table, run on the backend) */
    SFB_SHADE_AVERAGE_RENORMALIZED = 1,/* the stencils one level at a time, each level's normals normalised */
    SFB_SHADE_AVERAGE_SPHERICAL = 2    /* one level at a time, each new normal the weighted spherical mean (the
                                          unit vector minimising the weighted sum of squared angles) */
} sfb_shade_averaging;
#define SFB_SHADE_LEVEL_CONTROL (-1) /* normals_level / weights_level: start on the control mesh */
typedef struct sfb_shading_options {
    int variant;        /* sfb_shade_variant */
    int darts;          /* sfb_shade_darts */
    int normals_level;  /* level where N_S starts (face-normal averages); 0: default 1; SFB_SHADE_LEVEL_CONTROL: 0 */
    int weights_level;  /* level where the blend weights are seeded; 0: default 1; SFB_SHADE_LEVEL_CONTROL: 0 */
    int averaging;      /* sfb_shade_averaging: how N_S averages normals from one level to the next */
} sfb_shading_options;

/* Manifold-based blending (seed 000), SFB_SCHEME_MANIFOLD_BLEND; zero = defaults. */
typedef enum sfb_manifold_weights {
    SFB_MANIFOLD_WEIGHTS_HERMITE = 0, /* default (the seed): eta(t) = 2t^3 - 3t^2 + 1, a C1 surface */
    SFB_MANIFOLD_WEIGHTS_CINF = 1     /* Ying-Zorin's kind: eta flat to all orders at 0 and 1 */
} sfb_manifold_weights;
typedef struct sfb_manifold_options {
    int weights;        /* sfb_manifold_weights */
} sfb_manifold_options;

/* Quartic triangular Bezier surfaces (seed 004), SFB_SCHEME_TRIBEZIER; zero = defaults: every
 * crease's s from its sharpness tag clamped to [0, 1] (infinite: 1), every corner's from its
 * corner tag. s = 0 is the smooth (G1) spline surface, s = 1 the crease, between them the point-wise
 * blend. */
typedef struct sfb_tribezier_options {
    int sharpness_set;  /* nonzero: `sharpness` replaces every tagged crease's and corner's s */
    float sharpness;    /* in [0, 1] */
} sfb_tribezier_options;

typedef struct sfb_surface_config {
    sfb_scheme scheme;
    int refine_level;   /* uniform refinement level compiled into the tables (0..SFB_MAX_LEVEL) */
    unsigned flags;     /* SFB_REFINE_* */
    int isolation_level;/* patches: adaptive isolation limit around irregular features, 1..SFB_MAX_LEVEL
                           (0: SFB_DEFAULT_ISOLATION); below it faces get an end cap */
    sfb_shading_options shading; /* SFB_REFINE_SHADING */
    sfb_manifold_options manifold; /* SFB_SCHEME_MANIFOLD_BLEND */
    sfb_tribezier_options tribezier; /* SFB_SCHEME_TRIBEZIER */
} sfb_surface_config;
#define SFB_DEFAULT_ISOLATION 8
SFB_API sfb_surface_config sfb_surface_config_init(sfb_scheme scheme, int level);

typedef struct sfb_surface sfb_surface;

/* Compiles the tables (topology of the refined mesh, stencil tables) on the CPU. The surface
 * keeps a reference to nothing in `mesh`: the mesh may be destroyed afterwards. */
SFB_API sfb_result sfb_surface_create(sfb_context *ctx, const sfb_mesh *mesh,
                                      const sfb_surface_config *config, sfb_surface **out);
SFB_API void sfb_surface_destroy(sfb_surface *surface);

/* Which stencil table to apply. */
typedef enum sfb_table {
    SFB_TABLE_VERTEX = 0,  /* base vertices -> refined vertices */
    SFB_TABLE_LIMIT,       /* base vertices -> limit positions of refined vertices */
    SFB_TABLE_TANGENT_U,   /* base vertices -> first limit tangent */
    SFB_TABLE_TANGENT_V,   /* base vertices -> second limit tangent */
    SFB_TABLE_UV,          /* base UVs -> refined UVs (face-varying) */
    SFB_TABLE_COUNT_
} sfb_table;

/* A strided view into a float buffer (as OpenSubdiv's BufferDescriptor): element i, component c
 * is at data[offset + i*stride + c]; `length` is the number of components per element (1..16,
 * e.g. 3 for positions, 2 for UVs) and must match between source and destination; stride >= length. */
typedef struct sfb_buffer_desc { int offset, length, stride; } sfb_buffer_desc;

typedef struct sfb_stencil_info { int rows, sources, entries; } sfb_stencil_info;
/* Fails with SFB_INVALID_ARGS when the table was not built (flag missing). */
SFB_API sfb_result sfb_surface_stencil_info(const sfb_surface *surface, sfb_table table, sfb_stencil_info *out);

/* Applies one table on the context's backend: dst[row] = sum w * src[index]. src must hold
 * `sources` elements and dst `rows`: backends read src only in [offset, offset + (sources-1) *
 * stride + length) and write only the `length` components of each dst row (padding in the
 * stride is left alone). Argument errors set the context's last error, which concurrent
 * failing calls would race on: check arguments before calling from several threads. */
SFB_API sfb_result sfb_surface_eval_stencils(const sfb_surface *surface, sfb_table table,
                                             const float *src, sfb_buffer_desc src_desc,
                                             float *dst, sfb_buffer_desc dst_desc);
/* The engine case (gl backend with gl_use_current_context): apply a table to GL buffer
 * objects of the host's current context, writing straight into the buffer the host draws
 * from. Offsets and strides count floats. GL state the call binds is restored. Other
 * backends: SFB_UNSUPPORTED. */
SFB_API sfb_result sfb_surface_eval_stencils_gl(const sfb_surface *surface, sfb_table table,
                                                unsigned int src_buffer, sfb_buffer_desc src_desc,
                                                unsigned int dst_buffer, sfb_buffer_desc dst_desc);

/* ---- drawing a manifold blending surface on the host's GL context (seed 000 section V) ----
 * The engine case of seed 000's renderer: the gl backend with gl_use_current_context draws a
 * SFB_SCHEME_MANIFOLD_BLEND surface (built with SFB_REFINE_PATCHES) into the host's current
 * framebuffer. A vertex program evaluates the blend at every sample from the tables the
 * surface uploaded (the nine coefficient rows of each vertex's local geometry in a float
 * texture, as the seed's Fig. 8, and each patch's corner vertices and corner codes in an
 * integer texture): the four chart parameters, Table 2's vector pairs, the blend of the four
 * local geometries with the surface's weights, and the analytic normal, as sfb_surface_eval.
 * Each parametric face drawn is one instance of a (rate + 1) x (rate + 1) sample grid, sample
 * (i, j) at (u, v) = (i / rate, j / rate), drawn as 2 rate^2 indexed triangles,
 * counter-clockwise seen from the normal side. The fragment program lights the surface from
 * both sides (ambient 0.2 + diffuse 0.8 of `color`) and, with a trimming texture, discards the
 * fragments whose mask value at the face's (u, v) is below 0.5: the mask is read as
 * sfb_trim_mask describes (bilinear between texel centres, clamped at the tile's borders;
 * atlas tile t for parametric face t, faces past the last tile untrimmed).
 * The draw uses the host's framebuffer, viewport, depth, blend and cull state as they are.
 * What it binds (program, vertex array, texture units 0..2 and their samplers, the active
 * texture unit, transform feedback object and buffer, GL_RASTERIZER_DISCARD, pixel unpack
 * state) is restored before it returns. Call it where the host's context is current, on the
 * thread of the sfb context. */
typedef struct sfb_gl_draw_params {
    int rate;                   /* segments per parametric-face edge, 1..1024 (0: 16) */
    float mvp[16];              /* clip-from-object matrix, column-major as glUniformMatrix4fv (all 0: identity) */
    float normal_matrix[9];     /* column-major 3x3 taking object normals to the space of `light` (all 0: identity) */
    float light[3];             /* direction toward the light (need not be unit; all 0: (0, 0, 1)) */
    float color[4];             /* RGBA of the lit surface (all 0: (0.8, 0.8, 0.8, 1)) */
    unsigned int trim_texture;  /* 0: untrimmed; else a 2D texture of the current context holding the mask in
                                   its red channel, level 0 (sfb_gl_trim_texture makes one) */
    int trim_tiles_u, trim_tiles_v; /* atlas layout as sfb_trim_mask (0/0 or 1/1: one mask for every face); the
                                   texture's size must split into that many equal tiles */
    unsigned int capture_buffer;/* 0: none; else a buffer object of the current context that also receives every
                                   sample (a second pass of the same vertex program over the samples as points,
                                   rasterization off, through transform feedback): 6 floats per sample, the
                                   position and the unit normal in object space, sample (i, j) of the k-th face
                                   drawn at float index 6 ((k (rate + 1) + j) (rate + 1) + i); zeros for a hole */
    int first_face, face_count; /* parametric faces first_face .. first_face + face_count - 1 (face_count 0: all
                                   from first_face on) */
} sfb_gl_draw_params;
/* The defaults: rate 16, identity matrices, light (0, 0, 1), colour (0.8, 0.8, 0.8, 1), no
 * trimming, no capture, every face. */
SFB_API sfb_gl_draw_params sfb_gl_draw_params_init(void);
/* Draws `surface` as above. Errors: SFB_INVALID_ARGS for a NULL argument, a rate outside 0..1024,
 * a face range outside the surface's parametric faces, a trim_texture that is no texture, or a
 * capture_buffer that is no buffer or holds fewer than 24 (rate + 1)^2 bytes per face drawn;
 * SFB_INVALID_VALUE for a matrix, light or colour value that is not finite, atlas tiles that
 * are negative, half zero, or do not split the texture evenly; SFB_UNSUPPORTED when the context
 * does not run the gl backend on the host's context (gl_use_current_context; also a library
 * built without SURFBLEND_GL) or the surface is not a manifold blend with patches; GL
 * failures as SFB_BACKEND_ERROR or SFB_OUT_OF_MEMORY. Nothing is drawn on an error. */
SFB_API sfb_result sfb_surface_draw_gl(const sfb_surface *surface, const sfb_gl_draw_params *params);
/* Uploads a trimming mask (struct sfb_trim_mask, declared with the tessellator below; its
 * atlas tiles are not stored: pass them in sfb_gl_draw_params) into a new GL_R8 2D texture of
 * the host's current context, for sfb_gl_draw_params.trim_texture; the host owns it and deletes
 * it with glDeleteTextures. Same context requirement as sfb_surface_draw_gl (else
 * SFB_UNSUPPORTED); SFB_INVALID_ARGS for NULL arguments, SFB_INVALID_VALUE for a mask
 * sfb_surface_tessellate would refuse (NULL texels, a side outside 1..16384, bad tiles). */
struct sfb_trim_mask;
SFB_API sfb_result sfb_gl_trim_texture(sfb_context *ctx, const struct sfb_trim_mask *mask, unsigned int *texture);

/* The refined mesh as plain arrays. */
typedef struct sfb_mesh_data {
    int vertex_count, face_count, face_vertex_count, uv_count;
    float *positions;        /* xyz per refined vertex */
    float *limit_positions;  /* xyz, when SFB_REFINE_LIMIT */
    float *tangents_u, *tangents_v, *normals; /* xyz, when SFB_REFINE_LIMIT; normals unit length */
    float *uvs;              /* uv per refined UV value, when SFB_REFINE_UVS and the mesh has UVs */
    int *face_sizes, *face_vertices, *face_uvs;
    int crease_count; int *crease_vertices; float *crease_sharpness; /* remaining sharpness at this level */
    int corner_count; int *corner_vertices; float *corner_sharpness;
    int hole_count; int *holes;
    int boundary, crease_method, triangle_rule, uv_interp;
    /* sfb_surface_shade only (NULL otherwise); per output vertex: */
    float *blend_weights;       /* b at the refined level */
    float *limit_normals;       /* N_L, unit */
    float *subdivided_normals;  /* N_S, unit; zero where it was not computed (b = 0 without SFB_SHADE_ALL_SUBDIVIDED) */
    int *vertex_origin;         /* the refined vertex each output vertex is a copy of */
    int refined_vertex_count;   /* vertices of the refined level before splitting */
    int subdivided_count;       /* output vertices where N_S was computed */
    sfb_context *ctx_; /* allocator owner */
} sfb_mesh_data;

/* Applies the tables to the mesh's positions (and UVs) and returns the refined mesh. */
SFB_API sfb_result sfb_surface_refine(const sfb_surface *surface, sfb_mesh_data *out);
/* Same with other base positions (animation: same topology, new positions). */
SFB_API sfb_result sfb_surface_refine_positions(const sfb_surface *surface, const float *base_positions,
                                                int base_count, sfb_mesh_data *out);
SFB_API void sfb_mesh_data_free(sfb_mesh_data *data);

/* ---- subdivision shading (seed 001; needs SFB_REFINE_SHADING, Catmull-Clark or Loop) ----
 * Returns the refined mesh with blended normals N_B = normalize((1 - b^p) N_L + b^p N_S) in
 * `normals`: N_L the limit normals, N_S the subdivided normals (face-normal averages at the
 * normals level, refined with the scheme's stencils, one normal per crease region), b the
 * blend weights (1 at extraordinary vertices and their one-ring at the weights level,
 * refined with the scheme). Vertices on infinitely sharp creases are split, one output vertex
 * per region, so positions, limit_positions, tangents_u/v and the shade arrays are per output
 * vertex and face_vertices index output vertices (vertex_origin maps back). Crease, corner and
 * hole lists index refined vertices as sfb_surface_refine's. Safe to call from several threads
 * on one surface on the ref and simd backends. */
enum {
    SFB_SHADE_ALL_SUBDIVIDED = 1u << 0 /* compute N_S at every vertex (pictures, tests), not only where b > 0 */
};
typedef struct sfb_shade_params {
    float p;          /* blend exponent, > 0 (0: default 1) */
    unsigned flags;   /* SFB_SHADE_* */
} sfb_shade_params;
SFB_API sfb_shade_params sfb_shade_params_init(void);
SFB_API sfb_result sfb_surface_shade(const sfb_surface *surface, const sfb_shade_params *params, sfb_mesh_data *out);
typedef struct sfb_shade_info {
    int refined_vertices, output_vertices, split_vertices; /* split: refined vertices with more than one copy */
    int weighted;           /* output vertices with b > 0: where N_S is computed */
    int normals_level, weights_level, sources; /* sources: normals at the normals level (one per region) */
    size_t bytes;           /* memory of the shading tables */
} sfb_shade_info;
SFB_API sfb_result sfb_surface_shade_info(const sfb_surface *surface, sfb_shade_info *out);

/* A desc view of refined data (pointers into `data`), for sfb_write_obj or sfb_mesh_create. */
SFB_API void sfb_mesh_data_desc(const sfb_mesh_data *data, sfb_mesh_desc *out);


/* ---- limit evaluation (SFB_REFINE_PATCHES; Catmull-Clark, Loop, manifold blending) ----
 * Manifold blending (SFB_SCHEME_MANIFOLD_BLEND) uses the Catmull-Clark parametric faces: a
 * base quad is one, (u,v) as below; on a mesh with any non-quad face the blend is built on the
 * mesh after one Catmull-Clark step, and a base quad's square then holds its four child quads.
 * Locations are on parametric faces. Catmull-Clark: a base quad is one parametric face, (u,v)
 * in [0,1]^2 with (0,0) at its first vertex, (1,0) at its second and (0,1) at its last; a face
 * with n != 4 vertices is n parametric quads, sub-face i being (v_i, midpoint of v_i v_i+1,
 * centroid, midpoint of v_i-1 v_i) of the first subdivision step, (0,0) at v_i. Loop: a base
 * triangle is one parametric face with barycentric (u,v), u + v <= 1: the point
 * (1-u-v) v_0 + u v_1 + v v_2 of the parameter triangle. Parametric faces are numbered base face
 * by base face (sfb_surface_param_faces). */
typedef struct sfb_location { int face; float u, v; } sfb_location;
/* Output arrays, xyz per location; NULL members are not computed. du/dv are derivatives in
 * the parametric face's (u,v); normal is unit length (du x dv normalised, and at an
 * extraordinary vertex itself the limit normal, where du and dv are the limit tangent
 * directions since the parametric derivatives vanish or diverge there; SFB_SCHEME_PN: the
 * method's quadratic normal field normalised, which equals the vertex normals at the corners
 * but is not du x dv inside). */
typedef struct sfb_eval_output { float *position, *du, *dv, *normal, *duu, *duv, *dvv; } sfb_eval_output;

SFB_API int sfb_surface_param_face_count(const sfb_surface *surface);
/* The parametric faces of base face `base_face`: [*first, *first + *count). */
SFB_API sfb_result sfb_surface_param_faces(const sfb_surface *surface, int base_face, int *first, int *count);
/* The base face of a parametric face, and its sub-face index (-1 for a quad). */
SFB_API sfb_result sfb_surface_param_face_base(const sfb_surface *surface, int param_face, int *base_face, int *sub_face);
/* Evaluates the limit surface at `count` locations. Every location is checked first: a face
 * out of range, a hole, u or v outside [0,1] or not finite, u + v > 1 on a Loop triangle
 * (computed in double) returns SFB_INVALID_VALUE naming
 * the first bad query (element SFB_ELEMENT_NONE, index = its position) and writes nothing. */
SFB_API sfb_result sfb_surface_eval(const sfb_surface *surface, const sfb_location *locations, int count,
                                    const sfb_eval_output *out);

typedef struct sfb_patch_info {
    int param_faces, patches;
    int bspline, bezier;   /* regular patches: bicubic B-spline (Catmull-Clark), quartic Bezier triangle (Loop) */
    int stam, end_caps, max_depth, points;
    int manifold;          /* MANIFOLD4 blends (one per quad of the manifold mesh) */
    size_t bytes;  /* memory of the patch table and its points */
    int domain_sides;      /* 4: a parametric face's (u,v) is the unit square; 3: the triangle u + v <= 1 */
} sfb_patch_info;
SFB_API sfb_result sfb_surface_patch_info(const sfb_surface *surface, sfb_patch_info *out);

/* ---- tessellation (needs SFB_REFINE_PATCHES) ---- */
enum {
    SFB_TESS_SPLIT_CREASES = 1u << 0, /* duplicate the vertices along infinitely sharp interior creases, one
                                         copy per side, each with that side's normal (split normals) */
    SFB_TESS_UVS = 1u << 1            /* also the face-varying UVs at each vertex (sfb_tess_data.uvs): the limit of
                                         sfb_surface_refine's UVs at the same point (the mesh's uv_interp), so a
                                         tessellation and a refinement of one surface agree; vertices on a UV seam
                                         (an edge whose faces disagree on a UV) are split, one copy per side. Needs a
                                         surface created with SFB_REFINE_UVS from a mesh with UVs. A UV layout that is
                                         not a manifold (placeholder UVs shared by unrelated faces) is isolated one
                                         level only, so near its irregular features the UVs are approximated */
};
/* Trimming (seed 000 section V.5), for every scheme: a mask over each parametric face's (u,v)
 * square [0,1]^2 (a Loop triangle uses the half u + v <= 1 of it). Texel (i, j) =
 * texels[j * width + i] covers u in [i/width, (i+1)/width], v in [j/height, (j+1)/height] (row 0
 * at v = 0, as a GL texture). The mask value at (u,v) is the bilinear interpolation of the
 * texels at their centres, clamped at the borders, divided by 255; the surface is kept where it
 * is >= 0.5 (white) and trimmed where it is below (black). An atlas: tiles_u x tiles_v equal
 * tiles, tile t (row-major from row 0) for parametric face t; faces past the last tile are not
 * trimmed. tiles_u = tiles_v = 0 or 1: one mask for every face. The tessellator drops trimmed
 * triangles and cuts the ones crossing the 0.5 contour along it (new vertices evaluated on the
 * surface at the contour's (u,v)). */
typedef struct sfb_trim_mask {
    int width, height;           /* texels, 1..16384 each */
    const unsigned char *texels; /* width * height */
    int tiles_u, tiles_v;        /* atlas layout (0/0 or 1/1: one mask for all faces) */
} sfb_trim_mask;
typedef struct sfb_tess_config {
    int rate;         /* segments per parametric-face edge, 1..1024 (a quad: rate x rate cells, 2 triangles each;
                         a Loop triangle: the triangular grid of rate^2 triangles) */
    float tolerance;  /* 0: uniform. > 0: adaptive: each parametric face (and each edge) uses the smallest
                         rate <= `rate` whose chordal error is within `tolerance` (model units) */
    unsigned flags;   /* SFB_TESS_* */
    const struct sfb_trim_mask *trim; /* NULL: no trimming */
} sfb_tess_config;
SFB_API sfb_tess_config sfb_tess_config_init(int rate);

/* Indexed triangles. Watertight: a vertex on an edge shared by two parametric faces is computed
 * once and shared (except along infinitely sharp creases with SFB_TESS_SPLIT_CREASES, and UV
 * seams with SFB_TESS_UVS: there each side has its copy, at the same position). */
typedef struct sfb_tess_data {
    int vertex_count, triangle_count;
    float *positions, *normals;   /* xyz per vertex (unit normals) */
    sfb_location *locations;      /* per vertex: the parametric face and (u,v) it was evaluated at */
    int *triangles;               /* 3 vertex indices per triangle, counter-clockwise seen from the normal side */
    int *triangle_faces;          /* parametric face of each triangle */
    float *uvs;                   /* uv per vertex with SFB_TESS_UVS, else NULL */
    sfb_context *ctx_;            /* allocator owner */
} sfb_tess_data;
SFB_API sfb_result sfb_surface_tessellate(const sfb_surface *surface, const sfb_tess_config *config, sfb_tess_data *out);
SFB_API void sfb_tess_data_free(sfb_tess_data *data);

/* ---- software pictures ----
 * sfb_render draws a mesh (typically sfb_surface_refine's or sfb_surface_shade's output) into
 * an RGBA picture on the CPU, without GL: polygons fan-triangulated, z-buffered, per-pixel
 * normals interpolated and renormalised (Phong), two-sided lighting (the normal is turned
 * toward the viewer). The camera orbits the bounding-box centre of the vertices the faces use;
 * y is up. Faces listed in mesh->holes are not drawn; faces with a non-finite vertex are
 * skipped (counted in sfb_image.skipped_faces). Long renders report progress (stage "render")
 * and can be cancelled (SFB_CANCELLED, nothing kept). Reads the mesh only: several threads may
 * render the same mesh at once, each on its own context. */
#define SFB_RENDER_MAX_SIZE 8192 /* largest width or height in pixels */
typedef enum sfb_render_mode {
    SFB_RENDER_SHADED = 0,  /* neutral grey, diffuse + specular */
    SFB_RENDER_HIGHLIGHT,   /* highlight lines: parallel light lines in a plane fixed to the camera, followed along the
                               normal (ALGORITHMS.md section 7, Dir = N), as dark blue and cyan bands over lit grey; two
                               renders with the same view and positions but different normals are directly comparable */
    SFB_RENDER_WEIGHTS,     /* a per-vertex scalar in [0,1] as colour: blue (0), cyan, green, yellow, red (1), lightly shaded */
    SFB_RENDER_NORMALS      /* the unit normal as RGB = 0.5 + 0.5 n (world axes, before the two-sided flip) */
} sfb_render_mode;
typedef struct sfb_render_config {
    int width, height;       /* pixels, 1..SFB_RENDER_MAX_SIZE; 0: 640 (width), 480 (height) */
    int mode;                /* sfb_render_mode */
    const float *positions;  /* xyz per mesh vertex (vertex_count of them); NULL: mesh->positions */
    const float *normals;    /* xyz per mesh vertex, need not be unit; NULL: mesh->normals; NULL there too, or a
                                zero or non-finite normal: the polygon's flat normal */
    const float *scalars;    /* SFB_RENDER_WEIGHTS: one per vertex, clamped to [0,1] (non-finite: 0); NULL:
                                mesh->blend_weights (required in that mode) */
    int view_set;            /* 0: the default view (yaw 30, pitch 25); 1: yaw and pitch below */
    float yaw, pitch;        /* degrees: yaw turns the camera about the y axis (or up, below) from +z toward +x, pitch raises it */
    float zoom;              /* > 0: magnification; 0: 1, the bounding sphere just fits the smaller side */
    int orthographic;        /* 0: perspective (30 degree view of the bounding sphere); 1: orthographic */
    float stripes;           /* SFB_RENDER_HIGHLIGHT: light lines per bounding-sphere diameter in the light plane;
                                0: default 8 (more: denser lines) */
    float light_distance;    /* SFB_RENDER_HIGHLIGHT: distance of the light plane from the centre, toward the camera,
                                in bounding-sphere radii; 0: default 3 (farther: the lines follow the normal more) */
    int light_at_infinity;   /* SFB_RENDER_HIGHLIGHT: 1: the light plane infinitely far away, so that the stripe
                                depends on the normal alone (a flat face is one colour) */
    int draw_edges;          /* 1: overlay the polygons' edges (not the triangulation's diagonals) */
    unsigned char background[4]; /* RGBA of uncovered pixels; all 0: default opaque dark grey */
    float up[3];             /* the orbit's axis: zero (or +y): yaw turns about y; (0, 0, 1) for a z-up model, which the
                                same yaw and pitch then show as a y-up one is shown (finite) */
} sfb_render_config;
SFB_API sfb_render_config sfb_render_config_init(int mode);
typedef struct sfb_image {
    int width, height;
    unsigned char *rgba;     /* width * height * 4 bytes, rows top to bottom, alpha 255 on the object */
    int object_pixels;       /* pixels the mesh covers */
    int skipped_faces;       /* faces not drawn because a vertex is not finite (or behind the camera) */
    sfb_context *ctx_;       /* allocator owner */
} sfb_image;
/* Renders `mesh` with `config` (NULL: all defaults, SFB_RENDER_SHADED). Checks everything
 * before allocating: sizes (SFB_INVALID_ARGS when negative, SFB_LIMIT_EXCEEDED over
 * SFB_RENDER_MAX_SIZE or the memory budget), face sizes and vertex indices (SFB_INVALID_TOPOLOGY
 * naming the face; also for a mesh without faces), face sizes adding up to face_vertex_count,
 * holes in range, finite view values. On failure `out` is zeroed and nothing is kept. */
SFB_API sfb_result sfb_render(sfb_context *ctx, const sfb_mesh_data *mesh, const sfb_render_config *config, sfb_image *out);
SFB_API void sfb_image_free(sfb_image *img);

/* ---- surface quality analysis (seed 003), exact per pixel ----
 * sfb_surface_analyze draws a picture of a surface with patch tables (SFB_REFINE_PATCHES; every
 * scheme that evaluates) whose colours come from the exact limit position, normal and second
 * derivatives at every pixel, never from a mesh's interpolated normals. Steps: a proxy (each
 * parametric face sampled on a 2^level grid through the backend's eval_patches) is rasterised
 * into a buffer of (parametric face, u, v, depth) per pixel; each covered pixel is then projected
 * onto the exact surface along its own view ray (Newton steps on (u,v) in the picture's plane,
 * seeded by the proxy and, where that leaves its parametric face or the proxy's silhouette, by
 * the neighbouring pixels' solutions, so coverage and silhouettes are the limit surface's); the
 * limit surface is evaluated there (the backend's eval_patches) and the backend's `shade` kernel
 * turns position and derivatives into the mode's value; colours are filtered by each pixel's
 * footprint (band filtering, no moire). With `polygon_based` the same picture comes from the
 * proxy's interpolated limit positions and normals instead (the seed's Fig. 7b, for comparison).
 * Long analyses report progress (stage "analyze": 0.3 once the proxy is evaluated and
 * rasterised, 0.75 once every pixel is projected and evaluated, 0.9 after the shade kernel) and
 * can be cancelled (SFB_CANCELLED, nothing kept). The camera is sfb_render's (an orbit around the
 * centre of the control mesh's bounding box, y up) unless eye, target and up are given; `up`
 * alone (camera_set 0, up not zero) turns the orbit about that axis instead of y (0, 0, 1 for a
 * z-up model: the same yaw and pitch then see it as a y-up one is seen). */
typedef enum sfb_analyze_mode {
    SFB_ANALYZE_REFLECTION = 0, /* seed 003: the view ray's reflection r = v - 2(v.n)n meets a finite light plane carrying a
                                   texture (stripes, lattice, circles or an RGBA image); rays that miss show the miss colour */
    SFB_ANALYZE_HIGHLIGHT,      /* Beier-Chen highlight lines: the normal line P + mu n meets the light plane (ALGORITHMS.md 7),
                                   stripes across the plane (view-independent) */
    SFB_ANALYZE_ZEBRA,          /* zebra: stripes of an environment at infinity, by the angle between the reflected view ray
                                   and the stripe axis (bands of constant acos(r.axis)) */
    SFB_ANALYZE_ISOPHOTE,       /* isophotes: bands of n.l (l the light direction), coloured blue (n.l = -1) to red (1) */
    SFB_ANALYZE_CURVATURE,      /* Gaussian, mean or largest absolute principal curvature from the exact second
                                   derivatives, in a diverging map (blue < 0 < red; max: the blue-to-red map from 0),
                                   range returned; mean > 0 where the surface bulges toward the viewer; a Gaussian
                                   curvature under (1e-4 / bounding radius)^2 is 0 (float kernels' noise on flat parts) */
    SFB_ANALYZE_NORMALS,        /* the unit normal as RGB = 0.5 + 0.5 n */
    SFB_ANALYZE_SHADED,         /* diffuse + specular grey */
    SFB_ANALYZE_MODE_COUNT_
} sfb_analyze_mode;
typedef enum sfb_light_pattern {
    SFB_LIGHT_STRIPES = 0, /* parallel light lines across the plane's u axis */
    SFB_LIGHT_LATTICE,     /* lines along both axes (seed Fig. 6a) */
    SFB_LIGHT_CIRCLES,     /* regularly arranged round lights (seed Fig. 6b) */
    SFB_LIGHT_IMAGE        /* the caller's RGBA texture over the whole plane */
} sfb_light_pattern;
typedef enum sfb_curvature_kind { SFB_CURVATURE_GAUSSIAN = 0, SFB_CURVATURE_MEAN, SFB_CURVATURE_MAX_ABS } sfb_curvature_kind;
/* Scratch memory an analysis keeps for the next one (sfb_analyze_config.workspace): an editor's
 * analysis view redrawn per frame takes its buffers from here instead of allocating and
 * touching ~100 bytes per pixel afresh per call (about a fifth of a 1024 x 1024 analysis on
 * the simd backend). The buffers grow to the largest analysis run with it and stay (counted
 * against the context's memory budget) until sfb_analysis_workspace_destroy. It also keeps the
 * last surface's proxy and face adjacency (they depend on the surface and the proxy level, not
 * on the view: a surface never changes), so a surface analysed again, from any view, skips
 * their evaluation. A workspace belongs to the context it was made on and, like that context,
 * to one thread at a time; results are bit for bit those without it. */
typedef struct sfb_analysis_workspace sfb_analysis_workspace;
SFB_API sfb_result sfb_analysis_workspace_create(sfb_context *ctx, sfb_analysis_workspace **out);
SFB_API void sfb_analysis_workspace_destroy(sfb_analysis_workspace *workspace); /* NULL: nothing */
SFB_API size_t sfb_analysis_workspace_bytes(const sfb_analysis_workspace *workspace); /* held now */
#define SFB_ANALYZE_MAX_SIZE 8192 /* largest width or height in pixels */
#define SFB_ANALYZE_MAX_LEVEL 8   /* proxy level: 2^level segments per parametric-face edge */
typedef struct sfb_analyze_config {
    int width, height;        /* pixels; both 0: 640 x 480; one of them 0 or either negative: SFB_INVALID_ARGS */
    int mode;                 /* sfb_analyze_mode */
    int level;                /* proxy: each parametric face sampled on 2^level segments per edge (1 is the coarsest,
                                 "subdivided once"); 0: chosen from the view, the coarsest of 1..4 whose grid triangles
                                 cover about 256 pixels or fewer (the picture does not depend on it; the proxy only seeds
                                 the projection and fewer, larger triangles raster faster: 1 on meshes of a few hundred
                                 faces or more seen whole), 2 with polygon_based; sfb_analysis.proxy_level reports it */
    int polygon_based;        /* 1: shade from the proxy's interpolated limit positions and normals (the polygon-based
                                 method the seed shows to be wrong), for comparison */
    int newton_steps;         /* Newton steps per seed; 0: 8 */
    /* camera: the orbit of sfb_render (view_set, yaw, pitch, zoom) or, with camera_set, eye/target/up */
    int view_set;
    float yaw, pitch, zoom;
    int camera_set;
    float eye[3], target[3], up[3]; /* up without camera_set: the orbit's axis (zero: y) */
    float fov;                /* degrees, full vertical angle, 0: 30; orthographic: the picture's height in model units
                                 (0: the bounding sphere fits) */
    int orthographic;
    float near_plane;         /* distance below which proxy triangles are not drawn; 0: 1e-3 bounding radii; < 0: error */
    /* light */
    int light_pattern;        /* sfb_light_pattern (REFLECTION, HIGHLIGHT) */
    int light_set;            /* 1: the plane below; 0: derived from the bounding box and the view */
    float light_center[3], light_normal[3], light_axis[3]; /* the plane: centre, normal (toward the surface), its u axis
                                 (the direction across the stripes; projected into the plane) */
    float light_size[2];      /* extent along u and v in model units (0: 16 bounding radii) */
    float stripes;            /* stripes (or lattice cells, circle rows) across the light's u extent; REFLECTION 0: 16;
                                 HIGHLIGHT: per bounding-sphere diameter, 0: 5; ZEBRA: per 180 degrees, 0: 16;
                                 ISOPHOTE: bands over n.l in [-1,1], 0: 10 */
    float stripe_width;       /* lit share of each period (0..1); 0: 0.5 (HIGHLIGHT 0.7, LATTICE 0.2, CIRCLES: the
                                 circles' diameter share of the cell, 0.6) */
    float light_dir[3];       /* ZEBRA axis, ISOPHOTE light, SHADED key; all 0: from the camera (upper left) */
    const unsigned char *light_rgba; /* SFB_LIGHT_IMAGE: light_width x light_height RGBA, row 0 at the plane's v = 0 */
    int light_width, light_height;
    int curvature;            /* sfb_curvature_kind */
    float curvature_range;    /* > 0: the colour map spans [-range, range] ([0, range] for MAX_ABS); 0: the 90th
                                 percentile of |value| over the picture */
    unsigned char background[4]; /* RGBA of uncovered pixels; all 0: opaque dark grey */
    unsigned char miss[4];       /* REFLECTION, HIGHLIGHT: colour of rays that miss the light plane, lit a little by the
                                    key light so that the form reads; all 0: near black */
    sfb_analysis_workspace *workspace; /* NULL: the analysis allocates its scratch memory and frees it before returning */
} sfb_analyze_config;
SFB_API sfb_analyze_config sfb_analyze_config_init(int mode);
typedef struct sfb_analysis {
    int width, height;
    unsigned char *rgba;      /* width * height * 4, rows top to bottom, alpha 255 on the surface */
    float *values;            /* per pixel the mode's value at the pixel centre: stripe coordinate (REFLECTION: u
                                 periods, HIGHLIGHT/ZEBRA/ISOPHOTE: periods), curvature; NaN where uncovered or missed */
    unsigned char *classes;   /* per pixel: 0 uncovered, 1 missed the light, 2 dark band / outside a light, 3 lit band /
                                 inside a light; ISOPHOTE: 2 + band; CURVATURE: 2 + round(8 value / range) + 8 (17 bands, the
                                 middle one centred on 0), max |k|: 2 + floor(16 value / range); NORMALS, SHADED: 2 */
    sfb_location *hits;       /* per pixel: the parametric face and (u,v) the colour was evaluated at (face -1: none) */
    int covered_pixels;       /* pixels on the surface */
    int proxy_pixels;         /* pixels the proxy covered */
    int grown_pixels;         /* covered by the exact surface beyond the proxy's silhouette */
    int dropped_pixels;       /* covered by the proxy, but no view ray through them meets the exact surface */
    int fallback_pixels;      /* Newton did not converge: the proxy's point was used */
    int proxy_level;          /* the proxy level used (sfb_analyze_config.level, or the one chosen for 0) */
    int light_hits;           /* REFLECTION/HIGHLIGHT: pixels whose ray met the light plane */
    float value_min, value_max; /* over covered pixels */
    float range;              /* CURVATURE: the colour map's range used */
    sfb_context *ctx_;
} sfb_analysis;
/* Checks everything first (sizes and level: SFB_INVALID_ARGS / SFB_LIMIT_EXCEEDED; the memory
 * budget; NaN or infinite camera, light or range values, a camera whose eye equals its target,
 * a negative near plane, a zero light normal, an axis parallel to it, an image light without
 * texels or with a zero size: SFB_INVALID_VALUE). A REFLECTION or HIGHLIGHT picture whose rays
 * all miss the light plane (parallel to every ray, or behind the surface) is SFB_INVALID_VALUE
 * too. On failure `out` is zeroed and nothing is kept. */
SFB_API sfb_result sfb_surface_analyze(const sfb_surface *surface, const sfb_analyze_config *config, sfb_analysis *out);
SFB_API void sfb_analysis_free(sfb_analysis *a);
/* The "zebra view" of an editor: draws an analysis picture into the host's current framebuffer,
 * stretched over its current viewport (nearest texel), the pixels on the surface only (the rest
 * keep what the host drew). Depth test, face culling and blending are off for the draw; the
 * host's state is restored (program, vertex array, texture units 0-2 with their samplers, the
 * active unit, the unpack state, those three switches), and no GL error is left. Needs the gl
 * backend on the host's current context (gl_use_current_context), else SFB_UNSUPPORTED. */
SFB_API sfb_result sfb_analysis_draw_gl(sfb_context *ctx, const sfb_analysis *analysis);

/* ---- rolling-ball blending (fillets) of sharp features on triangle meshes (seed 002) ----
 * sfb_mesh_fillet rounds sharp features of a triangle mesh with a rolling ball of radius r
 * without remeshing: the output has the input's vertices, faces and connectivity; only the
 * vertices of each blend region move, onto a virtual sweep surface (profiles swept along the
 * spine, the path of the ball's centre). Pipeline, per curve: blending curve (feature edges whose
 * dihedral angle exceeds a threshold, chained; or a caller's vertex chain) -> base patches within
 * alpha*r of the curve -> offset patches (vertex normals, per side) -> their intersection through
 * an AABB tree: the spine -> spine samples and a profile per sample -> blend region vertices
 * mapped onto the sweep. Progress stages "fillet curves", "fillet spine", "fillet surface",
 * "fillet map", "fillet project" (a caller timing the stages reads them from the progress
 * callback); cancelling returns SFB_CANCELLED and keeps nothing. */
typedef enum sfb_fillet_profile {
    SFB_FILLET_ARC = 0,     /* the rolling ball's circular arc (rational quadratic, exact) */
    SFB_FILLET_CONIC = 1,   /* a conic through the same ends and end tangents: middle weight conic_weight */
    SFB_FILLET_SHARPEN = 2, /* the two end tangents up to their intersection: turns a rounded feature sharp */
    SFB_FILLET_HERMITE = 3  /* a cubic Hermite curve between the contact points, tangents scaled by hermite_scale */
} sfb_fillet_profile;
typedef struct sfb_fillet_curve {
    const int *vertices;    /* a chain of mesh edges v0-v1-...; closed when the last vertex equals the first */
    int count;              /* vertices in the list (>= 2) */
    float radius;           /* 0: the config's radius */
    int profile;            /* sfb_fillet_profile + 1; 0: the config's profile */
    float conic_weight;     /* 0: the config's */
} sfb_fillet_curve;
typedef struct sfb_fillet_config {
    float radius;           /* ball radius, > 0 (required) */
    float angle;            /* degrees: edges whose dihedral angle exceeds it are features; 0: 30 */
    int profile;            /* sfb_fillet_profile */
    float conic_weight;     /* SFB_FILLET_CONIC: weight of the middle control point (< 1 ellipse, 1 parabola,
                               > 1 hyperbola); 0: the arc's own, cos of half the central angle */
    float hermite_scale;    /* SFB_FILLET_HERMITE: end tangent length over the chord, in [0, 10]; 0: the arc's tangents */
    float alpha;            /* base patches: faces within alpha*radius of the curve; 0: 1.75 (seed Fig. 2) */
    int samples;            /* initial spine samples by arc length; 0: 40 (seed section 4.1) */
    float chord_ratio;      /* a spine interval is refined while chord height / chord length exceeds it; 0: 0.002 */
    const sfb_fillet_curve *curves; /* the caller's blending curves; NULL: features by angle */
    int curve_count;
    int map;                /* SFB_FILLET_MAP_*: how blend-region vertices find their place on the sweep */
    int relax;              /* SFB_FILLET_MAP_CONFORMAL: steps of Laplacian optimisation of the map in 2D (seed 5.2,
                               Fig. 9: uniform weights even out the triangles' sizes; kept only if no face turns
                               over); 0: none (the default: the conformal map alone gave the fairer triangles on
                               the tests' shapes, see fil_relax) */
    int skip_failed;        /* non-zero: a curve that cannot be filleted with its radius (its offset patches do not
                               meet, or meet away from it) is left as it is and reported (skipped) instead of
                               failing the call; the call fails when every curve is skipped */
} sfb_fillet_config;
enum {
    SFB_FILLET_MAP_CONFORMAL = 0, /* default: the direct projection on the region's boundary, a conformal (cotangent)
                                     map inside it solved by preconditioned conjugate gradients (seed 5); symmetrised
                                     mean-value weights where that folds, the direct projection where both fold */
    SFB_FILLET_MAP_DIRECT = 1     /* every vertex by its nearest spine point and its distance from the curve */
};
SFB_API sfb_fillet_config sfb_fillet_config_init(float radius);
typedef struct sfb_fillet_curve_report {
    int closed;                 /* 1: a closed loop, 0: an open chain */
    int convex;                 /* 1: the ball is inside the solid (offset against the normals) */
    int curve_vertices;         /* vertices of the blending curve */
    float radius;
    float curve_length;         /* the blending curve's own length */
    float spine_length;
    int samples;                /* spine samples after refinement */
    int vertices_moved;
    int vertices_kept;          /* region vertices left where they were: the sweep there lay over 2 d away (d: the
                                   base patches' reach, alpha r), which only an uneven surface gives */
    int self_intersections;     /* spine loops cut out (seed section 4.3) */
    float max_deviation;        /* largest distance of a moved vertex from the ideal sweep surface */
    int map;                    /* how the region was mapped: 0 direct projection, 1 conformal, 2 mean-value weights */
    int skipped;                /* config.skip_failed: this curve could not be filleted and was left as it was */
    int relaxed;                /* the 2D Laplacian optimisation was kept (config.relax) */
} sfb_fillet_curve_report;
typedef struct sfb_fillet_report {
    int curve_count;
    sfb_fillet_curve_report *curves;   /* curve_count entries, freed by sfb_fillet_report_free */
    int vertices_moved;         /* all curves' and corners' */
    int curves_skipped;         /* config.skip_failed: curves left as they were */
    int corner_count;           /* corners where three curves end, rounded by the ball's sphere */
    int corner_vertices_moved;
    int faces_folded;           /* faces turned over (normal over 90 degrees from the input's): the radius is too
                                   large for the surface around some curve; 0 on every generated shape in the tests */
    sfb_context *ctx_;
} sfb_fillet_report;
/* Fillets `mesh` (all faces triangles, manifold: SFB_INVALID_TOPOLOGY naming the face or edge
 * otherwise) into a new mesh *out (same vertices, faces, UVs and tags; positions moved; the
 * filleted edges lose their crease tags). Every curve is filleted on the input's positions; where
 * exactly three curves of one convexity and radius end at a vertex whose faces lie on three
 * planes (a box's corner), each sweep ends where the ball touches the third plane and the
 * vertices beyond move onto the ball's sphere. Errors, with *out NULL, the input untouched and nothing
 * kept: radius <= 0 or not finite, a bad profile or weight (SFB_INVALID_VALUE); a caller's curve
 * that is not a chain of mesh edges (SFB_INVALID_TOPOLOGY naming the vertex); no feature found or a
 * radius too large for the base patches, so that the offsets do not meet (SFB_INVALID_VALUE); the
 * memory budget (SFB_LIMIT_EXCEEDED, checked before the work). report may be NULL. */
SFB_API sfb_result sfb_mesh_fillet(sfb_context *ctx, const sfb_mesh *mesh, const sfb_fillet_config *config,
                                   sfb_mesh **out, sfb_fillet_report *report);
SFB_API void sfb_fillet_report_free(sfb_fillet_report *report);

/* Measures of a triangle mesh (faces of 3 vertices; SFB_INVALID_TOPOLOGY naming the face
 * otherwise): angle-weighted unit vertex normals (xyz per vertex; zero for a vertex no face uses),
 * and the mean curvature per vertex from the cotangent Laplacian with mixed Voronoi areas, signed
 * positive where the surface bends away from its normal (a sphere with outward normals: +1/R);
 * boundary and unused vertices get 0. For pictures (sfb_render's WEIGHTS mode) and checks. */
SFB_API sfb_result sfb_mesh_vertex_normals(sfb_context *ctx, const sfb_mesh *mesh, float *normals);
SFB_API sfb_result sfb_mesh_mean_curvature(sfb_context *ctx, const sfb_mesh *mesh, float *curvature);

#ifdef __cplusplus
}
#endif
#endif /* SURFBLEND_H */

#if defined(SURFBLEND_IMPLEMENTATION) && !defined(SURFBLEND_IMPLEMENTED)
#define SURFBLEND_IMPLEMENTED
#line 1 "src/sfb_internal.h"
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
    unsigned long serial;        /* the context's count of surfaces at its creation (from 1): a surface never changes,
                                    so data derived from it alone may be kept under it (sfb_analysis_workspace) */
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
/* The same with four child patches per triangle f (45 doubles each at net + 180 f + 45 i, child i
 * of the parametric triangle's quadtree: corners 0, 1, 2, the middle 3). */
SFB__IF sfb_result sfb__patch_table_beztri_children(sfb_context *ctx, const sfb__level *l, const double *net, sfb__patch_table *pt);
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
 * that the reuse changes nothing). */
enum { SFB__TBZ_SEED_PLANE = 1, SFB__TBZ_NO_REUSE = 2 };
typedef struct sfb__tbz_stats {
    long iterations;   /* CGLS iterations, all coordinates and nets */
    long unknowns;     /* points moved by the G1 solve, per coordinate and net */
    long constraints;  /* G1 rows */
    double residual;   /* largest G1 row left, relative to the net's largest coordinate */
    double ours_residual; /* the same within the constraint components around extraordinary crease vertices with
                             our tangent plane */
    int fallbacks;     /* smooth nets rebuilt with the seed's tangent plane (ours unsolvable) */
    int reused;        /* sharp-net constraint components that were the same system as a smooth-net one and took its
                          solution (SFB__TBZ_NO_REUSE: none) */
} sfb__tbz_stats;
SFB__IF sfb_result sfb__tribezier_points(sfb_context *ctx, const sfb__level *base, const float *positions,
                                         const sfb_tribezier_options *opt, unsigned flags, double **out, sfb__tbz_stats *stats);
/* The same on the mesh after one Loop step (*rl, free with sfb__level_free): 45 doubles per child
 * face 4 f + i (child i of triangle f in its parametric triangle's quadtree frame). */
SFB__IF sfb_result sfb__tribezier_refined_points(sfb_context *ctx, const sfb__level *base, const float *positions,
                                                 const sfb_tribezier_options *opt, unsigned flags, sfb__level *rl, double **out,
                                                 sfb__tbz_stats *stats);
/* The same as one BEZIER_TRI15 patch per triangle, or four (one Loop step) where the mesh's own
 * G1 constraints have no exact solution. */
SFB__IF sfb_result sfb__tribezier_build(sfb_context *ctx, const sfb__level *base, const float *positions,
                                        const sfb_tribezier_options *opt, sfb__patch_table *pt);
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
#line 1 "src/context.c"
/* Results, context, allocator with memory budget, errors, logging, progress. */

SFB_API const char *sfb_result_string(sfb_result r) {
    switch (r) {
#define SFB__RESULT_CASE(name, value, text) case name: return text;
        SFB_RESULT_LIST(SFB__RESULT_CASE)
#undef SFB__RESULT_CASE
    default: return "unknown result";
    }
}

static void *sfb__libc_alloc(size_t size, void *user) { (void)user; return malloc(size); }
static void *sfb__libc_realloc(void *p, size_t size, void *user) { (void)user; return realloc(p, size); }
static void sfb__libc_free(void *p, void *user) { (void)user; free(p); }

SFB_API sfb_context_config sfb_context_config_init(void) {
    sfb_context_config c;
    memset(&c, 0, sizeof c);
    return c;
}

int sfb__mul_size(size_t a, size_t b, size_t *out) {
    if (a != 0 && b > ((size_t)-1) / a) return 0;
    *out = a * b;
    return 1;
}

/* A big block of the default allocator is advised into transparent huge pages (Linux, where
 * the system leaves THP to madvise, the common default). A picture's per-pixel buffers are tens
 * of megabytes written once: at 4 KiB a page, faulting them in cost more than the analysis
 * itself on a virtual machine (catmark_car 1024^2 on the simd backend without a workspace:
 * 216 ms, 130 of them first touches; README, "Surface quality analysis"). Only the default
 * allocator's blocks: a caller's allocator owns its memory's policy. */
#define SFB__HUGE_MIN ((size_t)4 << 20)
static void sfb__advise_huge(const sfb_context *ctx, void *p, size_t size) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    uintptr_t a, e;
    if (size < SFB__HUGE_MIN || ctx->allocator.alloc != sfb__libc_alloc) return;
    a = ((uintptr_t)p + 0x1FFFFF) & ~(uintptr_t)0x1FFFFF; /* the whole 2 MiB pages inside the block */
    e = ((uintptr_t)p + size) & ~(uintptr_t)0x1FFFFF;
    if (e > a) (void)madvise((void *)a, (size_t)(e - a), MADV_HUGEPAGE); /* advice: a refusal changes nothing */
#else
    (void)ctx; (void)p; (void)size;
#endif
}

/* Every block carries its size in a 16-byte header so that the live total can be kept
 * against the memory budget exactly. */
#define SFB__HDR 16
void *sfb__alloc(sfb_context *ctx, size_t size) {
    unsigned char *p;
    if (size > ((size_t)-1) - SFB__HDR) return NULL;
    if (ctx->live_bytes + size > ctx->budget || ctx->live_bytes + size < ctx->live_bytes) {
        ctx->budget_refused = 1;
        return NULL;
    }
    p = (unsigned char *)ctx->allocator.alloc(size + SFB__HDR, ctx->allocator.user);
    if (!p) return NULL;
    sfb__advise_huge(ctx, p, size + SFB__HDR);
    memcpy(p, &size, sizeof size);
    ctx->live_bytes += size;
    if (ctx->live_bytes > ctx->peak_bytes) ctx->peak_bytes = ctx->live_bytes;
    return p + SFB__HDR;
}
void *sfb__calloc(sfb_context *ctx, size_t count, size_t size) {
    size_t total;
    void *p;
    if (!sfb__mul_size(count, size, &total)) return NULL;
    p = sfb__alloc(ctx, total ? total : 1);
    if (p) memset(p, 0, total);
    return p;
}
void *sfb__realloc(sfb_context *ctx, void *ptr, size_t size) {
    unsigned char *p, *np;
    size_t old;
    if (!ptr) return sfb__alloc(ctx, size);
    p = (unsigned char *)ptr - SFB__HDR;
    memcpy(&old, p, sizeof old);
    if (size > ((size_t)-1) - SFB__HDR) return NULL;
    if (size > old && (ctx->live_bytes - old + size > ctx->budget)) {
        ctx->budget_refused = 1;
        return NULL;
    }
    np = (unsigned char *)ctx->allocator.realloc(p, size + SFB__HDR, ctx->allocator.user);
    if (!np) return NULL;
    if (size > old) sfb__advise_huge(ctx, np, size + SFB__HDR);
    memcpy(np, &size, sizeof size);
    ctx->live_bytes = ctx->live_bytes - old + size;
    if (ctx->live_bytes > ctx->peak_bytes) ctx->peak_bytes = ctx->live_bytes;
    return np + SFB__HDR;
}
void sfb__free(sfb_context *ctx, void *ptr) {
    unsigned char *p;
    size_t old;
    if (!ptr) return;
    p = (unsigned char *)ptr - SFB__HDR;
    memcpy(&old, p, sizeof old);
    ctx->live_bytes -= old;
    ctx->allocator.free(p, ctx->allocator.user);
}

static const char *sfb__element_name(sfb_element_kind k) {
    switch (k) {
    case SFB_ELEMENT_VERTEX: return "vertex";
    case SFB_ELEMENT_EDGE: return "edge";
    case SFB_ELEMENT_FACE: return "face";
    case SFB_ELEMENT_LINE: return "line";
    case SFB_ELEMENT_UV: return "uv";
    default: return "";
    }
}

sfb_result sfb__error(sfb_context *ctx, sfb_result r, sfb_element_kind kind, long index, const char *fmt, ...) {
    va_list ap;
    char body[768];
    if (!ctx) return r;
    va_start(ap, fmt);
    vsnprintf(body, sizeof body, fmt, ap);
    va_end(ap);
    if (kind != SFB_ELEMENT_NONE && index >= 0)
        snprintf(ctx->error, sizeof ctx->error, "%s %ld: %s", sfb__element_name(kind), index, body);
    else
        snprintf(ctx->error, sizeof ctx->error, "%s", body);
    ctx->error_info.result = r;
    ctx->error_info.element = kind;
    ctx->error_info.index = index;
    ctx->error_info.message = ctx->error;
    if (ctx->logger.func) ctx->logger.func(SFB_LOG_ERROR, ctx->error, ctx->logger.user);
    return r;
}

void sfb__error_keep(const sfb_context *ctx, sfb__error_state *st) {
    memcpy(st->message, ctx->error, sizeof st->message);
    st->info = ctx->error_info;
}
void sfb__error_put_back(sfb_context *ctx, const sfb__error_state *st) {
    memcpy(ctx->error, st->message, sizeof ctx->error);
    ctx->error_info = st->info;
    ctx->error_info.message = ctx->error;
}

sfb_result sfb__oom(sfb_context *ctx, const char *what) {
    int budget = ctx->budget_refused;
    ctx->budget_refused = 0;
    if (budget)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "%s needs more memory than the memory budget allows (%zu bytes in use, budget %zu bytes)", what,
                          ctx->live_bytes, ctx->budget);
    return sfb__error(ctx, SFB_OUT_OF_MEMORY, SFB_ELEMENT_NONE, -1, "out of memory: the allocator failed during %s", what);
}

void sfb__log(sfb_context *ctx, int level, const char *fmt, ...) {
    va_list ap;
    char msg[768];
    if (!ctx || !ctx->logger.func) return;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ctx->logger.func(level, msg, ctx->logger.user);
}

sfb_result sfb__progress(sfb_context *ctx, float done, const char *stage) {
    if (ctx->progress.func && ctx->progress.func(done, stage, ctx->progress.user))
        return sfb__error(ctx, SFB_CANCELLED, SFB_ELEMENT_NONE, -1, "cancelled by the progress callback during %s", stage);
    return SFB_SUCCESS;
}

void sfb__parallel(sfb_context *ctx, void (*task)(void *arg, int first, int last), void *arg, int first, int last) {
    const sfb__backend_vtable *be = ctx->backend;
    if (first >= last) return;
    if (be && be->parallel && be->parallel(ctx->backend_state, task, arg, first, last)) return;
    task(arg, first, last);
}

/* sfb_context_create, keeping the backend report (what was tried, why each failed) in
 * report/size when no backend initialises. */
sfb_result sfb__context_create_reporting(const sfb_context_config *config, sfb_context **out, char *report, size_t size) {
    sfb_context_config c = config ? *config : sfb_context_config_init();
    sfb_allocator a = c.allocator;
    sfb_context *ctx;
    unsigned char *raw;
    size_t sz = sizeof(sfb_context);
    int i;
    if (!out) return SFB_INVALID_ARGS;
    *out = NULL;
    if ((a.alloc == NULL) != (a.free == NULL) || (a.alloc && !a.realloc)) return SFB_INVALID_ARGS;
    if (c.backend_count < 0 || c.backend_count > 16 || (c.backend_count > 0 && !c.backends)) return SFB_INVALID_ARGS;
    if (c.threads < 0) return SFB_INVALID_ARGS;
    if (!a.alloc) { a.alloc = sfb__libc_alloc; a.realloc = sfb__libc_realloc; a.free = sfb__libc_free; a.user = NULL; }
    raw = (unsigned char *)a.alloc(sz, a.user);
    if (!raw) return SFB_OUT_OF_MEMORY;
    ctx = (sfb_context *)raw;
    memset(ctx, 0, sizeof *ctx);
    ctx->allocator = a;
    ctx->logger = c.logger;
    ctx->progress = c.progress;
    ctx->budget = c.memory_budget ? c.memory_budget : SFB_DEFAULT_MEMORY_BUDGET;
    ctx->threads = c.threads;
    ctx->gl_use_current_context = c.gl_use_current_context;
    if (c.backends && c.backend_count > 0) {
        for (i = 0; i < c.backend_count; ++i) {
            if (c.backends[i] <= SFB_BACKEND_DEFAULT || c.backends[i] >= SFB_BACKEND_KIND_COUNT_) {
                a.free(raw, a.user);
                return SFB_INVALID_ARGS;
            }
            ctx->order[ctx->order_count++] = c.backends[i];
        }
    } else {
        /* The default order, written here only. */
        ctx->order[ctx->order_count++] = SFB_BACKEND_SIMD;
        ctx->order[ctx->order_count++] = SFB_BACKEND_REF;
    }
    ctx->error_info.index = -1;
    ctx->error_info.message = ctx->error;
    {
        const char *env = c.ignore_environment ? NULL : getenv("SURFBLEND_BACKEND");
        sfb_result r = sfb__select_backend(ctx, env);
        if (r != SFB_SUCCESS) {
            if (report && size) {
                size_t n = strlen(ctx->report);
                while (n > 0 && ctx->report[n - 1] == '\n') --n;
                if (n >= size) n = size - 1;
                memcpy(report, ctx->report, n);
                report[n] = 0;
            }
            a.free(raw, a.user);
            return r;
        }
    }
    *out = ctx;
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_context_create(const sfb_context_config *config, sfb_context **out) {
    return sfb__context_create_reporting(config, out, NULL, 0);
}

SFB_API void sfb_context_destroy(sfb_context *ctx) {
    sfb_allocator a;
    if (!ctx) return;
    if (ctx->backend && ctx->backend->shutdown) ctx->backend->shutdown(ctx, ctx->backend_state);
    {
        int n;
        for (n = 0; n <= SFB__STAM_MAX_VALENCE; ++n) { sfb__eigen_cc_free(ctx, ctx->eigen_cc[n]); sfb__eigen_loop_free(ctx, ctx->eigen_loop[n]); }
    }
    a = ctx->allocator;
    a.free(ctx, a.user);
}

SFB_API const char *sfb_last_error(const sfb_context *ctx) { return ctx ? ctx->error : ""; }
SFB_API sfb_error_info sfb_last_error_info(const sfb_context *ctx) {
    sfb_error_info e;
    if (ctx) return ctx->error_info;
    memset(&e, 0, sizeof e);
    e.index = -1;
    e.message = "";
    return e;
}
SFB_API void sfb_clear_error(sfb_context *ctx) {
    if (!ctx) return;
    ctx->error[0] = 0;
    ctx->error_info.result = SFB_SUCCESS;
    ctx->error_info.element = SFB_ELEMENT_NONE;
    ctx->error_info.index = -1;
}
#line 1 "src/pool.c"
/* A CPU thread pool that a backend owns and lends (the simd backend's kernels and the
 * `parallel` slot of simd, gl and osmesa; sfb__pool in src/sfb_internal.h).
 *
 * threads - 1 workers are started by sfb__pool_start and joined by sfb__pool_stop. A run cuts
 * [first, last) into 4 chunks per thread, of about equal entry counts (with `offsets`: stencil
 * rows) or of equal items; the caller and the workers claim chunks until none is left, and the
 * caller returns once every claimed chunk is done (it never waits for a worker still asleep).
 * Idle workers, and a caller waiting for the last chunks, spin a while before they sleep
 * (SFB__POOL_SPIN below), so that runs coming back to back do not pay a wake-up each.
 * A run while another thread's run holds the pool (pthread_mutex_trylock) returns 0 having run
 * nothing, and so does every run of a pool of one thread: the caller then runs the work
 * itself. Where no thread support is known (SFB__THREADS undefined: _WIN32 and others), a pool
 * always has one thread. */

int sfb__pool_threads(int requested) {
    long n = requested;
    if (n <= 0) {
#if defined(SFB__THREADS) && defined(_SC_NPROCESSORS_ONLN)
        n = sysconf(_SC_NPROCESSORS_ONLN);
#else
        n = 1;
#endif
    }
    if (n < 1) n = 1;
    if (n > SFB__POOL_MAX_THREADS) n = SFB__POOL_MAX_THREADS;
#ifndef SFB__THREADS
    n = 1; /* no thread support known here: single-threaded */
#endif
    return (int)n;
}

#ifdef SFB__THREADS
/* Spinning before sleeping. A sleeping thread woken through its condition variable runs some
 * 30-60 us later on a virtual machine (measured on the 2-core CI VM: a run of 10000 items of
 * 8 ns lost 27 us to it, and a run of 2000 items was slower than one thread), while the core's
 * and the kernels' runs come back to back (an analysis makes about 30 per picture, an eval call
 * one): so an idle worker first spins a while (SFB__POOL_SPINS pauses, about 20-200 us by CPU)
 * watching the job counter, and so does a caller waiting for the last chunks, before either
 * sleeps. The counters are read without the lock there (GCC/Clang atomics; elsewhere no spinning:
 * the lock and the condition variables alone, as before). */
#if defined(__GNUC__) || defined(__clang__)
#  define SFB__POOL_SPIN 1
#  define SFB__POOL_SPINS 4096
static void sfb__pool_pause(void) {
#  if defined(__x86_64__) || defined(__i386__)
    __asm__ __volatile__("pause");
#  elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#  else
    __asm__ __volatile__("" ::: "memory");
#  endif
}
#endif

/* First row in [first, last) whose entries start at or after `e` (last when none). */
static int sfb__pool_row_at(const int *offsets, int first, int last, size_t e) {
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
static int sfb__pool_chunk_start(const sfb__pool *p, int c) {
    if (c <= 0) return p->first;
    if (c >= p->chunks) return p->last;
    if (!p->offsets) return p->first + (int)((long long)(p->last - p->first) * c / p->chunks);
    return sfb__pool_row_at(p->offsets, p->first, p->last, p->entry0 + p->entries / (size_t)p->chunks * (size_t)c);
}

/* Runs chunks of the current job until none is left to claim. Called and returns with
 * p->lock held. A worker that wakes late finds nothing to claim (or joins the next job):
 * the job is only touched between claiming a chunk and counting it done. */
static void sfb__pool_drain(sfb__pool *p) {
    while (p->next_chunk < p->chunks) {
        const int c = p->next_chunk++;
        const int a = sfb__pool_chunk_start(p, c), b = sfb__pool_chunk_start(p, c + 1);
        void (*task)(const void *, const void *, int, int) = p->task;
        const void *owner = p->owner, *arg = p->arg;
        pthread_mutex_unlock(&p->lock);
        if (a < b) task(owner, arg, a, b);
        pthread_mutex_lock(&p->lock);
#ifdef SFB__POOL_SPIN
        if (__atomic_add_fetch(&p->chunks_done, 1, __ATOMIC_RELEASE) == p->chunks) pthread_cond_signal(&p->done);
#else
        if (++p->chunks_done == p->chunks) pthread_cond_signal(&p->done);
#endif
    }
}

static void *sfb__pool_worker(void *arg) {
    sfb__pool *p = (sfb__pool *)arg;
    unsigned long seen = 0;
    pthread_mutex_lock(&p->lock);
    for (;;) {
#ifdef SFB__POOL_SPIN
        if (!p->quit && p->generation == seen) {
            int i;
            pthread_mutex_unlock(&p->lock);
            for (i = 0; i < SFB__POOL_SPINS && __atomic_load_n(&p->generation, __ATOMIC_ACQUIRE) == seen && !__atomic_load_n(&p->quit, __ATOMIC_ACQUIRE); ++i)
                sfb__pool_pause();
            pthread_mutex_lock(&p->lock);
        }
#endif
        while (!p->quit && p->generation == seen) pthread_cond_wait(&p->wake, &p->lock);
        if (p->quit) break;
        seen = p->generation;
        sfb__pool_drain(p);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}
#endif /* SFB__THREADS */

void sfb__pool_stop(sfb__pool *p) {
#ifdef SFB__THREADS
    int i;
    if (p->threads <= 1) return;
    pthread_mutex_lock(&p->lock);
#ifdef SFB__POOL_SPIN
    __atomic_store_n(&p->quit, 1, __ATOMIC_RELEASE);
#else
    p->quit = 1;
#endif
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    for (i = 0; i < p->workers; ++i) pthread_join(p->tid[i], NULL);
    p->workers = 0;
    pthread_cond_destroy(&p->done);
    pthread_cond_destroy(&p->wake);
    pthread_mutex_destroy(&p->lock);
    pthread_mutex_destroy(&p->busy);
#endif
    p->threads = 1;
}

int sfb__pool_start(sfb__pool *p, int threads, char *why, size_t why_size) {
#ifdef SFB__THREADS
    int i, e;
#endif
    memset(p, 0, sizeof *p);
    p->threads = threads < 1 ? 1 : threads;
#ifdef SFB__THREADS
    if (p->threads == 1) return 1;
    if (pthread_mutex_init(&p->busy, NULL) != 0) goto fail0;
    if (pthread_mutex_init(&p->lock, NULL) != 0) goto fail1;
    if (pthread_cond_init(&p->wake, NULL) != 0) goto fail2;
    if (pthread_cond_init(&p->done, NULL) != 0) goto fail3;
    for (i = 0; i < p->threads - 1; ++i) {
        e = pthread_create(&p->tid[i], NULL, sfb__pool_worker, p);
        if (e != 0) {
            snprintf(why, why_size, "could not start worker thread %d of %d: %s", i + 1, p->threads - 1, strerror(e));
            sfb__pool_stop(p); /* joins the i already running */
            return 0;
        }
        p->workers = i + 1;
    }
    return 1;
fail3:
    pthread_cond_destroy(&p->wake);
fail2:
    pthread_mutex_destroy(&p->lock);
fail1:
    pthread_mutex_destroy(&p->busy);
fail0:
    snprintf(why, why_size, "could not create the thread pool's locks");
    p->threads = 1;
    return 0;
#else
    (void)why; (void)why_size;
    p->threads = 1;
    return 1;
#endif
}

int sfb__pool_run(sfb__pool *p, void (*task)(const void *owner, const void *arg, int a, int b), const void *owner, const void *arg, int first,
                  int last, const int *offsets, size_t e0, size_t entries) {
#ifdef SFB__THREADS
    if (p->threads <= 1 || pthread_mutex_trylock(&p->busy) != 0) return 0;
    pthread_mutex_lock(&p->lock);
    p->task = task;
    p->owner = owner;
    p->arg = arg;
    p->offsets = offsets;
    p->first = first;
    p->last = last;
    p->entry0 = e0;
    p->entries = entries;
    p->chunks = 4 * p->threads; /* several per thread: a late or slow thread takes fewer */
    p->next_chunk = 0;
    p->chunks_done = 0;
#ifdef SFB__POOL_SPIN
    __atomic_store_n(&p->generation, p->generation + 1, __ATOMIC_RELEASE); /* spinning workers read it unlocked */
#else
    ++p->generation;
#endif
    pthread_cond_broadcast(&p->wake);
    sfb__pool_drain(p);
    /* wait for chunks still running on workers, not for workers still asleep */
#ifdef SFB__POOL_SPIN
    if (p->chunks_done < p->chunks) {
        int i;
        pthread_mutex_unlock(&p->lock);
        for (i = 0; i < SFB__POOL_SPINS && __atomic_load_n(&p->chunks_done, __ATOMIC_ACQUIRE) < p->chunks; ++i) sfb__pool_pause();
        pthread_mutex_lock(&p->lock);
    }
#endif
    while (p->chunks_done < p->chunks) pthread_cond_wait(&p->done, &p->lock);
    p->task = NULL;
    p->owner = NULL;
    p->arg = NULL;
    pthread_mutex_unlock(&p->lock);
    pthread_mutex_unlock(&p->busy);
    return 1;
#else
    (void)p; (void)task; (void)owner; (void)arg; (void)first; (void)last; (void)offsets; (void)e0; (void)entries;
    return 0;
#endif
}

/* The `parallel` slot's body for a backend that owns `p`: task(arg, a, b) over its chunks. */
typedef struct sfb__pool_lent {
    void (*task)(void *arg, int first, int last);
    void *arg;
} sfb__pool_lent;

static void sfb__pool_lent_task(const void *owner, const void *arg, int a, int b) {
    const sfb__pool_lent *l = (const sfb__pool_lent *)arg;
    (void)owner;
    l->task(l->arg, a, b);
}

int sfb__pool_lend(sfb__pool *p, void (*task)(void *arg, int first, int last), void *arg, int first, int last) {
    sfb__pool_lent l;
    if (!p || !task || first >= last) return 0;
    l.task = task;
    l.arg = arg;
    return sfb__pool_run(p, sfb__pool_lent_task, NULL, &l, first, last, NULL, 0, 0);
}
#line 1 "src/backend.c"
/* Backend registry: ordered probing, first that initialises wins, every attempt reported. */

static const char *const sfb__backend_names[SFB_BACKEND_KIND_COUNT_] = {"default", "ref", "simd", "gl", "osmesa"};

SFB_API const char *sfb_backend_kind_name(sfb_backend_kind kind) {
    if ((int)kind < 0 || kind >= SFB_BACKEND_KIND_COUNT_) return "unknown";
    return sfb__backend_names[kind];
}

static int sfb__strieq(const char *a, const char *b) {
    for (; *a && *b; ++a, ++b) {
        int ca = (*a >= 'A' && *a <= 'Z') ? *a + 32 : *a;
        int cb = (*b >= 'A' && *b <= 'Z') ? *b + 32 : *b;
        if (ca != cb) return 0;
    }
    return *a == *b;
}

SFB_API sfb_backend_kind sfb_backend_kind_parse(const char *name) {
    int i;
    if (!name) return SFB_BACKEND_DEFAULT;
    for (i = 1; i < SFB_BACKEND_KIND_COUNT_; ++i)
        if (sfb__strieq(name, sfb__backend_names[i])) return (sfb_backend_kind)i;
    return SFB_BACKEND_DEFAULT;
}

/* Optional backends live in backends/ (sfb_NAME.h), compiled in by SURFBLEND_NAME (see
 * sfb_internal.h). Those not compiled in report "not built in". A backend is its bind function:
 * it fills the named slots it implements in a zeroed table. */
static sfb__backend_bind_fn sfb__backend_binder(sfb_backend_kind kind) {
    switch (kind) {
    case SFB_BACKEND_REF: return sfb__ref_bind;
#ifdef SURFBLEND_SIMD
    case SFB_BACKEND_SIMD: return sfb__simd_bind;
#endif
#ifdef SURFBLEND_GL
    case SFB_BACKEND_GL: return sfb__gl_bind;
#endif
#ifdef SURFBLEND_OSMESA
    case SFB_BACKEND_OSMESA: return sfb__osmesa_bind;
#endif
    default: return NULL;
    }
}

/* The table of `kind` bound into `vt` (zeroed first); 0 when the backend is not built in. */
int sfb__backend_bind(sfb_backend_kind kind, sfb__backend_vtable *vt) {
    sfb__backend_bind_fn bind = sfb__backend_binder(kind);
    memset(vt, 0, sizeof *vt);
    if (!bind) return 0;
    bind(vt);
    return vt->name != NULL && vt->init != NULL && vt->shutdown != NULL;
}

static void sfb__report_add(sfb_context *ctx, const char *fmt, ...) {
    size_t used = strlen(ctx->report);
    va_list ap;
    if (used + 1 >= sizeof ctx->report) return;
    va_start(ap, fmt);
    vsnprintf(ctx->report + used, sizeof ctx->report - used, fmt, ap);
    va_end(ap);
}

static int sfb__try_backend(sfb_context *ctx, sfb_backend_kind kind) {
    sfb__backend_vtable table;
    const sfb__backend_vtable *vt = &table;
    char why[512];
    void *state = NULL;
    sfb_result r;
    if (!sfb__backend_bind(kind, &table)) {
        sfb__report_add(ctx, "%s: unavailable (not built in: define SURFBLEND_%s or SURFBLEND_ALL_BACKENDS with SURFBLEND_IMPLEMENTATION)\n",
                        sfb_backend_kind_name(kind), kind == SFB_BACKEND_SIMD ? "SIMD" : kind == SFB_BACKEND_GL ? "GL" : "OSMESA");
        sfb__log(ctx, SFB_LOG_INFO, "backend %s not built in, trying the next", sfb_backend_kind_name(kind));
        return 0;
    }
    why[0] = 0;
    r = vt->init(ctx, &state, why, sizeof why);
    if (r != SFB_SUCCESS) {
        sfb__report_add(ctx, "%s: unavailable (%s: %s)\n", vt->name, sfb_result_string(r), why[0] ? why : "no reason given");
        sfb__log(ctx, SFB_LOG_INFO, "backend %s failed to initialise (%s), trying the next", vt->name, why);
        return 0;
    }
    ctx->backend_vt = table;
    ctx->backend = vt = &ctx->backend_vt;
    ctx->backend_state = state;
    why[0] = 0;
    if (vt->describe) vt->describe(state, why, sizeof why);
    if (why[0]) sfb__report_add(ctx, "%s: selected (%s)\n", vt->name, why);
    else sfb__report_add(ctx, "%s: selected\n", vt->name);
    sfb__log(ctx, SFB_LOG_INFO, "backend %s selected%s%s", vt->name, why[0] ? ": " : "", why);
    return 1;
}

sfb_result sfb__select_backend(sfb_context *ctx, const char *env) {
    int i;
    ctx->report[0] = 0;
    sfb__backend_bind(SFB_BACKEND_REF, &ctx->ref_vt);
    if (env && *env) {
        sfb_backend_kind k = sfb_backend_kind_parse(env);
        if (k == SFB_BACKEND_DEFAULT) {
            sfb__report_add(ctx, "SURFBLEND_BACKEND=%.64s: unavailable (unknown backend name; known: ref, simd, gl, osmesa)\n", env);
            sfb__log(ctx, SFB_LOG_WARN, "SURFBLEND_BACKEND=%.64s names no backend; using the default order", env);
        } else if (sfb__try_backend(ctx, k)) {
            return SFB_SUCCESS;
        }
    }
    for (i = 0; i < ctx->order_count; ++i)
        if (sfb__try_backend(ctx, ctx->order[i])) return SFB_SUCCESS;
    return SFB_NO_BACKEND;
}

SFB_API const char *sfb_context_backend_name(const sfb_context *ctx) {
    return (ctx && ctx->backend) ? ctx->backend->name : "none";
}

SFB_API sfb_result sfb_context_backend_report(const sfb_context *ctx, char *buf, size_t size) {
    size_t n;
    if (!ctx || !buf || size == 0) return SFB_INVALID_ARGS;
    n = strlen(ctx->report);
    if (n >= size) {
        memcpy(buf, ctx->report, size - 1);
        buf[size - 1] = 0;
        return SFB_LIMIT_EXCEEDED;
    }
    memcpy(buf, ctx->report, n + 1);
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_context_backend_info(const sfb_context *ctx, char *buf, size_t size) {
    if (!ctx || !buf || size == 0) return SFB_INVALID_ARGS;
    buf[0] = 0;
    if (ctx->backend && ctx->backend->describe) ctx->backend->describe(ctx->backend_state, buf, size);
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_backend_probe(sfb_backend_kind kind, const sfb_context_config *config, char *info, size_t size) {
    sfb__backend_vtable vt;
    sfb_context_config c = config ? *config : sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_result r;
    if (!info || size == 0 || (int)kind <= SFB_BACKEND_DEFAULT || kind >= SFB_BACKEND_KIND_COUNT_) return SFB_INVALID_ARGS;
    info[0] = 0;
    if (!sfb__backend_bind(kind, &vt)) {
        snprintf(info, size, "not built in: define SURFBLEND_%s or SURFBLEND_ALL_BACKENDS with SURFBLEND_IMPLEMENTATION",
                 kind == SFB_BACKEND_SIMD ? "SIMD" : kind == SFB_BACKEND_GL ? "GL" : kind == SFB_BACKEND_OSMESA ? "OSMESA" : "REF");
        return SFB_BACKEND_UNAVAILABLE;
    }
    /* A context with this backend alone: the probe is a real initialisation. */
    c.backends = &kind;
    c.backend_count = 1;
    c.ignore_environment = 1;
    r = sfb__context_create_reporting(&c, &ctx, info, size);
    if (r != SFB_SUCCESS) return r == SFB_NO_BACKEND ? SFB_BACKEND_UNAVAILABLE : r;
    info[0] = 0;
    if (vt.describe) vt.describe(ctx->backend_state, info, size);
    sfb_context_destroy(ctx);
    return SFB_SUCCESS;
}

/* The manifold draw path (sfb_surface_draw_gl, sfb_gl_trim_texture) lives in backends/sfb_gl.h;
 * its parameters' defaults are here so that they exist in every build, and without the gl
 * backend the calls link and answer SFB_UNSUPPORTED. */
SFB_API sfb_gl_draw_params sfb_gl_draw_params_init(void) {
    sfb_gl_draw_params p;
    memset(&p, 0, sizeof p);
    p.rate = 16;
    p.mvp[0] = p.mvp[5] = p.mvp[10] = p.mvp[15] = 1.0f;
    p.normal_matrix[0] = p.normal_matrix[4] = p.normal_matrix[8] = 1.0f;
    p.light[2] = 1.0f;
    p.color[0] = p.color[1] = p.color[2] = 0.8f;
    p.color[3] = 1.0f;
    return p;
}
#ifndef SURFBLEND_GL
SFB_API sfb_result sfb_surface_draw_gl(const sfb_surface *surface, const sfb_gl_draw_params *params) {
    (void)params;
    if (!surface) return SFB_INVALID_ARGS;
    return sfb__error(surface->ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                      "sfb_surface_draw_gl: this build has no gl backend (define SURFBLEND_GL or SURFBLEND_ALL_BACKENDS)");
}
SFB_API sfb_result sfb_analysis_draw_gl(sfb_context *ctx, const sfb_analysis *analysis) {
    (void)analysis;
    if (!ctx) return SFB_INVALID_ARGS;
    return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                      "sfb_analysis_draw_gl: this build has no gl backend (define SURFBLEND_GL or SURFBLEND_ALL_BACKENDS)");
}
SFB_API sfb_result sfb_gl_trim_texture(sfb_context *ctx, const struct sfb_trim_mask *mask, unsigned int *texture) {
    (void)mask;
    if (texture) *texture = 0;
    if (!ctx) return SFB_INVALID_ARGS;
    return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                      "sfb_gl_trim_texture: this build has no gl backend (define SURFBLEND_GL or SURFBLEND_ALL_BACKENDS)");
}
#endif
#line 1 "src/backend_ref.c"
/* The `ref` backend: plain C, the numeric oracle. Float storage, double accumulation in
 * table order (row by row, entries in stored order). */

static sfb_result sfb__ref_init(sfb_context *ctx, void **state, char *why, size_t why_size) {
    (void)ctx; (void)why; (void)why_size;
    *state = NULL;
    return SFB_SUCCESS;
}

static void sfb__ref_shutdown(sfb_context *ctx, void *state) { (void)ctx; (void)state; }

sfb_result sfb__ref_eval_stencils(void *state, const sfb__stencils *t, void *handle, int first, int last,
                                         const float *src, sfb_buffer_desc sd, float *dst, sfb_buffer_desc dd) {
    int r, c, k;
    double acc[16];
    (void)state; (void)handle;
    if (sd.length != dd.length || sd.length <= 0 || sd.length > 16) return SFB_INVALID_ARGS;
    for (r = first; r < last; ++r) {
        const int *idx = t->indices + t->offsets[r];
        const float *w = t->weights + t->offsets[r];
        int n = t->sizes[r];
        float *out = dst + dd.offset + (size_t)r * dd.stride;
        for (c = 0; c < sd.length; ++c) acc[c] = 0.0;
        for (k = 0; k < n; ++k) {
            const float *in = src + sd.offset + (size_t)idx[k] * sd.stride;
            double wk = w[k];
            for (c = 0; c < sd.length; ++c) acc[c] += wk * in[c];
        }
        for (c = 0; c < sd.length; ++c) out[c] = (float)acc[c];
    }
    return SFB_SUCCESS;
}

/* Seed 001's blend N_B = normalize((1 - b^p) N_L + b^p N_S), in double (see the vtable). */
static void sfb__ref_unit3(double *v) {
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len > 0.0) { v[0] /= len; v[1] /= len; v[2] /= len; }
    else v[0] = v[1] = v[2] = 0.0;
}

sfb_result sfb__ref_finish_normals(void *state, int first, int last, const float *tu, const float *tv,
                                          const float *ns, const int *ns_index, const float *b, float p,
                                          float *out_blend, float *out_limit, float *out_sub) {
    int i, c;
    (void)state;
    for (i = first; i < last; ++i) {
        const float *a = tu + 3 * (size_t)i, *d = tv + 3 * (size_t)i;
        double L[3], S[3] = {0.0, 0.0, 0.0}, B[3];
        int k = ns_index ? ns_index[i] : -1;
        L[0] = (double)a[1] * d[2] - (double)a[2] * d[1];
        L[1] = (double)a[2] * d[0] - (double)a[0] * d[2];
        L[2] = (double)a[0] * d[1] - (double)a[1] * d[0];
        sfb__ref_unit3(L);
        if (k >= 0) {
            for (c = 0; c < 3; ++c) S[c] = ns[3 * (size_t)k + c];
            sfb__ref_unit3(S);
        }
        if (k >= 0 && b && b[i] > 0.0f) {
            double bp = pow((double)b[i], (double)p);
            for (c = 0; c < 3; ++c) B[c] = (1.0 - bp) * L[c] + bp * S[c];
            sfb__ref_unit3(B);
        } else {
            for (c = 0; c < 3; ++c) B[c] = L[c];
        }
        for (c = 0; c < 3; ++c) {
            out_blend[3 * (size_t)i + c] = (float)B[c];
            if (out_limit) out_limit[3 * (size_t)i + c] = (float)L[c];
            if (out_sub) out_sub[3 * (size_t)i + c] = (float)S[c];
        }
    }
    return SFB_SUCCESS;
}

/* Seed 003's shade kernel, item by item in double (the contract is sfb__shade_job's comment). */
static double sfb__sh_dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double sfb__sh_curvature(const sfb__shade_job *j, size_t i, const double *n) {
    double pu[3], pv[3], puu[3], puv[3], pvv[3], E, F, G, L, M, N, det, K, H;
    int c;
    for (c = 0; c < 3; ++c) {
        pu[c] = j->du[3 * i + c]; pv[c] = j->dv[3 * i + c];
        puu[c] = j->duu[3 * i + c]; puv[c] = j->duv[3 * i + c]; pvv[c] = j->dvv[3 * i + c];
    }
    E = sfb__sh_dot(pu, pu); F = sfb__sh_dot(pu, pv); G = sfb__sh_dot(pv, pv);
    L = sfb__sh_dot(puu, n); M = sfb__sh_dot(puv, n); N = sfb__sh_dot(pvv, n);
    det = E * G - F * F;
    if (!(det > 1e-30 * (E * G + 1e-300)) || !isfinite(det)) return NAN;
    K = (L * N - M * M) / det;
    H = -(E * N - 2.0 * F * M + G * L) / (2.0 * det); /* the sign: convex toward the viewer is > 0 */
    if (j->curvature == SFB_CURVATURE_GAUSSIAN) return K;
    if (j->curvature == SFB_CURVATURE_MEAN) return H;
    return fabs(H) + sqrt(H * H - K > 0.0 ? H * H - K : 0.0);
}
sfb_result sfb__ref_shade(void *state, const sfb__shade_job *j, int first, int last) {
    int q, c;
    (void)state;
    for (q = first; q < last; ++q) {
        size_t i = (size_t)q;
        double p[3], n[3], v[3], r[3], vl, vn, val = NAN, val2 = NAN;
        for (c = 0; c < 3; ++c) { p[c] = j->position[3 * i + c]; n[c] = j->normal[3 * i + c]; }
        if (j->ortho) for (c = 0; c < 3; ++c) v[c] = -j->fwd[c];
        else for (c = 0; c < 3; ++c) v[c] = j->eye[c] - p[c];
        vl = sqrt(sfb__sh_dot(v, v));
        if (vl > 0.0) for (c = 0; c < 3; ++c) v[c] /= vl;
        vn = sfb__sh_dot(v, n);
        /* the normal toward the viewer; the curvature's sign follows it (convex toward the eye: > 0) */
        if (vn < 0.0) { for (c = 0; c < 3; ++c) n[c] = -n[c]; vn = -vn; }
        for (c = 0; c < 3; ++c) r[c] = 2.0 * vn * n[c] - v[c];
        switch (j->mode) {
        case SFB_ANALYZE_REFLECTION:
        case SFB_ANALYZE_HIGHLIGHT: {
            const double *dir = j->mode == SFB_ANALYZE_REFLECTION ? r : n;
            double dm = sfb__sh_dot(dir, j->lm), ap[3], mu, x[3], a, b;
            if (!(fabs(dm) > 1e-9)) break;
            for (c = 0; c < 3; ++c) ap[c] = j->lc[c] - p[c];
            mu = sfb__sh_dot(ap, j->lm) / dm;
            if (j->mode == SFB_ANALYZE_REFLECTION && !(mu > 0.0)) break;
            for (c = 0; c < 3; ++c) x[c] = p[c] + mu * dir[c] - j->lc[c];
            a = (sfb__sh_dot(x, j->lu) / j->lsize[0] + 0.5) * j->periods[0];
            b = (sfb__sh_dot(x, j->lv) / j->lsize[1] + 0.5) * j->periods[1];
            if (j->mode == SFB_ANALYZE_REFLECTION && !(a >= 0.0 && a <= j->periods[0] && b >= 0.0 && b <= j->periods[1])) break;
            if (!(isfinite(a) && isfinite(b) && fabs(a) < 1e7 && fabs(b) < 1e7)) break;
            val = a; val2 = b;
            break;
        }
        case SFB_ANALYZE_ZEBRA: {
            double t = sfb__sh_dot(r, j->dir);
            t = t < -1.0 ? -1.0 : t > 1.0 ? 1.0 : t;
            val = j->periods[0] * acos(t) / SFB__PI;
            break;
        }
        case SFB_ANALYZE_CURVATURE: val = sfb__sh_curvature(j, i, n); break;
        default: val = sfb__sh_dot(n, j->dir); break; /* ISOPHOTE, NORMALS, SHADED */
        }
        j->value[i] = (float)val;
        if (j->value2) j->value2[i] = (float)val2;
    }
    return SFB_SUCCESS;
}

/* ---- seed 003's proxy raster (the contract is sfb__raster_job's comment) ---- */
int sfb__raster_setup(const sfb__raster_vertex *const S[3], int w, int h, double grow, sfb__raster_edges *t) {
    double minx, maxx, miny, maxy, inv;
    int k;
    t->area = (S[1]->x - S[0]->x) * (S[2]->y - S[0]->y) - (S[2]->x - S[0]->x) * (S[1]->y - S[0]->y);
    if (!(fabs(t->area) > 1e-12) || !isfinite(t->area)) return 0;
    minx = maxx = S[0]->x;
    miny = maxy = S[0]->y;
    for (k = 1; k < 3; ++k) {
        if (S[k]->x < minx) minx = S[k]->x;
        if (S[k]->x > maxx) maxx = S[k]->x;
        if (S[k]->y < miny) miny = S[k]->y;
        if (S[k]->y > maxy) maxy = S[k]->y;
    }
    t->x0 = (int)sfb__rclamp(ceil(minx - 0.5 - grow), 0.0, (double)w);
    t->x1 = (int)sfb__rclamp(floor(maxx - 0.5 + grow), -1.0, (double)w - 1.0);
    t->y0 = (int)sfb__rclamp(ceil(miny - 0.5 - grow), 0.0, (double)h);
    t->y1 = (int)sfb__rclamp(floor(maxy - 0.5 + grow), -1.0, (double)h - 1.0);
    inv = 1.0 / t->area;
    for (k = 0; k < 3; ++k) {
        const sfb__raster_vertex *p0 = S[(k + 1) % 3], *p1 = S[(k + 2) % 3];
        t->ea[k] = -(p1->y - p0->y) * inv;
        t->eb[k] = (p1->x - p0->x) * inv;
        t->ec[k] = ((p1->y - p0->y) * p0->x - (p1->x - p0->x) * p0->y) * inv;
    }
    return 1;
}

/* Triangles [first, last) of the job on rows [row0, row1); with zmax, each is first tested
 * against the largest depth per 8 pixels of the rows it spans (sfb__raster_job's hint). */
static void sfb__raster_range(const sfb__raster_job *j, int row0, int row1, int first, int last, const float *zmax) {
    const int nb = (j->w + 7) / 8;
    int i;
    for (i = first; i < last; ++i) {
        const int *tv = j->tri + 4 * (size_t)i;
        const sfb__raster_vertex *S[3];
        sfb__raster_edges t;
        double lo, hi, rea[3];
        int k, x, y;
        /* the box first: each band of rows scans every triangle */
        if (j->ybox && !((double)j->ybox[2 * (size_t)i + 1] - 0.5 >= (double)row0 && (double)j->ybox[2 * (size_t)i] - 0.5 <= (double)row1 - 1.0)) continue;
        for (k = 0; k < 3; ++k) S[k] = &j->vert[tv[k]];
        lo = hi = S[0]->y;
        for (k = 1; k < 3; ++k) {
            if (S[k]->y < lo) lo = S[k]->y;
            if (S[k]->y > hi) hi = S[k]->y;
        }
        /* no pixel centre of the rows: skipped before the set-up */
        if (!(hi - 0.5 >= (double)row0 && lo - 0.5 <= (double)row1 - 1.0)) continue;
        if (zmax) {
            /* hidden over its whole box: every pixel there holds a depth at or below the
             * triangle's smallest (the interpolated depth is never below its vertices'; the
             * margin covers rounding), so none would pass the depth test */
            double zl = S[0]->z, xl = S[0]->x, xh = S[0]->x;
            int ya, yb, ba, bb, b, hidden = 1;
            for (k = 1; k < 3; ++k) {
                if (S[k]->z < zl) zl = S[k]->z;
                if (S[k]->x < xl) xl = S[k]->x;
                if (S[k]->x > xh) xh = S[k]->x;
            }
            zl -= 1e-6 * fabs(zl);
            ya = (int)sfb__rclamp(ceil(lo - 0.5), (double)row0, (double)row1);
            yb = (int)sfb__rclamp(floor(hi - 0.5), (double)row0 - 1.0, (double)row1 - 1.0);
            ba = (int)sfb__rclamp(ceil(xl - 0.5), 0.0, (double)j->w) / 8;
            bb = (int)sfb__rclamp(floor(xh - 0.5), -8.0, (double)j->w - 1.0);
            bb = bb < 0 ? -1 : bb / 8;
            for (y = ya; y <= yb && hidden; ++y)
                for (b = ba; b <= bb; ++b)
                    if (!(zmax[(size_t)y * nb + b] <= zl)) { hidden = 0; break; }
            if (hidden) continue;
        }
        if (!sfb__raster_setup(S, j->w, j->h, 0.0, &t)) continue;
        if (t.y0 < row0) t.y0 = row0;
        if (t.y1 > row1 - 1) t.y1 = row1 - 1;
        for (k = 0; k < 3; ++k) rea[k] = t.ea[k] != 0.0 ? 1.0 / t.ea[k] : 0.0;
        for (y = t.y0; y <= t.y1; ++y) {
            const double py = y + 0.5;
            double e[3], xl = t.x0 - 1.0, xh = t.x1 + 1.0;
            int in = 0, xa, xb;
            /* the row's inside run from the edge functions' zeros (e_k = ea_k (x + 0.5) + c_k
             * >= 0: x >= or <= -c_k / ea_k - 0.5 by the sign of ea_k), a pixel wider on each
             * side against rounding; the pixels between are still tested one by one (a thin
             * triangle's box is mostly outside it: catmark_car's level-1 proxy at 1024 x 1024
             * visited 2.5M pixels for 0.76M inside) */
            for (k = 0; k < 3; ++k) {
                const double z0 = -(t.eb[k] * py + t.ec[k]) * rea[k] - 0.5;
                if (t.ea[k] > 0.0) { if (z0 > xl) xl = z0; }
                else if (t.ea[k] < 0.0) { if (z0 < xh) xh = z0; }
            }
            if (!(xl <= xh)) continue; /* (NaN bounds are never taken) */
            xa = (int)xl - 1; /* x0 - 1 <= xl <= xh <= x1 + 1: the casts are safe, xa below ceil(xl), xb above floor(xh) */
            xb = (int)xh + 1;
            if (xa < t.x0) xa = t.x0;
            if (xb > t.x1) xb = t.x1;
            /* the edge functions at the run's first pixel centre, then stepped by ea per pixel */
            for (k = 0; k < 3; ++k) e[k] = t.ea[k] * (xa + 0.5) + t.eb[k] * py + t.ec[k];
            for (x = xa; x <= xb; ++x, e[0] += t.ea[0], e[1] += t.ea[1], e[2] += t.ea[2]) {
                const size_t pix = (size_t)y * (size_t)j->w + (size_t)x;
                double b[3], den, inv, z;
                /* the inside pixels of a row are one run: the first outside one after it ends the row */
                if (!((e[0] >= 0.0) & (e[1] >= 0.0) & (e[2] >= 0.0))) { if (in) break; continue; }
                in = 1;
                b[0] = e[0]; b[1] = e[1]; b[2] = e[2];
                den = b[0] * S[0]->q + b[1] * S[1]->q + b[2] * S[2]->q;
                if (!(den > 0.0)) continue;
                inv = 1.0 / den;
                z = j->ortho ? b[0] * S[0]->z + b[1] * S[1]->z + b[2] * S[2]->z : inv;
                if (!(z < (double)j->depth[pix])) continue;
                for (k = 0; k < 3; ++k) b[k] *= S[k]->q * inv;
                j->depth[pix] = (float)z;
                j->face[pix] = tv[3];
                j->uv[2 * pix] = (float)sfb__rclamp(b[0] * S[0]->u + b[1] * S[1]->u + b[2] * S[2]->u, 0.0, 1.0);
                j->uv[2 * pix + 1] = (float)sfb__rclamp(b[0] * S[0]->v + b[1] * S[1]->v + b[2] * S[2]->v, 0.0, 1.0);
                if (j->apos) {
                    int c;
                    for (c = 0; c < 3; ++c) {
                        j->pos[3 * pix + c] = (float)(b[0] * j->apos[3 * (size_t)tv[0] + c] + b[1] * j->apos[3 * (size_t)tv[1] + c] +
                                                      b[2] * j->apos[3 * (size_t)tv[2] + c]);
                        j->nrm[3 * pix + c] = (float)(b[0] * j->anrm[3 * (size_t)tv[0] + c] + b[1] * j->anrm[3 * (size_t)tv[1] + c] +
                                                      b[2] * j->anrm[3 * (size_t)tv[2] + c]);
                    }
                }
            }
        }
    }
}

void sfb__raster_rows(const sfb__raster_job *j, int row0, int row1) {
    const int nf = j->zmax && j->nfront > 0 && j->nfront < j->ntri ? j->nfront : j->ntri;
    sfb__raster_range(j, row0, row1, 0, nf, NULL);
    if (nf < j->ntri) {
        /* the largest depth per 8 pixels of each row (+inf where one is empty), then the rest */
        const int nb = (j->w + 7) / 8;
        int y, b, x;
        for (y = row0; y < row1; ++y) {
            const float *d = j->depth + (size_t)y * (size_t)j->w;
            float *m = j->zmax + (size_t)y * (size_t)nb;
            for (b = 0; b < nb; ++b) {
                const int xe = 8 * b + 8 < j->w ? 8 * b + 8 : j->w;
                float mx = d[8 * b];
                for (x = 8 * b + 1; x < xe; ++x) mx = d[x] > mx ? d[x] : mx;
                m[b] = mx;
            }
        }
        sfb__raster_range(j, row0, row1, nf, j->ntri, j->zmax);
    }
}

sfb_result sfb__ref_raster(void *state, const sfb__raster_job *j) {
    (void)state;
    sfb__raster_rows(j, 0, j->h);
    return SFB_SUCCESS;
}

/* Every kernel (sfb__ref_eval_patches is in patches.c). */
void sfb__ref_bind(sfb__backend_vtable *vt) {
    vt->name = "ref";
    vt->kind = SFB_BACKEND_REF;
    vt->init = sfb__ref_init;
    vt->shutdown = sfb__ref_shutdown;
    vt->eval_stencils = sfb__ref_eval_stencils;
    vt->eval_patches = sfb__ref_eval_patches;
    vt->finish_normals = sfb__ref_finish_normals;
    vt->shade = sfb__ref_shade;
    vt->raster = sfb__ref_raster;
}
#line 1 "src/topology.c"
/* Topology of one level: adjacency, counter-clockwise ordering around manifold vertices,
 * boundary and non-manifold tags, vertex rules. */

void sfb__level_free(sfb_context *ctx, sfb__level *l) {
    sfb__free(ctx, l->fv_off); sfb__free(ctx, l->fv); sfb__free(ctx, l->fe); sfb__free(ctx, l->ev);
    sfb__free(ctx, l->ef_off); sfb__free(ctx, l->ef); sfb__free(ctx, l->ef_slot);
    sfb__free(ctx, l->vf_off); sfb__free(ctx, l->vf); sfb__free(ctx, l->vf_slot);
    sfb__free(ctx, l->ve_off); sfb__free(ctx, l->ve);
    sfb__free(ctx, l->es); sfb__free(ctx, l->vs);
    sfb__free(ctx, l->etag); sfb__free(ctx, l->vtag); sfb__free(ctx, l->vrule); sfb__free(ctx, l->fhole);
    memset(l, 0, sizeof *l);
}

/* OpenSubdiv's vertex rule: any vertex sharpness makes a corner; else by sharp edge count. */
int sfb__rule_from(float vertex_sharpness, int sharp_edge_count) {
    if (vertex_sharpness > 0.0f) return SFB__RULE_CORNER;
    if (sharp_edge_count > 2) return SFB__RULE_CORNER;
    return 1 << sharp_edge_count;
}

void sfb__level_compute_rules(sfb__level *l) {
    int v, i;
    for (v = 0; v < l->nv; ++v) {
        int sharp = 0;
        for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i) sharp += l->es[l->ve[i]] > 0.0f;
        l->vrule[v] = (unsigned char)sfb__rule_from(l->vs[v], sharp);
    }
}

/* Walk the faces around a manifold candidate; returns 1 and reorders vf/vf_slot/ve when the
 * faces form one fan (or one cycle). */
static int sfb__order_vertex(sfb__level *l, int v, int *tf, int *ts, int *te) {
    int f0 = l->vf_off[v], k = l->vf_off[v + 1] - f0;
    int e0 = l->ve_off[v], m = l->ve_off[v + 1] - e0;
    int i, start = -1, boundary = (m == k + 1);
    int f, slot, count = 0;
    if (k == 0) return 0;
    if (boundary) {
        /* start at the face whose outgoing edge (v -> next) is a boundary edge */
        for (i = 0; i < k; ++i) {
            int ff = l->vf[f0 + i], s = l->vf_slot[f0 + i];
            int eo = l->fe[l->fv_off[ff] + s];
            if (l->ef_off[eo + 1] - l->ef_off[eo] == 1) { start = i; break; }
        }
        if (start < 0) return 0;
    } else {
        start = 0;
    }
    f = l->vf[f0 + start];
    slot = l->vf_slot[f0 + start];
    for (;;) {
        int n = l->fv_off[f + 1] - l->fv_off[f];
        int eo = l->fe[l->fv_off[f] + slot];
        int ei = l->fe[l->fv_off[f] + (slot + n - 1) % n];
        int nf, a, b, g, gs = -1;
        if (count >= k) return 0;
        tf[count] = f; ts[count] = slot; te[count] = eo;
        ++count;
        a = l->ef_off[ei]; b = l->ef_off[ei + 1];
        if (b - a == 1) {
            if (!boundary) return 0;
            te[count] = ei;
            break;
        }
        g = l->ef[a] == f ? l->ef[a + 1] : l->ef[a];
        if (g == f) return 0;
        /* the slot of v in g */
        {
            int q, gn = l->fv_off[g + 1] - l->fv_off[g];
            for (q = 0; q < gn; ++q)
                if (l->fv[l->fv_off[g] + q] == v) { gs = q; break; }
        }
        if (gs < 0) return 0;
        nf = g;
        if (!boundary && nf == l->vf[f0 + start]) break;
        f = nf;
        slot = gs;
    }
    if (count != k) return 0;
    /* the walk visited k distinct faces; with no non-manifold edge their outgoing edges are
     * distinct too, so the count decides */
    if ((boundary ? count + 1 : count) != m) return 0;
    memcpy(l->vf + f0, tf, (size_t)k * sizeof(int));
    memcpy(l->vf_slot + f0, ts, (size_t)k * sizeof(int));
    memcpy(l->ve + e0, te, (size_t)m * sizeof(int));
    return 1;
}

sfb_result sfb__level_complete(sfb_context *ctx, sfb__level *l) {
    int v, f, e, i, maxval = 0;
    int *fill = NULL, *tf = NULL, *ts = NULL, *te = NULL;
    l->nfv = l->fv_off[l->nf];
    l->ef_off = (int *)sfb__calloc(ctx, (size_t)l->ne + 1, sizeof(int));
    l->ef = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    l->ef_slot = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    l->vf_off = (int *)sfb__calloc(ctx, (size_t)l->nv + 1, sizeof(int));
    l->vf = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    l->vf_slot = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    l->ve_off = (int *)sfb__calloc(ctx, (size_t)l->nv + 1, sizeof(int));
    l->ve = (int *)sfb__alloc(ctx, ((size_t)l->ne * 2 + 1) * sizeof(int));
    l->etag = (unsigned char *)sfb__calloc(ctx, (size_t)l->ne + 1, 1);
    l->vtag = (unsigned char *)sfb__calloc(ctx, (size_t)l->nv + 1, 1);
    l->vrule = (unsigned char *)sfb__calloc(ctx, (size_t)l->nv + 1, 1);
    if (!l->fhole) l->fhole = (unsigned char *)sfb__calloc(ctx, (size_t)l->nf + 1, 1);
    fill = (int *)sfb__calloc(ctx, (size_t)(l->nv > l->ne ? l->nv : l->ne) + 1, sizeof(int));
    if (!l->ef_off || !l->ef || !l->ef_slot || !l->vf_off || !l->vf || !l->vf_slot || !l->ve_off || !l->ve ||
        !l->etag || !l->vtag || !l->vrule || !l->fhole || !fill)
        goto oom;
    /* edge -> faces */
    for (i = 0; i < l->nfv; ++i) l->ef_off[l->fe[i] + 1]++;
    for (e = 0; e < l->ne; ++e) l->ef_off[e + 1] += l->ef_off[e];
    for (f = 0; f < l->nf; ++f)
        for (i = l->fv_off[f]; i < l->fv_off[f + 1]; ++i) {
            int ed = l->fe[i], at = l->ef_off[ed] + fill[ed]++;
            l->ef[at] = f;
            l->ef_slot[at] = i - l->fv_off[f];
        }
    /* vertex -> faces (face order) */
    for (i = 0; i < l->nfv; ++i) l->vf_off[l->fv[i] + 1]++;
    for (v = 0; v < l->nv; ++v) l->vf_off[v + 1] += l->vf_off[v];
    memset(fill, 0, sizeof(int) * (size_t)l->nv);
    for (f = 0; f < l->nf; ++f)
        for (i = l->fv_off[f]; i < l->fv_off[f + 1]; ++i) {
            int vv = l->fv[i], at = l->vf_off[vv] + fill[vv]++;
            l->vf[at] = f;
            l->vf_slot[at] = i - l->fv_off[f];
        }
    /* vertex -> edges (edge order) */
    for (e = 0; e < l->ne; ++e) { l->ve_off[l->ev[2 * e] + 1]++; l->ve_off[l->ev[2 * e + 1] + 1]++; }
    for (v = 0; v < l->nv; ++v) l->ve_off[v + 1] += l->ve_off[v];
    memset(fill, 0, sizeof(int) * (size_t)l->nv);
    for (e = 0; e < l->ne; ++e) {
        int a = l->ev[2 * e], b = l->ev[2 * e + 1];
        l->ve[l->ve_off[a] + fill[a]++] = e;
        l->ve[l->ve_off[b] + fill[b]++] = e;
    }
    /* edge tags: boundary (one face), non-manifold (more than two faces, two faces running the
     * same direction, or no face at all) */
    for (e = 0; e < l->ne; ++e) {
        int a = l->ef_off[e], n = l->ef_off[e + 1] - a;
        if (n == 1) l->etag[e] |= SFB__TAG_BOUNDARY;
        /* a degenerate edge (both ends the same vertex, from a face that repeats a vertex) is
         * non-manifold, as OpenSubdiv treats it */
        if (n == 0 || n > 2 || l->ev[2 * e] == l->ev[2 * e + 1]) l->etag[e] |= SFB__TAG_NONMANIFOLD;
        if (n == 2) {
            int f1 = l->ef[a], s1 = l->ef_slot[a], f2 = l->ef[a + 1], s2 = l->ef_slot[a + 1];
            if (l->fv[l->fv_off[f1] + s1] == l->fv[l->fv_off[f2] + s2]) l->etag[e] |= SFB__TAG_NONMANIFOLD;
        }
    }
    for (v = 0; v < l->nv; ++v) {
        int d = l->ve_off[v + 1] - l->ve_off[v];
        if (d > maxval) maxval = d;
    }
    tf = (int *)sfb__alloc(ctx, ((size_t)maxval + 2) * sizeof(int));
    ts = (int *)sfb__alloc(ctx, ((size_t)maxval + 2) * sizeof(int));
    te = (int *)sfb__alloc(ctx, ((size_t)maxval + 2) * sizeof(int));
    if (!tf || !ts || !te) goto oom;
    for (v = 0; v < l->nv; ++v) {
        int k = l->vf_off[v + 1] - l->vf_off[v], m = l->ve_off[v + 1] - l->ve_off[v];
        int nm = 0, bnd = 0;
        for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i) {
            if (l->etag[l->ve[i]] & SFB__TAG_NONMANIFOLD) nm = 1;
            if (l->etag[l->ve[i]] & SFB__TAG_BOUNDARY) bnd++;
        }
        if (bnd) l->vtag[v] |= SFB__TAG_BOUNDARY;
        if (nm || k == 0 || !((m == k && bnd == 0) || (m == k + 1 && bnd == 2)) || !sfb__order_vertex(l, v, tf, ts, te))
            l->vtag[v] |= SFB__TAG_NONMANIFOLD;
    }
    sfb__free(ctx, fill); sfb__free(ctx, tf); sfb__free(ctx, ts); sfb__free(ctx, te);
    return SFB_SUCCESS;
oom:
    sfb__free(ctx, fill); sfb__free(ctx, tf); sfb__free(ctx, ts); sfb__free(ctx, te);
    return sfb__oom(ctx, "building topology");
}

static void *sfb__dup(sfb_context *ctx, const void *p, size_t bytes) {
    void *q = sfb__alloc(ctx, bytes ? bytes : 1);
    if (q && bytes) memcpy(q, p, bytes);
    return q;
}

/* Applies OpenSubdiv's preparation of the base level: faces at uninterpolated boundaries
 * become holes (boundary NONE), boundary and non-manifold edges become infinitely sharp,
 * topological corners (EDGE_AND_CORNER) and non-manifold vertices infinitely sharp, except
 * a vertex on a non-manifold crease (two non-manifold edges, no boundary, more faces than
 * edges), which keeps its own sharpness. */
sfb_result sfb__level_prepare(sfb_context *ctx, const sfb__level *s, int sharpen_corners, int make_boundary_holes,
                              sfb__level *d) {
    int v, e, i;
    memset(d, 0, sizeof *d);
    d->nv = s->nv; d->nf = s->nf; d->ne = s->ne; d->nfv = s->nfv;
#define SFB__DUP(field, count, type) d->field = (type *)sfb__dup(ctx, s->field, (size_t)(count) * sizeof(type))
    SFB__DUP(fv_off, s->nf + 1, int); SFB__DUP(fv, s->nfv, int); SFB__DUP(fe, s->nfv, int);
    SFB__DUP(ev, 2 * s->ne, int); SFB__DUP(ef_off, s->ne + 1, int); SFB__DUP(ef, s->nfv, int);
    SFB__DUP(ef_slot, s->nfv, int); SFB__DUP(vf_off, s->nv + 1, int); SFB__DUP(vf, s->nfv, int);
    SFB__DUP(vf_slot, s->nfv, int); SFB__DUP(ve_off, s->nv + 1, int); SFB__DUP(ve, 2 * s->ne, int);
    SFB__DUP(es, s->ne, float); SFB__DUP(vs, s->nv, float); SFB__DUP(etag, s->ne, unsigned char);
    SFB__DUP(vtag, s->nv, unsigned char); SFB__DUP(vrule, s->nv, unsigned char); SFB__DUP(fhole, s->nf, unsigned char);
#undef SFB__DUP
    if (!d->fv_off || !d->fv || !d->fe || !d->ev || !d->ef_off || !d->ef || !d->ef_slot || !d->vf_off || !d->vf ||
        !d->vf_slot || !d->ve_off || !d->ve || !d->es || !d->vs || !d->etag || !d->vtag || !d->vrule || !d->fhole) {
        sfb__level_free(ctx, d);
        return sfb__oom(ctx, "copying topology");
    }
    if (make_boundary_holes) {
        for (v = 0; v < d->nv; ++v) {
            int k = d->vf_off[v + 1] - d->vf_off[v], m = d->ve_off[v + 1] - d->ve_off[v], exclude = 0;
            if (k == m && !(d->vtag[v] & SFB__TAG_NONMANIFOLD)) continue;
            for (i = d->ve_off[v]; i < d->ve_off[v + 1] && !exclude; ++i) {
                int ed = d->ve[i];
                exclude = (d->ef_off[ed + 1] - d->ef_off[ed] == 1) && d->es[ed] < SFB_SHARPNESS_INFINITE;
            }
            if (exclude)
                for (i = d->vf_off[v]; i < d->vf_off[v + 1]; ++i) d->fhole[d->vf[i]] = 1;
        }
    }
    for (e = 0; e < d->ne; ++e) {
        if (d->etag[e] & (SFB__TAG_BOUNDARY | SFB__TAG_NONMANIFOLD)) d->es[e] = SFB_SHARPNESS_INFINITE;
        if (d->es[e] > SFB_SHARPNESS_INFINITE) d->es[e] = SFB_SHARPNESS_INFINITE;
    }
    for (v = 0; v < d->nv; ++v) {
        int k = d->vf_off[v + 1] - d->vf_off[v], m = d->ve_off[v + 1] - d->ve_off[v];
        int nm_edges = 0, bnd_edges = 0;
        for (i = d->ve_off[v]; i < d->ve_off[v + 1]; ++i) {
            nm_edges += (d->etag[d->ve[i]] & SFB__TAG_NONMANIFOLD) != 0;
            bnd_edges += (d->etag[d->ve[i]] & SFB__TAG_BOUNDARY) != 0;
        }
        if (k == 1 && m == 2 && sharpen_corners) {
            d->vs[v] = SFB_SHARPNESS_INFINITE;
        } else if (d->vtag[v] & SFB__TAG_NONMANIFOLD) {
            if (!(nm_edges == 2 && bnd_edges == 0 && k > m)) d->vs[v] = SFB_SHARPNESS_INFINITE;
        }
        if (d->vs[v] > SFB_SHARPNESS_INFINITE) d->vs[v] = SFB_SHARPNESS_INFINITE;
    }
    sfb__level_compute_rules(d);
    return SFB_SUCCESS;
}

/* The end of edge e that is not v. */
int sfb__other_end(const sfb__level *l, int e, int v) {
    return l->ev[2 * e] == v ? l->ev[2 * e + 1] : l->ev[2 * e];
}
#line 1 "src/stencil.c"
/* The stencil algebra every table builder shares (declared in sfb_internal.h): composed rows
 * of double weights over source vertices (sfb__rows), local masks of (vertex, weight) pairs
 * (sfb__mask), the composition of a mask with its parents' rows through a dense accumulator
 * (sfb__compose_row), and the conversion of rows into a backend's float stencil table
 * (sfb__rows_to_stencils). Refinement (refine.c), shading (shade.c) and manifold blending
 * (manifold.c) build their tables with it; the patch builder (patch/build.c) takes only each
 * step's local masks. */

/* ---- composed rows (double weights) ---- */

void sfb__rows_free(sfb_context *ctx, sfb__rows *r) {
    sfb__free(ctx, r->off); sfb__free(ctx, r->idx); sfb__free(ctx, r->w);
    memset(r, 0, sizeof *r);
}

int sfb__rows_reserve(sfb_context *ctx, sfb__rows *r, size_t need) {
    size_t cap;
    int *ni;
    double *nw;
    if (need <= r->cap) return 1;
    cap = r->cap ? r->cap : 1024;
    while (cap < need) {
        if (cap > ((size_t)-1) / 4) return 0;
        cap = 2 * cap + 16; /* doubling: a table grown row by row is copied at most once over in all */
    }
    ni = (int *)sfb__realloc(ctx, r->idx, cap * sizeof(int));
    if (!ni) return 0;
    r->idx = ni;
    nw = (double *)sfb__realloc(ctx, r->w, cap * sizeof(double));
    if (!nw) return 0;
    r->w = nw;
    r->cap = cap;
    return 1;
}

/* ---- local masks: (parent vertex, weight) pairs, duplicates allowed ---- */


int sfb__mask_grow(sfb_context *ctx, sfb__mask *m, int need) {
    int cap;
    int *ni;
    double *nw;
    if (m->n + need <= m->cap) return 1;
    cap = (m->cap ? m->cap * 2 : 64);
    while (cap < m->n + need) cap *= 2;
    ni = (int *)sfb__realloc(ctx, m->idx, (size_t)cap * sizeof(int));
    if (!ni) return 0;
    m->idx = ni;
    nw = (double *)sfb__realloc(ctx, m->w, (size_t)cap * sizeof(double));
    if (!nw) return 0;
    m->w = nw;
    m->cap = cap;
    return 1;
}


/* Adds w * (face centroid of f). */
void sfb__mask_face(sfb__mask *m, const sfb__level *l, int f, double w) {
    int i, n = l->fv_off[f + 1] - l->fv_off[f];
    for (i = 0; i < n; ++i) SFB__MASK_ADD(m, l->fv[l->fv_off[f] + i], w / n);
}

int sfb__mask_need_vertex(const sfb__level *l, int v) {
    int need = 1 + 2 * (l->ve_off[v + 1] - l->ve_off[v]), i;
    for (i = l->vf_off[v]; i < l->vf_off[v + 1]; ++i) need += l->fv_off[l->vf[i] + 1] - l->fv_off[l->vf[i]];
    return need;
}

/* Composes local masks with the parent's composed rows using a dense accumulator. */


int sfb__compose_row(sfb_context *ctx, sfb__accum *A, const sfb__rows *prow, const sfb__mask *m, sfb__rows *out, int row) {
    int i, nt = 0;
    size_t k;
    A->stamp++;
    if (A->stamp == 0) return 0; /* wrapped: caller resets */
    for (i = 0; i < m->n; ++i) {
        int j = m->idx[i];
        double wj = m->w[i];
        if (wj == 0.0) continue;
        for (k = prow->off[j]; k < prow->off[j + 1]; ++k) {
            int b = prow->idx[k];
            if (A->mark[b] != A->stamp) { A->mark[b] = A->stamp; A->acc[b] = 0.0; A->touched[nt++] = b; }
            A->acc[b] += wj * prow->w[k];
        }
    }
    if (!sfb__rows_reserve(ctx, out, out->n + (size_t)nt)) return 0;
    for (i = 0; i < nt; ++i) {
        int b = A->touched[i];
        if (A->acc[b] == 0.0) continue;
        out->idx[out->n] = b;
        out->w[out->n] = A->acc[b];
        out->n++;
    }
    out->off[row + 1] = out->n;
    return 1;
}

/* Appends local mask m as row `row` of out: what sfb__compose_row gives over identity rows
 * (entries in the order of first use, duplicates summed in mask order, zero weights and zero
 * sums dropped) without an accumulator over the sources. Masks are short: the merge is a
 * linear search. */
int sfb__rows_append_mask(sfb_context *ctx, sfb__rows *out, const sfb__mask *m, int row) {
    const size_t at = out->n;
    size_t k, j;
    int i;
    if (!sfb__rows_reserve(ctx, out, out->n + (size_t)m->n)) return 0;
    for (i = 0; i < m->n; ++i) {
        if (m->w[i] == 0.0) continue;
        for (k = at; k < out->n && out->idx[k] != m->idx[i]; ++k) {}
        if (k < out->n) {
            out->w[k] += m->w[i];
        } else {
            out->idx[out->n] = m->idx[i];
            out->w[out->n] = 0.0 + m->w[i];
            out->n++;
        }
    }
    for (j = k = at; k < out->n; ++k)
        if (out->w[k] != 0.0) { out->idx[j] = out->idx[k]; out->w[j] = out->w[k]; ++j; }
    out->n = j;
    out->off[row + 1] = out->n;
    return 1;
}

void sfb__stencils_free(sfb_context *ctx, sfb__stencils *s) {
    sfb__free(ctx, s->sizes); sfb__free(ctx, s->offsets); sfb__free(ctx, s->indices); sfb__free(ctx, s->weights);
    memset(s, 0, sizeof *s);
}

/* The row index of a stencil table from rows r (rows, sources, entries, sizes, offsets with the
 * end marker); the indices and weights are the caller's. 0 when out of memory (s freed). */
static int sfb__stencils_index(sfb_context *ctx, const sfb__rows *r, int sources, sfb__stencils *s) {
    int i;
    s->rows = r->rows;
    s->sources = sources;
    s->entries = r->n;
    s->sizes = (int *)sfb__alloc(ctx, ((size_t)r->rows + 1) * sizeof(int));
    s->offsets = (int *)sfb__alloc(ctx, ((size_t)r->rows + 1) * sizeof(int));
    if (!s->sizes || !s->offsets) {
        sfb__stencils_free(ctx, s);
        return 0;
    }
    for (i = 0; i < r->rows; ++i) {
        s->offsets[i] = (int)r->off[i];
        s->sizes[i] = (int)(r->off[i + 1] - r->off[i]);
    }
    s->offsets[r->rows] = (int)r->n; /* end marker: offsets[rows] == entries */
    s->sizes[r->rows] = 0;
    return 1;
}

/* sfb__rows_to_stencils for rows the caller frees next: the table takes over their blocks. The
 * indices are the rows' own (an int array either way); the weights are narrowed to float in
 * place, into the first half of the doubles' block (value k goes to bytes [4k, 4k+4), which hold
 * only doubles already read: those below k/2 + 1), through memcpy so that no store can be
 * moved before a load it overlaps; both blocks are then shrunk. Fresh tables of the same size
 * cost page faults and a copy: at catmark_car level 3 these tables are tens of megabytes.
 * On failure r is left as it was. */
sfb_result sfb__rows_move_to_stencils(sfb_context *ctx, sfb__rows *r, int sources, sfb__stencils *s) {
    unsigned char *wb = (unsigned char *)r->w;
    size_t k;
    void *p;
    memset(s, 0, sizeof *s);
    if (r->n > 0x7fffffff)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "stencil table of %zu entries is over the limit", r->n);
    if (!r->idx || !r->w) return sfb__rows_to_stencils(ctx, r, sources, s);
    if (!sfb__stencils_index(ctx, r, sources, s)) return SFB_OUT_OF_MEMORY;
    for (k = 0; k < r->n; ++k) {
        double d;
        float f;
        memcpy(&d, wb + 8 * k, sizeof d);
        f = (float)d;
        memcpy(wb + 4 * k, &f, sizeof f);
    }
    p = sfb__realloc(ctx, r->w, (r->n + 1) * sizeof(float));
    s->weights = p ? (float *)p : (float *)(void *)r->w;
    p = sfb__realloc(ctx, r->idx, (r->n + 1) * sizeof(int));
    s->indices = p ? (int *)p : r->idx;
    r->w = NULL;
    r->idx = NULL;
    r->n = r->cap = 0;
    return SFB_SUCCESS;
}

sfb_result sfb__rows_to_stencils(sfb_context *ctx, const sfb__rows *r, int sources, sfb__stencils *s) {
    size_t k;
    memset(s, 0, sizeof *s);
    if (r->n > 0x7fffffff)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "stencil table of %zu entries is over the limit", r->n);
    if (!sfb__stencils_index(ctx, r, sources, s)) return SFB_OUT_OF_MEMORY;
    s->indices = (int *)sfb__alloc(ctx, (r->n + 1) * sizeof(int));
    s->weights = (float *)sfb__alloc(ctx, (r->n + 1) * sizeof(float));
    if (!s->indices || !s->weights) {
        sfb__stencils_free(ctx, s);
        return SFB_OUT_OF_MEMORY;
    }
    if (r->n) memcpy(s->indices, r->idx, r->n * sizeof(int));
    for (k = 0; k < r->n; ++k) s->weights[k] = (float)r->w[k];
    return SFB_SUCCESS;
}
#line 1 "src/refine.c"
/* Uniform refinement: Catmull-Clark, Loop and bilinear with semi-sharp creases (DeRose et al.,
 * with OpenSubdiv 3.5's rules: fractional edge/vertex blending, uniform or Chaikin sharpness
 * decay, TRI_SUB_SMOOTH), compiled into stencil tables from the base vertices straight to the
 * last level, plus limit position and limit tangent tables at the last level's vertices.
 *
 * Child vertex order: children of vertices (same order), then of faces (Catmull-Clark and
 * bilinear only), then of edges. Child faces: for Catmull-Clark/bilinear face (v0..vn-1), the
 * quads (Vi, Ei, F, Ei-1) for i = 0..n-1; for Loop triangle (v0,v1,v2) the corners
 * (Vi, Ei, Ei-1) and then the middle (E0, E1, E2). Child edges: the two halves of each parent
 * edge (the half at its first vertex first), then the edges inside each face. */

/* ---- sharpness arithmetic, in float exactly as OpenSubdiv's Sdc::Crease ---- */
static float sfb__decrement(float s) {
    if (s <= 0.0f) return 0.0f;
    if (s >= SFB_SHARPNESS_INFINITE) return SFB_SHARPNESS_INFINITE;
    if (s > 1.0f) return s - 1.0f;
    return 0.0f;
}

static float sfb__sub_edge_at_vertex(float s, int chaikin, int vertex_edges, float semi_sum, int semi_count) {
    if (!chaikin || vertex_edges < 2) return sfb__decrement(s);
    if (s <= 0.0f) return 0.0f;
    if (s >= SFB_SHARPNESS_INFINITE) return SFB_SHARPNESS_INFINITE;
    if (semi_count > 1) {
        float avg = (semi_sum - s) / (float)(semi_count - 1);
        s = (0.75f * s) + (0.25f * avg);
    }
    s -= 1.0f;
    return s > 0.0f ? s : 0.0f;
}

/* The crease pair of a vertex: first and last incident edge with sharpness > 0 in the
 * vertex's edge order (OpenSubdiv's GetSharpEdgePairOfCrease). `sharp` is per incident edge. */
void sfb__crease_pair(const float *sharp, int n, int *a, int *b) {
    int i = 0, j = n - 1;
    while (i < n - 1 && sharp[i] <= 0.0f) ++i;
    while (j > 0 && sharp[j] <= 0.0f) --j;
    *a = i;
    *b = j;
}

/* Adds w * (vertex-vertex mask of `rule`) for vertex v; `sharp` holds the sharpness of v's
 * incident edges in ve order (parent or child values, as the rule requires). */
static void sfb__mask_vertex_rule(sfb__mask *m, const sfb__level *l, int v, int rule, const float *sharp,
                                  sfb_scheme scheme, double w) {
    int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0;
    int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0;
    int i;
    if (w == 0.0) return;
    if (rule == SFB__RULE_CORNER) {
        SFB__MASK_ADD(m, v, w);
        return;
    }
    if (rule == SFB__RULE_CREASE) {
        int a, b;
        sfb__crease_pair(sharp, ne, &a, &b);
        SFB__MASK_ADD(m, v, 0.75 * w);
        SFB__MASK_ADD(m, sfb__other_end(l, l->ve[e0 + a], v), 0.125 * w);
        SFB__MASK_ADD(m, sfb__other_end(l, l->ve[e0 + b], v), 0.125 * w);
        return;
    }
    /* smooth or dart: needs a manifold interior neighbourhood (guaranteed by sharpening:
     * boundary and non-manifold features are never smooth); guard anyway */
    if (nf != ne || nf == 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD)) {
        SFB__MASK_ADD(m, v, w);
        return;
    }
    if (scheme == SFB_SCHEME_LOOP) {
        double ew, vw;
        if (nf == 6) {
            ew = 0.0625;
            vw = 0.625;
        } else {
            double beta = 0.25 * cos(2.0 * SFB__PI / nf) + 0.375;
            ew = (0.625 - beta * beta) / nf;
            vw = 1.0 - ew * nf;
        }
        SFB__MASK_ADD(m, v, vw * w);
        for (i = 0; i < ne; ++i) SFB__MASK_ADD(m, sfb__other_end(l, l->ve[e0 + i], v), ew * w);
    } else {
        double n = nf, fw = 1.0 / (n * n);
        SFB__MASK_ADD(m, v, (n - 2.0) / n * w);
        for (i = 0; i < ne; ++i) SFB__MASK_ADD(m, sfb__other_end(l, l->ve[e0 + i], v), fw * w);
        for (i = 0; i < nf; ++i) sfb__mask_face(m, l, l->vf[f0 + i], fw * w);
    }
}

/* OpenSubdiv's Crease::ComputeFractionalWeightAtVertex. */
static float sfb__fractional_weight(float pvs, float cvs, int n, const float *ps, const float *cs, int chaikin) {
    int count = 0, i;
    float sum = 0.0f, fw;
    if (pvs > 0.0f && cvs <= 0.0f) { count = 1; sum = pvs; }
    for (i = 0; i < n; ++i) {
        int transition = chaikin ? (ps[i] > 0.0f && cs[i] <= 0.0f) : (ps[i] > 0.0f && ps[i] <= 1.0f);
        if (transition) { sum += ps[i]; count++; }
    }
    if (!count) return 0.0f;
    fw = sum / (float)count;
    return fw > 1.0f ? 1.0f : fw;
}

/* ---- one refinement step ---- */
typedef struct sfb__step {
    sfb_context *ctx;
    const sfb__refine_options *opt;
    const sfb__level *p;
    sfb__level *c;
    float *half;           /* child sharpness of each parent edge half: [2e + side] */
} sfb__step;

static int sfb__half_at(const sfb__level *p, int e, int v) { return p->ev[2 * e] == v ? 0 : 1; }

static sfb_result sfb__build_child_topology(sfb__step *st) {
    sfb_context *ctx = st->ctx;
    const sfb__level *p = st->p;
    sfb__level *c = st->c;
    int loop = st->opt->scheme == SFB_SCHEME_LOOP;
    int nvF = loop ? 0 : p->nf;               /* face-children count */
    int vE = p->nv + nvF;                     /* first edge-child */
    int f, i, e, v;
    size_t nf64, nfv64, ne64, nv64;
    int chaikin = st->opt->crease_method == SFB_CREASE_CHAIKIN;
    float *semi_sum = NULL;
    int *semi_cnt = NULL;

    nv64 = (size_t)p->nv + (size_t)nvF + (size_t)p->ne;
    if (loop) { nf64 = (size_t)p->nf * 4; nfv64 = nf64 * 3; ne64 = (size_t)p->ne * 2 + (size_t)p->nf * 3; }
    else { nf64 = (size_t)p->nfv; nfv64 = nf64 * 4; ne64 = (size_t)p->ne * 2 + (size_t)p->nfv; }
    if (nv64 > SFB_MAX_ELEMENTS || nfv64 > SFB_MAX_ELEMENTS || ne64 > SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "refined mesh would have %zu face-vertices, over the limit of %d", nfv64, SFB_MAX_ELEMENTS);
    memset(c, 0, sizeof *c);
    c->nv = (int)nv64; c->nf = (int)nf64; c->ne = (int)ne64; c->nfv = (int)nfv64;
    c->fv_off = (int *)sfb__alloc(ctx, (nf64 + 1) * sizeof(int));
    c->fv = (int *)sfb__alloc(ctx, (nfv64 + 1) * sizeof(int));
    c->fe = (int *)sfb__alloc(ctx, (nfv64 + 1) * sizeof(int));
    c->ev = (int *)sfb__alloc(ctx, (ne64 * 2 + 1) * sizeof(int));
    c->es = (float *)sfb__calloc(ctx, ne64 + 1, sizeof(float));
    c->vs = (float *)sfb__calloc(ctx, nv64 + 1, sizeof(float));
    c->fhole = (unsigned char *)sfb__calloc(ctx, nf64 + 1, 1);
    st->half = (float *)sfb__alloc(ctx, ((size_t)p->ne * 2 + 1) * sizeof(float));
    semi_sum = (float *)sfb__calloc(ctx, (size_t)p->nv + 1, sizeof(float));
    semi_cnt = (int *)sfb__calloc(ctx, (size_t)p->nv + 1, sizeof(int));
    if (!c->fv_off || !c->fv || !c->fe || !c->ev || !c->es || !c->vs || !c->fhole || !st->half || !semi_sum || !semi_cnt) {
        sfb__free(ctx, semi_sum); sfb__free(ctx, semi_cnt);
        return SFB_OUT_OF_MEMORY;
    }
    /* edge sharpness of the two halves of each parent edge */
    if (chaikin) {
        for (v = 0; v < p->nv; ++v)
            for (i = p->ve_off[v]; i < p->ve_off[v + 1]; ++i) {
                float s = p->es[p->ve[i]];
                if (s > 0.0f && s < SFB_SHARPNESS_INFINITE) { semi_sum[v] += s; semi_cnt[v]++; }
            }
    }
    for (e = 0; e < p->ne; ++e) {
        int side;
        for (side = 0; side < 2; ++side) {
            int pv = p->ev[2 * e + side];
            st->half[2 * e + side] = sfb__sub_edge_at_vertex(p->es[e], chaikin, p->ve_off[pv + 1] - p->ve_off[pv],
                                                             semi_sum[pv], semi_cnt[pv]);
        }
        c->ev[4 * e + 0] = p->ev[2 * e];
        c->ev[4 * e + 1] = vE + e;
        c->ev[4 * e + 2] = vE + e;
        c->ev[4 * e + 3] = p->ev[2 * e + 1];
        c->es[2 * e] = st->half[2 * e];
        c->es[2 * e + 1] = st->half[2 * e + 1];
    }
    sfb__free(ctx, semi_sum);
    sfb__free(ctx, semi_cnt);
    for (v = 0; v < p->nv; ++v) c->vs[v] = sfb__decrement(p->vs[v]);
    /* faces and interior edges */
    if (loop) {
        for (f = 0; f < p->nf; ++f) {
            int o = p->fv_off[f], ie = 2 * p->ne + 3 * f;
            for (i = 0; i < 3; ++i) {
                int cf = 4 * f + i, ip = (i + 2) % 3;
                int vi = p->fv[o + i], ei = p->fe[o + i], ep = p->fe[o + ip];
                c->fv_off[cf] = 3 * cf;
                c->fv[3 * cf + 0] = vi;
                c->fv[3 * cf + 1] = vE + ei;
                c->fv[3 * cf + 2] = vE + ep;
                c->fe[3 * cf + 0] = 2 * ei + sfb__half_at(p, ei, vi);
                c->fe[3 * cf + 1] = ie + i;
                c->fe[3 * cf + 2] = 2 * ep + sfb__half_at(p, ep, vi);
                c->ev[2 * (ie + i)] = vE + ei;
                c->ev[2 * (ie + i) + 1] = vE + ep;
                c->fhole[cf] = p->fhole[f];
            }
            {
                int cf = 4 * f + 3;
                c->fv_off[cf] = 3 * cf;
                for (i = 0; i < 3; ++i) {
                    c->fv[3 * cf + i] = vE + p->fe[o + i];
                    c->fe[3 * cf + i] = ie + (i + 1) % 3;
                }
                c->fhole[cf] = p->fhole[f];
            }
        }
        c->fv_off[c->nf] = c->nfv;
    } else {
        for (f = 0; f < p->nf; ++f) {
            int o = p->fv_off[f], n = p->fv_off[f + 1] - o, ie = 2 * p->ne + o;
            for (i = 0; i < n; ++i) {
                int cf = o + i, ip = (i + n - 1) % n;
                int vi = p->fv[o + i], ei = p->fe[o + i], ep = p->fe[o + ip];
                c->fv_off[cf] = 4 * cf;
                c->fv[4 * cf + 0] = vi;
                c->fv[4 * cf + 1] = vE + ei;
                c->fv[4 * cf + 2] = p->nv + f;
                c->fv[4 * cf + 3] = vE + ep;
                c->fe[4 * cf + 0] = 2 * ei + sfb__half_at(p, ei, vi);
                c->fe[4 * cf + 1] = ie + i;
                c->fe[4 * cf + 2] = ie + ip;
                c->fe[4 * cf + 3] = 2 * ep + sfb__half_at(p, ep, vi);
                c->ev[2 * (ie + i)] = vE + ei;
                c->ev[2 * (ie + i) + 1] = p->nv + f;
                c->fhole[cf] = p->fhole[f];
            }
        }
        c->fv_off[c->nf] = c->nfv;
    }
    {
        sfb_result r = sfb__level_complete(ctx, c);
        if (r != SFB_SUCCESS) return r;
    }
    sfb__level_compute_rules(c);
    return SFB_SUCCESS;
}

/* Local mask of child vertex `cv` in terms of parent vertices. */
static int sfb__child_mask(sfb__step *st, int cv, sfb__mask *m, float *ps, float *cs) {
    sfb_context *ctx = st->ctx;
    const sfb__level *p = st->p;
    const sfb__level *c = st->c;
    sfb_scheme scheme = st->opt->scheme;
    int loop = scheme == SFB_SCHEME_LOOP;
    int linear = scheme == SFB_SCHEME_BILINEAR || st->opt->linear;
    int nvF = loop ? 0 : p->nf;
    int i;
    m->n = 0;
    if (cv < p->nv) {
        /* vertex child */
        int v = cv, prule = p->vrule[v], crule = c->vrule[cv];
        int e0 = p->ve_off[v], ne = p->ve_off[v + 1] - e0;
        if (!sfb__mask_grow(ctx, m, 2 * sfb__mask_need_vertex(p, v) + 2)) return 0;
        if (linear) { SFB__MASK_ADD(m, v, 1.0); return 1; }
        for (i = 0; i < ne; ++i) {
            int e = p->ve[e0 + i];
            ps[i] = p->es[e];
            cs[i] = st->half[2 * e + sfb__half_at(p, e, v)];
        }
        if (prule == SFB__RULE_SMOOTH || prule == SFB__RULE_DART) {
            sfb__mask_vertex_rule(m, p, v, SFB__RULE_SMOOTH, ps, scheme, 1.0);
        } else if (crule == prule) {
            sfb__mask_vertex_rule(m, p, v, prule, ps, scheme, 1.0);
        } else {
            double pw = sfb__fractional_weight(p->vs[v], c->vs[cv], ne, ps, cs,
                                               st->opt->crease_method == SFB_CREASE_CHAIKIN);
            sfb__mask_vertex_rule(m, p, v, prule, ps, scheme, pw);
            sfb__mask_vertex_rule(m, p, v, crule == SFB__RULE_DART ? SFB__RULE_SMOOTH : crule, cs, scheme, 1.0 - pw);
        }
        return 1;
    }
    if (cv < p->nv + nvF) {
        int f = cv - p->nv, n = p->fv_off[f + 1] - p->fv_off[f];
        if (!sfb__mask_grow(ctx, m, n)) return 0;
        sfb__mask_face(m, p, f, 1.0);
        return 1;
    }
    {
        int e = cv - p->nv - nvF;
        int a = p->ev[2 * e], b = p->ev[2 * e + 1];
        int f0 = p->ef_off[e], nf = p->ef_off[e + 1] - f0;
        float s = p->es[e];
        double pw, cw;
        int need = 2;
        for (i = 0; i < nf; ++i) need += p->fv_off[p->ef[f0 + i] + 1] - p->fv_off[p->ef[f0 + i]];
        if (!sfb__mask_grow(ctx, m, need + 2)) return 0;
        if (linear || (s > 0.0f && c->vrule[cv] == SFB__RULE_CREASE)) {
            SFB__MASK_ADD(m, a, 0.5);
            SFB__MASK_ADD(m, b, 0.5);
            return 1;
        }
        /* smooth mask, blended with the midpoint by the parent sharpness when 0 < s */
        pw = s > 0.0f ? (double)s : 0.0;
        cw = 1.0 - pw;
        if (pw != 0.0) {
            SFB__MASK_ADD(m, a, 0.5 * pw);
            SFB__MASK_ADD(m, b, 0.5 * pw);
        }
        if (loop) {
            double vw = 0.375, fw = nf == 2 ? 0.125 : 0.125 * 2.0 / (nf ? nf : 1);
            SFB__MASK_ADD(m, a, vw * cw);
            SFB__MASK_ADD(m, b, vw * cw);
            for (i = 0; i < nf; ++i) {
                int f = p->ef[f0 + i], slot = p->ef_slot[f0 + i], o = p->fv_off[f];
                int n = p->fv_off[f + 1] - o;
                SFB__MASK_ADD(m, p->fv[o + (slot + 2) % n], fw * cw);
            }
        } else {
            double vw = 0.25, fw0 = 0.25, fw1 = 0.25;
            int tri = st->opt->triangle_rule == SFB_TRI_SMOOTH && nf == 2;
            if (tri) {
                int n0 = p->fv_off[p->ef[f0] + 1] - p->fv_off[p->ef[f0]];
                int n1 = p->fv_off[p->ef[f0 + 1] + 1] - p->fv_off[p->ef[f0 + 1]];
                tri = (n0 == 3) || (n1 == 3);
                if (tri) {
                    /* OpenSubdiv's CATMARK_SMOOTH_TRI_EDGE_WEIGHT, in float as it computes it */
                    float t0 = n0 == 3 ? 0.470f : 0.25f, t1 = n1 == 3 ? 0.470f : 0.25f;
                    float fw = 0.5f * (t0 + t1);
                    fw0 = fw1 = fw;
                    vw = 0.5f * (1.0f - 2.0f * fw);
                }
            }
            SFB__MASK_ADD(m, a, vw * cw);
            SFB__MASK_ADD(m, b, vw * cw);
            if (nf == 2) {
                sfb__mask_face(m, p, p->ef[f0], fw0 * cw);
                sfb__mask_face(m, p, p->ef[f0 + 1], fw1 * cw);
            } else {
                for (i = 0; i < nf; ++i) sfb__mask_face(m, p, p->ef[f0 + i], 0.5 / nf * cw);
            }
        }
        return 1;
    }
}

/* One step: refines `p` (whose vertices have composed rows `prow`) into `c`, with the
 * composed rows of c's vertices in `crow`. Progress is reported from p0 over a span of dp. */
sfb_result sfb__refine_step(sfb_context *ctx, const sfb__refine_options *opt, const sfb__level *p, const sfb__rows *prow,
                                   sfb__level *c, sfb__rows *crow, sfb__accum *A, sfb__mask *m, float *ps, float *cs,
                                   float p0, float dp) {
    return sfb__refine_step_local(ctx, opt, p, prow, c, crow, NULL, A, m, ps, cs, p0, dp);
}

/* sfb__refine_step that also gives the step's own rows (each child over the parent's
 * vertices: its local mask, duplicates merged) in `local` when that is not NULL. With prow
 * NULL (and local given) only the local rows are made: crow and A are not read. */
sfb_result sfb__refine_step_local(sfb_context *ctx, const sfb__refine_options *opt, const sfb__level *p, const sfb__rows *prow,
                                  sfb__level *c, sfb__rows *crow, sfb__rows *local, sfb__accum *A, sfb__mask *m, float *ps,
                                  float *cs, float p0, float dp) {
    sfb__step st;
    sfb_result r;
    int cv;
    st.ctx = ctx; st.opt = opt; st.p = p; st.c = c; st.half = NULL;
    r = sfb__build_child_topology(&st);
    if (r != SFB_SUCCESS) {
        sfb__free(ctx, st.half);
        return r == SFB_OUT_OF_MEMORY ? sfb__oom(ctx, "refinement topology") : r;
    }
    if (prow) {
        crow->rows = c->nv;
        crow->n = 0;
        crow->off = (size_t *)sfb__alloc(ctx, ((size_t)c->nv + 1) * sizeof(size_t));
        /* room for the child rows at once: a child's row spans about twice its parents' average
         * (it grows by doubling, copied by realloc, where this falls short; growing from 4 per row
         * copied the table five times over at level 3) */
        if (!crow->off || !sfb__rows_reserve(ctx, crow, (size_t)c->nv * (2 * (prow->n / (size_t)(prow->rows > 0 ? prow->rows : 1)) + 4) + 16)) {
            sfb__free(ctx, st.half);
            return sfb__oom(ctx, "stencil table");
        }
        crow->off[0] = 0;
    } else if (!local) {
        sfb__free(ctx, st.half);
        return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "refinement step with neither composed nor local rows");
    }
    if (local) {
        memset(local, 0, sizeof *local);
        local->rows = c->nv;
        local->off = (size_t *)sfb__alloc(ctx, ((size_t)c->nv + 1) * sizeof(size_t));
        if (!local->off || !sfb__rows_reserve(ctx, local, (size_t)c->nv * 8 + 16)) {
            sfb__free(ctx, st.half);
            return sfb__oom(ctx, "stencil table");
        }
        local->off[0] = 0;
    }
    for (cv = 0; cv < c->nv; ++cv) {
        if (!sfb__child_mask(&st, cv, m, ps, cs) || (prow && !sfb__compose_row(ctx, A, prow, m, crow, cv)) ||
            (local && !sfb__rows_append_mask(ctx, local, m, cv))) {
            sfb__free(ctx, st.half);
            return sfb__oom(ctx, "stencil table");
        }
        if ((cv & 0xffff) == 0xffff) {
            r = sfb__progress(ctx, p0 + dp * (float)cv / (float)c->nv, "refine");
            if (r != SFB_SUCCESS) { sfb__free(ctx, st.half); return r; }
        }
    }
    sfb__free(ctx, st.half);
    return SFB_SUCCESS;
}

/* Limit tangent masks of a crease vertex for the side whose faces lie between its crease
 * edges a and b (in v's edge order; b may exceed the edge count to go around an interior
 * vertex: indices are taken modulo it): m1 along the crease (from b's end towards a's), m2
 * into that side. The other side of an interior crease is (b, a + edge count). */
void sfb__crease_tangent_masks(const sfb__level *l, int v, int a, int b, int loop, sfb__mask *m1, sfb__mask *m2) {
    int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0;
    int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0;
    double tscale = loop ? 3.0 : 1.0;
    int i, k = b - a - 1; /* interior edges between the crease edges */
#define SFB__E(i) sfb__other_end(l, l->ve[e0 + (i) % ne], v)
#define SFB__HASF(i) ((i) % ne < nf)
#define SFB__D(i) l->fv[l->fv_off[l->vf[f0 + (i) % ne]] + (l->vf_slot[f0 + (i) % ne] + 2) % (l->fv_off[l->vf[f0 + (i) % ne] + 1] - l->fv_off[l->vf[f0 + (i) % ne]])]
    SFB__MASK_ADD(m1, SFB__E(a), 0.5 * tscale);
    SFB__MASK_ADD(m1, SFB__E(b), -0.5 * tscale);
    if (loop) {
        if (k == 0) {
            SFB__MASK_ADD(m2, v, -6.0); SFB__MASK_ADD(m2, SFB__E(a), 3.0); SFB__MASK_ADD(m2, SFB__E(b), 3.0);
        } else if (k == 1) {
            SFB__MASK_ADD(m2, v, -3.0); SFB__MASK_ADD(m2, SFB__E(a + 1), 3.0);
        } else if (k == 2) {
            double r3 = 1.73205080756887729352;
            SFB__MASK_ADD(m2, v, -r3); SFB__MASK_ADD(m2, SFB__E(a), -r3 / 2); SFB__MASK_ADD(m2, SFB__E(b), -r3 / 2);
            SFB__MASK_ADD(m2, SFB__E(a + 1), r3); SFB__MASK_ADD(m2, SFB__E(a + 2), r3);
        } else {
            double th = SFB__PI / (k + 1), cwt = -3.0 * sin(th), ec = -3.0 * 2.0 * (cos(th) - 1.0);
            SFB__MASK_ADD(m2, SFB__E(a), cwt); SFB__MASK_ADD(m2, SFB__E(b), cwt);
            for (i = 1; i <= k; ++i) SFB__MASK_ADD(m2, SFB__E(a + i), ec * sin(i * th));
        }
    } else {
        if (k == 0) {
            SFB__MASK_ADD(m2, v, -6.0); SFB__MASK_ADD(m2, SFB__E(a), 3.0); SFB__MASK_ADD(m2, SFB__E(b), 3.0);
        } else if (k == 1) {
            SFB__MASK_ADD(m2, v, -4.0 / 6.0);
            SFB__MASK_ADD(m2, SFB__E(a), -1.0 / 6.0); SFB__MASK_ADD(m2, SFB__E(a + 1), 4.0 / 6.0);
            SFB__MASK_ADD(m2, SFB__E(b), -1.0 / 6.0);
            if (SFB__HASF(a)) SFB__MASK_ADD(m2, SFB__D(a), 1.0 / 6.0);
            if (SFB__HASF(a + 1)) SFB__MASK_ADD(m2, SFB__D(a + 1), 1.0 / 6.0);
        } else {
            double kk = k + 1, th = SFB__PI / kk, ct = cos(th), st = sin(th);
            double den = 1.0 / (kk * (3.0 + ct)), R = (ct + 1.0) / st;
            SFB__MASK_ADD(m2, v, 4.0 * R * (ct - 1.0) * den);
            SFB__MASK_ADD(m2, SFB__E(a), -R * (1.0 + 2.0 * ct) * den);
            SFB__MASK_ADD(m2, SFB__E(b), -R * (1.0 + 2.0 * ct) * den);
            if (SFB__HASF(a)) SFB__MASK_ADD(m2, SFB__D(a), st * den);
            for (i = 1; i < kk; ++i) {
                double si = sin(i * th), si1 = sin((i + 1) * th);
                SFB__MASK_ADD(m2, SFB__E(a + i), 4.0 * si * den);
                if (SFB__HASF(a + i)) SFB__MASK_ADD(m2, SFB__D(a + i), (si + si1) * den);
            }
        }
    }
#undef SFB__E
#undef SFB__HASF
#undef SFB__D
}

/* ---- limit masks at the last level ---- */
void sfb__limit_masks(const sfb__level *l, int v, sfb_scheme scheme, sfb__mask *mp, sfb__mask *m1, sfb__mask *m2) {
    int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0;
    int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0;
    int rule = l->vrule[v], i;
    int loop = scheme == SFB_SCHEME_LOOP;
    double tscale = loop ? 3.0 : 1.0;
    mp->n = m1->n = m2->n = 0;
    if (scheme == SFB_SCHEME_BILINEAR || ne == 0) rule = SFB__RULE_CORNER;
    if ((rule == SFB__RULE_SMOOTH || rule == SFB__RULE_DART) &&
        (nf != ne || (l->vtag[v] & SFB__TAG_NONMANIFOLD) || (!loop && nf == 2)))
        rule = SFB__RULE_CORNER; /* Catmull-Clark valence 2 is a corner for the limit (as OpenSubdiv) */
    if (rule == SFB__RULE_CORNER) {
        SFB__MASK_ADD(mp, v, 1.0);
        if (ne >= 2) {
            SFB__MASK_ADD(m1, v, -tscale);
            SFB__MASK_ADD(m1, sfb__other_end(l, l->ve[e0], v), tscale);
            SFB__MASK_ADD(m2, v, -tscale);
            SFB__MASK_ADD(m2, sfb__other_end(l, l->ve[e0 + 1], v), tscale);
        }
        return;
    }
    if (rule == SFB__RULE_CREASE) {
        float sharp[SFB_MAX_VALENCE + 1];
        int a, b;
        for (i = 0; i < ne && i <= SFB_MAX_VALENCE; ++i) sharp[i] = l->es[l->ve[e0 + i]];
        sfb__crease_pair(sharp, ne, &a, &b);
        SFB__MASK_ADD(mp, v, 2.0 / 3.0);
        SFB__MASK_ADD(mp, sfb__other_end(l, l->ve[e0 + a], v), 1.0 / 6.0);
        SFB__MASK_ADD(mp, sfb__other_end(l, l->ve[e0 + b], v), 1.0 / 6.0);
        sfb__crease_tangent_masks(l, v, a, b, loop, m1, m2);
        return;
    }
    /* smooth */
#define SFB__E(i) sfb__other_end(l, l->ve[e0 + (i)], v)
#define SFB__D(i) l->fv[l->fv_off[l->vf[f0 + (i)]] + (l->vf_slot[f0 + (i)] + 2) % (l->fv_off[l->vf[f0 + (i)] + 1] - l->fv_off[l->vf[f0 + (i)]])]
    if (loop) {
        double ew, vw;
        if (nf == 6) {
            ew = 1.0 / 12.0;
            vw = 0.5;
        } else {
            double beta = 0.25 * cos(2.0 * SFB__PI / nf) + 0.375;
            double gamma = (0.625 - beta * beta) / nf;
            ew = 1.0 / (nf + 3.0 / (8.0 * gamma));
            vw = 1.0 - ew * nf;
        }
        SFB__MASK_ADD(mp, v, vw);
        for (i = 0; i < ne; ++i) {
            double al = 2.0 * SFB__PI * i / ne;
            SFB__MASK_ADD(mp, SFB__E(i), ew);
            SFB__MASK_ADD(m1, SFB__E(i), cos(al));
            SFB__MASK_ADD(m2, SFB__E(i), sin(al));
        }
    } else {
        double n = nf, fw = 1.0 / (n * (n + 5.0)), ew = 4.0 * fw;
        double th = 2.0 * SFB__PI / n, ct = cos(th), ch = cos(0.5 * th);
        double lambda = 5.0 / 16.0 + (ct + ch * sqrt(2.0 * (9.0 + ct))) / 16.0;
        double fscale = 1.0 / (4.0 * lambda - 1.0);
        if (nf == 4) { fw = 1.0 / 36.0; ew = 1.0 / 9.0; }
        SFB__MASK_ADD(mp, v, nf == 4 ? 4.0 / 9.0 : 1.0 - n * (ew + fw));
        for (i = 0; i < nf; ++i) {
            int ip = (i + nf - 1) % nf;
            double c0 = cos(i * th), c1 = cos((i + 1) * th);
            double t1e = 4.0 * c0, t1f = fscale * (c0 + c1);
            double cp0 = cos(ip * th), cp1 = cos((ip + 1) * th);
            double t2e = 4.0 * cp0, t2f = fscale * (cp0 + cp1);
            if (nf == 4) {
                static const double E1[4] = {4, 0, -4, 0}, F1[4] = {1, -1, -1, 1};
                static const double E2[4] = {0, 4, 0, -4}, F2[4] = {1, 1, -1, -1};
                t1e = E1[i]; t1f = F1[i]; t2e = E2[i]; t2f = F2[i];
            }
            SFB__MASK_ADD(mp, SFB__E(i), ew);
            SFB__MASK_ADD(mp, SFB__D(i), fw);
            SFB__MASK_ADD(m1, SFB__E(i), t1e);
            SFB__MASK_ADD(m1, SFB__D(i), t1f);
            SFB__MASK_ADD(m2, SFB__E(i), t2e);
            SFB__MASK_ADD(m2, SFB__D(i), t2f);
        }
    }
#undef SFB__E
#undef SFB__D
}


sfb_result sfb__refine(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int level,
                       sfb__level *top, sfb__stencils *vt, sfb__stencils *lt, float prog0, float prog1) {
    return sfb__refine_keep_levels(ctx, base, opt, level, top, vt, lt, NULL, prog0, prog1);
}

void sfb__refine_kept_free(sfb_context *ctx, sfb__refine_kept *keep, int level) {
    int k;
    for (k = 0; k < level; ++k) {
        sfb__level_free(ctx, &keep->lev[k]);
        sfb__stencils_free(ctx, &keep->T[k]);
    }
}

sfb_result sfb__refine_keep_levels(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int level,
                                   sfb__level *top, sfb__stencils *vt, sfb__stencils *lt, sfb__refine_kept *keep, float prog0,
                                   float prog1) {
    sfb__rows prow, crow, local;
    sfb__level cur, next;
    sfb__accum A;
    sfb__mask m;
    float *ps = NULL, *cs = NULL;
    sfb_result r = SFB_SUCCESS;
    int L, i, owns_cur = 0;
    memset(&prow, 0, sizeof prow); memset(&crow, 0, sizeof crow); memset(&local, 0, sizeof local);
    memset(&A, 0, sizeof A); memset(&m, 0, sizeof m);
    memset(&next, 0, sizeof next);
    cur = *base;
    A.acc = (double *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(double));
    A.mark = (unsigned *)sfb__calloc(ctx, (size_t)base->nv + 1, sizeof(unsigned));
    A.touched = (int *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(int));
    ps = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    cs = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    prow.rows = base->nv;
    prow.off = (size_t *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(size_t));
    if (!A.acc || !A.mark || !A.touched || !ps || !cs || !prow.off || !sfb__rows_reserve(ctx, &prow, (size_t)base->nv + 1)) {
        r = sfb__oom(ctx, "refinement");
        goto done;
    }
    for (i = 0; i < base->nv; ++i) { prow.off[i] = (size_t)i; prow.idx[i] = i; prow.w[i] = 1.0; }
    prow.off[base->nv] = (size_t)base->nv;
    prow.n = (size_t)base->nv;
    for (L = 0; L < level; ++L) {
        r = sfb__progress(ctx, prog0 + (prog1 - prog0) * (float)L / (float)(level + 1), "refine");
        if (r != SFB_SUCCESS) goto done;
        r = sfb__refine_step_local(ctx, opt, &cur, &prow, &next, &crow, keep ? &local : NULL, &A, &m, ps, cs,
                                   prog0 + (prog1 - prog0) * (float)L / (float)(level + 1), (prog1 - prog0) / (float)(level + 1));
        if (r != SFB_SUCCESS) goto done;
        if (keep) {
            r = sfb__rows_move_to_stencils(ctx, &local, cur.nv, &keep->T[L]);
            sfb__rows_free(ctx, &local);
            if (r != SFB_SUCCESS) { if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "stencil table"); goto done; }
        }
        sfb__rows_free(ctx, &prow);
        prow = crow;
        memset(&crow, 0, sizeof crow);
        if (owns_cur && keep) keep->lev[L] = cur; /* handed over: level L of the caller's copy */
        else if (owns_cur) sfb__level_free(ctx, &cur);
        cur = next;
        owns_cur = 1;
        memset(&next, 0, sizeof next);
    }
    /* the limit tables below compose over prow: moved only where there are none */
    r = lt ? sfb__rows_to_stencils(ctx, &prow, base->nv, vt) : sfb__rows_move_to_stencils(ctx, &prow, base->nv, vt);
    if (r != SFB_SUCCESS) { if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "stencil table"); goto done; }
    if (lt) {
        sfb__rows out[3];
        sfb__mask mm[3];
        int t, v;
        memset(out, 0, sizeof out);
        memset(mm, 0, sizeof mm);
        for (t = 0; t < 3 && r == SFB_SUCCESS; ++t) {
            out[t].rows = cur.nv;
            out[t].off = (size_t *)sfb__alloc(ctx, ((size_t)cur.nv + 1) * sizeof(size_t));
            if (!out[t].off) r = sfb__oom(ctx, "limit stencil table");
            else out[t].off[0] = 0;
        }
        for (v = 0; v < cur.nv && r == SFB_SUCCESS; ++v) {
            int need = 3 * sfb__mask_need_vertex(&cur, v) + 8;
            for (t = 0; t < 3; ++t)
                if (!sfb__mask_grow(ctx, &mm[t], need)) r = sfb__oom(ctx, "limit stencil table");
            if (r != SFB_SUCCESS) break;
            sfb__limit_masks(&cur, v, opt->scheme, &mm[0], &mm[1], &mm[2]);
            for (t = 0; t < 3; ++t)
                if (!sfb__compose_row(ctx, &A, &prow, &mm[t], &out[t], v)) { r = sfb__oom(ctx, "limit stencil table"); break; }
        }
        for (t = 0; t < 3; ++t) {
            if (r == SFB_SUCCESS) {
                r = sfb__rows_move_to_stencils(ctx, &out[t], base->nv, &lt[t]);
                if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "limit stencil table");
            }
            sfb__rows_free(ctx, &out[t]);
            sfb__free(ctx, mm[t].idx);
            sfb__free(ctx, mm[t].w);
        }
        if (r != SFB_SUCCESS) goto done;
    }
    if (owns_cur) {
        *top = cur;
        owns_cur = 0;
    } else {
        /* level 0: the caller's base is the top; hand back an independent copy (the base is
         * already prepared, so preparing it again changes nothing) */
        r = sfb__level_prepare(ctx, base, 0, 0, top);
    }
done:
    if (owns_cur) sfb__level_free(ctx, &cur);
    sfb__level_free(ctx, &next);
    sfb__rows_free(ctx, &prow);
    sfb__rows_free(ctx, &crow);
    sfb__rows_free(ctx, &local);
    sfb__free(ctx, A.acc); sfb__free(ctx, A.mark); sfb__free(ctx, A.touched);
    sfb__free(ctx, m.idx); sfb__free(ctx, m.w);
    sfb__free(ctx, ps); sfb__free(ctx, cs);
    if (r != SFB_SUCCESS) {
        sfb__stencils_free(ctx, vt);
        if (lt) { sfb__stencils_free(ctx, &lt[0]); sfb__stencils_free(ctx, &lt[1]); sfb__stencils_free(ctx, &lt[2]); }
        if (keep) sfb__refine_kept_free(ctx, keep, level);
    }
    return r;
}
#line 1 "src/patch/eigen.c"
/* Eigen structures for Stam's exact evaluation of Catmull-Clark patches around one smooth
 * extraordinary vertex (ALGORITHMS.md §1), in double precision.
 *
 * Point order (K = 2N+8): 0 the EV, 2i-1 edge neighbour e_i, 2i face diagonal f_i (i = 1..N),
 * 2N+1..2N+7 the outer points at grid (2,2),(2,1),(2,0),(2,-1),(1,2),(0,2),(-1,2); the patch
 * is (0, e_3, f_2, e_2) with u toward e_3 = (1,0) and v toward e_2 = (0,1).
 *
 * A = [S 0; S11 S12] is diagonalised without a general eigensolver:
 * - S (the 2N+1 ring points) is block-circulant: frequency j of the ring gives a 2x2 block
 *   (a 3x3 block with the EV for j = 0) whose eigenvalues are
 *   ((5 + cos t) +- sqrt((1 + cos t)(9 + cos t)))/16, t = 2 pi j / N, and whose eigenvectors
 *   are e_i = cos(i t) (or sin), f_i = (cos(i t) + cos((i+1) t))/(4 lambda - 1) (or sin);
 * - an eigenvector u of S extends to [u; w] of A with (lambda I - S12) w = S11 u, solved with
 *   full pivoting (a consistent singular system when lambda is also an eigenvalue of S12);
 * - the 7 eigenvalues of S12 (1/8, 1/8, 1/16, 1/16, 1/32, 1/32, 1/64) give [0; z].
 * V^-1 comes from an LU factorisation; every build checks max |A - V diag(lambda) V^-1| and
 * refuses the valence when it is not at rounding level. The cost is O(K^3): valences up to
 * SFB__STAM_MAX_VALENCE are supported; higher ones are isolated adaptively instead.
 *
 * What the kernels use: lambda (K), V^-1 (K x K, to make the eigen coefficients C^ = V^-1 C of
 * a face as stencil rows) and Phi_k = P_k Abar V (16 x K per sub-patch k = 1..3), so that
 * x(u,v) = sum_i lambda_i^(n-1) (b(u~,v~)^T Phi_k)_i C^_i. */

static const double sfb__S11[7][8] = {
    {1, 0, 0, 6, 36, 6, 0, 0}, {4, 0, 0, 4, 24, 24, 0, 0}, {6, 0, 0, 1, 6, 36, 6, 1}, {4, 0, 0, 0, 0, 24, 24, 4},
    {4, 0, 0, 24, 24, 4, 0, 0}, {6, 1, 6, 36, 6, 1, 0, 0}, {4, 4, 24, 24, 0, 0, 0, 0}};
static const double sfb__S12[7][7] = {
    {1, 6, 1, 0, 6, 1, 0}, {0, 4, 4, 0, 0, 0, 0}, {0, 1, 6, 1, 0, 0, 0}, {0, 0, 4, 4, 0, 0, 0},
    {0, 0, 0, 0, 4, 4, 0}, {0, 0, 0, 0, 1, 6, 1}, {0, 0, 0, 0, 0, 4, 4}};
static const double sfb__S21[9][7] = {
    {0, 0, 0, 0, 16, 0, 0}, {0, 0, 0, 0, 24, 4, 0}, {0, 0, 0, 0, 16, 16, 0}, {0, 0, 0, 0, 4, 24, 4},
    {0, 0, 0, 0, 0, 16, 16}, {0, 0, 0, 4, 24, 0, 0}, {0, 0, 0, 16, 16, 0, 0}, {0, 0, 4, 24, 4, 0, 0},
    {0, 0, 16, 16, 0, 0, 0}};
static const double sfb__S22[9][7] = {
    {16, 16, 0, 0, 16, 0, 0}, {4, 24, 4, 0, 4, 0, 0}, {0, 16, 16, 0, 0, 0, 0}, {0, 4, 24, 4, 0, 0, 0},
    {0, 0, 16, 16, 0, 0, 0}, {4, 4, 0, 0, 24, 4, 0}, {0, 0, 0, 0, 16, 16, 0}, {0, 0, 0, 0, 4, 24, 4},
    {0, 0, 0, 0, 0, 16, 16}};

/* Picking vectors (ALGORITHMS.md §1.3): entry = offset + m*mult, m = 2N. */
static int sfb__stam_pick(int N, int k, int j) {
    static const signed char off[3][16] = {
        {7, 6, 4, 12, 0, 5, 3, 11, 3, 4, 2, 10, 6, 5, 1, 9},
        {0, 5, 3, 11, 3, 4, 2, 10, 6, 5, 1, 9, 15, 14, 13, 8},
        {1, 0, 5, 3, 2, 3, 4, 2, 7, 6, 5, 1, 16, 15, 14, 13}};
    static const unsigned char mul[3][16] = {
        {0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 1, 1, 1, 1},
        {0, 0, 1, 1, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1},
        {0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1}};
    int v = off[k - 1][j] + (mul[k - 1][j] ? 2 * N : 0);
    /* N = 3: ring index 7 (e_4) is e_1 (the entries equal to m+1 are outer points) */
    if (N == 3 && v == 7 && !mul[k - 1][j]) v = 1;
    return v;
}

/* Dense A (K x K, row-major). */
static void sfb__stam_matrix(int N, double *A) {
    int K = 2 * N + 8, i, r, c;
    double a = 1.0 - 7.0 / (4.0 * N), b = 3.0 / (2.0 * N * N), cc = 1.0 / (4.0 * N * N);
#define SFB__E(i) (2 * ((((i) - 1) % N + N) % N + 1) - 1)
#define SFB__F(i) (2 * ((((i) - 1) % N + N) % N + 1))
    memset(A, 0, (size_t)K * K * sizeof(double));
    A[0] = a;
    for (i = 1; i <= N; ++i) { A[2 * i - 1] = b; A[2 * i] = cc; }
    for (i = 1; i <= N; ++i) {
        double *re = A + (size_t)SFB__E(i) * K, *rf = A + (size_t)SFB__F(i) * K;
        re[0] += 0.375; re[SFB__E(i)] += 0.375; re[SFB__E(i - 1)] += 0.0625; re[SFB__E(i + 1)] += 0.0625;
        re[SFB__F(i - 1)] += 0.0625; re[SFB__F(i)] += 0.0625;
        rf[0] += 0.25; rf[SFB__E(i)] += 0.25; rf[SFB__F(i)] += 0.25; rf[SFB__E(i + 1)] += 0.25;
    }
#undef SFB__E
#undef SFB__F
    for (r = 0; r < 7; ++r) {
        double *row = A + (size_t)(2 * N + 1 + r) * K;
        for (c = 0; c < 8; ++c) {
            int col = (N == 3 && c == 7) ? 1 : c; /* N = 3: e_4 is e_1 */
            row[col] += sfb__S11[r][c] / 64.0;
        }
        for (c = 0; c < 7; ++c) row[2 * N + 1 + c] += sfb__S12[r][c] / 64.0;
    }
}

/* Solves M x = y (n x n, row-major, destroyed) with full pivoting. Pivots below tol are
 * treated as zero (their unknowns set to 0); returns the residual max |M x - y| relative to
 * |y| + |M||x| computed on the original, which the caller passes as M0. */
static double sfb__solve_full(int n, double *M, double *y, double *x, const double *M0, const double *y0) {
    int piv_r[16], piv_c[16], i, j, k, rank = 0;
    double tol = 1e-12, res = 0.0, scale = 1e-300;
    int colperm[16];
    for (i = 0; i < n; ++i) colperm[i] = i;
    for (k = 0; k < n; ++k) {
        int br = -1, bc = -1;
        double best = tol;
        for (i = k; i < n; ++i)
            for (j = k; j < n; ++j)
                if (fabs(M[i * n + j]) > best) { best = fabs(M[i * n + j]); br = i; bc = j; }
        if (br < 0) break;
        if (br != k) {
            for (j = 0; j < n; ++j) { double t = M[k * n + j]; M[k * n + j] = M[br * n + j]; M[br * n + j] = t; }
            { double t = y[k]; y[k] = y[br]; y[br] = t; }
        }
        if (bc != k) {
            for (i = 0; i < n; ++i) { double t = M[i * n + k]; M[i * n + k] = M[i * n + bc]; M[i * n + bc] = t; }
            { int t = colperm[k]; colperm[k] = colperm[bc]; colperm[bc] = t; }
        }
        piv_r[k] = br; piv_c[k] = bc;
        for (i = k + 1; i < n; ++i) {
            double f = M[i * n + k] / M[k * n + k];
            if (f == 0.0) continue;
            for (j = k; j < n; ++j) M[i * n + j] -= f * M[k * n + j];
            y[i] -= f * y[k];
        }
        rank++;
    }
    {
        double z[16];
        for (i = n - 1; i >= 0; --i) {
            double s = y[i];
            if (i >= rank) { z[i] = 0.0; continue; }
            for (j = i + 1; j < n; ++j) s -= M[i * n + j] * z[j];
            z[i] = s / M[i * n + i];
        }
        for (i = 0; i < n; ++i) x[colperm[i]] = z[i];
    }
    for (i = 0; i < n; ++i) {
        double s = -y0[i], a = fabs(y0[i]);
        for (j = 0; j < n; ++j) { s += M0[i * n + j] * x[j]; a += fabs(M0[i * n + j] * x[j]); }
        if (a > scale) scale = a;
        if (fabs(s) > res) res = fabs(s);
    }
    (void)piv_r; (void)piv_c;
    return res / scale;
}

/* Null space of the 7x7 (S12 - mu I): up to 2 vectors, by full-pivot elimination. */
static int sfb__s12_null(double mu, double out[2][7]) {
    double M[49];
    int colperm[7], i, j, k, rank = 0, nfree, f;
    for (i = 0; i < 7; ++i) {
        colperm[i] = i;
        for (j = 0; j < 7; ++j) M[i * 7 + j] = sfb__S12[i][j] / 64.0 - (i == j ? mu : 0.0);
    }
    for (k = 0; k < 7; ++k) {
        int br = -1, bc = -1;
        double best = 1e-12;
        for (i = k; i < 7; ++i)
            for (j = k; j < 7; ++j)
                if (fabs(M[i * 7 + j]) > best) { best = fabs(M[i * 7 + j]); br = i; bc = j; }
        if (br < 0) break;
        for (j = 0; j < 7; ++j) { double t = M[k * 7 + j]; M[k * 7 + j] = M[br * 7 + j]; M[br * 7 + j] = t; }
        for (i = 0; i < 7; ++i) { double t = M[i * 7 + k]; M[i * 7 + k] = M[i * 7 + bc]; M[i * 7 + bc] = t; }
        { int t = colperm[k]; colperm[k] = colperm[bc]; colperm[bc] = t; }
        for (i = 0; i < 7; ++i) {
            double fct;
            if (i == k) continue;
            fct = M[i * 7 + k] / M[k * 7 + k];
            if (fct == 0.0) continue;
            for (j = k; j < 7; ++j) M[i * 7 + j] -= fct * M[k * 7 + j];
        }
        rank++;
    }
    nfree = 7 - rank;
    if (nfree > 2) nfree = 2;
    for (f = 0; f < nfree; ++f) {
        double z[7];
        int fc = rank + f;
        for (i = 0; i < 7; ++i) z[i] = 0.0;
        z[fc] = 1.0;
        for (i = 0; i < rank; ++i) z[i] = -M[i * 7 + fc] / M[i * 7 + i];
        for (i = 0; i < 7; ++i) out[f][colperm[i]] = z[i];
    }
    return nfree;
}

/* In-place inverse of an n x n row-major matrix by LU with partial pivoting (Gauss-Jordan).
 * Returns 0 when singular. `work` holds n ints. */
static int sfb__invert(int n, double *M, double *inv, int *perm) {
    int i, j, k;
    for (i = 0; i < n; ++i) {
        perm[i] = i;
        for (j = 0; j < n; ++j) inv[(size_t)i * n + j] = i == j ? 1.0 : 0.0;
    }
    for (k = 0; k < n; ++k) {
        int p = k;
        double best = fabs(M[(size_t)k * n + k]), d;
        for (i = k + 1; i < n; ++i)
            if (fabs(M[(size_t)i * n + k]) > best) { best = fabs(M[(size_t)i * n + k]); p = i; }
        if (best < 1e-300) return 0;
        if (p != k)
            for (j = 0; j < n; ++j) {
                double t = M[(size_t)k * n + j]; M[(size_t)k * n + j] = M[(size_t)p * n + j]; M[(size_t)p * n + j] = t;
                t = inv[(size_t)k * n + j]; inv[(size_t)k * n + j] = inv[(size_t)p * n + j]; inv[(size_t)p * n + j] = t;
            }
        d = 1.0 / M[(size_t)k * n + k];
        for (j = 0; j < n; ++j) { M[(size_t)k * n + j] *= d; inv[(size_t)k * n + j] *= d; }
        for (i = 0; i < n; ++i) {
            double f;
            if (i == k) continue;
            f = M[(size_t)i * n + k];
            if (f == 0.0) continue;
            for (j = k; j < n; ++j) M[(size_t)i * n + j] -= f * M[(size_t)k * n + j];
            for (j = 0; j < n; ++j) inv[(size_t)i * n + j] -= f * inv[(size_t)k * n + j];
        }
    }
    return 1;
}

void sfb__eigen_cc_free(sfb_context *ctx, sfb__eigen_cc *e) {
    if (!e) return;
    sfb__free(ctx, e->lambda); sfb__free(ctx, e->vinv); sfb__free(ctx, e->phi);
    sfb__free(ctx, e->v); sfb__free(ctx, e->a);
    sfb__free(ctx, e);
}

/* V^-1 into vinv (V copied to the scratch W; perm holds K ints) and *err = max |A - V J V^-1|,
 * J = diag(lambda) plus, where head (NULL: none) gives a Jordan head h for column k, a 1 at
 * (h, k). Returns 0 when V is singular or the error is not at rounding level. */
static int sfb__eigen_invert_check(int K, const double *A, const double *V, const double *lambda, const int *head, double *W,
                                   int *perm, double *vinv, double *err_out) {
    size_t KK = (size_t)K * K;
    double err = 0.0;
    int r, c, k;
    memcpy(W, V, KK * sizeof(double));
    if (!sfb__invert(K, W, vinv, perm)) return 0;
    for (r = 0; r < K; ++r)
        for (c = 0; c < K; ++c) {
            double s = 0.0;
            for (k = 0; k < K; ++k) {
                double vj = V[(size_t)r * K + k] * lambda[k];
                if (head && head[k] >= 0) vj += V[(size_t)r * K + head[k]];
                s += vj * vinv[(size_t)k * K + c];
            }
            s -= A[(size_t)r * K + c];
            if (fabs(s) > err) err = fabs(s);
        }
    *err_out = err;
    return err < 1e-9;
}

/* The 2N+1 right eigenvectors of S (the ring points; frequency 0 as the 3x3 block on (V, e,
 * f)) in the first rows of V's columns, their eigenvalues in lambda, the index of lambda = 1 in
 * *dominant. Returns the number of columns made. */
static int sfb__eigen_cc_ring(int N, const double *A, double *V, double *lambda, int *dominant) {
    int K = 2 * N + 8, col = 0, i, j, q;
#define SFB__SET(r, value) (V[(size_t)(r) * K + col] = (value))
    {
        /* j = 0: constant ring; 3x3 block on (V, e, f) */
        double a = A[0], bN = A[1] * N, cN = A[2] * N;
        double B[3][3];
        double tr, det, disc, l2, l3, lam[3];
        B[0][0] = a; B[0][1] = bN; B[0][2] = cN;
        B[1][0] = 0.375; B[1][1] = 0.5; B[1][2] = 0.125;
        B[2][0] = 0.25; B[2][1] = 0.5; B[2][2] = 0.25;
        tr = B[0][0] + B[1][1] + B[2][2];
        det = B[0][0] * (B[1][1] * B[2][2] - B[1][2] * B[2][1]) - B[0][1] * (B[1][0] * B[2][2] - B[1][2] * B[2][0]) +
              B[0][2] * (B[1][0] * B[2][1] - B[1][1] * B[2][0]);
        /* the other two eigenvalues: l2 + l3 = tr - 1, l2 l3 = det */
        disc = (tr - 1.0) * (tr - 1.0) - 4.0 * det;
        if (disc < 0.0) disc = 0.0;
        l2 = 0.5 * ((tr - 1.0) + sqrt(disc));
        l3 = 0.5 * ((tr - 1.0) - sqrt(disc));
        lam[0] = 1.0; lam[1] = l2; lam[2] = l3;
        for (q = 0; q < 3; ++q) {
            double M[3][3], best = -1.0, x[3] = {1, 1, 1};
            int r1, r2;
            if (q > 0) {
                for (i = 0; i < 3; ++i)
                    for (j = 0; j < 3; ++j) M[i][j] = B[i][j] - (i == j ? lam[q] : 0.0);
                for (r1 = 0; r1 < 3; ++r1)
                    for (r2 = r1 + 1; r2 < 3; ++r2) {
                        double c0 = M[r1][1] * M[r2][2] - M[r1][2] * M[r2][1];
                        double c1 = M[r1][2] * M[r2][0] - M[r1][0] * M[r2][2];
                        double c2 = M[r1][0] * M[r2][1] - M[r1][1] * M[r2][0];
                        double nn = c0 * c0 + c1 * c1 + c2 * c2;
                        if (nn > best) { best = nn; x[0] = c0; x[1] = c1; x[2] = c2; }
                    }
                best = sqrt(best);
                for (i = 0; i < 3; ++i) x[i] /= best;
            }
            SFB__SET(0, x[0]);
            for (i = 1; i <= N; ++i) { SFB__SET(2 * i - 1, x[1]); SFB__SET(2 * i, x[2]); }
            lambda[col] = lam[q];
            if (q == 0) *dominant = col;
            col++;
        }
    }
    for (j = 1; 2 * j < N; ++j) {
        double t = 2.0 * SFB__PI * j / N, c = cos(t);
        double root = sqrt((1.0 + c) * (9.0 + c));
        double lams[2];
        lams[0] = ((5.0 + c) + root) / 16.0;
        lams[1] = ((5.0 + c) - root) / 16.0;
        for (q = 0; q < 2; ++q) {
            double d = 1.0 / (4.0 * lams[q] - 1.0);
            int trig;
            for (trig = 0; trig < 2; ++trig) {
                SFB__SET(0, 0.0);
                for (i = 1; i <= N; ++i) {
                    double x0 = trig ? sin(i * t) : cos(i * t), x1 = trig ? sin((i + 1) * t) : cos((i + 1) * t);
                    SFB__SET(2 * i - 1, x0);
                    SFB__SET(2 * i, (x0 + x1) * d);
                }
                lambda[col++] = lams[q];
            }
        }
    }
    if (N % 2 == 0) {
        for (q = 0; q < 2; ++q) {
            SFB__SET(0, 0.0);
            for (i = 1; i <= N; ++i) {
                double s = (i % 2) ? -1.0 : 1.0;
                SFB__SET(2 * i - 1, q == 0 ? s : 0.0);
                SFB__SET(2 * i, q == 1 ? s : 0.0);
            }
            lambda[col++] = 0.25;
        }
    }
#undef SFB__SET
    return col;
}

/* Extends the `col` eigenvectors of S to A ((lambda I - S12) w = S11 u, in the outer rows of V)
 * and appends [0; z] for the null vectors z of S12 - mu I. Returns the number of columns, -1
 * when a system or a null space is not as expected. */
static int sfb__eigen_cc_extend(int N, double *V, double *lambda, int col) {
    static const double mus[4] = {0.125, 0.0625, 0.03125, 0.015625};
    static const int mult[4] = {2, 2, 2, 1};
    int K = 2 * N + 8, i, k, q;
    for (q = 0; q < col; ++q) {
        double M[49], M0[49], y[7], y0[7], w[7], res;
        for (i = 0; i < 7; ++i) {
            double s = 0.0;
            for (k = 0; k < 8; ++k) {
                int src = (N == 3 && k == 7) ? 1 : k;
                s += sfb__S11[i][k] / 64.0 * V[(size_t)src * K + q];
            }
            y[i] = y0[i] = s;
            for (k = 0; k < 7; ++k) M[i * 7 + k] = M0[i * 7 + k] = (i == k ? lambda[q] : 0.0) - sfb__S12[i][k] / 64.0;
        }
        res = sfb__solve_full(7, M, y, w, M0, y0);
        if (res > 1e-10) return -1;
        for (i = 0; i < 7; ++i) V[(size_t)(2 * N + 1 + i) * K + q] = w[i];
    }
    for (q = 0; q < 4; ++q) {
        double z[2][7];
        int got = sfb__s12_null(mus[q], z), f;
        if (got != mult[q]) return -1;
        for (f = 0; f < got; ++f) {
            for (i = 0; i < 7; ++i) V[(size_t)(2 * N + 1 + i) * K + col] = z[f][i];
            lambda[col++] = mus[q];
        }
    }
    return col;
}

/* Phi_k = P_k Abar V (16 x K per sub-patch k = 1..3) into phi: the picked rows of Abar V, rows
 * < K of it being rows of A V, rows K..K+8 [S21 0 S22] V (computed into the scratch AV, 9 x K). */
static void sfb__eigen_cc_phi(int N, const double *A, const double *V, double *AV, double *phi) {
    int K = 2 * N + 8, i, j, k, q;
    /* rows K..K+8 of Abar V: [S21 0 S22] V */
    for (i = 0; i < 9; ++i)
        for (q = 0; q < K; ++q) {
            double s = 0.0;
            for (k = 0; k < 7; ++k) {
                s += sfb__S21[i][k] / 64.0 * V[(size_t)k * K + q];
                s += sfb__S22[i][k] / 64.0 * V[(size_t)(2 * N + 1 + k) * K + q];
            }
            AV[(size_t)i * K + q] = s;
        }
    /* Phi_k rows: picked rows of Abar V; rows < K of A V are rows of V L */
    for (k = 1; k <= 3; ++k)
        for (j = 0; j < 16; ++j) {
            int p = sfb__stam_pick(N, k, j);
            double *dst = phi + ((size_t)(k - 1) * 16 + j) * K;
            for (q = 0; q < K; ++q) {
                if (p < K) {
                    double s = 0.0;
                    int c;
                    for (c = 0; c < K; ++c) s += A[(size_t)p * K + c] * V[(size_t)c * K + q];
                    dst[q] = s;
                } else {
                    dst[q] = AV[(size_t)(p - K) * K + q];
                }
            }
        }
}

/* Builds the eigen structure of valence N (3..SFB__STAM_MAX_VALENCE). keep: also keep V and A
 * (for tests). */
sfb_result sfb__eigen_cc_build(sfb_context *ctx, int N, int keep, sfb__eigen_cc **out) {
    sfb__eigen_cc *e;
    int K = 2 * N + 8, col, i;
    double *A = NULL, *V = NULL, *W = NULL, *AV = NULL;
    int *perm = NULL;
    size_t KK = (size_t)K * K;
    *out = NULL;
    if (N < 3 || N > SFB__STAM_MAX_VALENCE)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "no Stam eigen structure for valence %d (3..%d)", N,
                          SFB__STAM_MAX_VALENCE);
    e = (sfb__eigen_cc *)sfb__calloc(ctx, 1, sizeof *e);
    A = (double *)sfb__alloc(ctx, KK * sizeof(double));
    V = (double *)sfb__calloc(ctx, KK, sizeof(double));
    W = (double *)sfb__alloc(ctx, KK * sizeof(double));
    AV = (double *)sfb__alloc(ctx, (size_t)9 * K * sizeof(double));
    perm = (int *)sfb__alloc(ctx, (size_t)K * sizeof(int));
    if (e) {
        e->lambda = (double *)sfb__alloc(ctx, (size_t)K * sizeof(double));
        e->vinv = (double *)sfb__alloc(ctx, KK * sizeof(double));
        e->phi = (double *)sfb__alloc(ctx, (size_t)48 * K * sizeof(double));
    }
    if (!e || !A || !V || !W || !AV || !perm || !e->lambda || !e->vinv || !e->phi) goto oom;
    e->N = N;
    e->K = K;
    sfb__stam_matrix(N, A);
    /* right eigenvectors of S, column by column of V (row-major: V[r*K + col]) */
    col = sfb__eigen_cc_ring(N, A, V, e->lambda, &e->dominant);
    if (col != 2 * N + 1) goto defective;
    /* extend each to A: (lambda I - S12) w = S11 u; then S12's own eigenvectors */
    col = sfb__eigen_cc_extend(N, V, e->lambda, col);
    if (col != K) goto defective;
    /* V^-1, and the check A = V L V^-1 */
    if (!sfb__eigen_invert_check(K, A, V, e->lambda, NULL, W, perm, e->vinv, &e->error)) goto defective;
    e->sub = 0.0;
    for (i = 0; i < K; ++i)
        if (i != e->dominant && fabs(e->lambda[i]) > e->sub) e->sub = fabs(e->lambda[i]);
    sfb__eigen_cc_phi(N, A, V, AV, e->phi);
    if (keep) { e->v = V; e->a = A; V = A = NULL; }
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, AV); sfb__free(ctx, perm);
    *out = e;
    return SFB_SUCCESS;
defective:
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, AV); sfb__free(ctx, perm);
    sfb__eigen_cc_free(ctx, e);
    return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "Stam eigen structure of valence %d failed its check", N);
oom:
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, AV); sfb__free(ctx, perm);
    sfb__eigen_cc_free(ctx, e);
    return sfb__oom(ctx, "Stam eigen structure");
}

/* The context's cache: built on first use of a valence, kept until the context goes. */
const sfb__eigen_cc *sfb__eigen_cc_get(sfb_context *ctx, int N) {
    sfb__eigen_cc *e;
    sfb__error_state kept;
    if (N < 3 || N > SFB__STAM_MAX_VALENCE) return NULL;
    if (ctx->eigen_cc[N]) return ctx->eigen_cc[N];
    if (ctx->eigen_cc_failed[N]) return NULL;
    sfb__error_keep(ctx, &kept);
    if (sfb__eigen_cc_build(ctx, N, 0, &e) != SFB_SUCCESS) {
        /* recovered here: said to the logger, and the caller's last error put back (the call
         * that needed the basis still succeeds) */
        ctx->eigen_cc_failed[N] = 1;
        sfb__log(ctx, SFB_LOG_WARN, "valence %d: %s; its faces are isolated adaptively instead", N, ctx->error);
        sfb__error_put_back(ctx, &kept);
        return NULL;
    }
    ctx->eigen_cc[N] = e;
    return e;
}

/* ---- Stam's Loop evaluation, in eigen form (ALGORITHMS.md §1.5, with our own layout) ----
 *
 * Control set of a triangle (EV, a, b), counter-clockwise, a and b regular (valence 6). In the
 * lattice of the regular triangulation the EV is at (0,0), a at (1,0) and b at (0,1) (the
 * patch's (u,v) frame):
 *   0 the EV; 1..N its ring r_0 = a, r_1 = b, r_2, ... counter-clockwise (r_2 at (-1,1),
 *   r_{N-1} at (1,-1)); N+1 (1,1), opposite the edge ab; N+2 (2,0) and N+3 (2,-1) beyond a;
 *   N+4 (0,2) and N+5 (-1,2) beyond b. K = N + 6.
 * One Loop step maps these K points to the same lattice places one level finer (A, K x K);
 * six more points of the finer lattice, (3,0) (2,1) (3,-1) (1,2) (0,3) (-1,3), complete the
 * enlarged set (Abar) from which the three regular sub-patches of the ring are picked: the
 * corner at a ((1,0)..(2,0)..(1,1), k = 0), the corner at b (k = 1) and the middle triangle
 * (k = 2, corner 0 at (1,1), turned by 180 degrees). Each sub-patch is a 12-point box spline,
 * written as a quartic Bezier triangle by ALGORITHMS.md §5.1.
 *
 * A = [S 0; S10 S11] is put in Jordan form without a general eigensolver:
 * - S (EV and ring) is circulant on the ring: eigenvalues 1 and 5/8 - alpha (frequency 0) and
 *   3/8 + cos(2 pi j/N)/4 (cos and sin vectors of frequency j);
 * - S11 (the 5 outer points) has eigenvalues 1/8 (three) and 1/16 (two), eigenvectors known;
 * - an eigenvector w of S extends to [w; y] with y solved in S11's eigenbasis; when its
 *   eigenvalue is also one of S11's and the right-hand side has a component there, A is
 *   defective (valence 3: lambda = 1/16 three times, two eigenvectors): the extension is then
 *   the second vector of a 2 x 2 Jordan block whose head is that component.
 * A^m V = V J^m, so the level-n points of sub-patch k are Phi_k J^(n-1) V^-1 C, with
 * Phi_k = (Bezier of the picked rows of Abar) V (15 x K): a partner column l of a Jordan head h
 * gets lambda^m Phi_l + m lambda^(m-1) Phi_h. */

/* Index of lattice point (x,y) in the enlarged set, -1 if not in it. */
int sfb__loop_index(int N, int x, int y) {
    static const signed char pts[17][3] = {{0, 0, 0}, {1, 0, 1}, {0, 1, 2}, {-1, 1, 3}, {1, -1, -1},
                                           {1, 1, 7},  {2, 0, 8}, {2, -1, 9}, {0, 2, 10}, {-1, 2, 11},
                                           {3, 0, 12}, {2, 1, 13}, {3, -1, 14}, {1, 2, 15}, {0, 3, 16}, {-1, 3, 17}, {99, 99, 0}};
    int i;
    for (i = 0; pts[i][0] != 99; ++i)
        if (pts[i][0] == x && pts[i][1] == y) {
            int c = pts[i][2];
            if (c == -1) return N;           /* r_{N-1} */
            if (c == 3) return 1 + 2 % N;     /* r_2 (r_{N-1} itself when N = 3) */
            return c >= 7 ? N + (c - 6) : c;
        }
    return -1;
}

/* Sabin's rules (ALGORITHMS.md §5.1): Bezier point (i = exponent of s, j = exponent of t,
 * our order row by row in t) from the 12 box-spline points at lattice offsets boxpt[]. */
const signed char sfb__box12[12][2] = {{0, -1}, {1, -1}, {2, -1}, {-1, 0}, {0, 0}, {1, 0},
                                              {2, 0},  {-1, 1}, {0, 1},  {1, 1},  {-1, 2}, {0, 2}};
const unsigned char sfb__bez15_from_box[15][12] = {
    /* row t^0 */
    {2, 2, 0, 2, 12, 2, 0, 2, 2, 0, 0, 0}, {1, 3, 0, 0, 12, 4, 0, 1, 3, 0, 0, 0}, {0, 4, 0, 0, 8, 8, 0, 0, 4, 0, 0, 0},
    {0, 3, 1, 0, 4, 12, 0, 0, 3, 1, 0, 0}, {0, 2, 2, 0, 2, 12, 2, 0, 2, 2, 0, 0},
    /* t^1 */
    {0, 1, 0, 1, 12, 3, 0, 3, 4, 0, 0, 0}, {0, 1, 0, 0, 10, 6, 0, 1, 6, 0, 0, 0}, {0, 1, 0, 0, 6, 10, 0, 0, 6, 1, 0, 0},
    {0, 1, 0, 0, 3, 12, 1, 0, 4, 3, 0, 0},
    /* t^2 */
    {0, 0, 0, 0, 8, 4, 0, 4, 8, 0, 0, 0}, {0, 0, 0, 0, 6, 6, 0, 1, 10, 1, 0, 0}, {0, 0, 0, 0, 4, 8, 0, 0, 8, 4, 0, 0},
    /* t^3 */
    {0, 0, 0, 0, 4, 3, 0, 3, 12, 1, 1, 0}, {0, 0, 0, 0, 3, 4, 0, 1, 12, 3, 0, 1},
    /* t^4 */
    {0, 0, 0, 0, 2, 2, 0, 2, 12, 2, 2, 2}};

void sfb__eigen_loop_free(sfb_context *ctx, sfb__eigen_loop *e) {
    if (!e) return;
    sfb__free(ctx, e->lambda); sfb__free(ctx, e->head); sfb__free(ctx, e->vinv); sfb__free(ctx, e->phi);
    sfb__free(ctx, e->v); sfb__free(ctx, e->a);
    sfb__free(ctx, e);
}

/* A (K x K) followed by the 6 extra rows of Abar: (K + 6) x K, row-major. */
static void sfb__loop_matrix(int N, double *A) {
    int K = N + 6, i;
    double c = cos(2.0 * SFB__PI / N), alpha = 0.625 - (3.0 + 2.0 * c) * (3.0 + 2.0 * c) / 64.0;
    int a = 1, b = 2, r2 = 1 + 2 % N, rl = N, o11 = N + 1, o20 = N + 2, o2m = N + 3, o02 = N + 4, om2 = N + 5;
    memset(A, 0, (size_t)(K + 6) * K * sizeof(double));
#define SFB__A(r, col, w) (A[(size_t)(r) * K + (col)] += (w))
    SFB__A(0, 0, 1.0 - alpha);
    for (i = 1; i <= N; ++i) SFB__A(0, i, alpha / N);
    for (i = 0; i < N; ++i) {
        SFB__A(1 + i, 0, 0.375);
        SFB__A(1 + i, 1 + i, 0.375);
        SFB__A(1 + i, 1 + (i + N - 1) % N, 0.125);
        SFB__A(1 + i, 1 + (i + 1) % N, 0.125);
    }
    /* (1,1): edge ab */
    SFB__A(o11, a, 0.375); SFB__A(o11, b, 0.375); SFB__A(o11, 0, 0.125); SFB__A(o11, o11, 0.125);
    /* (2,0): vertex a (valence 6: 5/8 and 1/16 each) */
    SFB__A(o20, a, 0.625);
    SFB__A(o20, 0, 0.0625); SFB__A(o20, rl, 0.0625); SFB__A(o20, o2m, 0.0625); SFB__A(o20, o20, 0.0625);
    SFB__A(o20, o11, 0.0625); SFB__A(o20, b, 0.0625);
    /* (2,-1): edge a r_{N-1} */
    SFB__A(o2m, a, 0.375); SFB__A(o2m, rl, 0.375); SFB__A(o2m, 0, 0.125); SFB__A(o2m, o2m, 0.125);
    /* (0,2): vertex b */
    SFB__A(o02, b, 0.625);
    SFB__A(o02, 0, 0.0625); SFB__A(o02, a, 0.0625); SFB__A(o02, o11, 0.0625); SFB__A(o02, o02, 0.0625);
    SFB__A(o02, om2, 0.0625); SFB__A(o02, r2, 0.0625);
    /* (-1,2): edge b r_2 */
    SFB__A(om2, b, 0.375); SFB__A(om2, r2, 0.375); SFB__A(om2, 0, 0.125); SFB__A(om2, om2, 0.125);
    /* the enlarged set: (3,0) (2,1) (3,-1) (1,2) (0,3) (-1,3), all edge points */
    SFB__A(K + 0, a, 0.375); SFB__A(K + 0, o20, 0.375); SFB__A(K + 0, o11, 0.125); SFB__A(K + 0, o2m, 0.125);
    SFB__A(K + 1, a, 0.375); SFB__A(K + 1, o11, 0.375); SFB__A(K + 1, o20, 0.125); SFB__A(K + 1, b, 0.125);
    SFB__A(K + 2, a, 0.375); SFB__A(K + 2, o2m, 0.375); SFB__A(K + 2, o20, 0.125); SFB__A(K + 2, rl, 0.125);
    SFB__A(K + 3, b, 0.375); SFB__A(K + 3, o11, 0.375); SFB__A(K + 3, o02, 0.125); SFB__A(K + 3, a, 0.125);
    SFB__A(K + 4, b, 0.375); SFB__A(K + 4, o02, 0.375); SFB__A(K + 4, o11, 0.125); SFB__A(K + 4, om2, 0.125);
    SFB__A(K + 5, b, 0.375); SFB__A(K + 5, om2, 0.375); SFB__A(K + 5, o02, 0.125); SFB__A(K + 5, r2, 0.125);
#undef SFB__A
}

/* S11's eigenvectors (outer order (1,1) (2,0) (2,-1) (0,2) (-1,2)) and eigenvalues */
static const double sfb__loop_U[5][5] = {{1, 0, 0, 0, 0}, {1, 1, 0, 1, 0}, {0, 1, 0, 0, 0}, {1, 0, 1, 0, 1}, {0, 0, 1, 0, 0}};
static const double sfb__loop_mu[5] = {0.125, 0.125, 0.125, 0.0625, 0.0625};

/* S's eigenvectors in the first N+1 rows of V's columns, their eigenvalues in lambda, the
 * index of lambda = 1 in *dominant and the eigenvalue of frequency 1 in *c1. Returns the
 * number of columns made. */
static int sfb__eigen_loop_ring(int N, double *V, double *lambda, int *dominant, double *c1) {
    int K = N + 6, col = 0, i, j;
#define SFB__SET(r, value) (V[(size_t)(r) * K + col] = (value))
    {
        double c = cos(2.0 * SFB__PI / N), alpha = 0.625 - (3.0 + 2.0 * c) * (3.0 + 2.0 * c) / 64.0;
        for (i = 0; i <= N; ++i) SFB__SET(i, 1.0);
        lambda[col] = 1.0;
        *dominant = col++;
        SFB__SET(0, -8.0 * alpha / 3.0);
        for (i = 1; i <= N; ++i) SFB__SET(i, 1.0);
        lambda[col++] = 0.625 - alpha;
    }
    for (j = 1; 2 * j < N; ++j) {
        double t = 2.0 * SFB__PI * j / N;
        int trig;
        for (trig = 0; trig < 2; ++trig) {
            SFB__SET(0, 0.0);
            for (i = 0; i < N; ++i) SFB__SET(1 + i, trig ? sin(i * t) : cos(i * t));
            lambda[col++] = 0.375 + 0.25 * cos(t);
        }
        if (j == 1) *c1 = 0.375 + 0.25 * cos(t);
    }
    if (N % 2 == 0) {
        SFB__SET(0, 0.0);
        for (i = 0; i < N; ++i) SFB__SET(1 + i, (i % 2) ? -1.0 : 1.0);
        lambda[col++] = 0.125;
    }
#undef SFB__SET
    return col;
}

/* Extends S's N+1 eigenvectors to A: (S11 - lambda) y = -S10 w, solved in S11's eigenbasis (Ui
 * its inverse; outer_col the columns of S11's eigenvectors). Where A is defective the column
 * becomes the partner of a Jordan head (head[q]). Returns 0 when it is defective more than
 * once. */
static int sfb__eigen_loop_extend(int N, const double *A, double *V, const double *Ui, const int *outer_col, double *lambda,
                                  int *head) {
    int K = N + 6, i, k, q, l, njordan = 0;
    for (q = 0; q <= N; ++q) {
        double rhs[5], d[5], yh[5], best = 0.0;
        int lstar = -1;
        for (i = 0; i < 5; ++i) {
            double s = 0.0;
            for (k = 0; k <= N; ++k) s += A[(size_t)(N + 1 + i) * K + k] * V[(size_t)k * K + q];
            rhs[i] = s;
        }
        for (l = 0; l < 5; ++l) {
            double s = 0.0;
            for (i = 0; i < 5; ++i) s += Ui[l * 5 + i] * rhs[i];
            d[l] = s;
        }
        for (l = 0; l < 5; ++l) {
            if (fabs(lambda[q] - sfb__loop_mu[l]) > 1e-9) yh[l] = d[l] / (lambda[q] - sfb__loop_mu[l]);
            else {
                yh[l] = 0.0;
                if (fabs(d[l]) > 1e-12 && fabs(d[l]) > best) { best = fabs(d[l]); lstar = l; }
            }
        }
        for (i = 0; i < 5; ++i) {
            double s = 0.0;
            for (l = 0; l < 5; ++l) s += sfb__loop_U[i][l] * yh[l];
            V[(size_t)(N + 1 + i) * K + q] = s;
        }
        if (lstar >= 0) {
            /* defective: (A - lambda)[w; y] = sum over S11's lambda-eigenvectors of d_l [0; u_l].
             * That sum replaces the column of u_lstar as the Jordan head; [w; y] is its partner. */
            int h = outer_col[lstar];
            if (++njordan > 1) return 0;
            for (i = 0; i < 5; ++i) {
                double s = 0.0;
                for (l = 0; l < 5; ++l)
                    if (fabs(lambda[q] - sfb__loop_mu[l]) <= 1e-9) s += d[l] * sfb__loop_U[i][l];
                V[(size_t)(N + 1 + i) * K + h] = s;
            }
            lambda[q] = sfb__loop_mu[lstar];
            head[q] = h;
        }
    }
    return 1;
}

/* Phi_k into phi (15 x K per sub-patch k = 0..2): the Bezier points of the picked rows of
 * Abar V. Returns 0 when a picked point is not in the enlarged set. */
static int sfb__eigen_loop_phi(int N, const double *A, const double *V, double *phi) {
    int K = N + 6, i, j, k, q;
    for (k = 0; k < 3; ++k) {
        static const int org[3][4] = {{1, 0, 1, 0}, {0, 1, 1, 0}, {1, 1, -1, 0}}; /* origin x, y; frame sign; unused */
        int rows[12];
        for (j = 0; j < 12; ++j) {
            int x = org[k][0] + org[k][2] * sfb__box12[j][0], y = org[k][1] + org[k][2] * sfb__box12[j][1];
            rows[j] = sfb__loop_index(N, x, y);
            if (rows[j] < 0) return 0;
        }
        for (q = 0; q < K; ++q) {
            double av[12];
            for (j = 0; j < 12; ++j) {
                double s = 0.0;
                int c;
                for (c = 0; c < K; ++c) s += A[(size_t)rows[j] * K + c] * V[(size_t)c * K + q];
                av[j] = s;
            }
            for (j = 0; j < 15; ++j) {
                double s = 0.0;
                for (i = 0; i < 12; ++i) s += sfb__bez15_from_box[j][i] * av[i];
                phi[((size_t)k * 15 + j) * K + q] = s / 24.0;
            }
        }
    }
    return 1;
}

sfb_result sfb__eigen_loop_build(sfb_context *ctx, int N, int keep, sfb__eigen_loop **out) {
    sfb__eigen_loop *e;
    int K = N + 6, col, i, l;
    double *A = NULL, *V = NULL, *W = NULL;
    double Ui[25], Uw[25];
    int *perm = NULL, outer_col[5];
    size_t KK = (size_t)K * K;
    double c1 = 0.0;
    *out = NULL;
    if (N < 3 || N > SFB__STAM_MAX_VALENCE)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "no Stam-Loop eigen structure for valence %d (3..%d)", N,
                          SFB__STAM_MAX_VALENCE);
    e = (sfb__eigen_loop *)sfb__calloc(ctx, 1, sizeof *e);
    A = (double *)sfb__alloc(ctx, (size_t)(K + 6) * K * sizeof(double));
    V = (double *)sfb__calloc(ctx, KK, sizeof(double));
    W = (double *)sfb__alloc(ctx, KK * sizeof(double));
    perm = (int *)sfb__alloc(ctx, (size_t)K * sizeof(int));
    if (e) {
        e->lambda = (double *)sfb__alloc(ctx, (size_t)K * sizeof(double));
        e->head = (int *)sfb__alloc(ctx, (size_t)K * sizeof(int));
        e->vinv = (double *)sfb__alloc(ctx, KK * sizeof(double));
        e->phi = (double *)sfb__alloc(ctx, (size_t)45 * K * sizeof(double));
    }
    if (!e || !A || !V || !W || !perm || !e->lambda || !e->head || !e->vinv || !e->phi) goto oom;
    e->N = N;
    e->K = K;
    for (i = 0; i < K; ++i) e->head[i] = -1;
    sfb__loop_matrix(N, A);
    for (i = 0; i < 25; ++i) Uw[i] = sfb__loop_U[i / 5][i % 5];
    if (!sfb__invert(5, Uw, Ui, perm)) goto defective;
    /* S's eigenvectors in the first N+1 rows of V */
    col = sfb__eigen_loop_ring(N, V, e->lambda, &e->dominant, &c1);
    if (col != N + 1) goto defective;
    /* S11's eigenvectors [0; u_l] */
    for (l = 0; l < 5; ++l) {
        for (i = 0; i < 5; ++i) V[(size_t)(N + 1 + i) * K + col] = sfb__loop_U[i][l];
        e->lambda[col] = sfb__loop_mu[l];
        outer_col[l] = col++;
    }
    /* extend S's eigenvectors: (S11 - lambda) y = -S10 w, in S11's eigenbasis */
    if (!sfb__eigen_loop_extend(N, A, V, Ui, outer_col, e->lambda, e->head)) goto defective;
    /* V^-1, and the check A = V J V^-1 */
    if (!sfb__eigen_invert_check(K, A, V, e->lambda, e->head, W, perm, e->vinv, &e->error)) goto defective;
    e->sub = c1;
    /* Phi_k: Bezier points of the picked rows of Abar V */
    if (!sfb__eigen_loop_phi(N, A, V, e->phi)) goto defective;
    if (keep) { e->v = V; e->a = A; V = A = NULL; }
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, perm);
    *out = e;
    return SFB_SUCCESS;
defective:
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, perm);
    sfb__eigen_loop_free(ctx, e);
    return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "Stam-Loop eigen structure of valence %d failed its check", N);
oom:
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, perm);
    sfb__eigen_loop_free(ctx, e);
    return sfb__oom(ctx, "Stam-Loop eigen structure");
}

const sfb__eigen_loop *sfb__eigen_loop_get(sfb_context *ctx, int N) {
    sfb__eigen_loop *e;
    sfb__error_state kept;
    if (N < 3 || N > SFB__STAM_MAX_VALENCE) return NULL;
    if (ctx->eigen_loop[N]) return ctx->eigen_loop[N];
    if (ctx->eigen_loop_failed[N]) return NULL;
    sfb__error_keep(ctx, &kept);
    if (sfb__eigen_loop_build(ctx, N, 0, &e) != SFB_SUCCESS) {
        /* recovered here: said to the logger, and the caller's last error put back (the call
         * that needed the basis still succeeds) */
        ctx->eigen_loop_failed[N] = 1;
        sfb__log(ctx, SFB_LOG_WARN, "valence %d: %s; its faces are isolated adaptively instead", N, ctx->error);
        sfb__error_put_back(ctx, &kept);
        return NULL;
    }
    ctx->eigen_loop[N] = e;
    return e;
}
#line 1 "src/patch/table.c"
/* Reading a patch table (any scheme's): freeing it, the one locate (parametric face and (u,v)
 * to record and local (s,t) through the quadtree or triangle tree), the record kinds' registry
 * (sfb__patch_kind_of: which ref evaluator a record type has), and the ref kernel
 * (sfb__ref_eval_patches) that dispatches to them. Nothing here knows the scheme: the table's
 * domain says how to locate, a record's type says how to evaluate. */

void sfb__patch_table_free(sfb_context *ctx, sfb__patch_table *pt) {
    sfb__free(ctx, pt->ptype); sfb__free(ctx, pt->pfirst); sfb__free(ctx, pt->pparam); sfb__free(ctx, pt->pvalence);
    sfb__free(ctx, pt->cv); sfb__free(ctx, pt->ptex_face); sfb__free(ctx, pt->ptex_corner); sfb__free(ctx, pt->face_ptex);
    sfb__free(ctx, pt->ptex_root); sfb__free(ctx, pt->nodes); sfb__free(ctx, pt->point_data); sfb__free(ctx, pt->pcorner);
    if (pt->normal_field) {
        sfb__patch_table_free(ctx, pt->normal_field);
        sfb__free(ctx, pt->normal_field);
    }
    memset(pt, 0, sizeof *pt);
}

/* Triangle param faces (Loop). A triangle's (u,v) is barycentric: the point is
 * (1-u-v) P0 + u P1 + v P2 for its corners in face order. One Loop step splits it into four
 * children, numbered like quadrants of a quadtree node (x + 2y bits of the param code):
 * 0 the corner at P0, (2u, 2v); 1 the corner at P1, (2u-1, 2v); 2 the corner at P2,
 * (2u, 2v-1); 3 the middle, turned by 180 degrees: (1-2u, 1-2v), so its derivatives change
 * sign. The corner bits of the code give the face slot of the child's param corner 0. */

/* Patch index (or -1: hole) and local (s,t) of a valid location; *scale = 2^depth. */
/* Refuses what a scheme of one patch per triangle cannot build (who names it in the message):
 * faces that are not triangles, non-manifold edges (and, with manifold_vertices, vertices whose
 * triangles are not one fan), non-finite positions, triangles with an area below 1e-12 of the
 * squared bounding-box diagonal. */
sfb_result sfb__tri_mesh_check(sfb_context *ctx, const sfb__level *l, const float *positions, const char *who, int manifold_vertices) {
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, diag2 = 0.0;
    int f, e, v, c;
    for (f = 0; f < l->nf; ++f)
        if (sfb__face_n(l, f) != 3)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "%s: face %d has %d vertices (triangles only)", who, f,
                              sfb__face_n(l, f));
    for (e = 0; e < l->ne; ++e)
        if (l->ef_off[e + 1] - l->ef_off[e] > 2)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, e, "%s: edge %d (%d-%d) is non-manifold (%d triangles)", who, e,
                              l->ev[2 * e], l->ev[2 * e + 1], l->ef_off[e + 1] - l->ef_off[e]);
    for (v = 0; v < l->nv; ++v) {
        if (manifold_vertices && (l->vtag[v] & SFB__TAG_NONMANIFOLD))
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, v, "%s: vertex %d is non-manifold (its triangles are not one fan)",
                              who, v);
        for (c = 0; c < 3; ++c) {
            const double x = positions[3 * (size_t)v + c];
            if (!(x == x) || x > 3.4e38 || x < -3.4e38)
                return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, v, "%s: vertex %d is not finite", who, v);
            if (v == 0 || x < lo[c]) lo[c] = x;
            if (v == 0 || x > hi[c]) hi[c] = x;
        }
    }
    for (c = 0; c < 3; ++c) diag2 += (hi[c] - lo[c]) * (hi[c] - lo[c]);
    for (f = 0; f < l->nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        double u[3], w[3], n[3], area;
        for (c = 0; c < 3; ++c) {
            u[c] = (double)positions[3 * (size_t)fv[1] + c] - positions[3 * (size_t)fv[0] + c];
            w[c] = (double)positions[3 * (size_t)fv[2] + c] - positions[3 * (size_t)fv[0] + c];
        }
        sfb__cross3(u, w, n);
        area = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(area > 1e-12 * diag2))
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "%s: triangle %d (%d %d %d) is degenerate (area %g)", who, f,
                              fv[0], fv[1], fv[2], area);
    }
    return SFB_SUCCESS;
}

/* A table of one BEZIER_TRI15 patch with 15 points of its own per triangle of l that is not a
 * hole (one param face per triangle, depth 0), the points from net (45 doubles per triangle, our
 * patch order) -- the shape of schemes whose points are not masks (PN triangles, tribezier). */
/* The arrays of a table of npatch BEZIER_TRI15 patches (15 own points each) over nf triangles
 * with nnodes quadtree nodes; 0 (and the table freed) when out of memory. */
static int sfb__beztri_alloc(sfb_context *ctx, int nf, int npatch, int nnodes, sfb__patch_table *pt) {
    pt->domain = SFB__DOMAIN_TRI;
    pt->nptex = nf;
    pt->npatch = npatch;
    pt->ncv = 15 * npatch;
    pt->npoints = 15 * npatch;
    pt->nnodes = nnodes;
    pt->face_ptex = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    pt->ptex_face = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    pt->ptex_corner = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    pt->ptex_root = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    pt->nodes = (int *)sfb__alloc(ctx, ((size_t)nnodes + 1) * 4 * sizeof(int));
    pt->ptype = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(int));
    pt->pfirst = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(int));
    pt->pparam = (unsigned *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(unsigned));
    pt->pvalence = (int *)sfb__calloc(ctx, (size_t)npatch + 1, sizeof(int));
    pt->cv = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * 15 * sizeof(int));
    pt->point_data = (float *)sfb__alloc(ctx, ((size_t)npatch + 1) * 45 * sizeof(float));
    if (!pt->face_ptex || !pt->ptex_face || !pt->ptex_corner || !pt->ptex_root || !pt->nodes || !pt->ptype || !pt->pfirst ||
        !pt->pparam || !pt->pvalence || !pt->cv || !pt->point_data) {
        sfb__patch_table_free(ctx, pt);
        return 0;
    }
    return 1;
}

sfb_result sfb__patch_table_beztri_own(sfb_context *ctx, const sfb__level *l, const double *net, sfb__patch_table *pt) {
    int f, k, p = 0, npatch = 0;
    memset(pt, 0, sizeof *pt);
    for (f = 0; f < l->nf; ++f) npatch += !l->fhole[f];
    if (!sfb__beztri_alloc(ctx, l->nf, npatch, 0, pt)) return sfb__oom(ctx, "patch table");
    for (f = 0; f < l->nf; ++f) {
        pt->face_ptex[f] = pt->ptex_face[f] = f;
        pt->ptex_corner[f] = -1;
        if (l->fhole[f]) { pt->ptex_root[f] = -1; continue; }
        for (k = 0; k < 45; ++k) pt->point_data[45 * (size_t)p + k] = (float)net[45 * (size_t)f + k];
        pt->ptype[p] = SFB__PATCH_BEZTRI;
        pt->pfirst[p] = 15 * p;
        pt->pparam[p] = SFB__PARAM(0, 0, 0, 0);
        for (k = 0; k < 15; ++k) pt->cv[15 * p + k] = 15 * p + k;
        pt->ptex_root[f] = -(p + 2);
        p++;
    }
    pt->face_ptex[l->nf] = l->nf;
    pt->pfirst[npatch] = 15 * npatch;
    pt->counts[SFB__PATCH_BEZTRI] = npatch;
    return SFB_SUCCESS;
}

sfb_result sfb__patch_table_beztri_children(sfb_context *ctx, const sfb__level *l, const double *net, sfb__patch_table *pt) {
    int f, k, i, p = 0, nn = 0, npatch = 0;
    memset(pt, 0, sizeof *pt);
    for (f = 0; f < l->nf; ++f) npatch += l->fhole[f] ? 0 : 4;
    if (!sfb__beztri_alloc(ctx, l->nf, npatch, npatch / 4, pt)) return sfb__oom(ctx, "patch table");
    pt->max_depth = 1;
    for (f = 0; f < l->nf; ++f) {
        pt->face_ptex[f] = pt->ptex_face[f] = f;
        pt->ptex_corner[f] = -1;
        if (l->fhole[f]) { pt->ptex_root[f] = -1; continue; }
        pt->ptex_root[f] = nn;
        for (i = 0; i < 4; ++i, ++p) {
            for (k = 0; k < 45; ++k) pt->point_data[45 * (size_t)p + k] = (float)net[180 * (size_t)f + 45 * (size_t)i + k];
            pt->ptype[p] = SFB__PATCH_BEZTRI;
            pt->pfirst[p] = 15 * p;
            pt->pparam[p] = SFB__PARAM(1, i & 1, i >> 1, 0); /* quadrant x + 2y = i: sfb__pb_insert's encoding */
            for (k = 0; k < 15; ++k) pt->cv[15 * p + k] = 15 * p + k;
            pt->nodes[4 * nn + i] = -(p + 2);
        }
        ++nn;
    }
    pt->face_ptex[l->nf] = l->nf;
    pt->pfirst[npatch] = 15 * npatch;
    pt->counts[SFB__PATCH_BEZTRI] = npatch;
    return SFB_SUCCESS;
}

int sfb__patch_locate(const sfb__patch_table *pt, int ptex, double u, double v, double *s, double *t, double *scale) {
    int node = pt->ptex_root[ptex];
    double sc = 1.0;
    if (pt->domain == SFB__DOMAIN_TRI) {
        /* triangles: *scale is negative after an odd number of middle children */
        while (node >= 0) {
            int c;
            sc *= 2.0;
            if (u >= 0.5) { c = 1; u = 2.0 * u - 1.0; v = 2.0 * v; }
            else if (v >= 0.5) { c = 2; u = 2.0 * u; v = 2.0 * v - 1.0; }
            else if (u + v < 0.5) { c = 0; u = 2.0 * u; v = 2.0 * v; }
            else { c = 3; u = 1.0 - 2.0 * u; v = 1.0 - 2.0 * v; sc = -sc; }
            node = pt->nodes[4 * node + c];
        }
        *s = u; *t = v; *scale = sc;
        return node <= -2 ? -node - 2 : -1;
    }
    while (node >= 0) {
        int qx, qy;
        u *= 2.0; v *= 2.0; sc *= 2.0;
        qx = u >= 1.0; qy = v >= 1.0;
        if (qx) u -= 1.0;
        if (qy) v -= 1.0;
        node = pt->nodes[4 * node + qx + 2 * qy];
    }
    *s = u; *t = v; *scale = sc;
    return node <= -2 ? -node - 2 : -1;
}

void sfb__cross3(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* End-cap normal: the bilinear blend of the corners' limit normals (from the limit tangents),
 * so that the normal at a corner is the limit normal there. A corner whose limit normal is
 * more than 45 degrees from the cap's own (chord) normal at that corner belongs to another
 * sector (a corner or non-manifold vertex): that corner uses the chord normal instead. */
void sfb__endcap_normal(const float *pts, const int *cv, int nc, double s, double t, double nrm[3]) {
    double wts[4], n[3] = {0, 0, 0};
    int k, c;
    if (nc == 3) { wts[0] = 1 - s - t; wts[1] = s; wts[2] = t; }
    else { wts[0] = (1 - s) * (1 - t); wts[1] = s * (1 - t); wts[2] = s * t; wts[3] = (1 - s) * t; }
    for (k = 0; k < nc; ++k) {
        const float *p = pts + 3 * (size_t)cv[k], *pn = pts + 3 * (size_t)cv[(k + 1) % nc], *pp = pts + 3 * (size_t)cv[(k + nc - 1) % nc];
        const float *t1 = pts + 3 * (size_t)cv[nc + 2 * k], *t2 = pts + 3 * (size_t)cv[nc + 1 + 2 * k];
        double a[3], bb[3], ch[3], ln[3], lc, ll;
        for (c = 0; c < 3; ++c) { a[c] = (double)pn[c] - p[c]; bb[c] = (double)pp[c] - p[c]; }
        sfb__cross3(a, bb, ch);
        for (c = 0; c < 3; ++c) { a[c] = t1[c]; bb[c] = t2[c]; }
        sfb__cross3(a, bb, ln);
        lc = sqrt(ch[0] * ch[0] + ch[1] * ch[1] + ch[2] * ch[2]);
        ll = sqrt(ln[0] * ln[0] + ln[1] * ln[1] + ln[2] * ln[2]);
        if (lc > 0.0) for (c = 0; c < 3; ++c) ch[c] /= lc;
        if (ll > 0.0) for (c = 0; c < 3; ++c) ln[c] /= ll;
        {
            /* the tangent masks' orientation is the vertex's, not necessarily this face's */
            double d = ln[0] * ch[0] + ln[1] * ch[1] + ln[2] * ch[2];
            if (d < 0.0) { ln[0] = -ln[0]; ln[1] = -ln[1]; ln[2] = -ln[2]; d = -d; }
            if (!(ll > 0.0) || d < 0.70710678118654752) memcpy(ln, ch, sizeof ln);
        }
        for (c = 0; c < 3; ++c) n[c] += wts[k] * ln[c];
    }
    memcpy(nrm, n, sizeof n);
}

/* The end of both Stam kernels: nr holds the normalised first derivatives and sr the position
 * (row 0) and the second derivatives (rows 3..5) in the EV frame's (u,v); J = d(u,v)/d(s,t).
 * Writes res (P, Ps, Pt, Pss, Pst, Ptt; first derivatives times sc1, second times sc2) and nres
 * (the normalised first derivatives in (s,t)). */
double sfb__ipow(double x, int m) {
    double r = 1.0;
    for (; m > 0; m >>= 1, x *= x)
        if (m & 1) r *= x;
    return r;
}

void sfb__stam_finish(double J[2][2], double sc1, double sc2, double sr[6][3], double nr[2][3], double res[6][3],
                             double nres[2][3]) {
    int c;
    for (c = 0; c < 3; ++c) {
        double Pu = nr[0][c], Pv = nr[1][c], Puu = sr[3][c], Puv = sr[4][c], Pvv = sr[5][c];
        res[0][c] = sr[0][c];
        nres[0][c] = Pu * J[0][0] + Pv * J[1][0];
        nres[1][c] = Pu * J[0][1] + Pv * J[1][1];
        res[1][c] = nres[0][c] * sc1;
        res[2][c] = nres[1][c] * sc1;
        res[3][c] = sc2 * (Puu * J[0][0] * J[0][0] + 2.0 * Puv * J[0][0] * J[1][0] + Pvv * J[1][0] * J[1][0]);
        res[4][c] = sc2 * (Puu * J[0][0] * J[0][1] + Puv * (J[0][0] * J[1][1] + J[0][1] * J[1][0]) + Pvv * J[1][0] * J[1][1]);
        res[5][c] = sc2 * (Puu * J[0][1] * J[0][1] + 2.0 * Puv * J[0][1] * J[1][1] + Pvv * J[1][1] * J[1][1]);
    }
}

/* The ref evaluator of a record type: one line per kind. MANIFOLD4 records are evaluated by
 * patch/manifold.c's sfb__mf_eval_patch (their normal is final), see sfb__ref_eval_one. */
sfb__patch_kind sfb__patch_kind_of(int type) {
    sfb__patch_kind k;
    memset(&k, 0, sizeof k);
    switch (type) {
    case SFB__PATCH_STAM: k.eval = sfb__kind_stam; break;
    case SFB__PATCH_ENDCAP: k.poly = sfb__eval_endcap; k.cap_corners = 4; break;
    case SFB__PATCH_BEZTRI: k.poly = sfb__eval_beztri; break;
    case SFB__PATCH_STAM_LOOP: k.eval = sfb__kind_stam_loop; break;
    case SFB__PATCH_ENDCAP_TRI: k.poly = sfb__eval_endcap_tri; k.cap_corners = 3; break;
    default: k.poly = sfb__eval_bspline16; break;
    }
    return k;
}

/* res and the tangent directions dir of kind k at (s,t). */
static void sfb__kind_eval(const sfb__patch_kind *k, const sfb__patch_table *pt, const float *pts, int patch, const int *cv, double s,
                           double t, double res[6][3], double dir[2][3]) {
    if (!k->poly) { k->eval(pt, pts, patch, cv, s, t, res, dir); return; }
    k->poly(pts, cv, s, t, res);
    memcpy(dir[0], res[1], sizeof dir[0]);
    memcpy(dir[1], res[2], sizeof dir[1]);
}

/* The ref kernel: one location, double precision throughout. want2: the second derivatives are
 * asked for (a manifold blend only forms them then: they cost it four more blends); want_n: the
 * normal is (without it nrm stays 0 where the patch kind's normal is work of its own: end caps). */
static void sfb__ref_eval_one(const sfb__patch_table *pt, const float *pts, const sfb_location *loc, int want2, int want_n,
                              double res[6][3], double nrm[3]) {
    double s, t, sc, dir[2][3], len;
    int patch = sfb__patch_locate(pt, loc->face, loc->u, loc->v, &s, &t, &sc), c;
    const int *cv;
    sfb__patch_kind kind;
    memset(res, 0, sizeof(double) * 18);
    nrm[0] = nrm[1] = nrm[2] = 0.0;
    if (patch < 0) return;
    cv = pt->cv + pt->pfirst[patch];
    if (sfb__patch_family(pt->ptype[patch]) == SFB__FAMILY_MANIFOLD) {
        sfb__mf_eval_patch(pt, pts, patch, s, t, want2, res, nrm); /* its normal is final (patch/manifold.c) */
    } else {
        kind = sfb__patch_kind_of(pt->ptype[patch]);
        sfb__kind_eval(&kind, pt, pts, patch, cv, s, t, res, dir);
        if (kind.cap_corners && !want_n) { nrm[2] = 1.0; /* not asked for: any unit vector */ }
        else if (kind.cap_corners) sfb__endcap_normal(pts, cv, kind.cap_corners, s, t, nrm);
        else sfb__cross3(dir[0], dir[1], nrm);
        len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        if (!(len > 0.0) || !isfinite(len)) {
            /* degenerate tangents (a collapsed control net): the normal a step inside the patch */
            double r2[6][3];
            int tri = pt->domain == SFB__DOMAIN_TRI;
            double s2 = s + (s < 0.5 ? 1e-3 : -1e-3), t2 = t + (t < 0.5 ? 1e-3 : -1e-3);
            if (tri && s2 + t2 > 1.0) { s2 = s - 1e-3; t2 = t - 1e-3; }
            if (tri && s + t < 2e-3) { s2 = s + 1e-3; t2 = t + 1e-3; }
            sfb__kind_eval(&kind, pt, pts, patch, cv, s2, t2, r2, dir);
            sfb__cross3(dir[0], dir[1], nrm);
            len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        }
        if (len > 0.0 && isfinite(len)) for (c = 0; c < 3; ++c) nrm[c] /= len;
        else nrm[0] = nrm[1] = nrm[2] = 0.0;
    }
    for (c = 0; c < 3; ++c) {
        res[1][c] *= sc; res[2][c] *= sc;
        res[3][c] *= sc * sc; res[4][c] *= sc * sc; res[5][c] *= sc * sc;
    }
}

sfb_result sfb__ref_eval_patches(void *state, const sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                        int last, const sfb_eval_output *out) {
    int q, c;
    (void)state; (void)handle;
    for (q = first; q < last; ++q) {
        double res[6][3], nrm[3];
        size_t o = 3 * (size_t)q;
        sfb__ref_eval_one(pt, pt->point_data, &locs[q], out->duu || out->duv || out->dvv, out->normal != NULL, res, nrm);
        for (c = 0; c < 3; ++c) {
            if (out->position) out->position[o + c] = (float)res[0][c];
            if (out->du) out->du[o + c] = (float)res[1][c];
            if (out->dv) out->dv[o + c] = (float)res[2][c];
            if (out->duu) out->duu[o + c] = (float)res[3][c];
            if (out->duv) out->duv[o + c] = (float)res[4][c];
            if (out->dvv) out->dvv[o + c] = (float)res[5][c];
            if (out->normal) out->normal[o + c] = (float)nrm[c];
        }
    }
    return SFB_SUCCESS;
}
#line 1 "src/patch/build.c"
/* The Catmull-Clark and Loop scheme builders' common part: the patch-table builder (records,
 * points from the working levels' double positions, the quadtree), the shared corner helpers, and
 * feature-adaptive isolation (sfb__patches_build). The record kinds themselves are built and
 * evaluated in patch/quad.c (BSPLINE16, STAM, ENDCAP) and patch/tri.c (BEZTRI15, STAM_LOOP,
 * ENDCAP_TRI); patch/table.c reads a finished table.
 *
 * Parametric faces ("param faces", as OpenSubdiv's ptex faces): a base quad is one, with
 * (u,v) = (0,0) at its first vertex, (1,0) at the second, (0,1) at the last; an n-gon (n != 4)
 * is n of them, sub-face i being the quad (v_i, mid(v_i,v_i+1), centroid, mid(v_i-1,v_i)) of the
 * first Catmull-Clark step, in that corner order.
 *
 * Isolation. Level 0 is the prepared base mesh. A quad face becomes a patch when
 * - all four corners are regular for it: smooth valence 4 with no sharp edge (R1), a crease
 *   vertex with two infinitely sharp edges and two faces on this face's side (R2), or a corner
 *   (infinitely sharp) alone in its sector (R3) -> BSPLINE16, missing points mirrored
 *   (phantoms) across the crease/boundary, which is exact: the crease is then the uniform
 *   cubic B-spline of its vertices, as the crease rules make it;
 * - one corner is a smooth extraordinary vertex with no sharp edge (valence 3..256) and the
 *   other three are R1 -> STAM (eigen form, patch/eigen.c);
 * - otherwise it is refined: the next level is built only for these faces and the faces
 *   around them (the 1-ring whose vertices the masks read), and its children are classified
 *   in turn. Semi-sharp sharpness decays by one per level, so after ceil(s) levels the region
 *   is smooth and becomes exact patches.
 * At the isolation limit (default 8; semi-sharp features continue until smooth, at most
 * SFB_MAX_LEVEL + 1) a face that is still irregular (a crease or corner vertex with an
 * extraordinary sector, a dart, a non-manifold vertex) gets the END CAP: the bilinear patch
 * through the limit positions of its four corners, with normals blended from the corners'
 * limit normals (exact at the corners; oriented as the cap). Its distance to the limit surface is O(h^2) with
 * h = 2^-limit of the base face (measured by tests/limit.c and quoted in the README).
 * Holes produce no patches. */


int sfb__is_inf(float s) { return s >= SFB_SHARPNESS_INFINITE; }

/* Fan position of face g (corner slot `slot`) around vertex v, or -1. */
int sfb__fan_pos(const sfb__level *l, int v, int g, int slot) {
    int i;
    for (i = l->vf_off[v]; i < l->vf_off[v + 1]; ++i)
        if (l->vf[i] == g && l->vf_slot[i] == slot) return i - l->vf_off[v];
    return -1;
}

int sfb__face_n(const sfb__level *l, int f) { return l->fv_off[f + 1] - l->fv_off[f]; }

/* Does anything at g's corners still have to decay (semi-sharp edge or vertex)? */
int sfb__face_semisharp(const sfb__level *l, int g) {
    int k, i;
    for (k = l->fv_off[g]; k < l->fv_off[g + 1]; ++k) {
        int v = l->fv[k];
        if (l->vs[v] > 0.0f && !sfb__is_inf(l->vs[v])) return 1;
        for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i) {
            float s = l->es[l->ve[i]];
            if (s > 0.0f && !sfb__is_inf(s)) return 1;
        }
    }
    return 0;
}

static int sfb__pb_grow_int(sfb_context *ctx, int **a, int *cap, int need) {
    int nc;
    int *n;
    if (need <= *cap) return 1;
    nc = *cap ? *cap : 256;
    while (nc < need) nc *= 2;
    n = (int *)sfb__realloc(ctx, *a, (size_t)nc * sizeof(int));
    if (!n) return 0;
    *a = n;
    *cap = nc;
    return 1;
}

/* acc = the weighted sum of the xyz points pos[idx[i]] (zero weights skipped), in double. */
static void sfb__pb_combine(const int *idx, const double *w, size_t n, const double *pos, double acc[3]) {
    size_t i;
    int c;
    acc[0] = acc[1] = acc[2] = 0.0;
    for (i = 0; i < n; ++i) {
        const double *q = pos + 3 * (size_t)idx[i];
        if (w[i] == 0.0) continue;
        for (c = 0; c < 3; ++c) acc[c] += w[i] * q[c];
    }
}

/* Adds a point: mask m over working-level vertices applied to their double positions, rounded
 * to float once (a Stam point is an eigen coefficient, weights of both signs summing to 0 and a
 * result small next to the coordinates: it needs the double sum). A single vertex with weight 1 is shared through vrow. Returns the point's index
 * or -1 on allocation failure. Positions rather than rows composed over the base vertices:
 * nothing needs the rows once the points are made, and on a triangle mesh under Catmull-Clark
 * (an extraordinary vertex in every face) composing them was most of the build's time and
 * memory. */
int sfb__pb_point(sfb__pbuild *b, const double *wpos, const sfb__mask *m) {
    double acc[3];
    int c, row;
    if (m->n == 1 && m->w[0] == 1.0 && b->vrow[m->idx[0]] >= 0) return b->vrow[m->idx[0]];
    row = b->npts;
    if (row + 1 > b->cap_pts) {
        int nc = b->cap_pts ? b->cap_pts : 1024;
        float *np;
        while (nc < row + 1) {
            if (nc > 0x3fffffff) return -1; /* the int indices of cv */
            nc *= 2;
        }
        np = (float *)sfb__realloc(b->ctx, b->pts, (size_t)nc * 3 * sizeof(float));
        if (!np) return -1;
        b->pts = np;
        b->cap_pts = nc;
    }
    sfb__pb_combine(m->idx, m->w, (size_t)m->n, wpos, acc);
    for (c = 0; c < 3; ++c) b->pts[3 * (size_t)row + c] = (float)acc[c];
    b->npts = row + 1;
    if (m->n == 1 && m->w[0] == 1.0) b->vrow[m->idx[0]] = row;
    return row;
}

int sfb__pb_patch(sfb__pbuild *b, int type, unsigned param, int valence, int ncv) {
    sfb__patch_table *pt = b->pt;
    int n = pt->npatch;
    if (n + 1 > b->cap_patch) {
        int nc = b->cap_patch ? b->cap_patch * 2 : 256;
        int *t1 = (int *)sfb__realloc(b->ctx, pt->ptype, (size_t)nc * sizeof(int));
        if (!t1) return -1;
        pt->ptype = t1;
        t1 = (int *)sfb__realloc(b->ctx, pt->pfirst, (size_t)(nc + 1) * sizeof(int));
        if (!t1) return -1;
        pt->pfirst = t1;
        t1 = (int *)sfb__realloc(b->ctx, pt->pvalence, (size_t)nc * sizeof(int));
        if (!t1) return -1;
        pt->pvalence = t1;
        {
            unsigned *t2 = (unsigned *)sfb__realloc(b->ctx, pt->pparam, (size_t)nc * sizeof(unsigned));
            if (!t2) return -1;
            pt->pparam = t2;
        }
        b->cap_patch = nc;
    }
    if (!sfb__pb_grow_int(b->ctx, &pt->cv, &b->cap_cv, pt->ncv + ncv)) return -1;
    pt->ptype[n] = type;
    pt->pfirst[n] = pt->ncv;
    pt->pparam[n] = param;
    pt->pvalence[n] = valence;
    pt->ncv += ncv;
    pt->pfirst[n + 1] = pt->ncv;
    pt->npatch = n + 1;
    pt->counts[type]++;
    return n;
}

/* Inserts patch `patch` (or -1 for a hole) at (ptex, depth, i, j) in the quadtree. */
int sfb__pb_insert(sfb__pbuild *b, int ptex, unsigned param, int patch) {
    sfb__patch_table *pt = b->pt;
    int depth = SFB__PARAM_DEPTH(param), pi = SFB__PARAM_I(param), pj = SFB__PARAM_J(param);
    int *slot = &pt->ptex_root[ptex], d;
    for (d = 0; d < depth; ++d) {
        int qx = (pi >> (depth - 1 - d)) & 1, qy = (pj >> (depth - 1 - d)) & 1, node;
        if (*slot < 0) {
            /* a new internal node (its slot may only be empty: -1) */
            int k;
            ptrdiff_t off = slot - pt->nodes;
            int in_nodes = pt->nodes && slot >= pt->nodes && slot < pt->nodes + 4 * (size_t)pt->nnodes;
            if (!sfb__pb_grow_int(b->ctx, &pt->nodes, &b->cap_nodes, 4 * (pt->nnodes + 1))) return 0;
            if (in_nodes) slot = pt->nodes + off;
            node = pt->nnodes++;
            for (k = 0; k < 4; ++k) pt->nodes[4 * node + k] = -1;
            *slot = node;
        }
        node = *slot;
        slot = &pt->nodes[4 * node + qx + 2 * qy];
    }
    *slot = patch >= 0 ? -(patch + 2) : -1;
    return 1;
}

void sfb__wlevel_free(sfb_context *ctx, sfb__wlevel *w) {
    if (w->owns_level) sfb__level_free(ctx, &w->l);
    sfb__free(ctx, w->pos);
    sfb__free(ctx, w->fptex); sfb__free(ctx, w->fparam); sfb__free(ctx, w->vcomp); sfb__free(ctx, w->ecomp);
    memset(w, 0, sizeof *w);
}

/* End cap of face g (n = 3 or 4 corners, frame corner 0 at slot rot): the limit positions of
 * the corners in frame order (points 0..n-1), then the two limit tangents of each corner
 * (points n + 2k, n + 2k + 1) for the normals. */
sfb_result sfb__pb_endcap(sfb__pbuild *b, sfb__wlevel *w, int g, int rot, int n, unsigned param) {
    const sfb__level *l = &w->l;
    int base, k, patch;
    /* the builder's masks, grown once: a UV layout of placeholder values has vertices of
     * valence in the thousands, whose masks were allocated and freed at every cap */
    sfb__mask *mp = &b->cap[0], *m1 = &b->cap[1], *m2 = &b->cap[2];
    sfb_result er = SFB_SUCCESS;
    patch = sfb__pb_patch(b, n == 4 ? SFB__PATCH_ENDCAP : SFB__PATCH_ENDCAP_TRI, param, 0, 3 * n);
    if (patch < 0) return sfb__oom(b->ctx, "patch table");
    base = b->pt->pfirst[patch];
    for (k = 0; k < n && er == SFB_SUCCESS; ++k) {
        int v = l->fv[l->fv_off[g] + (rot + k) % n], r0, r1, r2, need = 3 * sfb__mask_need_vertex(l, v) + 8;
        mp->n = m1->n = m2->n = 0;
        if (!sfb__mask_grow(b->ctx, mp, need) || !sfb__mask_grow(b->ctx, m1, need) || !sfb__mask_grow(b->ctx, m2, need)) {
            er = sfb__oom(b->ctx, "patch points");
            break;
        }
        sfb__limit_masks(l, v, n == 4 ? SFB_SCHEME_CATMARK : SFB_SCHEME_LOOP, mp, m1, m2);
        r0 = sfb__pb_point(b, w->pos, mp);
        r1 = sfb__pb_point(b, w->pos, m1);
        r2 = sfb__pb_point(b, w->pos, m2);
        if (r0 < 0 || r1 < 0 || r2 < 0) er = sfb__oom(b->ctx, "patch points");
        b->pt->cv[base + k] = r0;
        b->pt->cv[base + n + 2 * k] = r1;
        b->pt->cv[base + n + 1 + 2 * k] = r2;
    }
    if (er != SFB_SUCCESS) return er;
    return sfb__pb_insert(b, w->fptex[g], param, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
}

/* A Stam-kind record (type STAM or STAM_LOOP, valence N) of K eigen-coefficient points, point i
 * = sum_m vinv[i K + m] C[m] over working-level vertices C; inserted at (ptex, param). Frees C. */
sfb_result sfb__pb_eigen_patch(sfb__pbuild *b, sfb__wlevel *w, int type, int ptex, unsigned param, int N, int K, const double *vinv,
                               int *C) {
    int patch = sfb__pb_patch(b, type, param, N, K), base, i, m;
    if (patch < 0 || !sfb__mask_grow(b->ctx, &b->m, K)) { sfb__free(b->ctx, C); return sfb__oom(b->ctx, "patch table"); }
    base = b->pt->pfirst[patch];
    for (i = 0; i < K; ++i) {
        int row;
        b->m.n = 0;
        for (m = 0; m < K; ++m) {
            double wgt = vinv[(size_t)i * K + m];
            if (wgt != 0.0) SFB__MASK_ADD(&b->m, C[m], wgt);
        }
        row = sfb__pb_point(b, w->pos, &b->m);
        if (row < 0) { sfb__free(b->ctx, C); return sfb__oom(b->ctx, "patch points"); }
        b->pt->cv[base + i] = row;
    }
    sfb__free(b->ctx, C);
    return sfb__pb_insert(b, ptex, param, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
}

/* The sub-mesh to refine: `mark` faces (active and their 1-ring), renumbered. */
static sfb_result sfb__pb_submesh(sfb_context *ctx, const sfb__wlevel *w, const unsigned char *mark, sfb__level *sub,
                                  int *vmap, int *emap, int *fmap, unsigned char *vcomp, unsigned char *ecomp) {
    const sfb__level *l = &w->l;
    int f, k, nv = 0, ne = 0, nf = 0, nfv = 0;
    sfb_result r;
    memset(sub, 0, sizeof *sub);
    for (k = 0; k < l->nv; ++k) vmap[k] = -1;
    for (k = 0; k < l->ne; ++k) emap[k] = -1;
    for (f = 0; f < l->nf; ++f) {
        fmap[f] = -1;
        if (!mark[f]) continue;
        fmap[f] = nf++;
        for (k = l->fv_off[f]; k < l->fv_off[f + 1]; ++k) {
            if (vmap[l->fv[k]] < 0) vmap[l->fv[k]] = nv++;
            if (emap[l->fe[k]] < 0) emap[l->fe[k]] = ne++;
            nfv++;
        }
    }
    sub->nv = nv; sub->ne = ne; sub->nf = nf; sub->nfv = nfv;
    sub->fv_off = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    sub->fv = (int *)sfb__alloc(ctx, ((size_t)nfv + 1) * sizeof(int));
    sub->fe = (int *)sfb__alloc(ctx, ((size_t)nfv + 1) * sizeof(int));
    sub->ev = (int *)sfb__alloc(ctx, ((size_t)ne * 2 + 1) * sizeof(int));
    sub->es = (float *)sfb__alloc(ctx, ((size_t)ne + 1) * sizeof(float));
    sub->vs = (float *)sfb__alloc(ctx, ((size_t)nv + 1) * sizeof(float));
    sub->fhole = (unsigned char *)sfb__calloc(ctx, (size_t)nf + 1, 1);
    if (!sub->fv_off || !sub->fv || !sub->fe || !sub->ev || !sub->es || !sub->vs || !sub->fhole) {
        sfb__level_free(ctx, sub);
        return sfb__oom(ctx, "adaptive refinement");
    }
    nfv = 0;
    for (f = 0; f < l->nf; ++f) {
        int sf = fmap[f];
        if (sf < 0) continue;
        sub->fv_off[sf] = nfv;
        sub->fhole[sf] = l->fhole[f];
        for (k = l->fv_off[f]; k < l->fv_off[f + 1]; ++k) {
            sub->fv[nfv] = vmap[l->fv[k]];
            sub->fe[nfv] = emap[l->fe[k]];
            nfv++;
        }
    }
    sub->fv_off[nf] = nfv;
    for (k = 0; k < l->ne; ++k)
        if (emap[k] >= 0) {
            sub->ev[2 * emap[k]] = vmap[l->ev[2 * k]];
            sub->ev[2 * emap[k] + 1] = vmap[l->ev[2 * k + 1]];
            sub->es[emap[k]] = l->es[k];
        }
    for (k = 0; k < l->nv; ++k)
        if (vmap[k] >= 0) sub->vs[vmap[k]] = l->vs[k];
    r = sfb__level_complete(ctx, sub);
    if (r != SFB_SUCCESS) { sfb__level_free(ctx, sub); return r; }
    sfb__level_compute_rules(sub);
    /* complete in the sub-mesh: complete before and nothing around it left out */
    for (k = 0; k < l->nv; ++k)
        if (vmap[k] >= 0)
            vcomp[vmap[k]] = w->vcomp[k] && (sub->vf_off[vmap[k] + 1] - sub->vf_off[vmap[k]] == l->vf_off[k + 1] - l->vf_off[k]);
    for (k = 0; k < l->ne; ++k)
        if (emap[k] >= 0)
            ecomp[emap[k]] = w->ecomp[k] && (sub->ef_off[emap[k] + 1] - sub->ef_off[emap[k]] == l->ef_off[k + 1] - l->ef_off[k]);
    return SFB_SUCCESS;
}

/* ---- the isolation driver ---- */

/* Parametric faces of the base level: one per quad (or triangle, tri), n per other n-gon. */
static sfb_result sfb__pb_param_faces(sfb_context *ctx, const sfb__level *base, int tri, sfb__patch_table *pt) {
    int f, k, nptex = 0;
    pt->face_ptex = (int *)sfb__alloc(ctx, ((size_t)base->nf + 1) * sizeof(int));
    if (!pt->face_ptex) return sfb__oom(ctx, "patch table");
    for (f = 0; f < base->nf; ++f) {
        pt->face_ptex[f] = nptex;
        nptex += (tri || sfb__face_n(base, f) == 4) ? 1 : sfb__face_n(base, f);
    }
    pt->face_ptex[base->nf] = nptex;
    pt->nptex = nptex;
    pt->ptex_face = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_corner = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_root = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    if (!pt->ptex_face || !pt->ptex_corner || !pt->ptex_root) return sfb__oom(ctx, "patch table");
    for (f = 0; f < base->nf; ++f)
        for (k = pt->face_ptex[f]; k < pt->face_ptex[f + 1]; ++k) {
            pt->ptex_face[k] = f;
            pt->ptex_corner[k] = (tri || sfb__face_n(base, f) == 4) ? -1 : k - pt->face_ptex[f];
            pt->ptex_root[k] = -1;
        }
    return SFB_SUCCESS;
}

/* Level 0: the base level with its positions in double, its faces the candidates, and the
 * builder's scratch (mask, vertex points; ps/cs for the refinement steps). */
static sfb_result sfb__pb_start(sfb__pbuild *b, sfb__wlevel *w, const sfb__level *base, int tri, const float *positions, float **ps,
                                float **cs) {
    sfb_context *ctx = b->ctx;
    int f;
    size_t k;
    w->l = *base;
    w->owns_level = 0;
    w->pos = (double *)sfb__alloc(ctx, ((size_t)base->nv + 1) * 3 * sizeof(double));
    w->fptex = (int *)sfb__alloc(ctx, ((size_t)base->nf + 1) * sizeof(int));
    w->fparam = (unsigned *)sfb__calloc(ctx, (size_t)base->nf + 1, sizeof(unsigned));
    w->vcomp = (unsigned char *)sfb__alloc(ctx, (size_t)base->nv + 1);
    w->ecomp = (unsigned char *)sfb__alloc(ctx, (size_t)base->ne + 1);
    *ps = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    *cs = (float *)sfb__alloc(ctx, (SFB_MAX_VALENCE + 2) * sizeof(float));
    b->vrow = (int *)sfb__alloc(ctx, ((size_t)base->nv + 1) * sizeof(int));
    if (!w->pos || !w->fptex || !w->fparam || !w->vcomp || !w->ecomp || !*ps || !*cs || !b->vrow || !sfb__mask_grow(ctx, &b->m, 64))
        return sfb__oom(ctx, "patch table");
    for (k = 0; k < 3 * (size_t)base->nv; ++k) w->pos[k] = (double)positions[k];
    memset(w->vcomp, 1, (size_t)base->nv + 1);
    memset(w->ecomp, 1, (size_t)base->ne + 1);
    for (f = 0; f < base->nf; ++f) w->fptex[f] = (tri || sfb__face_n(base, f) == 4) ? b->pt->face_ptex[f] : -1;
    return SFB_SUCCESS;
}

/* Classifies every candidate of the working level (patches added); the faces to refine go to
 * active[0 .. *nactive). At level 0 a Catmull-Clark n-gon is refined into its n quads. */
static sfb_result sfb__pb_classify(sfb__pbuild *b, sfb__wlevel *w, int level, int limit, int tri, int *active, int *nactive) {
    int f;
    sfb_result r;
    *nactive = 0;
    for (f = 0; f < w->l.nf; ++f) {
        int refine = 0;
        if (!tri && level == 0 && sfb__face_n(&w->l, f) != 4) {
            if (!w->l.fhole[f]) active[(*nactive)++] = f;
            continue;
        }
        if (w->fptex[f] < 0) continue;
        r = tri ? sfb__pb_face_tri(b, w, f, level, limit, &refine) : sfb__pb_face_quad(b, w, f, level, limit, &refine);
        if (r != SFB_SUCCESS) return r;
        if (refine) active[(*nactive)++] = f;
    }
    return SFB_SUCCESS;
}

/* Marks the active faces and their 1-ring (the faces the next level's masks read). */
static sfb_result sfb__pb_mark_ring(sfb_context *ctx, const sfb__wlevel *w, const int *active, int nactive, unsigned char *mark) {
    int k, q, i;
    for (k = 0; k < nactive; ++k) {
        int g = active[k];
        mark[g] = 1;
        for (q = w->l.fv_off[g]; q < w->l.fv_off[g + 1]; ++q) {
            int v = w->l.fv[q];
            if (!w->vcomp[v]) return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "adaptive isolation reached an incomplete vertex");
            for (i = w->l.vf_off[v]; i < w->l.vf_off[v + 1]; ++i) mark[w->l.vf[i]] = 1;
        }
    }
    return SFB_SUCCESS;
}

/* The positions of the sub-mesh's vertices (vmap: working-level vertex -> sub-mesh vertex). */
static double *sfb__pb_sub_pos(sfb_context *ctx, const sfb__wlevel *w, const int *vmap, int nsub) {
    int v, c;
    double *sp = (double *)sfb__alloc(ctx, ((size_t)nsub + 1) * 3 * sizeof(double));
    if (!sp) return NULL;
    for (v = 0; v < w->l.nv; ++v)
        if (vmap[v] >= 0)
            for (c = 0; c < 3; ++c) sp[3 * (size_t)vmap[v] + c] = w->pos[3 * (size_t)v + c];
    return sp;
}

/* Completeness flags and candidates of the child level nw of sub-mesh p: the children of the
 * active faces, with their parametric face and sub-square (see sfb__patch_locate). */
static sfb_result sfb__pb_children(sfb_context *ctx, const sfb__patch_table *pt, const sfb__wlevel *w, const sfb__level *p,
                                   sfb__wlevel *nw, const int *active, int nactive, const int *fmap, const unsigned char *vc,
                                   const unsigned char *ec, int level, int tri) {
    int v, e, f, k, nvf = tri ? 0 : p->nf; /* Loop has no face points */
    nw->fptex = (int *)sfb__alloc(ctx, ((size_t)nw->l.nf + 1) * sizeof(int));
    nw->fparam = (unsigned *)sfb__calloc(ctx, (size_t)nw->l.nf + 1, sizeof(unsigned));
    nw->vcomp = (unsigned char *)sfb__calloc(ctx, (size_t)nw->l.nv + 1, 1);
    nw->ecomp = (unsigned char *)sfb__calloc(ctx, (size_t)nw->l.ne + 1, 1);
    if (!nw->fptex || !nw->fparam || !nw->vcomp || !nw->ecomp) return sfb__oom(ctx, "adaptive refinement");
    for (v = 0; v < p->nv; ++v) nw->vcomp[v] = vc[v];
    for (f = 0; f < nvf; ++f) nw->vcomp[p->nv + f] = 1;
    for (e = 0; e < p->ne; ++e) {
        nw->vcomp[p->nv + nvf + e] = ec[e];
        nw->ecomp[2 * e] = nw->ecomp[2 * e + 1] = ec[e];
    }
    for (e = 2 * p->ne; e < nw->l.ne; ++e) nw->ecomp[e] = 1;
    for (f = 0; f < nw->l.nf; ++f) nw->fptex[f] = -1;
    for (k = 0; k < nactive; ++k) {
        int g = active[k], sf = fmap[g], o = p->fv_off[sf], n = p->fv_off[sf + 1] - o, i;
        unsigned par = w->fparam[g];
        if (tri) {
            /* children 4 sf + i: the corner at slot i (i < 3), the middle (i = 3) */
            int rot = SFB__PARAM_CORNER(par);
            for (i = 0; i < 4; ++i) {
                int c = i == 3 ? 3 : (i - rot + 3) % 3;
                int crot = i == 3 ? (rot + 1) % 3 : c == 0 ? 0 : c == 1 ? 2 : 1;
                nw->fptex[4 * sf + i] = w->fptex[g];
                nw->fparam[4 * sf + i] = SFB__PARAM(SFB__PARAM_DEPTH(par) + 1, 2 * SFB__PARAM_I(par) + (c & 1),
                                                    2 * SFB__PARAM_J(par) + (c >> 1), crot);
            }
            continue;
        }
        for (i = 0; i < n; ++i) {
            int cf = o + i;
            if (level == 0 && sfb__face_n(&w->l, g) != 4) {
                nw->fptex[cf] = pt->face_ptex[g] + i;
                nw->fparam[cf] = 0;
            } else {
                int rot = SFB__PARAM_CORNER(par), c = ((i - rot) % 4 + 4) % 4;
                int ox = (c == 1 || c == 2), oy = (c >= 2);
                nw->fptex[cf] = w->fptex[g];
                nw->fparam[cf] = SFB__PARAM(SFB__PARAM_DEPTH(par) + 1, 2 * SFB__PARAM_I(par) + ox, 2 * SFB__PARAM_J(par) + oy,
                                            ((rot - i) % 4 + 4) % 4);
            }
        }
    }
    return SFB_SUCCESS;
}

/* The next working level nw: the active faces and their 1-ring refined one step (positions
 * through the step's own masks, in double), with the children of the active faces as its
 * candidates. */
static sfb_result sfb__pb_next_level(sfb__pbuild *b, const sfb__refine_options *opt, const sfb__wlevel *w, sfb__wlevel *nw,
                                     const int *active, int nactive, int level, int tri, float *ps, float *cs) {
    sfb_context *ctx = b->ctx;
    const sfb__level *l = &w->l;
    unsigned char *mark, *vc, *ec;
    int *vmap, *emap, *fmap;
    sfb__level sub;
    sfb__rows local;
    double *subpos = NULL;
    sfb_result r;
    memset(&sub, 0, sizeof sub);
    memset(&local, 0, sizeof local);
    mark = (unsigned char *)sfb__calloc(ctx, (size_t)l->nf + 1, 1);
    vmap = (int *)sfb__alloc(ctx, ((size_t)l->nv + 1) * sizeof(int));
    emap = (int *)sfb__alloc(ctx, ((size_t)l->ne + 1) * sizeof(int));
    fmap = (int *)sfb__alloc(ctx, ((size_t)l->nf + 1) * sizeof(int));
    vc = (unsigned char *)sfb__alloc(ctx, (size_t)l->nv + 1);
    ec = (unsigned char *)sfb__alloc(ctx, (size_t)l->ne + 1);
    if (!mark || !vmap || !emap || !fmap || !vc || !ec) r = sfb__oom(ctx, "patch table");
    else r = sfb__pb_mark_ring(ctx, w, active, nactive, mark);
    if (r == SFB_SUCCESS) r = sfb__pb_submesh(ctx, w, mark, &sub, vmap, emap, fmap, vc, ec);
    if (r == SFB_SUCCESS && !(subpos = sfb__pb_sub_pos(ctx, w, vmap, sub.nv))) r = sfb__oom(ctx, "adaptive refinement");
    if (r == SFB_SUCCESS) {
        memset(nw, 0, sizeof *nw);
        r = sfb__refine_step_local(ctx, opt, &sub, NULL, &nw->l, NULL, &local, NULL, &b->m, ps, cs, 0.0f, 0.0f);
        nw->owns_level = 1;
    }
    if (r == SFB_SUCCESS) {
        int v;
        nw->pos = (double *)sfb__alloc(ctx, ((size_t)nw->l.nv + 1) * 3 * sizeof(double));
        if (!nw->pos) r = sfb__oom(ctx, "adaptive refinement");
        for (v = 0; r == SFB_SUCCESS && v < nw->l.nv; ++v)
            sfb__pb_combine(local.idx + local.off[v], local.w + local.off[v], local.off[v + 1] - local.off[v], subpos, nw->pos + 3 * (size_t)v);
    }
    if (r == SFB_SUCCESS) r = sfb__pb_children(ctx, b->pt, w, &sub, nw, active, nactive, fmap, vc, ec, level, tri);
    sfb__rows_free(ctx, &local);
    sfb__free(ctx, subpos);
    sfb__level_free(ctx, &sub);
    sfb__free(ctx, mark); sfb__free(ctx, vmap); sfb__free(ctx, emap); sfb__free(ctx, fmap); sfb__free(ctx, vc); sfb__free(ctx, ec);
    return r;
}

/* Catmull-Clark and Loop patch tables by feature-adaptive isolation (see the top of this file):
 * classify the working level's candidates, refine the ones left around them, repeat. */
sfb_result sfb__patches_build(sfb_context *ctx, const sfb__level *base, const sfb__refine_options *opt, int limit,
                              const float *positions, sfb__patch_table *pt) {
    sfb__pbuild b;
    sfb__wlevel w, nw;
    sfb_result r;
    float *ps = NULL, *cs = NULL;
    int level, k, *active = NULL, nactive = 0, tri = opt->scheme == SFB_SCHEME_LOOP;
    memset(&b, 0, sizeof b);
    memset(&w, 0, sizeof w);
    memset(&nw, 0, sizeof nw);
    memset(pt, 0, sizeof *pt);
    b.ctx = ctx;
    b.pt = pt;
    pt->domain = tri ? SFB__DOMAIN_TRI : SFB__DOMAIN_QUAD;
    pt->isolation = limit;
    r = sfb__pb_param_faces(ctx, base, tri, pt);
    if (r == SFB_SUCCESS) r = sfb__pb_start(&b, &w, base, tri, positions, &ps, &cs);
    for (level = 0; r == SFB_SUCCESS; ++level) {
        int k, *nv;
        r = sfb__progress(ctx, 0.8f + 0.15f * (float)level / (float)(SFB_MAX_LEVEL + 2), "patches");
        if (r != SFB_SUCCESS) break;
        for (k = 0; k < w.l.nv; ++k) b.vrow[k] = -1;
        sfb__free(ctx, active);
        active = (int *)sfb__alloc(ctx, ((size_t)w.l.nf + 1) * sizeof(int));
        if (!active) { r = sfb__oom(ctx, "patch table"); break; }
        r = sfb__pb_classify(&b, &w, level, limit, tri, active, &nactive);
        if (r != SFB_SUCCESS || nactive == 0) break;
        if (level > SFB_MAX_LEVEL + 1) {
            r = sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "adaptive isolation did not terminate");
            break;
        }
        r = sfb__pb_next_level(&b, opt, &w, &nw, active, nactive, level, tri, ps, cs);
        if (r != SFB_SUCCESS) break;
        sfb__wlevel_free(ctx, &w);
        w = nw;
        memset(&nw, 0, sizeof nw);
        nv = (int *)sfb__realloc(ctx, b.vrow, ((size_t)w.l.nv + 1) * sizeof(int));
        if (!nv) { r = sfb__oom(ctx, "patch table"); break; }
        b.vrow = nv;
        if (level + 1 > pt->max_depth) pt->max_depth = level + 1;
    }
    if (r == SFB_SUCCESS) {
        pt->npoints = b.npts;
        if (b.npts > 0) {
            /* the table takes the points, trimmed to their count (or as grown, if trimming fails) */
            float *trimmed = (float *)sfb__realloc(ctx, b.pts, (size_t)b.npts * 3 * sizeof(float));
            pt->point_data = trimmed ? trimmed : b.pts;
            b.pts = NULL;
        } else if (!(pt->point_data = (float *)sfb__alloc(ctx, 3 * sizeof(float)))) {
            r = sfb__oom(ctx, "patch points");
        }
    }
    sfb__wlevel_free(ctx, &w);
    sfb__wlevel_free(ctx, &nw);
    sfb__free(ctx, b.pts);
    sfb__free(ctx, b.m.idx); sfb__free(ctx, b.m.w);
    for (k = 0; k < 3; ++k) { sfb__free(ctx, b.cap[k].idx); sfb__free(ctx, b.cap[k].w); }
    sfb__free(ctx, b.vrow);
    sfb__free(ctx, ps); sfb__free(ctx, cs);
    sfb__free(ctx, active);
    if (r != SFB_SUCCESS) sfb__patch_table_free(ctx, pt);
    return r;
}
#line 1 "src/patch/quad.c"
/* The quad family's records (SFB__FAMILY_QUAD): BSPLINE16 (a regular quad, phantoms mirrored
 * across infinitely sharp creases), STAM (one smooth extraordinary corner, eigen form) and
 * ENDCAP (the bilinear cap at the isolation limit) -- how a candidate quad becomes one
 * (sfb__pb_face_quad, called by the isolation driver in patch/build.c) and their ref evaluation
 * (the sfb__kind_* evaluators that patch/table.c dispatches to). The GLSL kernel
 * (backends/gl/glsl/patches.comp.glsl) and the simd kernels evaluate the same records in float. */

/* Class of vertex v as a corner of quad g; *pos = g's fan position. */
static int sfb__corner_class(const sfb__level *l, int v, int g, int slot, int *pos) {
    int nF = l->vf_off[v + 1] - l->vf_off[v], nE = l->ve_off[v + 1] - l->ve_off[v];
    int e0 = l->ve_off[v], f0 = l->vf_off[v];
    int p = sfb__fan_pos(l, v, g, slot), i, nsharp = 0, ninf = 0, cyclic = nE == nF;
    int rule = l->vrule[v];
    float vs = l->vs[v];
    *pos = p;
    if (p < 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD)) return SFB__CORNER_IRREGULAR;
    for (i = 0; i < nE; ++i) {
        float s = l->es[l->ve[e0 + i]];
        nsharp += s > 0.0f;
        ninf += sfb__is_inf(s);
    }
    if (rule == SFB__RULE_SMOOTH && vs == 0.0f && nsharp == 0 && cyclic) {
        for (i = 0; i < nF; ++i)
            if (sfb__face_n(l, l->vf[f0 + i]) != 4) return SFB__CORNER_IRREGULAR;
        return nF == 4 ? SFB__CORNER_R1 : (nF >= 3 ? SFB__CORNER_EV : SFB__CORNER_IRREGULAR);
    }
    if (rule == SFB__RULE_CREASE && vs == 0.0f && nsharp == 2 && ninf == 2) {
        /* the sector of g: faces reachable without crossing a sharp edge */
        int e_d1 = l->ve[e0 + p], e_d2 = l->ve[e0 + (p + 1) % nE];
        if (!cyclic && p + 1 >= nE) return SFB__CORNER_IRREGULAR;
        if (sfb__face_n(l, g) != 4) return SFB__CORNER_IRREGULAR;
        if (sfb__is_inf(l->es[e_d1]) && !sfb__is_inf(l->es[e_d2])) {
            /* sector {g, next}: next face exists, is a quad, and the edge after it is sharp */
            int q = p + 1, e_next;
            if (q >= nF && !cyclic) return SFB__CORNER_IRREGULAR;
            q %= nF;
            e_next = l->ve[e0 + (p + 2) % nE];
            if (!cyclic && p + 2 >= nE) return SFB__CORNER_IRREGULAR;
            if (sfb__face_n(l, l->vf[f0 + q]) != 4 || !sfb__is_inf(l->es[e_next])) return SFB__CORNER_IRREGULAR;
            return SFB__CORNER_R2_D1; /* crease along d1 / -d1: phantoms at b = -1 */
        }
        if (!sfb__is_inf(l->es[e_d1]) && sfb__is_inf(l->es[e_d2])) {
            int q = p - 1, e_prev;
            if (q < 0 && !cyclic) return SFB__CORNER_IRREGULAR;
            q = (q + nF) % nF;
            e_prev = l->ve[e0 + (p - 1 + nE) % nE];
            if (!cyclic && p - 1 < 0) return SFB__CORNER_IRREGULAR;
            if (sfb__face_n(l, l->vf[f0 + q]) != 4 || !sfb__is_inf(l->es[e_prev])) return SFB__CORNER_IRREGULAR;
            return SFB__CORNER_R2_D2; /* crease along d2 / -d2: phantoms at a = -1 */
        }
        return SFB__CORNER_IRREGULAR;
    }
    if (rule == SFB__RULE_CORNER && (vs == 0.0f || sfb__is_inf(vs)) && nsharp == ninf) {
        int e_d1 = l->ve[e0 + p];
        int e_d2;
        if (!cyclic && p + 1 >= nE) return SFB__CORNER_IRREGULAR;
        e_d2 = l->ve[e0 + (p + 1) % nE];
        if (sfb__face_n(l, g) == 4 && sfb__is_inf(l->es[e_d1]) && sfb__is_inf(l->es[e_d2])) return SFB__CORNER_R3;
    }
    return SFB__CORNER_IRREGULAR;
}

static const int sfb__corner_pos[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

static const int sfb__corner_d1[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};

static const int sfb__corner_d2[4][2] = {{0, 1}, {-1, 0}, {0, -1}, {1, 0}};

static int sfb__diag(const sfb__level *l, int f, int v) {
    int o = l->fv_off[f], k;
    for (k = 0; k < 4; ++k)
        if (l->fv[o + k] == v) return l->fv[o + (k + 2) % 4];
    return -1;
}

/* The real points around corner vertex v (fan position p of g): local (a,b) -> vertex, for
 * the quadrants present (mask bit q: 0 = (+,+) g, 1 = (-,+), 2 = (-,-), 3 = (+,-)). */
static void sfb__corner_ring(const sfb__level *l, int v, int p, unsigned quads, int out[3][3]) {
    int e0 = l->ve_off[v], f0 = l->vf_off[v], nE = l->ve_off[v + 1] - e0, nF = l->vf_off[v + 1] - f0;
    int a, b;
#define SFB__EDGE(k) sfb__other_end(l, l->ve[e0 + ((p + (k)) % nE + nE) % nE], v)
#define SFB__FACE(k) l->vf[f0 + ((p + (k)) % nF + nF) % nF]
    for (a = 0; a < 3; ++a)
        for (b = 0; b < 3; ++b) out[a][b] = -1;
    out[1][1] = v;
    /* quadrant 0 (g) always: edges d1 (k=0) and d2 (k=1) */
    out[2][1] = SFB__EDGE(0);
    out[1][2] = SFB__EDGE(1);
    out[2][2] = sfb__diag(l, SFB__FACE(0), v);
    if (quads & 2u) { out[0][1] = SFB__EDGE(2); out[0][2] = sfb__diag(l, SFB__FACE(1), v); }
    if (quads & 4u) { out[0][1] = SFB__EDGE(2); out[1][0] = SFB__EDGE(3); out[0][0] = sfb__diag(l, SFB__FACE(2), v); }
    if (quads & 8u) { out[1][0] = SFB__EDGE(-1 + nE); out[2][0] = sfb__diag(l, SFB__FACE(-1 + nF), v); }
#undef SFB__EDGE
#undef SFB__FACE
}

/* Fills the 4x4 grid (cells x,y in -1..2 -> [y+1][x+1]) of quad g in the frame whose corner 0
 * is slot `rot`, for corners whose class is given (R1/R2/R3; skip = corner not gathered, for
 * the EV of a Stam patch). Returns 0 when the corners disagree. */
static int sfb__gather(const sfb__level *l, int g, int rot, const int cls[4], const int pos[4], int skip, sfb__cell grid[4][4]) {
    int k, a, b, x, y;
    for (y = 0; y < 4; ++y)
        for (x = 0; x < 4; ++x) grid[y][x].n = 0, grid[y][x].real = 0;
    /* real points first */
    for (k = 0; k < 4; ++k) {
        int ring[3][3], v;
        unsigned quads;
        if (k == skip) continue;
        v = l->fv[l->fv_off[g] + (rot + k) % 4];
        quads = cls[k] == SFB__CORNER_R1 ? 15u : cls[k] == SFB__CORNER_R2_D1 ? 3u : cls[k] == SFB__CORNER_R2_D2 ? 9u : 1u;
        sfb__corner_ring(l, v, pos[k], quads, ring);
        for (a = -1; a <= 1; ++a)
            for (b = -1; b <= 1; ++b) {
                int vv = ring[a + 1][b + 1];
                sfb__cell *c;
                if (vv < 0) continue;
                x = sfb__corner_pos[k][0] + a * sfb__corner_d1[k][0] + b * sfb__corner_d2[k][0];
                y = sfb__corner_pos[k][1] + a * sfb__corner_d1[k][1] + b * sfb__corner_d2[k][1];
                if (x < -1 || x > 2 || y < -1 || y > 2) continue;
                c = &grid[y + 1][x + 1];
                if (c->real && c->v[0] != vv) return 0;
                c->real = 1; c->n = 1; c->v[0] = vv; c->w[0] = 1.0;
            }
    }
    /* phantoms: mirror across the crease lines, corner by corner */
    for (k = 0; k < 4; ++k) {
        int pass;
        if (k == skip || cls[k] == SFB__CORNER_R1) continue;
        for (pass = 0; pass < 2; ++pass)
            for (a = -1; a <= 1; ++a)
                for (b = -1; b <= 1; ++b) {
                    int mirror_b = (cls[k] == SFB__CORNER_R2_D1 || cls[k] == SFB__CORNER_R3) && b == -1;
                    int mirror_a = (cls[k] == SFB__CORNER_R2_D2 || cls[k] == SFB__CORNER_R3) && a == -1;
                    int sa, sb, t;
                    sfb__cell *c, *p0, *p1;
                    /* pass 0: one mirrored index; pass 1: the (-1,-1) cell of R3 from pass-0 phantoms */
                    if (!(mirror_a || mirror_b) || (pass == 0) != !(mirror_a && mirror_b)) continue;
                    x = sfb__corner_pos[k][0] + a * sfb__corner_d1[k][0] + b * sfb__corner_d2[k][0];
                    y = sfb__corner_pos[k][1] + a * sfb__corner_d1[k][1] + b * sfb__corner_d2[k][1];
                    if (x < -1 || x > 2 || y < -1 || y > 2) continue;
                    c = &grid[y + 1][x + 1];
                    if (c->real) return 0;
                    if (c->n) continue;
                    /* P = 2 P(mirror line) - P(inside) along the mirrored direction */
                    if (mirror_b) { sa = a; sb = 0; }
                    else { sa = 0; sb = b; }
                    {
                        int x0 = sfb__corner_pos[k][0] + sa * sfb__corner_d1[k][0] + sb * sfb__corner_d2[k][0];
                        int y0 = sfb__corner_pos[k][1] + sa * sfb__corner_d1[k][1] + sb * sfb__corner_d2[k][1];
                        int ia = mirror_b ? a : 1, ib = mirror_b ? 1 : b;
                        int x1 = sfb__corner_pos[k][0] + ia * sfb__corner_d1[k][0] + ib * sfb__corner_d2[k][0];
                        int y1 = sfb__corner_pos[k][1] + ia * sfb__corner_d1[k][1] + ib * sfb__corner_d2[k][1];
                        p0 = &grid[y0 + 1][x0 + 1];
                        p1 = &grid[y1 + 1][x1 + 1];
                    }
                    if (!p0->n || !p1->n || p0->n + p1->n > 4) return 0;
                    c->n = 0;
                    for (t = 0; t < p0->n; ++t) { c->v[c->n] = p0->v[t]; c->w[c->n++] = 2.0 * p0->w[t]; }
                    for (t = 0; t < p1->n; ++t) { c->v[c->n] = p1->v[t]; c->w[c->n++] = -p1->w[t]; }
                }
    }
    return 1;
}

/* Classifies candidate g; adds its patch, or returns 1 in *refine. */
sfb_result sfb__pb_face_quad(sfb__pbuild *b, sfb__wlevel *w, int g, int level, int limit, int *refine) {
    const sfb__level *l = &w->l;
    unsigned par = w->fparam[g];
    int rot = SFB__PARAM_CORNER(par), ptex = w->fptex[g];
    int cls[4], pos[4], k, nev = 0, evk = -1, nirr = 0, patch;
    unsigned out_param;
    sfb__cell grid[4][4];
    *refine = 0;
    if (l->fhole[g]) return sfb__pb_insert(b, ptex, par & ~(3u << 30), -1) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    if (sfb__face_n(l, g) != 4) { *refine = 1; return SFB_SUCCESS; }
    for (k = 0; k < 4; ++k) {
        int slot = (rot + k) % 4, v = l->fv[l->fv_off[g] + slot];
        cls[k] = sfb__corner_class(l, v, g, slot, &pos[k]);
        if (cls[k] == SFB__CORNER_EV) { nev++; evk = k; }
        else if (cls[k] == SFB__CORNER_IRREGULAR) nirr++;
    }
    if (nirr == 0 && nev == 0 && sfb__gather(l, g, rot, cls, pos, -1, grid)) {
        int x, y, base;
        patch = sfb__pb_patch(b, SFB__PATCH_BSPLINE, par & ~(3u << 30), 0, 16);
        if (patch < 0) return sfb__oom(b->ctx, "patch table");
        base = b->pt->pfirst[patch];
        for (y = 0; y < 4; ++y)
            for (x = 0; x < 4; ++x) {
                sfb__cell *c = &grid[y][x];
                int t, row;
                b->m.n = 0;
                for (t = 0; t < c->n; ++t) SFB__MASK_ADD(&b->m, c->v[t], c->w[t]);
                row = sfb__pb_point(b, w->pos, &b->m);
                if (row < 0) return sfb__oom(b->ctx, "patch points");
                b->pt->cv[base + 4 * y + x] = row;
            }
        return sfb__pb_insert(b, ptex, par & ~(3u << 30), patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    }
    if (nev == 1 && nirr == 0 && cls[(evk + 1) % 4] == SFB__CORNER_R1 && cls[(evk + 2) % 4] == SFB__CORNER_R1 &&
        cls[(evk + 3) % 4] == SFB__CORNER_R1) {
        int ev = l->fv[l->fv_off[g] + (rot + evk) % 4];
        int N = l->vf_off[ev + 1] - l->vf_off[ev];
        const sfb__eigen_cc *e = sfb__eigen_cc_get(b->ctx, N);
        int scls[4], spos[4];
        if (e) {
            /* gather in the Stam frame: corner 0 = the EV */
            for (k = 0; k < 4; ++k) { scls[k] = cls[(evk + k) % 4]; spos[k] = pos[(evk + k) % 4]; }
            if (sfb__gather(l, g, (rot + evk) % 4, scls, spos, 0, grid)) {
                int K = e->K, i, pE = spos[0], e0 = l->ve_off[ev], f0 = l->vf_off[ev];
                int *C = (int *)sfb__alloc(b->ctx, (size_t)K * sizeof(int));
                static const int outer[7][2] = {{2, 2}, {2, 1}, {2, 0}, {2, -1}, {1, 2}, {0, 2}, {-1, 2}};
                if (!C) return sfb__oom(b->ctx, "patch table");
                C[0] = ev;
                for (i = 1; i <= N; ++i) {
                    int re = ((pE + (3 - i)) % N + N) % N, rf = ((pE + (2 - i)) % N + N) % N;
                    C[2 * i - 1] = sfb__other_end(l, l->ve[e0 + re], ev);
                    C[2 * i] = sfb__diag(l, l->vf[f0 + rf], ev);
                }
                for (i = 0; i < 7; ++i) {
                    sfb__cell *c = &grid[outer[i][1] + 1][outer[i][0] + 1];
                    C[2 * N + 1 + i] = (c->real && c->n == 1) ? c->v[0] : -1;
                }
                for (i = 0; i < K; ++i)
                    if (C[i] < 0) { sfb__free(b->ctx, C); C = NULL; break; }
                if (C) {
                    out_param = SFB__PARAM(SFB__PARAM_DEPTH(par), SFB__PARAM_I(par), SFB__PARAM_J(par), evk);
                    b->pt->eig[N] = e; /* the context's cache outlives the surface */
                    return sfb__pb_eigen_patch(b, w, SFB__PATCH_STAM, ptex, out_param, N, K, e->vinv, C);
                }
            }
        }
    }
    if ((level >= limit && !sfb__face_semisharp(l, g)) || level >= SFB_MAX_LEVEL + 1)
        return sfb__pb_endcap(b, w, g, rot, 4, par & ~(3u << 30));
    *refine = 1;
    return SFB_SUCCESS;
}

/* ---- ref evaluation ---- */

void sfb__bspline_basis(double t, double *b, double *d, double *dd) {
    double t2 = t * t, t3 = t2 * t, s = 1.0 - t;
    b[0] = s * s * s / 6.0; b[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0; b[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0; b[3] = t3 / 6.0;
    d[0] = -0.5 * s * s; d[1] = 1.5 * t2 - 2.0 * t; d[2] = -1.5 * t2 + t + 0.5; d[3] = 0.5 * t2;
    dd[0] = s; dd[1] = 3.0 * t - 2.0; dd[2] = -3.0 * t + 1.0; dd[3] = t;
}

/* res[0..5]: P, Ps, Pt, Pss, Pst, Ptt in the patch's (s,t); nrm: an unnormalised normal
 * direction (a positive multiple of Ps x Pt, finite where Ps x Pt under- or overflows). */
void sfb__eval_bspline16(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    double bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4];
    int i, j, c;
    sfb__bspline_basis(s, bu, du, ddu);
    sfb__bspline_basis(t, bv, dv, ddv);
    memset(res, 0, sizeof(double) * 18);
    for (j = 0; j < 4; ++j)
        for (i = 0; i < 4; ++i) {
            const float *p = pts + 3 * (size_t)cv[4 * j + i];
            double w[6];
            w[0] = bu[i] * bv[j]; w[1] = du[i] * bv[j]; w[2] = bu[i] * dv[j];
            w[3] = ddu[i] * bv[j]; w[4] = du[i] * dv[j]; w[5] = bu[i] * ddv[j];
            for (c = 0; c < 3; ++c) {
                int q;
                for (q = 0; q < 6; ++q) res[q][c] += w[q] * p[c];
            }
        }
}

void sfb__eval_endcap(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    const float *p0 = pts + 3 * (size_t)cv[0], *p1 = pts + 3 * (size_t)cv[1], *p2 = pts + 3 * (size_t)cv[2], *p3 = pts + 3 * (size_t)cv[3];
    int c;
    for (c = 0; c < 3; ++c) {
        res[0][c] = (1 - s) * (1 - t) * p0[c] + s * (1 - t) * p1[c] + s * t * p2[c] + (1 - s) * t * p3[c];
        res[1][c] = (1 - t) * ((double)p1[c] - p0[c]) + t * ((double)p2[c] - p3[c]);
        res[2][c] = (1 - s) * ((double)p3[c] - p0[c]) + s * ((double)p2[c] - p1[c]);
        res[3][c] = 0.0;
        res[4][c] = (double)p0[c] - p1[c] + p2[c] - p3[c];
        res[5][c] = 0.0;
    }
}

/* Stam: (s,t) in the patch, the EV at frame corner `corner`. nres[2] gets the derivatives
 * divided by sub^(n-1) 2^n (a finite tangent frame down to the EV). nw = 3 computes P and the
 * first derivatives only (res[3..5] = 0), nw = 6 the second derivatives too. Powers are
 * integer powers (repeated squaring), so every backend that calls this gets ref's very sums
 * (the simd backend does, for the locations nearer the EV than its packed levels). */
void sfb__eval_stam(const sfb__eigen_cc *e, const float *pts, const int *cv, int corner, double s, double t, int nw,
                    double res[6][3], double nres[2][3]) {
    int K = e->K, i, j, c, k, n = 1, at_ev, m;
    double u, v, J[2][2], bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4], uu, vv, w[6][16];
    double sr[6][3], nr[2][3], sc1, sc2;
    const double *phi;
    switch (corner) {
    default: u = s; v = t; J[0][0] = 1; J[0][1] = 0; J[1][0] = 0; J[1][1] = 1; break;
    case 1: u = t; v = 1.0 - s; J[0][0] = 0; J[0][1] = 1; J[1][0] = -1; J[1][1] = 0; break;
    case 2: u = 1.0 - s; v = 1.0 - t; J[0][0] = -1; J[0][1] = 0; J[1][0] = 0; J[1][1] = -1; break;
    case 3: u = 1.0 - t; v = s; J[0][0] = 0; J[0][1] = -1; J[1][0] = 1; J[1][1] = 0; break;
    }
    /* J[a][b] = d(u,v)_a / d(s,t)_b */
    memset(sr, 0, sizeof sr);
    memset(nr, 0, sizeof nr);
    at_ev = (u == 0.0 && v == 0.0);
    if (at_ev) {
        /* the limit point; tangents: the n -> infinity limit of the normalised derivatives */
        k = 2; uu = 0.0; vv = 0.0;
    } else {
        while (u < 0.5 && v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
        if (v < 0.5) { k = 1; uu = 2.0 * u - 1.0; vv = 2.0 * v; }
        else if (u < 0.5) { k = 3; uu = 2.0 * u; vv = 2.0 * v - 1.0; }
        else { k = 2; uu = 2.0 * u - 1.0; vv = 2.0 * v - 1.0; }
    }
    sfb__bspline_basis(uu, bu, du, ddu);
    sfb__bspline_basis(vv, bv, dv, ddv);
    for (j = 0; j < 16; ++j) {
        const int a = j % 4, b = j / 4;
        w[0][j] = bu[a] * bv[b]; w[1][j] = du[a] * bv[b]; w[2][j] = bu[a] * dv[b];
        w[3][j] = ddu[a] * bv[b]; w[4][j] = du[a] * dv[b]; w[5][j] = bu[a] * ddv[b];
    }
    phi = e->phi + (size_t)(k - 1) * 16 * K;
    m = n - 1;
    for (i = 0; i < K; ++i) {
        double f[6] = {0, 0, 0, 0, 0, 0}, lp, ln;
        const float *p = pts + 3 * (size_t)cv[i];
        const double *ph = phi + i;
        /* the eigenbasis function i and its derivatives at (uu, vv); named accumulators keep
         * the sums in registers */
        if (nw <= 3) {
            double f0 = 0.0, f1 = 0.0, f2 = 0.0;
            for (j = 0; j < 16; ++j, ph += K) { f0 += w[0][j] * *ph; f1 += w[1][j] * *ph; f2 += w[2][j] * *ph; }
            f[0] = f0; f[1] = f1; f[2] = f2;
        } else {
            double f0 = 0.0, f1 = 0.0, f2 = 0.0, f3 = 0.0, f4 = 0.0, f5 = 0.0;
            for (j = 0; j < 16; ++j, ph += K) {
                f0 += w[0][j] * *ph; f1 += w[1][j] * *ph; f2 += w[2][j] * *ph;
                f3 += w[3][j] * *ph; f4 += w[4][j] * *ph; f5 += w[5][j] * *ph;
            }
            f[0] = f0; f[1] = f1; f[2] = f2; f[3] = f3; f[4] = f4; f[5] = f5;
        }
        if (at_ev) {
            lp = i == e->dominant ? 1.0 : 0.0;
            ln = (i != e->dominant && fabs(fabs(e->lambda[i]) - e->sub) <= 1e-12) ? 1.0 : 0.0;
        } else {
            /* position: lambda^(n-1); derivatives normalised by sub^(n-1) (finite down to the EV) */
            lp = sfb__ipow(e->lambda[i], m);
            ln = i == e->dominant ? 0.0 : sfb__ipow(e->lambda[i] / e->sub, m);
        }
        for (c = 0; c < 3; ++c) {
            sr[0][c] += lp * f[0] * p[c];
            nr[0][c] += ln * f[1] * p[c];
            nr[1][c] += ln * f[2] * p[c];
            sr[3][c] += ln * f[3] * p[c];
            sr[4][c] += ln * f[4] * p[c];
            sr[5][c] += ln * f[5] * p[c];
        }
    }
    sc1 = at_ev ? 1.0 : sfb__ipow(e->sub, m) * ldexp(1.0, n);
    sc2 = at_ev || nw <= 3 ? 0.0 : sfb__ipow(e->sub, m) * ldexp(1.0, 2 * n);
    sfb__stam_finish(J, sc1, sc2, sr, nr, res, nres);
}

/* The Stam kind's evaluator (sfb__patch_kind, patch/table.c): res and the normalised tangent frame. */
void sfb__kind_stam(const sfb__patch_table *pt, const float *pts, int patch, const int *cv, double s, double t, double res[6][3],
                    double dir[2][3]) {
    sfb__eval_stam(pt->eig[pt->pvalence[patch]], pts, cv, SFB__PARAM_CORNER(pt->pparam[patch]), s, t, 6, res, dir);
}
#line 1 "src/patch/tri.c"
/* The triangle family's records (SFB__FAMILY_TRI): BEZTRI15 (a regular triangle: its box
 * spline as a quartic Bezier triangle by Sabin's rules), STAM_LOOP (one smooth extraordinary
 * corner, eigen form) and ENDCAP_TRI (the linear cap at the isolation limit) -- how a candidate
 * triangle becomes one (sfb__pb_face_tri) and their ref evaluation (sfb__kind_*).
 *
 * A corner of a triangle is R1 (smooth valence 6, no sharp edge), EV (smooth, valence 3..256,
 * no sharp edge), R2 (a crease vertex, two infinitely sharp edges, whose sector on this face's
 * side has 3 triangles) or R3 (a corner whose sector is this triangle alone). In the lattice of
 * the regular triangulation the face's param corners are at (0,0), (1,0), (0,1); corner k's
 * ring, counter-clockwise from the next corner, runs along the lattice directions
 * sfb__hexdir[2k], [2k+1], ... Points missing across a crease are phantoms: X = A + B - C for
 * the real triangle (A,B,C) across the edge AB from X, and X = 2A - B opposite a real neighbour B
 * at a corner (the points that make the box spline's boundary the crease's cubic B-spline, as
 * for OpenSubdiv's regular Loop boundary patches). */

static const int sfb__hexdir[6][2] = {{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}};

static const int sfb__tri_origin[3][2] = {{0, 0}, {1, 0}, {0, 1}};

/* Class of vertex v as a corner of triangle g; *pos = g's fan position; *sec = offset (from
 * *pos) of the first edge of g's sector for R2 (-2..0), 0 for R3. */
static int sfb__tri_corner_class(const sfb__level *l, int v, int g, int slot, int *pos, int *sec) {
    int nF = l->vf_off[v + 1] - l->vf_off[v], nE = l->ve_off[v + 1] - l->ve_off[v];
    int e0 = l->ve_off[v], f0 = l->vf_off[v];
    int p = sfb__fan_pos(l, v, g, slot), i, nsharp = 0, ninf = 0, cyclic = nE == nF;
    int rule = l->vrule[v];
    float vs = l->vs[v];
    *pos = p;
    *sec = 0;
    if (p < 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD)) return SFB__CORNER_IRREGULAR;
    for (i = 0; i < nE; ++i) {
        float s = l->es[l->ve[e0 + i]];
        nsharp += s > 0.0f;
        ninf += sfb__is_inf(s);
    }
    if (rule == SFB__RULE_SMOOTH && vs == 0.0f && nsharp == 0 && cyclic) {
        for (i = 0; i < nF; ++i)
            if (sfb__face_n(l, l->vf[f0 + i]) != 3) return SFB__CORNER_IRREGULAR;
        return nF == 6 ? SFB__CORNER_R1 : (nF >= 3 ? SFB__CORNER_EV : SFB__CORNER_IRREGULAR);
    }
#define SFB__TE(k) l->es[l->ve[e0 + ((p + (k)) % nE + nE) % nE]]
#define SFB__TIN(k, n) (cyclic || (p + (k) >= 0 && p + (k) < (n)))
    if (rule == SFB__RULE_CREASE && vs == 0.0f && nsharp == 2 && ninf == 2) {
        int st;
        for (st = 0; st >= -2; --st) {
            if (!SFB__TIN(st, nE)) return SFB__CORNER_IRREGULAR;
            if (sfb__is_inf(SFB__TE(st))) break;
        }
        if (st < -2) return SFB__CORNER_IRREGULAR;
        for (i = 0; i < 3; ++i) {
            if (!SFB__TIN(st + i, nF) || sfb__face_n(l, l->vf[f0 + ((p + st + i) % nF + nF) % nF]) != 3) return SFB__CORNER_IRREGULAR;
            if (i > 0 && SFB__TE(st + i) > 0.0f) return SFB__CORNER_IRREGULAR;
        }
        if (!SFB__TIN(st + 3, nE) || !sfb__is_inf(SFB__TE(st + 3))) return SFB__CORNER_IRREGULAR;
        *sec = st;
        return SFB__CORNER_R2_D1;
    }
    if (rule == SFB__RULE_CORNER && (vs == 0.0f || sfb__is_inf(vs)) && nsharp == ninf) {
        if (!SFB__TIN(1, nE) || sfb__face_n(l, g) != 3) return SFB__CORNER_IRREGULAR;
        if (sfb__is_inf(SFB__TE(0)) && sfb__is_inf(SFB__TE(1))) return SFB__CORNER_R3;
    }
#undef SFB__TE
#undef SFB__TIN
    return SFB__CORNER_IRREGULAR;
}

/* Fills grid[y+1][x+1] (x, y in -1..3) with the box-spline points of triangle g in the frame
 * whose corner 0 is slot `rot`; corner `skip` (the EV of a Stam patch) is not gathered.
 * Returns 0 when the corners disagree. */
static int sfb__gather_tri(const sfb__level *l, int g, int rot, const int cls[3], const int pos[3], const int sec[3], int skip,
                           sfb__cell grid[5][5]) {
    int k, x, y;
    for (y = 0; y < 5; ++y)
        for (x = 0; x < 5; ++x) grid[y][x].n = 0, grid[y][x].real = 0;
#define SFB__CELL(d) grid[sfb__tri_origin[k][1] + sfb__hexdir[((2 * k + (d)) % 6 + 6) % 6][1] + 1] \
                         [sfb__tri_origin[k][0] + sfb__hexdir[((2 * k + (d)) % 6 + 6) % 6][0] + 1]
    for (k = 0; k < 3; ++k) {
        int v, e0, nE, lo, hi, d;
        sfb__cell *c;
        if (k == skip) continue;
        v = l->fv[l->fv_off[g] + (rot + k) % 3];
        e0 = l->ve_off[v];
        nE = l->ve_off[v + 1] - e0;
        lo = cls[k] == SFB__CORNER_R1 ? 0 : sec[k];
        hi = cls[k] == SFB__CORNER_R1 ? 5 : cls[k] == SFB__CORNER_R3 ? 1 : sec[k] + 3;
        c = &grid[sfb__tri_origin[k][1] + 1][sfb__tri_origin[k][0] + 1];
        if (c->real && c->v[0] != v) return 0;
        c->real = 1; c->n = 1; c->v[0] = v; c->w[0] = 1.0;
        for (d = lo; d <= hi; ++d) {
            int vv = sfb__other_end(l, l->ve[e0 + ((pos[k] + d) % nE + nE) % nE], v);
            c = &SFB__CELL(d);
            if (c->real && c->v[0] != vv) return 0;
            c->real = 1; c->n = 1; c->v[0] = vv; c->w[0] = 1.0;
        }
    }
    for (k = 0; k < 3; ++k) {
        int lo, hi, d;
        if (k == skip || cls[k] == SFB__CORNER_R1) continue;
        lo = sec[k];
        hi = cls[k] == SFB__CORNER_R3 ? 1 : sec[k] + 3;
        for (d = hi + 1; d <= lo + 5; ++d) {
            sfb__cell *c = &SFB__CELL(d), *B, *C = NULL;
            const sfb__cell *A = &grid[sfb__tri_origin[k][1] + 1][sfb__tri_origin[k][0] + 1]; /* the corner itself */
            if (c->real) return 0;
            if (c->n) continue;
            if (d == hi + 1) { B = &SFB__CELL(hi); C = &SFB__CELL(hi - 1); }
            else if (d == lo + 5) { B = &SFB__CELL(lo); C = &SFB__CELL(lo + 1); }
            else if (d == hi + 2) B = &SFB__CELL(lo);     /* R3: opposite the first edge */
            else B = &SFB__CELL(hi);                      /* R3: opposite the second edge */
            c->n = 0;
            if (C) {
                c->v[c->n] = A->v[0]; c->w[c->n++] = 1.0;
                c->v[c->n] = B->v[0]; c->w[c->n++] = 1.0;
                c->v[c->n] = C->v[0]; c->w[c->n++] = -1.0;
            } else {
                c->v[c->n] = A->v[0]; c->w[c->n++] = 2.0;
                c->v[c->n] = B->v[0]; c->w[c->n++] = -1.0;
            }
        }
    }
#undef SFB__CELL
    return 1;
}

/* Adds one point: the combination sum_i w[i]/24 cell(box12[i]) of the grid (Sabin's rules). */
static int sfb__pb_bez_point(sfb__pbuild *b, const double *pos, sfb__cell grid[5][5], const unsigned char w[12]) {
    int i, t;
    b->m.n = 0;
    for (i = 0; i < 12; ++i) {
        const sfb__cell *c = &grid[sfb__box12[i][1] + 1][sfb__box12[i][0] + 1];
        if (!w[i]) continue;
        for (t = 0; t < c->n; ++t) SFB__MASK_ADD(&b->m, c->v[t], c->w[t] * w[i] / 24.0);
    }
    return sfb__pb_point(b, pos, &b->m);
}

/* Classifies candidate triangle g; adds its patch, or returns 1 in *refine. */
sfb_result sfb__pb_face_tri(sfb__pbuild *b, sfb__wlevel *w, int g, int level, int limit, int *refine) {
    const sfb__level *l = &w->l;
    unsigned par = w->fparam[g], plain = par & ~(3u << 30);
    int rot = SFB__PARAM_CORNER(par), ptex = w->fptex[g];
    int cls[3], pos[3], sec[3], k, nev = 0, evk = -1, nirr = 0, patch, base, j;
    sfb__cell grid[5][5];
    *refine = 0;
    if (l->fhole[g]) return sfb__pb_insert(b, ptex, plain, -1) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    if (sfb__face_n(l, g) != 3) { *refine = 1; return SFB_SUCCESS; }
    for (k = 0; k < 3; ++k) {
        int slot = (rot + k) % 3, v = l->fv[l->fv_off[g] + slot];
        cls[k] = sfb__tri_corner_class(l, v, g, slot, &pos[k], &sec[k]);
        if (cls[k] == SFB__CORNER_EV) { nev++; evk = k; }
        else if (cls[k] == SFB__CORNER_IRREGULAR) nirr++;
    }
    if (nirr == 0 && nev == 0 && sfb__gather_tri(l, g, rot, cls, pos, sec, -1, grid)) {
        patch = sfb__pb_patch(b, SFB__PATCH_BEZTRI, plain, 0, 15);
        if (patch < 0) return sfb__oom(b->ctx, "patch table");
        base = b->pt->pfirst[patch];
        for (j = 0; j < 15; ++j) {
            int row = sfb__pb_bez_point(b, w->pos, grid, sfb__bez15_from_box[j]);
            if (row < 0) return sfb__oom(b->ctx, "patch points");
            b->pt->cv[base + j] = row;
        }
        return sfb__pb_insert(b, ptex, plain, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    }
    if (nev == 1 && nirr == 0 && cls[(evk + 1) % 3] == SFB__CORNER_R1 && cls[(evk + 2) % 3] == SFB__CORNER_R1) {
        int ev = l->fv[l->fv_off[g] + (rot + evk) % 3];
        int N = l->vf_off[ev + 1] - l->vf_off[ev];
        const sfb__eigen_loop *e = sfb__eigen_loop_get(b->ctx, N);
        int scls[3], spos[3], ssec[3];
        for (k = 0; k < 3; ++k) { scls[k] = cls[(evk + k) % 3]; spos[k] = pos[(evk + k) % 3]; ssec[k] = sec[(evk + k) % 3]; }
        if (e && sfb__gather_tri(l, g, (rot + evk) % 3, scls, spos, ssec, 0, grid)) {
            static const int outer[5][2] = {{1, 1}, {2, 0}, {2, -1}, {0, 2}, {-1, 2}};
            int K = e->K, i, e0 = l->ve_off[ev], ok = 1;
            int *C = (int *)sfb__alloc(b->ctx, (size_t)K * sizeof(int));
            unsigned sp = SFB__PARAM(SFB__PARAM_DEPTH(par), SFB__PARAM_I(par), SFB__PARAM_J(par), evk);
            if (!C) return sfb__oom(b->ctx, "patch table");
            C[0] = ev;
            for (i = 0; i < N; ++i) C[1 + i] = sfb__other_end(l, l->ve[e0 + (spos[0] + i) % N], ev);
            for (i = 0; i < 5; ++i) {
                sfb__cell *c = &grid[outer[i][1] + 1][outer[i][0] + 1];
                C[N + 1 + i] = (c->real && c->n == 1) ? c->v[0] : -1;
                ok &= C[N + 1 + i] >= 0;
            }
            /* the regular corners' rings must close around the EV's ring as the lattice says */
            ok &= grid[1][1].real && grid[1][1].v[0] == ev && grid[1][2].v[0] == C[1] && grid[2][1].v[0] == C[2] &&
                  grid[0][2].real && grid[0][2].v[0] == C[N] && grid[2][0].real && grid[2][0].v[0] == C[1 + 2 % N];
            if (ok) {
                b->pt->eigl[N] = e;
                return sfb__pb_eigen_patch(b, w, SFB__PATCH_STAM_LOOP, ptex, sp, N, K, e->vinv, C);
            }
            sfb__free(b->ctx, C);
        }
    }
    if ((level >= limit && !sfb__face_semisharp(l, g)) || level >= SFB_MAX_LEVEL + 1)
        return sfb__pb_endcap(b, w, g, rot, 3, plain);
    *refine = 1;
    return SFB_SUCCESS;
}

/* ---- ref evaluation ---- */

/* Quartic Bernstein basis on a triangle, our point order (row by row in t, s rising in a
 * row): B[0..5][15] = value, d/ds, d/dt, d2/ds2, d2/dsdt, d2/dt2 (the last three only when
 * nw = 6; nw = 3 leaves them unset). Powers up to 4 of s, t and w = 1 - s - t from tables, and
 * the binomial weights 4! / (i! j! k!). */
void sfb__bez15_basis(double s, double t, int nw, double B[6][15]) {
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
            /* s^a t^b w^e, 0 for a negative exponent */
#define SFB__M(a, b, e) ((a) < 0 || (b) < 0 || (e) < 0 ? 0.0 : ps[(a) < 0 ? 0 : (a)] * pt[(b) < 0 ? 0 : (b)] * pw[(e) < 0 ? 0 : (e)])
            B[0][q] = c * SFB__M(i, j, k);
            B[1][q] = c * (i * SFB__M(i - 1, j, k) - k * SFB__M(i, j, k - 1));
            B[2][q] = c * (j * SFB__M(i, j - 1, k) - k * SFB__M(i, j, k - 1));
            if (nw > 3) {
                B[3][q] = c * (i * (i - 1) * SFB__M(i - 2, j, k) - 2 * i * k * SFB__M(i - 1, j, k - 1) + k * (k - 1) * SFB__M(i, j, k - 2));
                B[4][q] = c * (i * j * SFB__M(i - 1, j - 1, k) - i * k * SFB__M(i - 1, j, k - 1) - j * k * SFB__M(i, j - 1, k - 1) +
                               k * (k - 1) * SFB__M(i, j, k - 2));
                B[5][q] = c * (j * (j - 1) * SFB__M(i, j - 2, k) - 2 * j * k * SFB__M(i, j - 1, k - 1) + k * (k - 1) * SFB__M(i, j, k - 2));
            }
#undef SFB__M
        }
}

void sfb__eval_beztri(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    double B[6][15];
    int j, q, c;
    sfb__bez15_basis(s, t, 6, B);
    memset(res, 0, sizeof(double) * 18);
    for (j = 0; j < 15; ++j) {
        const float *p = pts + 3 * (size_t)cv[j];
        for (q = 0; q < 6; ++q)
            for (c = 0; c < 3; ++c) res[q][c] += B[q][j] * p[c];
    }
}

void sfb__eval_endcap_tri(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    const float *p0 = pts + 3 * (size_t)cv[0], *p1 = pts + 3 * (size_t)cv[1], *p2 = pts + 3 * (size_t)cv[2];
    int c;
    memset(res, 0, sizeof(double) * 18);
    for (c = 0; c < 3; ++c) {
        res[0][c] = (1 - s - t) * p0[c] + s * p1[c] + t * p2[c];
        res[1][c] = (double)p1[c] - p0[c];
        res[2][c] = (double)p2[c] - p0[c];
    }
}

/* Stam-Loop: (s,t) in the patch, the EV at frame corner `corner`; nw, nres and the powers as
 * sfb__eval_stam (the Jordan term of valence 3 included). */
void sfb__eval_stam_loop(const sfb__eigen_loop *e, const float *pts, const int *cv, int corner, double s, double t, int nw,
                         double res[6][3], double nres[2][3]) {
    int K = e->K, i, j, c, k, n = 1, at_ev, m, q;
    double u, v, J[2][2], B[6][15], ss, tt, sign = 1.0, subm, sc1, sc2;
    double sr[6][3], nr[2][3];
    double f[SFB__STAM_MAX_VALENCE + 6][6];
    const double *phi;
    if (nw > 3) nw = 6; else nw = 3;
    switch (corner) {
    default: u = s; v = t; J[0][0] = 1; J[0][1] = 0; J[1][0] = 0; J[1][1] = 1; break;
    case 1: u = t; v = 1.0 - s - t; J[0][0] = 0; J[0][1] = 1; J[1][0] = -1; J[1][1] = -1; break;
    case 2: u = 1.0 - s - t; v = s; J[0][0] = -1; J[0][1] = -1; J[1][0] = 1; J[1][1] = 0; break;
    }
    if (u < 0.0) u = 0.0;
    if (v < 0.0) v = 0.0;
    memset(sr, 0, sizeof sr);
    memset(nr, 0, sizeof nr);
    at_ev = u + v == 0.0;
    if (at_ev) {
        /* the limit point; tangents: the normalised derivatives' limit, which only the
         * subdominant pair reaches (evaluated anywhere in a sub-patch: the same plane) */
        k = 0; ss = 0.25; tt = 0.25;
    } else {
        while (u + v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
        if (u >= 0.5) { k = 0; ss = 2.0 * u - 1.0; tt = 2.0 * v; }
        else if (v >= 0.5) { k = 1; ss = 2.0 * u; tt = 2.0 * v - 1.0; }
        else { k = 2; ss = 1.0 - 2.0 * u; tt = 1.0 - 2.0 * v; sign = -1.0; }
    }
    m = n - 1;
    sfb__bez15_basis(ss, tt, nw, B);
    phi = e->phi + (size_t)k * 15 * K;
    for (i = 0; i < K; ++i) {
        /* eigenbasis function i and its derivatives at (ss, tt); named accumulators keep the
         * sums in registers */
        const double *ph = phi + i;
        double f0 = 0.0, f1 = 0.0, f2 = 0.0, f3 = 0.0, f4 = 0.0, f5 = 0.0;
        if (nw == 3) {
            for (j = 0; j < 15; ++j, ph += K) { f0 += B[0][j] * *ph; f1 += B[1][j] * *ph; f2 += B[2][j] * *ph; }
        } else {
            for (j = 0; j < 15; ++j, ph += K) {
                f0 += B[0][j] * *ph; f1 += B[1][j] * *ph; f2 += B[2][j] * *ph;
                f3 += B[3][j] * *ph; f4 += B[4][j] * *ph; f5 += B[5][j] * *ph;
            }
        }
        f[i][0] = f0; f[i][1] = f1; f[i][2] = f2; f[i][3] = f3; f[i][4] = f4; f[i][5] = f5;
    }
    subm = sfb__ipow(e->sub, m);
    for (i = 0; i < K; ++i) {
        const float *p = pts + 3 * (size_t)cv[i];
        double g[6];
        for (q = 0; q < 6; ++q) g[q] = 0.0;
        if (at_ev) {
            g[0] = i == e->dominant ? f[i][0] : 0.0;
            if (i != e->dominant && fabs(e->lambda[i] - e->sub) <= 1e-12)
                for (q = 1; q < 3; ++q) g[q] = f[i][q];
        } else {
            /* position: lambda^m; derivatives normalised by sub^m (finite down to the EV) */
            const double lp = sfb__ipow(e->lambda[i], m), ln = i == e->dominant ? 0.0 : sfb__ipow(e->lambda[i] / e->sub, m);
            g[0] = lp * f[i][0];
            for (q = 1; q < nw; ++q) g[q] = ln * f[i][q];
            if (e->head[i] >= 0 && m > 0) {
                /* the second vector of a Jordan block: m lambda^(m-1) of its head's function */
                const int h = e->head[i];
                const double jl = m * sfb__ipow(e->lambda[i], m - 1), jn = jl / subm;
                g[0] += jl * f[h][0];
                for (q = 1; q < nw; ++q) g[q] += jn * f[h][q];
            }
        }
        for (c = 0; c < 3; ++c) {
            sr[0][c] += g[0] * p[c];
            nr[0][c] += g[1] * p[c];
            nr[1][c] += g[2] * p[c];
            sr[3][c] += g[3] * p[c];
            sr[4][c] += g[4] * p[c];
            sr[5][c] += g[5] * p[c];
        }
    }
    for (c = 0; c < 3; ++c) { nr[0][c] *= sign; nr[1][c] *= sign; } /* the middle sub-patch is turned */
    sc1 = at_ev ? 1.0 : subm * ldexp(1.0, n);
    sc2 = at_ev || nw == 3 ? 0.0 : subm * ldexp(1.0, 2 * n);
    sfb__stam_finish(J, sc1, sc2, sr, nr, res, nres);
}

/* The Stam kind's evaluator (sfb__patch_kind, patch/table.c): res and the normalised tangent frame. */
void sfb__kind_stam_loop(const sfb__patch_table *pt, const float *pts, int patch, const int *cv, double s, double t, double res[6][3],
                         double dir[2][3]) {
    sfb__eval_stam_loop(pt->eigl[pt->pvalence[patch]], pts, cv, SFB__PARAM_CORNER(pt->pparam[patch]), s, t, 6, res, dir);
}
#line 1 "src/patch/manifold.c"
/* Manifold-based blending surfaces with darts, creases and corners (seed 000, after Ying and
 * Zorin): the MANIFOLD4 patch family of the patch table (scheme SFB_SCHEME_MANIFOLD_BLEND).
 *
 * The manifold mesh. A mesh of quads is used as it is. Any other mesh first takes one
 * Catmull-Clark step: edges with sharpness > 0 are made infinitely sharp for that step (so
 * their children are crease edges and stay sharp), vertices with sharpness > 0 likewise
 * (corners). A base quad is then one parametric face made of its four child quads (quadrants
 * of its (u,v) square, one level of the patch quadtree); an n-gon's sub-face i is its child
 * quad i, as for Catmull-Clark limit evaluation.
 *
 * Charts and local coordinates. In a quad with corners V0..V3 (counter-clockwise) the face
 * coordinates (c,d) in [0,1]^2 put V0 at (0,0), V1 at (1,0) and V3 at (0,1). Corner j sees the
 * point at its own coordinates (a_j, b_j), a along the edge to its next corner, b along the
 * edge to its previous one:
 *     j = 0: (c, d)    j = 1: (d, 1 - c)    j = 2: (1 - c, 1 - d)    j = 3: (1 - d, c).
 * Around a manifold vertex of valence k, face h lies between edge h (its a axis) and edge h + 1
 * (its b axis), counter-clockwise. The chart of the vertex maps the point of face h with
 * zeta = a + i b to z = zeta^(4/k) e^(2 pi i h / k) (seed section III.1): face h covers the
 * sector [2 pi h / k, 2 pi (h + 1) / k], the neighbour across edge h sits at e^(2 pi i h / k),
 * the far corner of face h at 2^(2/k) e^(i (2 pi h + pi) / k).
 *
 * Local geometry by the number n of sharp edges at the vertex (Table 1; an edge is sharp when
 * its sharpness is > 0; boundary and non-manifold edges are infinitely sharp once the mesh is
 * prepared, so they count):
 *   - n = 0 at an interior manifold vertex: the bi-quadratic patch of eq. 2,
 *     P(u + iv) = [1 u u^2] C [1 v v^2]^T, C_00 = the vertex (the constraint P(0) = v_i), the
 *     other eight coefficient vectors fitted by least squares to the 2k one-ring vertices (k
 *     edge neighbours and k far corners) at their chart positions. The system only depends on
 *     k; its pseudo-inverse (8 x 2k) is computed once per valence. Choice where the fit is
 *     under-determined (k = 2 and k = 3: 4 and 6 equations for 8 unknowns) or rank-deficient:
 *     the minimum-norm solution (eigenvalues of A^T A below 1e-12 of the largest are dropped).
 *     With k = 4 the fit interpolates the 3 x 3 grid.
 *   - n = 1 (dart), n >= 3 (corner), a vertex with sharpness > 0, a non-manifold or bare
 *     vertex: the vertex itself (a point).
 *   - n = 2 (crease; a boundary vertex whose only sharp edges are its two boundary edges is
 *     one): the quadratic Bezier curve q0 = the far end of the first sharp edge e1 (in the
 *     vertex's counter-clockwise edge order), q1 = the vertex, q2 = the far end of e2, at the
 *     curve parameter sigma = (1 - p1 + p2) / 2, p1 = the point's coordinate along e1 when e1
 *     is an edge of the face (a or b), else 0, p2 the same for e2. Choice: the seed's eq. 4
 *     reads 0.5 -/+ |z| cos(theta); we halve the projection so that the neighbours at the far
 *     ends of e1 and e2 sit at sigma = 0 and 1, the curve's ends: with evenly spaced collinear
 *     crease vertices the blended crease is then the straight segment at uniform speed (linear
 *     precision), which the unhalved form does not give. A face that holds both e1 and e2 (a
 *     boundary corner) gets both terms.
 *   Half-disk charts: a boundary vertex has two sharp (boundary) edges, so its local geometry
 *   is a curve or a point, neither of which reads the chart; no boundary chart is needed.
 *
 * Blending (eq. 5): S = sum_j w_j P_j(z_j), w_j = eta(a_j) eta(b_j). Hermite (the seed):
 * eta(t) = 2t^3 - 3t^2 + 1; C-infinity (Ying-Zorin's kind): eta(t) = g(1-t) / (g(t) + g(1-t)),
 * g(x) = exp(-1/x) for x > 0, else 0, flat to all orders at 0 and 1. Both satisfy
 * eta(t) + eta(1-t) = 1, so the four weights of a face sum to 1 exactly and no division is
 * needed. Derivatives are analytic: the chain rule through the corner coordinates and the
 * conformal chart (dz/dzeta = (4/k) zeta^(4/k - 1) e^(2 pi i h / k)). At a patch vertex itself
 * (zeta = 0), where that derivative vanishes (k < 4) or diverges (k > 4), du and dv are the
 * chart derivatives with (4/k) e^(2 pi i h / k) in its place: their cross product has the
 * direction of the surface normal there (the chart is conformal and keeps orientation).
 * Second derivatives are central differences of the analytic first derivatives (step 2^-17,
 * one-sided at the face border).
 *
 * Tables (seed section V.1): point_data holds nine xyz rows per manifold vertex (the texture
 * of Fig. 8): the patch's C_mn in row 3m + n; a point in row 0; a curve's q0, q1, q2 in rows
 * 0, 1, 2. Per patch: cv = the four corner vertices (row base = 9 * vertex), pcorner = the four
 * corner codes (SFB__MF_CODE: kind, k, h, the axes of e1 and e2 in that face). A kernel then
 * forms Table 2's vector pair per corner ([1 u u^2]/[1 v v^2], [1 0 0]/[1 0 0],
 * [1 0 0]/Bernstein(sigma)) and blends the four points. */

static double sfb__mf_g(double x) { return x > 0.0 ? exp(-1.0 / x) : 0.0; }

/* eta and its derivative (kind: SFB_MANIFOLD_WEIGHTS_*). */
double sfb__mf_eta(int kind, double t, double *dt) {
    if (kind == SFB_MANIFOLD_WEIGHTS_CINF) {
        double a, b, da, db, s;
        if (t <= 0.0) { *dt = 0.0; return 1.0; }
        if (t >= 1.0) { *dt = 0.0; return 0.0; }
        a = sfb__mf_g(1.0 - t); b = sfb__mf_g(t);
        da = a > 0.0 ? -a / ((1.0 - t) * (1.0 - t)) : 0.0; /* d/dt g(1-t) */
        db = b > 0.0 ? b / (t * t) : 0.0;
        s = a + b;
        *dt = (da * b - a * db) / (s * s); /* = (da s - a (da + db)) / s^2 without the cancellation near 0 and 1 */
        return a / s;
    }
    *dt = 6.0 * t * t - 6.0 * t;
    return (2.0 * t - 3.0) * t * t + 1.0;
}

/* One corner's local geometry at its coordinates (a,b): P and dP/da, dP/db. */
static void sfb__mf_local(const float *C, unsigned code, double a, double b, double P[3], double Pa[3], double Pb[3]) {
    int kind = SFB__MF_KIND(code), c;
    if (kind == SFB__MF_POINT) {
        for (c = 0; c < 3; ++c) { P[c] = C[c]; Pa[c] = Pb[c] = 0.0; }
    } else if (kind == SFB__MF_CURVE) {
        int a1 = SFB__MF_A1(code), a2 = SFB__MF_A2(code);
        double p1 = a1 == 1 ? a : a1 == 2 ? b : 0.0, p2 = a2 == 1 ? a : a2 == 2 ? b : 0.0;
        double s = 0.5 * (1.0 - p1 + p2);
        double dsa = 0.5 * ((a2 == 1) - (a1 == 1)), dsb = 0.5 * ((a2 == 2) - (a1 == 2));
        double b0 = (1.0 - s) * (1.0 - s), b1 = 2.0 * s * (1.0 - s), b2 = s * s;
        for (c = 0; c < 3; ++c) {
            double d = 2.0 * ((1.0 - s) * ((double)C[3 + c] - C[c]) + s * ((double)C[6 + c] - C[3 + c]));
            P[c] = b0 * C[c] + b1 * C[3 + c] + b2 * C[6 + c];
            Pa[c] = d * dsa; Pb[c] = d * dsb;
        }
    } else {
        int k = SFB__MF_K(code), h = SFB__MF_H(code), m, n;
        double e = 4.0 / k, phi = 2.0 * SFB__PI * h / k, r = sqrt(a * a + b * b), u, v, Ar, Ai;
        double um[3], vm[3], dum[3], dvm[3], Pu[3], Pv[3];
        if (r > 0.0) {
            double th = atan2(b, a), rz = pow(r, e), ang = e * th + phi, ra = e * pow(r, e - 1.0), angd = (e - 1.0) * th + phi;
            u = rz * cos(ang); v = rz * sin(ang);
            Ar = ra * cos(angd); Ai = ra * sin(angd);
        } else {
            u = v = 0.0;
            Ar = e * cos(phi); Ai = e * sin(phi);
        }
        um[0] = 1.0; um[1] = u; um[2] = u * u; dum[0] = 0.0; dum[1] = 1.0; dum[2] = 2.0 * u;
        vm[0] = 1.0; vm[1] = v; vm[2] = v * v; dvm[0] = 0.0; dvm[1] = 1.0; dvm[2] = 2.0 * v;
        for (c = 0; c < 3; ++c) P[c] = Pu[c] = Pv[c] = 0.0;
        for (m = 0; m < 3; ++m)
            for (n = 0; n < 3; ++n) {
                const float *q = C + 3 * (3 * m + n);
                for (c = 0; c < 3; ++c) {
                    P[c] += um[m] * vm[n] * q[c];
                    Pu[c] += dum[m] * vm[n] * q[c];
                    Pv[c] += um[m] * dvm[n] * q[c];
                }
            }
        /* conformal: d(u,v)/da = (Re A, Im A), d(u,v)/db = (-Im A, Re A) */
        for (c = 0; c < 3; ++c) {
            Pa[c] = Pu[c] * Ar + Pv[c] * Ai;
            Pb[c] = -Pu[c] * Ai + Pv[c] * Ar;
        }
    }
}

/* The blend at face coordinates (c,d): S, dS/dc, dS/dd. pts: point_data; cv: the four corner
 * vertices; codes: their corner codes; kind: SFB_MANIFOLD_WEIGHTS_*. */
void sfb__mf_eval(const float *pts, const int *cv, const unsigned *codes, int kind, double c, double d, double S[3], double Sc[3],
                  double Sd[3]) {
    /* corner j: (a_j, b_j) = o_j + J_j (c, d); J rows (da/dc, da/dd), (db/dc, db/dd) */
    static const double J[4][4] = {{1, 0, 0, 1}, {0, 1, -1, 0}, {-1, 0, 0, -1}, {0, -1, 1, 0}};
    static const double O[4][2] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
    int j, x;
    for (x = 0; x < 3; ++x) S[x] = Sc[x] = Sd[x] = 0.0;
    for (j = 0; j < 4; ++j) {
        double a = O[j][0] + J[j][0] * c + J[j][1] * d, b = O[j][1] + J[j][2] * c + J[j][3] * d;
        double ea, eb, dea, deb, w, wa, wb, P[3], Pa[3], Pb[3];
        ea = sfb__mf_eta(kind, a, &dea);
        eb = sfb__mf_eta(kind, b, &deb);
        w = ea * eb; wa = dea * eb; wb = ea * deb;
        if (w == 0.0 && wa == 0.0 && wb == 0.0) continue;
        sfb__mf_local(pts + 27 * (size_t)cv[j], codes[j], a, b, P, Pa, Pb);
        for (x = 0; x < 3; ++x) {
            double ga = wa * P[x] + w * Pa[x], gb = wb * P[x] + w * Pb[x];
            S[x] += w * P[x];
            Sc[x] += ga * J[j][0] + gb * J[j][2];
            Sd[x] += ga * J[j][1] + gb * J[j][3];
        }
    }
}

/* The ref kernel's MANIFOLD4 evaluation at the patch's (s,t): res[0] position, res[1..2] first
 * derivatives, res[3..5] second derivatives when want2, and the unit normal. */
void sfb__mf_eval_patch(const sfb__patch_table *pt, const float *pts, int patch, double s, double t, int want2, double res[6][3],
                        double nrm[3]) {
    const int *cv = pt->cv + pt->pfirst[patch];
    const unsigned *codes = pt->pcorner + 4 * (size_t)patch;
    int x;
    double len;
    sfb__mf_eval(pts, cv, codes, pt->mf_weights, s, t, res[0], res[1], res[2]);
    nrm[0] = res[1][1] * res[2][2] - res[1][2] * res[2][1];
    nrm[1] = res[1][2] * res[2][0] - res[1][0] * res[2][2];
    nrm[2] = res[1][0] * res[2][1] - res[1][1] * res[2][0];
    len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(len > 1e-300) || !isfinite(len)) {
        /* degenerate tangents: at a point or curve corner, and along edges between point or
         * curve geometries, where the derivative across the edge vanishes (eta'(0) = 0): the
         * normal a step inside the face, 1e-4, or 1e-2 when the C-infinity weights are still
         * flat to double precision there (exp(-1/1e-4) underflows) */
        static const double steps[2] = {1e-4, 1e-2};
        int k;
        for (k = 0; k < 2 && !(len > 1e-300 && isfinite(len)); ++k) {
            double h = steps[k], s2 = s + (s < 0.5 ? h : -h), t2 = t + (t < 0.5 ? h : -h), P[3], A[3], B[3];
            sfb__mf_eval(pts, cv, codes, pt->mf_weights, s2, t2, P, A, B);
            nrm[0] = A[1] * B[2] - A[2] * B[1];
            nrm[1] = A[2] * B[0] - A[0] * B[2];
            nrm[2] = A[0] * B[1] - A[1] * B[0];
            len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        }
    }
    if (len > 0.0 && isfinite(len)) for (x = 0; x < 3; ++x) nrm[x] /= len;
    else nrm[0] = nrm[1] = nrm[2] = 0.0;
    for (x = 0; x < 3; ++x) res[3][x] = res[4][x] = res[5][x] = 0.0;
    if (want2) {
        const double h = 1.0 / 131072.0;
        double s0 = s - h < 0.0 ? s : s - h, s1 = s + h > 1.0 ? s : s + h;
        double t0 = t - h < 0.0 ? t : t - h, t1 = t + h > 1.0 ? t : t + h;
        double P[3], A0[3], B0[3], A1[3], B1[3], C0[3], D0[3], C1[3], D1[3];
        sfb__mf_eval(pts, cv, codes, pt->mf_weights, s0, t, P, A0, B0);
        sfb__mf_eval(pts, cv, codes, pt->mf_weights, s1, t, P, A1, B1);
        sfb__mf_eval(pts, cv, codes, pt->mf_weights, s, t0, P, C0, D0);
        sfb__mf_eval(pts, cv, codes, pt->mf_weights, s, t1, P, C1, D1);
        for (x = 0; x < 3; ++x) {
            res[3][x] = (A1[x] - A0[x]) / (s1 - s0);
            res[4][x] = 0.5 * ((B1[x] - B0[x]) / (s1 - s0) + (C1[x] - C0[x]) / (t1 - t0));
            res[5][x] = (D1[x] - D0[x]) / (t1 - t0);
        }
    }
}

/* ---- construction ---- */

/* Symmetric eigen decomposition of an n x n matrix (Jacobi rotations): a is destroyed, its
 * diagonal the eigenvalues; vec columns the eigenvectors. */
static void sfb__mf_jacobi(double *a, double *vec, int n) {
    int sweep, p, q, i;
    for (i = 0; i < n * n; ++i) vec[i] = (i % (n + 1)) == 0 ? 1.0 : 0.0;
    for (sweep = 0; sweep < 64; ++sweep) {
        double off = 0.0;
        for (p = 0; p < n; ++p) for (q = p + 1; q < n; ++q) off += a[p * n + q] * a[p * n + q];
        if (off < 1e-30) break;
        for (p = 0; p < n; ++p)
            for (q = p + 1; q < n; ++q) {
                double apq = a[p * n + q], th, tt, cs, sn;
                if (fabs(apq) < 1e-300) continue;
                th = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
                tt = (th >= 0.0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                cs = 1.0 / sqrt(tt * tt + 1.0); sn = tt * cs;
                for (i = 0; i < n; ++i) { /* columns p, q */
                    double x = a[i * n + p], y = a[i * n + q];
                    a[i * n + p] = cs * x - sn * y; a[i * n + q] = sn * x + cs * y;
                }
                for (i = 0; i < n; ++i) { /* rows p, q */
                    double x = a[p * n + i], y = a[q * n + i];
                    a[p * n + i] = cs * x - sn * y; a[q * n + i] = sn * x + cs * y;
                }
                for (i = 0; i < n; ++i) {
                    double x = vec[i * n + p], y = vec[i * n + q];
                    vec[i * n + p] = cs * x - sn * y; vec[i * n + q] = sn * x + cs * y;
                }
            }
    }
}

/* The chart position of one-ring point l (0..2k-1: edge neighbour l/2 when l is even, far
 * corner of face l/2 when odd) of a valence-k vertex. */
static void sfb__mf_ring_pos(int k, int l, double *u, double *v) {
    double r = (l & 1) ? pow(2.0, 2.0 / k) : 1.0, ang = 2.0 * SFB__PI * (l / 2) / k + ((l & 1) ? SFB__PI / k : 0.0);
    *u = r * cos(ang); *v = r * sin(ang);
}

/* Pseudo-inverse (8 x 2k, row-major) of the eq. 2 fit of a valence-k vertex: coefficient
 * C_mn (index 3m + n - 1) = sum_l pinv[(3m+n-1) * 2k + l] (p_l - v). Minimum norm where the
 * system is under-determined or rank-deficient. */
sfb_result sfb__mf_pinv(sfb_context *ctx, int k, double **out) {
    int rows = 2 * k, i, j, l, q;
    double *A = NULL, *pinv = NULL, ata[64], vec[64], lmax = 0.0;
    *out = NULL;
    A = (double *)sfb__alloc(ctx, (size_t)rows * 8 * sizeof(double));
    pinv = (double *)sfb__calloc(ctx, (size_t)rows * 8, sizeof(double));
    if (!A || !pinv) { sfb__free(ctx, A); sfb__free(ctx, pinv); return sfb__oom(ctx, "manifold fit"); }
    for (l = 0; l < rows; ++l) {
        double u, v, um[3], vm[3];
        sfb__mf_ring_pos(k, l, &u, &v);
        um[0] = 1.0; um[1] = u; um[2] = u * u; vm[0] = 1.0; vm[1] = v; vm[2] = v * v;
        for (q = 1; q < 9; ++q) A[l * 8 + q - 1] = um[q / 3] * vm[q % 3];
    }
    for (i = 0; i < 8; ++i)
        for (j = 0; j < 8; ++j) {
            double s = 0.0;
            for (l = 0; l < rows; ++l) s += A[l * 8 + i] * A[l * 8 + j];
            ata[i * 8 + j] = s;
        }
    sfb__mf_jacobi(ata, vec, 8);
    for (i = 0; i < 8; ++i) if (ata[i * 9] > lmax) lmax = ata[i * 9];
    /* pinv = V diag(1/lambda) V^T A^T over the kept eigenvalues */
    for (q = 0; q < 8; ++q) {
        double lam = ata[q * 9];
        if (!(lam > 1e-12 * lmax)) continue;
        for (l = 0; l < rows; ++l) {
            double proj = 0.0; /* (V^T A^T)_{q,l} = sum_i vec[i][q] A[l][i] */
            for (i = 0; i < 8; ++i) proj += vec[i * 8 + q] * A[l * 8 + i];
            proj /= lam;
            for (i = 0; i < 8; ++i) pinv[i * rows + l] += vec[i * 8 + q] * proj;
        }
    }
    sfb__free(ctx, A);
    *out = pinv;
    return SFB_SUCCESS;
}

/* Vertex classes. */
static int sfb__mf_vertex_kind(const sfb__level *l, int v, int *e1, int *e2) {
    int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0, nf = l->vf_off[v + 1] - l->vf_off[v], i, n = 0;
    *e1 = *e2 = -1;
    if (nf == 0 || ne == 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD) || !(nf == ne || nf == ne - 1) || l->vs[v] > 0.0f) return SFB__MF_POINT;
    for (i = 0; i < ne; ++i)
        if (l->es[l->ve[e0 + i]] > 0.0f) {
            if (n == 0) *e1 = i;
            else if (n == 1) *e2 = i;
            n++;
        }
    if (n == 0) return nf == ne && !(l->vtag[v] & SFB__TAG_BOUNDARY) ? SFB__MF_PATCH : SFB__MF_POINT;
    if (n == 2) return SFB__MF_CURVE;
    return SFB__MF_POINT;
}

/* The corner code of slot `slot` of face f. */
static unsigned sfb__mf_corner_code(const sfb__level *l, const unsigned char *kind, const int *ev1, const int *ev2, int f, int slot) {
    int v = l->fv[l->fv_off[f] + slot], i, h = -1, k, ne, a1 = 0, a2 = 0;
    for (i = l->vf_off[v]; i < l->vf_off[v + 1]; ++i)
        if (l->vf[i] == f && l->vf_slot[i] == slot) { h = i - l->vf_off[v]; break; }
    k = l->vf_off[v + 1] - l->vf_off[v];
    ne = l->ve_off[v + 1] - l->ve_off[v];
    if (kind[v] == SFB__MF_POINT || h < 0) return SFB__MF_CODE(SFB__MF_POINT, 0, 0, 0, 0);
    if (kind[v] == SFB__MF_CURVE) {
        int ea = h, eb = (h + 1) % ne; /* edges of face h: its a and b axes */
        a1 = ev1[v] == ea ? 1 : ev1[v] == eb ? 2 : 0;
        a2 = ev2[v] == ea ? 1 : ev2[v] == eb ? 2 : 0;
        return SFB__MF_CODE(SFB__MF_CURVE, k, h, a1, a2);
    }
    return SFB__MF_CODE(SFB__MF_PATCH, k, h, 0, 0);
}

/* The manifold mesh L and its positions P (double, xyz): the base itself when every face is a
 * quad, else one Catmull-Clark step of it into work/lev1/T with sharp edges and vertices
 * carried as infinitely sharp (*refined = 1). */
static sfb_result sfb__mf_manifold_mesh(sfb_context *ctx, const sfb__level *base, const float *positions, sfb__level *work,
                                        sfb__level *lev1, sfb__stencils *T, const sfb__level **L_out, double **P_out, int *refined) {
    const sfb__level *L;
    double *P;
    sfb_result r;
    int quads = 1, f, v, i, c;
    for (f = 0; f < base->nf; ++f) if (base->fv_off[f + 1] - base->fv_off[f] != 4) quads = 0;
    if (quads) {
        *L_out = base;
        P = *P_out = (double *)sfb__alloc(ctx, ((size_t)base->nv + 1) * 3 * sizeof(double));
        if (!P) return sfb__oom(ctx, "manifold patch table");
        for (i = 0; i < 3 * base->nv; ++i) P[i] = positions[i];
    } else {
        /* one Catmull-Clark step, sharp edges and vertices carried as infinitely sharp */
        sfb__refine_options o;
        int e;
        *refined = 1;
        if ((r = sfb__level_prepare(ctx, base, 0, 0, work)) != SFB_SUCCESS) return r;
        for (e = 0; e < work->ne; ++e) if (work->es[e] > 0.0f) work->es[e] = SFB_SHARPNESS_INFINITE;
        for (v = 0; v < work->nv; ++v) if (work->vs[v] > 0.0f) work->vs[v] = SFB_SHARPNESS_INFINITE;
        sfb__level_compute_rules(work);
        memset(&o, 0, sizeof o);
        o.scheme = SFB_SCHEME_CATMARK;
        if ((r = sfb__refine(ctx, work, &o, 1, lev1, T, NULL, 0.0f, 0.5f)) != SFB_SUCCESS) return r;
        L = *L_out = lev1;
        P = *P_out = (double *)sfb__calloc(ctx, ((size_t)L->nv + 1) * 3, sizeof(double));
        if (!P) return sfb__oom(ctx, "manifold patch table");
        for (v = 0; v < T->rows; ++v)
            for (i = 0; i < T->sizes[v]; ++i) {
                int src = T->indices[T->offsets[v] + i];
                double w = T->weights[T->offsets[v] + i];
                for (c = 0; c < 3; ++c) P[3 * (size_t)v + c] += w * positions[3 * (size_t)src + c];
            }
    }
    return SFB_SUCCESS;
}

/* The local geometry of every vertex of L into pt->point_data (nine xyz rows each: a point, a
 * crease curve or the fitted bi-quadratic patch), its kind and sharp edges into kind/ev1/ev2;
 * pinv caches the pseudo-inverse of each valence. */
static sfb_result sfb__mf_local_geometry(sfb_context *ctx, const sfb__level *L, const double *P, unsigned char *kind, int *ev1,
                                         int *ev2, double **pinv, sfb__patch_table *pt) {
    sfb_result r;
    int v, i, c;
    for (v = 0; v < L->nv; ++v) {
        float *C = pt->point_data + 27 * (size_t)v;
        int k = L->vf_off[v + 1] - L->vf_off[v], e0 = L->ve_off[v];
        kind[v] = (unsigned char)sfb__mf_vertex_kind(L, v, &ev1[v], &ev2[v]);
        for (c = 0; c < 3; ++c) C[c] = (float)P[3 * (size_t)v + c];
        if (kind[v] == SFB__MF_CURVE) {
            int qa = sfb__other_end(L, L->ve[e0 + ev1[v]], v), qb = sfb__other_end(L, L->ve[e0 + ev2[v]], v);
            for (c = 0; c < 3; ++c) {
                C[c] = (float)P[3 * (size_t)qa + c];
                C[3 + c] = (float)P[3 * (size_t)v + c];
                C[6 + c] = (float)P[3 * (size_t)qb + c];
            }
        } else if (kind[v] == SFB__MF_PATCH) {
            const double *M;
            int q;
            if (k > SFB_MAX_VALENCE) { kind[v] = SFB__MF_POINT; continue; }
            if (!pinv[k] && (r = sfb__mf_pinv(ctx, k, &pinv[k])) != SFB_SUCCESS) return r;
            M = pinv[k];
            for (q = 1; q < 9; ++q) {
                double acc[3] = {0.0, 0.0, 0.0};
                for (i = 0; i < 2 * k; ++i) {
                    int g = L->vf[L->vf_off[v] + i / 2], gs = L->vf_slot[L->vf_off[v] + i / 2];
                    int nb = (i & 1) ? L->fv[L->fv_off[g] + (gs + 2) % 4] : sfb__other_end(L, L->ve[e0 + i / 2], v);
                    for (c = 0; c < 3; ++c) acc[c] += M[(q - 1) * 2 * k + i] * (P[3 * (size_t)nb + c] - P[3 * (size_t)v + c]);
                }
                for (c = 0; c < 3; ++c) C[3 * q + c] = (float)acc[c];
            }
        }
    }
    return SFB_SUCCESS;
}

/* Counts the param faces, patches and quadtree nodes of the base faces and allocates the
 * patch table's arrays for them. */
static sfb_result sfb__mf_alloc_patches(sfb_context *ctx, const sfb__level *base, int refined, sfb__patch_table *pt) {
    int f, nptex = 0, npatch = 0, nnodes = 0;
    pt->face_ptex = (int *)sfb__alloc(ctx, ((size_t)base->nf + 1) * sizeof(int));
    if (!pt->face_ptex) return sfb__oom(ctx, "manifold patch table");
    for (f = 0; f < base->nf; ++f) {
        int n = base->fv_off[f + 1] - base->fv_off[f];
        pt->face_ptex[f] = nptex;
        nptex += n == 4 ? 1 : n;
        if (!base->fhole[f]) { npatch += refined ? n : 1; nnodes += refined && n == 4; }
    }
    pt->face_ptex[base->nf] = nptex;
    pt->nptex = nptex; pt->npatch = npatch; pt->nnodes = nnodes; pt->ncv = 4 * npatch;
    pt->max_depth = refined && nnodes > 0 ? 1 : 0;
    pt->ptex_face = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_corner = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_root = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->nodes = (int *)sfb__alloc(ctx, ((size_t)nnodes + 1) * 4 * sizeof(int));
    pt->ptype = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(int));
    pt->pfirst = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(int));
    pt->pparam = (unsigned *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(unsigned));
    pt->pvalence = (int *)sfb__calloc(ctx, (size_t)npatch + 1, sizeof(int));
    pt->cv = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * 4 * sizeof(int));
    pt->pcorner = (unsigned *)sfb__alloc(ctx, ((size_t)npatch + 1) * 4 * sizeof(unsigned));
    if (!pt->ptex_face || !pt->ptex_corner || !pt->ptex_root || !pt->nodes || !pt->ptype || !pt->pfirst || !pt->pparam || !pt->pvalence ||
        !pt->cv || !pt->pcorner)
        return sfb__oom(ctx, "manifold patch table");
    return SFB_SUCCESS;
}

/* Fills the param faces, quadtree nodes and MANIFOLD4 patches (control vertices and corner
 * codes) of every base face: one patch per quad, or one per child quad when L is refined. */
static void sfb__mf_fill_patches(const sfb__level *base, const sfb__level *L, int refined, const unsigned char *kind, const int *ev1,
                                 const int *ev2, sfb__patch_table *pt) {
    int p = 0, node = 0, f, i, j, npatch = pt->npatch;
    for (f = 0; f < base->nf; ++f) {
        int n = base->fv_off[f + 1] - base->fv_off[f], k0 = pt->face_ptex[f];
        for (i = 0; i < (n == 4 ? 1 : n); ++i) {
            pt->ptex_face[k0 + i] = f;
            pt->ptex_corner[k0 + i] = n == 4 ? -1 : i;
            pt->ptex_root[k0 + i] = -1;
        }
        if (base->fhole[f]) continue;
        if (!refined) {
            pt->ptex_root[k0] = -(p + 2);
            pt->pparam[p] = SFB__PARAM(0, 0, 0, 0);
            for (j = 0; j < 4; ++j) {
                pt->cv[4 * p + j] = L->fv[L->fv_off[f] + j];
                pt->pcorner[4 * p + j] = sfb__mf_corner_code(L, kind, ev1, ev2, f, j);
            }
            pt->ptype[p] = SFB__PATCH_MANIFOLD4; pt->pfirst[p] = 4 * p;
            p++;
            continue;
        }
        /* child quad i of base face f is refined face fv_off[f] + i, its slot 0 at the
         * corner v_i (v_i, mid(v_i,v_i+1), centroid, mid(v_i-1,v_i)) */
        if (n == 4) pt->ptex_root[k0] = node;
        for (i = 0; i < n; ++i) {
            int g = base->fv_off[f] + i, s0 = n == 4 ? (4 - i) % 4 : 0;
            static const int qx[4] = {0, 1, 1, 0}, qy[4] = {0, 0, 1, 1};
            if (n == 4) {
                pt->nodes[4 * node + qx[i] + 2 * qy[i]] = -(p + 2);
                pt->pparam[p] = SFB__PARAM(1, qx[i], qy[i], 0);
            } else {
                pt->ptex_root[k0 + i] = -(p + 2);
                pt->pparam[p] = SFB__PARAM(0, 0, 0, 0);
            }
            for (j = 0; j < 4; ++j) {
                int slot = (s0 + j) % 4;
                pt->cv[4 * p + j] = L->fv[L->fv_off[g] + slot];
                pt->pcorner[4 * p + j] = sfb__mf_corner_code(L, kind, ev1, ev2, g, slot);
            }
            pt->ptype[p] = SFB__PATCH_MANIFOLD4; pt->pfirst[p] = 4 * p;
            p++;
        }
        if (n == 4) node++;
    }
    pt->pfirst[npatch] = 4 * npatch;
}

sfb_result sfb__manifold_build(sfb_context *ctx, const sfb__level *base, int weights, const float *positions, sfb__patch_table *pt) {
    sfb__level work, lev1;
    const sfb__level *L = NULL;
    sfb__stencils T;
    double *P = NULL, **pinv = NULL;
    unsigned char *kind = NULL;
    int *ev1 = NULL, *ev2 = NULL;
    int i, refined = 0;
    sfb_result r = SFB_SUCCESS;
    memset(pt, 0, sizeof *pt);
    memset(&work, 0, sizeof work); memset(&lev1, 0, sizeof lev1); memset(&T, 0, sizeof T);
    if (weights != SFB_MANIFOLD_WEIGHTS_HERMITE && weights != SFB_MANIFOLD_WEIGHTS_CINF)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "manifold weights %d are not SFB_MANIFOLD_WEIGHTS_HERMITE or _CINF", weights);
    pt->domain = SFB__DOMAIN_QUAD;
    pt->mf_weights = weights;
    if ((r = sfb__mf_manifold_mesh(ctx, base, positions, &work, &lev1, &T, &L, &P, &refined)) != SFB_SUCCESS) goto done;
    /* local geometries */
    kind = (unsigned char *)sfb__alloc(ctx, (size_t)L->nv + 1);
    ev1 = (int *)sfb__alloc(ctx, ((size_t)L->nv + 1) * sizeof(int));
    ev2 = (int *)sfb__alloc(ctx, ((size_t)L->nv + 1) * sizeof(int));
    pt->point_data = (float *)sfb__calloc(ctx, (size_t)L->nv * 27 + 1, sizeof(float));
    pinv = (double **)sfb__calloc(ctx, SFB_MAX_VALENCE + 1, sizeof(double *));
    if (!kind || !ev1 || !ev2 || !pt->point_data || !pinv) { r = sfb__oom(ctx, "manifold patch table"); goto done; }
    pt->npoints = 9 * L->nv;
    if ((r = sfb__mf_local_geometry(ctx, L, P, kind, ev1, ev2, pinv, pt)) != SFB_SUCCESS) goto done;
    /* param faces and patches */
    if ((r = sfb__mf_alloc_patches(ctx, base, refined, pt)) != SFB_SUCCESS) goto done;
    sfb__mf_fill_patches(base, L, refined, kind, ev1, ev2, pt);
    pt->counts[SFB__PATCH_MANIFOLD4] = pt->npatch;
done:
    if (pinv) { for (i = 0; i <= SFB_MAX_VALENCE; ++i) sfb__free(ctx, pinv[i]); sfb__free(ctx, pinv); }
    sfb__free(ctx, kind); sfb__free(ctx, ev1); sfb__free(ctx, ev2); sfb__free(ctx, P);
    sfb__level_free(ctx, &work); sfb__level_free(ctx, &lev1); sfb__stencils_free(ctx, &T);
    if (r != SFB_SUCCESS) sfb__patch_table_free(ctx, pt);
    return r;
}
#line 1 "src/patch/pn.c"
/* Curved PN triangles (SFB_SCHEME_PN; ALGORITHMS.md section 5.3): what engines tessellate
 * today, beside seed 004's triangular splines for comparison. One cubic Bezier triangle per
 * mesh triangle from its corners and their vertex normals, degree-raised to the quartic
 * BEZIER_TRI15 patches the Loop work evaluates, so eval, tessellation, trimming, rendering and
 * the glTF export run on every backend unchanged.
 *
 * Choices the method leaves open, made here:
 *   - vertex normals: the angle-weighted mean of the incident triangles' normals (each
 *     triangle's normal weighted by its angle at the vertex), computed from the base positions
 *     when the surface is built; a mean that cancels (opposite triangles) falls back to the
 *     first incident triangle's normal. PN triangles know no creases: sharpness tags are
 *     ignored, every vertex has one normal.
 *   - normals: the method's quadratic normal field (for shading), not du x dv: the patch table
 *     carries it as its normal_field, a second table of BEZIER_TRI15 patches (the quadratic
 *     field degree-raised twice) evaluated on the backend like the positions and normalised
 *     (sfb__surface_eval_unchecked). So tessellation, rendering, the analysis and the glTF export
 *     shade with what engines shade with. Corners get the vertex normals exactly (so do the
 *     geometric normals: both edge points next to a corner lie in the plane through it normal to
 *     that vertex normal); along an edge the field depends on that edge's two vertices only, so
 *     it is continuous across edges. An edge's middle coefficient normalize(N_i + N_j -
 *     v_ij (P_j - P_i)) that cancels (normals mirrored into opposite directions) is the
 *     triangle's unit normal instead. du, dv and the second derivatives stay the cubic geometry's.
 *   - refused: faces that are not triangles, non-manifold edges (more than two triangles),
 *     degenerate triangles (an area below 1e-12 of the squared bounding-box diagonal, or
 *     non-finite positions), since their normals, and so the patch, are undefined.
 * Param faces are the triangles, (u,v) barycentric as Loop's: (1-u-v) P0 + u P1 + v P2. */

/* Cubic point (a = exponent of s, b = exponent of t) of triangle (P[0], P[1], P[2]) with
 * vertex normals N: corners P0 (0,0), P1 (3,0), P2 (0,3). */
static void sfb__pn_cubic(double P[3][3], double N[3][3], double C[5][5][3]) {
    /* the corner of each (a, b) on the boundary and the corner it points to */
    static const int edge[6][4] = {{1, 0, 0, 1}, {2, 0, 1, 0}, {0, 1, 0, 2}, {0, 2, 2, 0}, {2, 1, 1, 2}, {1, 2, 2, 1}};
    double E[3] = {0, 0, 0}, V[3];
    int k, c;
    for (c = 0; c < 3; ++c) {
        C[0][0][c] = P[0][c];
        C[3][0][c] = P[1][c];
        C[0][3][c] = P[2][c];
        V[c] = (P[0][c] + P[1][c] + P[2][c]) / 3.0;
    }
    for (k = 0; k < 6; ++k) {
        const int a = edge[k][0], b = edge[k][1], i = edge[k][2], j = edge[k][3];
        double w = 0.0;
        for (c = 0; c < 3; ++c) w += (P[j][c] - P[i][c]) * N[i][c];
        for (c = 0; c < 3; ++c) {
            C[a][b][c] = (2.0 * P[i][c] + P[j][c] - w * N[i][c]) / 3.0;
            E[c] += C[a][b][c] / 6.0;
        }
    }
    for (c = 0; c < 3; ++c) C[1][1][c] = E[c] + 0.5 * (E[c] - V[c]);
}

/* Degree raising from degree d to d + 1 (the Bezier triangle's points by exponents (a, b) of s
 * and t, a + b <= d): r(i,j) = (i c(i-1,j) + j c(i,j-1) + k c(i,j)) / (d + 1), with
 * k = d + 1 - i - j the exponent of w. */
static void sfb__pn_raise_degree(int d, double C[5][5][3], double R[5][5][3]) {
    int i, j, c;
    for (j = 0; j <= d + 1; ++j)
        for (i = 0; i + j <= d + 1; ++i) {
            const int k = d + 1 - i - j;
            for (c = 0; c < 3; ++c) {
                double v = 0.0;
                if (i > 0) v += i * C[i - 1][j][c];
                if (j > 0) v += j * C[i][j - 1][c];
                if (k > 0) v += k * C[i][j][c];
                R[i][j][c] = v / (d + 1);
            }
        }
}

/* A cubic raised to our quartic order (row by row in t, s rising in a row), 45 doubles. */
static void sfb__pn_raise(double C[5][5][3], double *out) {
    double R[5][5][3];
    int i, j, c, q = 0;
    sfb__pn_raise_degree(3, C, R);
    for (j = 0; j <= 4; ++j)
        for (i = 0; i + j <= 4; ++i, ++q)
            for (c = 0; c < 3; ++c) out[3 * q + c] = R[i][j][c];
}

/* The quadratic normal field of the triangle (its unit normal `fn`), raised to a cubic C for
 * sfb__pn_raise: Q(a, b) with a + b <= 2, corners N0 (0,0), N1 (2,0), N2 (0,2), the edges'
 * middles at (1,0) P0P1, (0,1) P0P2, (1,1) P1P2. */
static void sfb__pn_quadratic_normals(double P[3][3], double N[3][3], const double fn[3], double C[5][5][3]) {
    static const int mid[3][4] = {{1, 0, 0, 1}, {0, 1, 0, 2}, {1, 1, 1, 2}};
    double Q[5][5][3];
    int k, c;
    for (c = 0; c < 3; ++c) {
        Q[0][0][c] = N[0][c];
        Q[2][0][c] = N[1][c];
        Q[0][2][c] = N[2][c];
    }
    for (k = 0; k < 3; ++k) {
        const int a = mid[k][0], b = mid[k][1], p = mid[k][2], q = mid[k][3];
        double d[3], h[3], dd = 0.0, dn = 0.0, len = 0.0;
        for (c = 0; c < 3; ++c) {
            d[c] = P[q][c] - P[p][c];
            dd += d[c] * d[c];
            dn += d[c] * (N[p][c] + N[q][c]);
        }
        for (c = 0; c < 3; ++c) {
            h[c] = N[p][c] + N[q][c] - 2.0 * dn / dd * d[c]; /* dd > 0: degenerate triangles are refused */
            len += h[c] * h[c];
        }
        len = sqrt(len);
        for (c = 0; c < 3; ++c) Q[a][b][c] = len > 1e-9 ? h[c] / len : fn[c];
    }
    sfb__pn_raise_degree(2, Q, C);
}

static void sfb__pn_face_normal(const float *a, const float *b, const float *c, double n[3]) {
    double u[3], v[3];
    int k;
    for (k = 0; k < 3; ++k) { u[k] = (double)b[k] - a[k]; v[k] = (double)c[k] - a[k]; }
    sfb__cross3(u, v, n);
}

/* The angle at corner a of triangle (a, b, c). */
static double sfb__pn_angle(const float *a, const float *b, const float *c) {
    double u[3], v[3], x[3], d = 0.0;
    int k;
    for (k = 0; k < 3; ++k) { u[k] = (double)b[k] - a[k]; v[k] = (double)c[k] - a[k]; d += u[k] * v[k]; }
    sfb__cross3(u, v, x);
    return atan2(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), d);
}

sfb_result sfb__pn_build(sfb_context *ctx, const sfb__level *l, const float *positions, sfb__patch_table *pt) {
    double *vn = NULL, *net = NULL;
    int f, v, k, c;
    sfb_result r = SFB_SUCCESS;
    memset(pt, 0, sizeof *pt);
    r = sfb__tri_mesh_check(ctx, l, positions, "PN triangles", 0);
    if (r != SFB_SUCCESS) return r;
    vn = (double *)sfb__calloc(ctx, (size_t)l->nv * 3 + 1, sizeof(double));
    if (!vn) return sfb__oom(ctx, "PN triangles");
    for (f = 0; f < l->nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        double n[3], len;
        sfb__pn_face_normal(positions + 3 * (size_t)fv[0], positions + 3 * (size_t)fv[1], positions + 3 * (size_t)fv[2], n);
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]); /* > 0: sfb__tri_mesh_check refused degenerate triangles */
        for (k = 0; k < 3; ++k) {
            const double a = sfb__pn_angle(positions + 3 * (size_t)fv[k], positions + 3 * (size_t)fv[(k + 1) % 3],
                                           positions + 3 * (size_t)fv[(k + 2) % 3]);
            for (c = 0; c < 3; ++c) vn[3 * (size_t)fv[k] + c] += a * n[c] / len;
        }
    }
    for (v = 0; v < l->nv; ++v) {
        double *n = vn + 3 * (size_t)v, len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 1e-9) && l->vf_off[v + 1] > l->vf_off[v]) { /* cancelled: the first triangle's normal */
            const int g = l->vf[l->vf_off[v]], *fv = l->fv + l->fv_off[g];
            sfb__pn_face_normal(positions + 3 * (size_t)fv[0], positions + 3 * (size_t)fv[1], positions + 3 * (size_t)fv[2], n);
            len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        }
        if (len > 0.0)
            for (c = 0; c < 3; ++c) n[c] /= len;
    }
    /* the tables: one param face and one BEZIER_TRI15 patch (15 points of its own) per
     * triangle, for the geometry and for the normal field */
    net = (double *)sfb__alloc(ctx, 2 * 45 * (size_t)l->nf * sizeof(double) + 1);
    if (!net) { r = sfb__oom(ctx, "PN triangles"); goto done; }
    for (f = 0; f < l->nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        double P[3][3], N[3][3], C[5][5][3], fn[3], len;
        for (k = 0; k < 3; ++k)
            for (c = 0; c < 3; ++c) {
                P[k][c] = positions[3 * (size_t)fv[k] + c];
                N[k][c] = vn[3 * (size_t)fv[k] + c];
            }
        sfb__pn_cubic(P, N, C);
        sfb__pn_raise(C, net + 45 * (size_t)f);
        sfb__pn_face_normal(positions + 3 * (size_t)fv[0], positions + 3 * (size_t)fv[1], positions + 3 * (size_t)fv[2], fn);
        len = sqrt(fn[0] * fn[0] + fn[1] * fn[1] + fn[2] * fn[2]);
        for (c = 0; c < 3; ++c) fn[c] /= len;
        sfb__pn_quadratic_normals(P, N, fn, C);
        sfb__pn_raise(C, net + 45 * ((size_t)l->nf + f));
    }
    if ((r = sfb__patch_table_beztri_own(ctx, l, net, pt)) != SFB_SUCCESS) goto done;
    pt->normal_field = (sfb__patch_table *)sfb__calloc(ctx, 1, sizeof *pt->normal_field);
    if (!pt->normal_field) { r = sfb__oom(ctx, "PN triangles' normals"); goto done; }
    r = sfb__patch_table_beztri_own(ctx, l, net + 45 * (size_t)l->nf, pt->normal_field);
done:
    sfb__free(ctx, vn);
    sfb__free(ctx, net);
    if (r != SFB_SUCCESS) sfb__patch_table_free(ctx, pt);
    return r;
}
#line 1 "src/patch/tribezier.c"
/* Quartic triangular Bezier surfaces with a sharpness slider (SFB_SCHEME_TRIBEZIER, seed 004;
 * ALGORITHMS.md sections 5 and 8). One quartic Bezier triangle (15 points) per mesh triangle,
 * emitted as the BEZIER_TRI15 patches the Loop work evaluates, so eval, tessellation, trimming,
 * rendering and the glTF export run on every backend unchanged.
 *
 * The construction, and the choices the seed leaves open:
 *   - the control net is global: one point per vertex (b400), three per edge (b310, b220, b130),
 *     three per triangle (b211, b121, b112), so neighbouring patches share their boundary points
 *     and the surface is closed (C0) by construction, for every s.
 *   - two nets are built from the mesh: the smooth one (s = 0) and the sharp one (s = 1, every
 *     tagged feature sharp); the surface at s is (1 - s) smooth + s sharp point by point (seed
 *     section 4, ALGORITHMS.md 8.5: every Bezier point of the mesh extension is linear in s).
 *     Where creases carry different s, a point takes the s of the nearest feature (graph distance
 *     over mesh edges; at a feature vertex the mean of its features' s, averaged over the point's
 *     home vertices: its corner, its edge's ends, its triangle's corners); for one s everywhere
 *     the blend is exact.
 *   - regular vertices (valence 6, or a crease/boundary vertex with three triangles on each
 *     side) take Sabin's rules (seed eq. 4-7, ALGORITHMS.md 8.1) on the mesh extended across
 *     sharp edges by parallelograms (seed eq. 8 at s = 1: the phantom across wall edge (a, b) is
 *     a + b - the near-side opposite vertex). There the surface is the Loop limit surface, and
 *     a regular sharp crease is Loop's crease: the degree-raised cubic B-spline of its vertices.
 *   - sharp edges (in the sharp net every tagged edge with s > 0, in both nets every boundary
 *     edge) whose ends are crease or corner vertices are fixed to that cubic B-spline (a corner
 *     is interpolated, its phantom 2V - N), in both neighbours' patches.
 *   - G1 at extraordinary vertices: ALGORITHMS.md 8.4's polynomial construction (S2), generalised.
 *     Chosen over 8.3's Gregory triangle because it stays a polynomial BEZIER_TRI15 patch (no new
 *     kernel family on every backend) and because its constraints are linear, so creases,
 *     corners and boundaries enter it as more constraints rather than as separate cases. Every
 *     Bezier point within net distance TBZ_REACH of an irregular vertex is an unknown; per
 *     interior edge that is not sharp in the net being built, the five quartic Bernstein
 *     coefficients of mu(t) X(t) + nu(t) Y(t) - lambda(t) T(t) vanish (X, Y: derivatives of the
 *     two patches towards their opposite vertices, T along the edge), mu, nu, lambda linear in t
 *     with their end values from the characteristic angles of the two end vertices (below); the
 *     smallest change of the unknowns (least squares, CGLS from zero: the minimum-norm solution)
 *     that satisfies them is applied, per connected component of the constraints (each solved on
 *     a compact copy of its rows, three coordinates at once; see tbz_cgls for when it stops).
 *     Regular regions are untouched, so they stay Loop's. Where extraordinary vertices of
 *     different valences touch, the constraints have no exact solution on the mesh itself; the
 *     net is then built on the mesh after one Loop step (tbz_refine: the smooth net's positions
 *     by Loop's smooth rules, the sharp net's with its features sharp), four child patches per
 *     triangle (sfb__tribezier_build), and is exactly G1 again (tests/tribezier.c, touching_evs).
 *   - characteristic angles phi (the angle each triangle takes at a vertex): 2 pi / n at a
 *     smooth vertex (and at a dart, and at a vertex with only a corner tag); a sector between two
 *     sharp edges with k triangles spans pi at a crease or boundary vertex (its two crease
 *     tangents opposite, as the B-spline's are), and at a corner the angle between its two sharp
 *     edges (clamped to [pi/8, 7 pi/8]).
 *   - the seed's open problem (section 5, undulation at s = 0.5 near an extraordinary crease
 *     vertex): in the smooth net an irregular crease vertex keeps the sector angles (pi each
 *     side) and is given the crease B-spline's tangents, so its tangent plane contains the
 *     crease tangents; its corner point is the B-spline's point moved by the mean offset of its
 *     crease neighbours' smooth points from their B-spline points, so the smooth crease curve
 *     runs on at the height and side the smooth surface has along the crease (pinned to the
 *     B-spline point it dipped there: the in-plane undulation was 0.11 mean edges at s = 0.25,
 *     now 0.0014-0.0023, the seed's kind 0.008-0.016; tests/tribezier.c). (TBZ_SEED_PLANE builds
 *     the seed's kind instead, the smooth net ignoring the crease, for the measurement in
 *     bench/tests.)
 *   - darts: in the sharp net the dart vertex stays smooth (uniform angles, a Loop-limit corner);
 *     the dart edge is C0 only (no G1 constraint) and is not fixed to a B-spline, so the crease
 *     fades out at the dart.
 *   - corners (a `t corner` tag, or three or more sharp edges; a boundary vertex with one
 *     triangle): the sharp net interpolates the vertex (b400 = V), each sector G1 in itself
 *     (the seed's eq. 9 blend is replaced by the constraint solve, which covers every valence).
 *     A corner tag on a vertex with no sharp edge (or one: a dart) keeps the smooth vertex's
 *     tangents (8.2) around V, so the surface stays G1 through it: the cone point that the tag
 *     makes in Loop's limit would need a normal jump along every spoke, which the tangents along
 *     the spokes had (0.2-0.5 rad on tests/tribezier.c's corner_only bump).
 *   - non-manifold vertices (sheets touching at a vertex): one vertex per fan of triangles, each
 *     sheet built as a manifold mesh of its own through the vertex, a corner (tbz_split).
 *   - refused: faces that are not triangles (split them first: the choice of diagonal is the
 *     modeller's), non-manifold edges, degenerate triangles (area below 1e-12 of the squared
 *     bounding-box diagonal), non-finite positions, an override s outside [0, 1] or NaN.
 * Param faces are the triangles, (u,v) barycentric as Loop's: (1-u-v) P0 + u P1 + v P2. */

#define TBZ_REACH 6   /* net distance of the unknowns from an irregular vertex (ALGORITHMS.md 8.4) */
#define TBZ_PI 3.14159265358979323846

enum { TBZ_SMOOTH = 0, TBZ_DART, TBZ_CREASE, TBZ_CORNER };

typedef struct sfb__tbz {
    sfb_context *ctx;
    const sfb__level *l;
    const float *pos;
    int nv, ne, nf, np;
    int seed_plane;
    /* per state */
    int sharp;                 /* building the sharp net */
    unsigned char *efeat;      /* per edge: sharp in this net */
    unsigned char *vtype;      /* per vertex */
    unsigned char *virr;       /* per vertex: irregular in this net */
    double *phi;               /* per vertex-face (vf order): characteristic angle */
    double *x;                 /* np * 3: the net */
    unsigned char *fixed;      /* per point */
    int *dist;                 /* per point: net distance to an irregular vertex */
    int *grid;                 /* per face: its 15 points (tbz_patch), made once (the topology is the same in every
                                  state) */
    float *tag_s;              /* per edge: s of a tagged edge (0: none) */
    float *corner_s;           /* per vertex: s of a corner tag (0: none) */
    /* the seed-plane fallback of the smooth net: the first (our-plane) solution and its vertices
     * of type CREASE | 16; components of the constraints away from those are the same systems in
     * both nets, so their solution is copied rather than solved again */
    const double *reuse_x;
    const unsigned char *reuse_ours;
    /* the smooth net's solve recorded for the sharp net (tbz_prev): rec while building the
     * smooth net, prev while building the sharp one */
    struct tbz_prev *rec;
    const struct tbz_prev *prev;
    double scale;              /* the mesh's largest coordinate (of the smooth net's positions): the solves' stopping
                                  and residuals are relative to it, the same in both nets (so that their systems can
                                  be compared: tbz_prev); it was the net's own largest point, which differs between
                                  the nets by their sharp points */
    sfb__tbz_stats st;
} sfb__tbz;

static int tbz_vp(const sfb__tbz *T, int v) { (void)T; return v; }
static int tbz_ep(const sfb__tbz *T, int e, int q) { return T->nv + 3 * e + q; }
static int tbz_fp(const sfb__tbz *T, int f, int k) { return T->nv + 3 * T->ne + 3 * f + k; }

/* Global index of the point of triangle f with weights w[k] on its corner k (sum 4). */
static int tbz_pt(const sfb__tbz *T, int f, const int w[3]) {
    const sfb__level *l = T->l;
    const int *fv = l->fv + l->fv_off[f];
    int k;
    for (k = 0; k < 3; ++k)
        if (w[k] == 4) return tbz_vp(T, fv[k]);
    for (k = 0; k < 3; ++k)
        if (w[(k + 2) % 3] == 0) { /* on edge k: fv[k] -> fv[k+1] */
            const int e = l->fe[l->fv_off[f] + k], near = w[k]; /* weight of fv[k] */
            return l->ev[2 * e] == fv[k] ? tbz_ep(T, e, 4 - near - 1) : tbz_ep(T, e, near - 1);
        }
    for (k = 0; k < 3; ++k)
        if (w[k] == 2) return tbz_fp(T, f, k);
    return -1;
}

/* The 15 global indices of triangle f in our patch order (row by row in v, u rising). */
static void tbz_patch(const sfb__tbz *T, int f, int g[15]) {
    int i, j, q = 0;
    for (j = 0; j <= 4; ++j)
        for (i = 0; i + j <= 4; ++i, ++q) {
            int w[3];
            w[0] = 4 - i - j; w[1] = i; w[2] = j;
            g[q] = tbz_pt(T, f, w);
        }
}

static int tbz_qij(int i, int j) { return 5 * j - j * (j - 1) / 2 + i; }

static int tbz_ring(const sfb__level *l, int v, int j) { return sfb__other_end(l, l->ve[l->ve_off[v] + j], v); }
static int tbz_nf(const sfb__level *l, int v) { return l->vf_off[v + 1] - l->vf_off[v]; }
static int tbz_boundary(const sfb__level *l, int v) { return l->ve_off[v + 1] - l->ve_off[v] > tbz_nf(l, v); }

static void tbz_get(const sfb__tbz *T, int v, double out[3]) {
    out[0] = T->pos[3 * (size_t)v]; out[1] = T->pos[3 * (size_t)v + 1]; out[2] = T->pos[3 * (size_t)v + 2];
}
static void tbz_axpy(double *y, double a, const double *x) { y[0] += a * x[0]; y[1] += a * x[1]; y[2] += a * x[2]; }

/* The spoke slot of edge e in v's ring. */
static int tbz_spoke(const sfb__level *l, int v, int e) {
    int i;
    for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i)
        if (l->ve[i] == e) return i - l->ve_off[v];
    return -1;
}

/* The two sharp neighbours of a crease vertex (first and last sharp spoke). */
static void tbz_crease_pair(const sfb__tbz *T, int v, int *a, int *b) {
    const sfb__level *l = T->l;
    int i, m = l->ve_off[v + 1] - l->ve_off[v];
    *a = *b = -1;
    for (i = 0; i < m; ++i)
        if (T->efeat[l->ve[l->ve_off[v] + i]] || ((T->vtype[v] & 16) && T->tag_s[l->ve[l->ve_off[v] + i]] > 0.0f)) {
            if (*a < 0) *a = tbz_ring(l, v, i);
            else *b = tbz_ring(l, v, i);
        }
}

/* Corner point of the sharp crease curve at v: (A + 4V + B)/6 at a crease vertex, V at a corner. */
static void tbz_crease_point(const sfb__tbz *T, int v, int type, double P[3]) {
    double V[3], A[3], B[3];
    int a, b, c;
    tbz_get(T, v, V);
    if (type != TBZ_CREASE) { memcpy(P, V, sizeof V); return; }
    tbz_crease_pair(T, v, &a, &b);
    tbz_get(T, a, A); tbz_get(T, b, B);
    for (c = 0; c < 3; ++c) P[c] = (A[c] + 4.0 * V[c] + B[c]) / 6.0;
}

/* Classifies the vertices of the net being built and sets their characteristic angles. */
static void tbz_classify(sfb__tbz *T) {
    const sfb__level *l = T->l;
    int v, e, j;
    for (e = 0; e < T->ne; ++e) {
        const int bnd = l->ef_off[e + 1] - l->ef_off[e] == 1;
        T->efeat[e] = (unsigned char)(bnd || (T->sharp && T->tag_s[e] > 0.0f));
    }
    for (v = 0; v < T->nv; ++v) {
        const int n = tbz_nf(l, v), m = l->ve_off[v + 1] - l->ve_off[v], bnd = tbz_boundary(l, v);
        int nfeat = 0, ntag = 0, type, irr = 0;
        double *phi = T->phi + l->vf_off[v];
        for (j = 0; j < m; ++j) {
            const int ej = l->ve[l->ve_off[v] + j];
            nfeat += T->efeat[ej];
            ntag += T->tag_s[ej] > 0.0f && l->ef_off[ej + 1] - l->ef_off[ej] == 2;
        }
        if (n == 0) { T->vtype[v] = TBZ_SMOOTH; T->virr[v] = 0; continue; }
        if (bnd && n == 1) type = TBZ_CORNER;
        else if (nfeat >= 3 || (T->sharp && T->corner_s[v] > 0.0f && nfeat >= 2)) type = TBZ_CORNER;
        else if (nfeat == 2) type = TBZ_CREASE;
        else if (nfeat == 1) type = TBZ_DART;
        else type = TBZ_SMOOTH;
        /* the smooth net at a tagged crease vertex: our tangent plane through the crease tangents */
        if (!T->sharp && !T->seed_plane && type == TBZ_SMOOTH && ntag == 2 && !(T->corner_s[v] > 0.0f)) type = TBZ_CREASE + 16;
        T->vtype[v] = (unsigned char)type;
        if (type == TBZ_SMOOTH || type == TBZ_DART) {
            for (j = 0; j < n; ++j) phi[j] = 2.0 * TBZ_PI / n;
            irr = n != 6 || type == TBZ_DART || (T->sharp && T->corner_s[v] > 0.0f);
        } else {
            /* sectors between sharp (or, type CREASE + 16, tagged) spokes */
            int first = -1, k, start, cnt;
            for (j = 0; j < m; ++j) {
                const int ej = l->ve[l->ve_off[v] + j];
                if (type == TBZ_CREASE + 16 ? T->tag_s[ej] > 0.0f : T->efeat[ej]) { first = j; break; }
            }
            start = first;
            irr = (type == TBZ_CORNER);
            for (cnt = 0; cnt < n;) {
                /* the sector from spoke `start`: faces start, start+1, ... until the next sharp spoke */
                double span, V[3], A[3], B[3], la = 0, lb = 0, d = 0;
                int end = start, c;
                k = 0;
                do {
                    int ej;
                    ++k;
                    end = (end + 1) % m;
                    ej = l->ve[l->ve_off[v] + end];
                    if (type == TBZ_CREASE + 16 ? T->tag_s[ej] > 0.0f : T->efeat[ej]) break;
                } while (cnt + k < n);
                if (type == TBZ_CORNER) {
                    tbz_get(T, v, V); tbz_get(T, tbz_ring(l, v, start), A); tbz_get(T, tbz_ring(l, v, end), B);
                    for (c = 0; c < 3; ++c) {
                        A[c] -= V[c]; B[c] -= V[c];
                        la += A[c] * A[c]; lb += B[c] * B[c]; d += A[c] * B[c];
                    }
                    span = acos(fmax(-1.0, fmin(1.0, d / sqrt(la * lb + 1e-300))));
                    span = fmin(fmax(span, TBZ_PI / 8), 7 * TBZ_PI / 8);
                } else {
                    span = TBZ_PI;
                }
                for (j = 0; j < k; ++j) phi[(start + j) % n] = span / k;
                if (k != 3) irr = 1;
                cnt += k;
                start = end;
            }
            /* ours, regular (three triangles a side): the plain smooth vertex */
            if (type == TBZ_CREASE + 16) T->vtype[v] = (unsigned char)(irr ? (TBZ_CREASE | 16) : TBZ_SMOOTH);
        }
        T->virr[v] = (unsigned char)irr;
    }
}

/* The ring of regular vertex v in the extended mesh seen from its triangle slot j: R[0] = r_j,
 * R[1] = r_{j+1}, ... (six points; across sharp spokes the parallelogram phantoms). */
static void tbz_ring6(const sfb__tbz *T, int v, int j, double R[6][3]) {
    const sfb__level *l = T->l;
    const int n = tbz_nf(l, v), m = l->ve_off[v + 1] - l->ve_off[v];
    double V[3];
    int i, c;
    tbz_get(T, v, V);
    if (T->vtype[v] == TBZ_SMOOTH) {
        for (i = 0; i < 6; ++i) tbz_get(T, tbz_ring(l, v, (j + i) % n), R[i]);
        return;
    }
    {
        /* crease / boundary with three triangles a side: the sector holding slot j */
        int s0 = j, k;
        double S[4][3];
        while (!T->efeat[l->ve[l->ve_off[v] + s0]]) s0 = (s0 + m - 1) % m;
        for (k = 0; k < 4; ++k) tbz_get(T, tbz_ring(l, v, (s0 + k) % m), S[k]);
        /* ccw: C1 = S0, n1, n2, C2 = S3, V + C2 - n2, V + C1 - n1 */
        {
            double E[6][3];
            for (k = 0; k < 4; ++k) memcpy(E[k], S[k], sizeof S[k]);
            for (c = 0; c < 3; ++c) {
                E[4][c] = V[c] + S[3][c] - S[2][c];
                E[5][c] = V[c] + S[0][c] - S[1][c];
            }
            k = (j - s0 + m) % m; /* slot j's position in the sector */
            for (i = 0; i < 6; ++i) memcpy(R[i], E[(k + i) % 6], sizeof E[0]);
        }
    }
}

/* Loop limit corner of a smooth vertex (ALGORITHMS.md 8.2; 8.1 at n = 6). */
static void tbz_loop_corner(const sfb__tbz *T, int v, double P[3]) {
    const sfb__level *l = T->l;
    const int n = tbz_nf(l, v);
    const double cn = cos(2.0 * TBZ_PI / n), a = 0.625 - (0.375 + 0.25 * cn) * (0.375 + 0.25 * cn), w = 3.0 * n / (8.0 * a);
    double V[3], R[3];
    int j;
    tbz_get(T, v, V);
    P[0] = w * V[0]; P[1] = w * V[1]; P[2] = w * V[2];
    for (j = 0; j < n; ++j) { tbz_get(T, tbz_ring(l, v, j), R); tbz_axpy(P, 1.0, R); }
    for (j = 0; j < 3; ++j) P[j] /= (w + n);
}

/* Our irregular crease vertex in the smooth net: its corner point is the crease B-spline's
 * point moved by the mean offset of its two crease neighbours' smooth corner points from
 * their own B-spline points. The smooth surface lies off the crease polygon by that offset
 * along the whole crease (Loop's limit: above a valley, beside the crease where the mesh is
 * not symmetric); pinning the extraordinary vertex to the B-spline made the crease curve dip
 * there, an undulation of its own at every s < 1 (tests/tribezier.c, undulation). A
 * neighbour that is not an ordinary crease vertex (two tagged edges) adds no offset. */
static void tbz_ours_offset(sfb__tbz *T) {
    const sfb__level *l = T->l;
    int v, j, c;
    if (T->sharp || T->seed_plane) return;
    for (v = 0; v < T->nv; ++v) {
        double off[3] = {0.0, 0.0, 0.0};
        int m = l->ve_off[v + 1] - l->ve_off[v], cnt = 0;
        if (T->vtype[v] != (TBZ_CREASE | 16) || !T->virr[v]) continue;
        for (j = 0; j < m; ++j) {
            const int w = tbz_ring(l, v, j);
            int nb[2], nn = 0, i2, m2 = l->ve_off[w + 1] - l->ve_off[w];
            double W[3], A[3], B[3];
            if (!(T->tag_s[l->ve[l->ve_off[v] + j]] > 0.0f) || (T->vtype[w] == (TBZ_CREASE | 16) && T->virr[w])) continue;
            for (i2 = 0; i2 < m2; ++i2)
                if (T->tag_s[l->ve[l->ve_off[w] + i2]] > 0.0f) { if (nn < 2) nb[nn] = tbz_ring(l, w, i2); ++nn; }
            if (nn != 2 || tbz_boundary(l, w) || T->corner_s[w] > 0.0f) continue;
            tbz_get(T, w, W); tbz_get(T, nb[0], A); tbz_get(T, nb[1], B);
            for (c = 0; c < 3; ++c) off[c] += T->x[3 * (size_t)tbz_vp(T, w) + c] - (A[c] + 4.0 * W[c] + B[c]) / 6.0;
            ++cnt;
        }
        if (cnt)
            for (c = 0; c < 3; ++c) T->x[3 * (size_t)tbz_vp(T, v) + c] += off[c] / cnt;
    }
}

/* The initial net (and its fixed points) for the current state. */
static void tbz_initial(sfb__tbz *T) {
    const sfb__level *l = T->l;
    int v, e, f, j, c, k;
    memset(T->fixed, 0, (size_t)T->np);
    /* corners */
    for (v = 0; v < T->nv; ++v) {
        double *P = T->x + 3 * (size_t)tbz_vp(T, v);
        const int type = T->vtype[v] & 15, n = tbz_nf(l, v);
        if (n == 0) { tbz_get(T, v, P); continue; }
        if (!T->virr[v]) {
            double R[6][3], V[3];
            tbz_ring6(T, v, 0, R);
            tbz_get(T, v, V);
            for (c = 0; c < 3; ++c) P[c] = (6.0 * V[c] + R[0][c] + R[1][c] + R[2][c] + R[3][c] + R[4][c] + R[5][c]) / 12.0;
        } else if (type == TBZ_CREASE || type == TBZ_CORNER) {
            tbz_crease_point(T, v, type, P);
        } else if (T->sharp && T->corner_s[v] > 0.0f) {
            tbz_get(T, v, P);
        } else {
            tbz_loop_corner(T, v, P);
        }
        if (type == TBZ_CORNER || (type == TBZ_CREASE && T->virr[v]) || (T->sharp && T->corner_s[v] > 0.0f)) T->fixed[v] = 1;
        if (type == TBZ_CREASE && !T->virr[v] && (T->vtype[v] & 16) == 0) T->fixed[v] = 1; /* = the regular value */
    }
    tbz_ours_offset(T);
    /* edge points: near each end from that end's rules, the middle from the two opposite vertices */
    for (e = 0; e < T->ne; ++e) {
        const int a = l->ev[2 * e], b = l->ev[2 * e + 1];
        int end;
        for (end = 0; end < 2; ++end) {
            const int v = end ? b : a, w = end ? a : b, q = end ? 2 : 0;
            double *E = T->x + 3 * (size_t)tbz_ep(T, e, q), V[3], W[3];
            const int m = tbz_spoke(l, v, e), n = tbz_nf(l, v);
            const double *P = T->x + 3 * (size_t)v;
            tbz_get(T, v, V); tbz_get(T, w, W);
            if (!T->virr[v]) {
                double R[6][3];
                /* a slot whose triangle has the spoke as R[0] or R[1] */
                if (m < n) {
                    tbz_ring6(T, v, m, R);
                    for (c = 0; c < 3; ++c)
                        E[c] = (12.0 * V[c] + 4.0 * R[0][c] + 3.0 * (R[1][c] + R[5][c]) + R[2][c] + R[4][c]) / 24.0;
                } else {
                    tbz_ring6(T, v, m - 1, R);
                    for (c = 0; c < 3; ++c)
                        E[c] = (12.0 * V[c] + 4.0 * R[1][c] + 3.0 * (R[2][c] + R[0][c]) + R[3][c] + R[5][c]) / 24.0;
                }
            } else if (((T->vtype[v] & 15) == TBZ_SMOOTH || (T->vtype[v] & 15) == TBZ_DART)) {
                /* 8.2: P + 3/4 (3 + 2c)/(6n) T_m */
                const double cn = cos(2.0 * TBZ_PI / n), g = 0.75 * (3.0 + 2.0 * cn) / (6.0 * n);
                double R[3];
                memcpy(E, P, 3 * sizeof(double));
                for (k = 0; k < n; ++k) {
                    tbz_get(T, tbz_ring(l, v, (m + k) % n), R);
                    tbz_axpy(E, g * cos(2.0 * TBZ_PI * k / n), R);
                }
            } else {
                /* the B-spline's: 3/4 P + 1/4 (2V + W)/3 */
                for (c = 0; c < 3; ++c) E[c] = 0.75 * P[c] + (2.0 * V[c] + W[c]) / 12.0;
            }
        }
        {
            /* b220 = (2a + 2b + X + Y)/6; across a sharp edge Y = a + b - X, so (a + b)/2 */
            double *M = T->x + 3 * (size_t)tbz_ep(T, e, 1), A[3], B[3], X[3];
            tbz_get(T, a, A); tbz_get(T, b, B);
            if (T->efeat[e] || l->ef_off[e + 1] - l->ef_off[e] < 2) {
                for (c = 0; c < 3; ++c) M[c] = 0.5 * (A[c] + B[c]);
            } else {
                for (c = 0; c < 3; ++c) M[c] = (2.0 * A[c] + 2.0 * B[c]) / 6.0;
                for (k = 0; k < 2; ++k) {
                    const int g = l->ef[l->ef_off[e] + k], s = l->ef_slot[l->ef_off[e] + k];
                    tbz_get(T, l->fv[l->fv_off[g] + (s + 2) % 3], X);
                    tbz_axpy(M, 1.0 / 6.0, X);
                }
            }
        }
        /* a sharp edge between crease/corner ends: the degree-raised cubic B-spline */
        if (T->efeat[e] && (T->vtype[a] & 15) >= TBZ_CREASE && (T->vtype[b] & 15) >= TBZ_CREASE && !(T->vtype[a] & 16) &&
            !(T->vtype[b] & 16)) {
            double P0[3], P3[3], A[3], B[3];
            tbz_crease_point(T, a, T->vtype[a] & 15, P0);
            tbz_crease_point(T, b, T->vtype[b] & 15, P3);
            tbz_get(T, a, A); tbz_get(T, b, B);
            for (c = 0; c < 3; ++c) {
                const double P1 = (2.0 * A[c] + B[c]) / 3.0, P2 = (A[c] + 2.0 * B[c]) / 3.0;
                T->x[3 * (size_t)tbz_ep(T, e, 0) + c] = (P0[c] + 3.0 * P1) / 4.0;
                T->x[3 * (size_t)tbz_ep(T, e, 1) + c] = (P1 + P2) / 2.0;
                T->x[3 * (size_t)tbz_ep(T, e, 2) + c] = (3.0 * P2 + P3[c]) / 4.0;
            }
            T->fixed[tbz_ep(T, e, 0)] = T->fixed[tbz_ep(T, e, 1)] = T->fixed[tbz_ep(T, e, 2)] = 1;
        }
        /* the smooth net at our crease vertex: the crease tangent is the B-spline's */
        for (k = 0; k < 2; ++k) {
            const int v = k ? b : a, w = k ? a : b;
            if ((T->vtype[v] & 16) && T->virr[v] && T->tag_s[e] > 0.0f) {
                double V[3], W[3], *E = T->x + 3 * (size_t)tbz_ep(T, e, k ? 2 : 0);
                const double *P = T->x + 3 * (size_t)v;
                tbz_get(T, v, V); tbz_get(T, w, W);
                for (c = 0; c < 3; ++c) E[c] = 0.25 * P[c] + 0.75 * (2.0 * V[c] + W[c]) / 3.0;
                T->fixed[tbz_ep(T, e, k ? 2 : 0)] = 1;
            }
        }
    }
    /* an irregular smooth vertex keeps its Loop limit point and tangent plane (ALGORITHMS.md 8.2:
     * corner and edge points already satisfy the t = 0 relations): left free, the minimum-norm
     * solve collapses tangents to zero where extraordinary vertices touch (valence 4: the
     * relation X + Y = 0 T holds for X = Y = 0), and with them fixed the constraints stay
     * solvable there (checked on closed meshes of valence 4 and 5 everywhere) */
    {
        for (v = 0; v < T->nv; ++v)
            if (T->virr[v] && (T->vtype[v] & 15) == TBZ_SMOOTH) {
                T->fixed[v] = 1;
                for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                    e = l->ve[j];
                    T->fixed[tbz_ep(T, e, l->ev[2 * e] == v ? 0 : 2)] = 1;
                }
            }
    }
    /* our irregular crease vertex in the smooth net: every spoke's tangent from the sector
     * angles, T(theta) = cos(theta) a + sin(theta) b, a the B-spline's crease tangent (so both
     * crease tangents lie in the plane), b = 2/(3n) sum sin(theta_j) (r_j - V); fixed, so the
     * t = 0 relations hold and no tangent can collapse */
    for (v = 0; v < T->nv; ++v)
        if (T->vtype[v] == (TBZ_CREASE | 16) && T->virr[v]) {
            const int n = tbz_nf(l, v);
            const double *P = T->x + 3 * (size_t)v, *phi = T->phi + l->vf_off[v];
            double th[64], a[3], bv[3] = {0, 0, 0}, V[3], R[3], A[3], B[3];
            int first = -1, other = -1;
            if (n > 64) continue;
            for (j = 0; j < n; ++j)
                if (T->tag_s[l->ve[l->ve_off[v] + j]] > 0.0f) { if (first < 0) first = j; else other = j; }
            if (first < 0 || other < 0) continue;
            tbz_get(T, v, V);
            th[first] = 0.0;
            for (k = 1; k < n; ++k) th[(first + k) % n] = th[(first + k - 1) % n] + phi[(first + k - 1) % n];
            tbz_get(T, tbz_ring(l, v, first), A); tbz_get(T, tbz_ring(l, v, other), B);
            for (c = 0; c < 3; ++c) a[c] = (A[c] - B[c]) / 6.0;
            for (j = 0; j < n; ++j) {
                tbz_get(T, tbz_ring(l, v, j), R);
                for (c = 0; c < 3; ++c) bv[c] += 2.0 / (3.0 * n) * sin(th[j]) * (R[c] - V[c]);
            }
            for (j = 0; j < n; ++j) {
                const int ej = l->ve[l->ve_off[v] + j], q = tbz_ep(T, ej, l->ev[2 * ej] == v ? 0 : 2);
                for (c = 0; c < 3; ++c) T->x[3 * (size_t)q + c] = P[c] + 0.75 * (cos(th[j]) * a[c] + sin(th[j]) * bv[c]);
                T->fixed[q] = 1;
            }
        }
    /* interior points: b211 near corner v of triangle (v, r_m, r_{m+1}) */
    for (f = 0; f < T->nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        for (k = 0; k < 3; ++k) {
            const int v = fv[k], n = tbz_nf(l, v), bnd = tbz_boundary(l, v);
            double *F = T->x + 3 * (size_t)tbz_fp(T, f, k), V[3];
            int m = -1;
            for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j)
                if (l->vf[j] == f) { m = j - l->vf_off[v]; break; }
            tbz_get(T, v, V);
            if (!T->virr[v]) {
                double R[6][3];
                tbz_ring6(T, v, m, R);
                for (c = 0; c < 3; ++c) F[c] = (10.0 * V[c] + 6.0 * R[0][c] + 6.0 * R[1][c] + R[5][c] + R[2][c]) / 24.0;
            } else {
                double A[3], B[3], Cm[3], D[3];
                tbz_get(T, tbz_ring(l, v, m), A);
                tbz_get(T, tbz_ring(l, v, m + 1 <= (bnd ? n : n - 1) ? m + 1 : 0), B);
                if (!bnd || m > 0) tbz_get(T, tbz_ring(l, v, (m + n - 1) % n), Cm);
                else for (c = 0; c < 3; ++c) Cm[c] = V[c] + A[c] - B[c];
                if (!bnd) tbz_get(T, tbz_ring(l, v, (m + 2) % n), D);
                else if (m + 2 <= n) tbz_get(T, tbz_ring(l, v, m + 2), D);
                else for (c = 0; c < 3; ++c) D[c] = V[c] + B[c] - A[c];
                for (c = 0; c < 3; ++c) F[c] = (10.0 * V[c] + 6.0 * A[c] + 6.0 * B[c] + Cm[c] + D[c]) / 24.0;
            }
        }
    }
}

/* ---- the G1 constraints and their least-squares solve ---- */

typedef struct tbz_sys {
    int rows, cap_rows;
    size_t n, cap;
    size_t *off;
    int *edge, cur_edge; /* per row: its mesh edge */
    int *col;       /* global point index */
    double *w;
} tbz_sys;

static int tbz_sys_push(sfb__tbz *T, tbz_sys *S, int col, double w) {
    if (S->n == S->cap) {
        size_t nc = S->cap ? 2 * S->cap : 4096;
        int *c2 = (int *)sfb__realloc(T->ctx, S->col, nc * sizeof(int));
        double *w2;
        if (!c2) return 0;
        S->col = c2;
        w2 = (double *)sfb__realloc(T->ctx, S->w, nc * sizeof(double));
        if (!w2) return 0;
        S->w = w2;
        S->cap = nc;
    }
    S->col[S->n] = col;
    S->w[S->n++] = w;
    return 1;
}
static int tbz_sys_row(sfb__tbz *T, tbz_sys *S) {
    if (S->rows + 1 >= S->cap_rows) {
        int nc = S->cap_rows ? 2 * S->cap_rows : 1024;
        size_t *o2 = (size_t *)sfb__realloc(T->ctx, S->off, ((size_t)nc + 1) * sizeof(size_t));
        int *e2;
        if (!o2) return 0;
        S->off = o2;
        e2 = (int *)sfb__realloc(T->ctx, S->edge, ((size_t)nc + 1) * sizeof(int));
        if (!e2) return 0;
        S->edge = e2;
        S->cap_rows = nc;
    }
    if (S->rows == 0) S->off[0] = 0;
    S->edge[S->rows] = S->cur_edge;
    S->off[++S->rows] = S->n;
    return 1;
}

/* End coefficients (mu, nu, lambda) of the G1 relation along spoke to `w` at vertex v, where X
 * is the derivative towards the triangle after the spoke (ccw) and Y towards the one before;
 * `at_end` for the edge's far end (t = 1). Normalised to mu + nu = 2. */
static void tbz_coef(const sfb__tbz *T, int v, int e, int at_end, double out[3]) {
    const sfb__level *l = T->l;
    const int n = tbz_nf(l, v), m = tbz_spoke(l, v, e);
    const double *phi = T->phi + l->vf_off[v];
    const double after = phi[m % n], before = phi[(m + n - 1) % n];
    double mu, nu, la, s;
    if (!at_end) {
        /* at t = 0: sin(before) T_{m+1} + sin(after) T_{m-1} = sin(after + before) T_m */
        mu = sin(before); nu = sin(after); la = sin(after + before);
    } else {
        /* at t = 1 (seen from the far end, X towards its ring's previous, Y towards its next) */
        mu = sin(after); nu = sin(before); la = mu + nu - sin(after + before);
    }
    s = 2.0 / (mu + nu);
    out[0] = mu * s; out[1] = nu * s; out[2] = la * s;
}

/* Five rows for interior edge e. */
static int tbz_edge_rows(sfb__tbz *T, tbz_sys *S, int e) {
    const sfb__level *l = T->l;
    const int a = l->ev[2 * e], b = l->ev[2 * e + 1];
    int fL = -1, fR = -1, sL = 0, sR = 0, k, j, m;
    int Ei[5], Li[4], Ri[4];
    double c0[3], c1[3];
    for (k = 0; k < 2; ++k) {
        const int g = l->ef[l->ef_off[e] + k], s = l->ef_slot[l->ef_off[e] + k];
        if (l->fv[l->fv_off[g] + s] == a) { fL = g; sL = s; }
        else { fR = g; sR = s; }
    }
    if (fL < 0 || fR < 0) return 1;
    /* left triangle (a, b, C): a at slot sL, b at sL+1, C at sL+2; right (b, a, D): b at sR */
    for (j = 0; j <= 4; ++j) {
        int w[3];
        w[sL] = 4 - j; w[(sL + 1) % 3] = j; w[(sL + 2) % 3] = 0;
        Ei[j] = tbz_pt(T, fL, w);
    }
    for (j = 0; j <= 3; ++j) {
        int w[3];
        w[sL] = 3 - j; w[(sL + 1) % 3] = j; w[(sL + 2) % 3] = 1;
        Li[j] = tbz_pt(T, fL, w);
        w[(sR + 1) % 3] = 3 - j; w[sR] = j; w[(sR + 2) % 3] = 1;
        Ri[j] = tbz_pt(T, fR, w);
    }
    {
        int any = 0;
        for (j = 0; j < 5; ++j) any |= !T->fixed[Ei[j]] && T->dist[Ei[j]] <= TBZ_REACH;
        for (j = 0; j < 4; ++j) any |= (!T->fixed[Li[j]] && T->dist[Li[j]] <= TBZ_REACH) || (!T->fixed[Ri[j]] && T->dist[Ri[j]] <= TBZ_REACH);
        if (!any) return 1;
    }
    /* at a: X towards C (after the spoke in a's ring), Y towards D */
    tbz_coef(T, a, e, 0, c0);
    /* at b: X towards C is b's ring previous, Y towards D its next */
    tbz_coef(T, b, e, 1, c1);
    for (m = 0; m <= 4; ++m) {
        for (j = m - 1; j <= m; ++j) {
            const double *cc = j == m ? c0 : c1;
            const double f = j == m ? (4.0 - m) / 4.0 : m / 4.0;
            if (j < 0 || j > 3) continue;
            /* mu (L_j - E_j) + nu (R_j - E_j) - la (E_{j+1} - E_j) */
            if (!tbz_sys_push(T, S, Li[j], f * cc[0]) || !tbz_sys_push(T, S, Ri[j], f * cc[1]) ||
                !tbz_sys_push(T, S, Ei[j], f * (cc[2] - cc[0] - cc[1])) || !tbz_sys_push(T, S, Ei[j + 1], -f * cc[2]))
                return 0;
        }
        if (!tbz_sys_row(T, S)) return 0;
    }
    return 1;
}

/* Net distances (in steps of the Bezier net) from the irregular vertices' corner points: sweeps
 * over the 30 neighbouring pairs of every face's net (Bellman-Ford: after k sweeps every
 * distance up to k is exact and the others are larger, so the unknowns, dist <= TBZ_REACH, do
 * not depend on the order of the pairs). */
static void tbz_distances(sfb__tbz *T) {
    static const int nb[3][2] = {{1, 0}, {0, 1}, {-1, 1}};
    int pa[30], pb[30], npair = 0, i, f, it, q, jj, a;
    for (jj = 0; jj <= 4; ++jj)
        for (a = 0; a + jj <= 4; ++a)
            for (q = 0; q < 3; ++q) {
                const int i2 = a + nb[q][0], j2 = jj + nb[q][1];
                if (i2 < 0 || i2 + j2 > 4) continue;
                pa[npair] = tbz_qij(a, jj); pb[npair++] = tbz_qij(i2, j2);
            }
    for (i = 0; i < T->np; ++i) T->dist[i] = i < T->nv && T->virr[i] ? 0 : 1000;
    for (it = 0; it < TBZ_REACH + 2; ++it) {
        int changed = 0;
        for (f = 0; f < T->nf; ++f) {
            const int *g = T->grid + 15 * (size_t)f;
            for (q = 0; q < npair; ++q) {
                const int p0 = g[pa[q]], p1 = g[pb[q]];
                if (T->dist[p0] + 1 < T->dist[p1]) { T->dist[p1] = T->dist[p0] + 1; changed = 1; }
                if (T->dist[p1] + 1 < T->dist[p0]) { T->dist[p0] = T->dist[p1] + 1; changed = 1; }
            }
        }
        if (!changed) break;
    }
}

/* Union-find root of unknown i (path halving). */
static int tbz_root(int *parent, int i) {
    while (parent[i] != i) { parent[i] = parent[parent[i]]; i = parent[i]; }
    return i;
}

/* CGLS from zero on one connected component of the constraints (rows `rows[0..nr)`, unknowns
 * `unk[0..nu)` with local[] mapping a point to its column or -1), the three coordinates at once
 * (one matrix, three right-hand sides, each with its own recurrence); adds the change to T->x.
 * The component's matrix is first copied into a compact local CSR (lo/lc/lw: S->n + nr + 1
 * entries each; duplicate columns of a row merged, fixed points left out). w: 6 * nr + 12 * nu +
 * 3 * TBZ_STALL doubles. Stops a coordinate when its residual is below 1e-15 of the scale
 * (consistent: exactly G1), when A^T r has fallen by 1e-13, or when |r|^2 has fallen by less
 * than 1e-5 of itself over the last TBZ_STALL iterations (inconsistent -- touching extraordinary
 * vertices of different valences --: the least-squares residual is reached; what CGLS would
 * still move are the near-null directions, which only make the net wilder). */
#define TBZ_STALL 40
#define TBZ_MAX(a, b) ((a) > (b) ? (a) : (b))
/* sv = A^T r, three coordinates, gathered per unknown from the transpose (co, cr, cw: each
 * column's entries in row order, so each sum adds the terms a row-by-row scatter would, in its
 * order). */
static void tbz_atr(const size_t *co, const int *cr, const double *cw, const double *rr, int nu, double *sv) {
    int i;
    size_t k;
    for (i = 0; i < nu; ++i) {
        double s0 = 0.0, s1 = 0.0, s2 = 0.0;
        for (k = co[i]; k < co[i + 1]; ++k) {
            const double *rv = rr + 3 * (size_t)cr[k];
            s0 += cw[k] * rv[0]; s1 += cw[k] * rv[1]; s2 += cw[k] * rv[2];
        }
        sv[3 * i] = s0; sv[3 * i + 1] = s1; sv[3 * i + 2] = s2;
    }
}
static int tbz_cgls(sfb__tbz *T, const tbz_sys *S, const int *rows, int nr, const int *unk, int nu, const int *local, double scale,
                    double *w, size_t *lo, int *lc, double *lw, size_t *co, int *cr, double *cw) {
    double *rr = w, *q = w + 3 * (size_t)nr, *xs = q + 3 * (size_t)nr, *sv = xs + 3 * (size_t)nu, *p = sv + 3 * (size_t)nu;
    double *hist = p + 3 * (size_t)nu;
    double gamma[3], gamma0[3];
    int active[3], it, i, r, c, left = 3;
    const int maxit = 20 * nu + 200 < 5000 ? 20 * nu + 200 : 5000;
    size_t n = 0, k, k2;
    /* the local matrix, and the residual of the initial net b = -A x0 (fixed points included) */
    for (r = 0; r < nr; ++r) {
        double v[3] = {0.0, 0.0, 0.0};
        lo[r] = n;
        for (k = S->off[rows[r]]; k < S->off[rows[r] + 1]; ++k) {
            const int u = local[S->col[k]];
            for (c = 0; c < 3; ++c) v[c] += S->w[k] * T->x[3 * (size_t)S->col[k] + c];
            if (u < 0) continue;
            for (k2 = lo[r]; k2 < n && lc[k2] != u; ++k2) {}
            if (k2 < n) lw[k2] += S->w[k];
            else { lc[n] = u; lw[n++] = S->w[k]; }
        }
        for (c = 0; c < 3; ++c) rr[3 * r + c] = -v[c];
    }
    lo[nr] = n;
    /* its transpose (co/cr/cw), each column's entries in row order (tbz_atr) */
    for (i = 0; i <= nu; ++i) co[i] = 0;
    for (k = 0; k < n; ++k) ++co[lc[k] + 1];
    for (i = 0; i < nu; ++i) co[i + 1] += co[i];
    for (r = 0; r < nr; ++r)
        for (k = lo[r]; k < lo[r + 1]; ++k) {
            const size_t at = co[lc[k]]++;
            cr[at] = r;
            cw[at] = lw[k];
        }
    for (i = nu; i > 0; --i) co[i] = co[i - 1];
    co[0] = 0;
    for (i = 0; i < 3 * nu; ++i) xs[i] = 0.0;
    tbz_atr(co, cr, cw, rr, nu, sv);
    for (c = 0; c < 3; ++c) { gamma[c] = 0.0; active[c] = 1; }
    for (i = 0; i < nu; ++i)
        for (c = 0; c < 3; ++c) { p[3 * i + c] = sv[3 * i + c]; gamma[c] += sv[3 * i + c] * sv[3 * i + c]; }
    for (c = 0; c < 3; ++c) {
        gamma0[c] = gamma[c];
        if (!(gamma[c] > 0.0)) { active[c] = 0; --left; }
    }
    for (it = 0; it < maxit && left > 0; ++it) {
        double qq[3] = {0.0, 0.0, 0.0}, rn[3] = {0.0, 0.0, 0.0}, r2[3] = {0.0, 0.0, 0.0}, g2[3] = {0.0, 0.0, 0.0}, alpha[3];
        for (r = 0; r < nr; ++r) {
            double v0 = 0.0, v1 = 0.0, v2 = 0.0;
            for (k = lo[r]; k < lo[r + 1]; ++k) {
                const double *pp = p + 3 * lc[k];
                v0 += lw[k] * pp[0]; v1 += lw[k] * pp[1]; v2 += lw[k] * pp[2];
            }
            q[3 * r] = v0; q[3 * r + 1] = v1; q[3 * r + 2] = v2;
            qq[0] += v0 * v0; qq[1] += v1 * v1; qq[2] += v2 * v2;
        }
        for (c = 0; c < 3; ++c) {
            if (active[c] && !(qq[c] > 0.0)) { active[c] = 0; --left; }
            alpha[c] = active[c] ? gamma[c] / qq[c] : 0.0;
        }
        for (i = 0; i < nu; ++i)
            for (c = 0; c < 3; ++c) xs[3 * i + c] += alpha[c] * p[3 * i + c];
        for (r = 0; r < nr; ++r)
            for (c = 0; c < 3; ++c) {
                const double v = rr[3 * r + c] - alpha[c] * q[3 * r + c];
                rr[3 * r + c] = v;
                rn[c] = TBZ_MAX(rn[c], fabs(v));
                r2[c] += v * v;
            }
        for (c = 0; c < 3; ++c) {
            double *h = hist + (size_t)c * TBZ_STALL;
            if (!active[c]) continue;
            if (rn[c] <= 1e-15 * scale || (it >= TBZ_STALL && h[it % TBZ_STALL] - r2[c] <= 1e-5 * r2[c])) { active[c] = 0; --left; }
            h[it % TBZ_STALL] = r2[c];
        }
        if (left == 0) { ++it; break; }
        tbz_atr(co, cr, cw, rr, nu, sv);
        for (i = 0; i < nu; ++i)
            for (c = 0; c < 3; ++c) g2[c] += sv[3 * i + c] * sv[3 * i + c];
        for (c = 0; c < 3; ++c) {
            if (active[c] && g2[c] <= 1e-26 * gamma0[c]) { active[c] = 0; --left; }
            if (!active[c]) continue;
            for (i = 0; i < nu; ++i) p[3 * i + c] = sv[3 * i + c] + (g2[c] / gamma[c]) * p[3 * i + c];
            gamma[c] = g2[c];
        }
    }
    for (i = 0; i < nu; ++i)
        for (c = 0; c < 3; ++c) T->x[3 * (size_t)unk[i] + c] += xs[3 * i + c];
    return it;
}

/* The connected components of the constraints: rows sharing an unknown are in one. rows[] and
 * unk[] list the rows and the unknowns' points component by component, [rstart[i], rstart[i+1])
 * and [ustart[i], ustart[i+1]). */
typedef struct tbz_comps {
    int nc;
    int *rstart, *ustart, *rows, *unk;
} tbz_comps;

static sfb_result tbz_components(sfb__tbz *T, const tbz_sys *S, const int *ucol, int nu, tbz_comps *C) {
    int *parent = (int *)sfb__alloc(T->ctx, ((size_t)nu + 1) * sizeof(int));
    int *comp = (int *)sfb__alloc(T->ctx, ((size_t)nu + (size_t)S->rows + 1) * sizeof(int)); /* per unknown, then per row */
    int i, r, nc = 0;
    sfb_result res = SFB_SUCCESS;
    C->rows = (int *)sfb__alloc(T->ctx, ((size_t)S->rows + 1) * sizeof(int));
    C->unk = (int *)sfb__alloc(T->ctx, ((size_t)nu + 1) * sizeof(int));
    if (!parent || !comp || !C->rows || !C->unk) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    for (i = 0; i < nu; ++i) parent[i] = i;
    for (r = 0; r < S->rows; ++r) {
        int first = -1;
        size_t k;
        for (k = S->off[r]; k < S->off[r + 1]; ++k) {
            const int u = ucol[S->col[k]];
            if (u < 0) continue;
            if (first < 0) first = tbz_root(parent, u);
            else { const int b2 = tbz_root(parent, u); if (b2 != first) parent[b2] = first; }
        }
        comp[nu + r] = first; /* an unknown for now; -1: the row has none (tbz_edge_rows skips those) */
    }
    for (i = 0; i < nu; ++i) comp[i] = -1;
    for (i = 0; i < nu; ++i) { const int root = tbz_root(parent, i); if (comp[root] < 0) comp[root] = nc++; }
    for (i = 0; i < nu; ++i) parent[i] = tbz_root(parent, i);  /* every unknown points at its root... */
    for (i = 0; i < nu; ++i) parent[i] = comp[parent[i]];       /* ...then holds its component */
    C->nc = nc;
    C->rstart = (int *)sfb__calloc(T->ctx, (size_t)nc + 2, sizeof(int));
    C->ustart = (int *)sfb__calloc(T->ctx, (size_t)nc + 2, sizeof(int));
    if (!C->rstart || !C->ustart) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    for (r = 0; r < S->rows; ++r) {
        const int u0 = comp[nu + r];
        comp[nu + r] = u0 >= 0 ? parent[u0] : -1;
        if (u0 >= 0) ++C->rstart[comp[nu + r] + 1];
    }
    for (i = 0; i < nu; ++i) ++C->ustart[parent[i] + 1];
    for (i = 0; i < nc; ++i) {
        C->rstart[i + 1] += C->rstart[i];
        C->ustart[i + 1] += C->ustart[i];
    }
    /* fill, reusing comp[0..nc) (the per-unknown part is no longer needed) as the cursors */
    for (i = 0; i < nc; ++i) comp[i] = C->rstart[i];
    for (r = 0; r < S->rows; ++r)
        if (comp[nu + r] >= 0) C->rows[comp[comp[nu + r]]++] = r;
    for (i = 0; i < nc; ++i) comp[i] = C->ustart[i];
    for (i = 0; i < T->np; ++i)
        if (ucol[i] >= 0) C->unk[comp[parent[ucol[i]]]++] = i;
done:
    sfb__free(T->ctx, parent);
    sfb__free(T->ctx, comp);
    return res;
}

/* The entries of component i's rows in S (its local matrix has at most as many). */
static size_t tbz_comp_entries(const tbz_sys *S, const tbz_comps *C, int i) {
    size_t n = 0;
    int r;
    for (r = C->rstart[i]; r < C->rstart[i + 1]; ++r) n += S->off[C->rows[r] + 1] - S->off[C->rows[r]];
    return n;
}

/* The components to solve, in blocks over the backend's threads (sfb__parallel): components
 * are independent (a component's rows read only its own unknowns, which it alone writes, and
 * points no component moves), so the net is bit for bit that of solving them one by one. A
 * block holds consecutive components of about equal work and its own scratch (tbz_cgls's w, lo,
 * lc, lw, sized for its largest component); local maps every unknown to its column within its
 * component. */
#define TBZ_BLOCKS 32
typedef struct tbz_block {
    double *w, *lw, *cw;
    size_t *lo, *co;
    int *lc, *cr;
} tbz_block;
typedef struct tbz_job {
    sfb__tbz *T;
    const tbz_sys *S;
    const tbz_comps *C;
    const int *local, *todo, *bstart; /* todo[bstart[b] .. bstart[b + 1]): block b's components */
    double scale;
    tbz_block *blk;
    int *its; /* per todo entry: its iterations */
} tbz_job;

static void tbz_solve_blocks(void *arg, int first, int last) {
    const tbz_job *J = (const tbz_job *)arg;
    int b, t;
    for (b = first; b < last; ++b)
        for (t = J->bstart[b]; t < J->bstart[b + 1]; ++t) {
            const int i = J->todo[t], r0 = J->C->rstart[i], u0 = J->C->ustart[i];
            J->its[t] = tbz_cgls(J->T, J->S, J->C->rows + r0, J->C->rstart[i + 1] - r0, J->C->unk + u0, J->C->ustart[i + 1] - u0, J->local,
                                 J->scale, J->blk[b].w, J->blk[b].lo, J->blk[b].lc, J->blk[b].lw, J->blk[b].co, J->blk[b].cr, J->blk[b].cw);
        }
}

/* Solves the components todo[0 .. nt) (see tbz_job). */
static sfb_result tbz_solve_todo(sfb__tbz *T, const tbz_sys *S, const tbz_comps *C, const int *local, const int *todo, int nt, double scale) {
    tbz_job J;
    int bstart[TBZ_BLOCKS + 1], nb = nt < TBZ_BLOCKS ? nt : TBZ_BLOCKS, b, t;
    tbz_block blk[TBZ_BLOCKS];
    size_t total = 0, acc = 0, *ent;
    sfb_result res = SFB_SUCCESS;
    if (nt == 0) return SFB_SUCCESS;
    memset(blk, 0, sizeof blk);
    J.its = (int *)sfb__alloc(T->ctx, (size_t)nt * sizeof(int));
    if (!J.its) return sfb__oom(T->ctx, "tribezier constraints");
    /* a component's work ~ the entries of its rows (ent, per todo entry, in its for now) */
    ent = (size_t *)sfb__alloc(T->ctx, (size_t)nt * sizeof(size_t));
    if (!ent) { sfb__free(T->ctx, J.its); return sfb__oom(T->ctx, "tribezier constraints"); }
    for (t = 0; t < nt; ++t) total += (ent[t] = tbz_comp_entries(S, C, todo[t])) + 1;
    bstart[0] = 0;
    for (b = 1, t = 0; b < nb; ++b) {
        const size_t goal = total / (size_t)nb * (size_t)b;
        while (t < nt && acc < goal) acc += ent[t++] + 1;
        bstart[b] = t;
    }
    bstart[nb] = nt;
    for (b = 0; b < nb && res == SFB_SUCCESS; ++b) {
        size_t mr = 0, mu = 0, me = 0;
        for (t = bstart[b]; t < bstart[b + 1]; ++t) {
            const int i = todo[t];
            const size_t nr = (size_t)(C->rstart[i + 1] - C->rstart[i]), nu = (size_t)(C->ustart[i + 1] - C->ustart[i]);
            mr = nr > mr ? nr : mr; mu = nu > mu ? nu : mu; me = ent[t] > me ? ent[t] : me;
        }
        blk[b].w = (double *)sfb__alloc(T->ctx, (6 * mr + 12 * mu + 3 * TBZ_STALL + 1) * sizeof(double));
        blk[b].lo = (size_t *)sfb__alloc(T->ctx, (mr + 1) * sizeof(size_t));
        blk[b].lc = (int *)sfb__alloc(T->ctx, (me + 1) * sizeof(int));
        blk[b].lw = (double *)sfb__alloc(T->ctx, (me + 1) * sizeof(double));
        blk[b].co = (size_t *)sfb__alloc(T->ctx, (mu + 1) * sizeof(size_t));
        blk[b].cr = (int *)sfb__alloc(T->ctx, (me + 1) * sizeof(int));
        blk[b].cw = (double *)sfb__alloc(T->ctx, (me + 1) * sizeof(double));
        if (!blk[b].w || !blk[b].lo || !blk[b].lc || !blk[b].lw || !blk[b].co || !blk[b].cr || !blk[b].cw) res = sfb__oom(T->ctx, "tribezier constraints");
    }
    if (res == SFB_SUCCESS) {
        J.T = T; J.S = S; J.C = C; J.local = local; J.todo = todo; J.bstart = bstart; J.scale = scale; J.blk = blk;
        sfb__parallel(T->ctx, tbz_solve_blocks, &J, 0, nb);
        for (t = 0; t < nt; ++t) T->st.iterations += J.its[t];
    }
    for (b = 0; b < nb; ++b) {
        sfb__free(T->ctx, blk[b].w); sfb__free(T->ctx, blk[b].lo); sfb__free(T->ctx, blk[b].lc); sfb__free(T->ctx, blk[b].lw);
        sfb__free(T->ctx, blk[b].co); sfb__free(T->ctx, blk[b].cr); sfb__free(T->ctx, blk[b].cw);
    }
    sfb__free(T->ctx, J.its);
    sfb__free(T->ctx, ent);
    return res;
}

/* The smooth net's solve, kept for the sharp net. A component of the sharp net's constraints
 * whose rows, unknowns and the points its rows read are those of a smooth-net component is the
 * very same system: CGLS (the same rows in the same order, the same unknowns, the same stopping:
 * T->scale is the same in both nets) would repeat the smooth net's iterations bit for bit, so the sharp net takes
 * that component's smooth solution instead. Most components lie away from every tagged feature,
 * where both nets have the same points: on the bench's torus this cuts the construction by a third.
 * Recorded only when the smooth net kept our tangent plane (no seed-plane fallback). */
typedef struct tbz_prev {
    int ok;
    tbz_sys S;         /* the smooth net's rows (owned) */
    int *erow;         /* per edge: its first row in S, -1: none */
    double *x0;        /* the smooth net before its solve (3 np) */
    const double *x1;  /* after it */
    int *pcomp;        /* per point: its component, -1: not an unknown */
    int *crows, *cunk; /* per component: its rows and unknowns */
} tbz_prev;

static void tbz_prev_free(sfb_context *ctx, tbz_prev *P) {
    sfb__free(ctx, P->S.off); sfb__free(ctx, P->S.edge); sfb__free(ctx, P->S.col); sfb__free(ctx, P->S.w);
    sfb__free(ctx, P->erow); sfb__free(ctx, P->x0); sfb__free(ctx, P->pcomp); sfb__free(ctx, P->crows); sfb__free(ctx, P->cunk);
    memset(P, 0, sizeof *P);
}

/* Per edge its first row in S, -1: none (an edge's rows are consecutive). */
static void tbz_edge_first_rows(const tbz_sys *S, int ne, int *erow) {
    int e, r;
    for (e = 0; e < ne; ++e) erow[e] = -1;
    for (r = S->rows - 1; r >= 0; --r) erow[S->edge[r]] = r;
}

/* The smooth-net component that is the same system as the sharp net's component (rows[0..nr),
 * unk[0..nu)), -1: none (see tbz_prev). erow: the sharp net's tbz_edge_first_rows. */
static int tbz_same_component(const sfb__tbz *T, const tbz_sys *S, const int *erow, const int *ucol, const int *rows, int nr,
                              const int *unk, int nu) {
    const tbz_prev *P = T->prev;
    int r, j, pc;
    if (nr == 0 || nu == 0) return -1;
    pc = P->pcomp[unk[0]];
    if (pc < 0 || P->crows[pc] != nr || P->cunk[pc] != nu) return -1;
    for (j = 1; j < nu; ++j)
        if (P->pcomp[unk[j]] != pc) return -1;
    /* every row the same as one of pc's (so, with the counts equal, the same rows and unknowns) */
    for (r = 0; r < nr; ++r) {
        const int g = rows[r], e = S->edge[g];
        size_t k, pk;
        int pr;
        if (P->erow[e] < 0) return -1;
        pr = P->erow[e] + (g - erow[e]);
        if (pr >= P->S.rows || P->S.edge[pr] != e || S->off[g + 1] - S->off[g] != P->S.off[pr + 1] - P->S.off[pr]) return -1;
        for (k = S->off[g], pk = P->S.off[pr]; k < S->off[g + 1]; ++k, ++pk) {
            const int col = S->col[k];
            if (col != P->S.col[pk] || S->w[k] != P->S.w[pk] || (ucol[col] >= 0) != (P->pcomp[col] >= 0) ||
                memcmp(T->x + 3 * (size_t)col, P->x0 + 3 * (size_t)col, 3 * sizeof(double)) != 0)
                return -1;
        }
    }
    return pc;
}

/* Applies the smallest change of the unknowns that satisfies the constraints: the minimum-norm
 * least-squares solution, per connected component of the constraint graph (the solution of a
 * block-diagonal system is the blocks' solutions; each block converges at its own pace, so a
 * slow block near touching extraordinary vertices does not hold the others up). */
static sfb_result tbz_solve(sfb__tbz *T) {
    const sfb__level *l = T->l;
    tbz_sys S;
    unsigned char *ours = NULL;
    tbz_comps C;
    int *ucol = NULL, *rstart, *ustart, *rows, *unk, *local = NULL, *erow = NULL, *todo = NULL;
    tbz_prev *rec = T->rec && !T->sharp && !T->reuse_x ? T->rec : NULL;
    int nu = 0, e, i, r, nc, nt = 0;
    double scale = 0.0;
    sfb_result res = SFB_SUCCESS;
    memset(&S, 0, sizeof S);
    memset(&C, 0, sizeof C);
    for (e = 0; e < T->ne; ++e)
        if (l->ef_off[e + 1] - l->ef_off[e] == 2 && !T->efeat[e]) {
            S.cur_edge = e;
            if (!tbz_edge_rows(T, &S, e)) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
        }
    if (S.rows == 0) goto done;
    ucol = (int *)sfb__alloc(T->ctx, (size_t)T->np * sizeof(int));
    local = (int *)sfb__alloc(T->ctx, (size_t)T->np * sizeof(int));
    if (!ucol || !local) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    for (i = 0; i < T->np; ++i) { ucol[i] = (!T->fixed[i] && T->dist[i] <= TBZ_REACH) ? nu++ : -1; local[i] = -1; }
    scale = T->scale;
    if ((res = tbz_components(T, &S, ucol, nu, &C)) != SFB_SUCCESS) goto done;
    nc = C.nc; rstart = C.rstart; ustart = C.ustart; rows = C.rows; unk = C.unk;
    if (rec) {
        /* the net before the solve, and the components (tbz_prev); S joins them at the end */
        rec->x0 = (double *)sfb__alloc(T->ctx, 3 * (size_t)T->np * sizeof(double) + 1);
        rec->erow = (int *)sfb__alloc(T->ctx, ((size_t)T->ne + 1) * sizeof(int));
        rec->pcomp = (int *)sfb__alloc(T->ctx, ((size_t)T->np + 1) * sizeof(int));
        rec->crows = (int *)sfb__alloc(T->ctx, ((size_t)nc + 1) * sizeof(int));
        rec->cunk = (int *)sfb__alloc(T->ctx, ((size_t)nc + 1) * sizeof(int));
        if (!rec->x0 || !rec->erow || !rec->pcomp || !rec->crows || !rec->cunk) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
        memcpy(rec->x0, T->x, 3 * (size_t)T->np * sizeof(double));
        tbz_edge_first_rows(&S, T->ne, rec->erow);
        for (i = 0; i < T->np; ++i) rec->pcomp[i] = -1;
        for (i = 0; i < nc; ++i) {
            int j;
            rec->crows[i] = rstart[i + 1] - rstart[i];
            rec->cunk[i] = ustart[i + 1] - ustart[i];
            for (j = ustart[i]; j < ustart[i + 1]; ++j) rec->pcomp[unk[j]] = i;
        }
    }
    if (T->prev && T->prev->ok) {
        erow = (int *)sfb__alloc(T->ctx, ((size_t)T->ne + 1) * sizeof(int));
        if (!erow) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
        tbz_edge_first_rows(&S, T->ne, erow);
    }
    todo = (int *)sfb__alloc(T->ctx, ((size_t)nc + 1) * sizeof(int));
    if (!todo) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    /* components at an extraordinary crease vertex with our plane (this net's, or in the
     * fallback the first net's) */
    ours = (unsigned char *)sfb__calloc(T->ctx, (size_t)nc + 1, 1);
    if (!ours) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    for (i = 0; i < nc; ++i)
        for (r = rstart[i]; r < rstart[i + 1] && !ours[i]; ++r) {
            const int e2 = S.edge[rows[r]], a = l->ev[2 * e2], b = l->ev[2 * e2 + 1];
            ours[i] = (unsigned char)(((T->vtype[a] & 16) && T->virr[a]) || ((T->vtype[b] & 16) && T->virr[b]) ||
                                      (T->reuse_ours && (T->reuse_ours[a] || T->reuse_ours[b])));
        }
    for (i = 0; i < nc; ++i) {
        const int u0 = ustart[i], cu = ustart[i + 1] - u0;
        int j;
        if (T->reuse_x && !ours[i]) {
            for (j = 0; j < cu; ++j)
                for (r = 0; r < 3; ++r) T->x[3 * (size_t)unk[u0 + j] + r] = T->reuse_x[3 * (size_t)unk[u0 + j] + r];
            continue;
        }
        if (erow) {
            const int pc = tbz_same_component(T, &S, erow, ucol, rows + rstart[i], rstart[i + 1] - rstart[i], unk + u0, cu);
            if (pc >= 0) {
                for (j = 0; j < cu; ++j)
                    for (r = 0; r < 3; ++r) T->x[3 * (size_t)unk[u0 + j] + r] = T->prev->x1[3 * (size_t)unk[u0 + j] + r];
                T->st.reused++;
                continue;
            }
        }
        for (j = 0; j < cu; ++j) local[unk[u0 + j]] = j;
        todo[nt++] = i;
    }
    if ((res = tbz_solve_todo(T, &S, &C, local, todo, nt, scale)) != SFB_SUCCESS) goto done;
    /* the residual left, relative to T->scale; and that of the components around an
     * extraordinary crease vertex with our tangent plane (vtype CREASE | 16), which decides the
     * fallback to the seed's plane (sfb__tribezier_points) */
    {
        for (i = 0; i < nc; ++i)
            for (r = rstart[i]; r < rstart[i + 1]; ++r) {
                int c;
                for (c = 0; c < 3; ++c) {
                    double v = 0.0;
                    size_t k;
                    for (k = S.off[rows[r]]; k < S.off[rows[r] + 1]; ++k) v += S.w[k] * T->x[3 * (size_t)S.col[k] + c];
                    T->st.residual = TBZ_MAX(T->st.residual, fabs(v) / scale);
                    if (ours[i]) T->st.ours_residual = TBZ_MAX(T->st.ours_residual, fabs(v) / scale);
                }
            }
    }
    T->st.unknowns += nu;
    T->st.constraints += S.rows;
    if (rec) { /* the rows join the record */
        rec->S = S;
        memset(&S, 0, sizeof S);
        rec->ok = 1;
    }
done:
    sfb__free(T->ctx, S.off); sfb__free(T->ctx, S.edge); sfb__free(T->ctx, S.col); sfb__free(T->ctx, S.w);
    sfb__free(T->ctx, ucol); sfb__free(T->ctx, local); sfb__free(T->ctx, erow);
    sfb__free(T->ctx, C.rows); sfb__free(T->ctx, C.unk); sfb__free(T->ctx, C.rstart); sfb__free(T->ctx, C.ustart);
    sfb__free(T->ctx, ours); sfb__free(T->ctx, todo);
    return res;
}

/* Builds the net of the current state into T->x. */
static sfb_result tbz_state(sfb__tbz *T, int sharp) {
    T->sharp = sharp;
    tbz_classify(T);
    tbz_initial(T);
    tbz_distances(T);
    return tbz_solve(T);
}

/* Does a patch corner of the net have (nearly) parallel edge tangents? */
static int tbz_degenerate(const sfb__tbz *T) {
    int f, k, c;
    for (f = 0; f < T->nf; ++f)
        for (k = 0; k < 3; ++k) {
            int w[3], p0, p1, p2;
            double a[3], b[3], x[3], la = 0, lb = 0;
            w[k] = 4; w[(k + 1) % 3] = 0; w[(k + 2) % 3] = 0;
            p0 = tbz_pt(T, f, w);
            w[k] = 3; w[(k + 1) % 3] = 1;
            p1 = tbz_pt(T, f, w);
            w[(k + 1) % 3] = 0; w[(k + 2) % 3] = 1;
            p2 = tbz_pt(T, f, w);
            for (c = 0; c < 3; ++c) {
                a[c] = T->x[3 * (size_t)p1 + c] - T->x[3 * (size_t)p0 + c];
                b[c] = T->x[3 * (size_t)p2 + c] - T->x[3 * (size_t)p0 + c];
                la += a[c] * a[c]; lb += b[c] * b[c];
            }
            sfb__cross3(a, b, x);
            if (!(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) > 1e-6 * sqrt(la * lb))) return 1;
        }
    return 0;
}

/* Per vertex the s of the nearest tagged feature (breadth first over mesh edges). */
static sfb_result tbz_vertex_s(sfb__tbz *T, double *vs) {
    const sfb__level *l = T->l;
    int *queue = (int *)sfb__alloc(T->ctx, ((size_t)T->nv + 1) * sizeof(int)), head = 0, tail = 0, v, i;
    unsigned char *seen;
    if (!queue) return sfb__oom(T->ctx, "tribezier");
    seen = (unsigned char *)sfb__calloc(T->ctx, (size_t)T->nv + 1, 1);
    if (!seen) { sfb__free(T->ctx, queue); return sfb__oom(T->ctx, "tribezier"); }
    for (v = 0; v < T->nv; ++v) {
        double sum = 0.0;
        int cnt = 0;
        for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i)
            if (T->tag_s[l->ve[i]] > 0.0f && l->ef_off[l->ve[i] + 1] - l->ef_off[l->ve[i]] == 2) { sum += T->tag_s[l->ve[i]]; cnt++; }
        vs[v] = cnt ? sum / cnt : 0.0;
        if (T->corner_s[v] > 0.0f) { vs[v] = cnt ? fmax(vs[v], T->corner_s[v]) : T->corner_s[v]; cnt = 1; }
        if (cnt) { seen[v] = 1; queue[tail++] = v; }
    }
    while (head < tail) {
        const int u = queue[head++];
        for (i = l->ve_off[u]; i < l->ve_off[u + 1]; ++i) {
            const int w = sfb__other_end(l, l->ve[i], u);
            if (!seen[w]) { seen[w] = 1; vs[w] = vs[u]; queue[tail++] = w; }
        }
    }
    sfb__free(T->ctx, queue); sfb__free(T->ctx, seen);
    return SFB_SUCCESS;
}

static sfb_result tbz_points(sfb_context *ctx, const sfb__level *l, const float *positions, const float *sharp_positions,
                             const sfb_tribezier_options *opt, unsigned flags, double **out, sfb__tbz_stats *stats) {
    sfb__tbz T;
    tbz_prev prev;
    double *x0 = NULL, *vs = NULL, *res = NULL;
    int v, e, f, c, k, any_tag = 0;
    sfb_result r = SFB_SUCCESS;
    *out = NULL;
    /* the nets read rings in fan order: every vertex with triangles a fan, every edge manifold
     * (tbz_check and tbz_split see to it on the mesh; a mesh after one Loop step, tbz_refine,
     * can still fail: two triangles on the same three vertices give four triangles on an edge) */
    for (e = 0; e < l->ne; ++e)
        if (l->etag[e] & SFB__TAG_NONMANIFOLD)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, -1,
                              "tribezier: after one Loop step an edge is non-manifold (two triangles on the same three vertices?)");
    for (v = 0; v < l->nv; ++v)
        if ((l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v])
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, -1,
                              "tribezier: after one Loop step a vertex is non-manifold (two triangles on the same three vertices?)");
    memset(&T, 0, sizeof T);
    memset(&prev, 0, sizeof prev);
    T.ctx = ctx; T.l = l; T.pos = positions;
    for (v = 0; v < 3 * l->nv; ++v) T.scale = fmax(T.scale, fabs((double)positions[v]));
    if (!(T.scale > 0.0)) T.scale = 1.0;
    T.nv = l->nv; T.ne = l->ne; T.nf = l->nf;
    T.np = l->nv + 3 * l->ne + 3 * l->nf;
    T.seed_plane = (flags & SFB__TBZ_SEED_PLANE) != 0;
    T.efeat = (unsigned char *)sfb__calloc(ctx, (size_t)T.ne + 1, 1);
    T.vtype = (unsigned char *)sfb__calloc(ctx, (size_t)T.nv + 1, 1);
    T.virr = (unsigned char *)sfb__calloc(ctx, (size_t)T.nv + 1, 1);
    T.phi = (double *)sfb__calloc(ctx, (size_t)l->vf_off[l->nv] + 1, sizeof(double));
    T.x = (double *)sfb__calloc(ctx, 3 * (size_t)T.np + 1, sizeof(double));
    T.fixed = (unsigned char *)sfb__calloc(ctx, (size_t)T.np + 1, 1);
    T.dist = (int *)sfb__calloc(ctx, (size_t)T.np + 1, sizeof(int));
    T.grid = (int *)sfb__alloc(ctx, 15 * (size_t)T.nf * sizeof(int) + 1);
    T.tag_s = (float *)sfb__calloc(ctx, (size_t)T.ne + 1, sizeof(float));
    T.corner_s = (float *)sfb__calloc(ctx, (size_t)T.nv + 1, sizeof(float));
    res = (double *)sfb__alloc(ctx, 45 * (size_t)T.nf * sizeof(double) + 1);
    if (!T.efeat || !T.vtype || !T.virr || !T.phi || !T.x || !T.fixed || !T.dist || !T.grid || !T.tag_s || !T.corner_s || !res) {
        r = sfb__oom(ctx, "tribezier");
        goto done;
    }
    for (f = 0; f < T.nf; ++f) tbz_patch(&T, f, T.grid + 15 * (size_t)f);
    /* s per feature: the tag clamped to [0, 1] (infinite: 1), or the override */
    for (e = 0; e < T.ne; ++e)
        if (l->ef_off[e + 1] - l->ef_off[e] == 2 && l->es[e] > 0.0f) {
            T.tag_s[e] = opt && opt->sharpness_set ? opt->sharpness : (l->es[e] < 1.0f ? l->es[e] : 1.0f);
            if (T.tag_s[e] <= 0.0f) T.tag_s[e] = 1e-30f; /* a feature at s = 0: the smooth net's treatment */
            any_tag = 1;
        }
    for (v = 0; v < T.nv; ++v)
        if (l->vs[v] > 0.0f && !(tbz_boundary(l, v) && tbz_nf(l, v) == 1)) {
            T.corner_s[v] = opt && opt->sharpness_set ? opt->sharpness : (l->vs[v] < 1.0f ? l->vs[v] : 1.0f);
            if (T.corner_s[v] <= 0.0f) T.corner_s[v] = 1e-30f;
            any_tag = 1;
        }
    /* the smooth net's solve is recorded for the sharp net (tbz_prev), unless asked not to */
    T.rec = any_tag && !(flags & SFB__TBZ_NO_REUSE) ? &prev : NULL;
    r = tbz_state(&T, 0);
    T.rec = NULL;
    if (r == SFB_SUCCESS && !T.seed_plane && any_tag && (T.st.ours_residual > 1e-10 || tbz_degenerate(&T))) {
        /* our crease tangent plane left the constraints around it unsolvable or a patch corner
         * degenerate (seen at valence 8 and up with a crease through the vertex): the smooth net
         * falls back to the seed's kind (measured in tests/tribezier.c). Residuals elsewhere
         * (touching extraordinary vertices of different valences) are no reason to. */
        double *first = T.x;
        unsigned char *was = (unsigned char *)sfb__calloc(ctx, (size_t)T.nv + 1, 1);
        T.x = (double *)sfb__calloc(ctx, 3 * (size_t)T.np + 1, sizeof(double));
        if (!T.x || !was) { sfb__free(ctx, first); sfb__free(ctx, was); r = sfb__oom(ctx, "tribezier"); goto done; }
        tbz_prev_free(ctx, &prev); /* the record is of the net now replaced */
        for (v = 0; v < T.nv; ++v) was[v] = (unsigned char)((T.vtype[v] & 16) && T.virr[v]);
        memset(&T.st, 0, sizeof T.st);
        T.seed_plane = 1;
        T.reuse_x = first;
        T.reuse_ours = was;
        r = tbz_state(&T, 0);
        T.reuse_x = NULL;
        T.reuse_ours = NULL;
        sfb__free(ctx, first);
        sfb__free(ctx, was);
        T.seed_plane = (flags & SFB__TBZ_SEED_PLANE) != 0;
        T.st.fallbacks++;
    }
    if (r != SFB_SUCCESS) goto done;
    if (any_tag) {
        x0 = T.x;
        T.x = (double *)sfb__calloc(ctx, 3 * (size_t)T.np + 1, sizeof(double));
        vs = (double *)sfb__calloc(ctx, (size_t)T.nv + 1, sizeof(double));
        if (!T.x || !vs) { r = sfb__oom(ctx, "tribezier"); goto done; }
        T.pos = sharp_positions;
        prev.x1 = x0;
        T.prev = &prev;
        r = tbz_state(&T, 1);
        T.prev = NULL;
        if (r != SFB_SUCCESS) goto done;
        r = tbz_vertex_s(&T, vs);
        if (r != SFB_SUCCESS) goto done;
    }
    for (f = 0; f < T.nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        const int *g = T.grid + 15 * (size_t)f;
        int i, j, q = 0;
        for (j = 0; j <= 4; ++j)
            for (i = 0; i + j <= 4; ++i, ++q) {
                double s = 0.0, wsum = 0.0;
                if (any_tag) {
                    /* the point's home vertices: weights > 0 */
                    const int w[3] = {4 - i - j, i, j};
                    for (k = 0; k < 3; ++k)
                        if (w[k] > 0 && (w[0] == 4 || w[1] == 4 || w[2] == 4 ? w[k] == 4 : 1)) { s += vs[fv[k]]; wsum += 1.0; }
                    s = wsum > 0.0 ? s / wsum : 0.0;
                    if (s < 1e-20) s = 0.0;
                }
                for (c = 0; c < 3; ++c) {
                    const double sh = T.x[3 * (size_t)g[q] + c];
                    res[45 * (size_t)f + 3 * q + c] = any_tag ? (1.0 - s) * x0[3 * (size_t)g[q] + c] + s * sh : sh;
                }
            }
    }
    *out = res;
    res = NULL;
    if (stats) *stats = T.st;
done:
    sfb__free(ctx, T.efeat); sfb__free(ctx, T.vtype); sfb__free(ctx, T.virr); sfb__free(ctx, T.phi);
    sfb__free(ctx, T.x); sfb__free(ctx, T.fixed); sfb__free(ctx, T.dist); sfb__free(ctx, T.grid); sfb__free(ctx, T.tag_s); sfb__free(ctx, T.corner_s);
    sfb__free(ctx, x0); sfb__free(ctx, vs); sfb__free(ctx, res);
    tbz_prev_free(ctx, &prev);
    return r;
}

/* The refusals of every entry point: an override s outside [0, 1] or NaN, and
 * sfb__tri_mesh_check's (non-manifold vertices are split instead: tbz_split). */
static sfb_result tbz_check(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt) {
    sfb_result r;
    int e;
    if (opt && opt->sharpness_set && !(opt->sharpness >= 0.0f && opt->sharpness <= 1.0f))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "tribezier: sharpness %g is not in [0, 1]", (double)opt->sharpness);
    if ((r = sfb__tri_mesh_check(ctx, l, positions, "tribezier", 0)) != SFB_SUCCESS) return r;
    /* two triangles that run their edge the same way (the rest of the non-manifold edges
     * sfb__tri_mesh_check refused) */
    for (e = 0; e < l->ne; ++e)
        if (l->etag[e] & SFB__TAG_NONMANIFOLD)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, e,
                              "tribezier: edge %d (%d-%d) is non-manifold (its triangles run it the same way: orient them consistently)", e,
                              l->ev[2 * e], l->ev[2 * e + 1]);
    return SFB_SUCCESS;
}

/* Non-manifold vertices (edges are manifold: tbz_check): a vertex whose triangles form more
 * than one fan (two sheets touching at a point, pieces sharing a boundary vertex) becomes one
 * vertex per fan, at the same position, so that every sheet is a manifold mesh of its own: a
 * closed fan's copy is an interior vertex, an open one's a boundary vertex. The triangles keep
 * their order and slots (param faces unchanged). Every copy keeps the vertex's corner tag (the
 * base level makes a non-manifold vertex an infinitely sharp corner, sfb__level_prepare, as
 * OpenSubdiv does), so every sheet passes through the vertex at s = 1 and the sheets still
 * touch there; a closed fan's copy, a corner without sharp edges, stays G1 (tbz_initial).
 * *split = 0: none (sl, *spos untouched). */
static sfb_result tbz_split(sfb_context *ctx, const sfb__level *l, const float *positions, int *split, sfb__level *sl, float **spos) {
    int v, j, f, k, nv2 = l->nv, any = 0;
    int *fan = NULL, *sizes = NULL, *fv = NULL, *parent = NULL, *copy = NULL;
    sfb_result r = SFB_SUCCESS;
    *split = 0;
    for (v = 0; v < l->nv; ++v) any |= (l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v];
    if (!any) return SFB_SUCCESS;
    fan = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));    /* per vf entry: its vertex id in the split */
    parent = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int)); /* union-find over vf entries */
    copy = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    sizes = (int *)sfb__alloc(ctx, ((size_t)l->nf + 1) * sizeof(int));
    fv = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    if (!fan || !parent || !copy || !sizes || !fv) { r = sfb__oom(ctx, "tribezier non-manifold vertices"); goto done; }
    memcpy(fv, l->fv, (size_t)l->nfv * sizeof(int));
    for (f = 0; f < l->nf; ++f) sizes[f] = l->fv_off[f + 1] - l->fv_off[f];
    for (v = 0; v < l->nv; ++v) {
        const int a = l->vf_off[v], b = l->vf_off[v + 1];
        if (!(l->vtag[v] & SFB__TAG_NONMANIFOLD) || a == b) continue;
        for (j = a; j < b; ++j) { parent[j] = j; copy[j] = -1; }
        /* faces of v sharing an edge of v are in one fan */
        for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
            const int e = l->ve[j];
            int ends[2], ne2 = 0, q;
            if (l->ef_off[e + 1] - l->ef_off[e] != 2) continue;
            for (k = l->ef_off[e]; k < l->ef_off[e + 1]; ++k)
                for (q = a; q < b; ++q)
                    if (l->vf[q] == l->ef[k] && ne2 < 2) { ends[ne2++] = q; break; }
            if (ne2 == 2) {
                int x = ends[0], y = ends[1];
                while (parent[x] != x) x = parent[x];
                while (parent[y] != y) y = parent[y];
                if (x != y) parent[y] = x;
            }
        }
        /* the fan of the first face keeps v; the others take new ids */
        for (j = a; j < b; ++j) {
            int root = j;
            while (parent[root] != root) root = parent[root];
            if (copy[root] < 0) copy[root] = root == a || j == a ? v : nv2++;
            fan[j] = copy[root];
            fv[l->fv_off[l->vf[j]] + l->vf_slot[j]] = fan[j];
        }
    }
    *spos = (float *)sfb__alloc(ctx, 3 * (size_t)nv2 * sizeof(float));
    if (!*spos) { r = sfb__oom(ctx, "tribezier non-manifold vertices"); goto done; }
    memcpy(*spos, positions, 3 * (size_t)l->nv * sizeof(float));
    for (v = 0; v < l->nv; ++v)
        if ((l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v])
            for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j)
                if (fan[j] >= l->nv) memcpy(*spos + 3 * (size_t)fan[j], positions + 3 * (size_t)v, 3 * sizeof(float));
    r = sfb__level_from_faces(ctx, nv2, l->nf, sizes, fv, NULL, SFB_ELEMENT_VERTEX, sl);
    if (r != SFB_SUCCESS) { sfb__free(ctx, *spos); *spos = NULL; goto done; }
    /* the tags: an edge keeps its own (the same face slot in both), a vertex and its copies
     * the vertex's */
    for (f = 0; f < l->nf; ++f)
        for (k = l->fv_off[f]; k < l->fv_off[f + 1]; ++k) sl->es[sl->fe[k]] = l->es[l->fe[k]];
    for (v = 0; v < l->nv; ++v) {
        sl->vs[v] = l->vs[v];
        if ((l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v])
            for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j) sl->vs[fan[j]] = l->vs[v];
    }
    memcpy(sl->fhole, l->fhole, (size_t)l->nf);
    sfb__level_compute_rules(sl);
    for (v = 0; v < nv2; ++v)
        if ((sl->vtag[v] & SFB__TAG_NONMANIFOLD) && sl->vf_off[v + 1] > sl->vf_off[v]) {
            /* not a fan even so (tbz_check refused the edges that would make one) */
            const int o = v < l->nv ? v : -1;
            sfb__level_free(ctx, sl);
            sfb__free(ctx, *spos);
            *spos = NULL;
            r = sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, o, "tribezier: vertex %d is non-manifold (its triangles do not form fans)", o);
            goto done;
        }
    *split = 1;
done:
    sfb__free(ctx, fan); sfb__free(ctx, parent); sfb__free(ctx, copy); sfb__free(ctx, sizes); sfb__free(ctx, fv);
    return r;
}

sfb_result sfb__tribezier_points(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                                 unsigned flags, double **out, sfb__tbz_stats *stats) {
    sfb__level sl;
    float *spos = NULL;
    int split;
    sfb_result r;
    *out = NULL;
    r = tbz_check(ctx, l, positions, opt);
    if (r == SFB_SUCCESS) r = tbz_split(ctx, l, positions, &split, &sl, &spos);
    if (r != SFB_SUCCESS) return r;
    if (!split) return tbz_points(ctx, l, positions, positions, opt, flags, out, stats);
    r = tbz_points(ctx, &sl, spos, spos, opt, flags, out, stats);
    sfb__level_free(ctx, &sl);
    sfb__free(ctx, spos);
    return r;
}

/* One Loop step of the triangle mesh `b` into *rl, with the positions of the smooth net's rules
 * (only boundaries sharp) into *ps and of the sharp net's (boundaries, every tagged edge and
 * corner tag) into *pp. Child face 4f + i of triangle f = (V0, V1, V2), edge points E01, E12,
 * E20: i = 0 (V0, E01, E20), 1 (E01, V1, E12), 2 (E20, E12, V2), 3 (E12, E20, E01) -- each in
 * the frame of quadtree child i of the parametric triangle (sfb__patch_locate), so its 15
 * points are that child patch's. Child edges keep their parent edge's tag, the old vertices
 * their corner tags. */
static sfb_result tbz_refine(sfb_context *ctx, const sfb__level *b, const float *pos, sfb__level *rl, float **ps, float **pp) {
    const int nv = b->nv, nf = b->nf, ne = b->ne, nv2 = nv + ne;
    int *sizes = (int *)sfb__alloc(ctx, (size_t)4 * nf * sizeof(int) + 1);
    int *fv = (int *)sfb__alloc(ctx, (size_t)12 * nf * sizeof(int) + 1);
    int f, e, v, k, c, net;
    sfb_result r;
    memset(rl, 0, sizeof *rl);
    *ps = (float *)sfb__alloc(ctx, (size_t)3 * nv2 * sizeof(float) + 1);
    *pp = (float *)sfb__alloc(ctx, (size_t)3 * nv2 * sizeof(float) + 1);
    if (!sizes || !fv || !*ps || !*pp) { r = sfb__oom(ctx, "tribezier refinement"); goto done; }
    for (f = 0; f < nf; ++f) {
        const int *V = b->fv + b->fv_off[f], *E = b->fe + b->fv_off[f]; /* E[k]: edge V[k] -> V[k+1] */
        const int ch[4][3] = {{V[0], nv + E[0], nv + E[2]}, {nv + E[0], V[1], nv + E[1]}, {nv + E[2], nv + E[1], V[2]},
                              {nv + E[1], nv + E[2], nv + E[0]}};
        for (k = 0; k < 4; ++k) {
            sizes[4 * f + k] = 3;
            for (c = 0; c < 3; ++c) fv[12 * f + 3 * k + c] = ch[k][c];
        }
    }
    r = sfb__level_from_faces(ctx, nv2, 4 * nf, sizes, fv, NULL, SFB_ELEMENT_VERTEX, rl);
    if (r != SFB_SUCCESS) goto done;
    for (e = 0; e < rl->ne; ++e) {
        const int a = rl->ev[2 * e], d = rl->ev[2 * e + 1], old = a < nv ? a : d, mid = a < nv ? d : a;
        rl->es[e] = (old < nv && mid >= nv) ? b->es[mid - nv] : 0.0f;
    }
    for (v = 0; v < nv2; ++v) rl->vs[v] = v < nv ? b->vs[v] : 0.0f;
    for (f = 0; f < 4 * nf; ++f) rl->fhole[f] = b->fhole[f / 4];
    for (net = 0; net < 2; ++net) {
        float *out = net ? *pp : *ps;
        /* the sharp edges of this net's rules */
        for (e = 0; e < ne; ++e) {
            const int n2 = b->ef_off[e + 1] - b->ef_off[e], a = b->ev[2 * e], d = b->ev[2 * e + 1];
            const int sharp = n2 < 2 || (net && b->es[e] > 0.0f);
            double P[3];
            for (c = 0; c < 3; ++c) P[c] = sharp ? 0.5 * ((double)pos[3 * a + c] + pos[3 * d + c]) : 0.375 * ((double)pos[3 * a + c] + pos[3 * d + c]);
            if (!sharp)
                for (k = 0; k < 2; ++k) {
                    const int g = b->ef[b->ef_off[e] + k], sl = b->ef_slot[b->ef_off[e] + k];
                    const int o = b->fv[b->fv_off[g] + (sl + 2) % 3];
                    for (c = 0; c < 3; ++c) P[c] += 0.125 * pos[3 * o + c];
                }
            for (c = 0; c < 3; ++c) out[3 * (size_t)(nv + e) + c] = (float)P[c];
        }
        for (v = 0; v < nv; ++v) {
            const int m = b->ve_off[v + 1] - b->ve_off[v], nfv = b->vf_off[v + 1] - b->vf_off[v];
            int ns = 0, sa = -1, sb = -1, j;
            double P[3];
            for (j = 0; j < m; ++j) {
                const int ej = b->ve[b->ve_off[v] + j];
                if (b->ef_off[ej + 1] - b->ef_off[ej] < 2 || (net && b->es[ej] > 0.0f)) {
                    const int w = sfb__other_end(b, ej, v);
                    if (ns == 0) sa = w; else sb = w;
                    ++ns;
                }
            }
            if (nfv == 0 || ns >= 3 || (m > nfv && nfv == 1) || (net && b->vs[v] > 0.0f)) {
                for (c = 0; c < 3; ++c) P[c] = pos[3 * v + c]; /* corner */
            } else if (ns == 2) {
                for (c = 0; c < 3; ++c) P[c] = 0.75 * pos[3 * v + c] + 0.125 * ((double)pos[3 * sa + c] + pos[3 * sb + c]);
            } else {
                /* Loop's rule (the library's, refine.c): (5/8 - (3/8 + cos(2 pi / n) / 4)^2) / n per neighbour */
                const double beta = 0.25 * cos(2.0 * TBZ_PI / m) + 0.375, w = (0.625 - beta * beta) / m;
                for (c = 0; c < 3; ++c) P[c] = (1.0 - m * w) * pos[3 * v + c];
                for (j = 0; j < m; ++j) {
                    const int o = sfb__other_end(b, b->ve[b->ve_off[v] + j], v);
                    for (c = 0; c < 3; ++c) P[c] += w * pos[3 * o + c];
                }
            }
            for (c = 0; c < 3; ++c) out[3 * (size_t)v + c] = (float)P[c];
        }
    }
done:
    sfb__free(ctx, sizes);
    sfb__free(ctx, fv);
    if (r != SFB_SUCCESS) {
        sfb__level_free(ctx, rl);
        sfb__free(ctx, *ps); sfb__free(ctx, *pp);
        *ps = *pp = NULL;
    }
    return r;
}

sfb_result sfb__tribezier_refined_points(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                                         unsigned flags, sfb__level *rl, double **out, sfb__tbz_stats *stats) {
    float *ps = NULL, *pp = NULL, *spos = NULL;
    sfb__level sl;
    int split = 0;
    sfb_result r;
    *out = NULL;
    memset(rl, 0, sizeof *rl);
    r = tbz_check(ctx, l, positions, opt);
    if (r == SFB_SUCCESS) r = tbz_split(ctx, l, positions, &split, &sl, &spos);
    if (r == SFB_SUCCESS) r = tbz_refine(ctx, split ? &sl : l, split ? spos : positions, rl, &ps, &pp);
    if (r == SFB_SUCCESS) r = tbz_points(ctx, rl, ps, pp, opt, flags, out, stats);
    if (r != SFB_SUCCESS) sfb__level_free(ctx, rl);
    if (split) sfb__level_free(ctx, &sl);
    sfb__free(ctx, spos);
    sfb__free(ctx, ps);
    sfb__free(ctx, pp);
    return r;
}

/* One patch per triangle where the G1 constraints are solvable on the mesh itself; where they
 * are not (extraordinary vertices of different valences that touch, found up front, or a
 * residual above 1e-10 left), the net is built on the mesh after one Loop step instead (Peters' remedy: afterwards every
 * extraordinary vertex is surrounded by ordinary ones) and each triangle gets its four child
 * patches (depth 1 of its parametric triangle); the refined net is kept if it is closer to G1. */
/* Do two interior extraordinary vertices of different valences share an edge? (Then the
 * constraints on the mesh itself have no exact solution: the refined net is built directly.) */
static int tbz_touching(const sfb__level *l) {
    int e;
    for (e = 0; e < l->ne; ++e) {
        const int a = l->ev[2 * e], b = l->ev[2 * e + 1], na = tbz_nf(l, a), nb = tbz_nf(l, b);
        if (l->ef_off[e + 1] - l->ef_off[e] != 2 || tbz_boundary(l, a) || tbz_boundary(l, b)) continue;
        if (na != 6 && nb != 6 && na != nb) return 1;
    }
    return 0;
}

static sfb_result tbz_build(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                            sfb__patch_table *pt);

sfb_result sfb__tribezier_build(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                                sfb__patch_table *pt) {
    /* non-manifold vertices split (tbz_split): the same triangles, so the table is the split
     * mesh's */
    sfb__level sl;
    float *spos = NULL;
    int split;
    sfb_result r;
    memset(pt, 0, sizeof *pt);
    r = tbz_check(ctx, l, positions, opt);
    if (r == SFB_SUCCESS) r = tbz_split(ctx, l, positions, &split, &sl, &spos);
    if (r != SFB_SUCCESS) return r;
    if (!split) return tbz_build(ctx, l, positions, opt, pt);
    r = tbz_build(ctx, &sl, spos, opt, pt);
    sfb__level_free(ctx, &sl);
    sfb__free(ctx, spos);
    return r;
}

/* sfb__tribezier_build on a mesh of manifold vertices (checked). */
static sfb_result tbz_build(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                            sfb__patch_table *pt) {
    double *net = NULL, *net4 = NULL;
    sfb__tbz_stats st, st4;
    sfb__level rl;
    sfb_result r;
    memset(&st, 0, sizeof st);
    if (tbz_touching(l)) {
        r = sfb__tribezier_refined_points(ctx, l, positions, opt, 0, &rl, &net4, NULL);
        if (r != SFB_SUCCESS) return r;
        r = sfb__patch_table_beztri_children(ctx, l, net4, pt);
        sfb__free(ctx, net4);
        sfb__level_free(ctx, &rl);
        return r;
    }
    r = sfb__tribezier_points(ctx, l, positions, opt, 0, &net, &st);
    if (r != SFB_SUCCESS) return r;
    if (st.residual > 1e-10) {
        /* a refused step is this build's own business, not a failure the caller should read
         * after a successful create */
        sfb__error_state kept;
        sfb__error_keep(ctx, &kept);
        memset(&st4, 0, sizeof st4);
        r = sfb__tribezier_refined_points(ctx, l, positions, opt, 0, &rl, &net4, &st4);
        if (r == SFB_INVALID_TOPOLOGY) { /* not built after one step: the mesh's own net */
            sfb__log(ctx, SFB_LOG_INFO, "tribezier: the net after one Loop step is refused (%s); the mesh's own net is kept (G1 residual %.3g)",
                     ctx->error, st.residual);
            sfb__error_put_back(ctx, &kept);
            st4.residual = HUGE_VAL;
        } else if (r != SFB_SUCCESS) { sfb__free(ctx, net); return r; }
        if (st4.residual < st.residual) {
            sfb__free(ctx, net);
            r = sfb__patch_table_beztri_children(ctx, l, net4, pt);
            sfb__free(ctx, net4);
            sfb__level_free(ctx, &rl);
            return r;
        }
        sfb__free(ctx, net4);
        sfb__level_free(ctx, &rl);
    }
    r = sfb__patch_table_beztri_own(ctx, l, net, pt);
    sfb__free(ctx, net);
    return r;
}
#line 1 "src/tess.c"
/* Watertight tessellation of the limit surface (sfb_surface_tessellate).
 *
 * Every parametric face ("param face", see sfb_location) is cut into triangles in its own
 * (u,v); the vertices are evaluated through the public sfb_surface_eval, so tessellation runs
 * on whichever backend the context selected. Catmull-Clark param faces are quads (a base quad,
 * or a sub-face of an n-gon); Loop param faces are the base triangles, (u,v) barycentric with
 * corners (0,0), (1,0), (0,1) at the face's vertices in order, so every location has
 * u + v <= 1 (a point on the side u + v = 1 gets its u rounded down if float rounding would
 * put it past). A vertex on the boundary of a param face is shared with the neighbours
 * through a canonical key, so that it is created and evaluated exactly once and the mesh has
 * no cracks:
 *   - a corner at a base vertex: the base vertex (with SFB_TESS_SPLIT_CREASES: the base
 *     vertex within one sector, the faces around it reachable without crossing an infinitely
 *     sharp interior edge);
 *   - a point on a base edge: (edge, step along it from ev[0] to ev[1]); with
 *     SFB_TESS_SPLIT_CREASES an infinitely sharp interior edge has one copy per incident face,
 *     each evaluated from its own face so that it carries that side's normal;
 *   - a point on a spoke of an n-gon (from the midpoint of edge i to the centroid, shared by
 *     sub-faces i and i+1): (n-gon, spoke, step); the centroid: the n-gon.
 * Segment counts belong to those shared entities, not to the faces: a base edge has S
 * segments over its whole length, a spoke T. An n-gon's sub-face sees half of each of its
 * base edges, so an edge an n-gon uses has an even S and its midpoint (a corner of those
 * sub-faces) is one of its points; a quad beside it then sees 2*rate segments on that edge.
 * The first subdivision step puts the edge point at the parametric midpoint on both sides,
 * so step k of S is the same surface point from either face; since each point is evaluated
 * once, the mesh is closed whatever the rounding.
 *
 * A quad param face whose interior rate r equals every boundary count is a regular r x r
 * grid, two triangles per cell (diagonal (i,j)-(i+1,j+1)); a triangle face with all three
 * counts r is the triangular grid of the points (i/r, j/r), i + j <= r, r^2 triangles.
 * Otherwise (adaptive rates, quads beside n-gons) a quad gets an inner grid of rate
 * R = max(r,2) without its outer ring, a triangle the points of the rate R = max(r,3)
 * triangular grid that are not on its sides (an inner triangular grid of rate R - 3), and
 * each side is stitched from its boundary points to the inner grid's side by a zipper strip:
 * no T-junctions. Triangles are counter-clockwise in (u,v), which is the du x dv normal side.
 *
 * Adaptive mode (tolerance > 0): a param face gets the first rate c in 1, 2, 4, ... (< rate,
 * else rate) for which the surface at the midpoints of the c-grid's edges (quads: the c x c
 * grid's cell edges and diagonals; triangles: the three edges of each of its c^2 triangles)
 * is within `tolerance` of the chords; a shared edge takes the largest rate of its faces.
 * This samples the surface: a feature narrower than a cell can be missed at that rate.
 *
 * Trimming (cfg->trim, seed 000 section V.5): param face t reads tile t of the mask (every face
 * the one mask when the atlas is 0 x 0 or 1 x 1; faces past the last tile are not trimmed)
 * through the bilinear interpolation of its texel centres, clamped at the tile's borders; a
 * point is kept where the value / 255 is >= 0.5. A tile whose texels are all >= 128 keeps its
 * face whole and one whose texels are all <= 127 drops it (the bilinear value lies between its
 * texels' extremes). Otherwise the 0.5 contour crosses the tile, and the face's rate is raised
 * to max(tile width, tile height) (at most SFB__TESS_MAX_RATE) so that a cell is at most one
 * texel wide: the contour is followed within one texel whatever rate was asked for. The raised
 * rates go through the per-face rates and shared edge counts of adaptive mode, so faces of
 * different rates still meet without cracks.
 * Every triangle corner is then classified by its own face's mask at its (u,v) in that face:
 * a triangle with three trimmed corners is dropped, one with three kept corners kept, and
 * otherwise each edge whose ends differ is cut where the mask first changes sides walking from
 * its lower vertex id. Along a segment the mask is a quadratic in the segment's parameter
 * between the texel-centre lines it crosses; each such piece is split at its extremum into
 * monotone parts and the first part whose ends differ is bisected on the exact bilinear value,
 * in double precision. The kept part (a triangle, or a convex quad split along its shorter
 * (u,v) diagonal) keeps the triangle's counter-clockwise order. Where the contour bends inside
 * a cell the straight cut leaves a sliver of less than a cell on one side.
 * A cut point is keyed by its tessellation edge (the two vertex ids) in a hash table, so the
 * two triangles on an edge share one vertex and the kept mesh stays watertight. On an edge
 * between two param faces each face cuts with its own mask: the faces share the point when
 * they put it at the same place along the edge (within 1e-7 of its length), else each side
 * has its own and the seam opens there, as the masks disagree. A cut within SFB__TRIM_SNAP of
 * an end in (u,v) (a few float steps: it would round onto it) is that end, and a kept polygon
 * that repeats a vertex loses the repeat (fewer than 3 left: nothing). Cut points are new
 * vertices, located in the face that made them and evaluated with the others through
 * sfb_surface_eval, so on the selected backend. Vertices that no kept triangle uses are
 * removed and the others keep their order, so an all-white mask gives the untrimmed output
 * exactly.
 *
 * Thread safety: reads the surface only; allocations, errors and progress go through the
 * surface's context, so one call per context at a time. */

#define SFB__TESS_MAX_RATE 1024
#define SFB__TESS_MAX_SEG (2 * SFB__TESS_MAX_RATE) /* a quad edge beside an n-gon sub-face */
#define SFB__TESS_EVAL_CHUNK 65536                 /* locations per sfb_surface_eval call */
#define SFB__TESS_FACE_CHUNK 1024                  /* param faces between progress reports */
#define SFB__TRIM_MAX_SIZE 16384                   /* texels on a side of a trimming mask */
#define SFB__TRIM_SNAP 2.5e-7                      /* a cut this near an end of its edge, in (u,v), is that end */

SFB_API sfb_tess_config sfb_tess_config_init(int rate) {
    sfb_tess_config c;
    memset(&c, 0, sizeof c);
    c.rate = rate;
    return c;
}

SFB_API void sfb_tess_data_free(sfb_tess_data *d) {
    sfb_context *ctx;
    if (!d) return;
    ctx = d->ctx_;
    if (ctx) {
        sfb__free(ctx, d->positions); sfb__free(ctx, d->normals); sfb__free(ctx, d->locations);
        sfb__free(ctx, d->triangles); sfb__free(ctx, d->triangle_faces); sfb__free(ctx, d->uvs);
    }
    memset(d, 0, sizeof *d);
}

/* A cut point: the edge (lo << 32 | hi, vertex ids), its place t from lo to hi, the vertex
 * and the param face that computed it. vid < 0: an empty slot. */
typedef struct sfb__trim_cut {
    unsigned long long key;
    double t;
    int vid, face;
} sfb__trim_cut;

typedef struct sfb__tess {
    sfb_context *ctx;
    const sfb_surface *s;
    const sfb__level *l;          /* the prepared base level the patches were built from */
    const sfb__patch_table *pt;
    int rate, split;              /* split: some edges have a copy per face (esplit) */
    unsigned char *esplit;        /* split: per base edge, its faces get their own copies of its points */
    int loop;                     /* Loop: every param face is a base triangle */
    int *prate;                   /* per param face: interior rate, 0 = nothing (hole) */
    int *eseg;                    /* per base edge: segments over the whole edge */
    unsigned char *engon;         /* per base edge: an n-gon uses it (eseg is then even) */
    int *sseg;                    /* per n-gon sub-face i (param face): segments of spoke i */
    int *uf;                      /* split: union-find over face corners, one set per sector */
    int *ecopy;                   /* split: per face corner slot, the ef entry of its outgoing edge */
    int *vcorner;                 /* vertex of each base vertex (split: of each sector's root corner) */
    int *vedge;                   /* per ef entry: first vertex of the interior points of that edge copy */
    int *vspoke;                  /* per n-gon sub-face: first vertex of the interior points of its spoke */
    int *vcenter;                 /* per base face: its centroid vertex (n-gons) */
    int *ifirst;                  /* per param face: first vertex of its interior points */
    int *bids;                    /* scratch: 4 boundary chains, then one outer and one inner chain */
    size_t nvert, ntri;
    /* emit pass */
    sfb_location *loc;
    int *tri, *tface;
    size_t tri_at;
    /* trimming (NULL trim: none of these is used) */
    const sfb_trim_mask *trim;
    int ntiles, tiles_u, tw, th;  /* tiles in use (1: one mask for all faces), tile size in texels */
    unsigned char *fstate;        /* per param face: SFB__TRIM_KEEP, _DROP or _CUT */
    double *cuv;                  /* per vertex: (u,v) in the face being emitted (faces to cut) */
    unsigned char *ckept;         /* per vertex: kept by that face's mask */
    int *otri, *oface;            /* trimmed triangles (grown) */
    size_t ocount, ocap;
    sfb_location *nloc;           /* cut points: vertex nvert + i (grown) */
    size_t nnew, ncap;
    sfb__trim_cut *cuts;          /* hash table of cut points by tessellation edge */
    size_t cut_cap, cut_count;
    sfb_result err;               /* first failure inside the emit pass */
} sfb__tess;

enum { SFB__TRIM_KEEP = 0, SFB__TRIM_DROP = 1, SFB__TRIM_CUT = 2 };

static void *sfb__tess_array(sfb_context *ctx, size_t count, size_t size) {
    size_t bytes;
    if (!sfb__mul_size(count, size, &bytes) || bytes > ((size_t)-1) - 16) return NULL;
    return sfb__alloc(ctx, bytes + 1); /* + 1: never a zero-size block */
}

static void sfb__tess_free_work(sfb__tess *T) {
    sfb_context *ctx = T->ctx;
    sfb__free(ctx, T->prate); sfb__free(ctx, T->eseg); sfb__free(ctx, T->engon); sfb__free(ctx, T->sseg);
    sfb__free(ctx, T->uf); sfb__free(ctx, T->ecopy); sfb__free(ctx, T->vcorner); sfb__free(ctx, T->vedge);
    sfb__free(ctx, T->vspoke); sfb__free(ctx, T->vcenter); sfb__free(ctx, T->ifirst); sfb__free(ctx, T->bids);
    T->prate = T->eseg = T->sseg = T->uf = T->ecopy = T->vcorner = T->vedge = T->vspoke = T->vcenter = T->ifirst = T->bids = NULL;
    sfb__free(ctx, T->esplit);
    T->engon = T->esplit = NULL;
    sfb__free(ctx, T->fstate); sfb__free(ctx, T->cuv); sfb__free(ctx, T->ckept); sfb__free(ctx, T->otri);
    sfb__free(ctx, T->oface); sfb__free(ctx, T->nloc); sfb__free(ctx, T->cuts);
    T->fstate = T->ckept = NULL;
    T->cuv = NULL;
    T->otri = T->oface = NULL;
    T->nloc = NULL;
    T->cuts = NULL;
    if (T->trim) sfb__free(ctx, T->loc); /* trimming: the untrimmed locations are scratch */
    T->loc = NULL;
}

static int sfb__tess_face_n(const sfb__level *l, int f) { return l->fv_off[f + 1] - l->fv_off[f]; }

/* Edges whose sides get their own vertices (sfb__tess_mark_splits): under SFB_TESS_SPLIT_CREASES
 * the infinitely sharp interior ones, under SFB_TESS_UVS the UV seams. */
static int sfb__tess_split_edge(const sfb__tess *T, int e) { return T->split && T->esplit[e]; }

/* Whether the faces of base edge e disagree on the UV at either of its ends (uvl: the base UV
 * layout, whose faces are the base level's). */
static int sfb__tess_uv_seam(const sfb__level *l, const sfb__level *uvl, int e) {
    int a = l->ef_off[e], z = l->ef_off[e + 1], q, u0 = -1, u1 = -1;
    for (q = a; q < z; ++q) {
        int g = l->ef[q], o = l->fv_off[g], n = l->fv_off[g + 1] - o, sl = l->ef_slot[q];
        int c0 = o + sl, c1 = o + (sl + 1) % n, t;
        if (l->fv[c0] != l->ev[2 * e]) { t = c0; c0 = c1; c1 = t; } /* c0 at ev[0], c1 at ev[1] */
        if (q == a) { u0 = uvl->fv[c0]; u1 = uvl->fv[c1]; }
        else if (uvl->fv[c0] != u0 || uvl->fv[c1] != u1) return 1;
    }
    return 0;
}

/* An infinitely sharp edge not on the boundary (a boundary edge has one side only). */
static int sfb__tess_crease_edge(const sfb__level *l, int e) {
    return l->es[e] >= SFB_SHARPNESS_INFINITE && !(l->etag[e] & SFB__TAG_BOUNDARY);
}

static int sfb__tess_find(int *uf, int x) {
    while (uf[x] != x) {
        uf[x] = uf[uf[x]];
        x = uf[x];
    }
    return x;
}

static void sfb__tess_union(int *uf, int a, int b) {
    a = sfb__tess_find(uf, a);
    b = sfb__tess_find(uf, b);
    if (a < b) uf[b] = a;
    else if (b < a) uf[a] = b;
}

static int sfb__tess_new(sfb__tess *T, int count) {
    int id = (int)T->nvert;
    T->nvert += (size_t)count;
    return id;
}

/* (u,v) as floats; on a triangle param face u is rounded down where rounding both to nearest
 * would give u + v > 1 (points on the side u + v = 1), which evaluation refuses. */
static void sfb__tess_uv(int tri, double u, double v, sfb_location *L) {
    float fu = (float)u, fv = (float)v;
    if (tri && (double)fu + (double)fv > 1.0) {
        fu = (float)(1.0 - (double)fv);
        while (fu > 0.0f && (double)fu + (double)fv > 1.0) fu = nextafterf(fu, 0.0f);
    }
    L->u = fu;
    L->v = fv;
}

/* ---- trimming ---- */

/* The mask tile of param face pf (its first texel; rows are the mask's width apart), or NULL
 * for a face past the last tile of an atlas. */
static const unsigned char *sfb__trim_tile(const sfb__tess *T, int pf) {
    const sfb_trim_mask *m = T->trim;
    if (T->ntiles == 1) return m->texels;
    if (pf < 0 || pf >= T->ntiles) return NULL;
    return m->texels + (size_t)(pf / T->tiles_u) * (size_t)T->th * (size_t)m->width + (size_t)(pf % T->tiles_u) * (size_t)T->tw;
}

/* The mask at (u,v) of a tile, in [0,1]: the bilinear interpolation of the texel centres,
 * clamped at the tile's borders, / 255. */
static double sfb__trim_value(const sfb__tess *T, const unsigned char *tile, double u, double v) {
    int tw = T->tw, th = T->th, i0, j0, i1, j1;
    size_t w = (size_t)T->trim->width;
    double x = u * tw - 0.5, y = v * th - 0.5, fx, fy, a, b;
    if (!(x > 0.0)) x = 0.0; /* NaN too */
    if (x > tw - 1) x = tw - 1;
    if (!(y > 0.0)) y = 0.0;
    if (y > th - 1) y = th - 1;
    i0 = (int)x;
    j0 = (int)y;
    if (i0 > tw - 2) i0 = tw > 1 ? tw - 2 : 0;
    if (j0 > th - 2) j0 = th > 1 ? th - 2 : 0;
    fx = x - i0;
    fy = y - j0;
    i1 = tw > 1 ? i0 + 1 : i0;
    j1 = th > 1 ? j0 + 1 : j0;
    a = (1.0 - fx) * tile[(size_t)j0 * w + (size_t)i0] + fx * tile[(size_t)j0 * w + (size_t)i1];
    b = (1.0 - fx) * tile[(size_t)j1 * w + (size_t)i0] + fx * tile[(size_t)j1 * w + (size_t)i1];
    return ((1.0 - fy) * a + fy * b) / 255.0;
}

/* Kept (1) or trimmed (0) at p0 + t (p1 - p0); t = 1 is p1 itself. */
static int sfb__trim_kept_at(const sfb__tess *T, const unsigned char *tile, const double *p0, const double *p1, double t) {
    double u = p1[0], v = p1[1];
    if (t < 1.0) {
        u = p0[0] + t * (p1[0] - p0[0]);
        v = p0[1] + t * (p1[1] - p0[1]);
    }
    return sfb__trim_value(T, tile, u, v) >= 0.5;
}

static double sfb__trim_g(const sfb__tess *T, const unsigned char *tile, const double *p0, const double *p1, double t) {
    double u = p1[0], v = p1[1];
    if (t < 1.0) {
        u = p0[0] + t * (p1[0] - p0[0]);
        v = p0[1] + t * (p1[1] - p0[1]);
    }
    return sfb__trim_value(T, tile, u, v) - 0.5;
}

/* The texel-centre lines x = k (integers 0..n-1, where the bilinear pieces change) strictly
 * between x0 and x0 + dx: from *k in steps *step while *k != *end. */
static void sfb__trim_lines(double x0, double dx, int n, long *k, long *end, int *step) {
    double x1 = x0 + dx;
    long first, last;
    *step = dx > 0.0 ? 1 : -1;
    *k = *end = 0;
    if (!(dx != 0.0)) return;
    if (dx > 0.0) {
        first = (long)floor(x0) + 1;
        last = (long)ceil(x1) - 1;
        if (first < 0) first = 0;
        if (last > n - 1) last = n - 1;
        if (first <= last) { *k = first; *end = last + 1; }
    } else {
        first = (long)ceil(x0) - 1;
        last = (long)floor(x1) + 1;
        if (first > n - 1) first = n - 1;
        if (last < 0) last = 0;
        if (first >= last) { *k = first; *end = last - 1; }
    }
}

/* Where the mask first changes sides along p0 -> p1, whose ends are on different sides
 * (kept0: the side of p0). Between texel-centre lines the mask is a quadratic in t; each
 * piece is split at its extremum into monotone parts, and the first part whose ends differ
 * is bisected on the exact value. Returns t in (0,1]. */
static double sfb__trim_solve(const sfb__tess *T, const unsigned char *tile, const double *p0, const double *p1, int kept0) {
    double x0 = p0[0] * T->tw - 0.5, dx = (p1[0] - p0[0]) * T->tw;
    double y0 = p0[1] * T->th - 0.5, dy = (p1[1] - p0[1]) * T->th;
    double ta = 0.0;
    long kx, kx_end, ky, ky_end;
    int sx, sy;
    sfb__trim_lines(x0, dx, T->tw, &kx, &kx_end, &sx);
    sfb__trim_lines(y0, dy, T->th, &ky, &ky_end, &sy);
    for (;;) {
        double tb = 1.0, tx = 2.0, ty = 2.0;
        if (kx != kx_end) tx = ((double)kx - x0) / dx;
        if (ky != ky_end) ty = ((double)ky - y0) / dy;
        if (tx <= ty && tx < 1.0) { tb = tx; kx += sx; }
        else if (ty < 1.0) { tb = ty; ky += sy; }
        if (tb > ta) {
            double ga = sfb__trim_g(T, tile, p0, p1, ta), gm = sfb__trim_g(T, tile, p0, p1, 0.5 * (ta + tb));
            double gb = sfb__trim_g(T, tile, p0, p1, tb), c = 2.0 * (gb + ga - 2.0 * gm), b = gb - ga - c, ends[2], lo = ta;
            int n = 0, q;
            if (c != 0.0) {
                double sm = -b / (2.0 * c);
                if (sm > 0.0 && sm < 1.0) ends[n++] = ta + sm * (tb - ta);
            }
            ends[n++] = tb;
            for (q = 0; q < n; ++q) {
                double hi = ends[q];
                if (sfb__trim_kept_at(T, tile, p0, p1, hi) != kept0) {
                    int it;
                    for (it = 0; it < 80; ++it) {
                        double mid = 0.5 * (lo + hi);
                        if (!(mid > lo && mid < hi)) break;
                        if (sfb__trim_kept_at(T, tile, p0, p1, mid) == kept0) lo = mid;
                        else hi = mid;
                    }
                    return 0.5 * (lo + hi);
                }
                lo = hi;
            }
            ta = tb;
        }
        if (tb >= 1.0) break;
    }
    return 1.0; /* not reached: p1 is on the other side */
}

static size_t sfb__trim_hash(unsigned long long key) {
    key ^= key >> 29;
    key *= 0x9E3779B97F4A7C15ULL;
    return (size_t)(key ^ (key >> 32));
}

/* Grows an array to hold at least `need` elements (doubling); 0 when that fails. */
static int sfb__trim_grow(sfb_context *ctx, void **p, size_t *cap, size_t need, size_t elem) {
    size_t nc = *cap ? *cap : 1024, bytes;
    void *np;
    if (need <= *cap) return 1;
    while (nc < need) nc *= 2;
    if (!sfb__mul_size(nc, elem, &bytes)) return 0;
    np = sfb__realloc(ctx, *p, bytes);
    if (!np) return 0;
    *p = np;
    *cap = nc;
    return 1;
}

static void sfb__trim_fail(sfb__tess *T, sfb_result r) {
    if (T->err == SFB_SUCCESS) T->err = r;
}

/* Adds an entry to the cut table, growing it to stay at most half full. */
static int sfb__trim_insert(sfb__tess *T, unsigned long long key, double t, int vid, int face) {
    size_t i, mask;
    if ((T->cut_count + 1) * 2 > T->cut_cap) {
        size_t nc = T->cut_cap * 2, j;
        sfb__trim_cut *nt = (sfb__trim_cut *)sfb__tess_array(T->ctx, nc, sizeof(sfb__trim_cut));
        if (!nt) return 0;
        for (j = 0; j < nc; ++j) nt[j].vid = -1;
        for (j = 0; j < T->cut_cap; ++j)
            if (T->cuts[j].vid >= 0) {
                for (i = sfb__trim_hash(T->cuts[j].key) & (nc - 1); nt[i].vid >= 0; i = (i + 1) & (nc - 1)) {}
                nt[i] = T->cuts[j];
            }
        sfb__free(T->ctx, T->cuts);
        T->cuts = nt;
        T->cut_cap = nc;
    }
    mask = T->cut_cap - 1;
    for (i = sfb__trim_hash(key) & mask; T->cuts[i].vid >= 0; i = (i + 1) & mask) {}
    T->cuts[i].key = key;
    T->cuts[i].t = t;
    T->cuts[i].vid = vid;
    T->cuts[i].face = face;
    T->cut_count++;
    return 1;
}

/* The vertex where the edge p-q of a triangle of param face pf crosses the contour, with its
 * (u,v) in that face; -1 (T->err set) on failure. */
static int sfb__trim_cut_edge(sfb__tess *T, const unsigned char *tile, int p, int q, int pf, double *uv) {
    int lo = p < q ? p : q, hi = p < q ? q : p, vid = -1, found = 0;
    const double *a = T->cuv + 2 * (size_t)lo, *b = T->cuv + 2 * (size_t)hi;
    unsigned long long key = (unsigned long long)(unsigned)lo << 32 | (unsigned)hi;
    size_t mask = T->cut_cap - 1, i;
    double t = 0.0;
    for (i = sfb__trim_hash(key) & mask; T->cuts[i].vid >= 0; i = (i + 1) & mask)
        if (T->cuts[i].key == key && T->cuts[i].face == pf) { /* this face cut it already */
            t = T->cuts[i].t;
            vid = T->cuts[i].vid;
            found = 1;
            break;
        }
    if (!found) {
        double len = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]));
        t = sfb__trim_solve(T, tile, a, b, T->ckept[lo]);
        if (t <= 1e-9 || t * len <= SFB__TRIM_SNAP) vid = lo;
        else if (t >= 1.0 - 1e-9 || (1.0 - t) * len <= SFB__TRIM_SNAP) vid = hi;
        else
            for (i = sfb__trim_hash(key) & mask; T->cuts[i].vid >= 0; i = (i + 1) & mask)
                if (T->cuts[i].key == key && fabs(T->cuts[i].t - t) <= 1e-7) { /* another face cut it at the same place */
                    vid = T->cuts[i].vid;
                    break;
                }
    }
    if (vid == lo) { uv[0] = a[0]; uv[1] = a[1]; }
    else if (vid == hi) { uv[0] = b[0]; uv[1] = b[1]; }
    else { uv[0] = a[0] + t * (b[0] - a[0]); uv[1] = a[1] + t * (b[1] - a[1]); }
    if (found) return vid;
    if (vid < 0) {
        sfb_location *L;
        if (T->nvert + T->nnew >= (size_t)SFB_MAX_ELEMENTS) {
            sfb__trim_fail(T, sfb__error(T->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                                         "trimmed tessellation makes more than %d vertices (SFB_MAX_ELEMENTS)", SFB_MAX_ELEMENTS));
            return -1;
        }
        if (!sfb__trim_grow(T->ctx, (void **)&T->nloc, &T->ncap, T->nnew + 1, sizeof(sfb_location))) {
            sfb__trim_fail(T, sfb__oom(T->ctx, "tessellation"));
            return -1;
        }
        vid = (int)(T->nvert + T->nnew);
        L = &T->nloc[T->nnew++];
        L->face = pf;
        sfb__tess_uv(T->loop, uv[0] < 0.0 ? 0.0 : uv[0] > 1.0 ? 1.0 : uv[0], uv[1] < 0.0 ? 0.0 : uv[1] > 1.0 ? 1.0 : uv[1], L);
    }
    if (!sfb__trim_insert(T, key, t, vid, pf)) {
        sfb__trim_fail(T, sfb__oom(T->ctx, "tessellation"));
        return -1;
    }
    return vid;
}

static void sfb__trim_push(sfb__tess *T, int a, int b, int c, int pf) {
    size_t cap = T->ocap;
    if (T->ocount >= (size_t)SFB_MAX_ELEMENTS) {
        sfb__trim_fail(T, sfb__error(T->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                                     "trimmed tessellation makes more than %d triangles (SFB_MAX_ELEMENTS)", SFB_MAX_ELEMENTS));
        return;
    }
    if (T->ocount >= cap) { /* both arrays to twice the triangles */
        size_t nc = cap ? 2 * cap : 1024, b1, b3;
        int *nf = NULL, *nt = NULL;
        if (sfb__mul_size(nc, sizeof(int), &b1) && sfb__mul_size(nc, 3 * sizeof(int), &b3)) {
            nf = (int *)sfb__realloc(T->ctx, T->oface, b1);
            if (nf) T->oface = nf;
            nt = nf ? (int *)sfb__realloc(T->ctx, T->otri, b3) : NULL;
        }
        if (!nt) {
            sfb__trim_fail(T, sfb__oom(T->ctx, "tessellation"));
            return;
        }
        T->otri = nt;
        T->ocap = nc;
    }
    T->otri[3 * T->ocount] = a;
    T->otri[3 * T->ocount + 1] = b;
    T->otri[3 * T->ocount + 2] = c;
    T->oface[T->ocount++] = pf;
}

/* One triangle (counter-clockwise) of param face pf through the mask: dropped, kept, or cut
 * to its kept part. */
static void sfb__trim_triangle(sfb__tess *T, int a, int b, int c, int pf) {
    const unsigned char *tile;
    int v[3], poly[4], ids[4], n = 0, m = 0, k;
    double puv[4][2], quv[4][2];
    if (T->err != SFB_SUCCESS || T->fstate[pf] == SFB__TRIM_DROP) return;
    if (T->fstate[pf] == SFB__TRIM_KEEP || (T->ckept[a] && T->ckept[b] && T->ckept[c])) {
        sfb__trim_push(T, a, b, c, pf);
        return;
    }
    if (!T->ckept[a] && !T->ckept[b] && !T->ckept[c]) return;
    tile = sfb__trim_tile(T, pf);
    v[0] = a; v[1] = b; v[2] = c;
    for (k = 0; k < 3; ++k) {
        int p = v[k], q = v[(k + 1) % 3];
        if (T->ckept[p]) {
            poly[n] = p;
            puv[n][0] = T->cuv[2 * (size_t)p];
            puv[n][1] = T->cuv[2 * (size_t)p + 1];
            ++n;
        }
        if (T->ckept[p] != T->ckept[q]) {
            int x = sfb__trim_cut_edge(T, tile, p, q, pf, puv[n]);
            if (x < 0) return;
            poly[n++] = x;
        }
    }
    /* a cut point at a corner repeats it: drop repeats (cyclically) */
    for (k = 0; k < n; ++k)
        if (m == 0 || ids[m - 1] != poly[k]) {
            ids[m] = poly[k];
            quv[m][0] = puv[k][0];
            quv[m][1] = puv[k][1];
            ++m;
        }
    while (m > 1 && ids[m - 1] == ids[0]) --m;
    if (m == 3) {
        sfb__trim_push(T, ids[0], ids[1], ids[2], pf);
    } else if (m == 4) { /* convex: split along the shorter diagonal */
        double d02 = (quv[0][0] - quv[2][0]) * (quv[0][0] - quv[2][0]) + (quv[0][1] - quv[2][1]) * (quv[0][1] - quv[2][1]);
        double d13 = (quv[1][0] - quv[3][0]) * (quv[1][0] - quv[3][0]) + (quv[1][1] - quv[3][1]) * (quv[1][1] - quv[3][1]);
        if (d02 <= d13) {
            sfb__trim_push(T, ids[0], ids[1], ids[2], pf);
            sfb__trim_push(T, ids[0], ids[2], ids[3], pf);
        } else {
            sfb__trim_push(T, ids[1], ids[2], ids[3], pf);
            sfb__trim_push(T, ids[1], ids[3], ids[0], pf);
        }
    }
}

/* The location a vertex is evaluated at: the first param face that reaches it in the emit
 * pass (for a split crease copy that is always a face on its own side). */
static void sfb__tess_loc(sfb__tess *T, int id, int pf, double u, double v) {
    if (T->loc && T->loc[id].face < 0) {
        T->loc[id].face = pf;
        sfb__tess_uv(T->loop, u, v, &T->loc[id]);
    }
    if (T->cuv && T->fstate[pf] == SFB__TRIM_CUT) { /* trimming: where this face sees it, and its side */
        T->cuv[2 * (size_t)id] = u;
        T->cuv[2 * (size_t)id + 1] = v;
        T->ckept[id] = (unsigned char)(sfb__trim_value(T, sfb__trim_tile(T, pf), u, v) >= 0.5);
    }
}

static int sfb__tess_corner(sfb__tess *T, int f, int slot) {
    int c = T->l->fv_off[f] + slot;
    int key = T->split ? sfb__tess_find(T->uf, c) : T->l->fv[c];
    if (T->vcorner[key] < 0) T->vcorner[key] = sfb__tess_new(T, 1);
    return T->vcorner[key];
}

/* Point `fidx` of the S points of face f's edge `slot`, counted in the face's direction
 * (fidx 0 = the face's vertex at `slot`). Shared by every face on that edge copy through the
 * edge's own direction. */
static int sfb__tess_epoint(sfb__tess *T, int f, int slot, int fidx) {
    const sfb__level *l = T->l;
    int o = l->fv_off[f], n = l->fv_off[f + 1] - o, e = l->fe[o + slot], S = T->eseg[e], copy, g;
    if (fidx <= 0) return sfb__tess_corner(T, f, slot);
    if (fidx >= S) return sfb__tess_corner(T, f, (slot + 1) % n);
    copy = sfb__tess_split_edge(T, e) ? T->ecopy[o + slot] : l->ef_off[e];
    if (T->vedge[copy] < 0) T->vedge[copy] = sfb__tess_new(T, S - 1);
    g = l->fv[o + slot] == l->ev[2 * e] ? fidx : S - fidx;
    return T->vedge[copy] + g - 1;
}

static int sfb__tess_center(sfb__tess *T, int f) {
    if (T->vcenter[f] < 0) T->vcenter[f] = sfb__tess_new(T, 1);
    return T->vcenter[f];
}

/* Point t of spoke i of n-gon f: t = 0 at the midpoint of edge i, t = T at the centroid. */
static int sfb__tess_spoke(sfb__tess *T, int f, int i, int t) {
    const sfb__level *l = T->l;
    int pf = T->pt->face_ptex[f] + i, n = T->sseg[pf];
    if (t <= 0) return sfb__tess_epoint(T, f, i, T->eseg[l->fe[l->fv_off[f] + i]] / 2);
    if (t >= n) return sfb__tess_center(T, f);
    if (T->vspoke[pf] < 0) T->vspoke[pf] = sfb__tess_new(T, n - 1);
    return T->vspoke[pf] + t - 1;
}

static void sfb__tess_tri(sfb__tess *T, int a, int b, int c, int pf) {
    size_t t;
    if (T->trim) {
        T->tri_at++;
        sfb__trim_triangle(T, a, b, c, pf);
        return;
    }
    t = T->tri_at++;
    T->tri[3 * t] = a;
    T->tri[3 * t + 1] = b;
    T->tri[3 * t + 2] = c;
    T->tface[t] = pf;
}

/* Stitches a boundary chain (na segments, point i at i/na along the side) to the inner
 * grid's side (nb segments, point j at (j + o2/2)/R: o2 = 2 on a quad, where the inner grid's
 * side is inset by one cell; o2 = 3 on a triangle, where the inner triangle's corner (1,1)
 * projects to 1.5/R along each side), both running counter-clockwise around the face. Each
 * step adds the triangle whose new cross edge is the more nearly perpendicular to the side
 * (positions compared in units of 1/(2 na R), exactly), which keeps them well shaped. */
static void sfb__tess_zipper(sfb__tess *T, const int *outer, int na, const int *inner, int nb, int R, int o2, int pf) {
    int i = 0, j = 0;
    while (i < na || j < nb) {
        long to = labs(2L * (i + 1) * R - (long)(2 * j + o2) * na);     /* outer step: edge outer[i+1] - inner[j] */
        long ti = labs((long)(2 * j + 2 + o2) * na - 2L * i * R);       /* inner step: edge outer[i] - inner[j+1] */
        if (j >= nb || (i < na && to <= ti)) {
            sfb__tess_tri(T, outer[i], outer[i + 1], inner[j], pf);
            ++i;
        } else {
            sfb__tess_tri(T, outer[i], inner[j + 1], inner[j], pf);
            ++j;
        }
    }
}

/* A triangle param face (Loop), as sfb__tess_face. Its sides, counter-clockwise in (u,v):
 * edge 0 from P0 (0,0) to P1 (1,0), edge 1 from P1 to P2 (0,1), edge 2 from P2 to P0; point
 * (i,j) of a rate-R grid is (i/R, j/R). The points strictly inside (i, j >= 1,
 * i + j <= R - 1) are numbered row by row in j, row j holding i = 1 .. R-1-j. */
static void sfb__tess_face_tri(sfb__tess *T, int pf, int emit) {
    const sfb__level *l = T->l;
    int f = T->pt->ptex_face[pf], r = T->prate[pf];
    int o = l->fv_off[f], s[3], *b[3], *inner, k, q, i, j, regular, R, base;
    if (r <= 0) return;
    for (k = 0; k < 3; ++k) {
        b[k] = T->bids + (size_t)k * (SFB__TESS_MAX_SEG + 1);
        s[k] = T->eseg[l->fe[o + k]];
        for (q = 0; q <= s[k]; ++q) b[k][q] = sfb__tess_epoint(T, f, k, q);
    }
    inner = T->bids + (size_t)5 * (SFB__TESS_MAX_SEG + 1);
    regular = s[0] == r && s[1] == r && s[2] == r;
    R = regular ? r : (r < 3 ? 3 : r);
    if (!emit) {
        T->ifirst[pf] = sfb__tess_new(T, (R - 1) * (R - 2) / 2);
        if (regular) T->ntri += (size_t)r * (size_t)r;
        else T->ntri += (size_t)(R - 3) * (size_t)(R - 3) + (size_t)s[0] + (size_t)s[1] + (size_t)s[2] + (size_t)3 * (size_t)(R - 3);
        return;
    }
    for (q = 0; q <= s[0]; ++q) sfb__tess_loc(T, b[0][q], pf, (double)q / s[0], 0.0);
    for (q = 0; q <= s[1]; ++q) sfb__tess_loc(T, b[1][q], pf, (double)(s[1] - q) / s[1], (double)q / s[1]);
    for (q = 0; q <= s[2]; ++q) sfb__tess_loc(T, b[2][q], pf, 0.0, (double)(s[2] - q) / s[2]);
    base = T->ifirst[pf];
#define SFB__TRI_INNER(i, j) (base + ((j) - 1) * (R - 1) - ((j) - 1) * (j) / 2 + ((i) - 1))
    for (j = 1; j < R - 1; ++j)
        for (i = 1; i + j < R; ++i) sfb__tess_loc(T, SFB__TRI_INNER(i, j), pf, (double)i / R, (double)j / R);
    if (regular) {
#define SFB__TRI_ID(i, j) ((j) == 0 ? b[0][i] : (i) + (j) == r ? b[1][j] : (i) == 0 ? b[2][r - (j)] : SFB__TRI_INNER(i, j))
        for (j = 0; j < r; ++j)
            for (i = 0; i + j < r; ++i) {
                sfb__tess_tri(T, SFB__TRI_ID(i, j), SFB__TRI_ID(i + 1, j), SFB__TRI_ID(i, j + 1), pf);
                if (i + j + 2 <= r) sfb__tess_tri(T, SFB__TRI_ID(i + 1, j), SFB__TRI_ID(i + 1, j + 1), SFB__TRI_ID(i, j + 1), pf);
            }
#undef SFB__TRI_ID
        return;
    }
    /* the inner triangular grid: points with i, j >= 1, i + j <= R - 1 */
    for (j = 1; j + 2 < R; ++j)
        for (i = 1; i + j + 2 <= R; ++i) {
            sfb__tess_tri(T, SFB__TRI_INNER(i, j), SFB__TRI_INNER(i + 1, j), SFB__TRI_INNER(i, j + 1), pf);
            if (i + j + 3 <= R) sfb__tess_tri(T, SFB__TRI_INNER(i + 1, j), SFB__TRI_INNER(i + 1, j + 1), SFB__TRI_INNER(i, j + 1), pf);
        }
    /* the ring, one side at a time, counter-clockwise; the inner side of side k runs between
     * the inner corners (1,1), (R-2,1), (1,R-2) in the same order */
    for (k = 0; k < 3; ++k) {
        for (q = 0; q <= R - 3; ++q)
            inner[q] = k == 0 ? SFB__TRI_INNER(1 + q, 1) : k == 1 ? SFB__TRI_INNER(R - 2 - q, 1 + q) : SFB__TRI_INNER(1, R - 2 - q);
        sfb__tess_zipper(T, b[k], s[k], inner, R - 3, R, 3, pf);
    }
#undef SFB__TRI_INNER
}

/* One param face. Count pass (emit = 0): creates the ids of every point it touches and
 * counts its triangles. Emit pass: records the locations of points not yet located and
 * writes the triangles. Both passes visit faces in the same order, so ids agree. */
static void sfb__tess_face(sfb__tess *T, int pf, int emit) {
    const sfb__level *l = T->l;
    int f = T->pt->ptex_face[pf], sub = T->pt->ptex_corner[pf], r = T->prate[pf];
    int o = l->fv_off[f], s[4], *b[4], *outer, *inner, k, i, j, regular, R, base;
    if (T->loop) {
        sfb__tess_face_tri(T, pf, emit);
        return;
    }
    if (r <= 0) return;
    for (k = 0; k < 4; ++k) b[k] = T->bids + (size_t)k * (SFB__TESS_MAX_SEG + 1);
    outer = T->bids + (size_t)4 * (SFB__TESS_MAX_SEG + 1);
    inner = outer + (SFB__TESS_MAX_SEG + 1);
    /* the four sides in natural order: v=0 and v=1 with u increasing, u=1 and u=0 with v
     * increasing */
    if (sub < 0) {
        for (k = 0; k < 4; ++k) s[k] = T->eseg[l->fe[o + k]];
        for (k = 0; k <= s[0]; ++k) b[0][k] = sfb__tess_epoint(T, f, 0, k);
        for (k = 0; k <= s[1]; ++k) b[1][k] = sfb__tess_epoint(T, f, 1, k);
        for (k = 0; k <= s[2]; ++k) b[2][k] = sfb__tess_epoint(T, f, 2, s[2] - k); /* slot 2 runs (1,1) -> (0,1) */
        for (k = 0; k <= s[3]; ++k) b[3][k] = sfb__tess_epoint(T, f, 3, s[3] - k); /* slot 3 runs (0,1) -> (0,0) */
    } else {
        int n = sfb__tess_face_n(l, f), ip = (sub + n - 1) % n;
        s[0] = T->eseg[l->fe[o + sub]] / 2;
        s[1] = T->sseg[pf];
        s[2] = T->sseg[T->pt->face_ptex[f] + ip];
        s[3] = T->eseg[l->fe[o + ip]] / 2;
        for (k = 0; k <= s[0]; ++k) b[0][k] = sfb__tess_epoint(T, f, sub, k);        /* v_i -> mid(v_i, v_i+1) */
        for (k = 0; k <= s[1]; ++k) b[1][k] = sfb__tess_spoke(T, f, sub, k);         /* spoke i -> centroid */
        for (k = 0; k <= s[2]; ++k) b[2][k] = sfb__tess_spoke(T, f, ip, k);          /* spoke i-1 -> centroid */
        for (k = 0; k <= s[3]; ++k) b[3][k] = sfb__tess_epoint(T, f, ip, 2 * s[3] - k); /* v_i -> mid(v_i-1, v_i) */
    }
    regular = s[0] == r && s[1] == r && s[2] == r && s[3] == r;
    R = regular ? r : (r < 2 ? 2 : r);
    if (!emit) {
        T->ifirst[pf] = sfb__tess_new(T, (R - 1) * (R - 1));
        if (regular) T->ntri += (size_t)2 * (size_t)r * (size_t)r;
        else T->ntri += (size_t)2 * (size_t)(R - 2) * (size_t)(R - 2) + (size_t)s[0] + (size_t)s[1] + (size_t)s[2] + (size_t)s[3] +
                        (size_t)4 * (size_t)(R - 2);
        return;
    }
    for (k = 0; k <= s[0]; ++k) sfb__tess_loc(T, b[0][k], pf, (double)k / s[0], 0.0);
    for (k = 0; k <= s[1]; ++k) sfb__tess_loc(T, b[1][k], pf, 1.0, (double)k / s[1]);
    for (k = 0; k <= s[2]; ++k) sfb__tess_loc(T, b[2][k], pf, (double)k / s[2], 1.0);
    for (k = 0; k <= s[3]; ++k) sfb__tess_loc(T, b[3][k], pf, 0.0, (double)k / s[3]);
    base = T->ifirst[pf];
    for (j = 1; j < R; ++j)
        for (i = 1; i < R; ++i) sfb__tess_loc(T, base + (j - 1) * (R - 1) + (i - 1), pf, (double)i / R, (double)j / R);
#define SFB__INNER(i, j) (base + ((j) - 1) * (R - 1) + ((i) - 1))
    if (regular) {
        for (j = 0; j < r; ++j)
            for (i = 0; i < r; ++i) {
                int id[4], c;
                for (c = 0; c < 4; ++c) {
                    int x = i + (c == 1 || c == 2), y = j + (c >= 2);
                    id[c] = y == 0 ? b[0][x] : x == r ? b[1][y] : y == r ? b[2][x] : x == 0 ? b[3][y] : SFB__INNER(x, y);
                }
                sfb__tess_tri(T, id[0], id[1], id[2], pf);
                sfb__tess_tri(T, id[0], id[2], id[3], pf);
            }
        return;
    }
    for (j = 1; j < R - 1; ++j)
        for (i = 1; i < R - 1; ++i) {
            int a = SFB__INNER(i, j), bb = SFB__INNER(i + 1, j), c = SFB__INNER(i + 1, j + 1), d = SFB__INNER(i, j + 1);
            sfb__tess_tri(T, a, bb, c, pf);
            sfb__tess_tri(T, a, c, d, pf);
        }
    /* the ring, one side at a time, counter-clockwise: v=0, u=1, v=1 (reversed), u=0 (reversed) */
    for (k = 0; k < 4; ++k) {
        int q;
        for (q = 0; q <= s[k]; ++q) outer[q] = (k < 2) ? b[k][q] : b[k][s[k] - q];
        for (q = 0; q <= R - 2; ++q) {
            int t = (k < 2) ? 1 + q : R - 1 - q; /* position along the side, inset by one cell */
            inner[q] = k == 0 ? SFB__INNER(t, 1) : k == 1 ? SFB__INNER(R - 1, t) : k == 2 ? SFB__INNER(t, R - 1) : SFB__INNER(1, t);
        }
        sfb__tess_zipper(T, outer, s[k], inner, R - 2, R, 2, pf);
    }
#undef SFB__INNER
}

static int sfb__tess_live(const sfb__tess *T, int pf) {
    return !T->l->fhole[T->pt->ptex_face[pf]] && T->pt->ptex_root[pf] != -1;
}

/* Largest squared distance between the surface at the midpoints of the c x c grid's cell
 * edges and diagonals (the (2c+1)^2 samples P) and the chords the triangles make there. */
static double sfb__tess_chord_error(const float *P, int c) {
    int g = 2 * c + 1, i, j, q;
    double worst = 0.0;
    for (j = 0; j <= c; ++j)
        for (i = 0; i <= c; ++i) {
            /* (mid, end a, end b) sample offsets from corner (2i, 2j): bottom edge, left edge, diagonal */
            static const int chk[3][6] = { { 1, 0, 0, 0, 2, 0 }, { 0, 1, 0, 0, 0, 2 }, { 1, 1, 0, 0, 2, 2 } };
            for (q = 0; q < 3; ++q) {
                int x = 2 * i, y = 2 * j, cc;
                const float *m, *a, *b;
                double d2 = 0.0;
                if ((q != 1 && i == c) || (q != 0 && j == c)) continue; /* past the far sides */
                m = P + 3 * ((size_t)(y + chk[q][1]) * g + (size_t)(x + chk[q][0]));
                a = P + 3 * ((size_t)(y + chk[q][3]) * g + (size_t)(x + chk[q][2]));
                b = P + 3 * ((size_t)(y + chk[q][5]) * g + (size_t)(x + chk[q][4]));
                for (cc = 0; cc < 3; ++cc) {
                    double d = (double)m[cc] - 0.5 * ((double)a[cc] + (double)b[cc]);
                    d2 += d * d;
                }
                if (!(d2 <= worst)) worst = d2; /* NaN propagates: such a face is refined */
            }
        }
    return worst;
}

/* The same on a triangle param face: the samples are the points (x, y) of the rate-2c
 * triangular grid (x + y <= 2c), row by row in y; the chords are the three edges of each of
 * the c-grid's c (c+1) / 2 upward triangles, which are all of its edges. */
static double sfb__tess_chord_error_tri(const float *P, int c) {
    int g = 2 * c + 1, i, j, q;
    double worst = 0.0;
#define SFB__TRI_SAMPLE(x, y) (P + 3 * ((size_t)(y) * (size_t)(2 * g + 1 - (y)) / 2 + (size_t)(x)))
    for (j = 0; j < c; ++j)
        for (i = 0; i + j < c; ++i) {
            /* (mid, end a, end b) offsets from corner (2i, 2j): bottom edge, left edge, slanted edge */
            static const int chk[3][6] = { { 1, 0, 0, 0, 2, 0 }, { 0, 1, 0, 0, 0, 2 }, { 1, 1, 2, 0, 0, 2 } };
            for (q = 0; q < 3; ++q) {
                int x = 2 * i, y = 2 * j, cc;
                const float *m = SFB__TRI_SAMPLE(x + chk[q][0], y + chk[q][1]);
                const float *a = SFB__TRI_SAMPLE(x + chk[q][2], y + chk[q][3]);
                const float *b = SFB__TRI_SAMPLE(x + chk[q][4], y + chk[q][5]);
                double d2 = 0.0;
                for (cc = 0; cc < 3; ++cc) {
                    double d = (double)m[cc] - 0.5 * ((double)a[cc] + (double)b[cc]);
                    d2 += d * d;
                }
                if (!(d2 <= worst)) worst = d2; /* NaN propagates: such a face is refined */
            }
        }
#undef SFB__TRI_SAMPLE
    return worst;
}

/* Adaptive rates: candidates 1, 2, 4, ... below `rate` are tested in rounds over a chunk of
 * faces, many faces per sfb_surface_eval call; a face keeps the first candidate within
 * tolerance, else `rate`. */
static sfb_result sfb__tess_adaptive(sfb__tess *T, float tolerance, float p0, float p1) {
    sfb_context *ctx = T->ctx;
    int nptex = T->pt->nptex, maxc = 1, first, pf;
    size_t need, cap;
    sfb_location *loc = NULL;
    float *pos = NULL;
    int *list = NULL;
    sfb_result r = SFB_SUCCESS;
    double tol2 = (double)tolerance * (double)tolerance;
    if (T->rate == 1) return SFB_SUCCESS;
    while (maxc * 2 < T->rate) maxc *= 2;
    need = (size_t)(2 * maxc + 1) * (size_t)(2 * maxc + 1);
    cap = need > SFB__TESS_EVAL_CHUNK ? need : SFB__TESS_EVAL_CHUNK;
    loc = (sfb_location *)sfb__tess_array(ctx, cap, sizeof *loc);
    pos = (float *)sfb__tess_array(ctx, cap, 3 * sizeof(float));
    list = (int *)sfb__tess_array(ctx, SFB__TESS_FACE_CHUNK, sizeof(int));
    if (!loc || !pos || !list) { r = sfb__oom(ctx, "tessellation"); goto done; }
    for (first = 0; first < nptex; first += SFB__TESS_FACE_CHUNK) {
        int last = first + SFB__TESS_FACE_CHUNK < nptex ? first + SFB__TESS_FACE_CHUNK : nptex, n = 0, c;
        r = sfb__progress(ctx, p0 + (p1 - p0) * (float)first / (float)nptex, "tessellate");
        if (r != SFB_SUCCESS) goto done;
        for (pf = first; pf < last; ++pf)
            if (T->prate[pf] > 0) list[n++] = pf;
        for (c = 1; c < T->rate && n > 0; c *= 2) {
            int g = 2 * c + 1, a = 0, keep = 0, q;
            size_t per = T->loop ? (size_t)g * (size_t)(g + 1) / 2 : (size_t)g * (size_t)g;
            while (a < n) {
                int bnd = a, x, y;
                size_t used = 0;
                sfb_eval_output eo;
                while (bnd < n && used + per <= cap) {
                    for (y = 0; y < g; ++y)
                        for (x = 0; x < (T->loop ? g - y : g); ++x) {
                            sfb_location *L = &loc[used++];
                            L->face = list[bnd];
                            sfb__tess_uv(T->loop, (double)x / (g - 1), (double)y / (g - 1), L);
                        }
                    ++bnd;
                }
                memset(&eo, 0, sizeof eo);
                eo.position = pos;
                r = sfb_surface_eval(T->s, loc, (int)used, &eo);
                if (r != SFB_SUCCESS) goto done;
                for (q = a; q < bnd; ++q) {
                    const float *P = pos + 3 * per * (size_t)(q - a);
                    double err = T->loop ? sfb__tess_chord_error_tri(P, c) : sfb__tess_chord_error(P, c);
                    if (err <= tol2) T->prate[list[q]] = c;
                    else list[keep++] = list[q];
                }
                a = bnd;
            }
            n = keep;
        }
    }
done:
    sfb__free(ctx, loc);
    sfb__free(ctx, pos);
    sfb__free(ctx, list);
    return r;
}

/* Which side of 0.5 a tile's texels are on: all kept, all trimmed, or both (the contour
 * crosses it). */
static int sfb__trim_scan(const sfb__tess *T, const unsigned char *tile) {
    int lo = 0, hi = 0, i, j;
    for (j = 0; j < T->th; ++j) {
        const unsigned char *row = tile + (size_t)j * (size_t)T->trim->width;
        for (i = 0; i < T->tw; ++i) {
            if (row[i] >= 128) hi = 1;
            else lo = 1;
        }
        if (lo && hi) return SFB__TRIM_CUT;
    }
    return lo ? SFB__TRIM_DROP : SFB__TRIM_KEEP;
}

/* The trimming state of every param face, and the rate of those the contour crosses raised
 * to one cell per texel of their tile (at most SFB__TESS_MAX_RATE). */
static sfb_result sfb__trim_rates(sfb__tess *T, float p) {
    const sfb_trim_mask *m = T->trim;
    int nptex = T->pt->nptex, atlas = m->tiles_u > 1 || m->tiles_v > 1, pf, need, one = SFB__TRIM_KEEP;
    sfb_result r;
    T->tiles_u = atlas ? m->tiles_u : 1;
    T->ntiles = atlas ? m->tiles_u * m->tiles_v : 1;
    T->tw = m->width / T->tiles_u;
    T->th = m->height / (atlas ? m->tiles_v : 1);
    need = T->tw > T->th ? T->tw : T->th;
    if (need > SFB__TESS_MAX_RATE) need = SFB__TESS_MAX_RATE;
    T->fstate = (unsigned char *)sfb__tess_array(T->ctx, (size_t)nptex, 1);
    if (!T->fstate) return sfb__oom(T->ctx, "tessellation");
    if (!atlas) one = sfb__trim_scan(T, m->texels);
    for (pf = 0; pf < nptex; ++pf) {
        int st = SFB__TRIM_KEEP;
        if (atlas && pf % SFB__TESS_FACE_CHUNK == 0 && (r = sfb__progress(T->ctx, p, "tessellate")) != SFB_SUCCESS) return r;
        if (T->prate[pf] > 0) st = atlas ? (pf < T->ntiles ? sfb__trim_scan(T, sfb__trim_tile(T, pf)) : SFB__TRIM_KEEP) : one;
        T->fstate[pf] = (unsigned char)st;
        if (st == SFB__TRIM_CUT && T->prate[pf] < need) T->prate[pf] = need;
    }
    return SFB_SUCCESS;
}

/* The emit pass with trimming: locations of the untrimmed points, triangles through the mask
 * (sfb__trim_triangle), then the vertices no triangle uses are removed (the others keep
 * their order) and `out` gets the compacted arrays. */
static sfb_result sfb__trim_emit(sfb__tess *T, sfb_tess_data *out, float p0, float p1) {
    sfb_context *ctx = T->ctx;
    int nptex = T->pt->nptex, pf, *remap = NULL;
    size_t v, total, nv = 0, i;
    sfb_result r;
    T->loc = (sfb_location *)sfb__tess_array(ctx, T->nvert, sizeof(sfb_location));
    T->cuv = (double *)sfb__tess_array(ctx, T->nvert, 2 * sizeof(double));
    T->ckept = (unsigned char *)sfb__tess_array(ctx, T->nvert, 1);
    T->cut_cap = 1024;
    T->cuts = (sfb__trim_cut *)sfb__tess_array(ctx, T->cut_cap, sizeof(sfb__trim_cut));
    if (!T->loc || !T->cuv || !T->ckept || !T->cuts) return sfb__oom(ctx, "tessellation");
    for (v = 0; v < T->nvert; ++v) {
        T->loc[v].face = -1;
        T->loc[v].u = T->loc[v].v = 0.0f;
        T->ckept[v] = 1;
    }
    for (i = 0; i < T->cut_cap; ++i) T->cuts[i].vid = -1;
    T->err = SFB_SUCCESS;
    for (pf = 0; pf < nptex; ++pf) {
        if (pf % SFB__TESS_FACE_CHUNK == 0 && pf > 0) {
            r = sfb__progress(ctx, p0 + (p1 - p0) * (float)pf / (float)nptex, "tessellate");
            if (r != SFB_SUCCESS) return r;
        }
        sfb__tess_face(T, pf, 1);
        if (T->err != SFB_SUCCESS) return T->err;
    }
    if (T->tri_at != T->ntri)
        return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellation wrote %zu triangles, counted %zu", T->tri_at, T->ntri);
    for (v = 0; v < T->nvert; ++v)
        if (T->loc[v].face < 0)
            return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellation vertex %zu has no location", v);
    /* compaction */
    total = T->nvert + T->nnew;
    remap = (int *)sfb__tess_array(ctx, total, sizeof(int));
    if (!remap) return sfb__oom(ctx, "tessellation");
    for (v = 0; v < total; ++v) remap[v] = -1;
    for (i = 0; i < 3 * T->ocount; ++i) remap[T->otri[i]] = 0;
    for (v = 0; v < total; ++v)
        if (remap[v] == 0) remap[v] = (int)nv++;
    out->vertex_count = (int)nv;
    out->triangle_count = (int)T->ocount;
    out->positions = (float *)sfb__tess_array(ctx, nv, 3 * sizeof(float));
    out->normals = (float *)sfb__tess_array(ctx, nv, 3 * sizeof(float));
    out->locations = (sfb_location *)sfb__tess_array(ctx, nv, sizeof(sfb_location));
    if (!out->positions || !out->normals || !out->locations || (!T->otri && !(T->otri = (int *)sfb__tess_array(ctx, 1, 3 * sizeof(int)))) ||
        (!T->oface && !(T->oface = (int *)sfb__tess_array(ctx, 1, sizeof(int))))) {
        sfb__free(ctx, remap);
        return sfb__oom(ctx, "tessellation");
    }
    for (v = 0; v < total; ++v)
        if (remap[v] >= 0) out->locations[remap[v]] = v < T->nvert ? T->loc[v] : T->nloc[v - T->nvert];
    for (i = 0; i < 3 * T->ocount; ++i) T->otri[i] = remap[T->otri[i]];
    sfb__free(ctx, remap);
    out->triangles = T->otri;
    out->triangle_faces = T->oface;
    T->otri = T->oface = NULL;
    return SFB_SUCCESS;
}

/* Refuses a surface without a patch table and a rate, tolerance, flag set or trimming mask
 * out of range, before any allocation. */
static sfb_result sfb__tess_check(sfb_context *ctx, const sfb_surface *s, const sfb_tess_config *cfg) {
    if (!s->has_patches || s->pbase.nf != s->base_face_count || !s->pbase.fe)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_tessellate: the surface has no patch table (create it with SFB_REFINE_PATCHES)");
    if (cfg->rate < 1 || cfg->rate > SFB__TESS_MAX_RATE)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "tessellation rate %d is outside 1..%d", cfg->rate,
                          SFB__TESS_MAX_RATE);
    if (!(cfg->tolerance >= 0.0f))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "tessellation tolerance %g must be >= 0 (0: uniform)",
                          (double)cfg->tolerance);
    if (cfg->flags & ~(unsigned)(SFB_TESS_SPLIT_CREASES | SFB_TESS_UVS))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown tessellation flags 0x%x", cfg->flags);
    if ((cfg->flags & SFB_TESS_UVS) && (!s->has_uvs || !s->base_uvs || !s->uv_base.fv))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_tessellate: SFB_TESS_UVS, but the surface has no UVs (create it with SFB_REFINE_UVS | "
                          "SFB_REFINE_PATCHES from a mesh with UVs)");
    if ((cfg->flags & SFB_TESS_UVS) && (s->uv_base.nf != s->pbase.nf || s->uv_base.nfv != s->pbase.nfv))
        return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "sfb_surface_tessellate: the UV layout's faces are not the surface's");
    if (cfg->trim) {
        const sfb_trim_mask *m = cfg->trim;
        if (!m->texels) return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: texels is NULL");
        if (m->width < 1 || m->width > SFB__TRIM_MAX_SIZE || m->height < 1 || m->height > SFB__TRIM_MAX_SIZE)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: %d x %d texels, each side must be 1..%d",
                              m->width, m->height, SFB__TRIM_MAX_SIZE);
        if (m->tiles_u < 0 || m->tiles_v < 0)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: negative atlas tiles %d x %d", m->tiles_u,
                              m->tiles_v);
        if ((m->tiles_u == 0) != (m->tiles_v == 0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                              "trimming mask: atlas tiles %d x %d (0 x 0 or both >= 1: one zero and not the other)", m->tiles_u, m->tiles_v);
        if (m->tiles_u > 0 && (m->width % m->tiles_u != 0 || m->height % m->tiles_v != 0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                              "trimming mask: %d x %d texels do not split into %d x %d equal tiles", m->width, m->height, m->tiles_u,
                              m->tiles_v);
    }
    return SFB_SUCCESS;
}

/* Zeroes T and sets it up for s and cfg: the work arrays, the uniform rate on every live param
 * face, no vertex ids yet. On failure T holds what was allocated (sfb__tess_free_work). */
static sfb_result sfb__tess_init(sfb__tess *T, const sfb_surface *s, const sfb_tess_config *cfg) {
    sfb_context *ctx = s->ctx;
    const sfb__level *l;
    int pf, f, i, nptex;
    memset(T, 0, sizeof *T);
    T->ctx = ctx;
    T->s = s;
    T->l = l = &s->pbase;
    T->pt = &s->patches;
    T->rate = cfg->rate;
    T->split = (cfg->flags & (SFB_TESS_SPLIT_CREASES | SFB_TESS_UVS)) != 0;
    T->loop = T->pt->domain == SFB__DOMAIN_TRI;
    nptex = T->pt->nptex;
    T->prate = (int *)sfb__tess_array(ctx, (size_t)nptex, sizeof(int));
    T->sseg = (int *)sfb__tess_array(ctx, (size_t)nptex, sizeof(int));
    T->vspoke = (int *)sfb__tess_array(ctx, (size_t)nptex, sizeof(int));
    T->ifirst = (int *)sfb__tess_array(ctx, (size_t)nptex, sizeof(int));
    T->eseg = (int *)sfb__tess_array(ctx, (size_t)l->ne, sizeof(int));
    T->engon = (unsigned char *)sfb__tess_array(ctx, (size_t)l->ne, 1);
    T->vedge = (int *)sfb__tess_array(ctx, (size_t)l->nfv, sizeof(int));
    T->vcenter = (int *)sfb__tess_array(ctx, (size_t)l->nf, sizeof(int));
    T->vcorner = (int *)sfb__tess_array(ctx, (size_t)(T->split ? l->nfv : l->nv), sizeof(int));
    T->bids = (int *)sfb__tess_array(ctx, (size_t)6 * (SFB__TESS_MAX_SEG + 1), sizeof(int));
    if (T->split) {
        T->uf = (int *)sfb__tess_array(ctx, (size_t)l->nfv, sizeof(int));
        T->ecopy = (int *)sfb__tess_array(ctx, (size_t)l->nfv, sizeof(int));
        T->esplit = (unsigned char *)sfb__tess_array(ctx, (size_t)l->ne, 1);
    }
    if (!T->prate || !T->sseg || !T->vspoke || !T->ifirst || !T->eseg || !T->engon || !T->vedge || !T->vcenter || !T->vcorner ||
        !T->bids || (T->split && (!T->uf || !T->ecopy || !T->esplit)))
        return sfb__oom(ctx, "tessellation");
    if (T->split) {
        int e;
        for (e = 0; e < l->ne; ++e)
            T->esplit[e] = (unsigned char)(((cfg->flags & SFB_TESS_SPLIT_CREASES) && sfb__tess_crease_edge(l, e)) ||
                                           ((cfg->flags & SFB_TESS_UVS) && sfb__tess_uv_seam(l, &s->uv_base, e)));
    }
    for (pf = 0; pf < nptex; ++pf) {
        T->prate[pf] = sfb__tess_live(T, pf) ? T->rate : 0;
        T->vspoke[pf] = -1;
        T->sseg[pf] = 0;
    }
    for (i = 0; i < l->nfv; ++i) T->vedge[i] = -1;
    for (f = 0; f < l->nf; ++f) T->vcenter[f] = -1;
    for (i = 0; i < (T->split ? l->nfv : l->nv); ++i) T->vcorner[i] = -1;
    return SFB_SUCCESS;
}

/* Segments of each base edge and spoke: the largest rate of the faces on it (an n-gon sub-face
 * covers half an edge, so it asks for twice its rate, and the count stays even). */
static void sfb__tess_edge_segments(sfb__tess *T) {
    const sfb__level *l = T->l;
    int pf, f, e, k, nptex = T->pt->nptex;
    memset(T->eseg, 0, (size_t)l->ne * sizeof(int));
    memset(T->engon, 0, (size_t)l->ne);
    for (pf = 0; pf < nptex; ++pf) {
        int rr = T->prate[pf], sub = T->pt->ptex_corner[pf], o, n;
        if (rr <= 0) continue;
        f = T->pt->ptex_face[pf];
        o = l->fv_off[f];
        n = sfb__tess_face_n(l, f);
        if (sub < 0) { /* a quad, or a Loop triangle */
            for (k = 0; k < n; ++k) {
                e = l->fe[o + k];
                if (T->eseg[e] < rr) T->eseg[e] = rr;
            }
        } else {
            int ip = (sub + n - 1) % n, nx = T->pt->face_ptex[f] + (sub + 1) % n;
            int e0 = l->fe[o + sub], e1 = l->fe[o + ip], other = T->prate[nx];
            if (T->eseg[e0] < 2 * rr) T->eseg[e0] = 2 * rr;
            if (T->eseg[e1] < 2 * rr) T->eseg[e1] = 2 * rr;
            T->engon[e0] = T->engon[e1] = 1;
            T->sseg[pf] = rr > other ? rr : other;
        }
    }
    for (e = 0; e < l->ne; ++e)
        if (T->engon[e] && (T->eseg[e] & 1)) T->eseg[e] += 1;
}

/* Sectors for split creases: corners of faces joined across every edge that is not split
 * (holes join nothing), in the union-find T->uf. */
static void sfb__tess_sectors(sfb__tess *T) {
    const sfb__level *l = T->l;
    int i, e;
    for (i = 0; i < l->nfv; ++i) T->uf[i] = i;
    for (e = 0; e < l->ne; ++e) {
        int a = l->ef_off[e], z = l->ef_off[e + 1], first0 = -1, first1 = -1, q;
        for (q = a; q < z; ++q) T->ecopy[l->fv_off[l->ef[q]] + l->ef_slot[q]] = q;
        if (sfb__tess_split_edge(T, e)) continue;
        for (q = a; q < z; ++q) {
            int g = l->ef[q], o = l->fv_off[g], n = sfb__tess_face_n(l, g), sl = l->ef_slot[q];
            int c0 = o + sl, c1 = o + (sl + 1) % n, t;
            if (l->fhole[g]) continue;
            if (l->fv[c0] != l->ev[2 * e]) { t = c0; c0 = c1; c1 = t; } /* c0 at ev[0], c1 at ev[1] */
            if (first0 < 0) { first0 = c0; first1 = c1; }
            else { sfb__tess_union(T->uf, first0, c0); sfb__tess_union(T->uf, first1, c1); }
        }
    }
}

/* The count pass: ids of every point, and the totals, checked against SFB_MAX_ELEMENTS before
 * anything is allocated for them. */
static sfb_result sfb__tess_count(sfb__tess *T) {
    int pf, nptex = T->pt->nptex;
    for (pf = 0; pf < nptex; ++pf) {
        sfb__tess_face(T, pf, 0);
        if (T->nvert > (size_t)SFB_MAX_ELEMENTS || T->ntri > (size_t)SFB_MAX_ELEMENTS)
            return sfb__error(T->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                              "tessellation at rate %d makes more than %d %s (SFB_MAX_ELEMENTS)", T->rate, SFB_MAX_ELEMENTS,
                              T->nvert > (size_t)SFB_MAX_ELEMENTS ? "vertices" : "triangles");
    }
    return SFB_SUCCESS;
}

/* The emit pass without trimming: `out`'s arrays, then the locations and triangles of every
 * param face written straight into them (progress from p0 to p1). */
static sfb_result sfb__tess_emit(sfb__tess *T, sfb_tess_data *out, float p0, float p1) {
    sfb_context *ctx = T->ctx;
    int pf, nptex = T->pt->nptex;
    size_t v;
    sfb_result r;
    out->vertex_count = (int)T->nvert;
    out->triangle_count = (int)T->ntri;
    out->positions = (float *)sfb__tess_array(ctx, T->nvert, 3 * sizeof(float));
    out->normals = (float *)sfb__tess_array(ctx, T->nvert, 3 * sizeof(float));
    out->locations = (sfb_location *)sfb__tess_array(ctx, T->nvert, sizeof(sfb_location));
    out->triangles = (int *)sfb__tess_array(ctx, T->ntri, 3 * sizeof(int));
    out->triangle_faces = (int *)sfb__tess_array(ctx, T->ntri, sizeof(int));
    if (!out->positions || !out->normals || !out->locations || !out->triangles || !out->triangle_faces)
        return sfb__oom(ctx, "tessellation");
    for (v = 0; v < T->nvert; ++v) {
        out->locations[v].face = -1;
        out->locations[v].u = out->locations[v].v = 0.0f;
    }
    T->loc = out->locations;
    T->tri = out->triangles;
    T->tface = out->triangle_faces;
    for (pf = 0; pf < nptex; ++pf) {
        if (pf % SFB__TESS_FACE_CHUNK == 0 && pf > 0) {
            r = sfb__progress(ctx, p0 + (p1 - p0) * (float)pf / (float)nptex, "tessellate");
            if (r != SFB_SUCCESS) return r;
        }
        sfb__tess_face(T, pf, 1);
    }
    if (T->tri_at != T->ntri)
        return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellation wrote %zu triangles, counted %zu", T->tri_at, T->ntri);
    for (v = 0; v < T->nvert; ++v)
        if (out->locations[v].face < 0)
            return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellation vertex %zu has no location", v);
    return SFB_SUCCESS;
}

/* Evaluates every vertex of `out` once, in chunks, on the context's backend (progress from p0
 * to p1). */
static sfb_result sfb__tess_evaluate(const sfb_surface *s, sfb_tess_data *out, float p0, float p1) {
    sfb_context *ctx = s->ctx;
    size_t done_v, nv = (size_t)out->vertex_count;
    sfb_result r;
    for (done_v = 0; done_v < nv; done_v += SFB__TESS_EVAL_CHUNK) {
        size_t n = nv - done_v < SFB__TESS_EVAL_CHUNK ? nv - done_v : SFB__TESS_EVAL_CHUNK;
        sfb_eval_output eo;
        r = sfb__progress(ctx, p0 + (p1 - p0) * (float)done_v / (float)nv, "tessellate");
        if (r != SFB_SUCCESS) return r;
        memset(&eo, 0, sizeof eo);
        eo.position = out->positions + 3 * done_v;
        eo.normal = out->normals + 3 * done_v;
        r = sfb_surface_eval(s, out->locations + done_v, (int)n, &eo);
        if (r != SFB_SUCCESS) return r;
    }
    return sfb__progress(ctx, p1, "tessellate");
}

/* SFB_UV_LINEAR: the UVs follow each face linearly, as the bilinear masks refine them on the
 * scheme's own face split -- a quad bilinearly, an n-gon's sub-face i bilinearly between its
 * corner's UV, the two edge midpoints and the centroid, a Loop triangle barycentrically. */
static void sfb__tess_uv_linear(const sfb_surface *s, const sfb_location *L, float uv[2]) {
    const sfb__level *ul = &s->uv_base;
    const sfb__patch_table *pt = &s->patches;
    int f = pt->ptex_face[L->face], sub = pt->ptex_corner[L->face], o = ul->fv_off[f], n = ul->fv_off[f + 1] - o, c, k;
    double u = L->u, v = L->v;
    for (c = 0; c < 2; ++c) {
        double q[4];
        if (pt->domain == SFB__DOMAIN_TRI) {
            uv[c] = (float)((1.0 - u - v) * s->base_uvs[2 * ul->fv[o] + c] + u * s->base_uvs[2 * ul->fv[o + 1] + c] +
                            v * s->base_uvs[2 * ul->fv[o + 2] + c]);
            continue;
        }
        if (sub < 0) {
            for (k = 0; k < 4; ++k) q[k] = s->base_uvs[2 * ul->fv[o + k] + c];
        } else {
            double mean = 0.0, a = s->base_uvs[2 * ul->fv[o + sub] + c];
            for (k = 0; k < n; ++k) mean += s->base_uvs[2 * ul->fv[o + k] + c];
            q[0] = a;
            q[1] = 0.5 * (a + s->base_uvs[2 * ul->fv[o + (sub + 1) % n] + c]);
            q[2] = mean / n;
            q[3] = 0.5 * (a + s->base_uvs[2 * ul->fv[o + (sub + n - 1) % n] + c]);
        }
        uv[c] = (float)((1.0 - u) * (1.0 - v) * q[0] + u * (1.0 - v) * q[1] + u * v * q[2] + (1.0 - u) * v * q[3]);
    }
}

/* SFB_TESS_UVS: out->uvs at out->locations (progress from p0 to 1). Smooth UVs are the limit
 * of the refined UV layout: the layout's own patch table (sfb__surface_uv_patches, built per
 * call, so a surface that never tessellates UVs does not pay for it), uploaded to and
 * evaluated on the context's backend as the positions are. The manifold blend blends the UV layout as it blends
 * positions (the blend is linear in the data); tribezier builds its own surface of the layout
 * (a similarity of a planar mesh's layout gives that map of the positions), linear per face
 * where its builder refuses the layout; PN triangles take the linear UVs, which is what they
 * make of a planar layout. */
static sfb_result sfb__tess_eval_uvs(const sfb_surface *s, sfb_tess_data *out, float p0) {
    sfb_context *ctx = s->ctx;
    size_t v, nv = (size_t)out->vertex_count, done_v;
    sfb__patch_table upt;
    const sfb__backend_vtable *be = ctx->backend;
    void *handle = NULL;
    int uploaded = 0, linear = 0;
    float *tmp = NULL;
    sfb_result r = SFB_SUCCESS;
    out->uvs = (float *)sfb__tess_array(ctx, nv, 2 * sizeof(float));
    if (!out->uvs) return sfb__oom(ctx, "tessellated UVs");
    memset(&upt, 0, sizeof upt);
    if (sfb__surface_smooth_uvs(s)) {
        /* UVS_OR_LINEAR: linear UVs where the scheme's builder cannot take the layout -- one
         * that is not a manifold (placeholder UVs) is not offered to it, so that no error is
         * logged for it; other refusals (a flat UV triangle) come back from the builder */
        const sfb__scheme_info *si = sfb__scheme_info_of(s->config.scheme);
        const int fallback = si && (si->caps & SFB__SCHEME_UVS_OR_LINEAR);
        int i;
        for (i = 0; fallback && i < s->uv_base.nv && !linear; ++i) linear = (s->uv_base.vtag[i] & SFB__TAG_NONMANIFOLD) != 0;
        if (linear) {
            sfb__log(ctx, SFB_LOG_INFO, "tessellated UVs: the UV layout is not a manifold: linear per face (%s)", si->name);
        } else if ((r = sfb__surface_uv_patches(s, &upt)) != SFB_SUCCESS) {
            if (r == SFB_OUT_OF_MEMORY || r == SFB_CANCELLED || !fallback) goto done;
            sfb__log(ctx, SFB_LOG_INFO, "tessellated UVs: the %s surface of the UV layout cannot be built (%s): linear per face",
                     si->name, sfb_last_error(ctx));
            linear = 1;
        }
    } else {
        linear = 1;
    }
    if (linear) {
        for (v = 0; v < nv; ++v) sfb__tess_uv_linear(s, &out->locations[v], out->uvs + 2 * v);
        r = sfb__progress(ctx, 1.0f, "tessellate");
        goto done;
    }
    tmp = (float *)sfb__tess_array(ctx, SFB__TESS_EVAL_CHUNK, 3 * sizeof(float));
    if (!tmp) { r = sfb__oom(ctx, "tessellated UVs"); goto done; }
    /* on the context's backend, like the positions (ref when it has no patch kernels) */
    if (be && be->upload_patches && be->eval_patches) {
        if ((r = be->upload_patches(ctx->backend_state, &upt, &handle)) != SFB_SUCCESS) goto done;
        uploaded = 1;
    }
    for (done_v = 0; done_v < nv; done_v += SFB__TESS_EVAL_CHUNK) {
        size_t n = nv - done_v < SFB__TESS_EVAL_CHUNK ? nv - done_v : SFB__TESS_EVAL_CHUNK;
        sfb_eval_output eo;
        if ((r = sfb__progress(ctx, p0 + (1.0f - p0) * (float)done_v / (float)nv, "tessellate")) != SFB_SUCCESS) goto done;
        memset(&eo, 0, sizeof eo);
        eo.position = tmp;
        r = be && be->eval_patches ? be->eval_patches(ctx->backend_state, &upt, handle, out->locations + done_v, 0, (int)n, &eo)
                                   : sfb__ref_eval_patches(NULL, &upt, NULL, out->locations + done_v, 0, (int)n, &eo);
        if (r != SFB_SUCCESS) goto done;
        for (v = 0; v < n; ++v) {
            out->uvs[2 * (done_v + v)] = tmp[3 * v];
            out->uvs[2 * (done_v + v) + 1] = tmp[3 * v + 1];
        }
    }
    r = sfb__progress(ctx, 1.0f, "tessellate");
done:
    if (uploaded && be->release_patches) be->release_patches(ctx->backend_state, handle);
    sfb__patch_table_free(ctx, &upt);
    sfb__free(ctx, tmp);
    return r;
}

SFB_API sfb_result sfb_surface_tessellate(const sfb_surface *s, const sfb_tess_config *cfg, sfb_tess_data *out) {
    sfb_context *ctx;
    sfb__tess T;
    sfb_result r = SFB_SUCCESS;
    float p_emit, p_eval;
    if (out) memset(out, 0, sizeof *out);
    if (!s) return SFB_INVALID_ARGS;
    ctx = s->ctx;
    if (!cfg || !out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_tessellate: NULL argument");
    if ((r = sfb__tess_check(ctx, s, cfg)) != SFB_SUCCESS) return r;
    if ((r = sfb__progress(ctx, 0.0f, "tessellate")) != SFB_SUCCESS) return r;
    if ((r = sfb__tess_init(&T, s, cfg)) != SFB_SUCCESS) goto fail;

    /* 1. a rate per param face */
    p_emit = 0.0f;
    if (cfg->tolerance > 0.0f) {
        r = sfb__tess_adaptive(&T, cfg->tolerance, 0.0f, 0.5f);
        if (r != SFB_SUCCESS) goto fail;
        p_emit = 0.5f;
    }
    p_eval = p_emit + 0.1f;
    if (cfg->trim) {
        T.trim = cfg->trim;
        r = sfb__trim_rates(&T, p_emit);
        if (r != SFB_SUCCESS) goto fail;
    }
    /* 2. segments of each base edge and spoke; 3. sectors for split creases */
    sfb__tess_edge_segments(&T);
    if (T.split) sfb__tess_sectors(&T);
    /* 4. count pass */
    if ((r = sfb__tess_count(&T)) != SFB_SUCCESS) goto fail;
    /* 5. emit pass: locations and triangles */
    out->ctx_ = ctx;
    r = T.trim ? sfb__trim_emit(&T, out, p_emit, p_eval) : sfb__tess_emit(&T, out, p_emit, p_eval);
    if (r != SFB_SUCCESS) goto fail;
    sfb__tess_free_work(&T);
    /* 6. evaluate every vertex once, in chunks, on the context's backend; 7. the UVs */
    r = sfb__tess_evaluate(s, out, p_eval, (cfg->flags & SFB_TESS_UVS) ? 0.9f : 1.0f);
    if (r == SFB_SUCCESS && (cfg->flags & SFB_TESS_UVS)) r = sfb__tess_eval_uvs(s, out, 0.9f);
    if (r == SFB_SUCCESS) return SFB_SUCCESS;
fail:
    sfb__tess_free_work(&T);
    out->ctx_ = ctx;
    sfb_tess_data_free(out);
    return r;
}
#line 1 "src/mesh.c"
/* Control meshes: validation of untrusted arrays, edges, topology, creases, info. */


static sfb_result sfb__elem_error(sfb_context *ctx, sfb_result r, const sfb__src_lines *lines, const int *line_of,
                                  sfb_element_kind kind, long index, const char *what, long what_index, const char *detail) {
    if (lines && line_of)
        return sfb__error(ctx, r, SFB_ELEMENT_LINE, line_of[what_index], "%s %ld: %s", what, what_index, detail);
    if (kind == SFB_ELEMENT_NONE) return sfb__error(ctx, r, kind, -1, "%s %ld: %s", what, what_index, detail);
    return sfb__error(ctx, r, kind, index, "%s", detail);
}

/* Builds the edge list of a face list by hashing vertex pairs. */
static sfb_result sfb__build_edges(sfb_context *ctx, int nv, int nf, const int *fv_off, const int *fv, int *ne_out,
                                   int **fe_out, int **ev_out) {
    int nfv = fv_off[nf], f, i, ne = 0;
    size_t cap = 16, mask;
    uint64_t *keys = NULL;
    int *vals = NULL, *fe = NULL, *ev = NULL;
    (void)nv;
    while (cap < (size_t)nfv * 2 + 16) cap <<= 1;
    mask = cap - 1;
    keys = (uint64_t *)sfb__alloc(ctx, cap * sizeof(uint64_t));
    vals = (int *)sfb__alloc(ctx, cap * sizeof(int));
    fe = (int *)sfb__alloc(ctx, ((size_t)nfv + 1) * sizeof(int));
    ev = (int *)sfb__alloc(ctx, ((size_t)nfv * 2 + 2) * sizeof(int));
    if (!keys || !vals || !fe || !ev) goto oom;
    memset(keys, 0xff, cap * sizeof(uint64_t));
    for (f = 0; f < nf; ++f) {
        int o = fv_off[f], n = fv_off[f + 1] - o;
        for (i = 0; i < n; ++i) {
            unsigned a = (unsigned)fv[o + i], b = (unsigned)fv[o + (i + 1) % n];
            uint64_t key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 17) & mask;
            while (keys[h] != ~(uint64_t)0 && keys[h] != key) h = (h + 1) & mask;
            if (a == b) {
                /* a degenerate edge (a face repeating a vertex) is never shared: each occurrence is
                 * an edge of its own, as in OpenSubdiv */
                ev[2 * ne] = (int)a;
                ev[2 * ne + 1] = (int)b;
                fe[o + i] = ne++;
            } else if (keys[h] == key) {
                int k, again = 0;
                /* the same edge twice in one face (a face folding back on itself) gives two edges */
                for (k = 0; k < i && !again; ++k) again = fe[o + k] == vals[h];
                if (again) {
                    ev[2 * ne] = (int)a;
                    ev[2 * ne + 1] = (int)b;
                    fe[o + i] = ne++;
                } else {
                    fe[o + i] = vals[h];
                }
            } else {
                keys[h] = key;
                vals[h] = ne;
                ev[2 * ne] = (int)a;
                ev[2 * ne + 1] = (int)b;
                fe[o + i] = ne++;
            }
        }
    }
    sfb__free(ctx, keys);
    sfb__free(ctx, vals);
    *ne_out = ne;
    *fe_out = fe;
    *ev_out = ev;
    return SFB_SUCCESS;
oom:
    sfb__free(ctx, keys); sfb__free(ctx, vals); sfb__free(ctx, fe); sfb__free(ctx, ev);
    return SFB_OUT_OF_MEMORY;
}

/* Finds the edge between a and b through a's incident edges; -1 if none. */
static int sfb__find_edge(const sfb__level *l, int a, int b) {
    int i;
    for (i = l->ve_off[a]; i < l->ve_off[a + 1]; ++i) {
        int e = l->ve[i];
        if ((l->ev[2 * e] == a && l->ev[2 * e + 1] == b) || (l->ev[2 * e] == b && l->ev[2 * e + 1] == a)) return e;
    }
    return -1;
}

static int sfb__finite3(const float *p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }

/* Builds a level (topology only, zero sharpness) from faces; validates indices. */
sfb_result sfb__level_from_faces(sfb_context *ctx, int nv, int nf, const int *sizes, const int *fvin,
                                        const sfb__src_lines *lines, sfb_element_kind vkind, sfb__level *l) {
    int f, i;
    size_t nfv = 0;
    sfb_result r;
    memset(l, 0, sizeof *l);
    for (f = 0; f < nf; ++f) {
        char msg[160];
        if (sizes[f] < 3) {
            snprintf(msg, sizeof msg, "face has %d %s; a face needs at least 3", sizes[f], sizes[f] == 1 ? "vertex" : "vertices");
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
        }
        if (sizes[f] > SFB_MAX_FACE_SIZE) {
            snprintf(msg, sizeof msg, "face has %d vertices, over the limit of %d (SFB_MAX_FACE_SIZE)", sizes[f], SFB_MAX_FACE_SIZE);
            return sfb__elem_error(ctx, SFB_LIMIT_EXCEEDED, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
        }
        nfv += (size_t)sizes[f];
        if (nfv > SFB_MAX_ELEMENTS)
            return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_FACE, f, "total face-vertex count over the limit of %d", SFB_MAX_ELEMENTS);
    }
    l->nv = nv;
    l->nf = nf;
    l->fv_off = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    l->fv = (int *)sfb__alloc(ctx, (nfv + 1) * sizeof(int));
    if (!l->fv_off || !l->fv) goto oom;
    l->fv_off[0] = 0;
    for (f = 0; f < nf; ++f) {
        int o = l->fv_off[f], n = sizes[f];
        l->fv_off[f + 1] = o + n;
        for (i = 0; i < n; ++i) {
            int v = fvin[o + i];
            char msg[200];
            if (v < 0 || v >= nv) {
                snprintf(msg, sizeof msg, "%s index %d out of range (%d %s)", vkind == SFB_ELEMENT_UV ? "uv" : "vertex", v, nv,
                         vkind == SFB_ELEMENT_UV ? "uvs" : "vertices");
                sfb__level_free(ctx, l);
                return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
            }
            l->fv[o + i] = v;
        }
    }
    r = sfb__build_edges(ctx, nv, nf, l->fv_off, l->fv, &l->ne, &l->fe, &l->ev);
    if (r != SFB_SUCCESS) goto oom;
    l->es = (float *)sfb__calloc(ctx, (size_t)l->ne + 1, sizeof(float));
    l->vs = (float *)sfb__calloc(ctx, (size_t)nv + 1, sizeof(float));
    if (!l->es || !l->vs) goto oom;
    r = sfb__level_complete(ctx, l);
    if (r != SFB_SUCCESS) { sfb__level_free(ctx, l); return r; }
    return SFB_SUCCESS;
oom:
    sfb__level_free(ctx, l);
    return sfb__oom(ctx, "building the mesh topology");
}

static sfb_result sfb__check_sharpness(sfb_context *ctx, float s, const sfb__src_lines *lines, const int *line_of,
                                       const char *what, int index) {
    char msg[160];
    if (isnan(s) || s < 0.0f) {
        snprintf(msg, sizeof msg, "sharpness %g is invalid: sharpness must be a number >= 0", (double)s);
        return sfb__elem_error(ctx, SFB_INVALID_VALUE, lines, line_of, SFB_ELEMENT_NONE, -1, what, index, msg);
    }
    return SFB_SUCCESS;
}

void sfb_mesh_destroy(sfb_mesh *mesh);

/* Refuses a mesh description with bad counts, missing arrays, unknown options or non-finite
 * positions, before any allocation. */
static sfb_result sfb__mesh_check_desc(sfb_context *ctx, const sfb_mesh_desc *d) {
    int v;
    if (d->vertex_count < 0 || d->face_count < 0 || d->crease_count < 0 || d->corner_count < 0 || d->hole_count < 0 ||
        d->uv_count < 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "negative element count in the mesh description");
    if (d->vertex_count > SFB_MAX_ELEMENTS || d->face_count > SFB_MAX_ELEMENTS || d->uv_count > SFB_MAX_ELEMENTS ||
        d->crease_count > SFB_MAX_ELEMENTS || d->corner_count > SFB_MAX_ELEMENTS || d->hole_count > SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "element count over the limit of %d", SFB_MAX_ELEMENTS);
    if (d->face_count == 0) return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_NONE, -1, "mesh has no faces");
    if (!d->positions || !d->face_sizes || !d->face_vertices)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mesh description lacks positions or faces");
    if ((d->crease_count && (!d->crease_vertices || !d->crease_sharpness)) ||
        (d->corner_count && (!d->corner_vertices || !d->corner_sharpness)) || (d->hole_count && !d->holes) ||
        (d->uv_count && (!d->uvs || !d->face_uvs)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mesh description has a count without its array");
    if (d->boundary < 0 || d->boundary > 2 || d->crease_method < 0 || d->crease_method > 1 || d->triangle_rule < 0 ||
        d->triangle_rule > 1 || d->uv_interp < 0 || d->uv_interp > 1)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "invalid boundary/crease method/triangle rule/uv mode value");
    for (v = 0; v < d->vertex_count; ++v)
        if (!sfb__finite3(d->positions + 3 * (size_t)v))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, v, "coordinate is not finite (NaN or inf)");
    return SFB_SUCCESS;
}

/* Refuses a vertex of the base level with more edges or faces than SFB_MAX_VALENCE. */
static sfb_result sfb__mesh_check_valence(sfb_context *ctx, const sfb__level *l) {
    int v;
    for (v = 0; v < l->nv; ++v) {
        int val = l->ve_off[v + 1] - l->ve_off[v];
        int fal = l->vf_off[v + 1] - l->vf_off[v];
        if (val > SFB_MAX_VALENCE || fal > SFB_MAX_VALENCE)
            return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_VERTEX, v, "valence %d is over the limit of %d (SFB_MAX_VALENCE)",
                              val > fal ? val : fal, SFB_MAX_VALENCE);
    }
    return SFB_SUCCESS;
}

/* Edge sharpness from the crease list and the per-face edge sharpness of the description. */
static sfb_result sfb__mesh_apply_creases(sfb_context *ctx, sfb_mesh *m, const sfb_mesh_desc *d, const sfb__src_lines *lines) {
    sfb_result r;
    int i, e;
    char msg[256];
    /* creases: later entries override earlier ones on the same edge (as OpenSubdiv) */
    for (i = 0; i < d->crease_count; ++i) {
        int a = d->crease_vertices[2 * i], b = d->crease_vertices[2 * i + 1];
        float s = d->crease_sharpness[i];
        const int *lo = lines ? lines->crease : NULL;
        if (a < 0 || a >= d->vertex_count || b < 0 || b >= d->vertex_count) {
            snprintf(msg, sizeof msg, "crease names vertex index %d out of range (%d vertices)",
                     (a < 0 || a >= d->vertex_count) ? a : b, d->vertex_count);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lo, SFB_ELEMENT_EDGE, i, "crease", i, msg);
        }
        r = sfb__check_sharpness(ctx, s, lines, lo, "crease", i);
        if (r != SFB_SUCCESS) return r;
        e = sfb__find_edge(&m->base, a, b);
        if (e < 0) {
            snprintf(msg, sizeof msg, "crease between vertices %d and %d is not an edge of the mesh", a, b);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lo, SFB_ELEMENT_EDGE, i, "crease", i, msg);
        }
        m->base.es[e] = s;
    }
    if (d->face_edge_sharpness) {
        int f;
        for (f = 0; f < d->face_count; ++f) {
            int o = m->base.fv_off[f], n = m->base.fv_off[f + 1] - o;
            for (i = 0; i < n; ++i) {
                float s = d->face_edge_sharpness[o + i];
                if (isnan(s) || s < 0.0f) {
                    snprintf(msg, sizeof msg, "per-face edge sharpness %g is invalid: sharpness must be a number >= 0", (double)s);
                    return sfb__elem_error(ctx, SFB_INVALID_VALUE, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
                }
                /* seed 001: where two faces give an edge different values, the highest wins */
                if (s > m->base.es[m->base.fe[o + i]]) m->base.es[m->base.fe[o + i]] = s;
            }
        }
    }
    return SFB_SUCCESS;
}

/* Vertex sharpness from the corner list and face holes from the hole list of the description. */
static sfb_result sfb__mesh_apply_corners_holes(sfb_context *ctx, sfb_mesh *m, const sfb_mesh_desc *d, const sfb__src_lines *lines) {
    sfb_result r;
    int i;
    char msg[256];
    for (i = 0; i < d->corner_count; ++i) {
        int a = d->corner_vertices[i];
        const int *lo = lines ? lines->corner : NULL;
        if (a < 0 || a >= d->vertex_count) {
            snprintf(msg, sizeof msg, "corner names vertex index %d out of range (%d vertices)", a, d->vertex_count);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lo, SFB_ELEMENT_VERTEX, a, "corner", i, msg);
        }
        r = sfb__check_sharpness(ctx, d->corner_sharpness[i], lines, lo, "corner", i);
        if (r != SFB_SUCCESS) return r;
        m->base.vs[a] = d->corner_sharpness[i];
    }
    for (i = 0; i < d->hole_count; ++i) {
        int f = d->holes[i];
        if (f < 0 || f >= d->face_count) {
            snprintf(msg, sizeof msg, "hole names face index %d out of range (%d faces)", f, d->face_count);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lines ? lines->hole : NULL, SFB_ELEMENT_FACE, f, "hole", i, msg);
        }
        m->base.fhole[f] = 1;
    }
    return SFB_SUCCESS;
}

/* Refuses non-finite UVs and face UV indices out of range (the UVs are copied by the caller). */
static sfb_result sfb__mesh_check_uvs(sfb_context *ctx, const sfb_mesh *m, const sfb_mesh_desc *d, const sfb__src_lines *lines) {
    size_t nfv = (size_t)m->base.nfv;
    int i;
    char msg[256];
    for (i = 0; i < d->uv_count; ++i)
        if (!isfinite(d->uvs[2 * i]) || !isfinite(d->uvs[2 * i + 1]))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_UV, i, "uv coordinate is not finite (NaN or inf)");
    for (i = 0; (size_t)i < nfv; ++i)
        if (d->face_uvs[i] < 0 || d->face_uvs[i] >= d->uv_count) {
            int f = 0;
            while (m->base.fv_off[f + 1] <= i) ++f;
            snprintf(msg, sizeof msg, "uv index %d out of range (%d uvs)", d->face_uvs[i], d->uv_count);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
        }
    return SFB_SUCCESS;
}

/* The description view (sfb_mesh_get_desc): per-edge creases, corners and holes as lists.
 * Returns 0 when an allocation failed. */
static int sfb__mesh_desc_view(sfb_context *ctx, sfb_mesh *m) {
    int nc = 0, nk = 0, nh = 0, f, e, v;
    for (e = 0; e < m->base.ne; ++e) nc += m->base.es[e] > 0.0f;
    for (v = 0; v < m->base.nv; ++v) nk += m->base.vs[v] > 0.0f;
    for (f = 0; f < m->base.nf; ++f) nh += m->base.fhole[f] != 0;
    m->crease_vertices = (int *)sfb__alloc(ctx, (size_t)nc * 2 * sizeof(int) + 1);
    m->crease_sharpness = (float *)sfb__alloc(ctx, (size_t)nc * sizeof(float) + 1);
    m->corner_vertices = (int *)sfb__alloc(ctx, (size_t)nk * sizeof(int) + 1);
    m->corner_sharpness = (float *)sfb__alloc(ctx, (size_t)nk * sizeof(float) + 1);
    m->holes = (int *)sfb__alloc(ctx, (size_t)nh * sizeof(int) + 1);
    if (!m->crease_vertices || !m->crease_sharpness || !m->corner_vertices || !m->corner_sharpness || !m->holes) return 0;
    for (e = 0; e < m->base.ne; ++e)
        if (m->base.es[e] > 0.0f) {
            m->crease_vertices[2 * m->crease_count] = m->base.ev[2 * e];
            m->crease_vertices[2 * m->crease_count + 1] = m->base.ev[2 * e + 1];
            m->crease_sharpness[m->crease_count++] = m->base.es[e];
        }
    for (v = 0; v < m->base.nv; ++v)
        if (m->base.vs[v] > 0.0f) {
            m->corner_vertices[m->corner_count] = v;
            m->corner_sharpness[m->corner_count++] = m->base.vs[v];
        }
    for (f = 0; f < m->base.nf; ++f)
        if (m->base.fhole[f]) m->holes[m->hole_count++] = f;
    return 1;
}

sfb_result sfb__mesh_create(sfb_context *ctx, const sfb_mesh_desc *d, const sfb__src_lines *lines, sfb_mesh **out) {
    sfb_mesh *m;
    sfb_result r;
    const char *oom = NULL;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!d || !out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_mesh_create: NULL argument");
    *out = NULL;
    if ((r = sfb__mesh_check_desc(ctx, d)) != SFB_SUCCESS) return r;
    m = (sfb_mesh *)sfb__calloc(ctx, 1, sizeof(sfb_mesh));
    if (!m) return sfb__oom(ctx, "mesh");
    m->ctx = ctx;
    m->boundary = d->boundary; m->crease_method = d->crease_method;
    m->triangle_rule = d->triangle_rule; m->uv_interp = d->uv_interp;
    r = sfb__level_from_faces(ctx, d->vertex_count, d->face_count, d->face_sizes, d->face_vertices, lines, SFB_ELEMENT_VERTEX, &m->base);
    if (r != SFB_SUCCESS) goto fail;
    if ((r = sfb__mesh_check_valence(ctx, &m->base)) != SFB_SUCCESS) goto fail;
    m->positions = (float *)sfb__alloc(ctx, (size_t)d->vertex_count * 3 * sizeof(float) + 1);
    m->face_sizes = (int *)sfb__alloc(ctx, (size_t)d->face_count * sizeof(int));
    if (!m->positions || !m->face_sizes) { oom = "mesh"; goto fail; }
    memcpy(m->positions, d->positions, (size_t)d->vertex_count * 3 * sizeof(float));
    memcpy(m->face_sizes, d->face_sizes, (size_t)d->face_count * sizeof(int));
    if ((r = sfb__mesh_apply_creases(ctx, m, d, lines)) != SFB_SUCCESS) goto fail;
    if ((r = sfb__mesh_apply_corners_holes(ctx, m, d, lines)) != SFB_SUCCESS) goto fail;
    if (d->uv_count > 0) {
        size_t nfv = (size_t)m->base.nfv;
        if ((r = sfb__mesh_check_uvs(ctx, m, d, lines)) != SFB_SUCCESS) goto fail;
        m->uv_count = d->uv_count;
        m->uvs = (float *)sfb__alloc(ctx, (size_t)d->uv_count * 2 * sizeof(float));
        m->face_uvs = (int *)sfb__alloc(ctx, nfv * sizeof(int));
        if (!m->uvs || !m->face_uvs) { oom = "mesh uvs"; goto fail; }
        memcpy(m->uvs, d->uvs, (size_t)d->uv_count * 2 * sizeof(float));
        memcpy(m->face_uvs, d->face_uvs, nfv * sizeof(int));
    }
    if (!sfb__mesh_desc_view(ctx, m)) { oom = "mesh"; goto fail; }
    sfb__level_compute_rules(&m->base);
    *out = m;
    return SFB_SUCCESS;
fail:
    /* an allocation failure is reported after the mesh is gone (the message gives the bytes
     * still in use) */
    sfb_mesh_destroy(m);
    return oom ? sfb__oom(ctx, oom) : r;
}

SFB_API sfb_result sfb_mesh_create(sfb_context *ctx, const sfb_mesh_desc *desc, sfb_mesh **out) {
    return sfb__mesh_create(ctx, desc, NULL, out);
}

SFB_API void sfb_mesh_destroy(sfb_mesh *m) {
    sfb_context *ctx;
    if (!m) return;
    ctx = m->ctx;
    sfb__level_free(ctx, &m->base);
    sfb__free(ctx, m->positions); sfb__free(ctx, m->uvs); sfb__free(ctx, m->face_uvs); sfb__free(ctx, m->face_sizes);
    sfb__free(ctx, m->crease_vertices); sfb__free(ctx, m->crease_sharpness);
    sfb__free(ctx, m->corner_vertices); sfb__free(ctx, m->corner_sharpness); sfb__free(ctx, m->holes);
    sfb__free(ctx, m);
}

SFB_API void sfb_mesh_get_desc(const sfb_mesh *m, sfb_mesh_desc *d) {
    if (!d) return;
    memset(d, 0, sizeof *d);
    if (!m) return;
    d->vertex_count = m->base.nv; d->positions = m->positions;
    d->face_count = m->base.nf; d->face_sizes = m->face_sizes; d->face_vertices = m->base.fv;
    d->crease_count = m->crease_count; d->crease_vertices = m->crease_vertices; d->crease_sharpness = m->crease_sharpness;
    d->corner_count = m->corner_count; d->corner_vertices = m->corner_vertices; d->corner_sharpness = m->corner_sharpness;
    d->hole_count = m->hole_count; d->holes = m->holes;
    d->uv_count = m->uv_count; d->uvs = m->uvs; d->face_uvs = m->face_uvs;
    d->boundary = m->boundary; d->crease_method = m->crease_method;
    d->triangle_rule = m->triangle_rule; d->uv_interp = m->uv_interp;
}

/* Face f's Newell normal (unnormalised; twice the vector area of a planar polygon). */
static void sfb__face_newell(const sfb_mesh *m, int f, double n[3]) {
    const int a = m->base.fv_off[f], k = m->base.fv_off[f + 1] - a;
    int i;
    n[0] = n[1] = n[2] = 0.0;
    for (i = 0; i < k; ++i) {
        const float *p = m->positions + 3 * (size_t)m->base.fv[a + i], *q = m->positions + 3 * (size_t)m->base.fv[a + (i + 1) % k];
        n[0] += ((double)p[1] - q[1]) * ((double)p[2] + q[2]);
        n[1] += ((double)p[2] - q[2]) * ((double)p[0] + q[0]);
        n[2] += ((double)p[0] - q[0]) * ((double)p[1] + q[1]);
    }
}

SFB_API sfb_result sfb_mesh_crease_by_angle(sfb_context *ctx, const sfb_mesh *m, float degrees, sfb_mesh **out, int *added) {
    const sfb__level *l;
    sfb_mesh_desc d;
    double *fn = NULL, cos_limit;
    int *cv = NULL, e, nc = 0, nadd = 0;
    float *cs = NULL;
    sfb_result r;
    if (added) *added = 0;
    if (!ctx || !m || !out) return SFB_INVALID_ARGS;
    *out = NULL;
    if (!(degrees >= 0.0f && degrees <= 180.0f))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "crease angle %g is not a number of degrees in 0..180", (double)degrees);
    l = &m->base;
    fn = (double *)sfb__alloc(ctx, ((size_t)l->nf + 1) * 3 * sizeof(double));
    cv = (int *)sfb__alloc(ctx, ((size_t)l->ne + 1) * 2 * sizeof(int));
    cs = (float *)sfb__alloc(ctx, ((size_t)l->ne + 1) * sizeof(float));
    if (!fn || !cv || !cs) {
        sfb__free(ctx, fn); sfb__free(ctx, cv); sfb__free(ctx, cs);
        return sfb__oom(ctx, "the crease-angle edge lists");
    }
    for (e = 0; e < l->nf; ++e) sfb__face_newell(m, e, fn + 3 * (size_t)e);
    cos_limit = cos((double)degrees * 3.14159265358979323846 / 180.0);
    for (e = 0; e < l->ne; ++e) {
        float sharp = l->es[e];
        if (l->ef_off[e + 1] - l->ef_off[e] == 2 && sharp < SFB_SHARPNESS_INFINITE) {
            const int f0 = l->ef[l->ef_off[e]], f1 = l->ef[l->ef_off[e] + 1];
            const double *a = fn + 3 * (size_t)f0, *b = fn + 3 * (size_t)f1;
            const double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
            const int holes = (l->fhole && (l->fhole[f0] || l->fhole[f1]));
            /* the angle is over the limit when cos(angle) < cos(limit) (180: never) */
            if (!holes && la > 0.0 && lb > 0.0 && isfinite(la) && isfinite(lb) && degrees < 180.0f &&
                (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb) < cos_limit) {
                sharp = SFB_SHARPNESS_INFINITE;
                ++nadd;
            }
        }
        if (sharp > 0.0f) {
            cv[2 * nc] = l->ev[2 * e];
            cv[2 * nc + 1] = l->ev[2 * e + 1];
            cs[nc++] = sharp;
        }
    }
    sfb_mesh_get_desc(m, &d);
    d.crease_count = nc;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    r = sfb_mesh_create(ctx, &d, out);
    if (r == SFB_SUCCESS && added) *added = nadd;
    sfb__free(ctx, fn);
    sfb__free(ctx, cv);
    sfb__free(ctx, cs);
    return r;
}

SFB_API void sfb_mesh_get_info(const sfb_mesh *m, sfb_mesh_info *o) {
    const sfb__level *l;
    sfb__level prep;
    int v, e, f, c;
    if (!o) return;
    memset(o, 0, sizeof *o);
    if (!m) return;
    l = &m->base;
    o->vertex_count = l->nv; o->face_count = l->nf; o->edge_count = l->ne; o->face_vertex_count = l->nfv;
    o->uv_count = m->uv_count;
    for (f = 0; f < l->nf; ++f) {
        int n = l->fv_off[f + 1] - l->fv_off[f];
        if (n == 3) o->triangles++; else if (n == 4) o->quads++; else o->ngons++;
        if (n > o->max_face_size) o->max_face_size = n;
        o->holes += l->fhole[f] != 0;
    }
    for (e = 0; e < l->ne; ++e) {
        if (l->etag[e] & SFB__TAG_BOUNDARY) o->boundary_edges++;
        if (l->etag[e] & SFB__TAG_NONMANIFOLD) o->nonmanifold_edges++;
        if (l->es[e] > 0.0f) {
            o->sharp_edges++;
            if (l->es[e] >= SFB_SHARPNESS_INFINITE) o->infsharp_edges++; else o->semisharp_edges++;
        }
    }
    for (c = 0; c < 3; ++c) { o->bbox_min[c] = l->nv ? 3.4e38f : 0.0f; o->bbox_max[c] = l->nv ? -3.4e38f : 0.0f; }
    for (v = 0; v < l->nv; ++v) {
        int k = l->vf_off[v + 1] - l->vf_off[v], d = l->ve_off[v + 1] - l->ve_off[v];
        if (l->vtag[v] & SFB__TAG_BOUNDARY) o->boundary_vertices++;
        if (l->vtag[v] & SFB__TAG_NONMANIFOLD) { if (k == 0) o->bare_vertices++; else o->nonmanifold_vertices++; }
        if (l->vs[v] > 0.0f) o->corners++;
        if (d > o->max_valence) o->max_valence = d;
        if (!(l->vtag[v] & SFB__TAG_NONMANIFOLD)) {
            if (l->vtag[v] & SFB__TAG_BOUNDARY) {
                o->extraordinary_catmark += k != 2 && k != 1;
                o->extraordinary_loop += k != 3 && k != 1;
            } else {
                o->extraordinary_catmark += k != 4;
                o->extraordinary_loop += k != 6;
            }
        }
        for (c = 0; c < 3; ++c) {
            float x = m->positions[3 * (size_t)v + c];
            if (x < o->bbox_min[c]) o->bbox_min[c] = x;
            if (x > o->bbox_max[c]) o->bbox_max[c] = x;
        }
    }
    /* vertex rules as refinement will see them (after boundary sharpening) */
    if (sfb__level_prepare(m->ctx, l, m->boundary == SFB_BOUNDARY_EDGE_AND_CORNER, 0, &prep) == SFB_SUCCESS) {
        for (v = 0; v < prep.nv; ++v) {
            o->darts += prep.vrule[v] == SFB__RULE_DART;
            o->crease_vertices += prep.vrule[v] == SFB__RULE_CREASE;
            o->corner_vertices += prep.vrule[v] == SFB__RULE_CORNER && prep.ve_off[v + 1] > prep.ve_off[v];
        }
        sfb__level_free(m->ctx, &prep);
    }
}

SFB_API int sfb_mesh_valence_histogram(const sfb_mesh *m, int *counts, int max_valence) {
    int v, over = 0;
    if (!m || !counts || max_valence <= 0) return 0;
    memset(counts, 0, sizeof(int) * (size_t)max_valence);
    for (v = 0; v < m->base.nv; ++v) {
        int d = m->base.ve_off[v + 1] - m->base.ve_off[v];
        if (d < max_valence) counts[d]++; else over++;
    }
    return over;
}
#line 1 "src/obj.c"
/* OBJ reader (from memory) and writer: v/vt/vn/f, OpenSubdiv's `t` tags, seed 001's fs/as.
 *
 * Choices where the formats are loose:
 * - `fs s0 s1 ...` applies to the face on the line before it; value i is the sharpness of the
 *   edge from the face's vertex i to vertex i+1 in the order the face lists them (seed 001 says
 *   "clockwise order" without naming the first edge; we follow the face's own order).
 * - `as n s0 s1 ...` gives the same values to each of the next n faces (seed 001); each of those
 *   faces must have as many edges as values. Where two faces disagree on an edge the highest
 *   value wins. `as` counting past the last face is an error.
 * - Faces either all carry vt indices or none does; otherwise the UVs are dropped (logged).
 * - `t crease` with more than two vertices is a chain of edges; one value applies to all, or
 *   one value per edge. Hierarchical edits (vertexedit, edgeedit, faceedit) and unknown tags are
 *   ignored with a warning, as OpenSubdiv 3 does.
 */

typedef struct sfb__vec {
    void *p;
    size_t n, cap, elem;
} sfb__vec;

static int sfb__vec_push(sfb_context *ctx, sfb__vec *v, const void *x) {
    if (v->n == v->cap) {
        size_t cap = v->cap ? v->cap * 2 : 64;
        void *np;
        if (cap > SFB_MAX_ELEMENTS * (size_t)2) return 0;
        np = sfb__realloc(ctx, v->p, cap * v->elem);
        if (!np) return 0;
        v->p = np;
        v->cap = cap;
    }
    memcpy((char *)v->p + v->n * v->elem, x, v->elem);
    v->n++;
    return 1;
}

typedef struct sfb__objp {
    sfb_context *ctx;
    long line;
    sfb__vec pos, uv, fsize, fv, fuv, fline, fsharp, cv, cs, cline, kv, ks, kline, holes, hline;
    int first_has_uv;          /* -1 before the first face */
    long uv_mismatch_face, uv_mismatch_line; /* first face whose uv use differs from face 0; -1 none */
    int any_fsharp;
    int boundary, crease_method, triangle_rule;
    /* pending `as` */
    long as_left, as_line;
    float *as_vals;
    int as_count;
} sfb__objp;

static sfb_result sfb__perr(sfb__objp *P, sfb_result r, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static sfb_result sfb__perr(sfb__objp *P, sfb_result r, const char *fmt, ...) {
    char body[600];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(body, sizeof body, fmt, ap);
    va_end(ap);
    return sfb__error(P->ctx, r, SFB_ELEMENT_LINE, P->line, "%s", body);
}

static int sfb__next_tok(const char **cur, const char *end, const char **tok, size_t *len) {
    const char *c = *cur;
    while (c < end && (*c == ' ' || *c == '\t')) ++c;
    if (c >= end || *c == '#') { *cur = end; return 0; }
    *tok = c;
    while (c < end && *c != ' ' && *c != '\t') ++c;
    *len = (size_t)(c - *tok);
    *cur = c;
    return 1;
}

static int sfb__tok_eq(const char *t, size_t n, const char *s) { return strlen(s) == n && memcmp(t, s, n) == 0; }

/* 0 ok, 1 not a number, 2 not finite */
static int sfb__parse_double(const char *t, size_t n, double *out) {
    char buf[72];
    char *endp;
    double x;
    if (n == 0 || n >= sizeof buf) return 1;
    memcpy(buf, t, n);
    buf[n] = 0;
    if (!((buf[0] >= '0' && buf[0] <= '9') || buf[0] == '-' || buf[0] == '+' || buf[0] == '.' || buf[0] == 'n' ||
          buf[0] == 'N' || buf[0] == 'i' || buf[0] == 'I'))
        return 1;
    x = strtod(buf, &endp);
    if (*endp != 0 || endp == buf) return 1;
    *out = x;
    /* not finite as a float: the doubles that round to infinity, |x| >= FLT_MAX + half an ulp
     * (2^128 - 2^103; FLT_MAX itself, written with 9 digits as 3.40282347e+38, is above
     * FLT_MAX as a double and rounds back to it) */
    if (!isfinite(x) || fabs(x) >= 3.4028235677973366e38) return 2;
    return 0;
}

static sfb_result sfb__tok_float(sfb__objp *P, const char *t, size_t n, const char *what, float *out) {
    double x;
    int r = sfb__parse_double(t, n, &x);
    if (r == 1) return sfb__perr(P, SFB_PARSE_ERROR, "expected a number for %s, got '%.*s'", what, (int)(n > 40 ? 40 : n), t);
    if (r == 2) return sfb__perr(P, SFB_INVALID_VALUE, "%s '%.*s' is not a finite number (NaN or inf)", what, (int)(n > 40 ? 40 : n), t);
    *out = (float)x;
    return SFB_SUCCESS;
}

static sfb_result sfb__tok_sharpness(sfb__objp *P, const char *t, size_t n, float *out) {
    double x;
    int r = sfb__parse_double(t, n, &x);
    if (r == 1) return sfb__perr(P, SFB_PARSE_ERROR, "expected a sharpness number, got '%.*s'", (int)(n > 40 ? 40 : n), t);
    if (isnan(x) || x < 0.0)
        return sfb__perr(P, SFB_INVALID_VALUE, "sharpness '%.*s' is invalid: sharpness must be a number >= 0", (int)(n > 40 ? 40 : n), t);
    *out = x >= SFB_SHARPNESS_INFINITE ? SFB_SHARPNESS_INFINITE : (float)x;
    return SFB_SUCCESS;
}

/* Parses a decimal integer; 0 ok, 1 malformed, 2 overflow. Stops at '/' or the end. */
static int sfb__parse_int(const char **c, const char *end, long *out) {
    const char *p = *c;
    int neg = 0;
    long v = 0;
    if (p < end && (*p == '-' || *p == '+')) { neg = *p == '-'; ++p; }
    if (p >= end || *p < '0' || *p > '9') return 1;
    while (p < end && *p >= '0' && *p <= '9') {
        v = v * 10 + (*p - '0');
        if (v > 0x7fffffffL) return 2;
        ++p;
    }
    *c = p;
    *out = neg ? -v : v;
    return 0;
}

static sfb_result sfb__tok_int(sfb__objp *P, const char *t, size_t n, const char *what, long *out) {
    const char *c = t;
    int r = sfb__parse_int(&c, t + n, out);
    if (r == 2) return sfb__perr(P, SFB_LIMIT_EXCEEDED, "%s '%.*s' is over the limit of a 32-bit integer", what, (int)(n > 40 ? 40 : n), t);
    if (r == 1 || c != t + n) return sfb__perr(P, SFB_PARSE_ERROR, "expected an integer for %s, got '%.*s'", what, (int)(n > 40 ? 40 : n), t);
    return SFB_SUCCESS;
}

/* Resolves an OBJ index (1-based or negative relative) against `count` elements so far. */
static sfb_result sfb__resolve(sfb__objp *P, long idx, size_t count, const char *what, int *out) {
    if (idx == 0) return sfb__perr(P, SFB_INVALID_TOPOLOGY, "%s index 0 is invalid (OBJ indices start at 1)", what);
    if (idx < 0) idx = (long)count + idx;
    else idx = idx - 1;
    if (idx < 0 || (size_t)idx >= count)
        return sfb__perr(P, SFB_INVALID_TOPOLOGY, "%s index out of range (%zu %s defined so far)", what, count,
                         strcmp(what, "vertex") == 0 ? "vertices" : "uvs");
    *out = (int)idx;
    return SFB_SUCCESS;
}

#define SFB__PUSH(vec, val) do { if (!sfb__vec_push(P->ctx, &(vec), &(val))) return sfb__oom(P->ctx, "OBJ reader"); } while (0)

static sfb_result sfb__obj_face(sfb__objp *P, const char *cur, const char *end) {
    const char *t;
    size_t n;
    int count = 0, has_uv = -1, line = (int)P->line;
    size_t first = P->fv.n;
    sfb_result r;
    while (sfb__next_tok(&cur, end, &t, &n)) {
        const char *c = t, *te = t + n;
        long a, b = 0;
        int vi, ti = -1, this_uv = 0, pr;
        pr = sfb__parse_int(&c, te, &a);
        if (pr == 1) return sfb__perr(P, SFB_PARSE_ERROR, "malformed face index '%.*s'", (int)(n > 40 ? 40 : n), t);
        if (pr == 2) return sfb__perr(P, SFB_INVALID_TOPOLOGY, "vertex index '%.*s' out of range", (int)(n > 40 ? 40 : n), t);
        if (c < te) {
            if (*c != '/') return sfb__perr(P, SFB_PARSE_ERROR, "malformed face index '%.*s'", (int)(n > 40 ? 40 : n), t);
            ++c;
            if (c < te && *c != '/') {
                pr = sfb__parse_int(&c, te, &b);
                if (pr == 1) return sfb__perr(P, SFB_PARSE_ERROR, "malformed uv index in '%.*s'", (int)(n > 40 ? 40 : n), t);
                if (pr == 2) return sfb__perr(P, SFB_INVALID_TOPOLOGY, "uv index in '%.*s' out of range", (int)(n > 40 ? 40 : n), t);
                this_uv = 1;
            } else if (c >= te) {
                return sfb__perr(P, SFB_PARSE_ERROR, "truncated face index '%.*s'", (int)(n > 40 ? 40 : n), t);
            }
            if (c < te) {
                long nn;
                if (*c != '/') return sfb__perr(P, SFB_PARSE_ERROR, "malformed face index '%.*s'", (int)(n > 40 ? 40 : n), t);
                ++c;
                pr = sfb__parse_int(&c, te, &nn);
                if (pr != 0 || c != te) return sfb__perr(P, SFB_PARSE_ERROR, "malformed normal index in '%.*s'", (int)(n > 40 ? 40 : n), t);
            }
        }
        r = sfb__resolve(P, a, P->pos.n / 3, "vertex", &vi);
        if (r != SFB_SUCCESS) return r;
        if (this_uv) {
            r = sfb__resolve(P, b, P->uv.n / 2, "uv", &ti);
            if (r != SFB_SUCCESS) return r;
        }
        if (has_uv < 0) has_uv = this_uv;
        else if (has_uv != this_uv) return sfb__perr(P, SFB_PARSE_ERROR, "face mixes corners with and without uv indices");
        if (count >= SFB_MAX_FACE_SIZE)
            return sfb__perr(P, SFB_LIMIT_EXCEEDED, "face has more than %d vertices (SFB_MAX_FACE_SIZE)", SFB_MAX_FACE_SIZE);
        SFB__PUSH(P->fv, vi);
        SFB__PUSH(P->fuv, ti);
        count++;
    }
    if (count < 3)
        return sfb__perr(P, SFB_INVALID_TOPOLOGY, "face has %d %s; a face needs at least 3", count, count == 1 ? "vertex" : "vertices");
    SFB__PUSH(P->fsize, count);
    SFB__PUSH(P->fline, line);
    if (P->first_has_uv < 0) P->first_has_uv = has_uv;
    else if (has_uv != P->first_has_uv && P->uv_mismatch_face < 0) {
        P->uv_mismatch_face = (long)P->fsize.n - 1;
        P->uv_mismatch_line = line;
    }
    {
        float zero = 0.0f;
        int i;
        for (i = 0; i < count; ++i) SFB__PUSH(P->fsharp, zero);
    }
    if (P->as_left > 0) {
        int i;
        if (P->as_count != count)
            return sfb__perr(P, SFB_PARSE_ERROR, "face has %d edges but the 'as' on line %ld gives %d sharpness values", count,
                             P->as_line, P->as_count);
        for (i = 0; i < count; ++i) {
            float *fs = (float *)P->fsharp.p + first + i;
            if (P->as_vals[i] > *fs) *fs = P->as_vals[i];
        }
        P->any_fsharp = 1;
        P->as_left--;
    }
    return SFB_SUCCESS;
}

static sfb_result sfb__obj_tag(sfb__objp *P, const char *cur, const char *end) {
    const char *t, *name;
    size_t n, nn;
    long ni, nf, ns, i;
    long ints[64];
    float flts[64];
    const char *strs[4];
    size_t strl[4];
    long *iv = ints;
    float *fv = flts;
    sfb_result r = SFB_SUCCESS;
    if (!sfb__next_tok(&cur, end, &name, &nn)) return sfb__perr(P, SFB_PARSE_ERROR, "'t' line without a tag name");
    if (!sfb__next_tok(&cur, end, &t, &n)) return sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' lacks its argument counts", (int)(nn > 40 ? 40 : nn), name);
    {
        const char *c = t, *te = t + n;
        if (sfb__parse_int(&c, te, &ni) || c >= te || *c++ != '/' || sfb__parse_int(&c, te, &nf) || c >= te || *c++ != '/' ||
            sfb__parse_int(&c, te, &ns) || c != te || ni < 0 || nf < 0 || ns < 0)
            return sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' has malformed argument counts '%.*s' (expected i/f/s)",
                             (int)(nn > 40 ? 40 : nn), name, (int)(n > 40 ? 40 : n), t);
    }
    if (sfb__tok_eq(name, nn, "vertexedit") || sfb__tok_eq(name, nn, "edgeedit") || sfb__tok_eq(name, nn, "faceedit")) {
        sfb__log(P->ctx, SFB_LOG_WARN, "line %ld: hierarchical edit '%.*s' ignored (not supported)", P->line, (int)nn, name);
        return SFB_SUCCESS;
    }
    if (ni > 1000000 || nf > 1000000 || ns > 1000000)
        return sfb__perr(P, SFB_LIMIT_EXCEEDED, "tag '%.*s' declares more than 1000000 arguments (over the limit)", (int)(nn > 40 ? 40 : nn), name);
    if (ni > 64) iv = (long *)sfb__alloc(P->ctx, (size_t)ni * sizeof(long));
    if (nf > 64) fv = (float *)sfb__alloc(P->ctx, (size_t)nf * sizeof(float));
    if (!iv || !fv) { r = sfb__oom(P->ctx, "OBJ reader"); goto out; }
    for (i = 0; i < ni; ++i) {
        if (!sfb__next_tok(&cur, end, &t, &n)) { r = sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' declares %ld integers but the line has fewer values", (int)(nn > 40 ? 40 : nn), name, ni); goto out; }
        r = sfb__tok_int(P, t, n, "tag argument", &iv[i]);
        if (r) goto out;
    }
    for (i = 0; i < nf; ++i) {
        if (!sfb__next_tok(&cur, end, &t, &n)) { r = sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' declares %ld floats but the line has fewer values", (int)(nn > 40 ? 40 : nn), name, nf); goto out; }
        r = sfb__tok_sharpness(P, t, n, &fv[i]);
        if (r) goto out;
    }
    for (i = 0; i < ns; ++i) {
        if (!sfb__next_tok(&cur, end, &t, &n)) { r = sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' declares %ld strings but the line has fewer values", (int)(nn > 40 ? 40 : nn), name, ns); goto out; }
        if (i < 4) { strs[i] = t; strl[i] = n; }
    }
    if (sfb__next_tok(&cur, end, &t, &n)) { r = sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' has more values than its counts declare", (int)(nn > 40 ? 40 : nn), name); goto out; }
    if (sfb__tok_eq(name, nn, "crease")) {
        if (ni < 2 || !(nf == 1 || nf == ni - 1)) { r = sfb__perr(P, SFB_PARSE_ERROR, "crease needs at least 2 vertices and 1 sharpness (or one per edge)"); goto out; }
        for (i = 0; i + 1 < ni; ++i) {
            int a = (int)iv[i], b = (int)iv[i + 1], ln = (int)P->line;
            float s = fv[nf == 1 ? 0 : i];
            if (iv[i] < 0 || iv[i + 1] < 0) { r = sfb__perr(P, SFB_INVALID_TOPOLOGY, "crease vertex index %ld out of range", iv[i] < 0 ? iv[i] : iv[i + 1]); goto out; }
            if (!sfb__vec_push(P->ctx, &P->cv, &a) || !sfb__vec_push(P->ctx, &P->cv, &b) || !sfb__vec_push(P->ctx, &P->cs, &s) ||
                !sfb__vec_push(P->ctx, &P->cline, &ln)) { r = sfb__oom(P->ctx, "OBJ reader"); goto out; }
        }
    } else if (sfb__tok_eq(name, nn, "corner")) {
        if (ni < 1 || !(nf == 1 || nf == ni)) { r = sfb__perr(P, SFB_PARSE_ERROR, "corner needs vertices and 1 sharpness (or one per vertex)"); goto out; }
        for (i = 0; i < ni; ++i) {
            int a = (int)iv[i], ln = (int)P->line;
            float s = fv[nf == 1 ? 0 : i];
            if (iv[i] < 0) { r = sfb__perr(P, SFB_INVALID_TOPOLOGY, "corner vertex index %ld out of range", iv[i]); goto out; }
            if (!sfb__vec_push(P->ctx, &P->kv, &a) || !sfb__vec_push(P->ctx, &P->ks, &s) || !sfb__vec_push(P->ctx, &P->kline, &ln)) {
                r = sfb__oom(P->ctx, "OBJ reader"); goto out;
            }
        }
    } else if (sfb__tok_eq(name, nn, "hole")) {
        for (i = 0; i < ni; ++i) {
            int a = (int)iv[i], ln = (int)P->line;
            if (iv[i] < 0) { r = sfb__perr(P, SFB_INVALID_TOPOLOGY, "hole face index %ld out of range", iv[i]); goto out; }
            if (!sfb__vec_push(P->ctx, &P->holes, &a) || !sfb__vec_push(P->ctx, &P->hline, &ln)) { r = sfb__oom(P->ctx, "OBJ reader"); goto out; }
        }
    } else if (sfb__tok_eq(name, nn, "interpolateboundary")) {
        if (ni != 1) { r = sfb__perr(P, SFB_PARSE_ERROR, "interpolateboundary needs one integer"); goto out; }
        if (iv[0] == 0) P->boundary = SFB_BOUNDARY_NONE;
        else if (iv[0] == 1) P->boundary = SFB_BOUNDARY_EDGE_AND_CORNER;
        else if (iv[0] == 2) P->boundary = SFB_BOUNDARY_EDGE_ONLY;
        else { r = sfb__perr(P, SFB_INVALID_VALUE, "interpolateboundary value %ld is not 0, 1 or 2", iv[0]); goto out; }
    } else if (sfb__tok_eq(name, nn, "creasemethod")) {
        if (ns != 1) { r = sfb__perr(P, SFB_PARSE_ERROR, "creasemethod needs one string"); goto out; }
        if (sfb__tok_eq(strs[0], strl[0], "chaikin")) P->crease_method = SFB_CREASE_CHAIKIN;
        else if (sfb__tok_eq(strs[0], strl[0], "uniform") || sfb__tok_eq(strs[0], strl[0], "normal")) P->crease_method = SFB_CREASE_UNIFORM;
        else { r = sfb__perr(P, SFB_INVALID_VALUE, "creasemethod '%.*s' is not chaikin, uniform or normal", (int)(strl[0] > 40 ? 40 : strl[0]), strs[0]); goto out; }
    } else if (sfb__tok_eq(name, nn, "smoothtriangles")) {
        if (ns != 1) { r = sfb__perr(P, SFB_PARSE_ERROR, "smoothtriangles needs one string"); goto out; }
        if (sfb__tok_eq(strs[0], strl[0], "smooth")) P->triangle_rule = SFB_TRI_SMOOTH;
        else if (sfb__tok_eq(strs[0], strl[0], "catmark")) P->triangle_rule = SFB_TRI_CATMARK;
        else { r = sfb__perr(P, SFB_INVALID_VALUE, "smoothtriangles '%.*s' is not smooth or catmark", (int)(strl[0] > 40 ? 40 : strl[0]), strs[0]); goto out; }
    } else {
        sfb__log(P->ctx, SFB_LOG_WARN, "line %ld: tag '%.*s' ignored", P->line, (int)(nn > 40 ? 40 : nn), name);
    }
out:
    if (iv != ints) sfb__free(P->ctx, iv);
    if (fv != flts) sfb__free(P->ctx, fv);
    return r;
}

static const char *const sfb__obj_ignored[] = {"o", "g", "s", "usemtl", "mtllib", "l", "p", "vp", "cstype", "deg", "bmat",
                                               "step", "curv", "curv2", "surf", "parm", "trim", "end", "con", "mg", "lod",
                                               "maplib", "usemap", "shadow_obj", "trace_obj", "ctech", "stech", "bevel",
                                               "c_interp", "d_interp", "sp", "scrv", NULL};

static sfb_result sfb__obj_line(sfb__objp *P, const char *cur, const char *end) {
    const char *kw, *t;
    size_t kn, n;
    sfb_result r;
    if (!sfb__next_tok(&cur, end, &kw, &kn)) return SFB_SUCCESS;
    if (sfb__tok_eq(kw, kn, "v")) {
        float x[3];
        int i;
        for (i = 0; i < 3; ++i) {
            if (!sfb__next_tok(&cur, end, &t, &n)) return sfb__perr(P, SFB_PARSE_ERROR, "vertex needs 3 coordinates, got %d", i);
            r = sfb__tok_float(P, t, n, "vertex coordinate", &x[i]);
            if (r) return r;
        }
        while (sfb__next_tok(&cur, end, &t, &n)) { /* w or vertex colour: must be numbers */
            float dummy;
            r = sfb__tok_float(P, t, n, "vertex value", &dummy);
            if (r) return r;
        }
        if (P->pos.n / 3 >= SFB_MAX_ELEMENTS) return sfb__perr(P, SFB_LIMIT_EXCEEDED, "too many vertices");
        for (i = 0; i < 3; ++i) SFB__PUSH(P->pos, x[i]);
        return SFB_SUCCESS;
    }
    if (sfb__tok_eq(kw, kn, "vt")) {
        float x[2];
        int i;
        for (i = 0; i < 2; ++i) {
            if (!sfb__next_tok(&cur, end, &t, &n)) return sfb__perr(P, SFB_PARSE_ERROR, "texture coordinate needs 2 values, got %d", i);
            r = sfb__tok_float(P, t, n, "texture coordinate", &x[i]);
            if (r) return r;
        }
        if (sfb__next_tok(&cur, end, &t, &n)) {
            float dummy;
            r = sfb__tok_float(P, t, n, "texture coordinate", &dummy);
            if (r) return r;
        }
        for (i = 0; i < 2; ++i) SFB__PUSH(P->uv, x[i]);
        return SFB_SUCCESS;
    }
    if (sfb__tok_eq(kw, kn, "vn")) return SFB_SUCCESS; /* normals are recomputed from the surface */
    if (sfb__tok_eq(kw, kn, "f")) return sfb__obj_face(P, cur, end);
    if (sfb__tok_eq(kw, kn, "t")) return sfb__obj_tag(P, cur, end);
    if (sfb__tok_eq(kw, kn, "fs")) {
        size_t nfaces = P->fsize.n, first;
        int fsz, i = 0;
        if (nfaces == 0) return sfb__perr(P, SFB_PARSE_ERROR, "'fs' before any face");
        fsz = ((int *)P->fsize.p)[nfaces - 1];
        first = P->fv.n - (size_t)fsz;
        while (sfb__next_tok(&cur, end, &t, &n)) {
            float s;
            if (i >= fsz) return sfb__perr(P, SFB_PARSE_ERROR, "'fs' has more values than the face's %d edges", fsz);
            r = sfb__tok_sharpness(P, t, n, &s);
            if (r) return r;
            if (s > ((float *)P->fsharp.p)[first + i]) ((float *)P->fsharp.p)[first + i] = s;
            ++i;
        }
        if (i != fsz) return sfb__perr(P, SFB_PARSE_ERROR, "'fs' has %d values but the face has %d edges", i, fsz);
        P->any_fsharp = 1;
        return SFB_SUCCESS;
    }
    if (sfb__tok_eq(kw, kn, "as")) {
        long cnt;
        int k = 0;
        if (P->as_left > 0)
            return sfb__perr(P, SFB_PARSE_ERROR, "'as' starts before the 'as' on line %ld covered its faces", P->as_line);
        if (!sfb__next_tok(&cur, end, &t, &n)) return sfb__perr(P, SFB_PARSE_ERROR, "'as' needs a face count");
        r = sfb__tok_int(P, t, n, "'as' face count", &cnt);
        if (r) return r;
        if (cnt <= 0) return sfb__perr(P, SFB_PARSE_ERROR, "'as' face count %ld must be positive", cnt);
        if (cnt > SFB_MAX_ELEMENTS)
            return sfb__perr(P, SFB_LIMIT_EXCEEDED, "'as' face count %ld is over the limit of %d faces", cnt, SFB_MAX_ELEMENTS);
        if (!P->as_vals) {
            P->as_vals = (float *)sfb__alloc(P->ctx, SFB_MAX_FACE_SIZE * sizeof(float));
            if (!P->as_vals) return sfb__oom(P->ctx, "OBJ reader");
        }
        while (sfb__next_tok(&cur, end, &t, &n)) {
            if (k >= SFB_MAX_FACE_SIZE) return sfb__perr(P, SFB_LIMIT_EXCEEDED, "'as' has more than %d values", SFB_MAX_FACE_SIZE);
            r = sfb__tok_sharpness(P, t, n, &P->as_vals[k]);
            if (r) return r;
            ++k;
        }
        if (k < 3) return sfb__perr(P, SFB_PARSE_ERROR, "'as' needs one sharpness per face edge (at least 3), got %d", k);
        P->as_left = cnt;
        P->as_line = P->line;
        P->as_count = k;
        return SFB_SUCCESS;
    }
    {
        int i;
        for (i = 0; sfb__obj_ignored[i]; ++i)
            if (sfb__tok_eq(kw, kn, sfb__obj_ignored[i])) return SFB_SUCCESS;
    }
    return sfb__perr(P, SFB_PARSE_ERROR, "unknown statement '%.*s'", (int)(kn > 24 ? 24 : kn), kw);
}

static void sfb__objp_free(sfb__objp *P) {
    sfb__vec *vs[] = {&P->pos, &P->uv, &P->fsize, &P->fv, &P->fuv, &P->fline, &P->fsharp, &P->cv, &P->cs, &P->cline,
                      &P->kv, &P->ks, &P->kline, &P->holes, &P->hline};
    size_t i;
    for (i = 0; i < sizeof vs / sizeof vs[0]; ++i) sfb__free(P->ctx, vs[i]->p);
    sfb__free(P->ctx, P->as_vals);
}

SFB_API sfb_result sfb_mesh_read_obj(sfb_context *ctx, const char *text, size_t size, sfb_mesh **out) {
    sfb__objp P;
    const char *c, *end;
    sfb_result r = SFB_SUCCESS;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!out || (!text && size)) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_mesh_read_obj: NULL argument");
    *out = NULL;
    memset(&P, 0, sizeof P);
    P.ctx = ctx;
    P.first_has_uv = -1;
    P.uv_mismatch_face = -1;
    P.pos.elem = sizeof(float); P.uv.elem = sizeof(float); P.fsize.elem = sizeof(int); P.fv.elem = sizeof(int);
    P.fuv.elem = sizeof(int); P.fline.elem = sizeof(int); P.fsharp.elem = sizeof(float); P.cv.elem = sizeof(int);
    P.cs.elem = sizeof(float); P.cline.elem = sizeof(int); P.kv.elem = sizeof(int); P.ks.elem = sizeof(float);
    P.kline.elem = sizeof(int); P.holes.elem = sizeof(int); P.hline.elem = sizeof(int);
    c = text;
    end = text + size;
    while (c < end && r == SFB_SUCCESS) {
        const char *le = (const char *)memchr(c, '\n', (size_t)(end - c)), *q;
        const char *next = le ? le + 1 : end;
        if (!le) le = end;
        P.line++;
        if (le > c && le[-1] == '\r') --le;
        for (q = c; q < le; ++q) {
            unsigned char ch = (unsigned char)*q;
            if (ch == 0 || (ch < 32 && ch != '\t') || ch == 127) {
                r = sfb__perr(&P, SFB_PARSE_ERROR, "binary data (byte 0x%02x) in text", ch);
                break;
            }
        }
        if (r == SFB_SUCCESS) r = sfb__obj_line(&P, c, le);
        if ((P.line & 0xffff) == 0 && r == SFB_SUCCESS) r = sfb__progress(ctx, (float)(c - text) / (float)size, "read OBJ");
        c = next;
    }
    if (r == SFB_SUCCESS && P.as_left > 0) {
        P.line = P.as_line;
        r = sfb__perr(&P, SFB_PARSE_ERROR, "'as' covers %ld more faces than the file has", P.as_left);
    }
    if (r == SFB_SUCCESS) {
        sfb_mesh_desc d;
        sfb__src_lines lines;
        memset(&d, 0, sizeof d);
        d.vertex_count = (int)(P.pos.n / 3);
        d.positions = (const float *)P.pos.p;
        d.face_count = (int)P.fsize.n;
        d.face_sizes = (const int *)P.fsize.p;
        d.face_vertices = (const int *)P.fv.p;
        d.crease_count = (int)P.cs.n;
        d.crease_vertices = (const int *)P.cv.p;
        d.crease_sharpness = (const float *)P.cs.p;
        d.corner_count = (int)P.ks.n;
        d.corner_vertices = (const int *)P.kv.p;
        d.corner_sharpness = (const float *)P.ks.p;
        d.hole_count = (int)P.holes.n;
        d.holes = (const int *)P.holes.p;
        if (P.uv_mismatch_face >= 0) {
            /* some faces with uv indices, some without: refuse rather than drop the uvs */
            P.line = P.uv_mismatch_line;
            r = sfb__perr(&P, SFB_INVALID_TOPOLOGY, "face %ld %s uv indices but face 0 %s (every face needs uvs, or none)",
                          P.uv_mismatch_face, P.first_has_uv ? "lacks" : "has", P.first_has_uv ? "has them" : "does not");
        } else if (P.first_has_uv == 1 && P.uv.n > 0) {
            d.uv_count = (int)(P.uv.n / 2);
            d.uvs = (const float *)P.uv.p;
            d.face_uvs = (const int *)P.fuv.p;
        }
        d.face_edge_sharpness = P.any_fsharp ? (const float *)P.fsharp.p : NULL;
        d.boundary = P.boundary;
        d.crease_method = P.crease_method;
        d.triangle_rule = P.triangle_rule;
        lines.face = (const int *)P.fline.p;
        lines.crease = (const int *)P.cline.p;
        lines.corner = (const int *)P.kline.p;
        lines.hole = (const int *)P.hline.p;
        if (r != SFB_SUCCESS) { /* reported above */ }
        else if (d.face_count == 0) r = sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_NONE, -1, "OBJ has no faces (line %ld is the last)", P.line);
        else r = sfb__mesh_create(ctx, &d, &lines, out);
    }
    sfb__objp_free(&P);
    return r;
}

/* ---- writer ---- */
typedef struct sfb__wbuf {
    sfb_write_fn fn;
    void *user;
    char buf[8192];
    size_t n;
    int failed;
} sfb__wbuf;

static void sfb__wflush(sfb__wbuf *w) {
    if (w->n && !w->failed && w->fn(w->buf, w->n, w->user)) w->failed = 1;
    w->n = 0;
}

static void sfb__wprintf(sfb__wbuf *w, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void sfb__wprintf(sfb__wbuf *w, const char *fmt, ...) {
    va_list ap;
    int k;
    if (w->n > sizeof w->buf - 256) sfb__wflush(w);
    va_start(ap, fmt);
    k = vsnprintf(w->buf + w->n, sizeof w->buf - w->n, fmt, ap);
    va_end(ap);
    if (k > 0 && (size_t)k < sizeof w->buf - w->n) w->n += (size_t)k;
}

SFB_API sfb_result sfb_write_obj(const sfb_mesh_desc *d, sfb_write_fn write, void *user) {
    sfb__wbuf wb, *w = &wb; /* on the stack: the writer has no context, so no allocator */
    int i, f, o = 0;
    static const int osd_boundary[3] = {2, 1, 0}; /* our enum -> OpenSubdiv's interpolateboundary */
    sfb_result r = SFB_SUCCESS;
    if (!d || !write || d->vertex_count < 0 || d->face_count < 0 || (d->vertex_count && !d->positions) ||
        (d->face_count && (!d->face_sizes || !d->face_vertices)))
        return SFB_INVALID_ARGS;
    w->fn = write; w->user = user; w->n = 0; w->failed = 0;
    sfb__wprintf(w, "# surfblend OBJ: %d vertices, %d faces\n", d->vertex_count, d->face_count);
    for (i = 0; i < d->vertex_count; ++i)
        sfb__wprintf(w, "v %.9g %.9g %.9g\n", d->positions[3 * i], d->positions[3 * i + 1], d->positions[3 * i + 2]);
    for (i = 0; i < d->uv_count; ++i) sfb__wprintf(w, "vt %.9g %.9g\n", d->uvs[2 * i], d->uvs[2 * i + 1]);
    for (f = 0; f < d->face_count; ++f) {
        int n = d->face_sizes[f], any = 0;
        if (n < 0 || n > SFB_MAX_FACE_SIZE) { r = SFB_INVALID_ARGS; break; }
        sfb__wprintf(w, "f");
        for (i = 0; i < n; ++i) {
            if (w->n > sizeof w->buf - 64) sfb__wflush(w);
            if (d->uv_count && d->face_uvs) sfb__wprintf(w, " %d/%d", d->face_vertices[o + i] + 1, d->face_uvs[o + i] + 1);
            else sfb__wprintf(w, " %d", d->face_vertices[o + i] + 1);
        }
        sfb__wprintf(w, "\n");
        if (d->face_edge_sharpness) {
            for (i = 0; i < n; ++i) any |= d->face_edge_sharpness[o + i] > 0.0f;
            if (any) {
                sfb__wprintf(w, "fs");
                for (i = 0; i < n; ++i) sfb__wprintf(w, " %.9g", d->face_edge_sharpness[o + i]);
                sfb__wprintf(w, "\n");
            }
        }
        o += n;
    }
    for (i = 0; i < d->crease_count; ++i)
        sfb__wprintf(w, "t crease 2/1/0 %d %d %.9g\n", d->crease_vertices[2 * i], d->crease_vertices[2 * i + 1], d->crease_sharpness[i]);
    for (i = 0; i < d->corner_count; ++i)
        sfb__wprintf(w, "t corner 1/1/0 %d %.9g\n", d->corner_vertices[i], d->corner_sharpness[i]);
    for (i = 0; i < d->hole_count; ++i) sfb__wprintf(w, "t hole 1/0/0 %d\n", d->holes[i]);
    if (d->boundary >= 0 && d->boundary <= 2) sfb__wprintf(w, "t interpolateboundary 1/0/0 %d\n", osd_boundary[d->boundary]);
    if (d->crease_method == SFB_CREASE_CHAIKIN) sfb__wprintf(w, "t creasemethod 0/0/1 chaikin\n");
    if (d->triangle_rule == SFB_TRI_SMOOTH) sfb__wprintf(w, "t smoothtriangles 0/0/1 smooth\n");
    sfb__wflush(w);
    if (r == SFB_SUCCESS && w->failed) r = SFB_IO_ERROR;
    return r;
}

SFB_API sfb_result sfb_mesh_write_obj(const sfb_mesh *mesh, sfb_write_fn write, void *user) {
    sfb_mesh_desc d;
    if (!mesh) return SFB_INVALID_ARGS;
    sfb_mesh_get_desc(mesh, &d);
    return sfb_write_obj(&d, write, user);
}
#line 1 "src/scheme.c"
/* The schemes at the API edge: what each sfb_scheme is made of -- which rules refine it, which
 * builder writes its patch table, what it supports -- in one table. sfb_surface_create reads
 * the scheme's row here and calls its builders; nothing past the builders asks the scheme again
 * (tables say what they are: docs/ARCHITECTURE.md). A new scheme is its builder's file plus one
 * row below (and its enum value in sfb_api.h). */

/* Patch-table builders of the schemes (the surface's prepared base level, refine options with
 * the scheme's rules, its configuration and base positions). */
static sfb_result sfb__scheme_build_isolated(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt,
                                             const sfb_surface_config *cfg, const float *positions, sfb__patch_table *pt) {
    return sfb__patches_build(ctx, prep, opt, cfg->isolation_level ? cfg->isolation_level : SFB_DEFAULT_ISOLATION, positions, pt);
}

static sfb_result sfb__scheme_build_manifold(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt,
                                             const sfb_surface_config *cfg, const float *positions, sfb__patch_table *pt) {
    (void)opt;
    return sfb__manifold_build(ctx, prep, cfg->manifold.weights, positions, pt);
}

static sfb_result sfb__scheme_build_pn(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt,
                                       const sfb_surface_config *cfg, const float *positions, sfb__patch_table *pt) {
    (void)opt; (void)cfg;
    return sfb__pn_build(ctx, prep, positions, pt);
}

static sfb_result sfb__scheme_build_tribezier(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt,
                                              const sfb_surface_config *cfg, const float *positions, sfb__patch_table *pt) {
    (void)opt;
    return sfb__tribezier_build(ctx, prep, positions, &cfg->tribezier, pt);
}

/* One row per scheme. */
static const sfb__scheme_info sfb__schemes[] = {
    {SFB_SCHEME_CATMARK, "catmark", "Catmull-Clark", SFB_SCHEME_CATMARK,
     SFB__SCHEME_REFINES | SFB__SCHEME_SHADES | SFB__SCHEME_BOUNDARY_HOLES, sfb__scheme_build_isolated},
    {SFB_SCHEME_LOOP, "loop", "Loop", SFB_SCHEME_LOOP,
     SFB__SCHEME_REFINES | SFB__SCHEME_SHADES | SFB__SCHEME_BOUNDARY_HOLES | SFB__SCHEME_TRIANGLES, sfb__scheme_build_isolated},
    {SFB_SCHEME_BILINEAR, "bilinear", "bilinear", SFB_SCHEME_BILINEAR, SFB__SCHEME_REFINES, NULL},
    /* evaluated only: its tables are built at level 0, where Catmull-Clark's rules are the identity */
    {SFB_SCHEME_MANIFOLD_BLEND, "manifold", "manifold blending", SFB_SCHEME_CATMARK, SFB__SCHEME_BOUNDARY_HOLES,
     sfb__scheme_build_manifold},
    /* evaluated only (seed 004): its tables are built at level 0, where Loop's rules are the identity */
    {SFB_SCHEME_TRIBEZIER, "tribezier", "quartic triangular Bezier", SFB_SCHEME_LOOP, SFB__SCHEME_TRIANGLES | SFB__SCHEME_UVS_OR_LINEAR,
     sfb__scheme_build_tribezier},
    /* evaluated only: its tables are built at level 0, where Loop's rules are the identity */
    {SFB_SCHEME_PN, "pn", "PN triangles", SFB_SCHEME_LOOP, SFB__SCHEME_TRIANGLES | SFB__SCHEME_LINEAR_UVS, sfb__scheme_build_pn}
};

const sfb__scheme_info *sfb__scheme_info_of(sfb_scheme s) {
    size_t i;
    for (i = 0; i < sizeof sfb__schemes / sizeof *sfb__schemes; ++i)
        if (sfb__schemes[i].scheme == s) return &sfb__schemes[i];
    return NULL;
}

SFB_API const char *sfb_scheme_name(sfb_scheme s) {
    const sfb__scheme_info *si = sfb__scheme_info_of(s);
    return si ? si->name : "unknown";
}

SFB_API int sfb_scheme_parse(const char *name, sfb_scheme *out) {
    size_t i;
    if (!name || !out) return 0;
    if (strcmp(name, "catmull-clark") == 0) { *out = SFB_SCHEME_CATMARK; return 1; }
    for (i = 0; i < sizeof sfb__schemes / sizeof *sfb__schemes; ++i)
        if (strcmp(name, sfb__schemes[i].name) == 0) { *out = sfb__schemes[i].scheme; return 1; }
    return 0;
}

SFB_API unsigned sfb_scheme_caps(sfb_scheme s) {
    const sfb__scheme_info *si = sfb__scheme_info_of(s);
    if (!si) return 0;
    return (si->caps & (SFB_SCHEME_CAN_REFINE | SFB_SCHEME_CAN_SHADE | SFB_SCHEME_TRIANGLES)) |
           (si->build_patches ? (unsigned)SFB_SCHEME_CAN_EVAL : 0u);
}

/* The names of the schemes that have `cap` (or, cap 0, a patch builder), comma-separated. */
static void sfb__scheme_list(unsigned cap, char *buf, size_t size) {
    size_t i, used = 0;
    buf[0] = 0;
    for (i = 0; i < sizeof sfb__schemes / sizeof *sfb__schemes; ++i) {
        const sfb__scheme_info *si = &sfb__schemes[i];
        if (cap ? !(si->caps & cap) : !si->build_patches) continue;
        used += (size_t)snprintf(buf + used, size - used, "%s%s", used ? ", " : "", si->name);
        if (used >= size) return;
    }
}

/* Refuses a scheme that cannot be built as configured (its kind of surface). */
sfb_result sfb__scheme_check_kind(sfb_context *ctx, const sfb__scheme_info *si, const sfb_surface_config *cfg) {
    if (!si) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "scheme %d is not an sfb_scheme", (int)cfg->scheme);
    if (!(si->caps & SFB__SCHEME_REFINES) && si->build_patches) {
        /* evaluated, not refined (manifold blending) */
        if (!(cfg->flags & SFB_REFINE_PATCHES) || cfg->refine_level != 0 || (cfg->flags & (SFB_REFINE_LIMIT | SFB_REFINE_SHADING)))
            return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                              "scheme '%s' is evaluated, not refined: use refine level 0 with SFB_REFINE_PATCHES (and neither "
                              "SFB_REFINE_LIMIT nor SFB_REFINE_SHADING), then sfb_surface_eval or sfb_surface_tessellate", si->name);
    } else if (!(si->caps & SFB__SCHEME_REFINES)) {
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1, "scheme '%s' cannot be refined uniformly yet", si->name);
    }
    return SFB_SUCCESS;
}

/* Refuses flags the scheme does not support (evaluation, shading). */
sfb_result sfb__scheme_check_flags(sfb_context *ctx, const sfb__scheme_info *si, const sfb_surface_config *cfg) {
    char list[256];
    if ((cfg->flags & SFB_REFINE_PATCHES) && !si->build_patches) {
        sfb__scheme_list(0, list, sizeof list);
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1, "evaluation (SFB_REFINE_PATCHES) is built for %s; scheme '%s' is not supported",
                          list, si->name);
    }
    if ((cfg->flags & SFB_REFINE_SHADING) && !(si->caps & SFB__SCHEME_SHADES)) {
        sfb__scheme_list(SFB__SCHEME_SHADES, list, sizeof list);
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "subdivision shading (SFB_REFINE_SHADING) is built for %s; scheme '%s' is not supported", list, si->name);
    }
    return SFB_SUCCESS;
}
#line 1 "src/surface.c"
/* Surfaces: compile a mesh into tables once (sfb_surface_create), apply them on the
 * context's backend as often as needed (sfb_surface_eval_stencils / sfb_surface_refine). */

SFB_API sfb_surface_config sfb_surface_config_init(sfb_scheme scheme, int level) {
    sfb_surface_config c;
    memset(&c, 0, sizeof c);
    c.scheme = scheme;
    c.refine_level = level;
    return c;
}

SFB_API void sfb_surface_destroy(sfb_surface *s) {
    sfb_context *ctx;
    int t;
    if (!s) return;
    ctx = s->ctx;
    for (t = 0; t < SFB_TABLE_COUNT_; ++t) {
        if (s->backend_tables[t] && s->uploaded_by && s->uploaded_by->release_stencils)
            s->uploaded_by->release_stencils(ctx->backend_state, s->backend_tables[t]);
        sfb__stencils_free(ctx, &s->tables[t]);
    }
    if (s->backend_patches && s->uploaded_by && s->uploaded_by->release_patches)
        s->uploaded_by->release_patches(ctx->backend_state, s->backend_patches);
    if (s->backend_normal_field && s->uploaded_by && s->uploaded_by->release_patches)
        s->uploaded_by->release_patches(ctx->backend_state, s->backend_normal_field);
    sfb__patch_table_free(ctx, &s->patches);
    if (s->shading) {
        int h;
        for (h = 0; h < 5; ++h)
            if (s->shading->handles[h] && s->uploaded_by && s->uploaded_by->release_stencils)
                s->uploaded_by->release_stencils(ctx->backend_state, s->shading->handles[h]);
        sfb__shading_free(ctx, s->shading);
    }
    sfb__level_free(ctx, &s->pbase);
    sfb__level_free(ctx, &s->top);
    sfb__level_free(ctx, &s->uv_top);
    sfb__level_free(ctx, &s->uv_base);
    sfb__free(ctx, s->base_positions);
    sfb__free(ctx, s->base_uvs);
    sfb__free(ctx, s);
}

/* Rough peak bytes of refining `m` to `level`: topology of the last two levels plus composed
 * stencil rows in double during construction. Used to refuse early, before any allocation
 * sized by the level. */
static double sfb__estimate_bytes(const sfb_mesh *m, int triangles, int level, int limit, double *faces_out) {
    double faces = m->base.nf, verts = m->base.nv;
    int L;
    for (L = 0; L < level; ++L) {
        if (triangles) faces *= 4.0;
        else faces = (L == 0) ? (double)m->base.nfv : faces * 4.0;
    }
    verts = triangles ? faces / 2.0 + 2.0 : faces + 2.0;
    if (level == 0) verts = m->base.nv;
    *faces_out = faces;
    return faces * 4.0 * 40.0 + verts * 16.0 * 12.0 * (limit ? 3.0 : 1.5);
}

/* Refuses a scheme, level, flag set or mesh that sfb_surface_create cannot build, before any
 * allocation (the size estimate against SFB_MAX_ELEMENTS and the memory budget included). */
static sfb_result sfb__surface_check(sfb_context *ctx, const sfb_mesh *mesh, const sfb_surface_config *cfg) {
    const sfb__scheme_info *si = sfb__scheme_info_of(cfg->scheme);
    double faces, bytes;
    int f;
    sfb_result r;
    if ((r = sfb__scheme_check_kind(ctx, si, cfg)) != SFB_SUCCESS) return r;
    if (cfg->refine_level < 0) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "refinement level %d is negative", cfg->refine_level);
    if (cfg->refine_level > SFB_MAX_LEVEL)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "refinement level %d is over the limit of %d (SFB_MAX_LEVEL)",
                          cfg->refine_level, SFB_MAX_LEVEL);
    if ((r = sfb__scheme_check_flags(ctx, si, cfg)) != SFB_SUCCESS) return r;
    if ((cfg->flags & SFB_REFINE_PATCHES) && (cfg->isolation_level < 0 || cfg->isolation_level > SFB_MAX_LEVEL))
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "isolation level %d is outside 0..%d (0 = default %d)",
                          cfg->isolation_level, SFB_MAX_LEVEL, SFB_DEFAULT_ISOLATION);
    if (si->caps & SFB__SCHEME_TRIANGLES)
        for (f = 0; f < mesh->base.nf; ++f)
            if (mesh->base.fv_off[f + 1] - mesh->base.fv_off[f] != 3)
                return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "%s subdivision needs triangles; this face has %d vertices",
                                  si->title, mesh->base.fv_off[f + 1] - mesh->base.fv_off[f]);
    bytes = sfb__estimate_bytes(mesh, (si->caps & SFB__SCHEME_TRIANGLES) != 0, cfg->refine_level, (cfg->flags & SFB_REFINE_LIMIT) != 0, &faces);
    if (faces > (double)SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "refining to level %d would make %.0f faces, over the limit of %d", cfg->refine_level, faces, SFB_MAX_ELEMENTS);
    if (bytes > (double)(ctx->budget - ctx->live_bytes))
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "refining to level %d needs about %.0f MiB, over the memory budget of %.1f MiB",
                          cfg->refine_level, bytes / 1048576.0, (double)ctx->budget / 1048576.0);
    return SFB_SUCCESS;
}

/* Refines the vertex mesh into s: the vertex (and limit) tables, the shading tables and the
 * patch table the flags ask for (s keeps the prepared base level of a patch table). */
static sfb_result sfb__surface_build_vertex(sfb_surface *s, const sfb_mesh *mesh, const sfb_surface_config *cfg) {
    sfb_context *ctx = s->ctx;
    const sfb__scheme_info *si = sfb__scheme_info_of(cfg->scheme);
    sfb__level prep;
    sfb__refine_options opt;
    sfb_result r;
    r = sfb__level_prepare(ctx, &mesh->base, mesh->boundary == SFB_BOUNDARY_EDGE_AND_CORNER,
                           mesh->boundary == SFB_BOUNDARY_NONE && (si->caps & SFB__SCHEME_BOUNDARY_HOLES), &prep);
    if (r != SFB_SUCCESS) return r;
    memset(&opt, 0, sizeof opt);
    opt.scheme = si->rules;
    opt.crease_method = mesh->crease_method;
    opt.triangle_rule = mesh->triangle_rule;
    opt.want_limit = (cfg->flags & SFB_REFINE_LIMIT) != 0;
    {
        /* the shading tables need every level and each step's own table: the vertex refinement
         * hands its over instead of the shading build refining a second time */
        const int shading = (cfg->flags & SFB_REFINE_SHADING) != 0, keep = shading && cfg->refine_level > 0;
        sfb__refine_kept kept;
        kept.lev = keep ? (sfb__level *)sfb__calloc(ctx, (size_t)cfg->refine_level, sizeof *kept.lev) : NULL;
        kept.T = keep ? (sfb__stencils *)sfb__calloc(ctx, (size_t)cfg->refine_level, sizeof *kept.T) : NULL;
        if (keep && (!kept.lev || !kept.T)) r = sfb__oom(ctx, "refinement");
        else r = sfb__refine_keep_levels(ctx, &prep, &opt, cfg->refine_level, &s->top, &s->tables[SFB_TABLE_VERTEX],
                                         opt.want_limit ? &s->tables[SFB_TABLE_LIMIT] : NULL, keep ? &kept : NULL, 0.0f, 0.8f);
        if (r == SFB_SUCCESS && shading)
            r = sfb__shading_build(ctx, &prep, &opt, cfg->refine_level, &cfg->shading, keep ? &kept : NULL, &s->top, &s->shading);
        sfb__free(ctx, kept.lev);
        sfb__free(ctx, kept.T);
    }
    if (r == SFB_SUCCESS && (cfg->flags & SFB_REFINE_PATCHES)) {
        r = si->build_patches(ctx, &prep, &opt, cfg, s->base_positions, &s->patches);
        if (r == SFB_SUCCESS) { s->has_patches = 1; s->pbase = prep; memset(&prep, 0, sizeof prep); }
    }
    sfb__level_free(ctx, &prep);
    if (r != SFB_SUCCESS) return r;
    s->built[SFB_TABLE_VERTEX] = 1;
    if (opt.want_limit) s->built[SFB_TABLE_LIMIT] = s->built[SFB_TABLE_TANGENT_U] = s->built[SFB_TABLE_TANGENT_V] = 1;
    return SFB_SUCCESS;
}

/* The UV layout is refined as a mesh of its own: its vertices are the UV values, so a seam (an
 * edge whose two faces disagree on a UV) is a boundary of the layout. It keeps the vertex
 * mesh's creases and corners; its own corners (one face, two edges) are pinned, as
 * OpenSubdiv's "linear corners only" face-varying mode. SFB_UV_LINEAR uses bilinear masks on
 * the same face split. Builds the UV table into s (the base UVs are copied by the caller). */
static sfb_result sfb__surface_build_uvs(sfb_surface *s, const sfb_mesh *mesh, const sfb_surface_config *cfg) {
    sfb_context *ctx = s->ctx;
    sfb__level uvl, uvp;
    sfb__refine_options opt;
    sfb__stencils dummy;
    sfb_result r;
    int f, o, i;
    r = sfb__level_from_faces(ctx, mesh->uv_count, mesh->base.nf, mesh->face_sizes, mesh->face_uvs, NULL, SFB_ELEMENT_UV, &uvl);
    if (r != SFB_SUCCESS) return r;
    for (f = 0; f < mesh->base.nf; ++f)
        for (o = mesh->base.fv_off[f], i = 0; o + i < mesh->base.fv_off[f + 1]; ++i) {
            int ue = uvl.fe[o + i], e = mesh->base.fe[o + i], uvv = mesh->face_uvs[o + i], vv = mesh->base.fv[o + i];
            if (mesh->base.es[e] > uvl.es[ue]) uvl.es[ue] = mesh->base.es[e];
            if (mesh->base.vs[vv] > uvl.vs[uvv]) uvl.vs[uvv] = mesh->base.vs[vv];
        }
    r = sfb__level_prepare(ctx, &uvl, 1, 0, &uvp);
    sfb__level_free(ctx, &uvl);
    if (r != SFB_SUCCESS) return r;
    memset(&opt, 0, sizeof opt);
    opt.scheme = sfb__scheme_info_of(cfg->scheme)->rules;
    opt.crease_method = mesh->crease_method;
    opt.triangle_rule = mesh->triangle_rule;
    opt.linear = mesh->uv_interp == SFB_UV_LINEAR;
    memset(&dummy, 0, sizeof dummy);
    r = sfb__refine(ctx, &uvp, &opt, cfg->refine_level, &s->uv_top, &s->tables[SFB_TABLE_UV], NULL, 0.8f, 1.0f);
    /* kept for tessellated UVs (SFB_TESS_UVS builds their patch table from it when asked) */
    if (r == SFB_SUCCESS && (cfg->flags & SFB_REFINE_PATCHES)) { s->uv_base = uvp; memset(&uvp, 0, sizeof uvp); }
    sfb__level_free(ctx, &uvp);
    if (r != SFB_SUCCESS) return r;
    s->built[SFB_TABLE_UV] = 1;
    s->has_uvs = 1;
    s->base_uv_count = mesh->uv_count;
    return SFB_SUCCESS;
}

/* Whether tessellated UVs are the limit of the UV layout (its own patch table,
 * sfb__surface_uv_patches), or follow each face linearly: SFB_UV_LINEAR, and the schemes marked
 * SFB__SCHEME_LINEAR_UVS or without a patch builder. */
int sfb__surface_smooth_uvs(const sfb_surface *s) {
    const sfb__scheme_info *si = sfb__scheme_info_of(s->config.scheme);
    return s->uv_interp != SFB_UV_LINEAR && si && si->build_patches && !(si->caps & SFB__SCHEME_LINEAR_UVS);
}

/* The patch table of the base UV layout (its vertices the UV values, z = 0) by the scheme's own
 * builder, for tessellated UVs (tess.c); its parametric faces are the surface's.
 * A layout that is not a manifold (a UV value shared by faces that do not form one fan, as
 * placeholder UVs are: OpenSubdiv's car has 4 UV values for 1575 faces) is sharpened there like
 * any non-manifold vertex, and every face beside such a vertex is irregular: isolating them to
 * the surface's level costs seconds and gigabytes for a label, not a layout. Such a layout is
 * isolated one level only; end caps approximate it near its irregular features. */
sfb_result sfb__surface_uv_patches(const sfb_surface *s, sfb__patch_table *upt) {
    sfb_context *ctx = s->ctx;
    const sfb__scheme_info *si = sfb__scheme_info_of(s->config.scheme);
    sfb__refine_options opt;
    sfb_surface_config ucfg;
    float *P;
    sfb_result r;
    int i;
    memset(upt, 0, sizeof *upt);
    if (!si || !si->build_patches || !s->uv_base.fv)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "tessellated UVs: the surface has no UV layout to evaluate");
    memset(&opt, 0, sizeof opt);
    opt.scheme = si->rules;
    opt.crease_method = s->crease_method;
    opt.triangle_rule = s->triangle_rule;
    P = (float *)sfb__alloc(ctx, ((size_t)s->uv_base.nv + 1) * 3 * sizeof(float));
    if (!P) return sfb__oom(ctx, "tessellated UVs");
    for (i = 0; i < s->uv_base.nv; ++i) {
        P[3 * i] = s->base_uvs[2 * i];
        P[3 * i + 1] = s->base_uvs[2 * i + 1];
        P[3 * i + 2] = 0.0f;
    }
    ucfg = s->config;
    for (i = 0; i < s->uv_base.nv; ++i)
        if (s->uv_base.vtag[i] & SFB__TAG_NONMANIFOLD) break;
    if (i < s->uv_base.nv) {
        ucfg.isolation_level = 1;
        sfb__log(ctx, SFB_LOG_INFO, "tessellated UVs: the UV layout is not a manifold (UV %d): isolated one level", i);
    }
    r = si->build_patches(ctx, &s->uv_base, &opt, &ucfg, P, upt);
    sfb__free(ctx, P);
    if (r == SFB_SUCCESS && upt->nptex != s->patches.nptex) {
        r = sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellated UVs: the UV layout has %d parametric faces, the surface %d",
                       upt->nptex, s->patches.nptex);
        sfb__patch_table_free(ctx, upt);
    }
    return r;
}

/* Hands the built tables (stencils, shading, patches) to the context's backend once (device
 * upload); failures come back here. */
static sfb_result sfb__surface_upload(sfb_surface *s) {
    sfb_context *ctx = s->ctx;
    sfb_result r;
    if (ctx->backend && ctx->backend->upload_stencils) {
        int t;
        s->uploaded_by = ctx->backend;
        for (t = 0; t < SFB_TABLE_COUNT_; ++t) {
            if (!s->built[t] || s->tables[t].rows == 0) continue;
            r = ctx->backend->upload_stencils(ctx->backend_state, &s->tables[t], &s->backend_tables[t]);
            if (r != SFB_SUCCESS) return r;
        }
        if (s->shading) {
            sfb__shading *sh = s->shading;
            const sfb__stencils *st[5];
            st[0] = &sh->npos; st[1] = &sh->ns; st[2] = &sh->lim[0]; st[3] = &sh->lim[1]; st[4] = &sh->lim[2];
            for (t = 0; t < 5; ++t) {
                if (st[t]->rows == 0) continue;
                r = ctx->backend->upload_stencils(ctx->backend_state, st[t], &sh->handles[t]);
                if (r != SFB_SUCCESS) return r;
            }
        }
    }
    if (s->has_patches && ctx->backend && ctx->backend->upload_patches) {
        s->uploaded_by = ctx->backend;
        r = ctx->backend->upload_patches(ctx->backend_state, &s->patches, &s->backend_patches);
        if (r == SFB_SUCCESS && s->patches.normal_field)
            r = ctx->backend->upload_patches(ctx->backend_state, s->patches.normal_field, &s->backend_normal_field);
        if (r != SFB_SUCCESS) return r;
    }
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_surface_create(sfb_context *ctx, const sfb_mesh *mesh, const sfb_surface_config *cfg, sfb_surface **out) {
    sfb_surface *s;
    sfb_result r;
    int oom = 0;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!mesh || !cfg || !out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_create: NULL argument");
    *out = NULL;
    if ((r = sfb__surface_check(ctx, mesh, cfg)) != SFB_SUCCESS) return r;
    s = (sfb_surface *)sfb__calloc(ctx, 1, sizeof *s);
    if (!s) return sfb__oom(ctx, "surface");
    s->ctx = ctx;
    s->serial = ++ctx->surfaces_made;
    s->config = *cfg;
    s->boundary = mesh->boundary; s->crease_method = mesh->crease_method;
    s->triangle_rule = mesh->triangle_rule; s->uv_interp = mesh->uv_interp;
    s->base_vertex_count = mesh->base.nv;
    s->base_face_count = mesh->base.nf;
    s->base_positions = (float *)sfb__alloc(ctx, (size_t)mesh->base.nv * 3 * sizeof(float) + 1);
    if (!s->base_positions) { oom = 1; goto fail; }
    memcpy(s->base_positions, mesh->positions, (size_t)mesh->base.nv * 3 * sizeof(float));
    if ((r = sfb__surface_build_vertex(s, mesh, cfg)) != SFB_SUCCESS) goto fail;
    if ((cfg->flags & SFB_REFINE_UVS) && mesh->uv_count > 0) {
        if ((r = sfb__surface_build_uvs(s, mesh, cfg)) != SFB_SUCCESS) goto fail;
        s->base_uvs = (float *)sfb__alloc(ctx, (size_t)mesh->uv_count * 2 * sizeof(float));
        if (!s->base_uvs) { oom = 1; goto fail; }
        memcpy(s->base_uvs, mesh->uvs, (size_t)mesh->uv_count * 2 * sizeof(float));
    }
    if ((r = sfb__progress(ctx, 1.0f, "refine")) != SFB_SUCCESS) goto fail;
    if ((r = sfb__surface_upload(s)) != SFB_SUCCESS) goto fail;
    *out = s;
    return SFB_SUCCESS;
fail:
    /* the one cleanup path: everything s holds; an allocation failure is reported after it (the
     * message gives the bytes still in use) */
    sfb_surface_destroy(s);
    return oom ? sfb__oom(ctx, "surface") : r;
}

SFB_API int sfb_surface_param_face_count(const sfb_surface *s) { return s && s->has_patches ? s->patches.nptex : 0; }

SFB_API sfb_result sfb_surface_param_faces(const sfb_surface *s, int base_face, int *first, int *count) {
    if (!s || !first || !count) return SFB_INVALID_ARGS;
    if (!s->has_patches) return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the surface has no patch table (SFB_REFINE_PATCHES)");
    if (base_face < 0 || !s->patches.face_ptex || base_face >= s->base_face_count)
        return sfb__error(s->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_FACE, base_face, "base face %d is out of range (0..%d)", base_face, s->base_face_count - 1);
    *first = s->patches.face_ptex[base_face];
    *count = s->patches.face_ptex[base_face + 1] - *first;
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_surface_param_face_base(const sfb_surface *s, int pf, int *base_face, int *sub_face) {
    if (!s || !base_face || !sub_face) return SFB_INVALID_ARGS;
    if (!s->has_patches) return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the surface has no patch table (SFB_REFINE_PATCHES)");
    if (pf < 0 || pf >= s->patches.nptex)
        return sfb__error(s->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_FACE, pf, "parametric face %d is out of range (0..%d)", pf, s->patches.nptex - 1);
    *base_face = s->patches.ptex_face[pf];
    *sub_face = s->patches.ptex_corner[pf];
    return SFB_SUCCESS;
}

/* The memory of a patch table and its points, its normal field's included. */
static size_t sfb__patch_table_bytes(const sfb__patch_table *pt) {
    return (size_t)pt->npatch * (4 * sizeof(int)) + (size_t)pt->ncv * sizeof(int) + (size_t)pt->nptex * 3 * sizeof(int) +
           (size_t)pt->nnodes * 4 * sizeof(int) + (size_t)pt->npoints * 3 * sizeof(float) +
           (pt->pcorner ? (size_t)pt->npatch * 4 * sizeof(unsigned) : 0) + (pt->normal_field ? sfb__patch_table_bytes(pt->normal_field) : 0);
}

SFB_API sfb_result sfb_surface_patch_info(const sfb_surface *s, sfb_patch_info *o) {
    const sfb__patch_table *pt;
    if (!s || !o) return SFB_INVALID_ARGS;
    memset(o, 0, sizeof *o);
    if (!s->has_patches) return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the surface has no patch table (SFB_REFINE_PATCHES)");
    pt = &s->patches;
    o->param_faces = pt->nptex;
    o->patches = pt->npatch;
    o->bspline = pt->counts[SFB__PATCH_BSPLINE];
    o->bezier = pt->counts[SFB__PATCH_BEZTRI];
    o->stam = pt->counts[SFB__PATCH_STAM] + pt->counts[SFB__PATCH_STAM_LOOP];
    o->end_caps = pt->counts[SFB__PATCH_ENDCAP] + pt->counts[SFB__PATCH_ENDCAP_TRI];
    o->manifold = pt->counts[SFB__PATCH_MANIFOLD4];
    o->max_depth = pt->max_depth;
    o->points = pt->npoints;
    o->domain_sides = pt->domain == SFB__DOMAIN_TRI ? 3 : 4;
    o->bytes = sfb__patch_table_bytes(pt);
    return SFB_SUCCESS;
}

/* What is wrong with location l: 0 nothing, 1 its face is out of range, 2 (u,v) is outside
 * [0,1]^2, 3 outside the triangle u + v <= 1, 4 its face is a hole (holes are whole parametric
 * faces, since a hole is a base face: the root says it). */
static int sfb__location_fault(const sfb_surface *s, const sfb_location *l) {
    if (l->face < 0 || l->face >= s->patches.nptex) return 1;
    if (!(l->u >= 0.0f && l->u <= 1.0f && l->v >= 0.0f && l->v <= 1.0f)) return 2;
    if (s->patches.domain == SFB__DOMAIN_TRI && (double)l->u + (double)l->v > 1.0) return 3;
    if (s->patches.ptex_root[l->face] == -1) return 4;
    return 0;
}

/* The location check of sfb_surface_eval in blocks over the backend's threads: block b's first
 * faulty location (or -1) into first_bad[b]. */
#define SFB__EVAL_CHECK_BLOCKS 64
#define SFB__EVAL_CHECK_PARALLEL 131072 /* locations: from this many on the check goes to the threads */
typedef struct sfb__eval_check_job {
    const sfb_surface *s;
    const sfb_location *loc;
    int count, block;
    int first_bad[SFB__EVAL_CHECK_BLOCKS];
} sfb__eval_check_job;

static void sfb__eval_check_blocks(void *arg, int a, int b) {
    sfb__eval_check_job *J = (sfb__eval_check_job *)arg;
    int k, q;
    for (k = a; k < b; ++k) {
        const int end = (int)((long long)(k + 1) * J->block < J->count ? (long long)(k + 1) * J->block : J->count);
        J->first_bad[k] = -1;
        for (q = k * J->block; q < end; ++q)
            if (sfb__location_fault(J->s, &J->loc[q])) { J->first_bad[k] = q; break; }
    }
}

SFB_API sfb_result sfb_surface_eval(const sfb_surface *s, const sfb_location *loc, int count, const sfb_eval_output *out) {
    sfb_context *ctx;
    int q = -1, fault = 0;
    if (!s) return SFB_INVALID_ARGS;
    ctx = s->ctx;
    if (!s->has_patches) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_eval: the surface has no patch table (create it with SFB_REFINE_PATCHES)");
    if (count < 0 || (count > 0 && (!loc || !out)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_eval: %s", count < 0 ? "negative count" : "NULL locations or outputs");
    /* every location is checked before anything is written; the first faulty one is reported */
    if (count >= SFB__EVAL_CHECK_PARALLEL) {
        sfb__eval_check_job J;
        int k;
        J.s = s; J.loc = loc; J.count = count;
        J.block = (count + SFB__EVAL_CHECK_BLOCKS - 1) / SFB__EVAL_CHECK_BLOCKS;
        sfb__parallel(ctx, sfb__eval_check_blocks, &J, 0, SFB__EVAL_CHECK_BLOCKS);
        for (k = 0; k < SFB__EVAL_CHECK_BLOCKS && q < 0; ++k) q = J.first_bad[k];
        if (q >= 0) fault = sfb__location_fault(s, &loc[q]);
    } else {
        for (q = 0; q < count && !(fault = sfb__location_fault(s, &loc[q])); ++q) {}
    }
    if (fault) {
        const sfb_location *l = &loc[q];
        if (fault == 1)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, q, "location %d: parametric face %d is out of range (0..%d)", q, l->face,
                              s->patches.nptex - 1);
        if (fault == 2)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, q, "location %d: (u,v) = (%g,%g) is outside [0,1]^2", q, (double)l->u,
                              (double)l->v);
        if (fault == 3)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, q, "location %d: (u,v) = (%g,%g) is outside the triangle u + v <= 1", q,
                              (double)l->u, (double)l->v);
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, q, "location %d: parametric face %d is a hole", q, l->face);
    }
    return sfb__surface_eval_unchecked(s, loc, count, out);
}

/* One of the surface's patch tables (`handle`: its upload) on the context's backend, or on ref
 * when the backend lacks eval_patches. */
static sfb_result sfb__surface_eval_table(const sfb_surface *s, const sfb__patch_table *pt, void *handle, const sfb_location *loc,
                                          int count, const sfb_eval_output *out) {
    sfb_context *ctx = s->ctx;
    const sfb__backend_vtable *be = ctx->backend;
    if (!be || !be->eval_patches) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks eval_patches; using ref", be ? be->name : "none");
        return sfb__ref_eval_patches(NULL, pt, NULL, loc, 0, count, out);
    }
    return be->eval_patches(ctx->backend_state, pt, s->uploaded_by == be ? handle : NULL, loc, 0, count, out);
}

/* With a normal field (PN triangles), the normals are that field's values normalised, in
 * double (a zero vector stays zero), and the patches give the rest. */
sfb_result sfb__surface_eval_unchecked(const sfb_surface *s, const sfb_location *loc, int count, const sfb_eval_output *out) {
    const sfb__patch_table *nf = s->patches.normal_field;
    sfb_eval_output rest;
    sfb_result r;
    int q;
    if (count == 0) return SFB_SUCCESS;
    if (!nf || !out->normal) return sfb__surface_eval_table(s, &s->patches, s->backend_patches, loc, count, out);
    memset(&rest, 0, sizeof rest);
    rest.position = out->normal;
    if ((r = sfb__surface_eval_table(s, nf, s->backend_normal_field, loc, count, &rest)) != SFB_SUCCESS) return r;
    for (q = 0; q < count; ++q) {
        float *n = out->normal + 3 * (size_t)q;
        const double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (len > 0.0) {
            n[0] = (float)(n[0] / len); n[1] = (float)(n[1] / len); n[2] = (float)(n[2] / len);
        }
    }
    rest = *out;
    rest.normal = NULL;
    if (!rest.position && !rest.du && !rest.dv && !rest.duu && !rest.duv && !rest.dvv) return SFB_SUCCESS;
    return sfb__surface_eval_table(s, &s->patches, s->backend_patches, loc, count, &rest);
}

SFB_API sfb_result sfb_surface_stencil_info(const sfb_surface *s, sfb_table t, sfb_stencil_info *out) {
    if (!s || !out || (int)t < 0 || t >= SFB_TABLE_COUNT_ || !s->built[t]) return SFB_INVALID_ARGS;
    out->rows = s->tables[t].rows;
    out->sources = s->tables[t].sources;
    out->entries = (int)s->tables[t].entries;
    return SFB_SUCCESS;
}

static int sfb__desc_ok(sfb_buffer_desc d) { return d.offset >= 0 && d.length >= 1 && d.length <= 16 && d.stride >= d.length; }

/* The checks both eval entry points share: a built table and two compatible views. */
static sfb_result sfb__eval_args(const sfb_surface *s, sfb_table t, int have_buffers, sfb_buffer_desc sd, sfb_buffer_desc dd,
                                 const char *what) {
    if ((int)t < 0 || t >= SFB_TABLE_COUNT_ || !s->built[t])
        return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "stencil table %d was not built for this surface", (int)t);
    if (!have_buffers || !sfb__desc_ok(sd) || !sfb__desc_ok(dd) || sd.length != dd.length)
        return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "invalid %s or buffer descriptors for stencil evaluation", what);
    return SFB_SUCCESS;
}

/* Rows [0, rows) of table `t` on the context's backend (`handle`: its upload of t), or on ref
 * when the backend lacks eval_stencils. Arguments already checked. */
sfb_result sfb__surface_apply(const sfb_surface *s, const sfb__stencils *t, void *handle, int rows, const float *src,
                                     sfb_buffer_desc sd, float *dst, sfb_buffer_desc dd) {
    sfb_context *ctx = s->ctx;
    const sfb__backend_vtable *be = ctx->backend;
    if (!be || !be->eval_stencils) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks eval_stencils; using ref", be ? be->name : "none");
        return sfb__ref_eval_stencils(NULL, t, NULL, 0, rows, src, sd, dst, dd);
    }
    if (rows <= 0) return SFB_SUCCESS;
    return be->eval_stencils(ctx->backend_state, t, s->uploaded_by == be ? handle : NULL, 0, rows, src, sd, dst, dd);
}

SFB_API sfb_result sfb_surface_eval_stencils(const sfb_surface *s, sfb_table t, const float *src, sfb_buffer_desc sd,
                                             float *dst, sfb_buffer_desc dd) {
    sfb_result r;
    if (!s) return SFB_INVALID_ARGS;
    if ((r = sfb__eval_args(s, t, src && dst, sd, dd, "buffers")) != SFB_SUCCESS) return r;
    return sfb__surface_apply(s, &s->tables[t], s->backend_tables[t], s->tables[t].rows, src, sd, dst, dd);
}

SFB_API sfb_result sfb_surface_eval_stencils_gl(const sfb_surface *s, sfb_table t, unsigned int src_buffer, sfb_buffer_desc sd,
                                                unsigned int dst_buffer, sfb_buffer_desc dd) {
    sfb_context *ctx;
    const sfb__backend_vtable *be;
    sfb_result r;
    if (!s) return SFB_INVALID_ARGS;
    ctx = s->ctx;
    if ((r = sfb__eval_args(s, t, src_buffer && dst_buffer, sd, dd, "GL buffers")) != SFB_SUCCESS) return r;
    be = ctx->backend;
    if (!be || !be->eval_stencils_gl)
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_eval_stencils_gl needs the gl backend on the host's context (gl_use_current_context); this context runs %s",
                          be ? be->name : "no backend");
    if (s->tables[t].rows == 0) return SFB_SUCCESS;
    return be->eval_stencils_gl(ctx->backend_state, &s->tables[t], s->uploaded_by == be ? s->backend_tables[t] : NULL,
                                src_buffer, sd, dst_buffer, dd);
}

SFB_API void sfb_mesh_data_free(sfb_mesh_data *d) {
    sfb_context *ctx;
    if (!d || !d->ctx_) return;
    ctx = d->ctx_;
    sfb__free(ctx, d->positions); sfb__free(ctx, d->limit_positions); sfb__free(ctx, d->tangents_u);
    sfb__free(ctx, d->tangents_v); sfb__free(ctx, d->normals); sfb__free(ctx, d->uvs);
    sfb__free(ctx, d->face_sizes); sfb__free(ctx, d->face_vertices); sfb__free(ctx, d->face_uvs);
    sfb__free(ctx, d->crease_vertices); sfb__free(ctx, d->crease_sharpness);
    sfb__free(ctx, d->corner_vertices); sfb__free(ctx, d->corner_sharpness); sfb__free(ctx, d->holes);
    sfb__free(ctx, d->blend_weights); sfb__free(ctx, d->limit_normals); sfb__free(ctx, d->subdivided_normals);
    sfb__free(ctx, d->vertex_origin);
    memset(d, 0, sizeof *d);
}


SFB_API sfb_result sfb_surface_refine(const sfb_surface *s, sfb_mesh_data *out) {
    if (!s) return SFB_INVALID_ARGS;
    return sfb_surface_refine_positions(s, s->base_positions, s->base_vertex_count, out);
}

SFB_API sfb_result sfb_surface_refine_positions(const sfb_surface *s, const float *base, int base_count, sfb_mesh_data *o) {
    return sfb__refine_output(s, base, base_count, 1, o);
}

/* The refined mesh; with want_limit the limit tables too (when built). */
sfb_result sfb__refine_output(const sfb_surface *s, const float *base, int base_count, int want_limit, sfb_mesh_data *o) {
    sfb_context *ctx;
    const sfb__level *l;
    sfb_buffer_desc d3 = {0, 3, 3}, d2 = {0, 2, 2};
    sfb_result r;
    int i, e, v, f, nv;
    if (!s || !o) return SFB_INVALID_ARGS;
    memset(o, 0, sizeof *o);
    ctx = s->ctx;
    if (!base || base_count != s->base_vertex_count)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "expected %d base positions, got %d", s->base_vertex_count, base_count);
    l = &s->top;
    nv = l->nv;
    o->ctx_ = ctx;
    o->vertex_count = nv;
    o->face_count = l->nf;
    o->face_vertex_count = l->nfv;
    o->boundary = s->boundary; o->crease_method = s->crease_method;
    o->triangle_rule = s->triangle_rule; o->uv_interp = s->uv_interp;
    o->positions = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
    o->face_sizes = (int *)sfb__alloc(ctx, (size_t)l->nf * sizeof(int) + 1);
    o->face_vertices = (int *)sfb__alloc(ctx, (size_t)l->nfv * sizeof(int) + 1);
    if (!o->positions || !o->face_sizes || !o->face_vertices) goto oom;
    r = sfb_surface_eval_stencils(s, SFB_TABLE_VERTEX, base, d3, o->positions, d3);
    if (r != SFB_SUCCESS) { sfb_mesh_data_free(o); return r; }
    if (s->built[SFB_TABLE_LIMIT] && want_limit) {
        o->limit_positions = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
        o->tangents_u = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
        o->tangents_v = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
        o->normals = (float *)sfb__alloc(ctx, (size_t)nv * 3 * sizeof(float) + 1);
        if (!o->limit_positions || !o->tangents_u || !o->tangents_v || !o->normals) goto oom;
        if ((r = sfb_surface_eval_stencils(s, SFB_TABLE_LIMIT, base, d3, o->limit_positions, d3)) != SFB_SUCCESS ||
            (r = sfb_surface_eval_stencils(s, SFB_TABLE_TANGENT_U, base, d3, o->tangents_u, d3)) != SFB_SUCCESS ||
            (r = sfb_surface_eval_stencils(s, SFB_TABLE_TANGENT_V, base, d3, o->tangents_v, d3)) != SFB_SUCCESS) {
            sfb_mesh_data_free(o);
            return r;
        }
        for (v = 0; v < nv; ++v) {
            const float *a = o->tangents_u + 3 * (size_t)v, *b = o->tangents_v + 3 * (size_t)v;
            double n0 = (double)a[1] * b[2] - (double)a[2] * b[1];
            double n1 = (double)a[2] * b[0] - (double)a[0] * b[2];
            double n2 = (double)a[0] * b[1] - (double)a[1] * b[0];
            double len = sqrt(n0 * n0 + n1 * n1 + n2 * n2);
            float *n = o->normals + 3 * (size_t)v;
            /* degenerate tangents (e.g. a corner with collinear edges) give a zero normal */
            if (len > 0.0) { n[0] = (float)(n0 / len); n[1] = (float)(n1 / len); n[2] = (float)(n2 / len); }
            else { n[0] = n[1] = n[2] = 0.0f; }
        }
    }
    for (f = 0; f < l->nf; ++f) o->face_sizes[f] = l->fv_off[f + 1] - l->fv_off[f];
    memcpy(o->face_vertices, l->fv, (size_t)l->nfv * sizeof(int));
    if (s->has_uvs) {
        o->uv_count = s->uv_top.nv;
        o->uvs = (float *)sfb__alloc(ctx, (size_t)o->uv_count * 2 * sizeof(float) + 1);
        o->face_uvs = (int *)sfb__alloc(ctx, (size_t)l->nfv * sizeof(int) + 1);
        if (!o->uvs || !o->face_uvs) goto oom;
        r = sfb_surface_eval_stencils(s, SFB_TABLE_UV, s->base_uvs, d2, o->uvs, d2);
        if (r != SFB_SUCCESS) { sfb_mesh_data_free(o); return r; }
        memcpy(o->face_uvs, s->uv_top.fv, (size_t)l->nfv * sizeof(int));
    }
    /* remaining sharpness: edges with sharpness that are not boundary edges (those are always
     * sharp), vertices with sharpness, hole faces */
    for (e = 0; e < l->ne; ++e) o->crease_count += l->es[e] > 0.0f && !(l->etag[e] & SFB__TAG_BOUNDARY);
    for (v = 0; v < nv; ++v) o->corner_count += l->vs[v] > 0.0f;
    for (f = 0; f < l->nf; ++f) o->hole_count += l->fhole[f] != 0;
    o->crease_vertices = (int *)sfb__alloc(ctx, (size_t)o->crease_count * 2 * sizeof(int) + 1);
    o->crease_sharpness = (float *)sfb__alloc(ctx, (size_t)o->crease_count * sizeof(float) + 1);
    o->corner_vertices = (int *)sfb__alloc(ctx, (size_t)o->corner_count * sizeof(int) + 1);
    o->corner_sharpness = (float *)sfb__alloc(ctx, (size_t)o->corner_count * sizeof(float) + 1);
    o->holes = (int *)sfb__alloc(ctx, (size_t)o->hole_count * sizeof(int) + 1);
    if (!o->crease_vertices || !o->crease_sharpness || !o->corner_vertices || !o->corner_sharpness || !o->holes) goto oom;
    for (i = 0, e = 0; e < l->ne; ++e)
        if (l->es[e] > 0.0f && !(l->etag[e] & SFB__TAG_BOUNDARY)) {
            o->crease_vertices[2 * i] = l->ev[2 * e];
            o->crease_vertices[2 * i + 1] = l->ev[2 * e + 1];
            o->crease_sharpness[i++] = l->es[e];
        }
    for (i = 0, v = 0; v < nv; ++v)
        if (l->vs[v] > 0.0f) { o->corner_vertices[i] = v; o->corner_sharpness[i++] = l->vs[v]; }
    for (i = 0, f = 0; f < l->nf; ++f)
        if (l->fhole[f]) o->holes[i++] = f;
    return SFB_SUCCESS;
oom:
    sfb_mesh_data_free(o);
    return sfb__oom(ctx, "refined mesh output");
}

SFB_API void sfb_mesh_data_desc(const sfb_mesh_data *m, sfb_mesh_desc *d) {
    if (!d) return;
    memset(d, 0, sizeof *d);
    if (!m) return;
    d->vertex_count = m->vertex_count; d->positions = m->positions;
    d->face_count = m->face_count; d->face_sizes = m->face_sizes; d->face_vertices = m->face_vertices;
    d->crease_count = m->crease_count; d->crease_vertices = m->crease_vertices; d->crease_sharpness = m->crease_sharpness;
    d->corner_count = m->corner_count; d->corner_vertices = m->corner_vertices; d->corner_sharpness = m->corner_sharpness;
    d->hole_count = m->hole_count; d->holes = m->holes;
    d->uv_count = m->uv_count; d->uvs = m->uvs; d->face_uvs = m->face_uvs;
    d->boundary = m->boundary; d->crease_method = m->crease_method;
    d->triangle_rule = m->triangle_rule; d->uv_interp = m->uv_interp;
}
#line 1 "src/shade.c"
/* Subdivision shading (seed 001): subdivided normals N_S with crease regions, blend weights b
 * (variants A/B, darts smooth/sharp, semi-sharp re-seeding) and the blended normals
 * N_B = normalize((1 - b^p) N_L + b^p N_S).
 *
 * Everything that depends on topology and sharpness only is compiled here, on the CPU, into
 * flat tables when the surface is created (SFB_REFINE_SHADING):
 *   - the blend weights b of every output vertex (numbers: they depend on no position);
 *   - a stencil table from the normals-level sources (one normal per vertex region) to N_S of
 *     the output vertices, its rows with b > 0 first, so that N_S is computed only there;
 *   - local limit masks (limit position, two tangents) of every output vertex over the refined
 *     vertices: one row per region at split vertices;
 *   - the split of vertices along infinitely sharp creases (one output vertex per region).
 * sfb_surface_shade then runs: refined positions (vertex table), normals-level positions, face
 * normals averaged per region (CPU: one pass over the coarse level's faces), the N_S rows, the
 * limit rows, and the backend's finish_normals kernel.
 *
 * Averaging (sfb_shading_options.averaging): LINEAR, the default, is the above: N_S is one
 * composed table run by the backend. RENORMALIZED and SPHERICAL compute N_S one level at a
 * time instead, because a normalisation (or a spherical mean) between the levels is not linear
 * and cannot be folded into one table: the build keeps one region table per step instead of
 * the composed one (the same region masks the composed table is made of, each over the level
 * below alone; the last step's rows are the output rows, in the composed table's order) and
 * sfb_surface_shade runs them in the core, on the CPU in double, for every backend - each new
 * normal is normalize(sum w_i n_i) (RENORMALIZED) or the weighted spherical mean of the n_i
 * (SPHERICAL: see sfb__shade_spherical_mean). The limit tables and finish_normals still run on
 * the backend. Only the last step is restricted to the rows needed (b > 0, or all with
 * SFB_SHADE_ALL_SUBDIVIDED); the earlier levels are computed in full: the rows of level L-1 a
 * restricted last step reads are the support of its rows (and of the levels below, theirs),
 * different for the two row sets, so restricting would take per-level marks kept at build time
 * for each, while a level has about a quarter of the next one's vertices (Catmull-Clark and
 * Loop quadruple the faces per step): all earlier steps together cost about a third of the last
 * one, and near the extraordinary vertices, where b > 0, most of their rows are in that support
 * anyway. When the normals level is the last level there is no step: the output rows are the
 * face-weighted region means (the composed table) in every mode. Cost: on catmark_car at
 * level 3 on ref, sfb_surface_shade takes about as long with RENORMALIZED as with LINEAR and
 * about 6-8x as long with SPHERICAL (a few iterations per row, an atan2 per entry and
 * iteration where the angle is not small).
 *
 * Choices where the seed is silent (each tested in tests/shade.c):
 *   - Linear averaging by default (the seed's choice, §2.3), normalised once at the end (in
 *     finish_normals) rather than after every level. Renormalising a linear average only
 *     rescales it, so the direction differs from a per-level renormalisation by the small
 *     change of the stencil weights this rescaling makes; in exchange N_S is one linear map of
 *     the normals-level normals, which is what lets it compile to one stencil table run on the
 *     backend. Per-level renormalised and spherical averaging (the original subdivision
 *     shading's) are options, computed in the core (above): they differ from linear by small
 *     angles (tests/shade.c measures them) and cost a CPU pass per level.
 *   - A region is a maximal fan of a vertex's faces not separated by a sharp edge (sharpness
 *     > 0 at that level; boundary edges are sharp). A vertex with fewer than two sharp edges, or
 *     a non-manifold one, has one region.
 *   - A stencil entry that reaches a parent vertex with several regions takes the parent's
 *     region normals of the parent faces the new vertex's region lies in (the parent faces of
 *     the child faces of that region), weighted by how many of those faces each region has.
 *     When the new vertex lies in faces of several parent regions - a semi-sharp edge ran out
 *     of sharpness between the levels, so the child has fewer regions than the parent - this
 *     merges the separated regions' normals in proportion to the faces each contributes. No
 *     face of the new vertex at the parent vertex (cannot happen for Catmull-Clark or Loop
 *     masks): all of the parent's regions equally.
 *   - Output regions split only along infinitely sharp edges; N_S of an output vertex is the
 *     face-count weighted mean of the N_S regions it covers (a semi-sharp edge still sharp at
 *     the last level separates N_S regions but does not split the vertex).
 *   - Weights, re-seeding (seed §3.2): at the weights level b = 1 at every extraordinary vertex
 *     that is not held and at every vertex of its incident faces (its one-ring: edge
 *     neighbours, and for Catmull-Clark the face diagonals too), then b = 0 at every held
 *     vertex. Held: in variant B a vertex with two or more sharp edges at that level (crease or
 *     corner rule, boundary included) or, with sharp darts, a regular dart; in variant A no
 *     vertex is held. After every subdivision step of the weights (the scheme's stencils,
 *     creases included): b = 0 at every held vertex again (its sharpness has not run out); a
 *     vertex released at this step (held before, not now: its semi-sharp edges ran out) that is
 *     extraordinary is seeded as a smooth extraordinary vertex, it and its one-ring set to 1
 *     (Fig. 4 of the seed); and b = 1 at every extraordinary vertex that is not held (the
 *     vertex alone: away from held vertices this changes nothing, since a vertex whose one-ring
 *     is all 1 keeps 1; next to held vertices it keeps the limit value 1 at the extraordinary
 *     point, which the blended field needs to be smooth there).
 *   - Extraordinary: Catmull-Clark an interior vertex whose face count is not 4 or with a
 *     non-quad face, a boundary vertex whose face count is not 2; Loop 6 and 3 with triangles;
 *     non-manifold vertices count as extraordinary. A dart that is extraordinary is
 *     extraordinary whatever the dart option.
 *   - Limit normals of split vertices: at a crease vertex each side uses the crease tangent
 *     and that side's cross tangent (the limit masks of a boundary vertex on that side); at a
 *     corner each region uses the two edges of its first face, as the corner limit masks do. */

typedef struct sfb__regions {
    int *first;   /* nv + 1: first region-vertex of each vertex */
    int *of_vf;   /* per vf entry: region-vertex of that face at that vertex */
    int *faces;   /* per region-vertex: number of faces */
    int total;
} sfb__regions;

static void sfb__regions_free(sfb_context *ctx, sfb__regions *r) {
    sfb__free(ctx, r->first); sfb__free(ctx, r->of_vf); sfb__free(ctx, r->faces);
    memset(r, 0, sizeof *r);
}

/* Regions of every vertex: edges with sharpness > 0 separate them (>= infinite with inf_only). */
static sfb_result sfb__regions_build(sfb_context *ctx, const sfb__level *l, int inf_only, sfb__regions *r) {
    int v, i, nvf = l->vf_off[l->nv];
    memset(r, 0, sizeof *r);
    r->first = (int *)sfb__alloc(ctx, ((size_t)l->nv + 1) * sizeof(int));
    r->of_vf = (int *)sfb__alloc(ctx, ((size_t)nvf + 1) * sizeof(int));
    if (!r->first || !r->of_vf) { sfb__regions_free(ctx, r); return sfb__oom(ctx, "shading regions"); }
    r->total = 0;
    for (v = 0; v < l->nv; ++v) {
        int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0;
        int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0;
        int sharp = 0, reg = 0, interior = nf == ne && !(l->vtag[v] & SFB__TAG_BOUNDARY);
        r->first[v] = r->total;
        if (!(l->vtag[v] & SFB__TAG_NONMANIFOLD) && (nf == ne || nf == ne - 1))
            for (i = 0; i < ne; ++i) {
                float s = l->es[l->ve[e0 + i]];
                sharp += inf_only ? s >= SFB_SHARPNESS_INFINITE : s > 0.0f;
            }
        if (sharp < 2) {
            for (i = 0; i < nf; ++i) r->of_vf[f0 + i] = r->total;
            r->total += 1;
            continue;
        }
        for (i = 0; i < nf; ++i) {
            float s = l->es[l->ve[e0 + i]]; /* edge i precedes face i */
            if (i > 0 && (inf_only ? s >= SFB_SHARPNESS_INFINITE : s > 0.0f)) reg++;
            r->of_vf[f0 + i] = reg;
        }
        if (interior && reg > 0) {
            float s0 = l->es[l->ve[e0]];
            if (!(inf_only ? s0 >= SFB_SHARPNESS_INFINITE : s0 > 0.0f)) {
                /* the fan closes through edge 0: the last run joins the first region */
                for (i = 0; i < nf; ++i)
                    if (r->of_vf[f0 + i] == reg) r->of_vf[f0 + i] = 0;
                reg--;
            }
        }
        for (i = 0; i < nf; ++i) r->of_vf[f0 + i] += r->total;
        r->total += reg + 1;
    }
    r->first[l->nv] = r->total;
    r->faces = (int *)sfb__calloc(ctx, (size_t)r->total + 1, sizeof(int));
    if (!r->faces) { sfb__regions_free(ctx, r); return sfb__oom(ctx, "shading regions"); }
    for (i = 0; i < nvf; ++i) r->faces[r->of_vf[i]]++;
    return SFB_SUCCESS;
}

void sfb__shading_free(sfb_context *ctx, sfb__shading *sh) {
    int t;
    if (!sh) return;
    sfb__level_free(ctx, &sh->nlev);
    sfb__free(ctx, sh->nsrc_of_vf);
    sfb__stencils_free(ctx, &sh->npos);
    sfb__free(ctx, sh->out_origin); sfb__free(ctx, sh->out_fv); sfb__free(ctx, sh->b);
    sfb__free(ctx, sh->ns_idx_w); sfb__free(ctx, sh->ns_idx_all);
    sfb__stencils_free(ctx, &sh->ns);
    for (t = 0; t < 3; ++t) sfb__stencils_free(ctx, &sh->lim[t]);
    if (sh->steps) {
        for (t = 0; t < sh->nsteps; ++t) sfb__stencils_free(ctx, &sh->steps[t]);
        sfb__free(ctx, sh->steps);
    }
    sfb__free(ctx, sh);
}

int sfb__shade_extraordinary(const sfb__level *l, int v, int loop) {
    int f0 = l->vf_off[v], nf = l->vf_off[v + 1] - f0, i, reg;
    if (l->ve_off[v + 1] == l->ve_off[v]) return 0; /* bare vertex */
    if (l->vtag[v] & SFB__TAG_NONMANIFOLD) return 1;
    reg = (l->vtag[v] & SFB__TAG_BOUNDARY) ? (loop ? 3 : 2) : (loop ? 6 : 4);
    if (nf != reg) return 1;
    for (i = 0; i < nf; ++i) {
        int f = l->vf[f0 + i];
        if (l->fv_off[f + 1] - l->fv_off[f] != (loop ? 3 : 4)) return 1;
    }
    return 0;
}

int sfb__shade_held(const sfb__level *l, int v, int loop, int variant, int darts) {
    int rule = l->vrule[v];
    if (variant != SFB_SHADE_VARIANT_B) return 0;
    if (rule == SFB__RULE_CREASE || rule == SFB__RULE_CORNER) return 1;
    return darts == SFB_SHADE_DARTS_SHARP && rule == SFB__RULE_DART && !sfb__shade_extraordinary(l, v, loop);
}

/* The seeding of the blend weights on level l (see the top of this file): b = 1 at every
 * extraordinary vertex that is not held, and at its one-ring when `ring` says so (all of them
 * with ring == NULL; else those with ring[v] set); then b = 0 at every held vertex. */
static void sfb__shade_seed(const sfb__level *l, double *b, int loop, int variant, int darts, const unsigned char *ring) {
    int v, i, j;
    for (v = 0; v < l->nv; ++v) {
        if (!sfb__shade_extraordinary(l, v, loop) || sfb__shade_held(l, v, loop, variant, darts)) continue;
        b[v] = 1.0;
        if (ring && !ring[v]) continue;
        for (i = l->vf_off[v]; i < l->vf_off[v + 1]; ++i) {
            int f = l->vf[i];
            for (j = l->fv_off[f]; j < l->fv_off[f + 1]; ++j) b[l->fv[j]] = 1.0;
        }
    }
    for (v = 0; v < l->nv; ++v)
        if (sfb__shade_held(l, v, loop, variant, darts)) b[v] = 0.0;
}

/* Parent face of every child face of one step. */
static int *sfb__shade_parent_faces(sfb_context *ctx, const sfb__level *p, const sfb__level *c, int loop) {
    int *pf = (int *)sfb__alloc(ctx, ((size_t)c->nf + 1) * sizeof(int));
    int f, i;
    if (!pf) return NULL;
    if (loop) {
        for (f = 0; f < c->nf; ++f) pf[f] = f / 4;
    } else {
        for (f = 0; f < p->nf; ++f)
            for (i = p->fv_off[f]; i < p->fv_off[f + 1]; ++i) pf[i] = f; /* child faces of f: its face-vertex slots */
    }
    return pf;
}

/* Scratch of the region masks. */
typedef struct sfb__shade_scratch {
    int *fset, nfset;          /* parent faces of the child region being built */
    double *cnt;               /* per region of the parent vertex */
} sfb__shade_scratch;

/* Adds scale * (the step's mask of child vertex cv, restricted to its region creg - a
 * region-vertex of cr, or -1 for all of cv's faces) over the parent's region-vertices. */
static int sfb__shade_region_mask(sfb_context *ctx, const sfb__level *p, const sfb__regions *pr, const sfb__level *c,
                                  const sfb__regions *cr, const int *cparent, const sfb__stencils *T, int cv, int creg,
                                  double scale, sfb__mask *m, sfb__shade_scratch *sc) {
    int i, j, k, n = T->sizes[cv], o = T->offsets[cv];
    sc->nfset = 0;
    for (i = c->vf_off[cv]; i < c->vf_off[cv + 1]; ++i) {
        int pf;
        if (creg >= 0 && cr->of_vf[i] != creg) continue;
        pf = cparent[c->vf[i]];
        for (j = 0; j < sc->nfset && sc->fset[j] != pf; ++j) {}
        if (j == sc->nfset) sc->fset[sc->nfset++] = pf;
    }
    for (k = 0; k < n; ++k) {
        int pj = T->indices[o + k], nr = pr->first[pj + 1] - pr->first[pj];
        double w = (double)T->weights[o + k] * scale, tot = 0.0;
        if (!sfb__mask_grow(ctx, m, nr)) return 0;
        if (nr == 1) { SFB__MASK_ADD(m, pr->first[pj], w); continue; }
        for (i = 0; i < nr; ++i) sc->cnt[i] = 0.0;
        for (i = p->vf_off[pj]; i < p->vf_off[pj + 1]; ++i)
            for (j = 0; j < sc->nfset; ++j)
                if (sc->fset[j] == p->vf[i]) { sc->cnt[pr->of_vf[i] - pr->first[pj]] += 1.0; tot += 1.0; break; }
        for (i = 0; i < nr; ++i) {
            double f = tot > 0.0 ? sc->cnt[i] / tot : 1.0 / nr;
            if (f != 0.0) SFB__MASK_ADD(m, pr->first[pj] + i, w * f);
        }
    }
    return 1;
}

/* Rows of the identity over n sources. */
static int sfb__shade_identity(sfb_context *ctx, sfb__rows *r, int n) {
    int i;
    memset(r, 0, sizeof *r);
    r->rows = n;
    r->off = (size_t *)sfb__alloc(ctx, ((size_t)n + 1) * sizeof(size_t));
    if (!r->off || !sfb__rows_reserve(ctx, r, (size_t)n + 1)) return 0;
    for (i = 0; i < n; ++i) { r->off[i] = (size_t)i; r->idx[i] = i; r->w[i] = 1.0; }
    r->off[n] = (size_t)n;
    r->n = (size_t)n;
    return 1;
}

/* Composed rows of level k+1 from those of level k through the step's stencils (positions). */
static int sfb__shade_compose_step(sfb_context *ctx, sfb__accum *A, const sfb__rows *prow, const sfb__stencils *T,
                                   sfb__mask *m, sfb__rows *out) {
    int cv, k;
    memset(out, 0, sizeof *out);
    out->rows = T->rows;
    out->off = (size_t *)sfb__alloc(ctx, ((size_t)T->rows + 1) * sizeof(size_t));
    if (!out->off) return 0;
    out->off[0] = 0;
    for (cv = 0; cv < T->rows; ++cv) {
        m->n = 0;
        if (!sfb__mask_grow(ctx, m, T->sizes[cv])) return 0;
        for (k = 0; k < T->sizes[cv]; ++k) SFB__MASK_ADD(m, T->indices[T->offsets[cv] + k], (double)T->weights[T->offsets[cv] + k]);
        if (!sfb__compose_row(ctx, A, prow, m, out, cv)) return 0;
    }
    return 1;
}

static sfb_result sfb__shade_level_arg(sfb_context *ctx, int given, int level, const char *what, int *out) {
    int l = given == 0 ? 1 : given == SFB_SHADE_LEVEL_CONTROL ? 0 : given;
    if (given < SFB_SHADE_LEVEL_CONTROL || given > SFB_MAX_LEVEL)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                          "shading %s level %d is outside %d..%d (0 = default 1, SFB_SHADE_LEVEL_CONTROL = the control mesh)",
                          what, given, SFB_SHADE_LEVEL_CONTROL, SFB_MAX_LEVEL);
    *out = l < level ? l : level; /* a start level above the refinement level starts at the last level */
    return SFB_SUCCESS;
}

/* The working state of sfb__shading_build: the levels one step apart with their local
 * stencils, regions and parent faces, the output regions, and the scratch of composing rows. */
typedef struct sfb__shade_build {
    sfb_context *ctx;
    const sfb__level *prep;
    const sfb__refine_options *opt;
    const sfb_shading_options *o;
    sfb__shading *sh;
    int L, Ln, Lw;         /* last, normals and weights level */
    int loop, per_level;   /* Loop scheme; N_S one level at a time (averaging not linear) */
    sfb__level *lev;       /* L + 1 levels: lev[0] borrowed (prep), lev[Ln] moved to sh->nlev */
    sfb__stencils *T;      /* L + 1: T[k] the step from level k to k + 1 */
    sfb__regions *reg;     /* L + 1: regions (sharpness > 0) from the normals level up */
    sfb__regions outreg;   /* regions of the last level split by infinitely sharp edges only */
    int **parent;          /* L + 1: parent face of every face of level k (k >= 1) */
    const sfb__level *top; /* the last level */
    sfb__refine_kept *kept;    /* the vertex refinement's levels and steps, taken over (or NULL) */
    const sfb__level *kept_top; /* with kept: the vertex refinement's last level, lev[L] borrows it */
    sfb__rows prow, crow;
    sfb__accum A;
    sfb__mask m, mm[3];
    sfb__shade_scratch sc;
    double *bw, *bn;       /* blend weights of the current and the next level */
    int *order;            /* output vertices in N_S row order (b > 0 first) */
} sfb__shade_build;

/* Frees the working state of sfb__shading_build (not the shading it builds). */
static void sfb__shade_build_free(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    int k, t, L = B->L;
    if (B->lev) {
        if (B->kept_top) memset(&B->lev[L], 0, sizeof B->lev[L]); /* borrowed */
        for (k = 1; k <= L; ++k) sfb__level_free(ctx, &B->lev[k]);
        sfb__free(ctx, B->lev);
    }
    if (B->T) { for (k = 0; k <= L; ++k) sfb__stencils_free(ctx, &B->T[k]); sfb__free(ctx, B->T); }
    if (B->reg) { for (k = 0; k <= L; ++k) sfb__regions_free(ctx, &B->reg[k]); sfb__free(ctx, B->reg); }
    if (B->parent) { for (k = 0; k <= L; ++k) sfb__free(ctx, B->parent[k]); sfb__free(ctx, B->parent); }
    sfb__regions_free(ctx, &B->outreg);
    sfb__rows_free(ctx, &B->prow); sfb__rows_free(ctx, &B->crow);
    sfb__free(ctx, B->A.acc); sfb__free(ctx, B->A.mark); sfb__free(ctx, B->A.touched);
    sfb__free(ctx, B->m.idx); sfb__free(ctx, B->m.w);
    for (t = 0; t < 3; ++t) { sfb__free(ctx, B->mm[t].idx); sfb__free(ctx, B->mm[t].w); }
    sfb__free(ctx, B->sc.fset); sfb__free(ctx, B->sc.cnt);
    sfb__free(ctx, B->bw); sfb__free(ctx, B->bn); sfb__free(ctx, B->order);
}

/* Checks the shading options against refinement level L; the normals and weights levels they
 * give into *Ln and *Lw. */
static sfb_result sfb__shade_check_options(sfb_context *ctx, const sfb_shading_options *o, int L, int *Ln, int *Lw) {
    sfb_result r;
    if ((r = sfb__shade_level_arg(ctx, o->normals_level, L, "normals", Ln)) != SFB_SUCCESS) return r;
    if ((r = sfb__shade_level_arg(ctx, o->weights_level, L, "weights", Lw)) != SFB_SUCCESS) return r;
    if (o->variant != SFB_SHADE_VARIANT_A && o->variant != SFB_SHADE_VARIANT_B)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "shading variant %d is not SFB_SHADE_VARIANT_A or _B", o->variant);
    if (o->darts != SFB_SHADE_DARTS_SMOOTH && o->darts != SFB_SHADE_DARTS_SHARP)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "shading darts option %d is not SFB_SHADE_DARTS_SMOOTH or _SHARP", o->darts);
    if (o->averaging != SFB_SHADE_AVERAGE_LINEAR && o->averaging != SFB_SHADE_AVERAGE_RENORMALIZED && o->averaging != SFB_SHADE_AVERAGE_SPHERICAL)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                          "shading averaging %d is not SFB_SHADE_AVERAGE_LINEAR, _RENORMALIZED or _SPHERICAL", o->averaging);
    return SFB_SUCCESS;
}

/* Allocates the shading and the per-level arrays, then the levels one step at a time with each
 * step's local stencils and parent faces, the region-mask scratch, the regions from the
 * normals level up and the output regions of the last level. */
static sfb_result sfb__shade_build_levels(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    const sfb_shading_options *o = B->o;
    sfb__shading *sh;
    sfb__level *lev;
    sfb_result r;
    int L = B->L, k, v, maxv = 1;
    sh = B->sh = (sfb__shading *)sfb__calloc(ctx, 1, sizeof *sh);
    lev = B->lev = (sfb__level *)sfb__calloc(ctx, (size_t)L + 1, sizeof *lev);
    B->T = (sfb__stencils *)sfb__calloc(ctx, (size_t)L + 1, sizeof *B->T);
    B->reg = (sfb__regions *)sfb__calloc(ctx, (size_t)L + 1, sizeof *B->reg);
    B->parent = (int **)sfb__calloc(ctx, (size_t)L + 1, sizeof *B->parent);
    if (!sh || !lev || !B->T || !B->reg || !B->parent) {
        if (B->kept) sfb__refine_kept_free(ctx, B->kept, L);
        B->kept_top = NULL;
        return sfb__oom(ctx, "shading tables");
    }
    sh->normals_level = B->Ln; sh->weights_level = B->Lw; sh->level = L; sh->variant = o->variant; sh->darts = o->darts;
    sh->averaging = o->averaging;
    B->per_level = o->averaging != SFB_SHADE_AVERAGE_LINEAR && L > B->Ln;

    /* the levels, one step at a time, with each step's local stencils: those the vertex
     * refinement made (taken over; its last level borrowed), or refined here */
    lev[0] = *B->prep; /* borrowed */
    if (B->kept) {
        for (k = 0; k < L; ++k) {
            if (k > 0) lev[k] = B->kept->lev[k];
            B->T[k] = B->kept->T[k];
            memset(&B->kept->lev[k], 0, sizeof B->kept->lev[k]);
            memset(&B->kept->T[k], 0, sizeof B->kept->T[k]);
        }
        lev[L] = *B->kept_top;
    }
    for (k = 0; k < L; ++k) {
        if (!B->kept) {
            r = sfb__refine(ctx, &lev[k], B->opt, 1, &lev[k + 1], &B->T[k], NULL, 0.8f, 0.8f);
            if (r != SFB_SUCCESS) return r;
        }
        B->parent[k + 1] = sfb__shade_parent_faces(ctx, &lev[k], &lev[k + 1], B->loop);
        if (!B->parent[k + 1]) return sfb__oom(ctx, "shading tables");
    }
    B->top = &lev[L];
    for (k = 0; k <= L; ++k)
        for (v = 0; v < lev[k].nv; ++v) {
            int n = lev[k].vf_off[v + 1] - lev[k].vf_off[v];
            if (n + 1 > maxv) maxv = n + 1;
        }
    B->sc.fset = (int *)sfb__alloc(ctx, (size_t)maxv * sizeof(int));
    B->sc.cnt = (double *)sfb__alloc(ctx, (size_t)maxv * sizeof(double));
    if (!B->sc.fset || !B->sc.cnt) return sfb__oom(ctx, "shading tables");

    /* regions (sharpness > 0) from the normals level up */
    for (k = B->Ln; k <= L; ++k)
        if ((r = sfb__regions_build(ctx, &lev[k], 0, &B->reg[k])) != SFB_SUCCESS) return r;
    return sfb__regions_build(ctx, B->top, 0, &B->outreg);
}

/* The normals level: its topology (sh->nlev: prepared from the base, or moved out of lev[Ln]),
 * the source of every face at every vertex, the composing accumulator and, when it lies between
 * the base and the last level, the table of its positions over the base vertices (sh->npos). */
static sfb_result sfb__shade_normals_level(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *prep = B->prep;
    sfb_result r = SFB_SUCCESS;
    int L = B->L, Ln = B->Ln, k, asz;
    if (Ln == 0) r = sfb__level_prepare(ctx, prep, 0, 0, &sh->nlev);
    else if (Ln == L && B->kept_top) r = sfb__level_prepare(ctx, &B->lev[Ln], 0, 0, &sh->nlev); /* borrowed: a copy */
    else { sh->nlev = B->lev[Ln]; memset(&B->lev[Ln], 0, sizeof B->lev[Ln]); }
    if (r != SFB_SUCCESS) return r;
    if (Ln == L) B->top = &sh->nlev;
    sh->nsrc = B->reg[Ln].total;
    sh->nsrc_of_vf = (int *)sfb__alloc(ctx, ((size_t)sh->nlev.vf_off[sh->nlev.nv] + 1) * sizeof(int));
    if (!sh->nsrc_of_vf) return sfb__oom(ctx, "shading tables");
    memcpy(sh->nsrc_of_vf, B->reg[Ln].of_vf, (size_t)sh->nlev.vf_off[sh->nlev.nv] * sizeof(int));
    asz = prep->nv > sh->nsrc ? prep->nv : sh->nsrc;
    for (k = Ln; B->per_level && k < L; ++k)
        if (B->reg[k].total > asz) asz = B->reg[k].total; /* per level: rows over each level's regions */
    B->A.acc = (double *)sfb__alloc(ctx, ((size_t)asz + 1) * sizeof(double));
    B->A.mark = (unsigned *)sfb__calloc(ctx, (size_t)asz + 1, sizeof(unsigned));
    B->A.touched = (int *)sfb__alloc(ctx, ((size_t)asz + 1) * sizeof(int));
    if (!B->A.acc || !B->A.mark || !B->A.touched) return sfb__oom(ctx, "shading tables");
    sh->npos_mode = Ln == 0 ? 0 : Ln == L ? 2 : 1;
    if (sh->npos_mode == 1) {
        if (!sfb__shade_identity(ctx, &B->prow, prep->nv)) return sfb__oom(ctx, "shading tables");
        for (k = 0; k < Ln; ++k) {
            if (!sfb__shade_compose_step(ctx, &B->A, &B->prow, &B->T[k], &B->m, &B->crow)) return sfb__oom(ctx, "shading tables");
            sfb__rows_free(ctx, &B->prow);
            B->prow = B->crow;
            memset(&B->crow, 0, sizeof B->crow);
        }
        r = sfb__rows_move_to_stencils(ctx, &B->prow, prep->nv, &sh->npos);
        if (r != SFB_SUCCESS) return sfb__oom(ctx, "shading tables");
        sfb__rows_free(ctx, &B->prow);
    }
    return SFB_SUCCESS;
}

/* The blend weights from the weights level to the last (B->bw): seeded, then one subdivision
 * step at a time, the held vertices and those released at the step seeded again. */
static sfb_result sfb__shade_weights(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    const sfb_shading_options *o = B->o;
    sfb__shading *sh = B->sh;
    const sfb__level *lev = B->lev;
    int L = B->L, Ln = B->Ln, Lw = B->Lw, loop = B->loop, k, v, i;
    B->bw = (double *)sfb__calloc(ctx, (size_t)(Lw == Ln ? &sh->nlev : &lev[Lw])->nv + 1, sizeof(double));
    if (!B->bw) return sfb__oom(ctx, "shading weights");
    sfb__shade_seed(Lw == Ln ? &sh->nlev : &lev[Lw], B->bw, loop, o->variant, o->darts, NULL);
    for (k = Lw; k < L; ++k) {
        const sfb__stencils *S = &B->T[k];
        const sfb__level *pl = k == Ln ? &sh->nlev : &lev[k], *cl = k + 1 == Ln ? &sh->nlev : &lev[k + 1];
        unsigned char *released;
        B->bn = (double *)sfb__calloc(ctx, (size_t)S->rows + 1, sizeof(double));
        released = (unsigned char *)sfb__calloc(ctx, (size_t)S->rows + 1, 1);
        if (!B->bn || !released) { sfb__free(ctx, released); return sfb__oom(ctx, "shading weights"); }
        for (v = 0; v < S->rows; ++v) {
            double acc = 0.0;
            for (i = 0; i < S->sizes[v]; ++i) acc += (double)S->weights[S->offsets[v] + i] * B->bw[S->indices[S->offsets[v] + i]];
            B->bn[v] = acc < 0.0 ? 0.0 : acc > 1.0 ? 1.0 : acc;
        }
        /* vertex children whose parent was held and who are not: released at this level */
        for (v = 0; v < pl->nv; ++v)
            released[v] = sfb__shade_held(pl, v, loop, o->variant, o->darts) && !sfb__shade_held(cl, v, loop, o->variant, o->darts);
        sfb__shade_seed(cl, B->bn, loop, o->variant, o->darts, released);
        sfb__free(ctx, released);
        sfb__free(ctx, B->bw);
        B->bw = B->bn;
        B->bn = NULL;
    }
    return SFB_SUCCESS;
}

/* The output vertices, one per region of the infinitely sharp partition of the last level:
 * their origin, face-vertex slots and blend weight, and the order of the N_S rows (those with
 * b > 0 first, B->order). */
static sfb_result sfb__shade_outputs(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *top = B->top;
    const sfb__regions *outreg = &B->outreg;
    int *order;
    int v, i;
    sh->nout = outreg->total;
    sh->out_origin = (int *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(int));
    sh->out_fv = (int *)sfb__alloc(ctx, ((size_t)top->nfv + 1) * sizeof(int));
    sh->b = (float *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(float));
    sh->ns_idx_w = (int *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(int));
    sh->ns_idx_all = (int *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(int));
    order = B->order = (int *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(int));
    if (!sh->out_origin || !sh->out_fv || !sh->b || !sh->ns_idx_w || !sh->ns_idx_all || !order) return sfb__oom(ctx, "shading tables");
    for (v = 0; v < top->nv; ++v) {
        int nr = outreg->first[v + 1] - outreg->first[v];
        if (nr > 1) sh->nsplit++;
        for (i = 0; i < nr; ++i) {
            sh->out_origin[outreg->first[v] + i] = v;
            sh->b[outreg->first[v] + i] = (float)B->bw[v];
        }
        for (i = top->vf_off[v]; i < top->vf_off[v + 1]; ++i) {
            int f = top->vf[i];
            sh->out_fv[top->fv_off[f] + top->vf_slot[i]] = outreg->of_vf[i];
        }
    }
    /* N_S rows: those with b > 0 first */
    for (v = 0, i = 0; v < sh->nout; ++v) if (sh->b[v] > 0.0f) order[i++] = v;
    sh->nweighted = i;
    for (v = 0; v < sh->nout; ++v) if (!(sh->b[v] > 0.0f)) order[i++] = v;
    for (i = 0; i < sh->nout; ++i) {
        sh->ns_idx_all[order[i]] = i;
        sh->ns_idx_w[order[i]] = i < sh->nweighted ? i : -1;
    }
    return SFB_SUCCESS;
}

/* N_S: region rows composed from the normals level up to the level below the last (B->prow).
 * Per level (averaging not linear): each step's rows over the regions of the level below alone
 * (composed with an identity, which merges repeated sources), kept as a table of its own. */
static sfb_result sfb__shade_ns_steps(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *lev = B->lev;
    const sfb__regions *reg = B->reg;
    sfb_result r;
    int L = B->L, Ln = B->Ln, k;
    if (B->per_level) {
        sh->steps = (sfb__stencils *)sfb__calloc(ctx, (size_t)(L - Ln), sizeof *sh->steps);
        if (!sh->steps) return sfb__oom(ctx, "shading tables");
        sh->nsteps = L - Ln;
    }
    if (!sfb__shade_identity(ctx, &B->prow, sh->nsrc)) return sfb__oom(ctx, "shading tables");
    for (k = Ln; k < L - 1; ++k) {
        const sfb__level *pl = k == Ln ? &sh->nlev : &lev[k];
        int cv, rv;
        memset(&B->crow, 0, sizeof B->crow);
        B->crow.rows = reg[k + 1].total;
        B->crow.off = (size_t *)sfb__alloc(ctx, ((size_t)B->crow.rows + 1) * sizeof(size_t));
        if (!B->crow.off) return sfb__oom(ctx, "shading tables");
        B->crow.off[0] = 0;
        for (cv = 0; cv < lev[k + 1].nv; ++cv)
            for (rv = reg[k + 1].first[cv]; rv < reg[k + 1].first[cv + 1]; ++rv) {
                int creg = reg[k + 1].first[cv + 1] - reg[k + 1].first[cv] > 1 ? rv : -1;
                B->m.n = 0;
                if (!sfb__shade_region_mask(ctx, pl, &reg[k], &lev[k + 1], &reg[k + 1], B->parent[k + 1], &B->T[k], cv, creg, 1.0, &B->m,
                                            &B->sc) ||
                    !sfb__compose_row(ctx, &B->A, &B->prow, &B->m, &B->crow, rv))
                    return sfb__oom(ctx, "shading tables");
            }
        sfb__rows_free(ctx, &B->prow);
        if (B->per_level) {
            r = sfb__rows_move_to_stencils(ctx, &B->crow, reg[k].total, &sh->steps[k - Ln]);
            if (r != SFB_SUCCESS) { if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "shading tables"); return r; }
            sfb__rows_free(ctx, &B->crow);
            if (!sfb__shade_identity(ctx, &B->prow, reg[k + 1].total)) return sfb__oom(ctx, "shading tables");
        } else {
            B->prow = B->crow;
        }
        memset(&B->crow, 0, sizeof B->crow);
        r = sfb__progress(ctx, 0.8f, "shading");
        if (r != SFB_SUCCESS) return r;
    }
    return SFB_SUCCESS;
}

/* The output rows of N_S, in B->order: each the face-weighted mean of the N_S regions of the
 * last level it covers; then the N_S table (sh->ns), or per level the last step's table and the
 * sizes of the steps. */
static sfb_result sfb__shade_ns_output(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *top = B->top;
    const sfb__regions *reg = B->reg, *outreg = &B->outreg;
    sfb_result r;
    int L = B->L, Ln = B->Ln, i, k;
    memset(&B->crow, 0, sizeof B->crow);
    B->crow.rows = sh->nout;
    B->crow.off = (size_t *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(size_t));
    /* room for rows as long as the composed rows they come from, at once */
    if (!B->crow.off || !sfb__rows_reserve(ctx, &B->crow, (size_t)sh->nout * (B->prow.n / (size_t)(B->prow.rows > 0 ? B->prow.rows : 1) + 4) + 16))
        return sfb__oom(ctx, "shading tables");
    B->crow.off[0] = 0;
    for (i = 0; i < sh->nout; ++i) {
        int ov = B->order[i], cv = sh->out_origin[ov], rv, j;
        int faces = outreg->faces[ov];
        B->m.n = 0;
        for (rv = reg[L].first[cv]; rv < reg[L].first[cv + 1]; ++rv) {
            /* the output region of N_S region rv: that of any of its faces (a bare vertex has
             * one of each) */
            int in = faces == 0;
            double frac;
            int creg = reg[L].first[cv + 1] - reg[L].first[cv] > 1 ? rv : -1;
            for (j = top->vf_off[cv]; j < top->vf_off[cv + 1]; ++j)
                if (reg[L].of_vf[j] == rv) { in = outreg->of_vf[j] == ov; break; }
            if (!in) continue;
            frac = faces ? (double)reg[L].faces[rv] / faces : 1.0;
            if (L == Ln) {
                if (!sfb__mask_grow(ctx, &B->m, 1)) return sfb__oom(ctx, "shading tables");
                SFB__MASK_ADD(&B->m, rv, frac);
            } else if (!sfb__shade_region_mask(ctx, L - 1 == Ln ? &sh->nlev : &B->lev[L - 1], &reg[L - 1], top, &reg[L],
                                               B->parent[L], &B->T[L - 1], cv, creg, frac, &B->m, &B->sc)) {
                return sfb__oom(ctx, "shading tables");
            }
        }
        if (!sfb__compose_row(ctx, &B->A, &B->prow, &B->m, &B->crow, i)) return sfb__oom(ctx, "shading tables");
    }
    if (B->per_level) {
        r = sfb__rows_move_to_stencils(ctx, &B->crow, reg[L - 1].total, &sh->steps[sh->nsteps - 1]);
        if (r != SFB_SUCCESS) { if (r == SFB_OUT_OF_MEMORY) r = sfb__oom(ctx, "shading tables"); return r; }
        for (k = 0; k < sh->nsteps; ++k) {
            const sfb__stencils *S = &sh->steps[k];
            if (S->rows > sh->step_rows_max) sh->step_rows_max = S->rows;
            if (S->sources > sh->step_rows_max) sh->step_rows_max = S->sources;
            for (i = 0; i < S->rows; ++i)
                if (S->sizes[i] > sh->step_size_max) sh->step_size_max = S->sizes[i];
        }
    } else {
        r = sfb__rows_move_to_stencils(ctx, &B->crow, sh->nsrc, &sh->ns);
        if (r != SFB_SUCCESS) return sfb__oom(ctx, "shading tables");
    }
    sfb__rows_free(ctx, &B->crow);
    sfb__rows_free(ctx, &B->prow);
    return SFB_SUCCESS;
}

/* The limit masks (position, two tangents) into mm of output vertex ov, one of the regions of
 * split vertex v of the last level: at a crease vertex the crease tangent and that side's cross
 * tangent, at a corner the two edges of the region's first face. */
static void sfb__shade_split_limit_masks(const sfb__level *top, const sfb__regions *outreg, int v, int ov, int loop, sfb__mask *mm) {
    int e0 = top->ve_off[v], ne = top->ve_off[v + 1] - e0;
    int f0 = top->vf_off[v], nf = top->vf_off[v + 1] - f0, i;
    /* the region's faces: a run first..first+len-1 around v (mod nf) */
    int first = -1, len = 0;
    for (i = 0; i < nf; ++i) {
        int prev = i > 0 ? outreg->of_vf[f0 + i - 1] : (nf == ne ? outreg->of_vf[f0 + nf - 1] : -1);
        if (outreg->of_vf[f0 + i] == ov) { len++; if (prev != ov) first = i; }
    }
    if (first < 0) first = 0;
    if (top->vrule[v] == SFB__RULE_CREASE) {
        float sharp[SFB_MAX_VALENCE + 1];
        int a, b;
        for (i = 0; i < ne && i <= SFB_MAX_VALENCE; ++i) sharp[i] = top->es[top->ve[e0 + i]];
        sfb__crease_pair(sharp, ne, &a, &b);
        SFB__MASK_ADD(&mm[0], v, 2.0 / 3.0);
        SFB__MASK_ADD(&mm[0], sfb__other_end(top, top->ve[e0 + a], v), 1.0 / 6.0);
        SFB__MASK_ADD(&mm[0], sfb__other_end(top, top->ve[e0 + b], v), 1.0 / 6.0);
        sfb__crease_tangent_masks(top, v, first, first + len, loop, &mm[1], &mm[2]);
    } else {
        SFB__MASK_ADD(&mm[0], v, 1.0);
        SFB__MASK_ADD(&mm[1], v, -1.0);
        SFB__MASK_ADD(&mm[1], sfb__other_end(top, top->ve[e0 + first % ne], v), 1.0);
        SFB__MASK_ADD(&mm[2], v, -1.0);
        SFB__MASK_ADD(&mm[2], sfb__other_end(top, top->ve[e0 + (first + 1) % ne], v), 1.0);
    }
}

/* Appends mask mk to the local rows lr as row ov (duplicates merged); 0 when out of memory. */
static int sfb__shade_rows_append(sfb_context *ctx, sfb__rows *lr, const sfb__mask *mk, int ov) {
    size_t at;
    int a2, b2;
    if (!sfb__rows_reserve(ctx, lr, lr->n + (size_t)mk->n)) return 0;
    at = lr->n;
    for (a2 = 0; a2 < mk->n; ++a2) {
        for (b2 = (int)at; b2 < (int)lr->n && lr->idx[b2] != mk->idx[a2]; ++b2) {}
        if (b2 < (int)lr->n) lr->w[b2] += mk->w[a2];
        else { lr->idx[lr->n] = mk->idx[a2]; lr->w[lr->n] = mk->w[a2]; lr->n++; }
    }
    lr->off[ov + 1] = lr->n;
    return 1;
}

/* Limit position and tangents of every output vertex over the refined vertices of the last
 * level (sh->lim[0..2]): local rows, one region of a split vertex at a time. */
static sfb_result sfb__shade_limits(sfb__shade_build *B) {
    sfb_context *ctx = B->ctx;
    sfb__shading *sh = B->sh;
    const sfb__level *top = B->top;
    const sfb__regions *outreg = &B->outreg;
    sfb__mask *mm = B->mm;
    sfb__rows lr[3];
    sfb_result r = SFB_SUCCESS;
    int v, t;
    memset(lr, 0, sizeof lr);
    for (t = 0; t < 3; ++t) {
        lr[t].rows = sh->nout;
        lr[t].off = (size_t *)sfb__alloc(ctx, ((size_t)sh->nout + 1) * sizeof(size_t));
        /* room for a vertex's masks (9 entries at a regular quad vertex, its tangents 6-8) at once: grown
         * from nothing, the tables were copied by realloc over and over */
        if (!lr[t].off || !sfb__rows_reserve(ctx, &lr[t], (size_t)sh->nout * 12 + 16)) r = sfb__oom(ctx, "shading limit tables");
        else lr[t].off[0] = 0;
    }
    for (v = 0; v < top->nv && r == SFB_SUCCESS; ++v) {
        int nr = outreg->first[v + 1] - outreg->first[v], rr;
        int need = 3 * sfb__mask_need_vertex(top, v) + 8;
        for (rr = 0; rr < nr && r == SFB_SUCCESS; ++rr) {
            int ov = outreg->first[v] + rr;
            for (t = 0; t < 3; ++t) {
                mm[t].n = 0;
                if (!sfb__mask_grow(ctx, &mm[t], need)) r = sfb__oom(ctx, "shading limit tables");
            }
            if (r != SFB_SUCCESS) break;
            if (nr == 1) sfb__limit_masks(top, v, B->opt->scheme, &mm[0], &mm[1], &mm[2]);
            else sfb__shade_split_limit_masks(top, outreg, v, ov, B->loop, mm);
            for (t = 0; t < 3; ++t)
                if (!sfb__shade_rows_append(ctx, &lr[t], &mm[t], ov)) { r = sfb__oom(ctx, "shading limit tables"); break; }
        }
    }
    for (t = 0; t < 3; ++t) {
        if (r == SFB_SUCCESS) {
            r = sfb__rows_move_to_stencils(ctx, &lr[t], top->nv, &sh->lim[t]);
            if (r != SFB_SUCCESS) r = sfb__oom(ctx, "shading limit tables");
        }
        sfb__rows_free(ctx, &lr[t]);
    }
    return r;
}

sfb_result sfb__shading_build(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt, int L,
                              const sfb_shading_options *o, sfb__refine_kept *kept, const sfb__level *top, sfb__shading **out) {
    sfb__shade_build B;
    sfb__shading *sh;
    sfb_result r;
    int k;
    *out = NULL;
    memset(&B, 0, sizeof B);
    B.ctx = ctx; B.prep = prep; B.opt = opt; B.o = o; B.L = L;
    B.kept = kept && top && L > 0 ? kept : NULL;
    B.kept_top = B.kept ? top : NULL;
    B.loop = opt->scheme == SFB_SCHEME_LOOP;
    if ((r = sfb__shade_check_options(ctx, o, L, &B.Ln, &B.Lw)) != SFB_SUCCESS) {
        if (B.kept) sfb__refine_kept_free(ctx, B.kept, L);
        return r;
    }
    if ((r = sfb__shade_build_levels(&B)) != SFB_SUCCESS) goto done;
    if ((r = sfb__shade_normals_level(&B)) != SFB_SUCCESS) goto done;
    /* blend weights from the weights level to the last */
    if ((r = sfb__shade_weights(&B)) != SFB_SUCCESS) goto done;
    /* output vertices: one per region of the infinitely sharp partition */
    if ((r = sfb__shade_outputs(&B)) != SFB_SUCCESS) goto done;
    /* N_S rows up to the level below the last, then the output rows */
    if ((r = sfb__shade_ns_steps(&B)) != SFB_SUCCESS) goto done;
    if ((r = sfb__shade_ns_output(&B)) != SFB_SUCCESS) goto done;
    /* limit position and tangents of every output vertex over the refined vertices */
    if ((r = sfb__shade_limits(&B)) != SFB_SUCCESS) goto done;
    sh = B.sh;
    sh->bytes = sizeof *sh + (sh->ns.entries + sh->npos.entries + sh->lim[0].entries + sh->lim[1].entries + sh->lim[2].entries) * 8 +
                (size_t)sh->nout * 6 * sizeof(int) + (size_t)B.top->nfv * sizeof(int) + (size_t)sh->nlev.nfv * 3 * sizeof(int);
    for (k = 0; k < sh->nsteps; ++k) sh->bytes += sizeof *sh->steps + sh->steps[k].entries * 8 + (size_t)sh->steps[k].rows * 2 * sizeof(int);
done:
    sfb__shade_build_free(&B);
    if (r != SFB_SUCCESS) { sfb__shading_free(ctx, B.sh); return r; }
    *out = B.sh;
    return SFB_SUCCESS;
}

SFB_API sfb_shade_params sfb_shade_params_init(void) {
    sfb_shade_params p;
    memset(&p, 0, sizeof p);
    p.p = 1.0f;
    return p;
}

/* One shading table on the context's backend (surface.c's sfb__surface_apply), xyz rows. */
static sfb_result sfb__shade_apply(const sfb_surface *s, const sfb__stencils *t, void *handle, int rows, const float *src, float *dst) {
    sfb_buffer_desc d3 = {0, 3, 3};
    if (rows <= 0) return SFB_SUCCESS;
    return sfb__surface_apply(s, t, handle, rows, src, d3, dst, d3);
}

/* The weighted spherical mean of `count` vectors n (xyz, unit length expected) with weights w:
 * the unit vector q minimising sum w_i angle(q, n_i)^2, where sum w_i log_q(n_i) = 0. Start at
 * the normalised linear average, then q <- exp_q(sum (w_i / W) log_q(n_i)), W = sum w_i, until
 * the step is shorter than 1e-12 or after 32 iterations, with
 *   log_q(n) = (n - (q.n) q) theta / sin(theta), theta = angle(q, n)  (the tangent at q towards n),
 *   exp_q(t) = cos|t| q + sin|t| t / |t|                                (walk |t| along t).
 * A zero linear average gives zero (as linear averaging does). A zero input with a nonzero
 * weight, a weight sum <= 0, an input within 1e-6 rad of -q (log_q undefined there) or a
 * non-finite iterate give the normalised linear average instead. Returns the iterations taken
 * (>= 1), 0 for the zero result, -1 where the linear average was returned. Pure: safe from any
 * thread. */
int sfb__shade_spherical_mean(int count, const double *n, const double *w, double out[3]) {
    double s[3] = {0.0, 0.0, 0.0}, q[3], W = 0.0, len;
    int i, c, it, degenerate = 0;
    for (i = 0; i < count; ++i) {
        const double *v = n + 3 * (size_t)i;
        for (c = 0; c < 3; ++c) s[c] += w[i] * v[c];
        W += w[i];
        if (w[i] != 0.0 && v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0) degenerate = 1;
    }
    out[0] = out[1] = out[2] = 0.0;
    len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (!(len > 0.0)) return 0;
    for (c = 0; c < 3; ++c) out[c] = q[c] = s[c] / len;
    if (degenerate || !(W > 0.0)) return -1;
    for (it = 1;; ++it) {
        double t[3] = {0.0, 0.0, 0.0}, tl, st;
        for (i = 0; i < count; ++i) {
            const double *v = n + 3 * (size_t)i;
            double vl = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), d, u[3], sv, theta, f;
            if (w[i] == 0.0) continue;
            d = (q[0] * v[0] + q[1] * v[1] + q[2] * v[2]) / vl;
            for (c = 0; c < 3; ++c) u[c] = v[c] / vl - d * q[c];
            sv = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            if (d > 0.0 && sv < 0.03) {
                /* theta / sin(theta) = asin(s) / s = 1 + s^2/6 + 3 s^4/40 + 5 s^6/112 + O(s^8):
                 * below s = 0.03 the rest is under 1e-14 of it (most entries: neighbouring
                 * normals), and no atan2 is needed */
                const double s2 = sv * sv;
                f = 1.0 + s2 * (1.0 / 6.0 + s2 * (3.0 / 40.0 + s2 * (5.0 / 112.0)));
            } else {
                theta = atan2(sv, d);
                if (theta > SFB__PI - 1e-6) return -1; /* nearly opposite q: no tangent towards it */
                f = theta / sv;
            }
            for (c = 0; c < 3; ++c) t[c] += (w[i] / W) * f * u[c];
        }
        tl = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        if (tl < 1e-12) break;
        st = sin(tl) / tl;
        tl = cos(tl);
        for (c = 0; c < 3; ++c) q[c] = tl * q[c] + st * t[c];
        len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        if (!(len > 0.5) || !(len < 2.0)) return -1; /* not finite */
        for (c = 0; c < 3; ++c) q[c] /= len;
        if (it == 32) break;
    }
    for (c = 0; c < 3; ++c) out[c] = q[c];
    return it;
}

/* N_S one level at a time (averaging renormalised or spherical), on the CPU in double: `src`
 * holds the normals-level region normals (nsh->nsrc xyz); each step's rows average the
 * previous level's normals (RENORMALIZED: normalize(sum w_i n_i); SPHERICAL: the weighted
 * spherical mean); the last step's rows [0, rows) go to ns as floats. */
static sfb_result sfb__shade_levels(sfb_context *ctx, const sfb__shading *sh, const double *src, int rows, float *ns) {
    size_t nrow = (size_t)sh->step_rows_max * 3 + 1, nsz = (size_t)sh->step_size_max + 1;
    double *a = (double *)sfb__alloc(ctx, nrow * sizeof(double)), *b = (double *)sfb__alloc(ctx, nrow * sizeof(double));
    double *vec = (double *)sfb__alloc(ctx, nsz * 3 * sizeof(double)), *w = (double *)sfb__alloc(ctx, nsz * sizeof(double));
    const double *cur = src;
    int k, i, j, c;
    if (!a || !b || !vec || !w) {
        sfb__free(ctx, a); sfb__free(ctx, b); sfb__free(ctx, vec); sfb__free(ctx, w);
        return sfb__oom(ctx, "shading normals");
    }
    for (k = 0; k < sh->nsteps; ++k) {
        const sfb__stencils *T = &sh->steps[k];
        const int last = k == sh->nsteps - 1, n = last ? rows : T->rows;
        double *nx = cur == a ? b : a;
        for (i = 0; i < n; ++i) {
            const int o = T->offsets[i], cnt = T->sizes[i];
            double q[3];
            if (sh->averaging == SFB_SHADE_AVERAGE_SPHERICAL) {
                for (j = 0; j < cnt; ++j) {
                    const double *p = cur + 3 * (size_t)T->indices[o + j];
                    w[j] = (double)T->weights[o + j];
                    vec[3 * j] = p[0]; vec[3 * j + 1] = p[1]; vec[3 * j + 2] = p[2];
                }
                sfb__shade_spherical_mean(cnt, vec, w, q);
            } else {
                double len;
                q[0] = q[1] = q[2] = 0.0;
                for (j = 0; j < cnt; ++j) {
                    const double *p = cur + 3 * (size_t)T->indices[o + j], wj = (double)T->weights[o + j];
                    for (c = 0; c < 3; ++c) q[c] += wj * p[c];
                }
                len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                for (c = 0; c < 3; ++c) q[c] = len > 0.0 ? q[c] / len : 0.0;
            }
            if (last) for (c = 0; c < 3; ++c) ns[3 * (size_t)i + c] = (float)q[c];
            else for (c = 0; c < 3; ++c) nx[3 * (size_t)i + c] = q[c];
        }
        cur = nx;
    }
    sfb__free(ctx, a); sfb__free(ctx, b); sfb__free(ctx, vec); sfb__free(ctx, w);
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_surface_shade(const sfb_surface *s, const sfb_shade_params *params, sfb_mesh_data *o) {
    sfb_context *ctx;
    const sfb__shading *sh;
    const sfb__backend_vtable *be;
    sfb_shade_params prm;
    float *refined = NULL, *npos_buf = NULL, *src = NULL, *ns = NULL, *fnrm = NULL;
    double *srcd = NULL; /* the sources in double (per-level averaging) */
    const float *npos;
    sfb_result r;
    int all, rows, v, f, i, c;
    if (!s || !o) return SFB_INVALID_ARGS;
    memset(o, 0, sizeof *o);
    ctx = s->ctx;
    sh = s->shading;
    if (!sh) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_shade: the surface was created without SFB_REFINE_SHADING");
    prm = params ? *params : sfb_shade_params_init();
    if (prm.p == 0.0f) prm.p = 1.0f;
    if (!(prm.p > 0.0f) || !(prm.p < 1e6f))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "blend exponent p = %g: it must be a finite number > 0", (double)prm.p);
    if (prm.flags & ~(unsigned)SFB_SHADE_ALL_SUBDIVIDED)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_shade: unknown flags 0x%x", prm.flags & ~(unsigned)SFB_SHADE_ALL_SUBDIVIDED);
    all = (prm.flags & SFB_SHADE_ALL_SUBDIVIDED) != 0;
    rows = all ? sh->nout : sh->nweighted;

    /* refined positions, normals-level positions */
    r = sfb__refine_output(s, s->base_positions, s->base_vertex_count, 0, o);
    if (r != SFB_SUCCESS) return r;
    refined = o->positions;
    o->positions = NULL;
    if (sh->npos_mode == 0) npos = s->base_positions;
    else if (sh->npos_mode == 2) npos = refined;
    else {
        npos_buf = (float *)sfb__alloc(ctx, (size_t)sh->npos.rows * 3 * sizeof(float) + 1);
        if (!npos_buf) goto oom;
        r = sfb__shade_apply(s, &sh->npos, sh->handles[0], sh->npos.rows, s->base_positions, npos_buf);
        if (r != SFB_SUCCESS) goto fail;
        npos = npos_buf;
    }
    /* face normals at the normals level (Newell), averaged per region into the sources */
    fnrm = (float *)sfb__alloc(ctx, (size_t)sh->nlev.nf * 3 * sizeof(float) + 1);
    src = (float *)sfb__calloc(ctx, (size_t)sh->nsrc * 3 + 1, sizeof(float));
    if (!fnrm || !src) goto oom;
    for (f = 0; f < sh->nlev.nf; ++f) {
        double n[3] = {0.0, 0.0, 0.0}, len;
        int a = sh->nlev.fv_off[f], cnt = sh->nlev.fv_off[f + 1] - a;
        for (i = 0; i < cnt; ++i) {
            const float *p = npos + 3 * (size_t)sh->nlev.fv[a + i], *q = npos + 3 * (size_t)sh->nlev.fv[a + (i + 1) % cnt];
            n[0] += ((double)p[1] - q[1]) * ((double)p[2] + q[2]);
            n[1] += ((double)p[2] - q[2]) * ((double)p[0] + q[0]);
            n[2] += ((double)p[0] - q[0]) * ((double)p[1] + q[1]);
        }
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (c = 0; c < 3; ++c) fnrm[3 * (size_t)f + c] = len > 0.0 ? (float)(n[c] / len) : 0.0f;
    }
    {
        double *acc = (double *)sfb__calloc(ctx, (size_t)sh->nsrc * 3 + 1, sizeof(double));
        if (!acc) goto oom;
        for (v = 0; v < sh->nlev.nv; ++v)
            for (i = sh->nlev.vf_off[v]; i < sh->nlev.vf_off[v + 1]; ++i)
                for (c = 0; c < 3; ++c) acc[3 * (size_t)sh->nsrc_of_vf[i] + c] += fnrm[3 * (size_t)sh->nlev.vf[i] + c];
        for (i = 0; i < sh->nsrc; ++i) {
            double *a = acc + 3 * (size_t)i, len = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
            for (c = 0; c < 3; ++c) {
                a[c] = len > 0.0 ? a[c] / len : 0.0;
                src[3 * (size_t)i + c] = (float)a[c];
            }
        }
        if (sh->nsteps > 0) srcd = acc;
        else sfb__free(ctx, acc);
    }
    /* output arrays */
    o->positions = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->limit_positions = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->tangents_u = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->tangents_v = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->normals = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->limit_normals = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->subdivided_normals = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    o->blend_weights = (float *)sfb__alloc(ctx, (size_t)sh->nout * sizeof(float) + 1);
    o->vertex_origin = (int *)sfb__alloc(ctx, (size_t)sh->nout * sizeof(int) + 1);
    ns = (float *)sfb__alloc(ctx, (size_t)sh->nout * 3 * sizeof(float) + 1);
    if (!o->positions || !o->limit_positions || !o->tangents_u || !o->tangents_v || !o->normals || !o->limit_normals ||
        !o->subdivided_normals || !o->blend_weights || !o->vertex_origin || !ns) goto oom;
    if ((r = sh->nsteps > 0 ? sfb__shade_levels(ctx, sh, srcd, rows, ns) : sfb__shade_apply(s, &sh->ns, sh->handles[1], rows, src, ns)) != SFB_SUCCESS ||
        (r = sfb__shade_apply(s, &sh->lim[0], sh->handles[2], sh->nout, refined, o->limit_positions)) != SFB_SUCCESS ||
        (r = sfb__shade_apply(s, &sh->lim[1], sh->handles[3], sh->nout, refined, o->tangents_u)) != SFB_SUCCESS ||
        (r = sfb__shade_apply(s, &sh->lim[2], sh->handles[4], sh->nout, refined, o->tangents_v)) != SFB_SUCCESS)
        goto fail;
    be = ctx->backend;
    if (!be || !be->finish_normals) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks finish_normals; using ref", be ? be->name : "none");
        be = &ctx->ref_vt;
    }
    r = be->finish_normals(be == ctx->backend ? ctx->backend_state : NULL, 0, sh->nout, o->tangents_u, o->tangents_v, ns,
                           all ? sh->ns_idx_all : sh->ns_idx_w, sh->b, prm.p, o->normals, o->limit_normals, o->subdivided_normals);
    if (r != SFB_SUCCESS) goto fail;
    for (v = 0; v < sh->nout; ++v) {
        int ov = sh->out_origin[v];
        for (c = 0; c < 3; ++c) o->positions[3 * (size_t)v + c] = refined[3 * (size_t)ov + c];
    }
    memcpy(o->blend_weights, sh->b, (size_t)sh->nout * sizeof(float));
    memcpy(o->vertex_origin, sh->out_origin, (size_t)sh->nout * sizeof(int));
    memcpy(o->face_vertices, sh->out_fv, (size_t)o->face_vertex_count * sizeof(int));
    o->refined_vertex_count = o->vertex_count;
    o->vertex_count = sh->nout;
    o->subdivided_count = rows;
    sfb__free(ctx, refined); sfb__free(ctx, npos_buf); sfb__free(ctx, src); sfb__free(ctx, ns); sfb__free(ctx, fnrm); sfb__free(ctx, srcd);
    return SFB_SUCCESS;
oom:
    r = sfb__oom(ctx, "shading output");
fail:
    sfb__free(ctx, refined); sfb__free(ctx, npos_buf); sfb__free(ctx, src); sfb__free(ctx, ns); sfb__free(ctx, fnrm); sfb__free(ctx, srcd);
    sfb_mesh_data_free(o);
    return r;
}

SFB_API sfb_result sfb_surface_shade_info(const sfb_surface *s, sfb_shade_info *out) {
    const sfb__shading *sh;
    if (!s || !out) return SFB_INVALID_ARGS;
    memset(out, 0, sizeof *out);
    sh = s->shading;
    if (!sh) return sfb__error(s->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_shade_info: the surface was created without SFB_REFINE_SHADING");
    out->refined_vertices = s->top.nv;
    out->output_vertices = sh->nout;
    out->split_vertices = sh->nsplit;
    out->weighted = sh->nweighted;
    out->normals_level = sh->normals_level;
    out->weights_level = sh->weights_level;
    out->sources = sh->nsrc;
    out->bytes = sh->bytes;
    return SFB_SUCCESS;
}
#line 1 "src/render.c"
/* Software pictures (no GL): a small z-buffered rasterizer for refined meshes.
 *
 * Two passes over a G-buffer. Pass 1 fan-triangulates every polygon, projects it with an
 * orbit camera around the bounding-box centre and keeps, per pixel, the nearest fragment's
 * depth, perspective-correct position, normal and scalar (and its distance to the polygon's
 * own edges, for the edge overlay). Pass 2 shades every covered pixel: the interpolated
 * normal is renormalised (Phong) and turned toward the viewer (two-sided lighting), then
 * coloured by the mode: diffuse + specular grey; highlight lines (ALGORITHMS.md §7, parallel
 * light lines in a plane fixed to the camera, Dir = N); a blue-to-red scalar map; the normal
 * as RGB. Highlight stripes are filtered by their own screen-space rate, so bands finer
 * than a pixel fade to their average colour instead of aliasing. */

#define SFB__RENDER_DEFAULT_W 640
#define SFB__RENDER_DEFAULT_H 480
#define SFB__RENDER_DEFAULT_YAW 30.0f
#define SFB__RENDER_DEFAULT_PITCH 25.0f
#define SFB__RENDER_DEFAULT_STRIPES 8.0f
#define SFB__RENDER_DEFAULT_LIGHT_DISTANCE 3.0f
#define SFB__RENDER_HALF_FOV 15.0           /* degrees: the bounding sphere fits a 30 degree cone */
#define SFB__RENDER_MARGIN 0.92             /* the bounding sphere's share of the smaller side */
#define SFB__RENDER_GB 8                    /* floats per pixel: depth, normal xyz, position xyz, scalar */

SFB_API sfb_render_config sfb_render_config_init(int mode) {
    sfb_render_config c;
    memset(&c, 0, sizeof c);
    c.mode = mode;
    return c;
}

SFB_API void sfb_image_free(sfb_image *img) {
    if (!img) return;
    if (img->ctx_) sfb__free(img->ctx_, img->rgba);
    memset(img, 0, sizeof *img);
}

/* The camera: an orbit around `centre` at yaw/pitch; right/up/forward unit vectors. */
typedef struct sfb__camera {
    double eye[3], right[3], up[3], fwd[3];
    double focal;  /* perspective: pixels per unit of x/z; orthographic: pixels per unit */
    double cx, cy; /* image centre in pixels */
    int ortho;
} sfb__camera;

double sfb__rdot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
void sfb__rcross(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
double sfb__rnormalize(double *a) {
    double l = sqrt(sfb__rdot(a, a));
    if (l > 0.0 && isfinite(l)) { a[0] /= l; a[1] /= l; a[2] /= l; }
    return l;
}
double sfb__rclamp(double x, double lo, double hi) { return x < lo ? lo : x > hi ? hi : x; }

/* Integral over [0, x] of the unit-periodic indicator of the band [a, b] (0 <= a <= b <= 1). */
static double sfb__band_integral(double x, double a, double b) {
    double fl = floor(x), fr = x - fl;
    return fl * (b - a) + (sfb__rclamp(fr, a, b) - a);
}
/* Share of the pixel footprint [w - fw/2, w + fw/2] covered by the periodic band [a, b]. */
double sfb__band_cover(double w, double fw, double a, double b) {
    if (fw > 64.0) return b - a;
    if (fw < 1e-4) {
        double fr = w - floor(w);
        return fr >= a && fr < b;
    }
    return (sfb__band_integral(w + 0.5 * fw, a, b) - sfb__band_integral(w - 0.5 * fw, a, b)) / fw;
}

/* Colour map for scalars in [0,1]: blue, cyan, green, yellow, red. */
void sfb__colormap(double t, double *rgb) {
    static const double stops[5][3] = { {0.10, 0.20, 1.00}, {0.00, 0.85, 1.00}, {0.10, 0.90, 0.15},
                                        {1.00, 0.92, 0.00}, {1.00, 0.10, 0.05} };
    double x = sfb__rclamp(t, 0.0, 1.0) * 4.0;
    int i = (int)x, c;
    double f;
    if (i > 3) i = 3;
    f = x - i;
    for (c = 0; c < 3; ++c) rgb[c] = stops[i][c] * (1.0 - f) + stops[i + 1][c] * f;
}

unsigned char sfb__to_byte(double v) {
    v = sfb__rclamp(v, 0.0, 1.0);
    return (unsigned char)(v * 255.0 + 0.5);
}

/* Newell normal of polygon f (unnormalised; zero when degenerate or not finite). */
static void sfb__polygon_normal(const float *pos, const int *fv, int n, double *o) {
    int i;
    o[0] = o[1] = o[2] = 0.0;
    for (i = 0; i < n; ++i) {
        const float *a = pos + 3 * (size_t)fv[i], *b = pos + 3 * (size_t)fv[(i + 1) % n];
        o[0] += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
        o[1] += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
        o[2] += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
    }
    if (!(isfinite(o[0]) && isfinite(o[1]) && isfinite(o[2]))) o[0] = o[1] = o[2] = 0.0;
}

/* State of one render. */
typedef struct sfb__raster {
    int w, h;
    float *gb;             /* SFB__RENDER_GB floats per pixel; depth +inf: empty */
    unsigned char *edge;   /* per pixel: edge overlay coverage 0..255 */
    const float *pos, *nrm, *scal;
    const sfb__camera *cam;
    int draw_edges;
} sfb__raster;

/* Projected vertex: screen x, y, view depth z, and the interpolation weight q (1/z or 1). */
typedef struct sfb__pv { double x, y, z, q; } sfb__pv;

/* Rasterizes one fan triangle of a polygon: P its projected corners, vi their vertex indices,
 * real[k] whether the side opposite corner k is a side of the polygon (drawn by the overlay)
 * rather than a fan diagonal. fnormal: the polygon's unit normal (used where there are no
 * vertex normals or they vanish). */
static void sfb__raster_tri(sfb__raster *R, const sfb__pv *P, const int *vi, const int *real, const double *fnormal) {
    double x0 = P[0].x, y0 = P[0].y, x1 = P[1].x, y1 = P[1].y, x2 = P[2].x, y2 = P[2].y;
    double area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
    double minx, maxx, miny, maxy, inv, elen[3];
    int ix0, ix1, iy0, iy1, x, y, k;
    if (!(fabs(area) > 1e-12) || !isfinite(area)) return;
    minx = x0 < x1 ? (x0 < x2 ? x0 : x2) : (x1 < x2 ? x1 : x2);
    maxx = x0 > x1 ? (x0 > x2 ? x0 : x2) : (x1 > x2 ? x1 : x2);
    miny = y0 < y1 ? (y0 < y2 ? y0 : y2) : (y1 < y2 ? y1 : y2);
    maxy = y0 > y1 ? (y0 > y2 ? y0 : y2) : (y1 > y2 ? y1 : y2);
    /* pixel centres at i + 0.5; clamp in double before converting */
    minx = sfb__rclamp(ceil(minx - 0.5), 0.0, (double)R->w);
    maxx = sfb__rclamp(floor(maxx - 0.5), -1.0, (double)R->w - 1.0);
    miny = sfb__rclamp(ceil(miny - 0.5), 0.0, (double)R->h);
    maxy = sfb__rclamp(floor(maxy - 0.5), -1.0, (double)R->h - 1.0);
    ix0 = (int)minx; ix1 = (int)maxx; iy0 = (int)miny; iy1 = (int)maxy;
    if (ix0 > ix1 || iy0 > iy1) return;
    inv = 1.0 / area;
    /* edge k is opposite vertex k: e0 = (1,2), e1 = (2,0), e2 = (0,1) */
    elen[0] = sqrt((x2 - x1) * (x2 - x1) + (y2 - y1) * (y2 - y1));
    elen[1] = sqrt((x0 - x2) * (x0 - x2) + (y0 - y2) * (y0 - y2));
    elen[2] = sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0));
    for (y = iy0; y <= iy1; ++y) {
        double py = y + 0.5;
        for (x = ix0; x <= ix1; ++x) {
            double px = x + 0.5, e[3], b[3], den, z, cover = 0.0;
            size_t pix = (size_t)y * (size_t)R->w + (size_t)x;
            float *g = R->gb + pix * SFB__RENDER_GB;
            e[0] = (x2 - x1) * (py - y1) - (y2 - y1) * (px - x1);
            e[1] = (x0 - x2) * (py - y2) - (y0 - y2) * (px - x2);
            e[2] = (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0);
            b[0] = e[0] * inv; b[1] = e[1] * inv; b[2] = e[2] * inv;
            if (b[0] < 0.0 || b[1] < 0.0 || b[2] < 0.0) continue;
            den = b[0] * P[0].q + b[1] * P[1].q + b[2] * P[2].q;
            if (!(den > 0.0)) continue;
            /* perspective: q = 1/z is affine in the picture; orthographic: q = 1 and z is */
            z = R->cam->ortho ? b[0] * P[0].z + b[1] * P[1].z + b[2] * P[2].z : 1.0 / den;
            if (!(z < (double)g[0])) continue;
            /* perspective-correct weights */
            for (k = 0; k < 3; ++k) b[k] = b[k] * P[k].q / den;
            g[0] = (float)z;
            {
                double n[3] = { 0.0, 0.0, 0.0 }, p[3] = { 0.0, 0.0, 0.0 }, s = 0.0;
                int c;
                for (k = 0; k < 3; ++k) {
                    const float *pp = R->pos + 3 * (size_t)vi[k];
                    for (c = 0; c < 3; ++c) p[c] += b[k] * pp[c];
                    if (R->nrm) {
                        const float *nn = R->nrm + 3 * (size_t)vi[k];
                        if (isfinite(nn[0]) && isfinite(nn[1]) && isfinite(nn[2]))
                            for (c = 0; c < 3; ++c) n[c] += b[k] * nn[c];
                    }
                    if (R->scal) {
                        float sv = R->scal[vi[k]];
                        s += b[k] * (isfinite(sv) ? sfb__rclamp(sv, 0.0, 1.0) : 0.0);
                    }
                }
                if (!R->nrm || !(sfb__rdot(n, n) > 1e-20)) { n[0] = fnormal[0]; n[1] = fnormal[1]; n[2] = fnormal[2]; }
                for (c = 0; c < 3; ++c) { g[1 + c] = (float)n[c]; g[4 + c] = (float)p[c]; }
                g[7] = (float)s;
            }
            if (R->draw_edges) {
                for (k = 0; k < 3; ++k)
                    if (real[k] && elen[k] > 0.0) {
                        double d = fabs(e[k]) / elen[k], c = sfb__rclamp(1.25 - d, 0.0, 1.0);
                        if (c > cover) cover = c;
                    }
                R->edge[pix] = sfb__to_byte(cover);
            }
        }
    }
}

static sfb_result sfb__render_check(sfb_context *ctx, const sfb_mesh_data *m, const sfb_render_config *c,
                                    const float **pos, const float **nrm, const float **scal, int *w, int *h) {
    int f;
    size_t off = 0;
    *w = c->width ? c->width : SFB__RENDER_DEFAULT_W;
    *h = c->height ? c->height : SFB__RENDER_DEFAULT_H;
    if (*w < 0 || *h < 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "image size %d x %d is negative", *w, *h);
    if (*w > SFB_RENDER_MAX_SIZE || *h > SFB_RENDER_MAX_SIZE)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "image size %d x %d is over the limit of %d (SFB_RENDER_MAX_SIZE)",
                          *w, *h, SFB_RENDER_MAX_SIZE);
    if (c->mode < SFB_RENDER_SHADED || c->mode > SFB_RENDER_NORMALS)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown render mode %d", c->mode);
    if (!isfinite(c->yaw) || !isfinite(c->pitch) || !isfinite(c->zoom) || c->zoom < 0.0f)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "view (yaw %g, pitch %g, zoom %g): angles must be finite, zoom finite and >= 0",
                          (double)c->yaw, (double)c->pitch, (double)c->zoom);
    if (!isfinite(c->up[0]) || !isfinite(c->up[1]) || !isfinite(c->up[2]))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the orbit's up direction (%g, %g, %g) is not finite", (double)c->up[0],
                          (double)c->up[1], (double)c->up[2]);
    if (!isfinite(c->stripes) || c->stripes < 0.0f || c->stripes > 1e5f || !isfinite(c->light_distance) || c->light_distance < 0.0f)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "highlight stripes %g and light distance %g must be finite and >= 0 (stripes <= 1e5)",
                          (double)c->stripes, (double)c->light_distance);
    if (m->vertex_count < 0 || m->face_count < 0 || m->face_vertex_count < 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "negative element count in the mesh");
    if (m->vertex_count > SFB_MAX_ELEMENTS || m->face_count > SFB_MAX_ELEMENTS || m->face_vertex_count > SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "element count over the limit of %d", SFB_MAX_ELEMENTS);
    if (m->face_count == 0) return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_NONE, -1, "mesh has no faces");
    *pos = c->positions ? c->positions : m->positions;
    *nrm = c->normals ? c->normals : m->normals;
    *scal = c->scalars ? c->scalars : m->blend_weights;
    if (!*pos || !m->face_sizes || !m->face_vertices)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mesh lacks positions or faces");
    if (c->mode == SFB_RENDER_WEIGHTS && !*scal)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                          "the weights picture needs scalars (config scalars or the mesh's blend_weights from sfb_surface_shade)");
    if (m->hole_count > SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "hole count over the limit of %d", SFB_MAX_ELEMENTS);
    if (m->hole_count < 0 || (m->hole_count > 0 && !m->holes))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mesh has a hole count without its array");
    for (f = 0; f < m->face_count; ++f) {
        int n = m->face_sizes[f], i;
        if (n < 3 || n > SFB_MAX_FACE_SIZE)
            return sfb__error(ctx, n < 3 ? SFB_INVALID_TOPOLOGY : SFB_LIMIT_EXCEEDED, SFB_ELEMENT_FACE, f,
                              "face has %d vertices (3..%d)", n, SFB_MAX_FACE_SIZE);
        if ((size_t)n > (size_t)m->face_vertex_count - off)
            return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_FACE, f, "face sizes add up to more than face_vertex_count (%d)",
                              m->face_vertex_count);
        for (i = 0; i < n; ++i) {
            int v = m->face_vertices[off + (size_t)i];
            if (v < 0 || v >= m->vertex_count)
                return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "vertex index %d out of range (%d vertices)", v,
                                  m->vertex_count);
        }
        off += (size_t)n;
    }
    if (off != (size_t)m->face_vertex_count)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "face sizes add up to %zu, face_vertex_count is %d", off,
                          m->face_vertex_count);
    for (f = 0; f < m->hole_count; ++f)
        if (m->holes[f] < 0 || m->holes[f] >= m->face_count)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, m->holes[f], "hole %d names a face out of range (%d faces)", f,
                              m->face_count);
    return SFB_SUCCESS;
}

/* Bounding box of the finite vertices that faces use; returns 0 when there is none. */
static int sfb__render_bounds(const sfb_mesh_data *m, const float *pos, double *lo, double *hi) {
    int i, any = 0;
    size_t k;
    lo[0] = lo[1] = lo[2] = HUGE_VAL;
    hi[0] = hi[1] = hi[2] = -HUGE_VAL;
    for (k = 0; k < (size_t)m->face_vertex_count; ++k) {
        const float *p = pos + 3 * (size_t)m->face_vertices[k];
        if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) continue;
        for (i = 0; i < 3; ++i) {
            if (p[i] < lo[i]) lo[i] = p[i];
            if (p[i] > hi[i]) hi[i] = p[i];
        }
        any = 1;
    }
    return any;
}

/* The camera and the lights of one picture, the lights fixed to the camera. */
typedef struct sfb__render_view {
    sfb__camera cam;
    double centre[3], radius;
    double key[3], fill[3];  /* directions of the key and the fill light */
    /* the light plane of the highlight lines: normal m, line direction e, across the lines d,
     * a point a; line spacing and the plane's distance */
    double light_m[3], light_e[3], light_d[3], light_a[3], spacing, lightdist;
} sfb__render_view;

/* The orbit about `up` (zero, or +y: the default y-up orbit, untouched): the orbit's
 * direction and right vector, made about +y, turned by the shortest rotation that takes +y to
 * up (about x by pi when up is -y). A z-up model (CAD, catmark_car) is then seen from its side
 * and above, as a y-up one is by default (sfb_render and sfb_surface_analyze). */
void sfb__orbit_up(const float up[3], double dir[3], double right[3]) {
    double u[3], ax[3], len, c, s, t, *v[2];
    int i, k;
    for (i = 0; i < 3; ++i) u[i] = up[i];
    len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (!(len > 0.0) || (u[0] == 0.0 && u[2] == 0.0 && u[1] > 0.0)) return;
    for (i = 0; i < 3; ++i) u[i] /= len;
    /* axis +y x u, sine its length, cosine u.y */
    ax[0] = u[2]; ax[1] = 0.0; ax[2] = -u[0];
    s = sqrt(ax[0] * ax[0] + ax[2] * ax[2]);
    c = u[1];
    if (s > 0.0) { ax[0] /= s; ax[2] /= s; }
    else { ax[0] = 1.0; ax[2] = 0.0; } /* up is -y */
    v[0] = dir; v[1] = right;
    for (k = 0; k < 2; ++k) {
        /* Rodrigues: v c + (ax x v) s + ax (ax.v)(1 - c) */
        double *x = v[k], cr[3], r[3];
        cr[0] = ax[1] * x[2] - ax[2] * x[1]; cr[1] = ax[2] * x[0] - ax[0] * x[2]; cr[2] = ax[0] * x[1] - ax[1] * x[0];
        t = (ax[0] * x[0] + ax[1] * x[1] + ax[2] * x[2]) * (1.0 - c);
        for (i = 0; i < 3; ++i) r[i] = x[i] * c + cr[i] * s + ax[i] * t;
        for (i = 0; i < 3; ++i) x[i] = r[i];
    }
}

/* The orbit camera around the bounding box of what the faces use and the lights (config c, a
 * w x h picture). */
static void sfb__render_view_setup(const sfb_mesh_data *m, const float *pos, const sfb_render_config *c, int w, int h,
                                   sfb__render_view *V) {
    double lo[3], hi[3], yaw, pitch;
    sfb__camera *cam = &V->cam;
    int i;
    /* camera */
    if (!sfb__render_bounds(m, pos, lo, hi)) { lo[0] = lo[1] = lo[2] = -1.0; hi[0] = hi[1] = hi[2] = 1.0; }
    for (i = 0; i < 3; ++i) V->centre[i] = 0.5 * (lo[i] + hi[i]);
    V->radius = 0.5 * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (!(V->radius > 0.0) || !isfinite(V->radius)) V->radius = 1.0;
    yaw = (c->view_set ? c->yaw : SFB__RENDER_DEFAULT_YAW) * SFB__PI / 180.0;
    pitch = (c->view_set ? c->pitch : SFB__RENDER_DEFAULT_PITCH) * SFB__PI / 180.0;
    memset(cam, 0, sizeof *cam);
    cam->ortho = c->orthographic != 0;
    {
        double dir[3], dist = V->radius / sin(SFB__RENDER_HALF_FOV * SFB__PI / 180.0);
        double zoom = c->zoom > 0.0f ? c->zoom : 1.0, half = 0.5 * (w < h ? w : h) * SFB__RENDER_MARGIN;
        dir[0] = cos(pitch) * sin(yaw); dir[1] = sin(pitch); dir[2] = cos(pitch) * cos(yaw);
        cam->right[0] = cos(yaw); cam->right[1] = 0.0; cam->right[2] = -sin(yaw);
        sfb__orbit_up(c->up, dir, cam->right);
        for (i = 0; i < 3; ++i) { cam->eye[i] = V->centre[i] + dist * dir[i]; cam->fwd[i] = -dir[i]; }
        sfb__rcross(cam->right, cam->fwd, cam->up);
        sfb__rnormalize(cam->up);
        cam->focal = cam->ortho ? half * zoom / V->radius : half * zoom / tan(SFB__RENDER_HALF_FOV * SFB__PI / 180.0);
        cam->cx = 0.5 * w;
        cam->cy = 0.5 * h;
    }
    /* lights, fixed to the camera: a key light from the upper left behind the viewer, a fill */
    for (i = 0; i < 3; ++i) {
        V->key[i] = -cam->fwd[i] + 0.55 * cam->up[i] - 0.45 * cam->right[i];
        V->fill[i] = -cam->fwd[i] - 0.3 * cam->up[i] + 0.8 * cam->right[i];
    }
    sfb__rnormalize(V->key);
    sfb__rnormalize(V->fill);
    /* the light plane of the highlight lines: facing the object from the camera's side, lines
     * running at 30 degrees from the picture's vertical */
    V->lightdist = (c->light_distance > 0.0f ? c->light_distance : SFB__RENDER_DEFAULT_LIGHT_DISTANCE) * V->radius;
    V->spacing = 2.0 * V->radius / (c->stripes > 0.0f ? c->stripes : SFB__RENDER_DEFAULT_STRIPES);
    for (i = 0; i < 3; ++i) {
        V->light_m[i] = -cam->fwd[i];
        V->light_e[i] = cos(SFB__PI / 6.0) * cam->up[i] + sin(SFB__PI / 6.0) * cam->right[i];
        V->light_a[i] = V->centre[i] + V->lightdist * V->light_m[i];
    }
    sfb__rcross(V->light_m, V->light_e, V->light_d);
    sfb__rnormalize(V->light_d);
}

/* Projects every vertex into pv (a non-finite one gets z = -1). */
static void sfb__render_project(const sfb_mesh_data *m, const float *pos, const sfb__camera *cam, sfb__pv *pv) {
    int i;
    for (i = 0; i < m->vertex_count; ++i) {
        const float *p = pos + 3 * (size_t)i;
        double d[3], xc, yc, zc;
        if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) { pv[i].z = -1.0; pv[i].x = pv[i].y = pv[i].q = 0.0; continue; }
        d[0] = p[0] - cam->eye[0]; d[1] = p[1] - cam->eye[1]; d[2] = p[2] - cam->eye[2];
        xc = sfb__rdot(d, cam->right); yc = sfb__rdot(d, cam->up); zc = sfb__rdot(d, cam->fwd);
        pv[i].z = zc;
        if (cam->ortho) {
            pv[i].q = 1.0;
            pv[i].x = cam->cx + cam->focal * xc;
            pv[i].y = cam->cy - cam->focal * yc;
        } else {
            pv[i].q = zc > 0.0 ? 1.0 / zc : 0.0;
            pv[i].x = cam->cx + cam->focal * xc * pv[i].q;
            pv[i].y = cam->cy - cam->focal * yc * pv[i].q;
        }
    }
}

/* Pass 1: fan-triangulates and rasterizes every face that is not a hole; a face with a
 * non-finite vertex or one behind the near plane is skipped (counted in *skipped). */
static sfb_result sfb__render_rasterize(sfb_context *ctx, sfb__raster *R, const sfb_mesh_data *m, const sfb__pv *pv,
                                        const unsigned char *hole, double radius, int *skipped) {
    const sfb__camera *cam = R->cam;
    const float *pos = R->pos;
    double near_z = cam->ortho ? -HUGE_VAL : 1e-3 * radius;
    size_t off;
    sfb_result r;
    int f, i;
    for (f = 0, off = 0; f < m->face_count; off += (size_t)m->face_sizes[f], ++f) {
        const int *fv = m->face_vertices + off;
        int n = m->face_sizes[f], bad = 0, t;
        double fn[3];
        if ((f & 255) == 255 && (r = sfb__progress(ctx, 0.6f * (float)f / (float)m->face_count, "render")) != SFB_SUCCESS) return r;
        if (hole && hole[f]) continue;
        for (i = 0; i < n; ++i) {
            const float *p = pos + 3 * (size_t)fv[i];
            if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) bad = 1;
            else if (!(pv[fv[i]].z > near_z)) bad = 1;
        }
        if (bad) { ++*skipped; continue; }
        sfb__polygon_normal(pos, fv, n, fn);
        if (!(sfb__rnormalize(fn) > 0.0)) { fn[0] = -cam->fwd[0]; fn[1] = -cam->fwd[1]; fn[2] = -cam->fwd[2]; }
        for (t = 1; t + 1 < n; ++t) {
            sfb__pv tri[3];
            int vi[3], real[3];
            vi[0] = fv[0]; vi[1] = fv[t]; vi[2] = fv[t + 1];
            tri[0] = pv[vi[0]]; tri[1] = pv[vi[1]]; tri[2] = pv[vi[2]];
            real[0] = 1;              /* (t, t+1) */
            real[1] = t + 2 == n;     /* (t+1, 0): the polygon's last side */
            real[2] = t == 1;         /* (0, 1): its first side */
            sfb__raster_tri(R, tri, vi, real, fn);
        }
    }
    return SFB_SUCCESS;
}

/* Pass 2a (highlight): the stripe coordinate of every covered pixel, kept in its scalar slot
 * (+inf where the normal is parallel to the light plane or the value is out of range). */
static void sfb__render_stripes(const sfb__raster *R, size_t npix, const sfb_render_config *c, const sfb__render_view *V) {
    const sfb__camera *cam = &V->cam;
    size_t k;
    int i;
    for (k = 0; k < npix; ++k) {
        float *g = R->gb + k * SFB__RENDER_GB;
        double n[3], p[3], v[3], nm, wv;
        if (!(g[0] < (float)HUGE_VAL)) continue;
        n[0] = g[1]; n[1] = g[2]; n[2] = g[3];
        p[0] = g[4]; p[1] = g[5]; p[2] = g[6];
        sfb__rnormalize(n);
        if (cam->ortho) { v[0] = -cam->fwd[0]; v[1] = -cam->fwd[1]; v[2] = -cam->fwd[2]; }
        else { v[0] = cam->eye[0] - p[0]; v[1] = cam->eye[1] - p[1]; v[2] = cam->eye[2] - p[2]; }
        if (sfb__rdot(n, v) < 0.0) { n[0] = -n[0]; n[1] = -n[1]; n[2] = -n[2]; }
        nm = sfb__rdot(n, V->light_m);
        if (fabs(nm) < 1e-6) { g[7] = (float)HUGE_VAL; continue; }
        if (c->light_at_infinity) {
            wv = V->lightdist * sfb__rdot(n, V->light_d) / nm / V->spacing;
        } else {
            double ap[3], mu, X[3];
            for (i = 0; i < 3; ++i) ap[i] = V->light_a[i] - p[i];
            mu = sfb__rdot(ap, V->light_m) / nm;
            for (i = 0; i < 3; ++i) X[i] = p[i] + mu * n[i] - V->light_a[i];
            wv = sfb__rdot(X, V->light_d) / V->spacing;
        }
        g[7] = isfinite(wv) && fabs(wv) < 1e7 ? (float)wv : (float)HUGE_VAL;
    }
}

/* The highlight colour of pixel (x, y) (index pix, stripe coordinate wv, diffuse term diff)
 * over its lit grey base in rgb: a dark blue and a cyan band per period, filtered by the pixel's
 * footprint in stripe periods. */
static void sfb__render_highlight(const sfb__raster *R, int x, int y, size_t pix, double wv, double diff, double *rgb) {
    int w = R->w, h = R->h, i;
    double dx = HUGE_VAL, dy = HUGE_VAL, fw, cb, cc;
    /* the pixel footprint in stripe periods: the smaller one-sided difference per
     * axis (robust at silhouettes, where one neighbour is another surface) */
    if (x > 0 && R->gb[(pix - 1) * SFB__RENDER_GB + 7] < 1e30f) dx = fabs(wv - R->gb[(pix - 1) * SFB__RENDER_GB + 7]);
    if (x + 1 < w && R->gb[(pix + 1) * SFB__RENDER_GB + 7] < 1e30f) {
        double d2 = fabs(wv - R->gb[(pix + 1) * SFB__RENDER_GB + 7]);
        if (d2 < dx) dx = d2;
    }
    if (y > 0 && R->gb[(pix - (size_t)w) * SFB__RENDER_GB + 7] < 1e30f)
        dy = fabs(wv - R->gb[(pix - (size_t)w) * SFB__RENDER_GB + 7]);
    if (y + 1 < h && R->gb[(pix + (size_t)w) * SFB__RENDER_GB + 7] < 1e30f) {
        double d2 = fabs(wv - R->gb[(pix + (size_t)w) * SFB__RENDER_GB + 7]);
        if (d2 < dy) dy = d2;
    }
    if (dx == HUGE_VAL) dx = 0.0;
    if (dy == HUGE_VAL) dy = 0.0;
    fw = dx + dy;
    cb = sfb__band_cover(wv, fw, 0.00, 0.22);
    cc = sfb__band_cover(wv, fw, 0.50, 0.72);
    {
        double lum = 0.45 + 0.55 * diff;
        double blue[3], cyan[3];
        blue[0] = 0.05 * lum; blue[1] = 0.12 * lum; blue[2] = 0.75 * lum;
        cyan[0] = 0.10 * lum; cyan[1] = 0.80 * lum; cyan[2] = 0.95 * lum;
        for (i = 0; i < 3; ++i) rgb[i] = rgb[i] * (1.0 - cb - cc) + blue[i] * cb + cyan[i] * cc;
    }
}

/* The colour of covered pixel (x, y) (index pix) in the config's mode, before gamma and the
 * edge overlay: the normal as RGB, or lit (diffuse, specular, fill) grey, scalar map or
 * highlight lines. */
static void sfb__render_lit(const sfb__raster *R, const sfb_render_config *c, const sfb__render_view *V, int x, int y, size_t pix,
                            double *rgb) {
    const sfb__camera *cam = &V->cam;
    const float *g = R->gb + pix * SFB__RENDER_GB;
    double n[3], p[3], v[3], diff, spec, hv[3];
    int i;
    n[0] = g[1]; n[1] = g[2]; n[2] = g[3];
    p[0] = g[4]; p[1] = g[5]; p[2] = g[6];
    sfb__rnormalize(n);
    if (c->mode == SFB_RENDER_NORMALS) {
        for (i = 0; i < 3; ++i) rgb[i] = 0.5 + 0.5 * n[i];
        return;
    }
    if (cam->ortho) { v[0] = -cam->fwd[0]; v[1] = -cam->fwd[1]; v[2] = -cam->fwd[2]; }
    else { v[0] = cam->eye[0] - p[0]; v[1] = cam->eye[1] - p[1]; v[2] = cam->eye[2] - p[2]; }
    sfb__rnormalize(v);
    if (sfb__rdot(n, v) < 0.0) { n[0] = -n[0]; n[1] = -n[1]; n[2] = -n[2]; }
    diff = sfb__rdot(n, V->key);
    if (diff < 0.0) diff = 0.0;
    for (i = 0; i < 3; ++i) hv[i] = V->key[i] + v[i];
    sfb__rnormalize(hv);
    spec = sfb__rdot(n, hv);
    spec = spec > 0.0 ? pow(spec, 48.0) : 0.0;
    if (c->mode == SFB_RENDER_SHADED) {
        double fl = sfb__rdot(n, V->fill), lum;
        if (fl < 0.0) fl = 0.0;
        lum = 0.72 * (0.16 + 0.70 * diff + 0.18 * fl) + 0.30 * spec;
        rgb[0] = rgb[1] = rgb[2] = lum;
    } else if (c->mode == SFB_RENDER_WEIGHTS) {
        double lum = 0.55 + 0.45 * diff;
        sfb__colormap(g[7], rgb);
        for (i = 0; i < 3; ++i) rgb[i] = rgb[i] * lum + 0.12 * spec;
    } else {
        /* highlight: a lit light-grey base with a dark blue and a cyan band per period */
        double base = 0.42 + 0.55 * diff, wv = g[7];
        rgb[0] = rgb[1] = rgb[2] = base;
        if (wv < 1e30) sfb__render_highlight(R, x, y, pix, wv, diff, rgb);
    }
}

/* Pass 2: shades every pixel into rgba (the background where nothing is drawn), counting the
 * covered ones in *object_pixels. */
static sfb_result sfb__render_shade(sfb_context *ctx, const sfb__raster *R, const sfb_render_config *c, const sfb__render_view *V,
                                    const unsigned char *bg, unsigned char *rgba, long *object_pixels) {
    int w = R->w, h = R->h, x, y, i;
    sfb_result r;
    for (y = 0; y < h; ++y) {
        if ((y & 15) == 0 && (r = sfb__progress(ctx, 0.6f + 0.4f * (float)y / (float)h, "render")) != SFB_SUCCESS) return r;
        for (x = 0; x < w; ++x) {
            size_t pix = (size_t)y * (size_t)w + (size_t)x;
            const float *g = R->gb + pix * SFB__RENDER_GB;
            unsigned char *o = rgba + 4 * pix;
            double rgb[3], e;
            if (!(g[0] < (float)HUGE_VAL)) { memcpy(o, bg, 4); continue; }
            ++*object_pixels;
            sfb__render_lit(R, c, V, x, y, pix, rgb);
            /* a little gamma on lit colours, so that the darker half keeps detail (normals are
             * written as they are) */
            if (c->mode != SFB_RENDER_NORMALS)
                for (i = 0; i < 3; ++i) rgb[i] = pow(sfb__rclamp(rgb[i], 0.0, 1.0), 1.0 / 1.6);
            if (R->edge && R->edge[pix]) {
                e = R->edge[pix] / 255.0 * 0.85;
                for (i = 0; i < 3; ++i) rgb[i] = rgb[i] * (1.0 - e) + 0.08 * e;
            }
            o[0] = sfb__to_byte(rgb[0]); o[1] = sfb__to_byte(rgb[1]); o[2] = sfb__to_byte(rgb[2]); o[3] = 255;
        }
    }
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_render(sfb_context *ctx, const sfb_mesh_data *m, const sfb_render_config *cfg, sfb_image *out) {
    sfb_render_config c;
    const float *pos = NULL, *nrm = NULL, *scal = NULL;
    int w = 0, h = 0, f;
    size_t npix, bytes, gbytes, k;
    sfb__render_view V;
    sfb__raster R;
    sfb__pv *pv = NULL;
    unsigned char *hole = NULL, *rgba = NULL;
    unsigned char bg[4];
    sfb_result r = SFB_SUCCESS;
    long object_pixels = 0;
    int skipped = 0;
    if (out) memset(out, 0, sizeof *out);
    if (!ctx) return SFB_INVALID_ARGS;
    if (!m || !out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_render: NULL argument");
    c = cfg ? *cfg : sfb_render_config_init(SFB_RENDER_SHADED);
    if ((r = sfb__render_check(ctx, m, &c, &pos, &nrm, &scal, &w, &h)) != SFB_SUCCESS) return r;
    if (c.mode != SFB_RENDER_WEIGHTS) scal = NULL;
    if (c.background[0] | c.background[1] | c.background[2] | c.background[3]) memcpy(bg, c.background, 4);
    else { bg[0] = 44; bg[1] = 48; bg[2] = 56; bg[3] = 255; }

    /* memory: G-buffer, edge coverage, projected vertices, hole flags, the picture */
    npix = (size_t)w * (size_t)h;
    if (!sfb__mul_size(npix, SFB__RENDER_GB * sizeof(float), &gbytes) || !sfb__mul_size(npix, 4, &bytes))
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "image too large");
    if ((r = sfb__progress(ctx, 0.0f, "render")) != SFB_SUCCESS) return r;
    R.gb = (float *)sfb__alloc(ctx, gbytes);
    R.edge = c.draw_edges ? (unsigned char *)sfb__calloc(ctx, npix, 1) : NULL;
    pv = (sfb__pv *)sfb__alloc(ctx, ((size_t)m->vertex_count + 1) * sizeof(sfb__pv));
    hole = m->hole_count > 0 ? (unsigned char *)sfb__calloc(ctx, (size_t)m->face_count, 1) : NULL;
    rgba = (unsigned char *)sfb__alloc(ctx, bytes);
    if (!R.gb || (c.draw_edges && !R.edge) || !pv || (m->hole_count > 0 && !hole) || !rgba) {
        r = sfb__oom(ctx, "the picture (render)");
        goto done;
    }
    for (f = 0; f < m->hole_count; ++f) hole[m->holes[f]] = 1;
    /* depth "none"; and no stripe coordinate (slot 7): the highlight filter reads the slot of
     * every neighbour, background ones included, which were left uninitialised (a picture that
     * depended on what the allocator handed back) */
    for (k = 0; k < npix; ++k) R.gb[k * SFB__RENDER_GB] = R.gb[k * SFB__RENDER_GB + 7] = (float)HUGE_VAL;

    sfb__render_view_setup(m, pos, &c, w, h, &V);
    sfb__render_project(m, pos, &V.cam, pv);
    /* pass 1: rasterize */
    R.w = w; R.h = h; R.pos = pos; R.nrm = nrm; R.scal = scal; R.cam = &V.cam; R.draw_edges = c.draw_edges != 0;
    if ((r = sfb__render_rasterize(ctx, &R, m, pv, hole, V.radius, &skipped)) != SFB_SUCCESS) goto done;
    /* pass 2a (highlight): stripe coordinate per pixel, kept in the scalar slot */
    if (c.mode == SFB_RENDER_HIGHLIGHT) sfb__render_stripes(&R, npix, &c, &V);
    /* pass 2: shade */
    if ((r = sfb__render_shade(ctx, &R, &c, &V, bg, rgba, &object_pixels)) != SFB_SUCCESS) goto done;
    if ((r = sfb__progress(ctx, 1.0f, "render")) != SFB_SUCCESS) goto done;
    out->width = w;
    out->height = h;
    out->rgba = rgba;
    out->object_pixels = object_pixels > 2147483647L ? 2147483647 : (int)object_pixels;
    out->skipped_faces = skipped;
    out->ctx_ = ctx;
    rgba = NULL;
done:
    sfb__free(ctx, R.gb);
    sfb__free(ctx, R.edge);
    sfb__free(ctx, pv);
    sfb__free(ctx, hole);
    sfb__free(ctx, rgba);
    return r;
}
#line 1 "src/analyze.c"
/* Seed 003: surface quality analysis evaluated exactly per pixel (sfb_surface_analyze).
 *
 * 1. Proxy: every parametric face that is not a hole is sampled on a uniform grid of 2^level
 *    segments per edge (a quad: (n+1)^2 points, a triangle: (n+1)(n+2)/2), evaluated through
 *    the backend's eval_patches; each grid triangle knows its face and its corners' (u,v) in
 *    that face, so rasterising it gives per pixel (face, u, v, depth) with perspective-correct
 *    (u,v): a pixel's (u,v) is always in its own face's frame. The backend's `raster` kernel
 *    draws it (sfb__raster_job: ref's on the CPU, simd's in bands over its threads, gl's and
 *    osmesa's in GL). Thin or grazing triangles (near a silhouette) also leave a seed in the
 *    uncovered pixels within 2 pixels of them. The faces' adjacency comes from the proxy too
 *    (sides whose ends and middle coincide).
 * 2. Projection (beyond the seed, which shades the proxy's (u,v), leaves gaps and patches them
 *    with a 1.7^2 larger viewport, its §5): each pixel is moved onto the exact surface along its
 *    own view ray. We solve in the picture plane: find (u,v) with proj(S(u,v)) = pixel centre,
 *    Newton on the 2x2 Jacobian d proj / d(u,v) = d proj / dP [S_u S_v], steps clamped to a
 *    third of the domain; a step that leaves the face carries on in the neighbour across the
 *    side it left by (at most 4 crossings), else the iterate is clamped and gives up after two
 *    steps against the border. Outcomes per attempt: HIT (residual below SFB__AN_TOL pixels),
 *    NEAR (within half a pixel after the steps: not converged), MISS (further: no surface there).
 *    Round 0 seeds the proxy pixels on a grid of every 4th pixel with their own (face, u, v),
 *    then the pixels between those hits from them (cubic Hermite in (u,v) along a picture axis,
 *    the hits' inverse screen Jacobians as tangents, across a face side in the two faces'
 *    unfolded frame), down to every pixel; an attempt that stalls over a pixel away stops
 *    early. Every later round seeds, from the hits the round
 *    before made or replaced, their 8 neighbours that are not hit yet, or hit on another face
 *    at least 1 % of the bounding radius farther away (a nearer sheet may hide them: near
 *    silhouettes the proxy's depth order is not the exact surface's); up to three faces per
 *    pixel and round; a pixel keeps its nearest hit.
 *    That grows coverage past the proxy's silhouette up to the exact one (pixels outside it MISS
 *    and stop the growth). The rounds end when a round changes nothing (at most SFB__AN_ROUNDS).
 *    Round 0's attempts own their hit slots (no two share a pixel) and run in chunks, each to
 *    its outcomes on one of the backend's threads; a hit's location and the inverse of its
 *    screen Jacobian are also kept per pixel, where the seeds and neighbour scans read them row
 *    by row.
 *    Then a proxy pixel without a hit is kept on the proxy's point when one attempt was NEAR
 *    (counted: fallback_pixels), and dropped when all MISSed (the exact surface is not there:
 *    counted: dropped_pixels); hits outside the proxy are counted as grown_pixels.
 * 3. Shade: the hits' exact positions, derivatives and normals (second derivatives for
 *    CURVATURE, evaluated once more there) go to the backend's `shade` kernel (ref's when it
 *    lacks one), which returns the mode's values.
 * 4. Colour: per pixel from its values, the band or pattern filtered by its footprint (the
 *    smaller one-sided difference of the value to its neighbours, per axis), so bands finer than
 *    a pixel fade to their average colour.
 * polygon_based: step 2 is skipped; position and normal are the proxy's interpolated limit
 * positions and limit normals (the polygon-based method of the seed's Fig. 7b).
 * Choices (the seed is silent): the camera's default orbit and the default light plane come
 * from the control mesh's bounding box, never the proxy's, so that the picture does not depend
 * on the level; the mean curvature's sign follows the normal turned toward the viewer, so a
 * surface bulging toward the eye has H > 0. */

#define SFB__AN_DEFAULT_W 640
#define SFB__AN_DEFAULT_H 480
#define SFB__AN_DEFAULT_LEVEL 2   /* a polygon-based picture's proxy level for a config's 0 (the others: sfb__an_auto_level) */
#define SFB__AN_DEFAULT_STEPS 8
#define SFB__AN_TOL 2e-3      /* pixels: a hit (looser ones let stripe classes flip where stripes are dense) */
#define SFB__AN_NEAR 0.5      /* pixels: within this, a non-converged attempt may fall back to the proxy */
#define SFB__AN_TOL2 (SFB__AN_TOL * SFB__AN_TOL)   /* the same, squared (sfb__an_step compares squared residuals) */
#define SFB__AN_NEAR2 (SFB__AN_NEAR * SFB__AN_NEAR)
#define SFB__AN_ROUNDS 64
#define SFB__AN_ANCHOR 4      /* pixels: round 0 starts from the proxy on this grid, the others between its hits */
#define SFB__AN_BATCH 32768   /* round 0's attempts run in batches of this many (the buffers stay small and warm: at
                                 1024 x 1024 on catmark_car, one batch per part held 41 MB, freshly faulted in per call),
                                 each in chunks of 1024 on the backend's threads (sfb__an_fresh) */
#define SFB__AN_BATCH_WS 131072 /* the same with a workspace, whose buffers are kept: fewer batches, fewer waits for the
                                 last chunk (catmark_car 1024 x 1024 on 2 threads: about 2 ms less); the pictures do not
                                 depend on the batch size (sfb__an_predict) */
#define SFB__AN_PARALLEL 4096  /* items: from this many on, a per-item loop goes to the backend's threads (sfb__parallel) */
#define SFB__AN_OUT_NEW_HIT 4
#define SFB__AN_CHUNKS 64     /* round 0: a batch runs in at most this many chunks, of 1024 attempts or more on average (sfb__an_fresh) */
#define SFB__AN_DILATE 2.0    /* pixels: uncovered pixels this close to a thin proxy triangle are seeded from it too */
#define SFB__AN_MARGIN 0.92   /* the bounding sphere's share of the smaller side (as sfb_render) */

SFB_API sfb_analyze_config sfb_analyze_config_init(int mode) {
    sfb_analyze_config c;
    memset(&c, 0, sizeof c);
    c.mode = mode;
    return c;
}

SFB_API void sfb_analysis_free(sfb_analysis *a) {
    if (!a) return;
    if (a->ctx_) {
        sfb__free(a->ctx_, a->rgba);
        sfb__free(a->ctx_, a->values);
        sfb__free(a->ctx_, a->classes);
        sfb__free(a->ctx_, a->hits);
    }
    memset(a, 0, sizeof *a);
}

static void sfb__an_unit3f(float *a) {
    double l = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
    if (l > 0.0 && isfinite(l)) { a[0] = (float)(a[0] / l); a[1] = (float)(a[1] / l); a[2] = (float)(a[2] / l); }
}
static int sfb__an_finite3(const float *p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }
/* The camera: right/up/forward unit vectors, pixels per unit (focal), the picture centre. */
typedef struct sfb__an_cam {
    double eye[3], right[3], up[3], fwd[3], focal, cx, cy, near_z;
    int ortho;
} sfb__an_cam;

/* Projects p: screen x, y (pixels, y down) and view depth z; returns 0 behind the near plane. */
static inline int sfb__an_project(const sfb__an_cam *c, const double *p, double *sx, double *sy, double *z) {
    double d[3], xc, yc, zc;
    d[0] = p[0] - c->eye[0]; d[1] = p[1] - c->eye[1]; d[2] = p[2] - c->eye[2];
    xc = sfb__rdot(d, c->right); yc = sfb__rdot(d, c->up); zc = sfb__rdot(d, c->fwd);
    *z = zc;
    if (c->ortho) { *sx = c->cx + c->focal * xc; *sy = c->cy - c->focal * yc; return 1; }
    if (!(zc > c->near_z)) return 0;
    *sx = c->cx + c->focal * xc / zc;
    *sy = c->cy - c->focal * yc / zc;
    return 1;
}

/* The screen Jacobian of a surface point p with tangents tu, tv: j = (dsx/du, dsx/dv, dsy/du,
 * dsy/dv) and its determinant; 0 when it is singular (or not finite). */
static inline int sfb__an_jacobian(const sfb__an_cam *c, const double *p, const double *tu, const double *tv, double j[4], double *det) {
    const double tux = sfb__rdot(tu, c->right), tuy = sfb__rdot(tu, c->up), tvx = sfb__rdot(tv, c->right), tvy = sfb__rdot(tv, c->up);
    if (c->ortho) {
        j[0] = c->focal * tux; j[2] = -c->focal * tuy;
        j[1] = c->focal * tvx; j[3] = -c->focal * tvy;
    } else {
        double d[3], xc, yc, zc, tuz, tvz, zz;
        d[0] = p[0] - c->eye[0]; d[1] = p[1] - c->eye[1]; d[2] = p[2] - c->eye[2];
        xc = sfb__rdot(d, c->right); yc = sfb__rdot(d, c->up); zc = sfb__rdot(d, c->fwd);
        tuz = sfb__rdot(tu, c->fwd); tvz = sfb__rdot(tv, c->fwd);
        zz = c->focal / (zc * zc);
        j[0] = (tux * zc - xc * tuz) * zz;
        j[2] = -(tuy * zc - yc * tuz) * zz;
        j[1] = (tvx * zc - xc * tvz) * zz;
        j[3] = -(tvy * zc - yc * tvz) * zz;
    }
    *det = j[0] * j[3] - j[1] * j[2];
    return fabs(*det) > 1e-18 && isfinite(*det);
}

/* ---- configuration checks ---- */
static int sfb__an_finite_n(const float *v, int n) {
    int i;
    for (i = 0; i < n; ++i) if (!isfinite(v[i])) return 0;
    return 1;
}
static sfb_result sfb__an_check(sfb_context *ctx, const sfb_analyze_config *c, int *w, int *h, int *level) {
    if (c->width == 0 && c->height == 0) { *w = SFB__AN_DEFAULT_W; *h = SFB__AN_DEFAULT_H; }
    else { *w = c->width; *h = c->height; }
    if (*w <= 0 || *h <= 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "analysis image size %d x %d: both must be >= 1 (both 0: the default 640 x 480)",
                          c->width, c->height);
    if (*w > SFB_ANALYZE_MAX_SIZE || *h > SFB_ANALYZE_MAX_SIZE)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "analysis image size %d x %d is over the limit of %d (SFB_ANALYZE_MAX_SIZE)",
                          *w, *h, SFB_ANALYZE_MAX_SIZE);
    if (c->mode < 0 || c->mode >= SFB_ANALYZE_MODE_COUNT_)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown analysis mode %d", c->mode);
    *level = c->level; /* 0: chosen in sfb_surface_analyze (sfb__an_auto_level) */
    if (*level < 0 || *level > SFB_ANALYZE_MAX_LEVEL)
        return sfb__error(ctx, c->level < 0 ? SFB_INVALID_ARGS : SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "proxy level %d is outside 1..%d",
                          c->level, SFB_ANALYZE_MAX_LEVEL);
    if (c->newton_steps < 0 || c->newton_steps > 64)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "newton_steps %d is outside 0..64", c->newton_steps);
    if (c->light_pattern < SFB_LIGHT_STRIPES || c->light_pattern > SFB_LIGHT_IMAGE)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown light pattern %d", c->light_pattern);
    if (c->curvature < SFB_CURVATURE_GAUSSIAN || c->curvature > SFB_CURVATURE_MAX_ABS)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown curvature kind %d", c->curvature);
    if (c->polygon_based && c->mode == SFB_ANALYZE_CURVATURE)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the polygon-based method has no second derivatives: no CURVATURE picture");
    if (!isfinite(c->yaw) || !isfinite(c->pitch) || !isfinite(c->zoom) || c->zoom < 0.0f || !isfinite(c->fov) || c->fov < 0.0f ||
        (!c->orthographic && !(c->fov < 179.0f)))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "view (yaw %g, pitch %g, zoom %g, fov %g): angles must be finite, zoom and fov >= 0, fov < 179 degrees",
                          (double)c->yaw, (double)c->pitch, (double)c->zoom, (double)c->fov);
    if (!isfinite(c->near_plane) || c->near_plane < 0.0f)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "near plane %g must be finite and >= 0 (0: automatic)", (double)c->near_plane);
    if (!c->camera_set && !sfb__an_finite_n(c->up, 3))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "the orbit's up direction (%g, %g, %g) is not finite", (double)c->up[0],
                          (double)c->up[1], (double)c->up[2]);
    if (c->camera_set) {
        double d[3], up[3], x[3];
        int i;
        if (!sfb__an_finite_n(c->eye, 3) || !sfb__an_finite_n(c->target, 3) || !sfb__an_finite_n(c->up, 3))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "camera eye, target or up is not finite");
        for (i = 0; i < 3; ++i) { d[i] = (double)c->target[i] - c->eye[i]; up[i] = c->up[i]; }
        if (!(sfb__rnormalize(d) > 0.0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "camera eye equals its target");
        if (!(sfb__rdot(up, up) > 0.0)) up[1] = 1.0;
        sfb__rnormalize(up);
        sfb__rcross(d, up, x);
        if (!(sqrt(sfb__rdot(x, x)) > 1e-6))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "camera up (%g, %g, %g) is parallel to the view direction",
                              (double)c->up[0], (double)c->up[1], (double)c->up[2]);
    }
    if (!isfinite(c->stripes) || c->stripes < 0.0f || c->stripes > 1e5f || !isfinite(c->stripe_width) || c->stripe_width < 0.0f ||
        c->stripe_width >= 1.0f)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "stripes %g (0..1e5) and stripe width %g ([0, 1)) out of range",
                          (double)c->stripes, (double)c->stripe_width);
    if (!sfb__an_finite_n(c->light_dir, 3) || !isfinite(c->curvature_range) || c->curvature_range < 0.0f)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "light direction or curvature range is not finite (range must be >= 0)");
    if (c->light_set) {
        double m[3], a[3], x[3];
        int i;
        if (!sfb__an_finite_n(c->light_center, 3) || !sfb__an_finite_n(c->light_normal, 3) || !sfb__an_finite_n(c->light_axis, 3) ||
            !sfb__an_finite_n(c->light_size, 2) || c->light_size[0] < 0.0f || c->light_size[1] < 0.0f)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "light plane centre, normal, axis or size is not finite (sizes >= 0)");
        for (i = 0; i < 3; ++i) { m[i] = c->light_normal[i]; a[i] = c->light_axis[i]; }
        if (!(sfb__rnormalize(m) > 0.0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "light plane normal is zero");
        sfb__rnormalize(a);
        sfb__rcross(m, a, x);
        if (!(sqrt(sfb__rdot(x, x)) > 1e-6))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "light plane axis (%g, %g, %g) is zero or parallel to its normal",
                              (double)c->light_axis[0], (double)c->light_axis[1], (double)c->light_axis[2]);
    }
    if (c->light_pattern == SFB_LIGHT_IMAGE && (c->mode == SFB_ANALYZE_REFLECTION || c->mode == SFB_ANALYZE_HIGHLIGHT)) {
        if (c->light_width <= 0 || c->light_height <= 0 || !c->light_rgba)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "image light of %d x %d texels%s: it needs texels and a size >= 1",
                              c->light_width, c->light_height, c->light_rgba ? "" : " without data");
        if (c->light_width > 16384 || c->light_height > 16384)
            return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "image light of %d x %d texels is over 16384", c->light_width,
                              c->light_height);
    }
    return SFB_SUCCESS;
}

/* ---- state of one analysis ---- */
typedef struct sfb__an {
    sfb_context *ctx;
    sfb_analysis_workspace *ws; /* NULL: none */
    const sfb_surface *s;
    const sfb_analyze_config *c;
    int w, h, tri, nf, R, per;   /* picture, triangle domain, parametric faces, grid segments, grid points per face */
    sfb__an_cam cam;
    double centre[3], radius;
    /* the proxy: grid points of every face (NaN for holes) */
    float *gpos, *gnrm;
    sfb__raster_vertex *rv;      /* the grid points in the picture */
    int *rtri, ntri;             /* the proxy's triangles (sfb__raster_job) */
    float *ybox;                 /* their y boxes (sfb__raster_job): rtri's, then the raster order's */
    float *zmax;                 /* the raster's scratch (sfb__raster_job) */
    unsigned char *ucov;         /* per 8 pixels of a row after the raster: 1 where one is not drawn (sfb__an_ucov_rows) */
    /* per pixel */
    float *depth;                /* +inf: empty */
    int *face;                   /* proxy face, -1: none */
    float *uv;                   /* proxy (u,v) */
    float *ppos, *pnrm;          /* polygon_based: interpolated proxy position and normal */
    int *cface;                  /* uncovered pixels within SFB__AN_DILATE pixels of a proxy triangle: its face, */
    float *cuv, *cdist;          /* the (u,v) of its nearest point, the distance in pixels */
    int *hit;                    /* index into the hit arrays, -1: none */
    sfb_location *hl;            /* per pixel (valid where hit >= 0): its hit's location, and */
    int seeding;                 /* round 0 runs a part that seeds later ones: hinv is kept up to date (sfb__an_store_hit) */
    float *hinv;                 /* d(u,v)/d(pixel x), d(u,v)/d(pixel y) there (NaN: singular): round 0's seeds and neighbour scans
                                    read these per pixel, row by row (the hit slots lie in round 0's part order, scattered) */
    int *adj;                    /* per face and side: (4 * neighbour face + its side) * 2 + reversed, -1: none */
    unsigned char *state;        /* SFB__AN_* per pixel */
    unsigned char *cand;         /* per pixel: 2 drawn by the proxy (face), 1 seeded beside a thin triangle (cface), 0 neither */
    /* hits (compact) */
    int nhit;
    int *chg, nchg;              /* the pixels of the hits made or replaced by the last batch of attempts */
    unsigned char *nbm;          /* per change: the neighbours it seeds (sfb__an_neighbours) */
    int *hpix;
    float *hpos, *hdu, *hdv, *hnrm, *hdepth; /* hdu, hdv: CURVATURE only (else NULL) */
} sfb__an;

enum { SFB__AN_NONE = 0, SFB__AN_TRIED_NEAR = 1, SFB__AN_HIT = 2 };

/* ---- the workspace (sfb_analysis_workspace): the large scratch buffers, by slot ---- */
enum {
    SFB__WS_GPOS, SFB__WS_GNRM, SFB__WS_RV, SFB__WS_RTRI, SFB__WS_DEPTH, SFB__WS_FACE, SFB__WS_UV, SFB__WS_HIT, SFB__WS_CFACE,
    SFB__WS_CUV, SFB__WS_CDIST, SFB__WS_STATE, SFB__WS_PPOS, SFB__WS_PNRM, SFB__WS_HPIX, SFB__WS_HLOC, SFB__WS_HPOS, SFB__WS_HDU,
    SFB__WS_HDV, SFB__WS_HNRM, SFB__WS_HDEPTH, SFB__WS_CHG, SFB__WS_TRIES, SFB__WS_LOCS, SFB__WS_BUF, SFB__WS_MARK, SFB__WS_ROWAT,
    SFB__WS_NBM, SFB__WS_HV1, SFB__WS_HV2, SFB__WS_V2, SFB__WS_SEC, SFB__WS_HINV, SFB__WS_HL, SFB__WS_CAND, SFB__WS_ZMAX, SFB__WS_NBC, SFB__WS_ADJ, SFB__WS_UCOV, SFB__WS_DONE, SFB__WS_YBOX, SFB__WS_COUNT
};
struct sfb_analysis_workspace {
    sfb_context *ctx;
    void *p[SFB__WS_COUNT];
    size_t n[SFB__WS_COUNT];
    int mark_base; /* the projection's round tags in the kept mark buffer start above it (sfb__an_project_all) */
    /* the proxy (GPOS, GNRM) and the face adjacency (ADJ) in the slots belong to the surface of
     * this serial at this level when proxy_ok (adj_ok): they depend on nothing else (not on the
     * view), so an analysis of it from another view reuses them (0: none kept) */
    unsigned long proxy_serial;
    int proxy_level, proxy_ok, adj_ok;
};

SFB_API sfb_result sfb_analysis_workspace_create(sfb_context *ctx, sfb_analysis_workspace **out) {
    sfb_analysis_workspace *ws;
    if (out) *out = NULL;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_analysis_workspace_create: NULL output");
    ws = (sfb_analysis_workspace *)sfb__alloc(ctx, sizeof *ws);
    if (!ws) return sfb__oom(ctx, "the analysis workspace");
    memset(ws, 0, sizeof *ws);
    ws->ctx = ctx;
    *out = ws;
    return SFB_SUCCESS;
}

SFB_API void sfb_analysis_workspace_destroy(sfb_analysis_workspace *ws) {
    int k;
    if (!ws) return;
    for (k = 0; k < SFB__WS_COUNT; ++k) sfb__free(ws->ctx, ws->p[k]);
    sfb__free(ws->ctx, ws);
}

SFB_API size_t sfb_analysis_workspace_bytes(const sfb_analysis_workspace *ws) {
    size_t b = 0;
    int k;
    if (!ws) return 0;
    for (k = 0; k < SFB__WS_COUNT; ++k) b += ws->n[k];
    return b;
}

/* A scratch buffer of at least `bytes` for slot `slot`: the workspace's (grown when too small:
 * the old contents are lost), else a fresh allocation. *fresh (when given) says whether the
 * memory is newly allocated. NULL when the allocation failed. */
static void *sfb__an_get(const sfb__an *A, int slot, size_t bytes, int *fresh) {
    sfb_analysis_workspace *ws = A->ws;
    if (fresh) *fresh = 1;
    if (!ws) return sfb__alloc(A->ctx, bytes);
    if (ws->p[slot] && ws->n[slot] >= bytes) {
        if (fresh) *fresh = 0;
        return ws->p[slot];
    }
    sfb__free(A->ctx, ws->p[slot]);
    ws->n[slot] = 0;
    ws->p[slot] = sfb__alloc(A->ctx, bytes);
    if (ws->p[slot]) ws->n[slot] = bytes;
    return ws->p[slot];
}

/* sfb__an_get zeroed (calloc). */
static void *sfb__an_get_zeroed(const sfb__an *A, int slot, size_t bytes) {
    void *p;
    if (!A->ws) return sfb__calloc(A->ctx, bytes, 1);
    p = sfb__an_get(A, slot, bytes, NULL);
    if (p) memset(p, 0, bytes);
    return p;
}

/* Grows slot's buffer p to `bytes`, keeping its contents (realloc); NULL when it failed (p is
 * then still valid). */
static void *sfb__an_regrow(const sfb__an *A, int slot, void *p, size_t bytes) {
    sfb_analysis_workspace *ws = A->ws;
    void *q = sfb__realloc(A->ctx, p, bytes);
    if (ws && q) { ws->p[slot] = q; ws->n[slot] = bytes; }
    return q;
}

/* Gives a buffer of sfb__an_get back: freed, unless the workspace keeps it. */
static void sfb__an_put(const sfb__an *A, void *p) {
    if (!A->ws) sfb__free(A->ctx, p);
}

/* sfb__parallel when there are enough items to be worth it (`work`, in items of ~100 ns),
 * else the task as one call. */
static void sfb__an_run(const sfb__an *A, void (*task)(void *arg, int first, int last), void *arg, int first, int last, double work) {
    if (work >= SFB__AN_PARALLEL) sfb__parallel(A->ctx, task, arg, first, last);
    else task(arg, first, last);
}

/* Whether the Newton attempts run in chunks over the backend's lent threads, each chunk
 * calling the backend's eval there (simd: that call then runs on that one thread); else in one
 * chunk on the calling thread, where a GPU backend's context is current and which evaluates a
 * batch at once. */
static int sfb__an_chunked(const sfb__an *A) {
    const sfb__backend_vtable *b = A->ctx->backend;
    return b && b->parallel && b->kernels_in_tasks;
}

static void sfb__an_grid_uv(const sfb__an *A, int k, double *u, double *v) {
    int R = A->R;
    if (!A->tri) { *u = (double)(k % (R + 1)) / R; *v = (double)(k / (R + 1)) / R; return; }
    {
        int j = 0, row = R + 1;
        while (k >= row) { k -= row; --row; ++j; }
        *u = (double)k / R;
        *v = (double)j / R;
    }
}
static int sfb__an_grid_index(const sfb__an *A, int i, int j) {
    int R = A->R;
    return A->tri ? j * (R + 1) - j * (j - 1) / 2 + i : j * (R + 1) + i;
}

/* Step 1a: the proxy's grid points, evaluated on the backend: face by face (a hole face's
 * points stay NaN), in runs of whole faces that lie one after another in the grid, at most
 * max(65536, points per face) locations a call; each face's (u,v) are the same grid. */
static sfb_result sfb__an_proxy(sfb__an *A) {
    const sfb__patch_table *pt = &A->s->patches;
    const size_t per = (size_t)A->per, chunk = per > ((size_t)1 << 16) ? per : ((size_t)1 << 16), n = (size_t)A->nf * per;
    sfb_location *loc = (sfb_location *)sfb__alloc(A->ctx, chunk * sizeof(sfb_location));
    float *gu = (float *)sfb__alloc(A->ctx, per * 2 * sizeof(float));
    sfb_result r = SFB_SUCCESS;
    size_t first = 0, cnt = 0, q;
    int f;
    if (!loc || !gu) {
        sfb__free(A->ctx, loc); sfb__free(A->ctx, gu);
        return sfb__oom(A->ctx, "the analysis proxy");
    }
    for (q = 0; q < per; ++q) {
        double u, v;
        sfb__an_grid_uv(A, (int)q, &u, &v);
        gu[2 * q] = (float)u;
        gu[2 * q + 1] = (float)v;
        if (A->tri && (double)gu[2 * q] + (double)gu[2 * q + 1] > 1.0) gu[2 * q + 1] = nextafterf(gu[2 * q + 1], 0.0f);
    }
    for (f = 0; f <= A->nf && r == SFB_SUCCESS; ++f) {
        const size_t base = (size_t)f * per;
        const int hole = f < A->nf && pt->ptex_root[f] == -1;
        /* the run so far is evaluated into place before a hole, before a face it has no room
         * for, and at the end */
        if (cnt > 0 && (f == A->nf || hole || cnt + per > chunk)) {
            sfb_eval_output out;
            memset(&out, 0, sizeof out);
            out.position = A->gpos + 3 * first;
            out.normal = A->gnrm + 3 * first;
            r = sfb__surface_eval_unchecked(A->s, loc, (int)cnt, &out);
            if (r == SFB_SUCCESS) r = sfb__progress(A->ctx, 0.2f * (float)(first + cnt) / (float)n, "analyze");
            cnt = 0;
        }
        if (f == A->nf || r != SFB_SUCCESS) break;
        if (hole) {
            for (q = 3 * base; q < 3 * (base + per); ++q) A->gpos[q] = A->gnrm[q] = NAN;
            continue;
        }
        if (cnt == 0) first = base;
        for (q = 0; q < per; ++q, ++cnt) {
            loc[cnt].face = f;
            loc[cnt].u = gu[2 * q];
            loc[cnt].v = gu[2 * q + 1];
        }
    }
    sfb__free(A->ctx, loc);
    sfb__free(A->ctx, gu);
    return r;
}

/* ---- parametric-face adjacency, from the proxy (for Newton steps that leave a face) ----
 * Sides: quad 0 (v = 0, u = t), 1 (u = 1, v = t), 2 (v = 1, u = 1 - t), 3 (u = 0, v = 1 - t);
 * triangle 0 (v = 0, u = t), 1 (u + v = 1, v = t), 2 (u = 0, v = 1 - t); t runs from the side's
 * first corner to its next. Two sides are neighbours when their ends and middles (proxy points,
 * evaluated from each face's own patch) coincide within 1e-5 bounding radii: a crease edge, a
 * Catmull-Clark n-gon's inner sides and a Loop edge alike. */
static void sfb__an_side_point(int tri, int side, double t, double *u, double *v) {
    if (tri) {
        if (side == 0) { *u = t; *v = 0.0; }
        else if (side == 1) { *u = 1.0 - t; *v = t; }
        else { *u = 0.0; *v = 1.0 - t; }
        return;
    }
    if (side == 0) { *u = t; *v = 0.0; }
    else if (side == 1) { *u = 1.0; *v = t; }
    else if (side == 2) { *u = 1.0 - t; *v = 1.0; }
    else { *u = 0.0; *v = 1.0 - t; }
}
/* The grid index of the point at t = k / R on a side. */
static int sfb__an_side_grid(const sfb__an *A, int side, int k) {
    int R = A->R;
    double u, v;
    sfb__an_side_point(A->tri, side, (double)k / R, &u, &v);
    return sfb__an_grid_index(A, (int)floor(u * R + 0.5), (int)floor(v * R + 0.5));
}
typedef struct sfb__an_side { long long key; int face, side; } sfb__an_side;
static int sfb__an_close(const float *a, const float *b, double tol) {
    return fabs((double)a[0] - b[0]) <= tol && fabs((double)a[1] - b[1]) <= tol && fabs((double)a[2] - b[2]) <= tol;
}
/* Sides a and b (the only two with their key) made neighbours when their ends coincide too
 * (ends[2 k], ends[2 k + 1]: the grid indices of side k's ends). */
static void sfb__an_pair(sfb__an *A, const sfb__an_side *a, const sfb__an_side *b, const int *ends, double tol) {
    const float *a0 = A->gpos + 3 * ((size_t)a->face * A->per + ends[2 * a->side]);
    const float *a1 = A->gpos + 3 * ((size_t)a->face * A->per + ends[2 * a->side + 1]);
    const float *b0 = A->gpos + 3 * ((size_t)b->face * A->per + ends[2 * b->side]);
    const float *b1 = A->gpos + 3 * ((size_t)b->face * A->per + ends[2 * b->side + 1]);
    int rev = sfb__an_close(a0, b1, tol) && sfb__an_close(a1, b0, tol), same = sfb__an_close(a0, b0, tol) && sfb__an_close(a1, b1, tol);
    if (a->face == b->face || (!rev && !same)) return;
    A->adj[4 * a->face + a->side] = (4 * b->face + b->side) * 2 + rev;
    A->adj[4 * b->face + b->side] = (4 * a->face + a->side) * 2 + rev;
}
/* Sides grouped by the hash of their middle point's cell (open addressing, a table of twice
 * as many slots as sides or more: one pass, where sorting the keys took spot.obj's 17.6k
 * sides 2-3 ms); a key held by exactly two sides pairs them (sfb__an_pair). */
static sfb_result sfb__an_adjacency(sfb__an *A) {
    int ns = A->tri ? 3 : 4, f, k, n = 0, i, mid[4], ends[8];
    double q = 1e-4 * A->radius, tol = 1e-5 * A->radius;
    size_t cap = 16, mask, h;
    sfb__an_side *sd = (sfb__an_side *)sfb__alloc(A->ctx, ((size_t)A->nf * ns + 1) * sizeof *sd);
    int *slot, *cnt, *two;
    while (cap < 2 * ((size_t)A->nf * ns + 1)) cap *= 2;
    mask = cap - 1;
    slot = (int *)sfb__alloc(A->ctx, cap * 3 * sizeof(int)); /* per slot: its first side (-1: empty); its count; its second side */
    if (!sd || !slot) {
        sfb__free(A->ctx, sd); sfb__free(A->ctx, slot);
        return sfb__oom(A->ctx, "the analysis face adjacency");
    }
    cnt = slot + cap;
    two = cnt + cap;
    for (h = 0; h < cap; ++h) slot[h] = -1;
    for (i = 0; i < A->nf * 4; ++i) A->adj[i] = -1;
    for (k = 0; k < ns; ++k) { /* the same grid points of every face */
        mid[k] = sfb__an_side_grid(A, k, A->R / 2);
        ends[2 * k] = sfb__an_side_grid(A, k, 0);
        ends[2 * k + 1] = sfb__an_side_grid(A, k, A->R);
    }
    for (f = 0; f < A->nf; ++f)
        for (k = 0; k < ns; ++k) {
            const float *m = A->gpos + 3 * ((size_t)f * A->per + mid[k]);
            unsigned long long hh = 1469598103934665603ull;
            int c;
            if (!sfb__an_finite3(m)) continue;
            for (c = 0; c < 3; ++c) { hh ^= (unsigned long long)(long long)floor(m[c] / q); hh *= 1099511628211ull; }
            sd[n].key = (long long)(hh >> 1); sd[n].face = f; sd[n].side = k;
            for (h = (size_t)(hh ^ (hh >> 29)) & mask; slot[h] >= 0 && sd[slot[h]].key != sd[n].key; h = (h + 1) & mask) {}
            if (slot[h] < 0) { slot[h] = n; cnt[h] = 1; }
            else if (cnt[h]++ == 1) two[h] = n;
            ++n;
        }
    for (h = 0; h < cap; ++h)
        if (slot[h] >= 0 && cnt[h] == 2) sfb__an_pair(A, &sd[slot[h]], &sd[two[h]], ends, tol);
    sfb__free(A->ctx, sd);
    sfb__free(A->ctx, slot);
    return SFB_SUCCESS;
}

/* The camera (the config's or sfb_render's orbit) from the control mesh's bounding box (not the
 * proxy's: the picture must not depend on the proxy's level). */
static void sfb__an_camera(sfb__an *A) {
    const sfb_analyze_config *c = A->c;
    double lo[3] = { HUGE_VAL, HUGE_VAL, HUGE_VAL }, hi[3] = { -HUGE_VAL, -HUGE_VAL, -HUGE_VAL };
    size_t n = (size_t)A->s->base_vertex_count, k;
    sfb__an_cam *cam = &A->cam;
    int i, any = 0, w = A->w, h = A->h;
    double half = 0.5 * (w < h ? w : h) * SFB__AN_MARGIN, zoom = c->zoom > 0.0f ? c->zoom : 1.0;
    double hfov = (c->fov > 0.0f && !c->orthographic ? c->fov : 30.0) * 0.5 * SFB__PI / 180.0;
    for (k = 0; k < n; ++k) {
        const float *p = A->s->base_positions + 3 * k;
        if (!sfb__an_finite3(p)) continue;
        for (i = 0; i < 3; ++i) { if (p[i] < lo[i]) lo[i] = p[i]; if (p[i] > hi[i]) hi[i] = p[i]; }
        any = 1;
    }
    if (!any) { lo[0] = lo[1] = lo[2] = -1.0; hi[0] = hi[1] = hi[2] = 1.0; }
    for (i = 0; i < 3; ++i) A->centre[i] = 0.5 * (lo[i] + hi[i]);
    A->radius = 0.5 * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (!(A->radius > 0.0) || !isfinite(A->radius)) A->radius = 1.0;
    memset(cam, 0, sizeof *cam);
    cam->ortho = c->orthographic != 0;
    cam->cx = 0.5 * w;
    cam->cy = 0.5 * h;
    if (c->camera_set) {
        double up[3];
        for (i = 0; i < 3; ++i) { cam->eye[i] = c->eye[i]; cam->fwd[i] = (double)c->target[i] - c->eye[i]; up[i] = c->up[i]; }
        sfb__rnormalize(cam->fwd);
        if (!(sfb__rdot(up, up) > 0.0)) up[1] = 1.0;
        sfb__rcross(cam->fwd, up, cam->right);
        sfb__rnormalize(cam->right);
        sfb__rcross(cam->right, cam->fwd, cam->up);
        sfb__rnormalize(cam->up);
        if (cam->ortho) cam->focal = c->fov > 0.0f ? h / (double)c->fov : half / A->radius;
        else cam->focal = 0.5 * h / tan(hfov);
    } else {
        double yaw = (c->view_set ? c->yaw : 30.0f) * SFB__PI / 180.0, pitch = (c->view_set ? c->pitch : 25.0f) * SFB__PI / 180.0;
        double dir[3], dist = A->radius / sin(hfov);
        dir[0] = cos(pitch) * sin(yaw); dir[1] = sin(pitch); dir[2] = cos(pitch) * cos(yaw);
        cam->right[0] = cos(yaw); cam->right[1] = 0.0; cam->right[2] = -sin(yaw);
        sfb__orbit_up(c->up, dir, cam->right);
        for (i = 0; i < 3; ++i) { cam->eye[i] = A->centre[i] + dist * dir[i]; cam->fwd[i] = -dir[i]; }
        sfb__rcross(cam->right, cam->fwd, cam->up);
        sfb__rnormalize(cam->up);
        cam->focal = cam->ortho ? half * zoom / A->radius : half * zoom / tan(hfov);
    }
    cam->near_z = c->near_plane > 0.0f ? c->near_plane : 1e-3 * A->radius;
}

/* The proxy level for a config's 0 (sfb_analyze_config.level): the coarsest from 1 to
 * SFB__AN_AUTO_MAX whose grid triangles cover at most SFB__AN_AUTO_PIXELS pixels each on
 * average, taking the picture of the surface as the bounding sphere's disc in this view (at
 * most the whole picture) spread over every parametric face. The proxy only seeds the
 * projection, so the picture does not depend on it (tests/analyze.c, level independence);
 * what it changes is the time: fewer, larger triangles raster and seed faster, as long as
 * the anchors' seeds stay close. Measured at 1024 x 1024, best of 3 (ms, level 1 / 2 / 3):
 * catmark_car 29.5 / 31.7 / 40.1, catmark_bishop 20.2 / 22.0 / 29.6, spot (Loop) 29.5 /
 * 34.3 / 49.5, cow (Loop) 30.3 / 35.4 / 51.5 (each level 1 here: 30 to 90 pixels per
 * triangle); catmark_torus (32 faces) 18.3 / 17.2 / 17.5 and catmark_cube (6 faces; level
 * 4: 12.6) 14.1 / 13.1 / 12.8, whose level-1 triangles cover thousands of pixels and whose
 * anchors then start far from the surface (levels 3 and 4 here). */
#define SFB__AN_AUTO_PIXELS 256.0
#define SFB__AN_AUTO_MAX 4
static int sfb__an_auto_level(const sfb__an *A) {
    const sfb__an_cam *cam = &A->cam;
    const double R = A->radius, full = (double)A->w * (double)A->h;
    double d2 = 0.0, rpx, area;
    int i, L;
    for (i = 0; i < 3; ++i) d2 += (A->centre[i] - cam->eye[i]) * (A->centre[i] - cam->eye[i]);
    if (cam->ortho) rpx = cam->focal * R;
    else rpx = d2 > 1.0001 * R * R ? cam->focal * R / sqrt(d2 - R * R) : HUGE_VAL; /* the sphere's silhouette cone */
    area = SFB__PI * rpx * rpx;
    if (!(area < full)) area = full;
    if (A->nf <= 0) return 1;
    for (L = 1; L < SFB__AN_AUTO_MAX; ++L)
        if (area <= SFB__AN_AUTO_PIXELS * (double)A->nf * (A->tri ? 1.0 : 2.0) * (double)(1 << (2 * L))) break;
    return L;
}

/* Step 1b, pass 2: the uncovered pixels within SFB__AN_DILATE pixels of a thin or grazing proxy
 * triangle (near the silhouette, where the exact surface may stick out past it, or where it
 * covers no pixel centre at all) get it as a seed: its face and the (u,v) of its nearest point
 * (the barycentric coordinates clamped), nearest triangle first. The others' neighbours are
 * reached by the projection's rounds. */
static void sfb__an_seed_tri(sfb__an *A, const int *tv, int row0, int row1) {
    const sfb__raster_vertex *S[3];
    const float *P[3];
    sfb__raster_edges t;
    double area, longest, elen[3], e1[3], e2[3], cr[3], a3, sc;
    int k, x, y;
    for (k = 0; k < 3; ++k) {
        S[k] = &A->rv[tv[k]];
        P[k] = A->gpos + 3 * (size_t)tv[k];
    }
    {
        /* the tiles of 8 x 8 pixels under the dilated box first: inside the surface's picture
         * every pixel is drawn and the triangle has nothing to seed (the box is a pixel wider
         * than sfb__raster_setup's; the tiles are sfb__an_ucov_rows') */
        const int nb = (A->w + 7) / 8;
        const unsigned char *tile = A->ucov + (size_t)A->h * (size_t)nb;
        double lx = S[0]->x, hx = lx, ly = S[0]->y, hy = ly;
        int tx0, tx1, ty0, ty1, any = 0;
        for (k = 1; k < 3; ++k) {
            if (S[k]->x < lx) lx = S[k]->x;
            if (S[k]->x > hx) hx = S[k]->x;
            if (S[k]->y < ly) ly = S[k]->y;
            if (S[k]->y > hy) hy = S[k]->y;
        }
        tx0 = (int)sfb__rclamp(floor(lx - 1.5 - SFB__AN_DILATE), 0.0, (double)A->w - 1.0) >> 3;
        tx1 = (int)sfb__rclamp(ceil(hx + 0.5 + SFB__AN_DILATE), 0.0, (double)A->w - 1.0) >> 3;
        ty0 = (int)sfb__rclamp(floor(ly - 1.5 - SFB__AN_DILATE), (double)row0, (double)row1 - 1.0) >> 3;
        ty1 = (int)sfb__rclamp(ceil(hy + 0.5 + SFB__AN_DILATE), (double)row0, (double)row1 - 1.0) >> 3;
        for (y = ty0; y <= ty1 && !any; ++y)
            for (x = tx0; x <= tx1; ++x)
                if (tile[(size_t)y * (size_t)nb + (size_t)x]) { any = 1; break; }
        if (!any) return;
    }
    /* thin or grazing first (most are neither): area as sfb__raster_setup has it */
    area = (S[1]->x - S[0]->x) * (S[2]->y - S[0]->y) - (S[2]->x - S[0]->x) * (S[1]->y - S[0]->y);
    for (k = 0; k < 3; ++k) { /* edge k, opposite corner k */
        const sfb__raster_vertex *p0 = S[(k + 1) % 3], *p1 = S[(k + 2) % 3];
        elen[k] = sqrt((p1->x - p0->x) * (p1->x - p0->x) + (p1->y - p0->y) * (p1->y - p0->y));
    }
    longest = elen[0] > elen[1] ? (elen[0] > elen[2] ? elen[0] : elen[2]) : (elen[1] > elen[2] ? elen[1] : elen[2]);
    for (k = 0; k < 3; ++k) { e1[k] = (double)P[1][k] - P[0][k]; e2[k] = (double)P[2][k] - P[0][k]; }
    sfb__rcross(e1, e2, cr);
    sc = A->cam.ortho ? A->cam.focal : A->cam.focal * 3.0 / (S[0]->z + S[1]->z + S[2]->z);
    a3 = sqrt(sfb__rdot(cr, cr)) * sc * sc; /* twice the area, in pixels, seen face-on */
    /* thin (under 2 pixels high) or grazing (seen at under 20 degrees): near the silhouette */
    if (!(fabs(area) < 2.0 * longest || fabs(area) < 0.35 * a3)) return;
    if (!sfb__raster_setup(S, A->w, A->h, SFB__AN_DILATE, &t)) return;
    if (t.y0 < row0) t.y0 = row0;
    if (t.y1 > row1 - 1) t.y1 = row1 - 1;
    if (t.y0 > t.y1) return;
    for (y = t.y0; y <= t.y1; ++y)
        for (x = t.x0; x <= t.x1; ++x) {
            const double px = x + 0.5, py = y + 0.5;
            const size_t pix = (size_t)y * (size_t)A->w + (size_t)x;
            double b[3], d = 0.0, sum;
            /* most of a thin triangle's box is drawn: whole drawn blocks of 8 skipped */
            if (!A->ucov[(size_t)y * (size_t)((A->w + 7) / 8) + (size_t)(x >> 3)]) { x |= 7; continue; }
            if (A->face[pix] >= 0) continue;
            for (k = 0; k < 3; ++k) b[k] = t.ea[k] * px + t.eb[k] * py + t.ec[k];
            if (b[0] >= 0.0 && b[1] >= 0.0 && b[2] >= 0.0) continue; /* inside: the raster's pixel */
            for (k = 0; k < 3; ++k)
                if (b[k] < 0.0 && elen[k] > 0.0) { double e = -b[k] * fabs(t.area) / elen[k]; if (e > d) d = e; }
            if (!(d <= SFB__AN_DILATE) || !(d < A->cdist[pix])) continue;
            for (k = 0; k < 3; ++k) b[k] = (b[k] < 0.0 ? 0.0 : b[k]) * S[k]->q;
            sum = b[0] + b[1] + b[2];
            if (!(sum > 0.0)) continue;
            A->cdist[pix] = (float)d;
            A->cface[pix] = tv[3];
            A->cuv[2 * pix] = (float)sfb__rclamp((b[0] * S[0]->u + b[1] * S[1]->u + b[2] * S[2]->u) / sum, 0.0, 1.0);
            A->cuv[2 * pix + 1] = (float)sfb__rclamp((b[0] * S[0]->v + b[1] * S[1]->v + b[2] * S[2]->v) / sum, 0.0, 1.0);
        }
}

/* Tile rows [t0, t1) (8 pixel rows each) after the raster: per block of 8 pixels of a row,
 * whether one is not drawn; and per tile of 8 x 8 pixels, whether one of its blocks is (after
 * the rows' blocks in A->ucov). */
static void sfb__an_ucov_rows(void *arg, int t0, int t1) {
    sfb__an *A = (sfb__an *)arg;
    const int nb = (A->w + 7) / 8;
    unsigned char *tile = A->ucov + (size_t)A->h * (size_t)nb;
    int ty, y, b, x;
    for (ty = t0; ty < t1; ++ty) {
        const int ye = 8 * ty + 8 < A->h ? 8 * ty + 8 : A->h;
        unsigned char *tu = tile + (size_t)ty * (size_t)nb;
        memset(tu, 0, (size_t)nb);
        for (y = 8 * ty; y < ye; ++y) {
            const int *f = A->face + (size_t)y * (size_t)A->w;
            unsigned char *u = A->ucov + (size_t)y * (size_t)nb;
            for (b = 0; b < nb; ++b) {
                const int xe = 8 * b + 8 < A->w ? 8 * b + 8 : A->w;
                int m = 0;
                for (x = 8 * b; x < xe; ++x) m |= f[x];
                u[b] = (unsigned char)(m < 0); /* a face of -1 sets the sign bit */
                tu[b] |= u[b];
            }
        }
    }
}

/* sfb__an_seed_tri over every proxy triangle, on rows [row0, row1) (bands of rows are
 * independent: a pixel's triangles are visited in order within its band). */
static void sfb__an_seed_rows_tri(void *arg, int row0, int row1) {
    sfb__an *A = (sfb__an *)arg;
    const double lo = row0 - 0.5 - SFB__AN_DILATE, hi = row1 + 0.5 + SFB__AN_DILATE;
    int k;
    for (k = 0; k < A->ntri; ++k) {
        /* the box's test is the vertices' (below or above the band), conservative */
        if ((double)A->ybox[2 * (size_t)k + 1] < lo || (double)A->ybox[2 * (size_t)k] > hi) continue;
        sfb__an_seed_tri(A, A->rtri + 4 * (size_t)k, row0, row1);
    }
}

/* The y boxes of the proxy's triangles [a, b) (rtri's) into A->ybox (sfb__raster_job's ybox;
 * sfb__an_order carries them into the raster's order). */
static void sfb__an_ybox(void *arg, int a, int b) {
    sfb__an *A = (sfb__an *)arg;
    const sfb__raster_vertex *rv = A->rv;
    int k;
    for (k = a; k < b; ++k) {
        const int *tv = A->rtri + 4 * (size_t)k;
        double lo = rv[tv[0]].y, hi = lo;
        float l, h;
        if (rv[tv[1]].y < lo) lo = rv[tv[1]].y;
        if (rv[tv[1]].y > hi) hi = rv[tv[1]].y;
        if (rv[tv[2]].y < lo) lo = rv[tv[2]].y;
        if (rv[tv[2]].y > hi) hi = rv[tv[2]].y;
        /* widened by more than float's rounding (2^-24 relative) before the conversion */
        l = (float)(lo - (1e-6 * fabs(lo) + 1e-3));
        h = (float)(hi + (1e-6 * fabs(hi) + 1e-3));
        A->ybox[2 * (size_t)k] = l;
        A->ybox[2 * (size_t)k + 1] = h;
    }
}

/* The proxy's grid points [a, b) projected into the picture (x NaN: behind the near plane or
 * not finite). */
static void sfb__an_project_grid(void *arg, int a, int b) {
    sfb__an *A = (sfb__an *)arg;
    int g;
    for (g = a; g < b; ++g) {
        const float *P = A->gpos + 3 * (size_t)g;
        sfb__raster_vertex *V = &A->rv[g];
        double p[3];
        V->x = NAN;
        if (!sfb__an_finite3(P)) continue;
        p[0] = P[0]; p[1] = P[1]; p[2] = P[2];
        if (!sfb__an_project(&A->cam, p, &V->x, &V->y, &V->z)) { V->x = NAN; continue; }
        V->q = A->cam.ortho ? 1.0 : 1.0 / V->z;
        sfb__an_grid_uv(A, g % A->per, &V->u, &V->v);
    }
}

/* Rows [y0, y1) after the raster: cand per pixel, and the row's proxy pixels into rowcnt[y]. */
typedef struct sfb__an_cand_job {
    sfb__an *A;
    int *rowcnt;
} sfb__an_cand_job;

static void sfb__an_candidates(void *arg, int y0, int y1) {
    const sfb__an_cand_job *J = (const sfb__an_cand_job *)arg;
    sfb__an *A = J->A;
    int y, x;
    for (y = y0; y < y1; ++y) {
        const size_t row = (size_t)y * (size_t)A->w;
        int n = 0;
        for (x = 0; x < A->w; ++x) {
            const int f = A->face[row + x];
            n += f >= 0;
            A->cand[row + x] = (unsigned char)(f >= 0 ? 2 : A->cface[row + x] >= 0 ? 1 : 0);
        }
        J->rowcnt[y] = n;
    }
}

/* Triangles of chunks [c0, c1) of SFB__AN_CHUNKS: whether each faces away (away[k]), and each
 * chunk's sum of six times the signed volumes of (centre, triangle) and of their sizes. */
typedef struct sfb__an_away_job {
    const sfb__an *A;
    unsigned char *away;
    double vol[SFB__AN_CHUNKS], mag[SFB__AN_CHUNKS];
} sfb__an_away_job;
static void sfb__an_away(void *arg, int c0, int c1) {
    sfb__an_away_job *J = (sfb__an_away_job *)arg;
    const sfb__an *A = J->A;
    int c, k;
    for (c = c0; c < c1; ++c) {
        const int a = (int)((long long)A->ntri * c / SFB__AN_CHUNKS), b = (int)((long long)A->ntri * (c + 1) / SFB__AN_CHUNKS);
        double vol = 0.0, mag = 0.0;
        for (k = a; k < b; ++k) {
            const int *tv = A->rtri + 4 * (size_t)k;
            double p[3][3], nr[3], d[3], e1[3], e2[3], t;
            int i, q;
            for (i = 0; i < 3; ++i)
                for (q = 0; q < 3; ++q) p[i][q] = (double)A->gpos[3 * (size_t)tv[i] + q] - A->centre[q];
            for (q = 0; q < 3; ++q) {
                e1[q] = p[1][q] - p[0][q];
                e2[q] = p[2][q] - p[0][q];
                d[q] = A->cam.ortho ? -A->cam.fwd[q] : A->cam.eye[q] - A->centre[q] - p[0][q];
            }
            sfb__rcross(e1, e2, nr);
            t = sfb__rdot(nr, p[0]);
            vol += t;
            mag += fabs(t);
            J->away[k] = (unsigned char)(sfb__rdot(nr, d) < 0.0);
        }
        J->vol[c] = vol;
        J->mag[c] = mag;
    }
}

/* Step 1b: the proxy's triangles reordered into ord[] (4 ints each; their y boxes into obox)
 * for the raster: those facing the eye first, then those facing away (each part in rtri's
 * order); the count of the first part.
 * "Facing" takes the outward side from the sign of the whole proxy's signed volume (+ when it is
 * about zero). On a closed proxy seen from outside, a view ray's first crossing enters it, so the
 * triangles facing away are never nearest; on an open one (catmark_car's wheel arches) some are.
 * Either way the raster draws the first part, then skips the triangles of the second that the
 * depth already drawn hides over their whole box (sfb__raster_job's nfront and zmax): the same
 * buffers, but for which of two triangles at exactly equal depth a pixel keeps. */
static int sfb__an_order(sfb__an *A, int *ord, float *obox) {
    sfb__an_away_job J;
    unsigned char *away = (unsigned char *)sfb__alloc(A->ctx, (size_t)A->ntri + 1);
    double vol = 0.0, mag = 0.0;
    int k, n = 0, sg;
    if (!away) { /* one part */
        memcpy(ord, A->rtri, (size_t)A->ntri * 4 * sizeof(int));
        memcpy(obox, A->ybox, (size_t)A->ntri * 2 * sizeof(float));
        return A->ntri;
    }
    /* over the threads in SFB__AN_CHUNKS parts, the sums combined in order */
    J.A = A;
    J.away = away;
    sfb__an_run(A, sfb__an_away, &J, 0, SFB__AN_CHUNKS, (double)A->ntri * 4.0);
    for (k = 0; k < SFB__AN_CHUNKS; ++k) { vol += J.vol[k]; mag += J.mag[k]; }
    sg = vol < -1e-6 * mag; /* 1: the proxy is inward-facing, "away" means facing the eye */
    for (k = 0; k < A->ntri; ++k)
        if (away[k] == sg) {
            memcpy(ord + 4 * (size_t)n, A->rtri + 4 * (size_t)k, 4 * sizeof(int));
            memcpy(obox + 2 * (size_t)n++, A->ybox + 2 * (size_t)k, 2 * sizeof(float));
        }
    {
        int m = n;
        for (k = 0; k < A->ntri; ++k)
            if (away[k] != sg) {
                memcpy(ord + 4 * (size_t)m, A->rtri + 4 * (size_t)k, 4 * sizeof(int));
                memcpy(obox + 2 * (size_t)m++, A->ybox + 2 * (size_t)k, 2 * sizeof(float));
            }
    }
    sfb__free(A->ctx, away);
    return n;
}

/* The raster kernel of the context's backend, or ref's. */
static sfb_result sfb__an_raster_kernel(const sfb__an *A, const sfb__raster_job *job) {
    sfb_context *ctx = A->ctx;
    const sfb__backend_vtable *be = ctx->backend;
    if (job->ntri == 0) return SFB_SUCCESS;
    if (!be || !be->raster) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks raster; using ref", be ? be->name : "none");
        return sfb__ref_raster(NULL, job);
    }
    return be->raster(ctx->backend_state, job);
}

/* Step 1b: the proxy's grid points projected into the picture (x NaN: behind the near plane or
 * not finite), its triangles (those with three such points, face by face), rasterised by the
 * backend's kernel, then pass 2's seeds around thin ones. */
static sfb_result sfb__an_raster(sfb__an *A) {
    size_t n = (size_t)A->nf * (size_t)A->per;
    int f, i, j, k, R = A->R;
    sfb__raster_job job;
    sfb_result r;
    A->ntri = 0;
    sfb__an_run(A, sfb__an_project_grid, A, 0, (int)n, (double)n); /* n <= INT_MAX: sfb_surface_analyze */
    for (f = 0; f < A->nf; ++f) {
        const size_t base = (size_t)f * (size_t)A->per;
        if (A->s->patches.ptex_root[f] == -1) continue;
        for (j = 0; j < R; ++j)
            for (i = 0; i < (A->tri ? R - j : R); ++i) {
                int q[2][3], nt = 1;
                if (A->tri) {
                    q[0][0] = sfb__an_grid_index(A, i, j); q[0][1] = sfb__an_grid_index(A, i + 1, j); q[0][2] = sfb__an_grid_index(A, i, j + 1);
                    if (i + j + 1 < R) {
                        q[1][0] = sfb__an_grid_index(A, i + 1, j); q[1][1] = sfb__an_grid_index(A, i + 1, j + 1);
                        q[1][2] = sfb__an_grid_index(A, i, j + 1);
                        nt = 2;
                    }
                } else {
                    q[0][0] = sfb__an_grid_index(A, i, j); q[0][1] = sfb__an_grid_index(A, i + 1, j); q[0][2] = sfb__an_grid_index(A, i + 1, j + 1);
                    q[1][0] = q[0][0]; q[1][1] = q[0][2]; q[1][2] = sfb__an_grid_index(A, i, j + 1);
                    nt = 2;
                }
                for (k = 0; k < nt; ++k) {
                    int *t = A->rtri + 4 * (size_t)A->ntri, c, ok = 1;
                    for (c = 0; c < 3; ++c) {
                        t[c] = (int)(base + (size_t)q[k][c]);
                        ok &= isfinite(A->rv[t[c]].x) != 0;
                    }
                    t[3] = f;
                    A->ntri += ok;
                }
            }
    }
    if ((r = sfb__progress(A->ctx, 0.2f, "analyze")) != SFB_SUCCESS) return r;
    memset(&job, 0, sizeof job);
    job.w = A->w; job.h = A->h; job.ortho = A->cam.ortho;
    job.ntri = A->ntri; job.vert = A->rv;
    job.tri = A->rtri + (size_t)A->nf * (size_t)A->per * 2 * 4; /* the second half: the raster's order */
    sfb__an_run(A, sfb__an_ybox, A, 0, A->ntri, (double)A->ntri * 2.0);
    job.ybox = A->ybox + 2 * (size_t)A->ntri;
    job.nfront = sfb__an_order(A, (int *)job.tri, A->ybox + 2 * (size_t)A->ntri);
    job.zmax = A->zmax;
    job.depth = A->depth; job.face = A->face; job.uv = A->uv;
    if (A->ppos) { job.apos = A->gpos; job.anrm = A->gnrm; job.pos = A->ppos; job.nrm = A->pnrm; }
    if ((r = sfb__an_raster_kernel(A, &job)) != SFB_SUCCESS) return r;
    if ((r = sfb__progress(A->ctx, 0.25f, "analyze")) != SFB_SUCCESS) return r;
    sfb__an_run(A, sfb__an_ucov_rows, A, 0, (A->h + 7) / 8, (double)A->w * A->h * 0.1);
    sfb__an_run(A, sfb__an_seed_rows_tri, A, 0, A->h, (double)A->ntri * 4.0);
    return SFB_SUCCESS;
}

/* ---- step 2: Newton projection, in batches ---- */
typedef struct sfb__an_try {
    int pix, x, y;     /* the pixel, its column and row */
    int k;             /* its hit slot (round 0, sfb__an_fresh) */
    double z;          /* a new hit's depth */
    float res, res2;   /* the squared residual of the last evaluation, and of the one before (pixels^2) */
    unsigned char pinned, crossed; /* steps against the border, face crossings */
    unsigned char outcome; /* 0 running, 1 hit, 2 near, 3 miss (SFB__AN_OUT_NEW_HIT: a hit the caller has yet to record) */
} sfb__an_try;

/* A new hit slot for pixel pix (not hit yet). */
static int sfb__an_new_slot(sfb__an *A, int pix) {
    const int k = A->nhit++;
    A->hpix[k] = pix;
    A->hit[pix] = k;
    A->state[pix] = SFB__AN_HIT;
    return k;
}

/* Hit slot k's data: the evaluation at loc, at depth z; and per pixel its location and, in
 * round 0's parts whose hits seed later parts (A->seeding), the inverse of its screen Jacobian
 * (computed once here: every seed taken from the hit reads it; those seeds are its only
 * readers, so round 0's last part and the later rounds, whose hits are recorded on one thread,
 * leave it, stale where they replace a hit). */
static void sfb__an_store_hit(sfb__an *A, size_t k, const sfb_location *loc, double z, const float *p, const float *du, const float *dv,
                              const float *n) {
    double pd[3], tu[3], tv[3], jac[4], det;
    const size_t pix = (size_t)A->hpix[k];
    float *m = A->hinv + 4 * pix;
    int c;
    A->hl[pix] = *loc;
    A->hdepth[k] = (float)z;
    for (c = 0; c < 3; ++c) {
        A->hpos[3 * k + c] = p[c]; A->hnrm[3 * k + c] = n[c];
        pd[c] = p[c]; tu[c] = du[c]; tv[c] = dv[c];
    }
    if (A->hdu)
        for (c = 0; c < 3; ++c) { A->hdu[3 * k + c] = du[c]; A->hdv[3 * k + c] = dv[c]; }
    if (!A->seeding) return;
    if (sfb__an_jacobian(&A->cam, pd, tu, tv, jac, &det)) {
        const double inv = 1.0 / det; /* one division (a hit's inverse is kept in float) */
        m[0] = (float)(jac[3] * inv); m[1] = (float)(-jac[2] * inv);
        m[2] = (float)(-jac[1] * inv); m[3] = (float)(jac[0] * inv);
    } else m[0] = m[1] = m[2] = m[3] = NAN;
}

/* Records the evaluation at loc as pixel pix's hit at depth z (a pixel already hit keeps the
 * nearer one). */
static void sfb__an_add_hit(sfb__an *A, int pix, const sfb_location *loc, double z, const float *p, const float *du, const float *dv,
                            const float *n) {
    int k = A->hit[pix];
    if (k >= 0) {
        if (!(z < A->hdepth[k] - 1e-6 * A->radius)) return;
    } else {
        k = sfb__an_new_slot(A, pix);
    }
    if ((size_t)A->nchg < (size_t)A->w * (size_t)A->h) A->chg[A->nchg++] = pix; /* a pixel listed twice is harmless */
    sfb__an_store_hit(A, (size_t)k, loc, z, p, du, dv, n);
}

/* Clamps (u,v) into the domain; returns 1 when it had to. */
static inline int sfb__an_clamp_domain(const sfb__an *A, double *u, double *v) {
    int moved = 0;
    if (*u < 0.0) { *u = 0.0; moved = 1; }
    if (*v < 0.0) { *v = 0.0; moved = 1; }
    if (*u > 1.0) { *u = 1.0; moved = 1; }
    if (*v > 1.0) { *v = 1.0; moved = 1; }
    if (A->tri && *u + *v > 1.0) {
        double e = 0.5 * (*u + *v - 1.0);
        *u -= e; *v -= e;
        if (*u < 0.0) { *v += *u; *u = 0.0; }
        if (*v < 0.0) { *u += *v; *v = 0.0; }
        moved = 1;
    }
    return moved;
}

/* The side a step to (uo, vo) left the domain by (clamped to (u, v)), and t on it; -1: none. */
static int sfb__an_exit_side(const sfb__an *A, double uo, double vo, double u, double v, double *t) {
    double over[4] = { 0.0, 0.0, 0.0, 0.0 };
    int k, best = -1;
    if (A->tri) {
        over[0] = -vo; over[2] = -uo; over[1] = uo + vo - 1.0;
    } else {
        over[0] = -vo; over[1] = uo - 1.0; over[2] = vo - 1.0; over[3] = -uo;
    }
    for (k = 0; k < (A->tri ? 3 : 4); ++k)
        if (over[k] > 0.0 && (best < 0 || over[k] > over[best])) best = k;
    if (best < 0) return -1;
    if (A->tri) *t = best == 0 ? u : best == 1 ? v : 1.0 - v;
    else *t = best == 0 ? u : best == 1 ? v : best == 2 ? 1.0 - u : 1.0 - v;
    *t = sfb__rclamp(*t, 0.0, 1.0);
    return best;
}

/* One Newton step of the running attempts [a, b) of a batch (sfb__an_step_job), from their
 * evaluations: the residual, the outcome, or the next (u,v) (crossing into a neighbour face
 * where the step leaves the face). A hit is not recorded here: its outcome is
 * SFB__AN_OUT_NEW_HIT, with its depth in z, and the caller records it (sfb__an_newton, in
 * attempt order on one thread; sfb__an_fresh, in its own slot). */
typedef struct sfb__an_step_job {
    const sfb__an *A;
    sfb__an_try *tries;
    sfb_location *locs;
    const float *pos, *du, *dv;
    int it, steps;
} sfb__an_step_job;

static void sfb__an_step(void *arg, int a, int b) {
    const sfb__an_step_job *J = (const sfb__an_step_job *)arg;
    const sfb__an *A = J->A;
    const float *pos = J->pos, *du = J->du, *dv = J->dv;
    const int it = J->it, steps = J->steps;
    int i;
    for (i = a; i < b; ++i) {
        sfb__an_try *t = &J->tries[i];
        sfb_location *l = &J->locs[i];
        const int x = t->x, y = t->y;
        double p[3], tu[3], tv[3], sx, sy, z, rx, ry, jac[4], det, du_, dv_, m, u, v, res;
        /* res: the squared residual (pixels^2), so that no square root waits before the tests */
        int c, ok;
        for (c = 0; c < 3; ++c) { p[c] = pos[3 * i + c]; tu[c] = du[3 * i + c]; tv[c] = dv[3 * i + c]; }
        ok = sfb__an_finite3(pos + 3 * i) && sfb__an_project(&A->cam, p, &sx, &sy, &z);
        res = HUGE_VAL;
        if (ok) {
            rx = (x + 0.5) - sx; ry = (y + 0.5) - sy;
            res = rx * rx + ry * ry;
        }
        /* stalled: an attempt whose residual has not halved over the last two steps and is
         * over a pixel (a pixel off the exact silhouette, or across a face it cannot reach)
         * stops as a miss instead of running out its steps (at half a pixel, a few more
         * silhouette pixels were dropped on catmark_car and spot) */
        if (ok && it >= 2 && res > 1.0 && !(res < 0.25 * t->res2)) { t->res = (float)res; t->outcome = 3; continue; }
        /* and one within a pixel of the pixel but not converging (not halved over two steps by
         * its fifth evaluation: beside a silhouette, where round 1 tries thousands of pixels)
         * stops too, as near or a miss (catmark_car: round 1's evaluations -15 %, coverage the same) */
        if (ok && it >= 4 && res > 0.05 * 0.05 && !(res < 0.25 * t->res2)) {
            t->res = (float)res;
            t->outcome = res < SFB__AN_NEAR2 ? 2 : 3;
            continue;
        }
        t->res2 = t->res;
        t->res = (float)res;
        if (ok && res < SFB__AN_TOL2) { t->z = z; t->outcome = SFB__AN_OUT_NEW_HIT; continue; }
        if (!ok || it == steps) { t->outcome = ok && res < SFB__AN_NEAR2 ? 2 : 3; continue; }
        if (!sfb__an_jacobian(&A->cam, p, tu, tv, jac, &det)) { t->outcome = res < SFB__AN_NEAR2 ? 2 : 3; continue; }
        du_ = (jac[3] * rx - jac[1] * ry) / det;
        dv_ = (-jac[2] * rx + jac[0] * ry) / det;
        m = fabs(du_) > fabs(dv_) ? fabs(du_) : fabs(dv_);
        if (m > 0.34) { du_ *= 0.34 / m; dv_ *= 0.34 / m; }
        u = l->u + du_;
        v = l->v + dv_;
        if (sfb__an_clamp_domain(A, &u, &v)) {
            /* left the face: carry on in the neighbour across the side it left by (at most
             * 4 crossings), else give up after two steps against the border */
            double uo = l->u + du_, vo = l->v + dv_, ts = 0.0;
            int side = sfb__an_exit_side(A, uo, vo, u, v, &ts), nb = side >= 0 ? A->adj[4 * l->face + side] : -1;
            if (nb >= 0 && t->crossed < 4) {
                int nside = (nb >> 1) & 3, nf = nb >> 3;
                sfb__an_side_point(A->tri, nside, (nb & 1) ? 1.0 - ts : ts, &u, &v);
                l->face = nf;
                ++t->crossed;
                t->pinned = 0;
            } else if (++t->pinned >= 2) { t->outcome = res < SFB__AN_NEAR2 ? 2 : 3; continue; }
        } else t->pinned = 0;
        l->u = (float)u;
        l->v = (float)v;
        if (A->tri && (double)l->u + (double)l->v > 1.0) l->v = nextafterf(l->v, 0.0f);
    }
}

/* An attempt's outcome for a later round's recording (sfb__an_newton): its pixel, outcome and,
 * for a hit, the evaluation and depth. */
typedef struct sfb__an_done {
    float p[3], du[3], dv[3], n[3];
    double z;
    sfb_location loc;
    int pix;
    unsigned char outcome;
} sfb__an_done;

/* Round 0's attempts (sfb__an_project_all): no attempt's pixel is hit yet and no two share a
 * pixel, so attempt i of a batch owns hit slot base + i (tries[i].k), which it fills when it
 * hits and leaves a hole (hpix -1) when it does not; sfb__an_fill_holes closes the holes after
 * round 0. The batch is cut into `nchunks` chunks, each run to its outcomes on its own
 * (evaluate, step, record, move the running ones first, within the chunk), over the backend's
 * threads: no step waits for the whole batch, and nothing runs on one thread between steps.
 * The chunks shrink from about twice the mean to a few attempts (chunk c starts at
 * count (1 - (1 - c / nchunks)^2)): the backend hands its threads runs of equally many chunks,
 * so the last run taken is short and the other threads wait less for it. One chunk, on the
 * calling thread, when the backend's kernels may not run in lent tasks (sfb__an_chunked: a GPU
 * evaluates a batch at once, and its context is current on the calling thread alone); its
 * step and record loops then go to the threads. res[c]: chunk c's evaluation result. The later
 * rounds' attempts run here too, with `done` (sfb__an_newton). */
typedef struct sfb__an_fresh_job {
    sfb__an *A;
    sfb__an_try *tries;
    sfb_location *locs;
    float *pos, *du, *dv, *nrm;
    int count, nchunks, steps;
    sfb_result *res;
    sfb__an_done *done; /* NULL: round 0 (the attempts record their own hits); else the later rounds: attempt
                           tries[i].k's outcome into done[tries[i].k], recorded after the chunks */
} sfb__an_fresh_job;

static int sfb__an_fresh_start(const sfb__an_fresh_job *F, int c) {
    const long long x = F->nchunks - c, n2 = (long long)F->nchunks * F->nchunks;
    return F->count - (int)((long long)F->count * x * x / n2);
}

/* The attempts of a chunk that ended this step (outcome != 0), each into its own slot: round
 * 0's hit slot tries[i].k and pixel (no two of its attempts share one), or a later round's
 * done[tries[i].k]; so they may run in parallel, and the chunk moves its running attempts
 * first afterwards. */
typedef struct sfb__an_record_job {
    const sfb__an_fresh_job *F;
    const sfb__an_try *tries;
    const sfb_location *locs;
    const float *pos, *du, *dv, *nrm;
} sfb__an_record_job;

static void sfb__an_record(void *arg, int a, int b) {
    const sfb__an_record_job *R = (const sfb__an_record_job *)arg;
    const sfb__an_fresh_job *F = R->F;
    sfb__an *A = F->A;
    const sfb__an_try *tries = R->tries;
    const sfb_location *locs = R->locs;
    const float *pos = R->pos, *du = R->du, *dv = R->dv, *nrm = R->nrm;
    int i;
    for (i = a; i < b; ++i) {
        const sfb__an_try *t = &tries[i];
        if (t->outcome == 0) continue;
        if (F->done) {
            sfb__an_done *o = &F->done[t->k];
            int q;
            o->pix = t->pix;
            o->outcome = t->outcome;
            if (t->outcome == SFB__AN_OUT_NEW_HIT) {
                for (q = 0; q < 3; ++q) {
                    o->p[q] = pos[3 * i + q]; o->du[q] = du[3 * i + q]; o->dv[q] = dv[3 * i + q]; o->n[q] = nrm[3 * i + q];
                }
                o->z = t->z;
                o->loc = locs[i];
            }
            continue;
        }
        if (t->outcome == SFB__AN_OUT_NEW_HIT) {
            A->hpix[t->k] = t->pix;
            A->hit[t->pix] = t->k;
            A->state[t->pix] = SFB__AN_HIT;
            sfb__an_store_hit(A, (size_t)t->k, &locs[i], t->z, pos + 3 * i, du + 3 * i, dv + 3 * i, nrm + 3 * i);
        } else {
            A->hpix[t->k] = -1;
            if (t->outcome == 2) A->state[t->pix] = SFB__AN_TRIED_NEAR;
        }
    }
}

static void sfb__an_fresh(void *arg, int c0, int c1) {
    const sfb__an_fresh_job *F = (const sfb__an_fresh_job *)arg;
    sfb__an *A = F->A;
    int c;
    for (c = c0; c < c1; ++c) {
        const int a = sfb__an_fresh_start(F, c), n = sfb__an_fresh_start(F, c + 1) - a;
        sfb__an_try *tries = F->tries + a;
        sfb_location *locs = F->locs + a;
        float *pos = F->pos + 3 * (size_t)a, *du = F->du + 3 * (size_t)a, *dv = F->dv + 3 * (size_t)a, *nrm = F->nrm + 3 * (size_t)a;
        sfb__an_step_job J;
        sfb__an_record_job R;
        int active = n, it, i;
        F->res[c] = SFB_SUCCESS;
        R.F = F;
        J.A = A; J.tries = tries; J.locs = locs; J.pos = pos; J.du = du; J.dv = dv; J.steps = F->steps;
        for (it = 0; it <= F->steps && active > 0; ++it) {
            sfb_eval_output out;
            int keep = 0;
            memset(&out, 0, sizeof out);
            out.position = pos; out.du = du; out.dv = dv; out.normal = nrm;
            if ((F->res[c] = sfb__surface_eval_unchecked(A->s, locs, active, &out)) != SFB_SUCCESS) {
                if (!F->done)
                    for (i = 0; i < active; ++i) A->hpix[tries[i].k] = -1;
                break;
            }
            J.it = it;
            R.tries = tries; R.locs = locs; R.pos = pos; R.du = du; R.dv = dv; R.nrm = nrm;
            if (F->nchunks == 1) {
                /* one chunk on the calling thread (sfb__an_chunked): its loops go to the threads */
                sfb__an_run(A, sfb__an_step, &J, 0, active, (double)active * 8.0);
                sfb__an_run(A, sfb__an_record, &R, 0, active, (double)active * 4.0);
            } else {
                sfb__an_step(&J, 0, active);
                sfb__an_record(&R, 0, active);
            }
            for (i = 0; i < active; ++i)
                if (tries[i].outcome == 0) {
                    if (keep != i) { tries[keep] = tries[i]; locs[keep] = locs[i]; }
                    ++keep;
                }
            active = keep;
        }
    }
}

/* Closes the holes round 0 left in the hit slots (sfb__an_fresh): the last slots move into
 * them (the slots' order means nothing: the per-pixel arrays say which pixel has which). */
static void sfb__an_fill_holes(sfb__an *A) {
    int k = 0, last = A->nhit - 1;
    for (;;) {
        while (last >= 0 && A->hpix[last] < 0) --last;
        while (k < last && A->hpix[k] >= 0) ++k;
        if (k >= last) break;
        {
            const size_t to = (size_t)k, from = (size_t)last;
            int c;
            A->hpix[to] = A->hpix[from];
            A->hdepth[to] = A->hdepth[from];
            for (c = 0; c < 3; ++c) {
                A->hpos[3 * to + c] = A->hpos[3 * from + c]; A->hnrm[3 * to + c] = A->hnrm[3 * from + c];
                if (A->hdu) { A->hdu[3 * to + c] = A->hdu[3 * from + c]; A->hdv[3 * to + c] = A->hdv[3 * from + c]; }
            }
            A->hit[A->hpix[to]] = k;
            A->hpix[from] = -1;
        }
    }
    A->nhit = last + 1;
}

/* Runs a later round's attempts (tries[i] for pixel tries[i].pix from locs[i]) to their
 * outcomes, then records the hits in attempt order (sfb__an_add_hit: a pixel already hit keeps
 * the nearer one). The attempts run as round 0's do (sfb__an_fresh: in shrinking chunks over
 * the backend's threads, each chunk to its outcomes), but, since several attempts may share a
 * pixel here, leave their outcomes in a list that is recorded afterwards on one thread. */
static sfb_result sfb__an_newton(sfb__an *A, sfb__an_try *tries, sfb_location *locs, int count, float *buf, int steps) {
    sfb__an_fresh_job F;
    sfb_result res[SFB__AN_CHUNKS];
    sfb__an_done *done = (sfb__an_done *)sfb__an_get(A, SFB__WS_DONE, (size_t)count * sizeof *done, NULL);
    const int nck = sfb__an_chunked(A) ? (count + 511) / 512 : 1;
    int i, c;
    if (!done) return sfb__oom(A->ctx, "the analysis projection");
    for (i = 0; i < count; ++i) tries[i].k = i; /* each attempt's index in the round, for its outcome */
    memset(&F, 0, sizeof F);
    F.A = A; F.tries = tries; F.locs = locs; F.count = count; F.steps = steps; F.res = res; F.done = done;
    F.pos = buf; F.du = buf + 3 * (size_t)count; F.dv = buf + 6 * (size_t)count; F.nrm = buf + 9 * (size_t)count;
    F.nchunks = nck < SFB__AN_CHUNKS ? nck : SFB__AN_CHUNKS;
    if (F.nchunks > 1) sfb__an_run(A, sfb__an_fresh, &F, 0, F.nchunks, (double)count * 8.0);
    else sfb__an_fresh(&F, 0, 1); /* on this thread (sfb__an_chunked) */
    for (c = 0; c < F.nchunks; ++c)
        if (res[c] != SFB_SUCCESS) { sfb__an_put(A, done); return res[c]; }
    /* the outcomes in attempt order: new hits recorded, near ones marked (a later hit of the
     * pixel overrides that) */
    for (i = 0; i < count; ++i) {
        const sfb__an_done *o = &done[i];
        if (o->outcome == SFB__AN_OUT_NEW_HIT) sfb__an_add_hit(A, o->pix, &o->loc, o->z, o->p, o->du, o->dv, o->n);
        else if (o->outcome == 2 && A->state[o->pix] == SFB__AN_NONE) A->state[o->pix] = SFB__AN_TRIED_NEAR;
    }
    sfb__an_put(A, done);
    return SFB_SUCCESS;
}

/* d(u,v)/d(pixel) along the picture's axis `axis` (0: x, 1: y) at the hit of pixel pix: its
 * screen Jacobian's inverse applied to that axis (sfb__an_store_hit); 0 when it is singular. */
static int sfb__an_uv_per_pixel(const sfb__an *A, size_t pix, int axis, double m[2]) {
    const float *h = A->hinv + 4 * pix + 2 * axis;
    if (!(isfinite(h[0]) && isfinite(h[1]))) return 0;
    m[0] = h[0];
    m[1] = h[1];
    return 1;
}

/* The part of round 0 that seeds pixel (x, y) (sfb__an_project_all: 0 the anchors, every
 * SFB__AN_ANCHOR = 4 pixels; 1 and 2 one or both coordinates odd multiples of 2; 3 and 4 of 1). */
static int sfb__an_part_of(int x, int y) {
    const int ox = x & 1, oy = y & 1;
    if (ox | oy) return 2 + ox + oy;
    return (x & 2) || (y & 2) ? ((x & 2) && (y & 2) ? 2 : 1) : 0;
}

/* A seed for pixel (x, y) from a hit neighbour d pixels away of an earlier part (of its proxy face, else any):
 * the neighbour's (u,v) moved by the inverse of its screen Jacobian towards (x, y); loc is kept
 * when no neighbour is hit or the Jacobian is singular. */
static void sfb__an_predict(const sfb__an *A, int x, int y, int d, int part, sfb_location *loc) {
    int dx, dy, best = -1, bdx = 0, bdy = 0;
    double mx[2], my[2], u, v;
    for (dy = -d; dy <= d; dy += d)
        for (dx = -d; dx <= d; dx += d) {
            int nx = x + dx, ny = y + dy, q;
            if ((dx | dy) == 0 || nx < 0 || ny < 0 || nx >= A->w || ny >= A->h) continue;
            /* only the parts before this one: their hits are all in, whatever the batches (a
             * neighbour of this part is hit or not depending on where a batch ended) */
            if (sfb__an_part_of(nx, ny) >= part) continue;
            q = ny * A->w + nx;
            if (A->hit[q] < 0) continue;
            if (best < 0 || (A->hl[q].face == loc->face && A->hl[best].face != loc->face)) { best = q; bdx = dx; bdy = dy; }
        }
    if (best < 0 || !sfb__an_uv_per_pixel(A, (size_t)best, 0, mx) || !sfb__an_uv_per_pixel(A, (size_t)best, 1, my)) return;
    u = A->hl[best].u - mx[0] * bdx - my[0] * bdy;
    v = A->hl[best].v - mx[1] * bdx - my[1] * bdy;
    if (!isfinite(u) || !isfinite(v)) return;
    sfb__an_clamp_domain(A, &u, &v);
    loc->face = A->hl[best].face;
    loc->u = (float)u;
    loc->v = (float)v;
}

/* Side k's own frame of a face's point (u, v): t along the side (sfb__an_side_point's t), s
 * from the side inward (1 at the opposite corner or side); and back. */
static void sfb__an_side_frame(int tri, int k, double u, double v, double *t, double *s) {
    if (tri) {
        if (k == 0) { *t = u; *s = v; }
        else if (k == 1) { *t = v; *s = 1.0 - u - v; }
        else { *t = 1.0 - v; *s = u; }
        return;
    }
    if (k == 0) { *t = u; *s = v; }
    else if (k == 1) { *t = v; *s = 1.0 - u; }
    else if (k == 2) { *t = 1.0 - u; *s = 1.0 - v; }
    else { *t = 1.0 - v; *s = u; }
}
static void sfb__an_side_unframe(int tri, int k, double t, double s, double *u, double *v) {
    if (tri) {
        if (k == 0) { *u = t; *v = s; }
        else if (k == 1) { *u = 1.0 - s - t; *v = t; }
        else { *u = s; *v = 1.0 - t; }
        return;
    }
    if (k == 0) { *u = t; *v = s; }
    else if (k == 1) { *u = 1.0 - s; *v = t; }
    else if (k == 2) { *u = 1.0 - t; *v = 1.0 - s; }
    else { *u = s; *v = 1.0 - t; }
}

/* A point (u, v) of face G in the frame of its neighbour F across G's side kg (F's side kf; rev:
 * the sides run opposite ways, as A->adj has it), F's domain extended over the side: the two
 * faces unfolded into one plane, G's side onto F's and G's inside beyond it, as two squares of
 * a regular grid (Catmull-Clark), or two triangles of a regular lattice, which make a
 * parallelogram (Loop: G's opposite corner lands on F's corner point-reflected through the
 * side's middle). The same call with F and G swapped is its inverse. */
static void sfb__an_unfold(int tri, int kg, int kf, int rev, double u, double v, double *uf, double *vf) {
    double t, s, tf;
    sfb__an_side_frame(tri, kg, u, v, &t, &s);
    tf = rev ? 1.0 - t : t;
    if (tri) {
        /* the opposite corner's t per side: (0, 1), (0, 0), (1, 0) */
        const double og = kg == 2 ? 1.0 : 0.0, of = kf == 2 ? 1.0 : 0.0;
        tf += ((1.0 - of) - (rev ? 1.0 - og : og)) * s;
    }
    sfb__an_side_unframe(tri, kf, tf, -s, uf, vf);
}

/* Whether (u, v) lies in the face's domain, within eps. */
static int sfb__an_in_domain(const sfb__an *A, double u, double v, double eps) {
    if (!(u >= -eps && v >= -eps)) return 0;
    return A->tri ? u + v <= 1.0 + eps : u <= 1.0 + eps && v <= 1.0 + eps;
}

/* A seed for pixel (x, y) between two hits, d pixels either side along `axis`: the cubic
 * Hermite interpolant of their (u,v) with their d(u,v)/d(pixel) as end tangents, at its
 * middle, (a + b) / 2 + d (m_a - m_b) / 4 (the hits 2d pixels apart), off by fourth-order terms
 * only, so that the pixel usually hits at its first evaluation (a one-sided linear prediction
 * is off by the second-order term, above SFB__AN_TOL where a patch spans under ~100 pixels).
 * Two hits on neighbouring faces (across a side of A->adj) are interpolated with b's (u,v) and
 * tangent unfolded into a's frame (sfb__an_unfold), and the middle is put on the face it lands
 * in (catmark_car at 1024 x 1024: 9 % of round 0's pixels have their two hits on two faces,
 * and took 2.2 evaluations each from the one-sided prediction). 0 (loc kept) when either hit is
 * missing, they lie on faces that are not neighbours, the middle lands on neither face (next to
 * a corner) or a Jacobian is singular. */
static int sfb__an_hermite(const sfb__an *A, int x, int y, int axis, int d, sfb_location *loc) {
    const int dx = axis ? 0 : d, dy = axis ? d : 0;
    const int ns = A->tri ? 3 : 4;
    double ma[2], mb[2], ub, vb, u, v;
    size_t a, b;
    int fa, fb, kf = 0, nb = -1;
    if (x - dx < 0 || y - dy < 0 || x + dx >= A->w || y + dy >= A->h) return 0;
    a = (size_t)(y - dy) * (size_t)A->w + (size_t)(x - dx);
    b = (size_t)(y + dy) * (size_t)A->w + (size_t)(x + dx);
    if (A->hit[a] < 0 || A->hit[b] < 0) return 0;
    if (!sfb__an_uv_per_pixel(A, a, axis, ma) || !sfb__an_uv_per_pixel(A, b, axis, mb)) return 0;
    fa = A->hl[a].face;
    fb = A->hl[b].face;
    ub = A->hl[b].u;
    vb = A->hl[b].v;
    if (fa != fb) {
        /* b's point and tangent into a's frame, across their shared side */
        double u1, v1;
        for (kf = 0; kf < ns; ++kf) {
            nb = A->adj[4 * fa + kf];
            if (nb >= 0 && (nb >> 3) == fb) break;
        }
        if (kf == ns) return 0;
        sfb__an_unfold(A->tri, (nb >> 1) & 3, kf, nb & 1, ub + mb[0], vb + mb[1], &u1, &v1);
        sfb__an_unfold(A->tri, (nb >> 1) & 3, kf, nb & 1, ub, vb, &ub, &vb);
        mb[0] = u1 - ub;
        mb[1] = v1 - vb;
    }
    u = 0.5 * ((double)A->hl[a].u + ub) + 0.25 * d * (ma[0] - mb[0]);
    v = 0.5 * ((double)A->hl[a].v + vb) + 0.25 * d * (ma[1] - mb[1]);
    if (!isfinite(u) || !isfinite(v)) return 0;
    if (fa != fb && !sfb__an_in_domain(A, u, v, 1e-6)) {
        /* beyond a's side: back into b's frame */
        sfb__an_unfold(A->tri, kf, (nb >> 1) & 3, nb & 1, u, v, &u, &v);
        if (!sfb__an_in_domain(A, u, v, 1e-6)) return 0;
        fa = fb;
    }
    sfb__an_clamp_domain(A, &u, &v);
    loc->face = fa;
    loc->u = (float)u;
    loc->v = (float)v;
    return 1;
}

/* Round 0's attempts of one part (grid spacing d; `want` of x, y odd multiples of d) on grid
 * rows [a, b) (row r: y = r d): with fill 0, the count of each row into rowat[r]; with fill 1,
 * row r's attempts into tries and locs from index rowat[r] on, seeded (the proxy's (face, u,
 * v), then sfb__an_hermite or sfb__an_predict from the hits so far). Rows are independent:
 * seeding reads hits, which only sfb__an_newton writes. */
typedef struct sfb__an_seed_job {
    const sfb__an *A;
    sfb__an_try *tries;
    sfb_location *locs;
    int *rowat;
    int part, d, want, fill, base;
} sfb__an_seed_job;

static void sfb__an_seed_rows(void *arg, int a, int b) {
    const sfb__an_seed_job *J = (const sfb__an_seed_job *)arg;
    const sfb__an *A = J->A;
    const int d = J->d, part = J->part, want = J->want;
    int row;
    for (row = a; row < b; ++row) {
        /* d is a power of two */
        const int y = row * d, oy = part > 0 && (y & (2 * d - 1)) == d;
        /* the row's pixels of the part: x an odd multiple of d when ox (= want - oy) is 1, a
         * multiple of 2d when it is 0 (part 0: every multiple of d) */
        const int ox = want - oy, step = part > 0 ? 2 * d : d;
        int x, n = J->fill ? J->rowat[row] : 0;
        for (x = ox == 1 ? d : 0; x < A->w && (ox == 0 || ox == 1); x += step) {
            const size_t p = (size_t)y * (size_t)A->w + (size_t)x;
            sfb_location *l;
            if (!A->cand[p]) continue;
            if (!J->fill) { ++n; continue; }
            memset(&J->tries[n], 0, sizeof J->tries[n]);
            J->tries[n].pix = (int)p;
            J->tries[n].x = x;
            J->tries[n].y = y;
            J->tries[n].k = J->base + n;
            l = &J->locs[n];
            if (A->cand[p] == 2) {
                l->face = A->face[p]; l->u = A->uv[2 * p]; l->v = A->uv[2 * p + 1];
            } else {
                l->face = A->cface[p]; l->u = A->cuv[2 * p]; l->v = A->cuv[2 * p + 1];
            }
            if (part > 0 && !sfb__an_hermite(A, x, y, ox ? 0 : 1, d, l) && !(ox && oy && sfb__an_hermite(A, x, y, 1, d, l)))
                sfb__an_predict(A, x, y, d, part, l);
            if (A->tri && (double)l->u + (double)l->v > 1.0) l->v = nextafterf(l->v, 0.0f);
            ++n;
        }
        if (!J->fill) J->rowat[row] = n;
    }
}

/* Which of hit pixel pix's 8 neighbours (bit i: the i-th of dy, dx = -1..1 in order, the
 * middle skipped) its hit would seed: not hit yet, or hit on another face at least 1 % of the
 * bounding radius farther away. */
static unsigned char sfb__an_neighbour_mask(const sfb__an *A, int x, int y) {
    const int pix = y * A->w + x, f = A->hl[pix].face;
    int dx, dy, bit = 0, m = 0;
    for (dy = -1; dy <= 1; ++dy)
        for (dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            int q, k;
            if ((dx | dy) == 0) continue;
            ++bit;
            if (nx < 0 || ny < 0 || nx >= A->w || ny >= A->h) continue;
            q = ny * A->w + nx;
            k = A->hit[q];
            if (k >= 0 && (A->hl[q].face == f || !(A->hdepth[A->hit[pix]] < A->hdepth[k] - 0.01 * A->radius))) continue;
            m |= 1 << (bit - 1);
        }
    return (unsigned char)m;
}

/* sfb__an_neighbour_mask of the changes [a, b) of the last round (A->chg) into A->nbm. */
static void sfb__an_neighbours(void *arg, int a, int b) {
    sfb__an *A = (sfb__an *)arg;
    int ci;
    for (ci = a; ci < b; ++ci) {
        const int pix = A->chg[ci];
        A->nbm[ci] = sfb__an_neighbour_mask(A, pix % A->w, pix / A->w);
    }
}

/* Round 1's changes: every hit, scanned row by row. sfb__an_neighbour_rows: the mask per pixel
 * on rows [y0, y1) into J->mask, 0 where no hit, and each row's count of masks that are not 0
 * into J->rowcnt[y]; sfb__an_neighbour_list: then, rows [y0, y1)'s pixels of masks not 0, in
 * order, into A->chg and their masks into J->list, from J->rowcnt[y] (by then their first
 * index) on. */
typedef struct sfb__an_nb_job {
    sfb__an *A;
    unsigned char *mask, *list;
    int *rowcnt;
} sfb__an_nb_job;
static void sfb__an_neighbour_list(void *arg, int y0, int y1) {
    const sfb__an_nb_job *J = (const sfb__an_nb_job *)arg;
    const int w = J->A->w;
    int x, y;
    for (y = y0; y < y1; ++y) {
        int o = J->rowcnt[y];
        for (x = 0; x < w; ++x) {
            const size_t p = (size_t)y * (size_t)w + (size_t)x;
            if (J->mask[p]) { J->A->chg[o] = (int)p; J->list[o++] = J->mask[p]; }
        }
    }
}
static void sfb__an_neighbour_rows(void *arg, int y0, int y1) {
    const sfb__an_nb_job *J = (const sfb__an_nb_job *)arg;
    sfb__an *A = J->A;
    unsigned char *nbm = J->mask;
    const int w = A->w;
    int x, y;
    for (y = y0; y < y1; ++y) {
        int n = 0;
        for (x = 0; x < w; ++x) {
            const size_t p = (size_t)y * (size_t)w + (size_t)x;
            if (A->hit[p] < 0) { nbm[p] = 0; continue; }
            if (x > 0 && y > 0 && x + 1 < w && y + 1 < A->h) {
                /* inside the surface's picture every neighbour is hit on the same face: none
                 * to seed (the mask's first test), without the general scan */
                const int f = A->hl[p].face, *hu = A->hit + p - w, *hm = A->hit + p, *hd = A->hit + p + w;
                const sfb_location *lu = A->hl + p - w, *lm = A->hl + p, *ld = A->hl + p + w;
                if (((hu[-1] | hu[0] | hu[1] | hm[-1] | hm[1] | hd[-1] | hd[0] | hd[1]) >= 0) && lu[-1].face == f && lu[0].face == f &&
                    lu[1].face == f && lm[-1].face == f && lm[1].face == f && ld[-1].face == f && ld[0].face == f && ld[1].face == f) {
                    nbm[p] = 0;
                    continue;
                }
            }
            nbm[p] = sfb__an_neighbour_mask(A, x, y);
            n += nbm[p] != 0;
        }
        J->rowcnt[y] = n;
    }
}

/* The projection's round tags of rows [y0, y1) cleared (the faces after them are read only
 * where the tag is the round's, so they are left as they are). */
typedef struct sfb__an_tags_job {
    int *tags;
    int w;
} sfb__an_tags_job;
static void sfb__an_clear_tags(void *arg, int y0, int y1) {
    const sfb__an_tags_job *J = (const sfb__an_tags_job *)arg;
    memset(J->tags + (size_t)y0 * (size_t)J->w, 0, (size_t)(y1 - y0) * (size_t)J->w * sizeof(int));
}

/* Step 2 over every round (see the file's comment). */
static sfb_result sfb__an_project_all(sfb__an *A, int steps) {
    size_t npix = (size_t)A->w * (size_t)A->h;
    int cap = 0, count = 0, round, part;
    sfb__an_try *tries = NULL;
    sfb_location *locs = NULL;
    float *buf = NULL;
    int *mark = NULL;  /* per pixel the last round that seeded it (its tag), then per pixel 3 faces it was seeded
                          from in that round (read only where the tag is this round's: only the tags are cleared) */
    int *rowat = NULL; /* round 0: per grid row, its attempts, then where they start in their band */
    unsigned char *nbc = NULL; /* round 1's changes' masks (sfb__an_neighbour_rows) */
    int mark_base = 0;
    sfb_result r = SFB_SUCCESS;
    cap = A->ws ? SFB__AN_BATCH_WS : SFB__AN_BATCH;
    if ((size_t)cap > npix) cap = (int)npix; /* later rounds grow it when they need to */
    if (cap < 4096) cap = 4096;
    if (cap < A->w) cap = A->w; /* round 0's bands hold at least a row */
    tries = (sfb__an_try *)sfb__an_get(A, SFB__WS_TRIES, (size_t)cap * sizeof *tries, NULL);
    locs = (sfb_location *)sfb__an_get(A, SFB__WS_LOCS, (size_t)cap * sizeof *locs, NULL);
    buf = (float *)sfb__an_get(A, SFB__WS_BUF, (size_t)cap * 12 * sizeof(float), NULL);
    rowat = (int *)sfb__an_get(A, SFB__WS_ROWAT, ((size_t)A->h + 1) * sizeof(int), NULL);
    A->nbm = (unsigned char *)sfb__an_get(A, SFB__WS_NBM, npix + 1, NULL);
    nbc = (unsigned char *)sfb__an_get(A, SFB__WS_NBC, npix + 1, NULL);
    /* the marks' round tags are base + round: a workspace's kept marks hold tags of earlier
     * analyses, all at or below its base, which grows by SFB__AN_ROUNDS per analysis (the
     * buffer is zeroed when new, or when the tags would overflow) */
    {
        int fresh = 1;
        mark = (int *)sfb__an_get(A, SFB__WS_MARK, npix * 4 * sizeof(int), &fresh);
        if (mark && !A->ws) {
            sfb__an_tags_job T;
            T.tags = mark;
            T.w = A->w;
            sfb__an_run(A, sfb__an_clear_tags, &T, 0, A->h, (double)npix * 0.05);
        }
        if (mark && A->ws) {
            if (fresh || A->ws->mark_base > 2147483647 - 2 * (SFB__AN_ROUNDS + 1)) {
                memset(mark, 0, npix * sizeof(int));
                A->ws->mark_base = 0;
            }
            mark_base = A->ws->mark_base;
            A->ws->mark_base += SFB__AN_ROUNDS + 1;
        }
    }
    if (!tries || !locs || !buf || !mark || !rowat || !A->nbm || !nbc) { r = sfb__oom(A->ctx, "the analysis projection"); goto done; }
    /* round 0, in five parts: first the anchors, the pixels whose x and y are multiples of
     * SFB__AN_ANCHOR (4), from their proxy (face, u, v); then, for d = 2 and then 1, the pixels
     * on the grid of spacing d with one coordinate an odd multiple of d, then those with both,
     * each between two hits of the parts before, d pixels either side along an axis
     * (sfb__an_hermite: most hit at their first evaluation), else from a hit anchor-grid
     * neighbour moved by the inverse of its screen Jacobian (sfb__an_predict), else from the
     * proxy too. Measured on catmark_car at 1024 x 1024 (413k covered pixels), every round:
     * 1.35 evaluations per covered pixel (round 0: 1.21); 1.41 (1.27) when the two hits of a
     * Hermite seed had to lie on one face, the others predicted from one side (a one-sided
     * cubic extrapolation for those saved 2 % of round 0's time and put 0.04 % of the pixels
     * on a farther sheet, which the later rounds then had to correct: not kept); 2.6 with
     * anchors every 2 pixels, the one-sided prediction alone and no stall rule (sfb__an_step).
     * The seeds the prediction still makes (next to silhouettes, face corners, and faces not
     * neighbours) take 2.2 evaluations each, Hermite seeds 1.05 to 1.15 */
    for (part = 0; part < 5; ++part) {
        const int d = part == 0 ? SFB__AN_ANCHOR : part <= 2 ? 2 : 1, nrows = (A->h + d - 1) / d;
        int r0, r1;
        sfb__an_seed_job J;
        J.A = A; J.tries = tries; J.locs = locs; J.rowat = rowat;
        J.part = part; J.d = d; J.want = part == 0 ? 0 : 2 - (part & 1);
        A->seeding = part < 4; /* the last part's hits seed no pixel of round 0 */
        A->nchg = 0; /* round 0's changes are every hit (below) */
        /* the attempts per grid row, then bands of whole rows of at most cap attempts (cap >=
         * w: a row fits), each seeded over the threads and run at once (its hits then seed the
         * bands after it too) */
        J.fill = 0;
        sfb__an_run(A, sfb__an_seed_rows, &J, 0, nrows, (double)A->w * A->h / ((double)d * d));
        for (r0 = 0; r0 < nrows; r0 = r1) {
            int total = 0;
            for (r1 = r0; r1 < nrows && total + rowat[r1] <= cap; ++r1) {
                const int n = rowat[r1];
                rowat[r1] = total;
                total += n;
            }
            if (total == 0) continue;
            J.fill = 1;
            J.base = A->nhit;
            sfb__an_run(A, sfb__an_seed_rows, &J, r0, r1, (double)total * 4.0);
            {
                sfb__an_fresh_job F;
                sfb_result res[SFB__AN_CHUNKS];
                const int nck = sfb__an_chunked(A) ? (total + 1023) / 1024 : 1;
                int c;
                F.A = A; F.tries = tries; F.locs = locs; F.count = total; F.steps = steps; F.res = res; F.done = NULL;
                F.pos = buf; F.du = buf + 3 * (size_t)total; F.dv = buf + 6 * (size_t)total; F.nrm = buf + 9 * (size_t)total;
                F.nchunks = nck < SFB__AN_CHUNKS ? nck : SFB__AN_CHUNKS;
                A->nhit += total; /* the batch's slots (holes where it misses) */
                if (F.nchunks > 1) sfb__an_run(A, sfb__an_fresh, &F, 0, F.nchunks, (double)total * 8.0);
                else sfb__an_fresh(&F, 0, 1); /* on this thread (sfb__an_chunked) */
                for (c = 0; c < F.nchunks; ++c)
                    if (res[c] != SFB_SUCCESS) { r = res[c]; goto done; }
            }
        }
    }
    sfb__an_fill_holes(A);
    /* round 0's changes: every hit, scanned per pixel row by row over the threads; those that
     * seed a neighbour listed in the picture's order (the hit slots lie in round 0's part
     * order, scattered over the picture: scanning them in that order cost a cache miss on
     * every neighbour read) */
    {
        sfb__an_nb_job N;
        int y, total = 0;
        N.A = A; N.mask = A->nbm; N.list = nbc; N.rowcnt = rowat;
        sfb__an_run(A, sfb__an_neighbour_rows, &N, 0, A->h, (double)npix);
        for (y = 0; y < A->h; ++y) { const int n = rowat[y]; rowat[y] = total; total += n; }
        sfb__an_run(A, sfb__an_neighbour_list, &N, 0, A->h, (double)npix * 0.25);
        A->nchg = total;
        A->nbm = nbc; /* per change from here on */
        nbc = N.mask;
    }
    if ((r = sfb__progress(A->ctx, 0.6f, "analyze")) != SFB_SUCCESS) goto done;
    /* later rounds: the pixels next to the last round's new or nearer hits, seeded by them:
     * pixels not hit yet, and pixels hit on another face at least 1 % of the bounding radius
     * farther away (a nearer surface next to them may hide their hit: the proxy's depth order
     * is not the exact surface's near silhouettes) */
    for (round = 1; round <= SFB__AN_ROUNDS; ++round) {
        int ci;
        count = 0;
        /* which neighbours each change would seed, over the threads (reads only; round 1's
         * are known), then the seeding in the changes' order, here */
        if (round > 1) sfb__an_run(A, sfb__an_neighbours, A, 0, A->nchg, (double)A->nchg);
        for (ci = 0; ci < A->nchg; ++ci) {
            int pix, x, y, dx, dy, bit = 0;
            if (!A->nbm[ci]) continue;
            pix = A->chg[ci]; x = pix % A->w; y = pix / A->w;
            for (dy = -1; dy <= 1; ++dy)
                for (dx = -1; dx <= 1; ++dx) {
                    int q, k, *mq, f = A->hl[pix].face;
                    if ((dx | dy) == 0) continue;
                    if (!(A->nbm[ci] & (1 << bit++))) continue;
                    q = (y + dy) * A->w + (x + dx);
                    mq = mark + npix + 3 * (size_t)q;
                    if (mark[q] != mark_base + round) { mark[q] = mark_base + round; mq[0] = mq[1] = mq[2] = -1; }
                    for (k = 0; k < 3 && mq[k] >= 0 && mq[k] != f; ++k) {}
                    if (k == 3 || mq[k] == f) continue; /* three faces tried this round, or this one */
                    mq[k] = f;
                    if (count == cap) {
                        int nc = cap * 2;
                        void *a = sfb__an_regrow(A, SFB__WS_TRIES, tries, (size_t)nc * sizeof *tries);
                        if (!a) { r = sfb__oom(A->ctx, "the analysis projection"); goto done; }
                        tries = (sfb__an_try *)a;
                        a = sfb__an_regrow(A, SFB__WS_LOCS, locs, (size_t)nc * sizeof *locs);
                        if (!a) { r = sfb__oom(A->ctx, "the analysis projection"); goto done; }
                        locs = (sfb_location *)a;
                        a = sfb__an_regrow(A, SFB__WS_BUF, buf, (size_t)nc * 12 * sizeof(float));
                        if (!a) { r = sfb__oom(A->ctx, "the analysis projection"); goto done; }
                        buf = (float *)a;
                        cap = nc;
                    }
                    memset(&tries[count], 0, sizeof tries[count]);
                    tries[count].pix = q;
                    tries[count].x = x + dx;
                    tries[count].y = y + dy;
                    locs[count] = A->hl[pix];
                    ++count;
                }
        }
        if (count == 0) break;
        A->nchg = 0;
        if ((r = sfb__an_newton(A, tries, locs, count, buf, steps)) != SFB_SUCCESS) goto done;
        if (A->nchg == 0) break;
        if ((r = sfb__progress(A->ctx, 0.6f + 0.1f * (float)round / SFB__AN_ROUNDS, "analyze")) != SFB_SUCCESS) goto done;
    }
done:
    sfb__an_put(A, tries);
    sfb__an_put(A, locs);
    sfb__an_put(A, buf);
    sfb__an_put(A, mark);
    sfb__an_put(A, rowat);
    sfb__an_put(A, A->nbm);
    sfb__an_put(A, nbc);
    A->nbm = NULL;
    return r;
}

/* Rows [y0, y1): per row y, its proxy pixels left near (to fall back), left far (dropped) and
 * its hits off the proxy (grown) into cnt[3 y ..]. */
typedef struct sfb__an_left_job {
    const sfb__an *A;
    int *cnt;
} sfb__an_left_job;
static void sfb__an_left_rows(void *arg, int y0, int y1) {
    const sfb__an_left_job *J = (const sfb__an_left_job *)arg;
    const sfb__an *A = J->A;
    int x, y;
    for (y = y0; y < y1; ++y) {
        int near = 0, far = 0, grown = 0;
        for (x = 0; x < A->w; ++x) {
            const size_t p = (size_t)y * (size_t)A->w + (size_t)x;
            const int drawn = A->face[p] >= 0, hit = A->hit[p] >= 0;
            grown += hit && !drawn;
            if (drawn && !hit) {
                if (A->state[p] == SFB__AN_TRIED_NEAR) ++near;
                else ++far;
            }
        }
        J->cnt[3 * y] = near; J->cnt[3 * y + 1] = far; J->cnt[3 * y + 2] = grown;
    }
}

/* Proxy pixels left without a hit: NEAR ones fall back to the proxy's point (evaluated there),
 * the others are dropped (counted into dropped); hits off the proxy are counted into grown.
 * polygon_based: every proxy pixel is a "hit" on its interpolated data. */
static sfb_result sfb__an_leftovers(sfb__an *A, int *fallback, int *dropped, int *grown) {
    size_t p;
    int n = 0, i, y;
    sfb_location *loc;
    float *buf;
    int *pix, *cnt = (int *)sfb__alloc(A->ctx, ((size_t)A->h + 1) * 3 * sizeof(int));
    sfb_eval_output out;
    sfb_result r;
    *fallback = *dropped = *grown = 0;
    if (!cnt) return sfb__oom(A->ctx, "the analysis fallback");
    {
        sfb__an_left_job J;
        J.A = A; J.cnt = cnt;
        sfb__an_run(A, sfb__an_left_rows, &J, 0, A->h, (double)A->w * A->h * 0.25);
    }
    for (y = 0; y < A->h; ++y) { n += cnt[3 * y]; *dropped += cnt[3 * y + 1]; *grown += cnt[3 * y + 2]; }
    if (n == 0) { sfb__free(A->ctx, cnt); return SFB_SUCCESS; }
    loc = (sfb_location *)sfb__alloc(A->ctx, (size_t)n * sizeof *loc);
    buf = (float *)sfb__alloc(A->ctx, (size_t)n * 12 * sizeof(float));
    pix = (int *)sfb__alloc(A->ctx, (size_t)n * sizeof(int));
    if (!loc || !buf || !pix) {
        sfb__free(A->ctx, loc); sfb__free(A->ctx, buf); sfb__free(A->ctx, pix); sfb__free(A->ctx, cnt);
        return sfb__oom(A->ctx, "the analysis fallback");
    }
    for (y = 0, i = 0; y < A->h; ++y) {
        const size_t end = ((size_t)y + 1) * (size_t)A->w;
        if (!cnt[3 * y]) continue;
        for (p = (size_t)y * (size_t)A->w; p < end; ++p)
            if (A->face[p] >= 0 && A->hit[p] < 0 && A->state[p] == SFB__AN_TRIED_NEAR) {
                pix[i] = (int)p;
                loc[i].face = A->face[p]; loc[i].u = A->uv[2 * p]; loc[i].v = A->uv[2 * p + 1];
                if (A->tri && (double)loc[i].u + (double)loc[i].v > 1.0) loc[i].v = nextafterf(loc[i].v, 0.0f);
                ++i;
            }
    }
    sfb__free(A->ctx, cnt);
    memset(&out, 0, sizeof out);
    out.position = buf; out.du = buf + 3 * (size_t)n; out.dv = buf + 6 * (size_t)n; out.normal = buf + 9 * (size_t)n;
    r = sfb__surface_eval_unchecked(A->s, loc, n, &out);
    if (r == SFB_SUCCESS)
        for (i = 0; i < n; ++i)
            sfb__an_add_hit(A, pix[i], &loc[i], A->depth[pix[i]], out.position + 3 * (size_t)i, out.du + 3 * (size_t)i, out.dv + 3 * (size_t)i,
                            out.normal + 3 * (size_t)i);
    *fallback = n;
    sfb__free(A->ctx, loc); sfb__free(A->ctx, buf); sfb__free(A->ctx, pix);
    return r;
}

/* ---- step 4: colours ---- */
/* The smaller of two one-sided differences of an axis, each +inf (off the picture, or an infinite
 * neighbour) or NaN (a NaN neighbour) when it does not count; 0 when neither does. */
static double sfb__an_smaller_side(double a, double b) {
    return a < b ? a : b < HUGE_VAL ? b : a < HUGE_VAL ? a : 0.0;
}
/* The footprint of pixel pix in units of the value in v: per axis the smaller one-sided
 * difference (robust at silhouettes and band ends), summed. */
static double sfb__an_footprint(const float *v, int w, int h, int x, int y) {
    const int pix = y * w + x;
    const double c = v[pix];
    const double l = x > 0 ? fabs(c - v[pix - 1]) : HUGE_VAL, r = x + 1 < w ? fabs(c - v[pix + 1]) : HUGE_VAL;
    const double u = y > 0 ? fabs(c - v[pix - w]) : HUGE_VAL, o = y + 1 < h ? fabs(c - v[pix + w]) : HUGE_VAL;
    return sfb__an_smaller_side(l, r) + sfb__an_smaller_side(u, o);
}
/* The looks of one analysis: resolved light and colours. */
typedef struct sfb__an_look {
    sfb__shade_job job;
    double key[3], width, range;
    int pattern;
    unsigned char bg[4], miss[4];
} sfb__an_look;

static void sfb__an_lights(const sfb__an *A, sfb__an_look *L) {
    const sfb_analyze_config *c = A->c;
    const sfb__an_cam *cam = &A->cam;
    sfb__shade_job *j = &L->job;
    double R = A->radius, d[3];
    int i, mode = c->mode;
    memset(L, 0, sizeof *L);
    j->mode = mode; j->curvature = c->curvature; j->ortho = cam->ortho;
    for (i = 0; i < 3; ++i) { j->eye[i] = cam->eye[i]; j->fwd[i] = cam->fwd[i]; }
    for (i = 0; i < 3; ++i) L->key[i] = -cam->fwd[i] + 0.55 * cam->up[i] - 0.45 * cam->right[i];
    sfb__rnormalize(L->key);
    L->pattern = c->light_pattern;
    L->width = c->stripe_width > 0.0f ? c->stripe_width
               : L->pattern == SFB_LIGHT_LATTICE ? 0.2 : L->pattern == SFB_LIGHT_CIRCLES ? 0.6 : mode == SFB_ANALYZE_HIGHLIGHT ? 0.7 : 0.5;
    for (i = 0; i < 3; ++i) d[i] = c->light_dir[i];
    if (!(sfb__rnormalize(d) > 0.0)) {
        /* zebra: bands about the camera's up; isophotes and shading: the key light */
        for (i = 0; i < 3; ++i) d[i] = mode == SFB_ANALYZE_ZEBRA ? cam->up[i] : L->key[i];
    }
    for (i = 0; i < 3; ++i) j->dir[i] = d[i];
    if (mode == SFB_ANALYZE_REFLECTION || mode == SFB_ANALYZE_HIGHLIGHT) {
        double ell[3], per = c->stripes > 0.0f ? c->stripes : mode == SFB_ANALYZE_REFLECTION ? 16.0 : 5.0, t;
        if (c->light_set) {
            for (i = 0; i < 3; ++i) { j->lc[i] = c->light_center[i]; j->lm[i] = c->light_normal[i]; j->lu[i] = c->light_axis[i]; }
            sfb__rnormalize(j->lm);
            j->lsize[0] = c->light_size[0] > 0.0f ? c->light_size[0] : 16.0 * R;
            j->lsize[1] = c->light_size[1] > 0.0f ? c->light_size[1] : j->lsize[0];
        } else if (mode == SFB_ANALYZE_REFLECTION) {
            /* directly above the surface (the seed's Fig. 2: "an area light source is put directly
             * above a surface"), up being the camera's up, or the orbit's (the world's y unless
             * `up` is given); the lines run away from the viewer (a design studio's ceiling of
             * tubes) */
            for (i = 0; i < 3; ++i) ell[i] = c->up[i];
            if (!(sfb__rnormalize(ell) > 0.0)) { ell[0] = 0.0; ell[1] = 1.0; ell[2] = 0.0; }
            for (i = 0; i < 3; ++i) { j->lc[i] = A->centre[i] + 2.5 * R * ell[i]; j->lm[i] = -ell[i]; j->lu[i] = cam->right[i]; }
            j->lsize[0] = j->lsize[1] = 16.0 * R;
        } else {
            /* sfb_render's highlight plane: toward the camera, lines at 30 degrees from vertical */
            double e[3];
            for (i = 0; i < 3; ++i) {
                j->lm[i] = -cam->fwd[i];
                j->lc[i] = A->centre[i] + 3.0 * R * j->lm[i];
                e[i] = cos(SFB__PI / 6.0) * cam->up[i] + sin(SFB__PI / 6.0) * cam->right[i];
            }
            sfb__rcross(e, j->lm, j->lu);
            j->lsize[0] = j->lsize[1] = 2.0 * R;
        }
        t = sfb__rdot(j->lu, j->lm);
        for (i = 0; i < 3; ++i) j->lu[i] -= t * j->lm[i];
        sfb__rnormalize(j->lu);
        sfb__rcross(j->lm, j->lu, j->lv);
        j->periods[0] = per;
        j->periods[1] = per * j->lsize[1] / j->lsize[0];
    } else if (mode == SFB_ANALYZE_ZEBRA) j->periods[0] = c->stripes > 0.0f ? c->stripes : 16.0;
    else if (mode == SFB_ANALYZE_ISOPHOTE) j->periods[0] = c->stripes > 0.0f ? c->stripes : 10.0;
    if (c->background[0] | c->background[1] | c->background[2] | c->background[3]) memcpy(L->bg, c->background, 4);
    else { L->bg[0] = 44; L->bg[1] = 48; L->bg[2] = 56; L->bg[3] = 255; }
    if (c->miss[0] | c->miss[1] | c->miss[2] | c->miss[3]) memcpy(L->miss, c->miss, 4);
    else { L->miss[0] = 26; L->miss[1] = 28; L->miss[2] = 34; L->miss[3] = 255; }
}

/* The k-th smallest of v[0..n) (reorders v; quickselect, median-of-three pivots). */
static float sfb__an_select(float *v, int n, int k) {
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int i = lo, j = hi, mid = lo + (hi - lo) / 2;
        float a = v[lo], b = v[mid], c = v[hi], piv = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        while (i <= j) {
            while (v[i] < piv) ++i;
            while (v[j] > piv) --j;
            if (i <= j) { float t = v[i]; v[i] = v[j]; v[j] = t; ++i; --j; }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else break;
    }
    return v[k];
}

/* The curvature map's range: the config's, or the 90th percentile of |value| (exact, so that
 * a few pixels more or less move it by a rank, not by a histogram bin). */
static sfb_result sfb__an_range(const sfb__an *A, const float *val, int n, double *range) {
    float *a;
    int i, m = 0;
    *range = 1.0;
    if (A->c->curvature_range > 0.0f) { *range = A->c->curvature_range; return SFB_SUCCESS; }
    a = (float *)sfb__alloc(A->ctx, ((size_t)n + 1) * sizeof(float));
    if (!a) return sfb__oom(A->ctx, "the curvature range");
    for (i = 0; i < n; ++i) if (isfinite(val[i])) a[m++] = fabsf(val[i]);
    if (m > 0) {
        double r = sfb__an_select(a, m, (int)(0.9 * (m - 1)));
        if (r > 0.0) *range = r;
    }
    sfb__free(A->ctx, a);
    return SFB_SUCCESS;
}

/* Samples the image light at plane coordinates (s, t) in [0,1] (bilinear, clamped). */
static void sfb__an_texel(const sfb_analyze_config *c, double s, double t, double *rgba) {
    double x = sfb__rclamp(s, 0.0, 1.0) * c->light_width - 0.5, y = sfb__rclamp(t, 0.0, 1.0) * c->light_height - 0.5, fx, fy;
    int x0, y0, x1, y1, k;
    x = sfb__rclamp(x, 0.0, c->light_width - 1.0);
    y = sfb__rclamp(y, 0.0, c->light_height - 1.0);
    x0 = (int)x; y0 = (int)y; fx = x - x0; fy = y - y0;
    x1 = x0 + 1 < c->light_width ? x0 + 1 : x0;
    y1 = y0 + 1 < c->light_height ? y0 + 1 : y0;
    for (k = 0; k < 4; ++k) {
        const unsigned char *T = c->light_rgba;
        double a = T[4 * ((size_t)y0 * c->light_width + x0) + k], b = T[4 * ((size_t)y0 * c->light_width + x1) + k];
        double d = T[4 * ((size_t)y1 * c->light_width + x0) + k], e = T[4 * ((size_t)y1 * c->light_width + x1) + k];
        rgba[k] = ((a * (1 - fx) + b * fx) * (1 - fy) + (d * (1 - fx) + e * fx) * fy) / 255.0;
    }
}

/* Lit share of a light-pattern pixel (values a, b with footprints fa, fb) and its class (2/3). */
static double sfb__an_pattern(const sfb__an_look *L, double a, double b, double fa, double fb, int *cls) {
    double w = L->width, cover;
    if (L->pattern == SFB_LIGHT_LATTICE) {
        double ca = sfb__band_cover(a, fa, 0.0, w), cb = sfb__band_cover(b, fb, 0.0, w);
        double ra = a - floor(a), rb = b - floor(b);
        *cls = (ra < w || rb < w) ? 3 : 2;
        return ca + cb - ca * cb;
    }
    if (L->pattern == SFB_LIGHT_CIRCLES) {
        double ua = a - floor(a) - 0.5, ub = b - floor(b) - 0.5, d = sqrt(ua * ua + ub * ub), rad = 0.5 * w;
        double f = fa > fb ? fa : fb, edge, avg = SFB__PI * rad * rad, t;
        *cls = d < rad ? 3 : 2;
        edge = f > 1e-6 ? sfb__rclamp((rad - d) / f + 0.5, 0.0, 1.0) : (d < rad);
        t = sfb__rclamp((f - 0.25) / 0.25, 0.0, 1.0);
        cover = (1.0 - t) * edge + t * avg;
        return cover;
    }
    *cls = (a - floor(a)) < w ? 3 : 2;
    return sfb__band_cover(a, fa, 0.0, w);
}

/* Colours the pixels of rows [y0, y1) from the values (full-picture arrays v1, v2) and the
 * hits' normals (rows are independent: a task of sfb__parallel). */
typedef struct sfb__an_colour_job {
    const sfb__an *A;
    const sfb__an_look *L;
    const float *v1, *v2;
    unsigned char *rgba, *cls;
} sfb__an_colour_job;

static void sfb__an_colour(void *arg, int y0, int y1) {
    const sfb__an_colour_job *J = (const sfb__an_colour_job *)arg;
    const sfb__an *A = J->A;
    const sfb__an_look *L = J->L;
    const float *v1 = J->v1, *v2 = J->v2;
    unsigned char *rgba = J->rgba, *cls = J->cls;
    const sfb_analyze_config *c = A->c;
    const int mode = c->mode, w = A->w, ortho = A->cam.ortho;
    int col, row;
    for (row = y0; row < y1; ++row)
        for (col = 0; col < w; ++col) {
            const size_t p = (size_t)row * (size_t)w + (size_t)col;
            int k = A->hit[p], i, cl = 2;
            double rgb[3] = { 0.0, 0.0, 0.0 }, n[3], diff, a;
            unsigned char *o = rgba + 4 * p;
            if (k < 0) { memcpy(o, L->bg, 4); cls[p] = 0; continue; }
            a = v1[p];
            {
                const float *hn = A->hnrm + 3 * (size_t)k;
                double vv[3];
                n[0] = hn[0]; n[1] = hn[1]; n[2] = hn[2];
                if (ortho) for (i = 0; i < 3; ++i) vv[i] = -A->cam.fwd[i];
                else {
                    const float *hp = A->hpos + 3 * (size_t)k;
                    for (i = 0; i < 3; ++i) vv[i] = A->cam.eye[i] - hp[i];
                }
                if (sfb__rdot(vv, n) < 0.0) for (i = 0; i < 3; ++i) n[i] = -n[i];
            }
            diff = sfb__rdot(n, L->key);
            if (diff < 0.0) diff = 0.0;
            switch (mode) {
            case SFB_ANALYZE_REFLECTION:
            case SFB_ANALYZE_HIGHLIGHT:
                if (!isfinite(a)) {
                    /* the miss colour, lit a little by the key light so that the form still reads */
                    cl = 1;
                    for (i = 0; i < 3; ++i) rgb[i] = L->miss[i] / 255.0 * (0.55 + 0.9 * diff);
                    break;
                }
                if (L->pattern == SFB_LIGHT_IMAGE) {
                    double t[4], base = mode == SFB_ANALYZE_REFLECTION ? 0.08 : 0.3 + 0.4 * diff;
                    sfb__an_texel(c, a / L->job.periods[0], v2[p] / L->job.periods[1], t);
                    for (i = 0; i < 3; ++i) rgb[i] = base * (1.0 - t[3]) + t[i] * t[3];
                    cl = 2 + (0.299 * t[0] + 0.587 * t[1] + 0.114 * t[2] >= 0.5);
                } else {
                    /* stripes read only the first value's footprint */
                    double fa = sfb__an_footprint(v1, A->w, A->h, col, row),
                           fb = L->pattern == SFB_LIGHT_LATTICE || L->pattern == SFB_LIGHT_CIRCLES ? sfb__an_footprint(v2, A->w, A->h, col, row) : 0.0;
                    double cover = sfb__an_pattern(L, a, v2[p], fa, fb, &cl);
                    if (mode == SFB_ANALYZE_REFLECTION) {
                        double dark = 0.07 + 0.16 * diff;
                        for (i = 0; i < 3; ++i) rgb[i] = dark * (1.0 - cover) + 0.97 * cover;
                    } else {
                        double base = 0.45 + 0.5 * diff, blue[3];
                        blue[0] = 0.05 * base; blue[1] = 0.12 * base; blue[2] = 0.70 * base;
                        for (i = 0; i < 3; ++i) rgb[i] = base * cover + blue[i] * (1.0 - cover);
                    }
                }
                break;
            case SFB_ANALYZE_ZEBRA: {
                double fa = sfb__an_footprint(v1, A->w, A->h, col, row), cover = sfb__band_cover(a, fa, 0.0, L->width);
                cl = (a - floor(a)) < L->width ? 3 : 2;
                for (i = 0; i < 3; ++i) rgb[i] = 0.04 + 0.92 * cover;
                break;
            }
            case SFB_ANALYZE_ISOPHOTE: {
                double N = L->job.periods[0], x = (sfb__rclamp(a, -1.0, 1.0) + 1.0) * 0.5 * N, fx = sfb__an_footprint(v1, A->w, A->h, col, row) * 0.5 * N;
                double kb = floor(x), f = x - kb, c0[3], c1[3], m = 0.0;
                int kk = (int)kb, nb = kk;
                if (kk >= (int)N) kk = (int)N - 1;
                cl = 2 + (kk < 0 ? 0 : kk > 200 ? 200 : kk);
                sfb__colormap((kk + 0.5) / N, c0);
                if (fx > 1e-6 && f < 0.5 * fx) { nb = kk - 1; m = (0.5 * fx - f) / fx; }
                else if (fx > 1e-6 && 1.0 - f < 0.5 * fx) { nb = kk + 1; m = (0.5 * fx - (1.0 - f)) / fx; }
                if (nb < 0) nb = 0;
                if (nb >= (int)N) nb = (int)N - 1;
                sfb__colormap((nb + 0.5) / N, c1);
                for (i = 0; i < 3; ++i) rgb[i] = c0[i] * (1.0 - m) + c1[i] * m;
                break;
            }
            case SFB_ANALYZE_CURVATURE: {
                double t, lum = 0.72 + 0.28 * diff;
                if (!isfinite(a)) { cl = 1; rgb[0] = rgb[1] = rgb[2] = 0.5; break; }
                if (c->curvature == SFB_CURVATURE_MAX_ABS) {
                    t = sfb__rclamp(a / L->range, 0.0, 1.0);
                    cl = 2 + (int)sfb__rclamp(floor(t * 16.0), 0.0, 15.0);
                    sfb__colormap(t, rgb);
                } else {
                    static const double neg[3] = { 0.12, 0.30, 1.00 }, pos[3] = { 1.00, 0.16, 0.08 };
                    t = sfb__rclamp(a / L->range, -1.0, 1.0);
                    cl = 2 + 8 + (int)floor(t * 8.0 + 0.5); /* 17 bins, the middle one centred on 0 */
                    for (i = 0; i < 3; ++i) rgb[i] = (1.0 - fabs(t)) * 0.96 + fabs(t) * (t < 0.0 ? neg[i] : pos[i]);
                }
                for (i = 0; i < 3; ++i) rgb[i] *= lum;
                break;
            }
            case SFB_ANALYZE_NORMALS:
                for (i = 0; i < 3; ++i) rgb[i] = 0.5 + 0.5 * A->hnrm[3 * (size_t)k + i];
                break;
            default: {
                double hv[3], vv[3], spec;
                if (A->cam.ortho) for (i = 0; i < 3; ++i) vv[i] = -A->cam.fwd[i];
                else for (i = 0; i < 3; ++i) vv[i] = A->cam.eye[i] - A->hpos[3 * (size_t)k + i];
                sfb__rnormalize(vv);
                for (i = 0; i < 3; ++i) hv[i] = L->key[i] + vv[i];
                sfb__rnormalize(hv);
                spec = sfb__rdot(n, hv);
                spec = spec > 0.0 ? pow(spec, 48.0) : 0.0;
                rgb[0] = rgb[1] = rgb[2] = pow(sfb__rclamp(0.72 * (0.16 + 0.78 * diff) + 0.3 * spec, 0.0, 1.0), 1.0 / 1.6);
                break;
            }
            }
            cls[p] = (unsigned char)cl;
            o[0] = sfb__to_byte(rgb[0]); o[1] = sfb__to_byte(rgb[1]); o[2] = sfb__to_byte(rgb[2]); o[3] = 255;
        }
}

/* The shade kernel of the context's backend, or ref's. */
static sfb_result sfb__an_shade(const sfb__an *A, const sfb__shade_job *job, int n) {
    sfb_context *ctx = A->ctx;
    const sfb__backend_vtable *be = ctx->backend;
    if (n == 0) return SFB_SUCCESS;
    if (!be || !be->shade) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks shade; using ref", be ? be->name : "none");
        return sfb__ref_shade(NULL, job, 0, n);
    }
    return be->shade(ctx->backend_state, job, 0, n);
}

static void sfb__an_free(sfb__an *A) {
    sfb__an_put(A, A->gpos); sfb__an_put(A, A->gnrm); sfb__an_put(A, A->rv); sfb__an_put(A, A->rtri); sfb__an_put(A, A->ybox);
    sfb__an_put(A, A->cface); sfb__an_put(A, A->cuv); sfb__an_put(A, A->cdist);
    sfb__an_put(A, A->depth); sfb__an_put(A, A->face); sfb__an_put(A, A->uv); sfb__an_put(A, A->ppos); sfb__an_put(A, A->pnrm);
    sfb__an_put(A, A->hit); sfb__an_put(A, A->state); sfb__an_put(A, A->cand); sfb__an_put(A, A->zmax); sfb__an_put(A, A->ucov);
    sfb__an_put(A, A->hpix); sfb__an_put(A, A->hpos); sfb__an_put(A, A->hdu); sfb__an_put(A, A->hdv);
    sfb__an_put(A, A->hnrm); sfb__an_put(A, A->hdepth); sfb__an_put(A, A->hinv); sfb__an_put(A, A->hl); sfb__an_put(A, A->chg);
    sfb__an_put(A, A->adj);
}

/* Bytes the analysis will hold at its peak (checked against the budget before allocating). */
static double sfb__an_bytes(const sfb__an *A) {
    double npix = (double)A->w * A->h, grid = (double)A->nf * A->per;
    double per_pixel = 16 + 4 + 4 + 8 + 4 + 1 + 1 + 1 /* zmax, ucov */ + 4 + 4 + 1 + 4 + 12 /* buffers, outputs */ + 4 + 24 + 4 + 16 + 12 /* hits */ +
                       (A->c->mode == SFB_ANALYZE_CURVATURE ? 24 + 12 + 36 : 0) /* their first and second derivatives */ +
                       (A->c->polygon_based ? 24 : 92 + 16 + 2) /* proxy data or the projection's attempts, marks and neighbour masks */;
    return npix * per_pixel + grid * (24.0 + sizeof(sfb__raster_vertex) + 2 * 2 * 4 * sizeof(int) + 2 * 2 * 2 * sizeof(float)) + 65536.0 * sizeof(sfb_location) + (double)A->nf * 4 * (sizeof(int) + sizeof(sfb__an_side) + 12 * sizeof(int)) /* adjacency, its hash table */;
}

/* The per-pixel buffers of rows [y0, y1) before the raster: nothing drawn, nothing hit. */
static void sfb__an_clear_rows(void *arg, int y0, int y1) {
    sfb__an *A = (sfb__an *)arg;
    size_t p, end = (size_t)y1 * (size_t)A->w;
    for (p = (size_t)y0 * (size_t)A->w; p < end; ++p) {
        A->depth[p] = A->cdist[p] = (float)HUGE_VAL;
        A->face[p] = A->cface[p] = -1;
        A->hit[p] = -1;
    }
}

/* The buffers of one analysis (A's sizes set), initialised; 0 when one could not be had. */
static int sfb__an_alloc(sfb__an *A) {
    size_t npix = (size_t)A->w * (size_t)A->h, grid = (size_t)A->nf * (size_t)A->per;
    A->gpos = (float *)sfb__an_get(A, SFB__WS_GPOS, grid * 3 * sizeof(float), NULL);
    A->gnrm = (float *)sfb__an_get(A, SFB__WS_GNRM, grid * 3 * sizeof(float), NULL);
    A->rv = (sfb__raster_vertex *)sfb__an_get(A, SFB__WS_RV, grid * sizeof(sfb__raster_vertex), NULL);
    /* at most two triangles per grid point, then as many in the raster's order (sfb__an_order) */
    A->rtri = (int *)sfb__an_get(A, SFB__WS_RTRI, grid * 2 * 2 * 4 * sizeof(int), NULL);
    A->ybox = (float *)sfb__an_get(A, SFB__WS_YBOX, grid * 2 * 2 * 2 * sizeof(float), NULL);
    A->depth = (float *)sfb__an_get(A, SFB__WS_DEPTH, npix * sizeof(float), NULL);
    A->face = (int *)sfb__an_get(A, SFB__WS_FACE, npix * sizeof(int), NULL);
    A->uv = (float *)sfb__an_get(A, SFB__WS_UV, npix * 2 * sizeof(float), NULL);
    A->hit = (int *)sfb__an_get(A, SFB__WS_HIT, npix * sizeof(int), NULL);
    A->adj = (int *)sfb__an_get(A, SFB__WS_ADJ, ((size_t)A->nf + 1) * 4 * sizeof(int), NULL);
    A->cface = (int *)sfb__an_get(A, SFB__WS_CFACE, npix * sizeof(int), NULL);
    A->cuv = (float *)sfb__an_get(A, SFB__WS_CUV, npix * 2 * sizeof(float), NULL);
    A->cdist = (float *)sfb__an_get(A, SFB__WS_CDIST, npix * sizeof(float), NULL);
    A->state = (unsigned char *)sfb__an_get_zeroed(A, SFB__WS_STATE, npix);
    A->cand = (unsigned char *)sfb__an_get(A, SFB__WS_CAND, npix, NULL);
    A->zmax = (float *)sfb__an_get(A, SFB__WS_ZMAX, (size_t)A->h * (size_t)((A->w + 7) / 8) * sizeof(float) + 1, NULL);
    A->ucov = (unsigned char *)sfb__an_get(A, SFB__WS_UCOV, ((size_t)A->h + (size_t)(A->h + 7) / 8) * (size_t)((A->w + 7) / 8) + 1, NULL);
    if (A->c->polygon_based) {
        A->ppos = (float *)sfb__an_get(A, SFB__WS_PPOS, npix * 3 * sizeof(float), NULL);
        A->pnrm = (float *)sfb__an_get(A, SFB__WS_PNRM, npix * 3 * sizeof(float), NULL);
    }
    A->hpix = (int *)sfb__an_get(A, SFB__WS_HPIX, npix * sizeof(int), NULL);
    A->hpos = (float *)sfb__an_get(A, SFB__WS_HPOS, npix * 3 * sizeof(float), NULL);
    if (A->c->mode == SFB_ANALYZE_CURVATURE) { /* the first derivatives: only curvature reads them after the projection */
        A->hdu = (float *)sfb__an_get(A, SFB__WS_HDU, npix * 3 * sizeof(float), NULL);
        A->hdv = (float *)sfb__an_get(A, SFB__WS_HDV, npix * 3 * sizeof(float), NULL);
    }
    A->hnrm = (float *)sfb__an_get(A, SFB__WS_HNRM, npix * 3 * sizeof(float), NULL);
    A->hdepth = (float *)sfb__an_get(A, SFB__WS_HDEPTH, npix * sizeof(float), NULL);
    A->hinv = (float *)sfb__an_get(A, SFB__WS_HINV, npix * 4 * sizeof(float), NULL);
    A->hl = (sfb_location *)sfb__an_get(A, SFB__WS_HL, npix * sizeof(sfb_location), NULL);
    A->chg = (int *)sfb__an_get(A, SFB__WS_CHG, (npix + 1) * sizeof(int), NULL);
    if (!A->gpos || !A->gnrm || !A->rv || !A->rtri || !A->ybox || !A->depth || !A->face || !A->uv || !A->hit || !A->adj || !A->cface || !A->cuv || !A->cdist || !A->state || !A->cand || !A->zmax || !A->ucov ||
        (A->c->polygon_based && (!A->ppos || !A->pnrm)) || !A->hpix || !A->hpos || (A->c->mode == SFB_ANALYZE_CURVATURE && (!A->hdu || !A->hdv)) || !A->hnrm || !A->hdepth ||
        !A->hinv || !A->hl || !A->chg)
        return 0;
    sfb__an_run(A, sfb__an_clear_rows, A, 0, A->h, (double)npix * 0.1);
    return 1;
}

/* Step 2 for polygon_based: every proxy pixel is a "hit" on its interpolated data. */
static void sfb__an_polygon_hits(sfb__an *A) {
    static const float zero[3] = { 0.0f, 0.0f, 0.0f };
    size_t npix = (size_t)A->w * (size_t)A->h, p;
    for (p = 0; p < npix; ++p)
        if (A->face[p] >= 0) {
            sfb_location l;
            l.face = A->face[p]; l.u = A->uv[2 * p]; l.v = A->uv[2 * p + 1];
            sfb__an_add_hit(A, (int)p, &l, A->depth[p], A->ppos + 3 * p, zero, zero, A->pnrm + 3 * p);
            sfb__an_unit3f(A->hnrm + 3 * (size_t)A->hit[p]);
        }
}

/* Step 3: the second derivatives (CURVATURE) and the shade kernel into hv1, hv2 (nhit each). */
static sfb_result sfb__an_values(sfb__an *A, sfb__an_look *L, float *hv1, float *hv2) {
    const sfb_analyze_config *c = A->c;
    float *sec = NULL;
    sfb_result r = SFB_SUCCESS;
    int k;
    L->job.position = A->hpos; L->job.du = A->hdu; L->job.dv = A->hdv; L->job.normal = A->hnrm;
    L->job.value = hv1; L->job.value2 = hv2;
    if (c->mode == SFB_ANALYZE_CURVATURE && A->nhit > 0) {
        sfb_eval_output o;
        sfb_location *loc = (sfb_location *)sfb__an_get(A, SFB__WS_HLOC, (size_t)A->nhit * sizeof(sfb_location), NULL);
        sec = (float *)sfb__an_get(A, SFB__WS_SEC, (size_t)A->nhit * 9 * sizeof(float), NULL);
        if (!sec || !loc) { sfb__an_put(A, loc); sfb__an_put(A, sec); return sfb__oom(A->ctx, "the analysis second derivatives"); }
        for (k = 0; k < A->nhit; ++k) loc[k] = A->hl[A->hpix[k]]; /* the hits' locations, in slot order */
        memset(&o, 0, sizeof o);
        o.duu = sec; o.duv = sec + 3 * (size_t)A->nhit; o.dvv = sec + 6 * (size_t)A->nhit;
        r = sfb__surface_eval_unchecked(A->s, loc, A->nhit, &o);
        sfb__an_put(A, loc);
        L->job.duu = o.duu; L->job.duv = o.duv; L->job.dvv = o.dvv;
        /* curvature is the geometry's: where the normals come from a field of their own (PN
         * triangles' quadratic normals), the second fundamental form takes du x dv instead */
        if (A->s->patches.normal_field)
            for (k = 0; k < A->nhit; ++k) {
                const float *a = A->hdu + 3 * (size_t)k, *b = A->hdv + 3 * (size_t)k;
                float *n = A->hnrm + 3 * (size_t)k;
                const double x = (double)a[1] * b[2] - (double)a[2] * b[1], y = (double)a[2] * b[0] - (double)a[0] * b[2],
                             z = (double)a[0] * b[1] - (double)a[1] * b[0], len = sqrt(x * x + y * y + z * z);
                if (len > 0.0) { n[0] = (float)(x / len); n[1] = (float)(y / len); n[2] = (float)(z / len); }
            }
    }
    if (r == SFB_SUCCESS) r = sfb__an_shade(A, &L->job, A->nhit);
    if (r == SFB_SUCCESS && c->mode == SFB_ANALYZE_CURVATURE && c->curvature == SFB_CURVATURE_GAUSSIAN) {
        /* the noise floor of float second derivatives: a Gaussian curvature under (1e-4 per
         * bounding radius)^2 is 0, so that a flat region is flat on every backend (the float
         * kernels leave K ~1e-10 / R^2 there where ref leaves ~1e-26, and the automatic range
         * would amplify either) */
        const double floor_k = 1e-8 / (A->radius * A->radius);
        for (k = 0; k < A->nhit; ++k)
            if (fabs(hv1[k]) < floor_k) hv1[k] = 0.0f;
    }
    L->job.duu = L->job.duv = L->job.dvv = NULL;
    sfb__an_put(A, sec);
    return r;
}

/* The picture's per-pixel values and hits on rows [y0, y1): the pixel's hit's, else no value,
 * no hit. */
typedef struct sfb__an_fill_job {
    const sfb__an *A;
    const float *hv1, *hv2;
    float *v1, *v2;
    sfb_location *hits;
} sfb__an_fill_job;

static void sfb__an_fill_picture(void *arg, int y0, int y1) {
    const sfb__an_fill_job *J = (const sfb__an_fill_job *)arg;
    const sfb__an *A = J->A;
    size_t p, end = (size_t)y1 * (size_t)A->w;
    for (p = (size_t)y0 * (size_t)A->w; p < end; ++p) {
        const int k = A->hit[p];
        if (k >= 0) {
            J->v1[p] = J->hv1[k]; J->v2[p] = J->hv2[k];
            J->hits[p] = A->hl[p];
        } else {
            J->v1[p] = J->v2[p] = NAN;
            J->hits[p].face = -1;
            J->hits[p].u = J->hits[p].v = 0.0f;
        }
    }
}

/* The finite values' smallest, largest and count, of parts [c0, c1) of SFB__AN_CHUNKS of v[0..n). */
typedef struct sfb__an_range_job {
    const float *v;
    int n;
    float *mn, *mx;
    int *cnt;
} sfb__an_range_job;
static void sfb__an_value_range(void *arg, int c0, int c1) {
    const sfb__an_range_job *R = (const sfb__an_range_job *)arg;
    int c, k;
    for (c = c0; c < c1; ++c) {
        const int a = (int)((long long)R->n * c / SFB__AN_CHUNKS), b = (int)((long long)R->n * (c + 1) / SFB__AN_CHUNKS);
        float mn = (float)HUGE_VAL, mx = (float)-HUGE_VAL;
        int n = 0;
        for (k = a; k < b; ++k)
            if (isfinite(R->v[k])) {
                if (R->v[k] < mn) mn = R->v[k];
                if (R->v[k] > mx) mx = R->v[k];
                ++n;
            }
        R->mn[c] = mn; R->mx[c] = mx; R->cnt[c] = n;
    }
}

/* Step 4: the picture and its per-pixel outputs into out (on success the arrays are out's). */
static sfb_result sfb__an_picture(sfb__an *A, sfb__an_look *L, const float *hv1, const float *hv2, sfb_analysis *out) {
    sfb_context *ctx = A->ctx;
    const sfb_analyze_config *c = A->c;
    size_t npix = (size_t)A->w * (size_t)A->h;
    float *v1 = (float *)sfb__alloc(ctx, npix * sizeof(float)), *v2 = (float *)sfb__an_get(A, SFB__WS_V2, npix * sizeof(float), NULL);
    unsigned char *rgba = (unsigned char *)sfb__alloc(ctx, npix * 4), *cls = (unsigned char *)sfb__alloc(ctx, npix);
    sfb_location *hits = (sfb_location *)sfb__alloc(ctx, npix * sizeof(sfb_location));
    sfb_result r = SFB_SUCCESS;
    int k, light_hits = 0;
    if (!v1 || !v2 || !rgba || !cls || !hits) { r = sfb__oom(ctx, "the analysis picture"); goto done; }
    {
        sfb__an_fill_job F;
        F.A = A; F.hv1 = hv1; F.hv2 = hv2; F.v1 = v1; F.v2 = v2; F.hits = hits;
        sfb__an_run(A, sfb__an_fill_picture, &F, 0, A->h, (double)npix * 0.1);
    }
    {
        /* over the threads in SFB__AN_CHUNKS parts, combined in order */
        sfb__an_range_job R;
        float mn[SFB__AN_CHUNKS], mx[SFB__AN_CHUNKS];
        int cnt[SFB__AN_CHUNKS];
        R.v = hv1; R.n = A->nhit; R.mn = mn; R.mx = mx; R.cnt = cnt;
        sfb__an_run(A, sfb__an_value_range, &R, 0, SFB__AN_CHUNKS, (double)A->nhit);
        out->value_min = (float)HUGE_VAL; out->value_max = (float)-HUGE_VAL;
        for (k = 0; k < SFB__AN_CHUNKS; ++k) {
            if (mn[k] < out->value_min) out->value_min = mn[k];
            if (mx[k] > out->value_max) out->value_max = mx[k];
            light_hits += cnt[k]; /* REFLECTION, HIGHLIGHT: a finite value is a ray that meets the light */
        }
    }
    if (c->mode != SFB_ANALYZE_REFLECTION && c->mode != SFB_ANALYZE_HIGHLIGHT) light_hits = 0;
    if (!(out->value_min <= out->value_max)) out->value_min = out->value_max = 0.0f;
    L->range = 0.0;
    if (c->mode == SFB_ANALYZE_CURVATURE && (r = sfb__an_range(A, hv1, A->nhit, &L->range)) != SFB_SUCCESS) goto done;
    {
        sfb__an_colour_job J;
        J.A = A; J.L = L; J.v1 = v1; J.v2 = v2; J.rgba = rgba; J.cls = cls;
        sfb__an_run(A, sfb__an_colour, &J, 0, A->h, (double)A->nhit);
    }
    if ((c->mode == SFB_ANALYZE_REFLECTION || c->mode == SFB_ANALYZE_HIGHLIGHT) && A->nhit > 0 && light_hits == 0) {
        r = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                       "the light plane meets none of the %d rays from the surface: it is parallel to them, behind the surface or too small",
                       A->nhit);
        goto done;
    }
    out->width = A->w; out->height = A->h;
    out->rgba = rgba; out->values = v1; out->classes = cls; out->hits = hits;
    out->light_hits = light_hits;
    out->range = (float)L->range;
    rgba = NULL; v1 = NULL; cls = NULL; hits = NULL;
done:
    sfb__free(ctx, v1); sfb__an_put(A, v2); sfb__free(ctx, rgba); sfb__free(ctx, cls); sfb__free(ctx, hits);
    return r;
}

SFB_API sfb_result sfb_surface_analyze(const sfb_surface *s, const sfb_analyze_config *cfg, sfb_analysis *out) {
    sfb_analyze_config c;
    sfb__an A;
    sfb__an_look L;
    sfb_context *ctx;
    size_t npix;
    float *hv1 = NULL, *hv2 = NULL;
    sfb_result r;
    int level = 0, fallback = 0, dropped = 0, proxy_pixels = 0, grown = 0;
    double need;
    if (out) memset(out, 0, sizeof *out);
    if (!s) return SFB_INVALID_ARGS;
    ctx = s->ctx;
    if (!out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_analyze: NULL output");
    if (!s->has_patches)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_analyze: the surface has no patch table (create it with SFB_REFINE_PATCHES)");
    c = cfg ? *cfg : sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
    memset(&A, 0, sizeof A);
    if ((r = sfb__an_check(ctx, &c, &A.w, &A.h, &level)) != SFB_SUCCESS) return r;
    A.ctx = ctx; A.s = s; A.c = &c;
    A.ws = c.workspace;
    if (A.ws && A.ws->ctx != ctx)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_analyze: the workspace was made on another context");
    A.tri = s->patches.domain == SFB__DOMAIN_TRI;
    A.nf = s->patches.nptex;
    sfb__an_camera(&A); /* the base mesh's box and the config: before the proxy, for the level */
    if (level == 0) level = c.polygon_based ? SFB__AN_DEFAULT_LEVEL : sfb__an_auto_level(&A);
    A.R = 1 << level;
    A.per = A.tri ? (A.R + 1) * (A.R + 2) / 2 : (A.R + 1) * (A.R + 1);
    npix = (size_t)A.w * (size_t)A.h;
    if ((double)A.nf * A.per > 2147483647.0)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "proxy of %d parametric faces at level %d is too large", A.nf, level);
    need = sfb__an_bytes(&A) - (double)sfb_analysis_workspace_bytes(A.ws); /* what the workspace holds is in use already */
    if (need > (double)ctx->budget - (double)ctx->live_bytes)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "a %d x %d analysis with a level-%d proxy needs about %.0f MB, over the memory budget (%zu bytes, %zu in use)", A.w,
                          A.h, level, need / 1048576.0, ctx->budget, ctx->live_bytes);
    if ((r = sfb__progress(ctx, 0.0f, "analyze")) != SFB_SUCCESS) return r;
    {
        /* the workspace's proxy and adjacency: kept when they are this surface's at this level */
        sfb_analysis_workspace *ws = A.ws;
        const int same = ws && s->serial != 0 && ws->proxy_serial == s->serial && ws->proxy_level == level;
        const int proxy_kept = same && ws->proxy_ok, adj_kept = same && ws->adj_ok;
        if (ws) {
            if (!same) ws->adj_ok = 0;
            ws->proxy_ok = 0; /* until computed (or kept) below */
            ws->proxy_serial = s->serial;
            ws->proxy_level = level;
        }
        if (!sfb__an_alloc(&A)) { r = sfb__oom(ctx, "the analysis buffers"); goto done; }
        /* 1: the proxy and its raster */
        if (proxy_kept) r = sfb__progress(ctx, 0.2f, "analyze");
        else r = sfb__an_proxy(&A);
        if (r != SFB_SUCCESS) goto done;
        if (ws) ws->proxy_ok = 1;
        if (!c.polygon_based && !adj_kept) {
            if (ws) ws->adj_ok = 0;
            if ((r = sfb__an_adjacency(&A)) != SFB_SUCCESS) goto done;
            if (ws) ws->adj_ok = 1;
        }
    }
    if ((r = sfb__an_raster(&A)) != SFB_SUCCESS) goto done;
    {
        /* the candidates of the projection and the proxy's pixels, row by row over the threads */
        sfb__an_cand_job J;
        int y;
        J.A = &A;
        J.rowcnt = (int *)sfb__alloc(ctx, ((size_t)A.h + 1) * sizeof(int));
        if (!J.rowcnt) { r = sfb__oom(ctx, "the analysis rows"); goto done; }
        sfb__an_run(&A, sfb__an_candidates, &J, 0, A.h, (double)npix * 0.2);
        for (y = 0; y < A.h; ++y) proxy_pixels += J.rowcnt[y];
        sfb__free(ctx, J.rowcnt);
    }
    if ((r = sfb__progress(ctx, 0.3f, "analyze")) != SFB_SUCCESS) goto done;
    /* 2: onto the exact surface (or the polygon-based data) */
    if (c.polygon_based) sfb__an_polygon_hits(&A);
    else {
        if ((r = sfb__an_project_all(&A, c.newton_steps ? c.newton_steps : SFB__AN_DEFAULT_STEPS)) != SFB_SUCCESS) goto done;
        /* grown: counted before the fallback, whose hits are all on the proxy */
        if ((r = sfb__an_leftovers(&A, &fallback, &dropped, &grown)) != SFB_SUCCESS) goto done;
    }
    if ((r = sfb__progress(ctx, 0.75f, "analyze")) != SFB_SUCCESS) goto done;
    /* 3: the values */
    sfb__an_lights(&A, &L);
    hv1 = (float *)sfb__an_get(&A, SFB__WS_HV1, ((size_t)A.nhit + 1) * sizeof(float), NULL);
    hv2 = (float *)sfb__an_get(&A, SFB__WS_HV2, ((size_t)A.nhit + 1) * sizeof(float), NULL);
    if (!hv1 || !hv2) { r = sfb__oom(ctx, "the analysis values"); goto done; }
    if ((r = sfb__an_values(&A, &L, hv1, hv2)) != SFB_SUCCESS) goto done;
    if ((r = sfb__progress(ctx, 0.9f, "analyze")) != SFB_SUCCESS) goto done;
    /* 4: colours */
    if ((r = sfb__an_picture(&A, &L, hv1, hv2, out)) != SFB_SUCCESS) goto done;
    out->covered_pixels = A.nhit;
    out->proxy_pixels = proxy_pixels;
    out->grown_pixels = grown;
    out->dropped_pixels = dropped;
    out->fallback_pixels = fallback;
    out->proxy_level = level;
    out->ctx_ = ctx;
    if ((r = sfb__progress(ctx, 1.0f, "analyze")) != SFB_SUCCESS) sfb_analysis_free(out);
done:
    if (r != SFB_SUCCESS) memset(out, 0, sizeof *out);
    sfb__an_free(&A);
    sfb__an_put(&A, hv1);
    sfb__an_put(&A, hv2);
    return r;
}
#line 1 "src/aabb.c"
/* An axis-aligned bounding-box tree over triangles and the robust triangle geometry built on it
 * (the rolling-ball operator's intersections and projections, seed 002, and the checks of any
 * triangle mesh): a top-down build by median split on the longest axis of each node's box
 * (leaves of at most SFB__AABB_LEAF triangles, so the depth is at most about log2(count) and
 * every traversal runs on a small fixed stack), all pairs of overlapping triangle boxes of two
 * trees or of one tree with itself by simultaneous descent, the nearest point by branch and
 * bound, the closest point on one triangle (the Voronoi-region method of Ericson's Real-Time
 * Collision Detection, written here from the geometry), the intersection segment of two
 * triangles (the interval method of Moller 1997 with the care of Guigue-Devillers 2003 for
 * vertices on planes and coplanar pairs) and a mesh's self-intersections. Storage: the node array
 * holds node_count tree nodes followed by item_count boxes, nodes[node_count + i] being the box of
 * triangle items[i] (sfb__aabb has no other place for them; the pair query tests them so that it
 * reports exactly the triangle pairs whose own boxes overlap). Everything is double; a built tree
 * is read-only and any number of threads may query it at once. */

#define SFB__AABB_LEAF 4
/* Median splits halve a node (the larger half has ceil(n/2) items), so a tree over at most
 * INT_MAX triangles with leaves of 4 is at most 30 levels deep: a descent of one tree pushes at
 * most 2 nodes per level, a simultaneous descent of two at most 3 pairs per step of at most 60. */
#define SFB__AABB_STACK 256

/* The tolerances of the triangle-triangle test (sfb__tri_tri_segment), relative to s, the
 * longest edge of the two triangles:
 *   - a triangle is degenerate (zero area) when |(v1 - v0) x (v2 - v0)| <= SFB__TT_AREA * L^2, L its
 *     own longest edge: its smallest height is below 1e-12 L (this also catches L = 0);
 *   - a vertex lies on the other triangle's plane when its signed distance to it (the unit normal
 *     dotted with the vertex minus a vertex of the plane's triangle) is within SFB__TT_DIST * s;
 *   - intervals on the line of the two planes, and projections of coplanar triangles on a
 *     separating axis, touch when their gap is within the same SFB__TT_DIST * s.
 * Rounding of these distances is a few units of 1e-16 s for triangles that are not needles, so
 * shared vertices and edges (bitwise equal coordinates) always land on the planes. */
#define SFB__TT_AREA 1e-12
#define SFB__TT_DIST 1e-12
/* A segment between two triangles that share one vertex is more than that vertex when it is
 * longer than SFB__SELF_LEN * s (sfb__trimesh_self_intersections). */
#define SFB__SELF_LEN 1e-10

static void aabb_sub3(const double *a, const double *b, double *c) {
    c[0] = a[0] - b[0];
    c[1] = a[1] - b[1];
    c[2] = a[2] - b[2];
}
static double aabb_dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void aabb_cross3(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
static int aabb_finite3(const double *p) {
    /* x - x is 0 for finite x and NaN for inf and NaN */
    return p[0] - p[0] == 0.0 && p[1] - p[1] == 0.0 && p[2] - p[2] == 0.0;
}

/* ---- build ---- */

/* Reorders perm[lo, hi) so that perm[k] holds the item whose key (cen[3 * item + axis]) would be
 * there sorted, with no larger key before it and no smaller one after (Hoare partitions around
 * the median of three). */
static void aabb_select(int *perm, int lo, int hi, int k, const double *cen, int axis) {
    hi--;
    while (hi > lo) {
        const int mid = lo + (hi - lo) / 2;
        double x = cen[3 * (size_t)perm[lo] + axis], y = cen[3 * (size_t)perm[mid] + axis], z = cen[3 * (size_t)perm[hi] + axis];
        double pv;
        int i = lo, j = hi;
        if (x > y) { double s = x; x = y; y = s; }
        pv = z < x ? x : z > y ? y : z;
        while (i <= j) {
            while (cen[3 * (size_t)perm[i] + axis] < pv) i++;
            while (cen[3 * (size_t)perm[j] + axis] > pv) j--;
            if (i <= j) {
                const int s = perm[i];
                perm[i] = perm[j];
                perm[j] = s;
                i++;
                j--;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else break;
    }
}

sfb_result sfb__aabb_build(sfb_context *ctx, const double *pos, const int *tri, const int *ids, int count, sfb__aabb *out) {
    double *tbox = NULL, *cen = NULL;
    int *perm = NULL, m = 0, i, sp = 0;
    int stack[3 * SFB__AABB_STACK];
    size_t bytes, nodes_cap;
    sfb__aabb t;
    if (!out) return ctx ? sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb__aabb_build: NULL tree") : SFB_INVALID_ARGS;
    memset(out, 0, sizeof *out);
    if (!ctx) return SFB_INVALID_ARGS;
    if (count < 0 || (count > 0 && (!pos || !tri)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb__aabb_build: %d triangles without their arrays", count);
    if (count == 0) return SFB_SUCCESS;
    memset(&t, 0, sizeof t);
    if (!sfb__mul_size((size_t)count, 6 * sizeof(double), &bytes) || !(tbox = (double *)sfb__alloc(ctx, bytes)) ||
        !(cen = (double *)sfb__alloc(ctx, bytes / 2)) || !(perm = (int *)sfb__alloc(ctx, (size_t)count * sizeof(int)))) {
        sfb__free(ctx, tbox);
        sfb__free(ctx, cen);
        return sfb__oom(ctx, "an AABB tree's triangle boxes");
    }
    /* the finite triangles, each with its box and centroid */
    for (i = 0; i < count; ++i) {
        const int *v = tri + 3 * (size_t)i;
        double *lo = tbox + 6 * (size_t)m, *hi = lo + 3;
        int c, k, ok = v[0] >= 0 && v[1] >= 0 && v[2] >= 0;
        for (c = 0; c < 3 && ok; ++c) ok = aabb_finite3(pos + 3 * (size_t)v[c]);
        if (!ok) continue;
        for (k = 0; k < 3; ++k) {
            const double x = pos[3 * (size_t)v[0] + k], y = pos[3 * (size_t)v[1] + k], z = pos[3 * (size_t)v[2] + k];
            lo[k] = x < y ? (x < z ? x : z) : (y < z ? y : z);
            hi[k] = x > y ? (x > z ? x : z) : (y > z ? y : z);
            cen[3 * (size_t)m + k] = (x + y + z) * (1.0 / 3.0);
        }
        perm[m] = i;
        m++;
    }
    /* perm[j] is the j-th finite triangle; its box and centroid are at slot j */
    if (m == 0) goto done;
    nodes_cap = 2 * (size_t)m - 1 + (size_t)m;
    if (!sfb__mul_size(nodes_cap, sizeof(sfb__aabb_node), &bytes) || !(t.nodes = (sfb__aabb_node *)sfb__alloc(ctx, bytes)) ||
        !(t.items = (int *)sfb__alloc(ctx, (size_t)m * sizeof(int)))) {
        sfb__free(ctx, t.nodes);
        sfb__free(ctx, tbox);
        sfb__free(ctx, cen);
        sfb__free(ctx, perm);
        return sfb__oom(ctx, "an AABB tree");
    }
    {
        /* slots 0..m-1 sorted in place of ord; the tree refers to slots, items are filled last */
        int *ord = t.items;
        for (i = 0; i < m; ++i) ord[i] = i;
        t.node_count = 1;
        stack[sp++] = 0; stack[sp++] = 0; stack[sp++] = m;
        while (sp > 0) {
            const int e = stack[--sp], b = stack[--sp], nd = stack[--sp];
            sfb__aabb_node *N = &t.nodes[nd];
            int k, j, axis = 0;
            for (k = 0; k < 3; ++k) { N->lo[k] = HUGE_VAL; N->hi[k] = -HUGE_VAL; }
            for (j = b; j < e; ++j) {
                const double *bx = tbox + 6 * (size_t)ord[j];
                for (k = 0; k < 3; ++k) {
                    if (bx[k] < N->lo[k]) N->lo[k] = bx[k];
                    if (bx[3 + k] > N->hi[k]) N->hi[k] = bx[3 + k];
                }
            }
            N->first = b;
            N->count = e - b;
            if (e - b <= SFB__AABB_LEAF) {
                N->left = N->right = -1;
                continue;
            }
            for (k = 1; k < 3; ++k)
                if (N->hi[k] - N->lo[k] > N->hi[axis] - N->lo[axis]) axis = k;
            aabb_select(ord, b, e, b + (e - b) / 2, cen, axis);
            N->left = t.node_count++;
            N->right = t.node_count++;
            stack[sp++] = N->right; stack[sp++] = b + (e - b) / 2; stack[sp++] = e;
            stack[sp++] = N->left; stack[sp++] = b; stack[sp++] = b + (e - b) / 2;
        }
        t.item_count = m;
        for (i = 0; i < m; ++i) {
            const int slot = ord[i];
            sfb__aabb_node *B = &t.nodes[t.node_count + i];
            int k;
            for (k = 0; k < 3; ++k) {
                B->lo[k] = tbox[6 * (size_t)slot + k];
                B->hi[k] = tbox[6 * (size_t)slot + 3 + k];
            }
            B->left = B->right = -1;
            B->first = i;
            B->count = 1;
            ord[i] = ids ? ids[perm[slot]] : perm[slot];
        }
    }
done:
    sfb__free(ctx, tbox);
    sfb__free(ctx, cen);
    sfb__free(ctx, perm);
    *out = t;
    return SFB_SUCCESS;
}

void sfb__aabb_free(sfb_context *ctx, sfb__aabb *t) {
    if (!t) return;
    if (ctx) {
        sfb__free(ctx, t->nodes);
        sfb__free(ctx, t->items);
    }
    memset(t, 0, sizeof *t);
}

/* ---- pairs ---- */

static int aabb_overlap(const sfb__aabb_node *p, const sfb__aabb_node *q, double eps) {
    int k;
    for (k = 0; k < 3; ++k)
        if (p->lo[k] - eps > q->hi[k] + eps || q->lo[k] - eps > p->hi[k] + eps) return 0;
    return 1;
}

/* The triangles of leaves p of a and q of b (p == q within one tree: each pair of it once). */
static int aabb_leaf_pairs(const sfb__aabb *a, const sfb__aabb *b, const sfb__aabb_node *p, const sfb__aabb_node *q, int self,
                           double eps, int (*fn)(int, int, void *), void *user) {
    int i, j;
    for (i = p->first; i < p->first + p->count; ++i) {
        const sfb__aabb_node *bi = &a->nodes[a->node_count + i];
        for (j = (p == q ? i + 1 : q->first); j < q->first + q->count; ++j) {
            if (self && a->items[i] == b->items[j]) continue;
            if (aabb_overlap(bi, &b->nodes[b->node_count + j], eps) && fn(a->items[i], b->items[j], user)) return 1;
        }
    }
    return 0;
}

int sfb__aabb_pairs(const sfb__aabb *a, const sfb__aabb *b, double eps, int (*fn)(int, int, void *), void *user) {
    int stack[2 * SFB__AABB_STACK], sp = 0;
    const int self = a == b;
    if (!a || !b || !fn || a->node_count == 0 || b->node_count == 0) return 0;
    if (!(eps >= 0.0)) eps = 0.0;
    stack[sp++] = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const int j = stack[--sp], i = stack[--sp];
        const sfb__aabb_node *P = &a->nodes[i], *Q = &b->nodes[j];
        if (self && i == j) {
            /* one subtree with itself: its children with themselves and with each other */
            if (P->left < 0) {
                if (aabb_leaf_pairs(a, b, P, P, 1, eps, fn, user)) return 1;
                continue;
            }
            stack[sp++] = P->left; stack[sp++] = P->right;
            stack[sp++] = P->right; stack[sp++] = P->right;
            stack[sp++] = P->left; stack[sp++] = P->left;
            continue;
        }
        if (!aabb_overlap(P, Q, eps)) continue;
        if (P->left < 0 && Q->left < 0) {
            if (aabb_leaf_pairs(a, b, P, Q, self, eps, fn, user)) return 1;
        } else if (P->left < 0 || (Q->left >= 0 && Q->count > P->count)) {
            stack[sp++] = i; stack[sp++] = Q->right;
            stack[sp++] = i; stack[sp++] = Q->left;
        } else {
            stack[sp++] = P->right; stack[sp++] = j;
            stack[sp++] = P->left; stack[sp++] = j;
        }
    }
    return 0;
}

/* ---- nearest point ---- */

static double aabb_box_dist2(const sfb__aabb_node *n, const double *p) {
    double d = 0.0;
    int k;
    for (k = 0; k < 3; ++k) {
        const double e = p[k] < n->lo[k] ? n->lo[k] - p[k] : p[k] > n->hi[k] ? p[k] - n->hi[k] : 0.0;
        d += e * e;
    }
    return d;
}

int sfb__aabb_nearest(const sfb__aabb *t, const double *pos, const int *tri, const int *tri_of_id, const double p[3],
                      double out_point[3], double *out_dist2, double out_bary[3]) {
    int stack[SFB__AABB_STACK], sp = 0, best = -1, k;
    double bestd = HUGE_VAL, bq[3] = {0, 0, 0}, bb[3] = {0, 0, 0};
    if (t && t->node_count > 0 && pos && tri && p && aabb_finite3(p)) {
        stack[sp++] = 0;
        while (sp > 0) {
            const sfb__aabb_node *n = &t->nodes[stack[--sp]];
            if (aabb_box_dist2(n, p) >= bestd) continue;
            if (n->left < 0) {
                int i;
                for (i = n->first; i < n->first + n->count; ++i) {
                    const int id = t->items[i], row = tri_of_id ? tri_of_id[id] : id;
                    const int *v = tri + 3 * (size_t)row;
                    double q[3], bc[3], d[3], d2;
                    sfb__closest_on_triangle(p, pos + 3 * (size_t)v[0], pos + 3 * (size_t)v[1], pos + 3 * (size_t)v[2], q, bc);
                    aabb_sub3(q, p, d);
                    d2 = aabb_dot3(d, d);
                    if (d2 < bestd) {
                        bestd = d2;
                        best = id;
                        memcpy(bq, q, sizeof q);
                        memcpy(bb, bc, sizeof bc);
                    }
                }
            } else {
                const double dl = aabb_box_dist2(&t->nodes[n->left], p), dr = aabb_box_dist2(&t->nodes[n->right], p);
                /* the nearer child is searched first: pushed last */
                if (dl <= dr) {
                    if (dr < bestd) stack[sp++] = n->right;
                    if (dl < bestd) stack[sp++] = n->left;
                } else {
                    if (dl < bestd) stack[sp++] = n->left;
                    if (dr < bestd) stack[sp++] = n->right;
                }
            }
        }
    }
    if (out_point)
        for (k = 0; k < 3; ++k) out_point[k] = bq[k];
    if (out_dist2) *out_dist2 = bestd;
    if (out_bary)
        for (k = 0; k < 3; ++k) out_bary[k] = bb[k];
    return best;
}

/* ---- closest point on a triangle ---- */

/* The point of segment u-v nearest p, at u + s (v - u). */
static double aabb_closest_on_segment(const double *p, const double *u, const double *v, double *q) {
    double e[3], w[3], s, l2;
    aabb_sub3(v, u, e);
    aabb_sub3(p, u, w);
    l2 = aabb_dot3(e, e);
    s = l2 > 0.0 ? aabb_dot3(w, e) / l2 : 0.0;
    s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
    q[0] = u[0] + s * e[0];
    q[1] = u[1] + s * e[1];
    q[2] = u[2] + s * e[2];
    return s;
}

void sfb__closest_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3], double q[3],
                              double bary[3]) {
    double ab[3], ac[3], bc[3], ap[3], bp[3], cp[3], n[3], w[3] = {0, 0, 0};
    double lab, lac, lbc, lmax, d1, d2, d3, d4, d5, d6, va, vb, vc;
    int k;
    aabb_sub3(b, a, ab);
    aabb_sub3(c, a, ac);
    aabb_sub3(c, b, bc);
    aabb_cross3(ab, ac, n);
    lab = aabb_dot3(ab, ab);
    lac = aabb_dot3(ac, ac);
    lbc = aabb_dot3(bc, bc);
    lmax = lab > lac ? (lab > lbc ? lab : lbc) : (lac > lbc ? lac : lbc);
    if (!(aabb_dot3(n, n) > SFB__TT_AREA * SFB__TT_AREA * lmax * lmax)) {
        /* degenerate: the longest edge */
        double s;
        if (lmax == lab) { s = aabb_closest_on_segment(p, a, b, q); w[0] = 1.0 - s; w[1] = s; }
        else if (lmax == lac) { s = aabb_closest_on_segment(p, a, c, q); w[0] = 1.0 - s; w[2] = s; }
        else { s = aabb_closest_on_segment(p, b, c, q); w[1] = 1.0 - s; w[2] = s; }
        if (bary) memcpy(bary, w, sizeof w);
        return;
    }
    /* p's Voronoi region: the corners, then the edges, else the face. d1..d6 are the projections
     * of p - corner on the two edges from a; va, vb, vc are (up to a common factor) the
     * barycentric coordinates of p's projection on the plane. */
    aabb_sub3(p, a, ap);
    d1 = aabb_dot3(ab, ap);
    d2 = aabb_dot3(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) { w[0] = 1.0; goto out; }
    aabb_sub3(p, b, bp);
    d3 = aabb_dot3(ab, bp);
    d4 = aabb_dot3(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) { w[1] = 1.0; goto out; }
    vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double s = d1 / (d1 - d3);
        w[0] = 1.0 - s; w[1] = s;
        goto out;
    }
    aabb_sub3(p, c, cp);
    d5 = aabb_dot3(ab, cp);
    d6 = aabb_dot3(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) { w[2] = 1.0; goto out; }
    vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double s = d2 / (d2 - d6);
        w[0] = 1.0 - s; w[2] = s;
        goto out;
    }
    va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w[1] = 1.0 - s; w[2] = s;
        goto out;
    }
    {
        const double inv = 1.0 / (va + vb + vc);
        w[1] = vb * inv;
        w[2] = vc * inv;
        w[0] = 1.0 - w[1] - w[2];
    }
out:
    for (k = 0; k < 3; ++k) q[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
    if (bary) memcpy(bary, w, sizeof w);
}

/* ---- triangle-triangle intersection ---- */

/* The points where triangle V (signed distances d to the other plane, snapped: exact zeros are
 * on it) meets that plane: 1 (a vertex touching it) or 2, with the edge each lies on (off + k
 * for edge k; a vertex names an edge from it, the edge between them when two vertices are on the
 * plane). */
static int tt_plane_points(const double *const V[3], const double d[3], int off, double P[2][3], int src[2]) {
    int k, n = 0;
    for (k = 0; k < 3; ++k) {
        const int k1 = (k + 1) % 3;
        if (d[k] == 0.0 && d[k1] == 0.0) {
            memcpy(P[0], V[k], 3 * sizeof(double));
            memcpy(P[1], V[k1], 3 * sizeof(double));
            src[0] = src[1] = off + k;
            return 2;
        }
    }
    for (k = 0; k < 3 && n < 2; ++k)
        if (d[k] == 0.0) {
            memcpy(P[n], V[k], 3 * sizeof(double));
            src[n++] = off + k;
        }
    for (k = 0; k < 3 && n < 2; ++k) {
        const int k1 = (k + 1) % 3;
        if ((d[k] > 0.0 && d[k1] < 0.0) || (d[k] < 0.0 && d[k1] > 0.0)) {
            const double s = d[k] / (d[k] - d[k1]);
            int c;
            for (c = 0; c < 3; ++c) P[n][c] = V[k][c] + s * (V[k1][c] - V[k][c]);
            src[n++] = off + k;
        }
    }
    return n;
}

/* Do coplanar triangles A and B (in the plane of unit normal n) meet, touching included? Their
 * projections on the coordinate plane across n's largest component, separated by none of the six
 * edge normals (separating axes of two convex polygons) by more than tol along it. */
static int tt_coplanar_meet(const double *const A[3], const double *const B[3], const double *n, double tol) {
    const double ax = fabs(n[0]), ay = fabs(n[1]), az = fabs(n[2]);
    const int i0 = ax >= ay && ax >= az ? 1 : 0, i1 = ax >= ay && ax >= az ? 2 : ay >= az ? 2 : 1;
    double P[6][2];
    int e, k;
    for (k = 0; k < 3; ++k) {
        P[k][0] = A[k][i0]; P[k][1] = A[k][i1];
        P[3 + k][0] = B[k][i0]; P[3 + k][1] = B[k][i1];
    }
    for (e = 0; e < 6; ++e) {
        const double *p = P[e], *q = P[e < 3 ? (e + 1) % 3 : 3 + (e - 2) % 3];
        const double nx = -(q[1] - p[1]), ny = q[0] - p[0], len = sqrt(nx * nx + ny * ny);
        double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
        if (!(len > 0.0)) continue;
        for (k = 0; k < 6; ++k) {
            const double x = (nx * P[k][0] + ny * P[k][1]) / len;
            const int s = k / 3;
            if (x < lo[s]) lo[s] = x;
            if (x > hi[s]) hi[s] = x;
        }
        if (lo[1] > hi[0] + tol || lo[0] > hi[1] + tol) return 0;
    }
    return 1;
}

/* Longest squared edge of triangle V; n gets its (unnormalised) normal. */
static double tt_setup(const double *const V[3], double *n) {
    double e0[3], e1[3], e2[3], l0, l1, l2;
    aabb_sub3(V[1], V[0], e0);
    aabb_sub3(V[2], V[0], e1);
    aabb_sub3(V[2], V[1], e2);
    aabb_cross3(e0, e1, n);
    l0 = aabb_dot3(e0, e0);
    l1 = aabb_dot3(e1, e1);
    l2 = aabb_dot3(e2, e2);
    return l0 > l1 ? (l0 > l2 ? l0 : l2) : (l1 > l2 ? l1 : l2);
}

int sfb__tri_tri_segment(const double a0[3], const double a1[3], const double a2[3], const double b0[3], const double b1[3],
                         const double b2[3], double s0[3], double s1[3], int *src0, int *src1) {
    const double *const A[3] = {a0, a1, a2}, *const B[3] = {b0, b1, b2};
    double na[3], nb[3], la2, lb2, lna, lnb, s, eps, da[3], db[3], D[3], lD;
    double PA[2][3], PB[2][3], ta[2], tb[2], lo, hi;
    int sa[2], sb[2], k, pos_a = 0, neg_a = 0, pos_b = 0, neg_b = 0, nA, nB;
    const double *plo, *phi;
    int slo, shi;
    for (k = 0; k < 3; ++k)
        if (!aabb_finite3(A[k]) || !aabb_finite3(B[k])) return 0;
    la2 = tt_setup(A, na);
    lb2 = tt_setup(B, nb);
    lna = sqrt(aabb_dot3(na, na));
    lnb = sqrt(aabb_dot3(nb, nb));
    if (!(lna > SFB__TT_AREA * la2) || !(lnb > SFB__TT_AREA * lb2)) return 0; /* zero area */
    s = sqrt(la2 > lb2 ? la2 : lb2);
    eps = SFB__TT_DIST * s;
    for (k = 0; k < 3; ++k) {
        na[k] /= lna;
        nb[k] /= lnb;
    }
    /* signed distances of each triangle's vertices to the other's plane, near zeros made zero */
    for (k = 0; k < 3; ++k) {
        double w[3];
        aabb_sub3(A[k], b0, w);
        da[k] = aabb_dot3(nb, w);
        if (fabs(da[k]) <= eps) da[k] = 0.0;
        pos_a += da[k] > 0.0;
        neg_a += da[k] < 0.0;
        aabb_sub3(B[k], a0, w);
        db[k] = aabb_dot3(na, w);
        if (fabs(db[k]) <= eps) db[k] = 0.0;
        pos_b += db[k] > 0.0;
        neg_b += db[k] < 0.0;
    }
    if (pos_a == 3 || neg_a == 3 || pos_b == 3 || neg_b == 3) return 0;
    aabb_cross3(na, nb, D);
    lD = sqrt(aabb_dot3(D, D));
    if (pos_a + neg_a == 0 || pos_b + neg_b == 0 || !(lD > 1e-15))
        return tt_coplanar_meet(A, B, pos_a + neg_a == 0 ? nb : na, eps) ? 2 : 0;
    for (k = 0; k < 3; ++k) D[k] /= lD;
    /* each triangle's piece of the line where the planes meet, as an interval along D */
    nA = tt_plane_points(A, da, 0, PA, sa);
    nB = tt_plane_points(B, db, 3, PB, sb);
    if (nA < 1 || nB < 1) return 0; /* cannot happen with the signs above */
    if (nA == 1) { memcpy(PA[1], PA[0], sizeof PA[0]); sa[1] = sa[0]; }
    if (nB == 1) { memcpy(PB[1], PB[0], sizeof PB[0]); sb[1] = sb[0]; }
    for (k = 0; k < 2; ++k) {
        ta[k] = aabb_dot3(D, PA[k]);
        tb[k] = aabb_dot3(D, PB[k]);
    }
    if (ta[1] < ta[0]) {
        double x = ta[0], tmp[3];
        int si = sa[0];
        ta[0] = ta[1]; ta[1] = x;
        sa[0] = sa[1]; sa[1] = si;
        memcpy(tmp, PA[0], sizeof tmp); memcpy(PA[0], PA[1], sizeof tmp); memcpy(PA[1], tmp, sizeof tmp);
    }
    if (tb[1] < tb[0]) {
        double x = tb[0], tmp[3];
        int si = sb[0];
        tb[0] = tb[1]; tb[1] = x;
        sb[0] = sb[1]; sb[1] = si;
        memcpy(tmp, PB[0], sizeof tmp); memcpy(PB[0], PB[1], sizeof tmp); memcpy(PB[1], tmp, sizeof tmp);
    }
    /* the overlap: each end is the inner of the two, a's on a tie */
    if (ta[0] >= tb[0]) { lo = ta[0]; plo = PA[0]; slo = sa[0]; }
    else { lo = tb[0]; plo = PB[0]; slo = sb[0]; }
    if (ta[1] <= tb[1]) { hi = ta[1]; phi = PA[1]; shi = sa[1]; }
    else { hi = tb[1]; phi = PB[1]; shi = sb[1]; }
    if (lo > hi + eps) return 0;
    if (lo > hi) { phi = plo; shi = slo; } /* touching within the tolerance: one point */
    if (s0) memcpy(s0, plo, 3 * sizeof(double));
    if (s1) memcpy(s1, phi, 3 * sizeof(double));
    if (src0) *src0 = slo;
    if (src1) *src1 = shi;
    return 1;
}

/* ---- a mesh's self-intersections ---- */

typedef struct sfb__aabb_self {
    const double *pos;
    const int *tri;
    long pairs;
    int first[2];
} sfb__aabb_self;

/* In the plane of unit normal n: does the corner of triangle (v, p0, p1) at v overlap that of
 * (v, q0, q1) in more than v (a ray of one inside the other's closed wedge, touching included)? */
static int self_wedges_meet(const double *n, const double *v, const double *p0, const double *p1, const double *q0,
                            const double *q1) {
    double r[4][3], c[3];
    int w, k;
    aabb_sub3(p0, v, r[0]);
    aabb_sub3(p1, v, r[1]);
    aabb_sub3(q0, v, r[2]);
    aabb_sub3(q1, v, r[3]);
    for (k = 0; k < 4; ++k) {
        const double l = sqrt(aabb_dot3(r[k], r[k]));
        if (!(l > 0.0)) return 1;
        r[k][0] /= l; r[k][1] /= l; r[k][2] /= l;
    }
    /* orient both wedges counter-clockwise about n */
    for (w = 0; w < 4; w += 2) {
        aabb_cross3(r[w], r[w + 1], c);
        if (aabb_dot3(c, n) < 0.0)
            for (k = 0; k < 3; ++k) {
                const double x = r[w][k];
                r[w][k] = r[w + 1][k];
                r[w + 1][k] = x;
            }
    }
    for (w = 0; w < 4; ++w) {
        const double *e0 = r[w < 2 ? 2 : 0], *e1 = r[w < 2 ? 3 : 1];
        double c0[3], c1[3];
        aabb_cross3(e0, r[w], c0);
        aabb_cross3(r[w], e1, c1);
        if (aabb_dot3(c0, n) >= -SFB__SELF_LEN && aabb_dot3(c1, n) >= -SFB__SELF_LEN) return 1;
    }
    return 0;
}

static int self_pair_cb(int i, int j, void *user) {
    sfb__aabb_self *S = (sfb__aabb_self *)user;
    const int *a = S->tri + 3 * (size_t)i, *b = S->tri + 3 * (size_t)j;
    const double *A[3], *B[3];
    double s0[3], s1[3];
    int shared = 0, ia = -1, ib = -1, ja = -1, jb = -1, k, l, r, hit = 0;
    for (k = 0; k < 3; ++k) {
        A[k] = S->pos + 3 * (size_t)a[k];
        B[k] = S->pos + 3 * (size_t)b[k];
    }
    r = sfb__tri_tri_segment(A[0], A[1], A[2], B[0], B[1], B[2], s0, s1, NULL, NULL);
    if (r == 0) return 0;
    /* both have an area, so each one's three indices differ */
    for (k = 0; k < 3; ++k)
        for (l = 0; l < 3; ++l)
            if (a[k] == b[l]) {
                if (shared == 0) { ia = k; ib = l; } else { ja = k; jb = l; }
                shared++;
            }
    if (shared == 0 || shared >= 3) hit = 1;
    else if (shared == 1) {
        if (r == 1) {
            /* they meet in a segment through the shared vertex: more than it when it has a length */
            double d[3], e[3], sc = 0.0;
            for (k = 0; k < 3; ++k) {
                aabb_sub3(A[(k + 1) % 3], A[k], e);
                if (aabb_dot3(e, e) > sc) sc = aabb_dot3(e, e);
                aabb_sub3(B[(k + 1) % 3], B[k], e);
                if (aabb_dot3(e, e) > sc) sc = aabb_dot3(e, e);
            }
            aabb_sub3(s1, s0, d);
            hit = sqrt(aabb_dot3(d, d)) > SFB__SELF_LEN * sqrt(sc);
        } else {
            double n[3], e0[3], e1[3];
            aabb_sub3(A[1], A[0], e0);
            aabb_sub3(A[2], A[0], e1);
            aabb_cross3(e0, e1, n);
            hit = self_wedges_meet(n, A[ia], A[(ia + 1) % 3], A[(ia + 2) % 3], B[(ib + 1) % 3], B[(ib + 2) % 3]);
        }
    } else {
        /* an edge in common: coplanar with the third vertices on the same side of it */
        if (r == 2) {
            const int pa = 3 - ia - ja, pb = 3 - ib - jb;
            double e[3], u[3], w[3], cu[3], cw[3];
            aabb_sub3(A[ja], A[ia], e);
            aabb_sub3(A[pa], A[ia], u);
            aabb_sub3(B[pb], A[ia], w);
            aabb_cross3(e, u, cu);
            aabb_cross3(e, w, cw);
            hit = aabb_dot3(cu, cw) > 0.0;
        }
    }
    if (hit) {
        if (S->pairs == 0) {
            S->first[0] = i < j ? i : j;
            S->first[1] = i < j ? j : i;
        }
        S->pairs++;
    }
    return 0;
}

sfb_result sfb__trimesh_self_intersections(sfb_context *ctx, const double *pos, const int *tri, int count, long *pairs,
                                           int first[2]) {
    sfb__aabb t;
    sfb__aabb_self S;
    sfb_result r;
    double diag = 0.0;
    int k;
    if (first) first[0] = first[1] = -1;
    if (pairs) *pairs = 0;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!pairs || count < 0 || (count > 0 && (!pos || !tri)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb__trimesh_self_intersections: bad arguments");
    r = sfb__aabb_build(ctx, pos, tri, NULL, count, &t);
    if (r != SFB_SUCCESS) return r;
    S.pos = pos;
    S.tri = tri;
    S.pairs = 0;
    S.first[0] = S.first[1] = -1;
    if (t.node_count > 0) {
        for (k = 0; k < 3; ++k) diag += (t.nodes[0].hi[k] - t.nodes[0].lo[k]) * (t.nodes[0].hi[k] - t.nodes[0].lo[k]);
        sfb__aabb_pairs(&t, &t, SFB__TT_DIST * sqrt(diag), self_pair_cb, &S);
    }
    sfb__aabb_free(ctx, &t);
    *pairs = S.pairs;
    if (first) {
        first[0] = S.first[0];
        first[1] = S.first[1];
    }
    return SFB_SUCCESS;
}
#line 1 "src/sparse.c"
/* Sparse symmetric systems: a square matrix in compressed rows (each row's columns ascending,
 * duplicates summed) assembled from (row, column, value) triplets by two stable counting sorts
 * (by column, then by row, so that duplicates meet in input order and the result does not depend
 * on anything but the input), the product with a vector, and a Jacobi-preconditioned conjugate
 * gradient solver for symmetric positive definite matrices (Hestenes-Stiefel with the diagonal as
 * preconditioner; when the recurrence says the tolerance is met the true residual b - A x is
 * recomputed, and the iteration restarts from it if the recurrence had drifted). Used by the
 * rolling-ball operator's conformal map (seed 002) and whatever else needs a Laplacian solve. All
 * in double; a built matrix is read-only and may be used by many threads at once. */

sfb_result sfb__sparse_from_triplets(sfb_context *ctx, int n, int count, const int *row, const int *col, const double *val,
                                     sfb__sparse *out) {
    int *cnt = NULL, *ord1 = NULL, *ord2 = NULL, k, i, nnz = 0;
    size_t bytes_i, bytes_d;
    sfb__sparse m;
    if (!out) return ctx ? sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb__sparse_from_triplets: NULL matrix") : SFB_INVALID_ARGS;
    memset(out, 0, sizeof *out);
    if (!ctx) return SFB_INVALID_ARGS;
    if (n < 0 || count < 0 || (count > 0 && (!row || !col || !val)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sparse matrix: %d rows and %d triplets without their arrays", n,
                          count);
    for (k = 0; k < count; ++k)
        if (row[k] < 0 || row[k] >= n || col[k] < 0 || col[k] >= n)
            return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sparse matrix: triplet %d (%d, %d) outside the %d x %d matrix", k,
                              row[k], col[k], n, n);
    memset(&m, 0, sizeof m);
    m.n = n;
    if (!sfb__mul_size((size_t)count, sizeof(int), &bytes_i) ||
        !(cnt = (int *)sfb__calloc(ctx, (size_t)n + 1, sizeof(int))) || !(ord1 = (int *)sfb__alloc(ctx, bytes_i)) ||
        !(ord2 = (int *)sfb__alloc(ctx, bytes_i)) || !(m.row_off = (int *)sfb__calloc(ctx, (size_t)n + 1, sizeof(int)))) {
        sfb__free(ctx, cnt);
        sfb__free(ctx, ord1);
        sfb__free(ctx, ord2);
        return sfb__oom(ctx, "a sparse matrix");
    }
    /* stable counting sort by column, then by row: rows in order, columns ascending in each,
     * equal (row, column) in input order */
    for (k = 0; k < count; ++k) cnt[col[k] + 1]++;
    for (i = 0; i < n; ++i) cnt[i + 1] += cnt[i];
    for (k = 0; k < count; ++k) ord1[cnt[col[k]]++] = k;
    memset(cnt, 0, ((size_t)n + 1) * sizeof(int));
    for (k = 0; k < count; ++k) cnt[row[k] + 1]++;
    for (i = 0; i < n; ++i) cnt[i + 1] += cnt[i];
    for (k = 0; k < count; ++k) {
        const int t = ord1[k];
        ord2[cnt[row[t]]++] = t;
    }
    /* distinct entries per row */
    for (k = 0; k < count; ++k) {
        const int t = ord2[k];
        if (k == 0 || row[t] != row[ord2[k - 1]] || col[t] != col[ord2[k - 1]]) {
            m.row_off[row[t] + 1]++;
            nnz++;
        }
    }
    for (i = 0; i < n; ++i) m.row_off[i + 1] += m.row_off[i];
    if (!sfb__mul_size((size_t)nnz, sizeof(double), &bytes_d) || !(m.col = (int *)sfb__alloc(ctx, (size_t)nnz * sizeof(int))) ||
        !(m.val = (double *)sfb__alloc(ctx, bytes_d))) {
        sfb__free(ctx, cnt);
        sfb__free(ctx, ord1);
        sfb__free(ctx, ord2);
        sfb__sparse_free(ctx, &m);
        return sfb__oom(ctx, "a sparse matrix");
    }
    nnz = 0;
    for (k = 0; k < count; ++k) {
        const int t = ord2[k];
        if (k == 0 || row[t] != row[ord2[k - 1]] || col[t] != col[ord2[k - 1]]) {
            m.col[nnz] = col[t];
            m.val[nnz] = val[t];
            nnz++;
        } else
            m.val[nnz - 1] += val[t];
    }
    sfb__free(ctx, cnt);
    sfb__free(ctx, ord1);
    sfb__free(ctx, ord2);
    *out = m;
    return SFB_SUCCESS;
}

void sfb__sparse_free(sfb_context *ctx, sfb__sparse *m) {
    if (!m) return;
    if (ctx) {
        sfb__free(ctx, m->row_off);
        sfb__free(ctx, m->col);
        sfb__free(ctx, m->val);
    }
    memset(m, 0, sizeof *m);
}

void sfb__sparse_mul(const sfb__sparse *A, const double *x, double *y) {
    int i, k;
    for (i = 0; i < A->n; ++i) {
        double s = 0.0;
        for (k = A->row_off[i]; k < A->row_off[i + 1]; ++k) s += A->val[k] * x[A->col[k]];
        y[i] = s;
    }
}

static double sparse_dot(int n, const double *a, const double *b) {
    double s = 0.0;
    int i;
    for (i = 0; i < n; ++i) s += a[i] * b[i];
    return s;
}

sfb_result sfb__sparse_cg(sfb_context *ctx, const sfb__sparse *A, const double *b, double *x, double tol, int max_iter, int *iters,
                          double *residual) {
    double *dinv = NULL, *r, *z, *p, *q, bnorm, rz, rnorm, rel = 0.0;
    int n, i, k, it = 0, fresh = 1;
    size_t bytes;
    sfb_result res = SFB_SUCCESS;
    if (iters) *iters = 0;
    if (residual) *residual = 0.0;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!A || !b || !x || A->n < 0 || (A->n > 0 && (!A->row_off || !A->col || !A->val)) || !(tol >= 0.0) || max_iter < 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "conjugate gradients: bad arguments");
    n = A->n;
    if (n == 0) return SFB_SUCCESS;
    for (i = 0; i < n; ++i)
        if (!(b[i] - b[i] == 0.0) || !(x[i] - x[i] == 0.0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "conjugate gradients: non-finite %s at row %d",
                              b[i] - b[i] == 0.0 ? "start value" : "right-hand side", i);
    if (!sfb__mul_size((size_t)n, 5 * sizeof(double), &bytes) || !(dinv = (double *)sfb__alloc(ctx, bytes)))
        return sfb__oom(ctx, "conjugate gradients");
    r = dinv + n;
    z = r + n;
    p = z + n;
    q = p + n;
    for (i = 0; i < n; ++i) {
        double d = 0.0;
        for (k = A->row_off[i]; k < A->row_off[i + 1]; ++k)
            if (A->col[k] == i) d = A->val[k];
        if (!(d > 0.0) || !(d - d == 0.0)) {
            res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                             "conjugate gradients: diagonal entry %d is %g, not positive (the matrix is not positive definite)", i, d);
            goto done;
        }
        dinv[i] = 1.0 / d;
    }
    bnorm = sqrt(sparse_dot(n, b, b));
    if (bnorm == 0.0) {
        /* b = 0: x = 0 exactly */
        memset(x, 0, (size_t)n * sizeof(double));
        goto done;
    }
    rz = 0.0;
    for (;;) {
        if (fresh) {
            /* r = b - A x, from x itself (the start, or a restart after the recurrence drifted) */
            sfb__sparse_mul(A, x, r);
            for (i = 0; i < n; ++i) {
                r[i] = b[i] - r[i];
                z[i] = dinv[i] * r[i];
                p[i] = z[i];
            }
            rz = sparse_dot(n, r, z);
        }
        rnorm = sqrt(sparse_dot(n, r, r));
        rel = rnorm / bnorm;
        if (!(rel - rel == 0.0)) {
            res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "conjugate gradients: a non-finite value after %d iterations", it);
            goto done;
        }
        if (rel <= tol) {
            if (fresh) break;
            fresh = 1; /* confirm with the true residual */
            continue;
        }
        if (it >= max_iter) {
            res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                             "conjugate gradients did not converge in %d iterations (residual %g of |b|, tolerance %g)", it, rel, tol);
            goto done;
        }
        fresh = 0;
        {
            double pq, alpha, beta, rz_new;
            sfb__sparse_mul(A, p, q);
            pq = sparse_dot(n, p, q);
            if (!(pq > 0.0)) {
                res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                                 "conjugate gradients: p.Ap = %g after %d iterations (the matrix is not positive definite)", pq, it);
                goto done;
            }
            alpha = rz / pq;
            for (i = 0; i < n; ++i) {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
                z[i] = dinv[i] * r[i];
            }
            rz_new = sparse_dot(n, r, z);
            beta = rz_new / rz;
            for (i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
            rz = rz_new;
            it++;
        }
    }
done:
    if (iters) *iters = it;
    if (residual) *residual = rel;
    sfb__free(ctx, dinv);
    return res;
}
#line 1 "src/trimesh.c"
/* Measures of a triangle mesh: angle-weighted vertex normals (each face's unit normal weighted by
 * its angle at the vertex, Thurmer and Wuthrich 1998) and the mean curvature per vertex from the
 * cotangent Laplacian with the mixed Voronoi areas of Meyer, Desbrun, Schroder and Barr 2002
 * (K(x_i) = 1/(2 A_i) sum_j (cot alpha_ij + cot beta_ij) (x_i - x_j) = 2 H n: |K|/2, signed by
 * K's side of the vertex normal, so positive where the surface bends away from the normal),
 * zero at vertices on an edge that does not have exactly two faces (the boundary, non-manifold
 * edges) and at vertices no face uses; plus the public sfb_mesh_vertex_normals and
 * sfb_mesh_mean_curvature on an sfb_mesh of triangles. Faces with an index out of range or
 * repeated, or with no area, contribute nothing. All in double; the functions write only their
 * outputs, so any number of threads may run them on one mesh at once. */

/* Corner data of face (i, j, k): the edges from corner c to the next two, their cross product. */
static int trimesh_face(const double *pos, const int *t, double e[3][3], double *twice_area) {
    const double *p0 = pos + 3 * (size_t)t[0], *p1 = pos + 3 * (size_t)t[1], *p2 = pos + 3 * (size_t)t[2];
    double n[3];
    int k;
    for (k = 0; k < 3; ++k) {
        e[0][k] = p1[k] - p0[k]; /* edge 0: 0 -> 1 */
        e[1][k] = p2[k] - p1[k]; /* edge 1: 1 -> 2 */
        e[2][k] = p0[k] - p2[k]; /* edge 2: 2 -> 0 */
    }
    sfb__cross3(e[0], e[1], n);
    *twice_area = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return *twice_area > 0.0 && *twice_area - *twice_area == 0.0;
}

static int trimesh_valid(int nv, const int *t) {
    return t[0] >= 0 && t[0] < nv && t[1] >= 0 && t[1] < nv && t[2] >= 0 && t[2] < nv && t[0] != t[1] && t[1] != t[2] &&
           t[0] != t[2];
}

static double trimesh_dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

void sfb__trimesh_vertex_normals(int nv, const double *pos, int nf, const int *tri, double *normals) {
    int f, v, c, k;
    if (nv <= 0 || !normals) return;
    memset(normals, 0, (size_t)nv * 3 * sizeof(double));
    if (!pos || !tri) return;
    for (f = 0; f < nf; ++f) {
        const int *t = tri + 3 * (size_t)f;
        double e[3][3], n[3], ta;
        if (!trimesh_valid(nv, t) || !trimesh_face(pos, t, e, &ta)) continue;
        sfb__cross3(e[0], e[1], n);
        for (k = 0; k < 3; ++k) n[k] /= ta;
        for (c = 0; c < 3; ++c) {
            /* the angle at corner c, between the edge out of it and the reversed edge into it */
            const double *out = e[c], *in = e[(c + 2) % 3];
            double cr[3], ang;
            sfb__cross3(out, in, cr);
            ang = atan2(sqrt(trimesh_dot(cr, cr)), -trimesh_dot(out, in));
            for (k = 0; k < 3; ++k) normals[3 * (size_t)t[c] + k] += ang * n[k];
        }
    }
    for (v = 0; v < nv; ++v) {
        double *n = normals + 3 * (size_t)v;
        const double l = sqrt(trimesh_dot(n, n));
        if (l > 0.0 && l - l == 0.0)
            for (k = 0; k < 3; ++k) n[k] /= l;
        else
            n[0] = n[1] = n[2] = 0.0;
    }
}

sfb_result sfb__trimesh_mean_curvature(sfb_context *ctx, int nv, const double *pos, int nf, const int *tri, double *H) {
    double *S = NULL, *A, *N;
    int *off = NULL, *other, *cnt;
    unsigned char *bad;
    size_t bytes;
    int f, v, c, k;
    if (!ctx) return SFB_INVALID_ARGS;
    if (nv < 0 || nf < 0 || (nv > 0 && (!pos || !H)) || (nf > 0 && !tri))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mean curvature: bad arguments");
    if (nv == 0) return SFB_SUCCESS;
    /* per vertex: S (3), A (1), N (3) doubles; off (nv + 1), cnt (nv) ints, bad bytes; other: 3 nf ints */
    if (!sfb__mul_size((size_t)nv, 7 * sizeof(double), &bytes) || !(S = (double *)sfb__calloc(ctx, 1, bytes)) ||
        !sfb__mul_size((size_t)nv + 1 + (size_t)nv + 3 * (size_t)nf, sizeof(int), &bytes) || bytes > ((size_t)-1) - (size_t)nv ||
        !(off = (int *)sfb__calloc(ctx, 1, bytes + (size_t)nv))) {
        sfb__free(ctx, S);
        return sfb__oom(ctx, "the mean curvature");
    }
    A = S + 3 * (size_t)nv;
    N = A + nv;
    cnt = off + nv + 1;
    other = cnt + nv;
    bad = (unsigned char *)(other + 3 * (size_t)nf);
    /* edges with other than two faces: each edge (lo, hi) listed at lo, counted through cnt */
    for (f = 0; f < nf; ++f) {
        const int *t = tri + 3 * (size_t)f;
        if (!trimesh_valid(nv, t)) continue;
        for (c = 0; c < 3; ++c) {
            const int a = t[c], b = t[(c + 1) % 3];
            off[(a < b ? a : b) + 1]++;
        }
    }
    for (v = 0; v < nv; ++v) off[v + 1] += off[v];
    for (f = 0; f < nf; ++f) {
        const int *t = tri + 3 * (size_t)f;
        if (!trimesh_valid(nv, t)) continue;
        for (c = 0; c < 3; ++c) {
            const int a = t[c], b = t[(c + 1) % 3];
            other[off[a < b ? a : b]++] = a < b ? b : a;
        }
    }
    for (v = nv; v > 0; --v) off[v] = off[v - 1];
    off[0] = 0;
    for (v = 0; v < nv; ++v) {
        int i;
        for (i = off[v]; i < off[v + 1]; ++i) cnt[other[i]]++;
        for (i = off[v]; i < off[v + 1]; ++i)
            if (cnt[other[i]] != 2) bad[v] = bad[other[i]] = 1;
        for (i = off[v]; i < off[v + 1]; ++i) cnt[other[i]] = 0;
    }
    /* the cotangent sums and the mixed areas */
    for (f = 0; f < nf; ++f) {
        const int *t = tri + 3 * (size_t)f;
        double e[3][3], ta, cot[3], dots[3];
        if (!trimesh_valid(nv, t) || !trimesh_face(pos, t, e, &ta)) continue;
        for (c = 0; c < 3; ++c) {
            /* at corner c: edges out of it (e[c]) and into it reversed (-e[c+2]) */
            dots[c] = -trimesh_dot(e[c], e[(c + 2) % 3]);
            cot[c] = dots[c] / ta;
        }
        for (c = 0; c < 3; ++c) {
            const int i = t[c], j = t[(c + 1) % 3], l = t[(c + 2) % 3];
            const double *xi = pos + 3 * (size_t)i, *xj = pos + 3 * (size_t)j, *xl = pos + 3 * (size_t)l;
            /* edge i-j faces corner c+2, edge i-l faces corner c+1 */
            const double cij = cot[(c + 2) % 3], cil = cot[(c + 1) % 3];
            for (k = 0; k < 3; ++k) S[3 * (size_t)i + k] += cij * (xi[k] - xj[k]) + cil * (xi[k] - xl[k]);
            if (dots[0] >= 0.0 && dots[1] >= 0.0 && dots[2] >= 0.0)
                A[i] += (cij * trimesh_dot(e[c], e[c]) + cil * trimesh_dot(e[(c + 2) % 3], e[(c + 2) % 3])) / 8.0;
            else if (dots[c] < 0.0)
                A[i] += ta / 4.0; /* obtuse at i: half the area */
            else
                A[i] += ta / 8.0; /* obtuse elsewhere: a quarter */
        }
    }
    sfb__trimesh_vertex_normals(nv, pos, nf, tri, N);
    for (v = 0; v < nv; ++v) {
        double K[3], h;
        if (bad[v] || !(A[v] > 0.0)) { H[v] = 0.0; continue; }
        for (k = 0; k < 3; ++k) K[k] = S[3 * (size_t)v + k] / (2.0 * A[v]);
        h = 0.5 * sqrt(trimesh_dot(K, K));
        H[v] = trimesh_dot(K, N + 3 * (size_t)v) < 0.0 ? -h : h;
        if (!(H[v] - H[v] == 0.0)) H[v] = 0.0;
    }
    sfb__free(ctx, S);
    sfb__free(ctx, off);
    return SFB_SUCCESS;
}

/* ---- on an sfb_mesh ---- */

/* The mesh's positions in double, after checking that every face is a triangle. */
static sfb_result trimesh_of_mesh(sfb_context *ctx, const sfb_mesh *mesh, const void *outp, const char *who, double **pos) {
    const sfb__level *l;
    size_t bytes;
    int f, i;
    *pos = NULL;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!mesh || !outp) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "%s: NULL argument", who);
    l = &mesh->base;
    for (f = 0; f < l->nf; ++f)
        if (l->fv_off[f + 1] - l->fv_off[f] != 3 || l->fv_off[f] != 3 * f)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "%s needs triangles; this face has %d vertices", who,
                              l->fv_off[f + 1] - l->fv_off[f]);
    if (!sfb__mul_size((size_t)l->nv + 1, 3 * sizeof(double), &bytes) || !(*pos = (double *)sfb__alloc(ctx, bytes)))
        return sfb__oom(ctx, who);
    for (i = 0; i < 3 * l->nv; ++i) (*pos)[i] = (double)mesh->positions[i];
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_mesh_vertex_normals(sfb_context *ctx, const sfb_mesh *mesh, float *normals) {
    double *pos, *n;
    const sfb__level *l;
    size_t bytes;
    int i;
    sfb_result r = trimesh_of_mesh(ctx, mesh, normals, "sfb_mesh_vertex_normals", &pos);
    if (r != SFB_SUCCESS) return r;
    l = &mesh->base;
    if (!sfb__mul_size((size_t)l->nv + 1, 3 * sizeof(double), &bytes) || !(n = (double *)sfb__alloc(ctx, bytes))) {
        sfb__free(ctx, pos);
        return sfb__oom(ctx, "sfb_mesh_vertex_normals");
    }
    sfb__trimesh_vertex_normals(l->nv, pos, l->nf, l->fv, n);
    for (i = 0; i < 3 * l->nv; ++i) normals[i] = (float)n[i];
    sfb__free(ctx, n);
    sfb__free(ctx, pos);
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_mesh_mean_curvature(sfb_context *ctx, const sfb_mesh *mesh, float *curvature) {
    double *pos, *h;
    const sfb__level *l;
    int i;
    sfb_result r = trimesh_of_mesh(ctx, mesh, curvature, "sfb_mesh_mean_curvature", &pos);
    if (r != SFB_SUCCESS) return r;
    l = &mesh->base;
    if (!(h = (double *)sfb__calloc(ctx, (size_t)l->nv + 1, sizeof(double)))) {
        sfb__free(ctx, pos);
        return sfb__oom(ctx, "sfb_mesh_mean_curvature");
    }
    r = sfb__trimesh_mean_curvature(ctx, l->nv, pos, l->nf, l->fv, h);
    if (r == SFB_SUCCESS)
        for (i = 0; i < l->nv; ++i) curvature[i] = (float)h[i];
    sfb__free(ctx, h);
    sfb__free(ctx, pos);
    return r;
}
#line 1 "src/fillet/fillet.c"
/* Seed 002: rolling-ball blending (fillets) of sharp features on triangle meshes, connectivity
 * unchanged. sfb_mesh_fillet runs, per blending curve:
 *   curves   feature edges over a dihedral angle chained into closed loops and open chains, or
 *            the caller's vertex chains (fillet_curves_*);
 *   spine    base patches within d of the curve, one per side; per-side vertex normals; offset
 *            patches; their intersection through two AABB trees (aabb.c) chained, the longest
 *            loop (closed curves) or chain (open ones) kept; spine loops cut out (seed 4.3);
 *   surface  spine samples by arc length, refined by chord height / chord length (seed 4.1); per
 *            sample the linkage points (the spine point's nearest point on each offset patch,
 *            carried back to the base face by its barycentric coordinates: seed 3 step 4) and a
 *            profile (arc, conic, sharpening polyline, Hermite; seed 4.2); ruled surfaces between
 *            consecutive profiles (seed eq. 1);
 *   map      each vertex of the blend region gets (t, a): first directly (t from its nearest point
 *            on its side's linkage polyline, a from how far it lies past its side's linkage point
 *            toward the curve), then, inside the region, the cotangent (conformal) map with those
 *            boundary values solved by conjugate gradients (sparse.c); mean-value weights where the
 *            cotangent map folds, the direct values where both fold;
 *   project  the vertex moves to the ruled surface at (t, a).
 * Choices where the seed is silent, and why:
 *  - No splitting path: a closed spine's t is periodic and each edge of the map carries its jump
 *    (the smaller difference), so the region needs no disc topology; blend regions with holes or
 *    several boundary loops (seed 7's failure) map like any other, and open chains need no
 *    splitting either. SFB_FILLET_MAP_DIRECT keeps the direct values throughout. Across the
 *    region, a is arc-length-like: the blending curve goes to the profile's middle by arc length
 *    when both linkage distances are equal.
 *  - Region membership is a half-space test at the vertex's own linkage point (past it toward the
 *    curve), not a distance to the curve: at a reflex corner of the seam the ball sits in the
 *    corner and the vertices behind it have no profile plane of their own; the distance test left
 *    single vertices there out and stretched triangles across the corner (8014 intersecting pairs
 *    on the L prism of tests/fillet.c before, 0 after).
 *  - Consecutive profiles are joined at equal arc-length fractions (a ruled surface whose rulings
 *    join points at the same fraction a), not at equal rational parameter u: profiles of
 *    different opening angles then still pair corresponding points.
 *  - d grows with the curve's sharpest dihedral angle: the linkage points lie r tan(delta/2) from
 *    the curve (delta the dihedral angle between the face normals), beyond alpha r when delta >
 *    120 degrees; d = alpha r max(1, tan(delta/2)).
 *  - Sides: the face holding the curve's edge in the curve's direction is side 0. The two base
 *    patches grow breadth first at the same time, so around the ends of an open chain they meet
 *    halfway instead of one swallowing the other.
 *  - Convex or concave per curve: side 1's faces lie below side 0's tangent plane (summed over the
 *    curve's edges) for a convex edge. Convex: offsets against the normals; concave: along them.
 *  - Every curve is filleted on the input's positions (each writes its own region), and base
 *    patches stop at the edges of the call's other curves: where curves meet at a corner their
 *    regions then end at the corner's planes instead of wrapping round onto the third face. (One
 *    after the other, each on the positions the earlier ones left, the box's edges crumpled at
 *    the corners and the crumples fed the next curves' offsets: spines ran away to 44x their
 *    length.)
 *  - Corners (sfb__fil_corner): three arc curves of one convexity and radius ending at a vertex
 *    on three planes get the ball's sphere (exact: the rolling ball touching all three faces). Other
 *    junctions (mixed convexity, other profiles, curved faces, more than three curves) keep each
 *    curve's sweep ending at the plane through the vertex. */


#define SFB__FIL_TAB 48 /* profile arc-length table intervals */

typedef struct sfb__fil_curve {
    int *v;           /* vertices, closed: v[n-1] == v[0] */
    int n, closed;
    double radius;
    int profile;
    double conic_w;
    int corner[2];    /* per end (v[0], v[n-1]): the corner (sfb__fil_corner) it ends at, or -1 */
    double setback[2];/* per end at another junction (sfb__fil_junction): how far before it the sweep stops; 0: none */
} sfb__fil_curve;

/* A junction: any other vertex where two or more open curves end (curves of both convexities,
 * other profiles or radii, faces not on three planes, more than three curves: a prism's sharp
 * vertical edge standing on a filleted floor seam). There is no exact rolling-ball answer the
 * seed gives; each curve's sweep stops `s` before it (the largest reach of the curves there, r
 * max(1, tan(delta / 2))), so that their regions do not overlap, and the vertices around it that
 * no sweep moved take the harmonic interpolation of the moves around them (a membrane patch:
 * continuous, no exact geometry). Before, every sweep ran to the vertex and the regions overlapped:
 * the L prism with sharp vertical corners, filleted by angle, had 767 intersecting triangle pairs. */
typedef struct sfb__fil_junction {
    int v;
    double s;
} sfb__fil_junction;

/* A corner: a vertex where exactly three open curves end, all convex or all concave, all with the
 * arc profile and one radius, around
 * which the faces lie on three planes (within 2 % of r). The ball touches all three there: its
 * centre C is r from each plane (inside the solid for convex curves, outside for concave ones),
 * each curve's sweep ends in the plane through C across its end, and the vertices beyond all
 * three end planes move onto the ball's sphere. (The seed fillets closed curves only; this is the
 * rolling ball's own answer at a corner: the three cylinders meet the sphere along their end
 * circles, tangent-continuous.) */
typedef struct sfb__fil_corner {
    int v;            /* the corner vertex */
    double C[3], r;   /* the ball's centre and radius */
    double u[3][3];   /* per curve end: unit direction out of the curve into the corner */
    int curve[3];     /* the three curves */
    int moved;
} sfb__fil_corner;

typedef struct sfb__fil_prof {
    double P1[3], P0[3], P2[3], C[3], E[3];
    double w, r, L1, L2;   /* middle weight; radius; linkage distances from the curve, sides 0 and 1 */
    double T[SFB__FIL_TAB + 1][3];
    double acc[SFB__FIL_TAB + 1]; /* arc length fractions of T */
} sfb__fil_prof;

typedef struct sfb__fil {
    sfb_context *ctx;
    const sfb_fillet_config *cfg;
    const sfb__level *l;
    int nv, nf;
    const int *tri;
    double *pos, *fn;      /* the input's positions; unit face normals */
    double *npos;          /* positions after the current curve */
    double *opos;          /* the output's positions: every curve and corner writes its moved vertices */
    unsigned char *fmark;  /* per edge: on any blending curve of this call (base patches stop there) */
    sfb__fil_corner *corners;
    int ncorners;
    sfb__fil_junction *junctions;
    int njunctions;
    double scale;          /* bounding-box diagonal */
    sfb__fil_curve *curves;
    int ncurves, curves_cap;
    unsigned char *emark;  /* per edge: on the current curve */
} sfb__fil;

/* ---- small vector helpers ---- */
static double fil_dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void fil_sub(const double *a, const double *b, double *o) { o[0] = a[0] - b[0]; o[1] = a[1] - b[1]; o[2] = a[2] - b[2]; }
static double fil_len(const double *a) { return sqrt(fil_dot(a, a)); }
static double fil_dist(const double *a, const double *b) {
    double d[3];
    fil_sub(a, b, d);
    return fil_len(d);
}
static void fil_lerp(const double *a, const double *b, double t, double *o) {
    o[0] = a[0] + t * (b[0] - a[0]); o[1] = a[1] + t * (b[1] - a[1]); o[2] = a[2] + t * (b[2] - a[2]);
}
static void fil_cross(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1]; o[1] = a[2] * b[0] - a[0] * b[2]; o[2] = a[0] * b[1] - a[1] * b[0];
}
/* Nearest point of segment a-b to p: its parameter in [0,1]. */
static double fil_seg_param(const double *p, const double *a, const double *b) {
    double ab[3], ap[3], l2, t;
    fil_sub(b, a, ab); fil_sub(p, a, ap);
    l2 = fil_dot(ab, ab);
    if (!(l2 > 0.0)) return 0.0;
    t = fil_dot(ap, ab) / l2;
    return t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
}

static int fil_edge_of(const sfb__level *l, int a, int b) {
    int k;
    for (k = l->ve_off[a]; k < l->ve_off[a + 1]; ++k) {
        const int e = l->ve[k];
        if (sfb__other_end(l, e, a) == b) return e;
    }
    return -1;
}

static void fil_face_normals(sfb__fil *F) {
    int f;
    for (f = 0; f < F->nf; ++f) {
        const double *a = F->pos + 3 * (size_t)F->tri[3 * f], *b = F->pos + 3 * (size_t)F->tri[3 * f + 1],
                     *c = F->pos + 3 * (size_t)F->tri[3 * f + 2];
        double u[3], v[3], n[3], ln;
        fil_sub(b, a, u); fil_sub(c, a, v); fil_cross(u, v, n);
        ln = fil_len(n);
        if (ln > 0.0) { n[0] /= ln; n[1] /= ln; n[2] /= ln; } else n[0] = n[1] = n[2] = 0.0;
        memcpy(F->fn + 3 * (size_t)f, n, sizeof n);
    }
}

/* Angle between the normals of edge e's two faces (radians); -1 for an edge without two faces. */
static double fil_dihedral(const sfb__fil *F, int e) {
    const sfb__level *l = F->l;
    double c;
    if (l->ef_off[e + 1] - l->ef_off[e] != 2) return -1.0;
    c = fil_dot(F->fn + 3 * (size_t)l->ef[l->ef_off[e]], F->fn + 3 * (size_t)l->ef[l->ef_off[e] + 1]);
    c = c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c;
    return acos(c);
}

/* ---- curves ---- */
static sfb_result fil_add_curve(sfb__fil *F, const int *v, int n, int closed, double radius, int profile, double w) {
    sfb__fil_curve *c;
    if (F->ncurves == F->curves_cap) {
        const int cap = F->curves_cap ? 2 * F->curves_cap : 8;
        sfb__fil_curve *nc = (sfb__fil_curve *)sfb__realloc(F->ctx, F->curves, (size_t)cap * sizeof *nc);
        if (!nc) return sfb__oom(F->ctx, "the blending curves");
        F->curves = nc;
        F->curves_cap = cap;
    }
    c = &F->curves[F->ncurves];
    c->v = (int *)sfb__alloc(F->ctx, (size_t)n * sizeof(int));
    if (!c->v) return sfb__oom(F->ctx, "a blending curve");
    memcpy(c->v, v, (size_t)n * sizeof(int));
    c->n = n;
    c->closed = closed;
    c->corner[0] = c->corner[1] = -1;
    c->setback[0] = c->setback[1] = 0.0;
    c->radius = radius;
    c->profile = profile;
    c->conic_w = w;
    F->ncurves++;
    return SFB_SUCCESS;
}

/* How far from a curve the ball of radius r touches the faces: r tan(delta / 2) for the sharpest
 * dihedral angle delta (capped at 170 degrees), at least r. The base patches reach alpha times it;
 * a junction's setback is the largest of its curves'. */
static double fil_reach(double r, double delta) {
    const double t = tan(0.5 * (delta < 170.0 * SFB__PI / 180.0 ? delta : 170.0 * SFB__PI / 180.0));
    return r * (t > 1.0 ? t : 1.0);
}

/* Edge e (a-b, two faces): negative when convex -- each face's third vertex lies below the other
 * face's plane -- positive when concave; summed over a curve's edges it decides the curve. */
static double fil_edge_conv(const sfb__fil *F, int e, int a, int b) {
    const sfb__level *l = F->l;
    const int f0 = l->ef[l->ef_off[e]], f1 = l->ef[l->ef_off[e] + 1];
    double conv = 0.0;
    int j;
    for (j = 0; j < 3; ++j) {
        const int o1 = F->tri[3 * f1 + j], o0 = F->tri[3 * f0 + j];
        double dv[3];
        if (o1 != a && o1 != b) { fil_sub(F->pos + 3 * (size_t)o1, F->pos + 3 * (size_t)a, dv); conv += fil_dot(dv, F->fn + 3 * (size_t)f0); }
        if (o0 != a && o0 != b) { fil_sub(F->pos + 3 * (size_t)o0, F->pos + 3 * (size_t)a, dv); conv += fil_dot(dv, F->fn + 3 * (size_t)f1); }
    }
    return conv;
}

/* Feature edges (dihedral angle over the threshold, two faces) chained: chains start at vertices
 * with other than two feature edges, or with one convex and one concave (a curve has one
 * convexity: its offsets go one way); what is left are closed loops. */
static sfb_result fil_curves_from_angle(sfb__fil *F) {
    const sfb__level *l = F->l;
    const double limit = (F->cfg->angle > 0.0f ? F->cfg->angle : 30.0f) * SFB__PI / 180.0;
    unsigned char *feat = (unsigned char *)sfb__calloc(F->ctx, (size_t)l->ne + 1, 1);
    int *deg = (int *)sfb__calloc(F->ctx, (size_t)l->nv + 1, sizeof(int));
    int *chain = (int *)sfb__alloc(F->ctx, ((size_t)l->ne + 2) * sizeof(int));
    signed char *vsign = (signed char *)sfb__calloc(F->ctx, (size_t)l->nv + 1, 1); /* 2: both convexities meet here */
    int e, v, pass, total = 0;
    sfb_result r = SFB_SUCCESS;
    if (!feat || !deg || !chain || !vsign) {
        r = sfb__oom(F->ctx, "the feature edges");
        goto done;
    }
    for (e = 0; e < l->ne; ++e)
        if (fil_dihedral(F, e) > limit) {
            const signed char sg = fil_edge_conv(F, e, l->ev[2 * e], l->ev[2 * e + 1]) < 0.0 ? -1 : 1;
            int k;
            feat[e] = 1;
            deg[l->ev[2 * e]]++;
            deg[l->ev[2 * e + 1]]++;
            for (k = 0; k < 2; ++k) {
                signed char *vs = &vsign[l->ev[2 * e + k]];
                *vs = *vs == 0 ? sg : *vs == sg ? *vs : 2;
            }
            total++;
        }
    if (!total) {
        r = sfb__error(F->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                       "no feature edge: no edge's dihedral angle exceeds %g degrees", limit * 180.0 / SFB__PI);
        goto done;
    }
    /* pass 0: chains from end vertices (degree != 2); pass 1: closed loops */
    for (pass = 0; pass < 2 && r == SFB_SUCCESS; ++pass)
        for (v = 0; v < l->nv && r == SFB_SUCCESS; ++v) {
            int k;
            if (pass == 0 && deg[v] == 2 && vsign[v] != 2) continue;
            for (k = l->ve_off[v]; k < l->ve_off[v + 1] && r == SFB_SUCCESS; ++k) {
                int cur = v, ce = l->ve[k], n = 0;
                if (!feat[ce]) continue;
                chain[n++] = v;
                while (ce >= 0) {
                    int nx = sfb__other_end(l, ce, cur), j;
                    feat[ce] = 0;
                    chain[n++] = nx;
                    cur = nx;
                    ce = -1;
                    if (nx == v || deg[nx] != 2 || vsign[nx] == 2) break;
                    for (j = l->ve_off[nx]; j < l->ve_off[nx + 1]; ++j)
                        if (feat[l->ve[j]]) { ce = l->ve[j]; break; }
                }
                r = fil_add_curve(F, chain, n, chain[n - 1] == chain[0], F->cfg->radius, F->cfg->profile, F->cfg->conic_weight);
            }
        }
done:
    sfb__free(F->ctx, feat);
    sfb__free(F->ctx, deg);
    sfb__free(F->ctx, chain);
    sfb__free(F->ctx, vsign);
    return r;
}

static sfb_result fil_curves_from_caller(sfb__fil *F) {
    const sfb_fillet_config *cfg = F->cfg;
    int c, i;
    for (c = 0; c < cfg->curve_count; ++c) {
        const sfb_fillet_curve *cc = &cfg->curves[c];
        sfb_result r;
        double radius = cc->radius != 0.0f ? cc->radius : cfg->radius;
        int profile = cc->profile ? cc->profile - 1 : cfg->profile;
        double w = cc->conic_weight != 0.0f ? cc->conic_weight : cfg->conic_weight;
        if (!cc->vertices || cc->count < 2)
            return sfb__error(F->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "blending curve %d: needs at least 2 vertices", c);
        if (!(radius > 0.0) || !isfinite(radius))
            return sfb__error(F->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "blending curve %d: radius %g is not a positive number", c, radius);
        if (profile < 0 || profile > SFB_FILLET_HERMITE)
            return sfb__error(F->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "blending curve %d: unknown profile %d", c, profile);
        if (!(w >= 0.0) || !isfinite(w))
            return sfb__error(F->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "blending curve %d: conic weight %g is not >= 0", c, w);
        for (i = 0; i < cc->count; ++i)
            if (cc->vertices[i] < 0 || cc->vertices[i] >= F->nv)
                return sfb__error(F->ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, cc->vertices[i],
                                  "blending curve %d: vertex %d is not a vertex of the mesh", c, cc->vertices[i]);
        for (i = 0; i + 1 < cc->count; ++i) {
            const int e = fil_edge_of(F->l, cc->vertices[i], cc->vertices[i + 1]);
            if (e < 0)
                return sfb__error(F->ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, cc->vertices[i + 1],
                                  "blending curve %d is not a chain of mesh edges: no edge from vertex %d to vertex %d", c,
                                  cc->vertices[i], cc->vertices[i + 1]);
            if (F->l->ef_off[e + 1] - F->l->ef_off[e] != 2)
                return sfb__error(F->ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, e,
                                  "blending curve %d: the edge from vertex %d to vertex %d is not between two faces", c,
                                  cc->vertices[i], cc->vertices[i + 1]);
        }
        r = fil_add_curve(F, cc->vertices, cc->count, cc->vertices[0] == cc->vertices[cc->count - 1] && cc->count > 3, radius,
                          profile, w);
        if (r != SFB_SUCCESS) return r;
    }
    return SFB_SUCCESS;
}

/* The corners (sfb__fil_corner): vertices where exactly three open curves end, with one
 * convexity, whose faces lie on three planes. Marks every curve's edges in fmark too. */
static sfb_result fil_find_corners(sfb__fil *F) {
    const sfb__level *l = F->l;
    int *ends = (int *)sfb__calloc(F->ctx, (size_t)F->nv + 1, sizeof(int));
    int c, k, i;
    if (!ends) return sfb__oom(F->ctx, "the corners");
    for (c = 0; c < F->ncurves; ++c) {
        const sfb__fil_curve *cv = &F->curves[c];
        for (i = 0; i + 1 < cv->n; ++i) {
            const int e = fil_edge_of(l, cv->v[i], cv->v[i + 1]);
            if (e >= 0) F->fmark[e] = 1;
        }
        if (!cv->closed) { ends[cv->v[0]]++; ends[cv->v[cv->n - 1]]++; }
    }
    for (c = 0; c < F->ncurves; ++c) {
        sfb__fil_curve *cv = &F->curves[c];
        for (k = 0; k < 2 && !cv->closed; ++k) {
            const int v = k ? cv->v[cv->n - 1] : cv->v[0];
            int members[3][2], nm = 0, sign = 0, ok = 1, d, j, known = -1;
            double A[3][3] = {{0}}, rhs[3] = {0}, det, tr, X[3], r = 0.0;
            sfb__fil_corner *K;
            if (ends[v] != 3) continue;
            for (j = 0; j < F->ncorners; ++j)
                if (F->corners[j].v == v) known = j;
            if (known >= 0) { cv->corner[k] = known; continue; }
            /* the three curve ends at v: one convexity, one radius */
            for (d = 0; d < F->ncurves && nm <= 3; ++d) {
                const sfb__fil_curve *w = &F->curves[d];
                int kk;
                for (kk = 0; kk < 2 && !w->closed; ++kk)
                    if ((kk ? w->v[w->n - 1] : w->v[0]) == v && nm < 3) {
                        double conv = 0.0;
                        for (j = 0; j + 1 < w->n; ++j) {
                            const int e = fil_edge_of(l, w->v[j], w->v[j + 1]);
                            if (e >= 0 && l->ef_off[e + 1] - l->ef_off[e] == 2) conv += fil_edge_conv(F, e, w->v[j], w->v[j + 1]);
                        }
                        if (sign == 0) sign = conv < 0 ? -1 : 1;
                        else if ((conv < 0 ? -1 : 1) != sign) ok = 0;
                        if (w->profile != SFB_FILLET_ARC) ok = 0; /* the sphere continues the arc only */
                        if (nm == 0) r = w->radius;
                        else if (fabs(w->radius - r) > 1e-9 * r) ok = 0;
                        members[nm][0] = d;
                        members[nm][1] = kk;
                        nm++;
                    }
            }
            if (!ok || nm != 3) continue;
            /* the ball's centre: r from every face plane around v, least squares (angle weighted) */
            for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j) {
                const int f = l->vf[j];
                const double *n = F->fn + 3 * (size_t)f;
                int q, p2;
                for (q = 0; q < 3; ++q) {
                    for (p2 = 0; p2 < 3; ++p2) A[q][p2] += n[q] * n[p2];
                    rhs[q] += n[q] * (fil_dot(n, F->pos + 3 * (size_t)v) + sign * r);
                }
            }
            det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                  A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
            tr = A[0][0] + A[1][1] + A[2][2];
            if (!(fabs(det) > 1e-3 * tr * tr * tr)) continue; /* fewer than three independent planes */
            for (j = 0; j < 3; ++j) {
                double M[3][3];
                int q;
                memcpy(M, A, sizeof M);
                for (q = 0; q < 3; ++q) M[q][j] = rhs[q];
                X[j] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                        M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
            }
            /* every face plane r from it (the faces around v lie on three planes) */
            for (j = l->vf_off[v]; j < l->vf_off[v + 1] && ok; ++j) {
                const double *n = F->fn + 3 * (size_t)l->vf[j];
                double dv[3];
                fil_sub(X, F->pos + 3 * (size_t)v, dv);
                if (fabs(fil_dot(n, dv) - sign * r) > 0.02 * r) ok = 0;
            }
            if (!ok) continue;
            if (F->ncorners % 8 == 0) {
                sfb__fil_corner *nc = (sfb__fil_corner *)sfb__realloc(F->ctx, F->corners, (size_t)(F->ncorners + 8) * sizeof *nc);
                if (!nc) { sfb__free(F->ctx, ends); return sfb__oom(F->ctx, "the corners"); }
                F->corners = nc;
            }
            K = &F->corners[F->ncorners];
            memset(K, 0, sizeof *K);
            K->v = v;
            K->r = r;
            memcpy(K->C, X, sizeof X);
            for (j = 0; j < 3; ++j) {
                const sfb__fil_curve *w = &F->curves[members[j][0]];
                const int a = members[j][1] ? w->v[w->n - 1] : w->v[0], b = members[j][1] ? w->v[w->n - 2] : w->v[1];
                double u[3], lu;
                fil_sub(F->pos + 3 * (size_t)a, F->pos + 3 * (size_t)b, u);
                lu = fil_len(u);
                for (d = 0; d < 3; ++d) K->u[j][d] = lu > 0 ? u[d] / lu : 0.0;
                K->curve[j] = members[j][0];
            }
            cv->corner[k] = F->ncorners++;
        }
    }
    /* the other junctions: the largest reach of the curves ending there */
    for (c = 0; c < F->ncurves; ++c) {
        sfb__fil_curve *cv = &F->curves[c];
        for (k = 0; k < 2 && !cv->closed; ++k) {
            const int v = k ? cv->v[cv->n - 1] : cv->v[0];
            double s = 0.0;
            int d, j, known = -1;
            if (ends[v] < 2 || cv->corner[k] >= 0) continue;
            for (j = 0; j < F->njunctions; ++j)
                if (F->junctions[j].v == v) known = j;
            if (known < 0) {
                for (d = 0; d < F->ncurves; ++d) {
                    const sfb__fil_curve *w = &F->curves[d];
                    double dm = 0.0, reach;
                    if (w->closed || (w->v[0] != v && w->v[w->n - 1] != v)) continue;
                    for (j = 0; j + 1 < w->n; ++j) {
                        const int e = fil_edge_of(l, w->v[j], w->v[j + 1]);
                        if (e >= 0 && fil_dihedral(F, e) > dm) dm = fil_dihedral(F, e);
                    }
                    reach = fil_reach(w->radius, dm);
                    if (reach > s) s = reach;
                }
                if (F->njunctions % 8 == 0) {
                    sfb__fil_junction *nj = (sfb__fil_junction *)sfb__realloc(F->ctx, F->junctions, (size_t)(F->njunctions + 8) * sizeof *nj);
                    if (!nj) { sfb__free(F->ctx, ends); return sfb__oom(F->ctx, "the junctions"); }
                    F->junctions = nj;
                }
                F->junctions[F->njunctions].v = v;
                F->junctions[F->njunctions].s = s;
                known = F->njunctions++;
            }
            cv->setback[k] = F->junctions[known].s;
        }
    }
    sfb__free(F->ctx, ends);
    return SFB_SUCCESS;
}

/* The junctions' membranes: around each junction vertex (within 2 s), the vertices no sweep or
 * corner moved get the harmonic interpolation (uniform weights, sparse CG) of the moves of the
 * vertices around them; those at 2 s and beyond keep theirs (mostly none). */
static sfb_result fil_junctions_fill(sfb__fil *F) {
    sfb_context *ctx = F->ctx;
    const sfb__level *l = F->l;
    int *loc = NULL, *list = NULL, *rowi = NULL, *coli = NULL, jn;
    double *val = NULL, *b = NULL, *x = NULL;
    sfb_result res = SFB_SUCCESS;
    if (F->njunctions == 0) return SFB_SUCCESS;
    loc = (int *)sfb__alloc(ctx, ((size_t)F->nv + 1) * sizeof(int));
    list = (int *)sfb__alloc(ctx, ((size_t)F->nv + 1) * sizeof(int));
    if (!loc || !list) { res = sfb__oom(ctx, "the junctions"); goto done; }
    for (jn = 0; jn < F->nv; ++jn) loc[jn] = -1;
    for (jn = 0; jn < F->njunctions; ++jn) {
        const sfb__fil_junction *J = &F->junctions[jn];
        const double *V = F->pos + 3 * (size_t)J->v, R = 1.25 * J->s;
        int head = 0, n = 0, nu = 0, i, j, c, nt = 0, it;
        double resid;
        /* the vertices within R of V, reached over edges; loc: -2 seen and fixed, >= 0 unknown */
        list[n++] = J->v;
        loc[J->v] = -2;
        while (head < n) {
            const int v = list[head++];
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                const int w = sfb__other_end(l, l->ve[j], v);
                if (loc[w] != -1 || fil_dist(F->pos + 3 * (size_t)w, V) >= R) continue;
                loc[w] = -2;
                list[n++] = w;
            }
        }
        for (i = 0; i < n; ++i) {
            const int v = list[i];
            int boundary = 0;
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) boundary |= l->ef_off[l->ve[j] + 1] - l->ef_off[l->ve[j]] != 2;
            if (!boundary && memcmp(F->pos + 3 * (size_t)v, F->opos + 3 * (size_t)v, 3 * sizeof(double)) == 0) loc[v] = nu++;
        }
        if (nu > 0) {
            size_t cap = 0;
            sfb__sparse A;
            memset(&A, 0, sizeof A);
            for (i = 0; i < n; ++i)
                if (loc[list[i]] >= 0) cap += (size_t)(l->ve_off[list[i] + 1] - l->ve_off[list[i]]) + 1;
            rowi = (int *)sfb__alloc(ctx, cap * sizeof(int));
            coli = (int *)sfb__alloc(ctx, cap * sizeof(int));
            val = (double *)sfb__alloc(ctx, cap * sizeof(double));
            b = (double *)sfb__calloc(ctx, (size_t)nu * 3, sizeof(double));
            x = (double *)sfb__calloc(ctx, (size_t)nu, sizeof(double));
            if (!rowi || !coli || !val || !b || !x) { res = sfb__oom(ctx, "the junctions"); goto done; }
            for (i = 0; i < n; ++i) {
                const int v = list[i], u = loc[v];
                if (u < 0) continue;
                rowi[nt] = u; coli[nt] = u; val[nt] = (double)(l->ve_off[v + 1] - l->ve_off[v]); nt++;
                for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                    const int w = sfb__other_end(l, l->ve[j], v);
                    if (loc[w] >= 0) { rowi[nt] = u; coli[nt] = loc[w]; val[nt] = -1.0; nt++; }
                    else
                        for (c = 0; c < 3; ++c) b[3 * (size_t)u + c] += F->opos[3 * (size_t)w + c] - F->pos[3 * (size_t)w + c];
                }
            }
            res = sfb__sparse_from_triplets(ctx, nu, nt, rowi, coli, val, &A);
            for (c = 0; c < 3 && res == SFB_SUCCESS; ++c) {
                double *bc = (double *)sfb__alloc(ctx, (size_t)nu * sizeof(double));
                if (!bc) { res = sfb__oom(ctx, "the junctions"); break; }
                for (i = 0; i < nu; ++i) { bc[i] = b[3 * (size_t)i + c]; x[i] = 0.0; }
                {
                    /* best effort: a solve that does not converge keeps its last iterate, said to
                     * the logger; the caller's last error is put back */
                    sfb__error_state kept;
                    sfb__error_keep(ctx, &kept);
                    if (sfb__sparse_cg(ctx, &A, bc, x, 1e-12, 4 * nu + 200, &it, &resid) != SFB_SUCCESS) {
                        sfb__log(ctx, SFB_LOG_INFO, "fillet junctions: %s; the last iterate is kept", ctx->error);
                        sfb__error_put_back(ctx, &kept);
                    }
                }
                for (i = 0; i < n; ++i)
                    if (loc[list[i]] >= 0 && isfinite(x[loc[list[i]]])) F->opos[3 * (size_t)list[i] + c] = F->pos[3 * (size_t)list[i] + c] + x[loc[list[i]]];
                sfb__free(ctx, bc);
            }
            sfb__sparse_free(ctx, &A);
            sfb__free(ctx, rowi); sfb__free(ctx, coli); sfb__free(ctx, val); sfb__free(ctx, b); sfb__free(ctx, x);
            rowi = coli = NULL; val = b = x = NULL;
            if (res != SFB_SUCCESS) goto done;
        }
        for (i = 0; i < n; ++i) loc[list[i]] = -1;
    }
done:
    sfb__free(ctx, loc); sfb__free(ctx, list);
    sfb__free(ctx, rowi); sfb__free(ctx, coli); sfb__free(ctx, val); sfb__free(ctx, b); sfb__free(ctx, x);
    return res;
}

/* The corners' spheres: from the corner vertex through the vertices beyond all three end planes
 * (within 4 r of the ball's centre), each moved to the sphere along the ray from the centre. */
static sfb_result fil_corners_project(sfb__fil *F, const sfb_fillet_curve_report *reps) {
    const sfb__level *l = F->l;
    int *stack = (int *)sfb__alloc(F->ctx, ((size_t)F->nv + 1) * sizeof(int));
    unsigned char *seen = (unsigned char *)sfb__calloc(F->ctx, (size_t)F->nv + 1, 1);
    int k;
    if (!stack || !seen) { sfb__free(F->ctx, stack); sfb__free(F->ctx, seen); return sfb__oom(F->ctx, "the corners"); }
    for (k = 0; k < F->ncorners; ++k) {
        sfb__fil_corner *K = &F->corners[k];
        int sp = 0, j;
        if (reps[K->curve[0]].skipped || reps[K->curve[1]].skipped || reps[K->curve[2]].skipped) continue; /* left sharp */
        stack[sp++] = K->v;
        seen[K->v] |= 1;
        while (sp > 0) {
            const int v = stack[--sp];
            const double *p = F->pos + 3 * (size_t)v;
            double dv[3], ld;
            int inside = 1;
            fil_sub(p, K->C, dv);
            ld = fil_len(dv);
            for (j = 0; j < 3; ++j) inside &= fil_dot(dv, K->u[j]) >= -1e-9 * K->r;
            if (!inside || !(ld > 0) || ld > 4.0 * K->r) continue;
            if (!(seen[v] & 2)) { /* a vertex two corners reach (a tiny mesh) moves once, for the first */
                for (j = 0; j < 3; ++j) F->opos[3 * (size_t)v + j] = K->C[j] + K->r * dv[j] / ld;
                K->moved++;
                seen[v] |= 2;
            }
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                const int w = sfb__other_end(l, l->ve[j], v);
                if (!(seen[w] & 1)) { seen[w] |= 1; stack[sp++] = w; }
            }
        }
        /* reset seen for the next corner: the visited set is small, walk it again */
        stack[0] = K->v;
        sp = 1;
        seen[K->v] &= (unsigned char)~1u;
        while (sp > 0) {
            const int v = stack[--sp];
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                const int w = sfb__other_end(l, l->ve[j], v);
                if (seen[w] & 1) { seen[w] &= (unsigned char)~1u; stack[sp++] = w; }
            }
        }
    }
    sfb__free(F->ctx, stack);
    sfb__free(F->ctx, seen);
    return SFB_SUCCESS;
}

/* ---- one curve ---- */
typedef struct sfb__fil_seg { double a[3], b[3]; } sfb__fil_seg;
typedef struct sfb__fil_pairs {
    sfb__fil *F;
    const double *op0, *op1;
    const int *t0, *t1;
    sfb__fil_seg *segs;
    size_t n, cap;
    int failed;
} sfb__fil_pairs;

static int fil_pair_cb(int i, int j, void *user) {
    sfb__fil_pairs *P = (sfb__fil_pairs *)user;
    const int *a = P->t0 + 3 * (size_t)i, *b = P->t1 + 3 * (size_t)j;
    double s0[3], s1[3];
    if (sfb__tri_tri_segment(P->op0 + 3 * (size_t)a[0], P->op0 + 3 * (size_t)a[1], P->op0 + 3 * (size_t)a[2],
                             P->op1 + 3 * (size_t)b[0], P->op1 + 3 * (size_t)b[1], P->op1 + 3 * (size_t)b[2], s0, s1, NULL,
                             NULL) != 1)
        return 0;
    if (P->n == P->cap) {
        const size_t cap = P->cap ? 2 * P->cap : 256;
        sfb__fil_seg *ns = (sfb__fil_seg *)sfb__realloc(P->F->ctx, P->segs, cap * sizeof *ns);
        if (!ns) { P->failed = 1; return 1; }
        P->segs = ns;
        P->cap = cap;
    }
    memcpy(P->segs[P->n].a, s0, sizeof s0);
    memcpy(P->segs[P->n].b, s1, sizeof s1);
    P->n++;
    return 0;
}

typedef struct sfb__fil_key { double x; int id; } sfb__fil_key;
static int fil_key_cmp(const void *a, const void *b) {
    const double x = ((const sfb__fil_key *)a)->x, y = ((const sfb__fil_key *)b)->x;
    return x < y ? -1 : x > y ? 1 : 0;
}

/* Chains intersection segments into the spine: endpoints welded within tol, duplicate pieces
 * dropped, then walks along unused pieces (through a node where pieces cross, the straightest way
 * on); stray bits and non-manifold branches end up in walks of their own and are dropped by
 * keeping one walk: the longest closed loop when `want_closed` (else the longest walk), the longest
 * open chain otherwise (a closed loop when there is none). Writes the points (closed: not repeated). */
static sfb_result fil_chain(sfb_context *ctx, const sfb__fil_seg *segs, size_t ns, double tol, int want_closed, double **out,
                            int *out_n, int *out_closed) {
    const size_t np = 2 * ns;
    sfb__fil_key *keys = (sfb__fil_key *)sfb__alloc(ctx, (np + 1) * sizeof *keys);
    int *node = (int *)sfb__alloc(ctx, (np + 1) * sizeof(int));
    int *deg = NULL, *path = NULL, *best = NULL;
    double *npos = NULL;
    int nn = 0, best_n = 0, best_closed = 0;
    double best_len = -1.0;
    size_t i, k;
    sfb_result r = SFB_SUCCESS;
    *out = NULL;
    *out_n = 0;
    *out_closed = 0;
    if (!keys || !node) { r = sfb__oom(ctx, "the spine's points"); goto done; }
    for (i = 0; i < np; ++i) {
        keys[i].x = (i & 1) ? segs[i / 2].b[0] : segs[i / 2].a[0];
        keys[i].id = (int)i;
        node[i] = -1;
    }
    qsort(keys, np, sizeof *keys, fil_key_cmp);
    npos = (double *)sfb__alloc(ctx, (np + 1) * 3 * sizeof(double));
    if (!npos) { r = sfb__oom(ctx, "the spine's points"); goto done; }
    for (i = 0; i < np; ++i) {
        const int id = keys[i].id;
        const double *p = (id & 1) ? segs[id / 2].b : segs[id / 2].a;
        if (node[id] >= 0) continue;
        node[id] = nn;
        memcpy(npos + 3 * (size_t)nn, p, 3 * sizeof(double));
        for (k = i + 1; k < np && keys[k].x - keys[i].x <= tol; ++k) {
            const int jd = keys[k].id;
            const double *q = (jd & 1) ? segs[jd / 2].b : segs[jd / 2].a;
            if (node[jd] < 0 && fil_dist(p, q) <= tol) node[jd] = nn;
        }
        nn++;
    }
    /* edges between distinct nodes, each once; adjacency lists (compressed) */
    {
        int *eu = (int *)sfb__alloc(ctx, (ns + 1) * 2 * sizeof(int)), ne = 0, *off = NULL, *inc = NULL, *fill = NULL;
        unsigned char *eused = NULL;
        int s, e;
        deg = (int *)sfb__calloc(ctx, (size_t)nn + 1, sizeof(int));
        path = (int *)sfb__alloc(ctx, ((size_t)ns + 2) * sizeof(int));
        best = (int *)sfb__alloc(ctx, ((size_t)ns + 2) * sizeof(int));
        off = (int *)sfb__calloc(ctx, (size_t)nn + 2, sizeof(int));
        if (!eu || !deg || !path || !best || !off) { sfb__free(ctx, eu); sfb__free(ctx, off); r = sfb__oom(ctx, "the spine's chains"); goto done; }
        for (i = 0; i < ns; ++i) {
            const int a = node[2 * i], b = node[2 * i + 1];
            if (a == b) continue;
            eu[2 * ne] = a < b ? a : b;
            eu[2 * ne + 1] = a < b ? b : a;
            ne++;
        }
        /* the same piece found from two triangle pairs: drop duplicates (sort by key) */
        {
            sfb__fil_key *ek = (sfb__fil_key *)sfb__alloc(ctx, ((size_t)ne + 1) * sizeof *ek);
            int *keep = (int *)sfb__alloc(ctx, ((size_t)ne + 1) * 2 * sizeof(int)), nk = 0;
            if (!ek || !keep) { sfb__free(ctx, ek); sfb__free(ctx, keep); sfb__free(ctx, eu); sfb__free(ctx, off); r = sfb__oom(ctx, "the spine's chains"); goto done; }
            for (e = 0; e < ne; ++e) { ek[e].x = (double)eu[2 * e] * ((double)nn + 1.0) + eu[2 * e + 1]; ek[e].id = e; }
            qsort(ek, (size_t)ne, sizeof *ek, fil_key_cmp);
            for (e = 0; e < ne; ++e)
                if (e == 0 || ek[e].x != ek[e - 1].x) { keep[2 * nk] = eu[2 * ek[e].id]; keep[2 * nk + 1] = eu[2 * ek[e].id + 1]; nk++; }
            memcpy(eu, keep, (size_t)nk * 2 * sizeof(int));
            ne = nk;
            sfb__free(ctx, ek);
            sfb__free(ctx, keep);
        }
        for (e = 0; e < ne; ++e) { off[eu[2 * e] + 1]++; off[eu[2 * e + 1] + 1]++; }
        for (s = 0; s < nn; ++s) { deg[s] = off[s + 1]; off[s + 1] += off[s]; }
        inc = (int *)sfb__alloc(ctx, ((size_t)2 * ne + 1) * sizeof(int));
        fill = (int *)sfb__calloc(ctx, (size_t)nn + 1, sizeof(int));
        eused = (unsigned char *)sfb__calloc(ctx, (size_t)ne + 1, 1);
        if (!inc || !fill || !eused) {
            sfb__free(ctx, eu); sfb__free(ctx, off); sfb__free(ctx, inc); sfb__free(ctx, fill); sfb__free(ctx, eused);
            r = sfb__oom(ctx, "the spine's chains");
            goto done;
        }
        for (e = 0; e < ne; ++e) {
            inc[off[eu[2 * e]] + fill[eu[2 * e]]++] = e;
            inc[off[eu[2 * e + 1]] + fill[eu[2 * e + 1]]++] = e;
        }
        /* walks: from ends (odd degree) first, then whatever is left; at a node of degree > 2 (two
         * pieces crossing: a spine that intersects itself, seed 4.3) the walk goes on along the
         * straightest unused edge, so a self-crossing spine stays one curve for the loop removal */
        for (k = 0; k < 2; ++k)
            for (s = 0; s < nn; ++s) {
                int n = 0, cur = s, closed = 0;
                double len = 0.0;
                if (k == 0 && !(deg[s] & 1)) continue;
                for (;;) {
                    int j2, pick = -1, nx;
                    double bestd = -HUGE_VAL;
                    path[n++] = cur;
                    if (n > (int)ns + 1) break;
                    for (j2 = off[cur]; j2 < off[cur + 1]; ++j2) {
                        const int ed = inc[j2];
                        double dir[3], din[3], ld, li, dd;
                        if (eused[ed]) continue;
                        nx = eu[2 * ed] == cur ? eu[2 * ed + 1] : eu[2 * ed];
                        if (n < 2) { pick = ed; break; }
                        fil_sub(npos + 3 * (size_t)nx, npos + 3 * (size_t)cur, dir);
                        fil_sub(npos + 3 * (size_t)cur, npos + 3 * (size_t)path[n - 2], din);
                        ld = fil_len(dir); li = fil_len(din);
                        dd = (ld > 0 && li > 0) ? fil_dot(dir, din) / (ld * li) : -1.0;
                        if (dd > bestd) { bestd = dd; pick = ed; }
                    }
                    if (pick < 0) break;
                    eused[pick] = 1;
                    nx = eu[2 * pick] == cur ? eu[2 * pick + 1] : eu[2 * pick];
                    len += fil_dist(npos + 3 * (size_t)cur, npos + 3 * (size_t)nx);
                    cur = nx;
                    if (cur == s) {
                        /* back at the start: closed unless the start has more to walk (then go on) */
                        int more = 0;
                        for (j2 = off[cur]; j2 < off[cur + 1]; ++j2) more |= !eused[inc[j2]];
                        if (!more) { closed = 1; break; }
                    }
                }
                if (n < 2) continue;
                {
                    const int match = closed == want_closed, best_match = best_closed == want_closed;
                    if (best_n == 0 || (match && !best_match) || (match == best_match && len > best_len)) {
                        memcpy(best, path, (size_t)n * sizeof(int));
                        best_n = n;
                        best_len = len;
                        best_closed = closed;
                    }
                }
            }
        sfb__free(ctx, eu); sfb__free(ctx, off); sfb__free(ctx, inc); sfb__free(ctx, fill); sfb__free(ctx, eused);
    }
    if (best_n >= 2) {
        double *o = (double *)sfb__alloc(ctx, (size_t)best_n * 3 * sizeof(double));
        if (!o) { r = sfb__oom(ctx, "the spine"); goto done; }
        for (i = 0; i < (size_t)best_n; ++i) memcpy(o + 3 * i, npos + 3 * (size_t)best[i], 3 * sizeof(double));
        *out = o;
        *out_n = best_n;
        *out_closed = best_closed;
    }
done:
    sfb__free(ctx, keys); sfb__free(ctx, node); sfb__free(ctx, deg); sfb__free(ctx, path); sfb__free(ctx, best); sfb__free(ctx, npos);
    return r;
}

/* Nearest point to p on polyline pts (n points; closed: the last joins the first): the segment i
 * (from point i to i+1 mod n), its parameter and the squared distance. */
static void fil_polyline_nearest(const double *pts, int n, int closed, const double *p, int *seg, double *t, double *d2) {
    const int segs = closed ? n : n - 1;
    int i;
    *seg = 0; *t = 0.0; *d2 = HUGE_VAL;
    for (i = 0; i < segs; ++i) {
        const double *a = pts + 3 * (size_t)i, *b = pts + 3 * (size_t)((i + 1) % n);
        const double s = fil_seg_param(p, a, b);
        double q[3], dd;
        fil_lerp(a, b, s, q);
        dd = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) + (q[2] - p[2]) * (q[2] - p[2]);
        if (dd < *d2) { *d2 = dd; *seg = i; *t = s; }
    }
}

/* The Hermite segment that reconnects a spine's regressive points (seed 4.3): from A with the
 * direction ta to B with tb, both tangents scaled to the chord; writes its 7 inner points (8
 * pieces) to out and returns 7. */
static int fil_hermite_bridge(const double *A, const double *ta_dir, const double *B, const double *tb_dir, double *out) {
    const int m = 8;
    const double L = fil_dist(A, B), la = fil_len(ta_dir), lb = fil_len(tb_dir);
    double ta[3], tb[3];
    int k, c;
    for (c = 0; c < 3; ++c) { ta[c] = ta_dir[c] * (la > 0 ? L / la : 0); tb[c] = tb_dir[c] * (lb > 0 ? L / lb : 0); }
    for (k = 1; k < m; ++k) {
        const double s = (double)k / m, h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s, h01 = -2 * s * s * s + 3 * s * s,
                     h11 = s * s * s - s * s;
        for (c = 0; c < 3; ++c) out[3 * (size_t)(k - 1) + c] = h00 * A[c] + h10 * ta[c] + h01 * B[c] + h11 * tb[c];
    }
    return m - 1;
}

/* Spine self-intersections (seed 4.3): two spine pieces closer than tol, apart along the spine by
 * more than `gap`, close a loop; the loop (the shorter way round for a closed spine, the part
 * between them for an open one) is cut out and its ends Q1, Q2 -- the points `gap` before and
 * after it -- are joined by a cubic Hermite segment with the spine's tangents there. Then
 * non-shrinking Taubin smoothing (lambda 0.5, mu -0.53) of the whole spine. Returns the loops cut. */
static int fil_spine_untangle(sfb_context *ctx, double **pts_io, int *n_io, int closed, double tol, double gap) {
    int n = *n_io, cuts = 0, guard;
    double *pts = *pts_io;
    for (guard = 0; guard < 16; ++guard) {
        double *acc;
        int found = 0;
        int i, j, bi = -1, bj = -1;
        /* arc length positions */
        acc = (double *)sfb__alloc(ctx, ((size_t)n + 1) * sizeof(double));
        if (!acc) break;
        acc[0] = 0.0;
        for (i = 1; i < n; ++i) acc[i] = acc[i - 1] + fil_dist(pts + 3 * (size_t)(i - 1), pts + 3 * (size_t)i);
        acc[n] = acc[n - 1] + (closed ? fil_dist(pts + 3 * (size_t)(n - 1), pts) : 0.0);
        for (i = 0; i < n && !found; ++i)
            for (j = i + 2; j < n; ++j) {
                double along = acc[j] - acc[i];
                if (closed && acc[n] - along < along) along = acc[n] - along;
                if (along <= 2.0 * gap) continue;
                if (fil_dist(pts + 3 * (size_t)i, pts + 3 * (size_t)j) < tol) { bi = i; bj = j; found = 1; break; }
            }
        if (!found) { sfb__free(ctx, acc); break; }
        {
            /* the loop is i..j (inner), or for a closed spine the shorter of i..j and j..i */
            int keep_inner = 0, q1, q2, k, o = 0;
            double *np_;
            if (closed && (acc[bj] - acc[bi]) > acc[n] / 2) keep_inner = 1; /* the outer part is the loop */
            if (keep_inner) {
                /* keep bi..bj, drop the wrap-around part */
                q1 = bi; q2 = bj;
                while (q1 < bj && acc[q1] - acc[bi] < gap) q1++;
                while (q2 > q1 && acc[bj] - acc[q2] < gap) q2--;
                np_ = (double *)sfb__alloc(ctx, ((size_t)(q2 - q1 + 1) + 16) * 3 * sizeof(double));
                if (!np_) { sfb__free(ctx, acc); break; }
                for (k = q1; k <= q2; ++k) memcpy(np_ + 3 * (size_t)o++, pts + 3 * (size_t)k, 3 * sizeof(double));
                /* Hermite from q2 back to q1 across the cut */
                {
                    double ta[3], tb[3];
                    fil_sub(pts + 3 * (size_t)q2, pts + 3 * (size_t)(q2 - 1), ta);
                    fil_sub(pts + 3 * (size_t)(q1 + 1), pts + 3 * (size_t)q1, tb);
                    o += fil_hermite_bridge(pts + 3 * (size_t)q2, ta, pts + 3 * (size_t)q1, tb, np_ + 3 * (size_t)o);
                }
            } else {
                q1 = bi; q2 = bj;
                while (q1 > 0 && acc[bi] - acc[q1] < gap) q1--;
                while (q2 < n - 1 && acc[q2] - acc[bj] < gap) q2++;
                np_ = (double *)sfb__alloc(ctx, ((size_t)n + 16) * 3 * sizeof(double));
                if (!np_) { sfb__free(ctx, acc); break; }
                for (k = 0; k <= q1; ++k) memcpy(np_ + 3 * (size_t)o++, pts + 3 * (size_t)k, 3 * sizeof(double));
                {
                    double ta[3], tb[3];
                    fil_sub(pts + 3 * (size_t)q1, pts + 3 * (size_t)(q1 > 0 ? q1 - 1 : q1), ta);
                    if (q1 == 0) fil_sub(pts + 3 * (size_t)1, pts, ta);
                    fil_sub(pts + 3 * (size_t)(q2 + 1 < n ? q2 + 1 : q2), pts + 3 * (size_t)q2, tb);
                    if (q2 + 1 >= n) fil_sub(pts + 3 * (size_t)q2, pts + 3 * (size_t)(q2 - 1), tb);
                    o += fil_hermite_bridge(pts + 3 * (size_t)q1, ta, pts + 3 * (size_t)q2, tb, np_ + 3 * (size_t)o);
                }
                for (k = q2; k < n; ++k) memcpy(np_ + 3 * (size_t)o++, pts + 3 * (size_t)k, 3 * sizeof(double));
            }
            sfb__free(ctx, pts);
            pts = np_;
            n = o;
        }
        sfb__free(ctx, acc);
        cuts++;
    }
    if (cuts) {
        /* Taubin lambda|mu smoothing, ends of an open spine fixed */
        double *tmp = (double *)sfb__alloc(ctx, (size_t)n * 3 * sizeof(double));
        int it, i, c;
        if (tmp)
            for (it = 0; it < 20; ++it) {
                const double f = (it & 1) ? -0.53 : 0.5;
                memcpy(tmp, pts, (size_t)n * 3 * sizeof(double));
                for (i = 0; i < n; ++i) {
                    int a = i - 1, b = i + 1;
                    if (!closed && (i == 0 || i == n - 1)) continue;
                    if (a < 0) a = n - 1;
                    if (b >= n) b = 0;
                    for (c = 0; c < 3; ++c)
                        pts[3 * (size_t)i + c] = tmp[3 * (size_t)i + c] + f * (0.5 * (tmp[3 * (size_t)a + c] + tmp[3 * (size_t)b + c]) - tmp[3 * (size_t)i + c]);
                }
            }
        sfb__free(ctx, tmp);
    }
    *pts_io = pts;
    *n_io = n;
    return cuts;
}

/* ---- profiles (seed 4.2) ---- */
/* A profile from spine point C and linkage points P1 (u = 0), P2 (u = 1): P0 is the end tangents'
 * intersection, P0 = C + (a + b) / (1 + cos phi) with a = P1 - C, b = P2 - C (seed eq. 2), phi the
 * central angle; the arc is the rational quadratic (P1, P0, P2) with middle weight cos(phi / 2)
 * (ALGORITHMS.md 6: the central angle, not the angle at P0). */
static void fil_prof_eval(const sfb__fil_prof *P, int kind, double hs, double u, double *o) {
    int c;
    if (kind == SFB_FILLET_SHARPEN) {
        const double l1 = fil_dist(P->P1, P->P0), l2 = fil_dist(P->P0, P->P2), s = u * (l1 + l2);
        if (s <= l1 && l1 > 0.0) fil_lerp(P->P1, P->P0, s / l1, o);
        else if (l2 > 0.0) fil_lerp(P->P0, P->P2, (s - l1) / l2, o);
        else memcpy(o, P->P2, 3 * sizeof(double));
        return;
    }
    if (kind == SFB_FILLET_HERMITE) {
        double t1[3], t2[3], l1, l2, chord = fil_dist(P->P1, P->P2), len;
        const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u, h01 = -2 * u * u * u + 3 * u * u,
                     h11 = u * u * u - u * u;
        double phi;
        fil_sub(P->P0, P->P1, t1);
        fil_sub(P->P2, P->P0, t2);
        l1 = fil_len(t1);
        l2 = fil_len(t2);
        {
            double a[3], b[3], cphi;
            fil_sub(P->P1, P->C, a);
            fil_sub(P->P2, P->C, b);
            cphi = fil_dot(a, b) / (fil_len(a) * fil_len(b) + 1e-300);
            phi = acos(cphi > 1 ? 1 : cphi < -1 ? -1 : cphi);
        }
        /* the arc's own: a cubic Bezier arm of 4/3 tan(phi/4) r is a Hermite tangent of 4 tan(phi/4) r */
        len = hs > 0.0 ? hs * chord : 4.0 * tan(phi / 4.0) * P->r;
        for (c = 0; c < 3; ++c) {
            const double a = l1 > 0 ? t1[c] / l1 * len : 0.0, b = l2 > 0 ? t2[c] / l2 * len : 0.0;
            o[c] = h00 * P->P1[c] + h10 * a + h01 * P->P2[c] + h11 * b;
        }
        return;
    }
    {
        const double b0 = (1 - u) * (1 - u), b1 = 2 * u * (1 - u) * P->w, b2 = u * u, den = b0 + b1 + b2;
        for (c = 0; c < 3; ++c) o[c] = (b0 * P->P1[c] + b1 * P->P0[c] + b2 * P->P2[c]) / den;
    }
}

static void fil_prof_build(sfb__fil_prof *P, const double *C, const double *P1, const double *P2, const double *E, int kind,
                           double conic_w, double hs) {
    double a[3], b[3], la, lb, cphi;
    int k;
    memcpy(P->C, C, sizeof P->C);
    memcpy(P->P1, P1, sizeof P->P1);
    memcpy(P->P2, P2, sizeof P->P2);
    memcpy(P->E, E, sizeof P->E);
    fil_sub(P1, C, a);
    fil_sub(P2, C, b);
    la = fil_len(a);
    lb = fil_len(b);
    P->r = 0.5 * (la + lb);
    cphi = (la > 0 && lb > 0) ? fil_dot(a, b) / (la * lb) : 1.0;
    cphi = cphi > 1 ? 1 : cphi < -1 ? -1 : cphi;
    if (1.0 + cphi > 1e-9) {
        for (k = 0; k < 3; ++k) P->P0[k] = C[k] + (a[k] + b[k]) / (1.0 + cphi);
        P->w = sqrt(0.5 * (1.0 + cphi)); /* cos(phi / 2) */
    } else { /* half a turn: no corner to round; a straight profile */
        fil_lerp(P1, P2, 0.5, P->P0);
        P->w = 1.0;
    }
    if (kind == SFB_FILLET_CONIC && conic_w > 0.0) P->w = conic_w;
    P->L1 = fil_dist(P1, E);
    P->L2 = fil_dist(P2, E);
    P->acc[0] = 0.0;
    for (k = 0; k <= SFB__FIL_TAB; ++k) {
        fil_prof_eval(P, kind, hs, (double)k / SFB__FIL_TAB, P->T[k]);
        if (k) P->acc[k] = P->acc[k - 1] + fil_dist(P->T[k - 1], P->T[k]);
    }
    if (P->acc[SFB__FIL_TAB] > 0.0)
        for (k = 1; k <= SFB__FIL_TAB; ++k) P->acc[k] /= P->acc[SFB__FIL_TAB];
}

/* The profile's point at arc-length fraction a in [0,1]. The table only finds the parameter: the
 * point is evaluated on the curve itself, so it lies on the exact arc or conic. */
static void fil_prof_at(const sfb__fil_prof *P, int kind, double hs, double a, double *o) {
    int lo = 0, hi = SFB__FIL_TAB;
    double u, span;
    if (kind == SFB_FILLET_SHARPEN) { fil_prof_eval(P, kind, hs, a, o); return; }
    a = a < 0 ? 0 : a > 1 ? 1 : a;
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (P->acc[mid] <= a) lo = mid; else hi = mid;
    }
    span = P->acc[hi] - P->acc[lo];
    u = (lo + (span > 0 ? (a - P->acc[lo]) / span : 0.0)) / SFB__FIL_TAB;
    fil_prof_eval(P, kind, hs, u, o);
}

/* Distance from q to profile P's curve (its table, refined around the nearest piece). */
static double fil_prof_distance(const sfb__fil_prof *P, int kind, double hs, const double *q) {
    double best = HUGE_VAL;
    int k, bk = 0;
    if (kind == SFB_FILLET_ARC) return fabs(fil_dist(q, P->C) - P->r);
    for (k = 0; k < SFB__FIL_TAB; ++k) {
        const double t = fil_seg_param(q, P->T[k], P->T[k + 1]);
        double x[3], d;
        fil_lerp(P->T[k], P->T[k + 1], t, x);
        d = fil_dist(x, q);
        if (d < best) { best = d; bk = k; }
    }
    if (kind != SFB_FILLET_SHARPEN) { /* a finer look on the nearest two pieces */
        const double u0 = (bk > 0 ? bk - 1 : 0) / (double)SFB__FIL_TAB, u1 = (bk + 2 < SFB__FIL_TAB ? bk + 2 : SFB__FIL_TAB) / (double)SFB__FIL_TAB;
        double prev[3], cur[3];
        fil_prof_eval(P, kind, hs, u0, prev);
        for (k = 1; k <= 64; ++k) {
            double t, x[3], d;
            fil_prof_eval(P, kind, hs, u0 + (u1 - u0) * k / 64.0, cur);
            t = fil_seg_param(q, prev, cur);
            fil_lerp(prev, cur, t, x);
            d = fil_dist(x, q);
            if (d < best) best = d;
            memcpy(prev, cur, sizeof cur);
        }
    }
    return best;
}

/* ---- spine sampling (seed 4.1) ---- */
static void fil_point_at(const double *pts, const double *cum, int n, int closed, double s, double *o) {
    const int segs = closed ? n : n - 1;
    int lo = 0, hi = segs;
    double len;
    if (s <= 0) { memcpy(o, pts, 3 * sizeof(double)); return; }
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (cum[mid] <= s) lo = mid; else hi = mid;
    }
    len = cum[lo + 1] - cum[lo];
    fil_lerp(pts + 3 * (size_t)lo, pts + 3 * (size_t)((lo + 1) % n), len > 0 ? (s - cum[lo]) / len : 0.0, o);
}

/* Chord height of the spine between arc lengths s0 < s1 over the chord's length. */
static double fil_chord_ratio(const double *pts, const double *cum, int n, int closed, double s0, double s1) {
    double a[3], b[3], ab[3], l, h = 0.0;
    int i;
    fil_point_at(pts, cum, n, closed, s0, a);
    fil_point_at(pts, cum, n, closed, s1, b);
    fil_sub(b, a, ab);
    l = fil_len(ab);
    if (!(l > 0)) return 0.0;
    for (i = 0; i < (closed ? n : n - 1); ++i)
        if (cum[i] > s0 && cum[i] < s1) {
            const double t = fil_seg_param(pts + 3 * (size_t)i, a, b);
            double x[3];
            fil_lerp(a, b, t, x);
            if (fil_dist(x, pts + 3 * (size_t)i) > h) h = fil_dist(x, pts + 3 * (size_t)i);
        }
    return h / l;
}

typedef struct sfb__fil_samples {
    sfb_context *ctx;
    const double *pts, *cum;
    int n, closed;
    double ratio, min_len;
    double *s;
    int cnt, cap, failed;
} sfb__fil_samples;

static void fil_sample_push(sfb__fil_samples *S, double v) {
    if (S->failed) return;
    if (S->cnt == S->cap) {
        const int cap = S->cap ? 2 * S->cap : 128;
        double *ns = (double *)sfb__realloc(S->ctx, S->s, (size_t)cap * sizeof(double));
        if (!ns) { S->failed = 1; return; }
        S->s = ns;
        S->cap = cap;
    }
    S->s[S->cnt++] = v;
}

/* Halves [a, b] while its chord ratio exceeds the threshold (at most 12 times), pushing the
 * inner sample arc lengths in order. */
static void fil_sample_refine(sfb__fil_samples *S, double a, double b, int depth) {
    double m;
    if (depth >= 12 || b - a <= S->min_len || fil_chord_ratio(S->pts, S->cum, S->n, S->closed, a, b) <= S->ratio) return;
    m = 0.5 * (a + b);
    fil_sample_refine(S, a, m, depth + 1);
    fil_sample_push(S, m);
    fil_sample_refine(S, m, b, depth + 1);
}

/* Sample arc lengths: `want` by arc length, then intervals halved while their chord height over
 * chord length exceeds `ratio`. Closed spines: samples in [0, L), the last joins the first. */
static sfb_result fil_sample(sfb_context *ctx, const double *pts, const double *cum, int n, int closed, int want, double ratio,
                             double **out, int *out_n) {
    const double L = cum[closed ? n : n - 1];
    const int intervals = closed ? want : want - 1;
    sfb__fil_samples S;
    int k;
    memset(&S, 0, sizeof S);
    S.ctx = ctx; S.pts = pts; S.cum = cum; S.n = n; S.closed = closed; S.ratio = ratio;
    S.min_len = L * 1e-6;
    for (k = 0; k < intervals; ++k) {
        const double a = L * k / intervals, b = L * (k + 1) / intervals;
        fil_sample_push(&S, a);
        fil_sample_refine(&S, a, b, 0);
    }
    if (!closed) fil_sample_push(&S, L);
    if (S.failed) {
        sfb__free(ctx, S.s);
        return sfb__oom(ctx, "the spine samples");
    }
    *out = S.s;
    *out_n = S.cnt;
    return SFB_SUCCESS;
}

/* ---- one curve: base patches, offsets, spine, samples, profiles, projection ---- */
typedef struct sfb__fil_work {
    int *fside;         /* nf: -1, or the side (0, 1) of a base-patch face */
    double *vd;         /* nv: distance to the curve (-1: not computed) */
    int *vdlist;        /* the vertices whose vd was computed */
    int nvd;
    int *queue;         /* nf */
    double *nrm[2];     /* nv x 3 per side: vertex normals of that side's faces */
    double *op[2];      /* nv x 3 per side: offset positions */
    int *rows[2];       /* per side: the base-patch triangles (3 vertex indices each) */
    int nrows[2];
    unsigned char *vin; /* nv: bit 1 side 0, bit 2 side 1, bit 4 on the curve */
    int *vlist;         /* the vertices with vin != 0 */
    int nvlist;
    double *ta;         /* nv x 2: a blend-region vertex's (t, a) on the sweep (vin bit 8) */
} sfb__fil_work;

static sfb_result fil_stage(sfb__fil *F, int ci, int stage, const char *name) {
    return sfb__progress(F->ctx, (float)((ci + stage / 5.0) / (F->ncurves > 0 ? F->ncurves : 1)), name);
}

/* A polyline with an AABB tree over its segments (each a degenerate triangle i, i+1, i+1, whose
 * nearest point aabb.c finds on the segment): nearest-point queries in log time. Short polylines
 * (fewer than 32 segments) are searched linearly. The nearest segment of two at equal distance
 * may differ from fil_polyline_nearest's choice; the point and distance do not. */
typedef struct sfb__fil_poly {
    const double *pts;
    int n, closed;
    int *tri;
    sfb__aabb tree;
} sfb__fil_poly;
static sfb_result fil_poly_build(sfb_context *ctx, sfb__fil_poly *P, const double *pts, int n, int closed) {
    const int segs = closed ? n : n - 1;
    int i;
    memset(P, 0, sizeof *P);
    P->pts = pts;
    P->n = n;
    P->closed = closed;
    if (segs < 32) return SFB_SUCCESS;
    P->tri = (int *)sfb__alloc(ctx, (size_t)segs * 3 * sizeof(int));
    if (!P->tri) return sfb__oom(ctx, "a polyline's segment tree");
    for (i = 0; i < segs; ++i) {
        P->tri[3 * i] = i;
        P->tri[3 * i + 1] = P->tri[3 * i + 2] = (i + 1) % n;
    }
    return sfb__aabb_build(ctx, pts, P->tri, NULL, segs, &P->tree);
}
static void fil_poly_free(sfb_context *ctx, sfb__fil_poly *P) {
    sfb__aabb_free(ctx, &P->tree);
    sfb__free(ctx, P->tri);
    P->tri = NULL;
}
static void fil_poly_nearest(const sfb__fil_poly *P, const double *p, int *seg, double *t, double *d2) {
    double bary[3];
    int id;
    if (!P->tri || P->tree.node_count == 0 ||
        (id = sfb__aabb_nearest(&P->tree, P->pts, P->tri, NULL, p, NULL, d2, bary)) < 0) {
        fil_polyline_nearest(P->pts, P->n, P->closed, p, seg, t, d2);
        return;
    }
    *seg = id;
    *t = 1.0 - bary[0];
    *t = *t < 0.0 ? 0.0 : *t > 1.0 ? 1.0 : *t;
}


/* ---- the conformal map (seed 5), on the direct map's boundary ----
 * The seed splits the cylinder-like region along a shortest path and maps it onto a rectangle with
 * its boundary fixed there (so the region's boundary vertices are pulled onto the linkage curves).
 * Here the region's boundary vertices (blend vertices with a neighbour outside) keep the direct
 * map's (t, a) -- they stay where they are on the sweep -- and the inside solves the cotangent
 * Laplace equation for t and a (the discrete conformal map: angle preserving, the seed's "inner
 * fairness" in one step) by preconditioned conjugate gradients. A closed spine's t is periodic:
 * instead of cutting the region, every edge carries the jump (0 or +-T) the direct map's values
 * show across it, so the equations are those of the split region, with no vertex copied; holes and
 * several boundary loops are just more boundary (seed 7's failure does not arise). When the
 * cotangent map folds a triangle (negative weights on obtuse triangles) or does not solve, the
 * symmetrised mean-value weights (positive: no fold with a convex boundary) are tried, then the
 * direct map is kept. *used gets 1 (conformal), 2 (mean value) or 0 (direct). */
static double fil_corner_angle(const double *p, const double *a, const double *b) {
    double u[3], v[3], c, lu, lv;
    fil_sub(a, p, u);
    fil_sub(b, p, v);
    lu = fil_len(u);
    lv = fil_len(v);
    if (!(lu > 0 && lv > 0)) return 0.0;
    c = fil_dot(u, v) / (lu * lv);
    return acos(c > 1 ? 1 : c < -1 ? -1 : c);
}

static sfb_result fil_harmonic(sfb__fil *F, sfb__fil_work *W, double T, int periodic, int *used) {
    sfb_context *ctx = F->ctx;
    const sfb__level *l = F->l;
    int *mv = NULL, *inner = NULL, *rowi = NULL, *coli = NULL, *full = NULL;
    double *val = NULL, *x = NULL, *b = NULL, *sol = NULL;
    int n = 0, ni = 0, nfull = 0, i, k, pass, f;
    size_t cap, nt;
    sfb_result res = SFB_SUCCESS;
    sfb__error_state kept;
    *used = 0;
    mv = (int *)sfb__alloc(ctx, ((size_t)W->nvlist + 1) * sizeof(int));
    if (!mv) { res = sfb__oom(ctx, "the conformal map"); goto done; }
    /* local ids: blend vertices; inner ones (every face around them all blend) are the unknowns */
    for (i = 0; i < W->nvlist; ++i)
        if (W->vin[W->vlist[i]] & 8) mv[n++] = W->vlist[i];
    if (n == 0) goto done;
    inner = (int *)sfb__alloc(ctx, (size_t)n * sizeof(int));
    full = (int *)sfb__alloc(ctx, ((size_t)l->nf + 1) * sizeof(int));
    if (!inner || !full) { res = sfb__oom(ctx, "the conformal map"); goto done; }
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        int ok = 1, j;
        for (j = l->vf_off[v]; j < l->vf_off[v + 1] && ok; ++j) {
            const int g = l->vf[j];
            for (k = 0; k < 3; ++k) ok &= (W->vin[F->tri[3 * g + k]] & 8) != 0;
        }
        if (l->vf_off[v + 1] == l->vf_off[v]) ok = 0;
        /* a boundary vertex of the mesh itself stays where the direct map puts it */
        for (j = l->ve_off[v]; j < l->ve_off[v + 1] && ok; ++j) ok &= l->ef_off[l->ve[j] + 1] - l->ef_off[l->ve[j]] == 2;
        inner[i] = ok ? ni++ : -1;
    }
    if (ni == 0) goto done;
    /* the faces with three blend vertices (each once: found from its smallest local vertex) */
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        int j;
        for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j) {
            const int g = l->vf[j];
            int all = 1, lowest = 1;
            for (k = 0; k < 3; ++k) {
                const int u = F->tri[3 * g + k];
                all &= (W->vin[u] & 8) != 0;
                if (u < v) lowest = 0;
            }
            if (all && lowest) full[nfull++] = g;
        }
    }
    cap = (size_t)nfull * 12 + 16;
    rowi = (int *)sfb__alloc(ctx, cap * sizeof(int));
    coli = (int *)sfb__alloc(ctx, cap * sizeof(int));
    val = (double *)sfb__alloc(ctx, cap * sizeof(double));
    x = (double *)sfb__alloc(ctx, (size_t)ni * 2 * sizeof(double));
    b = (double *)sfb__alloc(ctx, (size_t)ni * 2 * sizeof(double));
    sol = (double *)sfb__alloc(ctx, (size_t)n * 2 * sizeof(double));
    if (!rowi || !coli || !val || !x || !b || !sol) { res = sfb__oom(ctx, "the conformal map"); goto done; }
    /* a blend vertex's local index, kept in vd (the base patches are found: vd is free now; reset below) */
    for (i = 0; i < n; ++i) W->vd[mv[i]] = (double)i;
    for (pass = 1; pass <= 2 && *used == 0; ++pass) {
        sfb__sparse A;
        int fold = 0, comp, it;
        double resid, orient = 0.0;
        memset(&A, 0, sizeof A);
        nt = 0;
        for (i = 0; i < 2 * ni; ++i) b[i] = 0.0;
        /* edge weights per face corner, symmetric */
        for (k = 0; k < nfull; ++k) {
            const int g = full[k];
            int c;
            for (c = 0; c < 3; ++c) {
                const int vi = F->tri[3 * g + c], vj = F->tri[3 * g + (c + 1) % 3], vk = F->tri[3 * g + (c + 2) % 3];
                const double *pi = F->pos + 3 * (size_t)vi, *pj = F->pos + 3 * (size_t)vj, *pk = F->pos + 3 * (size_t)vk;
                const int li = (int)W->vd[vi], lj = (int)W->vd[vj];
                double w;
                if (pass == 1) { /* cot of the angle at k, for edge i-j */
                    const double ang = fil_corner_angle(pk, pi, pj), sn = sin(ang);
                    w = sn > 1e-12 ? 0.5 * cos(ang) / sn : 0.0;
                } else { /* mean value: tan(half the angle at i) / |ij| + tan(half the angle at j) / |ij|, halved */
                    const double ai = fil_corner_angle(pi, pj, pk), aj = fil_corner_angle(pj, pk, pi), len = fil_dist(pi, pj);
                    w = len > 0 ? 0.5 * (tan(0.5 * ai) + tan(0.5 * aj)) / len : 0.0;
                }
                /* row of each inner endpoint: diagonal +w, the other -w (inner) or into b (boundary) */
                for (comp = 0; comp < 2; ++comp) {
                    const int a_ = comp ? lj : li, o_ = comp ? li : lj, ia = inner[a_], io = inner[o_];
                    const int va = mv[a_], vo = mv[o_];
                    double jump;
                    if (ia < 0) continue;
                    /* t_o as seen from a: t_o + jump, the jump making the difference smallest */
                    jump = 0.0;
                    if (periodic && T > 0) {
                        const double dd = W->ta[2 * (size_t)vo] - W->ta[2 * (size_t)va];
                        jump = dd > 0.5 * T ? -T : dd < -0.5 * T ? T : 0.0;
                    }
                    rowi[nt] = ia; coli[nt] = ia; val[nt] = w; nt++;
                    if (io >= 0) { rowi[nt] = ia; coli[nt] = io; val[nt] = -w; nt++; }
                    else {
                        b[2 * (size_t)ia] += w * W->ta[2 * (size_t)vo];
                        b[2 * (size_t)ia + 1] += w * W->ta[2 * (size_t)vo + 1];
                    }
                    b[2 * (size_t)ia] += w * jump;
                }
            }
        }
        res = sfb__sparse_from_triplets(ctx, ni, (int)nt, rowi, coli, val, &A);
        if (res != SFB_SUCCESS) goto done;
        for (comp = 0; comp < 2 && !fold; ++comp) {
            double *bb = (double *)sfb__alloc(ctx, (size_t)ni * sizeof(double)), *xx = (double *)sfb__alloc(ctx, (size_t)ni * sizeof(double));
            sfb_result cr;
            if (!bb || !xx) { sfb__free(ctx, bb); sfb__free(ctx, xx); sfb__sparse_free(ctx, &A); res = sfb__oom(ctx, "the conformal map"); goto done; }
            for (i = 0; i < n; ++i)
                if (inner[i] >= 0) { bb[inner[i]] = b[2 * (size_t)inner[i] + comp]; xx[inner[i]] = W->ta[2 * (size_t)mv[i] + comp]; }
            sfb__error_keep(ctx, &kept);
            cr = sfb__sparse_cg(ctx, &A, bb, xx, 1e-10, 4 * ni + 200, &it, &resid);
            if (cr != SFB_SUCCESS) { /* not positive definite (cotangent weights) or no convergence: the next map */
                sfb__log(ctx, SFB_LOG_INFO, "fillet: the %s map's solve failed (%s); trying the next", pass == 1 ? "conformal" : "mean-value", ctx->error);
                sfb__error_put_back(ctx, &kept);
                fold = 1;
            }
            for (i = 0; i < ni; ++i) x[2 * (size_t)i + comp] = xx[i];
            sfb__free(ctx, bb);
            sfb__free(ctx, xx);
        }
        sfb__sparse_free(ctx, &A);
        if (fold) continue;
        /* the solution with the boundary's own values; folds: a face whose (t, a) orientation
         * disagrees with the direct map's prevailing one */
        for (i = 0; i < n; ++i) {
            const int q = inner[i];
            sol[2 * (size_t)i] = q >= 0 ? x[2 * (size_t)q] : W->ta[2 * (size_t)mv[i]];
            sol[2 * (size_t)i + 1] = q >= 0 ? x[2 * (size_t)q + 1] : W->ta[2 * (size_t)mv[i] + 1];
        }
        for (f = 0; f < 2 && !fold; ++f) /* f = 0: the direct map's orientation; f = 1: the solution's */
            for (k = 0; k < nfull; ++k) {
                const int g = full[k];
                double uv[3][2], ar;
                int c;
                for (c = 0; c < 3; ++c) {
                    const int li = (int)W->vd[F->tri[3 * g + c]];
                    uv[c][0] = f ? sol[2 * (size_t)li] : W->ta[2 * (size_t)mv[li]];
                    uv[c][1] = f ? sol[2 * (size_t)li + 1] : W->ta[2 * (size_t)mv[li] + 1];
                    if (periodic && T > 0 && c > 0) {
                        const double dd = uv[c][0] - uv[0][0];
                        uv[c][0] += dd > 0.5 * T ? -T : dd < -0.5 * T ? T : 0.0;
                    }
                }
                ar = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
                if (f == 0) orient += ar;
                else if (ar * orient <= 0.0) { fold = 1; break; }
            }
        if (fold) continue;
        for (i = 0; i < n; ++i) {
            W->ta[2 * (size_t)mv[i]] = sol[2 * (size_t)i];
            W->ta[2 * (size_t)mv[i] + 1] = sol[2 * (size_t)i + 1];
        }
        *used = pass;
    }
done:
    for (i = 0; i < n; ++i) W->vd[mv[i]] = -1.0;
    sfb__free(ctx, mv); sfb__free(ctx, inner); sfb__free(ctx, full);
    sfb__free(ctx, rowi); sfb__free(ctx, coli); sfb__free(ctx, val); sfb__free(ctx, x); sfb__free(ctx, b); sfb__free(ctx, sol);
    return res;
}

/* Seed 5.2's inner fairness, Laplacian optimisation in 2D (its Fig. 9): `iters` Jacobi steps
 * moving each inner region vertex's (t, a) to its neighbours' mean (uniform weights: they even
 * out the triangles' sizes, which the conformal map keeps from the input), the boundary fixed. A
 * closed spine's t is periodic: neighbours are unwrapped to the nearer copy. Kept only when no
 * region face turns over in (t, a); *done says whether it was kept.
 * Off by default (config.relax 0): measured on the box-cylinder seam (r 0.15), the smallest
 * angle of the moved triangles is 26.8 degrees after the conformal map alone and 16.7 / 12.7 /
 * 10.9 after 10 / 30 / 100 steps (the 1st percentile 27.7 -> 29.1 / 26.3 / 23.1, the median
 * unchanged): the conformal map, which keeps the input's angles, is already the fairer one here. */
static sfb_result fil_relax(sfb__fil *F, sfb__fil_work *W, double T, int periodic, int iters, int *done) {
    sfb_context *ctx = F->ctx;
    const sfb__level *l = F->l;
    int *mv = NULL, *inner = NULL, n = 0, i, j, k, it, ok = 1;
    double *cur = NULL, *nxt = NULL;
    signed char *orient = NULL;
    *done = 0;
    mv = (int *)sfb__alloc(ctx, ((size_t)W->nvlist + 1) * sizeof(int));
    if (!mv) return sfb__oom(ctx, "the 2D optimisation");
    for (i = 0; i < W->nvlist; ++i)
        if (W->vin[W->vlist[i]] & 8) mv[n++] = W->vlist[i];
    inner = (int *)sfb__alloc(ctx, ((size_t)n + 1) * sizeof(int));
    cur = (double *)sfb__alloc(ctx, ((size_t)n + 1) * 2 * sizeof(double));
    nxt = (double *)sfb__alloc(ctx, ((size_t)n + 1) * 2 * sizeof(double));
    orient = (signed char *)sfb__alloc(ctx, ((size_t)l->nf + 1));
    if (!inner || !cur || !nxt || !orient) { sfb__free(ctx, mv); sfb__free(ctx, inner); sfb__free(ctx, cur); sfb__free(ctx, nxt); sfb__free(ctx, orient); return sfb__oom(ctx, "the 2D optimisation"); }
    for (i = 0; i < n; ++i) W->vd[mv[i]] = -2.0 - i; /* local index -(vd + 2) while this runs (vd is reset below) */
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        int in_ = l->vf_off[v + 1] > l->vf_off[v];
        for (j = l->vf_off[v]; j < l->vf_off[v + 1] && in_; ++j)
            for (k = 0; k < 3; ++k) in_ &= (W->vin[F->tri[3 * l->vf[j] + k]] & 8) != 0;
        for (j = l->ve_off[v]; j < l->ve_off[v + 1] && in_; ++j) in_ &= l->ef_off[l->ve[j] + 1] - l->ef_off[l->ve[j]] == 2;
        inner[i] = in_ && !(W->vin[v] & 4) ? 1 : 0; /* the curve's own vertices stay: they carry the profile's middle */
        cur[2 * i] = W->ta[2 * (size_t)v];
        cur[2 * i + 1] = W->ta[2 * (size_t)v + 1];
    }
    /* every region face's orientation in (t, a) before */
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j) {
            const int f = l->vf[j];
            double uv[3][2], ar;
            int c, all = 1;
            for (c = 0; c < 3; ++c) all &= (W->vin[F->tri[3 * f + c]] & 8) != 0;
            if (!all) continue;
            for (c = 0; c < 3; ++c) {
                const int li = (int)(-W->vd[F->tri[3 * f + c]] - 2.0);
                uv[c][0] = cur[2 * li];
                uv[c][1] = cur[2 * li + 1];
                if (periodic && T > 0 && c > 0) uv[c][0] += uv[c][0] - uv[0][0] > 0.5 * T ? -T : uv[c][0] - uv[0][0] < -0.5 * T ? T : 0.0;
            }
            ar = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
            orient[f] = (signed char)(ar > 0 ? 1 : ar < 0 ? -1 : 0);
        }
    }
    for (it = 0; it < iters; ++it) {
        for (i = 0; i < n; ++i) {
            const int v = mv[i];
            double st = 0.0, sa = 0.0;
            int cnt = 0;
            nxt[2 * i] = cur[2 * i];
            nxt[2 * i + 1] = cur[2 * i + 1];
            if (!inner[i]) continue;
            for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                const int w = sfb__other_end(l, l->ve[j], v), lw = (int)(-W->vd[w] - 2.0);
                double t = cur[2 * lw];
                if (periodic && T > 0) t += t - cur[2 * i] > 0.5 * T ? -T : t - cur[2 * i] < -0.5 * T ? T : 0.0;
                st += t;
                sa += cur[2 * lw + 1];
                cnt++;
            }
            if (cnt) { nxt[2 * i] = st / cnt; nxt[2 * i + 1] = sa / cnt; }
        }
        { double *sw = cur; cur = nxt; nxt = sw; }
    }
    /* no face may turn over (a face that was flat may go either way) */
    for (i = 0; i < n && ok; ++i) {
        const int v = mv[i];
        for (j = l->vf_off[v]; j < l->vf_off[v + 1] && ok; ++j) {
            const int f = l->vf[j];
            double uv[3][2], ar;
            int c, all = 1;
            for (c = 0; c < 3; ++c) all &= (W->vin[F->tri[3 * f + c]] & 8) != 0;
            if (!all || orient[f] == 0) continue;
            for (c = 0; c < 3; ++c) {
                const int li = (int)(-W->vd[F->tri[3 * f + c]] - 2.0);
                uv[c][0] = cur[2 * li];
                uv[c][1] = cur[2 * li + 1];
                if (periodic && T > 0 && c > 0) uv[c][0] += uv[c][0] - uv[0][0] > 0.5 * T ? -T : uv[c][0] - uv[0][0] < -0.5 * T ? T : 0.0;
            }
            ar = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
            if (ar * orient[f] <= 0.0) ok = 0;
        }
    }
    for (i = 0; i < n; ++i) {
        const int v = mv[i];
        if (ok) {
            double t = cur[2 * i];
            if (periodic && T > 0) { t = fmod(t, T); if (t < 0) t += T; }
            W->ta[2 * (size_t)v] = t;
            W->ta[2 * (size_t)v + 1] = cur[2 * i + 1];
        }
        W->vd[v] = -1.0;
    }
    *done = ok && iters > 0;
    sfb__free(ctx, mv); sfb__free(ctx, inner); sfb__free(ctx, cur); sfb__free(ctx, nxt); sfb__free(ctx, orient);
    return SFB_SUCCESS;
}

static sfb_result fil_one(sfb__fil *F, sfb__fil_work *W, const sfb__fil_curve *cv, int ci, sfb_fillet_curve_report *rep) {
    sfb_context *ctx = F->ctx;
    const sfb__level *l = F->l;
    const double r = cv->radius;
    const int kind = cv->profile;
    const double hs = F->cfg->hermite_scale;
    const int m = cv->closed ? cv->n - 1 : cv->n; /* distinct curve points */
    double *cp = NULL, *spine = NULL, *cum = NULL, *sarc = NULL, *C = NULL, *S = NULL, *LK[2] = {NULL, NULL};
    sfb__fil_prof *prof = NULL, *ip = NULL;
    sfb__aabb tree[2];
    sfb__fil_pairs P;
    sfb__fil_poly PC, PS, PL[2];
    int *cedge = NULL, nce = 0, i, k, side, qh = 0, qt = 0, ns = 0, sclosed = 0, nsamp = 0, moved = 0, convex;
    double dmax = 0.0, d, conv = 0.0, maxdev = 0.0;
    sfb_result res = SFB_SUCCESS;
    memset(tree, 0, sizeof tree);
    memset(&P, 0, sizeof P);
    memset(&PC, 0, sizeof PC);
    memset(&PS, 0, sizeof PS);
    memset(PL, 0, sizeof PL);
    memset(rep, 0, sizeof *rep);
    rep->closed = cv->closed;
    rep->curve_vertices = m;
    rep->radius = (float)r;
    if (m < 2) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "blending curve %d has fewer than 2 vertices", ci);

    res = fil_stage(F, ci, 0, "fillet curves");
    if (res != SFB_SUCCESS) return res;
    cp = (double *)sfb__alloc(ctx, (size_t)m * 3 * sizeof(double));
    cedge = (int *)sfb__alloc(ctx, (size_t)cv->n * sizeof(int));
    if (!cp || !cedge) { res = sfb__oom(ctx, "the blending curve"); goto done; }
    for (i = 0; i < m; ++i) memcpy(cp + 3 * (size_t)i, F->pos + 3 * (size_t)cv->v[i], 3 * sizeof(double));
    for (i = 0; i + 1 < cv->n; ++i) rep->curve_length += (float)fil_dist(F->pos + 3 * (size_t)cv->v[i], F->pos + 3 * (size_t)cv->v[i + 1]);
    res = fil_poly_build(ctx, &PC, cp, m, cv->closed);
    if (res != SFB_SUCCESS) goto done;
    /* curve edges, the sides' seed faces, the sharpest dihedral angle */
    for (i = 0; i + 1 < cv->n; ++i) {
        const int a = cv->v[i], b = cv->v[i + 1], e = fil_edge_of(l, a, b);
        int f0, f1, j;
        if (e < 0 || l->ef_off[e + 1] - l->ef_off[e] != 2) continue; /* checked for callers' curves */
        cedge[nce++] = e;
        F->emark[e] = 1;
        f0 = l->ef[l->ef_off[e]];
        f1 = l->ef[l->ef_off[e] + 1];
        for (j = 0; j < 3; ++j) /* side 0 holds a -> b */
            if (F->tri[3 * f1 + j] == a && F->tri[3 * f1 + (j + 1) % 3] == b) { const int t = f0; f0 = f1; f1 = t; break; }
        if (fil_dihedral(F, e) > dmax) dmax = fil_dihedral(F, e);
        if (W->fside[f0] < 0) { W->fside[f0] = 0; W->queue[qt++] = f0; }
        if (W->fside[f1] < 0) { W->fside[f1] = 1; W->queue[qt++] = f1; }
        conv += fil_edge_conv(F, e, a, b);
    }
    convex = conv < 0.0;
    rep->convex = convex;
    d = (F->cfg->alpha > 0.0f ? F->cfg->alpha : 1.75) * fil_reach(r, dmax);
    if (!(d <= F->scale)) {
        /* base patches reaching past the whole mesh: every face would be one, the offsets lie a
         * radius away from everything, and no check below could tell (they scale with r) */
        res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, cv->v[0],
                         "blending curve %d (from vertex %d): radius %g is too large for this mesh: its base patches would reach %g from "
                         "the curve, beyond the mesh's size (bounding-box diagonal %g), and the offset patches do not meet within it",
                         ci, cv->v[0], r, d, F->scale);
        goto done;
    }

    /* base patches: both sides grow breadth first together through faces within d */
    while (qh < qt) {
        const int f = W->queue[qh++];
        for (k = 0; k < 3; ++k) {
            const int e = l->fe[l->fv_off[f] + k];
            int j;
            if (F->emark[e] || F->fmark[e]) continue;
            for (j = l->ef_off[e]; j < l->ef_off[e + 1]; ++j) {
                const int g = l->ef[j];
                int c, near_ = 0;
                if (W->fside[g] >= 0) continue;
                for (c = 0; c < 3; ++c) {
                    const int v = F->tri[3 * g + c];
                    if (W->vd[v] < 0) {
                        {
                            int sg;
                            double tt, dd;
                            fil_poly_nearest(&PC, F->pos + 3 * (size_t)v, &sg, &tt, &dd);
                            W->vd[v] = sqrt(dd);
                        }
                        W->vdlist[W->nvd++] = v;
                    }
                    if (W->vd[v] < d) near_ = 1;
                }
                if (!near_) continue;
                W->fside[g] = W->fside[f];
                W->queue[qt++] = g;
            }
        }
    }
    /* per side: rows, vertex normals (angle weighted over that side's faces), offsets */
    for (side = 0; side < 2; ++side) {
        W->rows[side] = (int *)sfb__alloc(ctx, ((size_t)qt + 1) * 3 * sizeof(int));
        if (!W->rows[side]) { res = sfb__oom(ctx, "the base patches"); goto done; }
        W->nrows[side] = 0;
    }
    for (i = 0; i < qt; ++i) {
        const int f = W->queue[i], s = W->fside[f];
        int c;
        memcpy(W->rows[s] + 3 * (size_t)W->nrows[s], F->tri + 3 * (size_t)f, 3 * sizeof(int));
        W->nrows[s]++;
        for (c = 0; c < 3; ++c) {
            const int v = F->tri[3 * f + c];
            const double *p = F->pos + 3 * (size_t)v, *pa = F->pos + 3 * (size_t)F->tri[3 * f + (c + 1) % 3],
                         *pb = F->pos + 3 * (size_t)F->tri[3 * f + (c + 2) % 3];
            double ea[3], eb[3], la, lb, cang, ang;
            fil_sub(pa, p, ea); fil_sub(pb, p, eb);
            la = fil_len(ea); lb = fil_len(eb);
            cang = (la > 0 && lb > 0) ? fil_dot(ea, eb) / (la * lb) : 1.0;
            ang = acos(cang > 1 ? 1 : cang < -1 ? -1 : cang);
            if (!W->vin[v]) W->vlist[W->nvlist++] = v;
            W->vin[v] |= (unsigned char)(1 << s);
            W->nrm[s][3 * (size_t)v] += ang * F->fn[3 * (size_t)f];
            W->nrm[s][3 * (size_t)v + 1] += ang * F->fn[3 * (size_t)f + 1];
            W->nrm[s][3 * (size_t)v + 2] += ang * F->fn[3 * (size_t)f + 2];
        }
    }
    for (i = 0; i < cv->n; ++i) W->vin[cv->v[i]] |= 4;
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        for (side = 0; side < 2; ++side) {
            double *n = W->nrm[side] + 3 * (size_t)v, ln = fil_len(n), *o = W->op[side] + 3 * (size_t)v;
            const double sg = convex ? -r : r;
            if (ln > 0) { n[0] /= ln; n[1] /= ln; n[2] /= ln; }
            for (k = 0; k < 3; ++k) o[k] = F->pos[3 * (size_t)v + k] + sg * n[k];
        }
    }

    /* CSC: the offset patches' intersection */
    res = fil_stage(F, ci, 1, "fillet spine");
    if (res != SFB_SUCCESS) goto done;
    for (side = 0; side < 2; ++side) {
        res = sfb__aabb_build(ctx, W->op[side], W->rows[side], NULL, W->nrows[side], &tree[side]);
        if (res != SFB_SUCCESS) goto done;
    }
    P.F = F;
    P.op0 = W->op[0]; P.op1 = W->op[1];
    P.t0 = W->rows[0]; P.t1 = W->rows[1];
    sfb__aabb_pairs(&tree[0], &tree[1], 1e-9 * F->scale, fil_pair_cb, &P);
    if (P.failed) { res = sfb__oom(ctx, "the offset patches' intersection"); goto done; }
    res = fil_chain(ctx, P.segs, P.n, 1e-8 * (F->scale + r), cv->closed, &spine, &ns, &sclosed);
    if (res != SFB_SUCCESS) goto done;
    if (ns < 2) {
        res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, cv->v[0],
                         "blending curve %d (from vertex %d): the offset patches at radius %g do not meet -- the radius is too large "
                         "for the base patches (faces within %g of the curve) or the feature is too flat", ci, cv->v[0], r, d);
        goto done;
    }
    if (!cv->closed && !sclosed) {
        /* orient the spine like the curve, then clip it to the planes through the curve's ends */
        double t0[3], t1[3], a[3], b[3];
        int lo = 0, hi = ns - 1;
        fil_sub(spine + 3 * (size_t)(ns - 1), spine, a);
        fil_sub(cp + 3 * (size_t)(m - 1), cp, b);
        if (fil_dot(a, b) < 0)
            for (i = 0; i < ns / 2; ++i)
                for (k = 0; k < 3; ++k) {
                    const double t = spine[3 * (size_t)i + k];
                    spine[3 * (size_t)i + k] = spine[3 * (size_t)(ns - 1 - i) + k];
                    spine[3 * (size_t)(ns - 1 - i) + k] = t;
                }
        /* the end planes: through the curve's end point, or through the corner ball's centre where
         * the end is at a corner (the sweep stops where the ball starts touching the third face) */
        double jp[2][3];
        const double *pl0 = cv->corner[0] >= 0 ? F->corners[cv->corner[0]].C : cp;
        const double *pl1 = cv->corner[1] >= 0 ? F->corners[cv->corner[1]].C : cp + 3 * (size_t)(m - 1);
        /* ... or `setback` before another junction (at most 0.45 of the curve's length) */
        for (k = 0; k < 2; ++k)
            if (cv->setback[k] > 0.0) {
                const double *e = k ? cp + 3 * (size_t)(m - 1) : cp, *e2 = k ? cp + 3 * (size_t)(m - 2) : cp + 3;
                const double sb = cv->setback[k] < 0.45 * rep->curve_length ? cv->setback[k] : 0.45 * rep->curve_length;
                double u[3], lu;
                fil_sub(e2, e, u);
                lu = fil_len(u);
                for (i = 0; i < 3; ++i) jp[k][i] = e[i] + (lu > 0 ? sb * u[i] / lu : 0.0);
                if (k) pl1 = jp[1]; else pl0 = jp[0];
            }
        fil_sub(cp + 3, cp, t0);                                              /* into the curve at its start */
        fil_sub(cp + 3 * (size_t)(m - 1), cp + 3 * (size_t)(m - 2), t1);       /* out of it at its end */
        while (lo < ns - 1) {
            fil_sub(spine + 3 * (size_t)(lo + 1), pl0, a);
            if (fil_dot(a, t0) > 0) break;
            lo++;
        }
        while (hi > lo) {
            fil_sub(spine + 3 * (size_t)(hi - 1), pl1, a);
            if (fil_dot(a, t1) < 0) break;
            hi--;
        }
        /* points lo and hi may lie beyond the planes: move them onto them */
        if (hi > lo) {
            double da, db;
            fil_sub(spine + 3 * (size_t)lo, pl0, a); da = fil_dot(a, t0);
            fil_sub(spine + 3 * (size_t)(lo + 1), pl0, b); db = fil_dot(b, t0);
            if (da < 0 && db > da) fil_lerp(spine + 3 * (size_t)lo, spine + 3 * (size_t)(lo + 1), da / (da - db), spine + 3 * (size_t)lo);
            fil_sub(spine + 3 * (size_t)hi, pl1, a); da = fil_dot(a, t1);
            fil_sub(spine + 3 * (size_t)(hi - 1), pl1, b); db = fil_dot(b, t1);
            if (da > 0 && db < da) fil_lerp(spine + 3 * (size_t)hi, spine + 3 * (size_t)(hi - 1), da / (da - db), spine + 3 * (size_t)hi);
            memmove(spine, spine + 3 * (size_t)lo, (size_t)(hi - lo + 1) * 3 * sizeof(double));
            ns = hi - lo + 1;
        }
    }
    {
        /* spine loops (seed 4.3): pieces closer than 1.5 mean spine steps (at most r/10) while apart
         * along the spine by more than r/2 */
        double mean = 0.0, tol;
        for (i = 0; i + 1 < ns; ++i) mean += fil_dist(spine + 3 * (size_t)i, spine + 3 * (size_t)(i + 1));
        mean /= (ns > 1 ? ns - 1 : 1);
        tol = 1.5 * mean < 0.1 * r ? 1.5 * mean : 0.1 * r;
        rep->self_intersections = fil_spine_untangle(ctx, &spine, &ns, sclosed, tol, 0.25 * r);
    }
    {
        /* the spine must follow the curve: the ball's centre lies r / cos(delta / 2) from it, within
         * d. On real meshes the offsets' intersection can run off along another branch near a
         * curve's end (spot.obj's short creases: a curve vertex moved 14 r). An open spine keeps its
         * longest run of points within 1.5 d of the curve; a closed one that strays fails. */
        int best_lo = 0, best_n = 0, run_lo = 0, run_n = 0, bad = 0;
        for (i = 0; i < ns; ++i) {
            int sg;
            double tt, dd;
            fil_poly_nearest(&PC, spine + 3 * (size_t)i, &sg, &tt, &dd);
            if (sqrt(dd) <= 1.5 * d) {
                if (run_n == 0) run_lo = i;
                if (++run_n > best_n) { best_n = run_n; best_lo = run_lo; }
            } else { run_n = 0; bad++; }
        }
        if (bad && (sclosed || best_n < 2)) {
            res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, cv->v[0],
                             "blending curve %d (from vertex %d): the offset patches at radius %g meet away from the curve (%d of %d spine points "
                             "farther than %g from it) -- the surface around the curve is too uneven for this radius",
                             ci, cv->v[0], r, bad, ns, 1.5 * d);
            goto done;
        }
        if (bad) {
            memmove(spine, spine + 3 * (size_t)best_lo, (size_t)best_n * 3 * sizeof(double));
            ns = best_n;
        }
    }
    cum = (double *)sfb__alloc(ctx, ((size_t)ns + 1) * sizeof(double));
    if (!cum) { res = sfb__oom(ctx, "the spine"); goto done; }
    cum[0] = 0.0;
    for (i = 1; i <= ns; ++i)
        cum[i] = cum[i - 1] + (i < ns ? fil_dist(spine + 3 * (size_t)(i - 1), spine + 3 * (size_t)i)
                                      : (sclosed ? fil_dist(spine + 3 * (size_t)(ns - 1), spine) : 0.0));
    rep->spine_length = (float)cum[sclosed ? ns : ns - 1];

    /* virtual surface: samples and their profiles */
    res = fil_stage(F, ci, 2, "fillet surface");
    if (res != SFB_SUCCESS) goto done;
    res = fil_sample(ctx, spine, cum, ns, sclosed, F->cfg->samples > 0 ? F->cfg->samples : 40,
                     F->cfg->chord_ratio > 0.0f ? F->cfg->chord_ratio : 0.002, &sarc, &nsamp);
    if (res != SFB_SUCCESS) goto done;
    rep->samples = nsamp;
    C = (double *)sfb__alloc(ctx, (size_t)nsamp * 3 * sizeof(double));
    prof = (sfb__fil_prof *)sfb__alloc(ctx, (size_t)nsamp * sizeof *prof);
    if (!C || !prof) { res = sfb__oom(ctx, "the sweep's profiles"); goto done; }
    for (i = 0; i < nsamp; ++i) {
        double link[2][3], E[3], bary[3];
        fil_point_at(spine, cum, ns, sclosed, sarc[i], C + 3 * (size_t)i);
        for (side = 0; side < 2; ++side) {
            const int row = sfb__aabb_nearest(&tree[side], W->op[side], W->rows[side], NULL, C + 3 * (size_t)i, NULL, NULL, bary);
            const int *t = W->rows[side] + 3 * (size_t)(row < 0 ? 0 : row);
            for (k = 0; k < 3; ++k)
                link[side][k] = bary[0] * F->pos[3 * (size_t)t[0] + k] + bary[1] * F->pos[3 * (size_t)t[1] + k] +
                                bary[2] * F->pos[3 * (size_t)t[2] + k];
        }
        {
            int sg;
            double tt, dd;
            fil_poly_nearest(&PC, C + 3 * (size_t)i, &sg, &tt, &dd);
            fil_lerp(cp + 3 * (size_t)sg, cp + 3 * (size_t)((sg + 1) % m), tt, E);
        }
        fil_prof_build(&prof[i], C + 3 * (size_t)i, link[0], link[1], E, kind, cv->conic_w, hs);
    }

    /* map: every base-patch vertex between the linkage curves gets (t, a): t the arc length of its
     * nearest point on the samples' polyline, a its place across */
    res = fil_stage(F, ci, 3, "fillet map");
    if (res != SFB_SUCCESS) goto done;
    ip = (sfb__fil_prof *)sfb__alloc(ctx, sizeof *ip);
    S = (double *)sfb__alloc(ctx, ((size_t)nsamp + 1) * sizeof(double));
    LK[0] = (double *)sfb__alloc(ctx, (size_t)nsamp * 3 * sizeof(double));
    LK[1] = (double *)sfb__alloc(ctx, (size_t)nsamp * 3 * sizeof(double));
    if (!ip || !S || !LK[0] || !LK[1]) { res = sfb__oom(ctx, "the sweep's profiles"); goto done; }
    for (i = 0; i < nsamp; ++i) {
        memcpy(LK[0] + 3 * (size_t)i, prof[i].P1, 3 * sizeof(double));
        memcpy(LK[1] + 3 * (size_t)i, prof[i].P2, 3 * sizeof(double));
    }
    if ((res = fil_poly_build(ctx, &PS, C, nsamp, sclosed)) != SFB_SUCCESS || (res = fil_poly_build(ctx, &PL[0], LK[0], nsamp, sclosed)) != SFB_SUCCESS ||
        (res = fil_poly_build(ctx, &PL[1], LK[1], nsamp, sclosed)) != SFB_SUCCESS)
        goto done;
    S[0] = 0.0;
    for (i = 1; i <= nsamp; ++i)
        S[i] = S[i - 1] + (i < nsamp ? fil_dist(C + 3 * (size_t)(i - 1), C + 3 * (size_t)i) : sclosed ? fil_dist(C + 3 * (size_t)(nsamp - 1), C) : 0.0);
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        const double *p = F->pos + 3 * (size_t)v;
        int seg, j, vs = 0;
        double t, d2, E[3], L1, L2, s;
        fil_poly_nearest(&PS, p, &seg, &t, &d2);
        j = (seg + 1) % nsamp;
        if (!sclosed && ((seg == 0 && t <= 0.0) || (seg == nsamp - 2 && t >= 1.0))) {
            /* beyond an end of an open spine: outside unless on the end plane */
            const int e = seg == 0 && t <= 0.0 ? 0 : nsamp - 1, e2 = e == 0 ? 1 : nsamp - 2;
            double out[3], dv[3];
            fil_sub(C + 3 * (size_t)e, C + 3 * (size_t)e2, out);
            fil_sub(p, C + 3 * (size_t)e, dv);
            if (fil_dot(dv, out) > 1e-9 * fil_len(out) * (F->scale + r)) continue;
        }
        if (!(W->vin[v] & 4)) {
            /* t off the curve: the nearest point on the vertex's own side's linkage polyline, not
             * on the spine. Both agree where the sweep is a plain tube; where the spine was cut and
             * bridged (a reflex corner, seed 4.3) the profile planes there are not the spine's
             * normal planes, and the vertices near the linkage curve -- the region's boundary,
             * which the conformal map keeps -- find their own profile only this way. */
            int sg0, sg1;
            double t0, t1, e0, e1;
            fil_poly_nearest(&PL[0], p, &sg0, &t0, &e0);
            fil_poly_nearest(&PL[1], p, &sg1, &t1, &e1);
            vs = (W->vin[v] & 1) ? 0 : 1;
            if ((W->vin[v] & 3) == 3) vs = e0 <= e1 ? 0 : 1; /* both sides (around an open chain's end): the nearer */
            seg = vs == 0 ? sg0 : sg1;
            t = vs == 0 ? t0 : t1;
            j = (seg + 1) % nsamp;
        }
        fil_lerp(prof[seg].E, prof[j].E, t, E);
        L1 = prof[seg].L1 + t * (prof[j].L1 - prof[seg].L1);
        L2 = prof[seg].L2 + t * (prof[j].L2 - prof[seg].L2);
        if (!(L1 + L2 > 0)) continue;
        if (W->vd[v] < 0) { /* its distance to the curve, if the base patches' search did not need it */
            int sg;
            double tt, dd;
            fil_poly_nearest(&PC, p, &sg, &tt, &dd);
            W->vd[v] = sqrt(dd);
            W->vdlist[W->nvd++] = v;
        }
        /* a base-patch face's far corner (the patches take whole faces) is no region vertex */
        if (W->vd[v] > d) continue;
        if (W->vin[v] & 4) { s = 0.0; vs = 0; }
        else {
            /* s: how far the vertex lies past its side's linkage point toward the curve, measured
             * along the line from the one to the other. Inside the region when s > 0. (The distance
             * to the curve's foot E, used before, decides differently for neighbouring vertices
             * where the spine turns sharply -- a reflex corner of the seam, where the ball sits in
             * the corner and the vertices behind it have no profile plane of their own -- and left
             * single vertices out, stretching triangles across the corner.) */
            double l0[3], l1[3], lk[3], u[3], dv[3], lu;
            fil_lerp(prof[seg].P1, prof[j].P1, t, l0);
            fil_lerp(prof[seg].P2, prof[j].P2, t, l1);
            memcpy(lk, vs == 0 ? l0 : l1, sizeof lk);
            fil_sub(E, lk, u);
            lu = fil_len(u);
            if (!(lu > 0)) continue;
            fil_sub(p, lk, dv);
            s = fil_dot(dv, u) / lu;
            if (s <= 0.0) continue;
            s = (vs == 0 ? L1 : L2) - (s < lu ? s : lu) * (vs == 0 ? L1 : L2) / lu; /* as a distance from the curve */
        }
        W->ta[2 * (size_t)v] = S[seg] + t * (S[seg + 1] - S[seg]);
        W->ta[2 * (size_t)v + 1] = vs == 0 ? (L1 - s) / (L1 + L2) : (L1 + s) / (L1 + L2);
        W->vin[v] |= 8;
        moved++;
    }
    rep->map = 0;
    if (F->cfg->map == SFB_FILLET_MAP_CONFORMAL) {
        res = fil_harmonic(F, W, S[sclosed ? nsamp : nsamp - 1], sclosed, &rep->map);
        if (res != SFB_SUCCESS) goto done;
        if (F->cfg->relax > 0) {
            res = fil_relax(F, W, S[sclosed ? nsamp : nsamp - 1], sclosed, F->cfg->relax, &rep->relaxed);
            if (res != SFB_SUCCESS) goto done;
        }
    }

    /* project: (t, a) onto the ruled surface between the two profiles around t */
    res = fil_stage(F, ci, 4, "fillet project");
    if (res != SFB_SUCCESS) goto done;
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        const double T = S[sclosed ? nsamp : nsamp - 1];
        double t = W->ta[2 * (size_t)v], a = W->ta[2 * (size_t)v + 1], th, qa[3], qb[3], np_[3], Ct[3], P1t[3], P2t[3], Et[3], dev;
        int lo = 0, hi = sclosed ? nsamp : nsamp - 1, j;
        if (!(W->vin[v] & 8)) continue;
        if (sclosed) { t = fmod(t, T); if (t < 0) t += T; }
        else t = t < 0 ? 0 : t > T ? T : t;
        a = a < 0 ? 0 : a > 1 ? 1 : a;
        while (hi - lo > 1) {
            const int mid = (lo + hi) / 2;
            if (S[mid] <= t) lo = mid; else hi = mid;
        }
        j = (lo + 1) % nsamp;
        th = S[lo + 1] > S[lo] ? (t - S[lo]) / (S[lo + 1] - S[lo]) : 0.0;
        th = th < 0 ? 0 : th > 1 ? 1 : th;
        fil_prof_at(&prof[lo], kind, hs, a, qa);
        fil_prof_at(&prof[j], kind, hs, a, qb);
        fil_lerp(qa, qb, th, np_);
        if (fil_dist(np_, F->pos + 3 * (size_t)v) > 2.0 * d) { /* no profile near it: it stays (counted) */
            W->vin[v] &= (unsigned char)~8u;
            moved--;
            rep->vertices_kept++;
            continue;
        }
        memcpy(F->npos + 3 * (size_t)v, np_, sizeof np_);
        /* the ideal surface here: the profile built from the interpolated spine and linkage points */
        fil_lerp(prof[lo].C, prof[j].C, th, Ct);
        fil_lerp(prof[lo].P1, prof[j].P1, th, P1t);
        fil_lerp(prof[lo].P2, prof[j].P2, th, P2t);
        fil_lerp(prof[lo].E, prof[j].E, th, Et);
        fil_prof_build(ip, Ct, P1t, P2t, Et, kind, cv->conic_w, hs);
        if (kind == SFB_FILLET_ARC) ip->r = r; /* the ideal arc has the ball's radius */
        dev = fil_prof_distance(ip, kind, hs, np_);
        if (dev > maxdev) maxdev = dev;
    }
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        if (W->vin[v] & 8) memcpy(F->opos + 3 * (size_t)v, F->npos + 3 * (size_t)v, 3 * sizeof(double));
    }
    rep->vertices_moved = moved;
    rep->max_deviation = (float)maxdev;
done:
    /* reset the work arrays for the next curve */
    for (i = 0; i < qt; ++i) W->fside[W->queue[i]] = -1;
    for (i = 0; i < W->nvlist; ++i) {
        const int v = W->vlist[i];
        int c;
        W->vin[v] = 0;
        for (c = 0; c < 3; ++c) W->nrm[0][3 * (size_t)v + c] = W->nrm[1][3 * (size_t)v + c] = 0.0;
    }
    for (i = 0; i < cv->n; ++i) W->vin[cv->v[i]] = 0;
    W->nvlist = 0;
    for (i = 0; i < W->nvd; ++i) W->vd[W->vdlist[i]] = -1.0;
    W->nvd = 0;
    for (i = 0; i < nce; ++i) F->emark[cedge[i]] = 0;
    for (side = 0; side < 2; ++side) {
        sfb__aabb_free(ctx, &tree[side]);
        sfb__free(ctx, W->rows[side]);
        W->rows[side] = NULL;
    }
    sfb__free(ctx, P.segs);
    sfb__free(ctx, cp); sfb__free(ctx, cedge); sfb__free(ctx, spine); sfb__free(ctx, cum);
    sfb__free(ctx, sarc); sfb__free(ctx, C); sfb__free(ctx, prof); sfb__free(ctx, ip); sfb__free(ctx, S);
    sfb__free(ctx, LK[0]); sfb__free(ctx, LK[1]);
    fil_poly_free(ctx, &PC); fil_poly_free(ctx, &PS); fil_poly_free(ctx, &PL[0]); fil_poly_free(ctx, &PL[1]);
    return res;
}

/* ---- the API ---- */
SFB_API sfb_fillet_config sfb_fillet_config_init(float radius) {
    sfb_fillet_config c;
    memset(&c, 0, sizeof c);
    c.radius = radius;
    return c;
}

SFB_API void sfb_fillet_report_free(sfb_fillet_report *report) {
    if (!report) return;
    if (report->ctx_) sfb__free(report->ctx_, report->curves);
    memset(report, 0, sizeof *report);
}

static sfb_result fil_check(sfb_context *ctx, const sfb_mesh *mesh, const sfb_fillet_config *c) {
    const sfb__level *l = &mesh->base;
    int f, e;
    if (!(c->radius > 0.0f) || !isfinite(c->radius))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "fillet radius %g is not a positive number", (double)c->radius);
    if (!(c->angle >= 0.0f && c->angle < 180.0f))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "feature angle %g is not a number of degrees in [0, 180)", (double)c->angle);
    if (c->profile < 0 || c->profile > SFB_FILLET_HERMITE)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "unknown fillet profile %d", c->profile);
    if (!(c->conic_weight >= 0.0f) || !isfinite(c->conic_weight))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "conic weight %g is not a number >= 0", (double)c->conic_weight);
    if (!(c->hermite_scale >= 0.0f && c->hermite_scale <= 10.0f))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "Hermite scale %g is not in [0, 10] (tangent length over the chord)",
                          (double)c->hermite_scale);
    if (!(c->alpha == 0.0f || (c->alpha >= 1.0f && c->alpha <= 100.0f)))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "base patch factor alpha %g is not 0 or in [1, 100]", (double)c->alpha);
    if (c->samples < 0 || c->samples == 1 || c->samples > 100000)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "spine samples %d is not 0 or in [2, 100000]", c->samples);
    if (!(c->chord_ratio >= 0.0f && c->chord_ratio < 1.0f))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "chord ratio %g is not in [0, 1)", (double)c->chord_ratio);
    if (c->map != SFB_FILLET_MAP_CONFORMAL && c->map != SFB_FILLET_MAP_DIRECT)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "unknown fillet map %d", c->map);
    if (c->curve_count < 0 || (c->curve_count > 0 && !c->curves))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "curve_count %d with %s curves", c->curve_count, c->curves ? "its" : "no");
    if (l->nf == 0) return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_NONE, -1, "the mesh has no faces");
    for (f = 0; f < l->nf; ++f)
        if (l->fv_off[f + 1] - l->fv_off[f] != 3)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "it has %d vertices: fillets need a triangle mesh",
                              l->fv_off[f + 1] - l->fv_off[f]);
    for (e = 0; e < l->ne; ++e)
        if (l->ef_off[e + 1] - l->ef_off[e] > 2)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, e, "edge %d (vertices %d-%d) has %d faces: the mesh is not manifold", e,
                              l->ev[2 * e], l->ev[2 * e + 1], l->ef_off[e + 1] - l->ef_off[e]);
    {
        sfb_mesh_info info;
        sfb_mesh_get_info(mesh, &info);
        if (info.nonmanifold_vertices > 0) {
            int v, first = -1;
            for (v = 0; v < l->nv && first < 0; ++v)
                if ((l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v]) first = v;
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, first,
                              "the mesh has %d non-manifold vertices (where separate fans of faces meet; this is the first): "
                              "fillets need a manifold mesh", info.nonmanifold_vertices);
        }
    }
    for (e = 0; e < 3 * l->nv; ++e)
        if (!isfinite(mesh->positions[e]))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, e / 3, "vertex %d is not finite", e / 3);
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_mesh_fillet(sfb_context *ctx, const sfb_mesh *mesh, const sfb_fillet_config *config, sfb_mesh **out,
                                   sfb_fillet_report *report) {
    sfb__fil F;
    sfb__fil_work W;
    sfb_fillet_curve_report *reps = NULL;
    float *fpos = NULL;
    int *cvert = NULL, i, nc = 0, nskip = 0;
    float *csharp = NULL;
    sfb_result res;
    sfb__error_state kept;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, need;
    if (out) *out = NULL;
    if (report) memset(report, 0, sizeof *report);
    if (!ctx || !mesh || !config || !out) return ctx ? sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_mesh_fillet: NULL argument") : SFB_INVALID_ARGS;
    res = fil_check(ctx, mesh, config);
    if (res != SFB_SUCCESS) return res;
    memset(&F, 0, sizeof F);
    memset(&W, 0, sizeof W);
    F.ctx = ctx;
    F.cfg = config;
    F.l = &mesh->base;
    F.nv = mesh->base.nv;
    F.nf = mesh->base.nf;
    F.tri = mesh->base.fv;
    /* the memory budget, before the work: per vertex 11 doubles x 3 and some ints, per face a few */
    need = (double)F.nv * (13.0 * 3 * sizeof(double) + 4 * sizeof(int) + 2) + (double)F.nf * (3 * sizeof(double) + 12 * sizeof(int)) +
           (double)mesh->base.ne;
    if (need > (double)ctx->budget - (double)ctx->live_bytes)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "filleting a mesh of %d vertices and %d faces needs about %.0f MB, over the memory budget (%zu bytes, %zu in use)",
                          F.nv, F.nf, need / 1048576.0, ctx->budget, ctx->live_bytes);
    F.pos = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(double));
    F.npos = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(double));
    F.opos = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(double));
    F.fmark = (unsigned char *)sfb__calloc(ctx, (size_t)mesh->base.ne + 1, 1);
    F.fn = (double *)sfb__alloc(ctx, ((size_t)F.nf + 1) * 3 * sizeof(double));
    F.emark = (unsigned char *)sfb__calloc(ctx, (size_t)mesh->base.ne + 1, 1);
    W.fside = (int *)sfb__alloc(ctx, ((size_t)F.nf + 1) * sizeof(int));
    W.queue = (int *)sfb__alloc(ctx, ((size_t)F.nf + 1) * sizeof(int));
    W.vd = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * sizeof(double));
    W.vdlist = (int *)sfb__alloc(ctx, ((size_t)F.nv + 1) * sizeof(int));
    W.vlist = (int *)sfb__alloc(ctx, ((size_t)F.nv + 1) * sizeof(int));
    W.vin = (unsigned char *)sfb__calloc(ctx, (size_t)F.nv + 1, 1);
    W.ta = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 2 * sizeof(double));
    for (i = 0; i < 2; ++i) {
        W.nrm[i] = (double *)sfb__calloc(ctx, ((size_t)F.nv + 1) * 3, sizeof(double));
        W.op[i] = (double *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(double));
    }
    if (!F.pos || !F.npos || !F.opos || !F.fmark || !F.fn || !F.emark || !W.fside || !W.queue || !W.vd || !W.vdlist || !W.vlist || !W.vin || !W.ta || !W.nrm[0] ||
        !W.nrm[1] || !W.op[0] || !W.op[1]) {
        res = sfb__oom(ctx, "the fillet's work arrays");
        goto done;
    }
    for (i = 0; i < 3 * F.nv; ++i) {
        F.pos[i] = F.opos[i] = mesh->positions[i];
        if (F.pos[i] < lo[i % 3]) lo[i % 3] = F.pos[i];
        if (F.pos[i] > hi[i % 3]) hi[i % 3] = F.pos[i];
    }
    F.scale = F.nv ? sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2])) : 1.0;
    for (i = 0; i < F.nf; ++i) W.fside[i] = -1;
    for (i = 0; i < F.nv; ++i) W.vd[i] = -1.0;
    fil_face_normals(&F);
    res = config->curves ? fil_curves_from_caller(&F) : fil_curves_from_angle(&F);
    if (res != SFB_SUCCESS) goto done;
    reps = (sfb_fillet_curve_report *)sfb__calloc(ctx, (size_t)F.ncurves + 1, sizeof *reps);
    if (!reps) { res = sfb__oom(ctx, "the fillet report"); goto done; }
    res = fil_find_corners(&F);
    if (res != SFB_SUCCESS) goto done;
    /* every curve on the input's positions (each writes its own region into opos; the regions of
     * curves that meet at a corner end at the corner's planes, so they do not overlap) */
    sfb__error_keep(ctx, &kept);
    for (i = 0; i < F.ncurves; ++i) {
        res = fil_one(&F, &W, &F.curves[i], i, &reps[i]);
        if (res == SFB_INVALID_VALUE && config->skip_failed) {
            /* this curve cannot be filleted with this radius (fil_one wrote nothing): left sharp, said */
            reps[i].skipped = 1;
            nskip++;
            /* the reason goes to the logger; the caller's last error is put back (the call succeeds) */
            sfb__log(ctx, SFB_LOG_WARN, "fillet: curve %d left sharp (skip_failed): %s", i, ctx->error);
            sfb__error_put_back(ctx, &kept);
            res = SFB_SUCCESS;
            continue;
        }
        if (res != SFB_SUCCESS) goto done;
    }
    if (nskip == F.ncurves) {
        res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                         "none of the %d blending curves could be filleted: radius %g is too large for the base patches or for the "
                         "surface around the curves (the offset patches do not meet, or meet away from the curves)", F.ncurves,
                         (double)config->radius);
        goto done;
    }
    res = fil_corners_project(&F, reps);
    if (res == SFB_SUCCESS) res = fil_junctions_fill(&F);
    if (res != SFB_SUCCESS) goto done;
    res = sfb__progress(ctx, 1.0f, "fillet project");
    if (res != SFB_SUCCESS) goto done;
    {
        /* the output: the input's arrays with the new positions; filleted edges lose their crease tags */
        sfb_mesh_desc d;
        int c;
        sfb_mesh_get_desc(mesh, &d);
        fpos = (float *)sfb__alloc(ctx, ((size_t)F.nv + 1) * 3 * sizeof(float));
        cvert = (int *)sfb__alloc(ctx, ((size_t)d.crease_count + 1) * 2 * sizeof(int));
        csharp = (float *)sfb__alloc(ctx, ((size_t)d.crease_count + 1) * sizeof(float));
        if (!fpos || !cvert || !csharp) { res = sfb__oom(ctx, "the filleted mesh"); goto done; }
        for (i = 0; i < 3 * F.nv; ++i) fpos[i] = (float)F.opos[i];
        for (c = 0; c < F.ncurves; ++c)
            for (i = 0; i + 1 < F.curves[c].n && !reps[c].skipped; ++i) {
                const int e = fil_edge_of(F.l, F.curves[c].v[i], F.curves[c].v[i + 1]);
                if (e >= 0) F.emark[e] = 1;
            }
        for (i = 0; i < d.crease_count; ++i) {
            const int e = fil_edge_of(F.l, d.crease_vertices[2 * i], d.crease_vertices[2 * i + 1]);
            if (e >= 0 && F.emark[e]) continue;
            cvert[2 * nc] = d.crease_vertices[2 * i];
            cvert[2 * nc + 1] = d.crease_vertices[2 * i + 1];
            csharp[nc++] = d.crease_sharpness[i];
        }
        d.positions = fpos;
        d.crease_count = nc;
        d.crease_vertices = cvert;
        d.crease_sharpness = csharp;
        res = sfb_mesh_create(ctx, &d, out);
        if (res != SFB_SUCCESS) goto done;
    }
    if (report) {
        report->curve_count = F.ncurves;
        report->curves = reps;
        report->ctx_ = ctx;
        for (i = 0; i < F.ncurves; ++i) report->vertices_moved += reps[i].vertices_moved;
        report->curves_skipped = nskip;
        for (i = 0; i < F.ncorners; ++i) report->corner_count += F.corners[i].moved > 0;
        /* faces the fillet turned over (normal more than 90 degrees from the input's): a radius too
         * large for the surface around a curve; said, not refused (the caller decides) */
        for (i = 0; i < F.nf; ++i) {
            const int *t = F.tri + 3 * (size_t)i;
            double u[3], w[3], n[3];
            fil_sub(F.opos + 3 * (size_t)t[1], F.opos + 3 * (size_t)t[0], u);
            fil_sub(F.opos + 3 * (size_t)t[2], F.opos + 3 * (size_t)t[0], w);
            fil_cross(u, w, n);
            if (fil_dot(n, F.fn + 3 * (size_t)i) < 0.0) report->faces_folded++;
        }
        for (i = 0; i < F.ncorners; ++i) report->corner_vertices_moved += F.corners[i].moved;
        report->vertices_moved += report->corner_vertices_moved;
        reps = NULL;
    }
done:
    if (res != SFB_SUCCESS && out && *out) { sfb_mesh_destroy(*out); *out = NULL; }
    for (i = 0; i < F.ncurves; ++i) sfb__free(ctx, F.curves[i].v);
    sfb__free(ctx, F.curves);
    sfb__free(ctx, reps);
    sfb__free(ctx, F.pos); sfb__free(ctx, F.npos); sfb__free(ctx, F.fn); sfb__free(ctx, F.emark);
    sfb__free(ctx, F.opos); sfb__free(ctx, F.fmark); sfb__free(ctx, F.corners); sfb__free(ctx, F.junctions);
    sfb__free(ctx, W.fside); sfb__free(ctx, W.queue); sfb__free(ctx, W.vd); sfb__free(ctx, W.vdlist);
    sfb__free(ctx, W.vlist); sfb__free(ctx, W.vin); sfb__free(ctx, W.ta);
    for (i = 0; i < 2; ++i) { sfb__free(ctx, W.nrm[i]); sfb__free(ctx, W.op[i]); }
    sfb__free(ctx, fpos); sfb__free(ctx, cvert); sfb__free(ctx, csharp);
    return res;
}
#line 1 "src/backends_include.c"
/* Optional backends: their code lives in backends/ beside surfblend.h and is compiled here,
 * after the core, when SURFBLEND_SIMD / SURFBLEND_GL / SURFBLEND_OSMESA (or
 * SURFBLEND_ALL_BACKENDS) are defined with SURFBLEND_IMPLEMENTATION (see sfb_internal.h). */
#ifdef SURFBLEND_SIMD
#include "backends/sfb_simd.h"
#endif
#ifdef SURFBLEND_GL
#include "backends/sfb_gl.h"
#endif
#ifdef SURFBLEND_OSMESA
#include "backends/sfb_osmesa.h"
#endif
#endif /* SURFBLEND_IMPLEMENTATION */
