/* backends/simd/patches.h -- the simd backend's polynomial patch families: eval_patches on
 * quad tables (BSPLINE16, STAM, ENDCAP: Catmull-Clark limit evaluation) and triangle tables
 * (BEZTRI15, STAM_LOOP, ENDCAP_TRI: Loop). This file: the layout, what the two share (the
 * finishing, the range loops, packing and upload, sfb__simd_patches_family for vtable.h);
 * patches_quad.h and patches_tri.h: each one's locating, window kernels per instruction set
 * and packing. Part of backends/simd/sfb_simd.h. (A manifold table shares the quadtree copy
 * and the thread pool but packs and runs its own kernel: manifold.h.)
 *
 * Data packed at upload_patches (sfb__simd_patches), read-only afterwards:
 *   blk     xyzw points in "grids" of columns: point (i, j) (i along u, j along v) of a 4x4
 *           B-spline control net at blk + i * cs + 4 * j (cs, the column stride, in floats), so
 *           that the four points of a column are 64 contiguous bytes (one AVX-512 load, two
 *           AVX2 loads, four 128-bit loads).
 *           - a B-spline patch: its 16 points (cs = 16; 256 bytes, 64-byte aligned);
 *           - a Stam patch (EV at frame corner c): for each level n = 1..SFB__SIMD_STAM_LEVELS
 *             one 5 x 5 grid (cs = 20; 400 bytes) of the level-n points around the EV: the
 *             three sub-patches k = 1, 2, 3 of that level are the 4 x 4 windows at lattice
 *             (0,-1), (0,0), (-1,0) (the EV at (0,0)), 24 distinct points (the corner (-1,-1)
 *             is unused). Their control points Q[j] = sum_i lambda_i^(n-1) phi_k[j][i] c_i are
 *             computed in double once, so a location near an EV costs what a B-spline
 *             location costs. (Upload checks that the windows agree on their shared points;
 *             a patch whose eigen data said otherwise would be left to the ref kernel.)
 *           Points are stored relative to the grid's origin o (the centroid, in float):
 *           differences of nearby points then keep float's relative precision however far the
 *           patch lies from the coordinate origin and however deep it is, which is what lets
 *           float derivatives and normals agree with ref's double ones. The w lanes of the
 *           window diagonal (0,0), (1,1), (2,2), (3,3) hold o.x, o.y, o.z and E, the largest
 *           |coordinate| of the grid's relative points (the scale of float's rounding errors);
 *           the three Stam windows have disjoint diagonals, so every window finds them there.
 *           Other w lanes are 0; the kernels' w lanes are never stored as results.
 *           Loop tables (triangles) use "triangles" of 48 floats (192 bytes: three cache
 *           lines, 64-byte aligned; random locations are bound by the lines they miss, and
 *           the 256-byte xyzw layout took four): the 15 control points of a quartic Bezier
 *           triangle in the table's order (row j = 0..4 by row in t, i = 0..4-j rising in s),
 *           relative to the first, o = point 0 in float: points 1..14 as xyz at floats 0..41
 *           (point 0's relative point is 0 and not stored), o at 42..44, E x
 *           SFB__SIMD_TRI_EFACTOR at 45 (E as above; 3 cs + 15 finds it with cs = 10), 0 at
 *           46, 47. The kernels load a point as 4 floats, the 4th being the next float (w
 *           lanes are never stored as results).
 *           - a Bezier triangle patch (BEZTRI): its 15 points;
 *           - a Stam-Loop patch (EV at frame corner c): for each level n = 1..
 *             SFB__SIMD_LOOP_LEVELS the three sub-patches k = 0, 1, 2 of that level as
 *             triangles (144 floats per level), control points Q[j] = sum_i (lambda_i^m
 *             phi_k[j][i] + m lambda_i^(m-1) phi_k[j][head_i]) c_i, m = n - 1 (the second term
 *             for the second vector of a Jordan block), computed in double once. (Upload
 *             checks that the sub-patches agree on their shared edges, as for Stam.)
 *   root, node  a copy of the table's quadtree (ptex_root, nodes) whose leaves say directly
 *           what to run: -(code + 1) with code = offset / 4 << 4 | corner << 2 | kind, kind 0
 *           B-spline grid, 1 Stam grids (Stam-Loop triangles in a Loop table), 2 the ref
 *           kernel (end caps, holes), 3 a Bezier triangle. One dependent load less per
 *           location than going through the patch arrays.
 * Everything is derived from the table's point_data at upload time (the table is immutable).
 * Locations nearer an EV than level SFB__SIMD_STAM_LEVELS (a 4^-L share of a Stam patch) are
 * evaluated from the eigen structure in double (sfb__simd_stam_far; Stam-Loop beyond
 * SFB__SIMD_LOOP_LEVELS: sfb__simd_loop_far); the EV itself, end caps (quad and triangle)
 * and degenerate normals go to the ref kernel, one location at a time.
 *
 * Numerics. Locating is done in float and is exact (u, v are floats; doubling, and subtracting
 * 1 from a value in [1,2), are exact), so the patch and (s, t) are ref's; so are a Stam
 * location's level and sub-patch (see sfb__simd_prep). The B-spline sums run in float on the
 * relative points (errors ~1e-7 of the patch size). Triangles are located in double with
 * ref's operations (sfb__simd_prep_tri: the same patch, (s, t), Stam-Loop level and
 * sub-patch), and their kernels run de Casteljau in double on the float relative points: a
 * quartic's second derivatives (12 x second differences, times 4^depth) lose too much in
 * float at depth 8, and in double they cost AVX2/AVX-512 about as many instructions (one xyzw
 * point per 256-bit register). Without second derivatives, avx2 and avx512 evaluate two
 * triangle locations in a row of a batch at once in float (sfb__simd_avx2_tri2: two points per
 * 256-bit register, half the instructions; its error and measurements are beside it; a location
 * without such a neighbour runs the double kernel), and neon on AArch64 every triangle location
 * in float (sfb__simd_tri_neon: one point per 128-bit register, the same steps and bits as a
 * lane of the pair kernel; not timed on an ARM core here). A normal is made from float tangents
 * only when the estimated angle error, ~2e-7 E (|Pu| + |Pv|) / |Pu x Pv|, is below 1e-4 rad
 * (triangles: 4 E, their derivatives weigh the points by up to 8 where a B-spline's weigh them
 * by 1; the float triangle kernels': 16 E); otherwise (collapsed or nearly parallel tangents,
 * overflow, NaN) the location goes to ref, whose double evaluation and degenerate-tangent rule
 * then decide the normal.
 *
 * Kernels: avx512 (a column of 4 points per register), avx2 (2 points per register), sse2
 * (xyz in 4 lanes per point; no FMA); these finish (scale, rotate, normal, stores) in 128-bit
 * registers. portable and neon evaluate into a float[6][4] and finish in scalar C (double).
 * (They work on a window's points with shuffles and horizontal sums, which the lane-per-
 * location vector operations of sfb_simd.h do not express: they stay intrinsics.)
 * Triangles: one point per 256-bit register of doubles (avx2, avx512), two 128-bit ones (sse2,
 * neon on AArch64 with second derivatives), scalar double (portable, 32-bit neon); in float
 * without them: the pair kernel (avx2, avx512), one point per register (neon on AArch64).
 * Locations are prepared (located, grids prefetched) in batches of SFB__SIMD_BATCH, a batch
 * ahead of the kernels, so that the loads of many locations are in flight at once and their
 * descents overlap (sfb__simd_prep_batch). Threads: the locations are cut into equal chunks
 * over the pool (calls under SFB__SIMD_INLINE_LOCATIONS stay on the caller). */
