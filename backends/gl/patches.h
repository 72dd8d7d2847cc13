/* backends/gl/patches.h -- polynomial patch tables, the quad family (B-spline, Stam, end caps)
 * and the triangle family (Bezier triangles, Stam-Loop, end caps): one source,
 * patches.comp.glsl, compiled once per family with the other family left out.
 *
 * Part of the gl backend (backends/sfb_gl.h includes the parts in order); do not include it
 * directly. */
#ifndef SFB__GL_PATCHES_H
#define SFB__GL_PATCHES_H

/* The kernel source: a build-time override, used by tests/gl_errors.c to exercise the failure
 * paths for real. */
#ifndef SFB__GL_PATCH_SOURCE
#define SFB__GL_PATCH_SOURCE sfb__glsl_patches_comp_glsl
#endif

/* One piece of an uploaded patch table (sfb__gl_ptable): patches [patch0, patch1) with the
 * control points and eigen blocks they use, copied and renumbered so that each of its four
 * arrays fits one shader storage block (GL_MAX_SHADER_STORAGE_BLOCK_SIZE: at least 128 MiB on
 * real drivers, so one piece in practice; the tests shrink it to force several). */
struct sfb__gl_ppiece {
    int patch0, patch1;
    sfb__GLuint buf[4]; /* patch records (ivec4), cvs (piece-local rows), points (vec4), eigen blocks (vec4) */
};

/* Patch kinds as the shader numbers them (patches.comp.glsl), independent of the core's. */
enum { SFB__GL_KIND_BSPLINE = 0, SFB__GL_KIND_STAM = 1, SFB__GL_KIND_ENDCAP = 2, SFB__GL_KIND_BEZTRI = 3,
       SFB__GL_KIND_STAM_LOOP = 4, SFB__GL_KIND_ENDCAP_TRI = 5 };
enum { SFB__GL_OUTPUTS = 7 };  /* position, du, dv, normal, duu, duv, dvv */
/* Sort keys of the queries within a piece: B-spline or Bezier triangle, end cap (quad or
 * triangle), then Stam or Stam-Loop by valence (a table holds one family's kinds only). */
enum { SFB__GL_BUCKETS = SFB__STAM_MAX_VALENCE + 3 };
static const char *const sfb__gl_patch_uniforms[5] = {"u_first", "u_last", "u_stride", "u_slot", "u_second"};

/* Floats of one valence's eigen block, as vec4s (patches.comp.glsl): header (K, dominant, sub,
 * 0), per eigenvalue (lambda, lambda/sub, at-EV tangent mask, 0), and phi (3 sub-patches x K x
 * the 4 rows of the 4x4 B-spline coefficients), so that the kernel reads whole vec4s. The Loop
 * block (sfb__gl_eigl_pack) has the same size: its phi are 15 Bezier coefficients and a 0. */
static size_t sfb__gl_eig_floats(int K) { return 4 * (1 + 13 * (size_t)K); }

static void sfb__gl_eig_pack(const sfb__eigen_cc *e, float *o) {
    int K = e->K, i, k, j;
    float *phi = o + 4 * (1 + (size_t)K);
    /* K and the dominant index stay small integers: exact as floats */
    o[0] = (float)K; o[1] = (float)e->dominant; o[2] = (float)e->sub; o[3] = 0.0f;
    for (i = 0; i < K; ++i) {
        double l = e->lambda[i];
        float *h = o + 4 * (1 + (size_t)i);
        h[0] = (float)l;
        /* the ratio is formed in double so that the subdominant ones round to exactly +-1 */
        h[1] = i == e->dominant ? 0.0f : (float)(l / e->sub);
        /* as sfb__eval_stam at the EV: the eigenvectors that survive the normalisation */
        h[2] = (i != e->dominant && fabs(fabs(l) - e->sub) <= 1e-12) ? 1.0f : 0.0f;
        h[3] = 0.0f;
    }
    /* e->phi[((k-1)*16 + j)*K + i] -> phi[((k-1)*K + i)*16 + j]: one coefficient's 16 together */
    for (k = 0; k < 3; ++k)
        for (i = 0; i < K; ++i)
            for (j = 0; j < 16; ++j)
                phi[((size_t)k * K + i) * 16 + j] = (float)e->phi[((size_t)k * 16 + j) * K + i];
}

