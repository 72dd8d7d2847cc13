/* fuzz_manifold.c - libFuzzer target for manifold-based blending surfaces (seed 000).
 *
 * Input: OBJ text. If sfb_mesh_read_obj accepts it, build SFB_SCHEME_MANIFOLD_BLEND surfaces with
 * both weight kinds (an error is fine, with a message), then:
 *   - evaluate every parametric face (holes excepted) at its corners, edge midpoints, centre and
 *     two interior points with every output; the patch info must count one blend per patch;
 *   - a normal is unit length or zero; when every input position is finite and small (|x| <
 *     1e6), positions and first derivatives are finite and positions lie within the bounding box
 *     of the control points grown by 100 times its diagonal (the blend is a convex combination
 *     of local geometries fitted to the one-rings);
 *   - tessellate at rate 2 and check the triangles' indices.
 * A violated invariant calls abort().
 *
 * Build (from the repository root):
 *   clang -g -O1 -fsanitize=fuzzer,address,undefined -I. fuzz/fuzz_manifold.c -x c tools/impl.c -o fuzz_manifold
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_manifold: invariant violated: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    abort();
}

static void check_error(sfb_context *ctx, sfb_result r, const char *call)
{
    const char *m;
    if (r == SFB_SUCCESS) return;
    m = sfb_last_error(ctx);
    if (!m || !m[0]) fail("empty error message after failure of", call);
}

static void run(sfb_context *ctx, const sfb_mesh *mesh, int weights)
{
    sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_MANIFOLD_BLEND, 0);
    sfb_surface *s = NULL;
    sfb_mesh_info info;
    sfb_patch_info pi;
    sfb_result r;
    int nf, f, q, n = 0, tame;
    double lo[3], hi[3], diag;
    static const float uv[9][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5f, 0}, {1, 0.5f}, {0.5f, 1}, {0, 0.5f}, {0.5f, 0.5f}};
    cfg.flags = SFB_REFINE_PATCHES;
    cfg.manifold.weights = weights;
    r = sfb_surface_create(ctx, mesh, &cfg, &s);
    if (r != SFB_SUCCESS) { check_error(ctx, r, "sfb_surface_create(manifold)"); return; }
    if (sfb_surface_patch_info(s, &pi) != SFB_SUCCESS || pi.manifold != pi.patches) fail("patch info does not count the blends", NULL);
    sfb_mesh_get_info(mesh, &info);
    tame = 1;
    for (q = 0; q < 3; ++q) {
        lo[q] = info.bbox_min[q]; hi[q] = info.bbox_max[q];
        if (!(fabs(lo[q]) < 1e6 && fabs(hi[q]) < 1e6)) tame = 0;
    }
    diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    nf = sfb_surface_param_face_count(s);
    if (nf > 4096) nf = 4096;
    {
        sfb_location *L = (sfb_location *)malloc(sizeof *L * (size_t)(11 * nf + 1));
        float *P = (float *)malloc(sizeof(float) * 3 * (size_t)(11 * nf + 1) * 7), *D = P + 3 * (size_t)(11 * nf + 1);
        sfb_eval_output o;
        size_t st = 3 * (size_t)(11 * nf + 1);
        if (!L || !P) fail("test allocation", NULL);
        for (f = 0; f < nf; ++f) {
            int first, count, base, sub;
            if (sfb_surface_param_face_base(s, f, &base, &sub) != SFB_SUCCESS) fail("param face base", NULL);
            if (sfb_surface_param_faces(s, base, &first, &count) != SFB_SUCCESS || f < first || f >= first + count) fail("param faces", NULL);
            for (q = 0; q < 11; ++q) {
                L[n].face = f;
                L[n].u = q < 9 ? uv[q][0] : (q == 9 ? 0.25f : 0.8f);
                L[n].v = q < 9 ? uv[q][1] : (q == 9 ? 0.7f : 0.1f);
                n++;
            }
        }
        memset(&o, 0, sizeof o);
        o.position = P; o.du = D; o.dv = D + st; o.normal = D + 2 * st; o.duu = D + 3 * st; o.duv = D + 4 * st; o.dvv = D + 5 * st;
        /* face by face: a hole face is refused (SFB_INVALID_VALUE), the others must evaluate */
        for (f = 0; f < nf; ++f) {
            sfb_eval_output of = o;
            size_t at = 3 * (size_t)(11 * f);
            of.position += at; of.du += at; of.dv += at; of.normal += at; of.duu += at; of.duv += at; of.dvv += at;
            r = sfb_surface_eval(s, L + 11 * f, 11, &of);
            if (r != SFB_SUCCESS) {
                check_error(ctx, r, "sfb_surface_eval");
                if (r != SFB_INVALID_VALUE) fail("eval of a valid location failed", sfb_last_error(ctx));
                for (q = 11 * f; q < 11 * f + 11; ++q) L[q].face = -1;
            }
        }
        {
            for (q = 0; q < n; ++q) {
                if (L[q].face < 0) continue;
                {
                const float *p = P + 3 * q, *nn = o.normal + 3 * q;
                double ln = sqrt((double)nn[0] * nn[0] + (double)nn[1] * nn[1] + (double)nn[2] * nn[2]);
                int c;
                if (!(ln == 0.0 || fabs(ln - 1.0) < 1e-3) && tame) fail("normal neither unit nor zero", NULL);
                if (!tame) continue;
                for (c = 0; c < 3; ++c) {
                    if (!isfinite(p[c]) || !isfinite(o.du[3 * q + c]) || !isfinite(o.dv[3 * q + c])) fail("non-finite position or derivative", NULL);
                    if (p[c] < lo[c] - 100.0 * diag - 1e-3 || p[c] > hi[c] + 100.0 * diag + 1e-3) fail("blend far outside the control points", NULL);
                }
                }
            }
        }
        free(L); free(P);
    }
    {
        sfb_tess_config tc = sfb_tess_config_init(2);
        sfb_tess_data td;
        r = sfb_surface_tessellate(s, &tc, &td);
        if (r != SFB_SUCCESS) check_error(ctx, r, "sfb_surface_tessellate");
        else {
            for (q = 0; q < 3 * td.triangle_count; ++q)
                if (td.triangles[q] < 0 || td.triangles[q] >= td.vertex_count) fail("tessellation index out of range", NULL);
            sfb_tess_data_free(&td);
        }
    }
    sfb_surface_destroy(s);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_backend_kind ref = SFB_BACKEND_REF;
    cc.backends = &ref;
    cc.backend_count = 1;
    cc.ignore_environment = 1;
    cc.memory_budget = (size_t)256 << 20;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) return 0;
    if (sfb_mesh_read_obj(ctx, (const char *)data, size, &mesh) == SFB_SUCCESS) {
        sfb_mesh_info info;
        sfb_mesh_get_info(mesh, &info);
        if (info.face_count <= 20000) { run(ctx, mesh, 0); run(ctx, mesh, 1); }
        sfb_mesh_destroy(mesh);
    }
    sfb_context_destroy(ctx);
    return 0;
}
