/* Software pictures (no GL): a small z-buffered rasterizer for refined meshes.
 *
 * Two passes over a G-buffer. Pass 1 fan-triangulates every polygon, projects it with an
 * orbit camera around the bounding-box centre and keeps, per pixel, the nearest fragment's
 * depth, perspective-correct position, normal and scalar (and its distance to the polygon's
 * own edges, for the edge overlay). Pass 2 shades every covered pixel: the interpolated
 * normal is renormalised (Phong) and turned toward the viewer (two-sided lighting), then
 * coloured by the mode: diffuse + specular grey; highlight lines (ALGORITHMS.md §7, parallel
 * light lines in a plane fixed to the camera, Dir = N); a blue-to-red scalar map; the normal
 * as RGB. Highlight stripes are filtered by their own screen-space rate, so bands finer
 * than a pixel fade to their average colour instead of aliasing. */

#define SFB__RENDER_DEFAULT_W 640
#define SFB__RENDER_DEFAULT_H 480
#define SFB__RENDER_DEFAULT_YAW 30.0f
#define SFB__RENDER_DEFAULT_PITCH 25.0f
#define SFB__RENDER_DEFAULT_STRIPES 8.0f
#define SFB__RENDER_DEFAULT_LIGHT_DISTANCE 3.0f
#define SFB__RENDER_HALF_FOV 15.0           /* degrees: the bounding sphere fits a 30 degree cone */
#define SFB__RENDER_MARGIN 0.92             /* the bounding sphere's share of the smaller side */
#define SFB__RENDER_GB 8                    /* floats per pixel: depth, normal xyz, position xyz, scalar */

SFB_API sfb_render_config sfb_render_config_init(int mode) {
    sfb_render_config c;
    memset(&c, 0, sizeof c);
    c.mode = mode;
    return c;
}

SFB_API void sfb_image_free(sfb_image *img) {
    if (!img) return;
    if (img->ctx_) sfb__free(img->ctx_, img->rgba);
    memset(img, 0, sizeof *img);
}

/* The camera: an orbit around `centre` at yaw/pitch; right/up/forward unit vectors. */
typedef struct sfb__camera {
    double eye[3], right[3], up[3], fwd[3];
    double focal;  /* perspective: pixels per unit of x/z; orthographic: pixels per unit */
    double cx, cy; /* image centre in pixels */
    int ortho;
} sfb__camera;

