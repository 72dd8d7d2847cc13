/* Failure paths of the gl and osmesa backends, for real: this program compiles the library
 * with a kernel source the GL compiler must reject, and with libOSMesa looked up under names
 * that do not exist (as on Mesa 25.1+, which ships none). Checks that each comes back as a
 * result with the reason (the driver's compile log for gl) and that selection falls through to
 * the next backend. Prints PASS/FAIL/SKIP lines and "N passed, N failed, N skipped". */
#define SURFBLEND_IMPLEMENTATION
#define SURFBLEND_GL
#define SURFBLEND_OSMESA
#define SFB__GL_STENCIL_SOURCE "layout(local_size_x = 64) in;\nvoid main() { undeclared_thing = 1; }\n"
#define SFB__OSMESA_LIBRARY_NAMES {"libOSMesa-absent.so.8", "libOSMesa-absent.so.6", NULL}
#include "surfblend.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int passed, failed, skipped;
static void check(int ok, const char *name, const char *detail) {
    if (ok) { printf("PASS %s\n", name); ++passed; }
    else { printf("FAIL %s: %s\n", name, detail); ++failed; }
}

static int required(const char *name) {
    const char *req = getenv("SFB_REQUIRE_BACKENDS");
    return req && strstr(req, name) != NULL;
}

int main(void) {
    char info[1024], report[2048];
    sfb_result r;
    sfb_context *ctx = NULL;
    sfb_context_config cfg = sfb_context_config_init();
    sfb_backend_kind order[2];

    /* osmesa: library missing */
    r = sfb_backend_probe(SFB_BACKEND_OSMESA, NULL, info, sizeof info);
    check(r == SFB_BACKEND_UNAVAILABLE, "osmesa-missing-library-result", sfb_result_string(r));
    check(strstr(info, "libOSMesa") != NULL && strstr(info, "not found") != NULL, "osmesa-missing-library-reason", info);
    order[0] = SFB_BACKEND_OSMESA; order[1] = SFB_BACKEND_REF;
    cfg.backends = order; cfg.backend_count = 2; cfg.ignore_environment = 1;
    r = sfb_context_create(&cfg, &ctx);
    check(r == SFB_SUCCESS && strcmp(sfb_context_backend_name(ctx), "ref") == 0, "osmesa-missing-falls-back-to-ref",
          sfb_result_string(r));
    if (ctx) {
        sfb_context_backend_report(ctx, report, sizeof report);
        check(strstr(report, "osmesa: unavailable (") != NULL && strstr(report, "not found") != NULL &&
              strstr(report, "ref: selected") != NULL, "osmesa-missing-report", report);
        sfb_context_destroy(ctx);
        ctx = NULL;
    }

    /* gl: the driver must reject the kernel, and its log must reach the caller */
    r = sfb_backend_probe(SFB_BACKEND_GL, NULL, info, sizeof info);
    if (r == SFB_BACKEND_UNAVAILABLE && strstr(info, "failed to compile") == NULL && !required("gl")) {
        printf("SKIP gl-compile-error: no GL 4.3 context here (%s)\n", info);
        ++skipped;
    } else {
        check(r != SFB_SUCCESS, "gl-compile-error-result", "a broken kernel initialised");
        check(strstr(info, "failed to compile") != NULL && strstr(info, "stencils.comp.glsl") != NULL,
              "gl-compile-error-names-the-shader", info);
        /* the driver's own log follows: Mesa says "error", others "ERROR" */
        check(strstr(info, "undeclared_thing") != NULL || strstr(info, "rror") != NULL, "gl-compile-error-driver-log", info);
        order[0] = SFB_BACKEND_GL; order[1] = SFB_BACKEND_REF;
        r = sfb_context_create(&cfg, &ctx);
        check(r == SFB_SUCCESS && strcmp(sfb_context_backend_name(ctx), "ref") == 0, "gl-compile-error-falls-back", sfb_result_string(r));
        if (ctx) {
            sfb_context_backend_report(ctx, report, sizeof report);
            check(strstr(report, "gl: unavailable (backend error: gl: stencils.comp.glsl") != NULL, "gl-compile-error-report", report);
            sfb_context_destroy(ctx);
        }
    }
    printf("%d passed, %d failed, %d skipped\n", passed, failed, skipped);
    return failed ? 1 : 0;
}
