#!/bin/bash
# Runs every test suite and prints one closing line: "N passed, N failed, N skipped".
# Each suite reports its own counts; a suite that crashes or prints no counts is one failure.
# Independent suites run side by side, JOBS at a time (default: one per core); each suite's
# output goes to $BUILD/test-logs/NAME.log and its summary line, with its wall time, is printed
# in a fixed order once all have ended, then the total wall time and the slowest suite.
#
# SFB_TEST_PROFILE=sanitize (make asan): the suites that run library code only, on the shapes
# the caller passes (make asan passes a smaller set, tests/sanitize_shapes.txt); the checks that
# only compile (C99/C++ header, separate modules, install) or validate GLSL, and the web checks,
# are not run again there.
set -u
BUILD=${BUILD:-build}
SHAPES=${SHAPES:-../shared/peers/opensubdiv-shapes}
CC=${CC:-cc}
CXX=${CXX:-c++}
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
PROFILE=${SFB_TEST_PROFILE:-full}
LOG=$BUILD/test-logs
RES=$LOG/results
mkdir -p "$LOG"
rm -rf "$RES"; mkdir -p "$RES"
T0=$(date +%s.%N)
ORDER=()

now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }

# result NAME PASSED FAILED SKIPPED SECONDS [NOTE]: what the summary prints for a suite
result() { printf '%s %s %s %s %s\n' "$2" "$3" "$4" "$5" "${6:-}" > "$RES/$1.res"; }

# counts LOGFILE: "P F S" from the last "N passed, N failed[, N skipped]" line, or nothing
counts() {
  local line
  line=$(grep -E "^[0-9]+ passed, [0-9]+ failed" "$1" | tail -n 1)
  [ -n "$line" ] || return 1
  echo "$(echo "$line" | sed -E 's/^([0-9]+) passed.*/\1/') $(echo "$line" | sed -E 's/.* ([0-9]+) failed.*/\1/') \
$(echo "$line" | grep -oE "[0-9]+ skipped" | grep -oE "[0-9]+" || echo 0)"
}

# counted NAME COMMAND...: a suite that closes with "N passed, N failed[, N skipped]" (no such
# line: one failure; a non-zero exit with no failure counted: one more).
counted() {
  local name=$1; shift
  local t rc c p f s
  t=$(now)
  "$@" > "$LOG/$name.log" 2>&1; rc=$?
  if c=$(counts "$LOG/$name.log"); then
    read -r p f s <<< "$c"
    [ "$rc" -eq 0 ] || [ "$f" -gt 0 ] || f=$((f + 1))
    result "$name" "$p" "$f" "$s" "$(elapsed "$t")" "$([ "$rc" -ne 0 ] && echo "exit $rc")"
  else
    result "$name" 0 1 0 "$(elapsed "$t")" "no closing line (exit $rc)"
  fi
}

# single NAME COMMAND...: one check, passes iff the command exits 0
single() {
  local name=$1; shift
  local t rc
  t=$(now)
  "$@" > "$LOG/$name.log" 2>&1; rc=$?
  if [ "$rc" -eq 0 ]; then result "$name" 1 0 0 "$(elapsed "$t")"; else result "$name" 0 1 0 "$(elapsed "$t")" "exit $rc"; fi
}

# criterion NAME COMMAND...: a Criterion runner (its "Synthesis" line)
criterion() {
  local name=$1; shift
  local t rc syn p f
  t=$(now)
  "$@" > "$LOG/$name.log" 2>&1; rc=$?
  syn=$(grep -E "Synthesis: Tested:" "$LOG/$name.log" | tail -n 1 | sed 's/\x1b\[[0-9;]*m//g')
  if [ -n "$syn" ]; then
    p=$(echo "$syn" | sed -E 's/.*Passing: ([0-9]+).*/\1/'); f=$(echo "$syn" | sed -E 's/.*Failing: ([0-9]+).*/\1/')
    [ "$rc" -eq 0 ] || [ "$f" -gt 0 ] || f=$((f + 1))
    result "$name" "$p" "$f" 0 "$(elapsed "$t")"
  else
    result "$name" 0 1 0 "$(elapsed "$t")" "no Synthesis line (exit $rc)"
  fi
}

# skipped NAME WHY: a suite that cannot run here (counted as one skip, never as passed)
skipped() { ORDER+=("$1"); result "$1" 0 0 1 0 "$2"; }

# suite KIND NAME COMMAND...: queue it; at most JOBS run at once
suite() {
  local kind=$1 name=$2; shift 2
  ORDER+=("$name")
  while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do wait -n 2>/dev/null || true; done
  "$kind" "$name" "$@" &
}

HAVE_SHAPES=0; [ -d "$SHAPES" ] && HAVE_SHAPES=1
with_shapes() { if [ "$HAVE_SHAPES" = 1 ]; then echo "$SHAPES"; fi; }

