/* agree: the backend agreement suite. Every optional backend (simd, gl, osmesa) against `ref`,
 * the numeric oracle, on the same meshes and the same compiled tables.
 *
 *   agree [SHAPES_DIR] [--seed S] [--cases N] [--l3-faces N] [--verbose]
 *
 * Prints one line per check, "PASS name", "FAIL name: details (seed S)" or "SKIP name: why",
 * comment lines starting with "#", and closes with "N passed, N failed, N skipped". Exit status
 * 1 when anything failed.
 *
 * Checks, for each backend that the probe finds available (sfb_backend_probe):
 *   BACKEND/shape/NAME@L     every peer shape (the .obj files of SHAPES_DIR, scheme from the catmark_/loop_/
 *                            bilinear_ prefix) at level 2, and at level 3 those of at most 400
 *                            faces (all but 9; --l3-faces N moves the bound): tables
 *                            VERTEX, LIMIT, TANGENT_U, TANGENT_V and UV (shapes with UVs)
 *   BACKEND/random/I         random grids and tori (jittered, triangles and hexagons mixed in for
 *                            Catmull-Clark, all triangles for Loop) with random creases and crease
 *                            lines (sharpness 0.5, 1, 1.7, 3, 10), corners, holes, boundary modes,
 *                            Chaikin, UVs with seams; levels 1..3
 *   BACKEND/layout/lenL/K    strided buffers: lengths 1, 2, 3, 4, 7, 16, layouts with offsets and
 *                            strides > length (VERTEX and LIMIT tables, random data); padding and
 *                            the tail of dst must stay untouched (filled with a sentinel first);
 *                            src is allocated to the exact span of its view, so an over-read is an
 *                            error under AddressSanitizer. Also run for ref against itself, and for
 *                            every simd kernel (simd-ISA/..., SURFBLEND_SIMD_ISA) the CPU has.
 *   simd/threads/T           threads = 1, 2 and 0 (one per core) on a large mesh, and several
 *                            application threads calling eval on one surface at once
 *   simd/threads/patches-S   the simd patch upload over its pool: Catmull-Clark and Loop surfaces of
 *                            a triangulated torus built on 1 and on 4 threads evaluate the same bit
 *                            for bit (position, derivatives, normal; and without second derivatives,
 *                            the simd float pair kernel's case, over an odd count of locations)
 *   BACKEND/eval_gl          sfb_surface_eval_stencils_gl returns SFB_UNSUPPORTED (no host context)
 * and, independent of availability:
 *   env/bogus                SURFBLEND_BACKEND=bogus: the context is still created on the default
 *                            order and the report says the name is unknown
 *   forced/NAME              a backend that cannot initialise here, forced first in the list:
 *                            the report says "unavailable (reason)" and selection falls to ref
 *
 * A backend that is unavailable makes its checks SKIP with the probe's reason, never PASS; when
 * the environment variable SFB_REQUIRE_BACKENDS (comma-separated names, e.g. "simd,gl,osmesa")
 * lists it, each of its checks FAILs instead. Random data use the seed from --seed, else
 * SFB_SEED, else the clock; it is printed first and with every failure: rerun with --seed S.
 *
 * Tolerances (shared/DESIGN.md): positions (VERTEX, LIMIT) 1e-5 x the control mesh's bounding
 * box diagonal; UVs 1e-5 x the UV bounding box diagonal (at least 1e-5); tangents 1e-5 x diagonal
 * x max(1, largest |tangent| of ref), because tangent rows have weights of mixed sign summing to
 * zero, so their float rounding grows with the magnitudes involved rather than with the result;
 * random primvar data (layout checks) 1e-5 x max |src| (the VERTEX and LIMIT tables used there
 * have non-negative weights summing to one).
 *
 * Build: cc -std=c99 -I. tests/agree.c build/libsfb.o -lm -lpthread -ldl   (libsfb.o compiled
 * with SURFBLEND_ALL_BACKENDS; nothing else is linked: GL, EGL, OSMesa are dlopen'ed).
 */
#define _POSIX_C_SOURCE 200809L
#include "surfblend.h"
#include "harness.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>

#define TOL_REL 1e-5

/* ---- backends under test (tests/harness.h: backend) ---- */

static int g_verbose;

static sfb_context *g_ref;      /* the oracle's context */
static const char *g_only;      /* --only LIST: the backends to test (default all) */
static backend g_backends[3];
static const int g_backend_count = 3;

static void setup_backends(void) {
    static const sfb_backend_kind kinds[3] = {SFB_BACKEND_SIMD, SFB_BACKEND_GL, SFB_BACKEND_OSMESA};
    char ref_info[256];
    int i;
    if (sfb_backend_probe(SFB_BACKEND_REF, NULL, ref_info, sizeof ref_info) != SFB_SUCCESS)
        fail("probe/ref", "ref must always be available: %s", ref_info);
    else
        pass("probe/ref");
    g_ref = make_context_threads(SFB_BACKEND_REF, 1);
    for (i = 0; i < g_backend_count; ++i) {
        backend *b = &g_backends[i];
        char name[64];
        sfb_result r;
        memset(b, 0, sizeof *b);
        b->kind = kinds[i];
        b->name = sfb_backend_kind_name(kinds[i]);
        b->required = backend_required(b->name);
        if (g_only && !listed(g_only, b->name)) {
            b->excluded = 1;
            snprintf(b->why, sizeof b->why, "left out by --only");
            continue;
        }
        snprintf(name, sizeof name, "probe/%s", b->name);
        r = sfb_backend_probe(b->kind, NULL, b->why, sizeof b->why);
        if (r != SFB_SUCCESS) {
            if (!b->why[0]) snprintf(b->why, sizeof b->why, "%s (no reason given)", sfb_result_string(r));
            printf("# %s: unavailable (%s): %s\n", b->name, sfb_result_string(r), b->why);
            backend_missing(b, name);
            continue;
        }
        printf("# %s: available: %s\n", b->name, b->why[0] ? b->why : "(no description)");
        b->ctx = make_context_threads(b->kind, 0);
        if (!b->ctx) {
            fail(name, "probe succeeded (%s) but sfb_context_create with backends = {%s} failed", b->why, b->name);
            snprintf(b->why, sizeof b->why, "context creation failed after a successful probe");
            continue;
        }
        if (strcmp(sfb_context_backend_name(b->ctx), b->name) != 0) {
            char rep[1024];
            sfb_context_backend_report(b->ctx, rep, sizeof rep);
            fail(name, "context asked for %s alone runs %s; report: %s", b->name, sfb_context_backend_name(b->ctx), rep);
            sfb_context_destroy(b->ctx);
            b->ctx = NULL;
            snprintf(b->why, sizeof b->why, "context selected another backend");
            continue;
        }
        b->available = 1;
        {
            char info[512];
            info[0] = 0;
            sfb_context_backend_info(b->ctx, info, sizeof info);
            if (!info[0]) fail(name, "sfb_context_backend_info is empty for %s", b->name);
            else pass(name);
        }
    }
}

/* ---- buffers and comparisons ---- */

typedef struct cmp {
    double err, tol;   /* largest |difference| and its tolerance */
    int row, comp;     /* where */
    float want, got;
    int bad;           /* err > tol, or a non-finite value where ref is finite */
} cmp;

static const char *table_name(sfb_table t) {
    switch (t) {
    case SFB_TABLE_VERTEX: return "VERTEX";
    case SFB_TABLE_LIMIT: return "LIMIT";
    case SFB_TABLE_TANGENT_U: return "TANGENT_U";
    case SFB_TABLE_TANGENT_V: return "TANGENT_V";
    case SFB_TABLE_UV: return "UV";
    default: return "?";
    }
}

/* Compares rows x len values: want contiguous (stride len), got through desc gd. */
static cmp compare(const float *want, const float *got, sfb_buffer_desc gd, int rows, int len, double tol) {
    cmp c;
    int r, k;
    memset(&c, 0, sizeof c);
    c.tol = tol;
    c.row = -1;
    for (r = 0; r < rows; ++r)
        for (k = 0; k < len; ++k) {
            float w = want[(size_t)r * len + k], g = got[gd.offset + (size_t)r * gd.stride + k];
            double d = fabs((double)w - (double)g);
            if (isfinite(w) && !isfinite(g)) d = INFINITY;
            if (!isfinite(w) && !isfinite(g)) d = 0.0; /* both non-finite: not this suite's concern */
            if (d > c.err || (c.row < 0 && d > 0)) {
                c.err = d; c.row = r; c.comp = k; c.want = w; c.got = g;
            }
        }
    c.bad = !(c.err <= c.tol);
    return c;
}

static double max_abs(const float *v, size_t n) {
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        if (isfinite(v[i]) && fabs(v[i]) > m) m = fabs(v[i]);
    return m;
}

