/* Surface quality analysis (sfb_surface_analyze, src/analyze.c, seed 003) on every backend:
 *   - analytic truth: regular Catmull-Clark grids whose control points sample the paraboloid
 *     z = a (x^2 + y^2) (limit: the same paraboloid raised by 2a/3, since the uniform cubic
 *     B-spline of the samples of x^2 is x^2 + 1/3) and the saddle z = a x y (reproduced exactly),
 *     seen from straight above (orthographic) inside their regular region: the reflection
 *     classes agree with the analytic ones on >= 99.5 % of the pixels, Gaussian and mean curvature
 *     within 1e-4 relative;
 *   - level independence: the classes of level-1 and level-4 proxies agree on >= 99.5 % of the
 *     pixels both cover, on shapes with extraordinary vertices and creases (Catmull-Clark, Loop,
 *     manifold blending), while the polygon-based method disagrees far more (both printed);
 *   - no gaps: at level 1 no uncovered pixel is enclosed by the surface, and the coverage equals
 *     a level-6 proxy's except within a one-pixel band of its silhouette;
 *   - every backend against ref: >= 99.5 % identical classes, curvature within 1e-3 relative;
 *   - bad configurations are refused with the output zeroed; cancellation; the memory budget.
 * A backend that is unavailable SKIPs (FAILs when listed in SFB_REQUIRE_BACKENDS). */
#include "surfblend.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"

static const char *g_shapes = "../shared/peers/opensubdiv-shapes";

/* A regular grid of n x n vertices, spacing 1, centred at 0, z = f(x, y). */
static sfb_mesh *grid_mesh(sfb_context *ctx, int n, double a, int saddle) {
    float *p = (float *)xmalloc((size_t)n * n * 3 * sizeof(float));
    int *fs = (int *)xmalloc((size_t)(n - 1) * (n - 1) * sizeof(int)), *fv = (int *)xmalloc((size_t)(n - 1) * (n - 1) * 4 * sizeof(int));
    int i, j, f = 0;
    sfb_mesh_desc d;
    sfb_mesh *m = NULL;
    double c = 0.5 * (n - 1);
    for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) {
            double x = i - c, y = j - c;
            p[3 * (j * n + i)] = (float)x;
            p[3 * (j * n + i) + 1] = (float)y;
            p[3 * (j * n + i) + 2] = (float)(saddle ? a * x * y : a * (x * x + y * y));
        }
    for (j = 0; j + 1 < n; ++j)
        for (i = 0; i + 1 < n; ++i) {
            fs[f] = 4;
            fv[4 * f] = j * n + i; fv[4 * f + 1] = j * n + i + 1; fv[4 * f + 2] = (j + 1) * n + i + 1; fv[4 * f + 3] = (j + 1) * n + i;
            ++f;
        }
    memset(&d, 0, sizeof d);
    d.vertex_count = n * n; d.positions = p; d.face_count = f; d.face_sizes = fs; d.face_vertices = fv;
    if (sfb_mesh_create(ctx, &d, &m) != SFB_SUCCESS) m = NULL;
    free(p); free(fs); free(fv);
    return m;
}

static sfb_surface *patch_surface(sfb_context *ctx, const sfb_mesh *m, sfb_scheme scheme) {
    sfb_surface_config sc = sfb_surface_config_init(scheme, 0);
    sfb_surface *s = NULL;
    sc.flags = SFB_REFINE_PATCHES;
    if (sfb_surface_create(ctx, m, &sc, &s) != SFB_SUCCESS) return NULL;
    return s;
}

static sfb_mesh *load_shape(sfb_context *ctx, const char *path) {
    size_t n;
    char *t = slurp(path, &n);
    sfb_mesh *m = NULL;
    if (!t) return NULL;
    if (sfb_mesh_read_obj(ctx, t, n, &m) != SFB_SUCCESS) m = NULL;
    free(t);
    return m;
}

/* The view from straight above onto the square [-h, h]^2 (orthographic). */
static void top_view(sfb_analyze_config *c, double h, int size) {
    c->width = c->height = size;
    c->camera_set = 1;
    c->orthographic = 1;
    c->eye[0] = 0.0f; c->eye[1] = 0.0f; c->eye[2] = 30.0f;
    c->target[0] = c->target[1] = c->target[2] = 0.0f;
    c->up[0] = 0.0f; c->up[1] = 1.0f; c->up[2] = 0.0f;
    c->fov = (float)(2.0 * h);
}
/* A light plane above: centre (0, 0, 12), facing down, axis x, 40 x 40, 20 stripes. */
static void top_light(sfb_analyze_config *c) {
    c->light_set = 1;
    c->light_center[0] = 0.0f; c->light_center[1] = 0.0f; c->light_center[2] = 12.0f;
    c->light_normal[0] = 0.0f; c->light_normal[1] = 0.0f; c->light_normal[2] = -1.0f;
    c->light_axis[0] = 1.0f; c->light_axis[1] = 0.0f; c->light_axis[2] = 0.0f;
    c->light_size[0] = c->light_size[1] = 40.0f;
    c->stripes = 20.0f;
}

/* ---- analytic truth ---- */
typedef struct surf_pt { double z, fx, fy, fxx, fxy, fyy; } surf_pt;
static surf_pt analytic(double a, int saddle, double x, double y) {
    surf_pt s;
    if (saddle) { s.z = a * x * y; s.fx = a * y; s.fy = a * x; s.fxx = 0.0; s.fxy = a; s.fyy = 0.0; }
    else { s.z = a * (x * x + y * y) + 2.0 * a / 3.0; s.fx = 2.0 * a * x; s.fy = 2.0 * a * y; s.fxx = 2.0 * a; s.fxy = 0.0; s.fyy = 2.0 * a; }
    return s;
}

