/* backends/gl/sfb_gl.h -- the gl backend's runtime: its state (shared with osmesa), the own
 * headless EGL context or the host's EGL/GLX one, saving and restoring what a call binds,
 * shader compilation, device buffers, and init/shutdown/describe. The kernels are in the
 * family files beside it.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. */
#ifndef SFB__GL_RUNTIME_H
#define SFB__GL_RUNTIME_H

#include "api.h"
#include "shaders.h"

/* The library names tried by dlopen for the own context, NULL-terminated: a build-time override. */
#ifndef SFB__EGL_LIBRARY_NAMES
#define SFB__EGL_LIBRARY_NAMES {"libEGL.so.1", "libEGL.so", NULL}
#endif

/* ---- the backend state, shared by gl and osmesa ---- */
enum { SFB__GL_HOST = 0, SFB__GL_OWN_EGL = 1, SFB__GL_OSMESA = 2 };
enum { SFB__GL_BINDINGS = 8 }; /* SSBO binding points 0..7 used by the shaders (shade.comp.glsl: all 8), saved and restored on the host context */

typedef struct sfb__gl_saved {
    sfb__GLint program, generic;
    sfb__GLint binding[SFB__GL_BINDINGS];
    sfb__GLint64 start[SFB__GL_BINDINGS], size[SFB__GL_BINDINGS];
    /* own EGL context: what was current on the thread before the call */
    sfb__EGLenum api;
    sfb__EGLContext prev_ctx;
    sfb__EGLDisplay prev_dpy;
    sfb__EGLSurface prev_draw, prev_read;
    void *prev_osmesa;
    /* contexts of other window-system APIs current before the call: Mesa keeps one current
     * context per thread across EGL, GLX and OSMesa, so making ours current displaces them */
    sfb__EGLenum fegl_api;
    sfb__EGLContext fegl_ctx;
    sfb__EGLDisplay fegl_dpy;
    sfb__EGLSurface fegl_draw, fegl_read;
    void *glx_ctx, *glx_dpy;
    unsigned long glx_draw, glx_read;
} sfb__gl_saved;

typedef struct sfb__gl {
    sfb__pool pool; /* CPU threads lent to the core's per-item loops (the `parallel` slot) */
    sfb_context *ctx;
    int mode;                       /* SFB__GL_HOST, _OWN_EGL, _OSMESA */
    sfb__glfns gl;
    void *libgl;                    /* fallback for entry points getprocaddress lacks */
    /* EGL */
    void *libegl;
    sfb__eglfns egl;
    sfb__EGLDisplay dpy;
    sfb__EGLContext egl_ctx;
    sfb__EGLenum egl_api;
    int terminate_display;          /* display was opened with reference tracking */
    /* OSMesa (sfb_osmesa.h) */
    void *libosmesa;
    void *osmesa_ctx;
    void *(*osmesa_get_current)(void);
    sfb__GLboolean (*osmesa_make_current)(void *, void *, sfb__GLenum, sfb__GLsizei, sfb__GLsizei);
    void (*osmesa_destroy)(void *);
    unsigned char osmesa_pixel[16];
    /* the other window-system APIs, if the process has loaded them (never loaded by us) */
    void *fegl_lib, *glx_lib;
    sfb__eglfns fegl;
    void *(*glx_get_context)(void);
    void *(*glx_get_display)(void);
    unsigned long (*glx_get_draw)(void);
    unsigned long (*glx_get_read)(void);
    int (*glx_make_current)(void *, unsigned long, unsigned long, void *);
    /* GL side */
    int es;                         /* GLES 3.1+ rather than desktop 4.3+ */
    sfb__GLint max_block;           /* GL_MAX_SHADER_STORAGE_BLOCK_SIZE, bytes */
    sfb__GLint max_groups;          /* GL_MAX_COMPUTE_WORK_GROUP_COUNT[0] */
    sfb__GLuint program[17];        /* stencil kernel per SFB_LENGTH, compiled on first use */
    sfb__GLint loc[17][8];
    sfb__GLuint patch_program[2];   /* patch kernels (Catmull-Clark, Loop), compiled on first use */
    sfb__GLint patch_loc[2][5];
    sfb__GLuint scratch_src, scratch_dst;
    size_t scratch_src_cap, scratch_dst_cap;
    sfb__GLuint normals_program;    /* finish_normals kernel, compiled on first use */
    sfb__GLint normals_loc[8];
    sfb__GLuint normals_buf[5];     /* finish_normals inputs: tu, tv, ns, ns_index, b */
    size_t normals_cap[5];
    sfb__GLuint shade_program;      /* seed 003's shade kernel, compiled on first use */
    sfb__GLint shade_loc[13];
    sfb__GLuint shade_buf[7];       /* shade inputs: position, normal, du, dv, duu, duv, dvv */
    size_t shade_cap[7];
    sfb__GLint max_texture;         /* GL_MAX_TEXTURE_SIZE */
    sfb__GLuint mf_program;         /* manifold.comp.glsl's compute stage, compiled on first use */
    sfb__GLint mf_loc[10];
    sfb__GLuint sampler;            /* nearest, clamped: the tables' textures and the trimming mask */
    /* the draw path (sfb_surface_draw_gl, host's context): manifold.comp.glsl's vertex stage with
     * manifold_draw.frag.glsl, the index buffer of one face's sample grid, a transform feedback
     * object for the capture; made on first use */
    sfb__GLuint draw_program, draw_vao, draw_ibo, draw_tfo;
    sfb__GLint draw_loc[16];
    int draw_rate;                  /* the grid draw_ibo holds */
    sfb__GLuint an_program, an_vao; /* sfb_analysis_draw_gl: analysis_draw.{vert,frag}.glsl, made on first use */
    sfb__GLint an_loc[3];
    sfb__GLuint raster_program, raster_vao; /* seed 003's proxy raster (raster.h), made on first use */
    sfb__GLint raster_loc[7];
    char desc[320];
} sfb__gl;

