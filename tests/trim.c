/* Trimming of tessellations (sfb_surface_tessellate with a sfb_trim_mask, src/tess.c) on every
 * backend, ref first. The masks are read here through this test's own implementation of their
 * documented meaning (bilinear between texel centres, indices clamped, kept where >= 0.5), and
 * a triangle's corners are taken into its own face's (u,v) through the base mesh (a corner may
 * be located on a neighbour: a shared base vertex, base edge point, n-gon spoke or centroid).
 * Checks, each on every backend:
 *   - kept (u,v) area of every param face against the mask's, within one texel's worth
 *     (1/width): a half-black mask (16x16, 64x64, 37x5) keeps 1/2 of a quad (Catmull-Clark
 *     quads and n-gon sub-faces; (1-c)^2/2 of a Loop triangle), a disc its sampled area, a 2x2
 *     atlas (black, white, half, quarter) 0, 1, 1/2, 3/4 and faces past its last tile 1;
 *   - 3-D area of the inner faces of a planar regular grid (an affine image of (u,v)) equal to
 *     their kept (u,v) area, so it halves under the half mask;
 *   - the cut: every vertex of a boundary edge inside its face's (u,v) domain (a new one) has
 *     mask 0.5 within 1e-4, and lies within one texel of the half mask's line u = c or of the
 *     disc's circle;
 *   - nothing trimmed kept: every kept triangle's centroid has mask >= 0.5 - 1e-6 on straight
 *     contours and >= 0.4 where the contour bends inside a cell (disc, quarter: the straight
 *     cut leaves a sliver there), and 7 points of every kept triangle lie within one texel of
 *     where the mask keeps;
 *   - watertight: no edge used by more than 2 triangles nor twice in one direction; on closed
 *     meshes with a disc per face every boundary edge is a cut (both ends on the contour); on
 *     the open grid with disc holes, and with a band whose contours cross the seams between
 *     faces away from any grid point (the faces must share those cut points), every boundary
 *     edge is a cut or lies on the base mesh's boundary;
 *   - an all-white mask gives the untrimmed tessellation exactly, an all-black one (127) none;
 *   - agreement: the same topology and locations as ref, positions within 1e-4 x the bounding
 *     box diagonal, normals within 1e-3 rad;
 *   - bad masks (SFB_INVALID_VALUE, `out` zeroed, a message), failing allocations
 *     (SFB_OUT_OF_MEMORY) and cancellation at every progress report (SFB_CANCELLED), both
 *     leaving `out` zeroed and nothing leaked, progress in order.
 * A backend that is unavailable SKIPs (FAILs when listed in SFB_REQUIRE_BACKENDS). Usage:
 * trim [SHAPES_DIR] (OpenSubdiv's loop_cube.obj is read from there when present). */
#define SURFBLEND_EXPOSE_INTERNALS /* the internals below have external linkage in libsfb_internal.o */
#include "surfblend.h"
#include "src/sfb_internal.h" /* the library's internal interfaces (linked from libsfb_internal.o) */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
static double g_agree_pos[4], g_agree_nrm[4]; /* largest differences from ref, per backend (position / diagonal, rad) */

/* ---- masks, as sfb_api.h documents them ---- */

typedef struct mask {
    int w, h, tu, tv;     /* texels; atlas tiles (0/0: one mask) */
    unsigned char *t;
} mask;

static mask mask_new(int w, int h) {
    mask m;
    m.w = w; m.h = h; m.tu = m.tv = 0;
    m.t = (unsigned char *)calloc((size_t)w * (size_t)h, 1);
    return m;
}

static sfb_trim_mask mask_api(const mask *m) {
    sfb_trim_mask a;
    memset(&a, 0, sizeof a);
    a.width = m->w; a.height = m->h; a.texels = m->t; a.tiles_u = m->tu; a.tiles_v = m->tv;
    return a;
}

/* The tile of param face pf: first texel, size; 0 when the face is not trimmed. */
static int mask_tile(const mask *m, int pf, const unsigned char **tile, int *tw, int *th) {
    int atlas = m->tu > 1 || m->tv > 1, nu = atlas ? m->tu : 1, nv = atlas ? m->tv : 1;
    if (atlas && pf >= nu * nv) return 0; /* past the last tile */
    if (!atlas) pf = 0;
    *tw = m->w / nu;
    *th = m->h / nv;
    *tile = m->t + (size_t)(pf / nu) * (size_t)(*th) * (size_t)m->w + (size_t)(pf % nu) * (size_t)(*tw);
    return 1;
}

static int clampi(int i, int n) { return i < 0 ? 0 : i >= n ? n - 1 : i; }

/* The mask value in [0,1] at (u,v) of param face pf (1 where the face is not trimmed):
 * texel centres at ((i + 1/2)/tw, (j + 1/2)/th), interpolated bilinearly, indices clamped. */
static double mask_at(const mask *m, int pf, double u, double v) {
    const unsigned char *tile;
    int tw, th, i, j, i0, i1, j0, j1;
    double x, y, fx, fy, a, b;
    if (!mask_tile(m, pf, &tile, &tw, &th)) return 1.0;
    x = u * tw - 0.5; y = v * th - 0.5;
    i = (int)floor(x); j = (int)floor(y);
    fx = x - i; fy = y - j;
    i0 = clampi(i, tw); i1 = clampi(i + 1, tw); j0 = clampi(j, th); j1 = clampi(j + 1, th);
    a = tile[(size_t)j0 * m->w + i0] + fx * (tile[(size_t)j0 * m->w + i1] - tile[(size_t)j0 * m->w + i0]);
    b = tile[(size_t)j1 * m->w + i0] + fx * (tile[(size_t)j1 * m->w + i1] - tile[(size_t)j1 * m->w + i0]);
    return (a + fy * (b - a)) / 255.0;
}

/* Whether a point of param face pf lies within one texel of where the mask keeps: the mask
 * there, or at 32 points on each of the circles of 1/2 and 1 texel around it. */
static int near_kept(const mask *m, int pf, double u, double v) {
    const unsigned char *tile;
    int tw, th, k, r;
    if (!mask_tile(m, pf, &tile, &tw, &th) || mask_at(m, pf, u, v) >= 0.5) return 1;
    for (r = 1; r <= 2; ++r)
        for (k = 0; k < 32; ++k) {
            double a = 2.0 * 3.14159265358979 * k / 32;
            if (mask_at(m, pf, u + 0.5 * r * cos(a) / tw, v + 0.5 * r * sin(a) / th) >= 0.5) return 1;
        }
    return 0;
}

/* Fills the tile rectangle [x0,x0+tw) x [y0,y0+th) by a rule on texel centres (s,t) in [0,1]^2. */
enum { FILL_WHITE, FILL_BLACK, FILL_HALF, FILL_QUARTER, FILL_DISC, FILL_HOLE, FILL_BAND };
typedef struct fill { int kind; double cx, cy, r; } fill;
static void mask_fill(mask *m, int x0, int y0, int tw, int th, fill f) {
    int i, j;
    for (j = 0; j < th; ++j)
        for (i = 0; i < tw; ++i) {
            double s = (i + 0.5) / tw, t = (j + 0.5) / th, d = hypot(s - f.cx, t - f.cy);
            int white = 1;
            if (f.kind == FILL_BLACK) white = 0;
            else if (f.kind == FILL_HALF) white = !(s < 0.5);
            else if (f.kind == FILL_QUARTER) white = !(s < 0.5 && t < 0.5);
            else if (f.kind == FILL_DISC) white = d < f.r;
            else if (f.kind == FILL_HOLE) white = !(d < f.r);
            else if (f.kind == FILL_BAND) white = fabs(s - 0.5) < f.r;
            m->t[(size_t)(y0 + j) * m->w + x0 + i] = (unsigned char)(white ? 255 : 0);
        }
}