static double max_norm3(const float *v, int rows) {
    double m = 0.0;
    int i;
    for (i = 0; i < rows; ++i) {
        double n = sqrt((double)v[3 * i] * v[3 * i] + (double)v[3 * i + 1] * v[3 * i + 1] + (double)v[3 * i + 2] * v[3 * i + 2]);
        if (isfinite(n) && n > m) m = n;
    }
    return m;
}

static double bbox_diag(const float *p, int n, int dim) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, d = 0.0;
    int i, k;
    if (n <= 0) return 0.0;
    for (i = 0; i < n; ++i)
        for (k = 0; k < dim; ++k) {
            double x = p[(size_t)i * dim + k];
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
        }
    for (k = 0; k < dim; ++k) d += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    return sqrt(d);
}

/* ---- one mesh, all tables, every backend against ref ---- */

typedef struct table_out {
    int built, rows, len;
    float *data; /* rows x len, contiguous */
} table_out;

/* Source buffer and tolerance of table t for this mesh. */
static const float *table_source(const sfb_mesh_desc *d, sfb_table t, int *len) {
    if (t == SFB_TABLE_UV) { *len = 2; return d->uvs; }
    *len = 3;
    return d->positions;
}

static sfb_result eval_all(const sfb_surface *s, const sfb_mesh_desc *d, table_out out[SFB_TABLE_COUNT_], char *err, size_t errsz,
                           sfb_context *ctx) {
    int t;
    for (t = 0; t < SFB_TABLE_COUNT_; ++t) {
        sfb_stencil_info info;
        sfb_buffer_desc bd;
        const float *src;
        int len;
        sfb_result r;
        out[t].built = 0;
        out[t].data = NULL;
        if (sfb_surface_stencil_info(s, (sfb_table)t, &info) != SFB_SUCCESS) continue;
        src = table_source(d, (sfb_table)t, &len);
        if (!src) continue;
        out[t].built = 1;
        out[t].rows = info.rows;
        out[t].len = len;
        out[t].data = (float *)xmalloc((size_t)info.rows * len * sizeof(float) + sizeof(float));
        bd.offset = 0; bd.length = len; bd.stride = len;
        r = sfb_surface_eval_stencils(s, (sfb_table)t, src, bd, out[t].data, bd);
        if (r != SFB_SUCCESS) {
            snprintf(err, errsz, "sfb_surface_eval_stencils(%s): %s: %s", table_name((sfb_table)t), sfb_result_string(r),
                     sfb_last_error(ctx));
            return r;
        }
    }
    return SFB_SUCCESS;
}

static void free_all(table_out out[SFB_TABLE_COUNT_]) {
    int t;
    for (t = 0; t < SFB_TABLE_COUNT_; ++t) {
        free(out[t].data);
        out[t].data = NULL;
    }
}

/* Tolerance of each table for a mesh with position diagonal `diag`, UV diagonal `uvdiag`. */
static double table_tol(sfb_table t, double diag, double uvdiag, const table_out *ref) {
    double scale = diag > 0 && isfinite(diag) ? diag : 1.0;
    if (t == SFB_TABLE_UV) return TOL_REL * (uvdiag > 1.0 ? uvdiag : 1.0);
    if (t == SFB_TABLE_TANGENT_U || t == SFB_TABLE_TANGENT_V) {
        double tm = max_norm3(ref->data, ref->rows);
        return TOL_REL * scale * (tm > 1.0 ? tm : 1.0);
    }
    return TOL_REL * scale;
}

/* Runs one mesh: ref once, then every backend. `group`/`label` name the checks. */
static void run_mesh(const char *group, const char *label, const sfb_mesh *mesh, sfb_scheme scheme, int level, const char *extra) {
    sfb_surface_config cfg = sfb_surface_config_init(scheme, level);
    sfb_surface *rs = NULL;
    sfb_mesh_desc d;
    table_out want[SFB_TABLE_COUNT_];
    double diag, uvdiag, tol[SFB_TABLE_COUNT_];
    char err[1024];
    sfb_result r;
    int i, t;

    cfg.flags = SFB_REFINE_LIMIT | SFB_REFINE_UVS;
    sfb_mesh_get_desc(mesh, &d);
    diag = bbox_diag(d.positions, d.vertex_count, 3);
    uvdiag = d.uvs ? bbox_diag(d.uvs, d.uv_count, 2) : 0.0;

    r = sfb_surface_create(g_ref, mesh, &cfg, &rs);
    if (r == SFB_SUCCESS) {
        r = eval_all(rs, &d, want, err, sizeof err, g_ref);
    } else {
        snprintf(err, sizeof err, "sfb_surface_create: %s", sfb_last_error(g_ref));
        memset(want, 0, sizeof want);
    }
    for (t = 0; t < SFB_TABLE_COUNT_; ++t) tol[t] = want[t].built ? table_tol((sfb_table)t, diag, uvdiag, &want[t]) : 0.0;

    for (i = 0; i < g_backend_count; ++i) {
        backend *b = &g_backends[i];
        char name[300], fails[2048];
        sfb_surface *bs = NULL;
        table_out got[SFB_TABLE_COUNT_];
        size_t used = 0;
        snprintf(name, sizeof name, "%s/%s/%s", b->name, group, label);
        if (!b->available) { backend_missing(b, name); continue; }
        if (r != SFB_SUCCESS) { fail(name, "ref failed on this mesh (%s)%s%s", err, extra ? "; " : "", extra ? extra : ""); continue; }
        if (sfb_surface_create(b->ctx, mesh, &cfg, &bs) != SFB_SUCCESS) {
            fail(name, "sfb_surface_create on %s: %s%s%s", b->name, sfb_last_error(b->ctx), extra ? "; " : "", extra ? extra : "");
            continue;
        }
        if (eval_all(bs, &d, got, err, sizeof err, b->ctx) != SFB_SUCCESS) {
            fail(name, "%s%s%s", err, extra ? "; " : "", extra ? extra : "");
            free_all(got);
            sfb_surface_destroy(bs);
            continue;
        }
        fails[0] = 0;
        for (t = 0; t < SFB_TABLE_COUNT_; ++t) {
            sfb_buffer_desc gd;
            cmp c;
            if (!want[t].built) continue;
            if (!got[t].built || got[t].rows != want[t].rows) {
                used += (size_t)snprintf(fails + used, sizeof fails - used, "%s%s: table differs (rows %d vs ref %d)", used ? "; " : "",
                                         table_name((sfb_table)t), got[t].built ? got[t].rows : -1, want[t].rows);
                if (used >= sizeof fails) used = sizeof fails - 1;
                continue;
            }
            gd.offset = 0; gd.length = want[t].len; gd.stride = want[t].len;
            c = compare(want[t].data, got[t].data, gd, want[t].rows, want[t].len, tol[t]);
            if (g_verbose)
                printf("#   %s %s: max |diff| %.3g, tol %.3g (%.2g of tol)\n", name, table_name((sfb_table)t), c.err, c.tol,
                       c.tol > 0 ? c.err / c.tol : 0.0);
            if (c.bad) {
                used += (size_t)snprintf(fails + used, sizeof fails - used,
                                         "%s%s: max |diff| %.3g > tol %.3g at row %d component %d (ref %.9g, %s %.9g)", used ? "; " : "",
                                         table_name((sfb_table)t), c.err, c.tol, c.row, c.comp, (double)c.want, b->name, (double)c.got);
                if (used >= sizeof fails) used = sizeof fails - 1;
            }
        }
        if (fails[0]) fail(name, "%s%s%s", fails, extra ? "; mesh: " : "", extra ? extra : "");
        else pass(name);
        free_all(got);
        sfb_surface_destroy(bs);
    }
    free_all(want);
    sfb_surface_destroy(rs);
}

/* ---- (a) the peer corpus ---- */

/* Level 3 as well for shapes this small (base faces): keeps the suite within its time budget.
 * --l3-faces N changes it (a large N: every shape at level 3). */
static int g_l3_max_faces = 400;

