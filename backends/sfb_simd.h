/* backends/sfb_simd.h -- the `simd` backend: the kernels vectorised (portable, SSE2, AVX2+FMA,
 * AVX-512, NEON; chosen at init by CPU detection) over a small thread pool.
 *
 * Compiled by surfblend.h's implementation when SURFBLEND_SIMD (or SURFBLEND_ALL_BACKENDS) is
 * defined next to SURFBLEND_IMPLEMENTATION; do not include it directly. It sees the core's
 * private declarations (src/sfb_internal.h).
 *
 * The backend is cut by kernel family, one file each under backends/simd/, included here in
 * order (backends/simd/sfb_simd.h says what each holds):
 *   simd/sfb_simd.h   the runtime: ISA availability and detection, the thread pool, the vector
 *                     operations every family is written on, the state, init/shutdown/describe
 *   simd/stencils.h   eval_stencils
 *   simd/patches.h    the polynomial patch families (simd/patches_quad.h, simd/patches_tri.h)
 *   simd/manifold.h   MANIFOLD4 (seed 000)
 *   simd/normals.h    finish_normals (seed 001)
 *   simd/shade.h      shade (seed 003's per-pixel analysis values)
 *   simd/raster.h     raster (seed 003's proxy raster, in bands of rows over the threads)
 *   simd/vtable.h     patch slots dispatched by the table's families; sfb__simd_bind
 */
#ifndef SFB__SIMD_BACKEND_H
#define SFB__SIMD_BACKEND_H

#include "simd/sfb_simd.h"
#include "simd/stencils.h"
#include "simd/patches.h"
#include "simd/manifold.h"
#include "simd/normals.h"
#include "simd/shade.h"
#include "simd/raster.h"
#include "simd/vtable.h"

#endif /* SFB__SIMD_BACKEND_H */
