/* 02_backends: which compute backends this machine has, and whether they agree.
 *
 * surfblend compiles a mesh into stencil tables once, on the CPU; a backend applies them:
 *   ref     plain C, double accumulation: the reference every other backend is checked against
 *   simd    SSE2/AVX2/AVX-512/NEON kernels on a thread pool
 *   gl      OpenGL 4.3 compute shaders (its own headless EGL context, or the host's)
 *   osmesa  the gl kernels in Mesa's off-screen software renderer (servers, CI)
 * This program asks each one whether it can run here (sfb_backend_probe), then refines the same
 * creased cube on every backend that can and prints how far its refined points and limit points
 * are from ref's. Exit status 0 when every available backend agrees within 1e-5 x the cube's
 * bounding-box diagonal, 1 otherwise.
 *
 *   cc -std=c99 -I. examples/02_backends.c tools/impl.c -lm -lpthread -ldl
 * (tools/impl.c defines SURFBLEND_ALL_BACKENDS: GL, EGL and OSMesa are opened at run time, so
 * nothing else is linked; a library that is missing only makes its backend unavailable.) */
#include "surfblend.h"
#include <math.h>
#include <stdio.h>

/* A cube whose top four edges are semi-sharp (sharpness 2) with one sharp corner. */
static const float positions[8 * 3] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1,
                                       -1, -1, 1,  1, -1, 1,  1, 1, 1,  -1, 1, 1};
static const int sizes[6] = {4, 4, 4, 4, 4, 4};
static const int faces[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
static const int creases[8] = {4, 5, 5, 6, 6, 7, 7, 4};
static const float crease_sharpness[4] = {2, 2, 2, 2};
static const int corners[1] = {0};
static const float corner_sharpness[1] = {10};

/* Refines the cube to level 3 on one backend: *ctx_out is the context (it owns the memory of
 * `out`: free `out` with sfb_mesh_data_free before destroying the context). */
static sfb_result refine_on(sfb_backend_kind kind, sfb_context **ctx_out, sfb_mesh_data *out, char *info, size_t info_size) {
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surface = NULL;
    sfb_mesh_desc desc = {0};
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 3);
    sfb_result r;

    cc.backends = &kind;        /* this backend and no other */
    cc.backend_count = 1;
    cc.ignore_environment = 1;  /* SURFBLEND_BACKEND must not change what we compare */
    *ctx_out = NULL;
    r = sfb_context_create(&cc, &ctx);
    if (r != SFB_SUCCESS) return r;
    sfb_context_backend_info(ctx, info, info_size);

    desc.vertex_count = 8; desc.positions = positions;
    desc.face_count = 6; desc.face_sizes = sizes; desc.face_vertices = faces;
    desc.crease_count = 4; desc.crease_vertices = creases; desc.crease_sharpness = crease_sharpness;
    desc.corner_count = 1; desc.corner_vertices = corners; desc.corner_sharpness = corner_sharpness;
    sc.flags = SFB_REFINE_LIMIT;
    if ((r = sfb_mesh_create(ctx, &desc, &mesh)) == SFB_SUCCESS &&
        (r = sfb_surface_create(ctx, mesh, &sc, &surface)) == SFB_SUCCESS)
        r = sfb_surface_refine(surface, out);   /* runs the tables on this context's backend */
    if (r != SFB_SUCCESS) fprintf(stderr, "  %s: %s\n", sfb_backend_kind_name(kind), sfb_last_error(ctx));
    sfb_surface_destroy(surface); /* `out` has its own copy of everything */
    sfb_mesh_destroy(mesh);
    if (r != SFB_SUCCESS) sfb_context_destroy(ctx);
    else *ctx_out = ctx;
    return r;
}

static double max_difference(const float *a, const float *b, int n) {
    double worst = 0.0;
    int i;
    for (i = 0; i < n; ++i) {
        double d = fabs((double)a[i] - (double)b[i]);
        if (d != d) return INFINITY; /* NaN: no agreement */
        if (d > worst) worst = d;
    }
    return worst;
}

int main(void) {
    static const sfb_backend_kind kinds[4] = {SFB_BACKEND_REF, SFB_BACKEND_SIMD, SFB_BACKEND_GL, SFB_BACKEND_OSMESA};
    const double tolerance = 1e-5 * sqrt(12.0); /* 1e-5 x diagonal of the 2 x 2 x 2 cube */
    sfb_context *ref_ctx;
    sfb_mesh_data ref;
    char info[512];
    int i, status = 0;

    printf("backends compiled into this program and whether they run here:\n");
    for (i = 0; i < 4; ++i) {
        sfb_result r = sfb_backend_probe(kinds[i], NULL, info, sizeof info);
        printf("  %-7s %s: %s\n", sfb_backend_kind_name(kinds[i]), r == SFB_SUCCESS ? "available  " : "unavailable",
               info[0] ? info : (kinds[i] == SFB_BACKEND_REF ? "plain C, double accumulation" : sfb_result_string(r)));
    }

    if (refine_on(SFB_BACKEND_REF, &ref_ctx, &ref, info, sizeof info) != SFB_SUCCESS) return 1;
    printf("\ncreased cube, Catmull-Clark level 3: %d vertices, %d faces; tolerance %.2g\n", ref.vertex_count, ref.face_count,
           tolerance);
    printf("  %-7s %-22s %-22s %s\n", "backend", "max |dp| positions", "max |dp| limit", "verdict");
    for (i = 1; i < 4; ++i) {
        sfb_context *ctx;
        sfb_mesh_data out;
        double dp, dl;
        int ok;
        if (sfb_backend_probe(kinds[i], NULL, info, sizeof info) != SFB_SUCCESS) {
            printf("  %-7s skipped (unavailable)\n", sfb_backend_kind_name(kinds[i]));
            continue;
        }
        if (refine_on(kinds[i], &ctx, &out, info, sizeof info) != SFB_SUCCESS) {
            printf("  %-7s FAILED to refine\n", sfb_backend_kind_name(kinds[i]));
            status = 1;
            continue;
        }
        ok = out.vertex_count == ref.vertex_count;
        dp = ok ? max_difference(out.positions, ref.positions, 3 * ref.vertex_count) : INFINITY;
        dl = ok ? max_difference(out.limit_positions, ref.limit_positions, 3 * ref.vertex_count) : INFINITY;
        ok = ok && dp <= tolerance && dl <= tolerance;
        printf("  %-7s %-22.3g %-22.3g %s\n", sfb_backend_kind_name(kinds[i]), dp, dl, ok ? "agrees with ref" : "DISAGREES");
        if (!ok) status = 1;
        sfb_mesh_data_free(&out);
        sfb_context_destroy(ctx);
    }
    sfb_mesh_data_free(&ref);
    sfb_context_destroy(ref_ctx);
    return status;
}
