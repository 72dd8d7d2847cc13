/* Control meshes: validation of untrusted arrays, edges, topology, creases, info. */


static sfb_result sfb__elem_error(sfb_context *ctx, sfb_result r, const sfb__src_lines *lines, const int *line_of,
                                  sfb_element_kind kind, long index, const char *what, long what_index, const char *detail) {
    if (lines && line_of)
        return sfb__error(ctx, r, SFB_ELEMENT_LINE, line_of[what_index], "%s %ld: %s", what, what_index, detail);
    if (kind == SFB_ELEMENT_NONE) return sfb__error(ctx, r, kind, -1, "%s %ld: %s", what, what_index, detail);
    return sfb__error(ctx, r, kind, index, "%s", detail);
}

/* Builds the edge list of a face list by hashing vertex pairs. */
static sfb_result sfb__build_edges(sfb_context *ctx, int nv, int nf, const int *fv_off, const int *fv, int *ne_out,
                                   int **fe_out, int **ev_out) {
    int nfv = fv_off[nf], f, i, ne = 0;
    size_t cap = 16, mask;
    uint64_t *keys = NULL;
    int *vals = NULL, *fe = NULL, *ev = NULL;
    (void)nv;
    while (cap < (size_t)nfv * 2 + 16) cap <<= 1;
    mask = cap - 1;
    keys = (uint64_t *)sfb__alloc(ctx, cap * sizeof(uint64_t));
    vals = (int *)sfb__alloc(ctx, cap * sizeof(int));
    fe = (int *)sfb__alloc(ctx, ((size_t)nfv + 1) * sizeof(int));
    ev = (int *)sfb__alloc(ctx, ((size_t)nfv * 2 + 2) * sizeof(int));
    if (!keys || !vals || !fe || !ev) goto oom;
    memset(keys, 0xff, cap * sizeof(uint64_t));
    for (f = 0; f < nf; ++f) {
        int o = fv_off[f], n = fv_off[f + 1] - o;
        for (i = 0; i < n; ++i) {
            unsigned a = (unsigned)fv[o + i], b = (unsigned)fv[o + (i + 1) % n];
            uint64_t key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 17) & mask;
            while (keys[h] != ~(uint64_t)0 && keys[h] != key) h = (h + 1) & mask;
            if (a == b) {
                /* a degenerate edge (a face repeating a vertex) is never shared: each occurrence is
                 * an edge of its own, as in OpenSubdiv */
                ev[2 * ne] = (int)a;
                ev[2 * ne + 1] = (int)b;
                fe[o + i] = ne++;
            } else if (keys[h] == key) {
                int k, again = 0;
                /* the same edge twice in one face (a face folding back on itself) gives two edges */
                for (k = 0; k < i && !again; ++k) again = fe[o + k] == vals[h];
                if (again) {
                    ev[2 * ne] = (int)a;
                    ev[2 * ne + 1] = (int)b;
                    fe[o + i] = ne++;
                } else {
                    fe[o + i] = vals[h];
                }
            } else {
                keys[h] = key;
                vals[h] = ne;
                ev[2 * ne] = (int)a;
                ev[2 * ne + 1] = (int)b;
                fe[o + i] = ne++;
            }
        }
    }
    sfb__free(ctx, keys);
    sfb__free(ctx, vals);
    *ne_out = ne;
    *fe_out = fe;
    *ev_out = ev;
    return SFB_SUCCESS;
oom:
    sfb__free(ctx, keys); sfb__free(ctx, vals); sfb__free(ctx, fe); sfb__free(ctx, ev);
    return SFB_OUT_OF_MEMORY;
}

/* Finds the edge between a and b through a's incident edges; -1 if none. */
static int sfb__find_edge(const sfb__level *l, int a, int b) {
    int i;
    for (i = l->ve_off[a]; i < l->ve_off[a + 1]; ++i) {
        int e = l->ve[i];
        if ((l->ev[2 * e] == a && l->ev[2 * e + 1] == b) || (l->ev[2 * e] == b && l->ev[2 * e + 1] == a)) return e;
    }
    return -1;
}

static int sfb__finite3(const float *p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }

/* Builds a level (topology only, zero sharpness) from faces; validates indices. */
sfb_result sfb__level_from_faces(sfb_context *ctx, int nv, int nf, const int *sizes, const int *fvin,
                                        const sfb__src_lines *lines, sfb_element_kind vkind, sfb__level *l) {
    int f, i;
    size_t nfv = 0;
    sfb_result r;
    memset(l, 0, sizeof *l);
    for (f = 0; f < nf; ++f) {
        char msg[160];
        if (sizes[f] < 3) {
            snprintf(msg, sizeof msg, "face has %d %s; a face needs at least 3", sizes[f], sizes[f] == 1 ? "vertex" : "vertices");
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
        }
        if (sizes[f] > SFB_MAX_FACE_SIZE) {
            snprintf(msg, sizeof msg, "face has %d vertices, over the limit of %d (SFB_MAX_FACE_SIZE)", sizes[f], SFB_MAX_FACE_SIZE);
            return sfb__elem_error(ctx, SFB_LIMIT_EXCEEDED, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
        }
        nfv += (size_t)sizes[f];
        if (nfv > SFB_MAX_ELEMENTS)
            return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_FACE, f, "total face-vertex count over the limit of %d", SFB_MAX_ELEMENTS);
    }
    l->nv = nv;
    l->nf = nf;
    l->fv_off = (int *)sfb__alloc(ctx, ((size_t)nf + 1) * sizeof(int));
    l->fv = (int *)sfb__alloc(ctx, (nfv + 1) * sizeof(int));
    if (!l->fv_off || !l->fv) goto oom;
    l->fv_off[0] = 0;
    for (f = 0; f < nf; ++f) {
        int o = l->fv_off[f], n = sizes[f];
        l->fv_off[f + 1] = o + n;
        for (i = 0; i < n; ++i) {
            int v = fvin[o + i];
            char msg[200];
            if (v < 0 || v >= nv) {
                snprintf(msg, sizeof msg, "%s index %d out of range (%d %s)", vkind == SFB_ELEMENT_UV ? "uv" : "vertex", v, nv,
                         vkind == SFB_ELEMENT_UV ? "uvs" : "vertices");
                sfb__level_free(ctx, l);
                return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
            }
            l->fv[o + i] = v;
        }
    }
    r = sfb__build_edges(ctx, nv, nf, l->fv_off, l->fv, &l->ne, &l->fe, &l->ev);
    if (r != SFB_SUCCESS) goto oom;
    l->es = (float *)sfb__calloc(ctx, (size_t)l->ne + 1, sizeof(float));
    l->vs = (float *)sfb__calloc(ctx, (size_t)nv + 1, sizeof(float));
    if (!l->es || !l->vs) goto oom;
    r = sfb__level_complete(ctx, l);
    if (r != SFB_SUCCESS) { sfb__level_free(ctx, l); return r; }
    return SFB_SUCCESS;
oom:
    sfb__level_free(ctx, l);
    return sfb__oom(ctx, "building the mesh topology");
}

static sfb_result sfb__check_sharpness(sfb_context *ctx, float s, const sfb__src_lines *lines, const int *line_of,
                                       const char *what, int index) {
    char msg[160];
    if (isnan(s) || s < 0.0f) {
        snprintf(msg, sizeof msg, "sharpness %g is invalid: sharpness must be a number >= 0", (double)s);
        return sfb__elem_error(ctx, SFB_INVALID_VALUE, lines, line_of, SFB_ELEMENT_NONE, -1, what, index, msg);
    }
    return SFB_SUCCESS;
}

void sfb_mesh_destroy(sfb_mesh *mesh);

/* Refuses a mesh description with bad counts, missing arrays, unknown options or non-finite
 * positions, before any allocation. */
static sfb_result sfb__mesh_check_desc(sfb_context *ctx, const sfb_mesh_desc *d) {
    int v;
    if (d->vertex_count < 0 || d->face_count < 0 || d->crease_count < 0 || d->corner_count < 0 || d->hole_count < 0 ||
        d->uv_count < 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "negative element count in the mesh description");
    if (d->vertex_count > SFB_MAX_ELEMENTS || d->face_count > SFB_MAX_ELEMENTS || d->uv_count > SFB_MAX_ELEMENTS ||
        d->crease_count > SFB_MAX_ELEMENTS || d->corner_count > SFB_MAX_ELEMENTS || d->hole_count > SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "element count over the limit of %d", SFB_MAX_ELEMENTS);
    if (d->face_count == 0) return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_NONE, -1, "mesh has no faces");
    if (!d->positions || !d->face_sizes || !d->face_vertices)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mesh description lacks positions or faces");
    if ((d->crease_count && (!d->crease_vertices || !d->crease_sharpness)) ||
        (d->corner_count && (!d->corner_vertices || !d->corner_sharpness)) || (d->hole_count && !d->holes) ||
        (d->uv_count && (!d->uvs || !d->face_uvs)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mesh description has a count without its array");
    if (d->boundary < 0 || d->boundary > 2 || d->crease_method < 0 || d->crease_method > 1 || d->triangle_rule < 0 ||
        d->triangle_rule > 1 || d->uv_interp < 0 || d->uv_interp > 1)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "invalid boundary/crease method/triangle rule/uv mode value");
    for (v = 0; v < d->vertex_count; ++v)
        if (!sfb__finite3(d->positions + 3 * (size_t)v))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_VERTEX, v, "coordinate is not finite (NaN or inf)");
    return SFB_SUCCESS;
}

/* Refuses a vertex of the base level with more edges or faces than SFB_MAX_VALENCE. */
static sfb_result sfb__mesh_check_valence(sfb_context *ctx, const sfb__level *l) {
    int v;
    for (v = 0; v < l->nv; ++v) {
        int val = l->ve_off[v + 1] - l->ve_off[v];
        int fal = l->vf_off[v + 1] - l->vf_off[v];
        if (val > SFB_MAX_VALENCE || fal > SFB_MAX_VALENCE)
            return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_VERTEX, v, "valence %d is over the limit of %d (SFB_MAX_VALENCE)",
                              val > fal ? val : fal, SFB_MAX_VALENCE);
    }
    return SFB_SUCCESS;
}

