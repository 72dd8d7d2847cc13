/* Curved PN triangles (SFB_SCHEME_PN; ALGORITHMS.md section 5.3): what engines tessellate
 * today, beside seed 004's triangular splines for comparison. One cubic Bezier triangle per
 * mesh triangle from its corners and their vertex normals, degree-raised to the quartic
 * BEZIER_TRI15 patches the Loop work evaluates, so eval, tessellation, trimming, rendering and
 * the glTF export run on every backend unchanged.
 *
 * Choices the method leaves open, made here:
 *   - vertex normals: the angle-weighted mean of the incident triangles' normals (each
 *     triangle's normal weighted by its angle at the vertex), computed from the base positions
 *     when the surface is built; a mean that cancels (opposite triangles) falls back to the
 *     first incident triangle's normal. PN triangles know no creases: sharpness tags are
 *     ignored, every vertex has one normal.
 *   - normals: the method's quadratic normal field (for shading), not du x dv: the patch table
 *     carries it as its normal_field, a second table of BEZIER_TRI15 patches (the quadratic
 *     field degree-raised twice) evaluated on the backend like the positions and normalised
 *     (sfb__surface_eval_unchecked). So tessellation, rendering, the analysis and the glTF export
 *     shade with what engines shade with. Corners get the vertex normals exactly (so do the
 *     geometric normals: both edge points next to a corner lie in the plane through it normal to
 *     that vertex normal); along an edge the field depends on that edge's two vertices only, so
 *     it is continuous across edges. An edge's middle coefficient normalize(N_i + N_j -
 *     v_ij (P_j - P_i)) that cancels (normals mirrored into opposite directions) is the
 *     triangle's unit normal instead. du, dv and the second derivatives stay the cubic geometry's.
 *   - refused: faces that are not triangles, non-manifold edges (more than two triangles),
 *     degenerate triangles (an area below 1e-12 of the squared bounding-box diagonal, or
 *     non-finite positions), since their normals, and so the patch, are undefined.
 * Param faces are the triangles, (u,v) barycentric as Loop's: (1-u-v) P0 + u P1 + v P2. */

/* Cubic point (a = exponent of s, b = exponent of t) of triangle (P[0], P[1], P[2]) with
 * vertex normals N: corners P0 (0,0), P1 (3,0), P2 (0,3). */
static void sfb__pn_cubic(double P[3][3], double N[3][3], double C[5][5][3]) {
    /* the corner of each (a, b) on the boundary and the corner it points to */
    static const int edge[6][4] = {{1, 0, 0, 1}, {2, 0, 1, 0}, {0, 1, 0, 2}, {0, 2, 2, 0}, {2, 1, 1, 2}, {1, 2, 2, 1}};
    double E[3] = {0, 0, 0}, V[3];
    int k, c;
    for (c = 0; c < 3; ++c) {
        C[0][0][c] = P[0][c];
        C[3][0][c] = P[1][c];
        C[0][3][c] = P[2][c];
        V[c] = (P[0][c] + P[1][c] + P[2][c]) / 3.0;
    }
    for (k = 0; k < 6; ++k) {
        const int a = edge[k][0], b = edge[k][1], i = edge[k][2], j = edge[k][3];
        double w = 0.0;
        for (c = 0; c < 3; ++c) w += (P[j][c] - P[i][c]) * N[i][c];
        for (c = 0; c < 3; ++c) {
            C[a][b][c] = (2.0 * P[i][c] + P[j][c] - w * N[i][c]) / 3.0;
            E[c] += C[a][b][c] / 6.0;
        }
    }
    for (c = 0; c < 3; ++c) C[1][1][c] = E[c] + 0.5 * (E[c] - V[c]);
}

/* Degree raising from degree d to d + 1 (the Bezier triangle's points by exponents (a, b) of s
 * and t, a + b <= d): r(i,j) = (i c(i-1,j) + j c(i,j-1) + k c(i,j)) / (d + 1), with
 * k = d + 1 - i - j the exponent of w. */
static void sfb__pn_raise_degree(int d, double C[5][5][3], double R[5][5][3]) {
    int i, j, c;
    for (j = 0; j <= d + 1; ++j)
        for (i = 0; i + j <= d + 1; ++i) {
            const int k = d + 1 - i - j;
            for (c = 0; c < 3; ++c) {
                double v = 0.0;
                if (i > 0) v += i * C[i - 1][j][c];
                if (j > 0) v += j * C[i][j - 1][c];
                if (k > 0) v += k * C[i][j][c];
                R[i][j][c] = v / (d + 1);
            }
        }
}

/* A cubic raised to our quartic order (row by row in t, s rising in a row), 45 doubles. */
static void sfb__pn_raise(double C[5][5][3], double *out) {
    double R[5][5][3];
    int i, j, c, q = 0;
    sfb__pn_raise_degree(3, C, R);
    for (j = 0; j <= 4; ++j)
        for (i = 0; i + j <= 4; ++i, ++q)
            for (c = 0; c < 3; ++c) out[3 * q + c] = R[i][j][c];
}

/* The quadratic normal field of the triangle (its unit normal `fn`), raised to a cubic C for
 * sfb__pn_raise: Q(a, b) with a + b <= 2, corners N0 (0,0), N1 (2,0), N2 (0,2), the edges'
 * middles at (1,0) P0P1, (0,1) P0P2, (1,1) P1P2. */
