#!/bin/bash
# The simd backend's NEON kernels, for real: tests/agree.c cross-compiled for AArch64 with the
# simd backend alone and run under qemu-aarch64 user emulation, simd against ref on the peer
# shapes, random creased meshes, buffer layouts and threads; and tests/analysis_kernels.c (seed 003's
# shade and raster kernels) the same way. Closing line: "N passed, N failed, N skipped".
set -u
BUILD=${BUILD:-build}
SHAPES=${SHAPES:-../shared/peers/opensubdiv-shapes}
out=$BUILD/neon
mkdir -p "$out"
printf '#define SURFBLEND_IMPLEMENTATION\n#define SURFBLEND_SIMD\n#include "surfblend.h"\n' > "$out/impl.c"
if ! aarch64-linux-gnu-gcc -std=c99 -O2 -Wall -Wextra -pedantic -Werror -static -I. "$out/impl.c" tests/agree.c \
     -o "$out/agree" -lm -lpthread; then
  echo "FAIL the library and tests/agree.c do not build for AArch64"; echo "0 passed, 1 failed, 0 skipped"; exit 1
fi
log=$(SFB_REQUIRE_BACKENDS=simd qemu-aarch64-static "$out/agree" "$SHAPES" --only simd --cases 12 2>&1); rc=$?
echo "$log" | grep -E "^(FAIL|# simd)" | head -n 40
line=$(echo "$log" | grep -E "^[0-9]+ passed, [0-9]+ failed" | tail -n 1)
[ -n "$line" ] || { echo "$log" | tail -n 20; echo "0 passed, 1 failed, 0 skipped"; exit 1; }
p=$(echo "$line" | sed -E 's/^([0-9]+) passed.*/\1/'); f=$(echo "$line" | sed -E 's/.* ([0-9]+) failed.*/\1/')
s=$(echo "$line" | grep -oE "[0-9]+ skipped" | grep -oE "[0-9]+" || echo 0)
# the point of the run: the NEON kernels were the ones chosen
if echo "$log" | grep -q "^# simd: available: neon kernels"; then p=$((p + 1)); echo "ok simd ran its neon kernels"
else f=$((f + 1)); echo "FAIL simd did not choose its neon kernels"; fi
[ "$rc" -eq 0 ] || [ "$f" -gt 0 ] || { f=$((f + 1)); echo "FAIL agree exited $rc"; }
# seed 003's shade and raster kernels (tests/analysis_kernels.c): the neon vector pass, bit for bit with ref
if aarch64-linux-gnu-gcc -std=c99 -O2 -Wall -Wextra -pedantic -Werror -static -DANALYSIS_KERNELS_SIMD_ONLY -I. tests/analysis_kernels.c \
     -o "$out/analysis_kernels" -lm -lpthread; then
  klog=$(SURFBLEND_SIMD_ISA=neon qemu-aarch64-static "$out/analysis_kernels" 2>&1); krc=$?
  echo "$klog" | grep -E "^FAIL" | head -n 20
  kline=$(echo "$klog" | grep -E "^[0-9]+ passed, [0-9]+ failed" | tail -n 1)
  if [ -n "$kline" ] && [ "$krc" -eq 0 ] && echo "$klog" | grep -q "^# simd-neon/t1: neon kernels"; then
    p=$((p + $(echo "$kline" | sed -E 's/^([0-9]+) passed.*/\1/'))); echo "ok analysis_kernels ran the neon kernels: $kline"
  else f=$((f + 1)); echo "FAIL analysis_kernels on AArch64 (exit $krc): ${kline:-no summary}"; fi
else
  f=$((f + 1)); echo "FAIL tests/analysis_kernels.c does not build for AArch64"
fi
echo "$p passed, $f failed, $s skipped"
[ "$f" -eq 0 ]
