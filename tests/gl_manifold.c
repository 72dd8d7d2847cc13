/* gl_manifold: manifold-based blending surfaces (seed 000, SFB_SCHEME_MANIFOLD_BLEND) on the gl
 * and osmesa backends: the compute kernel (sfb_surface_eval) against ref, and the draw path
 * (sfb_surface_draw_gl, sfb_gl_trim_texture) on a GL context this program makes and owns as a
 * host application would (headless EGL, OpenGL 4.3 core, gl_use_current_context).
 *
 *   gl_manifold [SHAPES_DIR] [--verbose] [--bench]
 *
 * Checks (one line each: "PASS name", "FAIL name: details", "SKIP name: why"; closing line
 * "N passed, N failed, N skipped"; exit 1 on any failure):
 *   compute/BACKEND/SHAPE/WEIGHTS  gl (its own EGL context) and osmesa against ref, Hermite and
 *                             C-infinity weights, on quad meshes (catmark_cube, _torus, _car,
 *                             _helmet), one with creases, one with a hole and meshes with
 *                             non-quads (one Catmull-Clark step first, depth-1 faces): a 9 x 9 grid
 *                             per parametric face (corners and edges included) and 16 random
 *                             points inside; position, du, dv, normal, and duu/duv/dvv on three
 *   draw/capture/SHAPE        the vertex program's samples (capture_buffer) against ref's
 *                             sfb_surface_eval at the same (face, i/rate, j/rate); a hole's zeros
 *   draw/state                the host's GL state (program, vertex array, texture units and
 *                             samplers, active unit, transform feedback, rasterizer discard,
 *                             pixel unpack state, storage buffer bindings) is as it set it after
 *                             sfb_gl_trim_texture and sfb_surface_draw_gl, and no GL error is left
 *   errors/state, draw/destroy  the same after the failing calls of errors/..., and after
 *                             sfb_context_destroy
 *   draw/pixels               an untrimmed render of a bumped grid (orthographic, from the front,
 *                             into a 512 x 512 framebuffer object) covers pixels
 *   draw/trim-half            a mask whose left half (u < 0.5) is black: the covered pixels are
 *                             half of the untrimmed render's (within 10%)
 *   draw/trim-black           an all-black mask: nothing is drawn
 *   draw/trim-atlas           a 2 x 1 atlas (tile 0 black, tile 1 white): face 0 is trimmed, face 1
 *                             kept, faces past the last tile untrimmed: the covered pixels are the
 *                             untrimmed render's minus face 0's alone (first_face/face_count)
 *   draw/gles31               the compute kernel, the capture, a render and seed 003's analysis
 *                             (its proxy raster drawn in GL) on a host OpenGL ES 3.1 context (the
 *                             "#version 310 es" shaders)
 *   errors/...                the documented codes: a Catmull-Clark surface and a ref, an own-
 *                             context gl and an osmesa context (SFB_UNSUPPORTED); rates -1 and
 *                             1025, faces out of range, a small capture buffer, a trim texture or
 *                             capture buffer that is no object (SFB_INVALID_ARGS); a NaN matrix,
 *                             atlas tiles 1 x 0 or not splitting the texture (SFB_INVALID_VALUE);
 *                             sfb_gl_trim_texture's checks
 *   analysis/overlay          seed 003's analysis of a creased cube, computed on the host's
 *                             context, drawn by sfb_analysis_draw_gl over a magenta framebuffer
 *                             with the host's depth test (GL_NEVER), culling and blending (zero
 *                             factors) on: the surface's pixels are the picture's (within 1 of
 *                             255), the others still magenta
 *   analysis/state            the host's state after sfb_surface_analyze and the overlay, as
 *                             draw/state (the storage bindings 0..7 shade.comp.glsl uses included)
 *   analysis/raster-state     the analysis's proxy raster (an offscreen framebuffer of its own) with
 *                             the host's scissor box, masks, GL_NEVER, stencil, culling, blending,
 *                             viewport and pack state set against it: that state is the host's
 *                             again afterwards, and the picture is a ref context's
 *   analysis/not-host         sfb_analysis_draw_gl on a ref context: SFB_UNSUPPORTED
 * With --bench: frames per second of the draw path, seed 000's Table 3 setting (30 x 30 samples
 * per face, rate 29) on tori of 32, 180 and 442 quads and on peer shapes, 512 x 512 framebuffer
 * object, each frame timed to glFinish (lines starting with "#").
 *
 * Tolerances. Positions: 1e-5 x the control mesh's bounding-box diagonal (DESIGN.md). du, dv:
 * 1e-5 x diagonal x max(1, |ref's derivative|) (as tests/agree.c for tangents). Second
 * derivatives: the backend forms them on the CPU as ref does, so 1e-6 x the same. Normals:
 * 1e-3 rad, raised to (K_NORMAL + K_STEP / h) / sin(theta) where ref's tangents make the angle
 * theta: a normal is the cross product of the tangents, and the float kernel's tangents carry
 * relative errors of about 1e-7..1e-5 (K_NORMAL = 1e-5), which turn into about that over
 * sin(theta) in direction. Where ref's tangents vanish (a point or curve corner, an edge between
 * two points) ref takes the normal h = 1e-4 (else 1e-2) inside the face (src/patch/manifold.c): theta
 * is measured there, and the tangents there are h-sized differences of patch-sized values, so
 * float keeps about 6e-8 / h of them (K_STEP = 4e-7: at most 4e-3 / sin(theta) at h = 1e-4; on
 * the peer shapes those tangents can be nearly parallel, sin(theta) down to 1e-4). Where ref is
 * no oracle (C-infinity weights near a border, see compute_checks) the samples are chosen or
 * checked otherwise.
 * Every check is SKIP when its backend cannot run here (with the reason) or FAIL when
 * SFB_REQUIRE_BACKENDS lists it ("gl" for compute/gl and the draw checks, "osmesa").
 *
 * Build (the test links EGL and GL itself, as a host does; the library still dlopens them):
 *   cc -std=c99 -I. tests/gl_manifold.c build/libsfb.o -lEGL -lGL -lm -lpthread -ldl
 */
#define _POSIX_C_SOURCE 200809L
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include "surfblend.h"
#include "egl_host.h"
#include "harness.h"

#include <math.h>

static int g_verbose;
/* Normals: tolerance max(1e-3, (K_NORMAL + K_STEP / h) / sin(theta)) (see the file comment). */
#define K_NORMAL 1e-5
#define K_STEP 4e-7
static const char *g_shapes = "../shared/peers/opensubdiv-shapes";

/* A context on `kind` alone; use_current: the gl backend on the current (host's) context. */
static sfb_context *gl_context(sfb_backend_kind kind, int use_current) {
    sfb_context_config cfg = sfb_context_config_init();
    cfg.gl_use_current_context = use_current;
    cfg.logger.func = cpu_raster_logger;
    return make_context_with(cfg, kind);
}

/* ---- shapes ---- */

typedef struct shape {
    const char *name;
    char *text;
    size_t size;
    double diag;
    int nonquads;  /* the blend is built one Catmull-Clark step down: base quads are depth-1 faces */
} shape;

static int shape_load(shape *s, const char *name) {
    char path[1024];
    memset(s, 0, sizeof *s);
    s->name = name;
    snprintf(path, sizeof path, "%s/%s.obj", g_shapes, name);
    s->text = slurp(path, &s->size);
    return s->text != NULL;
}

static sfb_mesh *shape_mesh(sfb_context *ctx, shape *s) {
    sfb_mesh *m = NULL;
    sfb_mesh_info info;
    if (sfb_mesh_read_obj(ctx, s->text, s->size, &m) != SFB_SUCCESS) return NULL;
    sfb_mesh_get_info(m, &info);
    s->diag = sqrt(pow((double)info.bbox_max[0] - info.bbox_min[0], 2) + pow((double)info.bbox_max[1] - info.bbox_min[1], 2) +
                   pow((double)info.bbox_max[2] - info.bbox_min[2], 2));
    s->nonquads = info.triangles + info.ngons > 0;
    return m;
}

static sfb_surface *manifold_surface(sfb_context *ctx, const sfb_mesh *m, int weights) {
    sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_MANIFOLD_BLEND, 0);
    sfb_surface *s = NULL;
    cfg.flags = SFB_REFINE_PATCHES;
    cfg.manifold.weights = weights;
    if (sfb_surface_create(ctx, m, &cfg, &s) != SFB_SUCCESS) return NULL;
    return s;
}

/* A parametric face is a hole when ref refuses a location on it. */
static int is_hole(const sfb_surface *ref, int face) {
    sfb_location l;
    float p[3];
    sfb_eval_output o;
    memset(&o, 0, sizeof o);
    o.position = p;
    l.face = face; l.u = 0.5f; l.v = 0.5f;
    return sfb_surface_eval(ref, &l, 1, &o) != SFB_SUCCESS;
}

typedef struct evals { float *p, *du, *dv, *n, *duu, *duv, *dvv; } evals;

static void evals_alloc(evals *e, int n, int second) {
    e->p = (float *)xmalloc((size_t)n * 12); e->du = (float *)xmalloc((size_t)n * 12);
    e->dv = (float *)xmalloc((size_t)n * 12); e->n = (float *)xmalloc((size_t)n * 12);
    e->duu = second ? (float *)xmalloc((size_t)n * 12) : NULL;
    e->duv = second ? (float *)xmalloc((size_t)n * 12) : NULL;
    e->dvv = second ? (float *)xmalloc((size_t)n * 12) : NULL;
}
static void evals_free(evals *e) { free(e->p); free(e->du); free(e->dv); free(e->n); free(e->duu); free(e->duv); free(e->dvv); }

static sfb_result evals_run(const sfb_surface *s, const sfb_location *l, int n, evals *e) {
    sfb_eval_output o;
    o.position = e->p; o.du = e->du; o.dv = e->dv; o.normal = e->n; o.duu = e->duu; o.duv = e->duv; o.dvv = e->dvv;
    return sfb_surface_eval(s, l, n, &o);
}

