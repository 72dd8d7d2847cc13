/* gl_host: the engine case. This program plays the host application: it makes its own
 * headless OpenGL 4.3 core context through EGL, sets GL state of its own, and then runs the
 * gl backend on that context (sfb_context_config.gl_use_current_context = 1), evaluating
 * stencils straight from one of its GL buffers into another (sfb_surface_eval_stencils_gl).
 *
 *   gl_host [--verbose]
 *
 * Checks (one line each: "PASS name", "FAIL name: details", "SKIP name: why"; closing line
 * "N passed, N failed, N skipped"; exit 1 on any failure):
 *   host/context              the EGL context (surfaceless platform, else the default display)
 *   host/probe                sfb_backend_probe(gl, gl_use_current_context) runs here and leaves the
 *                             host's state alone (when it fails, every other check is SKIP with
 *                             its reason, or FAIL when gl is required)
 *   host/sfb-context          an sfb context on it selects gl and says it runs on the host's context
 *   host/surface              building a surface uploads tables without disturbing host state
 *   host/eval_gl/TABLE        VERTEX, LIMIT, TANGENT_U, TANGENT_V, UV: host buffer -> host buffer
 *                             with offsets and strides != length; the padding of the destination
 *                             (pre-filled with a sentinel) stays; results agree with ref
 *   host/eval_gl/lenN         primvars of length 1, 2, 4, 7, 16 in interleaved host buffers
 *   host/eval_cpu/TABLE       sfb_surface_eval_stencils (CPU pointers) on the same host context
 *   host/eval_gl-too-small    a destination buffer too small for the view: refused, nothing written
 *   host/eval_gl-not-a-buffer a name that is no buffer object: refused
 *   host/ref-unsupported      sfb_surface_eval_stencils_gl on a ref context: SFB_UNSUPPORTED
 *   host/own-gl-beside-host   a second sfb context with the gl backend on its own EGL context,
 *                             used while the host's context is current: agrees, and the host's
 *                             context is current again afterwards with its state intact
 *   host/osmesa-beside-host   the same with the osmesa backend (in a child process, since a
 *                             driver crash there must not take the other checks down)
 *   host/eval_gl/one-buffer   source and destination views in one host buffer (control points
 *                             first, refined points after them, as OpenSubdiv's GL examples lay out)
 *   host/destroy              sfb_context_destroy leaves the host's context current and intact
 *   host/gles31               the same engine case on a host OpenGL ES 3.1 context (the kernels'
 *                             "#version 310 es" variant, compiled by the driver at run time)
 * After every sfb call the host's state is compared with what it set: GL_ARRAY_BUFFER_BINDING,
 * GL_SHADER_STORAGE_BUFFER_BINDING (generic and indexed 0..7 with start and size),
 * GL_CURRENT_PROGRAM, GL_VERTEX_ARRAY_BINDING, GL_UNIFORM_BUFFER_BINDING, GL_COPY_READ/WRITE
 * bindings, and glGetError() must be GL_NO_ERROR.
 *
 * Every check is SKIP when no EGL display or OpenGL 4.3 core context can be made here (with
 * the reason), or FAIL when SFB_REQUIRE_BACKENDS lists gl. Tolerances as tests/agree.c:
 * 1e-5 x bounding-box diagonal (tangents x max(1, max |tangent|)), 1e-5 x max |src| for
 * random primvars.
 *
 * Build (the test links EGL and GL itself, as a host does; the library still dlopens them):
 *   cc -std=c99 -I. tests/gl_host.c build/libsfb.o -lEGL -lGL -lm -lpthread -ldl
 */
#define _POSIX_C_SOURCE 200809L
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include "surfblend.h"
#include "egl_host.h"
#include "harness.h"

#include <math.h>
#include <stdint.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#define TOL_REL 1e-5

static int g_verbose, g_required;

/* ---- the host's context: a desktop OpenGL 4.3 core context, current, no surface (tests/egl_host.h) ---- */

typedef egl_host host;

/* ---- the host's own GL state ---- */

enum { NIDX = 8 };
typedef struct gl_state {
    GLint array_buffer, ssbo, ssbo_idx[NIDX], program, vao, ubo, copy_read, copy_write;
    GLint64 start[NIDX], size[NIDX];
} gl_state;

static void state_read(gl_state *s) {
    int i;
    memset(s, 0, sizeof *s);
    glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &s->array_buffer);
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_BINDING, &s->ssbo);
    glGetIntegerv(GL_CURRENT_PROGRAM, &s->program);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &s->vao);
    glGetIntegerv(GL_UNIFORM_BUFFER_BINDING, &s->ubo);
    glGetIntegerv(GL_COPY_READ_BUFFER_BINDING, &s->copy_read);
    glGetIntegerv(GL_COPY_WRITE_BUFFER_BINDING, &s->copy_write);
    for (i = 0; i < NIDX; ++i) {
        glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, (GLuint)i, &s->ssbo_idx[i]);
        glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_START, (GLuint)i, &s->start[i]);
        glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_SIZE, (GLuint)i, &s->size[i]);
    }
}

