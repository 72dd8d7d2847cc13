/* backends/gl/vtable.h -- the backend's table: the patch-table slots, and sfb__gl_bind with the
 * kernels osmesa shares.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. */
#ifndef SFB__GL_VTABLE_H
#define SFB__GL_VTABLE_H


static sfb_result sfb__gl_upload_patches(void *state, const sfb__patch_table *pt, void **handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved s;
    sfb__gl_ptable *tab = NULL;
    sfb_result r;
    *handle = NULL;
    if ((r = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return r;
    if (sfb__patch_families(pt) & (1u << SFB__FAMILY_MANIFOLD)) r = sfb__gl_mf_upload_current(g, pt, &tab);
    else r = sfb__gl_patches_upload_current(g, pt, &tab);
    sfb__gl_leave(g, &s);
    *handle = tab;
    return r;
}

static void sfb__gl_release_patches(void *state, void *handle) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_saved s;
    if (!handle) return;
    if (sfb__gl_enter(g, &s) == SFB_SUCCESS) {
        sfb__gl_ptable_free(g, (sfb__gl_ptable *)handle);
        sfb__gl_leave(g, &s);
    } else {
        sfb__free(g->ctx, ((sfb__gl_ptable *)handle)->pieces);
        sfb__free(g->ctx, handle);
    }
}


/* The kernels gl and osmesa share (osmesa binds these, then its own init and no host buffers). */
static void sfb__gl_bind_kernels(sfb__backend_vtable *vt) {
    vt->shutdown = sfb__gl_shutdown;
    vt->describe = sfb__gl_describe;
    vt->upload_stencils = sfb__gl_upload;
    vt->release_stencils = sfb__gl_release;
    vt->eval_stencils = sfb__gl_eval;
    vt->upload_patches = sfb__gl_upload_patches;
    vt->release_patches = sfb__gl_release_patches;
    vt->eval_patches = sfb__gl_eval_patches;
    vt->finish_normals = sfb__gl_finish_normals;
}

void sfb__gl_bind(sfb__backend_vtable *vt) {
    vt->name = "gl";
    vt->kind = SFB_BACKEND_GL;
    vt->init = sfb__gl_init;
    sfb__gl_bind_kernels(vt);
    vt->eval_stencils_gl = sfb__gl_eval_buffers;
}

#endif /* SFB__GL_VTABLE_H */