static double norm3(const float *a) { return sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]); }
static double dist3(const float *a, const float *b) {
    double x = (double)a[0] - b[0], y = (double)a[1] - b[1], z = (double)a[2] - b[2];
    return sqrt(x * x + y * y + z * z);
}
/* The angle between two directions (robust near 0). */
static double angle3(const float *a, const float *b) {
    double x = (double)a[1] * b[2] - (double)a[2] * b[1], y = (double)a[2] * b[0] - (double)a[0] * b[2],
           z = (double)a[0] * b[1] - (double)a[1] * b[0];
    return atan2(sqrt(x * x + y * y + z * z), (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2]);
}
/* sin of the angle between two tangents (0 when either vanishes). */
static double sin3(const float *a, const float *b) {
    double la = norm3(a), lb = norm3(b), x, y, z;
    if (!(la > 0.0) || !(lb > 0.0)) return 0.0;
    x = ((double)a[1] * b[2] - (double)a[2] * b[1]) / (la * lb);
    y = ((double)a[2] * b[0] - (double)a[0] * b[2]) / (la * lb);
    z = ((double)a[0] * b[1] - (double)a[1] * b[0]) / (la * lb);
    return sqrt(x * x + y * y + z * z);
}

/* The location a step h inside the patch of a sample, as ref's degenerate-normal fallback
 * takes it (in the patch's (s,t); a base quad of a mesh with non-quads is a depth-1 face of four
 * patches). */
static sfb_location step_inside(sfb_location l, int depth1, double h) {
    double u = l.u, v = l.v, s = u, t = v, qx = 0.0, qy = 0.0, sc = 1.0;
    if (depth1) {
        sc = 2.0;
        s = 2.0 * u; t = 2.0 * v;
        if (s >= 1.0) { s -= 1.0; qx = 1.0; }
        if (t >= 1.0) { t -= 1.0; qy = 1.0; }
    }
    s += s < 0.5 ? h : -h;
    t += t < 0.5 ? h : -h;
    l.u = (float)((s + qx) / sc);
    l.v = (float)((t + qy) / sc);
    return l;
}

/* Per sample, where ref's normal comes from and how well float can follow it (see the file
 * comment): step 0 the sample's own tangents, 1 or 2 those 1e-4 or 1e-2 inside (where ref's
 * tangents vanish), with sin(theta) of ref's tangents there; the tolerance
 * max(1e-3, (K_NORMAL + K_STEP / h) / sin(theta)); skip: ref's normal is not compared (its
 * C-infinity 1e-2 step, see compute_checks). */
typedef struct ncond { double sin, tol; int step; unsigned char skip; } ncond;

static ncond *normal_conditions(const sfb_surface *ref, const shape *sh, const sfb_location *loc, const evals *R, int n, int weights) {
    ncond *nc = (ncond *)xmalloc((size_t)n * sizeof *nc);
    sfb_location *st = (sfb_location *)xmalloc((size_t)n * sizeof *st);
    int *which = (int *)xmalloc((size_t)n * sizeof(int));
    int i, m, k, pass;
    for (i = 0; i < n; ++i) {
        nc[i].sin = sin3(R->du + 3 * i, R->dv + 3 * i);
        nc[i].step = 0;
        nc[i].skip = 0;
    }
    for (pass = 1; pass <= 2; ++pass) {
        evals S;
        m = 0;
        for (i = 0; i < n; ++i) {
            int base = 0, sub = -1;
            if (nc[i].sin > 1e-6 || nc[i].step != pass - 1) continue;
            sfb_surface_param_face_base(ref, loc[i].face, &base, &sub);
            st[m] = step_inside(loc[i], sh->nonquads && sub < 0, pass == 1 ? 1e-4 : 1e-2);
            which[m++] = i;
        }
        if (m == 0) break;
        evals_alloc(&S, m, 0);
        if (evals_run(ref, st, m, &S) != SFB_SUCCESS)
            for (k = 0; k < 3 * m; ++k) S.du[k] = 0.0f;
        for (k = 0; k < m; ++k) {
            nc[which[k]].sin = sin3(S.du + 3 * k, S.dv + 3 * k);
            nc[which[k]].step = pass;
        }
        evals_free(&S);
    }
    for (i = 0; i < n; ++i) {
        double h = nc[i].step == 1 ? 1e-4 : nc[i].step == 2 ? 1e-2 : 0.0, k = K_NORMAL + (h > 0.0 ? K_STEP / h : 0.0);
        nc[i].tol = nc[i].sin > 0.0 ? k / nc[i].sin : 1.0;
        if (nc[i].tol < 1e-3) nc[i].tol = 1e-3;
        nc[i].skip = weights == SFB_MANIFOLD_WEIGHTS_CINF && nc[i].step == 2;
    }
    free(st);
    free(which);
    return nc;
}

/* Compares `got` with ref; msg empty when within tolerance. Samples with nc[i].skip set have
 * their normal left out. worst[]: position / diag, derivative / its tolerance, normal (rad),
 * and normal error x sin(theta) at samples of step 0, 1 and 2 (see normal_conditions). */
static void compare_evals(const shape *sh, const sfb_location *loc, const evals *R, const evals *G, const ncond *nc, int n, int second,
                          char *msg, size_t msz, double worst[6]) {
    int i, c;
    msg[0] = 0;
    for (i = 0; i < 6; ++i) worst[i] = 0.0;
    for (i = 0; i < n; ++i) {
        const float *rp = R->p + 3 * i, *gp = G->p + 3 * i;
        double ep = dist3(rp, gp), en = angle3(R->n + 3 * i, G->n + 3 * i);
        double tdu = 1e-5 * sh->diag * (norm3(R->du + 3 * i) > 1.0 ? norm3(R->du + 3 * i) : 1.0);
        double tdv = 1e-5 * sh->diag * (norm3(R->dv + 3 * i) > 1.0 ? norm3(R->dv + 3 * i) : 1.0);
        double edu = dist3(R->du + 3 * i, G->du + 3 * i), edv = dist3(R->dv + 3 * i, G->dv + 3 * i);
        int bad = 0, has_n = norm3(R->n + 3 * i) > 0.5 && !nc[i].skip;
        for (c = 0; c < 3; ++c)
            if (!isfinite(gp[c]) || !isfinite(G->du[3 * i + c]) || !isfinite(G->dv[3 * i + c]) || !isfinite(G->n[3 * i + c])) bad = 1;
        if (has_n && !(en <= nc[i].tol)) bad = 1;
        if (!(ep <= 1e-5 * sh->diag) || !(edu <= tdu) || !(edv <= tdv)) bad = 1;
        if (second) {
            double a = dist3(R->duu + 3 * i, G->duu + 3 * i), b = dist3(R->duv + 3 * i, G->duv + 3 * i), d = dist3(R->dvv + 3 * i, G->dvv + 3 * i);
            double t = 1e-6 * sh->diag * (1.0 + norm3(R->duu + 3 * i) + norm3(R->duv + 3 * i) + norm3(R->dvv + 3 * i));
            if (!(a <= t && b <= t && d <= t)) bad = 1;
        }
        if (ep / sh->diag > worst[0]) worst[0] = ep / sh->diag;
        if (edu / tdu > worst[1]) worst[1] = edu / tdu;
        if (edv / tdv > worst[1]) worst[1] = edv / tdv;
        if (has_n && en > worst[2]) worst[2] = en;
        if (has_n && en * nc[i].sin > worst[3 + nc[i].step]) worst[3 + nc[i].step] = en * nc[i].sin;
        if (bad && !msg[0])
            snprintf(msg, msz,
                     "face %d (%.9g, %.9g): position ref (%.9g %.9g %.9g) got (%.9g %.9g %.9g) [%.3g x diag]; du err %.3g (tol %.3g), dv err %.3g "
                     "(tol %.3g); normal ref (%.7g %.7g %.7g) got (%.7g %.7g %.7g) %.3g rad (tol %.3g, step %d, sin %.3g)",
                     loc[i].face, loc[i].u, loc[i].v, rp[0], rp[1], rp[2], gp[0], gp[1], gp[2], ep / sh->diag, edu, tdu, edv, tdv, R->n[3 * i],
                     R->n[3 * i + 1], R->n[3 * i + 2], G->n[3 * i], G->n[3 * i + 1], G->n[3 * i + 2], en, nc[i].tol, nc[i].step, nc[i].sin);
    }
}

/* A copy of `m` moved by t (on ctx). */
static sfb_mesh *translated_mesh(sfb_context *ctx, const sfb_mesh *m, const double t[3]) {
    sfb_mesh_desc d;
    sfb_mesh *out = NULL;
    float *pos;
    int i;
    sfb_mesh_get_desc(m, &d);
    pos = (float *)xmalloc((size_t)d.vertex_count * 3 * sizeof(float));
    for (i = 0; i < 3 * d.vertex_count; ++i) pos[i] = (float)((double)d.positions[i] + t[i % 3]);
    d.positions = pos;
    if (sfb_mesh_create(ctx, &d, &out) != SFB_SUCCESS) out = NULL;
    free(pos);
    return out;
}

/* The sample locations of a surface: a 9 x 9 grid per parametric face and 16 random points
 * whose patch coordinates lie in [0.04, 0.96] (see compute_checks); holes left out. */
static sfb_location *sample_locations(const sfb_surface *ref, const shape *sh, int *count, unsigned seed) {
    int nf = sfb_surface_param_face_count(ref), f, i, j, n = 0;
    sfb_location *l = (sfb_location *)xmalloc((size_t)nf * 97 * sizeof *l);
    for (f = 0; f < nf; ++f) {
        int base = 0, sub = -1, depth1;
        if (is_hole(ref, f)) continue;
        sfb_surface_param_face_base(ref, f, &base, &sub);
        depth1 = sh->nonquads && sub < 0;
        for (j = 0; j <= 8; ++j)
            for (i = 0; i <= 8; ++i) { l[n].face = f; l[n].u = (float)i / 8.0f; l[n].v = (float)j / 8.0f; ++n; }
        for (i = 0; i < 16; ++i) {
            double s, t;
            seed = seed * 1664525u + 1013904223u;
            s = 0.04 + 0.92 * ((seed >> 8) / 16777216.0);
            seed = seed * 1664525u + 1013904223u;
            t = 0.04 + 0.92 * ((seed >> 8) / 16777216.0);
            if (depth1) { s = 0.5 * (s + (i & 1)); t = 0.5 * (t + ((i >> 1) & 1)); } /* a quadrant's patch */
            l[n].u = (float)s;
            l[n].v = (float)t;
            l[n].face = f;
            ++n;
        }
    }
    *count = n;
    return l;
}

