/* analysis_kernels: seed 003's two analysis kernels of the backend vtable, `shade` and `raster`,
 * of every backend against ref's (sfb__ref_shade, sfb__ref_raster), called through the bound
 * vtables directly on random jobs. The program compiles the library in.
 *
 *   analysis_kernels [--seed S]
 *
 * Targets: simd once per instruction set the CPU and build have (simd-ISA/tT, threads 1 and 2;
 * only the one SURFBLEND_SIMD_ISA names when it is set), gl, osmesa. Checks, per target T:
 *   T/shade/MODE/CAMERA  20000 random pixels (positions in a box, normals of random lengths and
 *                        directions, a third of them facing away from the eye; 1 in 16 with a
 *                        normal in the light plane, so that the plane is missed) for every mode
 *                        but CURVATURE with its second derivatives (REFLECTION, HIGHLIGHT,
 *                        ZEBRA, ISOPHOTE, NORMALS, SHADED) and CURVATURE (mean and Gaussian),
 *                        perspective and orthographic: simd's values are ref's bit for bit (both
 *                        NaN counts as equal); gl's and osmesa's (float) within 1e-4 of 1 +
 *                        |ref| (stripe coordinates, cosines), NaN exactly where ref's is, at
 *                        most 1 pixel in 1000 off (a ray that grazes the plane's edge)
 *   T/raster/CAMERA      2000 random triangles (some tiny, some off the picture; for simd a fifth
 *                        overlapping at one depth) in a 97 x 61 picture: simd's face, (u,v) and
 *                        depth buffers are ref's bit for bit; gl's and osmesa's agree on at
 *                        least 99 % of the covered pixels (GL's tie rule on edges, float), their
 *                        depths within 1e-5 relative where the faces agree (each target runs
 *                        with the hint that the second half is likely hidden: nfront, zmax)
 *   ref/raster/hint/CAMERA  ref's raster with that hint is ref's without it, bit for bit (half of
 *                        the second half pushed behind, so that the hint skips some)
 * A backend that is unavailable prints one SKIP line (a FAIL when SFB_REQUIRE_BACKENDS names it).
 *
 * Build: cc -std=c99 -I. tests/analysis_kernels.c -o build/analysis_kernels -lm -lpthread -ldl
 * (-DANALYSIS_KERNELS_SIMD_ONLY: the simd backend alone, as tests/neon.sh builds it for AArch64). */
#define _POSIX_C_SOURCE 200809L
#define SURFBLEND_EXPOSE_INTERNALS
#define SURFBLEND_IMPLEMENTATION
#ifdef ANALYSIS_KERNELS_SIMD_ONLY /* tests/neon.sh: the simd backend alone, for AArch64 under qemu */
#define SURFBLEND_SIMD
#else
#define SURFBLEND_ALL_BACKENDS
#endif
#include "surfblend.h"

#include "harness.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double rnd(rng *g) { return rng_unit(g); }
static double rnd_in(rng *g, double lo, double hi) { return rng_range(g, lo, hi); }

enum { NPIX = 20000, NTRI = 2000, RW = 97, RH = 61 };

typedef struct pixels {
    float p[3 * NPIX], n[3 * NPIX], du[3 * NPIX], dv[3 * NPIX], duu[3 * NPIX], duv[3 * NPIX], dvv[3 * NPIX];
} pixels;

