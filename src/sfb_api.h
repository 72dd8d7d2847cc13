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

/* A copy of `mesh` with every face of more than three corners split into triangles, what the
 * loop, tribezier and pn schemes need from a mesh of quads or mixed faces. A quad is split along
 * its shorter diagonal (the other where the shorter lies outside a non-convex quad); a larger
 * polygon by ear clipping in the plane of its Newell normal, each step cutting the ear whose
 * closing diagonal is shortest (polygons of more than 256 corners are fanned from their first
 * corner). A diagonal that is already an edge of the mesh is taken only where no other will do.
 * Face f of k corners becomes the k - 2 faces that follow those of the faces before it, in order
 * (a triangle stays one face), its triangles keep its orientation. Kept: positions, crease tags
 * (per edge; the new diagonals are smooth), corners, UVs (per corner), the rules; each triangle
 * of a hole is a hole. *split (may be NULL) gets the number of faces that were split. */
SFB_API sfb_result sfb_mesh_triangulate(sfb_context *ctx, const sfb_mesh *mesh, sfb_mesh **out, int *split);

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
    int slider;         /* nonzero: the surface keeps its smooth (s = 0) and sharp (s = 1) nets (about 2.5 times
                           the patch table's memory), so that sfb_surface_set_sharpness and
                           sfb_surface_set_feature_sharpness move s without a rebuild */
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
 * keeps a reference to nothing in `mesh`: the mesh may be destroyed afterwards. SFB_SCHEME_TRIBEZIER's
 * build, which can take seconds on meshes with many extraordinary vertices, reports progress
 * (stage "tribezier", rising to 1) and can be cancelled there (SFB_CANCELLED, nothing kept). */
SFB_API sfb_result sfb_surface_create(sfb_context *ctx, const sfb_mesh *mesh,
                                      const sfb_surface_config *config, sfb_surface **out);
SFB_API void sfb_surface_destroy(sfb_surface *surface);
/* The sharpness slider of SFB_SCHEME_TRIBEZIER (seed 004): the surface becomes the one
 * sfb_surface_create makes with `options` (sharpness_set and sharpness; slider is kept),
 * bit for bit, in time linear in the patch points: no G1 solve runs again (the surface at s is
 * (1 - s) x the smooth net + s x the sharp net, point by point). The surface must have been
 * built with tribezier.slider set. Its patches are uploaded to the backend again; it counts as a
 * new surface for an sfb_analysis_workspace. Not to be called while another thread uses the
 * surface. On an error (an s outside [0, 1] or NaN, a surface without the nets) it is unchanged. */
SFB_API sfb_result sfb_surface_set_sharpness(sfb_surface *surface, const sfb_tribezier_options *options);
/* The slider per feature: the s of some of the mesh's tagged creases (crease_count pairs of
 * vertex indices, each an edge tagged when the surface was built; on a boundary, which is sharp
 * anyway, it changes nothing) and corners (tagged vertices), as tag values (>= 0; clamped to
 * [0, 1] as at create; a crease at 0 is still a feature -- the smooth surface there, its tangent
 * plane through the crease --, which an untagged edge is not). The surface becomes the one sfb_surface_create makes from the mesh with
 * those tags changed (the others as they are now) and tribezier.sharpness_set 0, bit for bit, as
 * sfb_surface_set_sharpness does (built with tribezier.slider; no G1 solve; uploaded again). A
 * feature that was not tagged at create cannot be added here: the nets depend on which features
 * there are (SFB_INVALID_VALUE, the surface unchanged, as for a negative or NaN value). A later
 * sfb_surface_set_sharpness without the override shows these values. */
SFB_API sfb_result sfb_surface_set_feature_sharpness(sfb_surface *surface, int crease_count, const int *crease_vertices,
                                                     const float *crease_sharpness, int corner_count, const int *corner_vertices,
                                                     const float *corner_sharpness);

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
    size_t bytes;  /* memory of the patch table and its points (and the two nets of tribezier.slider) */
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
 * on the view; sfb_surface_set_sharpness and sfb_surface_set_feature_sharpness, the calls that
 * change a surface, make it count as a new one), so a surface analysed again, from any view,
 * skips their evaluation. A workspace belongs to the context it was made on and, like that
 * context, to one thread at a time; results are bit for bit those without it. */
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
