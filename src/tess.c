/* Watertight tessellation of the limit surface (sfb_surface_tessellate).
 *
 * Every parametric face ("param face", see sfb_location) is cut into triangles in its own
 * (u,v); the vertices are evaluated through the public sfb_surface_eval, so tessellation runs
 * on whichever backend the context selected. Catmull-Clark param faces are quads (a base quad,
 * or a sub-face of an n-gon); Loop param faces are the base triangles, (u,v) barycentric with
 * corners (0,0), (1,0), (0,1) at the face's vertices in order, so every location has
 * u + v <= 1 (a point on the side u + v = 1 gets its u rounded down if float rounding would
 * put it past). A vertex on the boundary of a param face is shared with the neighbours
 * through a canonical key, so that it is created and evaluated exactly once and the mesh has
 * no cracks:
 *   - a corner at a base vertex: the base vertex (with SFB_TESS_SPLIT_CREASES: the base
 *     vertex within one sector, the faces around it reachable without crossing an infinitely
 *     sharp interior edge);
 *   - a point on a base edge: (edge, step along it from ev[0] to ev[1]); with
 *     SFB_TESS_SPLIT_CREASES an infinitely sharp interior edge has one copy per incident face,
 *     each evaluated from its own face so that it carries that side's normal;
 *   - a point on a spoke of an n-gon (from the midpoint of edge i to the centroid, shared by
 *     sub-faces i and i+1): (n-gon, spoke, step); the centroid: the n-gon.
 * Segment counts belong to those shared entities, not to the faces: a base edge has S
 * segments over its whole length, a spoke T. An n-gon's sub-face sees half of each of its
 * base edges, so an edge an n-gon uses has an even S and its midpoint (a corner of those
 * sub-faces) is one of its points; a quad beside it then sees 2*rate segments on that edge.
 * The first subdivision step puts the edge point at the parametric midpoint on both sides,
 * so step k of S is the same surface point from either face; since each point is evaluated
 * once, the mesh is closed whatever the rounding.
 *
 * A quad param face whose interior rate r equals every boundary count is a regular r x r
 * grid, two triangles per cell (diagonal (i,j)-(i+1,j+1)); a triangle face with all three
 * counts r is the triangular grid of the points (i/r, j/r), i + j <= r, r^2 triangles.
 * Otherwise (adaptive rates, quads beside n-gons) a quad gets an inner grid of rate
 * R = max(r,2) without its outer ring, a triangle the points of the rate R = max(r,3)
 * triangular grid that are not on its sides (an inner triangular grid of rate R - 3), and
 * each side is stitched from its boundary points to the inner grid's side by a zipper strip:
 * no T-junctions. Triangles are counter-clockwise in (u,v), which is the du x dv normal side.
 *
 * Adaptive mode (tolerance > 0): a param face gets the first rate c in 1, 2, 4, ... (< rate,
 * else rate) for which the surface at the midpoints of the c-grid's edges (quads: the c x c
 * grid's cell edges and diagonals; triangles: the three edges of each of its c^2 triangles)
 * is within `tolerance` of the chords; a shared edge takes the largest rate of its faces.
 * This samples the surface: a feature narrower than a cell can be missed at that rate.
 *
 * Trimming (cfg->trim, seed 000 section V.5): param face t reads tile t of the mask (every face
 * the one mask when the atlas is 0 x 0 or 1 x 1; faces past the last tile are not trimmed)
 * through the bilinear interpolation of its texel centres, clamped at the tile's borders; a
 * point is kept where the value / 255 is >= 0.5. A tile whose texels are all >= 128 keeps its
 * face whole and one whose texels are all <= 127 drops it (the bilinear value lies between its
 * texels' extremes). Otherwise the 0.5 contour crosses the tile, and the face's rate is raised
 * to max(tile width, tile height) (at most SFB__TESS_MAX_RATE) so that a cell is at most one
 * texel wide: the contour is followed within one texel whatever rate was asked for. The raised
 * rates go through the per-face rates and shared edge counts of adaptive mode, so faces of
 * different rates still meet without cracks.
 * Every triangle corner is then classified by its own face's mask at its (u,v) in that face:
 * a triangle with three trimmed corners is dropped, one with three kept corners kept, and
 * otherwise each edge whose ends differ is cut where the mask first changes sides walking from
 * its lower vertex id. Along a segment the mask is a quadratic in the segment's parameter
 * between the texel-centre lines it crosses; each such piece is split at its extremum into
 * monotone parts and the first part whose ends differ is bisected on the exact bilinear value,
 * in double precision. The kept part (a triangle, or a convex quad split along its shorter
 * (u,v) diagonal) keeps the triangle's counter-clockwise order. Where the contour bends inside
 * a cell the straight cut leaves a sliver of less than a cell on one side.
 * A cut point is keyed by its tessellation edge (the two vertex ids) in a hash table, so the
 * two triangles on an edge share one vertex and the kept mesh stays watertight. On an edge
 * between two param faces each face cuts with its own mask: the faces share the point when
 * they put it at the same place along the edge (within 1e-7 of its length), else each side
 * has its own and the seam opens there, as the masks disagree. A cut within SFB__TRIM_SNAP of
 * an end in (u,v) (a few float steps: it would round onto it) is that end, and a kept polygon
 * that repeats a vertex loses the repeat (fewer than 3 left: nothing). Cut points are new
 * vertices, located in the face that made them and evaluated with the others through
 * sfb_surface_eval, so on the selected backend. Vertices that no kept triangle uses are
 * removed and the others keep their order, so an all-white mask gives the untrimmed output
 * exactly.
 *
 * Thread safety: reads the surface only; allocations, errors and progress go through the
 * surface's context, so one call per context at a time. */

#define SFB__TESS_MAX_RATE 1024
#define SFB__TESS_MAX_SEG (2 * SFB__TESS_MAX_RATE) /* a quad edge beside an n-gon sub-face */
#define SFB__TESS_EVAL_CHUNK 65536                 /* locations per sfb_surface_eval call */
#define SFB__TESS_FACE_CHUNK 1024                  /* param faces between progress reports */
#define SFB__TRIM_MAX_SIZE 16384                   /* texels on a side of a trimming mask */
#define SFB__TRIM_SNAP 2.5e-7                      /* a cut this near an end of its edge, in (u,v), is that end */

SFB_API sfb_tess_config sfb_tess_config_init(int rate) {
    sfb_tess_config c;
    memset(&c, 0, sizeof c);
    c.rate = rate;
    return c;
}

SFB_API void sfb_tess_data_free(sfb_tess_data *d) {
    sfb_context *ctx;
    if (!d) return;
    ctx = d->ctx_;
    if (ctx) {
        sfb__free(ctx, d->positions); sfb__free(ctx, d->normals); sfb__free(ctx, d->locations);
        sfb__free(ctx, d->triangles); sfb__free(ctx, d->triangle_faces); sfb__free(ctx, d->uvs);
    }
    memset(d, 0, sizeof *d);
}

/* A cut point: the edge (lo << 32 | hi, vertex ids), its place t from lo to hi, the vertex
 * and the param face that computed it. vid < 0: an empty slot. */
typedef struct sfb__trim_cut {
    unsigned long long key;
    double t;
    int vid, face;
} sfb__trim_cut;

typedef struct sfb__tess {
    sfb_context *ctx;
    const sfb_surface *s;
    const sfb__level *l;          /* the prepared base level the patches were built from */
    const sfb__patch_table *pt;
    int rate, split;              /* split: some edges have a copy per face (esplit) */
    unsigned char *esplit;        /* split: per base edge, its faces get their own copies of its points */
    int loop;                     /* Loop: every param face is a base triangle */
    int *prate;                   /* per param face: interior rate, 0 = nothing (hole) */
    int *eseg;                    /* per base edge: segments over the whole edge */
    unsigned char *engon;         /* per base edge: an n-gon uses it (eseg is then even) */
    int *sseg;                    /* per n-gon sub-face i (param face): segments of spoke i */
    int *uf;                      /* split: union-find over face corners, one set per sector */
    int *ecopy;                   /* split: per face corner slot, the ef entry of its outgoing edge */
    int *vcorner;                 /* vertex of each base vertex (split: of each sector's root corner) */
    int *vedge;                   /* per ef entry: first vertex of the interior points of that edge copy */
    int *vspoke;                  /* per n-gon sub-face: first vertex of the interior points of its spoke */
    int *vcenter;                 /* per base face: its centroid vertex (n-gons) */
    int *ifirst;                  /* per param face: first vertex of its interior points */
    int *bids;                    /* scratch: 4 boundary chains, then one outer and one inner chain */
    size_t nvert, ntri;
    /* emit pass */
    sfb_location *loc;
    int *tri, *tface;
    size_t tri_at;
    /* trimming (NULL trim: none of these is used) */
    const sfb_trim_mask *trim;
    int ntiles, tiles_u, tw, th;  /* tiles in use (1: one mask for all faces), tile size in texels */
    unsigned char *fstate;        /* per param face: SFB__TRIM_KEEP, _DROP or _CUT */
    double *cuv;                  /* per vertex: (u,v) in the face being emitted (faces to cut) */
    unsigned char *ckept;         /* per vertex: kept by that face's mask */
    int *otri, *oface;            /* trimmed triangles (grown) */
    size_t ocount, ocap;
    sfb_location *nloc;           /* cut points: vertex nvert + i (grown) */
    size_t nnew, ncap;
    sfb__trim_cut *cuts;          /* hash table of cut points by tessellation edge */
    size_t cut_cap, cut_count;
    sfb_result err;               /* first failure inside the emit pass */
} sfb__tess;

enum { SFB__TRIM_KEEP = 0, SFB__TRIM_DROP = 1, SFB__TRIM_CUT = 2 };

static void *sfb__tess_array(sfb_context *ctx, size_t count, size_t size) {
    size_t bytes;
    if (!sfb__mul_size(count, size, &bytes) || bytes > ((size_t)-1) - 16) return NULL;
    return sfb__alloc(ctx, bytes + 1); /* + 1: never a zero-size block */
}