static void pixels_random(pixels *px, rng *g, const double *lm) {
    int i, c;
    for (i = 0; i < NPIX; ++i) {
        double n[3], len = 0.0;
        for (c = 0; c < 3; ++c) {
            px->p[3 * i + c] = (float)rnd_in(g, -1.0, 1.0);
            n[c] = rnd_in(g, -1.0, 1.0);
            px->du[3 * i + c] = (float)rnd_in(g, -2.0, 2.0);
            px->dv[3 * i + c] = (float)rnd_in(g, -2.0, 2.0);
            px->duu[3 * i + c] = (float)rnd_in(g, -3.0, 3.0);
            px->duv[3 * i + c] = (float)rnd_in(g, -3.0, 3.0);
            px->dvv[3 * i + c] = (float)rnd_in(g, -3.0, 3.0);
        }
        if (i % 16 == 5) { /* a normal in the light plane: HIGHLIGHT misses it */
            const double d = n[0] * lm[0] + n[1] * lm[1] + n[2] * lm[2];
            for (c = 0; c < 3; ++c) n[c] -= d * lm[c];
        }
        for (c = 0; c < 3; ++c) len += n[c] * n[c];
        len = sqrt(len) * rnd_in(g, 0.5, 2.0);
        for (c = 0; c < 3; ++c) px->n[3 * i + c] = (float)(len > 0.0 ? n[c] / len : 0.0);
        if (i % 16 == 5) for (c = 0; c < 3; ++c) px->n[3 * i + c] = (float)(n[c] / sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] + 1e-300));
    }
}

static void job_random(sfb__shade_job *j, rng *g, int mode, int curvature, int ortho) {
    static const double lm[3] = {0.0, 0.0, 1.0};
    int c;
    memset(j, 0, sizeof *j);
    j->mode = mode;
    j->curvature = curvature;
    j->ortho = ortho;
    for (c = 0; c < 3; ++c) {
        j->eye[c] = rnd_in(g, 3.0, 5.0);
        j->lc[c] = c == 2 ? 3.0 : rnd_in(g, -0.5, 0.5);
        j->lm[c] = lm[c];
    }
    j->fwd[0] = -0.6; j->fwd[1] = -0.48; j->fwd[2] = -0.64;
    j->lu[0] = 1.0; j->lv[1] = 1.0;
    j->lsize[0] = 40.0; j->lsize[1] = 30.0; /* most reflected rays that rise meet it */
    j->periods[0] = 9.0; j->periods[1] = 7.0;
    j->dir[0] = 0.48; j->dir[1] = 0.6; j->dir[2] = 0.64;
}

typedef struct target {
    char name[96];
    const sfb__backend_vtable *vt;
    void *state;
    int exact;
} target;

static int both_nan_or_equal(float a, float b) { return (isnan(a) && isnan(b)) || a == b; }

static void check_shade(const target *t, const pixels *px) {
    static const int modes[8] = {SFB_ANALYZE_REFLECTION, SFB_ANALYZE_HIGHLIGHT, SFB_ANALYZE_ZEBRA, SFB_ANALYZE_ISOPHOTE,
                                 SFB_ANALYZE_NORMALS,    SFB_ANALYZE_SHADED,    SFB_ANALYZE_CURVATURE, SFB_ANALYZE_CURVATURE};
    static const char *const names[8] = {"reflection", "highlight", "zebra", "isophote", "normals", "shaded", "mean_curvature", "gaussian_curvature"};
    static float rv[NPIX], rv2[NPIX], bv[NPIX], bv2[NPIX];
    int m, ortho, i;
    for (m = 0; m < 8; ++m)
        for (ortho = 0; ortho < 2; ++ortho) {
            char name[160];
            sfb__shade_job j;
            rng g = rng_for(g_seed, (unsigned long long)(100 + 2 * m + ortho));
            long off = 0, nanoff = 0, misses = 0;
            double worst = 0.0;
            sfb_result r;
            snprintf(name, sizeof name, "%s/shade/%s/%s", t->name, names[m], ortho ? "orthographic" : "perspective");
            job_random(&j, &g, modes[m], m == 7 ? SFB_CURVATURE_GAUSSIAN : SFB_CURVATURE_MEAN, ortho);
            j.position = px->p; j.normal = px->n; j.du = px->du; j.dv = px->dv; j.duu = px->duu; j.duv = px->duv; j.dvv = px->dvv;
            j.value = rv; j.value2 = rv2;
            sfb__ref_shade(NULL, &j, 0, NPIX);
            j.value = bv; j.value2 = bv2;
            for (i = 0; i < NPIX; ++i) bv[i] = bv2[i] = -12345.0f;
            r = t->vt->shade(t->state, &j, 0, NPIX);
            if (r != SFB_SUCCESS) { fail(name, "%s", sfb_result_string(r)); continue; }
            for (i = 0; i < NPIX; ++i) {
                misses += isnan(rv[i]);
                if (t->exact) {
                    off += !both_nan_or_equal(rv[i], bv[i]) || !both_nan_or_equal(rv2[i], bv2[i]);
                } else if (isnan(rv[i]) != isnan(bv[i])) {
                    ++nanoff;
                } else if (!isnan(rv[i])) {
                    const double e = fabs((double)bv[i] - rv[i]) / (1.0 + fabs((double)rv[i]));
                    if (e > worst) worst = e;
                    off += e > (m >= 6 ? 1e-3 : 1e-4);
                }
            }
            if (t->exact)
                check(off == 0 && misses < NPIX, name, "%ld of %d pixels differ from ref's bits (%ld missed by ref)", off, NPIX, misses);
            else
                check(off + nanoff <= NPIX / 1000 && misses < NPIX, name, "%ld values off, %ld NaN mismatches of %d (worst %.3g; %ld missed by ref)",
                      off, nanoff, NPIX, worst, misses);
        }
}