#define SFB__SIMD_STAM_LEVELS 3
#define SFB__SIMD_LOOP_LEVELS 3     /* Stam-Loop levels packed (144 floats each) */
#define SFB__SIMD_TRI_EFACTOR 4.0f  /* a triangle's E is scaled by this for the normal test */
#define SFB__SIMD_TRI_FLOATS 48     /* a packed Bezier triangle (the layout above) */
#define SFB__SIMD_TRI_ORIGIN 42     /* its o (E follows, at 3 cs + 15 with cs = 10) */
#define SFB__SIMD_TRI2_EFACTOR 4.0f /* the float triangle kernels' E factor beyond SFB__SIMD_TRI_EFACTOR */


/* One location made ready for a kernel: the window, where to evaluate it, and how to map its
 * derivatives to the parametric face's: rotate by the Stam frame corner `rot`, (Ps, Pt) =
 * (Pu, Pv), (-Pv, Pu), (-Pu, -Pv), (Pv, -Pu) for rot 0..3, and for the Stam-Loop frames of
 * corners 1 and 2, rot 4: (-Pv, Pu - Pv), rot 5: (Pv - Pu, -Pu) (second derivatives likewise;
 * det 1, so the normal is unchanged), then multiply by dsc = 2^(n + depth) (Loop: negative
 * after an odd number of middle children). run: the square window kernel (KERNEL), the
 * triangle kernel (TRI: blk is a 48-float triangle, cs 10 so that the normal test finds E),
 * or the double paths. */
enum { SFB__SIMD_RUN_REF = 0, SFB__SIMD_RUN_KERNEL = 1, SFB__SIMD_RUN_STAM_FAR = 2, SFB__SIMD_RUN_TRI = 3, SFB__SIMD_RUN_LOOP_FAR = 4 };
typedef struct sfb__simd_slot {
    const float *blk;
    float s, t, dsc;
    int cs, rot, run;
} sfb__simd_slot;

