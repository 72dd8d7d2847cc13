/* surfblend benchmark against OpenSubdiv 3.5 (uniform Catmull-Clark refinement, stencil tables).
 *
 * The mesh is generated here: a torus of 100 x 60 quads with creases (two semi-sharp rings,
 * two semi-sharp meridians, one infinitely sharp ring and a corner). For levels 1..4 it measures
 * (median of several runs, std::chrono::steady_clock):
 *   build:  surfblend  sfb_mesh_create + sfb_surface_create(refine_level L)
 *           OpenSubdiv TopologyRefinerFactory::Create + RefineUniform(L) + StencilTableFactory::Create
 *                      (base vertices straight to level L: generateIntermediateLevels = false)
 *   apply:  surfblend  sfb_surface_eval_stencils(SFB_TABLE_VERTEX) on the context's backend
 *           OpenSubdiv Osd::CpuEvaluator::EvalStencils (single thread)
 * and checks that both give the same refined points (matched as point sets: the vertex orders
 * of the two libraries differ).
 *
 * Then stencil evaluation alone, positions (length 3), Catmull-Clark level 4 of the same torus,
 * on every surfblend backend beside OpenSubdiv's evaluators, all in this run:
 *   surfblend  ref; simd with 1 thread and with all threads (threads = 0); gl on its own
 *              headless EGL context (CPU copies in and out); osmesa (CPU copies); and gl on an
 *              EGL context this program makes and makes current (gl_use_current_context = 1),
 *              both GL buffer to GL buffer (sfb_surface_eval_stencils_gl + glFinish) and with
 *              CPU copies (sfb_surface_eval_stencils)
 *   OpenSubdiv Osd::CpuEvaluator, Osd::OmpEvaluator (as many threads as simd's "all"), and
 *              Osd::GLComputeEvaluator (Osd::GLStencilTableSSBO, Osd::GLVertexBuffer) on the same
 *              EGL context, + glFinish
 * Each: the best (minimum) of N runs after warm-up runs, in milliseconds, with the ratio to
 * OpenSubdiv's CpuEvaluator and to ref measured in the same run, and the difference from ref
 * (OpenSubdiv's points matched as point sets). A backend that cannot run here prints
 * "unavailable: why".
 *
 * Then limit evaluation (SFB_REFINE_PATCHES) on a variant of the torus with extraordinary
 * vertices (quads split into triangles: valence 5; quad pairs merged into hexagons: valence 3;
 * some on the semi-sharp and the infinitely sharp ring; same creases and corner):
 *   patch build  surfblend  sfb_mesh_create + sfb_surface_create(level 0, SFB_REFINE_PATCHES),
 *                           and memory from sfb_surface_patch_info
 *                OpenSubdiv TopologyRefinerFactory::Create + RefineAdaptive (the isolation of
 *                           PatchTableFactory::Options, 10) + PatchTableFactory::Create (default
 *                           options: Gregory basis end caps); then with PatchMap, the stencil
 *                           table of all levels + AppendLocalPointStencilTable and EvalStencils
 *                           (what evaluation needs), and memory (patch indices and params,
 *                           stencils, points); also with useInfSharpPatch (not the default)
 *   limit eval   1M random (parametric face, u, v), fixed seed, position + du + dv:
 *                surfblend  sfb_surface_eval (locating included) on ref, simd 1 thread and all
 *                           threads, gl (own EGL context), osmesa; a backend without an
 *                           eval_patches kernel (the library then runs ref's) is "skipped"
 *                OpenSubdiv Far::PatchMap::FindPatch + Osd::CpuEvaluator::EvalPatches, and
 *                           EvalPatches alone; the same with Osd::OmpEvaluator
 *   tessellate   sfb_surface_tessellate at rate 8 on ref and simd (triangles per second)
 * The same again for Loop on that torus cut into triangles (OpenSubdiv: its Loop patch table,
 * Gregory triangle end caps).
 * Best of 3 runs after one warm-up (builds: median of 3). `bench --limit` runs this part alone.
 */
#include "surfblend.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include "tests/egl_host.h"
#include "examples/fillet_shapes.h"

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/osd/bufferDescriptor.h>
#include <opensubdiv/osd/cpuEvaluator.h>
#include <opensubdiv/osd/cpuPatchTable.h>
#include <opensubdiv/osd/cpuVertexBuffer.h>
#include <opensubdiv/osd/glComputeEvaluator.h>
#include <opensubdiv/osd/glVertexBuffer.h>
#include <opensubdiv/osd/ompEvaluator.h>

#include <algorithm>
#include <initializer_list>
#include <map>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

using namespace OpenSubdiv;

/* Exported by libosdGPU but declared in no public header: OpenSubdiv's GL evaluators need it
 * called once with a context current (shared/peers/README.md). */
namespace OpenSubdiv {
namespace internal {
namespace GLLoader {
bool libraryInitializeGL();
}
}
}

typedef std::chrono::steady_clock Clock;

static double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/* The whole file as text; false when it cannot be opened. */
static bool read_text(const char *path, std::string *text) {
    FILE *f = fopen(path, "rb");
    if (!f) return false;
    char buf[65536];
    size_t n;
    text->clear();
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) text->append(buf, n);
    fclose(f);
    return true;
}

static double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return (n % 2) ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* ---- the test mesh ---- */

struct TorusMesh {
    int nu, nv;
    std::vector<float> positions;
    std::vector<int> face_sizes, face_vertices;
    std::vector<int> crease_vertices;
    std::vector<float> crease_sharpness;
    std::vector<int> corner_vertices;
    std::vector<float> corner_sharpness;

    int vid(int i, int j) const { return ((i + nu) % nu) * nv + ((j + nv) % nv); }

    /* Any mesh (nu = nv = 0), a copy of desc's arrays: for OpenSubdiv beside surfblend on meshes
     * read from files (the tribezier section's real meshes). */
    TorusMesh() : nu(0), nv(0) {}
    void assign(const sfb_mesh_desc &d) {
        size_t nfv = 0;
        for (int f = 0; f < d.face_count; ++f) nfv += (size_t)d.face_sizes[f];
        positions.assign(d.positions, d.positions + 3 * (size_t)d.vertex_count);
        face_sizes.assign(d.face_sizes, d.face_sizes + d.face_count);
        face_vertices.assign(d.face_vertices, d.face_vertices + nfv);
        crease_vertices.assign(d.crease_vertices, d.crease_vertices + 2 * (size_t)d.crease_count);
        crease_sharpness.assign(d.crease_sharpness, d.crease_sharpness + d.crease_count);
        corner_vertices.assign(d.corner_vertices, d.corner_vertices + d.corner_count);
        corner_sharpness.assign(d.corner_sharpness, d.corner_sharpness + d.corner_count);
    }

    /* extraordinary = true: the variant for limit evaluation (see make_extraordinary) */
    TorusMesh(int nu_, int nv_, bool extraordinary = false) : nu(nu_), nv(nv_) {
        const double R = 3.0, r = 1.0, two_pi = 6.283185307179586;
        for (int i = 0; i < nu; ++i)
            for (int j = 0; j < nv; ++j) {
                double u = two_pi * i / nu, v = two_pi * j / nv;
                /* a little unevenness so that no two refined points coincide by symmetry alone */
                double rr = r * (1.0 + 0.05 * std::sin(3.0 * u) * std::cos(2.0 * v));
                positions.push_back((float)((R + rr * std::cos(v)) * std::cos(u)));
                positions.push_back((float)((R + rr * std::cos(v)) * std::sin(u)));
                positions.push_back((float)(rr * std::sin(v)));
            }
        for (int i = 0; i < nu; ++i)
            for (int j = 0; j < nv; ++j) {
                face_sizes.push_back(4);
                face_vertices.push_back(vid(i, j));
                face_vertices.push_back(vid(i + 1, j));
                face_vertices.push_back(vid(i + 1, j + 1));
                face_vertices.push_back(vid(i, j + 1));
            }
        /* rings: edges (i,j)-(i+1,j) for fixed j */
        add_ring(0, 1.5f);
        add_ring(nv / 3, 2.5f);
        add_ring(2 * nv / 3, SFB_SHARPNESS_INFINITE);
        /* meridians: edges (i,j)-(i,j+1) for fixed i */
        add_meridian(0, 1.5f);
        add_meridian(nu / 2, 2.5f);
        corner_vertices.push_back(vid(nu / 4, nv / 2));
        corner_sharpness.push_back(2.0f);
        if (extraordinary) make_extraordinary();
    }
    /* Extraordinary vertices on the same creased torus (meant for nu = 100, nv = 60):
     * - quads (i,j) with i % 8 == 3 and j % 5 == 2, and j = 19 and 39 (touching the semi-sharp
     *   ring j = 20 and the infinitely sharp ring j = 40), split by a diagonal into two
     *   triangles: both ends of the diagonal get valence 5 (on the rings: crease vertices with
     *   an extraordinary sector);
     * - quad pairs (i,j), (i,j+1) with i % 8 == 7 and j % 6 == 4 merged into a hexagon (the
     *   shared edge, never a crease, removed): its two ends get valence 3.
     * Creases and the corner are kept (no creased edge is removed). */
    void make_extraordinary() {
        std::vector<int> sizes, fv;
        for (int i = 0; i < nu; ++i)
            for (int j = 0; j < nv; ++j) {
                int a = vid(i, j), b = vid(i + 1, j), c = vid(i + 1, j + 1), d = vid(i, j + 1);
                bool split = i % 8 == 3 && (j % 5 == 2 || j == 19 || j == 39);
                bool merge_first = i % 8 == 7 && j % 6 == 4 && j + 1 < nv, merge_second = i % 8 == 7 && j % 6 == 5;
                if (split && (i + j) % 2 == 0) {
                    int t[6] = {a, b, c, a, c, d};
                    sizes.push_back(3); sizes.push_back(3);
                    fv.insert(fv.end(), t, t + 6);
                } else if (split) {
                    int t[6] = {a, b, d, b, c, d};
                    sizes.push_back(3); sizes.push_back(3);
                    fv.insert(fv.end(), t, t + 6);
                } else if (merge_first) {
                    int h[6] = {a, b, c, vid(i + 1, j + 2), vid(i, j + 2), d};
                    sizes.push_back(6);
                    fv.insert(fv.end(), h, h + 6);
                } else if (!merge_second) {
                    int q[4] = {a, b, c, d};
                    sizes.push_back(4);
                    fv.insert(fv.end(), q, q + 4);
                }
            }
        face_sizes.swap(sizes);
        face_vertices.swap(fv);
    }
    /* Loop's variant: every face cut into triangles (quads by the diagonal (a,c), a regular
     * valence-6 lattice; hexagons fanned from their first vertex), creases and corner kept. The
     * extraordinary variant's triangles and hexagon fans leave vertices of valence 3 to 9. */
    void triangulate() {
        std::vector<int> sizes, fv;
        for (size_t f = 0, o = 0; f < face_sizes.size(); o += (size_t)face_sizes[f], ++f)
            for (int k = 1; k + 1 < face_sizes[f]; ++k) {
                sizes.push_back(3);
                fv.push_back(face_vertices[o]);
                fv.push_back(face_vertices[o + (size_t)k]);
                fv.push_back(face_vertices[o + (size_t)k + 1]);
            }
        face_sizes.swap(sizes);
        face_vertices.swap(fv);
    }
    void add_ring(int j, float s) {
        for (int i = 0; i < nu; ++i) {
            crease_vertices.push_back(vid(i, j));
            crease_vertices.push_back(vid(i + 1, j));
            crease_sharpness.push_back(s);
        }
    }
    void add_meridian(int i, float s) {
        for (int j = 0; j < nv; ++j) {
            crease_vertices.push_back(vid(i, j));
            crease_vertices.push_back(vid(i, j + 1));
            crease_sharpness.push_back(s);
        }
    }
    int vertex_count() const { return (int)positions.size() / 3; }
    int face_count() const { return (int)face_sizes.size(); }
    int crease_count() const { return (int)crease_sharpness.size(); }

    sfb_mesh_desc sfb_desc() const {
        sfb_mesh_desc d;
        memset(&d, 0, sizeof d);
        d.vertex_count = vertex_count();
        d.positions = &positions[0];
        d.face_count = face_count();
        d.face_sizes = &face_sizes[0];
        d.face_vertices = &face_vertices[0];
        d.crease_count = crease_count();
        d.crease_vertices = crease_vertices.data();
        d.crease_sharpness = crease_sharpness.data();
        d.corner_count = (int)corner_vertices.size();
        d.corner_vertices = corner_vertices.data();
        d.corner_sharpness = corner_sharpness.data();
        d.boundary = SFB_BOUNDARY_EDGE_ONLY;
        d.crease_method = SFB_CREASE_UNIFORM;
        d.triangle_rule = SFB_TRI_CATMARK;
        return d;
    }
    Far::TopologyDescriptor osd_desc() const {
        Far::TopologyDescriptor d;
        d.numVertices = vertex_count();
        d.numFaces = face_count();
        d.numVertsPerFace = &face_sizes[0];
        d.vertIndicesPerFace = &face_vertices[0];
        d.numCreases = crease_count();
        d.creaseVertexIndexPairs = crease_vertices.data();
        d.creaseWeights = crease_sharpness.data();
        d.numCorners = (int)corner_vertices.size();
        d.cornerVertexIndices = corner_vertices.data();
        d.cornerWeights = corner_sharpness.data();
        return d;
    }
};

/* ---- OpenSubdiv ---- */

static Far::StencilTable const *osd_build(const TorusMesh &m, int level) {
    Far::TopologyDescriptor desc = m.osd_desc();
    Sdc::Options opt;
    opt.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    opt.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
    opt.SetTriangleSubdivision(Sdc::Options::TRI_SUB_CATMARK);
    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
    Far::TopologyRefiner *r = Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, opt));
    if (!r) return NULL;
    r->RefineUniform(Far::TopologyRefiner::UniformOptions(level));
    Far::StencilTableFactory::Options so;
    so.interpolationMode = Far::StencilTableFactory::INTERPOLATE_VERTEX;
    so.generateIntermediateLevels = false;
    so.generateOffsets = true;
    Far::StencilTable const *t = Far::StencilTableFactory::Create(*r, so);
    delete r;
    return t;
}

static void osd_apply(const Far::StencilTable *t, const float *src, float *dst) {
    Osd::BufferDescriptor desc(0, 3, 3);
    Osd::CpuEvaluator::EvalStencils(src, desc, dst, desc, &t->GetSizes()[0], &t->GetOffsets()[0],
                                    &t->GetControlIndices()[0], &t->GetWeights()[0], 0, t->GetNumStencils());
}

/* ---- point set agreement ---- */

/* Largest distance between matched points when every point of a is paired with the nearest
 * unpaired point of b within tol (uniform grid of cell size tol); *unmatched counts the points
 * of a without a partner. */
