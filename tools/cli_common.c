/* What the command-line tools share: see tools/cli_common.h. C99 and C++14. */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L /* mkstemp, fdopen, fchmod, umask, stat */
#endif
#include "cli_common.h"
/* trimming masks (Debian libstb-dev), private to this file: the glTF tool links tinygltf, which
 * carries its own copy */
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_PNG
#if defined(__GNUC__)
/* the static copy leaves some of stb's API unused (reported at the end of the file) */
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include <stb/stb_image.h>

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#ifndef _WIN32
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>
#endif

const char *cli_program = "surfblend";

void cli_error(const char *fmt, ...) {
    va_list ap;
    fprintf(stderr, "%s: ", cli_program);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

char *cli_read_file(const char *path, size_t *size) {
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

sfb_context *cli_make_context(const char *backend) {
    sfb_progress none;
    none.func = NULL;
    none.user = NULL;
    return cli_make_context_progress(backend, none);
}

sfb_context *cli_make_context_progress(const char *backend, sfb_progress progress) {
    sfb_context_config cfg = sfb_context_config_init();
    sfb_backend_kind kinds[3];
    sfb_context *ctx = NULL;
    sfb_result r;
    const char *env = getenv("SURFBLEND_BACKEND");
    char report[2048];
    if (backend) {
        kinds[0] = sfb_backend_kind_parse(backend);
        if (kinds[0] == SFB_BACKEND_DEFAULT) {
            cli_error("unknown backend '%s' (ref, simd, gl, osmesa)", backend);
            return NULL;
        }
        kinds[1] = SFB_BACKEND_SIMD;
        kinds[2] = SFB_BACKEND_REF;
        cfg.backends = kinds;
        cfg.backend_count = 3;
        cfg.ignore_environment = 1;
    }
    cfg.progress = progress;
    r = sfb_context_create(&cfg, &ctx);
    if (r != SFB_SUCCESS) {
        cli_error("no backend could be initialised (%s)", sfb_result_string(r));
        return NULL;
    }
    if ((backend && sfb_backend_kind_parse(sfb_context_backend_name(ctx)) != kinds[0]) ||
        (!backend && env && *env && sfb_backend_kind_parse(sfb_context_backend_name(ctx)) != sfb_backend_kind_parse(env))) {
        sfb_context_backend_report(ctx, report, sizeof report);
        fprintf(stderr, "%s: the requested backend is unavailable; using %s. Backends tried:\n%s", cli_program,
                sfb_context_backend_name(ctx), report);
    }
    return ctx;
}

sfb_mesh *cli_load_obj(sfb_context *ctx, const char *path) {
    size_t size = 0;
    char *text = cli_read_file(path, &size);
    sfb_mesh *mesh = NULL;
    sfb_result r;
    if (!text) {
        cli_error("cannot read '%s'", path);
        return NULL;
    }
    r = sfb_mesh_read_obj(ctx, text, size, &mesh);
    free(text);
    if (r != SFB_SUCCESS) {
        cli_error("%s: %s: %s", path, sfb_result_string(r), sfb_last_error(ctx));
        return NULL;
    }
    return mesh;
}

sfb_mesh *cli_load_mesh(sfb_context *ctx, const char *path, double crease_angle, int triangulate) {
    sfb_mesh *mesh = cli_load_obj(ctx, path), *next = NULL;
    sfb_result r;
    int added = 0, split = 0;
    if (mesh && crease_angle >= 0.0) {
        r = sfb_mesh_crease_by_angle(ctx, mesh, (float)crease_angle, &next, &added);
        sfb_mesh_destroy(mesh);
        mesh = next;
        if (r != SFB_SUCCESS) {
            cli_error("%s: --crease-angle: %s: %s", path, sfb_result_string(r), sfb_last_error(ctx));
            return NULL;
        }
    }
    if (mesh && triangulate) {
        /* after the crease angle: the new diagonals are no features */
        r = sfb_mesh_triangulate(ctx, mesh, &next, &split);
        sfb_mesh_destroy(mesh);
        mesh = next;
        if (r != SFB_SUCCESS) {
            cli_error("%s: --triangulate: %s: %s", path, sfb_result_string(r), sfb_last_error(ctx));
            return NULL;
        }
    }
    return mesh;
}

int cli_scheme_from_name(const char *s, sfb_scheme *out) { return sfb_scheme_parse(s, out); }

sfb_scheme cli_scheme_for(const char *path, int have_scheme, sfb_scheme scheme) {
    const char *base;
    if (have_scheme) return scheme;
    base = strrchr(path, '/');
    base = base ? base + 1 : path;
    if (strncmp(base, "loop_", 5) == 0) return SFB_SCHEME_LOOP;
    if (strncmp(base, "bilinear_", 9) == 0) return SFB_SCHEME_BILINEAR;
    return SFB_SCHEME_CATMARK;
}

/* ---- atomic output ---- */

#ifndef _WIN32
/* The temporary files being written, removed when a signal that ends the program arrives before
 * they are finished (SIGINT, SIGTERM, SIGHUP, SIGQUIT, and SIGPIPE: `surfblend ... 2>&1 | head`
 * closes the pipe its summary line goes to): a killed command leaves no PATH.tmpXXXXXX behind.
 * The handler unlinks them (async-signal-safe), then the signal, its handler reset, ends the
 * program as it would have. Signals a caller set to be ignored (nohup) stay ignored. SIGKILL
 * cannot be caught. */
#define CLI_MAX_TEMPS 8
static char *volatile cli_temps[CLI_MAX_TEMPS];

static void cli_on_signal(int sig) {
    int i;
    for (i = 0; i < CLI_MAX_TEMPS; ++i) {
        char *t = cli_temps[i];
        if (t) unlink(t);
    }
    raise(sig); /* delivered, with the default action, once this handler returns */
}

static void cli_temp_track(char *name) {
    static int installed = 0;
    int i;
    if (!installed) {
        static const int sigs[5] = { SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE };
        for (i = 0; i < 5; ++i) {
            struct sigaction old, sa;
            if (sigaction(sigs[i], NULL, &old) != 0 || old.sa_handler != SIG_DFL) continue;
            memset(&sa, 0, sizeof sa);
            sa.sa_handler = cli_on_signal;
            sigemptyset(&sa.sa_mask);
            sa.sa_flags = SA_RESETHAND;
            (void)sigaction(sigs[i], &sa, NULL);
        }
        installed = 1;
    }
    for (i = 0; i < CLI_MAX_TEMPS; ++i)
        if (!cli_temps[i]) { cli_temps[i] = name; return; }
}

static void cli_temp_untrack(const char *name) {
    int i;
    for (i = 0; i < CLI_MAX_TEMPS; ++i)
        if (cli_temps[i] == name) cli_temps[i] = NULL;
}
#endif

/* A temporary file beside `path`, created new (PATH.tmpXXXXXX, with the permissions a plain
 * fopen would give); NULL on failure, errno set. */
static FILE *open_temporary(const char *path, char **tmp_name) {
    size_t n = strlen(path);
    char *name = (char *)malloc(n + 12);
    FILE *f = NULL;
    if (!name) { errno = ENOMEM; return NULL; }
    memcpy(name, path, n);
#ifdef _WIN32
    memcpy(name + n, ".tmp", 5);
    f = fopen(name, "wb");
#else
    memcpy(name + n, ".tmpXXXXXX", 11);
    {
        int fd = mkstemp(name);
        if (fd >= 0) {
            mode_t mask = umask(0);
            umask(mask);
            (void)fchmod(fd, (mode_t)(0666 & ~mask));
            f = fdopen(fd, "wb");
            if (!f) {
                int e = errno;
                close(fd);
                remove(name);
                errno = e;
            }
        }
    }
#endif
    if (!f) { free(name); return NULL; }
#ifndef _WIN32
    cli_temp_track(name);
#endif
    *tmp_name = name;
    return f;
}

/* Whether `path` names something that exists and is not a regular file (a device, a pipe). */
static int is_special(const char *path) {
#ifdef _WIN32
    (void)path;
    return 0;
#else
    struct stat st;
    return stat(path, &st) == 0 && !S_ISREG(st.st_mode);
#endif
}

FILE *cli_output_open(cli_output *out, const char *path) {
    out->f = NULL;
    out->tmp = NULL;
    out->path = path && strcmp(path, "-") != 0 ? path : NULL;
    if (!out->path) out->f = stdout;
    else if (is_special(path)) out->f = fopen(path, "wb");
    else out->f = open_temporary(path, &out->tmp);
    if (!out->f) cli_error("cannot write '%s': %s", path, strerror(errno));
    return out->f;
}

int cli_output_finish(cli_output *out, int rc) {
    FILE *f = out->f;
    const char *shown = out->path ? out->path : "the output";
    if (!f) return rc;
    out->f = NULL;
    if (f == stdout) {
        if ((fflush(stdout) != 0 || ferror(stdout)) && rc == 0) { cli_error("writing the output failed"); rc = 1; }
        return rc;
    }
    if (rc == 0 && (fflush(f) != 0 || ferror(f))) { cli_error("writing '%s' failed: %s", shown, strerror(errno)); rc = 1; }
    if (fclose(f) != 0 && rc == 0) { cli_error("writing '%s' failed: %s", shown, strerror(errno)); rc = 1; }
    if (out->tmp) {
#ifdef _WIN32
        if (rc == 0) remove(out->path);
#endif
        if (rc == 0 && rename(out->tmp, out->path) != 0) { cli_error("cannot write '%s': %s", out->path, strerror(errno)); rc = 1; }
        if (rc != 0) remove(out->tmp);
#ifndef _WIN32
        cli_temp_untrack(out->tmp); /* after the rename: a signal before it still removes the file */
#endif
        free(out->tmp);
        out->tmp = NULL;
    }
    return rc;
}

int cli_write_file(const char *path, const void *data, size_t size) {
    cli_output out;
    int rc;
    if (!cli_output_open(&out, path)) return 1;
    rc = fwrite(data, 1, size, out.f) != size;
    if (rc) cli_error("writing '%s' failed: %s", path, strerror(errno));
    return cli_output_finish(&out, rc);
}

int cli_file_write(const void *data, size_t size, void *user) {
    return fwrite(data, 1, size, (FILE *)user) != size;
}

/* A PNG with `channels` bytes per texel, rows flipped (the picture's top row last). */
static int load_png_flipped(const char *path, int channels, const char *what, unsigned char **texels, int *w, int *h) {
    int n = 0, j;
    size_t row;
    unsigned char *px, *tmp, *copy;
    *texels = NULL;
    px = stbi_load(path, w, h, &n, channels);
    if (!px) {
        cli_error("cannot read the %s '%s': %s", what, path, stbi_failure_reason());
        return 0;
    }
    row = (size_t)*w * (size_t)channels;
    tmp = (unsigned char *)malloc(row ? row : 1);
    copy = (unsigned char *)malloc(row * (size_t)*h > 0 ? row * (size_t)*h : 1);
    if (!tmp || !copy) {
        cli_error("out of memory reading '%s'", path);
        free(tmp);
        free(copy);
        stbi_image_free(px);
        return 0;
    }
    for (j = 0; j < *h / 2; ++j) {
        unsigned char *a = px + (size_t)j * row, *b = px + (size_t)(*h - 1 - j) * row;
        memcpy(tmp, a, row);
        memcpy(a, b, row);
        memcpy(b, tmp, row);
    }
    memcpy(copy, px, row * (size_t)*h);
    free(tmp);
    stbi_image_free(px);
    *texels = copy;
    return 1;
}

int cli_load_mask(const char *path, unsigned char **texels, int *w, int *h) {
    return load_png_flipped(path, 1, "trimming mask", texels, w, h);
}

int cli_load_rgba(const char *path, unsigned char **texels, int *w, int *h) {
    return load_png_flipped(path, 4, "light image", texels, w, h);
}
