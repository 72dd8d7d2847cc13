/* The Stam eigen structures (src/patch/eigen.c), checked independently of the checks the builds do
 * themselves. This program reaches the internal builders through src/sfb_internal.h (linked
 * from libsfb_internal.o). For every valence 3..64 and a sample up to SFB__STAM_MAX_VALENCE, Catmull-Clark and Loop:
 *   - the subdivision matrix A is affine (rows sum to 1) and its EV row is the scheme's
 *     vertex rule (weights written here from the textbook formulas);
 *   - A V = V J and V V^-1 = I, recomputed here from the kept V, the eigenvalues and the
 *     Jordan heads (max error relative to max |A|, bound 1e-9);
 *   - the dominant eigenvalue is 1 with eigenvector all ones, the subdominant one is the
 *     closed form of ALGORITHMS.md §1.2 / §1.5;
 *   - Loop valence 3 has exactly one Jordan block ((A - lambda) v_partner = v_head), the
 *     other valences none.
 * And for Loop valence 6 (the regular case), the Stam evaluation of the eigen form must equal
 * the quartic Bezier triangle of the 12-point box spline on the same points, at random (u,v)
 * (position and first and second derivatives): a test of the layout, the subdivision and
 * enlarged matrices, the picking of the three sub-patches (the middle one turned), the level
 * search and the derivative scales. Prints PASS/FAIL lines and "N passed, N failed, N skipped" (tests/harness.h). */
#define SURFBLEND_EXPOSE_INTERNALS /* the internals below have external linkage in libsfb_internal.o */
#include "surfblend.h"
#include "src/sfb_internal.h" /* the library's internal interfaces (linked from libsfb_internal.o) */
#include "harness.h"
#include <math.h>

/* max |A V - V J| and max |V V^-1 - I|, J = diag(lambda) + the Jordan heads' ones */
static void check_decomposition(int K, const double *A, const double *V, const double *vinv, const double *lambda, const int *head,
                                double *e_av, double *e_inv) {
    int r, c, k;
    double amax = 0.0;
    *e_av = *e_inv = 0.0;
    for (r = 0; r < K * K; ++r)
        if (fabs(A[r]) > amax) amax = fabs(A[r]);
    for (r = 0; r < K; ++r)
        for (c = 0; c < K; ++c) {
            double av = 0.0, vj = V[(size_t)r * K + c] * lambda[c], vv = 0.0;
            for (k = 0; k < K; ++k) {
                av += A[(size_t)r * K + k] * V[(size_t)k * K + c];
                vv += V[(size_t)r * K + k] * vinv[(size_t)k * K + c];
            }
            if (head && head[c] >= 0) vj += V[(size_t)r * K + head[c]];
            if (fabs(av - vj) / amax > *e_av) *e_av = fabs(av - vj) / amax;
            if (fabs(vv - (r == c ? 1.0 : 0.0)) > *e_inv) *e_inv = fabs(vv - (r == c ? 1.0 : 0.0));
        }
}

static double row_sum_error(int rows, int K, const double *A) {
    double worst = 0.0;
    int r, c;
    for (r = 0; r < rows; ++r) {
        double s = 0.0;
        for (c = 0; c < K; ++c) s += A[(size_t)r * K + c];
        if (fabs(s - 1.0) > worst) worst = fabs(s - 1.0);
    }
    return worst;
}