static void sfb__tess_free_work(sfb__tess *T) {
    sfb_context *ctx = T->ctx;
    sfb__free(ctx, T->prate); sfb__free(ctx, T->eseg); sfb__free(ctx, T->engon); sfb__free(ctx, T->sseg);
    sfb__free(ctx, T->uf); sfb__free(ctx, T->ecopy); sfb__free(ctx, T->vcorner); sfb__free(ctx, T->vedge);
    sfb__free(ctx, T->vspoke); sfb__free(ctx, T->vcenter); sfb__free(ctx, T->ifirst); sfb__free(ctx, T->bids);
    T->prate = T->eseg = T->sseg = T->uf = T->ecopy = T->vcorner = T->vedge = T->vspoke = T->vcenter = T->ifirst = T->bids = NULL;
    sfb__free(ctx, T->esplit);
    T->engon = T->esplit = NULL;
    sfb__free(ctx, T->fstate); sfb__free(ctx, T->cuv); sfb__free(ctx, T->ckept); sfb__free(ctx, T->otri);
    sfb__free(ctx, T->oface); sfb__free(ctx, T->nloc); sfb__free(ctx, T->cuts);
    T->fstate = T->ckept = NULL;
    T->cuv = NULL;
    T->otri = T->oface = NULL;
    T->nloc = NULL;
    T->cuts = NULL;
    if (T->trim) sfb__free(ctx, T->loc); /* trimming: the untrimmed locations are scratch */
    T->loc = NULL;
}

static int sfb__tess_face_n(const sfb__level *l, int f) { return l->fv_off[f + 1] - l->fv_off[f]; }

/* Edges whose sides get their own vertices (sfb__tess_mark_splits): under SFB_TESS_SPLIT_CREASES
 * the infinitely sharp interior ones, under SFB_TESS_UVS the UV seams. */
static int sfb__tess_split_edge(const sfb__tess *T, int e) { return T->split && T->esplit[e]; }

/* Whether the faces of base edge e disagree on the UV at either of its ends (uvl: the base UV
 * layout, whose faces are the base level's). */
static int sfb__tess_uv_seam(const sfb__level *l, const sfb__level *uvl, int e) {
    int a = l->ef_off[e], z = l->ef_off[e + 1], q, u0 = -1, u1 = -1;
    for (q = a; q < z; ++q) {
        int g = l->ef[q], o = l->fv_off[g], n = l->fv_off[g + 1] - o, sl = l->ef_slot[q];
        int c0 = o + sl, c1 = o + (sl + 1) % n, t;
        if (l->fv[c0] != l->ev[2 * e]) { t = c0; c0 = c1; c1 = t; } /* c0 at ev[0], c1 at ev[1] */
        if (q == a) { u0 = uvl->fv[c0]; u1 = uvl->fv[c1]; }
        else if (uvl->fv[c0] != u0 || uvl->fv[c1] != u1) return 1;
    }
    return 0;
}

/* An infinitely sharp edge not on the boundary (a boundary edge has one side only). */
static int sfb__tess_crease_edge(const sfb__level *l, int e) {
    return l->es[e] >= SFB_SHARPNESS_INFINITE && !(l->etag[e] & SFB__TAG_BOUNDARY);
}

static int sfb__tess_find(int *uf, int x) {
    while (uf[x] != x) {
        uf[x] = uf[uf[x]];
        x = uf[x];
    }
    return x;
}

static void sfb__tess_union(int *uf, int a, int b) {
    a = sfb__tess_find(uf, a);
    b = sfb__tess_find(uf, b);
    if (a < b) uf[b] = a;
    else if (b < a) uf[a] = b;
}

static int sfb__tess_new(sfb__tess *T, int count) {
    int id = (int)T->nvert;
    T->nvert += (size_t)count;
    return id;
}

/* (u,v) as floats; on a triangle param face u is rounded down where rounding both to nearest
 * would give u + v > 1 (points on the side u + v = 1), which evaluation refuses. */
static void sfb__tess_uv(int tri, double u, double v, sfb_location *L) {
    float fu = (float)u, fv = (float)v;
    if (tri && (double)fu + (double)fv > 1.0) {
        fu = (float)(1.0 - (double)fv);
        while (fu > 0.0f && (double)fu + (double)fv > 1.0) fu = nextafterf(fu, 0.0f);
    }
    L->u = fu;
    L->v = fv;
}

/* ---- trimming ---- */

/* The mask tile of param face pf (its first texel; rows are the mask's width apart), or NULL
 * for a face past the last tile of an atlas. */
static const unsigned char *sfb__trim_tile(const sfb__tess *T, int pf) {
    const sfb_trim_mask *m = T->trim;
    if (T->ntiles == 1) return m->texels;
    if (pf < 0 || pf >= T->ntiles) return NULL;
    return m->texels + (size_t)(pf / T->tiles_u) * (size_t)T->th * (size_t)m->width + (size_t)(pf % T->tiles_u) * (size_t)T->tw;
}

/* The mask at (u,v) of a tile, in [0,1]: the bilinear interpolation of the texel centres,
 * clamped at the tile's borders, / 255. */
static double sfb__trim_value(const sfb__tess *T, const unsigned char *tile, double u, double v) {
    int tw = T->tw, th = T->th, i0, j0, i1, j1;
    size_t w = (size_t)T->trim->width;
    double x = u * tw - 0.5, y = v * th - 0.5, fx, fy, a, b;
    if (!(x > 0.0)) x = 0.0; /* NaN too */
    if (x > tw - 1) x = tw - 1;
    if (!(y > 0.0)) y = 0.0;
    if (y > th - 1) y = th - 1;
    i0 = (int)x;
    j0 = (int)y;
    if (i0 > tw - 2) i0 = tw > 1 ? tw - 2 : 0;
    if (j0 > th - 2) j0 = th > 1 ? th - 2 : 0;
    fx = x - i0;
    fy = y - j0;
    i1 = tw > 1 ? i0 + 1 : i0;
    j1 = th > 1 ? j0 + 1 : j0;
    a = (1.0 - fx) * tile[(size_t)j0 * w + (size_t)i0] + fx * tile[(size_t)j0 * w + (size_t)i1];
    b = (1.0 - fx) * tile[(size_t)j1 * w + (size_t)i0] + fx * tile[(size_t)j1 * w + (size_t)i1];
    return ((1.0 - fy) * a + fy * b) / 255.0;
}

/* Kept (1) or trimmed (0) at p0 + t (p1 - p0); t = 1 is p1 itself. */
static int sfb__trim_kept_at(const sfb__tess *T, const unsigned char *tile, const double *p0, const double *p1, double t) {
    double u = p1[0], v = p1[1];
    if (t < 1.0) {
        u = p0[0] + t * (p1[0] - p0[0]);
        v = p0[1] + t * (p1[1] - p0[1]);
    }
    return sfb__trim_value(T, tile, u, v) >= 0.5;
}

static double sfb__trim_g(const sfb__tess *T, const unsigned char *tile, const double *p0, const double *p1, double t) {
    double u = p1[0], v = p1[1];
    if (t < 1.0) {
        u = p0[0] + t * (p1[0] - p0[0]);
        v = p0[1] + t * (p1[1] - p0[1]);
    }
    return sfb__trim_value(T, tile, u, v) - 0.5;
}

/* The texel-centre lines x = k (integers 0..n-1, where the bilinear pieces change) strictly
 * between x0 and x0 + dx: from *k in steps *step while *k != *end. */
static void sfb__trim_lines(double x0, double dx, int n, long *k, long *end, int *step) {
    double x1 = x0 + dx;
    long first, last;
    *step = dx > 0.0 ? 1 : -1;
    *k = *end = 0;
    if (!(dx != 0.0)) return;
    if (dx > 0.0) {
        first = (long)floor(x0) + 1;
        last = (long)ceil(x1) - 1;
        if (first < 0) first = 0;
        if (last > n - 1) last = n - 1;
        if (first <= last) { *k = first; *end = last + 1; }
    } else {
        first = (long)ceil(x0) - 1;
        last = (long)floor(x1) + 1;
        if (first > n - 1) first = n - 1;
        if (last < 0) last = 0;
        if (first >= last) { *k = first; *end = last - 1; }
    }
}

/* Where the mask first changes sides along p0 -> p1, whose ends are on different sides
 * (kept0: the side of p0). Between texel-centre lines the mask is a quadratic in t; each
 * piece is split at its extremum into monotone parts, and the first part whose ends differ
 * is bisected on the exact value. Returns t in (0,1]. */
static double sfb__trim_solve(const sfb__tess *T, const unsigned char *tile, const double *p0, const double *p1, int kept0) {
    double x0 = p0[0] * T->tw - 0.5, dx = (p1[0] - p0[0]) * T->tw;
    double y0 = p0[1] * T->th - 0.5, dy = (p1[1] - p0[1]) * T->th;
    double ta = 0.0;
    long kx, kx_end, ky, ky_end;
    int sx, sy;
    sfb__trim_lines(x0, dx, T->tw, &kx, &kx_end, &sx);
    sfb__trim_lines(y0, dy, T->th, &ky, &ky_end, &sy);
    for (;;) {
        double tb = 1.0, tx = 2.0, ty = 2.0;
        if (kx != kx_end) tx = ((double)kx - x0) / dx;
        if (ky != ky_end) ty = ((double)ky - y0) / dy;
        if (tx <= ty && tx < 1.0) { tb = tx; kx += sx; }
        else if (ty < 1.0) { tb = ty; ky += sy; }
        if (tb > ta) {
            double ga = sfb__trim_g(T, tile, p0, p1, ta), gm = sfb__trim_g(T, tile, p0, p1, 0.5 * (ta + tb));
            double gb = sfb__trim_g(T, tile, p0, p1, tb), c = 2.0 * (gb + ga - 2.0 * gm), b = gb - ga - c, ends[2], lo = ta;
            int n = 0, q;
            if (c != 0.0) {
                double sm = -b / (2.0 * c);
                if (sm > 0.0 && sm < 1.0) ends[n++] = ta + sm * (tb - ta);
            }
            ends[n++] = tb;
            for (q = 0; q < n; ++q) {
                double hi = ends[q];
                if (sfb__trim_kept_at(T, tile, p0, p1, hi) != kept0) {
                    int it;
                    for (it = 0; it < 80; ++it) {
                        double mid = 0.5 * (lo + hi);
                        if (!(mid > lo && mid < hi)) break;
                        if (sfb__trim_kept_at(T, tile, p0, p1, mid) == kept0) lo = mid;
                        else hi = mid;
                    }
                    return 0.5 * (lo + hi);
                }
                lo = hi;
            }
            ta = tb;
        }
        if (tb >= 1.0) break;
    }
    return 1.0; /* not reached: p1 is on the other side */
}

