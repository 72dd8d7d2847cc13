/* OBJ reader (from memory) and writer: v/vt/vn/f, OpenSubdiv's `t` tags, seed 001's fs/as.
 *
 * Choices where the formats are loose:
 * - `fs s0 s1 ...` applies to the face on the line before it; value i is the sharpness of the
 *   edge from the face's vertex i to vertex i+1 in the order the face lists them (seed 001 says
 *   "clockwise order" without naming the first edge; we follow the face's own order).
 * - `as n s0 s1 ...` gives the same values to each of the next n faces (seed 001); each of those
 *   faces must have as many edges as values. Where two faces disagree on an edge the highest
 *   value wins. `as` counting past the last face is an error.
 * - Faces either all carry vt indices or none does; otherwise the UVs are dropped (logged).
 * - `t crease` with more than two vertices is a chain of edges; one value applies to all, or
 *   one value per edge. Hierarchical edits (vertexedit, edgeedit, faceedit) and unknown tags are
 *   ignored with a warning, as OpenSubdiv 3 does.
 */

typedef struct sfb__vec {
    void *p;
    size_t n, cap, elem;
} sfb__vec;

static int sfb__vec_push(sfb_context *ctx, sfb__vec *v, const void *x) {
    if (v->n == v->cap) {
        size_t cap = v->cap ? v->cap * 2 : 64;
        void *np;
        if (cap > SFB_MAX_ELEMENTS * (size_t)2) return 0;
        np = sfb__realloc(ctx, v->p, cap * v->elem);
        if (!np) return 0;
        v->p = np;
        v->cap = cap;
    }
    memcpy((char *)v->p + v->n * v->elem, x, v->elem);
    v->n++;
    return 1;
}

typedef struct sfb__objp {
    sfb_context *ctx;
    long line;
    sfb__vec pos, uv, fsize, fv, fuv, fline, fsharp, cv, cs, cline, kv, ks, kline, holes, hline;
    int first_has_uv;          /* -1 before the first face */
    long uv_mismatch_face, uv_mismatch_line; /* first face whose uv use differs from face 0; -1 none */
    int any_fsharp;
    int boundary, crease_method, triangle_rule;
    /* pending `as` */
    long as_left, as_line;
    float *as_vals;
    int as_count;
} sfb__objp;

