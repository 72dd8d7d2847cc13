/* fuzz_obj.c - libFuzzer target for the OBJ reader and everything a parsed mesh feeds.
 *
 * Input: OBJ text. If sfb_mesh_read_obj accepts it:
 *   - write the mesh back with sfb_mesh_write_obj, re-read it, and require the same
 *     vertex / face / face-vertex / uv counts;
 *   - build catmark, loop and bilinear surfaces at levels 1 and 2 with
 *     SFB_REFINE_LIMIT | SFB_REFINE_UVS (errors such as loop on quads are fine), refine, and
 *     check that the refined topology is self-consistent (indices in range, sizes add up);
 *   - write the level-1 refined mesh as OBJ and re-read it (non-finite refined values may be
 *     refused with SFB_INVALID_VALUE; anything else must round-trip).
 * Every failure must come with a non-empty message. A violated invariant calls abort().
 *
 * Build (from the repository root):
 *   clang -g -O1 -fsanitize=fuzzer,address,undefined -I. fuzz/fuzz_obj.c -x c tools/impl.c -o fuzz_obj
 * Run:
 *   mkdir -p /tmp/corpus_work && ./fuzz_obj -max_total_time=60 -dict=fuzz/obj.dict /tmp/corpus_work fuzz/corpus
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "surfblend.h"

#define OUT_CAP ((size_t)64 << 20)

typedef struct membuf {
    char *data;
    size_t size, cap;
    int overflow;
} membuf;

static int membuf_write(const void *data, size_t size, void *user)
{
    membuf *b = user;
    if (size > OUT_CAP - b->size) { b->overflow = 1; return 1; }
    if (b->size + size > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->size + size) cap *= 2;
        char *nd = realloc(b->data, cap);
        if (!nd) { b->overflow = 1; return 1; }
        b->data = nd;
        b->cap = cap;
    }
    memcpy(b->data + b->size, data, size);
    b->size += size;
    return 0;
}

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_obj: invariant violated: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    abort();
}

static void check_error(sfb_context *ctx, sfb_result r, const char *call)
{
    if (r == SFB_SUCCESS) return;
    if (r > 0 || r < SFB_RESULT_MIN_) {
        char buf[128];
        snprintf(buf, sizeof buf, "%s returned %d, not an sfb_result", call, (int)r);
        fail(buf, NULL);
    }
    const char *m = sfb_last_error(ctx);
    if (!m || !m[0]) fail("empty error message after failure of", call);
    const char *s = sfb_result_string(r);
    if (!s || !s[0]) fail("empty sfb_result_string", call);
}

/* Topology of refined data must be self-consistent. */
static void check_data(const sfb_mesh_data *d, unsigned flags, int mesh_has_uvs)
{
    if (d->vertex_count < 0 || d->face_count < 0 || d->face_vertex_count < 0 || d->uv_count < 0)
        fail("negative count in sfb_mesh_data", NULL);
    if (d->vertex_count > 0 && !d->positions) fail("refined positions missing", NULL);
    if (d->face_count > 0 && (!d->face_sizes || !d->face_vertices)) fail("refined faces missing", NULL);
    if ((flags & SFB_REFINE_LIMIT) && d->vertex_count > 0 &&
        (!d->limit_positions || !d->tangents_u || !d->tangents_v || !d->normals))
        fail("SFB_REFINE_LIMIT given but limit arrays missing", NULL);
    long total = 0;
    for (int f = 0; f < d->face_count; f++) {
        int n = d->face_sizes[f];
        if (n < 3 || n > SFB_MAX_FACE_SIZE) fail("refined face with bad size", NULL);
        total += n;
        if (total > d->face_vertex_count) fail("refined face sizes exceed face_vertex_count", NULL);
    }
    if (total != d->face_vertex_count) fail("refined face sizes do not add up to face_vertex_count", NULL);
    for (long i = 0; i < total; i++)
        if (d->face_vertices[i] < 0 || d->face_vertices[i] >= d->vertex_count)
            fail("refined face vertex index out of range", NULL);
    if ((flags & SFB_REFINE_UVS) && mesh_has_uvs && d->face_uvs) {
        if (d->uv_count > 0 && !d->uvs) fail("refined uvs missing", NULL);
        for (long i = 0; i < total; i++)
            if (d->face_uvs[i] < 0 || d->face_uvs[i] >= d->uv_count) fail("refined face uv index out of range", NULL);
    }
    for (int i = 0; i < d->crease_count; i++) {
        if (!d->crease_vertices || !d->crease_sharpness) fail("refined creases missing", NULL);
        int a = d->crease_vertices[2 * i], b = d->crease_vertices[2 * i + 1];
        if (a < 0 || a >= d->vertex_count || b < 0 || b >= d->vertex_count) fail("refined crease vertex out of range", NULL);
        if (!(d->crease_sharpness[i] >= 0.0f)) fail("refined crease sharpness negative or NaN", NULL);
    }
    for (int i = 0; i < d->corner_count; i++) {
        if (!d->corner_vertices || !d->corner_sharpness) fail("refined corners missing", NULL);
        if (d->corner_vertices[i] < 0 || d->corner_vertices[i] >= d->vertex_count) fail("refined corner out of range", NULL);
    }
    for (int i = 0; i < d->hole_count; i++) {
        if (!d->holes) fail("refined holes missing", NULL);
        if (d->holes[i] < 0 || d->holes[i] >= d->face_count) fail("refined hole out of range", NULL);
    }
}