/* A random raster job: triangles with their own three vertices each (faces 0..99, 20 triangles
 * per face sharing none), some tiny, some off the picture; with `ties`, a fifth of them at one
 * depth, overlapping (the first one in order keeps a pixel: ref's rule, which GL's float depth
 * cannot promise, so only for the bit-exact targets). */
typedef struct rjob {
    sfb__raster_vertex vert[3 * NTRI];
    int tri[4 * NTRI];
    float depth[RW * RH], uv[2 * RW * RH];
    int face[RW * RH];
} rjob;

static void rjob_random(rjob *R, rng *g, int ortho, int ties) {
    int t, k;
    for (t = 0; t < NTRI; ++t) {
        const double cx = rnd_in(g, -10.0, RW + 10.0), cy = rnd_in(g, -10.0, RH + 10.0), s = t % 7 == 0 ? 0.3 : rnd_in(g, 1.0, 12.0);
        const int flat = ties && t % 5 == 1;
        const double z0 = flat ? 2.0 : rnd_in(g, 1.0, 4.0);
        for (k = 0; k < 3; ++k) {
            sfb__raster_vertex *v = &R->vert[3 * t + k];
            v->x = cx + s * rnd_in(g, -1.0, 1.0);
            v->y = cy + s * rnd_in(g, -1.0, 1.0);
            v->z = flat ? z0 : z0 + rnd_in(g, -0.3, 0.3);
            v->q = ortho ? 1.0 : 1.0 / v->z;
            v->u = rnd(g);
            v->v = rnd(g) * (1.0 - v->u);
            R->tri[4 * t + k] = 3 * t + k;
        }
        R->tri[4 * t + 3] = t / 20;
    }
}

/* hint: the job says its second half is likely hidden (nfront, zmax: kernels may skip the
 * triangles there that would draw nothing), which must not change a bit */
static void rjob_run(const rjob *R, rjob *out, int ortho, const sfb__backend_vtable *vt, void *state, int hint, sfb_result *r) {
    static float zmax[RH * ((RW + 7) / 8)];
    sfb__raster_job j;
    int p;
    for (p = 0; p < RW * RH; ++p) { out->depth[p] = (float)HUGE_VAL; out->face[p] = -1; out->uv[2 * p] = out->uv[2 * p + 1] = -1.0f; }
    memset(&j, 0, sizeof j);
    j.w = RW; j.h = RH; j.ortho = ortho; j.ntri = NTRI; j.vert = R->vert; j.tri = R->tri;
    j.depth = out->depth; j.face = out->face; j.uv = out->uv;
    if (hint) { j.nfront = NTRI / 2; j.zmax = zmax; }
    *r = vt ? vt->raster(state, &j) : sfb__ref_raster(NULL, &j);
}