/* ---- compute: gl and osmesa against ref ---- */

static const char *const k_compute_shapes[] = {"catmark_cube", "catmark_torus", "catmark_car", "catmark_cube_creases1", "catmark_hole_test2",
                                               "catmark_pyramid", "catmark_nonquads", "catmark_helmet", NULL};

/* Where ref is not the oracle, with C-infinity weights: ref's eta' (src/patch/manifold.c,
 * sfb__mf_eta) forms (da s - a (da + db)) / s^2, in which the terms of size exp(-1/t) are lost
 * to rounding near t = 0 (b and db against a and da in a + b and da + db; the same value written
 * (da b - a db) / s^2 keeps them): its eta'(t) is off by 1e-3 relative at t = 0.025 and is all
 * rounding below t = 0.02. The tangents are sums of such terms near a point corner, so (1)
 * random samples keep their patch coordinates in [0.04, 0.96] (for every weight kind), and (2)
 * where ref's tangents vanish at the sample and 1e-4 inside, its normal (from 1e-2 inside, where
 * those terms are all it has) is not compared: there ref keeps only the far corners' share of
 * the tangents, which points along their absolute positions, so that its normal turns when the
 * mesh moves. The backend keeps those terms (manifold.comp.glsl); where ref's normal is left
 * out, the backend's must not turn when the mesh moves by 1.3 diagonals (within 1e-2 rad: the
 * move itself rounds the control points). */
static void compute_checks(sfb_context *ref) {
    static const sfb_backend_kind kinds[2] = {SFB_BACKEND_GL, SFB_BACKEND_OSMESA};
    int b, k, w;
    for (b = 0; b < 2; ++b) {
        const char *bname = sfb_backend_kind_name(kinds[b]);
        char probe[512];
        sfb_context *ctx = NULL;
        if (sfb_backend_probe(kinds[b], NULL, probe, sizeof probe) == SFB_SUCCESS) ctx = gl_context(kinds[b], 0);
        for (k = 0; k_compute_shapes[k]; ++k)
            for (w = 0; w < 2; ++w) {
                char name[160], msg[1200];
                shape sh;
                sfb_mesh *mr = NULL, *mg = NULL, *mrt = NULL, *mgt = NULL;
                sfb_surface *sr = NULL, *sg = NULL, *srt = NULL, *sgt = NULL;
                sfb_location *loc = NULL;
                evals R, G, RT, GT;
                double worst[6], move[3];
                int n, second, i, skipped = 0;
                snprintf(name, sizeof name, "compute/%s/%s/%s", bname, k_compute_shapes[k], w ? "cinf" : "hermite");
                if (!ctx) { backend_unavailable(name, bname, probe); continue; }
                if (!shape_load(&sh, k_compute_shapes[k])) { skip(name, "peer shape not found (pass SHAPES_DIR)"); continue; }
                mr = shape_mesh(ref, &sh);
                mg = shape_mesh(ctx, &sh);
                move[0] = 0.78 * sh.diag; move[1] = -0.624 * sh.diag; move[2] = 0.832 * sh.diag;
                mrt = mr ? translated_mesh(ref, mr, move) : NULL;
                mgt = mg ? translated_mesh(ctx, mg, move) : NULL;
                sr = mr ? manifold_surface(ref, mr, w) : NULL;
                sg = mg ? manifold_surface(ctx, mg, w) : NULL;
                srt = mrt ? manifold_surface(ref, mrt, w) : NULL;
                sgt = mgt ? manifold_surface(ctx, mgt, w) : NULL;
                if (!sr || !sg || !srt || !sgt) {
                    fail(name, "building the surfaces: ref: %s; %s: %s", sr && srt ? "ok" : sfb_last_error(ref), bname,
                               sg && sgt ? "ok" : sfb_last_error(ctx));
                } else {
                    loc = sample_locations(sr, &sh, &n, 1234u + (unsigned)k);
                    /* second derivatives on the first three shapes (they cost ref four blends more) */
                    second = k < 3;
                    evals_alloc(&R, n, second);
                    evals_alloc(&G, n, second);
                    evals_alloc(&RT, n, 0);
                    evals_alloc(&GT, n, 0);
                    if (evals_run(sr, loc, n, &R) != SFB_SUCCESS || evals_run(srt, loc, n, &RT) != SFB_SUCCESS)
                        fail(name, "ref eval: %s", sfb_last_error(ref));
                    else if (evals_run(sg, loc, n, &G) != SFB_SUCCESS || evals_run(sgt, loc, n, &GT) != SFB_SUCCESS)
                        fail(name, "%s eval: %s", bname, sfb_last_error(ctx));
                    else {
                        ncond *nc = normal_conditions(sr, &sh, loc, &R, n, w);
                        msg[0] = 0;
                        for (i = 0; i < n; ++i) {
                            double moved = angle3(G.n + 3 * i, GT.n + 3 * i);
                            if (!nc[i].skip) continue;
                            ++skipped;
                            if (!(moved <= 1e-2) && !msg[0])
                                snprintf(msg, sizeof msg,
                                         "face %d (%.9g, %.9g): %s's normal (%.7g %.7g %.7g) turns by %.3g rad to (%.7g %.7g %.7g) when the mesh moves",
                                         loc[i].face, loc[i].u, loc[i].v, bname, G.n[3 * i], G.n[3 * i + 1], G.n[3 * i + 2], moved, GT.n[3 * i],
                                         GT.n[3 * i + 1], GT.n[3 * i + 2]);
                        }
                        if (!msg[0]) compare_evals(&sh, loc, &R, &G, nc, n, second, msg, sizeof msg, worst);
                        if (msg[0]) fail(name, "%s", msg);
                        else {
                            printf("# %s: %d samples, worst position %.2g x diag, derivative %.2g x tol, normal %.2g rad (x sin(theta): %.2g, "
                                   "at ref's steps %.2g, %.2g)%s",
                                   name, n, worst[0], worst[1], worst[2], worst[3], worst[4], worst[5], skipped ? "" : "\n");
                            if (skipped) printf("; %d normals at ref's C-infinity 1e-2 step not compared\n", skipped);
                            pass(name);
                        }
                        free(nc);
                    }
                    evals_free(&R); evals_free(&G); evals_free(&RT); evals_free(&GT);
                    free(loc);
                }
                sfb_surface_destroy(sr); sfb_surface_destroy(sg); sfb_surface_destroy(srt); sfb_surface_destroy(sgt);
                sfb_mesh_destroy(mr); sfb_mesh_destroy(mg); sfb_mesh_destroy(mrt); sfb_mesh_destroy(mgt);
                free(sh.text);
            }
        sfb_context_destroy(ctx);
    }
}

/* ---- the host ---- */

typedef struct host {
    egl_host e; /* tests/egl_host.h */
    GLuint fbo, color, depth;
} host;

enum { FB_SIZE = 512 };

/* Makes a desktop OpenGL 4.3 core context current with no surface, and a 512 x 512 RGBA8 +
 * depth framebuffer object bound for drawing. 0 + why on failure. */
static int host_create(host *h, char *why, size_t wn) {
    memset(h, 0, sizeof *h);
    if (!egl_host_open(&h->e, 4, 3, why, wn)) return 0;
    glGenFramebuffers(1, &h->fbo);
    glGenRenderbuffers(1, &h->color);
    glGenRenderbuffers(1, &h->depth);
    glBindRenderbuffer(GL_RENDERBUFFER, h->color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, FB_SIZE, FB_SIZE);
    glBindRenderbuffer(GL_RENDERBUFFER, h->depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, FB_SIZE, FB_SIZE);
    glBindFramebuffer(GL_FRAMEBUFFER, h->fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, h->color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, h->depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        snprintf(why, wn, "the 512 x 512 RGBA8 + depth framebuffer object is incomplete");
        return 0;
    }
    glViewport(0, 0, FB_SIZE, FB_SIZE);
    glEnable(GL_DEPTH_TEST);
    return 1;
}

/* The host's own GL state that the draw path must leave alone. */
enum { NUNITS = 4, NIDX = 8 };
typedef struct gl_state {
    GLint program, vao, array_buffer, element_buffer, active, tex[NUNITS], sampler[NUNITS], tfo, tf_buffer, discard;
    GLint unpack_buffer, align, row_length, ssbo, ssbo_idx[NIDX];
} gl_state;

static void state_read(gl_state *s) {
    int i;
    GLboolean d;
    memset(s, 0, sizeof *s);
    glGetIntegerv(GL_CURRENT_PROGRAM, &s->program);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &s->vao);
    glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &s->array_buffer);
    glGetIntegerv(GL_ELEMENT_ARRAY_BUFFER_BINDING, &s->element_buffer);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &s->active);
    for (i = 0; i < NUNITS; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &s->tex[i]);
        glGetIntegerv(GL_SAMPLER_BINDING, &s->sampler[i]);
    }
    glActiveTexture((GLenum)s->active);
    glGetIntegerv(GL_TRANSFORM_FEEDBACK_BINDING, &s->tfo);
    glGetIntegerv(GL_TRANSFORM_FEEDBACK_BUFFER_BINDING, &s->tf_buffer);
    d = glIsEnabled(GL_RASTERIZER_DISCARD);
    s->discard = d;
    glGetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &s->unpack_buffer);
    glGetIntegerv(GL_UNPACK_ALIGNMENT, &s->align);
    glGetIntegerv(GL_UNPACK_ROW_LENGTH, &s->row_length);
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_BINDING, &s->ssbo);
    for (i = 0; i < NIDX; ++i) glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, (GLuint)i, &s->ssbo_idx[i]);
}

