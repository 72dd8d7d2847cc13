/* surfblend command-line tool.
 *   surfblend info in.obj
 *   surfblend refine [--scheme catmark|loop|bilinear] [--level L] [--limit] [--backend NAME] in.obj -o out.obj
 *   surfblend eval [--scheme catmark|loop|manifold] [--weights hermite|cinf] [--backend NAME] (--random N [--seed S] | --locations FILE)
 *                  [--derivatives] [-o OUT] in.obj
 *   surfblend tess [--scheme catmark|loop|manifold] [--weights hermite|cinf] [--backend NAME] --rate N [--tolerance T] [--split-creases]
 *                  [--trim mask.png [--trim-tiles U V]] in.obj -o out.obj
 *   surfblend shade [shading options] [--limit] [--backend NAME] in.obj -o out.obj
 *   surfblend render [shading options] [--normals limit|subdivided|blended] [--highlight|--weights|--normal-colors]
 *                    [--size WxH] [--view YAW,PITCH] [--zoom Z] [--stripes N] [--edges] [--positions refined|limit] in.obj -o out.png
 *   surfblend render --scheme manifold [--manifold-weights hermite|cinf] [--rate N] [--trim mask.png [--trim-tiles U V]] [picture options]
 *                    in.obj -o out.png
 *   surfblend backends
 * Exit codes: 0 success, 1 bad input (message on stderr), 2 usage error. */
#include "surfblend.h"
/* PNG output and trimming-mask input (Debian libstb-dev); the library itself only takes and
 * returns raw pixel buffers */
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb/stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* In pieces: ISO C99 compilers need support string literals of 4095 characters only. */
static const char *const usage_text[] = {
    "usage:\n"
    "  surfblend info IN.obj                      counts, valences, creases, extraordinary vertices, problems\n"
    "  surfblend refine [options] IN.obj -o OUT.obj\n"
    "      --scheme catmark|loop|bilinear   subdivision scheme (default: from the file name prefix, else catmark)\n"
    "      --level L                        uniform refinement level 0..10 (default 2)\n"
    "      --limit                          write limit positions (and limit normals as vn) instead of refined points\n"
    "      --backend NAME                   ref|simd|gl|osmesa, tried first (else SURFBLEND_BACKEND, else the default order)\n"
    "  surfblend eval [options] IN.obj            the limit surface at parametric locations\n"
    "      --scheme catmark|loop|manifold   as for refine, or the manifold blending surface (seed 000)\n"
    "      --weights hermite|cinf           manifold blend weights: Hermite (default) or C-infinity\n"
    "      --locations FILE                 lines 'face u v' (parametric face; u, v in [0,1], and u + v <= 1 on Loop's\n"
    "                                       triangles; '#' starts a comment)\n"
    "      --random N [--seed S]            N random locations on faces that are not holes (deterministic for a seed)\n"
    "      --derivatives                    also print du and dv\n"
    "      -o OUT                           write to OUT instead of stdout\n"
    "      --backend NAME                   as for refine\n"
    "    prints one line per location: face u v px py pz nx ny nz [dux duy duz dvx dvy dvz]\n"
    "  surfblend tess [options] IN.obj -o OUT.obj   watertight triangles of the limit surface (v, vn, f v//vn)\n"
    "      --scheme catmark|loop|manifold   as for eval\n"
    "      --weights hermite|cinf           as for eval\n"
    "      --rate N                         segments per parametric-face edge, 1..1024 (required)\n"
    "      --tolerance T                    adaptive: per face the smallest rate <= N within chordal error T\n"
    "      --split-creases                  separate vertices (and normals) on each side of infinitely sharp creases\n"
    "      --trim MASK.png                  trim with a mask over each parametric face's (u,v) square (seed 000 V.5):\n"
    "                                       grey level >= 50% kept, darker trimmed; the picture's top row is v = 1\n"
    "      --trim-tiles U V                 the mask is an atlas of U x V tiles, tile t (row-major from v = 0) for\n"
    "                                       parametric face t; later faces untrimmed (default: one mask for all)\n"
    "      --backend NAME                   as for refine\n"
    ,
    "  surfblend shade [options] IN.obj -o OUT.obj   subdivision shading (seed 001): v, blended normals as vn, f v//vn\n"
    "      --scheme catmark|loop            as for refine\n"
    "      --level L                        uniform refinement level 0..10 (default 3)\n"
    "      --variant A|B                    sharp vertices: B (default) blend weight 0, A treated as smooth ones\n"
    "      --darts smooth|sharp             darts count as smooth (default) or sharp vertices for the weights\n"
    "      --normals-level L                level where the subdivided normals N_S start (0: control mesh; default 1)\n"
    "      --weights-level L                level where the blend weights are seeded (0: control mesh; default 1)\n"
    "      --p P                            blend exponent, > 0 (default 1): N_B = (1 - b^P) N_L + b^P N_S\n"
    "      --averaging linear|renormalized|spherical   how N_S is averaged from one level to the next (default linear)\n"
    "      --all-subdivided                 compute N_S at every vertex, not only where b > 0\n"
    "      --limit                          write limit positions instead of refined points\n"
    "      --backend NAME                   as for refine\n"
    "    prints output vertices, split vertices (infinitely sharp creases) and where N_S was computed\n"
    "  surfblend render [options] IN.obj -o OUT.png   a software picture of the shaded surface\n"
    "      the shading options above (not --limit), and:\n"
    "      --normals limit|subdivided|blended  which normal field to draw (default blended)\n"
    "      --highlight | --weights | --normal-colors   highlight lines, blend weights (blue 0 .. red 1), normals as RGB\n"
    "                                       (default: grey shading)\n"
    "      --positions refined|limit        refined points or limit positions (default limit)\n"
    "      --size WxH                       picture size, 1..8192 each (default 640x480)\n"
    "      --view YAW,PITCH                 camera angles in degrees around the y axis and above the xz plane (default 30,25)\n"
    "      --zoom Z                         magnification (default 1: the bounding sphere fits)\n"
    "      --stripes N                      highlight lines per object diameter (default 8)\n"
    "      --edges                          draw the refined mesh's edges\n"
    "      --scheme manifold                draw the manifold blending surface (seed 000) tessellated instead, with:\n"
    "        --manifold-weights hermite|cinf (tess's --weights), --rate N (default 16), --trim MASK.png [--trim-tiles U V]\n"
    "  surfblend backends                         list the backends and whether each is available\n"
    "  surfblend --help | --version\n"
    "exit codes: 0 success, 1 bad input, 2 usage error\n",
    NULL
};

static void print_usage(FILE *f) {
    int i;
    for (i = 0; usage_text[i]; ++i) fputs(usage_text[i], f);
}

static int usage(const char *msg) {
    if (msg) fprintf(stderr, "surfblend: %s\n", msg);
    print_usage(stderr);
    return 2;
}

/* The arguments every command that reads one OBJ shares: --backend NAME, -o/--output FILE,
 * the input file; anything else starting with '-' is an unknown option. Consumes argv[*i]
 * (and its value); returns 0, or usage()'s status. */