static double point_set_difference(const std::vector<float> &a, const std::vector<float> &b, double tol,
                                   int *unmatched) {
    size_t na = a.size() / 3, nb = b.size() / 3;
    struct G {
        static bool cell(const float *p, double h, long long c[3]) {
            for (int k = 0; k < 3; ++k) {
                double q = std::floor(p[k] / h);
                if (!std::isfinite(q)) return false;
                c[k] = (long long)q;
            }
            return true;
        }
        static unsigned long long key(long long x, long long y, long long z) {
            const unsigned long long m = (1ull << 21) - 1;
            return (((unsigned long long)x & m) << 42) | (((unsigned long long)y & m) << 21) | ((unsigned long long)z & m);
        }
    };
    std::vector<std::pair<unsigned long long, int> > grid;
    grid.reserve(nb);
    for (size_t j = 0; j < nb; ++j) {
        long long c[3];
        if (G::cell(&b[3 * j], tol, c)) grid.push_back(std::make_pair(G::key(c[0], c[1], c[2]), (int)j));
    }
    std::sort(grid.begin(), grid.end());
    std::vector<char> used(nb, 0);
    double worst = 0.0;
    *unmatched = 0;
    for (size_t i = 0; i < na; ++i) {
        const float *p = &a[3 * i];
        long long c[3];
        if (!G::cell(p, tol, c)) { ++*unmatched; continue; }
        int best = -1;
        double best_d2 = tol * tol;
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    unsigned long long k = G::key(c[0] + dx, c[1] + dy, c[2] + dz);
                    std::vector<std::pair<unsigned long long, int> >::const_iterator it =
                        std::lower_bound(grid.begin(), grid.end(), std::make_pair(k, -1));
                    for (; it != grid.end() && it->first == k; ++it) {
                        if (used[(size_t)it->second]) continue;
                        const float *q = &b[3 * (size_t)it->second];
                        double ex = (double)q[0] - p[0], ey = (double)q[1] - p[1], ez = (double)q[2] - p[2];
                        double d2 = ex * ex + ey * ey + ez * ez;
                        if (d2 <= best_d2) { best_d2 = d2; best = it->second; }
                    }
                }
        if (best < 0) { ++*unmatched; continue; }
        used[(size_t)best] = 1;
        worst = std::max(worst, std::sqrt(best_d2));
    }
    if (na != nb) *unmatched += (int)(na > nb ? na - nb : nb - na);
    return worst;
}

/* ---- stencil evaluation on every backend ---- */

/* Best (minimum) time of `reps` runs of f after `warm` runs, in ms; stops repeating after
 * about budget_ms (at least one timed run). f returns false on failure. */
template <typename F> static double best_of(int warm, int reps, double budget_ms, F f, bool *ok) {
    double best = 1e300, spent = 0.0;
    *ok = true;
    for (int i = 0; i < warm; ++i)
        if (!f()) { *ok = false; return 0.0; }
    for (int i = 0; i < reps && (i == 0 || spent < budget_ms); ++i) {
        Clock::time_point t0 = Clock::now();
        if (!f()) { *ok = false; return 0.0; }
        double t = ms_since(t0);
        spent += t;
        best = std::min(best, t);
    }
    return best;
}

struct EvalRow {
    std::string name, note;  /* note: what runs, or why not */
    bool ran;
    double ms;
    double diff;             /* max |difference| from ref (point sets for OpenSubdiv) */
    int unmatched;           /* OpenSubdiv rows: points without a partner within tolerance */
    EvalRow(const std::string &n) : name(n), ran(false), ms(0.0), diff(0.0), unmatched(0) {}
};

/* A headless desktop OpenGL 4.3 core context made current on this thread, as a host
 * application would have (tests/egl_host.h: EGL surfaceless platform, else the default display). */
struct HostGL {
    egl_host h;
    std::string why, renderer;
    HostGL() { h.dpy = EGL_NO_DISPLAY; h.ctx = EGL_NO_CONTEXT; h.renderer[0] = 0; }
    bool open() {
        char w[512];
        if (!egl_host_open(&h, 4, 3, w, sizeof w)) { why = w; return false; }
        renderer = h.renderer;
        return true;
    }
    ~HostGL() { egl_host_close(&h); }
};

static sfb_context *eval_context(sfb_backend_kind kind, int threads, int use_current, std::string *why,
                                 const sfb_logger *logger = NULL) {
    sfb_context_config cfg = sfb_context_config_init();
    if (logger) cfg.logger = *logger;
    cfg.backends = &kind;
    cfg.backend_count = 1;
    cfg.ignore_environment = 1;
    cfg.threads = threads;
    cfg.gl_use_current_context = use_current;
    char info[512];
    info[0] = 0;
    if (sfb_backend_probe(kind, &cfg, info, sizeof info) != SFB_SUCCESS) {
        *why = info;
        return NULL;
    }
    sfb_context *ctx = NULL;
    if (sfb_context_create(&cfg, &ctx) != SFB_SUCCESS) {
        *why = "sfb_context_create failed after a successful probe";
        return NULL;
    }
    sfb_context_backend_info(ctx, info, sizeof info);
    *why = info;
    return ctx;
}

static double max_abs_diff(const std::vector<float> &a, const std::vector<float> &b) {
    if (a.size() != b.size()) return INFINITY;
    double m = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
        double d = std::fabs((double)a[i] - (double)b[i]);
        if (!(d <= m)) m = std::isnan(d) ? INFINITY : d;
    }
    return m;
}

static int eval_section(const TorusMesh &torus, double diag) {
    const int level = 4, warm = 2, reps = 15;
    const double budget_ms = 6000.0, tol = 1e-5 * diag; /* DESIGN.md: backends agree with ref within 1e-5 x diagonal */
    sfb_mesh_desc desc = torus.sfb_desc();
    sfb_surface_config scfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, level);
    sfb_buffer_desc bd = {0, 3, 3};
    const float *src = &torus.positions[0];
    std::vector<EvalRow> rows;
    std::vector<float> want;
    int status = 0, nrows = 0, nsources = torus.vertex_count();
    Clock::time_point t_sec = Clock::now();

    /* all threads: what the simd backend takes for threads = 0 (one per online core) */
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int all_threads = cores > 0 ? (int)std::min(cores, 64L) : 1;

    printf("\nstencil evaluation: positions (length 3), Catmull-Clark level %d of the torus; best of up to %d runs after %d\n"
           "warm-up runs, milliseconds; 'x OSD CPU' and 'x ref' are how many times faster than OpenSubdiv's\n"
           "CpuEvaluator and than surfblend's ref in this run (> 1: faster); difference from ref's points\n"
           "(OpenSubdiv's matched as point sets), tolerance %.3g.\n",
           level, reps, warm, tol);
    fflush(stdout);

    /* one surfblend surface per backend context (tables are uploaded when a surface is made) */
    auto run_sfb = [&](const char *name, sfb_context *ctx, const std::string &why, EvalRow *out_row) {
        EvalRow row(name);
        row.note = why;
        if (ctx) {
            sfb_mesh *mesh = NULL;
            sfb_surface *surf = NULL;
            if (sfb_mesh_create(ctx, &desc, &mesh) != SFB_SUCCESS || sfb_surface_create(ctx, mesh, &scfg, &surf) != SFB_SUCCESS) {
                row.note = std::string("error: ") + sfb_last_error(ctx);
                status = 1;
            } else {
                sfb_stencil_info info;
                sfb_surface_stencil_info(surf, SFB_TABLE_VERTEX, &info);
                nrows = info.rows;
                std::vector<float> dst((size_t)info.rows * 3);
                bool ok;
                row.ms = best_of(warm, reps, budget_ms, [&]() {
                    return sfb_surface_eval_stencils(surf, SFB_TABLE_VERTEX, src, bd, &dst[0], bd) == SFB_SUCCESS;
                }, &ok);
                if (!ok) {
                    row.note = std::string("error: ") + sfb_last_error(ctx);
                    status = 1;
                } else {
                    row.ran = true;
                    if (want.empty()) want = dst;
                    row.diff = max_abs_diff(dst, want);
                    if (!(row.diff <= tol)) status = 1;
                }
            }
            sfb_surface_destroy(surf);
            sfb_mesh_destroy(mesh);
        }
        if (out_row) *out_row = row;
        else rows.push_back(row);
    };

    std::string why;
    sfb_context *c;
    c = eval_context(SFB_BACKEND_REF, 1, 0, &why);
    run_sfb("surfblend ref", c, "plain C, double accumulation", NULL);
    if (c) sfb_context_destroy(c);
    if (!rows[0].ran) { printf("  ref failed: %s\n", rows[0].note.c_str()); return 1; }
    c = eval_context(SFB_BACKEND_SIMD, 1, 0, &why);
    run_sfb("surfblend simd, 1 thread", c, why, NULL);
    if (c) sfb_context_destroy(c);
    c = eval_context(SFB_BACKEND_SIMD, 0, 0, &why);
    run_sfb("surfblend simd, all threads", c, why, NULL);
    if (c) sfb_context_destroy(c);
    c = eval_context(SFB_BACKEND_GL, 0, 0, &why);
    run_sfb("surfblend gl, own EGL ctx, CPU copies", c, why, NULL);
    if (c) sfb_context_destroy(c);
    /* osmesa before the host context below exists: OSMesa shares Mesa's current-context slot */
    c = eval_context(SFB_BACKEND_OSMESA, 0, 0, &why);
    run_sfb("surfblend osmesa, CPU copies", c, why, NULL);
    if (c) sfb_context_destroy(c);

    /* OpenSubdiv on the CPU */
    Far::StencilTable const *table = osd_build(torus, level);
    std::vector<float> osd_dst((size_t)(table ? table->GetNumStencils() : 0) * 3);
    {
        EvalRow row("OpenSubdiv CpuEvaluator");
        row.note = "Osd::CpuEvaluator::EvalStencils, 1 thread";
        bool ok = table != NULL;
        if (ok)
            row.ms = best_of(warm, reps, budget_ms, [&]() { osd_apply(table, src, &osd_dst[0]); return true; }, &ok);
        if (ok) {
            row.ran = true;
            row.diff = point_set_difference(osd_dst, want, tol, &row.unmatched);
        } else row.note = "OpenSubdiv could not build the table";
        rows.push_back(row);
    }
    {
        EvalRow row("OpenSubdiv OmpEvaluator");
        char note[128];
        snprintf(note, sizeof note, "Osd::OmpEvaluator::EvalStencils, %d threads", all_threads);
        row.note = note;
        bool ok = table != NULL;
        if (ok) {
            Osd::OmpEvaluator::SetNumThreads(all_threads);
            Osd::BufferDescriptor d(0, 3, 3);
            row.ms = best_of(warm, reps, budget_ms, [&]() {
                return Osd::OmpEvaluator::EvalStencils(src, d, &osd_dst[0], d, &table->GetSizes()[0], &table->GetOffsets()[0],
                                                       &table->GetControlIndices()[0], &table->GetWeights()[0], 0,
                                                       table->GetNumStencils());
            }, &ok);
        }
        if (ok) {
            row.ran = true;
            row.diff = point_set_difference(osd_dst, want, tol, &row.unmatched);
        } else if (table) row.note = "Osd::OmpEvaluator::EvalStencils failed";
        rows.push_back(row);
    }

    /* the host's EGL context: surfblend gl on it, and OpenSubdiv's GL compute evaluator */
    HostGL host;
    std::string renderer;
    if (!host.open()) {
        const char *names[3] = {"surfblend gl, host ctx, GL buffers", "surfblend gl, host ctx, CPU copies", "OpenSubdiv GLComputeEvaluator"};
        for (int i = 0; i < 3; ++i) {
            EvalRow row(names[i]);
            row.note = host.why;
            rows.push_back(row);
        }
    } else {
        renderer = host.renderer;
        /* host buffers: the control points, and room for the refined points */
        GLuint gsrc = 0, gdst = 0;
        glGenBuffers(1, &gsrc);
        glGenBuffers(1, &gdst);
        glBindBuffer(GL_COPY_WRITE_BUFFER, gsrc);
        glBufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)(nsources * 3 * sizeof(float)), src, GL_STATIC_DRAW);
        glBindBuffer(GL_COPY_WRITE_BUFFER, gdst);
        glBufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)((size_t)nrows * 3 * sizeof(float)), NULL, GL_DYNAMIC_DRAW);
        glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
        auto read_back = [&](GLuint b, size_t floats) {
            std::vector<float> v(floats);
            glBindBuffer(GL_COPY_READ_BUFFER, b);
            glGetBufferSubData(GL_COPY_READ_BUFFER, 0, (GLsizeiptr)(floats * sizeof(float)), &v[0]);
            glBindBuffer(GL_COPY_READ_BUFFER, 0);
            return v;
        };

        c = eval_context(SFB_BACKEND_GL, 0, 1, &why);
        {
            EvalRow row("surfblend gl, host ctx, GL buffers");
            row.note = why;
            sfb_mesh *mesh = NULL;
            sfb_surface *surf = NULL;
            if (c && (sfb_mesh_create(c, &desc, &mesh) != SFB_SUCCESS || sfb_surface_create(c, mesh, &scfg, &surf) != SFB_SUCCESS)) {
                row.note = std::string("error: ") + sfb_last_error(c);
                status = 1;
            } else if (c) {
                bool ok;
                row.ms = best_of(warm, reps, budget_ms, [&]() {
                    sfb_result r = sfb_surface_eval_stencils_gl(surf, SFB_TABLE_VERTEX, gsrc, bd, gdst, bd);
                    glFinish();
                    return r == SFB_SUCCESS;
                }, &ok);
                if (!ok) {
                    row.note = std::string("error: ") + sfb_last_error(c);
                    status = 1;
                } else {
                    row.ran = true;
                    row.diff = max_abs_diff(read_back(gdst, (size_t)nrows * 3), want);
                    if (!(row.diff <= tol)) status = 1;
                }
            }
            rows.push_back(row);
            /* the same surface with CPU pointers: upload, dispatch, read back */
            EvalRow row2("surfblend gl, host ctx, CPU copies");
            row2.note = row.note;
            if (surf) {
                std::vector<float> dst((size_t)nrows * 3);
                bool ok;
                row2.ms = best_of(warm, reps, budget_ms, [&]() {
                    return sfb_surface_eval_stencils(surf, SFB_TABLE_VERTEX, src, bd, &dst[0], bd) == SFB_SUCCESS;
                }, &ok);
                if (!ok) {
                    row2.note = std::string("error: ") + sfb_last_error(c);
                    status = 1;
                } else {
                    row2.ran = true;
                    row2.diff = max_abs_diff(dst, want);
                    if (!(row2.diff <= tol)) status = 1;
                }
            }
            rows.push_back(row2);
            sfb_surface_destroy(surf);
            sfb_mesh_destroy(mesh);
            if (c) sfb_context_destroy(c);
        }
        {
            EvalRow row("OpenSubdiv GLComputeEvaluator");
            row.note = "Osd::GLComputeEvaluator, GLStencilTableSSBO, GLVertexBuffer";
            OpenSubdiv::internal::GLLoader::libraryInitializeGL();
            Osd::BufferDescriptor d(0, 3, 3);
            Osd::GLComputeEvaluator *ev = table ? Osd::GLComputeEvaluator::Create(d, d, Osd::BufferDescriptor(), Osd::BufferDescriptor()) : NULL;
            Osd::GLStencilTableSSBO *gtab = table ? Osd::GLStencilTableSSBO::Create(table) : NULL;
            Osd::GLVertexBuffer *vsrc = Osd::GLVertexBuffer::Create(3, nsources);
            Osd::GLVertexBuffer *vdst = table ? Osd::GLVertexBuffer::Create(3, table->GetNumStencils()) : NULL;
            if (!ev || !gtab || !vsrc || !vdst) {
                row.note = "could not create OpenSubdiv's GL evaluator or buffers";
            } else {
                vsrc->UpdateData(src, 0, nsources);
                bool ok;
                row.ms = best_of(warm, reps, budget_ms, [&]() {
                    bool r = Osd::GLComputeEvaluator::EvalStencils(vsrc, d, vdst, d, gtab, ev);
                    glFinish();
                    return r;
                }, &ok);
                if (ok) {
                    row.ran = true;
                    row.diff = point_set_difference(read_back(vdst->BindVBO(), (size_t)table->GetNumStencils() * 3), want, tol,
                                                    &row.unmatched);
                } else row.note = "Osd::GLComputeEvaluator::EvalStencils failed";
            }
            delete vdst;
            delete vsrc;
            delete gtab;
            delete ev;
            rows.push_back(row);
        }
        glDeleteBuffers(1, &gsrc);
        glDeleteBuffers(1, &gdst);
    }
    delete table;

    double osd_cpu = 0.0, ref_ms = rows[0].ms;
    for (size_t i = 0; i < rows.size(); ++i)
        if (rows[i].name == "OpenSubdiv CpuEvaluator" && rows[i].ran) osd_cpu = rows[i].ms;
    printf("renderer: %s\n\n", renderer.empty() ? "(no EGL context)" : renderer.c_str());
    printf("%-38s | %9s | %9s | %6s | %11s | %s\n", "evaluator", "best ms", "x OSD CPU", "x ref", "diff vs ref", "what runs");
    for (size_t i = 0; i < rows.size(); ++i) {
        const EvalRow &r = rows[i];
        if (!r.ran) {
            printf("%-38s | unavailable: %s\n", r.name.c_str(), r.note.c_str());
            continue;
        }
        char diff[48];
        if (r.unmatched) snprintf(diff, sizeof diff, "%d unmatched", r.unmatched);
        else snprintf(diff, sizeof diff, "%.3g", r.diff);
        printf("%-38s | %9.3f | %9.2f | %6.2f | %11s | %s\n", r.name.c_str(), r.ms, osd_cpu > 0 ? osd_cpu / r.ms : 0.0,
               ref_ms > 0 ? ref_ms / r.ms : 0.0, diff, r.note.c_str());
        if (r.unmatched || !(r.diff <= tol)) status = 1;
    }
    printf("(%d refined points from %d control points; section took %.1f s)\n", nrows, nsources, ms_since(t_sec) / 1000.0);
    return status;
}

