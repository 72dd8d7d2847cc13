/* Manifold-based blending surfaces with darts, creases and corners (seed 000, after Ying and
 * Zorin): the MANIFOLD4 patch family of the patch table (scheme SFB_SCHEME_MANIFOLD_BLEND).
 *
 * The manifold mesh. A mesh of quads is used as it is. Any other mesh first takes one
 * Catmull-Clark step: edges with sharpness > 0 are made infinitely sharp for that step (so
 * their children are crease edges and stay sharp), vertices with sharpness > 0 likewise
 * (corners). A base quad is then one parametric face made of its four child quads (quadrants
 * of its (u,v) square, one level of the patch quadtree); an n-gon's sub-face i is its child
 * quad i, as for Catmull-Clark limit evaluation.
 *
 * Charts and local coordinates. In a quad with corners V0..V3 (counter-clockwise) the face
 * coordinates (c,d) in [0,1]^2 put V0 at (0,0), V1 at (1,0) and V3 at (0,1). Corner j sees the
 * point at its own coordinates (a_j, b_j), a along the edge to its next corner, b along the
 * edge to its previous one:
 *     j = 0: (c, d)    j = 1: (d, 1 - c)    j = 2: (1 - c, 1 - d)    j = 3: (1 - d, c).
 * Around a manifold vertex of valence k, face h lies between edge h (its a axis) and edge h + 1
 * (its b axis), counter-clockwise. The chart of the vertex maps the point of face h with
 * zeta = a + i b to z = zeta^(4/k) e^(2 pi i h / k) (seed section III.1): face h covers the
 * sector [2 pi h / k, 2 pi (h + 1) / k], the neighbour across edge h sits at e^(2 pi i h / k),
 * the far corner of face h at 2^(2/k) e^(i (2 pi h + pi) / k).
 *
 * Local geometry by the number n of sharp edges at the vertex (Table 1; an edge is sharp when
 * its sharpness is > 0; boundary and non-manifold edges are infinitely sharp once the mesh is
 * prepared, so they count):
 *   - n = 0 at an interior manifold vertex: the bi-quadratic patch of eq. 2,
 *     P(u + iv) = [1 u u^2] C [1 v v^2]^T, C_00 = the vertex (the constraint P(0) = v_i), the
 *     other eight coefficient vectors fitted by least squares to the 2k one-ring vertices (k
 *     edge neighbours and k far corners) at their chart positions. The system only depends on
 *     k; its pseudo-inverse (8 x 2k) is computed once per valence. Choice where the fit is
 *     under-determined (k = 2 and k = 3: 4 and 6 equations for 8 unknowns) or rank-deficient:
 *     the minimum-norm solution (eigenvalues of A^T A below 1e-12 of the largest are dropped).
 *     With k = 4 the fit interpolates the 3 x 3 grid.
 *   - n = 1 (dart), n >= 3 (corner), a vertex with sharpness > 0, a non-manifold or bare
 *     vertex: the vertex itself (a point).
 *   - n = 2 (crease; a boundary vertex whose only sharp edges are its two boundary edges is
 *     one): the quadratic Bezier curve q0 = the far end of the first sharp edge e1 (in the
 *     vertex's counter-clockwise edge order), q1 = the vertex, q2 = the far end of e2, at the
 *     curve parameter sigma = (1 - p1 + p2) / 2, p1 = the point's coordinate along e1 when e1
 *     is an edge of the face (a or b), else 0, p2 the same for e2. Choice: the seed's eq. 4
 *     reads 0.5 -/+ |z| cos(theta); we halve the projection so that the neighbours at the far
 *     ends of e1 and e2 sit at sigma = 0 and 1, the curve's ends: with evenly spaced collinear
 *     crease vertices the blended crease is then the straight segment at uniform speed (linear
 *     precision), which the unhalved form does not give. A face that holds both e1 and e2 (a
 *     boundary corner) gets both terms.
 *   Half-disk charts: a boundary vertex has two sharp (boundary) edges, so its local geometry
 *   is a curve or a point, neither of which reads the chart; no boundary chart is needed.
 *
 * Blending (eq. 5): S = sum_j w_j P_j(z_j), w_j = eta(a_j) eta(b_j). Hermite (the seed):
 * eta(t) = 2t^3 - 3t^2 + 1; C-infinity (Ying-Zorin's kind): eta(t) = g(1-t) / (g(t) + g(1-t)),
 * g(x) = exp(-1/x) for x > 0, else 0, flat to all orders at 0 and 1. Both satisfy
 * eta(t) + eta(1-t) = 1, so the four weights of a face sum to 1 exactly and no division is
 * needed. Derivatives are analytic: the chain rule through the corner coordinates and the
 * conformal chart (dz/dzeta = (4/k) zeta^(4/k - 1) e^(2 pi i h / k)). At a patch vertex itself
 * (zeta = 0), where that derivative vanishes (k < 4) or diverges (k > 4), du and dv are the
 * chart derivatives with (4/k) e^(2 pi i h / k) in its place: their cross product has the
 * direction of the surface normal there (the chart is conformal and keeps orientation).
 * Second derivatives are central differences of the analytic first derivatives (step 2^-17,
 * one-sided at the face border).
 *
 * Tables (seed section V.1): point_data holds nine xyz rows per manifold vertex (the texture
 * of Fig. 8): the patch's C_mn in row 3m + n; a point in row 0; a curve's q0, q1, q2 in rows
 * 0, 1, 2. Per patch: cv = the four corner vertices (row base = 9 * vertex), pcorner = the four
 * corner codes (SFB__MF_CODE: kind, k, h, the axes of e1 and e2 in that face). A kernel then
 * forms Table 2's vector pair per corner ([1 u u^2]/[1 v v^2], [1 0 0]/[1 0 0],
 * [1 0 0]/Bernstein(sigma)) and blends the four points. */

