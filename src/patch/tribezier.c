/* Quartic triangular Bezier surfaces with a sharpness slider (SFB_SCHEME_TRIBEZIER, seed 004;
 * ALGORITHMS.md sections 5 and 8). One quartic Bezier triangle (15 points) per mesh triangle,
 * emitted as the BEZIER_TRI15 patches the Loop work evaluates, so eval, tessellation, trimming,
 * rendering and the glTF export run on every backend unchanged.
 *
 * The construction, and the choices the seed leaves open:
 *   - the control net is global: one point per vertex (b400), three per edge (b310, b220, b130),
 *     three per triangle (b211, b121, b112), so neighbouring patches share their boundary points
 *     and the surface is closed (C0) by construction, for every s.
 *   - two nets are built from the mesh: the smooth one (s = 0) and the sharp one (s = 1, every
 *     tagged feature sharp); the surface at s is (1 - s) smooth + s sharp point by point (seed
 *     section 4, ALGORITHMS.md 8.5: every Bezier point of the mesh extension is linear in s).
 *     Where creases carry different s, a point takes the s of the nearest feature (graph distance
 *     over mesh edges; at a feature vertex the mean of its features' s, averaged over the point's
 *     home vertices: its corner, its edge's ends, its triangle's corners); for one s everywhere
 *     the blend is exact. The nets depend on which features there are, not on their s (a
 *     feature at s = 0 is still one: tbz_tag_values), so the slider (tribezier.slider) keeps
 *     both nets in float and how each point's s follows from the base mesh's tags
 *     (sfb__tbz_features: the edges and corners each vertex's s is taken from, mapped back
 *     through the split and the Loop steps), and sfb_surface_set_sharpness and
 *     sfb_surface_set_feature_sharpness blend them again (sfb__tribezier_blend): the build with
 *     the slider takes its points' s the same way and blends from the float nets too (and
 *     builds both nets where s = 1 everywhere), so a move is bit for bit a fresh build with the
 *     slider; without it, within a float rounding of one.
 *   - regular vertices (valence 6, or a crease/boundary vertex with three triangles on each
 *     side) take Sabin's rules (seed eq. 4-7, ALGORITHMS.md 8.1) on the mesh extended across
 *     sharp edges by parallelograms (seed eq. 8 at s = 1: the phantom across wall edge (a, b) is
 *     a + b - the near-side opposite vertex). There the surface is the Loop limit surface, and
 *     a regular sharp crease is Loop's crease: the degree-raised cubic B-spline of its vertices.
 *   - sharp edges (in the sharp net every tagged edge with s > 0, in both nets every boundary
 *     edge) whose ends are crease or corner vertices are fixed to that cubic B-spline (a corner
 *     is interpolated, its phantom 2V - N), in both neighbours' patches.
 *   - G1 at extraordinary vertices: ALGORITHMS.md 8.4's polynomial construction (S2), generalised.
 *     Chosen over 8.3's Gregory triangle because it stays a polynomial BEZIER_TRI15 patch (no new
 *     kernel family on every backend) and because its constraints are linear, so creases,
 *     corners and boundaries enter it as more constraints rather than as separate cases. Every
 *     Bezier point within net distance TBZ_REACH of an irregular vertex is an unknown; per
 *     interior edge that is not sharp in the net being built, the five quartic Bernstein
 *     coefficients of mu(t) X(t) + nu(t) Y(t) - lambda(t) T(t) vanish (X, Y: derivatives of the
 *     two patches towards their opposite vertices, T along the edge), mu, nu, lambda linear in t
 *     with their end values from the characteristic angles of the two end vertices (below); the
 *     smallest change of the unknowns (least squares: the minimum-norm solution) that satisfies
 *     them is applied, per connected component of the constraints: a component around one
 *     extraordinary vertex whose shape is met twice or more by a dense solve made once per shape
 *     (tbz_templates), every other by CGLS from zero (on a compact copy of its rows, three
 *     coordinates at once; see tbz_cgls for when it stops). Regular regions are untouched, so
 *     they stay Loop's. Where extraordinary vertices of different valences touch, the
 *     constraints have no exact solution on the mesh itself; the net is then built on the mesh
 *     after one Loop step (Peters' remedy; tbz_refine: the smooth net's positions by Loop's
 *     smooth rules, the sharp net's with its features sharp), four patches per triangle, or after
 *     two, sixteen (sfb__tribezier_build), and is exactly G1 again (tests/tribezier.c,
 *     touching_evs). Two steps where extraordinary vertices come in large groups joined by
 *     edges (tbz_largest_group): after one step the regions of unknowns around a group's
 *     vertices (two edges apart then) overlap and merge into one component, of up to half a
 *     million unknowns on real meshes (cow.obj: 42,000; 500-680 CGLS iterations each, 0.9-1.2 s
 *     to build); after two, every extraordinary vertex is four edges from the next, its component
 *     is its own and of a shape met hundreds of times (cow: 1,447 components, 11 shapes), so the
 *     templates solve them all (bench: cow 189 -> 42-64 ms per 1,000 triangles). One step too
 *     where the mesh is too coarse for the construction (TBZ_COVER: the solve may move more than
 *     half of a net's points, and its waves crossed whole faces).
 *   - characteristic angles phi (the angle each triangle takes at a vertex): 2 pi / n at a
 *     smooth vertex (and at a dart, and at a vertex with only a corner tag); a sector between two
 *     sharp edges with k triangles spans pi at a crease or boundary vertex (its two crease
 *     tangents opposite, as the B-spline's are), and at a corner the angle between its two sharp
 *     edges (clamped to [pi/8, 7 pi/8]).
 *   - the seed's open problem (section 5, undulation at s = 0.5 near an extraordinary crease
 *     vertex): in the smooth net an irregular crease vertex keeps the sector angles (pi each
 *     side) and is given the crease B-spline's tangents, so its tangent plane contains the
 *     crease tangents; its corner point is the B-spline's point moved by the mean offset of its
 *     crease neighbours' smooth points from their B-spline points, so the smooth crease curve
 *     runs on at the height and side the smooth surface has along the crease (pinned to the
 *     B-spline point it dipped there: the in-plane undulation was 0.11 mean edges at s = 0.25,
 *     then 0.0014-0.0023, the seed's kind 0.008-0.016; tests/tribezier.c). The G1 solve still
 *     bent that curve (six curvature sign changes within two edges of the vertex), so the
 *     smooth net is solved a second time with the crease's points weighted and held to a
 *     parabola fitted to the first pass's, and the change along the crease's normal taken from
 *     that solve (tbz_crease_points, tbz_crease_fit, tbz_mix), where it bends the net at most
 *     3 % more (tbz_take_second): no sign change left on the issue's meshes, height range below
 *     5e-5 mean edges, the surface's curvature energy within 1.4 %. The crease's place across
 *     itself is held too (a parabola in the lateral direction, fitted the same way) where that
 *     costs the surface's curvature energy at most 1 % more: where the mesh's rows lie at the
 *     same heights on both sides (Loop's limit then in the crease's vertical plane), the crease
 *     curve stays within 1.6e-4 mean edges of that plane at valence 5 and 7 (it bent 0.0017 and
 *     0.0049 off it at s = 0.25; seed's kind 0.063, 0.045).
 *     Where our plane leaves the rows around a vertex unmet or a patch corner beside it
 *     degenerate, that vertex alone gets the seed's plane (tbz_ours_bad; it was the whole net).
 *     (SFB__TBZ_SEED_PLANE builds the seed's kind everywhere, the smooth net ignoring the
 *     crease, and SFB__TBZ_NO_STRAIGHT ours in one pass, for the measurements in bench/tests.)
 *   - darts: in the sharp net the dart vertex stays smooth (uniform angles, a Loop-limit corner);
 *     the dart edge is C0 only (no G1 constraint) and is not fixed to a B-spline, so the crease
 *     fades out at the dart.
 *   - corners (a `t corner` tag, or three or more sharp edges; a boundary vertex with one
 *     triangle): the sharp net interpolates the vertex (b400 = V), each sector G1 in itself
 *     (the seed's eq. 9 blend is replaced by the constraint solve, which covers every valence).
 *     A corner tag on a vertex with no sharp edge (or one: a dart) keeps the smooth vertex's
 *     tangents (8.2) around V, so the surface stays G1 through it: the cone point that the tag
 *     makes in Loop's limit would need a normal jump along every spoke, which the tangents along
 *     the spokes had (0.2-0.5 rad on tests/tribezier.c's corner_only bump).
 *   - non-manifold vertices (sheets touching at a vertex): one vertex per fan of triangles, each
 *     sheet built as a manifold mesh of its own through the vertex, a corner (tbz_split).
 *   - refused: faces that are not triangles (split them first: the choice of diagonal is the
 *     modeller's), non-manifold edges, degenerate triangles (area below 1e-12 of the squared
 *     bounding-box diagonal), non-finite positions, an override s outside [0, 1] or NaN.
 * Param faces are the triangles, (u,v) barycentric as Loop's: (1-u-v) P0 + u P1 + v P2. */

#define TBZ_USIN 32  /* valences below this have their uniform sines made once (tbz_usin) */
#define TBZ_OURS_RESIDUAL 1e-10 /* a row left above this around our crease vertex: the seed's plane there (tbz_ours_bad) */
#define TBZ_REACH 6   /* net distance of the unknowns from an irregular vertex (ALGORITHMS.md 8.4) */
#define TBZ_PI 3.14159265358979323846

enum { TBZ_SMOOTH = 0, TBZ_DART, TBZ_CREASE, TBZ_CORNER };

typedef struct sfb__tbz {
    sfb_context *ctx;
    const sfb__level *l;
    const float *pos;
    int nv, ne, nf, np;
    int seed_plane;
    unsigned flags;            /* SFB__TBZ_* */
    int par_unknowns;          /* components of this many unknowns or more: each iteration's loops on the threads */
    /* progress (stage "tribezier", tbz_progress): this solve's window [p0, p1], the value last
     * reported (never less after), and the solve's work (entries of its components' rows): all,
     * done, and the large component being solved */
    float p0, p1, plast;
    double pbase;              /* the share of the solve the templates did (tbz_templates): CGLS reports over the rest */
    double work_all, work_done, work_cur;
    /* per state */
    int sharp;                 /* building the sharp net */
    unsigned char *efeat;      /* per edge: sharp in this net */
    unsigned char *vtype;      /* per vertex */
    unsigned char *virr;       /* per vertex: irregular in this net */
    double *phi;               /* per vertex-face (vf order): characteristic angle */
    double *x;                 /* np * 3: the net */
    unsigned char *fixed;      /* per point */
    int *dist;                 /* per point: net distance to an irregular vertex */
    int *grid;                 /* per face: its 15 points (tbz_patch), made once (the topology is the same in every
                                  state) */
    float *tag_s;              /* per edge: s of a tagged edge (0: none) */
    float *corner_s;           /* per vertex: s of a corner tag (0: none) */
    /* the seed-plane fallback of the smooth net: the first (our-plane) solution and its vertices
     * of type CREASE | 16; components of the constraints away from those are the same systems in
     * both nets, so their solution is copied rather than solved again */
    const double *reuse_x;
    const unsigned char *reuse_ours;
    const double *straight_x;  /* the smooth net's second pass: the first's net (tbz_crease_points, tbz_mix) */
    /* per vertex: built with the seed's plane in the smooth net, though others have ours (NULL:
     * none; tbz_ours_bad) */
    unsigned char *seed_v;
    /* per vertex, written by the smooth net's solve where not NULL: ours, and a row of its
     * component left unmet (tbz_solve) */
    unsigned char *bad_v;
    /* the smooth net's solve recorded for the sharp net (tbz_prev): rec while building the
     * smooth net, prev while building the sharp one */
    struct tbz_prev *rec;
    const struct tbz_prev *prev;
    double scale;              /* the mesh's largest coordinate (of the smooth net's positions): the solves' stopping
                                  and residuals are relative to it, the same in both nets (so that their systems can
                                  be compared: tbz_prev); it was the net's own largest point, which differs between
                                  the nets by their sharp points */
    sfb__tbz_stats st;
    double usin[TBZ_USIN][2]; /* per valence n: sin(2 pi / n) and sin(4 pi / n) as tbz_coef computes them (tbz_usin) */
} sfb__tbz;

/* T->usin: what tbz_coef would compute at a spoke with the uniform angles 2 pi / n of a smooth
 * vertex on both sides, the same bits (six sines per edge of rows were a sixth of their time) */
static void tbz_usin(sfb__tbz *T) {
    int n;
    T->usin[0][0] = T->usin[0][1] = 0.0;
    for (n = 1; n < TBZ_USIN; ++n) {
        const double a = 2.0 * TBZ_PI / n;
        T->usin[n][0] = sin(a);
        T->usin[n][1] = sin(a + a);
    }
}

static int tbz_vp(const sfb__tbz *T, int v) { (void)T; return v; }
static int tbz_ep(const sfb__tbz *T, int e, int q) { return T->nv + 3 * e + q; }
static int tbz_fp(const sfb__tbz *T, int f, int k) { return T->nv + 3 * T->ne + 3 * f + k; }

/* The 15 global indices of triangle f in our patch order (row by row in v, u rising; position
 * (i, j) has weights 4 - i - j, i, j on corners 0, 1, 2): a corner's vertex point, an edge's
 * three points in the edge's direction, a face point per corner (weight 2). */
static void tbz_patch(const sfb__tbz *T, int f, int g[15]) {
    static const int eq[3][3] = {{1, 2, 3}, {8, 11, 13}, {12, 9, 5}}; /* edge k's points, fv[k]'s weight 3, 2, 1 */
    const sfb__level *l = T->l;
    const int *fv = l->fv + l->fv_off[f], *fe = l->fe + l->fv_off[f];
    int k, q;
    g[0] = tbz_vp(T, fv[0]); g[4] = tbz_vp(T, fv[1]); g[14] = tbz_vp(T, fv[2]);
    for (k = 0; k < 3; ++k) {
        const int e = fe[k], fwd = l->ev[2 * e] == fv[k];
        for (q = 0; q < 3; ++q) g[eq[k][q]] = tbz_ep(T, e, fwd ? q : 2 - q);
    }
    g[6] = tbz_fp(T, f, 0); g[7] = tbz_fp(T, f, 1); g[10] = tbz_fp(T, f, 2);
}

static int tbz_qij(int i, int j) { return 5 * j - j * (j - 1) / 2 + i; }
/* The global index of the point of triangle f with weights w[k] on its corner k (sum 4), from
 * the faces' grids (T->grid, made once per net by tbz_patch). */
static int tbz_gpt(const sfb__tbz *T, int f, const int w[3]) { return T->grid[15 * (size_t)f + tbz_qij(w[1], w[2])]; }
/* The lattice place (tbz_qij order) of the point with weights w[r] = 4 - i - j, w[r + 1] = i,
 * w[r + 2] = j, where q = tbz_qij(i, j): place q of the frame turned to start at corner r. */
static int tbz_rot_q(int r, int q) {
    static const signed char tab[3][15] = {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14},
                                           {4, 8, 11, 13, 14, 3, 7, 10, 12, 2, 6, 9, 1, 5, 0},
                                           {14, 12, 9, 5, 0, 13, 10, 6, 1, 11, 7, 2, 8, 3, 4}};
    return tab[r][q];
}

static int tbz_ring(const sfb__level *l, int v, int j) { return sfb__other_end(l, l->ve[l->ve_off[v] + j], v); }
static int tbz_nf(const sfb__level *l, int v) { return l->vf_off[v + 1] - l->vf_off[v]; }
static int tbz_boundary(const sfb__level *l, int v) { return l->ve_off[v + 1] - l->ve_off[v] > tbz_nf(l, v); }
/* Is v an extraordinary crease vertex with our plane in the current (smooth) net? */
static int tbz_ours(const sfb__tbz *T, int v) { return T->vtype[v] == (TBZ_CREASE | 16) && T->virr[v]; }

static void tbz_get(const sfb__tbz *T, int v, double out[3]) {
    out[0] = T->pos[3 * (size_t)v]; out[1] = T->pos[3 * (size_t)v + 1]; out[2] = T->pos[3 * (size_t)v + 2];
}
static void tbz_axpy(double *y, double a, const double *x) { y[0] += a * x[0]; y[1] += a * x[1]; y[2] += a * x[2]; }

/* The spoke slot of edge e in v's ring. */
static int tbz_spoke(const sfb__level *l, int v, int e) {
    int i;
    for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i)
        if (l->ve[i] == e) return i - l->ve_off[v];
    return -1;
}

/* The two sharp neighbours of a crease vertex (first and last sharp spoke). */
static void tbz_crease_pair(const sfb__tbz *T, int v, int *a, int *b) {
    const sfb__level *l = T->l;
    int i, m = l->ve_off[v + 1] - l->ve_off[v];
    *a = *b = -1;
    for (i = 0; i < m; ++i)
        if (T->efeat[l->ve[l->ve_off[v] + i]] || ((T->vtype[v] & 16) && T->tag_s[l->ve[l->ve_off[v] + i]] > 0.0f)) {
            if (*a < 0) *a = tbz_ring(l, v, i);
            else *b = tbz_ring(l, v, i);
        }
}

/* Corner point of the sharp crease curve at v: (A + 4V + B)/6 at a crease vertex, V at a corner. */
static void tbz_crease_point(const sfb__tbz *T, int v, int type, double P[3]) {
    double V[3], A[3], B[3];
    int a, b, c;
    tbz_get(T, v, V);
    if (type != TBZ_CREASE) { memcpy(P, V, sizeof V); return; }
    tbz_crease_pair(T, v, &a, &b);
    tbz_get(T, a, A); tbz_get(T, b, B);
    for (c = 0; c < 3; ++c) P[c] = (A[c] + 4.0 * V[c] + B[c]) / 6.0;
}

/* Classifies the vertices of the net being built and sets their characteristic angles. */
static void tbz_classify(sfb__tbz *T) {
    const sfb__level *l = T->l;
    int v, e, j;
    for (e = 0; e < T->ne; ++e) {
        const int bnd = l->ef_off[e + 1] - l->ef_off[e] == 1;
        T->efeat[e] = (unsigned char)(bnd || (T->sharp && T->tag_s[e] > 0.0f));
    }
    for (v = 0; v < T->nv; ++v) {
        const int n = tbz_nf(l, v), m = l->ve_off[v + 1] - l->ve_off[v], bnd = tbz_boundary(l, v);
        int nfeat = 0, ntag = 0, type, irr = 0;
        double *phi = T->phi + l->vf_off[v];
        for (j = 0; j < m; ++j) {
            const int ej = l->ve[l->ve_off[v] + j];
            nfeat += T->efeat[ej];
            ntag += T->tag_s[ej] > 0.0f && l->ef_off[ej + 1] - l->ef_off[ej] == 2;
        }
        if (n == 0) { T->vtype[v] = TBZ_SMOOTH; T->virr[v] = 0; continue; }
        if (bnd && n == 1) type = TBZ_CORNER;
        else if (nfeat >= 3 || (T->sharp && T->corner_s[v] > 0.0f && nfeat >= 2)) type = TBZ_CORNER;
        else if (nfeat == 2) type = TBZ_CREASE;
        else if (nfeat == 1) type = TBZ_DART;
        else type = TBZ_SMOOTH;
        /* the smooth net at a tagged crease vertex: our tangent plane through the crease tangents */
        if (!T->sharp && !T->seed_plane && !(T->seed_v && T->seed_v[v]) && type == TBZ_SMOOTH && ntag == 2 && !(T->corner_s[v] > 0.0f))
            type = TBZ_CREASE + 16;
        T->vtype[v] = (unsigned char)type;
        if (type == TBZ_SMOOTH || type == TBZ_DART) {
            for (j = 0; j < n; ++j) phi[j] = 2.0 * TBZ_PI / n;
            irr = n != 6 || type == TBZ_DART || (T->sharp && T->corner_s[v] > 0.0f);
        } else {
            /* sectors between sharp (or, type CREASE + 16, tagged) spokes */
            int first = -1, k, start, cnt;
            for (j = 0; j < m; ++j) {
                const int ej = l->ve[l->ve_off[v] + j];
                if (type == TBZ_CREASE + 16 ? T->tag_s[ej] > 0.0f : T->efeat[ej]) { first = j; break; }
            }
            start = first;
            irr = (type == TBZ_CORNER);
            for (cnt = 0; cnt < n;) {
                /* the sector from spoke `start`: faces start, start+1, ... until the next sharp spoke */
                double span, V[3], A[3], B[3], la = 0, lb = 0, d = 0;
                int end = start, c;
                k = 0;
                do {
                    int ej;
                    ++k;
                    end = (end + 1) % m;
                    ej = l->ve[l->ve_off[v] + end];
                    if (type == TBZ_CREASE + 16 ? T->tag_s[ej] > 0.0f : T->efeat[ej]) break;
                } while (cnt + k < n);
                if (type == TBZ_CORNER) {
                    tbz_get(T, v, V); tbz_get(T, tbz_ring(l, v, start), A); tbz_get(T, tbz_ring(l, v, end), B);
                    for (c = 0; c < 3; ++c) {
                        A[c] -= V[c]; B[c] -= V[c];
                        la += A[c] * A[c]; lb += B[c] * B[c]; d += A[c] * B[c];
                    }
                    span = acos(fmax(-1.0, fmin(1.0, d / sqrt(la * lb + 1e-300))));
                    span = fmin(fmax(span, TBZ_PI / 8), 7 * TBZ_PI / 8);
                } else {
                    span = TBZ_PI;
                }
                for (j = 0; j < k; ++j) phi[(start + j) % n] = span / k;
                if (k != 3) irr = 1;
                cnt += k;
                start = end;
            }
            /* ours, regular (three triangles a side): the plain smooth vertex */
            if (type == TBZ_CREASE + 16) T->vtype[v] = (unsigned char)(irr ? (TBZ_CREASE | 16) : TBZ_SMOOTH);
        }
        T->virr[v] = (unsigned char)irr;
    }
}

/* The ring of regular vertex v in the extended mesh seen from its triangle slot j: R[0] = r_j,
 * R[1] = r_{j+1}, ... (six points; across sharp spokes the parallelogram phantoms). */
static void tbz_ring6(const sfb__tbz *T, int v, int j, double R[6][3]) {
    const sfb__level *l = T->l;
    const int n = tbz_nf(l, v), m = l->ve_off[v + 1] - l->ve_off[v];
    double V[3];
    int i, c;
    tbz_get(T, v, V);
    if (T->vtype[v] == TBZ_SMOOTH) {
        for (i = 0; i < 6; ++i) tbz_get(T, tbz_ring(l, v, (j + i) % n), R[i]);
        return;
    }
    {
        /* crease / boundary with three triangles a side: the sector holding slot j */
        int s0 = j, k;
        double S[4][3];
        while (!T->efeat[l->ve[l->ve_off[v] + s0]]) s0 = (s0 + m - 1) % m;
        for (k = 0; k < 4; ++k) tbz_get(T, tbz_ring(l, v, (s0 + k) % m), S[k]);
        /* ccw: C1 = S0, n1, n2, C2 = S3, V + C2 - n2, V + C1 - n1 */
        {
            double E[6][3];
            for (k = 0; k < 4; ++k) memcpy(E[k], S[k], sizeof S[k]);
            for (c = 0; c < 3; ++c) {
                E[4][c] = V[c] + S[3][c] - S[2][c];
                E[5][c] = V[c] + S[0][c] - S[1][c];
            }
            k = (j - s0 + m) % m; /* slot j's position in the sector */
            for (i = 0; i < 6; ++i) memcpy(R[i], E[(k + i) % 6], sizeof E[0]);
        }
    }
}

/* Loop limit corner of a smooth vertex (ALGORITHMS.md 8.2; 8.1 at n = 6). */
static void tbz_loop_corner(const sfb__tbz *T, int v, double P[3]) {
    const sfb__level *l = T->l;
    const int n = tbz_nf(l, v);
    const double cn = cos(2.0 * TBZ_PI / n), a = 0.625 - (0.375 + 0.25 * cn) * (0.375 + 0.25 * cn), w = 3.0 * n / (8.0 * a);
    double V[3], R[3];
    int j;
    tbz_get(T, v, V);
    P[0] = w * V[0]; P[1] = w * V[1]; P[2] = w * V[2];
    for (j = 0; j < n; ++j) { tbz_get(T, tbz_ring(l, v, j), R); tbz_axpy(P, 1.0, R); }
    for (j = 0; j < 3; ++j) P[j] /= (w + n);
}

/* Our irregular crease vertex in the smooth net: its corner point is the crease B-spline's
 * point moved by the mean offset of its two crease neighbours' smooth corner points from
 * their own B-spline points. The smooth surface lies off the crease polygon by that offset
 * along the whole crease (Loop's limit: above a valley, beside the crease where the mesh is
 * not symmetric); pinning the extraordinary vertex to the B-spline made the crease curve dip
 * there, an undulation of its own at every s < 1 (tests/tribezier.c, undulation). A
 * neighbour that is not an ordinary crease vertex (two tagged edges) adds no offset. */
static void tbz_ours_offset(sfb__tbz *T) {
    const sfb__level *l = T->l;
    int v, j, c;
    if (T->sharp || T->seed_plane) return;
    for (v = 0; v < T->nv; ++v) {
        double off[3] = {0.0, 0.0, 0.0};
        int m = l->ve_off[v + 1] - l->ve_off[v], cnt = 0;
        if (!tbz_ours(T, v)) continue;
        for (j = 0; j < m; ++j) {
            const int w = tbz_ring(l, v, j);
            int nb[2], nn = 0, i2, m2 = l->ve_off[w + 1] - l->ve_off[w];
            double W[3], A[3], B[3];
            if (!(T->tag_s[l->ve[l->ve_off[v] + j]] > 0.0f) || tbz_ours(T, w)) continue;
            for (i2 = 0; i2 < m2; ++i2)
                if (T->tag_s[l->ve[l->ve_off[w] + i2]] > 0.0f) { if (nn < 2) nb[nn] = tbz_ring(l, w, i2); ++nn; }
            if (nn != 2 || tbz_boundary(l, w) || T->corner_s[w] > 0.0f) continue;
            tbz_get(T, w, W); tbz_get(T, nb[0], A); tbz_get(T, nb[1], B);
            for (c = 0; c < 3; ++c) off[c] += T->x[3 * (size_t)tbz_vp(T, w) + c] - (A[c] + 4.0 * W[c] + B[c]) / 6.0;
            ++cnt;
        }
        if (cnt)
            for (c = 0; c < 3; ++c) T->x[3 * (size_t)tbz_vp(T, v) + c] += off[c] / cnt;
    }
}

/* The initial net (and its fixed points) for the current state. */
/* A regular smooth vertex (valence 6, no feature): Sabin's rules (ALGORITHMS.md 8.1) for its
 * corner, its end of every spoke and its corner of every triangle, its ring read once (the
 * loops of tbz_initial read it again for every point: a fifth of the nets' setup after two
 * Loop steps, where nearly every vertex is one of these). */
#define TBZ_FAST(T, v) (!(T)->virr[v] && (T)->vtype[v] == TBZ_SMOOTH && tbz_nf((T)->l, v) == 6 && !tbz_boundary((T)->l, v))
/* Sabin's rules on a regular ring R (ALGORITHMS.md 8.1): the corner, the edge point on the spoke
 * to R[j], the interior point of the triangle (V, R[j], R[j+1]). */