/* Empty string when the state equals `want` and no GL error is pending; else what differs. */
static void state_diff(const gl_state *want, char *msg, size_t n) {
    gl_state s;
    GLenum e = glGetError();
    size_t used = 0;
    int i;
    msg[0] = 0;
    state_read(&s);
#define DIFF(field, label)                                                                                      \
    if (s.field != want->field && used < n)                                                                     \
        used += (size_t)snprintf(msg + used, n - used, "%s%s is %lld, the host set %lld", used ? "; " : "", label, \
                                 (long long)s.field, (long long)want->field);
    DIFF(array_buffer, "GL_ARRAY_BUFFER_BINDING")
    DIFF(ssbo, "GL_SHADER_STORAGE_BUFFER_BINDING")
    DIFF(program, "GL_CURRENT_PROGRAM")
    DIFF(vao, "GL_VERTEX_ARRAY_BINDING")
    DIFF(ubo, "GL_UNIFORM_BUFFER_BINDING")
    DIFF(copy_read, "GL_COPY_READ_BUFFER_BINDING")
    DIFF(copy_write, "GL_COPY_WRITE_BUFFER_BINDING")
#undef DIFF
    for (i = 0; i < NIDX && used < n; ++i)
        if (s.ssbo_idx[i] != want->ssbo_idx[i] || s.start[i] != want->start[i] || s.size[i] != want->size[i])
            used += (size_t)snprintf(msg + used, n - used, "%sSSBO binding %d is buffer %d [%lld, +%lld), the host set %d [%lld, +%lld)",
                                     used ? "; " : "", i, s.ssbo_idx[i], (long long)s.start[i], (long long)s.size[i],
                                     want->ssbo_idx[i], (long long)want->start[i], (long long)want->size[i]);
    if (e != GL_NO_ERROR && used < n)
        used += (size_t)snprintf(msg + used, n - used, "%sglGetError() = 0x%04x", used ? "; " : "", e);
    while (glGetError() != GL_NO_ERROR) {}
}

/* A compute program of the host's own (it only has to link). */
static GLuint host_program(void) {
    static const char *src = "#version 430 core\nlayout(local_size_x = 1) in;\n"
                             "layout(std430, binding = 0) buffer B { float v[]; };\nvoid main() { v[0] += 1.0; }\n";
    GLuint sh = glCreateShader(GL_COMPUTE_SHADER), prog = glCreateProgram();
    GLint ok = 0;
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    glAttachShader(prog, sh);
    glLinkProgram(prog);
    glDeleteShader(sh);
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    return ok ? prog : 0;
}

typedef struct host_objects { GLuint vao, buf[8], prog; } host_objects;

/* Binds buffers, a VAO and a program of the host's; returns the state it set. */
static void host_set_state(host_objects *o, gl_state *set) {
    GLint align = 256;
    int i;
    glGenVertexArrays(1, &o->vao);
    glGenBuffers(8, o->buf);
    for (i = 0; i < 8; ++i) {
        glBindBuffer(GL_COPY_WRITE_BUFFER, o->buf[i]);
        glBufferData(GL_COPY_WRITE_BUFFER, 8192, NULL, GL_DYNAMIC_DRAW);
    }
    glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &align);
    if (align < 1) align = 256;
    o->prog = host_program();
    glBindVertexArray(o->vao);
    glBindBuffer(GL_ARRAY_BUFFER, o->buf[0]);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, o->buf[1]);
    glBindBuffer(GL_UNIFORM_BUFFER, o->buf[2]);
    for (i = 0; i < 4; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)i, o->buf[3 + i]);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 4, o->buf[7], (GLintptr)align, 1024); /* a range, not the whole buffer */
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, o->buf[3]);
    /* 6 and 7 left unbound (0) */
    glUseProgram(o->prog);
    state_read(set);
}

/* ---- a creased test mesh: jittered torus with crease ring, sharp meridian, corner, UVs ---- */

typedef struct tmesh {
    int nv, nf, nc, nuv;
    float pos[16 * 10 * 3], cs[26], uv[17 * 11 * 2];
    int fs[160], fv[640], cv[52], fuv[640], corner[1];
    float corner_s[1];
} tmesh;

static sfb_mesh *make_mesh(sfb_context *ctx, tmesh *m) {
    const int nu = 16, nv = 10;
    sfb_mesh_desc d;
    sfb_mesh *mesh = NULL;
    unsigned s = 12345u;
    int i, j;
    memset(m, 0, sizeof *m);
    for (i = 0; i < nu; ++i)
        for (j = 0; j < nv; ++j) {
            double ju, jv, u, v;
            s = s * 1103515245u + 12345u; ju = ((s >> 8) & 1023) / 1023.0 - 0.5;
            s = s * 1103515245u + 12345u; jv = ((s >> 8) & 1023) / 1023.0 - 0.5;
            u = 6.283185307179586 * (i + 0.3 * ju) / nu;
            v = 6.283185307179586 * (j + 0.3 * jv) / nv;
            m->pos[3 * (i * nv + j)] = (float)((3.0 + cos(v)) * cos(u));
            m->pos[3 * (i * nv + j) + 1] = (float)((3.0 + cos(v)) * sin(u));
            m->pos[3 * (i * nv + j) + 2] = (float)sin(v);
        }
    for (i = 0; i <= nu; ++i)
        for (j = 0; j <= nv; ++j) {
            m->uv[2 * (i * (nv + 1) + j)] = (float)i / nu;
            m->uv[2 * (i * (nv + 1) + j) + 1] = (float)j / nv;
        }
    for (i = 0; i < nu; ++i)
        for (j = 0; j < nv; ++j) {
            int f = m->nf++, k;
            int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
            m->fs[f] = 4;
            for (k = 0; k < 4; ++k) {
                m->fv[4 * f + k] = (ci[k] % nu) * nv + cj[k] % nv;
                m->fuv[4 * f + k] = ci[k] * (nv + 1) + cj[k];
            }
        }
    for (i = 0; i < nu; ++i) { m->cv[2 * m->nc] = i * nv; m->cv[2 * m->nc + 1] = ((i + 1) % nu) * nv; m->cs[m->nc++] = 1.7f; }
    for (j = 0; j < nv; ++j) { m->cv[2 * m->nc] = j; m->cv[2 * m->nc + 1] = (j + 1) % nv; m->cs[m->nc++] = 10.0f; }
    m->corner[0] = (nu / 2) * nv + nv / 2;
    m->corner_s[0] = 3.0f;
    m->nv = nu * nv;
    m->nuv = (nu + 1) * (nv + 1);
    memset(&d, 0, sizeof d);
    d.vertex_count = m->nv; d.positions = m->pos;
    d.face_count = m->nf; d.face_sizes = m->fs; d.face_vertices = m->fv;
    d.crease_count = m->nc; d.crease_vertices = m->cv; d.crease_sharpness = m->cs;
    d.corner_count = 1; d.corner_vertices = m->corner; d.corner_sharpness = m->corner_s;
    d.uv_count = m->nuv; d.uvs = m->uv; d.face_uvs = m->fuv;
    if (sfb_mesh_create(ctx, &d, &mesh) != SFB_SUCCESS) return NULL;
    return mesh;
}

