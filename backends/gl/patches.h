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

/* Patch kinds as the shader numbers them (patches.comp.glsl), independent of the core's. */
enum { SFB__GL_KIND_BSPLINE = 0, SFB__GL_KIND_STAM = 1, SFB__GL_KIND_ENDCAP = 2, SFB__GL_KIND_BEZTRI = 3,
       SFB__GL_KIND_STAM_LOOP = 4, SFB__GL_KIND_ENDCAP_TRI = 5 };
enum { SFB__GL_OUTPUTS = 7 };  /* position, du, dv, normal, duu, duv, dvv */
/* Sort keys of the queries within a piece: B-spline or Bezier triangle, end cap (quad or
 * triangle), then Stam or Stam-Loop by valence (a table holds one scheme's kinds only). */
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



/* Uploads a patch table with the context current. Pieces are built greedily, patch after
 * patch; a point or an eigen block shared by patches of one piece is stored once in it. */
static sfb_result sfb__gl_patches_upload_current(sfb__gl *g, const sfb__patch_table *pt, sfb__gl_ptable **out) {
    const char *who = g->mode == SFB__GL_OSMESA ? "osmesa" : "gl";
    size_t cap_rec = (size_t)g->max_block / 16, cap_cv = (size_t)g->max_block / 4, cap_pts = (size_t)g->max_block / 16,
           cap_eig = (size_t)g->max_block / 4, eig_total = 0, max_pts;
    int rows = pt->npoints, p, count = 0, allocated = 0, stamp_id = 0, N;
    /* per eigen block: Catmull-Clark valence N at N, Loop at SFB__STAM_MAX_VALENCE + 1 + N */
    int eig_stamp[2 * (SFB__STAM_MAX_VALENCE + 1)];
    size_t eig_at[2 * (SFB__STAM_MAX_VALENCE + 1)];
    int *stamp = NULL, *local = NULL, *rec = NULL, *cvl = NULL;
    float *pts = NULL, *eig = NULL;
    sfb__gl_ptable *tab;
    sfb_result res = SFB_SUCCESS;
    *out = NULL;
    for (N = 0; N < 2 * (SFB__STAM_MAX_VALENCE + 1); ++N) {
        eig_stamp[N] = -1;
        eig_at[N] = 0;
    }
    for (N = 0; N <= SFB__STAM_MAX_VALENCE; ++N) {
        if (pt->eig[N]) eig_total += sfb__gl_eig_floats(pt->eig[N]->K);
        if (pt->eigl[N]) eig_total += sfb__gl_eig_floats(pt->eigl[N]->K);
    }
    max_pts = (size_t)pt->ncv < (size_t)rows ? (size_t)pt->ncv : (size_t)rows;
    tab = (sfb__gl_ptable *)sfb__calloc(g->ctx, 1, sizeof *tab);
    stamp = (int *)sfb__alloc(g->ctx, ((size_t)rows + 1) * sizeof(int));
    local = (int *)sfb__alloc(g->ctx, ((size_t)rows + 1) * sizeof(int));
    rec = (int *)sfb__alloc(g->ctx, ((size_t)pt->npatch + 1) * 4 * sizeof(int));
    cvl = (int *)sfb__alloc(g->ctx, ((size_t)pt->ncv + 1) * sizeof(int));
    pts = (float *)sfb__alloc(g->ctx, (max_pts + 1) * 4 * sizeof(float));
    eig = (float *)sfb__alloc(g->ctx, (eig_total + 4) * sizeof(float));
    if (!tab || !stamp || !local || !rec || !cvl || !pts || !eig) { res = sfb__oom(g->ctx, "gl patch table"); goto done; }
    for (p = 0; p < rows; ++p) stamp[p] = -1;
    p = 0;
    while (p < pt->npatch) {
        size_t nrec = 0, ncv = 0, npts = 0, neig = 0;
        sfb__gl_ppiece *piece;
        int p0 = p, k;
        for (; p < pt->npatch; ++p) {
            int first = pt->pfirst[p], n = pt->pfirst[p + 1] - first, kind, eoff = -1, fits, slot = -1, eK = 0;
            size_t npts0 = npts, neig0 = neig;
            const sfb__eigen_cc *e = NULL;
            const sfb__eigen_loop *el = NULL;
            switch (pt->ptype[p]) {
            case SFB__PATCH_BSPLINE: kind = SFB__GL_KIND_BSPLINE; fits = n == 16; break;
            /* 4 corner positions, or those and each corner's two limit tangents (normals) */
            case SFB__PATCH_ENDCAP: kind = SFB__GL_KIND_ENDCAP; fits = n == 4 || n == 12; eoff = n; break;
            case SFB__PATCH_STAM:
                kind = SFB__GL_KIND_STAM;
                N = pt->pvalence[p];
                e = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eig[N] : NULL;
                fits = e && n == e->K;
                if (e) { slot = N; eK = e->K; }
                break;
            case SFB__PATCH_BEZTRI: kind = SFB__GL_KIND_BEZTRI; fits = n == 15; break;
            /* 3 corner positions and each corner's two limit tangents */
            case SFB__PATCH_ENDCAP_TRI: kind = SFB__GL_KIND_ENDCAP_TRI; fits = n == 9; eoff = n; break;
            case SFB__PATCH_STAM_LOOP:
                kind = SFB__GL_KIND_STAM_LOOP;
                N = pt->pvalence[p];
                el = N >= 3 && N <= SFB__STAM_MAX_VALENCE ? pt->eigl[N] : NULL;
                fits = el && n == el->K;
                if (el) { slot = SFB__STAM_MAX_VALENCE + 1 + N; eK = el->K; }
                break;
            default: kind = -1; fits = 0; break;
            }
            if (!fits) {
                res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: patch %d (type %d, %d points) is malformed", who, p,
                                 pt->ptype[p], n);
                goto done;
            }
            /* its points, new to this piece */
            for (k = 0; k < n; ++k) {
                int row = pt->cv[first + k];
                if (row < 0 || row >= rows) {
                    res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "%s: patch %d reads point %d of %d", who, p, row, rows);
                    goto done;
                }
                if (stamp[row] != stamp_id) {
                    stamp[row] = stamp_id;
                    local[row] = (int)npts;
                    memcpy(pts + 4 * npts, pt->point_data + 3 * (size_t)row, 3 * sizeof(float));
                    pts[4 * npts + 3] = 0.0f;
                    ++npts;
                }
                cvl[ncv + (size_t)k] = local[row];
            }
            if (slot >= 0) {
                if (eig_stamp[slot] != stamp_id) {
                    eig_stamp[slot] = stamp_id;
                    eig_at[slot] = neig / 4; /* in vec4s */
                    if (e) sfb__gl_eig_pack(e, eig + neig);
                    else sfb__gl_eigl_pack(el, eig + neig);
                    neig += sfb__gl_eig_floats(eK);
                }
                eoff = (int)eig_at[slot];
            }
            if (nrec + 1 > cap_rec || ncv + (size_t)n > cap_cv || npts > cap_pts || neig > cap_eig) {
                if (nrec == 0) {
                    res = sfb__error(g->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                                     "%s: patch %d (%d points%s) needs more than one shader storage block holds (%d bytes)", who, p, n,
                                     e ? ", Stam eigen data" : el ? ", Stam-Loop eigen data" : "", (int)g->max_block);
                    goto done;
                }
                /* this patch starts the next piece: drop what it added here (the stamps of
                 * this piece are not looked at again) */
                npts = npts0;
                neig = neig0;
                break;
            }
            rec[4 * nrec] = kind;
            rec[4 * nrec + 1] = (int)ncv;
            rec[4 * nrec + 2] = SFB__PARAM_CORNER(pt->pparam[p]);
            rec[4 * nrec + 3] = eoff;
            ++nrec;
            ncv += (size_t)n;
        }
        if (count == allocated) {
            int na = allocated ? allocated * 2 : 4;
            sfb__gl_ppiece *np = (sfb__gl_ppiece *)sfb__realloc(g->ctx, tab->pieces, (size_t)na * sizeof *np);
            if (!np) { res = sfb__oom(g->ctx, "gl patch table"); goto done; }
            tab->pieces = np;
            allocated = na;
        }
        piece = &tab->pieces[count];
        memset(piece, 0, sizeof *piece);
        piece->patch0 = p0;
        piece->patch1 = p;
        g->gl.GenBuffers(4, piece->buf);
        tab->count = ++count;
        /* a zero-length storage buffer cannot be bound: keep at least one element */
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[0]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)(nrec * 16), rec, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[1]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)((ncv ? ncv : 1) * 4), cvl, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[2]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)((npts ? npts : 1) * 16), pts, SFB__GL_STATIC_DRAW);
        g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, piece->buf[3]);
        g->gl.BufferData(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLsizeiptr)((neig ? neig : 4) * 4), eig, SFB__GL_STATIC_DRAW);
        if ((res = sfb__gl_check(g, "uploading a patch table")) != SFB_SUCCESS) goto done;
        ++stamp_id;
    }
