/* 03_engine: surfblend inside a minimal "game engine" (C++14, GLM, OpenGL 4.3 core).
 *
 * The engine owns everything a real one owns: the GL context (headless EGL here,
 * tests/egl_host.h), its vertex buffers, its shader program, its camera and its framebuffer.
 * surfblend is a guest on that context: the engine hands it the control points in one of its
 * buffers, and the library's gl backend writes the refined surface straight into the vertex
 * buffer the engine draws from -- no copy through CPU memory per frame.
 *
 *   03_engine [--mesh IN.obj] [--level L] [--frames N] [--size WxH] [--view YAW,PITCH] [--zoom Z]
 *             [-o OUT.png] [--reference REF.png [--reference-view YAW,PITCH]]
 *
 * What it does, in order:
 *   1. the engine makes its GL context and its GL objects, and binds its own state
 *      (program, vertex array with its element buffer, array buffer, framebuffer, viewport,
 *      depth test);
 *   2. surfblend: an sfb context on the gl backend bound to the engine's current context
 *      (gl_use_current_context), a creased Catmull-Clark surface from the OBJ
 *      (default examples/data/creased_box.obj: semi-sharp creases, an infinitely sharp edge,
 *      a dart, a corner); the stencil tables are compiled on the CPU and uploaded once;
 *   3. every frame the engine moves some control points (a twist of the +x half, on the CPU),
 *      uploads them into its control buffer, and asks surfblend to apply three stencil tables
 *      on the GPU into its vertex buffer: limit positions (SFB_TABLE_LIMIT) and the two limit
 *      tangents (SFB_TABLE_TANGENT_U/V), interleaved 9 floats per vertex; the engine's vertex
 *      shader takes the normal as normalize(cross(tu, tv)), as the library defines it;
 *   4. the engine draws with its own GLSL program and a glm::perspective / glm::lookAt camera
 *      into its offscreen framebuffer, and prints each frame's update time (upload + the three
 *      table applications, waited for with glFinish only to time them) and draw time;
 *   5. the last frame is read back and written as PNG (stb_image_write); the background is
 *      transparent (alpha 0), the surface opaque.
 *
 * It checks itself and exits 1 when a check fails: glGetError() is GL_NO_ERROR after every
 * frame (and before every library call, which would otherwise clear the engine's error as
 * "pending before surfblend's call"); the engine's GL state is the same after every surfblend
 * call as before it (the library promises to restore what it binds; nothing is re-set here
 * before the comparison); at the end the vertex buffer is read back once and compared with
 * the same surface refined on the CPU by the ref backend (1e-5 x bounding-box diagonal).
 *
 * The camera follows sfb_render's rules exactly (src/render.c): it orbits the bounding-box
 * centre of the drawn mesh at yaw/pitch (degrees, y up), at the distance where the bounding
 * sphere fills a 30 degree cone, and the sphere spans 92% of the picture's smaller side times
 * the zoom. The shot is framed once, at start-up, on the pose of the last frame (refined once on
 * the CPU), so that --reference can draw the same picture in software: it writes sfb_render's
 * picture of the ref backend's refinement of the last pose, same camera (or --reference-view),
 * same transparent background, for a silhouette comparison (tests/engine_test.sh).
 *
 * Exit codes: 0 success, 1 a check or a library call failed, 2 usage error, 77 no usable GL
 * context here (no EGL display, no OpenGL 4.3 core context, or the gl backend cannot run on it):
 * the reason is printed, nothing is drawn.
 *
 * Build (the engine links EGL and GL, as engines do; the library itself dlopens them):
 *   c++ -std=c++14 -I. examples/03_engine.cpp build/libsfb.o -lEGL -lGL -lm -lpthread -ldl
 */
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include "surfblend.h"
#include "tests/egl_host.h"

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

const double kPi = 3.14159265358979323846;
const int kExitCheck = 1, kExitUsage = 2, kExitSkip = 77;

/* ---- options ---- */

struct Options {
    std::string mesh = "examples/data/creased_box.obj";
    std::string out = "out/03_engine.png"; /* out/ is made when missing */
    std::string reference;          /* empty: no software picture */
    int level = 3, frames = 30, width = 640, height = 480;
    float yaw = 30.0f, pitch = 25.0f, zoom = 1.0f; /* sfb_render's default view */
    bool reference_view_set = false;
    float ref_yaw = 0.0f, ref_pitch = 0.0f;
};