static void run_shapes(const char *dir) {
    int n = 0, i;
    char **names = list_shapes(dir, NULL, NULL, &n);
    if (!names) return;
    if (n == 0) fail("shapes", "no .obj files in %s", dir);
    for (i = 0; i < n; ++i) {
        char label[300], why[1200];
        sfb_scheme scheme;
        sfb_mesh *mesh = NULL;
        sfb_mesh_info info;
        int level;
        char base[256];
        size_t bl = strlen(names[i]) - 4;
        if (bl >= sizeof base) bl = sizeof base - 1;
        memcpy(base, names[i], bl);
        base[bl] = 0;
        if (strncmp(base, "catmark_", 8) == 0) scheme = SFB_SCHEME_CATMARK;
        else if (strncmp(base, "loop_", 5) == 0) scheme = SFB_SCHEME_LOOP;
        else if (strncmp(base, "bilinear_", 9) == 0) scheme = SFB_SCHEME_BILINEAR;
        else { printf("# %s left out: no catmark_/loop_/bilinear_ prefix\n", base); continue; }
        if (!(mesh = load_obj(g_ref, dir, names[i], why, sizeof why))) {
            snprintf(label, sizeof label, "shape/%s", base);
            fail(label, "%s", why);
            continue;
        }
        sfb_mesh_get_info(mesh, &info);
        for (level = 2; level <= 3; ++level) {
            if (level == 3 && info.face_count > g_l3_max_faces) break;
            snprintf(label, sizeof label, "%s@%d", base, level);
            run_mesh("shape", label, mesh, scheme, level, NULL);
        }
        sfb_mesh_destroy(mesh);
    }
    free_names(names, n);
}

/* ---- (b) random meshes ---- */

typedef struct rmesh {
    int nv, nf, nfv, nc, ncorner, nholes, nuv;
    float *pos, *cs, *corner_s, *uv;
    int *fs, *fv, *cv, *corner, *holes, *fuv;
    int boundary, crease_method, tri_rule, uv_interp;
    char descr[256];
} rmesh;

static void rmesh_free(rmesh *m) {
    free(m->pos); free(m->cs); free(m->corner_s); free(m->uv);
    free(m->fs); free(m->fv); free(m->cv); free(m->corner); free(m->holes); free(m->fuv);
    memset(m, 0, sizeof *m);
}

static const float k_sharpness[5] = {0.5f, 1.0f, 1.7f, 3.0f, 10.0f};

/* A grid (open) or torus (closed) of nu x nv cells; Loop: every cell two triangles; others:
 * some cells two triangles, some pairs of cells merged into hexagons. Jittered positions,
 * UVs on an (nu+1) x (nv+1) lattice (seams where the torus wraps), random creases (single
 * edges and whole lines), corners, a hole, boundary/crease/triangle/UV options. */
static void rmesh_generate(rng *g, sfb_scheme scheme, rmesh *m) {
    int torus = rng_int(g, 2), nu, nv, i, j, ne = 0, k;
    int *edges, *used_cell;
    float *esharp;
    int ncrease_lines = 0, nrandom = 0;
    memset(m, 0, sizeof *m);
    nu = torus ? 3 + rng_int(g, 8) : 1 + rng_int(g, 9);
    nv = torus ? 3 + rng_int(g, 8) : 1 + rng_int(g, 9);
    m->nv = torus ? nu * nv : (nu + 1) * (nv + 1);
    m->pos = (float *)xmalloc((size_t)m->nv * 3 * sizeof(float));
    for (i = 0; i < (torus ? nu : nu + 1); ++i)
        for (j = 0; j < (torus ? nv : nv + 1); ++j) {
            float *p = m->pos + 3 * (size_t)(torus ? i * nv + j : i * (nv + 1) + j);
            if (torus) {
                double u = 6.283185307179586 * (i + rng_range(g, -0.2, 0.2)) / nu;
                double v = 6.283185307179586 * (j + rng_range(g, -0.2, 0.2)) / nv;
                double rr = 1.0 + rng_range(g, -0.15, 0.15);
                p[0] = (float)((3.0 + rr * cos(v)) * cos(u));
                p[1] = (float)((3.0 + rr * cos(v)) * sin(u));
                p[2] = (float)(rr * sin(v));
            } else {
                p[0] = (float)(i + rng_range(g, -0.25, 0.25));
                p[1] = (float)(j + rng_range(g, -0.25, 0.25));
                p[2] = (float)rng_range(g, -0.5, 0.5);
            }
        }
#define VID(a, b) (torus ? (((a) % nu) * nv + ((b) % nv)) : ((a) * (nv + 1) + (b)))
#define UVID(a, b) ((a) * (nv + 1) + (b))
    m->nuv = (nu + 1) * (nv + 1);
    m->uv = (float *)xmalloc((size_t)m->nuv * 2 * sizeof(float));
    for (i = 0; i <= nu; ++i)
        for (j = 0; j <= nv; ++j) {
            m->uv[2 * UVID(i, j)] = (float)i / nu;
            m->uv[2 * UVID(i, j) + 1] = (float)j / nv;
        }
    /* at most 2 faces per cell, 6 face-vertices per cell */
    m->fs = (int *)xmalloc((size_t)nu * nv * 2 * sizeof(int));
    m->fv = (int *)xmalloc((size_t)nu * nv * 6 * sizeof(int));
    m->fuv = (int *)xmalloc((size_t)nu * nv * 6 * sizeof(int));
    used_cell = (int *)calloc((size_t)nu * nv, sizeof(int));
    if (!used_cell) exit(2);
    for (j = 0; j < nv; ++j)
        for (i = 0; i < nu; ++i) {
            int ci[4], cj[4], c, roll = rng_int(g, 100);
            if (used_cell[i * nv + j]) continue;
            used_cell[i * nv + j] = 1;
            ci[0] = i; cj[0] = j; ci[1] = i + 1; cj[1] = j; ci[2] = i + 1; cj[2] = j + 1; ci[3] = i; cj[3] = j + 1;
            if (scheme == SFB_SCHEME_LOOP || roll < 15) { /* two triangles, random diagonal */
                int d = rng_int(g, 2), tri[2][3], f;
                tri[0][0] = d; tri[0][1] = d + 1; tri[0][2] = (d + 2) % 4;
                tri[1][0] = d; tri[1][1] = (d + 2) % 4; tri[1][2] = (d + 3) % 4;
                for (f = 0; f < 2; ++f) {
                    m->fs[m->nf++] = 3;
                    for (c = 0; c < 3; ++c) {
                        m->fv[m->nfv] = VID(ci[tri[f][c]], cj[tri[f][c]]);
                        m->fuv[m->nfv++] = UVID(ci[tri[f][c]], cj[tri[f][c]]);
                    }
                }
            } else if (roll < 27 && i + 1 < nu && !used_cell[(i + 1) * nv + j]) { /* hexagon of two cells */
                int hi[6], hj[6];
                used_cell[(i + 1) * nv + j] = 1;
                hi[0] = i; hj[0] = j; hi[1] = i + 1; hj[1] = j; hi[2] = i + 2; hj[2] = j;
                hi[3] = i + 2; hj[3] = j + 1; hi[4] = i + 1; hj[4] = j + 1; hi[5] = i; hj[5] = j + 1;
                m->fs[m->nf++] = 6;
                for (c = 0; c < 6; ++c) { m->fv[m->nfv] = VID(hi[c], hj[c]); m->fuv[m->nfv++] = UVID(hi[c], hj[c]); }
            } else {
                m->fs[m->nf++] = 4;
                for (c = 0; c < 4; ++c) { m->fv[m->nfv] = VID(ci[c], cj[c]); m->fuv[m->nfv++] = UVID(ci[c], cj[c]); }
            }
        }
    free(used_cell);
    /* unique edges with a sharpness each (0: none) */
    edges = (int *)xmalloc((size_t)m->nfv * 2 * sizeof(int));
    esharp = (float *)xmalloc((size_t)m->nfv * sizeof(float));
    {
        int f, o = 0;
        for (f = 0; f < m->nf; ++f) {
            int n = m->fs[f], c;
            for (c = 0; c < n; ++c) {
                int a = m->fv[o + c], b = m->fv[o + (c + 1) % n], lo = a < b ? a : b, hi = a < b ? b : a, x;
                for (x = 0; x < ne; ++x)
                    if (edges[2 * x] == lo && edges[2 * x + 1] == hi) break;
                if (x == ne) { edges[2 * ne] = lo; edges[2 * ne + 1] = hi; esharp[ne++] = 0.0f; }
            }
            o += n;
        }
    }
    /* whole crease lines along j = const (always edges, whatever the cells became) */
    if (rng_int(g, 2)) {
        int lines = 1 + rng_int(g, 2), l;
        for (l = 0; l < lines; ++l) {
            int jj = rng_int(g, torus ? nv : nv + 1);
            float s = k_sharpness[rng_int(g, 5)];
            for (i = 0; i < nu; ++i) {
                int a = VID(i, jj), b = VID(i + 1, jj), lo = a < b ? a : b, hi = a < b ? b : a, x;
                for (x = 0; x < ne; ++x)
                    if (edges[2 * x] == lo && edges[2 * x + 1] == hi) { esharp[x] = s; break; }
            }
            ++ncrease_lines;
        }
    }
    nrandom = rng_int(g, ne / 3 + 1);
    for (k = 0; k < nrandom; ++k) esharp[rng_int(g, ne)] = k_sharpness[rng_int(g, 5)];
    m->cv = (int *)xmalloc((size_t)ne * 2 * sizeof(int) + 1);
    m->cs = (float *)xmalloc((size_t)ne * sizeof(float) + 1);
    for (k = 0; k < ne; ++k)
        if (esharp[k] > 0.0f) {
            m->cv[2 * m->nc] = edges[2 * k];
            m->cv[2 * m->nc + 1] = edges[2 * k + 1];
            m->cs[m->nc++] = esharp[k];
        }
    free(edges);
    free(esharp);
    m->ncorner = rng_int(g, 4);
    m->corner = (int *)xmalloc(4 * sizeof(int));
    m->corner_s = (float *)xmalloc(4 * sizeof(float));
    for (k = 0; k < m->ncorner; ++k) {
        int v = rng_int(g, m->nv), x;
        for (x = 0; x < k; ++x)
            if (m->corner[x] == v) break;
        if (x < k) { --m->ncorner; --k; continue; } /* drop a repeat */
        m->corner[k] = v;
        m->corner_s[k] = k_sharpness[rng_int(g, 5)];
    }
    m->holes = (int *)xmalloc(sizeof(int));
    if (m->nf > 2 && rng_int(g, 4) == 0) m->holes[m->nholes++] = rng_int(g, m->nf);
    m->boundary = rng_int(g, 3);
    m->crease_method = rng_int(g, 2);
    m->tri_rule = rng_int(g, 2);
    m->uv_interp = rng_int(g, 2);
    snprintf(m->descr, sizeof m->descr,
             "%s %dx%d %s, %d faces, %d crease edges (%d lines), %d corners, %d holes, boundary %d, %s, tri %d, uv %d",
             torus ? "torus" : "grid", nu, nv, sfb_scheme_name(scheme), m->nf, m->nc, ncrease_lines, m->ncorner, m->nholes,
             m->boundary, m->crease_method ? "chaikin" : "uniform", m->tri_rule, m->uv_interp);
#undef VID
#undef UVID
}

