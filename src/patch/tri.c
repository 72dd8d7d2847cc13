/* The triangle family's records (SFB__FAMILY_TRI): BEZTRI15 (a regular triangle: its box
 * spline as a quartic Bezier triangle by Sabin's rules), STAM_LOOP (one smooth extraordinary
 * corner, eigen form) and ENDCAP_TRI (the linear cap at the isolation limit) -- how a candidate
 * triangle becomes one (sfb__pb_face_tri) and their ref evaluation (sfb__kind_*).
 *
 * A corner of a triangle is R1 (smooth valence 6, no sharp edge), EV (smooth, valence 3..256,
 * no sharp edge), R2 (a crease vertex, two infinitely sharp edges, whose sector on this face's
 * side has 3 triangles) or R3 (a corner whose sector is this triangle alone). In the lattice of
 * the regular triangulation the face's param corners are at (0,0), (1,0), (0,1); corner k's
 * ring, counter-clockwise from the next corner, runs along the lattice directions
 * sfb__hexdir[2k], [2k+1], ... Points missing across a crease are phantoms: X = A + B - C for
 * the real triangle (A,B,C) across the edge AB from X, and X = 2A - B opposite a real neighbour B
 * at a corner (the points that make the box spline's boundary the crease's cubic B-spline, as
 * for OpenSubdiv's regular Loop boundary patches). */

static const int sfb__hexdir[6][2] = {{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}};

static const int sfb__tri_origin[3][2] = {{0, 0}, {1, 0}, {0, 1}};

/* Class of vertex v as a corner of triangle g; *pos = g's fan position; *sec = offset (from
 * *pos) of the first edge of g's sector for R2 (-2..0), 0 for R3. */
static int sfb__tri_corner_class(const sfb__level *l, int v, int g, int slot, int *pos, int *sec) {
    int nF = l->vf_off[v + 1] - l->vf_off[v], nE = l->ve_off[v + 1] - l->ve_off[v];
    int e0 = l->ve_off[v], f0 = l->vf_off[v];
    int p = sfb__fan_pos(l, v, g, slot), i, nsharp = 0, ninf = 0, cyclic = nE == nF;
    int rule = l->vrule[v];
    float vs = l->vs[v];
    *pos = p;
    *sec = 0;
    if (p < 0 || (l->vtag[v] & SFB__TAG_NONMANIFOLD)) return SFB__CORNER_IRREGULAR;
    for (i = 0; i < nE; ++i) {
        float s = l->es[l->ve[e0 + i]];
        nsharp += s > 0.0f;
        ninf += sfb__is_inf(s);
    }
    if (rule == SFB__RULE_SMOOTH && vs == 0.0f && nsharp == 0 && cyclic) {
        for (i = 0; i < nF; ++i)
            if (sfb__face_n(l, l->vf[f0 + i]) != 3) return SFB__CORNER_IRREGULAR;
        return nF == 6 ? SFB__CORNER_R1 : (nF >= 3 ? SFB__CORNER_EV : SFB__CORNER_IRREGULAR);
    }
#define SFB__TE(k) l->es[l->ve[e0 + ((p + (k)) % nE + nE) % nE]]
#define SFB__TIN(k, n) (cyclic || (p + (k) >= 0 && p + (k) < (n)))
    if (rule == SFB__RULE_CREASE && vs == 0.0f && nsharp == 2 && ninf == 2) {
        int st;
        for (st = 0; st >= -2; --st) {
            if (!SFB__TIN(st, nE)) return SFB__CORNER_IRREGULAR;
            if (sfb__is_inf(SFB__TE(st))) break;
        }
        if (st < -2) return SFB__CORNER_IRREGULAR;
        for (i = 0; i < 3; ++i) {
            if (!SFB__TIN(st + i, nF) || sfb__face_n(l, l->vf[f0 + ((p + st + i) % nF + nF) % nF]) != 3) return SFB__CORNER_IRREGULAR;
            if (i > 0 && SFB__TE(st + i) > 0.0f) return SFB__CORNER_IRREGULAR;
        }
        if (!SFB__TIN(st + 3, nE) || !sfb__is_inf(SFB__TE(st + 3))) return SFB__CORNER_IRREGULAR;
        *sec = st;
        return SFB__CORNER_R2_D1;
    }
    if (rule == SFB__RULE_CORNER && (vs == 0.0f || sfb__is_inf(vs)) && nsharp == ninf) {
        if (!SFB__TIN(1, nE) || sfb__face_n(l, g) != 3) return SFB__CORNER_IRREGULAR;
        if (sfb__is_inf(SFB__TE(0)) && sfb__is_inf(SFB__TE(1))) return SFB__CORNER_R3;
    }
#undef SFB__TE
#undef SFB__TIN
    return SFB__CORNER_IRREGULAR;
}