static int common_arg(int argc, char **argv, int *i, const char *cmd, const char **backend, const char **outp, const char **in) {
    char msg[64];
    if (strcmp(argv[*i], "--backend") == 0) {
        if (++*i >= argc) return usage("--backend needs a name");
        *backend = argv[*i];
    } else if (strcmp(argv[*i], "-o") == 0 || strcmp(argv[*i], "--output") == 0) {
        if (++*i >= argc) return usage("-o needs a file name");
        *outp = argv[*i];
    } else if (argv[*i][0] == '-' && argv[*i][1]) {
        fprintf(stderr, "surfblend: unknown option '%s'\n", argv[*i]);
        return usage(NULL);
    } else if (!*in) {
        *in = argv[*i];
    } else {
        snprintf(msg, sizeof msg, "%s takes one input file", cmd);
        return usage(msg);
    }
    return 0;
}

static char *read_file(const char *path, size_t *size) {
    FILE *f = strcmp(path, "-") == 0 ? stdin : fopen(path, "rb");
    char *buf = NULL;
    size_t cap = 0, n = 0;
    if (!f) return NULL;
    for (;;) {
        size_t got;
        if (n == cap) {
            char *nb;
            cap = cap ? cap * 2 : 1 << 16;
            if (cap > ((size_t)1 << 32)) { free(buf); buf = NULL; break; }
            nb = (char *)realloc(buf, cap);
            if (!nb) { free(buf); buf = NULL; break; }
            buf = nb;
        }
        got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) break;
    }
    if (f != stdin) fclose(f);
    *size = n;
    return buf;
}

static int file_write(const void *data, size_t size, void *user) {
    return fwrite(data, 1, size, (FILE *)user) != size;
}

/* --backend NAME is tried first; if it cannot initialise, the default order follows and the
 * reason is printed (the same fall-through a library user gets). */
static sfb_context *make_context(const char *backend) {
    sfb_context_config cfg = sfb_context_config_init();
    sfb_backend_kind kinds[3];
    sfb_context *ctx = NULL;
    sfb_result r;
    char report[2048];
    if (backend) {
        kinds[0] = sfb_backend_kind_parse(backend);
        if (kinds[0] == SFB_BACKEND_DEFAULT) {
            fprintf(stderr, "surfblend: unknown backend '%s' (ref, simd, gl, osmesa)\n", backend);
            return NULL;
        }
        kinds[1] = SFB_BACKEND_SIMD;
        kinds[2] = SFB_BACKEND_REF;
        cfg.backends = kinds;
        cfg.backend_count = 3;
        cfg.ignore_environment = 1;
    }
    r = sfb_context_create(&cfg, &ctx);
    if (r != SFB_SUCCESS) {
        fprintf(stderr, "surfblend: no backend could be initialised (%s)\n", sfb_result_string(r));
        return NULL;
    }
    if ((backend && sfb_backend_kind_parse(sfb_context_backend_name(ctx)) != kinds[0]) ||
        (!backend && getenv("SURFBLEND_BACKEND") && *getenv("SURFBLEND_BACKEND") &&
         sfb_backend_kind_parse(sfb_context_backend_name(ctx)) != sfb_backend_kind_parse(getenv("SURFBLEND_BACKEND")))) {
        sfb_context_backend_report(ctx, report, sizeof report);
        fprintf(stderr, "surfblend: the requested backend is unavailable; using %s. Backends tried:\n%s",
                sfb_context_backend_name(ctx), report);
    }
    return ctx;
}

static sfb_mesh *load(sfb_context *ctx, const char *path) {
    size_t size = 0;
    char *text = read_file(path, &size);
    sfb_mesh *mesh = NULL;
    sfb_result r;
    if (!text) {
        fprintf(stderr, "surfblend: cannot read '%s'\n", path);
        return NULL;
    }
    r = sfb_mesh_read_obj(ctx, text, size, &mesh);
    free(text);
    if (r != SFB_SUCCESS) {
        fprintf(stderr, "surfblend: %s: %s: %s\n", path, sfb_result_string(r), sfb_last_error(ctx));
        return NULL;
    }
    return mesh;
}

static int cmd_info(int argc, char **argv) {
    sfb_context *ctx;
    sfb_mesh *mesh;
    sfb_mesh_info in;
    int hist[33], over, i, problems = 0;
    if (argc != 1) return usage("info takes one OBJ file");
    ctx = make_context(NULL);
    if (!ctx) return 1;
    mesh = load(ctx, argv[0]);
    if (!mesh) { sfb_context_destroy(ctx); return 1; }
    sfb_mesh_get_info(mesh, &in);
    printf("file:        %s\n", argv[0]);
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
    if (in.triangles + in.ngons > 0 && in.quads > 0) { printf(" mixed face sizes (Loop needs all triangles);"); problems++; }
    if (!problems) printf(" none");
    printf("\n");
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return 0;
}

static int scheme_from_name(const char *s, sfb_scheme *out) {
    if (strcmp(s, "catmark") == 0 || strcmp(s, "catmull-clark") == 0) *out = SFB_SCHEME_CATMARK;
    else if (strcmp(s, "loop") == 0) *out = SFB_SCHEME_LOOP;
    else if (strcmp(s, "bilinear") == 0) *out = SFB_SCHEME_BILINEAR;
    else if (strcmp(s, "manifold") == 0) *out = SFB_SCHEME_MANIFOLD_BLEND;
    else return 0;
    return 1;
}

/* The scheme of an input: --scheme if given, else the file name's prefix (loop_, bilinear_),
 * else Catmull-Clark. */
static sfb_scheme scheme_for(const char *path, int have_scheme, sfb_scheme scheme) {
    const char *base;
    if (have_scheme) return scheme;
    base = strrchr(path, '/');
    base = base ? base + 1 : path;
    if (strncmp(base, "loop_", 5) == 0) return SFB_SCHEME_LOOP;
    if (strncmp(base, "bilinear_", 9) == 0) return SFB_SCHEME_BILINEAR;
    return SFB_SCHEME_CATMARK;
}

