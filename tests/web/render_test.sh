#!/bin/bash
# three.js in headless Chromium against the library's software renderer (tests/web/render.mjs,
# tests/web/png_iou.c), without any glTF exporter: a shaded OBJ from `surfblend shade` is drawn
# by `surfblend render` (the same refined mesh: --positions refined, same size and view) and by
# render.mjs through OBJLoader, and through GLTFLoader after tests/web/gltf_fixtures.mjs wrote it
# as .glb / .gltf (float, KHR_mesh_quantization, EXT_meshopt_compression); the silhouettes' IoU must be >= MIN_IOU,
# the counts three.js reports must be the OBJ's, the glTF files must validate, and a
# deliberately different view must fall well below (< BAD_IOU), so that the check can fail.
# sfb2gltf's own exports (plain, quantized, compressed, and --lods with MSFT_lod, of which the
# page must draw the most detailed LOD alone) are drawn and counted the same way, and its
# --sharpness-morph files (seed 004's slider as a morph target) at their default weights.
# Closes with "N passed, N failed, N skipped". Without node, the npm packages, Chromium or
# WebGL: skipped with the reason (failed instead when SFB_REQUIRE_WEB is set, as on CI).
set -u
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
SHAPES=${SHAPES:-../shared/peers/opensubdiv-shapes}
export SFB_NODE_DIR=${SFB_NODE_DIR:-$BUILD/node}
MIN_IOU=${MIN_IOU:-0.98}
BAD_IOU=${BAD_IOU:-0.90}
SFB=$BUILD/surfblend
IOU=$BUILD/web/png_iou
W=$BUILD/web/render; rm -rf "$W"; mkdir -p "$W"
P=0; F=0; S=0
pass() { P=$((P + 1)); echo "ok $1"; }
fail() { F=$((F + 1)); echo "FAIL $1"; }
skip() { S=$((S + 1)); echo "SKIP $1"; }
finish() { echo "$P passed, $F failed, $S skipped"; [ "$F" = 0 ]; exit; }
unavailable() { # the whole suite cannot run here
  if [ -n "${SFB_REQUIRE_WEB:-}" ]; then fail "web: $1 (SFB_REQUIRE_WEB is set)"; else skip "web: $1"; fi
  finish
}
for p in "$SFB" "$IOU"; do [ -x "$p" ] || { fail "$p not built (make $p)"; finish; }; done
command -v node > /dev/null || unavailable "node not found"

json() { node -e 'const r = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8")); console.log(r[process.argv[2]]);' "$1" "$2"; }
# iou A B: the IoU value alone (png_iou's line goes to the log)
iou() { "$IOU" "$1" "$2" > "$W/iou.log" 2>&1; cat "$W/iou.log" >&2; sed -nE 's/^iou ([0-9.]+).*/\1/p' "$W/iou.log"; }
ge() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && a + 0 >= b + 0) }'; }
add() { awk -v a="$1" -v b="$2" 'BEGIN { print a + b }'; }
mul() { awk -v a="$1" -v b="$2" 'BEGIN { print a * b }'; }

# Phase 1 writes every model and the library's pictures and queues render.mjs's jobs (one
# browser for all: $W/jobs.txt); phase 2 draws them; phase 3 compares.
JOBS=$W/jobs.txt; : > "$JOBS"
CHECKS=() # "KIND NAME JOB V T": KIND iou (>= MIN_IOU and counts) or wrong (< BAD_IOU)
job() { # NAME MODEL YAW PITCH ZOOM SIZE
  echo "--model $2 --out $W/$1.png --report $W/$1.json --yaw $3 --pitch $4 --zoom $5 --size $6" >> "$JOBS"
}
# can it run here at all? (no: the whole suite is skipped, with render.mjs's reason)
node tests/web/render.mjs --check > "$W/check.log" 2>&1; rc=$?
cat "$W/check.log"
[ "$rc" = 3 ] && unavailable "$(sed -n 's/^render.mjs: unavailable: //p' "$W/check.log" | head -n 1)"
[ "$rc" = 0 ] || { fail "render.mjs --check: exit $rc"; finish; }
# and where it cannot, it says so (exit 3: what this suite turns into a skip, never a pass)
printf '#!/bin/sh\nexec "%s" --disable-3d-apis "$@"\n' "${CHROMIUM:-/usr/bin/chromium}" > "$W/no-webgl.sh"; chmod +x "$W/no-webgl.sh"
node tests/web/render.mjs --check --chromium "$W/no-webgl.sh" > "$W/no-webgl.log" 2>&1; rc=$?
[ "$rc" = 3 ] && grep -q "WebGL is not available" "$W/no-webgl.log" && pass "without WebGL: exit 3, reason given" ||
  { fail "without WebGL: exit $rc"; cat "$W/no-webgl.log"; }