/* Edge sharpness from the crease list and the per-face edge sharpness of the description. */
static sfb_result sfb__mesh_apply_creases(sfb_context *ctx, sfb_mesh *m, const sfb_mesh_desc *d, const sfb__src_lines *lines) {
    sfb_result r;
    int i, e;
    char msg[256];
    /* creases: later entries override earlier ones on the same edge (as OpenSubdiv) */
    for (i = 0; i < d->crease_count; ++i) {
        int a = d->crease_vertices[2 * i], b = d->crease_vertices[2 * i + 1];
        float s = d->crease_sharpness[i];
        const int *lo = lines ? lines->crease : NULL;
        if (a < 0 || a >= d->vertex_count || b < 0 || b >= d->vertex_count) {
            snprintf(msg, sizeof msg, "crease names vertex index %d out of range (%d vertices)",
                     (a < 0 || a >= d->vertex_count) ? a : b, d->vertex_count);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lo, SFB_ELEMENT_EDGE, i, "crease", i, msg);
        }
        r = sfb__check_sharpness(ctx, s, lines, lo, "crease", i);
        if (r != SFB_SUCCESS) return r;
        e = sfb__find_edge(&m->base, a, b);
        if (e < 0) {
            snprintf(msg, sizeof msg, "crease between vertices %d and %d is not an edge of the mesh", a, b);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lo, SFB_ELEMENT_EDGE, i, "crease", i, msg);
        }
        m->base.es[e] = s;
    }
    if (d->face_edge_sharpness) {
        int f;
        for (f = 0; f < d->face_count; ++f) {
            int o = m->base.fv_off[f], n = m->base.fv_off[f + 1] - o;
            for (i = 0; i < n; ++i) {
                float s = d->face_edge_sharpness[o + i];
                if (isnan(s) || s < 0.0f) {
                    snprintf(msg, sizeof msg, "per-face edge sharpness %g is invalid: sharpness must be a number >= 0", (double)s);
                    return sfb__elem_error(ctx, SFB_INVALID_VALUE, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
                }
                /* seed 001: where two faces give an edge different values, the highest wins */
                if (s > m->base.es[m->base.fe[o + i]]) m->base.es[m->base.fe[o + i]] = s;
            }
        }
    }
    return SFB_SUCCESS;
}

/* Vertex sharpness from the corner list and face holes from the hole list of the description. */
static sfb_result sfb__mesh_apply_corners_holes(sfb_context *ctx, sfb_mesh *m, const sfb_mesh_desc *d, const sfb__src_lines *lines) {
    sfb_result r;
    int i;
    char msg[256];
    for (i = 0; i < d->corner_count; ++i) {
        int a = d->corner_vertices[i];
        const int *lo = lines ? lines->corner : NULL;
        if (a < 0 || a >= d->vertex_count) {
            snprintf(msg, sizeof msg, "corner names vertex index %d out of range (%d vertices)", a, d->vertex_count);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lo, SFB_ELEMENT_VERTEX, a, "corner", i, msg);
        }
        r = sfb__check_sharpness(ctx, d->corner_sharpness[i], lines, lo, "corner", i);
        if (r != SFB_SUCCESS) return r;
        m->base.vs[a] = d->corner_sharpness[i];
    }
    for (i = 0; i < d->hole_count; ++i) {
        int f = d->holes[i];
        if (f < 0 || f >= d->face_count) {
            snprintf(msg, sizeof msg, "hole names face index %d out of range (%d faces)", f, d->face_count);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lines ? lines->hole : NULL, SFB_ELEMENT_FACE, f, "hole", i, msg);
        }
        m->base.fhole[f] = 1;
    }
    return SFB_SUCCESS;
}

/* Refuses non-finite UVs and face UV indices out of range (the UVs are copied by the caller). */
static sfb_result sfb__mesh_check_uvs(sfb_context *ctx, const sfb_mesh *m, const sfb_mesh_desc *d, const sfb__src_lines *lines) {
    size_t nfv = (size_t)m->base.nfv;
    int i;
    char msg[256];
    for (i = 0; i < d->uv_count; ++i)
        if (!isfinite(d->uvs[2 * i]) || !isfinite(d->uvs[2 * i + 1]))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_UV, i, "uv coordinate is not finite (NaN or inf)");
    for (i = 0; (size_t)i < nfv; ++i)
        if (d->face_uvs[i] < 0 || d->face_uvs[i] >= d->uv_count) {
            int f = 0;
            while (m->base.fv_off[f + 1] <= i) ++f;
            snprintf(msg, sizeof msg, "uv index %d out of range (%d uvs)", d->face_uvs[i], d->uv_count);
            return sfb__elem_error(ctx, SFB_INVALID_TOPOLOGY, lines, lines ? lines->face : NULL, SFB_ELEMENT_FACE, f, "face", f, msg);
        }
    return SFB_SUCCESS;
}

/* The description view (sfb_mesh_get_desc): per-edge creases, corners and holes as lists.
 * Returns 0 when an allocation failed. */
