/* The one translation unit that compiles the library's implementation. */
#define SURFBLEND_IMPLEMENTATION
#include "surfblend.h"
