/* Eigen structures for Stam's exact evaluation of Catmull-Clark patches around one smooth
 * extraordinary vertex (ALGORITHMS.md §1), in double precision.
 *
 * Point order (K = 2N+8): 0 the EV, 2i-1 edge neighbour e_i, 2i face diagonal f_i (i = 1..N),
 * 2N+1..2N+7 the outer points at grid (2,2),(2,1),(2,0),(2,-1),(1,2),(0,2),(-1,2); the patch
 * is (0, e_3, f_2, e_2) with u toward e_3 = (1,0) and v toward e_2 = (0,1).
 *
 * A = [S 0; S11 S12] is diagonalised without a general eigensolver:
 * - S (the 2N+1 ring points) is block-circulant: frequency j of the ring gives a 2x2 block
 *   (a 3x3 block with the EV for j = 0) whose eigenvalues are
 *   ((5 + cos t) +- sqrt((1 + cos t)(9 + cos t)))/16, t = 2 pi j / N, and whose eigenvectors
 *   are e_i = cos(i t) (or sin), f_i = (cos(i t) + cos((i+1) t))/(4 lambda - 1) (or sin);
 * - an eigenvector u of S extends to [u; w] of A with (lambda I - S12) w = S11 u, solved with
 *   full pivoting (a consistent singular system when lambda is also an eigenvalue of S12);
 * - the 7 eigenvalues of S12 (1/8, 1/8, 1/16, 1/16, 1/32, 1/32, 1/64) give [0; z].
 * V^-1 comes from an LU factorisation; every build checks max |A - V diag(lambda) V^-1| and
 * refuses the valence when it is not at rounding level. The cost is O(K^3): valences up to
 * SFB__STAM_MAX_VALENCE are supported; higher ones are isolated adaptively instead.
 *
 * What the kernels use: lambda (K), V^-1 (K x K, to make the eigen coefficients C^ = V^-1 C of
 * a face as stencil rows) and Phi_k = P_k Abar V (16 x K per sub-patch k = 1..3), so that
 * x(u,v) = sum_i lambda_i^(n-1) (b(u~,v~)^T Phi_k)_i C^_i. */

static const double sfb__S11[7][8] = {
    {1, 0, 0, 6, 36, 6, 0, 0}, {4, 0, 0, 4, 24, 24, 0, 0}, {6, 0, 0, 1, 6, 36, 6, 1}, {4, 0, 0, 0, 0, 24, 24, 4},
    {4, 0, 0, 24, 24, 4, 0, 0}, {6, 1, 6, 36, 6, 1, 0, 0}, {4, 4, 24, 24, 0, 0, 0, 0}};
static const double sfb__S12[7][7] = {
    {1, 6, 1, 0, 6, 1, 0}, {0, 4, 4, 0, 0, 0, 0}, {0, 1, 6, 1, 0, 0, 0}, {0, 0, 4, 4, 0, 0, 0},
    {0, 0, 0, 0, 4, 4, 0}, {0, 0, 0, 0, 1, 6, 1}, {0, 0, 0, 0, 0, 4, 4}};
static const double sfb__S21[9][7] = {
    {0, 0, 0, 0, 16, 0, 0}, {0, 0, 0, 0, 24, 4, 0}, {0, 0, 0, 0, 16, 16, 0}, {0, 0, 0, 0, 4, 24, 4},
    {0, 0, 0, 0, 0, 16, 16}, {0, 0, 0, 4, 24, 0, 0}, {0, 0, 0, 16, 16, 0, 0}, {0, 0, 4, 24, 4, 0, 0},
    {0, 0, 16, 16, 0, 0, 0}};
static const double sfb__S22[9][7] = {
    {16, 16, 0, 0, 16, 0, 0}, {4, 24, 4, 0, 4, 0, 0}, {0, 16, 16, 0, 0, 0, 0}, {0, 4, 24, 4, 0, 0, 0},
    {0, 0, 16, 16, 0, 0, 0}, {4, 4, 0, 0, 24, 4, 0}, {0, 0, 0, 0, 16, 16, 0}, {0, 0, 0, 0, 4, 24, 4},
    {0, 0, 0, 0, 0, 16, 16}};

/* Picking vectors (ALGORITHMS.md §1.3): entry = offset + m*mult, m = 2N. */
static int sfb__stam_pick(int N, int k, int j) {
    static const signed char off[3][16] = {
        {7, 6, 4, 12, 0, 5, 3, 11, 3, 4, 2, 10, 6, 5, 1, 9},
        {0, 5, 3, 11, 3, 4, 2, 10, 6, 5, 1, 9, 15, 14, 13, 8},
        {1, 0, 5, 3, 2, 3, 4, 2, 7, 6, 5, 1, 16, 15, 14, 13}};
    static const unsigned char mul[3][16] = {
        {0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 1, 1, 1, 1},
        {0, 0, 1, 1, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1},
        {0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1}};
    int v = off[k - 1][j] + (mul[k - 1][j] ? 2 * N : 0);
    /* N = 3: ring index 7 (e_4) is e_1 (the entries equal to m+1 are outer points) */
    if (N == 3 && v == 7 && !mul[k - 1][j]) v = 1;
    return v;
}

