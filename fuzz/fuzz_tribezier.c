/* fuzz_tribezier.c - libFuzzer target for quartic triangular Bezier surfaces with sharpness
 * (SFB_SCHEME_TRIBEZIER, seed 004).
 *
 * Input: OBJ text. If sfb_mesh_read_obj accepts it, build the surface (an error is fine, with a
 * message: faces that are not triangles, non-manifold edges, degenerate triangles; non-manifold vertices are split),
 * with the tags' sharpness, or, for inputs whose length is a multiple of 3, one override s =
 * (length mod 11) / 10, then:
 *   - evaluate every parametric face (holes excepted) at its corners, edge midpoints and centre: a normal
 *     is unit length or zero; when every input position is finite and small (|x| < 1e6), the
 *     positions are finite and every point lies within the bounding box grown by 10 times its
 *     diagonal (the net is an affine combination of the vertices, the G1 solve's change small);
 *   - inputs whose length is a multiple of 5 are built with the slider (tribezier.slider): moved to
 *     s = (length mod 7) / 6 and back to the options they were built with, the positions must be
 *     bit for bit the first ones (sfb_surface_set_sharpness); without the override, the first
 *     tagged crease moved to 0.5 and back to its tag (sfb_surface_set_feature_sharpness) too;
 *   - tessellate at rate 3 and check the triangles' indices;
 *   - a mesh with faces of more than three corners: sfb_mesh_triangulate (pieces, tags, holes
 *     checked: triangulated()), then all of the above on the result.
 * A violated invariant calls abort().
 *
 * Build (from the repository root):
 *   clang -g -O1 -fsanitize=fuzzer,address,undefined -I. fuzz/fuzz_tribezier.c -x c tools/impl.c -o fuzz_tribezier
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_tribezier: invariant violated: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    abort();
}

static void run(sfb_context *ctx, const sfb_mesh *mesh, size_t size)
{
    static const float uv[7][2] = {{0, 0}, {1, 0}, {0, 1}, {0.5f, 0}, {0.5f, 0.5f}, {0, 0.5f}, {1.0f / 3, 1.0f / 3}};
    sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
    sfb_surface *s = NULL;
    sfb_mesh_info info;
    sfb_mesh_desc d;
    sfb_result r;
    int nf, f, q, c, n = 0, tame = 1;
    double diag = 0.0;
    cfg.flags = SFB_REFINE_PATCHES;
    if (size % 3 == 0) {
        cfg.tribezier.sharpness_set = 1;
        cfg.tribezier.sharpness = (float)(size % 11) / 10.0f;
    }
    cfg.tribezier.slider = size % 5 == 0;
    r = sfb_surface_create(ctx, mesh, &cfg, &s);
    if (r != SFB_SUCCESS) {
        const char *m = sfb_last_error(ctx);
        if (!m || !m[0]) fail("empty error message after failure of", "sfb_surface_create(tribezier)");
        return;
    }
    sfb_mesh_get_info(mesh, &info);
    sfb_mesh_get_desc(mesh, &d);
    for (q = 0; q < 3; ++q) {
        if (!(fabs(info.bbox_min[q]) < 1e6 && fabs(info.bbox_max[q]) < 1e6)) tame = 0;
        diag += ((double)info.bbox_max[q] - info.bbox_min[q]) * ((double)info.bbox_max[q] - info.bbox_min[q]);
    }
    diag = sqrt(diag);
    nf = sfb_surface_param_face_count(s);
    if (nf > 4096) nf = 4096;
    {
        sfb_location *L = (sfb_location *)malloc(sizeof *L * (size_t)(7 * nf + 1));
        float *P = (float *)malloc(sizeof(float) * 6 * (size_t)(7 * nf + 1)), *N = P + 3 * (size_t)(7 * nf + 1);
        sfb_eval_output o;
        if (!L || !P) fail("test allocation", NULL);
        for (f = 0; f < nf; ++f) {
            int h, hole = 0;
            for (h = 0; h < d.hole_count; ++h) hole |= d.holes[h] == f; /* one param face per triangle */
            if (hole) continue;
            for (q = 0; q < 7; ++q) {
                L[n].face = f;
                L[n].u = uv[q][0];
                L[n].v = uv[q][1];
                n++;
            }
        }
        memset(&o, 0, sizeof o);
        o.position = P;
        o.normal = N;
        r = sfb_surface_eval(s, L, n, &o);
        if (r != SFB_SUCCESS) fail("sfb_surface_eval on valid locations", sfb_last_error(ctx));
        for (q = 0; q < n; ++q) {
            const float *p = P + 3 * (size_t)q, *nn = N + 3 * (size_t)q;
            double len = sqrt((double)nn[0] * nn[0] + (double)nn[1] * nn[1] + (double)nn[2] * nn[2]);
            if (!(len == 0.0 || fabs(len - 1.0) < 1e-3)) fail("normal neither unit nor zero", NULL);
            if (!tame) continue;
            for (c = 0; c < 3; ++c) {
                if (!isfinite(p[c])) fail("non-finite position from finite input", NULL);
                if (p[c] < info.bbox_min[c] - 10 * diag - 1e-3 || p[c] > info.bbox_max[c] + 10 * diag + 1e-3) fail("point far outside", NULL);
            }
        }
        if (cfg.tribezier.slider) {
            /* the slider moved and back: the same surface, bit for bit (evaluated for the same
             * outputs: the simd backend's float kernel hands a location whose normal it cannot
             * trust to its double kernel, position included, so a position may differ by a
             * rounding with and without normals asked) */
            float *P2 = (float *)malloc(sizeof(float) * 6 * (size_t)(n + 1));
            sfb_tribezier_options to = cfg.tribezier;
            if (!P2) fail("test allocation", NULL);
            to.sharpness_set = 1;
            to.sharpness = (float)(size % 7) / 6.0f;
            if (sfb_surface_set_sharpness(s, &to) != SFB_SUCCESS || sfb_surface_set_sharpness(s, &cfg.tribezier) != SFB_SUCCESS)
                fail("sfb_surface_set_sharpness on a slider surface", sfb_last_error(ctx));
            int once = d.crease_count > 0, k;
            for (k = 1; k < d.crease_count && once; ++k) /* tagged once: its tag is the mesh's */
                once = !((d.crease_vertices[2 * k] == d.crease_vertices[0] && d.crease_vertices[2 * k + 1] == d.crease_vertices[1]) ||
                         (d.crease_vertices[2 * k] == d.crease_vertices[1] && d.crease_vertices[2 * k + 1] == d.crease_vertices[0]));
            if (!cfg.tribezier.sharpness_set && once && d.crease_sharpness[0] > 0.0f) {
                /* a tagged crease: moved and back (its tag as the mesh has it) */
                const float half = 0.5f;
                r = sfb_surface_set_feature_sharpness(s, 1, d.crease_vertices, &half, 0, NULL, NULL);
                if (r == SFB_SUCCESS) r = sfb_surface_set_feature_sharpness(s, 1, d.crease_vertices, d.crease_sharpness, 0, NULL, NULL);
                if (r != SFB_SUCCESS) fail("sfb_surface_set_feature_sharpness on a tagged crease", sfb_last_error(ctx));
            }
            memset(&o, 0, sizeof o);
            o.position = P2;
            o.normal = P2 + 3 * (size_t)(n + 1);
            if (sfb_surface_eval(s, L, n, &o) != SFB_SUCCESS) fail("sfb_surface_eval after the slider", sfb_last_error(ctx));
            if (memcmp(P, P2, sizeof(float) * 3 * (size_t)n) != 0 || memcmp(N, o.normal, sizeof(float) * 3 * (size_t)n) != 0)
                fail("the slider moved and back changed the surface", NULL);
            free(P2);
        }
        free(L);
        free(P);
    }
    {
        sfb_tess_config tc = sfb_tess_config_init(3);
        sfb_tess_data t;
        tc.flags = SFB_TESS_SPLIT_CREASES;
        r = sfb_surface_tessellate(s, &tc, &t);
        if (r == SFB_SUCCESS) {
            for (q = 0; q < 3 * t.triangle_count; ++q)
                if (t.triangles[q] < 0 || t.triangles[q] >= t.vertex_count) fail("tessellation index out of range", NULL);
            sfb_tess_data_free(&t);
        } else if (!sfb_last_error(ctx)[0]) fail("empty error message after failure of", "sfb_surface_tessellate");
    }
    sfb_surface_destroy(s);
}

