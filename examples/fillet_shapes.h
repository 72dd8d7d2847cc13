/* Generated triangle meshes for the rolling-ball fillet (seed 002): its tests (tests/fillet.c),
 * its picture (examples/06_fillet_panel.c) and its benchmark (bench/bench.cpp). Generated, so that
 * the exact answers are known: a fold of two half-planes, a closed box-cylinder union (its seam a
 * closed concave curve between a plane and a cylinder), a round slab with an L-shaped prism on it
 * (its seam turns round a reflex corner). Every mesh is welded (shared vertices by index) and
 * oriented outward (counter-clockwise seen from outside); the closed ones are watertight.
 * Header-only, C99 and C++; malloc'd arrays, fs_free frees them. */
#ifndef SFB_FILLET_SHAPES_H
#define SFB_FILLET_SHAPES_H
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>

typedef struct fs_mesh {
    int nv, nf;
    float *pos;          /* xyz per vertex */
    int *tri;            /* 3 per triangle */
    int loop_count;      /* the seam (or the fold's edge): a vertex chain, closed ones end with their first vertex */
    int *loop;
    int cap_v, cap_f;
} fs_mesh;

static inline void fs_free(fs_mesh *m) {
    free(m->pos);
    free(m->tri);
    free(m->loop);
    memset(m, 0, sizeof *m);
}

static inline int fs_vertex(fs_mesh *m, double x, double y, double z) {
    if (m->nv == m->cap_v) {
        const int cap = m->cap_v ? 2 * m->cap_v : 1024;
        float *p = (float *)realloc(m->pos, (size_t)cap * 3 * sizeof(float));
        if (!p) return -1;
        m->pos = p;
        m->cap_v = cap;
    }
    m->pos[3 * m->nv] = (float)x;
    m->pos[3 * m->nv + 1] = (float)y;
    m->pos[3 * m->nv + 2] = (float)z;
    return m->nv++;
}