static int sfb__mesh_desc_view(sfb_context *ctx, sfb_mesh *m) {
    int nc = 0, nk = 0, nh = 0, f, e, v;
    for (e = 0; e < m->base.ne; ++e) nc += m->base.es[e] > 0.0f;
    for (v = 0; v < m->base.nv; ++v) nk += m->base.vs[v] > 0.0f;
    for (f = 0; f < m->base.nf; ++f) nh += m->base.fhole[f] != 0;
    m->crease_vertices = (int *)sfb__alloc(ctx, (size_t)nc * 2 * sizeof(int) + 1);
    m->crease_sharpness = (float *)sfb__alloc(ctx, (size_t)nc * sizeof(float) + 1);
    m->corner_vertices = (int *)sfb__alloc(ctx, (size_t)nk * sizeof(int) + 1);
    m->corner_sharpness = (float *)sfb__alloc(ctx, (size_t)nk * sizeof(float) + 1);
    m->holes = (int *)sfb__alloc(ctx, (size_t)nh * sizeof(int) + 1);
    if (!m->crease_vertices || !m->crease_sharpness || !m->corner_vertices || !m->corner_sharpness || !m->holes) return 0;
    for (e = 0; e < m->base.ne; ++e)
        if (m->base.es[e] > 0.0f) {
            m->crease_vertices[2 * m->crease_count] = m->base.ev[2 * e];
            m->crease_vertices[2 * m->crease_count + 1] = m->base.ev[2 * e + 1];
            m->crease_sharpness[m->crease_count++] = m->base.es[e];
        }
    for (v = 0; v < m->base.nv; ++v)
        if (m->base.vs[v] > 0.0f) {
            m->corner_vertices[m->corner_count] = v;
            m->corner_sharpness[m->corner_count++] = m->base.vs[v];
        }
    for (f = 0; f < m->base.nf; ++f)
        if (m->base.fhole[f]) m->holes[m->hole_count++] = f;
    return 1;
}

sfb_result sfb__mesh_create(sfb_context *ctx, const sfb_mesh_desc *d, const sfb__src_lines *lines, sfb_mesh **out) {
    sfb_mesh *m;
    sfb_result r;
    const char *oom = NULL;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!d || !out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_mesh_create: NULL argument");
    *out = NULL;
    if ((r = sfb__mesh_check_desc(ctx, d)) != SFB_SUCCESS) return r;
    m = (sfb_mesh *)sfb__calloc(ctx, 1, sizeof(sfb_mesh));
    if (!m) return sfb__oom(ctx, "mesh");
    m->ctx = ctx;
    m->boundary = d->boundary; m->crease_method = d->crease_method;
    m->triangle_rule = d->triangle_rule; m->uv_interp = d->uv_interp;
    r = sfb__level_from_faces(ctx, d->vertex_count, d->face_count, d->face_sizes, d->face_vertices, lines, SFB_ELEMENT_VERTEX, &m->base);
    if (r != SFB_SUCCESS) goto fail;
    if ((r = sfb__mesh_check_valence(ctx, &m->base)) != SFB_SUCCESS) goto fail;
    m->positions = (float *)sfb__alloc(ctx, (size_t)d->vertex_count * 3 * sizeof(float) + 1);
    m->face_sizes = (int *)sfb__alloc(ctx, (size_t)d->face_count * sizeof(int));
    if (!m->positions || !m->face_sizes) { oom = "mesh"; goto fail; }
    memcpy(m->positions, d->positions, (size_t)d->vertex_count * 3 * sizeof(float));
    memcpy(m->face_sizes, d->face_sizes, (size_t)d->face_count * sizeof(int));
    if ((r = sfb__mesh_apply_creases(ctx, m, d, lines)) != SFB_SUCCESS) goto fail;
    if ((r = sfb__mesh_apply_corners_holes(ctx, m, d, lines)) != SFB_SUCCESS) goto fail;
    if (d->uv_count > 0) {
        size_t nfv = (size_t)m->base.nfv;
        if ((r = sfb__mesh_check_uvs(ctx, m, d, lines)) != SFB_SUCCESS) goto fail;
        m->uv_count = d->uv_count;
        m->uvs = (float *)sfb__alloc(ctx, (size_t)d->uv_count * 2 * sizeof(float));
        m->face_uvs = (int *)sfb__alloc(ctx, nfv * sizeof(int));
        if (!m->uvs || !m->face_uvs) { oom = "mesh uvs"; goto fail; }
        memcpy(m->uvs, d->uvs, (size_t)d->uv_count * 2 * sizeof(float));
        memcpy(m->face_uvs, d->face_uvs, nfv * sizeof(int));
    }
    if (!sfb__mesh_desc_view(ctx, m)) { oom = "mesh"; goto fail; }
    sfb__level_compute_rules(&m->base);
    *out = m;
    return SFB_SUCCESS;
fail:
    /* an allocation failure is reported after the mesh is gone (the message gives the bytes
     * still in use) */
    sfb_mesh_destroy(m);
    return oom ? sfb__oom(ctx, oom) : r;
}

SFB_API sfb_result sfb_mesh_create(sfb_context *ctx, const sfb_mesh_desc *desc, sfb_mesh **out) {
    return sfb__mesh_create(ctx, desc, NULL, out);
}

SFB_API void sfb_mesh_destroy(sfb_mesh *m) {
    sfb_context *ctx;
    if (!m) return;
    ctx = m->ctx;
    sfb__level_free(ctx, &m->base);
    sfb__free(ctx, m->positions); sfb__free(ctx, m->uvs); sfb__free(ctx, m->face_uvs); sfb__free(ctx, m->face_sizes);
    sfb__free(ctx, m->crease_vertices); sfb__free(ctx, m->crease_sharpness);
    sfb__free(ctx, m->corner_vertices); sfb__free(ctx, m->corner_sharpness); sfb__free(ctx, m->holes);
    sfb__free(ctx, m);
}