static double sfb__mf_g(double x) { return x > 0.0 ? exp(-1.0 / x) : 0.0; }

/* eta and its derivative (kind: SFB_MANIFOLD_WEIGHTS_*). */
double sfb__mf_eta(int kind, double t, double *dt) {
    if (kind == SFB_MANIFOLD_WEIGHTS_CINF) {
        double a, b, da, db, s;
        if (t <= 0.0) { *dt = 0.0; return 1.0; }
        if (t >= 1.0) { *dt = 0.0; return 0.0; }
        a = sfb__mf_g(1.0 - t); b = sfb__mf_g(t);
        da = a > 0.0 ? -a / ((1.0 - t) * (1.0 - t)) : 0.0; /* d/dt g(1-t) */
        db = b > 0.0 ? b / (t * t) : 0.0;
        s = a + b;
        *dt = (da * b - a * db) / (s * s); /* = (da s - a (da + db)) / s^2 without the cancellation near 0 and 1 */
        return a / s;
    }
    *dt = 6.0 * t * t - 6.0 * t;
    return (2.0 * t - 3.0) * t * t + 1.0;
}

/* One corner's local geometry at its coordinates (a,b): P and dP/da, dP/db. */
static void sfb__mf_local(const float *C, unsigned code, double a, double b, double P[3], double Pa[3], double Pb[3]) {
    int kind = SFB__MF_KIND(code), c;
    if (kind == SFB__MF_POINT) {
        for (c = 0; c < 3; ++c) { P[c] = C[c]; Pa[c] = Pb[c] = 0.0; }
    } else if (kind == SFB__MF_CURVE) {
        int a1 = SFB__MF_A1(code), a2 = SFB__MF_A2(code);
        double p1 = a1 == 1 ? a : a1 == 2 ? b : 0.0, p2 = a2 == 1 ? a : a2 == 2 ? b : 0.0;
        double s = 0.5 * (1.0 - p1 + p2);
        double dsa = 0.5 * ((a2 == 1) - (a1 == 1)), dsb = 0.5 * ((a2 == 2) - (a1 == 2));
        double b0 = (1.0 - s) * (1.0 - s), b1 = 2.0 * s * (1.0 - s), b2 = s * s;
        for (c = 0; c < 3; ++c) {
            double d = 2.0 * ((1.0 - s) * ((double)C[3 + c] - C[c]) + s * ((double)C[6 + c] - C[3 + c]));
            P[c] = b0 * C[c] + b1 * C[3 + c] + b2 * C[6 + c];
            Pa[c] = d * dsa; Pb[c] = d * dsb;
        }
    } else {
        int k = SFB__MF_K(code), h = SFB__MF_H(code), m, n;
        double e = 4.0 / k, phi = 2.0 * SFB__PI * h / k, r = sqrt(a * a + b * b), u, v, Ar, Ai;
        double um[3], vm[3], dum[3], dvm[3], Pu[3], Pv[3];
        if (r > 0.0) {
            double th = atan2(b, a), rz = pow(r, e), ang = e * th + phi, ra = e * pow(r, e - 1.0), angd = (e - 1.0) * th + phi;
            u = rz * cos(ang); v = rz * sin(ang);
            Ar = ra * cos(angd); Ai = ra * sin(angd);
        } else {
            u = v = 0.0;
            Ar = e * cos(phi); Ai = e * sin(phi);
        }
        um[0] = 1.0; um[1] = u; um[2] = u * u; dum[0] = 0.0; dum[1] = 1.0; dum[2] = 2.0 * u;
        vm[0] = 1.0; vm[1] = v; vm[2] = v * v; dvm[0] = 0.0; dvm[1] = 1.0; dvm[2] = 2.0 * v;
        for (c = 0; c < 3; ++c) P[c] = Pu[c] = Pv[c] = 0.0;
        for (m = 0; m < 3; ++m)
            for (n = 0; n < 3; ++n) {
                const float *q = C + 3 * (3 * m + n);
                for (c = 0; c < 3; ++c) {
                    P[c] += um[m] * vm[n] * q[c];
                    Pu[c] += dum[m] * vm[n] * q[c];
                    Pv[c] += um[m] * dvm[n] * q[c];
                }
            }
        /* conformal: d(u,v)/da = (Re A, Im A), d(u,v)/db = (-Im A, Re A) */
        for (c = 0; c < 3; ++c) {
            Pa[c] = Pu[c] * Ar + Pv[c] * Ai;
            Pb[c] = -Pu[c] * Ai + Pv[c] * Ar;
        }
    }
}

