// Patch evaluation (exact limit surface of Catmull-Clark and Loop): one invocation per location.
// The CPU has already found each location's patch and its (s,t) in it (sfb__patch_locate, a
// quadtree walk; for Loop the triangle descent), so this kernel only evaluates. It is the ref
// kernel (src/patch/quad.c, tri.c, table.c: sfb__eval_bspline16, sfb__eval_stam, sfb__eval_endcap,
// sfb__eval_beztri, sfb__eval_stam_loop, sfb__eval_endcap_tri, sfb__ref_eval_one) in float.
//
// Buffers (one piece of the uploaded table; indices are piece-local):
//   patches[p]  = (type, first cv, EV corner, eigen block offset (Stam) or cv count (end cap))
//                 type 0: bicubic B-spline (16 cvs, row-major 4x4, row = v)
//                 type 1: Stam (K = 2N+8 eigen coefficients; (s,t) arrive already turned into
//                         the EV's frame (u,v) by the CPU, in double, so that the EV is at (0,0)
//                         exactly and small distances to it keep their precision)
//                 type 2: bilinear end cap: 4 corner limit positions, then (12 cvs) the two
//                         limit tangents of each corner, whose normals are blended
//                 type 3: quartic Bezier triangle (Loop; 15 cvs row by row in t, s rising in a
//                         row: cv q = (i, j) is the coefficient of s^i t^j w^(4-i-j), w = 1-s-t)
//                 type 4: Stam-Loop (K = N+6 eigen coefficients; (s,t) arrive in the EV's frame
//                         as for type 1, the triangle's (u,v) with the EV at (0,0))
//                 type 5: linear triangle end cap (Loop): 3 corner limit positions, then the
//                         two limit tangents of each corner (9 cvs), normals blended
//   cvs[]       = rows of points[]
//   points[]    = (x, y, z, 0) per point: one load each
//   eig[o...]   = (K, dominant index, subdominant eigenvalue sub, 0), then per eigenvalue i
//                 (lambda, lambda/sub (0 for the dominant), 1 where |lambda| = sub else 0,
//                 Loop: index of its Jordan head or -1), then phi: for sub-patch k and
//                 eigenvalue i, 4 vec4s:
//                 Catmull-Clark (k = 1..3): row b of the 4x4 B-spline coefficients (a = 0..3
//                 in x..w), i.e. Phi_k[a + 4b][i];
//                 Loop (k = 0..2): the 15 Bezier coefficients Phi_k[q][i] in cv order, then 0
//   queries[q]  = (patch, s, t, scale): scale = +-2^depth (negative after an odd number of
//                 middle triangles), derivatives in (s,t) times scale are those in (u,v)
//   results[]   = u_stride floats per query: output `o` (position, du, dv, normal, duu, duv, dvv)
//                 at 3 * u_slot[o] when u_slot[o] >= 0
// The backend prepends "#version 430 core" (desktop) or "#version 310 es" + precision
// (GLES 3.1), and SFB_NO_LOOP or SFB_NO_CATMARK (the kinds of the table's family only); the
// tests validate both versions, with neither define (every kind), with glslangValidator.

layout(local_size_x = 64) in;

struct SfbQuery { int patch_index; float s; float t; float scale; };

layout(std430, binding = 0) readonly buffer SfbPatches { ivec4 patches[]; };
layout(std430, binding = 1) readonly buffer SfbCvs { int cvs[]; };
layout(std430, binding = 2) readonly buffer SfbPoints { vec4 points[]; };
layout(std430, binding = 3) readonly buffer SfbEigen { vec4 eig[]; };
layout(std430, binding = 4) readonly buffer SfbQueries { SfbQuery queries[]; };
layout(std430, binding = 5) writeonly buffer SfbResults { float results[]; };

uniform int u_first;     // first query of this dispatch
uniform int u_last;      // one past the last query
uniform int u_stride;    // floats per query in results[]
uniform int u_slot[7];   // slot of position, du, dv, normal, duu, duv, dvv, or -1
uniform int u_second;    // nonzero: second derivatives are asked for

vec3 sfb_point(int row) { return points[row].xyz; }