static void tbz_sabin_corner(const double V[3], double R[6][3], double *P) {
    int c;
    for (c = 0; c < 3; ++c) P[c] = (6.0 * V[c] + R[0][c] + R[1][c] + R[2][c] + R[3][c] + R[4][c] + R[5][c]) / 12.0;
}
static void tbz_sabin_edge(const double V[3], double R[6][3], int j, double *E) {
    const int j1 = (j + 1) % 6, j2 = (j + 2) % 6, j4 = (j + 4) % 6, j5 = (j + 5) % 6;
    int c;
    for (c = 0; c < 3; ++c) E[c] = (12.0 * V[c] + 4.0 * R[j][c] + 3.0 * (R[j1][c] + R[j5][c]) + R[j2][c] + R[j4][c]) / 24.0;
}
static void tbz_sabin_face(const double V[3], double R[6][3], int j, double *F) {
    const int j1 = (j + 1) % 6, j2 = (j + 2) % 6, j5 = (j + 5) % 6;
    int c;
    for (c = 0; c < 3; ++c) F[c] = (10.0 * V[c] + 6.0 * R[j][c] + 6.0 * R[j1][c] + R[j5][c] + R[j2][c]) / 24.0;
}
static void tbz_regular_vertex(sfb__tbz *T, int v) {
    const sfb__level *l = T->l;
    double R[6][3], V[3];
    int j;
    tbz_get(T, v, V);
    for (j = 0; j < 6; ++j) tbz_get(T, tbz_ring(l, v, j), R[j]);
    tbz_sabin_corner(V, R, T->x + 3 * (size_t)tbz_vp(T, v));
    for (j = 0; j < 6; ++j) {
        const int e = l->ve[l->ve_off[v] + j], f = l->vf[l->vf_off[v] + j], k = l->vf_slot[l->vf_off[v] + j];
        tbz_sabin_edge(V, R, j, T->x + 3 * (size_t)tbz_ep(T, e, l->ev[2 * e] == v ? 0 : 2));
        tbz_sabin_face(V, R, j, T->x + 3 * (size_t)tbz_fp(T, f, k));
    }
}

static void tbz_initial(sfb__tbz *T) {
    const sfb__level *l = T->l;
    int v, e, f, j, c, k;
    memset(T->fixed, 0, (size_t)T->np);
    for (v = 0; v < T->nv; ++v)
        if (TBZ_FAST(T, v)) tbz_regular_vertex(T, v);
    /* corners */
    for (v = 0; v < T->nv; ++v) {
        double *P = T->x + 3 * (size_t)tbz_vp(T, v);
        const int type = T->vtype[v] & 15, n = tbz_nf(l, v);
        if (n == 0) { tbz_get(T, v, P); continue; }
        if (TBZ_FAST(T, v)) continue;
        if (!T->virr[v]) {
            double R[6][3], V[3];
            tbz_ring6(T, v, 0, R);
            tbz_get(T, v, V);
            tbz_sabin_corner(V, R, P);
        } else if (type == TBZ_CREASE || type == TBZ_CORNER) {
            tbz_crease_point(T, v, type, P);
        } else if (T->sharp && T->corner_s[v] > 0.0f) {
            tbz_get(T, v, P);
        } else {
            tbz_loop_corner(T, v, P);
        }
        if (type == TBZ_CORNER || (type == TBZ_CREASE && T->virr[v]) || (T->sharp && T->corner_s[v] > 0.0f)) T->fixed[v] = 1;
        if (type == TBZ_CREASE && !T->virr[v] && (T->vtype[v] & 16) == 0) T->fixed[v] = 1; /* = the regular value */
    }
    tbz_ours_offset(T);
    /* edge points: near each end from that end's rules, the middle from the two opposite vertices */
    for (e = 0; e < T->ne; ++e) {
        const int a = l->ev[2 * e], b = l->ev[2 * e + 1];
        int end;
        for (end = 0; end < 2; ++end) {
            const int v = end ? b : a, w = end ? a : b, q = end ? 2 : 0;
            double *E = T->x + 3 * (size_t)tbz_ep(T, e, q), V[3], W[3];
            const double *P = T->x + 3 * (size_t)v;
            int m, n;
            if (TBZ_FAST(T, v)) continue; /* tbz_regular_vertex */
            m = tbz_spoke(l, v, e);
            n = tbz_nf(l, v);
            tbz_get(T, v, V); tbz_get(T, w, W);
            if (!T->virr[v]) {
                double R[6][3];
                /* a slot whose triangle has the spoke as R[0] or R[1] */
                if (m < n) {
                    tbz_ring6(T, v, m, R);
                    tbz_sabin_edge(V, R, 0, E);
                } else {
                    tbz_ring6(T, v, m - 1, R);
                    tbz_sabin_edge(V, R, 1, E);
                }
            } else if (((T->vtype[v] & 15) == TBZ_SMOOTH || (T->vtype[v] & 15) == TBZ_DART)) {
                /* 8.2: P + 3/4 (3 + 2c)/(6n) T_m */
                const double cn = cos(2.0 * TBZ_PI / n), g = 0.75 * (3.0 + 2.0 * cn) / (6.0 * n);
                double R[3];
                memcpy(E, P, 3 * sizeof(double));
                for (k = 0; k < n; ++k) {
                    tbz_get(T, tbz_ring(l, v, (m + k) % n), R);
                    tbz_axpy(E, g * cos(2.0 * TBZ_PI * k / n), R);
                }
            } else {
                /* the B-spline's: 3/4 P + 1/4 (2V + W)/3 */
                for (c = 0; c < 3; ++c) E[c] = 0.75 * P[c] + (2.0 * V[c] + W[c]) / 12.0;
            }
        }
        {
            /* b220 = (2a + 2b + X + Y)/6; across a sharp edge Y = a + b - X, so (a + b)/2 */
            double *M = T->x + 3 * (size_t)tbz_ep(T, e, 1), A[3], B[3], X[3];
            tbz_get(T, a, A); tbz_get(T, b, B);
            if (T->efeat[e] || l->ef_off[e + 1] - l->ef_off[e] < 2) {
                for (c = 0; c < 3; ++c) M[c] = 0.5 * (A[c] + B[c]);
            } else {
                for (c = 0; c < 3; ++c) M[c] = (2.0 * A[c] + 2.0 * B[c]) / 6.0;
                for (k = 0; k < 2; ++k) {
                    const int g = l->ef[l->ef_off[e] + k], s = l->ef_slot[l->ef_off[e] + k];
                    tbz_get(T, l->fv[l->fv_off[g] + (s + 2) % 3], X);
                    tbz_axpy(M, 1.0 / 6.0, X);
                }
            }
        }
        /* a sharp edge between crease/corner ends: the degree-raised cubic B-spline */
        if (T->efeat[e] && (T->vtype[a] & 15) >= TBZ_CREASE && (T->vtype[b] & 15) >= TBZ_CREASE && !(T->vtype[a] & 16) &&
            !(T->vtype[b] & 16)) {
            double P0[3], P3[3], A[3], B[3];
            tbz_crease_point(T, a, T->vtype[a] & 15, P0);
            tbz_crease_point(T, b, T->vtype[b] & 15, P3);
            tbz_get(T, a, A); tbz_get(T, b, B);
            for (c = 0; c < 3; ++c) {
                const double P1 = (2.0 * A[c] + B[c]) / 3.0, P2 = (A[c] + 2.0 * B[c]) / 3.0;
                T->x[3 * (size_t)tbz_ep(T, e, 0) + c] = (P0[c] + 3.0 * P1) / 4.0;
                T->x[3 * (size_t)tbz_ep(T, e, 1) + c] = (P1 + P2) / 2.0;
                T->x[3 * (size_t)tbz_ep(T, e, 2) + c] = (3.0 * P2 + P3[c]) / 4.0;
            }
            T->fixed[tbz_ep(T, e, 0)] = T->fixed[tbz_ep(T, e, 1)] = T->fixed[tbz_ep(T, e, 2)] = 1;
        }
        /* the smooth net at our crease vertex: the crease tangent is the B-spline's */
        for (k = 0; k < 2; ++k) {
            const int v = k ? b : a, w = k ? a : b;
            if (tbz_ours(T, v) && T->tag_s[e] > 0.0f) {
                double V[3], W[3], *E = T->x + 3 * (size_t)tbz_ep(T, e, k ? 2 : 0);
                const double *P = T->x + 3 * (size_t)v;
                tbz_get(T, v, V); tbz_get(T, w, W);
                for (c = 0; c < 3; ++c) E[c] = 0.25 * P[c] + 0.75 * (2.0 * V[c] + W[c]) / 3.0;
                T->fixed[tbz_ep(T, e, k ? 2 : 0)] = 1;
            }
        }
    }
    /* an irregular smooth vertex keeps its Loop limit point and tangent plane (ALGORITHMS.md 8.2:
     * corner and edge points already satisfy the t = 0 relations): left free, the minimum-norm
     * solve collapses tangents to zero where extraordinary vertices touch (valence 4: the
     * relation X + Y = 0 T holds for X = Y = 0), and with them fixed the constraints stay
     * solvable there (checked on closed meshes of valence 4 and 5 everywhere) */
    {
        for (v = 0; v < T->nv; ++v)
            if (T->virr[v] && (T->vtype[v] & 15) == TBZ_SMOOTH) {
                T->fixed[v] = 1;
                for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
                    e = l->ve[j];
                    T->fixed[tbz_ep(T, e, l->ev[2 * e] == v ? 0 : 2)] = 1;
                }
            }
    }
    /* our irregular crease vertex in the smooth net: every spoke's tangent from the sector
     * angles, T(theta) = cos(theta) a + sin(theta) b, a the B-spline's crease tangent (so both
     * crease tangents lie in the plane), b = 2/(3n) sum sin(theta_j) (r_j - V); fixed, so the
     * t = 0 relations hold and no tangent can collapse */
    for (v = 0; v < T->nv; ++v)
        if (tbz_ours(T, v)) {
            const int n = tbz_nf(l, v);
            const double *P = T->x + 3 * (size_t)v, *phi = T->phi + l->vf_off[v];
            double th[64], a[3], bv[3] = {0, 0, 0}, V[3], R[3], A[3], B[3];
            int first = -1, other = -1;
            if (n > 64) continue;
            for (j = 0; j < n; ++j)
                if (T->tag_s[l->ve[l->ve_off[v] + j]] > 0.0f) { if (first < 0) first = j; else other = j; }
            if (first < 0 || other < 0) continue;
            tbz_get(T, v, V);
            th[first] = 0.0;
            for (k = 1; k < n; ++k) th[(first + k) % n] = th[(first + k - 1) % n] + phi[(first + k - 1) % n];
            tbz_get(T, tbz_ring(l, v, first), A); tbz_get(T, tbz_ring(l, v, other), B);
            for (c = 0; c < 3; ++c) a[c] = (A[c] - B[c]) / 6.0;
            for (j = 0; j < n; ++j) {
                tbz_get(T, tbz_ring(l, v, j), R);
                for (c = 0; c < 3; ++c) bv[c] += 2.0 / (3.0 * n) * sin(th[j]) * (R[c] - V[c]);
            }
            for (j = 0; j < n; ++j) {
                const int ej = l->ve[l->ve_off[v] + j], q = tbz_ep(T, ej, l->ev[2 * ej] == v ? 0 : 2);
                for (c = 0; c < 3; ++c) T->x[3 * (size_t)q + c] = P[c] + 0.75 * (cos(th[j]) * a[c] + sin(th[j]) * bv[c]);
                T->fixed[q] = 1;
            }
        }
    /* interior points: b211 near corner v of triangle (v, r_m, r_{m+1}) */
    for (f = 0; f < T->nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        for (k = 0; k < 3; ++k) {
            const int v = fv[k], n = tbz_nf(l, v), bnd = tbz_boundary(l, v);
            double *F = T->x + 3 * (size_t)tbz_fp(T, f, k), V[3];
            int m = -1;
            if (TBZ_FAST(T, v)) continue;
            for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j)
                if (l->vf[j] == f) { m = j - l->vf_off[v]; break; }
            tbz_get(T, v, V);
            if (!T->virr[v]) {
                double R[6][3];
                tbz_ring6(T, v, m, R);
                tbz_sabin_face(V, R, 0, F);
            } else {
                double A[3], B[3], Cm[3], D[3];
                tbz_get(T, tbz_ring(l, v, m), A);
                tbz_get(T, tbz_ring(l, v, m + 1 <= (bnd ? n : n - 1) ? m + 1 : 0), B);
                if (!bnd || m > 0) tbz_get(T, tbz_ring(l, v, (m + n - 1) % n), Cm);
                else for (c = 0; c < 3; ++c) Cm[c] = V[c] + A[c] - B[c];
                if (!bnd) tbz_get(T, tbz_ring(l, v, (m + 2) % n), D);
                else if (m + 2 <= n) tbz_get(T, tbz_ring(l, v, m + 2), D);
                else for (c = 0; c < 3; ++c) D[c] = V[c] + B[c] - A[c];
                for (c = 0; c < 3; ++c) F[c] = (10.0 * V[c] + 6.0 * A[c] + 6.0 * B[c] + Cm[c] + D[c]) / 24.0;
            }
        }
    }
}

/* ---- the G1 constraints and their least-squares solve ---- */

typedef struct tbz_sys {
    int rows, cap_rows;
    size_t n, cap;
    size_t *off;
    int *edge, cur_edge; /* per row: its mesh edge */
    int *col;       /* global point index */
    double *w;
} tbz_sys;

static int tbz_sys_push(sfb__tbz *T, tbz_sys *S, int col, double w) {
    if (S->n == S->cap) {
        size_t nc = S->cap ? 2 * S->cap : 4096;
        int *c2 = (int *)sfb__realloc(T->ctx, S->col, nc * sizeof(int));
        double *w2;
        if (!c2) return 0;
        S->col = c2;
        w2 = (double *)sfb__realloc(T->ctx, S->w, nc * sizeof(double));
        if (!w2) return 0;
        S->w = w2;
        S->cap = nc;
    }
    S->col[S->n] = col;
    S->w[S->n++] = w;
    return 1;
}
static int tbz_sys_row(sfb__tbz *T, tbz_sys *S) {
    if (S->rows + 1 >= S->cap_rows) {
        int nc = S->cap_rows ? 2 * S->cap_rows : 1024;
        size_t *o2 = (size_t *)sfb__realloc(T->ctx, S->off, ((size_t)nc + 1) * sizeof(size_t));
        int *e2;
        if (!o2) return 0;
        S->off = o2;
        e2 = (int *)sfb__realloc(T->ctx, S->edge, ((size_t)nc + 1) * sizeof(int));
        if (!e2) return 0;
        S->edge = e2;
        S->cap_rows = nc;
    }
    if (S->rows == 0) S->off[0] = 0;
    S->edge[S->rows] = S->cur_edge;
    S->off[++S->rows] = S->n;
    return 1;
}

/* End coefficients (mu, nu, lambda) of the G1 relation along spoke to `w` at vertex v, where X
 * is the derivative towards the triangle after the spoke (ccw) and Y towards the one before;
 * `at_end` for the edge's far end (t = 1). Normalised to mu + nu = 2. */
static void tbz_coef(const sfb__tbz *T, int v, int e, int at_end, double out[3]) {
    const sfb__level *l = T->l;
    const int n = tbz_nf(l, v), m = tbz_spoke(l, v, e);
    const double *phi = T->phi + l->vf_off[v];
    const double after = phi[m % n], before = phi[(m + n - 1) % n];
    double mu, nu, la, s, sa, sb, sab;
    if (after == before && n < TBZ_USIN && after == 2.0 * TBZ_PI / n) {
        sa = sb = T->usin[n][0];
        sab = T->usin[n][1];
    } else {
        sa = sin(after); sb = sin(before); sab = sin(after + before);
    }
    if (!at_end) {
        /* at t = 0: sin(before) T_{m+1} + sin(after) T_{m-1} = sin(after + before) T_m */
        mu = sb; nu = sa; la = sab;
    } else {
        /* at t = 1 (seen from the far end, X towards its ring's previous, Y towards its next) */
        mu = sa; nu = sb; la = mu + nu - sab;
    }
    s = 2.0 / (mu + nu);
    out[0] = mu * s; out[1] = nu * s; out[2] = la * s;
}

/* Five rows for interior edge e. */
static int tbz_edge_rows(sfb__tbz *T, tbz_sys *S, int e) {
    const sfb__level *l = T->l;
    const int a = l->ev[2 * e], b = l->ev[2 * e + 1];
    int fL = -1, fR = -1, sL = 0, sR = 0, k, j, m;
    int Ei[5], Li[4], Ri[4];
    double c0[3], c1[3];
    for (k = 0; k < 2; ++k) {
        const int g = l->ef[l->ef_off[e] + k], s = l->ef_slot[l->ef_off[e] + k];
        if (l->fv[l->fv_off[g] + s] == a) { fL = g; sL = s; }
        else { fR = g; sR = s; }
    }
    if (fL < 0 || fR < 0) return 1;
    /* left triangle (a, b, C): a at slot sL, b at sL+1, C at sL+2; right (b, a, D): b at sR */
    for (j = 0; j <= 4; ++j) {
        int w[3];
        w[sL] = 4 - j; w[(sL + 1) % 3] = j; w[(sL + 2) % 3] = 0;
        Ei[j] = tbz_gpt(T, fL, w);
    }
    for (j = 0; j <= 3; ++j) {
        int w[3];
        w[sL] = 3 - j; w[(sL + 1) % 3] = j; w[(sL + 2) % 3] = 1;
        Li[j] = tbz_gpt(T, fL, w);
        w[(sR + 1) % 3] = 3 - j; w[sR] = j; w[(sR + 2) % 3] = 1;
        Ri[j] = tbz_gpt(T, fR, w);
    }
    {
        int any = 0;
        for (j = 0; j < 5; ++j) any |= !T->fixed[Ei[j]] && T->dist[Ei[j]] <= TBZ_REACH;
        for (j = 0; j < 4; ++j) any |= (!T->fixed[Li[j]] && T->dist[Li[j]] <= TBZ_REACH) || (!T->fixed[Ri[j]] && T->dist[Ri[j]] <= TBZ_REACH);
        if (!any) return 1;
    }
    /* at a: X towards C (after the spoke in a's ring), Y towards D */
    tbz_coef(T, a, e, 0, c0);
    /* at b: X towards C is b's ring previous, Y towards D its next */
    tbz_coef(T, b, e, 1, c1);
    for (m = 0; m <= 4; ++m) {
        for (j = m - 1; j <= m; ++j) {
            const double *cc = j == m ? c0 : c1;
            const double f = j == m ? (4.0 - m) / 4.0 : m / 4.0;
            if (j < 0 || j > 3) continue;
            /* mu (L_j - E_j) + nu (R_j - E_j) - la (E_{j+1} - E_j) */
            if (!tbz_sys_push(T, S, Li[j], f * cc[0]) || !tbz_sys_push(T, S, Ri[j], f * cc[1]) ||
                !tbz_sys_push(T, S, Ei[j], f * (cc[2] - cc[0] - cc[1])) || !tbz_sys_push(T, S, Ei[j + 1], -f * cc[2]))
                return 0;
        }
        if (!tbz_sys_row(T, S)) return 0;
    }
    return 1;
}

/* Net distances (in steps of the Bezier net) from the irregular vertices' corner points, exact
 * up to TBZ_REACH (the unknowns: dist <= TBZ_REACH) and larger beyond: breadth first over the
 * points, each point's neighbours the points next to it (the six directions of the lattice) in
 * the triangles it belongs to. (Sweeps over every triangle, as before, took 25 ms on the cow
 * after two Loop steps; this touches only the points near irregular vertices.) */
static sfb_result tbz_distances(sfb__tbz *T) {
    static const int dir[6][2] = {{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}};
    const sfb__level *l = T->l;
    int nbr[15][7], i, q, k, head = 0, tail = 0;
    int *queue = (int *)sfb__alloc(T->ctx, ((size_t)T->np + 1) * sizeof(int));
    if (!queue) return sfb__oom(T->ctx, "tribezier distances");
    /* per lattice position q = (a, j) its neighbours, -1 ended */
    for (q = 0; q < 15; ++q) {
        int a, j, n = 0;
        for (j = 0; j <= 4; ++j)
            for (a = 0; a + j <= 4; ++a)
                if (tbz_qij(a, j) == q)
                    for (k = 0; k < 6; ++k) {
                        const int a2 = a + dir[k][0], j2 = j + dir[k][1];
                        if (a2 >= 0 && j2 >= 0 && a2 + j2 <= 4) nbr[q][n++] = tbz_qij(a2, j2);
                    }
        nbr[q][n] = -1;
    }
    for (i = 0; i < T->np; ++i) T->dist[i] = 1000;
    /* from every irregular vertex; in the smooth net's second pass from those with our plane
     * alone (tbz_state) */
    for (i = 0; i < T->nv; ++i)
        if (T->virr[i] && (!T->straight_x || tbz_ours(T, i))) { T->dist[tbz_vp(T, i)] = 0; queue[tail++] = tbz_vp(T, i); }
    while (head < tail) {
        const int p = queue[head++], d = T->dist[p];
        int f0, f1, fi;
        const int *fl;
        if (d >= TBZ_REACH) continue;
        /* the triangles p belongs to */
        if (p < T->nv) { fl = l->vf; f0 = l->vf_off[p]; f1 = l->vf_off[p + 1]; }
        else if (p < T->nv + 3 * T->ne) { const int e = (p - T->nv) / 3; fl = l->ef; f0 = l->ef_off[e]; f1 = l->ef_off[e + 1]; }
        else { static const int none = 0; fl = &none; f0 = 0; f1 = 1; }
        for (fi = f0; fi < f1; ++fi) {
            const int f = p < T->nv + 3 * T->ne ? fl[fi] : (p - T->nv - 3 * T->ne) / 3;
            const int *g = T->grid + 15 * (size_t)f;
            for (q = 0; q < 15 && g[q] != p; ++q) {}
            if (q == 15) continue;
            for (k = 0; nbr[q][k] >= 0; ++k) {
                const int p2 = g[nbr[q][k]];
                if (T->dist[p2] > d + 1) { T->dist[p2] = d + 1; queue[tail++] = p2; }
            }
        }
    }
    sfb__free(T->ctx, queue);
    return SFB_SUCCESS;
}

/* Union-find root of unknown i (path halving). */
static int tbz_root(int *parent, int i) {
    while (parent[i] != i) { parent[i] = parent[parent[i]]; i = parent[i]; }
    return i;
}

#define TBZ_STALL 40
#define TBZ_MAX(a, b) ((a) > (b) ? (a) : (b))
/* The loops of an iteration run over TBZ_CHUNKS fixed chunks of the rows and of the unknowns,
 * each chunk keeping its own partial sums, added in chunk order: so the arithmetic is the same
 * whether the chunks run on one thread or on the backend's threads (a component of at least
 * TBZ_PAR_UNKNOWNS unknowns runs its chunks on them, tbz_solve_todo), and the net is the same bit
 * for bit on every backend and thread count. The threshold: an iteration hands its loops to the
 * threads four times, and waking a worker costs 30-60 us (bench), so the loops must be long
 * enough to pay for it; below it, components are solved whole, several at a time, in one chunk
 * (64 chunks of a component of a few dozen unknowns cost more than the iteration's own work:
 * teapot 47 -> 20 ms, bench). Which components run in chunks depends on their size only, not on
 * the thread count, so this keeps the nets the same bit for bit. */
#define TBZ_CHUNKS 64
#define TBZ_PAR_UNKNOWNS 65536
#define TBZ_PAR_UNKNOWNS_SMALL 1024 /* SFB__TBZ_PAR_SMALL */
typedef struct tbz_cg {
    int nr, nu;
    int nch;               /* chunks: TBZ_CHUNKS for a component on the threads, 1 for one solved whole */
    const size_t *lo, *co; /* the local CSR and its transpose (each column's entries in row order) */
    const int *lc, *cr;
    const double *lw, *cw;
    double *rr, *q, *xs, *sv, *p;
    double alpha[3], beta[3];
    int active[3];
    double part[TBZ_CHUNKS][3][3]; /* per chunk: its partial sums (three kinds, three coordinates) */
} tbz_cg;
static void tbz_span(const tbz_cg *G, int n, int ch, int *a, int *b) {
    *a = (int)((long long)n * ch / G->nch);
    *b = (int)((long long)n * (ch + 1) / G->nch);
}
/* out = the sums of w[k] vec[idx[k]] over k in [k0, k1), three coordinates (in k order). */
static void tbz_dot3(const int *idx, const double *w, size_t k0, size_t k1, const double *vec, double out[3]) {
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
    size_t k;
    for (k = k0; k < k1; ++k) {
        const double *x = vec + 3 * (size_t)idx[k];
        s0 += w[k] * x[0]; s1 += w[k] * x[1]; s2 += w[k] * x[2];
    }
    out[0] = s0; out[1] = s1; out[2] = s2;
}
/* q = A p over the chunks' rows; part[.][0] = |q|^2. */
static void tbz_cg_aq(void *arg, int first, int last) {
    tbz_cg *G = (tbz_cg *)arg;
    const size_t *lo = G->lo;
    const int *lc = G->lc;
    const double *lw = G->lw, *p = G->p;
    double *q = G->q;
    int ch, r, r0, r1;
    for (ch = first; ch < last; ++ch) {
        double qq0 = 0.0, qq1 = 0.0, qq2 = 0.0;
        tbz_span(G, G->nr, ch, &r0, &r1);
        for (r = r0; r < r1; ++r) {
            double *v = q + 3 * r;
            tbz_dot3(lc, lw, lo[r], lo[r + 1], p, v);
            qq0 += v[0] * v[0]; qq1 += v[1] * v[1]; qq2 += v[2] * v[2];
        }
        G->part[ch][0][0] = qq0; G->part[ch][0][1] = qq1; G->part[ch][0][2] = qq2;
    }
}
/* r -= alpha q over the chunks' rows; part[.][1] = max |r|, part[.][2] = |r|^2. */
static void tbz_cg_r(void *arg, int first, int last) {
    tbz_cg *G = (tbz_cg *)arg;
    const double *q = G->q, a[3] = {G->alpha[0], G->alpha[1], G->alpha[2]};
    double *rr = G->rr;
    int ch, r, r0, r1, c;
    for (ch = first; ch < last; ++ch) {
        double rn[3] = {0.0, 0.0, 0.0}, r2[3] = {0.0, 0.0, 0.0};
        tbz_span(G, G->nr, ch, &r0, &r1);
        for (r = r0; r < r1; ++r)
            for (c = 0; c < 3; ++c) {
                const double v = rr[3 * r + c] - a[c] * q[3 * r + c];
                rr[3 * r + c] = v;
                rn[c] = TBZ_MAX(rn[c], fabs(v));
                r2[c] += v * v;
            }
        for (c = 0; c < 3; ++c) { G->part[ch][1][c] = rn[c]; G->part[ch][2][c] = r2[c]; }
    }
}
/* Over the chunks' unknowns: x += alpha p, then sv = A^T r (gathered per unknown from the
 * transpose, so each sum adds the terms a row-by-row scatter would, in its order); part[.][0] =
 * |sv|^2. */
static void tbz_cg_atr(void *arg, int first, int last) {
    tbz_cg *G = (tbz_cg *)arg;
    const size_t *co = G->co;
    const int *cr = G->cr;
    const double *cw = G->cw, *rr = G->rr, *p = G->p, a[3] = {G->alpha[0], G->alpha[1], G->alpha[2]};
    double *xs = G->xs, *sv = G->sv;
    int ch, i, i0, i1, c;
    for (ch = first; ch < last; ++ch) {
        double g0 = 0.0, g1 = 0.0, g2 = 0.0;
        tbz_span(G, G->nu, ch, &i0, &i1);
        for (i = i0; i < i1; ++i) {
            double *v = sv + 3 * i;
            for (c = 0; c < 3; ++c) xs[3 * i + c] += a[c] * p[3 * i + c];
            tbz_dot3(cr, cw, co[i], co[i + 1], rr, v);
            g0 += v[0] * v[0]; g1 += v[1] * v[1]; g2 += v[2] * v[2];
        }
        G->part[ch][0][0] = g0; G->part[ch][0][1] = g1; G->part[ch][0][2] = g2;
    }
}
/* p = sv + beta p over the chunks' unknowns, for the active coordinates. */
static void tbz_cg_p(void *arg, int first, int last) {
    tbz_cg *G = (tbz_cg *)arg;
    const double *sv = G->sv;
    double *p = G->p;
    int ch, i, i0, i1, c;
    for (ch = first; ch < last; ++ch) {
        tbz_span(G, G->nu, ch, &i0, &i1);
        for (c = 0; c < 3; ++c)
            if (G->active[c]) {
                const double b = G->beta[c];
                for (i = i0; i < i1; ++i) p[3 * i + c] = sv[3 * i + c] + b * p[3 * i + c];
            }
    }
}
/* Runs a phase over every chunk, on the backend's threads (ctx) or here (NULL). */
static void tbz_cg_run(sfb_context *ctx, tbz_cg *G, void (*phase)(void *, int, int)) {
    if (ctx) sfb__parallel(ctx, phase, G, 0, G->nch);
    else phase(G, 0, G->nch);
}
/* s[c] = the sum (kind 0 or 2) or the largest (kind 1) of the chunks' part[.][kind][c], in chunk
 * order. */