/* Writes location q (exactly three floats per asked output). */
static void sfb__simd_write(const sfb__simd_pjob *j, int q, double res[6][3], const double nrm[3]) {
    const sfb_eval_output *o = j->out;
    float *dst[7];
    const double *src[7];
    int k, c;
    dst[0] = o->position; dst[1] = o->du; dst[2] = o->dv; dst[3] = o->duu; dst[4] = o->duv; dst[5] = o->dvv; dst[6] = o->normal;
    for (k = 0; k < 6; ++k) src[k] = res[k];
    src[6] = nrm;
    for (k = 0; k < 7; ++k)
        if (dst[k])
            for (c = 0; c < 3; ++c) dst[k][3 * (size_t)q + c] = (float)src[k][c];
}

/* The end of the Stam locations beyond the packed levels: res (in the patch's (s, t)) scaled
 * to the location's parametric face by the locate scale sc, the normal from the finite frame
 * nres; a frame whose normal under- or overflows goes to the ref kernel. */
static void sfb__simd_far_finish(const sfb__simd_pjob *j, int q, double sc, double res[6][3], double nres[2][3]) {
    double nrm[3], len;
    int c;
    nrm[0] = nres[0][1] * nres[1][2] - nres[0][2] * nres[1][1];
    nrm[1] = nres[0][2] * nres[1][0] - nres[0][0] * nres[1][2];
    nrm[2] = nres[0][0] * nres[1][1] - nres[0][1] * nres[1][0];
    len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (j->out->normal && !(len > 0.0 && len <= 1e300)) { sfb__simd_ref_one(j, q); return; }
    for (c = 0; c < 3; ++c) {
        if (j->out->normal) nrm[c] /= len;
        res[1][c] *= sc; res[2][c] *= sc;
        res[3][c] *= sc * sc; res[4][c] *= sc * sc; res[5][c] *= sc * sc;
    }
    sfb__simd_write(j, q, res, nrm);
}

/* Unit normal from window tangents du, dv (lanes 0..2), or 0 where float cannot be trusted to
 * give it within ~1e-4 rad (see Numerics): |n| >= 2e-3 E (|du| + |dv|), using
 * (|du| + |dv|)^2 <= 2 (|du|^2 + |dv|^2). */
static int sfb__simd_unit_normal(const float *du, const float *dv, float E, double n[3]) {
    double a = 0.0, b = 0.0, c, e = (double)E;
    int k;
    n[0] = (double)du[1] * dv[2] - (double)du[2] * dv[1];
    n[1] = (double)du[2] * dv[0] - (double)du[0] * dv[2];
    n[2] = (double)du[0] * dv[1] - (double)du[1] * dv[0];
    for (k = 0; k < 3; ++k) { a += (double)du[k] * du[k]; b += (double)dv[k] * dv[k]; }
    c = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (!(c > 0.0 && c >= 8e-6 * e * e * (a + b) && c <= 1e300)) return 0;
    c = sqrt(c);
    for (k = 0; k < 3; ++k) n[k] /= c;
    return 1;
}

/* Finishes a window result r in double (portable, neon); returns 0, having written nothing,
 * where the normal must come from ref. ef scales the window's E in the normal's float-trust test
 * (as sfb__simd_sse2_put's). */
static int sfb__simd_put_generic(const sfb__simd_pjob *j, int q, float r[6][4], const sfb__simd_slot *sl, float ef) {
    double res[6][3], nrm[3] = {0.0, 0.0, 0.0};
    const double d = sl->dsc, d2 = d * d;
    int c;
    if (j->out->normal && !sfb__simd_unit_normal(r[1], r[2], sl->blk[3 * sl->cs + 15] * ef, nrm)) return 0;
    for (c = 0; c < 3; ++c) {
        const double Pu = d * r[1][c], Pv = d * r[2][c];
        res[0][c] = r[0][c];
        switch (sl->rot) {
        default: res[1][c] = Pu; res[2][c] = Pv; break;
        case 1: res[1][c] = -Pv; res[2][c] = Pu; break;
        case 2: res[1][c] = -Pu; res[2][c] = -Pv; break;
        case 3: res[1][c] = Pv; res[2][c] = -Pu; break;
        case 4: res[1][c] = -Pv; res[2][c] = Pu - Pv; break;
        case 5: res[1][c] = Pv - Pu; res[2][c] = -Pu; break;
        }
        if (!j->second) {
            res[3][c] = res[4][c] = res[5][c] = 0.0;
        } else if (sl->rot == 4) {
            res[3][c] = d2 * r[5][c]; res[4][c] = d2 * ((double)r[5][c] - r[4][c]); res[5][c] = d2 * (((double)r[3][c] - 2.0 * r[4][c]) + r[5][c]);
        } else if (sl->rot == 5) {
            res[3][c] = d2 * (((double)r[3][c] - 2.0 * r[4][c]) + r[5][c]); res[4][c] = d2 * ((double)r[3][c] - r[4][c]); res[5][c] = d2 * r[3][c];
        } else if (sl->rot & 1) {
            res[3][c] = d2 * r[5][c]; res[4][c] = -d2 * r[4][c]; res[5][c] = d2 * r[3][c];
        } else {
            res[3][c] = d2 * r[3][c]; res[4][c] = d2 * r[4][c]; res[5][c] = d2 * r[5][c];
        }
    }
    sfb__simd_write(j, q, res, nrm);
    return 1;
}

