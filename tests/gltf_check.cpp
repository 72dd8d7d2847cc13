// gltf_check: reads a .glb/.gltf that sfb2gltf wrote (tinygltf) and compares it with what the
// library gives for the same input and options, computed here directly:
//
//   gltf_check FILE.glb IN.obj [--scheme S] [--level L] [--normals shading|limit|flat]
//              [--crease-angle DEG] [--tess RATE] [--min-splits N] [--uvs yes|no]
//
// Checks (PASS/FAIL lines, tests/harness.h):
//  - the file loads; one mesh, one TRIANGLES primitive with indices, POSITION, NORMAL;
//  - the triangle count equals the library's (refined faces fan-triangulated, holes left out;
//    or the tessellation's);
//  - every glTF vertex (position, normal, uv) is one of the library's output vertices (refined:
//    the shaded mesh's (vertex, uv) corners with N_B, N_L or the face normal; tessellated: the
//    tessellation's vertices), within 1e-6 relative (positions), 1e-5 (normals), 1e-6 (uvs,
//    with glTF's v = 1 - v), and the number of distinct vertices is the library's;
//  - normals are unit; POSITION's min/max are the data's;
//  - with --min-splits N: at least N positions carry more than one normal (hard edges split);
//  - --uvs yes|no: TEXCOORD_0 is there or not;
//  - EXT_meshopt_compression files are decoded first (meshoptimizer's decoders) into a plain
//    glTF in memory, which tinygltf then reads;
//  - --quantize (with sfb2gltf's --position-bits, --normal-bits, --uv-bits): the data is read
//    dequantised and through the node transforms, and must agree within half a grid step;
//  - --sharpness S: the library's tribezier surface at s = S;
//  - --morph W (a file of --sharpness-morph): one morph target named "sharpness", the mesh's
//    default weight S (--sharpness, else 1); the mesh at weight W (POSITION + W x target, NORMAL +
//    W x target normalised, as a viewer shows it) against the library at s = W: positions as
//    above, and normals within --morph-degrees D (default 5) of the library's, the largest angle
//    printed (a blend of the two ends' normals, not the normal at W).
#include <tiny_gltf.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "surfblend.h"
#include "tests/harness.h"

