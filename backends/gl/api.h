/* backends/gl/api.h -- the GL and EGL types, constants and entry-point tables the backend uses
 * (values from the Khronos registry, so that no GL header is needed to build), and the run-time
 * loader (dlopen of a library the process may already have).
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. */
#ifndef SFB__GL_API_H
#define SFB__GL_API_H

#if !defined(_WIN32)
#include <dlfcn.h>
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
    SFB__GL_INTERLEAVED_ATTRIBS = 0x8C8C, SFB__GL_RASTERIZER_DISCARD = 0x8C89,
    /* the analysis on the host's framebuffer (sfb_analysis_draw_gl) */
    SFB__GL_DEPTH_TEST = 0x0B71, SFB__GL_CULL_FACE = 0x0B44, SFB__GL_BLEND = 0x0BE2, SFB__GL_VIEWPORT = 0x0BA2, SFB__GL_RGBA8 = 0x8058,
    /* the analysis proxy's raster (raster.h): an offscreen framebuffer */
    SFB__GL_FRAMEBUFFER = 0x8D40, SFB__GL_DRAW_FRAMEBUFFER = 0x8CA9, SFB__GL_READ_FRAMEBUFFER = 0x8CA8,
    SFB__GL_DRAW_FRAMEBUFFER_BINDING = 0x8CA6, SFB__GL_READ_FRAMEBUFFER_BINDING = 0x8CAA, SFB__GL_FRAMEBUFFER_COMPLETE = 0x8CD5,
    SFB__GL_COLOR_ATTACHMENT0 = 0x8CE0, SFB__GL_DEPTH_ATTACHMENT = 0x8D00, SFB__GL_NONE = 0,
    SFB__GL_RGBA32UI = 0x8D70, SFB__GL_DEPTH_COMPONENT32F = 0x8CAC, SFB__GL_DEPTH_COMPONENT = 0x1902,
    SFB__GL_COLOR = 0x1800, SFB__GL_DEPTH = 0x1801, SFB__GL_LESS = 0x0201, SFB__GL_DEPTH_FUNC = 0x0B74,
    SFB__GL_DEPTH_WRITEMASK = 0x0B72, SFB__GL_COLOR_WRITEMASK = 0x0C23, SFB__GL_SCISSOR_TEST = 0x0C11, SFB__GL_STENCIL_TEST = 0x0B90,
    SFB__GL_PACK_ALIGNMENT = 0x0D05, SFB__GL_PACK_ROW_LENGTH = 0x0D02, SFB__GL_PACK_SKIP_ROWS = 0x0D03, SFB__GL_PACK_SKIP_PIXELS = 0x0D04,
    SFB__GL_PIXEL_PACK_BUFFER = 0x88EB, SFB__GL_PIXEL_PACK_BUFFER_BINDING = 0x88ED,
    SFB__GL_ARRAY_BUFFER = 0x8892, SFB__GL_ARRAY_BUFFER_BINDING = 0x8894, SFB__GL_MAX_VIEWPORT_DIMS = 0x0D3A
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
    X(void, UniformMatrix4fv, (sfb__GLint, sfb__GLsizei, sfb__GLboolean, const float *))              \
    X(void, Uniform2f, (sfb__GLint, float, float))                                                    \
    X(void, GetBooleanv, (sfb__GLenum, sfb__GLboolean *))                                             \
    X(void, GenFramebuffers, (sfb__GLsizei, sfb__GLuint *))                                           \
    X(void, DeleteFramebuffers, (sfb__GLsizei, const sfb__GLuint *))                                  \
    X(void, BindFramebuffer, (sfb__GLenum, sfb__GLuint))                                              \
    X(void, FramebufferTexture2D, (sfb__GLenum, sfb__GLenum, sfb__GLenum, sfb__GLuint, sfb__GLint))   \
    X(sfb__GLenum, CheckFramebufferStatus, (sfb__GLenum))                                             \
    X(void, DrawBuffers, (sfb__GLsizei, const sfb__GLenum *))                                         \
    X(void, ReadBuffer, (sfb__GLenum))                                                                \
    X(void, ClearBufferuiv, (sfb__GLenum, sfb__GLint, const sfb__GLuint *))                           \
    X(void, ClearBufferfv, (sfb__GLenum, sfb__GLint, const float *))                                  \
    X(void, ReadPixels, (sfb__GLint, sfb__GLint, sfb__GLsizei, sfb__GLsizei, sfb__GLenum, sfb__GLenum, void *)) \
    X(void, Viewport, (sfb__GLint, sfb__GLint, sfb__GLsizei, sfb__GLsizei))                           \
    X(void, DepthFunc, (sfb__GLenum))                                                                 \
    X(void, DepthMask, (sfb__GLboolean))                                                              \
    X(void, ColorMask, (sfb__GLboolean, sfb__GLboolean, sfb__GLboolean, sfb__GLboolean))              \
    X(void, EnableVertexAttribArray, (sfb__GLuint))                                                   \
    X(void, VertexAttribPointer, (sfb__GLuint, sfb__GLint, sfb__GLenum, sfb__GLboolean, sfb__GLsizei, const void *)) \
    X(void, VertexAttribIPointer, (sfb__GLuint, sfb__GLint, sfb__GLenum, sfb__GLsizei, const void *))

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

#endif /* SFB__GL_API_H */
