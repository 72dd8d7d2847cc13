/* 06_fillet_panel: rolling-ball fillets of a triangle mesh's sharp features (seed 002, its Fig. 12).
 *
 * The shape is generated (examples/fillet_shapes.h): a box with a cylinder unioned on its top, one
 * closed watertight triangle mesh. Its feature edges (dihedral angle over 30 degrees) are the
 * closed concave seam between the cylinder and the box's top, the cylinder's convex rim and the
 * box's twelve convex edges, which meet three at a time at the box's eight corners. sfb_mesh_fillet
 * rounds every feature as it finds them (config.curves NULL: the seam and the rim as closed loops,
 * the box's edges as twelve open chains ending at the corners, where the ball's sphere joins each
 * three), without remeshing, with one ball radius r = 0.15 ("after", which the checks below hold
 * to) and, only when a picture is asked for, with r = 0.25 (checked for folds and spikes too).
 * The panel: columns before / after r = 0.15 / after r = 0.25; rows highlight lines from the angle-weighted
 * vertex normals (sfb_mesh_vertex_normals) interpolated across the triangles, the signed mean
 * curvature (sfb_mesh_mean_curvature: blue concave, green flat, red convex, |H| = 1/r at the
 * ends), a close-up of the seam (highlight lines) and of a box corner (mean curvature).
 *
 * It also measures what the pictures show, per region (the seam, the rim, the box's edges away
 * from the corners, the corners: within 3r of one): the mean |H| over the region's feature
 * vertices before and after, the sharpest edge before and after, the edges folded back (a
 * dihedral angle over 120 degrees: the input's sharpest are 90), the most an edge's dihedral
 * grew, and the largest dihedral across the linkage curves (edges between moved and still
 * triangles) beside the 95th percentile inside the fillet (the tessellation's own). Exit status 1
 * when the "after" fillet fails, when a region's mean |H| does not drop 2x or an edge there stays
 * sharper than 30 degrees, when the seam's or the rim's normals jump across the linkage curves 2
 * degrees more than inside the fillet, when any edge folds back or a vertex moves r or farther
 * (a spike: a corner's vertex moves at most r (sqrt 3 - 1)), or when the box's 8 corners are not
 * all rounded; and, with r = 0.25, when an edge folds or a vertex moves that ball's r. The picture is written also when a check fails (it shows what went wrong).
 *
 *   06_fillet_panel [OUT.png]     (no argument: measure "after" only, write nothing)
 *   cc -std=c99 -I. examples/06_fillet_panel.c tools/impl.c -lm -lpthread -ldl
 * PNG output uses stb_image_write (Debian's libstb-dev, headers only). */
#include "surfblend.h"
#include "fillet_shapes.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb/stb_image_write.h>
#include "panel_font.h"

#define PANEL_PI 3.14159265358979323846
#define TILE_W 440
#define TILE_H 340
#define COLS 3
#define ROWS 4

/* The shape: box [-HALF, HALF]^2 x [-HEIGHT, 0], cylinder of CYL_R from z = 0 to CYL_H; the ball. */
#define SHAPE_N 48
#define HALF 1.0f
#define HEIGHT 0.6f
#define CYL_R 0.5f
#define CYL_H 0.6f
#define RADIUS 0.15f
#define FEATURE_ANGLE 30.0f
#define RADIUS2 0.25f            /* the third column's ball */
#define CORNER (3.0 * RADIUS)  /* the corner regions' radius */
#define FOLD 120.0             /* degrees: an edge sharper than this (and than before) is folded back (the
                                  input's sharpest edges are 90 degrees) */

enum { R_SEAM = 0, R_RIM, R_EDGE, R_CORNER, R_KINDS };
static const char *const region_name[R_KINDS] = {"seam (concave)", "cylinder rim", "box edges", "box corners"};

/* ---- labels: panel_font.h's glyphs, plus the few letters and signs these labels need ---- */
static const char extra_chars[] = "f/+";
static const unsigned char extra_glyphs[][7] = {{6, 9, 8, 28, 8, 8, 8}, {1, 1, 2, 4, 8, 16, 16}, {0, 4, 4, 31, 4, 4, 0}};