/* ---- helpers: buffers, reference results, comparisons ---- */

#define SENTINEL_BITS 0x7fc0beefu
static float sentinel(void) { uint32_t u = SENTINEL_BITS; float f; memcpy(&f, &u, sizeof f); return f; }
static int is_sentinel(float f) { uint32_t u; memcpy(&u, &f, sizeof u); return u == SENTINEL_BITS; }

static const char *table_name(int t) {
    static const char *const n[] = {"VERTEX", "LIMIT", "TANGENT_U", "TANGENT_V", "UV"};
    return t >= 0 && t < 5 ? n[t] : "?";
}

/* A host buffer holding `count` elements of data (packed, length len) in view d, the rest
 * (and `tail` extra floats) filled with `fill`. Returns the buffer and its float count. */
static GLuint host_buffer(const float *packed, int count, int len, sfb_buffer_desc d, float fill, int tail, size_t *floats) {
    size_t n = (size_t)d.offset + (size_t)count * (size_t)d.stride + (size_t)tail, i;
    float *tmp = (float *)xmalloc(n * sizeof(float));
    GLuint b = 0;
    int r, c;
    for (i = 0; i < n; ++i) tmp[i] = fill;
    if (packed)
        for (r = 0; r < count; ++r)
            for (c = 0; c < len; ++c) tmp[(size_t)d.offset + (size_t)r * d.stride + c] = packed[(size_t)r * len + c];
    glGenBuffers(1, &b);
    glBindBuffer(GL_COPY_WRITE_BUFFER, b);
    glBufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)(n * sizeof(float)), tmp, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
    free(tmp);
    *floats = n;
    return b;
}

static float *host_read(GLuint b, size_t floats) {
    float *out = (float *)xmalloc(floats * sizeof(float));
    glBindBuffer(GL_COPY_READ_BUFFER, b);
    glGetBufferSubData(GL_COPY_READ_BUFFER, 0, (GLsizeiptr)(floats * sizeof(float)), out);
    glBindBuffer(GL_COPY_READ_BUFFER, 0);
    return out;
}

static double bbox_diag(const float *p, int n, int dim) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, d = 0;
    int i, k;
    for (i = 0; i < n; ++i)
        for (k = 0; k < dim; ++k) {
            if (p[i * dim + k] < lo[k]) lo[k] = p[i * dim + k];
            if (p[i * dim + k] > hi[k]) hi[k] = p[i * dim + k];
        }
    for (k = 0; k < dim; ++k) d += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    return sqrt(d);
}

/* Compares got (view d, `floats` long) with want (packed rows x len); checks that every float
 * outside the view's elements is the sentinel. Empty msg: agreement. */
static void compare_view(const float *want, int rows, int len, const float *got, sfb_buffer_desc d, size_t floats, double tol,
                         char *msg, size_t n) {
    double worst = 0.0;
    int wr = -1, wc = 0, r, c;
    size_t i;
    msg[0] = 0;
    for (r = 0; r < rows; ++r)
        for (c = 0; c < len; ++c) {
            float g = got[(size_t)d.offset + (size_t)r * d.stride + c], w = want[(size_t)r * len + c];
            double e = isfinite(g) ? fabs((double)g - (double)w) : INFINITY;
            if (e > worst || wr < 0) { worst = e; wr = r; wc = c; }
        }
    if (!(worst <= tol)) {
        snprintf(msg, n, "max |diff| %.3g > tol %.3g at row %d component %d (ref %.9g, gl %.9g)", worst, tol, wr, wc,
                 (double)want[(size_t)wr * len + wc], (double)got[(size_t)d.offset + (size_t)wr * d.stride + wc]);
        return;
    }
    for (i = 0; i < floats; ++i) {
        int inside = 0;
        if (i >= (size_t)d.offset) {
            size_t rel = i - (size_t)d.offset;
            inside = rel / (size_t)d.stride < (size_t)rows && (int)(rel % (size_t)d.stride) < len;
        }
        if (!inside && !is_sentinel(got[i])) {
            snprintf(msg, n, "float %zu of the destination buffer (outside the view {%d,%d,%d} x %d rows) was overwritten with %.9g", i,
                     d.offset, d.length, d.stride, rows, (double)got[i]);
            return;
        }
    }
}

static double max_norm3(const float *v, int rows) {
    double m = 0.0;
    int i;
    for (i = 0; i < rows; ++i) {
        double x = sqrt((double)v[3 * i] * v[3 * i] + (double)v[3 * i + 1] * v[3 * i + 1] + (double)v[3 * i + 2] * v[3 * i + 2]);
        if (x > m) m = x;
    }
    return m;
}

typedef struct reference {
    int built[5], rows[5], sources[5], len[5];
    const float *src[5];
    float *want[5];
    double tol[5];
} reference;

static int reference_make(sfb_context *ref, const sfb_mesh *mesh, const sfb_surface_config *cfg, const tmesh *m, reference *R) {
    sfb_surface *s = NULL;
    double diag = bbox_diag(m->pos, m->nv, 3), uvdiag = bbox_diag(m->uv, m->nuv, 2);
    int t;
    memset(R, 0, sizeof *R);
    if (sfb_surface_create(ref, mesh, cfg, &s) != SFB_SUCCESS) return 0;
    for (t = 0; t < 5; ++t) {
        sfb_stencil_info info;
        sfb_buffer_desc d;
        if (sfb_surface_stencil_info(s, (sfb_table)t, &info) != SFB_SUCCESS) continue;
        R->built[t] = 1;
        R->rows[t] = info.rows;
        R->sources[t] = info.sources;
        R->len[t] = t == SFB_TABLE_UV ? 2 : 3;
        R->src[t] = t == SFB_TABLE_UV ? m->uv : m->pos;
        R->want[t] = (float *)xmalloc((size_t)info.rows * R->len[t] * sizeof(float));
        d.offset = 0; d.length = R->len[t]; d.stride = R->len[t];
        if (sfb_surface_eval_stencils(s, (sfb_table)t, R->src[t], d, R->want[t], d) != SFB_SUCCESS) { sfb_surface_destroy(s); return 0; }
        if (t == SFB_TABLE_UV) R->tol[t] = TOL_REL * (uvdiag > 1.0 ? uvdiag : 1.0);
        else if (t == SFB_TABLE_TANGENT_U || t == SFB_TABLE_TANGENT_V) {
            double tm = max_norm3(R->want[t], info.rows);
            R->tol[t] = TOL_REL * diag * (tm > 1.0 ? tm : 1.0);
        } else R->tol[t] = TOL_REL * diag;
    }
    sfb_surface_destroy(s);
    return 1;
}

