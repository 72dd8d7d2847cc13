/* Prelude of a core module compiled as its own translation unit (`make check-modules`): the
 * public API and the declared internal interfaces, nothing else. The amalgamation (surfblend.h)
 * does not use this file; there every module sees exactly the same declarations. */
#define SURFBLEND_IMPLEMENTATION
#define SFB__SEPARATE_MODULES /* module interfaces get external linkage (src/sfb_internal.h, SFB__IF) */
#ifndef SURFBLEND_ALL_BACKENDS
#define SURFBLEND_ALL_BACKENDS
#endif
#include "sfb_api.h"
#include "sfb_internal.h"