static void label(unsigned char *rgba, int width, int height, int x0, int y0, const char *text) {
    const int scale = 2;
    int c, row, col, dx, dy, n = (int)strlen(text);
    panel_draw_text(rgba, width, height, x0, y0, text);
    for (c = 0; c < n; ++c) {
        const char *g = strchr(extra_chars, text[c]);
        if (!g) continue;
        for (row = 0; row < 7; ++row)
            for (col = 0; col < 5; ++col)
                if (extra_glyphs[g - extra_chars][row] & (16 >> col))
                    for (dy = 0; dy < scale; ++dy)
                        for (dx = 0; dx < scale; ++dx) {
                            const int x = x0 + (c * 6 + col) * scale + dx, y = y0 + row * scale + dy;
                            unsigned char *p;
                            if (x < 0 || y < 0 || x >= width || y >= height) continue;
                            p = rgba + 4 * ((size_t)y * (size_t)width + (size_t)x);
                            p[0] = p[1] = p[2] = 255;
                            p[3] = 255;
                        }
    }
}

/* ---- the mesh's edges ---- */
typedef struct edge_list {
    int n;
    int *v;            /* 2 per edge */
    int *f;            /* 2 per edge: its faces (the shape is closed: always two) */
    int *ve_off, *ve;  /* the edges at each vertex */
} edge_list;