/* Dense A (K x K, row-major). */
static void sfb__stam_matrix(int N, double *A) {
    int K = 2 * N + 8, i, r, c;
    double a = 1.0 - 7.0 / (4.0 * N), b = 3.0 / (2.0 * N * N), cc = 1.0 / (4.0 * N * N);
#define SFB__E(i) (2 * ((((i) - 1) % N + N) % N + 1) - 1)
#define SFB__F(i) (2 * ((((i) - 1) % N + N) % N + 1))
    memset(A, 0, (size_t)K * K * sizeof(double));
    A[0] = a;
    for (i = 1; i <= N; ++i) { A[2 * i - 1] = b; A[2 * i] = cc; }
    for (i = 1; i <= N; ++i) {
        double *re = A + (size_t)SFB__E(i) * K, *rf = A + (size_t)SFB__F(i) * K;
        re[0] += 0.375; re[SFB__E(i)] += 0.375; re[SFB__E(i - 1)] += 0.0625; re[SFB__E(i + 1)] += 0.0625;
        re[SFB__F(i - 1)] += 0.0625; re[SFB__F(i)] += 0.0625;
        rf[0] += 0.25; rf[SFB__E(i)] += 0.25; rf[SFB__F(i)] += 0.25; rf[SFB__E(i + 1)] += 0.25;
    }
#undef SFB__E
#undef SFB__F
    for (r = 0; r < 7; ++r) {
        double *row = A + (size_t)(2 * N + 1 + r) * K;
        for (c = 0; c < 8; ++c) {
            int col = (N == 3 && c == 7) ? 1 : c; /* N = 3: e_4 is e_1 */
            row[col] += sfb__S11[r][c] / 64.0;
        }
        for (c = 0; c < 7; ++c) row[2 * N + 1 + c] += sfb__S12[r][c] / 64.0;
    }
}

/* Solves M x = y (n x n, row-major, destroyed) with full pivoting. Pivots below tol are
 * treated as zero (their unknowns set to 0); returns the residual max |M x - y| relative to
 * |y| + |M||x| computed on the original, which the caller passes as M0. */
static double sfb__solve_full(int n, double *M, double *y, double *x, const double *M0, const double *y0) {
    int piv_r[16], piv_c[16], i, j, k, rank = 0;
    double tol = 1e-12, res = 0.0, scale = 1e-300;
    int colperm[16];
    for (i = 0; i < n; ++i) colperm[i] = i;
    for (k = 0; k < n; ++k) {
        int br = -1, bc = -1;
        double best = tol;
        for (i = k; i < n; ++i)
            for (j = k; j < n; ++j)
                if (fabs(M[i * n + j]) > best) { best = fabs(M[i * n + j]); br = i; bc = j; }
        if (br < 0) break;
        if (br != k) {
            for (j = 0; j < n; ++j) { double t = M[k * n + j]; M[k * n + j] = M[br * n + j]; M[br * n + j] = t; }
            { double t = y[k]; y[k] = y[br]; y[br] = t; }
        }
        if (bc != k) {
            for (i = 0; i < n; ++i) { double t = M[i * n + k]; M[i * n + k] = M[i * n + bc]; M[i * n + bc] = t; }
            { int t = colperm[k]; colperm[k] = colperm[bc]; colperm[bc] = t; }
        }
        piv_r[k] = br; piv_c[k] = bc;
        for (i = k + 1; i < n; ++i) {
            double f = M[i * n + k] / M[k * n + k];
            if (f == 0.0) continue;
            for (j = k; j < n; ++j) M[i * n + j] -= f * M[k * n + j];
            y[i] -= f * y[k];
        }
        rank++;
    }
    {
        double z[16];
        for (i = n - 1; i >= 0; --i) {
            double s = y[i];
            if (i >= rank) { z[i] = 0.0; continue; }
            for (j = i + 1; j < n; ++j) s -= M[i * n + j] * z[j];
            z[i] = s / M[i * n + i];
        }
        for (i = 0; i < n; ++i) x[colperm[i]] = z[i];
    }
    for (i = 0; i < n; ++i) {
        double s = -y0[i], a = fabs(y0[i]);
        for (j = 0; j < n; ++j) { s += M0[i * n + j] * x[j]; a += fabs(M0[i * n + j] * x[j]); }
        if (a > scale) scale = a;
        if (fabs(s) > res) res = fabs(s);
    }
    (void)piv_r; (void)piv_c;
    return res / scale;
}

/* Null space of the 7x7 (S12 - mu I): up to 2 vectors, by full-pivot elimination. */
static int sfb__s12_null(double mu, double out[2][7]) {
    double M[49];
    int colperm[7], i, j, k, rank = 0, nfree, f;
    for (i = 0; i < 7; ++i) {
        colperm[i] = i;
        for (j = 0; j < 7; ++j) M[i * 7 + j] = sfb__S12[i][j] / 64.0 - (i == j ? mu : 0.0);
    }
    for (k = 0; k < 7; ++k) {
        int br = -1, bc = -1;
        double best = 1e-12;
        for (i = k; i < 7; ++i)
            for (j = k; j < 7; ++j)
                if (fabs(M[i * 7 + j]) > best) { best = fabs(M[i * 7 + j]); br = i; bc = j; }
        if (br < 0) break;
        for (j = 0; j < 7; ++j) { double t = M[k * 7 + j]; M[k * 7 + j] = M[br * 7 + j]; M[br * 7 + j] = t; }
        for (i = 0; i < 7; ++i) { double t = M[i * 7 + k]; M[i * 7 + k] = M[i * 7 + bc]; M[i * 7 + bc] = t; }
        { int t = colperm[k]; colperm[k] = colperm[bc]; colperm[bc] = t; }
        for (i = 0; i < 7; ++i) {
            double fct;
            if (i == k) continue;
            fct = M[i * 7 + k] / M[k * 7 + k];
            if (fct == 0.0) continue;
            for (j = k; j < 7; ++j) M[i * 7 + j] -= fct * M[k * 7 + j];
        }
        rank++;
    }
    nfree = 7 - rank;
    if (nfree > 2) nfree = 2;
    for (f = 0; f < nfree; ++f) {
        double z[7];
        int fc = rank + f;
        for (i = 0; i < 7; ++i) z[i] = 0.0;
        z[fc] = 1.0;
        for (i = 0; i < rank; ++i) z[i] = -M[i * 7 + fc] / M[i * 7 + i];
        for (i = 0; i < 7; ++i) out[f][colperm[i]] = z[i];
    }
    return nfree;
}

/* In-place inverse of an n x n row-major matrix by LU with partial pivoting (Gauss-Jordan).
 * Returns 0 when singular. `work` holds n ints. */