/* The Stam-Loop block: header (K, dominant, sub, 0), per eigenvalue (lambda, lambda/sub (0 for
 * the dominant), at-EV tangent mask, index of its Jordan head or -1), then per sub-patch
 * k = 0..2 and eigenvalue i the 15 Bezier coefficients of Phi_k[.][i] and a 0. */
static void sfb__gl_eigl_pack(const sfb__eigen_loop *e, float *o) {
    int K = e->K, i, k, j;
    float *phi = o + 4 * (1 + (size_t)K);
    o[0] = (float)K; o[1] = (float)e->dominant; o[2] = (float)e->sub; o[3] = 0.0f;
    for (i = 0; i < K; ++i) {
        double l = e->lambda[i];
        float *h = o + 4 * (1 + (size_t)i);
        h[0] = (float)l;
        h[1] = i == e->dominant ? 0.0f : (float)(l / e->sub);
        /* as sfb__eval_stam_loop at the EV */
        h[2] = (i != e->dominant && fabs(l - e->sub) <= 1e-12) ? 1.0f : 0.0f;
        h[3] = e->head[i] >= 0 ? (float)e->head[i] : -1.0f;
    }
    /* e->phi[(k*15 + j)*K + i] -> phi[(k*K + i)*16 + j] */
    for (k = 0; k < 3; ++k)
        for (i = 0; i < K; ++i) {
            for (j = 0; j < 15; ++j) phi[((size_t)k * K + i) * 16 + j] = (float)e->phi[((size_t)k * 15 + j) * K + i];
            phi[((size_t)k * K + i) * 16 + 15] = 0.0f;
        }
}

static void sfb__gl_patches_free(sfb__gl *g, sfb__gl_ptable *t) {
    int i;
    if (!t) return;
    for (i = 0; i < t->count; ++i) g->gl.DeleteBuffers(4, t->pieces[i].buf);
    sfb__free(g->ctx, t->pieces);
    sfb__free(g->ctx, t);
}

/* A patch table's upload in progress: the arrays of the piece being filled, and the stamps
 * that tell a point or an eigen block already in it. */
typedef struct sfb__gl_pbuild {
    const char *who;
    size_t cap_rec, cap_cv, cap_pts, cap_eig;  /* what one storage block holds of each array */
    int stamp_id;                              /* the piece being filled */
    /* per eigen block: Catmull-Clark valence N at N, Loop at SFB__STAM_MAX_VALENCE + 1 + N */
    int eig_stamp[2 * (SFB__STAM_MAX_VALENCE + 1)];
    size_t eig_at[2 * (SFB__STAM_MAX_VALENCE + 1)];
    int *stamp, *local, *rec, *cvl;            /* per point: piece stamp, piece-local row */
    float *pts, *eig;
    size_t nrec, ncv, npts, neig;              /* the piece's arrays so far */
} sfb__gl_pbuild;

static sfb_result sfb__gl_pbuild_init(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_pbuild *b) {
    size_t eig_total = 0, max_pts;
    int rows = pt->npoints, N, p;
    memset(b, 0, sizeof *b);
    b->who = g->mode == SFB__GL_OSMESA ? "osmesa" : "gl";
    b->cap_rec = (size_t)g->max_block / 16;
    b->cap_cv = (size_t)g->max_block / 4;
    b->cap_pts = (size_t)g->max_block / 16;
    b->cap_eig = (size_t)g->max_block / 4;
    for (N = 0; N < 2 * (SFB__STAM_MAX_VALENCE + 1); ++N) {
        b->eig_stamp[N] = -1;
        b->eig_at[N] = 0;
    }
    for (N = 0; N <= SFB__STAM_MAX_VALENCE; ++N) {
        if (pt->eig[N]) eig_total += sfb__gl_eig_floats(pt->eig[N]->K);
        if (pt->eigl[N]) eig_total += sfb__gl_eig_floats(pt->eigl[N]->K);
    }
    max_pts = (size_t)pt->ncv < (size_t)rows ? (size_t)pt->ncv : (size_t)rows;
    b->stamp = (int *)sfb__alloc(g->ctx, ((size_t)rows + 1) * sizeof(int));
    b->local = (int *)sfb__alloc(g->ctx, ((size_t)rows + 1) * sizeof(int));
    b->rec = (int *)sfb__alloc(g->ctx, ((size_t)pt->npatch + 1) * 4 * sizeof(int));
    b->cvl = (int *)sfb__alloc(g->ctx, ((size_t)pt->ncv + 1) * sizeof(int));
    b->pts = (float *)sfb__alloc(g->ctx, (max_pts + 1) * 4 * sizeof(float));
    b->eig = (float *)sfb__alloc(g->ctx, (eig_total + 4) * sizeof(float));
    if (!b->stamp || !b->local || !b->rec || !b->cvl || !b->pts || !b->eig) return sfb__oom(g->ctx, "gl patch table");
    for (p = 0; p < rows; ++p) b->stamp[p] = -1;
    return SFB_SUCCESS;
}

