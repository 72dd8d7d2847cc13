/* Failure paths of the gl and osmesa backends, for real: this program compiles the library
 * with kernel sources the GL compiler must reject, and with libOSMesa looked up under names
 * that do not exist (as on Mesa 25.1+, which ships none). Checks that each comes back as a
 * result with the reason (the driver's compile log for gl) and that selection falls through to
 * the next backend. The stencil kernel is compiled when the backend starts, so a broken one
 * makes gl unavailable; the normals kernel (finish_normals, seed 001's blend) is compiled on
 * first use, so a broken one makes sfb_surface_shade fail with the log while the backend and
 * its other kernels keep working. Which source is broken is switched at run time (the source
 * macros read the flags below). Prints PASS/FAIL/SKIP lines and "N passed, N failed, N skipped" (tests/harness.h). */
#define SURFBLEND_IMPLEMENTATION
#define SURFBLEND_GL
#define SURFBLEND_OSMESA
static int g_break_stencils = 1, g_break_normals = 0;
#define SFB__GL_STENCIL_SOURCE \
    (g_break_stencils ? "layout(local_size_x = 64) in;\nvoid main() { undeclared_thing = 1; }\n" : sfb__glsl_stencils_comp_glsl)
#define SFB__GL_NORMALS_SOURCE \
    (g_break_normals ? "layout(local_size_x = 64) in;\nvoid main() { undeclared_normal = 1; }\n" : sfb__glsl_normals_comp_glsl)
#define SFB__OSMESA_LIBRARY_NAMES {"libOSMesa-absent.so.8", "libOSMesa-absent.so.6", NULL}
#include "surfblend.h"
#include "harness.h"

