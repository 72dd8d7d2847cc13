/* backends/simd/manifold.h -- the simd backend's manifold family: eval_patches on MANIFOLD4
 * tables (manifold blending, seed 000, src/patch/manifold.c). Part of backends/simd/sfb_simd.h.
 *
 * The function is ref's sfb__mf_eval (src/patch/manifold.c holds the spec), evaluated in float on W
 * locations at once, one location per vector lane (structure of arrays): W = 16 avx512, 8 avx2,
 * 4 sse2 and neon on AArch64, 1 portable and 32-bit neon.
 *
 * Data packed at upload_patches (sfb__simd_upload_mf): one record of SFB__SIMD_MF_REC floats
 * per patch (the seed's section V.1 texture, turned into the unified form of V.3):
 *   [0..2] the centre o (the mean of the four corner vertices, in float), [3], [4] the error
 *   scales of the normal test (below), then per corner j at SFB__SIMD_MF_CORNER(j) 27
 *   coefficient floats, rows r = 3m + n (coordinates x, y, z) of C in
 *   P = [1 u u^2] C [1 v v^2]^T, and the corner's constants:
 *     patch (no sharp edge): C as fitted, C_00 (the vertex) made relative to o; e = 4/k,
 *       (cos phi, sin phi) and e (cos phi, sin phi), phi = 2 pi h / k, and whether k = 4;
 *       (u, v) = the chart z = zeta^e e^(i phi) of the corner coordinates zeta = a + i b;
 *     curve (two sharp edges): the quadratic Bezier q0 q1 q2 in the power basis of its
 *       parameter sigma, rows 0..2 = (q0 - o, 2 (q1 - q0), q0 - 2 q1 + q2); u = 0 and
 *       v = sigma = s0 + sa a + sb b (s0 = 1/2, sa and sb = +-1/2 or 0 from the axes of e1 and
 *       e2 in this face);
 *     point: row 0 = the vertex - o, all else 0 (u = v = 0).
 *   So every corner is P = [1 u u^2] C [1 v v^2]^T with (u, v) chosen by kind, Table 2's
 *   vector pairs: a lane evaluates any kind without branching on it (selects).
 * The records sit after one zero record (offset 0: lanes that ref evaluates read it), and the
 * quadtree leaves (root, node, as for Catmull-Clark) hold -(offset / 4 << 4 | 0) - 1, or the
 * ref leaf for a patch that cannot be packed (a corner code or vertex out of range).
 *
 * Kernel: locations are located SFB__SIMD_MF_CHUNK at a time (float quadtree descent: exact,
 * the patch and (s, t) are ref's) ahead of the blocks. A block is the next W locations when
 * they share a patch (its record then read with broadcasts), or their leading run in one patch
 * when that holds at least W/4 (a face's samples in one quadrant of a depth-1 face), else W
 * locations reading their records with gathers. Per block: the weights eta(t), eta(1 - t),
 * eta'(t) at t = c and d (Hermite written (1 - t)^2 (1 + 2t) and t^2 (3 - 2t), accurate near
 * both ends; C-infinity 1 / (1 + E) and E / (1 + E), E = exp((2t - 1) / (t (1 - t))), the
 * exponent clamped to [-80, 80]); per corner its coordinates (a, b), the chart (valence 4:
 * z = zeta e^(i phi), no transcendental function; other valences, when a lane has one: polar
 * form, r^e = exp2(e/2 log2 r^2), theta = atan2(b, a) in the first quadrant, cos and sin of
 * e theta rotated by phi, polynomial approximations with errors below 2e-9 so that float
 * rounding dominates; dz/dzeta = e z / zeta, and ref's e e^(i phi) at zeta = 0), then
 * P, dP/da, dP/db (conformal for patches: d(u,v)/db = (-Im, Re) of dz/dzeta; curves:
 * (0, sa), (0, sb)) and the blend S, dS/dc, dS/dd (eq. 5 and the chain rule of sfb__mf_eval);
 * derivatives times 2^depth. Blocks skip the patch arithmetic of a corner where no lane has a
 * patch corner there. A lane's result does not depend on the other lanes of its block, so it
 * is the same bits whatever the batch, chunking or thread count.
 *
 * Numerics: coefficients relative to the record's centre keep positions to ~1e-7 of the patch
 * size wherever the patch lies. Lanes go to the ref kernel (sfb__simd_ref_one) where float
 * cannot be trusted: a non-valence-4 patch corner at 0 < |zeta|^2 < 1e-24 (zeta = 0 itself is
 * evaluated here, as ref does), and, when normals are asked, where the estimated error of the
 * float normal exceeds 1e-4 rad. The estimate: dS/dc has a float error ~ K eps E Gc, dS/dd
 * ~ K eps E Gd (E the record's largest coefficient, Gc and Gd the sums over the corners of
 * |wa| + |w| |d(u,v)/da| or |wb| + |w| |d(u,v)/db|, whichever feeds that derivative: the
 * weights of the coefficient terms in it), plus ref's own rounding where it is larger (below);
 * the angle error is then ~ (errc |Sd| + errd |Sc|) / |Sc x Sd|. That sends collapsed
 * tangents (a face corner at a point, dart or crease vertex, where ref takes the normal a step
 * inside), overflow and NaN to ref, and, with C-infinity weights, the strips along sharp edges
 * where a derivative is ~exp(-1/t) and below ref's double rounding (there ref's normal is its
 * rounding, which float cannot reproduce).
 * Second derivatives (duu, duv, dvv asked): the whole call runs ref's kernel (central
 * differences of its analytic first derivatives, in double) on the thread pool; a float
 * difference quotient would lose 3 to 4 digits.
 *
 * The kernel is written once (SFB__SIMD_MF_DEFINE) on the float lanes of the vector operations
 * of sfb_simd.h, X##_op with X the instruction set's prefix (sfb__vp portable, sfb__vs sse2,
 * sfb__va avx2, sfb__vz avx512, sfb__vn neon). */
