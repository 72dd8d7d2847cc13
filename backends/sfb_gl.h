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
 *    indexed SSBO bindings 0..5; for manifold tables also texture units 0..2 with their
 *    samplers, the active unit and the pixel unpack state) is saved first and restored after,
 *    and sfb_surface_eval_stencils_gl writes straight into the host's buffer objects. Here
 *    alone sfb_surface_draw_gl draws manifold blending surfaces (seed 000's vertex and
 *    fragment programs) into the host's framebuffer.
 *
 * Patch tables: Catmull-Clark and Loop tables as storage buffers in pieces (patches.comp.glsl);
 * MANIFOLD4 tables (seed 000) as two textures, the seed's Fig. 8 coefficient texture and an
 * integer one of face and patch records, read by manifold.comp.glsl's compute stage
 * (sfb_surface_eval) and its vertex stage (the draw path) alike.
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
#include "gl/shaders.h"

/* Build-time overrides, used by tests/gl_errors.c to exercise the failure paths for real: the
 * kernel source, and the library names tried by dlopen (NULL-terminated initialisers). */
#ifndef SFB__GL_STENCIL_SOURCE
#define SFB__GL_STENCIL_SOURCE sfb__glsl_stencils_comp_glsl
#endif
#ifndef SFB__GL_PATCH_SOURCE
#define SFB__GL_PATCH_SOURCE sfb__glsl_patches_comp_glsl
#endif
#ifndef SFB__GL_NORMALS_SOURCE
#define SFB__GL_NORMALS_SOURCE sfb__glsl_normals_comp_glsl
#endif
#ifndef SFB__GL_MANIFOLD_SOURCE
#define SFB__GL_MANIFOLD_SOURCE sfb__glsl_manifold_comp_glsl
#endif
#ifndef SFB__GL_MANIFOLD_FRAG_SOURCE
#define SFB__GL_MANIFOLD_FRAG_SOURCE sfb__glsl_manifold_draw_frag_glsl
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
    SFB__GL_MAP_READ_BIT = 0x0001, SFB__GL_BUFFER_SIZE = 0x8764,
    /* the manifold tables' textures and the draw path (sfb_surface_draw_gl) */
    SFB__GL_VERTEX_SHADER = 0x8B31, SFB__GL_FRAGMENT_SHADER = 0x8B30,
    SFB__GL_TEXTURE_2D = 0x0DE1, SFB__GL_TEXTURE0 = 0x84C0, SFB__GL_ACTIVE_TEXTURE = 0x84E0,
    SFB__GL_TEXTURE_BINDING_2D = 0x8069, SFB__GL_SAMPLER_BINDING = 0x8919, SFB__GL_MAX_TEXTURE_SIZE = 0x0D33,
    SFB__GL_TEXTURE_MIN_FILTER = 0x2801, SFB__GL_TEXTURE_MAG_FILTER = 0x2800, SFB__GL_NEAREST = 0x2600,
    SFB__GL_TEXTURE_WRAP_S = 0x2802, SFB__GL_TEXTURE_WRAP_T = 0x2803, SFB__GL_CLAMP_TO_EDGE = 0x812F,
    SFB__GL_TEXTURE_BASE_LEVEL = 0x813C, SFB__GL_TEXTURE_MAX_LEVEL = 0x813D,
    SFB__GL_TEXTURE_WIDTH = 0x1000, SFB__GL_TEXTURE_HEIGHT = 0x1001,
    SFB__GL_RGBA32F = 0x8814, SFB__GL_RGBA32I = 0x8D82, SFB__GL_RGBA_INTEGER = 0x8D99, SFB__GL_R8 = 0x8229, SFB__GL_RED = 0x1903,
    SFB__GL_FLOAT = 0x1406, SFB__GL_INT = 0x1404, SFB__GL_UNSIGNED_INT = 0x1405,
    SFB__GL_UNPACK_ALIGNMENT = 0x0CF5, SFB__GL_UNPACK_ROW_LENGTH = 0x0CF2, SFB__GL_UNPACK_SKIP_ROWS = 0x0CF3,
    SFB__GL_UNPACK_SKIP_PIXELS = 0x0CF4, SFB__GL_PIXEL_UNPACK_BUFFER = 0x88EC, SFB__GL_PIXEL_UNPACK_BUFFER_BINDING = 0x88EF,
    SFB__GL_ELEMENT_ARRAY_BUFFER = 0x8893, SFB__GL_VERTEX_ARRAY_BINDING = 0x85B5,
    SFB__GL_POINTS = 0x0000, SFB__GL_TRIANGLES = 0x0004,
    SFB__GL_TRANSFORM_FEEDBACK = 0x8E22, SFB__GL_TRANSFORM_FEEDBACK_BINDING = 0x8E25,
    SFB__GL_TRANSFORM_FEEDBACK_BUFFER = 0x8C8E, SFB__GL_TRANSFORM_FEEDBACK_BUFFER_BINDING = 0x8C8F,
    SFB__GL_INTERLEAVED_ATTRIBS = 0x8C8C, SFB__GL_RASTERIZER_DISCARD = 0x8C89
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
    X(void, Uniform1f, (sfb__GLint, float))                                                           \
    X(void, Uniform1iv, (sfb__GLint, sfb__GLsizei, const sfb__GLint *))                               \
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
    X(void, Finish, (void))                                                                           \
    X(void, GenTextures, (sfb__GLsizei, sfb__GLuint *))                                               \
    X(void, DeleteTextures, (sfb__GLsizei, const sfb__GLuint *))                                      \
    X(void, BindTexture, (sfb__GLenum, sfb__GLuint))                                                  \
    X(void, ActiveTexture, (sfb__GLenum))                                                             \
    X(sfb__GLboolean, IsTexture, (sfb__GLuint))                                                       \
    X(void, TexParameteri, (sfb__GLenum, sfb__GLenum, sfb__GLint))                                    \
    X(void, TexImage2D, (sfb__GLenum, sfb__GLint, sfb__GLint, sfb__GLsizei, sfb__GLsizei, sfb__GLint, sfb__GLenum, sfb__GLenum, const void *)) \
    X(void, GetTexLevelParameteriv, (sfb__GLenum, sfb__GLint, sfb__GLenum, sfb__GLint *))             \
    X(void, PixelStorei, (sfb__GLenum, sfb__GLint))                                                   \
    X(void, GenSamplers, (sfb__GLsizei, sfb__GLuint *))                                               \
    X(void, DeleteSamplers, (sfb__GLsizei, const sfb__GLuint *))                                      \
    X(void, BindSampler, (sfb__GLuint, sfb__GLuint))                                                  \
    X(void, SamplerParameteri, (sfb__GLuint, sfb__GLenum, sfb__GLint))                                \
    X(sfb__GLboolean, IsBuffer, (sfb__GLuint))                                                        \
    X(sfb__GLboolean, IsEnabled, (sfb__GLenum))                                                       \
    X(void, Enable, (sfb__GLenum))                                                                    \
    X(void, Disable, (sfb__GLenum))                                                                   \
    X(void, GenVertexArrays, (sfb__GLsizei, sfb__GLuint *))                                           \
    X(void, DeleteVertexArrays, (sfb__GLsizei, const sfb__GLuint *))                                  \
    X(void, BindVertexArray, (sfb__GLuint))                                                           \
    X(void, DrawElementsInstanced, (sfb__GLenum, sfb__GLsizei, sfb__GLenum, const void *, sfb__GLsizei)) \
    X(void, DrawArraysInstanced, (sfb__GLenum, sfb__GLint, sfb__GLsizei, sfb__GLsizei))               \
    X(void, TransformFeedbackVaryings, (sfb__GLuint, sfb__GLsizei, const sfb__GLchar *const *, sfb__GLenum)) \
    X(void, GenTransformFeedbacks, (sfb__GLsizei, sfb__GLuint *))                                     \
    X(void, DeleteTransformFeedbacks, (sfb__GLsizei, const sfb__GLuint *))                            \
    X(void, BindTransformFeedback, (sfb__GLenum, sfb__GLuint))                                        \
    X(void, BeginTransformFeedback, (sfb__GLenum))                                                    \
    X(void, EndTransformFeedback, (void))                                                             \
    X(void, Uniform2i, (sfb__GLint, sfb__GLint, sfb__GLint))                                          \
    X(void, Uniform3f, (sfb__GLint, float, float, float))                                             \
    X(void, Uniform4f, (sfb__GLint, float, float, float, float))                                      \
    X(void, UniformMatrix3fv, (sfb__GLint, sfb__GLsizei, sfb__GLboolean, const float *))              \
    X(void, UniformMatrix4fv, (sfb__GLint, sfb__GLsizei, sfb__GLboolean, const float *))

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
    sfb__GLuint patch_program[2];   /* patch kernels (Catmull-Clark, Loop), compiled on first use */
    sfb__GLint patch_loc[2][5];
    sfb__GLuint scratch_src, scratch_dst;
    size_t scratch_src_cap, scratch_dst_cap;
    sfb__GLuint normals_program;    /* finish_normals kernel, compiled on first use */
    sfb__GLint normals_loc[8];
    sfb__GLuint normals_buf[5];     /* finish_normals inputs: tu, tv, ns, ns_index, b */
    size_t normals_cap[5];
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
/* Compiles one shader of `type`: the version header for this context, `defines`, then
 * `source`. `label` names it in errors, which carry the driver's log. */
