/* The stencil algebra every table builder shares (declared in sfb_internal.h): composed rows
 * of double weights over source vertices (sfb__rows), local masks of (vertex, weight) pairs
 * (sfb__mask), the composition of a mask with its parents' rows through a dense accumulator
 * (sfb__compose_row), and the conversion of rows into a backend's float stencil table
 * (sfb__rows_to_stencils). Refinement (refine.c), shading (shade.c) and manifold blending
 * (manifold.c) build their tables with it; the patch builder (patch/build.c) takes only each
 * step's local masks. */

/* ---- composed rows (double weights) ---- */

void sfb__rows_free(sfb_context *ctx, sfb__rows *r) {
    sfb__free(ctx, r->off); sfb__free(ctx, r->idx); sfb__free(ctx, r->w);
    memset(r, 0, sizeof *r);
}

int sfb__rows_reserve(sfb_context *ctx, sfb__rows *r, size_t need) {
    size_t cap;
    int *ni;
    double *nw;
    if (need <= r->cap) return 1;
    cap = r->cap ? r->cap : 1024;
    while (cap < need) {
        if (cap > ((size_t)-1) / 4) return 0;
        cap = 2 * cap + 16; /* doubling: a table grown row by row is copied at most once over in all */
    }
    ni = (int *)sfb__realloc(ctx, r->idx, cap * sizeof(int));
    if (!ni) return 0;
    r->idx = ni;
    nw = (double *)sfb__realloc(ctx, r->w, cap * sizeof(double));
    if (!nw) return 0;
    r->w = nw;
    r->cap = cap;
    return 1;
}

/* ---- local masks: (parent vertex, weight) pairs, duplicates allowed ---- */


int sfb__mask_grow(sfb_context *ctx, sfb__mask *m, int need) {
    int cap;
    int *ni;
    double *nw;
    if (m->n + need <= m->cap) return 1;
    cap = (m->cap ? m->cap * 2 : 64);
    while (cap < m->n + need) cap *= 2;
    ni = (int *)sfb__realloc(ctx, m->idx, (size_t)cap * sizeof(int));
    if (!ni) return 0;
    m->idx = ni;
    nw = (double *)sfb__realloc(ctx, m->w, (size_t)cap * sizeof(double));
    if (!nw) return 0;
    m->w = nw;
    m->cap = cap;
    return 1;
}


/* Adds w * (face centroid of f). */
void sfb__mask_face(sfb__mask *m, const sfb__level *l, int f, double w) {
    int i, n = l->fv_off[f + 1] - l->fv_off[f];
    for (i = 0; i < n; ++i) SFB__MASK_ADD(m, l->fv[l->fv_off[f] + i], w / n);
}

int sfb__mask_need_vertex(const sfb__level *l, int v) {
    int need = 1 + 2 * (l->ve_off[v + 1] - l->ve_off[v]), i;
    for (i = l->vf_off[v]; i < l->vf_off[v + 1]; ++i) need += l->fv_off[l->vf[i] + 1] - l->fv_off[l->vf[i]];
    return need;
}

/* Composes local masks with the parent's composed rows using a dense accumulator. */


int sfb__compose_row(sfb_context *ctx, sfb__accum *A, const sfb__rows *prow, const sfb__mask *m, sfb__rows *out, int row) {
    int i, nt = 0;
    size_t k;
    A->stamp++;
    if (A->stamp == 0) return 0; /* wrapped: caller resets */
    for (i = 0; i < m->n; ++i) {
        int j = m->idx[i];
        double wj = m->w[i];
        if (wj == 0.0) continue;
        for (k = prow->off[j]; k < prow->off[j + 1]; ++k) {
            int b = prow->idx[k];
            if (A->mark[b] != A->stamp) { A->mark[b] = A->stamp; A->acc[b] = 0.0; A->touched[nt++] = b; }
            A->acc[b] += wj * prow->w[k];
        }
    }
    if (!sfb__rows_reserve(ctx, out, out->n + (size_t)nt)) return 0;
    for (i = 0; i < nt; ++i) {
        int b = A->touched[i];
        if (A->acc[b] == 0.0) continue;
        out->idx[out->n] = b;
        out->w[out->n] = A->acc[b];
        out->n++;
    }
    out->off[row + 1] = out->n;
    return 1;
}

/* Appends local mask m as row `row` of out: what sfb__compose_row gives over identity rows
 * (entries in the order of first use, duplicates summed in mask order, zero weights and zero
 * sums dropped) without an accumulator over the sources. Masks are short: the merge is a
 * linear search. */