static size_t sfb__trim_hash(unsigned long long key) {
    key ^= key >> 29;
    key *= 0x9E3779B97F4A7C15ULL;
    return (size_t)(key ^ (key >> 32));
}

/* Grows an array to hold at least `need` elements (doubling); 0 when that fails. */
static int sfb__trim_grow(sfb_context *ctx, void **p, size_t *cap, size_t need, size_t elem) {
    size_t nc = *cap ? *cap : 1024, bytes;
    void *np;
    if (need <= *cap) return 1;
    while (nc < need) nc *= 2;
    if (!sfb__mul_size(nc, elem, &bytes)) return 0;
    np = sfb__realloc(ctx, *p, bytes);
    if (!np) return 0;
    *p = np;
    *cap = nc;
    return 1;
}

static void sfb__trim_fail(sfb__tess *T, sfb_result r) {
    if (T->err == SFB_SUCCESS) T->err = r;
}

/* Adds an entry to the cut table, growing it to stay at most half full. */
static int sfb__trim_insert(sfb__tess *T, unsigned long long key, double t, int vid, int face) {
    size_t i, mask;
    if ((T->cut_count + 1) * 2 > T->cut_cap) {
        size_t nc = T->cut_cap * 2, j;
        sfb__trim_cut *nt = (sfb__trim_cut *)sfb__tess_array(T->ctx, nc, sizeof(sfb__trim_cut));
        if (!nt) return 0;
        for (j = 0; j < nc; ++j) nt[j].vid = -1;
        for (j = 0; j < T->cut_cap; ++j)
            if (T->cuts[j].vid >= 0) {
                for (i = sfb__trim_hash(T->cuts[j].key) & (nc - 1); nt[i].vid >= 0; i = (i + 1) & (nc - 1)) {}
                nt[i] = T->cuts[j];
            }
        sfb__free(T->ctx, T->cuts);
        T->cuts = nt;
        T->cut_cap = nc;
    }
    mask = T->cut_cap - 1;
    for (i = sfb__trim_hash(key) & mask; T->cuts[i].vid >= 0; i = (i + 1) & mask) {}
    T->cuts[i].key = key;
    T->cuts[i].t = t;
    T->cuts[i].vid = vid;
    T->cuts[i].face = face;
    T->cut_count++;
    return 1;
}

/* The vertex where the edge p-q of a triangle of param face pf crosses the contour, with its
 * (u,v) in that face; -1 (T->err set) on failure. */
static int sfb__trim_cut_edge(sfb__tess *T, const unsigned char *tile, int p, int q, int pf, double *uv) {
    int lo = p < q ? p : q, hi = p < q ? q : p, vid = -1, found = 0;
    const double *a = T->cuv + 2 * (size_t)lo, *b = T->cuv + 2 * (size_t)hi;
    unsigned long long key = (unsigned long long)(unsigned)lo << 32 | (unsigned)hi;
    size_t mask = T->cut_cap - 1, i;
    double t = 0.0;
    for (i = sfb__trim_hash(key) & mask; T->cuts[i].vid >= 0; i = (i + 1) & mask)
        if (T->cuts[i].key == key && T->cuts[i].face == pf) { /* this face cut it already */
            t = T->cuts[i].t;
            vid = T->cuts[i].vid;
            found = 1;
            break;
        }
    if (!found) {
        double len = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]));
        t = sfb__trim_solve(T, tile, a, b, T->ckept[lo]);
        if (t <= 1e-9 || t * len <= SFB__TRIM_SNAP) vid = lo;
        else if (t >= 1.0 - 1e-9 || (1.0 - t) * len <= SFB__TRIM_SNAP) vid = hi;
        else
            for (i = sfb__trim_hash(key) & mask; T->cuts[i].vid >= 0; i = (i + 1) & mask)
                if (T->cuts[i].key == key && fabs(T->cuts[i].t - t) <= 1e-7) { /* another face cut it at the same place */
                    vid = T->cuts[i].vid;
                    break;
                }
    }
    if (vid == lo) { uv[0] = a[0]; uv[1] = a[1]; }
    else if (vid == hi) { uv[0] = b[0]; uv[1] = b[1]; }
    else { uv[0] = a[0] + t * (b[0] - a[0]); uv[1] = a[1] + t * (b[1] - a[1]); }
    if (found) return vid;
    if (vid < 0) {
        sfb_location *L;
        if (T->nvert + T->nnew >= (size_t)SFB_MAX_ELEMENTS) {
            sfb__trim_fail(T, sfb__error(T->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                                         "trimmed tessellation makes more than %d vertices (SFB_MAX_ELEMENTS)", SFB_MAX_ELEMENTS));
            return -1;
        }
        if (!sfb__trim_grow(T->ctx, (void **)&T->nloc, &T->ncap, T->nnew + 1, sizeof(sfb_location))) {
            sfb__trim_fail(T, sfb__oom(T->ctx, "tessellation"));
            return -1;
        }
        vid = (int)(T->nvert + T->nnew);
        L = &T->nloc[T->nnew++];
        L->face = pf;
        sfb__tess_uv(T->loop, uv[0] < 0.0 ? 0.0 : uv[0] > 1.0 ? 1.0 : uv[0], uv[1] < 0.0 ? 0.0 : uv[1] > 1.0 ? 1.0 : uv[1], L);
    }
    if (!sfb__trim_insert(T, key, t, vid, pf)) {
        sfb__trim_fail(T, sfb__oom(T->ctx, "tessellation"));
        return -1;
    }
    return vid;
}

static void sfb__trim_push(sfb__tess *T, int a, int b, int c, int pf) {
    size_t cap = T->ocap;
    if (T->ocount >= (size_t)SFB_MAX_ELEMENTS) {
        sfb__trim_fail(T, sfb__error(T->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                                     "trimmed tessellation makes more than %d triangles (SFB_MAX_ELEMENTS)", SFB_MAX_ELEMENTS));
        return;
    }
    if (T->ocount >= cap) { /* both arrays to twice the triangles */
        size_t nc = cap ? 2 * cap : 1024, b1, b3;
        int *nf = NULL, *nt = NULL;
        if (sfb__mul_size(nc, sizeof(int), &b1) && sfb__mul_size(nc, 3 * sizeof(int), &b3)) {
            nf = (int *)sfb__realloc(T->ctx, T->oface, b1);
            if (nf) T->oface = nf;
            nt = nf ? (int *)sfb__realloc(T->ctx, T->otri, b3) : NULL;
        }
        if (!nt) {
            sfb__trim_fail(T, sfb__oom(T->ctx, "tessellation"));
            return;
        }
        T->otri = nt;
        T->ocap = nc;
    }
    T->otri[3 * T->ocount] = a;
    T->otri[3 * T->ocount + 1] = b;
    T->otri[3 * T->ocount + 2] = c;
    T->oface[T->ocount++] = pf;
}

/* One triangle (counter-clockwise) of param face pf through the mask: dropped, kept, or cut
 * to its kept part. */
static void sfb__trim_triangle(sfb__tess *T, int a, int b, int c, int pf) {
    const unsigned char *tile;
    int v[3], poly[4], ids[4], n = 0, m = 0, k;
    double puv[4][2], quv[4][2];
    if (T->err != SFB_SUCCESS || T->fstate[pf] == SFB__TRIM_DROP) return;
    if (T->fstate[pf] == SFB__TRIM_KEEP || (T->ckept[a] && T->ckept[b] && T->ckept[c])) {
        sfb__trim_push(T, a, b, c, pf);
        return;
    }
    if (!T->ckept[a] && !T->ckept[b] && !T->ckept[c]) return;
    tile = sfb__trim_tile(T, pf);
    v[0] = a; v[1] = b; v[2] = c;
    for (k = 0; k < 3; ++k) {
        int p = v[k], q = v[(k + 1) % 3];
        if (T->ckept[p]) {
            poly[n] = p;
            puv[n][0] = T->cuv[2 * (size_t)p];
            puv[n][1] = T->cuv[2 * (size_t)p + 1];
            ++n;
        }
        if (T->ckept[p] != T->ckept[q]) {
            int x = sfb__trim_cut_edge(T, tile, p, q, pf, puv[n]);
            if (x < 0) return;
            poly[n++] = x;
        }
    }
    /* a cut point at a corner repeats it: drop repeats (cyclically) */
    for (k = 0; k < n; ++k)
        if (m == 0 || ids[m - 1] != poly[k]) {
            ids[m] = poly[k];
            quv[m][0] = puv[k][0];
            quv[m][1] = puv[k][1];
            ++m;
        }
    while (m > 1 && ids[m - 1] == ids[0]) --m;
    if (m == 3) {
        sfb__trim_push(T, ids[0], ids[1], ids[2], pf);
    } else if (m == 4) { /* convex: split along the shorter diagonal */
        double d02 = (quv[0][0] - quv[2][0]) * (quv[0][0] - quv[2][0]) + (quv[0][1] - quv[2][1]) * (quv[0][1] - quv[2][1]);
        double d13 = (quv[1][0] - quv[3][0]) * (quv[1][0] - quv[3][0]) + (quv[1][1] - quv[3][1]) * (quv[1][1] - quv[3][1]);
        if (d02 <= d13) {
            sfb__trim_push(T, ids[0], ids[1], ids[2], pf);
            sfb__trim_push(T, ids[0], ids[2], ids[3], pf);
        } else {
            sfb__trim_push(T, ids[1], ids[2], ids[3], pf);
            sfb__trim_push(T, ids[1], ids[3], ids[0], pf);
        }
    }
}

/* The location a vertex is evaluated at: the first param face that reaches it in the emit
 * pass (for a split crease copy that is always a face on its own side). */