/* ---- limit evaluation, patch build and tessellation (SFB_REFINE_PATCHES) ---- */

/* Deterministic random numbers (splitmix64), the same on every platform. */
struct SplitMix {
    unsigned long long s;
    explicit SplitMix(unsigned long long seed) : s(seed) {}
    unsigned long long next() {
        unsigned long long z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    float unit() { return (float)(next() >> 40) * (1.0f / 16777216.0f); } /* [0,1), 24 bits */
    int below(int n) { return (int)((next() >> 11) % (unsigned long long)n); }
};

/* Collects log messages of a context (to tell when sfb_surface_eval fell back to ref). */
struct LogCapture {
    std::string text;
    static void func(int level, const char *msg, void *user) {
        (void)level;
        LogCapture *c = (LogCapture *)user;
        c->text += msg ? msg : "";
        c->text += "\n";
    }
    sfb_logger logger() { sfb_logger l; l.func = func; l.user = this; return l; }
};

/* OpenSubdiv's feature-adaptive patch table for the same mesh, ready to evaluate. */
struct OsdPatches {
    Far::TopologyRefiner *refiner;
    Far::PatchTable *table;
    Far::PatchMap *map;
    Far::StencilTable const *stencils; /* refined vertices + local points (end caps), over base vertices */
    Osd::CpuVertexBuffer *points;      /* base vertices, refined vertices, local points */
    Osd::CpuPatchTable *cpu_table;
    int isolation;
    OsdPatches() : refiner(NULL), table(NULL), map(NULL), stencils(NULL), points(NULL), cpu_table(NULL), isolation(0) {}
    ~OsdPatches() { clear(); }
    void clear() {
        delete cpu_table; delete points; delete stencils; delete map; delete table; delete refiner;
        cpu_table = NULL; points = NULL; stencils = NULL; map = NULL; table = NULL; refiner = NULL;
    }
    /* TopologyRefinerFactory::Create + RefineAdaptive (PatchTableFactory::Options' default
     * isolation) + PatchTableFactory::Create (default options: Gregory basis end caps). */
    bool build_patches(const TorusMesh &m, bool inf_sharp_patch = false, Sdc::SchemeType type = Sdc::SCHEME_CATMARK) {
        clear();
        Far::TopologyDescriptor desc = m.osd_desc();
        Sdc::Options opt;
        opt.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
        opt.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
        opt.SetTriangleSubdivision(Sdc::Options::TRI_SUB_CATMARK);
        typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
        refiner = Factory::Create(desc, Factory::Options(type, opt));
        if (!refiner) return false;
        Far::PatchTableFactory::Options po;
        po.useInfSharpPatch = inf_sharp_patch;
        isolation = (int)po.maxIsolationLevel;
        refiner->RefineAdaptive(po.GetRefineAdaptiveOptions());
        table = Far::PatchTableFactory::Create(*refiner, po);
        return table != NULL;
    }
    /* PatchMap, the stencil table (every refined vertex, then the local points), the points
     * themselves (EvalStencils) and the Osd::CpuPatchTable. */
    bool build_eval(const TorusMesh &m) {
        map = new Far::PatchMap(*table);
        Far::StencilTableFactory::Options so;
        so.generateOffsets = true;
        so.generateIntermediateLevels = true;
        Far::StencilTable const *refined = Far::StencilTableFactory::Create(*refiner, so);
        stencils = refined;
        if (Far::StencilTable const *local = table->GetLocalPointStencilTable()) {
            stencils = Far::StencilTableFactory::AppendLocalPointStencilTable(*refiner, refined, local);
            delete refined;
        }
        if (!stencils) return false;
        int nbase = m.vertex_count(), nall = nbase + stencils->GetNumStencils();
        points = Osd::CpuVertexBuffer::Create(3, nall);
        points->UpdateData(&m.positions[0], 0, nbase);
        Osd::BufferDescriptor sd(0, 3, 3), dd(3 * nbase, 3, 3);
        if (!Osd::CpuEvaluator::EvalStencils(points, sd, points, dd, stencils)) return false;
        cpu_table = Osd::CpuPatchTable::Create(table);
        return cpu_table != NULL;
    }
    /* rough memory: patch vertex indices and patch params, the stencil table, the points */
    size_t bytes() const {
        size_t b = 0;
        if (table)
            b += table->GetPatchControlVerticesTable().size() * sizeof(Far::Index) +
                 table->GetPatchParamTable().size() * sizeof(Far::PatchParam);
        if (stencils)
            b += (stencils->GetSizes().size() + stencils->GetOffsets().size() + stencils->GetControlIndices().size()) * sizeof(int) +
                 stencils->GetWeights().size() * sizeof(float);
        if (points) b += (size_t)points->GetNumVertices() * 3 * sizeof(float);
        return b;
    }
};

struct LimitRow {
    std::string name, note;
    bool ran;
    double ms;
    double diff; /* max |position difference| from surfblend ref */
    LimitRow(const std::string &n) : name(n), ran(false), ms(0.0), diff(0.0) {}
};

static void max_mean_diff(const std::vector<float> &a, const std::vector<float> &b, double *mx, double *mean) {
    double m = 0.0, s = 0.0;
    size_t n = std::min(a.size(), b.size()) / 3;
    for (size_t i = 0; i < n; ++i) {
        double dx = (double)a[3 * i] - b[3 * i], dy = (double)a[3 * i + 1] - b[3 * i + 1], dz = (double)a[3 * i + 2] - b[3 * i + 2];
        double d = std::sqrt(dx * dx + dy * dy + dz * dz);
        if (!(d <= m)) m = std::isnan(d) ? INFINITY : d;
        s += d;
    }
    *mx = a.size() == b.size() ? m : INFINITY;
    *mean = n ? s / (double)n : 0.0;
}

/* kind: LIMIT_CATMARK, LIMIT_LOOP, or LIMIT_TRIBEZIER (seed 004's quartic triangular Bezier
 * surface on Loop's triangulated torus, beside surfblend's Loop patches and OpenSubdiv's Loop
 * patch table: issue 16's construction and evaluation rows). */
enum { LIMIT_CATMARK = 0, LIMIT_LOOP = 1, LIMIT_TRIBEZIER = 2 };
static int limit_section(double diag, int kind) {
    const bool loop = kind != LIMIT_CATMARK, tbz = kind == LIMIT_TRIBEZIER;
    const int npoints = 1000000, warm = 1, reps = 3, tess_rate = 8;
    const double budget_ms = 1e300; /* always the 3 runs */
    const double tol = 1e-5 * diag;  /* surfblend backends against ref */
    int status = 0;
    Clock::time_point t_sec = Clock::now();
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int all_threads = cores > 0 ? (int)std::min(cores, 64L) : 1;

    TorusMesh mesh(100, 60, true);
    if (loop) mesh.triangulate();
    const Sdc::SchemeType osd_type = loop ? Sdc::SCHEME_LOOP : Sdc::SCHEME_CATMARK;
    const char *scheme_name = tbz ? "tribezier" : loop ? "Loop" : "Catmull-Clark";
    sfb_mesh_desc desc = mesh.sfb_desc();
    sfb_surface_config pcfg = sfb_surface_config_init(tbz ? SFB_SCHEME_TRIBEZIER : loop ? SFB_SCHEME_LOOP : SFB_SCHEME_CATMARK, 0);
    pcfg.flags = SFB_REFINE_PATCHES;
    sfb_surface_config loopcfg = sfb_surface_config_init(SFB_SCHEME_LOOP, 0); /* tribezier: Loop's build beside it */
    loopcfg.flags = SFB_REFINE_PATCHES;

    /* the reference surface (ref backend): mesh statistics, parametric faces */
    std::string why;
    sfb_context *rctx = eval_context(SFB_BACKEND_REF, 1, 0, &why);
    if (!rctx) { printf("\nlimit evaluation: no ref context: %s\n", why.c_str()); return 1; }
    sfb_mesh *rmesh = NULL;
    sfb_surface *rsurf = NULL;
    if (sfb_mesh_create(rctx, &desc, &rmesh) != SFB_SUCCESS || sfb_surface_create(rctx, rmesh, &pcfg, &rsurf) != SFB_SUCCESS) {
        printf("\nlimit evaluation: surfblend could not build the patch surface: %s\n", sfb_last_error(rctx));
        sfb_mesh_destroy(rmesh);
        sfb_context_destroy(rctx);
        return 1;
    }
    sfb_mesh_info mi;
    sfb_mesh_get_info(rmesh, &mi);
    sfb_patch_info pi;
    memset(&pi, 0, sizeof pi);
    sfb_surface_patch_info(rsurf, &pi);
    int nparam = sfb_surface_param_face_count(rsurf);

    if (tbz)
        printf("\n==== tribezier (seed 004) ====\nquartic triangular Bezier surfaces (SFB_SCHEME_TRIBEZIER; s from the crease tags clamped to\n"
               "[0, 1], so the semi-sharp rings are s = 1 creases) beside Loop (surfblend's and OpenSubdiv's patches) on the\n"
               "torus with extraordinary vertices, cut into triangles:\n");
    else printf("\n==== %s ====\nlimit evaluation (SFB_REFINE_PATCHES, %s) on the torus with extraordinary vertices%s:\n", scheme_name,
                scheme_name, loop ? ", cut into triangles" : "");
    printf("%d faces (%d quads, %d triangles, %d hexagons) = %d parametric faces, %d vertices, %d extraordinary\n"
           "(%s, some on the semi-sharp and the infinitely sharp ring), the same %d creases and corner\n",
           mi.face_count, mi.quads, mi.triangles, mi.ngons, nparam,
           mi.vertex_count, loop ? mi.extraordinary_loop : mi.extraordinary_catmark, loop ? "valence 3 to 9" : "valence 3 and 5",
           mi.sharp_edges);
    fflush(stdout);

    /* ---- patch build ---- */
    std::vector<double> t_sfb_build, t_sfb_surf, t_osd_patch, t_osd_eval;
    for (int rep = 0; rep < 3; ++rep) {
        sfb_mesh *m = NULL;
        sfb_surface *s = NULL;
        Clock::time_point t0 = Clock::now();
        sfb_result r = sfb_mesh_create(rctx, &desc, &m);
        Clock::time_point t1 = Clock::now();
        if (r == SFB_SUCCESS) r = sfb_surface_create(rctx, m, &pcfg, &s);
        double tb = ms_since(t0), ts = ms_since(t1);
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
        if (r != SFB_SUCCESS) { printf("  sfb_surface_create failed: %s\n", sfb_last_error(rctx)); status = 1; break; }
        t_sfb_build.push_back(tb);
        t_sfb_surf.push_back(ts);
    }
    std::vector<double> t_sfb_loop; /* tribezier: surfblend's Loop patches of the same mesh */
    for (int rep = 0; tbz && rep < 3; ++rep) {
        sfb_surface *s = NULL;
        Clock::time_point t0 = Clock::now();
        sfb_result r = sfb_surface_create(rctx, rmesh, &loopcfg, &s);
        double ts = ms_since(t0);
        sfb_surface_destroy(s);
        if (r != SFB_SUCCESS) { printf("  sfb_surface_create (Loop) failed: %s\n", sfb_last_error(rctx)); status = 1; break; }
        t_sfb_loop.push_back(ts);
    }
    /* tribezier: the same build on a simd context with all threads (its components' solves run
     * on the backend's threads; the net is bit for bit the single-threaded one) */
    std::vector<double> t_sfb_tbz_mt;
    std::string mt_why;
    if (tbz) {
        sfb_context *mctx = eval_context(SFB_BACKEND_SIMD, 0, 0, &mt_why);
        sfb_mesh *mm = NULL;
        if (mctx && sfb_mesh_create(mctx, &desc, &mm) == SFB_SUCCESS) {
            for (int rep = 0; rep < 3; ++rep) {
                sfb_surface *s = NULL;
                Clock::time_point t0 = Clock::now();
                sfb_result r = sfb_surface_create(mctx, mm, &pcfg, &s);
                double ts = ms_since(t0);
                sfb_surface_destroy(s);
                if (r != SFB_SUCCESS) { printf("  sfb_surface_create (simd) failed: %s\n", sfb_last_error(mctx)); status = 1; break; }
                t_sfb_tbz_mt.push_back(ts);
            }
        }
        sfb_mesh_destroy(mm);
        sfb_context_destroy(mctx);
    }
    OsdPatches osd;
    bool osd_ok = true;
    for (int rep = 0; rep < 3 && osd_ok; ++rep) {
        Clock::time_point t0 = Clock::now();
        osd_ok = osd.build_patches(mesh, false, osd_type);
        double tp = ms_since(t0);
        Clock::time_point t1 = Clock::now();
        osd_ok = osd_ok && osd.build_eval(mesh);
        t_osd_patch.push_back(tp);
        t_osd_eval.push_back(tp + ms_since(t1));
    }
    auto patch_counts = [](const Far::PatchTable *t, int c[3]) {
        c[0] = c[1] = c[2] = 0;
        for (int a = 0; a < t->GetNumPatchArrays(); ++a) {
            Far::PatchDescriptor::Type ty = t->GetPatchArrayDescriptor(a).GetType();
            c[ty == Far::PatchDescriptor::REGULAR ? 0 : ty == Far::PatchDescriptor::GREGORY_BASIS ? 1 : 2] += t->GetNumPatches(a);
        }
    };
    int osd_counts[3] = {0, 0, 0};
    if (osd_ok) patch_counts(osd.table, osd_counts);
    /* also with useInfSharpPatch (infinitely sharp creases as regular boundary patches, as
     * surfblend does): not the default, shown for the build cost alone */
    std::vector<double> t_osd_inf;
    int inf_counts[3] = {0, 0, 0}, inf_total = 0;
    if (osd_ok) {
        OsdPatches o2;
        for (int rep = 0; rep < 3; ++rep) {
            Clock::time_point t0 = Clock::now();
            if (!o2.build_patches(mesh, true, osd_type)) break;
            t_osd_inf.push_back(ms_since(t0));
        }
        if (o2.table) { patch_counts(o2.table, inf_counts); inf_total = o2.table->GetNumPatchesTotal(); }
    }
    {
        double sb = median(t_sfb_build), ss = median(t_sfb_surf), op = median(t_osd_patch), oe = median(t_osd_eval);
        printf("\npatch build: median of 3, milliseconds; 'x OSD' = OpenSubdiv's refine + patch table time / this\n");
        printf("%-38s | %9s | %7s | %9s | %s\n", "patch build", "median ms", "x OSD", "memory MB", "what");
        char what[256];
        snprintf(what, sizeof what, "sfb_mesh_create + sfb_surface_create(level 0, SFB_REFINE_PATCHES, isolation %d)",
                 SFB_DEFAULT_ISOLATION);
        printf("%-38s | %9.2f | %7.2f | %9s | %s\n", "surfblend mesh + surface", sb, sb > 0 ? op / sb : 0.0, "", what);
        snprintf(what, sizeof what, "%d patches: %d %s, %d Stam, %d end caps; max depth %d; %d points (patch table + points)",
                 pi.patches, loop ? pi.bezier : pi.bspline, loop ? "Bezier triangles" : "B-spline", pi.stam, pi.end_caps,
                 pi.max_depth, pi.points);
        printf("%-38s | %9.2f | %7.2f | %9.2f | %s\n", tbz ? "surfblend sfb_surface_create, tribezier" : "surfblend sfb_surface_create",
               ss, ss > 0 ? op / ss : 0.0, (double)pi.bytes / (1 << 20), what);
        if (tbz && !t_sfb_loop.empty()) {
            double sl = median(t_sfb_loop);
            printf("%-38s | %9.2f | %7.2f | %9s | %s\n", "surfblend sfb_surface_create, Loop", sl, sl > 0 ? op / sl : 0.0, "",
                   "SFB_SCHEME_LOOP on the same mesh: Bezier triangles where regular, Stam / end caps at extraordinary vertices");
            if (!t_sfb_tbz_mt.empty()) {
                const double sm = median(t_sfb_tbz_mt);
                snprintf(what, sizeof what, "the same on a simd context, all threads (%s): the constraint regions solved in parallel, "
                         "the same net bit for bit", mt_why.c_str());
                printf("%-38s | %9.2f | %7.2f | %9s | %s\n", "  ... tribezier, simd all threads", sm, sm > 0 ? op / sm : 0.0, "", what);
            } else {
                printf("  (tribezier on a simd context: not measured: %s)\n", mt_why.c_str());
            }
            printf("per 1,000 triangles: tribezier %.2f ms (one thread; %.2f ms on the simd context's threads), surfblend Loop %.2f ms, "
                   "OpenSubdiv Loop refine + patch table %.2f ms\n"
                   "(target: tribezier <= OpenSubdiv's, both on one thread)\n",
                   ss * 1000.0 / mi.triangles, t_sfb_tbz_mt.empty() ? 0.0 : median(t_sfb_tbz_mt) * 1000.0 / mi.triangles,
                   sl * 1000.0 / mi.triangles, op * 1000.0 / mi.triangles);
        }
        if (osd_ok) {
            snprintf(what, sizeof what, "TopologyRefinerFactory + RefineAdaptive(isolation %d) + PatchTableFactory (Gregory basis end "
                     "caps): %d patches, %d regular, %d Gregory basis, %d other", osd.isolation,
                     (int)osd.table->GetNumPatchesTotal(), osd_counts[0], osd_counts[1], osd_counts[2]);
            printf("%-38s | %9.2f | %7.2f | %9s | %s\n", "OpenSubdiv refine + patch table", op, 1.0, "", what);
            if (!t_osd_inf.empty()) {
                double oi = median(t_osd_inf);
                snprintf(what, sizeof what, "the same with Options::useInfSharpPatch = true (not the default): %d patches, %d regular, "
                         "%d Gregory basis, %d other", inf_total, inf_counts[0], inf_counts[1], inf_counts[2]);
                printf("%-38s | %9.2f | %7.2f | %9s | %s\n", "OpenSubdiv ..., useInfSharpPatch", oi, oi > 0 ? op / oi : 0.0, "", what);
            }
            snprintf(what, sizeof what, "+ PatchMap, StencilTableFactory (all levels) + AppendLocalPointStencilTable, EvalStencils: "
                     "%d points, %d local; memory = patch indices/params + stencils + points", osd.points->GetNumVertices(),
                     osd.table->GetNumLocalPoints());
            printf("%-38s | %9.2f | %7.2f | %9.2f | %s\n", "OpenSubdiv ... + stencils + points", oe, oe > 0 ? op / oe : 0.0,
                   (double)osd.bytes() / (1 << 20), what);
        } else {
            printf("%-38s | unavailable: OpenSubdiv could not build the patch table\n", "OpenSubdiv refine + patch table");
        }
        fflush(stdout);
    }

    /* ---- the locations ---- */
    std::vector<sfb_location> locs((size_t)npoints);
    SplitMix rng(0x5eedf00dull);
    for (int i = 0; i < npoints; ++i) {
        locs[(size_t)i].face = rng.below(nparam);
        locs[(size_t)i].u = rng.unit();
        locs[(size_t)i].v = rng.unit();
        if (loop && (double)locs[(size_t)i].u + locs[(size_t)i].v > 1.0) {
            /* into the triangle: the other half of the square turned over (exact for 24-bit values) */
            locs[(size_t)i].u = 1.0f - locs[(size_t)i].u;
            locs[(size_t)i].v = 1.0f - locs[(size_t)i].v;
        }
    }
    std::vector<char> ngon_sub((size_t)nparam, 0); /* parametric face is a sub-face of an n-gon */
    for (int f = 0; f < nparam; ++f) {
        int bf = -1, sub = -1;
        if (sfb_surface_param_face_base(rsurf, f, &bf, &sub) == SFB_SUCCESS) ngon_sub[(size_t)f] = sub >= 0;
    }
    std::vector<LimitRow> rows;
    std::vector<float> want_p, want_du, want_dv;

    /* surfblend, one surface per backend context */
    auto run_sfb = [&](const char *name, sfb_backend_kind kind, int threads, const char *what) {
        LimitRow row(name);
        LogCapture log;
        sfb_logger lg = log.logger();
        sfb_context *c = eval_context(kind, threads, 0, &why, &lg);
        row.note = why;
        if (!c) { rows.push_back(row); return; }
        if (what) row.note = std::string(what) + (why.empty() ? "" : ", ") + why;
        sfb_mesh *m = NULL;
        sfb_surface *s = NULL;
        if (sfb_mesh_create(c, &desc, &m) != SFB_SUCCESS || sfb_surface_create(c, m, &pcfg, &s) != SFB_SUCCESS) {
            row.note = std::string("error: ") + sfb_last_error(c);
            status = 1;
        } else {
            std::vector<float> p((size_t)npoints * 3), du((size_t)npoints * 3), dv((size_t)npoints * 3);
            sfb_eval_output out;
            memset(&out, 0, sizeof out);
            out.position = &p[0];
            out.du = &du[0];
            out.dv = &dv[0];
            log.text.clear();
            bool ok = sfb_surface_eval(s, &locs[0], npoints, &out) == SFB_SUCCESS; /* warm-up */
            if (ok && kind != SFB_BACKEND_REF && log.text.find("lacks eval_patches") != std::string::npos) {
                row.note = std::string("skipped: ") + sfb_backend_kind_name(kind) +
                           " has no eval_patches kernel yet (sfb_surface_eval runs ref's)";
            } else if (ok) {
                row.ms = best_of(warm - 1, reps, budget_ms, [&]() { return sfb_surface_eval(s, &locs[0], npoints, &out) == SFB_SUCCESS; }, &ok);
            }
            if (!ok) {
                row.note = std::string("error: ") + sfb_last_error(c);
                status = 1;
            } else if (row.note.compare(0, 8, "skipped:") != 0) {
                row.ran = true;
                if (want_p.empty()) { want_p = p; want_du = du; want_dv = dv; }
                row.diff = max_abs_diff(p, want_p);
                if (!(row.diff <= tol)) status = 1;
            }
        }
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
        sfb_context_destroy(c);
        rows.push_back(row);
    };
    run_sfb("surfblend ref", SFB_BACKEND_REF, 1, "plain C, double");
    if (!rows[0].ran) {
        printf("  surfblend ref failed: %s\n", rows[0].note.c_str());
        sfb_surface_destroy(rsurf);
        sfb_mesh_destroy(rmesh);
        sfb_context_destroy(rctx);
        return 1;
    }
    run_sfb("surfblend simd, 1 thread", SFB_BACKEND_SIMD, 1, NULL);
    run_sfb("surfblend simd, all threads", SFB_BACKEND_SIMD, 0, NULL);
    run_sfb("surfblend gl, own EGL ctx, CPU copies", SFB_BACKEND_GL, 0, NULL);
    run_sfb("surfblend osmesa, CPU copies", SFB_BACKEND_OSMESA, 0, NULL);
    fprintf(stderr, "limit eval: surfblend rows done (%.1f s)\n", ms_since(t_sec) / 1000.0);

    /* OpenSubdiv: the same (face, u, v) as ptex faces */
    double osd_du_max = 0, osd_du_mean = 0, osd_dv_max = 0, osd_dv_mean = 0, osd_p_mean = 0;
    double osd_find_ms = 0.0;
    int osd_ptex = -1, not_found = 0;
    if (osd_ok) {
        Far::PtexIndices ptex(*osd.refiner);
        osd_ptex = ptex.GetNumFaces();
    }
    const char *osd_names[4] = {"OpenSubdiv FindPatch + CpuEvaluator", "OpenSubdiv CpuEvaluator alone",
                                "OpenSubdiv FindPatch + OmpEvaluator", "OpenSubdiv OmpEvaluator alone"};
    if (!osd_ok || osd_ptex != nparam) {
        for (int k = 0; k < 4; ++k) {
            LimitRow row(osd_names[k]);
            if (!osd_ok) row.note = "OpenSubdiv could not build the patch table";
            else {
                char b[160];
                snprintf(b, sizeof b, "OpenSubdiv has %d ptex faces, surfblend %d parametric faces", osd_ptex, nparam);
                row.note = b;
                status = 1;
            }
            rows.push_back(row);
        }
    } else {
        std::vector<Osd::PatchCoord> coords((size_t)npoints);
        auto find_all = [&]() {
            not_found = 0;
            for (int i = 0; i < npoints; ++i) {
                const sfb_location &l = locs[(size_t)i];
                Far::PatchTable::PatchHandle const *h = osd.map->FindPatch(l.face, l.u, l.v);
                if (h) coords[(size_t)i] = Osd::PatchCoord(*h, l.u, l.v);
                else { coords[(size_t)i] = coords[0]; ++not_found; }
            }
            return true;
        };
        std::vector<float> p((size_t)npoints * 3), du((size_t)npoints * 3), dv((size_t)npoints * 3);
        Osd::BufferDescriptor sd(0, 3, 3), dd(0, 3, 3);
        const float *src = osd.points->BindCpuBuffer();
        const Osd::PatchArray *arrays = osd.cpu_table->GetPatchArrayBuffer();
        const int *indices = osd.cpu_table->GetPatchIndexBuffer();
        const Osd::PatchParam *params = osd.cpu_table->GetPatchParamBuffer();
        auto cpu_eval = [&]() {
            return Osd::CpuEvaluator::EvalPatches(src, sd, &p[0], dd, &du[0], dd, &dv[0], dd, npoints, &coords[0], arrays, indices, params);
        };
        auto omp_eval = [&]() {
            return Osd::OmpEvaluator::EvalPatches(src, sd, &p[0], dd, &du[0], dd, &dv[0], dd, npoints, &coords[0], arrays, indices, params);
        };
        Osd::OmpEvaluator::SetNumThreads(all_threads);
        char note[256];
        for (int k = 0; k < 4; ++k) {
            LimitRow row(osd_names[k]);
            bool ok;
            bool omp = k >= 2, find = k % 2 == 0;
            if (find)
                row.ms = best_of(warm, reps, budget_ms, [&]() { return find_all() && (omp ? omp_eval() : cpu_eval()); }, &ok);
            else
                row.ms = best_of(warm, reps, budget_ms, [&]() { return omp ? omp_eval() : cpu_eval(); }, &ok);
            if (k == 0) osd_find_ms = best_of(0, reps, budget_ms, find_all, &ok) ;
            if (find)
                snprintf(note, sizeof note, "Far::PatchMap::FindPatch per point (1 thread) + Osd::%s::EvalPatches (P, du, dv), %d thread%s",
                         omp ? "OmpEvaluator" : "CpuEvaluator", omp ? all_threads : 1, omp && all_threads > 1 ? "s" : "");
            else
                snprintf(note, sizeof note, "Osd::%s::EvalPatches only (PatchCoords found beforehand), %d thread%s",
                         omp ? "OmpEvaluator" : "CpuEvaluator", omp ? all_threads : 1, omp && all_threads > 1 ? "s" : "");
            row.note = note;
            if (!ok) row.note = "EvalPatches failed";
            else {
                row.ran = true;
                row.diff = max_abs_diff(p, want_p);
                if (k == 0) {
                    /* OpenSubdiv scales derivatives by 2^depth counting the n-gon's split as a
                     * level (PatchParam depth includes it, Normalize() does not): on n-gon
                     * sub-faces its du, dv are twice d/du, d/dv of the parametric face. */
                    std::vector<float> du2(du), dv2(dv);
                    for (int i = 0; i < npoints; ++i)
                        if (ngon_sub[(size_t)locs[(size_t)i].face])
                            for (int c = 0; c < 3; ++c) { du2[3 * (size_t)i + c] *= 0.5f; dv2[3 * (size_t)i + c] *= 0.5f; }
                    double mx;
                    max_mean_diff(p, want_p, &mx, &osd_p_mean);
                    max_mean_diff(du2, want_du, &osd_du_max, &osd_du_mean);
                    max_mean_diff(dv2, want_dv, &osd_dv_max, &osd_dv_mean);
                }
            }
            rows.push_back(row);
        }
    }

    double osd_ms = 0.0, osd_p_max = 0.0, ref_ms = rows[0].ms;
    for (size_t i = 0; i < rows.size(); ++i)
        if (rows[i].name == osd_names[0] && rows[i].ran) { osd_ms = rows[i].ms; osd_p_max = rows[i].diff; }
    printf("\nlimit evaluation (%s): %d random locations (parametric face uniform, u and v uniform in [0,1]%s, fixed seed),\n"
           "position + du + dv; best of %d runs after %d warm-up run, milliseconds and million points per second;\n"
           "'x OSD' and 'x ref' are how many times faster than OpenSubdiv's FindPatch + CpuEvaluator and than\n"
           "surfblend's ref in this run. surfblend's time includes locating the patch (sfb_surface_eval takes\n"
           "(face, u, v)). 'diff vs ref' is the largest position difference from ref (OpenSubdiv: its Gregory\n"
           "end caps approximate the surface near extraordinary vertices%s).\n",
           scheme_name, npoints, loop ? " folded into u + v <= 1" : "", reps, warm,
           tbz ? "; here it evaluates Loop's limit surface, another surface than tribezier's, so its diff is no error" : "");
    printf("%-38s | %9s | %8s | %7s | %6s | %11s | %s\n", "limit eval", "best ms", "M pts/s", "x OSD", "x ref", "diff vs ref",
           "what runs");
    for (size_t i = 0; i < rows.size(); ++i) {
        const LimitRow &r = rows[i];
        if (!r.ran) {
            if (r.note.compare(0, 8, "skipped:") == 0) printf("%-38s | %s\n", r.name.c_str(), r.note.c_str());
            else printf("%-38s | unavailable: %s\n", r.name.c_str(), r.note.c_str());
            continue;
        }
        printf("%-38s | %9.2f | %8.2f | %7.2f | %6.2f | %11.3g | %s\n", r.name.c_str(), r.ms, r.ms > 0 ? npoints / (r.ms * 1e3) : 0.0,
               osd_ms > 0 ? osd_ms / r.ms : 0.0, ref_ms > 0 ? ref_ms / r.ms : 0.0, r.diff, r.note.c_str());
    }
    if (osd_ms > 0)
        printf("(OpenSubdiv vs surfblend ref: position max %.3g mean %.3g, du max %.3g mean %.3g, dv max %.3g mean %.3g,\n"
               " OpenSubdiv's du, dv halved on n-gon sub-faces, where it gives twice the parametric face's derivatives;\n"
               " FindPatch alone %.2f ms; %d locations without an OpenSubdiv patch)\n",
               osd_p_max, osd_p_mean, osd_du_max, osd_du_mean, osd_dv_max, osd_dv_mean, osd_find_ms,
               not_found);
    fflush(stdout);

    /* ---- the same locations in engine-sized calls: what a call costs the backend's thread pool ---- */
    {
        const int call = 4096, ncalls = npoints / call;
        printf("\nlimit evaluation (%s) in calls of %d locations (%d calls, the first %d of the locations above; an engine's\n"
               "per-frame call): microseconds per call, best of %d; 'x 1 thread': how many times faster than simd on one thread,\n"
               "which shows what the pool's hand-over costs a call of this size (waking a sleeping worker: 30-60 us here)\n",
               scheme_name, call, ncalls, ncalls * call, reps);
        printf("%-38s | %9s | %11s | %s\n", "eval calls of 4096", "us/call", "x 1 thread", "what runs");
        struct CallCase { const char *name; int threads; };
        const CallCase cc[2] = {{"surfblend simd, 1 thread", 1}, {"surfblend simd, all threads", 0}};
        double one = 0.0;
        std::vector<float> cp((size_t)call * 3), cdu((size_t)call * 3), cdv((size_t)call * 3);
        for (int k = 0; k < 2 && ncalls > 0; ++k) {
            sfb_context *c = eval_context(SFB_BACKEND_SIMD, cc[k].threads, 0, &why);
            sfb_mesh *m = NULL;
            sfb_surface *s = NULL;
            if (!c) { printf("%-38s | unavailable: %s\n", cc[k].name, why.c_str()); continue; }
            if (sfb_mesh_create(c, &desc, &m) != SFB_SUCCESS || sfb_surface_create(c, m, &pcfg, &s) != SFB_SUCCESS) {
                printf("%-38s | error: %s\n", cc[k].name, sfb_last_error(c));
                status = 1;
            } else {
                sfb_eval_output o;
                bool ok = true;
                memset(&o, 0, sizeof o);
                o.position = cp.data(); o.du = cdu.data(); o.dv = cdv.data();
                double best = best_of(warm, reps, 4000.0, [&]() {
                    for (int q = 0; q < ncalls; ++q)
                        if (sfb_surface_eval(s, &locs[(size_t)q * call], call, &o) != SFB_SUCCESS) return false;
                    return true;
                }, &ok);
                if (!ok) { printf("%-38s | error: %s\n", cc[k].name, sfb_last_error(c)); status = 1; }
                else {
                    const double us = best * 1e3 / ncalls;
                    if (k == 0) one = us;
                    printf("%-38s | %9.1f | %11.2f | %s\n", cc[k].name, us, one > 0 ? one / us : 0.0, why.c_str());
                }
            }
            sfb_surface_destroy(s);
            sfb_mesh_destroy(m);
            sfb_context_destroy(c);
        }
        fflush(stdout);
    }
    fprintf(stderr, "limit eval done (%.1f s)\n", ms_since(t_sec) / 1000.0);

    /* ---- tessellation ---- */
    if (loop)
        printf("\ntessellation (Loop): sfb_surface_tessellate, uniform rate %d (a triangular grid of %d triangles per parametric\n"
               "face), positions + normals; best of %d runs after %d warm-up run\n", tess_rate, tess_rate * tess_rate, reps, warm);
    else
        printf("\ntessellation: sfb_surface_tessellate, uniform rate %d (%d x %d quads, 2 triangles each, per parametric face),\n"
               "positions + normals; best of %d runs after %d warm-up run\n", tess_rate, tess_rate, tess_rate, reps, warm);
    printf("%-38s | %9s | %9s | %10s | %9s | %s\n", "tessellate", "best ms", "M tris/s", "triangles", "vertices", "what runs");
    struct TessCase { const char *name; sfb_backend_kind kind; int threads; };
    const TessCase tcases[3] = {{"surfblend ref", SFB_BACKEND_REF, 1}, {"surfblend simd, 1 thread", SFB_BACKEND_SIMD, 1},
                                {"surfblend simd, all threads", SFB_BACKEND_SIMD, 0}};
    for (int k = 0; k < 3; ++k) {
        LogCapture log;
        sfb_logger lg = log.logger();
        sfb_context *c = eval_context(tcases[k].kind, tcases[k].threads, 0, &why, &lg);
        if (!c) { printf("%-38s | unavailable: %s\n", tcases[k].name, why.c_str()); continue; }
        if (tcases[k].kind == SFB_BACKEND_REF) why = "plain C, double";
        sfb_mesh *m = NULL;
        sfb_surface *s = NULL;
        if (sfb_mesh_create(c, &desc, &m) != SFB_SUCCESS || sfb_surface_create(c, m, &pcfg, &s) != SFB_SUCCESS) {
            printf("%-38s | error: %s\n", tcases[k].name, sfb_last_error(c));
            status = 1;
        } else {
            sfb_tess_config tc = sfb_tess_config_init(tess_rate);
            double best = 1e300;
            int tris = 0, verts = 0;
            bool ok = true;
            for (int i = 0; i < warm + reps && ok; ++i) {
                sfb_tess_data td;
                memset(&td, 0, sizeof td);
                Clock::time_point t0 = Clock::now();
                ok = sfb_surface_tessellate(s, &tc, &td) == SFB_SUCCESS;
                double t = ms_since(t0);
                if (i >= warm) best = std::min(best, t);
                tris = td.triangle_count;
                verts = td.vertex_count;
                sfb_tess_data_free(&td);
            }
            if (!ok) {
                printf("%-38s | error: %s\n", tcases[k].name, sfb_last_error(c));
                status = 1;
            } else {
                if (tcases[k].kind != SFB_BACKEND_REF && log.text.find("lacks eval_patches") != std::string::npos)
                    why += "; evaluation on ref's kernel (no eval_patches kernel on this backend yet)";
                printf("%-38s | %9.2f | %9.2f | %10d | %9d | %s\n", tcases[k].name, best, tris / (best * 1e3), tris, verts, why.c_str());
            }
        }
        sfb_surface_destroy(s);
        sfb_mesh_destroy(m);
        sfb_context_destroy(c);
    }

    sfb_surface_destroy(rsurf);
    sfb_mesh_destroy(rmesh);
    sfb_context_destroy(rctx);
    printf("(section took %.1f s)\n", ms_since(t_sec) / 1000.0);
    return status;
}

/* ---- main ---- */

struct Row {
    int level, faces_out, rows_sfb, rows_osd;
    double sfb_build, sfb_surface, osd_build, sfb_apply, osd_apply;
    long long entries_sfb, entries_osd;
    double max_diff;
    int unmatched;
};

/* Subdivision shading (seed 001): sfb_surface_shade against sfb_surface_refine with limit
 * normals (SFB_REFINE_LIMIT: refined positions, limit positions, tangents, normals) on the same
 * surface, same level, per backend; tables compiled once beforehand (not timed). */
static int shade_section() {
    struct Case { const char *path; int level; };
    const Case cases[] = {{"examples/data/creased_box.obj", 5}, {"../shared/peers/opensubdiv-shapes/catmark_car.obj", 3},
                          {"../shared/peers/opensubdiv-shapes/catmark_pole64.obj", 4}};
    const sfb_backend_kind kinds[4] = {SFB_BACKEND_REF, SFB_BACKEND_SIMD, SFB_BACKEND_GL, SFB_BACKEND_OSMESA};
    printf("\n== subdivision shading: sfb_surface_shade vs sfb_surface_refine (limit normals), same surface and level\n");
    printf("%-14s %-5s %-8s %9s %9s %12s %12s %7s %10s\n", "mesh", "level", "backend", "vertices", "N_S at", "refine ms",
           "shade ms", "ratio", "split");
    int status = 0;
    for (const Case &c : cases) {
        std::string text;
        if (!read_text(c.path, &text)) { printf("%-14s skipped: %s not found\n", "", c.path); continue; }
        std::string name = c.path;
        name = name.substr(name.find_last_of('/') + 1);
        name = name.substr(0, name.size() - 4);
        for (sfb_backend_kind kind : kinds) {
            std::string why;
            sfb_context *ctx = eval_context(kind, 0, 0, &why);
            if (!ctx) { printf("%-14s %-5d %-8s skipped: %s\n", name.c_str(), c.level, sfb_backend_kind_name(kind), why.c_str()); continue; }
            sfb_mesh *mesh = NULL;
            sfb_surface *surf = NULL;
            sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, c.level);
            cfg.flags = SFB_REFINE_LIMIT | SFB_REFINE_SHADING;
            if (sfb_mesh_read_obj(ctx, text.data(), text.size(), &mesh) != SFB_SUCCESS ||
                sfb_surface_create(ctx, mesh, &cfg, &surf) != SFB_SUCCESS) {
                printf("%-14s failed: %s\n", name.c_str(), sfb_last_error(ctx));
                status = 1;
            } else {
                double tr = 1e30, ts = 1e30;
                int nv = 0, nout = 0, nsub = 0, split = 0;
                for (int rep = 0; rep < 7; ++rep) {
                    sfb_mesh_data d;
                    Clock::time_point t0 = Clock::now();
                    if (sfb_surface_refine(surf, &d) != SFB_SUCCESS) { status = 1; break; }
                    tr = std::min(tr, ms_since(t0));
                    nv = d.vertex_count;
                    sfb_mesh_data_free(&d);
                    t0 = Clock::now();
                    if (sfb_surface_shade(surf, NULL, &d) != SFB_SUCCESS) { status = 1; break; }
                    ts = std::min(ts, ms_since(t0));
                    nout = d.vertex_count; nsub = d.subdivided_count; split = d.vertex_count - d.refined_vertex_count;
                    sfb_mesh_data_free(&d);
                }
                char frac[32];
                snprintf(frac, sizeof frac, "%.1f%%", nout ? 100.0 * nsub / nout : 0.0);
                printf("%-14s %-5d %-8s %9d %9s %12.2f %12.2f %6.2fx %10d\n", name.c_str(), c.level, sfb_backend_kind_name(kind), nv, frac, tr, ts,
                       ts / tr, split);
            }
            if (surf) sfb_surface_destroy(surf);
            if (mesh) sfb_mesh_destroy(mesh);
            sfb_context_destroy(ctx);
        }
    }
    printf("(ratio: shade time / refine time, best of 7; target <= 1.3x. N_S at: share of output vertices where the subdivided normal is computed)\n");
    return status;
}