/* A mesh with faces of more than three corners: sfb_mesh_triangulate, then the surface of the
 * result. Invariants: success or a message; on success every face of k corners became the next
 * k - 2 triangles, of its own vertices; the vertices and corners are kept, every crease tag is
 * one of the mesh's, each hole's pieces are holes. */
static void triangulated(sfb_context *ctx, const sfb_mesh *mesh, size_t size)
{
    sfb_mesh *t = NULL;
    sfb_mesh_desc d, o;
    int split = -1, f, k, at = 0, out = 0, nh = 0, h;
    sfb_result r = sfb_mesh_triangulate(ctx, mesh, &t, &split);
    if (r != SFB_SUCCESS) {
        if (!sfb_last_error(ctx)[0]) fail("empty error message after failure of", "sfb_mesh_triangulate");
        if (t) fail("a mesh returned with an error", NULL);
        return;
    }
    sfb_mesh_get_desc(mesh, &d);
    sfb_mesh_get_desc(t, &o);
    /* (two crease tags may become one: a face that repeats a vertex can make two edges of one
     * vertex pair, which its triangles join) */
    if (o.vertex_count != d.vertex_count || o.crease_count > d.crease_count || o.corner_count != d.corner_count)
        fail("triangulate lost vertices or corners, or made creases", NULL);
    for (k = 0; k < o.crease_count; ++k) {
        const int a = o.crease_vertices[2 * k], b = o.crease_vertices[2 * k + 1];
        int j = 0;
        while (j < d.crease_count && !(((d.crease_vertices[2 * j] == a && d.crease_vertices[2 * j + 1] == b) ||
                                        (d.crease_vertices[2 * j] == b && d.crease_vertices[2 * j + 1] == a)) &&
                                       d.crease_sharpness[j] == o.crease_sharpness[k]))
            ++j;
        if (j == d.crease_count) fail("a crease tag that was not in the mesh", NULL);
    }
    for (f = 0; f < d.face_count; ++f) {
        const int n = d.face_sizes[f];
        split -= n > 3;
        for (k = 0; k < 3 * (n - 2); ++k, ++out) {
            int j = 0;
            if (out >= 3 * o.face_count) fail("triangulate made too few faces", NULL);
            while (j < n && d.face_vertices[at + j] != o.face_vertices[out]) ++j;
            if (j == n) fail("a triangle's corner is not one of its face's", NULL);
        }
        for (h = 0; h < d.hole_count; ++h) nh += d.holes[h] == f ? n - 2 : 0;
        at += n;
    }
    if (out != 3 * o.face_count || split != 0 || nh != o.hole_count) fail("triangulate's counts", NULL);
    for (f = 0; f < o.face_count; ++f)
        if (o.face_sizes[f] != 3) fail("triangulate left a face that is not a triangle", NULL);
    run(ctx, t, size);
    sfb_mesh_destroy(t);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    cc.ignore_environment = 1;
    cc.memory_budget = (size_t)256 << 20;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) return 0;
    if (sfb_mesh_read_obj(ctx, (const char *)data, size, &mesh) == SFB_SUCCESS) {
        sfb_mesh_info info;
        run(ctx, mesh, size);
        sfb_mesh_get_info(mesh, &info);
        if (info.quads + info.ngons > 0) triangulated(ctx, mesh, size);
        sfb_mesh_destroy(mesh);
    }
    sfb_context_destroy(ctx);
    return 0;
}