/* The blend at face coordinates (c,d): S, dS/dc, dS/dd. pts: point_data; cv: the four corner
 * vertices; codes: their corner codes; kind: SFB_MANIFOLD_WEIGHTS_*. */
void sfb__mf_eval(const float *pts, const int *cv, const unsigned *codes, int kind, double c, double d, double S[3], double Sc[3],
                  double Sd[3]) {
    /* corner j: (a_j, b_j) = o_j + J_j (c, d); J rows (da/dc, da/dd), (db/dc, db/dd) */
    static const double J[4][4] = {{1, 0, 0, 1}, {0, 1, -1, 0}, {-1, 0, 0, -1}, {0, -1, 1, 0}};
    static const double O[4][2] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
    int j, x;
    for (x = 0; x < 3; ++x) S[x] = Sc[x] = Sd[x] = 0.0;
    for (j = 0; j < 4; ++j) {
        double a = O[j][0] + J[j][0] * c + J[j][1] * d, b = O[j][1] + J[j][2] * c + J[j][3] * d;
        double ea, eb, dea, deb, w, wa, wb, P[3], Pa[3], Pb[3];
        ea = sfb__mf_eta(kind, a, &dea);
        eb = sfb__mf_eta(kind, b, &deb);
        w = ea * eb; wa = dea * eb; wb = ea * deb;
        if (w == 0.0 && wa == 0.0 && wb == 0.0) continue;
        sfb__mf_local(pts + 27 * (size_t)cv[j], codes[j], a, b, P, Pa, Pb);
        for (x = 0; x < 3; ++x) {
            double ga = wa * P[x] + w * Pa[x], gb = wb * P[x] + w * Pb[x];
            S[x] += w * P[x];
            Sc[x] += ga * J[j][0] + gb * J[j][2];
            Sd[x] += ga * J[j][1] + gb * J[j][3];
        }
    }
}

/* The ref kernel's MANIFOLD4 evaluation at the patch's (s,t): res[0] position, res[1..2] first
 * derivatives, res[3..5] second derivatives when want2, and the unit normal. */