static sfb_result sfb__gl_shader(sfb__gl *g, sfb__GLenum type, const char *defines, const char *source, const char *label,
                                 sfb__GLuint *out) {
    char header[160];
    const sfb__GLchar *parts[2];
    sfb__GLuint sh;
    sfb__GLint ok = 0, len = 0;
    const char *what = type == SFB__GL_COMPUTE_SHADER ? "GL_COMPUTE_SHADER" : type == SFB__GL_VERTEX_SHADER ? "GL_VERTEX_SHADER" : "GL_FRAGMENT_SHADER";
    *out = 0;
    snprintf(header, sizeof header, "%s%s",
             g->es ? "#version 310 es\nprecision highp float;\nprecision highp int;\n" : "#version 430 core\n", defines);
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

/* Compiles and links one compute kernel (see sfb__gl_shader). */
static sfb_result sfb__gl_compile(sfb__gl *g, const char *defines, const char *source, const char *label, sfb__GLuint *out) {
    sfb__GLuint sh;
    sfb_result r = sfb__gl_shader(g, SFB__GL_COMPUTE_SHADER, defines, source, label, &sh);
    *out = 0;
    if (r != SFB_SUCCESS) return r;
    return sfb__gl_link(g, &sh, 1, NULL, 0, label, out);
}

static sfb_result sfb__gl_program(sfb__gl *g, int length, sfb__GLuint *out) {
    char defines[48], label[64];
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->program[length]) { *out = g->program[length]; return SFB_SUCCESS; }
    snprintf(defines, sizeof defines, "#define SFB_LENGTH %d\n", length);
    snprintf(label, sizeof label, "stencils.comp.glsl (SFB_LENGTH %d)", length);
    if ((r = sfb__gl_compile(g, defines, SFB__GL_STENCIL_SOURCE, label, &prog)) != SFB_SUCCESS) return r;
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
    if (g->scratch_src) g->gl.DeleteBuffers(1, &g->scratch_src);
    if (g->scratch_dst) g->gl.DeleteBuffers(1, &g->scratch_dst);
    if (g->mf_program) g->gl.DeleteProgram(g->mf_program);
    if (g->sampler) g->gl.DeleteSamplers(1, &g->sampler);
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

/* ---- patch tables (limit evaluation) ---- */
/* One piece of an uploaded patch table: patches [patch0, patch1) with the control points and
 * eigen blocks they use, copied and renumbered so that each of its four arrays fits one
 * shader storage block (GL_MAX_SHADER_STORAGE_BLOCK_SIZE: at least 128 MiB on real drivers,
 * so one piece in practice; the tests shrink it to force several). */
typedef struct sfb__gl_ppiece {
    int patch0, patch1;
    sfb__GLuint buf[4]; /* patch records (ivec4), cvs (piece-local rows), points (vec4), eigen blocks (vec4) */
} sfb__gl_ppiece;
typedef struct sfb__gl_ptable {
    int count;
    sfb__gl_ppiece *pieces;
    /* a MANIFOLD4 table (no pieces): its two textures (manifold.comp.glsl), their row width,
     * and the first patch texel of the integer one */
    int manifold;
    sfb__GLuint mf_tex[2];
    int mf_width, mf_patch_base;
} sfb__gl_ptable;

/* A location as the patch kernel reads it (std430 struct SfbQuery). */
typedef struct sfb__gl_query {
    int patch;           /* piece-local */
    float s, t;          /* Stam and Stam-Loop patches: (u,v) in the EV's frame instead of (s,t) */
    float scale;         /* +-2^depth: negative after an odd number of middle triangles (Loop) */
} sfb__gl_query;

/* Patch kinds as the shader numbers them (patches.comp.glsl), independent of the core's. */
enum { SFB__GL_KIND_BSPLINE = 0, SFB__GL_KIND_STAM = 1, SFB__GL_KIND_ENDCAP = 2, SFB__GL_KIND_BEZTRI = 3,
       SFB__GL_KIND_STAM_LOOP = 4, SFB__GL_KIND_ENDCAP_TRI = 5 };
enum { SFB__GL_OUTPUTS = 7 };  /* position, du, dv, normal, duu, duv, dvv */
/* Sort keys of the queries within a piece: B-spline or Bezier triangle, end cap (quad or
 * triangle), then Stam or Stam-Loop by valence (a table holds one scheme's kinds only). */
enum { SFB__GL_BUCKETS = SFB__STAM_MAX_VALENCE + 3 };
static const char *const sfb__gl_patch_uniforms[5] = {"u_first", "u_last", "u_stride", "u_slot", "u_second"};

/* Floats of one valence's eigen block, as vec4s (patches.comp.glsl): header (K, dominant, sub,
 * 0), per eigenvalue (lambda, lambda/sub, at-EV tangent mask, 0), and phi (3 sub-patches x K x
 * the 4 rows of the 4x4 B-spline coefficients), so that the kernel reads whole vec4s. The Loop
 * block (sfb__gl_eigl_pack) has the same size: its phi are 15 Bezier coefficients and a 0. */
static size_t sfb__gl_eig_floats(int K) { return 4 * (1 + 13 * (size_t)K); }

static void sfb__gl_eig_pack(const sfb__eigen_cc *e, float *o) {
    int K = e->K, i, k, j;
    float *phi = o + 4 * (1 + (size_t)K);
    /* K and the dominant index stay small integers: exact as floats */
    o[0] = (float)K; o[1] = (float)e->dominant; o[2] = (float)e->sub; o[3] = 0.0f;
    for (i = 0; i < K; ++i) {
        double l = e->lambda[i];
        float *h = o + 4 * (1 + (size_t)i);
        h[0] = (float)l;
        /* the ratio is formed in double so that the subdominant ones round to exactly +-1 */
        h[1] = i == e->dominant ? 0.0f : (float)(l / e->sub);
        /* as sfb__eval_stam at the EV: the eigenvectors that survive the normalisation */
        h[2] = (i != e->dominant && fabs(fabs(l) - e->sub) <= 1e-12) ? 1.0f : 0.0f;
        h[3] = 0.0f;
    }
    /* e->phi[((k-1)*16 + j)*K + i] -> phi[((k-1)*K + i)*16 + j]: one coefficient's 16 together */
    for (k = 0; k < 3; ++k)
        for (i = 0; i < K; ++i)
            for (j = 0; j < 16; ++j)
                phi[((size_t)k * K + i) * 16 + j] = (float)e->phi[((size_t)k * 16 + j) * K + i];
}

/* The Stam-Loop block: header (K, dominant, sub, 0), per eigenvalue (lambda, lambda/sub (0 for
 * the dominant), at-EV tangent mask, index of its Jordan head or -1), then per sub-patch
 * k = 0..2 and eigenvalue i the 15 Bezier coefficients of Phi_k[.][i] and a 0. */
static void sfb__gl_eigl_pack(const sfb__eigen_loop *e, float *o) {
    int K = e->K, i, k, j;
    float *phi = o + 4 * (1 + (size_t)K);
    o[0] = (float)K; o[1] = (float)e->dominant; o[2] = (float)e->sub; o[3] = 0.0f;
    for (i = 0; i < K; ++i) {
        double l = e->lambda[i];
        float *h = o + 4 * (1 + (size_t)i);
        h[0] = (float)l;
        h[1] = i == e->dominant ? 0.0f : (float)(l / e->sub);
        /* as sfb__eval_stam_loop at the EV */
        h[2] = (i != e->dominant && fabs(l - e->sub) <= 1e-12) ? 1.0f : 0.0f;
        h[3] = e->head[i] >= 0 ? (float)e->head[i] : -1.0f;
    }
    /* e->phi[(k*15 + j)*K + i] -> phi[(k*K + i)*16 + j] */
    for (k = 0; k < 3; ++k)
        for (i = 0; i < K; ++i) {
            for (j = 0; j < 15; ++j) phi[((size_t)k * K + i) * 16 + j] = (float)e->phi[((size_t)k * 15 + j) * K + i];
            phi[((size_t)k * K + i) * 16 + 15] = 0.0f;
        }
}

static void sfb__gl_ptable_free(sfb__gl *g, sfb__gl_ptable *t) {
    int i;
    if (!t) return;
    for (i = 0; i < 2; ++i)
        if (t->mf_tex[i]) g->gl.DeleteTextures(1, &t->mf_tex[i]);
    for (i = 0; i < t->count; ++i) g->gl.DeleteBuffers(4, t->pieces[i].buf);
    sfb__free(g->ctx, t->pieces);
    sfb__free(g->ctx, t);
}

/* Uploads a patch table with the context current. Pieces are built greedily, patch after
 * patch; a point or an eigen block shared by patches of one piece is stored once in it. */
static sfb_result sfb__gl_patches_upload_current(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable **out) {
    const char *who = g->mode == SFB__GL_OSMESA ? "osmesa" : "gl";
    size_t cap_rec = (size_t)g->max_block / 16, cap_cv = (size_t)g->max_block / 4, cap_pts = (size_t)g->max_block / 16,
           cap_eig = (size_t)g->max_block / 4, eig_total = 0, max_pts;
    int rows = pt->npoints, p, count = 0, allocated = 0, stamp_id = 0, N;
    /* per eigen block: Catmull-Clark valence N at N, Loop at SFB__STAM_MAX_VALENCE + 1 + N */
    int eig_stamp[2 * (SFB__STAM_MAX_VALENCE + 1)];
    size_t eig_at[2 * (SFB__STAM_MAX_VALENCE + 1)];
    int *stamp = NULL, *local = NULL, *rec = NULL, *cvl = NULL;
    float *pts = NULL, *eig = NULL;
    sfb__gl_ptable *tab;
    sfb_result res = SFB_SUCCESS;
    *out = NULL;
    for (N = 0; N < 2 * (SFB__STAM_MAX_VALENCE + 1); ++N) {
        eig_stamp[N] = -1;
        eig_at[N] = 0;
    }
    for (N = 0; N <= SFB__STAM_MAX_VALENCE; ++N) {
        if (pt->eig[N]) eig_total += sfb__gl_eig_floats(pt->eig[N]->K);
        if (pt->eigl[N]) eig_total += sfb__gl_eig_floats(pt->eigl[N]->K);
    }
    max_pts = (size_t)pt->ncv < (size_t)rows ? (size_t)pt->ncv : (size_t)rows;
    tab = (sfb__gl_ptable *)sfb__calloc(g->ctx, 1, sizeof *tab);
    stamp = (int *)sfb__alloc(g->ctx, ((size_t)rows + 1) * sizeof(int));
    local = (int *)sfb__alloc(g->ctx, ((size_t)rows + 1) * sizeof(int));
    rec = (int *)sfb__alloc(g->ctx, ((size_t)pt->npatch + 1) * 4 * sizeof(int));
    cvl = (int *)sfb__alloc(g->ctx, ((size_t)pt->ncv + 1) * sizeof(int));
    pts = (float *)sfb__alloc(g->ctx, (max_pts + 1) * 4 * sizeof(float));
    eig = (float *)sfb__alloc(g->ctx, (eig_total + 4) * sizeof(float));
    if (!tab || !stamp || !local || !rec || !cvl || !pts || !eig) { res = sfb__oom(g->ctx, "gl patch table"); goto done; }
    for (p = 0; p < rows; ++p) stamp[p] = -1;
    p = 0;
    while (p < pt->npatch) {
        size_t nrec = 0, ncv = 0, npts = 0, neig = 0;
        sfb__gl_ppiece *piece;
        int p0 = p, k;
        for (; p < pt->npatch; ++p) {
            int first = pt->pfirst[p], n = pt->pfirst[p + 1] - first, kind, eoff = -1, fits, slot = -1, eK = 0;
            size_t npts0 = npts, neig0 = neig;
            const sfb__eigen_cc *e = NULL;
            const sfb__eigen_loop *el = NULL;
            switch (pt->ptype[p]) {
            case SFB__PATCH_BSPLINE: kind = SFB__GL_KIND_BSPLINE; fits = n == 16; break;
            /* 4 corner positions, or those and each corner's two limit tangents (normals) */
            case SFB__PATCH_ENDCAP: kind = SFB__GL_KIND_ENDCAP; fits = n == 4 || n == 12; eoff = n; break;
            case SFB__PATCH_STAM:
                kind = SFB__GL_KIND_STAM;
                N = pt->pvalence[p];
                e = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eig[N] : NULL;
                fits = e && n == e->K;
                if (e) { slot = N; eK = e->K; }
                break;
            case SFB__PATCH_BEZTRI: kind = SFB__GL_KIND_BEZTRI; fits = n == 15; break;
            /* 3 corner positions and each corner's two limit tangents */
            case SFB__PATCH_ENDCAP_TRI: kind = SFB__GL_KIND_ENDCAP_TRI; fits = n == 9; eoff = n; break;
            case SFB__PATCH_STAM_LOOP:
                kind = SFB__GL_KIND_STAM_LOOP;
                N = pt->pvalence[p];
                el = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eigl[N] : NULL;
                fits = el && n == el->K;
                if (el) { slot = SFB__STAM_MAX_VALENCE + 1 + N; eK = el->K; }
                break;
            default: kind = -1; fits = 0; break;
            }
            if (!fits) {
                res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: patch %d (type %d, %d points) is malformed", who, p,
                                 pt->ptype[p], n);
                goto done;
            }
            /* its points, new to this piece */
            for (k = 0; k < n; ++k) {
                int row = pt->cv[first + k];
                if (row < 0 || row >= rows) {
                    res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: patch %d reads point %d of %d", who, p, row, rows);
                    goto done;
                }
                if (stamp[row] != stamp_id) {
                    stamp[row] = stamp_id;
                    local[row] = (int)npts;
                    memcpy(pts + 4 * npts, pt->point_data + 3 * (size_t)row, 3 * sizeof(float));
                    pts[4 * npts + 3] = 0.0f;
                    ++npts;
                }
                cvl[ncv + (size_t)k] = local[row];
            }
            if (slot >= 0) {
                if (eig_stamp[slot] != stamp_id) {
                    eig_stamp[slot] = stamp_id;
                    eig_at[slot] = neig / 4; /* in vec4s */
                    if (e) sfb__gl_eig_pack(e, eig + neig);
                    else sfb__gl_eigl_pack(el, eig + neig);
                    neig += sfb__gl_eig_floats(eK);
                }
                eoff = (int)eig_at[slot];
            }
            if (nrec + 1 > cap_rec || ncv + (size_t)n > cap_cv || npts > cap_pts || neig > cap_eig) {
                if (nrec == 0) {
                    res = sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                                     "%s: patch %d (%d points%s) needs more than one shader storage block holds (%d bytes)", who, p, n,
                                     e ? ", Stam eigen data" : el ? ", Stam-Loop eigen data" : "", (int)g->max_block);
                    goto done;
                }
                /* this patch starts the next piece: drop what it added here (the stamps of
                 * this piece are not looked at again) */
                npts = npts0;
                neig = neig0;
                break;
            }
            rec[4 * nrec] = kind;
            rec[4 * nrec + 1] = (int)ncv;
            rec[4 * nrec + 2] = SFB__PARAM_CORNER(pt->pparam[p]);
            rec[4 * nrec + 3] = eoff;
            ++nrec;
            ncv += (size_t)n;
        }
        if (count == allocated) {
            int na = allocated ? allocated * 2 : 4;
            sfb__gl_ppiece *np = (sfb__gl_ppiece *)sfb__realloc(g->ctx, tab->pieces, (size_t)na * sizeof *np);
            if (!np) { res = sfb__oom(g->ctx, "gl patch table"); goto done; }
            tab->pieces = np;
            allocated = na;
        }
        piece = &tab->pieces[count];
        memset(piece, 0, sizeof *piece);
        piece->patch0 = p0;
        piece->patch1 = p;
        g->gl.GenBuffers(4, piece->buf);
        tab->count = ++count;
        /* a zero-length storage buffer cannot be bound: keep at least one element */
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[0]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(nrec * 16), rec, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[1]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)((ncv ? ncv : 1) * 4), cvl, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[2]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)((npts ? npts : 1) * 16), pts, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[3]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)((neig ? neig : 4) * 4), eig, SFB__GL_STATIC_DRAW);
        if ((res = sfb__gl_check(g, "uploading a patch table")) != SFB_SUCCESS) goto done;
        ++stamp_id;
    }