node tests/web/render.mjs --check --chromium "$W/absent-chromium" > "$W/no-chromium.log" 2>&1; rc=$?
[ "$rc" = 3 ] && grep -q "no Chromium at" "$W/no-chromium.log" && pass "without Chromium: exit 3, reason given" ||
  { fail "without Chromium: exit $rc"; cat "$W/no-chromium.log"; }
[ -f "$SFB_NODE_DIR/node_modules/gltf-validator/package.json" ] || unavailable "gltf-validator not installed under $SFB_NODE_DIR (make deps-web)"
node tests/web/gltf_fixtures.mjs "$W/fx" || { fail "fixtures"; finish; }
# the probe: a triangle that must cover most of its small picture, so WebGL really draws
job probe "$W/fx/tri.glb" 0 0 1 64x64

# prepare NAME SRC.obj LEVEL YAW PITCH ZOOM SIZE [FORMAT...]: one mesh's models and pictures.
# FORMAT: glb, gltf (with its .bin), glb:quantized (KHR_mesh_quantization), glb:meshopt (the
# same, its vertex attributes EXT_meshopt_compression-compressed: needs the MeshoptDecoder)
prepare() {
  local name=$1 src=$2 level=$3 yaw=$4 pitch=$5 zoom=$6 size=$7 obj v t g file opt; shift 7
  obj=$W/$name.obj
  "$SFB" shade --level "$level" "$src" -o "$obj" 2> "$W/$name.shade.log" || { fail "$name: surfblend shade"; cat "$W/$name.shade.log"; return; }
  "$SFB" render --level "$level" --positions refined --view "$yaw,$pitch" --zoom "$zoom" --size "$size" "$src" -o "$W/$name.sfb.png" \
    2> "$W/$name.render.log" || { fail "$name: surfblend render"; cat "$W/$name.render.log"; return; }
  v=$(grep -c '^v ' "$obj")
  t=$(awk '$1 == "f" { t += NF - 3 } END { print t + 0 }' "$obj")
  echo "$name: $v vertices, $t triangles (fanned faces) in $obj; view $yaw,$pitch zoom $zoom, $size"
  job "$name.obj" "$obj" "$yaw" "$pitch" "$zoom" "$size"; CHECKS+=("iou $name obj $v $t")
  # a deliberately different view must not pass
  job "$name.wrong" "$obj" "$(add "$yaw" 40)" "$(add "$pitch" -35)" "$(mul "$zoom" 1.25)" "$size"; CHECKS+=("wrong $name wrong $v $t")
  # the same mesh as glTF, written here (not by an exporter), validated, then drawn by GLTFLoader
  for g in "$@"; do
    file=$W/$name.${g%%:*}; opt=
    [ "${g#*:}" = quantized ] && { opt=--quantize; file=$W/$name.q.${g%%:*}; }
    [ "${g#*:}" = meshopt ] && { opt="--quantize --meshopt"; file=$W/$name.mq.${g%%:*}; }
    node tests/web/gltf_fixtures.mjs --obj "$obj" "$file" $opt || { fail "$name $g: written"; continue; }
    if node tests/web/validate.mjs "$file"; then pass "$name $g: validates"; else fail "$name $g: validates"; continue; fi
    job "$name.${g/:/_}" "$file" "$yaw" "$pitch" "$zoom" "$size"; CHECKS+=("iou $name ${g/:/_} $v $t")
  done
  # the same surface exported by sfb2gltf (shading normals, hard edges split, optimised): the
  # page must draw it as the software renderer does, with the counts sfb2gltf reports
  if [ -x "$BUILD/sfb2gltf" ]; then
    if "$BUILD/sfb2gltf" --level "$level" "$src" -o "$W/$name.sfb2gltf.glb" 2> "$W/$name.sfb2gltf.log"; then
      read -r gv gt <<< "$(sed -nE 's/.* ([0-9]+) vertices, ([0-9]+) triangles.*/\1 \2/p' "$W/$name.sfb2gltf.log")"
      if [ "$gt" = "$t" ]; then pass "$name sfb2gltf: $gt triangles, as the shaded mesh"; else fail "$name sfb2gltf: $gt triangles, the shaded mesh $t"; fi
      job "$name.sfb2gltf" "$W/$name.sfb2gltf.glb" "$yaw" "$pitch" "$zoom" "$size"; CHECKS+=("iou $name sfb2gltf $gv $gt")
      # quantized (KHR_mesh_quantization: integer positions under a dequantising node)
      if "$BUILD/sfb2gltf" -q --quantize --level "$level" "$src" -o "$W/$name.sfb2gltfq.glb" 2> "$W/$name.sfb2gltfq.log"; then
        job "$name.sfb2gltfq" "$W/$name.sfb2gltfq.glb" "$yaw" "$pitch" "$zoom" "$size"; CHECKS+=("iou $name sfb2gltfq $gv $gt")
      else
        fail "$name: sfb2gltf --quantize"; cat "$W/$name.sfb2gltfq.log"
      fi
      # quantized and compressed (EXT_meshopt_compression: three's MeshoptDecoder)
      if "$BUILD/sfb2gltf" -q --quantize --compress --level "$level" "$src" -o "$W/$name.sfb2gltfc.glb" 2> "$W/$name.sfb2gltfc.log"; then
        job "$name.sfb2gltfc" "$W/$name.sfb2gltfc.glb" "$yaw" "$pitch" "$zoom" "$size"; CHECKS+=("iou $name sfb2gltfc $gv $gt")
      else
        fail "$name: sfb2gltf --quantize --compress"; cat "$W/$name.sfb2gltfc.log"
      fi
      # --lods (listed out of order, quantized and compressed): the most detailed LOD is the one
      # in the scene, MSFT_lod names the others, which three.js does not read: the page must
      # draw this level alone, with its counts
      if "$BUILD/sfb2gltf" -q --lods "$((level - 1)),$level,0" --quantize --compress "$src" -o "$W/$name.sfb2gltfl.glb" 2> "$W/$name.sfb2gltfl.log"; then
        job "$name.sfb2gltfl" "$W/$name.sfb2gltfl.glb" "$yaw" "$pitch" "$zoom" "$size"; CHECKS+=("iou $name sfb2gltfl $gv $gt")
      else
        fail "$name: sfb2gltf --lods"; cat "$W/$name.sfb2gltfl.log"
      fi
    else
      fail "$name: sfb2gltf"; cat "$W/$name.sfb2gltf.log"
    fi
  fi
}
prepare creased_box examples/data/creased_box.obj 3 30 25 1 320x240 glb gltf glb:quantized glb:meshopt
if [ -d "$SHAPES" ]; then
  prepare catmark_car "$SHAPES/catmark_car.obj" 2 -60 20 1.1 240x320 glb
  prepare loop_toroidal_tet "$SHAPES/loop_toroidal_tet.obj" 3 15 40 1 300x300
