// Seed 003's proxy raster (the `raster` slot, backends/gl/raster.h), vertex stage: corner
// gl_VertexID % 3 of triangle gl_VertexID / 3, read from the triangle texture (no vertex
// attributes), from picture coordinates (x, y in pixels, y down) to clip space with w = 1. GL
// only decides which pixels a triangle covers: the fragment stage computes every value at the
// pixel centre from the triangle's own corners, as ref does, so neither GL's perspective
// correction nor its snapping of corners to the sub-pixel grid (8 bits on NVIDIA) reaches them.
uniform highp sampler2D u_tris; // per triangle u_nt texels (raster.frag.glsl), u_tpr triangles a row
uniform vec2 u_size;            // the picture's width and height
uniform int u_nt;
uniform int u_tpr;
flat out int v_tri;

void main() {
    int t = gl_VertexID / 3, k = gl_VertexID - 3 * t;
    vec4 c = texelFetch(u_tris, ivec2((t % u_tpr) * u_nt + k, t / u_tpr), 0);
    gl_Position = vec4(2.0 * c.x / u_size.x - 1.0, 1.0 - 2.0 * c.y / u_size.y, 0.0, 1.0);
    v_tri = t;
}