double sfb__rdot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
void sfb__rcross(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
double sfb__rnormalize(double *a) {
    double l = sqrt(sfb__rdot(a, a));
    if (l > 0.0 && isfinite(l)) { a[0] /= l; a[1] /= l; a[2] /= l; }
    return l;
}
double sfb__rclamp(double x, double lo, double hi) { return x < lo ? lo : x > hi ? hi : x; }

/* Integral over [0, x] of the unit-periodic indicator of the band [a, b] (0 <= a <= b <= 1). */
static double sfb__band_integral(double x, double a, double b) {
    double fl = floor(x), fr = x - fl;
    return fl * (b - a) + (sfb__rclamp(fr, a, b) - a);
}
/* Share of the pixel footprint [w - fw/2, w + fw/2] covered by the periodic band [a, b]. */
double sfb__band_cover(double w, double fw, double a, double b) {
    if (fw > 64.0) return b - a;
    if (fw < 1e-4) {
        double fr = w - floor(w);
        return fr >= a && fr < b;
    }
    return (sfb__band_integral(w + 0.5 * fw, a, b) - sfb__band_integral(w - 0.5 * fw, a, b)) / fw;
}

/* Colour map for scalars in [0,1]: blue, cyan, green, yellow, red. */
void sfb__colormap(double t, double *rgb) {
    static const double stops[5][3] = { {0.10, 0.20, 1.00}, {0.00, 0.85, 1.00}, {0.10, 0.90, 0.15},
                                        {1.00, 0.92, 0.00}, {1.00, 0.10, 0.05} };
    double x = sfb__rclamp(t, 0.0, 1.0) * 4.0;
    int i = (int)x, c;
    double f;
    if (i > 3) i = 3;
    f = x - i;
    for (c = 0; c < 3; ++c) rgb[c] = stops[i][c] * (1.0 - f) + stops[i + 1][c] * f;
}

unsigned char sfb__to_byte(double v) {
    v = sfb__rclamp(v, 0.0, 1.0);
    return (unsigned char)(v * 255.0 + 0.5);
}

/* Newell normal of polygon f (unnormalised; zero when degenerate or not finite). */
static void sfb__polygon_normal(const float *pos, const int *fv, int n, double *o) {
    int i;
    o[0] = o[1] = o[2] = 0.0;
    for (i = 0; i < n; ++i) {
        const float *a = pos + 3 * (size_t)fv[i], *b = pos + 3 * (size_t)fv[(i + 1) % n];
        o[0] += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
        o[1] += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
        o[2] += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
    }
    if (!(isfinite(o[0]) && isfinite(o[1]) && isfinite(o[2]))) o[0] = o[1] = o[2] = 0.0;
}

/* State of one render. */
typedef struct sfb__raster {
    int w, h;
    float *gb;             /* SFB__RENDER_GB floats per pixel; depth +inf: empty */
    unsigned char *edge;   /* per pixel: edge overlay coverage 0..255 */
    const float *pos, *nrm, *scal;
    const sfb__camera *cam;
    int draw_edges;
} sfb__raster;

/* Projected vertex: screen x, y, view depth z, and the interpolation weight q (1/z or 1). */
typedef struct sfb__pv { double x, y, z, q; } sfb__pv;

/* Rasterizes one fan triangle of a polygon: P its projected corners, vi their vertex indices,
 * real[k] whether the side opposite corner k is a side of the polygon (drawn by the overlay)
 * rather than a fan diagonal. fnormal: the polygon's unit normal (used where there are no
 * vertex normals or they vanish). */
static void sfb__raster_tri(sfb__raster *R, const sfb__pv *P, const int *vi, const int *real, const double *fnormal) {
    double x0 = P[0].x, y0 = P[0].y, x1 = P[1].x, y1 = P[1].y, x2 = P[2].x, y2 = P[2].y;
    double area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
    double minx, maxx, miny, maxy, inv, elen[3];
    int ix0, ix1, iy0, iy1, x, y, k;
    if (!(fabs(area) > 1e-12) || !isfinite(area)) return;
    minx = x0 < x1 ? (x0 < x2 ? x0 : x2) : (x1 < x2 ? x1 : x2);
    maxx = x0 > x1 ? (x0 > x2 ? x0 : x2) : (x1 > x2 ? x1 : x2);
    miny = y0 < y1 ? (y0 < y2 ? y0 : y2) : (y1 < y2 ? y1 : y2);
    maxy = y0 > y1 ? (y0 > y2 ? y0 : y2) : (y1 > y2 ? y1 : y2);
    /* pixel centres at i + 0.5; clamp in double before converting */
    minx = sfb__rclamp(ceil(minx - 0.5), 0.0, (double)R->w);
    maxx = sfb__rclamp(floor(maxx - 0.5), -1.0, (double)R->w - 1.0);
    miny = sfb__rclamp(ceil(miny - 0.5), 0.0, (double)R->h);
    maxy = sfb__rclamp(floor(maxy - 0.5), -1.0, (double)R->h - 1.0);
    ix0 = (int)minx; ix1 = (int)maxx; iy0 = (int)miny; iy1 = (int)maxy;
    if (ix0 > ix1 || iy0 > iy1) return;
    inv = 1.0 / area;
    /* edge k is opposite vertex k: e0 = (1,2), e1 = (2,0), e2 = (0,1) */
    elen[0] = sqrt((x2 - x1) * (x2 - x1) + (y2 - y1) * (y2 - y1));
    elen[1] = sqrt((x0 - x2) * (x0 - x2) + (y0 - y2) * (y0 - y2));
    elen[2] = sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0));
    for (y = iy0; y <= iy1; ++y) {
        double py = y + 0.5;
        for (x = ix0; x <= ix1; ++x) {
            double px = x + 0.5, e[3], b[3], den, z, cover = 0.0;
            size_t pix = (size_t)y * (size_t)R->w + (size_t)x;
            float *g = R->gb + pix * SFB__RENDER_GB;
            e[0] = (x2 - x1) * (py - y1) - (y2 - y1) * (px - x1);
            e[1] = (x0 - x2) * (py - y2) - (y0 - y2) * (px - x2);
            e[2] = (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0);
            b[0] = e[0] * inv; b[1] = e[1] * inv; b[2] = e[2] * inv;
            if (b[0] < 0.0 || b[1] < 0.0 || b[2] < 0.0) continue;
            den = b[0] * P[0].q + b[1] * P[1].q + b[2] * P[2].q;
            if (!(den > 0.0)) continue;
            /* perspective: q = 1/z is affine in the picture; orthographic: q = 1 and z is */
            z = R->cam->ortho ? b[0] * P[0].z + b[1] * P[1].z + b[2] * P[2].z : 1.0 / den;
            if (!(z < (double)g[0])) continue;
            /* perspective-correct weights */
            for (k = 0; k < 3; ++k) b[k] = b[k] * P[k].q / den;
            g[0] = (float)z;
            {
                double n[3] = { 0.0, 0.0, 0.0 }, p[3] = { 0.0, 0.0, 0.0 }, s = 0.0;
                int c;
                for (k = 0; k < 3; ++k) {
                    const float *pp = R->pos + 3 * (size_t)vi[k];
                    for (c = 0; c < 3; ++c) p[c] += b[k] * pp[c];
                    if (R->nrm) {
                        const float *nn = R->nrm + 3 * (size_t)vi[k];
                        if (isfinite(nn[0]) && isfinite(nn[1]) && isfinite(nn[2]))
                            for (c = 0; c < 3; ++c) n[c] += b[k] * nn[c];
                    }
                    if (R->scal) {
                        float sv = R->scal[vi[k]];
                        s += b[k] * (isfinite(sv) ? sfb__rclamp(sv, 0.0, 1.0) : 0.0);
                    }
                }
                if (!R->nrm || !(sfb__rdot(n, n) > 1e-20)) { n[0] = fnormal[0]; n[1] = fnormal[1]; n[2] = fnormal[2]; }
                for (c = 0; c < 3; ++c) { g[1 + c] = (float)n[c]; g[4 + c] = (float)p[c]; }
                g[7] = (float)s;
            }
            if (R->draw_edges) {
                for (k = 0; k < 3; ++k)
                    if (real[k] && elen[k] > 0.0) {
                        double d = fabs(e[k]) / elen[k], c = sfb__rclamp(1.25 - d, 0.0, 1.0);
                        if (c > cover) cover = c;
                    }
                R->edge[pix] = sfb__to_byte(cover);
            }
        }
    }
}

