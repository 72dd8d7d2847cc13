/* surfblend: software pictures (sfb_render): coverage inside and background outside, each
 * mode's colours (weights blue/red, normals as RGB, highlight bands on curved surfaces and
 * none on a plane with the light at infinity), the edge overlay (polygon edges, not fan
 * diagonals), holes, non-finite positions, views, argument checks with nothing allocated,
 * the memory budget, cancellation at every progress report and allocation failure at every
 * allocation without leaks, and pictures of sfb_surface_shade's output. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

/* ------------------------------------------------------------------------- */
/* meshes and helpers                                                         */

static const char *rn_cube_obj =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n";

/* the unit square in the xy plane (z = 0), facing +z */
static float rn_quad_pos[] = { -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0 };
static int rn_quad_sizes[] = { 4 };
static int rn_quad_fv[] = { 0, 1, 2, 3 };

/* a sfb_mesh_data view of caller arrays (no ctx_: never passed to sfb_mesh_data_free) */
static sfb_mesh_data rn_view(int nv, float *pos, int nf, int *sizes, int *fv)
{
    sfb_mesh_data m;
    memset(&m, 0, sizeof m);
    m.vertex_count = nv;
    m.positions = pos;
    m.face_count = nf;
    m.face_sizes = sizes;
    m.face_vertices = fv;
    for (int f = 0; f < nf; ++f) m.face_vertex_count += sizes[f];
    return m;
}

static sfb_context *rn_ctx(void)
{
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    return ctx;
}