#define SFB__SIMD_MF_REC 176                  /* floats per record (a multiple of 16: 64-byte aligned) */
#define SFB__SIMD_MF_CORNER(j) (8 + 40 * (j)) /* a corner's 27 coefficients, then its constants */
enum {
    SFB__SIMD_MF_E = 27, SFB__SIMD_MF_CPHI = 28, SFB__SIMD_MF_SPHI = 29, SFB__SIMD_MF_ECPHI = 30, SFB__SIMD_MF_ESPHI = 31,
    SFB__SIMD_MF_S0 = 32, SFB__SIMD_MF_SA = 33, SFB__SIMD_MF_SB = 34, SFB__SIMD_MF_ISPATCH = 35, SFB__SIMD_MF_UNIT = 36
};
#define SFB__SIMD_LEAF_MF 0 /* a manifold table's leaf kind: a record (other kinds: SFB__SIMD_LEAF_REF) */
/* The normal test: (errc |Sd| + errd |Sc|)^2 <= 2 (errc^2 |Sd|^2 + errd^2 |Sc|^2), so with
 * record[3] = sqrt(2) K eps E / 1e-4 and record[4] the same for the floor below, gc =
 * record[3] Gc + record[4] (and gd) and the test reads |Sc x Sd|^2 >= gc^2 |Sd|^2 + gd^2 |Sc|^2.
 * K = 2 from measurements: over the peer shapes the accepted lanes' normals agree with ref
 * within ~3e-5 rad, their derivatives within ~2e-5 relative. */
#define SFB__SIMD_MF_KEPS 1.2e-7 /* K eps: K = 2 float roundings of the largest term */
/* ref's own error where it exceeds ours: its derivative of the C-infinity eta is a difference
 * of products ~1, so ~1e-15 absolute even where the derivative itself is ~exp(-1/t), times
 * absolute positions: ~4e-15 (|o| + E) in dS/dc and dS/dd. The floor, GFLOOR K eps (|o| + E)
 * = 1.2e-14 (|o| + E), keeps a margin of 3. Where the true derivative is below that, ref's
 * normal is its rounding, and the lane goes to ref. */
#define SFB__SIMD_MF_GFLOOR 1e-7

/* Reads constant k of the record (or corner block) at p: a broadcast, or a gather over the
 * lanes' record offsets vidx (the kernel's `gather`, a constant after inlining). */
#define SFB__SIMD_MF_F(X, p, k) (gather ? X##_gather((p) + (k), vidx) : X##_set1((p)[k]))

#define SFB__SIMD_MF_CHUNK 128 /* locations located ahead of the blocks */
/* Locates locations [q, end) (end - q <= SFB__SIMD_MF_CHUNK) into off (record offsets; 0, the
 * zero record, for a ref leaf), cs, ds (the patch's (s, t)) and sc (2^depth) from index 0, with
 * 16 copies of the last one after them (the lanes of a block past `end`). The float descent of
 * sfb__simd_prep: exact, so the patch and (s, t) are ref's. */
static void sfb__simd_mf_locate(const sfb__simd_patches *h, const sfb_location *locs, int q, int end, int *off, float *cs, float *ds,
                                float *sc) {
    int i, l;
    for (i = 0; q + i < end; ++i) {
        const sfb_location *loc = &locs[q + i];
        int node = h->root[loc->face], code;
        float s = loc->u, t = loc->v, f = 1.0f;
        while (node >= 0) {
            int qx, qy;
            s += s; t += t; f += f;
            qx = s >= 1.0f; qy = t >= 1.0f;
            s -= (float)qx;
            t -= (float)qy;
            node = h->node[4 * node + qx + 2 * qy];
        }
        code = -node - 1;
        off[i] = (code & 3) == SFB__SIMD_LEAF_MF ? (code >> 4) * 4 : 0;
        cs[i] = s; ds[i] = t; sc[i] = f;
    }
    for (l = 0; l < 16; ++l) {
        off[i + l] = off[i - 1]; cs[i + l] = cs[i - 1]; ds[i + l] = ds[i - 1]; sc[i + l] = sc[i - 1];
    }
}