/* Empty msg when the state is `want` and no GL error is pending; else what differs. */
static void state_diff(const gl_state *want, char *msg, size_t n) {
    gl_state s;
    GLenum e = glGetError();
    size_t used = 0;
    int i;
    msg[0] = 0;
    state_read(&s);
#define DIFF(field, label)                                                                                          \
    if (s.field != want->field && used < n)                                                                         \
        used += (size_t)snprintf(msg + used, n - used, "%s%s is %d, the host set %d", used ? "; " : "", label, (int)s.field, \
                                 (int)want->field);
    DIFF(program, "GL_CURRENT_PROGRAM")
    DIFF(vao, "GL_VERTEX_ARRAY_BINDING")
    DIFF(array_buffer, "GL_ARRAY_BUFFER_BINDING")
    DIFF(element_buffer, "GL_ELEMENT_ARRAY_BUFFER_BINDING")
    DIFF(active, "GL_ACTIVE_TEXTURE")
    DIFF(tfo, "GL_TRANSFORM_FEEDBACK_BINDING")
    DIFF(tf_buffer, "GL_TRANSFORM_FEEDBACK_BUFFER_BINDING")
    DIFF(discard, "GL_RASTERIZER_DISCARD")
    DIFF(unpack_buffer, "GL_PIXEL_UNPACK_BUFFER_BINDING")
    DIFF(align, "GL_UNPACK_ALIGNMENT")
    DIFF(row_length, "GL_UNPACK_ROW_LENGTH")
    DIFF(ssbo, "GL_SHADER_STORAGE_BUFFER_BINDING")
#undef DIFF
    for (i = 0; i < NUNITS && used < n; ++i)
        if (s.tex[i] != want->tex[i] || s.sampler[i] != want->sampler[i])
            used += (size_t)snprintf(msg + used, n - used, "%sunit %d has texture %d sampler %d, the host set %d and %d", used ? "; " : "", i,
                                     s.tex[i], s.sampler[i], want->tex[i], want->sampler[i]);
    for (i = 0; i < NIDX && used < n; ++i)
        if (s.ssbo_idx[i] != want->ssbo_idx[i])
            used += (size_t)snprintf(msg + used, n - used, "%sSSBO binding %d is %d, the host set %d", used ? "; " : "", i, s.ssbo_idx[i],
                                     want->ssbo_idx[i]);
    if (e != GL_NO_ERROR && used < n) used += (size_t)snprintf(msg + used, n - used, "%sglGetError() = 0x%04x", used ? "; " : "", e);
    while (glGetError() != GL_NO_ERROR) {}
}

/* Binds objects of the host's own on everything the draw path touches. */
typedef struct host_objects { GLuint vao, buf[4], tex[NUNITS], sampler, tfo, prog; } host_objects;

static GLuint host_program(void) {
    static const char *vs = "#version 430 core\nvoid main() { gl_Position = vec4(0.0); }\n";
    GLuint sh = glCreateShader(GL_VERTEX_SHADER), prog = glCreateProgram();
    GLint ok = 0;
    glShaderSource(sh, 1, &vs, NULL);
    glCompileShader(sh);
    glAttachShader(prog, sh);
    glLinkProgram(prog);
    glDeleteShader(sh);
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    return ok ? prog : 0;
}

static void host_set_state(host_objects *o, gl_state *set) {
    static const unsigned char px[4] = {1, 2, 3, 4};
    int i;
    glGenVertexArrays(1, &o->vao);
    glGenBuffers(4, o->buf);
    glGenTextures(NUNITS, o->tex);
    glGenSamplers(1, &o->sampler);
    glGenTransformFeedbacks(1, &o->tfo);
    o->prog = host_program();
    glBindVertexArray(o->vao);
    glBindBuffer(GL_ARRAY_BUFFER, o->buf[0]);
    glBufferData(GL_ARRAY_BUFFER, 64, NULL, GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, o->buf[1]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, 64, NULL, GL_STATIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, o->buf[2]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, 64, NULL, GL_STATIC_DRAW);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, o->buf[2]);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    for (i = 0; i < NUNITS; ++i) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, o->tex[i]);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, px);
    }
    glBindSampler(1, o->sampler);
    glActiveTexture(GL_TEXTURE3);
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, o->tfo);
    glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, o->buf[3]);
    glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, 64, NULL, GL_STATIC_DRAW);
    /* unpack state that would garble a tightly packed upload */
    glPixelStorei(GL_UNPACK_ALIGNMENT, 8);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 3);
    glUseProgram(o->prog);
    state_read(set);
}

/* ---- the draw path ---- */

/* An orthographic clip-from-object matrix (column-major) that fits the box [lo, hi] into 90% of
 * the view, looking down -z. */
static void ortho_fit(const float lo[3], const float hi[3], float m[16]) {
    double c[3], r = 0.0;
    int i;
    for (i = 0; i < 3; ++i) {
        c[i] = 0.5 * ((double)lo[i] + hi[i]);
        if (0.5 * ((double)hi[i] - lo[i]) > r) r = 0.5 * ((double)hi[i] - lo[i]);
    }
    if (!(r > 0.0)) r = 1.0;
    memset(m, 0, 16 * sizeof(float));
    m[0] = (float)(0.9 / r);
    m[5] = (float)(0.9 / r);
    m[10] = (float)(-0.5 / r);
    m[12] = (float)(-0.9 * c[0] / r);
    m[13] = (float)(-0.9 * c[1] / r);
    m[14] = (float)(0.5 * c[2] / r);
    m[15] = 1.0f;
}

static int covered_pixels(void) {
    unsigned char *px = (unsigned char *)xmalloc((size_t)FB_SIZE * FB_SIZE * 4);
    int i, n = 0;
    glReadPixels(0, 0, FB_SIZE, FB_SIZE, GL_RGBA, GL_UNSIGNED_BYTE, px);
    for (i = 0; i < FB_SIZE * FB_SIZE; ++i) n += px[4 * i + 3] != 0;
    free(px);
    return n;
}