void usage(FILE *f) {
    std::fprintf(f,
                 "usage: 03_engine [options]\n"
                 "  A minimal engine: the gl backend refines a creased surface into the engine's own vertex\n"
                 "  buffer on its EGL context every frame; the engine draws it offscreen and saves the last frame.\n"
                 "      --mesh IN.obj          control mesh (default examples/data/creased_box.obj)\n"
                 "      --level L              Catmull-Clark levels, 1..6 (default 3)\n"
                 "      --frames N             frames to animate, 1..10000 (default 30)\n"
                 "      --size WxH             picture size in pixels, 1..8192 a side (default 640x480)\n"
                 "      --view YAW,PITCH       camera orbit in degrees, as sfb_render (default 30,25)\n"
                 "      --zoom Z               magnification, > 0 (default 1)\n"
                 "  -o, --output OUT.png       the last frame (default out/03_engine.png)\n"
                 "      --reference REF.png    also write sfb_render's software picture of the last frame's\n"
                 "                             surface (ref backend) with the same camera\n"
                 "      --reference-view Y,P   the software picture's view instead (for testing the comparison)\n"
                 "  -h, --help                 this text\n"
                 "Exit codes: 0 success, 1 a check failed, 2 usage error, 77 no usable GL context here.\n");
}

bool parse_pair(const char *s, float *a, float *b, char sep) {
    char *end = nullptr;
    *a = std::strtof(s, &end);
    if (end == s || *end != sep) return false;
    const char *t = end + 1;
    *b = std::strtof(t, &end);
    return end != t && *end == 0 && std::isfinite(*a) && std::isfinite(*b);
}

bool parse_int(const char *s, int lo, int hi, int *out) {
    char *end = nullptr;
    long v = std::strtol(s, &end, 10);
    if (end == s || *end != 0 || v < lo || v > hi) return false;
    *out = (int)v;
    return true;
}

/* 0: run; 1: --help printed; -1: usage error (message printed). */
int parse_args(int argc, char **argv, Options *o) {
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : nullptr;
        bool ok = true;
        if (a == "-h" || a == "--help") { usage(stdout); return 1; }
        if (a != "--mesh" && a != "--level" && a != "--frames" && a != "--size" && a != "--view" && a != "--zoom" &&
            a != "-o" && a != "--output" && a != "--reference" && a != "--reference-view") {
            std::fprintf(stderr, "03_engine: unknown option '%s'\n", argv[i]);
            usage(stderr);
            return -1;
        }
        if (!v) { std::fprintf(stderr, "03_engine: %s needs a value\n", argv[i]); usage(stderr); return -1; }
        ++i;
        if (a == "--mesh") o->mesh = v;
        else if (a == "-o" || a == "--output") o->out = v;
        else if (a == "--reference") o->reference = v;
        else if (a == "--level") ok = parse_int(v, 1, 6, &o->level);
        else if (a == "--frames") ok = parse_int(v, 1, 10000, &o->frames);
        else if (a == "--size") {
            float w, h;
            ok = parse_pair(v, &w, &h, 'x') && w >= 1 && h >= 1 && w <= SFB_RENDER_MAX_SIZE && h <= SFB_RENDER_MAX_SIZE &&
                 w == std::floor(w) && h == std::floor(h);
            o->width = (int)w; o->height = (int)h;
        } else if (a == "--view") ok = parse_pair(v, &o->yaw, &o->pitch, ',');
        else if (a == "--reference-view") ok = o->reference_view_set = parse_pair(v, &o->ref_yaw, &o->ref_pitch, ',');
        else if (a == "--zoom") {
            char *end = nullptr;
            o->zoom = std::strtof(v, &end);
            ok = end != v && *end == 0 && std::isfinite(o->zoom) && o->zoom > 0.0f;
        }
        if (!ok) { std::fprintf(stderr, "03_engine: bad value '%s' for %s\n", v, a.c_str()); usage(stderr); return -1; }
    }
    if (!o->reference_view_set) { o->ref_yaw = o->yaw; o->ref_pitch = o->pitch; }
    return 0;
}

/* ---- the engine's self-checks ---- */

int g_failures = 0;

void check_failed(const std::string &what) {
    ++g_failures;
    std::printf("CHECK FAILED: %s\n", what.c_str());
    std::fflush(stdout);
}

/* glGetError must be clean here; `where` names the moment. */
void expect_no_gl_error(const char *where) {
    GLenum e = glGetError();
    if (e == GL_NO_ERROR) return;
    char msg[160];
    std::snprintf(msg, sizeof msg, "glGetError() = 0x%04x %s", e, where);
    while (glGetError() != GL_NO_ERROR) {}
    check_failed(msg);
}

/* The GL state the engine sets and relies on between its own calls. */
struct GlState {
    GLint program = 0, vao = 0, array_buffer = 0, element_buffer = 0, draw_fbo = 0, read_fbo = 0;
    GLint viewport[4] = {0, 0, 0, 0};
    GLboolean depth_test = GL_FALSE;
    GLint depth_func = 0, ssbo = 0, ubo = 0, active_texture = 0;
    GLboolean cull_face = GL_FALSE;