/* Fills grid[y+1][x+1] (x, y in -1..3) with the box-spline points of triangle g in the frame
 * whose corner 0 is slot `rot`; corner `skip` (the EV of a Stam patch) is not gathered.
 * Returns 0 when the corners disagree. */
static int sfb__gather_tri(const sfb__level *l, int g, int rot, const int cls[3], const int pos[3], const int sec[3], int skip,
                           sfb__cell grid[5][5]) {
    int k, x, y;
    for (y = 0; y < 5; ++y)
        for (x = 0; x < 5; ++x) grid[y][x].n = 0, grid[y][x].real = 0;
#define SFB__CELL(d) grid[sfb__tri_origin[k][1] + sfb__hexdir[((2 * k + (d)) % 6 + 6) % 6][1] + 1] \
                         [sfb__tri_origin[k][0] + sfb__hexdir[((2 * k + (d)) % 6 + 6) % 6][0] + 1]
    for (k = 0; k < 3; ++k) {
        int v, e0, nE, lo, hi, d;
        sfb__cell *c;
        if (k == skip) continue;
        v = l->fv[l->fv_off[g] + (rot + k) % 3];
        e0 = l->ve_off[v];
        nE = l->ve_off[v + 1] - e0;
        lo = cls[k] == SFB__CORNER_R1 ? 0 : sec[k];
        hi = cls[k] == SFB__CORNER_R1 ? 5 : cls[k] == SFB__CORNER_R3 ? 1 : sec[k] + 3;
        c = &grid[sfb__tri_origin[k][1] + 1][sfb__tri_origin[k][0] + 1];
        if (c->real && c->v[0] != v) return 0;
        c->real = 1; c->n = 1; c->v[0] = v; c->w[0] = 1.0;
        for (d = lo; d <= hi; ++d) {
            int vv = sfb__other_end(l, l->ve[e0 + ((pos[k] + d) % nE + nE) % nE], v);
            c = &SFB__CELL(d);
            if (c->real && c->v[0] != vv) return 0;
            c->real = 1; c->n = 1; c->v[0] = vv; c->w[0] = 1.0;
        }
    }
    for (k = 0; k < 3; ++k) {
        int lo, hi, d;
        if (k == skip || cls[k] == SFB__CORNER_R1) continue;
        lo = sec[k];
        hi = cls[k] == SFB__CORNER_R3 ? 1 : sec[k] + 3;
        for (d = hi + 1; d <= lo + 5; ++d) {
            sfb__cell *c = &SFB__CELL(d), *B, *C = NULL;
            const sfb__cell *A = &grid[sfb__tri_origin[k][1] + 1][sfb__tri_origin[k][0] + 1]; /* the corner itself */
            if (c->real) return 0;
            if (c->n) continue;
            if (d == hi + 1) { B = &SFB__CELL(hi); C = &SFB__CELL(hi - 1); }
            else if (d == lo + 5) { B = &SFB__CELL(lo); C = &SFB__CELL(lo + 1); }
            else if (d == hi + 2) B = &SFB__CELL(lo);     /* R3: opposite the first edge */
            else B = &SFB__CELL(hi);                      /* R3: opposite the second edge */
            c->n = 0;
            if (C) {
                c->v[c->n] = A->v[0]; c->w[c->n++] = 1.0;
                c->v[c->n] = B->v[0]; c->w[c->n++] = 1.0;
                c->v[c->n] = C->v[0]; c->w[c->n++] = -1.0;
            } else {
                c->v[c->n] = A->v[0]; c->w[c->n++] = 2.0;
                c->v[c->n] = B->v[0]; c->w[c->n++] = -1.0;
            }
        }
    }
#undef SFB__CELL
    return 1;
}