static void tbz_cg_sum(const tbz_cg *G, int kind, double s[3]) {
    int ch, c;
    for (c = 0; c < 3; ++c) s[c] = 0.0;
    for (ch = 0; ch < G->nch; ++ch)
        for (c = 0; c < 3; ++c) s[c] = kind == 1 ? TBZ_MAX(s[c], G->part[ch][1][c]) : s[c] + G->part[ch][kind][c];
}
/* Reports the solve's progress: fraction f of its work done, mapped into [p0, p1]. */
static sfb_result tbz_progress(sfb__tbz *T, double f) {
    float v;
    f = T->pbase + (1.0 - T->pbase) * f;
    v = T->p0 + (T->p1 - T->p0) * (float)(f < 0.0 ? 0.0 : f > 1.0 ? 1.0 : f);
    if (v < T->plast) v = T->plast;
    T->plast = v;
    return sfb__progress(T->ctx, v, "tribezier");
}
/* CGLS from zero on one connected component of the constraints (rows `rows[0..nr)`, unknowns
 * `unk[0..nu)` with local[] mapping a point to its column or -1), the three coordinates at once
 * (one matrix, three right-hand sides, each with its own recurrence); adds the change to T->x.
 * The component's matrix is first copied into a compact local CSR (lo/lc/lw: S->n + nr + 1
 * entries each; duplicate columns of a row merged, fixed points left out). w: 6 * nr + 12 * nu +
 * 3 * TBZ_STALL doubles. Stops a coordinate when its residual is below 1e-15 of the scale
 * (consistent: exactly G1), when A^T r has fallen by 1e-13, or when |r|^2 has fallen by less
 * than 1e-5 of itself over the last TBZ_STALL iterations (inconsistent -- touching extraordinary
 * vertices of different valences --: the least-squares residual is reached; what CGLS would
 * still move are the near-null directions, which only make the net wilder). par: the context
 * whose threads run each iteration's loops (tbz_cg), or NULL: here; with par (called on the
 * caller's thread) it reports progress every 16 iterations and returns -1 when cancelled. */
static int tbz_cgls(sfb__tbz *T, const tbz_sys *S, const int *rows, int nr, const int *unk, int nu, const int *local, double scale,
                    double *w, size_t *lo, int *lc, double *lw, size_t *co, int *cr, double *cw, sfb_context *par) {
    tbz_cg G;
    double *rr = w, *hist = w + 6 * (size_t)nr + 12 * (size_t)nu;
    double gamma[3], gamma0[3];
    int it, i, r, c, left = 3;
    const int maxit = 20 * nu + 200 < 5000 ? 20 * nu + 200 : 5000;
    size_t n = 0, k, k2;
    /* the local matrix, and the residual of the initial net b = -A x0 (fixed points included) */
    for (r = 0; r < nr; ++r) {
        double v[3] = {0.0, 0.0, 0.0};
        lo[r] = n;
        for (k = S->off[rows[r]]; k < S->off[rows[r] + 1]; ++k) {
            const int u = local[S->col[k]];
            for (c = 0; c < 3; ++c) v[c] += S->w[k] * T->x[3 * (size_t)S->col[k] + c];
            if (u < 0) continue;
            for (k2 = lo[r]; k2 < n && lc[k2] != u; ++k2) {}
            if (k2 < n) lw[k2] += S->w[k];
            else { lc[n] = u; lw[n++] = S->w[k]; }
        }
        for (c = 0; c < 3; ++c) rr[3 * r + c] = -v[c];
    }
    lo[nr] = n;
    /* its transpose (co/cr/cw), each column's entries in row order (tbz_cg_atr) */
    for (i = 0; i <= nu; ++i) co[i] = 0;
    for (k = 0; k < n; ++k) ++co[lc[k] + 1];
    for (i = 0; i < nu; ++i) co[i + 1] += co[i];
    for (r = 0; r < nr; ++r)
        for (k = lo[r]; k < lo[r + 1]; ++k) {
            const size_t at = co[lc[k]]++;
            cr[at] = r;
            cw[at] = lw[k];
        }
    for (i = nu; i > 0; --i) co[i] = co[i - 1];
    co[0] = 0;
    G.nch = par ? TBZ_CHUNKS : 1;
    G.nr = nr; G.nu = nu; G.lo = lo; G.co = co; G.lc = lc; G.cr = cr; G.lw = lw; G.cw = cw;
    G.rr = rr; G.q = rr + 3 * (size_t)nr; G.xs = G.q + 3 * (size_t)nr; G.sv = G.xs + 3 * (size_t)nu; G.p = G.sv + 3 * (size_t)nu;
    for (i = 0; i < 3 * nu; ++i) { G.xs[i] = 0.0; G.p[i] = 0.0; }
    for (c = 0; c < 3; ++c) { G.alpha[c] = 0.0; G.beta[c] = 0.0; G.active[c] = 1; }
    tbz_cg_run(par, &G, tbz_cg_atr); /* sv = A^T r (x stays 0: alpha = 0) */
    tbz_cg_sum(&G, 0, gamma);
    tbz_cg_run(par, &G, tbz_cg_p);   /* p = sv */
    for (c = 0; c < 3; ++c) {
        gamma0[c] = gamma[c];
        if (!(gamma[c] > 0.0)) { G.active[c] = 0; --left; }
    }
    for (it = 0; it < maxit && left > 0; ++it) {
        double qq[3], rn[3], r2[3], g2[3];
        /* a large component's share of the work counted as done over 600 iterations (about
         * what one takes), at most 95% of it before it ends */
        if (par && (it & 15) == 15 &&
            tbz_progress(T, (T->work_done + T->work_cur * (it < 570 ? it / 600.0 : 0.95)) / T->work_all) != SFB_SUCCESS)
            return -1;
        tbz_cg_run(par, &G, tbz_cg_aq);
        tbz_cg_sum(&G, 0, qq);
        for (c = 0; c < 3; ++c) {
            if (G.active[c] && !(qq[c] > 0.0)) { G.active[c] = 0; --left; }
            G.alpha[c] = G.active[c] ? gamma[c] / qq[c] : 0.0;
        }
        tbz_cg_run(par, &G, tbz_cg_r);
        tbz_cg_sum(&G, 1, rn);
        tbz_cg_sum(&G, 2, r2);
        for (c = 0; c < 3; ++c) {
            double *h = hist + (size_t)c * TBZ_STALL;
            if (!G.active[c]) continue;
            if (rn[c] <= 1e-15 * scale || (it >= TBZ_STALL && h[it % TBZ_STALL] - r2[c] <= 1e-5 * r2[c])) { G.active[c] = 0; --left; }
            h[it % TBZ_STALL] = r2[c];
        }
        /* x += alpha p (every coordinate that moved this iteration), sv = A^T r */
        tbz_cg_run(par, &G, tbz_cg_atr);
        tbz_cg_sum(&G, 0, g2);
        if (left == 0) { ++it; break; }
        for (c = 0; c < 3; ++c) {
            if (G.active[c] && g2[c] <= 1e-26 * gamma0[c]) { G.active[c] = 0; --left; }
            if (!G.active[c]) continue;
            G.beta[c] = g2[c] / gamma[c];
            gamma[c] = g2[c];
        }
        tbz_cg_run(par, &G, tbz_cg_p);
    }
    for (i = 0; i < nu; ++i)
        for (c = 0; c < 3; ++c) T->x[3 * (size_t)unk[i] + c] += G.xs[3 * i + c];
    return it;
}

/* The connected components of the constraints: rows sharing an unknown are in one. rows[] and
 * unk[] list the rows and the unknowns' points component by component, [rstart[i], rstart[i+1])
 * and [ustart[i], ustart[i+1]). */
typedef struct tbz_comps {
    int nc;
    int *rstart, *ustart, *rows, *unk;
} tbz_comps;

static sfb_result tbz_components(sfb__tbz *T, const tbz_sys *S, const int *ucol, int nu, tbz_comps *C) {
    int *parent = (int *)sfb__alloc(T->ctx, ((size_t)nu + 1) * sizeof(int));
    int *comp = (int *)sfb__alloc(T->ctx, ((size_t)nu + (size_t)S->rows + 1) * sizeof(int)); /* per unknown, then per row */
    int i, r, nc = 0;
    sfb_result res = SFB_SUCCESS;
    C->rows = (int *)sfb__alloc(T->ctx, ((size_t)S->rows + 1) * sizeof(int));
    C->unk = (int *)sfb__alloc(T->ctx, ((size_t)nu + 1) * sizeof(int));
    if (!parent || !comp || !C->rows || !C->unk) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    for (i = 0; i < nu; ++i) parent[i] = i;
    for (r = 0; r < S->rows; ++r) {
        int first = -1;
        size_t k;
        for (k = S->off[r]; k < S->off[r + 1]; ++k) {
            const int u = ucol[S->col[k]];
            if (u < 0) continue;
            if (first < 0) first = tbz_root(parent, u);
            else { const int b2 = tbz_root(parent, u); if (b2 != first) parent[b2] = first; }
        }
        comp[nu + r] = first; /* an unknown for now; -1: the row has none (tbz_edge_rows skips those) */
    }
    for (i = 0; i < nu; ++i) comp[i] = -1;
    for (i = 0; i < nu; ++i) { const int root = tbz_root(parent, i); if (comp[root] < 0) comp[root] = nc++; }
    for (i = 0; i < nu; ++i) parent[i] = tbz_root(parent, i);  /* every unknown points at its root... */
    for (i = 0; i < nu; ++i) parent[i] = comp[parent[i]];       /* ...then holds its component */
    C->nc = nc;
    C->rstart = (int *)sfb__calloc(T->ctx, (size_t)nc + 2, sizeof(int));
    C->ustart = (int *)sfb__calloc(T->ctx, (size_t)nc + 2, sizeof(int));
    if (!C->rstart || !C->ustart) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    for (r = 0; r < S->rows; ++r) {
        const int u0 = comp[nu + r];
        comp[nu + r] = u0 >= 0 ? parent[u0] : -1;
        if (u0 >= 0) ++C->rstart[comp[nu + r] + 1];
    }
    for (i = 0; i < nu; ++i) ++C->ustart[parent[i] + 1];
    for (i = 0; i < nc; ++i) {
        C->rstart[i + 1] += C->rstart[i];
        C->ustart[i + 1] += C->ustart[i];
    }
    /* fill, reusing comp[0..nc) (the per-unknown part is no longer needed) as the cursors */
    for (i = 0; i < nc; ++i) comp[i] = C->rstart[i];
    for (r = 0; r < S->rows; ++r)
        if (comp[nu + r] >= 0) C->rows[comp[comp[nu + r]]++] = r;
    for (i = 0; i < nc; ++i) comp[i] = C->ustart[i];
    for (i = 0; i < T->np; ++i)
        if (ucol[i] >= 0) C->unk[comp[parent[ucol[i]]]++] = i;
done:
    sfb__free(T->ctx, parent);
    sfb__free(T->ctx, comp);
    return res;
}

/* The entries of component i's rows in S (its local matrix has at most as many). */
static size_t tbz_comp_entries(const tbz_sys *S, const tbz_comps *C, int i) {
    size_t n = 0;
    int r;
    for (r = C->rstart[i]; r < C->rstart[i + 1]; ++r) n += S->off[C->rows[r] + 1] - S->off[C->rows[r]];
    return n;
}

/* The components to solve: the small ones in blocks over the backend's threads (sfb__parallel;
 * components are independent: a component's rows read only its own unknowns, which it alone
 * writes, and points no component moves), then the large ones (T->par_unknowns unknowns or
 * more: on a mesh with extraordinary vertices everywhere the regions merge into a few large
 * ones) one by one, each iteration's loops on the threads (tbz_cg); the net is bit for bit that
 * of solving them one by one on one thread. A block holds consecutive components of about equal
 * work and its own scratch (tbz_cgls's w, lo, lc, lw, co, cr, cw, sized for its largest
 * component); local maps every unknown to its column within its component. */
#define TBZ_BLOCKS 32
#define TBZ_ROUNDS 4
typedef struct tbz_block {
    double *w, *lw, *cw;
    size_t *lo, *co;
    int *lc, *cr;
} tbz_block;
typedef struct tbz_job {
    sfb__tbz *T;
    const tbz_sys *S;
    const tbz_comps *C;
    const int *local, *todo, *bstart; /* todo[bstart[b] .. bstart[b + 1]): block b's components */
    double scale;
    tbz_block *blk;
    int *its; /* per todo entry: its iterations (-1: cancelled) */
} tbz_job;

/* Todo entry t of J with block b's scratch; par: the context whose threads run each iteration's
 * loops, or NULL (tbz_cgls). */
static void tbz_solve_one(const tbz_job *J, int b, int t, sfb_context *par) {
    const int i = J->todo[t], r0 = J->C->rstart[i], u0 = J->C->ustart[i];
    J->its[t] = tbz_cgls(J->T, J->S, J->C->rows + r0, J->C->rstart[i + 1] - r0, J->C->unk + u0, J->C->ustart[i + 1] - u0, J->local, J->scale,
                         J->blk[b].w, J->blk[b].lo, J->blk[b].lc, J->blk[b].lw, J->blk[b].co, J->blk[b].cr, J->blk[b].cw, par);
}
/* Blocks [first, last) of J, each component whole on the calling thread. */
static void tbz_solve_blocks(void *arg, int first, int last) {
    const tbz_job *J = (const tbz_job *)arg;
    int b, t;
    for (b = first; b < last; ++b)
        for (t = J->bstart[b]; t < J->bstart[b + 1]; ++t) tbz_solve_one(J, b, t, NULL);
}

/* Solves the components todo[0 .. nt) (see tbz_job). */
static sfb_result tbz_solve_todo(sfb__tbz *T, const tbz_sys *S, const tbz_comps *C, const int *local, const int *todo, int nt, double scale) {
    tbz_job J;
    int bstart[TBZ_BLOCKS + 2], nb, ns = 0, b, t, *order;
    tbz_block blk[TBZ_BLOCKS + 1];
    size_t total = 0, acc = 0, *ent;
    sfb_result res = SFB_SUCCESS;
    if (nt == 0) return SFB_SUCCESS;
    memset(blk, 0, sizeof blk);
    J.its = (int *)sfb__alloc(T->ctx, (size_t)nt * sizeof(int));
    order = (int *)sfb__alloc(T->ctx, (size_t)nt * sizeof(int));
    /* a component's work ~ the entries of its rows (ent, per order entry) */
    ent = (size_t *)sfb__alloc(T->ctx, (size_t)nt * sizeof(size_t));
    if (!J.its || !order || !ent) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    /* the small components first, then the large ones */
    for (t = 0; t < nt; ++t)
        if (C->ustart[todo[t] + 1] - C->ustart[todo[t]] < T->par_unknowns) order[ns++] = todo[t];
    for (t = 0, b = ns; t < nt; ++t)
        if (C->ustart[todo[t] + 1] - C->ustart[todo[t]] >= T->par_unknowns) order[b++] = todo[t];
    for (t = 0; t < nt; ++t) ent[t] = tbz_comp_entries(S, C, order[t]);
    for (t = 0; t < ns; ++t) total += ent[t] + 1;
    nb = ns < TBZ_BLOCKS ? ns : TBZ_BLOCKS;
    bstart[0] = 0;
    for (b = 1, t = 0; b < nb; ++b) {
        const size_t goal = total / (size_t)nb * (size_t)b;
        while (t < ns && acc < goal) acc += ent[t++] + 1;
        bstart[b] = t;
    }
    bstart[nb] = ns;
    bstart[nb + 1] = nt; /* block nb: the large components */
    for (b = 0; b <= nb && res == SFB_SUCCESS; ++b) {
        size_t mr = 0, mu = 0, me = 0;
        for (t = bstart[b]; t < bstart[b + 1]; ++t) {
            const int i = order[t];
            const size_t nr = (size_t)(C->rstart[i + 1] - C->rstart[i]), nu = (size_t)(C->ustart[i + 1] - C->ustart[i]);
            mr = nr > mr ? nr : mr; mu = nu > mu ? nu : mu; me = ent[t] > me ? ent[t] : me;
        }
        if (bstart[b] == bstart[b + 1]) continue;
        blk[b].w = (double *)sfb__alloc(T->ctx, (6 * mr + 12 * mu + 3 * TBZ_STALL + 1) * sizeof(double));
        blk[b].lo = (size_t *)sfb__alloc(T->ctx, (mr + 1) * sizeof(size_t));
        blk[b].lc = (int *)sfb__alloc(T->ctx, (me + 1) * sizeof(int));
        blk[b].lw = (double *)sfb__alloc(T->ctx, (me + 1) * sizeof(double));
        blk[b].co = (size_t *)sfb__alloc(T->ctx, (mu + 1) * sizeof(size_t));
        blk[b].cr = (int *)sfb__alloc(T->ctx, (me + 1) * sizeof(int));
        blk[b].cw = (double *)sfb__alloc(T->ctx, (me + 1) * sizeof(double));
        if (!blk[b].w || !blk[b].lo || !blk[b].lc || !blk[b].lw || !blk[b].co || !blk[b].cr || !blk[b].cw) res = sfb__oom(T->ctx, "tribezier constraints");
    }
    if (res == SFB_SUCCESS) {
        /* the small components in TBZ_ROUNDS rounds of blocks, progress reported (and a cancel
         * taken) after each; then the large ones, which report as they go (tbz_cgls) */
        double work_all = 0.0;
        int round;
        J.T = T; J.S = S; J.C = C; J.local = local; J.todo = order; J.bstart = bstart; J.scale = scale; J.blk = blk;
        for (t = 0; t < nt; ++t) work_all += (double)ent[t] + 1.0;
        T->work_all = work_all;
        T->work_done = 0.0;
        for (round = 0; round < TBZ_ROUNDS && res == SFB_SUCCESS; ++round) {
            const int b0 = nb * round / TBZ_ROUNDS, b1 = nb * (round + 1) / TBZ_ROUNDS;
            sfb__parallel(T->ctx, tbz_solve_blocks, &J, b0, b1);
            for (t = bstart[b0]; t < bstart[b1]; ++t) T->work_done += (double)ent[t] + 1.0;
            res = tbz_progress(T, T->work_done / work_all);
        }
        for (t = ns; t < nt && res == SFB_SUCCESS; ++t) {
            T->work_cur = (double)ent[t] + 1.0;
            tbz_solve_one(&J, nb, t, T->ctx); /* block nb: the large components' scratch */
            if (J.its[t] < 0) { res = SFB_CANCELLED; break; }
            T->work_done += T->work_cur;
            T->st.large++;
            res = tbz_progress(T, T->work_done / work_all);
        }
        for (t = 0; t < nt && res == SFB_SUCCESS; ++t) T->st.iterations += J.its[t];
    }
    for (b = 0; b <= TBZ_BLOCKS; ++b) {
        sfb__free(T->ctx, blk[b].w); sfb__free(T->ctx, blk[b].lo); sfb__free(T->ctx, blk[b].lc); sfb__free(T->ctx, blk[b].lw);
        sfb__free(T->ctx, blk[b].co); sfb__free(T->ctx, blk[b].cr); sfb__free(T->ctx, blk[b].cw);
    }
done:
    sfb__free(T->ctx, J.its);
    sfb__free(T->ctx, order);
    sfb__free(T->ctx, ent);
    return res;
}

/* The smooth net's solve, kept for the sharp net. A component of the sharp net's constraints
 * whose rows, unknowns and the points its rows read are those of a smooth-net component is the
 * very same system: CGLS (the same rows in the same order, the same unknowns, the same stopping:
 * T->scale is the same in both nets) would repeat the smooth net's iterations bit for bit, so the sharp net takes
 * that component's smooth solution instead. Most components lie away from every tagged feature,
 * where both nets have the same points: on the bench's torus this cuts the construction by a third.
 * Recorded only when the smooth net kept our tangent plane (no seed-plane fallback). */
typedef struct tbz_prev {
    int ok;
    tbz_sys S;         /* the smooth net's rows (owned) */
    int *erow;         /* per edge: its first row in S, -1: none */
    double *x0;        /* the smooth net before its solve (3 np) */
    const double *x1;  /* after it */
    int *pcomp;        /* per point: its component, -1: not an unknown */
    int *crows, *cunk; /* per component: its rows and unknowns */
} tbz_prev;

static void tbz_prev_free(sfb_context *ctx, tbz_prev *P) {
    sfb__free(ctx, P->S.off); sfb__free(ctx, P->S.edge); sfb__free(ctx, P->S.col); sfb__free(ctx, P->S.w);
    sfb__free(ctx, P->erow); sfb__free(ctx, P->x0); sfb__free(ctx, P->pcomp); sfb__free(ctx, P->crows); sfb__free(ctx, P->cunk);
    memset(P, 0, sizeof *P);
}

/* Per edge its first row in S, -1: none (an edge's rows are consecutive). */
static void tbz_edge_first_rows(const tbz_sys *S, int ne, int *erow) {
    int e, r;
    for (e = 0; e < ne; ++e) erow[e] = -1;
    for (r = S->rows - 1; r >= 0; --r) erow[S->edge[r]] = r;
}

/* The smooth-net component that is the same system as the sharp net's component (rows[0..nr),
 * unk[0..nu)), -1: none (see tbz_prev). erow: the sharp net's tbz_edge_first_rows. */
static int tbz_same_component(const sfb__tbz *T, const tbz_sys *S, const int *erow, const int *ucol, const int *rows, int nr,
                              const int *unk, int nu) {
    const tbz_prev *P = T->prev;
    int r, j, pc;
    if (nr == 0 || nu == 0) return -1;
    pc = P->pcomp[unk[0]];
    if (pc < 0 || P->crows[pc] != nr || P->cunk[pc] != nu) return -1;
    for (j = 1; j < nu; ++j)
        if (P->pcomp[unk[j]] != pc) return -1;
    /* every row the same as one of pc's (so, with the counts equal, the same rows and unknowns) */
    for (r = 0; r < nr; ++r) {
        const int g = rows[r], e = S->edge[g];
        size_t k, pk;
        int pr;
        if (P->erow[e] < 0) return -1;
        pr = P->erow[e] + (g - erow[e]);
        if (pr >= P->S.rows || P->S.edge[pr] != e || S->off[g + 1] - S->off[g] != P->S.off[pr + 1] - P->S.off[pr]) return -1;
        for (k = S->off[g], pk = P->S.off[pr]; k < S->off[g + 1]; ++k, ++pk) {
            const int col = S->col[k];
            if (col != P->S.col[pk] || S->w[k] != P->S.w[pk] || (ucol[col] >= 0) != (P->pcomp[col] >= 0) ||
                memcmp(T->x + 3 * (size_t)col, P->x0 + 3 * (size_t)col, 3 * sizeof(double)) != 0)
                return -1;
        }
    }
    return pc;
}

/* ---- templates: a component around one extraordinary vertex solved once per shape ----
 * After a Loop step or two (and on most meshes' own nets) nearly every component of the
 * constraints is the neighbourhood of one extraordinary vertex, and neighbourhoods of the same
 * shape (the same triangles around the vertex, valences, features, characteristic angles, and
 * the same points unknown) are the same system A dx = b up to the numbering of its points (and
 * the direction its edges' rows are written in, which spans the same rows): its minimum-norm
 * solution is dx = A_I^T (A_I A_I^T)^-1 b_I, I a maximal set of independent rows (the others
 * follow, the system being consistent). CGLS takes 70-600 iterations on each such component (A
 * is nearly square: kappa ~ 50, and a quarter of its rows are dependent), so for a shape seen
 * twice or more I and the Cholesky factor of A_I A_I^T are found once (a template), and each of
 * its components then costs two triangular solves with its residual (tbz_templates). tbz_walk
 * numbers a neighbourhood's points the same way wherever the shape is the same and hashes the
 * shape; every component a template solves is checked (its largest row residual left:
 * tbz_tpl_apply), and one that fails is solved by CGLS instead. */
#define TBZ_WALK_FACES 256     /* the most triangles a walk covers (valence 12 with regular rings: 108) */
#define TBZ_TPL_MAX_UNK 1024   /* larger components are left to CGLS */
/* A component of a shape met once (or not around one extraordinary vertex) of at most this many
 * rows is solved the same way, its template made for it alone: its factor (within the
 * envelopes of tbz_tpl_make's ordering) costs less than CGLS's 70-600 iterations of ~100 nr
 * multiply-adds each (teapot.obj's own net, whose components of 13 to 600 rows are each of its
 * own shape: 0.46 G instructions by CGLS, 0.21 G so) */
#define TBZ_DIRECT_ROWS 640
#define TBZ_DROP 1e-11        /* a factor's rows dropped as dependent: what is left of the diagonal at most this of B's largest */
#define TBZ_DROP_RETRY 1e-14  /* the same for the second try of a region's own factor (tbz_templates) */
typedef struct tbz_walk {
    int *fidx;  /* per face: its index in the walk, -1 (every entry -1 between walks) */
    int *plab;  /* per point: its label, -1 */
    int *vdist; /* per vertex: its distance from the centre (0 to 2), -1 */
    unsigned char *mine; /* per point: 0, and 1 meanwhile for a region's unknowns (tbz_tpl_apply) */
    int face[TBZ_WALK_FACES], rot[TBZ_WALK_FACES], nface;
    int vert[3 * TBZ_WALK_FACES], nvert;
    int lab[15 * TBZ_WALK_FACES], nlab; /* label -> point (tbz_walk_run with labels) */
    int lq[15 * TBZ_WALK_FACES];        /* label -> where first met: 15 x its triangle's place in the walk + its lattice place */
    unsigned long long hash;
} tbz_walk;
static void tbz_walk_mix(unsigned long long *h, long long v) {
    *h = (*h ^ (unsigned long long)v) * 0x9E3779B97F4A7C15ull;
    *h ^= *h >> 29;
}
/* Clears the walk's marks. */
static void tbz_walk_reset(tbz_walk *W) {
    int i;
    for (i = 0; i < W->nface; ++i) W->fidx[W->face[i]] = -1;
    for (i = 0; i < W->nvert; ++i) W->vdist[W->vert[i]] = -1;
    for (i = 0; i < W->nlab; ++i) W->plab[W->lab[i]] = -1;
    W->nface = W->nvert = W->nlab = 0;
}
/* Walks the triangles with a vertex within two edges of v, breadth first across their edges
 * from v's first triangle, each entered at a fixed corner (the first: v; a neighbour: the end of
 * the edge it was entered by), and hashes what the constraints depend on: per corner its
 * valence, type, distance from v and (where not told by those) characteristic angle, per edge
 * the triangle across it and its features. With `label` it also labels the triangles' points in
 * the order met (lab, lq). The points' own part (which coincide, which are unknowns) is left
 * out of the hash: the triangles' adjacency tells the first, the region's numbers of rows and
 * unknowns go into its key (tbz_templates), and tbz_tpl_apply checks that the template's
 * unknowns are the region's and that its rows are met. (Labelling every region's points took
 * half the walks' time, a cache miss per point.) 0: too large (the marks are cleared). */
