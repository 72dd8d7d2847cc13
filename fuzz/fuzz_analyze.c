/* fuzz_analyze.c - libFuzzer target for the exact per-pixel surface analysis
 * (sfb_surface_analyze, seed 003).
 *
 * Input: the first 96 bytes are an analysis configuration (any bytes: sizes reduced to 1..48
 * pixels a side so that a run stays short, but the camera, light, stripes, modes and levels as
 * they come, NaN and infinities included; the level and the modes taken modulo a little over their
 * ranges so that both valid and invalid values occur); the rest, if any, is OBJ text for the
 * mesh, else a built-in creased cube. The scheme is Catmull-Clark, or Loop when the mesh is
 * triangles only and the byte 0 is odd. Invariants (abort() when violated):
 *   - a failure leaves the output zeroed and sets an error message;
 *   - on success the picture has the asked size, covered_pixels equals the pixels whose class is
 *     not 0, every covered pixel's hit names a parametric face in range with (u,v) in its
 *     domain, and uncovered pixels are the background;
 *   - with byte 90 odd, the same analysis through an sfb_analysis_workspace that a picture of
 *     another size (bytes 91, 92) used first gives the same result code, and on success the same
 *     picture bit for bit.
 *
 * Build (from the repository root):
 *   clang -g -O1 -fsanitize=fuzzer,address,undefined -I. fuzz/fuzz_analyze.c -x c tools/impl.c -o fuzz_analyze
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_analyze: invariant violated: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    abort();
}

static const char cube_obj[] =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"
    "t crease 2/1/0 1 2 2.5\nt crease 2/1/0 6 7 10\nt corner 1/1/0 3 10\n";

static float f32(const uint8_t *p)
{
    float f;
    memcpy(&f, p, sizeof f);
    return f;
}

static void config_from(const uint8_t *b, sfb_analyze_config *c)
{
    int i;
    *c = sfb_analyze_config_init(b[1] % (SFB_ANALYZE_MODE_COUNT_ + 1));
    c->width = 1 + b[2] % 48;
    c->height = 1 + b[3] % 48;
    if (b[4] == 0) c->width = 0; /* 0 x h: refused; 0 x 0 would be the default 640 x 480 */
    c->level = b[5] % (SFB_ANALYZE_MAX_LEVEL + 2) - (b[5] == 255);
    if (c->level > 4) c->level = 1 + c->level % 4; /* keep runs short; the limit itself is tested by tests/analyze.c */
    c->polygon_based = b[6] & 1;
    c->newton_steps = b[7] % 10;
    c->view_set = b[8] & 1;
    c->yaw = f32(b + 9);
    c->pitch = f32(b + 13);
    c->zoom = b[17] & 1 ? f32(b + 18) : 0.0f;
    c->camera_set = b[22] & 1;
    for (i = 0; i < 3; ++i) {
        c->eye[i] = f32(b + 23 + 4 * i);
        c->target[i] = (float)(int8_t)b[35 + i] / 16.0f;
        c->up[i] = (float)(int8_t)b[38 + i];
    }
    c->fov = b[41] & 1 ? f32(b + 42) : 0.0f;
    c->orthographic = b[46] & 1;
    c->near_plane = b[47] & 1 ? f32(b + 48) : 0.0f;
    c->light_pattern = b[52] % 5;
    c->light_set = b[53] & 1;
    for (i = 0; i < 3; ++i) {
        c->light_center[i] = (float)(int8_t)b[54 + i] / 8.0f;
        c->light_normal[i] = (float)(int8_t)b[57 + i];
        c->light_axis[i] = (float)(int8_t)b[60 + i];
    }
    c->light_size[0] = (float)b[63] / 8.0f;
    c->light_size[1] = (float)b[64] / 8.0f;
    c->stripes = b[65] & 1 ? f32(b + 66) : (float)(b[65] >> 1);
    c->stripe_width = (float)b[70] / 256.0f;
    for (i = 0; i < 3; ++i) c->light_dir[i] = (float)(int8_t)b[71 + i];
    c->curvature = b[74] % 4;
    c->curvature_range = b[75] & 1 ? f32(b + 76) : 0.0f;
    c->light_width = b[80] % 5;
    c->light_height = b[81] % 5;
    for (i = 0; i < 4; ++i) { c->background[i] = b[82 + i]; c->miss[i] = b[86 + i]; }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static unsigned char texels[4 * 4 * 4];
    uint8_t head[96];
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *s = NULL;
    sfb_surface_config sc;
    sfb_analyze_config c;
    sfb_analysis a, zero;
    sfb_mesh_info info;
    sfb_result r;
    const char *text = cube_obj;
    size_t tlen = sizeof cube_obj - 1;
    int i;
    memset(head, 0, sizeof head);
    memcpy(head, data, size < sizeof head ? size : sizeof head);
    if (size > sizeof head) { text = (const char *)data + sizeof head; tlen = size - sizeof head; }
    for (i = 0; i < (int)sizeof texels; ++i) texels[i] = (unsigned char)(i * 37);
    cc.ignore_environment = 1;
    cc.memory_budget = (size_t)256 << 20;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) return 0;
    if (sfb_mesh_read_obj(ctx, text, tlen, &mesh) != SFB_SUCCESS) { sfb_context_destroy(ctx); return 0; }
    sfb_mesh_get_info(mesh, &info);
    sc = sfb_surface_config_init((head[0] & 1) && info.triangles == info.face_count ? SFB_SCHEME_LOOP : SFB_SCHEME_CATMARK, 0);
    sc.flags = SFB_REFINE_PATCHES;
    if (info.face_count > 200 || sfb_surface_create(ctx, mesh, &sc, &s) != SFB_SUCCESS) {
        sfb_mesh_destroy(mesh);
        sfb_context_destroy(ctx);
        return 0;
    }
    config_from(head, &c);
    if (c.light_width > 0 && c.light_height > 0 && (head[80] & 128) == 0) c.light_rgba = texels;
    memset(&zero, 0, sizeof zero);
    memset(&a, 0x5a, sizeof a);
    r = sfb_surface_analyze(s, &c, &a);
    if (r != SFB_SUCCESS) {
        const char *m = sfb_last_error(ctx);
        if (memcmp(&a, &zero, sizeof a) != 0) fail("the output is not zeroed after", sfb_result_string(r));
        if (!m || !m[0]) fail("empty error message after", sfb_result_string(r));
    } else {
        int w = c.width ? c.width : 640, h = c.height ? c.height : 480, covered = 0, nf = sfb_surface_param_face_count(s);
        long k;
        if (a.width != w || a.height != h || !a.rgba || !a.values || !a.classes || !a.hits) fail("picture size or arrays", NULL);
        for (k = 0; k < (long)w * h; ++k) {
            const sfb_location *l = &a.hits[k];
            if (!a.classes[k]) continue;
            ++covered;
            if (l->face < 0 || l->face >= nf || !(l->u >= 0.0f && l->u <= 1.0f && l->v >= 0.0f && l->v <= 1.0f))
                fail("a covered pixel's hit is outside its parametric face", NULL);
            if (sc.scheme == SFB_SCHEME_LOOP && (double)l->u + (double)l->v > 1.0 + 1e-6) fail("a Loop hit outside its triangle", NULL);
        }
        if (covered != a.covered_pixels) fail("covered_pixels differs from the classes", NULL);
    }
    if (head[90] & 1) {
        sfb_analysis_workspace *ws = NULL;
        sfb_analyze_config c2 = c;
        sfb_analysis b;
        sfb_result rb;
        if (sfb_analysis_workspace_create(ctx, &ws) == SFB_SUCCESS) {
            c2.width = 1 + head[91] % 48;
            c2.height = 1 + head[92] % 48;
            c2.workspace = ws;
            if (sfb_surface_analyze(s, &c2, &b) == SFB_SUCCESS) sfb_analysis_free(&b);
            c2 = c;
            c2.workspace = ws;
            rb = sfb_surface_analyze(s, &c2, &b);
            if (rb != r) fail("a workspace changed the result code", sfb_result_string(rb));
            if (r == SFB_SUCCESS) {
                const size_t n = (size_t)a.width * a.height;
                if (b.covered_pixels != a.covered_pixels || b.dropped_pixels != a.dropped_pixels || b.fallback_pixels != a.fallback_pixels ||
                    memcmp(a.rgba, b.rgba, 4 * n) != 0 || memcmp(a.classes, b.classes, n) != 0 || memcmp(a.values, b.values, n * sizeof(float)) != 0 ||
                    memcmp(a.hits, b.hits, n * sizeof(sfb_location)) != 0)
                    fail("a workspace changed the picture", NULL);
                sfb_analysis_free(&b);
            }
            sfb_analysis_workspace_destroy(ws);
        }
    }
    if (r == SFB_SUCCESS) sfb_analysis_free(&a);
    sfb_surface_destroy(s);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return 0;
}
