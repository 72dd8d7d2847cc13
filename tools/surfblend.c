/* surfblend command-line tool: `surfblend --help` lists the commands, `surfblend CMD --help` one
 * command's options. Every option is one row of the table `options` below (its name, value,
 * commands, help text and where it is stored); one parser (parse_args) reads every command's
 * arguments from it and the usage text is printed from it.
 * Exit codes: 0 success, 1 bad input (message on stderr), 2 usage error. */
#include "surfblend.h"
#include "tools/cli_common.h"
/* PNG output (Debian libstb-dev; the trimming masks are read by cli_common.c); the library
 * itself only takes and returns raw pixel buffers */
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb/stb_image_write.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the options ---- */

/* What the parser counts per option (o->seen[id]: how often it was given); several rows may
 * share one id (one option spelt per command, or the three picture modes). */
enum {
    O_HELP, O_BACKEND, O_OUTPUT, O_SCHEME, O_LEVEL, O_LIMIT, O_WEIGHTS, O_LOCATIONS, O_RANDOM, O_SEED, O_DERIVATIVES,
    O_RATE, O_TOLERANCE, O_SPLIT, O_TRIM, O_TILES, O_VARIANT, O_DARTS, O_NORMALS_LEVEL, O_WEIGHTS_LEVEL, O_P,
    O_AVERAGING, O_ALL_SUBDIVIDED, O_NORMALS, O_POSITIONS, O_MODE, O_EDGES, O_SIZE, O_VIEW, O_ZOOM, O_STRIPES, O_CREASE_ANGLE, O_TRIANGULATE, O_SHARPNESS,
    O_AMODE, O_LIGHT, O_CURVATURE, O_EYE, O_TARGET, O_UP, O_FOV, O_ORTHO, O_POLYGON, O_BAND,
    O_RADIUS, O_ANGLE, O_PROFILE, O_CURVE, O_SAMPLES, O_ALPHA, O_SKIP_FAILED, O_RELAX,
    O_COUNT_
};

struct cli_command;

/* Every command's options, in one place; what a command does not take keeps its default. */
typedef struct cli_opts {
    const struct cli_command *cmd;
    const char *in, *outp, *backend;
    int scheme, level, limit, weights;                      /* weights: manifold blend weights */
    const char *locfile;                                    /* eval */
    long nrandom, seed;
    int derivatives;
    long rate, tiles[2];                                    /* tess, render --scheme manifold */
    double tolerance;
    int split;
    const char *trim;
    int variant, darts, normals_level, weights_level, all_subdivided, averaging; /* shade, render */
    double p;
    int normals, limit_pos, mode, edges;                    /* render */
    long size[2];
    double view[2], zoom, stripes;
    double crease_angle;                                    /* --crease-angle (seen[O_CREASE_ANGLE]) */
    int triangulate;                                        /* --triangulate */
    double sharpness;                                       /* --sharpness (seen[O_SHARPNESS]): tribezier */
    int amode, curvature, ortho, polygon;                   /* analyze */
    const char *light;
    double eye[3], target[3], up[3], fov, band;
    double radius, angle, alpha;                            /* fillet */
    const char *profile, *curve;
    long samples, relax;
    int skip_failed;
    int seen[O_COUNT_];
} cli_opts;

/* Command bits: which commands take an option. */
enum {
    C_INFO = 1, C_REFINE = 2, C_EVAL = 4, C_TESS = 8, C_SHADE = 16, C_RENDER = 32, C_BACKENDS = 64, C_ANALYZE = 128,
    C_FILLET = 256, C_ALL = 511, C_SURFACE = C_REFINE | C_EVAL | C_TESS | C_SHADE | C_RENDER | C_ANALYZE, C_SHADING = C_SHADE | C_RENDER
};

typedef enum opt_kind {
    K_HELP,     /* print the command's usage, exit 0 */
    K_SET,      /* no value: stores .value (int) */
    K_STRING,   /* const char * */
    K_INT,      /* int in [.lo, .hi] */
    K_LONG,     /* long in [.lo, .hi] */
    K_LONG2,    /* two values, long[2] in [.lo, .hi] */
    K_DOUBLE,   /* any number */
    K_POSITIVE, /* a number in (0, .hi] */
    K_CHOICE,   /* one of .choices: int */
    K_SCHEME,   /* a scheme name (cli_scheme_from_name) not in the mask .value: int */
    K_LEVEL,    /* a shading level >= 0 (int; 0: SFB_SHADE_LEVEL_CONTROL) */
    K_SIZE,     /* WxH, long[2] each 1..1000000 */
    K_VIEW,     /* YAW,PITCH in degrees, double[2] */
    K_VEC3      /* X,Y,Z, double[3], finite */
} opt_kind;

typedef struct opt_choice { const char *name; int value, hidden; } opt_choice;

typedef struct opt_spec {
    const char *name, *alias; /* alias: another spelling (shown after the name) */
    opt_kind kind;
    unsigned cmds;            /* C_* */
    int id;                   /* O_* */
    size_t offset;            /* where the value goes in cli_opts */
    const char *metavar;      /* NULL: from .choices */
    const opt_choice *choices;
    double lo, hi;
    int value;
    const char *needs;        /* "--NAME needs ...": NULL: from .choices */
    const char *help;         /* '\n' continues on the next line */
} opt_spec;

static const opt_choice weight_choices[] = { { "hermite", SFB_MANIFOLD_WEIGHTS_HERMITE, 0 }, { "cinf", SFB_MANIFOLD_WEIGHTS_CINF, 0 }, { NULL, 0, 0 } };
static const opt_choice variant_choices[] = {
    { "A", SFB_SHADE_VARIANT_A, 0 }, { "B", SFB_SHADE_VARIANT_B, 0 }, { "a", SFB_SHADE_VARIANT_A, 1 }, { "b", SFB_SHADE_VARIANT_B, 1 }, { NULL, 0, 0 }
};
static const opt_choice darts_choices[] = { { "smooth", SFB_SHADE_DARTS_SMOOTH, 0 }, { "sharp", SFB_SHADE_DARTS_SHARP, 0 }, { NULL, 0, 0 } };
static const opt_choice averaging_choices[] = {
    { "linear", SFB_SHADE_AVERAGE_LINEAR, 0 }, { "renormalized", SFB_SHADE_AVERAGE_RENORMALIZED, 0 },
    { "spherical", SFB_SHADE_AVERAGE_SPHERICAL, 0 }, { NULL, 0, 0 }
};
/* render --normals: the values index normal_names */
static const opt_choice normals_choices[] = { { "limit", 0, 0 }, { "subdivided", 1, 0 }, { "blended", 2, 0 }, { NULL, 0, 0 } };
static const char *const normal_names[3] = { "limit", "subdivided", "blended" };
static const opt_choice positions_choices[] = { { "refined", 0, 0 }, { "limit", 1, 0 }, { NULL, 0, 0 } };
static const opt_choice amode_choices[] = {
    { "reflection", SFB_ANALYZE_REFLECTION, 0 }, { "highlight", SFB_ANALYZE_HIGHLIGHT, 0 }, { "zebra", SFB_ANALYZE_ZEBRA, 0 },
    { "isophote", SFB_ANALYZE_ISOPHOTE, 0 }, { "curvature", SFB_ANALYZE_CURVATURE, 0 }, { "normals", SFB_ANALYZE_NORMALS, 0 },
    { "shaded", SFB_ANALYZE_SHADED, 0 }, { NULL, 0, 0 }
};
static const opt_choice curvature_choices[] = {
    { "gaussian", SFB_CURVATURE_GAUSSIAN, 0 }, { "mean", SFB_CURVATURE_MEAN, 0 }, { "max", SFB_CURVATURE_MAX_ABS, 0 }, { NULL, 0, 0 }
};

#define AT(field) offsetof(cli_opts, field)
#define ANY_INT -2147483647.0, 2147483647.0
#define NO_BILINEAR (1 << SFB_SCHEME_BILINEAR)