static const char *sfb__gl_error_name(sfb__GLenum e) {
    switch (e) {
    case 0x0500: return "GL_INVALID_ENUM";
    case 0x0501: return "GL_INVALID_VALUE";
    case 0x0502: return "GL_INVALID_OPERATION";
    case 0x0505: return "GL_OUT_OF_MEMORY";
    case 0x0506: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    default: return "GL error";
    }
}

/* Turns a pending GL error into a result with the operation named. */
static sfb_result sfb__gl_check(sfb__gl *g, const char *what) {
    sfb__GLenum e = g->gl.GetError();
    if (e == SFB__GL_NO_ERROR) return SFB_SUCCESS;
    while (g->gl.GetError() != SFB__GL_NO_ERROR) {}
    return sfb__error(g->ctx, e == SFB__GL_OUT_OF_MEMORY ? SFB_OUT_OF_MEMORY : SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1,
                      "%s: %s (0x%04x) during %s", g->mode == SFB__GL_OSMESA ? "osmesa" : "gl", sfb__gl_error_name(e), e, what);
}

/* ---- making the context current for a call, and putting things back ---- */
/* Finds GLX (and, for osmesa, EGL) if the process has loaded them, to save and restore a
 * context of theirs that our own context displaces. Looked up again until found. */
static void sfb__gl_find_foreign(sfb__gl *g) {
#if !defined(_WIN32)
    if (!g->glx_lib && (g->glx_lib = dlopen("libGL.so.1", RTLD_LAZY | RTLD_LOCAL | RTLD_NOLOAD)) != NULL) {
        sfb__glproc p;
        p = sfb__gl_dlsym(g->glx_lib, "glXGetCurrentContext"); memcpy(&g->glx_get_context, &p, sizeof p);
        p = sfb__gl_dlsym(g->glx_lib, "glXGetCurrentDisplay"); memcpy(&g->glx_get_display, &p, sizeof p);
        p = sfb__gl_dlsym(g->glx_lib, "glXGetCurrentDrawable"); memcpy(&g->glx_get_draw, &p, sizeof p);
        p = sfb__gl_dlsym(g->glx_lib, "glXGetCurrentReadDrawable"); memcpy(&g->glx_get_read, &p, sizeof p);
        p = sfb__gl_dlsym(g->glx_lib, "glXMakeContextCurrent"); memcpy(&g->glx_make_current, &p, sizeof p);
        if (!g->glx_get_context || !g->glx_get_display || !g->glx_get_draw || !g->glx_get_read || !g->glx_make_current)
            g->glx_get_context = NULL;
    }
    if (g->mode == SFB__GL_OSMESA && !g->fegl_lib &&
        (g->fegl_lib = dlopen("libEGL.so.1", RTLD_LAZY | RTLD_LOCAL | RTLD_NOLOAD)) != NULL && !sfb__egl_load(g->fegl_lib, &g->fegl))
        g->fegl.GetCurrentContext = NULL;
#else
    (void)g;
#endif
}

static void sfb__gl_save_foreign(sfb__gl *g, sfb__gl_saved *s) {
    sfb__gl_find_foreign(g);
    if (g->glx_get_context && (s->glx_ctx = g->glx_get_context()) != NULL) {
        s->glx_dpy = g->glx_get_display();
        s->glx_draw = g->glx_get_draw();
        s->glx_read = g->glx_get_read();
    }
    if (g->mode == SFB__GL_OSMESA && g->fegl.GetCurrentContext && (s->fegl_ctx = g->fegl.GetCurrentContext()) != NULL) {
        s->fegl_api = g->fegl.QueryAPI();
        s->fegl_dpy = g->fegl.GetCurrentDisplay();
        s->fegl_draw = g->fegl.GetCurrentSurface(SFB__EGL_DRAW);
        s->fegl_read = g->fegl.GetCurrentSurface(SFB__EGL_READ);
    }
}

/* Puts a displaced GLX/EGL context back: released first, since re-binding a context its API
 * still believes current is skipped by the driver. */
static void sfb__gl_restore_foreign(sfb__gl *g, const sfb__gl_saved *s) {
    if (s->glx_ctx) {
        g->glx_make_current(s->glx_dpy, 0, 0, NULL);
        g->glx_make_current(s->glx_dpy, s->glx_draw, s->glx_read, s->glx_ctx);
    }
    if (s->fegl_ctx) {
        g->fegl.BindAPI(s->fegl_api);
        g->fegl.MakeCurrent(s->fegl_dpy, NULL, NULL, NULL);
        g->fegl.MakeCurrent(s->fegl_dpy, s->fegl_draw, s->fegl_read, s->fegl_ctx);
    }
}

static sfb_result sfb__gl_enter(sfb__gl *g, sfb__gl_saved *s) {
    int i;
    memset(s, 0, sizeof *s);
    if (g->mode != SFB__GL_HOST) sfb__gl_save_foreign(g, s);
    if (g->mode == SFB__GL_OWN_EGL) {
        s->api = g->egl.QueryAPI();
        if (s->api != g->egl_api) g->egl.BindAPI(g->egl_api);
        s->prev_ctx = g->egl.GetCurrentContext();
        s->prev_dpy = g->egl.GetCurrentDisplay();
        s->prev_draw = g->egl.GetCurrentSurface(SFB__EGL_DRAW);
        s->prev_read = g->egl.GetCurrentSurface(SFB__EGL_READ);
        if (s->prev_ctx != g->egl_ctx && !g->egl.MakeCurrent(g->dpy, NULL, NULL, g->egl_ctx)) {
            if (s->api != g->egl_api) g->egl.BindAPI(s->api);
            return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1,
                              "gl: eglMakeCurrent failed (EGL error 0x%x)", (unsigned)g->egl.GetError());
        }
    } else if (g->mode == SFB__GL_OSMESA) {
        s->prev_osmesa = g->osmesa_get_current();
        if (s->prev_osmesa != g->osmesa_ctx &&
            !g->osmesa_make_current(g->osmesa_ctx, g->osmesa_pixel, SFB__GL_UNSIGNED_BYTE, 1, 1)) {
            sfb__gl_restore_foreign(g, s);
            return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "osmesa: OSMesaMakeCurrent failed");
        }
    }
    /* Errors pending before we start are the host's, not ours: note them and clear. */
    {
        sfb__GLenum e = g->gl.GetError();
        if (e != SFB__GL_NO_ERROR) {
            sfb__log(g->ctx, SFB_LOG_WARN, "gl: %s (0x%04x) was pending before surfblend's call; cleared", sfb__gl_error_name(e), e);
            while (g->gl.GetError() != SFB__GL_NO_ERROR) {}
        }
    }
    g->gl.GetIntegerv(SFB__GL_CURRENT_PROGRAM, &s->program);
    g->gl.GetIntegerv(SFB__GL_SHADER_STORAGE_BUFFER_BINDING, &s->generic);
    for (i = 0; i < SFB__GL_BINDINGS; ++i) {
        g->gl.GetIntegeri_v(SFB__GL_SHADER_STORAGE_BUFFER_BINDING, (sfb__GLuint)i, &s->binding[i]);
        g->gl.GetInteger64i_v(SFB__GL_SHADER_STORAGE_BUFFER_START, (sfb__GLuint)i, &s->start[i]);
        g->gl.GetInteger64i_v(SFB__GL_SHADER_STORAGE_BUFFER_SIZE, (sfb__GLuint)i, &s->size[i]);
    }
    return SFB_SUCCESS;
}