static void check_cc(sfb_context *ctx, int N, double *worst) {
    sfb__eigen_cc *e = NULL;
    char name[128];
    int K = 2 * N + 8, i;
    double eav, einv, rs, ev_err = 0.0, sub, t = 2.0 * 3.14159265358979323846 / N;
    if (sfb__eigen_cc_build(ctx, N, 1, &e) != SFB_SUCCESS) {
        snprintf(name, sizeof name, "catmark/%d/build", N);
        fail(name, "%s", sfb_last_error(ctx));
        return;
    }
    check_decomposition(K, e->a, e->v, e->vinv, e->lambda, NULL, &eav, &einv);
    rs = row_sum_error(K, K, e->a);
    /* the EV row: 1 - 7/(4N) on the EV, 3/(2N^2) on each edge neighbour, 1/(4N^2) on each diagonal */
    ev_err = fabs(e->a[0] - (1.0 - 7.0 / (4.0 * N)));
    for (i = 1; i <= N; ++i) {
        ev_err = fmax(ev_err, fabs(e->a[2 * i - 1] - 3.0 / (2.0 * N * N)));
        ev_err = fmax(ev_err, fabs(e->a[2 * i] - 1.0 / (4.0 * N * N)));
    }
    sub = (5.0 + cos(t) + cos(t / 2.0) * sqrt(2.0 * (9.0 + cos(t)))) / 16.0;
    snprintf(name, sizeof name, "catmark/%d/A_rules", N);
    check(rs < 1e-13 && ev_err < 1e-15, name, "row sums off by %.3g, EV row off by %.3g", rs, ev_err);
    snprintf(name, sizeof name, "catmark/%d/AV=VL", N);
    check(eav < 1e-9 && einv < 1e-9, name, "|AV - VL| = %.3g, |V V^-1 - I| = %.3g", eav, einv);
    snprintf(name, sizeof name, "catmark/%d/eigenvalues", N);
    {
        double onesdev = 0.0;
        for (i = 0; i < K; ++i) onesdev = fmax(onesdev, fabs(e->v[(size_t)i * K + e->dominant] / e->v[e->dominant] - 1.0));
        check(fabs(e->lambda[e->dominant] - 1.0) < 1e-15 && fabs(e->sub - sub) < 1e-12 && onesdev < 1e-12, name,
               "dominant/ones off by %.3g, subdominant off by %.3g", fmax(fabs(e->lambda[e->dominant] - 1.0), onesdev), fabs(e->sub - sub));
    }
    if (eav > *worst) *worst = eav;
    sfb__eigen_cc_free(ctx, e);
}

static void check_loop(sfb_context *ctx, int N, double *worst) {
    sfb__eigen_loop *e = NULL;
    char name[128];
    int K = N + 6, i, nj = 0;
    double eav, einv, rs, ev_err, c = cos(2.0 * 3.14159265358979323846 / N), alpha = 0.625 - (3.0 + 2.0 * c) * (3.0 + 2.0 * c) / 64.0;
    if (sfb__eigen_loop_build(ctx, N, 1, &e) != SFB_SUCCESS) {
        snprintf(name, sizeof name, "loop/%d/build", N);
        fail(name, "%s", sfb_last_error(ctx));
        return;
    }
    check_decomposition(K, e->a, e->v, e->vinv, e->lambda, e->head, &eav, &einv);
    rs = row_sum_error(K + 6, K, e->a);
    /* the EV row: 1 - alpha on the EV, alpha/N on each neighbour */
    ev_err = fabs(e->a[0] - (1.0 - alpha));
    for (i = 1; i <= N; ++i) ev_err = fmax(ev_err, fabs(e->a[i] - alpha / N));
    for (i = N + 1; i < K; ++i) ev_err = fmax(ev_err, fabs(e->a[i]));
    snprintf(name, sizeof name, "loop/%d/A_rules", N);
    check(rs < 1e-13 && ev_err < 1e-15, name, "row sums off by %.3g, EV row off by %.3g", rs, ev_err);
    snprintf(name, sizeof name, "loop/%d/AV=VJ", N);
    check(eav < 1e-9 && einv < 1e-9, name, "|AV - VJ| = %.3g, |V V^-1 - I| = %.3g", eav, einv);
    for (i = 0; i < K; ++i) nj += e->head[i] >= 0;
    snprintf(name, sizeof name, "loop/%d/jordan_blocks", N);
    check(nj == (N == 3 ? 1 : 0), name, "%.0f Jordan blocks, expected %.0f", (double)nj, N == 3 ? 1.0 : 0.0);
    snprintf(name, sizeof name, "loop/%d/eigenvalues", N);
    {
        double onesdev = 0.0;
        for (i = 0; i < K; ++i) onesdev = fmax(onesdev, fabs(e->v[(size_t)i * K + e->dominant] / e->v[e->dominant] - 1.0));
        check(fabs(e->lambda[e->dominant] - 1.0) < 1e-15 && fabs(e->sub - (0.375 + 0.25 * c)) < 1e-15 && onesdev < 1e-12, name,
               "dominant/ones off by %.3g, subdominant off by %.3g", onesdev, fabs(e->sub - (0.375 + 0.25 * c)));
    }
    if (eav > *worst) *worst = eav;
    sfb__eigen_loop_free(ctx, e);
}

