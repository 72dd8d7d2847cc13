/* surfblend command-line tool.
 *   surfblend info in.obj
 *   surfblend refine [--scheme catmark|loop|bilinear] [--level L] [--limit] [--backend NAME] in.obj -o out.obj
 *   surfblend backends
 * Exit codes: 0 success, 1 bad input (message on stderr), 2 usage error. */
#include "surfblend.h"
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
    "  surfblend backends                         list the backends and whether each is available\n"
    "  surfblend --help | --version\n"
    "exit codes: 0 success, 1 bad input, 2 usage error\n";

static int usage(const char *msg) {
    if (msg) fprintf(stderr, "surfblend: %s\n", msg);
    fputs(usage_text, stderr);
    return 2;
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

static int cmd_refine(int argc, char **argv) {
    const char *in = NULL, *outp = NULL, *backend = NULL, *base;
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
        } else if (strcmp(argv[i], "--backend") == 0) {
            if (++i >= argc) return usage("--backend needs a name");
            backend = argv[i];
        } else if (strcmp(argv[i], "-o") == 0 || strcmp(argv[i], "--output") == 0) {
            if (++i >= argc) return usage("-o needs a file name");
            outp = argv[i];
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "surfblend: unknown option '%s'\n", argv[i]);
            return usage(NULL);
        } else if (!in) {
            in = argv[i];
        } else {
            return usage("refine takes one input file");
        }
    }
    if (!in) return usage("refine needs an input OBJ file");
    if (!outp) return usage("refine needs -o OUT.obj");
    if (!have_scheme) {
        base = strrchr(in, '/');
        base = base ? base + 1 : in;
        if (strncmp(base, "loop_", 5) == 0) scheme = SFB_SCHEME_LOOP;
        else if (strncmp(base, "bilinear_", 9) == 0) scheme = SFB_SCHEME_BILINEAR;
    }
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
    if (strcmp(argv[1], "backends") == 0) return argc == 2 ? cmd_backends() : usage("backends takes no arguments");
    fprintf(stderr, "surfblend: unknown command '%s'\n", argv[1]);
    return usage(NULL);
}
