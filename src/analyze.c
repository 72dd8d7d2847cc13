/* Seed 003: surface quality analysis evaluated exactly per pixel (sfb_surface_analyze).
 *
 * 1. Proxy: every parametric face that is not a hole is sampled on a uniform grid of 2^level
 *    segments per edge (a quad: (n+1)^2 points, a triangle: (n+1)(n+2)/2), evaluated through
 *    the backend's eval_patches; each grid triangle knows its face and its corners' (u,v) in
 *    that face, so rasterising it gives per pixel (face, u, v, depth) with perspective-correct
 *    (u,v): a pixel's (u,v) is always in its own face's frame. The backend's `raster` kernel
 *    draws it (sfb__raster_job: ref's on the CPU, simd's in bands over its threads, gl's and
 *    osmesa's in GL). Thin or grazing triangles (near a silhouette) also leave a seed in the
 *    uncovered pixels within 2 pixels of them. The faces' adjacency comes from the proxy too
 *    (sides whose ends and middle coincide).
 * 2. Projection (beyond the seed, which shades the proxy's (u,v), leaves gaps and patches them
 *    with a 1.7^2 larger viewport, its §5): each pixel is moved onto the exact surface along its
 *    own view ray. We solve in the picture plane: find (u,v) with proj(S(u,v)) = pixel centre,
 *    Newton on the 2x2 Jacobian d proj / d(u,v) = d proj / dP [S_u S_v], steps clamped to a
 *    third of the domain; a step that leaves the face carries on in the neighbour across the
 *    side it left by (at most 4 crossings), else the iterate is clamped and gives up after two
 *    steps against the border. Outcomes per attempt: HIT (residual below SFB__AN_TOL pixels),
 *    NEAR (within half a pixel after the steps: not converged), MISS (further: no surface there).
 *    Round 0 seeds the proxy pixels on a grid of every 4th pixel with their own (face, u, v),
 *    then the pixels between those hits from them (cubic Hermite in (u,v) along a picture axis,
 *    the hits' inverse screen Jacobians as tangents, across a face side in the two faces'
 *    unfolded frame), down to every pixel; an attempt that stalls over a pixel away stops
 *    early. Every later round seeds, from the hits the round
 *    before made or replaced, their 8 neighbours that are not hit yet, or hit on another face
 *    at least 1 % of the bounding radius farther away (a nearer sheet may hide them: near
 *    silhouettes the proxy's depth order is not the exact surface's); up to three faces per
 *    pixel and round; a pixel keeps its nearest hit.
 *    That grows coverage past the proxy's silhouette up to the exact one (pixels outside it MISS
 *    and stop the growth). The rounds end when a round changes nothing (at most SFB__AN_ROUNDS).
 *    Round 0's attempts own their hit slots (no two share a pixel) and run in chunks, each to
 *    its outcomes on one of the backend's threads; a hit's location and the inverse of its
 *    screen Jacobian are also kept per pixel, where the seeds and neighbour scans read them row
 *    by row.
 *    Then a proxy pixel without a hit is kept on the proxy's point when one attempt was NEAR
 *    (counted: fallback_pixels), and dropped when all MISSed (the exact surface is not there:
 *    counted: dropped_pixels); hits outside the proxy are counted as grown_pixels.
 * 3. Shade: the hits' exact positions, derivatives and normals (second derivatives for
 *    CURVATURE, evaluated once more there) go to the backend's `shade` kernel (ref's when it
 *    lacks one), which returns the mode's values.
 * 4. Colour: per pixel from its values, the band or pattern filtered by its footprint (the
 *    smaller one-sided difference of the value to its neighbours, per axis), so bands finer than
 *    a pixel fade to their average colour.
 * polygon_based: step 2 is skipped; position and normal are the proxy's interpolated limit
 * positions and limit normals (the polygon-based method of the seed's Fig. 7b).
 * Choices (the seed is silent): the camera's default orbit and the default light plane come
 * from the control mesh's bounding box, never the proxy's, so that the picture does not depend
 * on the level; the mean curvature's sign follows the normal turned toward the viewer, so a
 * surface bulging toward the eye has H > 0. */

#define SFB__AN_DEFAULT_W 640
#define SFB__AN_DEFAULT_H 480
#define SFB__AN_DEFAULT_LEVEL 2   /* a polygon-based picture's proxy level for a config's 0 (the others: sfb__an_auto_level) */
#define SFB__AN_DEFAULT_STEPS 8
#define SFB__AN_TOL 2e-3      /* pixels: a hit (looser ones let stripe classes flip where stripes are dense) */
#define SFB__AN_NEAR 0.5      /* pixels: within this, a non-converged attempt may fall back to the proxy */
#define SFB__AN_TOL2 (SFB__AN_TOL * SFB__AN_TOL)   /* the same, squared (sfb__an_step compares squared residuals) */
#define SFB__AN_NEAR2 (SFB__AN_NEAR * SFB__AN_NEAR)
#define SFB__AN_ROUNDS 64
#define SFB__AN_ANCHOR 4      /* pixels: round 0 starts from the proxy on this grid, the others between its hits */
#define SFB__AN_BATCH 32768   /* round 0's attempts run in batches of this many (the buffers stay small and warm: at
                                 1024 x 1024 on catmark_car, one batch per part held 41 MB, freshly faulted in per call),
                                 each in chunks of 1024 on the backend's threads (sfb__an_fresh) */
#define SFB__AN_BATCH_WS 131072 /* the same with a workspace, whose buffers are kept: fewer batches, fewer waits for the
                                 last chunk (catmark_car 1024 x 1024 on 2 threads: about 2 ms less); the pictures do not
                                 depend on the batch size (sfb__an_predict) */
#define SFB__AN_PARALLEL 4096  /* items: from this many on, a per-item loop goes to the backend's threads (sfb__parallel) */
#define SFB__AN_OUT_NEW_HIT 4
#define SFB__AN_CHUNKS 64     /* round 0: a batch runs in at most this many chunks, of 1024 attempts or more on average (sfb__an_fresh) */
#define SFB__AN_DILATE 2.0    /* pixels: uncovered pixels this close to a thin proxy triangle are seeded from it too */
#define SFB__AN_MARGIN 0.92   /* the bounding sphere's share of the smaller side (as sfb_render) */

SFB_API sfb_analyze_config sfb_analyze_config_init(int mode) {
    sfb_analyze_config c;
    memset(&c, 0, sizeof c);
    c.mode = mode;
    return c;
}

SFB_API void sfb_analysis_free(sfb_analysis *a) {
    if (!a) return;
    if (a->ctx_) {
        sfb__free(a->ctx_, a->rgba);
        sfb__free(a->ctx_, a->values);
        sfb__free(a->ctx_, a->classes);
        sfb__free(a->ctx_, a->hits);
    }
    memset(a, 0, sizeof *a);
}

static void sfb__an_unit3f(float *a) {
    double l = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
    if (l > 0.0 && isfinite(l)) { a[0] = (float)(a[0] / l); a[1] = (float)(a[1] / l); a[2] = (float)(a[2] / l); }
}
static int sfb__an_finite3(const float *p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }
/* The camera: right/up/forward unit vectors, pixels per unit (focal), the picture centre. */
typedef struct sfb__an_cam {
    double eye[3], right[3], up[3], fwd[3], focal, cx, cy, near_z;
    int ortho;
} sfb__an_cam;

/* Projects p: screen x, y (pixels, y down) and view depth z; returns 0 behind the near plane. */
static inline int sfb__an_project(const sfb__an_cam *c, const double *p, double *sx, double *sy, double *z) {
    double d[3], xc, yc, zc;
    d[0] = p[0] - c->eye[0]; d[1] = p[1] - c->eye[1]; d[2] = p[2] - c->eye[2];
    xc = sfb__rdot(d, c->right); yc = sfb__rdot(d, c->up); zc = sfb__rdot(d, c->fwd);
    *z = zc;
    if (c->ortho) { *sx = c->cx + c->focal * xc; *sy = c->cy - c->focal * yc; return 1; }
    if (!(zc > c->near_z)) return 0;
    *sx = c->cx + c->focal * xc / zc;
    *sy = c->cy - c->focal * yc / zc;
    return 1;
}

/* The screen Jacobian of a surface point p with tangents tu, tv: j = (dsx/du, dsx/dv, dsy/du,
 * dsy/dv) and its determinant; 0 when it is singular (or not finite). */
static inline int sfb__an_jacobian(const sfb__an_cam *c, const double *p, const double *tu, const double *tv, double j[4], double *det) {
    const double tux = sfb__rdot(tu, c->right), tuy = sfb__rdot(tu, c->up), tvx = sfb__rdot(tv, c->right), tvy = sfb__rdot(tv, c->up);
    if (c->ortho) {
        j[0] = c->focal * tux; j[2] = -c->focal * tuy;
        j[1] = c->focal * tvx; j[3] = -c->focal * tvy;
    } else {
        double d[3], xc, yc, zc, tuz, tvz, zz;
        d[0] = p[0] - c->eye[0]; d[1] = p[1] - c->eye[1]; d[2] = p[2] - c->eye[2];
        xc = sfb__rdot(d, c->right); yc = sfb__rdot(d, c->up); zc = sfb__rdot(d, c->fwd);
        tuz = sfb__rdot(tu, c->fwd); tvz = sfb__rdot(tv, c->fwd);
        zz = c->focal / (zc * zc);
        j[0] = (tux * zc - xc * tuz) * zz;
        j[2] = -(tuy * zc - yc * tuz) * zz;
        j[1] = (tvx * zc - xc * tvz) * zz;
        j[3] = -(tvy * zc - yc * tvz) * zz;
    }
    *det = j[0] * j[3] - j[1] * j[2];
    return fabs(*det) > 1e-18 && isfinite(*det);
}

/* ---- configuration checks ---- */
static int sfb__an_finite_n(const float *v, int n) {
    int i;
    for (i = 0; i < n; ++i) if (!isfinite(v[i])) return 0;
    return 1;
}
static sfb_result sfb__an_check(sfb_context *ctx, const sfb_analyze_config *c, int *w, int *h, int *level) {
    if (c->width == 0 && c->height == 0) { *w = SFB__AN_DEFAULT_W; *h = SFB__AN_DEFAULT_H; }
    else { *w = c->width; *h = c->height; }
    if (*w <= 0 || *h <= 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "analysis image size %d x %d: both must be >= 1 (both 0: the default 640 x 480)",
                          c->width, c->height);
    if (*w > SFB_ANALYZE_MAX_SIZE || *h > SFB_ANALYZE_MAX_SIZE)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "analysis image size %d x %d is over the limit of %d (SFB_ANALYZE_MAX_SIZE)",
                          *w, *h, SFB_ANALYZE_MAX_SIZE);
    if (c->mode < 0 || c->mode >= SFB_ANALYZE_MODE_COUNT_)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown analysis mode %d", c->mode);
    *level = c->level; /* 0: chosen in sfb_surface_analyze (sfb__an_auto_level) */
    if (*level < 0 || *level > SFB_ANALYZE_MAX_LEVEL)
        return sfb__error(ctx, c->level < 0 ? SFB_INVALID_ARGS : SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "proxy level %d is outside 1..%d",
                          c->level, SFB_ANALYZE_MAX_LEVEL);
    if (c->newton_steps < 0 || c->newton_steps > 64)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "newton_steps %d is outside 0..64", c->newton_steps);
    if (c->light_pattern < SFB_LIGHT_STRIPES || c->light_pattern > SFB_LIGHT_IMAGE)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown light pattern %d", c->light_pattern);
    if (c->curvature < SFB_CURVATURE_GAUSSIAN || c->curvature > SFB_CURVATURE_MAX_ABS)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown curvature kind %d", c->curvature);
    if (c->polygon_based && c->mode == SFB_ANALYZE_CURVATURE)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the polygon-based method has no second derivatives: no CURVATURE picture");
    if (!isfinite(c->yaw) || !isfinite(c->pitch) || !isfinite(c->zoom) || c->zoom < 0.0f || !isfinite(c->fov) || c->fov < 0.0f ||
        (!c->orthographic && !(c->fov < 179.0f)))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "view (yaw %g, pitch %g, zoom %g, fov %g): angles must be finite, zoom and fov >= 0, fov < 179 degrees",
                          (double)c->yaw, (double)c->pitch, (double)c->zoom, (double)c->fov);
    if (!isfinite(c->near_plane) || c->near_plane < 0.0f)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "near plane %g must be finite and >= 0 (0: automatic)", (double)c->near_plane);
    if (!c->camera_set && !sfb__an_finite_n(c->up, 3))
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "the orbit's up direction (%g, %g, %g) is not finite", (double)c->up[0],
                          (double)c->up[1], (double)c->up[2]);
    if (c->camera_set) {
        double d[3], up[3], x[3];
        int i;
        if (!sfb__an_finite_n(c->eye, 3) || !sfb__an_finite_n(c->target, 3) || !sfb__an_finite_n(c->up, 3))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "camera eye, target or up is not finite");
        for (i = 0; i < 3; ++i) { d[i] = (double)c->target[i] - c->eye[i]; up[i] = c->up[i]; }
        if (!(sfb__rnormalize(d) > 0.0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "camera eye equals its target");
        if (!(sfb__rdot(up, up) > 0.0)) up[1] = 1.0;
        sfb__rnormalize(up);
        sfb__rcross(d, up, x);
        if (!(sqrt(sfb__rdot(x, x)) > 1e-6))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "camera up (%g, %g, %g) is parallel to the view direction",
                              (double)c->up[0], (double)c->up[1], (double)c->up[2]);
    }
    if (!isfinite(c->stripes) || c->stripes < 0.0f || c->stripes > 1e5f || !isfinite(c->stripe_width) || c->stripe_width < 0.0f ||
        c->stripe_width >= 1.0f)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "stripes %g (0..1e5) and stripe width %g ([0, 1)) out of range",
                          (double)c->stripes, (double)c->stripe_width);
    if (!sfb__an_finite_n(c->light_dir, 3) || !isfinite(c->curvature_range) || c->curvature_range < 0.0f)
        return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "light direction or curvature range is not finite (range must be >= 0)");
    if (c->light_set) {
        double m[3], a[3], x[3];
        int i;
        if (!sfb__an_finite_n(c->light_center, 3) || !sfb__an_finite_n(c->light_normal, 3) || !sfb__an_finite_n(c->light_axis, 3) ||
            !sfb__an_finite_n(c->light_size, 2) || c->light_size[0] < 0.0f || c->light_size[1] < 0.0f)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "light plane centre, normal, axis or size is not finite (sizes >= 0)");
        for (i = 0; i < 3; ++i) { m[i] = c->light_normal[i]; a[i] = c->light_axis[i]; }
        if (!(sfb__rnormalize(m) > 0.0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "light plane normal is zero");
        sfb__rnormalize(a);
        sfb__rcross(m, a, x);
        if (!(sqrt(sfb__rdot(x, x)) > 1e-6))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "light plane axis (%g, %g, %g) is zero or parallel to its normal",
                              (double)c->light_axis[0], (double)c->light_axis[1], (double)c->light_axis[2]);
    }
    if (c->light_pattern == SFB_LIGHT_IMAGE && (c->mode == SFB_ANALYZE_REFLECTION || c->mode == SFB_ANALYZE_HIGHLIGHT)) {
        if (c->light_width <= 0 || c->light_height <= 0 || !c->light_rgba)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "image light of %d x %d texels%s: it needs texels and a size >= 1",
                              c->light_width, c->light_height, c->light_rgba ? "" : " without data");
        if (c->light_width > 16384 || c->light_height > 16384)
            return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "image light of %d x %d texels is over 16384", c->light_width,
                              c->light_height);
    }
    return SFB_SUCCESS;
}

/* ---- state of one analysis ---- */
typedef struct sfb__an {
    sfb_context *ctx;
    sfb_analysis_workspace *ws; /* NULL: none */
    const sfb_surface *s;
    const sfb_analyze_config *c;
    int w, h, tri, nf, R, per;   /* picture, triangle domain, parametric faces, grid segments, grid points per face */
    sfb__an_cam cam;
    double centre[3], radius;
    /* the proxy: grid points of every face (NaN for holes) */
    float *gpos, *gnrm;
    sfb__raster_vertex *rv;      /* the grid points in the picture */
    int *rtri, ntri;             /* the proxy's triangles (sfb__raster_job) */
    float *ybox;                 /* their y boxes (sfb__raster_job): rtri's, then the raster order's */
    float *zmax;                 /* the raster's scratch (sfb__raster_job) */
    unsigned char *ucov;         /* per 8 pixels of a row after the raster: 1 where one is not drawn (sfb__an_ucov_rows) */
    /* per pixel */
    float *depth;                /* +inf: empty */
    int *face;                   /* proxy face, -1: none */
    float *uv;                   /* proxy (u,v) */
    float *ppos, *pnrm;          /* polygon_based: interpolated proxy position and normal */
    int *cface;                  /* uncovered pixels within SFB__AN_DILATE pixels of a proxy triangle: its face, */
    float *cuv, *cdist;          /* the (u,v) of its nearest point, the distance in pixels */
    int *hit;                    /* index into the hit arrays, -1: none */
    sfb_location *hl;            /* per pixel (valid where hit >= 0): its hit's location, and */
    int seeding;                 /* round 0 runs a part that seeds later ones: hinv is kept up to date (sfb__an_store_hit) */
    float *hinv;                 /* d(u,v)/d(pixel x), d(u,v)/d(pixel y) there (NaN: singular): round 0's seeds and neighbour scans
                                    read these per pixel, row by row (the hit slots lie in round 0's part order, scattered) */
    int *adj;                    /* per face and side: (4 * neighbour face + its side) * 2 + reversed, -1: none */
    unsigned char *state;        /* SFB__AN_* per pixel */
    unsigned char *cand;         /* per pixel: 2 drawn by the proxy (face), 1 seeded beside a thin triangle (cface), 0 neither */
    /* hits (compact) */
    int nhit;
    int *chg, nchg;              /* the pixels of the hits made or replaced by the last batch of attempts */
    unsigned char *nbm;          /* per change: the neighbours it seeds (sfb__an_neighbours) */
    int *hpix;
    float *hpos, *hdu, *hdv, *hnrm, *hdepth; /* hdu, hdv: CURVATURE only (else NULL) */
} sfb__an;

enum { SFB__AN_NONE = 0, SFB__AN_TRIED_NEAR = 1, SFB__AN_HIT = 2 };