static sfb_mesh_desc rmesh_desc(const rmesh *m) {
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = m->nv; d.positions = m->pos;
    d.face_count = m->nf; d.face_sizes = m->fs; d.face_vertices = m->fv;
    d.crease_count = m->nc; d.crease_vertices = m->cv; d.crease_sharpness = m->cs;
    d.corner_count = m->ncorner; d.corner_vertices = m->corner; d.corner_sharpness = m->corner_s;
    d.hole_count = m->nholes; d.holes = m->holes;
    d.uv_count = m->nuv; d.uvs = m->uv; d.face_uvs = m->fuv;
    d.boundary = m->boundary; d.crease_method = m->crease_method; d.triangle_rule = m->tri_rule; d.uv_interp = m->uv_interp;
    return d;
}

static void run_random(int cases) {
    int c;
    for (c = 0; c < cases; ++c) {
        rng g = rng_for(g_seed, (unsigned long long)c + 1);
        sfb_scheme scheme = (sfb_scheme)(c % 3 == 0 ? SFB_SCHEME_LOOP : c % 3 == 1 ? SFB_SCHEME_CATMARK : rng_int(&g, 3));
        rmesh m;
        sfb_mesh_desc d;
        sfb_mesh *mesh = NULL;
        char label[64], extra[400];
        int level;
        double faces;
        rmesh_generate(&g, scheme, &m);
        level = 1 + rng_int(&g, 3);
        faces = m.nf;
        while (level > 1 && faces * pow(4.0, level) > 40000.0) --level;
        snprintf(label, sizeof label, "%d", c);
        snprintf(extra, sizeof extra, "case %d: %s, level %d", c, m.descr, level);
        d = rmesh_desc(&m);
        if (sfb_mesh_create(g_ref, &d, &mesh) != SFB_SUCCESS) {
            char name[100];
            snprintf(name, sizeof name, "random/%d", c);
            fail(name, "sfb_mesh_create refused a generated mesh: %s; %s", sfb_last_error(g_ref), extra);
            rmesh_free(&m);
            continue;
        }
        if (g_verbose) printf("# random %s\n", extra);
        run_mesh("random", label, mesh, scheme, level, extra);
        sfb_mesh_destroy(mesh);
        rmesh_free(&m);
    }
}

/* ---- (c) buffer layouts ---- */

#define SENTINEL_BITS 0x7fc0beefu /* a NaN payload no kernel writes */

static float sentinel(void) {
    uint32_t u = SENTINEL_BITS;
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}
static int is_sentinel(float f) {
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u == SENTINEL_BITS;
}

/* One creased mesh for the layout and thread checks: a jittered torus of nu x nv quads with
 * crease lines, a corner and UVs. */
static sfb_mesh *layout_mesh(sfb_context *ctx, int nu, int nv, rmesh *keep) {
    rmesh *m = keep;
    int i, j, k;
    sfb_mesh_desc d;
    sfb_mesh *mesh = NULL;
    rng g = rng_for(g_seed, 0xABCDEFull + (unsigned long long)nu);
    memset(m, 0, sizeof *m);
    m->nv = nu * nv;
    m->pos = (float *)xmalloc((size_t)m->nv * 3 * sizeof(float));
    m->fs = (int *)xmalloc((size_t)nu * nv * sizeof(int));
    m->fv = (int *)xmalloc((size_t)nu * nv * 4 * sizeof(int));
    m->cv = (int *)xmalloc((size_t)(nu + nv) * 2 * sizeof(int));
    m->cs = (float *)xmalloc((size_t)(nu + nv) * sizeof(float));
    m->corner = (int *)xmalloc(sizeof(int));
    m->corner_s = (float *)xmalloc(sizeof(float));
    for (i = 0; i < nu; ++i)
        for (j = 0; j < nv; ++j) {
            double u = 6.283185307179586 * (i + rng_range(&g, -0.2, 0.2)) / nu, v = 6.283185307179586 * (j + rng_range(&g, -0.2, 0.2)) / nv;
            float *p = m->pos + 3 * (size_t)(i * nv + j);
            p[0] = (float)((3.0 + cos(v)) * cos(u));
            p[1] = (float)((3.0 + cos(v)) * sin(u));
            p[2] = (float)sin(v);
            m->fs[m->nf++] = 4;
            m->fv[m->nfv++] = i * nv + j;
            m->fv[m->nfv++] = ((i + 1) % nu) * nv + j;
            m->fv[m->nfv++] = ((i + 1) % nu) * nv + (j + 1) % nv;
            m->fv[m->nfv++] = i * nv + (j + 1) % nv;
        }
    for (i = 0; i < nu; ++i) { /* ring j = 0, sharpness 1.7 */
        m->cv[2 * m->nc] = i * nv;
        m->cv[2 * m->nc + 1] = ((i + 1) % nu) * nv;
        m->cs[m->nc++] = 1.7f;
    }
    for (k = 0; k < nv; ++k) { /* meridian i = 0, infinitely sharp */
        m->cv[2 * m->nc] = k;
        m->cv[2 * m->nc + 1] = (k + 1) % nv;
        m->cs[m->nc++] = 10.0f;
    }
    m->corner[0] = (nu / 2) * nv + nv / 2;
    m->corner_s[0] = 3.0f;
    m->ncorner = 1;
    d = rmesh_desc(m);
    if (sfb_mesh_create(ctx, &d, &mesh) != SFB_SUCCESS) return NULL;
    return mesh;
}

typedef struct layout { int src_off, src_pad, dst_off, dst_pad; const char *name; } layout;
static const layout k_layouts[3] = {
    {0, 0, 0, 0, "packed"},
    {5, 3, 2, 1, "offset+stride"},
    {1, 9, 7, 4, "interleaved"},
};

/* Evaluates `table` with src/dst in layout lo and length len on surface s; compares with ref's
 * packed result `want`; checks every dst float outside the written elements is still the
 * sentinel. Returns a failure message in msg (empty: pass). */