/* The refined (level) mesh of `obj` with limit positions and normals. */
static sfb_mesh_data rn_refined(sfb_context *ctx, const char *obj, sfb_scheme scheme, int level)
{
    sfb_mesh *m = NULL;
    cr_assert_eq(sfb_mesh_read_obj(ctx, obj, strlen(obj), &m), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_surface_config sc = sfb_surface_config_init(scheme, level);
    sc.flags = SFB_REFINE_LIMIT;
    sfb_surface *s = NULL;
    cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_mesh_data d;
    cr_assert_eq(sfb_surface_refine(s, &d), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    return d;
}

static const unsigned char rn_bg[4] = { 1, 2, 3, 255 };

static int rn_is_bg(const sfb_image *img, int x, int y)
{
    const unsigned char *p = img->rgba + 4 * ((size_t)y * img->width + x);
    return p[0] == rn_bg[0] && p[1] == rn_bg[1] && p[2] == rn_bg[2] && p[3] == rn_bg[3];
}

static const unsigned char *rn_px(const sfb_image *img, int x, int y)
{
    return img->rgba + 4 * ((size_t)y * img->width + x);
}

static sfb_render_config rn_config(int mode, int w, int h)
{
    sfb_render_config c = sfb_render_config_init(mode);
    c.width = w;
    c.height = h;
    memcpy(c.background, rn_bg, 4);
    return c;
}

static sfb_image rn_render_ok(sfb_context *ctx, const sfb_mesh_data *m, const sfb_render_config *c)
{
    sfb_image img;
    sfb_result r = sfb_render(ctx, m, c, &img);
    cr_assert_eq(r, SFB_SUCCESS, "render: %s: %s", sfb_result_string(r), sfb_last_error(ctx));
    cr_assert_not_null(img.rgba);
    cr_assert_eq(img.width, c && c->width ? c->width : 640);
    cr_assert_eq(img.height, c && c->height ? c->height : 480);
    return img;
}

static long rn_count_object(const sfb_image *img)
{
    long n = 0;
    for (int y = 0; y < img->height; ++y)
        for (int x = 0; x < img->width; ++x) n += !rn_is_bg(img, x, y);
    return n;
}

/* ------------------------------------------------------------------------- */
/* pictures                                                                   */

Test(render, config_init_and_free_of_empty)
{
    sfb_render_config c = sfb_render_config_init(SFB_RENDER_WEIGHTS);
    cr_expect_eq(c.mode, SFB_RENDER_WEIGHTS);
    cr_expect_eq(c.width, 0);
    cr_expect_null(c.positions);
    cr_expect_eq(c.zoom, 0.0f);
    sfb_image img;
    memset(&img, 0, sizeof img);
    sfb_image_free(&img);
    sfb_image_free(NULL);
}

Test(render, refined_cube_covers_the_middle_not_the_corners)
{
    sfb_context *ctx = rn_ctx();
    sfb_mesh_data d = rn_refined(ctx, rn_cube_obj, SFB_SCHEME_CATMARK, 3);
    for (int mode = SFB_RENDER_SHADED; mode <= SFB_RENDER_NORMALS; ++mode) {
        sfb_render_config c = rn_config(mode, 160, 120);
        c.positions = d.limit_positions;
        float *s = malloc((size_t)d.vertex_count * sizeof(float));
        for (int i = 0; i < d.vertex_count; ++i) s[i] = 0.5f;
        c.scalars = s;
        sfb_image img = rn_render_ok(ctx, &d, &c);
        cr_expect(!rn_is_bg(&img, 80, 60), "mode %d: the middle is the object", mode);
        cr_expect(rn_is_bg(&img, 0, 0) && rn_is_bg(&img, 159, 0) && rn_is_bg(&img, 0, 119) && rn_is_bg(&img, 159, 119),
                  "mode %d: the corners are background", mode);
        long n = rn_count_object(&img);
        cr_expect_eq(n, img.object_pixels, "mode %d: object_pixels %d, counted %ld", mode, img.object_pixels, n);
        /* a sphere-like blob fitted to 92% of the smaller side: roughly a disc of radius 40..55 */
        cr_expect(n > 3000 && n < 120 * 120, "mode %d: %ld object pixels", mode, n);
        cr_expect_eq(img.skipped_faces, 0);
        for (long i = 0; i < 160L * 120; ++i) cr_assert_eq(img.rgba[4 * i + 3], 255, "opaque");
        sfb_image_free(&img);
        cr_expect_null(img.rgba);
        free(s);
    }
    sfb_mesh_data_free(&d);
    sfb_context_destroy(ctx);
}

Test(render, defaults_and_null_config)
{
    sfb_context *ctx = rn_ctx();
    sfb_mesh_data d = rn_refined(ctx, rn_cube_obj, SFB_SCHEME_CATMARK, 1);
    sfb_image img;
    cr_assert_eq(sfb_render(ctx, &d, NULL, &img), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    cr_expect_eq(img.width, 640);
    cr_expect_eq(img.height, 480);
    /* the default background is an opaque dark grey */
    const unsigned char *p = rn_px(&img, 0, 0);
    cr_expect(p[3] == 255 && p[0] < 100 && p[0] == rn_px(&img, 639, 479)[0]);
    cr_expect_gt(img.object_pixels, 1000);
    sfb_image_free(&img);
    sfb_mesh_data_free(&d);
    sfb_context_destroy(ctx);
}

Test(render, weights_one_is_red_zero_is_blue)
{
    sfb_context *ctx = rn_ctx();
    sfb_mesh_data d = rn_refined(ctx, rn_cube_obj, SFB_SCHEME_CATMARK, 2);
    float *w = malloc((size_t)d.vertex_count * sizeof(float));
    for (int k = 0; k < 2; ++k) {
        for (int i = 0; i < d.vertex_count; ++i) w[i] = (float)k;
        /* by default the scalars are the mesh's blend weights */
        d.blend_weights = w;
        sfb_render_config c = rn_config(SFB_RENDER_WEIGHTS, 120, 120);
        sfb_image img = rn_render_ok(ctx, &d, &c);
        long red = 0, blue = 0, n = 0;
        for (int y = 0; y < 120; ++y)
            for (int x = 0; x < 120; ++x) {
                if (rn_is_bg(&img, x, y)) continue;
                const unsigned char *p = rn_px(&img, x, y);
                ++n;
                red += p[0] > p[2] + 40;
                blue += p[2] > p[0] + 40;
            }
        cr_assert_gt(n, 0);
        if (k == 1) cr_expect_eq(red, n, "weight 1: %ld of %ld pixels red-dominant", red, n);
        else cr_expect_eq(blue, n, "weight 0: %ld of %ld pixels blue-dominant", blue, n);
        sfb_image_free(&img);
    }
    d.blend_weights = NULL;
    free(w);
    sfb_mesh_data_free(&d);
    sfb_context_destroy(ctx);
}

/* The stripe colour classes along the middle row: how often the class changes (grey,
 * blue, cyan by the dominant channel). */
static int rn_band_changes(const sfb_image *img, int y)
{
    int changes = 0, last = -1;
    for (int x = 0; x < img->width; ++x) {
        if (rn_is_bg(img, x, y)) continue;
        const unsigned char *p = rn_px(img, x, y);
        int cls = p[2] > p[0] + 60 ? (p[1] > p[0] + 60 ? 2 : 1) : 0;
        if (last >= 0 && cls != last) ++changes;
        last = cls;
    }
    return changes;
}

Test(render, highlight_bands_on_curved_surfaces_none_on_a_plane_at_infinity)
{
    sfb_context *ctx = rn_ctx();
    /* a plane facing the camera, one constant normal: with the light plane at infinity the
     * stripe depends on the normal alone, so one colour */
    sfb_mesh_data q = rn_view(4, rn_quad_pos, 1, rn_quad_sizes, rn_quad_fv);
    float nrm[12];
    for (int i = 0; i < 4; ++i) { nrm[3 * i] = 0.0f; nrm[3 * i + 1] = 0.0f; nrm[3 * i + 2] = 1.0f; }
    sfb_render_config c = rn_config(SFB_RENDER_HIGHLIGHT, 200, 200);
    c.normals = nrm;
    c.view_set = 1;
    c.light_at_infinity = 1;
    sfb_image img = rn_render_ok(ctx, &q, &c);
    const unsigned char *first = NULL;
    long differ = 0;
    for (int y = 0; y < 200; ++y)
        for (int x = 0; x < 200; ++x) {
            if (rn_is_bg(&img, x, y)) continue;
            const unsigned char *p = rn_px(&img, x, y);
            if (!first) first = p;
            else differ += memcmp(p, first, 3) != 0;
        }
    cr_assert_not_null(first);
    cr_expect_eq(differ, 0, "%ld pixels of the plane differ", differ);
    sfb_image_free(&img);
    /* the same plane with the light plane at a finite distance: straight parallel lines, some */
    c.light_at_infinity = 0;
    img = rn_render_ok(ctx, &q, &c);
    int plane_changes = rn_band_changes(&img, 100);
    cr_expect_gt(plane_changes, 0);
    sfb_image_free(&img);
    /* a curved surface: several bands across the middle, more than the plane has */
    sfb_mesh_data d = rn_refined(ctx, rn_cube_obj, SFB_SCHEME_CATMARK, 3);
    c = rn_config(SFB_RENDER_HIGHLIGHT, 200, 200);
    c.positions = d.limit_positions;
    img = rn_render_ok(ctx, &d, &c);
    int curved = rn_band_changes(&img, 100);
    cr_expect_geq(curved, 6, "%d band changes on the curved surface", curved);
    cr_expect_gt(curved, plane_changes);
    sfb_image_free(&img);
    c.light_at_infinity = 1;
    img = rn_render_ok(ctx, &d, &c);
    cr_expect_geq(rn_band_changes(&img, 100), 4, "bands with the light at infinity too");
    sfb_image_free(&img);
    sfb_mesh_data_free(&d);
    sfb_context_destroy(ctx);
}

Test(render, highlight_compares_normal_fields_under_one_view)
{
    sfb_context *ctx = rn_ctx();
    sfb_mesh_data d = rn_refined(ctx, rn_cube_obj, SFB_SCHEME_CATMARK, 3);
    sfb_render_config c = rn_config(SFB_RENDER_HIGHLIGHT, 160, 120);
    c.positions = d.limit_positions;
    sfb_image a = rn_render_ok(ctx, &d, &c);
    sfb_image b = rn_render_ok(ctx, &d, &c);
    cr_expect_eq(memcmp(a.rgba, b.rgba, 160 * 120 * 4), 0, "deterministic");
    sfb_image_free(&b);
    /* other normals (a small tilt), same positions and view: same silhouette, other stripes */
    float *n2 = malloc((size_t)d.vertex_count * 3 * sizeof(float));
    for (int i = 0; i < d.vertex_count; ++i) {
        n2[3 * i] = d.normals[3 * i] + 0.15f;
        n2[3 * i + 1] = d.normals[3 * i + 1];
        n2[3 * i + 2] = d.normals[3 * i + 2];
    }
    c.normals = n2;
    b = rn_render_ok(ctx, &d, &c);
    long differ = 0, silhouette = 0;
    for (int y = 0; y < 120; ++y)
        for (int x = 0; x < 160; ++x) {
            silhouette += rn_is_bg(&a, x, y) != rn_is_bg(&b, x, y);
            differ += memcmp(rn_px(&a, x, y), rn_px(&b, x, y), 3) != 0;
        }
    cr_expect_eq(silhouette, 0);
    cr_expect_gt(differ, 200, "%ld pixels differ", differ);
    cr_expect_eq(a.object_pixels, b.object_pixels);
    sfb_image_free(&a);
    sfb_image_free(&b);
    free(n2);
    sfb_mesh_data_free(&d);
    sfb_context_destroy(ctx);
}

Test(render, normals_as_rgb_and_flat_normals)
{
    sfb_context *ctx = rn_ctx();
    sfb_mesh_data q = rn_view(4, rn_quad_pos, 1, rn_quad_sizes, rn_quad_fv);
    sfb_render_config c = rn_config(SFB_RENDER_NORMALS, 64, 64);
    c.view_set = 1; /* yaw 0, pitch 0: looking down -z at the square */
    /* no normals anywhere: the polygon's own normal, +z */
    sfb_image img = rn_render_ok(ctx, &q, &c);
    const unsigned char *p = rn_px(&img, 32, 32);
    cr_expect(abs(p[0] - 128) <= 2 && abs(p[1] - 128) <= 2 && p[2] >= 250, "flat +z normal: %d %d %d", p[0], p[1], p[2]);
    sfb_image_free(&img);
    /* given normals, +x everywhere: red */
    float nrm[12];
    for (int i = 0; i < 4; ++i) { nrm[3 * i] = 2.0f; nrm[3 * i + 1] = 0.0f; nrm[3 * i + 2] = 0.0f; }
    c.normals = nrm;
    img = rn_render_ok(ctx, &q, &c);
    p = rn_px(&img, 32, 32);
    cr_expect(p[0] >= 250 && abs(p[1] - 128) <= 2 && abs(p[2] - 128) <= 2, "+x normal: %d %d %d", p[0], p[1], p[2]);
    sfb_image_free(&img);
    /* zero and non-finite normals fall back to the flat normal */
    for (int i = 0; i < 12; ++i) nrm[i] = i < 6 ? 0.0f : NAN;
    img = rn_render_ok(ctx, &q, &c);
    p = rn_px(&img, 32, 32);
    cr_expect(p[2] >= 250, "fallback normal: %d %d %d", p[0], p[1], p[2]);
    sfb_image_free(&img);
    sfb_context_destroy(ctx);
}

Test(render, two_sided_lighting_lights_the_back)
{
    sfb_context *ctx = rn_ctx();
    sfb_mesh_data q = rn_view(4, rn_quad_pos, 1, rn_quad_sizes, rn_quad_fv);
    sfb_render_config c = rn_config(SFB_RENDER_SHADED, 64, 64);
    c.view_set = 1;
    sfb_image front = rn_render_ok(ctx, &q, &c);
    c.yaw = 180.0f; /* from behind */
    sfb_image back = rn_render_ok(ctx, &q, &c);
    const unsigned char *a = rn_px(&front, 32, 32), *b = rn_px(&back, 32, 32);
    cr_expect_gt(a[0], 60);
    cr_expect(abs(a[0] - b[0]) <= 2, "front %d, back %d", a[0], b[0]);
    cr_expect_eq(front.object_pixels, back.object_pixels);
    sfb_image_free(&front);
    sfb_image_free(&back);
    sfb_context_destroy(ctx);
}

Test(render, orthographic_square_is_centred_and_zoom_grows_it)
{
    sfb_context *ctx = rn_ctx();
    sfb_mesh_data q = rn_view(4, rn_quad_pos, 1, rn_quad_sizes, rn_quad_fv);
    sfb_render_config c = rn_config(SFB_RENDER_SHADED, 100, 100);
    c.view_set = 1;
    c.orthographic = 1;
    sfb_image img = rn_render_ok(ctx, &q, &c);
    /* the bounding sphere (radius sqrt 2) fills 92% of 100 pixels: the square's half side is
     * 46 / sqrt 2 = 32.5 pixels */
    int minx = 100, maxx = -1, miny = 100, maxy = -1;
    for (int y = 0; y < 100; ++y)
        for (int x = 0; x < 100; ++x)
            if (!rn_is_bg(&img, x, y)) {
                if (x < minx) minx = x;
                if (x > maxx) maxx = x;
                if (y < miny) miny = y;
                if (y > maxy) maxy = y;
            }
    cr_expect(minx == 100 - 1 - maxx && miny == 100 - 1 - maxy, "centred: x %d..%d, y %d..%d", minx, maxx, miny, maxy);
    cr_expect(abs((maxx - minx + 1) - 65) <= 1, "width %d", maxx - minx + 1);
    long n1 = img.object_pixels;
    sfb_image_free(&img);
    c.zoom = 1.4f;
    img = rn_render_ok(ctx, &q, &c);
    cr_expect_gt(img.object_pixels, n1 * 3 / 2);
    sfb_image_free(&img);
    /* in perspective the square is centred too */
    c.zoom = 0.0f;
    c.orthographic = 0;
    img = rn_render_ok(ctx, &q, &c);
    cr_expect(!rn_is_bg(&img, 50, 50) && rn_is_bg(&img, 5, 50) && rn_is_bg(&img, 94, 50));
    sfb_image_free(&img);
    sfb_context_destroy(ctx);
}

/* `up` turns the orbit: a 2 x 1 x 0.5 box with y up is the default picture with up = +y (bit for
 * bit), and the same box turned z-up, (x, y, z) -> (x, -z, y), seen about up = z is the y-up
 * picture (the lights follow the camera), which it is not about y; a non-finite up is refused. */
Test(render, up_turns_the_orbit)
{
    static int sizes[6] = { 4, 4, 4, 4, 4, 4 };
    static int fv[24] = { 0, 1, 3, 2, 4, 6, 7, 5, 0, 4, 5, 1, 2, 3, 7, 6, 0, 2, 6, 4, 1, 5, 7, 3 };
    float py[24], pz[24];
    for (int i = 0; i < 8; ++i) {
        const float x = (i & 1) ? 1.0f : -1.0f, y = (i & 2) ? 0.5f : -0.5f, z = (i & 4) ? 0.25f : -0.25f;
        py[3 * i] = x; py[3 * i + 1] = y; py[3 * i + 2] = z;
        pz[3 * i] = x; pz[3 * i + 1] = -z; pz[3 * i + 2] = y;
    }
    sfb_context *ctx = rn_ctx();
    sfb_mesh_data my = rn_view(8, py, 6, sizes, fv), mz = rn_view(8, pz, 6, sizes, fv);
    sfb_render_config c = rn_config(SFB_RENDER_SHADED, 160, 120);
    c.view_set = 1;
    c.yaw = 35.0f;
    c.pitch = 20.0f;
    sfb_image a = rn_render_ok(ctx, &my, &c);
    c.up[1] = 1.0f;
    sfb_image b = rn_render_ok(ctx, &my, &c);
    cr_expect(memcmp(a.rgba, b.rgba, (size_t)160 * 120 * 4) == 0, "up = +y is the default view");
    sfb_image_free(&b);
    long n = 160 * 120, same[2] = { 0, 0 }, cov[2] = { 0, 0 };
    for (int k = 0; k < 2; ++k) {
        c.up[0] = 0.0f; c.up[1] = k ? 1.0f : 0.0f; c.up[2] = k ? 0.0f : 1.0f;
        sfb_image z = rn_render_ok(ctx, &mz, &c);
        for (long p = 0; p < n; ++p) {
            const unsigned char *pa = a.rgba + 4 * p, *pb = z.rgba + 4 * p;
            const int oa = pa[0] != rn_bg[0] || pa[1] != rn_bg[1] || pa[2] != rn_bg[2];
            const int ob = pb[0] != rn_bg[0] || pb[1] != rn_bg[1] || pb[2] != rn_bg[2];
            if (!oa && !ob) continue;
            ++cov[k];
            same[k] += oa && ob && abs(pa[0] - pb[0]) <= 2 && abs(pa[1] - pb[1]) <= 2 && abs(pa[2] - pb[2]) <= 2;
        }
        sfb_image_free(&z);
    }
    printf("# render up: the z-up box about z matches the y-up picture on %.3f %% of %ld pixels, about y on %.3f %%\n",
           100.0 * same[0] / (double)(cov[0] ? cov[0] : 1), cov[0], 100.0 * same[1] / (double)(cov[1] ? cov[1] : 1));
    cr_expect(cov[0] > 2000 && same[0] >= 0.995 * cov[0], "about z: %ld of %ld pixels the same", same[0], cov[0]);
    cr_expect(same[1] < 0.9 * cov[1], "about y the z-up box is seen otherwise: %ld of %ld pixels the same", same[1], cov[1]);
    sfb_image_free(&a);
    c.up[0] = 0.0f; c.up[1] = NAN; c.up[2] = 0.0f;
    sfb_image bad;
    cr_expect_eq(sfb_render(ctx, &my, &c, &bad), SFB_INVALID_ARGS);
    cr_expect_null(bad.rgba);
    cr_expect(strstr(sfb_last_error(ctx), "up direction") != NULL, "%s", sfb_last_error(ctx));
    sfb_context_destroy(ctx);
}

Test(render, edges_overlay_draws_polygon_sides_not_diagonals)
{
    sfb_context *ctx = rn_ctx();
    /* two quads side by side: x in [-2,0] and [0,2] */
    float pos[] = { -2, -1, 0, 0, -1, 0, 2, -1, 0, -2, 1, 0, 0, 1, 0, 2, 1, 0 };
    int sizes[] = { 4, 4 }, fv[] = { 0, 1, 4, 3, 1, 2, 5, 4 };
    sfb_mesh_data m = rn_view(6, pos, 2, sizes, fv);
    sfb_render_config c = rn_config(SFB_RENDER_SHADED, 200, 200);
    c.view_set = 1;
    c.orthographic = 1;
    sfb_image plain = rn_render_ok(ctx, &m, &c);
    c.draw_edges = 1;
    sfb_image edged = rn_render_ok(ctx, &m, &c);
    /* the shared side x = 0 is the picture's middle column (pixels 99 and 100 straddle it) */
    const unsigned char *a = rn_px(&plain, 99, 100), *b = rn_px(&edged, 99, 100);
    cr_expect_lt(b[0] + 40, a[0], "the shared side is dark: %d vs %d", b[0], a[0]);
    /* the fan diagonal of the left quad, from (-2,-1) to (0,1), crosses the middle row at its
     * centre (-1, 0): about pixel 59 (41 pixels per unit) */
    long darker = 0;
    for (int x = 45; x < 80; ++x) darker += rn_px(&edged, x, 100)[0] + 20 < rn_px(&plain, x, 100)[0];
    cr_expect_eq(darker, 0, "%ld pixels darkened along the middle row of the left quad (a diagonal drawn?)", darker);
    sfb_image_free(&plain);
    sfb_image_free(&edged);
    sfb_context_destroy(ctx);
}

Test(render, holes_and_non_finite_positions_are_not_drawn)
{
    sfb_context *ctx = rn_ctx();
    float pos[] = { -2, -1, 0, 0, -1, 0, 2, -1, 0, -2, 1, 0, 0, 1, 0, 2, 1, 0, NAN, 0, 0 };
    int sizes[] = { 4, 4, 3 }, fv[] = { 0, 1, 4, 3, 1, 2, 5, 4, 4, 5, 6 };
    sfb_mesh_data m = rn_view(7, pos, 3, sizes, fv);
    sfb_render_config c = rn_config(SFB_RENDER_SHADED, 200, 200);
    c.view_set = 1;
    c.orthographic = 1;
    sfb_image all = rn_render_ok(ctx, &m, &c);
    cr_expect_eq(all.skipped_faces, 1, "the triangle with a NaN vertex is skipped");
    cr_expect(!rn_is_bg(&all, 50, 100) && !rn_is_bg(&all, 150, 100));
    int holes[] = { 0 };
    m.hole_count = 1;
    m.holes = holes;
    sfb_image holed = rn_render_ok(ctx, &m, &c);
    cr_expect(rn_is_bg(&holed, 50, 100), "the hole is not drawn");
    cr_expect(!rn_is_bg(&holed, 150, 100));
    cr_expect_lt(holed.object_pixels, all.object_pixels * 2 / 3);
    sfb_image_free(&all);
    sfb_image_free(&holed);
    /* every position non-finite: nothing to draw, still a picture */
    float nan_pos[] = { NAN, 0, 0, 0, INFINITY, 0, 0, 0, NAN };
    int tsz[] = { 3 }, tfv[] = { 0, 1, 2 };
    sfb_mesh_data t = rn_view(3, nan_pos, 1, tsz, tfv);
    sfb_image none = rn_render_ok(ctx, &t, &c);
    cr_expect_eq(none.object_pixels, 0);
    cr_expect_eq(none.skipped_faces, 1);
    sfb_image_free(&none);
    sfb_context_destroy(ctx);
}

Test(render, loop_triangles_render)
{
    sfb_context *ctx = rn_ctx();
    static const char *tet = "v 1 1 1\nv -1 -1 1\nv -1 1 -1\nv 1 -1 -1\nf 1 2 4\nf 1 4 3\nf 1 3 2\nf 2 3 4\n";
    sfb_mesh_data d = rn_refined(ctx, tet, SFB_SCHEME_LOOP, 3);
    sfb_render_config c = rn_config(SFB_RENDER_SHADED, 100, 100);
    c.positions = d.limit_positions;
    sfb_image img = rn_render_ok(ctx, &d, &c);
    cr_expect(!rn_is_bg(&img, 50, 50) && rn_is_bg(&img, 0, 0));
    sfb_image_free(&img);
    sfb_mesh_data_free(&d);
    sfb_context_destroy(ctx);
}

/* ------------------------------------------------------------------------- */
/* arguments, limits, cancellation, allocation failures                        */

/* a counting allocator that can be told to fail */
typedef struct rn_alloc {
    long live, total, fail_at; /* fail_at: the allocation number (from 1) that fails; 0: never */
} rn_alloc;

typedef struct rn_hdr {
    size_t size;
    size_t pad;
} rn_hdr;

static void *rn_malloc(size_t n, void *user)
{
    rn_alloc *a = user;
    if (a->fail_at && a->total + 1 == a->fail_at) {
        a->total++;
        return NULL;
    }
    rn_hdr *h = malloc(sizeof *h + n);
    if (!h) return NULL;
    h->size = n;
    a->live++;
    a->total++;
    return h + 1;
}

static void *rn_realloc(void *p, size_t n, void *user)
{
    rn_alloc *a = user;
    if (!p) return rn_malloc(n, user);
    if (a->fail_at && a->total + 1 == a->fail_at) {
        a->total++;
        return NULL;
    }
    rn_hdr *h = realloc((rn_hdr *)p - 1, sizeof *h + n);
    if (!h) return NULL;
    h->size = n;
    a->total++;
    return h + 1;
}

static void rn_free(void *p, void *user)
{
    rn_alloc *a = user;
    if (!p) return;
    a->live--;
    free((rn_hdr *)p - 1);
}

typedef struct rn_prog {
    int calls, cancel_at, bad, renders;
    float last;
} rn_prog;

static int rn_progress(float done, const char *stage, void *user)
{
    rn_prog *p = user;
    if (!stage || strcmp(stage, "render") != 0) return 0;
    p->calls++;
    if (!(done >= 0.0f && done <= 1.0f)) p->bad++;
    if (done + 1e-6f < p->last) p->bad++;
    p->last = done;
    return p->cancel_at && p->calls == p->cancel_at;
}

static sfb_context *rn_counting_ctx(rn_alloc *al, rn_prog *pr, size_t budget)
{
    sfb_context_config cc = sfb_context_config_init();
    cc.ignore_environment = 1;
    cc.allocator.alloc = rn_malloc;
    cc.allocator.realloc = rn_realloc;
    cc.allocator.free = rn_free;
    cc.allocator.user = al;
    if (pr) {
        cc.progress.func = rn_progress;
        cc.progress.user = pr;
    }
    cc.memory_budget = budget;
    sfb_context *ctx = NULL;
    cr_assert_eq(sfb_context_create(&cc, &ctx), SFB_SUCCESS);
    return ctx;
}

/* renders expecting `want`, out zeroed and no allocation left behind */
static void rn_expect_fail(sfb_context *ctx, rn_alloc *al, const sfb_mesh_data *m, const sfb_render_config *c, sfb_result want,
                           const char *needle, const char *what)
{
    sfb_image img;
    memset(&img, 0x5a, sizeof img);
    long live = al ? al->live : 0;
    sfb_result r = sfb_render(ctx, m, c, &img);
    cr_expect_eq(r, want, "%s: got %s (%s), wanted %s", what, sfb_result_string(r), sfb_last_error(ctx), sfb_result_string(want));
    cr_expect_null(img.rgba, "%s: out zeroed", what);
    cr_expect_eq(img.width, 0, "%s: out zeroed", what);
    if (al) cr_expect_eq(al->live, live, "%s: %ld blocks left", what, al->live - live);
    if (needle) cr_expect(strstr(sfb_last_error(ctx), needle) != NULL, "%s: message '%s' lacks '%s'", what, sfb_last_error(ctx), needle);
}

Test(render, bad_arguments_allocate_nothing)
{
    rn_alloc al = { 0, 0, 0 };
    sfb_context *ctx = rn_counting_ctx(&al, NULL, 0);
    long base = al.live; /* the context itself */
    float pos[] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
    int sizes[] = { 4 }, fv[] = { 0, 1, 2, 3 }, badfv[] = { 0, 1, 2, 4 }, negfv[] = { 0, -1, 2, 3 };
    sfb_mesh_data m = rn_view(4, pos, 1, sizes, fv);
    sfb_render_config c = rn_config(SFB_RENDER_SHADED, 32, 32);
    sfb_image img;
    cr_expect_eq(sfb_render(NULL, &m, &c, &img), SFB_INVALID_ARGS);
    rn_expect_fail(ctx, &al, NULL, &c, SFB_INVALID_ARGS, "NULL", "NULL mesh");
    cr_expect_eq(sfb_render(ctx, &m, &c, NULL), SFB_INVALID_ARGS);
    /* indices */
    sfb_mesh_data bad = rn_view(4, pos, 1, sizes, badfv);
    rn_expect_fail(ctx, &al, &bad, &c, SFB_INVALID_TOPOLOGY, "face 0: vertex index 4 out of range", "index past the end");
    cr_expect_eq(sfb_last_error_info(ctx).element, SFB_ELEMENT_FACE);
    cr_expect_eq(sfb_last_error_info(ctx).index, 0);
    bad = rn_view(4, pos, 1, sizes, negfv);
    rn_expect_fail(ctx, &al, &bad, &c, SFB_INVALID_TOPOLOGY, "vertex index -1", "negative index");
    /* zero faces, a face too small, sizes not adding up, counts */
    bad = rn_view(4, pos, 0, sizes, fv);
    rn_expect_fail(ctx, &al, &bad, &c, SFB_INVALID_TOPOLOGY, "no faces", "zero faces");
    int two[] = { 2 };
    bad = rn_view(4, pos, 1, two, fv);
    rn_expect_fail(ctx, &al, &bad, &c, SFB_INVALID_TOPOLOGY, "face 0", "a two-vertex face");
    bad = rn_view(4, pos, 1, sizes, fv);
    bad.face_vertex_count = 3;
    rn_expect_fail(ctx, &al, &bad, &c, SFB_INVALID_ARGS, "face_vertex_count", "face sizes past face_vertex_count");
    bad.face_vertex_count = 5;
    rn_expect_fail(ctx, &al, &bad, &c, SFB_INVALID_ARGS, "face_vertex_count", "face sizes short of face_vertex_count");
    bad = rn_view(4, pos, 1, sizes, fv);
    bad.vertex_count = -1;
    rn_expect_fail(ctx, &al, &bad, &c, SFB_INVALID_ARGS, NULL, "negative vertex count");
    bad = rn_view(4, NULL, 1, sizes, fv);
    rn_expect_fail(ctx, &al, &bad, &c, SFB_INVALID_ARGS, "positions", "no positions");
    int hole[] = { 3 };
    bad = rn_view(4, pos, 1, sizes, fv);
    bad.hole_count = 1;
    bad.holes = hole;
    rn_expect_fail(ctx, &al, &bad, &c, SFB_INVALID_TOPOLOGY, "hole", "hole out of range");
    /* sizes */
    sfb_render_config big = c;
    big.width = SFB_RENDER_MAX_SIZE + 1;
    rn_expect_fail(ctx, &al, &m, &big, SFB_LIMIT_EXCEEDED, "SFB_RENDER_MAX_SIZE", "huge width");
    big = c;
    big.height = 1 << 30;
    rn_expect_fail(ctx, &al, &m, &big, SFB_LIMIT_EXCEEDED, NULL, "huge height");
    big = c;
    big.width = -5;
    rn_expect_fail(ctx, &al, &m, &big, SFB_INVALID_ARGS, "negative", "negative width");
    /* config values */
    sfb_render_config v = c;
    v.mode = 4;
    rn_expect_fail(ctx, &al, &m, &v, SFB_INVALID_ARGS, "mode", "unknown mode");
    v = c;
    v.mode = -1;
    rn_expect_fail(ctx, &al, &m, &v, SFB_INVALID_ARGS, "mode", "negative mode");
    v = c;
    v.zoom = NAN;
    rn_expect_fail(ctx, &al, &m, &v, SFB_INVALID_ARGS, "zoom", "NaN zoom");
    v = c;
    v.zoom = -1.0f;
    rn_expect_fail(ctx, &al, &m, &v, SFB_INVALID_ARGS, "zoom", "negative zoom");
    v = c;
    v.view_set = 1;
    v.yaw = INFINITY;
    rn_expect_fail(ctx, &al, &m, &v, SFB_INVALID_ARGS, "yaw", "infinite yaw");
    v = c;
    v.stripes = -2.0f;
    rn_expect_fail(ctx, &al, &m, &v, SFB_INVALID_ARGS, "stripes", "negative stripes");
    v = c;
    v.light_distance = NAN;
    rn_expect_fail(ctx, &al, &m, &v, SFB_INVALID_ARGS, "light distance", "NaN light distance");
    v = rn_config(SFB_RENDER_WEIGHTS, 32, 32);
    rn_expect_fail(ctx, &al, &m, &v, SFB_INVALID_ARGS, "scalars", "weights without scalars");
    cr_expect_eq(al.live, base, "nothing allocated by failed calls");
    /* the limits themselves are allowed */
    sfb_render_config one = rn_config(SFB_RENDER_SHADED, 1, 1);
    img = rn_render_ok(ctx, &m, &one);
    sfb_image_free(&img);
    cr_expect_eq(al.live, base);
    sfb_context_destroy(ctx);
}

Test(render, memory_budget_refuses_large_pictures)
{
    rn_alloc al = { 0, 0, 0 };
    sfb_context *ctx = rn_counting_ctx(&al, NULL, (size_t)16 << 20);
    long base = al.live;
    float pos[] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
    int sizes[] = { 4 }, fv[] = { 0, 1, 2, 3 };
    sfb_mesh_data m = rn_view(4, pos, 1, sizes, fv);
    sfb_render_config c = rn_config(SFB_RENDER_HIGHLIGHT, SFB_RENDER_MAX_SIZE, SFB_RENDER_MAX_SIZE);
    rn_expect_fail(ctx, &al, &m, &c, SFB_LIMIT_EXCEEDED, "memory budget", "8192 x 8192 in 16 MiB");
    c.width = c.height = 256;
    sfb_image img = rn_render_ok(ctx, &m, &c);
    sfb_image_free(&img);
    cr_expect_eq(al.live, base);
    sfb_context_destroy(ctx);
}

/* Renders the level-2 cube with report number k cancelling (or allocation number k failing)
 * for every k until the call succeeds: every failure returns the expected code, leaves `out`
 * zeroed and leaks nothing; the final picture matches one made without failures. */
static void rn_failure_sweep(int cancel, int mode, int edges)
{
    rn_alloc al = { 0, 0, 0 };
    rn_prog pr = { 0, 0, 0, 0, 0.0f };
    sfb_context *ctx = rn_counting_ctx(&al, &pr, 0);
    sfb_mesh_data d = rn_refined(ctx, rn_cube_obj, SFB_SCHEME_CATMARK, 2);
    float *w = malloc((size_t)d.vertex_count * sizeof(float));
    for (int i = 0; i < d.vertex_count; ++i) w[i] = (float)(i % 7) / 6.0f;
    sfb_render_config c = rn_config(mode, 96, 72);
    c.positions = d.limit_positions;
    c.scalars = w;
    c.draw_edges = edges;
    d.hole_count = 1; /* a hole, so that the hole flags are allocated too */
    int hole[] = { 3 };
    int *saved_holes = d.holes;
    d.holes = hole;
    sfb_image ref = rn_render_ok(ctx, &d, &c);
    int failures = 0;
    for (int k = 1; k < 1000; ++k) {
        long live = al.live;
        sfb_image img;
        pr.calls = 0;
        pr.last = 0.0f;
        if (cancel) pr.cancel_at = k;
        else al.fail_at = al.total + k;
        sfb_result r = sfb_render(ctx, &d, &c, &img);
        al.fail_at = 0;
        pr.cancel_at = 0;
        if (r == SFB_SUCCESS) {
            cr_expect_geq(failures, cancel ? 3 : 4, "only %d failure points", failures);
            cr_expect_eq(memcmp(img.rgba, ref.rgba, 96 * 72 * 4), 0, "the picture after the failures");
            sfb_image_free(&img);
            break;
        }
        failures++;
        cr_assert_eq(r, cancel ? SFB_CANCELLED : SFB_OUT_OF_MEMORY, "step %d: %s: %s", k, sfb_result_string(r), sfb_last_error(ctx));
        cr_assert_eq(al.live, live, "step %d leaked %ld blocks", k, al.live - live);
        cr_assert_null(img.rgba);
        cr_assert_eq(img.width, 0);
    }
    cr_expect_gt(failures, 0);
    cr_expect_eq(pr.bad, 0, "progress values out of order or outside [0,1]");
    sfb_image_free(&ref);
    d.holes = saved_holes;
    sfb_mesh_data_free(&d);
    free(w);
    sfb_context_destroy(ctx);
    cr_expect_eq(al.live, 0, "%ld blocks leaked", al.live);
}

Test(render, cancellation_at_every_report)
{
    rn_failure_sweep(1, SFB_RENDER_HIGHLIGHT, 1);
}

Test(render, allocation_failure_at_every_step)
{
    rn_failure_sweep(0, SFB_RENDER_WEIGHTS, 1);
}

Test(render, allocation_failure_at_every_step_without_edges)
{
    rn_failure_sweep(0, SFB_RENDER_SHADED, 0);
}

Test(render, cancelled_before_anything)
{
    rn_alloc al = { 0, 0, 0 };
    rn_prog pr = { 0, 1, 0, 0, 0.0f };
    sfb_context *ctx = rn_counting_ctx(&al, &pr, 0);
    float pos[] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
    int sizes[] = { 4 }, fv[] = { 0, 1, 2, 3 };
    sfb_mesh_data m = rn_view(4, pos, 1, sizes, fv);
    sfb_render_config c = rn_config(SFB_RENDER_SHADED, 64, 64);
    rn_expect_fail(ctx, &al, &m, &c, SFB_CANCELLED, "cancelled", "cancel at the first report");
    sfb_context_destroy(ctx);
}

/* ------------------------------------------------------------------------- */
/* pictures of subdivision shading                                            */

Test(render, shaded_surface_pictures)
{
    sfb_context *ctx = rn_ctx();
    /* the cube with a semi-sharp edge: 8 extraordinary vertices (valence 3) */
    static const char *obj =
        "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
        "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\nt crease 2/1/0 6 7 1.5\n";
    sfb_mesh *m = NULL;
    cr_assert_eq(sfb_mesh_read_obj(ctx, obj, strlen(obj), &m), SFB_SUCCESS);
    sfb_surface_config sc = sfb_surface_config_init(SFB_SCHEME_CATMARK, 3);
    sc.flags = SFB_REFINE_LIMIT | SFB_REFINE_SHADING;
    sfb_surface *s = NULL;
    cr_assert_eq(sfb_surface_create(ctx, m, &sc, &s), SFB_SUCCESS, "%s", sfb_last_error(ctx));
    sfb_shade_params sp = sfb_shade_params_init();
    sfb_mesh_data d;
    sfb_result r = sfb_surface_shade(s, &sp, &d);
    if (r == SFB_UNSUPPORTED) {
        cr_log_warn("sfb_surface_shade unsupported: shading pictures not checked");
    } else {
        cr_assert_eq(r, SFB_SUCCESS, "%s", sfb_last_error(ctx));
        cr_assert_not_null(d.blend_weights);
        /* weights picture: the mesh's own blend weights; every corner of the cube is an EV,
         * so red appears */
        sfb_render_config c = rn_config(SFB_RENDER_WEIGHTS, 160, 120);
        c.positions = d.limit_positions;
        sfb_image img = rn_render_ok(ctx, &d, &c);
        long red = 0;
        for (int y = 0; y < 120; ++y)
            for (int x = 0; x < 160; ++x) {
                const unsigned char *p = rn_px(&img, x, y);
                if (!rn_is_bg(&img, x, y) && p[0] > p[2] + 60) ++red;
            }
        cr_expect_gt(red, 20, "%ld red pixels", red);
        sfb_image_free(&img);
        /* highlight lines of the limit and of the blended normals: same silhouette, other stripes */
        c = rn_config(SFB_RENDER_HIGHLIGHT, 160, 120);
        c.positions = d.limit_positions;
        c.normals = d.limit_normals;
        sfb_image before = rn_render_ok(ctx, &d, &c);
        c.normals = NULL; /* the mesh's normals: the blended ones */
        sfb_image after = rn_render_ok(ctx, &d, &c);
        cr_expect_eq(before.object_pixels, after.object_pixels);
        cr_expect_neq(memcmp(before.rgba, after.rgba, 160 * 120 * 4), 0);
        sfb_image_free(&before);
        sfb_image_free(&after);
        sfb_mesh_data_free(&d);
    }
    sfb_surface_destroy(s);
    sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
}