static void sfb__gl_pbuild_free(sfb__gl *g, sfb__gl_pbuild *b) {
    sfb__free(g->ctx, b->stamp); sfb__free(g->ctx, b->local); sfb__free(g->ctx, b->rec); sfb__free(g->ctx, b->cvl);
    sfb__free(g->ctx, b->pts); sfb__free(g->ctx, b->eig);
}

/* Patch p as the kernel reads it: its kind (SFB__GL_KIND_*, -1 for none), whether its point
 * count is right, its eigen structure and block slot (Stam, Stam-Loop) and, for end caps,
 * where its tangents start (eoff). */
static int sfb__gl_patch_kind(const sfb__patch_table *pt, int p, int *fits, const sfb__eigen_cc **e, const sfb__eigen_loop **el,
                              int *slot, int *eK, int *eoff) {
    int n = pt->pfirst[p + 1] - pt->pfirst[p], N;
    *e = NULL; *el = NULL; *slot = -1; *eK = 0; *eoff = -1;
    switch (pt->ptype[p]) {
    case SFB__PATCH_BSPLINE: *fits = n == 16; return SFB__GL_KIND_BSPLINE;
    /* 4 corner positions, or those and each corner's two limit tangents (normals) */
    case SFB__PATCH_ENDCAP: *fits = n == 4 || n == 12; *eoff = n; return SFB__GL_KIND_ENDCAP;
    case SFB__PATCH_STAM:
        N = pt->pvalence[p];
        *e = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eig[N] : NULL;
        *fits = *e && n == (*e)->K;
        if (*e) { *slot = N; *eK = (*e)->K; }
        return SFB__GL_KIND_STAM;
    case SFB__PATCH_BEZTRI: *fits = n == 15; return SFB__GL_KIND_BEZTRI;
    /* 3 corner positions and each corner's two limit tangents */
    case SFB__PATCH_ENDCAP_TRI: *fits = n == 9; *eoff = n; return SFB__GL_KIND_ENDCAP_TRI;
    case SFB__PATCH_STAM_LOOP:
        N = pt->pvalence[p];
        *el = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eigl[N] : NULL;
        *fits = *el && n == (*el)->K;
        if (*el) { *slot = SFB__STAM_MAX_VALENCE + 1 + N; *eK = (*el)->K; }
        return SFB__GL_KIND_STAM_LOOP;
    default: *fits = 0; return -1;
    }
}

/* Adds patch p to the piece being filled: *added = 0 when the piece is full (p starts the
 * next one), an error when p is malformed or fits no piece at all. */