#define SFB__SIMD_MF_DEFINE(X, ATTR)                                                                                                                   \
/* 2^x, x clamped to [-126, 126] */                                                                                                                    \
ATTR static SFB__SIMD_FORCEINLINE X##_v X##_exp2(X##_v x) {                                                                                            \
    X##_v n, f, p;                                                                                                                                     \
    x = X##_min(X##_max(x, X##_set1(-126.0f)), X##_set1(126.0f));                                                                                      \
    n = X##_round(x);                                                                                                                                  \
    f = X##_sub(x, n);                                                                                                                                 \
    p = X##_fma(X##_set1(1.534640198e-4f), f, X##_set1(1.339993820e-3f));                                                                              \
    p = X##_fma(p, f, X##_set1(9.618486785e-3f));                                                                                                      \
    p = X##_fma(p, f, X##_set1(5.550328755e-2f));                                                                                                      \
    p = X##_fma(p, f, X##_set1(2.402264691e-1f));                                                                                                      \
    p = X##_fma(p, f, X##_set1(6.931472058e-1f));                                                                                                      \
    p = X##_fma(p, f, X##_set1(1.0f));                                                                                                                 \
    return X##_mul(p, X##_pow2i(n));                                                                                                                   \
}                                                                                                                                                      \
/* log2 x for normal x > 0: exponent + 2 atanh((m - 1) / (m + 1)) / ln 2, m in [sqrt(1/2), sqrt(2)) */                                                 \
ATTR static SFB__SIMD_FORCEINLINE X##_v X##_log2(X##_v x) {                                                                                            \
    X##_v m = X##_mant(x), e = X##_expo(x), y, z, p;                                                                                                   \
    const X##_m big = X##_gt(m, X##_set1(1.41421356f));                                                                                                \
    m = X##_sel(big, X##_mul(m, X##_set1(0.5f)), m);                                                                                                   \
    e = X##_sel(big, X##_add(e, X##_set1(1.0f)), e);                                                                                                   \
    y = X##_div(X##_sub(m, X##_set1(1.0f)), X##_add(m, X##_set1(1.0f)));                                                                               \
    z = X##_mul(y, y);                                                                                                                                 \
    p = X##_fma(X##_set1(1.0f / 9.0f), z, X##_set1(1.0f / 7.0f));                                                                                      \
    p = X##_fma(p, z, X##_set1(0.2f));                                                                                                                 \
    p = X##_fma(p, z, X##_set1(1.0f / 3.0f));                                                                                                          \
    p = X##_fma(p, z, X##_set1(1.0f));                                                                                                                 \
    return X##_fma(X##_mul(y, p), X##_set1(2.88539008f), e);                                                                                           \
}                                                                                                                                                      \
/* atan2(b, a) for a, b >= 0 (0 at a = b = 0): one division, |t| <= tan(pi/8) */                                                                       \
ATTR static SFB__SIMD_FORCEINLINE X##_v X##_angle(X##_v a, X##_v b) {                                                                                  \
    const X##_v mn = X##_min(a, b), mx = X##_max(a, b);                                                                                                \
    const X##_m big = X##_gt(mn, X##_mul(mx, X##_set1(0.414213562f)));                                                                                 \
    const X##_v t = X##_div(X##_sel(big, X##_sub(mn, mx), mn), X##_max(X##_sel(big, X##_add(mn, mx), mx), X##_set1(1e-37f)));                          \
    const X##_v z = X##_mul(t, t);                                                                                                                     \
    X##_v p = X##_fma(X##_set1(-0.0608424948f), z, X##_set1(0.105963986f));                                                                            \
    p = X##_fma(p, z, X##_set1(-0.142439180f));                                                                                                        \
    p = X##_fma(p, z, X##_set1(0.199984942f));                                                                                                         \
    p = X##_fma(p, z, X##_set1(-0.333333156f));                                                                                                        \
    p = X##_fma(X##_mul(t, z), p, t);                                                                                                                  \
    p = X##_sel(big, X##_add(p, X##_set1(0.785398163f)), p);                                                                                           \
    return X##_sel(X##_gt(b, a), X##_sub(X##_set1(1.57079633f), p), p);                                                                                \
}                                                                                                                                                      \
/* eta(t), eta(1 - t) and eta'(t) (= eta'(1 - t)) of the weights kind */                                                                               \
ATTR static SFB__SIMD_FORCEINLINE void X##_eta(X##_v t, const int cinf, X##_v *e0, X##_v *e1, X##_v *de) {                                             \
    const X##_v one = X##_set1(1.0f), ot = X##_sub(one, t);                                                                                            \
    if (!cinf) {                                                                                                                                       \
        *e0 = X##_mul(X##_mul(ot, ot), X##_fma(X##_set1(2.0f), t, one));                                                                               \
        *e1 = X##_mul(X##_mul(t, t), X##_fma(X##_set1(2.0f), ot, one));                                                                                \
        *de = X##_mul(X##_mul(X##_set1(-6.0f), t), ot);                                                                                                \
    } else {                                                                                                                                           \
        /* eta(t) = 1 / (1 + E), eta(1 - t) = E / (1 + E), E = exp((2t - 1) / (t (1 - t))) */                                                          \
        const X##_v m = X##_max(X##_mul(t, ot), X##_set1(1e-4f));                                                                                      \
        const X##_v x = X##_min(X##_max(X##_div(X##_sub(t, ot), m), X##_set1(-80.0f)), X##_set1(80.0f));                                               \
        const X##_v E = X##_exp2(X##_mul(x, X##_set1(1.44269504f)));                                                                                   \
        const X##_v r = X##_div(one, X##_add(one, E)), Er = X##_mul(E, r);                                                                             \
        *e0 = r;                                                                                                                                       \
        *e1 = Er;                                                                                                                                      \
        *de = X##_neg(X##_div(X##_mul(X##_mul(Er, r), X##_fma(t, t, X##_mul(ot, ot))), X##_mul(m, m)));                                                \
    }                                                                                                                                                  \
}                                                                                                                                                      \
/* The chart of a patch corner: (u, v) = zeta^e e^(i phi), (ar, ai) = dz/dzeta; lanes of patch                                                         \
 * corners at 0 < |zeta|^2 < 1e-24 are marked bad */                                                                                                   \
