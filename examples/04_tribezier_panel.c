/* 04_tribezier_panel: the sharpness slider of quartic triangular Bezier surfaces (seed 004).
 *
 * Four small triangle meshes are built here, in code (like the seed's Fig. 7): a disk around one
 * extraordinary vertex of valence 4, 5 and 7 with a straight crease through it, and a disk around
 * a vertex of valence 3 with three crease edges meeting at a corner. Each is made a
 * SFB_SCHEME_TRIBEZIER surface with the crease's sharpness s = 0 (the smooth G1 spline surface),
 * then moved to 0.5 and 1 with the slider (sfb_surface_set_sharpness: built once, tribezier.slider)
 * (the crease; the corner interpolated), and drawn with highlight lines from the exact
 * limit normals: rows are the meshes, columns the three values of s (the seed's Figs. 8-11 as one
 * picture).
 *
 * It also measures what the pictures show: the largest angle between the normals of the two
 * sides of the crease edges (evaluated with sfb_surface_eval at matching points of both faces),
 * which must be ~0 at s = 0 (G1) and grow with s. Exit status 1 when it does not.
 *
 *   04_tribezier_panel [OUT.png]     (no argument: measure only, write nothing)
 *   cc -std=c99 -I. examples/04_tribezier_panel.c tools/impl.c -lm -lpthread -ldl
 * PNG output uses stb_image_write (Debian's libstb-dev, headers only). */
#include "surfblend.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb/stb_image_write.h>
#include "panel_font.h"

#define PANEL_PI 3.14159265358979323846
#define RINGS 3      /* rings of triangles around the extraordinary vertex */
#define RATE 16      /* tessellation segments per triangle edge */
#define TILE_W 400
#define TILE_H 300

typedef struct panel_mesh {
    int n, corner;                   /* valence of the centre; corner: three crease rays and a corner tag */
    int vertex_count, face_count, crease_count;
    float *positions;                /* xyz, y up */
    int *faces, *sizes, *creases;    /* creases: vertex pairs */
    float *sharpness;
} panel_mesh;

/* Index of lattice point (a, b) of wedge w (a + b = ring r): the centre is 0, ring r holds n r
 * points counter-clockwise from ray 0. */
static int lattice_index(int n, int w, int a, int b) {
    const int r = a + b;
    if (r == 0) return 0;
    return 1 + n * (r - 1) * r / 2 + (w * r + b) % (n * r);
}

/* Height over the plane point (x, z) (the disk lies in y = 0, y up). Crease: a roof ridge along the
 * x axis (the crease line) on a dome; corner: a three-sided pyramid whose ridges are
 * the crease rays, on the same bump. */
static double height(const panel_mesh *m, const double *ray_angle, double x, double z) {
    const double bump = 0.6 * (x * x + z * z) / (RINGS * RINGS);
    if (!m->corner) return -0.5 * fabs(z) - bump * 0.5;
    {
        double best = -1e300;
        int i;
        for (i = 0; i < 3; ++i) { /* the bisector of sector i (between rays i and i+1) */
            const double a = 0.5 * (ray_angle[i * m->n / 3] + ray_angle[(i + 1) * m->n / 3]);
            const double d = x * cos(a) + z * sin(a);
            if (d > best) best = d;
        }
        return -0.45 * best - bump * 0.5;
    }
}

/* Builds the disk: n wedges of the regular triangle lattice, every inner vertex but the centre of
 * valence 6. Returns 0 when out of memory. */
