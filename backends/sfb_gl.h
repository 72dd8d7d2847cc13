/* backends/sfb_gl.h -- the `gl` backend: the kernels as OpenGL 4.3 / GLES 3.1 compute shaders
 * over shader storage buffers.
 *
 * Compiled by surfblend.h's implementation when SURFBLEND_GL (or SURFBLEND_OSMESA,
 * SURFBLEND_ALL_BACKENDS) is defined next to SURFBLEND_IMPLEMENTATION; do not include it
 * directly. It sees the core's private declarations (src/sfb_internal.h).
 *
 * Two ways in:
 *  - own context (default): a headless context made through EGL -- the device platform
 *    first (GPUs without a display server), then Mesa's surfaceless platform, then the
 *    default display. It is made current for the length of each call and the thread's
 *    previous EGL context (and bound API) is restored afterwards.
 *  - the host's context (sfb_context_config.gl_use_current_context): the engine case. The
 *    host's EGL or GLX context must be current on the calling thread for every call, from
 *    sfb_context_create to sfb_context_destroy. What a call binds (program, generic and
 *    indexed SSBO bindings 0..5) is saved first and restored after, and
 *    sfb_surface_eval_stencils_gl writes straight into the host's buffer objects.
 *
 * GL, EGL (and, in sfb_osmesa.h, OSMesa) are loaded at run time with dlopen, reusing a
 * library the process already loaded; nothing links -lGL or -lEGL. Types and constants are
 * declared here so no GL header is needed to build. Shaders are the .glsl files in backends/glsl,
 * embedded into sfb_gl_shaders.h by `make embed-glsl`.
 */
#ifndef SFB__GL_H
#define SFB__GL_H

#if !defined(_WIN32)
#include <dlfcn.h>
#endif
#include "sfb_gl_shaders.h"

/* Build-time overrides, used by tests/gl_errors.c to exercise the failure paths for real: the
 * kernel source, and the library names tried by dlopen (NULL-terminated initialisers). */
#ifndef SFB__GL_STENCIL_SOURCE
#define SFB__GL_STENCIL_SOURCE sfb__glsl_stencils_comp_glsl
#endif
#ifndef SFB__EGL_LIBRARY_NAMES
#define SFB__EGL_LIBRARY_NAMES {"libEGL.so.1", "libEGL.so", NULL}
#endif
#ifndef SFB__OSMESA_LIBRARY_NAMES
#define SFB__OSMESA_LIBRARY_NAMES {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so", NULL}
#endif

/* ---- GL types and the constants we use (values from the Khronos registry) ---- */
typedef unsigned int sfb__GLenum;
typedef unsigned int sfb__GLuint;
typedef int sfb__GLint;
typedef int sfb__GLsizei;
typedef ptrdiff_t sfb__GLsizeiptr;
typedef ptrdiff_t sfb__GLintptr;
typedef unsigned char sfb__GLubyte;
typedef unsigned char sfb__GLboolean;
typedef unsigned int sfb__GLbitfield;
typedef char sfb__GLchar;
typedef long long sfb__GLint64;
#if defined(_WIN32)
#define SFB__GLAPI __stdcall
#else
#define SFB__GLAPI
#endif
typedef void (*sfb__glproc)(void);

enum {
    SFB__GL_NO_ERROR = 0, SFB__GL_OUT_OF_MEMORY = 0x0505,
    SFB__GL_VENDOR = 0x1F00, SFB__GL_RENDERER = 0x1F01, SFB__GL_VERSION = 0x1F02,
    SFB__GL_UNSIGNED_BYTE = 0x1401, SFB__GL_RGBA = 0x1908,
    SFB__GL_COMPUTE_SHADER = 0x91B9, SFB__GL_COMPILE_STATUS = 0x8B81, SFB__GL_LINK_STATUS = 0x8B82,
    SFB__GL_INFO_LOG_LENGTH = 0x8B84, SFB__GL_CURRENT_PROGRAM = 0x8B8D,
    SFB__GL_SHADER_STORAGE_BUFFER = 0x90D2, SFB__GL_SHADER_STORAGE_BUFFER_BINDING = 0x90D3,
    SFB__GL_SHADER_STORAGE_BUFFER_START = 0x90D4, SFB__GL_SHADER_STORAGE_BUFFER_SIZE = 0x90D5,
    SFB__GL_MAX_SHADER_STORAGE_BLOCK_SIZE = 0x90DE, SFB__GL_MAX_COMPUTE_WORK_GROUP_COUNT = 0x91BE,
    SFB__GL_STATIC_DRAW = 0x88E4, SFB__GL_STREAM_DRAW = 0x88E0, SFB__GL_DYNAMIC_READ = 0x88E9,
    SFB__GL_MAP_READ_BIT = 0x0001, SFB__GL_BUFFER_SIZE = 0x8764
};
#define SFB__GL_ALL_BARRIER_BITS 0xFFFFFFFFu
#define SFB__GL_BUFFER_UPDATE_BARRIER_BIT 0x00000200u