static void sfb__tess_loc(sfb__tess *T, int id, int pf, double u, double v) {
    if (T->loc && T->loc[id].face < 0) {
        T->loc[id].face = pf;
        sfb__tess_uv(T->loop, u, v, &T->loc[id]);
    }
    if (T->cuv && T->fstate[pf] == SFB__TRIM_CUT) { /* trimming: where this face sees it, and its side */
        T->cuv[2 * (size_t)id] = u;
        T->cuv[2 * (size_t)id + 1] = v;
        T->ckept[id] = (unsigned char)(sfb__trim_value(T, sfb__trim_tile(T, pf), u, v) >= 0.5);
    }
}

static int sfb__tess_corner(sfb__tess *T, int f, int slot) {
    int c = T->l->fv_off[f] + slot;
    int key = T->split ? sfb__tess_find(T->uf, c) : T->l->fv[c];
    if (T->vcorner[key] < 0) T->vcorner[key] = sfb__tess_new(T, 1);
    return T->vcorner[key];
}

/* Point `fidx` of the S points of face f's edge `slot`, counted in the face's direction
 * (fidx 0 = the face's vertex at `slot`). Shared by every face on that edge copy through the
 * edge's own direction. */
static int sfb__tess_epoint(sfb__tess *T, int f, int slot, int fidx) {
    const sfb__level *l = T->l;
    int o = l->fv_off[f], n = l->fv_off[f + 1] - o, e = l->fe[o + slot], S = T->eseg[e], copy, g;
    if (fidx <= 0) return sfb__tess_corner(T, f, slot);
    if (fidx >= S) return sfb__tess_corner(T, f, (slot + 1) % n);
    copy = sfb__tess_split_edge(T, e) ? T->ecopy[o + slot] : l->ef_off[e];
    if (T->vedge[copy] < 0) T->vedge[copy] = sfb__tess_new(T, S - 1);
    g = l->fv[o + slot] == l->ev[2 * e] ? fidx : S - fidx;
    return T->vedge[copy] + g - 1;
}

static int sfb__tess_center(sfb__tess *T, int f) {
    if (T->vcenter[f] < 0) T->vcenter[f] = sfb__tess_new(T, 1);
    return T->vcenter[f];
}

/* Point t of spoke i of n-gon f: t = 0 at the midpoint of edge i, t = T at the centroid. */
static int sfb__tess_spoke(sfb__tess *T, int f, int i, int t) {
    const sfb__level *l = T->l;
    int pf = T->pt->face_ptex[f] + i, n = T->sseg[pf];
    if (t <= 0) return sfb__tess_epoint(T, f, i, T->eseg[l->fe[l->fv_off[f] + i]] / 2);
    if (t >= n) return sfb__tess_center(T, f);
    if (T->vspoke[pf] < 0) T->vspoke[pf] = sfb__tess_new(T, n - 1);
    return T->vspoke[pf] + t - 1;
}

static void sfb__tess_tri(sfb__tess *T, int a, int b, int c, int pf) {
    size_t t;
    if (T->trim) {
        T->tri_at++;
        sfb__trim_triangle(T, a, b, c, pf);
        return;
    }
    t = T->tri_at++;
    T->tri[3 * t] = a;
    T->tri[3 * t + 1] = b;
    T->tri[3 * t + 2] = c;
    T->tface[t] = pf;
}

/* Stitches a boundary chain (na segments, point i at i/na along the side) to the inner
 * grid's side (nb segments, point j at (j + o2/2)/R: o2 = 2 on a quad, where the inner grid's
 * side is inset by one cell; o2 = 3 on a triangle, where the inner triangle's corner (1,1)
 * projects to 1.5/R along each side), both running counter-clockwise around the face. Each
 * step adds the triangle whose new cross edge is the more nearly perpendicular to the side
 * (positions compared in units of 1/(2 na R), exactly), which keeps them well shaped. */
static void sfb__tess_zipper(sfb__tess *T, const int *outer, int na, const int *inner, int nb, int R, int o2, int pf) {
    int i = 0, j = 0;
    while (i < na || j < nb) {
        long to = labs(2L * (i + 1) * R - (long)(2 * j + o2) * na);     /* outer step: edge outer[i+1] - inner[j] */
        long ti = labs((long)(2 * j + 2 + o2) * na - 2L * i * R);       /* inner step: edge outer[i] - inner[j+1] */
        if (j >= nb || (i < na && to <= ti)) {
            sfb__tess_tri(T, outer[i], outer[i + 1], inner[j], pf);
            ++i;
        } else {
            sfb__tess_tri(T, outer[i], inner[j + 1], inner[j], pf);
            ++j;
        }
    }
}

/* A triangle param face (Loop), as sfb__tess_face. Its sides, counter-clockwise in (u,v):
 * edge 0 from P0 (0,0) to P1 (1,0), edge 1 from P1 to P2 (0,1), edge 2 from P2 to P0; point
 * (i,j) of a rate-R grid is (i/R, j/R). The points strictly inside (i, j >= 1,
 * i + j <= R - 1) are numbered row by row in j, row j holding i = 1 .. R-1-j. */
static void sfb__tess_face_tri(sfb__tess *T, int pf, int emit) {
    const sfb__level *l = T->l;
    int f = T->pt->ptex_face[pf], r = T->prate[pf];
    int o = l->fv_off[f], s[3], *b[3], *inner, k, q, i, j, regular, R, base;
    if (r <= 0) return;
    for (k = 0; k < 3; ++k) {
        b[k] = T->bids + (size_t)k * (SFB__TESS_MAX_SEG + 1);
        s[k] = T->eseg[l->fe[o + k]];
        for (q = 0; q <= s[k]; ++q) b[k][q] = sfb__tess_epoint(T, f, k, q);
    }
    inner = T->bids + (size_t)5 * (SFB__TESS_MAX_SEG + 1);
    regular = s[0] == r && s[1] == r && s[2] == r;
    R = regular ? r : (r < 3 ? 3 : r);
    if (!emit) {
        T->ifirst[pf] = sfb__tess_new(T, (R - 1) * (R - 2) / 2);
        if (regular) T->ntri += (size_t)r * (size_t)r;
        else T->ntri += (size_t)(R - 3) * (size_t)(R - 3) + (size_t)s[0] + (size_t)s[1] + (size_t)s[2] + (size_t)3 * (size_t)(R - 3);
        return;
    }
    for (q = 0; q <= s[0]; ++q) sfb__tess_loc(T, b[0][q], pf, (double)q / s[0], 0.0);
    for (q = 0; q <= s[1]; ++q) sfb__tess_loc(T, b[1][q], pf, (double)(s[1] - q) / s[1], (double)q / s[1]);
    for (q = 0; q <= s[2]; ++q) sfb__tess_loc(T, b[2][q], pf, 0.0, (double)(s[2] - q) / s[2]);
    base = T->ifirst[pf];
#define SFB__TRI_INNER(i, j) (base + ((j) - 1) * (R - 1) - ((j) - 1) * (j) / 2 + ((i) - 1))
    for (j = 1; j < R - 1; ++j)
        for (i = 1; i + j < R; ++i) sfb__tess_loc(T, SFB__TRI_INNER(i, j), pf, (double)i / R, (double)j / R);
    if (regular) {
#define SFB__TRI_ID(i, j) ((j) == 0 ? b[0][i] : (i) + (j) == r ? b[1][j] : (i) == 0 ? b[2][r - (j)] : SFB__TRI_INNER(i, j))
        for (j = 0; j < r; ++j)
            for (i = 0; i + j < r; ++i) {
                sfb__tess_tri(T, SFB__TRI_ID(i, j), SFB__TRI_ID(i + 1, j), SFB__TRI_ID(i, j + 1), pf);
                if (i + j + 2 <= r) sfb__tess_tri(T, SFB__TRI_ID(i + 1, j), SFB__TRI_ID(i + 1, j + 1), SFB__TRI_ID(i, j + 1), pf);
            }
#undef SFB__TRI_ID
        return;
    }
    /* the inner triangular grid: points with i, j >= 1, i + j <= R - 1 */
    for (j = 1; j + 2 < R; ++j)
        for (i = 1; i + j + 2 <= R; ++i) {
            sfb__tess_tri(T, SFB__TRI_INNER(i, j), SFB__TRI_INNER(i + 1, j), SFB__TRI_INNER(i, j + 1), pf);
            if (i + j + 3 <= R) sfb__tess_tri(T, SFB__TRI_INNER(i + 1, j), SFB__TRI_INNER(i + 1, j + 1), SFB__TRI_INNER(i, j + 1), pf);
        }
    /* the ring, one side at a time, counter-clockwise; the inner side of side k runs between
     * the inner corners (1,1), (R-2,1), (1,R-2) in the same order */
    for (k = 0; k < 3; ++k) {
        for (q = 0; q <= R - 3; ++q)
            inner[q] = k == 0 ? SFB__TRI_INNER(1 + q, 1) : k == 1 ? SFB__TRI_INNER(R - 2 - q, 1 + q) : SFB__TRI_INNER(1, R - 2 - q);
        sfb__tess_zipper(T, b[k], s[k], inner, R - 3, R, 3, pf);
    }
#undef SFB__TRI_INNER
}

/* One param face. Count pass (emit = 0): creates the ids of every point it touches and
 * counts its triangles. Emit pass: records the locations of points not yet located and
 * writes the triangles. Both passes visit faces in the same order, so ids agree. */