void sfb__mf_eval_patch(const sfb__patch_table *pt, const float *pts, int patch, double s, double t, int want2, double res[6][3],
                        double nrm[3]) {
    const int *cv = pt->cv + pt->pfirst[patch];
    const unsigned *codes = pt->pcorner + 4 * (size_t)patch;
    int x;
    double len;
    sfb__mf_eval(pts, cv, codes, pt->mf_weights, s, t, res[0], res[1], res[2]);
    nrm[0] = res[1][1] * res[2][2] - res[1][2] * res[2][1];
    nrm[1] = res[1][2] * res[2][0] - res[1][0] * res[2][2];
    nrm[2] = res[1][0] * res[2][1] - res[1][1] * res[2][0];
    len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(len > 1e-300) || !isfinite(len)) {
        /* degenerate tangents: at a point or curve corner, and along edges between point or
         * curve geometries, where the derivative across the edge vanishes (eta'(0) = 0): the
         * normal a step inside the face, 1e-4, or 1e-2 when the C-infinity weights are still
         * flat to double precision there (exp(-1/1e-4) underflows) */
        static const double steps[2] = {1e-4, 1e-2};
        int k;
        for (k = 0; k < 2 && !(len > 1e-300 && isfinite(len)); ++k) {
            double h = steps[k], s2 = s + (s < 0.5 ? h : -h), t2 = t + (t < 0.5 ? h : -h), P[3], A[3], B[3];
            sfb__mf_eval(pts, cv, codes, pt->mf_weights, s2, t2, P, A, B);
            nrm[0] = A[1] * B[2] - A[2] * B[1];
            nrm[1] = A[2] * B[0] - A[0] * B[2];
            nrm[2] = A[0] * B[1] - A[1] * B[0];
            len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        }
    }
    if (len > 0.0 && isfinite(len)) for (x = 0; x < 3; ++x) nrm[x] /= len;
    else nrm[0] = nrm[1] = nrm[2] = 0.0;
    for (x = 0; x < 3; ++x) res[3][x] = res[4][x] = res[5][x] = 0.0;
    if (want2) {
        const double h = 1.0 / 131072.0;
        double s0 = s - h < 0.0 ? s : s - h, s1 = s + h > 1.0 ? s : s + h;
        double t0 = t - h < 0.0 ? t : t - h, t1 = t + h > 1.0 ? t : t + h;
        double P[3], A0[3], B0[3], A1[3], B1[3], C0[3], D0[3], C1[3], D1[3];
        sfb__mf_eval(pts, cv, codes, pt->mf_weights, s0, t, P, A0, B0);
        sfb__mf_eval(pts, cv, codes, pt->mf_weights, s1, t, P, A1, B1);
        sfb__mf_eval(pts, cv, codes, pt->mf_weights, s, t0, P, C0, D0);
        sfb__mf_eval(pts, cv, codes, pt->mf_weights, s, t1, P, C1, D1);
        for (x = 0; x < 3; ++x) {
            res[3][x] = (A1[x] - A0[x]) / (s1 - s0);
            res[4][x] = 0.5 * ((B1[x] - B0[x]) / (s1 - s0) + (C1[x] - C0[x]) / (t1 - t0));
            res[5][x] = (D1[x] - D0[x]) / (t1 - t0);
        }
    }
}

/* ---- construction ---- */

/* Symmetric eigen decomposition of an n x n matrix (Jacobi rotations): a is destroyed, its
 * diagonal the eigenvalues; vec columns the eigenvectors. */