static fill fill_of(int kind) { fill f; f.kind = kind; f.cx = f.cy = 0.5; f.r = 0.3; return f; }

/* Kept (u,v) area of a param face under its mask, by sampling an n x n grid of cell centres
 * (triangles: the half u + v < 1). */
static double sampled_area(const mask *m, int pf, int loop, int n) {
    int i, j;
    long kept = 0;
    for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) {
            double u = (i + 0.5) / n, v = (j + 0.5) / n;
            if (loop && u + v >= 1.0) continue;
            if (mask_at(m, pf, u, v) >= 0.5) kept++;
        }
    return (double)kept / ((double)n * n);
}

/* ---- meshes ---- */

/* An n x n grid of unit squares in the plane z = 0, counter-clockwise seen from +z. */
static char *grid_obj(int n) {
    size_t cap = 64 * (size_t)(n + 1) * (size_t)(n + 1) + 64 * (size_t)n * (size_t)n, at = 0;
    char *s = (char *)malloc(cap);
    int i, j;
    for (j = 0; j <= n; ++j)
        for (i = 0; i <= n; ++i) at += (size_t)snprintf(s + at, cap - at, "v %d %d 0\n", i, j);
    for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) {
            int a = j * (n + 1) + i + 1;
            at += (size_t)snprintf(s + at, cap - at, "f %d %d %d %d\n", a, a + 1, a + n + 2, a + n + 1);
        }
    return s;
}

static const char *cube_obj =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n";

/* a pentagonal prism: two pentagons and five quads */
static const char *prism_obj =
    "v 1 0 -1\nv 0.309017 0.951057 -1\nv -0.809017 0.587785 -1\nv -0.809017 -0.587785 -1\nv 0.309017 -0.951057 -1\n"
    "v 1 0 1\nv 0.309017 0.951057 1\nv -0.809017 0.587785 1\nv -0.809017 -0.587785 1\nv 0.309017 -0.951057 1\n"
    "f 6 7 8 9 10\nf 5 4 3 2 1\n"
    "f 1 2 7 6\nf 2 3 8 7\nf 3 4 9 8\nf 4 5 10 9\nf 5 1 6 10\n";

static const char *octahedron_obj =
    "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
    "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

/* the cube with a closed loop of infinitely sharp edges around its top */
static const char *creased_cube_obj =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n"
    "t crease 2/1/0 0 1 10\nt crease 2/1/0 1 3 10\nt crease 2/1/0 3 2 10\nt crease 2/1/0 2 0 10\n";

static sfb_mesh *mesh_of(sfb_context *ctx, const char *obj) {
    sfb_mesh *m = NULL;
    if (sfb_mesh_read_obj(ctx, obj, strlen(obj), &m) != SFB_SUCCESS) return NULL;
    return m;
}

static sfb_surface *surface_of(sfb_context *ctx, const sfb_mesh *m, int loop) {
    sfb_surface_config c = sfb_surface_config_init(loop ? SFB_SCHEME_LOOP : SFB_SCHEME_CATMARK, 0);
    sfb_surface *s = NULL;
    c.flags = SFB_REFINE_PATCHES;
    if (sfb_surface_create(ctx, m, &c, &s) != SFB_SUCCESS) return NULL;
    return s;
}

/* ---- (u,v) of a tessellation vertex in any param face it lies on ----
 * Each param face's sides are named by what they lie on in the base mesh: a base edge a -> b
 * over the part [s0, s1] of it (from a), or a spoke of an n-gon (from the midpoint of its
 * edge i to the centroid). A point on a side is then a base vertex, a point of a base edge,
 * of a spoke, or a centroid, the same from every face that has it. */
typedef struct side { int spoke, a, b, g, i; double s0, s1, uv0[2], uv1[2]; } side;
typedef struct pface { int n, base, sub; side sd[4]; } pface;
enum { P_NONE, P_VERTEX, P_EDGE, P_SPOKE, P_CENTROID };
typedef struct cpt { int kind, a, b, g, i; double s; } cpt;

static side mkside(int spoke, int a, int b, int g, int i, double s0, double s1, double u0, double v0, double u1, double v1) {
    side s;
    s.spoke = spoke; s.a = a; s.b = b; s.g = g; s.i = i; s.s0 = s0; s.s1 = s1;
    s.uv0[0] = u0; s.uv0[1] = v0; s.uv1[0] = u1; s.uv1[1] = v1;
    return s;
}

static pface *param_faces(const sfb_surface *s, const sfb_mesh *m, int loop) {
    sfb_mesh_desc d;
    int np = sfb_surface_param_face_count(s), pf, *off, f;
    pface *P = (pface *)calloc((size_t)np + 1, sizeof *P);
    sfb_mesh_get_desc(m, &d);
    off = (int *)calloc((size_t)d.face_count + 1, sizeof(int));
    for (f = 0; f < d.face_count; ++f) off[f + 1] = off[f] + d.face_sizes[f];
    for (pf = 0; pf < np; ++pf) {
        int base, sub, n;
        const int *w;
        pface *q = &P[pf];
        sfb_surface_param_face_base(s, pf, &base, &sub);
        q->base = base; q->sub = sub;
        n = d.face_sizes[base];
        w = d.face_vertices + off[base];
        if (loop) {
            q->n = 3;
            q->sd[0] = mkside(0, w[0], w[1], base, 0, 0, 1, 0, 0, 1, 0);
            q->sd[1] = mkside(0, w[1], w[2], base, 1, 0, 1, 1, 0, 0, 1);
            q->sd[2] = mkside(0, w[2], w[0], base, 2, 0, 1, 0, 1, 0, 0);
        } else if (sub < 0) {
            q->n = 4;
            q->sd[0] = mkside(0, w[0], w[1], base, 0, 0, 1, 0, 0, 1, 0);
            q->sd[1] = mkside(0, w[1], w[2], base, 1, 0, 1, 1, 0, 1, 1);
            q->sd[2] = mkside(0, w[2], w[3], base, 2, 0, 1, 1, 1, 0, 1);
            q->sd[3] = mkside(0, w[3], w[0], base, 3, 0, 1, 0, 1, 0, 0);
        } else {
            int i = sub, ip = (sub + n - 1) % n, in = (sub + 1) % n;
            q->n = 4;
            q->sd[0] = mkside(0, w[i], w[in], base, i, 0, 0.5, 0, 0, 1, 0);
            q->sd[1] = mkside(1, w[i], w[in], base, i, 0, 1, 1, 0, 1, 1);   /* spoke i: from mid(w_i, w_i+1) */
            q->sd[2] = mkside(1, w[ip], w[i], base, ip, 0, 1, 0, 1, 1, 1); /* spoke i-1: from mid(w_i-1, w_i) */
            q->sd[3] = mkside(0, w[i], w[ip], base, ip, 0, 0.5, 0, 0, 0, 1);
        }
    }
    free(off);
    return P;
}

/* The base mesh's boundary: edges used by one face (sorted keys a << 32 | b, a < b), and
 * their vertices. */