static void test_analytic(sfb_context *ctx, int saddle) {
    const double a = saddle ? 0.06 : 0.05, h = 3.5;
    const int size = 160;
    char name[128];
    sfb_mesh *m = grid_mesh(ctx, 16, a, saddle);
    sfb_surface *s = m ? patch_surface(ctx, m, SFB_SCHEME_CATMARK) : NULL;
    sfb_analyze_config c = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
    sfb_analysis an;
    int kind, x, y;
    snprintf(name, sizeof name, "analytic_%s_reflection", saddle ? "saddle" : "paraboloid");
    if (!s) { fail(name, "no surface: %s", sfb_last_error(ctx)); sfb_mesh_destroy(m); return; }
    top_view(&c, h, size);
    top_light(&c);
    c.level = 1;
    if (sfb_surface_analyze(s, &c, &an) != SFB_SUCCESS) fail(name, "%s", sfb_last_error(ctx));
    else {
        long same = 0, total = 0;
        double worst = 0.0;
        for (y = 0; y < size; ++y)
            for (x = 0; x < size; ++x) {
                /* the pixel centre's ray: (px, py) in the model, straight down */
                double px = -h + 2.0 * h * (x + 0.5) / size, py = h - 2.0 * h * (y + 0.5) / size, n[3], r[3], l, mu, X[3], w;
                surf_pt t = analytic(a, saddle, px, py);
                int cls, k = y * size + x;
                n[0] = -t.fx; n[1] = -t.fy; n[2] = 1.0;
                l = sqrt(n[0] * n[0] + n[1] * n[1] + 1.0);
                n[0] /= l; n[1] /= l; n[2] /= l;
                /* v = (0, 0, 1) toward the viewer; r = 2 (v.n) n - v */
                r[0] = 2.0 * n[2] * n[0]; r[1] = 2.0 * n[2] * n[1]; r[2] = 2.0 * n[2] * n[2] - 1.0;
                mu = (12.0 - t.z) / r[2];
                X[0] = px + mu * r[0]; X[1] = py + mu * r[1]; X[2] = t.z + mu * r[2];
                w = (X[0] / 40.0 + 0.5) * 20.0;
                cls = (w - floor(w)) < 0.5 ? 3 : 2;
                ++total;
                same += an.classes[k] == cls;
                if (isfinite(an.values[k]) && fabs(an.values[k] - w) > worst) worst = fabs(an.values[k] - w);
            }
        check(same >= 0.995 * total, name, "classes agree on %.3f %% of %ld pixels (worst stripe coordinate error %.2e)",
              100.0 * same / total, total, worst);
        printf("# %s: %.3f %% of %ld pixels agree, stripe coordinate within %.2e\n", name, 100.0 * same / total, total, worst);
        sfb_analysis_free(&an);
    }
    for (kind = 0; kind < 2; ++kind) {
        snprintf(name, sizeof name, "analytic_%s_%s_curvature", saddle ? "saddle" : "paraboloid", kind ? "mean" : "gaussian");
        c = sfb_analyze_config_init(SFB_ANALYZE_CURVATURE);
        top_view(&c, h, size);
        c.curvature = kind ? SFB_CURVATURE_MEAN : SFB_CURVATURE_GAUSSIAN;
        c.level = 1;
        if (sfb_surface_analyze(s, &c, &an) != SFB_SUCCESS) { fail(name, "%s", sfb_last_error(ctx)); continue; }
        {
            double worst = 0.0;
            long bad = 0, total = 0;
            for (y = 0; y < size; ++y)
                for (x = 0; x < size; ++x) {
                    double px = -h + 2.0 * h * (x + 0.5) / size, py = h - 2.0 * h * (y + 0.5) / size, W2, K, H, want, got, e;
                    surf_pt t = analytic(a, saddle, px, py);
                    W2 = 1.0 + t.fx * t.fx + t.fy * t.fy;
                    K = (t.fxx * t.fyy - t.fxy * t.fxy) / (W2 * W2);
                    /* the library's sign: convex toward the viewer (above) positive */
                    H = -((1.0 + t.fx * t.fx) * t.fyy - 2.0 * t.fx * t.fy * t.fxy + (1.0 + t.fy * t.fy) * t.fxx) / (2.0 * pow(W2, 1.5));
                    want = kind ? H : K;
                    got = an.values[y * size + x];
                    /* relative to the value, or where it passes through 0 (the saddle's mean
                     * curvature on the axes) to a hundredth of the shape's scale a */
                    e = fabs(got - want) / (fabs(want) > 1e-2 * a ? fabs(want) : 1e-2 * a);
                    if (!(e <= 1e-4)) ++bad;
                    if (e > worst || !isfinite(e)) worst = isfinite(e) ? e : HUGE_VAL;
                    ++total;
                }
            check(bad == 0, name, "%ld of %ld pixels off by more than 1e-4 relative (worst %.2e)", bad, total, worst);
            printf("# %s: worst relative error %.2e over %ld pixels\n", name, worst, total);
        }
        sfb_analysis_free(&an);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
}

/* ---- level independence, no gaps ---- */
typedef struct shape { const char *label, *path; sfb_scheme scheme; } shape;

/* Share of pixels covered in both with the same class, over those covered in both. */
static double agreement(const sfb_analysis *a, const sfb_analysis *b, long *both) {
    long n = 0, same = 0, k, np = (long)a->width * a->height;
    for (k = 0; k < np; ++k)
        if (a->classes[k] && b->classes[k]) { ++n; same += a->classes[k] == b->classes[k]; }
    *both = n;
    return n ? (double)same / n : 0.0;
}

static int analyze_at(sfb_surface *s, int level, int polygon, sfb_analysis *an) {
    sfb_analyze_config c = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
    c.width = 240; c.height = 180;
    c.level = level;
    c.polygon_based = polygon;
    return sfb_surface_analyze(s, &c, an) == SFB_SUCCESS;
}

/* Uncovered pixels that the background, flooded from the border, does not reach. */
static long enclosed_holes(const sfb_analysis *a) {
    int w = a->width, h = a->height;
    long n = (long)w * h, k, holes = 0, top = 0;
    unsigned char *seen = (unsigned char *)calloc((size_t)n, 1);
    long *stack = (long *)xmalloc((size_t)n * sizeof(long));
    for (k = 0; k < n; ++k) {
        int x = (int)(k % w), y = (int)(k / w);
        if ((x == 0 || y == 0 || x == w - 1 || y == h - 1) && a->classes[k] == 0) { seen[k] = 1; stack[top++] = k; }
    }
    while (top > 0) {
        long q = stack[--top];
        int x = (int)(q % w), y = (int)(q / w), d;
        static const int dx[4] = { 1, -1, 0, 0 }, dy[4] = { 0, 0, 1, -1 };
        for (d = 0; d < 4; ++d) {
            int nx = x + dx[d], ny = y + dy[d];
            long r;
            if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
            r = (long)ny * w + nx;
            if (!seen[r] && a->classes[r] == 0) { seen[r] = 1; stack[top++] = r; }
        }
    }
    for (k = 0; k < n; ++k) holes += a->classes[k] == 0 && !seen[k];
    free(seen);
    free(stack);
    return holes;
}

/* Pixels whose coverage differs from ref's that are not next to ref's silhouette. */
static long coverage_off_band(const sfb_analysis *a, const sfb_analysis *ref) {
    int w = a->width, h = a->height, x, y, dx, dy;
    long off = 0;
    for (y = 0; y < h; ++y)
        for (x = 0; x < w; ++x) {
            long k = (long)y * w + x;
            int ca = a->classes[k] != 0, cr = ref->classes[k] != 0, band = 0;
            if (ca == cr) continue;
            for (dy = -1; dy <= 1 && !band; ++dy)
                for (dx = -1; dx <= 1; ++dx) {
                    int nx = x + dx, ny = y + dy;
                    if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                    if ((ref->classes[(long)ny * w + nx] != 0) != cr) { band = 1; break; }
                }
            off += !band;
        }
    return off;
}

static void test_levels(sfb_context *ctx, const shape *shapes, int count) {
    int i;
    for (i = 0; i < count; ++i) {
        char name[160];
        sfb_mesh *m = load_shape(ctx, shapes[i].path);
        sfb_surface *s = m ? patch_surface(ctx, m, shapes[i].scheme) : NULL;
        sfb_analysis e1, e4, p1, p4, e6;
        long both_e, both_p;
        double ae, ap;
        snprintf(name, sizeof name, "level_independence_%s", shapes[i].label);
        if (!m) { skip(name, "shape not found"); continue; }
        if (!s) { fail(name, "no surface: %s", sfb_last_error(ctx)); sfb_mesh_destroy(m); continue; }
        memset(&e1, 0, sizeof e1); memset(&e4, 0, sizeof e4); memset(&p1, 0, sizeof p1); memset(&p4, 0, sizeof p4); memset(&e6, 0, sizeof e6);
        if (!analyze_at(s, 1, 0, &e1) || !analyze_at(s, 4, 0, &e4) || !analyze_at(s, 1, 1, &p1) || !analyze_at(s, 4, 1, &p4) ||
            !analyze_at(s, 6, 0, &e6)) {
            fail(name, "%s", sfb_last_error(ctx));
        } else {
            ae = agreement(&e1, &e4, &both_e);
            ap = agreement(&p1, &p4, &both_p);
            printf("# %s: exact per pixel level 1 vs 4 agree on %.3f %% of %ld pixels; polygon-based on %.3f %% of %ld "
                   "(level 1: %d fallback, %d grown, %d dropped)\n",
                   shapes[i].label, 100.0 * ae, both_e, 100.0 * ap, both_p, e1.fallback_pixels, e1.grown_pixels, e1.dropped_pixels);
            check(ae >= 0.995 && both_e > 1000, name, "level 1 vs 4 agree on %.3f %% of %ld pixels (>= 99.5 %% wanted)", 100.0 * ae, both_e);
            snprintf(name, sizeof name, "polygon_based_depends_on_level_%s", shapes[i].label);
            check(1.0 - ap >= 3.0 * (1.0 - ae) && 1.0 - ap > 0.01, name, "polygon-based disagreement %.3f %% vs exact %.3f %%",
                  100.0 * (1.0 - ap), 100.0 * (1.0 - ae));
            snprintf(name, sizeof name, "no_gaps_%s", shapes[i].label);
            {
                long holes = enclosed_holes(&e1), off = coverage_off_band(&e1, &e6);
                check(holes == 0 && off == 0, name, "level 1: %ld enclosed uncovered pixels, %ld coverage differences from level 6 outside the one-pixel band",
                      holes, off);
                printf("# %s: level-1 proxy covers %d pixels, the exact surface %d (level 6: %d)\n", shapes[i].label, e1.proxy_pixels,
                       e1.covered_pixels, e6.covered_pixels);
            }
        }
        sfb_analysis_free(&e1); sfb_analysis_free(&e4); sfb_analysis_free(&p1); sfb_analysis_free(&p4); sfb_analysis_free(&e6);
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
    }
}

/* A large picture (800 x 800, over 100k covered pixels): round 0's attempts then run in
 * several bands of rows (SFB__AN_BATCH, 32768, attempts at most), whose hits seed the bands
 * after them. Level 1 and
 * level 6 must still agree on the classes (>= 99.5 %) and on the coverage outside the
 * one-pixel band, with no enclosed holes at level 1. */
static void test_large(sfb_context *ctx, const shape *sh) {
    const char *name = "large_picture_batches_creased_box";
    sfb_mesh *m = load_shape(ctx, sh->path);
    sfb_surface *s = m ? patch_surface(ctx, m, sh->scheme) : NULL;
    sfb_analysis a1, a6;
    sfb_analyze_config c = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
    long both = 0;
    memset(&a1, 0, sizeof a1); memset(&a6, 0, sizeof a6);
    if (!m) { skip(name, "shape not found"); return; }
    c.width = c.height = 800;
    c.level = 1;
    if (!s || sfb_surface_analyze(s, &c, &a1) != SFB_SUCCESS || (c.level = 6, sfb_surface_analyze(s, &c, &a6)) != SFB_SUCCESS) {
        fail(name, "%s", sfb_last_error(ctx));
    } else {
        const double agree = agreement(&a1, &a6, &both);
        const long holes = enclosed_holes(&a1), off = coverage_off_band(&a1, &a6);
        check(a1.covered_pixels > 100000 && agree >= 0.995 && holes == 0 && off == 0, name,
              "%d pixels covered, level 1 vs 6 agree on %.3f %%, %ld enclosed holes, %ld coverage differences outside the band",
              a1.covered_pixels, 100.0 * agree, holes, off);
        printf("# %s: %d pixels, level 1 vs 6 agree on %.3f %% (%d dropped)\n", name, a1.covered_pixels, 100.0 * agree, a1.dropped_pixels);
    }
    sfb_analysis_free(&a1); sfb_analysis_free(&a6);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
}

/* The default proxy level (sfb_analyze_config.level 0) is chosen from the view: reported in
 * proxy_level, within 1..4; finer on a coarse mesh (a 6-face cube: its level-1 triangles
 * would cover thousands of pixels) than on a fine one (catmark_car's 1575 faces: level 1);
 * an explicit level is used as given, a polygon-based picture's default is 2; and the picture
 * at the chosen level agrees with the level-4 one (>= 99.5 % of the pixels both cover). */
static void test_auto_level(sfb_context *ctx, const shape *shapes, int count) {
    char car[1024];
    shape all[8];
    int i, n = 0, coarse = -1, fine = -1;
    for (i = 0; i < count && n < 7; ++i) all[n++] = shapes[i];
    snprintf(car, sizeof car, "%s/catmark_car.obj", g_shapes);
    all[n].label = "catmark_car"; all[n].path = car; all[n].scheme = SFB_SCHEME_CATMARK; ++n;
    for (i = 0; i < n; ++i) {
        char name[160];
        sfb_mesh *m = load_shape(ctx, all[i].path);
        sfb_surface *s = m ? patch_surface(ctx, m, all[i].scheme) : NULL;
        sfb_analysis a, b, e, pg;
        sfb_analyze_config c = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
        long both = 0;
        memset(&a, 0, sizeof a); memset(&b, 0, sizeof b); memset(&e, 0, sizeof e); memset(&pg, 0, sizeof pg);
        snprintf(name, sizeof name, "auto_level/%s", all[i].label);
        if (!m) { skip(name, "shape not found"); continue; }
        if (!s || sfb_surface_analyze(s, &c, &a) != SFB_SUCCESS || (c.level = 4, sfb_surface_analyze(s, &c, &b)) != SFB_SUCCESS ||
            (c.level = 3, sfb_surface_analyze(s, &c, &e)) != SFB_SUCCESS || (c.level = 0, c.polygon_based = 1, sfb_surface_analyze(s, &c, &pg)) != SFB_SUCCESS) {
            fail(name, "%s", sfb_last_error(ctx));
        } else {
            const double agree = agreement(&a, &b, &both);
            check(a.proxy_level >= 1 && a.proxy_level <= 4 && b.proxy_level == 4 && e.proxy_level == 3 && pg.proxy_level == 2 && agree >= 0.995 &&
                      both > 1000,
                  name, "chosen level %d (explicit 4 and 3 reported as %d and %d, polygon-based default %d), agrees with level 4 on %.3f %% of %ld pixels",
                  a.proxy_level, b.proxy_level, e.proxy_level, pg.proxy_level, 100.0 * agree, both);
            printf("# %s: level %d chosen at 640 x 480, %.3f %% as level 4\n", name, a.proxy_level, 100.0 * agree);
            if (strcmp(all[i].label, "catmark_cube_creases1") == 0) coarse = a.proxy_level;
            if (strcmp(all[i].label, "catmark_car") == 0) fine = a.proxy_level;
        }
        sfb_analysis_free(&a); sfb_analysis_free(&b); sfb_analysis_free(&e); sfb_analysis_free(&pg);
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
    }
    if (coarse < 0 || fine < 0) skip("auto_level/coarse_finer_than_fine", "a shape not found");
    else check(fine == 1 && coarse > fine, "auto_level/coarse_finer_than_fine", "6-face cube: level %d, catmark_car: level %d", coarse, fine);
}

/* The core's per-pixel loops run on the backend's threads (sfb__parallel: the seeding, the
 * Newton updates, the neighbour scans, the colours): a picture must not depend on how many
 * there are. simd with 1 thread (every loop on the caller) against 2 (the pool), bit for bit:
 * colours, classes, values, hits and the pixel counts, on a Catmull-Clark and a Loop shape in
 * three modes, at 640 x 480 (every loop past the size that goes to the threads). */
static void test_threads(const shape *shapes, int count) {
    static const int modes[3] = { SFB_ANALYZE_REFLECTION, SFB_ANALYZE_ZEBRA, SFB_ANALYZE_CURVATURE };
    sfb_context *cx[2] = { NULL, NULL };
    int t, i, mode;
    for (t = 0; t < 2; ++t) {
        sfb_context_config cc = sfb_context_config_init();
        sfb_backend_kind kind = SFB_BACKEND_SIMD;
        cc.backends = &kind; cc.backend_count = 1; cc.ignore_environment = 1;
        cc.threads = t + 1;
        if (sfb_context_create(&cc, &cx[t]) != SFB_SUCCESS) cx[t] = NULL;
    }
    for (i = 0; i < count; ++i)
        for (mode = 0; mode < 3; ++mode) {
            char name[160];
            sfb_mesh *m[2] = { NULL, NULL };
            sfb_surface *sf[2] = { NULL, NULL };
            sfb_analysis a[2];
            sfb_analyze_config c = sfb_analyze_config_init(modes[mode]);
            int ok = 1;
            snprintf(name, sizeof name, "threads_1_vs_2_%s_%s", shapes[i].label, mode == 0 ? "reflection" : mode == 1 ? "zebra" : "mean_curvature");
            if (!cx[0] || !cx[1]) { skip(name, "the simd backend is not available"); continue; }
            memset(a, 0, sizeof a);
            c.width = 640; c.height = 480; c.level = 1;
            c.curvature = SFB_CURVATURE_MEAN;
            for (t = 0; t < 2; ++t) {
                m[t] = load_shape(cx[t], shapes[i].path);
                sf[t] = m[t] ? patch_surface(cx[t], m[t], shapes[i].scheme) : NULL;
                if (!sf[t] || sfb_surface_analyze(sf[t], &c, &a[t]) != SFB_SUCCESS) ok = 0;
            }
            if (!ok) {
                fail(name, "%s / %s", sfb_last_error(cx[0]), sfb_last_error(cx[1]));
            } else {
                const size_t n = (size_t)a[0].width * a[0].height;
                const int same_counts = a[0].covered_pixels == a[1].covered_pixels && a[0].dropped_pixels == a[1].dropped_pixels &&
                                        a[0].fallback_pixels == a[1].fallback_pixels && a[0].grown_pixels == a[1].grown_pixels;
                const int same_rgba = memcmp(a[0].rgba, a[1].rgba, 4 * n) == 0, same_cls = memcmp(a[0].classes, a[1].classes, n) == 0;
                const int same_val = memcmp(a[0].values, a[1].values, n * sizeof(float)) == 0;
                const int same_hits = memcmp(a[0].hits, a[1].hits, n * sizeof(sfb_location)) == 0;
                check(a[0].covered_pixels > 20000 && same_counts && same_rgba && same_cls && same_val && same_hits, name,
                      "%d pixels covered (1 thread) / %d (2), dropped %d / %d; identical: colours %d, classes %d, values %d, hits %d",
                      a[0].covered_pixels, a[1].covered_pixels, a[0].dropped_pixels, a[1].dropped_pixels, same_rgba, same_cls, same_val,
                      same_hits);
            }
            for (t = 0; t < 2; ++t) {
                sfb_analysis_free(&a[t]);
                sfb_surface_destroy(sf[t]);
                sfb_mesh_destroy(m[t]);
            }
        }
    for (t = 0; t < 2; ++t) sfb_context_destroy(cx[t]);
}

/* Two pictures bit for bit: colours, values, classes, hits and the counts. */
static int same_picture(const sfb_analysis *a, const sfb_analysis *b) {
    const size_t n = (size_t)a->width * a->height;
    return a->width == b->width && a->height == b->height && a->covered_pixels == b->covered_pixels &&
           a->dropped_pixels == b->dropped_pixels && a->fallback_pixels == b->fallback_pixels && a->grown_pixels == b->grown_pixels &&
           a->light_hits == b->light_hits && a->range == b->range && memcmp(a->rgba, b->rgba, 4 * n) == 0 &&
           memcmp(a->classes, b->classes, n) == 0 && memcmp(a->values, b->values, n * sizeof(float)) == 0 &&
           memcmp(a->hits, b->hits, n * sizeof(sfb_location)) == 0;
}

/* The orbit about `up` (camera_set 0): up = +y is the default orbit, bit for bit; a model
 * turned z-up ((x, y, z) -> (x, -z, y), exact in float) and seen with up = +z gives the y-up
 * model's default picture (classes of >= 99.5 % of the pixels, the camera equal up to the
 * rotation's rounding); a non-finite up is refused. */
static sfb_mesh *load_turned_z_up(sfb_context *ctx, const char *path) {
    size_t n, i = 0, o = 0;
    char *t = slurp(path, &n), *out;
    sfb_mesh *m = NULL;
    if (!t) return NULL;
    out = (char *)malloc(2 * n + 64);
    while (i < n) {
        size_t e = i;
        while (e < n && t[e] != '\n') ++e;
        if (e - i > 2 && t[i] == 'v' && t[i + 1] == ' ') {
            char *q = t + i + 2;
            double x = strtod(q, &q), y = strtod(q, &q), z = strtod(q, &q);
            o += (size_t)sprintf(out + o, "v %.9g %.9g %.9g", x, z == 0.0 ? 0.0 : -z, y);
        } else {
            memcpy(out + o, t + i, e - i);
            o += e - i;
        }
        if (e < n) out[o++] = '\n';
        i = e + 1;
    }
    if (sfb_mesh_read_obj(ctx, out, o, &m) != SFB_SUCCESS) m = NULL;
    free(out);
    free(t);
    return m;
}

static void test_orbit_up(const shape *sh) {
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *m = NULL, *mz = NULL;
    sfb_surface *s = NULL, *sz = NULL;
    sfb_analysis a, b, z;
    sfb_analyze_config c = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
    sfb_result ra, rb, rz, rn;
    long k, np, same = 0, cov = 0;
    cc.ignore_environment = 1;
    memset(&a, 0, sizeof a); memset(&b, 0, sizeof b); memset(&z, 0, sizeof z);
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) { fail("orbit_up", "no context"); return; }
    m = load_shape(ctx, sh->path);
    mz = load_turned_z_up(ctx, sh->path);
    s = m ? patch_surface(ctx, m, sh->scheme) : NULL;
    sz = mz ? patch_surface(ctx, mz, sh->scheme) : NULL;
    if (!s || !sz) { fail("orbit_up", "%s not loaded", sh->path); goto done; }
    c.width = 240; c.height = 180; c.view_set = 1; c.yaw = 35.0f; c.pitch = 20.0f;
    ra = sfb_surface_analyze(s, &c, &a);
    c.up[1] = 1.0f;
    rb = sfb_surface_analyze(s, &c, &b);
    check(ra == SFB_SUCCESS && rb == SFB_SUCCESS && a.covered_pixels > 1000 && same_picture(&a, &b), "orbit_up/plus_y_is_the_default",
          "%s / %s, %d / %d pixels", sfb_result_string(ra), sfb_result_string(rb), a.covered_pixels, b.covered_pixels);
    c.up[1] = 0.0f; c.up[2] = 1.0f;
    rz = sfb_surface_analyze(sz, &c, &z);
    if (ra == SFB_SUCCESS && rz == SFB_SUCCESS) {
        np = (long)a.width * a.height;
        for (k = 0; k < np; ++k)
            if (a.classes[k] || z.classes[k]) { ++cov; same += a.classes[k] == z.classes[k]; }
    }
    check(rz == SFB_SUCCESS && same >= 0.995 * cov && cov > 1000 && labs((long)z.covered_pixels - a.covered_pixels) <= a.covered_pixels / 200,
          "orbit_up/z_up_model_as_y_up", "%s: %.3f %% of %ld pixels in the same class, covered %d against %d", sfb_result_string(rz),
          100.0 * same / (cov ? cov : 1), cov, z.covered_pixels, a.covered_pixels);
    printf("# orbit_up: the z-up model seen about up = z: %.3f %% of %ld pixels in the y-up picture's class\n", 100.0 * same / (cov ? cov : 1),
           cov);
    sfb_analysis_free(&z);
    c.up[2] = NAN;
    rn = sfb_surface_analyze(s, &c, &z);
    check(rn == SFB_INVALID_VALUE && z.rgba == NULL && strstr(sfb_last_error(ctx), "up direction") != NULL, "orbit_up/not_finite", "%s: %s",
          sfb_result_string(rn), sfb_last_error(ctx));
done:
    sfb_analysis_free(&a); sfb_analysis_free(&b); sfb_analysis_free(&z);
    sfb_surface_destroy(s); sfb_surface_destroy(sz);
    sfb_mesh_destroy(m); sfb_mesh_destroy(mz);
    sfb_context_destroy(ctx);
}