static int cmp_ll(const void *a, const void *b) {
    const long long x = *(const long long *)a, y = *(const long long *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}

static void free_edges(edge_list *e) {
    free(e->v); free(e->f); free(e->ve_off); free(e->ve);
    memset(e, 0, sizeof *e);
}

/* The edges of a closed triangle mesh with their two faces. 0 when out of memory or not closed. */
static int build_edges(int nv, int nf, const int *tri, edge_list *e) {
    long long *key = (long long *)malloc(sizeof(long long) * 3 * (size_t)nf + 1);
    int i, k = 0, *fill = NULL;
    memset(e, 0, sizeof *e);
    e->v = (int *)malloc(sizeof(int) * 3 * (size_t)nf + 1);
    e->f = (int *)malloc(sizeof(int) * 3 * (size_t)nf + 1);
    e->ve_off = (int *)calloc((size_t)nv + 1, sizeof(int));
    e->ve = (int *)malloc(sizeof(int) * 3 * (size_t)nf + 1);
    fill = (int *)calloc((size_t)nv + 1, sizeof(int));
    if (!key || !e->v || !e->f || !e->ve_off || !e->ve || !fill) { free(key); free(fill); free_edges(e); return 0; }
    /* key: (min vertex, max vertex, face); each edge of a closed mesh appears exactly twice */
    for (i = 0; i < 3 * nf; ++i) {
        const int a = tri[i], b = tri[i % 3 == 2 ? i - 2 : i + 1], lo = a < b ? a : b, hi = a < b ? b : a;
        key[i] = ((long long)lo * nv + hi) * nf + i / 3;
    }
    qsort(key, (size_t)3 * nf, sizeof *key, cmp_ll);
    for (i = 0; i < 3 * nf; i += 2, ++k) {
        const long long pair = key[i] / nf;
        if (i + 1 >= 3 * nf || key[i + 1] / nf != pair || (i + 2 < 3 * nf && key[i + 2] / nf == pair)) {
            free(key); free(fill); free_edges(e);
            return 0;
        }
        e->v[2 * k] = (int)(pair / nv);
        e->v[2 * k + 1] = (int)(pair % nv);
        e->f[2 * k] = (int)(key[i] % nf);
        e->f[2 * k + 1] = (int)(key[i + 1] % nf);
    }
    e->n = k;
    for (i = 0; i < 2 * k; ++i) e->ve_off[e->v[i] + 1]++;
    for (i = 0; i < nv; ++i) e->ve_off[i + 1] += e->ve_off[i];
    for (i = 0; i < 2 * k; ++i) e->ve[e->ve_off[e->v[i]] + fill[e->v[i]]++] = i / 2;
    free(key);
    free(fill);
    return 1;
}

static void face_normal(const float *pos, const int *t, double *n) {
    const float *a = pos + 3 * t[0], *b = pos + 3 * t[1], *c = pos + 3 * t[2];
    const double u[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
    const double v[3] = {(double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2]};
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
}

/* The angle (degrees) between the normals of an edge's two faces: 0 where flat, 180 folded flat. */
static double dihedral(const float *pos, const int *tri, const edge_list *e, int i) {
    double a[3], b[3], la, lb, c;
    face_normal(pos, tri + 3 * e->f[2 * i], a);
    face_normal(pos, tri + 3 * e->f[2 * i + 1], b);
    la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    if (!(la > 0) || !(lb > 0)) return 180.0;
    c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
    c = c > 1 ? 1 : c < -1 ? -1 : c;
    return acos(c) * 180.0 / PANEL_PI;
}

static double corner_distance(const float *p) {
    const double dx = HALF - fabs((double)p[0]), dy = HALF - fabs((double)p[1]);
    const double dz = p[2] > -0.5 * HEIGHT ? -(double)p[2] : HEIGHT + (double)p[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* The region of a point of the input: near the cylinder's cap (the rim), near the cylinder on the
 * box's top (the seam), within CORNER of a box corner, or the rest (the box's edges). */
static int region_of(const float *p) {
    const double rho = sqrt((double)p[0] * p[0] + (double)p[1] * p[1]), reach = 3.0 * RADIUS;
    if (rho < CYL_R + reach && p[2] > CYL_H - reach) return R_RIM;
    if (rho < CYL_R + reach && p[2] > -reach) return R_SEAM;
    if (corner_distance(p) < CORNER) return R_CORNER;
    return R_EDGE;
}

/* ---- the measures ---- */
static int cmp_double(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}

typedef struct region_stats {
    int vertices;                      /* the region's feature vertices (on a feature edge of the input) */
    double h_before, h_after;          /* mean |H| over them */
    double sharp_before, sharp_after;  /* the largest dihedral of any edge in the region */
    int folds;                         /* edges folded back: dihedral over FOLD, and over their own before */
    double fold_max;                   /* the most an edge's dihedral grew */
    int fillet_edges, linkage_edges;
    double fillet_p95, linkage_max;    /* dihedrals inside the fillet (95th percentile) and across the linkage */
} region_stats;

typedef struct variant {
    const char *name, *title;
    sfb_mesh *mesh;
    const float *pos;
    float *n, *h;
    int curves, moved;
    double farthest;                   /* the farthest a vertex moved */
    sfb_fillet_report report;
    region_stats st[R_KINDS];
} variant;

/* Per region: the measures of variant `v` against the input (positions `p0`, curvature `h0`). */
static int measure(const fs_mesh *m, const edge_list *el, const unsigned char *feature, const float *h0, variant *v) {
    unsigned char *moved = (unsigned char *)calloc((size_t)m->nv + 1, 1), *fvert = (unsigned char *)calloc((size_t)m->nv + 1, 1);
    double *inner = (double *)malloc(sizeof(double) * ((size_t)el->n + 1));
    int i, e, k;
    if (!moved || !fvert || !inner) { free(moved); free(fvert); free(inner); return 0; }
    memset(v->st, 0, sizeof v->st);
    v->moved = 0;
    v->farthest = 0.0;
    for (i = 0; i < m->nv; ++i) {
        const float *a = m->pos + 3 * i, *b = v->pos + 3 * i;
        const double d = sqrt(((double)a[0] - b[0]) * (a[0] - b[0]) + ((double)a[1] - b[1]) * (a[1] - b[1]) + ((double)a[2] - b[2]) * (a[2] - b[2]));
        moved[i] = memcmp(a, b, 3 * sizeof(float)) != 0;
        v->moved += moved[i];
        if (d > v->farthest) v->farthest = d;
    }
    for (e = 0; e < el->n; ++e)
        if (feature[e]) fvert[el->v[2 * e]] = fvert[el->v[2 * e + 1]] = 1;
    for (i = 0; i < m->nv; ++i)
        if (fvert[i]) {
            region_stats *s = &v->st[region_of(m->pos + 3 * i)];
            s->vertices++;
            s->h_before += fabs(h0[i]);
            s->h_after += fabs(v->h[i]);
        }
    for (k = 0; k < R_KINDS; ++k) {
        region_stats *s = &v->st[k];
        int ni = 0;
        if (s->vertices) { s->h_before /= s->vertices; s->h_after /= s->vertices; }
        for (e = 0; e < el->n; ++e) {
            const int *fa = m->tri + 3 * el->f[2 * e], *fb = m->tri + 3 * el->f[2 * e + 1];
            int ma = 0, mb = 0, c;
            double a0, a1;
            if (region_of(m->pos + 3 * el->v[2 * e]) != k) continue;
            a0 = dihedral(m->pos, m->tri, el, e);
            a1 = dihedral(v->pos, m->tri, el, e);
            if (a0 > s->sharp_before) s->sharp_before = a0;
            if (a1 > s->sharp_after) s->sharp_after = a1;
            if (a1 - a0 > s->fold_max) s->fold_max = a1 - a0;
            if (a1 > FOLD && a1 > a0) s->folds++;
            for (c = 0; c < 3; ++c) { ma += moved[fa[c]]; mb += moved[fb[c]]; }
            if (ma == 3 && mb == 3) inner[ni++] = a1;
            else if ((ma > 0 || mb > 0) && (ma < 3 || mb < 3)) {
                s->linkage_edges++;
                if (a1 > s->linkage_max) s->linkage_max = a1;
            }
        }
        qsort(inner, (size_t)ni, sizeof *inner, cmp_double);
        s->fillet_edges = ni;
        s->fillet_p95 = ni ? inner[(size_t)(0.95 * (ni - 1))] : 0.0;
    }
    free(moved);
    free(fvert);
    free(inner);
    return 1;
}

static void print_stats(const variant *v) {
    int k;
    printf("  %s: %d curves, %d vertices moved, the farthest by %.3f (%.2f r)\n", v->name, v->curves, v->moved, v->farthest,
           v->farthest / RADIUS);
    for (k = 0; k < v->report.curve_count; ++k) {
        const sfb_fillet_curve_report *c = &v->report.curves[k];
        printf("    curve %2d: %-6s %-7s %3d vertices, spine %7.3f, %5d samples, %4d moved, %2d loops cut, deviation %.2g\n", k,
               c->closed ? "closed" : "open", c->convex ? "convex" : "concave", c->curve_vertices, c->spine_length, c->samples,
               c->vertices_moved, c->self_intersections, c->max_deviation);
    }
    printf("    %-15s %5s %16s %18s %6s %9s %24s\n", "region", "verts", "mean |H| bef/aft", "sharpest edge deg", "folds", "most grew",
           "linkage max / fillet p95");
    for (k = 0; k < R_KINDS; ++k) {
        const region_stats *s = &v->st[k];
        printf("    %-15s %5d %7.2f -> %6.2f %7.1f -> %7.1f %6d %9.1f %14.2f / %6.2f\n", region_name[k], s->vertices, s->h_before, s->h_after,
               s->sharp_before, s->sharp_after, s->folds, s->fold_max, s->linkage_max, s->fillet_p95);
    }
}

/* ---- pictures ---- */
typedef struct view { float yaw, pitch, zoom, stripes; float centre[3], half; } view; /* half 0: the whole mesh */

/* The faces a view draws: all of them, or those inside its box both on the input's positions and on
 * `pos` (a spike that leaves the box is cut off, the frame stays), and two degenerate triangles (not
 * drawn) at the corners of the box (the whole mesh: of the input's bounding box), so that every
 * column frames the same box. Returns the face count. */
static int view_faces(const fs_mesh *m, const float *pos, const view *vw, int *tri, float *extra) {
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    int f, c, k, n = 0;
    for (f = 0; f < m->nf; ++f) {
        int inside = 1;
        for (c = 0; c < 3 && vw->half > 0; ++c)
            for (k = 0; k < 3; ++k)
                if (fabsf(m->pos[3 * m->tri[3 * f + c] + k] - vw->centre[k]) > vw->half ||
                    fabsf(pos[3 * m->tri[3 * f + c] + k] - vw->centre[k]) > vw->half)
                    inside = 0;
        if (!inside) continue;
        memcpy(tri + 3 * n, m->tri + 3 * f, 3 * sizeof(int));
        ++n;
    }
    for (k = 0; k < 3; ++k) {
        if (vw->half > 0) {
            lo[k] = vw->centre[k] - vw->half;
            hi[k] = vw->centre[k] + vw->half;
        } else
            for (c = 0; c < m->nv; ++c) {
                if (m->pos[3 * c + k] < lo[k]) lo[k] = m->pos[3 * c + k];
                if (m->pos[3 * c + k] > hi[k]) hi[k] = m->pos[3 * c + k];
            }
    }
    memcpy(extra, lo, sizeof lo);
    memcpy(extra + 3, hi, sizeof hi);
    for (k = 0; k < 2; ++k) tri[3 * (n + k)] = tri[3 * (n + k) + 1] = tri[3 * (n + k) + 2] = m->nv + k;
    return n + 2;
}

/* Renders the faces `tri` (z up in the shape, y up for sfb_render: (x, y, z) -> (x, z, -y), a
 * rotation) with highlight lines from `normals`, or the signed mean curvature `h` as colour:
 * |H| = 1/r (twice the ball's 1/(2r)) at the ends of the map. */
static int render_tile(sfb_context *ctx, int nv, const float *pos, const float *extra, int nf, const int *tri, const float *normals,
                       const float *h, const view *vw, sfb_image *img) {
    const int nvx = nv + 2;
    float *p = (float *)malloc(sizeof(float) * 3 * (size_t)nvx), *n = (float *)malloc(sizeof(float) * 3 * (size_t)nvx);
    float *s = (float *)malloc(sizeof(float) * (size_t)nvx);
    int *sizes = (int *)malloc(sizeof(int) * (size_t)nf);
    sfb_mesh_data data;
    sfb_render_config rc = sfb_render_config_init(h ? SFB_RENDER_WEIGHTS : SFB_RENDER_HIGHLIGHT);
    int i, ok = 0;
    if (!p || !n || !s || !sizes) { fprintf(stderr, "06_fillet_panel: out of memory\n"); goto done; }
    for (i = 0; i < nvx; ++i) {
        const float *q = i < nv ? pos + 3 * i : extra + 3 * (i - nv);
        const float *nq = i < nv ? normals + 3 * i : NULL;
        p[3 * i] = q[0]; p[3 * i + 1] = q[2]; p[3 * i + 2] = -q[1];
        n[3 * i] = nq ? nq[0] : 0.0f; n[3 * i + 1] = nq ? nq[2] : 1.0f; n[3 * i + 2] = nq ? -nq[1] : 0.0f;
        if (h) {
            const double t = i < nv ? 0.5 + 0.5 * h[i] * RADIUS : 0.5;
            s[i] = (float)(t < 0 ? 0 : t > 1 ? 1 : t);
        }
    }
    for (i = 0; i < nf; ++i) sizes[i] = 3;
    memset(&data, 0, sizeof data);
    data.vertex_count = nvx;
    data.positions = p;
    data.normals = n;
    data.face_count = nf;
    data.face_sizes = sizes;
    data.face_vertices = (int *)tri;
    data.face_vertex_count = 3 * nf;
    rc.width = TILE_W;
    rc.height = TILE_H;
    rc.view_set = 1;
    rc.yaw = vw->yaw;
    rc.pitch = vw->pitch;
    rc.zoom = vw->zoom;
    rc.stripes = vw->stripes;
    if (h) rc.scalars = s;
    if (sfb_render(ctx, &data, &rc, img) != SFB_SUCCESS) { fprintf(stderr, "06_fillet_panel: %s\n", sfb_last_error(ctx)); goto done; }
    ok = 1;
done:
    free(p); free(n); free(s); free(sizes);
    return ok;
}

static void blit(unsigned char *panel, int W, const sfb_image *img, int x0, int y0) {
    int y;
    for (y = 0; y < img->height; ++y)
        memcpy(panel + 4 * ((size_t)(y0 + y) * (size_t)W + (size_t)x0), img->rgba + 4 * (size_t)y * (size_t)img->width, 4 * (size_t)img->width);
}

static void usage(FILE *f) {
    fprintf(f, "usage: 06_fillet_panel [OUT.png]\n"
               "  Rolling-ball fillets (seed 002): a box with a cylinder on top, every feature found by dihedral angle --\n"
               "  the concave seam, the cylinder's rim, the box's edges and its corners (the ball's sphere) -- with r = 0.15\n"
               "  (after) and, for the picture, r = 0.25; before and after with highlight lines, the signed mean\n"
               "  curvature and close-ups. Prints per region the mean |H|, the sharpest edge, folds and the normal jump\n"
               "  across the linkage curves. Without OUT.png it only measures \"after\". Exit status 1 when the fillet\n"
               "  fails or is not smooth (the picture is still written).\n");
}

int main(int argc, char **argv) {
    /* rows: the whole shape with highlight lines, with the mean curvature; the seam close up
     * (highlight lines); a box corner close up (mean curvature) */
    static const view views[ROWS] = {{30.0f, 28.0f, 1.15f, 10.0f, {0, 0, 0}, 0.0f},
                                     {30.0f, 28.0f, 1.15f, 10.0f, {0, 0, 0}, 0.0f},
                                     {30.0f, 30.0f, 1.45f, 8.0f, {0.1f, -0.5f, 0.12f}, 0.32f},
                                     {30.0f, 30.0f, 1.2f, 8.0f, {0.72f, -0.72f, -0.28f}, 0.36f}};
    static const char *const row_name[ROWS] = {"highlight lines", "mean curvature", "seam close-up - highlight lines",
                                               "corner close-up - mean curvature"};
    const char *outp = NULL;
    const int W = COLS * TILE_W, H = ROWS * TILE_H;
    unsigned char *panel = NULL, *feature = NULL;
    sfb_context *ctx = NULL;
    sfb_mesh *in = NULL;
    fs_mesh fm;
    edge_list el;
    variant var[COLS];
    float *n0 = NULL, *h0 = NULL;
    int *vtri = NULL;
    int status = 1, i, k, e, col, row;
    sfb_result r;
    memset(&fm, 0, sizeof fm);
    memset(&el, 0, sizeof el);
    memset(var, 0, sizeof var);
    if (argc == 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) { usage(stdout); return 0; }
    if (argc > 2 || (argc == 2 && argv[1][0] == '-')) { usage(stderr); return 2; }
    if (argc == 2) outp = argv[1];
    if (sfb_context_create(NULL, &ctx) != SFB_SUCCESS) { fprintf(stderr, "06_fillet_panel: no context\n"); return 1; }
    if (fs_box_cylinder(&fm, SHAPE_N, HALF, HEIGHT, CYL_R, CYL_H) != 0 || fs_to_mesh(ctx, &fm, &in) != SFB_SUCCESS) {
        fprintf(stderr, "06_fillet_panel: cannot build the box-cylinder mesh\n");
        goto done;
    }
    n0 = (float *)malloc(sizeof(float) * 3 * (size_t)fm.nv);
    h0 = (float *)malloc(sizeof(float) * (size_t)fm.nv);
    feature = (unsigned char *)calloc((size_t)3 * fm.nf, 1);
    if (!n0 || !h0 || !feature || !build_edges(fm.nv, fm.nf, fm.tri, &el)) { fprintf(stderr, "06_fillet_panel: out of memory\n"); goto done; }
    for (e = 0; e < el.n; ++e) feature[e] = dihedral(fm.pos, fm.tri, &el, e) > FEATURE_ANGLE;
    if (sfb_mesh_vertex_normals(ctx, in, n0) != SFB_SUCCESS || sfb_mesh_mean_curvature(ctx, in, h0) != SFB_SUCCESS) {
        fprintf(stderr, "06_fillet_panel: %s\n", sfb_last_error(ctx));
        goto done;
    }
    printf("fillet (seed 002): box %gx%gx%g with a cylinder r=%g h=%g on top, %d vertices, %d triangles; ball radius r=%g;\n"
           "  features: edges over %g deg\n",
           2 * HALF, 2 * HALF, HEIGHT, CYL_R, CYL_H, fm.nv, fm.nf, RADIUS, FEATURE_ANGLE);
    var[0].name = "before";
    var[0].title = "before";
    var[0].mesh = in;
    var[0].pos = fm.pos;
    var[0].n = n0;
    var[0].h = h0;
    var[1].name = "after (every feature by angle, r = 0.15)";
    var[1].title = "after - r = 0.15";
    var[2].name = "after (every feature by angle, r = 0.25)";
    var[2].title = "after - r = 0.25";
    status = 0;
    for (col = 1; col < COLS; ++col) {
        variant *v = &var[col];
        sfb_fillet_config cfg = sfb_fillet_config_init(col == 1 ? RADIUS : RADIUS2);
        sfb_fillet_report rep;
        sfb_mesh_desc d;
        memset(&rep, 0, sizeof rep);
        if (col == 2 && !outp) break; /* the larger ball: for the picture only */
        cfg.angle = FEATURE_ANGLE;
        r = sfb_mesh_fillet(ctx, in, &cfg, &v->mesh, &rep);
        if (r != SFB_SUCCESS) {
            printf("  FAILED: %s: sfb_mesh_fillet: %s: %s\n", v->name, sfb_result_string(r), sfb_last_error(ctx));
            status = 1;
            continue;
        }
        printf("  %s: %d corners rounded (%d vertices on their spheres)\n", v->name, rep.corner_count, rep.corner_vertices_moved);
        if (rep.corner_count != 8) {
            printf("  FAILED: %s: %d of the box's 8 corners rounded\n", v->name, rep.corner_count);
            status = 1;
        }
        v->curves = rep.curve_count;
        v->report = rep;
        sfb_mesh_get_desc(v->mesh, &d);
        v->pos = d.positions;
        v->n = (float *)malloc(sizeof(float) * 3 * (size_t)fm.nv);
        v->h = (float *)malloc(sizeof(float) * (size_t)fm.nv);
        if (!v->n || !v->h) { fprintf(stderr, "06_fillet_panel: out of memory\n"); status = 1; goto done; }
        if (sfb_mesh_vertex_normals(ctx, v->mesh, v->n) != SFB_SUCCESS || sfb_mesh_mean_curvature(ctx, v->mesh, v->h) != SFB_SUCCESS) {
            fprintf(stderr, "06_fillet_panel: %s\n", sfb_last_error(ctx));
            status = 1;
            goto done;
        }
        if (!measure(&fm, &el, feature, h0, v)) { fprintf(stderr, "06_fillet_panel: out of memory\n"); status = 1; goto done; }
        print_stats(v);
    }
    printf("  ideal |H| on a ball-radius fillet: 1/(2r) = %.2f\n", 0.5 / RADIUS);
    if (var[1].mesh) {
        const region_stats *s = var[1].st;
        /* a 90-degree edge's vertex moves r (sqrt 2 - 1) onto the ball's arc, a corner r (sqrt 3 - 1); none r */
        if (!(var[1].farthest < RADIUS)) {
            printf("  FAILED: after: a vertex moved %.3f, farther than the ball's radius %g (a spike)\n", var[1].farthest, RADIUS);
            status = 1;
        }
        for (k = 0; k < R_KINDS; ++k) {
            if ((!(s[k].h_after > 0) || s[k].h_before / s[k].h_after < 2.0 || !(s[k].sharp_after < FEATURE_ANGLE))) {
                printf("  FAILED: after: %s: mean |H| %.3f -> %.3f (want 2x lower), sharpest edge %.1f deg (want < %g)\n", region_name[k],
                       s[k].h_before, s[k].h_after, s[k].sharp_after, FEATURE_ANGLE);
                status = 1;
            }
            if ((k == R_SEAM || k == R_RIM) && (s[k].linkage_edges == 0 || s[k].linkage_max - s[k].fillet_p95 > 2.0)) {
                printf("  FAILED: after: %s: the normals jump across the linkage curves by %.2f deg (inside the fillet %.2f)\n", region_name[k],
                       s[k].linkage_max, s[k].fillet_p95);
                status = 1;
            }
            if (s[k].folds) {
                printf("  FAILED: after: %s: %d edges fold (dihedral grows by up to %.1f deg)\n", region_name[k], s[k].folds, s[k].fold_max);
                status = 1;
            }
        }
    }
    if (var[2].mesh) {
        int folds = 0;
        for (k = 0; k < R_KINDS; ++k) folds += var[2].st[k].folds;
        if (folds || !(var[2].farthest < RADIUS2)) {
            printf("  FAILED: %s: %d edges folded back (dihedral > %g deg), a vertex moved %.3f (r = %g)\n", var[2].name, folds, FOLD,
                   var[2].farthest, RADIUS2);
            status = 1;
        }
    }

    if (outp && var[1].mesh) {
        /* drawn also when a check failed (the picture shows what went wrong); exit status 1 then */
        float extra[6];
        int drawn = 1;
        if (!(panel = (unsigned char *)calloc((size_t)W * (size_t)H, 4)) || !(vtri = (int *)malloc(sizeof(int) * 3 * ((size_t)fm.nf + 2)))) {
            fprintf(stderr, "06_fillet_panel: out of memory\n");
            status = 1;
            goto done;
        }
        for (row = 0; row < ROWS; ++row)
            for (col = 0; col < COLS; ++col) {
                const variant *v = &var[col];
                const int curvature = row == 1 || row == 3;
                int nf;
                sfb_image img;
                if (!v->mesh) { /* the fillet failed (printed) */
                    label(panel, W, H, col * TILE_W + 8, row * TILE_H + 8, "fillet failed");
                    continue;
                }
                nf = view_faces(&fm, v->pos, &views[row], vtri, extra);
                memset(&img, 0, sizeof img);
                if (!render_tile(ctx, fm.nv, v->pos, extra, nf, vtri, v->n, curvature ? v->h : NULL, &views[row], &img)) {
                    drawn = 0;
                    continue;
                }
                blit(panel, W, &img, col * TILE_W, row * TILE_H);
                sfb_image_free(&img);
                label(panel, W, H, col * TILE_W + 8, row * TILE_H + 8, v->title);
                label(panel, W, H, col * TILE_W + 8, row * TILE_H + 30, row_name[row]);
                if (row == 1 && col == 0) label(panel, W, H, 8, row * TILE_H + TILE_H - 24, "h: blue -1/r  green 0  red +1/r");
            }
        for (i = 1; i < COLS; ++i) /* thin separators between the columns */
            for (row = 0; row < H; ++row) {
                unsigned char *p = panel + 4 * ((size_t)row * (size_t)W + (size_t)i * TILE_W);
                p[0] = p[1] = p[2] = 140;
                p[3] = 255;
            }
        if (!drawn) status = 1;
        else {
            /* written under a temporary name, renamed when complete: no partial file */
            char tmp[4096];
            snprintf(tmp, sizeof tmp, "%s.part", outp);
            if (strlen(outp) + 6 > sizeof tmp || !stbi_write_png(tmp, W, H, 4, panel, W * 4) || rename(tmp, outp) != 0) {
                fprintf(stderr, "06_fillet_panel: cannot write %s\n", outp);
                remove(tmp);
                status = 1;
            } else printf("wrote %s (%dx%d)%s\n", outp, W, H, status ? ", but a check FAILED (above)" : "");
        }
    }
done:
    free(panel);
    free(vtri);
    for (col = 1; col < COLS; ++col) {
        sfb_fillet_report_free(&var[col].report);
        free(var[col].n);
        free(var[col].h);
        sfb_mesh_destroy(var[col].mesh);
    }
    free(n0); free(h0); free(feature);
    free_edges(&el);
    sfb_mesh_destroy(in);
    fs_free(&fm);
    sfb_context_destroy(ctx);
    return status;
}
