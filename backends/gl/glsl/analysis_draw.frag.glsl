// sfb_analysis_draw_gl's fragment stage: the analysis picture (RGBA8, texel row 0 the picture's
// top row, alpha 0 off the surface) stretched over the host's viewport, nearest texel; the
// pixels off the surface are discarded, so the host's framebuffer keeps them.
uniform highp sampler2D u_picture;
uniform vec4 u_viewport;   // x, y, width, height of the host's viewport, in window pixels
uniform ivec2 u_size;      // the picture's width and height
layout(location = 0) out vec4 o_color;

void main() {
    vec2 f = (gl_FragCoord.xy - u_viewport.xy) / u_viewport.zw;  // 0..1 from the viewport's bottom left
    ivec2 t = clamp(ivec2(int(floor(f.x * float(u_size.x))), int(floor((1.0 - f.y) * float(u_size.y)))), ivec2(0), u_size - 1);
    vec4 c = texelFetch(u_picture, t, 0);
    if (c.a < 0.5) discard;
    o_color = vec4(c.rgb, 1.0);
}
