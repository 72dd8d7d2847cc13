/* 01_minimal: build a mesh from arrays, refine it twice with Catmull-Clark on the default
 * backend, and print a few refined and limit points.
 *   cc -std=c99 -I. examples/01_minimal.c tools/impl.c -lm -lpthread -ldl */
#include "surfblend.h"
#include <stdio.h>

int main(void) {
    /* a cube whose top four edges are semi-sharp (sharpness 2) */
    static const float positions[8 * 3] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1,
                                           -1, -1, 1,  1, -1, 1,  1, 1, 1,  -1, 1, 1};
    static const int sizes[6] = {4, 4, 4, 4, 4, 4};
    static const int faces[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
    static const int creases[8] = {4, 5, 5, 6, 6, 7, 7, 4};
    static const float sharpness[4] = {2, 2, 2, 2};
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surface = NULL;
    sfb_mesh_desc desc = {0};
    sfb_surface_config cfg;
    sfb_mesh_data out;
    sfb_result r;
    int i;

    if (sfb_context_create(NULL, &ctx) != SFB_SUCCESS) return 1;
    desc.vertex_count = 8; desc.positions = positions;
    desc.face_count = 6; desc.face_sizes = sizes; desc.face_vertices = faces;
    desc.crease_count = 4; desc.crease_vertices = creases; desc.crease_sharpness = sharpness;
    r = sfb_mesh_create(ctx, &desc, &mesh);
    if (r != SFB_SUCCESS) { fprintf(stderr, "mesh: %s\n", sfb_last_error(ctx)); return 1; }

    cfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, 2);
    cfg.flags = SFB_REFINE_LIMIT;
    r = sfb_surface_create(ctx, mesh, &cfg, &surface);
    if (r == SFB_SUCCESS) r = sfb_surface_refine(surface, &out);
    if (r != SFB_SUCCESS) { fprintf(stderr, "refine: %s\n", sfb_last_error(ctx)); return 1; }

    printf("backend %s: %d vertices, %d faces after 2 levels\n", sfb_context_backend_name(ctx), out.vertex_count, out.face_count);
    for (i = 0; i < 8; ++i) /* refined vertices 0..7 are the children of the cube's corners */
        printf("corner %d: refined (%.4f %.4f %.4f) limit (%.4f %.4f %.4f) normal (%.3f %.3f %.3f)\n", i,
               out.positions[3 * i], out.positions[3 * i + 1], out.positions[3 * i + 2],
               out.limit_positions[3 * i], out.limit_positions[3 * i + 1], out.limit_positions[3 * i + 2],
               out.normals[3 * i], out.normals[3 * i + 1], out.normals[3 * i + 2]);
    sfb_mesh_data_free(&out);
    sfb_surface_destroy(surface);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return 0;
}