static int cmd_refine(int argc, char **argv) {
    const char *in = NULL, *outp = NULL, *backend = NULL;
    sfb_scheme scheme = SFB_SCHEME_CATMARK;
    int have_scheme = 0, level = 2, limit = 0, i, rc = 1;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_surface_config cfg;
    sfb_mesh_data data;
    sfb_result r;
    FILE *f = NULL;
    memset(&data, 0, sizeof data);
    for (i = 0; i < argc; ++i) {
        if (strcmp(argv[i], "--scheme") == 0) {
            if (++i >= argc || !scheme_from_name(argv[i], &scheme)) return usage("--scheme needs catmark, loop or bilinear");
            have_scheme = 1;
        } else if (strcmp(argv[i], "--level") == 0) {
            char *end;
            long l;
            if (++i >= argc) return usage("--level needs a number");
            l = strtol(argv[i], &end, 10);
            if (*end || end == argv[i] || l < 0 || l > 1000) return usage("--level needs a number >= 0");
            level = (int)l;
        } else if (strcmp(argv[i], "--limit") == 0) {
            limit = 1;
        } else {
            int ur = common_arg(argc, argv, &i, "refine", &backend, &outp, &in);
            if (ur) return ur;
        }
    }
    if (!in) return usage("refine needs an input OBJ file");
    if (!outp) return usage("refine needs -o OUT.obj");
    scheme = scheme_for(in, have_scheme, scheme);
    ctx = make_context(backend);
    if (!ctx) return 1;
    mesh = load(ctx, in);
    if (!mesh) goto done;
    cfg = sfb_surface_config_init(scheme, level);
    cfg.flags = SFB_REFINE_UVS | (limit ? SFB_REFINE_LIMIT : 0u);
    r = sfb_surface_create(ctx, mesh, &cfg, &surf);
    if (r == SFB_SUCCESS) r = sfb_surface_refine(surf, &data);
    if (r != SFB_SUCCESS) {
        fprintf(stderr, "surfblend: %s: %s: %s\n", in, sfb_result_string(r), sfb_last_error(ctx));
        goto done;
    }
    f = strcmp(outp, "-") == 0 ? stdout : fopen(outp, "wb");
    if (!f) {
        fprintf(stderr, "surfblend: cannot write '%s'\n", outp);
        goto done;
    }
    {
        sfb_mesh_desc d;
        sfb_mesh_data_desc(&data, &d);
        if (limit) {
            d.positions = data.limit_positions;
            for (i = 0; i < data.vertex_count; ++i)
                fprintf(f, "vn %.7g %.7g %.7g\n", data.normals[3 * i], data.normals[3 * i + 1], data.normals[3 * i + 2]);
        }
        r = sfb_write_obj(&d, file_write, f);
        if (r != SFB_SUCCESS) {
            fprintf(stderr, "surfblend: writing '%s' failed: %s\n", outp, sfb_result_string(r));
            goto done;
        }
    }
    fprintf(stderr, "surfblend: %s level %d: %d vertices, %d faces -> %s (backend %s)\n", sfb_scheme_name(scheme), level,
            data.vertex_count, data.face_count, outp, sfb_context_backend_name(ctx));
    rc = 0;
done:
    if (f && f != stdout && fclose(f) != 0 && rc == 0) { fprintf(stderr, "surfblend: writing '%s' failed\n", outp); rc = 1; }
    sfb_mesh_data_free(&data);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return rc;
}

/* A surface with its patch table (limit evaluation, tessellation). */
/* --weights hermite|cinf of the manifold scheme */
static int weights_from_name(const char *s, int *out) {
    if (strcmp(s, "hermite") == 0) *out = SFB_MANIFOLD_WEIGHTS_HERMITE;
    else if (strcmp(s, "cinf") == 0) *out = SFB_MANIFOLD_WEIGHTS_CINF;
    else return 0;
    return 1;
}

static sfb_surface *make_patch_surface(sfb_context *ctx, const sfb_mesh *mesh, const char *path, sfb_scheme scheme, int weights) {
    sfb_surface_config cfg = sfb_surface_config_init(scheme, 0);
    sfb_surface *surf = NULL;
    sfb_result r;
    cfg.flags = SFB_REFINE_PATCHES;
    cfg.manifold.weights = weights;
    r = sfb_surface_create(ctx, mesh, &cfg, &surf);
    if (r != SFB_SUCCESS) {
        fprintf(stderr, "surfblend: %s: %s: %s\n", path, sfb_result_string(r), sfb_last_error(ctx));
        return NULL;
    }
    return surf;
}

static int parse_int(const char *s, long lo, long hi, long *out) {
    char *end;
    long v = strtol(s, &end, 10);
    if (end == s || *end || v < lo || v > hi) return 0;
    *out = v;
    return 1;
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
    char *text = read_file(path, &size);
    long line = 0;
    if (!text) {
        fprintf(stderr, "surfblend: cannot read '%s'\n", path);
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
            fprintf(stderr, "surfblend: %s: line %ld: line too long\n", path, line);
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
            fprintf(stderr, "surfblend: %s: too many locations\n", path);
            free(text);
            return 0;
        }
        continue;
    bad:
        fprintf(stderr, "surfblend: %s: line %ld: expected 'face u v' (an integer and two numbers)\n", path, line);
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
static int random_locations(sfb_context *ctx, const sfb_surface *surf, int triangles, long count, unsigned long long seed, loc_list *L) {
    int np = sfb_surface_param_face_count(surf), nlive = 0, i;
    int *live = (int *)malloc(((size_t)np + 1) * sizeof(int));
    sfb_location *probe = (sfb_location *)malloc(((size_t)np + 1) * sizeof(sfb_location));
    float *pos = (float *)malloc(((size_t)np + 1) * 3 * sizeof(float));
    int ok = 0;
    if (!live || !probe || !pos) goto done;
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
            fprintf(stderr, "surfblend: %s: %s\n", sfb_result_string(r), sfb_last_error(ctx));
            goto done;
        }
        i = (int)sfb_last_error_info(ctx).index;
        memmove(live + i, live + i + 1, (size_t)(nlive - i - 1) * sizeof(int));
        --nlive;
    }
    sfb_clear_error(ctx);
    if (nlive == 0 && count > 0) {
        fprintf(stderr, "surfblend: the surface has no parametric face to sample (every face is a hole)\n");
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
        if (!loc_push(L, live[a % (unsigned long long)nlive], u, v, 0)) { fprintf(stderr, "surfblend: out of memory\n"); goto done; }
    }
    ok = 1;
done:
    free(live);
    free(probe);
    free(pos);
    return ok;
}