ATTR static SFB__SIMD_FORCEINLINE void X##_chart(X##_v a, X##_v b, X##_v e, X##_v cphi, X##_v sphi, X##_v ecphi, X##_v esphi,                          \
                                                 X##_m isp, X##_v *u, X##_v *v, X##_v *ar, X##_v *ai, X##_m *bad) {                                    \
    const X##_v zero = X##_zero(), r2 = X##_fma(a, a, X##_mul(b, b)), r2c = X##_max(r2, X##_set1(1e-37f));                                             \
    const X##_m at0 = X##_mand(X##_eq(a, zero), X##_eq(b, zero));                                                                                      \
    const X##_v rz = X##_exp2(X##_mul(X##_mul(X##_set1(0.5f), e), X##_log2(r2c)));                                                                     \
    /* y = e theta - pi/2 in [-pi/2, pi/2]: cos(e theta) = -sin y, sin(e theta) = cos y */                                                             \
    const X##_v y = X##_fma(e, X##_angle(a, b), X##_set1(-1.57079633f)), y2 = X##_mul(y, y);                                                           \
    X##_v sn = X##_fma(X##_set1(-2.39099661e-8f), y2, X##_set1(2.75266661e-6f)), cs;                                                                   \
    X##_v cr, sr, uu, vv, ia, ib, k;                                                                                                                   \
    sn = X##_fma(sn, y2, X##_set1(-1.98408952e-4f));                                                                                                   \
    sn = X##_fma(sn, y2, X##_set1(8.33333133e-3f));                                                                                                    \
    sn = X##_fma(sn, y2, X##_set1(-1.66666666e-1f));                                                                                                   \
    sn = X##_fma(X##_mul(y, y2), sn, y);                                                                                                               \
    cs = X##_fma(X##_set1(-2.60775814e-7f), y2, X##_set1(2.47619208e-5f));                                                                             \
    cs = X##_fma(cs, y2, X##_set1(-1.38884044e-3f));                                                                                                   \
    cs = X##_fma(cs, y2, X##_set1(4.16666408e-2f));                                                                                                    \
    cs = X##_fma(cs, y2, X##_set1(-4.99999996e-1f));                                                                                                   \
    cs = X##_fma(cs, y2, X##_set1(1.0f));                                                                                                              \
    cr = X##_neg(X##_fma(sn, cphi, X##_mul(cs, sphi)));                                                                                                \
    sr = X##_fnma(sn, sphi, X##_mul(cs, cphi));                                                                                                        \
    uu = X##_mul(rz, cr);                                                                                                                              \
    vv = X##_mul(rz, sr);                                                                                                                              \
    /* e z / zeta = e z conj(zeta) / |zeta|^2 */                                                                                                       \
    k = X##_div(e, r2c);                                                                                                                               \
    ia = X##_mul(a, k);                                                                                                                                \
    ib = X##_mul(b, k);                                                                                                                                \
    *u = X##_sel(at0, zero, uu);                                                                                                                       \
    *v = X##_sel(at0, zero, vv);                                                                                                                       \
    *ar = X##_sel(at0, ecphi, X##_fma(uu, ia, X##_mul(vv, ib)));                                                                                       \
    *ai = X##_sel(at0, esphi, X##_fnma(uu, ib, X##_mul(vv, ia)));                                                                                      \
    *bad = X##_mor(*bad, X##_mand(isp, X##_mand(X##_lt(r2, X##_set1(1e-24f)), X##_mnot(at0))));                                                        \
}                                                                                                                                                      \
/* Adds corner j's terms for coordinate x: w P to *S, and the derivatives of w P along the                                                             \
 * corner's a and b, mapped to d/dc and d/dd, to *Sc and *Sd ((a, b) = (c, d), (d, 1 - c),                                                             \
 * (1 - c, 1 - d), (1 - d, c) for j = 0..3: see sfb__mf_eval). P = [1 u u^2] C [1 v v^2]^T with                                                        \
 * (u, v) moving along a and b at (jua, jva) and (jub, jvb), here times w; pc: u = 0 in every                                                          \
 * lane (points and curves: C's rows 0..2 alone), cf: every lane conformal (patch corners:                                                             \
 * (jub, jvb) = (-jva, jua)). j, x, pc and cf are constants after inlining. */                                                                         \
ATTR static SFB__SIMD_FORCEINLINE void X##_coord(const float *cr, X##_i vidx, const int gather, const int j, const int x, const int pc, const int cf,  \
                                                 X##_v u, X##_v v, X##_v jua, X##_v jva, X##_v jub, X##_v jvb, X##_v w, X##_v wa, X##_v wb,            \
                                                 X##_v *S, X##_v *Sc, X##_v *Sd) {                                                                     \
    X##_v p, pa, pb, ga, gb;                                                                                                                           \
    const X##_v c00 = SFB__SIMD_MF_F(X, cr, x), c01 = SFB__SIMD_MF_F(X, cr, 3 + x), c02 = SFB__SIMD_MF_F(X, cr, 6 + x);                                \
    const X##_v v2 = X##_add(v, v), r0 = X##_fma(v, X##_fma(v, c02, c01), c00), d0 = X##_fma(v2, c02, c01);                                            \
    if (pc) {                                                                                                                                          \
        p = r0;                                                                                                                                        \
        pa = X##_mul(d0, jva);                                                                                                                         \
        pb = X##_mul(d0, jvb);                                                                                                                         \
    } else {                                                                                                                                           \
        /* R_m = C_m0 + v C_m1 + v^2 C_m2 and d/dv, then P = R_0 + u R_1 + u^2 R_2 */                                                                  \
        const X##_v c10 = SFB__SIMD_MF_F(X, cr, 9 + x), c11 = SFB__SIMD_MF_F(X, cr, 12 + x), c12 = SFB__SIMD_MF_F(X, cr, 15 + x);                      \
        const X##_v c20 = SFB__SIMD_MF_F(X, cr, 18 + x), c21 = SFB__SIMD_MF_F(X, cr, 21 + x), c22 = SFB__SIMD_MF_F(X, cr, 24 + x);                     \
        const X##_v r1 = X##_fma(v, X##_fma(v, c12, c11), c10), d1 = X##_fma(v2, c12, c11);                                                            \
        const X##_v r2 = X##_fma(v, X##_fma(v, c22, c21), c20), d2 = X##_fma(v2, c22, c21);                                                            \
        const X##_v pu = X##_fma(X##_add(u, u), r2, r1), pv = X##_fma(u, X##_fma(u, d2, d1), d0);                                                      \
        p = X##_fma(u, X##_fma(u, r2, r1), r0);                                                                                                        \
        pa = X##_fma(pu, jua, X##_mul(pv, jva));                                                                                                       \
        pb = cf ? X##_fnma(pu, jva, X##_mul(pv, jua)) : X##_fma(pu, jub, X##_mul(pv, jvb));                                                            \
    }                                                                                                                                                  \
    ga = X##_fma(wa, p, pa);                                                                                                                           \
    gb = X##_fma(wb, p, pb);                                                                                                                           \
    *S = X##_fma(w, p, *S);                                                                                                                            \
    switch (j) {                                                                                                                                       \
    case 0: *Sc = X##_add(*Sc, ga); *Sd = X##_add(*Sd, gb); break;                                                                                     \
    case 1: *Sc = X##_sub(*Sc, gb); *Sd = X##_add(*Sd, ga); break;                                                                                     \
    case 2: *Sc = X##_sub(*Sc, ga); *Sd = X##_sub(*Sd, gb); break;                                                                                     \
    default: *Sc = X##_add(*Sc, gb); *Sd = X##_sub(*Sd, ga); break;                                                                                    \
    }                                                                                                                                                  \
}                                                                                                                                                      \
/* Corner j at its coordinates (a, b) with weight w and derivatives wa, wb: adds to the blend                                                          \
 * acc (S xyz, dS/dc xyz, dS/dd xyz; constant indices only, so that they stay in registers)                                                            \
 * and to the error weights G (see the normal test) */                                                                                                 \