static void sfb__tess_face(sfb__tess *T, int pf, int emit) {
    const sfb__level *l = T->l;
    int f = T->pt->ptex_face[pf], sub = T->pt->ptex_corner[pf], r = T->prate[pf];
    int o = l->fv_off[f], s[4], *b[4], *outer, *inner, k, i, j, regular, R, base;
    if (T->loop) {
        sfb__tess_face_tri(T, pf, emit);
        return;
    }
    if (r <= 0) return;
    for (k = 0; k < 4; ++k) b[k] = T->bids + (size_t)k * (SFB__TESS_MAX_SEG + 1);
    outer = T->bids + (size_t)4 * (SFB__TESS_MAX_SEG + 1);
    inner = outer + (SFB__TESS_MAX_SEG + 1);
    /* the four sides in natural order: v=0 and v=1 with u increasing, u=1 and u=0 with v
     * increasing */
    if (sub < 0) {
        for (k = 0; k < 4; ++k) s[k] = T->eseg[l->fe[o + k]];
        for (k = 0; k <= s[0]; ++k) b[0][k] = sfb__tess_epoint(T, f, 0, k);
        for (k = 0; k <= s[1]; ++k) b[1][k] = sfb__tess_epoint(T, f, 1, k);
        for (k = 0; k <= s[2]; ++k) b[2][k] = sfb__tess_epoint(T, f, 2, s[2] - k); /* slot 2 runs (1,1) -> (0,1) */
        for (k = 0; k <= s[3]; ++k) b[3][k] = sfb__tess_epoint(T, f, 3, s[3] - k); /* slot 3 runs (0,1) -> (0,0) */
    } else {
        int n = sfb__tess_face_n(l, f), ip = (sub + n - 1) % n;
        s[0] = T->eseg[l->fe[o + sub]] / 2;
        s[1] = T->sseg[pf];
        s[2] = T->sseg[T->pt->face_ptex[f] + ip];
        s[3] = T->eseg[l->fe[o + ip]] / 2;
        for (k = 0; k <= s[0]; ++k) b[0][k] = sfb__tess_epoint(T, f, sub, k);        /* v_i -> mid(v_i, v_i+1) */
        for (k = 0; k <= s[1]; ++k) b[1][k] = sfb__tess_spoke(T, f, sub, k);         /* spoke i -> centroid */
        for (k = 0; k <= s[2]; ++k) b[2][k] = sfb__tess_spoke(T, f, ip, k);          /* spoke i-1 -> centroid */
        for (k = 0; k <= s[3]; ++k) b[3][k] = sfb__tess_epoint(T, f, ip, 2 * s[3] - k); /* v_i -> mid(v_i-1, v_i) */
    }
    regular = s[0] == r && s[1] == r && s[2] == r && s[3] == r;
    R = regular ? r : (r < 2 ? 2 : r);
    if (!emit) {
        T->ifirst[pf] = sfb__tess_new(T, (R - 1) * (R - 1));
        if (regular) T->ntri += (size_t)2 * (size_t)r * (size_t)r;
        else T->ntri += (size_t)2 * (size_t)(R - 2) * (size_t)(R - 2) + (size_t)s[0] + (size_t)s[1] + (size_t)s[2] + (size_t)s[3] +
                        (size_t)4 * (size_t)(R - 2);
        return;
    }
    for (k = 0; k <= s[0]; ++k) sfb__tess_loc(T, b[0][k], pf, (double)k / s[0], 0.0);
    for (k = 0; k <= s[1]; ++k) sfb__tess_loc(T, b[1][k], pf, 1.0, (double)k / s[1]);
    for (k = 0; k <= s[2]; ++k) sfb__tess_loc(T, b[2][k], pf, (double)k / s[2], 1.0);
    for (k = 0; k <= s[3]; ++k) sfb__tess_loc(T, b[3][k], pf, 0.0, (double)k / s[3]);
    base = T->ifirst[pf];
    for (j = 1; j < R; ++j)
        for (i = 1; i < R; ++i) sfb__tess_loc(T, base + (j - 1) * (R - 1) + (i - 1), pf, (double)i / R, (double)j / R);
#define SFB__INNER(i, j) (base + ((j) - 1) * (R - 1) + ((i) - 1))
    if (regular) {
        for (j = 0; j < r; ++j)
            for (i = 0; i < r; ++i) {
                int id[4], c;
                for (c = 0; c < 4; ++c) {
                    int x = i + (c == 1 || c == 2), y = j + (c >= 2);
                    id[c] = y == 0 ? b[0][x] : x == r ? b[1][y] : y == r ? b[2][x] : x == 0 ? b[3][y] : SFB__INNER(x, y);
                }
                sfb__tess_tri(T, id[0], id[1], id[2], pf);
                sfb__tess_tri(T, id[0], id[2], id[3], pf);
            }
        return;
    }
    for (j = 1; j < R - 1; ++j)
        for (i = 1; i < R - 1; ++i) {
            int a = SFB__INNER(i, j), bb = SFB__INNER(i + 1, j), c = SFB__INNER(i + 1, j + 1), d = SFB__INNER(i, j + 1);
            sfb__tess_tri(T, a, bb, c, pf);
            sfb__tess_tri(T, a, c, d, pf);
        }
    /* the ring, one side at a time, counter-clockwise: v=0, u=1, v=1 (reversed), u=0 (reversed) */
    for (k = 0; k < 4; ++k) {
        int q;
        for (q = 0; q <= s[k]; ++q) outer[q] = (k < 2) ? b[k][q] : b[k][s[k] - q];
        for (q = 0; q <= R - 2; ++q) {
            int t = (k < 2) ? 1 + q : R - 1 - q; /* position along the side, inset by one cell */
            inner[q] = k == 0 ? SFB__INNER(t, 1) : k == 1 ? SFB__INNER(R - 1, t) : k == 2 ? SFB__INNER(t, R - 1) : SFB__INNER(1, t);
        }
        sfb__tess_zipper(T, outer, s[k], inner, R - 2, R, 2, pf);
    }
#undef SFB__INNER
}

static int sfb__tess_live(const sfb__tess *T, int pf) {
    return !T->l->fhole[T->pt->ptex_face[pf]] && T->pt->ptex_root[pf] != -1;
}

/* Largest squared distance between the surface at the midpoints of the c x c grid's cell
 * edges and diagonals (the (2c+1)^2 samples P) and the chords the triangles make there. */
static double sfb__tess_chord_error(const float *P, int c) {
    int g = 2 * c + 1, i, j, q;
    double worst = 0.0;
    for (j = 0; j <= c; ++j)
        for (i = 0; i <= c; ++i) {
            /* (mid, end a, end b) sample offsets from corner (2i, 2j): bottom edge, left edge, diagonal */
            static const int chk[3][6] = { { 1, 0, 0, 0, 2, 0 }, { 0, 1, 0, 0, 0, 2 }, { 1, 1, 0, 0, 2, 2 } };
            for (q = 0; q < 3; ++q) {
                int x = 2 * i, y = 2 * j, cc;
                const float *m, *a, *b;
                double d2 = 0.0;
                if ((q != 1 && i == c) || (q != 0 && j == c)) continue; /* past the far sides */
                m = P + 3 * ((size_t)(y + chk[q][1]) * g + (size_t)(x + chk[q][0]));
                a = P + 3 * ((size_t)(y + chk[q][3]) * g + (size_t)(x + chk[q][2]));
                b = P + 3 * ((size_t)(y + chk[q][5]) * g + (size_t)(x + chk[q][4]));
                for (cc = 0; cc < 3; ++cc) {
                    double d = (double)m[cc] - 0.5 * ((double)a[cc] + (double)b[cc]);
                    d2 += d * d;
                }
                if (!(d2 <= worst)) worst = d2; /* NaN propagates: such a face is refined */
            }
        }
    return worst;
}

/* The same on a triangle param face: the samples are the points (x, y) of the rate-2c
 * triangular grid (x + y <= 2c), row by row in y; the chords are the three edges of each of
 * the c-grid's c (c+1) / 2 upward triangles, which are all of its edges. */
static double sfb__tess_chord_error_tri(const float *P, int c) {
    int g = 2 * c + 1, i, j, q;
    double worst = 0.0;
#define SFB__TRI_SAMPLE(x, y) (P + 3 * ((size_t)(y) * (size_t)(2 * g + 1 - (y)) / 2 + (size_t)(x)))
    for (j = 0; j < c; ++j)
        for (i = 0; i + j < c; ++i) {
            /* (mid, end a, end b) offsets from corner (2i, 2j): bottom edge, left edge, slanted edge */
            static const int chk[3][6] = { { 1, 0, 0, 0, 2, 0 }, { 0, 1, 0, 0, 0, 2 }, { 1, 1, 2, 0, 0, 2 } };
            for (q = 0; q < 3; ++q) {
                int x = 2 * i, y = 2 * j, cc;
                const float *m = SFB__TRI_SAMPLE(x + chk[q][0], y + chk[q][1]);
                const float *a = SFB__TRI_SAMPLE(x + chk[q][2], y + chk[q][3]);
                const float *b = SFB__TRI_SAMPLE(x + chk[q][4], y + chk[q][5]);
                double d2 = 0.0;
                for (cc = 0; cc < 3; ++cc) {
                    double d = (double)m[cc] - 0.5 * ((double)a[cc] + (double)b[cc]);
                    d2 += d * d;
                }
                if (!(d2 <= worst)) worst = d2; /* NaN propagates: such a face is refined */
            }
        }
#undef SFB__TRI_SAMPLE
    return worst;
}

/* Adaptive rates: candidates 1, 2, 4, ... below `rate` are tested in rounds over a chunk of
 * faces, many faces per sfb_surface_eval call; a face keeps the first candidate within
 * tolerance, else `rate`. */