static void sfb__gl_leave(sfb__gl *g, const sfb__gl_saved *s) {
    int i;
    for (i = 0; i < SFB__GL_BINDINGS; ++i) {
        if (s->binding[i] && s->size[i] > 0)
            g->gl.BindBufferRange(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)i, (sfb__GLuint)s->binding[i],
                                  (sfb__GLintptr)s->start[i], (sfb__GLsizeiptr)s->size[i]);
        else
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)i, (sfb__GLuint)s->binding[i]);
    }
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)s->generic);
    g->gl.UseProgram((sfb__GLuint)s->program);
    if (g->mode == SFB__GL_OWN_EGL) {
        if (s->prev_ctx != g->egl_ctx) {
            /* our context stays bound to nothing; the thread gets back what it had */
            if (s->prev_ctx) {
                if (s->api != g->egl_api) g->egl.BindAPI(s->api);
                g->egl.MakeCurrent(s->prev_dpy, s->prev_draw, s->prev_read, s->prev_ctx);
            } else {
                g->egl.MakeCurrent(g->dpy, NULL, NULL, NULL);
                if (s->api != g->egl_api) g->egl.BindAPI(s->api);
            }
        } else if (s->api != g->egl_api) {
            g->egl.BindAPI(s->api);
        }
    } else if (g->mode == SFB__GL_OSMESA) {
        /* With an EGL/GLX context current, OSMesaGetCurrentContext reports that one (Mesa shares
         * the slot): release ours and put it back. OSMesa cannot tell which buffer another
         * OSMesa context was bound to, so a different OSMesa context is not restored. */
        if (s->prev_osmesa != g->osmesa_ctx && (!s->prev_osmesa || s->fegl_ctx || s->glx_ctx))
            g->osmesa_make_current(NULL, NULL, 0, 0, 0);
    }
    if (g->mode != SFB__GL_HOST) sfb__gl_restore_foreign(g, s);
}

/* Drops the trailing newlines drivers end their logs with. */
static void sfb__gl_trim(char *log) {
    size_t n = strlen(log);
    while (n > 0 && (log[n - 1] == '\n' || log[n - 1] == '\r' || log[n - 1] == ' ')) log[--n] = 0;
}

/* ---- shaders ---- */
/* Compiles one shader of `type`: the version header for this context, `defines`, then
 * `source`. `label` names it in errors, which carry the driver's log. */
static sfb_result sfb__gl_shader(sfb__gl *g, sfb__GLenum type, const char *defines, const char *source, const char *label,
                                 sfb__GLuint *out) {
    char header[512];
    const sfb__GLchar *parts[2];
    sfb__GLuint sh;
    sfb__GLint ok = 0, len = 0;
    const char *what = type == SFB__GL_COMPUTE_SHADER ? "GL_COMPUTE_SHADER" : type == SFB__GL_VERTEX_SHADER ? "GL_VERTEX_SHADER" : "GL_FRAGMENT_SHADER";
    *out = 0;
    /* SFB_PRECISE: GLSL's `precise`, so that a compiler that fuses a * b - c * d into one
     * fused multiply-add (NVIDIA's does) keeps a cross product of parallel vectors exactly zero,
     * as ref's is; GLSL ES 3.1 has the keyword with (EXT|OES)_gpu_shader5 only (whose #extension
     * comes before the first statement), and without either the kernels run unqualified */
    snprintf(header, sizeof header, "%s%s",
             g->es ? "#version 310 es\n"
                     "#if defined(GL_EXT_gpu_shader5)\n#extension GL_EXT_gpu_shader5 : enable\n#define SFB_PRECISE precise\n"
                     "#elif defined(GL_OES_gpu_shader5)\n#extension GL_OES_gpu_shader5 : enable\n#define SFB_PRECISE precise\n"
                     "#else\n#define SFB_PRECISE\n#endif\nprecision highp float;\nprecision highp int;\n"
                   : "#version 430 core\n#define SFB_PRECISE precise\n",
             defines);
    parts[0] = header;
    parts[1] = source;
    sh = g->gl.CreateShader(type);
    if (!sh) {
        char op[64];
        sfb_result r;
        snprintf(op, sizeof op, "glCreateShader(%s)", what);
        r = sfb__gl_check(g, op);
        return r != SFB_SUCCESS ? r : sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: glCreateShader(%s) returned 0", what);
    }
    g->gl.ShaderSource(sh, 2, parts, NULL);
    g->gl.CompileShader(sh);
    g->gl.GetShaderiv(sh, SFB__GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[768];
        log[0] = 0;
        g->gl.GetShaderInfoLog(sh, (sfb__GLsizei)sizeof log, &len, log);
        sfb__gl_trim(log);
        g->gl.DeleteShader(sh);
        return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: %s failed to compile: %s", label, log);
    }
    *out = sh;
    return SFB_SUCCESS;
}

