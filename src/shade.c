/* Subdivision shading (seed 001): subdivided normals N_S with crease regions, blend weights b
 * (variants A/B, darts smooth/sharp, semi-sharp re-seeding) and the blended normals
 * N_B = normalize((1 - b^p) N_L + b^p N_S). */

SFB_API sfb_shade_params sfb_shade_params_init(void) {
    sfb_shade_params p;
    memset(&p, 0, sizeof p);
    p.p = 1.0f;
    return p;
}

SFB_API sfb_result sfb_surface_shade(const sfb_surface *s, const sfb_shade_params *params, sfb_mesh_data *out) {
    (void)params;
    if (out) memset(out, 0, sizeof *out);
    if (!s) return SFB_INVALID_ARGS;
    return sfb__error(s->ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1, "sfb_surface_shade: not built yet");
}

SFB_API sfb_result sfb_surface_shade_info(const sfb_surface *s, sfb_shade_info *out) {
    if (out) memset(out, 0, sizeof *out);
    if (!s) return SFB_INVALID_ARGS;
    return sfb__error(s->ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1, "sfb_surface_shade_info: not built yet");
}
