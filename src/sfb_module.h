/* Prelude of a core module compiled as its own translation unit (`make check-modules`): the
 * public API and the declared internal interfaces, nothing else. The amalgamation (surfblend.h)
 * does not use this file; there every module sees exactly the same declarations. */
#define SURFBLEND_IMPLEMENTATION
#ifndef SURFBLEND_ALL_BACKENDS
#define SURFBLEND_ALL_BACKENDS
#endif
#include "sfb_api.h"
#include "sfb_internal.h"