typedef struct outline { unsigned long long *e; size_t n; unsigned char *v; } outline;
static int cmp_u64(const void *x, const void *y);
static outline outline_of(const sfb_mesh *m) {
    sfb_mesh_desc d;
    outline o;
    size_t k = 0, a, b, nfv = 0;
    int f, i, off = 0;
    unsigned long long *all;
    sfb_mesh_get_desc(m, &d);
    for (f = 0; f < d.face_count; ++f) nfv += (size_t)d.face_sizes[f];
    all = (unsigned long long *)malloc(sizeof *all * (nfv + 1));
    o.e = (unsigned long long *)malloc(sizeof *o.e * (nfv + 1));
    o.v = (unsigned char *)calloc((size_t)d.vertex_count + 1, 1);
    o.n = 0;
    for (f = 0; f < d.face_count; off += d.face_sizes[f], ++f)
        for (i = 0; i < d.face_sizes[f]; ++i) {
            unsigned long long p = (unsigned)d.face_vertices[off + i], q = (unsigned)d.face_vertices[off + (i + 1) % d.face_sizes[f]];
            all[k++] = p < q ? (p << 32 | q) : (q << 32 | p);
        }
    qsort(all, k, sizeof *all, cmp_u64);
    for (a = 0; a < k; a = b) {
        for (b = a; b < k && all[b] == all[a]; ++b) {}
        if (b - a == 1) {
            o.e[o.n++] = all[a];
            o.v[all[a] >> 32] = o.v[all[a] & 0xffffffffu] = 1;
        }
    }
    free(all);
    return o;
}

static cpt edge_point(int a, int b, double s) {
    cpt c;
    memset(&c, 0, sizeof c);
    if (s < 1e-6) { c.kind = P_VERTEX; c.a = a; return c; }
    if (s > 1.0 - 1e-6) { c.kind = P_VERTEX; c.a = b; return c; }
    c.kind = P_EDGE;
    if (a < b) { c.a = a; c.b = b; c.s = s; } else { c.a = b; c.b = a; c.s = 1.0 - s; }
    return c;
}

/* What (u,v) of face q lies on (P_NONE: inside it). */
static cpt canon(const pface *q, double u, double v) {
    int k;
    cpt c;
    memset(&c, 0, sizeof c);
    for (k = 0; k < q->n; ++k) {
        const side *sd = &q->sd[k];
        double dx = sd->uv1[0] - sd->uv0[0], dy = sd->uv1[1] - sd->uv0[1], len2 = dx * dx + dy * dy;
        double r = ((u - sd->uv0[0]) * dx + (v - sd->uv0[1]) * dy) / len2;
        double dist = fabs((u - sd->uv0[0]) * dy - (v - sd->uv0[1]) * dx) / sqrt(len2);
        if (dist > 1e-6 || r < -1e-6 || r > 1.0 + 1e-6) continue;
        if (!sd->spoke) return edge_point(sd->a, sd->b, sd->s0 + r * (sd->s1 - sd->s0));
        if (r > 1.0 - 1e-6) { c.kind = P_CENTROID; c.g = sd->g; return c; }
        if (r < 1e-6) return edge_point(sd->a, sd->b, 0.5);
        c.kind = P_SPOKE; c.g = sd->g; c.i = sd->i; c.s = r;
        return c;
    }
    c.kind = P_NONE;
    return c;
}

/* (u,v) in face q of a point named by canon(); 0 when q does not have it. */
static int uv_of(const pface *q, cpt c, double *uv) {
    int k;
    if (c.kind == P_CENTROID) {
        if (q->sub < 0 || q->base != c.g) return 0;
        uv[0] = uv[1] = 1.0;
        return 1;
    }
    for (k = 0; k < q->n; ++k) {
        const side *sd = &q->sd[k];
        double r = -1.0, sp;
        if (c.kind == P_SPOKE) {
            if (!sd->spoke || sd->g != c.g || sd->i != c.i) continue;
            r = c.s;
        } else if (c.kind == P_VERTEX) {
            if (sd->spoke) continue;
            if (sd->a == c.a && sd->s0 == 0.0) r = 0.0;
            else if (sd->b == c.a && sd->s1 == 1.0) r = 1.0;
            else continue;
        } else if (c.kind == P_EDGE) {
            if (sd->spoke) continue;
            if (sd->a == c.a && sd->b == c.b) sp = c.s;
            else if (sd->a == c.b && sd->b == c.a) sp = 1.0 - c.s;
            else continue;
            r = (sp - sd->s0) / (sd->s1 - sd->s0);
            if (r < -1e-6 || r > 1.0 + 1e-6) continue;
        } else {
            return 0;
        }
        uv[0] = sd->uv0[0] + r * (sd->uv1[0] - sd->uv0[0]);
        uv[1] = sd->uv0[1] + r * (sd->uv1[1] - sd->uv0[1]);
        return 1;
    }
    return 0;
}

/* Whether tessellation vertex vtx lies on the base mesh's boundary. */
static int on_outline(const pface *P, const outline *o, const sfb_tess_data *t, int vtx) {
    const sfb_location *l = &t->locations[vtx];
    cpt c = canon(&P[l->face], l->u, l->v);
    unsigned long long key;
    if (c.kind == P_VERTEX) return o->v[c.a];
    if (c.kind != P_EDGE) return 0;
    key = (unsigned long long)(unsigned)c.a << 32 | (unsigned)c.b;
    return o->n && bsearch(&key, o->e, o->n, sizeof key, cmp_u64) != NULL;
}

/* (u,v) of vertex vtx in param face f. */
static int vertex_uv(const pface *P, const sfb_tess_data *t, int vtx, int f, double *uv) {
    const sfb_location *l = &t->locations[vtx];
    if (l->face == f) { uv[0] = l->u; uv[1] = l->v; return 1; }
    return uv_of(&P[f], canon(&P[l->face], l->u, l->v), uv);
}

/* ---- one case: a mesh, a mask, what to expect ---- */

typedef struct expect {
    const char *name;
    int loop, rate;
    float tolerance;                /* adaptive */
    unsigned flags;
    double *area;                   /* per param face: expected kept (u,v) area (NULL: not checked) */
    double area_tol;                /* one texel's worth */
    int contour;                    /* 0: mask 0.5 only; 1: half (u = half_u); 2: disc (cx, cy, r); 3: band (u = cx +- r) */
    double half_u, cx, cy, r, texel;
    double centroid_tol;            /* mask at points of kept triangles >= 0.5 - this */
    int boundary;                   /* 0: not checked; 1: every boundary edge is a cut; 2: a cut or on the base mesh's boundary */
    int affine_n;                   /* > 0: an affine_n x affine_n grid whose inner faces map (u,v) affinely */
    int need_cut;                   /* the cut must make boundary vertices */
} expect;

static void sort_u64(unsigned long long *k, size_t n);