static int build_mesh(panel_mesh *m, int n, int corner) {
    const int nv = 1 + n * RINGS * (RINGS + 1) / 2, nf = n * RINGS * RINGS;
    double ray_angle[16];
    int r, w, a, b, f = 0, c = 0, v = 1, k;
    memset(m, 0, sizeof *m);
    m->n = n; m->corner = corner;
    m->positions = (float *)malloc(sizeof(float) * 3 * (size_t)nv);
    m->faces = (int *)malloc(sizeof(int) * 3 * (size_t)nf);
    m->sizes = (int *)malloc(sizeof(int) * (size_t)nf);
    m->creases = (int *)malloc(sizeof(int) * 2 * 3 * RINGS);
    m->sharpness = (float *)malloc(sizeof(float) * 3 * RINGS);
    if (!m->positions || !m->faces || !m->sizes || !m->creases || !m->sharpness) return 0;
    /* crease: rays 0 and k span pi on either side, so the crease is a straight line; corner:
     * uniform rays, creases on rays 0, n/3, 2n/3 */
    for (w = 0; w <= n; ++w) {
        const int k2 = n / 2;
        ray_angle[w] = corner ? 2.0 * PANEL_PI * w / n
                              : w <= k2 ? PANEL_PI * w / k2 : PANEL_PI + PANEL_PI * (w - k2) / (n - k2);
    }
    m->positions[0] = 0.0f; m->positions[2] = 0.0f;
    m->positions[1] = (float)height(m, ray_angle, 0.0, 0.0);
    for (r = 1; r <= RINGS; ++r)
        for (w = 0; w < n; ++w)
            for (b = 0; b < r; ++b, ++v) { /* point b of ring r in wedge w, on the straight lattice row */
                const double t = (double)b / r;
                const double x = r * ((1.0 - t) * cos(ray_angle[w]) + t * cos(ray_angle[w + 1]));
                const double z = r * ((1.0 - t) * sin(ray_angle[w]) + t * sin(ray_angle[w + 1]));
                m->positions[3 * v] = (float)x;
                m->positions[3 * v + 1] = (float)height(m, ray_angle, x, z);
                m->positions[3 * v + 2] = (float)z;
            }
    for (w = 0; w < n; ++w)
        for (a = 0; a < RINGS; ++a)
            for (b = 0; a + b < RINGS; ++b) {
                /* counter-clockwise seen from +y (the disk is in x,z: z x x = y, so list x then z) */
                m->faces[3 * f] = lattice_index(n, w, a, b);
                m->faces[3 * f + 1] = lattice_index(n, w, a, b + 1);
                m->faces[3 * f + 2] = lattice_index(n, w, a + 1, b);
                m->sizes[f++] = 3;
                if (a + b + 1 < RINGS) {
                    m->faces[3 * f] = lattice_index(n, w, a + 1, b);
                    m->faces[3 * f + 1] = lattice_index(n, w, a, b + 1);
                    m->faces[3 * f + 2] = lattice_index(n, w, a + 1, b + 1);
                    m->sizes[f++] = 3;
                }
            }
    for (k = 0; k < (corner ? 3 : 2); ++k) {
        const int ray = corner ? k * n / 3 : k * (n / 2);
        for (r = 0; r < RINGS; ++r, ++c) {
            m->creases[2 * c] = lattice_index(n, ray, r, 0);
            m->creases[2 * c + 1] = lattice_index(n, ray, r + 1, 0);
            m->sharpness[c] = 1.0f; /* the tag's value does not matter: cfg.tribezier.sharpness overrides it */
        }
    }
    m->vertex_count = nv; m->face_count = f; m->crease_count = c;
    return 1;
}

static void free_mesh(panel_mesh *m) {
    free(m->positions); free(m->faces); free(m->sizes); free(m->creases); free(m->sharpness);
}

/* The surface of `m` at sharpness s, or NULL with the reason printed; built with the slider, so
 * that the other columns' s are set on it (sfb_surface_set_sharpness) rather than built again. */
static sfb_surface *make_surface(sfb_context *ctx, const panel_mesh *m, float s, sfb_mesh **mesh_out) {
    static const int corner_vertex[1] = {0};
    static const float corner_sharpness[1] = {1.0f};
    sfb_mesh_desc desc;
    sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
    sfb_surface *surface = NULL;
    memset(&desc, 0, sizeof desc);
    desc.vertex_count = m->vertex_count; desc.positions = m->positions;
    desc.face_count = m->face_count; desc.face_sizes = m->sizes; desc.face_vertices = m->faces;
    desc.crease_count = m->crease_count; desc.crease_vertices = m->creases; desc.crease_sharpness = m->sharpness;
    if (m->corner) { desc.corner_count = 1; desc.corner_vertices = corner_vertex; desc.corner_sharpness = corner_sharpness; }
    cfg.flags = SFB_REFINE_PATCHES;
    cfg.tribezier.sharpness_set = 1;
    cfg.tribezier.sharpness = s;
    cfg.tribezier.slider = 1;
    if (sfb_mesh_create(ctx, &desc, mesh_out) != SFB_SUCCESS || sfb_surface_create(ctx, *mesh_out, &cfg, &surface) != SFB_SUCCESS) {
        fprintf(stderr, "04_tribezier_panel: %s\n", sfb_last_error(ctx));
        return NULL;
    }
    return surface;
}