SFB_API void sfb_mesh_get_desc(const sfb_mesh *m, sfb_mesh_desc *d) {
    if (!d) return;
    memset(d, 0, sizeof *d);
    if (!m) return;
    d->vertex_count = m->base.nv; d->positions = m->positions;
    d->face_count = m->base.nf; d->face_sizes = m->face_sizes; d->face_vertices = m->base.fv;
    d->crease_count = m->crease_count; d->crease_vertices = m->crease_vertices; d->crease_sharpness = m->crease_sharpness;
    d->corner_count = m->corner_count; d->corner_vertices = m->corner_vertices; d->corner_sharpness = m->corner_sharpness;
    d->hole_count = m->hole_count; d->holes = m->holes;
    d->uv_count = m->uv_count; d->uvs = m->uvs; d->face_uvs = m->face_uvs;
    d->boundary = m->boundary; d->crease_method = m->crease_method;
    d->triangle_rule = m->triangle_rule; d->uv_interp = m->uv_interp;
}

/* Face f's Newell normal (unnormalised; twice the vector area of a planar polygon). */
static void sfb__face_newell(const sfb_mesh *m, int f, double n[3]) {
    const int a = m->base.fv_off[f], k = m->base.fv_off[f + 1] - a;
    int i;
    n[0] = n[1] = n[2] = 0.0;
    for (i = 0; i < k; ++i) {
        const float *p = m->positions + 3 * (size_t)m->base.fv[a + i], *q = m->positions + 3 * (size_t)m->base.fv[a + (i + 1) % k];
        n[0] += ((double)p[1] - q[1]) * ((double)p[2] + q[2]);
        n[1] += ((double)p[2] - q[2]) * ((double)p[0] + q[0]);
        n[2] += ((double)p[0] - q[0]) * ((double)p[1] + q[1]);
    }
}

SFB_API sfb_result sfb_mesh_crease_by_angle(sfb_context *ctx, const sfb_mesh *m, float degrees, sfb_mesh **out, int *added) {
    const sfb__level *l;
    sfb_mesh_desc d;
    double *fn = NULL, cos_limit;
    int *cv = NULL, e, nc = 0, nadd = 0;
    float *cs = NULL;
    sfb_result r;
    if (added) *added = 0;
    if (!ctx || !m || !out) return SFB_INVALID_ARGS;
    *out = NULL;
    if (!(degrees >= 0.0f && degrees <= 180.0f))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "crease angle %g is not a number of degrees in 0..180", (double)degrees);
    l = &m->base;
    fn = (double *)sfb__alloc(ctx, ((size_t)l->nf + 1) * 3 * sizeof(double));
    cv = (int *)sfb__alloc(ctx, ((size_t)l->ne + 1) * 2 * sizeof(int));
    cs = (float *)sfb__alloc(ctx, ((size_t)l->ne + 1) * sizeof(float));
    if (!fn || !cv || !cs) {
        sfb__free(ctx, fn); sfb__free(ctx, cv); sfb__free(ctx, cs);
        return sfb__oom(ctx, "the crease-angle edge lists");
    }
    for (e = 0; e < l->nf; ++e) sfb__face_newell(m, e, fn + 3 * (size_t)e);
    cos_limit = cos((double)degrees * 3.14159265358979323846 / 180.0);
    for (e = 0; e < l->ne; ++e) {
        float sharp = l->es[e];
        if (l->ef_off[e + 1] - l->ef_off[e] == 2 && sharp < SFB_SHARPNESS_INFINITE) {
            const int f0 = l->ef[l->ef_off[e]], f1 = l->ef[l->ef_off[e] + 1];
            const double *a = fn + 3 * (size_t)f0, *b = fn + 3 * (size_t)f1;
            const double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
            const int holes = (l->fhole && (l->fhole[f0] || l->fhole[f1]));
            /* the angle is over the limit when cos(angle) < cos(limit) (180: never) */
            if (!holes && la > 0.0 && lb > 0.0 && isfinite(la) && isfinite(lb) && degrees < 180.0f &&
                (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb) < cos_limit) {
                sharp = SFB_SHARPNESS_INFINITE;
                ++nadd;
            }
        }
        if (sharp > 0.0f) {
            cv[2 * nc] = l->ev[2 * e];
            cv[2 * nc + 1] = l->ev[2 * e + 1];
            cs[nc++] = sharp;
        }
    }
    sfb_mesh_get_desc(m, &d);
    d.crease_count = nc;
    d.crease_vertices = cv;
    d.crease_sharpness = cs;
    r = sfb_mesh_create(ctx, &d, out);
    if (r == SFB_SUCCESS && added) *added = nadd;
    sfb__free(ctx, fn);
    sfb__free(ctx, cv);
    sfb__free(ctx, cs);
    return r;
}

/* ---- sfb_mesh_triangulate ---- */

/* The diagonals made so far (vertex pairs, low index first, packed in 64 bits; 0 = empty slot):
 * open addressing, at most half full. */
