// Manifold-based blending surfaces (seed 000 sections V.1-V.4; the MANIFOLD4 patch family): the
// blend of four chart local geometries, in float. It is the ref kernel of src/patch/manifold.c
// (sfb__mf_eta, sfb__mf_local, sfb__mf_eval, sfb__mf_eval_patch), whose top comment is the spec.
//
// One source, two stages:
//  - compute (default): one invocation per query of sfb_surface_eval. The CPU has located each
//    query (quadtree walk, depth 0 or 1) and passes the patch, its (s,t) and the scale 2^depth.
//    Second derivatives are not computed here (the backend forms them on the CPU, see gl/manifold.h).
//  - vertex (SFB_MF_VERTEX defined): the seed's vertex program, for sfb_surface_draw_gl. The
//    sample of instance k (parametric face u_first_face + k) and vertex id i + (u_rate + 1) j is
//    (u, v) = (i, j) / u_rate; the program locates it in the face's patch itself.
// The tables are two textures, the same for both stages (texel n of a texture at
// (n % u_width, n / u_width)):
//   u_coef   (RGBA32F) 37 texels per patch p: texel 37p its origin (a point near it, in the
//            model's coordinates); texel 37p + 1 + 9j + r coefficient row r of the local geometry
//            of its corner j (the seed's Fig. 8, one column per patch corner): a patch's C_mn in
//            row 3m + n, a point in row 0, a curve's q0, q1, q2 in rows 0..2. The rows that hold
//            positions (row 0, and a curve's rows 1 and 2) are relative to the origin, so that
//            float keeps their differences at the size of the patch (near a point corner the
//            tangents are differences of nearly equal local geometries).
//   u_index  (RGBA32I) texel f < u_patch_base: parametric face f: (-1, -1, -1, -1) a hole,
//            (p, -2, -2, -2) one patch p, else the patches of its four quadrants (x + 2y order);
//            texel u_patch_base + p: the corner codes of patch p's corners V0..V3 (V0 at
//            (s,t) = (0,0), V1 at (1,0), V3 at (0,1); SFB__MF_CODE bits: kind 0 patch / 1 point /
//            2 curve in bits 0-1, valence k in 2-14, chart face h in 15-27, curve axes a1 in 28-29
//            and a2 in 30-31).
// The backend prepends "#version 430 core" (desktop) or "#version 310 es" + precision (GLES 3.1);
// the tests validate the compute stage of both with glslangValidator, and compile the vertex
// stage on the driver (tests/gl_manifold.c).

#ifdef GL_ES
precision highp sampler2D;
precision highp isampler2D;
#endif

#ifndef SFB_MF_VERTEX
layout(local_size_x = 64) in;

struct SfbQuery { int patch_index; float s; float t; float scale; };
layout(std430, binding = 4) readonly buffer SfbQueries { SfbQuery queries[]; };
layout(std430, binding = 5) writeonly buffer SfbResults { float results[]; };

uniform int u_first;    // first query of this dispatch
uniform int u_last;     // one past the last query
uniform int u_stride;   // floats per query in results[]
uniform int u_slot[4];  // slot of position, du, dv, normal, or -1
#endif

uniform sampler2D u_coef;
uniform isampler2D u_index;
uniform int u_width;      // texels per row of both textures
uniform int u_patch_base; // first patch texel of u_index
uniform int u_weights;    // 0: Hermite, 1: C-infinity

vec3 sfb_mf_texel(int n) { return texelFetch(u_coef, ivec2(n % u_width, n / u_width), 0).xyz; }

ivec4 sfb_mf_int(int n) { return texelFetch(u_index, ivec2(n % u_width, n / u_width), 0); }

// Hermite eta(t) = s^2 (1 + 2t) and eta'(t) = -6 t s (sfb__mf_eta), given t and s = 1 - t,
// whichever of the two is the exact one: a corner coordinate is c, 1 - c, d or 1 - d, and 1 - c
// rounds in float where c is small. This form keeps its relative precision near both ends
// (2t^3 - 3t^2 + 1 near t = 1 would not: the small weights of the far corners multiply whole
// positions, and their errors would swamp the tangents near a corner).
float sfb_mf_hermite(float t, float s, out float dt) {
    dt = -6.0 * t * s;
    return s * s * (1.0 + 2.0 * t);
}