/* ---- the workspace (sfb_analysis_workspace): the large scratch buffers, by slot ---- */
enum {
    SFB__WS_GPOS, SFB__WS_GNRM, SFB__WS_RV, SFB__WS_RTRI, SFB__WS_DEPTH, SFB__WS_FACE, SFB__WS_UV, SFB__WS_HIT, SFB__WS_CFACE,
    SFB__WS_CUV, SFB__WS_CDIST, SFB__WS_STATE, SFB__WS_PPOS, SFB__WS_PNRM, SFB__WS_HPIX, SFB__WS_HLOC, SFB__WS_HPOS, SFB__WS_HDU,
    SFB__WS_HDV, SFB__WS_HNRM, SFB__WS_HDEPTH, SFB__WS_CHG, SFB__WS_TRIES, SFB__WS_LOCS, SFB__WS_BUF, SFB__WS_MARK, SFB__WS_ROWAT,
    SFB__WS_NBM, SFB__WS_HV1, SFB__WS_HV2, SFB__WS_V2, SFB__WS_SEC, SFB__WS_HINV, SFB__WS_HL, SFB__WS_CAND, SFB__WS_ZMAX, SFB__WS_NBC, SFB__WS_ADJ, SFB__WS_UCOV, SFB__WS_DONE, SFB__WS_YBOX, SFB__WS_COUNT
};
struct sfb_analysis_workspace {
    sfb_context *ctx;
    void *p[SFB__WS_COUNT];
    size_t n[SFB__WS_COUNT];
    int mark_base; /* the projection's round tags in the kept mark buffer start above it (sfb__an_project_all) */
    /* the proxy (GPOS, GNRM) and the face adjacency (ADJ) in the slots belong to the surface of
     * this serial at this level when proxy_ok (adj_ok): they depend on nothing else (not on the
     * view), so an analysis of it from another view reuses them (0: none kept) */
    unsigned long proxy_serial;
    int proxy_level, proxy_ok, adj_ok;
};

SFB_API sfb_result sfb_analysis_workspace_create(sfb_context *ctx, sfb_analysis_workspace **out) {
    sfb_analysis_workspace *ws;
    if (out) *out = NULL;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_analysis_workspace_create: NULL output");
    ws = (sfb_analysis_workspace *)sfb__alloc(ctx, sizeof *ws);
    if (!ws) return sfb__oom(ctx, "the analysis workspace");
    memset(ws, 0, sizeof *ws);
    ws->ctx = ctx;
    *out = ws;
    return SFB_SUCCESS;
}

SFB_API void sfb_analysis_workspace_destroy(sfb_analysis_workspace *ws) {
    int k;
    if (!ws) return;
    for (k = 0; k < SFB__WS_COUNT; ++k) sfb__free(ws->ctx, ws->p[k]);
    sfb__free(ws->ctx, ws);
}

SFB_API size_t sfb_analysis_workspace_bytes(const sfb_analysis_workspace *ws) {
    size_t b = 0;
    int k;
    if (!ws) return 0;
    for (k = 0; k < SFB__WS_COUNT; ++k) b += ws->n[k];
    return b;
}

/* A scratch buffer of at least `bytes` for slot `slot`: the workspace's (grown when too small:
 * the old contents are lost), else a fresh allocation. *fresh (when given) says whether the
 * memory is newly allocated. NULL when the allocation failed. */
static void *sfb__an_get(const sfb__an *A, int slot, size_t bytes, int *fresh) {
    sfb_analysis_workspace *ws = A->ws;
    if (fresh) *fresh = 1;
    if (!ws) return sfb__alloc(A->ctx, bytes);
    if (ws->p[slot] && ws->n[slot] >= bytes) {
        if (fresh) *fresh = 0;
        return ws->p[slot];
    }
    sfb__free(A->ctx, ws->p[slot]);
    ws->n[slot] = 0;
    ws->p[slot] = sfb__alloc(A->ctx, bytes);
    if (ws->p[slot]) ws->n[slot] = bytes;
    return ws->p[slot];
}

/* sfb__an_get zeroed (calloc). */
static void *sfb__an_get_zeroed(const sfb__an *A, int slot, size_t bytes) {
    void *p;
    if (!A->ws) return sfb__calloc(A->ctx, bytes, 1);
    p = sfb__an_get(A, slot, bytes, NULL);
    if (p) memset(p, 0, bytes);
    return p;
}

/* Grows slot's buffer p to `bytes`, keeping its contents (realloc); NULL when it failed (p is
 * then still valid). */
static void *sfb__an_regrow(const sfb__an *A, int slot, void *p, size_t bytes) {
    sfb_analysis_workspace *ws = A->ws;
    void *q = sfb__realloc(A->ctx, p, bytes);
    if (ws && q) { ws->p[slot] = q; ws->n[slot] = bytes; }
    return q;
}

/* Gives a buffer of sfb__an_get back: freed, unless the workspace keeps it. */
static void sfb__an_put(const sfb__an *A, void *p) {
    if (!A->ws) sfb__free(A->ctx, p);
}

/* sfb__parallel when there are enough items to be worth it (`work`, in items of ~100 ns),
 * else the task as one call. */
static void sfb__an_run(const sfb__an *A, void (*task)(void *arg, int first, int last), void *arg, int first, int last, double work) {
    if (work >= SFB__AN_PARALLEL) sfb__parallel(A->ctx, task, arg, first, last);
    else task(arg, first, last);
}

/* Whether the Newton attempts run in chunks over the backend's lent threads, each chunk
 * calling the backend's eval there (simd: that call then runs on that one thread); else in one
 * chunk on the calling thread, where a GPU backend's context is current and which evaluates a
 * batch at once. */
static int sfb__an_chunked(const sfb__an *A) {
    const sfb__backend_vtable *b = A->ctx->backend;
    return b && b->parallel && b->kernels_in_tasks;
}

static void sfb__an_grid_uv(const sfb__an *A, int k, double *u, double *v) {
    int R = A->R;
    if (!A->tri) { *u = (double)(k % (R + 1)) / R; *v = (double)(k / (R + 1)) / R; return; }
    {
        int j = 0, row = R + 1;
        while (k >= row) { k -= row; --row; ++j; }
        *u = (double)k / R;
        *v = (double)j / R;
    }
}
static int sfb__an_grid_index(const sfb__an *A, int i, int j) {
    int R = A->R;
    return A->tri ? j * (R + 1) - j * (j - 1) / 2 + i : j * (R + 1) + i;
}

/* Step 1a: the proxy's grid points, evaluated on the backend: face by face (a hole face's
 * points stay NaN), in runs of whole faces that lie one after another in the grid, at most
 * max(65536, points per face) locations a call; each face's (u,v) are the same grid. */
static sfb_result sfb__an_proxy(sfb__an *A) {
    const sfb__patch_table *pt = &A->s->patches;
    const size_t per = (size_t)A->per, chunk = per > ((size_t)1 << 16) ? per : ((size_t)1 << 16), n = (size_t)A->nf * per;
    sfb_location *loc = (sfb_location *)sfb__alloc(A->ctx, chunk * sizeof(sfb_location));
    float *gu = (float *)sfb__alloc(A->ctx, per * 2 * sizeof(float));
    sfb_result r = SFB_SUCCESS;
    size_t first = 0, cnt = 0, q;
    int f;
    if (!loc || !gu) {
        sfb__free(A->ctx, loc); sfb__free(A->ctx, gu);
        return sfb__oom(A->ctx, "the analysis proxy");
    }
    for (q = 0; q < per; ++q) {
        double u, v;
        sfb__an_grid_uv(A, (int)q, &u, &v);
        gu[2 * q] = (float)u;
        gu[2 * q + 1] = (float)v;
        if (A->tri && (double)gu[2 * q] + (double)gu[2 * q + 1] > 1.0) gu[2 * q + 1] = nextafterf(gu[2 * q + 1], 0.0f);
    }
    for (f = 0; f <= A->nf && r == SFB_SUCCESS; ++f) {
        const size_t base = (size_t)f * per;
        const int hole = f < A->nf && pt->ptex_root[f] == -1;
        /* the run so far is evaluated into place before a hole, before a face it has no room
         * for, and at the end */
        if (cnt > 0 && (f == A->nf || hole || cnt + per > chunk)) {
            sfb_eval_output out;
            memset(&out, 0, sizeof out);
            out.position = A->gpos + 3 * first;
            out.normal = A->gnrm + 3 * first;
            r = sfb__surface_eval_unchecked(A->s, loc, (int)cnt, &out);
            if (r == SFB_SUCCESS) r = sfb__progress(A->ctx, 0.2f * (float)(first + cnt) / (float)n, "analyze");
            cnt = 0;
        }
        if (f == A->nf || r != SFB_SUCCESS) break;
        if (hole) {
            for (q = 3 * base; q < 3 * (base + per); ++q) A->gpos[q] = A->gnrm[q] = NAN;
            continue;
        }
        if (cnt == 0) first = base;
        for (q = 0; q < per; ++q, ++cnt) {
            loc[cnt].face = f;
            loc[cnt].u = gu[2 * q];
            loc[cnt].v = gu[2 * q + 1];
        }
    }
    sfb__free(A->ctx, loc);
    sfb__free(A->ctx, gu);
    return r;
}

/* ---- parametric-face adjacency, from the proxy (for Newton steps that leave a face) ----
 * Sides: quad 0 (v = 0, u = t), 1 (u = 1, v = t), 2 (v = 1, u = 1 - t), 3 (u = 0, v = 1 - t);
 * triangle 0 (v = 0, u = t), 1 (u + v = 1, v = t), 2 (u = 0, v = 1 - t); t runs from the side's
 * first corner to its next. Two sides are neighbours when their ends and middles (proxy points,
 * evaluated from each face's own patch) coincide within 1e-5 bounding radii: a crease edge, a
 * Catmull-Clark n-gon's inner sides and a Loop edge alike. */
static void sfb__an_side_point(int tri, int side, double t, double *u, double *v) {
    if (tri) {
        if (side == 0) { *u = t; *v = 0.0; }
        else if (side == 1) { *u = 1.0 - t; *v = t; }
        else { *u = 0.0; *v = 1.0 - t; }
        return;
    }
    if (side == 0) { *u = t; *v = 0.0; }
    else if (side == 1) { *u = 1.0; *v = t; }
    else if (side == 2) { *u = 1.0 - t; *v = 1.0; }
    else { *u = 0.0; *v = 1.0 - t; }
}
/* The grid index of the point at t = k / R on a side. */
static int sfb__an_side_grid(const sfb__an *A, int side, int k) {
    int R = A->R;
    double u, v;
    sfb__an_side_point(A->tri, side, (double)k / R, &u, &v);
    return sfb__an_grid_index(A, (int)floor(u * R + 0.5), (int)floor(v * R + 0.5));
}
typedef struct sfb__an_side { long long key; int face, side; } sfb__an_side;
static int sfb__an_close(const float *a, const float *b, double tol) {
    return fabs((double)a[0] - b[0]) <= tol && fabs((double)a[1] - b[1]) <= tol && fabs((double)a[2] - b[2]) <= tol;
}
/* Sides a and b (the only two with their key) made neighbours when their ends coincide too
 * (ends[2 k], ends[2 k + 1]: the grid indices of side k's ends). */
static void sfb__an_pair(sfb__an *A, const sfb__an_side *a, const sfb__an_side *b, const int *ends, double tol) {
    const float *a0 = A->gpos + 3 * ((size_t)a->face * A->per + ends[2 * a->side]);
    const float *a1 = A->gpos + 3 * ((size_t)a->face * A->per + ends[2 * a->side + 1]);
    const float *b0 = A->gpos + 3 * ((size_t)b->face * A->per + ends[2 * b->side]);
    const float *b1 = A->gpos + 3 * ((size_t)b->face * A->per + ends[2 * b->side + 1]);
    int rev = sfb__an_close(a0, b1, tol) && sfb__an_close(a1, b0, tol), same = sfb__an_close(a0, b0, tol) && sfb__an_close(a1, b1, tol);
    if (a->face == b->face || (!rev && !same)) return;
    A->adj[4 * a->face + a->side] = (4 * b->face + b->side) * 2 + rev;
    A->adj[4 * b->face + b->side] = (4 * a->face + a->side) * 2 + rev;
}
/* Sides grouped by the hash of their middle point's cell (open addressing, a table of twice
 * as many slots as sides or more: one pass, where sorting the keys took spot.obj's 17.6k
 * sides 2-3 ms); a key held by exactly two sides pairs them (sfb__an_pair). */
static sfb_result sfb__an_adjacency(sfb__an *A) {
    int ns = A->tri ? 3 : 4, f, k, n = 0, i, mid[4], ends[8];
    double q = 1e-4 * A->radius, tol = 1e-5 * A->radius;
    size_t cap = 16, mask, h;
    sfb__an_side *sd = (sfb__an_side *)sfb__alloc(A->ctx, ((size_t)A->nf * ns + 1) * sizeof *sd);
    int *slot, *cnt, *two;
    while (cap < 2 * ((size_t)A->nf * ns + 1)) cap *= 2;
    mask = cap - 1;
    slot = (int *)sfb__alloc(A->ctx, cap * 3 * sizeof(int)); /* per slot: its first side (-1: empty); its count; its second side */
    if (!sd || !slot) {
        sfb__free(A->ctx, sd); sfb__free(A->ctx, slot);
        return sfb__oom(A->ctx, "the analysis face adjacency");
    }
    cnt = slot + cap;
    two = cnt + cap;
    for (h = 0; h < cap; ++h) slot[h] = -1;
    for (i = 0; i < A->nf * 4; ++i) A->adj[i] = -1;
    for (k = 0; k < ns; ++k) { /* the same grid points of every face */
        mid[k] = sfb__an_side_grid(A, k, A->R / 2);
        ends[2 * k] = sfb__an_side_grid(A, k, 0);
        ends[2 * k + 1] = sfb__an_side_grid(A, k, A->R);
    }
    for (f = 0; f < A->nf; ++f)
        for (k = 0; k < ns; ++k) {
            const float *m = A->gpos + 3 * ((size_t)f * A->per + mid[k]);
            unsigned long long hh = 1469598103934665603ull;
            int c;
            if (!sfb__an_finite3(m)) continue;
            for (c = 0; c < 3; ++c) { hh ^= (unsigned long long)(long long)floor(m[c] / q); hh *= 1099511628211ull; }
            sd[n].key = (long long)(hh >> 1); sd[n].face = f; sd[n].side = k;
            for (h = (size_t)(hh ^ (hh >> 29)) & mask; slot[h] >= 0 && sd[slot[h]].key != sd[n].key; h = (h + 1) & mask) {}
            if (slot[h] < 0) { slot[h] = n; cnt[h] = 1; }
            else if (cnt[h]++ == 1) two[h] = n;
            ++n;
        }
    for (h = 0; h < cap; ++h)
        if (slot[h] >= 0 && cnt[h] == 2) sfb__an_pair(A, &sd[slot[h]], &sd[two[h]], ends, tol);
    sfb__free(A->ctx, sd);
    sfb__free(A->ctx, slot);
    return SFB_SUCCESS;
}

/* The camera (the config's or sfb_render's orbit) from the control mesh's bounding box (not the
 * proxy's: the picture must not depend on the proxy's level). */
static void sfb__an_camera(sfb__an *A) {
    const sfb_analyze_config *c = A->c;
    double lo[3] = { HUGE_VAL, HUGE_VAL, HUGE_VAL }, hi[3] = { -HUGE_VAL, -HUGE_VAL, -HUGE_VAL };
    size_t n = (size_t)A->s->base_vertex_count, k;
    sfb__an_cam *cam = &A->cam;
    int i, any = 0, w = A->w, h = A->h;
    double half = 0.5 * (w < h ? w : h) * SFB__AN_MARGIN, zoom = c->zoom > 0.0f ? c->zoom : 1.0;
    double hfov = (c->fov > 0.0f && !c->orthographic ? c->fov : 30.0) * 0.5 * SFB__PI / 180.0;
    for (k = 0; k < n; ++k) {
        const float *p = A->s->base_positions + 3 * k;
        if (!sfb__an_finite3(p)) continue;
        for (i = 0; i < 3; ++i) { if (p[i] < lo[i]) lo[i] = p[i]; if (p[i] > hi[i]) hi[i] = p[i]; }
        any = 1;
    }
    if (!any) { lo[0] = lo[1] = lo[2] = -1.0; hi[0] = hi[1] = hi[2] = 1.0; }
    for (i = 0; i < 3; ++i) A->centre[i] = 0.5 * (lo[i] + hi[i]);
    A->radius = 0.5 * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (!(A->radius > 0.0) || !isfinite(A->radius)) A->radius = 1.0;
    memset(cam, 0, sizeof *cam);
    cam->ortho = c->orthographic != 0;
    cam->cx = 0.5 * w;
    cam->cy = 0.5 * h;
    if (c->camera_set) {
        double up[3];
        for (i = 0; i < 3; ++i) { cam->eye[i] = c->eye[i]; cam->fwd[i] = (double)c->target[i] - c->eye[i]; up[i] = c->up[i]; }
        sfb__rnormalize(cam->fwd);
        if (!(sfb__rdot(up, up) > 0.0)) up[1] = 1.0;
        sfb__rcross(cam->fwd, up, cam->right);
        sfb__rnormalize(cam->right);
        sfb__rcross(cam->right, cam->fwd, cam->up);
        sfb__rnormalize(cam->up);
        if (cam->ortho) cam->focal = c->fov > 0.0f ? h / (double)c->fov : half / A->radius;
        else cam->focal = 0.5 * h / tan(hfov);
    } else {
        double yaw = (c->view_set ? c->yaw : 30.0f) * SFB__PI / 180.0, pitch = (c->view_set ? c->pitch : 25.0f) * SFB__PI / 180.0;
        double dir[3], dist = A->radius / sin(hfov);
        dir[0] = cos(pitch) * sin(yaw); dir[1] = sin(pitch); dir[2] = cos(pitch) * cos(yaw);
        cam->right[0] = cos(yaw); cam->right[1] = 0.0; cam->right[2] = -sin(yaw);
        sfb__orbit_up(c->up, dir, cam->right);
        for (i = 0; i < 3; ++i) { cam->eye[i] = A->centre[i] + dist * dir[i]; cam->fwd[i] = -dir[i]; }
        sfb__rcross(cam->right, cam->fwd, cam->up);
        sfb__rnormalize(cam->up);
        cam->focal = cam->ortho ? half * zoom / A->radius : half * zoom / tan(hfov);
    }
    cam->near_z = c->near_plane > 0.0f ? c->near_plane : 1e-3 * A->radius;
}

/* The proxy level for a config's 0 (sfb_analyze_config.level): the coarsest from 1 to
 * SFB__AN_AUTO_MAX whose grid triangles cover at most SFB__AN_AUTO_PIXELS pixels each on
 * average, taking the picture of the surface as the bounding sphere's disc in this view (at
 * most the whole picture) spread over every parametric face. The proxy only seeds the
 * projection, so the picture does not depend on it (tests/analyze.c, level independence);
 * what it changes is the time: fewer, larger triangles raster and seed faster, as long as
 * the anchors' seeds stay close. Measured at 1024 x 1024, best of 3 (ms, level 1 / 2 / 3):
 * catmark_car 29.5 / 31.7 / 40.1, catmark_bishop 20.2 / 22.0 / 29.6, spot (Loop) 29.5 /
 * 34.3 / 49.5, cow (Loop) 30.3 / 35.4 / 51.5 (each level 1 here: 30 to 90 pixels per
 * triangle); catmark_torus (32 faces) 18.3 / 17.2 / 17.5 and catmark_cube (6 faces; level
 * 4: 12.6) 14.1 / 13.1 / 12.8, whose level-1 triangles cover thousands of pixels and whose
 * anchors then start far from the surface (levels 3 and 4 here). */
