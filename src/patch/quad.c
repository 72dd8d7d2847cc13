/* The quad family's records (SFB__FAMILY_QUAD): BSPLINE16 (a regular quad, phantoms mirrored
 * across infinitely sharp creases), STAM (one smooth extraordinary corner, eigen form) and
 * ENDCAP (the bilinear cap at the isolation limit) -- how a candidate quad becomes one
 * (sfb__pb_face_quad, called by the isolation driver in patch/build.c) and their ref evaluation
 * (the sfb__kind_* evaluators that patch/table.c dispatches to). The GLSL kernel
 * (backends/gl/glsl/patches.comp.glsl) and the simd kernels evaluate the same records in float. */

/* Class of vertex v as a corner of quad g; *pos = g's fan position. */
static int sfb__corner_class(const sfb__level *l, int v, int g, int slot, int *pos) {
    int nF = l->vf_off[v + 1] - l->vf_off[v], nE = l->ve_off[v + 1] - l->ve_off[v];
    int e0 = l->ve_off[v], f0 = l->vf_off[v];
    int p = sfb__fan_pos(l, v, g, slot), i, nsharp = 0, ninf = 0, cyclic = nE == nF;
    int rule = l->vrule[v];
    float vs = l->vs[v];
    *pos = p;
    if (p < 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD)) return SFB__CORNER_IRREGULAR;
    for (i = 0; i < nE; ++i) {
        float s = l->es[l->ve[e0 + i]];
        nsharp += s > 0.0f;
        ninf += sfb__is_inf(s);
    }
    if (rule == SFB__RULE_SMOOTH && vs == 0.0f && nsharp == 0 && cyclic) {
        for (i = 0; i < nF; ++i)
            if (sfb__face_n(l, l->vf[f0 + i]) != 4) return SFB__CORNER_IRREGULAR;
        return nF == 4 ? SFB__CORNER_R1 : (nF >= 3 ? SFB__CORNER_EV : SFB__CORNER_IRREGULAR);
    }
    if (rule == SFB__RULE_CREASE && vs == 0.0f && nsharp == 2 && ninf == 2) {
        /* the sector of g: faces reachable without crossing a sharp edge */
        int e_d1 = l->ve[e0 + p], e_d2 = l->ve[e0 + (p + 1) % nE];
        if (!cyclic && p + 1 >= nE) return SFB__CORNER_IRREGULAR;
        if (sfb__face_n(l, g) != 4) return SFB__CORNER_IRREGULAR;
        if (sfb__is_inf(l->es[e_d1]) && !sfb__is_inf(l->es[e_d2])) {
            /* sector {g, next}: next face exists, is a quad, and the edge after it is sharp */
            int q = p + 1, e_next;
            if (q >= nF && !cyclic) return SFB__CORNER_IRREGULAR;
            q %= nF;
            e_next = l->ve[e0 + (p + 2) % nE];
            if (!cyclic && p + 2 >= nE) return SFB__CORNER_IRREGULAR;
            if (sfb__face_n(l, l->vf[f0 + q]) != 4 || !sfb__is_inf(l->es[e_next])) return SFB__CORNER_IRREGULAR;
            return SFB__CORNER_R2_D1; /* crease along d1 / -d1: phantoms at b = -1 */
        }
        if (!sfb__is_inf(l->es[e_d1]) && sfb__is_inf(l->es[e_d2])) {
            int q = p - 1, e_prev;
            if (q < 0 && !cyclic) return SFB__CORNER_IRREGULAR;
            q = (q + nF) % nF;
            e_prev = l->ve[e0 + (p - 1 + nE) % nE];
            if (!cyclic && p - 1 < 0) return SFB__CORNER_IRREGULAR;
            if (sfb__face_n(l, l->vf[f0 + q]) != 4 || !sfb__is_inf(l->es[e_prev])) return SFB__CORNER_IRREGULAR;
            return SFB__CORNER_R2_D2; /* crease along d2 / -d2: phantoms at a = -1 */
        }
        return SFB__CORNER_IRREGULAR;
    }
    if (rule == SFB__RULE_CORNER && (vs == 0.0f || sfb__is_inf(vs)) && nsharp == ninf) {
        int e_d1 = l->ve[e0 + p];
        int e_d2;
        if (!cyclic && p + 1 >= nE) return SFB__CORNER_IRREGULAR;
        e_d2 = l->ve[e0 + (p + 1) % nE];
        if (sfb__face_n(l, g) == 4 && sfb__is_inf(l->es[e_d1]) && sfb__is_inf(l->es[e_d2])) return SFB__CORNER_R3;
    }
    return SFB__CORNER_IRREGULAR;
}

