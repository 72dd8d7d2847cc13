/* What the command-line tools share (tools/surfblend.c and the glTF export tool): reading a
 * whole file, a context with a backend chosen by name, an OBJ mesh from a path, a scheme from
 * its name, and output files written atomically. Compiles as C99 and as C++14 (the functions
 * have C linkage either way); link tools/cli_common.c with the library (tools/impl.c).
 *
 * Every function that fails prints why on stderr, prefixed with cli_program ("surfblend" unless
 * the tool sets it), and returns NULL or non-zero. */
#ifndef SFB_CLI_COMMON_H
#define SFB_CLI_COMMON_H

#include "surfblend.h"
#include <stddef.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The prefix of every message ("surfblend: ..."). */
extern const char *cli_program;

/* Prints "PROGRAM: " and the message (printf style) and a newline on stderr. */
void cli_error(const char *fmt, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* The whole of `path` ("-": standard input) in a malloc'd buffer (free it), its length in *size;
 * NULL when it cannot be read (nothing printed: the caller names the file). */
char *cli_read_file(const char *path, size_t *size);

/* A context. backend (NULL: none asked for) names the backend tried first (ref, simd, gl,
 * osmesa); when it cannot initialise, simd then ref follow and the reason is printed. Without
 * it the library's order applies (SURFBLEND_BACKEND first, when set; a forced backend that
 * did not start is reported the same way). NULL (message printed) for an unknown name or when
 * no backend starts. */
sfb_context *cli_make_context(const char *backend);

/* cli_make_context with the library's progress reports (and cancellation) going to `progress`. */
sfb_context *cli_make_context_progress(const char *backend, sfb_progress progress);

/* A trimming mask (sfb_trim_mask) from the PNG at `path`: one grey byte per texel, rows
 * flipped so that the picture's top row is v = 1 (the mask's row 0 is v = 0). 1 with *texels
 * (free it) and the size set, or 0 with a message printed. */
int cli_load_mask(const char *path, unsigned char **texels, int *w, int *h);
/* An RGBA light image the same way (4 bytes per texel, row 0 the picture's bottom row). */
int cli_load_rgba(const char *path, unsigned char **texels, int *w, int *h);

/* The OBJ file at `path` ("-": standard input) as a mesh; NULL with the reason printed. */
sfb_mesh *cli_load_obj(sfb_context *ctx, const char *path);

/* cli_load_obj, then (crease_angle >= 0, degrees) the edges whose dihedral angle is over it made
 * infinitely sharp creases (sfb_mesh_crease_by_angle): --crease-angle of every tool; then
 * (triangulate) every face of more than three corners split into triangles
 * (sfb_mesh_triangulate): --triangulate. */
sfb_mesh *cli_load_mesh(sfb_context *ctx, const char *path, double crease_angle, int triangulate);

/* catmark (or catmull-clark), loop, bilinear, manifold: 1 and *out set; 0 for another name. */
int cli_scheme_from_name(const char *name, sfb_scheme *out);

/* The scheme of an input: `scheme` when have_scheme, else from the file name's prefix (loop_,
 * bilinear_), else Catmull-Clark. */
sfb_scheme cli_scheme_for(const char *path, int have_scheme, sfb_scheme scheme);

/* An output file written atomically: into a temporary file beside `path`, renamed onto `path`
 * only when everything was written, so that a failed command leaves no partial file (and an
 * existing file at `path` untouched). "-" (or NULL) is standard output; a path that exists and
 * is not a regular file (/dev/null, a pipe) is written directly. */
typedef struct cli_output {
    FILE *f;          /* where to write; NULL until opened */
    const char *path; /* the final name; NULL for standard output */
    char *tmp;        /* the temporary file's name; NULL when written directly */
} cli_output;

/* Opens *out for `path`; returns out->f, or NULL with "cannot write 'PATH'" printed. */
FILE *cli_output_open(cli_output *out, const char *path);

/* Finishes *out for a command whose status so far is rc (0: all written): with rc == 0 it
 * flushes, closes and renames the temporary file onto the path; otherwise (or when that
 * fails) it removes the temporary file. Returns rc, or 1 when finishing failed (printed).
 * Does nothing (returns rc) when *out was never opened. */
int cli_output_finish(cli_output *out, int rc);

/* `size` bytes to `path` atomically (as cli_output); 0 on success, 1 on failure (printed). */
int cli_write_file(const char *path, const void *data, size_t size);

/* An sfb_write_fn writing to the FILE * in `user` (sfb_write_obj). */
int cli_file_write(const void *data, size_t size, void *user);

#ifdef __cplusplus
}
#endif

#endif