else
  skip "catmark_car, loop_toroidal_tet: peer shapes not found at $SHAPES"
fi

# seed 004's sharpness slider as a glTF morph target (sfb2gltf --sharpness-morph: the base at s = 0,
# one target to s = 1, the mesh's default weight --sharpness S): three.js applies that weight, so
# the file written with S = 0 must draw as the library's surface at s = 0 and the one with S = 1
# as at s = 1 (the creased box cut into triangles: rounded at 0, boxy at 1); and the S = 1 file
# drawn against the s = 0 picture must fall below BAD_IOU, so the weight is seen to matter
if [ -x "$BUILD/sfb2gltf" ]; then
  for s in 0 1; do
    "$SFB" render --scheme tribezier --triangulate --sharpness $s --rate 8 --view 30,25 --size 320x240 examples/data/creased_box.obj \
      -o "$W/tbzmorph$s.sfb.png" 2> "$W/tbzmorph$s.render.log" || { fail "tbzmorph$s: surfblend render"; cat "$W/tbzmorph$s.render.log"; continue; }
    if "$BUILD/sfb2gltf" --scheme tribezier --triangulate --tess 8 --sharpness-morph --sharpness $s examples/data/creased_box.obj \
      -o "$W/tbzmorph$s.glb" 2> "$W/tbzmorph$s.sfb2gltf.log"; then
      read -r gv gt <<< "$(sed -nE 's/.* ([0-9]+) vertices, ([0-9]+) triangles.*/\1 \2/p' "$W/tbzmorph$s.sfb2gltf.log")"
      job "tbzmorph$s.morph" "$W/tbzmorph$s.glb" 30 25 1 320x240; CHECKS+=("iou tbzmorph$s morph $gv $gt")
    else
      fail "tbzmorph$s: sfb2gltf --sharpness-morph"; cat "$W/tbzmorph$s.sfb2gltf.log"
    fi
  done
  [ -f "$W/tbzmorph1.glb" ] && { job "tbzmorph0.weight1" "$W/tbzmorph1.glb" 30 25 1 320x240; CHECKS+=("wrong tbzmorph0 weight1 0 0"); }
  # quantized (KHR_mesh_quantization, the target in grid steps under the dequantising node)
  if "$BUILD/sfb2gltf" --scheme tribezier --triangulate --tess 8 --sharpness-morph --sharpness 1 --quantize examples/data/creased_box.obj \
    -o "$W/tbzmorph1q.glb" 2> "$W/tbzmorph1q.sfb2gltf.log"; then
    read -r gv gt <<< "$(sed -nE 's/.* ([0-9]+) vertices, ([0-9]+) triangles.*/\1 \2/p' "$W/tbzmorph1q.sfb2gltf.log")"
    job "tbzmorph1.morphq" "$W/tbzmorph1q.glb" 30 25 1 320x240; CHECKS+=("iou tbzmorph1 morphq $gv $gt")
  else
    fail "tbzmorph1q: sfb2gltf --sharpness-morph --quantize"; cat "$W/tbzmorph1q.sfb2gltf.log"
  fi