static sfb_result sfb__render_check(sfb_context *ctx, const sfb_mesh_data *m, const sfb_render_config *c,
                                    const float **pos, const float **nrm, const float **scal, int *w, int *h) {
    int f;
    size_t off = 0;
    *w = c->width ? c->width : SFB__RENDER_DEFAULT_W;
    *h = c->height ? c->height : SFB__RENDER_DEFAULT_H;
    if (*w < 0 || *h < 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "image size %d x %d is negative", *w, *h);
    if (*w > SFB_RENDER_MAX_SIZE || *h > SFB_RENDER_MAX_SIZE)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "image size %d x %d is over the limit of %d (SFB_RENDER_MAX_SIZE)",
                          *w, *h, SFB_RENDER_MAX_SIZE);
    if (c->mode < SFB_RENDER_SHADED || c->mode > SFB_RENDER_NORMALS)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "unknown render mode %d", c->mode);
    if (!isfinite(c->yaw) || !isfinite(c->pitch) || !isfinite(c->zoom) || c->zoom < 0.0f)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "view (yaw %g, pitch %g, zoom %g): angles must be finite, zoom finite and >= 0",
                          (double)c->yaw, (double)c->pitch, (double)c->zoom);
    if (!isfinite(c->up[0]) || !isfinite(c->up[1]) || !isfinite(c->up[2]))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "the orbit's up direction (%g, %g, %g) is not finite", (double)c->up[0],
                          (double)c->up[1], (double)c->up[2]);
    if (!isfinite(c->stripes) || c->stripes < 0.0f || c->stripes > 1e5f || !isfinite(c->light_distance) || c->light_distance < 0.0f)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "highlight stripes %g and light distance %g must be finite and >= 0 (stripes <= 1e5)",
                          (double)c->stripes, (double)c->light_distance);
    if (m->vertex_count < 0 || m->face_count < 0 || m->face_vertex_count < 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "negative element count in the mesh");
    if (m->vertex_count > SFB_MAX_ELEMENTS || m->face_count > SFB_MAX_ELEMENTS || m->face_vertex_count > SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "element count over the limit of %d", SFB_MAX_ELEMENTS);
    if (m->face_count == 0) return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_NONE, -1, "mesh has no faces");
    *pos = c->positions ? c->positions : m->positions;
    *nrm = c->normals ? c->normals : m->normals;
    *scal = c->scalars ? c->scalars : m->blend_weights;
    if (!*pos || !m->face_sizes || !m->face_vertices)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mesh lacks positions or faces");
    if (c->mode == SFB_RENDER_WEIGHTS && !*scal)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1,
                          "the weights picture needs scalars (config scalars or the mesh's blend_weights from sfb_surface_shade)");
    if (m->hole_count > SFB_MAX_ELEMENTS)
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "hole count over the limit of %d", SFB_MAX_ELEMENTS);
    if (m->hole_count < 0 || (m->hole_count > 0 && !m->holes))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "mesh has a hole count without its array");
    for (f = 0; f < m->face_count; ++f) {
        int n = m->face_sizes[f], i;
        if (n < 3 || n > SFB_MAX_FACE_SIZE)
            return sfb__error(ctx, n < 3 ? SFB_INVALID_TOPOLOGY : SFB_LIMIT_EXCEEDED, SFB_ELEMENT_FACE, f,
                              "face has %d vertices (3..%d)", n, SFB_MAX_FACE_SIZE);
        if ((size_t)n > (size_t)m->face_vertex_count - off)
            return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_FACE, f, "face sizes add up to more than face_vertex_count (%d)",
                              m->face_vertex_count);
        for (i = 0; i < n; ++i) {
            int v = m->face_vertices[off + (size_t)i];
            if (v < 0 || v >= m->vertex_count)
                return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, f, "vertex index %d out of range (%d vertices)", v,
                                  m->vertex_count);
        }
        off += (size_t)n;
    }
    if (off != (size_t)m->face_vertex_count)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "face sizes add up to %zu, face_vertex_count is %d", off,
                          m->face_vertex_count);
    for (f = 0; f < m->hole_count; ++f)
        if (m->holes[f] < 0 || m->holes[f] >= m->face_count)
            return sfb__error(ctx, SFB_INVALID_TOPOLOGY, SFB_ELEMENT_FACE, m->holes[f], "hole %d names a face out of range (%d faces)", f,
                              m->face_count);
    return SFB_SUCCESS;
}