/* Every check of one trimmed tessellation. */
static void check_result(const char *be, const expect *E, const mask *M, const sfb_surface *s, const pface *P, const outline *O,
                         const sfb_tess_data *t) {
    char nm[512];
    int np = sfb_surface_param_face_count(s), i, c, bad = 0, conv_bad = 0, nb_cut = 0, bad_contour = 0, bad_geo = 0, bad_bnd = 0;
    double *area = (double *)calloc((size_t)np + 1, sizeof(double)), *area3 = (double *)calloc((size_t)np + 1, sizeof(double));
    double worst_area = 0.0, worst_area3 = 0.0, min_centroid = 1.0, worst_mask = 0.0, worst_geo = 0.0;
    long far_trimmed = 0;
    int worst_face = -1;
    unsigned char *used = (unsigned char *)calloc((size_t)t->vertex_count + 1, 1);
    unsigned long long *keys = (unsigned long long *)malloc(sizeof(unsigned long long) * (3 * (size_t)t->triangle_count + 1));
    unsigned long long *dkeys = (unsigned long long *)malloc(sizeof(unsigned long long) * (3 * (size_t)t->triangle_count + 1));
    size_t nk = 3 * (size_t)t->triangle_count, a, b;
    long once = 0, more = 0, ddup = 0;
    /* validity */
    for (i = 0; i < t->triangle_count && !bad; ++i) {
        if (t->triangle_faces[i] < 0 || t->triangle_faces[i] >= np) bad = 1;
        for (c = 0; c < 3; ++c) {
            int v = t->triangles[3 * i + c];
            if (v < 0 || v >= t->vertex_count) bad = 1; else used[v] = 1;
        }
    }
    for (i = 0; i < t->vertex_count && !bad; ++i) {
        const sfb_location *l = &t->locations[i];
        const float *n = t->normals + 3 * (size_t)i, *p = t->positions + 3 * (size_t)i;
        double ln = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (!used[i] || l->face < 0 || l->face >= np || !(l->u >= 0.0f && l->u <= 1.0f && l->v >= 0.0f && l->v <= 1.0f) ||
            (E->loop && (double)l->u + l->v > 1.0) || !isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]) || fabs(ln - 1.0) > 1e-3)
            bad = 2 + i;
    }
    snprintf(nm, sizeof nm, "%s/%s/valid: indices, every vertex used, locations, unit normals", be, E->name);
    check(!bad, nm, "problem %d (%d vertices, %d triangles)", bad, t->vertex_count, t->triangle_count);
    if (bad) goto done;
    /* (u,v) of every corner in its triangle's face: areas, orientation, samples of the mask */
    for (i = 0; i < t->triangle_count; ++i) {
        int f = t->triangle_faces[i], ok = 1, q;
        double uv[3][2], a2, x[3][3];
        static const double bary[7][3] = { { 1 / 3.0, 1 / 3.0, 1 / 3.0 }, { 0.6, 0.2, 0.2 }, { 0.2, 0.6, 0.2 }, { 0.2, 0.2, 0.6 },
                                           { 0.45, 0.45, 0.1 }, { 0.1, 0.45, 0.45 }, { 0.45, 0.1, 0.45 } };
        for (c = 0; c < 3; ++c) {
            int v = t->triangles[3 * i + c];
            ok &= vertex_uv(P, t, v, f, uv[c]);
            x[c][0] = t->positions[3 * (size_t)v]; x[c][1] = t->positions[3 * (size_t)v + 1]; x[c][2] = t->positions[3 * (size_t)v + 2];
        }
        if (!ok) { conv_bad++; continue; }
        a2 = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[1][1] - uv[0][1]) * (uv[2][0] - uv[0][0]);
        if (!(a2 > 0.0)) conv_bad++;
        area[f] += 0.5 * a2;
        {
            double e1[3], e2[3], cr[3];
            for (c = 0; c < 3; ++c) { e1[c] = x[1][c] - x[0][c]; e2[c] = x[2][c] - x[0][c]; }
            cr[0] = e1[1] * e2[2] - e1[2] * e2[1]; cr[1] = e1[2] * e2[0] - e1[0] * e2[2]; cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
            area3[f] += 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
        }
        for (q = 0; q < 7; ++q) {
            double u = bary[q][0] * uv[0][0] + bary[q][1] * uv[1][0] + bary[q][2] * uv[2][0];
            double v = bary[q][0] * uv[0][1] + bary[q][1] * uv[1][1] + bary[q][2] * uv[2][1];
            double mv = mask_at(M, f, u, v);
            if (q == 0 && mv < min_centroid) min_centroid = mv;
            if (mv < 0.5 && !near_kept(M, f, u, v)) far_trimmed++;
        }
    }
    snprintf(nm, sizeof nm, "%s/%s/every corner in its face's (u,v), counter-clockwise", be, E->name);
    check(conv_bad == 0, nm, "%d triangles with a corner off their face or not counter-clockwise", conv_bad);
    snprintf(nm, sizeof nm, "%s/%s/kept triangles' centroids: mask >= 0.5 - %g", be, E->name, E->centroid_tol);
    check(min_centroid >= 0.5 - E->centroid_tol, nm, "lowest mask %.6f", min_centroid);
    snprintf(nm, sizeof nm, "%s/%s/nothing trimmed kept: 7 points of every kept triangle within one texel of the kept region", be, E->name);
    check(far_trimmed == 0, nm, "%ld points farther", far_trimmed);
    if (!strcmp(be, "ref")) printf("# %s: lowest centroid mask %.4f\n", E->name, min_centroid);
    if (E->area) {
        for (i = 0; i < np; ++i) {
            double d = fabs(area[i] - E->area[i]);
            if (d > worst_area) { worst_area = d; worst_face = i; }
        }
        snprintf(nm, sizeof nm, "%s/%s/kept (u,v) area per face within %.4g", be, E->name, E->area_tol);
        check(worst_area <= E->area_tol, nm, "face %d keeps %.6f, mask %.6f", worst_face, worst_face >= 0 ? area[worst_face] : 0.0,
              worst_face >= 0 ? E->area[worst_face] : 0.0);
        if (g_be[0].name == be || !strcmp(be, "ref")) printf("# %s: largest kept-area error %.3g (tolerance %.3g)\n", E->name, worst_area, E->area_tol);
    }
    if (E->affine_n > 0 && E->area) {
        int n = E->affine_n, fi, fj, cnt = 0;
        for (fj = 1; fj < n - 1; ++fj)
            for (fi = 1; fi < n - 1; ++fi) {
                int f = fj * n + fi;
                double d = fabs(area3[f] - E->area[f]);
                if (d > worst_area3) worst_area3 = d;
                cnt++;
            }
        snprintf(nm, sizeof nm, "%s/%s/3-D area of the %d inner (affine) faces within %.4g", be, E->name, cnt, E->area_tol);
        check(cnt > 0 && worst_area3 <= E->area_tol, nm, "largest difference %.6f", worst_area3);
    }
    /* edges: uses, directions, the boundary */
    for (i = 0; i < t->triangle_count; ++i)
        for (c = 0; c < 3; ++c) {
            unsigned long long p = (unsigned)t->triangles[3 * i + c], q = (unsigned)t->triangles[3 * i + (c + 1) % 3];
            keys[3 * i + c] = p < q ? (p << 32 | q) : (q << 32 | p);
            dkeys[3 * i + c] = p << 32 | q;
        }
    sort_u64(keys, nk);
    sort_u64(dkeys, nk);
    for (a = 1; a < nk; ++a) if (dkeys[a] == dkeys[a - 1]) ddup++;
    for (a = 0; a < nk; a = b) {
        for (b = a; b < nk && keys[b] == keys[a]; ++b) {}
        if (b - a > 2) more++;
        if (b - a == 1) {
            int e[2], k, cut = 1, outl = 1;
            once++;
            e[0] = (int)(keys[a] >> 32); e[1] = (int)(keys[a] & 0xffffffffu);
            for (k = 0; k < 2; ++k) {
                const sfb_location *l = &t->locations[e[k]];
                double mv = mask_at(M, l->face, l->u, l->v);
                if (fabs(mv - 0.5) > 1e-4) cut = 0;
                if (!on_outline(P, O, t, e[k])) outl = 0;
            }
            if (E->boundary == 1 && !cut) bad_bnd++;
            if (E->boundary == 2 && !cut && !outl) bad_bnd++;
        }
    }
    snprintf(nm, sizeof nm, "%s/%s/watertight: no edge used more than twice or twice in one direction", be, E->name);
    check(more == 0 && ddup == 0, nm, "%ld edges used 3+ times, %ld directed edges repeated", more, ddup);
    if (E->boundary) {
        snprintf(nm, sizeof nm, "%s/%s/boundary edges are the cut%s", be, E->name, E->boundary == 2 ? " or the outline" : "");
        check(bad_bnd == 0 && once > 0, nm, "%d of %ld boundary edges are neither", bad_bnd, once);
    }
    /* vertices of boundary edges inside their face: on the contour */
    for (a = 0; a < nk; a = b) {
        for (b = a; b < nk && keys[b] == keys[a]; ++b) {}
        if (b - a == 1) {
            int k;
            for (k = 0; k < 2; ++k) {
                int v = k ? (int)(keys[a] & 0xffffffffu) : (int)(keys[a] >> 32);
                const sfb_location *l = &t->locations[v];
                double u = l->u, w = l->v, mv, geo = 0.0;
                if (canon(&P[l->face], u, w).kind != P_NONE || used[v] == 3) continue;
                used[v] = 3;
                nb_cut++;
                mv = mask_at(M, l->face, u, w);
                if (fabs(mv - 0.5) > worst_mask) worst_mask = fabs(mv - 0.5);
                if (fabs(mv - 0.5) > 1e-4) bad_contour++;
                if (E->contour == 1) geo = fabs(u - E->half_u);
                if (E->contour == 2) geo = fabs(hypot(u - E->cx, w - E->cy) - E->r);
                if (E->contour == 3) geo = fabs(fabs(u - E->cx) - E->r);
                if (geo > worst_geo) worst_geo = geo;
                if (geo > E->texel) bad_geo++;
            }
        }
    }
    snprintf(nm, sizeof nm, "%s/%s/new boundary vertices on the contour (mask 0.5 within 1e-4)", be, E->name);
    check(bad_contour == 0 && (!E->need_cut || nb_cut > 0), nm, "%d of %d off by up to %.3g", bad_contour, nb_cut, worst_mask);
    if (E->contour) {
        snprintf(nm, sizeof nm, "%s/%s/new boundary vertices within one texel (%.4g) of the %s", be, E->name, E->texel,
                 E->contour == 2 ? "circle" : "line(s) u = contour");
        check(bad_geo == 0 && nb_cut > 0, nm, "%d of %d farther, up to %.4g", bad_geo, nb_cut, worst_geo);
        if (!strcmp(be, "ref")) printf("# %s: new boundary vertices up to %.3g texel from the %s\n", E->name, worst_geo / E->texel,
                                       E->contour == 2 ? "circle" : "line");
    }
