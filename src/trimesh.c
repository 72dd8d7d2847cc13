/* Measures of a triangle mesh: angle-weighted vertex normals (each face's unit normal weighted by
 * its angle at the vertex, Thurmer and Wuthrich 1998) and the mean curvature per vertex from the
 * cotangent Laplacian with the mixed Voronoi areas of Meyer, Desbrun, Schroder and Barr 2002
 * (K(x_i) = 1/(2 A_i) sum_j (cot alpha_ij + cot beta_ij) (x_i - x_j) = 2 H n: |K|/2, signed by
 * K's side of the vertex normal, so positive where the surface bends away from the normal),
 * zero at vertices on an edge that does not have exactly two faces (the boundary, non-manifold
 * edges) and at vertices no face uses; plus the public sfb_mesh_vertex_normals and
 * sfb_mesh_mean_curvature on an sfb_mesh of triangles. Faces with an index out of range or
 * repeated, or with no area, contribute nothing. All in double; the functions write only their
 * outputs, so any number of threads may run them on one mesh at once. */

/* Corner data of face (i, j, k): the edges from corner c to the next two, their cross product. */
static int trimesh_face(const double *pos, const int *t, double e[3][3], double *twice_area) {
    const double *p0 = pos + 3 * (size_t)t[0], *p1 = pos + 3 * (size_t)t[1], *p2 = pos + 3 * (size_t)t[2];
    double n[3];
    int k;
    for (k = 0; k < 3; ++k) {
        e[0][k] = p1[k] - p0[k]; /* edge 0: 0 -> 1 */
        e[1][k] = p2[k] - p1[k]; /* edge 1: 1 -> 2 */
        e[2][k] = p0[k] - p2[k]; /* edge 2: 2 -> 0 */
    }
    sfb__cross3(e[0], e[1], n);
    *twice_area = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return *twice_area > 0.0 && *twice_area - *twice_area == 0.0;
}

static int trimesh_valid(int nv, const int *t) {
    return t[0] >= 0 && t[0] < nv && t[1] >= 0 && t[1] < nv && t[2] >= 0 && t[2] < nv && t[0] != t[1] && t[1] != t[2] &&
           t[0] != t[2];
}

static double trimesh_dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

void sfb__trimesh_vertex_normals(int nv, const double *pos, int nf, const int *tri, double *normals) {
    int f, v, c, k;
    if (nv <= 0 || !normals) return;
    memset(normals, 0, (size_t)nv * 3 * sizeof(double));
    if (!pos || !tri) return;
    for (f = 0; f < nf; ++f) {
        const int *t = tri + 3 * (size_t)f;
        double e[3][3], n[3], ta;
        if (!trimesh_valid(nv, t) || !trimesh_face(pos, t, e, &ta)) continue;
        sfb__cross3(e[0], e[1], n);
        for (k = 0; k < 3; ++k) n[k] /= ta;
        for (c = 0; c < 3; ++c) {
            /* the angle at corner c, between the edge out of it and the reversed edge into it */
            const double *out = e[c], *in = e[(c + 2) % 3];
            double cr[3], ang;
            sfb__cross3(out, in, cr);
            ang = atan2(sqrt(trimesh_dot(cr, cr)), -trimesh_dot(out, in));
            for (k = 0; k < 3; ++k) normals[3 * (size_t)t[c] + k] += ang * n[k];
        }
    }
    for (v = 0; v < nv; ++v) {
        double *n = normals + 3 * (size_t)v;
        const double l = sqrt(trimesh_dot(n, n));
        if (l > 0.0 && l - l == 0.0)
            for (k = 0; k < 3; ++k) n[k] /= l;
        else
            n[0] = n[1] = n[2] = 0.0;
    }
}

