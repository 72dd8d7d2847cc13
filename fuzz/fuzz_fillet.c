/* fuzz_fillet.c - libFuzzer target for rolling-ball fillets (sfb_mesh_fillet, seed 002).
 *
 * Input: raw bytes, read front to back (zeros once they run out):
 *   - byte 0 picks the mesh: random triangles (indices may be out of range, faces non-manifold),
 *     a height field (a small grid with random heights and diagonals: sharp edges everywhere), a
 *     subdivided cube (convex edges meeting at corners; inside out: concave), or one of the
 *     generated shapes of examples/fillet_shapes.h at a small resolution: the fold (angle and
 *     orientation from the bytes), the box-cylinder union, the floor with the L prism; then a few
 *     perturbations of it (a vertex jittered, collapsed onto another, set to NaN / infinity /
 *     huge; a triangle flipped, dropped or rewired; the whole mesh scaled), optional crease tags
 *     on mesh edges;
 *   - the configuration: radius (NaN, infinities, zero, negative, tiny, huge, raw, or a fraction
 *     of the mesh's size), angle, profile (valid and not), conic weight, Hermite scale, alpha,
 *     samples (capped so that a run stays short, plus the invalid values around the limits),
 *     chord ratio, map mode, skip_failed; caller curves (none, the shape's own seam or a piece of it, reversed,
 *     a random walk along mesh edges, random indices out of range too, too short, NULL) with
 *     their own radius, profile and weight; a progress callback that cancels at its k-th call
 *     now and then, and always after a number of curves that shrinks as the mesh grows (an angle
 *     near 0 makes hundreds of curves: seconds a run), so that a run stays short.
 *   - the memory budget now and then tight (SFB_LIMIT_EXCEEDED or SFB_OUT_OF_MEMORY).
 * Invariants (abort() when violated):
 *   - success: *out is a mesh with the input's vertex and face counts, triangles with identical
 *     indices, no more crease tags than the input, every position finite; the report has one
 *     entry per curve (the caller's count when curves are given), vertices_moved the sum of the
 *     entries' and the corners', curves_skipped the skipped entries (none without skip_failed, not
 *     all of them), each entry's fields sane (flags 0/1, counts within the mesh, radius the
 *     curve's, lengths and deviations finite and >= 0, map 0..2 and 0 for the direct map, a
 *     skipped curve moved nothing), faces_folded within the faces; from finite input,
 *     no vertex moves farther than the fillet reaches (4 alpha r max(tan 85 deg, 1 / sin of half
 *     the sharpest fold's angle) per curve, summed, plus 1e-3 of the bounding-box diagonal), and
 *     with arc and conic profiles (inside the hull of their control points: the linkage points on
 *     the mesh and the tangents' meeting point, near the curve) no vertex leaves the input's
 *     bounding box grown by its diagonal;
 *   - failure: *out NULL, the report zeroed, an error message set, SFB_CANCELLED only when the
 *     callback cancelled;
 *   - either way the input mesh's positions are bit for bit unchanged, and nothing allocated by
 *     the call outlives it (a counting allocator: after freeing the output and the report the
 *     live block count is back where it was).
 *
 * Debugging: FUZZ_FILLET_VERBOSE=1 prints the configuration, the result and the report;
 * FUZZ_FILLET_DUMP=PREFIX writes the input mesh to PREFIX-in.obj and the output to PREFIX-out.obj;
 * FUZZ_FILLET_NO_GEOMETRY=1 skips the two geometric checks (to hunt other failures while a known
 * geometric one is open).
 *
 * Build (from the repository root):
 *   clang -g -O1 -fsanitize=fuzzer,address,undefined -I. fuzz/fuzz_fillet.c -x c tools/impl.c -o fuzz_fillet
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"
#include "examples/fillet_shapes.h"

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_fillet: invariant violated: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    abort();
}

/* ---- the byte reader ---- */
typedef struct reader { const uint8_t *p; size_t n, at; } reader;
static unsigned u8(reader *r) { return r->at < r->n ? r->p[r->at++] : 0u; }
static unsigned u16(reader *r) { const unsigned a = u8(r); return a | u8(r) << 8; }
static float f32(reader *r)
{
    uint32_t u = (uint32_t)u16(r);
    float f;
    u |= (uint32_t)u16(r) << 16;
    memcpy(&f, &u, sizeof f);
    return f;
}
/* The special values every float parameter meets now and then. */
static float special(unsigned k, reader *r)
{
    switch (k % 10) {
    case 0: return (float)NAN;
    case 1: return (float)INFINITY;
    case 2: return -(float)INFINITY;
    case 3: return 0.0f;
    case 4: return -1.0f;
    case 5: return 1e30f;
    case 6: return FLT_MAX;
    case 7: return 1e-30f;
    case 8: return 1e-45f; /* denormal */
    default: return f32(r);
    }
}

/* ---- the counting allocator: what a call allocates and does not free shows in `live` ---- */
static long live;
static void *c_alloc(size_t size, void *user) { void *p = malloc(size); (void)user; if (p) live++; return p; }
static void *c_realloc(void *ptr, size_t size, void *user)
{
    void *p = realloc(ptr, size);
    (void)user;
    if (p && !ptr) live++;
    return p;
}
static void c_free(void *ptr, void *user) { (void)user; if (ptr) { live--; free(ptr); } }