/* Links the shaders (deleted here, linked or not) into a program; `varyings` (NULL: none) are
 * captured interleaved by transform feedback. */
static sfb_result sfb__gl_link(sfb__gl *g, const sfb__GLuint *shaders, int count, const char *const *varyings, int nvaryings,
                               const char *label, sfb__GLuint *out) {
    sfb__GLuint prog = g->gl.CreateProgram();
    sfb__GLint ok = 0, len = 0;
    int i;
    *out = 0;
    for (i = 0; i < count; ++i) g->gl.AttachShader(prog, shaders[i]);
    if (varyings) g->gl.TransformFeedbackVaryings(prog, nvaryings, varyings, SFB__GL_INTERLEAVED_ATTRIBS);
    g->gl.LinkProgram(prog);
    for (i = 0; i < count; ++i) g->gl.DeleteShader(shaders[i]);
    g->gl.GetProgramiv(prog, SFB__GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[768];
        log[0] = 0;
        g->gl.GetProgramInfoLog(prog, (sfb__GLsizei)sizeof log, &len, log);
        sfb__gl_trim(log);
        g->gl.DeleteProgram(prog);
        return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: %s failed to link: %s", label, log);
    }
    *out = prog;
    return SFB_SUCCESS;
}

/* Compiles a vertex and a fragment stage (each with `defines`: vdefs for the vertex one) and
 * links them into a draw program (see sfb__gl_link for `varyings`). */
static sfb_result sfb__gl_draw_stages(sfb__gl *g, const char *vdefs, const char *vsrc, const char *vlabel, const char *fsrc, const char *flabel,
                                      const char *const *varyings, int nvaryings, const char *label, sfb__GLuint *out) {
    sfb__GLuint sh[2];
    sfb_result r;
    *out = 0;
    if ((r = sfb__gl_shader(g, SFB__GL_VERTEX_SHADER, vdefs, vsrc, vlabel, &sh[0])) != SFB_SUCCESS) return r;
    if ((r = sfb__gl_shader(g, SFB__GL_FRAGMENT_SHADER, "", fsrc, flabel, &sh[1])) != SFB_SUCCESS) {
        g->gl.DeleteShader(sh[0]);
        return r;
    }
    return sfb__gl_link(g, sh, 2, varyings, nvaryings, label, out);
}

/* Compiles and links one compute kernel (see sfb__gl_shader). */
static sfb_result sfb__gl_compile(sfb__gl *g, const char *defines, const char *source, const char *label, sfb__GLuint *out) {
    sfb__GLuint sh;
    sfb_result r = sfb__gl_shader(g, SFB__GL_COMPUTE_SHADER, defines, source, label, &sh);
    *out = 0;
    if (r != SFB_SUCCESS) return r;
    return sfb__gl_link(g, &sh, 1, NULL, 0, label, out);
}

/* Fills the function table, checks the version and reads the limits, with the context
 * current. getproc is the platform's GetProcAddress; g->libgl (if any) is the fallback. */