/* The workspace's kept proxy and adjacency (they belong to a surface at a level, whatever the
 * view): one workspace through views A and B of two surfaces, the polygon-based path between,
 * a call cancelled as the proxy is done, and a surface destroyed and another made in its place;
 * each picture bit for bit the one without a workspace. */
static int cancel_at(float done, const char *stage, void *user) {
    const float at = *(const float *)user;
    return strcmp(stage, "analyze") == 0 && at > 0.0f && done >= at;
}
static void test_workspace_proxy(const shape *shapes) {
    static const struct { int surf, view, polygon, level; float cancel; } runs[9] = {
        { 0, 0, 0, 2, 0.0f }, { 0, 1, 0, 2, 0.0f }, { 0, 0, 1, 2, 0.0f }, { 0, 1, 0, 2, 0.0f }, { 1, 1, 0, 2, 0.0f },
        { 0, 1, 0, 2, 0.0f }, { 0, 0, 0, 1, 0.0f }, { 0, 1, 0, 1, 0.2f }, { 0, 1, 0, 1, 0.0f } };
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_analysis_workspace *ws = NULL;
    sfb_mesh *m[3] = { NULL, NULL, NULL };
    sfb_surface *sf[2] = { NULL, NULL };
    float cancel = 0.0f;
    int i;
    cc.ignore_environment = 1;
    cc.progress.func = cancel_at;
    cc.progress.user = &cancel;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS || sfb_analysis_workspace_create(ctx, &ws) != SFB_SUCCESS) {
        fail("workspace_proxy/create", "no context or workspace");
        sfb_context_destroy(ctx);
        return;
    }
    for (i = 0; i < 3; ++i) m[i] = load_shape(ctx, shapes[i].path);
    for (i = 0; i < 2; ++i) sf[i] = m[i] ? patch_surface(ctx, m[i], shapes[i].scheme) : NULL;
    for (i = 0; i <= 9; ++i) {
        char name[128];
        const int k = i < 9 ? i : 4, sh = i < 9 ? runs[k].surf : 2;
        sfb_analyze_config c = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
        sfb_analysis a, b;
        sfb_result ra, rb;
        if (i == 9) {
            /* surface 1 destroyed and another (shape 2's) made, perhaps at its address */
            sfb_surface_destroy(sf[1]);
            sf[1] = m[2] ? patch_surface(ctx, m[2], shapes[2].scheme) : NULL;
        }
        snprintf(name, sizeof name, "workspace_proxy/run_%d_%s_view_%d_level_%d%s%s", i, shapes[sh].label, runs[k].view, runs[k].level,
                 runs[k].polygon ? "_polygon" : "", runs[k].cancel > 0.0f ? "_cancelled" : "");
        if (!sf[runs[k].surf]) { skip(name, "shape not found"); continue; }
        memset(&a, 0, sizeof a); memset(&b, 0, sizeof b);
        c.width = 240; c.height = 180; c.level = runs[k].level; c.polygon_based = runs[k].polygon;
        c.view_set = 1; c.yaw = runs[k].view ? 130.0f : 30.0f; c.pitch = runs[k].view ? -15.0f : 25.0f;
        c.workspace = ws;
        if (runs[k].cancel > 0.0f) {
            cancel = runs[k].cancel;
            rb = sfb_surface_analyze(sf[runs[k].surf], &c, &b);
            cancel = 0.0f;
            check(rb == SFB_CANCELLED && b.rgba == NULL, name, "%s", sfb_result_string(rb));
            continue;
        }
        rb = sfb_surface_analyze(sf[runs[k].surf], &c, &b);
        c.workspace = NULL;
        ra = sfb_surface_analyze(sf[runs[k].surf], &c, &a);
        check(ra == SFB_SUCCESS && rb == SFB_SUCCESS && a.covered_pixels > 1000 && same_picture(&a, &b), name,
              "%s / %s: %d / %d pixels covered, the same: %d", sfb_result_string(ra), sfb_result_string(rb), a.covered_pixels,
              b.covered_pixels, ra == SFB_SUCCESS && rb == SFB_SUCCESS && same_picture(&a, &b));
        sfb_analysis_free(&a); sfb_analysis_free(&b);
    }
    sfb_analysis_workspace_destroy(ws);
    for (i = 0; i < 2; ++i) sfb_surface_destroy(sf[i]);
    for (i = 0; i < 3; ++i) sfb_mesh_destroy(m[i]);
    sfb_context_destroy(ctx);
}