static void clear_fb(void) {
    glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
    glClearDepthf(1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

/* A bumped (nx x ny)-quad grid over [-1,1]^2 in the xy plane, faces counter-clockwise seen from +z. */
static sfb_mesh *grid_mesh(sfb_context *ctx, int nx, int ny) {
    int nv = (nx + 1) * (ny + 1), nf = nx * ny, i, j, f = 0;
    float *pos = (float *)xmalloc((size_t)nv * 3 * sizeof(float));
    int *fs = (int *)xmalloc((size_t)nf * sizeof(int)), *fv = (int *)xmalloc((size_t)nf * 4 * sizeof(int));
    sfb_mesh_desc d;
    sfb_mesh *m = NULL;
    for (j = 0; j <= ny; ++j)
        for (i = 0; i <= nx; ++i) {
            double x = -1.0 + 2.0 * i / nx, y = -1.0 + 2.0 * j / ny;
            float *p = pos + 3 * (j * (nx + 1) + i);
            p[0] = (float)x; p[1] = (float)y; p[2] = (float)(0.15 * sin(2.0 * x) * cos(2.0 * y));
        }
    for (j = 0; j < ny; ++j)
        for (i = 0; i < nx; ++i, ++f) {
            fs[f] = 4;
            fv[4 * f] = j * (nx + 1) + i;
            fv[4 * f + 1] = j * (nx + 1) + i + 1;
            fv[4 * f + 2] = (j + 1) * (nx + 1) + i + 1;
            fv[4 * f + 3] = (j + 1) * (nx + 1) + i;
        }
    memset(&d, 0, sizeof d);
    d.vertex_count = nv; d.positions = pos;
    d.face_count = nf; d.face_sizes = fs; d.face_vertices = fv;
    if (sfb_mesh_create(ctx, &d, &m) != SFB_SUCCESS) m = NULL;
    free(pos); free(fs); free(fv);
    return m;
}

/* A torus of nu x nv quads (radii 3 and 1). */
static sfb_mesh *torus_mesh(sfb_context *ctx, int nu, int nv) {
    int n = nu * nv, i, j;
    float *pos = (float *)xmalloc((size_t)n * 3 * sizeof(float));
    int *fs = (int *)xmalloc((size_t)n * sizeof(int)), *fv = (int *)xmalloc((size_t)n * 4 * sizeof(int));
    sfb_mesh_desc d;
    sfb_mesh *m = NULL;
    for (i = 0; i < nu; ++i)
        for (j = 0; j < nv; ++j) {
            double u = 6.283185307179586 * i / nu, v = 6.283185307179586 * j / nv;
            float *p = pos + 3 * (i * nv + j);
            int f = i * nv + j;
            p[0] = (float)((3.0 + cos(v)) * cos(u)); p[1] = (float)((3.0 + cos(v)) * sin(u)); p[2] = (float)sin(v);
            fs[f] = 4;
            fv[4 * f] = i * nv + j;
            fv[4 * f + 1] = ((i + 1) % nu) * nv + j;
            fv[4 * f + 2] = ((i + 1) % nu) * nv + (j + 1) % nv;
            fv[4 * f + 3] = i * nv + (j + 1) % nv;
        }
    memset(&d, 0, sizeof d);
    d.vertex_count = n; d.positions = pos;
    d.face_count = n; d.face_sizes = fs; d.face_vertices = fv;
    if (sfb_mesh_create(ctx, &d, &m) != SFB_SUCCESS) m = NULL;
    free(pos); free(fs); free(fv);
    return m;
}

/* draw/capture/NAME: the captured samples against ref. */
static void capture_check(const char *name, sfb_context *ctx, sfb_context *ref, const sfb_mesh *mg, const sfb_mesh *mr, double diag,
                          int nonquads, int weights, int rate) {
    sfb_surface *sg = manifold_surface(ctx, mg, weights), *sr = manifold_surface(ref, mr, weights);
    int nf, n = rate + 1, count, f, i, j, q = 0, holes = 0;
    size_t floats;
    GLuint buf = 0;
    float *cap;
    sfb_location *loc;
    evals R;
    ncond *nc;
    char msg[1200];
    sfb_gl_draw_params p = sfb_gl_draw_params_init();
    sfb_result r;
    shape sh;
    if (!sg || !sr) {
        fail(name, "building the surfaces: %s / %s", sg ? "ok" : sfb_last_error(ctx), sr ? "ok" : sfb_last_error(ref));
        sfb_surface_destroy(sg); sfb_surface_destroy(sr);
        return;
    }
    nf = sfb_surface_param_face_count(sr);
    count = nf * n * n;
    floats = (size_t)count * 6;
    glGenBuffers(1, &buf);
    glBindBuffer(GL_COPY_WRITE_BUFFER, buf);
    glBufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)(floats * sizeof(float)), NULL, GL_DYNAMIC_READ);
    glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
    p.rate = rate;
    p.capture_buffer = buf;
    clear_fb();
    r = sfb_surface_draw_gl(sg, &p);
    if (r != SFB_SUCCESS) {
        fail(name, "sfb_surface_draw_gl: %s: %s", sfb_result_string(r), sfb_last_error(ctx));
        glDeleteBuffers(1, &buf);
        sfb_surface_destroy(sg); sfb_surface_destroy(sr);
        return;
    }
    cap = (float *)xmalloc(floats * sizeof(float));
    glBindBuffer(GL_COPY_READ_BUFFER, buf);
    glGetBufferSubData(GL_COPY_READ_BUFFER, 0, (GLsizeiptr)(floats * sizeof(float)), cap);
    glBindBuffer(GL_COPY_READ_BUFFER, 0);
    glDeleteBuffers(1, &buf);
    loc = (sfb_location *)xmalloc((size_t)count * sizeof *loc);
    msg[0] = 0;
    for (f = 0; f < nf; ++f) {
        int hole = is_hole(sr, f);
        holes += hole;
        for (j = 0; j < n; ++j)
            for (i = 0; i < n; ++i) {
                const float *c = cap + 6 * ((size_t)(f * n + j) * (size_t)n + (size_t)i);
                if (hole) {
                    int k;
                    for (k = 0; k < 6; ++k)
                        if (c[k] != 0.0f && !msg[0]) snprintf(msg, sizeof msg, "hole face %d sample (%d,%d) captured %g, not 0", f, i, j, c[k]);
                    continue;
                }
                loc[q].face = f;
                loc[q].u = (float)i / (float)rate;
                loc[q].v = (float)j / (float)rate;
                ++q;
            }
    }
    memset(&sh, 0, sizeof sh);
    sh.name = name; sh.diag = diag; sh.nonquads = nonquads;
    evals_alloc(&R, q, 0);
    if (!msg[0] && evals_run(sr, loc, q, &R) != SFB_SUCCESS) snprintf(msg, sizeof msg, "ref eval: %s", sfb_last_error(ref));
    if (!msg[0]) {
        double wp = 0.0, wn = 0.0;
        nc = normal_conditions(sr, &sh, loc, &R, q, weights);
        q = 0;
        for (f = 0; f < nf && !msg[0]; ++f) {
            if (is_hole(sr, f)) continue;
            for (j = 0; j < n; ++j)
                for (i = 0; i < n; ++i, ++q) {
                    const float *c = cap + 6 * ((size_t)(f * n + j) * (size_t)n + (size_t)i);
                    double ep = dist3(R.p + 3 * q, c), en = angle3(R.n + 3 * q, c + 3);
                    if (ep / diag > wp) wp = ep / diag;
                    if (norm3(R.n + 3 * q) > 0.5 && !nc[q].skip && en > wn) wn = en;
                    if ((!(ep <= 1e-5 * diag) || (norm3(R.n + 3 * q) > 0.5 && !nc[q].skip && !(en <= nc[q].tol))) && !msg[0])
                        snprintf(msg, sizeof msg,
                                 "face %d sample (%d,%d): position ref (%.9g %.9g %.9g) captured (%.9g %.9g %.9g) [%.3g x diag]; normal ref (%.7g %.7g "
                                 "%.7g) captured (%.7g %.7g %.7g) %.3g rad (tol %.3g)",
                                 f, i, j, R.p[3 * q], R.p[3 * q + 1], R.p[3 * q + 2], c[0], c[1], c[2], ep / diag, R.n[3 * q], R.n[3 * q + 1],
                                 R.n[3 * q + 2], c[3], c[4], c[5], en, nc[q].tol);
                }
        }
        free(nc);
        if (!msg[0]) printf("# %s: %d samples (%d hole faces), worst position %.2g x diag, normal %.2g rad\n", name, q, holes, wp, wn);
    }
    if (msg[0]) fail(name, "%s", msg);
    else pass(name);
    evals_free(&R);
    free(loc);
    free(cap);
    sfb_surface_destroy(sg);
    sfb_surface_destroy(sr);
}

static void expect(const char *name, sfb_result got, sfb_result want, sfb_context *ctx) {
    if (got == want) pass(name);
    else fail(name, "returned %s (%s), documented: %s", sfb_result_string(got), sfb_last_error(ctx), sfb_result_string(want));
}

/* Frames per second of one surface at rate 29 (30 x 30 samples per face). */
static void bench_one(const char *label, sfb_context *ctx, const sfb_mesh *m) {
    sfb_surface *s = manifold_surface(ctx, m, SFB_MANIFOLD_WEIGHTS_HERMITE);
    sfb_gl_draw_params p = sfb_gl_draw_params_init();
    sfb_mesh_info info;
    int frames = 0, faces;
    double t0, t = 0.0;
    if (!s) { printf("# bench %s: %s\n", label, sfb_last_error(ctx)); return; }
    sfb_mesh_get_info(m, &info);
    ortho_fit(info.bbox_min, info.bbox_max, p.mvp);
    p.rate = 29;
    faces = sfb_surface_param_face_count(s);
    clear_fb();
    sfb_surface_draw_gl(s, &p); /* compiles, uploads the grid */
    glFinish();
    t0 = now_s();
    do {
        clear_fb();
        if (sfb_surface_draw_gl(s, &p) != SFB_SUCCESS) { printf("# bench %s: %s\n", label, sfb_last_error(ctx)); break; }
        glFinish();
        ++frames;
        t = now_s() - t0;
    } while (t < 2.0 && frames < 500);
    printf("# bench %s: %d faces x 900 samples, %d frames in %.2f s: %.1f frames/s (512 x 512 FBO, glFinish each frame)\n", label, faces,
           frames, t, frames / t);
    sfb_surface_destroy(s);
}

/* draw/gles31: the compute kernel and the draw path on a host OpenGL ES 3.1 context (the
 * "#version 310 es" variants, compiled by the driver at run time): sfb_surface_eval and the
 * captured samples of a C-infinity torus against ref, and a render that covers pixels. */
