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
