// Seed 001's normal blend (the backend vtable's finish_normals; the ref kernel is
// sfb__ref_finish_normals in src/backend_ref.c), one invocation per element, in float:
//   L = tu x tv, normalised;
//   S = ns[k] normalised where k = ns_index[i] >= 0, else 0;
//   B = (1 - b^p) L + b^p S, normalised, where k >= 0 and b > 0, else B = L;
// and a zero vector stays zero wherever one is normalised.
// Buffers hold one batch of elements (the CPU uploads them from the batch's first element):
//   tu[], tv[]    xyz per element
//   ns[]          xyz of the normals u_ns_base, u_ns_base + 1, ... (the rows the batch reaches)
//   ns_index[]    per element, read only when u_flags & 1 (else k = -1)
//   weights[]     b per element, read only when u_flags & 2 (else no element blends)
//   results[]     u_stride floats per element: B at 0, L at u_limit_slot and S at u_sub_slot
//                 (floats; -1: not asked for)
// b^p: b for p = 1, b * b for p = 2, b * b * b for p = 3, sqrt(b) for p = 0.5, 1 for b = 1 (so
// that b = 1 gives B = S up to the last normalisation), pow(b, p) otherwise.
// A vector is scaled by a power of two (exact) to a largest component in [0.5, 1) before its
// length is taken, so that tiny or huge tangents neither underflow nor overflow dot().
// The backend prepends "#version 430 core" (desktop) or "#version 310 es" + precision
// (GLES 3.1); the tests validate both with glslangValidator.

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer SfbTu { float tu[]; };
layout(std430, binding = 1) readonly buffer SfbTv { float tv[]; };
layout(std430, binding = 2) readonly buffer SfbNs { float ns[]; };
layout(std430, binding = 3) readonly buffer SfbNsIndex { int ns_index[]; };
layout(std430, binding = 4) readonly buffer SfbWeights { float weights[]; };
layout(std430, binding = 5) writeonly buffer SfbResults { float results[]; };

uniform int u_first;       // first element of this dispatch (batch-relative)
uniform int u_last;        // one past the last element
uniform int u_ns_base;     // ns[] starts at this normal
uniform int u_flags;       // 1: ns_index[] bound, 2: weights[] bound
uniform int u_stride;      // floats per element in results[]
uniform int u_limit_slot;  // where L goes in an element's results, or -1
uniform int u_sub_slot;    // where S goes, or -1
uniform float u_p;

// v times a power of two, its largest component then in [0.5, 1) (0 stays 0).
vec3 sfb_scaled(vec3 v) {
    int e;
    frexp(max(max(abs(v.x), abs(v.y)), abs(v.z)), e);
    return ldexp(v, ivec3(-e));
}

vec3 sfb_unit(vec3 v) {
    v = sfb_scaled(v);
    float l2 = dot(v, v);
    return l2 > 0.0 ? v / sqrt(l2) : vec3(0.0);
}

float sfb_bpow(float b) {
    if (b == 1.0 || u_p == 1.0) return b;
    if (u_p == 2.0) return b * b;
    if (u_p == 3.0) return b * b * b;
    if (u_p == 0.5) return sqrt(b);
    return pow(b, u_p);
}

void sfb_put(int at, vec3 v) {
    results[at] = v.x;
    results[at + 1] = v.y;
    results[at + 2] = v.z;
}

void main() {
    int i = int(gl_GlobalInvocationID.x) + u_first;
    if (i >= u_last) return;
    // each tangent scaled on its own first: the cross product's direction is unchanged
    vec3 a = sfb_scaled(vec3(tu[3 * i], tu[3 * i + 1], tu[3 * i + 2]));
    vec3 d = sfb_scaled(vec3(tv[3 * i], tv[3 * i + 1], tv[3 * i + 2]));
    // precise: exactly zero for parallel tangents, as ref (no fused multiply-add)
    SFB_PRECISE vec3 c = vec3(a.y * d.z - a.z * d.y, a.z * d.x - a.x * d.z, a.x * d.y - a.y * d.x);
    vec3 L = sfb_unit(c);
    vec3 S = vec3(0.0);
    vec3 B = L;
    int k = (u_flags & 1) != 0 ? ns_index[i] : -1;
    if (k >= 0) {
        int q = 3 * (k - u_ns_base);
        S = sfb_unit(vec3(ns[q], ns[q + 1], ns[q + 2]));
        float b = (u_flags & 2) != 0 ? weights[i] : 0.0;
        if (b > 0.0) {
            float w = sfb_bpow(b);
            B = sfb_unit((1.0 - w) * L + w * S);
        }
    }
    int o = i * u_stride;
    sfb_put(o, B);
    if (u_limit_slot >= 0) sfb_put(o + u_limit_slot, L);
    if (u_sub_slot >= 0) sfb_put(o + u_sub_slot, S);
}
