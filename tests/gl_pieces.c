/* The gl kernels' splitting paths, for real: this program compiles the library with a tiny
 * shader-storage block limit (8 KiB) and 2 work groups per dispatch, so a level-3 table is cut
 * into several pieces and each piece into several dispatches. gl and osmesa must still agree with
 * ref, and a buffer over the limit must come back as SFB_LIMIT_EXCEEDED with the sizes named.
 * Prints PASS/FAIL/SKIP lines and "N passed, N failed, N skipped" (tests/harness.h). */
#define SURFBLEND_IMPLEMENTATION
#define SURFBLEND_GL
#define SURFBLEND_OSMESA
#define SFB__GL_TEST_MAX_BLOCK 8192
#define SFB__GL_TEST_MAX_GROUPS 2
#include "surfblend.h"
#include "harness.h"
#include <math.h>

static int last_entries; /* entries of the last VERTEX table built */

/* a cube with semi-sharp top edges and a corner */
static const float cube_pos[8 * 3] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
static const int cube_sizes[6] = {4, 4, 4, 4, 4, 4};
static const int cube_faces[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
static const int cube_creases[8] = {4, 5, 5, 6, 6, 7, 7, 4};
static const float cube_sharp[4] = {2, 2.5f, 1, 10};
static const int cube_corner[1] = {0};
static const float cube_corner_sharp[1] = {3};

/* Refines the cube to `level` on `kind`; fills out[] with VERTEX then LIMIT rows (xyz). */
static sfb_result run(sfb_backend_kind kind, int level, float **out, int *rows, char *err, size_t err_size) {
    sfb_context_config cfg = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_mesh_desc d;
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, level);
    sfb_stencil_info si = {0, 0, 0};
    sfb_buffer_desc bd = {0, 3, 3};
    sfb_result r;
    memset(&d, 0, sizeof d);
    d.vertex_count = 8; d.positions = cube_pos;
    d.face_count = 6; d.face_sizes = cube_sizes; d.face_vertices = cube_faces;
    d.crease_count = 4; d.crease_vertices = cube_creases; d.crease_sharpness = cube_sharp;
    d.corner_count = 1; d.corner_vertices = cube_corner; d.corner_sharpness = cube_corner_sharp;
    cfg.backends = &kind; cfg.backend_count = 1; cfg.ignore_environment = 1;
    *out = NULL;
    err[0] = 0;
    if ((r = sfb_context_create(&cfg, &ctx)) != SFB_SUCCESS) { snprintf(err, err_size, "no context"); return r; }
    sc.flags = SFB_REFINE_LIMIT;
    if ((r = sfb_mesh_create(ctx, &d, &mesh)) == SFB_SUCCESS && (r = sfb_surface_create(ctx, mesh, &sc, &surf)) == SFB_SUCCESS) {
        sfb_surface_stencil_info(surf, SFB_TABLE_VERTEX, &si);
        *rows = si.rows;
        last_entries = si.entries;
        *out = (float *)calloc((size_t)si.rows * 6, sizeof(float));
        r = sfb_surface_eval_stencils(surf, SFB_TABLE_VERTEX, cube_pos, bd, *out, bd);
        if (r == SFB_SUCCESS) r = sfb_surface_eval_stencils(surf, SFB_TABLE_LIMIT, cube_pos, bd, *out + (size_t)si.rows * 3, bd);
    }
    if (r != SFB_SUCCESS) snprintf(err, err_size, "%s", sfb_last_error(ctx));
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return r;
}

int main(void) {
    static const sfb_backend_kind kinds[2] = {SFB_BACKEND_GL, SFB_BACKEND_OSMESA};
    float *ref = NULL, *got = NULL;
    int ref_rows = 0, rows = 0, k, i;
    char err[1024], info[512], name3[96], name4[96];
    if (run(SFB_BACKEND_REF, 3, &ref, &ref_rows, err, sizeof err) != SFB_SUCCESS) {
        fail("ref refinement", "%s", err);
        return close_tests();
    }
    /* the point of the test: the table must need more than one piece of 2048 entries */
    snprintf(name3, sizeof name3, "level-3 table has %d entries", last_entries);
    check(last_entries > 2048, name3, "no split to test (at most 2048: one piece)");
    for (k = 0; k < 2; ++k) {
        const char *name = sfb_backend_kind_name(kinds[k]);
        sfb_result r;
        double worst = 0;
        snprintf(name3, sizeof name3, "%s level 3 in pieces", name);
        snprintf(name4, sizeof name4, "%s buffer over the block limit", name);
        if (sfb_backend_probe(kinds[k], NULL, info, sizeof info) != SFB_SUCCESS) {
            char why[600];
            snprintf(why, sizeof why, "%s unavailable: %s", name, info);
            unavailable(name3, backend_required(name), why);
            unavailable(name4, backend_required(name), why);
            continue;
        }
        /* level 3: 386 rows in several pieces of at most 2048 entries, 128 rows per dispatch */
        r = run(kinds[k], 3, &got, &rows, err, sizeof err);
        if (r != SFB_SUCCESS || rows != ref_rows) {
            fail(name3, "%s (%s)", sfb_result_string(r), err);
        } else {
            for (i = 0; i < rows * 6; ++i) if (fabs((double)got[i] - ref[i]) > worst) worst = fabs((double)got[i] - ref[i]);
            /* tolerance: 1e-5 x the cube's diagonal (2 sqrt 3) */
            printf("# %s agrees with ref to %.3g\n", name3, worst);
            check(worst <= 1e-5 * 3.4641, name3, "differs from ref by %.3g", worst);
        }
        free(got);
        /* level 4: 1538 rows x 12 bytes of results is over the 8 KiB block */
        r = run(kinds[k], 4, &got, &rows, err, sizeof err);
        if (r == SFB_LIMIT_EXCEEDED && strstr(err, "GL_MAX_SHADER_STORAGE_BLOCK_SIZE")) printf("# %s is refused: %s\n", name4, err);
        check(r == SFB_LIMIT_EXCEEDED && strstr(err, "GL_MAX_SHADER_STORAGE_BLOCK_SIZE") != NULL, name4, "%s (%s)", sfb_result_string(r), err);
        free(got);
    }
    free(ref);
    return close_tests();
}