fi

t0=$(date +%s.%N)
node tests/web/render.mjs --batch "$JOBS" > "$W/render.log" 2>&1; rc=$?
cat "$W/render.log"
echo "render.mjs: $(wc -l < "$JOBS") pictures in $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s (exit $rc)"
[ "$rc" = 3 ] && unavailable "$(sed -n 's/^render.mjs: unavailable: //p' "$W/render.log" | head -n 1)"
if [ -f "$W/probe.json" ] && [ "$(json "$W/probe.json" objectPixels)" -gt 500 ]; then
  pass "WebGL draws headless: $(json "$W/probe.json" webgl) on $(json "$W/probe.json" glRenderer)"
else fail "the probe triangle was not drawn (exit $rc)"; fi

for c in "${CHECKS[@]}"; do
  read -r kind name what v t <<< "$c"
  r=$W/$name.$what
  [ -f "$r.json" ] || { fail "$name $what: render.mjs drew nothing (see above)"; continue; }
  i=$(iou "$W/$name.sfb.png" "$r.png")
  if [ "$kind" = wrong ]; then
    ge "$i" "$BAD_IOU" && fail "$name wrong view: IoU $i >= $BAD_IOU (the check cannot fail)" || pass "$name wrong view: IoU $i < $BAD_IOU"
    continue
  fi
  loader=GLTFLoader; [ "$what" = obj ] && loader=OBJLoader
  ge "$i" "$MIN_IOU" && pass "$name $loader $what: IoU $i >= $MIN_IOU" || fail "$name $loader $what: IoU $i < $MIN_IOU"
  [ "$(json "$r.json" vertices)" = "$v" ] && [ "$(json "$r.json" triangles)" = "$t" ] &&
    pass "$name $loader $what: counts $v vertices, $t triangles" ||
    fail "$name $loader $what: counts $(json "$r.json" vertices) vertices, $(json "$r.json" triangles) triangles, expected $v, $t"
done
finish