done:
    free(area); free(area3); free(used); free(keys); free(dkeys);
}

static int cmp_u64(const void *x, const void *y) {
    unsigned long long a = *(const unsigned long long *)x, b = *(const unsigned long long *)y;
    return a < b ? -1 : a > b;
}
static void sort_u64(unsigned long long *k, size_t n) { if (n) qsort(k, n, sizeof *k, cmp_u64); }

static double angle3(const float *a, const float *b) {
    double d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
    return acos(d > 1.0 ? 1.0 : d < -1.0 ? -1.0 : d);
}

/* Runs one case on every backend: the checks, and agreement with ref. */
static void run_case(const expect *E, const sfb_mesh *m, const mask *M) {
    sfb_tess_data ref;
    int e, have_ref = 0;
    double diag = mesh_diag(m);
    char nm[512];
    sfb_trim_mask tm = mask_api(M);
    memset(&ref, 0, sizeof ref);
    for (e = 0; e < g_nbe; ++e) {
        backend *b = &g_be[e];
        sfb_surface *s;
        sfb_tess_config c = sfb_tess_config_init(E->rate);
        sfb_tess_data t;
        pface *P;
        outline O;
        sfb_result r;
        snprintf(nm, sizeof nm, "%s/%s", b->name, E->name);
        if (!b->available) {
            if (b->required) fail(nm, "%s unavailable: %s (required by SFB_REQUIRE_BACKENDS)", b->name, b->why);
            else skip(nm, b->why);
            continue;
        }
        s = surface_of(b->ctx, m, E->loop);
        if (!s) { fail(nm, "surface: %s", sfb_last_error(b->ctx)); continue; }
        c.tolerance = E->tolerance;
        c.flags = E->flags;
        c.trim = &tm;
        r = sfb_surface_tessellate(s, &c, &t);
        if (r != SFB_SUCCESS) {
            fail(nm, "tessellate: %s: %s", sfb_result_string(r), sfb_last_error(b->ctx));
            sfb_surface_destroy(s);
            continue;
        }
        P = param_faces(s, m, E->loop);
        O = outline_of(m);
        check_result(b->name, E, M, s, P, &O, &t);
        free(P);
        free(O.e);
        free(O.v);
        if (e == 0) {
            ref = t;
            have_ref = 1;
        } else if (have_ref) {
            double wp = 0.0, wn = 0.0;
            int i, same = t.vertex_count == ref.vertex_count && t.triangle_count == ref.triangle_count &&
                          !memcmp(t.triangles, ref.triangles, sizeof(int) * 3 * (size_t)t.triangle_count) &&
                          !memcmp(t.triangle_faces, ref.triangle_faces, sizeof(int) * (size_t)t.triangle_count) &&
                          !memcmp(t.locations, ref.locations, sizeof(sfb_location) * (size_t)t.vertex_count);
            snprintf(nm, sizeof nm, "%s/%s/agrees with ref: topology and locations", b->name, E->name);
            check(same, nm, "%d/%d vertices, %d/%d triangles", t.vertex_count, ref.vertex_count, t.triangle_count, ref.triangle_count);
            if (same) {
                for (i = 0; i < 3 * t.vertex_count; ++i) {
                    double d = fabs((double)t.positions[i] - ref.positions[i]);
                    if (d > wp) wp = d;
                }
                for (i = 0; i < t.vertex_count; ++i) {
                    double d = angle3(t.normals + 3 * (size_t)i, ref.normals + 3 * (size_t)i);
                    if (d > wn) wn = d;
                }
                snprintf(nm, sizeof nm, "%s/%s/agrees with ref: positions within 1e-4 x diagonal, normals within 1e-3 rad", b->name, E->name);
                check(wp <= 1e-4 * diag && wn <= 1e-3, nm, "position %.3g (diagonal %.3g), normal %.3g rad", wp, diag, wn);
                if (wp / diag > g_agree_pos[e]) g_agree_pos[e] = wp / diag;
                if (wn > g_agree_nrm[e]) g_agree_nrm[e] = wn;
            }
            sfb_tess_data_free(&t);
        } else {
            sfb_tess_data_free(&t);
        }
        sfb_surface_destroy(s);
    }
    if (have_ref) sfb_tess_data_free(&ref);
}

/* Expected areas: one fill for every face (or an atlas), exact where the contour is straight. */
static double *areas_for(const sfb_surface *s, const mask *M, int loop, int kind) {
    int np = sfb_surface_param_face_count(s), pf;
    double *A = (double *)calloc((size_t)np + 1, sizeof(double));
    for (pf = 0; pf < np; ++pf) {
        const unsigned char *tile;
        int tw, th;
        if (kind == FILL_HALF && mask_tile(M, pf, &tile, &tw, &th)) {
            /* black columns: the contour runs half way between the last black and the first white centre */
            int k = 0;
            double c;
            while (k < tw && tile[k] == 0) ++k;
            c = (double)k / tw;
            A[pf] = loop ? 0.5 * (1.0 - c) * (1.0 - c) : 1.0 - c;
        } else {
            A[pf] = sampled_area(M, pf, loop, 1024);
        }
    }
    return A;
}

static void case_half(const char *name, sfb_mesh *m, int loop, int w, int h, int rate, int affine_n, int boundary) {
    sfb_surface *s = surface_of(g_be[0].ctx, m, loop);
    mask M = mask_new(w, h);
    expect E;
    int k = 0;
    memset(&E, 0, sizeof E);
    if (!s) { fail(name, "surface: %s", sfb_last_error(g_be[0].ctx)); free(M.t); return; }
    mask_fill(&M, 0, 0, w, h, fill_of(FILL_HALF));
    while (k < w && M.t[k] == 0) ++k;
    E.name = name; E.loop = loop; E.rate = rate;
    E.area = areas_for(s, &M, loop, FILL_HALF);
    E.area_tol = 1.0 / w;
    E.contour = 1; E.half_u = (double)k / w; E.texel = 1.0 / w;
    E.centroid_tol = 1e-6;
    E.affine_n = affine_n;
    E.boundary = boundary;
    E.need_cut = 1;
    run_case(&E, m, &M);
    free(E.area);
    free(M.t);
    sfb_surface_destroy(s);
}