/* Adds one point: the combination sum_i w[i]/24 cell(box12[i]) of the grid (Sabin's rules). */
static int sfb__pb_bez_point(sfb__pbuild *b, const double *pos, sfb__cell grid[5][5], const unsigned char w[12]) {
    int i, t;
    b->m.n = 0;
    for (i = 0; i < 12; ++i) {
        const sfb__cell *c = &grid[sfb__box12[i][1] + 1][sfb__box12[i][0] + 1];
        if (!w[i]) continue;
        for (t = 0; t < c->n; ++t) SFB__MASK_ADD(&b->m, c->v[t], c->w[t] * w[i] / 24.0);
    }
    return sfb__pb_point(b, pos, &b->m);
}

/* Classifies candidate triangle g; adds its patch, or returns 1 in *refine. */
sfb_result sfb__pb_face_tri(sfb__pbuild *b, sfb__wlevel *w, int g, int level, int limit, int *refine) {
    const sfb__level *l = &w->l;
    unsigned par = w->fparam[g], plain = par & ~(3u << 30);
    int rot = SFB__PARAM_CORNER(par), ptex = w->fptex[g];
    int cls[3], pos[3], sec[3], k, nev = 0, evk = -1, nirr = 0, patch, base, j;
    sfb__cell grid[5][5];
    *refine = 0;
    if (l->fhole[g]) return sfb__pb_insert(b, ptex, plain, -1) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    if (sfb__face_n(l, g) != 3) { *refine = 1; return SFB_SUCCESS; }
    for (k = 0; k < 3; ++k) {
        int slot = (rot + k) % 3, v = l->fv[l->fv_off[g] + slot];
        cls[k] = sfb__tri_corner_class(l, v, g, slot, &pos[k], &sec[k]);
        if (cls[k] == SFB__CORNER_EV) { nev++; evk = k; }
        else if (cls[k] == SFB__CORNER_IRREGULAR) nirr++;
    }
    if (nirr == 0 && nev == 0 && sfb__gather_tri(l, g, rot, cls, pos, sec, -1, grid)) {
        patch = sfb__pb_patch(b, SFB__PATCH_BEZTRI, plain, 0, 15);
        if (patch < 0) return sfb__oom(b->ctx, "patch table");
        base = b->pt->pfirst[patch];
        for (j = 0; j < 15; ++j) {
            int row = sfb__pb_bez_point(b, w->pos, grid, sfb__bez15_from_box[j]);
            if (row < 0) return sfb__oom(b->ctx, "patch points");
            b->pt->cv[base + j] = row;
        }
        return sfb__pb_insert(b, ptex, plain, patch) ? SFB_SUCCESS : sfb__oom(b->ctx, "patch table");
    }
    if (nev == 1 && nirr == 0 && cls[(evk + 1) % 3] == SFB__CORNER_R1 && cls[(evk + 2) % 3] == SFB__CORNER_R1) {
        int ev = l->fv[l->fv_off[g] + (rot + evk) % 3];
        int N = l->vf_off[ev + 1] - l->vf_off[ev];
        const sfb__eigen_loop *e = sfb__eigen_loop_get(b->ctx, N);
        int scls[3], spos[3], ssec[3];
        for (k = 0; k < 3; ++k) { scls[k] = cls[(evk + k) % 3]; spos[k] = pos[(evk + k) % 3]; ssec[k] = sec[(evk + k) % 3]; }
        if (e && sfb__gather_tri(l, g, (rot + evk) % 3, scls, spos, ssec, 0, grid)) {
            static const int outer[5][2] = {{1, 1}, {2, 0}, {2, -1}, {0, 2}, {-1, 2}};
            int K = e->K, i, e0 = l->ve_off[ev], ok = 1;
            int *C = (int *)sfb__alloc(b->ctx, (size_t)K * sizeof(int));
            unsigned sp = SFB__PARAM(SFB__PARAM_DEPTH(par), SFB__PARAM_I(par), SFB__PARAM_J(par), evk);
            if (!C) return sfb__oom(b->ctx, "patch table");
            C[0] = ev;
            for (i = 0; i < N; ++i) C[1 + i] = sfb__other_end(l, l->ve[e0 + (spos[0] + i) % N], ev);
            for (i = 0; i < 5; ++i) {
                sfb__cell *c = &grid[outer[i][1] + 1][outer[i][0] + 1];
                C[N + 1 + i] = (c->real && c->n == 1) ? c->v[0] : -1;
                ok &= C[N + 1 + i] >= 0;
            }
            /* the regular corners' rings must close around the EV's ring as the lattice says */
            ok &= grid[1][1].real && grid[1][1].v[0] == ev && grid[1][2].v[0] == C[1] && grid[2][1].v[0] == C[2] &&
                  grid[0][2].real && grid[0][2].v[0] == C[N] && grid[2][0].real && grid[2][0].v[0] == C[1 + 2 % N];
            if (ok) {
                b->pt->eigl[N] = e;
                return sfb__pb_eigen_patch(b, w, SFB__PATCH_STAM_LOOP, ptex, sp, N, K, e->vinv, C);
            }
            sfb__free(b->ctx, C);
        }
    }
    if ((level >= limit && !sfb__face_semisharp(l, g)) || level >= SFB_MAX_LEVEL + 1)
        return sfb__pb_endcap(b, w, g, rot, 3, plain);
    *refine = 1;
    return SFB_SUCCESS;
}