static void check_raster(const target *t) {
    static rjob R, A, B;
    int ortho, p;
    for (ortho = 0; ortho < 2; ++ortho) {
        char name[160];
        rng g = rng_for(g_seed, (unsigned long long)(7 + ortho));
        long cov = 0, same = 0, bits = 0, zoff = 0;
        sfb_result r0, r1;
        snprintf(name, sizeof name, "%s/raster/%s", t->name, ortho ? "orthographic" : "perspective");
        rjob_random(&R, &g, ortho, t->exact);
        rjob_run(&R, &A, ortho, NULL, NULL, 0, &r0);
        rjob_run(&R, &B, ortho, t->vt, t->state, 1, &r1);
        if (r0 != SFB_SUCCESS || r1 != SFB_SUCCESS) { fail(name, "%s / %s", sfb_result_string(r0), sfb_result_string(r1)); continue; }
        for (p = 0; p < RW * RH; ++p) {
            if (A.face[p] < 0 && B.face[p] < 0) continue;
            ++cov;
            bits += A.face[p] != B.face[p] || A.depth[p] != B.depth[p] || A.uv[2 * p] != B.uv[2 * p] || A.uv[2 * p + 1] != B.uv[2 * p + 1];
            if (A.face[p] == B.face[p]) {
                ++same;
                zoff += fabs((double)A.depth[p] - B.depth[p]) > 1e-5 * fabs((double)A.depth[p]);
            }
        }
        if (t->exact) check(bits == 0 && cov > 1000, name, "%ld of %ld covered pixels differ from ref's bits", bits, cov);
        else
            check(same >= 0.99 * cov && zoff <= cov / 1000 && cov > 1000, name, "%ld of %ld covered pixels on ref's face, %ld depths off", same,
                  cov, zoff);
    }
}

/* ref/raster/hint/CAMERA: ref's raster with the hint (the second half of the triangles likely
 * hidden, half of those pushed behind) is ref's without it, bit for bit, ties included */
static void check_raster_hint(void) {
    static rjob R, A, B;
    int ortho, p, t, k;
    for (ortho = 0; ortho < 2; ++ortho) {
        char name[160];
        rng g = rng_for(g_seed, (unsigned long long)(17 + ortho));
        long cov = 0, bits = 0;
        sfb_result r0, r1;
        snprintf(name, sizeof name, "ref/raster/hint/%s", ortho ? "orthographic" : "perspective");
        rjob_random(&R, &g, ortho, 1);
        for (t = NTRI / 2; t < NTRI; t += 2)
            for (k = 0; k < 3; ++k) {
                sfb__raster_vertex *v = &R.vert[3 * t + k];
                v->z += 2.0;
                v->q = ortho ? 1.0 : 1.0 / v->z;
            }
        rjob_run(&R, &A, ortho, NULL, NULL, 0, &r0);
        rjob_run(&R, &B, ortho, NULL, NULL, 1, &r1);
        if (r0 != SFB_SUCCESS || r1 != SFB_SUCCESS) { fail(name, "%s / %s", sfb_result_string(r0), sfb_result_string(r1)); continue; }
        for (p = 0; p < RW * RH; ++p) {
            if (A.face[p] < 0 && B.face[p] < 0) continue;
            ++cov;
            bits += A.face[p] != B.face[p] || A.depth[p] != B.depth[p] || A.uv[2 * p] != B.uv[2 * p] || A.uv[2 * p + 1] != B.uv[2 * p + 1];
        }
        check(bits == 0 && cov > 1000, name, "%ld of %ld covered pixels differ with the hint", bits, cov);
    }
}

static void run_target(target *t, const pixels *px) {
    if (!t->vt->shade || !t->vt->raster) {
        fail(t->name, "the bound vtable lacks %s", !t->vt->shade ? "shade" : "raster");
        return;
    }
    check_shade(t, px);
    check_raster(t);
}

/* The analysis's unfolding of a neighbour face into a face's frame (sfb__an_unfold, the
 * cross-face Hermite seeds): for every pair of sides and both directions, a point on the shared
 * side lands on the same point of the other side; the neighbour's inside lands beyond the side
 * (outside the face); the neighbour's opposite corner lands where a regular grid (two squares)
 * or lattice (two triangles making a parallelogram) puts it; and the reverse call undoes it. */