static sfb_result sfb__tess_adaptive(sfb__tess *T, float tolerance, float p0, float p1) {
    sfb_context *ctx = T->ctx;
    int nptex = T->pt->nptex, maxc = 1, first, pf;
    size_t need, cap;
    sfb_location *loc = NULL;
    float *pos = NULL;
    int *list = NULL;
    sfb_result r = SFB_SUCCESS;
    double tol2 = (double)tolerance * (double)tolerance;
    if (T->rate == 1) return SFB_SUCCESS;
    while (maxc * 2 < T->rate) maxc *= 2;
    need = (size_t)(2 * maxc + 1) * (size_t)(2 * maxc + 1);
    cap = need > SFB__TESS_EVAL_CHUNK ? need : SFB__TESS_EVAL_CHUNK;
    loc = (sfb_location *)sfb__tess_array(ctx, cap, sizeof *loc);
    pos = (float *)sfb__tess_array(ctx, cap, 3 * sizeof(float));
    list = (int *)sfb__tess_array(ctx, SFB__TESS_FACE_CHUNK, sizeof(int));
    if (!loc || !pos || !list) { r = sfb__oom(ctx, "tessellation"); goto done; }
    for (first = 0; first < nptex; first += SFB__TESS_FACE_CHUNK) {
        int last = first + SFB__TESS_FACE_CHUNK < nptex ? first + SFB__TESS_FACE_CHUNK : nptex, n = 0, c;
        r = sfb__progress(ctx, p0 + (p1 - p0) * (float)first / (float)nptex, "tessellate");
        if (r != SFB_SUCCESS) goto done;
        for (pf = first; pf < last; ++pf)
            if (T->prate[pf] > 0) list[n++] = pf;
        for (c = 1; c < T->rate && n > 0; c *= 2) {
            int g = 2 * c + 1, a = 0, keep = 0, q;
            size_t per = T->loop ? (size_t)g * (size_t)(g + 1) / 2 : (size_t)g * (size_t)g;
            while (a < n) {
                int bnd = a, x, y;
                size_t used = 0;
                sfb_eval_output eo;
                while (bnd < n && used + per <= cap) {
                    for (y = 0; y < g; ++y)
                        for (x = 0; x < (T->loop ? g - y : g); ++x) {
                            sfb_location *L = &loc[used++];
                            L->face = list[bnd];
                            sfb__tess_uv(T->loop, (double)x / (g - 1), (double)y / (g - 1), L);
                        }
                    ++bnd;
                }
                memset(&eo, 0, sizeof eo);
                eo.position = pos;
                r = sfb_surface_eval(T->s, loc, (int)used, &eo);
                if (r != SFB_SUCCESS) goto done;
                for (q = a; q < bnd; ++q) {
                    const float *P = pos + 3 * per * (size_t)(q - a);
                    double err = T->loop ? sfb__tess_chord_error_tri(P, c) : sfb__tess_chord_error(P, c);
                    if (err <= tol2) T->prate[list[q]] = c;
                    else list[keep++] = list[q];
                }
                a = bnd;
            }
            n = keep;
        }
    }
done:
    sfb__free(ctx, loc);
    sfb__free(ctx, pos);
    sfb__free(ctx, list);
    return r;
}

/* Which side of 0.5 a tile's texels are on: all kept, all trimmed, or both (the contour
 * crosses it). */
static int sfb__trim_scan(const sfb__tess *T, const unsigned char *tile) {
    int lo = 0, hi = 0, i, j;
    for (j = 0; j < T->th; ++j) {
        const unsigned char *row = tile + (size_t)j * (size_t)T->trim->width;
        for (i = 0; i < T->tw; ++i) {
            if (row[i] >= 128) hi = 1;
            else lo = 1;
        }
        if (lo && hi) return SFB__TRIM_CUT;
    }
    return lo ? SFB__TRIM_DROP : SFB__TRIM_KEEP;
}

/* The trimming state of every param face, and the rate of those the contour crosses raised
 * to one cell per texel of their tile (at most SFB__TESS_MAX_RATE). */
static sfb_result sfb__trim_rates(sfb__tess *T, float p) {
    const sfb_trim_mask *m = T->trim;
    int nptex = T->pt->nptex, atlas = m->tiles_u > 1 || m->tiles_v > 1, pf, need, one = SFB__TRIM_KEEP;
    sfb_result r;
    T->tiles_u = atlas ? m->tiles_u : 1;
    T->ntiles = atlas ? m->tiles_u * m->tiles_v : 1;
    T->tw = m->width / T->tiles_u;
    T->th = m->height / (atlas ? m->tiles_v : 1);
    need = T->tw > T->th ? T->tw : T->th;
    if (need > SFB__TESS_MAX_RATE) need = SFB__TESS_MAX_RATE;
    T->fstate = (unsigned char *)sfb__tess_array(T->ctx, (size_t)nptex, 1);
    if (!T->fstate) return sfb__oom(T->ctx, "tessellation");
    if (!atlas) one = sfb__trim_scan(T, m->texels);
    for (pf = 0; pf < nptex; ++pf) {
        int st = SFB__TRIM_KEEP;
        if (atlas && pf % SFB__TESS_FACE_CHUNK == 0 && (r = sfb__progress(T->ctx, p, "tessellate")) != SFB_SUCCESS) return r;
        if (T->prate[pf] > 0) st = atlas ? (pf < T->ntiles ? sfb__trim_scan(T, sfb__trim_tile(T, pf)) : SFB__TRIM_KEEP) : one;
        T->fstate[pf] = (unsigned char)st;
        if (st == SFB__TRIM_CUT && T->prate[pf] < need) T->prate[pf] = need;
    }
    return SFB_SUCCESS;
}

/* The emit pass with trimming: locations of the untrimmed points, triangles through the mask
 * (sfb__trim_triangle), then the vertices no triangle uses are removed (the others keep
 * their order) and `out` gets the compacted arrays. */
static sfb_result sfb__trim_emit(sfb__tess *T, sfb_tess_data *out, float p0, float p1) {
    sfb_context *ctx = T->ctx;
    int nptex = T->pt->nptex, pf, *remap = NULL;
    size_t v, total, nv = 0, i;
    sfb_result r;
    T->loc = (sfb_location *)sfb__tess_array(ctx, T->nvert, sizeof(sfb_location));
    T->cuv = (double *)sfb__tess_array(ctx, T->nvert, 2 * sizeof(double));
    T->ckept = (unsigned char *)sfb__tess_array(ctx, T->nvert, 1);
    T->cut_cap = 1024;
    T->cuts = (sfb__trim_cut *)sfb__tess_array(ctx, T->cut_cap, sizeof(sfb__trim_cut));
    if (!T->loc || !T->cuv || !T->ckept || !T->cuts) return sfb__oom(ctx, "tessellation");
    for (v = 0; v < T->nvert; ++v) {
        T->loc[v].face = -1;
        T->loc[v].u = T->loc[v].v = 0.0f;
        T->ckept[v] = 1;
    }
    for (i = 0; i < T->cut_cap; ++i) T->cuts[i].vid = -1;
    T->err = SFB_SUCCESS;
    for (pf = 0; pf < nptex; ++pf) {
        if (pf % SFB__TESS_FACE_CHUNK == 0 && pf > 0) {
            r = sfb__progress(ctx, p0 + (p1 - p0) * (float)pf / (float)nptex, "tessellate");
            if (r != SFB_SUCCESS) return r;
        }
        sfb__tess_face(T, pf, 1);
        if (T->err != SFB_SUCCESS) return T->err;
    }
    if (T->tri_at != T->ntri)
        return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellation wrote %zu triangles, counted %zu", T->tri_at, T->ntri);
    for (v = 0; v < T->nvert; ++v)
        if (T->loc[v].face < 0)
            return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellation vertex %zu has no location", v);
    /* compaction */
    total = T->nvert + T->nnew;
    remap = (int *)sfb__tess_array(ctx, total, sizeof(int));
    if (!remap) return sfb__oom(ctx, "tessellation");
    for (v = 0; v < total; ++v) remap[v] = -1;
    for (i = 0; i < 3 * T->ocount; ++i) remap[T->otri[i]] = 0;
    for (v = 0; v < total; ++v)
        if (remap[v] == 0) remap[v] = (int)nv++;
    out->vertex_count = (int)nv;
    out->triangle_count = (int)T->ocount;
    out->positions = (float *)sfb__tess_array(ctx, nv, 3 * sizeof(float));
    out->normals = (float *)sfb__tess_array(ctx, nv, 3 * sizeof(float));
    out->locations = (sfb_location *)sfb__tess_array(ctx, nv, sizeof(sfb_location));
    if (!out->positions || !out->normals || !out->locations || (!T->otri && !(T->otri = (int *)sfb__tess_array(ctx, 1, 3 * sizeof(int)))) ||
        (!T->oface && !(T->oface = (int *)sfb__tess_array(ctx, 1, sizeof(int))))) {
        sfb__free(ctx, remap);
        return sfb__oom(ctx, "tessellation");
    }
    for (v = 0; v < total; ++v)
        if (remap[v] >= 0) out->locations[remap[v]] = v < T->nvert ? T->loc[v] : T->nloc[v - T->nvert];
    for (i = 0; i < 3 * T->ocount; ++i) T->otri[i] = remap[T->otri[i]];
    sfb__free(ctx, remap);
    out->triangles = T->otri;
    out->triangle_faces = T->oface;
    T->otri = T->oface = NULL;
    return SFB_SUCCESS;
}

/* Refuses a surface without a patch table and a rate, tolerance, flag set or trimming mask
 * out of range, before any allocation. */
static sfb_result sfb__tess_check(sfb_context *ctx, const sfb_surface *s, const sfb_tess_config *cfg) {
    if (!s->has_patches || s->pbase.nf != s->base_face_count || !s->pbase.fe)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_tessellate: the surface has no patch table (create it with SFB_REFINE_PATCHES)");
    if (cfg->rate < 1 || cfg->rate > SFB__TESS_MAX_RATE)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "tessellation rate %d is outside 1..%d", cfg->rate,
                          SFB__TESS_MAX_RATE);
    if (!(cfg->tolerance >= 0.0f))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "tessellation tolerance %g must be >= 0 (0: uniform)",
                          (double)cfg->tolerance);
    if (cfg->flags & ~(unsigned)(SFB_TESS_SPLIT_CREASES | SFB_TESS_UVS))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown tessellation flags 0x%x", cfg->flags);
    if ((cfg->flags & SFB_TESS_UVS) && (!s->has_uvs || !s->base_uvs || !s->uv_base.fv))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                          "sfb_surface_tessellate: SFB_TESS_UVS, but the surface has no UVs (create it with SFB_REFINE_UVS | "
                          "SFB_REFINE_PATCHES from a mesh with UVs)");
    if ((cfg->flags & SFB_TESS_UVS) && (s->uv_base.nf != s->pbase.nf || s->uv_base.nfv != s->pbase.nfv))
        return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "sfb_surface_tessellate: the UV layout's faces are not the surface's");
    if (cfg->trim) {
        const sfb_trim_mask *m = cfg->trim;
        if (!m->texels) return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: texels is NULL");
        if (m->width < 1 || m->width > SFB__TRIM_MAX_SIZE || m->height < 1 || m->height > SFB__TRIM_MAX_SIZE)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: %d x %d texels, each side must be 1..%d",
                              m->width, m->height, SFB__TRIM_MAX_SIZE);
        if (m->tiles_u < 0 || m->tiles_v < 0)
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "trimming mask: negative atlas tiles %d x %d", m->tiles_u,
                              m->tiles_v);
        if ((m->tiles_u == 0) != (m->tiles_v == 0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                              "trimming mask: atlas tiles %d x %d (0 x 0 or both >= 1: one zero and not the other)", m->tiles_u, m->tiles_v);
        if (m->tiles_u > 0 && (m->width % m->tiles_u != 0 || m->height % m->tiles_v != 0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                              "trimming mask: %d x %d texels do not split into %d x %d equal tiles", m->width, m->height, m->tiles_u,
                              m->tiles_v);
    }
    return SFB_SUCCESS;
}