static void reference_free(reference *R) {
    int t;
    for (t = 0; t < 5; ++t) free(R->want[t]);
}

/* Evaluates table t with CPU pointers on surface s and compares with ref; empty msg: agreement. */
static void cpu_eval_check(const sfb_surface *s, sfb_context *ctx, const reference *R, int t, char *msg, size_t n) {
    sfb_buffer_desc d;
    float *out = (float *)xmalloc((size_t)R->rows[t] * R->len[t] * sizeof(float));
    sfb_result r;
    d.offset = 0; d.length = R->len[t]; d.stride = R->len[t];
    r = sfb_surface_eval_stencils(s, (sfb_table)t, R->src[t], d, out, d);
    if (r != SFB_SUCCESS) snprintf(msg, n, "sfb_surface_eval_stencils: %s: %s", sfb_result_string(r), sfb_last_error(ctx));
    else compare_view(R->want[t], R->rows[t], R->len[t], out, d, (size_t)R->rows[t] * R->len[t], R->tol[t], msg, n);
    free(out);
}

/* A context on `kind` alone; use_current: the gl backend on the current (host's) context. */
static sfb_context *gl_context(sfb_backend_kind kind, int use_current) {
    sfb_context_config cfg = sfb_context_config_init();
    cfg.gl_use_current_context = use_current;
    return make_context_with(cfg, kind);
}

/* ---- a second backend context (own EGL context, or OSMesa) used while the host's is current ---- */

/* Empty msg: success; "SKIP:why": the backend is unavailable; else what failed. */
static void beside_host(const host *h, sfb_backend_kind kind, const gl_state *set, sfb_context *ref, char *msg, size_t n) {
    tmesh m;
    sfb_mesh *mesh;
    sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, 2);
    reference R;
    sfb_context *ctx;
    sfb_surface *s = NULL;
    char probe[512], sub[600];
    int t;
    msg[0] = 0;
    cfg.flags = SFB_REFINE_LIMIT | SFB_REFINE_UVS;
    mesh = make_mesh(ref, &m);
    if (!mesh || !reference_make(ref, mesh, &cfg, &m, &R)) { snprintf(msg, n, "ref failed: %s", sfb_last_error(ref)); return; }
    if (sfb_backend_probe(kind, NULL, probe, sizeof probe) != SFB_SUCCESS) {
        snprintf(msg, n, "SKIP:%s unavailable: %s", sfb_backend_kind_name(kind), probe);
    } else if (!(ctx = gl_context(kind, 0))) {
        snprintf(msg, n, "sfb_context_create(%s) failed after a successful probe", sfb_backend_kind_name(kind));
    } else {
        if (eglGetCurrentContext() != h->ctx) snprintf(msg, n, "creating the %s context left another EGL context current", sfb_backend_kind_name(kind));
        if (!msg[0] && sfb_surface_create(ctx, mesh, &cfg, &s) != SFB_SUCCESS)
            snprintf(msg, n, "sfb_surface_create: %s", sfb_last_error(ctx));
        for (t = 0; t < 5 && !msg[0]; ++t) {
            if (!R.built[t]) continue;
            cpu_eval_check(s, ctx, &R, t, sub, sizeof sub);
            if (sub[0]) snprintf(msg, n, "%s: %s", table_name(t), sub);
        }
        if (!msg[0] && eglGetCurrentContext() != h->ctx)
            snprintf(msg, n, "after the %s calls the host's EGL context is no longer current (current: %p)", sfb_backend_kind_name(kind),
                     (void *)eglGetCurrentContext());
        if (!msg[0]) {
            state_diff(set, sub, sizeof sub);
            if (sub[0])
                snprintf(msg, n, "host state changed by the %s calls (eglGetCurrentContext() is still the host's, so either its state was "
                                 "changed or its GL calls now reach another context): %s", sfb_backend_kind_name(kind), sub);
        }
        sfb_surface_destroy(s);
        sfb_context_destroy(ctx);
        if (!msg[0] && eglGetCurrentContext() != h->ctx) snprintf(msg, n, "after sfb_context_destroy the host's EGL context is not current");
        if (!msg[0]) {
            state_diff(set, sub, sizeof sub);
            if (sub[0]) snprintf(msg, n, "host state changed by destroying the %s context: %s", sfb_backend_kind_name(kind), sub);
        }
        /* the host's context still works: a GL call of its own */
        if (!msg[0]) {
            GLuint b = 0;
            GLint got = -1;
            glGenBuffers(1, &b);
            glBindBuffer(GL_COPY_WRITE_BUFFER, b);
            glBufferData(GL_COPY_WRITE_BUFFER, 64, NULL, GL_STATIC_DRAW);
            glGetBufferParameteriv(GL_COPY_WRITE_BUFFER, GL_BUFFER_SIZE, &got);
            glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
            glDeleteBuffers(1, &b);
            if (!b || got != 64 || glGetError() != GL_NO_ERROR)
                snprintf(msg, n, "the host's GL context no longer works after the %s calls (glGenBuffers %u, size %d)", sfb_backend_kind_name(kind), b, got);
        }
    }
    reference_free(&R);
    sfb_mesh_destroy(mesh);
}