static sfb_result sfb__gl_pbuild_add(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_pbuild *b, int p, int *added) {
    int first = pt->pfirst[p], n = pt->pfirst[p + 1] - first, rows = pt->npoints, kind, eoff, fits, slot, eK, k;
    size_t npts0 = b->npts, neig0 = b->neig;
    const sfb__eigen_cc *e;
    const sfb__eigen_loop *el;
    *added = 0;
    kind = sfb__gl_patch_kind(pt, p, &fits, &e, &el, &slot, &eK, &eoff);
    if (!fits)
        return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: patch %d (type %d, %d points) is malformed", b->who, p,
                          pt->ptype[p], n);
    /* its points, new to this piece */
    for (k = 0; k < n; ++k) {
        int row = pt->cv[first + k];
        if (row < 0 || row >= rows)
            return sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: patch %d reads point %d of %d", b->who, p, row, rows);
        if (b->stamp[row] != b->stamp_id) {
            b->stamp[row] = b->stamp_id;
            b->local[row] = (int)b->npts;
            memcpy(b->pts + 4 * b->npts, pt->point_data + 3 * (size_t)row, 3 * sizeof(float));
            b->pts[4 * b->npts + 3] = 0.0f;
            ++b->npts;
        }
        b->cvl[b->ncv + (size_t)k] = b->local[row];
    }
    if (slot >= 0) {
        if (b->eig_stamp[slot] != b->stamp_id) {
            b->eig_stamp[slot] = b->stamp_id;
            b->eig_at[slot] = b->neig / 4; /* in vec4s */
            if (e) sfb__gl_eig_pack(e, b->eig + b->neig);
            else sfb__gl_eigl_pack(el, b->eig + b->neig);
            b->neig += sfb__gl_eig_floats(eK);
        }
        eoff = (int)b->eig_at[slot];
    }
    if (b->nrec + 1 > b->cap_rec || b->ncv + (size_t)n > b->cap_cv || b->npts > b->cap_pts || b->neig > b->cap_eig) {
        if (b->nrec == 0)
            return sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                              "%s: patch %d (%d points%s) needs more than one shader storage block holds (%d bytes)", b->who, p, n,
                              e ? ", Stam eigen data" : el ? ", Stam-Loop eigen data" : "", (int)g->max_block);
        /* this patch starts the next piece: drop what it added here (the stamps of this piece
         * are not looked at again) */
        b->npts = npts0;
        b->neig = neig0;
        return SFB_SUCCESS;
    }
    b->rec[4 * b->nrec] = kind;
    b->rec[4 * b->nrec + 1] = (int)b->ncv;
    b->rec[4 * b->nrec + 2] = SFB__PARAM_CORNER(pt->pparam[p]);
    b->rec[4 * b->nrec + 3] = eoff;
    ++b->nrec;
    b->ncv += (size_t)n;
    *added = 1;
    return SFB_SUCCESS;
}

/* Stores the filled piece, patches [p0, p1), as the table's next one (four storage buffers). */
static sfb_result sfb__gl_pbuild_store(sfb__gl *g, const sfb__gl_pbuild *b, sfb__gl_ptable *tab, int *allocated, int p0, int p1) {
    struct sfb__gl_ppiece *piece;
    if (tab->count == *allocated) {
        int na = *allocated ? *allocated * 2 : 4;
        struct sfb__gl_ppiece *np = (struct sfb__gl_ppiece *)sfb__realloc(g->ctx, tab->pieces, (size_t)na * sizeof *np);
        if (!np) return sfb__oom(g->ctx, "gl patch table");
        tab->pieces = np;
        *allocated = na;
    }
    piece = &tab->pieces[tab->count];
    memset(piece, 0, sizeof *piece);
    piece->patch0 = p0;
    piece->patch1 = p1;
    g->gl.GenBuffers(4, piece->buf);
    ++tab->count;
    /* a zero-length storage buffer cannot be bound: keep at least one element */
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[0]);
    g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(b->nrec * 16), b->rec, SFB__GL_STATIC_DRAW);
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[1]);
    g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)((b->ncv ? b->ncv : 1) * 4), b->cvl, SFB__GL_STATIC_DRAW);
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[2]);
    g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)((b->npts ? b->npts : 1) * 16), b->pts, SFB__GL_STATIC_DRAW);
    g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[3]);
    g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)((b->neig ? b->neig : 4) * 4), b->eig, SFB__GL_STATIC_DRAW);
    return sfb__gl_check(g, "uploading a patch table");
}

/* Uploads a patch table with the context current. Pieces are built greedily, patch after
 * patch; a point or an eigen block shared by patches of one piece is stored once in it. */