// C-infinity eta by axis. For a parameter x (c or d) with lo = min(x, 1 - x), hi = max(...):
// eps = g(lo) / g(hi) = exp(L), L = 1/hi - 1/lo <= 0 (g(x) = exp(-1/x)), and
//   eta(lo) = 1 / (1 + eps) = m0,   eta(hi) = eps m0,   eta'(lo) = eta'(hi) = eps md,
//   md = -(1/lo^2 + 1/hi^2) m0^2.
// eps falls below float's range within about 0.011 of a border (and below double's within
// 1/745), yet ref's tangents there are sums of such terms where the others vanish (near point
// corners): the blend keeps each term's power of eps_c and eps_d apart (four classes) and
// scales them only when it sums them. lo = 0: L = -1e30 (eps = 0), eta' = 0.
void sfb_mf_cinf_axis(float x, float x1, out float L, out float m0, out float md) {
    float lo = min(x, x1), hi = max(x, x1);
    if (!(lo > 0.0)) { L = -1e30; m0 = 1.0; md = 0.0; return; }
    L = 1.0 / hi - 1.0 / lo;
    m0 = 1.0 / (1.0 + exp(L));
    md = L > -745.0 ? -(1.0 / (lo * lo) + 1.0 / (hi * hi)) * m0 * m0 : 0.0;
}

// One corner's local geometry at its coordinates (a,b): P, dP/da, dP/db (sfb__mf_local), with
// Table 2's vector pairs: [1 u u^2] / [1 v v^2] for a patch, [1 0 0] / [1 0 0] for a point,
// [1 0 0] / Bernstein(sigma) for a curve.
void sfb_mf_local(int base, uint code, float a, float b, out vec3 P, out vec3 Pa, out vec3 Pb) {
    uint kind = code & 3u;
    if (kind == 1u) {
        P = sfb_mf_texel(base);
        Pa = vec3(0.0);
        Pb = vec3(0.0);
    } else if (kind == 2u) {
        uint a1 = (code >> 28) & 3u, a2 = (code >> 30) & 3u;
        float p1 = a1 == 1u ? a : (a1 == 2u ? b : 0.0), p2 = a2 == 1u ? a : (a2 == 2u ? b : 0.0);
        float s = 0.5 * (1.0 - p1 + p2);
        float dsa = 0.5 * (float(a2 == 1u) - float(a1 == 1u)), dsb = 0.5 * (float(a2 == 2u) - float(a1 == 2u));
        vec3 q0 = sfb_mf_texel(base), q1 = sfb_mf_texel(base + 1), q2 = sfb_mf_texel(base + 2);
        vec3 d = 2.0 * ((1.0 - s) * (q1 - q0) + s * (q2 - q1));
        P = ((1.0 - s) * (1.0 - s)) * q0 + (2.0 * s * (1.0 - s)) * q1 + (s * s) * q2;
        Pa = d * dsa;
        Pb = d * dsb;
    } else {
        // the chart: z = zeta^e e^(i phi), e = 4/k, phi = 2 pi h / k, zeta = a + i b, and
        // A = dz/dzeta = e z / zeta = e z conj(zeta) / |zeta|^2 (no second power or angle); at
        // zeta = 0 (and where |zeta|^2 underflows) e e^(i phi) stands in for it (ref's substitute)
        float k = float((code >> 2) & 8191u), h = float((code >> 15) & 8191u);
        float e = 4.0 / k, phi = 6.28318530717958647692 * h / k;
        float r2 = a * a + b * b, u, v, Ar, Ai;
        if (r2 > 0.0) {
            float rz = pow(r2, 0.5 * e), ang = e * atan(b, a) + phi;
            u = rz * cos(ang);
            v = rz * sin(ang);
            Ar = e * (u * a + v * b) / r2;
            Ai = e * (v * a - u * b) / r2;
        } else {
            u = 0.0;
            v = 0.0;
            Ar = e * cos(phi);
            Ai = e * sin(phi);
        }
        vec3 um = vec3(1.0, u, u * u), vm = vec3(1.0, v, v * v);
        vec3 dum = vec3(0.0, 1.0, 2.0 * u), dvm = vec3(0.0, 1.0, 2.0 * v);
        // P = um^T C vm: C's rows combined along v first (rows 3m .. 3m + 2 hold C_m0 .. C_m2)
        P = vec3(0.0);
        vec3 Pu = vec3(0.0), Pv = vec3(0.0);
        for (int m = 0; m < 3; ++m) {
            vec3 c0 = sfb_mf_texel(base + 3 * m), c1 = sfb_mf_texel(base + 3 * m + 1), c2 = sfb_mf_texel(base + 3 * m + 2);
            vec3 rv = c0 + vm.y * c1 + vm.z * c2, rd = c1 + dvm.z * c2;
            P += um[m] * rv;
            Pu += dum[m] * rv;
            Pv += um[m] * rd;
        }
        // conformal: d(u,v)/da = (Re A, Im A), d(u,v)/db = (-Im A, Re A)
        Pa = Pu * Ar + Pv * Ai;
        Pb = Pv * Ar - Pu * Ai;
    }
}

