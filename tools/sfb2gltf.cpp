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
#include <array>
#include <map>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "cli_common.h"

namespace {

const char *const kUsage =
    "usage: sfb2gltf [options] IN.obj|IN.glb|IN.gltf -o OUT.glb|OUT.gltf\n"
    "\n"
    "Subdivides (or evaluates) a control mesh with creases and writes it as glTF 2.0: .glb by\n"
    "default, .gltf with a .bin beside it when OUT ends in .gltf or with --gltf.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE      the output file (required)\n"
    "  --gltf                 write .gltf + .bin whatever OUT's extension (but .glb); the .bin takes OUT's base name\n"
    "  --scheme S             catmark, loop, bilinear, manifold, tribezier or pn (default: from the file name prefix\n"
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
    "  --triangulate          split every face of more than three corners into triangles first (quads along\n"
    "                         the shorter diagonal): what loop, tribezier, pn and --fillet need from quads\n"
    "  --fillet R             round the sharp features (dihedral angle over --crease-angle, which must then be\n"
    "                         in (0, 180); default 30) with a rolling ball of radius R before subdividing (seed\n"
    "                         002: the same triangles, the blend regions' vertices moved onto the ball's sweep;\n"
    "                         manifold triangle meshes only; curves the radius cannot fillet stay sharp, said)\n"
    "  --sharpness S          --scheme tribezier: s in [0, 1] for every tagged crease and corner (0: the smooth\n"
    "                         G1 surface, 1: the crease; default: each tag's value clamped to [0, 1])\n"
    "  --sharpness-morph      --scheme tribezier: the seed's sharpness slider as a glTF morph target:\n"
    "                         the base mesh at s = 0, one target (named \"sharpness\") to s = 1, the mesh's\n"
    "                         default weight --sharpness S (1 without it); a viewer's weight w then shows s = w,\n"
    "                         positions exactly (the surface is linear in s), normals blended (not exact);\n"
    "                         with --quantize the target is in the grid's steps (float)\n"
    "  --trim MASK.png        with --tess: trim the surface by a mask over each parametric face (seed 000)\n"
    "  --backend NAME         ref, simd, gl or osmesa (default: the library's order)\n"
    "  --quantize             KHR_mesh_quantization: positions as unsigned 16-bit integers on a grid of\n"
    "                         --position-bits B (default 14) bits over the mesh's extent, undone by a node\n"
    "                         transform; normals as normalised 8- or 16-bit integers rounded to\n"
    "                         --normal-bits (default 8); UVs in [0,1] as normalised 16-bit integers rounded\n"
    "                         to --uv-bits (default 12; UVs outside [0,1] stay float)\n"
    "  --compress             EXT_meshopt_compression: indices and vertex attributes encoded with\n"
    "                         meshoptimizer's codecs (a loader must decode it: three.js with its\n"
    "                         MeshoptDecoder, gltfpack); best with --quantize, where normals go through\n"
    "                         the octahedral filter and UVs in [0,1] through the exponential one (floats,\n"
    "                         a step of 2^-uv-bits or finer; twice that beside a coordinate of exactly 1);\n"
    "                         triangles in a strip-friendly order\n"
    "  --lods L0,L1,...       one mesh per level (or per rate with --tess, whose RATE it replaces; up to\n"
    "                         16), each in a node named \"NAME level L\" (\"NAME rate R\"): the most\n"
    "                         detailed one in the scene with MSFT_lod naming the others (a viewer without\n"
    "                         the extension shows the most detailed); every LOD evaluates the same surface\n"
    "  --report FILE.json     per mesh: counts, bytes, and the deviation of what is written (after\n"
    "                         --quantize) from the exact limit surface: positions (model units and share\n"
    "                         of the diagonal) and normals (degrees); a summary line on stderr\n"
    "  --no-optimize          keep the evaluation's vertex and triangle order (no meshoptimizer passes)\n"
    "  --progress             a progress bar on stderr even when stderr is not a terminal\n"
    "  --timings              each stage's wall time on stderr (read, build, evaluate, optimise, write)\n"
    "  -q, --quiet            no summary line and no progress bar\n"
    "  -h, --help             this text\n"
    "  --version              the version\n";

// ------------------------------------------------------------------ options

enum NormalsMode { NORMALS_DEFAULT, NORMALS_SHADING, NORMALS_LIMIT, NORMALS_FLAT };

struct Options {
    const char *in = nullptr, *out = nullptr, *trim = nullptr, *backend = nullptr, *report = nullptr;
    bool gltf = false, optimize = true, quiet = false, progress = false, timings = false;
    bool have_scheme = false, have_level = false, have_tess = false, have_tolerance = false, have_angle = false;
    sfb_scheme scheme = SFB_SCHEME_CATMARK;
    int level = 3, rate = 0;
    double tolerance = 0.0, angle = 0.0;
    bool have_sharpness = false, have_fillet = false, triangulate = false, morph = false;
    double fillet = 0.0;    // --fillet R
    double sharpness = 0.0; // --sharpness (tribezier: every tagged crease's and corner's s)
    bool quantize = false, have_bits = false, compress = false;
    int position_bits = 14, normal_bits = 8, uv_bits = 12; // --quantize
    NormalsMode normals = NORMALS_DEFAULT;
    std::vector<int> lods; // --lods: levels (or, with --tess, rates)
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

bool ends_with(const std::string &s, const char *suffix) {
    size_t n = strlen(suffix);
    if (s.size() < n) return false;
    for (size_t i = 0; i < n; ++i)
        if (tolower((unsigned char)s[s.size() - n + i]) != suffix[i]) return false;
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
        } else if (!strcmp(a, "--triangulate")) {
            o->triangulate = true;
        } else if (!strcmp(a, "--fillet")) {
            // checked as the float the library takes: 1e-50 would be 0 there, 1e39 infinite
            if (!parse_double(value(a), &o->fillet) || !((float)o->fillet > 0.0f) || !std::isfinite((float)o->fillet))
                return usage_error("--fillet needs a radius > 0 (a finite float)");
            o->have_fillet = true;
        } else if (!strcmp(a, "--sharpness")) {
            if (!parse_double(value(a), &o->sharpness) || !(o->sharpness >= 0.0 && o->sharpness <= 1.0))
                return usage_error("--sharpness needs a number in [0, 1]");
            o->have_sharpness = true;
        } else if (!strcmp(a, "--sharpness-morph")) {
            o->morph = true;
        } else if (!strcmp(a, "--trim")) {
            if (!(o->trim = value(a))) return usage_error("--trim needs a PNG file");
        } else if (!strcmp(a, "--backend")) {
            if (!(o->backend = value(a))) return usage_error("--backend needs a name (ref, simd, gl, osmesa)");
        } else if (!strcmp(a, "--lods")) {
            const char *v = value(a);
            if (!v || !*v) return usage_error("--lods needs a list L0,L1,... (levels, or rates with --tess)");
            std::string list = v;
            size_t at = 0;
            while (at <= list.size()) {
                size_t end = list.find(',', at);
                if (end == std::string::npos) end = list.size();
                long x;
                if (!parse_long(list.substr(at, end - at).c_str(), 0, 1024, &x) || o->lods.size() >= 16)
                    return usage_error("--lods takes up to 16 numbers separated by commas (got '%s')", v);
                o->lods.push_back((int)x);
                at = end + 1;
            }
        } else if (!strcmp(a, "--report")) {
            if (!(o->report = value(a))) return usage_error("--report needs a file name (FILE.json)");
        } else if (!strcmp(a, "--compress")) {
            o->compress = true;
        } else if (!strcmp(a, "--quantize")) {
            o->quantize = true;
        } else if (!strcmp(a, "--position-bits") || !strcmp(a, "--normal-bits") || !strcmp(a, "--uv-bits")) {
            long v;
            const long lo = a[2] == 'n' ? 2 : 2, hi = 16;
            if (!parse_long(value(a), lo, hi, &v)) return usage_error("%s needs a number of bits 2..16", a);
            (a[2] == 'p' ? o->position_bits : a[2] == 'n' ? o->normal_bits : o->uv_bits) = (int)v;
            o->have_bits = true;
        } else if (!strcmp(a, "--no-optimize")) {
            o->optimize = false;
        } else if (!strcmp(a, "--progress")) {
            o->progress = true;
        } else if (!strcmp(a, "--timings")) {
            o->timings = true;
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
    if (o->have_bits && !o->quantize) return usage_error("--position-bits, --normal-bits and --uv-bits belong to --quantize");
    if (o->gltf && ends_with(o->out, ".glb")) return usage_error("--gltf writes JSON text: name the output .gltf, not .glb");
    if (!o->have_scheme) o->scheme = cli_scheme_for(o->in, 0, o->scheme);
    const unsigned caps = sfb_scheme_caps(o->scheme);
    const bool tess_only = !(caps & SFB_SCHEME_CAN_REFINE); // the manifold blend: evaluated, not refined
    if (tess_only && !o->have_tess) {
        o->have_tess = true;
        o->rate = 16;
    }
    if (!o->lods.empty() && o->have_level)
        return usage_error("--lods gives the levels (or the rates with --tess): not with --level");
    if (o->have_tess && o->have_level) return usage_error("--level and --tess exclude each other (refine, or tessellate the limit)");
    if (o->have_tess && !(caps & SFB_SCHEME_CAN_EVAL))
        return usage_error("--tess needs a scheme with a limit surface (%s has none)", sfb_scheme_name(o->scheme));
    if (o->have_tolerance && !o->have_tess) return usage_error("--tolerance belongs to --tess");
    if (o->have_sharpness && o->scheme != SFB_SCHEME_TRIBEZIER) return usage_error("--sharpness belongs to --scheme tribezier");
    if (o->morph) {
        // the target is the tessellation at s = 1 minus the one at s = 0, vertex for vertex: the
        // same vertices at both (one rate, no adaptive choice, one mesh per node), no codec (the
        // octahedral normals would need the target decoded the same way)
        if (o->scheme != SFB_SCHEME_TRIBEZIER) return usage_error("--sharpness-morph belongs to --scheme tribezier");
        if (o->have_tolerance || !o->lods.empty() || o->compress || o->normals == NORMALS_FLAT)
            return usage_error("--sharpness-morph takes one fixed rate and limit normals: not with --tolerance, --lods, --compress or "
                               "--normals flat");
    }
    // --fillet's features are the edges over --crease-angle: 0 (the library's "default 30") and
    // 180 (no feature; the library refuses it) would silently fillet at 30 degrees instead
    if (o->have_fillet && o->have_angle && !((float)o->angle > 0.0f && (float)o->angle < 180.0f))
        return usage_error("--fillet takes its feature angle from --crease-angle: degrees in (0, 180), not %.12g", o->angle);
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
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(), last, stage_start = start;
    double seconds[6] = {0, 0, 0, 0, 0, 0}; // per stage (1..5), for --timings
    void begin(const char *name, int i) {
        const auto now = std::chrono::steady_clock::now();
        seconds[index] += std::chrono::duration<double>(now - stage_start).count();
        stage_start = now;
        stage = name;
        index = i;
        draw(0.0f, true);
    }
    // closes the running stage's time (the bar, if drawn, is ended separately)
    void stop() { begin("", 0); }
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
    // per vertex: the exact limit surface's point and unit normal there (--report measures the
    // written data against them)
    std::vector<float> exact_p, exact_n;
    // --sharpness-morph: per vertex the change of position and normal from s = 0 to s = 1
    std::vector<float> morph_p, morph_n;
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
void mesh_from_faces(const sfb_mesh_data &d, const float *normals, bool flat, const float *limit_p, const float *limit_n, OutMesh *m) {
    std::vector<char> hole((size_t)d.face_count + 1, 0);
    for (int h = 0; h < d.hole_count; ++h)
        if (d.holes[h] >= 0 && d.holes[h] < d.face_count) hole[(size_t)d.holes[h]] = 1;
    const bool uvs = d.uvs && d.face_uvs && d.uv_count > 0;
    // the glTF vertices made so far of each refined vertex, one per UV it was seen with: a chain
    // through `next` from `first[v]` (a vertex has one UV but on a seam)
    std::vector<int> first(flat ? 0 : (size_t)d.vertex_count, -1), next, uv_of;
    size_t corners = 0;
    for (int f = 0; f < d.face_count; ++f) corners += (size_t)d.face_sizes[f];
    const size_t expect = flat ? 3 * corners : (size_t)d.vertex_count + (size_t)d.vertex_count / 8;
    m->positions.reserve(3 * expect);
    m->normals.reserve(3 * expect);
    if (uvs) m->uvs.reserve(2 * expect);
    m->indices.reserve(3 * corners);
    auto emit = [&](int fvi, const float *flat_n) -> unsigned {
        const int v = d.face_vertices[fvi], t = uvs ? d.face_uvs[fvi] : 0;
        if (!flat)
            for (int k = first[(size_t)v]; k >= 0; k = next[(size_t)k])
                if (uv_of[(size_t)k] == t) return (unsigned)k;
        const unsigned id = (unsigned)(m->positions.size() / 3);
        for (int c = 0; c < 3; ++c) m->positions.push_back(d.positions[3 * (size_t)v + c]);
        if (limit_p && limit_n) {
            float ln[3] = {limit_n[3 * (size_t)v], limit_n[3 * (size_t)v + 1], limit_n[3 * (size_t)v + 2]};
            normalize3(ln, flat_n);
            m->exact_p.insert(m->exact_p.end(), limit_p + 3 * (size_t)v, limit_p + 3 * (size_t)v + 3);
            m->exact_n.insert(m->exact_n.end(), ln, ln + 3);
        }
        float n[3];
        const float *src = flat ? flat_n : normals + 3 * (size_t)v;
        for (int c = 0; c < 3; ++c) n[c] = src[c];
        normalize3(n, flat_n);
        m->normals.insert(m->normals.end(), n, n + 3);
        if (uvs) {
            m->uvs.push_back(d.uvs[2 * (size_t)t]);
            m->uvs.push_back(1.0f - d.uvs[2 * (size_t)t + 1]);
        }
        if (!flat) {
            next.push_back(first[(size_t)v]);
            uv_of.push_back(t);
            first[(size_t)v] = (int)id;
        }
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
void mesh_from_tess(const sfb_tess_data &t, bool flat, bool exact, OutMesh *m) {
    if (!flat) {
        m->positions.assign(t.positions, t.positions + 3 * (size_t)t.vertex_count);
        m->normals.assign(t.normals, t.normals + 3 * (size_t)t.vertex_count);
        m->indices.assign(t.triangles, t.triangles + 3 * (size_t)t.triangle_count);
        if (exact) {
            m->exact_p = m->positions;
            m->exact_n.assign(t.normals, t.normals + 3 * (size_t)t.vertex_count);
        }
        if (t.uvs) // glTF's v runs down the image
            for (int v = 0; v < t.vertex_count; ++v) {
                m->uvs.push_back(t.uvs[2 * (size_t)v]);
                m->uvs.push_back(1.0f - t.uvs[2 * (size_t)v + 1]);
            }
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
            if (exact) {
                for (int q = 0; q < 3; ++q) m->exact_p.push_back(t.positions[3 * (size_t)c[j] + q]);
                for (int q = 0; q < 3; ++q) m->exact_n.push_back(t.normals[3 * (size_t)c[j] + q]);
            }
            if (t.uvs) {
                m->uvs.push_back(t.uvs[2 * (size_t)c[j]]);
                m->uvs.push_back(1.0f - t.uvs[2 * (size_t)c[j] + 1]);
            }
        }
    }
}

// f(stream, components) on every per-vertex stream of m (a reorder must move them all).
template <class F> void each_stream(OutMesh *m, F f) {
    f(m->positions, 3);
    f(m->normals, 3);
    f(m->uvs, 2);
    f(m->exact_p, 3);
    f(m->exact_n, 3);
    f(m->morph_p, 3);
    f(m->morph_n, 3);
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
// fetch), triangles for the post-transform cache, then for overdraw. With --compress the file's
// size comes first: triangles in meshoptimizer's strip-friendly cache order and no overdraw pass,
// whose reordering of triangle clusters breaks the index and vertex locality that its codecs
// compress (catmark_car level 3: 1.37 MB -> 1.29 MB; the cache stays near-optimal, ACMR within a
// few percent). That is what gltfpack does for -cc.
void optimize_mesh(OutMesh *m, bool for_size) {
    const size_t nv = m->positions.size() / 3, ni = m->indices.size();
    if (ni == 0 || nv == 0) return;
    if (for_size) {
        meshopt_optimizeVertexCacheStrip(m->indices.data(), m->indices.data(), ni, nv);
    } else {
        meshopt_optimizeVertexCache(m->indices.data(), m->indices.data(), ni, nv);
        meshopt_optimizeOverdraw(m->indices.data(), m->indices.data(), ni, m->positions.data(), nv, 3 * sizeof(float), 1.05f);
    }
    std::vector<unsigned> remap(nv);
    const size_t nu = meshopt_optimizeVertexFetchRemap(remap.data(), m->indices.data(), ni, nv);
    meshopt_remapIndexBuffer(m->indices.data(), m->indices.data(), ni, remap.data());
    auto remap_stream = [&](std::vector<float> &s, size_t comps) {
        if (s.empty()) return;
        std::vector<float> o(nu * comps);
        meshopt_remapVertexBuffer(o.data(), s.data(), nv, comps * sizeof(float), remap.data());
        s.swap(o);
    };
    each_stream(m, remap_stream);
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
    each_stream(m, squeeze);
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


// A TRIANGLES primitive with m's indices: uint16 where every index fits (65535 is primitive
// restart in some APIs: kept out), else uint32.
tinygltf::Primitive add_triangles(tinygltf::Model *model, const OutMesh &m) {
    const size_t nv = m.positions.size() / 3;
    int view, type;
    if (nv < 65535) {
        std::vector<unsigned short> s(m.indices.begin(), m.indices.end());
        view = add_view(*model, s.data(), s.size() * sizeof(unsigned short), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, 0);
        type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    } else {
        view = add_view(*model, m.indices.data(), m.indices.size() * sizeof(unsigned), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, 0);
        type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    }
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.indices = add_accessor(*model, view, type, TINYGLTF_TYPE_SCALAR, m.indices.size());
    return prim;
}

// --sharpness-morph: one morph target of float position (with its min/max, as glTF asks of
// POSITION) and normal changes per vertex, appended to prim.
void add_morph_target(tinygltf::Model *model, const std::vector<float> &dP, const std::vector<float> &dN, tinygltf::Primitive *prim) {
    const size_t nv = dP.size() / 3;
    std::vector<double> mn(3, 0.0), mx(3, 0.0);
    std::map<std::string, int> target;
    for (size_t v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c) {
            const double x = dP[3 * v + (size_t)c];
            if (v == 0 || x < mn[(size_t)c]) mn[(size_t)c] = x;
            if (v == 0 || x > mx[(size_t)c]) mx[(size_t)c] = x;
        }
    int view = add_view(*model, dP.data(), dP.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER, 12);
    target["POSITION"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv, mn, mx);
    view = add_view(*model, dN.data(), dN.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER, 12);
    target["NORMAL"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
    prim->targets.push_back(target);
}

// The quantization of one output mesh (all its primitives): positions p = t + s q with q the
// stored integers, 0 <= q <= 2^bits - 1 (a uniform scale, so that normals need nothing).
struct Quant {
    double t[3] = {0, 0, 0}, s = 1.0;
};

// v in [-1, 1] (normals) or [0, 1] (uvs) rounded to `bits` bits, as the normalised integer of
// `full` (127, 32767 or 65535) that dequantises to it most nearly.
long snap(double v, int bits, long full, bool is_signed) {
    const double steps = is_signed ? (double)((1L << (bits - 1)) - 1) : (double)((1L << bits) - 1);
    const double r = std::round(v * steps) / steps;
    return std::lround(std::min(std::max(r, is_signed ? -1.0 : 0.0), 1.0) * (double)full);
}

// A bufferView that --compress stores through one of EXT_meshopt_compression's filters.
using FilteredViews = std::vector<std::pair<int, const char *>>;

tinygltf::Primitive add_primitive_quantized(tinygltf::Model *model, const OutMesh &m, int material, const Quant &q, const Options &o,
                                            FilteredViews *filtered) {
    const size_t nv = m.positions.size() / 3;
    tinygltf::Primitive prim = add_triangles(model, m);
    // positions: UNSIGNED_SHORT x 3 from the mesh's minimum corner, padded to 8 bytes (vertex
    // attributes are 4-byte aligned); unsigned rather than centred signed values: no sign flips
    // between neighbours, which meshoptimizer's byte-wise delta codec compresses better
    const long qmax = (1L << o.position_bits) - 1;
    std::vector<unsigned short> P(nv * 4, 0);
    std::vector<double> mn(3, 0.0), mx(3, 0.0);
    for (size_t v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c) {
            const long x = std::lround((m.positions[3 * v + (size_t)c] - q.t[c]) / q.s);
            const unsigned short sx = (unsigned short)std::min(std::max(x, 0L), qmax);
            P[4 * v + (size_t)c] = sx;
            if (v == 0 || sx < mn[(size_t)c]) mn[(size_t)c] = sx;
            if (v == 0 || sx > mx[(size_t)c]) mx[(size_t)c] = sx;
        }
    int view = add_view(*model, P.data(), P.size() * sizeof(unsigned short), TINYGLTF_TARGET_ARRAY_BUFFER, 8);
    prim.attributes["POSITION"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC3, nv, mn, mx);
    // normals: normalised BYTE x 3 (padded to 4) up to 8 bits, SHORT x 3 (padded to 8) above
    if (o.compress) {
        // with --compress: the octahedral filter of EXT_meshopt_compression (two K-bit components
        // per unit vector, decoded to a normalised x, y, z), which compresses far better
        std::vector<float> F(nv * 4, 0.0f);
        for (size_t v = 0; v < nv; ++v)
            for (int c = 0; c < 3; ++c) F[4 * v + (size_t)c] = m.normals[3 * v + (size_t)c];
        const size_t stride = o.normal_bits <= 8 ? 4 : 8;
        std::vector<unsigned char> N(nv * stride);
        meshopt_encodeFilterOct(N.data(), nv, stride, o.normal_bits, F.data());
        view = add_view(*model, N.data(), N.size(), TINYGLTF_TARGET_ARRAY_BUFFER, (int)stride);
        filtered->push_back({view, "OCTAHEDRAL"});
        prim.attributes["NORMAL"] = add_accessor(*model, view, stride == 4 ? TINYGLTF_COMPONENT_TYPE_BYTE : TINYGLTF_COMPONENT_TYPE_SHORT,
                                                 TINYGLTF_TYPE_VEC3, nv);
    } else if (o.normal_bits <= 8) {
        std::vector<signed char> N(nv * 4, 0);
        for (size_t v = 0; v < nv; ++v)
            for (int c = 0; c < 3; ++c) N[4 * v + (size_t)c] = (signed char)snap(m.normals[3 * v + (size_t)c], o.normal_bits, 127, true);
        view = add_view(*model, N.data(), N.size(), TINYGLTF_TARGET_ARRAY_BUFFER, 4);
        prim.attributes["NORMAL"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_TYPE_VEC3, nv);
    } else {
        std::vector<short> N(nv * 4, 0);
        for (size_t v = 0; v < nv; ++v)
            for (int c = 0; c < 3; ++c) N[4 * v + (size_t)c] = (short)snap(m.normals[3 * v + (size_t)c], o.normal_bits, 32767, true);
        view = add_view(*model, N.data(), N.size() * sizeof(short), TINYGLTF_TARGET_ARRAY_BUFFER, 8);
        prim.attributes["NORMAL"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_TYPE_VEC3, nv);
    }
    model->accessors[(size_t)prim.attributes["NORMAL"]].normalized = true;
    if (!m.uvs.empty()) {
        bool unit = true;
        for (float x : m.uvs) unit = unit && x >= 0.0f && x <= 1.0f;
        if (unit && o.compress) {
            // with --compress: floats through the exponential filter (a signed mantissa of
            // uv_bits + 1 bits and an exponent per vertex), so that a uv in [1/2, 1) keeps the step
            // 2^-uv_bits of the normalised integers below and smaller ones a finer step; a vertex
            // with a coordinate of exactly 1 (exponent one higher) gets 2^(1 - uv_bits) for both
            // (one more mantissa bit for that costs 5 % of the uvs' bytes everywhere). The
            // normalised 16-bit integers of a 12-bit grid (round(q * 65535 / 4095)) fill their low
            // bits with the rounding of that scale, which the byte-wise codec cannot predict:
            // catmark_car level 3's uvs take 430 kB this way against 464 kB.
            std::vector<uint32_t> E(nv * 2);
            meshopt_encodeFilterExp(E.data(), nv, 8, o.uv_bits + 1, m.uvs.data());
            view = add_view(*model, E.data(), E.size() * sizeof(uint32_t), TINYGLTF_TARGET_ARRAY_BUFFER, 8);
            filtered->push_back({view, "EXPONENTIAL"});
            prim.attributes["TEXCOORD_0"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, nv);
        } else if (unit) {
            std::vector<unsigned short> T(nv * 2);
            for (size_t i = 0; i < T.size(); ++i) T[i] = (unsigned short)snap(m.uvs[i], o.uv_bits, 65535, false);
            view = add_view(*model, T.data(), T.size() * sizeof(unsigned short), TINYGLTF_TARGET_ARRAY_BUFFER, 4);
            prim.attributes["TEXCOORD_0"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC2, nv);
            model->accessors[(size_t)prim.attributes["TEXCOORD_0"]].normalized = true;
        } else {
            view = add_view(*model, m.uvs.data(), m.uvs.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER, 8);
            prim.attributes["TEXCOORD_0"] = add_accessor(*model, view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, nv);
        }
    }
    if (!m.morph_p.empty()) {
        // --sharpness-morph: the target in the base's units -- positions in grid steps (the s = 1
        // point's own grid value minus the base's: both ends land on the grid, within half a
        // step of the surface, and the surface between them is linear), normals as the
        // difference of the two ends' stored (rounded) normals -- as floats, which
        // KHR_mesh_quantization allows for targets (a step count can exceed a short's range)
        const long full = o.normal_bits <= 8 ? 127 : 32767;
        std::vector<float> dP(nv * 3), dN(nv * 3);
        for (size_t v = 0; v < nv; ++v)
            for (int c = 0; c < 3; ++c) {
                const size_t i = 3 * v + (size_t)c;
                const double p1 = (double)m.positions[i] + (double)m.morph_p[i];
                dP[i] = (float)(std::lround((p1 - q.t[c]) / q.s) - (long)P[4 * v + (size_t)c]);
                const double n1 = (double)m.normals[i] + (double)m.morph_n[i];
                dN[i] = (float)((double)snap(n1, o.normal_bits, full, true) / (double)full -
                                (double)snap(m.normals[i], o.normal_bits, full, true) / (double)full);
            }
        add_morph_target(model, dP, dN, &prim);
    }
    prim.material = material;
    return prim;
}

// One output primitive: the mesh's accessors appended to the model's buffer.
tinygltf::Primitive add_primitive(tinygltf::Model *model, const OutMesh &m, int material) {
    const size_t nv = m.positions.size() / 3;
    tinygltf::Primitive prim = add_triangles(model, m);
    std::vector<double> mn(3, 0.0), mx(3, 0.0);
    for (size_t v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c) {
            const double x = m.positions[3 * v + (size_t)c];
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
    if (!m.morph_p.empty()) add_morph_target(model, m.morph_p, m.morph_n, &prim);
    prim.material = material;
    return prim;
}

// EXT_meshopt_compression: every bufferView of buffer 0 encoded with meshoptimizer's codecs
// (index views as TRIANGLES, attribute views as ATTRIBUTES) into a new buffer; the views then
// point into a fallback buffer that has a length and no data (extensionsRequired: a loader
// must decode). Edits the JSON `doc` and returns the compressed bytes.
std::vector<unsigned char> meshopt_compress(const tinygltf::Model &model, const std::vector<unsigned char> &bin, const FilteredViews &filtered,
                                            nlohmann::json &doc) {
    std::vector<unsigned char> out;
    for (size_t i = 0; i < model.bufferViews.size(); ++i) {
        const tinygltf::BufferView &v = model.bufferViews[i];
        const unsigned char *data = bin.data() + v.byteOffset;
        std::vector<unsigned char> enc;
        nlohmann::json ext;
        while (out.size() % 4) out.push_back(0);
        if (v.target == TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER) {
            // the index view's component size, from its accessor
            size_t isize = 4;
            for (const tinygltf::Accessor &a : model.accessors)
                if (a.bufferView == (int)i) isize = (size_t)tinygltf::GetComponentSizeInBytes((uint32_t)a.componentType);
            const size_t count = v.byteLength / isize;
            std::vector<unsigned> idx(count);
            unsigned top = 0;
            for (size_t k = 0; k < count; ++k) {
                if (isize == 2) { unsigned short q; memcpy(&q, data + 2 * k, 2); idx[k] = q; }
                else memcpy(&idx[k], data + 4 * k, 4);
                top = std::max(top, idx[k]);
            }
            // index codec version 1 (EXT_meshopt_compression allows 0 and 1): smaller on the
            // strip-ordered triangles optimize_mesh makes for --compress
            meshopt_encodeIndexVersion(1);
            enc.resize(meshopt_encodeIndexBufferBound(count, (size_t)top + 1));
            enc.resize(meshopt_encodeIndexBuffer(enc.data(), enc.size(), idx.data(), count));
            ext = {{"buffer", 0}, {"byteOffset", out.size()}, {"byteLength", enc.size()}, {"byteStride", isize}, {"count", count}, {"mode", "TRIANGLES"}};
        } else {
            const size_t stride = v.byteStride, count = v.byteLength / stride;
            enc.resize(meshopt_encodeVertexBufferBound(count, stride));
            enc.resize(meshopt_encodeVertexBuffer(enc.data(), enc.size(), data, count, stride));
            ext = {{"buffer", 0}, {"byteOffset", out.size()}, {"byteLength", enc.size()}, {"byteStride", stride}, {"count", count}, {"mode", "ATTRIBUTES"}};
            for (const auto &f : filtered)
                if (f.first == (int)i) ext["filter"] = f.second;
        }
        out.insert(out.end(), enc.begin(), enc.end());
        nlohmann::json &jv = doc["bufferViews"][i];
        jv["buffer"] = 1;
        jv["extensions"]["EXT_meshopt_compression"] = ext;
    }
    while (out.size() % 4) out.push_back(0);
    for (const char *key : {"extensionsUsed", "extensionsRequired"}) {
        if (!doc.contains(key)) doc[key] = nlohmann::json::array();
        doc[key].push_back("EXT_meshopt_compression");
    }
    return out;
}

// A GLB container: the 12-byte header, the JSON chunk (padded with spaces), the BIN chunk
// (padded with zeros).
std::string glb_container(const std::string &json, const std::vector<unsigned char> &bin) {
    std::string j = json;
    while (j.size() % 4) j.push_back(' ');
    const uint32_t total = (uint32_t)(12 + 8 + j.size() + (bin.empty() ? 0 : 8 + bin.size()));
    std::string out;
    auto u32 = [&](uint32_t x) { for (int k = 0; k < 4; ++k) out.push_back((char)(x >> (8 * k) & 0xff)); };
    out += "glTF";
    u32(2);
    u32(total);
    u32((uint32_t)j.size());
    out += "JSON";
    out += j;
    if (!bin.empty()) {
        u32((uint32_t)bin.size());
        out += std::string("BIN\0", 4);
        out.append(reinterpret_cast<const char *>(bin.data()), bin.size());
    }
    return out;
}

// Serialises the model to OUT (.glb, or .gltf with its buffer in a .bin beside it), each file
// written atomically. tinygltf writes the JSON of everything but the buffers; the buffers (and
// --compress's bufferView extensions) are ours. Returns 0, or 1 with the reason printed.
int write_model(tinygltf::Model &model, const Options &o, const FilteredViews &filtered, size_t *bytes) {
    const std::string out = o.out;
    const bool text = o.gltf || ends_with(out, ".gltf");
    std::vector<unsigned char> bin;
    bin.swap(model.buffers[0].data);
    const size_t raw_size = bin.size();
    model.buffers.clear();
    tinygltf::TinyGLTF writer;
    std::ostringstream stream;
    if (!writer.WriteGltfSceneToStream(&model, stream, false, false)) {
        cli_error("%s: tinygltf could not serialise the model", o.out);
        return 1;
    }
    nlohmann::json doc = nlohmann::json::parse(stream.str(), nullptr, false);
    if (doc.is_discarded()) {
        cli_error("%s: tinygltf wrote JSON that does not parse", o.out);
        return 1;
    }
    const std::string dir = out.substr(0, out.find_last_of('/') == std::string::npos ? 0 : out.find_last_of('/') + 1);
    const std::string bin_name = base_name(out) + ".bin";
    if (o.compress) bin = meshopt_compress(model, bin, filtered, doc);
    nlohmann::json buffer = {{"byteLength", bin.size()}};
    if (text) buffer["uri"] = bin_name;
    doc["buffers"] = nlohmann::json::array({buffer});
    if (o.compress)
        doc["buffers"].push_back({{"byteLength", raw_size}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
    if (!text) {
        const std::string glb = glb_container(doc.dump(), bin);
        *bytes = glb.size();
        return cli_write_file(o.out, glb.data(), glb.size());
    }
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

// One control mesh: an OBJ file, or one TRIANGLES primitive of a glTF mesh.
struct Part {
    sfb_mesh *mesh = nullptr;
    bool owns = true;      // the LOD copies of a part share its mesh; the first owns it
    int level = 0, rate = 0; // what it is evaluated at (--level / --tess, or its --lods entry)
    int gltf_mesh = 0;     // the output mesh it belongs to
    int material = -1;     // the input's material (-1: the default one)
    std::string name;      // for messages: FILE, or FILE mesh M primitive P
    OutMesh out;
};

struct Run {
    Options o;
    Progress bar;
    sfb_context *ctx = nullptr;
    std::vector<Part> parts;
    std::vector<Quant> quant; // --quantize: per output mesh (set by assemble)
    FilteredViews filtered; // --quantize --compress: the views stored through a filter (normals, uvs)
    // the output's skeleton: the glTF input's nodes, scenes, materials (and their textures) and
    // mesh names, or for an OBJ one node and mesh named after the file, the default material
    tinygltf::Model skeleton;
    ~Run() {
        for (Part &p : parts)
            if (p.owns) sfb_mesh_destroy(p.mesh);
        sfb_context_destroy(ctx);
    }
    int fail_lib(const std::string &where, const char *what, sfb_result r) {
        bar.end();
        cli_error("%s: %s: %s: %s", where.c_str(), what, sfb_result_string(r), sfb_last_error(ctx));
        return 1;
    }
};

// ---- glTF input

// Reads accessor `index` (FLOAT, or normalised integers) as `comps` floats per element; an
// empty string, or why it cannot be read.
std::string accessor_floats(const tinygltf::Model &m, int index, int comps, std::vector<float> *out) {
    if (index < 0 || index >= (int)m.accessors.size()) return "an accessor index out of range";
    const tinygltf::Accessor &a = m.accessors[(size_t)index];
    if (a.sparse.isSparse) return "a sparse accessor (not read: densify the file first)";
    if (tinygltf::GetNumComponentsInType((uint32_t)a.type) != comps) return "an accessor of the wrong type";
    if (a.bufferView < 0 || a.bufferView >= (int)m.bufferViews.size()) return "an accessor without data";
    const tinygltf::BufferView &v = m.bufferViews[(size_t)a.bufferView];
    if (v.buffer < 0 || v.buffer >= (int)m.buffers.size()) return "a bufferView without a buffer";
    const std::vector<unsigned char> &b = m.buffers[(size_t)v.buffer].data;
    const int csize = tinygltf::GetComponentSizeInBytes((uint32_t)a.componentType);
    if (csize <= 0) return "an accessor of an unknown component type";
    const size_t stride = v.byteStride ? v.byteStride : (size_t)csize * (size_t)comps;
    if (a.count > (size_t)SFB_MAX_ELEMENTS) return "an accessor over the element limit";
    out->resize(a.count * (size_t)comps);
    for (size_t i = 0; i < a.count; ++i)
        for (int c = 0; c < comps; ++c) {
            const size_t at = v.byteOffset + a.byteOffset + i * stride + (size_t)c * (size_t)csize;
            if (at + (size_t)csize > b.size() || at + (size_t)csize > v.byteOffset + v.byteLength) return "an accessor past the end of its buffer";
            double x;
            switch (a.componentType) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; memcpy(&f, &b[at], 4); x = f; break; }
            case TINYGLTF_COMPONENT_TYPE_SHORT: { short q; memcpy(&q, &b[at], 2); x = a.normalized ? std::max(q / 32767.0, -1.0) : q; break; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { unsigned short q; memcpy(&q, &b[at], 2); x = a.normalized ? q / 65535.0 : q; break; }
            case TINYGLTF_COMPONENT_TYPE_BYTE: { signed char q = (signed char)b[at]; x = a.normalized ? std::max(q / 127.0, -1.0) : q; break; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: x = a.normalized ? b[at] / 255.0 : b[at]; break;
            default: return "an accessor of an unsupported component type";
            }
            if (!std::isfinite(x)) return "a NaN or infinite value";
            (*out)[i * (size_t)comps + (size_t)c] = (float)x;
        }
    return "";
}

std::string accessor_indices(const tinygltf::Model &m, int index, size_t vertices, std::vector<unsigned> *out) {
    if (index < 0 || index >= (int)m.accessors.size()) return "an index accessor out of range";
    const tinygltf::Accessor &a = m.accessors[(size_t)index];
    if (a.sparse.isSparse) return "a sparse index accessor (not read)";
    if (a.type != TINYGLTF_TYPE_SCALAR || a.bufferView < 0 || a.bufferView >= (int)m.bufferViews.size()) return "an index accessor that is not scalar";
    const tinygltf::BufferView &v = m.bufferViews[(size_t)a.bufferView];
    if (v.buffer < 0 || v.buffer >= (int)m.buffers.size()) return "a bufferView without a buffer";
    const std::vector<unsigned char> &b = m.buffers[(size_t)v.buffer].data;
    const int csize = tinygltf::GetComponentSizeInBytes((uint32_t)a.componentType);
    if (csize != 1 && csize != 2 && csize != 4) return "indices of an unsupported type";
    if (a.count > (size_t)SFB_MAX_ELEMENTS) return "an index accessor over the element limit";
    out->resize(a.count);
    for (size_t i = 0; i < a.count; ++i) {
        const size_t at = v.byteOffset + a.byteOffset + i * (v.byteStride ? v.byteStride : (size_t)csize);
        if (at + (size_t)csize > b.size()) return "indices past the end of their buffer";
        unsigned x = 0;
        if (csize == 1) x = b[at];
        else if (csize == 2) { unsigned short q; memcpy(&q, &b[at], 2); x = q; }
        else memcpy(&x, &b[at], 4);
        if (x >= vertices) return "an index out of range (" + std::to_string(x) + " of " + std::to_string(vertices) + " vertices)";
        (*out)[i] = x;
    }
    return "";
}

// Position key: exact float bits, -0 as 0.
std::array<unsigned, 3> pos_key(const float *p) {
    std::array<unsigned, 3> k;
    for (int c = 0; c < 3; ++c) {
        float x = p[c] == 0.0f ? 0.0f : p[c];
        memcpy(&k[(size_t)c], &x, 4);
    }
    return k;
}

struct KeyHash {
    size_t operator()(const std::array<unsigned, 3> &k) const { return ((size_t)k[0] * 73856093u) ^ ((size_t)k[1] * 19349663u) ^ ((size_t)k[2] * 83492791u); }
};

// A TRIANGLES primitive as a control mesh. glTF carries hard edges by splitting vertices: the
// vertices are welded by exact position, and an edge whose two triangles see different normals
// (over 1e-4 apart) at either end becomes infinitely sharp. UVs become face-varying (a UV seam:
// a boundary of the UV layout), v turned back (v_obj = 1 - v). Creases may also come from the
// primitive's extras: "sfb_creases": [a0, b0, s0, a1, b1, s1, ...], a/b vertex indices of the
// primitive, s the sharpness (>= 10: infinitely sharp); the sharper of the two wins.
std::string primitive_to_mesh(sfb_context *ctx, const tinygltf::Model &m, const tinygltf::Primitive &prim, sfb_mesh **out) {
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1)
        return "a primitive of mode " + std::to_string(prim.mode) + " (only TRIANGLES, mode 4, makes a surface)";
    auto pit = prim.attributes.find("POSITION");
    if (pit == prim.attributes.end()) return "a primitive without POSITION";
    std::vector<float> P, N, T;
    std::string e = accessor_floats(m, pit->second, 3, &P);
    if (!e.empty()) return "POSITION: " + e;
    const size_t nv = P.size() / 3;
    auto nit = prim.attributes.find("NORMAL"), tit = prim.attributes.find("TEXCOORD_0");
    if (nit != prim.attributes.end() && !(e = accessor_floats(m, nit->second, 3, &N)).empty()) return "NORMAL: " + e;
    if (tit != prim.attributes.end() && !(e = accessor_floats(m, tit->second, 2, &T)).empty()) return "TEXCOORD_0: " + e;
    if ((!N.empty() && N.size() / 3 != nv) || (!T.empty() && T.size() / 2 != nv)) return "attributes of different lengths";
    std::vector<unsigned> I;
    if (prim.indices >= 0) {
        if (!(e = accessor_indices(m, prim.indices, nv, &I)).empty()) return e;
    } else {
        I.resize(nv);
        for (size_t i = 0; i < nv; ++i) I[i] = (unsigned)i;
    }
    if (I.size() < 3 || I.size() % 3) return "no triangles";
    // weld
    std::unordered_map<std::array<unsigned, 3>, int, KeyHash> weld;
    std::vector<int> welded(nv);
    std::vector<float> positions;
    for (size_t v = 0; v < nv; ++v) {
        auto r = weld.emplace(pos_key(&P[3 * v]), (int)(positions.size() / 3));
        if (r.second) positions.insert(positions.end(), &P[3 * v], &P[3 * v] + 3);
        welded[v] = r.first->second;
    }
    // UVs by value
    std::map<std::pair<float, float>, int> uv_id;
    std::vector<float> uvs;
    std::vector<int> sizes, fv, fuv, tri_of; // tri_of: the kept triangles' first index in I
    for (size_t t = 0; t < I.size(); t += 3) {
        const int a = welded[I[t]], b = welded[I[t + 1]], c = welded[I[t + 2]];
        if (a == b || b == c || a == c) continue; // degenerate after welding: not a face
        sizes.push_back(3);
        tri_of.push_back((int)t);
        for (int k = 0; k < 3; ++k) {
            fv.push_back(welded[I[t + (size_t)k]]);
            if (!T.empty()) {
                const unsigned o = I[t + (size_t)k];
                auto r = uv_id.emplace(std::make_pair(T[2 * o], 1.0f - T[2 * o + 1]), (int)(uvs.size() / 2));
                if (r.second) { uvs.push_back(T[2 * o]); uvs.push_back(1.0f - T[2 * o + 1]); }
                fuv.push_back(r.first->second);
            }
        }
    }
    if (sizes.empty()) return "no triangles (every one degenerate)";
    // hard edges: the normals the two triangles of an edge see at its ends
    std::map<std::pair<int, int>, float> sharp;
    if (!N.empty()) {
        std::map<std::pair<int, int>, std::vector<std::pair<unsigned, unsigned>>> sides; // welded edge -> (orig at lo, orig at hi)
        for (size_t f = 0; f < tri_of.size(); ++f)
            for (int k = 0; k < 3; ++k) {
                const unsigned oa = I[(size_t)tri_of[f] + (size_t)k], ob = I[(size_t)tri_of[f] + (size_t)(k + 1) % 3];
                const int wa = welded[oa], wb = welded[ob];
                sides[{std::min(wa, wb), std::max(wa, wb)}].push_back(wa < wb ? std::make_pair(oa, ob) : std::make_pair(ob, oa));
            }
        auto differ = [&](unsigned x, unsigned y) {
            return std::fabs(N[3 * x] - N[3 * y]) + std::fabs(N[3 * x + 1] - N[3 * y + 1]) + std::fabs(N[3 * x + 2] - N[3 * y + 2]) > 1e-4f;
        };
        for (auto &kv : sides)
            if (kv.second.size() == 2 && (differ(kv.second[0].first, kv.second[1].first) || differ(kv.second[0].second, kv.second[1].second)))
                sharp[kv.first] = SFB_SHARPNESS_INFINITE;
    }
    auto xit = prim.extras.IsObject() && prim.extras.Has("sfb_creases") ? &prim.extras.Get("sfb_creases") : nullptr;
    if (xit) {
        if (!xit->IsArray() || xit->ArrayLen() % 3) return "extras.sfb_creases is not an array of (a, b, sharpness) triples";
        for (size_t i = 0; i + 2 < xit->ArrayLen(); i += 3) {
            const tinygltf::Value &va = xit->Get((int)i), &vb = xit->Get((int)i + 1), &vs = xit->Get((int)i + 2);
            if (!va.IsNumber() || !vb.IsNumber() || !vs.IsNumber()) return "extras.sfb_creases holds a value that is not a number";
            const double da = va.GetNumberAsDouble(), db = vb.GetNumberAsDouble(), ds = vs.GetNumberAsDouble();
            if (!(da >= 0 && da < (double)nv && db >= 0 && db < (double)nv) || !(ds >= 0))
                return "extras.sfb_creases triple " + std::to_string(i / 3) + " names a vertex out of range or a negative sharpness";
            const int wa = welded[(size_t)da], wb = welded[(size_t)db];
            float &s = sharp[{std::min(wa, wb), std::max(wa, wb)}];
            s = std::max(s, (float)std::min(ds, (double)SFB_SHARPNESS_INFINITE));
        }
    }
    std::vector<int> cv;
    std::vector<float> cs;
    for (auto &kv : sharp) { cv.push_back(kv.first.first); cv.push_back(kv.first.second); cs.push_back(kv.second); }
    sfb_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = (int)(positions.size() / 3);
    d.positions = positions.data();
    d.face_count = (int)sizes.size();
    d.face_sizes = sizes.data();
    d.face_vertices = fv.data();
    d.crease_count = (int)cs.size();
    d.crease_vertices = cv.data();
    d.crease_sharpness = cs.data();
    if (!T.empty()) {
        d.uv_count = (int)(uvs.size() / 2);
        d.uvs = uvs.data();
        d.face_uvs = fuv.data();
    }
    sfb_result r = sfb_mesh_create(ctx, &d, out);
    if (r != SFB_SUCCESS) return std::string(sfb_result_string(r)) + ": " + sfb_last_error(ctx);
    return "";
}

int read_gltf(Run &R) {
    tinygltf::TinyGLTF loader;
    tinygltf::Model &m = R.skeleton;
    std::string err, warn;
    FILE *probe = fopen(R.o.in, "rb");
    if (!probe) {
        cli_error("cannot read '%s'", R.o.in);
        return 1;
    }
    char magic[4] = {0, 0, 0, 0};
    const size_t got = fread(magic, 1, 4, probe);
    fclose(probe);
    const bool binary = got == 4 && !memcmp(magic, "glTF", 4);
    const bool ok = binary ? loader.LoadBinaryFromFile(&m, &err, &warn, R.o.in) : loader.LoadASCIIFromFile(&m, &err, &warn, R.o.in);
    if (!ok) {
        std::string first = err.substr(0, err.find('\n'));
        cli_error("%s: not a readable glTF file: %s", R.o.in, first.empty() ? "tinygltf gave no reason" : first.c_str());
        return 1;
    }
    for (size_t mi = 0; mi < m.meshes.size(); ++mi)
        for (size_t pi = 0; pi < m.meshes[mi].primitives.size(); ++pi) {
            const tinygltf::Primitive &prim = m.meshes[mi].primitives[pi];
            Part part;
            part.gltf_mesh = (int)mi;
            part.material = prim.material >= 0 && prim.material < (int)m.materials.size() ? prim.material : -1;
            part.name = std::string(R.o.in) + " mesh " + std::to_string(mi) + " primitive " + std::to_string(pi);
            std::string e = primitive_to_mesh(R.ctx, m, prim, &part.mesh);
            if (!e.empty()) {
                R.bar.end();
                cli_error("%s: %s", part.name.c_str(), e.c_str());
                return 1;
            }
            if (R.o.have_angle) {
                sfb_mesh *creased = nullptr;
                sfb_result r = sfb_mesh_crease_by_angle(R.ctx, part.mesh, (float)R.o.angle, &creased, nullptr);
                sfb_mesh_destroy(part.mesh);
                part.mesh = creased;
                if (r != SFB_SUCCESS) return R.fail_lib(part.name, "--crease-angle", r);
            }
            R.parts.push_back(std::move(part));
        }
    if (R.parts.empty()) {
        cli_error("%s: no triangles (the file has no mesh primitives)", R.o.in);
        return 1;
    }
    return 0;
}

bool is_gltf_name(const char *path) {
    const std::string p = path;
    return ends_with(p, ".glb") || ends_with(p, ".gltf");
}

// ---- the stages

int read_stage(Run &R) {
    R.bar.begin("read", 1);
    if (is_gltf_name(R.o.in)) return read_gltf(R);
    Part part;
    part.name = R.o.in;
    part.mesh = cli_load_mesh(R.ctx, R.o.in, R.o.have_angle ? R.o.angle : -1.0, R.o.triangulate);
    if (!part.mesh) return 1;
    R.parts.push_back(std::move(part));
    // an OBJ: one node and mesh named after the file
    tinygltf::Mesh mesh;
    mesh.name = base_name(R.o.in);
    R.skeleton.meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = mesh.name;
    node.mesh = 0;
    R.skeleton.nodes.push_back(node);
    tinygltf::Scene scene;
    scene.name = "surfblend";
    scene.nodes.push_back(0);
    R.skeleton.scenes.push_back(scene);
    R.skeleton.defaultScene = 0;
    return 0;
}

// --fillet: every part's sharp features rounded (sfb_mesh_fillet) before the surface is built;
// the features are the edges over --crease-angle (default 30 degrees), and the filleted edges
// lose the crease tags --crease-angle gave them.
int fillet_stage(Run &R) {
    R.bar.begin("fillet", 1);
    for (Part &part : R.parts) {
        sfb_fillet_config fc = sfb_fillet_config_init((float)R.o.fillet);
        if (R.o.have_angle) fc.angle = (float)R.o.angle; // in (0, 180): parse_args checked
        // a real mesh's many small creases: the ones this radius cannot fillet stay sharp (said below)
        fc.skip_failed = 1;
        sfb_fillet_report rep;
        sfb_mesh *out = nullptr;
        sfb_result r = sfb_mesh_fillet(R.ctx, part.mesh, &fc, &out, &rep);
        if (r != SFB_SUCCESS) return R.fail_lib(part.name, "--fillet", r);
        if (!R.o.quiet) {
            R.bar.end();
            cli_error("%s: %d curves filleted at radius %g, %d vertices moved", part.name.c_str(), rep.curve_count - rep.curves_skipped,
                      R.o.fillet, rep.vertices_moved);
        }
        if (rep.curves_skipped)
            cli_error("warning: %s: %d of %d curves could not be filleted at radius %g and stay sharp", part.name.c_str(), rep.curves_skipped,
                      rep.curve_count, R.o.fillet);
        if (rep.faces_folded)
            cli_error("warning: %s: the fillet turned %d faces over: the radius is too large for the surface around some curve",
                      part.name.c_str(), rep.faces_folded);
        sfb_fillet_report_free(&rep);
        sfb_mesh_destroy(part.mesh);
        part.mesh = out;
    }
    return 0;
}

// --sharpness-morph: the slider moved to s = 1 (sfb_surface_set_sharpness, no rebuild), the
// tessellation again, and its change from t (s = 0) per vertex into part.out's morph streams.
int morph_target(Run &R, Part &part, sfb_surface *surf, const sfb_tess_config &tc, const sfb_tess_data &t) {
    sfb_tribezier_options to;
    memset(&to, 0, sizeof to);
    to.sharpness_set = 1;
    to.sharpness = 1.0f;
    to.slider = 1;
    sfb_result r = sfb_surface_set_sharpness(surf, &to);
    if (r != SFB_SUCCESS) return R.fail_lib(part.name, "moving the sharpness slider to 1", r);
    sfb_tess_data t1;
    memset(&t1, 0, sizeof t1);
    r = sfb_surface_tessellate(surf, &tc, &t1);
    if (r != SFB_SUCCESS) return R.fail_lib(part.name, "tessellating at s = 1", r);
    int rc = 0;
    if (t1.vertex_count != t.vertex_count || t1.triangle_count != t.triangle_count ||
        memcmp(t1.triangles, t.triangles, 3 * sizeof(int) * (size_t)t.triangle_count) != 0) {
        cli_error("%s: the tessellations at s = 0 and s = 1 do not have the same vertices (%d and %d): no morph target", part.name.c_str(),
                  t.vertex_count, t1.vertex_count);
        rc = 1;
    } else {
        OutMesh one;
        mesh_from_tess(t1, false, false, &one);
        OutMesh &m = part.out;
        m.morph_p.resize(m.positions.size());
        m.morph_n.resize(m.normals.size());
        for (size_t i = 0; i < m.positions.size(); ++i) {
            m.morph_p[i] = one.positions[i] - m.positions[i];
            m.morph_n[i] = one.normals[i] - m.normals[i];
        }
    }
    sfb_tess_data_free(&t1);
    return rc;
}

// Builds and evaluates each part into its OutMesh (the surface and its data freed as it goes).
int evaluate_part(Run &R, Part &part) {
    sfb_mesh_desc d;
    sfb_mesh_get_desc(part.mesh, &d);
    sfb_surface_config cfg = sfb_surface_config_init(R.o.scheme, R.o.have_tess ? 0 : part.level);
    if (R.o.have_sharpness) {
        cfg.tribezier.sharpness_set = 1;
        cfg.tribezier.sharpness = (float)R.o.sharpness;
    }
    if (R.o.morph) {
        // built once with both nets: s = 0 for the base, s = 1 for the target
        cfg.tribezier.sharpness_set = 1;
        cfg.tribezier.sharpness = 0.0f;
        cfg.tribezier.slider = 1;
    }
    if (R.o.have_tess) cfg.flags = SFB_REFINE_PATCHES | (d.uv_count > 0 ? (unsigned)SFB_REFINE_UVS : 0u);
    else cfg.flags = (R.o.normals == NORMALS_FLAT ? (R.o.report ? (unsigned)SFB_REFINE_LIMIT : 0u) : (unsigned)SFB_REFINE_SHADING) |
                     (d.uv_count > 0 ? (unsigned)SFB_REFINE_UVS : 0u);
    sfb_surface *surf = nullptr;
    R.bar.begin("build", 2);
    sfb_result r = sfb_surface_create(R.ctx, part.mesh, &cfg, &surf);
    if (r != SFB_SUCCESS) return R.fail_lib(part.name, "building the surface", r);
    R.bar.begin("evaluate", 3);
    int rc = 0;
    if (R.o.have_tess) {
        sfb_tess_config tc = sfb_tess_config_init(part.rate);
        tc.tolerance = (float)R.o.tolerance;
        tc.flags = SFB_TESS_SPLIT_CREASES | (d.uv_count > 0 ? (unsigned)SFB_TESS_UVS : 0u); // UV seams split too
        sfb_trim_mask mask;
        unsigned char *texels = nullptr;
        if (R.o.trim) {
            memset(&mask, 0, sizeof mask);
            int w = 0, h = 0;
            if (!cli_load_mask(R.o.trim, &texels, &w, &h)) {
                sfb_surface_destroy(surf);
                return 1;
            }
            mask.width = w;
            mask.height = h;
            mask.texels = texels;
            tc.trim = &mask;
        }
        sfb_tess_data t;
        memset(&t, 0, sizeof t);
        r = sfb_surface_tessellate(surf, &tc, &t);
        if (r == SFB_SUCCESS) mesh_from_tess(t, R.o.normals == NORMALS_FLAT, R.o.report != nullptr, &part.out);
        else rc = R.fail_lib(part.name, "tessellating", r);
        if (rc == 0 && R.o.morph) rc = morph_target(R, part, surf, tc, t);
        sfb_tess_data_free(&t);
        free(texels);
    } else {
        sfb_mesh_data data;
        memset(&data, 0, sizeof data);
        if (R.o.normals == NORMALS_FLAT) {
            r = sfb_surface_refine(surf, &data);
            if (r == SFB_SUCCESS) mesh_from_faces(data, nullptr, true, R.o.report ? data.limit_positions : nullptr, data.normals, &part.out);
            else rc = R.fail_lib(part.name, "refining", r);
        } else {
            sfb_shade_params sp = sfb_shade_params_init();
            r = sfb_surface_shade(surf, &sp, &data);
            if (r == SFB_SUCCESS)
                mesh_from_faces(data, R.o.normals == NORMALS_LIMIT ? data.limit_normals : data.normals, false,
                                R.o.report ? data.limit_positions : nullptr,
                                data.limit_normals, &part.out);
            else rc = R.fail_lib(part.name, "shading", r);
        }
        sfb_mesh_data_free(&data);
    }
    sfb_surface_destroy(surf);
    return rc;
}

// The output model: the skeleton's nodes, scenes, materials (textures, images, samplers) and
// mesh names, each mesh's primitives replaced by the evaluated parts. Animations, skins and
// morph targets are not kept (the surface is evaluated at rest).
void assemble(Run &R, tinygltf::Model *model) {
    tinygltf::Model &k = R.skeleton;
    model->asset.version = "2.0";
    char gen[64];
    snprintf(gen, sizeof gen, "surfblend sfb2gltf %d.%d.%d", SFB_VERSION_MAJOR, SFB_VERSION_MINOR, SFB_VERSION_PATCH);
    model->asset.generator = gen;
    model->buffers.resize(1);
    model->nodes = k.nodes;
    for (tinygltf::Node &n : model->nodes) {
        n.skin = -1;
        n.weights.clear();
        n.camera = n.camera >= 0 && n.camera < (int)k.cameras.size() ? n.camera : -1;
    }
    model->cameras = k.cameras;
    model->scenes = k.scenes;
    model->defaultScene = k.defaultScene;
    model->materials = k.materials;
    model->textures = k.textures;
    model->images = k.images;
    model->samplers = k.samplers;
    model->extensionsUsed.clear();
    if (R.o.lods.size() > 1) model->extensionsUsed.push_back("MSFT_lod"); // used, not required (expand_lods)
    int default_material = -1;
    // --quantize: one grid per output mesh, over the extent of all its parts
    std::vector<Quant> &quant = R.quant;
    quant.assign(k.meshes.size(), Quant());
    if (R.o.quantize) {
        std::vector<double> lo(3 * k.meshes.size(), HUGE_VAL), hi(3 * k.meshes.size(), -HUGE_VAL);
        for (const Part &p : R.parts)
            for (size_t v = 0; v < p.out.positions.size(); v += 3)
                for (int c = 0; c < 3; ++c) {
                    double &l = lo[3 * (size_t)p.gltf_mesh + (size_t)c], &h = hi[3 * (size_t)p.gltf_mesh + (size_t)c];
                    l = std::min(l, (double)p.out.positions[v + (size_t)c]);
                    h = std::max(h, (double)p.out.positions[v + (size_t)c]);
                }
        const double qmax = (double)((1L << R.o.position_bits) - 1);
        for (size_t i = 0; i < quant.size(); ++i) {
            double extent = 0.0;
            for (int c = 0; c < 3; ++c) {
                if (!(lo[3 * i + (size_t)c] <= hi[3 * i + (size_t)c])) continue;
                quant[i].t[c] = lo[3 * i + (size_t)c];
                extent = std::max(extent, hi[3 * i + (size_t)c] - lo[3 * i + (size_t)c]);
            }
            quant[i].s = extent > 0.0 ? extent / qmax : 1.0;
        }
        model->extensionsUsed.push_back("KHR_mesh_quantization");
        model->extensionsRequired.push_back("KHR_mesh_quantization");
    }
    model->meshes.resize(k.meshes.size());
    for (size_t i = 0; i < k.meshes.size(); ++i) model->meshes[i].name = k.meshes[i].name;
    for (const Part &p : R.parts) {
        int mat = p.material;
        if (mat < 0) {
            if (default_material < 0) {
                // the input carries no material here: a neutral PBR default
                tinygltf::Material dm;
                dm.name = "surfblend default";
                dm.pbrMetallicRoughness.baseColorFactor = {0.8, 0.8, 0.8, 1.0};
                dm.pbrMetallicRoughness.metallicFactor = 0.0;
                dm.pbrMetallicRoughness.roughnessFactor = 0.5;
                model->materials.push_back(dm);
                default_material = (int)model->materials.size() - 1;
            }
            mat = default_material;
        }
        if (p.out.indices.empty()) continue;
        model->meshes[(size_t)p.gltf_mesh].primitives.push_back(R.o.quantize ? add_primitive_quantized(model, p.out, mat, quant[(size_t)p.gltf_mesh], R.o, &R.filtered)
                                                                              : add_primitive(model, p.out, mat));
    }
    if (R.o.morph)
        for (tinygltf::Mesh &mesh : model->meshes) {
            if (mesh.primitives.empty()) continue;
            // the default weight (the s shown), and the target's name (three.js reads
            // extras.targetNames into morphTargetDictionary)
            mesh.weights = {R.o.have_sharpness ? R.o.sharpness : 1.0};
            tinygltf::Value::Object ex;
            ex["targetNames"] = tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(std::string("sharpness"))});
            mesh.extras = tinygltf::Value(ex);
        }
    // a mesh left without primitives (all its parts empty) cannot be written: its nodes lose it
    std::vector<int> remap(model->meshes.size(), -1);
    std::vector<tinygltf::Mesh> kept;
    for (size_t i = 0; i < model->meshes.size(); ++i)
        if (!model->meshes[i].primitives.empty()) { remap[i] = (int)kept.size(); kept.push_back(model->meshes[i]); }
    model->meshes.swap(kept);
    const size_t nodes = model->nodes.size();
    for (size_t i = 0; i < nodes; ++i) {
        tinygltf::Node &n = model->nodes[i];
        const int old = n.mesh;
        n.mesh = old >= 0 && old < (int)remap.size() ? remap[(size_t)old] : -1;
        if (!R.o.quantize || n.mesh < 0) continue;
        // the dequantisation: the mesh moves to a child node whose transform undoes the grid
        tinygltf::Node child;
        child.name = n.name + " (dequantize)";
        child.mesh = n.mesh;
        child.translation = {quant[(size_t)old].t[0], quant[(size_t)old].t[1], quant[(size_t)old].t[2]};
        child.scale = {quant[(size_t)old].s, quant[(size_t)old].s, quant[(size_t)old].s};
        model->nodes[i].mesh = -1;
        model->nodes[i].children.push_back((int)model->nodes.size());
        model->nodes.push_back(child);
    }
}

// Every part at its level or rate; with --lods, one copy of each part per entry, each in a mesh
// of its own ("NAME level L" / "NAME rate R"), and a node per LOD named the same way. Each node
// that showed a mesh has one child, the most detailed LOD (the highest level or rate), which
// carries MSFT_lod: its `ids` are the other LOD nodes from the most detailed down, outside the
// node tree. A viewer without the extension shows the most detailed LOD alone (it showed all
// of them on top of each other before), an engine with it switches; the validator knows no
// MSFT_lod and says so as an info, and the LOD nodes only the extension names as unused
// objects (infos too): no warning. No MSFT_screencoverage is written (the switch distances
// are the engine's to choose). Every LOD evaluates the same limit surface.
void expand_lods(Run &R) {
    for (Part &p : R.parts) {
        p.level = R.o.level;
        p.rate = R.o.rate;
    }
    if (R.o.lods.empty()) return;
    tinygltf::Model &k = R.skeleton;
    const size_t nm = k.meshes.size(), nl = R.o.lods.size();
    auto what = [&](size_t i) { return std::string(R.o.have_tess ? " rate " : " level ") + std::to_string(R.o.lods[i]); };
    std::vector<tinygltf::Mesh> meshes;
    for (size_t i = 0; i < nl; ++i)
        for (size_t m = 0; m < nm; ++m) {
            tinygltf::Mesh mesh;
            mesh.name = (k.meshes[m].name.empty() ? "mesh " + std::to_string(m) : k.meshes[m].name) + what(i);
            meshes.push_back(mesh);
        }
    k.meshes.swap(meshes);
    std::vector<Part> parts;
    for (size_t i = 0; i < nl; ++i)
        for (const Part &p : R.parts) {
            Part q = p;
            q.owns = i == 0;
            q.gltf_mesh = (int)(i * nm) + p.gltf_mesh;
            (R.o.have_tess ? q.rate : q.level) = R.o.lods[i];
            q.name = p.name + what(i);
            parts.push_back(q);
        }
    R.parts.swap(parts);
    const size_t nodes = k.nodes.size();
    for (size_t n = 0; n < nodes; ++n) {
        const int m = k.nodes[n].mesh;
        if (m < 0 || m >= (int)nm) continue;
        k.nodes[n].mesh = -1;
        const std::string base = k.nodes[n].name.empty() ? "node " + std::to_string(n) : k.nodes[n].name;
        std::vector<size_t> order(nl); // the LODs, most detailed first (a stable sort: repeats keep their order)
        for (size_t i = 0; i < nl; ++i) order[i] = i;
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return R.o.lods[a] > R.o.lods[b]; });
        tinygltf::Value::Array ids;
        const int first = (int)k.nodes.size();
        for (size_t j = 0; j < nl; ++j) {
            tinygltf::Node child;
            child.name = base + what(order[j]);
            child.mesh = (int)(order[j] * nm) + m;
            if (j > 0) ids.push_back(tinygltf::Value((int)k.nodes.size()));
            k.nodes.push_back(child);
        }
        k.nodes[n].children.push_back(first);
        if (!ids.empty()) {
            tinygltf::Value::Object lod;
            lod["ids"] = tinygltf::Value(ids);
            k.nodes[(size_t)first].extensions["MSFT_lod"] = tinygltf::Value(lod);
        }
    }
}

// --report: what is written against the exact limit surface, per part.
struct Deviation {
    double pos_max = 0.0, pos_sq = 0.0, nrm_max = 0.0, nrm_sq = 0.0, diag = 0.0;
    size_t n = 0;
};

Deviation measure(const Part &p, const Run &R) {
    Deviation d;
    const OutMesh &m = p.out;
    const size_t nv = m.positions.size() / 3;
    if (m.exact_p.size() != m.positions.size() || m.exact_n.size() != m.normals.size()) return d;
    const Quant *q = R.o.quantize && p.gltf_mesh < (int)R.quant.size() ? &R.quant[(size_t)p.gltf_mesh] : nullptr;
    const long qmax = (1L << R.o.position_bits) - 1;
    const long full = R.o.normal_bits <= 8 ? 127 : 32767;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (size_t v = 0; v < nv; ++v) {
        double w[3], n[3], e2 = 0.0, nl = 0.0, dot = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double x = m.positions[3 * v + (size_t)c];
            if (q) {
                const long k = std::min(std::max(std::lround((x - q->t[c]) / q->s), 0L), qmax);
                w[c] = (float)(q->t[c] + q->s * (double)k); // as a loader computes it, in float
                n[c] = (double)snap(m.normals[3 * v + (size_t)c], R.o.normal_bits, full, true) / (double)full;
                if (R.o.compress && c == 2) {
                    // the octahedral filter's round trip, as the file stores it
                    const float f[4] = {m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2], 0.0f};
                    if (full == 127) {
                        signed char b[4];
                        meshopt_encodeFilterOct(b, 1, 4, R.o.normal_bits, f);
                        meshopt_decodeFilterOct(b, 1, 4);
                        for (int e = 0; e < 3; ++e) n[e] = b[e] / 127.0;
                    } else {
                        short b[4];
                        meshopt_encodeFilterOct(b, 1, 8, R.o.normal_bits, f);
                        meshopt_decodeFilterOct(b, 1, 8);
                        for (int e = 0; e < 3; ++e) n[e] = b[e] / 32767.0;
                    }
                }
            } else {
                w[c] = x;
                n[c] = m.normals[3 * v + (size_t)c];
            }
            e2 += (w[c] - m.exact_p[3 * v + (size_t)c]) * (w[c] - m.exact_p[3 * v + (size_t)c]);
            nl += n[c] * n[c];
            lo[c] = std::min(lo[c], (double)m.exact_p[3 * v + (size_t)c]);
            hi[c] = std::max(hi[c], (double)m.exact_p[3 * v + (size_t)c]);
        }
        (void)nl;
        // the angle as atan2(|a x b|, a . b): exact for small angles, where acos is not
        const double *a = n;
        const double b[3] = {m.exact_n[3 * v], m.exact_n[3 * v + 1], m.exact_n[3 * v + 2]};
        const double x[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
        for (int c = 0; c < 3; ++c) dot += a[c] * b[c];
        const double deg = std::atan2(std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), dot) * 180.0 / 3.14159265358979323846;
        d.pos_max = std::max(d.pos_max, std::sqrt(e2));
        d.pos_sq += e2;
        d.nrm_max = std::max(d.nrm_max, deg);
        d.nrm_sq += deg * deg;
        ++d.n;
    }
    for (int c = 0; c < 3; ++c)
        if (hi[c] >= lo[c]) d.diag += (hi[c] - lo[c]) * (hi[c] - lo[c]);
    d.diag = std::sqrt(d.diag);
    return d;
}

// Writes the --report JSON (atomically) and the summary line; 0, or 1 (printed).
int write_report(const Run &R, size_t bytes) {
    nlohmann::json meshes = nlohmann::json::array();
    Deviation all;
    for (const Part &p : R.parts) {
        const Deviation d = measure(p, R);
        const size_t nv = p.out.positions.size() / 3;
        const size_t raw = nv * (R.o.quantize ? 12 : 24) + p.out.uvs.size() * (R.o.quantize ? 2 : 4) +
                           p.out.indices.size() * (nv < 65535 ? 2 : 4);
        nlohmann::json j = {{"name", p.name}, {"mesh", p.gltf_mesh}, {"vertices", nv}, {"triangles", p.out.indices.size() / 3},
                            {"uvs", !p.out.uvs.empty()}, {"bytes_uncompressed", raw}};
        if (d.n) {
            j["position_error"] = {{"max", d.pos_max}, {"rms", std::sqrt(d.pos_sq / (double)d.n)}, {"max_of_diagonal", d.diag > 0 ? d.pos_max / d.diag : 0.0}};
            j["normal_error_degrees"] = {{"max", d.nrm_max}, {"rms", std::sqrt(d.nrm_sq / (double)d.n)}};
            all.pos_max = std::max(all.pos_max, d.pos_max);
            all.nrm_max = std::max(all.nrm_max, d.nrm_max);
            all.diag = std::max(all.diag, d.diag);
            all.n += d.n;
        }
        meshes.push_back(j);
    }
    nlohmann::json doc = {{"input", R.o.in}, {"output", R.o.out}, {"bytes", bytes}, {"scheme", sfb_scheme_name(R.o.scheme)},
                          {"evaluation", R.o.have_tess ? "tessellated" : "refined"}, {"level", R.o.have_tess ? 0 : R.o.level},
                          {"rate", R.o.have_tess ? R.o.rate : 0},
                          {"normals", R.o.normals == NORMALS_SHADING ? "shading" : R.o.normals == NORMALS_LIMIT ? "limit" : "flat"},
                          {"quantize", R.o.quantize ? nlohmann::json({{"position_bits", R.o.position_bits}, {"normal_bits", R.o.normal_bits},
                                                                      {"uv_bits", R.o.uv_bits}}) : nlohmann::json(false)},
                          {"compress", R.o.compress}, {"meshes", meshes},
                          {"measured", "each written vertex (after quantization) against the exact limit surface's point and normal "
                                       "of the same vertex: refined vertices against their limit points"}};
    const std::string text = doc.dump(2) + "\n";
    if (cli_write_file(R.o.report, text.data(), text.size())) return 1;
    if (!R.o.quiet && all.n)
        fprintf(stderr, "sfb2gltf: deviation from the limit surface: positions up to %.3g (%.2g of the diagonal), normals up to %.3g degrees -> %s\n",
                all.pos_max, all.diag > 0 ? all.pos_max / all.diag : 0.0, all.nrm_max, R.o.report);
    return 0;
}

} // namespace

int main(int argc, char **argv) {
    cli_program = "sfb2gltf";
#if defined(__GLIBC__) && defined(M_MMAP_THRESHOLD)
    // One export allocates and frees tables of tens of megabytes in turn. glibc maps each block
    // over its threshold afresh and unmaps it on free, so every table is paid again in page
    // faults (a third of the export's time at catmark_car level 3); kept in the heap, freed
    // tables are reused. The process exits after one export, so nothing is held for long.
    mallopt(M_MMAP_THRESHOLD, 1 << 30);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
    Run R;
    int rc = parse_args(argc, argv, &R.o);
    if (rc) return rc == 1 ? 0 : 2;
    R.bar.on = !R.o.quiet && (R.o.progress || isatty(2));
    sfb_progress progress = {progress_cb, &R.bar};
    R.ctx = cli_make_context_progress(R.o.backend, progress);
    if (!R.ctx) return 1;
    if (read_stage(R)) {
        R.bar.end();
        return 1;
    }
    if (R.o.have_fillet && fillet_stage(R)) {
        R.bar.end();
        return 1;
    }
    expand_lods(R);
    R.bar.begin("build", 2);
    size_t vertices = 0, triangles = 0;
    bool uvs = false;
    for (Part &p : R.parts) {
        if (evaluate_part(R, p)) {
            R.bar.end();
            return 1;
        }
        drop_degenerate(&p.out);
    }
    R.bar.begin("optimise", 4);
    for (Part &p : R.parts) {
        if (R.o.optimize) optimize_mesh(&p.out, R.o.compress);
        else compact_mesh(&p.out);
        vertices += p.out.positions.size() / 3;
        triangles += p.out.indices.size() / 3;
        uvs = uvs || !p.out.uvs.empty();
    }
    if (triangles == 0) {
        R.bar.end();
        cli_error("%s: the surface has no triangles to write (every face a hole, or degenerate)", R.o.in);
        return 1;
    }
    R.bar.begin("write", 5);
    tinygltf::Model model;
    assemble(R, &model);
    size_t bytes = 0;
    rc = write_model(model, R.o, R.filtered, &bytes);
    R.bar.end();
    if (rc) return 1;
    if (R.o.report && write_report(R, bytes)) return 1;
    R.bar.stop();
    if (R.o.timings) {
        const double *t = R.bar.seconds;
        fprintf(stderr, "sfb2gltf: timings: read %.3f s, build %.3f s, evaluate %.3f s, optimise %.3f s, write %.3f s, total %.3f s\n", t[1], t[2],
                t[3], t[4], t[5], t[1] + t[2] + t[3] + t[4] + t[5]);
    }
    if (!R.o.quiet)
        fprintf(stderr, "sfb2gltf: %s: %s %s: %zu mesh%s, %zu vertices, %zu triangles%s -> %s (%zu bytes, backend %s)\n", R.o.in,
                sfb_scheme_name(R.o.scheme), R.o.have_tess ? "tessellated" : "refined", R.parts.size(), R.parts.size() == 1 ? "" : "es",
                vertices, triangles, uvs ? ", UVs" : "", R.o.out, bytes, sfb_context_backend_name(R.ctx));
    return 0;
}
