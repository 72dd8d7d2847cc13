/* The schemes at the API edge: what each sfb_scheme is made of -- which rules refine it, which
 * builder writes its patch table, what it supports -- in one table. sfb_surface_create reads
 * the scheme's row here and calls its builders; nothing past the builders asks the scheme again
 * (tables say what they are: docs/ARCHITECTURE.md). A new scheme is its builder's file plus one
 * row below (and its enum value in sfb_api.h). */

/* Patch-table builders of the schemes (the surface's prepared base level, refine options with
 * the scheme's rules, its configuration and base positions). */
static sfb_result sfb__scheme_build_isolated(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt,
                                             const sfb_surface_config *cfg, const float *positions, sfb__patch_table *pt) {
    return sfb__patches_build(ctx, prep, opt, cfg->isolation_level ? cfg->isolation_level : SFB_DEFAULT_ISOLATION, positions, pt);
}

static sfb_result sfb__scheme_build_manifold(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt,
                                             const sfb_surface_config *cfg, const float *positions, sfb__patch_table *pt) {
    (void)opt;
    return sfb__manifold_build(ctx, prep, cfg->manifold.weights, positions, pt);
}

static sfb_result sfb__scheme_build_pn(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt,
                                       const sfb_surface_config *cfg, const float *positions, sfb__patch_table *pt) {
    (void)opt; (void)cfg;
    return sfb__pn_build(ctx, prep, positions, pt);
}

static sfb_result sfb__scheme_build_tribezier(sfb_context *ctx, const sfb__level *prep, const sfb__refine_options *opt,
                                              const sfb_surface_config *cfg, const float *positions, sfb__patch_table *pt) {
    (void)opt;
    return sfb__tribezier_build(ctx, prep, positions, &cfg->tribezier, pt);
}

/* One row per scheme. */
static const sfb__scheme_info sfb__schemes[] = {
    {SFB_SCHEME_CATMARK, "catmark", "Catmull-Clark", SFB_SCHEME_CATMARK,
     SFB__SCHEME_REFINES | SFB__SCHEME_SHADES | SFB__SCHEME_BOUNDARY_HOLES, sfb__scheme_build_isolated},
    {SFB_SCHEME_LOOP, "loop", "Loop", SFB_SCHEME_LOOP,
     SFB__SCHEME_REFINES | SFB__SCHEME_SHADES | SFB__SCHEME_BOUNDARY_HOLES | SFB__SCHEME_TRIANGLES, sfb__scheme_build_isolated},
    {SFB_SCHEME_BILINEAR, "bilinear", "bilinear", SFB_SCHEME_BILINEAR, SFB__SCHEME_REFINES, NULL},
    /* evaluated only: its tables are built at level 0, where Catmull-Clark's rules are the identity */
    {SFB_SCHEME_MANIFOLD_BLEND, "manifold", "manifold blending", SFB_SCHEME_CATMARK, SFB__SCHEME_BOUNDARY_HOLES,
     sfb__scheme_build_manifold},
    /* evaluated only (seed 004): its tables are built at level 0, where Loop's rules are the identity */
    {SFB_SCHEME_TRIBEZIER, "tribezier", "quartic triangular Bezier", SFB_SCHEME_LOOP, SFB__SCHEME_TRIANGLES | SFB__SCHEME_UVS_OR_LINEAR,
     sfb__scheme_build_tribezier},
    /* evaluated only: its tables are built at level 0, where Loop's rules are the identity */
    {SFB_SCHEME_PN, "pn", "PN triangles", SFB_SCHEME_LOOP, SFB__SCHEME_TRIANGLES | SFB__SCHEME_LINEAR_UVS, sfb__scheme_build_pn}
};

const sfb__scheme_info *sfb__scheme_info_of(sfb_scheme s) {
    size_t i;
    for (i = 0; i < sizeof sfb__schemes / sizeof *sfb__schemes; ++i)
        if (sfb__schemes[i].scheme == s) return &sfb__schemes[i];
    return NULL;
}