done:
    sfb__free(g->ctx, stamp); sfb__free(g->ctx, local); sfb__free(g->ctx, rec); sfb__free(g->ctx, cvl);
    sfb__free(g->ctx, pts); sfb__free(g->ctx, eig);
    if (res != SFB_SUCCESS) {
        if (tab) sfb__gl_ptable_free(g, tab);
        return res;
    }
    *out = tab;
    return SFB_SUCCESS;
}

static sfb_result sfb__gl_mf_upload_current(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable **out);

static sfb_result sfb__gl_upload_patches(void *state, const sfb__patch_table *pt, void **handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved s;
    sfb__gl_ptable *tab = NULL;
    sfb_result r;
    *handle = NULL;
    if ((r = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return r;
    if (sfb__patch_families(pt) & (1u << SFB__FAMILY_MANIFOLD)) r = sfb__gl_mf_upload_current(g, pt, &tab);
    else r = sfb__gl_patches_upload_current(g, pt, &tab);
    sfb__gl_leave(g, &s);
    *handle = tab;
    return r;
}

static void sfb__gl_release_patches(void *state, void *handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved s;
    if (!handle) return;
    if (sfb__gl_enter(g, &s) == SFB_SUCCESS) {
        sfb__gl_ptable_free(g, (sfb__gl_ptable *)handle);
        sfb__gl_leave(g, &s);
    } else {
        sfb__free(g->ctx, ((sfb__gl_ptable *)handle)->pieces);
        sfb__free(g->ctx, handle);
    }
}

/* The patch kernel of a family (loop = 0: the quad family's kinds, 1: the triangle family's):
 * one source, the other family's kinds left out by a define, so that neither pays the other's
 * compile. */
static sfb_result sfb__gl_patch_program(sfb__gl *g, int loop, sfb__GLuint *out) {
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->patch_program[loop]) { *out = g->patch_program[loop]; return SFB_SUCCESS; }
    if ((r = sfb__gl_compile(g, loop ? "#define SFB_NO_CATMARK\n" : "#define SFB_NO_LOOP\n", SFB__GL_PATCH_SOURCE, "patches.comp.glsl",
                             &prog)) != SFB_SUCCESS)
        return r;
    for (i = 0; i < 5; ++i) g->patch_loc[loop][i] = g->gl.GetUniformLocation(prog, sfb__gl_patch_uniforms[i]);
    g->patch_program[loop] = prog;
    *out = prog;
    return sfb__gl_check(g, "building the patch kernel");
}

/* Piece of a patch: pieces are consecutive patch ranges. */
static int sfb__gl_piece_of(const sfb__gl_ptable *tab, int patch) {
    int lo = 0, hi = tab->count - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (tab->pieces[mid].patch0 <= patch) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

/* ---- MANIFOLD4 tables (seed 000): textures, and the compute kernel of manifold.comp.glsl ---- */
/* Texture units the manifold kernels use: 0 coefficients, 1 patch records, 2 trimming mask. */
enum { SFB__GL_MF_UNITS = 3 };

/* GL state a manifold call binds besides the program and storage buffers (sfb__gl_enter):
 * texture units with their samplers, the active unit, and the pixel unpack state uploads use. */
typedef struct sfb__gl_texstate {
    sfb__GLint active, tex[SFB__GL_MF_UNITS], sampler[SFB__GL_MF_UNITS];
    sfb__GLint unpack_buffer, align, row_length, skip_rows, skip_pixels;
} sfb__gl_texstate;

static void sfb__gl_tex_save(sfb__gl *g, sfb__gl_texstate *t) {
    int i;
    g->gl.GetIntegerv(SFB__GL_ACTIVE_TEXTURE, &t->active);
    for (i = 0; i < SFB__GL_MF_UNITS; ++i) {
        g->gl.ActiveTexture(SFB__GL_TEXTURE0 + (sfb__GLenum)i);
        g->gl.GetIntegerv(SFB__GL_TEXTURE_BINDING_2D, &t->tex[i]);
        g->gl.GetIntegerv(SFB__GL_SAMPLER_BINDING, &t->sampler[i]);
    }
    g->gl.GetIntegerv(SFB__GL_PIXEL_UNPACK_BUFFER_BINDING, &t->unpack_buffer);
    g->gl.GetIntegerv(SFB__GL_UNPACK_ALIGNMENT, &t->align);
    g->gl.GetIntegerv(SFB__GL_UNPACK_ROW_LENGTH, &t->row_length);
    g->gl.GetIntegerv(SFB__GL_UNPACK_SKIP_ROWS, &t->skip_rows);
    g->gl.GetIntegerv(SFB__GL_UNPACK_SKIP_PIXELS, &t->skip_pixels);
    g->gl.ActiveTexture((sfb__GLenum)t->active);
}

static void sfb__gl_tex_restore(sfb__gl *g, const sfb__gl_texstate *t) {
    int i;
    for (i = 0; i < SFB__GL_MF_UNITS; ++i) {
        g->gl.ActiveTexture(SFB__GL_TEXTURE0 + (sfb__GLenum)i);
        g->gl.BindTexture(SFB__GL_TEXTURE_2D, (sfb__GLuint)t->tex[i]);
        g->gl.BindSampler((sfb__GLuint)i, (sfb__GLuint)t->sampler[i]);
    }
    g->gl.ActiveTexture((sfb__GLenum)t->active);
    g->gl.BindBuffer(SFB__GL_PIXEL_UNPACK_BUFFER, (sfb__GLuint)t->unpack_buffer);
    g->gl.PixelStorei(SFB__GL_UNPACK_ALIGNMENT, t->align);
    g->gl.PixelStorei(SFB__GL_UNPACK_ROW_LENGTH, t->row_length);
    g->gl.PixelStorei(SFB__GL_UNPACK_SKIP_ROWS, t->skip_rows);
    g->gl.PixelStorei(SFB__GL_UNPACK_SKIP_PIXELS, t->skip_pixels);
}

/* Tightly packed rows from client memory, whatever the host set. */
static void sfb__gl_unpack_plain(sfb__gl *g, int align) {
    g->gl.BindBuffer(SFB__GL_PIXEL_UNPACK_BUFFER, 0);
    g->gl.PixelStorei(SFB__GL_UNPACK_ALIGNMENT, align);
    g->gl.PixelStorei(SFB__GL_UNPACK_ROW_LENGTH, 0);
    g->gl.PixelStorei(SFB__GL_UNPACK_SKIP_ROWS, 0);
    g->gl.PixelStorei(SFB__GL_UNPACK_SKIP_PIXELS, 0);
}

/* Our sampler object (nearest, clamped): bound beside our textures, it makes them complete
 * whatever their own filter state (a host's mask texture may ask for mipmaps it lacks) and
 * keeps a host's sampler object off our units. */
static sfb_result sfb__gl_mf_sampler(sfb__gl *g) {
    if (g->sampler) return SFB_SUCCESS;
    g->gl.GenSamplers(1, &g->sampler);
    g->gl.SamplerParameteri(g->sampler, SFB__GL_TEXTURE_MIN_FILTER, SFB__GL_NEAREST);
    g->gl.SamplerParameteri(g->sampler, SFB__GL_TEXTURE_MAG_FILTER, SFB__GL_NEAREST);
    g->gl.SamplerParameteri(g->sampler, SFB__GL_TEXTURE_WRAP_S, SFB__GL_CLAMP_TO_EDGE);
    g->gl.SamplerParameteri(g->sampler, SFB__GL_TEXTURE_WRAP_T, SFB__GL_CLAMP_TO_EDGE);
    return sfb__gl_check(g, "making the manifold sampler");
}

/* A 2D texture of `width` x `height` texels (one level, nearest) from tightly packed `data`,
 * made on the active unit (whose binding the caller restores). */
static sfb__GLuint sfb__gl_mf_texture(sfb__gl *g, sfb__GLint internal, int width, int height, sfb__GLenum format, sfb__GLenum type,
                                      const void *data) {
    sfb__GLuint tex = 0;
    g->gl.GenTextures(1, &tex);
    g->gl.BindTexture(SFB__GL_TEXTURE_2D, tex);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_MIN_FILTER, SFB__GL_NEAREST);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_MAG_FILTER, SFB__GL_NEAREST);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_WRAP_S, SFB__GL_CLAMP_TO_EDGE);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_WRAP_T, SFB__GL_CLAMP_TO_EDGE);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_BASE_LEVEL, 0);
    g->gl.TexParameteri(SFB__GL_TEXTURE_2D, SFB__GL_TEXTURE_MAX_LEVEL, 0);
    g->gl.TexImage2D(SFB__GL_TEXTURE_2D, 0, internal, width, height, 0, format, type, data);
    return tex;
}