static int tbz_walk_run(const sfb__tbz *T, int v, tbz_walk *W, int label) {
    const sfb__level *l = T->l;
    int i, j, k, q, head;
    unsigned long long h = 14695981039346656037ull;
    if (tbz_nf(l, v) == 0) return 0;
    W->nface = W->nvert = W->nlab = 0;
    W->vdist[v] = 0;
    W->vert[W->nvert++] = v;
    for (head = 0; head < W->nvert; ++head) {
        const int u = W->vert[head];
        if (W->vdist[u] == 2) continue;
        for (i = l->ve_off[u]; i < l->ve_off[u + 1]; ++i) {
            const int w = sfb__other_end(l, l->ve[i], u);
            if (W->vdist[w] >= 0) continue;
            if (W->nvert == 3 * TBZ_WALK_FACES) { tbz_walk_reset(W); return 0; }
            W->vdist[w] = W->vdist[u] + 1;
            W->vert[W->nvert++] = w;
        }
    }
    {
        const int f0 = l->vf[l->vf_off[v]];
        for (k = 0; k < 3 && l->fv[l->fv_off[f0] + k] != v; ++k) {}
        W->face[0] = f0; W->rot[0] = k; W->fidx[f0] = 0; W->nface = 1;
    }
    for (head = 0; head < W->nface; ++head) {
        const int f = W->face[head], r = W->rot[head], *fv = l->fv + l->fv_off[f];
        for (k = 0; k < 3; ++k) {
            const int s = (r + k) % 3, c = fv[s], e = l->fe[l->fv_off[f] + s], ne2 = l->ef_off[e + 1] - l->ef_off[e];
            int g = -1, nb = -2;
            tbz_walk_mix(&h, tbz_nf(l, c) | tbz_boundary(l, c) << 8 | T->virr[c] << 9 | (long long)T->vtype[c] << 10 | (long long)(W->vdist[c] + 1) << 18);
            if ((T->vtype[c] & 15) != TBZ_SMOOTH && (T->vtype[c] & 15) != TBZ_DART) {
                /* this corner's characteristic angle (a smooth or dart vertex's are all 2 pi / n,
                 * told by the valence and type already) */
                long long bits;
                for (j = l->vf_off[c]; j < l->vf_off[c + 1] && l->vf[j] != f; ++j) {}
                memcpy(&bits, T->phi + j, sizeof bits);
                tbz_walk_mix(&h, bits);
            }
            if (ne2 == 2) g = l->ef[l->ef_off[e]] == f ? l->ef[l->ef_off[e] + 1] : l->ef[l->ef_off[e]];
            if (g >= 0) {
                int near = 0;
                const int *gv = l->fv + l->fv_off[g];
                for (i = 0; i < 3; ++i) near |= W->vdist[gv[i]] >= 0;
                if (!near) nb = -1;
                else if (W->fidx[g] >= 0) nb = W->fidx[g];
                else {
                    const int end = fv[(s + 1) % 3];
                    if (W->nface == TBZ_WALK_FACES) { tbz_walk_reset(W); return 0; }
                    for (i = 0; i < 3 && gv[i] != end; ++i) {}
                    W->fidx[g] = nb = W->nface;
                    W->face[W->nface] = g; W->rot[W->nface++] = i;
                }
            }
            tbz_walk_mix(&h, nb | (long long)T->efeat[e] << 32 | (long long)(T->tag_s[e] > 0.0f) << 33 | (long long)ne2 << 34);
        }
        if (label)
            for (q = 0; q < 15; ++q) {
                const int p = T->grid[15 * (size_t)f + tbz_rot_q(r, q)];
                if (W->plab[p] < 0) { W->plab[p] = W->nlab; W->lq[W->nlab] = 15 * head + q; W->lab[W->nlab++] = p; }
            }
    }
    tbz_walk_mix(&h, W->nface);
    W->hash = h;
    return 1;
}

/* The labels' points of a region whose walk met the triangles face[0 .. ) at corners rot[]
 * (tbz_walk_run), from where the template's walk first met each label (lq[0 .. nlab)). */
static void tbz_walk_points(const sfb__tbz *T, const int *face, const int *rot, const int *lq, int nlab, int *lab) {
    int k;
    for (k = 0; k < nlab; ++k) {
        const int fi = lq[k] / 15;
        lab[k] = T->grid[15 * (size_t)face[fi] + tbz_rot_q(rot[fi], lq[k] - 15 * fi)];
    }
}

typedef struct tbz_tpl {
    int nlab, nu, nrow, nrank; /* the shape's labels, unknowns, rows, independent rows */
    int *ulab;                  /* per unknown column: its label */
    size_t *ro;                 /* the kept (independent) rows, nrank of them in factor order, entries over labels, fixed ones included */
    int *rl, *ru;               /* per entry: its label, and its unknown column (-1: a fixed point) */
    double *rw;
    double *lf;                 /* the Cholesky factor of those rows' A A^T, row a's envelope (columns lfirst[a] .. a) at lo[a] */
    int *lfirst;
    size_t *lo;
} tbz_tpl;
static void tbz_tpl_free(sfb_context *ctx, tbz_tpl *P) {
    sfb__free(ctx, P->ulab); sfb__free(ctx, P->ro); sfb__free(ctx, P->rl); sfb__free(ctx, P->rw);
    sfb__free(ctx, P->lfirst); sfb__free(ctx, P->lo);
    sfb__free(ctx, P->ru); sfb__free(ctx, P->lf);
    memset(P, 0, sizeof *P);
}

/* sum a[k] b[k], k < n, in four partial sums (a single one waits on each add in turn) */
static double tbz_dot(const double *a, const double *b, int n) {
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    int k;
    for (k = 0; k + 4 <= n; k += 4) {
        s0 += a[k] * b[k]; s1 += a[k + 1] * b[k + 1]; s2 += a[k + 2] * b[k + 2]; s3 += a[k + 3] * b[k + 3];
    }
    for (; k < n; ++k) s0 += a[k] * b[k];
    return (s0 + s1) + (s2 + s3);
}

/* The reverse Cuthill-McKee order of the graph of the symmetric nr x nr matrix B (i ~ j where
 * B[i][j] != 0; row i's columns bj[bo[i] .. bo[i + 1]), rising, its diagonal among them) into
 * ord: breadth first from a node of least degree at the far end of the graph (one pass of George
 * and Liu's search for a peripheral node), each node's new neighbours by rising degree, the
 * whole reversed; each connected part in turn. deg: nr ints, mark: 2 nr. */
static void tbz_rcm(const size_t *bo, const int *bj, int nr, int *ord, int *deg, int *mark) {
    int *lev = mark + nr, i, n = 0;
    size_t k;
    for (i = 0; i < nr; ++i) {
        deg[i] = 0;
        for (k = bo[i]; k < bo[i + 1]; ++k) deg[i] += bj[k] != i;
        mark[i] = 0;
    }
    while (n < nr) {
        int start = -1, pass, head, n0 = n;
        for (i = 0; i < nr; ++i)
            if (!mark[i] && (start < 0 || deg[i] < deg[start])) start = i;
        for (pass = 0; pass < 2; ++pass) {
            /* breadth first from start, levels in lev; the first pass only finds the far end */
            n = n0;
            ord[n++] = start;
            mark[start] = pass + 1;
            lev[start] = 0;
            for (head = n0; head < n; ++head) {
                const int u = ord[head], from = n;
                for (k = bo[u]; k < bo[u + 1]; ++k) {
                    const int j = bj[k];
                    if (mark[j] != pass + 1) {
                        int q = n++;
                        mark[j] = pass + 1;
                        lev[j] = lev[u] + 1;
                        while (q > from && deg[ord[q - 1]] > deg[j]) { ord[q] = ord[q - 1]; --q; }
                        ord[q] = j;
                    }
                }
            }
            if (pass == 0) {
                /* the last level's node of least degree */
                start = ord[n - 1];
                for (i = n - 1; i >= n0 && lev[ord[i]] == lev[ord[n - 1]]; --i)
                    if (deg[ord[i]] < deg[start]) start = ord[i];
            }
        }
    }
    for (i = 0, n = nr - 1; i < n; ++i, --n) { const int t = ord[i]; ord[i] = ord[n]; ord[n] = t; }
}

/* Builds template P from component i, plab its points' labels (nlab of them: a walk's, or the
 * order its rows read them in for a factor of its own: tbz_templates). 0: out of memory or a
 * point of its rows unlabelled (P left empty). Sparse throughout: B = A A^T by rows (a row
 * meets a dozen others), the factor within its envelopes (teapot.obj's regions of their own
 * shape, up to 640 rows: the dense B and factor, nr^2 each to clear and scan, were a third of
 * its build). */
static int tbz_tpl_make(sfb__tbz *T, const tbz_sys *S, const tbz_comps *C, int i, const int *plab, int nlab, double drop, tbz_tpl *P) {
    const int nr = C->rstart[i + 1] - C->rstart[i], nu = C->ustart[i + 1] - C->ustart[i];
    const int *rows = C->rows + C->rstart[i], *unk = C->unk + C->ustart[i];
    const size_t ent = tbz_comp_entries(S, C, i);
    int *uidx = (int *)sfb__alloc(T->ctx, ((size_t)nlab + 1) * sizeof(int));
    /* per row: its place in the factor order, the kept rows, their first columns, the kept
     * place of a row (-1: not (yet) kept), B's touched columns */
    int *piv = (int *)sfb__alloc(T->ctx, (5 * (size_t)nr + 1) * sizeof(int)), *kept = piv + nr, *first = kept + nr, *kpos = first + nr,
        *touch = kpos + nr;
    int *mark = (int *)sfb__alloc(T->ctx, (2 * (size_t)nr + 1) * sizeof(int)); /* tbz_rcm's scratch */
    size_t *cst = (size_t *)sfb__calloc(T->ctx, (size_t)nu + 2, sizeof(size_t));
    size_t *rst = (size_t *)sfb__calloc(T->ctx, (size_t)nr + 2, sizeof(size_t));
    size_t *bo = (size_t *)sfb__alloc(T->ctx, ((size_t)nr + 1) * sizeof(size_t));
    int *crow = (int *)sfb__alloc(T->ctx, (ent + 1) * sizeof(int)), *rcol = (int *)sfb__alloc(T->ctx, (ent + 1) * sizeof(int)), *bj = NULL;
    double *cw = (double *)sfb__alloc(T->ctx, (ent + 1) * sizeof(double)), *rw = (double *)sfb__alloc(T->ctx, (ent + 1) * sizeof(double));
    double *acc = (double *)sfb__calloc(T->ctx, (size_t)nr + 1, sizeof(double)); /* a row of B, by row; zero between uses */
    double *lk = (double *)sfb__alloc(T->ctx, ((size_t)nr + 1) * sizeof(double)); /* the factor's row being made, by kept place */
    double *bv = NULL;
    int *deg = (int *)sfb__alloc(T->ctx, ((size_t)nr + 1) * sizeof(int)); /* tbz_rcm's degrees */
    int ok = 0, r, a, b, u, k, rank = 0;
    size_t e, e2, n = 0, nb = 0, capb = 0, env = 0;
    double dmax = 0.0;
    memset(P, 0, sizeof *P);
    if (!uidx || !piv || !mark || !cst || !rst || !bo || !crow || !rcol || !cw || !rw || !acc || !lk || !deg) goto done;
    for (k = 0; k < nlab; ++k) uidx[k] = -1;
    P->nlab = nlab; P->nu = nu; P->nrow = nr;
    P->ulab = (int *)sfb__alloc(T->ctx, ((size_t)nu + 1) * sizeof(int));
    if (!P->ulab) goto done;
    for (u = 0; u < nu; ++u) {
        const int lb = plab[unk[u]];
        if (lb < 0) goto done;
        P->ulab[u] = lb; uidx[lb] = u;
    }
    /* A by columns: per unknown its row entries (a row's entries on one point are summed by
     * the products below, A A^T being bilinear); every point its rows read labelled */
    for (r = 0; r < nr; ++r)
        for (e = S->off[rows[r]]; e < S->off[rows[r] + 1]; ++e) {
            const int lb = plab[S->col[e]];
            if (lb < 0) goto done;
            if (uidx[lb] >= 0) { ++cst[uidx[lb] + 2]; ++rst[r + 2]; }
            ++n;
        }
    for (u = 0; u < nu; ++u) cst[u + 2] += cst[u + 1];
    for (r = 0; r < nr; ++r) rst[r + 2] += rst[r + 1];
    for (r = 0; r < nr; ++r)
        for (e = S->off[rows[r]]; e < S->off[rows[r] + 1]; ++e) {
            const int ui = uidx[plab[S->col[e]]];
            if (ui >= 0) { crow[cst[ui + 1]] = r; cw[cst[ui + 1]++] = S->w[e]; }
        }
    /* and by rows, each row's entries by rising column (so B's sums below add their terms in
     * the order of a column-by-column product) */
    for (u = 0; u < nu; ++u)
        for (e = cst[u]; e < cst[u + 1]; ++e) { rcol[rst[crow[e] + 1]] = u; rw[rst[crow[e] + 1]++] = cw[e]; }
    /* B = A A^T row by row: row r's entries times their columns' entries (a few hundred
     * products), its nonzero columns rising; mark[r2] = r + 1 once row r touched r2 */
    for (r = 0; r < nr; ++r) mark[r] = 0;
    for (r = 0; r < nr; ++r) {
        int nt = 0, t;
        bo[r] = nb;
        for (e = rst[r]; e < rst[r + 1]; ++e) {
            const int cu = rcol[e];
            for (e2 = cst[cu]; e2 < cst[cu + 1]; ++e2) {
                const int r2 = crow[e2];
                if (mark[r2] != r + 1) { mark[r2] = r + 1; touch[nt++] = r2; }
                acc[r2] += rw[e] * cw[e2];
            }
        }
        /* rising (a row has a few dozen) */
        for (t = 1; t < nt; ++t) {
            const int x = touch[t];
            int q = t;
            while (q > 0 && touch[q - 1] > x) { touch[q] = touch[q - 1]; --q; }
            touch[q] = x;
        }
        if (nb + (size_t)nt > capb) {
            const size_t nc = 2 * capb + (size_t)nt + 1024;
            int *j2 = (int *)sfb__realloc(T->ctx, bj, nc * sizeof(int));
            double *v2;
            if (!j2) goto done;
            bj = j2;
            v2 = (double *)sfb__realloc(T->ctx, bv, nc * sizeof(double));
            if (!v2) goto done;
            bv = v2;
            capb = nc;
        }
        for (t = 0; t < nt; ++t) {
            const int r2 = touch[t];
            if (acc[r2] != 0.0) { bj[nb] = r2; bv[nb++] = acc[r2]; }
            if (r2 == r) dmax = TBZ_MAX(dmax, acc[r2]);
            acc[r2] = 0.0;
        }
    }
    bo[nr] = nb;
    /* the rows in reverse Cuthill-McKee order of B's graph (rows sharing an unknown), which
     * keeps each row of the factor within a narrow envelope: its first nonzero is that of B's
     * row, and the products below run over the envelopes alone (a 300-row component: about a
     * tenth of the dense factor's multiply-adds, and the same for the solves of each use) */
    tbz_rcm(bo, bj, nr, piv, deg, mark);
    /* the factor's room: each row's envelope in that order with no row dropped (dropping only
     * narrows them) */
    for (a = 0; a < nr; ++a) kpos[piv[a]] = a;
    for (a = 0; a < nr; ++a) {
        int f = a;
        for (e = bo[piv[a]]; e < bo[piv[a] + 1]; ++e) f = kpos[bj[e]] < f ? kpos[bj[e]] : f;
        env += (size_t)(a - f + 1);
    }
    P->lf = (double *)sfb__alloc(T->ctx, (env + 1) * sizeof(double));
    P->lfirst = (int *)sfb__alloc(T->ctx, ((size_t)nr + 1) * sizeof(int));
    P->lo = (size_t *)sfb__alloc(T->ctx, ((size_t)nr + 1) * sizeof(size_t));
    if (!P->lf || !P->lfirst || !P->lo) goto done;
    for (r = 0; r < nr; ++r) kpos[r] = -1;
    /* Cholesky, row by row in that order (up-looking), a row that depends on those before it
     * (what is left of its diagonal at most `drop` of B's largest, TBZ_DROP: some rows' weights
     * on the unknowns are rounding residue, of norm 1e-16, and must go too) dropped: B is semidefinite
     * and a quarter of its rows are dependent; their b follows from the others' when the system
     * is consistent, which the check after each use confirms. Row k of the factor (the k-th
     * kept row, of row kept[k]) holds columns first[k] .. k, at P->lo[k] of P->lf; B's row is
     * spread into acc meanwhile. */
    for (k = 0, a = 0, e2 = 0; a < nr; ++a) {
        const int p = piv[a];
        double dd = 0.0;
        int f = k;
        for (e = bo[p]; e < bo[p + 1]; ++e) {
            acc[bj[e]] = bv[e];
            if (kpos[bj[e]] >= 0 && kpos[bj[e]] < f) f = kpos[bj[e]];
        }
        for (b = f; b < k; ++b) {
            const int lo2 = first[b] > f ? first[b] : f;
            const double *lb = P->lf + P->lo[b] - first[b]; /* lb[c]: column c of row b */
            lk[b] = (acc[kept[b]] - tbz_dot(lk + lo2, lb + lo2, b - lo2)) / lb[b];
        }
        dd = acc[p] - tbz_dot(lk + f, lk + f, k - f);
        for (e = bo[p]; e < bo[p + 1]; ++e) acc[bj[e]] = 0.0;
        if (!(dd > drop * dmax)) continue;
        lk[k] = sqrt(dd);
        first[k] = f;
        P->lo[k] = e2;
        for (b = f; b <= k; ++b) P->lf[e2++] = lk[b];
        kpos[p] = k;
        kept[k++] = p;
    }
    rank = k;
    P->nrank = rank;
    P->ro = (size_t *)sfb__alloc(T->ctx, ((size_t)rank + 1) * sizeof(size_t));
    P->rl = (int *)sfb__alloc(T->ctx, (n + 1) * sizeof(int));
    P->ru = (int *)sfb__alloc(T->ctx, (n + 1) * sizeof(int));
    P->rw = (double *)sfb__alloc(T->ctx, (n + 1) * sizeof(double));
    if (!P->ro || !P->rl || !P->ru || !P->rw) goto done;
    /* the factor's first columns, and the kept rows over labels */
    n = 0;
    for (a = 0; a < rank; ++a) {
        const int g = rows[kept[a]];
        P->lfirst[a] = first[a];
        P->ro[a] = n;
        for (e2 = S->off[g]; e2 < S->off[g + 1]; ++e2) {
            P->rl[n] = plab[S->col[e2]];
            P->ru[n] = uidx[P->rl[n]];
            P->rw[n++] = S->w[e2];
        }
    }
    P->ro[rank] = n;
    ok = 1;
done:
    if (!ok) tbz_tpl_free(T->ctx, P);
    sfb__free(T->ctx, uidx); sfb__free(T->ctx, piv); sfb__free(T->ctx, mark); sfb__free(T->ctx, cst); sfb__free(T->ctx, rst);
    sfb__free(T->ctx, bo); sfb__free(T->ctx, crow); sfb__free(T->ctx, rcol); sfb__free(T->ctx, cw); sfb__free(T->ctx, rw);
    sfb__free(T->ctx, acc); sfb__free(T->ctx, lk); sfb__free(T->ctx, bj); sfb__free(T->ctx, bv); sfb__free(T->ctx, deg);
    return ok;
}

/* Solves component i with template P, lab[0 .. nlab) the points of its walk's labels: 1 when its
 * rows are then met (the rule below), else 0 with
 * the net as it was. dx: 6 nu doubles, y: 3 P->nrank; mine: per point 0, and 0 again after;
 * *worst: the largest row residual left, relative to the scale (as tbz_solve's stats). */
static int tbz_tpl_apply(sfb__tbz *T, const tbz_sys *S, const tbz_comps *C, int i, const int *lab, int nlab, const tbz_tpl *P, double *dx,
                         double *y, unsigned char *mine, double *worst) {
    const int nr = C->rstart[i + 1] - C->rstart[i], nu = C->ustart[i + 1] - C->ustart[i];
    const int *rows = C->rows + C->rstart[i], *unk = C->unk + C->ustart[i];
    double *step = dx + 3 * (size_t)nu;
    int a, u, c, r, same = 1, pass, ok;
    size_t e;
    if (nlab != P->nlab || nu != P->nu || nr != P->nrow) return 0;
    /* the template's unknowns are the component's (as many, and each one of them) */
    for (u = 0; u < nu; ++u) mine[unk[u]] = 1;
    for (u = 0; u < nu; ++u) same &= mine[lab[P->ulab[u]]];
    for (u = 0; u < nu; ++u) mine[unk[u]] = 0;
    if (!same) return 0;
    /* y = the kept rows' residual b; L L^T y' = y (forward, then backward with L's rows);
     * dx = A^T y' over the unknown entries. Where a row is left above the rule a second pass
     * solves for what the first left (one step of iterative refinement: 3 of cow.obj's 1,444
     * components pass after it). The rule: each row's residual at most 1e-15 of the scale times
     * the sum of its weights' magnitudes (at least 1), which is about the rounding of evaluating
     * the row at all: with 1e-15 of the scale alone (CGLS's stopping rule, which iterates until
     * rounding happens to fall under it) half of spot.obj's components failed, by 1-2e-15 */
    /* dx: the unknowns as they were, put back bit for bit where the check fails (subtracting
     * the change again would not: CGLS would then start from a net a rounding away) */
    for (u = 0; u < nu; ++u)
        for (c = 0; c < 3; ++c) dx[3 * u + c] = T->x[3 * (size_t)lab[P->ulab[u]] + c];
    for (pass = 0; pass < 2; ++pass) {
        for (a = 0; a < P->nrank; ++a) {
            double bv[3] = {0.0, 0.0, 0.0};
            const double *lr = P->lf + P->lo[a] - P->lfirst[a]; /* lr[b]: column b, lfirst[a] <= b <= a */
            double b2[3] = {0.0, 0.0, 0.0}; /* two partial sums (one waits on each add in turn) */
            int b;
            for (e = P->ro[a]; e < P->ro[a + 1]; ++e) tbz_axpy(bv, -P->rw[e], T->x + 3 * (size_t)lab[P->rl[e]]);
            for (b = P->lfirst[a]; b + 2 <= a; b += 2) {
                tbz_axpy(bv, -lr[b], y + 3 * b);
                tbz_axpy(b2, -lr[b + 1], y + 3 * b + 3);
            }
            if (b < a) tbz_axpy(bv, -lr[b], y + 3 * b);
            for (c = 0; c < 3; ++c) y[3 * a + c] = (bv[c] + b2[c]) / lr[a];
        }
        for (a = P->nrank - 1; a >= 0; --a) {
            const double *lr = P->lf + P->lo[a] - P->lfirst[a];
            int b;
            for (c = 0; c < 3; ++c) y[3 * a + c] /= lr[a];
            for (b = P->lfirst[a]; b < a; ++b) tbz_axpy(y + 3 * b, -lr[b], y + 3 * a);
        }
        for (u = 0; u < 3 * nu; ++u) step[u] = 0.0;
        for (a = 0; a < P->nrank; ++a)
            for (e = P->ro[a]; e < P->ro[a + 1]; ++e)
                if (P->ru[e] >= 0) tbz_axpy(step + 3 * P->ru[e], P->rw[e], y + 3 * a);
        for (u = 0; u < nu; ++u) tbz_axpy(T->x + 3 * (size_t)lab[P->ulab[u]], 1.0, step + 3 * u);
        for (r = 0, ok = 1, *worst = 0.0; r < nr && ok; ++r) {
            double v[3], wsum = 0.0;
            tbz_dot3(S->col, S->w, S->off[rows[r]], S->off[rows[r] + 1], T->x, v);
            for (e = S->off[rows[r]]; e < S->off[rows[r] + 1]; ++e) wsum += fabs(S->w[e]);
            for (c = 0; c < 3; ++c) {
                ok &= fabs(v[c]) <= 1e-15 * T->scale * TBZ_MAX(1.0, wsum);
                *worst = TBZ_MAX(*worst, fabs(v[c]) / T->scale);
            }
        }
        if (ok && !(T->flags & SFB__TBZ_REJECT_TEMPLATES)) return 1;
    }
    for (u = 0; u < nu; ++u)
        for (c = 0; c < 3; ++c) T->x[3 * (size_t)lab[P->ulab[u]] + c] = dx[3 * u + c];
    return 0;
}

/* Asks for the net's points at idx[0 .. n) ahead of their use (the next region's, while this one
 * is solved: its points lie scattered over the net, each a cache miss on first touch). */
static void tbz_prefetch_points(const sfb__tbz *T, const int *idx, int n) {
#if defined(__GNUC__) || defined(__clang__)
    int k;
    for (k = 0; k < n; ++k) __builtin_prefetch(T->x + 3 * (size_t)idx[k]);
#else
    (void)T; (void)idx; (void)n;
#endif
}

typedef struct tbz_key { unsigned long long hash; int t; size_t at; int nface; } tbz_key; /* at: its walk's triangles and corners in wfr */
static int tbz_key_cmp(const void *pa, const void *pb) {
    const tbz_key *a = (const tbz_key *)pa, *b = (const tbz_key *)pb;
    if (a->hash != b->hash) return a->hash < b->hash ? -1 : 1;
    return a->t < b->t ? -1 : a->t > b->t;
}

/* Solves the components todo[0 .. *nt) that a template can (see above) and leaves the others
 * in todo, in order; cres[c]: component c's largest row residual left, where solved here. A component shares a template when its rows' edges have exactly one
 * irregular end among them (the centre of its walk), it has at most TBZ_TPL_MAX_UNK unknowns
 * and its shape is met twice or more; the others of at most TBZ_DIRECT_ROWS rows get one of
 * their own; what fails its check is left to CGLS. */