/* Writes desc as OBJ, re-reads it and compares counts. tolerate_value: a refused re-read with
 * SFB_INVALID_VALUE or SFB_LIMIT_EXCEEDED is acceptable (refined data may hold non-finite values
 * or be larger than the budget). */
static void round_trip(sfb_context *ctx, const sfb_mesh *mesh, const sfb_mesh_desc *desc, int tolerate)
{
    membuf b = { 0 };
    sfb_result r = mesh ? sfb_mesh_write_obj(mesh, membuf_write, &b) : sfb_write_obj(desc, membuf_write, &b);
    if (r != SFB_SUCCESS) {
        if (!b.overflow && !tolerate) {
            fprintf(stderr, "write: %s\n", sfb_result_string(r));
            fail("writing an accepted mesh as OBJ failed", NULL);
        }
        free(b.data);
        return;
    }
    sfb_mesh *again = NULL;
    r = sfb_mesh_read_obj(ctx, b.data ? b.data : "", b.size, &again);
    if (r != SFB_SUCCESS) {
        check_error(ctx, r, "sfb_mesh_read_obj (re-read)");
        if (tolerate && (r == SFB_INVALID_VALUE || r == SFB_LIMIT_EXCEEDED || r == SFB_OUT_OF_MEMORY)) {
            free(b.data);
            return;
        }
        fprintf(stderr, "re-read failed: %s: %s\n--- written OBJ (%zu bytes) ---\n%.*s\n---\n",
                sfb_result_string(r), sfb_last_error(ctx), b.size, (int)(b.size < 4000 ? b.size : 4000),
                b.data ? b.data : "");
        fail("the library cannot re-read the OBJ it wrote", NULL);
    }
    sfb_mesh_desc d2;
    sfb_mesh_get_desc(again, &d2);
    if (d2.vertex_count != desc->vertex_count || d2.face_count != desc->face_count) {
        fprintf(stderr, "vertices %d -> %d, faces %d -> %d\n", desc->vertex_count, d2.vertex_count,
                desc->face_count, d2.face_count);
        fail("round trip changed vertex/face counts", NULL);
    }
    long fv1 = 0, fv2 = 0;
    for (int f = 0; f < desc->face_count; f++) {
        fv1 += desc->face_sizes[f];
        fv2 += d2.face_sizes[f];
        if (desc->face_sizes[f] != d2.face_sizes[f]) fail("round trip changed a face size", NULL);
    }
    for (long i = 0; i < fv1; i++)
        if (desc->face_vertices[i] != d2.face_vertices[i]) fail("round trip changed face vertices", NULL);
    if ((desc->uv_count > 0) != (d2.uv_count > 0)) fail("round trip gained or lost UVs", NULL);
    if (desc->hole_count != d2.hole_count) fail("round trip changed the hole count", NULL);
    (void)fv2;
    sfb_mesh_destroy(again);
    free(b.data);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const sfb_backend_kind ref_only[1] = { SFB_BACKEND_REF };
    sfb_context_config cfg = sfb_context_config_init();
    cfg.memory_budget = (size_t)64 << 20;
    cfg.backends = ref_only;
    cfg.backend_count = 1;
    cfg.threads = 1;
    cfg.ignore_environment = 1;

    sfb_context *ctx = NULL;
    if (sfb_context_create(&cfg, &ctx) != SFB_SUCCESS || !ctx) fail("sfb_context_create failed", NULL);

    sfb_mesh *mesh = NULL;
    /* size may be 0; the reader must not need a NUL terminator (libFuzzer's data has none) */
    sfb_result r = sfb_mesh_read_obj(ctx, (const char *)data, size, &mesh);
    if (r != SFB_SUCCESS) {
        check_error(ctx, r, "sfb_mesh_read_obj");
        sfb_context_destroy(ctx);
        return 0;
    }
    if (!mesh) fail("sfb_mesh_read_obj succeeded without a mesh", NULL);

    sfb_mesh_desc desc;
    sfb_mesh_get_desc(mesh, &desc);
    sfb_mesh_info info;
    sfb_mesh_get_info(mesh, &info);
    if (info.vertex_count != desc.vertex_count || info.face_count != desc.face_count)
        fail("sfb_mesh_get_info disagrees with sfb_mesh_get_desc", NULL);
    if (info.max_valence > SFB_MAX_VALENCE) fail("accepted mesh exceeds SFB_MAX_VALENCE", NULL);
    if (info.max_face_size > SFB_MAX_FACE_SIZE) fail("accepted mesh exceeds SFB_MAX_FACE_SIZE", NULL);

    round_trip(ctx, mesh, &desc, 0);

    static const sfb_scheme schemes[3] = { SFB_SCHEME_CATMARK, SFB_SCHEME_LOOP, SFB_SCHEME_BILINEAR };
    for (int s = 0; s < 3; s++) {
        for (int level = 1; level <= 2; level++) {
            sfb_surface_config sc = sfb_surface_config_init(schemes[s], level);
            sc.flags = SFB_REFINE_LIMIT | SFB_REFINE_UVS;
            sfb_surface *surf = NULL;
            r = sfb_surface_create(ctx, mesh, &sc, &surf);
            if (r != SFB_SUCCESS) {
                check_error(ctx, r, "sfb_surface_create");
                continue;
            }
            if (!surf) fail("sfb_surface_create succeeded without a surface", NULL);
            for (int t = 0; t < SFB_TABLE_COUNT_; t++) {
                sfb_stencil_info si;
                if (sfb_surface_stencil_info(surf, (sfb_table)t, &si) == SFB_SUCCESS &&
                    (si.rows < 0 || si.sources < 0 || si.entries < 0))
                    fail("negative stencil info", NULL);
            }
            sfb_mesh_data md;
            memset(&md, 0, sizeof md);
            r = sfb_surface_refine(surf, &md);
            if (r != SFB_SUCCESS) {
                check_error(ctx, r, "sfb_surface_refine");
            } else {
                check_data(&md, sc.flags, desc.uv_count > 0);
                if (level == 1 && s == 0) {
                    sfb_mesh_desc rd;
                    sfb_mesh_data_desc(&md, &rd);
                    round_trip(ctx, NULL, &rd, 1);
                }
                sfb_mesh_data_free(&md);
            }
            sfb_surface_destroy(surf);
        }
    }

    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return 0;
}