/* sfb_analysis_workspace: one workspace through a sequence of analyses that grow and shrink it
 * (sizes, modes, schemes, the polygon-based path), each bit for bit the picture without it,
 * twice in a row (the kept mark tags of the first must not leak into the second), and the
 * first one again at the end;
 * a call cancelled halfway leaves it usable; a workspace of another context is refused. */
static int cancel_when_asked(float done, const char *stage, void *user) {
    return strcmp(stage, "analyze") == 0 && *(int *)user && done > 0.5f;
}

static void test_workspace(const shape *shapes) {
    static const struct { int shape, mode, w, h, level, polygon; } runs[6] = {
        { 1, SFB_ANALYZE_REFLECTION, 640, 480, 1, 0 }, { 2, SFB_ANALYZE_CURVATURE, 200, 150, 2, 0 }, { 0, SFB_ANALYZE_ZEBRA, 800, 600, 1, 0 },
        { 1, SFB_ANALYZE_REFLECTION, 320, 240, 2, 1 }, { 3, SFB_ANALYZE_ISOPHOTE, 300, 300, 2, 0 }, { 1, SFB_ANALYZE_REFLECTION, 640, 480, 1, 0 }};
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL, *other = NULL;
    sfb_analysis_workspace *ws = NULL, *foreign = NULL;
    sfb_mesh *m[4] = { NULL, NULL, NULL, NULL };
    sfb_surface *sf[4] = { NULL, NULL, NULL, NULL };
    int cancel = 0, i;
    size_t held_max = 0;
    cc.ignore_environment = 1;
    cc.progress.func = cancel_when_asked;
    cc.progress.user = &cancel;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS || sfb_analysis_workspace_create(ctx, &ws) != SFB_SUCCESS) {
        fail("workspace/create", "no context or workspace");
        sfb_context_destroy(ctx);
        return;
    }
    for (i = 0; i < 4; ++i) {
        m[i] = load_shape(ctx, shapes[i].path);
        sf[i] = m[i] ? patch_surface(ctx, m[i], shapes[i].scheme) : NULL;
    }
    for (i = 0; i < 6; ++i) {
        char name[128];
        sfb_analyze_config c = sfb_analyze_config_init(runs[i].mode);
        sfb_analysis a, b, b2;
        sfb_result ra, rb, rb2;
        snprintf(name, sizeof name, "workspace/run_%d_%s_%dx%d%s", i, shapes[runs[i].shape].label, runs[i].w, runs[i].h,
                 runs[i].polygon ? "_polygon" : "");
        if (!sf[runs[i].shape]) { skip(name, "shape not found"); continue; }
        memset(&a, 0, sizeof a); memset(&b, 0, sizeof b); memset(&b2, 0, sizeof b2);
        c.width = runs[i].w; c.height = runs[i].h; c.level = runs[i].level; c.polygon_based = runs[i].polygon;
        c.curvature = SFB_CURVATURE_MEAN;
        ra = sfb_surface_analyze(sf[runs[i].shape], &c, &a);
        c.workspace = ws;
        rb = sfb_surface_analyze(sf[runs[i].shape], &c, &b);
        rb2 = sfb_surface_analyze(sf[runs[i].shape], &c, &b2); /* at once again: everything kept is this picture's own */
        if (sfb_analysis_workspace_bytes(ws) > held_max) held_max = sfb_analysis_workspace_bytes(ws);
        check(ra == SFB_SUCCESS && rb == SFB_SUCCESS && rb2 == SFB_SUCCESS && a.covered_pixels > 1000 && same_picture(&a, &b) &&
                  same_picture(&a, &b2),
              name, "%s / %s / %s: %d / %d / %d pixels covered, the same: %d %d (workspace %zu bytes)", sfb_result_string(ra),
              sfb_result_string(rb), sfb_result_string(rb2), a.covered_pixels, b.covered_pixels, b2.covered_pixels,
              rb == SFB_SUCCESS && same_picture(&a, &b), rb2 == SFB_SUCCESS && same_picture(&a, &b2), sfb_analysis_workspace_bytes(ws));
        sfb_analysis_free(&a); sfb_analysis_free(&b); sfb_analysis_free(&b2);
        if (i == 2) {
            /* cancelled halfway with the workspace, then the same picture again */
            sfb_analysis x;
            sfb_result rx;
            memset(&x, 0, sizeof x);
            cancel = 1;
            rx = sfb_surface_analyze(sf[runs[i].shape], &c, &x);
            cancel = 0;
            check(rx == SFB_CANCELLED && x.rgba == NULL, "workspace/cancelled_call", "%s", sfb_result_string(rx));
        }
    }
    /* the buffers stay at the largest analysis (800 x 600: ~100 bytes per pixel at least) */
    check(held_max >= (size_t)800 * 600 * 100 && sfb_analysis_workspace_bytes(ws) == held_max, "workspace/keeps_the_largest",
          "largest %zu bytes, now %zu", held_max, sfb_analysis_workspace_bytes(ws));
    if (sfb_context_create(&cc, &other) == SFB_SUCCESS && sfb_analysis_workspace_create(other, &foreign) == SFB_SUCCESS && sf[1]) {
        sfb_analyze_config c = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
        sfb_analysis a;
        sfb_result r;
        c.workspace = foreign;
        r = sfb_surface_analyze(sf[1], &c, &a);
        check(r == SFB_INVALID_ARGS && a.rgba == NULL && strstr(sfb_last_error(ctx), "another context") != NULL, "workspace/of_another_context",
              "%s: %s", sfb_result_string(r), sfb_last_error(ctx));
        sfb_analysis_free(&a);
    } else {
        fail("workspace/of_another_context", "no second context");
    }
    sfb_analysis_workspace_destroy(foreign);
    sfb_analysis_workspace_destroy(NULL);
    sfb_context_destroy(other);
    sfb_analysis_workspace_destroy(ws);
    for (i = 0; i < 4; ++i) { sfb_surface_destroy(sf[i]); sfb_mesh_destroy(m[i]); }
    sfb_context_destroy(ctx);
}

