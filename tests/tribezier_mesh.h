/* Test meshes for the quartic triangular Bezier scheme (tests/tribezier.c, bench): a disk of R
 * rings around one vertex of valence n, made of n wedges of the regular triangle lattice (every
 * other vertex inside has valence 6), as OBJ text. Optionally a straight crease through the
 * centre (the wedges 0..k-1 span pi, the others pi, so the crease vertices lie on the x axis and
 * the surface is a height field: a ridge z = ridge |y| plus a smooth bump; the rays fanned
 * evenly over each side, or with level rows), a corner (three crease rays), and a jitter of
 * every position. */
#ifndef SFB_TRIBEZIER_MESH_H
#define SFB_TRIBEZIER_MESH_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define TBM_PI 3.14159265358979323846

typedef struct tbm_opts {
    int n, R;
    int crease_k;        /* > 0: crease rays 0 and k, a straight crease (without corner3) */
    int corner3;         /* crease rays 0, n/3, 2n/3, the centre tagged as a corner */
    double sharp;        /* the crease tag (0: untagged) */
    double ridge, bump;  /* z = ridge |y| + bump (x^2 - 0.5 y^2) / R^2 */
    double jitter;       /* random displacement of every vertex, in edge lengths */
    int level;           /* with crease_k: level rows (below) */
    unsigned seed;
} tbm_opts;

static unsigned tbm_rand(unsigned *s) { *s = *s * 1664525u + 1013904223u; return *s >> 8; }
static double tbm_unit(unsigned *s) { return (double)tbm_rand(s) / 16777216.0; }

/* Index of lattice point (a, b) of wedge w (a + b = ring r). */
static int tbm_index(const tbm_opts *o, int w, int a, int b) {
    const int r = a + b;
    if (r == 0) return 0;
    return 1 + o->n * (r - 1) * r / 2 + (w * r + b) % (o->n * r);
}

/* The mesh as OBJ text (malloc'd). */
static char *tbm_obj(const tbm_opts *o) {
    const int n = o->n, R = o->R, nv = 1 + n * R * (R + 1) / 2;
    size_t cap = (size_t)nv * 80 + (size_t)n * R * R * 2 * 40 + 4096, len = 0;
    char *s = (char *)malloc(cap);
    unsigned seed = o->seed ? o->seed : 1u;
    int r, w, b, a;
    double *ex = (double *)malloc(sizeof(double) * 2 * (size_t)(n + 1)), *ey = ex + n + 1;
    /* ray steps: unit vectors at angles spread evenly (over pi per side of a crease) */
    for (w = 0; w <= n; ++w) {
        double ang = 2.0 * TBM_PI * w / n;
        if (o->crease_k > 0 && !o->corner3)
            ang = w <= o->crease_k ? TBM_PI * w / o->crease_k : TBM_PI + TBM_PI * (w - o->crease_k) / (n - o->crease_k);
        ex[w] = cos(ang); ey[w] = sin(ang);
        if (o->level && o->crease_k > 0 && !o->corner3) {
            /* level rows: every ray step off the crease rises sqrt(3)/2 from it, so the lattice
             * rows of both sides lie at y = +-(sqrt(3)/2) x row, as in the regular lattice
             * (where a side has three wedges it is the regular lattice); Loop's limit surface
             * along the regular crease edges then lies in the vertical plane through the
             * crease by symmetry */
            const int side = w > o->crease_k, k = side ? n - o->crease_k : o->crease_k, i = side ? w - o->crease_k : w;
            const double sg = side ? -1.0 : 1.0;
            if (i == 0) { ex[w] = sg; ey[w] = 0.0; }
            else if (i == k) { ex[w] = -sg; ey[w] = 0.0; }
            else { ex[w] = sg * (k > 2 ? (k - 2.0 * i) / (2.0 * (k - 2)) : 0.0); ey[w] = sg * sqrt(0.75); }
        }
    }
    len += (size_t)snprintf(s + len, cap - len, "v 0 0 %.17g\n", 0.0);
    for (r = 1; r <= R; ++r)
        for (w = 0; w < n; ++w)
            for (b = 0; b < r; ++b) {
                /* point b of ring r in wedge w: between ray w and ray w+1 */
                const double t = (double)b / r;
                /* straight lattice rows: interpolate the two ray points linearly */
                const double x0 = r * ex[w], y0 = r * ey[w], x1 = r * ex[w + 1], y1 = r * ey[w + 1];
                double x = x0 + t * (x1 - x0), y = y0 + t * (y1 - y0), z;
                if (o->jitter > 0) { x += o->jitter * (tbm_unit(&seed) - 0.5); y += o->jitter * (tbm_unit(&seed) - 0.5); }
                z = o->ridge * fabs(y) + o->bump * (x * x - 0.5 * y * y) / (R * R);
                if (o->jitter > 0) z += o->jitter * (tbm_unit(&seed) - 0.5);
                len += (size_t)snprintf(s + len, cap - len, "v %.17g %.17g %.17g\n", x, y, z);
            }
    for (w = 0; w < n; ++w)
        for (a = 0; a < R; ++a)
            for (b = 0; a + b < R; ++b) {
                len += (size_t)snprintf(s + len, cap - len, "f %d %d %d\n", tbm_index(o, w, a, b) + 1, tbm_index(o, w, a + 1, b) + 1,
                                        tbm_index(o, w, a, b + 1) + 1);
                if (a + b + 1 < R)
                    len += (size_t)snprintf(s + len, cap - len, "f %d %d %d\n", tbm_index(o, w, a + 1, b) + 1,
                                            tbm_index(o, w, a + 1, b + 1) + 1, tbm_index(o, w, a, b + 1) + 1);
            }
    if (o->sharp > 0 && (o->crease_k > 0 || o->corner3)) {
        int rays[3], nr = 0, k;
        rays[nr++] = 0;
        if (o->corner3) { rays[nr++] = n / 3; rays[nr++] = 2 * n / 3; }
        else rays[nr++] = o->crease_k;
        for (k = 0; k < nr; ++k)
            for (r = 0; r < R; ++r)
                len += (size_t)snprintf(s + len, cap - len, "t crease 2/1/0 %d %d %.17g\n", tbm_index(o, rays[k], r, 0),
                                        tbm_index(o, rays[k], r + 1, 0), o->sharp);
        if (o->corner3) len += (size_t)snprintf(s + len, cap - len, "t corner 1/1/0 0 %.17g\n", o->sharp);
    }
    free(ex);
    return s;
}
#endif