static int sfb__invert(int n, double *M, double *inv, int *perm) {
    int i, j, k;
    for (i = 0; i < n; ++i) {
        perm[i] = i;
        for (j = 0; j < n; ++j) inv[(size_t)i * n + j] = i == j ? 1.0 : 0.0;
    }
    for (k = 0; k < n; ++k) {
        int p = k;
        double best = fabs(M[(size_t)k * n + k]), d;
        for (i = k + 1; i < n; ++i)
            if (fabs(M[(size_t)i * n + k]) > best) { best = fabs(M[(size_t)i * n + k]); p = i; }
        if (best < 1e-300) return 0;
        if (p != k)
            for (j = 0; j < n; ++j) {
                double t = M[(size_t)k * n + j]; M[(size_t)k * n + j] = M[(size_t)p * n + j]; M[(size_t)p * n + j] = t;
                t = inv[(size_t)k * n + j]; inv[(size_t)k * n + j] = inv[(size_t)p * n + j]; inv[(size_t)p * n + j] = t;
            }
        d = 1.0 / M[(size_t)k * n + k];
        for (j = 0; j < n; ++j) { M[(size_t)k * n + j] *= d; inv[(size_t)k * n + j] *= d; }
        for (i = 0; i < n; ++i) {
            double f;
            if (i == k) continue;
            f = M[(size_t)i * n + k];
            if (f == 0.0) continue;
            for (j = k; j < n; ++j) M[(size_t)i * n + j] -= f * M[(size_t)k * n + j];
            for (j = 0; j < n; ++j) inv[(size_t)i * n + j] -= f * inv[(size_t)k * n + j];
        }
    }
    return 1;
}

void sfb__eigen_cc_free(sfb_context *ctx, sfb__eigen_cc *e) {
    if (!e) return;
    sfb__free(ctx, e->lambda); sfb__free(ctx, e->vinv); sfb__free(ctx, e->phi);
    sfb__free(ctx, e->v); sfb__free(ctx, e->a);
    sfb__free(ctx, e);
}

/* V^-1 into vinv (V copied to the scratch W; perm holds K ints) and *err = max |A - V J V^-1|,
 * J = diag(lambda) plus, where head (NULL: none) gives a Jordan head h for column k, a 1 at
 * (h, k). Returns 0 when V is singular or the error is not at rounding level. */
static int sfb__eigen_invert_check(int K, const double *A, const double *V, const double *lambda, const int *head, double *W,
                                   int *perm, double *vinv, double *err_out) {
    size_t KK = (size_t)K * K;
    double err = 0.0;
    int r, c, k;
    memcpy(W, V, KK * sizeof(double));
    if (!sfb__invert(K, W, vinv, perm)) return 0;
    for (r = 0; r < K; ++r)
        for (c = 0; c < K; ++c) {
            double s = 0.0;
            for (k = 0; k < K; ++k) {
                double vj = V[(size_t)r * K + k] * lambda[k];
                if (head && head[k] >= 0) vj += V[(size_t)r * K + head[k]];
                s += vj * vinv[(size_t)k * K + c];
            }
            s -= A[(size_t)r * K + c];
            if (fabs(s) > err) err = fabs(s);
        }
    *err_out = err;
    return err < 1e-9;
}

/* The 2N+1 right eigenvectors of S (the ring points; frequency 0 as the 3x3 block on (V, e,
 * f)) in the first rows of V's columns, their eigenvalues in lambda, the index of lambda = 1 in
 * *dominant. Returns the number of columns made. */
static int sfb__eigen_cc_ring(int N, const double *A, double *V, double *lambda, int *dominant) {
    int K = 2 * N + 8, col = 0, i, j, q;
#define SFB__SET(r, value) (V[(size_t)(r) * K + col] = (value))
    {
        /* j = 0: constant ring; 3x3 block on (V, e, f) */
        double a = A[0], bN = A[1] * N, cN = A[2] * N;
        double B[3][3];
        double tr, det, disc, l2, l3, lam[3];
        B[0][0] = a; B[0][1] = bN; B[0][2] = cN;
        B[1][0] = 0.375; B[1][1] = 0.5; B[1][2] = 0.125;
        B[2][0] = 0.25; B[2][1] = 0.5; B[2][2] = 0.25;
        tr = B[0][0] + B[1][1] + B[2][2];
        det = B[0][0] * (B[1][1] * B[2][2] - B[1][2] * B[2][1]) - B[0][1] * (B[1][0] * B[2][2] - B[1][2] * B[2][0]) +
              B[0][2] * (B[1][0] * B[2][1] - B[1][1] * B[2][0]);
        /* the other two eigenvalues: l2 + l3 = tr - 1, l2 l3 = det */
        disc = (tr - 1.0) * (tr - 1.0) - 4.0 * det;
        if (disc < 0.0) disc = 0.0;
        l2 = 0.5 * ((tr - 1.0) + sqrt(disc));
        l3 = 0.5 * ((tr - 1.0) - sqrt(disc));
        lam[0] = 1.0; lam[1] = l2; lam[2] = l3;
        for (q = 0; q < 3; ++q) {
            double M[3][3], best = -1.0, x[3] = {1, 1, 1};
            int r1, r2;
            if (q > 0) {
                for (i = 0; i < 3; ++i)
                    for (j = 0; j < 3; ++j) M[i][j] = B[i][j] - (i == j ? lam[q] : 0.0);
                for (r1 = 0; r1 < 3; ++r1)
                    for (r2 = r1 + 1; r2 < 3; ++r2) {
                        double c0 = M[r1][1] * M[r2][2] - M[r1][2] * M[r2][1];
                        double c1 = M[r1][2] * M[r2][0] - M[r1][0] * M[r2][2];
                        double c2 = M[r1][0] * M[r2][1] - M[r1][1] * M[r2][0];
                        double nn = c0 * c0 + c1 * c1 + c2 * c2;
                        if (nn > best) { best = nn; x[0] = c0; x[1] = c1; x[2] = c2; }
                    }
                best = sqrt(best);
                for (i = 0; i < 3; ++i) x[i] /= best;
            }
            SFB__SET(0, x[0]);
            for (i = 1; i <= N; ++i) { SFB__SET(2 * i - 1, x[1]); SFB__SET(2 * i, x[2]); }
            lambda[col] = lam[q];
            if (q == 0) *dominant = col;
            col++;
        }
    }
    for (j = 1; 2 * j < N; ++j) {
        double t = 2.0 * SFB__PI * j / N, c = cos(t);
        double root = sqrt((1.0 + c) * (9.0 + c));
        double lams[2];
        lams[0] = ((5.0 + c) + root) / 16.0;
        lams[1] = ((5.0 + c) - root) / 16.0;
        for (q = 0; q < 2; ++q) {
            double d = 1.0 / (4.0 * lams[q] - 1.0);
            int trig;
            for (trig = 0; trig < 2; ++trig) {
                SFB__SET(0, 0.0);
                for (i = 1; i <= N; ++i) {
                    double x0 = trig ? sin(i * t) : cos(i * t), x1 = trig ? sin((i + 1) * t) : cos((i + 1) * t);
                    SFB__SET(2 * i - 1, x0);
                    SFB__SET(2 * i, (x0 + x1) * d);
                }
                lambda[col++] = lams[q];
            }
        }
    }
    if (N % 2 == 0) {
        for (q = 0; q < 2; ++q) {
            SFB__SET(0, 0.0);
            for (i = 1; i <= N; ++i) {
                double s = (i % 2) ? -1.0 : 1.0;
                SFB__SET(2 * i - 1, q == 0 ? s : 0.0);
                SFB__SET(2 * i, q == 1 ? s : 0.0);
            }
            lambda[col++] = 0.25;
        }
    }
#undef SFB__SET
    return col;
}