/* progress: cancel at the k-th call (k < 0: never), and at the limit-th: every curve reports five
 * stages, so the limit bounds the curves a run fillets (an angle near 0 makes every edge with any
 * dihedral angle a curve of its own: hundreds of curves, seconds a run) */
typedef struct cancel_at { int k, limit, calls; } cancel_at;
static int on_progress(float done, const char *stage, void *user)
{
    cancel_at *c = (cancel_at *)user;
    const int n = c->calls++;
    if (!(done >= 0.0f && done <= 1.0f)) fail("progress outside [0, 1]", stage);
    if (!stage || !stage[0]) fail("progress without a stage name", NULL);
    return n == c->k || n >= c->limit;
}

static int write_file(const void *data, size_t size, void *user) { return fwrite(data, 1, size, (FILE *)user) != size; }

/* ---- meshes ---- */
#define MAX_V 2048
#define MAX_F 4096

static int random_soup(fs_mesh *m, reader *r)
{
    int i;
    memset(m, 0, sizeof *m);
    m->nv = 3 + (int)(u8(r) % 14);
    m->nf = 1 + (int)(u8(r) % 24);
    m->pos = (float *)malloc(sizeof(float) * 3 * (size_t)m->nv);
    m->tri = (int *)malloc(sizeof(int) * 3 * (size_t)m->nf);
    if (!m->pos || !m->tri) return -1;
    for (i = 0; i < 3 * m->nv; ++i) m->pos[i] = (float)(int8_t)u8(r) / 16.0f;
    for (i = 0; i < 3 * m->nf; ++i) {
        const unsigned b = u8(r);
        m->tri[i] = b == 255 ? -1 : b == 254 ? m->nv : (int)(b % (unsigned)m->nv);
    }
    return 0;
}

/* A (w+1) x (h+1) grid with random heights, each quad split along a random diagonal. */
static int height_field(fs_mesh *m, reader *r)
{
    const int w = 1 + (int)(u8(r) % 6), h = 1 + (int)(u8(r) % 6);
    const float amp = (float)(1 + u8(r) % 8) / 16.0f;
    int i, j;
    memset(m, 0, sizeof *m);
    m->nv = (w + 1) * (h + 1);
    m->pos = (float *)malloc(sizeof(float) * 3 * (size_t)m->nv);
    m->tri = (int *)malloc(sizeof(int) * 6 * (size_t)(w * h));
    if (!m->pos || !m->tri) return -1;
    for (j = 0; j <= h; ++j)
        for (i = 0; i <= w; ++i) {
            float *p = m->pos + 3 * (j * (w + 1) + i);
            p[0] = (float)i;
            p[1] = (float)j;
            p[2] = (float)(int8_t)u8(r) / 128.0f * amp * 4.0f;
        }
    for (j = 0; j < h; ++j)
        for (i = 0; i < w; ++i) {
            const int a = j * (w + 1) + i, b = a + 1, c = a + w + 1, d = c + 1, t = 3 * m->nf;
            if (u8(r) & 1) {
                m->tri[t] = a; m->tri[t + 1] = b; m->tri[t + 2] = d;
                m->tri[t + 3] = a; m->tri[t + 4] = d; m->tri[t + 5] = c;
            } else {
                m->tri[t] = a; m->tri[t + 1] = b; m->tri[t + 2] = c;
                m->tri[t + 3] = b; m->tri[t + 4] = d; m->tri[t + 5] = c;
            }
            m->nf += 2;
        }
    return 0;
}

/* The cube [-1,1]^3, each face a g x g grid of split quads, welded, outward (flip: inward). */
static int weld(fs_mesh *m, double x, double y, double z)
{
    int i;
    for (i = 0; i < m->nv; ++i)
        if (m->pos[3 * i] == (float)x && m->pos[3 * i + 1] == (float)y && m->pos[3 * i + 2] == (float)z) return i;
    return fs_vertex(m, x, y, z);
}
static int cube(fs_mesh *m, int g, int flip)
{
    int f, i, j;
    memset(m, 0, sizeof *m);
    for (f = 0; f < 6; ++f) {
        const int ax = f % 3;
        const double s = f < 3 ? 1.0 : -1.0;
        double out[3] = {0, 0, 0};
        int idx[6][6];
        out[ax] = flip ? -s : s;
        for (j = 0; j <= g; ++j)
            for (i = 0; i <= g; ++i) {
                double p[3];
                p[ax] = s;
                p[(ax + 1) % 3] = -1.0 + 2.0 * i / g;
                p[(ax + 2) % 3] = -1.0 + 2.0 * j / g;
                if ((idx[j][i] = weld(m, p[0], p[1], p[2])) < 0) return -1;
            }
        for (j = 0; j < g; ++j)
            for (i = 0; i < g; ++i) {
                if (fs_triangle(m, idx[j][i], idx[j][i + 1], idx[j + 1][i + 1], out)) return -1;
                if (fs_triangle(m, idx[j][i], idx[j + 1][i + 1], idx[j + 1][i], out)) return -1;
            }
    }
    /* a seam for "the shape's curve": the edge x = 1, y = 1 from z = -1 to 1 */
    m->loop = (int *)malloc(sizeof(int) * (size_t)(g + 1));
    if (!m->loop) return -1;
    for (i = 0; i <= g; ++i) m->loop[i] = weld(m, 1.0, 1.0, -1.0 + 2.0 * i / g);
    m->loop_count = g + 1;
    return 0;
}