static sfb_result sfb__gl_patches_upload_current(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable **out) {
    sfb__gl_pbuild b;
    sfb__gl_ptable *tab = (sfb__gl_ptable *)sfb__calloc(g->ctx, 1, sizeof *tab);
    int p = 0, allocated = 0;
    sfb_result res = sfb__gl_pbuild_init(g, pt, &b);
    *out = NULL;
    if (res == SFB_SUCCESS && !tab) res = sfb__oom(g->ctx, "gl patch table");
    if (res != SFB_SUCCESS) goto done;
    tab->family = pt->domain == SFB__DOMAIN_TRI ? SFB__FAMILY_TRI : SFB__FAMILY_QUAD;
    while (p < pt->npatch) {
        int p0 = p, added = 1;
        b.nrec = b.ncv = b.npts = b.neig = 0;
        for (; p < pt->npatch && added; p += added)
            if ((res = sfb__gl_pbuild_add(g, pt, &b, p, &added)) != SFB_SUCCESS) goto done;
        if ((res = sfb__gl_pbuild_store(g, &b, tab, &allocated, p0, p)) != SFB_SUCCESS) goto done;
        ++b.stamp_id;
    }
done:
    sfb__gl_pbuild_free(g, &b);
    if (res != SFB_SUCCESS) {
        if (tab) sfb__gl_patches_free(g, tab);
        return res;
    }
    *out = tab;
    return SFB_SUCCESS;
}

/* The patch kernel of a family (loop = 0: the quad family's kinds, 1: the triangle family's):
 * one source, the other family's kinds left out by a define, so that neither pays the other's
 * compile. */
static sfb_result sfb__gl_patch_program(sfb__gl *g, int loop, sfb__GLuint *out) {
    sfb__GLuint prog;
    sfb_result r;
    int i;
    if (g->patch_program[loop]) { *out = g->patch_program[loop]; return SFB_SUCCESS; }
    if ((r = sfb__gl_compile(g, loop ? "#define SFB_NO_CATMARK\n" : "#define SFB_NO_LOOP\n", SFB__GL_PATCH_SOURCE, "patches.comp.glsl",
                             &prog)) != SFB_SUCCESS)
        return r;
    for (i = 0; i < 5; ++i) g->patch_loc[loop][i] = g->gl.GetUniformLocation(prog, sfb__gl_patch_uniforms[i]);
    g->patch_program[loop] = prog;
    *out = prog;
    return sfb__gl_check(g, "building the patch kernel");
}