static int is_crease(const panel_mesh *m, int a, int b) {
    int c;
    for (c = 0; c < m->crease_count; ++c)
        if ((m->creases[2 * c] == a && m->creases[2 * c + 1] == b) || (m->creases[2 * c] == b && m->creases[2 * c + 1] == a))
            return 1;
    return 0;
}

/* The location on face f (a triangle: param face f, barycentric u, v) of the point
 * (1 - t) a + t b of its edge (a, b). */
static sfb_location edge_location(const panel_mesh *m, int f, int a, int b, float t) {
    float w[3] = {0, 0, 0};
    int i;
    sfb_location l;
    for (i = 0; i < 3; ++i) {
        if (m->faces[3 * f + i] == a) w[i] = 1.0f - t;
        if (m->faces[3 * f + i] == b) w[i] = t;
    }
    l.face = f; l.u = w[1]; l.v = w[2];
    return l;
}

/* The largest angle (radians) between the normals of the two faces of any crease edge, sampled at
 * 9 points per edge. -1 on failure. */
static double crease_normal_jump(const sfb_surface *surface, const panel_mesh *m) {
    enum { SAMPLES = 9 };
    double worst = 0.0;
    int c, f, i, j, s;
    for (c = 0; c < m->crease_count; ++c) {
        const int a = m->creases[2 * c], b = m->creases[2 * c + 1];
        int side[2], ns = 0;
        sfb_location loc[2 * SAMPLES];
        float normal[2 * SAMPLES * 3];
        sfb_eval_output out;
        for (f = 0; f < m->face_count && ns < 2; ++f)
            for (i = 0; i < 3; ++i)
                if (is_crease(m, m->faces[3 * f + i], m->faces[3 * f + (i + 1) % 3]) &&
                    ((m->faces[3 * f + i] == a && m->faces[3 * f + (i + 1) % 3] == b) ||
                     (m->faces[3 * f + i] == b && m->faces[3 * f + (i + 1) % 3] == a)))
                    side[ns++] = f;
        if (ns != 2) return -1.0;
        for (j = 0; j < 2; ++j)
            for (s = 0; s < SAMPLES; ++s) loc[j * SAMPLES + s] = edge_location(m, side[j], a, b, (float)(s + 0.5) / SAMPLES);
        memset(&out, 0, sizeof out);
        out.normal = normal;
        if (sfb_surface_eval(surface, loc, 2 * SAMPLES, &out) != SFB_SUCCESS) return -1.0;
        for (s = 0; s < SAMPLES; ++s) {
            const float *p = normal + 3 * s, *q = normal + 3 * (SAMPLES + s);
            const double cx = p[1] * q[2] - p[2] * q[1], cy = p[2] * q[0] - p[0] * q[2], cz = p[0] * q[1] - p[1] * q[0];
            const double angle = atan2(sqrt(cx * cx + cy * cy + cz * cz), p[0] * q[0] + p[1] * q[1] + p[2] * q[2]);
            if (angle > worst) worst = angle;
        }
    }
    return worst;
}

/* Tessellates every triangle on its own (RATE segments per edge) with exact positions and normals
 * of that triangle's patch, so the normals of a crease's two sides stay apart, and renders the
 * result with highlight lines into `img`. 1, or 0 with the reason printed. */