static float shape_value(unsigned k)
{
    static const float v[] = {(float)NAN, (float)INFINITY, -(float)INFINITY, 1e30f, -1e30f, FLT_MAX, 1e-38f, 0.0f};
    return v[k % 8];
}

static void perturb(fs_mesh *m, reader *r, float size)
{
    int ops = (int)(u8(r) % 8), i;
    while (ops-- > 0 && m->nv > 0 && m->nf > 0) {
        const unsigned kind = u8(r) % 8;
        const int v = (int)(u16(r) % (unsigned)m->nv), w = (int)(u16(r) % (unsigned)m->nv), f = (int)(u16(r) % (unsigned)m->nf);
        switch (kind) {
        case 0: /* a jitter of a few percent of the size */
            for (i = 0; i < 3; ++i) m->pos[3 * v + i] += (float)(int8_t)u8(r) / 2048.0f * size;
            break;
        case 1: /* a tiny one */
            for (i = 0; i < 3; ++i) m->pos[3 * v + i] += (float)(int8_t)u8(r) * 1e-7f * size;
            break;
        case 2: /* collapsed onto another vertex: degenerate triangles */
            memcpy(m->pos + 3 * v, m->pos + 3 * w, 3 * sizeof(float));
            break;
        case 3: /* NaN, infinite, huge or tiny coordinate */
            m->pos[3 * v + u8(r) % 3] = shape_value(u8(r));
            break;
        case 4: { /* a triangle flipped */
            const int t = m->tri[3 * f + 1];
            m->tri[3 * f + 1] = m->tri[3 * f + 2];
            m->tri[3 * f + 2] = t;
            break;
        }
        case 5: /* a triangle dropped (a hole) */
            memmove(m->tri + 3 * f, m->tri + 3 * (f + 1), sizeof(int) * 3 * (size_t)(m->nf - f - 1));
            m->nf--;
            break;
        case 6: /* a triangle's corner rewired */
            m->tri[3 * f + u8(r) % 3] = w;
            break;
        default: { /* the whole mesh scaled (negative: mirrored, inside out) */
            static const float s[] = {1e-6f, 1e-3f, 0.5f, 3.0f, 1e3f, 1e6f, 1e20f, -1.0f};
            const float k = s[u8(r) % 8];
            for (i = 0; i < 3 * m->nv; ++i) m->pos[i] *= k;
            break;
        }
        }
    }
}

/* The smallest interior angle (radians, 0..pi) between the two faces of an edge, over the edges
 * with exactly two faces: pi minus the largest dihedral angle. Near 0 (a fold back onto itself)
 * the ball's centre may lie arbitrarily far away; the arc's middle lies r / sin(angle/2) from the
 * edge. */
static int cmp_key(const void *a, const void *b)
{
    const long long *x = (const long long *)a, *y = (const long long *)b;
    return x[0] < y[0] ? -1 : x[0] > y[0] ? 1 : 0;
}
static double sharpest_fold(const sfb_mesh_desc *d)
{
    long long *keys = (long long *)malloc(sizeof(long long) * 2 * 3 * (size_t)d->face_count + 1);
    double best = 3.14159265358979323846;
    int f, k, n = 0, i;
    if (!keys) return 0.0;
    for (f = 0; f < d->face_count; ++f)
        for (k = 0; k < 3; ++k) {
            const long long a = d->face_vertices[3 * f + k], b = d->face_vertices[3 * f + (k + 1) % 3];
            keys[2 * n] = (a < b ? a : b) * d->vertex_count + (a < b ? b : a);
            keys[2 * n + 1] = f;
            n++;
        }
    qsort(keys, (size_t)n, 2 * sizeof(long long), cmp_key);
    for (i = 0; i < n; ++i) {
        double nm[2][3], c, l0, l1;
        int q;
        if (i + 1 >= n || keys[2 * i] != keys[2 * i + 2] || (i + 2 < n && keys[2 * i + 4] == keys[2 * i])) continue;
        if (i > 0 && keys[2 * i - 2] == keys[2 * i]) continue;
        for (q = 0; q < 2; ++q) {
            const int *t = d->face_vertices + 3 * keys[2 * (i + q) + 1];
            const float *A = d->positions + 3 * t[0], *B = d->positions + 3 * t[1], *C = d->positions + 3 * t[2];
            const double u[3] = {(double)B[0] - A[0], (double)B[1] - A[1], (double)B[2] - A[2]};
            const double v[3] = {(double)C[0] - A[0], (double)C[1] - A[1], (double)C[2] - A[2]};
            nm[q][0] = u[1] * v[2] - u[2] * v[1];
            nm[q][1] = u[2] * v[0] - u[0] * v[2];
            nm[q][2] = u[0] * v[1] - u[1] * v[0];
        }
        l0 = sqrt(nm[0][0] * nm[0][0] + nm[0][1] * nm[0][1] + nm[0][2] * nm[0][2]);
        l1 = sqrt(nm[1][0] * nm[1][0] + nm[1][1] * nm[1][1] + nm[1][2] * nm[1][2]);
        if (!(l0 > 0 && l1 > 0)) continue; /* a degenerate face: no angle */
        c = (nm[0][0] * nm[1][0] + nm[0][1] * nm[1][1] + nm[0][2] * nm[1][2]) / (l0 * l1);
        c = c > 1 ? 1 : c < -1 ? -1 : c;
        if (3.14159265358979323846 - acos(c) < best) best = 3.14159265358979323846 - acos(c);
        i++;
    }
    free(keys);
    return best;
}