static void gles_check(const host *h, sfb_context *ref) {
    EGLContext es;
    sfb_context *ctx = NULL;
    sfb_mesh *mg = NULL, *mr = NULL;
    sfb_surface *sg = NULL, *sr = NULL;
    char msg[1200] = "";
    GLuint fbo = 0, rb[2] = {0, 0}, cap = 0;
    const int rate = 6, per = (rate + 1) * (rate + 1);
    if ((es = egl_host_gles_begin(&h->e, 3, 1, msg, sizeof msg)) == EGL_NO_CONTEXT) {
        skip("draw/gles31", msg);
        return;
    }
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(2, rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, FB_SIZE, FB_SIZE);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, FB_SIZE, FB_SIZE);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
    glViewport(0, 0, FB_SIZE, FB_SIZE);
    ctx = gl_context(SFB_BACKEND_GL, 1);
    if (!ctx) snprintf(msg, sizeof msg, "no gl backend on a GLES 3.1 host context");
    if (!msg[0]) {
        char info[512];
        sfb_context_backend_info(ctx, info, sizeof info);
        printf("# draw/gles31: %s\n", info);
        mg = torus_mesh(ctx, 6, 4);
        mr = torus_mesh(ref, 6, 4);
        sg = mg ? manifold_surface(ctx, mg, SFB_MANIFOLD_WEIGHTS_CINF) : NULL;
        sr = mr ? manifold_surface(ref, mr, SFB_MANIFOLD_WEIGHTS_CINF) : NULL;
        if (!sg || !sr) snprintf(msg, sizeof msg, "building the torus: %s / %s", sfb_last_error(ctx), sfb_last_error(ref));
    }
    if (!msg[0]) {
        int nf = sfb_surface_param_face_count(sr), f, i, j, q = 0, count = nf * per;
        sfb_location *loc = (sfb_location *)xmalloc((size_t)count * sizeof *loc);
        evals R, G;
        ncond *nc;
        shape sh;
        sfb_gl_draw_params p = sfb_gl_draw_params_init();
        static const float lo[3] = {-4.0f, -4.0f, -1.0f}, hi[3] = {4.0f, 4.0f, 1.0f};
        sfb_result r;
        for (f = 0; f < nf; ++f)
            for (j = 0; j <= rate; ++j)
                for (i = 0; i <= rate; ++i, ++q) { loc[q].face = f; loc[q].u = (float)i / (float)rate; loc[q].v = (float)j / (float)rate; }
        memset(&sh, 0, sizeof sh);
        sh.diag = sqrt(8.0 * 8.0 * 2.0 + 4.0);
        evals_alloc(&R, count, 0);
        evals_alloc(&G, count, 0);
        if (evals_run(sr, loc, count, &R) != SFB_SUCCESS) snprintf(msg, sizeof msg, "ref eval: %s", sfb_last_error(ref));
        else if (evals_run(sg, loc, count, &G) != SFB_SUCCESS) snprintf(msg, sizeof msg, "sfb_surface_eval on GLES: %s", sfb_last_error(ctx));
        if (!msg[0]) {
            double worst[6];
            nc = normal_conditions(sr, &sh, loc, &R, count, SFB_MANIFOLD_WEIGHTS_CINF);
            compare_evals(&sh, loc, &R, &G, nc, count, 0, msg, sizeof msg, worst);
            if (!msg[0]) {
                /* the capture: the samples of the vertex program, in G's arrays */
                const float *c;
                glGenBuffers(1, &cap);
                glBindBuffer(GL_COPY_WRITE_BUFFER, cap);
                glBufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)count * 24, NULL, GL_DYNAMIC_READ);
                glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
                ortho_fit(lo, hi, p.mvp);
                p.rate = rate;
                p.capture_buffer = cap;
                glEnable(GL_DEPTH_TEST);
                clear_fb();
                r = sfb_surface_draw_gl(sg, &p);
                if (r != SFB_SUCCESS) snprintf(msg, sizeof msg, "sfb_surface_draw_gl on GLES: %s: %s", sfb_result_string(r), sfb_last_error(ctx));
                else if (covered_pixels() < 1000) snprintf(msg, sizeof msg, "the GLES render covers %d pixels", covered_pixels());
                glBindBuffer(GL_COPY_READ_BUFFER, cap);
                c = msg[0] ? NULL : (const float *)glMapBufferRange(GL_COPY_READ_BUFFER, 0, (GLsizeiptr)count * 24, GL_MAP_READ_BIT);
                if (!msg[0] && !c) snprintf(msg, sizeof msg, "glMapBufferRange on the capture failed (0x%04x)", glGetError());
                if (c) {
                    for (q = 0; q < count; ++q) {
                        memcpy(G.p + 3 * q, c + 6 * q, 3 * sizeof(float));
                        memcpy(G.n + 3 * q, c + 6 * q + 3, 3 * sizeof(float));
                        memcpy(G.du + 3 * q, R.du + 3 * q, 3 * sizeof(float)); /* not captured */
                        memcpy(G.dv + 3 * q, R.dv + 3 * q, 3 * sizeof(float));
                    }
                    glUnmapBuffer(GL_COPY_READ_BUFFER);
                    compare_evals(&sh, loc, &R, &G, nc, count, 0, msg, sizeof msg, worst);
                }
                glBindBuffer(GL_COPY_READ_BUFFER, 0);
                glDeleteBuffers(1, &cap);
            }
            free(nc);
        }
        if (!msg[0]) {
            /* seed 003's analysis on the GLES context: its proxy raster drawn in GL (RGBA32UI and
             * DEPTH_COMPONENT32F attachments, integer read-back), against a ref context's */
            sfb_analyze_config ac = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
            sfb_analysis ag, ar;
            const int before = *cpu_rasters();
            long k, differ = 0;
            memset(&ag, 0, sizeof ag);
            memset(&ar, 0, sizeof ar);
            ac.width = 160;
            ac.height = 120;
            if (sfb_surface_analyze(sr, &ac, &ar) != SFB_SUCCESS) snprintf(msg, sizeof msg, "ref analysis: %s", sfb_last_error(ref));
            else if (sfb_surface_analyze(sg, &ac, &ag) != SFB_SUCCESS) snprintf(msg, sizeof msg, "analysis on GLES: %s", sfb_last_error(ctx));
            else {
                for (k = 0; k < (long)ar.width * ar.height; ++k) differ += ar.classes[k] != ag.classes[k];
                if (*cpu_rasters() != before || ag.proxy_pixels < 1000 || labs((long)ag.proxy_pixels - (long)ar.proxy_pixels) > ar.proxy_pixels / 200 ||
                    differ > ar.covered_pixels / 200)
                    snprintf(msg, sizeof msg, "analysis on GLES: %s, proxy pixels %d (ref %d), %ld of %d classes differ",
                             *cpu_rasters() != before ? "rasterised on the CPU" : "rasterised in GL", ag.proxy_pixels, ar.proxy_pixels, differ,
                             ar.covered_pixels);
            }
            sfb_analysis_free(&ag);
            sfb_analysis_free(&ar);
        }
        if (!msg[0]) {
            GLenum e = glGetError();
            if (e != GL_NO_ERROR) snprintf(msg, sizeof msg, "glGetError() = 0x%04x after the calls", e);
        }
        evals_free(&R);
        evals_free(&G);
        free(loc);
    }
    sfb_surface_destroy(sg);
    sfb_surface_destroy(sr);
    sfb_mesh_destroy(mg);
    sfb_mesh_destroy(mr);
    if (ctx) sfb_context_destroy(ctx);
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(2, rb);
    egl_host_gles_end(&h->e, es);
    if (msg[0]) fail("draw/gles31", "%s", msg);
    else pass("draw/gles31");
}

static const char *const k_draw_checks[] = {"draw/capture/catmark_torus", "draw/capture/catmark_pyramid", "draw/capture/catmark_cube_creases1",
                                            "draw/capture/catmark_hole_test2", "draw/capture/grid-cinf", "draw/state", "draw/pixels",
                                            "draw/trim-half", "draw/trim-black", "draw/trim-atlas", "errors/not-manifold",
                                            "errors/ref-context", "errors/own-gl-context", "errors/osmesa-context", "errors/rate-negative",
                                            "errors/rate-1025", "errors/faces", "errors/capture-small", "errors/capture-not-a-buffer",
                                            "errors/trim-not-a-texture", "errors/nan-matrix", "errors/tiles", "errors/trim-texture-mask",
                                            "errors/state", "draw/gles31", "analysis/overlay", "analysis/state", "analysis/raster-state", "analysis/not-host",
                                            "draw/destroy", NULL};

/* The analysis's proxy raster draws into a framebuffer of its own on the host's context: the
 * state that drawing touches, set by the host to values that would spoil the raster (a scissor
 * box, masks off, GL_NEVER, the stencil test, culling, blending, an odd viewport, pack state),
 * is the host's again afterwards, and the picture is the one a ref context computes (the
 * raster ignored the host's state). analysis/raster-state; 1 when `a` was computed. */
typedef struct raster_state {
    GLint draw_fbo, read_fbo, viewport[4], depth_func, pack_buffer, pack_align, pack_row;
    GLboolean depth_mask, color_mask[4], scissor, stencil, cull, blend, depth;
} raster_state;
static void raster_state_read(raster_state *r) {
    memset(r, 0, sizeof *r);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &r->draw_fbo);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &r->read_fbo);
    glGetIntegerv(GL_VIEWPORT, r->viewport);
    glGetIntegerv(GL_DEPTH_FUNC, &r->depth_func);
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &r->pack_buffer);
    glGetIntegerv(GL_PACK_ALIGNMENT, &r->pack_align);
    glGetIntegerv(GL_PACK_ROW_LENGTH, &r->pack_row);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &r->depth_mask);
    glGetBooleanv(GL_COLOR_WRITEMASK, r->color_mask);
    r->scissor = glIsEnabled(GL_SCISSOR_TEST);
    r->stencil = glIsEnabled(GL_STENCIL_TEST);
    r->cull = glIsEnabled(GL_CULL_FACE);
    r->blend = glIsEnabled(GL_BLEND);
    r->depth = glIsEnabled(GL_DEPTH_TEST);
}
static int analysis_raster_state(sfb_context *ctx, sfb_context *ref, sfb_surface *s, const char *obj, size_t len,
                                 const sfb_analyze_config *ac, sfb_analysis *a) {
    raster_state want, got;
    GLuint pack = 0;
    sfb_mesh *rm = NULL;
    sfb_surface *rs = NULL;
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 0);
    sfb_analysis ra;
    sfb_result r;
    long k, differ = 0;
    memset(&ra, 0, sizeof ra);
    glGenBuffers(1, &pack);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, pack);
    glBufferData(GL_PIXEL_PACK_BUFFER, 64, NULL, GL_STREAM_READ);
    glPixelStorei(GL_PACK_ALIGNMENT, 8);
    glPixelStorei(GL_PACK_ROW_LENGTH, 3);
    glViewport(3, 5, 7, 9);
    glScissor(0, 0, 1, 1);
    glEnable(GL_SCISSOR_TEST);
    glEnable(GL_STENCIL_TEST);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_FRONT_AND_BACK);
    glEnable(GL_BLEND);
    glDepthFunc(GL_NEVER);
    glDepthMask(GL_FALSE);
    glColorMask(GL_FALSE, GL_TRUE, GL_FALSE, GL_FALSE);
    raster_state_read(&want);
    r = sfb_surface_analyze(s, ac, a);
    raster_state_read(&got);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glDeleteBuffers(1, &pack);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glViewport(0, 0, FB_SIZE, FB_SIZE);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDisable(GL_BLEND);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    if (r != SFB_SUCCESS) {
        fail("analysis/raster-state", "sfb_surface_analyze: %s", sfb_last_error(ctx));
        return 0;
    }
    sc.flags = SFB_REFINE_PATCHES;
    if (sfb_mesh_read_obj(ref, obj, len, &rm) != SFB_SUCCESS || sfb_surface_create(ref, rm, &sc, &rs) != SFB_SUCCESS ||
        sfb_surface_analyze(rs, ac, &ra) != SFB_SUCCESS) {
        fail("analysis/raster-state", "the ref analysis: %s", sfb_last_error(ref));
    } else {
        for (k = 0; k < (long)ra.width * ra.height; ++k) differ += ra.classes[k] != a->classes[k];
        check(memcmp(&want, &got, sizeof want) == 0 && a->proxy_pixels > 1000 &&
                  labs((long)a->proxy_pixels - (long)ra.proxy_pixels) <= ra.proxy_pixels / 200 && differ <= ra.covered_pixels / 200,
              "analysis/raster-state",
              "state %s (viewport %d %d %d %d, depth func 0x%x, scissor %d, colour mask %d%d%d%d, pack %d/%d/%d); proxy pixels %d, ref %d; "
              "%ld of %d classes differ",
              memcmp(&want, &got, sizeof want) ? "changed" : "kept", got.viewport[0], got.viewport[1], got.viewport[2], got.viewport[3],
              got.depth_func, got.scissor, got.color_mask[0], got.color_mask[1], got.color_mask[2], got.color_mask[3], got.pack_buffer,
              got.pack_align, got.pack_row, a->proxy_pixels, ra.proxy_pixels, differ, ra.covered_pixels);
    }
    sfb_analysis_free(&ra);
    sfb_surface_destroy(rs);
    sfb_mesh_destroy(rm);
    return 1;
}