/* Piece of a patch: pieces are consecutive patch ranges. */
static int sfb__gl_piece_of(const sfb__gl_ptable *tab, int patch) {
    int lo = 0, hi = tab->count - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (tab->pieces[mid].patch0 <= patch) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

/* Into the frame patches.comp.glsl evaluates patch `patch` in, and its sort key within a piece
 * (SFB__GL_BUCKETS): 0 B-spline or Bezier triangle, 1 end cap, 2 + valence Stam or Stam-Loop. */
static int sfb__gl_patch_frame(const sfb__patch_table *pt, int patch, double *u, double *v) {
    double s0 = *u, t0 = *v;
    if (pt->ptype[patch] == SFB__PATCH_STAM_LOOP) {
        /* into the EV's frame (the EV at (0,0)) in double, as for Stam; the triangle's
         * frame turns: corner 1 (u,v) = (t, 1-s-t), corner 2 (1-s-t, s). The scale keeps
         * its sign: the kernel multiplies the derivatives by it. */
        switch (SFB__PARAM_CORNER(pt->pparam[patch])) {
        case 1: *u = t0; *v = 1.0 - s0 - t0; break;
        case 2: *u = 1.0 - s0 - t0; *v = s0; break;
        default: break;
        }
        if (*u < 0.0) *u = 0.0;
        if (*v < 0.0) *v = 0.0;
        return 2 + pt->pvalence[patch];
    }
    if (pt->ptype[patch] == SFB__PATCH_STAM) {
        /* into the EV's frame here, in double: the EV is then exactly (0,0) and a small
         * distance to it keeps its relative precision in float */
        switch (SFB__PARAM_CORNER(pt->pparam[patch])) {
        case 1: *u = t0; *v = 1.0 - s0; break;
        case 2: *u = 1.0 - s0; *v = 1.0 - t0; break;
        case 3: *u = 1.0 - t0; *v = s0; break;
        default: break;
        }
        return 2 + pt->pvalence[patch];
    }
    return pt->ptype[patch] == SFB__PATCH_ENDCAP || pt->ptype[patch] == SFB__PATCH_ENDCAP_TRI ? 1 : 0;
}

/* The queries of a call, grouped by piece: queries[piece_start[i] .. piece_start[i+1]) go to
 * piece i; order[] (NULL when no sort was needed) maps a query back to its location. */
typedef struct sfb__gl_pqueries {
    sfb__gl_query *queries;
    int *order, *piece_start;
} sfb__gl_pqueries;

/* Locates locations [first, first + count) on the CPU (a quadtree walk per location, a few
 * ns) and sorts them stably by (piece, kind, valence): one dispatch per piece, and SIMD groups
 * that run one code path over one loop length (a GPU, and llvmpipe's SIMD lanes, pay for every
 * path any of its invocations takes). */
static sfb_result sfb__gl_patches_locate(sfb__gl *g, const sfb__patch_table *pt, const sfb__gl_ptable *tab, const sfb_location *locs,
                                         int first, int count, sfb__gl_pqueries *pq) {
    size_t nbuckets = (size_t)tab->count * SFB__GL_BUCKETS, z;
    int *key = (int *)sfb__alloc(g->ctx, (size_t)count * sizeof(int));
    int *bucket = (int *)sfb__calloc(g->ctx, nbuckets + 1, sizeof(int));
    int q, i, used = 0;
    sfb__gl_query *sorted = NULL;
    sfb_result res = SFB_SUCCESS;
    pq->queries = (sfb__gl_query *)sfb__alloc(g->ctx, (size_t)count * sizeof *pq->queries);
    pq->piece_start = (int *)sfb__alloc(g->ctx, ((size_t)tab->count + 1) * sizeof(int));
    pq->order = NULL;
    if (!pq->queries || !key || !bucket || !pq->piece_start) { res = sfb__oom(g->ctx, "gl patch evaluation"); goto done; }
    for (q = 0; q < count; ++q) {
        const sfb_location *l = &locs[first + q];
        double u, v, sc;
        int patch = sfb__patch_locate(pt, l->face, l->u, l->v, &u, &v, &sc), pc, kind;
        if (patch < 0 || tab->count == 0) {
            res = sfb__error(g->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, first + q, "location %d: parametric face %d is a hole", first + q, l->face);
            goto done;
        }
        kind = sfb__gl_patch_frame(pt, patch, &u, &v);
        pc = tab->count > 1 ? sfb__gl_piece_of(tab, patch) : 0;
        pq->queries[q].patch = patch - tab->pieces[pc].patch0;
        pq->queries[q].s = (float)u;
        pq->queries[q].t = (float)v;
        pq->queries[q].scale = (float)sc;
        key[q] = pc * SFB__GL_BUCKETS + kind;
        if (bucket[key[q] + 1]++ == 0) ++used;
    }
    for (z = 0; z < nbuckets; ++z) bucket[z + 1] += bucket[z];
    for (i = 0; i <= tab->count; ++i) pq->piece_start[i] = bucket[(size_t)i * SFB__GL_BUCKETS];
    if (used > 1) {
        /* a stable counting sort */
        sorted = (sfb__gl_query *)sfb__alloc(g->ctx, (size_t)count * sizeof *sorted);
        pq->order = (int *)sfb__alloc(g->ctx, (size_t)count * sizeof(int));
        if (!sorted || !pq->order) { sfb__free(g->ctx, sorted); res = sfb__oom(g->ctx, "gl patch evaluation"); goto done; }
        for (q = 0; q < count; ++q) {
            int at = bucket[key[q]]++;
            sorted[at] = pq->queries[q];
            pq->order[at] = first + q;
        }
        sfb__free(g->ctx, pq->queries);
        pq->queries = sorted;
    }
done:
    sfb__free(g->ctx, key);
    sfb__free(g->ctx, bucket);
    return res;
}

/* Runs the patch kernel (in use, with its output uniforms set) over each piece's queries in
 * batches that fit one storage block; results come back compact (only the asked outputs,
 * `stride` floats a query) and are scattered into the caller's arrays. */
static sfb_result sfb__gl_patches_run(sfb__gl *g, const sfb__gl_ptable *tab, int loop, const sfb__gl_pqueries *pq, int first,
                                      float *const *dst, const sfb__GLint *slot, int stride) {
    size_t batch = sfb__gl_query_batch(g, stride);
    int i, k;
    sfb_result res;
    for (i = 0; i < tab->count; ++i) {
        const struct sfb__gl_ppiece *pc = &tab->pieces[i];
        int a = pq->piece_start[i], b = pq->piece_start[i + 1];
        if (a >= b) continue;
        for (k = 0; k < 4; ++k) g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)k, pc->buf[k]);
        while (a < b) {
            int n = (size_t)(b - a) > batch ? (int)batch : b - a;
            const float *mapped;
            size_t qbytes = (size_t)n * sizeof(sfb__gl_query), rbytes = (size_t)n * (size_t)stride * sizeof(float);
            if ((res = sfb__gl_query_buffers(g, pq->queries + a, qbytes, rbytes)) != SFB_SUCCESS) return res;
            sfb__gl_dispatch_range(g, g->patch_loc[loop][0], g->patch_loc[loop][1], 0, n);
            if ((res = sfb__gl_check(g, "the patch kernel")) != SFB_SUCCESS) return res;
            if ((res = sfb__gl_map_results(g, rbytes, &mapped)) != SFB_SUCCESS) return res;
            sfb__gl_scatter(dst, slot, SFB__GL_OUTPUTS, mapped, stride, n, pq->order ? pq->order + a : NULL, first + a);
            if ((res = sfb__gl_unmap_results(g)) != SFB_SUCCESS) return res;
            a += n;
        }
    }
    return SFB_SUCCESS;
}