static void case_disc(const char *name, sfb_mesh *m, int loop, int n, int hole, int boundary, int rate, float tol, unsigned flags) {
    sfb_surface *s = surface_of(g_be[0].ctx, m, loop);
    mask M = mask_new(n, n);
    fill f = fill_of(hole ? FILL_HOLE : FILL_DISC);
    expect E;
    memset(&E, 0, sizeof E);
    if (!s) { fail(name, "surface: %s", sfb_last_error(g_be[0].ctx)); free(M.t); return; }
    if (loop) { f.cx = f.cy = 0.3; f.r = 0.2; } /* inside the triangle u + v <= 1 */
    mask_fill(&M, 0, 0, n, n, f);
    E.name = name; E.loop = loop; E.rate = rate; E.tolerance = tol; E.flags = flags;
    E.area = areas_for(s, &M, loop, f.kind);
    E.area_tol = 1.0 / n;
    E.contour = 2; E.cx = f.cx; E.cy = f.cy; E.r = f.r; E.texel = 1.0 / n;
    E.centroid_tol = 0.1; /* the contour bends inside cells */
    E.boundary = boundary;
    E.need_cut = 1;
    run_case(&E, m, &M);
    free(E.area);
    free(M.t);
    sfb_surface_destroy(s);
}

/* A band of white columns |u - 1/2| < 0.3 on a 5 x 16 mask: contours u = 0.2 and 0.8 (half way
 * between texel centres), which the rate-16 grid does not have, cross the seams between the
 * grid's rows, where both faces must cut at the same shared point; both ends of every face
 * are black, so every boundary edge is a cut or on the grid's outline. */
static void case_band(sfb_mesh *grid6) {
    sfb_surface *s = surface_of(g_be[0].ctx, grid6, 0);
    mask M = mask_new(5, 16);
    fill f = fill_of(FILL_BAND);
    expect E;
    memset(&E, 0, sizeof E);
    if (!s) { fail("band", "surface: %s", sfb_last_error(g_be[0].ctx)); free(M.t); return; }
    mask_fill(&M, 0, 0, 5, 16, f);
    E.name = "grid 6x6 band 5x16 (cuts on the seams)"; E.rate = 3;
    E.area = areas_for(s, &M, 0, FILL_BAND);
    E.area_tol = 1.0 / 5;
    E.contour = 3; E.cx = 0.5; E.r = 0.3; E.texel = 1.0 / 5;
    E.centroid_tol = 1e-6;
    E.boundary = 2;
    E.need_cut = 1;
    run_case(&E, grid6, &M);
    {   /* the band keeps 0.6 of every face, exactly: the contour is straight */
        int k, ok = 1;
        for (k = 0; k < 36; ++k) if (fabs(E.area[k] - 0.6) > 2e-3) ok = 0;
        check(ok, "band/the test's own mask keeps 0.6 of a face", "%g", E.area[0]);
    }
    free(E.area);
    free(M.t);
    sfb_surface_destroy(s);
}

/* A 2 x 2 atlas (tiles black, white, half, quarter) on a 3 x 3 grid: faces 4..8 past the last
 * tile are not trimmed; and a 2 x 1 atlas of non-square tiles. */
static void case_atlas(sfb_mesh *grid3) {
    sfb_surface *s = surface_of(g_be[0].ctx, grid3, 0);
    mask M = mask_new(64, 64), M2 = mask_new(64, 16);
    static const int kinds[4] = { FILL_BLACK, FILL_WHITE, FILL_HALF, FILL_QUARTER };
    static const double want[4] = { 0.0, 1.0, 0.5, 0.75 };
    expect E;
    int k, ok = 1;
    memset(&E, 0, sizeof E);
    if (!s) { fail("atlas", "surface: %s", sfb_last_error(g_be[0].ctx)); free(M.t); free(M2.t); return; }
    M.tu = M.tv = 2;
    for (k = 0; k < 4; ++k) mask_fill(&M, (k % 2) * 32, (k / 2) * 32, 32, 32, fill_of(kinds[k]));
    E.name = "atlas 2x2 on a 3x3 grid"; E.rate = 4;
    E.area = areas_for(s, &M, 0, -1);
    for (k = 0; k < 9; ++k) {
        double w = k < 4 ? want[k] : 1.0;
        if (fabs(E.area[k] - w) > 1.0 / 32) ok = 0;
    }
    check(ok, "atlas/the test's own mask gives 0, 1, 0.5, 0.75, then 1", "areas %g %g %g %g %g", E.area[0], E.area[1], E.area[2], E.area[3], E.area[4]);
    for (k = 0; k < 9; ++k) E.area[k] = k < 4 ? want[k] : 1.0; /* the stated areas, within a texel */
    E.area_tol = 1.0 / 32;
    E.centroid_tol = 0.1; /* the quarter tile's contour turns a corner */
    E.boundary = 0;
    E.need_cut = 1;
    run_case(&E, grid3, &M);
    free(E.area);
    M2.tu = 2; M2.tv = 1;
    mask_fill(&M2, 0, 0, 32, 16, fill_of(FILL_HALF));
    mask_fill(&M2, 32, 0, 32, 16, fill_of(FILL_QUARTER));
    memset(&E, 0, sizeof E);
    E.name = "atlas 2x1 of 32x16 tiles"; E.rate = 2;
    E.area = areas_for(s, &M2, 0, -1);
    E.area[0] = 0.5;
    E.area_tol = 1.0 / 32;
    E.centroid_tol = 0.1;
    E.need_cut = 1;
    run_case(&E, grid3, &M2);
    free(E.area);
    free(M.t);
    free(M2.t);
    sfb_surface_destroy(s);
}