#define SFB__AN_AUTO_PIXELS 256.0
#define SFB__AN_AUTO_MAX 4
static int sfb__an_auto_level(const sfb__an *A) {
    const sfb__an_cam *cam = &A->cam;
    const double R = A->radius, full = (double)A->w * (double)A->h;
    double d2 = 0.0, rpx, area;
    int i, L;
    for (i = 0; i < 3; ++i) d2 += (A->centre[i] - cam->eye[i]) * (A->centre[i] - cam->eye[i]);
    if (cam->ortho) rpx = cam->focal * R;
    else rpx = d2 > 1.0001 * R * R ? cam->focal * R / sqrt(d2 - R * R) : HUGE_VAL; /* the sphere's silhouette cone */
    area = SFB__PI * rpx * rpx;
    if (!(area < full)) area = full;
    if (A->nf <= 0) return 1;
    for (L = 1; L < SFB__AN_AUTO_MAX; ++L)
        if (area <= SFB__AN_AUTO_PIXELS * (double)A->nf * (A->tri ? 1.0 : 2.0) * (double)(1 << (2 * L))) break;
    return L;
}

/* Step 1b, pass 2: the uncovered pixels within SFB__AN_DILATE pixels of a thin or grazing proxy
 * triangle (near the silhouette, where the exact surface may stick out past it, or where it
 * covers no pixel centre at all) get it as a seed: its face and the (u,v) of its nearest point
 * (the barycentric coordinates clamped), nearest triangle first. The others' neighbours are
 * reached by the projection's rounds. */
static void sfb__an_seed_tri(sfb__an *A, const int *tv, int row0, int row1) {
    const sfb__raster_vertex *S[3];
    const float *P[3];
    sfb__raster_edges t;
    double area, longest, elen[3], e1[3], e2[3], cr[3], a3, sc;
    int k, x, y;
    for (k = 0; k < 3; ++k) {
        S[k] = &A->rv[tv[k]];
        P[k] = A->gpos + 3 * (size_t)tv[k];
    }
    {
        /* the tiles of 8 x 8 pixels under the dilated box first: inside the surface's picture
         * every pixel is drawn and the triangle has nothing to seed (the box is a pixel wider
         * than sfb__raster_setup's; the tiles are sfb__an_ucov_rows') */
        const int nb = (A->w + 7) / 8;
        const unsigned char *tile = A->ucov + (size_t)A->h * (size_t)nb;
        double lx = S[0]->x, hx = lx, ly = S[0]->y, hy = ly;
        int tx0, tx1, ty0, ty1, any = 0;
        for (k = 1; k < 3; ++k) {
            if (S[k]->x < lx) lx = S[k]->x;
            if (S[k]->x > hx) hx = S[k]->x;
            if (S[k]->y < ly) ly = S[k]->y;
            if (S[k]->y > hy) hy = S[k]->y;
        }
        tx0 = (int)sfb__rclamp(floor(lx - 1.5 - SFB__AN_DILATE), 0.0, (double)A->w - 1.0) >> 3;
        tx1 = (int)sfb__rclamp(ceil(hx + 0.5 + SFB__AN_DILATE), 0.0, (double)A->w - 1.0) >> 3;
        ty0 = (int)sfb__rclamp(floor(ly - 1.5 - SFB__AN_DILATE), (double)row0, (double)row1 - 1.0) >> 3;
        ty1 = (int)sfb__rclamp(ceil(hy + 0.5 + SFB__AN_DILATE), (double)row0, (double)row1 - 1.0) >> 3;
        for (y = ty0; y <= ty1 && !any; ++y)
            for (x = tx0; x <= tx1; ++x)
                if (tile[(size_t)y * (size_t)nb + (size_t)x]) { any = 1; break; }
        if (!any) return;
    }
    /* thin or grazing first (most are neither): area as sfb__raster_setup has it */
    area = (S[1]->x - S[0]->x) * (S[2]->y - S[0]->y) - (S[2]->x - S[0]->x) * (S[1]->y - S[0]->y);
    for (k = 0; k < 3; ++k) { /* edge k, opposite corner k */
        const sfb__raster_vertex *p0 = S[(k + 1) % 3], *p1 = S[(k + 2) % 3];
        elen[k] = sqrt((p1->x - p0->x) * (p1->x - p0->x) + (p1->y - p0->y) * (p1->y - p0->y));
    }
    longest = elen[0] > elen[1] ? (elen[0] > elen[2] ? elen[0] : elen[2]) : (elen[1] > elen[2] ? elen[1] : elen[2]);
    for (k = 0; k < 3; ++k) { e1[k] = (double)P[1][k] - P[0][k]; e2[k] = (double)P[2][k] - P[0][k]; }
    sfb__rcross(e1, e2, cr);
    sc = A->cam.ortho ? A->cam.focal : A->cam.focal * 3.0 / (S[0]->z + S[1]->z + S[2]->z);
    a3 = sqrt(sfb__rdot(cr, cr)) * sc * sc; /* twice the area, in pixels, seen face-on */
    /* thin (under 2 pixels high) or grazing (seen at under 20 degrees): near the silhouette */
    if (!(fabs(area) < 2.0 * longest || fabs(area) < 0.35 * a3)) return;
    if (!sfb__raster_setup(S, A->w, A->h, SFB__AN_DILATE, &t)) return;
    if (t.y0 < row0) t.y0 = row0;
    if (t.y1 > row1 - 1) t.y1 = row1 - 1;
    if (t.y0 > t.y1) return;
    for (y = t.y0; y <= t.y1; ++y)
        for (x = t.x0; x <= t.x1; ++x) {
            const double px = x + 0.5, py = y + 0.5;
            const size_t pix = (size_t)y * (size_t)A->w + (size_t)x;
            double b[3], d = 0.0, sum;
            /* most of a thin triangle's box is drawn: whole drawn blocks of 8 skipped */
            if (!A->ucov[(size_t)y * (size_t)((A->w + 7) / 8) + (size_t)(x >> 3)]) { x |= 7; continue; }
            if (A->face[pix] >= 0) continue;
            for (k = 0; k < 3; ++k) b[k] = t.ea[k] * px + t.eb[k] * py + t.ec[k];
            if (b[0] >= 0.0 && b[1] >= 0.0 && b[2] >= 0.0) continue; /* inside: the raster's pixel */
            for (k = 0; k < 3; ++k)
                if (b[k] < 0.0 && elen[k] > 0.0) { double e = -b[k] * fabs(t.area) / elen[k]; if (e > d) d = e; }
            if (!(d <= SFB__AN_DILATE) || !(d < A->cdist[pix])) continue;
            for (k = 0; k < 3; ++k) b[k] = (b[k] < 0.0 ? 0.0 : b[k]) * S[k]->q;
            sum = b[0] + b[1] + b[2];
            if (!(sum > 0.0)) continue;
            A->cdist[pix] = (float)d;
            A->cface[pix] = tv[3];
            A->cuv[2 * pix] = (float)sfb__rclamp((b[0] * S[0]->u + b[1] * S[1]->u + b[2] * S[2]->u) / sum, 0.0, 1.0);
            A->cuv[2 * pix + 1] = (float)sfb__rclamp((b[0] * S[0]->v + b[1] * S[1]->v + b[2] * S[2]->v) / sum, 0.0, 1.0);
        }
}

/* Tile rows [t0, t1) (8 pixel rows each) after the raster: per block of 8 pixels of a row,
 * whether one is not drawn; and per tile of 8 x 8 pixels, whether one of its blocks is (after
 * the rows' blocks in A->ucov). */
static void sfb__an_ucov_rows(void *arg, int t0, int t1) {
    sfb__an *A = (sfb__an *)arg;
    const int nb = (A->w + 7) / 8;
    unsigned char *tile = A->ucov + (size_t)A->h * (size_t)nb;
    int ty, y, b, x;
    for (ty = t0; ty < t1; ++ty) {
        const int ye = 8 * ty + 8 < A->h ? 8 * ty + 8 : A->h;
        unsigned char *tu = tile + (size_t)ty * (size_t)nb;
        memset(tu, 0, (size_t)nb);
        for (y = 8 * ty; y < ye; ++y) {
            const int *f = A->face + (size_t)y * (size_t)A->w;
            unsigned char *u = A->ucov + (size_t)y * (size_t)nb;
            for (b = 0; b < nb; ++b) {
                const int xe = 8 * b + 8 < A->w ? 8 * b + 8 : A->w;
                int m = 0;
                for (x = 8 * b; x < xe; ++x) m |= f[x];
                u[b] = (unsigned char)(m < 0); /* a face of -1 sets the sign bit */
                tu[b] |= u[b];
            }
        }
    }
}

/* sfb__an_seed_tri over every proxy triangle, on rows [row0, row1) (bands of rows are
 * independent: a pixel's triangles are visited in order within its band). */
static void sfb__an_seed_rows_tri(void *arg, int row0, int row1) {
    sfb__an *A = (sfb__an *)arg;
    const double lo = row0 - 0.5 - SFB__AN_DILATE, hi = row1 + 0.5 + SFB__AN_DILATE;
    int k;
    for (k = 0; k < A->ntri; ++k) {
        /* the box's test is the vertices' (below or above the band), conservative */
        if ((double)A->ybox[2 * (size_t)k + 1] < lo || (double)A->ybox[2 * (size_t)k] > hi) continue;
        sfb__an_seed_tri(A, A->rtri + 4 * (size_t)k, row0, row1);
    }
}

/* The y boxes of the proxy's triangles [a, b) (rtri's) into A->ybox (sfb__raster_job's ybox;
 * sfb__an_order carries them into the raster's order). */
static void sfb__an_ybox(void *arg, int a, int b) {
    sfb__an *A = (sfb__an *)arg;
    const sfb__raster_vertex *rv = A->rv;
    int k;
    for (k = a; k < b; ++k) {
        const int *tv = A->rtri + 4 * (size_t)k;
        double lo = rv[tv[0]].y, hi = lo;
        float l, h;
        if (rv[tv[1]].y < lo) lo = rv[tv[1]].y;
        if (rv[tv[1]].y > hi) hi = rv[tv[1]].y;
        if (rv[tv[2]].y < lo) lo = rv[tv[2]].y;
        if (rv[tv[2]].y > hi) hi = rv[tv[2]].y;
        /* widened by more than float's rounding (2^-24 relative) before the conversion */
        l = (float)(lo - (1e-6 * fabs(lo) + 1e-3));
        h = (float)(hi + (1e-6 * fabs(hi) + 1e-3));
        A->ybox[2 * (size_t)k] = l;
        A->ybox[2 * (size_t)k + 1] = h;
    }
}

/* The proxy's grid points [a, b) projected into the picture (x NaN: behind the near plane or
 * not finite). */
static void sfb__an_project_grid(void *arg, int a, int b) {
    sfb__an *A = (sfb__an *)arg;
    int g;
    for (g = a; g < b; ++g) {
        const float *P = A->gpos + 3 * (size_t)g;
        sfb__raster_vertex *V = &A->rv[g];
        double p[3];
        V->x = NAN;
        if (!sfb__an_finite3(P)) continue;
        p[0] = P[0]; p[1] = P[1]; p[2] = P[2];
        if (!sfb__an_project(&A->cam, p, &V->x, &V->y, &V->z)) { V->x = NAN; continue; }
        V->q = A->cam.ortho ? 1.0 : 1.0 / V->z;
        sfb__an_grid_uv(A, g % A->per, &V->u, &V->v);
    }
}

/* Rows [y0, y1) after the raster: cand per pixel, and the row's proxy pixels into rowcnt[y]. */
typedef struct sfb__an_cand_job {
    sfb__an *A;
    int *rowcnt;
} sfb__an_cand_job;

static void sfb__an_candidates(void *arg, int y0, int y1) {
    const sfb__an_cand_job *J = (const sfb__an_cand_job *)arg;
    sfb__an *A = J->A;
    int y, x;
    for (y = y0; y < y1; ++y) {
        const size_t row = (size_t)y * (size_t)A->w;
        int n = 0;
        for (x = 0; x < A->w; ++x) {
            const int f = A->face[row + x];
            n += f >= 0;
            A->cand[row + x] = (unsigned char)(f >= 0 ? 2 : A->cface[row + x] >= 0 ? 1 : 0);
        }
        J->rowcnt[y] = n;
    }
}

/* Triangles of chunks [c0, c1) of SFB__AN_CHUNKS: whether each faces away (away[k]), and each
 * chunk's sum of six times the signed volumes of (centre, triangle) and of their sizes. */
typedef struct sfb__an_away_job {
    const sfb__an *A;
    unsigned char *away;
    double vol[SFB__AN_CHUNKS], mag[SFB__AN_CHUNKS];
} sfb__an_away_job;
static void sfb__an_away(void *arg, int c0, int c1) {
    sfb__an_away_job *J = (sfb__an_away_job *)arg;
    const sfb__an *A = J->A;
    int c, k;
    for (c = c0; c < c1; ++c) {
        const int a = (int)((long long)A->ntri * c / SFB__AN_CHUNKS), b = (int)((long long)A->ntri * (c + 1) / SFB__AN_CHUNKS);
        double vol = 0.0, mag = 0.0;
        for (k = a; k < b; ++k) {
            const int *tv = A->rtri + 4 * (size_t)k;
            double p[3][3], nr[3], d[3], e1[3], e2[3], t;
            int i, q;
            for (i = 0; i < 3; ++i)
                for (q = 0; q < 3; ++q) p[i][q] = (double)A->gpos[3 * (size_t)tv[i] + q] - A->centre[q];
            for (q = 0; q < 3; ++q) {
                e1[q] = p[1][q] - p[0][q];
                e2[q] = p[2][q] - p[0][q];
                d[q] = A->cam.ortho ? -A->cam.fwd[q] : A->cam.eye[q] - A->centre[q] - p[0][q];
            }
            sfb__rcross(e1, e2, nr);
            t = sfb__rdot(nr, p[0]);
            vol += t;
            mag += fabs(t);
            J->away[k] = (unsigned char)(sfb__rdot(nr, d) < 0.0);
        }
        J->vol[c] = vol;
        J->mag[c] = mag;
    }
}

/* Step 1b: the proxy's triangles reordered into ord[] (4 ints each; their y boxes into obox)
 * for the raster: those facing the eye first, then those facing away (each part in rtri's
 * order); the count of the first part.
 * "Facing" takes the outward side from the sign of the whole proxy's signed volume (+ when it is
 * about zero). On a closed proxy seen from outside, a view ray's first crossing enters it, so the
 * triangles facing away are never nearest; on an open one (catmark_car's wheel arches) some are.
 * Either way the raster draws the first part, then skips the triangles of the second that the
 * depth already drawn hides over their whole box (sfb__raster_job's nfront and zmax): the same
 * buffers, but for which of two triangles at exactly equal depth a pixel keeps. */
static int sfb__an_order(sfb__an *A, int *ord, float *obox) {
    sfb__an_away_job J;
    unsigned char *away = (unsigned char *)sfb__alloc(A->ctx, (size_t)A->ntri + 1);
    double vol = 0.0, mag = 0.0;
    int k, n = 0, sg;
    if (!away) { /* one part */
        memcpy(ord, A->rtri, (size_t)A->ntri * 4 * sizeof(int));
        memcpy(obox, A->ybox, (size_t)A->ntri * 2 * sizeof(float));
        return A->ntri;
    }
    /* over the threads in SFB__AN_CHUNKS parts, the sums combined in order */
    J.A = A;
    J.away = away;
    sfb__an_run(A, sfb__an_away, &J, 0, SFB__AN_CHUNKS, (double)A->ntri * 4.0);
    for (k = 0; k < SFB__AN_CHUNKS; ++k) { vol += J.vol[k]; mag += J.mag[k]; }
    sg = vol < -1e-6 * mag; /* 1: the proxy is inward-facing, "away" means facing the eye */
    for (k = 0; k < A->ntri; ++k)
        if (away[k] == sg) {
            memcpy(ord + 4 * (size_t)n, A->rtri + 4 * (size_t)k, 4 * sizeof(int));
            memcpy(obox + 2 * (size_t)n++, A->ybox + 2 * (size_t)k, 2 * sizeof(float));
        }
    {
        int m = n;
        for (k = 0; k < A->ntri; ++k)
            if (away[k] != sg) {
                memcpy(ord + 4 * (size_t)m, A->rtri + 4 * (size_t)k, 4 * sizeof(int));
                memcpy(obox + 2 * (size_t)m++, A->ybox + 2 * (size_t)k, 2 * sizeof(float));
            }
    }
    sfb__free(A->ctx, away);
    return n;
}

/* The raster kernel of the context's backend, or ref's. */
static sfb_result sfb__an_raster_kernel(const sfb__an *A, const sfb__raster_job *job) {
    sfb_context *ctx = A->ctx;
    const sfb__backend_vtable *be = ctx->backend;
    if (job->ntri == 0) return SFB_SUCCESS;
    if (!be || !be->raster) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks raster; using ref", be ? be->name : "none");
        return sfb__ref_raster(NULL, job);
    }
    return be->raster(ctx->backend_state, job);
}

/* Step 1b: the proxy's grid points projected into the picture (x NaN: behind the near plane or
 * not finite), its triangles (those with three such points, face by face), rasterised by the
 * backend's kernel, then pass 2's seeds around thin ones. */
static sfb_result sfb__an_raster(sfb__an *A) {
    size_t n = (size_t)A->nf * (size_t)A->per;
    int f, i, j, k, R = A->R;
    sfb__raster_job job;
    sfb_result r;
    A->ntri = 0;
    sfb__an_run(A, sfb__an_project_grid, A, 0, (int)n, (double)n); /* n <= INT_MAX: sfb_surface_analyze */
    for (f = 0; f < A->nf; ++f) {
        const size_t base = (size_t)f * (size_t)A->per;
        if (A->s->patches.ptex_root[f] == -1) continue;
        for (j = 0; j < R; ++j)
            for (i = 0; i < (A->tri ? R - j : R); ++i) {
                int q[2][3], nt = 1;
                if (A->tri) {
                    q[0][0] = sfb__an_grid_index(A, i, j); q[0][1] = sfb__an_grid_index(A, i + 1, j); q[0][2] = sfb__an_grid_index(A, i, j + 1);
                    if (i + j + 1 < R) {
                        q[1][0] = sfb__an_grid_index(A, i + 1, j); q[1][1] = sfb__an_grid_index(A, i + 1, j + 1);
                        q[1][2] = sfb__an_grid_index(A, i, j + 1);
                        nt = 2;
                    }
                } else {
                    q[0][0] = sfb__an_grid_index(A, i, j); q[0][1] = sfb__an_grid_index(A, i + 1, j); q[0][2] = sfb__an_grid_index(A, i + 1, j + 1);
                    q[1][0] = q[0][0]; q[1][1] = q[0][2]; q[1][2] = sfb__an_grid_index(A, i, j + 1);
                    nt = 2;
                }
                for (k = 0; k < nt; ++k) {
                    int *t = A->rtri + 4 * (size_t)A->ntri, c, ok = 1;
                    for (c = 0; c < 3; ++c) {
                        t[c] = (int)(base + (size_t)q[k][c]);
                        ok &= isfinite(A->rv[t[c]].x) != 0;
                    }
                    t[3] = f;
                    A->ntri += ok;
                }
            }
    }
    if ((r = sfb__progress(A->ctx, 0.2f, "analyze")) != SFB_SUCCESS) return r;
    memset(&job, 0, sizeof job);
    job.w = A->w; job.h = A->h; job.ortho = A->cam.ortho;
    job.ntri = A->ntri; job.vert = A->rv;
    job.tri = A->rtri + (size_t)A->nf * (size_t)A->per * 2 * 4; /* the second half: the raster's order */
    sfb__an_run(A, sfb__an_ybox, A, 0, A->ntri, (double)A->ntri * 2.0);
    job.ybox = A->ybox + 2 * (size_t)A->ntri;
    job.nfront = sfb__an_order(A, (int *)job.tri, A->ybox + 2 * (size_t)A->ntri);
    job.zmax = A->zmax;
    job.depth = A->depth; job.face = A->face; job.uv = A->uv;
    if (A->ppos) { job.apos = A->gpos; job.anrm = A->gnrm; job.pos = A->ppos; job.nrm = A->pnrm; }
    if ((r = sfb__an_raster_kernel(A, &job)) != SFB_SUCCESS) return r;
    if ((r = sfb__progress(A->ctx, 0.25f, "analyze")) != SFB_SUCCESS) return r;
    sfb__an_run(A, sfb__an_ucov_rows, A, 0, (A->h + 7) / 8, (double)A->w * A->h * 0.1);
    sfb__an_run(A, sfb__an_seed_rows_tri, A, 0, A->h, (double)A->ntri * 4.0);
    return SFB_SUCCESS;
}