/* The GL entry points the kernels use: one typed table, filled by name at init. */
#define SFB__GL_FUNCS(X)                                                                              \
    X(sfb__GLenum, GetError, (void))                                                                  \
    X(const sfb__GLubyte *, GetString, (sfb__GLenum))                                                 \
    X(void, GetIntegerv, (sfb__GLenum, sfb__GLint *))                                                 \
    X(void, GetIntegeri_v, (sfb__GLenum, sfb__GLuint, sfb__GLint *))                                  \
    X(void, GetInteger64i_v, (sfb__GLenum, sfb__GLuint, sfb__GLint64 *))                              \
    X(sfb__GLuint, CreateShader, (sfb__GLenum))                                                       \
    X(void, ShaderSource, (sfb__GLuint, sfb__GLsizei, const sfb__GLchar *const *, const sfb__GLint *)) \
    X(void, CompileShader, (sfb__GLuint))                                                             \
    X(void, GetShaderiv, (sfb__GLuint, sfb__GLenum, sfb__GLint *))                                    \
    X(void, GetShaderInfoLog, (sfb__GLuint, sfb__GLsizei, sfb__GLsizei *, sfb__GLchar *))             \
    X(void, DeleteShader, (sfb__GLuint))                                                              \
    X(sfb__GLuint, CreateProgram, (void))                                                             \
    X(void, AttachShader, (sfb__GLuint, sfb__GLuint))                                                 \
    X(void, LinkProgram, (sfb__GLuint))                                                               \
    X(void, GetProgramiv, (sfb__GLuint, sfb__GLenum, sfb__GLint *))                                   \
    X(void, GetProgramInfoLog, (sfb__GLuint, sfb__GLsizei, sfb__GLsizei *, sfb__GLchar *))            \
    X(void, DeleteProgram, (sfb__GLuint))                                                             \
    X(void, UseProgram, (sfb__GLuint))                                                                \
    X(sfb__GLint, GetUniformLocation, (sfb__GLuint, const sfb__GLchar *))                             \
    X(void, Uniform1i, (sfb__GLint, sfb__GLint))                                                      \
    X(void, GenBuffers, (sfb__GLsizei, sfb__GLuint *))                                                \
    X(void, DeleteBuffers, (sfb__GLsizei, const sfb__GLuint *))                                       \
    X(void, BindBuffer, (sfb__GLenum, sfb__GLuint))                                                   \
    X(void, BufferData, (sfb__GLenum, sfb__GLsizeiptr, const void *, sfb__GLenum))                    \
    X(void, BufferSubData, (sfb__GLenum, sfb__GLintptr, sfb__GLsizeiptr, const void *))               \
    X(void, BindBufferBase, (sfb__GLenum, sfb__GLuint, sfb__GLuint))                                  \
    X(void, BindBufferRange, (sfb__GLenum, sfb__GLuint, sfb__GLuint, sfb__GLintptr, sfb__GLsizeiptr)) \
    X(void, GetBufferParameteriv, (sfb__GLenum, sfb__GLenum, sfb__GLint *))                           \
    X(void *, MapBufferRange, (sfb__GLenum, sfb__GLintptr, sfb__GLsizeiptr, sfb__GLbitfield))         \
    X(sfb__GLboolean, UnmapBuffer, (sfb__GLenum))                                                     \
    X(void, DispatchCompute, (sfb__GLuint, sfb__GLuint, sfb__GLuint))                                 \
    X(void, MemoryBarrier, (sfb__GLbitfield))                                                         \
    X(void, Finish, (void))