static int render_tile(sfb_context *ctx, const sfb_surface *surface, const panel_mesh *m, sfb_image *img) {
    const int per_face = (RATE + 1) * (RATE + 2) / 2, tris_per_face = RATE * RATE;
    const int nv = m->face_count * per_face, nt = m->face_count * tris_per_face;
    sfb_location *loc = (sfb_location *)malloc(sizeof(sfb_location) * (size_t)nv);
    float *pos = (float *)malloc(sizeof(float) * 3 * (size_t)nv), *nrm = (float *)malloc(sizeof(float) * 3 * (size_t)nv);
    int *tri = (int *)malloc(sizeof(int) * 3 * (size_t)nt), *sizes = (int *)malloc(sizeof(int) * (size_t)nt);
    int f, i, j, v = 0, t = 0, ok = 0;
    sfb_eval_output out;
    sfb_mesh_data data;
    sfb_render_config rc = sfb_render_config_init(SFB_RENDER_HIGHLIGHT);
    if (!loc || !pos || !nrm || !tri || !sizes) { fprintf(stderr, "04_tribezier_panel: out of memory\n"); goto done; }
    for (f = 0; f < m->face_count; ++f) {
        const int base = v;
        for (j = 0; j <= RATE; ++j)
            for (i = 0; i + j <= RATE; ++i, ++v) { loc[v].face = f; loc[v].u = (float)i / RATE; loc[v].v = (float)j / RATE; }
        /* vertex (i, j) of this face's grid: rows of constant j */
#define GRID(i_, j_) (base + (j_) * (RATE + 1) - (j_) * ((j_) - 1) / 2 + (i_))
        for (j = 0; j < RATE; ++j)
            for (i = 0; i + j < RATE; ++i) {
                tri[3 * t] = GRID(i, j); tri[3 * t + 1] = GRID(i + 1, j); tri[3 * t + 2] = GRID(i, j + 1); sizes[t++] = 3;
                if (i + j + 1 < RATE) {
                    tri[3 * t] = GRID(i + 1, j); tri[3 * t + 1] = GRID(i + 1, j + 1); tri[3 * t + 2] = GRID(i, j + 1); sizes[t++] = 3;
                }
            }
#undef GRID
    }
    memset(&out, 0, sizeof out);
    out.position = pos; out.normal = nrm;
    if (sfb_surface_eval(surface, loc, nv, &out) != SFB_SUCCESS) { fprintf(stderr, "04_tribezier_panel: %s\n", sfb_last_error(ctx)); goto done; }
    memset(&data, 0, sizeof data);
    data.vertex_count = nv; data.positions = pos; data.normals = nrm;
    data.face_count = t; data.face_sizes = sizes; data.face_vertices = tri; data.face_vertex_count = 3 * t;
    rc.width = TILE_W; rc.height = TILE_H;
    rc.view_set = 1; rc.yaw = 20.0f; rc.pitch = 50.0f; rc.zoom = 1.35f;
    rc.stripes = 6.0f;
    if (sfb_render(ctx, &data, &rc, img) != SFB_SUCCESS) { fprintf(stderr, "04_tribezier_panel: %s\n", sfb_last_error(ctx)); goto done; }
    ok = 1;
done:
    free(loc); free(pos); free(nrm); free(tri); free(sizes);
    return ok;
}

static void usage(FILE *f) {
    fprintf(f, "usage: 04_tribezier_panel [OUT.png]\n"
               "  Quartic triangular Bezier surfaces (seed 004): a crease through a vertex of valence 4, 5 and 7\n"
               "  and a corner at valence 3 (rows), each at sharpness s = 0, 0.5, 1 (columns), with highlight\n"
               "  lines; prints the largest normal jump across the crease edges per picture. Without OUT.png\n"
               "  it only measures. Exit status 1 when s = 0 is not G1 or the jump does not grow with s.\n");
}