static sfb_result tbz_templates(sfb__tbz *T, const tbz_sys *S, const tbz_comps *C, int *todo, int *nt, double *cres) {
    const sfb__level *l = T->l;
    tbz_walk *W = (tbz_walk *)sfb__alloc(T->ctx, sizeof(tbz_walk));
    tbz_key *key = (tbz_key *)sfb__alloc(T->ctx, ((size_t)*nt + 1) * sizeof(tbz_key));
    int *centre = (int *)sfb__alloc(T->ctx, ((size_t)*nt + 1) * sizeof(int));
    unsigned char *done = (unsigned char *)sfb__calloc(T->ctx, (size_t)*nt + 1, 1);
    double *dx = NULL;
    int *wfr = NULL; /* every walk's triangles, then the corners they were entered at, one walk after the other */
    int *dl = NULL;  /* a directly solved component's label -> point map */
    int *lq = NULL, *lab2 = NULL; /* a template's labels, where its walk met them; two regions' label -> point maps */
    size_t nwfr = 0, capwfr = 0, capdl = 0, capdx = 0;
    int t, nk = 0, g, i, m = 0, maxu = 0, maxr = 0, tried = 0;
    sfb_result res = SFB_SUCCESS;
    if (*nt == 0 || (*nt == 1 && C->rstart[todo[0] + 1] - C->rstart[todo[0]] > TBZ_DIRECT_ROWS)) { /* nothing to do here: nothing to allocate */
        sfb__free(T->ctx, W); sfb__free(T->ctx, key); sfb__free(T->ctx, centre); sfb__free(T->ctx, done);
        return SFB_SUCCESS;
    }
    if (W) { W->fidx = NULL; W->plab = NULL; W->vdist = NULL; W->mine = NULL; }
    if (!W || !key || !centre || !done) { res = sfb__oom(T->ctx, "tribezier templates"); goto out; }
    W->fidx = (int *)sfb__alloc(T->ctx, ((size_t)T->nf + 1) * sizeof(int));
    W->plab = (int *)sfb__alloc(T->ctx, ((size_t)T->np + 1) * sizeof(int));
    W->vdist = (int *)sfb__alloc(T->ctx, ((size_t)T->nv + 1) * sizeof(int));
    W->mine = (unsigned char *)sfb__calloc(T->ctx, (size_t)T->np + 1, 1);
    lq = (int *)sfb__alloc(T->ctx, 15 * TBZ_WALK_FACES * sizeof(int));
    lab2 = (int *)sfb__alloc(T->ctx, 2 * 15 * TBZ_WALK_FACES * sizeof(int));
    if (!W->fidx || !W->plab || !W->vdist || !W->mine || !lq || !lab2) { res = sfb__oom(T->ctx, "tribezier templates"); goto out; }
    for (i = 0; i < T->nf; ++i) W->fidx[i] = -1;
    for (i = 0; i < T->np; ++i) W->plab[i] = -1;
    for (i = 0; i < T->nv; ++i) W->vdist[i] = -1;
    W->nface = W->nvert = W->nlab = 0;
    /* each qualifying component's shape */
    for (t = 0; t < *nt; ++t) {
        const int c = todo[t], nu = C->ustart[c + 1] - C->ustart[c];
        int r, v = -1, two = 0;
        centre[t] = -1;
        if (nu > TBZ_TPL_MAX_UNK) continue;
        for (r = C->rstart[c]; r < C->rstart[c + 1] && !two; ++r) {
            const int e = S->edge[C->rows[r]];
            for (i = 0; i < 2; ++i) {
                const int w = l->ev[2 * e + i];
                if (T->virr[w]) { if (v < 0) v = w; else if (w != v) two = 1; }
            }
        }
        if (v < 0 || two || !tbz_walk_run(T, v, W, 0)) continue;
        if (nwfr + 2 * (size_t)W->nface > capwfr) {
            const size_t nc = 2 * capwfr + 2 * (size_t)W->nface + 4096;
            int *l2 = (int *)sfb__realloc(T->ctx, wfr, nc * sizeof(int));
            if (!l2) { tbz_walk_reset(W); res = sfb__oom(T->ctx, "tribezier templates"); goto out; }
            wfr = l2;
            capwfr = nc;
        }
        memcpy(wfr + nwfr, W->face, (size_t)W->nface * sizeof(int));
        memcpy(wfr + nwfr + W->nface, W->rot, (size_t)W->nface * sizeof(int));
        centre[t] = v;
        /* the shape: the walk's, and the region's numbers of unknowns and rows */
        tbz_walk_mix(&W->hash, nu);
        tbz_walk_mix(&W->hash, C->rstart[c + 1] - C->rstart[c]);
        key[nk].hash = W->hash; key[nk].t = t; key[nk].at = nwfr; key[nk++].nface = W->nface;
        nwfr += 2 * (size_t)W->nface;
        maxu = nu > maxu ? nu : maxu;
        maxr = C->rstart[c + 1] - C->rstart[c] > maxr ? C->rstart[c + 1] - C->rstart[c] : maxr;
        tbz_walk_reset(W);
    }
    qsort(key, (size_t)nk, sizeof *key, tbz_key_cmp);
    capdx = 6 * (size_t)maxu + 3 * (size_t)maxr; /* and y (rank <= rows) */
    dx = (double *)sfb__alloc(T->ctx, (capdx + 1) * sizeof(double));
    if (!dx) { res = sfb__oom(T->ctx, "tribezier templates"); goto out; }
    /* per shape met twice or more: its template, from its first component, used on every one */
    for (g = 0; g < nk && res == SFB_SUCCESS; g = m) {
        tbz_tpl P;
        int made, nlab, *cur = lab2, *next = lab2 + 15 * TBZ_WALK_FACES;
        for (m = g + 1; m < nk && key[m].hash == key[g].hash; ++m) {}
        if (m - g < 2) continue;
        made = tbz_walk_run(T, centre[key[g].t], W, 1) && tbz_tpl_make(T, S, C, todo[key[g].t], W->plab, W->nlab, TBZ_DROP, &P);
        nlab = W->nlab;
        memcpy(lq, W->lq, (size_t)nlab * sizeof(int));
        tbz_walk_reset(W);
        if (!made) continue;
        T->st.templates++;
        /* each region's points from its walk; the next region's asked for while this one is solved */
        tbz_walk_points(T, wfr + key[g].at, wfr + key[g].at + key[g].nface, lq, nlab, cur);
        for (i = g; i < m && res == SFB_SUCCESS; ++i) {
            const int ti = key[i].t;
            if (i + 1 < m) {
                tbz_walk_points(T, wfr + key[i + 1].at, wfr + key[i + 1].at + key[i + 1].nface, lq, nlab, next);
                tbz_prefetch_points(T, next, nlab);
            }
            if (tbz_tpl_apply(T, S, C, todo[ti], cur, nlab, &P, dx, dx + 6 * (size_t)maxu, W->mine, cres + todo[ti])) {
                done[ti] = 1;
                T->st.templated++;
            }
            /* progress (and a cancel) every 64 components, over the share of the components */
            if ((++tried & 63) == 0) res = tbz_progress(T, (double)tried / *nt);
            { int *sw = cur; cur = next; next = sw; }
        }
        tbz_tpl_free(T->ctx, &P);
    }
    /* the components left (a shape met once, or not around one extraordinary vertex) of up to
     * TBZ_DIRECT_ROWS rows: the same solve with a template made for each alone, its points
     * labelled in the order its rows read them */
    for (t = 0; t < *nt && res == SFB_SUCCESS; ++t) {
        const int c = todo[t], nr = C->rstart[c + 1] - C->rstart[c], nu = C->ustart[c + 1] - C->ustart[c];
        const size_t need = tbz_comp_entries(S, C, c), nd = 6 * (size_t)nu + 3 * (size_t)nr;
        tbz_tpl P;
        int nl = 0, r, made, k;
        size_t e;
        if (done[t] || nr == 0 || nr > TBZ_DIRECT_ROWS) continue;
        if (need > capdl) {
            int *l2 = (int *)sfb__realloc(T->ctx, dl, (need + 1) * sizeof(int));
            if (!l2) { res = sfb__oom(T->ctx, "tribezier templates"); break; }
            dl = l2;
            capdl = need;
        }
        if (nd > capdx) {
            double *d2 = (double *)sfb__realloc(T->ctx, dx, (nd + 1) * sizeof(double));
            if (!d2) { res = sfb__oom(T->ctx, "tribezier templates"); break; }
            dx = d2;
            capdx = nd;
        }
        for (r = C->rstart[c]; r < C->rstart[c + 1]; ++r)
            for (e = S->off[C->rows[r]]; e < S->off[C->rows[r] + 1]; ++e)
                if (W->plab[S->col[e]] < 0) { W->plab[S->col[e]] = nl; dl[nl++] = S->col[e]; }
        /* a factor dropping rows down to TBZ_DROP, and where its check fails once more keeping
         * rows down to TBZ_DROP_RETRY. A row left just above TBZ_DROP can be independent by a
         * little: dropping it left one of teapot.obj's regions (564 rows) at 4e-15 of the scale
         * against the check's 2e-15, and CGLS then took 363 iterations (a third of its build)
         * for what the factor keeping it meets; kept, the check decides as always */
        for (made = 0, k = 0; k < 2 && !done[t]; ++k) {
            if (!tbz_tpl_make(T, S, C, c, W->plab, nl, k ? TBZ_DROP_RETRY : TBZ_DROP, &P)) break;
            if (!k) { made = 1; T->st.direct++; }
            if (tbz_tpl_apply(T, S, C, c, dl, nl, &P, dx, dx + 6 * (size_t)nu, W->mine, cres + c)) { done[t] = 1; T->st.templated++; }
            tbz_tpl_free(T->ctx, &P);
        }
        for (i = 0; i < nl; ++i) W->plab[dl[i]] = -1;
        if (!made) continue;
        if ((++tried & 63) == 0) res = tbz_progress(T, (double)tried / *nt);
    }
    if (res != SFB_SUCCESS) goto out;
    for (t = 0, i = 0; t < *nt; ++t)
        if (!done[t]) todo[i++] = todo[t];
    T->pbase = *nt > 0 ? (double)(*nt - i) / *nt : 0.0; /* CGLS's reports go on from there */
    *nt = i;
out:
    if (W) { sfb__free(T->ctx, W->fidx); sfb__free(T->ctx, W->plab); sfb__free(T->ctx, W->vdist); sfb__free(T->ctx, W->mine); }
    sfb__free(T->ctx, W); sfb__free(T->ctx, key); sfb__free(T->ctx, centre); sfb__free(T->ctx, done); sfb__free(T->ctx, dx);
    sfb__free(T->ctx, wfr); sfb__free(T->ctx, dl); sfb__free(T->ctx, lq); sfb__free(T->ctx, lab2);
    return res;
}

/* The frame of our extraordinary crease vertex v: d along the crease (its two crease
 * neighbours' difference), n the crease's own normal: the bisector of the mean unit normals of
 * the mesh triangles on its two sides (the vertical of the test's valley, whatever the
 * triangles' count on each side; the smooth net's tangent plane there tilts with that count),
 * made orthogonal to d. Returns 0 where there is none (the sides folded onto each other). */
static int tbz_crease_frame(const sfb__tbz *T, int v, double d[3], double n[3]) {
    const sfb__level *l = T->l;
    const int m = l->ve_off[v + 1] - l->ve_off[v], nf = tbz_nf(l, v);
    double sn[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}, len = 0.0, dn = 0.0;
    int j, c, side, first = -1, other = -1;
    for (j = 0; j < m; ++j)
        if (T->tag_s[l->ve[l->ve_off[v] + j]] > 0.0f) { if (first < 0) first = j; else other = j; }
    if (first < 0 || other < 0) return 0;
    for (c = 0; c < 3; ++c) {
        d[c] = (double)T->pos[3 * (size_t)tbz_ring(l, v, first) + c] - T->pos[3 * (size_t)tbz_ring(l, v, other) + c];
        len += d[c] * d[c];
    }
    if (!(len > 0.0)) return 0;
    len = sqrt(len);
    for (c = 0; c < 3; ++c) d[c] /= len;
    /* triangle j lies between spokes j and j + 1 (an interior vertex: m = nf) */
    for (j = 0; j < nf; ++j) {
        const int f = l->vf[l->vf_off[v] + j], *fv = l->fv + l->fv_off[f];
        double a[3], b[3], x[3], q;
        side = j >= first && j < other ? 0 : 1;
        for (c = 0; c < 3; ++c) {
            a[c] = (double)T->pos[3 * (size_t)fv[1] + c] - T->pos[3 * (size_t)fv[0] + c];
            b[c] = (double)T->pos[3 * (size_t)fv[2] + c] - T->pos[3 * (size_t)fv[0] + c];
        }
        sfb__cross3(a, b, x);
        q = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        if (q > 0.0)
            for (c = 0; c < 3; ++c) sn[side][c] += x[c] / q;
    }
    for (side = 0; side < 2; ++side) {
        const double q = sqrt(sn[side][0] * sn[side][0] + sn[side][1] * sn[side][1] + sn[side][2] * sn[side][2]);
        if (!(q > 0.0)) return 0;
        for (c = 0; c < 3; ++c) sn[side][c] /= q;
    }
    for (c = 0; c < 3; ++c) { n[c] = sn[0][c] + sn[1][c]; dn += n[c] * d[c]; }
    for (c = 0; c < 3; ++c) n[c] -= dn * d[c];
    len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 1e-6)) return 0;
    for (c = 0; c < 3; ++c) n[c] /= len;
    return 1;
}

/* The profile the second pass holds the crease to near our vertex v: the first pass's crease
 * points (the two crease edges at v, and the next two beyond their ends where those are ordinary
 * crease vertices, with the vertices between) keep their place along the crease and take, along
 * n, a parabola z = c u^2 in u = along d from v's corner, one c per side fitted to them by least
 * squares (the corner and its tangents, fixed, have z = 0 and slope 0: n is orthogonal to the
 * crease tangent), and along the lateral l = n x d one fitted the same way, y = c' u^2. Each
 * side's curve then bends one way, as the surface does there, where the first pass's wiggled
 * (its least-norm change spread over the crease's points), and sideways no more than its
 * points beyond do on average (the first pass bent it off the crease's vertical plane near v
 * where the triangles' angles there differ on its two sides, valence 5 and 7; tbz_take_second
 * keeps that hold only where it is nearly free).
 * Holding the initial profile instead (the B-spline's point with the smooth offset at v, Sabin's
 * beyond) made the neighbours absorb the whole correction: blotched highlight lines at valence 5
 * on the panel's domed disk. */
static void tbz_crease_fit(sfb__tbz *T) {
    const sfb__level *l = T->l;
    const double *X1 = T->straight_x;
    int v, j, c, k, i;
    for (v = 0; v < T->nv; ++v) {
        double d[3], n[3], lat[3];
        const double *P = T->x + 3 * (size_t)v;
        int rays[2], nr = 0;
        if (!tbz_ours(T, v) || !tbz_crease_frame(T, v, d, n)) continue;
        for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j)
            if (T->tag_s[l->ve[j]] > 0.0f && nr < 2) rays[nr++] = l->ve[j];
        sfb__cross3(n, d, lat);
        for (k = 0; k < nr; ++k) {
            int pts[6], np = 0, e = rays[k], w = sfb__other_end(l, e, v), e2 = -1;
            double suz = 0.0, suy = 0.0, su4 = 0.0, cf, cl, u[6], z[6], y[6];
            pts[np++] = tbz_ep(T, e, 1);
            pts[np++] = tbz_ep(T, e, l->ev[2 * e] == w ? 0 : 2);
            if (!tbz_ours(T, w) && !tbz_boundary(l, w) && !(T->corner_s[w] > 0.0f)) {
                int nt = 0;
                for (j = l->ve_off[w]; j < l->ve_off[w + 1]; ++j)
                    if (T->tag_s[l->ve[j]] > 0.0f) { ++nt; if (l->ve[j] != e) e2 = l->ve[j]; }
                if (nt != 2) e2 = -1;
            }
            if (e2 >= 0) {
                pts[np++] = tbz_vp(T, w);
                pts[np++] = tbz_ep(T, e2, l->ev[2 * e2] == w ? 0 : 2);
                pts[np++] = tbz_ep(T, e2, 1);
                pts[np++] = tbz_ep(T, e2, l->ev[2 * e2] == w ? 2 : 0);
            }
            /* each point's place from v's corner: along d, n and l */
            for (i = 0; i < np; ++i) {
                u[i] = z[i] = y[i] = 0.0;
                for (c = 0; c < 3; ++c) {
                    const double q = X1[3 * (size_t)pts[i] + c] - P[c];
                    u[i] += q * d[c]; z[i] += q * n[c]; y[i] += q * lat[c];
                }
                suz += u[i] * u[i] * z[i]; suy += u[i] * u[i] * y[i]; su4 += u[i] * u[i] * u[i] * u[i];
            }
            if (!(su4 > 0.0)) continue;
            cf = suz / su4; cl = suy / su4;
            for (i = 0; i < np; ++i) {
                double *x = T->x + 3 * (size_t)pts[i];
                const double *x1 = X1 + 3 * (size_t)pts[i];
                if (T->fixed[pts[i]] || T->dist[pts[i]] > TBZ_REACH) continue; /* not an unknown: the first pass's */
                for (c = 0; c < 3; ++c) x[c] = x1[c] + (cf * u[i] * u[i] - z[i]) * n[c] + (cl * u[i] * u[i] - y[i]) * lat[c];
            }
        }
    }
}

/* Two solutions of a component's rows mixed point by point with one constant matrix M, x1 +
 * M (x - x1), are a solution too: the rows treat every coordinate alike. The second pass
 * (tbz_crease_points) mixes the weighted solve's solution x into the first pass's x1 with the
 * frame (d, n) of the component's (first) extraordinary crease vertex with our plane
 * (tbz_crease_frame; the lateral l = n x d): M = I - d d^T, the change across the crease from
 * the weighted solve, which holds the crease curve's profile along n and its place along l
 * (tbz_crease_fit), and the slide along the crease from the first pass; or, where that bends
 * the surface (tbz_take_second), M = n n^T, the profile alone. Held in every direction
 * (M = I), the crease also kept its slide along itself and the surface beside it paid: the
 * net's bending +4 to +25 % on tests/tribezier.c's disks, and wavy highlight lines beside the
 * crease at valence 5. Returns 0 where the component has no such frame. */
static int tbz_mix_frame(const sfb__tbz *T, const tbz_sys *S, const int *rows, int nr, double d[3], double n[3]) {
    const sfb__level *l = T->l;
    int r, j, v = -1;
    for (r = 0; r < nr && v < 0; ++r) {
        const int e = S->edge[rows[r]];
        for (j = 0; j < 2 && v < 0; ++j)
            if (tbz_ours(T, l->ev[2 * e + j])) v = l->ev[2 * e + j];
    }
    return v >= 0 && tbz_crease_frame(T, v, d, n);
}
/* x = x1 + M (x2 - x1) over the unknowns unk: M = n n^T (across 0), or I - d d^T (across 1) */
static void tbz_mix(sfb__tbz *T, const int *unk, int nu, const double *x2, const double d[3], const double n[3], int across) {
    const double *X1 = T->straight_x;
    int j, c;
    for (j = 0; j < nu; ++j) {
        double *x = T->x + 3 * (size_t)unk[j], dd = 0.0, dn = 0.0;
        const double *x1 = X1 + 3 * (size_t)unk[j], *y = x2 + 3 * (size_t)j;
        for (c = 0; c < 3; ++c) { dd += (y[c] - x1[c]) * d[c]; dn += (y[c] - x1[c]) * n[c]; }
        for (c = 0; c < 3; ++c) x[c] = across ? y[c] - dd * d[c] : x1[c] + dn * n[c];
    }
}

/* The bending of a net around a component (tbz_take_second): the squared second differences of
 * the Bezier points along the three lattice directions of each triangle, summed over the
 * triangles with a point in it (a fairness measure of the control net; both nets compared share
 * the lattice). */
static double tbz_face_bend(const sfb__tbz *T, int f) {
    static const int dir[3][3] = {{1, -1, 0}, {0, 1, -1}, {-1, 0, 1}};
    const double *x = T->x;
    double e = 0.0;
    int a, b, k, c;
    for (k = 0; k < 3; ++k)
        for (a = 0; a <= 4; ++a)
            for (b = 0; a + b <= 4; ++b) {
                int w0[3], w1[3], w2[3], q, ok = 1;
                w0[0] = a; w0[1] = b; w0[2] = 4 - a - b;
                for (q = 0; q < 3; ++q) {
                    w1[q] = w0[q] + dir[k][q]; w2[q] = w0[q] + 2 * dir[k][q];
                    ok &= w1[q] >= 0 && w1[q] <= 4 && w2[q] >= 0 && w2[q] <= 4;
                }
                if (!ok) continue;
                {
                    const double *p0 = x + 3 * (size_t)tbz_gpt(T, f, w0), *p1 = x + 3 * (size_t)tbz_gpt(T, f, w1), *p2 = x + 3 * (size_t)tbz_gpt(T, f, w2);
                    for (c = 0; c < 3; ++c) e += (p0[c] - 2.0 * p1[c] + p2[c]) * (p0[c] - 2.0 * p1[c] + p2[c]);
                }
            }
    return e;
}

/* The curvature energy of the surface (the integral of k1^2 + k2^2 over the area) on triangle
 * f of the current net, the fairness the second pass's hold across the crease is held to
 * (tbz_take_second): a 7-point rule (degree 5) on the (s, t) triangle; the quartic Bernstein
 * basis and its first and second derivatives at those places, with their weights, made once
 * per net (tbz_energy_rule: TBZ_QN x 6 x 15 + TBZ_QN doubles). The rule on each quarter of the
 * triangle (28 places) moved the ratios the choice rests on by 0.001 at most and made cow.obj's
 * build after two Loop steps about 30 % slower. A geometric measure: the net's bending
 * (tbz_face_bend) also counts how its points spread along the surface, and rose 19 % for that
 * hold on the level undulation disk of valence 5 (tests/tribezier.c) where this rose 0.7 %. */
#define TBZ_QN 7
static void tbz_energy_rule(double *B, double *wq) {
    static const double qp[TBZ_QN][3] = {{1.0 / 3, 1.0 / 3, 0.225},
                                         {0.0597158717, 0.4701420641, 0.1323941527}, {0.4701420641, 0.0597158717, 0.1323941527},
                                         {0.4701420641, 0.4701420641, 0.1323941527}, {0.7974269853, 0.1012865073, 0.1259391805},
                                         {0.1012865073, 0.7974269853, 0.1259391805}, {0.1012865073, 0.1012865073, 0.1259391805}};
    int m, k, q;
    for (m = 0; m < TBZ_QN; ++m) {
        double Bq[6][15];
        sfb__bez15_basis(qp[m][0], qp[m][1], 6, Bq);
        for (k = 0; k < 6; ++k)
            for (q = 0; q < 15; ++q) B[((size_t)m * 6 + k) * 15 + q] = Bq[k][q];
        wq[m] = qp[m][2] / 2.0; /* the (s, t) triangle's area is 1/2 */
    }
}
static double tbz_face_energy(const sfb__tbz *T, const double *B, const double *wq, int f) {
    const int *g = T->grid + 15 * (size_t)f;
    double e = 0.0;
    int p, k, q, c;
    for (p = 0; p < TBZ_QN; ++p) {
        double D[6][3], nv[3], len, E, F, G, L, M, N, det;
        memset(D, 0, sizeof D);
        for (k = 1; k < 6; ++k)
            for (q = 0; q < 15; ++q) {
                const double b = B[((size_t)p * 6 + k) * 15 + q], *x = T->x + 3 * (size_t)g[q];
                for (c = 0; c < 3; ++c) D[k][c] += b * x[c];
            }
        sfb__cross3(D[1], D[2], nv);
        len = sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
        if (!(len > 0.0)) continue;
        for (c = 0; c < 3; ++c) nv[c] /= len;
        E = D[1][0] * D[1][0] + D[1][1] * D[1][1] + D[1][2] * D[1][2];
        F = D[1][0] * D[2][0] + D[1][1] * D[2][1] + D[1][2] * D[2][2];
        G = D[2][0] * D[2][0] + D[2][1] * D[2][1] + D[2][2] * D[2][2];
        L = D[3][0] * nv[0] + D[3][1] * nv[1] + D[3][2] * nv[2];
        M = D[4][0] * nv[0] + D[4][1] * nv[1] + D[4][2] * nv[2];
        N = D[5][0] * nv[0] + D[5][1] * nv[1] + D[5][2] * nv[2];
        det = E * G - F * F;
        if (!(det > 0.0)) continue;
        {
            /* k1^2 + k2^2 = 4 H^2 - 2 K; dA = |Ps x Pt| ds dt */
            const double H = (E * N - 2.0 * F * M + G * L) / (2.0 * det), K = (L * N - M * M) / det;
            e += wq[p] * (4.0 * H * H - 2.0 * K) * len;
        }
    }
    return e;
}

/* The second pass taken per component around our vertex (ours == 1), in two steps:
 *   - the profile (M = n n^T, tbz_mix) where it leaves the net about as fair as the first pass:
 *     its bending (tbz_face_bend) over the triangles with a point in the component within
 *     TBZ_FAIR of the first's; else the first pass's points back. Measured (tests/tribezier.c):
 *     the issue's straight creases through valence 4, 5 and 7 -0.1 to +2.3 % (kept); the domed
 *     disks of tests/tribezier.c's coarse meshes and the panel at valence 4 and 7 +0 to +2.6 %
 *     (kept), at valence 5 +7 to +126 % (their highlight lines blotched beside the vertex: the
 *     first pass's);
 *   - then the crease's place across it too (M = I - d d^T: the second pass's change in every
 *     direction but along the crease), where the surface's curvature energy over those
 *     triangles (tbz_face_energy) is within TBZ_FAIR_ACROSS of the profile's alone. Measured:
 *     -0.2 to +0.3 % on the crease disks of valence 4 and 9 to 12 and on the undulation disks
 *     of valence 4 and 7 (kept), +0.7 % on the level undulation disk of valence 5 (kept: its
 *     crease 8e-5 mean edges off the plane instead of 0.0017), +1.3 % on the fanned one (given
 *     back: Loop's own limit lies 0.015 off the plane there). Judged by the net's bending it
 *     would have cost +19 % at valence 5: the hold moves the points along the surface more
 *     than it bends it. */
#define TBZ_FAIR 0.03
#define TBZ_FAIR_ACROSS 0.01
static sfb_result tbz_take_second(sfb__tbz *T, const tbz_sys *S, int nc, const int *rstart, const int *rows, const int *ustart, const int *unk,
                                  const unsigned char *ours) {
    const double *X1 = T->straight_x;
    int *comp = (int *)sfb__alloc(T->ctx, ((size_t)T->np + 1) * sizeof(int));
    int *fstart = (int *)sfb__calloc(T->ctx, (size_t)nc + 2, sizeof(int)), *flist = NULL;
    double *B = (double *)sfb__alloc(T->ctx, (TBZ_QN * 90 + TBZ_QN) * sizeof(double)), *wq, *x2 = NULL;
    int i, j, f, q, mu = 0;
    sfb_result res = SFB_SUCCESS;
    for (i = 0; i < nc; ++i) mu = TBZ_MAX(mu, ustart[i + 1] - ustart[i]);
    x2 = (double *)sfb__alloc(T->ctx, 3 * (size_t)mu * sizeof(double) + 1);
    flist = (int *)sfb__alloc(T->ctx, (size_t)T->nf * sizeof(int) + 1);
    if (!comp || !fstart || !B || !x2 || !flist) { res = sfb__oom(T->ctx, "tribezier"); goto out; }
    wq = B + TBZ_QN * 90;
    tbz_energy_rule(B, wq);
    for (i = 0; i < T->np; ++i) comp[i] = -1;
    for (i = 0; i < nc; ++i)
        if (ours[i] == 1)
            for (j = ustart[i]; j < ustart[i + 1]; ++j) comp[unk[j]] = i;
    /* the triangles of each component (one with points in two: the first found's) */
    for (f = 0; f < T->nf; ++f) {
        const int *g = T->grid + 15 * (size_t)f;
        for (q = 0; q < 15 && comp[g[q]] < 0; ++q) {}
        if (q < 15) fstart[comp[g[q]] + 2]++;
    }
    for (i = 0; i < nc; ++i) fstart[i + 2] += fstart[i + 1];
    for (f = 0; f < T->nf; ++f) {
        const int *g = T->grid + 15 * (size_t)f;
        for (q = 0; q < 15 && comp[g[q]] < 0; ++q) {}
        if (q < 15) flist[fstart[comp[g[q]] + 1]++] = f;
    }
    for (i = 0; i < nc; ++i) {
        const int nu = ustart[i + 1] - ustart[i], *uk = unk + ustart[i], *fl = flist + fstart[i], nfc = fstart[i + 1] - fstart[i];
        double d[3], n[3], b1 = 0.0, bn = 0.0;
        int kept = 0;
        if (ours[i] != 1) continue;
        for (j = 0; j < nu; ++j) memcpy(x2 + 3 * (size_t)j, T->x + 3 * (size_t)uk[j], 3 * sizeof(double));
        for (j = 0; j < nu; ++j) memcpy(T->x + 3 * (size_t)uk[j], X1 + 3 * (size_t)uk[j], 3 * sizeof(double));
        if (!tbz_mix_frame(T, S, rows + rstart[i], rstart[i + 1] - rstart[i], d, n)) continue; /* M = 0 */
        for (f = 0; f < nfc; ++f) b1 += tbz_face_bend(T, fl[f]);
        tbz_mix(T, uk, nu, x2, d, n, 0);
        for (f = 0; f < nfc; ++f) bn += tbz_face_bend(T, fl[f]);
        if (bn <= (1.0 + TBZ_FAIR) * b1) {
            double en = 0.0, ea = 0.0;
            kept = 1;
            for (f = 0; f < nfc; ++f) en += tbz_face_energy(T, B, wq, fl[f]);
            tbz_mix(T, uk, nu, x2, d, n, 1);
            for (f = 0; f < nfc; ++f) ea += tbz_face_energy(T, B, wq, fl[f]);
            if (ea <= (1.0 + TBZ_FAIR_ACROSS) * en) T->st.straight_across++;
            else tbz_mix(T, uk, nu, x2, d, n, 0);
        }
        if (!kept) {
            for (j = 0; j < nu; ++j) memcpy(T->x + 3 * (size_t)uk[j], X1 + 3 * (size_t)uk[j], 3 * sizeof(double));
            T->st.straight_unfair++;
        }
    }
out:
    sfb__free(T->ctx, comp);
    sfb__free(T->ctx, fstart);
    sfb__free(T->ctx, flist);
    sfb__free(T->ctx, B);
    sfb__free(T->ctx, x2);
    return res;
}