typedef struct sfb__pairs {
    unsigned long long *slot;
    size_t mask;
} sfb__pairs;
static size_t sfb__pairs_at(const sfb__pairs *P, unsigned long long key) {
    size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 17) & P->mask;
    while (P->slot[h] && P->slot[h] != key) h = (h + 1) & P->mask;
    return h;
}
static unsigned long long sfb__pair_key(int a, int b) {
    return a < b ? ((unsigned long long)(unsigned)a << 32 | (unsigned)b) + 1 : ((unsigned long long)(unsigned)b << 32 | (unsigned)a) + 1;
}

/* 1 when the mesh has an edge between vertices a and b, or an earlier split made one. */
static int sfb__has_edge(const sfb__level *l, const sfb__pairs *P, int a, int b) {
    int j;
    for (j = l->ve_off[a]; j < l->ve_off[a + 1]; ++j)
        if (sfb__other_end(l, l->ve[j], a) == b) return 1;
    return P->slot[sfb__pairs_at(P, sfb__pair_key(a, b))] != 0;
}

/* Polygons of more corners than this are fanned from their first corner (ear clipping costs the
 * square of the corners; a convex cap, the usual big polygon, fans the same) */
#define SFB__EAR_MAX 256

/* Is corner i (of the remaining polygon nx/pv, 2D points q) an ear: convex, and no other remaining
 * corner inside or on its triangle? key: its closing diagonal's preference (lower first: a
 * diagonal that is already an edge of the mesh after every other, then by length). */
static int sfb__ear(const sfb_mesh *m, const sfb__pairs *P, const int *fv, const double *q, const int *nx, const int *pv, int i, double tol, double *key) {
    const int p = pv[i], n = nx[i];
    const double ax = q[2 * p], ay = q[2 * p + 1], bx = q[2 * i], by = q[2 * i + 1], cx = q[2 * n], cy = q[2 * n + 1];
    const double area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
    const float *pa = m->positions + 3 * (size_t)fv[p], *pc = m->positions + 3 * (size_t)fv[n];
    int j;
    if (!(area > tol)) return 0;
    for (j = nx[n]; j != p; j = nx[j]) {
        const double x = q[2 * j], y = q[2 * j + 1];
        /* inside or on the triangle (a corner at the same place as one of the three counts too:
         * cutting there would leave a sliver) */
        if ((bx - ax) * (y - ay) - (by - ay) * (x - ax) >= -tol && (cx - bx) * (y - by) - (cy - by) * (x - bx) >= -tol &&
            (ax - cx) * (y - cy) - (ay - cy) * (x - cx) >= -tol)
            return 0;
    }
    *key = ((double)pa[0] - pc[0]) * ((double)pa[0] - pc[0]) + ((double)pa[1] - pc[1]) * ((double)pa[1] - pc[1]) +
           ((double)pa[2] - pc[2]) * ((double)pa[2] - pc[2]);
    if (sfb__has_edge(&m->base, P, fv[p], fv[n])) *key += 1e300;
    return 1;
}

/* Face f (k >= 4 corners) as k - 2 triangles of its local corner indices, into tri. Ear clipping in
 * the plane of its Newell normal; each step cuts the ear whose closing diagonal is shortest (so a
 * quad is split along its shorter diagonal where that lies inside it), a diagonal that is already
 * an edge of the mesh last; where no corner is an ear (a polygon folded over itself, or flat to
 * rounding) the corner with the largest triangle is cut. Its diagonals join P. Scratch: 3k ints,
 * 3k doubles. */
