/* backends/sfb_osmesa.h -- the `osmesa` backend: the gl kernels (backends/gl/) in an off-screen
 * Mesa context, with no window system and no GPU (servers, CI).
 *
 * Compiled by surfblend.h's implementation when SURFBLEND_OSMESA (or SURFBLEND_ALL_BACKENDS)
 * is defined next to SURFBLEND_IMPLEMENTATION; do not include it directly.
 *
 * libOSMesa is loaded at run time (libOSMesa.so.8, then .so.6; one the process already has
 * first). Mesa 25.1 and later no longer ship it: the backend then reports "unavailable" and
 * selection moves on. The context is a 4.3 core profile bound to a 1x1 RGBA buffer; it is made
 * current for each call and released afterwards (OSMesa cannot say which buffer another
 * OSMesa context was bound to, so a different OSMesa context current before a call is not
 * restored: use one per thread).
 */
#ifndef SFB__OSMESA_H
#define SFB__OSMESA_H

/* The library names tried by dlopen, NULL-terminated (tests/gl_errors.c overrides them). */
#ifndef SFB__OSMESA_LIBRARY_NAMES
#define SFB__OSMESA_LIBRARY_NAMES {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so", NULL}
#endif

enum {
    SFB__OSMESA_FORMAT = 0x22, SFB__OSMESA_DEPTH_BITS = 0x30, SFB__OSMESA_STENCIL_BITS = 0x31,
    SFB__OSMESA_ACCUM_BITS = 0x32, SFB__OSMESA_PROFILE = 0x33, SFB__OSMESA_CORE_PROFILE = 0x34,
    SFB__OSMESA_CONTEXT_MAJOR_VERSION = 0x36, SFB__OSMESA_CONTEXT_MINOR_VERSION = 0x37
};

static sfb_result sfb__osmesa_open(sfb__gl *g, char *why, size_t why_size) {
    static const char *const names[] = SFB__OSMESA_LIBRARY_NAMES;
    static const int versions[][2] = {{4, 5}, {4, 3}};
    void *(*create)(const int *, void *) = NULL;
    sfb__glproc p, (*getproc)(const char *) = NULL;
    sfb_result r;
    size_t v;
    g->mode = SFB__GL_OSMESA;
    char err[256] = "";
    g->libosmesa = sfb__gl_dlopen(names, err, sizeof err);
    if (!g->libosmesa) {
        snprintf(why, why_size, "libOSMesa.so.8 / .so.6 not found (Debian: libosmesa6; Mesa 25.1 and later ship none): %s", err);
        return SFB_BACKEND_UNAVAILABLE;
    }
    p = sfb__gl_dlsym(g->libosmesa, "OSMesaCreateContextAttribs"); memcpy(&create, &p, sizeof p);
    p = sfb__gl_dlsym(g->libosmesa, "OSMesaGetCurrentContext"); memcpy(&g->osmesa_get_current, &p, sizeof p);
    p = sfb__gl_dlsym(g->libosmesa, "OSMesaMakeCurrent"); memcpy(&g->osmesa_make_current, &p, sizeof p);
    p = sfb__gl_dlsym(g->libosmesa, "OSMesaDestroyContext"); memcpy(&g->osmesa_destroy, &p, sizeof p);
    p = sfb__gl_dlsym(g->libosmesa, "OSMesaGetProcAddress"); memcpy(&getproc, &p, sizeof p);
    if (!create || !g->osmesa_get_current || !g->osmesa_make_current || !g->osmesa_destroy || !getproc) {
        snprintf(why, why_size, "libOSMesa lacks OSMesaCreateContextAttribs (needs Mesa 11.2 or later)");
        return SFB_BACKEND_UNAVAILABLE;
    }
    for (v = 0; v < sizeof versions / sizeof versions[0] && !g->osmesa_ctx; ++v) {
        const int attrs[] = {SFB__OSMESA_FORMAT, SFB__GL_RGBA, SFB__OSMESA_DEPTH_BITS, 0, SFB__OSMESA_STENCIL_BITS, 0,
                             SFB__OSMESA_ACCUM_BITS, 0, SFB__OSMESA_PROFILE, SFB__OSMESA_CORE_PROFILE,
                             SFB__OSMESA_CONTEXT_MAJOR_VERSION, versions[v][0], SFB__OSMESA_CONTEXT_MINOR_VERSION, versions[v][1], 0};
        g->osmesa_ctx = create(attrs, NULL);
    }
    if (!g->osmesa_ctx) {
        snprintf(why, why_size, "OSMesa could not create an OpenGL 4.3 core context (this OSMesa lacks compute shaders)");
        return SFB_BACKEND_UNAVAILABLE;
    }
    {
        /* as sfb__gl_enter/leave, before the function table exists */
        sfb__gl_saved s;
        void *prev;
        memset(&s, 0, sizeof s);
        sfb__gl_save_foreign(g, &s);
        prev = g->osmesa_get_current();
        if (!g->osmesa_make_current(g->osmesa_ctx, g->osmesa_pixel, SFB__GL_UNSIGNED_BYTE, 1, 1)) {
            sfb__gl_restore_foreign(g, &s);
            snprintf(why, why_size, "OSMesaMakeCurrent failed");
            return SFB_BACKEND_UNAVAILABLE;
        }
        r = sfb__gl_setup(g, getproc, why, why_size);
        if (r == SFB_SUCCESS) r = sfb__gl_warm(g, why, why_size);
        if (!prev || s.fegl_ctx || s.glx_ctx) g->osmesa_make_current(NULL, NULL, 0, 0, 0);
        sfb__gl_restore_foreign(g, &s);
    }
    if (r == SFB_SUCCESS) {
        size_t used = strlen(g->desc);
        snprintf(g->desc + used, sizeof g->desc - used, "; OSMesa off-screen");
    }
    return r;
}

static sfb_result sfb__osmesa_init(sfb_context *ctx, void **state, char *why, size_t why_size) {
    sfb__gl *g = (sfb__gl *)sfb__calloc(ctx, 1, sizeof *g);
    sfb_result r;
    if (!g) { snprintf(why, why_size, "out of memory"); return SFB_OUT_OF_MEMORY; }
    g->ctx = ctx;
    r = sfb__osmesa_open(g, why, why_size);
    if (r == SFB_SUCCESS) r = sfb__gl_pool_open(g, why, why_size);
    if (r != SFB_SUCCESS) {
        sfb__gl_close(g);
        sfb__free(ctx, g);
        return r;
    }
    *state = g;
    return SFB_SUCCESS;
}

void sfb__osmesa_bind(sfb__backend_vtable *vt) {
    vt->name = "osmesa";
    vt->kind = SFB_BACKEND_OSMESA;
    sfb__gl_bind_kernels(vt);
    vt->init = sfb__osmesa_init;
}

#endif /* SFB__OSMESA_H */