int main(void) {
    char info[1024], report[2048], why[1100];
    sfb_result r;
    sfb_context *ctx = NULL;
    sfb_context_config cfg = sfb_context_config_init();
    sfb_backend_kind order[2];

    /* osmesa: library missing */
    r = sfb_backend_probe(SFB_BACKEND_OSMESA, NULL, info, sizeof info);
    check(r == SFB_BACKEND_UNAVAILABLE, "osmesa-missing-library-result", "%s", sfb_result_string(r));
    check(strstr(info, "libOSMesa") != NULL && strstr(info, "not found") != NULL, "osmesa-missing-library-reason", "%s", info);
    order[0] = SFB_BACKEND_OSMESA; order[1] = SFB_BACKEND_REF;
    cfg.backends = order; cfg.backend_count = 2; cfg.ignore_environment = 1;
    r = sfb_context_create(&cfg, &ctx);
    check(r == SFB_SUCCESS && strcmp(sfb_context_backend_name(ctx), "ref") == 0, "osmesa-missing-falls-back-to-ref",
          "%s", sfb_result_string(r));
    if (ctx) {
        sfb_context_backend_report(ctx, report, sizeof report);
        check(strstr(report, "osmesa: unavailable (") != NULL && strstr(report, "not found") != NULL &&
              strstr(report, "ref: selected") != NULL, "osmesa-missing-report", "%s", report);
        sfb_context_destroy(ctx);
        ctx = NULL;
    }

    /* gl: the driver must reject the kernel, and its log must reach the caller */
    r = sfb_backend_probe(SFB_BACKEND_GL, NULL, info, sizeof info);
    if (r == SFB_BACKEND_UNAVAILABLE && strstr(info, "failed to compile") == NULL && !backend_required("gl")) {
        snprintf(why, sizeof why, "no GL 4.3 context here (%s)", info);
        skip("gl-compile-error", why);
    } else {
        check(r != SFB_SUCCESS, "gl-compile-error-result", "a broken kernel initialised");
        check(strstr(info, "failed to compile") != NULL && strstr(info, "stencils.comp.glsl") != NULL,
              "gl-compile-error-names-the-shader", "%s", info);
        /* the driver's own log follows: Mesa says "error", others "ERROR" */
        check(strstr(info, "undeclared_thing") != NULL || strstr(info, "rror") != NULL, "gl-compile-error-driver-log", "%s", info);
        order[0] = SFB_BACKEND_GL; order[1] = SFB_BACKEND_REF;
        r = sfb_context_create(&cfg, &ctx);
        check(r == SFB_SUCCESS && strcmp(sfb_context_backend_name(ctx), "ref") == 0, "gl-compile-error-falls-back", "%s", sfb_result_string(r));
        if (ctx) {
            sfb_context_backend_report(ctx, report, sizeof report);
            check(strstr(report, "gl: unavailable (backend error: gl: stencils.comp.glsl") != NULL, "gl-compile-error-report", "%s", report);
            sfb_context_destroy(ctx);
        }
    }

    /* gl: a normals kernel the driver rejects (intact stencil kernel) */
    g_break_stencils = 0;
    g_break_normals = 1;
    r = sfb_backend_probe(SFB_BACKEND_GL, NULL, info, sizeof info);
    if (r != SFB_SUCCESS && !backend_required("gl")) {
        snprintf(why, sizeof why, "no GL 4.3 context here (%s)", info);
        skip("gl-normals-compile-error", why);
    } else {
        static const float P[8 * 3] = {-1, -1, 1, 1, -1, 1, -1, 1, 1, 1, 1, 1, -1, 1, -1, 1, 1, -1, -1, -1, -1, 1, -1, -1};
        static const int Q[6 * 4] = {0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4};
        static const int FS[6] = {4, 4, 4, 4, 4, 4};
        sfb_mesh_desc desc;
        sfb_mesh *m = NULL;
        sfb_surface *s = NULL;
        sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 2);
        sfb_mesh_data d;
        const char *err;
        check(r == SFB_SUCCESS, "gl-normals-compile-error-backend-starts", "%s", info);
        order[0] = SFB_BACKEND_GL;
        cfg.backend_count = 1;
        r = sfb_context_create(&cfg, &ctx);
        check(r == SFB_SUCCESS && strcmp(sfb_context_backend_name(ctx), "gl") == 0, "gl-normals-compile-error-gl-selected", "%s", sfb_result_string(r));
        memset(&desc, 0, sizeof desc);
        desc.vertex_count = 8; desc.positions = P; desc.face_count = 6; desc.face_sizes = FS; desc.face_vertices = Q;
        sc.flags = SFB_REFINE_SHADING;
        memset(&d, 0, sizeof d);
        if (!ctx || sfb_mesh_create(ctx, &desc, &m) != SFB_SUCCESS || sfb_surface_create(ctx, m, &sc, &s) != SFB_SUCCESS) {
            check(0, "gl-normals-compile-error-surface", "%s", ctx ? sfb_last_error(ctx) : "no context");
        } else {
            r = sfb_surface_shade(s, NULL, &d);
            err = sfb_last_error(ctx);
            printf("# %s\n", err);
            check(r == SFB_BACKEND_ERROR, "gl-normals-compile-error-result", "%s", sfb_result_string(r));
            check(strstr(err, "failed to compile") != NULL && strstr(err, "normals.comp.glsl") != NULL, "gl-normals-compile-error-names-the-shader",
                  "%s", err);
            check(strstr(err, "undeclared_normal") != NULL || strstr(err, "rror") != NULL, "gl-normals-compile-error-driver-log", "%s", err);
            check(d.positions == NULL && d.normals == NULL && d.vertex_count == 0, "gl-normals-compile-error-no-output", "output left behind");
            /* the failure is not cached: the next call compiles again and fails the same way */
            r = sfb_surface_shade(s, NULL, &d);
            check(r == SFB_BACKEND_ERROR && strstr(sfb_last_error(ctx), "normals.comp.glsl") != NULL, "gl-normals-compile-error-again",
                  "%s", sfb_last_error(ctx));
            /* the backend's other kernels still run */
            r = sfb_surface_refine(s, &d);
            check(r == SFB_SUCCESS && d.vertex_count == 98 && strcmp(sfb_context_backend_name(ctx), "gl") == 0, "gl-normals-compile-error-stencils-still-run",
                  "%s", sfb_last_error(ctx));
            sfb_mesh_data_free(&d);
        }
        if (s) sfb_surface_destroy(s);
        if (m) sfb_mesh_destroy(m);
        if (ctx) sfb_context_destroy(ctx);
        ctx = NULL;
    }
    return close_tests();
}