static void sfb__pn_quadratic_normals(double P[3][3], double N[3][3], const double fn[3], double C[5][5][3]) {
    static const int mid[3][4] = {{1, 0, 0, 1}, {0, 1, 0, 2}, {1, 1, 1, 2}};
    double Q[5][5][3];
    int k, c;
    for (c = 0; c < 3; ++c) {
        Q[0][0][c] = N[0][c];
        Q[2][0][c] = N[1][c];
        Q[0][2][c] = N[2][c];
    }
    for (k = 0; k < 3; ++k) {
        const int a = mid[k][0], b = mid[k][1], p = mid[k][2], q = mid[k][3];
        double d[3], h[3], dd = 0.0, dn = 0.0, len = 0.0;
        for (c = 0; c < 3; ++c) {
            d[c] = P[q][c] - P[p][c];
            dd += d[c] * d[c];
            dn += d[c] * (N[p][c] + N[q][c]);
        }
        for (c = 0; c < 3; ++c) {
            h[c] = N[p][c] + N[q][c] - 2.0 * dn / dd * d[c]; /* dd > 0: degenerate triangles are refused */
            len += h[c] * h[c];
        }
        len = sqrt(len);
        for (c = 0; c < 3; ++c) Q[a][b][c] = len > 1e-9 ? h[c] / len : fn[c];
    }
    sfb__pn_raise_degree(2, Q, C);
}

static void sfb__pn_face_normal(const float *a, const float *b, const float *c, double n[3]) {
    double u[3], v[3];
    int k;
    for (k = 0; k < 3; ++k) { u[k] = (double)b[k] - a[k]; v[k] = (double)c[k] - a[k]; }
    sfb__cross3(u, v, n);
}

/* The angle at corner a of triangle (a, b, c). */
static double sfb__pn_angle(const float *a, const float *b, const float *c) {
    double u[3], v[3], x[3], d = 0.0;
    int k;
    for (k = 0; k < 3; ++k) { u[k] = (double)b[k] - a[k]; v[k] = (double)c[k] - a[k]; d += u[k] * v[k]; }
    sfb__cross3(u, v, x);
    return atan2(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), d);
}

sfb_result sfb__pn_build(sfb_context *ctx, const sfb__level *l, const float *positions, sfb__patch_table *pt) {
    double *vn = NULL, *net = NULL;
    int f, v, k, c;
    sfb_result r = SFB_SUCCESS;
    memset(pt, 0, sizeof *pt);
    r = sfb__tri_mesh_check(ctx, l, positions, "PN triangles", 0);
    if (r != SFB_SUCCESS) return r;
    vn = (double *)sfb__calloc(ctx, (size_t)l->nv * 3 + 1, sizeof(double));
    if (!vn) return sfb__oom(ctx, "PN triangles");
    for (f = 0; f < l->nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        double n[3], len;
        sfb__pn_face_normal(positions + 3 * (size_t)fv[0], positions + 3 * (size_t)fv[1], positions + 3 * (size_t)fv[2], n);
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]); /* > 0: sfb__tri_mesh_check refused degenerate triangles */
        for (k = 0; k < 3; ++k) {
            const double a = sfb__pn_angle(positions + 3 * (size_t)fv[k], positions + 3 * (size_t)fv[(k + 1) % 3],
                                           positions + 3 * (size_t)fv[(k + 2) % 3]);
            for (c = 0; c < 3; ++c) vn[3 * (size_t)fv[k] + c] += a * n[c] / len;
        }
    }
    for (v = 0; v < l->nv; ++v) {
        double *n = vn + 3 * (size_t)v, len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 1e-9) && l->vf_off[v + 1] > l->vf_off[v]) { /* cancelled: the first triangle's normal */
            const int g = l->vf[l->vf_off[v]], *fv = l->fv + l->fv_off[g];
            sfb__pn_face_normal(positions + 3 * (size_t)fv[0], positions + 3 * (size_t)fv[1], positions + 3 * (size_t)fv[2], n);
            len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        }
        if (len > 0.0)
            for (c = 0; c < 3; ++c) n[c] /= len;
    }
    /* the tables: one param face and one BEZIER_TRI15 patch (15 points of its own) per
     * triangle, for the geometry and for the normal field */
    net = (double *)sfb__alloc(ctx, 2 * 45 * (size_t)l->nf * sizeof(double) + 1);
    if (!net) { r = sfb__oom(ctx, "PN triangles"); goto done; }
    for (f = 0; f < l->nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        double P[3][3], N[3][3], C[5][5][3], fn[3], len;
        for (k = 0; k < 3; ++k)
            for (c = 0; c < 3; ++c) {
                P[k][c] = positions[3 * (size_t)fv[k] + c];
                N[k][c] = vn[3 * (size_t)fv[k] + c];
            }
        sfb__pn_cubic(P, N, C);
        sfb__pn_raise(C, net + 45 * (size_t)f);
        sfb__pn_face_normal(positions + 3 * (size_t)fv[0], positions + 3 * (size_t)fv[1], positions + 3 * (size_t)fv[2], fn);
        len = sqrt(fn[0] * fn[0] + fn[1] * fn[1] + fn[2] * fn[2]);
        for (c = 0; c < 3; ++c) fn[c] /= len;
        sfb__pn_quadratic_normals(P, N, fn, C);
        sfb__pn_raise(C, net + 45 * ((size_t)l->nf + f));
    }
    if ((r = sfb__patch_table_beztri_own(ctx, l, net, pt)) != SFB_SUCCESS) goto done;
    pt->normal_field = (sfb__patch_table *)sfb__calloc(ctx, 1, sizeof *pt->normal_field);
    if (!pt->normal_field) { r = sfb__oom(ctx, "PN triangles' normals"); goto done; }
    r = sfb__patch_table_beztri_own(ctx, l, net + 45 * (size_t)l->nf, pt->normal_field);
done:
    sfb__free(ctx, vn);
    sfb__free(ctx, net);
    if (r != SFB_SUCCESS) sfb__patch_table_free(ctx, pt);
    return r;
}