/* seed 003's analysis drawn over the host's framebuffer (sfb_analysis_draw_gl): the pixels on
 * the surface are the analysis picture's, the others keep the host's clear colour, with the
 * host's depth test, culling and blending on and its objects bound, all restored. */
static void analysis_checks(sfb_context *ctx, sfb_context *ref, const gl_state *set) {
    static const char cube[] = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                               "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\nt crease 2/1/0 6 7 10\n";
    sfb_mesh *m = NULL;
    sfb_surface *s = NULL;
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 0);
    sfb_analyze_config ac = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
    sfb_analysis a;
    sfb_result r;
    char msg[1200];
    unsigned char *px = NULL;
    long k, bad = 0, on = 0, kept = 0;
    memset(&a, 0, sizeof a);
    sc.flags = SFB_REFINE_PATCHES;
    ac.width = ac.height = FB_SIZE;
    if (sfb_mesh_read_obj(ctx, cube, sizeof cube - 1, &m) != SFB_SUCCESS || sfb_surface_create(ctx, m, &sc, &s) != SFB_SUCCESS ||
        !analysis_raster_state(ctx, ref, s, cube, sizeof cube - 1, &ac, &a)) {
        fail("analysis/overlay", "setting up: %s", sfb_last_error(ctx));
        fail("analysis/state", "not run");
    } else {
        glClearColor(1.0f, 0.0f, 1.0f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glEnable(GL_CULL_FACE);
        glEnable(GL_BLEND);
        glBlendFunc(GL_ZERO, GL_ZERO); /* would blacken whatever is drawn with blending on */
        glDepthFunc(GL_NEVER);         /* would reject every fragment with the depth test on */
        r = sfb_analysis_draw_gl(ctx, &a);
        px = (unsigned char *)xmalloc((size_t)FB_SIZE * FB_SIZE * 4);
        glReadPixels(0, 0, FB_SIZE, FB_SIZE, GL_RGBA, GL_UNSIGNED_BYTE, px);
        for (k = 0; k < (long)FB_SIZE * FB_SIZE; ++k) {
            /* framebuffer row 0 is the bottom, the picture's row 0 its top */
            long x = k % FB_SIZE, y = k / FB_SIZE, q = (FB_SIZE - 1 - y) * FB_SIZE + x;
            const unsigned char *f = px + 4 * k, *w = a.rgba + 4 * q;
            if (a.classes[q]) {
                ++on;
                if (abs(f[0] - w[0]) > 1 || abs(f[1] - w[1]) > 1 || abs(f[2] - w[2]) > 1) ++bad;
            } else {
                ++kept;
                if (f[0] != 255 || f[1] != 0 || f[2] != 255) ++bad;
            }
        }
        check(r == SFB_SUCCESS && bad == 0 && on > 1000 && kept > 1000, "analysis/overlay",
              "%s (%s): %ld of %ld pixels wrong (%ld on the surface)", sfb_result_string(r), sfb_last_error(ctx), bad, on + kept, on);
        glDisable(GL_CULL_FACE);
        glDisable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ZERO);
        glDepthFunc(GL_LESS);
        state_diff(set, msg, sizeof msg);
        if (msg[0]) fail("analysis/state", "host state changed: %s", msg);
        else pass("analysis/state");
    }
    r = sfb_analysis_draw_gl(ref, &a);
    check(r == SFB_UNSUPPORTED && strstr(sfb_last_error(ref), "gl_use_current_context") != NULL, "analysis/not-host", "got %s (%s)",
          sfb_result_string(r), sfb_last_error(ref));
    free(px);
    sfb_analysis_free(&a);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
}