/* Extends the `col` eigenvectors of S to A ((lambda I - S12) w = S11 u, in the outer rows of V)
 * and appends [0; z] for the null vectors z of S12 - mu I. Returns the number of columns, -1
 * when a system or a null space is not as expected. */
static int sfb__eigen_cc_extend(int N, double *V, double *lambda, int col) {
    static const double mus[4] = {0.125, 0.0625, 0.03125, 0.015625};
    static const int mult[4] = {2, 2, 2, 1};
    int K = 2 * N + 8, i, k, q;
    for (q = 0; q < col; ++q) {
        double M[49], M0[49], y[7], y0[7], w[7], res;
        for (i = 0; i < 7; ++i) {
            double s = 0.0;
            for (k = 0; k < 8; ++k) {
                int src = (N == 3 && k == 7) ? 1 : k;
                s += sfb__S11[i][k] / 64.0 * V[(size_t)src * K + q];
            }
            y[i] = y0[i] = s;
            for (k = 0; k < 7; ++k) M[i * 7 + k] = M0[i * 7 + k] = (i == k ? lambda[q] : 0.0) - sfb__S12[i][k] / 64.0;
        }
        res = sfb__solve_full(7, M, y, w, M0, y0);
        if (res > 1e-10) return -1;
        for (i = 0; i < 7; ++i) V[(size_t)(2 * N + 1 + i) * K + q] = w[i];
    }
    for (q = 0; q < 4; ++q) {
        double z[2][7];
        int got = sfb__s12_null(mus[q], z), f;
        if (got != mult[q]) return -1;
        for (f = 0; f < got; ++f) {
            for (i = 0; i < 7; ++i) V[(size_t)(2 * N + 1 + i) * K + col] = z[f][i];
            lambda[col++] = mus[q];
        }
    }
    return col;
}

/* Phi_k = P_k Abar V (16 x K per sub-patch k = 1..3) into phi: the picked rows of Abar V, rows
 * < K of it being rows of A V, rows K..K+8 [S21 0 S22] V (computed into the scratch AV, 9 x K). */
static void sfb__eigen_cc_phi(int N, const double *A, const double *V, double *AV, double *phi) {
    int K = 2 * N + 8, i, j, k, q;
    /* rows K..K+8 of Abar V: [S21 0 S22] V */
    for (i = 0; i < 9; ++i)
        for (q = 0; q < K; ++q) {
            double s = 0.0;
            for (k = 0; k < 7; ++k) {
                s += sfb__S21[i][k] / 64.0 * V[(size_t)k * K + q];
                s += sfb__S22[i][k] / 64.0 * V[(size_t)(2 * N + 1 + k) * K + q];
            }
            AV[(size_t)i * K + q] = s;
        }
    /* Phi_k rows: picked rows of Abar V; rows < K of A V are rows of V L */
    for (k = 1; k <= 3; ++k)
        for (j = 0; j < 16; ++j) {
            int p = sfb__stam_pick(N, k, j);
            double *dst = phi + ((size_t)(k - 1) * 16 + j) * K;
            for (q = 0; q < K; ++q) {
                if (p < K) {
                    double s = 0.0;
                    int c;
                    for (c = 0; c < K; ++c) s += A[(size_t)p * K + c] * V[(size_t)c * K + q];
                    dst[q] = s;
                } else {
                    dst[q] = AV[(size_t)(p - K) * K + q];
                }
            }
        }
}

/* Builds the eigen structure of valence N (3..SFB__STAM_MAX_VALENCE). keep: also keep V and A
 * (for tests). */