/* Manifold-based blending (seed 000), the seed's Table 3 setting: 30 x 30 samples per face
 * (u, v = i / 29), positions and normals through sfb_surface_eval, per backend; one frame = every
 * sample of the mesh. Meshes: OpenSubdiv's catmark_torus (32 quads, the size of the seed's
 * mesh (a)), tori of 10 x 18 = 180 and 13 x 34 = 442 quads (the sizes of (c) 179 and (e) 442),
 * and a cube of 9 x 9 quads per side pushed onto a sphere (486 quads, valence-3 vertices). The
 * seed's figures (Pentium IV 3.2 GHz CPU, GeForce 6800 Ultra GPU) are printed beside ours. */
static sfb_mesh *bench_torus_mesh(sfb_context *ctx, int nu, int nv) {
    TorusMesh t(nu, nv);
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = (int)t.positions.size() / 3; d.positions = t.positions.data();
    d.face_count = (int)t.face_sizes.size(); d.face_sizes = t.face_sizes.data(); d.face_vertices = t.face_vertices.data();
    sfb_mesh *m = NULL;
    if (sfb_mesh_create(ctx, &d, &m) != SFB_SUCCESS) return NULL;
    return m;
}
static sfb_mesh *bench_sphere_cube(sfb_context *ctx, int n) {
    std::vector<float> p;
    std::vector<int> sizes, fv;
    std::vector<int> key((size_t)(n + 1) * (n + 1) * (n + 1), -1);
    for (int side = 0; side < 6; ++side) {
        int axis = side / 2, hi = side % 2;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                int q[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
                for (int k = 0; k < 4; ++k) {
                    int kk = hi ? k : (4 - k) % 4, xyz[3];
                    xyz[axis] = hi ? n : 0; xyz[(axis + 1) % 3] = q[kk][0]; xyz[(axis + 2) % 3] = q[kk][1];
                    int id = (xyz[0] * (n + 1) + xyz[1]) * (n + 1) + xyz[2];
                    if (key[id] < 0) {
                        double x = 2.0 * xyz[0] / n - 1.0, y = 2.0 * xyz[1] / n - 1.0, z = 2.0 * xyz[2] / n - 1.0, l = std::sqrt(x * x + y * y + z * z);
                        key[id] = (int)p.size() / 3;
                        p.push_back((float)(x / l)); p.push_back((float)(y / l)); p.push_back((float)(z / l));
                    }
                    fv.push_back(key[id]);
                }
                sizes.push_back(4);
            }
    }
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = (int)p.size() / 3; d.positions = p.data();
    d.face_count = (int)sizes.size(); d.face_sizes = sizes.data(); d.face_vertices = fv.data();
    sfb_mesh *m = NULL;
    if (sfb_mesh_create(ctx, &d, &m) != SFB_SUCCESS) return NULL;
    return m;
}

