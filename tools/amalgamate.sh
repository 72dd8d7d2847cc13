#!/bin/sh
# Writes surfblend.h to stdout from src/: the public API, then the implementation guarded by
# SURFBLEND_IMPLEMENTATION. Usage: tools/amalgamate.sh > surfblend.h
set -e
cd "$(dirname "$0")/.."
MODULES="sfb_internal.h context.c pool.c backend.c backend_ref.c topology.c stencil.c refine.c patch/eigen.c patch/table.c patch/build.c patch/quad.c patch/tri.c patch/manifold.c patch/pn.c patch/tribezier.c tess.c mesh.c obj.c scheme.c surface.c shade.c render.c analyze.c aabb.c sparse.c trimesh.c fillet/fillet.c backends_include.c"
cat <<'HDR'
/* surfblend.h -- subdivision surfaces with sharp and semi-sharp creases, evaluated on
 * several backends. Single-header library: GENERATED from src/ by `make amalgamate`; edit
 * src/ instead.
 *
 * In exactly one C or C++ file:
 *     #define SURFBLEND_IMPLEMENTATION
 *     #include "surfblend.h"
 * Optional backends (code in backends/ beside this file): also define SURFBLEND_SIMD,
 * SURFBLEND_GL, SURFBLEND_OSMESA or SURFBLEND_ALL_BACKENDS there; link -lm -lpthread -ldl.
 */
#ifndef SURFBLEND_H
#define SURFBLEND_H
HDR
echo '#line 1 "src/sfb_api.h"'
cat src/sfb_api.h
echo '#endif /* SURFBLEND_H */'
echo
echo '#if defined(SURFBLEND_IMPLEMENTATION) && !defined(SURFBLEND_IMPLEMENTED)'
echo '#define SURFBLEND_IMPLEMENTED'
for m in $MODULES; do
  echo "#line 1 \"src/$m\""
  cat "src/$m"
done
echo '#endif /* SURFBLEND_IMPLEMENTATION */'
