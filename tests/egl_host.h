/* A headless EGL context of the kind a host application has, for the programs that play the host
 * of the gl backend (tests/gl_host.c, tests/gl_manifold.c, bench/bench.cpp,
 * examples/03_engine.cpp): the display (Mesa's surfaceless platform when the client extensions
 * offer it, else the default display), a desktop OpenGL core context made current with no
 * surface, an OpenGL ES context beside it on the same display, and the teardown. Include after a GL header that declares glGetString (GL/gl.h, or
 * GL/glcorearb.h with GL_GLEXT_PROTOTYPES).
 * Everything is static inline; C99 and C++. Links -lEGL and -lGL. */
#ifndef SFB_TEST_EGL_HOST_H
#define SFB_TEST_EGL_HOST_H
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <stdio.h>
#include <string.h>

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

typedef struct egl_host {
    EGLDisplay dpy;
    EGLContext ctx;
    char renderer[256]; /* "OpenGL VERSION; RENDERER" once open */
} egl_host;

/* Is `word` one of the space-separated words of `list` (an extension string; NULL: none)? */
static inline int egl_has_word(const char *list, const char *word) {
    size_t n = strlen(word);
    const char *p = list;
    if (!list) return 0;
    while ((p = strstr(p, word)) != NULL) {
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == 0)) return 1;
        p += n;
    }
    return 0;
}

/* Makes none current, destroys the context, terminates the display (each when there is one);
 * safe on a host that failed to open, or was closed already. */
