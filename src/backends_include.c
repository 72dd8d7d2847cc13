/* Optional backends: their code lives in backends/ beside surfblend.h and is compiled here,
 * after the core, when SURFBLEND_SIMD / SURFBLEND_GL / SURFBLEND_OSMESA (or
 * SURFBLEND_ALL_BACKENDS) are defined with SURFBLEND_IMPLEMENTATION (see sfb_internal.h). */
#ifdef SURFBLEND_SIMD
#include "backends/sfb_simd.h"
#endif
#ifdef SURFBLEND_GL
#include "backends/sfb_gl.h"
#endif
#ifdef SURFBLEND_OSMESA
#include "backends/sfb_osmesa.h"
#endif