sfb_result sfb__eigen_cc_build(sfb_context *ctx, int N, int keep, sfb__eigen_cc **out) {
    sfb__eigen_cc *e;
    int K = 2 * N + 8, col, i;
    double *A = NULL, *V = NULL, *W = NULL, *AV = NULL;
    int *perm = NULL;
    size_t KK = (size_t)K * K;
    *out = NULL;
    if (N < 3 || N > SFB__STAM_MAX_VALENCE)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "no Stam eigen structure for valence %d (3..%d)", N,
                          SFB__STAM_MAX_VALENCE);
    e = (sfb__eigen_cc *)sfb__calloc(ctx, 1, sizeof *e);
    A = (double *)sfb__alloc(ctx, KK * sizeof(double));
    V = (double *)sfb__calloc(ctx, KK, sizeof(double));
    W = (double *)sfb__alloc(ctx, KK * sizeof(double));
    AV = (double *)sfb__alloc(ctx, (size_t)9 * K * sizeof(double));
    perm = (int *)sfb__alloc(ctx, (size_t)K * sizeof(int));
    if (e) {
        e->lambda = (double *)sfb__alloc(ctx, (size_t)K * sizeof(double));
        e->vinv = (double *)sfb__alloc(ctx, KK * sizeof(double));
        e->phi = (double *)sfb__alloc(ctx, (size_t)48 * K * sizeof(double));
    }
    if (!e || !A || !V || !W || !AV || !perm || !e->lambda || !e->vinv || !e->phi) goto oom;
    e->N = N;
    e->K = K;
    sfb__stam_matrix(N, A);
    /* right eigenvectors of S, column by column of V (row-major: V[r*K + col]) */
    col = sfb__eigen_cc_ring(N, A, V, e->lambda, &e->dominant);
    if (col != 2 * N + 1) goto defective;
    /* extend each to A: (lambda I - S12) w = S11 u; then S12's own eigenvectors */
    col = sfb__eigen_cc_extend(N, V, e->lambda, col);
    if (col != K) goto defective;
    /* V^-1, and the check A = V L V^-1 */
    if (!sfb__eigen_invert_check(K, A, V, e->lambda, NULL, W, perm, e->vinv, &e->error)) goto defective;
    e->sub = 0.0;
    for (i = 0; i < K; ++i)
        if (i != e->dominant && fabs(e->lambda[i]) > e->sub) e->sub = fabs(e->lambda[i]);
    sfb__eigen_cc_phi(N, A, V, AV, e->phi);
    if (keep) { e->v = V; e->a = A; V = A = NULL; }
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, AV); sfb__free(ctx, perm);
    *out = e;
    return SFB_SUCCESS;
defective:
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, AV); sfb__free(ctx, perm);
    sfb__eigen_cc_free(ctx, e);
    return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "Stam eigen structure of valence %d failed its check", N);
oom:
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, AV); sfb__free(ctx, perm);
    sfb__eigen_cc_free(ctx, e);
    return sfb__oom(ctx, "Stam eigen structure");
}

/* The context's cache: built on first use of a valence, kept until the context goes. */
const sfb__eigen_cc *sfb__eigen_cc_get(sfb_context *ctx, int N) {
    sfb__eigen_cc *e;
    sfb__error_state kept;
    if (N < 3 || N > SFB__STAM_MAX_VALENCE) return NULL;
    if (ctx->eigen_cc[N]) return ctx->eigen_cc[N];
    if (ctx->eigen_cc_failed[N]) return NULL;
    sfb__error_keep(ctx, &kept);
    if (sfb__eigen_cc_build(ctx, N, 0, &e) != SFB_SUCCESS) {
        /* recovered here: said to the logger, and the caller's last error put back (the call
         * that needed the basis still succeeds) */
        ctx->eigen_cc_failed[N] = 1;
        sfb__log(ctx, SFB_LOG_WARN, "valence %d: %s; its faces are isolated adaptively instead", N, ctx->error);
        sfb__error_put_back(ctx, &kept);
        return NULL;
    }
    ctx->eigen_cc[N] = e;
    return e;
}

/* ---- Stam's Loop evaluation, in eigen form (ALGORITHMS.md §1.5, with our own layout) ----
 *
 * Control set of a triangle (EV, a, b), counter-clockwise, a and b regular (valence 6). In the
 * lattice of the regular triangulation the EV is at (0,0), a at (1,0) and b at (0,1) (the
 * patch's (u,v) frame):
 *   0 the EV; 1..N its ring r_0 = a, r_1 = b, r_2, ... counter-clockwise (r_2 at (-1,1),
 *   r_{N-1} at (1,-1)); N+1 (1,1), opposite the edge ab; N+2 (2,0) and N+3 (2,-1) beyond a;
 *   N+4 (0,2) and N+5 (-1,2) beyond b. K = N + 6.
 * One Loop step maps these K points to the same lattice places one level finer (A, K x K);
 * six more points of the finer lattice, (3,0) (2,1) (3,-1) (1,2) (0,3) (-1,3), complete the
 * enlarged set (Abar) from which the three regular sub-patches of the ring are picked: the
 * corner at a ((1,0)..(2,0)..(1,1), k = 0), the corner at b (k = 1) and the middle triangle
 * (k = 2, corner 0 at (1,1), turned by 180 degrees). Each sub-patch is a 12-point box spline,
 * written as a quartic Bezier triangle by ALGORITHMS.md §5.1.
 *
 * A = [S 0; S10 S11] is put in Jordan form without a general eigensolver:
 * - S (EV and ring) is circulant on the ring: eigenvalues 1 and 5/8 - alpha (frequency 0) and
 *   3/8 + cos(2 pi j/N)/4 (cos and sin vectors of frequency j);
 * - S11 (the 5 outer points) has eigenvalues 1/8 (three) and 1/16 (two), eigenvectors known;
 * - an eigenvector w of S extends to [w; y] with y solved in S11's eigenbasis; when its
 *   eigenvalue is also one of S11's and the right-hand side has a component there, A is
 *   defective (valence 3: lambda = 1/16 three times, two eigenvectors): the extension is then
 *   the second vector of a 2 x 2 Jordan block whose head is that component.
 * A^m V = V J^m, so the level-n points of sub-patch k are Phi_k J^(n-1) V^-1 C, with
 * Phi_k = (Bezier of the picked rows of Abar) V (15 x K): a partner column l of a Jordan head h
 * gets lambda^m Phi_l + m lambda^(m-1) Phi_h. */