/* The order of the rows is the order of the usage text. */
static const opt_spec options[] = {
    { "--scheme", NULL, K_SCHEME, C_REFINE, O_SCHEME, AT(scheme), "catmark|loop|bilinear", NULL, 0, 0, 0,
      "catmark, loop or bilinear", "subdivision scheme (default: from the file name prefix loop_ or bilinear_, else catmark)" },
    { "--scheme", NULL, K_SCHEME, C_EVAL | C_TESS | C_ANALYZE, O_SCHEME, AT(scheme), "catmark|loop|manifold|tribezier|pn", NULL, 0, 0, 0,
      "catmark, loop, manifold, tribezier or pn", "a subdivision limit surface, the manifold blending surface (seed 000), quartic\n"
      "triangular Bezier surfaces with sharpness (seed 004) or PN triangles\n"
      "(default: from the file name prefix loop_ or bilinear_, else catmark)" },
    { "--scheme", NULL, K_SCHEME, C_SHADE, O_SCHEME, AT(scheme), "catmark|loop", NULL, 0, 0, NO_BILINEAR,
      "catmark or loop", "subdivision scheme (default: from the file name prefix loop_, else catmark)" },
    { "--scheme", NULL, K_SCHEME, C_RENDER, O_SCHEME, AT(scheme), "catmark|loop|manifold|tribezier|pn", NULL, 0, 0, NO_BILINEAR,
      "catmark, loop, manifold, tribezier or pn", "subdivision scheme (default: from the file name prefix loop_, else catmark);\n"
      "manifold, tribezier, pn: draw the manifold blending surface (seed 000), the quartic triangular\n"
      "Bezier surface (seed 004) or PN triangles tessellated instead" },
    { "--sharpness", NULL, K_DOUBLE, C_EVAL | C_TESS | C_RENDER | C_ANALYZE, O_SHARPNESS, AT(sharpness), "S", NULL, 0, 0, 0, "a number in [0, 1]",
      "tribezier: one s in [0, 1] for every tagged crease and corner (default: each tag's\nsharpness clamped to [0, 1])" },
    { "--level", NULL, K_INT, C_REFINE, O_LEVEL, AT(level), "L", NULL, 0, 1000, 0, "a number >= 0",
      "uniform refinement level 0..10 (default 2)" },
    { "--level", NULL, K_INT, C_SHADING, O_LEVEL, AT(level), "L", NULL, 0, 1000, 0, "a number >= 0",
      "uniform refinement level 0..10 (default 3)" },
    { "--limit", NULL, K_SET, C_REFINE, O_LIMIT, AT(limit), NULL, NULL, 0, 0, 1, NULL,
      "write limit positions (and limit normals as vn) instead of refined points" },
    { "--manifold-weights", "--weights", K_CHOICE, C_EVAL | C_TESS | C_ANALYZE, O_WEIGHTS, AT(weights), NULL, weight_choices, 0, 0, 0, NULL,
      "manifold blend weights: Hermite (default) or C-infinity (--weights: the old spelling)" },
    { "--locations", NULL, K_STRING, C_EVAL, O_LOCATIONS, AT(locfile), "FILE", NULL, 0, 0, 0, "a file name",
      "lines 'face u v' (parametric face; u, v in [0,1], and u + v <= 1 on Loop's\ntriangles; '#' starts a comment)" },
    { "--random", NULL, K_LONG, C_EVAL, O_RANDOM, AT(nrandom), "N", NULL, 0, 10000000.0, 0, "a count 0..10000000",
      "N random locations on faces that are not holes (deterministic for a seed)" },
    { "--seed", NULL, K_LONG, C_EVAL, O_SEED, AT(seed), "S", NULL, 0, 2147483647.0, 0, "a number >= 0",
      "the seed of --random (default 1)" },
    { "--derivatives", NULL, K_SET, C_EVAL, O_DERIVATIVES, AT(derivatives), NULL, NULL, 0, 0, 1, NULL, "also print du and dv" },
    /* the range (1..1024) is the library's to check and report */
    { "--rate", NULL, K_LONG, C_TESS, O_RATE, AT(rate), "N", NULL, ANY_INT, 0, "a number",
      "segments per parametric-face edge, 1..1024 (required)" },
    { "--tolerance", NULL, K_DOUBLE, C_TESS, O_TOLERANCE, AT(tolerance), "T", NULL, 0, 0, 0, "a number",
      "adaptive: per face the smallest rate <= N within chordal error T" },
    { "--split-creases", NULL, K_SET, C_TESS, O_SPLIT, AT(split), NULL, NULL, 0, 0, 1, NULL,
      "separate vertices (and normals) on each side of infinitely sharp creases" },
    { "--variant", NULL, K_CHOICE, C_SHADING, O_VARIANT, AT(variant), NULL, variant_choices, 0, 0, 0, NULL,
      "sharp vertices: B (default) blend weight 0, A treated as smooth ones" },
    { "--darts", NULL, K_CHOICE, C_SHADING, O_DARTS, AT(darts), NULL, darts_choices, 0, 0, 0, NULL,
      "darts count as smooth (default) or sharp vertices for the weights" },
    { "--normals-level", NULL, K_LEVEL, C_SHADING, O_NORMALS_LEVEL, AT(normals_level), "L", NULL, 0, 1000, 0,
      "a level >= 0 (0: the control mesh)", "level where the subdivided normals N_S start (0: control mesh; default 1)" },
    { "--weights-level", NULL, K_LEVEL, C_SHADING, O_WEIGHTS_LEVEL, AT(weights_level), "L", NULL, 0, 1000, 0,
      "a level >= 0 (0: the control mesh)", "level where the blend weights are seeded (0: control mesh; default 1)" },
    { "--p", NULL, K_POSITIVE, C_SHADING, O_P, AT(p), "P", NULL, 0, 1e30, 0, "a number > 0",
      "blend exponent, > 0 (default 1): N_B = (1 - b^P) N_L + b^P N_S" },
    { "--averaging", NULL, K_CHOICE, C_SHADING, O_AVERAGING, AT(averaging), NULL, averaging_choices, 0, 0, 0, NULL,
      "how N_S is averaged from one level to the next (default linear)" },
    { "--all-subdivided", NULL, K_SET, C_SHADING, O_ALL_SUBDIVIDED, AT(all_subdivided), NULL, NULL, 0, 0, 1, NULL,
      "compute N_S at every vertex, not only where b > 0" },
    { "--limit", NULL, K_SET, C_SHADE, O_LIMIT, AT(limit), NULL, NULL, 0, 0, 1, NULL, "write limit positions instead of refined points" },
    { "--normals", NULL, K_CHOICE, C_RENDER, O_NORMALS, AT(normals), NULL, normals_choices, 0, 0, 0, NULL,
      "which normal field to draw (default blended)" },
    { "--highlight", NULL, K_SET, C_RENDER, O_MODE, AT(mode), NULL, NULL, 0, 0, SFB_RENDER_HIGHLIGHT, NULL,
      "draw highlight lines (default: grey shading)" },
    { "--blend-weights", "--weights", K_SET, C_RENDER, O_MODE, AT(mode), NULL, NULL, 0, 0, SFB_RENDER_WEIGHTS, NULL,
      "draw the shading's blend weights (blue 0 .. red 1) (--weights: the old spelling)" },
    { "--normal-colors", NULL, K_SET, C_RENDER, O_MODE, AT(mode), NULL, NULL, 0, 0, SFB_RENDER_NORMALS, NULL, "draw normals as RGB" },
    { "--positions", NULL, K_CHOICE, C_RENDER, O_POSITIONS, AT(limit_pos), NULL, positions_choices, 0, 0, 0, NULL,
      "refined points or limit positions (default limit)" },
    /* the range (1..8192) is the library's to check and report */
    { "--size", NULL, K_SIZE, C_RENDER | C_ANALYZE, O_SIZE, AT(size), "WxH", NULL, 0, 0, 0, "positive WxH, e.g. 800x600",
      "picture size, 1..8192 each (default 640x480)" },
    { "--view", NULL, K_VIEW, C_RENDER | C_ANALYZE, O_VIEW, AT(view), "YAW,PITCH", NULL, 0, 0, 0, "YAW,PITCH in degrees, e.g. 30,20",
      "camera angles in degrees around the y axis and above the xz plane (default 30,25)" },
    { "--zoom", NULL, K_POSITIVE, C_RENDER | C_ANALYZE, O_ZOOM, AT(zoom), "Z", NULL, 0, 1e6, 0, "a number > 0",
      "magnification (default 1: the bounding sphere fits)" },
    { "--stripes", NULL, K_POSITIVE, C_RENDER, O_STRIPES, AT(stripes), "N", NULL, 0, 1e5, 0, "a number in (0, 100000]",
      "highlight lines per object diameter (default 8)" },
    { "--stripes", NULL, K_POSITIVE, C_ANALYZE, O_STRIPES, AT(stripes), "N", NULL, 0, 1e5, 0, "a number in (0, 100000]",
      "stripes across the light (reflection: 16 over the plane; highlight: 5 per\n"
      "object diameter; zebra: 16 per 180 degrees; isophote: 10 bands)" },
    { "--mode", NULL, K_CHOICE, C_ANALYZE, O_AMODE, AT(amode), NULL, amode_choices, 0, 0, 0, NULL,
      "what to draw from the exact surface (default reflection: seed 003's area light)" },
    { "--light", NULL, K_STRING, C_ANALYZE, O_LIGHT, AT(light), "stripes|lattice|circles|FILE.png", NULL, 0, 0, 0,
      "stripes, lattice, circles or a PNG file", "the light plane's texture (reflection, highlight; default stripes)" },
    { "--band", NULL, K_POSITIVE, C_ANALYZE, O_BAND, AT(band), "W", NULL, 0, 0.999, 0, "a number in (0, 1)",
      "lit share of each stripe period (default 0.5, highlight 0.7, lattice 0.2;\n"
      "circles: diameter per cell, 0.6)" },
    { "--curvature", NULL, K_CHOICE, C_ANALYZE, O_CURVATURE, AT(curvature), NULL, curvature_choices, 0, 0, 0, NULL,
      "--mode curvature: Gaussian (default), mean or largest absolute principal" },
    { "--level", NULL, K_INT, C_ANALYZE, O_LEVEL, AT(level), "L", NULL, 1, SFB_ANALYZE_MAX_LEVEL, 0, "a number in 1..8",
      "proxy: 2^L segments per parametric-face edge (default: chosen from the\n"
      "view, about 256 pixels per proxy triangle or fewer; --polygon-based: 2);\n"
      "the picture does not depend on it (every pixel is projected onto the\n"
      "exact surface)" },
    { "--polygon-based", NULL, K_SET, C_ANALYZE, O_POLYGON, AT(polygon), NULL, NULL, 0, 0, 1, NULL,
      "shade the proxy's interpolated limit normals instead (the method seed 003\n"
      "shows to be wrong; for comparison)" },
    { "--eye", NULL, K_VEC3, C_ANALYZE, O_EYE, AT(eye), "X,Y,Z", NULL, 0, 0, 0, "X,Y,Z, e.g. 0,2,5", "camera position (with --target)" },
    { "--target", NULL, K_VEC3, C_ANALYZE, O_TARGET, AT(target), "X,Y,Z", NULL, 0, 0, 0, "X,Y,Z, e.g. 0,0,0", "point the camera looks at" },
    { "--up", NULL, K_VEC3, C_RENDER | C_ANALYZE, O_UP, AT(up), "X,Y,Z", NULL, 0, 0, 0, "X,Y,Z, e.g. 0,0,1", "camera up direction (default 0,1,0); without --eye the --view orbit turns about it (0,0,1 for a z-up model)" },
    { "--fov", NULL, K_POSITIVE, C_ANALYZE, O_FOV, AT(fov), "DEG", NULL, 0, 178, 0, "degrees in (0, 178]",
      "vertical field of view (default 30; --orthographic: the picture's height in model units)" },
    { "--orthographic", NULL, K_SET, C_ANALYZE, O_ORTHO, AT(ortho), NULL, NULL, 0, 0, 1, NULL, "orthographic camera (default perspective)" },
    { "--edges", NULL, K_SET, C_RENDER, O_EDGES, AT(edges), NULL, NULL, 0, 0, 1, NULL, "draw the refined mesh's edges" },
    { "--rate", NULL, K_LONG, C_RENDER, O_RATE, AT(rate), "N", NULL, ANY_INT, 0, "a number",
      "--scheme manifold, tribezier, pn: segments per parametric-face edge, 1..1024 (default 16)" },
    { "--manifold-weights", NULL, K_CHOICE, C_RENDER, O_WEIGHTS, AT(weights), NULL, weight_choices, 0, 0, 0, NULL,
      "--scheme manifold: blend weights Hermite (default) or C-infinity" },
    { "--trim", NULL, K_STRING, C_TESS | C_RENDER, O_TRIM, AT(trim), "MASK.png", NULL, 0, 0, 0, "a PNG file",
      "trim with a mask over each parametric face's (u,v) square (seed 000 V.5):\n"
      "grey level >= 50% kept, darker trimmed; the picture's top row is v = 1" },
    /* the counts are the library's to check against the mask */
    { "--trim-tiles", NULL, K_LONG2, C_TESS | C_RENDER, O_TILES, AT(tiles), "U V", NULL, ANY_INT, 0, "two numbers U V",
      "the mask is an atlas of U x V tiles, tile t (row-major from v = 0) for\n"
      "parametric face t; later faces untrimmed (default: one mask for all)" },
    { "--crease-angle", NULL, K_POSITIVE, C_INFO | C_SURFACE, O_CREASE_ANGLE, AT(crease_angle), "DEG", NULL, 0, 180, 0,
      "degrees in (0, 180]", "edges whose dihedral angle is over DEG become infinitely sharp creases (a faceted\n"
      "mesh with no crease tags; sfb_mesh_crease_by_angle)" },
    { "--triangulate", NULL, K_SET, C_INFO | C_SURFACE | C_FILLET, O_TRIANGULATE, AT(triangulate), NULL, NULL, 0, 0, 1, NULL,
      "split every face of more than three corners into triangles first (quads along the shorter\n"
      "diagonal; sfb_mesh_triangulate): what loop, tribezier, pn and fillet need from quads" },
    { "--radius", NULL, K_POSITIVE, C_FILLET, O_RADIUS, AT(radius), "R", NULL, 0, 1e30, 0, "a number > 0",
      "the rolling ball's radius (required)" },
    { "--angle", NULL, K_POSITIVE, C_FILLET, O_ANGLE, AT(angle), "DEG", NULL, 0, 179.999, 0, "degrees in (0, 180)",
      "edges whose dihedral angle is over DEG are the features to fillet (default 30)" },
    { "--profile", NULL, K_STRING, C_FILLET, O_PROFILE, AT(profile), "arc|conic:W|sharpen|hermite[:S]", NULL, 0, 0, 0,
      "arc, conic:W, sharpen or hermite[:S]", "cross-section: the ball's arc (default), a conic of middle weight W\n"
      "(< 1 flatter, > 1 fuller), the sharp corner back (sharpen), a Hermite cubic" },
    { "--curve", NULL, K_STRING, C_FILLET, O_CURVE, AT(curve), "V0,V1,...[;...]", NULL, 0, 0, 0, "vertex indices",
      "blending curves as chains of mesh edges (0-based vertex indices; a curve\n"
      "closes when its last vertex is its first; ';' separates curves); default:\n"
      "the features found by --angle" },
    { "--samples", NULL, K_LONG, C_FILLET, O_SAMPLES, AT(samples), "N", NULL, 2, 100000, 0, "a number in 2..100000",
      "initial spine samples by arc length (default 40; refined where the spine bends)" },
    { "--alpha", NULL, K_POSITIVE, C_FILLET, O_ALPHA, AT(alpha), "A", NULL, 0, 100, 0, "a number in [1, 100]",
      "base patches: faces within A x radius of the curve (default 1.75)" },
    { "--relax", NULL, K_LONG, C_FILLET, O_RELAX, AT(relax), "N", NULL, 0, 10000, 0, "a number in 0..10000",
      "steps of Laplacian optimisation of the map in 2D (seed 5.2; default 0:\n"
      "the conformal map alone)" },
    { "--skip-failed", NULL, K_SET, C_FILLET, O_SKIP_FAILED, AT(skip_failed), NULL, NULL, 0, 0, 1, NULL,
      "leave a curve the radius cannot fillet sharp and go on (said per curve)\n"
      "instead of failing; fails only when no curve could be filleted" },
    { "--backend", NULL, K_STRING, C_SURFACE, O_BACKEND, AT(backend), "NAME", NULL, 0, 0, 0, "a name",
      "ref|simd|gl|osmesa, tried first (else SURFBLEND_BACKEND, else the default order)" },
    { "-o", "--output", K_STRING, C_SURFACE | C_FILLET, O_OUTPUT, AT(outp), "FILE", NULL, 0, 0, 0, "a file name",
      "the output file ('-': standard output)" },
    { "-h", "--help", K_HELP, C_ALL, O_HELP, 0, NULL, NULL, 0, 0, 0, NULL, "print this command's usage and exit" },
};
#define OPTION_COUNT (sizeof options / sizeof options[0])

