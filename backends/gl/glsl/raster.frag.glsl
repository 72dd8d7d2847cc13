// Seed 003's proxy raster, fragment stage: the nearest triangle's (u, v) (clamped to [0, 1]),
// view depth and parametric face (+ 1; 0 is "none") as the bits of an RGBA32UI texel, and its
// interpolated position and normal (the polygon-based method) in two more; the depth test keeps
// the smallest view depth (scaled into [0, 1] by u_zscale), the first of equal ones.
uniform float u_zscale;
in vec2 v_uv;
in float v_z;
flat in int v_face;
in vec3 v_pos;
in vec3 v_nrm;
layout(location = 0) out uvec4 o_hit;
layout(location = 1) out uvec4 o_pos;
layout(location = 2) out uvec4 o_nrm;

void main() {
    vec2 uv = clamp(v_uv, 0.0, 1.0);
    o_hit = uvec4(floatBitsToUint(uv.x), floatBitsToUint(uv.y), floatBitsToUint(v_z), uint(v_face + 1));
    o_pos = uvec4(floatBitsToUint(v_pos), 0u);
    o_nrm = uvec4(floatBitsToUint(v_nrm), 0u);
    gl_FragDepth = clamp(v_z * u_zscale, 0.0, 1.0);
}
