/* backends/simd/vtable.h -- the simd backend's table: the patch-table slots, dispatched by the
 * families a table holds, and sfb__simd_bind, one line per kernel family. Part of
 * backends/simd/sfb_simd.h (after the families).
 *
 * The kernel families choose their kernels for the state's instruction set themselves (each
 * family's select, from s->isa, fixed at init); a table goes to the patch family that
 * evaluates the families it holds (sfb__patch_families; a table of a family no entry here
 * evaluates is left to ref: upload leaves its handle NULL). */

/* The patch families, in the order a table is offered to them. */
static const sfb__simd_patch_family *const sfb__simd_patch_families[] = {
    &sfb__simd_manifold_family, /* MANIFOLD4 (manifold.h) */
    &sfb__simd_patches_family,  /* quad and triangle polynomial patches (patches.h) */
};

static const sfb__simd_patch_family *sfb__simd_patch_family_of(const sfb__patch_table *pt) {
    const unsigned families = sfb__patch_families(pt);
    size_t i;
    for (i = 0; i < sizeof sfb__simd_patch_families / sizeof sfb__simd_patch_families[0]; ++i)
        if (families & sfb__simd_patch_families[i]->families) return sfb__simd_patch_families[i];
    return NULL;
}

static sfb_result sfb__simd_upload_patches(void *state, const sfb__patch_table *pt, void **handle) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    const sfb__simd_patch_family *f;
    sfb_result r;
    if (!s || !pt || !handle) return SFB_INVALID_ARGS;
    *handle = NULL;
    if (pt->npatch <= 0 || pt->nptex <= 0 || !pt->point_data) return SFB_SUCCESS; /* nothing to pack: eval goes to ref */
    f = sfb__simd_patch_family_of(pt);
    if (!f) return SFB_SUCCESS;
    r = f->upload(s, pt, handle);
    if (*handle) ((sfb__simd_patches *)*handle)->family = f;
    return r;
}

#ifdef SFB__SIMD_THREADS
/* batches [a, b) of the call (SFB__SIMD_BATCH locations each from its first) */
static void sfb__simd_patch_task(const sfb__simd_state *s, const void *arg, int a, int b) {
    const sfb__simd_pjob *j = (const sfb__simd_pjob *)arg;
    const long long end = (long long)j->first + (long long)b * SFB__SIMD_BATCH;
    (void)s;
    j->range(j, j->first + a * SFB__SIMD_BATCH, end < j->last ? (int)end : j->last);
}
#endif

static sfb_result sfb__simd_eval_patches(void *state, const sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                         int last, const sfb_eval_output *out) {
    sfb__simd_state *s = (sfb__simd_state *)state;
    const sfb__simd_patches *h = (const sfb__simd_patches *)handle;
    sfb__simd_pjob j;
    if (!s || !pt || !locs || !out || first < 0 || first > last) return SFB_INVALID_ARGS;
    if (first == last) return SFB_SUCCESS;
    /* no packed data (not uploaded here, or an empty table): ref evaluates the call */
    if (!h || !h->family || h->npatch != pt->npatch || h->nptex != pt->nptex)
        return sfb__ref_eval_patches(NULL, pt, NULL, locs, first, last, out);
    memset(&j, 0, sizeof j);
    j.pt = pt;
    j.h = h;
    j.locs = locs;
    j.out = out;
    j.second = out->duu || out->duv || out->dvv;
    j.tri = pt->domain == SFB__DOMAIN_TRI;
    j.first = first;
    j.last = last;
    h->family->prepare(s, &j);
#ifdef SFB__SIMD_THREADS
    if (last - first >= SFB__SIMD_INLINE_LOCATIONS &&
        sfb__simd_pool_run(s, sfb__simd_patch_task, &j, 0, (last - first - 1) / SFB__SIMD_BATCH + 1, NULL, 0, 0))
        return SFB_SUCCESS;
#endif
    j.range(&j, first, last);
    return SFB_SUCCESS;
}

static void sfb__simd_patch_tables_bind(sfb__backend_vtable *vt) {
    vt->upload_patches = sfb__simd_upload_patches;
    vt->release_patches = sfb__simd_release_patches;
    vt->eval_patches = sfb__simd_eval_patches;
}

void sfb__simd_bind(sfb__backend_vtable *vt) {
    sfb__simd_runtime_bind(vt);     /* name, kind, init, shutdown, describe (sfb_simd.h) */
    sfb__simd_stencils_bind(vt);    /* eval_stencils (stencils.h) */
    sfb__simd_patch_tables_bind(vt); /* upload/release/eval_patches: the patch families above */
    sfb__simd_normals_bind(vt);     /* finish_normals (normals.h) */
    sfb__simd_shade_bind(vt);       /* shade (shade.h, seed 003) */
    sfb__simd_raster_bind(vt);      /* raster (raster.h, seed 003) */
}