#ifdef SFB__SIMD_SSE2
#define SFB__SIMD_BC(v, i) _mm_shuffle_ps(v, v, _MM_SHUFFLE(i, i, i, i))
#define SFB__SIMD_YZX(v) _mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 0, 2, 1))
#endif

/* ---- the quad and triangle kernels ---- */
#include "patches_quad.h"
#include "patches_tri.h"

/* Prepares locations [a, b) into sl[0 .. b - a): one tight loop, so that the out-of-order core
 * overlaps the descents of many locations (their dependent quadtree loads), where one prep
 * between two kernels left each descent's latency exposed (1 M random locations on the bench's
 * tori, one thread: Catmull-Clark 33 against 37 ns a location, tribezier 23 against 24). */
static SFB__SIMD_FORCEINLINE void sfb__simd_prep_batch(const sfb__simd_pjob *j, int a, int b, sfb__simd_slot *sl) {
    int q;
    if (j->tri)
        for (q = a; q < b; ++q) sfb__simd_prep_tri(j, q, &sl[q - a]);
    else
        for (q = a; q < b; ++q) sfb__simd_prep(j, q, &sl[q - a]);
}

static void sfb__simd_prange_generic(const sfb__simd_pjob *j, int first, int last) {
    sfb__simd_slot batch[2][SFB__SIMD_BATCH];
    int b, cur = 0;
    sfb__simd_prep_batch(j, first, last - first > SFB__SIMD_BATCH ? first + SFB__SIMD_BATCH : last, batch[0]);
    for (b = first; b < last; b += SFB__SIMD_BATCH, cur ^= 1) {
        const int e = last - b > SFB__SIMD_BATCH ? b + SFB__SIMD_BATCH : last;
        int q;
        sfb__simd_prep_batch(j, e, last - e > SFB__SIMD_BATCH ? e + SFB__SIMD_BATCH : last, batch[cur ^ 1]);
        for (q = b; q < e; ++q) {
            const sfb__simd_slot *sl = &batch[cur][q - b];
            float r[6][4];
            if (sl->run == SFB__SIMD_RUN_KERNEL || sl->run == SFB__SIMD_RUN_TRI) {
                float ef = 1.0f;
                if (sl->run == SFB__SIMD_RUN_TRI) ef = j->tri_eval(sl->blk, sl->s, sl->t, j->second, r);
                else j->bs(sl->blk, sl->cs, sl->s, sl->t, j->second, r);
                if (!sfb__simd_put_generic(j, q, r, sl, ef)) sfb__simd_ref_one(j, q);
            } else if (sl->run == SFB__SIMD_RUN_STAM_FAR) {
                sfb__simd_stam_far(j, q);
            } else if (sl->run == SFB__SIMD_RUN_LOOP_FAR) {
                sfb__simd_loop_far(j, q);
            } else {
                sfb__simd_ref_one(j, q);
            }
        }
    }
}

/* ---- sse2 (and the 128-bit finishing shared with avx2 and avx512) ---- */
#ifdef SFB__SIMD_SSE2
/* Stores lanes 0..2 of v at dst[at..at+2]; with `full` a 4-float store, whose 4th float is the
 * next location's x, which the same range writes afterwards. */
static inline void sfb__simd_sse2_store3(float *dst, size_t at, __m128 v, int full) {
    if (full) {
        _mm_storeu_ps(dst + at, v);
    } else {
        _mm_storel_pi((__m64 *)(void *)(dst + at), v);
        _mm_store_ss(dst + at + 2, _mm_movehl_ps(v, v));
    }
}

/* Maps the derivatives (rotation, scale), makes the normal and stores location q from a window
 * result; returns 0, having written nothing, where the normal must come from ref. ef scales the
 * window's E in the normal's float-trust test (1, or SFB__SIMD_TRI2_EFACTOR for the float pair
 * kernel's results). */