    static GlState read() {
        GlState s;
        glGetIntegerv(GL_CURRENT_PROGRAM, &s.program);
        glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &s.vao);
        glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &s.array_buffer);
        glGetIntegerv(GL_ELEMENT_ARRAY_BUFFER_BINDING, &s.element_buffer);
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s.draw_fbo);
        glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &s.read_fbo);
        glGetIntegerv(GL_VIEWPORT, s.viewport);
        s.depth_test = glIsEnabled(GL_DEPTH_TEST);
        glGetIntegerv(GL_DEPTH_FUNC, &s.depth_func);
        s.cull_face = glIsEnabled(GL_CULL_FACE);
        glGetIntegerv(GL_SHADER_STORAGE_BUFFER_BINDING, &s.ssbo);
        glGetIntegerv(GL_UNIFORM_BUFFER_BINDING, &s.ubo);
        glGetIntegerv(GL_ACTIVE_TEXTURE, &s.active_texture);
        return s;
    }
    /* "" when equal, else what differs */
    std::string diff(const GlState &want) const {
        std::ostringstream o;
        auto one = [&](const char *name, long long got, long long w) {
            if (got != w) o << (o.tellp() > 0 ? "; " : "") << name << " is " << got << ", was " << w;
        };
        one("GL_CURRENT_PROGRAM", program, want.program);
        one("GL_VERTEX_ARRAY_BINDING", vao, want.vao);
        one("GL_ARRAY_BUFFER_BINDING", array_buffer, want.array_buffer);
        one("GL_ELEMENT_ARRAY_BUFFER_BINDING", element_buffer, want.element_buffer);
        one("GL_DRAW_FRAMEBUFFER_BINDING", draw_fbo, want.draw_fbo);
        one("GL_READ_FRAMEBUFFER_BINDING", read_fbo, want.read_fbo);
        for (int i = 0; i < 4; ++i) one("GL_VIEWPORT", viewport[i], want.viewport[i]);
        one("GL_DEPTH_TEST", depth_test, want.depth_test);
        one("GL_DEPTH_FUNC", depth_func, want.depth_func);
        one("GL_CULL_FACE", cull_face, want.cull_face);
        one("GL_SHADER_STORAGE_BUFFER_BINDING", ssbo, want.ssbo);
        one("GL_UNIFORM_BUFFER_BINDING", ubo, want.ubo);
        one("GL_ACTIVE_TEXTURE", active_texture, want.active_texture);
        return o.str();
    }
};

int g_library_calls = 0;

/* Runs one surfblend call: the engine's error queue must be clean before it, and the engine's
 * state must be the same after it as before it, with no GL error left behind. */
template <typename F>
sfb_result library_call(const char *what, F &&call) {
    expect_no_gl_error((std::string("before ") + what).c_str());
    GlState before = GlState::read();
    sfb_result r = call();
    ++g_library_calls;
    std::string d = GlState::read().diff(before);
    if (!d.empty()) check_failed(std::string("GL state changed by ") + what + ": " + d);
    expect_no_gl_error((std::string("after ") + what).c_str());
    return r;
}

/* ---- the engine's GL objects ---- */

const char *kVertexShader = R"(#version 430 core
layout(location = 0) in vec3 position;   // limit position, written by surfblend
layout(location = 1) in vec3 tangent_u;  // limit tangents, written by surfblend
layout(location = 2) in vec3 tangent_v;
uniform mat4 u_view_projection;
uniform mat4 u_view;
out vec3 v_normal_view;
out vec3 v_position_view;
void main() {
    vec3 n = cross(tangent_u, tangent_v);  // surfblend's normal: normalize(t_u x t_v)
    float len = length(n);
    v_normal_view = mat3(u_view) * (len > 0.0 ? n / len : vec3(0.0));
    v_position_view = (u_view * vec4(position, 1.0)).xyz;
    gl_Position = u_view_projection * vec4(position, 1.0);
}
)";

const char *kFragmentShader = R"(#version 430 core
in vec3 v_normal_view;
in vec3 v_position_view;
uniform vec3 u_color;
out vec4 frag_color;
void main() {
    vec3 n = normalize(v_normal_view);
    vec3 to_eye = normalize(-v_position_view);
    if (dot(n, to_eye) < 0.0) n = -n;                      // two-sided, as sfb_render
    vec3 key = normalize(vec3(-0.45, 0.55, 1.0));          // a light over the viewer's left shoulder
    vec3 fill = normalize(vec3(0.8, -0.3, 1.0));           // a weaker one from the lower right
    float diffuse = max(dot(n, key), 0.0) + 0.35 * max(dot(n, fill), 0.0);
    float specular = pow(max(dot(reflect(-key, n), to_eye), 0.0), 40.0);
    frag_color = vec4(u_color * (0.2 + 0.65 * diffuse) + vec3(0.25 * specular), 1.0);
}
)";

GLuint compile(GLenum kind, const char *src) {
    GLuint sh = glCreateShader(kind);
    glShaderSource(sh, 1, &src, nullptr);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048] = {0};
        glGetShaderInfoLog(sh, sizeof log, nullptr, log);
        std::fprintf(stderr, "03_engine: shader does not compile:\n%s\n", log);
        glDeleteShader(sh);
        return 0;
    }
    return sh;
}