sfb_result sfb__trimesh_mean_curvature(sfb_context *ctx, int nv, const double *pos, int nf, const int *tri, double *H) {
    double *S = NULL, *A, *N;
    int *off = NULL, *other, *cnt;
    unsigned char *bad;
    size_t bytes;
    int f, v, c, k;
    if (!ctx) return SFB_INVALID_ARGS;
    if (nv < 0 || nf < 0 || (nv > 0 && (!pos || !H)) || (nf > 0 && !tri))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mean curvature: bad arguments");
    if (nv == 0) return SFB_SUCCESS;
    /* per vertex: S (3), A (1), N (3) doubles; off (nv + 1), cnt (nv) ints, bad bytes; other: 3 nf ints */
    if (!sfb__mul_size((size_t)nv, 7 * sizeof(double), &bytes) || !(S = (double *)sfb__calloc(ctx, 1, bytes)) ||
        !sfb__mul_size((size_t)nv + 1 + (size_t)nv + 3 * (size_t)nf, sizeof(int), &bytes) || bytes > ((size_t)-1) - (size_t)nv ||
        !(off = (int *)sfb__calloc(ctx, 1, bytes + (size_t)nv))) {
        sfb__free(ctx, S);
        return sfb__oom(ctx, "the mean curvature");
    }
    A = S + 3 * (size_t)nv;
    N = A + nv;
    cnt = off + nv + 1;
    other = cnt + nv;
    bad = (unsigned char *)(other + 3 * (size_t)nf);
    /* edges with other than two faces: each edge (lo, hi) listed at lo, counted through cnt */
    for (f = 0; f < nf; ++f) {
        const int *t = tri + 3 * (size_t)f;
        if (!trimesh_valid(nv, t)) continue;
        for (c = 0; c < 3; ++c) {
            const int a = t[c], b = t[(c + 1) % 3];
            off[(a < b ? a : b) + 1]++;
        }
    }
    for (v = 0; v < nv; ++v) off[v + 1] += off[v];
    for (f = 0; f < nf; ++f) {
        const int *t = tri + 3 * (size_t)f;
        if (!trimesh_valid(nv, t)) continue;
        for (c = 0; c < 3; ++c) {
            const int a = t[c], b = t[(c + 1) % 3];
            other[off[a < b ? a : b]++] = a < b ? b : a;
        }
    }
    for (v = nv; v > 0; --v) off[v] = off[v - 1];
    off[0] = 0;
    for (v = 0; v < nv; ++v) {
        int i;
        for (i = off[v]; i < off[v + 1]; ++i) cnt[other[i]]++;
        for (i = off[v]; i < off[v + 1]; ++i)
            if (cnt[other[i]] != 2) bad[v] = bad[other[i]] = 1;
        for (i = off[v]; i < off[v + 1]; ++i) cnt[other[i]] = 0;
    }
    /* the cotangent sums and the mixed areas */
    for (f = 0; f < nf; ++f) {
        const int *t = tri + 3 * (size_t)f;
        double e[3][3], ta, cot[3], dots[3];
        if (!trimesh_valid(nv, t) || !trimesh_face(pos, t, e, &ta)) continue;
        for (c = 0; c < 3; ++c) {
            /* at corner c: edges out of it (e[c]) and into it reversed (-e[c+2]) */
            dots[c] = -trimesh_dot(e[c], e[(c + 2) % 3]);
            cot[c] = dots[c] / ta;
        }
        for (c = 0; c < 3; ++c) {
            const int i = t[c], j = t[(c + 1) % 3], l = t[(c + 2) % 3];
            const double *xi = pos + 3 * (size_t)i, *xj = pos + 3 * (size_t)j, *xl = pos + 3 * (size_t)l;
            /* edge i-j faces corner c+2, edge i-l faces corner c+1 */
            const double cij = cot[(c + 2) % 3], cil = cot[(c + 1) % 3];
            for (k = 0; k < 3; ++k) S[3 * (size_t)i + k] += cij * (xi[k] - xj[k]) + cil * (xi[k] - xl[k]);
            if (dots[0] >= 0.0 && dots[1] >= 0.0 && dots[2] >= 0.0)
                A[i] += (cij * trimesh_dot(e[c], e[c]) + cil * trimesh_dot(e[(c + 2) % 3], e[(c + 2) % 3])) / 8.0;
            else if (dots[c] < 0.0)
                A[i] += ta / 4.0; /* obtuse at i: half the area */
            else
                A[i] += ta / 8.0; /* obtuse elsewhere: a quarter */
        }
    }
    sfb__trimesh_vertex_normals(nv, pos, nf, tri, N);
    for (v = 0; v < nv; ++v) {
        double K[3], h;
        if (bad[v] || !(A[v] > 0.0)) { H[v] = 0.0; continue; }
        for (k = 0; k < 3; ++k) K[k] = S[3 * (size_t)v + k] / (2.0 * A[v]);
        h = 0.5 * sqrt(trimesh_dot(K, K));
        H[v] = trimesh_dot(K, N + 3 * (size_t)v) < 0.0 ? -h : h;
        if (!(H[v] - H[v] == 0.0)) H[v] = 0.0;
    }
    sfb__free(ctx, S);
    sfb__free(ctx, off);
    return SFB_SUCCESS;
}