/* Index of lattice point (x,y) in the enlarged set, -1 if not in it. */
int sfb__loop_index(int N, int x, int y) {
    static const signed char pts[17][3] = {{0, 0, 0}, {1, 0, 1}, {0, 1, 2}, {-1, 1, 3}, {1, -1, -1},
                                           {1, 1, 7},  {2, 0, 8}, {2, -1, 9}, {0, 2, 10}, {-1, 2, 11},
                                           {3, 0, 12}, {2, 1, 13}, {3, -1, 14}, {1, 2, 15}, {0, 3, 16}, {-1, 3, 17}, {99, 99, 0}};
    int i;
    for (i = 0; pts[i][0] != 99; ++i)
        if (pts[i][0] == x && pts[i][1] == y) {
            int c = pts[i][2];
            if (c == -1) return N;           /* r_{N-1} */
            if (c == 3) return 1 + 2 % N;     /* r_2 (r_{N-1} itself when N = 3) */
            return c >= 7 ? N + (c - 6) : c;
        }
    return -1;
}

/* Sabin's rules (ALGORITHMS.md §5.1): Bezier point (i = exponent of s, j = exponent of t,
 * our order row by row in t) from the 12 box-spline points at lattice offsets boxpt[]. */
const signed char sfb__box12[12][2] = {{0, -1}, {1, -1}, {2, -1}, {-1, 0}, {0, 0}, {1, 0},
                                              {2, 0},  {-1, 1}, {0, 1},  {1, 1},  {-1, 2}, {0, 2}};
const unsigned char sfb__bez15_from_box[15][12] = {
    /* row t^0 */
    {2, 2, 0, 2, 12, 2, 0, 2, 2, 0, 0, 0}, {1, 3, 0, 0, 12, 4, 0, 1, 3, 0, 0, 0}, {0, 4, 0, 0, 8, 8, 0, 0, 4, 0, 0, 0},
    {0, 3, 1, 0, 4, 12, 0, 0, 3, 1, 0, 0}, {0, 2, 2, 0, 2, 12, 2, 0, 2, 2, 0, 0},
    /* t^1 */
    {0, 1, 0, 1, 12, 3, 0, 3, 4, 0, 0, 0}, {0, 1, 0, 0, 10, 6, 0, 1, 6, 0, 0, 0}, {0, 1, 0, 0, 6, 10, 0, 0, 6, 1, 0, 0},
    {0, 1, 0, 0, 3, 12, 1, 0, 4, 3, 0, 0},
    /* t^2 */
    {0, 0, 0, 0, 8, 4, 0, 4, 8, 0, 0, 0}, {0, 0, 0, 0, 6, 6, 0, 1, 10, 1, 0, 0}, {0, 0, 0, 0, 4, 8, 0, 0, 8, 4, 0, 0},
    /* t^3 */
    {0, 0, 0, 0, 4, 3, 0, 3, 12, 1, 1, 0}, {0, 0, 0, 0, 3, 4, 0, 1, 12, 3, 0, 1},
    /* t^4 */
    {0, 0, 0, 0, 2, 2, 0, 2, 12, 2, 2, 2}};

void sfb__eigen_loop_free(sfb_context *ctx, sfb__eigen_loop *e) {
    if (!e) return;
    sfb__free(ctx, e->lambda); sfb__free(ctx, e->head); sfb__free(ctx, e->vinv); sfb__free(ctx, e->phi);
    sfb__free(ctx, e->v); sfb__free(ctx, e->a);
    sfb__free(ctx, e);
}

/* A (K x K) followed by the 6 extra rows of Abar: (K + 6) x K, row-major. */
static void sfb__loop_matrix(int N, double *A) {
    int K = N + 6, i;
    double c = cos(2.0 * SFB__PI / N), alpha = 0.625 - (3.0 + 2.0 * c) * (3.0 + 2.0 * c) / 64.0;
    int a = 1, b = 2, r2 = 1 + 2 % N, rl = N, o11 = N + 1, o20 = N + 2, o2m = N + 3, o02 = N + 4, om2 = N + 5;
    memset(A, 0, (size_t)(K + 6) * K * sizeof(double));
#define SFB__A(r, col, w) (A[(size_t)(r) * K + (col)] += (w))
    SFB__A(0, 0, 1.0 - alpha);
    for (i = 1; i <= N; ++i) SFB__A(0, i, alpha / N);
    for (i = 0; i < N; ++i) {
        SFB__A(1 + i, 0, 0.375);
        SFB__A(1 + i, 1 + i, 0.375);
        SFB__A(1 + i, 1 + (i + N - 1) % N, 0.125);
        SFB__A(1 + i, 1 + (i + 1) % N, 0.125);
    }
    /* (1,1): edge ab */
    SFB__A(o11, a, 0.375); SFB__A(o11, b, 0.375); SFB__A(o11, 0, 0.125); SFB__A(o11, o11, 0.125);
    /* (2,0): vertex a (valence 6: 5/8 and 1/16 each) */
    SFB__A(o20, a, 0.625);
    SFB__A(o20, 0, 0.0625); SFB__A(o20, rl, 0.0625); SFB__A(o20, o2m, 0.0625); SFB__A(o20, o20, 0.0625);
    SFB__A(o20, o11, 0.0625); SFB__A(o20, b, 0.0625);
    /* (2,-1): edge a r_{N-1} */
    SFB__A(o2m, a, 0.375); SFB__A(o2m, rl, 0.375); SFB__A(o2m, 0, 0.125); SFB__A(o2m, o2m, 0.125);
    /* (0,2): vertex b */
    SFB__A(o02, b, 0.625);
    SFB__A(o02, 0, 0.0625); SFB__A(o02, a, 0.0625); SFB__A(o02, o11, 0.0625); SFB__A(o02, o02, 0.0625);
    SFB__A(o02, om2, 0.0625); SFB__A(o02, r2, 0.0625);
    /* (-1,2): edge b r_2 */
    SFB__A(om2, b, 0.375); SFB__A(om2, r2, 0.375); SFB__A(om2, 0, 0.125); SFB__A(om2, om2, 0.125);
    /* the enlarged set: (3,0) (2,1) (3,-1) (1,2) (0,3) (-1,3), all edge points */
    SFB__A(K + 0, a, 0.375); SFB__A(K + 0, o20, 0.375); SFB__A(K + 0, o11, 0.125); SFB__A(K + 0, o2m, 0.125);
    SFB__A(K + 1, a, 0.375); SFB__A(K + 1, o11, 0.375); SFB__A(K + 1, o20, 0.125); SFB__A(K + 1, b, 0.125);
    SFB__A(K + 2, a, 0.375); SFB__A(K + 2, o2m, 0.375); SFB__A(K + 2, o20, 0.125); SFB__A(K + 2, rl, 0.125);
    SFB__A(K + 3, b, 0.375); SFB__A(K + 3, o11, 0.375); SFB__A(K + 3, o02, 0.125); SFB__A(K + 3, a, 0.125);
    SFB__A(K + 4, b, 0.375); SFB__A(K + 4, o02, 0.375); SFB__A(K + 4, o11, 0.125); SFB__A(K + 4, om2, 0.125);
    SFB__A(K + 5, b, 0.375); SFB__A(K + 5, om2, 0.375); SFB__A(K + 5, o02, 0.125); SFB__A(K + 5, r2, 0.125);
#undef SFB__A
}

