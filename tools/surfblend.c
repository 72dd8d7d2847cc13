/* surfblend command-line tool.
 *   surfblend info in.obj
 *   surfblend refine [--scheme catmark|loop|bilinear] [--level L] [--limit] [--backend NAME] in.obj -o out.obj
 *   surfblend eval [--scheme catmark|loop] [--backend NAME] (--random N [--seed S] | --locations FILE) [--derivatives] [-o OUT] in.obj
 *   surfblend tess [--scheme catmark|loop] [--backend NAME] --rate N [--tolerance T] [--split-creases] in.obj -o out.obj
 *   surfblend backends
 * Exit codes: 0 success, 1 bad input (message on stderr), 2 usage error. */
#include "surfblend.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *usage_text =
    "usage:\n"
    "  surfblend info IN.obj                      counts, valences, creases, extraordinary vertices, problems\n"
    "  surfblend refine [options] IN.obj -o OUT.obj\n"
    "      --scheme catmark|loop|bilinear   subdivision scheme (default: from the file name prefix, else catmark)\n"
    "      --level L                        uniform refinement level 0..10 (default 2)\n"
    "      --limit                          write limit positions (and limit normals as vn) instead of refined points\n"
    "      --backend NAME                   ref|simd|gl|osmesa, tried first (else SURFBLEND_BACKEND, else the default order)\n"
    "  surfblend eval [options] IN.obj            the limit surface at parametric locations\n"
    "      --scheme catmark|loop            as for refine (default: from the file name prefix, else catmark)\n"
    "      --locations FILE                 lines 'face u v' (parametric face; u, v in [0,1], and u + v <= 1 on Loop's\n"
    "                                       triangles; '#' starts a comment)\n"
    "      --random N [--seed S]            N random locations on faces that are not holes (deterministic for a seed)\n"
    "      --derivatives                    also print du and dv\n"
    "      -o OUT                           write to OUT instead of stdout\n"
    "      --backend NAME                   as for refine\n"
    "    prints one line per location: face u v px py pz nx ny nz [dux duy duz dvx dvy dvz]\n"
    "  surfblend tess [options] IN.obj -o OUT.obj   watertight triangles of the limit surface (v, vn, f v//vn)\n"
    "      --scheme catmark|loop            as for refine\n"
    "      --rate N                         segments per parametric-face edge, 1..1024 (required)\n"
    "      --tolerance T                    adaptive: per face the smallest rate <= N within chordal error T\n"
    "      --split-creases                  separate vertices (and normals) on each side of infinitely sharp creases\n"
    "      --backend NAME                   as for refine\n"
    "  surfblend backends                         list the backends and whether each is available\n"
    "  surfblend --help | --version\n"
    "exit codes: 0 success, 1 bad input, 2 usage error\n";

static int usage(const char *msg) {
    if (msg) fprintf(stderr, "surfblend: %s\n", msg);
    fputs(usage_text, stderr);
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
static sfb_surface *make_patch_surface(sfb_context *ctx, const sfb_mesh *mesh, const char *path, sfb_scheme scheme) {
    sfb_surface_config cfg = sfb_surface_config_init(scheme, 0);
    sfb_surface *surf = NULL;
    sfb_result r;
    cfg.flags = SFB_REFINE_PATCHES;
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
    int derivs = 0, i, rc = 1, have_scheme = 0;
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
        } else if (strcmp(argv[i], "--scheme") == 0) {
            if (++i >= argc || !scheme_from_name(argv[i], &scheme)) return usage("--scheme needs catmark or loop");
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
    surf = make_patch_surface(ctx, mesh, in, scheme);
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

static int cmd_tess(int argc, char **argv) {
    const char *in = NULL, *outp = NULL, *backend = NULL;
    long rate = -1;
    double tolerance = 0.0;
    int split = 0, i, rc = 1, have_scheme = 0;
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
            if (++i >= argc || !scheme_from_name(argv[i], &scheme)) return usage("--scheme needs catmark or loop");
            have_scheme = 1;
        } else {
            int ur = common_arg(argc, argv, &i, "tess", &backend, &outp, &in);
            if (ur) return ur;
        }
    }
    if (!in) return usage("tess needs an input OBJ file");
    if (!outp) return usage("tess needs -o OUT.obj");
    if (rate == -1) return usage("tess needs --rate N");
    ctx = make_context(backend);
    if (!ctx) return 1;
    mesh = load(ctx, in);
    if (!mesh) goto done;
    surf = make_patch_surface(ctx, mesh, in, scheme_for(in, have_scheme, scheme));
    if (!surf) goto done;
    tc = sfb_tess_config_init((int)rate);
    tc.tolerance = (float)tolerance;
    tc.flags = split ? (unsigned)SFB_TESS_SPLIT_CREASES : 0u;
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
    fprintf(f, "# surfblend tess of %s: rate %ld%s%s, %d vertices, %d triangles\n", in, rate, tolerance > 0.0 ? " adaptive" : "",
            split ? " split creases" : "", td.vertex_count, td.triangle_count);
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
        fprintf(stderr, "surfblend: tess rate %ld%s: %d vertices, %d triangles, %ld edges (%ld closed, %ld boundary%s) -> %s (backend %s)\n",
                rate, tolerance > 0.0 ? " adaptive" : "", td.vertex_count, td.triangle_count, total, closed, boundary,
                more ? ", some non-manifold" : "", outp, sfb_context_backend_name(ctx));
    }
    rc = 0;
done:
    if (f && f != stdout && fclose(f) != 0 && rc == 0) { fprintf(stderr, "surfblend: writing '%s' failed\n", outp); rc = 1; }
    sfb_tess_data_free(&td);
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
        fputs(usage_text, stdout);
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
    if (strcmp(argv[1], "backends") == 0) return argc == 2 ? cmd_backends() : usage("backends takes no arguments");
    fprintf(stderr, "surfblend: unknown command '%s'\n", argv[1]);
    return usage(NULL);
}