static inline void egl_host_close(egl_host *h) {
    if (h->dpy != EGL_NO_DISPLAY) {
        eglMakeCurrent(h->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (h->ctx != EGL_NO_CONTEXT) eglDestroyContext(h->dpy, h->ctx);
        eglTerminate(h->dpy);
    }
    h->dpy = EGL_NO_DISPLAY;
    h->ctx = EGL_NO_CONTEXT;
}

/* Makes a desktop OpenGL `major`.`minor` core-profile context current with no surface. 1 on
 * success; else 0 with the reason in why, and nothing left open. */
static inline int egl_host_open(egl_host *h, int major, int minor, char *why, size_t wn) {
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, major, EGL_CONTEXT_MINOR_VERSION, minor,
                                EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLint emaj = 0, emin = 0, n = 0;
    EGLConfig config = EGL_NO_CONFIG_KHR;
    const char *ext, *version, *renderer;
    int gmaj = 0, gmin = 0;
    memset(h, 0, sizeof *h);
    h->dpy = EGL_NO_DISPLAY;
    h->ctx = EGL_NO_CONTEXT;
    if (egl_has_word(client, "EGL_MESA_platform_surfaceless")) {
        PFNEGLGETPLATFORMDISPLAYEXTPROC gpd = (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
        if (gpd) h->dpy = gpd(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
        if (h->dpy != EGL_NO_DISPLAY && !eglInitialize(h->dpy, &emaj, &emin)) h->dpy = EGL_NO_DISPLAY;
    }
    if (h->dpy == EGL_NO_DISPLAY) {
        h->dpy = eglGetDisplay(EGL_DEFAULT_DISPLAY);
        if (h->dpy == EGL_NO_DISPLAY || !eglInitialize(h->dpy, &emaj, &emin)) {
            snprintf(why, wn, "no EGL display (surfaceless platform or default display; EGL error 0x%x)", (unsigned)eglGetError());
            h->dpy = EGL_NO_DISPLAY;
            return 0;
        }
    }
    ext = eglQueryString(h->dpy, EGL_EXTENSIONS);
    if (!egl_has_word(ext, "EGL_KHR_surfaceless_context")) {
        snprintf(why, wn, "EGL %d.%d display lacks EGL_KHR_surfaceless_context", emaj, emin);
        egl_host_close(h);
        return 0;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        snprintf(why, wn, "eglBindAPI(EGL_OPENGL_API) failed: no desktop OpenGL through EGL here");
        egl_host_close(h);
        return 0;
    }
    if (!egl_has_word(ext, "EGL_KHR_no_config_context") && !egl_has_word(ext, "EGL_MESA_configless_context")) {
        static const EGLint cfg_attrs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        if (!eglChooseConfig(h->dpy, cfg_attrs, &config, 1, &n) || n < 1) {
            snprintf(why, wn, "no EGL config with EGL_OPENGL_BIT");
            egl_host_close(h);
            return 0;
        }
    }
    h->ctx = eglCreateContext(h->dpy, config, EGL_NO_CONTEXT, ctx_attrs);
    if (h->ctx == EGL_NO_CONTEXT) {
        snprintf(why, wn, "no OpenGL %d.%d core context (eglCreateContext: EGL error 0x%x; %s)", major, minor, (unsigned)eglGetError(),
                 eglQueryString(h->dpy, EGL_VENDOR));
        egl_host_close(h);
        return 0;
    }
    if (!eglMakeCurrent(h->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, h->ctx)) {
        snprintf(why, wn, "eglMakeCurrent failed (EGL error 0x%x)", (unsigned)eglGetError());
        egl_host_close(h);
        return 0;
    }
    version = (const char *)glGetString(GL_VERSION);
    if (!version || sscanf(version, "%d.%d", &gmaj, &gmin) != 2 || gmaj * 10 + gmin < major * 10 + minor) {
        snprintf(why, wn, "OpenGL version %s is below %d.%d", version ? version : "(none)", major, minor);
        egl_host_close(h);
        return 0;
    }
    renderer = (const char *)glGetString(GL_RENDERER);
    snprintf(h->renderer, sizeof h->renderer, "OpenGL %s; %s", version, renderer ? renderer : "?");
    return 1;
}

/* Makes an OpenGL ES `major`.`minor` context (3.x) current on the host's display, with no
 * surface, and returns it; EGL_NO_CONTEXT with the reason in why, and the host's desktop context
 * current again, when this EGL has none. End it with egl_host_gles_end. */
static inline EGLContext egl_host_gles_begin(const egl_host *h, int major, int minor, char *why, size_t wn) {
    const EGLint attrs[] = {EGL_CONTEXT_MAJOR_VERSION, major, EGL_CONTEXT_MINOR_VERSION, minor, EGL_NONE};
    const char *ext = eglQueryString(h->dpy, EGL_EXTENSIONS);
    EGLConfig config = EGL_NO_CONFIG_KHR;
    EGLContext es;
    EGLint n = 0;
    if (!eglBindAPI(EGL_OPENGL_ES_API)) {
        eglBindAPI(EGL_OPENGL_API);
        snprintf(why, wn, "this EGL has no OpenGL ES API");
        return EGL_NO_CONTEXT;
    }
    if (!egl_has_word(ext, "EGL_KHR_no_config_context") && !egl_has_word(ext, "EGL_MESA_configless_context")) {
        static const EGLint ca[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_NONE};
        if (!eglChooseConfig(h->dpy, ca, &config, 1, &n) || n < 1) config = EGL_NO_CONFIG_KHR;
    }
    es = config != EGL_NO_CONFIG_KHR || n == 0 ? eglCreateContext(h->dpy, config, EGL_NO_CONTEXT, attrs) : EGL_NO_CONTEXT;
    if (es == EGL_NO_CONTEXT || !eglMakeCurrent(h->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, es)) {
        if (es != EGL_NO_CONTEXT) eglDestroyContext(h->dpy, es);
        eglBindAPI(EGL_OPENGL_API);
        eglMakeCurrent(h->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, h->ctx);
        snprintf(why, wn, "no OpenGL ES %d.%d context through EGL here", major, minor);
        return EGL_NO_CONTEXT;
    }
    return es;
}

/* Destroys the ES context of egl_host_gles_begin and makes the host's desktop context current. */
static inline void egl_host_gles_end(const egl_host *h, EGLContext es) {
    eglMakeCurrent(h->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(h->dpy, es);
    eglBindAPI(EGL_OPENGL_API);
    eglMakeCurrent(h->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, h->ctx);
}
#endif