/* Uploads a MANIFOLD4 table with the context current: the seed's Fig. 8 coefficient texture
 * with one 9-row column per patch corner (RGBA32F, 37 texels per patch: its origin, then the
 * corners' rows, position rows relative to the origin, formed in double) and the RGBA32I
 * texture of parametric face records and corner codes (layout in manifold.comp.glsl). Texel n
 * sits at (n % W, n / W) with W = min(4096, GL_MAX_TEXTURE_SIZE). Per-patch origins, rather
 * than the shared per-vertex texture of the seed, keep float's error at the size of a patch:
 * the tangents near a point corner are differences of nearly equal local geometries, which
 * absolute positions would drown. A curve's rows 1 and 2 are positions too. */
static sfb_result sfb__gl_mf_upload_current(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable **out) {
    const char *who = g->mode == SFB__GL_OSMESA ? "osmesa" : "gl";
    int nv = pt->npoints / 9, np = pt->npatch, nf = pt->nptex, W = g->max_texture < 4096 ? g->max_texture : 4096, p, f, j, c, r;
    size_t ncoef = 37 * (size_t)np, nint = (size_t)nf + (size_t)np, hc = (ncoef + (size_t)W - 1) / (size_t)W,
           hi = (nint + (size_t)W - 1) / (size_t)W;
    float *coef = NULL;
    unsigned *recs = NULL;
    sfb__gl_ptable *tab = NULL;
    sfb__gl_texstate ts;
    sfb_result res = SFB_SUCCESS;
    *out = NULL;
    if (hc < 1) hc = 1;
    if (hi < 1) hi = 1;
    if (pt->npoints % 9 != 0 || !pt->pcorner || !pt->ptex_root || (pt->max_depth > 1))
        return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: malformed manifold table (%d points, depth %d)", who,
                          pt->npoints, pt->max_depth);
    if (hc > (size_t)g->max_texture || hi > (size_t)g->max_texture)
        return sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "%s: a manifold table of %d patches needs textures of %zu and %zu rows of %d texels (GL_MAX_TEXTURE_SIZE %d)",
                          who, np, hc, hi, W, (int)g->max_texture);
    coef = (float *)sfb__calloc(g->ctx, hc * (size_t)W * 4, sizeof(float));
    recs = (unsigned *)sfb__calloc(g->ctx, hi * (size_t)W * 4, sizeof(unsigned));
    tab = (sfb__gl_ptable *)sfb__calloc(g->ctx, 1, sizeof *tab);
    if (!coef || !recs || !tab) { res = sfb__oom(g->ctx, "gl manifold table"); goto done; }
    for (p = 0; p < np; ++p) {
        int first = pt->pfirst[p], nrow[4];
        double lo[3], hi3[3], origin[3];
        float *blk = coef + 4 * 37 * (size_t)p;
        if (pt->ptype[p] != SFB__PATCH_MANIFOLD4 || pt->pfirst[p + 1] - first != 4) {
            res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: manifold patch %d (type %d, %d points) is malformed", who, p,
                             pt->ptype[p], pt->pfirst[p + 1] - first);
            goto done;
        }
        for (c = 0; c < 3; ++c) { lo[c] = HUGE_VAL; hi3[c] = -HUGE_VAL; }
        for (j = 0; j < 4; ++j) {
            unsigned code = pt->pcorner[4 * (size_t)p + (size_t)j];
            int kind = SFB__MF_KIND(code), v = pt->cv[first + j];
            if (v < 0 || v >= nv || kind > SFB__MF_CURVE || (kind == SFB__MF_PATCH && SFB__MF_K(code) < 1)) {
                res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: manifold patch %d corner %d (vertex %d of %d, code 0x%x) is malformed",
                                 who, p, j, v, nv, code);
                goto done;
            }
            nrow[j] = kind == SFB__MF_CURVE ? 3 : 1; /* rows holding positions */
            for (r = 0; r < nrow[j]; ++r)
                for (c = 0; c < 3; ++c) {
                    double x = pt->point_data[27 * (size_t)v + 3 * (size_t)r + (size_t)c];
                    if (x < lo[c]) lo[c] = x;
                    if (x > hi3[c]) hi3[c] = x;
                }
        }
        /* the origin: the centre of the patch's positions, as a float (exactly what is added back) */
        for (c = 0; c < 3; ++c) {
            origin[c] = isfinite(lo[c]) && isfinite(hi3[c]) ? (double)(float)(0.5 * (lo[c] + hi3[c])) : 0.0;
            blk[c] = (float)origin[c];
        }
        for (j = 0; j < 4; ++j) {
            const float *src = pt->point_data + 27 * (size_t)pt->cv[first + j];
            for (r = 0; r < 9; ++r)
                for (c = 0; c < 3; ++c)
                    blk[4 * (1 + 9 * j + r) + c] = (float)(r < nrow[j] ? (double)src[3 * r + c] - origin[c] : (double)src[3 * r + c]);
        }
        for (j = 0; j < 4; ++j) recs[4 * ((size_t)nf + (size_t)p) + (size_t)j] = pt->pcorner[4 * (size_t)p + (size_t)j];
    }
    /* face records: a hole, one patch, or the patches of the four quadrants */
    for (f = 0; f < nf; ++f) {
        int root = pt->ptex_root[f], q;
        unsigned *o = recs + 4 * (size_t)f;
        if (root == -1) {
            for (q = 0; q < 4; ++q) o[q] = (unsigned)-1;
        } else if (root <= -2) {
            o[0] = (unsigned)(-root - 2);
            o[1] = o[2] = o[3] = (unsigned)-2;
        } else {
            for (q = 0; q < 4; ++q) {
                int ch = root < pt->nnodes ? pt->nodes[4 * root + q] : 0;
                if (ch >= 0) {
                    res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: manifold face %d is refined deeper than one level", who, f);
                    goto done;
                }
                o[q] = ch == -1 ? (unsigned)-1 : (unsigned)(-ch - 2);
            }
        }
    }
    tab->manifold = 1;
    tab->mf_width = W;
    tab->mf_patch_base = nf;
    sfb__gl_tex_save(g, &ts);
    sfb__gl_unpack_plain(g, 4);
    g->gl.ActiveTexture(SFB__GL_TEXTURE0);
    tab->mf_tex[0] = sfb__gl_mf_texture(g, SFB__GL_RGBA32F, W, (int)hc, SFB__GL_RGBA, SFB__GL_FLOAT, coef);
    tab->mf_tex[1] = sfb__gl_mf_texture(g, SFB__GL_RGBA32I, W, (int)hi, SFB__GL_RGBA_INTEGER, SFB__GL_INT, recs);
    res = sfb__gl_check(g, "uploading a manifold table");
    sfb__gl_tex_restore(g, &ts);
done:
    sfb__free(g->ctx, coef); sfb__free(g->ctx, recs);
    if (res != SFB_SUCCESS) {
        if (tab) sfb__gl_ptable_free(g, tab);
        return res;
    }
    *out = tab;
    return SFB_SUCCESS;
}

/* Uniforms of manifold.comp.glsl shared by both stages, at these indices of a location table. */
static const char *const sfb__gl_mf_common_uniforms[5] = {"u_coef", "u_index", "u_width", "u_patch_base", "u_weights"};

/* With `prog` in use: the table's textures on units 0 and 1 with our sampler, and the shared
 * uniforms (loc: their locations). */
static void sfb__gl_mf_bind(sfb__gl *g, const sfb__gl_ptable *tab, int weights, const sfb__GLint *loc) {
    int i;
    for (i = 0; i < 2; ++i) {
        g->gl.ActiveTexture(SFB__GL_TEXTURE0 + (sfb__GLenum)i);
        g->gl.BindTexture(SFB__GL_TEXTURE_2D, tab->mf_tex[i]);
        g->gl.BindSampler((sfb__GLuint)i, g->sampler);
    }
    g->gl.Uniform1i(loc[0], 0);
    g->gl.Uniform1i(loc[1], 1);
    g->gl.Uniform1i(loc[2], tab->mf_width);
    g->gl.Uniform1i(loc[3], tab->mf_patch_base);
    g->gl.Uniform1i(loc[4], weights);
}

static sfb_result sfb__gl_mf_program(sfb__gl *g, sfb__GLuint *out) {
    static const char *const own[4] = {"u_first", "u_last", "u_stride", "u_slot"};
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->mf_program) { *out = g->mf_program; return SFB_SUCCESS; }
    if ((r = sfb__gl_mf_sampler(g)) != SFB_SUCCESS) return r;
    if ((r = sfb__gl_compile(g, "", SFB__GL_MANIFOLD_SOURCE, "manifold.comp.glsl", &prog)) != SFB_SUCCESS) return r;
    for (i = 0; i < 5; ++i) g->mf_loc[i] = g->gl.GetUniformLocation(prog, sfb__gl_mf_common_uniforms[i]);
    for (i = 0; i < 4; ++i) g->mf_loc[5 + i] = g->gl.GetUniformLocation(prog, own[i]);
    g->mf_program = prog;
    *out = prog;
    return sfb__gl_check(g, "building the manifold kernel");
}

/* sfb_surface_eval on a MANIFOLD4 table: located on the CPU (sfb__patch_locate), evaluated by
 * manifold.comp.glsl in batches that fit one storage block (position, du, dv, normal). Second
 * derivatives are formed on the CPU, as ref forms them (sfb__mf_eval_patch: central differences
 * of the analytic first derivatives, step 2^-17, in double): in float a difference quotient
 * of that step would keep no digits, and a wider one would no longer be ref's function. */