// The blend at the patch's (c,d) (sfb__mf_eval): S (relative to the patch's origin), dS/dc,
// dS/dd, and Tc, Td: positive multiples of dS/dc and dS/dd for the normal's direction, with
// what double precision would keep of them (classes of C-infinity terms below 1e-321 dropped,
// as ref's exp underflows) scaled up to float's range. Corner j sees (a_j, b_j): j = 0 (c, d),
// 1 (d, 1 - c), 2 (1 - c, 1 - d), 3 (1 - d, c); a corner whose weight and weight derivatives
// vanish adds exact zeros (its point is finite there).
void sfb_mf_blend(int p, float c, float d, out vec3 S, out vec3 Sc, out vec3 Sd, out vec3 Tc, out vec3 Td) {
    ivec4 cc = sfb_mf_int(u_patch_base + p);
    float c1 = 1.0 - c, d1 = 1.0 - d;
    bool cinf = u_weights == 1;
    float Lc = 0.0, mc0 = 1.0, mcd = 0.0, Ld = 0.0, md0 = 1.0, mdd = 0.0;
    if (cinf) {
        sfb_mf_cinf_axis(c, c1, Lc, mc0, mcd);
        sfb_mf_cinf_axis(d, d1, Ld, md0, mdd);
    }
    // tangent terms by class kc + 2 kd: the power (0 or 1) of eps_c and of eps_d they carry
    vec3 Vc[4], Vd[4];
    for (int k = 0; k < 4; ++k) { Vc[k] = vec3(0.0); Vd[k] = vec3(0.0); }
    S = vec3(0.0);
    for (int j = 0; j < 4; ++j) {
        // (a, b), their complements, J = (da/dc, da/dd; db/dc, db/dd); the c-axis coordinate of
        // the corner (c or 1 - c, sign sc) and its d-axis one (sd)
        float a, b, ca, cb, vc, vd, sc, sd;
        vec4 J;
        if (j == 0) { a = c; ca = c1; b = d; cb = d1; J = vec4(1.0, 0.0, 0.0, 1.0); vc = c; sc = 1.0; vd = d; sd = 1.0; }
        else if (j == 1) { a = d; ca = d1; b = c1; cb = c; J = vec4(0.0, 1.0, -1.0, 0.0); vc = c1; sc = -1.0; vd = d; sd = 1.0; }
        else if (j == 2) { a = c1; ca = c; b = d1; cb = d; J = vec4(-1.0, 0.0, 0.0, -1.0); vc = c1; sc = -1.0; vd = d1; sd = -1.0; }
        else { a = d1; ca = d; b = c; cb = c1; J = vec4(0.0, -1.0, 1.0, 0.0); vc = c; sc = 1.0; vd = d1; sd = -1.0; }
        vec3 P, Pa, Pb;
        sfb_mf_local(37 * p + 1 + 9 * j, uint(cc[j]), a, b, P, Pa, Pb);
        vec3 Pc = Pa * J.x + Pb * J.z, Pd = Pa * J.y + Pb * J.w;
        // the weight's c-axis factor (mantissa ec, class kc, derivative along c: dc, class 1)
        // and its d-axis factor
        float ec, dc, ed, dd;
        int kc = 0, kd = 0;
        if (cinf) {
            kc = vc > 0.5 ? 1 : 0;
            kd = vd > 0.5 ? 1 : 0;
            ec = mc0; dc = sc * mcd;
            ed = md0; dd = sd * mdd;
            S += ((kc == 1 ? exp(Lc) : 1.0) * ec) * ((kd == 1 ? exp(Ld) : 1.0) * ed) * P;
        } else {
            float t;
            ec = sfb_mf_hermite(vc, vc == c ? c1 : c, t); dc = sc * t;
            ed = sfb_mf_hermite(vd, vd == d ? d1 : d, t); dd = sd * t;
            S += (ec * ed) * P;
        }
        Vc[kc + 2 * kd] += (ec * ed) * Pc;
        Vd[kc + 2 * kd] += (ec * ed) * Pd;
        Vc[(cinf ? 1 : 0) + 2 * kd] += (dc * ed) * P;
        Vd[kc + (cinf ? 2 : 0)] += (ec * dd) * P;
    }
    if (!cinf) {
        Sc = Vc[0]; Sd = Vd[0]; Tc = Sc; Td = Sd;
        return;
    }
    float E[4] = float[4](0.0, Lc, Ld, Lc + Ld);
    float topc = -1e30, topd = -1e30;
    Sc = vec3(0.0); Sd = vec3(0.0); Tc = vec3(0.0); Td = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        float f = exp(E[k]);
        Sc += f * Vc[k];
        Sd += f * Vd[k];
        if (E[k] > -740.0 && Vc[k] != vec3(0.0)) topc = max(topc, E[k]);
        if (E[k] > -740.0 && Vd[k] != vec3(0.0)) topd = max(topd, E[k]);
    }
    for (int k = 0; k < 4; ++k) {
        if (E[k] > -740.0 && Vc[k] != vec3(0.0)) Tc += exp(E[k] - topc) * Vc[k];
        if (E[k] > -740.0 && Vd[k] != vec3(0.0)) Td += exp(E[k] - topd) * Vd[k];
    }
}