static void sfb__mf_jacobi(double *a, double *vec, int n) {
    int sweep, p, q, i;
    for (i = 0; i < n * n; ++i) vec[i] = (i % (n + 1)) == 0 ? 1.0 : 0.0;
    for (sweep = 0; sweep < 64; ++sweep) {
        double off = 0.0;
        for (p = 0; p < n; ++p) for (q = p + 1; q < n; ++q) off += a[p * n + q] * a[p * n + q];
        if (off < 1e-30) break;
        for (p = 0; p < n; ++p)
            for (q = p + 1; q < n; ++q) {
                double apq = a[p * n + q], th, tt, cs, sn;
                if (fabs(apq) < 1e-300) continue;
                th = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
                tt = (th >= 0.0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                cs = 1.0 / sqrt(tt * tt + 1.0); sn = tt * cs;
                for (i = 0; i < n; ++i) { /* columns p, q */
                    double x = a[i * n + p], y = a[i * n + q];
                    a[i * n + p] = cs * x - sn * y; a[i * n + q] = sn * x + cs * y;
                }
                for (i = 0; i < n; ++i) { /* rows p, q */
                    double x = a[p * n + i], y = a[q * n + i];
                    a[p * n + i] = cs * x - sn * y; a[q * n + i] = sn * x + cs * y;
                }
                for (i = 0; i < n; ++i) {
                    double x = vec[i * n + p], y = vec[i * n + q];
                    vec[i * n + p] = cs * x - sn * y; vec[i * n + q] = sn * x + cs * y;
                }
            }
    }
}

/* The chart position of one-ring point l (0..2k-1: edge neighbour l/2 when l is even, far
 * corner of face l/2 when odd) of a valence-k vertex. */
static void sfb__mf_ring_pos(int k, int l, double *u, double *v) {
    double r = (l & 1) ? pow(2.0, 2.0 / k) : 1.0, ang = 2.0 * SFB__PI * (l / 2) / k + ((l & 1) ? SFB__PI / k : 0.0);
    *u = r * cos(ang); *v = r * sin(ang);
}

/* Pseudo-inverse (8 x 2k, row-major) of the eq. 2 fit of a valence-k vertex: coefficient
 * C_mn (index 3m + n - 1) = sum_l pinv[(3m+n-1) * 2k + l] (p_l - v). Minimum norm where the
 * system is under-determined or rank-deficient. */
sfb_result sfb__mf_pinv(sfb_context *ctx, int k, double **out) {
    int rows = 2 * k, i, j, l, q;
    double *A = NULL, *pinv = NULL, ata[64], vec[64], lmax = 0.0;
    *out = NULL;
    A = (double *)sfb__alloc(ctx, (size_t)rows * 8 * sizeof(double));
    pinv = (double *)sfb__calloc(ctx, (size_t)rows * 8, sizeof(double));
    if (!A || !pinv) { sfb__free(ctx, A); sfb__free(ctx, pinv); return sfb__oom(ctx, "manifold fit"); }
    for (l = 0; l < rows; ++l) {
        double u, v, um[3], vm[3];
        sfb__mf_ring_pos(k, l, &u, &v);
        um[0] = 1.0; um[1] = u; um[2] = u * u; vm[0] = 1.0; vm[1] = v; vm[2] = v * v;
        for (q = 1; q < 9; ++q) A[l * 8 + q - 1] = um[q / 3] * vm[q % 3];
    }
    for (i = 0; i < 8; ++i)
        for (j = 0; j < 8; ++j) {
            double s = 0.0;
            for (l = 0; l < rows; ++l) s += A[l * 8 + i] * A[l * 8 + j];
            ata[i * 8 + j] = s;
        }
    sfb__mf_jacobi(ata, vec, 8);
    for (i = 0; i < 8; ++i) if (ata[i * 9] > lmax) lmax = ata[i * 9];
    /* pinv = V diag(1/lambda) V^T A^T over the kept eigenvalues */
    for (q = 0; q < 8; ++q) {
        double lam = ata[q * 9];
        if (!(lam > 1e-12 * lmax)) continue;
        for (l = 0; l < rows; ++l) {
            double proj = 0.0; /* (V^T A^T)_{q,l} = sum_i vec[i][q] A[l][i] */
            for (i = 0; i < 8; ++i) proj += vec[i * 8 + q] * A[l * 8 + i];
            proj /= lam;
            for (i = 0; i < 8; ++i) pinv[i * rows + l] += vec[i * 8 + q] * proj;
        }
    }
    sfb__free(ctx, A);
    *out = pinv;
    return SFB_SUCCESS;
}

/* Vertex classes. */
static int sfb__mf_vertex_kind(const sfb__level *l, int v, int *e1, int *e2) {
    int e0 = l->ve_off[v], ne = l->ve_off[v + 1] - e0, nf = l->vf_off[v + 1] - l->vf_off[v], i, n = 0;
    *e1 = *e2 = -1;
    if (nf == 0 || ne == 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD) || !(nf == ne || nf == ne - 1) || l->vs[v] > 0.0f) return SFB__MF_POINT;
    for (i = 0; i < ne; ++i)
        if (l->es[l->ve[e0 + i]] > 0.0f) {
            if (n == 0) *e1 = i;
            else if (n == 1) *e2 = i;
            n++;
        }
    if (n == 0) return nf == ne && !(l->vtag[v] & SFB__TAG_BOUNDARY) ? SFB__MF_PATCH : SFB__MF_POINT;
    if (n == 2) return SFB__MF_CURVE;
    return SFB__MF_POINT;
}

/* The corner code of slot `slot` of face f. */
static unsigned sfb__mf_corner_code(const sfb__level *l, const unsigned char *kind, const int *ev1, const int *ev2, int f, int slot) {
    int v = l->fv[l->fv_off[f] + slot], i, h = -1, k, ne, a1 = 0, a2 = 0;
    for (i = l->vf_off[v]; i < l->vf_off[v + 1]; ++i)
        if (l->vf[i] == f && l->vf_slot[i] == slot) { h = i - l->vf_off[v]; break; }
    k = l->vf_off[v + 1] - l->vf_off[v];
    ne = l->ve_off[v + 1] - l->ve_off[v];
    if (kind[v] == SFB__MF_POINT || h < 0) return SFB__MF_CODE(SFB__MF_POINT, 0, 0, 0, 0);
    if (kind[v] == SFB__MF_CURVE) {
        int ea = h, eb = (h + 1) % ne; /* edges of face h: its a and b axes */
        a1 = ev1[v] == ea ? 1 : ev1[v] == eb ? 2 : 0;
        a2 = ev2[v] == ea ? 1 : ev2[v] == eb ? 2 : 0;
        return SFB__MF_CODE(SFB__MF_CURVE, k, h, a1, a2);
    }
    return SFB__MF_CODE(SFB__MF_PATCH, k, h, 0, 0);
}