/* Bounding box of the finite vertices that faces use; returns 0 when there is none. */
static int sfb__render_bounds(const sfb_mesh_data *m, const float *pos, double *lo, double *hi) {
    int i, any = 0;
    size_t k;
    lo[0] = lo[1] = lo[2] = HUGE_VAL;
    hi[0] = hi[1] = hi[2] = -HUGE_VAL;
    for (k = 0; k < (size_t)m->face_vertex_count; ++k) {
        const float *p = pos + 3 * (size_t)m->face_vertices[k];
        if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) continue;
        for (i = 0; i < 3; ++i) {
            if (p[i] < lo[i]) lo[i] = p[i];
            if (p[i] > hi[i]) hi[i] = p[i];
        }
        any = 1;
    }
    return any;
}

/* The camera and the lights of one picture, the lights fixed to the camera. */
typedef struct sfb__render_view {
    sfb__camera cam;
    double centre[3], radius;
    double key[3], fill[3];  /* directions of the key and the fill light */
    /* the light plane of the highlight lines: normal m, line direction e, across the lines d,
     * a point a; line spacing and the plane's distance */
    double light_m[3], light_e[3], light_d[3], light_a[3], spacing, lightdist;
} sfb__render_view;

/* The orbit about `up` (zero, or +y: the default y-up orbit, untouched): the orbit's
 * direction and right vector, made about +y, turned by the shortest rotation that takes +y to
 * up (about x by pi when up is -y). A z-up model (CAD, catmark_car) is then seen from its side
 * and above, as a y-up one is by default (sfb_render and sfb_surface_analyze). */
void sfb__orbit_up(const float up[3], double dir[3], double right[3]) {
    double u[3], ax[3], len, c, s, t, *v[2];
    int i, k;
    for (i = 0; i < 3; ++i) u[i] = up[i];
    len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (!(len > 0.0) || (u[0] == 0.0 && u[2] == 0.0 && u[1] > 0.0)) return;
    for (i = 0; i < 3; ++i) u[i] /= len;
    /* axis +y x u, sine its length, cosine u.y */
    ax[0] = u[2]; ax[1] = 0.0; ax[2] = -u[0];
    s = sqrt(ax[0] * ax[0] + ax[2] * ax[2]);
    c = u[1];
    if (s > 0.0) { ax[0] /= s; ax[2] /= s; }
    else { ax[0] = 1.0; ax[2] = 0.0; } /* up is -y */
    v[0] = dir; v[1] = right;
    for (k = 0; k < 2; ++k) {
        /* Rodrigues: v c + (ax x v) s + ax (ax.v)(1 - c) */
        double *x = v[k], cr[3], r[3];
        cr[0] = ax[1] * x[2] - ax[2] * x[1]; cr[1] = ax[2] * x[0] - ax[0] * x[2]; cr[2] = ax[0] * x[1] - ax[1] * x[0];
        t = (ax[0] * x[0] + ax[1] * x[1] + ax[2] * x[2]) * (1.0 - c);
        for (i = 0; i < 3; ++i) r[i] = x[i] * c + cr[i] * s + ax[i] * t;
        for (i = 0; i < 3; ++i) x[i] = r[i];
    }
}

/* The orbit camera around the bounding box of what the faces use and the lights (config c, a
 * w x h picture). */