typedef struct sfb__glfns {
#define SFB__GL_MEMBER(ret, name, args) ret(SFB__GLAPI *name) args;
    SFB__GL_FUNCS(SFB__GL_MEMBER)
#undef SFB__GL_MEMBER
} sfb__glfns;

/* ---- run-time loading ---- */
/* dlopen that reuses a library the process already has before loading one. On failure `err`
 * (if given) gets the loader's message for the first name. */
static void *sfb__gl_dlopen(const char *const *names, char *err, size_t err_size) {
#if defined(_WIN32)
    (void)names;
    if (err && err_size) snprintf(err, err_size, "run-time GL loading is not implemented on Windows yet");
    return NULL;
#else
    int i;
    void *h;
    for (i = 0; names[i]; ++i)
        if ((h = dlopen(names[i], RTLD_LAZY | RTLD_LOCAL | RTLD_NOLOAD)) != NULL) return h;
    for (i = 0; names[i]; ++i) {
        if ((h = dlopen(names[i], RTLD_LAZY | RTLD_LOCAL)) != NULL) return h;
        if (i == 0 && err && err_size) {
            const char *e = dlerror();
            snprintf(err, err_size, "%s", e ? e : "dlopen failed");
        }
    }
    return NULL;
#endif
}

static sfb__glproc sfb__gl_dlsym(void *lib, const char *name) {
    sfb__glproc f = NULL;
#if !defined(_WIN32)
    void *p = lib ? dlsym(lib, name) : NULL;
    memcpy(&f, &p, sizeof f); /* object to function pointer, without a pedantic cast */
#else
    (void)lib; (void)name;
#endif
    return f;
}

static void sfb__gl_dlclose(void *lib) {
#if !defined(_WIN32)
    if (lib) dlclose(lib);
#else
    (void)lib;
#endif
}

/* ---- EGL (own headless context, or detecting the host's) ---- */
typedef void *sfb__EGLDisplay;
typedef void *sfb__EGLContext;
typedef void *sfb__EGLSurface;
typedef void *sfb__EGLConfig;
typedef void *sfb__EGLDevice;
typedef int sfb__EGLint;
typedef unsigned int sfb__EGLBoolean;
typedef unsigned int sfb__EGLenum;
enum {
    SFB__EGL_NONE = 0x3038, SFB__EGL_EXTENSIONS = 0x3055, SFB__EGL_VENDOR = 0x3053,
    SFB__EGL_DRAW = 0x3059, SFB__EGL_READ = 0x305A,
    SFB__EGL_OPENGL_API = 0x30A2, SFB__EGL_OPENGL_ES_API = 0x30A0,
    SFB__EGL_OPENGL_BIT = 0x0008, SFB__EGL_OPENGL_ES3_BIT = 0x0040, SFB__EGL_PBUFFER_BIT = 0x0001,
    SFB__EGL_RENDERABLE_TYPE = 0x3040, SFB__EGL_SURFACE_TYPE = 0x3033,
    SFB__EGL_CONTEXT_MAJOR_VERSION = 0x3098, SFB__EGL_CONTEXT_MINOR_VERSION = 0x30FB,
    SFB__EGL_CONTEXT_OPENGL_PROFILE_MASK = 0x30FD, SFB__EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT = 1,
    SFB__EGL_PLATFORM_DEVICE_EXT = 0x313F, SFB__EGL_PLATFORM_SURFACELESS_MESA = 0x31DD,
    SFB__EGL_TRACK_REFERENCES_KHR = 0x3352, SFB__EGL_TRUE = 1
};