static void check_unfold(void) {
    int tri, kg, kf, rev, bad_side = 0, bad_out = 0, bad_corner = 0, bad_back = 0, n = 0;
    rng g = rng_for(g_seed, 7);
    for (tri = 0; tri < 2; ++tri) {
        const int ns = tri ? 3 : 4;
        sfb__an A;
        memset(&A, 0, sizeof A);
        A.tri = tri;
        for (kg = 0; kg < ns; ++kg)
            for (kf = 0; kf < ns; ++kf)
                for (rev = 0; rev < 2; ++rev) {
                    int i;
                    double t, ug, vg, uf, vf, ex, ey, u2, v2;
                    /* the shared side */
                    for (i = 0; i < 5; ++i) {
                        t = i / 4.0;
                        sfb__an_side_point(tri, kg, t, &ug, &vg);
                        sfb__an_unfold(tri, kg, kf, rev, ug, vg, &uf, &vf);
                        sfb__an_side_point(tri, kf, rev ? 1.0 - t : t, &ex, &ey);
                        bad_side += !(fabs(uf - ex) < 1e-12 && fabs(vf - ey) < 1e-12);
                    }
                    /* random inside points: beyond the side, and back */
                    for (i = 0; i < 50; ++i) {
                        ug = rnd_in(&g, 0.01, 0.99);
                        vg = rnd_in(&g, 0.01, tri ? 0.99 - ug : 0.99);
                        sfb__an_unfold(tri, kg, kf, rev, ug, vg, &uf, &vf);
                        bad_out += sfb__an_in_domain(&A, uf, vf, 1e-9);
                        sfb__an_unfold(tri, kf, kg, rev, uf, vf, &u2, &v2);
                        bad_back += !(fabs(u2 - ug) < 1e-12 && fabs(v2 - vg) < 1e-12);
                        ++n;
                    }
                    /* the neighbour's corners off the side: squares side by side (the side's
                     * ends moved across it by one), or F's own opposite corner point-reflected
                     * through the side's middle */
                    if (tri) {
                        double cu, cv, au, av, bu, bv, ou, ov;
                        /* G's opposite corner: the start of its side kg + 2 */
                        sfb__an_side_point(tri, (kg + 2) % 3, 0.0, &cu, &cv);
                        sfb__an_unfold(tri, kg, kf, rev, cu, cv, &uf, &vf);
                        sfb__an_side_point(tri, kf, 0.0, &au, &av);
                        sfb__an_side_point(tri, kf, 1.0, &bu, &bv);
                        sfb__an_side_point(tri, (kf + 2) % 3, 0.0, &ou, &ov); /* F's opposite corner */
                        bad_corner += !(fabs(uf - (au + bu - ou)) < 1e-12 && fabs(vf - (av + bv - ov)) < 1e-12);
                    } else {
                        double pu, pv, qu, qv, au, av, bu, bv, nu, nv;
                        /* G's corners off the side: the ends of side kg + 2 (it runs opposite) */
                        sfb__an_side_point(tri, (kg + 2) % 4, 1.0, &pu, &pv); /* off t = 0 */
                        sfb__an_side_point(tri, (kg + 2) % 4, 0.0, &qu, &qv); /* off t = 1 */
                        sfb__an_side_point(tri, kf, rev ? 1.0 : 0.0, &au, &av);
                        sfb__an_side_point(tri, kf, rev ? 0.0 : 1.0, &bu, &bv);
                        /* F's outward normal of side kf, one unit long in (u, v) */
                        sfb__an_side_point(tri, (kf + 2) % 4, 0.5, &nu, &nv);
                        {
                            double mu = 0.5 * (au + bu), mv = 0.5 * (av + bv);
                            double ou = mu - nu, ov = mv - nv;
                            sfb__an_unfold(tri, kg, kf, rev, pu, pv, &uf, &vf);
                            bad_corner += !(fabs(uf - (au + ou)) < 1e-12 && fabs(vf - (av + ov)) < 1e-12);
                            sfb__an_unfold(tri, kg, kf, rev, qu, qv, &uf, &vf);
                            bad_corner += !(fabs(uf - (bu + ou)) < 1e-12 && fabs(vf - (bv + ov)) < 1e-12);
                        }
                    }
                }
    }
    check(bad_side == 0, "unfold/shared_side", "%d shared-side points moved", bad_side);
    check(bad_out == 0, "unfold/beyond_the_side", "%d of %d neighbour points landed inside the face", bad_out, n);
    check(bad_corner == 0, "unfold/grid_corners", "%d neighbour corners off the regular grid", bad_corner);
    check(bad_back == 0, "unfold/inverse", "%d of %d points not restored by the reverse call", bad_back, n);
}