// A positive multiple of a x b, on the vectors scaled to a largest component of 1 (no under- or
// overflow), or zero where either vanishes or where |a x b| <= tol |a| |b| (scaled).
vec3 sfb_mf_normal_dir(vec3 a, vec3 b, float tol) {
    float ma = max(max(abs(a.x), abs(a.y)), abs(a.z)), mb = max(max(abs(b.x), abs(b.y)), abs(b.z));
    if (!(ma > 0.0) || !(mb > 0.0) || isinf(ma) || isinf(mb)) return vec3(0.0);
    vec3 x = a / ma, y = b / mb, n = cross(x, y);
    return dot(n, n) > tol * tol * dot(x, x) * dot(y, y) ? n : vec3(0.0);
}

// The unit normal at (c,d) from its tangents there (Tc, Td of sfb_mf_blend), else (degenerate
// tangents) from those 1e-4 inside the face, else 1e-2 inside (sfb__mf_eval_patch), else zero.
// Ref takes the steps where the cross product vanishes exactly: at a point corner, along an
// edge between two points, at a curve corner (whose tangents are multiples of one vector);
// float (with fused multiply-adds) leaves rounding noise of about 1e-7 there, hence the
// threshold 1e-6 on the sine of the tangents' angle. Tangents genuinely that close to parallel
// only occur within about 1e-6 of such a place. The tangents inside are differences of nearly
// equal local geometries, nearly parallel on some meshes: that normal is as ill-conditioned in
// float as the step makes it (tests/gl_manifold.c scales its tolerance by the tangents' angle).
vec3 sfb_mf_normal(int p, float c, float d, vec3 Tc, vec3 Td) {
    vec3 n = sfb_mf_normal_dir(Tc, Td, 1e-6);
    for (int k = 0; k < 2 && n == vec3(0.0); ++k) {
        float h = k == 0 ? 1e-4 : 1e-2;
        vec3 S2, A, B, TA, TB;
        sfb_mf_blend(p, c + (c < 0.5 ? h : -h), d + (d < 0.5 ? h : -h), S2, A, B, TA, TB);
        n = sfb_mf_normal_dir(TA, TB, 1e-6);
    }
    return n == vec3(0.0) ? n : normalize(n);
}