/* ---- ref evaluation ---- */

/* Quartic Bernstein basis on a triangle, our point order (row by row in t, s rising in a
 * row): B[0..5][15] = value, d/ds, d/dt, d2/ds2, d2/dsdt, d2/dt2 (the last three only when
 * nw = 6; nw = 3 leaves them unset). Powers up to 4 of s, t and w = 1 - s - t from tables, and
 * the binomial weights 4! / (i! j! k!). */
void sfb__bez15_basis(double s, double t, int nw, double B[6][15]) {
    static const double mult[15] = {1, 4, 6, 4, 1, 4, 12, 12, 4, 6, 12, 6, 4, 4, 1};
    double ps[5], pt[5], pw[5];
    int i, j, q = 0;
    const double w = 1.0 - s - t;
    ps[0] = pt[0] = pw[0] = 1.0;
    for (i = 1; i < 5; ++i) { ps[i] = ps[i - 1] * s; pt[i] = pt[i - 1] * t; pw[i] = pw[i - 1] * w; }
    for (j = 0; j <= 4; ++j)
        for (i = 0; i + j <= 4; ++i, ++q) {
            const int k = 4 - i - j;
            const double c = mult[q];
            /* s^a t^b w^e, 0 for a negative exponent */
#define SFB__M(a, b, e) ((a) < 0 || (b) < 0 || (e) < 0 ? 0.0 : ps[(a) < 0 ? 0 : (a)] * pt[(b) < 0 ? 0 : (b)] * pw[(e) < 0 ? 0 : (e)])
            B[0][q] = c * SFB__M(i, j, k);
            B[1][q] = c * (i * SFB__M(i - 1, j, k) - k * SFB__M(i, j, k - 1));
            B[2][q] = c * (j * SFB__M(i, j - 1, k) - k * SFB__M(i, j, k - 1));
            if (nw > 3) {
                B[3][q] = c * (i * (i - 1) * SFB__M(i - 2, j, k) - 2 * i * k * SFB__M(i - 1, j, k - 1) + k * (k - 1) * SFB__M(i, j, k - 2));
                B[4][q] = c * (i * j * SFB__M(i - 1, j - 1, k) - i * k * SFB__M(i - 1, j, k - 1) - j * k * SFB__M(i, j - 1, k - 1) +
                               k * (k - 1) * SFB__M(i, j, k - 2));
                B[5][q] = c * (j * (j - 1) * SFB__M(i, j - 2, k) - 2 * j * k * SFB__M(i, j - 1, k - 1) + k * (k - 1) * SFB__M(i, j, k - 2));
            }
#undef SFB__M
        }
}