ATTR static SFB__SIMD_FORCEINLINE void X##_corner(const float *rec, X##_i vidx, const int gather, const int j, X##_v a, X##_v b,                       \
                                                  X##_v w, X##_v wa, X##_v wb, X##_v acc[9], X##_v G[2], X##_m *bad) {                                 \
    const float *cr = rec + SFB__SIMD_MF_CORNER(j);                                                                                                    \
    const X##_v zero = X##_zero();                                                                                                                     \
    const X##_m isp = X##_gt(SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_ISPATCH), X##_set1(0.5f));                                                             \
    const X##_v sa = SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_SA), sb = SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_SB);                                              \
    const X##_v s = X##_fma(sa, a, X##_fma(sb, b, SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_S0)));                                                            \
    X##_v ea, eb;                                                                                                                                      \
    if (X##_none(isp)) {                                                                                                                               \
        /* points and curves only: u = 0, v = sigma */                                                                                                 \
        const X##_v wsa = X##_mul(w, sa), wsb = X##_mul(w, sb);                                                                                        \
        X##_coord(cr, vidx, gather, j, 0, 1, 0, zero, s, zero, wsa, zero, wsb, w, wa, wb, &acc[0], &acc[3], &acc[6]);                                  \
        X##_coord(cr, vidx, gather, j, 1, 1, 0, zero, s, zero, wsa, zero, wsb, w, wa, wb, &acc[1], &acc[4], &acc[7]);                                  \
        X##_coord(cr, vidx, gather, j, 2, 1, 0, zero, s, zero, wsa, zero, wsb, w, wa, wb, &acc[2], &acc[5], &acc[8]);                                  \
        ea = X##_fma(X##_abs(w), X##_abs(sa), X##_abs(wa));                                                                                            \
        eb = X##_fma(X##_abs(w), X##_abs(sb), X##_abs(wb));                                                                                            \
    } else {                                                                                                                                           \
        const X##_v cphi = SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_CPHI), sphi = SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_SPHI);                                  \
        const X##_m unit = X##_mand(isp, X##_gt(SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_UNIT), X##_set1(0.5f)));                                            \
        const int allp = X##_all(isp);                                                                                                                 \
        /* valence 4: z = zeta e^(i phi), no transcendental functions; the polar chart where any                                                       \
         * lane needs it (a lane's result never depends on the other lanes) */                                                                         \
        X##_v u = X##_fnma(b, sphi, X##_mul(a, cphi)), v = X##_fma(b, cphi, X##_mul(a, sphi)), ar = cphi, ai = sphi;                                   \
        X##_v jua, jva, jub, jvb;                                                                                                                      \
        if (!X##_all(unit)) {                                                                                                                          \
            X##_v cu, cv, car, cai;                                                                                                                    \
            X##_chart(a, b, SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_E), cphi, sphi, SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_ECPHI),                              \
                      SFB__SIMD_MF_F(X, cr, SFB__SIMD_MF_ESPHI), X##_mand(isp, X##_mnot(unit)), &cu, &cv, &car, &cai, bad);                            \
            u = X##_sel(unit, u, cu);                                                                                                                  \
            v = X##_sel(unit, v, cv);                                                                                                                  \
            ar = X##_sel(unit, ar, car);                                                                                                               \
            ai = X##_sel(unit, ai, cai);                                                                                                               \
        }                                                                                                                                              \
        /* d(u,v)/da = (ar, ai), d(u,v)/db = (-ai, ar) (conformal); curves: (0, sa), (0, sb) */                                                        \
        jua = X##_sel(isp, ar, zero);                                                                                                                  \
        jva = X##_sel(isp, ai, sa);                                                                                                                    \
        jub = X##_sel(isp, X##_neg(ai), zero);                                                                                                         \
        jvb = X##_sel(isp, ar, sb);                                                                                                                    \
        u = X##_sel(isp, u, zero);                                                                                                                     \
        v = X##_sel(isp, v, s);                                                                                                                        \
        ea = X##_fma(X##_abs(w), X##_add(X##_abs(jua), X##_abs(jva)), X##_abs(wa));                                                                    \
        eb = X##_fma(X##_abs(w), X##_add(X##_abs(jub), X##_abs(jvb)), X##_abs(wb));                                                                    \
        jua = X##_mul(w, jua);                                                                                                                         \
        jva = X##_mul(w, jva);                                                                                                                         \
        if (allp) {                                                                                                                                    \
            X##_coord(cr, vidx, gather, j, 0, 0, 1, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[0], &acc[3], &acc[6]);                                   \
            X##_coord(cr, vidx, gather, j, 1, 0, 1, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[1], &acc[4], &acc[7]);                                   \
            X##_coord(cr, vidx, gather, j, 2, 0, 1, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[2], &acc[5], &acc[8]);                                   \
        } else {                                                                                                                                       \
            jub = X##_mul(w, jub);                                                                                                                     \
            jvb = X##_mul(w, jvb);                                                                                                                     \
            X##_coord(cr, vidx, gather, j, 0, 0, 0, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[0], &acc[3], &acc[6]);                                   \
            X##_coord(cr, vidx, gather, j, 1, 0, 0, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[1], &acc[4], &acc[7]);                                   \
            X##_coord(cr, vidx, gather, j, 2, 0, 0, u, v, jua, jva, jub, jvb, w, wa, wb, &acc[2], &acc[5], &acc[8]);                                   \
        }                                                                                                                                              \
    }                                                                                                                                                  \
    G[0] = X##_add(G[0], (j & 1) ? eb : ea); /* dS/dc takes dP/da (j even) or dP/db (j odd) */                                                         \
    G[1] = X##_add(G[1], (j & 1) ? ea : eb);                                                                                                           \
}                                                                                                                                                      \
/* The blend at face coordinates (c, d): acc = S, dS/dc, dS/dd (xyz each); *G the normal                                                               \
 * test's error scale; *bad the lanes ref must take. rec: the record (gather = 0) or the first                                                         \
 * record with the lanes' offsets vidx (gather = 1). */                                                                                                \