static void layout_check(const sfb_surface *s, sfb_context *ctx, sfb_table table, int sources, int rows, int len, const layout *lo,
                         const float *packed_src, const float *want, double tol, char *msg, size_t msz) {
    sfb_buffer_desc sd, dd;
    size_t ssize, dsize, i;
    float *src, *dst;
    int r, k;
    sfb_result res;
    cmp c;
    msg[0] = 0;
    sd.offset = lo->src_off; sd.length = len; sd.stride = len + lo->src_pad;
    dd.offset = lo->dst_off; dd.length = len; dd.stride = len + lo->dst_pad;
    /* src: exactly the span the view covers, nothing after the last element's last component,
     * so that a read past it is a heap overflow under AddressSanitizer (make asan) */
    ssize = (size_t)sd.offset + (size_t)(sources - 1) * sd.stride + (size_t)len;
    dsize = (size_t)dd.offset + (size_t)rows * dd.stride + 16; /* 16 floats of tail that must stay */
    src = (float *)xmalloc(ssize * sizeof(float));
    dst = (float *)xmalloc(dsize * sizeof(float));
    for (i = 0; i < ssize; ++i) src[i] = 1e30f; /* padding of src: must not be read into results */
    for (r = 0; r < sources; ++r)
        for (k = 0; k < len; ++k) src[sd.offset + (size_t)r * sd.stride + k] = packed_src[(size_t)r * len + k];
    for (i = 0; i < dsize; ++i) dst[i] = sentinel();
    res = sfb_surface_eval_stencils(s, table, src, sd, dst, dd);
    if (res != SFB_SUCCESS) {
        snprintf(msg, msz, "%s: sfb_surface_eval_stencils: %s: %s", table_name(table), sfb_result_string(res), sfb_last_error(ctx));
    } else {
        size_t bad_at = (size_t)-1;
        c = compare(want, dst, dd, rows, len, tol);
        for (i = 0; i < dsize && bad_at == (size_t)-1; ++i) {
            int inside = 0;
            if (i >= (size_t)dd.offset) {
                size_t rel = i - (size_t)dd.offset;
                inside = rel / (size_t)dd.stride < (size_t)rows && (int)(rel % (size_t)dd.stride) < len;
            }
            if (!inside && !is_sentinel(dst[i])) bad_at = i;
        }
        if (c.bad)
            snprintf(msg, msz, "%s: max |diff| %.3g > tol %.3g at row %d component %d (ref %.9g, got %.9g); src {%d,%d,%d} dst {%d,%d,%d}",
                     table_name(table), c.err, c.tol, c.row, c.comp, (double)c.want, (double)c.got, sd.offset, sd.length, sd.stride,
                     dd.offset, dd.length, dd.stride);
        else if (bad_at != (size_t)-1)
            snprintf(msg, msz, "%s: dst float %zu (outside the written elements: %s) was overwritten with %.9g; dst {%d,%d,%d}, %d rows",
                     table_name(table), bad_at,
                     bad_at < (size_t)dd.offset ? "before offset" : bad_at >= (size_t)dd.offset + (size_t)rows * dd.stride ? "after the last row" : "padding",
                     (double)dst[bad_at], dd.offset, dd.length, dd.stride, rows);
    }
    free(src);
    free(dst);
}

/* The layout checks' shared data: one mesh, ref's packed results per length and table. */
static const int k_lengths[6] = {1, 2, 3, 4, 7, 16};
static const sfb_table k_layout_tables[2] = {SFB_TABLE_VERTEX, SFB_TABLE_LIMIT};
typedef struct layout_ref {
    sfb_mesh *mesh;
    rmesh keep;
    sfb_surface_config cfg;
    sfb_stencil_info info[2];
    float *psrc[6], *want[6][2];
    double tol[6];
} layout_ref;

static int layout_ref_make(layout_ref *L) {
    sfb_surface *rs = NULL;
    int li, ti, k;
    rng g = rng_for(g_seed, 0x1A1A1Aull);
    memset(L, 0, sizeof *L);
    /* 12 x 8 quads at level 3: 6144 rows, about 10^5 entries, above the simd backend's
     * threshold for spreading one call over its threads */
    L->mesh = layout_mesh(g_ref, 12, 8, &L->keep);
    L->cfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, 3);
    L->cfg.flags = SFB_REFINE_LIMIT;
    if (!L->mesh || sfb_surface_create(g_ref, L->mesh, &L->cfg, &rs) != SFB_SUCCESS ||
        sfb_surface_stencil_info(rs, SFB_TABLE_VERTEX, &L->info[0]) != SFB_SUCCESS ||
        sfb_surface_stencil_info(rs, SFB_TABLE_LIMIT, &L->info[1]) != SFB_SUCCESS) {
        fail("layout", "ref could not build the layout mesh: %s", sfb_last_error(g_ref));
        sfb_surface_destroy(rs);
        return 0;
    }
    for (li = 0; li < 6; ++li) {
        int len = k_lengths[li], sources = L->info[0].sources;
        sfb_buffer_desc pd;
        L->psrc[li] = (float *)xmalloc((size_t)sources * len * sizeof(float));
        for (k = 0; k < sources * len; ++k) L->psrc[li][k] = (float)rng_range(&g, -100.0, 100.0);
        L->tol[li] = TOL_REL * max_abs(L->psrc[li], (size_t)sources * len);
        pd.offset = 0; pd.length = len; pd.stride = len;
        for (ti = 0; ti < 2; ++ti) {
            L->want[li][ti] = (float *)xmalloc((size_t)L->info[ti].rows * len * sizeof(float));
            if (sfb_surface_eval_stencils(rs, k_layout_tables[ti], L->psrc[li], pd, L->want[li][ti], pd) != SFB_SUCCESS) {
                fail("layout", "ref eval failed (length %d): %s", len, sfb_last_error(g_ref));
                sfb_surface_destroy(rs);
                return 0;
            }
        }
    }
    sfb_surface_destroy(rs);
    return 1;
}

static void layout_ref_free(layout_ref *L) {
    int li;
    for (li = 0; li < 6; ++li) { free(L->psrc[li]); free(L->want[li][0]); free(L->want[li][1]); }
    if (L->mesh) sfb_mesh_destroy(L->mesh);
    rmesh_free(&L->keep);
    memset(L, 0, sizeof *L);
}

/* All lengths x layouts on context ctx (its backend), checks named PREFIX/layout/lenN/LAYOUT.
 * b: the backend (for SKIP/FAIL when unavailable), NULL for ref and ready-made contexts. */
static void layout_target(const layout_ref *L, const char *prefix, sfb_context *ctx, const backend *b, int skip_packed) {
    sfb_surface *s = NULL;
    int li, lk, ti;
    char name[160];
    if (b && !b->available) {
        for (li = 0; li < 6; ++li)
            for (lk = 0; lk < 3; ++lk) {
                snprintf(name, sizeof name, "%s/layout/len%d/%s", prefix, k_lengths[li], k_layouts[lk].name);
                backend_missing(b, name);
            }
        return;
    }
    if (sfb_surface_create(ctx, L->mesh, &L->cfg, &s) != SFB_SUCCESS) {
        snprintf(name, sizeof name, "%s/layout", prefix);
        fail(name, "sfb_surface_create: %s", sfb_last_error(ctx));
        return;
    }
    for (li = 0; li < 6; ++li)
        for (lk = 0; lk < 3; ++lk) {
            char msg[600];
            if (skip_packed && lk == 0) continue;
            snprintf(name, sizeof name, "%s/layout/len%d/%s", prefix, k_lengths[li], k_layouts[lk].name);
            msg[0] = 0;
            for (ti = 0; ti < 2 && !msg[0]; ++ti)
                layout_check(s, ctx, k_layout_tables[ti], L->info[0].sources, L->info[ti].rows, k_lengths[li], &k_layouts[lk],
                             L->psrc[li], L->want[li][ti], L->tol[li], msg, sizeof msg);
            if (msg[0]) fail(name, "%s", msg);
            else pass(name);
        }
    sfb_surface_destroy(s);
}

static void run_layouts(void) {
    static const char *const isas[4] = {"portable", "sse2", "avx2", "avx512"};
    layout_ref L;
    int bi, k;
    if (!layout_ref_make(&L)) { layout_ref_free(&L); return; }
    layout_target(&L, "ref", g_ref, NULL, 1); /* the oracle honours the layouts too */
    for (bi = 0; bi < g_backend_count; ++bi) layout_target(&L, g_backends[bi].name, g_backends[bi].ctx, &g_backends[bi], 0);
    /* every simd kernel (SURFBLEND_SIMD_ISA forces one, read when the context is created),
     * with 2 threads: the partial loads and stores of each instruction set */
    for (k = 0; k < 4; ++k) {
        char prefix[64], info[256], name[100];
        sfb_context *ctx;
        snprintf(prefix, sizeof prefix, "simd-%s", isas[k]);
        if (!g_backends[0].available) {
            snprintf(name, sizeof name, "%s/layout", prefix);
            backend_missing(&g_backends[0], name);
            continue;
        }
        {
            const char *old = getenv("SURFBLEND_SIMD_ISA");
            char saved[64];
            snprintf(saved, sizeof saved, "%s", old ? old : "");
            setenv("SURFBLEND_SIMD_ISA", isas[k], 1);
            ctx = make_context_threads(SFB_BACKEND_SIMD, 2);
            if (old) setenv("SURFBLEND_SIMD_ISA", saved, 1);
            else unsetenv("SURFBLEND_SIMD_ISA");
        }
        snprintf(name, sizeof name, "%s/layout", prefix);
        if (!ctx) { fail(name, "no simd context with SURFBLEND_SIMD_ISA=%s", isas[k]); continue; }
        info[0] = 0;
        sfb_context_backend_info(ctx, info, sizeof info);
        if (strncmp(info, isas[k], strlen(isas[k])) != 0 || info[strlen(isas[k])] != ' ') {
            char why[400];
            snprintf(why, sizeof why, "this CPU or build has no %s kernel (the backend runs: %s)", isas[k], info);
            skip(name, why);
        } else {
            layout_target(&L, prefix, ctx, NULL, 0);
        }
        sfb_context_destroy(ctx);
    }
    layout_ref_free(&L);
}