#define SFB__EGL_FUNCS(X)                                                                               \
    X(sfb__EGLint, GetError, (void))                                                                    \
    X(sfb__EGLDisplay, GetDisplay, (void *))                                                            \
    X(sfb__EGLBoolean, Initialize, (sfb__EGLDisplay, sfb__EGLint *, sfb__EGLint *))                     \
    X(sfb__EGLBoolean, Terminate, (sfb__EGLDisplay))                                                    \
    X(const char *, QueryString, (sfb__EGLDisplay, sfb__EGLint))                                        \
    X(sfb__EGLBoolean, BindAPI, (sfb__EGLenum))                                                         \
    X(sfb__EGLenum, QueryAPI, (void))                                                                   \
    X(sfb__EGLBoolean, ChooseConfig, (sfb__EGLDisplay, const sfb__EGLint *, sfb__EGLConfig *, sfb__EGLint, sfb__EGLint *)) \
    X(sfb__EGLContext, CreateContext, (sfb__EGLDisplay, sfb__EGLConfig, sfb__EGLContext, const sfb__EGLint *)) \
    X(sfb__EGLBoolean, DestroyContext, (sfb__EGLDisplay, sfb__EGLContext))                              \
    X(sfb__EGLBoolean, MakeCurrent, (sfb__EGLDisplay, sfb__EGLSurface, sfb__EGLSurface, sfb__EGLContext)) \
    X(sfb__EGLContext, GetCurrentContext, (void))                                                       \
    X(sfb__EGLDisplay, GetCurrentDisplay, (void))                                                       \
    X(sfb__EGLSurface, GetCurrentSurface, (sfb__EGLint))                                                \
    X(sfb__glproc, GetProcAddress, (const char *))

typedef struct sfb__eglfns {
#define SFB__EGL_MEMBER(ret, name, args) ret (*name) args;
    SFB__EGL_FUNCS(SFB__EGL_MEMBER)
#undef SFB__EGL_MEMBER
    sfb__EGLDisplay (*GetPlatformDisplayEXT)(sfb__EGLenum, void *, const sfb__EGLint *);
    sfb__EGLBoolean (*QueryDevicesEXT)(sfb__EGLint, sfb__EGLDevice *, sfb__EGLint *);
    const char *(*QueryDeviceStringEXT)(sfb__EGLDevice, sfb__EGLint);
} sfb__eglfns;

static int sfb__egl_load(void *lib, sfb__eglfns *e) {
    sfb__glproc p;
    memset(e, 0, sizeof *e);
#define SFB__EGL_LOAD(ret, name, args)                       \
    p = sfb__gl_dlsym(lib, "egl" #name);                     \
    if (!p) return 0;                                        \
    memcpy(&e->name, &p, sizeof p);
    SFB__EGL_FUNCS(SFB__EGL_LOAD)
#undef SFB__EGL_LOAD
    p = e->GetProcAddress("eglGetPlatformDisplayEXT");
    memcpy(&e->GetPlatformDisplayEXT, &p, sizeof p);
    p = e->GetProcAddress("eglQueryDevicesEXT");
    memcpy(&e->QueryDevicesEXT, &p, sizeof p);
    p = e->GetProcAddress("eglQueryDeviceStringEXT");
    memcpy(&e->QueryDeviceStringEXT, &p, sizeof p);
    return 1;
}

static int sfb__has_word(const char *list, const char *word) {
    size_t n = strlen(word);
    const char *p = list;
    if (!list) return 0;
    while ((p = strstr(p, word)) != NULL) {
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == 0)) return 1;
        p += n;
    }
    return 0;
}

/* ---- the backend state, shared by gl and osmesa ---- */
enum { SFB__GL_HOST = 0, SFB__GL_OWN_EGL = 1, SFB__GL_OSMESA = 2 };
enum { SFB__GL_BINDINGS = 6 }; /* SSBO binding points 0..5 used by the shaders */

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
    sfb__GLuint scratch_src, scratch_dst;
    size_t scratch_src_cap, scratch_dst_cap;
    char desc[320];
} sfb__gl;

/* One piece of an uploaded stencil table: rows [row0, row1) with their entries, small enough
 * for GL_MAX_SHADER_STORAGE_BLOCK_SIZE. */
typedef struct sfb__gl_piece {
    int row0, row1, entry0;
    sfb__GLuint buf[4]; /* sizes, offsets, indices, weights */
} sfb__gl_piece;
typedef struct sfb__gl_table {
    int count;
    sfb__gl_piece *pieces;
} sfb__gl_table;