static sfb_result sfb__gl_mf_eval(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable *tab, const sfb_location *locs, int first,
                                  int last, const sfb_eval_output *out) {
    float *dst[4];
    sfb__GLint slot[4];
    sfb__gl_query *queries = NULL;
    sfb__gl_ptable *temp = NULL;
    int count = last - first, nout = 0, o, q, stride;
    size_t batch;
    long long per = (long long)g->max_groups * 64;
    sfb__gl_saved s;
    sfb__gl_texstate ts;
    sfb__GLuint prog;
    sfb_result res;
    dst[0] = out->position; dst[1] = out->du; dst[2] = out->dv; dst[3] = out->normal;
    for (o = 0; o < 4; ++o) slot[o] = dst[o] ? nout++ : -1;
    if (count <= 0) return SFB_SUCCESS;
    for (q = 0; q < count; ++q) {
        double u, v, sc;
        const sfb_location *l = &locs[first + q];
        if (sfb__patch_locate(pt, l->face, l->u, l->v, &u, &v, &sc) < 0)
            return sfb__error(g->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, first + q, "location %d: parametric face %d is a hole", first + q, l->face);
    }
    if (out->duu || out->duv || out->dvv)
        for (q = first; q < last; ++q) {
            double u, v, sc, res2[6][3], nrm[3];
            int patch = sfb__patch_locate(pt, locs[q].face, locs[q].u, locs[q].v, &u, &v, &sc), c;
            sfb__mf_eval_patch(pt, pt->point_data, patch, u, v, 1, res2, nrm);
            for (c = 0; c < 3; ++c) {
                size_t at = 3 * (size_t)q + (size_t)c;
                if (out->duu) out->duu[at] = (float)(res2[3][c] * sc * sc);
                if (out->duv) out->duv[at] = (float)(res2[4][c] * sc * sc);
                if (out->dvv) out->dvv[at] = (float)(res2[5][c] * sc * sc);
            }
        }
    if (nout == 0) return SFB_SUCCESS;
    stride = 3 * nout;
    batch = (size_t)g->max_block / ((size_t)stride * sizeof(float));
    if (batch > (size_t)g->max_block / sizeof(sfb__gl_query)) batch = (size_t)g->max_block / sizeof(sfb__gl_query);
    if (batch < 1) batch = 1;
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    sfb__gl_tex_save(g, &ts);
    if (!tab || !tab->manifold) {
        /* the surface was uploaded to another backend: a temporary copy for this call */
        if ((res = sfb__gl_mf_upload_current(g, pt, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    if ((res = sfb__gl_mf_program(g, &prog)) != SFB_SUCCESS) goto done;
    queries = (sfb__gl_query *)sfb__alloc(g->ctx, (size_t)count * sizeof *queries);
    if (!queries) { res = sfb__oom(g->ctx, "gl manifold evaluation"); goto done; }
    for (q = 0; q < count; ++q) {
        const sfb_location *l = &locs[first + q];
        double u, v, sc;
        queries[q].patch = sfb__patch_locate(pt, l->face, l->u, l->v, &u, &v, &sc);
        queries[q].s = (float)u; /* exact: u, 2u or 2u - 1 of a float */
        queries[q].t = (float)v;
        queries[q].scale = (float)sc;
    }
    g->gl.UseProgram(prog);
    sfb__gl_mf_bind(g, tab, pt->mf_weights, g->mf_loc);
    g->gl.Uniform1i(g->mf_loc[7], stride);
    g->gl.Uniform1iv(g->mf_loc[8], 4, slot);
    for (q = 0; q < count;) {
        int n = (size_t)(count - q) > batch ? (int)batch : count - q, d, k;
        const float *mapped;
        size_t qbytes = (size_t)n * sizeof(sfb__gl_query), rbytes = (size_t)n * (size_t)stride * sizeof(float);
        if ((res = sfb__gl_grow(g, &g->scratch_src, &g->scratch_src_cap, qbytes, SFB__GL_STREAM_DRAW)) != SFB_SUCCESS) goto done;
        g->gl.BufferSubData(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)qbytes, queries + q);
        if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, rbytes, SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS) goto done;
        g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 4, g->scratch_src);
        g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 5, g->scratch_dst);
        for (d = 0; d < n;) {
            int m = (long long)(n - d) > per ? (int)per : n - d;
            g->gl.Uniform1i(g->mf_loc[5], d);
            g->gl.Uniform1i(g->mf_loc[6], d + m);
            g->gl.DispatchCompute((sfb__GLuint)((m + 63) / 64), 1, 1);
            d += m;
        }
        if ((res = sfb__gl_check(g, "the manifold kernel")) != SFB_SUCCESS) goto done;
        g->gl.MemoryBarrier(SFB__GL_BUFFER_UPDATE_BARRIER_BIT);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, g->scratch_dst);
        mapped = (const float *)g->gl.MapBufferRange(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)rbytes, SFB__GL_MAP_READ_BIT);
        if (!mapped) {
            res = sfb__gl_check(g, "mapping the results");
            if (res == SFB_SUCCESS) res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: glMapBufferRange returned NULL");
            goto done;
        }
        for (k = 0; k < n; ++k) {
            size_t at = 3 * ((size_t)first + (size_t)q + (size_t)k);
            const float *r = mapped + (size_t)k * (size_t)stride;
            for (o = 0; o < 4; ++o)
                if (dst[o]) {
                    const float *x = r + 3 * slot[o];
                    dst[o][at] = x[0];
                    dst[o][at + 1] = x[1];
                    dst[o][at + 2] = x[2];
                }
        }
        g->gl.UnmapBuffer(SFB__GL_SHADER_STORAGE_BUFFER);
        if ((res = sfb__gl_check(g, "reading the results back")) != SFB_SUCCESS) goto done;
        q += n;
    }
done:
    sfb__free(g->ctx, queries);
    if (temp) sfb__gl_ptable_free(g, temp);
    sfb__gl_tex_restore(g, &ts);
    sfb__gl_leave(g, &s);
    return res;
}

/* Locations are located on the CPU (a quadtree walk per location, a few ns), grouped by
 * piece, and evaluated by the kernel in batches that fit one storage block; results come back
 * compact (only the asked outputs) and are scattered into the caller's arrays. */
static sfb_result sfb__gl_eval_patches(void *state, const sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                       int last, const sfb_eval_output *out) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_ptable *tab = (sfb__gl_ptable *)handle, *temp = NULL;
    float *dst[SFB__GL_OUTPUTS];
    sfb__GLint slot[SFB__GL_OUTPUTS];
    sfb__gl_query *queries = NULL, *sorted = NULL;
    int *order = NULL, *piece_start = NULL, *key = NULL, *bucket = NULL;
    int count = last - first, nout = 0, o, q, i, k, stride, used = 0, loop = pt->domain == SFB__DOMAIN_TRI;
    size_t batch, nbuckets, z;
    long long per = (long long)g->max_groups * 64;
    sfb__gl_saved s;
    sfb__GLuint prog;
    sfb_result res;
    if (sfb__patch_families(pt) & (1u << SFB__FAMILY_MANIFOLD)) return sfb__gl_mf_eval(g, pt, tab, locs, first, last, out);
    dst[0] = out->position; dst[1] = out->du; dst[2] = out->dv; dst[3] = out->normal;
    dst[4] = out->duu; dst[5] = out->duv; dst[6] = out->dvv;
    for (o = 0; o < SFB__GL_OUTPUTS; ++o) slot[o] = dst[o] ? nout++ : -1;
    if (count <= 0 || nout == 0) return SFB_SUCCESS;
    stride = 3 * nout;
    batch = (size_t)g->max_block / ((size_t)stride * sizeof(float));
    if (batch > (size_t)g->max_block / sizeof(sfb__gl_query)) batch = (size_t)g->max_block / sizeof(sfb__gl_query);
    if (batch < 1) batch = 1;
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    if (!tab) {
        /* the surface was uploaded to another backend: a temporary copy for this call */
        if ((res = sfb__gl_patches_upload_current(g, pt, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    if ((res = sfb__gl_patch_program(g, loop, &prog)) != SFB_SUCCESS) goto done;
    nbuckets = (size_t)tab->count * SFB__GL_BUCKETS;
    queries = (sfb__gl_query *)sfb__alloc(g->ctx, (size_t)count * sizeof *queries);
    key = (int *)sfb__alloc(g->ctx, (size_t)count * sizeof(int));
    bucket = (int *)sfb__calloc(g->ctx, nbuckets + 1, sizeof(int));
    piece_start = (int *)sfb__alloc(g->ctx, ((size_t)tab->count + 1) * sizeof(int));
    if (!queries || !key || !bucket || !piece_start) { res = sfb__oom(g->ctx, "gl patch evaluation"); goto done; }
    for (q = 0; q < count; ++q) {
        const sfb_location *l = &locs[first + q];
        double u, v, sc;
        int patch = sfb__patch_locate(pt, l->face, l->u, l->v, &u, &v, &sc), pc, kind;
        if (patch < 0 || tab->count == 0) {
            res = sfb__error(g->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, first + q, "location %d: parametric face %d is a hole", first + q, l->face);
            goto done;
        }
        kind = pt->ptype[patch] == SFB__PATCH_ENDCAP || pt->ptype[patch] == SFB__PATCH_ENDCAP_TRI ? 1 : 0;
        if (pt->ptype[patch] == SFB__PATCH_STAM_LOOP) {
            /* into the EV's frame (the EV at (0,0)) in double, as for Stam; the triangle's
             * frame turns: corner 1 (u,v) = (t, 1-s-t), corner 2 (1-s-t, s). The scale keeps
             * its sign: the kernel multiplies the derivatives by it. */
            double s0 = u, t0 = v;
            switch (SFB__PARAM_CORNER(pt->pparam[patch])) {
            case 1: u = t0; v = 1.0 - s0 - t0; break;
            case 2: u = 1.0 - s0 - t0; v = s0; break;
            default: break;
            }
            if (u < 0.0) u = 0.0;
            if (v < 0.0) v = 0.0;
            kind = 2 + pt->pvalence[patch];
        } else if (pt->ptype[patch] == SFB__PATCH_STAM) {
            /* into the EV's frame here, in double: the EV is then exactly (0,0) and a small
             * distance to it keeps its relative precision in float */
            double s0 = u, t0 = v;
            switch (SFB__PARAM_CORNER(pt->pparam[patch])) {
            case 1: u = t0; v = 1.0 - s0; break;
            case 2: u = 1.0 - s0; v = 1.0 - t0; break;
            case 3: u = 1.0 - t0; v = s0; break;
            default: break;
            }
            kind = 2 + pt->pvalence[patch];
        }
        pc = tab->count > 1 ? sfb__gl_piece_of(tab, patch) : 0;
        queries[q].patch = patch - tab->pieces[pc].patch0;
        queries[q].s = (float)u;
        queries[q].t = (float)v;
        queries[q].scale = (float)sc;
        key[q] = pc * SFB__GL_BUCKETS + kind;
        if (bucket[key[q] + 1]++ == 0) ++used;
    }
    for (z = 0; z < nbuckets; ++z) bucket[z + 1] += bucket[z];
    for (i = 0; i <= tab->count; ++i) piece_start[i] = bucket[(size_t)i * SFB__GL_BUCKETS];
    if (used > 1) {
        /* Stable counting sort by (piece, kind, valence): one dispatch per piece, and SIMD
         * groups that run one code path over one loop length (a GPU, and llvmpipe's SIMD
         * lanes, pay for every path any of its invocations takes). order[] maps a sorted
         * query back to its location. */
        sorted = (sfb__gl_query *)sfb__alloc(g->ctx, (size_t)count * sizeof *sorted);
        order = (int *)sfb__alloc(g->ctx, (size_t)count * sizeof(int));
        if (!sorted || !order) { res = sfb__oom(g->ctx, "gl patch evaluation"); goto done; }
        for (q = 0; q < count; ++q) {
            int at = bucket[key[q]]++;
            sorted[at] = queries[q];
            order[at] = first + q;
        }
        sfb__free(g->ctx, queries);
        queries = sorted;
        sorted = NULL;
    }
    g->gl.UseProgram(prog);
    g->gl.Uniform1i(g->patch_loc[loop][2], stride);
    g->gl.Uniform1iv(g->patch_loc[loop][3], SFB__GL_OUTPUTS, slot);
    g->gl.Uniform1i(g->patch_loc[loop][4], dst[4] || dst[5] || dst[6]);
    for (i = 0; i < tab->count; ++i) {
        const sfb__gl_ppiece *pc = &tab->pieces[i];
        int a = piece_start[i], b = piece_start[i + 1];
        if (a >= b) continue;
        for (k = 0; k < 4; ++k) g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)k, pc->buf[k]);
        while (a < b) {
            int n = (size_t)(b - a) > batch ? (int)batch : b - a, d;
            const float *mapped;
            size_t qbytes = (size_t)n * sizeof(sfb__gl_query), rbytes = (size_t)n * (size_t)stride * sizeof(float);
            if ((res = sfb__gl_grow(g, &g->scratch_src, &g->scratch_src_cap, qbytes, SFB__GL_STREAM_DRAW)) != SFB_SUCCESS) goto done;
            g->gl.BufferSubData(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)qbytes, queries + a);
            if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, rbytes, SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS) goto done;
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 4, g->scratch_src);
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 5, g->scratch_dst);
            for (d = 0; d < n;) {
                int m = (long long)(n - d) > per ? (int)per : n - d;
                g->gl.Uniform1i(g->patch_loc[loop][0], d);
                g->gl.Uniform1i(g->patch_loc[loop][1], d + m);
                g->gl.DispatchCompute((sfb__GLuint)((m + 63) / 64), 1, 1);
                d += m;
            }
            if ((res = sfb__gl_check(g, "the patch kernel")) != SFB_SUCCESS) goto done;
            g->gl.MemoryBarrier(SFB__GL_BUFFER_UPDATE_BARRIER_BIT);
            g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, g->scratch_dst);
            mapped = (const float *)g->gl.MapBufferRange(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)rbytes, SFB__GL_MAP_READ_BIT);
            if (!mapped) {
                res = sfb__gl_check(g, "mapping the results");
                if (res == SFB_SUCCESS)
                    res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: glMapBufferRange returned NULL");
                goto done;
            }
            for (q = 0; q < n; ++q) {
                size_t at = 3 * (size_t)(order ? order[a + q] : first + a + q);
                const float *r = mapped + (size_t)q * (size_t)stride;
                for (o = 0; o < SFB__GL_OUTPUTS; ++o)
                    if (dst[o]) {
                        const float *x = r + 3 * slot[o];
                        dst[o][at] = x[0];
                        dst[o][at + 1] = x[1];
                        dst[o][at + 2] = x[2];
                    }
            }
            g->gl.UnmapBuffer(SFB__GL_SHADER_STORAGE_BUFFER);
            if ((res = sfb__gl_check(g, "reading the results back")) != SFB_SUCCESS) goto done;
            a += n;
        }
    }