void sfb__eval_beztri(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    double B[6][15];
    int j, q, c;
    sfb__bez15_basis(s, t, 6, B);
    memset(res, 0, sizeof(double) * 18);
    for (j = 0; j < 15; ++j) {
        const float *p = pts + 3 * (size_t)cv[j];
        for (q = 0; q < 6; ++q)
            for (c = 0; c < 3; ++c) res[q][c] += B[q][j] * p[c];
    }
}

void sfb__eval_endcap_tri(const float *pts, const int *cv, double s, double t, double res[6][3]) {
    const float *p0 = pts + 3 * (size_t)cv[0], *p1 = pts + 3 * (size_t)cv[1], *p2 = pts + 3 * (size_t)cv[2];
    int c;
    memset(res, 0, sizeof(double) * 18);
    for (c = 0; c < 3; ++c) {
        res[0][c] = (1 - s - t) * p0[c] + s * p1[c] + t * p2[c];
        res[1][c] = (double)p1[c] - p0[c];
        res[2][c] = (double)p2[c] - p0[c];
    }
}

/* Stam-Loop: (s,t) in the patch, the EV at frame corner `corner`; nw, nres and the powers as
 * sfb__eval_stam (the Jordan term of valence 3 included). */
void sfb__eval_stam_loop(const sfb__eigen_loop *e, const float *pts, const int *cv, int corner, double s, double t, int nw,
                         double res[6][3], double nres[2][3]) {
    int K = e->K, i, j, c, k, n = 1, at_ev, m, q;
    double u, v, J[2][2], B[6][15], ss, tt, sign = 1.0, subm, sc1, sc2;
    double sr[6][3], nr[2][3];
    double f[SFB__STAM_MAX_VALENCE + 6][6];
    const double *phi;
    if (nw > 3) nw = 6; else nw = 3;
    switch (corner) {
    default: u = s; v = t; J[0][0] = 1; J[0][1] = 0; J[1][0] = 0; J[1][1] = 1; break;
    case 1: u = t; v = 1.0 - s - t; J[0][0] = 0; J[0][1] = 1; J[1][0] = -1; J[1][1] = -1; break;
    case 2: u = 1.0 - s - t; v = s; J[0][0] = -1; J[0][1] = -1; J[1][0] = 1; J[1][1] = 0; break;
    }
    if (u < 0.0) u = 0.0;
    if (v < 0.0) v = 0.0;
    memset(sr, 0, sizeof sr);
    memset(nr, 0, sizeof nr);
    at_ev = u + v == 0.0;
    if (at_ev) {
        /* the limit point; tangents: the normalised derivatives' limit, which only the
         * subdominant pair reaches (evaluated anywhere in a sub-patch: the same plane) */
        k = 0; ss = 0.25; tt = 0.25;
    } else {
        while (u + v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
        if (u >= 0.5) { k = 0; ss = 2.0 * u - 1.0; tt = 2.0 * v; }
        else if (v >= 0.5) { k = 1; ss = 2.0 * u; tt = 2.0 * v - 1.0; }
        else { k = 2; ss = 1.0 - 2.0 * u; tt = 1.0 - 2.0 * v; sign = -1.0; }
    }
    m = n - 1;
    sfb__bez15_basis(ss, tt, nw, B);
    phi = e->phi + (size_t)k * 15 * K;
    for (i = 0; i < K; ++i) {
        /* eigenbasis function i and its derivatives at (ss, tt); named accumulators keep the
         * sums in registers */
        const double *ph = phi + i;
        double f0 = 0.0, f1 = 0.0, f2 = 0.0, f3 = 0.0, f4 = 0.0, f5 = 0.0;
        if (nw == 3) {
            for (j = 0; j < 15; ++j, ph += K) { f0 += B[0][j] * *ph; f1 += B[1][j] * *ph; f2 += B[2][j] * *ph; }
        } else {
            for (j = 0; j < 15; ++j, ph += K) {
                f0 += B[0][j] * *ph; f1 += B[1][j] * *ph; f2 += B[2][j] * *ph;
                f3 += B[3][j] * *ph; f4 += B[4][j] * *ph; f5 += B[5][j] * *ph;
            }
        }
        f[i][0] = f0; f[i][1] = f1; f[i][2] = f2; f[i][3] = f3; f[i][4] = f4; f[i][5] = f5;
    }
    subm = sfb__ipow(e->sub, m);
    for (i = 0; i < K; ++i) {
        const float *p = pts + 3 * (size_t)cv[i];
        double g[6];
        for (q = 0; q < 6; ++q) g[q] = 0.0;
        if (at_ev) {
            g[0] = i == e->dominant ? f[i][0] : 0.0;
            if (i != e->dominant && fabs(e->lambda[i] - e->sub) <= 1e-12)
                for (q = 1; q < 3; ++q) g[q] = f[i][q];
        } else {
            /* position: lambda^m; derivatives normalised by sub^m (finite down to the EV) */
            const double lp = sfb__ipow(e->lambda[i], m), ln = i == e->dominant ? 0.0 : sfb__ipow(e->lambda[i] / e->sub, m);
            g[0] = lp * f[i][0];
            for (q = 1; q < nw; ++q) g[q] = ln * f[i][q];
            if (e->head[i] >= 0 && m > 0) {
                /* the second vector of a Jordan block: m lambda^(m-1) of its head's function */
                const int h = e->head[i];
                const double jl = m * sfb__ipow(e->lambda[i], m - 1), jn = jl / subm;
                g[0] += jl * f[h][0];
                for (q = 1; q < nw; ++q) g[q] += jn * f[h][q];
            }
        }
        for (c = 0; c < 3; ++c) {
            sr[0][c] += g[0] * p[c];
            nr[0][c] += g[1] * p[c];
            nr[1][c] += g[2] * p[c];
            sr[3][c] += g[3] * p[c];
            sr[4][c] += g[4] * p[c];
            sr[5][c] += g[5] * p[c];
        }
    }
    for (c = 0; c < 3; ++c) { nr[0][c] *= sign; nr[1][c] *= sign; } /* the middle sub-patch is turned */
    sc1 = at_ev ? 1.0 : subm * ldexp(1.0, n);
    sc2 = at_ev || nw == 3 ? 0.0 : subm * ldexp(1.0, 2 * n);
    sfb__stam_finish(J, sc1, sc2, sr, nr, res, nres);
}

/* The Stam kind's evaluator (sfb__patch_kind, patch/table.c): res and the normalised tangent frame. */
void sfb__kind_stam_loop(const sfb__patch_table *pt, const float *pts, int patch, const int *cv, double s, double t, double res[6][3],
                         double dir[2][3]) {
    sfb__eval_stam_loop(pt->eigl[pt->pvalence[patch]], pts, cv, SFB__PARAM_CORNER(pt->pparam[patch]), s, t, 6, res, dir);
}