/* A neighbour of v along a triangle edge, the choice-th one found; -1 for none. */
static int neighbour(const fs_mesh *m, int v, unsigned choice)
{
    int f, k, found = 0, first = -1;
    for (f = 0; f < m->nf; ++f)
        for (k = 0; k < 3; ++k)
            if (m->tri[3 * f + k] == v) {
                const int n = m->tri[3 * f + (k + 1) % 3];
                if (n < 0 || n >= m->nv) continue;
                if (first < 0) first = n;
                if ((unsigned)found++ == choice) return n;
            }
    return first;
}

static int neighbour_of(const fs_mesh *m, int a, int b)
{
    int f, k;
    for (f = 0; f < m->nf; ++f)
        for (k = 0; k < 3; ++k)
            if ((m->tri[3 * f + k] == a && m->tri[3 * f + (k + 1) % 3] == b) ||
                (m->tri[3 * f + k] == b && m->tri[3 * f + (k + 1) % 3] == a))
                return 1;
    return 0;
}

#define MAX_CURVES 4
#define MAX_CHAIN 600

/* One caller curve's vertices into buf; returns the count (the curve's vertices may be NULL). */
static int make_chain(const fs_mesh *m, reader *r, int *buf, int *null_vertices)
{
    const unsigned kind = u8(r) % 8;
    int n = 0, i;
    *null_vertices = 0;
    switch (kind) {
    case 0: /* the shape's own seam */
    case 1: /* a piece of it */
    case 2: /* reversed */
        if (m->loop_count >= 2 && m->loop_count <= MAX_CHAIN) {
            int a = 0, b = m->loop_count - 1;
            if (kind == 1) {
                a = (int)(u8(r) % (unsigned)m->loop_count);
                b = (int)(u8(r) % (unsigned)m->loop_count);
                if (a > b) { const int t = a; a = b; b = t; }
            }
            for (i = a; i <= b; ++i) buf[n++] = m->loop[kind == 2 ? m->loop_count - 1 - i : i];
            return n;
        }
        /* no seam: a walk */
        /* fall through */
    case 3:
    case 4: { /* a random walk along mesh edges, closed now and then */
        int len = 2 + (int)(u8(r) % 24), v = m->nv ? (int)(u16(r) % (unsigned)m->nv) : 0, close = (int)(u8(r) % 4);
        buf[n++] = v;
        while (n < len) {
            const int w = neighbour(m, v, u8(r) % 8);
            if (w < 0) break;
            buf[n++] = v = w;
        }
        if (n >= 3 && ((close == 1 && neighbour_of(m, buf[n - 1], buf[0])) || close == 2)) buf[n++] = buf[0]; /* closed (or not a chain) */
        return n;
    }
    case 5: /* random indices, out of range too */
        n = (int)(u8(r) % 12);
        for (i = 0; i < n; ++i) {
            const unsigned b = u8(r);
            buf[i] = b >= 250 ? (b == 255 ? -1 : b == 254 ? m->nv : b == 253 ? 0x7fffffff : b == 252 ? (int)0x80000000u : m->nv + 1)
                              : (int)(b % (unsigned)(m->nv ? m->nv : 1));
        }
        return n;
    case 6: /* too short */
        buf[0] = m->nv ? (int)(u8(r) % (unsigned)m->nv) : 0;
        return u8(r) & 1;
    default: /* NULL vertices */
        *null_vertices = 1;
        return 2 + (int)(u8(r) % 3);
    }
}