/* The seed's own setting: the vertex-shader draw path (sfb_surface_draw_gl) on an EGL context
 * of our own, into a 512 x 512 framebuffer, 30 x 30 samples per face (rate 29), glFinish per
 * frame; frames/s over 20 frames after 2 warm-up frames. */
static void manifold_draw_row(const char *name, int kind, int a, int b) {
    HostGL host;
    if (!host.open()) { printf("%-14s %6s %-8s skipped: %s\n", name, "", "gl-draw", host.why.c_str()); return; }
    std::string why;
    sfb_context *ctx = eval_context(SFB_BACKEND_GL, 0, 1, &why);
    if (!ctx) { printf("%-14s %6s %-8s skipped: %s\n", name, "", "gl-draw", why.c_str()); return; }
    sfb_mesh *mesh = NULL;
    if (kind == 0) {
        std::string text;
        if (read_text("../shared/peers/opensubdiv-shapes/catmark_torus.obj", &text)) {
            if (sfb_mesh_read_obj(ctx, text.data(), text.size(), &mesh) != SFB_SUCCESS) mesh = NULL;
        } else mesh = bench_torus_mesh(ctx, 4, 8);
    } else if (kind == 1) mesh = bench_torus_mesh(ctx, a, b);
    else mesh = bench_sphere_cube(ctx, a);
    sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_MANIFOLD_BLEND, 0);
    cfg.flags = SFB_REFINE_PATCHES;
    sfb_surface *surf = NULL;
    GLuint fbo = 0, rb[2] = {0, 0};
    if (!mesh || sfb_surface_create(ctx, mesh, &cfg, &surf) != SFB_SUCCESS) {
        printf("%-14s %6s %-8s failed: %s\n", name, "", "gl-draw", sfb_last_error(ctx));
    } else {
        glGenFramebuffers(1, &fbo);
        glGenRenderbuffers(2, rb);
        glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 512, 512);
        glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, 512, 512);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
        glViewport(0, 0, 512, 512);
        glEnable(GL_DEPTH_TEST);
        sfb_gl_draw_params dp = sfb_gl_draw_params_init();
        dp.rate = 29;
        /* a uniform scale that fits the meshes (all within radius 4) into the clip cube */
        for (int i = 0; i < 16; ++i) dp.mvp[i] = 0.0f;
        dp.mvp[0] = dp.mvp[5] = dp.mvp[10] = 0.2f; dp.mvp[15] = 1.0f;
        int nf = sfb_surface_param_face_count(surf), ok = 1;
        double best = 1e30;
        for (int frame = 0; frame < 22 && ok; ++frame) {
            Clock::time_point t0 = Clock::now();
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            if (sfb_surface_draw_gl(surf, &dp) != SFB_SUCCESS) { ok = 0; break; }
            glFinish();
            if (frame >= 2) best = std::min(best, ms_since(t0));
        }
        if (!ok) printf("%-14s %6s %-8s failed: %s\n", name, "", "gl-draw", sfb_last_error(ctx));
        else {
            size_t pts = (size_t)nf * 900;
            printf("%-14s %6d %-8s %10zu %12.3f %12.1f %10.1f   (vertex-shader draw path, 512x512, %s)\n", name, nf, "gl-draw", pts, best,
                   pts / best / 1000.0, 1000.0 / best, host.renderer.c_str());
        }
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &fbo);
        glDeleteRenderbuffers(2, rb);
    }
    if (surf) sfb_surface_destroy(surf);
    if (mesh) sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
}

