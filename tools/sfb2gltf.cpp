// sfb2gltf: a control mesh with sharp and semi-sharp edges in, a smooth, validator-clean glTF 2.0
// out (.glb, or .gltf + .bin), in one command.
//
//   sfb2gltf [options] IN.obj -o OUT.glb|OUT.gltf
//
// The pipeline (stages, as the progress bar names them):
//   read      the OBJ through the library's reader (every tag it knows: t crease, corner, hole,
//             interpolateboundary, ...); --crease-angle adds infinitely sharp creases on the
//             edges whose dihedral angle is over a limit (sfb_mesh_crease_by_angle, shared with
//             the surfblend CLI)
//   build     the surface of the scheme (sfb_surface_create)
//   evaluate  either uniform refinement to --level L with subdivision-shading normals (seed
//             001, sfb_surface_shade: vertices split along infinitely sharp creases, so hard
//             edges stay hard) or limit normals, or flat normals; or the exact limit surface
//             tessellated at --tess RATE (sfb_surface_tessellate, creases split) -- the manifold
//             blend is always tessellated
//   optimise  meshoptimizer: vertex cache, overdraw, vertex fetch (--no-optimize: off)
//   write     tinygltf: indexed triangles (uint16 where every index fits, else uint32),
//             POSITION with min/max, unit NORMAL, TEXCOORD_0 from the face-varying UVs (glTF's v
//             runs downwards: v' = 1 - v), a default PBR material; written to a temporary file
//             beside the output and renamed only when complete (no partial output)
//
// Exit status: 0 done, 1 failure (a one-line message naming the file and the problem), 2 usage.
#include <tiny_gltf.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <unistd.h>

#include "cli_common.h"