static SFB__SIMD_FORCEINLINE int sfb__simd_sse2_put(const sfb__simd_pjob *j, int q, int full, const __m128 r[6], const sfb__simd_slot *sl,
                                                   float ef) {
    const sfb_eval_output *o = j->out;
    const size_t at = 3 * (size_t)q;
    const __m128 xyz = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
    const __m128 Pu = _mm_and_ps(r[1], xyz), Pv = _mm_and_ps(r[2], xyz), vsc = _mm_set1_ps(sl->dsc);
    __m128 du, dv;
    if (o->normal) {
        const float E = sl->blk[3 * sl->cs + 15] * ef;
        const __m128 n = SFB__SIMD_YZX(_mm_sub_ps(_mm_mul_ps(Pu, SFB__SIMD_YZX(Pv)), _mm_mul_ps(SFB__SIMD_YZX(Pu), Pv)));
        const __m128 x = _mm_mul_ps(Pu, Pu), y = _mm_mul_ps(Pv, Pv), z = _mm_mul_ps(n, n);
        __m128 ab = _mm_add_ps(_mm_unpacklo_ps(x, y), _mm_unpackhi_ps(x, y)); /* x0+x2 y0+y2 x1+x3 y1+y3 */
        __m128 cc = _mm_add_ps(z, _mm_movehl_ps(z, z));
        float a, b, c;
        ab = _mm_add_ps(ab, _mm_movehl_ps(ab, ab));
        cc = _mm_add_ss(cc, SFB__SIMD_BC(cc, 1));
        a = _mm_cvtss_f32(ab);
        b = _mm_cvtss_f32(SFB__SIMD_BC(ab, 1));
        c = _mm_cvtss_f32(cc);
        /* the float-trust test of sfb__simd_unit_normal, with c in float's comfortable range */
        if (!(c > 1e-30f && c <= 1e30f && c >= 8e-6f * E * E * (a + b))) return 0;
        sfb__simd_sse2_store3(o->normal, at, _mm_div_ps(n, _mm_sqrt_ps(SFB__SIMD_BC(cc, 0))), full);
    }
    {
        /* (Ps, Pt) = (a Pu + b Pv, c Pu + d Pv) dsc, (a, b, c, d) by frame (rot): a table, not
         * a branch (B-spline and Stam locations come in random order) */
        static const float rot[6][4] = {{1, 0, 0, 1}, {0, -1, 1, 0}, {-1, 0, 0, -1}, {0, 1, -1, 0}, {0, -1, 1, -1}, {-1, 1, -1, 0}};
        const __m128 k = _mm_mul_ps(_mm_loadu_ps(rot[sl->rot]), vsc);
        du = _mm_add_ps(_mm_mul_ps(Pu, SFB__SIMD_BC(k, 0)), _mm_mul_ps(Pv, SFB__SIMD_BC(k, 1)));
        dv = _mm_add_ps(_mm_mul_ps(Pu, SFB__SIMD_BC(k, 2)), _mm_mul_ps(Pv, SFB__SIMD_BC(k, 3)));
    }
    if (o->position) sfb__simd_sse2_store3(o->position, at, r[0], full);
    if (o->du) sfb__simd_sse2_store3(o->du, at, du, full);
    if (o->dv) sfb__simd_sse2_store3(o->dv, at, dv, full);
    if (j->second) {
        const __m128 sc2 = _mm_mul_ps(vsc, vsc);
        __m128 uu, uv, vv;
        if (sl->rot < 4) {
            const int odd = sl->rot & 1; /* frames turned by 90 degrees swap u and v */
            uu = _mm_mul_ps(odd ? r[5] : r[3], sc2);
            vv = _mm_mul_ps(odd ? r[3] : r[5], sc2);
            uv = _mm_mul_ps(r[4], odd ? _mm_xor_ps(sc2, _mm_set1_ps(-0.0f)) : sc2);
        } else if (sl->rot == 4) { /* Pss = Pvv, Pst = Pvv - Puv, Ptt = Puu - 2 Puv + Pvv */
            uu = _mm_mul_ps(r[5], sc2);
            uv = _mm_mul_ps(_mm_sub_ps(r[5], r[4]), sc2);
            vv = _mm_mul_ps(_mm_add_ps(_mm_sub_ps(r[3], _mm_add_ps(r[4], r[4])), r[5]), sc2);
        } else {                   /* Pss = Puu - 2 Puv + Pvv, Pst = Puu - Puv, Ptt = Puu */
            uu = _mm_mul_ps(_mm_add_ps(_mm_sub_ps(r[3], _mm_add_ps(r[4], r[4])), r[5]), sc2);
            uv = _mm_mul_ps(_mm_sub_ps(r[3], r[4]), sc2);
            vv = _mm_mul_ps(r[3], sc2);
        }
        if (o->duu) sfb__simd_sse2_store3(o->duu, at, uu, full);
        if (o->duv) sfb__simd_sse2_store3(o->duv, at, uv, full);
        if (o->dvv) sfb__simd_sse2_store3(o->dvv, at, vv, full);
    }
    return 1;
}

