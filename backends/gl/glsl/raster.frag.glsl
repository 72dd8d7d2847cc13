// Seed 003's proxy raster, fragment stage: the triangle's barycentric coordinates at the pixel
// centre from its corners (sfb__raster_range's edge functions, relative to a corner, in float),
// weighted by q = 1 / view depth in perspective (b_k q_k / sum b q), and from them the view depth
// (1 / sum b q; sum b z when orthographic), (u, v) clamped to [0, 1], and with u_polygon the
// interpolated position and normal (the polygon-based method). Written: the (u, v, depth,
// parametric face + 1) bits as an RGBA32UI texel, the position and normal in two more; the depth
// test keeps the smallest view depth (scaled into [0, 1] by u_zscale), the first of equal ones.
// A triangle's texels: 0-2 its corners (x, y, q, z), 3 (u0, v0, u1, v1), 4 (u2, v2, face, 0),
// then with u_polygon 5-7 the corners' positions and 8-10 their normals (xyz).
uniform highp sampler2D u_tris;
uniform vec2 u_size;
uniform int u_nt;
uniform int u_tpr;
uniform int u_ortho;
uniform int u_polygon;
uniform float u_zscale;
flat in int v_tri;
layout(location = 0) out uvec4 o_hit;
layout(location = 1) out uvec4 o_pos;
layout(location = 2) out uvec4 o_nrm;

vec4 sfb_tri(int k) { return texelFetch(u_tris, ivec2((v_tri % u_tpr) * u_nt + k, v_tri / u_tpr), 0); }

void main() {
    vec4 A = sfb_tri(0), B = sfb_tri(1), C = sfb_tri(2);
    vec2 p = vec2(gl_FragCoord.x, u_size.y - gl_FragCoord.y); // the pixel centre, y down
    float area = (B.x - A.x) * (C.y - A.y) - (C.x - A.x) * (B.y - A.y);
    vec3 b = vec3((C.x - B.x) * (p.y - B.y) - (C.y - B.y) * (p.x - B.x),
                  (A.x - C.x) * (p.y - C.y) - (A.y - C.y) * (p.x - C.x),
                  (B.x - A.x) * (p.y - A.y) - (B.y - A.y) * (p.x - A.x)) / area;
    vec3 q = vec3(A.z, B.z, C.z);
    float den = dot(b, q);
    if (!(den > 0.0) || isinf(den)) discard; // as ref: no depth there
    float inv = 1.0 / den;
    float z = u_ortho != 0 ? dot(b, vec3(A.w, B.w, C.w)) : inv;
    vec3 w = b * q * inv;
    vec4 U = sfb_tri(3), V = sfb_tri(4);
    vec2 uv = clamp(vec2(dot(w, vec3(U.x, U.z, V.x)), dot(w, vec3(U.y, U.w, V.y))), 0.0, 1.0);
    o_hit = uvec4(floatBitsToUint(uv.x), floatBitsToUint(uv.y), floatBitsToUint(z), uint(int(V.z) + 1));
    vec3 pos = vec3(0.0), nrm = vec3(0.0);
    if (u_polygon != 0) {
        pos = w.x * sfb_tri(5).xyz + w.y * sfb_tri(6).xyz + w.z * sfb_tri(7).xyz;
        nrm = w.x * sfb_tri(8).xyz + w.y * sfb_tri(9).xyz + w.z * sfb_tri(10).xyz;
    }
    o_pos = uvec4(floatBitsToUint(pos), 0u);
    o_nrm = uvec4(floatBitsToUint(nrm), 0u);
    gl_FragDepth = clamp(z * u_zscale, 0.0, 1.0);
}
