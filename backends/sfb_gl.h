/* backends/sfb_gl.h -- the `gl` backend: the kernels as OpenGL 4.3 / GLES 3.1 compute shaders
 * over shader storage buffers.
 *
 * Compiled by surfblend.h's implementation when SURFBLEND_GL (or SURFBLEND_OSMESA,
 * SURFBLEND_ALL_BACKENDS) is defined next to SURFBLEND_IMPLEMENTATION; do not include it
 * directly. It sees the core's private declarations (src/sfb_internal.h).
 *
 * Two ways in:
 *  - own context (default): a headless context made through EGL -- the device platform
 *    first (GPUs without a display server), then Mesa's surfaceless platform, then the
 *    default display. It is made current for the length of each call and the thread's
 *    previous EGL context (and bound API) is restored afterwards.
 *  - the host's context (sfb_context_config.gl_use_current_context): the engine case. The
 *    host's EGL or GLX context must be current on the calling thread for every call, from
 *    sfb_context_create to sfb_context_destroy. What a call binds (program, generic and
 *    indexed SSBO bindings 0..5; for manifold tables also texture units 0..2 with their
 *    samplers, the active unit and the pixel unpack state) is saved first and restored after,
 *    and sfb_surface_eval_stencils_gl writes straight into the host's buffer objects. Here
 *    alone sfb_surface_draw_gl draws manifold blending surfaces (seed 000's vertex and
 *    fragment programs) into the host's framebuffer.
 *
 * Patch tables: Catmull-Clark and Loop tables as storage buffers in pieces (patches.comp.glsl);
 * MANIFOLD4 tables (seed 000) as two textures, the seed's Fig. 8 coefficient texture and an
 * integer one of face and patch records, read by manifold.comp.glsl's compute stage
 * (sfb_surface_eval) and its vertex stage (the draw path) alike.
 *
 * GL, EGL (and, in sfb_osmesa.h, OSMesa) are loaded at run time with dlopen, reusing a
 * library the process already loaded; nothing links -lGL or -lEGL. Types and constants are
 * declared in gl/api.h so no GL header is needed to build. Shaders are the .glsl files in
 * backends/gl/glsl, embedded into gl/shaders.h by `make embed-glsl`.
 *
 * The backend is cut by kernel family, one file each under backends/gl/, and this header
 * includes them in order:
 *   gl/api.h       GL and EGL types, constants and entry-point tables; the dlopen loader
 *   gl/sfb_gl.h    the runtime: the backend state, EGL/GLX contexts, state save and restore,
 *                  shader compilation, device buffers, init/shutdown/describe
 *   gl/stencils.h  stencil tables (stencils.comp.glsl)
 *   gl/patches.h   polynomial patch tables, quad and triangle families (patches.comp.glsl)
 *   gl/manifold.h  MANIFOLD4 tables (seed 000; manifold.comp.glsl's compute stage)
 *   gl/normals.h   seed 001's normal blend, finish_normals (normals.comp.glsl)
 *   gl/shade.h     seed 003's per-pixel analysis values, shade (shade.comp.glsl)
 *   gl/draw.h      sfb_surface_draw_gl and sfb_gl_trim_texture (manifold.comp.glsl's vertex stage)
 *   gl/raster.h    seed 003's proxy raster into an offscreen framebuffer, raster (raster.{vert,frag}.glsl)
 *   gl/vtable.h    patch-table slots dispatched by the table's families; sfb__gl_bind
 * backends/sfb_osmesa.h runs the same kernels in an OSMesa context.
 */
#ifndef SFB__GL_H
#define SFB__GL_H

#include "gl/sfb_gl.h"
#include "gl/stencils.h"
#include "gl/manifold.h"
#include "gl/patches.h"
#include "gl/normals.h"
#include "gl/shade.h"
#include "gl/draw.h"
#include "gl/raster.h"
#include "gl/vtable.h"

#endif /* SFB__GL_H */