static sfb_result sfb__gl_setup(sfb__gl *g, sfb__glproc (*getproc)(const char *), char *why, size_t why_size) {
    const char *version, *renderer, *vendor;
    int major = 0, minor = 0;
    sfb__glproc p;
    char name[64];
#define SFB__GL_LOAD(ret, fn, args)                                                   \
    snprintf(name, sizeof name, "gl%s", #fn);                                         \
    p = getproc ? getproc(name) : NULL;                                               \
    if (!p) p = sfb__gl_dlsym(g->libgl, name);                                        \
    if (!p) {                                                                         \
        snprintf(why, why_size, "the GL library has no %s (needs OpenGL 4.3 or GLES 3.1)", name); \
        return SFB_BACKEND_UNAVAILABLE;                                               \
    }                                                                                 \
    memcpy(&g->gl.fn, &p, sizeof p);
    SFB__GL_FUNCS(SFB__GL_LOAD)
#undef SFB__GL_LOAD
    version = (const char *)g->gl.GetString(SFB__GL_VERSION);
    renderer = (const char *)g->gl.GetString(SFB__GL_RENDERER);
    vendor = (const char *)g->gl.GetString(SFB__GL_VENDOR);
    if (!version) {
        snprintf(why, why_size, "glGetString(GL_VERSION) returned NULL (no current context?)");
        return SFB_BACKEND_UNAVAILABLE;
    }
    if (strncmp(version, "OpenGL ES ", 10) == 0) {
        g->es = 1;
        sscanf(version + 10, "%d.%d", &major, &minor);
    } else {
        sscanf(version, "%d.%d", &major, &minor);
    }
    if (g->es ? (major * 10 + minor < 31) : (major * 10 + minor < 43)) {
        snprintf(why, why_size, "%s %d.%d is too old: compute shaders need OpenGL 4.3 or GLES 3.1 (%s)",
                 g->es ? "GLES" : "OpenGL", major, minor, renderer ? renderer : "unknown renderer");
        return SFB_BACKEND_UNAVAILABLE;
    }
    g->gl.GetIntegerv(SFB__GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &g->max_block);
    g->gl.GetIntegeri_v(SFB__GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &g->max_groups);
    g->gl.GetIntegerv(SFB__GL_MAX_TEXTURE_SIZE, &g->max_texture);
    if (g->max_texture < 2048) g->max_texture = 2048; /* the minimum GLES 3 guarantees */
    if (g->max_block < (1 << 16)) g->max_block = 1 << 16;     /* the minimum GL guarantees is 2^27 */
    if (g->max_groups < 1) g->max_groups = 65535;
#ifdef SFB__GL_TEST_MAX_BLOCK /* tests/gl_pieces.c: small limits force tables into pieces */
    if (g->max_block > SFB__GL_TEST_MAX_BLOCK) g->max_block = SFB__GL_TEST_MAX_BLOCK;
#endif
#ifdef SFB__GL_TEST_MAX_GROUPS
    g->max_groups = SFB__GL_TEST_MAX_GROUPS;
#endif
    while (g->gl.GetError() != SFB__GL_NO_ERROR) {}
    snprintf(g->desc, sizeof g->desc, "%s%s; %s; %s", g->es ? "" : "OpenGL ", version, renderer ? renderer : "?",
             vendor ? vendor : "?");
    return SFB_SUCCESS;
}

/* stencils.h: the stencil kernel of one SFB_LENGTH, compiled on first use */
static sfb_result sfb__gl_program(sfb__gl *g, int length, sfb__GLuint *out);

/* Compiles the most used kernel now so a broken shader compiler is an init failure. */
static sfb_result sfb__gl_warm(sfb__gl *g, char *why, size_t why_size) {
    sfb__GLuint prog;
    sfb_result r = sfb__gl_program(g, 3, &prog);
    if (r != SFB_SUCCESS) snprintf(why, why_size, "%s", g->ctx->error);
    return r;
}

static void sfb__gl_release_gl(sfb__gl *g) {
    int i;
    for (i = 0; i < 17; ++i)
        if (g->program[i]) g->gl.DeleteProgram(g->program[i]);
    for (i = 0; i < 2; ++i)
        if (g->patch_program[i]) g->gl.DeleteProgram(g->patch_program[i]);
    memset(g->patch_program, 0, sizeof g->patch_program);
    if (g->normals_program) g->gl.DeleteProgram(g->normals_program);
    g->normals_program = 0;
    for (i = 0; i < 5; ++i)
        if (g->normals_buf[i]) g->gl.DeleteBuffers(1, &g->normals_buf[i]);
    memset(g->normals_buf, 0, sizeof g->normals_buf);
    memset(g->normals_cap, 0, sizeof g->normals_cap);
    if (g->shade_program) g->gl.DeleteProgram(g->shade_program);
    g->shade_program = 0;
    for (i = 0; i < 7; ++i)
        if (g->shade_buf[i]) g->gl.DeleteBuffers(1, &g->shade_buf[i]);
    memset(g->shade_buf, 0, sizeof g->shade_buf);
    memset(g->shade_cap, 0, sizeof g->shade_cap);
    if (g->scratch_src) g->gl.DeleteBuffers(1, &g->scratch_src);
    if (g->scratch_dst) g->gl.DeleteBuffers(1, &g->scratch_dst);
    if (g->mf_program) g->gl.DeleteProgram(g->mf_program);
    if (g->sampler) g->gl.DeleteSamplers(1, &g->sampler);
    if (g->an_program) g->gl.DeleteProgram(g->an_program);
    if (g->an_vao) g->gl.DeleteVertexArrays(1, &g->an_vao);
    g->an_program = g->an_vao = 0;
    if (g->raster_program) g->gl.DeleteProgram(g->raster_program);
    if (g->raster_vao) g->gl.DeleteVertexArrays(1, &g->raster_vao);
    g->raster_program = g->raster_vao = 0;
    if (g->draw_program) g->gl.DeleteProgram(g->draw_program);
    if (g->draw_vao) g->gl.DeleteVertexArrays(1, &g->draw_vao);
    if (g->draw_ibo) g->gl.DeleteBuffers(1, &g->draw_ibo);
    if (g->draw_tfo) g->gl.DeleteTransformFeedbacks(1, &g->draw_tfo);
    g->mf_program = g->sampler = g->draw_program = g->draw_vao = g->draw_ibo = g->draw_tfo = 0;
    g->draw_rate = 0;
    memset(g->program, 0, sizeof g->program);
    g->scratch_src = g->scratch_dst = 0;
}

/* ---- the own headless EGL context ---- */
/* Opens an EGL display: the device platform (a hardware device first), then Mesa's surfaceless
 * platform, then the default display; *platform names the one found. */
static sfb_result sfb__gl_egl_display(sfb__gl *g, const char **platform, sfb__EGLint *major, sfb__EGLint *minor, char *why,
                                      size_t why_size) {
    const char *client = g->egl.QueryString(NULL, SFB__EGL_EXTENSIONS);
    int attempt;
    /* Displays are shared process-wide; terminate ours only where EGL counts references. */
    g->terminate_display = sfb__has_word(client, "EGL_KHR_display_reference");
    for (attempt = 0; attempt < 3 && !g->dpy; ++attempt) {
        sfb__EGLint attrs[3] = {SFB__EGL_NONE, 0, SFB__EGL_NONE};
        sfb__EGLDisplay d = NULL;
        if (g->terminate_display) { attrs[0] = SFB__EGL_TRACK_REFERENCES_KHR; attrs[1] = SFB__EGL_TRUE; }
        if (attempt == 0 && g->egl.GetPlatformDisplayEXT && g->egl.QueryDevicesEXT &&
            sfb__has_word(client, "EGL_EXT_platform_device")) {
            sfb__EGLDevice devs[16];
            sfb__EGLint count = 0, i, pick = 0;
            if (g->egl.QueryDevicesEXT(16, devs, &count) && count > 0) {
                /* a hardware device before Mesa's software one, when there is one */
                for (i = 0; i < count && g->egl.QueryDeviceStringEXT; ++i)
                    if (!sfb__has_word(g->egl.QueryDeviceStringEXT(devs[i], SFB__EGL_EXTENSIONS), "EGL_MESA_device_software")) {
                        pick = i;
                        break;
                    }
                d = g->egl.GetPlatformDisplayEXT(SFB__EGL_PLATFORM_DEVICE_EXT, devs[pick], attrs);
                *platform = "EGL device platform";
            }
        } else if (attempt == 1 && g->egl.GetPlatformDisplayEXT && sfb__has_word(client, "EGL_MESA_platform_surfaceless")) {
            d = g->egl.GetPlatformDisplayEXT(SFB__EGL_PLATFORM_SURFACELESS_MESA, NULL, attrs);
            *platform = "EGL surfaceless platform";
        } else if (attempt == 2) {
            d = g->egl.GetDisplay(NULL);
            *platform = "EGL default display";
            g->terminate_display = 0;
        }
        if (d && g->egl.Initialize(d, major, minor)) g->dpy = d;
    }
    if (!g->dpy) {
        snprintf(why, why_size, "no EGL display could be initialised (device, surfaceless and default; EGL error 0x%x)",
                 (unsigned)g->egl.GetError());
        return SFB_BACKEND_UNAVAILABLE;
    }
    return SFB_SUCCESS;
}

/* Creates the context on the display: desktop OpenGL 4.3 core first, then GLES 3.1. */
static sfb_result sfb__gl_egl_context(sfb__gl *g, const char *platform, sfb__EGLint major, sfb__EGLint minor, char *why, size_t why_size) {
    const char *ext = g->egl.QueryString(g->dpy, SFB__EGL_EXTENSIONS);
    sfb__EGLenum prev_api = g->egl.QueryAPI();
    int es;
    sfb__EGLint n = 0;
    sfb__EGLConfig config = NULL;
    if (!sfb__has_word(ext, "EGL_KHR_surfaceless_context")) {
        snprintf(why, why_size, "the EGL display lacks EGL_KHR_surfaceless_context");
        return SFB_BACKEND_UNAVAILABLE;
    }
    /* desktop OpenGL 4.3 core first, then GLES 3.1 */
    for (es = 0; es < 2 && !g->egl_ctx; ++es) {
        sfb__EGLint cattrs[] = {SFB__EGL_RENDERABLE_TYPE, es ? SFB__EGL_OPENGL_ES3_BIT : SFB__EGL_OPENGL_BIT, SFB__EGL_NONE};
        sfb__EGLint gl_attrs[] = {SFB__EGL_CONTEXT_MAJOR_VERSION, 4, SFB__EGL_CONTEXT_MINOR_VERSION, 3,
                                  SFB__EGL_CONTEXT_OPENGL_PROFILE_MASK, SFB__EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, SFB__EGL_NONE};
        sfb__EGLint es_attrs[] = {SFB__EGL_CONTEXT_MAJOR_VERSION, 3, SFB__EGL_CONTEXT_MINOR_VERSION, 1, SFB__EGL_NONE};
        sfb__EGLenum api = es ? SFB__EGL_OPENGL_ES_API : SFB__EGL_OPENGL_API;
        if (!g->egl.BindAPI(api)) continue;
        config = NULL;
        n = 0;
        if (!sfb__has_word(ext, "EGL_KHR_no_config_context") && !sfb__has_word(ext, "EGL_MESA_configless_context")) {
            if (!g->egl.ChooseConfig(g->dpy, cattrs, &config, 1, &n) || n < 1) continue;
        }
        g->egl_ctx = g->egl.CreateContext(g->dpy, config, NULL, es ? es_attrs : gl_attrs);
        if (g->egl_ctx) g->egl_api = api;
    }
    g->egl.BindAPI(prev_api);
    if (!g->egl_ctx) {
        snprintf(why, why_size, "%s (EGL %d.%d, %s): no OpenGL 4.3 core or GLES 3.1 context (EGL error 0x%x)", platform,
                 (int)major, (int)minor, g->egl.QueryString(g->dpy, SFB__EGL_VENDOR), (unsigned)g->egl.GetError());
        return SFB_BACKEND_UNAVAILABLE;
    }
    return SFB_SUCCESS;
}

static sfb_result sfb__gl_egl_open(sfb__gl *g, char *why, size_t why_size) {
    static const char *const egl_names[] = SFB__EGL_LIBRARY_NAMES;
    sfb__EGLint major = 0, minor = 0;
    const char *platform = "default display";
    char err[256] = "";
    sfb_result r0;
    g->libegl = sfb__gl_dlopen(egl_names, err, sizeof err);
    if (!g->libegl) {
        snprintf(why, why_size, "libEGL.so.1 not found (Debian: libegl1 and a driver, e.g. libegl-mesa0): %s", err);
        return SFB_BACKEND_UNAVAILABLE;
    }
    if (!sfb__egl_load(g->libegl, &g->egl)) {
        snprintf(why, why_size, "libEGL lacks EGL 1.4 entry points");
        return SFB_BACKEND_UNAVAILABLE;
    }
    if ((r0 = sfb__gl_egl_display(g, &platform, &major, &minor, why, why_size)) != SFB_SUCCESS) return r0;
    if ((r0 = sfb__gl_egl_context(g, platform, major, minor, why, why_size)) != SFB_SUCCESS) return r0;
    g->mode = SFB__GL_OWN_EGL;
    {
        size_t used;
        sfb__gl_saved s;
        sfb_result r;
        static const char *const gl_names[] = {"libOpenGL.so.0", "libGL.so.1", "libGLESv2.so.2", NULL};
        g->libgl = sfb__gl_dlopen(gl_names, NULL, 0);
        /* Make it current without the state save (the function table is not loaded yet). */
        memset(&s, 0, sizeof s);
        sfb__gl_save_foreign(g, &s);
        s.api = g->egl.QueryAPI();
        s.prev_ctx = g->egl.GetCurrentContext();
        s.prev_dpy = g->egl.GetCurrentDisplay();
        s.prev_draw = g->egl.GetCurrentSurface(SFB__EGL_DRAW);
        s.prev_read = g->egl.GetCurrentSurface(SFB__EGL_READ);
        g->egl.BindAPI(g->egl_api);
        if (!g->egl.MakeCurrent(g->dpy, NULL, NULL, g->egl_ctx)) {
            g->egl.BindAPI(s.api);
            sfb__gl_restore_foreign(g, &s);
            snprintf(why, why_size, "eglMakeCurrent on the new context failed (EGL error 0x%x)", (unsigned)g->egl.GetError());
            return SFB_BACKEND_UNAVAILABLE;
        }
        r = sfb__gl_setup(g, g->egl.GetProcAddress, why, why_size);
        if (r == SFB_SUCCESS) r = sfb__gl_warm(g, why, why_size);
        if (s.prev_ctx) {
            g->egl.BindAPI(s.api);
            g->egl.MakeCurrent(s.prev_dpy, s.prev_draw, s.prev_read, s.prev_ctx);
        } else {
            g->egl.MakeCurrent(g->dpy, NULL, NULL, NULL);
            g->egl.BindAPI(s.api);
        }
        sfb__gl_restore_foreign(g, &s);
        if (r != SFB_SUCCESS) return r;
        used = strlen(g->desc);
        snprintf(g->desc + used, sizeof g->desc - used, "; headless %s", platform);
    }
    return SFB_SUCCESS;
}

/* ---- the host's current context (EGL or GLX) ---- */
static sfb_result sfb__gl_host_open(sfb__gl *g, char *why, size_t why_size) {
    static const char *const egl_names[] = {"libEGL.so.1", "libEGL.so", NULL};
    static const char *const glx_names[] = {"libGL.so.1", "libGL.so", NULL};
    sfb_result r;
    sfb__glproc (*getproc)(const char *) = NULL;
    const char *via = NULL;
    void *lib;
    g->mode = SFB__GL_HOST;
#if !defined(_WIN32)
    /* EGL the host already loaded, with a context current on this thread */
    if ((lib = dlopen(egl_names[0], RTLD_LAZY | RTLD_LOCAL | RTLD_NOLOAD)) != NULL ||
        (lib = dlopen(egl_names[1], RTLD_LAZY | RTLD_LOCAL | RTLD_NOLOAD)) != NULL) {
        if (sfb__egl_load(lib, &g->egl) && g->egl.GetCurrentContext()) {
            g->libegl = lib;
            getproc = g->egl.GetProcAddress;
            via = "the host's EGL context";
        } else {
            dlclose(lib);
            memset(&g->egl, 0, sizeof g->egl);
        }
    }
    if (!getproc && ((lib = dlopen(glx_names[0], RTLD_LAZY | RTLD_LOCAL | RTLD_NOLOAD)) != NULL ||
                     (lib = dlopen(glx_names[1], RTLD_LAZY | RTLD_LOCAL | RTLD_NOLOAD)) != NULL)) {
        sfb__glproc cur = sfb__gl_dlsym(lib, "glXGetCurrentContext");
        sfb__glproc gpa = sfb__gl_dlsym(lib, "glXGetProcAddressARB");
        void *(*get_current)(void) = NULL;
        memcpy(&get_current, &cur, sizeof cur);
        if (get_current && gpa && get_current()) {
            memcpy(&getproc, &gpa, sizeof gpa);
            g->libgl = lib;
            via = "the host's GLX context";
        } else {
            dlclose(lib);
        }
    }
#else
    (void)egl_names; (void)glx_names; (void)lib;
#endif
    if (!getproc) {
        snprintf(why, why_size, "gl_use_current_context is set but no EGL or GLX context is current on this thread");
        return SFB_BACKEND_UNAVAILABLE;
    }
    r = sfb__gl_setup(g, getproc, why, why_size);
    if (r == SFB_SUCCESS) {
        sfb__gl_saved s;
        r = sfb__gl_enter(g, &s);
        if (r == SFB_SUCCESS) {
            r = sfb__gl_warm(g, why, why_size);
            sfb__gl_leave(g, &s);
        }
    }
    if (r == SFB_SUCCESS) {
        size_t used = strlen(g->desc);
        snprintf(g->desc + used, sizeof g->desc - used, "; on %s", via);
    }
    return r;
}

static void sfb__gl_close(sfb__gl *g) {
    sfb__gl_saved s;
    sfb__pool_stop(&g->pool); /* a zeroed pool (never started) stops as one of one thread */
    if (g->gl.GetError && sfb__gl_enter(g, &s) == SFB_SUCCESS) {
        sfb__gl_release_gl(g);
        sfb__gl_leave(g, &s);
    }
    if (g->mode == SFB__GL_OWN_EGL && g->egl_ctx) g->egl.DestroyContext(g->dpy, g->egl_ctx);
    if (g->mode == SFB__GL_OWN_EGL && g->dpy && g->terminate_display) g->egl.Terminate(g->dpy);
    if (g->mode == SFB__GL_OSMESA && g->osmesa_ctx) g->osmesa_destroy(g->osmesa_ctx);
    /* Driver libraries stay loaded: unloading Mesa while it keeps per-thread state is unsafe. */
    (void)sfb__gl_dlclose;
}

/* The CPU threads the backend lends to the core (ctx->threads as simd's: 0 is one per online
 * core). The GPU runs the kernels; the core's own per-pixel and per-location loops between
 * them (the analysis's seeding, Newton updates, neighbour scans and colours) ran on one thread
 * and were most of an analysis's time on a GPU host: on an NVIDIA H200 with 16 cores,
 * catmark_car's 1024 x 1024 reflection picture took 157-208 ms on gl against 35-38 ms on simd. */
static sfb_result sfb__gl_pool_open(sfb__gl *g, char *why, size_t why_size) {
    return sfb__pool_start(&g->pool, sfb__pool_threads(g->ctx->threads), why, why_size) ? SFB_SUCCESS : SFB_BACKEND_UNAVAILABLE;
}

/* The `parallel` slot. */
static int sfb__gl_parallel(void *state, void (*task)(void *arg, int first, int last), void *arg, int first, int last) {
    return state ? sfb__pool_lend(&((sfb__gl *)state)->pool, task, arg, first, last) : 0;
}

static sfb_result sfb__gl_init(sfb_context *ctx, void **state, char *why, size_t why_size) {
    sfb__gl *g = (sfb__gl *)sfb__calloc(ctx, 1, sizeof *g);
    sfb_result r;
    if (!g) { snprintf(why, why_size, "out of memory"); return SFB_OUT_OF_MEMORY; }
    g->ctx = ctx;
    r = ctx->gl_use_current_context ? sfb__gl_host_open(g, why, why_size) : sfb__gl_egl_open(g, why, why_size);
    if (r == SFB_SUCCESS) r = sfb__gl_pool_open(g, why, why_size);
    if (r != SFB_SUCCESS) {
        sfb__gl_close(g);
        sfb__free(ctx, g);
        return r;
    }
    *state = g;
    return SFB_SUCCESS;
}

static void sfb__gl_shutdown(sfb_context *ctx, void *state) {
    sfb__gl *g = (sfb__gl *)state;
    if (!g) return;
    sfb__gl_close(g);
    sfb__free(ctx, g);
}

static void sfb__gl_describe(void *state, char *buf, size_t size) {
    const sfb__gl *g = (const sfb__gl *)state;
    snprintf(buf, size, "%s", g ? g->desc : "");
}

/* Bytes a buffer view spans: offset + (count-1)*stride + length floats. */
static size_t sfb__gl_span(int count, sfb_buffer_desc d) {
    if (count <= 0) return 0;
    return ((size_t)d.offset + (size_t)(count - 1) * (size_t)d.stride + (size_t)d.length) * sizeof(float);
}

static sfb_result sfb__gl_grow(sfb__gl *g, sfb__GLuint *buf, size_t *cap, size_t bytes, sfb__GLenum usage) {
    if (!*buf) g->gl.GenBuffers(1, buf);
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, *buf);
    if (bytes > *cap) {
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)bytes, NULL, usage);
        *cap = bytes;
    }
    return sfb__gl_check(g, "allocating a scratch buffer");
}