static int cmd_eval(int argc, char **argv) {
    const char *in = NULL, *outp = NULL, *backend = NULL, *locfile = NULL;
    long nrandom = -1, seed = 1;
    int derivs = 0, i, rc = 1, have_scheme = 0, weights = SFB_MANIFOLD_WEIGHTS_HERMITE;
    sfb_scheme scheme = SFB_SCHEME_CATMARK;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    loc_list L;
    float *buf = NULL;
    FILE *f = NULL;
    memset(&L, 0, sizeof L);
    for (i = 0; i < argc; ++i) {
        if (strcmp(argv[i], "--random") == 0) {
            if (++i >= argc || !parse_int(argv[i], 0, 10000000L, &nrandom)) return usage("--random needs a count 0..10000000");
        } else if (strcmp(argv[i], "--seed") == 0) {
            if (++i >= argc || !parse_int(argv[i], 0, 2147483647L, &seed)) return usage("--seed needs a number >= 0");
        } else if (strcmp(argv[i], "--locations") == 0) {
            if (++i >= argc) return usage("--locations needs a file name");
            locfile = argv[i];
        } else if (strcmp(argv[i], "--derivatives") == 0) {
            derivs = 1;
        } else if (strcmp(argv[i], "--weights") == 0) {
            if (++i >= argc || !weights_from_name(argv[i], &weights)) return usage("--weights needs hermite or cinf");
        } else if (strcmp(argv[i], "--scheme") == 0) {
            if (++i >= argc || !scheme_from_name(argv[i], &scheme)) return usage("--scheme needs catmark, loop or manifold");
            have_scheme = 1;
        } else {
            int ur = common_arg(argc, argv, &i, "eval", &backend, &outp, &in);
            if (ur) return ur;
        }
    }
    if (!in) return usage("eval needs an input OBJ file");
    if ((nrandom >= 0) == (locfile != NULL)) return usage("eval needs either --random N or --locations FILE");
    ctx = make_context(backend);
    if (!ctx) return 1;
    mesh = load(ctx, in);
    if (!mesh) goto done;
    scheme = scheme_for(in, have_scheme, scheme);
    surf = make_patch_surface(ctx, mesh, in, scheme, weights);
    if (!surf) goto done;
    if (locfile ? !read_locations(locfile, &L)
                : !random_locations(ctx, surf, scheme == SFB_SCHEME_LOOP, nrandom, (unsigned long long)seed, &L))
        goto done;
    buf = (float *)malloc(((size_t)L.count + 1) * 12 * sizeof(float));
    if (!buf) { fprintf(stderr, "surfblend: out of memory\n"); goto done; }
    {
        sfb_eval_output eo;
        sfb_result r;
        size_t n = (size_t)L.count;
        memset(&eo, 0, sizeof eo);
        eo.position = buf;
        eo.normal = buf + 3 * n;
        if (derivs) { eo.du = buf + 6 * n; eo.dv = buf + 9 * n; }
        r = sfb_surface_eval(surf, L.loc, L.count, &eo);
        if (r != SFB_SUCCESS) {
            sfb_error_info e = sfb_last_error_info(ctx);
            if (locfile && e.index >= 0 && e.index < L.count)
                fprintf(stderr, "surfblend: %s: line %ld: %s: %s\n", locfile, L.line[e.index], sfb_result_string(r), sfb_last_error(ctx));
            else
                fprintf(stderr, "surfblend: %s: %s: %s\n", in, sfb_result_string(r), sfb_last_error(ctx));
            goto done;
        }
        f = (!outp || strcmp(outp, "-") == 0) ? stdout : fopen(outp, "wb");
        if (!f) {
            fprintf(stderr, "surfblend: cannot write '%s'\n", outp);
            goto done;
        }
        for (i = 0; i < L.count; ++i) {
            const float *p = buf + 3 * (size_t)i, *nn = eo.normal + 3 * (size_t)i;
            fprintf(f, "%d %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g", L.loc[i].face, L.loc[i].u, L.loc[i].v, p[0], p[1], p[2], nn[0],
                    nn[1], nn[2]);
            if (derivs) {
                const float *a = eo.du + 3 * (size_t)i, *b = eo.dv + 3 * (size_t)i;
                fprintf(f, " %.9g %.9g %.9g %.9g %.9g %.9g", a[0], a[1], a[2], b[0], b[1], b[2]);
            }
            fputc('\n', f);
        }
    }
    rc = 0;
done:
    if (f && f != stdout && fclose(f) != 0 && rc == 0) { fprintf(stderr, "surfblend: writing '%s' failed\n", outp); rc = 1; }
    if (f == stdout && fflush(stdout) != 0 && rc == 0) { fprintf(stderr, "surfblend: writing the output failed\n"); rc = 1; }
    free(buf);
    free(L.loc);
    free(L.line);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return rc;
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

/* A trimming mask from a PNG: 8-bit grey (luminance of colour pictures; alpha ignored), rows
 * flipped so that the picture's top row is v = 1 (the mask's row 0 is v = 0). Returns the
 * texels (free them), or NULL with a message printed. */
static unsigned char *load_mask(const char *path, int *w, int *h) {
    int n = 0, j;
    size_t row;
    unsigned char *px = stbi_load(path, w, h, &n, 1), *tmp;
    if (!px) {
        fprintf(stderr, "surfblend: cannot read the trimming mask '%s': %s\n", path, stbi_failure_reason());
        return NULL;
    }
    row = (size_t)*w;
    tmp = (unsigned char *)malloc(row ? row : 1);
    if (!tmp) {
        fprintf(stderr, "surfblend: out of memory reading '%s'\n", path);
        stbi_image_free(px);
        return NULL;
    }
    for (j = 0; j < *h / 2; ++j) {
        unsigned char *a = px + (size_t)j * row, *b = px + (size_t)(*h - 1 - j) * row;
        memcpy(tmp, a, row);
        memcpy(a, b, row);
        memcpy(b, tmp, row);
    }
    free(tmp);
    return px;
}

static int cmd_tess(int argc, char **argv) {
    const char *in = NULL, *outp = NULL, *backend = NULL, *trim_path = NULL;
    long rate = -1, tiles_u = 0, tiles_v = 0;
    int have_tiles = 0;
    unsigned char *texels = NULL;
    sfb_trim_mask mask;
    double tolerance = 0.0;
    int split = 0, i, rc = 1, have_scheme = 0, weights = SFB_MANIFOLD_WEIGHTS_HERMITE;
    sfb_scheme scheme = SFB_SCHEME_CATMARK;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_tess_config tc;
    sfb_tess_data td;
    sfb_result r;
    FILE *f = NULL;
    memset(&td, 0, sizeof td);
    for (i = 0; i < argc; ++i) {
        if (strcmp(argv[i], "--rate") == 0) {
            /* the range (1..1024) is the library's to check and report */
            if (++i >= argc || !parse_int(argv[i], -2147483647L, 2147483647L, &rate)) return usage("--rate needs a number");
        } else if (strcmp(argv[i], "--tolerance") == 0) {
            char *end;
            if (++i >= argc) return usage("--tolerance needs a number");
            tolerance = strtod(argv[i], &end);
            if (end == argv[i] || *end) return usage("--tolerance needs a number");
        } else if (strcmp(argv[i], "--split-creases") == 0) {
            split = 1;
        } else if (strcmp(argv[i], "--scheme") == 0) {
            if (++i >= argc || !scheme_from_name(argv[i], &scheme)) return usage("--scheme needs catmark, loop or manifold");
            have_scheme = 1;
        } else if (strcmp(argv[i], "--weights") == 0) {
            if (++i >= argc || !weights_from_name(argv[i], &weights)) return usage("--weights needs hermite or cinf");
        } else if (strcmp(argv[i], "--trim") == 0) {
            if (++i >= argc) return usage("--trim needs a PNG file");
            trim_path = argv[i];
        } else if (strcmp(argv[i], "--trim-tiles") == 0) {
            /* the counts are the library's to check against the mask */
            if (i + 2 >= argc || !parse_int(argv[i + 1], -2147483647L, 2147483647L, &tiles_u) ||
                !parse_int(argv[i + 2], -2147483647L, 2147483647L, &tiles_v))
                return usage("--trim-tiles needs two numbers U V");
            i += 2;
            have_tiles = 1;
        } else {
            int ur = common_arg(argc, argv, &i, "tess", &backend, &outp, &in);
            if (ur) return ur;
        }
    }
    if (!in) return usage("tess needs an input OBJ file");
    if (!outp) return usage("tess needs -o OUT.obj");
    if (rate == -1) return usage("tess needs --rate N");
    if (have_tiles && !trim_path) return usage("--trim-tiles needs --trim MASK.png");
    memset(&mask, 0, sizeof mask);
    if (trim_path) {
        texels = load_mask(trim_path, &mask.width, &mask.height);
        if (!texels) return 1;
        mask.texels = texels;
        mask.tiles_u = (int)tiles_u;
        mask.tiles_v = (int)tiles_v;
    }
    ctx = make_context(backend);
    if (!ctx) { stbi_image_free(texels); return 1; }
    mesh = load(ctx, in);
    if (!mesh) goto done;
    surf = make_patch_surface(ctx, mesh, in, scheme_for(in, have_scheme, scheme), weights);
    if (!surf) goto done;
    tc = sfb_tess_config_init((int)rate);
    tc.tolerance = (float)tolerance;
    tc.flags = split ? (unsigned)SFB_TESS_SPLIT_CREASES : 0u;
    tc.trim = trim_path ? &mask : NULL;
    r = sfb_surface_tessellate(surf, &tc, &td);
    if (r != SFB_SUCCESS) {
        fprintf(stderr, "surfblend: %s: %s: %s\n", in, sfb_result_string(r), sfb_last_error(ctx));
        goto done;
    }
    f = strcmp(outp, "-") == 0 ? stdout : fopen(outp, "wb");
    if (!f) {
        fprintf(stderr, "surfblend: cannot write '%s'\n", outp);
        goto done;
    }
    fprintf(f, "# surfblend tess of %s: rate %ld%s%s%s%s, %d vertices, %d triangles\n", in, rate, tolerance > 0.0 ? " adaptive" : "",
            split ? " split creases" : "", trim_path ? " trimmed by " : "", trim_path ? trim_path : "", td.vertex_count, td.triangle_count);
    for (i = 0; i < td.vertex_count; ++i)
        fprintf(f, "v %.7g %.7g %.7g\n", td.positions[3 * i], td.positions[3 * i + 1], td.positions[3 * i + 2]);
    for (i = 0; i < td.vertex_count; ++i)
        fprintf(f, "vn %.7g %.7g %.7g\n", td.normals[3 * i], td.normals[3 * i + 1], td.normals[3 * i + 2]);
    for (i = 0; i < td.triangle_count; ++i) {
        int a = td.triangles[3 * i] + 1, b = td.triangles[3 * i + 1] + 1, c = td.triangles[3 * i + 2] + 1;
        fprintf(f, "f %d//%d %d//%d %d//%d\n", a, a, b, b, c, c);
    }
    {
        long total, closed, boundary, more;
        if (!edge_counts(&td, &total, &closed, &boundary, &more)) { fprintf(stderr, "surfblend: out of memory\n"); goto done; }
        char trimmed[64] = "";
        if (trim_path) snprintf(trimmed, sizeof trimmed, " trimmed (%dx%d mask)", mask.width, mask.height);
        fprintf(stderr, "surfblend: tess rate %ld%s%s: %d vertices, %d triangles, %ld edges (%ld closed, %ld boundary%s) -> %s (backend %s)\n",
                rate, tolerance > 0.0 ? " adaptive" : "", trimmed, td.vertex_count, td.triangle_count, total, closed, boundary,
                more ? ", some non-manifold" : "", outp, sfb_context_backend_name(ctx));
    }
    rc = 0;
done:
    if (f && f != stdout && fclose(f) != 0 && rc == 0) { fprintf(stderr, "surfblend: writing '%s' failed\n", outp); rc = 1; }
    sfb_tess_data_free(&td);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    stbi_image_free(texels);
    return rc;
}

/* ---- subdivision shading (seed 001) and software pictures ---- */

/* Options shared by `shade` and `render`: the surface, the shading options, the blend. */
typedef struct shade_opts {
    const char *in, *outp, *backend;
    sfb_scheme scheme;
    int have_scheme, level, variant, darts, normals_level, weights_level, all_subdivided, averaging;
    double p;
} shade_opts;

static void shade_opts_init(shade_opts *o, int level) {
    memset(o, 0, sizeof *o);
    o->scheme = SFB_SCHEME_CATMARK;
    o->level = level;
    o->p = 1.0;
}

/* A shading level on the command line: 0 is the control mesh (SFB_SHADE_LEVEL_CONTROL; 0 in
 * the struct means the default, level 1). Whether it fits the refinement level is the
 * library's to check. */
static int parse_shade_level(const char *s, int *out) {
    long l;
    if (!parse_int(s, 0, 1000, &l)) return 0;
    *out = l == 0 ? SFB_SHADE_LEVEL_CONTROL : (int)l;
    return 1;
}

/* Consumes argv[*i] (and its value) when it is a shading option: returns 1; 0 when it is not
 * one; a negative value -(usage status) on a bad value. */
static int shade_arg(int argc, char **argv, int *i, shade_opts *o) {
    const char *a = argv[*i];
    if (strcmp(a, "--scheme") == 0) {
        if (++*i >= argc || !scheme_from_name(argv[*i], &o->scheme) || o->scheme == SFB_SCHEME_BILINEAR)
            return -usage("--scheme needs catmark or loop");
        o->have_scheme = 1;
    } else if (strcmp(a, "--level") == 0) {
        long l;
        if (++*i >= argc || !parse_int(argv[*i], 0, 1000, &l)) return -usage("--level needs a number >= 0");
        o->level = (int)l;
    } else if (strcmp(a, "--variant") == 0) {
        if (++*i >= argc) return -usage("--variant needs A or B");
        if (strcmp(argv[*i], "A") == 0 || strcmp(argv[*i], "a") == 0) o->variant = SFB_SHADE_VARIANT_A;
        else if (strcmp(argv[*i], "B") == 0 || strcmp(argv[*i], "b") == 0) o->variant = SFB_SHADE_VARIANT_B;
        else return -usage("--variant needs A or B");
    } else if (strcmp(a, "--darts") == 0) {
        if (++*i >= argc) return -usage("--darts needs smooth or sharp");
        if (strcmp(argv[*i], "smooth") == 0) o->darts = SFB_SHADE_DARTS_SMOOTH;
        else if (strcmp(argv[*i], "sharp") == 0) o->darts = SFB_SHADE_DARTS_SHARP;
        else return -usage("--darts needs smooth or sharp");
    } else if (strcmp(a, "--normals-level") == 0) {
        if (++*i >= argc || !parse_shade_level(argv[*i], &o->normals_level)) return -usage("--normals-level needs a level >= 0 (0: the control mesh)");
    } else if (strcmp(a, "--weights-level") == 0) {
        if (++*i >= argc || !parse_shade_level(argv[*i], &o->weights_level)) return -usage("--weights-level needs a level >= 0 (0: the control mesh)");
    } else if (strcmp(a, "--p") == 0) {
        char *end;
        if (++*i >= argc) return -usage("--p needs a number > 0");
        o->p = strtod(argv[*i], &end);
        if (end == argv[*i] || *end || !(o->p > 0.0) || !isfinite(o->p) || o->p > 1e30) return -usage("--p needs a number > 0");
    } else if (strcmp(a, "--averaging") == 0) {
        if (++*i >= argc) return -usage("--averaging needs linear, renormalized or spherical");
        if (strcmp(argv[*i], "linear") == 0) o->averaging = SFB_SHADE_AVERAGE_LINEAR;
        else if (strcmp(argv[*i], "renormalized") == 0) o->averaging = SFB_SHADE_AVERAGE_RENORMALIZED;
        else if (strcmp(argv[*i], "spherical") == 0) o->averaging = SFB_SHADE_AVERAGE_SPHERICAL;
        else return -usage("--averaging needs linear, renormalized or spherical");
    } else if (strcmp(a, "--all-subdivided") == 0) {
        o->all_subdivided = 1;
    } else {
        return 0;
    }
    return 1;
}

/* Builds the shading surface of o->in and shades it into *data. Returns 1 on success; on
 * failure prints why and returns 0 (what was made is freed by the caller). */
static int shade_mesh(sfb_context *ctx, const shade_opts *o, sfb_mesh **mesh, sfb_surface **surf, sfb_mesh_data *data) {
    sfb_surface_config cfg;
    sfb_shade_params sp;
    sfb_result r;
    *mesh = load(ctx, o->in);
    if (!*mesh) return 0;
    cfg = sfb_surface_config_init(scheme_for(o->in, o->have_scheme, o->scheme), o->level);
    cfg.flags = SFB_REFINE_LIMIT | SFB_REFINE_SHADING;
    cfg.shading.variant = o->variant;
    cfg.shading.darts = o->darts;
    cfg.shading.normals_level = o->normals_level;
    cfg.shading.weights_level = o->weights_level;
    cfg.shading.averaging = o->averaging;
    sp = sfb_shade_params_init();
    sp.p = (float)o->p;
    sp.flags = o->all_subdivided ? (unsigned)SFB_SHADE_ALL_SUBDIVIDED : 0u;
    r = sfb_surface_create(ctx, *mesh, &cfg, surf);
    if (r == SFB_SUCCESS) r = sfb_surface_shade(*surf, &sp, data);
    if (r != SFB_SUCCESS) {
        fprintf(stderr, "surfblend: %s: %s: %s\n", o->in, sfb_result_string(r), sfb_last_error(ctx));
        return 0;
    }
    return 1;
}

/* Output vertices, refined vertices with more than one copy, and the share of output
 * vertices where N_S was computed. */
static void shade_summary(const char *what, const shade_opts *o, const sfb_mesh_data *d, sfb_context *ctx, const char *outp) {
    int split = 0, i;
    int *copies = d->refined_vertex_count > 0 ? (int *)calloc((size_t)d->refined_vertex_count, sizeof(int)) : NULL;
    if (copies && d->vertex_origin) {
        for (i = 0; i < d->vertex_count; ++i) {
            int v = d->vertex_origin[i];
            if (v >= 0 && v < d->refined_vertex_count && ++copies[v] == 2) ++split;
        }
    }
    free(copies);
    fprintf(stderr, "surfblend: %s %s level %d: %d output vertices (%d refined, %d split), %d faces; N_S computed at %d vertices (%.1f%%) -> %s (backend %s)\n",
            what, sfb_scheme_name(scheme_for(o->in, o->have_scheme, o->scheme)), o->level, d->vertex_count, d->refined_vertex_count,
            split, d->face_count, d->subdivided_count, d->vertex_count > 0 ? 100.0 * d->subdivided_count / d->vertex_count : 0.0, outp,
            sfb_context_backend_name(ctx));
}

/* Finishes an output file: closes it, and removes it when anything failed, so that no
 * partial file is left behind. Returns rc, or 1 when closing failed. */
static int finish_output(FILE *f, const char *outp, int rc) {
    if (f == stdout) {
        if (fflush(stdout) != 0 && rc == 0) { fprintf(stderr, "surfblend: writing the output failed\n"); rc = 1; }
    } else if (f) {
        if (fclose(f) != 0 && rc == 0) { fprintf(stderr, "surfblend: writing '%s' failed\n", outp); rc = 1; }
        if (rc != 0) remove(outp);
    }
    return rc;
}

static int cmd_shade(int argc, char **argv) {
    shade_opts o;
    int limit = 0, i, rc = 1;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_mesh_data data;
    FILE *f = NULL;
    memset(&data, 0, sizeof data);
    shade_opts_init(&o, 3);
    for (i = 0; i < argc; ++i) {
        int sr = shade_arg(argc, argv, &i, &o);
        if (sr < 0) return -sr;
        if (sr) continue;
        if (strcmp(argv[i], "--limit") == 0) {
            limit = 1;
        } else {
            int ur = common_arg(argc, argv, &i, "shade", &o.backend, &o.outp, &o.in);
            if (ur) return ur;
        }
    }
    if (!o.in) return usage("shade needs an input OBJ file");
    if (!o.outp) return usage("shade needs -o OUT.obj");
    ctx = make_context(o.backend);
    if (!ctx) return 1;
    if (!shade_mesh(ctx, &o, &mesh, &surf, &data)) goto done;
    if (!data.normals || (limit && !data.limit_positions)) {
        fprintf(stderr, "surfblend: %s: the shaded mesh lacks %s\n", o.in, data.normals ? "limit positions" : "normals");
        goto done;
    }
    f = strcmp(o.outp, "-") == 0 ? stdout : fopen(o.outp, "wb");
    if (!f) {
        fprintf(stderr, "surfblend: cannot write '%s'\n", o.outp);
        goto done;
    }
    {
        const float *pos = limit ? data.limit_positions : data.positions;
        size_t off = 0;
        int ok = 1, j;
        static const char *averaging_names[3] = { "linear", "renormalized", "spherical" };
        ok &= fprintf(f, "# surfblend shade of %s: %s level %d, variant %s, darts %s, averaging %s, p %g; %d vertices (%d refined), %d faces\n",
                      o.in, sfb_scheme_name(scheme_for(o.in, o.have_scheme, o.scheme)), o.level, o.variant == SFB_SHADE_VARIANT_A ? "A" : "B",
                      o.darts == SFB_SHADE_DARTS_SHARP ? "sharp" : "smooth", averaging_names[o.averaging], o.p, data.vertex_count,
                      data.refined_vertex_count, data.face_count) > 0;
        for (i = 0; i < data.vertex_count && ok; ++i)
            ok &= fprintf(f, "v %.7g %.7g %.7g\n", pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]) > 0;
        for (i = 0; i < data.vertex_count && ok; ++i)
            ok &= fprintf(f, "vn %.7g %.7g %.7g\n", data.normals[3 * i], data.normals[3 * i + 1], data.normals[3 * i + 2]) > 0;
        for (i = 0; i < data.face_count && ok; ++i) {
            ok &= fputc('f', f) != EOF;
            for (j = 0; j < data.face_sizes[i]; ++j) {
                int v = data.face_vertices[off + (size_t)j] + 1;
                ok &= fprintf(f, " %d//%d", v, v) > 0;
            }
            ok &= fputc('\n', f) != EOF;
            off += (size_t)data.face_sizes[i];
        }
        if (!ok) {
            fprintf(stderr, "surfblend: writing '%s' failed\n", o.outp);
            goto done;
        }
    }
    shade_summary("shade", &o, &data, ctx, o.outp);
    rc = 0;
done:
    rc = finish_output(f, o.outp, rc);
    sfb_mesh_data_free(&data);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return rc;
}