/* Zeroes T and sets it up for s and cfg: the work arrays, the uniform rate on every live param
 * face, no vertex ids yet. On failure T holds what was allocated (sfb__tess_free_work). */
static sfb_result sfb__tess_init(sfb__tess *T, const sfb_surface *s, const sfb_tess_config *cfg) {
    sfb_context *ctx = s->ctx;
    const sfb__level *l;
    int pf, f, i, nptex;
    memset(T, 0, sizeof *T);
    T->ctx = ctx;
    T->s = s;
    T->l = l = &s->pbase;
    T->pt = &s->patches;
    T->rate = cfg->rate;
    T->split = (cfg->flags & (SFB_TESS_SPLIT_CREASES | SFB_TESS_UVS)) != 0;
    T->loop = T->pt->domain == SFB__DOMAIN_TRI;
    nptex = T->pt->nptex;
    T->prate = (int *)sfb__tess_array(ctx, (size_t)nptex, sizeof(int));
    T->sseg = (int *)sfb__tess_array(ctx, (size_t)nptex, sizeof(int));
    T->vspoke = (int *)sfb__tess_array(ctx, (size_t)nptex, sizeof(int));
    T->ifirst = (int *)sfb__tess_array(ctx, (size_t)nptex, sizeof(int));
    T->eseg = (int *)sfb__tess_array(ctx, (size_t)l->ne, sizeof(int));
    T->engon = (unsigned char *)sfb__tess_array(ctx, (size_t)l->ne, 1);
    T->vedge = (int *)sfb__tess_array(ctx, (size_t)l->nfv, sizeof(int));
    T->vcenter = (int *)sfb__tess_array(ctx, (size_t)l->nf, sizeof(int));
    T->vcorner = (int *)sfb__tess_array(ctx, (size_t)(T->split ? l->nfv : l->nv), sizeof(int));
    T->bids = (int *)sfb__tess_array(ctx, (size_t)6 * (SFB__TESS_MAX_SEG + 1), sizeof(int));
    if (T->split) {
        T->uf = (int *)sfb__tess_array(ctx, (size_t)l->nfv, sizeof(int));
        T->ecopy = (int *)sfb__tess_array(ctx, (size_t)l->nfv, sizeof(int));
        T->esplit = (unsigned char *)sfb__tess_array(ctx, (size_t)l->ne, 1);
    }
    if (!T->prate || !T->sseg || !T->vspoke || !T->ifirst || !T->eseg || !T->engon || !T->vedge || !T->vcenter || !T->vcorner ||
        !T->bids || (T->split && (!T->uf || !T->ecopy || !T->esplit)))
        return sfb__oom(ctx, "tessellation");
    if (T->split) {
        int e;
        for (e = 0; e < l->ne; ++e)
            T->esplit[e] = (unsigned char)(((cfg->flags & SFB_TESS_SPLIT_CREASES) && sfb__tess_crease_edge(l, e)) ||
                                           ((cfg->flags & SFB_TESS_UVS) && sfb__tess_uv_seam(l, &s->uv_base, e)));
    }
    for (pf = 0; pf < nptex; ++pf) {
        T->prate[pf] = sfb__tess_live(T, pf) ? T->rate : 0;
        T->vspoke[pf] = -1;
        T->sseg[pf] = 0;
    }
    for (i = 0; i < l->nfv; ++i) T->vedge[i] = -1;
    for (f = 0; f < l->nf; ++f) T->vcenter[f] = -1;
    for (i = 0; i < (T->split ? l->nfv : l->nv); ++i) T->vcorner[i] = -1;
    return SFB_SUCCESS;
}

/* Segments of each base edge and spoke: the largest rate of the faces on it (an n-gon sub-face
 * covers half an edge, so it asks for twice its rate, and the count stays even). */
static void sfb__tess_edge_segments(sfb__tess *T) {
    const sfb__level *l = T->l;
    int pf, f, e, k, nptex = T->pt->nptex;
    memset(T->eseg, 0, (size_t)l->ne * sizeof(int));
    memset(T->engon, 0, (size_t)l->ne);
    for (pf = 0; pf < nptex; ++pf) {
        int rr = T->prate[pf], sub = T->pt->ptex_corner[pf], o, n;
        if (rr <= 0) continue;
        f = T->pt->ptex_face[pf];
        o = l->fv_off[f];
        n = sfb__tess_face_n(l, f);
        if (sub < 0) { /* a quad, or a Loop triangle */
            for (k = 0; k < n; ++k) {
                e = l->fe[o + k];
                if (T->eseg[e] < rr) T->eseg[e] = rr;
            }
        } else {
            int ip = (sub + n - 1) % n, nx = T->pt->face_ptex[f] + (sub + 1) % n;
            int e0 = l->fe[o + sub], e1 = l->fe[o + ip], other = T->prate[nx];
            if (T->eseg[e0] < 2 * rr) T->eseg[e0] = 2 * rr;
            if (T->eseg[e1] < 2 * rr) T->eseg[e1] = 2 * rr;
            T->engon[e0] = T->engon[e1] = 1;
            T->sseg[pf] = rr > other ? rr : other;
        }
    }
    for (e = 0; e < l->ne; ++e)
        if (T->engon[e] && (T->eseg[e] & 1)) T->eseg[e] += 1;
}

/* Sectors for split creases: corners of faces joined across every edge that is not split
 * (holes join nothing), in the union-find T->uf. */
static void sfb__tess_sectors(sfb__tess *T) {
    const sfb__level *l = T->l;
    int i, e;
    for (i = 0; i < l->nfv; ++i) T->uf[i] = i;
    for (e = 0; e < l->ne; ++e) {
        int a = l->ef_off[e], z = l->ef_off[e + 1], first0 = -1, first1 = -1, q;
        for (q = a; q < z; ++q) T->ecopy[l->fv_off[l->ef[q]] + l->ef_slot[q]] = q;
        if (sfb__tess_split_edge(T, e)) continue;
        for (q = a; q < z; ++q) {
            int g = l->ef[q], o = l->fv_off[g], n = sfb__tess_face_n(l, g), sl = l->ef_slot[q];
            int c0 = o + sl, c1 = o + (sl + 1) % n, t;
            if (l->fhole[g]) continue;
            if (l->fv[c0] != l->ev[2 * e]) { t = c0; c0 = c1; c1 = t; } /* c0 at ev[0], c1 at ev[1] */
            if (first0 < 0) { first0 = c0; first1 = c1; }
            else { sfb__tess_union(T->uf, first0, c0); sfb__tess_union(T->uf, first1, c1); }
        }
    }
}

/* The count pass: ids of every point, and the totals, checked against SFB_MAX_ELEMENTS before
 * anything is allocated for them. */
static sfb_result sfb__tess_count(sfb__tess *T) {
    int pf, nptex = T->pt->nptex;
    for (pf = 0; pf < nptex; ++pf) {
        sfb__tess_face(T, pf, 0);
        if (T->nvert > (size_t)SFB_MAX_ELEMENTS || T->ntri > (size_t)SFB_MAX_ELEMENTS)
            return sfb__error(T->ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1,
                              "tessellation at rate %d makes more than %d %s (SFB_MAX_ELEMENTS)", T->rate, SFB_MAX_ELEMENTS,
                              T->nvert > (size_t)SFB_MAX_ELEMENTS ? "vertices" : "triangles");
    }
    return SFB_SUCCESS;
}

/* The emit pass without trimming: `out`'s arrays, then the locations and triangles of every
 * param face written straight into them (progress from p0 to p1). */
static sfb_result sfb__tess_emit(sfb__tess *T, sfb_tess_data *out, float p0, float p1) {
    sfb_context *ctx = T->ctx;
    int pf, nptex = T->pt->nptex;
    size_t v;
    sfb_result r;
    out->vertex_count = (int)T->nvert;
    out->triangle_count = (int)T->ntri;
    out->positions = (float *)sfb__tess_array(ctx, T->nvert, 3 * sizeof(float));
    out->normals = (float *)sfb__tess_array(ctx, T->nvert, 3 * sizeof(float));
    out->locations = (sfb_location *)sfb__tess_array(ctx, T->nvert, sizeof(sfb_location));
    out->triangles = (int *)sfb__tess_array(ctx, T->ntri, 3 * sizeof(int));
    out->triangle_faces = (int *)sfb__tess_array(ctx, T->ntri, sizeof(int));
    if (!out->positions || !out->normals || !out->locations || !out->triangles || !out->triangle_faces)
        return sfb__oom(ctx, "tessellation");
    for (v = 0; v < T->nvert; ++v) {
        out->locations[v].face = -1;
        out->locations[v].u = out->locations[v].v = 0.0f;
    }
    T->loc = out->locations;
    T->tri = out->triangles;
    T->tface = out->triangle_faces;
    for (pf = 0; pf < nptex; ++pf) {
        if (pf % SFB__TESS_FACE_CHUNK == 0 && pf > 0) {
            r = sfb__progress(ctx, p0 + (p1 - p0) * (float)pf / (float)nptex, "tessellate");
            if (r != SFB_SUCCESS) return r;
        }
        sfb__tess_face(T, pf, 1);
    }
    if (T->tri_at != T->ntri)
        return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellation wrote %zu triangles, counted %zu", T->tri_at, T->ntri);
    for (v = 0; v < T->nvert; ++v)
        if (out->locations[v].face < 0)
            return sfb__error(ctx, SFB_BACKEND_ERROR, SFB_ELEMENT_NONE, -1, "tessellation vertex %zu has no location", v);
    return SFB_SUCCESS;
}

/* Evaluates every vertex of `out` once, in chunks, on the context's backend (progress from p0
 * to p1). */