/* Runs the program in use over invocations [a, b), in dispatches of at most
 * GL_MAX_COMPUTE_WORK_GROUP_COUNT groups of 64, each told its range by the uniforms at
 * loc_first and loc_last. */
static void sfb__gl_dispatch_range(sfb__gl *g, sfb__GLint loc_first, sfb__GLint loc_last, int a, int b) {
    long long per = (long long)g->max_groups * 64;
    while (a < b) {
        int n = (long long)(b - a) > per ? (int)per : b - a;
        g->gl.Uniform1i(loc_first, a);
        g->gl.Uniform1i(loc_last, a + n);
        g->gl.DispatchCompute((sfb__GLuint)((n + 63) / 64), 1, 1);
        a += n;
    }
}

/* Waits for the `bytes` of results a kernel wrote into the scratch destination and maps them
 * for reading; sfb__gl_unmap_results ends the read. */
static sfb_result sfb__gl_map_results(sfb__gl *g, size_t bytes, const float **mapped) {
    g->gl.MemoryBarrier(SFB__GL_BUFFER_UPDATE_BARRIER_BIT);
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, g->scratch_dst);
    *mapped = (const float *)g->gl.MapBufferRange(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)bytes, SFB__GL_MAP_READ_BIT);
    if (!*mapped) {
        sfb_result res = sfb__gl_check(g, "mapping the results");
        return res != SFB_SUCCESS ? res : sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: glMapBufferRange returned NULL");
    }
    return SFB_SUCCESS;
}

