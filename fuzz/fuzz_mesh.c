/* fuzz_mesh.c - libFuzzer target for sfb_mesh_create and the surfaces built from it.
 *
 * The input bytes are read as a recipe for an sfb_mesh_desc: counts, face sizes, indices, raw
 * float bits (NaN, inf, denormals), optional arrays, enum values, and now and then junk:
 * negative or over-limit counts, out-of-range indices, NULL arrays with non-zero counts,
 * out-of-range enums. Every array is allocated with exactly the length the desc promises
 * (so AddressSanitizer sees any over-read); a junk count is always negative or above
 * SFB_MAX_ELEMENTS and must be refused before its array is read.
 *
 * If sfb_mesh_create accepts the desc: OBJ write/re-read round trip (same counts),
 * sfb_mesh_triangulate (k - 2 triangles per face of k corners), then one
 * surface (scheme, level 0..2 and flags from the input), sfb_surface_refine with topology
 * checks, and one sfb_surface_eval_stencils call. Invariant violations abort().
 *
 * Build (from the repository root):
 *   clang -g -O1 -fsanitize=fuzzer,address,undefined -I. fuzz/fuzz_mesh.c -x c tools/impl.c -o fuzz_mesh
 */
#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

/* ------------------------------------------------------------------ input reader */

typedef struct reader { const uint8_t *p; size_t n; } reader;

static uint8_t u8(reader *r)
{
    if (!r->n) return 0;
    r->n--;
    return *r->p++;
}

static uint32_t u32(reader *r)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++) v |= (uint32_t)u8(r) << (8 * i);
    return v;
}