ATTR static SFB__SIMD_FORCEINLINE void X##_block(const float *rec, X##_i vidx, const int gather, const int cinf, X##_v c, X##_v d,                     \
                                                 X##_v acc[9], X##_v G[2], X##_m *bad) {                                                               \
    const X##_v one = X##_set1(1.0f), oc = X##_sub(one, c), od = X##_sub(one, d);                                                                      \
    X##_v ec0, ec1, dc, ed0, ed1, dd;                                                                                                                  \
    X##_eta(c, cinf, &ec0, &ec1, &dc);                                                                                                                 \
    X##_eta(d, cinf, &ed0, &ed1, &dd);                                                                                                                 \
    acc[0] = acc[1] = acc[2] = acc[3] = acc[4] = acc[5] = acc[6] = acc[7] = acc[8] = G[0] = G[1] = X##_zero();                                         \
    *bad = X##_mfalse();                                                                                                                               \
    X##_corner(rec, vidx, gather, 0, c, d, X##_mul(ec0, ed0), X##_mul(dc, ed0), X##_mul(ec0, dd), acc, G, bad);                                        \
    X##_corner(rec, vidx, gather, 1, d, oc, X##_mul(ed0, ec1), X##_mul(dd, ec1), X##_mul(ed0, dc), acc, G, bad);                                       \
    X##_corner(rec, vidx, gather, 2, oc, od, X##_mul(ec1, ed1), X##_mul(dc, ed1), X##_mul(ec1, dd), acc, G, bad);                                      \
    X##_corner(rec, vidx, gather, 3, od, c, X##_mul(ed1, ec0), X##_mul(dd, ec0), X##_mul(ed1, dc), acc, G, bad);                                       \
    acc[0] = X##_add(acc[0], SFB__SIMD_MF_F(X, rec, 0));                                                                                               \
    acc[1] = X##_add(acc[1], SFB__SIMD_MF_F(X, rec, 1));                                                                                               \
    acc[2] = X##_add(acc[2], SFB__SIMD_MF_F(X, rec, 2));                                                                                               \
    G[0] = X##_fma(G[0], SFB__SIMD_MF_F(X, rec, 3), SFB__SIMD_MF_F(X, rec, 4));                                                                        \
    G[1] = X##_fma(G[1], SFB__SIMD_MF_F(X, rec, 3), SFB__SIMD_MF_F(X, rec, 4));                                                                        \
}                                                                                                                                                      \
/* Locations [first, last) of a manifold table, up to W at a time: a block is the next W                                                               \
 * locations when they share a patch, or the leading run of them that does when it holds at                                                            \
 * least W/4 (runs of a face's samples within one quadrant), else W locations gathered.                                                                \
 * Locations are located SFB__SIMD_MF_CHUNK at a time ahead of the blocks (sfb__simd_mf_locate),                                                       \
 * so that a block's vector loads do not wait on the scalar stores of the locating. */                                                                 \