/* PNG bytes gathered in memory, so that a failed render leaves no file at all. */
typedef struct png_buf { unsigned char *data; size_t size, cap; int failed; } png_buf;

static void png_append(void *user, void *data, int size) {
    png_buf *b = (png_buf *)user;
    if (b->failed || size <= 0) return;
    if (b->size + (size_t)size > b->cap) {
        size_t nc = b->cap ? b->cap : 1 << 16;
        unsigned char *nd;
        while (nc < b->size + (size_t)size) nc *= 2;
        nd = (unsigned char *)realloc(b->data, nc);
        if (!nd) { b->failed = 1; return; }
        b->data = nd;
        b->cap = nc;
    }
    memcpy(b->data + b->size, data, (size_t)size);
    b->size += (size_t)size;
}

static int cmd_render(int argc, char **argv) {
    shade_opts o;
    int i, rc = 1, mode = SFB_RENDER_SHADED, modes = 0, normals = 2 /* 0 limit, 1 subdivided, 2 blended */, limit_pos = 1, edges = 0;
    long width = 640, height = 480;
    int view_set = 0, weights = SFB_MANIFOLD_WEIGHTS_HERMITE, have_rate = 0, have_tiles = 0;
    long rate = 16, tiles_u = 0, tiles_v = 0;
    const char *trim_path = NULL;
    unsigned char *texels = NULL;
    sfb_trim_mask mask;
    sfb_tess_data td;
    double yaw = 0.0, pitch = 0.0, zoom = 0.0, stripes = 0.0;
    sfb_context *ctx = NULL;
    sfb_mesh *mesh = NULL;
    sfb_surface *surf = NULL;
    sfb_mesh_data data;
    sfb_image img;
    sfb_render_config rcfg;
    sfb_result r;
    png_buf png;
    FILE *f = NULL;
    static const char *normal_names[3] = { "limit", "subdivided", "blended" };
    memset(&data, 0, sizeof data);
    memset(&td, 0, sizeof td);
    memset(&mask, 0, sizeof mask);
    memset(&img, 0, sizeof img);
    memset(&png, 0, sizeof png);
    shade_opts_init(&o, 3);
    for (i = 0; i < argc; ++i) {
        int sr = shade_arg(argc, argv, &i, &o);
        if (sr < 0) return -sr;
        if (sr) continue;
        if (strcmp(argv[i], "--normals") == 0) {
            if (++i >= argc) return usage("--normals needs limit, subdivided or blended");
            for (normals = 0; normals < 3 && strcmp(argv[i], normal_names[normals]) != 0; ++normals) {}
            if (normals == 3) return usage("--normals needs limit, subdivided or blended");
        } else if (strcmp(argv[i], "--positions") == 0) {
            if (++i >= argc) return usage("--positions needs refined or limit");
            if (strcmp(argv[i], "limit") == 0) limit_pos = 1;
            else if (strcmp(argv[i], "refined") == 0) limit_pos = 0;
            else return usage("--positions needs refined or limit");
        } else if (strcmp(argv[i], "--rate") == 0) {
            /* the range (1..1024) is the library's to check and report */
            if (++i >= argc || !parse_int(argv[i], -2147483647L, 2147483647L, &rate)) return usage("--rate needs a number");
            have_rate = 1;
        } else if (strcmp(argv[i], "--manifold-weights") == 0) {
            if (++i >= argc || !weights_from_name(argv[i], &weights)) return usage("--manifold-weights needs hermite or cinf");
        } else if (strcmp(argv[i], "--trim") == 0) {
            if (++i >= argc) return usage("--trim needs a PNG file");
            trim_path = argv[i];
        } else if (strcmp(argv[i], "--trim-tiles") == 0) {
            if (i + 2 >= argc || !parse_int(argv[i + 1], -2147483647L, 2147483647L, &tiles_u) ||
                !parse_int(argv[i + 2], -2147483647L, 2147483647L, &tiles_v))
                return usage("--trim-tiles needs two numbers U V");
            i += 2;
            have_tiles = 1;
        } else if (strcmp(argv[i], "--highlight") == 0) {
            mode = SFB_RENDER_HIGHLIGHT; ++modes;
        } else if (strcmp(argv[i], "--weights") == 0) {
            mode = SFB_RENDER_WEIGHTS; ++modes;
        } else if (strcmp(argv[i], "--normal-colors") == 0) {
            mode = SFB_RENDER_NORMALS; ++modes;
        } else if (strcmp(argv[i], "--edges") == 0) {
            edges = 1;
        } else if (strcmp(argv[i], "--size") == 0) {
            char *end;
            if (++i >= argc) return usage("--size needs WxH");
            width = strtol(argv[i], &end, 10);
            if (end == argv[i] || (*end != 'x' && *end != 'X')) return usage("--size needs WxH, e.g. 800x600");
            {
                const char *hs = end + 1;
                height = strtol(hs, &end, 10);
                if (end == hs || *end) return usage("--size needs WxH, e.g. 800x600");
            }
            /* the range (1..8192) is the library's to check and report */
            if (width < 1 || height < 1 || width > 1000000L || height > 1000000L) return usage("--size needs positive WxH");
        } else if (strcmp(argv[i], "--view") == 0) {
            char *end;
            if (++i >= argc) return usage("--view needs YAW,PITCH in degrees");
            yaw = strtod(argv[i], &end);
            if (end == argv[i] || *end != ',') return usage("--view needs YAW,PITCH in degrees, e.g. 30,20");
            {
                const char *ps = end + 1;
                pitch = strtod(ps, &end);
                if (end == ps || *end || !isfinite(yaw) || !isfinite(pitch)) return usage("--view needs YAW,PITCH in degrees, e.g. 30,20");
            }
            view_set = 1;
        } else if (strcmp(argv[i], "--zoom") == 0) {
            char *end;
            if (++i >= argc) return usage("--zoom needs a number > 0");
            zoom = strtod(argv[i], &end);
            if (end == argv[i] || *end || !(zoom > 0.0) || zoom > 1e6) return usage("--zoom needs a number > 0");
        } else if (strcmp(argv[i], "--stripes") == 0) {
            char *end;
            if (++i >= argc) return usage("--stripes needs a number > 0");
            stripes = strtod(argv[i], &end);
            if (end == argv[i] || *end || !(stripes > 0.0) || stripes > 1e5) return usage("--stripes needs a number in (0, 100000]");
        } else {
            int ur = common_arg(argc, argv, &i, "render", &o.backend, &o.outp, &o.in);
            if (ur) return ur;
        }
    }
    if (!o.in) return usage("render needs an input OBJ file");
    if (!o.outp) return usage("render needs -o OUT.png");
    if (modes > 1) return usage("render takes one of --highlight, --weights, --normal-colors");
    if (normals == 1) o.all_subdivided = 1;
    if (o.scheme != SFB_SCHEME_MANIFOLD_BLEND && (have_rate || trim_path))
        return usage("--rate and --trim belong to --scheme manifold (the subdivision schemes render their shaded refinement)");
    if (have_tiles && !trim_path) return usage("--trim-tiles needs --trim MASK.png");
    if (o.scheme == SFB_SCHEME_MANIFOLD_BLEND && mode == SFB_RENDER_WEIGHTS) return usage("--weights pictures belong to subdivision shading");
    if (trim_path) {
        texels = load_mask(trim_path, &mask.width, &mask.height);
        if (!texels) return 1;
        mask.texels = texels;
        mask.tiles_u = (int)tiles_u;
        mask.tiles_v = (int)tiles_v;
    }
    ctx = make_context(o.backend);
    if (!ctx) { stbi_image_free(texels); return 1; }
    if (o.scheme == SFB_SCHEME_MANIFOLD_BLEND) {
        /* the blending surface, tessellated (and trimmed): the triangles with their normals */
        sfb_tess_config tc = sfb_tess_config_init((int)(rate > 2147483647L ? 2147483647L : rate < -2147483647L ? -2147483647L : rate));
        mesh = load(ctx, o.in);
        if (!mesh) goto done;
        surf = make_patch_surface(ctx, mesh, o.in, o.scheme, weights);
        if (!surf) goto done;
        tc.trim = trim_path ? &mask : NULL;
        r = sfb_surface_tessellate(surf, &tc, &td);
        if (r != SFB_SUCCESS) {
            fprintf(stderr, "surfblend: %s: %s: %s\n", o.in, sfb_result_string(r), sfb_last_error(ctx));
            goto done;
        }
        data.vertex_count = td.vertex_count;
        data.face_count = td.triangle_count;
        data.face_vertex_count = 3 * td.triangle_count;
        data.positions = data.limit_positions = td.positions;
        data.normals = data.limit_normals = data.subdivided_normals = td.normals;
        data.face_vertices = td.triangles;
        data.face_sizes = (int *)malloc(sizeof(int) * ((size_t)td.triangle_count + 1));
        if (!data.face_sizes) { fprintf(stderr, "surfblend: out of memory\n"); goto done; }
        for (i = 0; i < td.triangle_count; ++i) data.face_sizes[i] = 3;
    } else if (!shade_mesh(ctx, &o, &mesh, &surf, &data)) goto done;
    rcfg = sfb_render_config_init(mode);
    rcfg.width = (int)(width > 2147483647L ? 2147483647L : width);
    rcfg.height = (int)(height > 2147483647L ? 2147483647L : height);
    rcfg.positions = limit_pos ? data.limit_positions : data.positions;
    rcfg.normals = normals == 0 ? data.limit_normals : normals == 1 ? data.subdivided_normals : data.normals;
    rcfg.scalars = data.blend_weights;
    rcfg.view_set = view_set;
    rcfg.yaw = (float)yaw;
    rcfg.pitch = (float)pitch;
    rcfg.zoom = (float)zoom;
    rcfg.stripes = (float)stripes;
    rcfg.draw_edges = edges;
    if (!rcfg.positions || (mode != SFB_RENDER_WEIGHTS && !rcfg.normals) || (mode == SFB_RENDER_WEIGHTS && !rcfg.scalars)) {
        fprintf(stderr, "surfblend: %s: the shaded mesh lacks the %s\n", o.in,
                !rcfg.positions ? "positions" : mode == SFB_RENDER_WEIGHTS ? "blend weights" : "normals");
        goto done;
    }
    r = sfb_render(ctx, &data, &rcfg, &img);
    if (r != SFB_SUCCESS) {
        fprintf(stderr, "surfblend: %s: %s: %s\n", o.in, sfb_result_string(r), sfb_last_error(ctx));
        goto done;
    }
    if (!stbi_write_png_to_func(png_append, &png, img.width, img.height, 4, img.rgba, img.width * 4) || png.failed) {
        fprintf(stderr, "surfblend: encoding the PNG failed (out of memory)\n");
        goto done;
    }
    f = strcmp(o.outp, "-") == 0 ? stdout : fopen(o.outp, "wb");
    if (!f) {
        fprintf(stderr, "surfblend: cannot write '%s'\n", o.outp);
        goto done;
    }
    if (fwrite(png.data, 1, png.size, f) != png.size) {
        fprintf(stderr, "surfblend: writing '%s' failed\n", o.outp);
        goto done;
    }
    {
        static const char *mode_names[4] = { "shading", "highlight lines", "blend weights", "normal colours" };
        char what[256], field[64] = "";
        if (mode != SFB_RENDER_WEIGHTS && o.scheme != SFB_SCHEME_MANIFOLD_BLEND) snprintf(field, sizeof field, " of the %s normals", normal_names[normals]);
        snprintf(what, sizeof what, "render %s%s, %dx%d (%d object pixels%s):", mode_names[mode], field, img.width, img.height,
                 img.object_pixels, img.skipped_faces ? ", faces with non-finite positions skipped" : "");
        if (o.scheme == SFB_SCHEME_MANIFOLD_BLEND)
            fprintf(stderr, "surfblend: %s manifold blend (%s weights) tessellated at rate %ld%s: %d triangles -> %s (backend %s)\n", what,
                    weights ? "C-infinity" : "Hermite", rate, trim_path ? ", trimmed" : "", td.triangle_count, o.outp, sfb_context_backend_name(ctx));
        else shade_summary(what, &o, &data, ctx, o.outp);
    }
    rc = 0;
done:
    rc = finish_output(f, o.outp, rc);
    free(png.data);
    sfb_image_free(&img);
    if (o.scheme == SFB_SCHEME_MANIFOLD_BLEND) { free(data.face_sizes); memset(&data, 0, sizeof data); }
    sfb_tess_data_free(&td);
    stbi_image_free(texels);
    sfb_mesh_data_free(&data);
    sfb_surface_destroy(surf);
    sfb_mesh_destroy(mesh);
    sfb_context_destroy(ctx);
    return rc;
}