done:
    sfb__free(g->ctx, queries); sfb__free(g->ctx, sorted); sfb__free(g->ctx, order);
    sfb__free(g->ctx, piece_start); sfb__free(g->ctx, key); sfb__free(g->ctx, bucket);
    if (temp) sfb__gl_ptable_free(g, temp);
    sfb__gl_leave(g, &s);
    return res;
}

/* ---- seed 001's normal blend (finish_normals) ---- */
static const char *const sfb__gl_normals_uniforms[8] = {"u_first", "u_last", "u_ns_base", "u_flags",
                                                        "u_stride", "u_limit_slot", "u_sub_slot", "u_p"};

static sfb_result sfb__gl_normals_program(sfb__gl *g, sfb__GLuint *out) {
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->normals_program) { *out = g->normals_program; return SFB_SUCCESS; }
    if ((r = sfb__gl_compile(g, "", SFB__GL_NORMALS_SOURCE, "normals.comp.glsl", &prog)) != SFB_SUCCESS) return r;
    for (i = 0; i < 8; ++i) g->normals_loc[i] = g->gl.GetUniformLocation(prog, sfb__gl_normals_uniforms[i]);
    g->normals_program = prog;
    *out = prog;
    return sfb__gl_check(g, "building the normals kernel");
}

/* Uploads `bytes` of `data` into finish_normals input buffer `slot` (grown as needed) and binds
 * it to storage binding `slot`. */
static sfb_result sfb__gl_normals_input(sfb__gl *g, int slot, const void *data, size_t bytes) {
    sfb_result r = sfb__gl_grow(g, &g->normals_buf[slot], &g->normals_cap[slot], bytes, SFB__GL_STREAM_DRAW);
    if (r != SFB_SUCCESS) return r;
    g->gl.BufferSubData(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)bytes, data);
    g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)slot, g->normals_buf[slot]);
    return SFB_SUCCESS;
}

/* Elements go in batches whose every buffer fits one shader storage block: the per-element
 * arrays of the batch, and the rows of ns between the smallest and largest index the batch
 * uses. Where those rows would not fit (indices spread wider than a block holds), the batch's
 * rows are gathered here instead, one per element that has one, and its indices renumbered to
 * them. Results come back compact, B (L, S) per element, and are copied into the caller's
 * arrays. */
static sfb_result sfb__gl_finish_normals(void *state, int first, int last, const float *tu, const float *tv, const float *ns,
                                         const int *ns_index, const float *b, float p, float *out_blend, float *out_limit,
                                         float *out_sub) {
    sfb__gl *g = (sfb__gl *)state;
    const int stride = 3 * (1 + (out_limit != NULL) + (out_sub != NULL));
    const int flags = (ns_index ? 1 : 0) | (ns_index && b ? 2 : 0);
    long long per;
    size_t cap;
    sfb__gl_saved s;
    sfb__GLuint prog;
    sfb_result res;
    float *rows = NULL;   /* gathered rows and renumbered indices of a batch (when needed) */
    int *renum = NULL, a;
    if (!g || first < 0 || first > last) return SFB_INVALID_ARGS;
    if (first == last) return SFB_SUCCESS;
    if (!tu || !tv || !out_blend || (ns_index && !ns)) return SFB_INVALID_ARGS;
    per = (long long)g->max_groups * 64;
    /* the results (>= 12 bytes per element) are the largest per-element buffer */
    cap = (size_t)g->max_block / ((size_t)stride * sizeof(float));
    if (cap < 1) cap = 1;
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    if ((res = sfb__gl_normals_program(g, &prog)) != SFB_SUCCESS) goto done;
    g->gl.UseProgram(prog);
    g->gl.Uniform1i(g->normals_loc[3], flags);
    g->gl.Uniform1i(g->normals_loc[4], stride);
    g->gl.Uniform1i(g->normals_loc[5], out_limit ? 3 : -1);
    g->gl.Uniform1i(g->normals_loc[6], out_sub ? (out_limit ? 6 : 3) : -1);
    g->gl.Uniform1f(g->normals_loc[7], p);
    for (a = first; a < last;) {
        const int n = (size_t)(last - a) > cap ? (int)cap : last - a;
        int kmin = 0, kmax = -1, i, d;
        const int *index = ns_index ? ns_index + a : NULL;
        size_t rbytes;
        const float *mapped;
        for (i = 0; index && i < n; ++i) {
            const int k = index[i];
            if (k < 0) continue;
            if (kmax < 0 || k < kmin) kmin = k;
            if (k > kmax) kmax = k;
        }
        if ((res = sfb__gl_normals_input(g, 0, tu + 3 * (size_t)a, (size_t)n * 3 * sizeof(float))) != SFB_SUCCESS) goto done;
        if ((res = sfb__gl_normals_input(g, 1, tv + 3 * (size_t)a, (size_t)n * 3 * sizeof(float))) != SFB_SUCCESS) goto done;
        /* arrays the kernel does not read get tu's buffer: a binding must name a buffer */
        if (kmax >= 0 && ((size_t)kmax - (size_t)kmin + 1) * 3 * sizeof(float) <= (size_t)g->max_block) {
            res = sfb__gl_normals_input(g, 2, ns + 3 * (size_t)kmin, ((size_t)kmax - (size_t)kmin + 1) * 3 * sizeof(float));
            if (res != SFB_SUCCESS) goto done;
        } else if (kmax >= 0) {
            int used = 0;
            if (!rows) { /* for the largest batch of this call */
                const size_t most = (size_t)(last - a) < cap ? (size_t)(last - a) : cap;
                rows = (float *)sfb__alloc(g->ctx, most * 3 * sizeof(float));
                renum = (int *)sfb__alloc(g->ctx, most * sizeof(int));
                if (!rows || !renum) { res = sfb__oom(g->ctx, "gl finish_normals"); goto done; }
            }
            for (i = 0; i < n; ++i) {
                const int k = index[i];
                renum[i] = k >= 0 ? used : -1;
                if (k >= 0) memcpy(rows + 3 * (size_t)used++, ns + 3 * (size_t)k, 3 * sizeof(float));
            }
            index = renum;
            kmin = 0;
            if ((res = sfb__gl_normals_input(g, 2, rows, (size_t)used * 3 * sizeof(float))) != SFB_SUCCESS) goto done;
        } else {
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 2, g->normals_buf[0]);
        }
        if (flags & 1) {
            if ((res = sfb__gl_normals_input(g, 3, index, (size_t)n * sizeof(int))) != SFB_SUCCESS) goto done;
        } else {
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 3, g->normals_buf[0]);
        }
        if (flags & 2) {
            if ((res = sfb__gl_normals_input(g, 4, b + a, (size_t)n * sizeof(float))) != SFB_SUCCESS) goto done;
        } else {
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 4, g->normals_buf[0]);
        }
        rbytes = (size_t)n * (size_t)stride * sizeof(float);
        if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, rbytes, SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS) goto done;
        g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 5, g->scratch_dst);
        g->gl.Uniform1i(g->normals_loc[2], kmax >= 0 ? kmin : 0);
        for (d = 0; d < n;) {
            int m = (long long)(n - d) > per ? (int)per : n - d;
            g->gl.Uniform1i(g->normals_loc[0], d);
            g->gl.Uniform1i(g->normals_loc[1], d + m);
            g->gl.DispatchCompute((sfb__GLuint)((m + 63) / 64), 1, 1);
            d += m;
        }
        if ((res = sfb__gl_check(g, "the normals kernel")) != SFB_SUCCESS) goto done;
        g->gl.MemoryBarrier(SFB__GL_BUFFER_UPDATE_BARRIER_BIT);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, g->scratch_dst);
        mapped = (const float *)g->gl.MapBufferRange(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)rbytes, SFB__GL_MAP_READ_BIT);
        if (!mapped) {
            res = sfb__gl_check(g, "mapping the results");
            if (res == SFB_SUCCESS) res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: glMapBufferRange returned NULL");
            goto done;
        }
        if (stride == 3) {
            memcpy(out_blend + 3 * (size_t)a, mapped, rbytes);
        } else {
            for (i = 0; i < n; ++i) {
                const float *r = mapped + (size_t)i * (size_t)stride;
                float *o = out_blend + 3 * ((size_t)a + (size_t)i);
                o[0] = r[0]; o[1] = r[1]; o[2] = r[2];
                if (out_limit) {
                    o = out_limit + 3 * ((size_t)a + (size_t)i);
                    o[0] = r[3]; o[1] = r[4]; o[2] = r[5];
                }
                if (out_sub) {
                    r += out_limit ? 6 : 3;
                    o = out_sub + 3 * ((size_t)a + (size_t)i);
                    o[0] = r[0]; o[1] = r[1]; o[2] = r[2];
                }
            }
        }
        g->gl.UnmapBuffer(SFB__GL_SHADER_STORAGE_BUFFER);
        if ((res = sfb__gl_check(g, "reading the results back")) != SFB_SUCCESS) goto done;
        a += n;
    }