static int manifold_section() {
    const sfb_backend_kind kinds[4] = {SFB_BACKEND_REF, SFB_BACKEND_SIMD, SFB_BACKEND_GL, SFB_BACKEND_OSMESA};
    struct Case { const char *name; int kind; int a, b; const char *seed; };
    const Case cases[] = {{"torus32", 0, 0, 0, "(a) 32 faces: CPU 25.40 fps, GPU 438.2 fps"},
                          {"torus180", 1, 10, 18, "(c) 179 faces: CPU 3.84 fps, GPU 73.0 fps"},
                          {"torus442", 1, 13, 34, "(e) 442 faces: CPU 1.48 fps, GPU 30.1 fps"},
                          {"spherecube486", 2, 9, 0, "-"}};
    int status = 0;
    printf("\n== manifold blending (seed 000 Table 3 setting): 30x30 samples per face, positions + normals via sfb_surface_eval\n");
    printf("%-14s %6s %-8s %10s %12s %12s %10s   %s\n", "mesh", "faces", "backend", "points", "ms/frame", "Mpoints/s", "frames/s",
           "seed's figures for that size");
    for (const Case &c : cases) {
        double ref_ms = 0.0;
        for (sfb_backend_kind kind : kinds) {
            std::string why;
            sfb_context *ctx = eval_context(kind, 0, 0, &why);
            if (!ctx) { printf("%-14s %6s %-8s skipped: %s\n", c.name, "", sfb_backend_kind_name(kind), why.c_str()); continue; }
            sfb_mesh *mesh = NULL;
            if (c.kind == 0) {
                std::string text;
                if (read_text("../shared/peers/opensubdiv-shapes/catmark_torus.obj", &text)) {
                    if (sfb_mesh_read_obj(ctx, text.data(), text.size(), &mesh) != SFB_SUCCESS) mesh = NULL;
                } else mesh = bench_torus_mesh(ctx, 4, 8);
            } else if (c.kind == 1) mesh = bench_torus_mesh(ctx, c.a, c.b);
            else mesh = bench_sphere_cube(ctx, c.a);
            sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_MANIFOLD_BLEND, 0);
            cfg.flags = SFB_REFINE_PATCHES;
            sfb_surface *surf = NULL;
            if (!mesh || sfb_surface_create(ctx, mesh, &cfg, &surf) != SFB_SUCCESS) {
                printf("%-14s failed: %s\n", c.name, sfb_last_error(ctx));
                status = 1;
            } else {
                int nf = sfb_surface_param_face_count(surf);
                std::vector<sfb_location> locs;
                locs.reserve((size_t)nf * 900);
                for (int f = 0; f < nf; ++f)
                    for (int j = 0; j < 30; ++j)
                        for (int i = 0; i < 30; ++i) {
                            sfb_location l;
                            l.face = f; l.u = (float)(i / 29.0); l.v = (float)(j / 29.0);
                            locs.push_back(l);
                        }
                std::vector<float> P(locs.size() * 3), N(locs.size() * 3);
                sfb_eval_output o;
                memset(&o, 0, sizeof o);
                o.position = P.data(); o.normal = N.data();
                double best = 1e30;
                int reps = kind == SFB_BACKEND_REF ? 3 : 9;
                for (int rep = 0; rep < reps; ++rep) {
                    Clock::time_point t0 = Clock::now();
                    if (sfb_surface_eval(surf, locs.data(), (int)locs.size(), &o) != SFB_SUCCESS) { status = 1; break; }
                    best = std::min(best, ms_since(t0));
                }
                if (kind == SFB_BACKEND_REF) ref_ms = best;
                char ratio[32] = "";
                if (kind != SFB_BACKEND_REF && ref_ms > 0.0) snprintf(ratio, sizeof ratio, " (%.1fx ref)", ref_ms / best);
                printf("%-14s %6d %-8s %10zu %12.3f %12.1f %10.1f   %s%s\n", c.name, nf, sfb_backend_kind_name(kind), locs.size(), best,
                       locs.size() / best / 1000.0, 1000.0 / best, kind == SFB_BACKEND_REF ? c.seed : "", ratio);
            }
            if (surf) sfb_surface_destroy(surf);
            if (mesh) sfb_mesh_destroy(mesh);
            sfb_context_destroy(ctx);
        }
        manifold_draw_row(c.name, c.kind, c.a, c.b);
    }
    printf("(best of 9 runs, ref best of 3; simd target: >= 100 Mpoints/s and >= 8x ref on this machine. gl/osmesa include the\n"
           " upload of the locations and the read-back of the results; the seed's GPU figures are for its vertex-shader draw path)\n");
    return status;
}

/* Seed 003's analysis (sfb_surface_analyze): a 1024 x 1024 reflection-line picture of
 * catmark_car and of spot.obj as a Loop surface, per backend; the stages timed from the progress
 * reports (0.3: the proxy evaluated and rasterised, 0.75: every pixel projected and evaluated,
 * 0.9: shaded), best of 3; beside the polygon-based picture (the proxy's interpolated normals,
 * same pipeline without the projection) and the seed's Tables 1-2 (GeForce FX 5900 Ultra). */
struct AnalyzeClock { Clock::time_point t0, at[3]; };
static int analyze_progress(float done, const char *stage, void *user) {
    AnalyzeClock *c = (AnalyzeClock *)user;
    if (strcmp(stage, "analyze") != 0) return 0;
    if (done == 0.0f) c->t0 = Clock::now();
    else if (done == 0.3f) c->at[0] = Clock::now();
    else if (done == 0.75f) c->at[1] = Clock::now();
    else if (done == 0.9f) c->at[2] = Clock::now();
    return 0;
}
static int analyze_section() {
    struct Case { const char *label, *path; sfb_scheme scheme; int camera; };
    const Case cases[] = {{"catmark_car", "../shared/peers/opensubdiv-shapes/catmark_car.obj", SFB_SCHEME_CATMARK, 1},
                          {"spot (Loop)", "../shared/peers/real-meshes/spot.obj", SFB_SCHEME_LOOP, 0}};
    const sfb_backend_kind kinds[4] = {SFB_BACKEND_REF, SFB_BACKEND_SIMD, SFB_BACKEND_GL, SFB_BACKEND_OSMESA};
    int status = 0;
    printf("\n== surface analysis (seed 003): 1024 x 1024 reflection lines, exact per pixel, the default proxy level\n"
           "   (chosen from the view; \"L\": the level used); ms, best of 3\n");
    printf("%-12s %-9s %9s %2s %9s %10s %10s %10s %10s %9s\n", "mesh", "backend", "pixels", "L", "raster", "eval", "shade", "total",
           "polygon", "vs ref");
    for (const Case &c : cases) {
        std::string text;
        if (!read_text(c.path, &text)) { printf("%-12s skipped: %s not found\n", c.label, c.path); continue; }
        double ref_total = 0.0;
        for (sfb_backend_kind kind : kinds) {
            AnalyzeClock clk;
            sfb_context_config cfg = sfb_context_config_init();
            cfg.backends = &kind;
            cfg.backend_count = 1;
            cfg.ignore_environment = 1;
            cfg.progress.func = analyze_progress;
            cfg.progress.user = &clk;
            char info[512];
            sfb_context *ctx = NULL;
            if (sfb_backend_probe(kind, &cfg, info, sizeof info) != SFB_SUCCESS || sfb_context_create(&cfg, &ctx) != SFB_SUCCESS) {
                printf("%-12s %-9s skipped: %s\n", c.label, sfb_backend_kind_name(kind), info);
                continue;
            }
            sfb_mesh *mesh = NULL;
            sfb_surface *surf = NULL;
            sfb_surface_config sc = sfb_surface_config_init(c.scheme, 0);
            sc.flags = SFB_REFINE_PATCHES;
            if (sfb_mesh_read_obj(ctx, text.data(), text.size(), &mesh) != SFB_SUCCESS || sfb_surface_create(ctx, mesh, &sc, &surf) != SFB_SUCCESS) {
                printf("%-12s failed: %s\n", c.label, sfb_last_error(ctx));
                status = 1;
            } else {
                sfb_analyze_config ac = sfb_analyze_config_init(SFB_ANALYZE_REFLECTION);
                ac.width = ac.height = 1024;
                if (c.camera) {
                    const float eye[3] = {4.0f, -5.0f, 3.0f}, target[3] = {0.6f, -1.9f, 0.3f}, up[3] = {0.0f, 0.0f, 1.0f};
                    ac.camera_set = 1;
                    memcpy(ac.eye, eye, sizeof eye); memcpy(ac.target, target, sizeof target); memcpy(ac.up, up, sizeof up);
                }
                /* simd twice: as every backend, then with a workspace kept over the runs (the
                 * editor's case: its first run grows the buffers, the best of the others counts) */
                for (int with_ws = 0; with_ws < (kind == SFB_BACKEND_SIMD ? 2 : 1) && status == 0; ++with_ws) {
                    /* the polygon-based pictures keep their own workspace: their proxy is level 2
                     * (their default), the exact pictures' the one chosen from the view, and a
                     * workspace keeps one surface's proxy at one level */
                    sfb_analysis_workspace *ws = NULL, *ws_poly = NULL;
                    if (with_ws && (sfb_analysis_workspace_create(ctx, &ws) != SFB_SUCCESS || sfb_analysis_workspace_create(ctx, &ws_poly) != SFB_SUCCESS)) {
                        printf("%s\n", sfb_last_error(ctx));
                        sfb_analysis_workspace_destroy(ws);
                        status = 1;
                        break;
                    }
                    double best[4] = {1e30, 1e30, 1e30, 1e30}, poly = 1e30;
                    int pixels = 0, plevel = 0;
                    for (int rep = 0; rep < 3 + with_ws && status == 0; ++rep) {
                        sfb_analysis an;
                        ac.polygon_based = 0;
                        ac.workspace = ws;
                        if (sfb_surface_analyze(surf, &ac, &an) != SFB_SUCCESS) { printf("%s\n", sfb_last_error(ctx)); status = 1; break; }
                        Clock::time_point end = Clock::now();
                        pixels = an.covered_pixels;
                        plevel = an.proxy_level;
                        sfb_analysis_free(&an);
                        double st[4];
                        st[0] = std::chrono::duration<double, std::milli>(clk.at[0] - clk.t0).count();
                        st[1] = std::chrono::duration<double, std::milli>(clk.at[1] - clk.at[0]).count();
                        st[2] = std::chrono::duration<double, std::milli>(end - clk.at[1]).count();
                        st[3] = std::chrono::duration<double, std::milli>(end - clk.t0).count();
                        if (st[3] < best[3] && !(with_ws && rep == 0)) for (int k = 0; k < 4; ++k) best[k] = st[k];
                        ac.polygon_based = 1;
                        ac.workspace = ws_poly;
                        Clock::time_point t0 = Clock::now();
                        if (sfb_surface_analyze(surf, &ac, &an) != SFB_SUCCESS) { status = 1; break; }
                        if (!(with_ws && rep == 0)) poly = std::min(poly, ms_since(t0));
                        sfb_analysis_free(&an);
                    }
                    if (kind == SFB_BACKEND_REF) ref_total = best[3];
                    printf("%-12s %-9s %9d %2d %9.1f %10.1f %10.1f %10.1f %10.1f %8.2fx\n", c.label, with_ws ? "simd+ws" : sfb_backend_kind_name(kind), pixels,
                           plevel, best[0], best[1], best[2], best[3], poly, ref_total > 0.0 ? ref_total / best[3] : 0.0);
                    ac.workspace = NULL;
                    sfb_analysis_workspace_destroy(ws);
                    sfb_analysis_workspace_destroy(ws_poly);
                }
            }
            sfb_surface_destroy(surf);
            sfb_mesh_destroy(mesh);
            sfb_context_destroy(ctx);
        }
    }
    printf("(raster: proxy evaluated + rasterised into (face, u, v, depth); eval: every pixel projected onto the exact surface\n"
           " (Newton) and evaluated; shade: the shade kernel + colours; polygon: the same picture from the proxy's interpolated\n"
           " normals (its default level, 2), no projection. simd+ws: simd with an sfb_analysis_workspace kept over the runs\n"
           " (no buffer allocated or faulted in per picture, and the surface's proxy and face adjacency, which do not depend\n"
           " on the view, evaluated once: an editor redrawing any view of a surface gets this; simd shows a first picture).\n"
           " vs ref: ref's total / this total. Target: simd <= 50 ms total. Seed 003, Tables 1-2 (GeForce FX 5900 Ultra):\n"
           " 700 x 700 fragments 0.13 s positions + 0.52 s colours; parameters of 4800 faces 0.012 s)\n");
    return status;
}

/* Seed 002's rolling-ball fillets (sfb_mesh_fillet): the box-cylinder union's seam (a closed
 * concave curve between a plane and a cylinder, examples/fillet_shapes.h) at two resolutions --
 * about 8,500 triangles with a blend region of about 1,400 base-patch triangles (the seed's teapot
 * case, section 6.3: 1.52 s on a 1.7 GHz Pentium IV), and over 200,000 triangles. Stages timed
 * from the progress reports: setup (checks, face normals, work arrays: the whole mesh), curves
 * (base patches), spine (offsets, AABB trees, intersection, chaining, loops), surface (samples,
 * linkage, profiles), map + project (blend-region vertices), output (the new mesh: the whole
 * mesh). Best of 5. Target: <= 100 ms for the 8,500-triangle case. */