#ifndef SFB_MF_VERTEX
void sfb_store(int base, int slot, vec3 x) {
    if (slot < 0) return;
    int o = base + 3 * slot;
    results[o] = x.x;
    results[o + 1] = x.y;
    results[o + 2] = x.z;
}

void main() {
    int q = int(gl_GlobalInvocationID.x) + u_first;
    if (q >= u_last) return;
    SfbQuery qu = queries[q];
    vec3 S, Sc, Sd, Tc, Td;
    sfb_mf_blend(qu.patch_index, qu.s, qu.t, S, Sc, Sd, Tc, Td);
    vec3 n = u_slot[3] >= 0 ? sfb_mf_normal(qu.patch_index, qu.s, qu.t, Tc, Td) : vec3(0.0);
    int base = q * u_stride;
    sfb_store(base, u_slot[0], S + sfb_mf_texel(37 * qu.patch_index));
    sfb_store(base, u_slot[1], Sc * qu.scale);
    sfb_store(base, u_slot[2], Sd * qu.scale);
    sfb_store(base, u_slot[3], n);
}
#else
uniform mat4 u_mvp;
uniform mat3 u_normal_matrix;
uniform int u_rate;
uniform int u_first_face;

out vec2 v_uv;         // the sample's (u,v) in its parametric face (trimming)
flat out int v_face;   // the parametric face (trimming atlas tile)
out vec3 v_normal;     // u_normal_matrix * the unit normal (lighting)
out vec3 v_cap_pos;    // object-space position and unit normal (transform feedback capture)
out vec3 v_cap_nrm;

void main() {
    int n = u_rate + 1;
    int i = gl_VertexID % n, j = gl_VertexID / n;
    int face = u_first_face + gl_InstanceID;
    float u = float(i) / float(u_rate), v = float(j) / float(u_rate);
    v_uv = vec2(u, v);
    v_face = face;
    // locate (sfb__patch_locate): one patch, or a quadrant's at depth 1
    ivec4 rec = sfb_mf_int(face);
    int p;
    float s = u, t = v;
    if (rec.y == -2) {
        p = rec.x;
    } else {
        float u2 = 2.0 * u, v2 = 2.0 * v;
        int qx = u2 >= 1.0 ? 1 : 0, qy = v2 >= 1.0 ? 1 : 0;
        p = rec[qx + 2 * qy];
        s = u2 - float(qx);
        t = v2 - float(qy);
    }
    if (p < 0) {
        // a hole: every vertex of the face at one point with w = 0, so nothing is drawn
        gl_Position = vec4(0.0);
        v_normal = vec3(0.0);
        v_cap_pos = vec3(0.0);
        v_cap_nrm = vec3(0.0);
        return;
    }
    vec3 S, Sc, Sd, Tc, Td;
    sfb_mf_blend(p, s, t, S, Sc, Sd, Tc, Td);
    vec3 nrm = sfb_mf_normal(p, s, t, Tc, Td);
    vec3 pos = S + sfb_mf_texel(37 * p);
    gl_Position = u_mvp * vec4(pos, 1.0);
    v_normal = u_normal_matrix * nrm;
    v_cap_pos = pos;
    v_cap_nrm = nrm;
}
#endif