static void sfb__split_face(const sfb_mesh *m, sfb__pairs *P, int f, int *tri, int *iw, double *dw) {
    const sfb__level *l = &m->base;
    const int o = l->fv_off[f], k = l->fv_off[f + 1] - o, *fv = l->fv + o;
    int *nx = iw, *pv = iw + k, *ear = iw + 2 * k, i, left = k, nt = 0;
    double *q = dw, *key = dw + 2 * k, nrm[3], e1[3], e2[3], len, scale = 0.0, tol;
    if (k > SFB__EAR_MAX) {
        for (i = 1; i + 1 < k; ++i) {
            tri[3 * nt] = 0; tri[3 * nt + 1] = i; tri[3 * nt + 2] = i + 1;
            ++nt;
            if (i > 1) {
                const unsigned long long key2 = sfb__pair_key(fv[0], fv[i]);
                P->slot[sfb__pairs_at(P, key2)] = key2;
            }
        }
        return;
    }
    sfb__face_newell(m, f, nrm);
    len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (len > 0.0 && isfinite(len)) {
        /* e1, e2: an orthonormal pair with e1 x e2 along the normal (so the polygon runs
         * counter-clockwise in (e1, e2)) */
        const int ax = fabs(nrm[0]) < fabs(nrm[1]) ? (fabs(nrm[0]) < fabs(nrm[2]) ? 0 : 2) : (fabs(nrm[1]) < fabs(nrm[2]) ? 1 : 2);
        double t[3] = {0.0, 0.0, 0.0}, d;
        int c;
        for (c = 0; c < 3; ++c) nrm[c] /= len;
        t[ax] = 1.0;
        d = t[0] * nrm[0] + t[1] * nrm[1] + t[2] * nrm[2];
        for (c = 0; c < 3; ++c) e1[c] = t[c] - d * nrm[c];
        d = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
        for (c = 0; c < 3; ++c) e1[c] /= d;
        e2[0] = nrm[1] * e1[2] - nrm[2] * e1[1];
        e2[1] = nrm[2] * e1[0] - nrm[0] * e1[2];
        e2[2] = nrm[0] * e1[1] - nrm[1] * e1[0];
    } else {
        e1[0] = 1.0; e1[1] = e1[2] = 0.0;
        e2[1] = 1.0; e2[0] = e2[2] = 0.0;
    }
    for (i = 0; i < k; ++i) {
        const float *p = m->positions + 3 * (size_t)fv[i];
        q[2 * i] = p[0] * e1[0] + p[1] * e1[1] + p[2] * e1[2];
        q[2 * i + 1] = p[0] * e2[0] + p[1] * e2[1] + p[2] * e2[2];
        nx[i] = (i + 1) % k;
        pv[i] = (i + k - 1) % k;
    }
    for (i = 0; i < k; ++i) {
        const double dx = q[2 * i] - q[2 * nx[i]], dy = q[2 * i + 1] - q[2 * nx[i] + 1];
        scale = fmax(scale, dx * dx + dy * dy);
    }
    tol = 1e-12 * scale;
    for (i = 0; i < k; ++i) ear[i] = sfb__ear(m, P, fv, q, nx, pv, i, tol, key + i);
    for (i = 0; left > 3; --left) {
        int best = -1, j, c = i;
        /* the best ear; none: the corner of the largest triangle */
        for (j = 0; j < left; ++j, c = nx[c])
            if (ear[c] && (best < 0 || key[c] < key[best])) best = c;
        if (best < 0) {
            double amax = -1e300;
            for (j = 0, c = i; j < left; ++j, c = nx[c]) {
                const int p = pv[c], n = nx[c];
                const double a = (q[2 * c] - q[2 * p]) * (q[2 * n + 1] - q[2 * p + 1]) - (q[2 * c + 1] - q[2 * p + 1]) * (q[2 * n] - q[2 * p]);
                if (best < 0 || a > amax) { best = c; amax = a; }
            }
        }
        tri[3 * nt] = pv[best]; tri[3 * nt + 1] = best; tri[3 * nt + 2] = nx[best];
        ++nt;
        {
            const unsigned long long key2 = sfb__pair_key(fv[pv[best]], fv[nx[best]]);
            P->slot[sfb__pairs_at(P, key2)] = key2;
        }
        nx[pv[best]] = nx[best];
        pv[nx[best]] = pv[best];
        i = nx[best];
        if (left > 4) {
            ear[pv[best]] = sfb__ear(m, P, fv, q, nx, pv, pv[best], tol, key + pv[best]);
            ear[nx[best]] = sfb__ear(m, P, fv, q, nx, pv, nx[best], tol, key + nx[best]);
        }
    }
    tri[3 * nt] = pv[i]; tri[3 * nt + 1] = i; tri[3 * nt + 2] = nx[i];
}

SFB_API sfb_result sfb_mesh_triangulate(sfb_context *ctx, const sfb_mesh *m, sfb_mesh **out, int *split) {
    const sfb__level *l;
    sfb_mesh_desc d;
    int *sizes = NULL, *fvo = NULL, *fuv = NULL, *holes = NULL, *first = NULL, *tri = NULL, *iw = NULL;
    double *dw = NULL;
    int f, i, nt = 0, nsplit = 0, kmax = 3, nh = 0;
    size_t at = 0, ndiag = 0, cap = 16;
    sfb__pairs P;
    sfb_result r;
    if (split) *split = 0;
    if (!ctx || !m || !out) return SFB_INVALID_ARGS;
    *out = NULL;
    l = &m->base;
    for (f = 0; f < l->nf; ++f) {
        const int k = l->fv_off[f + 1] - l->fv_off[f];
        nt += k - 2;
        nsplit += k > 3;
        if (k > kmax) kmax = k;
        ndiag += (size_t)(k - 3);
    }
    while (cap < 2 * ndiag + 2) cap *= 2;
    P.mask = cap - 1;
    P.slot = (unsigned long long *)sfb__calloc(ctx, cap, sizeof(unsigned long long));
    sizes = (int *)sfb__alloc(ctx, ((size_t)nt + 1) * sizeof(int));
    fvo = (int *)sfb__alloc(ctx, ((size_t)nt + 1) * 3 * sizeof(int));
    fuv = m->face_uvs ? (int *)sfb__alloc(ctx, ((size_t)nt + 1) * 3 * sizeof(int)) : NULL;
    first = (int *)sfb__alloc(ctx, ((size_t)l->nf + 1) * sizeof(int));
    tri = (int *)sfb__alloc(ctx, (size_t)kmax * 3 * sizeof(int));
    iw = (int *)sfb__alloc(ctx, (size_t)kmax * 3 * sizeof(int));
    dw = (double *)sfb__alloc(ctx, (size_t)kmax * 3 * sizeof(double));
    holes = (int *)sfb__alloc(ctx, ((size_t)nt + 1) * sizeof(int));
    if (!sizes || !fvo || (m->face_uvs && !fuv) || !first || !tri || !iw || !dw || !holes || !P.slot) {
        r = sfb__oom(ctx, "the triangulated faces");
        goto done;
    }
    for (f = 0, nt = 0; f < l->nf; ++f) {
        const int o = l->fv_off[f], k = l->fv_off[f + 1] - o;
        first[f] = nt;
        if (k == 3) { tri[0] = 0; tri[1] = 1; tri[2] = 2; }
        else sfb__split_face(m, &P, f, tri, iw, dw);
        for (i = 0; i < 3 * (k - 2); ++i) {
            fvo[at] = l->fv[o + tri[i]];
            if (fuv) fuv[at] = m->face_uvs[o + tri[i]];
            ++at;
        }
        for (i = 0; i < k - 2; ++i) sizes[nt++] = 3;
    }
    for (f = 0; f < l->nf; ++f)
        if (l->fhole && l->fhole[f])
            for (i = 0; i < l->fv_off[f + 1] - l->fv_off[f] - 2; ++i) holes[nh++] = first[f] + i;
    sfb_mesh_get_desc(m, &d);
    d.face_count = nt;
    d.face_sizes = sizes;
    d.face_vertices = fvo;
    d.face_uvs = fuv;
    d.hole_count = nh;
    d.holes = holes;
    r = sfb_mesh_create(ctx, &d, out);
    if (r == SFB_SUCCESS && split) *split = nsplit;
done:
    sfb__free(ctx, sizes); sfb__free(ctx, fvo); sfb__free(ctx, fuv); sfb__free(ctx, first);
    sfb__free(ctx, tri); sfb__free(ctx, iw); sfb__free(ctx, dw); sfb__free(ctx, holes); sfb__free(ctx, P.slot);
    return r;
}