/* The range loop of the 128-bit-finishing kernels: batches of SFB__SIMD_BATCH locations, each
 * prepared while the one before is evaluated. With PAIR (avx2, avx512), two triangle locations in
 * a row of a batch without second derivatives go to the float pair kernel TRI2 (patches_tri.h),
 * a triangle location without such a neighbour to the double kernel: the same call gives the same
 * bits on any number of threads (eval_patches cuts it in whole batches), but a location may differ
 * in its last bits between calls where it has a neighbour and where it has none. (Giving a lone
 * location the pair kernel too, paired with itself, made the loop over a third slower on the bench's torus,
 * whose locations are all paired: whatever was added there, a branch, a deferred list or a call,
 * the loop's descent loads stalled longer; not understood, left.) */
#define SFB__SIMD_PATCH_RANGE(NAME, ATTR, EVAL, TRI, PAIR, TRI2)                                                 \
    ATTR static void NAME(const sfb__simd_pjob *j, int first, int last) {                                        \
        sfb__simd_slot batch[2][SFB__SIMD_BATCH];                                                                \
        int b, cur = 0;                                                                                          \
        sfb__simd_prep_batch(j, first, last - first > SFB__SIMD_BATCH ? first + SFB__SIMD_BATCH : last, batch[0]); \
        for (b = first; b < last; b += SFB__SIMD_BATCH, cur ^= 1) {                                              \
            const int e = last - b > SFB__SIMD_BATCH ? b + SFB__SIMD_BATCH : last;                               \
            int q;                                                                                               \
            sfb__simd_prep_batch(j, e, last - e > SFB__SIMD_BATCH ? e + SFB__SIMD_BATCH : last, batch[cur ^ 1]); \
            for (q = b; q < e; ++q) {                                                                            \
                const sfb__simd_slot *sl = &batch[cur][q - b];                                                   \
                __m128 r[6];                                                                                     \
                if (PAIR && sl->run == SFB__SIMD_RUN_TRI && !j->second && q + 1 < e && sl[1].run == SFB__SIMD_RUN_TRI) { \
                    __m128 r1[6];                                                                                \
                    TRI2(sl[0].blk, sl[0].s, sl[0].t, sl[1].blk, sl[1].s, sl[1].t, r, r1);                       \
                    if (!sfb__simd_sse2_put(j, q, 1, r, sl, SFB__SIMD_TRI2_EFACTOR)) sfb__simd_ref_one(j, q);    \
                    ++q;                                                                                         \
                    if (!sfb__simd_sse2_put(j, q, q + 1 < last, r1, sl + 1, SFB__SIMD_TRI2_EFACTOR)) sfb__simd_ref_one(j, q); \
                } else if (sl->run == SFB__SIMD_RUN_KERNEL) {                                                    \
                    EVAL(sl->blk, sl->cs, sl->s, sl->t, j->second, r);                                           \
                    if (!sfb__simd_sse2_put(j, q, q + 1 < last, r, sl, 1.0f)) sfb__simd_ref_one(j, q);           \
                } else if (sl->run == SFB__SIMD_RUN_TRI) {                                                       \
                    TRI(sl->blk, sl->cs, sl->s, sl->t, j->second, r);                                            \
                    if (!sfb__simd_sse2_put(j, q, q + 1 < last, r, sl, 1.0f)) sfb__simd_ref_one(j, q);           \
                } else if (sl->run == SFB__SIMD_RUN_STAM_FAR) {                                                  \
                    sfb__simd_stam_far(j, q);                                                                    \
                } else if (sl->run == SFB__SIMD_RUN_LOOP_FAR) {                                                  \
                    sfb__simd_loop_far(j, q);                                                                    \
                } else {                                                                                         \
                    sfb__simd_ref_one(j, q);                                                                     \
                }                                                                                                \
            }                                                                                                    \
        }                                                                                                        \
    }

SFB__SIMD_PATCH_RANGE(sfb__simd_prange_sse2, , sfb__simd_sse2_eval, sfb__simd_sse2_tri, 0, sfb__simd_sse2_tri2_none)
#endif /* SFB__SIMD_SSE2 */

#ifdef SFB__SIMD_X86_DISPATCH
SFB__SIMD_PATCH_RANGE(sfb__simd_prange_avx2, SFB__SIMD_TARGET_AVX2, sfb__simd_avx2_eval, sfb__simd_avx2_tri, 1, sfb__simd_avx2_tri2)
SFB__SIMD_PATCH_RANGE(sfb__simd_prange_avx512, SFB__SIMD_TARGET_AVX512, sfb__simd_avx512_eval, sfb__simd_avx512_tri, 1, sfb__simd_avx512_tri2)
#endif /* SFB__SIMD_X86_DISPATCH */