int sfb__rows_append_mask(sfb_context *ctx, sfb__rows *out, const sfb__mask *m, int row) {
    const size_t at = out->n;
    size_t k, j;
    int i;
    if (!sfb__rows_reserve(ctx, out, out->n + (size_t)m->n)) return 0;
    for (i = 0; i < m->n; ++i) {
        if (m->w[i] == 0.0) continue;
        for (k = at; k < out->n && out->idx[k] != m->idx[i]; ++k) {}
        if (k < out->n) {
            out->w[k] += m->w[i];
        } else {
            out->idx[out->n] = m->idx[i];
            out->w[out->n] = 0.0 + m->w[i];
            out->n++;
        }
    }
    for (j = k = at; k < out->n; ++k)
        if (out->w[k] != 0.0) { out->idx[j] = out->idx[k]; out->w[j] = out->w[k]; ++j; }
    out->n = j;
    out->off[row + 1] = out->n;
    return 1;
}

void sfb__stencils_free(sfb_context *ctx, sfb__stencils *s) {
    sfb__free(ctx, s->sizes); sfb__free(ctx, s->offsets); sfb__free(ctx, s->indices); sfb__free(ctx, s->weights);
    memset(s, 0, sizeof *s);
}

/* The row index of a stencil table from rows r (rows, sources, entries, sizes, offsets with the
 * end marker); the indices and weights are the caller's. 0 when out of memory (s freed). */
static int sfb__stencils_index(sfb_context *ctx, const sfb__rows *r, int sources, sfb__stencils *s) {
    int i;
    s->rows = r->rows;
    s->sources = sources;
    s->entries = r->n;
    s->sizes = (int *)sfb__alloc(ctx, ((size_t)r->rows + 1) * sizeof(int));
    s->offsets = (int *)sfb__alloc(ctx, ((size_t)r->rows + 1) * sizeof(int));
    if (!s->sizes || !s->offsets) {
        sfb__stencils_free(ctx, s);
        return 0;
    }
    for (i = 0; i < r->rows; ++i) {
        s->offsets[i] = (int)r->off[i];
        s->sizes[i] = (int)(r->off[i + 1] - r->off[i]);
    }
    s->offsets[r->rows] = (int)r->n; /* end marker: offsets[rows] == entries */
    s->sizes[r->rows] = 0;
    return 1;
}

/* sfb__rows_to_stencils for rows the caller frees next: the table takes over their blocks. The
 * indices are the rows' own (an int array either way); the weights are narrowed to float in
 * place, into the first half of the doubles' block (value k goes to bytes [4k, 4k+4), which hold
 * only doubles already read: those below k/2 + 1), through memcpy so that no store can be
 * moved before a load it overlaps; both blocks are then shrunk. Fresh tables of the same size
 * cost page faults and a copy: at catmark_car level 3 these tables are tens of megabytes.
 * On failure r is left as it was. */
sfb_result sfb__rows_move_to_stencils(sfb_context *ctx, sfb__rows *r, int sources, sfb__stencils *s) {
    unsigned char *wb = (unsigned char *)r->w;
    size_t k;
    void *p;
    memset(s, 0, sizeof *s);
    if (r->n > 0x7fffffff)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "stencil table of %zu entries is over the limit", r->n);
    if (!r->idx || !r->w) return sfb__rows_to_stencils(ctx, r, sources, s);
    if (!sfb__stencils_index(ctx, r, sources, s)) return SFB_OUT_OF_MEMORY;
    for (k = 0; k < r->n; ++k) {
        double d;
        float f;
        memcpy(&d, wb + 8 * k, sizeof d);
        f = (float)d;
        memcpy(wb + 4 * k, &f, sizeof f);
    }
    p = sfb__realloc(ctx, r->w, (r->n + 1) * sizeof(float));
    s->weights = p ? (float *)p : (float *)(void *)r->w;
    p = sfb__realloc(ctx, r->idx, (r->n + 1) * sizeof(int));
    s->indices = p ? (int *)p : r->idx;
    r->w = NULL;
    r->idx = NULL;
    r->n = r->cap = 0;
    return SFB_SUCCESS;
}

sfb_result sfb__rows_to_stencils(sfb_context *ctx, const sfb__rows *r, int sources, sfb__stencils *s) {
    size_t k;
    memset(s, 0, sizeof *s);
    if (r->n > 0x7fffffff)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "stencil table of %zu entries is over the limit", r->n);
    if (!sfb__stencils_index(ctx, r, sources, s)) return SFB_OUT_OF_MEMORY;
    s->indices = (int *)sfb__alloc(ctx, (r->n + 1) * sizeof(int));
    s->weights = (float *)sfb__alloc(ctx, (r->n + 1) * sizeof(float));
    if (!s->indices || !s->weights) {
        sfb__stencils_free(ctx, s);
        return SFB_OUT_OF_MEMORY;
    }
    if (r->n) memcpy(s->indices, r->idx, r->n * sizeof(int));
    for (k = 0; k < r->n; ++k) s->weights[k] = (float)r->w[k];
    return SFB_SUCCESS;
}