struct FilletClock { Clock::time_point t0, at[6]; };
static int fillet_progress(float done, const char *stage, void *user) {
    FilletClock *c = (FilletClock *)user;
    static const char *const names[5] = {"fillet curves", "fillet spine", "fillet surface", "fillet map", "fillet project"};
    for (int k = 0; k < 5; ++k)
        if (strcmp(stage, names[k]) == 0) {
            if (k == 4 && done == 1.0f) c->at[5] = Clock::now();
            else c->at[k] = Clock::now();
        }
    return 0;
}
static int fillet_section() {
    /* half: the box's half width -- the third case is the first's seam and blend region on a box
     * 12 times as wide (the mesh grows, the region does not) */
    struct Case { const char *label; int n; float radius, half; };
    const Case cases[] = {{"8.5k tris", 17, 0.14f, 1.0f}, {"200k+ tris", 110, 0.14f, 1.0f}, {"8.5k region", 17, 0.14f, 12.0f}};
    int status = 0;
    printf("\n== rolling-ball fillets (seed 002): box-cylinder seam, arc profile; ms, best of 5\n");
    printf("%-11s %8s %8s %7s %8s %7s %7s %8s %8s %8s %8s %8s\n", "mesh", "tris", "region", "moved", "setup", "curves", "spine",
           "surface", "map", "output", "total", "per-tri");
    for (const Case &c : cases) {
        fs_mesh fm;
        memset(&fm, 0, sizeof fm);
        FilletClock clk;
        sfb_context_config cfg = sfb_context_config_init();
        cfg.progress.func = fillet_progress;
        cfg.progress.user = &clk;
        sfb_context *ctx = NULL;
        sfb_mesh *in = NULL;
        if (fs_box_cylinder(&fm, c.n, c.half, 0.6f, 0.5f, 0.6f) != 0 || sfb_context_create(&cfg, &ctx) != SFB_SUCCESS ||
            fs_to_mesh(ctx, &fm, &in) != SFB_SUCCESS) {
            printf("%-11s failed to build the mesh\n", c.label);
            status = 1;
            fs_free(&fm);
            if (ctx) sfb_context_destroy(ctx);
            continue;
        }
        sfb_fillet_config fc = sfb_fillet_config_init(c.radius);
        sfb_fillet_curve curve;
        memset(&curve, 0, sizeof curve);
        curve.vertices = fm.loop;
        curve.count = fm.loop_count;
        fc.curves = &curve;
        fc.curve_count = 1;
        double best[7];
        for (int k = 0; k < 7; ++k) best[k] = 1e30;
        int moved = 0;
        for (int rep = 0; rep < 5; ++rep) {
            sfb_mesh *out = NULL;
            sfb_fillet_report fr;
            Clock::time_point t0 = Clock::now();
            if (sfb_mesh_fillet(ctx, in, &fc, &out, &fr) != SFB_SUCCESS) {
                printf("%-11s failed: %s\n", c.label, sfb_last_error(ctx));
                status = 1;
                break;
            }
            Clock::time_point end = Clock::now();
            moved = fr.vertices_moved;
            sfb_fillet_report_free(&fr);
            sfb_mesh_destroy(out);
            double st[7];
            st[0] = std::chrono::duration<double, std::milli>(clk.at[0] - t0).count();
            st[1] = std::chrono::duration<double, std::milli>(clk.at[1] - clk.at[0]).count();
            st[2] = std::chrono::duration<double, std::milli>(clk.at[2] - clk.at[1]).count();
            st[3] = std::chrono::duration<double, std::milli>(clk.at[3] - clk.at[2]).count();
            st[4] = std::chrono::duration<double, std::milli>(clk.at[5] - clk.at[3]).count();
            st[5] = std::chrono::duration<double, std::milli>(end - clk.at[5]).count();
            st[6] = std::chrono::duration<double, std::milli>(end - t0).count();
            if (st[6] < best[6]) for (int k = 0; k < 7; ++k) best[k] = st[k];
        }
        /* the base patches' size: faces within 1.75 r of the seam (what the operator works on) */
        int region = 0;
        for (int f = 0; f < fm.nf; ++f) {
            for (int k = 0; k < 3; ++k) {
                const float *p = fm.pos + 3 * fm.tri[3 * f + k];
                const double rr = sqrt((double)p[0] * p[0] + (double)p[1] * p[1]) - 0.5, z = p[2];
                const double dd = z >= 0 && rr >= 0 ? sqrt(rr * rr + z * z) : z >= 0 ? z : rr;
                if (fabs(dd) < 1.75 * c.radius && fabs(z) < 1.75 * c.radius && rr > -1e-6) { region++; break; }
            }
        }
        if (status == 0)
            printf("%-11s %8d %8d %7d %8.2f %7.2f %7.2f %8.2f %8.2f %8.2f %8.2f %7.1fus\n", c.label, fm.nf, region, moved, best[0], best[1],
                   best[2], best[3], best[4], best[5], best[6], 1000.0 * (best[1] + best[2] + best[3] + best[4]) / (region > 0 ? region : 1));
        sfb_mesh_destroy(in);
        sfb_context_destroy(ctx);
        fs_free(&fm);
    }
    printf("(region: base-patch triangles within 1.75 r of the seam; per-tri: curves + spine + surface + map per region\n"
           " triangle -- the part that grows with the blend region; setup and output touch the whole mesh. Seed 002, 6.3:\n"
           " 8,480 triangles, base patches of 1,423, 1.52 s on a 1.7 GHz Pentium IV. Target: <= 100 ms total for 8.5k)\n");
    return status;
}

static double bbox_diagonal(const TorusMesh &t) {
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    double d = 0.0;
    for (int i = 0; i < t.vertex_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            lo[c] = std::min(lo[c], t.positions[3 * (size_t)i + c]);
            hi[c] = std::max(hi[c], t.positions[3 * (size_t)i + c]);
        }
    for (int c = 0; c < 3; ++c) d += (double)(hi[c] - lo[c]) * (hi[c] - lo[c]);
    return std::sqrt(d);
}

/* A remeshed-looking triangle mesh: the torus nu x nv cut into triangles (every vertex of valence
 * 6), then a fraction `frac` of its edges flipped at random (a flip keeps valences in 4..8 and
 * never makes an edge twice), so that extraordinary vertices are everywhere and touch, as on
 * scanned or remeshed models. */
static TorusMesh flipped_torus(int nu, int nv, double frac, unsigned long long seed) {
    TorusMesh t(nu, nv);
    t.triangulate();
    t.crease_vertices.clear(); t.crease_sharpness.clear(); t.corner_vertices.clear(); t.corner_sharpness.clear();
    const int nf = t.face_count();
    std::vector<int> &fv = t.face_vertices;
    std::vector<int> val((size_t)t.vertex_count(), 0);
    std::map<std::pair<int, int>, std::vector<int> > edges; /* (low, high) -> its faces */
    auto key = [](int a, int b) { return std::make_pair(std::min(a, b), std::max(a, b)); };
    for (int f = 0; f < nf; ++f)
        for (int k = 0; k < 3; ++k) edges[key(fv[3 * f + k], fv[3 * f + (k + 1) % 3])].push_back(f);
    for (const auto &e : edges) { ++val[(size_t)e.first.first]; ++val[(size_t)e.first.second]; }
    std::vector<std::pair<int, int> > order;
    for (const auto &e : edges) order.push_back(e.first);
    SplitMix rng(seed);
    for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[(size_t)rng.below((int)i)]);
    const size_t want = (size_t)(frac * (double)order.size());
    size_t done = 0;
    for (size_t i = 0; i < order.size() && done < want; ++i) {
        auto it = edges.find(order[i]);
        if (it == edges.end() || it->second.size() != 2) continue;
        const int a = it->first.first, b = it->first.second, f0 = it->second[0], f1 = it->second[1];
        int c = -1, d = -1;
        for (int k = 0; k < 3; ++k) {
            if (fv[3 * f0 + k] != a && fv[3 * f0 + k] != b) c = fv[3 * f0 + k];
            if (fv[3 * f1 + k] != a && fv[3 * f1 + k] != b) d = fv[3 * f1 + k];
        }
        if (edges.count(key(c, d)) || val[(size_t)a] <= 4 || val[(size_t)b] <= 4 || val[(size_t)c] >= 8 || val[(size_t)d] >= 8) continue;
        /* f0 runs p -> q -> c with {p, q} = {a, b}: the new faces (c, p, d) and (d, q, c) */
        int k0 = 0;
        while (fv[3 * f0 + k0] == c) ++k0;
        const int p = fv[3 * f0 + k0], q = fv[3 * f0 + (k0 + 1) % 3] == c ? fv[3 * f0 + (k0 + 2) % 3] : fv[3 * f0 + (k0 + 1) % 3];
        const int pp = fv[3 * f0 + (k0 + 1) % 3] == c ? q : p, qq = pp == p ? q : p; /* pp -> qq is f0's order */
        const int n0[3] = {c, pp, d}, n1[3] = {d, qq, c};
        edges.erase(it);
        for (int k = 0; k < 3; ++k) { fv[3 * f0 + k] = n0[k]; fv[3 * f1 + k] = n1[k]; }
        /* the four outer edges: f0 keeps (c, pp) and takes (pp, d); f1 keeps (d, qq) and takes (qq, c) */
        std::vector<int> &e1 = edges[key(pp, d)], &e2 = edges[key(qq, c)];
        std::replace(e1.begin(), e1.end(), f1, f0);
        std::replace(e2.begin(), e2.end(), f0, f1);
        edges[key(c, d)] = {f0, f1};
        --val[(size_t)a]; --val[(size_t)b]; ++val[(size_t)c]; ++val[(size_t)d];
        ++done;
    }
    return t;
}

/* Issue 16's construction on meshes with extraordinary vertices everywhere, beside the torus row:
 * real models (../shared/peers/real-meshes) and the flipped torus; ms per 1,000 triangles, median
 * of 3, one thread (ref context) and all threads (simd), surfblend's Loop and OpenSubdiv's Loop
 * refine + patch table on the same mesh. */
static int tribezier_meshes_section() {
    struct Case { const char *label, *path; int nu, nv; };
    const Case cases[] = {{"cow", "../shared/peers/real-meshes/cow.obj", 0, 0},
                          {"spot", "../shared/peers/real-meshes/spot.obj", 0, 0},
                          {"teapot", "../shared/peers/real-meshes/teapot.obj", 0, 0},
                          {"flipped torus 60x40", NULL, 60, 40},
                          {"flipped torus 120x80", NULL, 120, 80}};
    int status = 0;
    std::string why, mt_why;
    sfb_context *rctx = eval_context(SFB_BACKEND_REF, 1, 0, &why), *mctx = eval_context(SFB_BACKEND_SIMD, 0, 0, &mt_why);
    printf("\ntribezier construction on meshes with extraordinary vertices everywhere (ms per 1,000 triangles, median of 3;\n"
           "'x OSD' = OpenSubdiv's / tribezier one thread; where extraordinary vertices of different valences touch, the net\n"
           "is built after one Loop step, 4 patches per triangle, or two, 16, where they come in groups of more than 8):\n");
    printf("%-22s %7s %6s %6s | %10s %10s %10s %10s | %6s\n", "mesh", "tris", "EVs", "solve", "tribezier", "simd all", "sfb Loop",
           "OSD Loop", "x OSD");
    for (const Case &c : cases) {
        if (!rctx) { printf("%-22s skipped: no ref context: %s\n", c.label, why.c_str()); break; }
        TorusMesh tm;
        sfb_mesh *m = NULL;
        if (c.path) {
            std::string text;
            if (!read_text(c.path, &text)) { printf("%-22s skipped: %s not found\n", c.label, c.path); continue; }
            sfb_mesh *fm = NULL;
            if (sfb_mesh_read_obj(rctx, text.data(), text.size(), &fm) != SFB_SUCCESS) {
                printf("%-22s failed: %s\n", c.label, sfb_last_error(rctx));
                status = 1;
                continue;
            }
            sfb_mesh_desc d;
            sfb_mesh_get_desc(fm, &d);
            tm.assign(d);
            sfb_mesh_destroy(fm);
        } else {
            tm = flipped_torus(c.nu, c.nv, 0.15, 0x7e57ull);
        }
        sfb_mesh_desc desc = tm.sfb_desc();
        desc.boundary = SFB_BOUNDARY_EDGE_ONLY;
        if (sfb_mesh_create(rctx, &desc, &m) != SFB_SUCCESS) { printf("%-22s failed: %s\n", c.label, sfb_last_error(rctx)); status = 1; continue; }
        sfb_mesh_info mi;
        sfb_mesh_get_info(m, &mi);
        sfb_surface_config tc = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0), lc = sfb_surface_config_init(SFB_SCHEME_LOOP, 0);
        tc.flags = lc.flags = SFB_REFINE_PATCHES;
        std::vector<double> t1, tl, tmt, to;
        int depth = 0;
        for (int rep = 0; rep < 3 && status == 0; ++rep) {
            sfb_surface *s = NULL;
            Clock::time_point t0 = Clock::now();
            if (sfb_surface_create(rctx, m, &tc, &s) != SFB_SUCCESS) { printf("%-22s failed: %s\n", c.label, sfb_last_error(rctx)); status = 1; break; }
            t1.push_back(ms_since(t0));
            sfb_patch_info pi;
            memset(&pi, 0, sizeof pi);
            sfb_surface_patch_info(s, &pi);
            depth = pi.max_depth;
            sfb_surface_destroy(s);
            s = NULL;
            t0 = Clock::now();
            if (sfb_surface_create(rctx, m, &lc, &s) == SFB_SUCCESS) tl.push_back(ms_since(t0));
            sfb_surface_destroy(s);
        }
        if (mctx && status == 0) {
            sfb_mesh *mm = NULL;
            if (sfb_mesh_create(mctx, &desc, &mm) == SFB_SUCCESS)
                for (int rep = 0; rep < 3; ++rep) {
                    sfb_surface *s = NULL;
                    Clock::time_point t0 = Clock::now();
                    if (sfb_surface_create(mctx, mm, &tc, &s) != SFB_SUCCESS) break;
                    tmt.push_back(ms_since(t0));
                    sfb_surface_destroy(s);
                }
            sfb_mesh_destroy(mm);
        }
        OsdPatches osd;
        for (int rep = 0; rep < 3; ++rep) {
            Clock::time_point t0 = Clock::now();
            if (!osd.build_patches(tm, false, Sdc::SCHEME_LOOP)) break;
            to.push_back(ms_since(t0));
        }
        sfb_mesh_destroy(m);
        if (t1.empty()) continue;
        const double k = 1000.0 / mi.triangles, a = median(t1), o = to.empty() ? 0.0 : median(to);
        printf("%-22s %7d %6d %6s | %10.2f", c.label, mi.triangles, mi.extraordinary_loop, depth == 2 ? "Loop 2" : depth == 1 ? "Loop 1" : "mesh", a * k);
        for (const std::vector<double> *v : {&tmt, &tl, &to}) {
            if (v->empty()) printf(" %10s", "-");
            else printf(" %10.2f", median(*v) * k);
        }
        printf(" | %6.2f\n", o > 0 && a > 0 ? o / a : 0.0);
        fflush(stdout);
    }
    if (mctx) printf("(simd all: %s)\n", mt_why.c_str());
    sfb_context_destroy(rctx);
    sfb_context_destroy(mctx);
    return status;
}