done:
    sfb__free(g->ctx, stamp); sfb__free(g->ctx, local); sfb__free(g->ctx, rec); sfb__free(g->ctx, cvl);
    sfb__free(g->ctx, pts); sfb__free(g->ctx, eig);
    if (res != SFB_SUCCESS) {
        if (tab) sfb__gl_ptable_free(g, tab);
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

/* Locations are located on the CPU (a quadtree walk per location, a few ns), grouped by
 * piece, and evaluated by the kernel in batches that fit one storage block; results come back
 * compact (only the asked outputs) and are scattered into the caller's arrays. */
static sfb_result sfb__gl_eval_patches(void *state, const sfb__patch_table *pt, void *handle, const sfb_location *locs, int first,
                                       int last, const sfb_eval_output *out) {
    sfb__gl *g = (sfb__gl *)state;
    sfb__gl_ptable *tab = (sfb__gl_ptable *)handle, *temp = NULL;
    float *dst[SFB__GL_OUTPUTS];
    sfb__GLint slot[SFB__GL_OUTPUTS];
    sfb__gl_query *queries = NULL, *sorted = NULL;
    int *order = NULL, *piece_start = NULL, *key = NULL, *bucket = NULL;
    int count = last - first, nout = 0, o, q, i, k, stride, used = 0, loop = pt->domain == SFB__DOMAIN_TRI;
    size_t batch, nbuckets, z;
    long long per = (long long)g->max_groups * 64;
    sfb__gl_saved s;
    sfb__GLuint prog;
    sfb_result res;
    if (sfb__patch_families(pt) & (1u << SFB__FAMILY_MANIFOLD)) return sfb__gl_mf_eval(g, pt, tab, locs, first, last, out);
    dst[0] = out->position; dst[1] = out->du; dst[2] = out->dv; dst[3] = out->normal;
    dst[4] = out->duu; dst[5] = out->duv; dst[6] = out->dvv;
    for (o = 0; o < SFB__GL_OUTPUTS; ++o) slot[o] = dst[o] ? nout++ : -1;
    if (count <= 0 || nout == 0) return SFB_SUCCESS;
    stride = 3 * nout;
    batch = (size_t)g->max_block / ((size_t)stride * sizeof(float));
    if (batch > (size_t)g->max_block / sizeof(sfb__gl_query)) batch = (size_t)g->max_block / sizeof(sfb__gl_query);
    if (batch < 1) batch = 1;
    if ((res = sfb__gl_enter(g, &s)) != SFB_SUCCESS) return res;
    if (!tab) {
        /* the surface was uploaded to another backend: a temporary copy for this call */
        if ((res = sfb__gl_patches_upload_current(g, pt, &temp)) != SFB_SUCCESS) goto done;
        tab = temp;
    }
    if ((res = sfb__gl_patch_program(g, loop, &prog)) != SFB_SUCCESS) goto done;
    nbuckets = (size_t)tab->count * SFB__GL_BUCKETS;
    queries = (sfb__gl_query *)sfb__alloc(g->ctx, (size_t)count * sizeof *queries);
    key = (int *)sfb__alloc(g->ctx, (size_t)count * sizeof(int));
    bucket = (int *)sfb__calloc(g->ctx, nbuckets + 1, sizeof(int));
    piece_start = (int *)sfb__alloc(g->ctx, ((size_t)tab->count + 1) * sizeof(int));
    if (!queries || !key || !bucket || !piece_start) { res = sfb__oom(g->ctx, "gl patch evaluation"); goto done; }
    for (q = 0; q < count; ++q) {
        const sfb_location *l = &locs[first + q];
        double u, v, sc;
        int patch = sfb__patch_locate(pt, l->face, l->u, l->v, &u, &v, &sc), pc, kind;
        if (patch < 0 || tab->count == 0) {
            res = sfb__error(g->ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, first + q, "location %d: parametric face %d is a hole", first + q, l->face);
            goto done;
        }
        kind = pt->ptype[patch] == SFB__PATCH_ENDCAP || pt->ptype[patch] == SFB__PATCH_ENDCAP_TRI ? 1 : 0;
        if (pt->ptype[patch] == SFB__PATCH_STAM_LOOP) {
            /* into the EV's frame (the EV at (0,0)) in double, as for Stam; the triangle's
             * frame turns: corner 1 (u,v) = (t, 1-s-t), corner 2 (1-s-t, s). The scale keeps
             * its sign: the kernel multiplies the derivatives by it. */
            double s0 = u, t0 = v;
            switch (SFB__PARAM_CORNER(pt->pparam[patch])) {
            case 1: u = t0; v = 1.0 - s0 - t0; break;
            case 2: u = 1.0 - s0 - t0; v = s0; break;
            default: break;
            }
            if (u < 0.0) u = 0.0;
            if (v < 0.0) v = 0.0;
            kind = 2 + pt->pvalence[patch];
        } else if (pt->ptype[patch] == SFB__PATCH_STAM) {
            /* into the EV's frame here, in double: the EV is then exactly (0,0) and a small
             * distance to it keeps its relative precision in float */
            double s0 = u, t0 = v;
            switch (SFB__PARAM_CORNER(pt->pparam[patch])) {
            case 1: u = t0; v = 1.0 - s0; break;
            case 2: u = 1.0 - s0; v = 1.0 - t0; break;
            case 3: u = 1.0 - t0; v = s0; break;
            default: break;
            }
            kind = 2 + pt->pvalence[patch];
        }
        pc = tab->count > 1 ? sfb__gl_piece_of(tab, patch) : 0;
        queries[q].patch = patch - tab->pieces[pc].patch0;
        queries[q].s = (float)u;
        queries[q].t = (float)v;
        queries[q].scale = (float)sc;
        key[q] = pc * SFB__GL_BUCKETS + kind;
        if (bucket[key[q] + 1]++ == 0) ++used;
    }
    for (z = 0; z < nbuckets; ++z) bucket[z + 1] += bucket[z];
    for (i = 0; i <= tab->count; ++i) piece_start[i] = bucket[(size_t)i * SFB__GL_BUCKETS];
    if (used > 1) {
        /* Stable counting sort by (piece, kind, valence): one dispatch per piece, and SIMD
         * groups that run one code path over one loop length (a GPU, and llvmpipe's SIMD
         * lanes, pay for every path any of its invocations takes). order[] maps a sorted
         * query back to its location. */
        sorted = (sfb__gl_query *)sfb__alloc(g->ctx, (size_t)count * sizeof *sorted);
        order = (int *)sfb__alloc(g->ctx, (size_t)count * sizeof(int));
        if (!sorted || !order) { res = sfb__oom(g->ctx, "gl patch evaluation"); goto done; }
        for (q = 0; q < count; ++q) {
            int at = bucket[key[q]]++;
            sorted[at] = queries[q];
            order[at] = first + q;
        }
        sfb__free(g->ctx, queries);
        queries = sorted;
        sorted = NULL;
    }
    g->gl.UseProgram(prog);
    g->gl.Uniform1i(g->patch_loc[loop][2], stride);
    g->gl.Uniform1iv(g->patch_loc[loop][3], SFB__GL_OUTPUTS, slot);
    g->gl.Uniform1i(g->patch_loc[loop][4], dst[4] || dst[5] || dst[6]);
    for (i = 0; i < tab->count; ++i) {
        const sfb__gl_ppiece *pc = &tab->pieces[i];
        int a = piece_start[i], b = piece_start[i + 1];
        if (a >= b) continue;
        for (k = 0; k < 4; ++k) g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, (sfb__GLuint)k, pc->buf[k]);
        while (a < b) {
            int n = (size_t)(b - a) > batch ? (int)batch : b - a, d;
            const float *mapped;
            size_t qbytes = (size_t)n * sizeof(sfb__gl_query), rbytes = (size_t)n * (size_t)stride * sizeof(float);
            if ((res = sfb__gl_grow(g, &g->scratch_src, &g->scratch_src_cap, qbytes, SFB__GL_STREAM_DRAW)) != SFB_SUCCESS) goto done;
            g->gl.BufferSubData(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)qbytes, queries + a);
            if ((res = sfb__gl_grow(g, &g->scratch_dst, &g->scratch_dst_cap, rbytes, SFB__GL_DYNAMIC_READ)) != SFB_SUCCESS) goto done;
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 4, g->scratch_src);
            g->gl.BindBufferBase(SFB__GL_SHADER_STORAGE_BUFFER, 5, g->scratch_dst);
            for (d = 0; d < n;) {
                int m = (long long)(n - d) > per ? (int)per : n - d;
                g->gl.Uniform1i(g->patch_loc[loop][0], d);
                g->gl.Uniform1i(g->patch_loc[loop][1], d + m);
                g->gl.DispatchCompute((sfb__GLuint)((m + 63) / 64), 1, 1);
                d += m;
            }
            if ((res = sfb__gl_check(g, "the patch kernel")) != SFB_SUCCESS) goto done;
            g->gl.MemoryBarrier(SFB__GL_BUFFER_UPDATE_BARRIER_BIT);
            g->gl.BindBuffer(SFB__GL_SHADER_STORAGE_BUFFER, g->scratch_dst);
            mapped = (const float *)g->gl.MapBufferRange(SFB__GL_SHADER_STORAGE_BUFFER, 0, (sfb__GLsizeiptr)rbytes, SFB__GL_MAP_READ_BIT);
            if (!mapped) {
                res = sfb__gl_check(g, "mapping the results");
                if (res == SFB_SUCCESS)
                    res = sfb__error(g->ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "gl: glMapBufferRange returned NULL");
                goto done;
            }
            for (q = 0; q < n; ++q) {
                size_t at = 3 * (size_t)(order ? order[a + q] : first + a + q);
                const float *r = mapped + (size_t)q * (size_t)stride;
                for (o = 0; o < SFB__GL_OUTPUTS; ++o)
                    if (dst[o]) {
                        const float *x = r + 3 * slot[o];
                        dst[o][at] = x[0];
                        dst[o][at + 1] = x[1];
                        dst[o][at + 2] = x[2];
                    }
            }
            g->gl.UnmapBuffer(SFB__GL_SHADER_STORAGE_BUFFER);
            if ((res = sfb__gl_check(g, "reading the results back")) != SFB_SUCCESS) goto done;
            a += n;
        }
    }
done:
    sfb__free(g->ctx, queries); sfb__free(g->ctx, sorted); sfb__free(g->ctx, order);
    sfb__free(g->ctx, piece_start); sfb__free(g->ctx, key); sfb__free(g->ctx, bucket);
    if (temp) sfb__gl_ptable_free(g, temp);
    sfb__gl_leave(g, &s);
    return res;
}

#endif /* SFB__GL_PATCHES_H */
