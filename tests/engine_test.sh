#!/bin/bash
# The engine example (examples/03_engine.cpp) on Mesa's llvmpipe: it animates 30 frames with
# the gl backend on its own EGL context, checking its GL state around every surfblend call and
# glGetError every frame itself (exit 1 on a failed check); here its last frame's silhouette is
# compared with the library's software render (sfb_render, same refined surface, same camera):
# intersection over union >= 0.98, measured by tests/png_iou.c on the two PNGs (alpha >= 128 is
# the object). A negative control renders the reference 10 degrees off and must fall below 0.98,
# so the comparison can fail. When no EGL / OpenGL 4.3 context can be made (the example exits
# 77) every run check is SKIP with the reason, or FAIL when SFB_REQUIRE_BACKENDS names gl.
# Prints "PASS name", "FAIL name: why", "SKIP name: why" and "N passed, N failed, N skipped".
# The pictures stay in $BUILD/test-logs/engine/ (with a composite: engine | sfb_render | difference).
set -u
BUILD=${BUILD:-build}
EX=$BUILD/examples/03_engine
IOU=$BUILD/png_iou
OUT=$BUILD/test-logs/engine
MIN_IOU=0.98
# the software rasteriser even where a GPU driver is installed (CI has none)
export LIBGL_ALWAYS_SOFTWARE=${LIBGL_ALWAYS_SOFTWARE-1}
# make asan (SFB_TEST_PROFILE=sanitize): AddressSanitizer and UBSan stay on, leak checking is off
# for the example. Mesa 22.3's llvmpipe (swrast_dri.so) keeps a few allocations of the vertex
# pipeline reachable only from its own globals; eglTerminate unloads the driver, so at exit
# LeakSanitizer reports them with frames in an unloaded module, which tests/lsan.supp cannot name
# (keeping the driver loaded makes the reports vanish). surfblend's own teardown on a host context
# is leak-checked by tests/gl_host.c and tests/gl_manifold.c.
if [ "${SFB_TEST_PROFILE:-full}" = sanitize ]; then export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"; fi
rm -rf "$OUT"; mkdir -p "$OUT"
P=0; F=0; S=0
pass() { P=$((P + 1)); echo "PASS $1"; }
fail() { F=$((F + 1)); echo "FAIL $1: $2"; }
skip() { S=$((S + 1)); echo "SKIP $1: $2"; }
required() { case ",${SFB_REQUIRE_BACKENDS:-}," in *,gl,*) return 0 ;; esac; return 1; }
close() { echo "$P passed, $F failed, $S skipped"; [ "$F" -eq 0 ]; }

for f in "$EX" "$IOU"; do
  [ -x "$f" ] || { fail "engine/build" "$f not built (make $f)"; close; exit 1; }
done

# usage
"$EX" --help > "$OUT/help.out" 2> "$OUT/help.err"; rc=$?
if [ $rc -eq 0 ] && [ ! -s "$OUT/help.err" ] && grep -q -- "--size WxH" "$OUT/help.out" && grep -q -- "--output" "$OUT/help.out"; then
  pass "engine/help"
else fail "engine/help" "exit $rc, or --size/--output missing from stdout"; fi
"$EX" --frobnicate > /dev/null 2> "$OUT/bad.err"; rc=$?
if [ $rc -eq 2 ] && grep -q "unknown option '--frobnicate'" "$OUT/bad.err"; then pass "engine/usage-error"
else fail "engine/usage-error" "exit $rc (want 2) or no message naming the option"; fi