static sfb_result sfb__perr(sfb__objp *P, sfb_result r, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static sfb_result sfb__perr(sfb__objp *P, sfb_result r, const char *fmt, ...) {
    char body[600];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(body, sizeof body, fmt, ap);
    va_end(ap);
    return sfb__error(P->ctx, r, SFB_ELEMENT_LINE, P->line, "%s", body);
}

static int sfb__next_tok(const char **cur, const char *end, const char **tok, size_t *len) {
    const char *c = *cur;
    while (c < end && (*c == ' ' || *c == '\t')) ++c;
    if (c >= end || *c == '#') { *cur = end; return 0; }
    *tok = c;
    while (c < end && *c != ' ' && *c != '\t') ++c;
    *len = (size_t)(c - *tok);
    *cur = c;
    return 1;
}

static int sfb__tok_eq(const char *t, size_t n, const char *s) { return strlen(s) == n && memcmp(t, s, n) == 0; }

/* 0 ok, 1 not a number, 2 not finite */
static int sfb__parse_double(const char *t, size_t n, double *out) {
    char buf[72];
    char *endp;
    double x;
    if (n == 0 || n >= sizeof buf) return 1;
    memcpy(buf, t, n);
    buf[n] = 0;
    if (!((buf[0] >= '0' && buf[0] <= '9') || buf[0] == '-' || buf[0] == '+' || buf[0] == '.' || buf[0] == 'n' ||
          buf[0] == 'N' || buf[0] == 'i' || buf[0] == 'I'))
        return 1;
    x = strtod(buf, &endp);
    if (*endp != 0 || endp == buf) return 1;
    *out = x;
    /* not finite as a float: the doubles that round to infinity, |x| >= FLT_MAX + half an ulp
     * (2^128 - 2^103; FLT_MAX itself, written with 9 digits as 3.40282347e+38, is above
     * FLT_MAX as a double and rounds back to it) */
    if (!isfinite(x) || fabs(x) >= 3.4028235677973366e38) return 2;
    return 0;
}

static sfb_result sfb__tok_float(sfb__objp *P, const char *t, size_t n, const char *what, float *out) {
    double x;
    int r = sfb__parse_double(t, n, &x);
    if (r == 1) return sfb__perr(P, SFB_PARSE_ERROR, "expected a number for %s, got '%.*s'", what, (int)(n > 40 ? 40 : n), t);
    if (r == 2) return sfb__perr(P, SFB_INVALID_VALUE, "%s '%.*s' is not a finite number (NaN or inf)", what, (int)(n > 40 ? 40 : n), t);
    *out = (float)x;
    return SFB_SUCCESS;
}

static sfb_result sfb__tok_sharpness(sfb__objp *P, const char *t, size_t n, float *out) {
    double x;
    int r = sfb__parse_double(t, n, &x);
    if (r == 1) return sfb__perr(P, SFB_PARSE_ERROR, "expected a sharpness number, got '%.*s'", (int)(n > 40 ? 40 : n), t);
    if (isnan(x) || x < 0.0)
        return sfb__perr(P, SFB_INVALID_VALUE, "sharpness '%.*s' is invalid: sharpness must be a number >= 0", (int)(n > 40 ? 40 : n), t);
    *out = x >= SFB_SHARPNESS_INFINITE ? SFB_SHARPNESS_INFINITE : (float)x;
    return SFB_SUCCESS;
}

/* Parses a decimal integer; 0 ok, 1 malformed, 2 overflow. Stops at '/' or the end. */
static int sfb__parse_int(const char **c, const char *end, long *out) {
    const char *p = *c;
    int neg = 0;
    long v = 0;
    if (p < end && (*p == '-' || *p == '+')) { neg = *p == '-'; ++p; }
    if (p >= end || *p < '0' || *p > '9') return 1;
    while (p < end && *p >= '0' && *p <= '9') {
        v = v * 10 + (*p - '0');
        if (v > 0x7fffffffL) return 2;
        ++p;
    }
    *c = p;
    *out = neg ? -v : v;
    return 0;
}

static sfb_result sfb__tok_int(sfb__objp *P, const char *t, size_t n, const char *what, long *out) {
    const char *c = t;
    int r = sfb__parse_int(&c, t + n, out);
    if (r == 2) return sfb__perr(P, SFB_LIMIT_EXCEEDED, "%s '%.*s' is over the limit of a 32-bit integer", what, (int)(n > 40 ? 40 : n), t);
    if (r == 1 || c != t + n) return sfb__perr(P, SFB_PARSE_ERROR, "expected an integer for %s, got '%.*s'", what, (int)(n > 40 ? 40 : n), t);
    return SFB_SUCCESS;
}

/* Resolves an OBJ index (1-based or negative relative) against `count` elements so far. */
static sfb_result sfb__resolve(sfb__objp *P, long idx, size_t count, const char *what, int *out) {
    if (idx == 0) return sfb__perr(P, SFB_INVALID_TOPOLOGY, "%s index 0 is invalid (OBJ indices start at 1)", what);
    if (idx < 0) idx = (long)count + idx;
    else idx = idx - 1;
    if (idx < 0 || (size_t)idx >= count)
        return sfb__perr(P, SFB_INVALID_TOPOLOGY, "%s index out of range (%zu %s defined so far)", what, count,
                         strcmp(what, "vertex") == 0 ? "vertices" : "uvs");
    *out = (int)idx;
    return SFB_SUCCESS;
}

#define SFB__PUSH(vec, val) do { if (!sfb__vec_push(P->ctx, &(vec), &(val))) return sfb__oom(P->ctx, "OBJ reader"); } while (0)

static sfb_result sfb__obj_face(sfb__objp *P, const char *cur, const char *end) {
    const char *t;
    size_t n;
    int count = 0, has_uv = -1, line = (int)P->line;
    size_t first = P->fv.n;
    sfb_result r;
    while (sfb__next_tok(&cur, end, &t, &n)) {
        const char *c = t, *te = t + n;
        long a, b = 0;
        int vi, ti = -1, this_uv = 0, pr;
        pr = sfb__parse_int(&c, te, &a);
        if (pr == 1) return sfb__perr(P, SFB_PARSE_ERROR, "malformed face index '%.*s'", (int)(n > 40 ? 40 : n), t);
        if (pr == 2) return sfb__perr(P, SFB_INVALID_TOPOLOGY, "vertex index '%.*s' out of range", (int)(n > 40 ? 40 : n), t);
        if (c < te) {
            if (*c != '/') return sfb__perr(P, SFB_PARSE_ERROR, "malformed face index '%.*s'", (int)(n > 40 ? 40 : n), t);
            ++c;
            if (c < te && *c != '/') {
                pr = sfb__parse_int(&c, te, &b);
                if (pr == 1) return sfb__perr(P, SFB_PARSE_ERROR, "malformed uv index in '%.*s'", (int)(n > 40 ? 40 : n), t);
                if (pr == 2) return sfb__perr(P, SFB_INVALID_TOPOLOGY, "uv index in '%.*s' out of range", (int)(n > 40 ? 40 : n), t);
                this_uv = 1;
            } else if (c >= te) {
                return sfb__perr(P, SFB_PARSE_ERROR, "truncated face index '%.*s'", (int)(n > 40 ? 40 : n), t);
            }
            if (c < te) {
                long nn;
                if (*c != '/') return sfb__perr(P, SFB_PARSE_ERROR, "malformed face index '%.*s'", (int)(n > 40 ? 40 : n), t);
                ++c;
                pr = sfb__parse_int(&c, te, &nn);
                if (pr != 0 || c != te) return sfb__perr(P, SFB_PARSE_ERROR, "malformed normal index in '%.*s'", (int)(n > 40 ? 40 : n), t);
            }
        }
        r = sfb__resolve(P, a, P->pos.n / 3, "vertex", &vi);
        if (r != SFB_SUCCESS) return r;
        if (this_uv) {
            r = sfb__resolve(P, b, P->uv.n / 2, "uv", &ti);
            if (r != SFB_SUCCESS) return r;
        }
        if (has_uv < 0) has_uv = this_uv;
        else if (has_uv != this_uv) return sfb__perr(P, SFB_PARSE_ERROR, "face mixes corners with and without uv indices");
        if (count >= SFB_MAX_FACE_SIZE)
            return sfb__perr(P, SFB_LIMIT_EXCEEDED, "face has more than %d vertices (SFB_MAX_FACE_SIZE)", SFB_MAX_FACE_SIZE);
        SFB__PUSH(P->fv, vi);
        SFB__PUSH(P->fuv, ti);
        count++;
    }
    if (count < 3)
        return sfb__perr(P, SFB_INVALID_TOPOLOGY, "face has %d %s; a face needs at least 3", count, count == 1 ? "vertex" : "vertices");
    SFB__PUSH(P->fsize, count);
    SFB__PUSH(P->fline, line);
    if (P->first_has_uv < 0) P->first_has_uv = has_uv;
    else if (has_uv != P->first_has_uv && P->uv_mismatch_face < 0) {
        P->uv_mismatch_face = (long)P->fsize.n - 1;
        P->uv_mismatch_line = line;
    }
    {
        float zero = 0.0f;
        int i;
        for (i = 0; i < count; ++i) SFB__PUSH(P->fsharp, zero);
    }
    if (P->as_left > 0) {
        int i;
        if (P->as_count != count)
            return sfb__perr(P, SFB_PARSE_ERROR, "face has %d edges but the 'as' on line %ld gives %d sharpness values", count,
                             P->as_line, P->as_count);
        for (i = 0; i < count; ++i) {
            float *fs = (float *)P->fsharp.p + first + i;
            if (P->as_vals[i] > *fs) *fs = P->as_vals[i];
        }
        P->any_fsharp = 1;
        P->as_left--;
    }
    return SFB_SUCCESS;
}

static sfb_result sfb__obj_tag(sfb__objp *P, const char *cur, const char *end) {
    const char *t, *name;
    size_t n, nn;
    long ni, nf, ns, i;
    long ints[64];
    float flts[64];
    const char *strs[4];
    size_t strl[4];
    long *iv = ints;
    float *fv = flts;
    sfb_result r = SFB_SUCCESS;
    if (!sfb__next_tok(&cur, end, &name, &nn)) return sfb__perr(P, SFB_PARSE_ERROR, "'t' line without a tag name");
    if (!sfb__next_tok(&cur, end, &t, &n)) return sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' lacks its argument counts", (int)(nn > 40 ? 40 : nn), name);
    {
        const char *c = t, *te = t + n;
        if (sfb__parse_int(&c, te, &ni) || c >= te || *c++ != '/' || sfb__parse_int(&c, te, &nf) || c >= te || *c++ != '/' ||
            sfb__parse_int(&c, te, &ns) || c != te || ni < 0 || nf < 0 || ns < 0)
            return sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' has malformed argument counts '%.*s' (expected i/f/s)",
                             (int)(nn > 40 ? 40 : nn), name, (int)(n > 40 ? 40 : n), t);
    }
    if (sfb__tok_eq(name, nn, "vertexedit") || sfb__tok_eq(name, nn, "edgeedit") || sfb__tok_eq(name, nn, "faceedit")) {
        sfb__log(P->ctx, SFB_LOG_WARN, "line %ld: hierarchical edit '%.*s' ignored (not supported)", P->line, (int)nn, name);
        return SFB_SUCCESS;
    }
    if (ni > 1000000 || nf > 1000000 || ns > 1000000)
        return sfb__perr(P, SFB_LIMIT_EXCEEDED, "tag '%.*s' declares more than 1000000 arguments (over the limit)", (int)(nn > 40 ? 40 : nn), name);
    if (ni > 64) iv = (long *)sfb__alloc(P->ctx, (size_t)ni * sizeof(long));
    if (nf > 64) fv = (float *)sfb__alloc(P->ctx, (size_t)nf * sizeof(float));
    if (!iv || !fv) { r = sfb__oom(P->ctx, "OBJ reader"); goto out; }
    for (i = 0; i < ni; ++i) {
        if (!sfb__next_tok(&cur, end, &t, &n)) { r = sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' declares %ld integers but the line has fewer values", (int)(nn > 40 ? 40 : nn), name, ni); goto out; }
        r = sfb__tok_int(P, t, n, "tag argument", &iv[i]);
        if (r) goto out;
    }
    for (i = 0; i < nf; ++i) {
        if (!sfb__next_tok(&cur, end, &t, &n)) { r = sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' declares %ld floats but the line has fewer values", (int)(nn > 40 ? 40 : nn), name, nf); goto out; }
        r = sfb__tok_sharpness(P, t, n, &fv[i]);
        if (r) goto out;
    }
    for (i = 0; i < ns; ++i) {
        if (!sfb__next_tok(&cur, end, &t, &n)) { r = sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' declares %ld strings but the line has fewer values", (int)(nn > 40 ? 40 : nn), name, ns); goto out; }
        if (i < 4) { strs[i] = t; strl[i] = n; }
    }
    if (sfb__next_tok(&cur, end, &t, &n)) { r = sfb__perr(P, SFB_PARSE_ERROR, "tag '%.*s' has more values than its counts declare", (int)(nn > 40 ? 40 : nn), name); goto out; }
    if (sfb__tok_eq(name, nn, "crease")) {
        if (ni < 2 || !(nf == 1 || nf == ni - 1)) { r = sfb__perr(P, SFB_PARSE_ERROR, "crease needs at least 2 vertices and 1 sharpness (or one per edge)"); goto out; }
        for (i = 0; i + 1 < ni; ++i) {
            int a = (int)iv[i], b = (int)iv[i + 1], ln = (int)P->line;
            float s = fv[nf == 1 ? 0 : i];
            if (iv[i] < 0 || iv[i + 1] < 0) { r = sfb__perr(P, SFB_INVALID_TOPOLOGY, "crease vertex index %ld out of range", iv[i] < 0 ? iv[i] : iv[i + 1]); goto out; }
            if (!sfb__vec_push(P->ctx, &P->cv, &a) || !sfb__vec_push(P->ctx, &P->cv, &b) || !sfb__vec_push(P->ctx, &P->cs, &s) ||
                !sfb__vec_push(P->ctx, &P->cline, &ln)) { r = sfb__oom(P->ctx, "OBJ reader"); goto out; }
        }
    } else if (sfb__tok_eq(name, nn, "corner")) {
        if (ni < 1 || !(nf == 1 || nf == ni)) { r = sfb__perr(P, SFB_PARSE_ERROR, "corner needs vertices and 1 sharpness (or one per vertex)"); goto out; }
        for (i = 0; i < ni; ++i) {
            int a = (int)iv[i], ln = (int)P->line;
            float s = fv[nf == 1 ? 0 : i];
            if (iv[i] < 0) { r = sfb__perr(P, SFB_INVALID_TOPOLOGY, "corner vertex index %ld out of range", iv[i]); goto out; }
            if (!sfb__vec_push(P->ctx, &P->kv, &a) || !sfb__vec_push(P->ctx, &P->ks, &s) || !sfb__vec_push(P->ctx, &P->kline, &ln)) {
                r = sfb__oom(P->ctx, "OBJ reader"); goto out;
            }
        }
    } else if (sfb__tok_eq(name, nn, "hole")) {
        for (i = 0; i < ni; ++i) {
            int a = (int)iv[i], ln = (int)P->line;
            if (iv[i] < 0) { r = sfb__perr(P, SFB_INVALID_TOPOLOGY, "hole face index %ld out of range", iv[i]); goto out; }
            if (!sfb__vec_push(P->ctx, &P->holes, &a) || !sfb__vec_push(P->ctx, &P->hline, &ln)) { r = sfb__oom(P->ctx, "OBJ reader"); goto out; }
        }
    } else if (sfb__tok_eq(name, nn, "interpolateboundary")) {
        if (ni != 1) { r = sfb__perr(P, SFB_PARSE_ERROR, "interpolateboundary needs one integer"); goto out; }
        if (iv[0] == 0) P->boundary = SFB_BOUNDARY_NONE;
        else if (iv[0] == 1) P->boundary = SFB_BOUNDARY_EDGE_AND_CORNER;
        else if (iv[0] == 2) P->boundary = SFB_BOUNDARY_EDGE_ONLY;
        else { r = sfb__perr(P, SFB_INVALID_VALUE, "interpolateboundary value %ld is not 0, 1 or 2", iv[0]); goto out; }
    } else if (sfb__tok_eq(name, nn, "creasemethod")) {
        if (ns != 1) { r = sfb__perr(P, SFB_PARSE_ERROR, "creasemethod needs one string"); goto out; }
        if (sfb__tok_eq(strs[0], strl[0], "chaikin")) P->crease_method = SFB_CREASE_CHAIKIN;
        else if (sfb__tok_eq(strs[0], strl[0], "uniform") || sfb__tok_eq(strs[0], strl[0], "normal")) P->crease_method = SFB_CREASE_UNIFORM;
        else { r = sfb__perr(P, SFB_INVALID_VALUE, "creasemethod '%.*s' is not chaikin, uniform or normal", (int)(strl[0] > 40 ? 40 : strl[0]), strs[0]); goto out; }
    } else if (sfb__tok_eq(name, nn, "smoothtriangles")) {
        if (ns != 1) { r = sfb__perr(P, SFB_PARSE_ERROR, "smoothtriangles needs one string"); goto out; }
        if (sfb__tok_eq(strs[0], strl[0], "smooth")) P->triangle_rule = SFB_TRI_SMOOTH;
        else if (sfb__tok_eq(strs[0], strl[0], "catmark")) P->triangle_rule = SFB_TRI_CATMARK;
        else { r = sfb__perr(P, SFB_INVALID_VALUE, "smoothtriangles '%.*s' is not smooth or catmark", (int)(strl[0] > 40 ? 40 : strl[0]), strs[0]); goto out; }
    } else {
        sfb__log(P->ctx, SFB_LOG_WARN, "line %ld: tag '%.*s' ignored", P->line, (int)(nn > 40 ? 40 : nn), name);
    }
out:
    if (iv != ints) sfb__free(P->ctx, iv);
    if (fv != flts) sfb__free(P->ctx, fv);
    return r;
}

static const char *const sfb__obj_ignored[] = {"o", "g", "s", "usemtl", "mtllib", "l", "p", "vp", "cstype", "deg", "bmat",
                                               "step", "curv", "curv2", "surf", "parm", "trim", "end", "con", "mg", "lod",
                                               "maplib", "usemap", "shadow_obj", "trace_obj", "ctech", "stech", "bevel",
                                               "c_interp", "d_interp", "sp", "scrv", NULL};

static sfb_result sfb__obj_line(sfb__objp *P, const char *cur, const char *end) {
    const char *kw, *t;
    size_t kn, n;
    sfb_result r;
    if (!sfb__next_tok(&cur, end, &kw, &kn)) return SFB_SUCCESS;
    if (sfb__tok_eq(kw, kn, "v")) {
        float x[3];
        int i;
        for (i = 0; i < 3; ++i) {
            if (!sfb__next_tok(&cur, end, &t, &n)) return sfb__perr(P, SFB_PARSE_ERROR, "vertex needs 3 coordinates, got %d", i);
            r = sfb__tok_float(P, t, n, "vertex coordinate", &x[i]);
            if (r) return r;
        }
        while (sfb__next_tok(&cur, end, &t, &n)) { /* w or vertex colour: must be numbers */
            float dummy;
            r = sfb__tok_float(P, t, n, "vertex value", &dummy);
            if (r) return r;
        }
        if (P->pos.n / 3 >= SFB_MAX_ELEMENTS) return sfb__perr(P, SFB_LIMIT_EXCEEDED, "too many vertices");
        for (i = 0; i < 3; ++i) SFB__PUSH(P->pos, x[i]);
        return SFB_SUCCESS;
    }
    if (sfb__tok_eq(kw, kn, "vt")) {
        float x[2];
        int i;
        for (i = 0; i < 2; ++i) {
            if (!sfb__next_tok(&cur, end, &t, &n)) return sfb__perr(P, SFB_PARSE_ERROR, "texture coordinate needs 2 values, got %d", i);
            r = sfb__tok_float(P, t, n, "texture coordinate", &x[i]);
            if (r) return r;
        }
        if (sfb__next_tok(&cur, end, &t, &n)) {
            float dummy;
            r = sfb__tok_float(P, t, n, "texture coordinate", &dummy);
            if (r) return r;
        }
        for (i = 0; i < 2; ++i) SFB__PUSH(P->uv, x[i]);
        return SFB_SUCCESS;
    }
    if (sfb__tok_eq(kw, kn, "vn")) return SFB_SUCCESS; /* normals are recomputed from the surface */
    if (sfb__tok_eq(kw, kn, "f")) return sfb__obj_face(P, cur, end);
    if (sfb__tok_eq(kw, kn, "t")) return sfb__obj_tag(P, cur, end);
    if (sfb__tok_eq(kw, kn, "fs")) {
        size_t nfaces = P->fsize.n, first;
        int fsz, i = 0;
        if (nfaces == 0) return sfb__perr(P, SFB_PARSE_ERROR, "'fs' before any face");
        fsz = ((int *)P->fsize.p)[nfaces - 1];
        first = P->fv.n - (size_t)fsz;
        while (sfb__next_tok(&cur, end, &t, &n)) {
            float s;
            if (i >= fsz) return sfb__perr(P, SFB_PARSE_ERROR, "'fs' has more values than the face's %d edges", fsz);
            r = sfb__tok_sharpness(P, t, n, &s);
            if (r) return r;
            if (s > ((float *)P->fsharp.p)[first + i]) ((float *)P->fsharp.p)[first + i] = s;
            ++i;
        }
        if (i != fsz) return sfb__perr(P, SFB_PARSE_ERROR, "'fs' has %d values but the face has %d edges", i, fsz);
        P->any_fsharp = 1;
        return SFB_SUCCESS;
    }
    if (sfb__tok_eq(kw, kn, "as")) {
        long cnt;
        int k = 0;
        if (P->as_left > 0)
            return sfb__perr(P, SFB_PARSE_ERROR, "'as' starts before the 'as' on line %ld covered its faces", P->as_line);
        if (!sfb__next_tok(&cur, end, &t, &n)) return sfb__perr(P, SFB_PARSE_ERROR, "'as' needs a face count");
        r = sfb__tok_int(P, t, n, "'as' face count", &cnt);
        if (r) return r;
        if (cnt <= 0) return sfb__perr(P, SFB_PARSE_ERROR, "'as' face count %ld must be positive", cnt);
        if (cnt > SFB_MAX_ELEMENTS)
            return sfb__perr(P, SFB_LIMIT_EXCEEDED, "'as' face count %ld is over the limit of %d faces", cnt, SFB_MAX_ELEMENTS);
        if (!P->as_vals) {
            P->as_vals = (float *)sfb__alloc(P->ctx, SFB_MAX_FACE_SIZE * sizeof(float));
            if (!P->as_vals) return sfb__oom(P->ctx, "OBJ reader");
        }
        while (sfb__next_tok(&cur, end, &t, &n)) {
            if (k >= SFB_MAX_FACE_SIZE) return sfb__perr(P, SFB_LIMIT_EXCEEDED, "'as' has more than %d values", SFB_MAX_FACE_SIZE);
            r = sfb__tok_sharpness(P, t, n, &P->as_vals[k]);
            if (r) return r;
            ++k;
        }
        if (k < 3) return sfb__perr(P, SFB_PARSE_ERROR, "'as' needs one sharpness per face edge (at least 3), got %d", k);
        P->as_left = cnt;
        P->as_line = P->line;
        P->as_count = k;
        return SFB_SUCCESS;
    }
    {
        int i;
        for (i = 0; sfb__obj_ignored[i]; ++i)
            if (sfb__tok_eq(kw, kn, sfb__obj_ignored[i])) return SFB_SUCCESS;
    }
    return sfb__perr(P, SFB_PARSE_ERROR, "unknown statement '%.*s'", (int)(kn > 24 ? 24 : kn), kw);
}

static void sfb__objp_free(sfb__objp *P) {
    sfb__vec *vs[] = {&P->pos, &P->uv, &P->fsize, &P->fv, &P->fuv, &P->fline, &P->fsharp, &P->cv, &P->cs, &P->cline,
                      &P->kv, &P->ks, &P->kline, &P->holes, &P->hline};
    size_t i;
    for (i = 0; i < sizeof vs / sizeof vs[0]; ++i) sfb__free(P->ctx, vs[i]->p);
    sfb__free(P->ctx, P->as_vals);
}

SFB_API sfb_result sfb_mesh_read_obj(sfb_context *ctx, const char *text, size_t size, sfb_mesh **out) {
    sfb__objp P;
    const char *c, *end;
    sfb_result r = SFB_SUCCESS;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!out || (!text && size)) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_mesh_read_obj: NULL argument");
    *out = NULL;
    memset(&P, 0, sizeof P);
    P.ctx = ctx;
    P.first_has_uv = -1;
    P.uv_mismatch_face = -1;
    P.pos.elem = sizeof(float); P.uv.elem = sizeof(float); P.fsize.elem = sizeof(int); P.fv.elem = sizeof(int);
    P.fuv.elem = sizeof(int); P.fline.elem = sizeof(int); P.fsharp.elem = sizeof(float); P.cv.elem = sizeof(int);
    P.cs.elem = sizeof(float); P.cline.elem = sizeof(int); P.kv.elem = sizeof(int); P.ks.elem = sizeof(float);
    P.kline.elem = sizeof(int); P.holes.elem = sizeof(int); P.hline.elem = sizeof(int);
    c = text;
    end = text + size;
    while (c < end && r == SFB_SUCCESS) {
        const char *le = (const char *)memchr(c, '\n', (size_t)(end - c)), *q;
        const char *next = le ? le + 1 : end;
        if (!le) le = end;
        P.line++;
        if (le > c && le[-1] == '\r') --le;
        for (q = c; q < le; ++q) {
            unsigned char ch = (unsigned char)*q;
            if (ch == 0 || (ch < 32 && ch != '\t') || ch == 127) {
                r = sfb__perr(&P, SFB_PARSE_ERROR, "binary data (byte 0x%02x) in text", ch);
                break;
            }
        }
        if (r == SFB_SUCCESS) r = sfb__obj_line(&P, c, le);
        if ((P.line & 0xffff) == 0 && r == SFB_SUCCESS) r = sfb__progress(ctx, (float)(c - text) / (float)size, "read OBJ");
        c = next;
    }
    if (r == SFB_SUCCESS && P.as_left > 0) {
        P.line = P.as_line;
        r = sfb__perr(&P, SFB_PARSE_ERROR, "'as' covers %ld more faces than the file has", P.as_left);
    }
    if (r == SFB_SUCCESS) {
        sfb_mesh_desc d;
        sfb__src_lines lines;
        memset(&d, 0, sizeof d);
        d.vertex_count = (int)(P.pos.n / 3);
        d.positions = (const float *)P.pos.p;
        d.face_count = (int)P.fsize.n;
        d.face_sizes = (const int *)P.fsize.p;
        d.face_vertices = (const int *)P.fv.p;
        d.crease_count = (int)P.cs.n;
        d.crease_vertices = (const int *)P.cv.p;
        d.crease_sharpness = (const float *)P.cs.p;
        d.corner_count = (int)P.ks.n;
        d.corner_vertices = (const int *)P.kv.p;
        d.corner_sharpness = (const float *)P.ks.p;
        d.hole_count = (int)P.holes.n;
        d.holes = (const int *)P.holes.p;
        if (P.uv_mismatch_face >= 0) {
            /* some faces with uv indices, some without: refuse rather than drop the uvs */
            P.line = P.uv_mismatch_line;
            r = sfb__perr(&P, SFB_INVALID_TOPOLOGY, "face %ld %s uv indices but face 0 %s (every face needs uvs, or none)",
                          P.uv_mismatch_face, P.first_has_uv ? "lacks" : "has", P.first_has_uv ? "has them" : "does not");
        } else if (P.first_has_uv == 1 && P.uv.n > 0) {
            d.uv_count = (int)(P.uv.n / 2);
            d.uvs = (const float *)P.uv.p;
            d.face_uvs = (const int *)P.fuv.p;
        }
        d.face_edge_sharpness = P.any_fsharp ? (const float *)P.fsharp.p : NULL;
        d.boundary = P.boundary;
        d.crease_method = P.crease_method;
        d.triangle_rule = P.triangle_rule;
        lines.face = (const int *)P.fline.p;
        lines.crease = (const int *)P.cline.p;
        lines.corner = (const int *)P.kline.p;
        lines.hole = (const int *)P.hline.p;
        if (r != SFB_SUCCESS) { /* reported above */ }
        else if (d.face_count == 0) r = sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_NONE, -1, "OBJ has no faces (line %ld is the last)", P.line);
        else r = sfb__mesh_create(ctx, &d, &lines, out);
    }
    sfb__objp_free(&P);
    return r;
}

/* ---- writer ---- */
typedef struct sfb__wbuf {
    sfb_write_fn fn;
    void *user;
    char buf[8192];
    size_t n;
    int failed;
} sfb__wbuf;

static void sfb__wflush(sfb__wbuf *w) {
    if (w->n && !w->failed && w->fn(w->buf, w->n, w->user)) w->failed = 1;
    w->n = 0;
}

static void sfb__wprintf(sfb__wbuf *w, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void sfb__wprintf(sfb__wbuf *w, const char *fmt, ...) {
    va_list ap;
    int k;
    if (w->n > sizeof w->buf - 256) sfb__wflush(w);
    va_start(ap, fmt);
    k = vsnprintf(w->buf + w->n, sizeof w->buf - w->n, fmt, ap);
    va_end(ap);
    if (k > 0 && (size_t)k < sizeof w->buf - w->n) w->n += (size_t)k;
}

SFB_API sfb_result sfb_write_obj(const sfb_mesh_desc *d, sfb_write_fn write, void *user) {
    sfb__wbuf wb, *w = &wb; /* on the stack: the writer has no context, so no allocator */
    int i, f, o = 0;
    static const int osd_boundary[3] = {2, 1, 0}; /* our enum -> OpenSubdiv's interpolateboundary */
    sfb_result r = SFB_SUCCESS;
    if (!d || !write || d->vertex_count < 0 || d->face_count < 0 || (d->vertex_count && !d->positions) ||
        (d->face_count && (!d->face_sizes || !d->face_vertices)))
        return SFB_INVALID_ARGS;
    w->fn = write; w->user = user; w->n = 0; w->failed = 0;
    sfb__wprintf(w, "# surfblend OBJ: %d vertices, %d faces\n", d->vertex_count, d->face_count);
    for (i = 0; i < d->vertex_count; ++i)
        sfb__wprintf(w, "v %.9g %.9g %.9g\n", d->positions[3 * i], d->positions[3 * i + 1], d->positions[3 * i + 2]);
    for (i = 0; i < d->uv_count; ++i) sfb__wprintf(w, "vt %.9g %.9g\n", d->uvs[2 * i], d->uvs[2 * i + 1]);
    for (f = 0; f < d->face_count; ++f) {
        int n = d->face_sizes[f], any = 0;
        if (n < 0 || n > SFB_MAX_FACE_SIZE) { r = SFB_INVALID_ARGS; break; }
        sfb__wprintf(w, "f");
        for (i = 0; i < n; ++i) {
            if (w->n > sizeof w->buf - 64) sfb__wflush(w);
            if (d->uv_count && d->face_uvs) sfb__wprintf(w, " %d/%d", d->face_vertices[o + i] + 1, d->face_uvs[o + i] + 1);
            else sfb__wprintf(w, " %d", d->face_vertices[o + i] + 1);
        }
        sfb__wprintf(w, "\n");
        if (d->face_edge_sharpness) {
            for (i = 0; i < n; ++i) any |= d->face_edge_sharpness[o + i] > 0.0f;
            if (any) {
                sfb__wprintf(w, "fs");
                for (i = 0; i < n; ++i) sfb__wprintf(w, " %.9g", d->face_edge_sharpness[o + i]);
                sfb__wprintf(w, "\n");
            }
        }
        o += n;
    }
    for (i = 0; i < d->crease_count; ++i)
        sfb__wprintf(w, "t crease 2/1/0 %d %d %.9g\n", d->crease_vertices[2 * i], d->crease_vertices[2 * i + 1], d->crease_sharpness[i]);
    for (i = 0; i < d->corner_count; ++i)
        sfb__wprintf(w, "t corner 1/1/0 %d %.9g\n", d->corner_vertices[i], d->corner_sharpness[i]);
    for (i = 0; i < d->hole_count; ++i) sfb__wprintf(w, "t hole 1/0/0 %d\n", d->holes[i]);
    if (d->boundary >= 0 && d->boundary <= 2) sfb__wprintf(w, "t interpolateboundary 1/0/0 %d\n", osd_boundary[d->boundary]);
    if (d->crease_method == SFB_CREASE_CHAIKIN) sfb__wprintf(w, "t creasemethod 0/0/1 chaikin\n");
    if (d->triangle_rule == SFB_TRI_SMOOTH) sfb__wprintf(w, "t smoothtriangles 0/0/1 smooth\n");
    sfb__wflush(w);
    if (r == SFB_SUCCESS && w->failed) r = SFB_IO_ERROR;
    return r;
}

SFB_API sfb_result sfb_mesh_write_obj(const sfb_mesh *mesh, sfb_write_fn write, void *user) {
    sfb_mesh_desc d;
    if (!mesh) return SFB_INVALID_ARGS;
    sfb_mesh_get_desc(mesh, &d);
    return sfb_write_obj(&d, write, user);
}
