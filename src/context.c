/* Results, context, allocator with memory budget, errors, logging, progress. */

SFB_API const char *sfb_result_string(sfb_result r) {
    switch (r) {
#define SFB__RESULT_CASE(name, value, text) case name: return text;
        SFB_RESULT_LIST(SFB__RESULT_CASE)
#undef SFB__RESULT_CASE
    default: return "unknown result";
    }
}

static void *sfb__libc_alloc(size_t size, void *user) { (void)user; return malloc(size); }
static void *sfb__libc_realloc(void *p, size_t size, void *user) { (void)user; return realloc(p, size); }
static void sfb__libc_free(void *p, void *user) { (void)user; free(p); }

SFB_API sfb_context_config sfb_context_config_init(void) {
    sfb_context_config c;
    memset(&c, 0, sizeof c);
    return c;
}

int sfb__mul_size(size_t a, size_t b, size_t *out) {
    if (a != 0 && b > ((size_t)-1) / a) return 0;
    *out = a * b;
    return 1;
}

/* A big block of the default allocator is advised into transparent huge pages (Linux, where
 * the system leaves THP to madvise, the common default). A picture's per-pixel buffers are tens
 * of megabytes written once: at 4 KiB a page, faulting them in cost more than the analysis
 * itself on a virtual machine (catmark_car 1024^2 on the simd backend without a workspace:
 * 216 ms, 130 of them first touches; README, "Surface quality analysis"). Only the default
 * allocator's blocks: a caller's allocator owns its memory's policy. */
#define SFB__HUGE_MIN ((size_t)4 << 20)
static void sfb__advise_huge(const sfb_context *ctx, void *p, size_t size) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    uintptr_t a, e;
    if (size < SFB__HUGE_MIN || ctx->allocator.alloc != sfb__libc_alloc) return;
    a = ((uintptr_t)p + 0x1FFFFF) & ~(uintptr_t)0x1FFFFF; /* the whole 2 MiB pages inside the block */
    e = ((uintptr_t)p + size) & ~(uintptr_t)0x1FFFFF;
    if (e > a) (void)madvise((void *)a, (size_t)(e - a), MADV_HUGEPAGE); /* advice: a refusal changes nothing */
#else
    (void)ctx; (void)p; (void)size;
#endif
}

/* Every block carries its size in a 16-byte header so that the live total can be kept
 * against the memory budget exactly. */
#define SFB__HDR 16
void *sfb__alloc(sfb_context *ctx, size_t size) {
    unsigned char *p;
    if (size > ((size_t)-1) - SFB__HDR) return NULL;
    if (ctx->live_bytes + size > ctx->budget || ctx->live_bytes + size < ctx->live_bytes) {
        ctx->budget_refused = 1;
        return NULL;
    }
    p = (unsigned char *)ctx->allocator.alloc(size + SFB__HDR, ctx->allocator.user);
    if (!p) return NULL;
    sfb__advise_huge(ctx, p, size + SFB__HDR);
    memcpy(p, &size, sizeof size);
    ctx->live_bytes += size;
    if (ctx->live_bytes > ctx->peak_bytes) ctx->peak_bytes = ctx->live_bytes;
    return p + SFB__HDR;
}
void *sfb__calloc(sfb_context *ctx, size_t count, size_t size) {
    size_t total;
    void *p;
    if (!sfb__mul_size(count, size, &total)) return NULL;
    p = sfb__alloc(ctx, total ? total : 1);
    if (p) memset(p, 0, total);
    return p;
}
void *sfb__realloc(sfb_context *ctx, void *ptr, size_t size) {
    unsigned char *p, *np;
    size_t old;
    if (!ptr) return sfb__alloc(ctx, size);
    p = (unsigned char *)ptr - SFB__HDR;
    memcpy(&old, p, sizeof old);
    if (size > ((size_t)-1) - SFB__HDR) return NULL;
    if (size > old && (ctx->live_bytes - old + size > ctx->budget)) {
        ctx->budget_refused = 1;
        return NULL;
    }
    np = (unsigned char *)ctx->allocator.realloc(p, size + SFB__HDR, ctx->allocator.user);
    if (!np) return NULL;
    if (size > old) sfb__advise_huge(ctx, np, size + SFB__HDR);
    memcpy(np, &size, sizeof size);
    ctx->live_bytes = ctx->live_bytes - old + size;
    if (ctx->live_bytes > ctx->peak_bytes) ctx->peak_bytes = ctx->live_bytes;
    return np + SFB__HDR;
}
void sfb__free(sfb_context *ctx, void *ptr) {
    unsigned char *p;
    size_t old;
    if (!ptr) return;
    p = (unsigned char *)ptr - SFB__HDR;
    memcpy(&old, p, sizeof old);
    ctx->live_bytes -= old;
    ctx->allocator.free(p, ctx->allocator.user);
}