/* The seed's open problem (section 5: "a small undulation is observed around the extraordinary
 * vertex when s = 0.5 ... This must be conquered"), met. At s the crease curve is (1 - s) x the
 * smooth net's + s x the sharp net's. The sharp one is the crease's B-spline. The smooth one
 * starts as Loop's curve (Sabin's rules; at our extraordinary crease vertex the B-spline's point
 * and tangents moved by the smooth offset, tbz_ours_offset), and the G1 solve then moves it: its
 * least-norm change spreads over every unknown in reach, the crease's points among them, and bent
 * the curve by 0.0005-0.002 mean edges with six curvature sign changes within two edges of the
 * vertex (tests/tribezier.c, undulation), the crease's at every s < 1.
 * So the smooth net is solved twice where there is such a vertex (sfb__tribezier_points): the
 * first pass as before; the second around those vertices alone, with the points on tagged edges
 * (and the crease vertices' corners) started on a parabola fitted to the first pass's
 * (tbz_crease_fit) and weighted, their moves costing TBZ_CREASE_WEIGHT^-2 times another point's;
 * each component around such a vertex then takes the second pass's change along the crease's
 * normal (and across the crease too where that is nearly free) and the first's along the
 * crease (tbz_mix), if that leaves it about as fair (tbz_take_second).
 * Fixing those points instead left the rows unsolvable:
 * around a vertex with as many triangles on both sides (even valence) the constraints need them
 * to slide along the crease, and on jittered meshes to move across it by 1e-3 of the mesh.
 * Marks the unknowns (ucol >= 0) on the smooth net's crease curves in wsc; returns how many. */
#define TBZ_CREASE_WEIGHT (1.0 / 1024.0)
static int tbz_crease_points(const sfb__tbz *T, const int *ucol, unsigned char *wsc) {
    const sfb__level *l = T->l;
    int e, q, n = 0;
    for (e = 0; e < T->ne; ++e)
        if (T->tag_s[e] > 0.0f && l->ef_off[e + 1] - l->ef_off[e] == 2) {
            const int pts[5] = {tbz_vp(T, l->ev[2 * e]), tbz_ep(T, e, 0), tbz_ep(T, e, 1), tbz_ep(T, e, 2), tbz_vp(T, l->ev[2 * e + 1])};
            for (q = 0; q < 5; ++q)
                if (ucol[pts[q]] >= 0 && !wsc[pts[q]]) { wsc[pts[q]] = 1; ++n; }
        }
    return n;
}

/* Applies the smallest change of the unknowns that satisfies the constraints: the minimum-norm
 * least-squares solution, per connected component of the constraint graph (the solution of a
 * block-diagonal system is the blocks' solutions; each block converges at its own pace, so a
 * slow block near touching extraordinary vertices does not hold the others up). */
static sfb_result tbz_solve(sfb__tbz *T) {
    const sfb__level *l = T->l;
    tbz_sys S;
    unsigned char *ours = NULL;
    tbz_comps C;
    int *ucol = NULL, *rstart, *ustart, *rows, *unk, *local = NULL, *erow = NULL, *todo = NULL;
    tbz_prev *rec = T->rec && !T->sharp ? T->rec : NULL;
    unsigned char *near = NULL, *wsc = NULL;
    int nu = 0, e, i, r, nc, nt = 0, any16, nw = 0;
    double scale = 0.0, *cres = NULL; /* per component: its residual where a template solved it, else -1 */
    sfb_result res = SFB_SUCCESS;
    memset(&S, 0, sizeof S);
    memset(&C, 0, sizeof C);
    /* an edge's rows read points of its two triangles only: with no unknown in either it has
     * none (tbz_edge_rows); near[f]: triangle f has one */
    near = (unsigned char *)sfb__alloc(T->ctx, (size_t)T->nf + 1);
    if (!near) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    for (i = 0; i < T->nf; ++i) {
        const int *g = T->grid + 15 * (size_t)i;
        int q, any = 0;
        for (q = 0; q < 15; ++q) any |= !T->fixed[g[q]] && T->dist[g[q]] <= TBZ_REACH;
        near[i] = (unsigned char)any;
    }
#define TBZ_ROW_EDGE(e) (l->ef_off[(e) + 1] - l->ef_off[e] == 2 && !T->efeat[e] && (near[l->ef[l->ef_off[e]]] || near[l->ef[l->ef_off[e] + 1]]))
    {
        /* room for every candidate's five rows at once, 32 entries (tbz_edge_rows: 4, 8, 8, 8
         * and 4; growing by doubling copied them over and over: a third of the rows' time after
         * two Loop steps) */
        size_t cand = 0;
        for (e = 0; e < T->ne; ++e) cand += TBZ_ROW_EDGE(e);
        S.cap = 32 * cand + 1;
        S.cap_rows = (int)(5 * cand + 2);
        S.col = (int *)sfb__alloc(T->ctx, S.cap * sizeof(int));
        S.w = (double *)sfb__alloc(T->ctx, S.cap * sizeof(double));
        S.off = (size_t *)sfb__alloc(T->ctx, ((size_t)S.cap_rows + 1) * sizeof(size_t));
        S.edge = (int *)sfb__alloc(T->ctx, ((size_t)S.cap_rows + 1) * sizeof(int));
        if (!S.col || !S.w || !S.off || !S.edge) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    }
    for (e = 0; e < T->ne; ++e)
        if (TBZ_ROW_EDGE(e)) {
            S.cur_edge = e;
            if (!tbz_edge_rows(T, &S, e)) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
        }
#undef TBZ_ROW_EDGE
    if (S.rows == 0) goto done;
    ucol = (int *)sfb__alloc(T->ctx, (size_t)T->np * sizeof(int));
    if (!ucol) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    for (i = 0; i < T->np; ++i) ucol[i] = (!T->fixed[i] && T->dist[i] <= TBZ_REACH) ? nu++ : -1;
    scale = T->scale;
    /* the smooth net's crease curves move as little as the constraints let them: their unknowns'
     * columns scaled by TBZ_CREASE_WEIGHT, and their points divided by it for the solve (both
     * exact: a power of two), so the least-norm change weighs a move of theirs 1 / w^2 times
     * (tbz_crease_points) */
    if (T->straight_x) {
        wsc = (unsigned char *)sfb__calloc(T->ctx, (size_t)T->np + 1, 1);
        if (!wsc) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
        nw = tbz_crease_points(T, ucol, wsc);
        if (nw) {
            size_t k;
            for (k = 0; k < S.off[S.rows]; ++k)
                if (wsc[S.col[k]]) S.w[k] *= TBZ_CREASE_WEIGHT;
            for (i = 0; i < T->np; ++i)
                if (wsc[i])
                    for (r = 0; r < 3; ++r) T->x[3 * (size_t)i + r] /= TBZ_CREASE_WEIGHT;
        }
    }
    if ((res = tbz_components(T, &S, ucol, nu, &C)) != SFB_SUCCESS) goto done;
    nc = C.nc; rstart = C.rstart; ustart = C.ustart; rows = C.rows; unk = C.unk;
    if (rec) {
        /* the net before the solve, and the components (tbz_prev); S joins them at the end */
        rec->x0 = (double *)sfb__alloc(T->ctx, 3 * (size_t)T->np * sizeof(double) + 1);
        rec->erow = (int *)sfb__alloc(T->ctx, ((size_t)T->ne + 1) * sizeof(int));
        rec->pcomp = (int *)sfb__alloc(T->ctx, ((size_t)T->np + 1) * sizeof(int));
        rec->crows = (int *)sfb__alloc(T->ctx, ((size_t)nc + 1) * sizeof(int));
        rec->cunk = (int *)sfb__alloc(T->ctx, ((size_t)nc + 1) * sizeof(int));
        if (!rec->x0 || !rec->erow || !rec->pcomp || !rec->crows || !rec->cunk) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
        memcpy(rec->x0, T->x, 3 * (size_t)T->np * sizeof(double));
        tbz_edge_first_rows(&S, T->ne, rec->erow);
        for (i = 0; i < T->np; ++i) rec->pcomp[i] = -1;
        for (i = 0; i < nc; ++i) {
            int j;
            rec->crows[i] = rstart[i + 1] - rstart[i];
            rec->cunk[i] = ustart[i + 1] - ustart[i];
            for (j = ustart[i]; j < ustart[i + 1]; ++j) rec->pcomp[unk[j]] = i;
        }
    }
    if (T->prev && T->prev->ok) {
        erow = (int *)sfb__alloc(T->ctx, ((size_t)T->ne + 1) * sizeof(int));
        if (!erow) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
        tbz_edge_first_rows(&S, T->ne, erow);
    }
    todo = (int *)sfb__alloc(T->ctx, ((size_t)nc + 1) * sizeof(int));
    if (!todo) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    /* components at an extraordinary crease vertex with our plane (this net's, or in the
     * fallback the first net's) */
    ours = (unsigned char *)sfb__calloc(T->ctx, (size_t)nc + 1, 1);
    if (!ours) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    any16 = T->reuse_ours != NULL; /* none: no row to look at */
    for (i = 0; i < T->nv && !any16; ++i) any16 = tbz_ours(T, i);
    for (i = 0; i < nc && any16; ++i)
        for (r = rstart[i]; r < rstart[i + 1] && !ours[i]; ++r) {
            const int e2 = S.edge[rows[r]], a = l->ev[2 * e2], b = l->ev[2 * e2 + 1];
            ours[i] = (unsigned char)(tbz_ours(T, a) || tbz_ours(T, b) ||
                                      (T->reuse_ours && (T->reuse_ours[a] || T->reuse_ours[b])));
        }
    for (i = 0; i < nc; ++i) {
        const int u0 = ustart[i], cu = ustart[i + 1] - u0;
        int j;
        if (T->straight_x && ours[i] && rstart[i + 1] - rstart[i] > TBZ_DIRECT_ROWS) {
            /* the second pass: a component of several vertices merged, too large for a dense
             * solve; CGLS on the weighted rows converged 4 times slower (cow.obj after one Loop
             * step, 11.9 s instead of 3.3) and did not reach the residual. It keeps the first
             * pass's net, its crease as the first solve bent it */
            ours[i] = 2;
            T->st.straight_skipped++;
        }
        if (T->reuse_x && (!ours[i] || ours[i] == 2)) {
            for (j = 0; j < cu; ++j)
                for (r = 0; r < 3; ++r)
                    T->x[3 * (size_t)unk[u0 + j] + r] = T->reuse_x[3 * (size_t)unk[u0 + j] + r] / (wsc && wsc[unk[u0 + j]] ? TBZ_CREASE_WEIGHT : 1.0);
            continue;
        }
        if (erow) {
            const int pc = tbz_same_component(T, &S, erow, ucol, rows + rstart[i], rstart[i + 1] - rstart[i], unk + u0, cu);
            if (pc >= 0) {
                for (j = 0; j < cu; ++j)
                    for (r = 0; r < 3; ++r) T->x[3 * (size_t)unk[u0 + j] + r] = T->prev->x1[3 * (size_t)unk[u0 + j] + r];
                T->st.reused++;
                continue;
            }
        }
        todo[nt++] = i;
    }
    cres = (double *)sfb__alloc(T->ctx, ((size_t)nc + 1) * sizeof(double));
    if (!cres) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
    for (i = 0; i < nc; ++i) cres[i] = -1.0;
    if (!(T->flags & SFB__TBZ_NO_TEMPLATES) && (res = tbz_templates(T, &S, &C, todo, &nt, cres)) != SFB_SUCCESS) goto done;
    if (nt > 0) {
        /* what is left for CGLS: each unknown's column in its component, -1 elsewhere */
        local = (int *)sfb__alloc(T->ctx, (size_t)T->np * sizeof(int));
        if (!local) { res = sfb__oom(T->ctx, "tribezier constraints"); goto done; }
        for (i = 0; i < T->np; ++i) local[i] = -1;
        for (i = 0; i < nt; ++i) {
            int j;
            for (j = ustart[todo[i]]; j < ustart[todo[i] + 1]; ++j) local[unk[j]] = j - ustart[todo[i]];
        }
    }
    if ((res = tbz_solve_todo(T, &S, &C, local, todo, nt, scale)) != SFB_SUCCESS) goto done;
    /* the residual left, relative to T->scale; and that of the components around an
     * extraordinary crease vertex with our tangent plane (vtype CREASE | 16), which decides the
     * fallback to the seed's plane (sfb__tribezier_points) */
    {
        for (i = 0; i < nc; ++i) {
            double ci = cres[i]; /* >= 0: a template's, found by its check */
            if (ci < 0.0) {
                ci = 0.0;
                for (r = rstart[i]; r < rstart[i + 1]; ++r) {
                    int c;
                    for (c = 0; c < 3; ++c) {
                        double v = 0.0;
                        size_t k;
                        for (k = S.off[rows[r]]; k < S.off[rows[r] + 1]; ++k) v += S.w[k] * T->x[3 * (size_t)S.col[k] + c];
                        ci = TBZ_MAX(ci, fabs(v) / scale);
                    }
                }
            }
            T->st.residual = TBZ_MAX(T->st.residual, ci);
            if (ours[i]) T->st.ours_residual = TBZ_MAX(T->st.ours_residual, ci);
            if (ours[i] && T->bad_v && ci > TBZ_OURS_RESIDUAL)
                for (r = rstart[i]; r < rstart[i + 1]; ++r) {
                    const int e2 = S.edge[rows[r]], a = l->ev[2 * e2], b = l->ev[2 * e2 + 1];
                    if (tbz_ours(T, a)) T->bad_v[a] = 1;
                    if (tbz_ours(T, b)) T->bad_v[b] = 1;
                }
        }
    }
    T->st.unknowns += nu;
    T->st.constraints += S.rows;
    T->st.crease_weighted += nw;
    if (nw) {
        /* back from the weighted columns; then, per component around our vertex, the normal part
         * of the change (and the lateral) from this solve and the rest from the first
         * (tbz_take_second) */
        for (i = 0; i < T->np; ++i)
            if (wsc[i])
                for (r = 0; r < 3; ++r) T->x[3 * (size_t)i + r] *= TBZ_CREASE_WEIGHT;
        nw = 0;
        if ((res = tbz_take_second(T, &S, nc, rstart, rows, ustart, unk, ours)) != SFB_SUCCESS) goto done;
    }
    if (rec) { /* the rows join the record */
        rec->S = S;
        memset(&S, 0, sizeof S);
        rec->ok = 1;
    }
done:
    T->pbase = 0.0;
    if (nw)
        for (i = 0; i < T->np; ++i)
            if (wsc[i])
                for (r = 0; r < 3; ++r) T->x[3 * (size_t)i + r] *= TBZ_CREASE_WEIGHT;
    sfb__free(T->ctx, near);
    sfb__free(T->ctx, wsc);
    sfb__free(T->ctx, S.off); sfb__free(T->ctx, S.edge); sfb__free(T->ctx, S.col); sfb__free(T->ctx, S.w);
    sfb__free(T->ctx, ucol); sfb__free(T->ctx, local); sfb__free(T->ctx, erow);
    sfb__free(T->ctx, C.rows); sfb__free(T->ctx, C.unk); sfb__free(T->ctx, C.rstart); sfb__free(T->ctx, C.ustart);
    sfb__free(T->ctx, ours); sfb__free(T->ctx, todo); sfb__free(T->ctx, cres);
    return res;
}

/* Builds the net of the current state into T->x. */
static sfb_result tbz_state(sfb__tbz *T, int sharp) {
    sfb_result r;
    T->sharp = sharp;
    tbz_classify(T);
    tbz_initial(T);
    if ((r = tbz_distances(T)) != SFB_SUCCESS) return r;
    if (T->straight_x) {
        /* the second pass solves around our vertices only: every point out of their reach is
         * the first pass's (the first net satisfies the rows, so the smaller system has a
         * solution; it was 2x the first pass's time solving the whole net again) */
        int i;
        for (i = 0; i < T->np; ++i)
            if (T->dist[i] > TBZ_REACH) memcpy(T->x + 3 * (size_t)i, T->straight_x + 3 * (size_t)i, 3 * sizeof(double));
        tbz_crease_fit(T);
    }
    return tbz_solve(T);
}

/* The vertices with our plane whose smooth net failed: with bad (not NULL) holding those in a
 * component with a row left unmet (tbz_solve), marks in it too those with a patch corner
 * (nearly) degenerate, parallel edge tangents, in a triangle of theirs (at the vertex or at a
 * corner beside it, whose tangents the solve around it moved). Returns how many are marked
 * (bad NULL: how many triangles of such vertices have such a corner). */
static int tbz_ours_bad(const sfb__tbz *T, unsigned char *bad) {
    const sfb__level *l = T->l;
    int f, k, c, n = 0, v;
    for (f = 0; f < T->nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        int ours = 0, degen = 0;
        for (k = 0; k < 3; ++k) ours |= tbz_ours(T, fv[k]);
        if (!ours) continue;
        for (k = 0; k < 3 && !degen; ++k) {
            int w[3], p0, p1, p2;
            double a[3], b[3], x[3], la = 0, lb = 0;
            w[k] = 4; w[(k + 1) % 3] = 0; w[(k + 2) % 3] = 0;
            p0 = tbz_gpt(T, f, w);
            w[k] = 3; w[(k + 1) % 3] = 1;
            p1 = tbz_gpt(T, f, w);
            w[(k + 1) % 3] = 0; w[(k + 2) % 3] = 1;
            p2 = tbz_gpt(T, f, w);
            for (c = 0; c < 3; ++c) {
                a[c] = T->x[3 * (size_t)p1 + c] - T->x[3 * (size_t)p0 + c];
                b[c] = T->x[3 * (size_t)p2 + c] - T->x[3 * (size_t)p0 + c];
                la += a[c] * a[c]; lb += b[c] * b[c];
            }
            sfb__cross3(a, b, x);
            degen = !(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) > 1e-6 * sqrt(la * lb));
        }
        if (!degen) continue;
        if (!bad) { ++n; continue; }
        for (k = 0; k < 3; ++k)
            if (tbz_ours(T, fv[k])) bad[fv[k]] = 1;
    }
    if (bad)
        for (v = 0; v < T->nv; ++v) n += bad[v] != 0;
    return n;
}

/* s per feature: the tag clamped to [0, 1] (infinite: 1), or (override) s; a feature at s = 0
 * 1e-30, so that it is still one (the nets depend on which features there are, not on their s).
 * Returns whether there is one. */
static int tbz_tag_values(sfb__tbz *T, int override, float s) {
    const sfb__level *l = T->l;
    int e, v, any = 0;
    for (e = 0; e < T->ne; ++e)
        if (l->ef_off[e + 1] - l->ef_off[e] == 2 && l->es[e] > 0.0f) {
            T->tag_s[e] = override ? s : (l->es[e] < 1.0f ? l->es[e] : 1.0f);
            if (T->tag_s[e] <= 0.0f) T->tag_s[e] = 1e-30f; /* a feature at s = 0: the smooth net's treatment */
            any = 1;
        }
    for (v = 0; v < T->nv; ++v)
        if (l->vs[v] > 0.0f && !(tbz_boundary(l, v) && tbz_nf(l, v) == 1)) {
            T->corner_s[v] = override ? s : (l->vs[v] < 1.0f ? l->vs[v] : 1.0f);
            if (T->corner_s[v] <= 0.0f) T->corner_s[v] = 1e-30f;
            any = 1;
        }
    return any;
}

/* The slider (tribezier.slider): where the level the nets are built on (L) came from -- per L
 * edge and vertex the base mesh's (NULL: the same ids), and the base mesh's counts and tags --,
 * and what the build leaves for sfb_surface_set_sharpness: both nets per patch in float
 * (SFB__TBZ_BLEND floats) and how each point's s follows from the features (sfb__tbz_features). */
typedef struct tbz_origin {
    const int *e, *v;
    int nbe, nbv;
    const float *bes, *bvs;
} tbz_origin;
typedef struct tbz_slider {
    tbz_origin org;
    float *blend;
    sfb__tbz_features *F;
} tbz_slider;

static void tbz_slider_free(sfb_context *ctx, tbz_slider *sv) {
    sfb__free(ctx, sv->blend);
    sfb__tbz_features_free(ctx, sv->F);
    sv->blend = NULL;
    sv->F = NULL;
}

void sfb__tbz_features_free(sfb_context *ctx, sfb__tbz_features *F) {
    if (!F) return;
    sfb__free(ctx, F->src); sfb__free(ctx, F->eoff); sfb__free(ctx, F->eid); sfb__free(ctx, F->corner); sfb__free(ctx, F->pv);
    sfb__free(ctx, F->es); sfb__free(ctx, F->cs);
    sfb__free(ctx, F);
}

/* The features of L for the slider (T classified, its tag_s and corner_s set: which edges and
 * vertices are features does not depend on their s): the edges tbz_vertex_s sums, as base edges,
 * the corners it takes, its breadth-first sources, each patch's triangle; and the base mesh's
 * tags, clamped. */
static sfb_result tbz_features_make(sfb__tbz *T, const tbz_origin *org, sfb__tbz_features **out) {
    const sfb__level *l = T->l;
    sfb__tbz_features *F = (sfb__tbz_features *)sfb__calloc(T->ctx, 1, sizeof *F);
    int v, i, f, n = 0, head = 0, tail = 0, held = 0;
    int *queue = NULL;
    *out = NULL;
    if (!F) return sfb__oom(T->ctx, "tribezier slider");
    for (f = 0; f < l->nf; ++f) held += !l->fhole[f];
    F->nv = l->nv; F->nbe = org->nbe; F->nbv = org->nbv;
    F->src = (int *)sfb__alloc(T->ctx, ((size_t)l->nv + 1) * sizeof(int));
    F->eoff = (int *)sfb__alloc(T->ctx, ((size_t)l->nv + 1) * sizeof(int));
    F->eid = (int *)sfb__alloc(T->ctx, ((size_t)l->ve_off[l->nv] + 1) * sizeof(int));
    F->corner = (int *)sfb__alloc(T->ctx, ((size_t)l->nv + 1) * sizeof(int));
    F->pv = (int *)sfb__alloc(T->ctx, 3 * (size_t)held * sizeof(int) + 1);
    F->es = (float *)sfb__calloc(T->ctx, (size_t)org->nbe + 1, sizeof(float));
    F->cs = (float *)sfb__calloc(T->ctx, (size_t)org->nbv + 1, sizeof(float));
    queue = (int *)sfb__alloc(T->ctx, ((size_t)l->nv + 1) * sizeof(int));
    if (!F->src || !F->eoff || !F->eid || !F->corner || !F->pv || !F->es || !F->cs || !queue) {
        sfb__tbz_features_free(T->ctx, F);
        sfb__free(T->ctx, queue);
        return sfb__oom(T->ctx, "tribezier slider");
    }
    for (i = 0; i < org->nbe; ++i) F->es[i] = org->bes[i] > 0.0f ? (org->bes[i] < 1.0f ? org->bes[i] : 1.0f) : 0.0f;
    for (i = 0; i < org->nbv; ++i) F->cs[i] = org->bvs[i] > 0.0f ? (org->bvs[i] < 1.0f ? org->bvs[i] : 1.0f) : 0.0f;
    for (v = 0; v < l->nv; ++v) {
        F->eoff[v] = n;
        for (i = l->ve_off[v]; i < l->ve_off[v + 1]; ++i)
            if (T->tag_s[l->ve[i]] > 0.0f && l->ef_off[l->ve[i] + 1] - l->ef_off[l->ve[i]] == 2)
                F->eid[n++] = org->e ? org->e[l->ve[i]] : l->ve[i];
        F->corner[v] = T->corner_s[v] > 0.0f ? (org->v ? org->v[v] : v) : -1;
        F->src[v] = -1;
        if (n > F->eoff[v] || F->corner[v] >= 0) { F->src[v] = v; queue[tail++] = v; }
    }
    F->eoff[l->nv] = n;
    /* tbz_vertex_s's breadth-first order */
    while (head < tail) {
        const int u = queue[head++];
        for (i = l->ve_off[u]; i < l->ve_off[u + 1]; ++i) {
            const int w = sfb__other_end(l, l->ve[i], u);
            if (F->src[w] < 0) { F->src[w] = F->src[u]; queue[tail++] = w; }
        }
    }
    sfb__free(T->ctx, queue);
    for (f = 0, n = 0; f < l->nf; ++f)
        if (!l->fhole[f])
            for (i = 0; i < 3; ++i) F->pv[n++] = l->fv[l->fv_off[f] + i];
    *out = F;
    return SFB_SUCCESS;
}

/* Per L vertex its s from the features' tags now, as tbz_vertex_s gives it (-1: none reached). */
static void tbz_features_vs(const sfb__tbz_features *F, double *vs) {
    int v, i;
    for (v = 0; v < F->nv; ++v) vs[v] = -1.0;
    for (v = 0; v < F->nv; ++v) {
        double sum = 0.0;
        int cnt = 0;
        if (F->src[v] != v) continue;
        for (i = F->eoff[v]; i < F->eoff[v + 1]; ++i) {
            const float t = F->es[F->eid[i]] > 0.0f ? F->es[F->eid[i]] : 1e-30f; /* tbz_tag_values */
            sum += t;
            cnt++;
        }
        vs[v] = cnt ? sum / cnt : 0.0;
        if (F->corner[v] >= 0) {
            const float c = F->cs[F->corner[v]] > 0.0f ? F->cs[F->corner[v]] : 1e-30f;
            vs[v] = cnt ? fmax(vs[v], c) : c;
        }
    }
    for (v = 0; v < F->nv; ++v)
        if (F->src[v] >= 0 && F->src[v] != v) vs[v] = vs[F->src[v]];
}

/* Per vertex the s of the nearest tagged feature (breadth first over mesh edges; -1 where none
 * can be reached), for T's tag values: the slider's features on T's own level
 * (tbz_features_make, tbz_features_vs), so that the slider and the plain build take the same
 * arithmetic. */
static sfb_result tbz_vertex_s(sfb__tbz *T, double *vs) {
    tbz_origin own;
    sfb__tbz_features *F = NULL;
    sfb_result r;
    memset(&own, 0, sizeof own);
    own.nbe = T->ne; own.nbv = T->nv; own.bes = T->tag_s; own.bvs = T->corner_s;
    if ((r = tbz_features_make(T, &own, &F)) != SFB_SUCCESS) return r;
    tbz_features_vs(F, vs);
    sfb__tbz_features_free(T->ctx, F);
    return SFB_SUCCESS;
}

/* The mean s of point (i, j) of a triangle over its home vertices fv (weights > 0; at a corner
 * the corner alone). */
static double tbz_home_s(const double *vs, const int *fv, int i, int j) {
    const int w[3] = {4 - i - j, i, j};
    double s = 0.0, wsum = 0.0;
    int kk;
    for (kk = 0; kk < 3; ++kk)
        if (w[kk] > 0 && (w[0] == 4 || w[1] == 4 || w[2] == 4 ? w[kk] == 4 : 1)) { s += vs[fv[kk]]; wsum += 1.0; }
    return wsum > 0.0 ? s / wsum : 0.0;
}