/* ---- (d) simd threads, and concurrent callers ---- */

typedef struct call_job {
    const sfb_surface *s;
    const float *src;
    float *dst;
    int rows, reps;
    sfb_result r;
} call_job;

static void *call_thread(void *arg) {
    call_job *j = (call_job *)arg;
    sfb_buffer_desc bd;
    int k;
    bd.offset = 0; bd.length = 3; bd.stride = 3;
    j->r = SFB_SUCCESS;
    for (k = 0; k < j->reps && j->r == SFB_SUCCESS; ++k) j->r = sfb_surface_eval_stencils(j->s, SFB_TABLE_VERTEX, j->src, bd, j->dst, bd);
    return NULL;
}

/* simd/threads/patches-SCHEME: the simd patch upload packs its patches over the pool (from 2048
 * patches on): a Catmull-Clark surface of a triangulated torus (every patch a Stam one) and a
 * Loop one (Stam-Loop patches at its valence-4 and -8 vertices), each built on one thread and on
 * four, evaluate (position, first and second derivatives, normal) the same bit for bit at 20000
 * random locations, and (position, du, dv, normal) at 19999 of them; the table must be large
 * enough for the pool to be used. */
static void run_patch_threads(void) {
    backend *simd = NULL;
    int b, scheme;
    for (b = 0; b < g_backend_count; ++b)
        if (strcmp(g_backends[b].name, "simd") == 0) simd = &g_backends[b];
    for (scheme = 0; scheme < 2; ++scheme) {
        const char *name = scheme ? "simd/threads/patches-loop" : "simd/threads/patches-catmark";
        enum { NU = 48, NV = 32, NLOC = 20000 };
        char *obj;
        size_t used = 0, cap = (size_t)NU * NV * 80 + 64;
        sfb_mesh *mesh = NULL;
        float *out[2] = {NULL, NULL};
        sfb_location *loc = NULL;
        int i, j, t, npatch[2] = {0, 0}, ok = 1;
        rng g = rng_for(g_seed, 0x7A7Cull + (unsigned long long)scheme);
        if (!simd || !simd->available) {
            if (simd) backend_missing(simd, name);
            else skip(name, "no simd backend compiled in");
            continue;
        }
        /* a torus, every cell two triangles, the diagonals alternating (valences 4, 6 and 8) */
        obj = (char *)xmalloc(cap);
        for (i = 0; i < NU; ++i)
            for (j = 0; j < NV; ++j) {
                const double a = 2.0 * 3.14159265358979 * i / NU, c = 2.0 * 3.14159265358979 * j / NV, r = 1.0 + 0.35 * cos(c);
                used += (size_t)snprintf(obj + used, cap - used, "v %.6f %.6f %.6f\n", r * cos(a), r * sin(a), 0.35 * sin(c) + 0.01 * rng_int(&g, 7));
            }
        for (i = 0; i < NU; ++i)
            for (j = 0; j < NV; ++j) {
                const int v00 = i * NV + j + 1, v10 = ((i + 1) % NU) * NV + j + 1, v01 = i * NV + (j + 1) % NV + 1, v11 = ((i + 1) % NU) * NV + (j + 1) % NV + 1;
                if ((i + j) & 1) used += (size_t)snprintf(obj + used, cap - used, "f %d %d %d\nf %d %d %d\n", v00, v10, v11, v00, v11, v01);
                else used += (size_t)snprintf(obj + used, cap - used, "f %d %d %d\nf %d %d %d\n", v00, v10, v01, v10, v11, v01);
            }
        if (sfb_mesh_read_obj(g_ref, obj, used, &mesh) != SFB_SUCCESS) {
            fail(name, "the torus: %s", sfb_last_error(g_ref));
            free(obj);
            continue;
        }
        free(obj);
        loc = (sfb_location *)xmalloc(NLOC * sizeof *loc);
        for (t = 0; t < 2 && ok; ++t) {
            sfb_context *ctx = make_context_threads(SFB_BACKEND_SIMD, t ? 4 : 1);
            sfb_surface_config cfg = sfb_surface_config_init(scheme ? SFB_SCHEME_LOOP : SFB_SCHEME_CATMARK, 0);
            sfb_surface *s = NULL;
            sfb_patch_info pi;
            sfb_eval_output o;
            cfg.flags = SFB_REFINE_PATCHES;
            if (!ctx || sfb_surface_create(ctx, mesh, &cfg, &s) != SFB_SUCCESS || sfb_surface_patch_info(s, &pi) != SFB_SUCCESS) {
                fail(name, "threads %d: %s", t ? 4 : 1, ctx ? sfb_last_error(ctx) : "no simd context");
                ok = 0;
            } else {
                const int np = sfb_surface_param_face_count(s);
                npatch[t] = pi.patches;
                if (t == 0)
                    for (i = 0; i < NLOC; ++i) {
                        /* multiples of 1/1024: exact, so u + v <= 1 holds exactly on Loop's triangles */
                        const int a = rng_int(&g, 1025);
                        loc[i].face = rng_int(&g, np);
                        loc[i].u = (float)a / 1024.0f;
                        loc[i].v = (float)rng_int(&g, scheme ? 1025 - a : 1025) / 1024.0f;
                    }
                out[t] = (float *)xmalloc((size_t)NLOC * 33 * sizeof(float));
                o.position = out[t]; o.du = out[t] + 3 * NLOC; o.dv = out[t] + 6 * NLOC; o.normal = out[t] + 9 * NLOC;
                o.duu = out[t] + 12 * NLOC; o.duv = out[t] + 15 * NLOC; o.dvv = out[t] + 18 * NLOC;
                if (sfb_surface_eval(s, loc, NLOC, &o) != SFB_SUCCESS) { fail(name, "eval: %s", sfb_last_error(ctx)); ok = 0; }
                /* without second derivatives (avx2, avx512: triangles two at a time in float),
                 * NLOC - 1 locations: the pool's chunks then start at odd places */
                memset(&o, 0, sizeof o);
                o.position = out[t] + 21 * NLOC; o.du = out[t] + 24 * NLOC; o.dv = out[t] + 27 * NLOC; o.normal = out[t] + 30 * NLOC;
                memset(out[t] + 21 * NLOC, 0, (size_t)NLOC * 12 * sizeof(float));
                if (ok && sfb_surface_eval(s, loc, NLOC - 1, &o) != SFB_SUCCESS) { fail(name, "eval: %s", sfb_last_error(ctx)); ok = 0; }
            }
            sfb_surface_destroy(s);
            if (ctx) sfb_context_destroy(ctx);
        }
        if (ok) {
            /* and without second derivatives against ref (the float kernels: avx2 and avx512 two
             * triangles at a time, neon one): positions within 2e-7 of the diagonal (measured
             * 4e-8), du and dv within 5e-4 of their length and normals within 5e-4 rad (measured
             * 1.2e-4 and 1.2e-4 rad, 6e-5 with the double kernels: the Stam-Loop sub-patches near
             * the extraordinary vertices, whose points simd stores in float) */
            sfb_surface_config cfg = sfb_surface_config_init(scheme ? SFB_SCHEME_LOOP : SFB_SCHEME_CATMARK, 0);
            sfb_surface *rs = NULL;
            sfb_eval_output ro;
            float *ref = (float *)xmalloc((size_t)NLOC * 12 * sizeof(float));
            char nm[96];
            snprintf(nm, sizeof nm, "%s/first_derivatives_vs_ref", name);
            cfg.flags = SFB_REFINE_PATCHES;
            memset(&ro, 0, sizeof ro);
            ro.position = ref; ro.du = ref + 3 * NLOC; ro.dv = ref + 6 * NLOC; ro.normal = ref + 9 * NLOC;
            if (sfb_surface_create(g_ref, mesh, &cfg, &rs) != SFB_SUCCESS || sfb_surface_eval(rs, loc, NLOC - 1, &ro) != SFB_SUCCESS) {
                fail(nm, "ref: %s", sfb_last_error(g_ref));
            } else {
                const float *got = out[0] + 21 * NLOC;
                double worst_p = 0.0, worst_d = 0.0, worst_n = 0.0;
                const double diag = bbox_diag(ref, NLOC - 1, 3);
                for (i = 0; i < NLOC - 1; ++i) {
                    double dp = 0.0, du2 = 0.0, dv2 = 0.0, lu = 0.0, lv = 0.0, dot = 0.0, cr[3];
                    int c;
                    for (c = 0; c < 3; ++c) {
                        const double ep = (double)got[3 * i + c] - ref[3 * i + c];
                        const double eu = (double)got[3 * NLOC + 3 * i + c] - ref[3 * NLOC + 3 * i + c];
                        const double ev = (double)got[6 * NLOC + 3 * i + c] - ref[6 * NLOC + 3 * i + c];
                        dp += ep * ep; du2 += eu * eu; dv2 += ev * ev;
                        lu += (double)ref[3 * NLOC + 3 * i + c] * ref[3 * NLOC + 3 * i + c];
                        lv += (double)ref[6 * NLOC + 3 * i + c] * ref[6 * NLOC + 3 * i + c];
                        dot += (double)got[9 * NLOC + 3 * i + c] * ref[9 * NLOC + 3 * i + c];
                    }
                    cr[0] = (double)got[9 * NLOC + 3 * i + 1] * ref[9 * NLOC + 3 * i + 2] - (double)got[9 * NLOC + 3 * i + 2] * ref[9 * NLOC + 3 * i + 1];
                    cr[1] = (double)got[9 * NLOC + 3 * i + 2] * ref[9 * NLOC + 3 * i + 0] - (double)got[9 * NLOC + 3 * i + 0] * ref[9 * NLOC + 3 * i + 2];
                    cr[2] = (double)got[9 * NLOC + 3 * i + 0] * ref[9 * NLOC + 3 * i + 1] - (double)got[9 * NLOC + 3 * i + 1] * ref[9 * NLOC + 3 * i + 0];
                    worst_p = fmax(worst_p, sqrt(dp) / diag);
                    worst_d = fmax(worst_d, fmax(sqrt(du2 / (lu + 1e-30)), sqrt(dv2 / (lv + 1e-30))));
                    worst_n = fmax(worst_n, atan2(sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]), dot));
                }
                check(worst_p <= 2e-7 && worst_d <= 5e-4 && worst_n <= 5e-4, nm,
                      "largest differences: position %.3g x diagonal, du/dv %.3g of their length, normal %.3g rad", worst_p, worst_d, worst_n);
            }
            sfb_surface_destroy(rs);
            free(ref);
        }
        if (ok) {
            const int same = memcmp(out[0], out[1], (size_t)NLOC * 21 * sizeof(float)) == 0;
            const int same1 = memcmp(out[0] + 21 * NLOC, out[1] + 21 * NLOC, (size_t)NLOC * 12 * sizeof(float)) == 0;
            check(npatch[0] >= 2048 && npatch[0] == npatch[1] && same && same1, name,
                  "%d and %d patches (the pool packs from 2048 on); evaluations %s, without second derivatives %s", npatch[0], npatch[1],
                  same ? "the same" : "DIFFER between 1 and 4 threads", same1 ? "the same" : "DIFFER between 1 and 4 threads");
        }
        free(out[0]); free(out[1]); free(loc);
        sfb_mesh_destroy(mesh);
    }
}