done:
    sfb__free(g->ctx, rows);
    sfb__free(g->ctx, renum);
    sfb__gl_leave(g, &s);
    return res;
}

/* The kernels gl and osmesa share (osmesa binds these, then its own init and no host buffers). */
static void sfb__gl_bind_kernels(sfb__backend_vtable *vt) {
    vt->shutdown = sfb__gl_shutdown;
    vt->describe = sfb__gl_describe;
    vt->upload_stencils = sfb__gl_upload;
    vt->release_stencils = sfb__gl_release;
    vt->eval_stencils = sfb__gl_eval;
    vt->upload_patches = sfb__gl_upload_patches;
    vt->release_patches = sfb__gl_release_patches;
    vt->eval_patches = sfb__gl_eval_patches;
    vt->finish_normals = sfb__gl_finish_normals;
}

void sfb__gl_bind(sfb__backend_vtable *vt) {
    vt->name = "gl";
    vt->kind = SFB_BACKEND_GL;
    vt->init = sfb__gl_init;
    sfb__gl_bind_kernels(vt);
    vt->eval_stencils_gl = sfb__gl_eval_buffers;
}

/* ---- the draw path: seed 000's vertex and fragment programs (sfb_surface_draw_gl) ---- */
/* Uniforms of the draw program: manifold.comp.glsl's shared five (sfb__gl_mf_common_uniforms),
 * then these. */
static const char *const sfb__gl_draw_uniforms[9] = {"u_mvp", "u_normal_matrix", "u_rate", "u_first_face", "u_trim",
                                                     "u_trim_on", "u_tiles", "u_light", "u_color"};

/* The gl state of `ctx` when it runs the gl backend on the host's context; else the error
 * (SFB_UNSUPPORTED, naming `fn` and what the context runs). */
static sfb_result sfb__gl_host_of(sfb_context *ctx, const char *fn, sfb__gl **out) {
    const sfb__backend_vtable *be = ctx->backend;
    sfb__gl *g = be && be->kind == SFB_BACKEND_GL ? (sfb__gl *)ctx->backend_state : NULL;
    *out = NULL;
    if (!g || g->mode != SFB__GL_HOST)
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "%s needs the gl backend on the host's current context (gl_use_current_context); this context runs %s%s", fn,
                          be ? be->name : "no backend", g ? " on its own context" : "");
    *out = g;
    return SFB_SUCCESS;
}

/* GL state the draw binds besides sfb__gl_enter's: texture units, vertex array, transform
 * feedback object and generic buffer, rasterizer discard. */
typedef struct sfb__gl_drawstate {
    sfb__gl_texstate tex;
    sfb__GLint vao, tfo, tf_buffer;
    sfb__GLboolean discard;
} sfb__gl_drawstate;

static void sfb__gl_draw_save(sfb__gl *g, sfb__gl_drawstate *d) {
    sfb__gl_tex_save(g, &d->tex);
    g->gl.GetIntegerv(SFB__GL_VERTEX_ARRAY_BINDING, &d->vao);
    g->gl.GetIntegerv(SFB__GL_TRANSFORM_FEEDBACK_BINDING, &d->tfo);
    g->gl.GetIntegerv(SFB__GL_TRANSFORM_FEEDBACK_BUFFER_BINDING, &d->tf_buffer);
    d->discard = g->gl.IsEnabled(SFB__GL_RASTERIZER_DISCARD);
}

static void sfb__gl_draw_restore(sfb__gl *g, const sfb__gl_drawstate *d) {
    if (d->discard) g->gl.Enable(SFB__GL_RASTERIZER_DISCARD);
    else g->gl.Disable(SFB__GL_RASTERIZER_DISCARD);
    g->gl.BindTransformFeedback(SFB__GL_TRANSFORM_FEEDBACK, (sfb__GLuint)d->tfo);
    g->gl.BindBuffer(SFB__GL_TRANSFORM_FEEDBACK_BUFFER, (sfb__GLuint)d->tf_buffer);
    g->gl.BindVertexArray((sfb__GLuint)d->vao);
    sfb__gl_tex_restore(g, &d->tex);
}

/* The draw program, with its vertex array (no attributes: the vertex program reads
 * gl_VertexID and gl_InstanceID), index buffer and transform feedback object. */
static sfb_result sfb__gl_draw_program(sfb__gl *g) {
    static const char *const varyings[2] = {"v_cap_pos", "v_cap_nrm"};
    sfb__GLuint sh[2], prog;
    sfb_result r;
    int i;
    if (g->draw_program) return SFB_SUCCESS;
    if ((r = sfb__gl_mf_sampler(g)) != SFB_SUCCESS) return r;
    if ((r = sfb__gl_shader(g, SFB__GL_VERTEX_SHADER, "#define SFB_MF_VERTEX\n", SFB__GL_MANIFOLD_SOURCE, "manifold.comp.glsl (vertex stage)",
                            &sh[0])) != SFB_SUCCESS)
        return r;
    if ((r = sfb__gl_shader(g, SFB__GL_FRAGMENT_SHADER, "", SFB__GL_MANIFOLD_FRAG_SOURCE, "manifold_draw.frag.glsl", &sh[1])) != SFB_SUCCESS) {
        g->gl.DeleteShader(sh[0]);
        return r;
    }
    if ((r = sfb__gl_link(g, sh, 2, varyings, 2, "the manifold draw program", &prog)) != SFB_SUCCESS) return r;
    for (i = 0; i < 5; ++i) g->draw_loc[i] = g->gl.GetUniformLocation(prog, sfb__gl_mf_common_uniforms[i]);
    for (i = 0; i < 9; ++i) g->draw_loc[5 + i] = g->gl.GetUniformLocation(prog, sfb__gl_draw_uniforms[i]);
    g->draw_program = prog;
    g->gl.GenVertexArrays(1, &g->draw_vao);
    g->gl.GenBuffers(1, &g->draw_ibo);
    g->gl.GenTransformFeedbacks(1, &g->draw_tfo);
    g->draw_rate = 0;
    return sfb__gl_check(g, "building the manifold draw program");
}

/* Binds the draw vertex array with the index buffer of a rate x rate cell grid: cell (i, j)
 * as the triangles (00, 10, 11) and (00, 11, 01), counter-clockwise in (u,v). */
static sfb_result sfb__gl_draw_grid(sfb__gl *g, int rate) {
    g->gl.BindVertexArray(g->draw_vao);
    g->gl.BindBuffer(SFB__GL_ELEMENT_ARRAY_BUFFER, g->draw_ibo);
    if (g->draw_rate != rate) {
        size_t cells = (size_t)rate * (size_t)rate;
        unsigned *idx = (unsigned *)sfb__alloc(g->ctx, cells * 6 * sizeof(unsigned));
        int i, j, n = rate + 1;
        if (!idx) return sfb__oom(g->ctx, "gl draw grid");
        for (j = 0; j < rate; ++j)
            for (i = 0; i < rate; ++i) {
                unsigned *o = idx + 6 * ((size_t)j * (size_t)rate + (size_t)i), v00 = (unsigned)(j * n + i);
                o[0] = v00; o[1] = v00 + 1; o[2] = v00 + 1 + (unsigned)n;
                o[3] = v00; o[4] = v00 + 1 + (unsigned)n; o[5] = v00 + (unsigned)n;
            }
        g->gl.BufferData(SFB__GL_ELEMENT_ARRAY_BUFFER, (sfb__GLsizeiptr)(cells * 6 * sizeof(unsigned)), idx, SFB__GL_STATIC_DRAW);
        sfb__free(g->ctx, idx);
        g->draw_rate = 0;
        if (g->gl.GetError() != SFB__GL_NO_ERROR) {
            while (g->gl.GetError() != SFB__GL_NO_ERROR) {}
            return sfb__error(g->ctx, SFB_OUT_OF_MEMORY, SFB_ELEMENT_NONE, -1, "gl: the index buffer of a %d x %d sample grid could not be made", rate, rate);
        }
        g->draw_rate = rate;
    }
    return SFB_SUCCESS;
}