/* The slider (sfb_surface_set_sharpness) against a rebuild for each new s, on the real models
 * with their edges over 40 degrees made creases (sfb_mesh_crease_by_angle) and on the seed-style
 * crease disk of examples/data: the build with the slider (both nets kept), the build without it
 * at one s (what a rebuild per slider move costs), one move (median of 9, s from 0.1 to 0.9), one
 * crease moved (sfb_surface_set_feature_sharpness, the same), all on the simd backend with its
 * threads; the patch memory with and without the slider. */
static int tribezier_slider_section() {
    struct Case { const char *label, *path; float angle; };
    const Case cases[] = {{"cow (40 deg creases)", "../shared/peers/real-meshes/cow.obj", 40.0f},
                          {"spot (40 deg creases)", "../shared/peers/real-meshes/spot.obj", 40.0f},
                          {"teapot (40 deg creases)", "../shared/peers/real-meshes/teapot.obj", 40.0f},
                          {"crease disk, valence 5", "examples/data/tribezier_crease_v5.obj", 0.0f}};
    std::string why;
    sfb_context *ctx = eval_context(SFB_BACKEND_SIMD, 0, 0, &why);
    int status = 0;
    printf("\ntribezier sharpness slider: sfb_surface_set_sharpness against a rebuild per move (ms, simd, all threads;\n"
           "'x' = rebuild / move; memory: the patch table without and with the slider's two nets):\n");
    printf("%-24s %7s %7s | %10s %10s %10s %8s %10s | %9s %9s\n", "mesh", "tris", "creases", "build+nets", "rebuild", "move", "x", "one crease",
           "MB", "MB slider");
    if (!ctx) { printf("skipped: no simd context: %s\n", why.c_str()); return 0; }
    for (const Case &c : cases) {
        std::string text;
        if (!read_text(c.path, &text)) { printf("%-24s skipped: %s not found\n", c.label, c.path); continue; }
        sfb_mesh *m0 = NULL, *m = NULL;
        int added = 0;
        if (sfb_mesh_read_obj(ctx, text.data(), text.size(), &m0) != SFB_SUCCESS ||
            (c.angle > 0.0f ? sfb_mesh_crease_by_angle(ctx, m0, c.angle, &m, &added) : SFB_SUCCESS) != SFB_SUCCESS) {
            printf("%-24s failed: %s\n", c.label, sfb_last_error(ctx));
            sfb_mesh_destroy(m0);
            status = 1;
            continue;
        }
        if (!m) { m = m0; m0 = NULL; }
        sfb_mesh_info mi;
        sfb_mesh_get_info(m, &mi);
        sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_TRIBEZIER, 0);
        cfg.flags = SFB_REFINE_PATCHES;
        cfg.tribezier.sharpness_set = 1;
        cfg.tribezier.sharpness = 0.5f;
        sfb_surface *plain = NULL, *sl = NULL;
        Clock::time_point t0 = Clock::now();
        sfb_result r = sfb_surface_create(ctx, m, &cfg, &plain);
        const double rebuild = ms_since(t0);
        cfg.tribezier.slider = 1;
        t0 = Clock::now();
        if (r == SFB_SUCCESS) r = sfb_surface_create(ctx, m, &cfg, &sl);
        const double build = ms_since(t0);
        std::vector<double> moves;
        for (int i = 1; i <= 9 && r == SFB_SUCCESS; ++i) {
            sfb_tribezier_options to;
            memset(&to, 0, sizeof to);
            to.sharpness_set = 1;
            to.sharpness = 0.1f * (float)i;
            t0 = Clock::now();
            r = sfb_surface_set_sharpness(sl, &to);
            moves.push_back(ms_since(t0));
        }
        // one crease moved (sfb_surface_set_feature_sharpness), median of 9
        std::vector<double> ones;
        sfb_mesh_desc md;
        sfb_mesh_get_desc(m, &md);
        for (int i = 1; i <= 9 && r == SFB_SUCCESS && md.crease_count > 0; ++i) {
            const float v = 0.1f * (float)i;
            t0 = Clock::now();
            r = sfb_surface_set_feature_sharpness(sl, 1, md.crease_vertices, &v, 0, NULL, NULL);
            ones.push_back(ms_since(t0));
        }
        if (r != SFB_SUCCESS) {
            printf("%-24s failed: %s\n", c.label, sfb_last_error(ctx));
            status = 1;
        } else {
            sfb_patch_info p0, p1;
            sfb_surface_patch_info(plain, &p0);
            sfb_surface_patch_info(sl, &p1);
            const double mv = median(moves);
            printf("%-24s %7d %7d | %10.1f %10.1f %10.3f %8.0f %10.3f | %9.1f %9.1f\n", c.label, mi.triangles, mi.sharp_edges, build, rebuild, mv,
                   mv > 0 ? rebuild / mv : 0.0, ones.empty() ? 0.0 : median(ones), p0.bytes / 1048576.0, p1.bytes / 1048576.0);
        }
        fflush(stdout);
        sfb_surface_destroy(plain);
        sfb_surface_destroy(sl);
        sfb_mesh_destroy(m);
        sfb_mesh_destroy(m0);
    }
    sfb_context_destroy(ctx);
    return status;
}

int main(int argc, char **argv) {
    int max_level = 4;
    bool limit_only = false;
#ifdef __GLIBC__
    /* One allocator state for every section, whatever ran before it: glibc otherwise maps large
     * blocks afresh and trims the heap after frees until its thresholds adapt, so a build that
     * allocates a lot pays page faults that depend on the sections before it (OpenSubdiv's Loop
     * patch table of the tribezier torus took 2.4 s in `bench --tribezier` and 0.53 s after the
     * other sections). Both libraries run under the same settings. */
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
    if (argc > 1 && strcmp(argv[1], "--shade") == 0) return shade_section();
    if (argc > 1 && strcmp(argv[1], "--manifold") == 0) return manifold_section();
    if (argc > 1 && strcmp(argv[1], "--analyze") == 0) return analyze_section();
    if (argc > 1 && strcmp(argv[1], "--fillet") == 0) return fillet_section();
    if (argc > 1 && strcmp(argv[1], "--tribezier-meshes") == 0) return tribezier_meshes_section();
    if (argc > 1 && strcmp(argv[1], "--tribezier-slider") == 0) return tribezier_slider_section();
    if (argc > 1 && strcmp(argv[1], "--tribezier") == 0) {
        TorusMesh t(100, 60);
        int st = limit_section(bbox_diagonal(t), LIMIT_TRIBEZIER);
        if (tribezier_meshes_section() != 0) st = 1;
        if (tribezier_slider_section() != 0) st = 1;
        return st;
    }
    if (argc > 1) {
        limit_only = strcmp(argv[1], "--limit") == 0;
        max_level = limit_only ? 0 : atoi(argv[1]);
        if (argc > 2 || (!limit_only && (max_level < 1 || max_level > 6))) {
            fprintf(stderr, "usage: bench [MAX_LEVEL 1..6, default 4 | --limit (the limit evaluation section alone) | --shade (the shading section alone) | --manifold (the manifold blending section alone) | --tribezier (the tribezier section alone) | --tribezier-meshes (its real and remeshed meshes alone) | --tribezier-slider (its slider rows alone) | --analyze (the analysis section alone) | --fillet (the fillet section alone)]\n");
            return 2;
        }
    }
    Clock::time_point t_start = Clock::now();

    sfb_context_config cc = sfb_context_config_init();
    sfb_context *ctx = NULL;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) {
        fprintf(stderr, "bench: sfb_context_create failed\n");
        return 1;
    }

    TorusMesh torus(100, 60);
    sfb_mesh_desc desc = torus.sfb_desc();
    const double diag = bbox_diagonal(torus);
    const double tol = 1e-6 * diag; /* as in tests/osd_agree.cpp */
    if (limit_only) {
        sfb_context_destroy(ctx);
        int st = limit_section(diag, LIMIT_CATMARK);
        if (limit_section(diag, LIMIT_LOOP) != 0) st = 1;
        if (limit_section(diag, LIMIT_TRIBEZIER) != 0) st = 1;
        printf("total time %.1f s\n", ms_since(t_start) / 1000.0);
        return st;
    }

    printf("surfblend %d.%d.%d vs OpenSubdiv 3.5, Catmull-Clark uniform refinement\n", SFB_VERSION_MAJOR,
           SFB_VERSION_MINOR, SFB_VERSION_PATCH);
    printf("mesh: torus %d x %d = %d quads, %d vertices, %d crease edges (1.5, 2.5, infinite), %d corner\n",
           torus.nu, torus.nv, torus.face_count(), torus.vertex_count(), torus.crease_count(),
           (int)torus.corner_vertices.size());
    printf("surfblend backend: %s (threads: %s); OpenSubdiv: Osd::CpuEvaluator (single thread)\n",
           sfb_context_backend_name(ctx), cc.threads ? "as configured" : "one per core");
    printf("build = topology + refinement + stencil table base -> level; sfb build includes sfb_mesh_create,\n"
           "sfb surf = sfb_surface_create alone. Times: median of several runs, milliseconds.\n\n");
    fflush(stdout);

    std::vector<Row> rows;
    int status = 0;
    for (int level = 1; level <= max_level; ++level) {
        Row row;
        memset(&row, 0, sizeof row);
        row.level = level;
        const int build_reps = level <= 2 ? 7 : (level == 3 ? 5 : 3);
        const int apply_reps = level <= 3 ? 11 : 5;
        const double budget_ms = 8000.0; /* per measurement: stop repeating past this (at least one run) */

        /* surfblend build */
        std::vector<double> tb, ts;
        sfb_surface *surf = NULL;
        double spent = 0.0;
        for (int rep = 0; rep < build_reps && (rep == 0 || spent < budget_ms); ++rep) {
            if (surf) { sfb_surface_destroy(surf); surf = NULL; }
            sfb_mesh *mesh = NULL;
            Clock::time_point t0 = Clock::now();
            sfb_result r = sfb_mesh_create(ctx, &desc, &mesh);
            double t_mesh = ms_since(t0);
            if (r != SFB_SUCCESS) {
                fprintf(stderr, "bench: sfb_mesh_create failed: %s\n", sfb_last_error(ctx));
                sfb_context_destroy(ctx);
                return 1;
            }
            sfb_surface_config cfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, level);
            Clock::time_point t1 = Clock::now();
            r = sfb_surface_create(ctx, mesh, &cfg, &surf);
            double t_surf = ms_since(t1);
            sfb_mesh_destroy(mesh);
            if (r != SFB_SUCCESS) {
                fprintf(stderr, "bench: sfb_surface_create (level %d) failed: %s\n", level, sfb_last_error(ctx));
                sfb_context_destroy(ctx);
                return 1;
            }
            tb.push_back(t_mesh + t_surf);
            ts.push_back(t_surf);
            spent += t_mesh + t_surf;
        }
        row.sfb_build = median(tb);
        row.sfb_surface = median(ts);

        /* OpenSubdiv build */
        std::vector<double> to;
        Far::StencilTable const *table = NULL;
        spent = 0.0;
        for (int rep = 0; rep < build_reps && (rep == 0 || spent < budget_ms); ++rep) {
            delete table;
            Clock::time_point t0 = Clock::now();
            table = osd_build(torus, level);
            double t = ms_since(t0);
            if (!table) {
                fprintf(stderr, "bench: OpenSubdiv could not build level %d\n", level);
                sfb_surface_destroy(surf);
                sfb_context_destroy(ctx);
                return 1;
            }
            to.push_back(t);
            spent += t;
        }
        row.osd_build = median(to);

        /* table sizes */
        sfb_stencil_info info;
        memset(&info, 0, sizeof info);
        if (sfb_surface_stencil_info(surf, SFB_TABLE_VERTEX, &info) != SFB_SUCCESS) {
            fprintf(stderr, "bench: sfb_surface_stencil_info failed: %s\n", sfb_last_error(ctx));
            status = 1;
        }
        row.rows_sfb = info.rows;
        row.entries_sfb = info.entries;
        row.rows_osd = table->GetNumStencils();
        row.entries_osd = (long long)table->GetWeights().size();
        row.faces_out = torus.face_count() << (2 * level);

        /* apply */
        std::vector<float> dst_sfb((size_t)std::max(info.rows, 0) * 3), dst_osd((size_t)row.rows_osd * 3);
        sfb_buffer_desc bd;
        bd.offset = 0;
        bd.length = 3;
        bd.stride = 3;
        std::vector<double> ta, tao;
        for (int rep = 0; rep < apply_reps; ++rep) {
            Clock::time_point t0 = Clock::now();
            sfb_result r = sfb_surface_eval_stencils(surf, SFB_TABLE_VERTEX, &torus.positions[0], bd,
                                                     dst_sfb.empty() ? NULL : &dst_sfb[0], bd);
            ta.push_back(ms_since(t0));
            if (r != SFB_SUCCESS) {
                fprintf(stderr, "bench: sfb_surface_eval_stencils failed: %s\n", sfb_last_error(ctx));
                status = 1;
                break;
            }
        }
        for (int rep = 0; rep < apply_reps; ++rep) {
            Clock::time_point t0 = Clock::now();
            osd_apply(table, &torus.positions[0], &dst_osd[0]);
            tao.push_back(ms_since(t0));
        }
        row.sfb_apply = median(ta);
        row.osd_apply = median(tao);

        row.max_diff = point_set_difference(dst_osd, dst_sfb, tol, &row.unmatched);
        if (row.unmatched) status = 1;

        rows.push_back(row);
        delete table;
        sfb_surface_destroy(surf);
        fprintf(stderr, "level %d done (%.1f s so far)\n", level, ms_since(t_start) / 1000.0);
    }

    printf("%5s | %9s | %12s | %11s | %12s | %7s | %12s | %12s | %7s | %s\n", "level", "faces out",
           "sfb build ms", "sfb surf ms", "osd build ms", "osd/sfb", "sfb apply ms", "osd apply ms", "osd/sfb",
           "stencil entries sfb/osd");
    for (size_t i = 0; i < rows.size(); ++i) {
        const Row &r = rows[i];
        char entries[64];
        snprintf(entries, sizeof entries, "%lld/%lld", r.entries_sfb, r.entries_osd);
        printf("%5d | %9d | %12.2f | %11.2f | %12.2f | %7.2f | %12.3f | %12.3f | %7.2f | %s\n", r.level,
               r.faces_out, r.sfb_build, r.sfb_surface, r.osd_build, r.sfb_build > 0 ? r.osd_build / r.sfb_build : 0.0,
               r.sfb_apply, r.osd_apply, r.sfb_apply > 0 ? r.osd_apply / r.sfb_apply : 0.0, entries);
    }
    printf("\nagreement (refined points matched as point sets, tolerance %.3g):\n", tol);
    for (size_t i = 0; i < rows.size(); ++i) {
        const Row &r = rows[i];
        printf("  level %d: rows sfb %d / osd %d, max difference %.3g, %d unmatched%s\n", r.level, r.rows_sfb,
               r.rows_osd, r.max_diff, r.unmatched, r.unmatched ? "  <-- DISAGREE" : "");
    }
    sfb_context_destroy(ctx);
    if (eval_section(torus, diag) != 0) status = 1;
    if (limit_section(diag, LIMIT_CATMARK) != 0) status = 1;
    if (limit_section(diag, LIMIT_LOOP) != 0) status = 1;
    if (limit_section(diag, LIMIT_TRIBEZIER) != 0) status = 1;
    if (tribezier_meshes_section() != 0) status = 1;
    if (tribezier_slider_section() != 0) status = 1;
    if (shade_section() != 0) status = 1;
    if (manifold_section() != 0) status = 1;
    if (analyze_section() != 0) status = 1;
    if (fillet_section() != 0) status = 1;
    printf("total time %.1f s\n", ms_since(t_start) / 1000.0);
    return status;
}