static void sfb__render_view_setup(const sfb_mesh_data *m, const float *pos, const sfb_render_config *c, int w, int h,
                                   sfb__render_view *V) {
    double lo[3], hi[3], yaw, pitch;
    sfb__camera *cam = &V->cam;
    int i;
    /* camera */
    if (!sfb__render_bounds(m, pos, lo, hi)) { lo[0] = lo[1] = lo[2] = -1.0; hi[0] = hi[1] = hi[2] = 1.0; }
    for (i = 0; i < 3; ++i) V->centre[i] = 0.5 * (lo[i] + hi[i]);
    V->radius = 0.5 * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (!(V->radius > 0.0) || !isfinite(V->radius)) V->radius = 1.0;
    yaw = (c->view_set ? c->yaw : SFB__RENDER_DEFAULT_YAW) * SFB__PI / 180.0;
    pitch = (c->view_set ? c->pitch : SFB__RENDER_DEFAULT_PITCH) * SFB__PI / 180.0;
    memset(cam, 0, sizeof *cam);
    cam->ortho = c->orthographic != 0;
    {
        double dir[3], dist = V->radius / sin(SFB__RENDER_HALF_FOV * SFB__PI / 180.0);
        double zoom = c->zoom > 0.0f ? c->zoom : 1.0, half = 0.5 * (w < h ? w : h) * SFB__RENDER_MARGIN;
        dir[0] = cos(pitch) * sin(yaw); dir[1] = sin(pitch); dir[2] = cos(pitch) * cos(yaw);
        cam->right[0] = cos(yaw); cam->right[1] = 0.0; cam->right[2] = -sin(yaw);
        sfb__orbit_up(c->up, dir, cam->right);
        for (i = 0; i < 3; ++i) { cam->eye[i] = V->centre[i] + dist * dir[i]; cam->fwd[i] = -dir[i]; }
        sfb__rcross(cam->right, cam->fwd, cam->up);
        sfb__rnormalize(cam->up);
        cam->focal = cam->ortho ? half * zoom / V->radius : half * zoom / tan(SFB__RENDER_HALF_FOV * SFB__PI / 180.0);
        cam->cx = 0.5 * w;
        cam->cy = 0.5 * h;
    }
    /* lights, fixed to the camera: a key light from the upper left behind the viewer, a fill */
    for (i = 0; i < 3; ++i) {
        V->key[i] = -cam->fwd[i] + 0.55 * cam->up[i] - 0.45 * cam->right[i];
        V->fill[i] = -cam->fwd[i] - 0.3 * cam->up[i] + 0.8 * cam->right[i];
    }
    sfb__rnormalize(V->key);
    sfb__rnormalize(V->fill);
    /* the light plane of the highlight lines: facing the object from the camera's side, lines
     * running at 30 degrees from the picture's vertical */
    V->lightdist = (c->light_distance > 0.0f ? c->light_distance : SFB__RENDER_DEFAULT_LIGHT_DISTANCE) * V->radius;
    V->spacing = 2.0 * V->radius / (c->stripes > 0.0f ? c->stripes : SFB__RENDER_DEFAULT_STRIPES);
    for (i = 0; i < 3; ++i) {
        V->light_m[i] = -cam->fwd[i];
        V->light_e[i] = cos(SFB__PI / 6.0) * cam->up[i] + sin(SFB__PI / 6.0) * cam->right[i];
        V->light_a[i] = V->centre[i] + V->lightdist * V->light_m[i];
    }
    sfb__rcross(V->light_m, V->light_e, V->light_d);
    sfb__rnormalize(V->light_d);
}

/* Projects every vertex into pv (a non-finite one gets z = -1). */
static void sfb__render_project(const sfb_mesh_data *m, const float *pos, const sfb__camera *cam, sfb__pv *pv) {
    int i;
    for (i = 0; i < m->vertex_count; ++i) {
        const float *p = pos + 3 * (size_t)i;
        double d[3], xc, yc, zc;
        if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) { pv[i].z = -1.0; pv[i].x = pv[i].y = pv[i].q = 0.0; continue; }
        d[0] = p[0] - cam->eye[0]; d[1] = p[1] - cam->eye[1]; d[2] = p[2] - cam->eye[2];
        xc = sfb__rdot(d, cam->right); yc = sfb__rdot(d, cam->up); zc = sfb__rdot(d, cam->fwd);
        pv[i].z = zc;
        if (cam->ortho) {
            pv[i].q = 1.0;
            pv[i].x = cam->cx + cam->focal * xc;
            pv[i].y = cam->cy - cam->focal * yc;
        } else {
            pv[i].q = zc > 0.0 ? 1.0 / zc : 0.0;
            pv[i].x = cam->cx + cam->focal * xc * pv[i].q;
            pv[i].y = cam->cy - cam->focal * yc * pv[i].q;
        }
    }
}

/* Pass 1: fan-triangulates and rasterizes every face that is not a hole; a face with a
 * non-finite vertex or one behind the near plane is skipped (counted in *skipped). */
static sfb_result sfb__render_rasterize(sfb_context *ctx, sfb__raster *R, const sfb_mesh_data *m, const sfb__pv *pv,
                                        const unsigned char *hole, double radius, int *skipped) {
    const sfb__camera *cam = R->cam;
    const float *pos = R->pos;
    double near_z = cam->ortho ? -HUGE_VAL : 1e-3 * radius;
    size_t off;
    sfb_result r;
    int f, i;
    for (f = 0, off = 0; f < m->face_count; off += (size_t)m->face_sizes[f], ++f) {
        const int *fv = m->face_vertices + off;
        int n = m->face_sizes[f], bad = 0, t;
        double fn[3];
        if ((f & 255) == 255 && (r = sfb__progress(ctx, 0.6f * (float)f / (float)m->face_count, "render")) != SFB_SUCCESS) return r;
        if (hole && hole[f]) continue;
        for (i = 0; i < n; ++i) {
            const float *p = pos + 3 * (size_t)fv[i];
            if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) bad = 1;
            else if (!(pv[fv[i]].z > near_z)) bad = 1;
        }
        if (bad) { ++*skipped; continue; }
        sfb__polygon_normal(pos, fv, n, fn);
        if (!(sfb__rnormalize(fn) > 0.0)) { fn[0] = -cam->fwd[0]; fn[1] = -cam->fwd[1]; fn[2] = -cam->fwd[2]; }
        for (t = 1; t + 1 < n; ++t) {
            sfb__pv tri[3];
            int vi[3], real[3];
            vi[0] = fv[0]; vi[1] = fv[t]; vi[2] = fv[t + 1];
            tri[0] = pv[vi[0]]; tri[1] = pv[vi[1]]; tri[2] = pv[vi[2]];
            real[0] = 1;              /* (t, t+1) */
            real[1] = t + 2 == n;     /* (t+1, 0): the polygon's last side */
            real[2] = t == 1;         /* (0, 1): its first side */
            sfb__raster_tri(R, tri, vi, real, fn);
        }
    }
    return SFB_SUCCESS;
}