/* All white: exactly the untrimmed tessellation; all black: nothing, successfully. */
static void case_white_black(const char *name, sfb_mesh *m, int loop, int rate, float tol, unsigned flags) {
    int e;
    for (e = 0; e < g_nbe; ++e) {
        backend *b = &g_be[e];
        sfb_surface *s;
        sfb_tess_data t0, t1, t2;
        sfb_tess_config c = sfb_tess_config_init(rate);
        mask W = mask_new(7, 3), B = mask_new(5, 5);
        sfb_trim_mask tw, tb;
        char nm[512];
        int same;
        memset(W.t, 255, 21);
        memset(B.t, 127, 25);
        tw = mask_api(&W);
        tb = mask_api(&B);
        snprintf(nm, sizeof nm, "%s/%s/white and black masks", b->name, name);
        if (!b->available) {
            if (b->required) fail(nm, "%s unavailable: %s (required by SFB_REQUIRE_BACKENDS)", b->name, b->why);
            else skip(nm, b->why);
            free(W.t); free(B.t);
            continue;
        }
        s = surface_of(b->ctx, m, loop);
        c.tolerance = tol;
        c.flags = flags;
        if (!s || sfb_surface_tessellate(s, &c, &t0) != SFB_SUCCESS) {
            fail(nm, "%s", sfb_last_error(b->ctx));
            if (s) sfb_surface_destroy(s);
            free(W.t); free(B.t);
            continue;
        }
        c.trim = &tw;
        if (sfb_surface_tessellate(s, &c, &t1) != SFB_SUCCESS) {
            fail(nm, "white: %s", sfb_last_error(b->ctx));
        } else {
            same = t0.vertex_count == t1.vertex_count && t0.triangle_count == t1.triangle_count &&
                   !memcmp(t0.positions, t1.positions, sizeof(float) * 3 * (size_t)t0.vertex_count) &&
                   !memcmp(t0.normals, t1.normals, sizeof(float) * 3 * (size_t)t0.vertex_count) &&
                   !memcmp(t0.locations, t1.locations, sizeof(sfb_location) * (size_t)t0.vertex_count) &&
                   !memcmp(t0.triangles, t1.triangles, sizeof(int) * 3 * (size_t)t0.triangle_count) &&
                   !memcmp(t0.triangle_faces, t1.triangle_faces, sizeof(int) * (size_t)t0.triangle_count);
            snprintf(nm, sizeof nm, "%s/%s/all-white mask: exactly the untrimmed tessellation", b->name, name);
            check(same, nm, "%d/%d vertices, %d/%d triangles or contents differ", t1.vertex_count, t0.vertex_count, t1.triangle_count,
                  t0.triangle_count);
            sfb_tess_data_free(&t1);
        }
        c.trim = &tb;
        snprintf(nm, sizeof nm, "%s/%s/all-black mask (127): no triangles, no vertices, success", b->name, name);
        if (sfb_surface_tessellate(s, &c, &t2) != SFB_SUCCESS) fail(nm, "%s", sfb_last_error(b->ctx));
        else {
            check(t2.triangle_count == 0 && t2.vertex_count == 0, nm, "%d triangles, %d vertices", t2.triangle_count, t2.vertex_count);
            sfb_tess_data_free(&t2);
        }
        sfb_tess_data_free(&t0);
        sfb_surface_destroy(s);
        free(W.t); free(B.t);
    }
}

/* ---- bad masks, failing allocations, cancellation ---- */

static int all_zero(const void *p, size_t n) {
    const unsigned char *b = (const unsigned char *)p;
    size_t i;
    for (i = 0; i < n; ++i) if (b[i]) return 0;
    return 1;
}

static void bad_masks(sfb_mesh *cube) {
    sfb_context *ctx = g_be[0].ctx;
    sfb_surface *s = surface_of(ctx, cube, 0);
    unsigned char tex[64];
    struct { const char *what; int w, h, tu, tv, null; } cases[] = {
        { "texels NULL", 4, 4, 0, 0, 1 },      { "width 0", 0, 4, 0, 0, 0 },         { "height 0", 4, 0, 0, 0, 0 },
        { "width -3", -3, 4, 0, 0, 0 },        { "width 16385", 16385, 1, 0, 0, 0 }, { "height 16385", 1, 16385, 0, 0, 0 },
        { "tiles_u -1", 4, 4, -1, 1, 0 },      { "tiles_v -2", 4, 4, 2, -2, 0 },     { "tiles 2 x 0", 4, 4, 2, 0, 0 },
        { "tiles 0 x 2", 4, 4, 0, 2, 0 },      { "width 4 in 3 tiles", 4, 4, 3, 1, 0 }, { "height 4 in 3 tiles", 4, 4, 1, 3, 0 },
        { "8 tiles across 4 texels", 4, 4, 8, 1, 0 },
    };
    int k;
    memset(tex, 255, sizeof tex);
    if (!s) { fail("ref/bad masks", "surface: %s", sfb_last_error(ctx)); return; }
    for (k = 0; k < (int)(sizeof cases / sizeof cases[0]); ++k) {
        sfb_trim_mask tm;
        sfb_tess_config c = sfb_tess_config_init(3);
        sfb_tess_data t;
        sfb_result r;
        char nm[256];
        memset(&tm, 0, sizeof tm);
        tm.width = cases[k].w; tm.height = cases[k].h; tm.tiles_u = cases[k].tu; tm.tiles_v = cases[k].tv;
        tm.texels = cases[k].null ? NULL : tex;
        c.trim = &tm;
        memset(&t, 0xab, sizeof t);
        r = sfb_surface_tessellate(s, &c, &t);
        snprintf(nm, sizeof nm, "ref/bad mask/%s: SFB_INVALID_VALUE, out zeroed, a message", cases[k].what);
        check(r == SFB_INVALID_VALUE && all_zero(&t, sizeof t) && strstr(sfb_last_error(ctx), "trimming mask") != NULL, nm, "%s: %s",
              sfb_result_string(r), sfb_last_error(ctx));
        if (r == SFB_SUCCESS) sfb_tess_data_free(&t);
    }
    /* the largest sizes and a 1 x 1 atlas are fine */
    {
        sfb_trim_mask tm;
        sfb_tess_config c = sfb_tess_config_init(2);
        sfb_tess_data t;
        unsigned char *big = (unsigned char *)malloc(16384 * 2);
        sfb_result r;
        memset(big, 200, 16384 * 2);
        memset(&tm, 0, sizeof tm);
        tm.width = 16384; tm.height = 2; tm.texels = big; tm.tiles_u = 1; tm.tiles_v = 1;
        c.trim = &tm;
        r = sfb_surface_tessellate(s, &c, &t);
        check(r == SFB_SUCCESS && t.triangle_count == 6 * 8, "ref/mask 16384 x 2 (1 x 1 atlas, all kept) is valid", "%s: %s (%d triangles)",
              sfb_result_string(r), sfb_last_error(ctx), t.triangle_count);
        if (r == SFB_SUCCESS) sfb_tess_data_free(&t);
        free(big);
    }
    sfb_surface_destroy(s);
}

/* Failing allocator: the k-th allocation after the surface is built fails; nothing may leak. */
typedef struct fa { long n, fail_at, live; int cancel_at, calls, bad_progress; float last; } fa;
static void *fa_alloc(size_t n, void *u) { fa *a = (fa *)u; void *p; if (a->n++ == a->fail_at) return NULL; p = malloc(n); if (p) a->live++; return p; }
static void *fa_realloc(void *p, size_t n, void *u) { fa *a = (fa *)u; void *q; if (a->n++ == a->fail_at) return NULL; q = realloc(p, n); if (q && !p) a->live++; return q; }
static void fa_free(void *p, void *u) { fa *a = (fa *)u; if (p) { a->live--; free(p); } }
static int fa_progress(float done, const char *stage, void *u) {
    fa *a = (fa *)u;
    if (!(done >= 0.0f && done <= 1.0f) || strcmp(stage, "tessellate") != 0 || done + 1e-6f < a->last) a->bad_progress++;
    a->last = done;
    return ++a->calls == a->cancel_at;
}