/* Child process for host/osmesa-beside-host: its own host context and state; exit 0 pass,
 * 1 fail (message on stdout), 77 skip. */
static int child_beside(sfb_backend_kind kind) {
    host h;
    host_objects o;
    gl_state set;
    char why[700], msg[900];
    sfb_context *ref;
    if (!egl_host_open(&h, 4, 3, why, sizeof why)) { printf("SKIP:%s\n", why); return 77; }
    host_set_state(&o, &set);
    ref = gl_context(SFB_BACKEND_REF, 0);
    if (!ref) { printf("no ref context\n"); return 1; }
    beside_host(&h, kind, &set, ref, msg, sizeof msg);
    sfb_context_destroy(ref);
    if (strncmp(msg, "SKIP:", 5) == 0) { printf("%s\n", msg); return 77; }
    if (msg[0]) { printf("%s\n", msg); return 1; }
    return 0;
}

static void run_child_check(const char *self, const char *name, const char *arg) {
    int fds[2];
    pid_t pid;
    char out[1200];
    size_t used = 0;
    ssize_t k;
    int status = 0;
    if (pipe(fds) != 0) { fail(name, "pipe failed"); return; }
    fflush(stdout);
    pid = fork();
    if (pid < 0) { fail(name, "fork failed"); return; }
    if (pid == 0) {
        char *const args[] = {(char *)self, (char *)"--child", (char *)arg, NULL};
        dup2(fds[1], 1);
        close(fds[0]);
        close(fds[1]);
        execv("/proc/self/exe", args);
        execv(self, args);
        _exit(127);
    }
    close(fds[1]);
    while (used + 1 < sizeof out && (k = read(fds[0], out + used, sizeof out - 1 - used)) > 0) used += (size_t)k;
    out[used] = 0;
    close(fds[0]);
    waitpid(pid, &status, 0);
    while (used > 0 && (out[used - 1] == '\n' || out[used - 1] == '\r')) out[--used] = 0;
    if (WIFSIGNALED(status)) fail(name, "the child process died of signal %d%s%s", WTERMSIG(status), used ? "; output: " : "", out);
    else if (WEXITSTATUS(status) == 0) pass(name);
    else if (WEXITSTATUS(status) == 77) {
        if (backend_required(arg)) fail(name, "%s (required by SFB_REQUIRE_BACKENDS)", strncmp(out, "SKIP:", 5) == 0 ? out + 5 : out);
        else skip(name, strncmp(out, "SKIP:", 5) == 0 ? out + 5 : out);
    }
    else fail(name, "%s", used ? out : "child failed without a message");
}

/* ---- a GLES 3.1 host ---- */

/* Makes an OpenGL ES 3.1 context current on the host's display, runs the gl backend on it
 * (buffer to buffer, every table), then makes the host's desktop context current again. */
static void gles_check(const host *h, const sfb_mesh *mesh, const sfb_surface_config *cfg, const reference *R) {
    EGLContext es;
    sfb_context *ctx;
    sfb_surface *s = NULL;
    char msg[700] = "", info[512] = "";
    int t;
    if ((es = egl_host_gles_begin(h, 3, 1, msg, sizeof msg)) == EGL_NO_CONTEXT) {
        skip("host/gles31", msg);
        return;
    }
    ctx = gl_context(SFB_BACKEND_GL, 1);
    if (!ctx) snprintf(msg, sizeof msg, "no gl backend on a GLES 3.1 host context");
    else sfb_context_backend_info(ctx, info, sizeof info);
    if (!msg[0] && sfb_surface_create(ctx, mesh, cfg, &s) != SFB_SUCCESS) snprintf(msg, sizeof msg, "sfb_surface_create: %s", sfb_last_error(ctx));
    for (t = 0; t < 5 && !msg[0]; ++t) {
        int len = R->len[t];
        sfb_buffer_desc sd, dd;
        size_t sf, df;
        GLuint sb, db;
        float *got;
        sfb_result r;
        char sub[600];
        if (!R->built[t]) continue;
        sd.offset = 2; sd.length = len; sd.stride = len + 1;
        dd.offset = 5; dd.length = len; dd.stride = len + 2;
        sb = host_buffer(R->src[t], R->sources[t], len, sd, 1e30f, 3, &sf);
        db = host_buffer(NULL, R->rows[t], len, dd, sentinel(), 3, &df);
        r = sfb_surface_eval_stencils_gl(s, (sfb_table)t, sb, sd, db, dd);
        if (r != SFB_SUCCESS) {
            snprintf(msg, sizeof msg, "%s: sfb_surface_eval_stencils_gl: %s: %s", table_name(t), sfb_result_string(r), sfb_last_error(ctx));
        } else {
            /* GLES 3.1 has no glGetBufferSubData: map the range */
            glBindBuffer(GL_COPY_READ_BUFFER, db);
            got = (float *)glMapBufferRange(GL_COPY_READ_BUFFER, 0, (GLsizeiptr)(df * sizeof(float)), GL_MAP_READ_BIT);
            if (!got) snprintf(msg, sizeof msg, "%s: glMapBufferRange failed (0x%04x)", table_name(t), glGetError());
            else {
                compare_view(R->want[t], R->rows[t], len, got, dd, df, R->tol[t], sub, sizeof sub);
                if (sub[0]) snprintf(msg, sizeof msg, "%s: %s", table_name(t), sub);
                glUnmapBuffer(GL_COPY_READ_BUFFER);
            }
            glBindBuffer(GL_COPY_READ_BUFFER, 0);
        }
        glDeleteBuffers(1, &sb);
        glDeleteBuffers(1, &db);
    }
    if (!msg[0]) {
        GLenum e = glGetError();
        if (e != GL_NO_ERROR) snprintf(msg, sizeof msg, "glGetError() = 0x%04x after the calls", e);
    }
    sfb_surface_destroy(s);
    if (ctx) sfb_context_destroy(ctx);
    egl_host_gles_end(h, es);
    if (msg[0]) fail("host/gles31", "%s", msg);
    else {
        if (g_verbose) printf("# gles host: %s\n", info);
        pass("host/gles31");
    }
}