namespace {

const char *const kUsage =
    "usage: sfb2gltf [options] IN.obj -o OUT.glb|OUT.gltf\n"
    "\n"
    "Subdivides (or evaluates) a control mesh with creases and writes it as glTF 2.0: .glb by\n"
    "default, .gltf with a .bin beside it when OUT ends in .gltf or with --gltf.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE      the output file (required)\n"
    "  --gltf                 write .gltf + .bin (OUT's extension is kept; the .bin takes OUT's base name)\n"
    "  --scheme S             catmark, loop, bilinear or manifold (default: from the file name prefix\n"
    "                         loop_ or bilinear_, else catmark)\n"
    "  --level L              uniform refinement level 0..10 (default 3; not with --tess)\n"
    "  --tess RATE            the exact limit surface tessellated at RATE segments per parametric-face\n"
    "                         edge, 1..1024 (default for --scheme manifold: 16)\n"
    "  --tolerance T          with --tess: adaptive, each face the smallest rate <= RATE whose chordal\n"
    "                         error is within T (model units)\n"
    "  --normals N            shading (subdivision shading, seed 001: the default for catmark and loop),\n"
    "                         limit (exact limit normals; the default with --tess and for manifold) or\n"
    "                         flat (one normal per triangle; the default for bilinear)\n"
    "  --crease-angle DEG     edges whose dihedral angle is over DEG (0..180) become infinitely sharp creases\n"
    "  --trim MASK.png        with --tess: trim the surface by a mask over each parametric face (seed 000)\n"
    "  --backend NAME         ref, simd, gl or osmesa (default: the library's order)\n"
    "  --no-optimize          keep the evaluation's vertex and triangle order (no meshoptimizer passes)\n"
    "  --progress             a progress bar on stderr even when stderr is not a terminal\n"
    "  -q, --quiet            no summary line and no progress bar\n"
    "  -h, --help             this text\n"
    "  --version              the version\n";

// ------------------------------------------------------------------ options

enum NormalsMode { NORMALS_DEFAULT, NORMALS_SHADING, NORMALS_LIMIT, NORMALS_FLAT };

struct Options {
    const char *in = nullptr, *out = nullptr, *trim = nullptr, *backend = nullptr;
    bool gltf = false, optimize = true, quiet = false, progress = false;
    bool have_scheme = false, have_level = false, have_tess = false, have_tolerance = false, have_angle = false;
    sfb_scheme scheme = SFB_SCHEME_CATMARK;
    int level = 3, rate = 0;
    double tolerance = 0.0, angle = 0.0;
    NormalsMode normals = NORMALS_DEFAULT;
};

int usage_error(const char *fmt, ...) {
    va_list ap;
    char msg[512];
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    fprintf(stderr, "sfb2gltf: %s\n(sfb2gltf --help for the options)\n", msg);
    return 2;
}

bool parse_long(const char *s, long lo, long hi, long *out) {
    char *end = nullptr;
    if (!s || !*s) return false;
    long v = strtol(s, &end, 10);
    if (*end || v < lo || v > hi) return false;
    *out = v;
    return true;
}

bool parse_double(const char *s, double *out) {
    char *end = nullptr;
    if (!s || !*s) return false;
    double v = strtod(s, &end);
    if (*end || !std::isfinite(v)) return false;
    *out = v;
    return true;
}

// 0: parsed; 1: exit 0 (help, version); 2: usage error (printed).
int parse_args(int argc, char **argv, Options *o) {
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        auto value = [&](const char *name) -> const char * {
            if (i + 1 >= argc) return nullptr;
            (void)name;
            return argv[++i];
        };
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(kUsage, stdout);
            return 1;
        } else if (!strcmp(a, "--version")) {
            printf("sfb2gltf (surfblend %d.%d.%d)\n", SFB_VERSION_MAJOR, SFB_VERSION_MINOR, SFB_VERSION_PATCH);
            return 1;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            if (!(o->out = value(a))) return usage_error("%s needs a file name", a);
        } else if (!strcmp(a, "--gltf")) {
            o->gltf = true;
        } else if (!strcmp(a, "--scheme")) {
            const char *v = value(a);
            if (!v) return usage_error("--scheme needs a scheme name");
            if (!cli_scheme_from_name(v, &o->scheme) || !(sfb_scheme_caps(o->scheme) & (SFB_SCHEME_CAN_REFINE | SFB_SCHEME_CAN_EVAL)))
                return usage_error("unknown scheme '%s' (catmark, loop, bilinear, manifold)", v);
            o->have_scheme = true;
        } else if (!strcmp(a, "--level")) {
            long v;
            if (!parse_long(value(a), 0, 1000, &v)) return usage_error("--level needs a number >= 0");
            o->level = (int)v;
            o->have_level = true;
        } else if (!strcmp(a, "--tess")) {
            long v;
            if (!parse_long(value(a), 1, 1024, &v)) return usage_error("--tess needs a rate 1..1024");
            o->rate = (int)v;
            o->have_tess = true;
        } else if (!strcmp(a, "--tolerance")) {
            if (!parse_double(value(a), &o->tolerance) || !(o->tolerance > 0.0)) return usage_error("--tolerance needs a number > 0");
            o->have_tolerance = true;
        } else if (!strcmp(a, "--normals")) {
            const char *v = value(a);
            if (v && !strcmp(v, "shading")) o->normals = NORMALS_SHADING;
            else if (v && !strcmp(v, "limit")) o->normals = NORMALS_LIMIT;
            else if (v && !strcmp(v, "flat")) o->normals = NORMALS_FLAT;
            else return usage_error("--normals takes shading, limit or flat");
        } else if (!strcmp(a, "--crease-angle")) {
            if (!parse_double(value(a), &o->angle) || o->angle < 0.0 || o->angle > 180.0)
                return usage_error("--crease-angle needs degrees in 0..180");
            o->have_angle = true;
        } else if (!strcmp(a, "--trim")) {
            if (!(o->trim = value(a))) return usage_error("--trim needs a PNG file");
        } else if (!strcmp(a, "--backend")) {
            if (!(o->backend = value(a))) return usage_error("--backend needs a name (ref, simd, gl, osmesa)");
        } else if (!strcmp(a, "--no-optimize")) {
            o->optimize = false;
        } else if (!strcmp(a, "--progress")) {
            o->progress = true;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            o->quiet = true;
        } else if (a[0] == '-' && a[1]) {
            return usage_error("unknown option '%s'", a);
        } else if (!o->in) {
            o->in = a;
        } else {
            return usage_error("one input file only ('%s' and '%s')", o->in, a);
        }
    }
    if (!o->in) return usage_error("no input file");
    if (!o->out) return usage_error("no output file (-o OUT.glb)");
    if (!o->have_scheme) o->scheme = cli_scheme_for(o->in, 0, o->scheme);
    const unsigned caps = sfb_scheme_caps(o->scheme);
    const bool tess_only = !(caps & SFB_SCHEME_CAN_REFINE); // the manifold blend: evaluated, not refined
    if (tess_only && !o->have_tess) {
        o->have_tess = true;
        o->rate = 16;
    }
    if (o->have_tess && o->have_level) return usage_error("--level and --tess exclude each other (refine, or tessellate the limit)");
    if (o->have_tess && !(caps & SFB_SCHEME_CAN_EVAL))
        return usage_error("--tess needs a scheme with a limit surface (%s has none)", sfb_scheme_name(o->scheme));
    if (o->have_tolerance && !o->have_tess) return usage_error("--tolerance belongs to --tess");
    if (o->trim && !o->have_tess) return usage_error("--trim belongs to --tess (trimming cuts the tessellation)");
    if (o->normals == NORMALS_DEFAULT)
        o->normals = o->have_tess ? NORMALS_LIMIT : (caps & SFB_SCHEME_CAN_SHADE) ? NORMALS_SHADING : NORMALS_FLAT;
    if (o->normals == NORMALS_SHADING && o->have_tess)
        return usage_error("--normals shading belongs to refinement (--level); the tessellation has limit or flat normals");
    if (o->normals == NORMALS_SHADING && !(caps & SFB_SCHEME_CAN_SHADE))
        return usage_error("--normals shading needs catmark or loop (%s has no subdivision shading)", sfb_scheme_name(o->scheme));
    if (o->normals == NORMALS_LIMIT && !o->have_tess && !(caps & SFB_SCHEME_CAN_SHADE))
        return usage_error("--normals limit on %s needs --tess", sfb_scheme_name(o->scheme));
    return 0;
}

