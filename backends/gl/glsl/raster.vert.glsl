// Seed 003's proxy raster (the `raster` slot, backends/gl/raster.h), vertex stage: a proxy grid
// point from its picture coordinates (x, y in pixels, y down; z the view depth) to clip space,
// with w = z in perspective (so GL's perspective-correct interpolation weighs each corner by
// q = 1 / z, as ref does) and w = 1 when orthographic.
uniform vec2 u_size;       // the picture's width and height
uniform int u_ortho;
layout(location = 0) in vec3 a_xyz;
layout(location = 1) in vec2 a_uv;
layout(location = 2) in int a_face;
layout(location = 3) in vec3 a_pos;
layout(location = 4) in vec3 a_nrm;
out vec2 v_uv;
out float v_z;
flat out int v_face;
out vec3 v_pos;
out vec3 v_nrm;

void main() {
    float w = u_ortho != 0 ? 1.0 : a_xyz.z;
    gl_Position = vec4((2.0 * a_xyz.x / u_size.x - 1.0) * w, (1.0 - 2.0 * a_xyz.y / u_size.y) * w, 0.0, w);
    v_uv = a_uv;
    v_z = a_xyz.z;
    v_face = a_face;
    v_pos = a_pos;
    v_nrm = a_nrm;
}