// x^e for 0 <= e < 256 by squaring: exact sign for negative eigenvalues (pow() is undefined
// for x < 0 in GLSL) and a harmless underflow to 0 for large e. A fixed trip count keeps the
// invocations of a SIMD group in step. (e <= 150: u >= 2^-149, the smallest float.)
float sfb_ipow(float x, int e) {
    float r = 1.0;
    for (int b = 0; b < 8; ++b) {
        if (((e >> b) & 1) != 0) r *= x;
        x *= x;
    }
    return r;
}

// The backend compiles one program per patch family: SFB_NO_LOOP leaves out the Loop kinds (3..5),
// SFB_NO_CATMARK the Catmull-Clark ones (0..2), so neither pays the other's compile time.
#ifndef SFB_NO_CATMARK
// Uniform cubic B-spline basis, first and second derivatives.
void sfb_basis(float t, out vec4 b, out vec4 d, out vec4 dd) {
    float t2 = t * t, t3 = t2 * t, s = 1.0 - t;
    b = vec4(s * s * s, 3.0 * t3 - 6.0 * t2 + 4.0, -3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0, t3) / 6.0;
    d = vec4(-0.5 * s * s, 1.5 * t2 - 2.0 * t, -1.5 * t2 + t + 0.5, 0.5 * t2);
    dd = vec4(s, 3.0 * t - 2.0, -3.0 * t + 1.0, t);
}

// res: P, Ps, Pt, Pss, Pst, Ptt; tg: the tangent pair whose cross product is the normal
// direction (Ps, Pt, or Stam's derivatives normalised by sub^(n-1) 2^n, finite at the EV).
// The points are taken relative to an inner one: the derivative weights sum to zero, so this
// changes nothing exactly, but in float it keeps the terms at the size of the patch rather
// than of the coordinates (a deep patch far from the origin would lose its tangents).
void sfb_bspline(int first, float s, float t, out vec3 res[6], out vec3 tg[2]) {
    vec4 bu, du, ddu, bv, dv, ddv;
    sfb_basis(s, bu, du, ddu);
    sfb_basis(t, bv, dv, ddv);
    vec3 o = sfb_point(cvs[first + 5]);
    for (int q = 0; q < 6; ++q) res[q] = vec3(0.0);
    for (int j = 0; j < 4; ++j) {
        vec3 r0 = vec3(0.0), r1 = vec3(0.0), r2 = vec3(0.0);
        for (int i = 0; i < 4; ++i) {
            vec3 p = sfb_point(cvs[first + 4 * j + i]) - o;
            r0 += bu[i] * p;
            r1 += du[i] * p;
            r2 += ddu[i] * p;
        }
        res[0] += bv[j] * r0;
        res[1] += bv[j] * r1;
        res[2] += dv[j] * r0;
        res[3] += bv[j] * r2;
        res[4] += dv[j] * r1;
        res[5] += ddv[j] * r0;
    }
    res[0] += o;  // the position weights sum to one
    tg[0] = res[1];
    tg[1] = res[2];
}

void sfb_endcap(int first, float s, float t, out vec3 res[6], out vec3 tg[2]) {
    vec3 p0 = sfb_point(cvs[first]), p1 = sfb_point(cvs[first + 1]);
    vec3 p2 = sfb_point(cvs[first + 2]), p3 = sfb_point(cvs[first + 3]);
    // relative to p0 (the weights sum to one): float error at the size of the cap
    res[0] = p0 + (s * (1.0 - t)) * (p1 - p0) + (s * t) * (p2 - p0) + ((1.0 - s) * t) * (p3 - p0);
    res[1] = (1.0 - t) * (p1 - p0) + t * (p2 - p3);
    res[2] = (1.0 - s) * (p3 - p0) + s * (p2 - p1);
    res[3] = vec3(0.0);
    // two differences of neighbouring corners first: each is exact or nearly so, where
    // p0 - p1 + p2 - p3 left to right loses the twist to cancellation at the points' own
    // magnitude (scaled by 4^depth on deep caps: 5e-4 off ref's at depth 5)
    res[4] = (p0 - p1) - (p3 - p2);
    res[5] = vec3(0.0);
    tg[0] = res[1];
    tg[1] = res[2];
}