static void run_threads(void) {
    static const int thread_counts[3] = {1, 2, 0};
    const backend *simd = &g_backends[0];
    rmesh keep;
    sfb_mesh *mesh;
    sfb_mesh_desc d;
    sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, 3);
    sfb_surface *rs = NULL;
    table_out want[SFB_TABLE_COUNT_];
    double diag, tol[SFB_TABLE_COUNT_];
    char err[600];
    int ti, t;
    if (!simd->available) {
        for (ti = 0; ti < 3; ++ti) {
            char name[64];
            snprintf(name, sizeof name, "simd/threads/%d", thread_counts[ti]);
            backend_missing(simd, name);
        }
        backend_missing(simd, "simd/threads/concurrent-calls");
        return;
    }
    mesh = layout_mesh(g_ref, 48, 32, &keep); /* 1536 quads -> 98304 at level 3 */
    cfg.flags = SFB_REFINE_LIMIT;
    if (!mesh || sfb_surface_create(g_ref, mesh, &cfg, &rs) != SFB_SUCCESS) {
        fail("simd/threads", "ref could not build the thread-test mesh: %s", sfb_last_error(g_ref));
        if (mesh) sfb_mesh_destroy(mesh);
        rmesh_free(&keep);
        return;
    }
    sfb_mesh_get_desc(mesh, &d);
    diag = bbox_diag(d.positions, d.vertex_count, 3);
    if (eval_all(rs, &d, want, err, sizeof err, g_ref) != SFB_SUCCESS) fail("simd/threads", "ref: %s", err);
    for (t = 0; t < SFB_TABLE_COUNT_; ++t) tol[t] = want[t].built ? table_tol((sfb_table)t, diag, 0.0, &want[t]) : 0.0;
    for (ti = 0; ti < 3; ++ti) {
        char name[64], fails[1500];
        size_t used = 0;
        sfb_context *ctx = make_context_threads(SFB_BACKEND_SIMD, thread_counts[ti]);
        sfb_surface *s = NULL;
        table_out got[SFB_TABLE_COUNT_];
        snprintf(name, sizeof name, "simd/threads/%d", thread_counts[ti]);
        if (!ctx || strcmp(sfb_context_backend_name(ctx), "simd") != 0) {
            fail(name, "no simd context with threads = %d", thread_counts[ti]);
            if (ctx) sfb_context_destroy(ctx);
            continue;
        }
        if (g_verbose) {
            char info[256];
            sfb_context_backend_info(ctx, info, sizeof info);
            printf("# simd threads=%d: %s\n", thread_counts[ti], info);
        }
        if (sfb_surface_create(ctx, mesh, &cfg, &s) != SFB_SUCCESS) {
            fail(name, "sfb_surface_create: %s", sfb_last_error(ctx));
            sfb_context_destroy(ctx);
            continue;
        }
        fails[0] = 0;
        if (eval_all(s, &d, got, err, sizeof err, ctx) != SFB_SUCCESS) {
            snprintf(fails, sizeof fails, "%s", err);
        } else {
            for (t = 0; t < SFB_TABLE_COUNT_; ++t) {
                sfb_buffer_desc gd;
                cmp c;
                if (!want[t].built) continue;
                gd.offset = 0; gd.length = 3; gd.stride = 3;
                c = compare(want[t].data, got[t].data, gd, want[t].rows, 3, tol[t]);
                if (c.bad) {
                    used += (size_t)snprintf(fails + used, sizeof fails - used, "%s%s: max |diff| %.3g > tol %.3g at row %d", used ? "; " : "",
                                             table_name((sfb_table)t), c.err, c.tol, c.row);
                    if (used >= sizeof fails) used = sizeof fails - 1;
                }
            }
        }
        if (fails[0]) fail(name, "%s", fails);
        else pass(name);
        free_all(got);
        /* several application threads on the one surface (documented as safe for simd) */
        if (thread_counts[ti] == 2) {
            enum { NCALLERS = 4 };
            pthread_t th[NCALLERS];
            call_job jobs[NCALLERS];
            int k, started = 0;
            fails[0] = 0;
            memset(jobs, 0, sizeof jobs);
            for (k = 0; k < NCALLERS; ++k) {
                jobs[k].s = s;
                jobs[k].src = d.positions;
                jobs[k].rows = want[SFB_TABLE_VERTEX].rows;
                jobs[k].reps = 3;
                jobs[k].dst = (float *)xmalloc((size_t)jobs[k].rows * 3 * sizeof(float));
                jobs[k].r = SFB_SUCCESS;
                if (pthread_create(&th[k], NULL, call_thread, &jobs[k]) == 0) ++started;
                else { jobs[k].r = SFB_BACKEND_ERROR; break; }
            }
            for (k = 0; k < started; ++k) pthread_join(th[k], NULL);
            for (k = 0; k < NCALLERS && !fails[0]; ++k) {
                sfb_buffer_desc gd;
                cmp c;
                if (k >= started || jobs[k].r != SFB_SUCCESS) {
                    snprintf(fails, sizeof fails, "caller %d: %s", k, k >= started ? "pthread_create failed" : sfb_result_string(jobs[k].r));
                    break;
                }
                gd.offset = 0; gd.length = 3; gd.stride = 3;
                c = compare(want[SFB_TABLE_VERTEX].data, jobs[k].dst, gd, jobs[k].rows, 3, tol[SFB_TABLE_VERTEX]);
                if (c.bad) snprintf(fails, sizeof fails, "caller %d: max |diff| %.3g > tol %.3g at row %d", k, c.err, c.tol, c.row);
            }
            for (k = 0; k < NCALLERS; ++k) free(jobs[k].dst);
            if (fails[0]) fail("simd/threads/concurrent-calls", "%s", fails);
            else pass("simd/threads/concurrent-calls");
        }
        sfb_surface_destroy(s);
        sfb_context_destroy(ctx);
    }
    free_all(want);
    sfb_surface_destroy(rs);
    sfb_mesh_destroy(mesh);
    rmesh_free(&keep);
}