/* ---- backends against ref ---- */
/* Modes: 0 reflection, 1 mean and 2 Gaussian curvature (exact per pixel), 3 polygon-based
 * reflection (the raster's own interpolated data, so the raster kernels compared directly). */
static void test_backends(const shape *shapes, int count) {
    int b, i, mode;
    for (b = 1; b < g_nbe; ++b) {
        const backend *be = &g_be[b];
        for (i = 0; i < count; ++i)
            for (mode = 0; mode < 4; ++mode) {
                char name[160];
                sfb_mesh *mr, *mb;
                sfb_surface *sr, *sb;
                sfb_analyze_config c = sfb_analyze_config_init(mode == 1 || mode == 2 ? SFB_ANALYZE_CURVATURE : SFB_ANALYZE_REFLECTION);
                sfb_analysis ar, ab;
                const int cpu_before = *cpu_rasters();
                snprintf(name, sizeof name, "backend_%s_%s_%s", be->name, shapes[i].label,
                         mode == 3 ? "polygon_reflection" : mode == 2 ? "gaussian_curvature" : mode ? "mean_curvature" : "reflection");
                c.polygon_based = mode == 3;
                if (!be->available) { backend_missing(be, name); continue; }
                mr = load_shape(g_be[0].ctx, shapes[i].path);
                mb = load_shape(be->ctx, shapes[i].path);
                if (!mr || !mb) { skip(name, "shape not found"); sfb_mesh_destroy(mr); sfb_mesh_destroy(mb); continue; }
                sr = patch_surface(g_be[0].ctx, mr, shapes[i].scheme);
                sb = patch_surface(be->ctx, mb, shapes[i].scheme);
                c.width = 200; c.height = 150; c.level = 2;
                /* mean: values within 1e-3 of themselves; Gaussian: of the colour range, since
                 * LN - M^2 cancels where the surface is near-parabolic (a rounded edge) and the
                 * float kernels' second derivatives then leave K ~1e-3 of the range, not of itself */
                c.curvature = mode == 2 ? SFB_CURVATURE_GAUSSIAN : SFB_CURVATURE_MEAN;
                memset(&ar, 0, sizeof ar); memset(&ab, 0, sizeof ab);
                /* the backend runs with ref's colour range (the automatic one is a percentile over the
                 * covered pixels, which may differ by a grazing pixel or two at the silhouette) */
                if (!sr || !sb || sfb_surface_analyze(sr, &c, &ar) != SFB_SUCCESS ||
                    (c.curvature_range = mode == 1 || mode == 2 ? ar.range : 0.0f, sfb_surface_analyze(sb, &c, &ab)) != SFB_SUCCESS) {
                    fail(name, "%s / %s", sfb_last_error(g_be[0].ctx), sfb_last_error(be->ctx));
                } else {
                    long k, np = (long)ar.width * ar.height, same = 0, cov = 0, bad = 0, both = 0;
                    for (k = 0; k < np; ++k) {
                        if (ar.classes[k] || ab.classes[k]) { ++cov; same += ar.classes[k] == ab.classes[k]; }
                        if ((mode == 1 || mode == 2) && ar.classes[k] && ab.classes[k] && isfinite(ar.values[k])) {
                            double x = ar.values[k], y = ab.values[k], fl = fabs(ar.range) * (mode == 2 ? 1.0 : 1e-3);
                            double sc = fabs(x) > fl ? fabs(x) : fl;
                            ++both;
                            if (!(fabs(x - y) <= 1e-3 * sc)) ++bad;
                        }
                    }
                    /* the proxy's own coverage: GL's raster differs only on pixel centres on an edge,
                     * simd's is ref's (in bands of rows) and must match it exactly */
                    const long dp = labs((long)ab.proxy_pixels - (long)ar.proxy_pixels),
                               dp_ok = be->kind == SFB_BACKEND_SIMD ? 0 : ar.proxy_pixels / 200;
                    const int own = *cpu_rasters() == cpu_before; /* every backend has its raster kernel */
                    if (mode == 1 || mode == 2)
                        check(same >= 0.995 * cov && bad <= 0.005 * both && dp <= dp_ok && own, name,
                              "%.3f %% identical classes, %ld of %ld curvatures off by > 1e-3 relative, proxy pixels %d vs ref %d%s",
                              100.0 * same / (cov ? cov : 1), bad, both, ab.proxy_pixels, ar.proxy_pixels, own ? "" : ", rasterised on the CPU");
                    else
                        check(same >= 0.995 * cov && dp <= dp_ok && own, name,
                              "%.3f %% identical classes of %ld pixels, proxy pixels %d vs ref %d%s", 100.0 * same / (cov ? cov : 1), cov,
                              ab.proxy_pixels, ar.proxy_pixels, own ? "" : ", rasterised on the CPU");
                }
                sfb_analysis_free(&ar); sfb_analysis_free(&ab);
                sfb_surface_destroy(sr); sfb_surface_destroy(sb);
                sfb_mesh_destroy(mr); sfb_mesh_destroy(mb);
            }
    }
}