/* ---- step 2: Newton projection, in batches ---- */
typedef struct sfb__an_try {
    int pix, x, y;     /* the pixel, its column and row */
    int k;             /* its hit slot (round 0, sfb__an_fresh) */
    double z;          /* a new hit's depth */
    float res, res2;   /* the squared residual of the last evaluation, and of the one before (pixels^2) */
    unsigned char pinned, crossed; /* steps against the border, face crossings */
    unsigned char outcome; /* 0 running, 1 hit, 2 near, 3 miss (SFB__AN_OUT_NEW_HIT: a hit the caller has yet to record) */
} sfb__an_try;

/* A new hit slot for pixel pix (not hit yet). */
static int sfb__an_new_slot(sfb__an *A, int pix) {
    const int k = A->nhit++;
    A->hpix[k] = pix;
    A->hit[pix] = k;
    A->state[pix] = SFB__AN_HIT;
    return k;
}

/* Hit slot k's data: the evaluation at loc, at depth z; and per pixel its location and, in
 * round 0's parts whose hits seed later parts (A->seeding), the inverse of its screen Jacobian
 * (computed once here: every seed taken from the hit reads it; those seeds are its only
 * readers, so round 0's last part and the later rounds, whose hits are recorded on one thread,
 * leave it, stale where they replace a hit). */
static void sfb__an_store_hit(sfb__an *A, size_t k, const sfb_location *loc, double z, const float *p, const float *du, const float *dv,
                              const float *n) {
    double pd[3], tu[3], tv[3], jac[4], det;
    const size_t pix = (size_t)A->hpix[k];
    float *m = A->hinv + 4 * pix;
    int c;
    A->hl[pix] = *loc;
    A->hdepth[k] = (float)z;
    for (c = 0; c < 3; ++c) {
        A->hpos[3 * k + c] = p[c]; A->hnrm[3 * k + c] = n[c];
        pd[c] = p[c]; tu[c] = du[c]; tv[c] = dv[c];
    }
    if (A->hdu)
        for (c = 0; c < 3; ++c) { A->hdu[3 * k + c] = du[c]; A->hdv[3 * k + c] = dv[c]; }
    if (!A->seeding) return;
    if (sfb__an_jacobian(&A->cam, pd, tu, tv, jac, &det)) {
        const double inv = 1.0 / det; /* one division (a hit's inverse is kept in float) */
        m[0] = (float)(jac[3] * inv); m[1] = (float)(-jac[2] * inv);
        m[2] = (float)(-jac[1] * inv); m[3] = (float)(jac[0] * inv);
    } else m[0] = m[1] = m[2] = m[3] = NAN;
}

/* Records the evaluation at loc as pixel pix's hit at depth z (a pixel already hit keeps the
 * nearer one). */
static void sfb__an_add_hit(sfb__an *A, int pix, const sfb_location *loc, double z, const float *p, const float *du, const float *dv,
                            const float *n) {
    int k = A->hit[pix];
    if (k >= 0) {
        if (!(z < A->hdepth[k] - 1e-6 * A->radius)) return;
    } else {
        k = sfb__an_new_slot(A, pix);
    }
    if ((size_t)A->nchg < (size_t)A->w * (size_t)A->h) A->chg[A->nchg++] = pix; /* a pixel listed twice is harmless */
    sfb__an_store_hit(A, (size_t)k, loc, z, p, du, dv, n);
}

/* Clamps (u,v) into the domain; returns 1 when it had to. */
static inline int sfb__an_clamp_domain(const sfb__an *A, double *u, double *v) {
    int moved = 0;
    if (*u < 0.0) { *u = 0.0; moved = 1; }
    if (*v < 0.0) { *v = 0.0; moved = 1; }
    if (*u > 1.0) { *u = 1.0; moved = 1; }
    if (*v > 1.0) { *v = 1.0; moved = 1; }
    if (A->tri && *u + *v > 1.0) {
        double e = 0.5 * (*u + *v - 1.0);
        *u -= e; *v -= e;
        if (*u < 0.0) { *v += *u; *u = 0.0; }
        if (*v < 0.0) { *u += *v; *v = 0.0; }
        moved = 1;
    }
    return moved;
}

/* The side a step to (uo, vo) left the domain by (clamped to (u, v)), and t on it; -1: none. */
static int sfb__an_exit_side(const sfb__an *A, double uo, double vo, double u, double v, double *t) {
    double over[4] = { 0.0, 0.0, 0.0, 0.0 };
    int k, best = -1;
    if (A->tri) {
        over[0] = -vo; over[2] = -uo; over[1] = uo + vo - 1.0;
    } else {
        over[0] = -vo; over[1] = uo - 1.0; over[2] = vo - 1.0; over[3] = -uo;
    }
    for (k = 0; k < (A->tri ? 3 : 4); ++k)
        if (over[k] > 0.0 && (best < 0 || over[k] > over[best])) best = k;
    if (best < 0) return -1;
    if (A->tri) *t = best == 0 ? u : best == 1 ? v : 1.0 - v;
    else *t = best == 0 ? u : best == 1 ? v : best == 2 ? 1.0 - u : 1.0 - v;
    *t = sfb__rclamp(*t, 0.0, 1.0);
    return best;
}

/* One Newton step of the running attempts [a, b) of a batch (sfb__an_step_job), from their
 * evaluations: the residual, the outcome, or the next (u,v) (crossing into a neighbour face
 * where the step leaves the face). A hit is not recorded here: its outcome is
 * SFB__AN_OUT_NEW_HIT, with its depth in z, and the caller records it (sfb__an_newton, in
 * attempt order on one thread; sfb__an_fresh, in its own slot). */
typedef struct sfb__an_step_job {
    const sfb__an *A;
    sfb__an_try *tries;
    sfb_location *locs;
    const float *pos, *du, *dv;
    int it, steps;
} sfb__an_step_job;

static void sfb__an_step(void *arg, int a, int b) {
    const sfb__an_step_job *J = (const sfb__an_step_job *)arg;
    const sfb__an *A = J->A;
    const float *pos = J->pos, *du = J->du, *dv = J->dv;
    const int it = J->it, steps = J->steps;
    int i;
    for (i = a; i < b; ++i) {
        sfb__an_try *t = &J->tries[i];
        sfb_location *l = &J->locs[i];
        const int x = t->x, y = t->y;
        double p[3], tu[3], tv[3], sx, sy, z, rx, ry, jac[4], det, du_, dv_, m, u, v, res;
        /* res: the squared residual (pixels^2), so that no square root waits before the tests */
        int c, ok;
        for (c = 0; c < 3; ++c) { p[c] = pos[3 * i + c]; tu[c] = du[3 * i + c]; tv[c] = dv[3 * i + c]; }
        ok = sfb__an_finite3(pos + 3 * i) && sfb__an_project(&A->cam, p, &sx, &sy, &z);
        res = HUGE_VAL;
        if (ok) {
            rx = (x + 0.5) - sx; ry = (y + 0.5) - sy;
            res = rx * rx + ry * ry;
        }
        /* stalled: an attempt whose residual has not halved over the last two steps and is
         * over a pixel (a pixel off the exact silhouette, or across a face it cannot reach)
         * stops as a miss instead of running out its steps (at half a pixel, a few more
         * silhouette pixels were dropped on catmark_car and spot) */
        if (ok && it >= 2 && res > 1.0 && !(res < 0.25 * t->res2)) { t->res = (float)res; t->outcome = 3; continue; }
        /* and one within a pixel of the pixel but not converging (not halved over two steps by
         * its fifth evaluation: beside a silhouette, where round 1 tries thousands of pixels)
         * stops too, as near or a miss (catmark_car: round 1's evaluations -15 %, coverage the same) */
        if (ok && it >= 4 && res > 0.05 * 0.05 && !(res < 0.25 * t->res2)) {
            t->res = (float)res;
            t->outcome = res < SFB__AN_NEAR2 ? 2 : 3;
            continue;
        }
        t->res2 = t->res;
        t->res = (float)res;
        if (ok && res < SFB__AN_TOL2) { t->z = z; t->outcome = SFB__AN_OUT_NEW_HIT; continue; }
        if (!ok || it == steps) { t->outcome = ok && res < SFB__AN_NEAR2 ? 2 : 3; continue; }
        if (!sfb__an_jacobian(&A->cam, p, tu, tv, jac, &det)) { t->outcome = res < SFB__AN_NEAR2 ? 2 : 3; continue; }
        du_ = (jac[3] * rx - jac[1] * ry) / det;
        dv_ = (-jac[2] * rx + jac[0] * ry) / det;
        m = fabs(du_) > fabs(dv_) ? fabs(du_) : fabs(dv_);
        if (m > 0.34) { du_ *= 0.34 / m; dv_ *= 0.34 / m; }
        u = l->u + du_;
        v = l->v + dv_;
        if (sfb__an_clamp_domain(A, &u, &v)) {
            /* left the face: carry on in the neighbour across the side it left by (at most
             * 4 crossings), else give up after two steps against the border */
            double uo = l->u + du_, vo = l->v + dv_, ts = 0.0;
            int side = sfb__an_exit_side(A, uo, vo, u, v, &ts), nb = side >= 0 ? A->adj[4 * l->face + side] : -1;
            if (nb >= 0 && t->crossed < 4) {
                int nside = (nb >> 1) & 3, nf = nb >> 3;
                sfb__an_side_point(A->tri, nside, (nb & 1) ? 1.0 - ts : ts, &u, &v);
                l->face = nf;
                ++t->crossed;
                t->pinned = 0;
            } else if (++t->pinned >= 2) { t->outcome = res < SFB__AN_NEAR2 ? 2 : 3; continue; }
        } else t->pinned = 0;
        l->u = (float)u;
        l->v = (float)v;
        if (A->tri && (double)l->u + (double)l->v > 1.0) l->v = nextafterf(l->v, 0.0f);
    }
}

/* An attempt's outcome for a later round's recording (sfb__an_newton): its pixel, outcome and,
 * for a hit, the evaluation and depth. */
typedef struct sfb__an_done {
    float p[3], du[3], dv[3], n[3];
    double z;
    sfb_location loc;
    int pix;
    unsigned char outcome;
} sfb__an_done;

/* Round 0's attempts (sfb__an_project_all): no attempt's pixel is hit yet and no two share a
 * pixel, so attempt i of a batch owns hit slot base + i (tries[i].k), which it fills when it
 * hits and leaves a hole (hpix -1) when it does not; sfb__an_fill_holes closes the holes after
 * round 0. The batch is cut into `nchunks` chunks, each run to its outcomes on its own
 * (evaluate, step, record, move the running ones first, within the chunk), over the backend's
 * threads: no step waits for the whole batch, and nothing runs on one thread between steps.
 * The chunks shrink from about twice the mean to a few attempts (chunk c starts at
 * count (1 - (1 - c / nchunks)^2)): the backend hands its threads runs of equally many chunks,
 * so the last run taken is short and the other threads wait less for it. One chunk, on the
 * calling thread, when the backend's kernels may not run in lent tasks (sfb__an_chunked: a GPU
 * evaluates a batch at once, and its context is current on the calling thread alone); its
 * step and record loops then go to the threads. res[c]: chunk c's evaluation result. The later
 * rounds' attempts run here too, with `done` (sfb__an_newton). */
typedef struct sfb__an_fresh_job {
    sfb__an *A;
    sfb__an_try *tries;
    sfb_location *locs;
    float *pos, *du, *dv, *nrm;
    int count, nchunks, steps;
    sfb_result *res;
    sfb__an_done *done; /* NULL: round 0 (the attempts record their own hits); else the later rounds: attempt
                           tries[i].k's outcome into done[tries[i].k], recorded after the chunks */
} sfb__an_fresh_job;

static int sfb__an_fresh_start(const sfb__an_fresh_job *F, int c) {
    const long long x = F->nchunks - c, n2 = (long long)F->nchunks * F->nchunks;
    return F->count - (int)((long long)F->count * x * x / n2);
}

/* The attempts of a chunk that ended this step (outcome != 0), each into its own slot: round
 * 0's hit slot tries[i].k and pixel (no two of its attempts share one), or a later round's
 * done[tries[i].k]; so they may run in parallel, and the chunk moves its running attempts
 * first afterwards. */
typedef struct sfb__an_record_job {
    const sfb__an_fresh_job *F;
    const sfb__an_try *tries;
    const sfb_location *locs;
    const float *pos, *du, *dv, *nrm;
} sfb__an_record_job;

static void sfb__an_record(void *arg, int a, int b) {
    const sfb__an_record_job *R = (const sfb__an_record_job *)arg;
    const sfb__an_fresh_job *F = R->F;
    sfb__an *A = F->A;
    const sfb__an_try *tries = R->tries;
    const sfb_location *locs = R->locs;
    const float *pos = R->pos, *du = R->du, *dv = R->dv, *nrm = R->nrm;
    int i;
    for (i = a; i < b; ++i) {
        const sfb__an_try *t = &tries[i];
        if (t->outcome == 0) continue;
        if (F->done) {
            sfb__an_done *o = &F->done[t->k];
            int q;
            o->pix = t->pix;
            o->outcome = t->outcome;
            if (t->outcome == SFB__AN_OUT_NEW_HIT) {
                for (q = 0; q < 3; ++q) {
                    o->p[q] = pos[3 * i + q]; o->du[q] = du[3 * i + q]; o->dv[q] = dv[3 * i + q]; o->n[q] = nrm[3 * i + q];
                }
                o->z = t->z;
                o->loc = locs[i];
            }
            continue;
        }
        if (t->outcome == SFB__AN_OUT_NEW_HIT) {
            A->hpix[t->k] = t->pix;
            A->hit[t->pix] = t->k;
            A->state[t->pix] = SFB__AN_HIT;
            sfb__an_store_hit(A, (size_t)t->k, &locs[i], t->z, pos + 3 * i, du + 3 * i, dv + 3 * i, nrm + 3 * i);
        } else {
            A->hpix[t->k] = -1;
            if (t->outcome == 2) A->state[t->pix] = SFB__AN_TRIED_NEAR;
        }
    }
}

static void sfb__an_fresh(void *arg, int c0, int c1) {
    const sfb__an_fresh_job *F = (const sfb__an_fresh_job *)arg;
    sfb__an *A = F->A;
    int c;
    for (c = c0; c < c1; ++c) {
        const int a = sfb__an_fresh_start(F, c), n = sfb__an_fresh_start(F, c + 1) - a;
        sfb__an_try *tries = F->tries + a;
        sfb_location *locs = F->locs + a;
        float *pos = F->pos + 3 * (size_t)a, *du = F->du + 3 * (size_t)a, *dv = F->dv + 3 * (size_t)a, *nrm = F->nrm + 3 * (size_t)a;
        sfb__an_step_job J;
        sfb__an_record_job R;
        int active = n, it, i;
        F->res[c] = SFB_SUCCESS;
        R.F = F;
        J.A = A; J.tries = tries; J.locs = locs; J.pos = pos; J.du = du; J.dv = dv; J.steps = F->steps;
        for (it = 0; it <= F->steps && active > 0; ++it) {
            sfb_eval_output out;
            int keep = 0;
            memset(&out, 0, sizeof out);
            out.position = pos; out.du = du; out.dv = dv; out.normal = nrm;
            if ((F->res[c] = sfb__surface_eval_unchecked(A->s, locs, active, &out)) != SFB_SUCCESS) {
                if (!F->done)
                    for (i = 0; i < active; ++i) A->hpix[tries[i].k] = -1;
                break;
            }
            J.it = it;
            R.tries = tries; R.locs = locs; R.pos = pos; R.du = du; R.dv = dv; R.nrm = nrm;
            if (F->nchunks == 1) {
                /* one chunk on the calling thread (sfb__an_chunked): its loops go to the threads */
                sfb__an_run(A, sfb__an_step, &J, 0, active, (double)active * 8.0);
                sfb__an_run(A, sfb__an_record, &R, 0, active, (double)active * 4.0);
            } else {
                sfb__an_step(&J, 0, active);
                sfb__an_record(&R, 0, active);
            }
            for (i = 0; i < active; ++i)
                if (tries[i].outcome == 0) {
                    if (keep != i) { tries[keep] = tries[i]; locs[keep] = locs[i]; }
                    ++keep;
                }
            active = keep;
        }
    }
}

/* Closes the holes round 0 left in the hit slots (sfb__an_fresh): the last slots move into
 * them (the slots' order means nothing: the per-pixel arrays say which pixel has which). */
static void sfb__an_fill_holes(sfb__an *A) {
    int k = 0, last = A->nhit - 1;
    for (;;) {
        while (last >= 0 && A->hpix[last] < 0) --last;
        while (k < last && A->hpix[k] >= 0) ++k;
        if (k >= last) break;
        {
            const size_t to = (size_t)k, from = (size_t)last;
            int c;
            A->hpix[to] = A->hpix[from];
            A->hdepth[to] = A->hdepth[from];
            for (c = 0; c < 3; ++c) {
                A->hpos[3 * to + c] = A->hpos[3 * from + c]; A->hnrm[3 * to + c] = A->hnrm[3 * from + c];
                if (A->hdu) { A->hdu[3 * to + c] = A->hdu[3 * from + c]; A->hdv[3 * to + c] = A->hdv[3 * from + c]; }
            }
            A->hit[A->hpix[to]] = k;
            A->hpix[from] = -1;
        }
    }
    A->nhit = last + 1;
}

/* Runs a later round's attempts (tries[i] for pixel tries[i].pix from locs[i]) to their
 * outcomes, then records the hits in attempt order (sfb__an_add_hit: a pixel already hit keeps
 * the nearer one). The attempts run as round 0's do (sfb__an_fresh: in shrinking chunks over
 * the backend's threads, each chunk to its outcomes), but, since several attempts may share a
 * pixel here, leave their outcomes in a list that is recorded afterwards on one thread. */