/* Pass 2a (highlight): the stripe coordinate of every covered pixel, kept in its scalar slot
 * (+inf where the normal is parallel to the light plane or the value is out of range). */
static void sfb__render_stripes(const sfb__raster *R, size_t npix, const sfb_render_config *c, const sfb__render_view *V) {
    const sfb__camera *cam = &V->cam;
    size_t k;
    int i;
    for (k = 0; k < npix; ++k) {
        float *g = R->gb + k * SFB__RENDER_GB;
        double n[3], p[3], v[3], nm, wv;
        if (!(g[0] < (float)HUGE_VAL)) continue;
        n[0] = g[1]; n[1] = g[2]; n[2] = g[3];
        p[0] = g[4]; p[1] = g[5]; p[2] = g[6];
        sfb__rnormalize(n);
        if (cam->ortho) { v[0] = -cam->fwd[0]; v[1] = -cam->fwd[1]; v[2] = -cam->fwd[2]; }
        else { v[0] = cam->eye[0] - p[0]; v[1] = cam->eye[1] - p[1]; v[2] = cam->eye[2] - p[2]; }
        if (sfb__rdot(n, v) < 0.0) { n[0] = -n[0]; n[1] = -n[1]; n[2] = -n[2]; }
        nm = sfb__rdot(n, V->light_m);
        if (fabs(nm) < 1e-6) { g[7] = (float)HUGE_VAL; continue; }
        if (c->light_at_infinity) {
            wv = V->lightdist * sfb__rdot(n, V->light_d) / nm / V->spacing;
        } else {
            double ap[3], mu, X[3];
            for (i = 0; i < 3; ++i) ap[i] = V->light_a[i] - p[i];
            mu = sfb__rdot(ap, V->light_m) / nm;
            for (i = 0; i < 3; ++i) X[i] = p[i] + mu * n[i] - V->light_a[i];
            wv = sfb__rdot(X, V->light_d) / V->spacing;
        }
        g[7] = isfinite(wv) && fabs(wv) < 1e7 ? (float)wv : (float)HUGE_VAL;
    }
}

/* The highlight colour of pixel (x, y) (index pix, stripe coordinate wv, diffuse term diff)
 * over its lit grey base in rgb: a dark blue and a cyan band per period, filtered by the pixel's
 * footprint in stripe periods. */
static void sfb__render_highlight(const sfb__raster *R, int x, int y, size_t pix, double wv, double diff, double *rgb) {
    int w = R->w, h = R->h, i;
    double dx = HUGE_VAL, dy = HUGE_VAL, fw, cb, cc;
    /* the pixel footprint in stripe periods: the smaller one-sided difference per
     * axis (robust at silhouettes, where one neighbour is another surface) */
    if (x > 0 && R->gb[(pix - 1) * SFB__RENDER_GB + 7] < 1e30f) dx = fabs(wv - R->gb[(pix - 1) * SFB__RENDER_GB + 7]);
    if (x + 1 < w && R->gb[(pix + 1) * SFB__RENDER_GB + 7] < 1e30f) {
        double d2 = fabs(wv - R->gb[(pix + 1) * SFB__RENDER_GB + 7]);
        if (d2 < dx) dx = d2;
    }
    if (y > 0 && R->gb[(pix - (size_t)w) * SFB__RENDER_GB + 7] < 1e30f)
        dy = fabs(wv - R->gb[(pix - (size_t)w) * SFB__RENDER_GB + 7]);
    if (y + 1 < h && R->gb[(pix + (size_t)w) * SFB__RENDER_GB + 7] < 1e30f) {
        double d2 = fabs(wv - R->gb[(pix + (size_t)w) * SFB__RENDER_GB + 7]);
        if (d2 < dy) dy = d2;
    }
    if (dx == HUGE_VAL) dx = 0.0;
    if (dy == HUGE_VAL) dy = 0.0;
    fw = dx + dy;
    cb = sfb__band_cover(wv, fw, 0.00, 0.22);
    cc = sfb__band_cover(wv, fw, 0.50, 0.72);
    {
        double lum = 0.45 + 0.55 * diff;
        double blue[3], cyan[3];
        blue[0] = 0.05 * lum; blue[1] = 0.12 * lum; blue[2] = 0.75 * lum;
        cyan[0] = 0.10 * lum; cyan[1] = 0.80 * lum; cyan[2] = 0.95 * lum;
        for (i = 0; i < 3; ++i) rgb[i] = rgb[i] * (1.0 - cb - cc) + blue[i] * cb + cyan[i] * cc;
    }
}