static int sfb__gl_all_finite(const float *v, int n) {
    int i;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

static int sfb__gl_all_zero(const float *v, int n) {
    int i;
    for (i = 0; i < n; ++i)
        if (v[i] != 0.0f) return 0;
    return 1;
}

SFB_API sfb_result sfb_surface_draw_gl(const sfb_surface *surface, const sfb_gl_draw_params *params) {
    static const float ident4[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, ident3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const float grey[4] = {0.8f, 0.8f, 0.8f, 1.0f};
    sfb_context *ctx;
    sfb__gl *g = NULL;
    sfb_gl_draw_params p;
    const sfb__patch_table *pt;
    sfb__gl_ptable *tab, *temp = NULL;
    sfb__gl_saved saved;
    sfb__gl_drawstate ds;
    const float *mvp, *nm, *color;
    float light[3] = {0.0f, 0.0f, 1.0f};
    int rate, n, first, count, nptex;
    size_t cap_bytes = 0;
    sfb_result r;
    if (!surface) return SFB_INVALID_ARGS;
    ctx = surface->ctx;
    if (!params) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: params is NULL");
    if ((r = sfb__gl_host_of(ctx, "sfb_surface_draw_gl", &g)) != SFB_SUCCESS) return r;
    pt = &surface->patches;
    if (!surface->has_patches || !(sfb__patch_families(pt) & (1u << SFB__FAMILY_MANIFOLD)))
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_draw_gl draws manifold blending surfaces (SFB_SCHEME_MANIFOLD_BLEND with SFB_REFINE_PATCHES); this surface is %s%s",
                          sfb_scheme_name(surface->config.scheme), surface->has_patches ? "" : " without patches");
    p = *params;
    rate = p.rate == 0 ? 16 : p.rate;
    if (rate < 1 || rate > 1024)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: rate %d is outside 1..1024 (0: 16)", p.rate);
    nptex = pt->nptex;
    first = p.first_face;
    count = p.face_count;
    if (first < 0 || count < 0 || first > nptex || count > nptex - first)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_draw_gl: faces %d (+%d) are outside the surface's %d parametric faces", first, count, nptex);
    if (count == 0) count = nptex - first;
    if (!sfb__gl_all_finite(p.mvp, 16) || !sfb__gl_all_finite(p.normal_matrix, 9) || !sfb__gl_all_finite(p.light, 3) ||
        !sfb__gl_all_finite(p.color, 4))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: a matrix, light or colour value is not finite");
    if (p.trim_tiles_u < 0 || p.trim_tiles_v < 0 || (p.trim_tiles_u == 0) != (p.trim_tiles_v == 0))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_draw_gl: trimming atlas tiles %d x %d (0 x 0, or both >= 1)", p.trim_tiles_u, p.trim_tiles_v);
    mvp = sfb__gl_all_zero(p.mvp, 16) ? ident4 : p.mvp;
    nm = sfb__gl_all_zero(p.normal_matrix, 9) ? ident3 : p.normal_matrix;
    color = sfb__gl_all_zero(p.color, 4) ? grey : p.color;
    if (!sfb__gl_all_zero(p.light, 3)) {
        /* in double: a tiny or huge light direction neither under- nor overflows */
        double lx = p.light[0], ly = p.light[1], lz = p.light[2], l = sqrt(lx * lx + ly * ly + lz * lz);
        light[0] = (float)(lx / l); light[1] = (float)(ly / l); light[2] = (float)(lz / l);
    }
    n = rate + 1;
    if (p.capture_buffer) cap_bytes = (size_t)count * (size_t)n * (size_t)n * 6 * sizeof(float);
    if (count == 0) return SFB_SUCCESS;
    if ((r = sfb__gl_enter(g, &saved)) != SFB_SUCCESS) return r;
    sfb__gl_draw_save(g, &ds);
    /* the host's objects */
    if (p.trim_texture) {
        sfb__GLint w = 0, h = 0;
        if (!g->gl.IsTexture(p.trim_texture)) {
            r = sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: trim_texture %u is not a texture of the current context",
                           p.trim_texture);
            goto done;
        }
        g->gl.ActiveTexture(SFB__GL_TEXTURE0 + 2);
        g->gl.BindTexture(SFB__GL_TEXTURE_2D, p.trim_texture);
        g->gl.GetTexLevelParameteriv(SFB__GL_TEXTURE_2D, 0, SFB__GL_TEXTURE_WIDTH, &w);
        g->gl.GetTexLevelParameteriv(SFB__GL_TEXTURE_2D, 0, SFB__GL_TEXTURE_HEIGHT, &h);
        if (g->gl.GetError() != SFB__GL_NO_ERROR || w < 1 || h < 1) {
            while (g->gl.GetError() != SFB__GL_NO_ERROR) {}
            r = sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: trim_texture %u is not a 2D texture with a level-0 image",
                           p.trim_texture);
            goto done;
        }
        if (p.trim_tiles_u > 0 && (w % p.trim_tiles_u != 0 || h % p.trim_tiles_v != 0)) {
            r = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: the %d x %d trimming texture does not split into %d x %d equal tiles",
                           (int)w, (int)h, p.trim_tiles_u, p.trim_tiles_v);
            goto done;
        }
    }
    if (p.capture_buffer) {
        sfb__GLint size = 0;
        if (!g->gl.IsBuffer(p.capture_buffer)) {
            r = sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_draw_gl: capture_buffer %u is not a buffer object of the current context",
                           p.capture_buffer);
            goto done;
        }
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, p.capture_buffer);
        g->gl.GetBufferParameteriv(SFB__GL_SHADER_STORAGE_BUFFER, SFB__GL_BUFFER_SIZE, &size);
        if (size < 0 || (size_t)size < cap_bytes) {
            r = sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                           "sfb_surface_draw_gl: capture_buffer %u has %d bytes; %d faces at rate %d need %zu", p.capture_buffer, (int)size, count,
                           rate, cap_bytes);
            goto done;
        }
    }
    tab = surface->uploaded_by && surface->uploaded_by->kind == SFB_BACKEND_GL ? (sfb__gl_ptable *)surface->backend_patches : NULL;
    if (!tab || !tab->manifold) {
        if ((r = sfb__gl_mf_upload_current(g, pt, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    if ((r = sfb__gl_draw_program(g)) != SFB_SUCCESS) goto done;
    if ((r = sfb__gl_draw_grid(g, rate)) != SFB_SUCCESS) goto done;
    g->gl.UseProgram(g->draw_program);
    sfb__gl_mf_bind(g, tab, pt->mf_weights, g->draw_loc);
    g->gl.ActiveTexture(SFB__GL_TEXTURE0 + 2);
    if (p.trim_texture) g->gl.BindTexture(SFB__GL_TEXTURE_2D, p.trim_texture);
    g->gl.BindSampler(2, g->sampler);
    g->gl.UniformMatrix4fv(g->draw_loc[5], 1, 0, mvp);
    g->gl.UniformMatrix3fv(g->draw_loc[6], 1, 0, nm);
    g->gl.Uniform1i(g->draw_loc[7], rate);
    g->gl.Uniform1i(g->draw_loc[8], first);
    g->gl.Uniform1i(g->draw_loc[9], 2);
    g->gl.Uniform1i(g->draw_loc[10], p.trim_texture != 0);
    g->gl.Uniform2i(g->draw_loc[11], p.trim_tiles_u, p.trim_tiles_v);
    g->gl.Uniform3f(g->draw_loc[12], light[0], light[1], light[2]);
    g->gl.Uniform4f(g->draw_loc[13], color[0], color[1], color[2], color[3]);
    if ((r = sfb__gl_check(g, "setting up the manifold draw")) != SFB_SUCCESS) goto done;
    if (p.capture_buffer) {
        /* the samples once each, as points, into the capture buffer */
        g->gl.BindTransformFeedback(SFB__GL_TRANSFORM_FEEDBACK, g->draw_tfo);
        g->gl.BindBufferRange(SFB__GL_TRANSFORM_FEEDBACK_BUFFER, 0, p.capture_buffer, 0, (sfb__GLsizeiptr)cap_bytes);
        g->gl.Enable(SFB__GL_RASTERIZER_DISCARD);
        g->gl.BeginTransformFeedback(SFB__GL_POINTS);
        g->gl.DrawArraysInstanced(SFB__GL_POINTS, 0, n * n, count);
        g->gl.EndTransformFeedback();
        if (!ds.discard) g->gl.Disable(SFB__GL_RASTERIZER_DISCARD);
        g->gl.BindTransformFeedback(SFB__GL_TRANSFORM_FEEDBACK, (sfb__GLuint)ds.tfo);
        if ((r = sfb__gl_check(g, "capturing the manifold samples")) != SFB_SUCCESS) goto done;
    }
    g->gl.DrawElementsInstanced(SFB__GL_TRIANGLES, 6 * rate * rate, SFB__GL_UNSIGNED_INT, NULL, count);
    r = sfb__gl_check(g, "drawing the manifold surface");
    /* the host may read the capture (map, copy, draw from it) next */
    if (r == SFB_SUCCESS && p.capture_buffer) g->gl.MemoryBarrier(SFB__GL_ALL_BARRIER_BITS);
done:
    if (temp) sfb__gl_ptable_free(g, temp);
    sfb__gl_draw_restore(g, &ds);
    sfb__gl_leave(g, &saved);
    return r;
}

SFB_API sfb_result sfb_gl_trim_texture(sfb_context *ctx, const struct sfb_trim_mask *mask, unsigned int *texture) {
    sfb__gl *g = NULL;
    sfb__gl_saved saved;
    sfb__gl_texstate ts;
    sfb__GLuint tex = 0;
    sfb_result r;
    if (texture) *texture = 0;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!mask || !texture) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_gl_trim_texture: %s is NULL", mask ? "texture" : "mask");
    if ((r = sfb__gl_host_of(ctx, "sfb_gl_trim_texture", &g)) != SFB_SUCCESS) return r;
    /* as sfb_surface_tessellate checks a mask */
    if (!mask->texels) return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: texels is NULL");
    if (mask->width < 1 || mask->width > 16384 || mask->height < 1 || mask->height > 16384)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: %d x %d texels, each side must be 1..16384", mask->width,
                          mask->height);
    if (mask->tiles_u < 0 || mask->tiles_v < 0 || (mask->tiles_u == 0) != (mask->tiles_v == 0))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: atlas tiles %d x %d (0 x 0, or both >= 1)", mask->tiles_u,
                          mask->tiles_v);
    if (mask->tiles_u > 0 && (mask->width % mask->tiles_u != 0 || mask->height % mask->tiles_v != 0))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: %d x %d texels do not split into %d x %d equal tiles",
                          mask->width, mask->height, mask->tiles_u, mask->tiles_v);
    if (mask->width > g->max_texture || mask->height > g->max_texture)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "trimming mask: %d x %d texels exceed GL_MAX_TEXTURE_SIZE (%d)", mask->width,
                          mask->height, (int)g->max_texture);
    if ((r = sfb__gl_enter(g, &saved)) != SFB_SUCCESS) return r;
    sfb__gl_tex_save(g, &ts);
    sfb__gl_unpack_plain(g, 1);
    g->gl.ActiveTexture(SFB__GL_TEXTURE0 + 2);
    tex = sfb__gl_mf_texture(g, SFB__GL_R8, mask->width, mask->height, SFB__GL_RED, SFB__GL_UNSIGNED_BYTE, mask->texels);
    r = sfb__gl_check(g, "uploading a trimming mask");
    if (r != SFB_SUCCESS && tex) g->gl.DeleteTextures(1, &tex);
    else *texture = tex;
    sfb__gl_tex_restore(g, &ts);
    sfb__gl_leave(g, &saved);
    return r;
}

#endif /* SFB__GL_H */