/* A command: its synopsis, what it does, how it runs. */
typedef struct cli_command {
    const char *name;
    unsigned bit;             /* C_* */
    const char *args;         /* the synopsis after the name */
    const char *summary;
    const char *notes;        /* after the options; NULL: none */
    int inputs;               /* input files: 1 or 0 */
    const char *output;       /* -o is required and names this ("OUT.obj"); NULL: optional */
    int (*run)(cli_opts *o);
} cli_command;

/* ---- usage, printed from the tables ---- */

/* The values of a choice (or the schemes of a K_SCHEME row), joined with sep and last. */
static void choice_list(const opt_spec *s, char *buf, size_t cap, const char *sep, const char *last) {
    const opt_choice *c;
    size_t n = 0, shown = 0, k = 0;
    buf[0] = 0;
    for (c = s->choices; c && c->name; ++c) shown += !c->hidden;
    for (c = s->choices; c && c->name; ++c) {
        if (c->hidden) continue;
        n += (size_t)snprintf(buf + n, n < cap ? cap - n : 0, "%s%s", k == 0 ? "" : k + 1 == shown ? last : sep, c->name);
        ++k;
        if (n >= cap) { buf[cap - 1] = 0; return; }
    }
}

static void print_option(FILE *f, const opt_spec *s) {
    char col[160], meta[96];
    const char *h;
    if (s->metavar) snprintf(meta, sizeof meta, "%s", s->metavar);
    else choice_list(s, meta, sizeof meta, "|", "|");
    snprintf(col, sizeof col, "%s%s%s%s%s", s->name, s->alias ? ", " : "", s->alias ? s->alias : "", meta[0] ? " " : "", meta);
    if (strlen(col) <= 32) fprintf(f, "      %-32s ", col);
    else fprintf(f, "      %s\n%39s", col, "");
    for (h = s->help; *h; ++h) {
        fputc(*h, f);
        if (*h == '\n') fprintf(f, "%39s", "");
    }
    fputc('\n', f);
}

/* One command: the synopsis, its options (without -h in the list of all commands), notes. */
static void print_command(FILE *f, const cli_command *c, int with_help) {
    char line[160];
    size_t i;
    int n = snprintf(line, sizeof line, "  surfblend %s%s%s", c->name, c->args[0] ? " " : "", c->args);
    fprintf(f, "%s%*s%s\n", line, n < 44 ? 45 - n : 3, "", c->summary);
    for (i = 0; i < OPTION_COUNT; ++i)
        if ((options[i].cmds & c->bit) && (with_help || options[i].kind != K_HELP)) print_option(f, &options[i]);
    if (c->notes) fprintf(f, "    %s\n", c->notes);
}

static const char names_note[] =
    "option names: the manifold blend weights are --manifold-weights (eval, tess, render) and render's\n"
    "picture of the shading's blend weights is --blend-weights; the old spelling --weights still works\n"
    "where it is unambiguous: for --manifold-weights on eval and tess, for --blend-weights on render\n";
static const char exit_note[] = "exit codes: 0 success, 1 bad input, 2 usage error\n";

static void print_command_usage(FILE *f, const cli_command *c) {
    fputs("usage:\n", f);
    print_command(f, c, 1);
    fputs(exit_note, f);
}

/* A usage error of command c (NULL: before a command): the message, then the usage, on stderr;
 * returns 2. */
static void print_usage(FILE *f);
static int usage_error(const cli_command *c, const char *msg) {
    if (msg) cli_error("%s", msg);
    if (c) {
        print_command_usage(stderr, c);
        fprintf(stderr, "(surfblend --help lists every command)\n");
    } else {
        print_usage(stderr);
    }
    return 2;
}

/* ---- the parser ---- */

static int parse_long(const char *s, long lo, long hi, long *out) {
    char *end;
    long v = strtol(s, &end, 10);
    if (end == s || *end || v < lo || v > hi) return 0;
    *out = v;
    return 1;
}

static int parse_number(const char *s, double *out) {
    char *end;
    *out = strtod(s, &end);
    return end != s && !*end;
}

/* WxH, each 1..1000000 */
static int parse_size(const char *s, long *wh) {
    char *end;
    const char *hs;
    wh[0] = strtol(s, &end, 10);
    if (end == s || (*end != 'x' && *end != 'X')) return 0;
    hs = end + 1;
    wh[1] = strtol(hs, &end, 10);
    if (end == hs || *end) return 0;
    return wh[0] >= 1 && wh[1] >= 1 && wh[0] <= 1000000L && wh[1] <= 1000000L;
}

/* YAW,PITCH, finite */
static int parse_view(const char *s, double *yp) {
    char *end;
    const char *ps;
    yp[0] = strtod(s, &end);
    if (end == s || *end != ',') return 0;
    ps = end + 1;
    yp[1] = strtod(ps, &end);
    return end != ps && !*end && isfinite(yp[0]) && isfinite(yp[1]);
}

/* X,Y,Z, finite */
static int parse_vec3(const char *s, double *xyz) {
    char *end;
    int i;
    for (i = 0; i < 3; ++i) {
        xyz[i] = strtod(s, &end);
        if (end == s || !isfinite(xyz[i]) || *end != (i < 2 ? ',' : 0)) return 0;
        s = end + 1;
    }
    return 1;
}

static int value_count(opt_kind k) { return k == K_HELP || k == K_SET ? 0 : k == K_LONG2 ? 2 : 1; }

/* Stores the value(s) v of option s into *o; 0 when they are not what s needs. */
static int store_value(const opt_spec *s, char **v, cli_opts *o) {
    char *p = (char *)o + s->offset;
    long l;
    double d;
    sfb_scheme scheme;
    const opt_choice *c;
    switch (s->kind) {
    case K_HELP: return 1;
    case K_SET: *(int *)p = s->value; return 1;
    case K_STRING: *(const char **)p = v[0]; return 1;
    case K_INT:
        if (!parse_long(v[0], (long)s->lo, (long)s->hi, &l)) return 0;
        *(int *)p = (int)l;
        return 1;
    case K_LONG: return parse_long(v[0], (long)s->lo, (long)s->hi, (long *)p);
    case K_LONG2: return parse_long(v[0], (long)s->lo, (long)s->hi, (long *)p) && parse_long(v[1], (long)s->lo, (long)s->hi, (long *)p + 1);
    case K_DOUBLE: return parse_number(v[0], (double *)p);
    case K_POSITIVE:
        if (!parse_number(v[0], &d) || !(d > 0.0) || !(d <= s->hi)) return 0;
        *(double *)p = d;
        return 1;
    case K_CHOICE:
        for (c = s->choices; c->name; ++c)
            if (strcmp(v[0], c->name) == 0) { *(int *)p = c->value; return 1; }
        return 0;
    case K_SCHEME:
        if (!cli_scheme_from_name(v[0], &scheme) || (s->value >> scheme & 1)) return 0;
        *(int *)p = (int)scheme;
        return 1;
    case K_LEVEL:
        if (!parse_long(v[0], (long)s->lo, (long)s->hi, &l)) return 0;
        *(int *)p = l == 0 ? SFB_SHADE_LEVEL_CONTROL : (int)l;
        return 1;
    case K_SIZE: return parse_size(v[0], (long *)p);
    case K_VIEW: return parse_view(v[0], (double *)p);
    case K_VEC3: return parse_vec3(v[0], (double *)p);
    }
    return 0;
}

static const opt_spec *find_option(const cli_command *c, const char *arg) {
    size_t i;
    for (i = 0; i < OPTION_COUNT; ++i)
        if ((options[i].cmds & c->bit) && (strcmp(arg, options[i].name) == 0 || (options[i].alias && strcmp(arg, options[i].alias) == 0)))
            return &options[i];
    return NULL;
}

/* The name (or alias) that two rows of one command share, or NULL: a table that the parser
 * cannot read unambiguously (checked at every start; a test runs the tool). */