static sfb_result sfb__an_newton(sfb__an *A, sfb__an_try *tries, sfb_location *locs, int count, float *buf, int steps) {
    sfb__an_fresh_job F;
    sfb_result res[SFB__AN_CHUNKS];
    sfb__an_done *done = (sfb__an_done *)sfb__an_get(A, SFB__WS_DONE, (size_t)count * sizeof *done, NULL);
    const int nck = sfb__an_chunked(A) ? (count + 511) / 512 : 1;
    int i, c;
    if (!done) return sfb__oom(A->ctx, "the analysis projection");
    for (i = 0; i < count; ++i) tries[i].k = i; /* each attempt's index in the round, for its outcome */
    memset(&F, 0, sizeof F);
    F.A = A; F.tries = tries; F.locs = locs; F.count = count; F.steps = steps; F.res = res; F.done = done;
    F.pos = buf; F.du = buf + 3 * (size_t)count; F.dv = buf + 6 * (size_t)count; F.nrm = buf + 9 * (size_t)count;
    F.nchunks = nck < SFB__AN_CHUNKS ? nck : SFB__AN_CHUNKS;
    if (F.nchunks > 1) sfb__an_run(A, sfb__an_fresh, &F, 0, F.nchunks, (double)count * 8.0);
    else sfb__an_fresh(&F, 0, 1); /* on this thread (sfb__an_chunked) */
    for (c = 0; c < F.nchunks; ++c)
        if (res[c] != SFB_SUCCESS) { sfb__an_put(A, done); return res[c]; }
    /* the outcomes in attempt order: new hits recorded, near ones marked (a later hit of the
     * pixel overrides that) */
    for (i = 0; i < count; ++i) {
        const sfb__an_done *o = &done[i];
        if (o->outcome == SFB__AN_OUT_NEW_HIT) sfb__an_add_hit(A, o->pix, &o->loc, o->z, o->p, o->du, o->dv, o->n);
        else if (o->outcome == 2 && A->state[o->pix] == SFB__AN_NONE) A->state[o->pix] = SFB__AN_TRIED_NEAR;
    }
    sfb__an_put(A, done);
    return SFB_SUCCESS;
}

/* d(u,v)/d(pixel) along the picture's axis `axis` (0: x, 1: y) at the hit of pixel pix: its
 * screen Jacobian's inverse applied to that axis (sfb__an_store_hit); 0 when it is singular. */
static int sfb__an_uv_per_pixel(const sfb__an *A, size_t pix, int axis, double m[2]) {
    const float *h = A->hinv + 4 * pix + 2 * axis;
    if (!(isfinite(h[0]) && isfinite(h[1]))) return 0;
    m[0] = h[0];
    m[1] = h[1];
    return 1;
}

/* The part of round 0 that seeds pixel (x, y) (sfb__an_project_all: 0 the anchors, every
 * SFB__AN_ANCHOR = 4 pixels; 1 and 2 one or both coordinates odd multiples of 2; 3 and 4 of 1). */
static int sfb__an_part_of(int x, int y) {
    const int ox = x & 1, oy = y & 1;
    if (ox | oy) return 2 + ox + oy;
    return (x & 2) || (y & 2) ? ((x & 2) && (y & 2) ? 2 : 1) : 0;
}

/* A seed for pixel (x, y) from a hit neighbour d pixels away of an earlier part (of its proxy face, else any):
 * the neighbour's (u,v) moved by the inverse of its screen Jacobian towards (x, y); loc is kept
 * when no neighbour is hit or the Jacobian is singular. */
static void sfb__an_predict(const sfb__an *A, int x, int y, int d, int part, sfb_location *loc) {
    int dx, dy, best = -1, bdx = 0, bdy = 0;
    double mx[2], my[2], u, v;
    for (dy = -d; dy <= d; dy += d)
        for (dx = -d; dx <= d; dx += d) {
            int nx = x + dx, ny = y + dy, q;
            if ((dx | dy) == 0 || nx < 0 || ny < 0 || nx >= A->w || ny >= A->h) continue;
            /* only the parts before this one: their hits are all in, whatever the batches (a
             * neighbour of this part is hit or not depending on where a batch ended) */
            if (sfb__an_part_of(nx, ny) >= part) continue;
            q = ny * A->w + nx;
            if (A->hit[q] < 0) continue;
            if (best < 0 || (A->hl[q].face == loc->face && A->hl[best].face != loc->face)) { best = q; bdx = dx; bdy = dy; }
        }
    if (best < 0 || !sfb__an_uv_per_pixel(A, (size_t)best, 0, mx) || !sfb__an_uv_per_pixel(A, (size_t)best, 1, my)) return;
    u = A->hl[best].u - mx[0] * bdx - my[0] * bdy;
    v = A->hl[best].v - mx[1] * bdx - my[1] * bdy;
    if (!isfinite(u) || !isfinite(v)) return;
    sfb__an_clamp_domain(A, &u, &v);
    loc->face = A->hl[best].face;
    loc->u = (float)u;
    loc->v = (float)v;
}

/* Side k's own frame of a face's point (u, v): t along the side (sfb__an_side_point's t), s
 * from the side inward (1 at the opposite corner or side); and back. */
static void sfb__an_side_frame(int tri, int k, double u, double v, double *t, double *s) {
    if (tri) {
        if (k == 0) { *t = u; *s = v; }
        else if (k == 1) { *t = v; *s = 1.0 - u - v; }
        else { *t = 1.0 - v; *s = u; }
        return;
    }
    if (k == 0) { *t = u; *s = v; }
    else if (k == 1) { *t = v; *s = 1.0 - u; }
    else if (k == 2) { *t = 1.0 - u; *s = 1.0 - v; }
    else { *t = 1.0 - v; *s = u; }
}
static void sfb__an_side_unframe(int tri, int k, double t, double s, double *u, double *v) {
    if (tri) {
        if (k == 0) { *u = t; *v = s; }
        else if (k == 1) { *u = 1.0 - s - t; *v = t; }
        else { *u = s; *v = 1.0 - t; }
        return;
    }
    if (k == 0) { *u = t; *v = s; }
    else if (k == 1) { *u = 1.0 - s; *v = t; }
    else if (k == 2) { *u = 1.0 - t; *v = 1.0 - s; }
    else { *u = s; *v = 1.0 - t; }
}

/* A point (u, v) of face G in the frame of its neighbour F across G's side kg (F's side kf; rev:
 * the sides run opposite ways, as A->adj has it), F's domain extended over the side: the two
 * faces unfolded into one plane, G's side onto F's and G's inside beyond it, as two squares of
 * a regular grid (Catmull-Clark), or two triangles of a regular lattice, which make a
 * parallelogram (Loop: G's opposite corner lands on F's corner point-reflected through the
 * side's middle). The same call with F and G swapped is its inverse. */
static void sfb__an_unfold(int tri, int kg, int kf, int rev, double u, double v, double *uf, double *vf) {
    double t, s, tf;
    sfb__an_side_frame(tri, kg, u, v, &t, &s);
    tf = rev ? 1.0 - t : t;
    if (tri) {
        /* the opposite corner's t per side: (0, 1), (0, 0), (1, 0) */
        const double og = kg == 2 ? 1.0 : 0.0, of = kf == 2 ? 1.0 : 0.0;
        tf += ((1.0 - of) - (rev ? 1.0 - og : og)) * s;
    }
    sfb__an_side_unframe(tri, kf, tf, -s, uf, vf);
}

/* Whether (u, v) lies in the face's domain, within eps. */
static int sfb__an_in_domain(const sfb__an *A, double u, double v, double eps) {
    if (!(u >= -eps && v >= -eps)) return 0;
    return A->tri ? u + v <= 1.0 + eps : u <= 1.0 + eps && v <= 1.0 + eps;
}

/* A seed for pixel (x, y) between two hits, d pixels either side along `axis`: the cubic
 * Hermite interpolant of their (u,v) with their d(u,v)/d(pixel) as end tangents, at its
 * middle, (a + b) / 2 + d (m_a - m_b) / 4 (the hits 2d pixels apart), off by fourth-order terms
 * only, so that the pixel usually hits at its first evaluation (a one-sided linear prediction
 * is off by the second-order term, above SFB__AN_TOL where a patch spans under ~100 pixels).
 * Two hits on neighbouring faces (across a side of A->adj) are interpolated with b's (u,v) and
 * tangent unfolded into a's frame (sfb__an_unfold), and the middle is put on the face it lands
 * in (catmark_car at 1024 x 1024: 9 % of round 0's pixels have their two hits on two faces,
 * and took 2.2 evaluations each from the one-sided prediction). 0 (loc kept) when either hit is
 * missing, they lie on faces that are not neighbours, the middle lands on neither face (next to
 * a corner) or a Jacobian is singular. */
static int sfb__an_hermite(const sfb__an *A, int x, int y, int axis, int d, sfb_location *loc) {
    const int dx = axis ? 0 : d, dy = axis ? d : 0;
    const int ns = A->tri ? 3 : 4;
    double ma[2], mb[2], ub, vb, u, v;
    size_t a, b;
    int fa, fb, kf = 0, nb = -1;
    if (x - dx < 0 || y - dy < 0 || x + dx >= A->w || y + dy >= A->h) return 0;
    a = (size_t)(y - dy) * (size_t)A->w + (size_t)(x - dx);
    b = (size_t)(y + dy) * (size_t)A->w + (size_t)(x + dx);
    if (A->hit[a] < 0 || A->hit[b] < 0) return 0;
    if (!sfb__an_uv_per_pixel(A, a, axis, ma) || !sfb__an_uv_per_pixel(A, b, axis, mb)) return 0;
    fa = A->hl[a].face;
    fb = A->hl[b].face;
    ub = A->hl[b].u;
    vb = A->hl[b].v;
    if (fa != fb) {
        /* b's point and tangent into a's frame, across their shared side */
        double u1, v1;
        for (kf = 0; kf < ns; ++kf) {
            nb = A->adj[4 * fa + kf];
            if (nb >= 0 && (nb >> 3) == fb) break;
        }
        if (kf == ns) return 0;
        sfb__an_unfold(A->tri, (nb >> 1) & 3, kf, nb & 1, ub + mb[0], vb + mb[1], &u1, &v1);
        sfb__an_unfold(A->tri, (nb >> 1) & 3, kf, nb & 1, ub, vb, &ub, &vb);
        mb[0] = u1 - ub;
        mb[1] = v1 - vb;
    }
    u = 0.5 * ((double)A->hl[a].u + ub) + 0.25 * d * (ma[0] - mb[0]);
    v = 0.5 * ((double)A->hl[a].v + vb) + 0.25 * d * (ma[1] - mb[1]);
    if (!isfinite(u) || !isfinite(v)) return 0;
    if (fa != fb && !sfb__an_in_domain(A, u, v, 1e-6)) {
        /* beyond a's side: back into b's frame */
        sfb__an_unfold(A->tri, kf, (nb >> 1) & 3, nb & 1, u, v, &u, &v);
        if (!sfb__an_in_domain(A, u, v, 1e-6)) return 0;
        fa = fb;
    }
    sfb__an_clamp_domain(A, &u, &v);
    loc->face = fa;
    loc->u = (float)u;
    loc->v = (float)v;
    return 1;
}

/* Round 0's attempts of one part (grid spacing d; `want` of x, y odd multiples of d) on grid
 * rows [a, b) (row r: y = r d): with fill 0, the count of each row into rowat[r]; with fill 1,
 * row r's attempts into tries and locs from index rowat[r] on, seeded (the proxy's (face, u,
 * v), then sfb__an_hermite or sfb__an_predict from the hits so far). Rows are independent:
 * seeding reads hits, which only sfb__an_newton writes. */
typedef struct sfb__an_seed_job {
    const sfb__an *A;
    sfb__an_try *tries;
    sfb_location *locs;
    int *rowat;
    int part, d, want, fill, base;
} sfb__an_seed_job;

static void sfb__an_seed_rows(void *arg, int a, int b) {
    const sfb__an_seed_job *J = (const sfb__an_seed_job *)arg;
    const sfb__an *A = J->A;
    const int d = J->d, part = J->part, want = J->want;
    int row;
    for (row = a; row < b; ++row) {
        /* d is a power of two */
        const int y = row * d, oy = part > 0 && (y & (2 * d - 1)) == d;
        /* the row's pixels of the part: x an odd multiple of d when ox (= want - oy) is 1, a
         * multiple of 2d when it is 0 (part 0: every multiple of d) */
        const int ox = want - oy, step = part > 0 ? 2 * d : d;
        int x, n = J->fill ? J->rowat[row] : 0;
        for (x = ox == 1 ? d : 0; x < A->w && (ox == 0 || ox == 1); x += step) {
            const size_t p = (size_t)y * (size_t)A->w + (size_t)x;
            sfb_location *l;
            if (!A->cand[p]) continue;
            if (!J->fill) { ++n; continue; }
            memset(&J->tries[n], 0, sizeof J->tries[n]);
            J->tries[n].pix = (int)p;
            J->tries[n].x = x;
            J->tries[n].y = y;
            J->tries[n].k = J->base + n;
            l = &J->locs[n];
            if (A->cand[p] == 2) {
                l->face = A->face[p]; l->u = A->uv[2 * p]; l->v = A->uv[2 * p + 1];
            } else {
                l->face = A->cface[p]; l->u = A->cuv[2 * p]; l->v = A->cuv[2 * p + 1];
            }
            if (part > 0 && !sfb__an_hermite(A, x, y, ox ? 0 : 1, d, l) && !(ox && oy && sfb__an_hermite(A, x, y, 1, d, l)))
                sfb__an_predict(A, x, y, d, part, l);
            if (A->tri && (double)l->u + (double)l->v > 1.0) l->v = nextafterf(l->v, 0.0f);
            ++n;
        }
        if (!J->fill) J->rowat[row] = n;
    }
}

/* Which of hit pixel pix's 8 neighbours (bit i: the i-th of dy, dx = -1..1 in order, the
 * middle skipped) its hit would seed: not hit yet, or hit on another face at least 1 % of the
 * bounding radius farther away. */
static unsigned char sfb__an_neighbour_mask(const sfb__an *A, int x, int y) {
    const int pix = y * A->w + x, f = A->hl[pix].face;
    int dx, dy, bit = 0, m = 0;
    for (dy = -1; dy <= 1; ++dy)
        for (dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            int q, k;
            if ((dx | dy) == 0) continue;
            ++bit;
            if (nx < 0 || ny < 0 || nx >= A->w || ny >= A->h) continue;
            q = ny * A->w + nx;
            k = A->hit[q];
            if (k >= 0 && (A->hl[q].face == f || !(A->hdepth[A->hit[pix]] < A->hdepth[k] - 0.01 * A->radius))) continue;
            m |= 1 << (bit - 1);
        }
    return (unsigned char)m;
}

/* sfb__an_neighbour_mask of the changes [a, b) of the last round (A->chg) into A->nbm. */
static void sfb__an_neighbours(void *arg, int a, int b) {
    sfb__an *A = (sfb__an *)arg;
    int ci;
    for (ci = a; ci < b; ++ci) {
        const int pix = A->chg[ci];
        A->nbm[ci] = sfb__an_neighbour_mask(A, pix % A->w, pix / A->w);
    }
}

/* Round 1's changes: every hit, scanned row by row. sfb__an_neighbour_rows: the mask per pixel
 * on rows [y0, y1) into J->mask, 0 where no hit, and each row's count of masks that are not 0
 * into J->rowcnt[y]; sfb__an_neighbour_list: then, rows [y0, y1)'s pixels of masks not 0, in
 * order, into A->chg and their masks into J->list, from J->rowcnt[y] (by then their first
 * index) on. */
typedef struct sfb__an_nb_job {
    sfb__an *A;
    unsigned char *mask, *list;
    int *rowcnt;
} sfb__an_nb_job;
static void sfb__an_neighbour_list(void *arg, int y0, int y1) {
    const sfb__an_nb_job *J = (const sfb__an_nb_job *)arg;
    const int w = J->A->w;
    int x, y;
    for (y = y0; y < y1; ++y) {
        int o = J->rowcnt[y];
        for (x = 0; x < w; ++x) {
            const size_t p = (size_t)y * (size_t)w + (size_t)x;
            if (J->mask[p]) { J->A->chg[o] = (int)p; J->list[o++] = J->mask[p]; }
        }
    }
}
static void sfb__an_neighbour_rows(void *arg, int y0, int y1) {
    const sfb__an_nb_job *J = (const sfb__an_nb_job *)arg;
    sfb__an *A = J->A;
    unsigned char *nbm = J->mask;
    const int w = A->w;
    int x, y;
    for (y = y0; y < y1; ++y) {
        int n = 0;
        for (x = 0; x < w; ++x) {
            const size_t p = (size_t)y * (size_t)w + (size_t)x;
            if (A->hit[p] < 0) { nbm[p] = 0; continue; }
            if (x > 0 && y > 0 && x + 1 < w && y + 1 < A->h) {
                /* inside the surface's picture every neighbour is hit on the same face: none
                 * to seed (the mask's first test), without the general scan */
                const int f = A->hl[p].face, *hu = A->hit + p - w, *hm = A->hit + p, *hd = A->hit + p + w;
                const sfb_location *lu = A->hl + p - w, *lm = A->hl + p, *ld = A->hl + p + w;
                if (((hu[-1] | hu[0] | hu[1] | hm[-1] | hm[1] | hd[-1] | hd[0] | hd[1]) >= 0) && lu[-1].face == f && lu[0].face == f &&
                    lu[1].face == f && lm[-1].face == f && lm[1].face == f && ld[-1].face == f && ld[0].face == f && ld[1].face == f) {
                    nbm[p] = 0;
                    continue;
                }
            }
            nbm[p] = sfb__an_neighbour_mask(A, x, y);
            n += nbm[p] != 0;
        }
        J->rowcnt[y] = n;
    }
}

/* The projection's round tags of rows [y0, y1) cleared (the faces after them are read only
 * where the tag is the round's, so they are left as they are). */
typedef struct sfb__an_tags_job {
    int *tags;
    int w;
} sfb__an_tags_job;
static void sfb__an_clear_tags(void *arg, int y0, int y1) {
    const sfb__an_tags_job *J = (const sfb__an_tags_job *)arg;
    memset(J->tags + (size_t)y0 * (size_t)J->w, 0, (size_t)(y1 - y0) * (size_t)J->w * sizeof(int));
}