static void failure_sweep(int cancel, const char *obj, int loop, int atlas) {
    fa a;
    sfb_context_config cfg = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_backend_kind kind = SFB_BACKEND_REF;
    sfb_mesh *m;
    sfb_surface *s;
    mask M = mask_new(48, 48);
    sfb_trim_mask tm;
    fill f = fill_of(FILL_HOLE);
    long k, bad = 0, tried = 0, base;
    int done = 0;
    char nm[256];
    memset(&a, 0, sizeof a);
    a.fail_at = -1;
    cfg.allocator.alloc = fa_alloc; cfg.allocator.realloc = fa_realloc; cfg.allocator.free = fa_free; cfg.allocator.user = &a;
    cfg.progress.func = fa_progress; cfg.progress.user = &a;
    cfg.backends = &kind; cfg.backend_count = 1; cfg.ignore_environment = 1;
    snprintf(nm, sizeof nm, "ref/%s at every %s: %s, out zeroed, nothing leaked", loop ? "loop" : atlas ? "atlas" : "catmark",
             cancel ? "progress report" : "allocation", cancel ? "SFB_CANCELLED" : "SFB_OUT_OF_MEMORY");
    if (sfb_context_create(&cfg, &ctx) != SFB_SUCCESS) { fail(nm, "context"); free(M.t); return; }
    if (loop) { f.cx = f.cy = 0.3; f.r = 0.2; }
    if (atlas) {
        M.tu = M.tv = 2;
        mask_fill(&M, 0, 0, 24, 24, f);
        mask_fill(&M, 24, 0, 24, 24, fill_of(FILL_BLACK));
        mask_fill(&M, 0, 24, 24, 24, fill_of(FILL_HALF));
        mask_fill(&M, 24, 24, 24, 24, fill_of(FILL_WHITE));
    } else {
        mask_fill(&M, 0, 0, 48, 48, f);
    }
    tm = mask_api(&M);
    m = mesh_of(ctx, obj);
    s = m ? surface_of(ctx, m, loop) : NULL;
    if (!s) { fail(nm, "surface"); goto out; }
    a.bad_progress = 0; /* building the surface reports its own stages */
    for (k = 0; k < 200000 && !done; ++k) {
        sfb_tess_config c = sfb_tess_config_init(4);
        sfb_tess_data t;
        sfb_result r;
        long live = a.live;
        c.trim = &tm;
        base = a.n;
        a.calls = 0;
        a.last = 0.0f;
        if (cancel) a.cancel_at = (int)k + 1;
        else a.fail_at = base + k;
        r = sfb_surface_tessellate(s, &c, &t);
        a.fail_at = -1;
        a.cancel_at = 0;
        tried++;
        if (r == SFB_SUCCESS) {
            if (t.triangle_count <= 0) bad++;
            sfb_tess_data_free(&t);
            done = 1;
        } else {
            if (r != (cancel ? SFB_CANCELLED : SFB_OUT_OF_MEMORY) || !all_zero(&t, sizeof t)) bad++;
        }
        if (a.live != live) bad++;
    }
    check(done && bad == 0 && tried > (cancel ? 2 : 5), nm, "%ld bad of %ld tried%s", bad, tried, done ? "" : ", never succeeded");
    snprintf(nm, sizeof nm, "ref/%s %s sweep: progress in [0,1], in order, stage \"tessellate\"", loop ? "loop" : atlas ? "atlas" : "catmark",
             cancel ? "cancellation" : "allocation");
    check(a.bad_progress == 0, nm, "%d bad reports", a.bad_progress);
out:
    if (s) sfb_surface_destroy(s);
    if (m) sfb_mesh_destroy(m);
    sfb_context_destroy(ctx);
    snprintf(nm, sizeof nm, "ref/%s sweep: every block freed", cancel ? "cancellation" : "allocation");
    check(a.live == 0, nm, "%ld blocks live", a.live);
    free(M.t);
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : NULL;
    sfb_mesh *grid6 = NULL, *grid3 = NULL, *cube = NULL, *prism = NULL, *octa = NULL, *lcube = NULL, *creased = NULL;
    char *g6, *g3;
    int i;
    if (!probe_backends()) return 1;
    g6 = grid_obj(6);
    g3 = grid_obj(3);
    grid6 = mesh_of(g_be[0].ctx, g6);
    grid3 = mesh_of(g_be[0].ctx, g3);
    cube = mesh_of(g_be[0].ctx, cube_obj);
    prism = mesh_of(g_be[0].ctx, prism_obj);
    octa = mesh_of(g_be[0].ctx, octahedron_obj);
    creased = mesh_of(g_be[0].ctx, creased_cube_obj);
    if (!grid6 || !grid3 || !cube || !prism || !octa || !creased) {
        fail("meshes", "%s", sfb_last_error(g_be[0].ctx));
        goto out;
    }
    if (dir) {
        char why[1200];
        lcube = load_obj(g_be[0].ctx, dir, "loop_cube.obj", why, sizeof why);
    }

    /* half masks: a planar grid (rate 3 asked, raised to the mask), the n-gon prism, Loop */
    case_half("grid 6x6 half 16x16", grid6, 0, 16, 16, 3, 6, 0);
    case_half("grid 6x6 half 64x64", grid6, 0, 64, 64, 3, 6, 0);
    case_half("grid 6x6 half 37x5", grid6, 0, 37, 5, 2, 6, 0);
    case_half("cube half 16x16", cube, 0, 16, 16, 5, 0, 0);
    case_half("prism (pentagons) half 16x16", prism, 0, 16, 16, 4, 0, 0);
    case_half("prism (pentagons) half 37x5", prism, 0, 37, 5, 4, 0, 0);
    case_half("octahedron loop half 16x16", octa, 1, 16, 16, 3, 0, 0);
    case_half("octahedron loop half 37x5", octa, 1, 37, 5, 3, 0, 0);
    if (lcube) case_half("loop_cube half 32x32", lcube, 1, 32, 32, 4, 0, 0);
    else skip("loop_cube", "shapes directory not given or loop_cube.obj not readable");
    /* discs: islands (every boundary edge a cut) and holes (the cut and the grid's outline) */
    case_disc("cube disc islands 32x32", cube, 0, 32, 0, 1, 3, 0.0f, 0);
    case_disc("cube disc holes 32x32", cube, 0, 32, 1, 1, 3, 0.0f, 0);
    case_disc("grid 6x6 disc holes 40x40", grid6, 0, 40, 1, 2, 2, 0.0f, 0);
    case_disc("prism disc holes 32x32", prism, 0, 32, 1, 1, 3, 0.0f, 0);
    case_disc("prism disc islands 32x32, adaptive", prism, 0, 32, 0, 1, 8, 1e-3f, 0);
    case_disc("octahedron loop disc holes 32x32", octa, 1, 32, 1, 1, 3, 0.0f, 0);
    case_disc("octahedron loop disc islands 24x24, adaptive", octa, 1, 24, 0, 1, 8, 1e-3f, 0);
    case_disc("creased cube disc holes 16x16, split creases", creased, 0, 16, 1, 0, 3, 0.0f, SFB_TESS_SPLIT_CREASES);
    if (lcube) case_disc("loop_cube disc holes 32x32", lcube, 1, 32, 1, 1, 2, 0.0f, 0);
    case_band(grid6);
    case_atlas(grid3);
    case_white_black("grid 6x6", grid6, 0, 5, 0.0f, 0);
    case_white_black("prism adaptive", prism, 0, 9, 1e-3f, 0);
    case_white_black("octahedron loop", octa, 1, 4, 0.0f, 0);
    case_white_black("creased cube split", creased, 0, 3, 0.0f, SFB_TESS_SPLIT_CREASES);
    bad_masks(cube);
    failure_sweep(0, cube_obj, 0, 0);
    failure_sweep(0, prism_obj, 0, 1);
    failure_sweep(0, octahedron_obj, 1, 0);
    failure_sweep(1, prism_obj, 0, 1);
    failure_sweep(1, octahedron_obj, 1, 0);
out:
    if (grid6) sfb_mesh_destroy(grid6);
    if (grid3) sfb_mesh_destroy(grid3);
    if (cube) sfb_mesh_destroy(cube);
    if (prism) sfb_mesh_destroy(prism);
    if (octa) sfb_mesh_destroy(octa);
    if (lcube) sfb_mesh_destroy(lcube);
    if (creased) sfb_mesh_destroy(creased);
    free(g6);
    free(g3);
    for (i = 1; i < g_nbe; ++i)
        if (g_be[i].available)
            printf("# %s against ref: largest position difference %.3g x diagonal, normal %.3g rad\n", g_be[i].name, g_agree_pos[i],
                   g_agree_nrm[i]);
    return finish_tests();
}