static const char *option_clash(void) {
    size_t i, j;
    for (i = 0; i < OPTION_COUNT; ++i)
        for (j = i + 1; j < OPTION_COUNT; ++j) {
            const opt_spec *a = &options[i], *b = &options[j];
            if (!(a->cmds & b->cmds)) continue;
            if (strcmp(a->name, b->name) == 0 || (b->alias && strcmp(a->name, b->alias) == 0)) return a->name;
            if (a->alias && (strcmp(a->alias, b->name) == 0 || (b->alias && strcmp(a->alias, b->alias) == 0))) return a->alias;
        }
    return NULL;
}

/* Every command's defaults. */
static void opts_init(cli_opts *o, const cli_command *c) {
    memset(o, 0, sizeof *o);
    o->cmd = c;
    o->scheme = SFB_SCHEME_CATMARK;
    o->weights = SFB_MANIFOLD_WEIGHTS_HERMITE;
    o->level = c->bit & C_SHADING ? 3 : 2;
    o->nrandom = -1;
    o->seed = 1;
    o->rate = c->bit & C_TESS ? -1 : 16;
    o->p = 1.0;
    o->normals = 2; /* blended */
    o->limit_pos = 1;
    o->mode = SFB_RENDER_SHADED;
    o->size[0] = 640;
    o->size[1] = 480;
    if (c->bit & C_ANALYZE) o->level = 0; /* chosen from the view (sfb_analyze_config.level) */
}

/* Reads command c's arguments into *o. Returns 0; 2 after a usage error (printed); -1 after
 * --help (the usage printed on stdout). */
static int parse_args(const cli_command *c, int argc, char **argv, cli_opts *o) {
    char msg[160];
    int i;
    opts_init(o, c);
    for (i = 0; i < argc; ++i) {
        const char *a = argv[i];
        const opt_spec *s;
        int n;
        if (a[0] != '-' || !a[1]) { /* an input file ("-": standard input) */
            if (o->in || !c->inputs) {
                snprintf(msg, sizeof msg, c->inputs ? "%s takes one input file" : "%s takes no arguments", c->name);
                return usage_error(c, msg);
            }
            o->in = a;
            continue;
        }
        s = find_option(c, a);
        if (!s) {
            snprintf(msg, sizeof msg, "unknown option '%s'", a);
            return usage_error(c, msg);
        }
        n = value_count(s->kind);
        if (i + n >= argc || !store_value(s, argv + i + 1, o)) {
            char list[96];
            if (!s->needs) choice_list(s, list, sizeof list, ", ", " or ");
            snprintf(msg, sizeof msg, "%s needs %s", a, s->needs ? s->needs : list);
            return usage_error(c, msg);
        }
        o->seen[s->id]++;
        i += n;
        if (s->kind == K_HELP) {
            print_command_usage(stdout, c);
            return -1;
        }
    }
    if (c->inputs && !o->in) {
        snprintf(msg, sizeof msg, "%s needs an input OBJ file", c->name);
        return usage_error(c, msg);
    }
    if (c->output && !o->outp) {
        snprintf(msg, sizeof msg, "%s needs -o %s", c->name, c->output);
        return usage_error(c, msg);
    }
    return 0;
}
/* ---- eval and tess: the limit surface through the patch table ---- */

/* A surface with its patch table (limit evaluation, tessellation). */
/* (o: the manifold weights and the tribezier sharpness) */
static sfb_surface *make_patch_surface(sfb_context *ctx, const sfb_mesh *mesh, const char *path, sfb_scheme scheme, const cli_opts *o) {
    sfb_surface_config cfg = sfb_surface_config_init(scheme, 0);
    sfb_surface *surf = NULL;
    sfb_result r;
    cfg.flags = SFB_REFINE_PATCHES;
    cfg.manifold.weights = o->weights;
    if (o->seen[O_SHARPNESS]) {
        cfg.tribezier.sharpness_set = 1;
        cfg.tribezier.sharpness = (float)o->sharpness;
    }
    r = sfb_surface_create(ctx, mesh, &cfg, &surf);
    if (r != SFB_SUCCESS) {
        cli_error("%s: %s: %s", path, sfb_result_string(r), sfb_last_error(ctx));
        return NULL;
    }
    return surf;
}

/* Growable list of locations with the file line each came from (0: generated). */
typedef struct loc_list {
    sfb_location *loc;
    long *line;
    int count, cap;
} loc_list;

static int loc_push(loc_list *L, int face, float u, float v, long line) {
    if (L->count == L->cap) {
        int nc = L->cap ? L->cap * 2 : 256;
        sfb_location *nl;
        long *nn;
        if (L->cap > (1 << 26)) return 0;
        nl = (sfb_location *)realloc(L->loc, (size_t)nc * sizeof *nl);
        if (!nl) return 0;
        L->loc = nl;
        nn = (long *)realloc(L->line, (size_t)nc * sizeof *nn);
        if (!nn) return 0;
        L->line = nn;
        L->cap = nc;
    }
    L->loc[L->count].face = face;
    L->loc[L->count].u = u;
    L->loc[L->count].v = v;
    L->line[L->count] = line;
    L->count++;
    return 1;
}

/* Lines "face u v"; blank lines and '#' comments are skipped. Range checks are the library's
 * (sfb_surface_eval names the bad query; the caller maps it back to its line). */
static int read_locations(const char *path, loc_list *L) {
    size_t size = 0, i = 0;
    char *text = cli_read_file(path, &size);
    long line = 0;
    if (!text) {
        cli_error("cannot read '%s'", path);
        return 0;
    }
    while (i < size) {
        char buf[256], *p, *end;
        size_t n = 0;
        long face;
        double u, v;
        ++line;
        while (i < size && text[i] != '\n') {
            if (n + 1 < sizeof buf) buf[n++] = text[i];
            ++i;
        }
        ++i;
        buf[n] = 0;
        if (n + 1 >= sizeof buf) {
            cli_error("%s: line %ld: line too long", path, line);
            free(text);
            return 0;
        }
        if ((p = strchr(buf, '#')) != NULL) *p = 0;
        for (p = buf; *p == ' ' || *p == '\t' || *p == '\r'; ++p) {}
        if (!*p) continue;
        face = strtol(p, &end, 10);
        if (end == p || face < -2147483647L || face > 2147483647L) goto bad;
        p = end;
        u = strtod(p, &end);
        if (end == p) goto bad;
        p = end;
        v = strtod(p, &end);
        if (end == p) goto bad;
        for (p = end; *p == ' ' || *p == '\t' || *p == '\r'; ++p) {}
        if (*p) goto bad;
        if (!loc_push(L, (int)face, (float)u, (float)v, line)) {
            cli_error("%s: too many locations", path);
            free(text);
            return 0;
        }
        continue;
    bad:
        cli_error("%s: line %ld: expected 'face u v' (an integer and two numbers)", path, line);
        free(text);
        return 0;
    }
    free(text);
    return 1;
}

/* A small deterministic generator (splitmix64): the same seed gives the same locations on
 * every platform. */