/* the random control points and parameters: a fixed stream */
static rng g_rng = {12345};
static double rnd(void) { return rng_unit(&g_rng); }

/* Loop, valence 6: the eigen form against the box spline of the same 12 points. */
static void check_loop_regular(sfb_context *ctx) {
    const sfb__eigen_loop *e = sfb__eigen_loop_get(ctx, 6);
    float pts[12 * 3], coef[12 * 3], bez[15 * 3];
    int cv[15], i, j, c, q, k, box[12];
    double worst[3] = {0.0, 0.0, 0.0}, scale = 0.0;
    if (!e) { fail("loop/6/stam_equals_box_spline", "no eigen structure"); return; }
    /* random control points on the lattice, a little perturbed */
    for (i = 0; i < 12; ++i)
        for (c = 0; c < 3; ++c) pts[3 * i + c] = (float)(rnd() * 2.0 - 1.0);
    for (i = 0; i < 12; ++i) {
        /* valence 6: the ring r_0..r_5 lies on the lattice directions (1,0), (0,1), (-1,1), ... */
        static const int dirs[6][2] = {{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}};
        int x = sfb__box12[i][0], y = sfb__box12[i][1], d;
        box[i] = sfb__loop_index(6, x, y);
        for (d = 0; d < 6; ++d)
            if (dirs[d][0] == x && dirs[d][1] == y) box[i] = 1 + d;
    }
    for (j = 0; j < 15; ++j) {
        for (c = 0; c < 3; ++c) {
            double s = 0.0;
            for (i = 0; i < 12; ++i) s += sfb__bez15_from_box[j][i] * (double)pts[3 * box[i] + c];
            bez[3 * j + c] = (float)(s / 24.0);
        }
        cv[j] = j;
    }
    /* eigen coefficients c = V^-1 C */
    for (i = 0; i < 12; ++i)
        for (c = 0; c < 3; ++c) {
            double s = 0.0;
            for (k = 0; k < 12; ++k) s += e->vinv[(size_t)i * 12 + k] * pts[3 * k + c];
            coef[3 * i + c] = (float)s;
        }
    for (q = 0; q < 2000; ++q) {
        double u = rnd(), v = rnd(), rs[6][3], rb[6][3], nres[2][3];
        int corner = q % 3;
        if (q < 200) { u *= 1e-3; v *= 1e-3; }
        if (u + v > 1.0) { u = 1.0 - u; v = 1.0 - v; }
        /* the EV may sit at any corner of the leaf: rotate the Bezier triangle's parameters */
        sfb__eval_stam_loop(e, coef, cv, corner, corner == 0 ? u : corner == 1 ? 1.0 - u - v : v,
                            corner == 0 ? v : corner == 1 ? u : 1.0 - u - v, 6, rs, nres);
        sfb__eval_beztri(bez, cv, u, v, rb);
        /* map the Stam results (in the rotated frame) back: compare position, and the
         * derivatives along the Bezier frame's directions through the chain rule */
        {
            double Js[2][2]; /* d(s_rot,t_rot)/d(u,v) */
            double d1[3], d2[3];
            if (corner == 0) { Js[0][0] = 1; Js[0][1] = 0; Js[1][0] = 0; Js[1][1] = 1; }
            else if (corner == 1) { Js[0][0] = -1; Js[0][1] = -1; Js[1][0] = 1; Js[1][1] = 0; }
            else { Js[0][0] = 0; Js[0][1] = 1; Js[1][0] = -1; Js[1][1] = -1; }
            for (c = 0; c < 3; ++c) {
                d1[c] = rs[1][c] * Js[0][0] + rs[2][c] * Js[1][0];
                d2[c] = rs[1][c] * Js[0][1] + rs[2][c] * Js[1][1];
                worst[0] = fmax(worst[0], fabs(rs[0][c] - rb[0][c]));
                worst[1] = fmax(worst[1], fmax(fabs(d1[c] - rb[1][c]), fabs(d2[c] - rb[2][c])));
                scale = fmax(scale, fabs(rb[1][c]));
            }
            if (corner == 0)
                for (c = 0; c < 3; ++c)
                    for (i = 3; i < 6; ++i) worst[2] = fmax(worst[2], fabs(rs[i][c] - rb[i][c]));
        }
    }
    printf("# loop valence 6, eigen form vs box spline: position %.3g, first derivatives %.3g, second %.3g\n", worst[0], worst[1], worst[2]);
    check(worst[0] < 1e-6 && worst[1] < 1e-5 * fmax(1.0, scale), "loop/6/stam_equals_box_spline", "position off by %.3g, derivatives by %.3g",
           worst[0], worst[1]);
    check(worst[2] < 1e-4, "loop/6/stam_second_derivatives", "second derivatives off by %.3g", worst[2]);
}