/* ---- the family ---- */
/* The kernels of the state's instruction set: a range loop, and for the generic
 * (scalar-finishing) range loop its window kernels. */
static void sfb__simd_patches_select(int isa, sfb__simd_prange_fn *range, sfb__simd_bs_fn *bs, sfb__simd_tri_fn *tri) {
    *range = sfb__simd_prange_generic;
    *bs = sfb__simd_bs_portable;
    *tri = sfb__simd_tri_portable;
    switch (isa) {
#ifdef SFB__SIMD_SSE2
    case SFB__SIMD_ISA_SSE2: *range = sfb__simd_prange_sse2; break;
#endif
#ifdef SFB__SIMD_X86_DISPATCH
    case SFB__SIMD_AVX2: *range = sfb__simd_prange_avx2; break;
    case SFB__SIMD_AVX512: *range = sfb__simd_prange_avx512; break;
#endif
#ifdef SFB__SIMD_NEON
    case SFB__SIMD_ISA_NEON:
        *bs = sfb__simd_bs_neon;
#ifdef SFB__SIMD_TRI_NEON
        *tri = sfb__simd_tri_neon;
#endif
        break;
#endif
    default: break;
    }
}

/* Floats of patch p's grids: 64 (B-spline), 48 (Bezier triangle), 100 per level (Stam with its
 * eigen structure), 144 per level (Stam-Loop), 0 (the ref kernel evaluates it). */
static size_t sfb__simd_patch_floats(const sfb__patch_table *pt, int p) {
    const int n = pt->pfirst[p + 1] - pt->pfirst[p];
    if (pt->ptype[p] == SFB__PATCH_BSPLINE) return n == 16 ? 64 : 0;
    if (pt->ptype[p] == SFB__PATCH_BEZTRI) return n == 15 ? SFB__SIMD_TRI_FLOATS : 0;
    if (pt->ptype[p] == SFB__PATCH_STAM) {
        const int N = pt->pvalence[p];
        const sfb__eigen_cc *e = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eig[N] : NULL;
        return e && e->K == n && e->lambda && e->phi ? 100 * SFB__SIMD_STAM_LEVELS : 0;
    }
    if (pt->ptype[p] == SFB__PATCH_STAM_LOOP) {
        const int N = pt->pvalence[p];
        const sfb__eigen_loop *e = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eigl[N] : NULL;
        return e && e->K == n && e->lambda && e->phi && e->head ? 3 * SFB__SIMD_TRI_FLOATS * SFB__SIMD_LOOP_LEVELS : 0;
    }
    return 0;
}

/* Packs patches [first, last) of a table at their offsets (poff, floats into blk), each its leaf
 * code into pcode: patches are independent, so ranges of them may be packed at once (the upload's
 * threads). */
typedef struct sfb__simd_pack_job {
    const sfb__patch_table *pt;
    float *blk;
    const size_t *poff;
    int *pcode;
} sfb__simd_pack_job;

static void sfb__simd_pack_range(const sfb__simd_pack_job *J, int first, int last) {
    const sfb__patch_table *pt = J->pt;
    double lp[2 * SFB__STAM_MAX_VALENCE + 8]; /* sfb__simd_pack_stam's scratch: Catmull-Clark Stam K = 2 N + 8 */
    int p;
    for (p = first; p < last; ++p) {
        const size_t f = sfb__simd_patch_floats(pt, p), at = J->poff[p];
        const int *cv = pt->cv + pt->pfirst[p];
        J->pcode[p] = -(SFB__SIMD_LEAF_REF + 1);
        if (f == 0) continue;
        if (pt->ptype[p] == SFB__PATCH_BEZTRI) {
            double q[15][3];
            int k, c;
            for (k = 0; k < 15; ++k)
                for (c = 0; c < 3; ++c) q[k][c] = pt->point_data[3 * (size_t)cv[k] + c];
            sfb__simd_pack_tri(J->blk + at, q);
            J->pcode[p] = -((int)((at / 4) << 4 | SFB__SIMD_LEAF_TRI) + 1);
        } else if (f == 64) {
            static const int win[1][2] = {{0, 0}};
            double q[16][3];
            unsigned char set[16];
            int k, c;
            for (k = 0; k < 16; ++k) {
                const int slot = (k % 4) * 4 + k / 4; /* cv[4 j + i] is point (i, j) */
                for (c = 0; c < 3; ++c) q[slot][c] = pt->point_data[3 * (size_t)cv[k] + c];
                set[k] = 1;
            }
            sfb__simd_pack_grid(J->blk + at, 4, 4, q, set, win, 1);
            J->pcode[p] = -((int)((at / 4) << 4 | SFB__SIMD_LEAF_BSPLINE) + 1);
        } else if (pt->ptype[p] == SFB__PATCH_STAM_LOOP ? SFB__PARAM_CORNER(pt->pparam[p]) < 3 && sfb__simd_pack_stam_loop(J->blk + at, pt, p)
                                                         : sfb__simd_pack_stam(J->blk + at, pt, p, lp)) {
            J->pcode[p] = -((int)((at / 4) << 4 | (size_t)SFB__PARAM_CORNER(pt->pparam[p]) << 2 | SFB__SIMD_LEAF_STAM) + 1);
        }
    }
}