static const char *sfb__element_name(sfb_element_kind k) {
    switch (k) {
    case SFB_ELEMENT_VERTEX: return "vertex";
    case SFB_ELEMENT_EDGE: return "edge";
    case SFB_ELEMENT_FACE: return "face";
    case SFB_ELEMENT_LINE: return "line";
    case SFB_ELEMENT_UV: return "uv";
    default: return "";
    }
}

sfb_result sfb__error(sfb_context *ctx, sfb_result r, sfb_element_kind kind, long index, const char *fmt, ...) {
    va_list ap;
    char body[768];
    if (!ctx) return r;
    va_start(ap, fmt);
    vsnprintf(body, sizeof body, fmt, ap);
    va_end(ap);
    if (kind != SFB_ELEMENT_NONE && index >= 0)
        snprintf(ctx->error, sizeof ctx->error, "%s %ld: %s", sfb__element_name(kind), index, body);
    else
        snprintf(ctx->error, sizeof ctx->error, "%s", body);
    ctx->error_info.result = r;
    ctx->error_info.element = kind;
    ctx->error_info.index = index;
    ctx->error_info.message = ctx->error;
    if (ctx->logger.func) ctx->logger.func(SFB_LOG_ERROR, ctx->error, ctx->logger.user);
    return r;
}

void sfb__error_keep(const sfb_context *ctx, sfb__error_state *st) {
    memcpy(st->message, ctx->error, sizeof st->message);
    st->info = ctx->error_info;
}
void sfb__error_put_back(sfb_context *ctx, const sfb__error_state *st) {
    memcpy(ctx->error, st->message, sizeof ctx->error);
    ctx->error_info = st->info;
    ctx->error_info.message = ctx->error;
}

sfb_result sfb__oom(sfb_context *ctx, const char *what) {
    int budget = ctx->budget_refused;
    ctx->budget_refused = 0;
    if (budget)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "%s needs more memory than the memory budget allows (%zu bytes in use, budget %zu bytes)", what,
                          ctx->live_bytes, ctx->budget);
    return sfb__error(ctx, SFB_OUT_OF_MEMORY, SFB_ELEMENT_NONE, -1, "out of memory: the allocator failed during %s", what);
}

void sfb__log(sfb_context *ctx, int level, const char *fmt, ...) {
    va_list ap;
    char msg[768];
    if (!ctx || !ctx->logger.func) return;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ctx->logger.func(level, msg, ctx->logger.user);
}

sfb_result sfb__progress(sfb_context *ctx, float done, const char *stage) {
    if (ctx->progress.func && ctx->progress.func(done, stage, ctx->progress.user))
        return sfb__error(ctx, SFB_CANCELLED, SFB_ELEMENT_NONE, -1, "cancelled by the progress callback during %s", stage);
    return SFB_SUCCESS;
}

void sfb__parallel(sfb_context *ctx, void (*task)(void *arg, int first, int last), void *arg, int first, int last) {
    const sfb__backend_vtable *be = ctx->backend;
    if (first >= last) return;
    if (be && be->parallel && be->parallel(ctx->backend_state, task, arg, first, last)) return;
    task(arg, first, last);
}

/* sfb_context_create, keeping the backend report (what was tried, why each failed) in
 * report/size when no backend initialises. */