/* A point's s for options opt: the override where the point has a feature in its part of the
 * mesh (home mean >= 0), else the features' s; below 1e-20 none. In float first, as the
 * slider's build and sfb__tribezier_blend both take it. */
static double tbz_slider_s(const sfb_tribezier_options *opt, float home) {
    const double s = opt && opt->sharpness_set ? (home >= 0.0f ? (double)opt->sharpness : 0.0) : (double)home;
    return s < 1e-20 ? 0.0 : s;
}

int sfb__tribezier_blend(sfb_context *ctx, const sfb__patch_table *pt, const sfb_tribezier_options *opt, float *point_data) {
    const sfb__tbz_features *F = pt->features;
    double *vs = (double *)sfb__alloc(ctx, ((size_t)F->nv + 1) * sizeof(double));
    int p, q, c, i, j;
    if (!vs) return 0;
    tbz_features_vs(F, vs);
    for (p = 0; p < pt->npatch; ++p) {
        const float *b = pt->blend + SFB__TBZ_BLEND * (size_t)p;
        float *o = point_data + 45 * (size_t)p;
        for (j = 0, q = 0; j <= 4; ++j)
            for (i = 0; i + j <= 4; ++i, ++q) {
                const double s = tbz_slider_s(opt, (float)tbz_home_s(vs, F->pv + 3 * (size_t)p, i, j));
                for (c = 0; c < 3; ++c) o[3 * q + c] = (float)((1.0 - s) * (double)b[3 * q + c] + s * (double)b[45 + 3 * q + c]);
            }
    }
    sfb__free(ctx, vs);
    return 1;
}

/* The smooth net built again (the seed-plane fallback, the second pass) from the current one,
 * first: the constraint components away from our vertices of first are the same systems,
 * copied rather than solved again (reuse_x, reuse_ours); rec: record it for the sharp net. */
static sfb_result tbz_state_again(sfb__tbz *T, const double *first, tbz_prev *rec) {
    unsigned char *was = (unsigned char *)sfb__calloc(T->ctx, (size_t)T->nv + 1, 1);
    sfb_result r;
    int v;
    if (!was) return sfb__oom(T->ctx, "tribezier");
    for (v = 0; v < T->nv; ++v) was[v] = (unsigned char)tbz_ours(T, v);
    T->reuse_x = first;
    T->reuse_ours = was;
    T->rec = rec;
    r = tbz_state(T, 0);
    T->rec = NULL;
    T->reuse_x = NULL;
    T->reuse_ours = NULL;
    sfb__free(T->ctx, was);
    return r;
}

/* fout: NULL, the net into *out (45 doubles per triangle); else the net into fout, 45 floats
 * per triangle that is not a hole, in order (sfb__patch_table_beztri_children's point data),
 * and *out left NULL (the doubles, a net as large again, never made) */
static sfb_result tbz_points(sfb_context *ctx, const sfb__level *l, const float *positions, const float *sharp_positions,
                             const sfb_tribezier_options *opt, unsigned flags, double **out, float *fout, tbz_slider *sv,
                             sfb__tbz_stats *stats) {
    sfb__tbz T;
    tbz_prev prev;
    int round;
    double *x0 = NULL, *vs = NULL, *vsf = NULL, *res = NULL;
    int v, e, f, c, k, kb, any_tag = 0, sharp_only = 0;
    sfb_result r = SFB_SUCCESS;
    *out = NULL;
    if (sv) { sv->blend = NULL; sv->F = NULL; }
    /* the nets read rings in fan order: every vertex with triangles a fan, every edge manifold
     * (tbz_check and tbz_split see to it on the mesh; a mesh after Loop steps, tbz_refine,
     * can still fail: two triangles on the same three vertices give four triangles on an edge) */
    for (e = 0; e < l->ne; ++e)
        if (l->etag[e] & SFB__TAG_NONMANIFOLD)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, -1,
                              "tribezier: after a Loop step an edge is non-manifold (two triangles on the same three vertices?)");
    for (v = 0; v < l->nv; ++v)
        if ((l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v])
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, -1,
                              "tribezier: after a Loop step a vertex is non-manifold (two triangles on the same three vertices?)");
    memset(&T, 0, sizeof T);
    memset(&prev, 0, sizeof prev);
    T.ctx = ctx; T.l = l; T.pos = positions;
    for (v = 0; v < 3 * l->nv; ++v) T.scale = fmax(T.scale, fabs((double)positions[v]));
    if (!(T.scale > 0.0)) T.scale = 1.0;
    tbz_usin(&T);
    T.nv = l->nv; T.ne = l->ne; T.nf = l->nf;
    T.np = l->nv + 3 * l->ne + 3 * l->nf;
    T.seed_plane = (flags & SFB__TBZ_SEED_PLANE) != 0;
    T.flags = flags;
    T.par_unknowns = flags & SFB__TBZ_PAR_SMALL ? TBZ_PAR_UNKNOWNS_SMALL : TBZ_PAR_UNKNOWNS;
    T.efeat = (unsigned char *)sfb__calloc(ctx, (size_t)T.ne + 1, 1);
    T.vtype = (unsigned char *)sfb__calloc(ctx, (size_t)T.nv + 1, 1);
    T.virr = (unsigned char *)sfb__calloc(ctx, (size_t)T.nv + 1, 1);
    T.phi = (double *)sfb__calloc(ctx, (size_t)l->vf_off[l->nv] + 1, sizeof(double));
    /* the net, its fixed marks and distances: every entry written before it is read
     * (tbz_initial, tbz_distances; checked with the net filled with NaN), so not cleared first (18
     * MB on spot.obj after two steps) */
    T.x = (double *)sfb__alloc(ctx, (3 * (size_t)T.np + 1) * sizeof(double));
    T.fixed = (unsigned char *)sfb__alloc(ctx, (size_t)T.np + 1);
    T.dist = (int *)sfb__alloc(ctx, ((size_t)T.np + 1) * sizeof(int));
    T.grid = (int *)sfb__alloc(ctx, 15 * (size_t)T.nf * sizeof(int) + 1);
    T.tag_s = (float *)sfb__calloc(ctx, (size_t)T.ne + 1, sizeof(float));
    T.corner_s = (float *)sfb__calloc(ctx, (size_t)T.nv + 1, sizeof(float));
    if (!fout) res = (double *)sfb__alloc(ctx, 45 * (size_t)T.nf * sizeof(double) + 1);
    if (!T.efeat || !T.vtype || !T.virr || !T.phi || !T.x || !T.fixed || !T.dist || !T.grid || !T.tag_s || !T.corner_s || (!fout && !res)) {
        r = sfb__oom(ctx, "tribezier");
        goto done;
    }
    for (f = 0; f < T.nf; ++f) tbz_patch(&T, f, T.grid + 15 * (size_t)f);
    any_tag = tbz_tag_values(&T, opt && opt->sharpness_set, opt ? opt->sharpness : 0.0f);
    /* s per vertex (tbz_vertex_s) follows from the tags alone. Where it is 1 at every vertex
     * (every tag s = 1: infinitely sharp creases, the corners of split non-manifold vertices --
     * cow.obj and teapot.obj have only those --, an override of 1) every point's blend is the
     * sharp net's, so the smooth net is not built (SFB__TBZ_BOTH_NETS: built all the same, for
     * the test that the net is the same) */
    if (any_tag) {
        vs = (double *)sfb__calloc(ctx, (size_t)T.nv + 1, sizeof(double));
        if (!vs) { r = sfb__oom(ctx, "tribezier"); goto done; }
        if ((r = tbz_vertex_s(&T, vs)) != SFB_SUCCESS) goto done;
        /* the slider needs both nets whatever s is now */
        sharp_only = !(flags & SFB__TBZ_BOTH_NETS) && !sv;
        for (v = 0; v < T.nv && sharp_only; ++v) sharp_only = vs[v] == 1.0;
    }
    if (sv) {
        /* the slider: the features, each vertex's s from their tags (tbz_features_vs, as
         * sfb__tribezier_blend takes it), the two nets' room */
        int held = 0;
        for (f = 0; f < T.nf; ++f) held += !l->fhole[f];
        if ((r = tbz_features_make(&T, &sv->org, &sv->F)) != SFB_SUCCESS) goto done;
        vsf = (double *)sfb__alloc(ctx, ((size_t)T.nv + 1) * sizeof(double));
        sv->blend = (float *)sfb__alloc(ctx, (size_t)SFB__TBZ_BLEND * held * sizeof(float) + 1);
        if (!vsf || !sv->blend) { r = sfb__oom(ctx, "tribezier slider"); goto done; }
        tbz_features_vs(sv->F, vsf);
    }
    /* progress: this call's window (sfb_internal.h), the smooth net's solve in its first half
     * where a sharp net follows (the seed-plane fallback reports in the same half again, never
     * below what was reported) */
    {
        const float w0 = flags & SFB__TBZ_PROGRESS_HIGH ? 0.5f : 0.0f, w1 = flags & SFB__TBZ_PROGRESS_LOW ? 0.5f : 1.0f;
        T.p0 = T.plast = w0;
        T.p1 = any_tag && !sharp_only ? 0.5f * (w0 + w1) : w1;
        if ((r = sfb__progress(ctx, w0, "tribezier")) != SFB_SUCCESS) goto done;
    }
    if (sharp_only) {
        T.pos = sharp_positions;
        if ((r = tbz_state(&T, 1)) != SFB_SUCCESS) goto done;
        T.st.sharp_only = 1;
        any_tag = 0; /* the blend below: the one net as it is */
        goto blend;
    }
    /* the smooth net's solve is recorded for the sharp net (tbz_prev), unless asked not to */
    T.rec = any_tag && !(flags & SFB__TBZ_NO_REUSE) ? &prev : NULL;
    if (any_tag && !T.seed_plane) {
        T.bad_v = (unsigned char *)sfb__calloc(ctx, (size_t)T.nv + 1, 1);
        T.seed_v = (unsigned char *)sfb__calloc(ctx, (size_t)T.nv + 1, 1);
        if (!T.bad_v || !T.seed_v) { r = sfb__oom(ctx, "tribezier"); goto done; }
    }
    r = tbz_state(&T, 0);
    T.rec = NULL;
    for (round = 0; r == SFB_SUCCESS && T.bad_v && !T.seed_plane && round < 2; ++round) {
        /* our crease tangent plane left the constraints around a vertex unsolvable or a patch
         * corner beside it degenerate (seen at valence 8 and up with a crease through the
         * vertex, and on real meshes: teapot.obj, spot.obj, cow.obj creased at 40 degrees after
         * their Loop steps): those vertices get the seed's plane (measured in tests/tribezier.c),
         * the others keep ours; a second time, every vertex. Residuals elsewhere (touching
         * extraordinary vertices of different valences) and degenerate corners away from our
         * vertices are no reason to. (The fallback was the whole net's at once, and on those real
         * meshes the seed's plane was all there was.) */
        double *first = T.x;
        if (!tbz_ours_bad(&T, T.bad_v)) break;
        T.x = (double *)sfb__calloc(ctx, 3 * (size_t)T.np + 1, sizeof(double));
        if (!T.x) { T.x = first; r = sfb__oom(ctx, "tribezier"); goto done; }
        tbz_prev_free(ctx, &prev); /* the record is of the net now replaced */
        for (v = 0; v < T.nv; ++v)
            if (T.bad_v[v]) T.seed_v[v] = 1;
        memset(T.bad_v, 0, (size_t)T.nv);
        memset(&T.st, 0, sizeof T.st);
        if (round == 1) T.seed_plane = 1;
        r = tbz_state_again(&T, first, !(flags & SFB__TBZ_NO_REUSE) ? &prev : NULL);
        sfb__free(ctx, first);
        T.st.fallbacks = round + 1;
    }
    for (v = 0; T.seed_v && v < T.nv; ++v) T.st.seed_vertices += T.seed_v[v];
    if (r != SFB_SUCCESS) goto done;
    if (any_tag && !T.seed_plane && !(flags & SFB__TBZ_NO_STRAIGHT)) {
        /* the smooth net's second pass (tbz_crease_points, tbz_mix) where there is an
         * extraordinary crease vertex with our plane: the components away from those copied from
         * the first (the same systems); the first net kept where the second leaves a row around
         * one unmet or a patch corner degenerate (not seen on the tests' meshes) */
        int any = 0;
        for (v = 0; v < T.nv && !any; ++v) any = tbz_ours(&T, v);
        if (any) {
            double *first = T.x;
            const sfb__tbz_stats st1 = T.st;
            T.x = (double *)sfb__alloc(ctx, (3 * (size_t)T.np + 1) * sizeof(double));
            if (!T.x) { T.x = first; r = sfb__oom(ctx, "tribezier"); goto done; }
            /* the record for the sharp net stays the first pass's: the second solves the
             * components around our vertices alone, which the sharp net does not share (its
             * crease edges have no rows) */
            memset(&T.st, 0, sizeof T.st);
            T.straight_x = first;
            r = tbz_state_again(&T, first, NULL);
            T.straight_x = NULL;
            if (r == SFB_SUCCESS && (T.st.ours_residual > TBZ_OURS_RESIDUAL || tbz_ours_bad(&T, NULL))) {
                sfb__free(ctx, T.x);
                T.x = first;
                T.st = st1;
                T.st.straight_kept_first++;
            } else {
                /* the first pass's figures (unknowns, rows, residual: the second's system is a
                 * part of the first's), with the work of both */
                const sfb__tbz_stats st2 = T.st;
                sfb__free(ctx, first);
                T.st = st1;
                T.st.iterations += st2.iterations;
                T.st.templates += st2.templates;
                T.st.templated += st2.templated;
                T.st.direct += st2.direct;
                T.st.large += st2.large;
                T.st.ours_residual = st2.ours_residual;
                T.st.crease_weighted = st2.crease_weighted;
                T.st.straight_skipped = st2.straight_skipped;
                T.st.straight_across = st2.straight_across;
                T.st.straight_unfair = st2.straight_unfair;
                T.st.straight = 1;
            }
            if (r != SFB_SUCCESS) goto done;
        }
    }
    if (any_tag) {
        x0 = T.x;
        T.x = (double *)sfb__calloc(ctx, 3 * (size_t)T.np + 1, sizeof(double));
        if (!T.x) { r = sfb__oom(ctx, "tribezier"); goto done; }
        T.pos = sharp_positions;
        prev.x1 = x0;
        T.prev = &prev;
        T.p0 = T.p1;
        T.p1 = flags & SFB__TBZ_PROGRESS_LOW ? 0.5f : 1.0f;
        r = tbz_state(&T, 1);
        T.prev = NULL;
        if (r != SFB_SUCCESS) goto done;
    }
blend:
    for (f = 0, k = 0, kb = 0; f < T.nf; ++f) {
        const int *fv = l->fv + l->fv_off[f];
        const int *g = T.grid + 15 * (size_t)f;
        int i, j, q = 0;
        float *fo = fout ? fout + 45 * (size_t)k : NULL, *bo = sv && !l->fhole[f] ? sv->blend + SFB__TBZ_BLEND * (size_t)kb++ : NULL;
        if (fout && l->fhole[f]) continue;
        k += fout != NULL;
        for (j = 0; j <= 4; ++j)
            for (i = 0; i + j <= 4; ++i, ++q) {
                double s = 0.0;
                if (any_tag) {
                    s = tbz_home_s(vs, fv, i, j);
                    if (s < 1e-20) s = 0.0;
                }
                if (bo) {
                    /* the slider: the nets in float, the output their blend as
                     * sfb__tribezier_blend makes it */
                    for (c = 0; c < 3; ++c) {
                        bo[3 * q + c] = (float)(any_tag ? x0 : T.x)[3 * (size_t)g[q] + c];
                        bo[45 + 3 * q + c] = (float)T.x[3 * (size_t)g[q] + c];
                    }
                    s = tbz_slider_s(opt, (float)tbz_home_s(vsf, fv, i, j));
                }
                for (c = 0; c < 3; ++c) {
                    const double sh = T.x[3 * (size_t)g[q] + c];
                    const double b = bo ? (1.0 - s) * (double)bo[3 * q + c] + s * (double)bo[45 + 3 * q + c]
                                        : any_tag ? (1.0 - s) * x0[3 * (size_t)g[q] + c] + s * sh : sh;
                    if (fo) fo[3 * q + c] = (float)b;
                    else res[45 * (size_t)f + 3 * q + c] = bo ? (double)(float)b : b;
                }
            }
    }
    *out = res;
    res = NULL;
    if (stats) *stats = T.st;
done:
    sfb__free(ctx, T.efeat); sfb__free(ctx, T.vtype); sfb__free(ctx, T.virr); sfb__free(ctx, T.phi);
    sfb__free(ctx, T.x); sfb__free(ctx, T.fixed); sfb__free(ctx, T.dist); sfb__free(ctx, T.grid); sfb__free(ctx, T.tag_s); sfb__free(ctx, T.corner_s);
    sfb__free(ctx, x0); sfb__free(ctx, vs); sfb__free(ctx, vsf); sfb__free(ctx, res);
    sfb__free(ctx, T.bad_v); sfb__free(ctx, T.seed_v);
    if (r != SFB_SUCCESS && sv) {
        sfb__free(ctx, sv->blend);
        sfb__tbz_features_free(ctx, sv->F);
        sv->blend = NULL;
        sv->F = NULL;
    }
    tbz_prev_free(ctx, &prev);
    return r;
}

/* The refusals of every entry point: an override s outside [0, 1] or NaN, and
 * sfb__tri_mesh_check's (non-manifold vertices are split instead: tbz_split). */
static sfb_result tbz_check(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt) {
    sfb_result r;
    int e;
    if (opt && opt->sharpness_set && !(opt->sharpness >= 0.0f && opt->sharpness <= 1.0f))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "tribezier: sharpness %g is not in [0, 1]", (double)opt->sharpness);
    if ((r = sfb__tri_mesh_check(ctx, l, positions, "tribezier", 0)) != SFB_SUCCESS) return r;
    /* two triangles that run their edge the same way (the rest of the non-manifold edges
     * sfb__tri_mesh_check refused) */
    for (e = 0; e < l->ne; ++e)
        if (l->etag[e] & SFB__TAG_NONMANIFOLD)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_EDGE, e,
                              "tribezier: edge %d (%d-%d) is non-manifold (its triangles run it the same way: orient them consistently)", e,
                              l->ev[2 * e], l->ev[2 * e + 1]);
    return SFB_SUCCESS;
}

/* Non-manifold vertices (edges are manifold: tbz_check): a vertex whose triangles form more
 * than one fan (two sheets touching at a point, pieces sharing a boundary vertex) becomes one
 * vertex per fan, at the same position, so that every sheet is a manifold mesh of its own: a
 * closed fan's copy is an interior vertex, an open one's a boundary vertex. The triangles keep
 * their order and slots (param faces unchanged). Every copy keeps the vertex's corner tag (the
 * base level makes a non-manifold vertex an infinitely sharp corner, sfb__level_prepare, as
 * OpenSubdiv does), so every sheet passes through the vertex at s = 1 and the sheets still
 * touch there; a closed fan's copy, a corner without sharp edges, stays G1 (tbz_initial).
 * *split = 0: none (sl, *spos untouched). */
static sfb_result tbz_split(sfb_context *ctx, const sfb__level *l, const float *positions, int *split, sfb__level *sl, float **spos) {
    int v, j, f, k, nv2 = l->nv, any = 0;
    int *fan = NULL, *sizes = NULL, *fv = NULL, *parent = NULL, *copy = NULL;
    sfb_result r = SFB_SUCCESS;
    *split = 0;
    for (v = 0; v < l->nv; ++v) any |= (l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v];
    if (!any) return SFB_SUCCESS;
    fan = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));    /* per vf entry: its vertex id in the split */
    parent = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int)); /* union-find over vf entries */
    copy = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    sizes = (int *)sfb__alloc(ctx, ((size_t)l->nf + 1) * sizeof(int));
    fv = (int *)sfb__alloc(ctx, ((size_t)l->nfv + 1) * sizeof(int));
    if (!fan || !parent || !copy || !sizes || !fv) { r = sfb__oom(ctx, "tribezier non-manifold vertices"); goto done; }
    memcpy(fv, l->fv, (size_t)l->nfv * sizeof(int));
    for (f = 0; f < l->nf; ++f) sizes[f] = l->fv_off[f + 1] - l->fv_off[f];
    for (v = 0; v < l->nv; ++v) {
        const int a = l->vf_off[v], b = l->vf_off[v + 1];
        if (!(l->vtag[v] & SFB__TAG_NONMANIFOLD) || a == b) continue;
        for (j = a; j < b; ++j) { parent[j] = j; copy[j] = -1; }
        /* faces of v sharing an edge of v are in one fan */
        for (j = l->ve_off[v]; j < l->ve_off[v + 1]; ++j) {
            const int e = l->ve[j];
            int ends[2], ne2 = 0, q;
            if (l->ef_off[e + 1] - l->ef_off[e] != 2) continue;
            for (k = l->ef_off[e]; k < l->ef_off[e + 1]; ++k)
                for (q = a; q < b; ++q)
                    if (l->vf[q] == l->ef[k] && ne2 < 2) { ends[ne2++] = q; break; }
            if (ne2 == 2) {
                int x = ends[0], y = ends[1];
                while (parent[x] != x) x = parent[x];
                while (parent[y] != y) y = parent[y];
                if (x != y) parent[y] = x;
            }
        }
        /* the fan of the first face keeps v; the others take new ids */
        for (j = a; j < b; ++j) {
            int root = j;
            while (parent[root] != root) root = parent[root];
            if (copy[root] < 0) copy[root] = root == a || j == a ? v : nv2++;
            fan[j] = copy[root];
            fv[l->fv_off[l->vf[j]] + l->vf_slot[j]] = fan[j];
        }
    }
    *spos = (float *)sfb__alloc(ctx, 3 * (size_t)nv2 * sizeof(float));
    if (!*spos) { r = sfb__oom(ctx, "tribezier non-manifold vertices"); goto done; }
    memcpy(*spos, positions, 3 * (size_t)l->nv * sizeof(float));
    for (v = 0; v < l->nv; ++v)
        if ((l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v])
            for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j)
                if (fan[j] >= l->nv) memcpy(*spos + 3 * (size_t)fan[j], positions + 3 * (size_t)v, 3 * sizeof(float));
    r = sfb__level_from_faces(ctx, nv2, l->nf, sizes, fv, NULL, SFB_ELEMENT_VERTEX, sl);
    if (r != SFB_SUCCESS) { sfb__free(ctx, *spos); *spos = NULL; goto done; }
    /* the tags: an edge keeps its own (the same face slot in both), a vertex and its copies
     * the vertex's */
    for (f = 0; f < l->nf; ++f)
        for (k = l->fv_off[f]; k < l->fv_off[f + 1]; ++k) sl->es[sl->fe[k]] = l->es[l->fe[k]];
    for (v = 0; v < l->nv; ++v) {
        sl->vs[v] = l->vs[v];
        if ((l->vtag[v] & SFB__TAG_NONMANIFOLD) && l->vf_off[v + 1] > l->vf_off[v])
            for (j = l->vf_off[v]; j < l->vf_off[v + 1]; ++j) sl->vs[fan[j]] = l->vs[v];
    }
    memcpy(sl->fhole, l->fhole, (size_t)l->nf);
    sfb__level_compute_rules(sl);
    for (v = 0; v < nv2; ++v)
        if ((sl->vtag[v] & SFB__TAG_NONMANIFOLD) && sl->vf_off[v + 1] > sl->vf_off[v]) {
            /* not a fan even so (tbz_check refused the edges that would make one) */
            const int o = v < l->nv ? v : -1;
            sfb__level_free(ctx, sl);
            sfb__free(ctx, *spos);
            *spos = NULL;
            r = sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_VERTEX, o, "tribezier: vertex %d is non-manifold (its triangles do not form fans)", o);
            goto done;
        }
    *split = 1;
done:
    sfb__free(ctx, fan); sfb__free(ctx, parent); sfb__free(ctx, copy); sfb__free(ctx, sizes); sfb__free(ctx, fv);
    return r;
}

sfb_result sfb__tribezier_points(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                                 unsigned flags, double **out, sfb__tbz_stats *stats) {
    sfb__level sl;
    float *spos = NULL;
    int split;
    sfb_result r;
    *out = NULL;
    r = tbz_check(ctx, l, positions, opt);
    if (r == SFB_SUCCESS) r = tbz_split(ctx, l, positions, &split, &sl, &spos);
    if (r != SFB_SUCCESS) return r;
    if (!split) return tbz_points(ctx, l, positions, positions, opt, flags, out, NULL, NULL, stats);
    r = tbz_points(ctx, &sl, spos, spos, opt, flags, out, NULL, NULL, stats);
    sfb__level_free(ctx, &sl);
    sfb__free(ctx, spos);
    return r;
}

/* The adjacency of child level rl (its faces, face edges and edge ends written by tbz_refine)
 * of b. Where every vertex of b with triangles has its rings in order and no edge is
 * non-manifold, each child vertex's rings follow from its parent's, in the order
 * sfb__level_complete would find by walking around it (its walk was 60% of the refined
 * topology's time after two steps): a vertex's children at its parent's triangles in the same
 * order; an edge's vertex, per triangle g of the edge (at slot s of g, running from its corner s
 * to s + 1) the children s + 1, 3 (the middle one) and s of g, from the lowest face on where
 * interior, at a boundary from child s + 1 (its outgoing edge the boundary's half). Elsewhere
 * sfb__level_complete. */
static sfb_result tbz_child_rings(sfb_context *ctx, const sfb__level *b, sfb__level *rl) {
    const int nv = b->nv, ne = b->ne;
    int v, e, i, k, *fo, *vo, *eo;
    for (e = 0; e < ne; ++e)
        if (b->ef_off[e + 1] - b->ef_off[e] < 1 || b->ef_off[e + 1] - b->ef_off[e] > 2 || (b->etag[e] & SFB__TAG_NONMANIFOLD))
            return sfb__level_complete(ctx, rl);
    for (v = 0; v < nv; ++v)
        if (b->vf_off[v + 1] > b->vf_off[v] && (b->vtag[v] & SFB__TAG_NONMANIFOLD)) return sfb__level_complete(ctx, rl);
    rl->vf_off = (int *)sfb__alloc(ctx, ((size_t)rl->nv + 1) * sizeof(int));
    rl->vf = (int *)sfb__alloc(ctx, ((size_t)rl->nfv + 1) * sizeof(int));
    rl->vf_slot = (int *)sfb__alloc(ctx, ((size_t)rl->nfv + 1) * sizeof(int));
    rl->ve_off = (int *)sfb__alloc(ctx, ((size_t)rl->nv + 1) * sizeof(int));
    rl->ve = (int *)sfb__alloc(ctx, ((size_t)rl->ne * 2 + 1) * sizeof(int));
    if (!rl->vf_off || !rl->vf || !rl->vf_slot || !rl->ve_off || !rl->ve) return sfb__oom(ctx, "tribezier refinement");
    rl->vf_off[0] = rl->ve_off[0] = 0;
    for (v = 0; v < nv; ++v) {
        rl->vf_off[v + 1] = rl->vf_off[v] + (b->vf_off[v + 1] - b->vf_off[v]);
        rl->ve_off[v + 1] = rl->ve_off[v] + (b->ve_off[v + 1] - b->ve_off[v]);
    }
    for (e = 0; e < ne; ++e) {
        const int nfe = b->ef_off[e + 1] - b->ef_off[e];
        rl->vf_off[nv + e + 1] = rl->vf_off[nv + e] + 3 * nfe;
        rl->ve_off[nv + e + 1] = rl->ve_off[nv + e] + (nfe == 2 ? 6 : 4);
    }
    for (v = 0; v < nv; ++v) {
        const int f0 = b->vf_off[v], n = b->vf_off[v + 1] - f0, m = b->ve_off[v + 1] - b->ve_off[v];
        int rot = 0;
        fo = rl->vf + rl->vf_off[v]; vo = rl->vf_slot + rl->vf_off[v]; eo = rl->ve + rl->ve_off[v];
        if (m == n) /* interior: from the lowest face */
            for (i = 1; i < n; ++i)
                if (b->vf[f0 + i] < b->vf[f0 + rot]) rot = i;
        for (i = 0; i < n; ++i) {
            const int j = (i + rot) % n, s = b->vf_slot[f0 + j];
            fo[i] = 4 * b->vf[f0 + j] + s; /* child s of a triangle holds its corner s at slot s */
            vo[i] = s;
        }
        for (i = 0; i < m; ++i) {
            const int ed = b->ve[b->ve_off[v] + (m == n ? (i + rot) % n : i)];
            eo[i] = 2 * ed + (b->ev[2 * ed] == v ? 0 : 1);
        }
    }
    for (e = 0; e < ne; ++e) {
        const int nfe = b->ef_off[e + 1] - b->ef_off[e], n = 3 * nfe;
        int f6[6], s6[6], rot = 0;
        for (k = 0; k < nfe; ++k) {
            const int g = b->ef[b->ef_off[e] + k], s = b->ef_slot[b->ef_off[e] + k];
            f6[3 * k] = 4 * g + (s + 1) % 3; s6[3 * k] = s;
            f6[3 * k + 1] = 4 * g + 3; s6[3 * k + 1] = (s + 2) % 3;
            f6[3 * k + 2] = 4 * g + s; s6[3 * k + 2] = (s + 1) % 3;
        }
        if (nfe == 2)
            for (i = 1; i < n; ++i)
                if (f6[i] < f6[rot]) rot = i;
        fo = rl->vf + rl->vf_off[nv + e]; vo = rl->vf_slot + rl->vf_off[nv + e]; eo = rl->ve + rl->ve_off[nv + e];
        for (i = 0; i < n; ++i) {
            const int j = (i + rot) % n;
            fo[i] = f6[j]; vo[i] = s6[j];
            eo[i] = rl->fe[rl->fv_off[f6[j]] + s6[j]]; /* outgoing */
        }
        if (nfe == 1) eo[3] = rl->fe[rl->fv_off[f6[2]] + (s6[2] + 2) % 3]; /* the last triangle's incoming: the boundary's other half */
    }
    return sfb__level_complete_ordered(ctx, rl);
}