/* ---- selection, environment, unsupported calls ---- */

static void run_eval_gl_unsupported(void) {
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    static const int fs[1] = {4}, fv[4] = {0, 1, 2, 3};
    sfb_mesh_desc d;
    sfb_mesh *mesh = NULL;
    sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, 1);
    sfb_buffer_desc bd = {0, 3, 3};
    int i;
    memset(&d, 0, sizeof d);
    d.vertex_count = 4; d.positions = pos; d.face_count = 1; d.face_sizes = fs; d.face_vertices = fv;
    if (sfb_mesh_create(g_ref, &d, &mesh) != SFB_SUCCESS) { fail("eval_gl", "mesh: %s", sfb_last_error(g_ref)); return; }
    for (i = -1; i < g_backend_count; ++i) {
        const char *bname = i < 0 ? "ref" : g_backends[i].name;
        sfb_context *ctx = i < 0 ? g_ref : g_backends[i].ctx;
        sfb_surface *s = NULL;
        char name[64];
        sfb_result r;
        snprintf(name, sizeof name, "%s/eval_gl-unsupported", bname);
        if (i >= 0 && !g_backends[i].available) { backend_missing(&g_backends[i], name); continue; }
        if (sfb_surface_create(ctx, mesh, &cfg, &s) != SFB_SUCCESS) { fail(name, "surface: %s", sfb_last_error(ctx)); continue; }
        /* buffer names 1 and 2 mean nothing here: the call must refuse before touching GL */
        r = sfb_surface_eval_stencils_gl(s, SFB_TABLE_VERTEX, 1u, bd, 2u, bd);
        if (r != SFB_UNSUPPORTED)
            fail(name, "sfb_surface_eval_stencils_gl on a %s context without gl_use_current_context returned %s, want SFB_UNSUPPORTED",
                       bname, sfb_result_string(r));
        else
            pass(name);
        sfb_surface_destroy(s);
    }
    sfb_mesh_destroy(mesh);
}

static void run_environment(void) {
    sfb_context_config cfg;
    sfb_context *ctx = NULL;
    char rep[2048];
    sfb_result r;
    int i;

    /* SURFBLEND_BACKEND names nothing: still a context, on the default order, report says unknown */
    setenv("SURFBLEND_BACKEND", "bogus", 1);
    cfg = sfb_context_config_init();
    r = sfb_context_create(&cfg, &ctx);
    unsetenv("SURFBLEND_BACKEND");
    if (r != SFB_SUCCESS) {
        fail("env/bogus", "sfb_context_create with SURFBLEND_BACKEND=bogus: %s", sfb_result_string(r));
    } else {
        rep[0] = 0;
        sfb_context_backend_report(ctx, rep, sizeof rep);
        if (!strstr(rep, "unknown") || !strstr(rep, "bogus"))
            fail("env/bogus", "report does not name the unknown backend 'bogus': %s", rep);
        else if (strcmp(sfb_context_backend_name(ctx), "none") == 0)
            fail("env/bogus", "no backend selected: %s", rep);
        else
            pass("env/bogus");
        sfb_context_destroy(ctx);
        ctx = NULL;
    }

    /* The same variable is ignored with ignore_environment. */
    setenv("SURFBLEND_BACKEND", "bogus", 1);
    cfg = sfb_context_config_init();
    cfg.ignore_environment = 1;
    r = sfb_context_create(&cfg, &ctx);
    unsetenv("SURFBLEND_BACKEND");
    if (r != SFB_SUCCESS) {
        fail("env/ignored", "sfb_context_create: %s", sfb_result_string(r));
    } else {
        rep[0] = 0;
        sfb_context_backend_report(ctx, rep, sizeof rep);
        if (strstr(rep, "bogus")) fail("env/ignored", "ignore_environment = 1 but the report mentions SURFBLEND_BACKEND: %s", rep);
        else pass("env/ignored");
        sfb_context_destroy(ctx);
        ctx = NULL;
    }

    /* A backend that cannot initialise, forced first: the gl backend asked to use the current
     * context when this thread has none is one everywhere; so is every backend the probe
     * found unavailable. Each must be reported as unavailable with a reason and fall to ref. */
    for (i = -1; i < g_backend_count; ++i) {
        sfb_backend_kind order[2];
        char name[64], line_start[64];
        const char *line, *reason;
        int via_env;
        for (via_env = 0; via_env < 2; ++via_env) {
            sfb_backend_kind kind = i < 0 ? SFB_BACKEND_GL : g_backends[i].kind;
            const char *bname = sfb_backend_kind_name(kind);
            if (i >= 0 && (g_backends[i].available || g_backends[i].excluded)) break;
            snprintf(name, sizeof name, "forced/%s%s%s", bname, i < 0 ? "-current-context-without-one" : "", via_env ? "/env" : "");
            cfg = sfb_context_config_init();
            if (i < 0) cfg.gl_use_current_context = 1;
            if (via_env) {
                order[0] = SFB_BACKEND_REF;
                cfg.backends = order;
                cfg.backend_count = 1;
                setenv("SURFBLEND_BACKEND", bname, 1);
            } else {
                order[0] = kind;
                order[1] = SFB_BACKEND_REF;
                cfg.backends = order;
                cfg.backend_count = 2;
                cfg.ignore_environment = 1;
            }
            ctx = NULL;
            r = sfb_context_create(&cfg, &ctx);
            if (via_env) unsetenv("SURFBLEND_BACKEND");
            if (r != SFB_SUCCESS) {
                fail(name, "sfb_context_create returned %s (want a fallback to ref)", sfb_result_string(r));
                continue;
            }
            rep[0] = 0;
            sfb_context_backend_report(ctx, rep, sizeof rep);
            snprintf(line_start, sizeof line_start, "%s: unavailable (", bname);
            line = strstr(rep, line_start);
            reason = line ? line + strlen(line_start) : NULL;
            if (strcmp(sfb_context_backend_name(ctx), "ref") != 0)
                fail(name, "selected %s, want ref; report: %s", sfb_context_backend_name(ctx), rep);
            else if (!reason || *reason == ')' || *reason == '\n' || *reason == 0)
                fail(name, "report lacks \"%s<reason>)\": %s", line_start, rep);
            else
                pass(name);
            if (g_verbose) printf("# %s report: %s", name, rep);
            sfb_context_destroy(ctx);
        }
    }
}

/* ---- main ---- */

int main(int argc, char **argv) {
    const char *shapes = NULL, *seed = NULL;
    int cases = 36, i;
    double t0 = now_s(), t;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) seed = argv[++i];
        else if (strcmp(argv[i], "--cases") == 0 && i + 1 < argc) cases = atoi(argv[++i]);
        else if (strcmp(argv[i], "--l3-faces") == 0 && i + 1 < argc) g_l3_max_faces = atoi(argv[++i]);
        else if (strcmp(argv[i], "--verbose") == 0) g_verbose = 1;
        else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc) g_only = argv[++i];
        else if (argv[i][0] == '-') {
            fprintf(stderr, "usage: agree [SHAPES_DIR] [--seed S] [--cases N] [--l3-faces N] [--only simd,gl,osmesa] [--verbose]\n");
            return 2;
        } else shapes = argv[i];
    }
    harness_seed(seed);
    printf("# seed %llu (rerun with --seed %llu or SFB_SEED=%llu)\n", g_seed, g_seed, g_seed);
    if (getenv("SFB_REQUIRE_BACKENDS")) printf("# SFB_REQUIRE_BACKENDS=%s\n", getenv("SFB_REQUIRE_BACKENDS"));

    setup_backends();
    if (!g_ref) {
        fail("ref", "cannot create a ref context");
        return close_tests();
    }
    t = now_s();
    run_environment();
    run_eval_gl_unsupported();
    run_layouts();
    if (g_verbose) printf("# layouts: %.1f s\n", now_s() - t);
    t = now_s();
    run_threads();
    run_patch_threads();
    if (g_verbose) printf("# threads: %.1f s\n", now_s() - t);
    t = now_s();
    run_random(cases);
    if (g_verbose) printf("# random: %.1f s\n", now_s() - t);
    t = now_s();
    run_shapes(shapes);
    if (g_verbose) printf("# shapes: %.1f s\n", now_s() - t);

    for (i = 0; i < g_backend_count; ++i)
        if (g_backends[i].ctx) sfb_context_destroy(g_backends[i].ctx);
    sfb_context_destroy(g_ref);
    printf("# total %.1f s\n", now_s() - t0);
    return close_tests();
}