static const char *const sfb__gl_uniforms[8] = {"u_first", "u_last", "u_entry_base", "u_row_base",
                                                "u_src_offset", "u_src_stride", "u_dst_offset", "u_dst_stride"};

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
static sfb_result sfb__gl_program(sfb__gl *g, int length, sfb__GLuint *out) {
    char header[160];
    const sfb__GLchar *parts[2];
    sfb__GLuint sh, prog;
    sfb__GLint ok = 0, len = 0;
    int i;
    if (g->program[length]) { *out = g->program[length]; return SFB_SUCCESS; }
    snprintf(header, sizeof header, "%s#define SFB_LENGTH %d\n",
             g->es ? "#version 310 es\nprecision highp float;\nprecision highp int;\n" : "#version 430 core\n", length);
    parts[0] = header;
    parts[1] = SFB__GL_STENCIL_SOURCE;
    sh = g->gl.CreateShader(SFB__GL_COMPUTE_SHADER);
    if (!sh) {
        sfb_result r = sfb__gl_check(g, "glCreateShader(GL_COMPUTE_SHADER)");
        return r != SFB_SUCCESS ? r : sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: glCreateShader(GL_COMPUTE_SHADER) returned 0");
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
        return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1,
                          "gl: stencils.comp.glsl (SFB_LENGTH %d) failed to compile: %s", length, log);
    }
    prog = g->gl.CreateProgram();
    g->gl.AttachShader(prog, sh);
    g->gl.LinkProgram(prog);
    g->gl.DeleteShader(sh);
    g->gl.GetProgramiv(prog, SFB__GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[768];
        log[0] = 0;
        g->gl.GetProgramInfoLog(prog, (sfb__GLsizei)sizeof log, &len, log);
        sfb__gl_trim(log);
        g->gl.DeleteProgram(prog);
        return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1,
                          "gl: stencils.comp.glsl (SFB_LENGTH %d) failed to link: %s", length, log);
    }
    for (i = 0; i < 8; ++i) g->loc[length][i] = g->gl.GetUniformLocation(prog, sfb__gl_uniforms[i]);
    g->program[length] = prog;
    *out = prog;
    return sfb__gl_check(g, "building the stencil kernel");
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
    if (g->scratch_src) g->gl.DeleteBuffers(1, &g->scratch_src);
    if (g->scratch_dst) g->gl.DeleteBuffers(1, &g->scratch_dst);
    memset(g->program, 0, sizeof g->program);
    g->scratch_src = g->scratch_dst = 0;
}

/* ---- the own headless EGL context ---- */
static sfb_result sfb__gl_egl_open(sfb__gl *g, char *why, size_t why_size) {
    static const char *const egl_names[] = SFB__EGL_LIBRARY_NAMES;
    const char *client;
    sfb__EGLint major = 0, minor = 0, n = 0;
    sfb__EGLConfig config = NULL;
    const char *platform = "default display";
    int attempt;
    char err[256] = "";
    g->libegl = sfb__gl_dlopen(egl_names, err, sizeof err);
    if (!g->libegl) {
        snprintf(why, why_size, "libEGL.so.1 not found (Debian: libegl1 and a driver, e.g. libegl-mesa0): %s", err);
        return SFB_BACKEND_UNAVAILABLE;
    }
    if (!sfb__egl_load(g->libegl, &g->egl)) {
        snprintf(why, why_size, "libEGL lacks EGL 1.4 entry points");
        return SFB_BACKEND_UNAVAILABLE;
    }
    client = g->egl.QueryString(NULL, SFB__EGL_EXTENSIONS);
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
                platform = "EGL device platform";
            }
        } else if (attempt == 1 && g->egl.GetPlatformDisplayEXT && sfb__has_word(client, "EGL_MESA_platform_surfaceless")) {
            d = g->egl.GetPlatformDisplayEXT(SFB__EGL_PLATFORM_SURFACELESS_MESA, NULL, attrs);
            platform = "EGL surfaceless platform";
        } else if (attempt == 2) {
            d = g->egl.GetDisplay(NULL);
            platform = "EGL default display";
            g->terminate_display = 0;
        }
        if (d && g->egl.Initialize(d, &major, &minor)) g->dpy = d;
    }
    if (!g->dpy) {
        snprintf(why, why_size, "no EGL display could be initialised (device, surfaceless and default; EGL error 0x%x)",
                 (unsigned)g->egl.GetError());
        return SFB_BACKEND_UNAVAILABLE;
    }
    {
        const char *ext = g->egl.QueryString(g->dpy, SFB__EGL_EXTENSIONS);
        sfb__EGLenum prev_api = g->egl.QueryAPI();
        int es;
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
    }
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