// Stam: (u,v) in the EV's frame (EV at (0,0)); corner says how that frame sits in the patch's
// (s,t), for the chain rule. Level n and sub-patch k as in ref; the derivatives are summed with
// (lambda_i / sub)^(n-1) <= 1 and scaled afterwards, so nothing overflows on the way.
void sfb_stam(int first, int corner, int o, float u, float v, bool second, out vec3 res[6], out vec3 tg[2]) {
    vec4 head = eig[o];
    int K = int(head.x), dom = int(head.y);
    float sub = head.z;
    // J[a][b] = d(u,v)_a / d(s,t)_b
    vec2 j0, j1; // rows: du/d(s,t), dv/d(s,t)
    if (corner == 1) { j0 = vec2(0.0, 1.0); j1 = vec2(-1.0, 0.0); }
    else if (corner == 2) { j0 = vec2(-1.0, 0.0); j1 = vec2(0.0, -1.0); }
    else if (corner == 3) { j0 = vec2(0.0, -1.0); j1 = vec2(1.0, 0.0); }
    else { j0 = vec2(1.0, 0.0); j1 = vec2(0.0, 1.0); }
    bool at_ev = (u == 0.0 && v == 0.0);
    int n = 1, k;
    float uu, vv;
    if (at_ev) {
        // the limit point; tangents: the n -> infinity limit of the normalised derivatives
        k = 2; uu = 0.0; vv = 0.0;
    } else {
        while (u < 0.5 && v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
        if (v < 0.5) { k = 1; uu = 2.0 * u - 1.0; vv = 2.0 * v; }
        else if (u < 0.5) { k = 3; uu = 2.0 * u; vv = 2.0 * v - 1.0; }
        else { k = 2; uu = 2.0 * u - 1.0; vv = 2.0 * v - 1.0; }
    }
    vec4 bu, du, ddu, bv, dv, ddv;
    sfb_basis(uu, bu, du, ddu);
    sfb_basis(vv, bv, dv, ddv);
    int phi = o + 1 + K + 4 * K * (k - 1);
    vec3 P = vec3(0.0), Pu = vec3(0.0), Pv = vec3(0.0), Puu = vec3(0.0), Puv = vec3(0.0), Pvv = vec3(0.0);
    for (int i = 0; i < K; ++i) {
        // (b(u)^T Phi_k)_i for each derivative: the rows of Phi_k first combined along v
        vec4 r0 = eig[phi + 4 * i], r1 = eig[phi + 4 * i + 1], r2 = eig[phi + 4 * i + 2], r3 = eig[phi + 4 * i + 3];
        vec4 A = bv.x * r0 + bv.y * r1 + bv.z * r2 + bv.w * r3;
        vec4 D = dv.x * r0 + dv.y * r1 + dv.z * r2 + dv.w * r3;
        float f0 = dot(bu, A), f1 = dot(du, A), f2 = dot(bu, D);
        vec4 e = eig[o + 1 + i];
        float lp, ln;
        if (at_ev) {
            lp = i == dom ? 1.0 : 0.0;
            ln = e.z;
        } else {
            lp = sfb_ipow(e.x, n - 1);
            ln = i == dom ? 0.0 : sfb_ipow(e.y, n - 1);
        }
        vec3 p = sfb_point(cvs[first + i]);
        P += (lp * f0) * p;
        Pu += (ln * f1) * p;
        Pv += (ln * f2) * p;
        if (second) {
            vec4 DD = ddv.x * r0 + ddv.y * r1 + ddv.z * r2 + ddv.w * r3;
            Puu += (ln * dot(ddu, A)) * p;
            Puv += (ln * dot(du, D)) * p;
            Pvv += (ln * dot(bu, DD)) * p;
        }
    }
    // sub^(n-1) 2^n and sub^(n-1) 4^n, formed so that neither factor overflows alone
    float sc1 = at_ev ? 1.0 : 2.0 * sfb_ipow(2.0 * sub, n - 1);
    float sc2 = at_ev ? 0.0 : 4.0 * sfb_ipow(4.0 * sub, n - 1);
    res[0] = P;
    tg[0] = Pu * j0.x + Pv * j1.x;
    tg[1] = Pu * j0.y + Pv * j1.y;
    res[1] = tg[0] * sc1;
    res[2] = tg[1] * sc1;
    res[3] = sc2 * (Puu * (j0.x * j0.x) + Puv * (2.0 * j0.x * j1.x) + Pvv * (j1.x * j1.x));
    res[4] = sc2 * (Puu * (j0.x * j0.y) + Puv * (j0.x * j1.y + j0.y * j1.x) + Pvv * (j1.x * j1.y));
    res[5] = sc2 * (Puu * (j0.y * j0.y) + Puv * (2.0 * j0.y * j1.y) + Pvv * (j1.y * j1.y));
}

#endif // SFB_NO_CATMARK

#ifndef SFB_NO_LOOP
// Quartic Bernstein basis on a triangle in our cv order (q = 0..14, index 15 is 0): B[4 d + c]
// holds entries 4c..4c+3 of quantity d = value, d/ds, d/dt, d2/ds2, d2/dsdt, d2/dt2 (the last
// three only when `second`). Powers are padded by one zero below, so that a term whose
// exponent would be negative vanishes.
const int SFB_BI[15] = int[15](0, 1, 2, 3, 4, 0, 1, 2, 3, 0, 1, 2, 0, 1, 0);
const int SFB_BJ[15] = int[15](0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 3, 3, 4);
const float SFB_FACT[5] = float[5](1.0, 1.0, 2.0, 6.0, 24.0);

void sfb_bez15(float s, float t, bool second, out vec4 B[24]) {
    float w = 1.0 - s - t;
    float S[7], T[7], W[7];
    S[0] = 0.0; S[1] = 0.0; S[2] = 1.0;
    T[0] = 0.0; T[1] = 0.0; T[2] = 1.0;
    W[0] = 0.0; W[1] = 0.0; W[2] = 1.0;
    for (int e = 3; e < 7; ++e) { S[e] = S[e - 1] * s; T[e] = T[e - 1] * t; W[e] = W[e - 1] * w; }
    for (int c = 0; c < 24; ++c) B[c] = vec4(0.0);
    for (int q = 0; q < 15; ++q) {
        int i = SFB_BI[q], j = SFB_BJ[q], k = 4 - i - j;
        float c = 24.0 / (SFB_FACT[i] * SFB_FACT[j] * SFB_FACT[k]);
        float fi = float(i), fj = float(j), fk = float(k);
        // S[2 + e] = s^e
        float m = S[2 + i] * T[2 + j];
        float ms = S[1 + i] * T[2 + j], mt = S[2 + i] * T[1 + j];
        int c4 = q >> 2, l = q & 3;
        B[c4][l] = c * m * W[2 + k];
        B[4 + c4][l] = c * (fi * ms * W[2 + k] - fk * m * W[1 + k]);
        B[8 + c4][l] = c * (fj * mt * W[2 + k] - fk * m * W[1 + k]);
        if (second) {
            float mss = S[i] * T[2 + j], mst = S[1 + i] * T[1 + j], mtt = S[2 + i] * T[j];
            B[12 + c4][l] = c * (fi * (fi - 1.0) * mss * W[2 + k] - 2.0 * fi * fk * ms * W[1 + k] + fk * (fk - 1.0) * m * W[k]);
            B[16 + c4][l] = c * (fi * fj * mst * W[2 + k] - fi * fk * ms * W[1 + k] - fj * fk * mt * W[1 + k] + fk * (fk - 1.0) * m * W[k]);
            B[20 + c4][l] = c * (fj * (fj - 1.0) * mtt * W[2 + k] - 2.0 * fj * fk * mt * W[1 + k] + fk * (fk - 1.0) * m * W[k]);
        }
    }
}

// One quantity of the basis applied to 16 coefficients (4 vec4s).
float sfb_bdot(vec4 B[24], int d, vec4 r0, vec4 r1, vec4 r2, vec4 r3) {
    return dot(B[4 * d], r0) + dot(B[4 * d + 1], r1) + dot(B[4 * d + 2], r2) + dot(B[4 * d + 3], r3);
}

// Quartic Bezier triangle. The derivatives are the degree-3 and degree-2 Bernstein sums of the
// control points' first and second differences, taken first: nearby points subtract exactly in
// float, and those weights are positive, so a deep patch (whose second differences are tiny
// against its points) keeps its second derivatives. The position sums the points relative to an
// inner one (as sfb_bspline).
// Index tables of the sums (flat loops of fixed length, which the compiler unrolls): the
// cubic's 10 terms (i, j) with their multinomial weight and the cvs (i,j), (i+1,j), (i,j+1);
// the quadratic's 6 with (i,j), (i+1,j), (i,j+1), (i+2,j), (i+1,j+1), (i,j+2).
const float SFB_C4[15] = float[15](1.0, 4.0, 6.0, 4.0, 1.0, 4.0, 12.0, 12.0, 4.0, 6.0, 12.0, 6.0, 4.0, 4.0, 1.0);
const ivec2 SFB_D3[10] = ivec2[10](ivec2(0, 0), ivec2(1, 0), ivec2(2, 0), ivec2(3, 0), ivec2(0, 1), ivec2(1, 1), ivec2(2, 1),
                                   ivec2(0, 2), ivec2(1, 2), ivec2(0, 3));
const float SFB_C3[10] = float[10](1.0, 3.0, 3.0, 1.0, 3.0, 6.0, 3.0, 3.0, 3.0, 1.0);
const ivec3 SFB_Q3[10] = ivec3[10](ivec3(0, 1, 5), ivec3(1, 2, 6), ivec3(2, 3, 7), ivec3(3, 4, 8), ivec3(5, 6, 9), ivec3(6, 7, 10),
                                   ivec3(7, 8, 11), ivec3(9, 10, 12), ivec3(10, 11, 13), ivec3(12, 13, 14));
const ivec2 SFB_D2[6] = ivec2[6](ivec2(0, 0), ivec2(1, 0), ivec2(2, 0), ivec2(0, 1), ivec2(1, 1), ivec2(0, 2));
const float SFB_C2[6] = float[6](1.0, 2.0, 1.0, 2.0, 2.0, 1.0);
const ivec3 SFB_Q2A[6] = ivec3[6](ivec3(0, 1, 5), ivec3(1, 2, 6), ivec3(2, 3, 7), ivec3(5, 6, 9), ivec3(6, 7, 10), ivec3(9, 10, 12));
const ivec3 SFB_Q2B[6] = ivec3[6](ivec3(2, 6, 9), ivec3(3, 7, 10), ivec3(4, 8, 11), ivec3(7, 10, 12), ivec3(8, 11, 13), ivec3(11, 13, 14));

void sfb_beztri(int first, float s, float t, bool second, out vec3 res[6], out vec3 tg[2]) {
    vec3 P[15];
    for (int q = 0; q < 15; ++q) P[q] = sfb_point(cvs[first + q]);
    float w = 1.0 - s - t;
    float S[5], T[5], W[5];
    S[0] = 1.0; T[0] = 1.0; W[0] = 1.0;
    for (int e = 1; e < 5; ++e) { S[e] = S[e - 1] * s; T[e] = T[e - 1] * t; W[e] = W[e - 1] * w; }
    vec3 o = P[6], p = vec3(0.0), ds = vec3(0.0), dt = vec3(0.0), dss = vec3(0.0), dst = vec3(0.0), dtt = vec3(0.0);
    for (int q = 0; q < 15; ++q)
        p += (SFB_C4[q] * S[SFB_BI[q]] * T[SFB_BJ[q]] * W[4 - SFB_BI[q] - SFB_BJ[q]]) * (P[q] - o);
    for (int r = 0; r < 10; ++r) {
        ivec2 d = SFB_D3[r];
        ivec3 c = SFB_Q3[r];
        float b = SFB_C3[r] * S[d.x] * T[d.y] * W[3 - d.x - d.y];
        ds += b * (P[c.y] - P[c.x]);
        dt += b * (P[c.z] - P[c.x]);
    }
    if (second)
        for (int r = 0; r < 6; ++r) {
            ivec2 d = SFB_D2[r];
            ivec3 c = SFB_Q2A[r], e = SFB_Q2B[r];
            float b = SFB_C2[r] * S[d.x] * T[d.y] * W[2 - d.x - d.y];
            vec3 e00 = P[c.x], e10 = P[c.y], e01 = P[c.z];
            dss += b * ((P[e.x] - e10) - (e10 - e00));
            dst += b * ((P[e.y] - e10) - (e01 - e00));
            dtt += b * ((P[e.z] - e01) - (e01 - e00));
        }
    res[0] = o + p;  // the position weights sum to one
    res[1] = 4.0 * ds;
    res[2] = 4.0 * dt;
    res[3] = 12.0 * dss;
    res[4] = 12.0 * dst;
    res[5] = 12.0 * dtt;
    tg[0] = res[1];
    tg[1] = res[2];
}

void sfb_endcap_tri(int first, float s, float t, out vec3 res[6], out vec3 tg[2]) {
    vec3 p0 = sfb_point(cvs[first]), p1 = sfb_point(cvs[first + 1]), p2 = sfb_point(cvs[first + 2]);
    res[0] = p0 + s * (p1 - p0) + t * (p2 - p0);
    res[1] = p1 - p0;
    res[2] = p2 - p0;
    res[3] = vec3(0.0);
    res[4] = vec3(0.0);
    res[5] = vec3(0.0);
    tg[0] = res[1];
    tg[1] = res[2];
}

// Stam-Loop: (u,v) in the EV's frame (EV at (0,0)), corner as in sfb_stam. Level n by doubling
// until u + v >= 1/2, then sub-patch k: 0 at u >= 1/2, 1 at v >= 1/2, 2 the middle (turned by
// 180 degrees: first derivatives change sign). Weights lambda^(n-1), the derivatives' ones
// divided by sub^(n-1) and scaled afterwards (the normal comes from the normalised ones), and
// for the second vector of a Jordan block (valence 3) the term (n-1) lambda^(n-2) of its head.
void sfb_stam_loop(int first, int corner, int o, float u, float v, bool second, out vec3 res[6], out vec3 tg[2]) {
    vec4 head = eig[o];
    int K = int(head.x), dom = int(head.y);
    float sub = head.z;
    vec2 j0, j1; // rows: du/d(s,t), dv/d(s,t)
    if (corner == 1) { j0 = vec2(0.0, 1.0); j1 = vec2(-1.0, -1.0); }
    else if (corner == 2) { j0 = vec2(-1.0, -1.0); j1 = vec2(1.0, 0.0); }
    else { j0 = vec2(1.0, 0.0); j1 = vec2(0.0, 1.0); }
    bool at_ev = u + v == 0.0;  // u, v >= 0
    int n = 1, k;
    float ss, tt, sg = 1.0;
    if (at_ev) {
        // the limit point; tangents: the limit of the normalised derivatives, which only the
        // subdominant pair reaches (the same plane anywhere in a sub-patch)
        k = 0; ss = 0.25; tt = 0.25;
    } else {
        while (u + v < 0.5) { u *= 2.0; v *= 2.0; ++n; }
        if (u >= 0.5) { k = 0; ss = 2.0 * u - 1.0; tt = 2.0 * v; }
        else if (v >= 0.5) { k = 1; ss = 2.0 * u; tt = 2.0 * v - 1.0; }
        else { k = 2; ss = 1.0 - 2.0 * u; tt = 1.0 - 2.0 * v; sg = -1.0; }
    }
    int m = n - 1;
    vec4 B[24];
    sfb_bez15(ss, tt, second, B);
    int phi = o + 1 + K + 4 * K * k;
    vec3 P = vec3(0.0), Pu = vec3(0.0), Pv = vec3(0.0), Puu = vec3(0.0), Puv = vec3(0.0), Pvv = vec3(0.0);
    for (int i = 0; i < K; ++i) {
        vec4 r0 = eig[phi + 4 * i], r1 = eig[phi + 4 * i + 1], r2 = eig[phi + 4 * i + 2], r3 = eig[phi + 4 * i + 3];
        vec4 e = eig[o + 1 + i];
        float lp, ln;
        if (at_ev) {
            lp = i == dom ? 1.0 : 0.0;
            ln = e.z;
        } else {
            lp = sfb_ipow(e.x, m);
            ln = i == dom ? 0.0 : sfb_ipow(e.y, m);
        }
        float g0 = lp * sfb_bdot(B, 0, r0, r1, r2, r3);
        float g1 = ln * sfb_bdot(B, 1, r0, r1, r2, r3), g2 = ln * sfb_bdot(B, 2, r0, r1, r2, r3);
        float g3 = 0.0, g4 = 0.0, g5 = 0.0;
        if (second) {
            g3 = ln * sfb_bdot(B, 3, r0, r1, r2, r3);
            g4 = ln * sfb_bdot(B, 4, r0, r1, r2, r3);
            g5 = ln * sfb_bdot(B, 5, r0, r1, r2, r3);
        }
        int h = int(e.w);
        if (!at_ev && h >= 0 && m > 0) {
            // m lambda^(m-1) of the head's function, and that over sub^m for the derivatives
            int ph = phi + 4 * h;
            vec4 h0 = eig[ph], h1 = eig[ph + 1], h2 = eig[ph + 2], h3 = eig[ph + 3];
            float jl = float(m) * sfb_ipow(e.x, m - 1), jn = float(m) * sfb_ipow(e.y, m - 1) / sub;
            g0 += jl * sfb_bdot(B, 0, h0, h1, h2, h3);
            g1 += jn * sfb_bdot(B, 1, h0, h1, h2, h3);
            g2 += jn * sfb_bdot(B, 2, h0, h1, h2, h3);
            if (second) {
                g3 += jn * sfb_bdot(B, 3, h0, h1, h2, h3);
                g4 += jn * sfb_bdot(B, 4, h0, h1, h2, h3);
                g5 += jn * sfb_bdot(B, 5, h0, h1, h2, h3);
            }
        }
        vec3 p = sfb_point(cvs[first + i]);
        P += g0 * p;
        Pu += g1 * p;
        Pv += g2 * p;
        Puu += g3 * p;
        Puv += g4 * p;
        Pvv += g5 * p;
    }
    Pu *= sg;
    Pv *= sg;
    // sub^(n-1) 2^n and sub^(n-1) 4^n, formed so that neither factor overflows alone
    float sc1 = at_ev ? 1.0 : 2.0 * sfb_ipow(2.0 * sub, m);
    float sc2 = at_ev ? 0.0 : 4.0 * sfb_ipow(4.0 * sub, m);
    res[0] = P;
    tg[0] = Pu * j0.x + Pv * j1.x;
    tg[1] = Pu * j0.y + Pv * j1.y;
    res[1] = tg[0] * sc1;
    res[2] = tg[1] * sc1;
    res[3] = sc2 * (Puu * (j0.x * j0.x) + Puv * (2.0 * j0.x * j1.x) + Pvv * (j1.x * j1.x));
    res[4] = sc2 * (Puu * (j0.x * j0.y) + Puv * (j0.x * j1.y + j0.y * j1.x) + Pvv * (j1.x * j1.y));
    res[5] = sc2 * (Puu * (j0.y * j0.y) + Puv * (2.0 * j0.y * j1.y) + Pvv * (j1.y * j1.y));
}

#endif // SFB_NO_LOOP

void sfb_eval(ivec4 rec, float s, float t, bool second, out vec3 res[6], out vec3 tg[2]) {
#ifndef SFB_NO_LOOP
    if (rec.x == 3) { sfb_beztri(rec.y, s, t, second, res, tg); return; }
    if (rec.x == 4) { sfb_stam_loop(rec.y, rec.z, rec.w, s, t, second, res, tg); return; }
    if (rec.x == 5) { sfb_endcap_tri(rec.y, s, t, res, tg); return; }
#endif
#ifndef SFB_NO_CATMARK
    if (rec.x == 1) { sfb_stam(rec.y, rec.z, rec.w, s, t, second, res, tg); return; }
    if (rec.x == 2) { sfb_endcap(rec.y, s, t, res, tg); return; }
    sfb_bspline(rec.y, s, t, res, tg);
#else
    for (int d = 0; d < 6; ++d) res[d] = vec3(0.0);
    tg[0] = vec3(0.0);
    tg[1] = vec3(0.0);
#endif
}

// A positive multiple of a x b, computed on the vectors scaled to a largest component of 1 so
// that tiny or huge tangents neither underflow nor overflow in float. Zero when either is (as
// ref, only an exactly vanishing normal sends the caller to a nearby point: a threshold would
// also discard nearly degenerate tangents whose direction float still resolves).
vec3 sfb_normal_dir(vec3 a, vec3 b) {
    float ma = max(max(abs(a.x), abs(a.y)), abs(a.z)), mb = max(max(abs(b.x), abs(b.y)), abs(b.z));
    if (!(ma > 0.0) || !(mb > 0.0) || isinf(ma) || isinf(mb)) return vec3(0.0);
    SFB_PRECISE vec3 n = cross(a / ma, b / mb); // precise: exactly zero for parallel tangents
    return n;
}

bool sfb_usable(vec3 n) {
    float l = length(n);
    return l > 0.0 && !isinf(l) && !isnan(l);
}

// End-cap normal as sfb__endcap_normal: the blend (bilinear on a quad, barycentric on a
// triangle: nc = 4 or 3 corners) of the corners' limit normals, each turned to the side of the
// cap's own (chord) normal at that corner, and replaced by the chord normal where it is more than
// 45 degrees away (the corner's limit normal is another sector's).
vec3 sfb_endcap_normal(int first, int nc, float s, float t) {
    float w[4];
    if (nc == 3) { w[0] = 1.0 - s - t; w[1] = s; w[2] = t; w[3] = 0.0; }
    else { w[0] = (1.0 - s) * (1.0 - t); w[1] = s * (1.0 - t); w[2] = s * t; w[3] = (1.0 - s) * t; }
    vec3 n = vec3(0.0);
    for (int k = 0; k < nc; ++k) {
        vec3 p = sfb_point(cvs[first + k]);
        vec3 pn = sfb_point(cvs[first + (k + 1) % nc]), pp = sfb_point(cvs[first + (k + nc - 1) % nc]);
        vec3 ch = sfb_normal_dir(pn - p, pp - p);
        vec3 ln = sfb_normal_dir(sfb_point(cvs[first + nc + 2 * k]), sfb_point(cvs[first + nc + 1 + 2 * k]));
        bool has = sfb_usable(ln);
        ch = sfb_usable(ch) ? normalize(ch) : vec3(0.0);
        ln = has ? normalize(ln) : vec3(0.0);
        float d = dot(ln, ch);
        if (d < 0.0) { ln = -ln; d = -d; }
        if (!has || d < 0.70710678118654752) ln = ch;
        n += w[k] * ln;
    }
    return n;
}

void sfb_store(int base, int slot, vec3 x) {
    if (slot < 0) return;
    int d = base + 3 * slot;
    results[d] = x.x;
    results[d + 1] = x.y;
    results[d + 2] = x.z;
}

void main() {
    int q = int(gl_GlobalInvocationID.x) + u_first;
    if (q >= u_last) return;
    SfbQuery qu = queries[q];
    ivec4 rec = patches[qu.patch_index];
    bool second = u_second != 0;
    vec3 res[6], tg[2];
    sfb_eval(rec, qu.s, qu.t, second, res, tg);
    vec3 nrm = vec3(0.0);
    if (u_slot[3] >= 0) {
        if (rec.x == 2 && rec.w == 12) nrm = sfb_endcap_normal(rec.y, 4, qu.s, qu.t);
        else if (rec.x == 5) nrm = sfb_endcap_normal(rec.y, 3, qu.s, qu.t);
        else nrm = sfb_normal_dir(tg[0], tg[1]);
        if (!sfb_usable(nrm)) {
            // degenerate tangents (a collapsed control net): the normal a step inside the patch,
            // from the tangents there (end caps too, as ref); a triangle's step stays inside it
            vec3 r2[6], t2[2];
            float s2 = qu.s + (qu.s < 0.5 ? 1e-3 : -1e-3), tt2 = qu.t + (qu.t < 0.5 ? 1e-3 : -1e-3);
            if (rec.x >= 3) {
                if (s2 + tt2 > 1.0) { s2 = qu.s - 1e-3; tt2 = qu.t - 1e-3; }
                if (qu.s + qu.t < 2e-3) { s2 = qu.s + 1e-3; tt2 = qu.t + 1e-3; }
            }
            sfb_eval(rec, s2, tt2, false, r2, t2);
            nrm = sfb_normal_dir(t2[0], t2[1]);
        }
        nrm = sfb_usable(nrm) ? normalize(nrm) : vec3(0.0);
    }
    float sc = qu.scale, sc2 = sc * sc;
    int base = q * u_stride;
    sfb_store(base, u_slot[0], res[0]);
    sfb_store(base, u_slot[1], res[1] * sc);
    sfb_store(base, u_slot[2], res[2] * sc);
    sfb_store(base, u_slot[3], nrm);
    sfb_store(base, u_slot[4], res[3] * sc2);
    sfb_store(base, u_slot[5], res[4] * sc2);
    sfb_store(base, u_slot[6], res[5] * sc2);
}