/* Probes every backend on its own: available with what it runs on, or why not. */
static int cmd_backends(void) {
    int k;
    const char *env = getenv("SURFBLEND_BACKEND");
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

int main(int argc, char **argv) {
    if (argc < 2) return usage("missing command");
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        print_usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("surfblend %d.%d.%d\n", SFB_VERSION_MAJOR, SFB_VERSION_MINOR, SFB_VERSION_PATCH);
        return 0;
    }
    if (strcmp(argv[1], "info") == 0) return cmd_info(argc - 2, argv + 2);
    if (strcmp(argv[1], "refine") == 0) return cmd_refine(argc - 2, argv + 2);
    if (strcmp(argv[1], "eval") == 0) return cmd_eval(argc - 2, argv + 2);
    if (strcmp(argv[1], "tess") == 0) return cmd_tess(argc - 2, argv + 2);
    if (strcmp(argv[1], "shade") == 0) return cmd_shade(argc - 2, argv + 2);
    if (strcmp(argv[1], "render") == 0) return cmd_render(argc - 2, argv + 2);
    if (strcmp(argv[1], "backends") == 0) return argc == 2 ? cmd_backends() : usage("backends takes no arguments");
    fprintf(stderr, "surfblend: unknown command '%s'\n", argv[1]);
    return usage(NULL);
}
