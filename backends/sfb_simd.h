/* backends/sfb_simd.h -- the `simd` backend, kept at this path for readers and includers of
 * the old single file: its code is in backends/simd/ (sfb_simd.h: the runtime, then one file
 * per kernel family). Not a public header; surfblend.h compiles it under SURFBLEND_SIMD. */
#include "simd/sfb_simd.h"