/* The colour of covered pixel (x, y) (index pix) in the config's mode, before gamma and the
 * edge overlay: the normal as RGB, or lit (diffuse, specular, fill) grey, scalar map or
 * highlight lines. */
static void sfb__render_lit(const sfb__raster *R, const sfb_render_config *c, const sfb__render_view *V, int x, int y, size_t pix,
                            double *rgb) {
    const sfb__camera *cam = &V->cam;
    const float *g = R->gb + pix * SFB__RENDER_GB;
    double n[3], p[3], v[3], diff, spec, hv[3];
    int i;
    n[0] = g[1]; n[1] = g[2]; n[2] = g[3];
    p[0] = g[4]; p[1] = g[5]; p[2] = g[6];
    sfb__rnormalize(n);
    if (c->mode == SFB_RENDER_NORMALS) {
        for (i = 0; i < 3; ++i) rgb[i] = 0.5 + 0.5 * n[i];
        return;
    }
    if (cam->ortho) { v[0] = -cam->fwd[0]; v[1] = -cam->fwd[1]; v[2] = -cam->fwd[2]; }
    else { v[0] = cam->eye[0] - p[0]; v[1] = cam->eye[1] - p[1]; v[2] = cam->eye[2] - p[2]; }
    sfb__rnormalize(v);
    if (sfb__rdot(n, v) < 0.0) { n[0] = -n[0]; n[1] = -n[1]; n[2] = -n[2]; }
    diff = sfb__rdot(n, V->key);
    if (diff < 0.0) diff = 0.0;
    for (i = 0; i < 3; ++i) hv[i] = V->key[i] + v[i];
    sfb__rnormalize(hv);
    spec = sfb__rdot(n, hv);
    spec = spec > 0.0 ? pow(spec, 48.0) : 0.0;
    if (c->mode == SFB_RENDER_SHADED) {
        double fl = sfb__rdot(n, V->fill), lum;
        if (fl < 0.0) fl = 0.0;
        lum = 0.72 * (0.16 + 0.70 * diff + 0.18 * fl) + 0.30 * spec;
        rgb[0] = rgb[1] = rgb[2] = lum;
    } else if (c->mode == SFB_RENDER_WEIGHTS) {
        double lum = 0.55 + 0.45 * diff;
        sfb__colormap(g[7], rgb);
        for (i = 0; i < 3; ++i) rgb[i] = rgb[i] * lum + 0.12 * spec;
    } else {
        /* highlight: a lit light-grey base with a dark blue and a cyan band per period */
        double base = 0.42 + 0.55 * diff, wv = g[7];
        rgb[0] = rgb[1] = rgb[2] = base;
        if (wv < 1e30) sfb__render_highlight(R, x, y, pix, wv, diff, rgb);
    }
}

/* Pass 2: shades every pixel into rgba (the background where nothing is drawn), counting the
 * covered ones in *object_pixels. */
static sfb_result sfb__render_shade(sfb_context *ctx, const sfb__raster *R, const sfb_render_config *c, const sfb__render_view *V,
                                    const unsigned char *bg, unsigned char *rgba, long *object_pixels) {
    int w = R->w, h = R->h, x, y, i;
    sfb_result r;
    for (y = 0; y < h; ++y) {
        if ((y & 15) == 0 && (r = sfb__progress(ctx, 0.6f + 0.4f * (float)y / (float)h, "render")) != SFB_SUCCESS) return r;
        for (x = 0; x < w; ++x) {
            size_t pix = (size_t)y * (size_t)w + (size_t)x;
            const float *g = R->gb + pix * SFB__RENDER_GB;
            unsigned char *o = rgba + 4 * pix;
            double rgb[3], e;
            if (!(g[0] < (float)HUGE_VAL)) { memcpy(o, bg, 4); continue; }
            ++*object_pixels;
            sfb__render_lit(R, c, V, x, y, pix, rgb);
            /* a little gamma on lit colours, so that the darker half keeps detail (normals are
             * written as they are) */
            if (c->mode != SFB_RENDER_NORMALS)
                for (i = 0; i < 3; ++i) rgb[i] = pow(sfb__rclamp(rgb[i], 0.0, 1.0), 1.0 / 1.6);
            if (R->edge && R->edge[pix]) {
                e = R->edge[pix] / 255.0 * 0.85;
                for (i = 0; i < 3; ++i) rgb[i] = rgb[i] * (1.0 - e) + 0.08 * e;
            }
            o[0] = sfb__to_byte(rgb[0]); o[1] = sfb__to_byte(rgb[1]); o[2] = sfb__to_byte(rgb[2]); o[3] = 255;
        }
    }
    return SFB_SUCCESS;
}

