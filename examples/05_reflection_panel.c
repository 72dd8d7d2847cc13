/* Seed 003's Fig. 7 and 8 with sfb_surface_analyze: reflection lines of an area light on a
 * Catmull-Clark surface with extraordinary vertices and creases, from proxies subdivided once,
 * twice and three times (columns). Top row: the polygon-based method (the proxy's interpolated
 * limit normals, as every renderer does); bottom row: every pixel projected onto the exact limit
 * surface and shaded from its exact normal. The bottom row does not change with the proxy; the
 * top row does. Also a close-up (Fig. 8: polygon-based and exact, level 3) and a mean-curvature
 * map. Prints how many pixels keep their stripe class between levels 1 and 3 for each method;
 * exit status 1 when the exact one is below 99.5 % or not better than the polygon-based one.
 *   05_reflection_panel [--mesh IN.obj] [OUT_DIR]
 * writes OUT_DIR/reflection_panel.png, reflection_closeup.png, curvature.png (no OUT_DIR:
 * measure only). The mesh defaults to examples/data/creased_box.obj.
 *   cc -std=c99 -I. examples/05_reflection_panel.c tools/impl.c -lm -lpthread -ldl
 * PNG output uses stb_image_write (Debian's libstb-dev, headers only). */
#include "surfblend.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb/stb_image_write.h>
#include "panel_font.h"

#define TILE_W 400
#define TILE_H 320

static char *read_file(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long n;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0 && (buf = (char *)malloc((size_t)n + 1)) != NULL) {
        if (fread(buf, 1, (size_t)n, f) != (size_t)n) { free(buf); buf = NULL; }
        else *size = (size_t)n;
    }
    fclose(f);
    return buf;
}

/* One picture of the surface; 0 with a message on failure. */
static int analyze(const sfb_surface *s, int level, int polygon, int mode, float zoom, int w, int h, sfb_analysis *out) {
    /* the close-up (zoom > 1) looks down onto the top, where the reflected stripes are */
    sfb_analyze_config c = sfb_analyze_config_init(mode);
    c.width = w;
    c.height = h;
    c.level = level;
    c.polygon_based = polygon;
    c.view_set = 1;
    c.yaw = 35.0f;
    c.pitch = zoom > 1.0f ? 50.0f : 30.0f;
    c.zoom = zoom;
    c.curvature = SFB_CURVATURE_MEAN;
    return sfb_surface_analyze(s, &c, out) == SFB_SUCCESS;
}

/* Share of the pixels both pictures cover whose classes agree. */
static double agreement(const sfb_analysis *a, const sfb_analysis *b) {
    long k, n = (long)a->width * a->height, both = 0, same = 0;
    for (k = 0; k < n; ++k)
        if (a->classes[k] && b->classes[k]) { ++both; same += a->classes[k] == b->classes[k]; }
    return both ? (double)same / both : 0.0;
}

static void blit(unsigned char *dst, int dw, int x0, int y0, const sfb_analysis *a) {
    int y;
    for (y = 0; y < a->height; ++y)
        memcpy(dst + 4 * ((size_t)(y0 + y) * (size_t)dw + (size_t)x0), a->rgba + 4 * (size_t)y * (size_t)a->width, 4 * (size_t)a->width);
}