static const int sfb__corner_pos[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

static const int sfb__corner_d1[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};

static const int sfb__corner_d2[4][2] = {{0, 1}, {-1, 0}, {0, -1}, {1, 0}};

static int sfb__diag(const sfb__level *l, int f, int v) {
    int o = l->fv_off[f], k;
    for (k = 0; k < 4; ++k)
        if (l->fv[o + k] == v) return l->fv[o + (k + 2) % 4];
    return -1;
}

/* The real points around corner vertex v (fan position p of g): local (a,b) -> vertex, for
 * the quadrants present (mask bit q: 0 = (+,+) g, 1 = (-,+), 2 = (-,-), 3 = (+,-)). */
static void sfb__corner_ring(const sfb__level *l, int v, int p, unsigned quads, int out[3][3]) {
    int e0 = l->ve_off[v], f0 = l->vf_off[v], nE = l->ve_off[v + 1] - e0, nF = l->vf_off[v + 1] - f0;
    int a, b;
#define SFB__EDGE(k) sfb__other_end(l, l->ve[e0 + ((p + (k)) % nE + nE) % nE], v)
#define SFB__FACE(k) l->vf[f0 + ((p + (k)) % nF + nF) % nF]
    for (a = 0; a < 3; ++a)
        for (b = 0; b < 3; ++b) out[a][b] = -1;
    out[1][1] = v;
    /* quadrant 0 (g) always: edges d1 (k=0) and d2 (k=1) */
    out[2][1] = SFB__EDGE(0);
    out[1][2] = SFB__EDGE(1);
    out[2][2] = sfb__diag(l, SFB__FACE(0), v);
    if (quads & 2u) { out[0][1] = SFB__EDGE(2); out[0][2] = sfb__diag(l, SFB__FACE(1), v); }
    if (quads & 4u) { out[0][1] = SFB__EDGE(2); out[1][0] = SFB__EDGE(3); out[0][0] = sfb__diag(l, SFB__FACE(2), v); }
    if (quads & 8u) { out[1][0] = SFB__EDGE(-1 + nE); out[2][0] = sfb__diag(l, SFB__FACE(-1 + nF), v); }
#undef SFB__EDGE
#undef SFB__FACE
}

/* Fills the 4x4 grid (cells x,y in -1..2 -> [y+1][x+1]) of quad g in the frame whose corner 0
 * is slot `rot`, for corners whose class is given (R1/R2/R3; skip = corner not gathered, for
 * the EV of a Stam patch). Returns 0 when the corners disagree. */
static int sfb__gather(const sfb__level *l, int g, int rot, const int cls[4], const int pos[4], int skip, sfb__cell grid[4][4]) {
    int k, a, b, x, y;
    for (y = 0; y < 4; ++y)
        for (x = 0; x < 4; ++x) grid[y][x].n = 0, grid[y][x].real = 0;
    /* real points first */
    for (k = 0; k < 4; ++k) {
        int ring[3][3], v;
        unsigned quads;
        if (k == skip) continue;
        v = l->fv[l->fv_off[g] + (rot + k) % 4];
        quads = cls[k] == SFB__CORNER_R1 ? 15u : cls[k] == SFB__CORNER_R2_D1 ? 3u : cls[k] == SFB__CORNER_R2_D2 ? 9u : 1u;
        sfb__corner_ring(l, v, pos[k], quads, ring);
        for (a = -1; a <= 1; ++a)
            for (b = -1; b <= 1; ++b) {
                int vv = ring[a + 1][b + 1];
                sfb__cell *c;
                if (vv < 0) continue;
                x = sfb__corner_pos[k][0] + a * sfb__corner_d1[k][0] + b * sfb__corner_d2[k][0];
                y = sfb__corner_pos[k][1] + a * sfb__corner_d1[k][1] + b * sfb__corner_d2[k][1];
                if (x < -1 || x > 2 || y < -1 || y > 2) continue;
                c = &grid[y + 1][x + 1];
                if (c->real && c->v[0] != vv) return 0;
                c->real = 1; c->n = 1; c->v[0] = vv; c->w[0] = 1.0;
            }
    }
    /* phantoms: mirror across the crease lines, corner by corner */
    for (k = 0; k < 4; ++k) {
        int pass;
        if (k == skip || cls[k] == SFB__CORNER_R1) continue;
        for (pass = 0; pass < 2; ++pass)
            for (a = -1; a <= 1; ++a)
                for (b = -1; b <= 1; ++b) {
                    int mirror_b = (cls[k] == SFB__CORNER_R2_D1 || cls[k] == SFB__CORNER_R3) && b == -1;
                    int mirror_a = (cls[k] == SFB__CORNER_R2_D2 || cls[k] == SFB__CORNER_R3) && a == -1;
                    int sa, sb, t;
                    sfb__cell *c, *p0, *p1;
                    /* pass 0: one mirrored index; pass 1: the (-1,-1) cell of R3 from pass-0 phantoms */
                    if (!(mirror_a || mirror_b) || (pass == 0) != !(mirror_a && mirror_b)) continue;
                    x = sfb__corner_pos[k][0] + a * sfb__corner_d1[k][0] + b * sfb__corner_d2[k][0];
                    y = sfb__corner_pos[k][1] + a * sfb__corner_d1[k][1] + b * sfb__corner_d2[k][1];
                    if (x < -1 || x > 2 || y < -1 || y > 2) continue;
                    c = &grid[y + 1][x + 1];
                    if (c->real) return 0;
                    if (c->n) continue;
                    /* P = 2 P(mirror line) - P(inside) along the mirrored direction */
                    if (mirror_b) { sa = a; sb = 0; }
                    else { sa = 0; sb = b; }
                    {
                        int x0 = sfb__corner_pos[k][0] + sa * sfb__corner_d1[k][0] + sb * sfb__corner_d2[k][0];
                        int y0 = sfb__corner_pos[k][1] + sa * sfb__corner_d1[k][1] + sb * sfb__corner_d2[k][1];
                        int ia = mirror_b ? a : 1, ib = mirror_b ? 1 : b;
                        int x1 = sfb__corner_pos[k][0] + ia * sfb__corner_d1[k][0] + ib * sfb__corner_d2[k][0];
                        int y1 = sfb__corner_pos[k][1] + ia * sfb__corner_d1[k][1] + ib * sfb__corner_d2[k][1];
                        p0 = &grid[y0 + 1][x0 + 1];
                        p1 = &grid[y1 + 1][x1 + 1];
                    }
                    if (!p0->n || !p1->n || p0->n + p1->n > 4) return 0;
                    c->n = 0;
                    for (t = 0; t < p0->n; ++t) { c->v[c->n] = p0->v[t]; c->w[c->n++] = 2.0 * p0->w[t]; }
                    for (t = 0; t < p1->n; ++t) { c->v[c->n] = p1->v[t]; c->w[c->n++] = -p1->w[t]; }
                }
    }
    return 1;
}

/* Classifies candidate g; adds its patch, or returns 1 in *refine. */
sfb_result sfb__pb_face_quad(sfb__pbuild *b, sfb__wlevel *w, int g, int level, int limit, int *refine) {
    const sfb__level *l = &w->l;
    unsigned par = w->fparam[g];
    int rot = SFB__PARAM_CORNER(par), ptex = w->fptex[g];
    int cls[4], pos[4], k, nev = 0, evk = -1, nirr = 0, patch;
    unsigned out_param;
    sfb__cell grid[4][4];
    *refine = 0;
    if (l->fhole[g]) return sfb__pb_insert(b, ptex, par & ~(3u << 30), -1) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    if (sfb__face_n(l, g) != 4) { *refine = 1; return SFB_SUCCESS; }
    for (k = 0; k < 4; ++k) {
        int slot = (rot + k) % 4, v = l->fv[l->fv_off[g] + slot];
        cls[k] = sfb__corner_class(l, v, g, slot, &pos[k]);
        if (cls[k] == SFB__CORNER_EV) { nev++; evk = k; }
        else if (cls[k] == SFB__CORNER_IRREGULAR) nirr++;
    }
    if (nirr == 0 && nev == 0 && sfb__gather(l, g, rot, cls, pos, -1, grid)) {
        int x, y, base;
        patch = sfb__pb_patch(b, SFB__PATCH_BSPLINE, par & ~(3u << 30), 0, 16);
        if (patch < 0) return sfb__oom(b->ctx, "patch table");
        base = b->pt->pfirst[patch];
        for (y = 0; y < 4; ++y)
            for (x = 0; x < 4; ++x) {
                sfb__cell *c = &grid[y][x];
                int t, row;
                b->m.n = 0;
                for (t = 0; t < c->n; ++t) SFB__MASK_ADD(&b->m, c->v[t], c->w[t]);
                row = sfb__pb_point(b, w->pos, &b->m);
                if (row < 0) return sfb__oom(b->ctx, "patch points");
                b->pt->cv[base + 4 * y + x] = row;
            }
        return sfb__pb_insert(b, ptex, par & ~(3u << 30), patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    }
    if (nev == 1 && nirr == 0 && cls[(evk + 1) % 4] == SFB__CORNER_R1 && cls[(evk + 2) % 4] == SFB__CORNER_R1 &&
        cls[(evk + 3) % 4] == SFB__CORNER_R1) {
        int ev = l->fv[l->fv_off[g] + (rot + evk) % 4];
        int N = l->vf_off[ev + 1] - l->vf_off[ev];
        const sfb__eigen_cc *e = sfb__eigen_cc_get(b->ctx, N);
        int scls[4], spos[4];
        if (e) {
            /* gather in the Stam frame: corner 0 = the EV */
            for (k = 0; k < 4; ++k) { scls[k] = cls[(evk + k) % 4]; spos[k] = pos[(evk + k) % 4]; }
            if (sfb__gather(l, g, (rot + evk) % 4, scls, spos, 0, grid)) {
                int K = e->K, i, pE = spos[0], e0 = l->ve_off[ev], f0 = l->vf_off[ev];
                int *C = (int *)sfb__alloc(b->ctx, (size_t)K * sizeof(int));
                static const int outer[7][2] = {{2, 2}, {2, 1}, {2, 0}, {2, -1}, {1, 2}, {0, 2}, {-1, 2}};
                if (!C) return sfb__oom(b->ctx, "patch table");
                C[0] = ev;
                for (i = 1; i <= N; ++i) {
                    int re = ((pE + (3 - i)) % N + N) % N, rf = ((pE + (2 - i)) % N + N) % N;
                    C[2 * i - 1] = sfb__other_end(l, l->ve[e0 + re], ev);
                    C[2 * i] = sfb__diag(l, l->vf[f0 + rf], ev);
                }
                for (i = 0; i < 7; ++i) {
                    sfb__cell *c = &grid[outer[i][1] + 1][outer[i][0] + 1];
                    C[2 * N + 1 + i] = (c->real && c->n == 1) ? c->v[0] : -1;
                }
                for (i = 0; i < K; ++i)
                    if (C[i] < 0) { sfb__free(b->ctx, C); C = NULL; break; }
                if (C) {
                    out_param = SFB__PARAM(SFB__PARAM_DEPTH(par), SFB__PARAM_I(par), SFB__PARAM_J(par), evk);
                    b->pt->eig[N] = e; /* the context's cache outlives the surface */
                    return sfb__pb_eigen_patch(b, w, SFB__PATCH_STAM, ptex, out_param, N, K, e->vinv, C);
                }
            }
        }
    }
    if ((level >= limit && !sfb__face_semisharp(l, g)) || level >= SFB_MAX_LEVEL + 1)
        return sfb__pb_endcap(b, w, g, rot, 4, par & ~(3u << 30));
    *refine = 1;
    return SFB_SUCCESS;
}

/* ---- ref evaluation ---- */

void sfb__bspline_basis(double t, double *b, double *d, double *dd) {
    double t2 = t * t, t3 = t2 * t, s = 1.0 - t;
    b[0] = s * s * s / 6.0; b[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0; b[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0; b[3] = t3 / 6.0;
    d[0] = -0.5 * s * s; d[1] = 1.5 * t2 - 2.0 * t; d[2] = -1.5 * t2 + t + 0.5; d[3] = 0.5 * t2;
    dd[0] = s; dd[1] = 3.0 * t - 2.0; dd[2] = -3.0 * t + 1.0; dd[3] = t;
}

/* res[0..5]: P, Ps, Pt, Pss, Pst, Ptt in the patch's (s,t); nrm: an unnormalised normal
 * direction (a positive multiple of Ps x Pt, finite where Ps x Pt under- or overflows). */
void sfb__eval_bspline16(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    double bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4];
    int i, j, c;
    sfb__bspline_basis(s, bu, du, ddu);
    sfb__bspline_basis(t, bv, dv, ddv);
    memset(res, 0, sizeof(double) * 18);
    for (j = 0; j < 4; ++j)
        for (i = 0; i < 4; ++i) {
            const float *p = pts + 3 * (size_t)cv[4 * j + i];
            double w[6];
            w[0] = bu[i] * bv[j]; w[1] = du[i] * bv[j]; w[2] = bu[i] * dv[j];
            w[3] = ddu[i] * bv[j]; w[4] = du[i] * dv[j]; w[5] = bu[i] * ddv[j];
            for (c = 0; c < 3; ++c) {
                int q;
                for (q = 0; q < 6; ++q) res[q][c] += w[q] * p[c];
            }
        }
}

void sfb__eval_endcap(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    const float *p0 = pts + 3 * (size_t)cv[0], *p1 = pts + 3 * (size_t)cv[1], *p2 = pts + 3 * (size_t)cv[2], *p3 = pts + 3 * (size_t)cv[3];
    int c;
    for (c = 0; c < 3; ++c) {
        res[0][c] = (1 - s) * (1 - t) * p0[c] + s * (1 - t) * p1[c] + s * t * p2[c] + (1 - s) * t * p3[c];
        res[1][c] = (1 - t) * ((double)p1[c] - p0[c]) + t * ((double)p2[c] - p3[c]);
        res[2][c] = (1 - s) * ((double)p3[c] - p0[c]) + s * ((double)p2[c] - p1[c]);
        res[3][c] = 0.0;
        res[4][c] = (double)p0[c] - p1[c] + p2[c] - p3[c];
        res[5][c] = 0.0;
    }
}

/* Stam: (s,t) in the patch, the EV at frame corner `corner`. nres[2] gets the derivatives
 * divided by sub^(n-1) 2^n (a finite tangent frame down to the EV). nw = 3 computes P and the
 * first derivatives only (res[3..5] = 0), nw = 6 the second derivatives too. Powers are
 * integer powers (repeated squaring), so every backend that calls this gets ref's very sums
 * (the simd backend does, for the locations nearer the EV than its packed levels). */
void sfb__eval_stam(const sfb__eigen_cc *e, const float *pts, const int *cv, int corner, double s, double t, int nw,
                    double res[6][3], double nres[2][3]) {
    int K = e->K, i, j, c, k, n = 1, at_ev, m;
    double u, v, J[2][2], bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4], uu, vv, w[6][16];
    double sr[6][3], nr[2][3], sc1, sc2;
    const double *phi;
    switch (corner) {
    default: u = s; v = t; J[0][0] = 1; J[0][1] = 0; J[1][0] = 0; J[1][1] = 1; break;
    case 1: u = t; v = 1.0 - s; J[0][0] = 0; J[0][1] = 1; J[1][0] = -1; J[1][1] = 0; break;
    case 2: u = 1.0 - s; v = 1.0 - t; J[0][0] = -1; J[0][1] = 0; J[1][0] = 0; J[1][1] = -1; break;
    case 3: u = 1.0 - t; v = s; J[0][0] = 0; J[0][1] = -1; J[1][0] = 1; J[1][1] = 0; break;
    }
    /* J[a][b] = d(u,v)_a / d(s,t)_b */
    memset(sr, 0, sizeof sr);
    memset(nr, 0, sizeof nr);
    at_ev = (u == 0.0 && v == 0.0);
    if (at_ev) {
        /* the limit point; tangents: the n -> infinity limit of the normalised derivatives */
        k = 2; uu = 0.0; vv = 0.0;
    } else {
        while (u < 0.5 && v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
        if (v < 0.5) { k = 1; uu = 2.0 * u - 1.0; vv = 2.0 * v; }
        else if (u < 0.5) { k = 3; uu = 2.0 * u; vv = 2.0 * v - 1.0; }
        else { k = 2; uu = 2.0 * u - 1.0; vv = 2.0 * v - 1.0; }
    }
    sfb__bspline_basis(uu, bu, du, ddu);
    sfb__bspline_basis(vv, bv, dv, ddv);
    for (j = 0; j < 16; ++j) {
        const int a = j % 4, b = j / 4;
        w[0][j] = bu[a] * bv[b]; w[1][j] = du[a] * bv[b]; w[2][j] = bu[a] * dv[b];
        w[3][j] = ddu[a] * bv[b]; w[4][j] = du[a] * dv[b]; w[5][j] = bu[a] * ddv[b];
    }
    phi = e->phi + (size_t)(k - 1) * 16 * K;
    m = n - 1;
    for (i = 0; i < K; ++i) {
        double f[6] = {0, 0, 0, 0, 0, 0}, lp, ln;
        const float *p = pts + 3 * (size_t)cv[i];
        const double *ph = phi + i;
        /* the eigenbasis function i and its derivatives at (uu, vv); named accumulators keep
         * the sums in registers */
        if (nw <= 3) {
            double f0 = 0.0, f1 = 0.0, f2 = 0.0;
            for (j = 0; j < 16; ++j, ph += K) { f0 += w[0][j] * *ph; f1 += w[1][j] * *ph; f2 += w[2][j] * *ph; }
            f[0] = f0; f[1] = f1; f[2] = f2;
        } else {
            double f0 = 0.0, f1 = 0.0, f2 = 0.0, f3 = 0.0, f4 = 0.0, f5 = 0.0;
            for (j = 0; j < 16; ++j, ph += K) {
                f0 += w[0][j] * *ph; f1 += w[1][j] * *ph; f2 += w[2][j] * *ph;
                f3 += w[3][j] * *ph; f4 += w[4][j] * *ph; f5 += w[5][j] * *ph;
            }
            f[0] = f0; f[1] = f1; f[2] = f2; f[3] = f3; f[4] = f4; f[5] = f5;
        }
        if (at_ev) {
            lp = i == e->dominant ? 1.0 : 0.0;
            ln = (i != e->dominant && fabs(fabs(e->lambda[i]) - e->sub) <= 1e-12) ? 1.0 : 0.0;
        } else {
            /* position: lambda^(n-1); derivatives normalised by sub^(n-1) (finite down to the EV) */
            lp = sfb__ipow(e->lambda[i], m);
            ln = i == e->dominant ? 0.0 : sfb__ipow(e->lambda[i] / e->sub, m);
        }
        for (c = 0; c < 3; ++c) {
            sr[0][c] += lp * f[0] * p[c];
            nr[0][c] += ln * f[1] * p[c];
            nr[1][c] += ln * f[2] * p[c];
            sr[3][c] += ln * f[3] * p[c];
            sr[4][c] += ln * f[4] * p[c];
            sr[5][c] += ln * f[5] * p[c];
        }
    }
    sc1 = at_ev ? 1.0 : sfb__ipow(e->sub, m) * ldexp(1.0, n);
    sc2 = at_ev || nw <= 3 ? 0.0 : sfb__ipow(e->sub, m) * ldexp(1.0, 2 * n);
    sfb__stam_finish(J, sc1, sc2, sr, nr, res, nres);
}

/* The Stam kind's evaluator (sfb__patch_kind, patch/table.c): res and the normalised tangent frame. */
void sfb__kind_stam(const sfb__patch_table *pt, const float *pts, int patch, const int *cv, double s, double t, double res[6][3],
                    double dir[2][3]) {
    sfb__eval_stam(pt->eig[pt->pvalence[patch]], pts, cv, SFB__PARAM_CORNER(pt->pparam[patch]), s, t, 6, res, dir);
}