/* The radius: special values, or a fraction of the mesh's size (where fillets fit). */
static float radius_from(reader *r, float size)
{
    const unsigned k = u8(r);
    if (k % 4 == 3) return special(k / 4, r);
    return size * (float)(1 + u8(r)) / (k % 4 == 1 ? 1024.0f : 4096.0f);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int chains[MAX_CURVES][MAX_CHAIN + 2];
    reader rd = {data, size, 0}, *r = &rd;
    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL, *out = NULL;
    sfb_mesh_desc d, od;
    sfb_fillet_config cfg;
    sfb_fillet_curve curves[MAX_CURVES];
    sfb_fillet_report rep, zero_rep;
    sfb_result res;
    cancel_at cancel = {-1, 0, 0};
    fs_mesh m;
    float *before = NULL, msize = 1.0f;
    int crease_pairs[8], ncrease = 0, i, k, ncurves = 0, finite_in = 1, pass_rep;
    float crease_s[4];
    long live0;
    const unsigned mode = u8(r) % 8;

    memset(&m, 0, sizeof m);
    /* the mesh */
    switch (mode) {
    case 0: if (random_soup(&m, r)) goto out_free; msize = 8.0f; break;
    case 1: if (height_field(&m, r)) goto out_free; msize = 4.0f; break;
    case 2: if (cube(&m, 1 + (int)(u8(r) % 4), (int)(u8(r) & 1))) goto out_free; msize = 3.5f; break;
    case 3:
    case 4: {
        static const float ang[] = {90.0f, 120.0f, 60.0f, 150.0f, 30.0f, 170.0f, 179.5f, 45.0f, 10.0f, 100.0f, 135.0f, 90.0f};
        const int n = 2 + (int)(u8(r) % 12);
        const unsigned a = u8(r);
        const float angle = a < 240 ? ang[a % 12] : 1.0f + (float)u8(r) * 179.0f / 255.0f;
        if (fs_fold(&m, n, 2.0f, 1.0f, angle, (int)(u8(r) & 1))) goto out_free;
        msize = 3.0f;
        break;
    }
    case 5:
    case 6: {
        static const float rad[] = {0.5f, 0.3f, 0.7f, 0.45f};
        if (fs_box_cylinder(&m, 2 + (int)(u8(r) % 4), 1.0f, 0.6f, rad[u8(r) % 4], 0.6f)) goto out_free;
        msize = 3.0f;
        break;
    }
    default:
        if (fs_floor_lprism(&m, 2 + (int)(u8(r) % 3), 2.5f, 0.3f, 1.0f, 0.4f, 0.5f)) goto out_free;
        msize = 3.0f;
        break;
    }
    if (m.nv > MAX_V || m.nf > MAX_F) goto out_free;
    perturb(&m, r, msize);

    /* crease tags on a few mesh edges (the filleted ones lose theirs) */
    if (u8(r) & 1) {
        const int want = (int)(u8(r) % 4);
        for (i = 0; i < want && m.nf > 0; ++i) {
            const int f = (int)(u16(r) % (unsigned)m.nf), c = (int)(u8(r) % 3);
            crease_pairs[2 * ncrease] = m.tri[3 * f + c];
            crease_pairs[2 * ncrease + 1] = m.tri[3 * f + (c + 1) % 3];
            crease_s[ncrease++] = (float)(u8(r) % 12);
        }
    }
    for (i = 0; i < m.loop_count; ++i)
        if (m.loop[i] < 0) goto out_free;

    cc.ignore_environment = 1;
    cc.memory_budget = (size_t)64 << 20;
    cc.allocator.alloc = c_alloc;
    cc.allocator.realloc = c_realloc;
    cc.allocator.free = c_free;
    {
        const unsigned c = u8(r);
        if (c % 8 == 7) cancel.k = (int)(c / 8 % 24); /* a cancel on purpose */
        if (c % 32 == 1) cc.memory_budget = (size_t)(16 + u16(r)) << 6; /* tight: the budget check */
        cancel.limit = 5 * (1000 / m.nv < 2 ? 2 : 1000 / m.nv > 24 ? 24 : 1000 / m.nv);
        cc.progress.func = on_progress;
        cc.progress.user = &cancel;
    }
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) goto out_free;
    {
        int *sizes = (int *)malloc(sizeof(int) * (size_t)m.nf + 1);
        sfb_mesh_desc md;
        if (!sizes) goto out_free;
        for (i = 0; i < m.nf; ++i) sizes[i] = 3;
        memset(&md, 0, sizeof md);
        md.vertex_count = m.nv;
        md.positions = m.pos;
        md.face_count = m.nf;
        md.face_sizes = sizes;
        md.face_vertices = m.tri;
        md.crease_count = ncrease;
        md.crease_vertices = crease_pairs;
        md.crease_sharpness = crease_s;
        res = sfb_mesh_create(ctx, &md, &mesh);
        if (res != SFB_SUCCESS && ncrease) { /* the tags may name no edge: without them */
            md.crease_count = 0;
            res = sfb_mesh_create(ctx, &md, &mesh);
        }
        free(sizes);
        if (res != SFB_SUCCESS) goto out_free;
    }

    /* the configuration */
    cfg = sfb_fillet_config_init(radius_from(r, msize));
    {
        unsigned b = u8(r);
        cfg.angle = b % 8 == 0 ? 0.0f : b % 8 == 1 ? special(u8(r), r) : b % 8 == 2 ? 180.0f : (float)u8(r) * 179.9f / 255.0f;
        b = u8(r);
        cfg.profile = b & 128 ? (int)(b % 7) - 2 : (int)(b % 4);
        b = u8(r);
        cfg.conic_weight = b % 4 == 3 ? special(b / 4, r) : b % 4 == 0 ? 0.0f : (float)u8(r) / 64.0f;
        b = u8(r);
        cfg.hermite_scale = b % 4 == 3 ? special(b / 4, r) : b % 4 == 0 ? 0.0f : (float)u8(r) / 64.0f;
        b = u8(r);
        cfg.alpha = b % 4 == 3 ? special(b / 4, r) : b % 4 == 0 ? 0.0f : b % 4 == 2 ? (float)(b / 4) * 2.0f : 1.0f + (float)u8(r) / 32.0f;
        b = u8(r);
        switch (b % 10) {
        case 0: cfg.samples = 0; break;
        case 1: cfg.samples = (int)(b / 10 % 4) - 2; break;          /* -2 .. 1 */
        case 2: cfg.samples = b & 16 ? 100001 : 100000; break;       /* beyond the limit, at the limit */
        default: cfg.samples = 2 + (int)(u8(r) % 80); break;
        }
        if (cfg.samples == 100000 && m.nv > 200) cfg.samples = 1000; /* keep a run short */
        b = u8(r);
        cfg.chord_ratio = b % 4 == 3 ? special(b / 4, r) : b % 4 == 0 ? 0.0f : b % 4 == 2 ? 1.0f - (float)(b / 4) / 64.0f : (float)u8(r) / 1024.0f;
        b = u8(r);
        cfg.map = b % 8 < 3 ? SFB_FILLET_MAP_CONFORMAL : b % 8 < 6 ? SFB_FILLET_MAP_DIRECT : b % 8 == 6 ? (int)(b / 8) - 16 : 2;
    }
    /* caller curves */
    {
        const unsigned b = u8(r);
        if (b % 3 == 0 && b != 0) {
            ncurves = 1 + (int)(b / 3 % MAX_CURVES);
            for (k = 0; k < ncurves; ++k) {
                int nullv = 0, n = make_chain(&m, r, chains[k], &nullv);
                const unsigned c = u8(r);
                memset(&curves[k], 0, sizeof curves[k]);
                curves[k].vertices = nullv ? NULL : chains[k];
                curves[k].count = n;
                if (c & 1) curves[k].radius = radius_from(r, msize);
                if (c & 2) curves[k].profile = (int)(u8(r) % 7) - 1; /* -1 .. 5: 0 the config's, 1..4 the kinds */
                if (c & 4) curves[k].conic_weight = c & 8 ? special(u8(r), r) : (float)u8(r) / 64.0f;
            }
            cfg.curves = curves;
            cfg.curve_count = ncurves;
            if (u8(r) == 255) cfg.curve_count = -1;
        } else if (b == 1) {
            cfg.curves = curves; /* curves with curve_count 0: nothing to fillet */
        } else if (b == 254) {
            cfg.curve_count = 2; /* a count without curves */
        }
    }

    sfb_mesh_get_desc(mesh, &d);
    before = (float *)malloc(sizeof(float) * 3 * (size_t)d.vertex_count + 1);
    if (!before) goto out_free;
    memcpy(before, d.positions, sizeof(float) * 3 * (size_t)d.vertex_count);
    for (i = 0; i < 3 * d.vertex_count; ++i) finite_in &= isfinite(d.positions[i]) != 0;

    memset(&zero_rep, 0, sizeof zero_rep);
    memset(&rep, 0x5a, sizeof rep);
    out = (sfb_mesh *)&rep; /* not NULL: a failure must clear it */
    live0 = live;
    pass_rep = u8(r) != 7;
    cfg.skip_failed = (int)(u8(r) & 1); /* a curve the radius cannot fillet is left sharp (the call fails when all are) */
    if (getenv("FUZZ_FILLET_VERBOSE"))
        fprintf(stderr, "fuzz_fillet: angle %g profile %d conic %g hermite %g alpha %g samples %d chord %g map %d\n", (double)cfg.angle,
                cfg.profile, (double)cfg.conic_weight, (double)cfg.hermite_scale, (double)cfg.alpha, cfg.samples, (double)cfg.chord_ratio, cfg.map);
    res = sfb_mesh_fillet(ctx, mesh, &cfg, &out, pass_rep ? &rep : NULL);
    if (getenv("FUZZ_FILLET_VERBOSE"))
        fprintf(stderr, "fuzz_fillet: mode %u, %d vertices, %d faces, radius %g, %d curves: %s%s%s\n", mode, d.vertex_count, d.face_count,
                (double)cfg.radius, cfg.curve_count, sfb_result_string(res), res ? " -- " : "", res ? sfb_last_error(ctx) : "");
    if (getenv("FUZZ_FILLET_DUMP")) { /* the input and the output as OBJ: PREFIX-in.obj, PREFIX-out.obj */
        char path[512];
        FILE *f;
        snprintf(path, sizeof path, "%s-in.obj", getenv("FUZZ_FILLET_DUMP"));
        if ((f = fopen(path, "wb"))) { sfb_mesh_write_obj(mesh, write_file, f); fclose(f); }
        snprintf(path, sizeof path, "%s-out.obj", getenv("FUZZ_FILLET_DUMP"));
        if (res == SFB_SUCCESS && (f = fopen(path, "wb"))) { sfb_mesh_write_obj(out, write_file, f); fclose(f); }
    }
    if (memcmp(before, d.positions, sizeof(float) * 3 * (size_t)d.vertex_count) != 0)
        fail("the input mesh's positions changed", sfb_result_string(res));
    if (res != SFB_SUCCESS) {
        const char *msg = sfb_last_error(ctx);
        if (out) fail("*out not NULL after", sfb_result_string(res));
        if (pass_rep && memcmp(&rep, &zero_rep, sizeof rep) != 0) fail("the report is not zeroed after", sfb_result_string(res));
        if (!msg || !msg[0]) fail("empty error message after", sfb_result_string(res));
        if (res == SFB_CANCELLED && cancel.k < 0 && cancel.calls <= cancel.limit) fail("SFB_CANCELLED without a cancel", NULL);
        if (live != live0) fail("allocations kept after a failure", sfb_result_string(res));
    } else {
        if (!out) fail("success without an output mesh", NULL);
        sfb_mesh_get_desc(out, &od);
        if (od.vertex_count != d.vertex_count || od.face_count != d.face_count) fail("vertex or face count changed", NULL);
        for (i = 0; i < d.face_count; ++i)
            if (od.face_sizes[i] != 3) fail("an output face is not a triangle", NULL);
        if (memcmp(od.face_vertices, d.face_vertices, sizeof(int) * 3 * (size_t)d.face_count) != 0) fail("face indices changed", NULL);
        if (od.crease_count > d.crease_count) fail("crease tags added", NULL);
        if (od.uv_count != d.uv_count) fail("UV count changed", NULL);
        for (i = 0; i < 3 * od.vertex_count; ++i)
            if (!isfinite(od.positions[i])) {
                char why[96];
                snprintf(why, sizeof why, "vertex %d coordinate %d = %g (was %g)", i / 3, i % 3, (double)od.positions[i], (double)before[i]);
                fail(finite_in ? "non-finite output position from finite input" : "non-finite output position", why);
            }
        if (getenv("FUZZ_FILLET_VERBOSE")) {
            double in_max = 0.0, out_max = 0.0, moved_max = 0.0;
            for (i = 0; i < 3 * od.vertex_count; ++i) {
                const double din = fabs((double)before[i]), dout = fabs((double)od.positions[i]);
                const double dm = fabs((double)od.positions[i] - before[i]);
                if (din > in_max) in_max = din;
                if (dout > out_max) out_max = dout;
                if (dm > moved_max) moved_max = dm;
            }
            fprintf(stderr, "fuzz_fillet: largest |coordinate| in %g, out %g; largest move %g\n", in_max, out_max, moved_max);
        }
        if (pass_rep) {
            int sum = 0, skipped = 0, want = cfg.curves ? cfg.curve_count : -1;
            if (rep.curve_count < 0 || (rep.curve_count > 0 && !rep.curves)) fail("report curve_count / curves", NULL);
            if (want >= 0 && rep.curve_count != want) fail("report curve_count differs from the caller's curves", NULL);
            for (k = 0; k < rep.curve_count; ++k) {
                const sfb_fillet_curve_report *c = &rep.curves[k];
                char why[160];
                snprintf(why, sizeof why, "curve %d: closed %d convex %d cv %d r %g len %g/%g samples %d moved %d kept %d si %d dev %g map %d%s", k,
                         c->closed, c->convex, c->curve_vertices, (double)c->radius, (double)c->curve_length, (double)c->spine_length, c->samples,
                         c->vertices_moved, c->vertices_kept, c->self_intersections, (double)c->max_deviation, c->map, c->skipped ? " skipped" : "");
                if (getenv("FUZZ_FILLET_VERBOSE")) fprintf(stderr, "fuzz_fillet: %s\n", why);
                if ((c->closed != 0 && c->closed != 1) || (c->convex != 0 && c->convex != 1)) fail("report flag not 0/1", why);
                if (c->curve_vertices < 2 || (want < 0 && c->curve_vertices > d.vertex_count)) fail("report curve_vertices out of range", why);
                if (!(c->radius > 0.0f) || !isfinite(c->radius)) fail("report radius not positive and finite", why);
                if (want < 0 && c->radius != cfg.radius) fail("report radius is not the config's", why);
                if (want >= 0) {
                    const float cr = curves[k].radius != 0.0f ? curves[k].radius : cfg.radius;
                    const int cn = curves[k].count - c->closed;
                    if (c->radius != cr) fail("report radius is not the curve's", why);
                    if (c->curve_vertices != cn) fail("report curve_vertices is not the curve's", why);
                }
                if (c->skipped != 0 && c->skipped != 1) fail("report skipped not 0/1", why);
                if (c->skipped && (!cfg.skip_failed || c->vertices_moved != 0)) fail("a skipped curve without skip_failed, or with moves", why);
                skipped += c->skipped;
                if (!(c->curve_length >= 0.0f) || !isfinite(c->curve_length)) fail("report curve_length", why);
                if (!(c->spine_length >= 0.0f) || !isfinite(c->spine_length)) fail("report spine_length", why);
                if (!c->skipped && c->samples < 2) fail("report samples < 2", why);
                if (c->vertices_moved < 0 || c->vertices_moved > d.vertex_count) fail("report vertices_moved out of range", why);
                if (c->vertices_kept < 0 || c->vertices_kept > d.vertex_count) fail("report vertices_kept out of range", why);
                if (c->self_intersections < 0) fail("report self_intersections negative", why);
                if (!(c->max_deviation >= 0.0f) || !isfinite(c->max_deviation)) fail("report max_deviation", why);
                if (c->map < 0 || c->map > 2) fail("report map out of range", why);
                if (cfg.map == SFB_FILLET_MAP_DIRECT && c->map != 0) fail("report map not 0 for the direct map", why);
                sum += c->vertices_moved;
            }
            if (getenv("FUZZ_FILLET_VERBOSE"))
                fprintf(stderr, "fuzz_fillet: report: %d curves (%d skipped), %d vertices moved, %d corners (%d vertices), %d faces folded\n",
                        rep.curve_count, rep.curves_skipped, rep.vertices_moved, rep.corner_count, rep.corner_vertices_moved, rep.faces_folded);
            if (skipped != rep.curves_skipped) fail("report curves_skipped is not the skipped entries' count", NULL);
            if (rep.curve_count > 0 && skipped == rep.curve_count) fail("success with every curve skipped", NULL);
            if (rep.corner_count < 0 || rep.corner_count > d.vertex_count || rep.corner_vertices_moved < 0 ||
                rep.corner_vertices_moved > d.vertex_count)
                fail("report corner counts out of range", NULL);
            if (rep.faces_folded < 0 || rep.faces_folded > d.face_count) fail("report faces_folded out of range", NULL);
            /* the curves' moves and the corners' */
            if (rep.vertices_moved != sum + rep.corner_vertices_moved) fail("report vertices_moved is not the curves' and corners' sum", NULL);
            if (finite_in && d.vertex_count > 0 && !getenv("FUZZ_FILLET_NO_GEOMETRY")) {
                /* Geometry. A vertex moves within its blend region, between a linkage point and the
                 * curve, onto a profile near it: not farther than a few times the base patches'
                 * reach alpha r max(1, tan(delta/2)) (delta capped at 170 degrees: tan 85 < 11.5;
                 * the arc's middle lies r / sin(theta/2) from an edge of interior angle theta, so
                 * the sharpest fold of the mesh may raise that), summed over the curves, times the
                 * Hermite scale where it is over 1, plus rounding. Arcs and conics lie in the hull
                 * of their control points (the linkage points on the mesh, the corner where the
                 * tangents meet, near the curve): outputs stay within the input's bounding box
                 * grown by its diagonal (degenerate slivers may push the corner point a little
                 * outside the box; a radius far larger than the mesh throws vertices 1e13 away). */
                double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, diag = 0.0, reach = 0.0, worst = 0.0;
                const double alpha = cfg.alpha > 0.0f ? cfg.alpha : 1.75;
                const double sharp = sharpest_fold(&d); /* the smallest angle between two faces at an edge */
                const double kfac = sharp > 1e-3 ? (1.0 / sin(0.5 * sharp) > 11.5 ? 1.0 / sin(0.5 * sharp) : 11.5) : HUGE_VAL;
                int hull = 1, wv = -1;
                char why[200];
                for (i = 0; i < 3 * d.vertex_count; ++i) {
                    if (before[i] < lo[i % 3]) lo[i % 3] = before[i];
                    if (before[i] > hi[i % 3]) hi[i % 3] = before[i];
                }
                for (i = 0; i < 3; ++i) diag += (hi[i] - lo[i]) * (hi[i] - lo[i]);
                diag = sqrt(diag);
                for (k = 0; k < rep.curve_count; ++k) {
                    const int prof = cfg.curves && curves[k].profile ? curves[k].profile - 1 : cfg.profile;
                    /* a Hermite profile's tangents are hermite_scale chords long (any scale is accepted) */
                    const double hs = prof == SFB_FILLET_HERMITE && cfg.hermite_scale > 1.0f ? cfg.hermite_scale : 1.0;
                    reach += 4.0 * alpha * (double)rep.curves[k].radius * kfac * hs;
                    if (prof != SFB_FILLET_ARC && prof != SFB_FILLET_CONIC) hull = 0;
                }
                for (i = 0; i < d.vertex_count; ++i) {
                    const float *a = before + 3 * i, *b = od.positions + 3 * i;
                    const double mv = sqrt(((double)b[0] - a[0]) * ((double)b[0] - a[0]) + ((double)b[1] - a[1]) * ((double)b[1] - a[1]) +
                                           ((double)b[2] - a[2]) * ((double)b[2] - a[2]));
                    if (mv > worst) { worst = mv; wv = i; }
                }
                snprintf(why, sizeof why, "vertex %d moved %g; %d curves, radius %g, alpha %g: allowed %g (bounding-box diagonal %g)", wv, worst,
                         rep.curve_count, (double)cfg.radius, alpha, reach + 1e-3 * diag, diag);
                if (worst > reach + 1e-3 * diag) fail("a vertex moved farther than the fillet reaches", why);
                for (i = 0; hull && i < 3 * d.vertex_count; ++i)
                    if (od.positions[i] < lo[i % 3] - diag || od.positions[i] > hi[i % 3] + diag) {
                        snprintf(why, sizeof why, "vertex %d coordinate %d: %g -> %g, the box [%g, %g], radius %g", i / 3, i % 3, (double)before[i],
                                 (double)od.positions[i], lo[i % 3], hi[i % 3], (double)cfg.radius);
                        fail("an arc or conic fillet moved a vertex far outside the input's bounding box", why);
                    }
            }
            sfb_fillet_report_free(&rep);
            if (rep.curves || rep.curve_count) fail("sfb_fillet_report_free left the report set", NULL);
        }
        sfb_mesh_destroy(out);
        if (live != live0) fail("allocations kept after the output and the report were freed", NULL);
    }
out_free:
    free(before);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    fs_free(&m);
    return 0;
}