# run NAME ARGS...: the example with its own checks (a failure is FAIL engine/NAME); 0 ran and
# passed, 1 failed, 77 cannot run here
SKIP_WHY=""
run() {
  local name=$1 rc; shift
  [ -n "$SKIP_WHY" ] && return 77
  "$EX" "$@" > "$OUT/$name.out" 2> "$OUT/$name.err"; rc=$?
  sed 's/^/# /' "$OUT/$name.out"
  if [ $rc -eq 77 ]; then
    SKIP_WHY=$(grep -m1 "cannot run here" "$OUT/$name.out" | sed 's/^03_engine: cannot run here: //')
    [ -n "$SKIP_WHY" ] || SKIP_WHY="the example exited 77"
    return 77
  fi
  if [ $rc -ne 0 ]; then
    fail "engine/$name" "exit $rc: $(grep -m3 'CHECK FAILED' "$OUT/$name.out" | tr '\n' ' ')$(head -c 300 "$OUT/$name.err")"
    return 1
  fi
  return 0
}
not_run() { # NAME: the check could not run
  if required; then fail "$1" "no GL context: $SKIP_WHY (gl required by SFB_REQUIRE_BACKENDS)"; else skip "$1" "$SKIP_WHY"; fi
}
# iou NAME A B: prints the IoU (empty when it cannot be measured)
iou() { "$IOU" "$2" "$3" --composite "$OUT/$1-composite.png" > "$OUT/$1.iou" 2>&1 && sed -n 's/^iou //p' "$OUT/$1.iou"; }
at_least() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a + 0 >= b + 0) }'; }

# 1. the default run: 640x480, 30 frames, the creased box at level 3, sfb_render's default view
run default -o "$OUT/engine.png" --reference "$OUT/reference.png"; rc=$?
if [ $rc -eq 77 ]; then
  for c in engine/default engine/frames engine/gl-state engine/png engine/iou engine/portrait engine/iou-discriminates; do not_run "$c"; done
  close; exit $?
fi
[ $rc -eq 0 ] && pass "engine/default"
n=$(grep -cE '^frame +[0-9]+: update [0-9.]+ ms' "$OUT/default.out")
if [ "$n" = 30 ]; then pass "engine/frames"; else fail "engine/frames" "$n per-frame update lines, want 30"; fi
if grep -q "CHECK FAILED" "$OUT/default.out"; then fail "engine/gl-state" "$(grep -m3 'CHECK FAILED' "$OUT/default.out" | tr '\n' ' ')"
elif grep -qE "surfblend calls on the engine's context; 0 checks failed" "$OUT/default.out"; then pass "engine/gl-state"
else fail "engine/gl-state" "no closing line of the example's checks"; fi
if [ $rc -eq 0 ]; then
  v=$(iou default "$OUT/engine.png" "$OUT/reference.png")
  if grep -q "^size 640x480$" "$OUT/default.iou"; then pass "engine/png"; else fail "engine/png" "$(head -n 2 "$OUT/default.iou" | tr '\n' ' ')"; fi
  echo "# silhouette IoU engine vs sfb_render: ${v:-none}"
  if [ -n "$v" ] && at_least "$v" "$MIN_IOU"; then pass "engine/iou"; else fail "engine/iou" "IoU ${v:-not measured} < $MIN_IOU ($OUT/default-composite.png)"; fi
else
  fail "engine/png" "the default run failed"; fail "engine/iou" "the default run failed"
fi

# 2. a portrait picture (the smaller side is the width), another view, zoomed out, 5 frames
run portrait --size 240x360 --view 120,-30 --zoom 0.8 --frames 5 -o "$OUT/portrait.png" --reference "$OUT/portrait-ref.png"; rc=$?
if [ $rc -eq 0 ]; then
  v=$(iou portrait "$OUT/portrait.png" "$OUT/portrait-ref.png")
  echo "# portrait IoU: ${v:-none}"
  if [ -n "$v" ] && at_least "$v" "$MIN_IOU"; then pass "engine/portrait"; else fail "engine/portrait" "IoU ${v:-not measured} < $MIN_IOU"; fi
elif [ $rc -eq 77 ]; then not_run "engine/portrait"; fi

# 3. the comparison can fail: the reference drawn 10 degrees off must not match
run iou-discriminates --frames 2 -o "$OUT/offset.png" --reference "$OUT/offset-ref.png" --reference-view 40,25; rc=$?
if [ $rc -eq 0 ]; then
  v=$(iou offset "$OUT/offset.png" "$OUT/offset-ref.png")
  echo "# IoU with the reference 10 degrees off: ${v:-none}"
  if [ -n "$v" ] && ! at_least "$v" "$MIN_IOU"; then pass "engine/iou-discriminates"
  else fail "engine/iou-discriminates" "IoU ${v:-not measured} with a wrong camera is not below $MIN_IOU"; fi
elif [ $rc -eq 77 ]; then not_run "engine/iou-discriminates"; fi
close