/* One Loop step of the triangle mesh `b` into *rl: the smooth net's positions psm by its rules
 * (only boundaries sharp) into *ps, and the sharp net's psh by its rules (boundaries, every
 * tagged edge and corner tag) into *pp. Child face 4f + i of triangle f = (V0, V1, V2), edge points E01, E12,
 * E20: i = 0 (V0, E01, E20), 1 (E01, V1, E12), 2 (E20, E12, V2), 3 (E12, E20, E01) -- each in
 * the frame of quadtree child i of the parametric triangle (sfb__patch_locate), so its 15
 * points are that child patch's. Child edges keep their parent edge's tag, the old vertices
 * their corner tags. */
static sfb_result tbz_refine(sfb_context *ctx, const sfb__level *b, const float *psm, const float *psh, sfb__level *rl, float **ps,
                             float **pp) {
    const int nv = b->nv, nf = b->nf, ne = b->ne, nv2 = nv + ne;
    int f, e, v, k, c, net, nets = 2;
    sfb_result r = SFB_SUCCESS;
    memset(rl, 0, sizeof *rl);
    *ps = (float *)sfb__alloc(ctx, (size_t)3 * nv2 * sizeof(float) + 1);
    *pp = (float *)sfb__alloc(ctx, (size_t)3 * nv2 * sizeof(float) + 1);
    if ((size_t)4 * nf * 3 > SFB_MAX_ELEMENTS || (size_t)2 * ne + 3 * (size_t)nf > SFB_MAX_ELEMENTS) {
        r = sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "tribezier: the mesh after a Loop step would have %zu face-vertices, over the limit of %d",
                       (size_t)12 * nf, SFB_MAX_ELEMENTS);
        goto done;
    }
    /* the child topology written directly (as refine.c's Loop step does; sfb__level_from_faces
     * would find the edges again by hashing): the half of parent edge e at its end ev[2e + h]
     * is child edge 2e + h, the inner edges of triangle f are 2 ne + 3 f + (0: E20-E01 at V0,
     * 1: E01-E12 at V1, 2: E12-E20 at V2) */
    rl->nv = nv2; rl->nf = 4 * nf; rl->ne = 2 * ne + 3 * nf; rl->nfv = 12 * nf;
    rl->fv_off = (int *)sfb__alloc(ctx, ((size_t)rl->nf + 1) * sizeof(int));
    rl->fv = (int *)sfb__alloc(ctx, ((size_t)rl->nfv + 1) * sizeof(int));
    rl->fe = (int *)sfb__alloc(ctx, ((size_t)rl->nfv + 1) * sizeof(int));
    rl->ev = (int *)sfb__alloc(ctx, (2 * (size_t)rl->ne + 1) * sizeof(int));
    rl->es = (float *)sfb__alloc(ctx, ((size_t)rl->ne + 1) * sizeof(float));
    rl->vs = (float *)sfb__alloc(ctx, ((size_t)nv2 + 1) * sizeof(float));
    rl->fhole = (unsigned char *)sfb__alloc(ctx, (size_t)rl->nf + 1);
    if (!*ps || !*pp || !rl->fv_off || !rl->fv || !rl->fe || !rl->ev || !rl->es || !rl->vs || !rl->fhole) {
        r = sfb__oom(ctx, "tribezier refinement");
        goto done;
    }
    for (e = 0; e < ne; ++e) {
        rl->ev[4 * e] = b->ev[2 * e]; rl->ev[4 * e + 1] = nv + e;
        rl->ev[4 * e + 2] = nv + e; rl->ev[4 * e + 3] = b->ev[2 * e + 1];
        rl->es[2 * e] = rl->es[2 * e + 1] = b->es[e]; /* child edges keep their parent edge's tag */
    }
    for (f = 0; f < nf; ++f) {
        const int *V = b->fv + b->fv_off[f], *E = b->fe + b->fv_off[f]; /* E[k]: edge V[k] -> V[k+1] */
        const int ie = 2 * ne + 3 * f;
        /* hv(k, j): the half of edge E[k] at V[j] */
#define TBZ_HALF(k, j) (2 * E[k] + (b->ev[2 * E[k]] == V[j] ? 0 : 1))
        const int ch[4][3] = {{V[0], nv + E[0], nv + E[2]}, {nv + E[0], V[1], nv + E[1]}, {nv + E[2], nv + E[1], V[2]},
                              {nv + E[1], nv + E[2], nv + E[0]}};
        const int ce[4][3] = {{TBZ_HALF(0, 0), ie, TBZ_HALF(2, 0)}, {TBZ_HALF(0, 1), TBZ_HALF(1, 1), ie + 1},
                              {ie + 2, TBZ_HALF(1, 2), TBZ_HALF(2, 2)}, {ie + 2, ie, ie + 1}};
#undef TBZ_HALF
        for (k = 0; k < 4; ++k) {
            rl->fv_off[4 * f + k] = 12 * f + 3 * k;
            rl->fhole[4 * f + k] = b->fhole[f];
            for (c = 0; c < 3; ++c) {
                rl->fv[12 * f + 3 * k + c] = ch[k][c];
                rl->fe[12 * f + 3 * k + c] = ce[k][c];
            }
        }
        rl->ev[2 * ie] = nv + E[2]; rl->ev[2 * ie + 1] = nv + E[0];
        rl->ev[2 * ie + 2] = nv + E[0]; rl->ev[2 * ie + 3] = nv + E[1];
        rl->ev[2 * ie + 4] = nv + E[1]; rl->ev[2 * ie + 5] = nv + E[2];
        rl->es[ie] = rl->es[ie + 1] = rl->es[ie + 2] = 0.0f;
    }
    rl->fv_off[rl->nf] = rl->nfv;
    for (v = 0; v < nv2; ++v) rl->vs[v] = v < nv ? b->vs[v] : 0.0f;
    if ((r = tbz_child_rings(ctx, b, rl)) != SFB_SUCCESS) goto done;
    {
        /* two triangles on the same three vertices give two inner edges on the same two
         * vertices (one edge of four triangles, had the edges been found by their ends): both
         * tagged non-manifold, which tbz_points refuses */
        int *seen = (int *)sfb__alloc(ctx, (2 * (size_t)nv2 + 1) * sizeof(int)), *by = seen + nv2, j; /* per vertex: the ring it was last met in, by which edge */
        if (!seen) { r = sfb__oom(ctx, "tribezier refinement"); goto done; }
        for (v = 0; v < nv2; ++v) seen[v] = -1;
        for (v = 0; v < nv2; ++v)
            for (j = rl->ve_off[v]; j < rl->ve_off[v + 1]; ++j) {
                const int w = sfb__other_end(rl, rl->ve[j], v);
                if (seen[w] == v) {
                    rl->etag[rl->ve[j]] |= SFB__TAG_NONMANIFOLD;
                    rl->etag[by[w]] |= SFB__TAG_NONMANIFOLD;
                }
                seen[w] = v;
                by[w] = rl->ve[j];
            }
        sfb__free(ctx, seen);
    }
    {
        /* with no tag the sharp net's rules are the smooth net's (boundaries alone sharp): where
         * its positions are the same too, they are copied, not computed again */
        int tagged = psh != psm && memcmp(psh, psm, 3 * (size_t)nv * sizeof(float)) != 0;
        for (e = 0; e < ne && !tagged; ++e) tagged = b->es[e] > 0.0f && b->ef_off[e + 1] - b->ef_off[e] == 2;
        for (v = 0; v < nv && !tagged; ++v) tagged = b->vs[v] > 0.0f;
        if (!tagged) nets = 1;
    }
    for (net = 0; net < nets; ++net) {
        float *out = net ? *pp : *ps;
        const float *pos = net ? psh : psm;
        /* the sharp edges of this net's rules */
        for (e = 0; e < ne; ++e) {
            const int n2 = b->ef_off[e + 1] - b->ef_off[e], a = b->ev[2 * e], d = b->ev[2 * e + 1];
            const int sharp = n2 < 2 || (net && b->es[e] > 0.0f);
            double P[3];
            for (c = 0; c < 3; ++c) P[c] = sharp ? 0.5 * ((double)pos[3 * a + c] + pos[3 * d + c]) : 0.375 * ((double)pos[3 * a + c] + pos[3 * d + c]);
            if (!sharp)
                for (k = 0; k < 2; ++k) {
                    const int g = b->ef[b->ef_off[e] + k], sl = b->ef_slot[b->ef_off[e] + k];
                    const int o = b->fv[b->fv_off[g] + (sl + 2) % 3];
                    for (c = 0; c < 3; ++c) P[c] += 0.125 * pos[3 * o + c];
                }
            for (c = 0; c < 3; ++c) out[3 * (size_t)(nv + e) + c] = (float)P[c];
        }
        for (v = 0; v < nv; ++v) {
            const int m = b->ve_off[v + 1] - b->ve_off[v], nfv = b->vf_off[v + 1] - b->vf_off[v];
            int ns = 0, sa = -1, sb = -1, j;
            double P[3];
            for (j = 0; j < m; ++j) {
                const int ej = b->ve[b->ve_off[v] + j];
                if (b->ef_off[ej + 1] - b->ef_off[ej] < 2 || (net && b->es[ej] > 0.0f)) {
                    const int w = sfb__other_end(b, ej, v);
                    if (ns == 0) sa = w; else sb = w;
                    ++ns;
                }
            }
            if (nfv == 0 || ns >= 3 || (m > nfv && nfv == 1) || (net && b->vs[v] > 0.0f)) {
                for (c = 0; c < 3; ++c) P[c] = pos[3 * v + c]; /* corner */
            } else if (ns == 2) {
                for (c = 0; c < 3; ++c) P[c] = 0.75 * pos[3 * v + c] + 0.125 * ((double)pos[3 * sa + c] + pos[3 * sb + c]);
            } else {
                /* Loop's rule (the library's, refine.c): (5/8 - (3/8 + cos(2 pi / n) / 4)^2) / n per neighbour */
                const double beta = 0.25 * cos(2.0 * TBZ_PI / m) + 0.375, w = (0.625 - beta * beta) / m;
                for (c = 0; c < 3; ++c) P[c] = (1.0 - m * w) * pos[3 * v + c];
                for (j = 0; j < m; ++j) {
                    const int o = sfb__other_end(b, b->ve[b->ve_off[v] + j], v);
                    for (c = 0; c < 3; ++c) P[c] += w * pos[3 * o + c];
                }
            }
            for (c = 0; c < 3; ++c) out[3 * (size_t)v + c] = (float)P[c];
        }
    }
    if (nets == 1) memcpy(*pp, *ps, 3 * (size_t)nv2 * sizeof(float));
done:
    if (r != SFB_SUCCESS) {
        sfb__level_free(ctx, rl);
        sfb__free(ctx, *ps); sfb__free(ctx, *pp);
        *ps = *pp = NULL;
    }
    return r;
}

/* The slider's origin maps one Loop step down (tbz_refine's numbering: the half of parent edge
 * e at either end is child edge 2e or 2e + 1, the inner edges come after; the parent's vertices
 * keep their ids): into *e and *v (freed by the caller). */
static int tbz_origin_step(sfb_context *ctx, const tbz_origin *in, int pnv, int pne, const sfb__level *child, int **e, int **v) {
    int i;
    *e = (int *)sfb__alloc(ctx, ((size_t)child->ne + 1) * sizeof(int));
    *v = (int *)sfb__alloc(ctx, ((size_t)child->nv + 1) * sizeof(int));
    if (!*e || !*v) return 0;
    for (i = 0; i < child->ne; ++i) (*e)[i] = i < 2 * pne ? (in->e ? in->e[i / 2] : i / 2) : -1;
    for (i = 0; i < child->nv; ++i) (*v)[i] = i < pnv ? (in->v ? in->v[i] : i) : -1;
    return 1;
}

/* tbz_refined's flag: l is checked and its non-manifold vertices split already (tbz_build's) */
#define TBZ_CHECKED (1u << 24)

/* sfb__tribezier_refined_points, the net into *out or (fout not NULL) into fout (tbz_points);
 * sv: the slider's (l as sfb__tribezier_build hands it to tbz_build, its vertices split) */
static sfb_result tbz_refined(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                              unsigned flags, sfb__level *rl, double **out, float *fout, tbz_slider *sv, sfb__tbz_stats *stats) {
    float *ps = NULL, *pp = NULL, *spos = NULL;
    sfb__level sl;
    int split = 0, *oe = NULL, *ov = NULL;
    tbz_slider sv2;
    sfb_result r;
    *out = NULL;
    memset(rl, 0, sizeof *rl);
    if (sv) sv2 = *sv;
    r = flags & TBZ_CHECKED ? SFB_SUCCESS : tbz_check(ctx, l, positions, opt);
    if (r == SFB_SUCCESS && !(flags & TBZ_CHECKED)) r = tbz_split(ctx, l, positions, &split, &sl, &spos);
    if (r == SFB_SUCCESS) r = tbz_refine(ctx, split ? &sl : l, split ? spos : positions, split ? spos : positions, rl, &ps, &pp);
    if (r == SFB_SUCCESS && sv && (split || !tbz_origin_step(ctx, &sv->org, l->nv, l->ne, rl, &oe, &ov)))
        r = split ? sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_NONE, -1, "tribezier slider: a non-manifold vertex left") : sfb__oom(ctx, "tribezier slider");
    if (r == SFB_SUCCESS && (flags & SFB__TBZ_TWO_STEPS)) {
        /* the second step: each net's positions by its own rules again */
        sfb__level r1 = *rl;
        float *ps1 = ps, *pp1 = pp;
        r = tbz_refine(ctx, &r1, ps1, pp1, rl, &ps, &pp);
        if (r == SFB_SUCCESS && sv) {
            tbz_origin o1 = sv->org;
            int *e1 = oe, *v1 = ov;
            o1.e = e1; o1.v = v1;
            if (!tbz_origin_step(ctx, &o1, r1.nv, r1.ne, rl, &oe, &ov)) r = sfb__oom(ctx, "tribezier slider");
            sfb__free(ctx, e1);
            sfb__free(ctx, v1);
        }
        sfb__level_free(ctx, &r1);
        sfb__free(ctx, ps1);
        sfb__free(ctx, pp1);
    }
    if (sv) { sv2.org.e = oe; sv2.org.v = ov; }
    if (r == SFB_SUCCESS) r = tbz_points(ctx, rl, ps, pp, opt, flags, out, fout, sv ? &sv2 : NULL, stats);
    if (sv) { sv->blend = r == SFB_SUCCESS ? sv2.blend : NULL; sv->F = r == SFB_SUCCESS ? sv2.F : NULL; }
    if (r != SFB_SUCCESS) sfb__level_free(ctx, rl);
    if (split) sfb__level_free(ctx, &sl);
    sfb__free(ctx, oe);
    sfb__free(ctx, ov);
    sfb__free(ctx, spos);
    sfb__free(ctx, ps);
    sfb__free(ctx, pp);
    return r;
}

sfb_result sfb__tribezier_refined_points(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                                         unsigned flags, sfb__level *rl, double **out, sfb__tbz_stats *stats) {
    return tbz_refined(ctx, l, positions, opt, flags, rl, out, NULL, NULL, stats);
}

/* One patch per triangle where the G1 constraints are solvable on the mesh itself; where they
 * are not (extraordinary vertices of different valences that touch, found up front, or a
 * residual above 1e-10 left), and where the mesh is too coarse for them (TBZ_COVER below), the
 * net is built on the mesh after one Loop step instead (Peters'
 * remedy: afterwards every extraordinary vertex is surrounded by ordinary ones), or two where
 * the extraordinary vertices come in large groups (tbz_largest_group), and each triangle gets
 * its four child patches (depth 1 of its parametric triangle) or sixteen grandchildren (depth
 * 2); the refined net is kept if it is closer to G1 (a coarse mesh's: if it is G1). */
/* The share of a net's points that the G1 solve may move (those within TBZ_REACH net steps of an
 * irregular vertex) above which the net is built after a Loop step instead, as where the solve
 * leaves a residual: there the mesh is too coarse for the construction, its irregular vertices'
 * regions cover most of it, and the correction waved the highlight lines across whole faces (the
 * creased box triangulated, 26 vertices: 87 % of the sharp net's points, where Loop's lines are
 * straight); one step halves the regions. A disk of four rings around one extraordinary vertex
 * (examples/data/tribezier_crease_v5.obj): 38-40 %, kept. */
#define TBZ_COVER 0.5
/* Do two interior extraordinary vertices of different valences share an edge? (Then the
 * constraints on the mesh itself have no exact solution: the refined net is built directly.) */
static int tbz_touching(const sfb__level *l) {
    int e;
    for (e = 0; e < l->ne; ++e) {
        const int a = l->ev[2 * e], b = l->ev[2 * e + 1], na = tbz_nf(l, a), nb = tbz_nf(l, b);
        if (l->ef_off[e + 1] - l->ef_off[e] != 2 || tbz_boundary(l, a) || tbz_boundary(l, b)) continue;
        if (na != 6 && nb != 6 && na != nb) return 1;
    }
    return 0;
}

static sfb_result tbz_build(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                            const tbz_origin *org, sfb__patch_table *pt);

/* The most interior extraordinary vertices in one group of them joined by edges (union-find;
 * out of memory: all of them, taken as large). After one Loop step each group's regions of
 * unknowns merge into one component (two edges apart, six net steps around each), after two
 * they do not (tbz_build). TBZ_ONE_STEP_GROUP: the largest group for which one step is taken:
 * a group of up to 8 merges into a component of at most about 1,500 unknowns, which CGLS solves
 * in milliseconds, and one step keeps four patches per triangle instead of sixteen (the bench's
 * torus, groups of at most 4: built in 34 ms per 1,000 triangles after one step, 26 after two,
 * but evaluated 9.7 times as fast as OpenSubdiv after one and 4.4 after two, its points four
 * times as many). Real meshes' groups are far larger (cow.obj 520, spot.obj 73). */
#define TBZ_ONE_STEP_GROUP 8
static int tbz_largest_group(sfb_context *ctx, const sfb__level *l) {
    int *parent = (int *)sfb__alloc(ctx, ((size_t)l->nv + 1) * sizeof(int));
    int *count = (int *)sfb__calloc(ctx, (size_t)l->nv + 1, sizeof(int));
    int v, e, best = 0;
    if (!parent || !count) { sfb__free(ctx, parent); sfb__free(ctx, count); return l->nv; }
    for (v = 0; v < l->nv; ++v) parent[v] = v;
    for (e = 0; e < l->ne; ++e) {
        const int a = l->ev[2 * e], b = l->ev[2 * e + 1];
        if (l->ef_off[e + 1] - l->ef_off[e] != 2 || tbz_boundary(l, a) || tbz_boundary(l, b) || tbz_nf(l, a) == 6 || tbz_nf(l, b) == 6) continue;
        {
            const int ra = tbz_root(parent, a), rb = tbz_root(parent, b);
            if (ra != rb) parent[rb] = ra;
        }
    }
    for (v = 0; v < l->nv; ++v)
        if (!tbz_boundary(l, v) && tbz_nf(l, v) != 6 && tbz_nf(l, v) > 0) {
            const int r = tbz_root(parent, v);
            if (++count[r] > best) best = count[r];
        }
    sfb__free(ctx, parent);
    sfb__free(ctx, count);
    return best;
}

sfb_result sfb__tribezier_build(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                                sfb__patch_table *pt) {
    /* non-manifold vertices split (tbz_split): the same triangles, so the table is the split
     * mesh's */
    sfb__level sl;
    float *spos = NULL;
    int split, *oe = NULL, *ov = NULL, k;
    tbz_origin org;
    sfb_result r;
    memset(pt, 0, sizeof *pt);
    r = tbz_check(ctx, l, positions, opt);
    if (r == SFB_SUCCESS) r = tbz_split(ctx, l, positions, &split, &sl, &spos);
    if (r != SFB_SUCCESS) return r;
    /* the slider's features are the base mesh's: the split level's edges and vertices mapped
     * back through the same face slots */
    memset(&org, 0, sizeof org);
    org.nbe = l->ne; org.nbv = l->nv; org.bes = l->es; org.bvs = l->vs;
    if (split && opt && opt->slider) {
        oe = (int *)sfb__alloc(ctx, ((size_t)sl.ne + 1) * sizeof(int));
        ov = (int *)sfb__alloc(ctx, ((size_t)sl.nv + 1) * sizeof(int));
        if (!oe || !ov) r = sfb__oom(ctx, "tribezier slider");
        else
            for (k = 0; k < l->nfv; ++k) { oe[sl.fe[k]] = l->fe[k]; ov[sl.fv[k]] = l->fv[k]; }
        org.e = oe; org.v = ov;
    }
    if (r == SFB_SUCCESS) r = split ? tbz_build(ctx, &sl, spos, opt, &org, pt) : tbz_build(ctx, l, positions, opt, &org, pt);
    sfb__free(ctx, oe);
    sfb__free(ctx, ov);
    if (split) {
        sfb__level_free(ctx, &sl);
        sfb__free(ctx, spos);
    }
    /* the build's last report; a cancel there keeps nothing either */
    if (r == SFB_SUCCESS && (r = sfb__progress(ctx, 1.0f, "tribezier")) != SFB_SUCCESS) sfb__patch_table_free(ctx, pt);
    return r;
}

/* sfb__tribezier_build on a mesh of manifold vertices (checked); org: where its edges and
 * vertices came from (the slider's). */
static sfb_result tbz_build(sfb_context *ctx, const sfb__level *l, const float *positions, const sfb_tribezier_options *opt,
                            const tbz_origin *org, sfb__patch_table *pt) {
    double *net = NULL, *net4 = NULL;
    tbz_slider sv, sv4, *want = NULL, *want4 = NULL;
    sfb__tbz_stats st, st4;
    sfb__level rl;
    sfb_result r;
    unsigned two;
    int cover;
    memset(&st, 0, sizeof st);
    memset(&sv, 0, sizeof sv);
    memset(&sv4, 0, sizeof sv4);
    if (opt && opt->slider) {
        sv.org = sv4.org = *org;
        want = &sv;
        want4 = &sv4;
    }
    /* progress (stage "tribezier"): the mesh's own net over [0, 0.5], the one after a Loop step
     * over [0.5, 1] (over [0, 1] where it is the only one). One Loop step or two (the top of
     * this file): two where a group of more than TBZ_ONE_STEP_GROUP extraordinary vertices would
     * merge into one large component after one (decided only where a step is taken) */
    if (tbz_touching(l)) {
        two = tbz_largest_group(ctx, l) > TBZ_ONE_STEP_GROUP ? SFB__TBZ_TWO_STEPS : 0;
        /* the table first, the net written into its point data (tbz_points) */
        if ((r = sfb__patch_table_beztri_children(ctx, l, NULL, two ? 2 : 1, pt)) != SFB_SUCCESS) return r;
        r = tbz_refined(ctx, l, positions, opt, two | TBZ_CHECKED, &rl, &net4, pt->point_data, want4, NULL);
        if (r != SFB_SUCCESS) { sfb__patch_table_free(ctx, pt); return r; }
        pt->blend = sv4.blend;
        pt->features = sv4.F;
        sfb__level_free(ctx, &rl);
        return r;
    }
    /* l is checked and split (sfb__tribezier_build): the points directly */
    r = tbz_points(ctx, l, positions, positions, opt, SFB__TBZ_PROGRESS_LOW, &net, NULL, want, &st);
    if (r != SFB_SUCCESS) return r;
    cover = (double)st.unknowns > TBZ_COVER * (double)(st.sharp_only ? 1 : 2) * ((double)l->nv + 3.0 * l->ne + 3.0 * l->nf);
    if (st.residual > 1e-10 || cover) {
        /* a refused step is this build's own business, not a failure the caller should read
         * after a successful create */
        sfb__error_state kept;
        two = tbz_largest_group(ctx, l) > TBZ_ONE_STEP_GROUP ? SFB__TBZ_TWO_STEPS : 0;
        sfb__error_keep(ctx, &kept);
        memset(&st4, 0, sizeof st4);
        r = tbz_refined(ctx, l, positions, opt, SFB__TBZ_PROGRESS_HIGH | two | TBZ_CHECKED, &rl, &net4, NULL, want4, &st4);
        if (r == SFB_INVALID_TOPOLOGY) { /* not built after the steps: the mesh's own net */
            sfb__log(ctx, SFB_LOG_INFO, "tribezier: the net after Loop steps is refused (%s); the mesh's own net is kept (G1 residual %.3g)",
                     ctx->error, st.residual);
            sfb__error_put_back(ctx, &kept);
            st4.residual = HUGE_VAL;
        } else if (r != SFB_SUCCESS) { sfb__free(ctx, net); tbz_slider_free(ctx, &sv); return r; }
        if (st4.residual < st.residual || (cover && st4.residual <= 1e-10)) {
            sfb__free(ctx, net);
            tbz_slider_free(ctx, &sv);
            r = sfb__patch_table_beztri_children(ctx, l, net4, two ? 2 : 1, pt);
            sfb__free(ctx, net4);
            sfb__level_free(ctx, &rl);
            if (r == SFB_SUCCESS) { pt->blend = sv4.blend; pt->features = sv4.F; }
            else tbz_slider_free(ctx, &sv4);
            return r;
        }
        sfb__free(ctx, net4);
        tbz_slider_free(ctx, &sv4);
        sfb__level_free(ctx, &rl);
    }
    r = sfb__patch_table_beztri_own(ctx, l, net, pt);
    sfb__free(ctx, net);
    if (r == SFB_SUCCESS) { pt->blend = sv.blend; pt->features = sv.F; }
    else tbz_slider_free(ctx, &sv);
    return r;
}