/* A triangle, turned so that its normal points along `out` (the outward direction there). */
static inline int fs_triangle(fs_mesh *m, int a, int b, int c, const double out[3]) {
    const float *A = m->pos + 3 * a, *B = m->pos + 3 * b, *C = m->pos + 3 * c;
    const double u[3] = {(double)B[0] - A[0], (double)B[1] - A[1], (double)B[2] - A[2]};
    const double v[3] = {(double)C[0] - A[0], (double)C[1] - A[1], (double)C[2] - A[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    if (m->nf == m->cap_f) {
        const int cap = m->cap_f ? 2 * m->cap_f : 2048;
        int *t = (int *)realloc(m->tri, (size_t)cap * 3 * sizeof(int));
        if (!t) return -1;
        m->tri = t;
        m->cap_f = cap;
    }
    if (n[0] * out[0] + n[1] * out[1] + n[2] * out[2] < 0) { const int t = b; b = c; c = t; }
    m->tri[3 * m->nf] = a;
    m->tri[3 * m->nf + 1] = b;
    m->tri[3 * m->nf + 2] = c;
    m->nf++;
    return 0;
}

/* The outward direction of a strip piece: kind 0 a fixed vector, 1 radial from (cx, cy) in xy. */
typedef struct fs_dir { int kind; double v[3], cx, cy; } fs_dir;
static inline void fs_dir_at(const fs_dir *d, const fs_mesh *m, int a, int b, int c, double out[3]) {
    if (d->kind == 0) { memcpy(out, d->v, 3 * sizeof(double)); return; }
    out[0] = ((double)m->pos[3 * a] + m->pos[3 * b] + m->pos[3 * c]) / 3.0 - d->cx;
    out[1] = ((double)m->pos[3 * a + 1] + m->pos[3 * b + 1] + m->pos[3 * c + 1]) / 3.0 - d->cy;
    out[2] = 0.0;
}

/* Quads between two rings of n vertices (ra[i], rb[i]; closed: n joins 0), split along the shorter diagonal. */
static inline int fs_strip(fs_mesh *m, const int *ra, const int *rb, int n, int closed, const fs_dir *d) {
    int i;
    for (i = 0; i < (closed ? n : n - 1); ++i) {
        const int a = ra[i], b = ra[(i + 1) % n], c = rb[i], e = rb[(i + 1) % n];
        const float *A = m->pos + 3 * a, *B = m->pos + 3 * b, *C = m->pos + 3 * c, *E = m->pos + 3 * e;
        const double d1 = (A[0] - E[0]) * (A[0] - E[0]) + (A[1] - E[1]) * (A[1] - E[1]) + (A[2] - E[2]) * (A[2] - E[2]);
        const double d2 = (B[0] - C[0]) * (B[0] - C[0]) + (B[1] - C[1]) * (B[1] - C[1]) + (B[2] - C[2]) * (B[2] - C[2]);
        double o[3];
        if (d1 <= d2) {
            fs_dir_at(d, m, a, b, e, o);
            if (fs_triangle(m, a, b, e, o)) return -1;
            fs_dir_at(d, m, a, e, c, o);
            if (fs_triangle(m, a, e, c, o)) return -1;
        } else {
            fs_dir_at(d, m, a, b, c, o);
            if (fs_triangle(m, a, b, c, o)) return -1;
            fs_dir_at(d, m, b, e, c, o);
            if (fs_triangle(m, b, e, c, o)) return -1;
        }
    }
    return 0;
}
static inline int fs_fan(fs_mesh *m, const int *ring, int n, int centre, const fs_dir *d) {
    int i;
    for (i = 0; i < n; ++i) {
        double o[3];
        fs_dir_at(d, m, ring[i], ring[(i + 1) % n], centre, o);
        if (fs_triangle(m, ring[i], ring[(i + 1) % n], centre, o)) return -1;
    }
    return 0;
}

/* Two planar rectangles meeting at a straight edge along the x axis, (0,0,0)-(length,0,0):
 * face A = (x, -s, 0), face B = (x, 0, 0) + s (0, -cos angle, -sin angle), s in [0, width]
 * (angle = 90: a box edge, normals +z and +y, the solid in the wedge: convex). n segments along
 * the edge, about n width / length across each face. flip = 1 reverses every triangle (normals
 * inward: the same fold, concave). Open. loop: the edge's vertices, x ascending. */
static inline int fs_fold(fs_mesh *m, int n, float length, float width, float angle_deg, int flip) {
    const double th = angle_deg * 3.14159265358979323846 / 180.0;
    int k = (int)(n * width / length + 0.5), i, j;
    int *rows;
    memset(m, 0, sizeof *m);
    if (n < 1 || !(length > 0) || !(width > 0)) return -1;
    if (k < 1) k = 1;
    rows = (int *)malloc((size_t)(2 * k + 1) * (n + 1) * sizeof(int));
    m->loop = (int *)malloc((size_t)(n + 1) * sizeof(int));
    if (!rows || !m->loop) { free(rows); return -1; }
    /* row r = 0..2k: s = (k - r) / k * width on A (r <= k), (r - k) / k * width on B */
    for (j = 0; j <= 2 * k; ++j)
        for (i = 0; i <= n; ++i) {
            const double x = (double)length * i / n, s = (double)width * (j <= k ? k - j : j - k) / k;
            const int v = j <= k ? fs_vertex(m, x, -s, 0.0) : fs_vertex(m, x, -cos(th) * s, -sin(th) * s);
            if (v < 0) { free(rows); return -1; }
            rows[j * (n + 1) + i] = v;
        }
    for (j = 0; j < 2 * k; ++j) {
        fs_dir d;
        memset(&d, 0, sizeof d);
        if (j < k) d.v[2] = 1.0;
        else { d.v[1] = sin(th); d.v[2] = -cos(th); }
        if (fs_strip(m, rows + j * (n + 1), rows + (j + 1) * (n + 1), n + 1, 0, &d)) { free(rows); return -1; }
    }
    for (i = 0; i <= n; ++i) m->loop[i] = rows[k * (n + 1) + i];
    m->loop_count = n + 1;
    free(rows);
    if (flip)
        for (i = 0; i < m->nf; ++i) { const int t = m->tri[3 * i + 1]; m->tri[3 * i + 1] = m->tri[3 * i + 2]; m->tri[3 * i + 2] = t; }
    return 0;
}

/* A step: the strip z = 0 for y in [-width, 0], the wall y = 0 down to z = -depth, the strip
 * z = -depth for y in [0, width], all for x in [0, length], outward normals +z, +y, +z: a convex
 * 90-degree edge along (x, 0, 0) and a concave one along (x, 0, -depth). n segments along x,
 * about as fine across. Open. loop: the convex edge's vertices, x ascending, then (loop2) the
 * concave edge's, stored after the first chain: loop[0..n] and loop[n+1..2n+1]. */
static inline int fs_step(fs_mesh *m, int n, float length, float width, float depth) {
    const double step = (double)length / n;
    const double yz[4][2] = {{-(double)width, 0.0}, {0.0, 0.0}, {0.0, -(double)depth}, {(double)width, -(double)depth}};
    int piece, j, i, rows = 0, *row = NULL, *prev = NULL, rc = -1, edge_row[2] = {0, 0};
    memset(m, 0, sizeof *m);
    if (n < 1 || !(length > 0) || !(width > 0) || !(depth > 0)) return -1;
    row = (int *)malloc((size_t)(n + 1) * sizeof(int));
    prev = (int *)malloc((size_t)(n + 1) * sizeof(int));
    m->loop = (int *)malloc((size_t)(2 * n + 2) * sizeof(int));
    if (!row || !prev || !m->loop) goto done;
    for (piece = 0; piece < 3; ++piece) {
        const double *a = yz[piece], *b = yz[piece + 1], len = hypot(b[0] - a[0], b[1] - a[1]);
        const int k = (int)(len / step + 0.5) < 1 ? 1 : (int)(len / step + 0.5);
        fs_dir d;
        memset(&d, 0, sizeof d);
        /* outward: the piece's direction in (y, z) turned a quarter counter-clockwise */
        d.v[1] = -(b[1] - a[1]) / len;
        d.v[2] = (b[0] - a[0]) / len;
        for (j = piece == 0 ? 0 : 1; j <= k; ++j) {
            const double y = a[0] + (b[0] - a[0]) * j / k, z = a[1] + (b[1] - a[1]) * j / k;
            for (i = 0; i <= n; ++i)
                if ((row[i] = fs_vertex(m, step * i, y, z)) < 0) goto done;
            if (j > 0 && fs_strip(m, prev, row, n + 1, 0, &d)) goto done;
            memcpy(prev, row, (size_t)(n + 1) * sizeof(int));
            rows++;
            if (j == k && piece < 2) edge_row[piece] = rows - 1;
        }
    }
    for (i = 0; i <= n; ++i) {
        m->loop[i] = edge_row[0] * (n + 1) + i;
        m->loop[n + 1 + i] = edge_row[1] * (n + 1) + i;
    }
    m->loop_count = n + 1;
    rc = 0;
done:
    free(row);
    free(prev);
    return rc;
}

/* The union of the box [-half, half]^2 x [-height, 0] and a cylinder of `radius` (< half) on its top
 * face from z = 0 to cyl_height, one closed watertight mesh. The top face is cut by rays from the
 * axis at M equal angles (M a multiple of 8, about 4 n: the square's corners lie on rays) into
 * rings graded from the seam circle to the square; the box's sides are one band of rows under the
 * square's points, its bottom rings down to the centre; the cylinder's rows and its cap likewise.
 * loop: the seam (the cylinder's bottom ring), closed. */
static inline int fs_box_cylinder(fs_mesh *m, int n, float half, float height, float radius, float cyl_height) {
    const double PI = 3.14159265358979323846;
    int M = 8 * ((n + 1) / 2), K, Hb, Hc, Kc, Kb, i, k, *ring = NULL, *prev = NULL, rc = -1;
    double step;
    fs_dir up, down, radial;
    memset(m, 0, sizeof *m);
    if (n < 2 || !(radius > 0) || !(half > radius) || !(height > 0) || !(cyl_height > 0)) return -1;
    if (M < 8) M = 8;
    step = 2 * PI * radius / M;                 /* the seam's spacing: every part about that fine */
    K = (int)((half - radius) / step + 0.5); if (K < 2) K = 2;
    Hb = (int)(height / (8.0 * half / M) + 0.5); if (Hb < 1) Hb = 1;
    Hc = (int)(cyl_height / step + 0.5); if (Hc < 2) Hc = 2;
    Kc = (int)(radius / step + 0.5); if (Kc < 2) Kc = 2;
    Kb = K + Kc;
    memset(&up, 0, sizeof up); up.v[2] = 1.0;
    memset(&down, 0, sizeof down); down.v[2] = -1.0;
    memset(&radial, 0, sizeof radial); radial.kind = 1;
    ring = (int *)malloc((size_t)M * sizeof(int));
    prev = (int *)malloc((size_t)M * sizeof(int));
    m->loop = (int *)malloc((size_t)(M + 1) * sizeof(int));
    if (!ring || !prev || !m->loop) goto done;
    /* the seam ring, then the top face's rings out to the square */
    for (i = 0; i < M; ++i) {
        const double a = 2 * PI * i / M;
        if ((prev[i] = fs_vertex(m, radius * cos(a), radius * sin(a), 0.0)) < 0) goto done;
        m->loop[i] = prev[i];
    }
    m->loop[M] = m->loop[0];
    m->loop_count = M + 1;
    for (k = 1; k <= K; ++k) {
        const double t = (double)k / K;
        for (i = 0; i < M; ++i) {
            const double a = 2 * PI * i / M, c = cos(a), s = sin(a), sq = half / (fabs(c) > fabs(s) ? fabs(c) : fabs(s));
            const double rr = radius + t * (sq - radius);
            if ((ring[i] = fs_vertex(m, rr * c, rr * s, 0.0)) < 0) goto done;
        }
        if (fs_strip(m, prev, ring, M, 1, &up)) goto done;
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    /* the box's sides: rows under the square's points */
    for (k = 1; k <= Hb; ++k) {
        const double z = -(double)height * k / Hb;
        for (i = 0; i < M; ++i)
            if ((ring[i] = fs_vertex(m, m->pos[3 * prev[i]], m->pos[3 * prev[i] + 1], z)) < 0) goto done;
        if (fs_strip(m, prev, ring, M, 1, &radial)) goto done;
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    /* the bottom: rings toward the centre, then a fan */
    for (k = 1; k < Kb; ++k) {
        const double t = 1.0 - (double)k / Kb;
        for (i = 0; i < M; ++i) {
            const double a = 2 * PI * i / M, c = cos(a), s = sin(a), sq = half / (fabs(c) > fabs(s) ? fabs(c) : fabs(s));
            if ((ring[i] = fs_vertex(m, t * sq * c, t * sq * s, -(double)height)) < 0) goto done;
        }
        if (fs_strip(m, prev, ring, M, 1, &down)) goto done;
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    if ((k = fs_vertex(m, 0.0, 0.0, -(double)height)) < 0 || fs_fan(m, prev, M, k, &down)) goto done;
    /* the cylinder's side from the seam up, its cap */
    memcpy(prev, m->loop, (size_t)M * sizeof(int));
    for (k = 1; k <= Hc; ++k) {
        const double z = (double)cyl_height * k / Hc;
        for (i = 0; i < M; ++i) {
            const double a = 2 * PI * i / M;
            if ((ring[i] = fs_vertex(m, radius * cos(a), radius * sin(a), z)) < 0) goto done;
        }
        if (fs_strip(m, prev, ring, M, 1, &radial)) goto done;
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    for (k = 1; k < Kc; ++k) {
        const double rr = radius * (1.0 - (double)k / Kc);
        for (i = 0; i < M; ++i) {
            const double a = 2 * PI * i / M;
            if ((ring[i] = fs_vertex(m, rr * cos(a), rr * sin(a), (double)cyl_height)) < 0) goto done;
        }
        if (fs_strip(m, prev, ring, M, 1, &up)) goto done;
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    if ((k = fs_vertex(m, 0.0, 0.0, (double)cyl_height)) < 0 || fs_fan(m, prev, M, k, &up)) goto done;
    rc = 0;
done:
    free(ring);
    free(prev);
    return rc;
}

/* A round slab (radius `half` about the footprint's kernel point, from z = -thick to 0) with a prism of
 * `height` standing on it whose footprint is an L: [0, arm] x [0, width] union [0, width] x [0, arm]
 * (one reflex corner at (width, width)). The footprint is sampled by arc length (its six corners
 * kept, about n segments per unit length); rays from the kernel point c = (width/2, width/2)
 * through those points carry the slab's top rings out to the slab's rim, the prism's walls go up
 * and its cap's rings shrink toward c. loop: the footprint on z = 0 (the seam), closed. */
static inline int fs_floor_lprism_round(fs_mesh *m, int n, float half, float thick, float arm, float width, float height, float round);
static inline int fs_floor_lprism(fs_mesh *m, int n, float half, float thick, float arm, float width, float height) {
    return fs_floor_lprism_round(m, n, half, thick, arm, width, height, 0.0f);
}
/* The same with the footprint's five convex corners rounded by arcs of radius `round` (0: sharp;
 * < width / 2), so that the prism's walls are smooth there and only the reflex corner is sharp: a
 * rolling ball in the seam then touches the walls along a curve everywhere (at a sharp convex
 * corner it touches the prism's vertical edge in one point, where the blend degenerates). */
static inline int fs_floor_lprism_round(fs_mesh *m, int n, float half, float thick, float arm, float width, float height, float round) {
    const double cx = width / 2.0, cy = width / 2.0;
    const double poly[6][2] = {{0, 0}, {arm, 0}, {arm, width}, {width, width}, {width, arm}, {0, arm}};
    double *F = NULL, perim = 0.0, seg, T[6][2][2], C[6][2];
    int M = 0, e, i, k, K, Hw, Kc, Ks, *ring = NULL, *prev = NULL, rc = -1;
    fs_dir up, down, radial;
    memset(m, 0, sizeof *m);
    if (n < 2 || !(width > 0) || !(arm > width) || !(half > 2 * arm) || !(thick > 0) || !(height > 0) || !(round >= 0) ||
        !(round < width / 2))
        return -1;
    /* each corner's two tangent points (equal at a sharp corner) and its arc's centre */
    for (e = 0; e < 6; ++e) {
        const double *p0 = poly[(e + 5) % 6], *p1 = poly[e], *p2 = poly[(e + 1) % 6];
        const double l1 = hypot(p1[0] - p0[0], p1[1] - p0[1]), l2 = hypot(p2[0] - p1[0], p2[1] - p1[1]);
        const double din[2] = {(p1[0] - p0[0]) / l1, (p1[1] - p0[1]) / l1}, dout[2] = {(p2[0] - p1[0]) / l2, (p2[1] - p1[1]) / l2};
        const double rr = e == 3 ? 0.0 : round; /* corner 3 is the reflex one */
        T[e][0][0] = p1[0] - din[0] * rr; T[e][0][1] = p1[1] - din[1] * rr;
        T[e][1][0] = p1[0] + dout[0] * rr; T[e][1][1] = p1[1] + dout[1] * rr;
        C[e][0] = T[e][0][0] - din[1] * rr; C[e][1] = T[e][0][1] + din[0] * rr; /* interior on the left */
    }
    for (e = 0; e < 6; ++e) perim += hypot(T[(e + 1) % 6][0][0] - T[e][1][0], T[(e + 1) % 6][0][1] - T[e][1][1]) + (e == 3 ? 0.0 : 0.5 * 3.14159265358979 * round);
    F = (double *)malloc((size_t)(n * perim + 64) * 2 * sizeof(double));
    if (!F) return -1;
    for (e = 0; e < 6; ++e) {
        /* corner e's arc (a quarter turn counter-clockwise), then the straight piece to corner e + 1 */
        if (e != 3 && round > 0) {
            const double a0 = atan2(T[e][0][1] - C[e][1], T[e][0][0] - C[e][0]);
            int s = (int)(n * 0.5 * 3.14159265358979 * round + 0.5), j;
            if (s < 2) s = 2;
            for (j = 0; j < s; ++j) {
                const double a = a0 + 0.5 * 3.14159265358979 * j / s;
                F[2 * M] = C[e][0] + round * cos(a);
                F[2 * M + 1] = C[e][1] + round * sin(a);
                M++;
            }
        }
        {
            const double *a = T[e][1], *b = T[(e + 1) % 6][0], len = hypot(b[0] - a[0], b[1] - a[1]);
            int s = (int)(n * len + 0.5), j;
            if (s < 2) s = 2;
            for (j = 0; j < s; ++j) {
                F[2 * M] = a[0] + (b[0] - a[0]) * j / s;
                F[2 * M + 1] = a[1] + (b[1] - a[1]) * j / s;
                M++;
            }
        }
    }
    seg = perim / M;
    K = (int)((half - arm) / seg + 0.5); if (K < 3) K = 3;
    Hw = (int)(height / seg + 0.5); if (Hw < 2) Hw = 2;
    Kc = (int)(width / 2.0 / seg + 0.5); if (Kc < 2) Kc = 2;
    Ks = (int)(thick / seg + 0.5); if (Ks < 1) Ks = 1;
    memset(&up, 0, sizeof up); up.v[2] = 1.0;
    memset(&down, 0, sizeof down); down.v[2] = -1.0;
    memset(&radial, 0, sizeof radial); radial.kind = 1; radial.cx = cx; radial.cy = cy;
    ring = (int *)malloc((size_t)M * sizeof(int));
    prev = (int *)malloc((size_t)M * sizeof(int));
    m->loop = (int *)malloc((size_t)(M + 1) * sizeof(int));
    if (!ring || !prev || !m->loop) goto done;
    for (i = 0; i < M; ++i) {
        if ((prev[i] = fs_vertex(m, F[2 * i], F[2 * i + 1], 0.0)) < 0) goto done;
        m->loop[i] = prev[i];
    }
    m->loop[M] = m->loop[0];
    m->loop_count = M + 1;
    /* the slab's top: from the footprint along the rays out to the rim circle of radius `half` about c */
    for (k = 1; k <= K; ++k) {
        const double t = (double)k / K;
        for (i = 0; i < M; ++i) {
            const double dx = F[2 * i] - cx, dy = F[2 * i + 1] - cy, l = hypot(dx, dy);
            const double rx = cx + dx / l * half, ry = cy + dy / l * half;
            /* graded: fine near the seam */
            const double g = t * t;
            if ((ring[i] = fs_vertex(m, F[2 * i] + g * (rx - F[2 * i]), F[2 * i + 1] + g * (ry - F[2 * i + 1]), 0.0)) < 0) goto done;
        }
        if (fs_strip(m, prev, ring, M, 1, &up)) goto done;
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    for (k = 1; k <= Ks; ++k) {
        const double z = -(double)thick * k / Ks;
        for (i = 0; i < M; ++i)
            if ((ring[i] = fs_vertex(m, m->pos[3 * prev[i]], m->pos[3 * prev[i] + 1], z)) < 0) goto done;
        if (fs_strip(m, prev, ring, M, 1, &radial)) goto done;
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    for (k = 1; k < K; ++k) {
        const double t = 1.0 - (double)k / K;
        for (i = 0; i < M; ++i) {
            const double dx = F[2 * i] - cx, dy = F[2 * i + 1] - cy, l = hypot(dx, dy);
            if ((ring[i] = fs_vertex(m, cx + dx / l * half * t, cy + dy / l * half * t, -(double)thick)) < 0) goto done;
        }
        if (fs_strip(m, prev, ring, M, 1, &down)) goto done;
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    if ((k = fs_vertex(m, cx, cy, -(double)thick)) < 0 || fs_fan(m, prev, M, k, &down)) goto done;
    /* the prism's walls and cap */
    memcpy(prev, m->loop, (size_t)M * sizeof(int));
    for (k = 1; k <= Hw; ++k) {
        const double z = (double)height * k / Hw;
        for (i = 0; i < M; ++i)
            if ((ring[i] = fs_vertex(m, F[2 * i], F[2 * i + 1], z)) < 0) goto done;
        {
            /* outward: away from the footprint, per piece (the L is not convex) */
            int j;
            for (j = 0; j < M; ++j) {
                const int a = prev[j], b = prev[(j + 1) % M], c = ring[j], d2 = ring[(j + 1) % M];
                const double ex = F[2 * ((j + 1) % M)] - F[2 * j], ey = F[2 * ((j + 1) % M) + 1] - F[2 * j + 1];
                const double o[3] = {ey, -ex, 0.0}; /* the footprint runs counter-clockwise: outward is to its right */
                if (fs_triangle(m, a, b, d2, o) || fs_triangle(m, a, d2, c, o)) goto done;
            }
        }
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    for (k = 1; k < Kc; ++k) {
        const double s = 1.0 - (double)k / Kc;
        for (i = 0; i < M; ++i)
            if ((ring[i] = fs_vertex(m, cx + (F[2 * i] - cx) * s, cy + (F[2 * i + 1] - cy) * s, (double)height)) < 0) goto done;
        if (fs_strip(m, prev, ring, M, 1, &up)) goto done;
        memcpy(prev, ring, (size_t)M * sizeof(int));
    }
    if ((k = fs_vertex(m, cx, cy, (double)height)) < 0 || fs_fan(m, prev, M, k, &up)) goto done;
    rc = 0;
done:
    free(F);
    free(ring);
    free(prev);
    return rc;
}

static inline int fs_cmp_ll(const void *a, const void *b) {
    const long long x = *(const long long *)a, y = *(const long long *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}
/* 0 when indices are in range, no triangle repeats a vertex and every edge is used at most twice,
 * once in each direction (exactly twice when `closed`); else -1 with the reason. */
static inline int fs_check(const fs_mesh *m, int closed, char *why, size_t size) {
    long long *keys = (long long *)malloc((size_t)m->nf * 3 * sizeof(long long) + 1);
    size_t n = 0, i;
    int f, k;
    if (!keys) { snprintf(why, size, "out of memory"); return -1; }
    for (f = 0; f < m->nf; ++f) {
        const int *t = m->tri + 3 * f;
        for (k = 0; k < 3; ++k)
            if (t[k] < 0 || t[k] >= m->nv) { snprintf(why, size, "triangle %d: vertex %d out of range", f, t[k]); free(keys); return -1; }
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) { snprintf(why, size, "triangle %d repeats a vertex", f); free(keys); return -1; }
        for (k = 0; k < 3; ++k) keys[n++] = (long long)t[k] * m->nv + t[(k + 1) % 3];
    }
    qsort(keys, n, sizeof *keys, fs_cmp_ll);
    for (i = 0; i < n; ++i) {
        const long long a = keys[i] / m->nv, b = keys[i] % m->nv, twin = b * m->nv + a;
        size_t lo = 0, hi = n;
        if (i + 1 < n && keys[i + 1] == keys[i]) {
            snprintf(why, size, "edge %lld-%lld is used twice in one direction", a, b);
            free(keys);
            return -1;
        }
        while (lo < hi) { const size_t mid = (lo + hi) / 2; if (keys[mid] < twin) lo = mid + 1; else hi = mid; }
        if (closed && (lo == n || keys[lo] != twin)) {
            snprintf(why, size, "edge %lld-%lld has no twin: the mesh is not closed", a, b);
            free(keys);
            return -1;
        }
    }
    free(keys);
    return 0;
}

/* The signed volume (positive for a closed mesh oriented outward). */
static inline double fs_volume(const fs_mesh *m) {
    double v = 0.0;
    int f;
    for (f = 0; f < m->nf; ++f) {
        const float *a = m->pos + 3 * m->tri[3 * f], *b = m->pos + 3 * m->tri[3 * f + 1], *c = m->pos + 3 * m->tri[3 * f + 2];
        v += ((double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) - (double)a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
              (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6.0;
    }
    return v;
}

#ifdef SURFBLEND_H
/* The mesh as an sfb_mesh (every face a triangle). */
static inline sfb_result fs_to_mesh(sfb_context *ctx, const fs_mesh *m, sfb_mesh **out) {
    sfb_mesh_desc d;
    sfb_result r;
    int i, *sizes = (int *)malloc((size_t)m->nf * sizeof(int) + 1);
    if (!sizes) return SFB_OUT_OF_MEMORY;
    for (i = 0; i < m->nf; ++i) sizes[i] = 3;
    memset(&d, 0, sizeof d);
    d.vertex_count = m->nv;
    d.positions = m->pos;
    d.face_count = m->nf;
    d.face_sizes = sizes;
    d.face_vertices = m->tri;
    r = sfb_mesh_create(ctx, &d, out);
    free(sizes);
    return r;
}
#endif

/* Writes the mesh as OBJ (v and f lines); 0 on success. */
static inline int fs_write_obj(const fs_mesh *m, const char *path) {
    FILE *f = fopen(path, "w");
    int i;
    if (!f) return -1;
    for (i = 0; i < m->nv; ++i) fprintf(f, "v %.7g %.7g %.7g\n", m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]);
    for (i = 0; i < m->nf; ++i) fprintf(f, "f %d %d %d\n", m->tri[3 * i] + 1, m->tri[3 * i + 1] + 1, m->tri[3 * i + 2] + 1);
    return fclose(f) == 0 ? 0 : -1;
}
#endif