// ------------------------------------------------------------------ progress

// A one-line bar on stderr, redrawn at most every 50 ms: the stage, its share and the time.
struct Progress {
    bool on = false;
    const char *stage = "";
    int index = 0;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(), last;
    void begin(const char *name, int i) {
        stage = name;
        index = i;
        draw(0.0f, true);
    }
    void draw(float done, bool force) {
        if (!on) return;
        auto now = std::chrono::steady_clock::now();
        if (!force && now - last < std::chrono::milliseconds(50)) return;
        last = now;
        const int width = 30, filled = (int)(std::min(std::max(done, 0.0f), 1.0f) * width);
        char bar[width + 1];
        for (int k = 0; k < width; ++k) bar[k] = k < filled ? '#' : '.';
        bar[width] = 0;
        double secs = std::chrono::duration<double>(now - start).count();
        fprintf(stderr, "\r[%d/5] %-9s [%s] %3d%% %6.1f s", index, stage, bar, (int)(done * 100.0f + 0.5f), secs);
        fflush(stderr);
    }
    void end() {
        if (!on) return;
        draw(1.0f, true);
        fputc('\n', stderr);
        on = false;
    }
};

int progress_cb(float done, const char *, void *user) {
    static_cast<Progress *>(user)->draw(done, false);
    return 0;
}

// ------------------------------------------------------------------ the output mesh

struct OutMesh {
    std::vector<float> positions, normals, uvs; // xyz, xyz, uv per vertex (uvs empty: none)
    std::vector<unsigned> indices;              // 3 per triangle
};