/* Mostly small, well-formed numbers; sometimes raw bits (NaN, inf, huge, denormal). */
static float num(reader *r)
{
    uint8_t m = u8(r);
    if (m < 224) return (float)((int)u8(r) - 128) / (float)(1 + (m & 7));
    uint32_t bits = u32(r);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* Sharpness: mostly 0..12 in quarter steps, sometimes raw bits (negative, NaN, inf). */
static float sharp(reader *r)
{
    uint8_t m = u8(r);
    if (m < 240) return (float)(m % 49) * 0.25f;
    uint32_t bits = u32(r);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* An index into [0, n), or (rarely) junk. */
static int index_of(reader *r, int n)
{
    uint8_t m = u8(r);
    if (m < 248 && n > 0) return (int)(u8(r) | (m & 7) << 8) % n;
    static const int junk[8] = { -1, 0, 1, INT_MIN, INT_MAX, -2, 0, 0 };
    int j = junk[m & 7];
    if (m & 1) j = n + (m & 6) / 2; /* n, n+1, n+2, n+3 */
    return j;
}

/* A count in [0, max], or (rarely, when junk_ok) a junk count: negative or over the limits. */
static int count_of(reader *r, int max, int junk_ok, int *junk)
{
    uint8_t m = u8(r);
    *junk = 0;
    if (junk_ok && m >= 250) {
        static const int junk_counts[6] = { -1, INT_MIN, SFB_MAX_ELEMENTS + 1, INT_MAX, -7, 2000000000 };
        *junk = 1;
        return junk_counts[m - 250];
    }
    return (int)(m | (u8(r) & 1) << 8) % (max + 1);
}

/* An enum value: mostly in range, sometimes not. */
static int enum_of(reader *r, int n)
{
    uint8_t m = u8(r);
    if (m < 240) return m % n;
    static const int junk[4] = { -1, 3, 100, INT_MIN };
    return junk[m & 3] == 3 ? n : junk[m & 3];
}

/* Array of n elements of size sz (n <= 0: a small dummy array that must not be read as n). */
static void *array(int n, size_t sz)
{
    size_t count = n > 0 ? (size_t)n : 1;
    void *p = calloc(count, sz);
    if (!p) abort();
    return p;
}

/* ------------------------------------------------------------------ checks */

static void fail(const char *what)
{
    fprintf(stderr, "fuzz_mesh: invariant violated: %s\n", what);
    abort();
}

static void check_error(sfb_context *ctx, sfb_result r, const char *call)
{
    if (r == SFB_SUCCESS) return;
    if (r > 0 || r < SFB_RESULT_MIN_) {
        fprintf(stderr, "%s returned %d\n", call, (int)r);
        fail("result outside sfb_result");
    }
    const char *m = sfb_last_error(ctx);
    if (!m || !m[0]) {
        fprintf(stderr, "%s failed with %s\n", call, sfb_result_string(r));
        fail("empty error message after a failure");
    }
}

typedef struct membuf { char *data; size_t size, cap; } membuf;

static int membuf_write(const void *data, size_t size, void *user)
{
    membuf *b = user;
    if (size > ((size_t)64 << 20) - b->size) return 1;
    if (b->size + size > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->size + size) cap *= 2;
        char *nd = realloc(b->data, cap);
        if (!nd) return 1;
        b->data = nd;
        b->cap = cap;
    }
    memcpy(b->data + b->size, data, size);
    b->size += size;
    return 0;
}

static void round_trip(sfb_context *ctx, const sfb_mesh *mesh)
{
    sfb_mesh_desc d1, d2;
    sfb_mesh_get_desc(mesh, &d1);
    membuf b = { 0 };
    sfb_result r = sfb_mesh_write_obj(mesh, membuf_write, &b);
    if (r != SFB_SUCCESS) {
        fprintf(stderr, "sfb_mesh_write_obj: %s\n", sfb_result_string(r));
        fail("writing an accepted mesh failed");
    }
    sfb_mesh *again = NULL;
    r = sfb_mesh_read_obj(ctx, b.data ? b.data : "", b.size, &again);
    if (r != SFB_SUCCESS) {
        fprintf(stderr, "re-read: %s: %s\n--- written OBJ ---\n%.*s\n---\n", sfb_result_string(r),
                sfb_last_error(ctx), (int)(b.size < 4000 ? b.size : 4000), b.data ? b.data : "");
        fail("the library cannot re-read the OBJ it wrote for an accepted mesh");
    }
    sfb_mesh_get_desc(again, &d2);
    if (d1.vertex_count != d2.vertex_count || d1.face_count != d2.face_count) {
        fprintf(stderr, "vertices %d -> %d, faces %d -> %d\n", d1.vertex_count, d2.vertex_count,
                d1.face_count, d2.face_count);
        fail("round trip changed vertex/face counts");
    }
    long fv = 0;
    for (int f = 0; f < d1.face_count; f++) {
        if (d1.face_sizes[f] != d2.face_sizes[f]) fail("round trip changed a face size");
        fv += d1.face_sizes[f];
    }
    for (long i = 0; i < fv; i++)
        if (d1.face_vertices[i] != d2.face_vertices[i]) fail("round trip changed face vertices");
    if (d1.hole_count != d2.hole_count) fail("round trip changed the hole count");
    if ((d1.uv_count > 0) != (d2.uv_count > 0)) fail("round trip gained or lost UVs");
    sfb_mesh_destroy(again);
    free(b.data);
}

static void check_data(const sfb_mesh_data *d)
{
    if (d->vertex_count < 0 || d->face_count < 0 || d->face_vertex_count < 0) fail("negative refined count");
    if (d->face_count > 0 && (!d->face_sizes || !d->face_vertices)) fail("refined faces missing");
    long total = 0;
    for (int f = 0; f < d->face_count; f++) {
        if (d->face_sizes[f] < 3) fail("refined face with < 3 vertices");
        total += d->face_sizes[f];
        if (total > d->face_vertex_count) fail("refined face sizes exceed face_vertex_count");
    }
    if (total != d->face_vertex_count) fail("refined face sizes do not add up");
    for (long i = 0; i < total; i++)
        if (d->face_vertices[i] < 0 || d->face_vertices[i] >= d->vertex_count) fail("refined index out of range");
    if (d->face_uvs)
        for (long i = 0; i < total; i++)
            if (d->face_uvs[i] < 0 || d->face_uvs[i] >= d->uv_count) fail("refined uv index out of range");
}

/* ------------------------------------------------------------------ target */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader rd = { data, size };
    reader *r = &rd;
    int junk;
    uint8_t flags = u8(r);

    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);

    /* vertices */
    d.vertex_count = count_of(r, 48, 1, &junk);
    float *positions = array(junk ? 0 : d.vertex_count * 3, sizeof(float));
    if (!junk) for (int i = 0; i < d.vertex_count * 3; i++) positions[i] = num(r);
    d.positions = positions;
    int nv = junk ? 0 : d.vertex_count;

    /* faces: sizes mostly 3..6, sometimes 0..2, a big one, or an over-limit one */
    d.face_count = count_of(r, 40, 1, &junk);
    int nf = junk ? 0 : d.face_count;
    int *face_sizes = array(nf, sizeof(int));
    long fv = 0;
    for (int f = 0; f < nf; f++) {
        uint8_t m = u8(r);
        int s;
        if (m < 224) s = 3 + m % 4;
        else if (m < 248) s = m % 3;                       /* 0, 1, 2 */
        else if (m < 252) s = 7 + (m & 3) * 40;            /* large but legal */
        else if (m == 252) s = SFB_MAX_FACE_SIZE;
        else if (m == 253) s = SFB_MAX_FACE_SIZE + 1;
        else if (m == 254) s = -3;
        else s = INT_MAX;
        face_sizes[f] = s;
        if (s > 0 && s <= SFB_MAX_FACE_SIZE) fv += s;     /* only legal sizes are backed */
    }
    d.face_sizes = face_sizes;
    int *face_vertices = array((int)fv, sizeof(int));
    {
        /* corners of one face are made distinct (when there are enough vertices) unless the
         * input asks for repeats, so that most descs get past the degenerate-face check */
        long at = 0;
        int allow_repeats = (flags & 8) != 0;
        for (int f = 0; f < nf; f++) {
            int s = face_sizes[f];
            if (s <= 0 || s > SFB_MAX_FACE_SIZE) continue;
            for (int k = 0; k < s; k++) {
                int v = index_of(r, nv);
                if (!allow_repeats && s <= nv && v >= 0 && v < nv) {
                    for (int tries = 0; tries < nv; tries++) {
                        int dup = 0;
                        for (int j = 0; j < k && !dup; j++) dup = face_vertices[at + j] == v;
                        if (!dup) break;
                        v = (v + 1) % nv;
                    }
                }
                face_vertices[at + k] = v;
            }
            at += s;
        }
    }
    d.face_vertices = face_vertices;

    /* creases */
    d.crease_count = count_of(r, 8, 1, &junk);
    int nc = junk ? 0 : d.crease_count;
    int *crease_vertices = array(nc * 2, sizeof(int));
    float *crease_sharpness = array(nc, sizeof(float));
    for (int i = 0; i < nc; i++) {
        /* mostly edges of existing faces */
        if (fv > 0 && (u8(r) & 15)) {
            long at = (long)(u32(r) % (uint32_t)fv);
            /* find the face holding `at` to pick its successor */
            long base = 0;
            int f = 0;
            for (; f < nf; f++) {
                int s = face_sizes[f];
                if (s <= 0 || s > SFB_MAX_FACE_SIZE) continue;
                if (at < base + s) break;
                base += s;
            }
            int s = face_sizes[f];
            crease_vertices[2 * i] = face_vertices[at];
            crease_vertices[2 * i + 1] = face_vertices[base + (at - base + 1) % s];
        } else {
            crease_vertices[2 * i] = index_of(r, nv);
            crease_vertices[2 * i + 1] = index_of(r, nv);
        }
        crease_sharpness[i] = sharp(r);
    }
    d.crease_vertices = crease_vertices;
    d.crease_sharpness = crease_sharpness;

    /* corners */
    d.corner_count = count_of(r, 6, 1, &junk);
    int nco = junk ? 0 : d.corner_count;
    int *corner_vertices = array(nco, sizeof(int));
    float *corner_sharpness = array(nco, sizeof(float));
    for (int i = 0; i < nco; i++) {
        corner_vertices[i] = index_of(r, nv);
        corner_sharpness[i] = sharp(r);
    }
    d.corner_vertices = corner_vertices;
    d.corner_sharpness = corner_sharpness;

    /* holes */
    d.hole_count = count_of(r, 4, 1, &junk);
    int nh = junk ? 0 : d.hole_count;
    int *holes = array(nh, sizeof(int));
    for (int i = 0; i < nh; i++) holes[i] = index_of(r, nf);
    d.holes = holes;

    /* uvs (optional) */
    float *uvs = NULL;
    int *face_uvs = NULL;
    if (flags & 1) {
        d.uv_count = count_of(r, 40, 1, &junk);
        int nu = junk ? 0 : d.uv_count;
        uvs = array(nu * 2, sizeof(float));
        for (int i = 0; i < nu * 2; i++) uvs[i] = num(r);
        face_uvs = array((int)fv, sizeof(int));
        for (long i = 0; i < fv; i++) face_uvs[i] = index_of(r, nu);
        d.uvs = uvs;
        d.face_uvs = face_uvs;
    }

    /* per face-vertex edge sharpness (optional) */
    float *fes = NULL;
    if (flags & 2) {
        fes = array((int)fv, sizeof(float));
        for (long i = 0; i < fv; i++) fes[i] = (u8(r) & 1) ? sharp(r) : 0.0f;
        d.face_edge_sharpness = fes;
    }

    d.boundary = enum_of(r, 3);
    d.crease_method = enum_of(r, 2);
    d.triangle_rule = enum_of(r, 2);
    d.uv_interp = enum_of(r, 2);

    /* now and then a NULL array behind a non-zero count */
    if (flags & 4) {
        switch (u8(r) % 8) {
        case 0: d.positions = NULL; break;
        case 1: d.face_sizes = NULL; break;
        case 2: d.face_vertices = NULL; break;
        case 3: d.crease_vertices = NULL; break;
        case 4: d.crease_sharpness = NULL; break;
        case 5: d.corner_sharpness = NULL; break;
        case 6: d.holes = NULL; break;
        default: d.uvs = NULL; break;
        }
    }

    static const sfb_backend_kind ref_only[1] = { SFB_BACKEND_REF };
    sfb_context_config cfg = sfb_context_config_init();
    cfg.memory_budget = (size_t)64 << 20;
    cfg.backends = ref_only;
    cfg.backend_count = 1;
    cfg.threads = 1;
    cfg.ignore_environment = 1;
    sfb_context *ctx = NULL;
    if (sfb_context_create(&cfg, &ctx) != SFB_SUCCESS || !ctx) fail("sfb_context_create failed");

    sfb_mesh *mesh = NULL;
    sfb_result res = sfb_mesh_create(ctx, &d, &mesh);
    if (res != SFB_SUCCESS) {
        check_error(ctx, res, "sfb_mesh_create");
    } else {
        if (!mesh) fail("sfb_mesh_create succeeded without a mesh");
        sfb_mesh_desc got;
        sfb_mesh_get_desc(mesh, &got);
        if (got.vertex_count != d.vertex_count || got.face_count != d.face_count)
            fail("sfb_mesh_get_desc counts differ from the desc given");
        sfb_mesh_info info;
        sfb_mesh_get_info(mesh, &info);
        if (info.max_valence > SFB_MAX_VALENCE || info.max_face_size > SFB_MAX_FACE_SIZE)
            fail("accepted mesh exceeds a hard limit");
        int hist[16];
        (void)sfb_mesh_valence_histogram(mesh, hist, 16);

        round_trip(ctx, mesh);

        /* triangles made of it (raw float bits: NaN, inf, flat polygons): every face of k
         * corners k - 2 triangles, or an error with a message and no mesh */
        {
            sfb_mesh *tri = NULL;
            int split = -1, want = 0;
            sfb_result tr = sfb_mesh_triangulate(ctx, mesh, &tri, &split);
            if (tr == SFB_SUCCESS) {
                sfb_mesh_info ti;
                for (int f = 0; f < got.face_count; ++f) want += got.face_sizes[f] - 2;
                sfb_mesh_get_info(tri, &ti);
                if (!tri || ti.face_count != want || ti.triangles != want || split != info.quads + info.ngons || ti.vertex_count != info.vertex_count)
                    fail("sfb_mesh_triangulate's counts");
            } else {
                check_error(ctx, tr, "sfb_mesh_triangulate");
                if (tri) fail("sfb_mesh_triangulate failed with a mesh");
            }
            sfb_mesh_destroy(tri);
        }

        sfb_scheme scheme = (sfb_scheme)(u8(r) % 5);
        int level = u8(r) % 3;
        sfb_surface_config sc = sfb_surface_config_init(scheme, level);
        sc.flags = u8(r) & 3;
        sfb_surface *surf = NULL;
        res = sfb_surface_create(ctx, mesh, &sc, &surf);
        if (res != SFB_SUCCESS) {
            check_error(ctx, res, "sfb_surface_create");
        } else {
            if (!surf) fail("sfb_surface_create succeeded without a surface");
            sfb_mesh_data md;
            memset(&md, 0, sizeof md);
            res = sfb_surface_refine(surf, &md);
            if (res == SFB_SUCCESS) {
                check_data(&md);
                sfb_mesh_data_free(&md);
            } else {
                check_error(ctx, res, "sfb_surface_refine");
            }

            /* apply the vertex table once, through a possibly padded layout */
            sfb_stencil_info si;
            if (sfb_surface_stencil_info(surf, SFB_TABLE_VERTEX, &si) == SFB_SUCCESS && si.sources >= 0 &&
                si.rows >= 0 && si.sources <= 1 << 20 && si.rows <= 1 << 22) {
                uint8_t m = u8(r);
                int off = m & 1, stride = 3 + ((m >> 1) & 1);
                size_t ns = (size_t)off + (size_t)(si.sources ? si.sources : 1) * (size_t)stride;
                size_t nd = (size_t)off + (size_t)(si.rows ? si.rows : 1) * (size_t)stride;
                float *src = calloc(ns, sizeof(float));
                float *dst = calloc(nd, sizeof(float));
                if (!src || !dst) abort();
                for (int v = 0; v < si.sources && v < got.vertex_count; v++)
                    memcpy(src + off + (size_t)v * stride, got.positions + 3 * (size_t)v, 3 * sizeof(float));
                sfb_buffer_desc sd = { off, 3, stride }, dd = { off, 3, stride };
                res = sfb_surface_eval_stencils(surf, SFB_TABLE_VERTEX, src, sd, dst, dd);
                check_error(ctx, res, "sfb_surface_eval_stencils");
                free(src);
                free(dst);
            }
            sfb_surface_destroy(surf);
        }
        sfb_mesh_destroy(mesh);
    }
    sfb_context_destroy(ctx);

    free(positions); free(face_sizes); free(face_vertices);
    free(crease_vertices); free(crease_sharpness);
    free(corner_vertices); free(corner_sharpness);
    free(holes); free(uvs); free(face_uvs); free(fes);
    return 0;
}