int main(int argc, char **argv) {
    static const int valence[4] = {4, 5, 7, 3};
    static const float svals[3] = {0.0f, 0.5f, 1.0f};
    const char *outp = NULL;
    const int W = 3 * TILE_W, H = 4 * TILE_H;
    unsigned char *panel = NULL;
    sfb_context *ctx = NULL;
    int row, col, status = 0;
    sfb_mesh *mesh;
    sfb_surface *surface;
    if (argc == 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) { usage(stdout); return 0; }
    if (argc > 2 || (argc == 2 && argv[1][0] == '-')) { usage(stderr); return 2; }
    if (argc == 2) outp = argv[1];
    if (sfb_context_create(NULL, &ctx) != SFB_SUCCESS) { fprintf(stderr, "04_tribezier_panel: no context\n"); return 1; }
    if (outp && !(panel = (unsigned char *)calloc((size_t)W * (size_t)H, 4))) { fprintf(stderr, "04_tribezier_panel: out of memory\n"); return 1; }
    printf("tribezier (backend %s): largest normal jump across the crease edges, degrees\n", sfb_context_backend_name(ctx));
    printf("  %-16s %10s %10s %10s\n", "mesh", "s = 0", "s = 0.5", "s = 1");
    for (row = 0; row < 4; ++row) {
        panel_mesh m;
        double jump[3];
        char name[32];
        if (!build_mesh(&m, valence[row], row == 3)) { fprintf(stderr, "04_tribezier_panel: out of memory\n"); status = 1; free_mesh(&m); break; }
        snprintf(name, sizeof name, "n=%d %s", valence[row], row == 3 ? "corner" : "crease");
        mesh = NULL;
        surface = make_surface(ctx, &m, svals[0], &mesh);
        for (col = 0; col < 3; ++col) {
            sfb_image img;
            memset(&img, 0, sizeof img);
            if (col > 0 && surface) {
                /* the slider: the same surface at the next s, its nets blended again (no G1 solve) */
                sfb_tribezier_options to;
                memset(&to, 0, sizeof to);
                to.sharpness_set = 1;
                to.sharpness = svals[col];
                to.slider = 1;
                if (sfb_surface_set_sharpness(surface, &to) != SFB_SUCCESS) {
                    fprintf(stderr, "04_tribezier_panel: %s\n", sfb_last_error(ctx));
                    sfb_surface_destroy(surface);
                    surface = NULL;
                }
            }
            jump[col] = surface ? crease_normal_jump(surface, &m) : -1.0;
            if (surface && panel && render_tile(ctx, surface, &m, &img)) {
                int y;
                char label[64];
                for (y = 0; y < TILE_H; ++y)
                    memcpy(panel + 4 * ((size_t)(row * TILE_H + y) * (size_t)W + (size_t)col * TILE_W), img.rgba + 4 * (size_t)y * TILE_W,
                           4 * (size_t)TILE_W);
                snprintf(label, sizeof label, "%s s=%g", name, svals[col]);
                panel_draw_text(panel, W, H, col * TILE_W + 8, row * TILE_H + 8, label);
            } else if (panel) status = 1;
            sfb_image_free(&img);
        }
        sfb_surface_destroy(surface);
        sfb_mesh_destroy(mesh);
        printf("  %-16s %10.3g %10.3g %10.3g\n", name, jump[0] * 180.0 / PANEL_PI, jump[1] * 180.0 / PANEL_PI, jump[2] * 180.0 / PANEL_PI);
        /* s = 0 is G1 (the patch points are floats: 1e-3 degrees is far above their rounding); the
         * crease appears and sharpens as s grows */
        if (jump[0] < 0 || jump[0] * 180.0 / PANEL_PI > 1e-3 || !(jump[1] * 180.0 / PANEL_PI > 1.0) || !(jump[2] > jump[1])) {
            printf("  FAILED: %s: expected ~0 at s = 0 and a jump that grows with s\n", name);
            status = 1;
        }
        free_mesh(&m);
    }
    if (panel && status == 0) {
        /* written under a temporary name, renamed when complete: no partial file */
        char tmp[4096];
        snprintf(tmp, sizeof tmp, "%s.part", outp);
        if (strlen(outp) + 6 > sizeof tmp || !stbi_write_png(tmp, W, H, 4, panel, W * 4) || rename(tmp, outp) != 0) {
            fprintf(stderr, "04_tribezier_panel: cannot write %s\n", outp);
            remove(tmp);
            status = 1;
        } else printf("wrote %s (%dx%d)\n", outp, W, H);
    }
    free(panel);
    sfb_context_destroy(ctx);
    return status;
}
