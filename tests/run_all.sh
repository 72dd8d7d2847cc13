#!/bin/bash
# Runs every test suite and prints one closing line: "N passed, N failed, N skipped".
# Each suite reports its own counts; a suite that crashes or prints no counts is one failure.
set -u
BUILD=${BUILD:-build}
SHAPES=${SHAPES:-../shared/peers/opensubdiv-shapes}
CC=${CC:-cc}
CXX=${CXX:-c++}
PASS=0; FAIL=0; SKIP=0
LOG=$BUILD/test-logs
mkdir -p "$LOG"

add_counts() { # name, passed, failed, skipped
  echo "== $1: $2 passed, $3 failed, $4 skipped"
  PASS=$((PASS + $2)); FAIL=$((FAIL + $3)); SKIP=$((SKIP + $4))
}

counted() { # name, command...: a suite that prints PASS/FAIL/SKIP lines and closes with
  # "N passed, N failed[, N skipped]"; adds its counts (no closing line: one failure; a non-zero
  # exit with no failure counted: one more). Shows FAIL lines, and SKIP lines grouped by reason.
  local name=$1; shift
  local out rc line p f s
  out=$("$@" 2>&1); rc=$?
  echo "$out" > "$LOG/$name.log"
  echo "$out" | grep -E "^FAIL " | head -n 40
  echo "$out" | grep -E "^SKIP " | sed -E 's/^SKIP [^:]*: //' | sort | uniq -c | sort -rn | head -n 8 |
    sed -E 's/^ *([0-9]+) (.*)/   (\1 skipped: \2)/'
  line=$(echo "$out" | grep -E "^[0-9]+ passed, [0-9]+ failed" | tail -n 1)
  if [ -n "$line" ]; then
    p=$(echo "$line" | sed -E 's/^([0-9]+) passed.*/\1/'); f=$(echo "$line" | sed -E 's/.* ([0-9]+) failed.*/\1/')
    s=$(echo "$line" | grep -oE "[0-9]+ skipped" | grep -oE "[0-9]+" || echo 0)
    add_counts "$name" "$p" "$f" "${s:-0}"
    [ "$rc" -eq 0 ] || [ "$f" -gt 0 ] || add_counts "$name-exit" 0 1 0
  else
    echo "--- $name printed no closing line (exit $rc); log tail:"; echo "$out" | tail -n 20
    add_counts "$name" 0 1 0
  fi
}

single() { # name, command...: one test, passes iff the command exits 0
  local name=$1; shift
  if "$@" > "$LOG/$name.log" 2>&1; then add_counts "$name" 1 0 0
  else echo "--- $name failed; log:"; tail -n 30 "$LOG/$name.log"; add_counts "$name" 0 1 0; fi
}

# 1. the header compiles as C99 and as C++ (with the implementation), warnings as errors
single compile-c99 $CC -std=c99 -pedantic -Wall -Wextra -Werror -c -x c tools/impl.c -I. -o "$LOG/impl_c99.o"
single compile-cxx $CXX -std=c++11 -Wall -Wextra -Werror -c -x c++ tools/impl.c -I. -o "$LOG/impl_cxx.o"

# 1b. the modules of src/ as separate translation units, linked with the examples (make check-modules)
single check-modules env CC="$CC" CXX="$CXX" ./tools/check_modules.sh "$BUILD"

# 2. unit tests (Criterion)
out=$("$BUILD/unit" --jobs 2 2>&1); rc=$?
echo "$out" > "$LOG/unit.log"
echo "$out" | grep -E "^\[(FAIL|----)\]|Synthesis" | tail -n 40
syn=$(echo "$out" | grep -E "Synthesis: Tested:" | tail -n 1 | sed 's/\x1b\[[0-9;]*m//g')
if [ -n "$syn" ]; then
  t=$(echo "$syn" | sed -E 's/.*Tested: ([0-9]+).*/\1/'); p=$(echo "$syn" | sed -E 's/.*Passing: ([0-9]+).*/\1/')
  f=$(echo "$syn" | sed -E 's/.*Failing: ([0-9]+).*/\1/'); c=$(echo "$syn" | sed -E 's/.*Crashing: ([0-9]+).*/\1/')
  add_counts unit "$p" "$((f))" 0
  [ "$rc" -eq 0 ] || [ "$f" -gt 0 ] || add_counts unit-exit 0 1 0
else
  echo "$out" | tail -n 20; add_counts unit 0 1 0
fi