/* A basis that cannot be built (here: the memory budget refuses it) is recovered from: get
 * returns NULL (its faces are then isolated adaptively), the reason goes to the logger as a
 * warning, and the caller's last error is left as it was, not wiped. */
typedef struct warn_log {
    int n;
    char msg[1024];
} warn_log;
static void warn_logger(int level, const char *msg, void *user) {
    warn_log *l = (warn_log *)user;
    if (level != SFB_LOG_WARN) return;
    l->n++;
    snprintf(l->msg, sizeof l->msg, "%s", msg);
}
static void check_failed_build_keeps_the_last_error(void) {
    int loop;
    for (loop = 0; loop < 2; ++loop) {
        sfb_context_config cc = sfb_context_config_init();
        sfb_context *ctx = NULL;
        sfb_mesh *m = NULL;
        warn_log lg;
        char earlier[1024], name[96];
        const void *got;
        size_t budget;
        memset(&lg, 0, sizeof lg);
        cc.logger.func = warn_logger;
        cc.logger.user = &lg;
        snprintf(name, sizeof name, "%s/failed_build_keeps_the_last_error", loop ? "loop" : "catmark");
        if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) { fail(name, "no context"); continue; }
        /* an earlier failure of the caller's */
        snprintf(earlier, sizeof earlier, "%s", sfb_mesh_read_obj(ctx, "v 0 0 0\nf 1 2 3\n", 18, &m) != SFB_SUCCESS ? sfb_last_error(ctx) : "");
        if (m) sfb_mesh_destroy(m);
        budget = ctx->budget;
        ctx->budget = ctx->live_bytes + 64; /* the build's first allocation is refused */
        got = loop ? (const void *)sfb__eigen_loop_get(ctx, 7) : (const void *)sfb__eigen_cc_get(ctx, 7);
        ctx->budget = budget;
        check(got == NULL && earlier[0] && strcmp(sfb_last_error(ctx), earlier) == 0 && lg.n == 1 && strstr(lg.msg, "valence 7"), name,
              "basis %p, last error '%s' (earlier '%s'), %d warnings, last '%s'", got, sfb_last_error(ctx), earlier, lg.n, lg.msg);
        /* the failure is remembered: no second attempt, no second warning */
        got = loop ? (const void *)sfb__eigen_loop_get(ctx, 7) : (const void *)sfb__eigen_cc_get(ctx, 7);
        snprintf(name, sizeof name, "%s/failed_build_remembered", loop ? "loop" : "catmark");
        check(got == NULL && lg.n == 1, name, "basis %p, %d warnings", got, lg.n);
        sfb_context_destroy(ctx);
    }
}

int main(void) {
    sfb_context *ctx = make_context(SFB_BACKEND_REF);
    double wcc = 0.0, wloop = 0.0;
    int N;
    if (!ctx) {
        fail("context", "no ref context");
        return close_tests();
    }
    /* every valence up to 64, then a sample up to the largest */
    for (N = 3; N <= SFB__STAM_MAX_VALENCE; N += N < 64 ? 1 : N < 128 ? 16 : 32) {
        check_cc(ctx, N, &wcc);
        check_loop(ctx, N, &wloop);
        if (N < SFB__STAM_MAX_VALENCE && N + (N < 64 ? 1 : N < 128 ? 16 : 32) > SFB__STAM_MAX_VALENCE) N = SFB__STAM_MAX_VALENCE - 32;
    }
    printf("# worst |AV - VJ| / max|A|: Catmull-Clark %.3g, Loop %.3g\n", wcc, wloop);
    check_loop_regular(ctx);
    sfb_context_destroy(ctx);
    check_failed_build_keeps_the_last_error();
    return close_tests();
}