/* The manifold mesh L and its positions P (double, xyz): the base itself when every face is a
 * quad, else one Catmull-Clark step of it into work/lev1/T with sharp edges and vertices
 * carried as infinitely sharp (*refined = 1). */
static sfb_result sfb__mf_manifold_mesh(sfb_context *ctx, const sfb__level *base, const float *positions, sfb__level *work,
                                        sfb__level *lev1, sfb__stencils *T, const sfb__level **L_out, double **P_out, int *refined) {
    const sfb__level *L;
    double *P;
    sfb_result r;
    int quads = 1, f, v, i, c;
    for (f = 0; f < base->nf; ++f) if (base->fv_off[f + 1] - base->fv_off[f] != 4) quads = 0;
    if (quads) {
        *L_out = base;
        P = *P_out = (double *)sfb__alloc(ctx, ((size_t)base->nv + 1) * 3 * sizeof(double));
        if (!P) return sfb__oom(ctx, "manifold patch table");
        for (i = 0; i < 3 * base->nv; ++i) P[i] = positions[i];
    } else {
        /* one Catmull-Clark step, sharp edges and vertices carried as infinitely sharp */
        sfb__refine_options o;
        int e;
        *refined = 1;
        if ((r = sfb__level_prepare(ctx, base, 0, 0, work)) != SFB_SUCCESS) return r;
        for (e = 0; e < work->ne; ++e) if (work->es[e] > 0.0f) work->es[e] = SFB_SHARPNESS_INFINITE;
        for (v = 0; v < work->nv; ++v) if (work->vs[v] > 0.0f) work->vs[v] = SFB_SHARPNESS_INFINITE;
        sfb__level_compute_rules(work);
        memset(&o, 0, sizeof o);
        o.scheme = SFB_SCHEME_CATMARK;
        if ((r = sfb__refine(ctx, work, &o, 1, lev1, T, NULL, 0.0f, 0.5f)) != SFB_SUCCESS) return r;
        L = *L_out = lev1;
        P = *P_out = (double *)sfb__calloc(ctx, ((size_t)L->nv + 1) * 3, sizeof(double));
        if (!P) return sfb__oom(ctx, "manifold patch table");
        for (v = 0; v < T->rows; ++v)
            for (i = 0; i < T->sizes[v]; ++i) {
                int src = T->indices[T->offsets[v] + i];
                double w = T->weights[T->offsets[v] + i];
                for (c = 0; c < 3; ++c) P[3 * (size_t)v + c] += w * positions[3 * (size_t)src + c];
            }
    }
    return SFB_SUCCESS;
}

/* The local geometry of every vertex of L into pt->point_data (nine xyz rows each: a point, a
 * crease curve or the fitted bi-quadratic patch), its kind and sharp edges into kind/ev1/ev2;
 * pinv caches the pseudo-inverse of each valence. */
static sfb_result sfb__mf_local_geometry(sfb_context *ctx, const sfb__level *L, const double *P, unsigned char *kind, int *ev1,
                                         int *ev2, double **pinv, sfb__patch_table *pt) {
    sfb_result r;
    int v, i, c;
    for (v = 0; v < L->nv; ++v) {
        float *C = pt->point_data + 27 * (size_t)v;
        int k = L->vf_off[v + 1] - L->vf_off[v], e0 = L->ve_off[v];
        kind[v] = (unsigned char)sfb__mf_vertex_kind(L, v, &ev1[v], &ev2[v]);
        for (c = 0; c < 3; ++c) C[c] = (float)P[3 * (size_t)v + c];
        if (kind[v] == SFB__MF_CURVE) {
            int qa = sfb__other_end(L, L->ve[e0 + ev1[v]], v), qb = sfb__other_end(L, L->ve[e0 + ev2[v]], v);
            for (c = 0; c < 3; ++c) {
                C[c] = (float)P[3 * (size_t)qa + c];
                C[3 + c] = (float)P[3 * (size_t)v + c];
                C[6 + c] = (float)P[3 * (size_t)qb + c];
            }
        } else if (kind[v] == SFB__MF_PATCH) {
            const double *M;
            int q;
            if (k > SFB_MAX_VALENCE) { kind[v] = SFB__MF_POINT; continue; }
            if (!pinv[k] && (r = sfb__mf_pinv(ctx, k, &pinv[k])) != SFB_SUCCESS) return r;
            M = pinv[k];
            for (q = 1; q < 9; ++q) {
                double acc[3] = {0.0, 0.0, 0.0};
                for (i = 0; i < 2 * k; ++i) {
                    int g = L->vf[L->vf_off[v] + i / 2], gs = L->vf_slot[L->vf_off[v] + i / 2];
                    int nb = (i & 1) ? L->fv[L->fv_off[g] + (gs + 2) % 4] : sfb__other_end(L, L->ve[e0 + i / 2], v);
                    for (c = 0; c < 3; ++c) acc[c] += M[(q - 1) * 2 * k + i] * (P[3 * (size_t)nb + c] - P[3 * (size_t)v + c]);
                }
                for (c = 0; c < 3; ++c) C[3 * q + c] = (float)acc[c];
            }
        }
    }
    return SFB_SUCCESS;
}