# The slowest first, so that the pool stays full to the end.
# shade is the longest suite (it runs threads of its own: two halves side by side were slower)
suite counted shade "$BUILD/shade" $(with_shapes)
[ "$HAVE_SHAPES" = 1 ] && suite counted limit "$BUILD/limit" "$SHAPES" || skipped limit "peer shapes not found at $SHAPES"
[ "$HAVE_SHAPES" = 1 ] && suite counted osd_agree "$BUILD/osd_agree" "$SHAPES" || skipped osd_agree "peer shapes not found at $SHAPES"
suite counted manifold "$BUILD/manifold" $(with_shapes)
suite counted tribezier "$BUILD/tribezier" "$(dirname "$SHAPES")/real-meshes"
suite counted trim "$BUILD/trim" $(with_shapes)
suite counted analyze "$BUILD/analyze" "$SHAPES"
suite counted geom "$BUILD/geom"
suite counted fillet "$BUILD/fillet"
suite counted agree "$BUILD/agree" $(with_shapes)
suite counted gl_manifold "$BUILD/gl_manifold" "$SHAPES"
suite counted cli env BUILD="$BUILD" SHAPES="$SHAPES" ./tests/cli_test.sh
# the glTF export tool: usage, bad input, the Khronos validator, read back against the library
suite counted gltf env BUILD="$BUILD" SHAPES="$SHAPES" ./tests/gltf_test.sh
suite criterion unit "$BUILD/unit" --jobs 1
suite counted finish_normals "$BUILD/finish_normals"
suite counted analysis_kernels "$BUILD/analysis_kernels"
suite counted eigen "$BUILD/eigen"
# the engine case: the gl backend on the host's own EGL context and GL buffers
suite counted gl_host "$BUILD/gl_host"
# failure paths of the gl/osmesa backends (broken kernel, missing libOSMesa), table pieces
suite counted gl_errors "$BUILD/gl_errors"
suite counted gl_pieces "$BUILD/gl_pieces"
if [ "$PROFILE" != sanitize ]; then
  # the header compiles as C99 and as C++ (with the implementation), warnings as errors
  suite single compile-c99 $CC -std=c99 -pedantic -Wall -Wextra -Werror -c -x c tools/impl.c -I. -o "$LOG/impl_c99.o"
  suite single compile-cxx $CXX -std=c++11 -Wall -Wextra -Werror -c -x c++ tools/impl.c -I. -o "$LOG/impl_cxx.o"
  # the modules of src/ as separate translation units, linked with the examples (make check-modules)
  suite single check-modules env CC="$CC" CXX="$CXX" ./tools/check_modules.sh "$BUILD"
  # the GLSL kernels validated with glslangValidator, embedded copies up to date
  suite counted glsl bash tools/check_glsl.sh
  # the web checks (tests/web/): three.js in headless Chromium against the software renderer, the
  # glTF validator wrapper; skipped with the reason where Chromium, WebGL or the npm packages
  # are missing (make deps-web), failed instead with SFB_REQUIRE_WEB (CI)
  suite counted web_render env BUILD="$BUILD" SHAPES="$SHAPES" ./tests/web/render_test.sh
  suite counted web_validate env BUILD="$BUILD" ./tests/web/validate_test.sh
  # make install into temporary prefixes, a program built against it with pkg-config
  suite counted install env BUILD="$BUILD" CC="$CC" ./tests/install_test.sh
fi
# the engine example (examples/03_engine.cpp) on llvmpipe: its GL state checks, glGetError, and
# its last frame's silhouette against sfb_render's (IoU >= 0.98) (tests/engine_test.sh)
suite counted engine env BUILD="$BUILD" ./tests/engine_test.sh
# the examples build and run (those with a suite of their own above are run there)
for ex in "$BUILD"/examples/*; do
  case $(basename "$ex") in 03_engine) continue ;; esac
  [ -x "$ex" ] && suite single "example-$(basename "$ex")" "$ex"
done
wait

PASS=0; FAIL=0; SKIP=0; SLOW=""; SLOWT=0
for name in "${ORDER[@]}"; do
  read -r p f s t note < "$RES/$name.res" || { p=0; f=1; s=0; t=0; note="no result"; }
  printf '== %s: %s passed, %s failed, %s skipped (%s s)%s\n' "$name" "$p" "$f" "$s" "$t" "${note:+ [$note]}"
  if [ "$f" -gt 0 ] && [ -f "$LOG/$name.log" ]; then
    grep -E "^FAIL|^\[FAIL\]" "$LOG/$name.log" | head -n 20 | sed 's/^/   /'
    grep -qE "^FAIL|^\[FAIL\]" "$LOG/$name.log" || tail -n 15 "$LOG/$name.log" | sed 's/^/   /'
  fi
  [ -f "$LOG/$name.log" ] && grep -E "^SKIP " "$LOG/$name.log" | sed -E 's/^SKIP [^:]*: //' | sort | uniq -c | sort -rn | head -n 5 |
    sed -E 's/^ *([0-9]+) (.*)/   (\1 skipped: \2)/'
  PASS=$((PASS + p)); FAIL=$((FAIL + f)); SKIP=$((SKIP + s))
  if awk -v a="$t" -v b="$SLOWT" 'BEGIN { exit !(a > b) }'; then SLOW=$name; SLOWT=$t; fi
done
echo "suites: ${#ORDER[@]}, $JOBS at a time, $(elapsed "$T0") s in all; slowest: $SLOW ($SLOWT s)"
echo
echo "$PASS passed, $FAIL failed, $SKIP skipped"
[ "$FAIL" -eq 0 ]