GLuint make_program() {
    GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader), fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
    if (!vs || !fs) return 0;
    GLuint p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048] = {0};
        glGetProgramInfoLog(p, sizeof log, nullptr, log);
        std::fprintf(stderr, "03_engine: program does not link:\n%s\n", log);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

/* Interleaved layout of the engine's vertex buffer (floats): surfblend writes each table into
 * its slice of every vertex through an sfb_buffer_desc {offset, length, stride}. */
const int kStride = 9, kOffPosition = 0, kOffTangentU = 3, kOffTangentV = 6;

struct Engine {
    egl_host host{};
    GLuint program = 0, vao = 0;
    GLuint control_buffer = 0; /* base control points, 3 floats each (the engine writes them) */
    GLuint vertex_buffer = 0;  /* refined vertices, kStride floats each (surfblend writes them) */
    GLuint index_buffer = 0;   /* triangles of the refined faces (fixed topology) */
    GLuint fbo = 0, color_rb = 0, depth_rb = 0;
    GLint u_view_projection = -1, u_view = -1, u_color = -1;
    int width = 0, height = 0;
    GLsizei index_count = 0;
};

bool engine_create_objects(Engine &e, int base_count, int refined_count, const std::vector<GLuint> &indices) {
    e.program = make_program();
    if (!e.program) return false;
    e.u_view_projection = glGetUniformLocation(e.program, "u_view_projection");
    e.u_view = glGetUniformLocation(e.program, "u_view");
    e.u_color = glGetUniformLocation(e.program, "u_color");

    glGenBuffers(1, &e.control_buffer);
    glBindBuffer(GL_COPY_WRITE_BUFFER, e.control_buffer);
    glBufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)(sizeof(float) * 3 * (size_t)base_count), nullptr, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_COPY_WRITE_BUFFER, 0);

    glGenVertexArrays(1, &e.vao);
    glBindVertexArray(e.vao);
    glGenBuffers(1, &e.vertex_buffer);
    glBindBuffer(GL_ARRAY_BUFFER, e.vertex_buffer);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * kStride * (size_t)refined_count), nullptr, GL_DYNAMIC_DRAW);
    const GLsizei stride = (GLsizei)(sizeof(float) * kStride);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, (const void *)(sizeof(float) * kOffPosition));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, (const void *)(sizeof(float) * kOffTangentU));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, stride, (const void *)(sizeof(float) * kOffTangentV));
    glGenBuffers(1, &e.index_buffer);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, e.index_buffer); /* recorded in the VAO */
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(sizeof(GLuint) * indices.size()), indices.data(), GL_STATIC_DRAW);
    e.index_count = (GLsizei)indices.size();

    glGenFramebuffers(1, &e.fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, e.fbo);
    glGenRenderbuffers(1, &e.color_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, e.color_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, e.width, e.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, e.color_rb);
    glGenRenderbuffers(1, &e.depth_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, e.depth_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, e.width, e.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, e.depth_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        std::fprintf(stderr, "03_engine: the offscreen framebuffer is incomplete\n");
        return false;
    }

    /* the engine's state from here on; surfblend must leave it as it is */
    glUseProgram(e.program);
    glViewport(0, 0, e.width, e.height);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE); /* the creased box is closed, but other meshes may not be */
    glClearColor(0.25f, 0.25f, 0.28f, 0.0f); /* transparent background: alpha marks the silhouette */
    return true;
}

void engine_destroy_objects(Engine &e) {
    glUseProgram(0);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (e.program) glDeleteProgram(e.program);
    GLuint buffers[3] = {e.control_buffer, e.vertex_buffer, e.index_buffer};
    glDeleteBuffers(3, buffers);
    if (e.vao) glDeleteVertexArrays(1, &e.vao);
    if (e.fbo) glDeleteFramebuffers(1, &e.fbo);
    GLuint rbs[2] = {e.color_rb, e.depth_rb};
    glDeleteRenderbuffers(2, rbs);
}

/* ---- the camera: sfb_render's orbit camera (src/render.c), in GLM ---- */

struct Camera {
    glm::mat4 view, projection;
};

/* Bounding box of the vertices the faces use (sfb_render frames the same box). */
void face_bounds(const sfb_mesh_data &m, const float *pos, glm::dvec3 &lo, glm::dvec3 &hi) {
    lo = glm::dvec3(HUGE_VAL);
    hi = glm::dvec3(-HUGE_VAL);
    for (int k = 0; k < m.face_vertex_count; ++k) {
        const float *p = pos + 3 * (size_t)m.face_vertices[k];
        glm::dvec3 q(p[0], p[1], p[2]);
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    }
    if (!(lo.x <= hi.x)) { lo = glm::dvec3(-1.0); hi = glm::dvec3(1.0); }
}