int main(int argc, char **argv) {
    static const char *const isas[5] = {"portable", "sse2", "avx2", "avx512", "neon"};
    static const double lm[3] = {0.0, 0.0, 1.0};
    static pixels px;
    const char *pinned = getenv("SURFBLEND_SIMD_ISA"), *seed = NULL;
    char saved[64];
    rng g;
    int k, threads, i;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) seed = argv[++i];
        else {
            fprintf(stderr, "usage: %s [--seed S]\n", argv[0]);
            return 2;
        }
    }
    harness_seed(seed);
    printf("# seed %llu\n", g_seed);
    g = rng_for(g_seed, 1);
    pixels_random(&px, &g, lm);
    check_raster_hint();
    check_unfold();
    snprintf(saved, sizeof saved, "%s", pinned ? pinned : "");
    for (k = 0; k < 5; ++k) {
        if (saved[0] && strcmp(saved, isas[k]) != 0) continue;
        for (threads = 1; threads <= 2; ++threads) {
            target t;
            char info[256], why[512];
            sfb_context *ctx;
            memset(&t, 0, sizeof t);
            snprintf(t.name, sizeof t.name, "simd-%s/t%d", isas[k], threads);
            setenv("SURFBLEND_SIMD_ISA", isas[k], 1);
            ctx = make_context_threads(SFB_BACKEND_SIMD, threads);
            if (saved[0]) setenv("SURFBLEND_SIMD_ISA", saved, 1);
            else unsetenv("SURFBLEND_SIMD_ISA");
            info[0] = 0;
            if (ctx) sfb_context_backend_info(ctx, info, sizeof info);
            if (!ctx || ctx->backend->kind != SFB_BACKEND_SIMD || strncmp(info, isas[k], strlen(isas[k])) != 0 || info[strlen(isas[k])] != ' ') {
                snprintf(why, sizeof why, "this CPU or build has no %s kernels%s%s", isas[k], info[0] ? " (the backend runs: " : "", info[0] ? info : "");
                if (info[0]) strncat(why, ")", sizeof why - strlen(why) - 1);
                skip(t.name, why);
                if (ctx) sfb_context_destroy(ctx);
                continue;
            }
            printf("# %s: %s\n", t.name, info);
            t.vt = ctx->backend;
            t.state = ctx->backend_state;
            t.exact = 1;
            run_target(&t, &px);
            sfb_context_destroy(ctx);
        }
    }
    for (k = 0; k < 2; ++k) {
        const sfb_backend_kind kind = k ? SFB_BACKEND_OSMESA : SFB_BACKEND_GL;
        target t;
        char why[512];
        sfb_context *ctx = make_context(kind);
        memset(&t, 0, sizeof t);
        snprintf(t.name, sizeof t.name, "%s", sfb_backend_kind_name(kind));
        if (!ctx || ctx->backend->kind != kind) {
            why[0] = 0;
            sfb_backend_probe(kind, NULL, why, sizeof why);
            backend_unavailable(t.name, t.name, why[0] ? why : "no context");
            if (ctx) sfb_context_destroy(ctx);
            continue;
        }
        t.vt = ctx->backend;
        t.state = ctx->backend_state;
        run_target(&t, &px);
        sfb_context_destroy(ctx);
    }
    return finish_tests();
}