/* Step 2 over every round (see the file's comment). */
static sfb_result sfb__an_project_all(sfb__an *A, int steps) {
    size_t npix = (size_t)A->w * (size_t)A->h;
    int cap = 0, count = 0, round, part;
    sfb__an_try *tries = NULL;
    sfb_location *locs = NULL;
    float *buf = NULL;
    int *mark = NULL;  /* per pixel the last round that seeded it (its tag), then per pixel 3 faces it was seeded
                          from in that round (read only where the tag is this round's: only the tags are cleared) */
    int *rowat = NULL; /* round 0: per grid row, its attempts, then where they start in their band */
    unsigned char *nbc = NULL; /* round 1's changes' masks (sfb__an_neighbour_rows) */
    int mark_base = 0;
    sfb_result r = SFB_SUCCESS;
    cap = A->ws ? SFB__AN_BATCH_WS : SFB__AN_BATCH;
    if ((size_t)cap > npix) cap = (int)npix; /* later rounds grow it when they need to */
    if (cap < 4096) cap = 4096;
    if (cap < A->w) cap = A->w; /* round 0's bands hold at least a row */
    tries = (sfb__an_try *)sfb__an_get(A, SFB__WS_TRIES, (size_t)cap * sizeof *tries, NULL);
    locs = (sfb_location *)sfb__an_get(A, SFB__WS_LOCS, (size_t)cap * sizeof *locs, NULL);
    buf = (float *)sfb__an_get(A, SFB__WS_BUF, (size_t)cap * 12 * sizeof(float), NULL);
    rowat = (int *)sfb__an_get(A, SFB__WS_ROWAT, ((size_t)A->h + 1) * sizeof(int), NULL);
    A->nbm = (unsigned char *)sfb__an_get(A, SFB__WS_NBM, npix + 1, NULL);
    nbc = (unsigned char *)sfb__an_get(A, SFB__WS_NBC, npix + 1, NULL);
    /* the marks' round tags are base + round: a workspace's kept marks hold tags of earlier
     * analyses, all at or below its base, which grows by SFB__AN_ROUNDS per analysis (the
     * buffer is zeroed when new, or when the tags would overflow) */
    {
        int fresh = 1;
        mark = (int *)sfb__an_get(A, SFB__WS_MARK, npix * 4 * sizeof(int), &fresh);
        if (mark && !A->ws) {
            sfb__an_tags_job T;
            T.tags = mark;
            T.w = A->w;
            sfb__an_run(A, sfb__an_clear_tags, &T, 0, A->h, (double)npix * 0.05);
        }
        if (mark && A->ws) {
            if (fresh || A->ws->mark_base > 2147483647 - 2 * (SFB__AN_ROUNDS + 1)) {
                memset(mark, 0, npix * sizeof(int));
                A->ws->mark_base = 0;
            }
            mark_base = A->ws->mark_base;
            A->ws->mark_base += SFB__AN_ROUNDS + 1;
        }
    }
    if (!tries || !locs || !buf || !mark || !rowat || !A->nbm || !nbc) { r = sfb__oom(A->ctx, "the analysis projection"); goto done; }
    /* round 0, in five parts: first the anchors, the pixels whose x and y are multiples of
     * SFB__AN_ANCHOR (4), from their proxy (face, u, v); then, for d = 2 and then 1, the pixels
     * on the grid of spacing d with one coordinate an odd multiple of d, then those with both,
     * each between two hits of the parts before, d pixels either side along an axis
     * (sfb__an_hermite: most hit at their first evaluation), else from a hit anchor-grid
     * neighbour moved by the inverse of its screen Jacobian (sfb__an_predict), else from the
     * proxy too. Measured on catmark_car at 1024 x 1024 (413k covered pixels), every round:
     * 1.35 evaluations per covered pixel (round 0: 1.21); 1.41 (1.27) when the two hits of a
     * Hermite seed had to lie on one face, the others predicted from one side (a one-sided
     * cubic extrapolation for those saved 2 % of round 0's time and put 0.04 % of the pixels
     * on a farther sheet, which the later rounds then had to correct: not kept); 2.6 with
     * anchors every 2 pixels, the one-sided prediction alone and no stall rule (sfb__an_step).
     * The seeds the prediction still makes (next to silhouettes, face corners, and faces not
     * neighbours) take 2.2 evaluations each, Hermite seeds 1.05 to 1.15 */
    for (part = 0; part < 5; ++part) {
        const int d = part == 0 ? SFB__AN_ANCHOR : part <= 2 ? 2 : 1, nrows = (A->h + d - 1) / d;
        int r0, r1;
        sfb__an_seed_job J;
        J.A = A; J.tries = tries; J.locs = locs; J.rowat = rowat;
        J.part = part; J.d = d; J.want = part == 0 ? 0 : 2 - (part & 1);
        A->seeding = part < 4; /* the last part's hits seed no pixel of round 0 */
        A->nchg = 0; /* round 0's changes are every hit (below) */
        /* the attempts per grid row, then bands of whole rows of at most cap attempts (cap >=
         * w: a row fits), each seeded over the threads and run at once (its hits then seed the
         * bands after it too) */
        J.fill = 0;
        sfb__an_run(A, sfb__an_seed_rows, &J, 0, nrows, (double)A->w * A->h / ((double)d * d));
        for (r0 = 0; r0 < nrows; r0 = r1) {
            int total = 0;
            for (r1 = r0; r1 < nrows && total + rowat[r1] <= cap; ++r1) {
                const int n = rowat[r1];
                rowat[r1] = total;
                total += n;
            }
            if (total == 0) continue;
            J.fill = 1;
            J.base = A->nhit;
            sfb__an_run(A, sfb__an_seed_rows, &J, r0, r1, (double)total * 4.0);
            {
                sfb__an_fresh_job F;
                sfb_result res[SFB__AN_CHUNKS];
                const int nck = sfb__an_chunked(A) ? (total + 1023) / 1024 : 1;
                int c;
                F.A = A; F.tries = tries; F.locs = locs; F.count = total; F.steps = steps; F.res = res; F.done = NULL;
                F.pos = buf; F.du = buf + 3 * (size_t)total; F.dv = buf + 6 * (size_t)total; F.nrm = buf + 9 * (size_t)total;
                F.nchunks = nck < SFB__AN_CHUNKS ? nck : SFB__AN_CHUNKS;
                A->nhit += total; /* the batch's slots (holes where it misses) */
                if (F.nchunks > 1) sfb__an_run(A, sfb__an_fresh, &F, 0, F.nchunks, (double)total * 8.0);
                else sfb__an_fresh(&F, 0, 1); /* on this thread (sfb__an_chunked) */
                for (c = 0; c < F.nchunks; ++c)
                    if (res[c] != SFB_SUCCESS) { r = res[c]; goto done; }
            }
        }
    }
    sfb__an_fill_holes(A);
    /* round 0's changes: every hit, scanned per pixel row by row over the threads; those that
     * seed a neighbour listed in the picture's order (the hit slots lie in round 0's part
     * order, scattered over the picture: scanning them in that order cost a cache miss on
     * every neighbour read) */
    {
        sfb__an_nb_job N;
        int y, total = 0;
        N.A = A; N.mask = A->nbm; N.list = nbc; N.rowcnt = rowat;
        sfb__an_run(A, sfb__an_neighbour_rows, &N, 0, A->h, (double)npix);
        for (y = 0; y < A->h; ++y) { const int n = rowat[y]; rowat[y] = total; total += n; }
        sfb__an_run(A, sfb__an_neighbour_list, &N, 0, A->h, (double)npix * 0.25);
        A->nchg = total;
        A->nbm = nbc; /* per change from here on */
        nbc = N.mask;
    }
    if ((r = sfb__progress(A->ctx, 0.6f, "analyze")) != SFB_SUCCESS) goto done;
    /* later rounds: the pixels next to the last round's new or nearer hits, seeded by them:
     * pixels not hit yet, and pixels hit on another face at least 1 % of the bounding radius
     * farther away (a nearer surface next to them may hide their hit: the proxy's depth order
     * is not the exact surface's near silhouettes) */
    for (round = 1; round <= SFB__AN_ROUNDS; ++round) {
        int ci;
        count = 0;
        /* which neighbours each change would seed, over the threads (reads only; round 1's
         * are known), then the seeding in the changes' order, here */
        if (round > 1) sfb__an_run(A, sfb__an_neighbours, A, 0, A->nchg, (double)A->nchg);
        for (ci = 0; ci < A->nchg; ++ci) {
            int pix, x, y, dx, dy, bit = 0;
            if (!A->nbm[ci]) continue;
            pix = A->chg[ci]; x = pix % A->w; y = pix / A->w;
            for (dy = -1; dy <= 1; ++dy)
                for (dx = -1; dx <= 1; ++dx) {
                    int q, k, *mq, f = A->hl[pix].face;
                    if ((dx | dy) == 0) continue;
                    if (!(A->nbm[ci] & (1 << bit++))) continue;
                    q = (y + dy) * A->w + (x + dx);
                    mq = mark + npix + 3 * (size_t)q;
                    if (mark[q] != mark_base + round) { mark[q] = mark_base + round; mq[0] = mq[1] = mq[2] = -1; }
                    for (k = 0; k < 3 && mq[k] >= 0 && mq[k] != f; ++k) {}
                    if (k == 3 || mq[k] == f) continue; /* three faces tried this round, or this one */
                    mq[k] = f;
                    if (count == cap) {
                        int nc = cap * 2;
                        void *a = sfb__an_regrow(A, SFB__WS_TRIES, tries, (size_t)nc * sizeof *tries);
                        if (!a) { r = sfb__oom(A->ctx, "the analysis projection"); goto done; }
                        tries = (sfb__an_try *)a;
                        a = sfb__an_regrow(A, SFB__WS_LOCS, locs, (size_t)nc * sizeof *locs);
                        if (!a) { r = sfb__oom(A->ctx, "the analysis projection"); goto done; }
                        locs = (sfb_location *)a;
                        a = sfb__an_regrow(A, SFB__WS_BUF, buf, (size_t)nc * 12 * sizeof(float));
                        if (!a) { r = sfb__oom(A->ctx, "the analysis projection"); goto done; }
                        buf = (float *)a;
                        cap = nc;
                    }
                    memset(&tries[count], 0, sizeof tries[count]);
                    tries[count].pix = q;
                    tries[count].x = x + dx;
                    tries[count].y = y + dy;
                    locs[count] = A->hl[pix];
                    ++count;
                }
        }
        if (count == 0) break;
        A->nchg = 0;
        if ((r = sfb__an_newton(A, tries, locs, count, buf, steps)) != SFB_SUCCESS) goto done;
        if (A->nchg == 0) break;
        if ((r = sfb__progress(A->ctx, 0.6f + 0.1f * (float)round / SFB__AN_ROUNDS, "analyze")) != SFB_SUCCESS) goto done;
    }
done:
    sfb__an_put(A, tries);
    sfb__an_put(A, locs);
    sfb__an_put(A, buf);
    sfb__an_put(A, mark);
    sfb__an_put(A, rowat);
    sfb__an_put(A, A->nbm);
    sfb__an_put(A, nbc);
    A->nbm = NULL;
    return r;
}

/* Rows [y0, y1): per row y, its proxy pixels left near (to fall back), left far (dropped) and
 * its hits off the proxy (grown) into cnt[3 y ..]. */
typedef struct sfb__an_left_job {
    const sfb__an *A;
    int *cnt;
} sfb__an_left_job;
static void sfb__an_left_rows(void *arg, int y0, int y1) {
    const sfb__an_left_job *J = (const sfb__an_left_job *)arg;
    const sfb__an *A = J->A;
    int x, y;
    for (y = y0; y < y1; ++y) {
        int near = 0, far = 0, grown = 0;
        for (x = 0; x < A->w; ++x) {
            const size_t p = (size_t)y * (size_t)A->w + (size_t)x;
            const int drawn = A->face[p] >= 0, hit = A->hit[p] >= 0;
            grown += hit && !drawn;
            if (drawn && !hit) {
                if (A->state[p] == SFB__AN_TRIED_NEAR) ++near;
                else ++far;
            }
        }
        J->cnt[3 * y] = near; J->cnt[3 * y + 1] = far; J->cnt[3 * y + 2] = grown;
    }
}

/* Proxy pixels left without a hit: NEAR ones fall back to the proxy's point (evaluated there),
 * the others are dropped (counted into dropped); hits off the proxy are counted into grown.
 * polygon_based: every proxy pixel is a "hit" on its interpolated data. */
static sfb_result sfb__an_leftovers(sfb__an *A, int *fallback, int *dropped, int *grown) {
    size_t p;
    int n = 0, i, y;
    sfb_location *loc;
    float *buf;
    int *pix, *cnt = (int *)sfb__alloc(A->ctx, ((size_t)A->h + 1) * 3 * sizeof(int));
    sfb_eval_output out;
    sfb_result r;
    *fallback = *dropped = *grown = 0;
    if (!cnt) return sfb__oom(A->ctx, "the analysis fallback");
    {
        sfb__an_left_job J;
        J.A = A; J.cnt = cnt;
        sfb__an_run(A, sfb__an_left_rows, &J, 0, A->h, (double)A->w * A->h * 0.25);
    }
    for (y = 0; y < A->h; ++y) { n += cnt[3 * y]; *dropped += cnt[3 * y + 1]; *grown += cnt[3 * y + 2]; }
    if (n == 0) { sfb__free(A->ctx, cnt); return SFB_SUCCESS; }
    loc = (sfb_location *)sfb__alloc(A->ctx, (size_t)n * sizeof *loc);
    buf = (float *)sfb__alloc(A->ctx, (size_t)n * 12 * sizeof(float));
    pix = (int *)sfb__alloc(A->ctx, (size_t)n * sizeof(int));
    if (!loc || !buf || !pix) {
        sfb__free(A->ctx, loc); sfb__free(A->ctx, buf); sfb__free(A->ctx, pix); sfb__free(A->ctx, cnt);
        return sfb__oom(A->ctx, "the analysis fallback");
    }
    for (y = 0, i = 0; y < A->h; ++y) {
        const size_t end = ((size_t)y + 1) * (size_t)A->w;
        if (!cnt[3 * y]) continue;
        for (p = (size_t)y * (size_t)A->w; p < end; ++p)
            if (A->face[p] >= 0 && A->hit[p] < 0 && A->state[p] == SFB__AN_TRIED_NEAR) {
                pix[i] = (int)p;
                loc[i].face = A->face[p]; loc[i].u = A->uv[2 * p]; loc[i].v = A->uv[2 * p + 1];
                if (A->tri && (double)loc[i].u + (double)loc[i].v > 1.0) loc[i].v = nextafterf(loc[i].v, 0.0f);
                ++i;
            }
    }
    sfb__free(A->ctx, cnt);
    memset(&out, 0, sizeof out);
    out.position = buf; out.du = buf + 3 * (size_t)n; out.dv = buf + 6 * (size_t)n; out.normal = buf + 9 * (size_t)n;
    r = sfb__surface_eval_unchecked(A->s, loc, n, &out);
    if (r == SFB_SUCCESS)
        for (i = 0; i < n; ++i)
            sfb__an_add_hit(A, pix[i], &loc[i], A->depth[pix[i]], out.position + 3 * (size_t)i, out.du + 3 * (size_t)i, out.dv + 3 * (size_t)i,
                            out.normal + 3 * (size_t)i);
    *fallback = n;
    sfb__free(A->ctx, loc); sfb__free(A->ctx, buf); sfb__free(A->ctx, pix);
    return r;
}

/* ---- step 4: colours ---- */
/* The smaller of two one-sided differences of an axis, each +inf (off the picture, or an infinite
 * neighbour) or NaN (a NaN neighbour) when it does not count; 0 when neither does. */
static double sfb__an_smaller_side(double a, double b) {
    return a < b ? a : b < HUGE_VAL ? b : a < HUGE_VAL ? a : 0.0;
}
/* The footprint of pixel pix in units of the value in v: per axis the smaller one-sided
 * difference (robust at silhouettes and band ends), summed. */
static double sfb__an_footprint(const float *v, int w, int h, int x, int y) {
    const int pix = y * w + x;
    const double c = v[pix];
    const double l = x > 0 ? fabs(c - v[pix - 1]) : HUGE_VAL, r = x + 1 < w ? fabs(c - v[pix + 1]) : HUGE_VAL;
    const double u = y > 0 ? fabs(c - v[pix - w]) : HUGE_VAL, o = y + 1 < h ? fabs(c - v[pix + w]) : HUGE_VAL;
    return sfb__an_smaller_side(l, r) + sfb__an_smaller_side(u, o);
}
/* The looks of one analysis: resolved light and colours. */
typedef struct sfb__an_look {
    sfb__shade_job job;
    double key[3], width, range;
    int pattern;
    unsigned char bg[4], miss[4];
} sfb__an_look;

static void sfb__an_lights(const sfb__an *A, sfb__an_look *L) {
    const sfb_analyze_config *c = A->c;
    const sfb__an_cam *cam = &A->cam;
    sfb__shade_job *j = &L->job;
    double R = A->radius, d[3];
    int i, mode = c->mode;
    memset(L, 0, sizeof *L);
    j->mode = mode; j->curvature = c->curvature; j->ortho = cam->ortho;
    for (i = 0; i < 3; ++i) { j->eye[i] = cam->eye[i]; j->fwd[i] = cam->fwd[i]; }
    for (i = 0; i < 3; ++i) L->key[i] = -cam->fwd[i] + 0.55 * cam->up[i] - 0.45 * cam->right[i];
    sfb__rnormalize(L->key);
    L->pattern = c->light_pattern;
    L->width = c->stripe_width > 0.0f ? c->stripe_width
               : L->pattern == SFB_LIGHT_LATTICE ? 0.2 : L->pattern == SFB_LIGHT_CIRCLES ? 0.6 : mode == SFB_ANALYZE_HIGHLIGHT ? 0.7 : 0.5;
    for (i = 0; i < 3; ++i) d[i] = c->light_dir[i];
    if (!(sfb__rnormalize(d) > 0.0)) {
        /* zebra: bands about the camera's up; isophotes and shading: the key light */
        for (i = 0; i < 3; ++i) d[i] = mode == SFB_ANALYZE_ZEBRA ? cam->up[i] : L->key[i];
    }
    for (i = 0; i < 3; ++i) j->dir[i] = d[i];
    if (mode == SFB_ANALYZE_REFLECTION || mode == SFB_ANALYZE_HIGHLIGHT) {
        double ell[3], per = c->stripes > 0.0f ? c->stripes : mode == SFB_ANALYZE_REFLECTION ? 16.0 : 5.0, t;
        if (c->light_set) {
            for (i = 0; i < 3; ++i) { j->lc[i] = c->light_center[i]; j->lm[i] = c->light_normal[i]; j->lu[i] = c->light_axis[i]; }
            sfb__rnormalize(j->lm);
            j->lsize[0] = c->light_size[0] > 0.0f ? c->light_size[0] : 16.0 * R;
            j->lsize[1] = c->light_size[1] > 0.0f ? c->light_size[1] : j->lsize[0];
        } else if (mode == SFB_ANALYZE_REFLECTION) {
            /* directly above the surface (the seed's Fig. 2: "an area light source is put directly
             * above a surface"), up being the camera's up, or the orbit's (the world's y unless
             * `up` is given); the lines run away from the viewer (a design studio's ceiling of
             * tubes) */
            for (i = 0; i < 3; ++i) ell[i] = c->up[i];
            if (!(sfb__rnormalize(ell) > 0.0)) { ell[0] = 0.0; ell[1] = 1.0; ell[2] = 0.0; }
            for (i = 0; i < 3; ++i) { j->lc[i] = A->centre[i] + 2.5 * R * ell[i]; j->lm[i] = -ell[i]; j->lu[i] = cam->right[i]; }
            j->lsize[0] = j->lsize[1] = 16.0 * R;
        } else {
            /* sfb_render's highlight plane: toward the camera, lines at 30 degrees from vertical */
            double e[3];
            for (i = 0; i < 3; ++i) {
                j->lm[i] = -cam->fwd[i];
                j->lc[i] = A->centre[i] + 3.0 * R * j->lm[i];
                e[i] = cos(SFB__PI / 6.0) * cam->up[i] + sin(SFB__PI / 6.0) * cam->right[i];
            }
            sfb__rcross(e, j->lm, j->lu);
            j->lsize[0] = j->lsize[1] = 2.0 * R;
        }
        t = sfb__rdot(j->lu, j->lm);
        for (i = 0; i < 3; ++i) j->lu[i] -= t * j->lm[i];
        sfb__rnormalize(j->lu);
        sfb__rcross(j->lm, j->lu, j->lv);
        j->periods[0] = per;
        j->periods[1] = per * j->lsize[1] / j->lsize[0];
    } else if (mode == SFB_ANALYZE_ZEBRA) j->periods[0] = c->stripes > 0.0f ? c->stripes : 16.0;
    else if (mode == SFB_ANALYZE_ISOPHOTE) j->periods[0] = c->stripes > 0.0f ? c->stripes : 10.0;
    if (c->background[0] | c->background[1] | c->background[2] | c->background[3]) memcpy(L->bg, c->background, 4);
    else { L->bg[0] = 44; L->bg[1] = 48; L->bg[2] = 56; L->bg[3] = 255; }
    if (c->miss[0] | c->miss[1] | c->miss[2] | c->miss[3]) memcpy(L->miss, c->miss, 4);
    else { L->miss[0] = 26; L->miss[1] = 28; L->miss[2] = 34; L->miss[3] = 255; }
}