static sfb_result sfb__gl_init(sfb_context *ctx, void **state, char *why, size_t why_size) {
    sfb__gl *g = (sfb__gl *)sfb__calloc(ctx, 1, sizeof *g);
    sfb_result r;
    if (!g) { snprintf(why, why_size, "out of memory"); return SFB_OUT_OF_MEMORY; }
    g->ctx = ctx;
    r = ctx->gl_use_current_context ? sfb__gl_host_open(g, why, why_size) : sfb__gl_egl_open(g, why, why_size);
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

/* ---- tables ---- */
static void sfb__gl_table_free(sfb__gl *g, sfb__gl_table *t) {
    int i;
    if (!t) return;
    for (i = 0; i < t->count; ++i) g->gl.DeleteBuffers(4, t->pieces[i].buf);
    sfb__free(g->ctx, t->pieces);
    sfb__free(g->ctx, t);
}

/* Uploads with the context already current. Rows are cut into pieces whose arrays each fit
 * one shader storage block (offsets in our tables are contiguous, row after row). */
static sfb_result sfb__gl_upload_current(sfb__gl *g, const sfb__stencils *t, sfb__gl_table **out) {
    size_t cap = (size_t)g->max_block / 4;
    int r0 = 0, count = 0, allocated = 0;
    sfb__gl_table *tab = (sfb__gl_table *)sfb__calloc(g->ctx, 1, sizeof *tab);
    sfb_result res;
    *out = NULL;
    if (!tab) return sfb__oom(g->ctx, "gl stencil table");
    while (r0 < t->rows) {
        int r1 = r0;
        size_t e0 = (size_t)t->offsets[r0], e1 = e0;
        sfb__gl_piece *p;
        while (r1 < t->rows && (size_t)(r1 - r0) < cap && (size_t)t->offsets[r1] + (size_t)t->sizes[r1] - e0 <= cap) {
            if ((size_t)t->offsets[r1] != e1) {
                sfb__gl_table_free(g, tab);
                return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: stencil rows are not contiguous (row %d)", r1);
            }
            e1 += (size_t)t->sizes[r1];
            ++r1;
        }
        if (r1 == r0) {
            sfb__gl_table_free(g, tab);
            return sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                              "gl: stencil row %d has %d entries, more than one storage block holds", r0, t->sizes[r0]);
        }
        if (count == allocated) {
            int na = allocated ? allocated * 2 : 4;
            sfb__gl_piece *np = (sfb__gl_piece *)sfb__realloc(g->ctx, tab->pieces, (size_t)na * sizeof *np);
            if (!np) { sfb__gl_table_free(g, tab); return sfb__oom(g->ctx, "gl stencil table"); }
            tab->pieces = np;
            allocated = na;
        }
        p = &tab->pieces[count];
        memset(p, 0, sizeof *p);
        p->row0 = r0;
        p->row1 = r1;
        p->entry0 = (int)e0;
        g->gl.GenBuffers(4, p->buf);
        tab->count = ++count;
        /* a zero-length storage buffer cannot be bound: keep at least one element */
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p->buf[0]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(r1 - r0) * 4, t->sizes + r0, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p->buf[1]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(r1 - r0) * 4, t->offsets + r0, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p->buf[2]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(e1 > e0 ? e1 - e0 : 1) * 4, t->indices + e0, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p->buf[3]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(e1 > e0 ? e1 - e0 : 1) * 4, t->weights + e0, SFB__GL_STATIC_DRAW);
        if ((res = sfb__gl_check(g, "uploading a stencil table")) != SFB_SUCCESS) {
            sfb__gl_table_free(g, tab);
            return res;
        }
        r0 = r1;
    }
    *out = tab;
    return SFB_SUCCESS;
}

static sfb_result sfb__gl_upload(void *state, const sfb__stencils *t, void **handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved s;
    sfb__gl_table *tab = NULL;
    sfb_result r = sfb__gl_enter(g, &s);
    if (r != SFB_SUCCESS) return r;
    r = sfb__gl_upload_current(g, t, &tab);
    sfb__gl_leave(g, &s);
    *handle = tab;
    return r;
}