/* sfb_surface_eval on a polynomial table (either family), `tab` its upload to this backend or
 * NULL. */
static sfb_result sfb__gl_patches_eval(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable *tab, const sfb_location *locs, int first,
                                       int last, const sfb_eval_output *out) {
    sfb__gl_ptable *temp = NULL;
    float *dst[SFB__GL_OUTPUTS];
    sfb__GLint slot[SFB__GL_OUTPUTS];
    sfb__gl_pqueries pq = {NULL, NULL, NULL};
    int count = last - first, nout = 0, o, stride, loop = pt->domain == SFB__DOMAIN_TRI;
    sfb__gl_saved s;
    sfb__GLuint prog;
    sfb_result res;
    dst[0] = out->position; dst[1] = out->du; dst[2] = out->dv; dst[3] = out->normal;
    dst[4] = out->duu; dst[5] = out->duv; dst[6] = out->dvv;
    for (o = 0; o < SFB__GL_OUTPUTS; ++o) slot[o] = dst[o] ? nout++ : -1;
    if (count <= 0 || nout == 0) return SFB_SUCCESS;
    stride = 3 * nout;
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    if (!tab) {
        /* the surface was uploaded to another backend: a temporary copy for this call */
        if ((res = sfb__gl_patches_upload_current(g, pt, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    if ((res = sfb__gl_patch_program(g, loop, &prog)) != SFB_SUCCESS) goto done;
    if ((res = sfb__gl_patches_locate(g, pt, tab, locs, first, count, &pq)) != SFB_SUCCESS) goto done;
    g->gl.UseProgram(prog);
    g->gl.Uniform1i(g->patch_loc[loop][2], stride);
    g->gl.Uniform1iv(g->patch_loc[loop][3], SFB__GL_OUTPUTS, slot);
    g->gl.Uniform1i(g->patch_loc[loop][4], dst[4] || dst[5] || dst[6]);
    res = sfb__gl_patches_run(g, tab, loop, &pq, first, dst, slot, stride);
done:
    sfb__free(g->ctx, pq.queries); sfb__free(g->ctx, pq.order); sfb__free(g->ctx, pq.piece_start);
    if (temp) sfb__gl_patches_free(g, temp);
    sfb__gl_leave(g, &s);
    return res;
}

/* The patch-table slots, for the quad and triangle families (vtable.h hands them their tables). */
static void sfb__gl_patches_bind(sfb__backend_vtable *vt) {
    vt->upload_patches = sfb__gl_upload_patches;
    vt->release_patches = sfb__gl_release_patches;
    vt->eval_patches = sfb__gl_eval_patches;
}

#endif /* SFB__GL_PATCHES_H */