/* The k-th smallest of v[0..n) (reorders v; quickselect, median-of-three pivots). */
static float sfb__an_select(float *v, int n, int k) {
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int i = lo, j = hi, mid = lo + (hi - lo) / 2;
        float a = v[lo], b = v[mid], c = v[hi], piv = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        while (i <= j) {
            while (v[i] < piv) ++i;
            while (v[j] > piv) --j;
            if (i <= j) { float t = v[i]; v[i] = v[j]; v[j] = t; ++i; --j; }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else break;
    }
    return v[k];
}

/* The curvature map's range: the config's, or the 90th percentile of |value| (exact, so that
 * a few pixels more or less move it by a rank, not by a histogram bin). */
static sfb_result sfb__an_range(const sfb__an *A, const float *val, int n, double *range) {
    float *a;
    int i, m = 0;
    *range = 1.0;
    if (A->c->curvature_range > 0.0f) { *range = A->c->curvature_range; return SFB_SUCCESS; }
    a = (float *)sfb__alloc(A->ctx, ((size_t)n + 1) * sizeof(float));
    if (!a) return sfb__oom(A->ctx, "the curvature range");
    for (i = 0; i < n; ++i) if (isfinite(val[i])) a[m++] = fabsf(val[i]);
    if (m > 0) {
        double r = sfb__an_select(a, m, (int)(0.9 * (m - 1)));
        if (r > 0.0) *range = r;
    }
    sfb__free(A->ctx, a);
    return SFB_SUCCESS;
}

/* Samples the image light at plane coordinates (s, t) in [0,1] (bilinear, clamped). */
static void sfb__an_texel(const sfb_analyze_config *c, double s, double t, double *rgba) {
    double x = sfb__rclamp(s, 0.0, 1.0) * c->light_width - 0.5, y = sfb__rclamp(t, 0.0, 1.0) * c->light_height - 0.5, fx, fy;
    int x0, y0, x1, y1, k;
    x = sfb__rclamp(x, 0.0, c->light_width - 1.0);
    y = sfb__rclamp(y, 0.0, c->light_height - 1.0);
    x0 = (int)x; y0 = (int)y; fx = x - x0; fy = y - y0;
    x1 = x0 + 1 < c->light_width ? x0 + 1 : x0;
    y1 = y0 + 1 < c->light_height ? y0 + 1 : y0;
    for (k = 0; k < 4; ++k) {
        const unsigned char *T = c->light_rgba;
        double a = T[4 * ((size_t)y0 * c->light_width + x0) + k], b = T[4 * ((size_t)y0 * c->light_width + x1) + k];
        double d = T[4 * ((size_t)y1 * c->light_width + x0) + k], e = T[4 * ((size_t)y1 * c->light_width + x1) + k];
        rgba[k] = ((a * (1 - fx) + b * fx) * (1 - fy) + (d * (1 - fx) + e * fx) * fy) / 255.0;
    }
}

/* Lit share of a light-pattern pixel (values a, b with footprints fa, fb) and its class (2/3). */
static double sfb__an_pattern(const sfb__an_look *L, double a, double b, double fa, double fb, int *cls) {
    double w = L->width, cover;
    if (L->pattern == SFB_LIGHT_LATTICE) {
        double ca = sfb__band_cover(a, fa, 0.0, w), cb = sfb__band_cover(b, fb, 0.0, w);
        double ra = a - floor(a), rb = b - floor(b);
        *cls = (ra < w || rb < w) ? 3 : 2;
        return ca + cb - ca * cb;
    }
    if (L->pattern == SFB_LIGHT_CIRCLES) {
        double ua = a - floor(a) - 0.5, ub = b - floor(b) - 0.5, d = sqrt(ua * ua + ub * ub), rad = 0.5 * w;
        double f = fa > fb ? fa : fb, edge, avg = SFB__PI * rad * rad, t;
        *cls = d < rad ? 3 : 2;
        edge = f > 1e-6 ? sfb__rclamp((rad - d) / f + 0.5, 0.0, 1.0) : (d < rad);
        t = sfb__rclamp((f - 0.25) / 0.25, 0.0, 1.0);
        cover = (1.0 - t) * edge + t * avg;
        return cover;
    }
    *cls = (a - floor(a)) < w ? 3 : 2;
    return sfb__band_cover(a, fa, 0.0, w);
}

/* Colours the pixels of rows [y0, y1) from the values (full-picture arrays v1, v2) and the
 * hits' normals (rows are independent: a task of sfb__parallel). */
typedef struct sfb__an_colour_job {
    const sfb__an *A;
    const sfb__an_look *L;
    const float *v1, *v2;
    unsigned char *rgba, *cls;
} sfb__an_colour_job;

static void sfb__an_colour(void *arg, int y0, int y1) {
    const sfb__an_colour_job *J = (const sfb__an_colour_job *)arg;
    const sfb__an *A = J->A;
    const sfb__an_look *L = J->L;
    const float *v1 = J->v1, *v2 = J->v2;
    unsigned char *rgba = J->rgba, *cls = J->cls;
    const sfb_analyze_config *c = A->c;
    const int mode = c->mode, w = A->w, ortho = A->cam.ortho;
    int col, row;
    for (row = y0; row < y1; ++row)
        for (col = 0; col < w; ++col) {
            const size_t p = (size_t)row * (size_t)w + (size_t)col;
            int k = A->hit[p], i, cl = 2;
            double rgb[3] = { 0.0, 0.0, 0.0 }, n[3], diff, a;
            unsigned char *o = rgba + 4 * p;
            if (k < 0) { memcpy(o, L->bg, 4); cls[p] = 0; continue; }
            a = v1[p];
            {
                const float *hn = A->hnrm + 3 * (size_t)k;
                double vv[3];
                n[0] = hn[0]; n[1] = hn[1]; n[2] = hn[2];
                if (ortho) for (i = 0; i < 3; ++i) vv[i] = -A->cam.fwd[i];
                else {
                    const float *hp = A->hpos + 3 * (size_t)k;
                    for (i = 0; i < 3; ++i) vv[i] = A->cam.eye[i] - hp[i];
                }
                if (sfb__rdot(vv, n) < 0.0) for (i = 0; i < 3; ++i) n[i] = -n[i];
            }
            diff = sfb__rdot(n, L->key);
            if (diff < 0.0) diff = 0.0;
            switch (mode) {
            case SFB_ANALYZE_REFLECTION:
            case SFB_ANALYZE_HIGHLIGHT:
                if (!isfinite(a)) {
                    /* the miss colour, lit a little by the key light so that the form still reads */
                    cl = 1;
                    for (i = 0; i < 3; ++i) rgb[i] = L->miss[i] / 255.0 * (0.55 + 0.9 * diff);
                    break;
                }
                if (L->pattern == SFB_LIGHT_IMAGE) {
                    double t[4], base = mode == SFB_ANALYZE_REFLECTION ? 0.08 : 0.3 + 0.4 * diff;
                    sfb__an_texel(c, a / L->job.periods[0], v2[p] / L->job.periods[1], t);
                    for (i = 0; i < 3; ++i) rgb[i] = base * (1.0 - t[3]) + t[i] * t[3];
                    cl = 2 + (0.299 * t[0] + 0.587 * t[1] + 0.114 * t[2] >= 0.5);
                } else {
                    /* stripes read only the first value's footprint */
                    double fa = sfb__an_footprint(v1, A->w, A->h, col, row),
                           fb = L->pattern == SFB_LIGHT_LATTICE || L->pattern == SFB_LIGHT_CIRCLES ? sfb__an_footprint(v2, A->w, A->h, col, row) : 0.0;
                    double cover = sfb__an_pattern(L, a, v2[p], fa, fb, &cl);
                    if (mode == SFB_ANALYZE_REFLECTION) {
                        double dark = 0.07 + 0.16 * diff;
                        for (i = 0; i < 3; ++i) rgb[i] = dark * (1.0 - cover) + 0.97 * cover;
                    } else {
                        double base = 0.45 + 0.5 * diff, blue[3];
                        blue[0] = 0.05 * base; blue[1] = 0.12 * base; blue[2] = 0.70 * base;
                        for (i = 0; i < 3; ++i) rgb[i] = base * cover + blue[i] * (1.0 - cover);
                    }
                }
                break;
            case SFB_ANALYZE_ZEBRA: {
                double fa = sfb__an_footprint(v1, A->w, A->h, col, row), cover = sfb__band_cover(a, fa, 0.0, L->width);
                cl = (a - floor(a)) < L->width ? 3 : 2;
                for (i = 0; i < 3; ++i) rgb[i] = 0.04 + 0.92 * cover;
                break;
            }
            case SFB_ANALYZE_ISOPHOTE: {
                double N = L->job.periods[0], x = (sfb__rclamp(a, -1.0, 1.0) + 1.0) * 0.5 * N, fx = sfb__an_footprint(v1, A->w, A->h, col, row) * 0.5 * N;
                double kb = floor(x), f = x - kb, c0[3], c1[3], m = 0.0;
                int kk = (int)kb, nb = kk;
                if (kk >= (int)N) kk = (int)N - 1;
                cl = 2 + (kk < 0 ? 0 : kk > 200 ? 200 : kk);
                sfb__colormap((kk + 0.5) / N, c0);
                if (fx > 1e-6 && f < 0.5 * fx) { nb = kk - 1; m = (0.5 * fx - f) / fx; }
                else if (fx > 1e-6 && 1.0 - f < 0.5 * fx) { nb = kk + 1; m = (0.5 * fx - (1.0 - f)) / fx; }
                if (nb < 0) nb = 0;
                if (nb >= (int)N) nb = (int)N - 1;
                sfb__colormap((nb + 0.5) / N, c1);
                for (i = 0; i < 3; ++i) rgb[i] = c0[i] * (1.0 - m) + c1[i] * m;
                break;
            }
            case SFB_ANALYZE_CURVATURE: {
                double t, lum = 0.72 + 0.28 * diff;
                if (!isfinite(a)) { cl = 1; rgb[0] = rgb[1] = rgb[2] = 0.5; break; }
                if (c->curvature == SFB_CURVATURE_MAX_ABS) {
                    t = sfb__rclamp(a / L->range, 0.0, 1.0);
                    cl = 2 + (int)sfb__rclamp(floor(t * 16.0), 0.0, 15.0);
                    sfb__colormap(t, rgb);
                } else {
                    static const double neg[3] = { 0.12, 0.30, 1.00 }, pos[3] = { 1.00, 0.16, 0.08 };
                    t = sfb__rclamp(a / L->range, -1.0, 1.0);
                    cl = 2 + 8 + (int)floor(t * 8.0 + 0.5); /* 17 bins, the middle one centred on 0 */
                    for (i = 0; i < 3; ++i) rgb[i] = (1.0 - fabs(t)) * 0.96 + fabs(t) * (t < 0.0 ? neg[i] : pos[i]);
                }
                for (i = 0; i < 3; ++i) rgb[i] *= lum;
                break;
            }
            case SFB_ANALYZE_NORMALS:
                for (i = 0; i < 3; ++i) rgb[i] = 0.5 + 0.5 * A->hnrm[3 * (size_t)k + i];
                break;
            default: {
                double hv[3], vv[3], spec;
                if (A->cam.ortho) for (i = 0; i < 3; ++i) vv[i] = -A->cam.fwd[i];
                else for (i = 0; i < 3; ++i) vv[i] = A->cam.eye[i] - A->hpos[3 * (size_t)k + i];
                sfb__rnormalize(vv);
                for (i = 0; i < 3; ++i) hv[i] = L->key[i] + vv[i];
                sfb__rnormalize(hv);
                spec = sfb__rdot(n, hv);
                spec = spec > 0.0 ? pow(spec, 48.0) : 0.0;
                rgb[0] = rgb[1] = rgb[2] = pow(sfb__rclamp(0.72 * (0.16 + 0.78 * diff) + 0.3 * spec, 0.0, 1.0), 1.0 / 1.6);
                break;
            }
            }
            cls[p] = (unsigned char)cl;
            o[0] = sfb__to_byte(rgb[0]); o[1] = sfb__to_byte(rgb[1]); o[2] = sfb__to_byte(rgb[2]); o[3] = 255;
        }
}

/* The shade kernel of the context's backend, or ref's. */
static sfb_result sfb__an_shade(const sfb__an *A, const sfb__shade_job *job, int n) {
    sfb_context *ctx = A->ctx;
    const sfb__backend_vtable *be = ctx->backend;
    if (n == 0) return SFB_SUCCESS;
    if (!be || !be->shade) {
        sfb__log(ctx, SFB_LOG_INFO, "backend %s lacks shade; using ref", be ? be->name : "none");
        return sfb__ref_shade(NULL, job, 0, n);
    }
    return be->shade(ctx->backend_state, job, 0, n);
}

static void sfb__an_free(sfb__an *A) {
    sfb__an_put(A, A->gpos); sfb__an_put(A, A->gnrm); sfb__an_put(A, A->rv); sfb__an_put(A, A->rtri); sfb__an_put(A, A->ybox);
    sfb__an_put(A, A->cface); sfb__an_put(A, A->cuv); sfb__an_put(A, A->cdist);
    sfb__an_put(A, A->depth); sfb__an_put(A, A->face); sfb__an_put(A, A->uv); sfb__an_put(A, A->ppos); sfb__an_put(A, A->pnrm);
    sfb__an_put(A, A->hit); sfb__an_put(A, A->state); sfb__an_put(A, A->cand); sfb__an_put(A, A->zmax); sfb__an_put(A, A->ucov);
    sfb__an_put(A, A->hpix); sfb__an_put(A, A->hpos); sfb__an_put(A, A->hdu); sfb__an_put(A, A->hdv);
    sfb__an_put(A, A->hnrm); sfb__an_put(A, A->hdepth); sfb__an_put(A, A->hinv); sfb__an_put(A, A->hl); sfb__an_put(A, A->chg);
    sfb__an_put(A, A->adj);
}

/* Bytes the analysis will hold at its peak (checked against the budget before allocating). */
static double sfb__an_bytes(const sfb__an *A) {
    double npix = (double)A->w * A->h, grid = (double)A->nf * A->per;
    double per_pixel = 16 + 4 + 4 + 8 + 4 + 1 + 1 + 1 /* zmax, ucov */ + 4 + 4 + 1 + 4 + 12 /* buffers, outputs */ + 4 + 24 + 4 + 16 + 12 /* hits */ +
                       (A->c->mode == SFB_ANALYZE_CURVATURE ? 24 + 12 + 36 : 0) /* their first and second derivatives */ +
                       (A->c->polygon_based ? 24 : 92 + 16 + 2) /* proxy data or the projection's attempts, marks and neighbour masks */;
    return npix * per_pixel + grid * (24.0 + sizeof(sfb__raster_vertex) + 2 * 2 * 4 * sizeof(int) + 2 * 2 * 2 * sizeof(float)) + 65536.0 * sizeof(sfb_location) + (double)A->nf * 4 * (sizeof(int) + sizeof(sfb__an_side) + 12 * sizeof(int)) /* adjacency, its hash table */;
}

/* The per-pixel buffers of rows [y0, y1) before the raster: nothing drawn, nothing hit. */
static void sfb__an_clear_rows(void *arg, int y0, int y1) {
    sfb__an *A = (sfb__an *)arg;
    size_t p, end = (size_t)y1 * (size_t)A->w;
    for (p = (size_t)y0 * (size_t)A->w; p < end; ++p) {
        A->depth[p] = A->cdist[p] = (float)HUGE_VAL;
        A->face[p] = A->cface[p] = -1;
        A->hit[p] = -1;
    }
}