static sfb_result sfb__gl_unmap_results(sfb__gl *g) {
    g->gl.UnmapBuffer(SFB__GL_SHADER_STORAGE_BUFFER);
    return sfb__gl_check(g, "reading the results back");
}

/* ---- patch tables: what the families share (their kernels: patches.h, manifold.h) ---- */
/* An uploaded patch table, the handle upload_patches returns. `family` (SFB__FAMILY_*) says
 * which family's kernel reads it, and so which members it fills. */
typedef struct sfb__gl_ptable {
    int family;
    /* the polynomial families (patches.h): consecutive patch ranges, each fitting the storage
     * blocks */
    int count;
    struct sfb__gl_ppiece *pieces;
    /* MANIFOLD4 (manifold.h, no pieces): its two textures (manifold.comp.glsl), their row
     * width, and the first patch texel of the integer one */
    sfb__GLuint mf_tex[2];
    int mf_width, mf_patch_base;
} sfb__gl_ptable;

/* A location as the patch kernels read it (std430 struct SfbQuery). */
typedef struct sfb__gl_query {
    int patch;           /* piece-local */
    float s, t;          /* Stam and Stam-Loop patches: (u,v) in the EV's frame instead of (s,t) */
    float scale;         /* +-2^depth: negative after an odd number of middle triangles (Loop) */
} sfb__gl_query;