Camera make_camera(const glm::dvec3 &lo, const glm::dvec3 &hi, float yaw_deg, float pitch_deg, float zoom, int w, int h) {
    const double half_fov = 15.0 * kPi / 180.0; /* the bounding sphere fits a 30 degree cone */
    const double margin = 0.92;                 /* share of the smaller side the sphere spans */
    glm::dvec3 centre = 0.5 * (lo + hi);
    double radius = 0.5 * glm::length(hi - lo);
    if (!(radius > 0.0) || !std::isfinite(radius)) radius = 1.0;
    double yaw = yaw_deg * kPi / 180.0, pitch = pitch_deg * kPi / 180.0;
    glm::dvec3 dir(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
    double dist = radius / std::sin(half_fov);
    glm::dvec3 eye = centre + dist * dir;
    glm::dvec3 right(std::cos(yaw), 0.0, -std::sin(yaw));
    glm::dvec3 up = glm::normalize(glm::cross(right, -dir)); /* as sfb_render: right x forward */
    /* sfb_render: pixel = centre +- focal * (x/z, y/z), focal = half * zoom / tan(15 deg) pixels,
     * the same in x and y; so GL's vertical field of view is 2 atan((h/2) / focal). */
    double focal = 0.5 * std::min(w, h) * margin * zoom / std::tan(half_fov);
    double fovy = 2.0 * std::atan(0.5 * h / focal);
    double near_plane = 0.5 * (dist - radius), far_plane = 2.0 * (dist + radius);
    Camera c;
    c.view = glm::mat4(glm::lookAt(eye, centre, up));
    c.projection = glm::mat4(glm::perspective(fovy, (double)w / (double)h, near_plane, far_plane));
    return c;
}

/* ---- the animation: the engine's own business, on the CPU ---- */

/* Twists the +x half of the control mesh about the x axis; frame f of n. */
void animate(const std::vector<float> &rest, std::vector<float> &out, int f, int n, const glm::vec3 &lo, const glm::vec3 &hi) {
    float cx = 0.5f * (lo.x + hi.x), hx = std::max(0.5f * (hi.x - lo.x), 1e-6f);
    float cy = 0.5f * (lo.y + hi.y), cz = 0.5f * (lo.z + hi.z);
    float phase = (float)(2.0 * kPi * (f + 1) / (n + 2)); /* the last frame is not the rest pose */
    float amplitude = 0.6f * std::sin(phase);
    out = rest;
    for (size_t i = 0; i + 2 < rest.size(); i += 3) {
        float t = (rest[i] - cx) / hx;
        if (t <= 0.0f) continue;
        float a = amplitude * t, c = std::cos(a), s = std::sin(a);
        float y = rest[i + 1] - cy, z = rest[i + 2] - cz;
        out[i + 1] = cy + c * y - s * z;
        out[i + 2] = cz + s * y + c * z;
    }
}

bool read_file(const std::string &path, std::string &text) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return false;
    std::ostringstream s;
    s << f.rdbuf();
    text = s.str();
    return true;
}

/* RGBA rows bottom-up (glReadPixels) -> PNG rows top-down */
bool write_png(const std::string &path, int w, int h, const unsigned char *rgba, bool bottom_up) {
    std::vector<unsigned char> rows((size_t)w * (size_t)h * 4);
    for (int y = 0; y < h; ++y)
        std::memcpy(&rows[(size_t)y * w * 4], rgba + (size_t)(bottom_up ? h - 1 - y : y) * w * 4, (size_t)w * 4);
    return stbi_write_png(path.c_str(), w, h, 4, rows.data(), w * 4) != 0;
}

void log_to_stderr(int level, const char *msg, void *) {
    if (level <= SFB_LOG_WARN) std::fprintf(stderr, "surfblend: %s\n", msg);
}

} // namespace