/* ---- on an sfb_mesh ---- */

/* The mesh's positions in double, after checking that every face is a triangle. */
static sfb_result trimesh_of_mesh(sfb_context *ctx, const sfb_mesh *mesh, const void *outp, const char *who, double **pos) {
    const sfb__level *l;
    size_t bytes;
    int f, i;
    *pos = NULL;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!mesh || !outp) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "%s: NULL argument", who);
    l = &mesh->base;
    for (f = 0; f < l->nf; ++f)
        if (l->fv_off[f + 1] - l->fv_off[f] != 3 || l->fv_off[f] != 3 * f)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "%s needs triangles; this face has %d vertices (sfb_mesh_triangulate, the tools' "
                              "--triangulate, splits faces into triangles)", who,
                              l->fv_off[f + 1] - l->fv_off[f]);
    if (!sfb__mul_size((size_t)l->nv + 1, 3 * sizeof(double), &bytes) || !(*pos = (double *)sfb__alloc(ctx, bytes)))
        return sfb__oom(ctx, who);
    for (i = 0; i < 3 * l->nv; ++i) (*pos)[i] = (double)mesh->positions[i];
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_mesh_vertex_normals(sfb_context *ctx, const sfb_mesh *mesh, float *normals) {
    double *pos, *n;
    const sfb__level *l;
    size_t bytes;
    int i;
    sfb_result r = trimesh_of_mesh(ctx, mesh, normals, "sfb_mesh_vertex_normals", &pos);
    if (r != SFB_SUCCESS) return r;
    l = &mesh->base;
    if (!sfb__mul_size((size_t)l->nv + 1, 3 * sizeof(double), &bytes) || !(n = (double *)sfb__alloc(ctx, bytes))) {
        sfb__free(ctx, pos);
        return sfb__oom(ctx, "sfb_mesh_vertex_normals");
    }
    sfb__trimesh_vertex_normals(l->nv, pos, l->nf, l->fv, n);
    for (i = 0; i < 3 * l->nv; ++i) normals[i] = (float)n[i];
    sfb__free(ctx, n);
    sfb__free(ctx, pos);
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_mesh_mean_curvature(sfb_context *ctx, const sfb_mesh *mesh, float *curvature) {
    double *pos, *h;
    const sfb__level *l;
    int i;
    sfb_result r = trimesh_of_mesh(ctx, mesh, curvature, "sfb_mesh_mean_curvature", &pos);
    if (r != SFB_SUCCESS) return r;
    l = &mesh->base;
    if (!(h = (double *)sfb__calloc(ctx, (size_t)l->nv + 1, sizeof(double)))) {
        sfb__free(ctx, pos);
        return sfb__oom(ctx, "sfb_mesh_mean_curvature");
    }
    r = sfb__trimesh_mean_curvature(ctx, l->nv, pos, l->nf, l->fv, h);
    if (r == SFB_SUCCESS)
        for (i = 0; i < l->nv; ++i) curvature[i] = (float)h[i];
    sfb__free(ctx, h);
    sfb__free(ctx, pos);
    return r;
}