static sfb_result sfb__tess_evaluate(const sfb_surface *s, sfb_tess_data *out, float p0, float p1) {
    sfb_context *ctx = s->ctx;
    size_t done_v, nv = (size_t)out->vertex_count;
    sfb_result r;
    for (done_v = 0; done_v < nv; done_v += SFB__TESS_EVAL_CHUNK) {
        size_t n = nv - done_v < SFB__TESS_EVAL_CHUNK ? nv - done_v : SFB__TESS_EVAL_CHUNK;
        sfb_eval_output eo;
        r = sfb__progress(ctx, p0 + (p1 - p0) * (float)done_v / (float)nv, "tessellate");
        if (r != SFB_SUCCESS) return r;
        memset(&eo, 0, sizeof eo);
        eo.position = out->positions + 3 * done_v;
        eo.normal = out->normals + 3 * done_v;
        r = sfb_surface_eval(s, out->locations + done_v, (int)n, &eo);
        if (r != SFB_SUCCESS) return r;
    }
    return sfb__progress(ctx, p1, "tessellate");
}

/* SFB_UV_LINEAR: the UVs follow each face linearly, as the bilinear masks refine them on the
 * scheme's own face split -- a quad bilinearly, an n-gon's sub-face i bilinearly between its
 * corner's UV, the two edge midpoints and the centroid, a Loop triangle barycentrically. */
static void sfb__tess_uv_linear(const sfb_surface *s, const sfb_location *L, float uv[2]) {
    const sfb__level *ul = &s->uv_base;
    const sfb__patch_table *pt = &s->patches;
    int f = pt->ptex_face[L->face], sub = pt->ptex_corner[L->face], o = ul->fv_off[f], n = ul->fv_off[f + 1] - o, c, k;
    double u = L->u, v = L->v;
    for (c = 0; c < 2; ++c) {
        double q[4];
        if (pt->domain == SFB__DOMAIN_TRI) {
            uv[c] = (float)((1.0 - u - v) * s->base_uvs[2 * ul->fv[o] + c] + u * s->base_uvs[2 * ul->fv[o + 1] + c] +
                            v * s->base_uvs[2 * ul->fv[o + 2] + c]);
            continue;
        }
        if (sub < 0) {
            for (k = 0; k < 4; ++k) q[k] = s->base_uvs[2 * ul->fv[o + k] + c];
        } else {
            double mean = 0.0, a = s->base_uvs[2 * ul->fv[o + sub] + c];
            for (k = 0; k < n; ++k) mean += s->base_uvs[2 * ul->fv[o + k] + c];
            q[0] = a;
            q[1] = 0.5 * (a + s->base_uvs[2 * ul->fv[o + (sub + 1) % n] + c]);
            q[2] = mean / n;
            q[3] = 0.5 * (a + s->base_uvs[2 * ul->fv[o + (sub + n - 1) % n] + c]);
        }
        uv[c] = (float)((1.0 - u) * (1.0 - v) * q[0] + u * (1.0 - v) * q[1] + u * v * q[2] + (1.0 - u) * v * q[3]);
    }
}

/* SFB_TESS_UVS: out->uvs at out->locations (progress from p0 to 1). Smooth UVs are the limit
 * of the refined UV layout: the layout's own patch table (sfb__surface_uv_patches, built per
 * call, so a surface that never tessellates UVs does not pay for it), uploaded to and
 * evaluated on the context's backend as the positions are. The manifold blend blends the UV layout as it blends
 * positions (the blend is linear in the data); tribezier builds its own surface of the layout
 * (a similarity of a planar mesh's layout gives that map of the positions), linear per face
 * where its builder refuses the layout; PN triangles take the linear UVs, which is what they
 * make of a planar layout. */
static sfb_result sfb__tess_eval_uvs(const sfb_surface *s, sfb_tess_data *out, float p0) {
    sfb_context *ctx = s->ctx;
    size_t v, nv = (size_t)out->vertex_count, done_v;
    sfb__patch_table upt;
    const sfb__backend_vtable *be = ctx->backend;
    void *handle = NULL;
    int uploaded = 0, linear = 0;
    float *tmp = NULL;
    sfb_result r = SFB_SUCCESS;
    out->uvs = (float *)sfb__tess_array(ctx, nv, 2 * sizeof(float));
    if (!out->uvs) return sfb__oom(ctx, "tessellated UVs");
    memset(&upt, 0, sizeof upt);
    if (sfb__surface_smooth_uvs(s)) {
        /* UVS_OR_LINEAR: linear UVs where the scheme's builder cannot take the layout -- one
         * that is not a manifold (placeholder UVs) is not offered to it, so that no error is
         * logged for it; other refusals (a flat UV triangle) come back from the builder */
        const sfb__scheme_info *si = sfb__scheme_info_of(s->config.scheme);
        const int fallback = si && (si->caps & SFB__SCHEME_UVS_OR_LINEAR);
        int i;
        for (i = 0; fallback && i < s->uv_base.nv && !linear; ++i) linear = (s->uv_base.vtag[i] & SFB__TAG_NONMANIFOLD) != 0;
        if (linear) {
            sfb__log(ctx, SFB_LOG_INFO, "tessellated UVs: the UV layout is not a manifold: linear per face (%s)", si->name);
        } else if ((r = sfb__surface_uv_patches(s, &upt)) != SFB_SUCCESS) {
            if (r == SFB_OUT_OF_MEMORY || r == SFB_CANCELLED || !fallback) goto done;
            sfb__log(ctx, SFB_LOG_INFO, "tessellated UVs: the %s surface of the UV layout cannot be built (%s): linear per face",
                     si->name, sfb_last_error(ctx));
            linear = 1;
        }
    } else {
        linear = 1;
    }
    if (linear) {
        for (v = 0; v < nv; ++v) sfb__tess_uv_linear(s, &out->locations[v], out->uvs + 2 * v);
        r = sfb__progress(ctx, 1.0f, "tessellate");
        goto done;
    }
    tmp = (float *)sfb__tess_array(ctx, SFB__TESS_EVAL_CHUNK, 3 * sizeof(float));
    if (!tmp) { r = sfb__oom(ctx, "tessellated UVs"); goto done; }
    /* on the context's backend, like the positions (ref when it has no patch kernels) */
    if (be && be->upload_patches && be->eval_patches) {
        if ((r = be->upload_patches(ctx->backend_state, &upt, &handle)) != SFB_SUCCESS) goto done;
        uploaded = 1;
    }
    for (done_v = 0; done_v < nv; done_v += SFB__TESS_EVAL_CHUNK) {
        size_t n = nv - done_v < SFB__TESS_EVAL_CHUNK ? nv - done_v : SFB__TESS_EVAL_CHUNK;
        sfb_eval_output eo;
        if ((r = sfb__progress(ctx, p0 + (1.0f - p0) * (float)done_v / (float)nv, "tessellate")) != SFB_SUCCESS) goto done;
        memset(&eo, 0, sizeof eo);
        eo.position = tmp;
        r = be && be->eval_patches ? be->eval_patches(ctx->backend_state, &upt, handle, out->locations + done_v, 0, (int)n, &eo)
                                   : sfb__ref_eval_patches(NULL, &upt, NULL, out->locations + done_v, 0, (int)n, &eo);
        if (r != SFB_SUCCESS) goto done;
        for (v = 0; v < n; ++v) {
            out->uvs[2 * (done_v + v)] = tmp[3 * v];
            out->uvs[2 * (done_v + v) + 1] = tmp[3 * v + 1];
        }
    }
    r = sfb__progress(ctx, 1.0f, "tessellate");
done:
    if (uploaded && be->release_patches) be->release_patches(ctx->backend_state, handle);
    sfb__patch_table_free(ctx, &upt);
    sfb__free(ctx, tmp);
    return r;
}

SFB_API sfb_result sfb_surface_tessellate(const sfb_surface *s, const sfb_tess_config *cfg, sfb_tess_data *out) {
    sfb_context *ctx;
    sfb__tess T;
    sfb_result r = SFB_SUCCESS;
    float p_emit, p_eval;
    if (out) memset(out, 0, sizeof *out);
    if (!s) return SFB_INVALID_ARGS;
    ctx = s->ctx;
    if (!cfg || !out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_surface_tessellate: NULL argument");
    if ((r = sfb__tess_check(ctx, s, cfg)) != SFB_SUCCESS) return r;
    if ((r = sfb__progress(ctx, 0.0f, "tessellate")) != SFB_SUCCESS) return r;
    if ((r = sfb__tess_init(&T, s, cfg)) != SFB_SUCCESS) goto fail;

    /* 1. a rate per param face */
    p_emit = 0.0f;
    if (cfg->tolerance > 0.0f) {
        r = sfb__tess_adaptive(&T, cfg->tolerance, 0.0f, 0.5f);
        if (r != SFB_SUCCESS) goto fail;
        p_emit = 0.5f;
    }
    p_eval = p_emit + 0.1f;
    if (cfg->trim) {
        T.trim = cfg->trim;
        r = sfb__trim_rates(&T, p_emit);
        if (r != SFB_SUCCESS) goto fail;
    }
    /* 2. segments of each base edge and spoke; 3. sectors for split creases */
    sfb__tess_edge_segments(&T);
    if (T.split) sfb__tess_sectors(&T);
    /* 4. count pass */
    if ((r = sfb__tess_count(&T)) != SFB_SUCCESS) goto fail;
    /* 5. emit pass: locations and triangles */
    out->ctx_ = ctx;
    r = T.trim ? sfb__trim_emit(&T, out, p_emit, p_eval) : sfb__tess_emit(&T, out, p_emit, p_eval);
    if (r != SFB_SUCCESS) goto fail;
    sfb__tess_free_work(&T);
    /* 6. evaluate every vertex once, in chunks, on the context's backend; 7. the UVs */
    r = sfb__tess_evaluate(s, out, p_eval, (cfg->flags & SFB_TESS_UVS) ? 0.9f : 1.0f);
    if (r == SFB_SUCCESS && (cfg->flags & SFB_TESS_UVS)) r = sfb__tess_eval_uvs(s, out, 0.9f);
    if (r == SFB_SUCCESS) return SFB_SUCCESS;
fail:
    sfb__tess_free_work(&T);
    out->ctx_ = ctx;
    sfb_tess_data_free(out);
    return r;
}