/* S11's eigenvectors (outer order (1,1) (2,0) (2,-1) (0,2) (-1,2)) and eigenvalues */
static const double sfb__loop_U[5][5] = {{1, 0, 0, 0, 0}, {1, 1, 0, 1, 0}, {0, 1, 0, 0, 0}, {1, 0, 1, 0, 1}, {0, 0, 1, 0, 0}};
static const double sfb__loop_mu[5] = {0.125, 0.125, 0.125, 0.0625, 0.0625};

/* S's eigenvectors in the first N+1 rows of V's columns, their eigenvalues in lambda, the
 * index of lambda = 1 in *dominant and the eigenvalue of frequency 1 in *c1. Returns the
 * number of columns made. */
static int sfb__eigen_loop_ring(int N, double *V, double *lambda, int *dominant, double *c1) {
    int K = N + 6, col = 0, i, j;
#define SFB__SET(r, value) (V[(size_t)(r) * K + col] = (value))
    {
        double c = cos(2.0 * SFB__PI / N), alpha = 0.625 - (3.0 + 2.0 * c) * (3.0 + 2.0 * c) / 64.0;
        for (i = 0; i <= N; ++i) SFB__SET(i, 1.0);
        lambda[col] = 1.0;
        *dominant = col++;
        SFB__SET(0, -8.0 * alpha / 3.0);
        for (i = 1; i <= N; ++i) SFB__SET(i, 1.0);
        lambda[col++] = 0.625 - alpha;
    }
    for (j = 1; 2 * j < N; ++j) {
        double t = 2.0 * SFB__PI * j / N;
        int trig;
        for (trig = 0; trig < 2; ++trig) {
            SFB__SET(0, 0.0);
            for (i = 0; i < N; ++i) SFB__SET(1 + i, trig ? sin(i * t) : cos(i * t));
            lambda[col++] = 0.375 + 0.25 * cos(t);
        }
        if (j == 1) *c1 = 0.375 + 0.25 * cos(t);
    }
    if (N % 2 == 0) {
        SFB__SET(0, 0.0);
        for (i = 0; i < N; ++i) SFB__SET(1 + i, (i % 2) ? -1.0 : 1.0);
        lambda[col++] = 0.125;
    }
#undef SFB__SET
    return col;
}

/* Extends S's N+1 eigenvectors to A: (S11 - lambda) y = -S10 w, solved in S11's eigenbasis (Ui
 * its inverse; outer_col the columns of S11's eigenvectors). Where A is defective the column
 * becomes the partner of a Jordan head (head[q]). Returns 0 when it is defective more than
 * once. */
static int sfb__eigen_loop_extend(int N, const double *A, double *V, const double *Ui, const int *outer_col, double *lambda,
                                  int *head) {
    int K = N + 6, i, k, q, l, njordan = 0;
    for (q = 0; q <= N; ++q) {
        double rhs[5], d[5], yh[5], best = 0.0;
        int lstar = -1;
        for (i = 0; i < 5; ++i) {
            double s = 0.0;
            for (k = 0; k <= N; ++k) s += A[(size_t)(N + 1 + i) * K + k] * V[(size_t)k * K + q];
            rhs[i] = s;
        }
        for (l = 0; l < 5; ++l) {
            double s = 0.0;
            for (i = 0; i < 5; ++i) s += Ui[l * 5 + i] * rhs[i];
            d[l] = s;
        }
        for (l = 0; l < 5; ++l) {
            if (fabs(lambda[q] - sfb__loop_mu[l]) > 1e-9) yh[l] = d[l] / (lambda[q] - sfb__loop_mu[l]);
            else {
                yh[l] = 0.0;
                if (fabs(d[l]) > 1e-12 && fabs(d[l]) > best) { best = fabs(d[l]); lstar = l; }
            }
        }
        for (i = 0; i < 5; ++i) {
            double s = 0.0;
            for (l = 0; l < 5; ++l) s += sfb__loop_U[i][l] * yh[l];
            V[(size_t)(N + 1 + i) * K + q] = s;
        }
        if (lstar >= 0) {
            /* defective: (A - lambda)[w; y] = sum over S11's lambda-eigenvectors of d_l [0; u_l].
             * That sum replaces the column of u_lstar as the Jordan head; [w; y] is its partner. */
            int h = outer_col[lstar];
            if (++njordan > 1) return 0;
            for (i = 0; i < 5; ++i) {
                double s = 0.0;
                for (l = 0; l < 5; ++l)
                    if (fabs(lambda[q] - sfb__loop_mu[l]) <= 1e-9) s += d[l] * sfb__loop_U[i][l];
                V[(size_t)(N + 1 + i) * K + h] = s;
            }
            lambda[q] = sfb__loop_mu[lstar];
            head[q] = h;
        }
    }
    return 1;
}