static void draw_checks(sfb_context *ref, int bench) {
    host h;
    host_objects o;
    gl_state set;
    char why[700], msg[1200], probe[512];
    sfb_context *ctx = NULL;
    sfb_mesh *grid = NULL, *gridr = NULL;
    sfb_surface *gs = NULL;
    sfb_context_config pc = sfb_context_config_init();
    int k, full = 0;
    if (!host_create(&h, why, sizeof why)) {
        for (k = 0; k_draw_checks[k]; ++k) backend_unavailable(k_draw_checks[k], "gl", why);
        return;
    }
    printf("# host context: %s\n", h.e.renderer);
    pc.gl_use_current_context = 1;
    if (sfb_backend_probe(SFB_BACKEND_GL, &pc, probe, sizeof probe) != SFB_SUCCESS || !(ctx = gl_context(SFB_BACKEND_GL, 1))) {
        for (k = 0; k_draw_checks[k]; ++k) backend_unavailable(k_draw_checks[k], "gl", probe);
        return;
    }
    host_set_state(&o, &set);
    glBindFramebuffer(GL_FRAMEBUFFER, h.fbo);

    /* capture */
    {
        static const char *const names[4] = {"catmark_torus", "catmark_pyramid", "catmark_cube_creases1", "catmark_hole_test2"};
        for (k = 0; k < 4; ++k) {
            char name[96];
            shape sh;
            sfb_mesh *mg, *mr;
            snprintf(name, sizeof name, "draw/capture/%s", names[k]);
            if (!shape_load(&sh, names[k])) { skip(name, "peer shape not found (pass SHAPES_DIR)"); continue; }
            mg = shape_mesh(ctx, &sh);
            mr = shape_mesh(ref, &sh);
            if (!mg || !mr) fail(name, "reading the shape: %s", sfb_last_error(mg ? ref : ctx));
            else capture_check(name, ctx, ref, mg, mr, sh.diag, sh.nonquads, k & 1, 7 + k);
            sfb_mesh_destroy(mg); sfb_mesh_destroy(mr);
            free(sh.text);
        }
        grid = grid_mesh(ctx, 5, 5);
        gridr = grid_mesh(ref, 5, 5);
        if (!grid || !gridr) fail("draw/capture/grid-cinf", "grid mesh: %s", sfb_last_error(ctx));
        else capture_check("draw/capture/grid-cinf", ctx, ref, grid, gridr, 2.0 * sqrt(2.0), 0, 1, 12);
    }

    /* pixels and trimming on the bumped grid, seen from the front */
    gs = grid ? manifold_surface(ctx, grid, SFB_MANIFOLD_WEIGHTS_HERMITE) : NULL;
    if (!gs) {
        for (k = 5; k < 10; ++k) fail(k_draw_checks[k], "no grid surface: %s", sfb_last_error(ctx));
    } else {
        static const float lo[3] = {-1.0f, -1.0f, -0.2f}, hi[3] = {1.0f, 1.0f, 0.2f};
        sfb_gl_draw_params p = sfb_gl_draw_params_init();
        unsigned char half[64 * 64], black[64 * 64], atlas[128 * 64];
        sfb_trim_mask mh, mb, ma;
        unsigned th = 0, tb = 0, ta = 0;
        int i, half_px, black_px, atlas_px, face0_px;
        sfb_result r1, r2, r3, r;
        for (i = 0; i < 64 * 64; ++i) { half[i] = (i % 64) < 32 ? 0 : 255; black[i] = 0; }
        for (i = 0; i < 128 * 64; ++i) atlas[i] = (i % 128) < 64 ? 0 : 255;
        memset(&mh, 0, sizeof mh); mh.width = 64; mh.height = 64; mh.texels = half;
        mb = mh; mb.texels = black;
        memset(&ma, 0, sizeof ma); ma.width = 128; ma.height = 64; ma.texels = atlas; ma.tiles_u = 2; ma.tiles_v = 1;
        ortho_fit(lo, hi, p.mvp);
        p.rate = 24;
        r1 = sfb_gl_trim_texture(ctx, &mh, &th);
        r2 = sfb_gl_trim_texture(ctx, &mb, &tb);
        r3 = sfb_gl_trim_texture(ctx, &ma, &ta);
        clear_fb();
        r = sfb_surface_draw_gl(gs, &p);
        full = covered_pixels();
        state_diff(&set, msg, sizeof msg);
        if (r1 != SFB_SUCCESS || r2 != SFB_SUCCESS || r3 != SFB_SUCCESS || r != SFB_SUCCESS)
            fail("draw/state", "sfb_gl_trim_texture %s %s %s, sfb_surface_draw_gl %s: %s", sfb_result_string(r1), sfb_result_string(r2),
                       sfb_result_string(r3), sfb_result_string(r), sfb_last_error(ctx));
        else if (msg[0]) fail("draw/state", "host state changed: %s", msg);
        else pass("draw/state");
        if (r == SFB_SUCCESS && full > FB_SIZE * FB_SIZE / 4) {
            printf("# draw/pixels: the untrimmed grid covers %d of %d pixels\n", full, FB_SIZE * FB_SIZE);
            pass("draw/pixels");
        } else {
            fail("draw/pixels", "the untrimmed grid covers %d of %d pixels (%s)", full, FB_SIZE * FB_SIZE, sfb_last_error(ctx));
        }
        p.trim_texture = th;
        clear_fb();
        r = sfb_surface_draw_gl(gs, &p);
        half_px = covered_pixels();
        if (r != SFB_SUCCESS) fail("draw/trim-half", "%s: %s", sfb_result_string(r), sfb_last_error(ctx));
        else if (!(full > 0 && fabs((double)half_px / full - 0.5) <= 0.05))
            fail("draw/trim-half", "%d pixels trimmed against %d untrimmed (ratio %.3f, wanted 0.5 within 10%%)", half_px, full,
                       full ? (double)half_px / full : 0.0);
        else {
            printf("# draw/trim-half: %d of %d pixels (ratio %.4f)\n", half_px, full, (double)half_px / full);
            pass("draw/trim-half");
        }
        p.trim_texture = tb;
        clear_fb();
        r = sfb_surface_draw_gl(gs, &p);
        black_px = covered_pixels();
        if (r != SFB_SUCCESS) fail("draw/trim-black", "%s: %s", sfb_result_string(r), sfb_last_error(ctx));
        else if (black_px != 0) fail("draw/trim-black", "an all-black mask left %d pixels", black_px);
        else pass("draw/trim-black");
        /* atlas: face 0 trimmed, face 1 kept, faces 2.. untrimmed = all minus face 0 */
        p.trim_texture = 0;
        p.first_face = 0;
        p.face_count = 1;
        clear_fb();
        r = sfb_surface_draw_gl(gs, &p);
        face0_px = covered_pixels();
        p.first_face = 0;
        p.face_count = 0;
        p.trim_texture = ta;
        p.trim_tiles_u = 2;
        p.trim_tiles_v = 1;
        clear_fb();
        if (r == SFB_SUCCESS) r = sfb_surface_draw_gl(gs, &p);
        atlas_px = covered_pixels();
        if (r != SFB_SUCCESS) fail("draw/trim-atlas", "%s: %s", sfb_result_string(r), sfb_last_error(ctx));
        else if (!(face0_px > 0 && abs(atlas_px - (full - face0_px)) <= full / 100))
            fail("draw/trim-atlas", "%d pixels with the atlas; untrimmed %d, face 0 alone %d: wanted %d", atlas_px, full, face0_px,
                       full - face0_px);
        else pass("draw/trim-atlas");

        /* errors */
        {
            sfb_context *rc = gl_context(SFB_BACKEND_REF, 0), *oc = NULL, *mc = NULL;
            sfb_surface *cs = NULL, *rs = NULL, *os = NULL, *ms = NULL;
            sfb_surface_config cc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 0);
            sfb_gl_draw_params e = sfb_gl_draw_params_init();
            sfb_mesh *m2 = NULL;
            GLuint small = 0;
            unsigned junk = 0;
            sfb_trim_mask bad;
            cc.flags = SFB_REFINE_PATCHES;
            e.rate = 4;
            sfb_surface_create(ctx, grid, &cc, &cs);
            expect("errors/not-manifold", cs ? sfb_surface_draw_gl(cs, &e) : SFB_INVALID_ARGS, SFB_UNSUPPORTED, ctx);
            m2 = rc ? grid_mesh(rc, 2, 2) : NULL;
            rs = m2 ? manifold_surface(rc, m2, 0) : NULL;
            expect("errors/ref-context", rs ? sfb_surface_draw_gl(rs, &e) : SFB_INVALID_ARGS, SFB_UNSUPPORTED, rc);
            sfb_surface_destroy(rs); sfb_mesh_destroy(m2); m2 = NULL;
            if (sfb_backend_probe(SFB_BACKEND_GL, NULL, probe, sizeof probe) == SFB_SUCCESS && (oc = gl_context(SFB_BACKEND_GL, 0)) != NULL) {
                m2 = grid_mesh(oc, 2, 2);
                os = m2 ? manifold_surface(oc, m2, 0) : NULL;
                expect("errors/own-gl-context", os ? sfb_surface_draw_gl(os, &e) : SFB_INVALID_ARGS, SFB_UNSUPPORTED, oc);
                sfb_surface_destroy(os); sfb_mesh_destroy(m2); m2 = NULL;
            } else {
                backend_unavailable("errors/own-gl-context", "gl", probe);
            }
            if (sfb_backend_probe(SFB_BACKEND_OSMESA, NULL, probe, sizeof probe) == SFB_SUCCESS && (mc = gl_context(SFB_BACKEND_OSMESA, 0)) != NULL) {
                m2 = grid_mesh(mc, 2, 2);
                ms = m2 ? manifold_surface(mc, m2, 0) : NULL;
                expect("errors/osmesa-context", ms ? sfb_surface_draw_gl(ms, &e) : SFB_INVALID_ARGS, SFB_UNSUPPORTED, mc);
                sfb_surface_destroy(ms); sfb_mesh_destroy(m2); m2 = NULL;
            } else {
                backend_unavailable("errors/osmesa-context", "osmesa", probe);
            }
            /* the own-context contexts above made their contexts current in between: ours again */
            eglMakeCurrent(h.e.dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, h.e.ctx);
            e.rate = -1;
            expect("errors/rate-negative", sfb_surface_draw_gl(gs, &e), SFB_INVALID_ARGS, ctx);
            e.rate = 1025;
            expect("errors/rate-1025", sfb_surface_draw_gl(gs, &e), SFB_INVALID_ARGS, ctx);
            e.rate = 4;
            e.first_face = 20;
            e.face_count = 6;
            expect("errors/faces", sfb_surface_draw_gl(gs, &e), SFB_INVALID_ARGS, ctx);
            e.first_face = 0;
            e.face_count = 0;
            glGenBuffers(1, &small);
            glBindBuffer(GL_COPY_WRITE_BUFFER, small);
            glBufferData(GL_COPY_WRITE_BUFFER, 25 * 25 * 24 - 4, NULL, GL_DYNAMIC_READ);
            glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
            e.capture_buffer = small;
            expect("errors/capture-small", sfb_surface_draw_gl(gs, &e), SFB_INVALID_ARGS, ctx);
            glDeleteBuffers(1, &small);
            e.capture_buffer = 4242;
            expect("errors/capture-not-a-buffer", sfb_surface_draw_gl(gs, &e), SFB_INVALID_ARGS, ctx);
            e.capture_buffer = 0;
            e.trim_texture = 4243;
            expect("errors/trim-not-a-texture", sfb_surface_draw_gl(gs, &e), SFB_INVALID_ARGS, ctx);
            e.trim_texture = 0;
            e.mvp[3] = (float)NAN;
            expect("errors/nan-matrix", sfb_surface_draw_gl(gs, &e), SFB_INVALID_VALUE, ctx);
            e.mvp[3] = 0.0f;
            e.trim_texture = th;
            e.trim_tiles_u = 1;
            e.trim_tiles_v = 0;
            r = sfb_surface_draw_gl(gs, &e);
            e.trim_tiles_u = 3;
            e.trim_tiles_v = 1; /* 64 texels do not split into 3 tiles */
            if (r == SFB_INVALID_VALUE) r = sfb_surface_draw_gl(gs, &e);
            expect("errors/tiles", r, SFB_INVALID_VALUE, ctx);
            memset(&bad, 0, sizeof bad);
            bad.width = 0; bad.height = 4; bad.texels = half;
            r = sfb_gl_trim_texture(ctx, &bad, &junk);
            if (r == SFB_INVALID_VALUE) {
                bad.width = 4; bad.texels = NULL;
                r = sfb_gl_trim_texture(ctx, &bad, &junk);
            }
            if (r == SFB_INVALID_VALUE) r = sfb_gl_trim_texture(ctx, NULL, &junk) == SFB_INVALID_ARGS ? SFB_INVALID_VALUE : SFB_SUCCESS;
            if (r == SFB_INVALID_VALUE && rc) r = sfb_gl_trim_texture(rc, &mh, &junk) == SFB_UNSUPPORTED ? SFB_INVALID_VALUE : SFB_SUCCESS;
            expect("errors/trim-texture-mask", junk == 0 ? r : SFB_SUCCESS, SFB_INVALID_VALUE, ctx);
            state_diff(&set, msg, sizeof msg);
            if (msg[0]) fail("errors/state", "host state changed by the failing calls: %s", msg);
            else pass("errors/state");
            sfb_surface_destroy(cs);
            sfb_context_destroy(oc);
            sfb_context_destroy(mc);
            sfb_context_destroy(rc);
            eglMakeCurrent(h.e.dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, h.e.ctx);
        }
        glDeleteTextures(1, &th);
        glDeleteTextures(1, &tb);
        glDeleteTextures(1, &ta);
    }

    gles_check(&h, ref);
    glBindFramebuffer(GL_FRAMEBUFFER, h.fbo);
    analysis_checks(ctx, ref, &set);

    if (bench) {
        static const int tori[3][2] = {{8, 4}, {15, 12}, {26, 17}};
        static const char *const peers[3] = {"catmark_torus", "catmark_helmet", "catmark_lefthanded"};
        for (k = 0; k < 3; ++k) {
            char label[64];
            sfb_mesh *m = torus_mesh(ctx, tori[k][0], tori[k][1]);
            snprintf(label, sizeof label, "torus %dx%d", tori[k][0], tori[k][1]);
            if (m) bench_one(label, ctx, m);
            sfb_mesh_destroy(m);
        }
        for (k = 0; k < 3; ++k) {
            shape sh;
            sfb_mesh *m;
            if (!shape_load(&sh, peers[k])) continue;
            if ((m = shape_mesh(ctx, &sh)) != NULL) bench_one(peers[k], ctx, m);
            sfb_mesh_destroy(m);
            free(sh.text);
        }
    }
    sfb_surface_destroy(gs);
    sfb_mesh_destroy(grid);
    sfb_mesh_destroy(gridr);
    sfb_context_destroy(ctx);
    state_diff(&set, msg, sizeof msg);
    if (msg[0]) fail("draw/destroy", "host state changed by sfb_context_destroy: %s", msg);
    else pass("draw/destroy");
}

int main(int argc, char **argv) {
    sfb_context *ref;
    int i, bench = 0;
    const char *env = getenv("SHAPES");
    if (env && *env) g_shapes = env;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--verbose") == 0) g_verbose = 1;
        else if (strcmp(argv[i], "--bench") == 0) bench = 1;
        else g_shapes = argv[i];
    }
    ref = gl_context(SFB_BACKEND_REF, 0);
    if (!ref) {
        fail("setup", "no ref context");
        return close_tests();
    }
    compute_checks(ref);
    draw_checks(ref, bench);
    sfb_context_destroy(ref);
    return close_tests();
}