/* Writes under a temporary name and renames it when complete: no partial file. */
static int write_png(const char *dir, const char *name, int w, int h, const unsigned char *rgba) {
    char path[4096], tmp[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    snprintf(tmp, sizeof tmp, "%s.part", path);
    if (!stbi_write_png(tmp, w, h, 4, rgba, w * 4) || rename(tmp, path) != 0) {
        fprintf(stderr, "05_reflection_panel: cannot write %s\n", path);
        remove(tmp);
        return 0;
    }
    printf("wrote %s (%dx%d)\n", path, w, h);
    return 1;
}

static void usage(FILE *f) {
    fprintf(f, "usage: 05_reflection_panel [--mesh IN.obj] [OUT_DIR]\n"
               "  Seed 003's Fig. 7: reflection lines from proxies subdivided 1, 2, 3 times (columns), polygon-based\n"
               "  (top) and exact per pixel (bottom) -> OUT_DIR/reflection_panel.png; a close-up of both (Fig. 8)\n"
               "  -> reflection_closeup.png; the mean curvature -> curvature.png. Without OUT_DIR it only measures.\n"
               "  Exit status 1 when the exact pictures change with the proxy (under 99.5 %% of pixels keep\n"
               "  their stripe class) or do not beat the polygon-based ones.\n");
}

int main(int argc, char **argv) {
    const char *mesh_path = "examples/data/creased_box.obj", *outdir = NULL;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 0);
    sfb_analysis tiles[2][3], close[2], curv;
    unsigned char *panel = NULL;
    char *text;
    size_t size = 0;
    int i, row, col, status = 1, ok = 1;
    double exact_agree, poly_agree;
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) { usage(stdout); return 0; }
        if (!strcmp(argv[i], "--mesh") && i + 1 < argc) mesh_path = argv[++i];
        else if (argv[i][0] != '-' && !outdir) outdir = argv[i];
        else { usage(stderr); return 2; }
    }
    memset(tiles, 0, sizeof tiles);
    memset(close, 0, sizeof close);
    memset(&curv, 0, sizeof curv);
    text = read_file(mesh_path, &size);
    if (!text) { fprintf(stderr, "05_reflection_panel: cannot read %s\n", mesh_path); return 1; }
    sc.flags = SFB_REFINE_PATCHES;
    if (sfb_context_create(NULL, &ctx) != SFB_SUCCESS) { fprintf(stderr, "05_reflection_panel: no context\n"); free(text); return 1; }
    if (sfb_mesh_read_obj(ctx, text, size, &mesh) != SFB_SUCCESS || sfb_surface_create(ctx, mesh, &sc, &surf) != SFB_SUCCESS) {
        fprintf(stderr, "05_reflection_panel: %s: %s\n", mesh_path, sfb_last_error(ctx));
        goto done;
    }
    for (row = 0; row < 2 && ok; ++row)
        for (col = 0; col < 3 && ok; ++col) ok = analyze(surf, col + 1, row == 0, SFB_ANALYZE_REFLECTION, 0.0f, TILE_W, TILE_H, &tiles[row][col]);
    for (i = 0; i < 2 && ok; ++i) ok = analyze(surf, 3, i == 0, SFB_ANALYZE_REFLECTION, 2.2f, TILE_W, TILE_H, &close[i]);
    if (ok) ok = analyze(surf, 1, 0, SFB_ANALYZE_CURVATURE, 0.0f, 2 * TILE_W, 2 * TILE_H, &curv);
    if (!ok) { fprintf(stderr, "05_reflection_panel: %s\n", sfb_last_error(ctx)); goto done; }
    poly_agree = agreement(&tiles[0][0], &tiles[0][2]);
    exact_agree = agreement(&tiles[1][0], &tiles[1][2]);
    printf("reflection lines of %s (backend %s), %dx%d: pixels keeping their stripe class from a level-1 to a level-3 proxy:\n"
           "  polygon-based %.2f %%, exact per pixel %.2f %% (level 1: %d pixels on the exact surface, the proxy covered %d)\n"
           "  mean curvature %.3g .. %.3g (colour map +-%.3g)\n",
           mesh_path, sfb_context_backend_name(ctx), TILE_W, TILE_H, 100.0 * poly_agree, 100.0 * exact_agree, tiles[1][0].covered_pixels,
           tiles[1][0].proxy_pixels, (double)curv.value_min, (double)curv.value_max, (double)curv.range);
    if (!(exact_agree >= 0.995) || !(exact_agree > poly_agree)) {
        printf("  FAILED: the exact pictures should not depend on the proxy\n");
        goto done;
    }
    status = 0;
    if (outdir) {
        const int W = 3 * TILE_W, H = 2 * TILE_H;
        panel = (unsigned char *)calloc((size_t)W * (size_t)H, 4);
        if (!panel) { fprintf(stderr, "05_reflection_panel: out of memory\n"); status = 1; goto done; }
        for (row = 0; row < 2; ++row)
            for (col = 0; col < 3; ++col) {
                char label[64];
                blit(panel, W, col * TILE_W, row * TILE_H, &tiles[row][col]);
                snprintf(label, sizeof label, "%s - level %d", row == 0 ? "polygon" : "exact", col + 1);
                panel_draw_text(panel, W, H, col * TILE_W + 8, row * TILE_H + 8, label);
            }
        if (!write_png(outdir, "reflection_panel.png", W, H, panel)) status = 1;
        memset(panel, 0, (size_t)W * (size_t)H * 4);
        for (i = 0; i < 2; ++i) {
            blit(panel, W, i * TILE_W, 0, &close[i]);
            panel_draw_text(panel, W, H, i * TILE_W + 8, 8, i == 0 ? "polygon - level 3" : "exact - level 3");
        }
        if (status == 0) {
            /* the close-up occupies the first 2 * TILE_W columns of the first TILE_H rows: copy them out */
            unsigned char *cl = (unsigned char *)malloc((size_t)2 * TILE_W * TILE_H * 4);
            if (!cl) status = 1;
            else {
                for (i = 0; i < TILE_H; ++i) memcpy(cl + 4 * (size_t)i * 2 * TILE_W, panel + 4 * (size_t)i * W, 4 * (size_t)2 * TILE_W);
                if (!write_png(outdir, "reflection_closeup.png", 2 * TILE_W, TILE_H, cl)) status = 1;
                free(cl);
            }
        }
        panel_draw_text(curv.rgba, curv.width, curv.height, 8, 8, "mean curvature - exact - level 1");
        if (status == 0 && !write_png(outdir, "curvature.png", curv.width, curv.height, curv.rgba)) status = 1;
    }
done:
    for (row = 0; row < 2; ++row)
        for (col = 0; col < 3; ++col) sfb_analysis_free(&tiles[row][col]);
    sfb_analysis_free(&close[0]);
    sfb_analysis_free(&close[1]);
    sfb_analysis_free(&curv);
    free(panel);
    free(text);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return status;
}