ATTR static void X##_mf_range(const sfb__simd_pjob *jb, int first, int last) {                                                                         \
    const sfb__simd_patches *h = jb->h;                                                                                                                \
    const sfb_eval_output *o = jb->out;                                                                                                                \
    const int cinf = jb->pt->mf_weights == SFB_MANIFOLD_WEIGHTS_CINF;                                                                                  \
    float cs[SFB__SIMD_MF_CHUNK + 16], ds[SFB__SIMD_MF_CHUNK + 16], sc[SFB__SIMD_MF_CHUNK + 16];                                                       \
    int off[SFB__SIMD_MF_CHUNK + 16], q0, n, cbase = first, cend = first;                                                                              \
    for (q0 = first; q0 < last; q0 += n) {                                                                                                             \
        int i0, l, uni, run;                                                                                                                           \
        unsigned refl = 0;                                                                                                                             \
        X##_v acc[9], G[2], c, d, k;                                                                                                                   \
        X##_m bad;                                                                                                                                     \
        X##_i vidx;                                                                                                                                    \
        if (q0 + X##_W > cend && cend < last) {                                                                                                        \
            cbase = q0;                                                                                                                                \
            cend = last - q0 < SFB__SIMD_MF_CHUNK ? last : q0 + SFB__SIMD_MF_CHUNK;                                                                    \
            sfb__simd_mf_locate(h, jb->locs, cbase, cend, off, cs, ds, sc);                                                                            \
        }                                                                                                                                              \
        i0 = q0 - cbase;                                                                                                                               \
        n = last - q0 < X##_W ? last - q0 : X##_W;                                                                                                     \
        for (run = 1; run < n && off[i0 + run] == off[i0]; ++run) {}                                                                                   \
        uni = run >= n || 4 * run >= X##_W;                                                                                                            \
        if (run < n && uni) n = run;                                                                                                                   \
        for (l = 0; l < n; ++l)                                                                                                                        \
            if (off[i0 + l] == 0) refl |= 1u << l; /* the zero record: a ref leaf */                                                                   \
        c = X##_loadu(cs + i0);                                                                                                                        \
        d = X##_loadu(ds + i0);                                                                                                                        \
        vidx = X##_loadi(off + i0);                                                                                                                    \
        if (uni) X##_block(h->blk + off[i0], vidx, 0, cinf, c, d, acc, G, &bad);                                                                       \
        else X##_block(h->blk, vidx, 1, cinf, c, d, acc, G, &bad);                                                                                     \
        refl |= X##_bits(bad);                                                                                                                         \
        if (o->normal) {                                                                                                                               \
            const X##_v nx = X##_fnma(acc[5], acc[7], X##_mul(acc[4], acc[8]));                                                                        \
            const X##_v ny = X##_fnma(acc[3], acc[8], X##_mul(acc[5], acc[6]));                                                                        \
            const X##_v nz = X##_fnma(acc[4], acc[6], X##_mul(acc[3], acc[7]));                                                                        \
            const X##_v nn = X##_fma(nx, nx, X##_fma(ny, ny, X##_mul(nz, nz)));                                                                        \
            const X##_v uu = X##_fma(acc[3], acc[3], X##_fma(acc[4], acc[4], X##_mul(acc[5], acc[5])));                                                \
            const X##_v vv = X##_fma(acc[6], acc[6], X##_fma(acc[7], acc[7], X##_mul(acc[8], acc[8])));                                                \
            const X##_v tol = X##_fma(X##_mul(G[0], G[0]), vv, X##_mul(X##_mul(G[1], G[1]), uu));                                                      \
            const X##_m ok = X##_mand(X##_mand(X##_gt(nn, X##_set1(1e-30f)), X##_le(nn, X##_set1(1e30f))), X##_ge(nn, tol));                           \
            const X##_v inv = X##_div(X##_set1(1.0f), X##_sqrt(nn));                                                                                   \
            refl |= X##_bits(X##_mnot(ok));                                                                                                            \
            X##_store3(o->normal + 3 * (size_t)q0, X##_mul(nx, inv), X##_mul(ny, inv), X##_mul(nz, inv), n);                                           \
        }                                                                                                                                              \
        if (o->position) X##_store3(o->position + 3 * (size_t)q0, acc[0], acc[1], acc[2], n);                                                          \
        k = X##_loadu(sc + i0);                                                                                                                        \
        if (o->du) X##_store3(o->du + 3 * (size_t)q0, X##_mul(acc[3], k), X##_mul(acc[4], k), X##_mul(acc[5], k), n);                                  \
        if (o->dv) X##_store3(o->dv + 3 * (size_t)q0, X##_mul(acc[6], k), X##_mul(acc[7], k), X##_mul(acc[8], k), n);                                  \
        for (l = 0; l < n; ++l)                                                                                                                        \
            if ((refl >> l) & 1u) sfb__simd_ref_one(jb, q0 + l);                                                                                       \
    }                                                                                                                                                  \
}

/* ---- the kernel on each instruction set's vector operations (sfb_simd.h) ---- */
SFB__SIMD_MF_DEFINE(sfb__vp, )
#ifdef SFB__SIMD_SSE2
SFB__SIMD_MF_DEFINE(sfb__vs, )
#endif
#ifdef SFB__SIMD_X86_DISPATCH
SFB__SIMD_MF_DEFINE(sfb__va, SFB__SIMD_TARGET_AVX2)
SFB__SIMD_MF_DEFINE(sfb__vz, SFB__SIMD_TARGET_AVX512)
#endif
#ifdef SFB__SIMD_VN
SFB__SIMD_MF_DEFINE(sfb__vn, )
#endif

/* The range loop of the state's instruction set (32-bit neon: portable). */
static sfb__simd_prange_fn sfb__simd_manifold_select(int isa) {
    switch (isa) {
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: return sfb__vs_mf_range;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2: return sfb__va_mf_range;
    case SFB__SIMD_AVX512: return sfb__vz_mf_range;
#endif
#ifdef SFB__SIMD_VN
    case SFB__SIMD_ISA_NEON: return sfb__vn_mf_range;
#endif
    default: return sfb__vp_mf_range;
    }
}

/* Locations [first, last) on the ref kernel (manifold tables with second derivatives asked). */
static void sfb__simd_ref_range(const sfb__simd_pjob *j, int first, int last) {
    sfb__ref_eval_patches(NULL, j->pt, NULL, j->locs, first, last, j->out);
}

/* Packs manifold patch p's record at rec (layout: the top of this file); 0 where a corner
 * code or vertex is out of range (that patch is left to ref). */