SFB_API void sfb_mesh_get_info(const sfb_mesh *m, sfb_mesh_info *o) {
    const sfb__level *l;
    sfb__level prep;
    int v, e, f, c;
    if (!o) return;
    memset(o, 0, sizeof *o);
    if (!m) return;
    l = &m->base;
    o->vertex_count = l->nv; o->face_count = l->nf; o->edge_count = l->ne; o->face_vertex_count = l->nfv;
    o->uv_count = m->uv_count;
    for (f = 0; f < l->nf; ++f) {
        int n = l->fv_off[f + 1] - l->fv_off[f];
        if (n == 3) o->triangles++; else if (n == 4) o->quads++; else o->ngons++;
        if (n > o->max_face_size) o->max_face_size = n;
        o->holes += l->fhole[f] != 0;
    }
    for (e = 0; e < l->ne; ++e) {
        if (l->etag[e] & SFB__TAG_BOUNDARY) o->boundary_edges++;
        if (l->etag[e] & SFB__TAG_NONMANIFOLD) o->nonmanifold_edges++;
        if (l->es[e] > 0.0f) {
            o->sharp_edges++;
            if (l->es[e] >= SFB_SHARPNESS_INFINITE) o->infsharp_edges++; else o->semisharp_edges++;
        }
    }
    for (c = 0; c < 3; ++c) { o->bbox_min[c] = l->nv ? 3.4e38f : 0.0f; o->bbox_max[c] = l->nv ? -3.4e38f : 0.0f; }
    for (v = 0; v < l->nv; ++v) {
        int k = l->vf_off[v + 1] - l->vf_off[v], d = l->ve_off[v + 1] - l->ve_off[v];
        if (l->vtag[v] & SFB__TAG_BOUNDARY) o->boundary_vertices++;
        if (l->vtag[v] & SFB__TAG_NONMANIFOLD) { if (k == 0) o->bare_vertices++; else o->nonmanifold_vertices++; }
        if (l->vs[v] > 0.0f) o->corners++;
        if (d > o->max_valence) o->max_valence = d;
        if (!(l->vtag[v] & SFB__TAG_NONMANIFOLD)) {
            if (l->vtag[v] & SFB__TAG_BOUNDARY) {
                o->extraordinary_catmark += k != 2 && k != 1;
                o->extraordinary_loop += k != 3 && k != 1;
            } else {
                o->extraordinary_catmark += k != 4;
                o->extraordinary_loop += k != 6;
            }
        }
        for (c = 0; c < 3; ++c) {
            float x = m->positions[3 * (size_t)v + c];
            if (x < o->bbox_min[c]) o->bbox_min[c] = x;
            if (x > o->bbox_max[c]) o->bbox_max[c] = x;
        }
    }
    /* vertex rules as refinement will see them (after boundary sharpening) */
    if (sfb__level_prepare(m->ctx, l, m->boundary == SFB_BOUNDARY_EDGE_AND_CORNER, 0, &prep) == SFB_SUCCESS) {
        for (v = 0; v < prep.nv; ++v) {
            o->darts += prep.vrule[v] == SFB__RULE_DART;
            o->crease_vertices += prep.vrule[v] == SFB__RULE_CREASE;
            o->corner_vertices += prep.vrule[v] == SFB__RULE_CORNER && prep.ve_off[v + 1] > prep.ve_off[v];
        }
        sfb__level_free(m->ctx, &prep);
    }
}

SFB_API int sfb_mesh_valence_histogram(const sfb_mesh *m, int *counts, int max_valence) {
    int v, over = 0;
    if (!m || !counts || max_valence <= 0) return 0;
    memset(counts, 0, sizeof(int) * (size_t)max_valence);
    for (v = 0; v < m->base.nv; ++v) {
        int d = m->base.ve_off[v + 1] - m->base.ve_off[v];
        if (d < max_valence) counts[d]++; else over++;
    }
    return over;
}