/* ---- bad configurations, cancellation, budget ---- */
static int zeroed(const sfb_analysis *a) {
    sfb_analysis z;
    memset(&z, 0, sizeof z);
    return memcmp(a, &z, sizeof z) == 0;
}
static void refused(sfb_surface *s, sfb_context *ctx, const sfb_analyze_config *c, sfb_result want, const char *name) {
    sfb_analysis a;
    sfb_result r;
    memset(&a, 0x5a, sizeof a);
    r = sfb_surface_analyze(s, c, &a);
    check(r == want && zeroed(&a) && strlen(sfb_last_error(ctx)) > 10, name, "got %s (%s), output %s", sfb_result_string(r), sfb_last_error(ctx),
          zeroed(&a) ? "zeroed" : "not zeroed");
    if (r == SFB_SUCCESS) sfb_analysis_free(&a);
}

static int cancel_at_half(float done, const char *stage, void *user) {
    if (strcmp(stage, "analyze") != 0) return 0;
    ++*(int *)user;
    return done > 0.5f;
}

static void test_bad(sfb_context *ctx) {
    sfb_mesh *m = grid_mesh(ctx, 10, 0.0, 0);
    sfb_surface *s = m ? patch_surface(ctx, m, SFB_SCHEME_CATMARK) : NULL;
    sfb_analyze_config c, base = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
    static const unsigned char texel[4] = { 255, 255, 255, 255 };
    if (!s) { fail("bad_config", "no surface"); sfb_mesh_destroy(m); return; }
    top_view(&base, 3.0, 64);
    c = base; c.width = 0; refused(s, ctx, &c, SFB_INVALID_ARGS, "bad_zero_size_image");
    c = base; c.height = -3; refused(s, ctx, &c, SFB_INVALID_ARGS, "bad_negative_size");
    c = base; c.width = SFB_ANALYZE_MAX_SIZE + 1; refused(s, ctx, &c, SFB_LIMIT_EXCEEDED, "bad_size_over_limit");
    c = base; c.level = SFB_ANALYZE_MAX_LEVEL + 1; refused(s, ctx, &c, SFB_LIMIT_EXCEEDED, "bad_level_over_limit");
    c = base; c.mode = 99; refused(s, ctx, &c, SFB_INVALID_ARGS, "bad_mode");
    c = base; c.eye[1] = NAN; refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_nan_eye");
    c = base; c.target[2] = c.eye[2]; c.target[0] = c.eye[0]; c.target[1] = c.eye[1]; refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_eye_equals_target");
    c = base; c.near_plane = -1.0f; c.eye[2] = 0.0f; c.target[2] = -1.0f; refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_negative_near_plane_inside_bbox");
    c = base; c.fov = NAN; refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_nan_fov");
    c = base; top_light(&c); c.light_normal[0] = c.light_normal[1] = c.light_normal[2] = 0.0f; refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_zero_light_normal");
    c = base; top_light(&c); c.light_axis[0] = 0.0f; c.light_axis[2] = 1.0f; refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_light_axis_along_normal");
    /* a flat sheet seen from above reflects every ray straight up: a light plane standing
     * upright is parallel to all of them */
    c = base; top_light(&c);
    c.light_normal[0] = 1.0f; c.light_normal[2] = 0.0f; c.light_axis[0] = 0.0f; c.light_axis[1] = 1.0f;
    refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_light_plane_parallel_to_every_ray");
    c = base; c.light_pattern = SFB_LIGHT_IMAGE; c.light_rgba = texel; c.light_width = 0; c.light_height = 1;
    refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_zero_size_light_texture");
    c = base; c.light_pattern = SFB_LIGHT_IMAGE; c.light_rgba = NULL; c.light_width = 1; c.light_height = 1;
    refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_light_texture_without_texels");
    c = base; c.stripes = NAN; refused(s, ctx, &c, SFB_INVALID_VALUE, "bad_nan_stripes");
    c = base; c.polygon_based = 1; c.mode = SFB_ANALYZE_CURVATURE; refused(s, ctx, &c, SFB_INVALID_ARGS, "bad_polygon_based_curvature");
    {
        sfb_analysis a;
        sfb_result r = sfb_surface_analyze(s, &base, NULL);
        check(r == SFB_INVALID_ARGS, "bad_null_output", "got %s", sfb_result_string(r));
        memset(&a, 0, sizeof a);
        c = base;
        top_light(&c);
        r = sfb_surface_analyze(s, &c, &a);
        check(r == SFB_SUCCESS && a.covered_pixels == 64 * 64, "flat_sheet_covers_the_picture", "%s: %d of %d pixels", sfb_result_string(r),
              a.covered_pixels, 64 * 64);
        sfb_analysis_free(&a);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    {
        /* cancellation from the progress callback, and the memory budget checked first */
        sfb_context_config cc = sfb_context_config_init();
        sfb_context *c2 = NULL;
        int calls = 0;
        cc.progress.func = cancel_at_half;
        cc.progress.user = &calls;
        cc.ignore_environment = 1;
        if (sfb_context_create(&cc, &c2) == SFB_SUCCESS) {
            sfb_mesh *m2 = grid_mesh(c2, 10, 0.05, 0);
            sfb_surface *s2 = m2 ? patch_surface(c2, m2, SFB_SCHEME_CATMARK) : NULL;
            sfb_analysis a;
            sfb_result r;
            memset(&a, 0x5a, sizeof a);
            calls = 0;
            r = s2 ? sfb_surface_analyze(s2, &base, &a) : SFB_OUT_OF_MEMORY;
            check(r == SFB_CANCELLED && zeroed(&a) && calls > 1, "cancelled_by_progress", "got %s after %d reports", sfb_result_string(r), calls);
            sfb_surface_destroy(s2);
            sfb_mesh_destroy(m2);
            sfb_context_destroy(c2);
        } else fail("cancelled_by_progress", "no context");
        cc = sfb_context_config_init();
        cc.ignore_environment = 1;
        cc.memory_budget = 8u << 20;
        if (sfb_context_create(&cc, &c2) == SFB_SUCCESS) {
            sfb_mesh *m2 = grid_mesh(c2, 10, 0.05, 0);
            sfb_surface *s2 = m2 ? patch_surface(c2, m2, SFB_SCHEME_CATMARK) : NULL;
            sfb_analyze_config big = base;
            big.width = big.height = 4096;
            if (s2) refused(s2, c2, &big, SFB_LIMIT_EXCEEDED, "memory_budget_checked_first");
            else fail("memory_budget_checked_first", "no surface");
            sfb_surface_destroy(s2);
            sfb_mesh_destroy(m2);
            sfb_context_destroy(c2);
        } else fail("memory_budget_checked_first", "no context");
    }
}

int main(int argc, char **argv) {
    sfb_context *ctx = NULL;
    sfb_context_config cc = sfb_context_config_init();
    char p[4][1024];
    shape shapes[4];
    if (argc > 1) g_shapes = argv[1];
    snprintf(p[0], sizeof p[0], "examples/data/creased_box.obj");
    snprintf(p[1], sizeof p[1], "%s/catmark_cube_creases1.obj", g_shapes);
    snprintf(p[2], sizeof p[2], "%s/loop_cube_creases1.obj", g_shapes);
    snprintf(p[3], sizeof p[3], "examples/data/manifold_features.obj");
    shapes[0].label = "creased_box"; shapes[0].path = p[0]; shapes[0].scheme = SFB_SCHEME_CATMARK;
    shapes[1].label = "catmark_cube_creases1"; shapes[1].path = p[1]; shapes[1].scheme = SFB_SCHEME_CATMARK;
    shapes[2].label = "loop_cube_creases1"; shapes[2].path = p[2]; shapes[2].scheme = SFB_SCHEME_LOOP;
    shapes[3].label = "manifold_features"; shapes[3].path = p[3]; shapes[3].scheme = SFB_SCHEME_MANIFOLD_BLEND;
    cc.ignore_environment = 1;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) { printf("no context\n"); return 1; }
    test_analytic(ctx, 0);
    test_analytic(ctx, 1);
    test_levels(ctx, shapes, 4);
    test_large(ctx, &shapes[0]);
    test_auto_level(ctx, shapes, 4);
    test_bad(ctx);
    sfb_context_destroy(ctx);
    test_threads(shapes, 3);
    test_workspace(shapes);
    test_workspace_proxy(shapes);
    test_orbit_up(&shapes[1]);
    {
        sfb_context_config bc = sfb_context_config_init();
        bc.logger.func = cpu_raster_logger;
        if (!probe_backends_with(&bc, NULL)) return 1;
    }
    test_backends(shapes, 3);
    return finish_tests();
}