static int sfb__simd_pack_mf(float *rec, const sfb__patch_table *pt, int p) {
    const int *cv = pt->cv + pt->pfirst[p];
    const unsigned *codes = pt->pcorner + 4 * (size_t)p;
    double C[4][9][3], o[3] = {0.0, 0.0, 0.0};
    float of[3], E = 0.0f;
    int j, r, c;
    if (pt->ptype[p] != SFB__PATCH_MANIFOLD4 || pt->pfirst[p + 1] - pt->pfirst[p] != 4) return 0;
    memset(rec, 0, SFB__SIMD_MF_REC * sizeof(float));
    memset(C, 0, sizeof C);
    for (j = 0; j < 4; ++j) {
        const int kind = SFB__MF_KIND(codes[j]);
        const float *q;
        float *k = rec + SFB__SIMD_MF_CORNER(j);
        if (cv[j] < 0 || (size_t)cv[j] >= (size_t)pt->npoints / 9) return 0;
        q = pt->point_data + 27 * (size_t)cv[j];
        if (kind == SFB__MF_PATCH) {
            const int kv = SFB__MF_K(codes[j]), hv = SFB__MF_H(codes[j]);
            const double e = 4.0 / kv, phi = 2.0 * SFB__PI * hv / kv;
            if (kv < 2 || hv >= kv) return 0;
            for (r = 0; r < 9; ++r)
                for (c = 0; c < 3; ++c) C[j][r][c] = q[3 * r + c];
            k[SFB__SIMD_MF_E] = (float)e;
            k[SFB__SIMD_MF_CPHI] = (float)cos(phi);
            k[SFB__SIMD_MF_SPHI] = (float)sin(phi);
            k[SFB__SIMD_MF_ECPHI] = (float)(e * cos(phi));
            k[SFB__SIMD_MF_ESPHI] = (float)(e * sin(phi));
            k[SFB__SIMD_MF_ISPATCH] = 1.0f;
            k[SFB__SIMD_MF_UNIT] = kv == 4 ? 1.0f : 0.0f;
            for (c = 0; c < 3; ++c) o[c] += q[c];
        } else if (kind == SFB__MF_CURVE) {
            const int a1 = SFB__MF_A1(codes[j]), a2 = SFB__MF_A2(codes[j]);
            if (a1 > 2 || a2 > 2) return 0;
            for (c = 0; c < 3; ++c) { /* q0 + s 2 (q1 - q0) + s^2 (q0 - 2 q1 + q2) */
                C[j][0][c] = q[c];
                C[j][1][c] = 2.0 * ((double)q[3 + c] - q[c]);
                C[j][2][c] = ((double)q[c] - 2.0 * q[3 + c]) + q[6 + c];
                o[c] += q[3 + c];
            }
            k[SFB__SIMD_MF_S0] = 0.5f;
            k[SFB__SIMD_MF_SA] = 0.5f * (float)((a2 == 1) - (a1 == 1));
            k[SFB__SIMD_MF_SB] = 0.5f * (float)((a2 == 2) - (a1 == 2));
        } else if (kind == SFB__MF_POINT) {
            for (c = 0; c < 3; ++c) {
                C[j][0][c] = q[c];
                o[c] += q[c];
            }
        } else {
            return 0;
        }
    }
    for (c = 0; c < 3; ++c) {
        of[c] = (float)(o[c] / 4.0);
        rec[c] = of[c];
    }
    for (j = 0; j < 4; ++j) {
        float *k = rec + SFB__SIMD_MF_CORNER(j);
        for (c = 0; c < 3; ++c) C[j][0][c] -= of[c];
        for (r = 0; r < 9; ++r)
            for (c = 0; c < 3; ++c) {
                k[3 * r + c] = (float)C[j][r][c];
                if (fabsf(k[3 * r + c]) > E) E = fabsf(k[3 * r + c]);
            }
    }
    {
        const double om = fmax(fabs((double)of[0]), fmax(fabs((double)of[1]), fabs((double)of[2])));
        rec[3] = (float)(SFB__SIMD_MF_KEPS * 1.41421356 / 1e-4 * E);
        rec[4] = (float)(SFB__SIMD_MF_KEPS * 1.41421356 / 1e-4 * SFB__SIMD_MF_GFLOOR * (E + om));
    }
    return 1;
}

/* upload_patches for a manifold table: one record per patch after a zero record. */
static sfb_result sfb__simd_upload_mf(sfb__simd_state *s, const sfb__patch_table *pt, void **handle) {
    sfb_context *ctx = s->ctx;
    sfb__simd_patches *h;
    int *pcode;
    size_t nf;
    int p;
    if (!pt->ptype || !pt->pfirst || !pt->cv || !pt->pcorner) return SFB_SUCCESS; /* eval goes to ref */
    nf = ((size_t)pt->npatch + 1) * SFB__SIMD_MF_REC;
    if (nf / 4 >= ((size_t)1 << 27)) /* leaf codes hold offset / 4 in 27 bits */
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "simd: the patch table is too large to pack (%zu floats)", nf);
    h = (sfb__simd_patches *)sfb__alloc(ctx, sizeof *h);
    if (!h) return sfb__oom(ctx, "the simd backend's patch data");
    memset(h, 0, sizeof *h);
    h->npatch = pt->npatch;
    h->nptex = pt->nptex;
    h->root = (int *)sfb__alloc(ctx, (size_t)pt->nptex * sizeof(int));
    h->node = (int *)sfb__alloc(ctx, ((size_t)pt->nnodes * 4 + 1) * sizeof(int));
    h->raw = sfb__alloc(ctx, nf * sizeof(float) + 64);
    pcode = (int *)sfb__alloc(ctx, (size_t)pt->npatch * sizeof(int));
    if (!h->root || !h->node || !h->raw || !pcode) {
        sfb__free(ctx, pcode);
        sfb__simd_release_patches(s, h);
        return sfb__oom(ctx, "the simd backend's patch data");
    }
    h->bytes = sizeof *h + ((size_t)pt->nptex + (size_t)pt->nnodes * 4 + 1) * sizeof(int) + nf * sizeof(float) + 64;
    h->blk = (float *)(void *)((char *)h->raw + ((64 - ((uintptr_t)h->raw & 63)) & 63));
    memset(h->blk, 0, SFB__SIMD_MF_REC * sizeof(float));
    for (p = 0; p < pt->npatch; ++p) {
        const size_t at = ((size_t)p + 1) * SFB__SIMD_MF_REC;
        pcode[p] = sfb__simd_pack_mf(h->blk + at, pt, p) ? -((int)((at / 4) << 4 | SFB__SIMD_LEAF_MF) + 1) : -(SFB__SIMD_LEAF_REF + 1);
    }
    for (p = 0; p < pt->nptex; ++p) h->root[p] = sfb__simd_leaf(pcode, pt->ptex_root[p]);
    for (p = 0; p < 4 * pt->nnodes; ++p) h->node[p] = sfb__simd_leaf(pcode, pt->nodes[p]);
    sfb__free(ctx, pcode);
    *handle = h;
    return SFB_SUCCESS;
}

/* A call's range loop: the kernel, or with second derivatives asked the ref kernel for every
 * location (on the pool all the same). */
static void sfb__simd_manifold_prepare(const sfb__simd_state *s, sfb__simd_pjob *j) {
    j->range = j->second ? sfb__simd_ref_range : sfb__simd_manifold_select(s->isa);
}

static const sfb__simd_patch_family sfb__simd_manifold_family = {1u << SFB__FAMILY_MANIFOLD, sfb__simd_upload_mf,
                                                                 sfb__simd_manifold_prepare};
