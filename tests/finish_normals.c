/* finish_normals: the finish_normals kernel (seed 001's normal blend, the backend vtable's
 * finish_normals) of every backend against ref, the oracle (sfb__ref_finish_normals). The
 * program compiles the library in and calls the kernels through the bound vtables directly.
 *
 *   finish_normals [--seed S] [--bench N]
 *
 * Targets: ref itself (the properties below hold for the oracle too); simd once per instruction
 * set the CPU and build have (simd-ISA; only the one SURFBLEND_SIMD_ISA names when it is set),
 * each with threads 1 and 2 (simd-ISA/tT); gl; osmesa. Checks, per target T:
 *   T/caps            the bound vtable has the kernel
 *   T/random/pP       10^5 random elements (p = 1, 0.5, 3, 2.2): tangents of random lengths at
 *                     least ~6 degrees apart, normals ns of random lengths, indices random (1 in 8
 *                     is -1), b random with exact 0s and 1s mixed in; elements whose blend would
 *                     nearly cancel (|(1 - b^p) L + b^p S| < 0.05) are not generated. B, L and S
 *                     agree with ref within 1e-5 per component
 *   T/b0, T/b1        b exactly 0: B = L; b exactly 1: B = S (within 1e-6, every p above)
 *   T/k_negative      every index -1: B = L and S = 0 exactly
 *   T/no_index        ns_index (and ns) NULL: B = L, S = 0
 *   T/no_b            b NULL: B = L, S = ns[k] normalised
 *   T/zero_tangents   tu or tv zero, or tu parallel to tv: L = 0 exactly; B = S where b > 0, 0
 *                     where b = 0
 *   T/zero_ns         ns rows of zeros: S = 0 exactly; B = L where b < 1, B = 0 where b = 1
 *   T/antiparallel    S = -L with b^p = 0.5 (b = 0.5, p = 1 and b = 0.25, p = 0.5): B = 0 exactly
 *   T/scale           tangents and normals scaled by 2^-70 and 2^70: the same results as unscaled
 *   T/outputs         out_limit / out_sub NULL or not (4 ways): the same B, bit for bit
 *   T/subrange        first > 0, last < count, small and large (the simd pool, several gl
 *                     batches): outputs outside [first, last) keep their sentinel, inside agree
 *   T/batches         indices that stay near the element (gl: ns uploaded as a slice per batch)
 *   T/empty           first == last: success, nothing written
 * gl and osmesa are built here with a 64 KiB storage block limit (SFB__GL_TEST_MAX_BLOCK), so
 * that their calls run in many batches, with the ns rows both sliced and gathered; define
 * FINISH_NORMALS_FULL_BLOCKS to build with the driver's limit (for --bench).
 *
 * A backend that is unavailable prints one SKIP line (a FAIL when the comma-separated
 * environment variable SFB_REQUIRE_BACKENDS names it), never PASS. Prints "PASS name",
 * "FAIL name: details (seed S)", "SKIP name: why", comments "# ...", and closes with
 * "N passed, N failed, N skipped"; exit status 1 when anything failed. --bench N times the
 * kernels on N random elements (p = 2.2, all three outputs) and prints "# bench" lines.
 *
 * Build: cc -std=c99 -I. tests/finish_normals.c -o build/finish_normals -lm -lpthread -ldl
 */
#define _POSIX_C_SOURCE 200809L
#ifndef FINISH_NORMALS_FULL_BLOCKS
#define SFB__GL_TEST_MAX_BLOCK (1 << 16)
#endif
/* The library is compiled into this test (not linked from libsfb.o) so that the block limit
 * above reaches the gl backend; the backend vtables are then in scope directly. */
#define SURFBLEND_IMPLEMENTATION
#define SURFBLEND_ALL_BACKENDS
#include "surfblend.h"

#include "harness.h"

#include <math.h>

/* ---- test data ---- */
typedef struct data {
    int n, nns;
    float *tu, *tv, *ns, *b;
    int *idx;
} data;

static void data_alloc(data *d, int n, int nns) {
    d->n = n;
    d->nns = nns;
    d->tu = (float *)xmalloc((size_t)n * 3 * sizeof(float));
    d->tv = (float *)xmalloc((size_t)n * 3 * sizeof(float));
    d->ns = (float *)xmalloc((size_t)(nns > 0 ? nns : 1) * 3 * sizeof(float));
    d->b = (float *)xmalloc((size_t)n * sizeof(float));
    d->idx = (int *)xmalloc((size_t)n * sizeof(int));
}

static void data_free(data *d) {
    free(d->tu); free(d->tv); free(d->ns); free(d->b); free(d->idx);
    memset(d, 0, sizeof *d);
}

