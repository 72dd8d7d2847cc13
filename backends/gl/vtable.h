/* backends/gl/vtable.h -- the backend's table: the patch-table slots, and sfb__gl_bind with the
 * kernels osmesa shares.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. */
#ifndef SFB__GL_VTABLE_H
#define SFB__GL_VTABLE_H

/* What a family's kernels do with a patch table, the context current (eval enters by itself). */
typedef struct sfb__gl_family {
    sfb_result (*upload)(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable **out);
    void (*free)(sfb__gl *g, sfb__gl_ptable *tab);
    sfb_result (*eval)(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable *tab, const sfb_location *locs, int first, int last,
                       const sfb_eval_output *out);
} sfb__gl_family;

/* Per SFB__FAMILY_*, in that order: the quad and triangle families share one kernel (its
 * variant chosen by the table's domain), MANIFOLD4 has its own. */
static const sfb__gl_family sfb__gl_families[SFB__FAMILY_COUNT] = {
    {sfb__gl_patches_upload_current, sfb__gl_patches_free, sfb__gl_patches_eval}, /* SFB__FAMILY_QUAD */
    {sfb__gl_patches_upload_current, sfb__gl_patches_free, sfb__gl_patches_eval}, /* SFB__FAMILY_TRI */
    {sfb__gl_mf_upload_current, sfb__gl_mf_free, sfb__gl_mf_eval}                 /* SFB__FAMILY_MANIFOLD */
};

/* The family whose kernel evaluates a table: MANIFOLD4 patches make it a manifold table; else
 * the polynomial family it holds (an empty table: the one of its domain). */
static int sfb__gl_family_of(const sfb__patch_table *pt) {
    unsigned m = sfb__patch_families(pt);
    if (m & (1u << SFB__FAMILY_MANIFOLD)) return SFB__FAMILY_MANIFOLD;
    if (m & (1u << SFB__FAMILY_TRI)) return SFB__FAMILY_TRI;
    if (m & (1u << SFB__FAMILY_QUAD)) return SFB__FAMILY_QUAD;
    return pt->domain == SFB__DOMAIN_TRI ? SFB__FAMILY_TRI : SFB__FAMILY_QUAD;
}

static sfb_result sfb__gl_upload_patches(void *state, const sfb__patch_table *pt, void **handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved s;
    sfb__gl_ptable *tab = NULL;
    sfb_result r;
    *handle = NULL;
    if ((r = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return r;
    r = sfb__gl_families[sfb__gl_family_of(pt)].upload(g, pt, &tab);
    sfb__gl_leave(g, &s);
    *handle = tab;
    return r;
}

static void sfb__gl_release_patches(void *state, void *handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_ptable *tab = (sfb__gl_ptable *)handle;
    sfb__gl_saved s;
    if (!tab) return;
    if (sfb__gl_enter(g, &s) == SFB_SUCCESS) {
        sfb__gl_families[tab->family].free(g, tab);
        sfb__gl_leave(g, &s);
    } else {
        sfb__free(g->ctx, tab->pieces);
        sfb__free(g->ctx, tab);
    }
}

/* `handle` is this backend's upload of the table, or NULL (uploaded elsewhere): the family's
 * kernel then makes a temporary one. */
static sfb_result sfb__gl_eval_patches(void *state, const sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                       int last, const sfb_eval_output *out) {
    return sfb__gl_families[sfb__gl_family_of(pt)].eval((sfb__gl *)state, pt, (sfb__gl_ptable *)handle, locs, first, last, out);
}

/* The kernels gl and osmesa share (osmesa binds these, then its own init and no host buffers):
 * one line per kernel family. */
static void sfb__gl_bind_kernels(sfb__backend_vtable *vt) {
    vt->shutdown = sfb__gl_shutdown;
    vt->describe = sfb__gl_describe;
    sfb__gl_stencils_bind(vt);
    sfb__gl_patches_bind(vt);
    sfb__gl_manifold_bind(vt);
    sfb__gl_normals_bind(vt);
    sfb__gl_shade_bind(vt);
    sfb__gl_raster_bind(vt);
    vt->parallel = sfb__gl_parallel; /* not a kernel: the CPU threads lent to the core */
}

void sfb__gl_bind(sfb__backend_vtable *vt) {
    vt->name = "gl";
    vt->kind = SFB_BACKEND_GL;
    vt->init = sfb__gl_init;
    sfb__gl_bind_kernels(vt);
    vt->eval_stencils_gl = sfb__gl_eval_buffers; /* the host's buffers: gl on the host's context only */
}

#endif /* SFB__GL_VTABLE_H */