sfb_result sfb__context_create_reporting(const sfb_context_config *config, sfb_context **out, char *report, size_t size) {
    sfb_context_config c = config ? *config : sfb_context_config_init();
    sfb_allocator a = c.allocator;
    sfb_context *ctx;
    unsigned char *raw;
    size_t sz = sizeof(sfb_context);
    int i;
    if (!out) return SFB_INVALID_ARGS;
    *out = NULL;
    if ((a.alloc == NULL) != (a.free == NULL) || (a.alloc && !a.realloc)) return SFB_INVALID_ARGS;
    if (c.backend_count < 0 || c.backend_count > 16 || (c.backend_count > 0 && !c.backends)) return SFB_INVALID_ARGS;
    if (c.threads < 0) return SFB_INVALID_ARGS;
    if (!a.alloc) { a.alloc = sfb__libc_alloc; a.realloc = sfb__libc_realloc; a.free = sfb__libc_free; a.user = NULL; }
    raw = (unsigned char *)a.alloc(sz, a.user);
    if (!raw) return SFB_OUT_OF_MEMORY;
    ctx = (sfb_context *)raw;
    memset(ctx, 0, sizeof *ctx);
    ctx->allocator = a;
    ctx->logger = c.logger;
    ctx->progress = c.progress;
    ctx->budget = c.memory_budget ? c.memory_budget : SFB_DEFAULT_MEMORY_BUDGET;
    ctx->threads = c.threads;
    ctx->gl_use_current_context = c.gl_use_current_context;
    if (c.backends && c.backend_count > 0) {
        for (i = 0; i < c.backend_count; ++i) {
            if (c.backends[i] <= SFB_BACKEND_DEFAULT || c.backends[i] >= SFB_BACKEND_KIND_COUNT_) {
                a.free(raw, a.user);
                return SFB_INVALID_ARGS;
            }
            ctx->order[ctx->order_count++] = c.backends[i];
        }
    } else {
        /* The default order, written here only. */
        ctx->order[ctx->order_count++] = SFB_BACKEND_SIMD;
        ctx->order[ctx->order_count++] = SFB_BACKEND_REF;
    }
    ctx->error_info.index = -1;
    ctx->error_info.message = ctx->error;
    {
        const char *env = c.ignore_environment ? NULL : getenv("SURFBLEND_BACKEND");
        sfb_result r = sfb__select_backend(ctx, env);
        if (r != SFB_SUCCESS) {
            if (report && size) {
                size_t n = strlen(ctx->report);
                while (n > 0 && ctx->report[n - 1] == '\n') --n;
                if (n >= size) n = size - 1;
                memcpy(report, ctx->report, n);
                report[n] = 0;
            }
            a.free(raw, a.user);
            return r;
        }
    }
    *out = ctx;
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_context_create(const sfb_context_config *config, sfb_context **out) {
    return sfb__context_create_reporting(config, out, NULL, 0);
}

SFB_API void sfb_context_destroy(sfb_context *ctx) {
    sfb_allocator a;
    if (!ctx) return;
    if (ctx->backend && ctx->backend->shutdown) ctx->backend->shutdown(ctx, ctx->backend_state);
    {
        int n;
        for (n = 0; n <= SFB__STAM_MAX_VALENCE; ++n) { sfb__eigen_cc_free(ctx, ctx->eigen_cc[n]); sfb__eigen_loop_free(ctx, ctx->eigen_loop[n]); }
    }
    a = ctx->allocator;
    a.free(ctx, a.user);
}

SFB_API const char *sfb_last_error(const sfb_context *ctx) { return ctx ? ctx->error : ""; }
SFB_API sfb_error_info sfb_last_error_info(const sfb_context *ctx) {
    sfb_error_info e;
    if (ctx) return ctx->error_info;
    memset(&e, 0, sizeof e);
    e.index = -1;
    e.message = "";
    return e;
}
SFB_API void sfb_clear_error(sfb_context *ctx) {
    if (!ctx) return;
    ctx->error[0] = 0;
    ctx->error_info.result = SFB_SUCCESS;
    ctx->error_info.element = SFB_ELEMENT_NONE;
    ctx->error_info.index = -1;
}