/* Queries per batch: a batch's queries, and its results of `stride` floats each, fit one
 * storage block. */
static size_t sfb__gl_query_batch(const sfb__gl *g, int stride) {
    size_t batch = (size_t)g->max_block / ((size_t)stride * sizeof(float));
    if (batch > (size_t)g->max_block / sizeof(sfb__gl_query)) batch = (size_t)g->max_block / sizeof(sfb__gl_query);
    return batch < 1 ? 1 : batch;
}

/* A batch's `qbytes` of queries into the scratch source (binding 4), and room for its `rbytes`
 * of results in the scratch destination (binding 5). */
static sfb_result sfb__gl_query_buffers(sfb__gl *g, const sfb__gl_query *queries, size_t qbytes, size_t rbytes) {
    sfb_result res;
    if ((res = sfb__gl_grow(g, &g->scratch_src, &g->scratch_src_cap, qbytes, SFB__GL_STREAM_DRAW)) != SFB_SUCCESS) return res;
    g->gl.BufferSubData(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)qbytes, queries);
    if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, rbytes, SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS) return res;
    g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 4, g->scratch_src);
    g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 5, g->scratch_dst);
    return SFB_SUCCESS;
}

/* Copies n compact result rows of `stride` floats (output o's xyz at 3 * slot[o]) into the
 * caller's arrays dst[o] that are not NULL, row k at location order[k] (base + k without an
 * order). */
static void sfb__gl_scatter(float *const *dst, const sfb__GLint *slot, int outputs, const float *mapped, int stride, int n,
                            const int *order, int base) {
    int k, o;
    for (k = 0; k < n; ++k) {
        size_t at = 3 * (size_t)(order ? order[k] : base + k);
        const float *r = mapped + (size_t)k * (size_t)stride;
        for (o = 0; o < outputs; ++o)
            if (dst[o]) {
                const float *x = r + 3 * slot[o];
                dst[o][at] = x[0];
                dst[o][at + 1] = x[1];
                dst[o][at + 2] = x[2];
            }
    }
}

/* vtable.h: the patch-table slots, which hand a table to its family's kernels (the families'
 * binds point the slots here). */
static sfb_result sfb__gl_upload_patches(void *state, const sfb__patch_table *pt, void **handle);
static void sfb__gl_release_patches(void *state, void *handle);
static sfb_result sfb__gl_eval_patches(void *state, const sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                       int last, const sfb_eval_output *out);

#endif /* SFB__GL_RUNTIME_H */