/* Counts the param faces, patches and quadtree nodes of the base faces and allocates the
 * patch table's arrays for them. */
static sfb_result sfb__mf_alloc_patches(sfb_context *ctx, const sfb__level *base, int refined, sfb__patch_table *pt) {
    int f, nptex = 0, npatch = 0, nnodes = 0;
    pt->face_ptex = (int *)sfb__alloc(ctx, ((size_t)base->nf + 1) * sizeof(int));
    if (!pt->face_ptex) return sfb__oom(ctx, "manifold patch table");
    for (f = 0; f < base->nf; ++f) {
        int n = base->fv_off[f + 1] - base->fv_off[f];
        pt->face_ptex[f] = nptex;
        nptex += n == 4 ? 1 : n;
        if (!base->fhole[f]) { npatch += refined ? n : 1; nnodes += refined && n == 4; }
    }
    pt->face_ptex[base->nf] = nptex;
    pt->nptex = nptex; pt->npatch = npatch; pt->nnodes = nnodes; pt->ncv = 4 * npatch;
    pt->max_depth = refined && nnodes > 0 ? 1 : 0;
    pt->ptex_face = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_corner = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->ptex_root = (int *)sfb__alloc(ctx, ((size_t)nptex + 1) * sizeof(int));
    pt->nodes = (int *)sfb__alloc(ctx, ((size_t)nnodes + 1) * 4 * sizeof(int));
    pt->ptype = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(int));
    pt->pfirst = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(int));
    pt->pparam = (unsigned *)sfb__alloc(ctx, ((size_t)npatch + 1) * sizeof(unsigned));
    pt->pvalence = (int *)sfb__calloc(ctx, (size_t)npatch + 1, sizeof(int));
    pt->cv = (int *)sfb__alloc(ctx, ((size_t)npatch + 1) * 4 * sizeof(int));
    pt->pcorner = (unsigned *)sfb__alloc(ctx, ((size_t)npatch + 1) * 4 * sizeof(unsigned));
    if (!pt->ptex_face || !pt->ptex_corner || !pt->ptex_root || !pt->nodes || !pt->ptype || !pt->pfirst || !pt->pparam || !pt->pvalence ||
        !pt->cv || !pt->pcorner)
        return sfb__oom(ctx, "manifold patch table");
    return SFB_SUCCESS;
}

/* Fills the param faces, quadtree nodes and MANIFOLD4 patches (control vertices and corner
 * codes) of every base face: one patch per quad, or one per child quad when L is refined. */