static void sfb__gl_release(void *state, void *handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved s;
    if (!handle) return;
    if (sfb__gl_enter(g, &s) == SFB_SUCCESS) {
        sfb__gl_table_free(g, (sfb__gl_table *)handle);
        sfb__gl_leave(g, &s);
    } else {
        sfb__free(g->ctx, ((sfb__gl_table *)handle)->pieces);
        sfb__free(g->ctx, handle);
    }
}

/* Runs the kernel over rows [first,last) with the given src/dst buffers bound whole. */
static sfb_result sfb__gl_dispatch(sfb__gl *g, const sfb__gl_table *tab, int first, int last, sfb__GLuint src,
                                   int src_offset, int src_stride, sfb__GLuint dst, int dst_offset, int dst_stride,
                                   int length) {
    sfb__GLuint prog;
    const sfb__GLint *loc;
    int i;
    sfb_result r = sfb__gl_program(g, length, &prog);
    if (r != SFB_SUCCESS) return r;
    loc = g->loc[length];
    g->gl.UseProgram(prog);
    g->gl.Uniform1i(loc[4], src_offset);
    g->gl.Uniform1i(loc[5], src_stride);
    g->gl.Uniform1i(loc[6], dst_offset);
    g->gl.Uniform1i(loc[7], dst_stride);
    g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 4, src);
    g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 5, dst);
    for (i = 0; i < tab->count; ++i) {
        const sfb__gl_piece *p = &tab->pieces[i];
        int a = first > p->row0 ? first : p->row0, b = last < p->row1 ? last : p->row1, k;
        long long per = (long long)g->max_groups * 64;
        if (a >= b) continue;
        for (k = 0; k < 4; ++k) g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)k, p->buf[k]);
        g->gl.Uniform1i(loc[2], p->entry0);
        g->gl.Uniform1i(loc[3], p->row0);
        while (a < b) {
            int n = (long long)(b - a) > per ? (int)per : b - a;
            g->gl.Uniform1i(loc[0], a - p->row0);
            g->gl.Uniform1i(loc[1], a - p->row0 + n);
            g->gl.DispatchCompute((sfb__GLuint)((n + 63) / 64), 1, 1);
            a += n;
        }
    }
    return sfb__gl_check(g, "the stencil kernel");
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

static sfb_result sfb__gl_eval(void *state, const sfb__stencils *t, void *handle, int first, int last, const float *src,
                               sfb_buffer_desc sd, float *dst, sfb_buffer_desc dd) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_table *tab = (sfb__gl_table *)handle, *temp = NULL;
    sfb__gl_saved s;
    size_t src_bytes = sfb__gl_span(t->sources, sd), dst_bytes;
    int rows = last - first, length = sd.length, r, c;
    sfb_result res;
    const float *mapped;
    if (rows <= 0) return SFB_SUCCESS;
    if (sd.length != dd.length || length < 1 || length > 16) return SFB_INVALID_ARGS;
    dst_bytes = (size_t)rows * (size_t)length * sizeof(float);
    /* src is uploaded from its first element; dst comes back compact and is scattered here */
    if (src_bytes - (size_t)sd.offset * sizeof(float) > (size_t)g->max_block || dst_bytes > (size_t)g->max_block)
        return sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "%s: buffers of %zu and %zu bytes exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE (%d)", g->mode == SFB__GL_OSMESA ? "osmesa" : "gl",
                          src_bytes, dst_bytes, (int)g->max_block);
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    if (!tab) {
        if ((res = sfb__gl_upload_current(g, t, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    if ((res = sfb__gl_grow(g, &g->scratch_src, &g->scratch_src_cap, src_bytes > 0 ? src_bytes : 4, SFB__GL_STREAM_DRAW)) != SFB_SUCCESS) goto done;
    if (src_bytes > (size_t)sd.offset * sizeof(float))
        g->gl.BufferSubData(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)(src_bytes - (size_t)sd.offset * sizeof(float)), src + sd.offset);
    if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, dst_bytes, SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS) goto done;
    res = sfb__gl_dispatch(g, tab, first, last, g->scratch_src, 0, sd.stride, g->scratch_dst, -first * length, length, length);
    if (res != SFB_SUCCESS) goto done;
    g->gl.MemoryBarrier(SFB__GL_BUFFER_UPDATE_BARRIER_BIT);
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, g->scratch_dst);
    mapped = (const float *)g->gl.MapBufferRange(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)dst_bytes, SFB__GL_MAP_READ_BIT);
    if (!mapped) {
        res = sfb__gl_check(g, "mapping the results");
        if (res == SFB_SUCCESS)
            res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: glMapBufferRange returned NULL");
        goto done;
    }
    for (r = 0; r < rows; ++r) {
        float *o = dst + dd.offset + (size_t)(first + r) * (size_t)dd.stride;
        const float *i = mapped + (size_t)r * (size_t)length;
        for (c = 0; c < length; ++c) o[c] = i[c];
    }
    g->gl.UnmapBuffer(SFB__GL_SHADER_STORAGE_BUFFER);
    res = sfb__gl_check(g, "reading the results back");