SFB_API const char *sfb_scheme_name(sfb_scheme s) {
    const sfb__scheme_info *si = sfb__scheme_info_of(s);
    return si ? si->name : "unknown";
}

SFB_API int sfb_scheme_parse(const char *name, sfb_scheme *out) {
    size_t i;
    if (!name || !out) return 0;
    if (strcmp(name, "catmull-clark") == 0) { *out = SFB_SCHEME_CATMARK; return 1; }
    for (i = 0; i < sizeof sfb__schemes / sizeof *sfb__schemes; ++i)
        if (strcmp(name, sfb__schemes[i].name) == 0) { *out = sfb__schemes[i].scheme; return 1; }
    return 0;
}

SFB_API unsigned sfb_scheme_caps(sfb_scheme s) {
    const sfb__scheme_info *si = sfb__scheme_info_of(s);
    if (!si) return 0;
    return (si->caps & (SFB_SCHEME_CAN_REFINE | SFB_SCHEME_CAN_SHADE | SFB_SCHEME_TRIANGLES)) |
           (si->build_patches ? (unsigned)SFB_SCHEME_CAN_EVAL : 0u);
}

/* The names of the schemes that have `cap` (or, cap 0, a patch builder), comma-separated. */
static void sfb__scheme_list(unsigned cap, char *buf, size_t size) {
    size_t i, used = 0;
    buf[0] = 0;
    for (i = 0; i < sizeof sfb__schemes / sizeof *sfb__schemes; ++i) {
        const sfb__scheme_info *si = &sfb__schemes[i];
        if (cap ? !(si->caps & cap) : !si->build_patches) continue;
        used += (size_t)snprintf(buf + used, size - used, "%s%s", used ? ", " : "", si->name);
        if (used >= size) return;
    }
}

/* Refuses a scheme that cannot be built as configured (its kind of surface). */
sfb_result sfb__scheme_check_kind(sfb_context *ctx, const sfb__scheme_info *si, const sfb_surface_config *cfg) {
    if (!si) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "scheme %d is not an sfb_scheme", (int)cfg->scheme);
    if (!(si->caps & SFB__SCHEME_REFINES) && si->build_patches) {
        /* evaluated, not refined (manifold blending) */
        if (!(cfg->flags & SFB_REFINE_PATCHES) || cfg->refine_level != 0 || (cfg->flags & (SFB_REFINE_LIMIT | SFB_REFINE_SHADING)))
            return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                              "scheme '%s' is evaluated, not refined: use refine level 0 with SFB_REFINE_PATCHES (and neither "
                              "SFB_REFINE_LIMIT nor SFB_REFINE_SHADING), then sfb_surface_eval or sfb_surface_tessellate", si->name);
    } else if (!(si->caps & SFB__SCHEME_REFINES)) {
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1, "scheme '%s' cannot be refined uniformly yet", si->name);
    }
    return SFB_SUCCESS;
}

/* Refuses flags the scheme does not support (evaluation, shading). */
sfb_result sfb__scheme_check_flags(sfb_context *ctx, const sfb__scheme_info *si, const sfb_surface_config *cfg) {
    char list[256];
    if ((cfg->flags & SFB_REFINE_PATCHES) && !si->build_patches) {
        sfb__scheme_list(0, list, sizeof list);
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1, "evaluation (SFB_REFINE_PATCHES) is built for %s; scheme '%s' is not supported",
                          list, si->name);
    }
    if ((cfg->flags & SFB_REFINE_SHADING) && !(si->caps & SFB__SCHEME_SHADES)) {
        sfb__scheme_list(SFB__SCHEME_SHADES, list, sizeof list);
        return sfb__error(ctx, SFB_UNSUPPORTED, SFB_ELEMENT_NONE, -1,
                          "subdivision shading (SFB_REFINE_SHADING) is built for %s; scheme '%s' is not supported", list, si->name);
    }
    return SFB_SUCCESS;
}