static void cross3(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static double len3(const double *v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* A random vector with components in [-1, 1], length >= 0.1, times a length factor in [0.1, 10]. */
static void random_vec(rng *g, float *out) {
    double v[3], s;
    do {
        v[0] = 2.0 * rng_unit(g) - 1.0;
        v[1] = 2.0 * rng_unit(g) - 1.0;
        v[2] = 2.0 * rng_unit(g) - 1.0;
    } while (len3(v) < 0.1);
    s = pow(10.0, 2.0 * rng_unit(g) - 1.0);
    out[0] = (float)(v[0] * s);
    out[1] = (float)(v[1] * s);
    out[2] = (float)(v[2] * s);
}

static void unit_of(const float *f, double *u) {
    double l;
    u[0] = f[0]; u[1] = f[1]; u[2] = f[2];
    l = len3(u);
    if (l > 0.0) { u[0] /= l; u[1] /= l; u[2] /= l; }
}

/* Random, non-degenerate elements (see the header) for exponent p. */
static void data_random(data *d, int n, int nns, float p, unsigned long long stream) {
    rng g = rng_for(g_seed, stream);
    int i, k;
    data_alloc(d, n, nns);
    for (k = 0; k < nns; ++k) random_vec(&g, d->ns + 3 * (size_t)k);
    for (i = 0; i < n; ++i) {
        float *a = d->tu + 3 * (size_t)i, *t = d->tv + 3 * (size_t)i;
        double ua[3], ut[3], L[3], r = rng_unit(&g);
        random_vec(&g, a);
        unit_of(a, ua);
        do {
            random_vec(&g, t);
            unit_of(t, ut);
            cross3(ua, ut, L);
        } while (len3(L) < 0.1); /* at least ~5.7 degrees apart */
        {
            const double l = len3(L);
            L[0] /= l; L[1] /= l; L[2] /= l;
        }
        d->b[i] = r < 0.05 ? 0.0f : r < 0.1 ? 1.0f : (float)rng_unit(&g);
        d->idx[i] = -1;
        if (rng_int(&g, 8) != 0) {
            int tries;
            const double w = d->b[i] > 0.0f ? pow((double)d->b[i], (double)p) : 0.0;
            for (tries = 0; tries < 20; ++tries) {
                double S[3], B[3];
                int c;
                k = rng_int(&g, nns);
                unit_of(d->ns + 3 * (size_t)k, S);
                for (c = 0; c < 3; ++c) B[c] = (1.0 - w) * L[c] + w * S[c];
                if (len3(B) >= 0.05) { d->idx[i] = k; break; }
            }
        }
    }
}

/* ---- targets ---- */
typedef struct target {
    char name[64];
    const sfb__backend_vtable *vt;
    void *state;
    sfb_context *ctx;    /* for its error messages (NULL for ref) */
} target;

typedef struct outputs {
    float *blend, *limit, *sub;
} outputs;

static const float k_sentinel = -1234.5f;

static void outputs_alloc(outputs *o, int n) {
    int i;
    o->blend = (float *)xmalloc((size_t)n * 3 * sizeof(float));
    o->limit = (float *)xmalloc((size_t)n * 3 * sizeof(float));
    o->sub = (float *)xmalloc((size_t)n * 3 * sizeof(float));
    for (i = 0; i < 3 * n; ++i) o->blend[i] = o->limit[i] = o->sub[i] = k_sentinel;
}

static void outputs_free(outputs *o) {
    free(o->blend); free(o->limit); free(o->sub);
    memset(o, 0, sizeof *o);
}

/* Runs t's kernel; on failure writes the message to err. */
static int run(const target *t, const data *d, int first, int last, const float *ns, const int *idx, const float *b, float p,
               float *blend, float *limit, float *sub, char *err, size_t err_size) {
    sfb_result r = t->vt->finish_normals(t->state, first, last, d->tu, d->tv, ns, idx, b, p, blend, limit, sub);
    if (r != SFB_SUCCESS) {
        snprintf(err, err_size, "finish_normals returned %s: %.900s", sfb_result_string(r), t->ctx ? sfb_last_error(t->ctx) : "");
        return 0;
    }
    return 1;
}

/* Runs ref on the whole data set. */
static void run_ref(const data *d, const float *ns, const int *idx, const float *b, float p, outputs *o) {
    sfb__ref_finish_normals(NULL, 0, d->n, d->tu, d->tv, ns, idx, b, p, o->blend, o->limit, o->sub);
}

/* Largest |got - want| over components [3 first, 3 last) (NaN counts as infinite); the
 * element where it is at *at. */
static double max_diff(const float *got, const float *want, int first, int last, int *at) {
    double worst = 0.0;
    size_t i;
    *at = -1;
    for (i = 3 * (size_t)first; i < 3 * (size_t)last; ++i) {
        double e = fabs((double)got[i] - (double)want[i]);
        if (e != e) e = HUGE_VAL;
        if (e > worst) { worst = e; *at = (int)(i / 3); }
    }
    return worst;
}

/* Compares the three outputs with ref's over [first, last); appends to msg what is off. */
static void agree(const outputs *got, const outputs *want, int first, int last, double tol, char *msg, size_t size) {
    static const char *const names[3] = {"blend", "limit", "sub"};
    const float *g[3], *w[3];
    int o, at;
    g[0] = got->blend; g[1] = got->limit; g[2] = got->sub;
    w[0] = want->blend; w[1] = want->limit; w[2] = want->sub;
    for (o = 0; o < 3; ++o) {
        double e;
        size_t used = strlen(msg);
        if (!g[o] || !w[o]) continue;
        e = max_diff(g[o], w[o], first, last, &at);
        if (e > tol && used + 1 < size)
            snprintf(msg + used, size - used, "%s%s off by %.3g at element %d (%g %g %g, ref %g %g %g)", used ? "; " : "", names[o], e, at,
                     g[o][3 * (size_t)at], g[o][3 * (size_t)at + 1], g[o][3 * (size_t)at + 2], w[o][3 * (size_t)at],
                     w[o][3 * (size_t)at + 1], w[o][3 * (size_t)at + 2]);
    }
}

/* Elements outside [first, last) must still hold the sentinel. */
static void untouched(const float *a, const char *what, int n, int first, int last, char *msg, size_t size) {
    size_t i;
    if (!a) return;
    for (i = 0; i < 3 * (size_t)n; ++i) {
        size_t e = i / 3, used;
        if ((int)e >= first && (int)e < last) continue;
        if (memcmp(&a[i], &k_sentinel, sizeof(float)) == 0) continue;
        used = strlen(msg);
        if (used + 1 < size) snprintf(msg + used, size - used, "%s%s[%zu] written outside [%d, %d): %g", used ? "; " : "", what, e, first, last, a[i]);
        return;
    }
}

/* Puts a printf-formatted head in front of a non-empty msg (cut to fit). */
static void prefix(char *msg, size_t size, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void prefix(char *msg, size_t size, const char *fmt, ...) {
    char head[256];
    size_t h, m;
    va_list ap;
    if (!msg[0]) return;
    va_start(ap, fmt);
    vsnprintf(head, sizeof head, fmt, ap);
    va_end(ap);
    h = strlen(head);
    m = strlen(msg);
    if (h + 1 >= size) return;
    if (h + m + 1 > size) m = size - 1 - h;
    memmove(msg + h, msg, m);
    msg[h + m] = 0;
    memcpy(msg, head, h);
}

static void report(const char *name, const char *msg) {
    if (msg[0]) fail(name, "%s", msg);
    else pass(name);
}

static const float k_ps[4] = {1.0f, 0.5f, 3.0f, 2.2f};

/* ---- the checks ---- */
static void check_caps(const target *t) {
    char name[128];
    snprintf(name, sizeof name, "%s/caps", t->name);
    if (!t->vt->finish_normals) fail(name, "%s has no finish_normals kernel", t->vt->name);
    else pass(name);
}

static void check_random(const target *t, const data *sets) {
    int pi;
    for (pi = 0; pi < 4; ++pi) {
        const data *d = &sets[pi];
        outputs got, want;
        char name[128], msg[1024] = "";
        snprintf(name, sizeof name, "%s/random/p%g", t->name, k_ps[pi]);
        outputs_alloc(&got, d->n);
        outputs_alloc(&want, d->n);
        run_ref(d, d->ns, d->idx, d->b, k_ps[pi], &want);
        if (run(t, d, 0, d->n, d->ns, d->idx, d->b, k_ps[pi], got.blend, got.limit, got.sub, msg, sizeof msg)) {
            int at;
            agree(&got, &want, 0, d->n, 1e-5, msg, sizeof msg);
            printf("# %s: largest differences to ref: B %.2g, L %.2g, S %.2g\n", name, max_diff(got.blend, want.blend, 0, d->n, &at),
                   max_diff(got.limit, want.limit, 0, d->n, &at), max_diff(got.sub, want.sub, 0, d->n, &at));
        }
        report(name, msg);
        outputs_free(&got);
        outputs_free(&want);
    }
}

/* b exactly 0 (B = L) or exactly 1 (B = S), within 1e-6, for every p; and against ref. */
static void check_b_exact(const target *t, const data *base, float value) {
    data d = *base;
    outputs got, want;
    char name[128], msg[1024] = "";
    int pi, i, at;
    float *b = (float *)xmalloc((size_t)d.n * sizeof(float));
    for (i = 0; i < d.n; ++i) b[i] = value;
    d.b = b;
    snprintf(name, sizeof name, "%s/b%g", t->name, value);
    outputs_alloc(&got, d.n);
    outputs_alloc(&want, d.n);
    for (pi = 0; pi < 4 && !msg[0]; ++pi) {
        double e;
        run_ref(&d, d.ns, d.idx, d.b, k_ps[pi], &want);
        if (!run(t, &d, 0, d.n, d.ns, d.idx, d.b, k_ps[pi], got.blend, got.limit, got.sub, msg, sizeof msg)) break;
        agree(&got, &want, 0, d.n, 1e-5, msg, sizeof msg);
        /* elements with k < 0 have B = L whatever b is; with b = 1 the others have B = S */
        for (i = 0; i < d.n && !msg[0]; ++i) {
            const float *x = (value == 0.0f || d.idx[i] < 0) ? got.limit : got.sub;
            e = max_diff(got.blend, x, i, i + 1, &at);
            if (e > 1e-6)
                snprintf(msg, sizeof msg, "p = %g, element %d: B (%g %g %g) is not %s (%g %g %g)", k_ps[pi], i, got.blend[3 * (size_t)i],
                         got.blend[3 * (size_t)i + 1], got.blend[3 * (size_t)i + 2], x == got.limit ? "L" : "S", x[3 * (size_t)i],
                         x[3 * (size_t)i + 1], x[3 * (size_t)i + 2]);
        }
        if (!strstr(msg, "p = ")) prefix(msg, sizeof msg, "p = %g: ", k_ps[pi]);
    }
    report(name, msg);
    outputs_free(&got);
    outputs_free(&want);
    free(b);
}

/* Every component of a[first..last) exactly zero? Appends a message if not. */
static void exactly_zero(const float *a, const char *what, int first, int last, const int *which, char *msg, size_t size) {
    int i, c;
    for (i = first; i < last; ++i) {
        if (which && !which[i]) continue;
        for (c = 0; c < 3; ++c)
            if (a[3 * (size_t)i + c] != 0.0f) {
                size_t used = strlen(msg);
                if (used + 1 < size)
                    snprintf(msg + used, size - used, "%s%s of element %d is (%g %g %g), not 0", used ? "; " : "", what, i, a[3 * (size_t)i],
                             a[3 * (size_t)i + 1], a[3 * (size_t)i + 2]);
                return;
            }
    }
}

/* Indices all -1, or no index array at all (ns NULL too): B = L, S = 0. */
static void check_no_normals(const target *t, const data *base) {
    int variant;
    for (variant = 0; variant < 2; ++variant) {
        data d = *base;
        outputs got, want;
        char name[128], msg[1024] = "";
        int i, at;
        int *neg = (int *)xmalloc((size_t)d.n * sizeof(int));
        for (i = 0; i < d.n; ++i) neg[i] = -1;
        snprintf(name, sizeof name, "%s/%s", t->name, variant ? "no_index" : "k_negative");
        outputs_alloc(&got, d.n);
        outputs_alloc(&want, d.n);
        run_ref(&d, variant ? NULL : d.ns, variant ? NULL : neg, d.b, 2.2f, &want);
        if (run(t, &d, 0, d.n, variant ? NULL : d.ns, variant ? NULL : neg, d.b, 2.2f, got.blend, got.limit, got.sub, msg, sizeof msg)) {
            agree(&got, &want, 0, d.n, 1e-5, msg, sizeof msg);
            exactly_zero(got.sub, "S", 0, d.n, NULL, msg, sizeof msg);
            if (max_diff(got.blend, got.limit, 0, d.n, &at) != 0.0 && !msg[0])
                snprintf(msg, sizeof msg, "B differs from L at element %d", at);
        }
        report(name, msg);
        outputs_free(&got);
        outputs_free(&want);
        free(neg);
    }
}

/* b NULL: B = L exactly, S = ns[k] normalised. */
static void check_no_b(const target *t, const data *d) {
    outputs got, want;
    char name[128], msg[1024] = "";
    int at;
    snprintf(name, sizeof name, "%s/no_b", t->name);
    outputs_alloc(&got, d->n);
    outputs_alloc(&want, d->n);
    run_ref(d, d->ns, d->idx, NULL, 3.0f, &want);
    if (run(t, d, 0, d->n, d->ns, d->idx, NULL, 3.0f, got.blend, got.limit, got.sub, msg, sizeof msg)) {
        agree(&got, &want, 0, d->n, 1e-5, msg, sizeof msg);
        if (max_diff(got.blend, got.limit, 0, d->n, &at) != 0.0 && !msg[0]) snprintf(msg, sizeof msg, "B differs from L at element %d", at);
    }
    report(name, msg);
    outputs_free(&got);
    outputs_free(&want);
}

/* tu zero, tv zero, or tv = 2 tu (every third element each): L = 0 exactly. With b > 0 and a
 * normal, B = S; with b = 0 (every other element), B = 0. */
static void check_zero_tangents(const target *t, const data *base) {
    data d = *base;
    outputs got, want;
    char name[128], msg[1024] = "";
    int i, c, at;
    float *tu = (float *)xmalloc((size_t)d.n * 3 * sizeof(float)), *tv = (float *)xmalloc((size_t)d.n * 3 * sizeof(float));
    float *b = (float *)xmalloc((size_t)d.n * sizeof(float));
    int *zero_b = (int *)xmalloc((size_t)d.n * sizeof(int)), *pos_b = (int *)xmalloc((size_t)d.n * sizeof(int));
    memcpy(tu, d.tu, (size_t)d.n * 3 * sizeof(float));
    memcpy(tv, d.tv, (size_t)d.n * 3 * sizeof(float));
    for (i = 0; i < d.n; ++i) {
        for (c = 0; c < 3; ++c) {
            if (i % 3 == 0) tu[3 * (size_t)i + c] = 0.0f;
            else if (i % 3 == 1) tv[3 * (size_t)i + c] = 0.0f;
            else tv[3 * (size_t)i + c] = 2.0f * tu[3 * (size_t)i + c];
        }
        b[i] = i % 2 ? 0.0f : (d.b[i] > 0.0f ? d.b[i] : 0.5f);
        zero_b[i] = b[i] == 0.0f;
        pos_b[i] = b[i] > 0.0f && d.idx[i] >= 0;
    }
    d.tu = tu;
    d.tv = tv;
    d.b = b;
    snprintf(name, sizeof name, "%s/zero_tangents", t->name);
    outputs_alloc(&got, d.n);
    outputs_alloc(&want, d.n);
    run_ref(&d, d.ns, d.idx, d.b, 0.5f, &want);
    if (run(t, &d, 0, d.n, d.ns, d.idx, d.b, 0.5f, got.blend, got.limit, got.sub, msg, sizeof msg)) {
        agree(&got, &want, 0, d.n, 1e-5, msg, sizeof msg);
        exactly_zero(got.limit, "L", 0, d.n, NULL, msg, sizeof msg);
        exactly_zero(got.blend, "B (b = 0)", 0, d.n, zero_b, msg, sizeof msg);
        for (i = 0; i < d.n && !msg[0]; ++i)
            if (pos_b[i] && max_diff(got.blend, got.sub, i, i + 1, &at) > 1e-6) snprintf(msg, sizeof msg, "B is not S at element %d", i);
    }
    report(name, msg);
    outputs_free(&got);
    outputs_free(&want);
    free(tu); free(tv); free(b); free(zero_b); free(pos_b);
}

/* Every ns row zero: S = 0 exactly; B = L where b < 1, 0 where b = 1. */
static void check_zero_ns(const target *t, const data *base) {
    data d = *base;
    outputs got, want;
    char name[128], msg[1024] = "";
    int i, at;
    float *ns = (float *)calloc((size_t)d.nns * 3, sizeof(float));
    int *one = (int *)xmalloc((size_t)d.n * sizeof(int));
    if (!ns) { printf("FAIL setup: out of memory\n"); exit(1); }
    for (i = 0; i < d.n; ++i) one[i] = d.idx[i] >= 0 && d.b[i] == 1.0f;
    d.ns = ns;
    snprintf(name, sizeof name, "%s/zero_ns", t->name);
    outputs_alloc(&got, d.n);
    outputs_alloc(&want, d.n);
    run_ref(&d, d.ns, d.idx, d.b, 3.0f, &want);
    if (run(t, &d, 0, d.n, d.ns, d.idx, d.b, 3.0f, got.blend, got.limit, got.sub, msg, sizeof msg)) {
        agree(&got, &want, 0, d.n, 1e-5, msg, sizeof msg);
        exactly_zero(got.sub, "S", 0, d.n, NULL, msg, sizeof msg);
        exactly_zero(got.blend, "B (b = 1)", 0, d.n, one, msg, sizeof msg);
        for (i = 0; i < d.n && !msg[0]; ++i)
            if (!one[i] && max_diff(got.blend, got.limit, i, i + 1, &at) > 1e-6) snprintf(msg, sizeof msg, "B is not L at element %d", i);
    }
    report(name, msg);
    outputs_free(&got);
    outputs_free(&want);
    free(ns); free(one);
}

/* L along an axis (tu, tv: signed axes scaled by powers of two), ns = -2^j L, b^p = 0.5
 * exactly: B = 0 exactly. */
static void check_antiparallel(const target *t) {
    const int n = 96;
    data d;
    outputs got, want;
    char name[128], msg[1024] = "";
    int i, v;
    data_alloc(&d, n, n);
    for (i = 0; i < n; ++i) {
        const int ax = i % 3, sa = (i / 3) % 2 ? -1 : 1, sb = (i / 6) % 2 ? -1 : 1;
        const float sc = ldexpf(1.0f, (i / 12) % 4 - 2), sn = ldexpf(1.0f, (i / 48) - 1);
        double L[3], a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
        int c;
        for (c = 0; c < 3; ++c) d.tu[3 * i + c] = d.tv[3 * i + c] = 0.0f;
        d.tu[3 * i + ax] = (float)sa * sc;
        d.tv[3 * i + (ax + 1) % 3] = (float)sb;
        a[ax] = sa;
        b[(ax + 1) % 3] = sb;
        cross3(a, b, L);
        for (c = 0; c < 3; ++c) d.ns[3 * i + c] = (float)(-L[c]) * sn;
        d.idx[i] = i;
    }
    snprintf(name, sizeof name, "%s/antiparallel", t->name);
    outputs_alloc(&got, n);
    outputs_alloc(&want, n);
    for (v = 0; v < 2 && !msg[0]; ++v) {
        const float p = v ? 0.5f : 1.0f, bv = v ? 0.25f : 0.5f;
        for (i = 0; i < n; ++i) d.b[i] = bv;
        run_ref(&d, d.ns, d.idx, d.b, p, &want);
        exactly_zero(want.blend, "ref's B", 0, n, NULL, msg, sizeof msg);
        if (run(t, &d, 0, n, d.ns, d.idx, d.b, p, got.blend, got.limit, got.sub, msg, sizeof msg)) {
            agree(&got, &want, 0, n, 1e-6, msg, sizeof msg);
            exactly_zero(got.blend, v ? "B (b = 0.25, p = 0.5)" : "B (b = 0.5, p = 1)", 0, n, NULL, msg, sizeof msg);
        }
    }
    report(name, msg);
    outputs_free(&got);
    outputs_free(&want);
    data_free(&d);
}

/* Tangents and normals times 2^-70, 2^70, and tu times 2^70 with tv and ns times 2^-70
 * (exact): the results of the unscaled data. */
static void check_scale(const target *t, const data *base) {
    outputs got, want;
    char name[128], msg[1024] = "";
    int s, i;
    snprintf(name, sizeof name, "%s/scale", t->name);
    outputs_alloc(&got, base->n);
    outputs_alloc(&want, base->n);
    run_ref(base, base->ns, base->idx, base->b, 2.2f, &want);
    for (s = 0; s < 3 && !msg[0]; ++s) {
        data d = *base;
        const int e = s == 1 ? 70 : -70, eu = s == 0 ? -70 : 70;
        d.tu = (float *)xmalloc((size_t)d.n * 3 * sizeof(float));
        d.tv = (float *)xmalloc((size_t)d.n * 3 * sizeof(float));
        d.ns = (float *)xmalloc((size_t)d.nns * 3 * sizeof(float));
        for (i = 0; i < 3 * d.n; ++i) {
            d.tu[i] = ldexpf(base->tu[i], eu);
            d.tv[i] = ldexpf(base->tv[i], e);
        }
        for (i = 0; i < 3 * d.nns; ++i) d.ns[i] = ldexpf(base->ns[i], e);
        if (run(t, &d, 0, d.n, d.ns, d.idx, d.b, 2.2f, got.blend, got.limit, got.sub, msg, sizeof msg)) {
            agree(&got, &want, 0, d.n, 1e-5, msg, sizeof msg);
            prefix(msg, sizeof msg, "tu times 2^%d, tv and ns times 2^%d: ", eu, e);
        }
        free(d.tu); free(d.tv); free(d.ns);
    }
    report(name, msg);
    outputs_free(&got);
    outputs_free(&want);
}

/* out_limit / out_sub NULL or given: B is the same bit for bit, the given ones agree with ref. */
static void check_outputs(const target *t, const data *d) {
    outputs first, got, want;
    char name[128], msg[1024] = "";
    int v, at;
    snprintf(name, sizeof name, "%s/outputs", t->name);
    outputs_alloc(&first, d->n);
    outputs_alloc(&got, d->n);
    outputs_alloc(&want, d->n);
    run_ref(d, d->ns, d->idx, d->b, 0.5f, &want);
    for (v = 0; v < 4 && !msg[0]; ++v) {
        float *lim = v & 1 ? got.limit : NULL, *sub = v & 2 ? got.sub : NULL;
        outputs view;
        if (!run(t, d, 0, d->n, d->ns, d->idx, d->b, 0.5f, got.blend, lim, sub, msg, sizeof msg)) break;
        view.blend = got.blend;
        view.limit = lim;
        view.sub = sub;
        agree(&view, &want, 0, d->n, 1e-5, msg, sizeof msg);
        if (v == 0) memcpy(first.blend, got.blend, (size_t)d->n * 3 * sizeof(float));
        else if (memcmp(first.blend, got.blend, (size_t)d->n * 3 * sizeof(float)) != 0 && !msg[0])
            snprintf(msg, sizeof msg, "B with%s limit and with%s sub differs from B alone (by %.3g at element %d)", lim ? "" : "out",
                     sub ? "" : "out", max_diff(got.blend, first.blend, 0, d->n, &at), at);
        if (!strstr(msg, "B with")) prefix(msg, sizeof msg, "limit %s, sub %s: ", lim ? "given" : "NULL", sub ? "given" : "NULL");
    }
    report(name, msg);
    outputs_free(&first);
    outputs_free(&got);
    outputs_free(&want);
}

/* Sub-ranges: outside [first, last) untouched (every output), inside as ref. */
static void check_subrange(const target *t, const data *small, const data *large) {
    static const int ranges[4][2] = {{1, 2}, {137, 731}, {3, -5}, {9000, -1}}; /* negative: from the end */
    outputs got, want;
    char name[128], msg[1024] = "";
    int r;
    snprintf(name, sizeof name, "%s/subrange", t->name);
    for (r = 0; r < 4 && !msg[0]; ++r) {
        const data *d = r < 2 ? small : large;
        const int first = ranges[r][0], last = ranges[r][1] < 0 ? d->n + ranges[r][1] : ranges[r][1];
        outputs_alloc(&got, d->n);
        outputs_alloc(&want, d->n);
        run_ref(d, d->ns, d->idx, d->b, 3.0f, &want);
        if (run(t, d, first, last, d->ns, d->idx, d->b, 3.0f, got.blend, r == 1 ? NULL : got.limit, got.sub, msg, sizeof msg)) {
            if (r == 1) { free(want.limit); want.limit = NULL; }
            agree(&got, &want, first, last, 1e-5, msg, sizeof msg);
            untouched(got.blend, "blend", d->n, first, last, msg, sizeof msg);
            untouched(got.limit, "limit", d->n, r == 1 ? 0 : first, r == 1 ? 0 : last, msg, sizeof msg);
            untouched(got.sub, "sub", d->n, first, last, msg, sizeof msg);
            prefix(msg, sizeof msg, "[%d, %d) of %d: ", first, last, d->n);
        }
        outputs_free(&got);
        outputs_free(&want);
    }
    report(name, msg);
}

/* |B| in double for element i blended with ns row k at exponent p (as data_random measures it). */
static double blend_len(const data *d, int i, int k, double p) {
    double ua[3], ut[3], L[3], S[3], B[3], l, w = d->b[i] > 0.0f ? pow((double)d->b[i], p) : 0.0;
    int c;
    unit_of(d->tu + 3 * (size_t)i, ua);
    unit_of(d->tv + 3 * (size_t)i, ut);
    cross3(ua, ut, L);
    l = len3(L);
    for (c = 0; c < 3; ++c) L[c] /= l;
    unit_of(d->ns + 3 * (size_t)k, S);
    for (c = 0; c < 3; ++c) B[c] = (1.0 - w) * L[c] + w * S[c];
    return len3(B);
}

/* Indices near the element (i / 3, every 5th -1), so that gl uploads a slice of ns per batch.
 * An index whose blend nearly cancels (|B| < 0.05, where normalising B magnifies float rounding
 * past the tolerance) is -1 instead, as data_random never picks one. */
static void check_batches(const target *t, const data *base) {
    data d = *base;
    outputs got, want;
    char name[128], msg[1024] = "";
    int i;
    int *idx = (int *)xmalloc((size_t)d.n * sizeof(int));
    for (i = 0; i < d.n; ++i) {
        int k = i / 3 < d.nns ? i / 3 : d.nns - 1;
        idx[i] = i % 5 == 4 || blend_len(&d, i, k, 1.0) < 0.05 ? -1 : k;
    }
    d.idx = idx;
    snprintf(name, sizeof name, "%s/batches", t->name);
    outputs_alloc(&got, d.n);
    outputs_alloc(&want, d.n);
    run_ref(&d, d.ns, d.idx, d.b, 1.0f, &want);
    if (run(t, &d, 0, d.n, d.ns, d.idx, d.b, 1.0f, got.blend, got.limit, got.sub, msg, sizeof msg))
        agree(&got, &want, 0, d.n, 1e-5, msg, sizeof msg);
    report(name, msg);
    outputs_free(&got);
    outputs_free(&want);
    free(idx);
}

static void check_empty(const target *t, const data *d) {
    outputs got;
    char name[128], msg[1024] = "";
    snprintf(name, sizeof name, "%s/empty", t->name);
    outputs_alloc(&got, d->n);
    if (run(t, d, 5, 5, d->ns, d->idx, d->b, 1.0f, got.blend, got.limit, got.sub, msg, sizeof msg)) {
        untouched(got.blend, "blend", d->n, 0, 0, msg, sizeof msg);
        untouched(got.limit, "limit", d->n, 0, 0, msg, sizeof msg);
        untouched(got.sub, "sub", d->n, 0, 0, msg, sizeof msg);
    }
    report(name, msg);
    outputs_free(&got);
}

typedef struct suite {
    data random[4];   /* 10^5 elements, one per exponent of k_ps */
    data small;       /* 1000 elements */
    data large;       /* 20000 elements */
} suite;

static void run_target(const target *t, const suite *S) {
    check_caps(t);
    if (!t->vt->finish_normals) return;
    check_random(t, S->random);
    check_b_exact(t, &S->small, 0.0f);
    check_b_exact(t, &S->small, 1.0f);
    check_no_normals(t, &S->small);
    check_no_b(t, &S->small);
    check_zero_tangents(t, &S->small);
    check_zero_ns(t, &S->small);
    check_antiparallel(t);
    check_scale(t, &S->small);
    check_outputs(t, &S->small);
    check_subrange(t, &S->small, &S->large);
    check_batches(t, &S->large);
    check_empty(t, &S->small);
}

/* ---- backends ---- */
/* A context on `kind` alone (NULL with `why` filled when it cannot initialise). */
static sfb_context *target_context(sfb_backend_kind kind, int threads, char *why, size_t why_size) {
    sfb_context *ctx = make_context_threads(kind, threads);
    if (ctx && ctx->backend && ctx->backend->kind == kind) return ctx;
    if (ctx) sfb_context_destroy(ctx);
    why[0] = 0;
    if (sfb_backend_probe(kind, NULL, why, why_size) == SFB_SUCCESS || !why[0])
        snprintf(why, why_size, "sfb_context_create failed (or chose another backend) after a successful probe");
    return NULL;
}

/* simd: each instruction set (or the one SURFBLEND_SIMD_ISA pins) with threads 1 and 2; one
 * that this CPU or build lacks is a SKIP. */
static void run_simd(const suite *S, int required) {
    static const char *const isas[5] = {"portable", "sse2", "avx2", "avx512", "neon"};
    const char *pinned = getenv("SURFBLEND_SIMD_ISA");
    char saved[64];
    int k, threads;
    snprintf(saved, sizeof saved, "%s", pinned ? pinned : "");
    if (saved[0]) {
        for (k = 0; k < 5 && strcmp(saved, isas[k]) != 0; ++k) {}
        if (k == 5) {
            skip("simd", "SURFBLEND_SIMD_ISA names no instruction set (portable, sse2, avx2, avx512, neon)");
            return;
        }
        printf("# SURFBLEND_SIMD_ISA=%s: that instruction set only\n", saved);
    }
    for (k = 0; k < 5; ++k) {
        const char *isa = isas[k];
        if (saved[0] && strcmp(saved, isa) != 0) continue;
        for (threads = 1; threads <= 2; ++threads) {
            target t;
            char why[512], info[256];
            sfb_context *ctx;
            memset(&t, 0, sizeof t);
            snprintf(t.name, sizeof t.name, "simd-%s/t%d", isa, threads);
            setenv("SURFBLEND_SIMD_ISA", isa, 1);
            ctx = target_context(SFB_BACKEND_SIMD, threads, why, sizeof why);
            if (saved[0]) setenv("SURFBLEND_SIMD_ISA", saved, 1);
            else unsetenv("SURFBLEND_SIMD_ISA");
            if (!ctx) {
                unavailable(t.name, required, why);
                continue;
            }
            info[0] = 0;
            sfb_context_backend_info(ctx, info, sizeof info);
            if (strncmp(info, isa, strlen(isa)) != 0 || info[strlen(isa)] != ' ') {
                snprintf(why, sizeof why, "this CPU or build has no %s kernels (the backend runs: %s)", isa, info);
                skip(t.name, why);
                sfb_context_destroy(ctx);
                continue;
            }
            printf("# %s: %s\n", t.name, info);
            t.vt = ctx->backend;
            t.state = ctx->backend_state;
            t.ctx = ctx;
            run_target(&t, S);
            sfb_context_destroy(ctx);
        }
    }
}

static void run_gl(const suite *S, sfb_backend_kind kind, int required) {
    target t;
    char why[512], info[400];
    sfb_context *ctx;
    memset(&t, 0, sizeof t);
    snprintf(t.name, sizeof t.name, "%s", sfb_backend_kind_name(kind));
    ctx = target_context(kind, 1, why, sizeof why);
    if (!ctx) {
        unavailable(t.name, required, why);
        return;
    }
    info[0] = 0;
    sfb_context_backend_info(ctx, info, sizeof info);
    printf("# %s: %s\n", t.name, info);
    t.vt = ctx->backend;
    t.state = ctx->backend_state;
    t.ctx = ctx;
    run_target(&t, S);
    sfb_context_destroy(ctx);
}

/* ---- --bench ---- */
static double bench_one(const target *t, const data *d, float p, int all) {
    outputs o;
    double best = HUGE_VAL;
    int r;
    char msg[512] = "";
    outputs_alloc(&o, d->n);
    for (r = 0; r < 7; ++r) {
        double t0 = now_s(), dt;
        if (!run(t, d, 0, d->n, d->ns, d->idx, d->b, p, o.blend, all ? o.limit : NULL, all ? o.sub : NULL, msg, sizeof msg)) {
            printf("# bench %s: %s\n", t->name, msg);
            break;
        }
        dt = now_s() - t0;
        if (r > 0 && dt < best) best = dt; /* the first call compiles, allocates, faults pages in */
    }
    outputs_free(&o);
    return best;
}

static void bench(int n) {
    data local, spread;
    static const sfb_backend_kind kinds[4] = {SFB_BACKEND_REF, SFB_BACKEND_SIMD, SFB_BACKEND_SIMD, SFB_BACKEND_GL};
    int i, k;
    data_random(&spread, n, n / 2, 2.2f, 99);
    local = spread;
    local.idx = (int *)xmalloc((size_t)n * sizeof(int));
    for (i = 0; i < n; ++i) local.idx[i] = spread.idx[i] < 0 ? -1 : i / 2;
    for (k = 0; k < 5; ++k) {
        const sfb_backend_kind kind = k == 4 ? SFB_BACKEND_OSMESA : kinds[k];
        target t;
        char why[512], info[400] = "";
        sfb_context *ctx = target_context(kind, k == 2 ? 2 : 1, why, sizeof why);
        if (!ctx) {
            printf("# bench %s: unavailable: %s\n", sfb_backend_kind_name(kind), why);
            continue;
        }
        sfb_context_backend_info(ctx, info, sizeof info);
        memset(&t, 0, sizeof t);
        snprintf(t.name, sizeof t.name, "%s", sfb_backend_kind_name(kind));
        t.vt = ctx->backend;
        t.state = ctx->backend_state;
        t.ctx = ctx;
        printf("# bench %-6s %8.2f ms all outputs, %8.2f ms B only (indices spread); %8.2f ms all outputs (indices local); %d elements; %s\n",
               t.name, 1e3 * bench_one(&t, &spread, 2.2f, 1), 1e3 * bench_one(&t, &spread, 2.2f, 0), 1e3 * bench_one(&t, &local, 2.2f, 1),
               n, info[0] ? info : "ref");
        sfb_context_destroy(ctx);
    }
    free(local.idx);
    data_free(&spread);
}

int main(int argc, char **argv) {
    const char *req = getenv("SFB_REQUIRE_BACKENDS"), *seed = NULL;
    suite S;
    target ref;
    sfb__backend_vtable ref_vt;
    int i, bench_n = 0;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) seed = argv[++i];
        else if (strcmp(argv[i], "--bench") == 0 && i + 1 < argc) bench_n = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: %s [--seed S] [--bench N]\n", argv[0]);
            return 2;
        }
    }
    harness_seed(seed);
    printf("# seed %llu\n", g_seed);
    if (req) printf("# SFB_REQUIRE_BACKENDS=%s\n", req);
    if (bench_n > 0) {
        bench(bench_n);
        return 0;
    }
    for (i = 0; i < 4; ++i) data_random(&S.random[i], 100000, 50000, k_ps[i], 1 + (unsigned long long)i);
    data_random(&S.small, 1000, 400, 2.2f, 10);
    data_random(&S.large, 20000, 9000, 3.0f, 11);

    memset(&ref, 0, sizeof ref);
    snprintf(ref.name, sizeof ref.name, "ref");
    sfb__backend_bind(SFB_BACKEND_REF, &ref_vt);
    ref.vt = &ref_vt;
    run_target(&ref, &S);
    run_simd(&S, backend_required("simd"));
    run_gl(&S, SFB_BACKEND_GL, backend_required("gl"));
    run_gl(&S, SFB_BACKEND_OSMESA, backend_required("osmesa"));

    for (i = 0; i < 4; ++i) data_free(&S.random[i]);
    data_free(&S.small);
    data_free(&S.large);
    return close_tests();
}