int main(int argc, char **argv) {
    Options opt;
    int parsed = parse_args(argc, argv, &opt);
    if (parsed != 0) return parsed > 0 ? 0 : kExitUsage;

    if (opt.out == Options().out) mkdir("out", 0777); /* the default's folder; an error shows when writing */
    std::string obj;
    if (!read_file(opt.mesh, obj)) { std::fprintf(stderr, "03_engine: cannot read %s\n", opt.mesh.c_str()); return kExitCheck; }

    /* 1. engine: the GL context (headless EGL, desktop OpenGL 4.3 core: compute shaders) */
    Engine e;
    e.width = opt.width;
    e.height = opt.height;
    char why[512];
    if (!egl_host_open(&e.host, 4, 3, why, sizeof why)) {
        std::printf("03_engine: cannot run here: %s\n", why);
        return kExitSkip;
    }
    std::printf("engine context: %s\n", e.host.renderer);

    /* 2. surfblend on the engine's context: the gl backend only, on the current context */
    sfb_context_config ccfg = sfb_context_config_init();
    sfb_backend_kind gl = SFB_BACKEND_GL;
    ccfg.backends = &gl;
    ccfg.backend_count = 1;
    ccfg.gl_use_current_context = 1;
    ccfg.ignore_environment = 1; /* SURFBLEND_BACKEND must not move it off the engine's context */
    ccfg.logger.func = log_to_stderr;
    /* the CPU reference for the checks: the ref backend, no GL at all */
    sfb_context_config rcfg = sfb_context_config_init();
    sfb_backend_kind ref = SFB_BACKEND_REF;
    rcfg.backends = &ref;
    rcfg.backend_count = 1;
    rcfg.ignore_environment = 1;

    sfb_context *ctx = nullptr, *ref_ctx = nullptr;
    sfb_mesh *mesh = nullptr;
    sfb_surface *surf = nullptr, *ref_surf = nullptr;
    sfb_mesh_data pose = {}, ref_pose = {};
    int status = 0;

    /* The engine binds a state of its own before the library starts, so that the library
     * calls below run with it in place (a real engine has its frame state bound). The vertex
     * array gets its buffers later; binding it now is what matters. */
    {
        GLuint placeholder_vao = 0;
        glGenVertexArrays(1, &placeholder_vao);
        glBindVertexArray(placeholder_vao);
        glViewport(0, 0, e.width, e.height);
        glEnable(GL_DEPTH_TEST);
        sfb_result r = library_call("sfb_context_create", [&] { return sfb_context_create(&ccfg, &ctx); });
        glBindVertexArray(0);
        glDeleteVertexArrays(1, &placeholder_vao);
        if (r != SFB_SUCCESS) {
            char probe[512];
            sfb_context_config pc = sfb_context_config_init();
            pc.gl_use_current_context = 1;
            sfb_backend_probe(SFB_BACKEND_GL, &pc, probe, sizeof probe);
            std::printf("03_engine: cannot run here: the gl backend does not start on this context: %s\n", probe);
            egl_host_close(&e.host);
            return kExitSkip;
        }
    }
    char info[512] = {0};
    sfb_context_backend_info(ctx, info, sizeof info);
    std::printf("surfblend backend: %s\n", info);
    if (sfb_context_create(&rcfg, &ref_ctx) != SFB_SUCCESS) { std::fprintf(stderr, "03_engine: no ref context\n"); return kExitCheck; }

    sfb_surface_config scfg = sfb_surface_config_init(SFB_SCHEME_CATMARK, opt.level);
    scfg.flags = SFB_REFINE_LIMIT; /* the limit tables: positions and the two tangents */
    std::vector<float> rest, moved;
    glm::vec3 base_lo, base_hi;
    std::vector<GLuint> indices;
    int base_count = 0, refined_count = 0;
    Camera cam;

    if (library_call("sfb_mesh_read_obj", [&] { return sfb_mesh_read_obj(ctx, obj.data(), obj.size(), &mesh); }) != SFB_SUCCESS) {
        std::fprintf(stderr, "03_engine: %s: %s\n", opt.mesh.c_str(), sfb_last_error(ctx));
        status = kExitCheck;
        goto done;
    }
    {
        sfb_mesh_desc d;
        sfb_mesh_info mi;
        sfb_mesh_get_desc(mesh, &d);
        sfb_mesh_get_info(mesh, &mi);
        base_count = d.vertex_count;
        rest.assign(d.positions, d.positions + 3 * (size_t)base_count);
        base_lo = glm::vec3(mi.bbox_min[0], mi.bbox_min[1], mi.bbox_min[2]);
        base_hi = glm::vec3(mi.bbox_max[0], mi.bbox_max[1], mi.bbox_max[2]);
        std::printf("mesh %s: %d vertices, %d faces, %d sharp edges (%d semi-sharp), %d corners, %d darts\n", opt.mesh.c_str(),
                    mi.vertex_count, mi.face_count, mi.sharp_edges, mi.semisharp_edges, mi.corner_vertices, mi.darts);
    }
    /* surfblend compiles the stencil tables on the CPU and uploads them to the engine's
     * context, once */
    if (library_call("sfb_surface_create", [&] { return sfb_surface_create(ctx, mesh, &scfg, &surf); }) != SFB_SUCCESS ||
        sfb_surface_create(ref_ctx, mesh, &scfg, &ref_surf) != SFB_SUCCESS) {
        std::fprintf(stderr, "03_engine: sfb_surface_create: %s%s\n", sfb_last_error(ctx), sfb_last_error(ref_ctx));
        status = kExitCheck;
        goto done;
    }

    /* Set-up, once, on the CPU: the refined topology (fixed while only positions move) and the
     * shot, framed on the last frame's pose as sfb_render would frame it. */
    animate(rest, moved, opt.frames - 1, opt.frames, base_lo, base_hi);
    if (library_call("sfb_surface_refine_positions",
                     [&] { return sfb_surface_refine_positions(surf, moved.data(), base_count, &pose); }) != SFB_SUCCESS) {
        std::fprintf(stderr, "03_engine: sfb_surface_refine_positions: %s\n", sfb_last_error(ctx));
        status = kExitCheck;
        goto done;
    }
    refined_count = pose.vertex_count;
    for (int f = 0, off = 0; f < pose.face_count; off += pose.face_sizes[f], ++f)
        for (int t = 1; t + 1 < pose.face_sizes[f]; ++t) { /* fan, as sfb_render triangulates */
            indices.push_back((GLuint)pose.face_vertices[off]);
            indices.push_back((GLuint)pose.face_vertices[off + t]);
            indices.push_back((GLuint)pose.face_vertices[off + t + 1]);
        }
    {
        glm::dvec3 lo, hi;
        face_bounds(pose, pose.limit_positions, lo, hi);
        cam = make_camera(lo, hi, opt.yaw, opt.pitch, opt.zoom, e.width, e.height);
    }
    std::printf("level %d: %d refined vertices, %d faces, %zu triangles\n", opt.level, refined_count, pose.face_count, indices.size() / 3);

    if (!engine_create_objects(e, base_count, refined_count, indices)) { status = kExitCheck; goto done; }
    expect_no_gl_error("after the engine's set-up");
    {
        const GlState engine_state = GlState::read();
        glm::mat4 vp = cam.projection * cam.view;
        glUniformMatrix4fv(e.u_view_projection, 1, GL_FALSE, glm::value_ptr(vp));
        glUniformMatrix4fv(e.u_view, 1, GL_FALSE, glm::value_ptr(cam.view));
        glUniform3f(e.u_color, 0.72f, 0.74f, 0.78f);

        /* where surfblend reads and writes, in floats: control points packed, each table
         * into its slice of the engine's interleaved vertices */
        const sfb_buffer_desc control = {0, 3, 3};
        const sfb_buffer_desc out_position = {kOffPosition, 3, kStride};
        const sfb_buffer_desc out_tangent_u = {kOffTangentU, 3, kStride};
        const sfb_buffer_desc out_tangent_v = {kOffTangentV, 3, kStride};
        double update_sum = 0.0, update_min = HUGE_VAL, update_max = 0.0;
        typedef std::chrono::steady_clock clock;

        for (int f = 0; f < opt.frames; ++f) {
            /* 3. update: the engine animates its control points and uploads them ... */
            auto t0 = clock::now();
            animate(rest, moved, f, opt.frames, base_lo, base_hi);
            glBindBuffer(GL_COPY_WRITE_BUFFER, e.control_buffer);
            glBufferSubData(GL_COPY_WRITE_BUFFER, 0, (GLsizeiptr)(sizeof(float) * moved.size()), moved.data());
            glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
            /* ... and surfblend refines them on the GPU, straight into the vertex buffer the
             * engine draws from (compute shaders; it ends with a memory barrier) */
            sfb_result r = library_call("sfb_surface_eval_stencils_gl(LIMIT)", [&] {
                return sfb_surface_eval_stencils_gl(surf, SFB_TABLE_LIMIT, e.control_buffer, control, e.vertex_buffer, out_position);
            });
            if (r == SFB_SUCCESS)
                r = library_call("sfb_surface_eval_stencils_gl(TANGENT_U)", [&] {
                    return sfb_surface_eval_stencils_gl(surf, SFB_TABLE_TANGENT_U, e.control_buffer, control, e.vertex_buffer, out_tangent_u);
                });
            if (r == SFB_SUCCESS)
                r = library_call("sfb_surface_eval_stencils_gl(TANGENT_V)", [&] {
                    return sfb_surface_eval_stencils_gl(surf, SFB_TABLE_TANGENT_V, e.control_buffer, control, e.vertex_buffer, out_tangent_v);
                });
            if (r != SFB_SUCCESS) {
                check_failed(std::string("sfb_surface_eval_stencils_gl: ") + sfb_last_error(ctx));
                status = kExitCheck;
                break;
            }
            glFinish(); /* only to time the update; an engine would not wait here */
            auto t1 = clock::now();

            /* 4. draw: the engine's program, VAO and framebuffer, all still bound */
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            glDrawElements(GL_TRIANGLES, e.index_count, GL_UNSIGNED_INT, nullptr);
            glFinish();
            auto t2 = clock::now();
            double update_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
            double draw_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
            update_sum += update_ms;
            update_min = std::min(update_min, update_ms);
            update_max = std::max(update_max, update_ms);
            std::printf("frame %2d: update %.3f ms, draw %.3f ms\n", f, update_ms, draw_ms);
            char where[64];
            std::snprintf(where, sizeof where, "after frame %d", f);
            expect_no_gl_error(where);
            std::string d = GlState::read().diff(engine_state);
            if (!d.empty()) check_failed(std::string(where) + ": the engine's state is not what it set: " + d);
        }
        if (status == 0)
            std::printf("update over %d frames: min %.3f ms, mean %.3f ms, max %.3f ms (%d refined vertices, 3 tables)\n", opt.frames,
                        update_min, update_sum / opt.frames, update_max, refined_count);
    }
    if (status != 0) goto done;

    /* 5. the last frame as PNG */
    {
        std::vector<unsigned char> pixels((size_t)e.width * e.height * 4);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, e.width, e.height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
        expect_no_gl_error("after glReadPixels");
        if (!write_png(opt.out, e.width, e.height, pixels.data(), true)) {
            check_failed("cannot write " + opt.out);
        } else {
            std::printf("wrote %s (%dx%d, the last frame)\n", opt.out.c_str(), e.width, e.height);
        }
    }

    /* check: what surfblend wrote into the engine's buffer is the ref backend's refinement of
     * the last pose (read back once, here, for the check only) */
    if (sfb_surface_refine_positions(ref_surf, moved.data(), base_count, &ref_pose) != SFB_SUCCESS) {
        check_failed(std::string("ref refinement: ") + sfb_last_error(ref_ctx));
    } else {
        std::vector<float> gpu((size_t)refined_count * kStride);
        glBindBuffer(GL_COPY_READ_BUFFER, e.vertex_buffer);
        glGetBufferSubData(GL_COPY_READ_BUFFER, 0, (GLsizeiptr)(sizeof(float) * gpu.size()), gpu.data());
        glBindBuffer(GL_COPY_READ_BUFFER, 0);
        expect_no_gl_error("after reading the vertex buffer back");
        glm::dvec3 lo, hi;
        face_bounds(ref_pose, ref_pose.limit_positions, lo, hi);
        double diag = glm::length(hi - lo), tmax = 1.0, worst[3] = {0, 0, 0};
        const float *want[3] = {ref_pose.limit_positions, ref_pose.tangents_u, ref_pose.tangents_v};
        for (int v = 0; v < refined_count; ++v)
            for (int c = 0; c < 3; ++c) {
                tmax = std::max(tmax, (double)std::fabs(ref_pose.tangents_u[3 * v + c]));
                tmax = std::max(tmax, (double)std::fabs(ref_pose.tangents_v[3 * v + c]));
            }
        for (int k = 0; k < 3; ++k)
            for (int v = 0; v < refined_count; ++v)
                for (int c = 0; c < 3; ++c) {
                    double err = std::fabs((double)gpu[(size_t)v * kStride + 3 * k + c] - (double)want[k][3 * v + c]);
                    if (!(err <= worst[k])) worst[k] = std::isfinite(err) ? err : HUGE_VAL;
                }
        double tol_p = 1e-5 * diag, tol_t = 1e-5 * diag * tmax;
        std::printf("vertex buffer vs ref: positions %.3g (tol %.3g), tangents %.3g %.3g (tol %.3g)\n", worst[0], tol_p, worst[1],
                    worst[2], tol_t);
        if (!(worst[0] <= tol_p) || !(worst[1] <= tol_t) || !(worst[2] <= tol_t))
            check_failed("the refined vertices in the engine's buffer differ from the ref backend's");
    }

    /* --reference: sfb_render's software picture of the same surface, same camera */
    if (!opt.reference.empty() && ref_pose.vertex_count > 0) {
        sfb_render_config rc = sfb_render_config_init(SFB_RENDER_SHADED);
        sfb_image img = {};
        rc.width = e.width;
        rc.height = e.height;
        rc.positions = ref_pose.limit_positions; /* what the engine draws */
        rc.normals = ref_pose.normals;
        rc.view_set = 1;
        rc.yaw = opt.ref_yaw;
        rc.pitch = opt.ref_pitch;
        rc.zoom = opt.zoom;
        const unsigned char bg[4] = {64, 64, 71, 0}; /* the engine's clear colour, transparent */
        std::memcpy(rc.background, bg, 4);
        if (sfb_render(ref_ctx, &ref_pose, &rc, &img) != SFB_SUCCESS) {
            check_failed(std::string("sfb_render: ") + sfb_last_error(ref_ctx));
        } else {
            if (!write_png(opt.reference, img.width, img.height, img.rgba, false)) check_failed("cannot write " + opt.reference);
            else std::printf("wrote %s (sfb_render, view %g,%g)\n", opt.reference.c_str(), opt.ref_yaw, opt.ref_pitch);
            sfb_image_free(&img);
        }
    }

done:
    sfb_mesh_data_free(&pose);
    sfb_mesh_data_free(&ref_pose);
    if (surf) library_call("sfb_surface_destroy", [&] { sfb_surface_destroy(surf); return SFB_SUCCESS; });
    if (mesh) sfb_mesh_destroy(mesh);
    if (ctx) library_call("sfb_context_destroy", [&] { sfb_context_destroy(ctx); return SFB_SUCCESS; });
    sfb_surface_destroy(ref_surf);
    sfb_context_destroy(ref_ctx);
    engine_destroy_objects(e);
    egl_host_close(&e.host);
    std::printf("%d surfblend calls on the engine's context; %d check%s failed\n", g_library_calls, g_failures,
                g_failures == 1 ? "" : "s");
    if (status == 0 && g_failures) status = kExitCheck;
    return status;
}