#ifdef SFB__SIMD_THREADS
static void sfb__simd_pack_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    (void)s;
    sfb__simd_pack_range((const sfb__simd_pack_job *)arg, a, b);
}
#endif

/* Patches from which the upload packs over the pool (fewer: on the caller's thread). */
#define SFB__SIMD_INLINE_PACK 2048

/* upload for quad and triangle tables: the grids and triangles (B-spline and Bezier triangle
 * ones first, all 64-byte aligned, then the Stam and Stam-Loop ones) and the quadtree with
 * leaf codes (vtable.h has checked the arguments and that there is something to pack). The
 * offsets are laid out first, then the patches packed, over the pool from SFB__SIMD_INLINE_PACK
 * patches on: every patch writes only its own floats and code, so the blocks are the same bit
 * for bit whatever the threads (a Catmull-Clark mesh of triangles, all of whose patches are
 * Stam ones after the first step, spent a fifth of its surface creation here on one thread). */
static sfb_result sfb__simd_patches_upload(sfb__simd_state *s, const sfb__patch_table *pt, void **handle) {
    sfb_context *ctx = s->ctx;
    sfb__simd_patches *h;
    sfb__simd_pack_job J;
    int *pcode = NULL;
    size_t nf = 0, at, *poff = NULL;
    int p, pass;
    for (p = 0; p < pt->npatch; ++p) nf += sfb__simd_patch_floats(pt, p);
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
    poff = (size_t *)sfb__alloc(ctx, ((size_t)pt->npatch + 1) * sizeof(size_t));
    if (!h->root || !h->node || !h->raw || !pcode || !poff) {
        sfb__free(ctx, pcode);
        sfb__free(ctx, poff);
        sfb__simd_release_patches(s, h);
        return sfb__oom(ctx, "the simd backend's patch data");
    }
    h->bytes = sizeof *h + ((size_t)pt->nptex + (size_t)pt->nnodes * 4 + 1) * sizeof(int) + nf * sizeof(float) + 64;
    /* 64-byte alignment: a B-spline column is then one cache line */
    h->blk = (float *)(void *)((char *)h->raw + ((64 - ((uintptr_t)h->raw & 63)) & 63));
    /* the offsets: B-spline grids and triangles first (all 64-byte aligned), then the Stam ones */
    at = 0;
    for (pass = 0; pass < 2; ++pass)
        for (p = 0; p < pt->npatch; ++p) {
            const size_t f = sfb__simd_patch_floats(pt, p);
            if (pass == 0) poff[p] = 0;
            if (f == 0 || (f == 64 || f == SFB__SIMD_TRI_FLOATS) != (pass == 0)) continue;
            poff[p] = at;
            at += f;
        }
    J.pt = pt; J.blk = h->blk; J.poff = poff; J.pcode = pcode;
#ifdef SFB__SIMD_THREADS
    if (pt->npatch < SFB__SIMD_INLINE_PACK || !sfb__simd_pool_run(s, sfb__simd_pack_task, &J, 0, pt->npatch, NULL, 0, 0))
#endif
        sfb__simd_pack_range(&J, 0, pt->npatch);
    for (p = 0; p < pt->nptex; ++p) h->root[p] = sfb__simd_leaf(pcode, pt->ptex_root[p]);
    for (p = 0; p < 4 * pt->nnodes; ++p) h->node[p] = sfb__simd_leaf(pcode, pt->nodes[p]);
    sfb__free(ctx, pcode);
    sfb__free(ctx, poff);
    *handle = h;
    return SFB_SUCCESS;
}

static void sfb__simd_patches_prepare(const sfb__simd_state *s, sfb__simd_pjob *j) {
    sfb__simd_patches_select(s->isa, &j->range, &j->bs, &j->tri_eval);
}

static const sfb__simd_patch_family sfb__simd_patches_family = {(1u << SFB__FAMILY_QUAD) | (1u << SFB__FAMILY_TRI),
                                                                sfb__simd_patches_upload, sfb__simd_patches_prepare};