# 3. agreement with OpenSubdiv 3.5 over the peer shapes
if [ -d "$SHAPES" ]; then
  out=$("$BUILD/osd_agree" "$SHAPES" 2>&1); rc=$?
  echo "$out" > "$LOG/osd_agree.log"
  echo "$out" | grep -vE "^PASS " | tail -n 40
  line=$(echo "$out" | grep -E "^[0-9]+ passed, [0-9]+ failed" | tail -n 1)
  if [ -n "$line" ]; then
    p=$(echo "$line" | sed -E 's/^([0-9]+) passed.*/\1/'); f=$(echo "$line" | sed -E 's/.* ([0-9]+) failed.*/\1/')
    s=$(echo "$line" | grep -oE "[0-9]+ skipped" | grep -oE "[0-9]+" || echo 0)
    add_counts osd_agree "$p" "$f" "${s:-0}"
    [ "$rc" -eq 0 ] || [ "$f" -gt 0 ] || add_counts osd_agree-exit 0 1 0
  else
    add_counts osd_agree 0 1 0
  fi
else
  echo "peer shapes not found at $SHAPES: OpenSubdiv agreement skipped"; add_counts osd_agree 0 0 1
fi

# 3b. every optional backend (simd, gl, osmesa) against ref: peer shapes, random creased meshes,
#     buffer layouts, threads. A backend listed in SFB_REQUIRE_BACKENDS (set by `make test` on CI)
#     fails its checks when unavailable instead of skipping them.
if [ -d "$SHAPES" ]; then counted agree "$BUILD/agree" "$SHAPES"
else echo "peer shapes not found at $SHAPES: agree runs without them"; counted agree "$BUILD/agree"; fi

# 3b''. the Stam eigen structures: tests/eigen.c
counted eigen "$BUILD/eigen"

# 3b'. limit evaluation on every backend (ref included): tests/limit.c
if [ -d "$SHAPES" ]; then counted limit "$BUILD/limit" "$SHAPES"
else echo "peer shapes not found at $SHAPES: limit evaluation suite skipped"; add_counts limit 0 0 1; fi

# 3b'''. subdivision shading on every backend: tests/shade.c; the finish_normals kernels: tests/finish_normals.c
if [ -d "$SHAPES" ]; then counted shade "$BUILD/shade" "$SHAPES"
else echo "peer shapes not found at $SHAPES: shade runs without them"; counted shade "$BUILD/shade"; fi
# 3b''''. trimmed tessellation on every backend: tests/trim.c (reads loop_cube.obj from the shapes when present)
if [ -d "$SHAPES" ]; then counted trim "$BUILD/trim" "$SHAPES"
else echo "peer shapes not found at $SHAPES: trim runs without them"; counted trim "$BUILD/trim"; fi
# manifold-based blending surfaces on every backend: tests/manifold.c
if [ -d "$SHAPES" ]; then counted manifold "$BUILD/manifold" "$SHAPES"
else echo "peer shapes not found at $SHAPES: manifold runs without them"; counted manifold "$BUILD/manifold"; fi
counted gl_manifold "$BUILD/gl_manifold" "$SHAPES"
counted finish_normals "$BUILD/finish_normals"

# 3c. the engine case: the gl backend on the host's own EGL context and GL buffers
counted gl_host "$BUILD/gl_host"

# 3d. failure paths of the gl/osmesa backends (broken kernel, missing libOSMesa)
counted gl_errors "$BUILD/gl_errors"
counted gl_pieces "$BUILD/gl_pieces"

# 3e. the GLSL kernels validated with glslangValidator, embedded copies up to date
[ -f tools/check_glsl.sh ] && counted glsl bash tools/check_glsl.sh

# 4. command-line tool
out=$(BUILD=$BUILD SHAPES=$SHAPES ./tests/cli_test.sh 2>&1)
echo "$out" > "$LOG/cli.log"
echo "$out" | grep -E "^(FAIL|SKIP)" | tail -n 20
line=$(echo "$out" | grep -E "^[0-9]+ passed, [0-9]+ failed" | tail -n 1)
if [ -n "$line" ]; then
  p=$(echo "$line" | sed -E 's/^([0-9]+) passed.*/\1/'); f=$(echo "$line" | sed -E 's/.* ([0-9]+) failed.*/\1/')
  s=$(echo "$line" | grep -oE "[0-9]+ skipped" | grep -oE "[0-9]+" || echo 0)
  add_counts cli "$p" "$f" "${s:-0}"
else
  echo "$out" | tail -n 20; add_counts cli 0 1 0
fi

# 5. examples build and run
for ex in "$BUILD"/examples/*; do
  [ -x "$ex" ] && single "example-$(basename "$ex")" "$ex"
done

echo
echo "$PASS passed, $FAIL failed, $SKIP skipped"
[ "$FAIL" -eq 0 ]