/* The buffers of one analysis (A's sizes set), initialised; 0 when one could not be had. */
static int sfb__an_alloc(sfb__an *A) {
    size_t npix = (size_t)A->w * (size_t)A->h, grid = (size_t)A->nf * (size_t)A->per;
    A->gpos = (float *)sfb__an_get(A, SFB__WS_GPOS, grid * 3 * sizeof(float), NULL);
    A->gnrm = (float *)sfb__an_get(A, SFB__WS_GNRM, grid * 3 * sizeof(float), NULL);
    A->rv = (sfb__raster_vertex *)sfb__an_get(A, SFB__WS_RV, grid * sizeof(sfb__raster_vertex), NULL);
    /* at most two triangles per grid point, then as many in the raster's order (sfb__an_order) */
    A->rtri = (int *)sfb__an_get(A, SFB__WS_RTRI, grid * 2 * 2 * 4 * sizeof(int), NULL);
    A->ybox = (float *)sfb__an_get(A, SFB__WS_YBOX, grid * 2 * 2 * 2 * sizeof(float), NULL);
    A->depth = (float *)sfb__an_get(A, SFB__WS_DEPTH, npix * sizeof(float), NULL);
    A->face = (int *)sfb__an_get(A, SFB__WS_FACE, npix * sizeof(int), NULL);
    A->uv = (float *)sfb__an_get(A, SFB__WS_UV, npix * 2 * sizeof(float), NULL);
    A->hit = (int *)sfb__an_get(A, SFB__WS_HIT, npix * sizeof(int), NULL);
    A->adj = (int *)sfb__an_get(A, SFB__WS_ADJ, ((size_t)A->nf + 1) * 4 * sizeof(int), NULL);
    A->cface = (int *)sfb__an_get(A, SFB__WS_CFACE, npix * sizeof(int), NULL);
    A->cuv = (float *)sfb__an_get(A, SFB__WS_CUV, npix * 2 * sizeof(float), NULL);
    A->cdist = (float *)sfb__an_get(A, SFB__WS_CDIST, npix * sizeof(float), NULL);
    A->state = (unsigned char *)sfb__an_get_zeroed(A, SFB__WS_STATE, npix);
    A->cand = (unsigned char *)sfb__an_get(A, SFB__WS_CAND, npix, NULL);
    A->zmax = (float *)sfb__an_get(A, SFB__WS_ZMAX, (size_t)A->h * (size_t)((A->w + 7) / 8) * sizeof(float) + 1, NULL);
    A->ucov = (unsigned char *)sfb__an_get(A, SFB__WS_UCOV, ((size_t)A->h + (size_t)(A->h + 7) / 8) * (size_t)((A->w + 7) / 8) + 1, NULL);
    if (A->c->polygon_based) {
        A->ppos = (float *)sfb__an_get(A, SFB__WS_PPOS, npix * 3 * sizeof(float), NULL);
        A->pnrm = (float *)sfb__an_get(A, SFB__WS_PNRM, npix * 3 * sizeof(float), NULL);
    }
    A->hpix = (int *)sfb__an_get(A, SFB__WS_HPIX, npix * sizeof(int), NULL);
    A->hpos = (float *)sfb__an_get(A, SFB__WS_HPOS, npix * 3 * sizeof(float), NULL);
    if (A->c->mode == SFB_ANALYZE_CURVATURE) { /* the first derivatives: only curvature reads them after the projection */
        A->hdu = (float *)sfb__an_get(A, SFB__WS_HDU, npix * 3 * sizeof(float), NULL);
        A->hdv = (float *)sfb__an_get(A, SFB__WS_HDV, npix * 3 * sizeof(float), NULL);
    }
    A->hnrm = (float *)sfb__an_get(A, SFB__WS_HNRM, npix * 3 * sizeof(float), NULL);
    A->hdepth = (float *)sfb__an_get(A, SFB__WS_HDEPTH, npix * sizeof(float), NULL);
    A->hinv = (float *)sfb__an_get(A, SFB__WS_HINV, npix * 4 * sizeof(float), NULL);
    A->hl = (sfb_location *)sfb__an_get(A, SFB__WS_HL, npix * sizeof(sfb_location), NULL);
    A->chg = (int *)sfb__an_get(A, SFB__WS_CHG, (npix + 1) * sizeof(int), NULL);
    if (!A->gpos || !A->gnrm || !A->rv || !A->rtri || !A->ybox || !A->depth || !A->face || !A->uv || !A->hit || !A->adj || !A->cface || !A->cuv || !A->cdist || !A->state || !A->cand || !A->zmax || !A->ucov ||
        (A->c->polygon_based && (!A->ppos || !A->pnrm)) || !A->hpix || !A->hpos || (A->c->mode == SFB_ANALYZE_CURVATURE && (!A->hdu || !A->hdv)) || !A->hnrm || !A->hdepth ||
        !A->hinv || !A->hl || !A->chg)
        return 0;
    sfb__an_run(A, sfb__an_clear_rows, A, 0, A->h, (double)npix * 0.1);
    return 1;
}

/* Step 2 for polygon_based: every proxy pixel is a "hit" on its interpolated data. */
static void sfb__an_polygon_hits(sfb__an *A) {
    static const float zero[3] = { 0.0f, 0.0f, 0.0f };
    size_t npix = (size_t)A->w * (size_t)A->h, p;
    for (p = 0; p < npix; ++p)
        if (A->face[p] >= 0) {
            sfb_location l;
            l.face = A->face[p]; l.u = A->uv[2 * p]; l.v = A->uv[2 * p + 1];
            sfb__an_add_hit(A, (int)p, &l, A->depth[p], A->ppos + 3 * p, zero, zero, A->pnrm + 3 * p);
            sfb__an_unit3f(A->hnrm + 3 * (size_t)A->hit[p]);
        }
}

/* Step 3: the second derivatives (CURVATURE) and the shade kernel into hv1, hv2 (nhit each). */
static sfb_result sfb__an_values(sfb__an *A, sfb__an_look *L, float *hv1, float *hv2) {
    const sfb_analyze_config *c = A->c;
    float *sec = NULL;
    sfb_result r = SFB_SUCCESS;
    int k;
    L->job.position = A->hpos; L->job.du = A->hdu; L->job.dv = A->hdv; L->job.normal = A->hnrm;
    L->job.value = hv1; L->job.value2 = hv2;
    if (c->mode == SFB_ANALYZE_CURVATURE && A->nhit > 0) {
        sfb_eval_output o;
        sfb_location *loc = (sfb_location *)sfb__an_get(A, SFB__WS_HLOC, (size_t)A->nhit * sizeof(sfb_location), NULL);
        sec = (float *)sfb__an_get(A, SFB__WS_SEC, (size_t)A->nhit * 9 * sizeof(float), NULL);
        if (!sec || !loc) { sfb__an_put(A, loc); sfb__an_put(A, sec); return sfb__oom(A->ctx, "the analysis second derivatives"); }
        for (k = 0; k < A->nhit; ++k) loc[k] = A->hl[A->hpix[k]]; /* the hits' locations, in slot order */
        memset(&o, 0, sizeof o);
        o.duu = sec; o.duv = sec + 3 * (size_t)A->nhit; o.dvv = sec + 6 * (size_t)A->nhit;
        r = sfb__surface_eval_unchecked(A->s, loc, A->nhit, &o);
        sfb__an_put(A, loc);
        L->job.duu = o.duu; L->job.duv = o.duv; L->job.dvv = o.dvv;
        /* curvature is the geometry's: where the normals come from a field of their own (PN
         * triangles' quadratic normals), the second fundamental form takes du x dv instead */
        if (A->s->patches.normal_field)
            for (k = 0; k < A->nhit; ++k) {
                const float *a = A->hdu + 3 * (size_t)k, *b = A->hdv + 3 * (size_t)k;
                float *n = A->hnrm + 3 * (size_t)k;
                const double x = (double)a[1] * b[2] - (double)a[2] * b[1], y = (double)a[2] * b[0] - (double)a[0] * b[2],
                             z = (double)a[0] * b[1] - (double)a[1] * b[0], len = sqrt(x * x + y * y + z * z);
                if (len > 0.0) { n[0] = (float)(x / len); n[1] = (float)(y / len); n[2] = (float)(z / len); }
            }
    }
    if (r == SFB_SUCCESS) r = sfb__an_shade(A, &L->job, A->nhit);
    if (r == SFB_SUCCESS && c->mode == SFB_ANALYZE_CURVATURE && c->curvature == SFB_CURVATURE_GAUSSIAN) {
        /* the noise floor of float second derivatives: a Gaussian curvature under (1e-4 per
         * bounding radius)^2 is 0, so that a flat region is flat on every backend (the float
         * kernels leave K ~1e-10 / R^2 there where ref leaves ~1e-26, and the automatic range
         * would amplify either) */
        const double floor_k = 1e-8 / (A->radius * A->radius);
        for (k = 0; k < A->nhit; ++k)
            if (fabs(hv1[k]) < floor_k) hv1[k] = 0.0f;
    }
    L->job.duu = L->job.duv = L->job.dvv = NULL;
    sfb__an_put(A, sec);
    return r;
}

/* The picture's per-pixel values and hits on rows [y0, y1): the pixel's hit's, else no value,
 * no hit. */
typedef struct sfb__an_fill_job {
    const sfb__an *A;
    const float *hv1, *hv2;
    float *v1, *v2;
    sfb_location *hits;
} sfb__an_fill_job;

static void sfb__an_fill_picture(void *arg, int y0, int y1) {
    const sfb__an_fill_job *J = (const sfb__an_fill_job *)arg;
    const sfb__an *A = J->A;
    size_t p, end = (size_t)y1 * (size_t)A->w;
    for (p = (size_t)y0 * (size_t)A->w; p < end; ++p) {
        const int k = A->hit[p];
        if (k >= 0) {
            J->v1[p] = J->hv1[k]; J->v2[p] = J->hv2[k];
            J->hits[p] = A->hl[p];
        } else {
            J->v1[p] = J->v2[p] = NAN;
            J->hits[p].face = -1;
            J->hits[p].u = J->hits[p].v = 0.0f;
        }
    }
}

/* The finite values' smallest, largest and count, of parts [c0, c1) of SFB__AN_CHUNKS of v[0..n). */
typedef struct sfb__an_range_job {
    const float *v;
    int n;
    float *mn, *mx;
    int *cnt;
} sfb__an_range_job;
static void sfb__an_value_range(void *arg, int c0, int c1) {
    const sfb__an_range_job *R = (const sfb__an_range_job *)arg;
    int c, k;
    for (c = c0; c < c1; ++c) {
        const int a = (int)((long long)R->n * c / SFB__AN_CHUNKS), b = (int)((long long)R->n * (c + 1) / SFB__AN_CHUNKS);
        float mn = (float)HUGE_VAL, mx = (float)-HUGE_VAL;
        int n = 0;
        for (k = a; k < b; ++k)
            if (isfinite(R->v[k])) {
                if (R->v[k] < mn) mn = R->v[k];
                if (R->v[k] > mx) mx = R->v[k];
                ++n;
            }
        R->mn[c] = mn; R->mx[c] = mx; R->cnt[c] = n;
    }
}

/* Step 4: the picture and its per-pixel outputs into out (on success the arrays are out's). */
static sfb_result sfb__an_picture(sfb__an *A, sfb__an_look *L, const float *hv1, const float *hv2, sfb_analysis *out) {
    sfb_context *ctx = A->ctx;
    const sfb_analyze_config *c = A->c;
    size_t npix = (size_t)A->w * (size_t)A->h;
    float *v1 = (float *)sfb__alloc(ctx, npix * sizeof(float)), *v2 = (float *)sfb__an_get(A, SFB__WS_V2, npix * sizeof(float), NULL);
    unsigned char *rgba = (unsigned char *)sfb__alloc(ctx, npix * 4), *cls = (unsigned char *)sfb__alloc(ctx, npix);
    sfb_location *hits = (sfb_location *)sfb__alloc(ctx, npix * sizeof(sfb_location));
    sfb_result r = SFB_SUCCESS;
    int k, light_hits = 0;
    if (!v1 || !v2 || !rgba || !cls || !hits) { r = sfb__oom(ctx, "the analysis picture"); goto done; }
    {
        sfb__an_fill_job F;
        F.A = A; F.hv1 = hv1; F.hv2 = hv2; F.v1 = v1; F.v2 = v2; F.hits = hits;
        sfb__an_run(A, sfb__an_fill_picture, &F, 0, A->h, (double)npix * 0.1);
    }
    {
        /* over the threads in SFB__AN_CHUNKS parts, combined in order */
        sfb__an_range_job R;
        float mn[SFB__AN_CHUNKS], mx[SFB__AN_CHUNKS];
        int cnt[SFB__AN_CHUNKS];
        R.v = hv1; R.n = A->nhit; R.mn = mn; R.mx = mx; R.cnt = cnt;
        sfb__an_run(A, sfb__an_value_range, &R, 0, SFB__AN_CHUNKS, (double)A->nhit);
        out->value_min = (float)HUGE_VAL; out->value_max = (float)-HUGE_VAL;
        for (k = 0; k < SFB__AN_CHUNKS; ++k) {
            if (mn[k] < out->value_min) out->value_min = mn[k];
            if (mx[k] > out->value_max) out->value_max = mx[k];
            light_hits += cnt[k]; /* REFLECTION, HIGHLIGHT: a finite value is a ray that meets the light */
        }
    }
    if (c->mode != SFB_ANALYZE_REFLECTION && c->mode != SFB_ANALYZE_HIGHLIGHT) light_hits = 0;
    if (!(out->value_min <= out->value_max)) out->value_min = out->value_max = 0.0f;
    L->range = 0.0;
    if (c->mode == SFB_ANALYZE_CURVATURE && (r = sfb__an_range(A, hv1, A->nhit, &L->range)) != SFB_SUCCESS) goto done;
    {
        sfb__an_colour_job J;
        J.A = A; J.L = L; J.v1 = v1; J.v2 = v2; J.rgba = rgba; J.cls = cls;
        sfb__an_run(A, sfb__an_colour, &J, 0, A->h, (double)A->nhit);
    }
    if ((c->mode == SFB_ANALYZE_REFLECTION || c->mode == SFB_ANALYZE_HIGHLIGHT) && A->nhit > 0 && light_hits == 0) {
        r = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                       "the light plane meets none of the %d rays from the surface: it is parallel to them, behind the surface or too small",
                       A->nhit);
        goto done;
    }
    out->width = A->w; out->height = A->h;
    out->rgba = rgba; out->values = v1; out->classes = cls; out->hits = hits;
    out->light_hits = light_hits;
    out->range = (float)L->range;
    rgba = NULL; v1 = NULL; cls = NULL; hits = NULL;
done:
    sfb__free(ctx, v1); sfb__an_put(A, v2); sfb__free(ctx, rgba); sfb__free(ctx, cls); sfb__free(ctx, hits);
    return r;
}

SFB_API sfb_result sfb_surface_analyze(const sfb_surface *s, const sfb_analyze_config *cfg, sfb_analysis *out) {
    sfb_analyze_config c;
    sfb__an A;
    sfb__an_look L;
    sfb_context *ctx;
    size_t npix;
    float *hv1 = NULL, *hv2 = NULL;
    sfb_result r;
    int level = 0, fallback = 0, dropped = 0, proxy_pixels = 0, grown = 0;
    double need;
    if (out) memset(out, 0, sizeof *out);
    if (!s) return SFB_INVALID_ARGS;
    ctx = s->ctx;
    if (!out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_analyze: NULL output");
    if (!s->has_patches)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_analyze: the surface has no patch table (create it with SFB_REFINE_PATCHES)");
    c = cfg ? *cfg : sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
    memset(&A, 0, sizeof A);
    if ((r = sfb__an_check(ctx, &c, &A.w, &A.h, &level)) != SFB_SUCCESS) return r;
    A.ctx = ctx; A.s = s; A.c = &c;
    A.ws = c.workspace;
    if (A.ws && A.ws->ctx != ctx)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_analyze: the workspace was made on another context");
    A.tri = s->patches.domain == SFB__DOMAIN_TRI;
    A.nf = s->patches.nptex;
    sfb__an_camera(&A); /* the base mesh's box and the config: before the proxy, for the level */
    if (level == 0) level = c.polygon_based ? SFB__AN_DEFAULT_LEVEL : sfb__an_auto_level(&A);
    A.R = 1 << level;
    A.per = A.tri ? (A.R + 1) * (A.R + 2) / 2 : (A.R + 1) * (A.R + 1);
    npix = (size_t)A.w * (size_t)A.h;
    if ((double)A.nf * A.per > 2147483647.0)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "proxy of %d parametric faces at level %d is too large", A.nf, level);
    need = sfb__an_bytes(&A) - (double)sfb_analysis_workspace_bytes(A.ws); /* what the workspace holds is in use already */
    if (need > (double)ctx->budget - (double)ctx->live_bytes)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                          "a %d x %d analysis with a level-%d proxy needs about %.0f MB, over the memory budget (%zu bytes, %zu in use)", A.w,
                          A.h, level, need / 1048576.0, ctx->budget, ctx->live_bytes);
    if ((r = sfb__progress(ctx, 0.0f, "analyze")) != SFB_SUCCESS) return r;
    {
        /* the workspace's proxy and adjacency: kept when they are this surface's at this level */
        sfb_analysis_workspace *ws = A.ws;
        const int same = ws && s->serial != 0 && ws->proxy_serial == s->serial && ws->proxy_level == level;
        const int proxy_kept = same && ws->proxy_ok, adj_kept = same && ws->adj_ok;
        if (ws) {
            if (!same) ws->adj_ok = 0;
            ws->proxy_ok = 0; /* until computed (or kept) below */
            ws->proxy_serial = s->serial;
            ws->proxy_level = level;
        }
        if (!sfb__an_alloc(&A)) { r = sfb__oom(ctx, "the analysis buffers"); goto done; }
        /* 1: the proxy and its raster */
        if (proxy_kept) r = sfb__progress(ctx, 0.2f, "analyze");
        else r = sfb__an_proxy(&A);
        if (r != SFB_SUCCESS) goto done;
        if (ws) ws->proxy_ok = 1;
        if (!c.polygon_based && !adj_kept) {
            if (ws) ws->adj_ok = 0;
            if ((r = sfb__an_adjacency(&A)) != SFB_SUCCESS) goto done;
            if (ws) ws->adj_ok = 1;
        }
    }
    if ((r = sfb__an_raster(&A)) != SFB_SUCCESS) goto done;
    {
        /* the candidates of the projection and the proxy's pixels, row by row over the threads */
        sfb__an_cand_job J;
        int y;
        J.A = &A;
        J.rowcnt = (int *)sfb__alloc(ctx, ((size_t)A.h + 1) * sizeof(int));
        if (!J.rowcnt) { r = sfb__oom(ctx, "the analysis rows"); goto done; }
        sfb__an_run(&A, sfb__an_candidates, &J, 0, A.h, (double)npix * 0.2);
        for (y = 0; y < A.h; ++y) proxy_pixels += J.rowcnt[y];
        sfb__free(ctx, J.rowcnt);
    }
    if ((r = sfb__progress(ctx, 0.3f, "analyze")) != SFB_SUCCESS) goto done;
    /* 2: onto the exact surface (or the polygon-based data) */
    if (c.polygon_based) sfb__an_polygon_hits(&A);
    else {
        if ((r = sfb__an_project_all(&A, c.newton_steps ? c.newton_steps : SFB__AN_DEFAULT_STEPS)) != SFB_SUCCESS) goto done;
        /* grown: counted before the fallback, whose hits are all on the proxy */
        if ((r = sfb__an_leftovers(&A, &fallback, &dropped, &grown)) != SFB_SUCCESS) goto done;
    }
    if ((r = sfb__progress(ctx, 0.75f, "analyze")) != SFB_SUCCESS) goto done;
    /* 3: the values */
    sfb__an_lights(&A, &L);
    hv1 = (float *)sfb__an_get(&A, SFB__WS_HV1, ((size_t)A.nhit + 1) * sizeof(float), NULL);
    hv2 = (float *)sfb__an_get(&A, SFB__WS_HV2, ((size_t)A.nhit + 1) * sizeof(float), NULL);
    if (!hv1 || !hv2) { r = sfb__oom(ctx, "the analysis values"); goto done; }
    if ((r = sfb__an_values(&A, &L, hv1, hv2)) != SFB_SUCCESS) goto done;
    if ((r = sfb__progress(ctx, 0.9f, "analyze")) != SFB_SUCCESS) goto done;
    /* 4: colours */
    if ((r = sfb__an_picture(&A, &L, hv1, hv2, out)) != SFB_SUCCESS) goto done;
    out->covered_pixels = A.nhit;
    out->proxy_pixels = proxy_pixels;
    out->grown_pixels = grown;
    out->dropped_pixels = dropped;
    out->fallback_pixels = fallback;
    out->proxy_level = level;
    out->ctx_ = ctx;
    if ((r = sfb__progress(ctx, 1.0f, "analyze")) != SFB_SUCCESS) sfb_analysis_free(out);
done:
    if (r != SFB_SUCCESS) memset(out, 0, sizeof *out);
    sfb__an_free(&A);
    sfb__an_put(&A, hv1);
    sfb__an_put(&A, hv2);
    return r;
}