static void sfb__mf_fill_patches(const sfb__level *base, const sfb__level *L, int refined, const unsigned char *kind, const int *ev1,
                                 const int *ev2, sfb__patch_table *pt) {
    int p = 0, node = 0, f, i, j, npatch = pt->npatch;
    for (f = 0; f < base->nf; ++f) {
        int n = base->fv_off[f + 1] - base->fv_off[f], k0 = pt->face_ptex[f];
        for (i = 0; i < (n == 4 ? 1 : n); ++i) {
            pt->ptex_face[k0 + i] = f;
            pt->ptex_corner[k0 + i] = n == 4 ? -1 : i;
            pt->ptex_root[k0 + i] = -1;
        }
        if (base->fhole[f]) continue;
        if (!refined) {
            pt->ptex_root[k0] = -(p + 2);
            pt->pparam[p] = SFB__PARAM(0, 0, 0, 0);
            for (j = 0; j < 4; ++j) {
                pt->cv[4 * p + j] = L->fv[L->fv_off[f] + j];
                pt->pcorner[4 * p + j] = sfb__mf_corner_code(L, kind, ev1, ev2, f, j);
            }
            pt->ptype[p] = SFB__PATCH_MANIFOLD4; pt->pfirst[p] = 4 * p;
            p++;
            continue;
        }
        /* child quad i of base face f is refined face fv_off[f] + i, its slot 0 at the
         * corner v_i (v_i, mid(v_i,v_i+1), centroid, mid(v_i-1,v_i)) */
        if (n == 4) pt->ptex_root[k0] = node;
        for (i = 0; i < n; ++i) {
            int g = base->fv_off[f] + i, s0 = n == 4 ? (4 - i) % 4 : 0;
            static const int qx[4] = {0, 1, 1, 0}, qy[4] = {0, 0, 1, 1};
            if (n == 4) {
                pt->nodes[4 * node + qx[i] + 2 * qy[i]] = -(p + 2);
                pt->pparam[p] = SFB__PARAM(1, qx[i], qy[i], 0);
            } else {
                pt->ptex_root[k0 + i] = -(p + 2);
                pt->pparam[p] = SFB__PARAM(0, 0, 0, 0);
            }
            for (j = 0; j < 4; ++j) {
                int slot = (s0 + j) % 4;
                pt->cv[4 * p + j] = L->fv[L->fv_off[g] + slot];
                pt->pcorner[4 * p + j] = sfb__mf_corner_code(L, kind, ev1, ev2, g, slot);
            }
            pt->ptype[p] = SFB__PATCH_MANIFOLD4; pt->pfirst[p] = 4 * p;
            p++;
        }
        if (n == 4) node++;
    }
    pt->pfirst[npatch] = 4 * npatch;
}

sfb_result sfb__manifold_build(sfb_context *ctx, const sfb__level *base, int weights, const float *positions, sfb__patch_table *pt) {
    sfb__level work, lev1;
    const sfb__level *L = NULL;
    sfb__stencils T;
    double *P = NULL, **pinv = NULL;
    unsigned char *kind = NULL;
    int *ev1 = NULL, *ev2 = NULL;
    int i, refined = 0;
    sfb_result r = SFB_SUCCESS;
    memset(pt, 0, sizeof *pt);
    memset(&work, 0, sizeof work); memset(&lev1, 0, sizeof lev1); memset(&T, 0, sizeof T);
    if (weights != SFB_MANIFOLD_WEIGHTS_HERMITE && weights != SFB_MANIFOLD_WEIGHTS_CINF)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "manifold weights %d are not SFB_MANIFOLD_WEIGHTS_HERMITE or _CINF", weights);
    pt->domain = SFB__DOMAIN_QUAD;
    pt->mf_weights = weights;
    if ((r = sfb__mf_manifold_mesh(ctx, base, positions, &work, &lev1, &T, &L, &P, &refined)) != SFB_SUCCESS) goto done;
    /* local geometries */
    kind = (unsigned char *)sfb__alloc(ctx, (size_t)L->nv + 1);
    ev1 = (int *)sfb__alloc(ctx, ((size_t)L->nv + 1) * sizeof(int));
    ev2 = (int *)sfb__alloc(ctx, ((size_t)L->nv + 1) * sizeof(int));
    pt->point_data = (float *)sfb__calloc(ctx, (size_t)L->nv * 27 + 1, sizeof(float));
    pinv = (double **)sfb__calloc(ctx, SFB_MAX_VALENCE + 1, sizeof(double *));
    if (!kind || !ev1 || !ev2 || !pt->point_data || !pinv) { r = sfb__oom(ctx, "manifold patch table"); goto done; }
    pt->npoints = 9 * L->nv;
    if ((r = sfb__mf_local_geometry(ctx, L, P, kind, ev1, ev2, pinv, pt)) != SFB_SUCCESS) goto done;
    /* param faces and patches */
    if ((r = sfb__mf_alloc_patches(ctx, base, refined, pt)) != SFB_SUCCESS) goto done;
    sfb__mf_fill_patches(base, L, refined, kind, ev1, ev2, pt);
    pt->counts[SFB__PATCH_MANIFOLD4] = pt->npatch;
done:
    if (pinv) { for (i = 0; i <= SFB_MAX_VALENCE; ++i) sfb__free(ctx, pinv[i]); sfb__free(ctx, pinv); }
    sfb__free(ctx, kind); sfb__free(ctx, ev1); sfb__free(ctx, ev2); sfb__free(ctx, P);
    sfb__level_free(ctx, &work); sfb__level_free(ctx, &lev1); sfb__stencils_free(ctx, &T);
    if (r != SFB_SUCCESS) sfb__patch_table_free(ctx, pt);
    return r;
}