static unsigned long long next_random(unsigned long long *state) {
    unsigned long long z = (*state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

/* N random locations on parametric faces that are not holes. Holes are found by asking the
 * library (a face whose centre it rejects), which also covers faces that boundary mode
 * 'none' turns into holes. */
static int random_locations(sfb_context *ctx, const sfb_surface *surf, long count, unsigned long long seed, loc_list *L) {
    int np = sfb_surface_param_face_count(surf), nlive = 0, i, triangles;
    sfb_patch_info pi;
    int *live = (int *)malloc(((size_t)np + 1) * sizeof(int));
    sfb_location *probe = (sfb_location *)malloc(((size_t)np + 1) * sizeof(sfb_location));
    float *pos = (float *)malloc(((size_t)np + 1) * 3 * sizeof(float));
    int ok = 0;
    if (!live || !probe || !pos) goto done;
    if (sfb_surface_patch_info(surf, &pi) != SFB_SUCCESS) {
        cli_error("%s", sfb_last_error(ctx));
        goto done;
    }
    triangles = pi.domain_sides == 3; /* sample u + v <= 1 */
    for (i = 0; i < np; ++i) live[nlive++] = i;
    for (;;) {
        sfb_eval_output eo;
        sfb_result r;
        memset(&eo, 0, sizeof eo);
        eo.position = pos;
        for (i = 0; i < nlive; ++i) { probe[i].face = live[i]; probe[i].u = probe[i].v = 0.5f; }
        r = sfb_surface_eval(surf, probe, nlive, &eo);
        if (r == SFB_SUCCESS) break;
        if (r != SFB_INVALID_VALUE || sfb_last_error_info(ctx).index < 0 || sfb_last_error_info(ctx).index >= nlive) {
            cli_error("%s: %s", sfb_result_string(r), sfb_last_error(ctx));
            goto done;
        }
        i = (int)sfb_last_error_info(ctx).index;
        memmove(live + i, live + i + 1, (size_t)(nlive - i - 1) * sizeof(int));
        --nlive;
    }
    sfb_clear_error(ctx);
    if (nlive == 0 && count > 0) {
        cli_error("the surface has no parametric face to sample (every face is a hole)");
        goto done;
    }
    for (i = 0; i < count; ++i) {
        unsigned long long a = next_random(&seed), b = next_random(&seed), c = next_random(&seed);
        /* 24 random bits each: exactly representable floats in [0,1] */
        float u = (float)(b >> 40) / 16777215.0f, v = (float)(c >> 40) / 16777215.0f;
        if (triangles && (double)u + (double)v > 1.0) {
            /* the other half of the square, turned into the triangle u + v <= 1 */
            u = 1.0f - u;
            v = 1.0f - v;
            while ((double)u + (double)v > 1.0) v = nextafterf(v, 0.0f);
        }
        if (!loc_push(L, live[a % (unsigned long long)nlive], u, v, 0)) { cli_error("out of memory"); goto done; }
    }
    ok = 1;
done:
    free(live);
    free(probe);
    free(pos);
    return ok;
}

static int cmp_u64(const void *a, const void *b) {
    unsigned long long x = *(const unsigned long long *)a, y = *(const unsigned long long *)b;
    return x < y ? -1 : x > y;
}

/* Undirected edges of a triangle list by use: once (boundary), twice (closed), more. */
static int edge_counts(const sfb_tess_data *t, long *total, long *closed, long *boundary, long *more) {
    size_t n = (size_t)t->triangle_count * 3, i = 0;
    unsigned long long *k = (unsigned long long *)malloc((n + 1) * sizeof *k);
    int c;
    *total = *closed = *boundary = *more = 0;
    if (!k) return 0;
    for (i = 0; i < (size_t)t->triangle_count; ++i)
        for (c = 0; c < 3; ++c) {
            unsigned long long a = (unsigned)t->triangles[3 * i + c], b = (unsigned)t->triangles[3 * i + (c + 1) % 3];
            k[3 * i + c] = a < b ? (a << 32 | b) : (b << 32 | a);
        }
    qsort(k, n, sizeof *k, cmp_u64);
    for (i = 0; i < n;) {
        size_t j = i;
        while (j < n && k[j] == k[i]) ++j;
        ++*total;
        if (j - i == 1) ++*boundary;
        else if (j - i == 2) ++*closed;
        else ++*more;
        i = j;
    }
    free(k);
    return 1;
}

/* The trimming mask of --trim (with --trim-tiles) into *mask; 1, or 0 with a message printed.
 * *texels is what to free (free). */
static int load_trim(const cli_opts *o, sfb_trim_mask *mask, unsigned char **texels) {
    memset(mask, 0, sizeof *mask);
    *texels = NULL;
    if (!o->trim) return 1;
    if (!cli_load_mask(o->trim, texels, &mask->width, &mask->height)) return 0;
    mask->texels = *texels;
    mask->tiles_u = (int)o->tiles[0];
    mask->tiles_v = (int)o->tiles[1];
    return 1;
}

/* ---- the commands ---- */

static int cmd_info(cli_opts *o) {
    sfb_context *ctx;
    sfb_mesh *mesh;
    sfb_mesh_info in;
    int hist[33], over, i, problems = 0;
    ctx = cli_make_context(NULL);
    if (!ctx) return 1;
    mesh = cli_load_mesh(ctx, o->in, o->seen[O_CREASE_ANGLE] ? o->crease_angle : -1.0, o->triangulate);
    if (!mesh) { sfb_context_destroy(ctx); return 1; }
    sfb_mesh_get_info(mesh, &in);
    printf("file:        %s\n", o->in);
    printf("vertices:    %d\nfaces:       %d (%d triangles, %d quads, %d n-gons, largest %d)\n", in.vertex_count, in.face_count,
           in.triangles, in.quads, in.ngons, in.max_face_size);
    printf("edges:       %d (%d boundary)\nuvs:         %d\n", in.edge_count, in.boundary_edges, in.uv_count);
    printf("creases:     %d sharp edges (%d semi-sharp, %d infinitely sharp), %d corner vertices tagged, %d holes\n",
           in.sharp_edges, in.semisharp_edges, in.infsharp_edges, in.corners, in.holes);
    printf("rules:       %d darts, %d crease vertices, %d corner vertices\n", in.darts, in.crease_vertices, in.corner_vertices);
    printf("extraordinary vertices: %d for Catmull-Clark, %d for Loop\n", in.extraordinary_catmark, in.extraordinary_loop);
    printf("bbox:        (%g %g %g) - (%g %g %g)\n", in.bbox_min[0], in.bbox_min[1], in.bbox_min[2], in.bbox_max[0],
           in.bbox_max[1], in.bbox_max[2]);
    over = sfb_mesh_valence_histogram(mesh, hist, 33);
    printf("valence histogram (edges per vertex):");
    for (i = 0; i < 33; ++i)
        if (hist[i]) printf(" %d:%d", i, hist[i]);
    if (over) printf(" >32:%d", over);
    printf("\nmax valence: %d\n", in.max_valence);
    printf("problems:   ");
    if (in.nonmanifold_edges) { printf(" %d non-manifold edges;", in.nonmanifold_edges); problems++; }
    if (in.nonmanifold_vertices) { printf(" %d non-manifold vertices (treated as corners);", in.nonmanifold_vertices); problems++; }
    if (in.bare_vertices) { printf(" %d vertices in no face;", in.bare_vertices); problems++; }
    if ((in.triangles > 0 && in.quads + in.ngons > 0) || (in.quads > 0 && in.ngons > 0)) {
        printf(" mixed face sizes: %d of %d faces are not triangles (loop, tribezier and pn take triangles only: --triangulate);",
               in.quads + in.ngons, in.triangles + in.quads + in.ngons);
        problems++;
    }
    if (!problems) printf(" none");
    printf("\n");
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return 0;
}

static int cmd_refine(cli_opts *o) {
    sfb_scheme scheme = cli_scheme_for(o->in, o->seen[O_SCHEME], (sfb_scheme)o->scheme);
    int i, rc = 1;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_surface_config cfg;
    sfb_mesh_data data;
    sfb_mesh_desc d;
    sfb_result r;
    cli_output out;
    memset(&data, 0, sizeof data);
    memset(&out, 0, sizeof out);
    ctx = cli_make_context(o->backend);
    if (!ctx) return 1;
    mesh = cli_load_mesh(ctx, o->in, o->seen[O_CREASE_ANGLE] ? o->crease_angle : -1.0, o->triangulate);
    if (!mesh) goto done;
    cfg = sfb_surface_config_init(scheme, o->level);
    cfg.flags = SFB_REFINE_UVS | (o->limit ? SFB_REFINE_LIMIT : 0u);
    r = sfb_surface_create(ctx, mesh, &cfg, &surf);
    if (r == SFB_SUCCESS) r = sfb_surface_refine(surf, &data);
    if (r != SFB_SUCCESS) {
        cli_error("%s: %s: %s", o->in, sfb_result_string(r), sfb_last_error(ctx));
        goto done;
    }
    if (!cli_output_open(&out, o->outp)) goto done;
    sfb_mesh_data_desc(&data, &d);
    if (o->limit) {
        d.positions = data.limit_positions;
        for (i = 0; i < data.vertex_count; ++i)
            fprintf(out.f, "vn %.7g %.7g %.7g\n", data.normals[3 * i], data.normals[3 * i + 1], data.normals[3 * i + 2]);
    }
    r = sfb_write_obj(&d, cli_file_write, out.f);
    if (r != SFB_SUCCESS) {
        cli_error("writing '%s' failed: %s", o->outp, sfb_result_string(r));
        goto done;
    }
    cli_error("%s level %d: %d vertices, %d faces -> %s (backend %s)", sfb_scheme_name(scheme), o->level, data.vertex_count,
              data.face_count, o->outp, sfb_context_backend_name(ctx));
    rc = 0;
done:
    rc = cli_output_finish(&out, rc);
    sfb_mesh_data_free(&data);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return rc;
}

/* eval's locations: from --locations, or --random on the faces that are not holes. */
static int eval_locations(sfb_context *ctx, const sfb_surface *surf, const cli_opts *o, loc_list *L) {
    if (o->locfile) return read_locations(o->locfile, L);
    return random_locations(ctx, surf, o->nrandom, (unsigned long long)o->seed, L);
}

/* One line per location: face u v, position, normal[, du, dv]. */
static void eval_print(FILE *f, const loc_list *L, const sfb_eval_output *eo) {
    int i;
    for (i = 0; i < L->count; ++i) {
        const float *p = eo->position + 3 * (size_t)i, *nn = eo->normal + 3 * (size_t)i;
        fprintf(f, "%d %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g", L->loc[i].face, L->loc[i].u, L->loc[i].v, p[0], p[1], p[2], nn[0],
                nn[1], nn[2]);
        if (eo->du) {
            const float *a = eo->du + 3 * (size_t)i, *b = eo->dv + 3 * (size_t)i;
            fprintf(f, " %.9g %.9g %.9g %.9g %.9g %.9g", a[0], a[1], a[2], b[0], b[1], b[2]);
        }
        fputc('\n', f);
    }
}

static int cmd_eval(cli_opts *o) {
    int rc = 1;
    sfb_scheme scheme = cli_scheme_for(o->in, o->seen[O_SCHEME], (sfb_scheme)o->scheme);
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    loc_list L;
    float *buf = NULL;
    sfb_eval_output eo;
    sfb_result r;
    size_t n;
    cli_output out;
    memset(&L, 0, sizeof L);
    memset(&eo, 0, sizeof eo);
    memset(&out, 0, sizeof out);
    if ((o->nrandom >= 0) == (o->locfile != NULL)) return usage_error(o->cmd, "eval needs either --random N or --locations FILE");
    ctx = cli_make_context(o->backend);
    if (!ctx) return 1;
    mesh = cli_load_mesh(ctx, o->in, o->seen[O_CREASE_ANGLE] ? o->crease_angle : -1.0, o->triangulate);
    if (!mesh) goto done;
    surf = make_patch_surface(ctx, mesh, o->in, scheme, o);
    if (!surf || !eval_locations(ctx, surf, o, &L)) goto done;
    n = (size_t)L.count;
    buf = (float *)malloc((n + 1) * 12 * sizeof(float));
    if (!buf) { cli_error("out of memory"); goto done; }
    eo.position = buf;
    eo.normal = buf + 3 * n;
    if (o->derivatives) { eo.du = buf + 6 * n; eo.dv = buf + 9 * n; }
    r = sfb_surface_eval(surf, L.loc, L.count, &eo);
    if (r != SFB_SUCCESS) {
        sfb_error_info e = sfb_last_error_info(ctx);
        if (o->locfile && e.index >= 0 && e.index < L.count)
            cli_error("%s: line %ld: %s: %s", o->locfile, L.line[e.index], sfb_result_string(r), sfb_last_error(ctx));
        else
            cli_error("%s: %s: %s", o->in, sfb_result_string(r), sfb_last_error(ctx));
        goto done;
    }
    if (!cli_output_open(&out, o->outp)) goto done;
    eval_print(out.f, &L, &eo);
    rc = 0;
done:
    rc = cli_output_finish(&out, rc);
    free(buf);
    free(L.loc);
    free(L.line);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return rc;
}

/* The tessellation as OBJ: v, vn, f v//vn. */
static void tess_print(FILE *f, const cli_opts *o, const sfb_tess_data *td) {
    int i;
    fprintf(f, "# surfblend tess of %s: rate %ld%s%s%s%s, %d vertices, %d triangles\n", o->in, o->rate, o->tolerance > 0.0 ? " adaptive" : "",
            o->split ? " split creases" : "", o->trim ? " trimmed by " : "", o->trim ? o->trim : "", td->vertex_count, td->triangle_count);
    for (i = 0; i < td->vertex_count; ++i)
        fprintf(f, "v %.7g %.7g %.7g\n", td->positions[3 * i], td->positions[3 * i + 1], td->positions[3 * i + 2]);
    for (i = 0; i < td->vertex_count; ++i)
        fprintf(f, "vn %.7g %.7g %.7g\n", td->normals[3 * i], td->normals[3 * i + 1], td->normals[3 * i + 2]);
    for (i = 0; i < td->triangle_count; ++i) {
        int a = td->triangles[3 * i] + 1, b = td->triangles[3 * i + 1] + 1, c = td->triangles[3 * i + 2] + 1;
        fprintf(f, "f %d//%d %d//%d %d//%d\n", a, a, b, b, c, c);
    }
}

/* The summary line on stderr, with the edge counts; 0 when out of memory (printed). */
static int tess_summary(const cli_opts *o, const sfb_tess_data *td, const sfb_trim_mask *mask, sfb_context *ctx) {
    long total, closed, boundary, more;
    char trimmed[64] = "";
    if (!edge_counts(td, &total, &closed, &boundary, &more)) { cli_error("out of memory"); return 0; }
    if (o->trim) snprintf(trimmed, sizeof trimmed, " trimmed (%dx%d mask)", mask->width, mask->height);
    cli_error("tess rate %ld%s%s: %d vertices, %d triangles, %ld edges (%ld closed, %ld boundary%s) -> %s (backend %s)", o->rate,
              o->tolerance > 0.0 ? " adaptive" : "", trimmed, td->vertex_count, td->triangle_count, total, closed, boundary,
              more ? ", some non-manifold" : "", o->outp, sfb_context_backend_name(ctx));
    return 1;
}

static int cmd_tess(cli_opts *o) {
    unsigned char *texels = NULL;
    sfb_trim_mask mask;
    int rc = 1;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_tess_config tc;
    sfb_tess_data td;
    sfb_result r;
    cli_output out;
    memset(&td, 0, sizeof td);
    memset(&out, 0, sizeof out);
    if (!o->seen[O_RATE]) return usage_error(o->cmd, "tess needs --rate N");
    if (o->seen[O_TILES] && !o->trim) return usage_error(o->cmd, "--trim-tiles needs --trim MASK.png");
    if (!load_trim(o, &mask, &texels)) return 1;
    ctx = cli_make_context(o->backend);
    if (!ctx) { free(texels); return 1; }
    mesh = cli_load_mesh(ctx, o->in, o->seen[O_CREASE_ANGLE] ? o->crease_angle : -1.0, o->triangulate);
    if (!mesh) goto done;
    surf = make_patch_surface(ctx, mesh, o->in, cli_scheme_for(o->in, o->seen[O_SCHEME], (sfb_scheme)o->scheme), o);
    if (!surf) goto done;
    tc = sfb_tess_config_init((int)o->rate);
    tc.tolerance = (float)o->tolerance;
    tc.flags = o->split ? (unsigned)SFB_TESS_SPLIT_CREASES : 0u;
    tc.trim = o->trim ? &mask : NULL;
    r = sfb_surface_tessellate(surf, &tc, &td);
    if (r != SFB_SUCCESS) {
        cli_error("%s: %s: %s", o->in, sfb_result_string(r), sfb_last_error(ctx));
        goto done;
    }
    if (!cli_output_open(&out, o->outp)) goto done;
    tess_print(out.f, o, &td);
    if (!tess_summary(o, &td, &mask, ctx)) goto done;
    rc = 0;
done:
    rc = cli_output_finish(&out, rc);
    sfb_tess_data_free(&td);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    free(texels);
    return rc;
}

/* ---- subdivision shading (seed 001) and software pictures ---- */

/* Builds the shading surface of o->in and shades it into *data. Returns 1 on success; on
 * failure prints why and returns 0 (what was made is freed by the caller). */
static int shade_mesh(sfb_context *ctx, const cli_opts *o, sfb_mesh **mesh, sfb_surface **surf, sfb_mesh_data *data) {
    sfb_surface_config cfg;
    sfb_shade_params sp;
    sfb_result r;
    *mesh = cli_load_mesh(ctx, o->in, o->seen[O_CREASE_ANGLE] ? o->crease_angle : -1.0, o->triangulate);
    if (!*mesh) return 0;
    cfg = sfb_surface_config_init(cli_scheme_for(o->in, o->seen[O_SCHEME], (sfb_scheme)o->scheme), o->level);
    cfg.flags = SFB_REFINE_LIMIT | SFB_REFINE_SHADING;
    cfg.shading.variant = (sfb_shade_variant)o->variant;
    cfg.shading.darts = (sfb_shade_darts)o->darts;
    cfg.shading.normals_level = o->normals_level;
    cfg.shading.weights_level = o->weights_level;
    cfg.shading.averaging = (sfb_shade_averaging)o->averaging;
    sp = sfb_shade_params_init();
    sp.p = (float)o->p;
    sp.flags = o->all_subdivided ? (unsigned)SFB_SHADE_ALL_SUBDIVIDED : 0u;
    r = sfb_surface_create(ctx, *mesh, &cfg, surf);
    if (r == SFB_SUCCESS) r = sfb_surface_shade(*surf, &sp, data);
    if (r != SFB_SUCCESS) {
        cli_error("%s: %s: %s", o->in, sfb_result_string(r), sfb_last_error(ctx));
        return 0;
    }
    return 1;
}

/* Output vertices, refined vertices with more than one copy, and the share of output
 * vertices where N_S was computed. */
static void shade_summary(const char *what, const cli_opts *o, const sfb_mesh_data *d, sfb_context *ctx) {
    int split = 0, i;
    int *copies = d->refined_vertex_count > 0 ? (int *)calloc((size_t)d->refined_vertex_count, sizeof(int)) : NULL;
    if (copies && d->vertex_origin) {
        for (i = 0; i < d->vertex_count; ++i) {
            int v = d->vertex_origin[i];
            if (v >= 0 && v < d->refined_vertex_count && ++copies[v] == 2) ++split;
        }
    }
    free(copies);
    cli_error("%s %s level %d: %d output vertices (%d refined, %d split), %d faces; N_S computed at %d vertices (%.1f%%) -> %s (backend %s)",
              what, sfb_scheme_name(cli_scheme_for(o->in, o->seen[O_SCHEME], (sfb_scheme)o->scheme)), o->level, d->vertex_count,
              d->refined_vertex_count, split, d->face_count, d->subdivided_count,
              d->vertex_count > 0 ? 100.0 * d->subdivided_count / d->vertex_count : 0.0, o->outp, sfb_context_backend_name(ctx));
}

/* The shaded mesh as OBJ: a comment with the options, v, vn (N_B), f v//vn. */
static void shade_print(FILE *f, const cli_opts *o, const sfb_mesh_data *data) {
    const float *pos = o->limit ? data->limit_positions : data->positions;
    size_t off = 0;
    int i, j;
    fprintf(f, "# surfblend shade of %s: %s level %d, variant %s, darts %s, averaging %s, p %g; %d vertices (%d refined), %d faces\n",
            o->in, sfb_scheme_name(cli_scheme_for(o->in, o->seen[O_SCHEME], (sfb_scheme)o->scheme)), o->level,
            o->variant == SFB_SHADE_VARIANT_A ? "A" : "B", o->darts == SFB_SHADE_DARTS_SHARP ? "sharp" : "smooth",
            averaging_choices[o->averaging].name, o->p, data->vertex_count, data->refined_vertex_count, data->face_count);
    for (i = 0; i < data->vertex_count; ++i) fprintf(f, "v %.7g %.7g %.7g\n", pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
    for (i = 0; i < data->vertex_count; ++i)
        fprintf(f, "vn %.7g %.7g %.7g\n", data->normals[3 * i], data->normals[3 * i + 1], data->normals[3 * i + 2]);
    for (i = 0; i < data->face_count; ++i) {
        fputc('f', f);
        for (j = 0; j < data->face_sizes[i]; ++j) {
            int v = data->face_vertices[off + (size_t)j] + 1;
            fprintf(f, " %d//%d", v, v);
        }
        fputc('\n', f);
        off += (size_t)data->face_sizes[i];
    }
}

static int cmd_shade(cli_opts *o) {
    int rc = 1;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_mesh_data data;
    cli_output out;
    memset(&data, 0, sizeof data);
    memset(&out, 0, sizeof out);
    ctx = cli_make_context(o->backend);
    if (!ctx) return 1;
    if (!shade_mesh(ctx, o, &mesh, &surf, &data)) goto done;
    if (!data.normals || (o->limit && !data.limit_positions)) {
        cli_error("%s: the shaded mesh lacks %s", o->in, data.normals ? "limit positions" : "normals");
        goto done;
    }
    if (!cli_output_open(&out, o->outp)) goto done;
    shade_print(out.f, o, &data);
    shade_summary("shade", o, &data, ctx);
    rc = 0;
done:
    rc = cli_output_finish(&out, rc);
    sfb_mesh_data_free(&data);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return rc;
}

/* What render makes and frees. */
typedef struct render_state {
    sfb_context *ctx;
    sfb_mesh *mesh;
    sfb_surface *surf;
    sfb_mesh_data data; /* the shaded mesh, or (--scheme manifold) a view of td */
    sfb_tess_data td;
    int *face_sizes;    /* --scheme manifold: data.face_sizes, all 3 */
    unsigned char *texels;
    sfb_trim_mask mask;
    sfb_image img;
} render_state;

/* Whether render draws the scheme's tessellated patches (a scheme without subdivision shading:
 * the manifold blend) rather than its shaded refinement. */
static int render_tessellates(const cli_opts *o) { return !(sfb_scheme_caps((sfb_scheme)o->scheme) & SFB_SCHEME_CAN_SHADE); }

/* The option combinations render refuses: 0, or usage_error()'s status. */
static int render_check(cli_opts *o) {
    int manifold = render_tessellates(o);
    if (o->seen[O_MODE] > 1) return usage_error(o->cmd, "render takes one of --highlight, --blend-weights, --normal-colors");
    if (!manifold && (o->seen[O_RATE] || o->trim))
        return usage_error(o->cmd, "--rate and --trim belong to the tessellated schemes, manifold, tribezier and pn (the subdivision schemes "
                                   "render their shaded refinement)");
    if (o->seen[O_TILES] && !o->trim) return usage_error(o->cmd, "--trim-tiles needs --trim MASK.png");
    if (manifold && o->mode == SFB_RENDER_WEIGHTS)
        return usage_error(o->cmd, "--blend-weights pictures belong to subdivision shading (the manifold blend's are --manifold-weights)");
    if (o->normals == 1) o->all_subdivided = 1;
    return 0;
}

/* --scheme manifold: the blending surface, tessellated (and trimmed), as the triangles of
 * s->data with their normals. 1, or 0 with the reason printed. */
static int render_manifold_mesh(const cli_opts *o, render_state *s) {
    sfb_tess_config tc = sfb_tess_config_init((int)(o->rate > 2147483647L ? 2147483647L : o->rate < -2147483647L ? -2147483647L : o->rate));
    sfb_result r;
    int i;
    s->mesh = cli_load_mesh(s->ctx, o->in, o->seen[O_CREASE_ANGLE] ? o->crease_angle : -1.0, o->triangulate);
    if (!s->mesh) return 0;
    s->surf = make_patch_surface(s->ctx, s->mesh, o->in, (sfb_scheme)o->scheme, o);
    if (!s->surf) return 0;
    tc.trim = o->trim ? &s->mask : NULL;
    r = sfb_surface_tessellate(s->surf, &tc, &s->td);
    if (r != SFB_SUCCESS) {
        cli_error("%s: %s: %s", o->in, sfb_result_string(r), sfb_last_error(s->ctx));
        return 0;
    }
    s->face_sizes = (int *)malloc(sizeof(int) * ((size_t)s->td.triangle_count + 1));
    if (!s->face_sizes) { cli_error("out of memory"); return 0; }
    for (i = 0; i < s->td.triangle_count; ++i) s->face_sizes[i] = 3;
    s->data.vertex_count = s->td.vertex_count;
    s->data.face_count = s->td.triangle_count;
    s->data.face_vertex_count = 3 * s->td.triangle_count;
    s->data.positions = s->data.limit_positions = s->td.positions;
    s->data.normals = s->data.limit_normals = s->data.subdivided_normals = s->td.normals;
    s->data.face_vertices = s->td.triangles;
    s->data.face_sizes = s->face_sizes;
    return 1;
}

/* Draws s->data into s->img as the options say. 1, or 0 with the reason printed. */
static int render_draw(const cli_opts *o, render_state *s) {
    sfb_render_config rcfg = sfb_render_config_init((sfb_render_mode)o->mode);
    const sfb_mesh_data *d = &s->data;
    sfb_result r;
    rcfg.width = (int)(o->size[0] > 2147483647L ? 2147483647L : o->size[0]);
    rcfg.height = (int)(o->size[1] > 2147483647L ? 2147483647L : o->size[1]);
    rcfg.positions = o->limit_pos ? d->limit_positions : d->positions;
    rcfg.normals = o->normals == 0 ? d->limit_normals : o->normals == 1 ? d->subdivided_normals : d->normals;
    rcfg.scalars = d->blend_weights;
    rcfg.view_set = o->seen[O_VIEW] > 0;
    rcfg.yaw = (float)o->view[0];
    rcfg.pitch = (float)o->view[1];
    if (o->seen[O_UP]) { rcfg.up[0] = (float)o->up[0]; rcfg.up[1] = (float)o->up[1]; rcfg.up[2] = (float)o->up[2]; }
    rcfg.zoom = (float)o->zoom;
    rcfg.stripes = (float)o->stripes;
    rcfg.draw_edges = o->edges;
    if (!rcfg.positions || (o->mode != SFB_RENDER_WEIGHTS && !rcfg.normals) || (o->mode == SFB_RENDER_WEIGHTS && !rcfg.scalars)) {
        cli_error("%s: the shaded mesh lacks the %s", o->in,
                  !rcfg.positions ? "positions" : o->mode == SFB_RENDER_WEIGHTS ? "blend weights" : "normals");
        return 0;
    }
    r = sfb_render(s->ctx, d, &rcfg, &s->img);
    if (r != SFB_SUCCESS) {
        cli_error("%s: %s: %s", o->in, sfb_result_string(r), sfb_last_error(s->ctx));
        return 0;
    }
    return 1;
}

static void png_to_file(void *user, void *data, int size) {
    if (size > 0) fwrite(data, 1, (size_t)size, (FILE *)user);
}

static void render_summary(const cli_opts *o, const render_state *s) {
    static const char *mode_names[4] = { "shading", "highlight lines", "blend weights", "normal colours" };
    char what[256], field[64] = "";
    int manifold = render_tessellates(o);
    if (o->mode != SFB_RENDER_WEIGHTS && !manifold) snprintf(field, sizeof field, " of the %s normals", normal_names[o->normals]);
    snprintf(what, sizeof what, "render %s%s, %dx%d (%d object pixels%s):", mode_names[o->mode], field, s->img.width, s->img.height,
             s->img.object_pixels, s->img.skipped_faces ? ", faces with non-finite positions skipped" : "");
    if (manifold && o->scheme == SFB_SCHEME_MANIFOLD_BLEND)
        cli_error("%s manifold blend (%s weights) tessellated at rate %ld%s: %d triangles -> %s (backend %s)", what,
                  o->weights ? "C-infinity" : "Hermite", o->rate, o->trim ? ", trimmed" : "", s->td.triangle_count, o->outp,
                  sfb_context_backend_name(s->ctx));
    else if (manifold)
        cli_error("%s %s surface tessellated at rate %ld%s: %d triangles -> %s (backend %s)", what, sfb_scheme_name((sfb_scheme)o->scheme),
                  o->rate, o->trim ? ", trimmed" : "", s->td.triangle_count, o->outp, sfb_context_backend_name(s->ctx));
    else shade_summary(what, o, &s->data, s->ctx);
}

static int cmd_render(cli_opts *o) {
    render_state s;
    int rc = render_check(o);
    cli_output out;
    if (rc) return rc;
    rc = 1;
    memset(&s, 0, sizeof s);
    memset(&out, 0, sizeof out);
    if (!load_trim(o, &s.mask, &s.texels)) return 1;
    s.ctx = cli_make_context(o->backend);
    if (!s.ctx) goto done;
    if (render_tessellates(o) ? !render_manifold_mesh(o, &s) : !shade_mesh(s.ctx, o, &s.mesh, &s.surf, &s.data)) goto done;
    if (!render_draw(o, &s) || !cli_output_open(&out, o->outp)) goto done;
    if (!stbi_write_png_to_func(png_to_file, out.f, s.img.width, s.img.height, 4, s.img.rgba, s.img.width * 4)) {
        cli_error("encoding the PNG failed (out of memory)");
        goto done;
    }
    render_summary(o, &s);
    rc = 0;
done:
    rc = cli_output_finish(&out, rc);
    sfb_image_free(&s.img);
    if (s.face_sizes) { free(s.face_sizes); memset(&s.data, 0, sizeof s.data); }
    sfb_tess_data_free(&s.td);
    free(s.texels);
    sfb_mesh_data_free(&s.data);
    sfb_surface_destroy(s.surf);
    sfb_mesh_destroy(s.mesh);
    sfb_context_destroy(s.ctx);
    return rc;
}

/* ---- analyze: seed 003's exact per-pixel surface analysis ---- */
static int analyze_light(const cli_opts *o, sfb_analyze_config *ac, unsigned char **texels) {
    static const char *const names[3] = { "stripes", "lattice", "circles" };
    int i, w = 0, h = 0;
    if (!o->light) return 1;
    for (i = 0; i < 3; ++i)
        if (strcmp(o->light, names[i]) == 0) { ac->light_pattern = i; return 1; }
    if (!cli_load_rgba(o->light, texels, &w, &h)) return 0;
    ac->light_pattern = SFB_LIGHT_IMAGE;
    ac->light_rgba = *texels;
    ac->light_width = w;
    ac->light_height = h;
    return 1;
}

static int cmd_analyze(cli_opts *o) {
    static const char *const mode_names[] = { "reflection lines", "highlight lines", "zebra", "isophotes", "curvature", "normals", "shading" };
    static const char *const curv_names[] = { "Gaussian", "mean", "max |k|" };
    int rc = 1, i;
    sfb_scheme scheme = cli_scheme_for(o->in, o->seen[O_SCHEME], (sfb_scheme)o->scheme);
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_analyze_config ac = sfb_analyze_config_init(o->amode);
    sfb_analysis an;
    unsigned char *texels = NULL;
    sfb_result r;
    cli_output out;
    memset(&an, 0, sizeof an);
    memset(&out, 0, sizeof out);
    if (o->seen[O_EYE] != o->seen[O_TARGET]) return usage_error(o->cmd, "--eye and --target go together");
    if (o->seen[O_EYE] && (o->seen[O_VIEW] || o->seen[O_ZOOM])) return usage_error(o->cmd, "--eye/--target replace --view and --zoom");
    if (o->seen[O_CURVATURE] && o->amode != SFB_ANALYZE_CURVATURE) return usage_error(o->cmd, "--curvature belongs to --mode curvature");
    if (o->seen[O_LIGHT] && o->amode != SFB_ANALYZE_REFLECTION && o->amode != SFB_ANALYZE_HIGHLIGHT)
        return usage_error(o->cmd, "--light belongs to --mode reflection and highlight");
    if (!analyze_light(o, &ac, &texels)) return 1;
    ac.width = (int)o->size[0];
    ac.height = (int)o->size[1];
    ac.level = o->level;
    ac.polygon_based = o->polygon;
    ac.curvature = o->curvature;
    ac.stripes = (float)o->stripes;
    ac.stripe_width = (float)o->band;
    ac.orthographic = o->ortho;
    ac.fov = (float)o->fov;
    if (o->seen[O_VIEW]) { ac.view_set = 1; ac.yaw = (float)o->view[0]; ac.pitch = (float)o->view[1]; }
    ac.zoom = (float)o->zoom;
    if (o->seen[O_EYE]) {
        ac.camera_set = 1;
        for (i = 0; i < 3; ++i) {
            ac.eye[i] = (float)o->eye[i];
            ac.target[i] = (float)o->target[i];
            ac.up[i] = o->seen[O_UP] ? (float)o->up[i] : (i == 1 ? 1.0f : 0.0f);
        }
    } else if (o->seen[O_UP]) {
        for (i = 0; i < 3; ++i) ac.up[i] = (float)o->up[i]; /* the orbit (--view) turns about it */
    }
    ctx = cli_make_context(o->backend);
    if (!ctx) goto done;
    mesh = cli_load_mesh(ctx, o->in, o->seen[O_CREASE_ANGLE] ? o->crease_angle : -1.0, o->triangulate);
    if (!mesh) goto done;
    surf = make_patch_surface(ctx, mesh, o->in, scheme, o);
    if (!surf) goto done;
    r = sfb_surface_analyze(surf, &ac, &an);
    if (r != SFB_SUCCESS) {
        cli_error("%s: %s: %s", o->in, sfb_result_string(r), sfb_last_error(ctx));
        goto done;
    }
    if (!cli_output_open(&out, o->outp)) goto done;
    if (!stbi_write_png_to_func(png_to_file, out.f, an.width, an.height, 4, an.rgba, an.width * 4)) {
        cli_error("encoding the PNG failed (out of memory)");
        goto done;
    }
    cli_error("analyze %s%s%s of the %s surface (%s, level-%d proxy), %dx%d: %d surface pixels (proxy %d, %d grown to the exact "
              "silhouette, %d dropped, %d on the proxy's point)%s -> %s (backend %s)",
              o->amode == SFB_ANALYZE_CURVATURE ? curv_names[o->curvature] : "", o->amode == SFB_ANALYZE_CURVATURE ? " " : "",
              mode_names[o->amode], sfb_scheme_name(scheme), o->polygon ? "polygon-based" : "exact per pixel", an.proxy_level, an.width, an.height,
              an.covered_pixels, an.proxy_pixels, an.grown_pixels, an.dropped_pixels, an.fallback_pixels, "", o->outp,
              sfb_context_backend_name(ctx));
    if (o->amode == SFB_ANALYZE_CURVATURE)
        cli_error("  curvature %g .. %g, colour map range +-%g", (double)an.value_min, (double)an.value_max, (double)an.range);
    if (o->amode == SFB_ANALYZE_REFLECTION || o->amode == SFB_ANALYZE_HIGHLIGHT)
        cli_error("  %d of %d rays meet the light plane", an.light_hits, an.covered_pixels);
    rc = 0;
done:
    rc = cli_output_finish(&out, rc);
    sfb_analysis_free(&an);
    free(texels);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return rc;
}

/* Probes every backend on its own: available with what it runs on, or why not. */
static int cmd_backends(cli_opts *o) {
    int k;
    const char *env = getenv("SURFBLEND_BACKEND");
    (void)o;
    printf("default order: simd, ref%s%s%s\n", env && *env ? "  (SURFBLEND_BACKEND=" : "", env && *env ? env : "",
           env && *env ? " forces one)" : "");
    for (k = SFB_BACKEND_REF; k < SFB_BACKEND_KIND_COUNT_; ++k) {
        char info[512];
        sfb_backend_kind kind = (sfb_backend_kind)k;
        sfb_result r = sfb_backend_probe(kind, NULL, info, sizeof info);
        if (r == SFB_SUCCESS)
            printf("%-7s available     %s\n", sfb_backend_kind_name(kind), info[0] ? info : "plain C, double accumulation (the oracle)");
        else
            printf("%-7s unavailable   %s (%s)\n", sfb_backend_kind_name(kind), info, sfb_result_string(r));
    }
    return 0;
}

/* ---- fillet: seed 002's rolling-ball blending on a triangle mesh ---- */
/* --profile: arc | conic:W | sharpen | hermite[:S]; 0 on a bad value (printed). */
static int fillet_profile(const char *s, sfb_fillet_config *fc) {
    char *end;
    if (!s || strcmp(s, "arc") == 0) { fc->profile = SFB_FILLET_ARC; return 1; }
    if (strcmp(s, "sharpen") == 0) { fc->profile = SFB_FILLET_SHARPEN; return 1; }
    if (strcmp(s, "hermite") == 0) { fc->profile = SFB_FILLET_HERMITE; return 1; }
    if (strncmp(s, "conic:", 6) == 0 || strncmp(s, "hermite:", 8) == 0) {
        const int conic = s[0] == 'c';
        const double w = strtod(s + (conic ? 6 : 8), &end);
        if (end != s + (conic ? 6 : 8) && !*end && w > 0.0 && w < (conic ? 1e6 : 10.000001)) {
            fc->profile = conic ? SFB_FILLET_CONIC : SFB_FILLET_HERMITE;
            if (conic) fc->conic_weight = (float)w; else fc->hermite_scale = (float)w;
            return 1;
        }
    }
    cli_error("--profile: '%s' is not arc, conic:W, sharpen or hermite[:S] (W a number > 0, S in (0, 10])", s);
    return 0;
}

/* --curve "a,b,c;d,e,f": the curves and their vertices (malloc'd); 0 on a bad list (printed). */
static int fillet_curves(const char *s, sfb_fillet_curve **curves, int *count, int **verts) {
    size_t n = strlen(s) + 2, k = 0;
    int nc = 0, start = 0, i;
    const char *p = s;
    *curves = NULL;
    *count = 0;
    *verts = (int *)malloc(n * sizeof(int));
    if (!*verts) return 0;
    for (;;) {
        char *end;
        long v = strtol(p, &end, 10);
        if (end == p || v < 0 || v > 2147483646L) {
            cli_error("--curve: '%s' is not a list of vertex indices (e.g. 0,1,2;5,6)", s);
            return 0;
        }
        (*verts)[k++] = (int)v;
        p = end;
        if (*p == ',') { ++p; continue; }
        if (*p == ';' || !*p) {
            sfb_fillet_curve *nc_ = (sfb_fillet_curve *)realloc(*curves, (size_t)(nc + 1) * sizeof **curves);
            if (!nc_) return 0;
            *curves = nc_;
            memset(&(*curves)[nc], 0, sizeof **curves);
            (*curves)[nc].count = (int)k - start;
            nc++;
            start = (int)k;
            if (!*p) break;
            ++p;
            continue;
        }
        cli_error("--curve: unexpected '%c' in '%s'", *p, s);
        return 0;
    }
    for (i = 0, k = 0; i < nc; ++i) { (*curves)[i].vertices = *verts + k; k += (size_t)(*curves)[i].count; }
    *count = nc;
    return 1;
}

static int cmd_fillet(cli_opts *o) {
    int rc = 1, i, *verts = NULL, ncurves = 0;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL, *res = NULL;
    sfb_fillet_config fc;
    sfb_fillet_curve *curves = NULL;
    sfb_fillet_report rep;
    sfb_result r;
    cli_output out;
    memset(&out, 0, sizeof out);
    memset(&rep, 0, sizeof rep);
    if (!o->seen[O_RADIUS]) return usage_error(o->cmd, "fillet needs --radius R");
    fc = sfb_fillet_config_init((float)o->radius);
    if (o->seen[O_ANGLE]) fc.angle = (float)o->angle;
    if (o->seen[O_SAMPLES]) fc.samples = (int)o->samples;
    fc.skip_failed = o->skip_failed;
    if (o->seen[O_RELAX]) fc.relax = (int)o->relax;
    if (o->seen[O_ALPHA]) {
        if (o->alpha < 1.0) return usage_error(o->cmd, "--alpha needs a number in [1, 100]");
        fc.alpha = (float)o->alpha;
    }
    if (!fillet_profile(o->profile, &fc)) return 2;
    if (o->curve && !fillet_curves(o->curve, &curves, &ncurves, &verts)) { free(curves); free(verts); return 2; }
    fc.curves = curves;
    fc.curve_count = ncurves;
    ctx = cli_make_context(NULL);
    if (!ctx) goto done;
    mesh = cli_load_mesh(ctx, o->in, -1.0, o->triangulate);
    if (!mesh) goto done;
    r = sfb_mesh_fillet(ctx, mesh, &fc, &res, &rep);
    if (r != SFB_SUCCESS) {
        cli_error("%s: %s: %s", o->in, sfb_result_string(r), sfb_last_error(ctx));
        goto done;
    }
    if (!cli_output_open(&out, o->outp)) goto done;
    r = sfb_mesh_write_obj(res, cli_file_write, out.f);
    if (r != SFB_SUCCESS) {
        cli_error("writing '%s' failed: %s", o->outp, sfb_result_string(r));
        goto done;
    }
    for (i = 0; i < rep.curve_count; ++i) {
        const sfb_fillet_curve_report *c = &rep.curves[i];
        if (c->skipped) {
            cli_error("curve %d: %s, %d vertices (%.4g long): skipped, left sharp (--skip-failed: the radius cannot fillet it)", i,
                      c->closed ? "closed" : "open", c->curve_vertices, (double)c->curve_length);
            continue;
        }
        cli_error("curve %d: %s %s, %d vertices (%.4g long), radius %g: spine %.4g long, %d samples, %d vertices moved, %d spine loops cut, "
                  "largest deviation from the sweep %.3g",
                  i, c->closed ? "closed" : "open", c->convex ? "convex" : "concave", c->curve_vertices, (double)c->curve_length, (double)c->radius,
                  (double)c->spine_length, c->samples, c->vertices_moved, c->self_intersections, (double)c->max_deviation);
    }
    if (rep.faces_folded)
        cli_error("warning: %d faces turned over: the radius is too large for the surface around some curve (try a smaller --radius "
                  "or a larger --angle)", rep.faces_folded);
    if (rep.corner_count) cli_error("%d corners rounded by the ball's sphere, %d vertices moved onto them", rep.corner_count, rep.corner_vertices_moved);
    cli_error("%d curves filleted (%d skipped), %d vertices moved -> %s", rep.curve_count - rep.curves_skipped, rep.curves_skipped,
              rep.vertices_moved, o->outp);
    rc = 0;
done:
    rc = cli_output_finish(&out, rc);
    sfb_fillet_report_free(&rep);
    sfb_mesh_destroy(res);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    free(curves);
    free(verts);
    return rc;
}

/* ---- the commands' table, main ---- */

static const cli_command commands[] = {
    { "info", C_INFO, "IN.obj", "counts, valences, creases, extraordinary vertices, problems", NULL, 1, NULL, cmd_info },
    { "refine", C_REFINE, "[options] IN.obj -o OUT.obj", "uniform refinement, written as OBJ", NULL, 1, "OUT.obj", cmd_refine },
    { "eval", C_EVAL, "[options] IN.obj", "the limit surface at parametric locations (--random N or --locations FILE)",
      "prints one line per location (to standard output without -o):\n"
      "    face u v px py pz nx ny nz [dux duy duz dvx dvy dvz]", 1, NULL, cmd_eval },
    { "tess", C_TESS, "[options] IN.obj -o OUT.obj", "watertight triangles of the limit surface (v, vn, f v//vn)", NULL, 1, "OUT.obj",
      cmd_tess },
    { "shade", C_SHADE, "[options] IN.obj -o OUT.obj", "subdivision shading (seed 001): v, blended normals as vn, f v//vn",
      "prints output vertices, split vertices (infinitely sharp creases) and where N_S was computed", 1, "OUT.obj", cmd_shade },
    { "render", C_RENDER, "[options] IN.obj -o OUT.png", "a software picture of the shaded surface (PNG)",
      "one of --highlight, --blend-weights, --normal-colors (default grey shading); --rate and --trim belong to\n"
      "    the tessellated schemes (manifold, tribezier, pn), --manifold-weights to manifold, the shading options\n"
      "    and --blend-weights to the subdivision schemes",
      1, "OUT.png", cmd_render },
    { "analyze", C_ANALYZE, "[options] IN.obj -o OUT.png", "surface quality (seed 003) from the exact limit surface per pixel (PNG)",
      "every pixel is projected onto the exact surface along its view ray and shaded from its exact normal\n"
      "    (and second derivatives): the picture does not depend on --level", 1, "OUT.png", cmd_analyze },
    { "fillet", C_FILLET, "--radius R [options] IN.obj -o OUT.obj", "rolling-ball fillets of a triangle mesh's sharp features (seed 002)",
      "the same vertices, faces and connectivity; only the vertices of each blend region move, onto the\n"
      "    ball's sweep; prints one line per curve", 1, "OUT.obj", cmd_fillet },
    { "backends", C_BACKENDS, "", "list the backends and whether each is available", NULL, 0, NULL, cmd_backends },
};
#define COMMAND_COUNT (sizeof commands / sizeof commands[0])

static void print_usage(FILE *f) {
    size_t i;
    fputs("usage:\n", f);
    for (i = 0; i < COMMAND_COUNT; ++i) print_command(f, &commands[i], 0);
    fputs("  surfblend --help | -h | help [COMMAND]     this text, or one command's (also: surfblend COMMAND --help)\n"
          "  surfblend --version\n",
          f);
    fputs(names_note, f);
    fputs(exit_note, f);
}

static const cli_command *find_command(const char *name) {
    size_t i;
    for (i = 0; i < COMMAND_COUNT; ++i)
        if (strcmp(name, commands[i].name) == 0) return &commands[i];
    return NULL;
}

int main(int argc, char **argv) {
    const cli_command *c;
    cli_opts o;
    int rc;
    if (option_clash()) {
        cli_error("internal error: option %s is in the table twice for one command", option_clash());
        return 2;
    }
    if (argc < 2) return usage_error(NULL, "missing command");
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        if (argc > 2 && !(c = find_command(argv[2]))) {
            cli_error("unknown command '%s'", argv[2]);
            return usage_error(NULL, NULL);
        }
        if (argc > 2) print_command_usage(stdout, c);
        else print_usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("surfblend %d.%d.%d\n", SFB_VERSION_MAJOR, SFB_VERSION_MINOR, SFB_VERSION_PATCH);
        return 0;
    }
    c = find_command(argv[1]);
    if (!c) {
        cli_error("unknown command '%s'", argv[1]);
        return usage_error(NULL, NULL);
    }
    rc = parse_args(c, argc - 2, argv + 2, &o);
    if (rc) return rc < 0 ? 0 : rc;
    return c->run(&o);
}
