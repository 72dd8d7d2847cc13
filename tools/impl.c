/* The one translation unit that compiles the library's implementation, with every optional
 * backend (simd, gl, osmesa); programs built on it link with -lm -lpthread -ldl only. */
#define _DEFAULT_SOURCE /* madvise for huge pages (src/sfb_internal.h); before any system header */
#define SURFBLEND_IMPLEMENTATION
#define SURFBLEND_ALL_BACKENDS
#include "surfblend.h"
