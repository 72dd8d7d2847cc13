// Seed 003's per-pixel analysis values (the backend vtable's shade; the ref kernel, in double,
// is sfb__ref_shade in src/backend_ref.c, whose comment in src/sfb_internal.h is the contract),
// one invocation per pixel, in float:
//   N the unit normal turned toward the viewer (V = eye - P, or -fwd when orthographic),
//   R = 2 (V.N) N - V the reflected view ray;
//   u_mode 0 (REFLECTION) / 1 (HIGHLIGHT): the ray P + mu R (P + mu N) meets the light plane
//     (centre lc, unit normal lm, unit axes lu, lv): mu = ((lc - P).lm) / (dir.lm), a miss when
//     |dir.lm| < 1e-9 or (REFLECTION) mu <= 0; value = ((X - lc).lu / lsize.x + 0.5) periods.x,
//     value2 likewise along lv; REFLECTION misses outside the plane's extent; a miss is NaN;
//   2 (ZEBRA): periods.x acos(R.dir) / pi;   3 (ISOPHOTE), 5, 6: N.dir;
//   4 (CURVATURE): from du, dv (E, F, G) and duu, duv, dvv along N (L, M, N): Gaussian
//     (LN - M^2) / (EG - F^2), mean -(EN - 2FM + GL) / (2 (EG - F^2)) or max |k| =
//     |H| + sqrt(max(H^2 - K, 0)) by u_curvature; NaN where EG - F^2 is not positive.
// Buffers hold one batch of pixels: position[], normal[] and (CURVATURE) du[], dv[], duu[],
// duv[], dvv[] (xyz per pixel); results[] 2 floats per pixel (value, value2).
// The backend prepends "#version 430 core" (desktop) or "#version 310 es" + precision
// (GLES 3.1); the tests validate both with glslangValidator.

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer SfbPos { float pos[]; };
layout(std430, binding = 1) readonly buffer SfbNrm { float nrm[]; };
layout(std430, binding = 2) readonly buffer SfbDu { float du[]; };
layout(std430, binding = 3) readonly buffer SfbDv { float dv[]; };
layout(std430, binding = 4) readonly buffer SfbDuu { float duu[]; };
layout(std430, binding = 5) readonly buffer SfbDuv { float duv[]; };
layout(std430, binding = 6) readonly buffer SfbDvv { float dvv[]; };
layout(std430, binding = 7) writeonly buffer SfbResults { float results[]; };

uniform int u_first;       // first pixel of this dispatch (batch-relative)
uniform int u_last;        // one past the last pixel
uniform int u_mode;        // sfb_analyze_mode
uniform int u_curvature;   // sfb_curvature_kind
uniform int u_ortho;
uniform vec3 u_eye, u_fwd, u_lc, u_lm, u_lu, u_lv, u_dir;
uniform vec4 u_size_periods;  // lsize.x, lsize.y, periods.x, periods.y

vec3 sfb_get(int which, int i) {
    int k = 3 * i;
    if (which == 0) return vec3(pos[k], pos[k + 1], pos[k + 2]);
    if (which == 1) return vec3(nrm[k], nrm[k + 1], nrm[k + 2]);
    if (which == 2) return vec3(du[k], du[k + 1], du[k + 2]);
    if (which == 3) return vec3(dv[k], dv[k + 1], dv[k + 2]);
    if (which == 4) return vec3(duu[k], duu[k + 1], duu[k + 2]);
    if (which == 5) return vec3(duv[k], duv[k + 1], duv[k + 2]);
    return vec3(dvv[k], dvv[k + 1], dvv[k + 2]);
}

float sfb_nan() { return intBitsToFloat(0x7fc00000); }

float sfb_curvature(int i, vec3 n) {
    vec3 pu = sfb_get(2, i), pv = sfb_get(3, i);
    float E = dot(pu, pu), F = dot(pu, pv), G = dot(pv, pv);
    float L = dot(sfb_get(4, i), n), M = dot(sfb_get(5, i), n), N = dot(sfb_get(6, i), n);
    // precise: the differences cancel near flat and parabolic points; as written, as ref's
    SFB_PRECISE float det = E * G - F * F;
    if (!(det > 1e-30 * E * G) || isinf(det) || isnan(det)) return sfb_nan();
    SFB_PRECISE float K = (L * N - M * M) / det;
    SFB_PRECISE float H = -(E * N - 2.0 * F * M + G * L) / (2.0 * det);
    if (u_curvature == 0) return K;
    if (u_curvature == 1) return H;
    return abs(H) + sqrt(max(H * H - K, 0.0));
}

void main() {
    int i = u_first + int(gl_GlobalInvocationID.x);
    if (i >= u_last) return;
    vec3 p = sfb_get(0, i), n = sfb_get(1, i);
    vec3 v = u_ortho != 0 ? -u_fwd : u_eye - p;
    float vl = length(v);
    if (vl > 0.0) v /= vl;
    float vn = dot(v, n);
    if (vn < 0.0) { n = -n; vn = -vn; }
    vec3 r = 2.0 * vn * n - v;
    float val = sfb_nan(), val2 = sfb_nan();
    if (u_mode == 0 || u_mode == 1) {
        vec3 d = u_mode == 0 ? r : n;
        float dm = dot(d, u_lm);
        if (abs(dm) > 1e-9) {
            float mu = dot(u_lc - p, u_lm) / dm;
            if (u_mode == 1 || mu > 0.0) {
                vec3 x = p + mu * d - u_lc;
                float a = (dot(x, u_lu) / u_size_periods.x + 0.5) * u_size_periods.z;
                float b = (dot(x, u_lv) / u_size_periods.y + 0.5) * u_size_periods.w;
                bool inside = u_mode == 1 || (a >= 0.0 && a <= u_size_periods.z && b >= 0.0 && b <= u_size_periods.w);
                if (inside && !isinf(a) && !isinf(b) && !isnan(a) && !isnan(b) && abs(a) < 1e7 && abs(b) < 1e7) { val = a; val2 = b; }
            }
        }
    } else if (u_mode == 2) {
        val = u_size_periods.z * acos(clamp(dot(r, u_dir), -1.0, 1.0)) / 3.14159265358979;
    } else if (u_mode == 4) {
        val = sfb_curvature(i, n);
    } else {
        val = dot(n, u_dir);
    }
    results[2 * i] = val;
    results[2 * i + 1] = val2;
}