/* ---- main ---- */

static const char *const k_checks[] = {
    "host/probe", "host/sfb-context", "host/surface", "host/eval_gl/VERTEX", "host/eval_gl/LIMIT", "host/eval_gl/TANGENT_U",
    "host/eval_gl/TANGENT_V", "host/eval_gl/UV", "host/eval_gl/len1", "host/eval_gl/len2", "host/eval_gl/len4",
    "host/eval_gl/len7", "host/eval_gl/len16", "host/eval_cpu/VERTEX", "host/eval_cpu/LIMIT", "host/eval_cpu/TANGENT_U",
    "host/eval_cpu/TANGENT_V", "host/eval_cpu/UV", "host/eval_gl-too-small", "host/eval_gl-not-a-buffer",
    "host/ref-unsupported", "host/own-gl-beside-host", "host/osmesa-beside-host", "host/eval_gl/one-buffer", "host/destroy",
    "host/gles31", NULL};

int main(int argc, char **argv) {
    host h;
    host_objects o;
    gl_state set;
    char why[700], msg[1200], info[512];
    sfb_context *ref = NULL, *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *s = NULL;
    sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, 2);
    reference R;
    tmesh m;
    int i, t;

    if (argc == 3 && strcmp(argv[1], "--child") == 0)
        return child_beside(strcmp(argv[2], "osmesa") == 0 ? SFB_BACKEND_OSMESA : SFB_BACKEND_GL);
    for (i = 1; i < argc; ++i)
        if (strcmp(argv[i], "--verbose") == 0) g_verbose = 1;
    g_required = backend_required("gl");

    if (!egl_host_open(&h, 4, 3, why, sizeof why)) {
        int k;
        if (g_required) fail("host/context", "%s (gl required by SFB_REQUIRE_BACKENDS)", why);
        else skip("host/context", why);
        for (k = 0; k_checks[k]; ++k) {
            if (g_required) fail(k_checks[k], "no host context: %s", why);
            else skip(k_checks[k], "no EGL / OpenGL 4.3 core context here");
        }
        return close_tests();
    }
    printf("# host context: %s\n", h.renderer);
    pass("host/context");
    host_set_state(&o, &set);
    if (!o.prog) fail("host/context", "the host's own compute program did not link");

    ref = gl_context(SFB_BACKEND_REF, 0);
    cfg.flags = SFB_REFINE_LIMIT | SFB_REFINE_UVS;
    mesh = ref ? make_mesh(ref, &m) : NULL;
    if (!mesh || !reference_make(ref, mesh, &cfg, &m, &R)) {
        fail("host/reference", "ref could not refine the test mesh: %s", ref ? sfb_last_error(ref) : "no context");
        return close_tests();
    }

    /* the gl backend must be able to run on this context at all (built in, GL 4.3) */
    {
        char probe[512];
        sfb_context_config pc = sfb_context_config_init();
        pc.gl_use_current_context = 1;
        if (sfb_backend_probe(SFB_BACKEND_GL, &pc, probe, sizeof probe) != SFB_SUCCESS) {
            int k;
            for (k = 0; k_checks[k]; ++k) {
                if (g_required) fail(k_checks[k], "gl backend unavailable on the host's context: %s (required by SFB_REQUIRE_BACKENDS)", probe);
                else {
                    char w[600];
                    snprintf(w, sizeof w, "gl backend unavailable on the host's context: %s", probe);
                    skip(k_checks[k], w);
                }
            }
            reference_free(&R);
            sfb_mesh_destroy(mesh);
            sfb_context_destroy(ref);
            return close_tests();
        }
        state_diff(&set, msg, sizeof msg);
        if (msg[0]) fail("host/probe", "host state changed by sfb_backend_probe(gl, gl_use_current_context): %s", msg);
        else pass("host/probe");
    }

    /* the sfb context on the host's context */
    ctx = gl_context(SFB_BACKEND_GL, 1);
    info[0] = 0;
    if (ctx) sfb_context_backend_info(ctx, info, sizeof info);
    state_diff(&set, msg, sizeof msg);
    if (!ctx) {
        char probe[512];
        sfb_context_config pc = sfb_context_config_init();
        pc.gl_use_current_context = 1;
        sfb_backend_probe(SFB_BACKEND_GL, &pc, probe, sizeof probe);
        fail("host/sfb-context", "no gl context on the host's context: %s", probe);
    } else if (strcmp(sfb_context_backend_name(ctx), "gl") != 0) {
        fail("host/sfb-context", "selected %s", sfb_context_backend_name(ctx));
    } else if (!strstr(info, "host")) {
        fail("host/sfb-context", "backend info does not say it runs on the host's context: %s", info);
    } else if (msg[0]) {
        fail("host/sfb-context", "host state changed by sfb_context_create: %s", msg);
    } else {
        printf("# sfb gl backend: %s\n", info);
        pass("host/sfb-context");
    }
    if (ctx && strcmp(sfb_context_backend_name(ctx), "gl") == 0) {
        if (sfb_surface_create(ctx, mesh, &cfg, &s) != SFB_SUCCESS) {
            fail("host/surface", "sfb_surface_create: %s", sfb_last_error(ctx));
        } else {
            state_diff(&set, msg, sizeof msg);
            if (msg[0]) fail("host/surface", "host state changed by sfb_surface_create (table upload): %s", msg);
            else pass("host/surface");
        }
    } else {
        fail("host/surface", "no gl context on the host's context");
    }

    /* host buffer -> host buffer, each table; the host's vertex layout: xyz at +1 of 5 floats */
    for (t = 0; t < 5; ++t) {
        char name[64];
        snprintf(name, sizeof name, "host/eval_gl/%s", table_name(t));
        if (!s) { fail(name, "no surface"); continue; }
        if (!R.built[t]) { skip(name, "table not built for this mesh"); continue; }
        {
            int len = R.len[t];
            sfb_buffer_desc sd, dd;
            size_t sf, df;
            GLuint sb, db;
            float *got;
            sfb_result r;
            sd.offset = 3; sd.length = len; sd.stride = len + 2;
            dd.offset = 7; dd.length = len; dd.stride = len + 3;
            sb = host_buffer(R.src[t], R.sources[t], len, sd, 1e30f, 5, &sf);
            db = host_buffer(NULL, R.rows[t], len, dd, sentinel(), 9, &df);
            r = sfb_surface_eval_stencils_gl(s, (sfb_table)t, sb, sd, db, dd);
            state_diff(&set, msg, sizeof msg);
            if (r != SFB_SUCCESS) {
                fail(name, "sfb_surface_eval_stencils_gl: %s: %s", sfb_result_string(r), sfb_last_error(ctx));
            } else if (msg[0]) {
                fail(name, "host state changed: %s", msg);
            } else {
                got = host_read(db, df);
                compare_view(R.want[t], R.rows[t], len, got, dd, df, R.tol[t], msg, sizeof msg);
                if (msg[0]) fail(name, "%s (src {%d,%d,%d}, dst {%d,%d,%d})", msg, sd.offset, sd.length, sd.stride, dd.offset, dd.length, dd.stride);
                else pass(name);
                free(got);
            }
            glDeleteBuffers(1, &sb);
            glDeleteBuffers(1, &db);
        }
    }

    /* other primvar lengths, random data interleaved with other attributes */
    {
        static const int lens[5] = {1, 2, 4, 7, 16};
        unsigned seed = 777u;
        for (i = 0; i < 5; ++i) {
            char name[64];
            int len = lens[i], rows = R.rows[SFB_TABLE_VERTEX], sources = R.sources[SFB_TABLE_VERTEX], k;
            float *psrc, *want;
            double mx = 0.0;
            sfb_buffer_desc pd, sd, dd;
            sfb_result r;
            snprintf(name, sizeof name, "host/eval_gl/len%d", len);
            if (!s) { fail(name, "no surface"); continue; }
            psrc = (float *)xmalloc((size_t)sources * len * sizeof(float));
            want = (float *)xmalloc((size_t)rows * len * sizeof(float));
            for (k = 0; k < sources * len; ++k) {
                seed = seed * 1664525u + 1013904223u;
                psrc[k] = (float)((seed >> 8) / 16777216.0 * 200.0 - 100.0);
                if (fabs(psrc[k]) > mx) mx = fabs(psrc[k]);
            }
            pd.offset = 0; pd.length = len; pd.stride = len;
            {
                sfb_surface *rs = NULL;
                if (sfb_surface_create(ref, mesh, &cfg, &rs) != SFB_SUCCESS ||
                    sfb_surface_eval_stencils(rs, SFB_TABLE_VERTEX, psrc, pd, want, pd) != SFB_SUCCESS)
                    fail(name, "ref: %s", sfb_last_error(ref));
                sfb_surface_destroy(rs);
            }
            sd.offset = len; sd.length = len; sd.stride = 2 * len + 1;
            dd.offset = 1; dd.length = len; dd.stride = len + 5;
            {
                size_t sf, df;
                GLuint sb = host_buffer(psrc, sources, len, sd, -1e30f, 3, &sf), db = host_buffer(NULL, rows, len, dd, sentinel(), 7, &df);
                r = sfb_surface_eval_stencils_gl(s, SFB_TABLE_VERTEX, sb, sd, db, dd);
                state_diff(&set, msg, sizeof msg);
                if (r != SFB_SUCCESS) fail(name, "sfb_surface_eval_stencils_gl: %s: %s", sfb_result_string(r), sfb_last_error(ctx));
                else if (msg[0]) fail(name, "host state changed: %s", msg);
                else {
                    float *got = host_read(db, df);
                    compare_view(want, rows, len, got, dd, df, TOL_REL * mx, msg, sizeof msg);
                    if (msg[0]) fail(name, "%s (src {%d,%d,%d}, dst {%d,%d,%d})", msg, sd.offset, sd.length, sd.stride, dd.offset, dd.length, dd.stride);
                    else pass(name);
                    free(got);
                }
                glDeleteBuffers(1, &sb);
                glDeleteBuffers(1, &db);
            }
            free(psrc);
            free(want);
        }
    }

    /* CPU pointers on the same host context */
    for (t = 0; t < 5; ++t) {
        char name[64];
        snprintf(name, sizeof name, "host/eval_cpu/%s", table_name(t));
        if (!s) { fail(name, "no surface"); continue; }
        if (!R.built[t]) { skip(name, "table not built for this mesh"); continue; }
        cpu_eval_check(s, ctx, &R, t, msg, sizeof msg);
        if (msg[0]) { fail(name, "%s", msg); continue; }
        state_diff(&set, msg, sizeof msg);
        if (msg[0]) fail(name, "host state changed: %s", msg);
        else pass(name);
    }

    /* refusals: a destination too small, a name that is not a buffer */
    if (s) {
        sfb_buffer_desc d3 = {0, 3, 3};
        size_t sf, df;
        int rows = R.rows[SFB_TABLE_VERTEX];
        GLuint sb = host_buffer(m.pos, m.nv, 3, d3, 0.0f, 0, &sf);
        GLuint db;
        float *got;
        sfb_result r;
        sfb_buffer_desc small = {0, 3, 3};
        size_t k;
        /* one row short */
        df = (size_t)(rows - 1) * 3;
        {
            float *fill = (float *)xmalloc(df * sizeof(float));
            for (k = 0; k < df; ++k) fill[k] = sentinel();
            glGenBuffers(1, &db);
            glBindBuffer(GL_COPY_WRITE_BUFFER, db);
            glBufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)(df * sizeof(float)), fill, GL_DYNAMIC_DRAW);
            glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
            free(fill);
        }
        r = sfb_surface_eval_stencils_gl(s, SFB_TABLE_VERTEX, sb, d3, db, small);
        state_diff(&set, msg, sizeof msg);
        got = host_read(db, df);
        for (k = 0; k < df && is_sentinel(got[k]); ++k) {}
        if (r == SFB_SUCCESS) fail("host/eval_gl-too-small", "a destination of %d rows for %d rows was accepted", rows - 1, rows);
        else if (msg[0]) fail("host/eval_gl-too-small", "host state after the refusal: %s", msg);
        else if (k < df) fail("host/eval_gl-too-small", "refused (%s) but float %zu of the buffer was written", sfb_result_string(r), k);
        else pass("host/eval_gl-too-small");
        if (g_verbose) printf("# too small: %s: %s\n", sfb_result_string(r), sfb_last_error(ctx));
        free(got);
        glDeleteBuffers(1, &db);
        r = sfb_surface_eval_stencils_gl(s, SFB_TABLE_VERTEX, sb, d3, 987654u, d3);
        state_diff(&set, msg, sizeof msg);
        if (r == SFB_SUCCESS) fail("host/eval_gl-not-a-buffer", "buffer name 987654 (never generated) was accepted");
        else if (msg[0]) fail("host/eval_gl-not-a-buffer", "host state after the refusal: %s", msg);
        else pass("host/eval_gl-not-a-buffer");
        if (g_verbose) printf("# not a buffer: %s: %s\n", sfb_result_string(r), sfb_last_error(ctx));
        glDeleteBuffers(1, &sb);
    } else {
        fail("host/eval_gl-too-small", "no surface");
        fail("host/eval_gl-not-a-buffer", "no surface");
    }

    /* the GL-buffer entry on a ref context */
    {
        sfb_surface *rs = NULL;
        sfb_buffer_desc d3 = {0, 3, 3};
        sfb_result r;
        if (sfb_surface_create(ref, mesh, &cfg, &rs) != SFB_SUCCESS) {
            fail("host/ref-unsupported", "ref surface: %s", sfb_last_error(ref));
        } else {
            r = sfb_surface_eval_stencils_gl(rs, SFB_TABLE_VERTEX, o.buf[0], d3, o.buf[1], d3);
            state_diff(&set, msg, sizeof msg);
            if (r != SFB_UNSUPPORTED) fail("host/ref-unsupported", "returned %s, want SFB_UNSUPPORTED", sfb_result_string(r));
            else if (msg[0]) fail("host/ref-unsupported", "host state changed: %s", msg);
            else pass("host/ref-unsupported");
            sfb_surface_destroy(rs);
        }
    }

    /* another backend context beside the host's */
    beside_host(&h, SFB_BACKEND_GL, &set, ref, msg, sizeof msg);
    if (strncmp(msg, "SKIP:", 5) == 0) {
        if (g_required) fail("host/own-gl-beside-host", "%s", msg + 5);
        else skip("host/own-gl-beside-host", msg + 5);
    } else if (msg[0]) fail("host/own-gl-beside-host", "%s", msg);
    else pass("host/own-gl-beside-host");
    run_child_check(argv[0], "host/osmesa-beside-host", "osmesa");

    /* one host buffer for both views: control points at the start, refined points after them */
    if (s) {
        int rows = R.rows[SFB_TABLE_VERTEX], k;
        sfb_buffer_desc whole = {0, 3, 3}, sd = {0, 3, 3}, dd;
        size_t floats;
        GLuint b;
        float *packed = (float *)xmalloc(((size_t)m.nv + (size_t)rows) * 3 * sizeof(float));
        sfb_result r;
        for (k = 0; k < 3 * m.nv; ++k) packed[k] = m.pos[k];
        for (k = 3 * m.nv; k < 3 * (m.nv + rows); ++k) packed[k] = sentinel();
        b = host_buffer(packed, m.nv + rows, 3, whole, sentinel(), 0, &floats);
        dd.offset = 3 * m.nv; dd.length = 3; dd.stride = 3;
        r = sfb_surface_eval_stencils_gl(s, SFB_TABLE_VERTEX, b, sd, b, dd);
        state_diff(&set, msg, sizeof msg);
        if (r != SFB_SUCCESS) fail("host/eval_gl/one-buffer", "sfb_surface_eval_stencils_gl: %s: %s", sfb_result_string(r), sfb_last_error(ctx));
        else if (msg[0]) fail("host/eval_gl/one-buffer", "host state changed: %s", msg);
        else {
            float *got = host_read(b, floats);
            for (k = 0; k < 3 * m.nv && got[k] == m.pos[k]; ++k) {}
            if (k < 3 * m.nv) fail("host/eval_gl/one-buffer", "the control points in the source view changed (float %d)", k);
            else {
                sfb_buffer_desc view = {0, 3, 3};
                compare_view(R.want[SFB_TABLE_VERTEX], rows, 3, got + 3 * m.nv, view, (size_t)rows * 3, R.tol[SFB_TABLE_VERTEX], msg, sizeof msg);
                if (msg[0]) fail("host/eval_gl/one-buffer", "%s", msg);
                else pass("host/eval_gl/one-buffer");
            }
            free(got);
        }
        glDeleteBuffers(1, &b);
        free(packed);
    } else {
        fail("host/eval_gl/one-buffer", "no surface");
    }

    /* teardown with the host's context current */
    sfb_surface_destroy(s);
    if (ctx) sfb_context_destroy(ctx);
    state_diff(&set, msg, sizeof msg);
    if (eglGetCurrentContext() != h.ctx) fail("host/destroy", "the host's context is no longer current");
    else if (msg[0]) fail("host/destroy", "host state changed by sfb_surface_destroy / sfb_context_destroy: %s", msg);
    else pass("host/destroy");

    /* the engine case on a GLES 3.1 host context */
    gles_check(&h, mesh, &cfg, &R);

    reference_free(&R);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ref);
    glUseProgram(0);
    glBindVertexArray(0);
    glDeleteProgram(o.prog);
    glDeleteVertexArrays(1, &o.vao);
    glDeleteBuffers(8, o.buf);
    egl_host_close(&h);
    return close_tests();
}