SFB_API sfb_result sfb_render(sfb_context *ctx, const sfb_mesh_data *m, const sfb_render_config *cfg, sfb_image *out) {
    sfb_render_config c;
    const float *pos = NULL, *nrm = NULL, *scal = NULL;
    int w = 0, h = 0, f;
    size_t npix, bytes, gbytes, k;
    sfb__render_view V;
    sfb__raster R;
    sfb__pv *pv = NULL;
    unsigned char *hole = NULL, *rgba = NULL;
    unsigned char bg[4];
    sfb_result r = SFB_SUCCESS;
    long object_pixels = 0;
    int skipped = 0;
    if (out) memset(out, 0, sizeof *out);
    if (!ctx) return SFB_INVALID_ARGS;
    if (!m || !out) return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb_render: NULL argument");
    c = cfg ? *cfg : sfb_render_config_init(SFB_RENDER_SHADED);
    if ((r = sfb__render_check(ctx, m, &c, &pos, &nrm, &scal, &w, &h)) != SFB_SUCCESS) return r;
    if (c.mode != SFB_RENDER_WEIGHTS) scal = NULL;
    if (c.background[0] | c.background[1] | c.background[2] | c.background[3]) memcpy(bg, c.background, 4);
    else { bg[0] = 44; bg[1] = 48; bg[2] = 56; bg[3] = 255; }

    /* memory: G-buffer, edge coverage, projected vertices, hole flags, the picture */
    npix = (size_t)w * (size_t)h;
    if (!sfb__mul_size(npix, SFB__RENDER_GB * sizeof(float), &gbytes) || !sfb__mul_size(npix, 4, &bytes))
        return sfb__error(ctx, SFB_LIMIT_EXCEEDED, SFB_ELEMENT_NONE, -1, "image too large");
    if ((r = sfb__progress(ctx, 0.0f, "render")) != SFB_SUCCESS) return r;
    R.gb = (float *)sfb__alloc(ctx, gbytes);
    R.edge = c.draw_edges ? (unsigned char *)sfb__calloc(ctx, npix, 1) : NULL;
    pv = (sfb__pv *)sfb__alloc(ctx, ((size_t)m->vertex_count + 1) * sizeof(sfb__pv));
    hole = m->hole_count > 0 ? (unsigned char *)sfb__calloc(ctx, (size_t)m->face_count, 1) : NULL;
    rgba = (unsigned char *)sfb__alloc(ctx, bytes);
    if (!R.gb || (c.draw_edges && !R.edge) || !pv || (m->hole_count > 0 && !hole) || !rgba) {
        r = sfb__oom(ctx, "the picture (render)");
        goto done;
    }
    for (f = 0; f < m->hole_count; ++f) hole[m->holes[f]] = 1;
    /* depth "none"; and no stripe coordinate (slot 7): the highlight filter reads the slot of
     * every neighbour, background ones included, which were left uninitialised (a picture that
     * depended on what the allocator handed back) */
    for (k = 0; k < npix; ++k) R.gb[k * SFB__RENDER_GB] = R.gb[k * SFB__RENDER_GB + 7] = (float)HUGE_VAL;

    sfb__render_view_setup(m, pos, &c, w, h, &V);
    sfb__render_project(m, pos, &V.cam, pv);
    /* pass 1: rasterize */
    R.w = w; R.h = h; R.pos = pos; R.nrm = nrm; R.scal = scal; R.cam = &V.cam; R.draw_edges = c.draw_edges != 0;
    if ((r = sfb__render_rasterize(ctx, &R, m, pv, hole, V.radius, &skipped)) != SFB_SUCCESS) goto done;
    /* pass 2a (highlight): stripe coordinate per pixel, kept in the scalar slot */
    if (c.mode == SFB_RENDER_HIGHLIGHT) sfb__render_stripes(&R, npix, &c, &V);
    /* pass 2: shade */
    if ((r = sfb__render_shade(ctx, &R, &c, &V, bg, rgba, &object_pixels)) != SFB_SUCCESS) goto done;
    if ((r = sfb__progress(ctx, 1.0f, "render")) != SFB_SUCCESS) goto done;
    out->width = w;
    out->height = h;
    out->rgba = rgba;
    out->object_pixels = object_pixels > 2147483647L ? 2147483647 : (int)object_pixels;
    out->skipped_faces = skipped;
    out->ctx_ = ctx;
    rgba = NULL;
done:
    sfb__free(ctx, R.gb);
    sfb__free(ctx, R.edge);
    sfb__free(ctx, pv);
    sfb__free(ctx, hole);
    sfb__free(ctx, rgba);
    return r;
}