/* Phi_k into phi (15 x K per sub-patch k = 0..2): the Bezier points of the picked rows of
 * Abar V. Returns 0 when a picked point is not in the enlarged set. */
static int sfb__eigen_loop_phi(int N, const double *A, const double *V, double *phi) {
    int K = N + 6, i, j, k, q;
    for (k = 0; k < 3; ++k) {
        static const int org[3][4] = {{1, 0, 1, 0}, {0, 1, 1, 0}, {1, 1, -1, 0}}; /* origin x, y; frame sign; unused */
        int rows[12];
        for (j = 0; j < 12; ++j) {
            int x = org[k][0] + org[k][2] * sfb__box12[j][0], y = org[k][1] + org[k][2] * sfb__box12[j][1];
            rows[j] = sfb__loop_index(N, x, y);
            if (rows[j] < 0) return 0;
        }
        for (q = 0; q < K; ++q) {
            double av[12];
            for (j = 0; j < 12; ++j) {
                double s = 0.0;
                int c;
                for (c = 0; c < K; ++c) s += A[(size_t)rows[j] * K + c] * V[(size_t)c * K + q];
                av[j] = s;
            }
            for (j = 0; j < 15; ++j) {
                double s = 0.0;
                for (i = 0; i < 12; ++i) s += sfb__bez15_from_box[j][i] * av[i];
                phi[((size_t)k * 15 + j) * K + q] = s / 24.0;
            }
        }
    }
    return 1;
}

sfb_result sfb__eigen_loop_build(sfb_context *ctx, int N, int keep, sfb__eigen_loop **out) {
    sfb__eigen_loop *e;
    int K = N + 6, col, i, l;
    double *A = NULL, *V = NULL, *W = NULL;
    double Ui[25], Uw[25];
    int *perm = NULL, outer_col[5];
    size_t KK = (size_t)K * K;
    double c1 = 0.0;
    *out = NULL;
    if (N < 3 || N > SFB__STAM_MAX_VALENCE)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "no Stam-Loop eigen structure for valence %d (3..%d)", N,
                          SFB__STAM_MAX_VALENCE);
    e = (sfb__eigen_loop *)sfb__calloc(ctx, 1, sizeof *e);
    A = (double *)sfb__alloc(ctx, (size_t)(K + 6) * K * sizeof(double));
    V = (double *)sfb__calloc(ctx, KK, sizeof(double));
    W = (double *)sfb__alloc(ctx, KK * sizeof(double));
    perm = (int *)sfb__alloc(ctx, (size_t)K * sizeof(int));
    if (e) {
        e->lambda = (double *)sfb__alloc(ctx, (size_t)K * sizeof(double));
        e->head = (int *)sfb__alloc(ctx, (size_t)K * sizeof(int));
        e->vinv = (double *)sfb__alloc(ctx, KK * sizeof(double));
        e->phi = (double *)sfb__alloc(ctx, (size_t)45 * K * sizeof(double));
    }
    if (!e || !A || !V || !W || !perm || !e->lambda || !e->head || !e->vinv || !e->phi) goto oom;
    e->N = N;
    e->K = K;
    for (i = 0; i < K; ++i) e->head[i] = -1;
    sfb__loop_matrix(N, A);
    for (i = 0; i < 25; ++i) Uw[i] = sfb__loop_U[i / 5][i % 5];
    if (!sfb__invert(5, Uw, Ui, perm)) goto defective;
    /* S's eigenvectors in the first N+1 rows of V */
    col = sfb__eigen_loop_ring(N, V, e->lambda, &e->dominant, &c1);
    if (col != N + 1) goto defective;
    /* S11's eigenvectors [0; u_l] */
    for (l = 0; l < 5; ++l) {
        for (i = 0; i < 5; ++i) V[(size_t)(N + 1 + i) * K + col] = sfb__loop_U[i][l];
        e->lambda[col] = sfb__loop_mu[l];
        outer_col[l] = col++;
    }
    /* extend S's eigenvectors: (S11 - lambda) y = -S10 w, in S11's eigenbasis */
    if (!sfb__eigen_loop_extend(N, A, V, Ui, outer_col, e->lambda, e->head)) goto defective;
    /* V^-1, and the check A = V J V^-1 */
    if (!sfb__eigen_invert_check(K, A, V, e->lambda, e->head, W, perm, e->vinv, &e->error)) goto defective;
    e->sub = c1;
    /* Phi_k: Bezier points of the picked rows of Abar V */
    if (!sfb__eigen_loop_phi(N, A, V, e->phi)) goto defective;
    if (keep) { e->v = V; e->a = A; V = A = NULL; }
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, perm);
    *out = e;
    return SFB_SUCCESS;
defective:
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, perm);
    sfb__eigen_loop_free(ctx, e);
    return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "Stam-Loop eigen structure of valence %d failed its check", N);
oom:
    sfb__free(ctx, A); sfb__free(ctx, V); sfb__free(ctx, W); sfb__free(ctx, perm);
    sfb__eigen_loop_free(ctx, e);
    return sfb__oom(ctx, "Stam-Loop eigen structure");
}

const sfb__eigen_loop *sfb__eigen_loop_get(sfb_context *ctx, int N) {
    sfb__eigen_loop *e;
    sfb__error_state kept;
    if (N < 3 || N > SFB__STAM_MAX_VALENCE) return NULL;
    if (ctx->eigen_loop[N]) return ctx->eigen_loop[N];
    if (ctx->eigen_loop_failed[N]) return NULL;
    sfb__error_keep(ctx, &kept);
    if (sfb__eigen_loop_build(ctx, N, 0, &e) != SFB_SUCCESS) {
        /* recovered here: said to the logger, and the caller's last error put back (the call
         * that needed the basis still succeeds) */
        ctx->eigen_loop_failed[N] = 1;
        sfb__log(ctx, SFB_LOG_WARN, "valence %d: %s; its faces are isolated adaptively instead", N, ctx->error);
        sfb__error_put_back(ctx, &kept);
        return NULL;
    }
    ctx->eigen_loop[N] = e;
    return e;
}