void normalize3(float *n, const float *fallback) {
    double l = std::sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    if (l > 0.0 && std::isfinite(l)) {
        for (int c = 0; c < 3; ++c) n[c] = (float)(n[c] / l);
        // a float normal within 1e-7 of unit: the validator's check (|n| - 1 within 0.0005) holds
        return;
    }
    if (fallback) {
        double m = std::sqrt((double)fallback[0] * fallback[0] + (double)fallback[1] * fallback[1] + (double)fallback[2] * fallback[2]);
        if (m > 0.0 && std::isfinite(m)) {
            for (int c = 0; c < 3; ++c) n[c] = (float)(fallback[c] / m);
            return;
        }
    }
    n[0] = 0.0f; n[1] = 0.0f; n[2] = 1.0f;
}

// The (unnormalised) normal of triangle a b c.
void tri_normal(const float *a, const float *b, const float *c, float *n) {
    const double u[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
    const double v[3] = {(double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2]};
    n[0] = (float)(u[1] * v[2] - u[2] * v[1]);
    n[1] = (float)(u[2] * v[0] - u[0] * v[2]);
    n[2] = (float)(u[0] * v[1] - u[1] * v[0]);
}

// Refined (or shaded) faces into glTF vertices: one per (vertex, UV) pair a face corner uses, so
// that a UV seam splits a vertex and nothing else does; polygons fan-triangulated from their
// first corner; holes skipped. normals: per vertex (NULL with flat: one per triangle, vertices
// then split per triangle).
void mesh_from_faces(const sfb_mesh_data &d, const float *normals, bool flat, OutMesh *m) {
    std::vector<char> hole((size_t)d.face_count + 1, 0);
    for (int h = 0; h < d.hole_count; ++h)
        if (d.holes[h] >= 0 && d.holes[h] < d.face_count) hole[(size_t)d.holes[h]] = 1;
    const bool uvs = d.uvs && d.face_uvs && d.uv_count > 0;
    std::unordered_map<unsigned long long, unsigned> seen;
    auto emit = [&](int fvi, const float *flat_n) -> unsigned {
        const int v = d.face_vertices[fvi], t = uvs ? d.face_uvs[fvi] : 0;
        const unsigned long long key = ((unsigned long long)(unsigned)v << 32) | (unsigned)t;
        if (!flat) {
            auto it = seen.find(key);
            if (it != seen.end()) return it->second;
        }
        const unsigned id = (unsigned)(m->positions.size() / 3);
        for (int c = 0; c < 3; ++c) m->positions.push_back(d.positions[3 * (size_t)v + c]);
        float n[3];
        const float *src = flat ? flat_n : normals + 3 * (size_t)v;
        for (int c = 0; c < 3; ++c) n[c] = src[c];
        normalize3(n, flat_n);
        m->normals.insert(m->normals.end(), n, n + 3);
        if (uvs) {
            m->uvs.push_back(d.uvs[2 * (size_t)t]);
            m->uvs.push_back(1.0f - d.uvs[2 * (size_t)t + 1]);
        }
        if (!flat) seen.emplace(key, id);
        return id;
    };
    int at = 0;
    for (int f = 0; f < d.face_count; at += d.face_sizes[f], ++f) {
        if (hole[(size_t)f]) continue;
        const int k = d.face_sizes[f];
        for (int i = 1; i + 1 < k; ++i) {
            const int c[3] = {at, at + i, at + i + 1};
            float fn[3];
            tri_normal(d.positions + 3 * (size_t)d.face_vertices[c[0]], d.positions + 3 * (size_t)d.face_vertices[c[1]],
                       d.positions + 3 * (size_t)d.face_vertices[c[2]], fn);
            for (int j = 0; j < 3; ++j) m->indices.push_back(emit(c[j], fn));
        }
    }
}

// A tessellation into glTF vertices (flat: split per triangle, normals from the triangles).
void mesh_from_tess(const sfb_tess_data &t, bool flat, OutMesh *m) {
    if (!flat) {
        m->positions.assign(t.positions, t.positions + 3 * (size_t)t.vertex_count);
        m->normals.assign(t.normals, t.normals + 3 * (size_t)t.vertex_count);
        m->indices.assign(t.triangles, t.triangles + 3 * (size_t)t.triangle_count);
        for (int i = 0; i < t.triangle_count; ++i) {
            float fn[3];
            const int *c = t.triangles + 3 * (size_t)i;
            tri_normal(t.positions + 3 * (size_t)c[0], t.positions + 3 * (size_t)c[1], t.positions + 3 * (size_t)c[2], fn);
            for (int j = 0; j < 3; ++j) normalize3(&m->normals[3 * (size_t)c[j]], fn);
        }
        return;
    }
    for (int i = 0; i < t.triangle_count; ++i) {
        const int *c = t.triangles + 3 * (size_t)i;
        float fn[3];
        tri_normal(t.positions + 3 * (size_t)c[0], t.positions + 3 * (size_t)c[1], t.positions + 3 * (size_t)c[2], fn);
        normalize3(fn, nullptr);
        for (int j = 0; j < 3; ++j) {
            m->indices.push_back((unsigned)(m->positions.size() / 3));
            for (int q = 0; q < 3; ++q) m->positions.push_back(t.positions[3 * (size_t)c[j] + q]);
            m->normals.insert(m->normals.end(), fn, fn + 3);
        }
    }
}

// Drops triangles with a repeated index (meshoptimizer and the validator dislike them; a
// subdivided pole can make them) and vertices with a non-finite position.
void drop_degenerate(OutMesh *m) {
    std::vector<unsigned> kept;
    kept.reserve(m->indices.size());
    const size_t nv = m->positions.size() / 3;
    for (size_t i = 0; i + 2 < m->indices.size(); i += 3) {
        const unsigned a = m->indices[i], b = m->indices[i + 1], c = m->indices[i + 2];
        if (a == b || b == c || a == c || a >= nv || b >= nv || c >= nv) continue;
        bool finite = true;
        for (unsigned v : {a, b, c})
            for (int q = 0; q < 3; ++q) finite = finite && std::isfinite(m->positions[3 * (size_t)v + q]);
        if (!finite) continue;
        kept.push_back(a); kept.push_back(b); kept.push_back(c);
    }
    m->indices.swap(kept);
}

// meshoptimizer's passes: unused vertices dropped and the rest in first-use order (vertex
// fetch), triangles for the post-transform cache, then for overdraw.
void optimize_mesh(OutMesh *m) {
    const size_t nv = m->positions.size() / 3, ni = m->indices.size();
    if (ni == 0 || nv == 0) return;
    meshopt_optimizeVertexCache(m->indices.data(), m->indices.data(), ni, nv);
    meshopt_optimizeOverdraw(m->indices.data(), m->indices.data(), ni, m->positions.data(), nv, 3 * sizeof(float), 1.05f);
    std::vector<unsigned> remap(nv);
    const size_t nu = meshopt_optimizeVertexFetchRemap(remap.data(), m->indices.data(), ni, nv);
    meshopt_remapIndexBuffer(m->indices.data(), m->indices.data(), ni, remap.data());
    auto remap_stream = [&](std::vector<float> &s, size_t comps) {
        if (s.empty()) return;
        std::vector<float> o(nu * comps);
        meshopt_remapVertexBuffer(o.data(), s.data(), nv, comps * sizeof(float), remap.data());
        s.swap(o);
    };
    remap_stream(m->positions, 3);
    remap_stream(m->normals, 3);
    remap_stream(m->uvs, 2);
}

// Without the optimiser: unused vertices still go (the validator warns on unused data), order kept.
void compact_mesh(OutMesh *m) {
    const size_t nv = m->positions.size() / 3;
    std::vector<unsigned> remap(nv, ~0u);
    unsigned next = 0;
    for (unsigned &i : m->indices) {
        if (remap[i] == ~0u) remap[i] = next++;
        i = remap[i];
    }
    if (next == nv) return;
    auto squeeze = [&](std::vector<float> &s, size_t comps) {
        if (s.empty()) return;
        std::vector<float> o((size_t)next * comps);
        for (size_t v = 0; v < nv; ++v)
            if (remap[v] != ~0u) std::copy(&s[v * comps], &s[v * comps] + comps, &o[(size_t)remap[v] * comps]);
        s.swap(o);
    };
    squeeze(m->positions, 3);
    squeeze(m->normals, 3);
    squeeze(m->uvs, 2);
}

// ------------------------------------------------------------------ glTF

// Appends bytes to the buffer, 4-byte aligned, as a new bufferView; returns its index.
int add_view(tinygltf::Model &model, const void *data, size_t size, int target, int stride) {
    std::vector<unsigned char> &buf = model.buffers[0].data;
    while (buf.size() % 4) buf.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buf.size();
    view.byteLength = size;
    view.target = target;
    if (stride) view.byteStride = (size_t)stride;
    const unsigned char *p = static_cast<const unsigned char *>(data);
    buf.insert(buf.end(), p, p + size);
    model.bufferViews.push_back(view);
    return (int)model.bufferViews.size() - 1;
}

int add_accessor(tinygltf::Model &model, int view, int component, int type, size_t count, std::vector<double> mn = {},
                 std::vector<double> mx = {}) {
    tinygltf::Accessor acc;
    acc.bufferView = view;
    acc.byteOffset = 0;
    acc.componentType = component;
    acc.type = type;
    acc.count = count;
    acc.minValues = std::move(mn);
    acc.maxValues = std::move(mx);
    model.accessors.push_back(acc);
    return (int)model.accessors.size() - 1;
}

std::string base_name(const std::string &path) {
    size_t s = path.find_last_of('/');
    std::string b = s == std::string::npos ? path : path.substr(s + 1);
    size_t d = b.find_last_of('.');
    return d == std::string::npos || d == 0 ? b : b.substr(0, d);
}

bool ends_with(const std::string &s, const char *suffix) {
    size_t n = strlen(suffix);
    if (s.size() < n) return false;
    for (size_t i = 0; i < n; ++i)
        if (tolower((unsigned char)s[s.size() - n + i]) != suffix[i]) return false;
    return true;
}

void build_model(const OutMesh &m, const std::string &name, const Options &o, tinygltf::Model *model) {
    model->asset.version = "2.0";
    char gen[64];
    snprintf(gen, sizeof gen, "surfblend sfb2gltf %d.%d.%d", SFB_VERSION_MAJOR, SFB_VERSION_MINOR, SFB_VERSION_PATCH);
    model->asset.generator = gen;
    model->buffers.resize(1);
    const size_t nv = m.positions.size() / 3;
    // indices: uint16 where every index fits (65535 is primitive restart in some APIs: kept out)
    int index_view;
    int index_type;
    if (nv < 65535) {
        std::vector<unsigned short> s(m.indices.begin(), m.indices.end());
        index_view = add_view(*model, s.data(), s.size() * sizeof(unsigned short), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, 0);
        index_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    } else {
        index_view = add_view(*model, m.indices.data(), m.indices.size() * sizeof(unsigned), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, 0);
        index_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    }
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.indices = add_accessor(*model, index_view, index_type, TINYGLTF_TYPE_SCALAR, m.indices.size());
    std::vector<double> mn(3, 0.0), mx(3, 0.0);
    for (size_t v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c) {
            const double x = m.positions[3 * v + c];
            if (v == 0 || x < mn[(size_t)c]) mn[(size_t)c] = x;
            if (v == 0 || x > mx[(size_t)c]) mx[(size_t)c] = x;
        }
    int view = add_view(*model, m.positions.data(), m.positions.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER, 12);
    prim.attributes["POSITION"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv, mn, mx);
    view = add_view(*model, m.normals.data(), m.normals.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER, 12);
    prim.attributes["NORMAL"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
    if (!m.uvs.empty()) {
        view = add_view(*model, m.uvs.data(), m.uvs.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER, 8);
        prim.attributes["TEXCOORD_0"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, nv);
    }
    // the input (OBJ) carries no material: a neutral PBR default
    tinygltf::Material mat;
    mat.name = "surfblend default";
    mat.pbrMetallicRoughness.baseColorFactor = {0.8, 0.8, 0.8, 1.0};
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 0.5;
    mat.doubleSided = false;
    model->materials.push_back(mat);
    prim.material = 0;
    tinygltf::Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(prim);
    model->meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = name;
    node.mesh = 0;
    model->nodes.push_back(node);
    tinygltf::Scene scene;
    scene.name = "surfblend";
    scene.nodes.push_back(0);
    model->scenes.push_back(scene);
    model->defaultScene = 0;
    (void)o;
}

// Serialises the model to OUT (.glb, or .gltf with its buffer in BIN beside it), each file
// written atomically. Returns 0, or 1 with the reason printed.
int write_model(tinygltf::Model &model, const Options &o, size_t *bytes) {
    const std::string out = o.out;
    const bool text = o.gltf || ends_with(out, ".gltf");
    tinygltf::TinyGLTF writer;
    std::ostringstream stream;
    if (!text) {
        if (!writer.WriteGltfSceneToStream(&model, stream, false, true)) {
            cli_error("%s: tinygltf could not serialise the model", o.out);
            return 1;
        }
        const std::string s = stream.str();
        *bytes = s.size();
        return cli_write_file(o.out, s.data(), s.size());
    }
    // .gltf: tinygltf would embed the buffer as base64 in a stream; write the JSON with the
    // buffer's uri pointing at our own .bin instead
    std::vector<unsigned char> bin;
    bin.swap(model.buffers[0].data);
    const size_t bin_size = bin.size();
    if (!writer.WriteGltfSceneToStream(&model, stream, true, false)) {
        cli_error("%s: tinygltf could not serialise the model", o.out);
        return 1;
    }
    nlohmann::json doc = nlohmann::json::parse(stream.str(), nullptr, false);
    if (doc.is_discarded()) {
        cli_error("%s: tinygltf wrote JSON that does not parse", o.out);
        return 1;
    }
    std::string dir = out.substr(0, out.find_last_of('/') == std::string::npos ? 0 : out.find_last_of('/') + 1);
    const std::string bin_name = base_name(out) + ".bin";
    doc["buffers"] = nlohmann::json::array({{{"byteLength", bin_size}, {"uri", bin_name}}});
    const std::string json = doc.dump(2) + "\n";
    if (cli_write_file((dir + bin_name).c_str(), bin.data(), bin.size())) return 1;
    if (cli_write_file(o.out, json.data(), json.size())) {
        remove((dir + bin_name).c_str());
        return 1;
    }
    *bytes = json.size() + bin.size();
    return 0;
}

// ------------------------------------------------------------------ the pipeline

struct Run {
    Options o;
    Progress bar;
    sfb_context *ctx = nullptr;
    sfb_mesh *mesh = nullptr;
    sfb_surface *surf = nullptr;
    sfb_mesh_data data{};
    sfb_tess_data tess{};
    unsigned char *trim_texels = nullptr;
    ~Run() {
        sfb_mesh_data_free(&data);
        sfb_tess_data_free(&tess);
        sfb_surface_destroy(surf);
        sfb_mesh_destroy(mesh);
        sfb_context_destroy(ctx);
        free(trim_texels);
    }
    int fail_lib(const char *what, sfb_result r) {
        bar.end();
        cli_error("%s: %s: %s: %s", o.in, what, sfb_result_string(r), sfb_last_error(ctx));
        return 1;
    }
};

int read_stage(Run &R) {
    R.bar.begin("read", 1);
    R.mesh = cli_load_mesh(R.ctx, R.o.in, R.o.have_angle ? R.o.angle : -1.0);
    return R.mesh ? 0 : 1;
}

int build_stage(Run &R) {
    R.bar.begin("build", 2);
    sfb_mesh_desc d;
    sfb_mesh_get_desc(R.mesh, &d);
    sfb_surface_config cfg = sfb_surface_config_init(R.o.scheme, R.o.have_tess ? 0 : R.o.level);
    if (R.o.have_tess) cfg.flags = SFB_REFINE_PATCHES;
    else cfg.flags = (R.o.normals == NORMALS_FLAT ? 0u : (unsigned)SFB_REFINE_SHADING) | (d.uv_count > 0 ? (unsigned)SFB_REFINE_UVS : 0u);
    sfb_result r = sfb_surface_create(R.ctx, R.mesh, &cfg, &R.surf);
    return r == SFB_SUCCESS ? 0 : R.fail_lib("building the surface", r);
}

int evaluate_stage(Run &R, OutMesh *m) {
    R.bar.begin("evaluate", 3);
    sfb_result r;
    if (R.o.have_tess) {
        sfb_tess_config tc = sfb_tess_config_init(R.o.rate);
        tc.tolerance = (float)R.o.tolerance;
        tc.flags = SFB_TESS_SPLIT_CREASES;
        sfb_trim_mask mask;
        if (R.o.trim) {
            memset(&mask, 0, sizeof mask);
            int w = 0, h = 0;
            if (!cli_load_mask(R.o.trim, &R.trim_texels, &w, &h)) return 1;
            mask.width = w;
            mask.height = h;
            mask.texels = R.trim_texels;
            tc.trim = &mask;
        }
        r = sfb_surface_tessellate(R.surf, &tc, &R.tess);
        if (r != SFB_SUCCESS) return R.fail_lib("tessellating", r);
        mesh_from_tess(R.tess, R.o.normals == NORMALS_FLAT, m);
        return 0;
    }
    if (R.o.normals == NORMALS_FLAT) {
        r = sfb_surface_refine(R.surf, &R.data);
        if (r != SFB_SUCCESS) return R.fail_lib("refining", r);
        mesh_from_faces(R.data, nullptr, true, m);
        return 0;
    }
    sfb_shade_params sp = sfb_shade_params_init();
    r = sfb_surface_shade(R.surf, &sp, &R.data);
    if (r != SFB_SUCCESS) return R.fail_lib("shading", r);
    mesh_from_faces(R.data, R.o.normals == NORMALS_LIMIT ? R.data.limit_normals : R.data.normals, false, m);
    return 0;
}

} // namespace

int main(int argc, char **argv) {
    cli_program = "sfb2gltf";
    Run R;
    int rc = parse_args(argc, argv, &R.o);
    if (rc) return rc == 1 ? 0 : 2;
    R.bar.on = !R.o.quiet && (R.o.progress || isatty(2));
    sfb_progress progress = {progress_cb, &R.bar};
    R.ctx = cli_make_context_progress(R.o.backend, progress);
    if (!R.ctx) return 1;
    OutMesh m;
    if (read_stage(R) || build_stage(R) || evaluate_stage(R, &m)) {
        R.bar.end();
        return 1;
    }
    drop_degenerate(&m);
    if (m.indices.empty()) {
        R.bar.end();
        cli_error("%s: the surface has no triangles to write (every face a hole, or degenerate)", R.o.in);
        return 1;
    }
    R.bar.begin("optimise", 4);
    if (R.o.optimize) optimize_mesh(&m);
    else compact_mesh(&m);
    R.bar.begin("write", 5);
    tinygltf::Model model;
    build_model(m, base_name(R.o.in), R.o, &model);
    size_t bytes = 0;
    rc = write_model(model, R.o, &bytes);
    R.bar.end();
    if (rc) return 1;
    if (!R.o.quiet)
        fprintf(stderr, "sfb2gltf: %s: %s %s: %zu vertices, %zu triangles%s -> %s (%zu bytes, backend %s)\n", R.o.in,
                sfb_scheme_name(R.o.scheme), R.o.have_tess ? "tessellated" : "refined", m.positions.size() / 3, m.indices.size() / 3,
                m.uvs.empty() ? "" : ", UVs", R.o.out, bytes, sfb_context_backend_name(R.ctx));
    return 0;
}
