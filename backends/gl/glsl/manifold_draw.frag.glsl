// The fragment program of sfb_surface_draw_gl (seed 000 section V.5): two-sided lighting of the
// manifold surface drawn by manifold.comp.glsl's vertex stage, and trimming: with u_trim_on the
// mask in u_trim's red channel is read at the face's (u,v) as sfb_trim_mask says (and as the
// tessellator reads it, src/tess.c sfb__trim_value): the bilinear interpolation of the texel
// centres of the face's tile, clamped at the tile's borders, fetched texel by texel (no
// filtering across tiles); the fragment is discarded where the value is below 0.5. Atlas:
// u_tiles tiles (0 x 0 or 1 x 1: one mask for every face), tile t for parametric face t, faces
// past the last tile untrimmed.
// The backend prepends "#version 430 core" (desktop) or "#version 310 es" + precision (GLES 3.1);
// the tests validate both with glslangValidator.

#ifdef GL_ES
precision highp sampler2D;
#endif

in vec2 v_uv;
flat in int v_face;
in vec3 v_normal;

uniform sampler2D u_trim;
uniform int u_trim_on;
uniform ivec2 u_tiles;
uniform vec3 u_light;   // toward the light, unit
uniform vec4 u_color;

out vec4 o_color;

float sfb_trim_value(vec2 uv) {
    ivec2 tiles = max(u_tiles, ivec2(1));
    int nt = tiles.x * tiles.y, tile = 0;
    if (nt > 1) {
        if (v_face >= nt) return 1.0;
        tile = v_face;
    }
    ivec2 tsz = textureSize(u_trim, 0) / tiles;
    ivec2 org = ivec2(tile % tiles.x, tile / tiles.x) * tsz;
    float x = clamp(uv.x * float(tsz.x) - 0.5, 0.0, float(tsz.x - 1));
    float y = clamp(uv.y * float(tsz.y) - 0.5, 0.0, float(tsz.y - 1));
    int i0 = min(int(x), max(tsz.x - 2, 0)), j0 = min(int(y), max(tsz.y - 2, 0));
    float fx = x - float(i0), fy = y - float(j0);
    int i1 = tsz.x > 1 ? i0 + 1 : i0, j1 = tsz.y > 1 ? j0 + 1 : j0;
    float t00 = texelFetch(u_trim, org + ivec2(i0, j0), 0).r, t10 = texelFetch(u_trim, org + ivec2(i1, j0), 0).r;
    float t01 = texelFetch(u_trim, org + ivec2(i0, j1), 0).r, t11 = texelFetch(u_trim, org + ivec2(i1, j1), 0).r;
    return (1.0 - fy) * ((1.0 - fx) * t00 + fx * t10) + fy * ((1.0 - fx) * t01 + fx * t11);
}

void main() {
    if (u_trim_on != 0 && sfb_trim_value(v_uv) < 0.5) discard;
    float l = length(v_normal);
    float diffuse = l > 0.0 ? abs(dot(v_normal / l, u_light)) : 0.0;
    o_color = vec4(u_color.rgb * (0.2 + 0.8 * diffuse), u_color.a);
}