done:
    if (temp) sfb__gl_table_free(g, temp);
    sfb__gl_leave(g, &s);
    return res;
}

static sfb_result sfb__gl_eval_buffers(void *state, const sfb__stencils *t, void *handle, unsigned src_buffer,
                                       sfb_buffer_desc sd, unsigned dst_buffer, sfb_buffer_desc dd) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_table *tab = (sfb__gl_table *)handle, *temp = NULL;
    sfb__gl_saved s;
    sfb__GLint src_size = 0, dst_size = 0;
    size_t need_src = sfb__gl_span(t->sources, sd), need_dst = sfb__gl_span(t->rows, dd);
    sfb_result res;
    if (g->mode != SFB__GL_HOST)
        return sfb__error(g->ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_eval_stencils_gl: the %s backend runs on its own context; set gl_use_current_context to share the host's buffers",
                          g->mode == SFB__GL_OSMESA ? "osmesa" : "gl");
    if (need_src > (size_t)g->max_block || need_dst > (size_t)g->max_block)
        return sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "gl: buffer views of %zu and %zu bytes exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE (%d)", need_src, need_dst, (int)g->max_block);
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, src_buffer);
    g->gl.GetBufferParameteriv(SFB__GL_SHADER_STORAGE_BUFFER, SFB__GL_BUFFER_SIZE, &src_size);
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, dst_buffer);
    g->gl.GetBufferParameteriv(SFB__GL_SHADER_STORAGE_BUFFER, SFB__GL_BUFFER_SIZE, &dst_size);
    if (g->gl.GetError() != SFB__GL_NO_ERROR) {
        while (g->gl.GetError() != SFB__GL_NO_ERROR) {}
        res = sfb__error(g->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "gl: buffer %u or %u is not a buffer object of the current context",
                         src_buffer, dst_buffer);
        goto done;
    }
    if ((size_t)src_size < need_src || (size_t)dst_size < need_dst) {
        res = sfb__error(g->ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                         "gl: buffer too small: source %u has %d bytes (needs %zu), destination %u has %d bytes (needs %zu)",
                         src_buffer, (int)src_size, need_src, dst_buffer, (int)dst_size, need_dst);
        goto done;
    }
    if (!tab) {
        if ((res = sfb__gl_upload_current(g, t, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    res = sfb__gl_dispatch(g, tab, 0, t->rows, src_buffer, sd.offset, sd.stride, dst_buffer, dd.offset, dd.stride, sd.length);
    /* the host may draw from, map or copy the result next */
    if (res == SFB_SUCCESS) g->gl.MemoryBarrier(SFB__GL_ALL_BARRIER_BITS);
done:
    if (temp) sfb__gl_table_free(g, temp);
    sfb__gl_leave(g, &s);
    return res;
}

static const sfb__backend_vtable sfb__gl_vtable = {
    "gl", SFB_BACKEND_GL, SFB__CAP_EVAL_STENCILS | SFB__CAP_GL_BUFFERS,
    sfb__gl_init, sfb__gl_shutdown, sfb__gl_describe, sfb__gl_upload, sfb__gl_release, sfb__gl_eval, sfb__gl_eval_buffers,
    NULL, NULL, NULL
};

const sfb__backend_vtable *sfb__backend_gl(void) { return &sfb__gl_vtable; }

#endif /* SFB__GL_H */