namespace {

struct Vertex {
    float p[3], n[3], t[2];
};

// Reads accessor `index` as floats (FLOAT, or normalised integers: dequantised).
bool read_floats(const tinygltf::Model &m, int index, int comps, std::vector<float> *out) {
    if (index < 0 || index >= (int)m.accessors.size()) return false;
    const tinygltf::Accessor &a = m.accessors[(size_t)index];
    if (tinygltf::GetNumComponentsInType((uint32_t)a.type) != comps || a.bufferView < 0) return false;
    const tinygltf::BufferView &v = m.bufferViews[(size_t)a.bufferView];
    const std::vector<unsigned char> &b = m.buffers[(size_t)v.buffer].data;
    const int csize = tinygltf::GetComponentSizeInBytes((uint32_t)a.componentType);
    const size_t stride = v.byteStride ? v.byteStride : (size_t)(csize * comps);
    out->resize(a.count * (size_t)comps);
    for (size_t i = 0; i < a.count; ++i)
        for (int c = 0; c < comps; ++c) {
            const size_t at = v.byteOffset + a.byteOffset + i * stride + (size_t)c * (size_t)csize;
            if (at + (size_t)csize > b.size()) return false;
            double x;
            switch (a.componentType) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; memcpy(&f, &b[at], 4); x = f; break; }
            case TINYGLTF_COMPONENT_TYPE_SHORT: { short s; memcpy(&s, &b[at], 2); x = a.normalized ? std::max(s / 32767.0, -1.0) : s; break; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { unsigned short s; memcpy(&s, &b[at], 2); x = a.normalized ? s / 65535.0 : s; break; }
            case TINYGLTF_COMPONENT_TYPE_BYTE: { signed char s = (signed char)b[at]; x = a.normalized ? std::max(s / 127.0, -1.0) : s; break; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { x = a.normalized ? b[at] / 255.0 : b[at]; break; }
            default: return false;
            }
            (*out)[i * (size_t)comps + (size_t)c] = (float)x;
        }
    return true;
}

bool read_indices(const tinygltf::Model &m, int index, std::vector<unsigned> *out) {
    if (index < 0 || index >= (int)m.accessors.size()) return false;
    const tinygltf::Accessor &a = m.accessors[(size_t)index];
    if (a.type != TINYGLTF_TYPE_SCALAR || a.bufferView < 0) return false;
    const tinygltf::BufferView &v = m.bufferViews[(size_t)a.bufferView];
    const std::vector<unsigned char> &b = m.buffers[(size_t)v.buffer].data;
    const int csize = tinygltf::GetComponentSizeInBytes((uint32_t)a.componentType);
    out->resize(a.count);
    for (size_t i = 0; i < a.count; ++i) {
        const size_t at = v.byteOffset + a.byteOffset + i * (size_t)csize;
        if (at + (size_t)csize > b.size()) return false;
        unsigned x = 0;
        if (csize == 1) x = b[at];
        else if (csize == 2) { unsigned short s; memcpy(&s, &b[at], 2); x = s; }
        else memcpy(&x, &b[at], 4);
        (*out)[i] = x;
    }
    return true;
}

void unit(float *n) {
    double l = std::sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    if (l > 0.0) for (int c = 0; c < 3; ++c) n[c] = (float)(n[c] / l);
}

// The library's vertices and triangle count for the same options.
struct Reference {
    std::vector<Vertex> verts;
    long triangles = 0;
    size_t distinct = 0; // distinct (output vertex, uv) corners: a split vertex whose copies have equal normals stays two
    bool uvs = false;
};

bool reference(const char *in, sfb_scheme scheme, int level, const std::string &normals, double angle, int rate, double sharpness, Reference *R) {
    sfb_context *ctx = nullptr;
    sfb_context_config cc = sfb_context_config_init();
    static const sfb_backend_kind ref[1] = {SFB_BACKEND_REF};
    cc.backends = ref;
    cc.backend_count = 1;
    cc.ignore_environment = 1;
    if (sfb_context_create(&cc, &ctx) != SFB_SUCCESS) return false;
    size_t size = 0;
    char *text = slurp(in, &size);
    sfb_mesh *mesh = nullptr, *creased = nullptr;
    sfb_surface *surf = nullptr;
    sfb_mesh_data d;
    sfb_tess_data t;
    memset(&d, 0, sizeof d);
    memset(&t, 0, sizeof t);
    bool ok = text && sfb_mesh_read_obj(ctx, text, size, &mesh) == SFB_SUCCESS;
    free(text);
    if (ok && angle >= 0.0) {
        ok = sfb_mesh_crease_by_angle(ctx, mesh, (float)angle, &creased, nullptr) == SFB_SUCCESS;
        if (ok) { sfb_mesh_destroy(mesh); mesh = creased; }
    }
    sfb_mesh_desc md;
    sfb_mesh_get_desc(mesh, &md);
    if (ok) {
        sfb_surface_config cfg = sfb_surface_config_init(scheme, rate > 0 ? 0 : level);
        cfg.flags = rate > 0 ? (unsigned)SFB_REFINE_PATCHES | (md.uv_count > 0 ? (unsigned)SFB_REFINE_UVS : 0u)
                             : ((normals == "flat" ? 0u : (unsigned)SFB_REFINE_SHADING) | (md.uv_count > 0 ? (unsigned)SFB_REFINE_UVS : 0u));
        if (sharpness >= 0.0) {
            cfg.tribezier.sharpness_set = 1;
            cfg.tribezier.sharpness = (float)sharpness;
        }
        ok = sfb_surface_create(ctx, mesh, &cfg, &surf) == SFB_SUCCESS;
    }
    if (ok && rate > 0) {
        sfb_tess_config tc = sfb_tess_config_init(rate);
        tc.flags = SFB_TESS_SPLIT_CREASES | (md.uv_count > 0 ? (unsigned)SFB_TESS_UVS : 0u);
        ok = sfb_surface_tessellate(surf, &tc, &t) == SFB_SUCCESS;
        R->uvs = ok && t.uvs;
        for (int i = 0; ok && i < t.vertex_count; ++i) {
            Vertex v{};
            memcpy(v.p, t.positions + 3 * (size_t)i, sizeof v.p);
            memcpy(v.n, t.normals + 3 * (size_t)i, sizeof v.n);
            unit(v.n);
            if (R->uvs) {
                v.t[0] = t.uvs[2 * (size_t)i];
                v.t[1] = 1.0f - t.uvs[2 * (size_t)i + 1];
            }
            R->verts.push_back(v);
        }
        R->triangles = t.triangle_count;
        R->distinct = (size_t)t.vertex_count;
    } else if (ok) {
        ok = (normals == "flat" ? sfb_surface_refine(surf, &d) : sfb_surface_shade(surf, nullptr, &d)) == SFB_SUCCESS;
        const float *nrm = normals == "limit" ? d.limit_normals : d.normals;
        R->uvs = d.uvs && d.face_uvs && d.uv_count > 0;
        std::vector<char> hole((size_t)d.face_count + 1, 0);
        for (int h = 0; ok && h < d.hole_count; ++h) hole[(size_t)d.holes[h]] = 1;
        int at = 0;
        std::vector<unsigned long long> corners;
        for (int f = 0; ok && f < d.face_count; at += d.face_sizes[f], ++f) {
            if (hole[(size_t)f]) continue;
            const int k = d.face_sizes[f];
            R->triangles += k - 2;
            for (int i = 0; i < k; ++i) {
                Vertex v{};
                const int vi = d.face_vertices[at + i];
                corners.push_back((unsigned long long)(unsigned)vi << 32 | (unsigned)(R->uvs ? d.face_uvs[at + i] : 0));
                memcpy(v.p, d.positions + 3 * (size_t)vi, sizeof v.p);
                if (normals == "flat") {
                    v.n[0] = v.n[1] = v.n[2] = NAN; // compared separately: per triangle
                } else {
                    memcpy(v.n, nrm + 3 * (size_t)vi, sizeof v.n);
                    unit(v.n);
                }
                if (R->uvs) {
                    v.t[0] = d.uvs[2 * (size_t)d.face_uvs[at + i]];
                    v.t[1] = 1.0f - d.uvs[2 * (size_t)d.face_uvs[at + i] + 1];
                }
                R->verts.push_back(v);
            }
        }
        std::sort(corners.begin(), corners.end());
        R->distinct = (size_t)(std::unique(corners.begin(), corners.end()) - corners.begin());
    }
    if (!ok) fprintf(stderr, "gltf_check: the reference failed: %s\n", sfb_last_error(ctx));
    sfb_mesh_data_free(&d);
    sfb_tess_data_free(&t);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return ok;
}

std::string read_all(const std::string &path) {
    size_t n = 0;
    char *b = slurp(path.c_str(), &n);
    std::string s = b ? std::string(b, n) : std::string();
    free(b);
    return s;
}

uint32_t le32(const std::string &s, size_t at) {
    uint32_t x = 0;
    for (int k = 0; k < 4; ++k) x |= (uint32_t)(unsigned char)s[at + (size_t)k] << (8 * k);
    return x;
}

// A .glb or .gltf that uses EXT_meshopt_compression, decoded into a plain GLB in memory (the
// fallback buffer filled, the extension removed); empty when the file does not use it, or on a
// decoding failure (*err says which).
std::string meshopt_decode_file(const std::string &path, std::string *err) {
    const std::string file = read_all(path);
    std::string json;
    std::vector<std::string> buffers; // the data of each buffer (external or BIN)
    nlohmann::json doc;
    if (file.size() >= 20 && file.compare(0, 4, "glTF") == 0) {
        const uint32_t jl = le32(file, 12);
        json = file.substr(20, jl);
        const size_t bin_at = 20 + jl;
        doc = nlohmann::json::parse(json, nullptr, false);
        if (doc.is_discarded()) { *err = "bad JSON chunk"; return ""; }
        if (bin_at + 8 <= file.size()) buffers.push_back(file.substr(bin_at + 8, le32(file, bin_at)));
    } else {
        doc = nlohmann::json::parse(file, nullptr, false);
        if (doc.is_discarded()) { *err = "bad JSON"; return ""; }
        const std::string dir = path.substr(0, path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
        for (auto &b : doc["buffers"]) buffers.push_back(b.contains("uri") ? read_all(dir + b["uri"].get<std::string>()) : std::string());
    }
    bool uses = false;
    for (auto &e : doc.value("extensionsUsed", nlohmann::json::array())) uses = uses || e == "EXT_meshopt_compression";
    if (!uses) return "";
    int fallback = -1;
    for (size_t i = 0; i < doc["buffers"].size(); ++i)
        if (doc["buffers"][i].contains("extensions")) fallback = (int)i;
    if (fallback < 0) { *err = "no fallback buffer"; return ""; }
    std::string plain((size_t)doc["buffers"][(size_t)fallback]["byteLength"].get<size_t>(), '\0');
    for (auto &v : doc["bufferViews"]) {
        if (!v.contains("extensions") || !v["extensions"].contains("EXT_meshopt_compression")) { *err = "a view not compressed"; return ""; }
        const auto &x = v["extensions"]["EXT_meshopt_compression"];
        const std::string &src = buffers.at(x["buffer"].get<size_t>());
        const size_t off = x.value("byteOffset", (size_t)0), len = x["byteLength"], count = x["count"], stride = x["byteStride"];
        unsigned char *dst = reinterpret_cast<unsigned char *>(&plain[v.value("byteOffset", (size_t)0)]);
        const unsigned char *in = reinterpret_cast<const unsigned char *>(src.data()) + off;
        int rc = x["mode"] == "ATTRIBUTES" ? meshopt_decodeVertexBuffer(dst, count, stride, in, len)
                                           : meshopt_decodeIndexBuffer(dst, count, stride, in, len);
        if (rc != 0) { *err = "a view does not decode (" + std::to_string(rc) + ")"; return ""; }
        const std::string filter = x.value("filter", std::string("NONE"));
        if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(dst, count, stride);
        else if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(dst, count, stride);
        else if (filter != "NONE") { *err = "filter " + filter + " not read"; return ""; }
        v.erase("extensions");
        v["buffer"] = 0;
    }
    doc["buffers"] = nlohmann::json::array({{{"byteLength", plain.size()}}});
    for (const char *key : {"extensionsUsed", "extensionsRequired"}) {
        nlohmann::json kept = nlohmann::json::array();
        for (auto &e : doc.value(key, nlohmann::json::array()))
            if (e != "EXT_meshopt_compression") kept.push_back(e);
        doc[key] = kept;
        if (kept.empty()) doc.erase(key);
    }
    std::string j = doc.dump();
    while (j.size() % 4) j.push_back(' ');
    while (plain.size() % 4) plain.push_back('\0');
    std::string glb = "glTF";
    auto u32 = [&](uint32_t x) { for (int k = 0; k < 4; ++k) glb.push_back((char)(x >> (8 * k) & 0xff)); };
    u32(2);
    u32((uint32_t)(28 + j.size() + plain.size()));
    u32((uint32_t)j.size());
    glb += "JSON" + j;
    u32((uint32_t)plain.size());
    glb += std::string("BIN\0", 4) + plain;
    return glb;
}

// Position key on a grid of `cell` (neighbouring cells searched too).
typedef std::array<long long, 3> Key;
Key key_of(const float *p, double cell) {
    return Key{(long long)std::floor(p[0] / cell), (long long)std::floor(p[1] / cell), (long long)std::floor(p[2] / cell)};
}

} // namespace

int main(int argc, char **argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: gltf_check FILE.glb IN.obj [--scheme S] [--level L] [--normals N] [--crease-angle DEG] [--tess RATE] "
                        "[--min-splits N] [--uvs yes|no]\n");
        return 2;
    }
    const char *file = argv[1], *in = argv[2];
    sfb_scheme scheme = SFB_SCHEME_CATMARK;
    bool have_scheme = false;
    int level = 3, rate = 0, min_splits = -1;
    double angle = -1.0, sharpness = -1.0, morph = -1.0, morph_degrees = 5.0;
    std::string normals, uvs_want;
    bool quantized = false;
    int position_bits = 14, normal_bits = 8, uv_bits = 12;
    // sfb2gltf's options are accepted as they are: the flags (--no-optimize, --gltf, -q) change
    // nothing the checks compare
    for (int i = 3; i < argc; ++i) {
        const std::string a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : "";
        if (a == "--no-optimize" || a == "--gltf" || a == "-q" || a == "--quiet") continue;
        if (a == "--quantize") { quantized = true; continue; }
        if (a == "--compress") continue; // decoded whenever the file uses it
        if (a == "--sharpness-morph") continue; // --morph W says what to check
        if (a == "--scheme") have_scheme = sfb_scheme_parse(v, &scheme);
        else if (a == "--level") level = atoi(v);
        else if (a == "--normals") normals = v;
        else if (a == "--crease-angle") angle = atof(v);
        else if (a == "--tess") rate = atoi(v);
        else if (a == "--min-splits") min_splits = atoi(v);
        else if (a == "--uvs") uvs_want = v;
        else if (a == "--sharpness") sharpness = atof(v);
        else if (a == "--morph") morph = atof(v);
        else if (a == "--morph-degrees") morph_degrees = atof(v);
        else if (a == "--backend") {}
        else if (a == "--position-bits") position_bits = atoi(v);
        else if (a == "--normal-bits") normal_bits = atoi(v);
        else if (a == "--uv-bits") uv_bits = atoi(v);
        else { fprintf(stderr, "gltf_check: unknown option '%s'\n", a.c_str()); return 2; }
        ++i;
    }
    if (!have_scheme) {
        const char *b = strrchr(in, '/');
        b = b ? b + 1 : in;
        scheme = !strncmp(b, "loop_", 5) ? SFB_SCHEME_LOOP : !strncmp(b, "bilinear_", 9) ? SFB_SCHEME_BILINEAR : SFB_SCHEME_CATMARK;
    }
    if (normals.empty()) normals = rate > 0 ? "limit" : (sfb_scheme_caps(scheme) & SFB_SCHEME_CAN_SHADE) ? "shading" : "flat";
    const std::string name = std::string(strrchr(file, '/') ? strrchr(file, '/') + 1 : file);

    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    const bool binary = name.size() > 4 && name.substr(name.size() - 4) == ".glb";
    std::string derr;
    const std::string decoded = meshopt_decode_file(file, &derr);
    if (!derr.empty()) fail((name + ": EXT_meshopt_compression decodes").c_str(), "%s", derr.c_str());
    if (!decoded.empty()) pass((name + ": EXT_meshopt_compression decodes").c_str());
    const bool loaded = !decoded.empty() ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char *>(decoded.data()),
                                                                        (unsigned)decoded.size())
                        : binary ? loader.LoadBinaryFromFile(&model, &err, &warn, file)
                                 : loader.LoadASCIIFromFile(&model, &err, &warn, file);
    check(loaded, (name + ": loads").c_str(), "%s", err.c_str());
    if (!loaded) return close_tests();
    const bool shape = model.meshes.size() == 1 && model.meshes[0].primitives.size() == 1;
    check(shape, (name + ": one mesh with one primitive").c_str(), "%zu meshes", model.meshes.size());
    if (!shape) return close_tests();
    const tinygltf::Primitive &prim = model.meshes[0].primitives[0];
    std::vector<float> P, N, T;
    std::vector<unsigned> I;
    const bool attrs = prim.mode == TINYGLTF_MODE_TRIANGLES && prim.attributes.count("POSITION") && prim.attributes.count("NORMAL") &&
                       read_floats(model, prim.attributes.at("POSITION"), 3, &P) && read_floats(model, prim.attributes.at("NORMAL"), 3, &N) &&
                       read_indices(model, prim.indices, &I) && N.size() == P.size() && I.size() % 3 == 0;
    check(attrs, (name + ": indexed triangles with POSITION and NORMAL").c_str(), "mode %d", prim.mode);
    if (!attrs) return close_tests();
    const bool has_uv = prim.attributes.count("TEXCOORD_0") && read_floats(model, prim.attributes.at("TEXCOORD_0"), 2, &T) &&
                        T.size() / 2 == P.size() / 3;
    if (!uvs_want.empty())
        check(has_uv == (uvs_want == "yes"), (name + ": TEXCOORD_0 " + (uvs_want == "yes" ? "present" : "absent")).c_str(), "it is %s",
              has_uv ? "present" : "absent");
    const size_t nv = P.size() / 3;
    {
        bool in_range = true;
        for (unsigned i : I) in_range = in_range && i < nv;
        check(in_range, (name + ": indices in range").c_str(), "an index >= %zu", nv);
        if (!in_range) return close_tests();
    }
    // min/max of POSITION
    {
        const tinygltf::Accessor &a = model.accessors[(size_t)prim.attributes.at("POSITION")];
        bool ok = a.minValues.size() == 3 && a.maxValues.size() == 3;
        for (int c = 0; ok && c < 3; ++c) {
            float lo = P[(size_t)c], hi = P[(size_t)c];
            for (size_t v = 0; v < nv; ++v) { lo = std::min(lo, P[3 * v + (size_t)c]); hi = std::max(hi, P[3 * v + (size_t)c]); }
            ok = (float)a.minValues[(size_t)c] == lo && (float)a.maxValues[(size_t)c] == hi;
        }
        check(ok, (name + ": POSITION min/max are the data's").c_str(), "they differ");
    }
    if (morph >= 0.0) {
        // the mesh at weight `morph`, as a viewer blends it (after the base's min/max check)
        const tinygltf::Mesh &mesh = model.meshes[0];
        std::vector<float> dP, dN;
        const bool one = prim.targets.size() == 1 && prim.targets[0].count("POSITION") && prim.targets[0].count("NORMAL") &&
                         read_floats(model, prim.targets[0].at("POSITION"), 3, &dP) && read_floats(model, prim.targets[0].at("NORMAL"), 3, &dN) &&
                         dP.size() == P.size() && dN.size() == N.size();
        const tinygltf::Value &names = mesh.extras.Get("targetNames");
        const bool named = names.IsArray() && names.ArrayLen() == 1 && names.Get(0).IsString() && names.Get(0).Get<std::string>() == "sharpness";
        const double want_w = sharpness >= 0.0 ? sharpness : 1.0;
        check(one && named && mesh.weights.size() == 1 && std::fabs(mesh.weights[0] - want_w) < 1e-12,
              (name + ": one morph target \"sharpness\", default weight --sharpness").c_str(), "targets %zu, named %d, weights %zu (%g, want %g)",
              prim.targets.size(), named, mesh.weights.size(), mesh.weights.empty() ? -1.0 : mesh.weights[0], want_w);
        if (!one) return close_tests();
        for (size_t i = 0; i < P.size(); ++i) {
            P[i] = (float)((double)P[i] + morph * dP[i]);
            N[i] = (float)((double)N[i] + morph * dN[i]);
        }
        for (size_t v = 0; v < P.size() / 3; ++v) unit(&N[3 * v]);
        sharpness = morph; // the library's surface at s = W
    }
    // positions into the scene: the transforms of the nodes down to the (first) node of mesh 0
    // (translation and uniform-or-not scale; --quantize's dequantisation is such a node)
    {
        std::vector<int> parent(model.nodes.size(), -1);
        for (size_t i = 0; i < model.nodes.size(); ++i)
            for (int c : model.nodes[i].children)
                if (c >= 0 && c < (int)parent.size()) parent[(size_t)c] = (int)i;
        int at = -1;
        for (size_t i = 0; i < model.nodes.size() && at < 0; ++i)
            if (model.nodes[i].mesh == 0) at = (int)i;
        bool rotated = false;
        for (; at >= 0; at = parent[(size_t)at]) {
            const tinygltf::Node &n = model.nodes[(size_t)at];
            rotated = rotated || !n.rotation.empty() || !n.matrix.empty();
            for (size_t v = 0; v < nv; ++v)
                for (int c = 0; c < 3; ++c) {
                    double x = P[3 * v + (size_t)c];
                    if (n.scale.size() == 3) x *= n.scale[(size_t)c];
                    if (n.translation.size() == 3) x += n.translation[(size_t)c];
                    P[3 * v + (size_t)c] = (float)x;
                }
        }
        check(!rotated, (name + ": node transforms are translations and scales").c_str(), "a rotation or matrix (not compared)");
    }
    // tolerances: float data agrees to rounding; quantized data within half a grid step
    const double qpos = quantized ? 1.0 / (double)((1L << (position_bits - 1)) - 1) : 0.0;
    // (twice the rounding step: --compress stores normals with the octahedral filter, whose
    // K-bit grid is coarser per component than K-bit components)
    const double ntol = quantized ? 2.0 / (double)((1L << (normal_bits - 1)) - 1) + (normal_bits <= 8 ? 1.0 / 127 : 1.0 / 32767) : 1e-5;
    const double ttol = quantized ? 1.0 / (double)((1L << uv_bits) - 1) + 1.0 / 65535 : 1e-6;
    double worst_len = 0.0;
    for (size_t v = 0; v < nv; ++v)
        worst_len = std::max(worst_len, std::fabs(std::sqrt((double)N[3 * v] * N[3 * v] + (double)N[3 * v + 1] * N[3 * v + 1] +
                                                            (double)N[3 * v + 2] * N[3 * v + 2]) - 1.0));
    check(worst_len < 2.0 * ntol, (name + ": normals are unit").c_str(), "| |n| - 1 | up to %g", worst_len);

    Reference R;
    if (!reference(in, scheme, level, normals, angle, rate, sharpness, &R)) {
        fail((name + ": the library's reference").c_str(), "could not be computed");
        return close_tests();
    }
    check((long)(I.size() / 3) == R.triangles, (name + ": triangle count is the library's").c_str(), "%zu, the library %ld", I.size() / 3,
          R.triangles);
    if (uvs_want.empty()) check(has_uv == R.uvs, (name + ": TEXCOORD_0 exactly when the library has UVs").c_str(), "glTF %d, library %d", has_uv, R.uvs);

    // every glTF vertex is a library vertex; distinct library vertices as many as glTF's
    float lo[3] = {P[0], P[1], P[2]}, hi[3] = {P[0], P[1], P[2]};
    for (size_t v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c) { lo[c] = std::min(lo[c], P[3 * v + (size_t)c]); hi[c] = std::max(hi[c], P[3 * v + (size_t)c]); }
    const double diag = std::sqrt((double)(hi[0] - lo[0]) * (hi[0] - lo[0]) + (double)(hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                  (double)(hi[2] - lo[2]) * (hi[2] - lo[2]));
    const double ptol = (1e-6 + 0.51 * qpos) * (diag > 0 ? diag : 1.0), cell = std::max(ptol * 4.0, 1e-30);
    const bool flat = normals == "flat";
    std::map<Key, std::vector<size_t>> grid;
    for (size_t r = 0; r < R.verts.size(); ++r) grid[key_of(R.verts[r].p, cell)].push_back(r);
    auto same = [&](const Vertex &a, const float *p, const float *n, const float *t) {
        for (int c = 0; c < 3; ++c)
            if (std::fabs(a.p[c] - p[c]) > ptol) return false;
        // a zero library normal (the shading's at non-manifold vertices, where no limit normal
        // exists) becomes a face normal in sfb2gltf: any unit normal matches it
        const bool zero = a.n[0] == 0.0f && a.n[1] == 0.0f && a.n[2] == 0.0f;
        if (!flat && !zero && morph < 0.0)
            for (int c = 0; c < 3; ++c)
                if (std::fabs(a.n[c] - n[c]) > ntol) return false;
        if (t && R.uvs)
            for (int c = 0; c < 2; ++c)
                if (std::fabs(a.t[c] - t[c]) > ttol) return false;
        return true;
    };
    size_t unmatched = 0, first_bad = 0;
    double morph_worst = 0.0; // --morph: per vertex the smallest angle to a library normal at its position, the largest of those
    for (size_t v = 0; v < nv; ++v) {
        const float *p = &P[3 * v], *n = &N[3 * v], *t = has_uv ? &T[2 * v] : nullptr;
        const Key k = key_of(p, cell);
        bool found = false;
        for (int dx = -1; dx <= 1 && !found; ++dx)
            for (int dy = -1; dy <= 1 && !found; ++dy)
                for (int dz = -1; dz <= 1 && !found; ++dz) {
                    auto it = grid.find(Key{k[0] + dx, k[1] + dy, k[2] + dz});
                    if (it == grid.end()) continue;
                    for (size_t r : it->second)
                        if (same(R.verts[r], p, n, t)) {
                            found = true;
                            if (morph < 0.0) break;
                        }
                }
        if (!found && unmatched++ == 0) first_bad = v;
        if (found && morph >= 0.0) {
            double best = M_PI;
            for (size_t r = 0; r < R.verts.size(); ++r)
                if (same(R.verts[r], p, n, t)) {
                    // atan2 of |m x n| and m . n: acos of a dot product of float unit vectors
                    // reads 3.5e-4 rad for equal ones
                    const float *m = R.verts[r].n;
                    const double d = (double)m[0] * n[0] + (double)m[1] * n[1] + (double)m[2] * n[2];
                    const double cx = (double)m[1] * n[2] - (double)m[2] * n[1], cy = (double)m[2] * n[0] - (double)m[0] * n[2],
                                 cz = (double)m[0] * n[1] - (double)m[1] * n[0];
                    best = std::min(best, std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), d));
                }
            morph_worst = std::max(morph_worst, best);
        }
    }
    if (morph >= 0.0) {
        printf("  %s: at weight %g the blended normals are within %.3g degrees of the library's at s = %g\n", name.c_str(), morph,
               morph_worst * 180.0 / M_PI, morph);
        check(morph_worst * 180.0 / M_PI <= morph_degrees, (name + ": morph normals near the library's").c_str(), "%.3g degrees, bound %g",
              morph_worst * 180.0 / M_PI, morph_degrees);
    }
    check(unmatched == 0, (name + ": every vertex is the library's (position, normal, uv)").c_str(),
          "%zu of %zu are not; the first, %zu: (%g %g %g) n (%g %g %g)", unmatched, nv, first_bad, P[3 * first_bad], P[3 * first_bad + 1],
          P[3 * first_bad + 2], N[3 * first_bad], N[3 * first_bad + 1], N[3 * first_bad + 2]);
    if (flat) {
        // flat: each triangle's vertices carry its own face normal
        size_t bad = 0;
        for (size_t i = 0; i < I.size(); i += 3) {
            const float *a = &P[3 * (size_t)I[i]], *b = &P[3 * (size_t)I[i + 1]], *c = &P[3 * (size_t)I[i + 2]];
            double u[3], w[3], f[3];
            for (int q = 0; q < 3; ++q) { u[q] = (double)b[q] - a[q]; w[q] = (double)c[q] - a[q]; }
            f[0] = u[1] * w[2] - u[2] * w[1]; f[1] = u[2] * w[0] - u[0] * w[2]; f[2] = u[0] * w[1] - u[1] * w[0];
            const double l = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            if (!(l > 0)) continue;
            for (int j = 0; j < 3; ++j) {
                const float *n = &N[3 * (size_t)I[i + (size_t)j]];
                if (std::fabs(n[0] - f[0] / l) + std::fabs(n[1] - f[1] / l) + std::fabs(n[2] - f[2] / l) > 1e-4) { ++bad; break; }
            }
        }
        check(bad == 0, (name + ": flat normals are the triangles' own").c_str(), "%zu triangles differ", bad);
    } else {
        check(R.distinct == nv, (name + ": as many vertices as the library's distinct corners").c_str(), "%zu, the library %zu", nv,
              R.distinct);
    }
    if (min_splits >= 0) {
        // positions with more than one normal: hard edges kept split
        std::map<std::array<float, 3>, std::vector<std::array<float, 3>>> normals_at;
        for (size_t v = 0; v < nv; ++v) {
            auto &list = normals_at[{P[3 * v], P[3 * v + 1], P[3 * v + 2]}];
            std::array<float, 3> n = {N[3 * v], N[3 * v + 1], N[3 * v + 2]};
            bool seen = false;
            for (auto &m : list) seen = seen || (std::fabs(m[0] - n[0]) + std::fabs(m[1] - n[1]) + std::fabs(m[2] - n[2]) < 1e-3f);
            if (!seen) list.push_back(n);
        }
        int splits = 0;
        for (auto &kv : normals_at) splits += kv.second.size() > 1;
        check(splits >= min_splits, (name + ": hard edges stay split").c_str(), "%d positions with several normals, wanted >= %d", splits,
              min_splits);
    }
    return close_tests();
}
